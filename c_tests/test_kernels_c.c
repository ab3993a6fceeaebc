/*
 * Plain C99 test of the 28 kernel entry points of include/ampm.h (no Eigen, no reference
 * implementation): exact properties that hold for every correct implementation, the
 * all-or-nothing write contract, and every error code.
 *
 * The body is written once in kernels_c_body.inc and instantiated for 2D/3D × f32/f64 by
 * the macros below (C has no templates). All test-side arithmetic (dot products, norms,
 * tolerances) is done in long double, so a residual measures the library, not the test.
 *
 * Tolerances. Each checked identity is exact in real arithmetic; the computed residual is
 * bounded by the rounding errors of the library's evaluation, which are ≤ c·ε·κ·S where
 *   ε  = the working type's machine epsilon (FLT_EPSILON or DBL_EPSILON),
 *   S  = the magnitude of the terms the formula adds (a sum of |terms|, so cancellation
 *        cannot hide in it), computed from the input below,
 *   κ  = g = ‖F‖_F‖F⁻¹‖_F ≥ κ₂(F): H = F⁻ᵀ = cof(F)/det F and the polar factor R are both
 *        computed with a relative error of at most ~ε·κ(F) (det F's cancellation; the polar
 *        factor's condition number is ≤ κ₂(F̂) = κ₂(F)),
 *   c  = TOL_OPS = 8·d² bounds the number of roundings any one output entry goes through
 *        (d-term dot products, d×d products, one SVD sweep per pair of columns, scalings).
 * A wrong formula leaves residuals of the order of S itself, i.e. 1/(c·ε·κ) ≈ 10¹³ (f64)
 * or 10⁴ (f32) times the tolerance for the well-conditioned F used here (κ ≤ 4).
 *
 * Batch calls run on every instruction set of the CPU (ampm_set_isa): on the scalar one bit
 * for bit equal to the single calls; on the SIMD ones (fused multiply-add) bit-identical to
 * each other and within 2·c·ε·κ·S of the single calls (see test_batch in the body).
 */
/* <stddef.h>/<stdint.h> first: whether ampm.h is self-contained is checked by the header_c99
 * test, not a reason for this test to stop compiling. */
#include <stddef.h>
#include <stdint.h>

#include "ampm.h"

#include <float.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

typedef long double ld;

static int g_checks = 0;
static int g_failures = 0;
static const char *g_ctx = "";

#define CHECK(cond, ...)                                                                      \
  do {                                                                                        \
    ++g_checks;                                                                               \
    if (!(cond)) {                                                                            \
      ++g_failures;                                                                           \
      fprintf(stderr, "%s:%d: FAIL [%s] %s: ", __FILE__, __LINE__, g_ctx, #cond);            \
      fprintf(stderr, __VA_ARGS__);                                                           \
      fputc('\n', stderr);                                                                    \
    }                                                                                         \
  } while (0)

static const char *status_name(AmpmStatus s) {
  switch (s) {
  case AMPM_OK: return "AMPM_OK";
  case AMPM_ERR_NULL_POINTER: return "AMPM_ERR_NULL_POINTER";
  case AMPM_ERR_NON_FINITE: return "AMPM_ERR_NON_FINITE";
  case AMPM_ERR_NON_POSITIVE_J: return "AMPM_ERR_NON_POSITIVE_J";
  case AMPM_ERR_OVERFLOW: return "AMPM_ERR_OVERFLOW";
  case AMPM_ERR_INVALID_ARGUMENT: return "AMPM_ERR_INVALID_ARGUMENT";
  case AMPM_ERR_NOT_CONVERGED: return "AMPM_ERR_NOT_CONVERGED";
  case AMPM_ERR_INTERNAL: return "AMPM_ERR_INTERNAL";
  case AMPM_ERR_NOT_PREPARED: return "AMPM_ERR_NOT_PREPARED";
  case AMPM_ERR_OUTSIDE_GRID: return "AMPM_ERR_OUTSIDE_GRID";
  }
  return "(unknown status)";
}

#define CHECK_STATUS(call, expected)                                                          \
  do {                                                                                        \
    AmpmStatus st_ = (call);                                                                  \
    CHECK(st_ == (expected), "got %s, expected %s", status_name(st_), status_name(expected)); \
  } while (0)

/* ---- long-double helpers shared by all instantiations (column-major d×d) ---------------- */

static ld ld_dot(const ld *a, const ld *b, int n) {
  ld s = 0.0L;
  for (int i = 0; i < n; ++i) s += a[i] * b[i];
  return s;
}

static ld ld_norm(const ld *a, int n) { return sqrtl(ld_dot(a, a, n)); }

static ld ld_det(const ld *m, int d) {
  if (d == 2) return m[0] * m[3] - m[2] * m[1];
  /* m[i + 3j] = M_ij */
  return m[0] * (m[4] * m[8] - m[7] * m[5]) - m[3] * (m[1] * m[8] - m[7] * m[2]) +
         m[6] * (m[1] * m[5] - m[4] * m[2]);
}

/* H = M⁻ᵀ = cof(M)/det M. */
static void ld_inv_transpose(const ld *m, int d, ld *h) {
  const ld det = ld_det(m, d);
  if (d == 2) {
    h[0] = m[3] / det;
    h[1] = -m[2] / det;
    h[2] = -m[1] / det;
    h[3] = m[0] / det;
    return;
  }
  for (int j = 0; j < 3; ++j) {
    for (int i = 0; i < 3; ++i) {
      const int i1 = (i + 1) % 3, i2 = (i + 2) % 3, j1 = (j + 1) % 3, j2 = (j + 2) % 3;
      h[i + 3 * j] = (m[i1 + 3 * j1] * m[i2 + 3 * j2] - m[i1 + 3 * j2] * m[i2 + 3 * j1]) / det;
    }
  }
}

/* (X Y) for d×d column-major. */
static void ld_mul(const ld *x, const ld *y, int d, ld *out) {
  for (int j = 0; j < d; ++j)
    for (int i = 0; i < d; ++i) {
      ld s = 0.0L;
      for (int k = 0; k < d; ++k) s += x[i + d * k] * y[k + d * j];
      out[i + d * j] = s;
    }
}

/* Everything the tolerances need about one F (see the file comment). */
struct geo {
  ld n_f;      /* ‖F‖_F */
  ld n_h;      /* ‖H‖_F */
  ld g;        /* ‖F‖_F‖H‖_F ≥ κ₂(F) */
  ld ja;       /* Jᵃ, a = −1/d */
  ld n_fhat;   /* ‖F̂‖_F = Jᵃ‖F‖_F */
  ld b_scale;  /* ‖𝓑‖ ≤ Jᵃ(1 + |a|‖F‖‖H‖) */
  ld a_scale;  /* ‖A‖ = 2μ‖F̂ − R̂‖ ≤ 2μ(‖F̂‖ + √d), per unit μ */
  ld c_scale;  /* ‖C‖ ≤ 2μ(1 + ‖F̂⁻¹‖) (‖δR‖ ≤ ‖δF‖/σ̂_min), per unit μ */
};

static struct geo geo_of(const ld *f, int d) {
  struct geo r;
  ld h[9];
  ld_inv_transpose(f, d, h);
  r.n_f = ld_norm(f, d * d);
  r.n_h = ld_norm(h, d * d);
  r.g = r.n_f * r.n_h;
  r.ja = powl(ld_det(f, d), -1.0L / (ld)d);
  r.n_fhat = r.ja * r.n_f;
  r.b_scale = r.ja * (1.0L + r.g / (ld)d);
  r.a_scale = 2.0L * (r.n_fhat + sqrtl((ld)d));
  r.c_scale = 2.0L * (1.0L + r.n_h / r.ja);
  return r;
}

#define TOL_OPS(d) (8.0L * (ld)(d) * (ld)(d))

/* ---- instruction sets of the batch calls ------------------------------------------------ */

static const char *isa_name(uint32_t isa) {
  switch (isa) {
  case AMPM_ISA_SCALAR: return "scalar";
  case AMPM_ISA_AVX2: return "AVX2";
  case AMPM_ISA_AVX512: return "AVX-512";
  }
  return "(unknown ISA)";
}

/* Fills isas[0..n) with AMPM_ISA_SCALAR followed by the SIMD sets ampm_set_isa accepts on this
 * CPU (AMPM_ERR_INVALID_ARGUMENT = unsupported, skipped), narrowest first; returns n. The
 * current choice is restored. */
static int supported_isas(uint32_t isas[3]) {
  const uint32_t prev = ampm_isa();
  int n = 0;
  isas[n++] = AMPM_ISA_SCALAR;
  if (ampm_set_isa(AMPM_ISA_AVX2) == AMPM_OK) isas[n++] = AMPM_ISA_AVX2;
  if (ampm_set_isa(AMPM_ISA_AVX512) == AMPM_OK) isas[n++] = AMPM_ISA_AVX512;
  CHECK_STATUS(ampm_set_isa(prev), AMPM_OK);
  return n;
}

/* ---- instantiations ------------------------------------------------------------------- */

#define AMPM_D 2
#define AMPM_T float
#define AMPM_EPS FLT_EPSILON
#define AMPM_SUBNORMAL 1e-40f
#define AMPM_NAME "2d_f32"
#define AMPM_API(op) ampm_##op##_2d_f32
#define AMPM_LOCAL(name) name##_2d_f32
#include "kernels_c_body.inc"

#define AMPM_D 3
#define AMPM_T float
#define AMPM_EPS FLT_EPSILON
#define AMPM_SUBNORMAL 1e-40f
#define AMPM_NAME "3d_f32"
#define AMPM_API(op) ampm_##op##_3d_f32
#define AMPM_LOCAL(name) name##_3d_f32
#include "kernels_c_body.inc"

#define AMPM_D 2
#define AMPM_T double
#define AMPM_EPS DBL_EPSILON
#define AMPM_SUBNORMAL 1e-310
#define AMPM_NAME "2d_f64"
#define AMPM_API(op) ampm_##op##_2d_f64
#define AMPM_LOCAL(name) name##_2d_f64
#include "kernels_c_body.inc"

#define AMPM_D 3
#define AMPM_T double
#define AMPM_EPS DBL_EPSILON
#define AMPM_SUBNORMAL 1e-310
#define AMPM_NAME "3d_f64"
#define AMPM_API(op) ampm_##op##_3d_f64
#define AMPM_LOCAL(name) name##_3d_f64
#include "kernels_c_body.inc"

int main(void) {
  run_all_2d_f32();
  run_all_3d_f32();
  run_all_2d_f64();
  run_all_3d_f64();
  printf("test_kernels_c: %d checks, %d failures\n", g_checks, g_failures);
  return g_failures == 0 ? 0 : 1;
}
