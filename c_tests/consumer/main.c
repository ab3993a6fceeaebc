/*
 * A program that uses ampm like any C library: built by c_tests (the consumer_* tests) against
 * an installed package (find_package, pkg-config) and against the source tree
 * (add_subdirectory), once with libampm.a and once with libampm.so. It checks that calls
 * through the linked library return the documented results; it exits non-zero otherwise.
 */
#include <math.h>
#include <stdint.h>
#include <stdio.h>

#include "ampm.h"

#ifndef AMPM_CONSUMER_LINK
#define AMPM_CONSUMER_LINK "unknown"
#endif

static int failures = 0;

#define CHECK(cond, ...)                                                     \
  do {                                                                       \
    if (!(cond)) {                                                           \
      fprintf(stderr, "FAILED %s:%d: %s: ", __FILE__, __LINE__, #cond);      \
      fprintf(stderr, __VA_ARGS__);                                          \
      fputc('\n', stderr);                                                   \
      ++failures;                                                            \
    }                                                                        \
  } while (0)

static double max_abs(const double *a, int n) {
  double m = 0.0;
  for (int i = 0; i < n; ++i) m = fmax(m, fabs(a[i]));
  return m;
}

int main(void) {
  const double mu = 10.0; /* Pa */
  /* F = [[1.1, 0.1, 0], [0, 0.9, 0.2], [0, 0, 1]], column-major: F[i + 3j] = F_ij. */
  const double F[9] = {1.1, 0.0, 0.0, 0.1, 0.9, 0.0, 0.0, 0.2, 1.0};
  double ahat[9];
  AmpmStatus s;

  const uint32_t isa = ampm_isa();
  CHECK(isa == AMPM_ISA_SCALAR || isa == AMPM_ISA_AVX2 || isa == AMPM_ISA_AVX512,
        "ampm_isa() = %u is no AMPM_ISA_*", (unsigned)isa);

  s = ampm_ahat_3d_f64(mu, F, ahat);
  CHECK(s == AMPM_OK, "ampm_ahat_3d_f64 returned %d", (int)s);
  for (int k = 0; k < 9; ++k) CHECK(isfinite(ahat[k]), "Â[%d] = %g is not finite", k, ahat[k]);
  CHECK(max_abs(ahat, 9) > 0.1, "Â = 0 for a deviatoric strain (max |Â| = %g)", max_abs(ahat, 9));

  /* Â = ∂Ψ̂/∂F: central differences of ampm_energy_hat_3d_f64, entry by entry. */
  const double h = 1e-6, tol = 1e-6 * fmax(1.0, max_abs(ahat, 9));
  for (int k = 0; k < 9; ++k) {
    double Fp[9], Fm[9], ep = NAN, em = NAN;
    for (int i = 0; i < 9; ++i) Fp[i] = Fm[i] = F[i];
    Fp[k] += h;
    Fm[k] -= h;
    CHECK(ampm_energy_hat_3d_f64(mu, Fp, &ep) == AMPM_OK, "energy at F + h e_%d", k);
    CHECK(ampm_energy_hat_3d_f64(mu, Fm, &em) == AMPM_OK, "energy at F - h e_%d", k);
    const double fd = (ep - em) / (2.0 * h);
    CHECK(fabs(fd - ahat[k]) <= tol, "Â[%d] = %.17g but the finite difference is %.17g", k,
          ahat[k], fd);
  }

  /* Ψ̂ is blind to uniform scaling: Â(2I) = 0 up to rounding. */
  const double twoI[9] = {2, 0, 0, 0, 2, 0, 0, 0, 2};
  s = ampm_ahat_3d_f64(mu, twoI, ahat);
  CHECK(s == AMPM_OK, "ampm_ahat_3d_f64(2I) returned %d", (int)s);
  CHECK(max_abs(ahat, 9) <= 1e-12 * mu, "Â(2I) = %g, not 0", max_abs(ahat, 9));

  /* det F < 0 is refused, and nothing is written. */
  const double flip[9] = {-1, 0, 0, 0, 1, 0, 0, 0, 1};
  double untouched[9];
  for (int k = 0; k < 9; ++k) untouched[k] = 42.0;
  s = ampm_ahat_3d_f64(mu, flip, untouched);
  CHECK(s == AMPM_ERR_NON_POSITIVE_J, "det F < 0 gave status %d", (int)s);
  for (int k = 0; k < 9; ++k) CHECK(untouched[k] == 42.0, "out[%d] written on an error", k);
  s = ampm_ahat_3d_f64(mu, NULL, ahat);
  CHECK(s == AMPM_ERR_NULL_POINTER, "F = NULL gave status %d", (int)s);

  if (failures != 0) {
    fprintf(stderr, "ampm consumer (%s): %d check(s) failed\n", AMPM_CONSUMER_LINK, failures);
    return 1;
  }
  printf("ampm consumer (%s): OK, instruction set %u\n", AMPM_CONSUMER_LINK, (unsigned)isa);
  return 0;
}
