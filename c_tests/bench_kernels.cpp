// Benchmark of the C batch calls of include/ampm.h against a hand-written Eigen baseline and
// the memory floor of the batch, in one run (the main job writes docs/bench-c.md with it).
//
//   bench_kernels [--n N] [--out FILE]   time every case, print a markdown table (and to FILE)
//   bench_kernels --check [--n N]        agreement check only (N = 1024 by default), for ctest
//
// Workload (fixed seed, the same for every run): N particles (default 65,536),
// F = R1·diag(σ)·R2 with σᵢ log-uniform in [0.5, 2] and R1, R2 Haar rotations, μ = 1, Z with
// entries uniform in [−1, 1]. F, Z and μ are drawn in double and rounded to the precision of the
// case, so f32 and f64 see the same particles. Layout as in README "Conventions": d·d scalars
// per particle, column-major, back to back.
//
// Cases 3D f32, 3D f64, 2D f32, 2D f64. Per case, one thread, std::chrono::steady_clock, one
// warm-up run, then the median of 7 runs over the whole batch, in ns per particle:
//   separate calls  ampm_ahat_batch + ampm_chat_z_batch (two calls, both outputs)
//   combined        ampm_ahat_chat_z_batch (Â and Ĉ:Z from one call)
//   prepare         ampm_hessian_prepare_batch, with Â
//   apply           ampm_hessian_apply_batch with psd = 0 (Ĉ:Z)
//   apply psd       ampm_hessian_apply_batch with psd = 1 (Ĉ⁺:Z)
//   Eigen           the baseline below: one Eigen::JacobiSVD per particle, Â and Ĉ:Z
//   memory floor    a loop moving the bytes of the combined call (reads μ, F, Z; writes two
//                   d×d outputs) and nothing else
//
// Before any timing (and alone in --check mode), the combined call (also with either output
// NULL), prepare + apply(psd = 0) (also prepared without Â) and the Eigen baseline must agree
// with the two separate calls, and apply(psd = 1) with ampm_chat_z_psd_batch: relative
// Frobenius error ‖x − y‖/‖y‖ per particle, in long double, at most 1e-4 (f32) or 1e-10 (f64),
// every status AMPM_OK and every first_failed = n. For Â alone a particle also agrees when
// ‖x − y‖ ≤ 64·ε·2μ‖F̂‖ (see kAhatFloor: Â vanishes at conformal F, its rounding error does
// not); the table counts those particles. Any disagreement exits with status 1 and names the
// particle.

// <cstddef>/<cstdint> before ampm.h, as in common.hpp.
#include <cstddef>
#include <cstdint>

#include "ampm.h"
#include "bench_machine.hpp"
#include "common.hpp"  // Rng (portable seeded draws), status names

#include <Eigen/Dense>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <limits>
#include <new>
#include <sstream>
#include <string>
#include <vector>

namespace {

using ampm_test::Rng;
using ld = long double;

constexpr std::uint64_t kSeed = 0xbe4c'a3b1'2014'0001ULL;
constexpr std::size_t kDefaultN = 65536;
constexpr std::size_t kCheckN = 1024;
constexpr int kReps = 7;

// ---- the C symbols by (scalar, dimension) --------------------------------------------------

template <class T, int D>
struct Api;

#define AMPM_BENCH_API(T, D, S)                                                    \
  template <>                                                                      \
  struct Api<T, D> {                                                               \
    static constexpr const char* name = #D "D " #S;                                \
    static constexpr auto ahat_batch = ampm_ahat_batch_##D##d_##S;                 \
    static constexpr auto chat_z_batch = ampm_chat_z_batch_##D##d_##S;             \
    static constexpr auto chat_z_psd_batch = ampm_chat_z_psd_batch_##D##d_##S;     \
    static constexpr auto ahat_chat_z_batch = ampm_ahat_chat_z_batch_##D##d_##S;   \
    static constexpr auto hessian_len = ampm_hessian_len_##D##d_##S;               \
    static constexpr auto hessian_prepare = ampm_hessian_prepare_batch_##D##d_##S; \
    static constexpr auto hessian_apply = ampm_hessian_apply_batch_##D##d_##S;     \
  };
AMPM_BENCH_API(float, 2, f32)
AMPM_BENCH_API(float, 3, f32)
AMPM_BENCH_API(double, 2, f64)
AMPM_BENCH_API(double, 3, f64)
#undef AMPM_BENCH_API

/// common.hpp's status names.
const char* status_name(AmpmStatus s) { return ampm_test::status_name(s); }

// ---- buffers -------------------------------------------------------------------------------

/// n scalars, 64-byte aligned (a cache line), so no case pays for a misaligned start.
template <class T>
class Buffer {
 public:
  explicit Buffer(std::size_t n) : n_(n) {
    const std::size_t bytes = ((n * sizeof(T) + 63) / 64) * 64;
    p_ = static_cast<T*>(std::aligned_alloc(64, bytes == 0 ? 64 : bytes));
    if (p_ == nullptr) throw std::bad_alloc();
    std::fill(p_, p_ + n, static_cast<T>(0));
  }
  ~Buffer() { std::free(p_); }
  Buffer(const Buffer&) = delete;
  Buffer& operator=(const Buffer&) = delete;
  T* data() { return p_; }
  const T* data() const { return p_; }
  std::size_t size() const { return n_; }

 private:
  T* p_ = nullptr;
  std::size_t n_ = 0;
};

// ---- the workload --------------------------------------------------------------------------

/// Haar rotation in SO(2): angle uniform in [0, 2π).
Eigen::Matrix2d haar_rotation2(Rng& rng) {
  const double t = rng.uniform(0.0, 6.283185307179586476925);
  Eigen::Matrix2d r;
  r << std::cos(t), -std::sin(t), std::sin(t), std::cos(t);
  return r;
}

/// Haar rotation in SO(3): the unit quaternion of a normalized standard Gaussian 4-vector is
/// uniform on S³, and the double cover S³ → SO(3) maps the uniform measure to the Haar measure
/// (Shoemake 1992, "Uniform random rotations", Graphics Gems III).
Eigen::Matrix3d haar_rotation3(Rng& rng) {
  Eigen::Vector4d q;
  do {
    for (int k = 0; k < 4; ++k) q(k) = rng.normal();
  } while (q.norm() < 1e-6);
  q.normalize();
  return Eigen::Quaterniond(q(0), q(1), q(2), q(3)).toRotationMatrix();
}

/// μ, F, Z of n particles in double (rounded to each case's precision later).
struct Workload {
  int d = 0;
  std::size_t n = 0;
  std::vector<double> mu, f, z;
};

Workload make_workload(int d, std::size_t n) {
  Rng rng(kSeed + static_cast<std::uint64_t>(d));
  Workload w;
  w.d = d;
  w.n = n;
  const std::size_t dd = static_cast<std::size_t>(d) * d;
  w.mu.assign(n, 1.0);
  w.f.resize(n * dd);
  w.z.resize(n * dd);
  for (std::size_t i = 0; i < n; ++i) {
    Eigen::Vector3d sigma;
    for (int k = 0; k < d; ++k) sigma(k) = rng.log_uniform(0.5, 2.0);
    if (d == 2) {
      const Eigen::Matrix2d r1 = haar_rotation2(rng), r2 = haar_rotation2(rng);
      const Eigen::Matrix2d f = r1 * sigma.head<2>().asDiagonal() * r2;
      std::copy(f.data(), f.data() + 4, w.f.begin() + i * dd);
    } else {
      const Eigen::Matrix3d r1 = haar_rotation3(rng), r2 = haar_rotation3(rng);
      const Eigen::Matrix3d f = r1 * sigma.asDiagonal() * r2;
      std::copy(f.data(), f.data() + 9, w.f.begin() + i * dd);
    }
    for (std::size_t k = 0; k < dd; ++k) w.z[i * dd + k] = rng.uniform(-1.0, 1.0);
  }
  return w;
}

// ---- the Eigen baseline --------------------------------------------------------------------

// GCC 12 reports -Wmaybe-uninitialized inside Eigen 3.4's JacobiSVD once it is inlined at -O3
// (its singular values are written by compute() before any read); silenced for the baseline only.
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif

/// Â and Ĉ:Z of the augmented fixed-corotated energy for one particle, as an engine author
/// would write them from README "The math in short" (Stomakhin et al. 2014, augmented MPM tech
/// report, with its J^{−1/a} read as Jᵃ): fixed-size Eigen types, no heap, one
/// Eigen::JacobiSVD per particle. Returns false when J ≤ 0 or J is not finite.
template <class T, int D>
bool eigen_particle(T mu, const Eigen::Matrix<T, D, D>& f, const Eigen::Matrix<T, D, D>& z,
                    Eigen::Matrix<T, D, D>& ahat, Eigen::Matrix<T, D, D>& chat_z) {
  using M = Eigen::Matrix<T, D, D>;
  using V = Eigen::Matrix<T, D, 1>;
  const T a = T(-1) / T(D);  // a = −1/d

  // J = det F, Jᵃ (sqrt/cbrt rather than pow with a rounded exponent), H = F⁻ᵀ.
  const T j = f.determinant();
  if (!(j > 0) || !std::isfinite(j)) return false;
  const T ja = D == 2 ? T(1) / std::sqrt(j) : T(1) / std::cbrt(j);
  const M h = f.inverse().transpose();

  // Rotation-variant SVD (README "The math in short"): U, V ∈ SO(d), only the last singular
  // value may be negative. JacobiSVD gives σ ≥ 0 sorted and U, V orthogonal; negate the last
  // column of a reflection and move the sign onto the last σ. F̂ = JᵃF has the same U, V and
  // σ̂ = Jᵃσ.
  const Eigen::JacobiSVD<M> svd(f, Eigen::ComputeFullU | Eigen::ComputeFullV);
  M u = svd.matrixU(), v = svd.matrixV();
  V s_hat = ja * svd.singularValues();
  if (u.determinant() < 0) {
    u.col(D - 1) = -u.col(D - 1);
    s_hat(D - 1) = -s_hat(D - 1);
  }
  if (v.determinant() < 0) {
    v.col(D - 1) = -v.col(D - 1);
    s_hat(D - 1) = -s_hat(D - 1);
  }
  const M r = u * v.transpose();  // R = U Vᵀ

  // Fixed corotated at F̂: A = 2μ(F̂ − R).
  const M fa = ja * f;
  const M pa = T(2) * mu * (fa - r);

  // Â = A:𝓑 with Z:𝓑 = Jᵃ(Z + a(F:Z)H).
  const T a_f = pa.cwiseProduct(f).sum();  // A:F
  ahat = ja * (pa + a * a_f * h);

  // 𝓑:Z = Jᵃ(Z + a(H:Z)F).
  const T h_z = h.cwiseProduct(z).sum();  // H:Z
  const M bz = ja * (z + a * h_z * f);

  // C:δF = 2μ(δF − δR) at F̂, δR = U W Vᵀ, W_ij = (Ũ_ij − Ũ_ji)/(σ̂ᵢ + σ̂ⱼ), Ũ = Uᵀ δF V.
  const M ut = u.transpose() * bz * v;
  M w = M::Zero();
  for (int c = 0; c < D; ++c)
    for (int rr = 0; rr < D; ++rr)
      if (rr != c) w(rr, c) = (ut(rr, c) - ut(c, rr)) / (s_hat(rr) + s_hat(c));
  const M c_bz = T(2) * mu * (bz - u * w * v.transpose());  // C:(𝓑:Z)

  // Ĉ:Z = (C:(𝓑:Z)):𝓑 + a(H:Z)A:𝓑 + aJᵃ(A:Z)H − aJᵃ(A:F)HZᵀH.
  const T fc = f.cwiseProduct(c_bz).sum();  // F:(C:(𝓑:Z)), for (C:(𝓑:Z)):𝓑
  const T a_z = pa.cwiseProduct(z).sum();   // A:Z
  chat_z = ja * (c_bz + a * fc * h) + a * h_z * ahat + (a * ja * a_z) * h -
           (a * ja * a_f) * (h * z.transpose() * h);
  return true;
}

/// The baseline over a batch (same layout as the C batch calls); returns the first failed
/// particle, or n.
template <class T, int D>
std::size_t eigen_batch(std::size_t n, const T* mu, const T* f, const T* z, T* ahat, T* chat_z) {
  using M = Eigen::Matrix<T, D, D>;
  constexpr std::size_t dd = D * D;
  std::size_t first_failed = n;
  for (std::size_t i = 0; i < n; ++i) {
    M a, c;
    if (!eigen_particle<T, D>(mu[i], Eigen::Map<const M>(f + i * dd),
                              Eigen::Map<const M>(z + i * dd), a, c)) {
      if (first_failed == n) first_failed = i;
      continue;
    }
    Eigen::Map<M>(ahat + i * dd) = a;
    Eigen::Map<M>(chat_z + i * dd) = c;
  }
  return first_failed;
}

#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic pop
#endif

// ---- the memory floor ----------------------------------------------------------------------

/// Moves the bytes of the combined call and does no other work: reads μ, F, Z and writes two
/// d×d outputs per particle (ahat = μF, chat_z = F + Z). noinline so the timed loop is this
/// one, compiled once, not merged into its caller.
template <class T, int D>
__attribute__((noinline)) void memory_floor(std::size_t n, const T* __restrict mu,
                                            const T* __restrict f, const T* __restrict z,
                                            T* __restrict ahat, T* __restrict chat_z) {
  constexpr std::size_t dd = D * D;
  for (std::size_t i = 0; i < n; ++i) {
    const T m = mu[i];
    for (std::size_t k = 0; k < dd; ++k) {
      ahat[i * dd + k] = m * f[i * dd + k];
      chat_z[i * dd + k] = f[i * dd + k] + z[i * dd + k];
    }
  }
}

// ---- timing --------------------------------------------------------------------------------

[[noreturn]] void fail(const std::string& msg) {
  std::fprintf(stderr, "bench_kernels: %s\n", msg.c_str());
  std::exit(1);
}

/// Median over `reps` runs of `body` (after one warm-up run), in ns per particle. `body`
/// returns an AmpmStatus (checked after the clock stops) and writes its first failed index.
template <class Body>
double time_per_particle(const char* what, const char* case_name, std::size_t n, int reps,
                         Body&& body) {
  std::vector<double> ns;
  for (int r = -1; r < reps; ++r) {  // r = −1: warm-up
    std::size_t first_failed = n + 1;
    const auto t0 = std::chrono::steady_clock::now();
    const AmpmStatus st = body(&first_failed);
    const auto t1 = std::chrono::steady_clock::now();
    if (st != AMPM_OK || first_failed != n)
      fail(std::string(case_name) + " " + what + ": status " + status_name(st) +
           ", first_failed " + std::to_string(first_failed) + " (n = " + std::to_string(n) +
           ") during timing");
    if (r >= 0) ns.push_back(std::chrono::duration<double, std::nano>(t1 - t0).count());
  }
  std::sort(ns.begin(), ns.end());
  return ns[ns.size() / 2] / static_cast<double>(n);
}

// ---- agreement -----------------------------------------------------------------------------

/// ‖x − y‖_F / ‖y‖_F of one d×d matrix, accumulated in long double.
template <class T>
ld rel_frob(const T* x, const T* y, std::size_t m) {
  ld num = 0, den = 0;
  for (std::size_t k = 0; k < m; ++k) {
    const ld diff = static_cast<ld>(x[k]) - static_cast<ld>(y[k]);
    num += diff * diff;
    den += static_cast<ld>(y[k]) * static_cast<ld>(y[k]);
  }
  if (den == 0) return num == 0 ? 0 : std::numeric_limits<ld>::infinity();
  return std::sqrt(num / den);
}

struct Agreement {
  std::string case_name, what;
  ld max_err = 0;             // max relative Frobenius error over the particles
  std::size_t worst = 0;      // its particle
  std::size_t identical = 0;  // particles equal bit for bit
  std::size_t by_floor = 0;   // Â only: particles within the rounding floor, not the tolerance
  std::size_t n = 0;
  ld tol = 0;
  bool has_floor = false;
};

template <class T>
ld tolerance() {
  return sizeof(T) == 4 ? 1e-4L : 1e-10L;
}

/// Multiple of ε·2μ‖F̂‖_F within which two Â agree even when their relative error is large.
/// Â = A:𝓑 with A = 2μ(F̂ − R) vanishes as F̂ → R (a conformal F, Â(sQ) = 0), while the rounding
/// of F̂ − R stays ε·2μ‖F̂‖: any backward-stable Â, in this library or in the baseline, has a
/// relative error ≈ ε‖F̂‖/‖F̂ − R‖ there, unbounded per particle. On the default workload in
/// f32 that exceeds 1e-4 for about 2 particles in a thousand in 2D (σ₁/σ₂ within ~1e-3 of 1)
/// and 2 of the 65,536 in 3D. Measured against a long-double reference (common.hpp's Reference) on the
/// default particles, the library's Â is within 28·ε·2μ‖F̂‖ and the baseline's within 7, so
/// their difference is below 35; 64 leaves a margin, and every particle that needs it is
/// counted in the table. Ĉ:Z has no such cancellation (its C:(𝓑:Z) term is O(μ‖Z‖) for any F)
/// and gets no floor.
constexpr ld kAhatFloor = 64;

/// ε·2μ‖F̂‖_F of one particle, F̂ = JᵃF, in long double.
template <class T, int D>
ld ahat_floor(T mu, const T* f) {
  const Eigen::Matrix<ld, D, D> fl = Eigen::Map<const Eigen::Matrix<T, D, D>>(f).template cast<ld>();
  const ld j = fl.determinant();
  const ld ja = D == 2 ? 1 / std::sqrt(j) : 1 / std::cbrt(j);
  return kAhatFloor * static_cast<ld>(std::numeric_limits<T>::epsilon()) * 2 *
         static_cast<ld>(mu) * ja * fl.norm();
}

/// Compares n d×d results x against y: a particle agrees when ‖x − y‖_F ≤ tol·‖y‖_F (in long
/// double), or, with `mu_for_floor` set (Â), when ‖x − y‖_F ≤ kAhatFloor·ε·2μ‖F̂‖_F. On any
/// particle that does not (or a NaN) prints its inputs and both results, then exits with 1.
template <class T, int D>
Agreement agree(const char* case_name, const char* what, std::size_t n, const T* x, const T* y,
                const T* f, const T* z, const T* mu_for_floor) {
  constexpr std::size_t dd = D * D;
  Agreement a;
  a.case_name = case_name;
  a.what = what;
  a.n = n;
  a.tol = tolerance<T>();
  a.has_floor = mu_for_floor != nullptr;
  std::size_t bad = 0, first_bad = n;
  for (std::size_t i = 0; i < n; ++i) {
    const ld e = rel_frob(x + i * dd, y + i * dd, dd);
    if (std::memcmp(x + i * dd, y + i * dd, dd * sizeof(T)) == 0) ++a.identical;
    if (!(e <= a.max_err)) {  // also records a NaN
      a.max_err = e;
      a.worst = i;
    }
    if (e <= a.tol) continue;
    if (mu_for_floor != nullptr) {
      ld d2 = 0;
      for (std::size_t k = 0; k < dd; ++k) {
        const ld diff = static_cast<ld>(x[i * dd + k]) - static_cast<ld>(y[i * dd + k]);
        d2 += diff * diff;
      }
      if (std::sqrt(d2) <= ahat_floor<T, D>(mu_for_floor[i], f + i * dd)) {
        ++a.by_floor;
        continue;
      }
    }
    if (bad == 0) first_bad = i;
    ++bad;
  }
  if (bad != 0) {
    std::fprintf(stderr,
                 "bench_kernels: DISAGREEMENT in %s, %s: %zu of %zu particles have relative "
                 "Frobenius error above %.0Le%s (max %.3Le at particle %zu)\n",
                 case_name, what, bad, n, a.tol,
                 a.has_floor ? " and a difference above the rounding floor" : "", a.max_err,
                 a.worst);
    std::fprintf(stderr, "  first such particle %zu: rel err %.3Le\n", first_bad,
                 rel_frob(x + first_bad * dd, y + first_bad * dd, dd));
    auto dump = [&](const char* name, const T* p) {
      std::fprintf(stderr, "    %-4s (column-major) = {", name);
      for (std::size_t k = 0; k < dd; ++k)
        std::fprintf(stderr, "%s%.17g", k ? ", " : "", static_cast<double>(p[first_bad * dd + k]));
      std::fprintf(stderr, "}\n");
    };
    dump("F", f);
    dump("Z", z);
    dump("got", x);
    dump("want", y);
    std::exit(1);
  }
  return a;
}

/// `first_failed` is read here, after the call (not as an argument evaluated next to it).
void check_call(const char* case_name, const char* what, AmpmStatus st,
                const std::size_t* first_failed, std::size_t n) {
  if (st != AMPM_OK || *first_failed != n)
    fail(std::string(case_name) + " " + what + ": returned " + status_name(st) +
         ", first_failed = " + std::to_string(*first_failed) + ", expected AMPM_OK and " +
         std::to_string(n));
}

// ---- one case ------------------------------------------------------------------------------

struct Row {
  std::string name;
  double separate = NAN, combined = NAN, prepare = NAN, apply = NAN, apply_psd = NAN,
         eigen = NAN, floor = NAN;
  std::size_t floor_bytes = 0;  // bytes per particle moved by the memory floor
};

template <class T, int D>
Row run_case(const Workload& w, bool timing, std::vector<Agreement>& agreements) {
  using A = Api<T, D>;
  constexpr std::size_t dd = D * D;
  const std::size_t n = w.n;
  const char* name = A::name;

  Buffer<T> mu(n), f(n * dd), z(n * dd);
  for (std::size_t i = 0; i < n; ++i) mu.data()[i] = static_cast<T>(w.mu[i]);
  for (std::size_t k = 0; k < n * dd; ++k) {
    f.data()[k] = static_cast<T>(w.f[k]);
    z.data()[k] = static_cast<T>(w.z[k]);
  }
  Buffer<T> sep_ahat(n * dd), sep_cz(n * dd), eig_ahat(n * dd), eig_cz(n * dd),
      floor_a(n * dd), floor_c(n * dd);

  // ---- agreement (always, before timing) ----
  std::size_t ff = n + 1;
  check_call(name, "ampm_ahat_batch",
             A::ahat_batch(n, mu.data(), f.data(), sep_ahat.data(), &ff), &ff, n);
  ff = n + 1;
  check_call(name, "ampm_chat_z_batch",
             A::chat_z_batch(n, mu.data(), f.data(), z.data(), sep_cz.data(), &ff), &ff, n);
  ff = eigen_batch<T, D>(n, mu.data(), f.data(), z.data(), eig_ahat.data(), eig_cz.data());
  if (ff != n)
    fail(std::string(name) + " Eigen baseline: J <= 0 or not finite at particle " +
         std::to_string(ff));

  const std::size_t plen = A::hessian_len();
  if (plen == 0) fail(std::string(name) + ": ampm_hessian_len returned 0");
  Buffer<T> comb_ahat(n * dd), comb_cz(n * dd), prep_ahat(n * dd), prepared(n * plen),
      app_cz(n * dd), app_psd(n * dd);
  ff = n + 1;
  check_call(name, "ampm_ahat_chat_z_batch",
             A::ahat_chat_z_batch(n, mu.data(), f.data(), z.data(), comb_ahat.data(),
                                  comb_cz.data(), &ff),
             &ff, n);
  ff = n + 1;
  check_call(name, "ampm_hessian_prepare_batch",
             A::hessian_prepare(n, mu.data(), f.data(), prep_ahat.data(), prepared.data(), &ff),
             &ff, n);
  ff = n + 1;
  check_call(name, "ampm_hessian_apply_batch (psd = 0)",
             A::hessian_apply(n, prepared.data(), z.data(), app_cz.data(), 0, &ff), &ff, n);
  ff = n + 1;
  check_call(name, "ampm_hessian_apply_batch (psd = 1)",
             A::hessian_apply(n, prepared.data(), z.data(), app_psd.data(), 1, &ff), &ff, n);
  Buffer<T> sep_psd(n * dd);
  ff = n + 1;
  check_call(name, "ampm_chat_z_psd_batch",
             A::chat_z_psd_batch(n, mu.data(), f.data(), z.data(), sep_psd.data(), &ff), &ff, n);
  // The optional outputs: ahat or chat_z NULL (Z NULL with it), prepare without Â.
  Buffer<T> only_ahat(n * dd), only_cz(n * dd), prepared2(n * plen), app_cz2(n * dd);
  ff = n + 1;
  check_call(name, "ampm_ahat_chat_z_batch (chat_z = Z = NULL)",
             A::ahat_chat_z_batch(n, mu.data(), f.data(), nullptr, only_ahat.data(), nullptr,
                                  &ff),
             &ff, n);
  ff = n + 1;
  check_call(name, "ampm_ahat_chat_z_batch (ahat = NULL)",
             A::ahat_chat_z_batch(n, mu.data(), f.data(), z.data(), nullptr, only_cz.data(), &ff),
             &ff, n);
  ff = n + 1;
  check_call(name, "ampm_hessian_prepare_batch (ahat = NULL)",
             A::hessian_prepare(n, mu.data(), f.data(), nullptr, prepared2.data(), &ff), &ff, n);
  ff = n + 1;
  check_call(name, "ampm_hessian_apply_batch (psd = 0, prepared without Â)",
             A::hessian_apply(n, prepared2.data(), z.data(), app_cz2.data(), 0, &ff), &ff, n);

  agreements.push_back(agree<T, D>(name, "combined Â vs separate", n, comb_ahat.data(),
                                   sep_ahat.data(), f.data(), z.data(), mu.data()));
  agreements.push_back(agree<T, D>(name, "combined Ĉ:Z vs separate", n, comb_cz.data(),
                                   sep_cz.data(), f.data(), z.data(), nullptr));
  agreements.push_back(agree<T, D>(name, "prepare Â vs separate", n, prep_ahat.data(),
                                   sep_ahat.data(), f.data(), z.data(), mu.data()));
  agreements.push_back(agree<T, D>(name, "apply(psd = 0) Ĉ:Z vs separate", n, app_cz.data(),
                                   sep_cz.data(), f.data(), z.data(), nullptr));
  agreements.push_back(agree<T, D>(name, "apply(psd = 1) Ĉ⁺:Z vs ampm_chat_z_psd_batch", n,
                                   app_psd.data(), sep_psd.data(), f.data(), z.data(),
                                   nullptr));
  agreements.push_back(agree<T, D>(name, "combined, Â only, vs separate", n, only_ahat.data(),
                                   sep_ahat.data(), f.data(), z.data(), mu.data()));
  agreements.push_back(agree<T, D>(name, "combined, Ĉ:Z only, vs separate", n, only_cz.data(),
                                   sep_cz.data(), f.data(), z.data(), nullptr));
  agreements.push_back(agree<T, D>(name, "apply(psd = 0) after prepare without Â vs separate",
                                   n, app_cz2.data(), sep_cz.data(), f.data(), z.data(),
                                   nullptr));
  agreements.push_back(agree<T, D>(name, "Eigen Â vs separate", n, eig_ahat.data(),
                                   sep_ahat.data(), f.data(), z.data(), mu.data()));
  agreements.push_back(agree<T, D>(name, "Eigen Ĉ:Z vs separate", n, eig_cz.data(),
                                   sep_cz.data(), f.data(), z.data(), nullptr));

  Row row;
  row.name = name;
  row.floor_bytes = (1 + 4 * dd) * sizeof(T);
  if (!timing) return row;

  // ---- timing ----
  row.separate = time_per_particle("separate calls", name, n, kReps, [&](std::size_t* first) {
    const AmpmStatus s1 = A::ahat_batch(n, mu.data(), f.data(), sep_ahat.data(), first);
    if (s1 != AMPM_OK) return s1;
    return A::chat_z_batch(n, mu.data(), f.data(), z.data(), sep_cz.data(), first);
  });
  row.combined = time_per_particle("combined", name, n, kReps, [&](std::size_t* first) {
    return A::ahat_chat_z_batch(n, mu.data(), f.data(), z.data(), comb_ahat.data(),
                                comb_cz.data(), first);
  });
  row.prepare = time_per_particle("prepare", name, n, kReps, [&](std::size_t* first) {
    return A::hessian_prepare(n, mu.data(), f.data(), prep_ahat.data(), prepared.data(), first);
  });
  row.apply = time_per_particle("apply (psd = 0)", name, n, kReps, [&](std::size_t* first) {
    return A::hessian_apply(n, prepared.data(), z.data(), app_cz.data(), 0, first);
  });
  row.apply_psd = time_per_particle("apply (psd = 1)", name, n, kReps, [&](std::size_t* first) {
    return A::hessian_apply(n, prepared.data(), z.data(), app_psd.data(), 1, first);
  });
  row.eigen = time_per_particle("Eigen baseline", name, n, kReps, [&](std::size_t* first) {
    *first = eigen_batch<T, D>(n, mu.data(), f.data(), z.data(), eig_ahat.data(), eig_cz.data());
    return *first == n ? AMPM_OK : AMPM_ERR_NON_POSITIVE_J;
  });
  row.floor = time_per_particle("memory floor", name, n, kReps, [&](std::size_t* first) {
    memory_floor<T, D>(n, mu.data(), f.data(), z.data(), floor_a.data(), floor_c.data());
    *first = n;
    return AMPM_OK;
  });
  return row;
}

// ---- machine and report --------------------------------------------------------------------

struct Machine {
  std::string model = "unknown CPU";
  bool have_flags = false, avx512f = false, avx2 = false, fma = false;
};

using bench_machine::trim;

/// CPU model and ISA flags from the first processor of /proc/cpuinfo (Linux).
Machine read_machine() {
  Machine m;
  std::ifstream in("/proc/cpuinfo");
  std::string line;
  bool have_model = false;
  while (std::getline(in, line)) {
    const auto colon = line.find(':');
    if (colon == std::string::npos) continue;
    const std::string key = trim(line.substr(0, colon)), val = trim(line.substr(colon + 1));
    if (key == "model name" && !have_model) {
      m.model = val;
      have_model = true;
    } else if (key == "flags" && !m.have_flags) {
      m.have_flags = true;
      std::istringstream ss(val);
      std::string flag;
      while (ss >> flag) {
        m.avx512f |= flag == "avx512f";
        m.avx2 |= flag == "avx2";
        m.fma |= flag == "fma";
      }
    }
    if (have_model && m.have_flags) break;
  }
  return m;
}

using bench_machine::compiler;

/// The ISA extensions this binary (the Eigen baseline and the memory floor) was compiled for.
std::string compiled_for() {
  std::string s;
#ifdef __AVX512F__
  s += " avx512f";
#endif
#ifdef __AVX2__
  s += " avx2";
#endif
#ifdef __FMA__
  s += " fma";
#endif
  return s.empty() ? " baseline x86-64 / none of avx512f, avx2, fma" : s;
}

std::string fmt(double ns) {
  if (std::isnan(ns)) return "n/a";
  char b[32];
  std::snprintf(b, sizeof b, ns < 10 ? "%.2f" : ns < 100 ? "%.1f" : "%.0f", ns);
  return b;
}

std::string report(const std::vector<Row>& rows, const std::vector<Agreement>& agreements,
                   std::size_t n, bool timing) {
  const Machine m = read_machine();
  auto yn = [&](bool b) { return m.have_flags ? (b ? "yes" : "no") : "unknown"; };
  std::ostringstream o;
  o << "# ampm C batch calls vs a hand-written Eigen baseline\n\n";
  o << "CPU: " << m.model << "; ISA (/proc/cpuinfo): avx512f " << yn(m.avx512f) << ", avx2 "
    << yn(m.avx2) << ", fma " << yn(m.fma) << "; N = " << n << "; compiler: " << compiler()
    << ", baseline built for" << compiled_for() << "\n\n";
  if (timing) {
    o << "ns per particle, one thread, median of " << kReps
      << " runs over the whole batch after one warm-up run (`c_tests/bench_kernels`). "
         "F = R1·diag(σ)·R2, σ log-uniform in [0.5, 2], R1, R2 Haar, μ = 1, Z uniform in "
         "[−1, 1].\n\n";
    o << "| case | separate calls | combined | prepare | apply | apply psd | Eigen | memory "
         "floor | Eigen/combined |\n";
    o << "|---|---:|---:|---:|---:|---:|---:|---:|---:|\n";
    for (const Row& r : rows) {
      std::string ratio = "n/a";
      if (!std::isnan(r.combined) && r.combined > 0) {
        char b[32];
        std::snprintf(b, sizeof b, "%.2f", r.eigen / r.combined);
        ratio = b;
      }
      o << "| " << r.name << " | " << fmt(r.separate) << " | " << fmt(r.combined) << " | "
        << fmt(r.prepare) << " | " << fmt(r.apply) << " | " << fmt(r.apply_psd) << " | "
        << fmt(r.eigen) << " | " << fmt(r.floor) << " | " << ratio << " |\n";
    }
    o << "\n";
    o << "- separate calls: `ampm_ahat_batch` + `ampm_chat_z_batch`; combined: "
         "`ampm_ahat_chat_z_batch` (both outputs); prepare: `ampm_hessian_prepare_batch` with "
         "Â; apply / apply psd: `ampm_hessian_apply_batch` with psd = 0 (Ĉ:Z) / 1 (Ĉ⁺:Z).\n";
    o << "- Eigen: per particle one `Eigen::JacobiSVD` (full U, V), Â and Ĉ:Z from README "
         "\"The math in short\", fixed-size types, no heap.\n";
    o << "- memory floor: a loop that reads μ, F, Z and writes two d×d outputs (";
    for (std::size_t i = 0; i < rows.size(); ++i)
      o << (i ? ", " : "") << rows[i].name << ": " << rows[i].floor_bytes << " B";
    o << " per particle), the bytes the combined call moves; it fits in whatever cache level "
         "that working set fits at this N.\n";
    o << "\n";
  }
  o << "Agreement with the separate calls (`ampm_ahat_batch`, `ampm_chat_z_batch`; for Ĉ⁺:Z "
       "`ampm_chat_z_psd_batch`), per particle: relative Frobenius error "
       "‖x − y‖/‖y‖ in long double at most the tolerance; for Â also accepted: "
       "‖x − y‖ ≤ " << static_cast<int>(kAhatFloor)
    << "·ε·2μ‖F̂‖ (Â → 0 as F becomes conformal while its rounding error does not; such "
       "particles are counted). Every status AMPM_OK, every first_failed = n.\n\n";
  o << "| case | result | max rel err | tolerance | within the Â floor only | bit-identical "
       "particles |\n";
  o << "|---|---|---:|---:|---:|---:|\n";
  for (const Agreement& a : agreements) {
    char e[32], t[32];
    std::snprintf(e, sizeof e, "%.2Le", a.max_err);
    std::snprintf(t, sizeof t, "%.0Le", a.tol);
    o << "| " << a.case_name << " | " << a.what << " | " << e << " | " << t << " | "
      << (a.has_floor ? std::to_string(a.by_floor) : std::string("—")) << " | " << a.identical
      << " / " << a.n << " |\n";
  }
  return o.str();
}

[[noreturn]] void usage(int code) {
  std::fprintf(code == 0 ? stdout : stderr,
               "usage: bench_kernels [--n N] [--out FILE]   time every case, markdown table\n"
               "       bench_kernels --check [--n N]        agreement check only (N = %zu)\n"
               "default N = %zu particles\n",
               kCheckN, kDefaultN);
  std::exit(code);
}

}  // namespace

int main(int argc, char** argv) {
  bool check = false;
  std::size_t n = 0;
  const char* out = nullptr;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--check") {
      check = true;
    } else if (arg == "--n" && i + 1 < argc) {
      const char* s = argv[++i];
      char* end = nullptr;
      const unsigned long long v = std::strtoull(s, &end, 10);
      if (*s == '\0' || *s == '-' || *end != '\0' || v == 0 || v > (1ULL << 32)) {
        std::fprintf(stderr, "bench_kernels: --n wants an integer in [1, 2^32], got '%s'\n", s);
        return 2;
      }
      n = static_cast<std::size_t>(v);
    } else if (arg == "--out" && i + 1 < argc) {
      out = argv[++i];
    } else if (arg == "--help" || arg == "-h") {
      usage(0);
    } else {
      std::fprintf(stderr, "bench_kernels: unknown or incomplete argument '%s'\n", arg.c_str());
      usage(2);
    }
  }
  if (n == 0) n = check ? kCheckN : kDefaultN;
  const bool timing = !check;

  std::vector<Row> rows;
  std::vector<Agreement> agreements;
  {
    const Workload w3 = make_workload(3, n);
    rows.push_back(run_case<float, 3>(w3, timing, agreements));
    rows.push_back(run_case<double, 3>(w3, timing, agreements));
  }
  {
    const Workload w2 = make_workload(2, n);
    rows.push_back(run_case<float, 2>(w2, timing, agreements));
    rows.push_back(run_case<double, 2>(w2, timing, agreements));
  }

  const std::string text = report(rows, agreements, n, timing);
  std::fputs(text.c_str(), stdout);
  if (out != nullptr) {
    std::ofstream f(out);
    f << text;
    f.close();
    if (!f) {
      std::fprintf(stderr, "bench_kernels: cannot write %s\n", out);
      return 1;
    }
  }
  if (check) std::printf("bench_kernels --check: all results agree (N = %zu)\n", n);
  return 0;
}
