// The agreement checks: the relative Frobenius error per particle against the tolerance (or,
// for Â, the rounding floor), the summary of one comparison, and the check of a call's status.
#pragma once

#include "bench_kernels/api.hpp"

#include <cstring>
#include <limits>

namespace {

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
/// and 2 of the 65,536 in 3D. Measured against a long-double reference (common.hpp's
/// Reference) on the default particles, the library's Â is within 28·ε·2μ‖F̂‖ and the
/// baseline's within 7, so their difference is below 35; 64 leaves a margin, and every
/// particle that needs it is counted in the table. Ĉ:Z has no such cancellation (its C:(𝓑:Z)
/// term is O(μ‖Z‖) for any F) and gets no floor.
constexpr ld kAhatFloor = 64;

/// ε·2μ‖F̂‖_F of one particle, F̂ = JᵃF, in long double.
template <class T, int D>
ld ahat_floor(T mu, const T* f) {
  const Eigen::Matrix<ld, D, D> fl =
      Eigen::Map<const Eigen::Matrix<T, D, D>>(f).template cast<ld>();
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

}  // namespace
