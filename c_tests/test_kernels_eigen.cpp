// The 28 kernel symbols of include/ampm.h against the independent long-double reference of
// common.hpp, and that reference against central finite differences.
//
// For 2D and 3D, f32 and f64: random F = U diag(σ) Vᵀ with Haar U, V ∈ SO(d) and σᵢ
// log-uniform in [0.2, 5] (so J > 0, κ₂(F) ≤ 25), random Gaussian Z, μ log-uniform in
// [0.1, 10]. The reference is evaluated at the exact input the library saw (F, Z, μ rounded
// to T and converted back to long double).
//
// Acceptance: relative error ≤ 1e-11 in f64 and ≤ 1e-4 in f32, i.e. 4.5·10⁴ ε₆₄ and
// 8.4·10² ε₃₂. "Relative" is the Frobenius norm of the error over the Frobenius norm of the
// reference result, except for Ψ̂ (see `psi_scale`).
//
// Batch calls run on every instruction set of the CPU (`ampm_set_isa`): on AMPM_ISA_SCALAR bit
// for bit equal to the single calls, on the SIMD sets bit-identical to each other and within
// twice the acceptance of the single calls (see `kBatchVsSingle`). `check_isa_api` tests
// ampm_set_isa / ampm_isa themselves.
#include "common.hpp"

#include <algorithm>
#include <cinttypes>
#include <cstdint>
#include <vector>

using namespace ampm_test;

namespace {

constexpr std::uint64_t kSeed = 0x5eed'a3b1'2014'0002ULL;
constexpr int kSamples = 4000;  // per (dimension, scalar type)
constexpr int kMaxPrinted = 5;  // failing inputs printed in full per quantity

template <class T>
struct Accept;
template <>
struct Accept<double> {
  static constexpr ld tol = 1e-11L;
};
template <>
struct Accept<float> {
  static constexpr ld tol = 1e-4L;
};

/// Scale of Ψ̂'s error: μ‖F̂‖²_F. Ψ̂ = μΣ(σ̂ᵢ − 1)² vanishes quadratically at rotations while
/// its rounding error does not: a backward-stable SVD gives |δσ̂ᵢ| ≤ c·ε·‖F̂‖ (Weyl), so
/// |δΨ̂| ≤ 2μΣ|σ̂ᵢ − 1||δσ̂ᵢ| ≤ 4d·c·ε·μ‖F̂‖²_F (|σ̂ᵢ − 1| ≤ σ̂ᵢ + 1 ≤ 2‖F̂‖_F, as ‖F̂‖_F ≥ √d
/// when det F̂ = 1). Relative to Ψ̂ itself the error would be unbounded near rotations;
/// relative to μ‖F̂‖² it is ε-sized everywhere.
template <int D>
ld psi_scale(const Reference<D>& ref) {
  return ref.mu() * ref.f_hat().squaredNorm();
}

/// Natural scale of Â, the scale its acceptance is measured against (as μ‖F̂‖² is for Ψ̂):
/// Â = 2μ(F̂ − R̂):𝓑 subtracts two terms of size 2μ‖F̂‖‖𝓑‖, ‖𝓑‖ ≤ Jᵃ(1 + ‖F‖‖H‖/d). The
/// problem itself is ill-conditioned relative to ‖Â‖ near a rotation: rounding F̂ = JᵃF to the
/// working precision (unavoidable: Jᵃ is irrational) already moves Â by ε·2μ‖F̂‖‖𝓑‖ however
/// small Â is, so the error relative to ‖Â‖ grows like ε‖F̂‖/‖F̂ − R̂‖ for every algorithm.
/// Measured against this scale the error is ε-sized everywhere; away from rotations the two
/// measures agree up to the factor ‖F̂‖/‖F̂ − R̂‖ = O(1).
template <int D>
ld ahat_backward_scale(const Reference<D>& ref) {
  const ld b_norm = ref.ja() * (1 + ref.f().norm() * ref.h().norm() / D);
  return 2 * ref.mu() * ref.f_hat().norm() * b_norm;
}

/// Worst value of one measured error over the samples.
struct Worst {
  ld value = 0;
  int sample = -1;
  void add(ld v, int s) {
    if (!(v <= value)) {  // also records NaN
      value = v;
      sample = s;
    }
  }
};

/// Bound on a SIMD batch result against the single call, in units of ε·scale (scale: the one
/// its accuracy is measured against, 2μ‖F̂‖‖𝓑‖ for Â, ‖Ĉ:Z‖ for Ĉ:Z). Both run the same
/// generic source, ~10³ operations per particle; they differ only in whether a·b + c is
/// rounded once (fused, SIMD batch) or twice (scalar single call), ≤ 1 ulp per operation,
/// amplified by at most the conditioning the accuracy bound already allows for. So the bound is
/// derived from that bound, not measured: the batch and the single call each meet
/// ‖x − ref‖ ≤ K·ε·scale with K = Accept<T>::tol/ε (4.5·10⁴ in f64, 8.4·10² in f32, the
/// acceptance; both are checked above), hence ‖batch − single‖ ≤ 2K·ε·scale.
template <class T>
constexpr ld kBatchVsSingle() {
  return 2 * Accept<T>::tol / static_cast<ld>(std::numeric_limits<T>::epsilon());
}

// ---- finite differences (formula-free check of the reference) -----------------------------

/// Derivation of the tolerance. Along a unit direction E (‖E‖_F = 1) let g(t) = Ψ̂(F + tE)
/// (or Â(F + tE)), D(h) = (g(h) − g(−h))/(2h) = g'(0) + c₂h² + c₄h⁴ + …, c₂ = g'''/6, and the
/// Richardson value R = (4D(h/2) − D(h))/3 = g'(0) − c₄h⁴/4 + ….
/// - Truncation: |D(h) − D(h/2)| = (3/4)|c₂|h² + O(h⁴) bounds R's O(h⁴) error as long as
///   h is well inside g's length scale ρ: Ψ̂ is analytic while FᵀF stays positive definite
///   (Ψ̂ = μ(‖F̂‖² − 2 tr√(F̂ᵀF̂) + d)), i.e. within ρ = σ_min(F)/2 of F, and the k-th derivative
///   scales like k!|g'|ρ^{1−k}; with h = 10⁻⁴ρ, |c₄|h⁴ ~ 10⁻¹⁶|g'|, below the rounding term.
/// - Rounding: each long-double evaluation of g has an absolute error ≤ η, so D(h) carries
///   ≤ η/h, D(h/2) ≤ 2η/h, R ≤ (8 + 1)η/(3h) = 3η/h, and the estimate D(h) − D(h/2) ≤ 3η/h.
/// Tolerance: |D(h) − D(h/2)| + 6η/h.
constexpr ld kFdStep = 1e-4L;  // h / ρ
constexpr ld kOps = 8;         // c = 8d²: roundings per entry (as in test_kernels_c.c)

template <int D>
struct FdResult {
  ld err = 0;  // |analytic − Richardson|
  ld tol = 0;
  ld scale = 0;  // |analytic| for reporting
};

template <int D>
FdResult<D> fd_ahat(const Reference<D>& ref, const MatL<D>& e, ld h) {
  auto g = [&](ld t) { return Reference<D>(ref.mu(), ref.f() + t * e).psi_hat(); };
  auto d = [&](ld s) { return (g(s) - g(-s)) / (2 * s); };
  const ld d1 = d(h), d2 = d(h / 2), rich = (4 * d2 - d1) / 3;
  const ld exact = ddot<D>(ref.ahat(), e);
  // η: the SVD's backward error, |δΨ̂| ≤ 4d·c·ε·μ‖F̂‖² (see psi_scale), plus the rounding of
  // F + tE's entries (relative ε each), which moves Ψ̂ by ≤ ε‖F‖‖Â‖.
  const ld eps = std::numeric_limits<ld>::epsilon();
  const ld c = kOps * D * D;
  const ld eta = 4 * D * c * eps * psi_scale(ref) + eps * ref.f().norm() * ref.ahat().norm();
  return {std::fabs(exact - rich), std::fabs(d1 - d2) + 6 * eta / h, std::fabs(exact)};
}

template <int D>
FdResult<D> fd_chat(const Reference<D>& ref, const MatL<D>& e, ld h) {
  using M = MatL<D>;
  auto g = [&](ld t) { return Reference<D>(ref.mu(), ref.f() + t * e).ahat(); };
  auto d = [&](ld s) -> M { return (g(s) - g(-s)) / (2 * s); };
  const M d1 = d(h), d2 = d(h / 2), rich = (4 * d2 - d1) / 3;
  const M exact = ref.chat_z(e);
  // η for Â = A:𝓑 in long double (κ = ‖F‖_F‖H‖_F ≥ κ₂(F) = κ₂(F̂)):
  //  - R from the SVD: ‖δR‖ ≤ ‖ΔF̂‖/σ̂_min ≤ c·ε·κ, so ‖δA‖ ≤ 2μ·c·ε·(‖F̂‖ + κ);
  //  - applying 𝓑 (H = F⁻ᵀ has relative error ~ε·κ): ≤ c·ε·κ·‖𝓑‖‖A‖, ‖𝓑‖ ≤ Jᵃ(1 + ‖F‖‖H‖/d);
  //  - the rounding of F + tE: ≤ ε‖F‖‖Ĉ‖ (‖Ĉ‖ ≤ its d²×d² Frobenius norm).
  const ld eps = std::numeric_limits<ld>::epsilon();
  const ld c = kOps * D * D;
  const ld kappa = ref.f().norm() * ref.h().norm();
  const ld b_norm = ref.ja() * (1 + kappa / D);
  const ld eta = c * eps *
                     (b_norm * 2 * ref.mu() * (ref.f_hat().norm() + kappa) +
                      kappa * b_norm * ref.first_piola().norm()) +
                 eps * ref.f().norm() * ref.chat_tensor().norm();
  return {(exact - rich).norm(), (d1 - d2).norm() + 6 * eta / h, exact.norm()};
}

// ---- one (scalar, dimension) ---------------------------------------------------------------

template <class T, int D>
struct Suite {
  static constexpr int DD = D * D;
  using A = Api<T, D>;
  using MT = Mat<T, D>;
  using ML = MatL<D>;

  Checker& ck;
  Rng rng;
  int n;
  // the inputs and single-call results of every sample, contiguous as the batch calls want
  std::vector<T> mu, f, z, ahat1, chat1;
  std::vector<ML> ahat_ref, chat_ref;
  std::vector<ld> ahat_scale;  // ahat_backward_scale per sample
  // worst SIMD |batch − single|/(ε·scale) over every batch test: [0] Â, [1] Ĉ:Z
  Worst worst_simd[2];

  Suite(Checker& c, std::uint64_t seed, int samples)
      : ck(c), rng(seed), n(samples), mu(n), f(n * DD), z(n * DD), ahat1(n * DD),
        chat1(n * DD), ahat_ref(n), chat_ref(n), ahat_scale(n) {}

  MT mat(const std::vector<T>& v, int p) const { return Eigen::Map<const MT>(v.data() + p * DD); }

  void report_input(int p) const {
    std::fprintf(stderr, "  input of sample %d (%s): mu = %a\n", p, A::name,
                 static_cast<double>(mu[p]));
    print_exact<T, D>("F", mat(f, p));
    print_exact<T, D>("Z", mat(z, p));
  }

  void run() {
    const ld tol = Accept<T>::tol;
    Worst w_bz, w_zb, w_psi, w_ahat, w_ahat_bw, w_chat, w_fd_a, w_fd_c, w_fd_a_ratio, w_fd_c_ratio;
    int printed[5] = {0, 0, 0, 0, 0};
    auto check_err = [&](ld e, int which, const char* what, int p) {
      const bool ok = e <= tol;
      AMPM_CHECK(ck, ok, "%s %s: relative error %.3Le > %.0Le (sample %d)", A::name, what, e,
                 tol, p);
      if (!ok && printed[which]++ < kMaxPrinted) report_input(p);
    };

    for (int p = 0; p < n; ++p) {
      const auto sigma = log_uniform_sigma<D>(rng, 0.2, 5.0);
      const MT ft = round_to<T, D>(random_f_with_sigma<D>(rng, sigma));
      const MT zt = round_to<T, D>(random_z<D>(rng));
      const T mut = static_cast<T>(rng.log_uniform(0.1, 10.0));
      std::copy(ft.data(), ft.data() + DD, f.begin() + p * DD);
      std::copy(zt.data(), zt.data() + DD, z.begin() + p * DD);
      mu[p] = mut;
      const ML fl = to_ld<T, D>(ft), zl = to_ld<T, D>(zt);
      const Reference<D> ref(static_cast<ld>(mut), fl);

      MT bz, zb, ah, cz;
      T psi = sentinel<T>();
      AMPM_CHECK_STATUS(ck, A::b_z(ft.data(), zt.data(), bz.data()), AMPM_OK);
      AMPM_CHECK_STATUS(ck, A::z_b(ft.data(), zt.data(), zb.data()), AMPM_OK);
      AMPM_CHECK_STATUS(ck, A::energy_hat(mut, ft.data(), &psi), AMPM_OK);
      AMPM_CHECK_STATUS(ck, A::ahat(mut, ft.data(), ah.data()), AMPM_OK);
      AMPM_CHECK_STATUS(ck, A::chat_z(mut, ft.data(), zt.data(), cz.data()), AMPM_OK);
      std::copy(ah.data(), ah.data() + DD, ahat1.begin() + p * DD);
      std::copy(cz.data(), cz.data() + DD, chat1.begin() + p * DD);
      ahat_ref[p] = ref.ahat();
      chat_ref[p] = ref.chat_z(zl);

      const ld e_bz = rel_err<T, D>(bz, ref.b_z(zl));
      const ld e_zb = rel_err<T, D>(zb, ref.z_b(zl));
      const ld e_psi = std::fabs(static_cast<ld>(psi) - ref.psi_hat()) / psi_scale(ref);
      ahat_scale[p] = ahat_backward_scale(ref);
      const ld e_ah = (to_ld<T, D>(ah) - ahat_ref[p]).norm() / ahat_scale[p];
      const ld e_cz = rel_err<T, D>(cz, chat_ref[p]);
      check_err(e_bz, 0, "b_z", p);
      check_err(e_zb, 1, "z_b", p);
      check_err(e_psi, 2, "energy_hat (relative to mu |F^|^2)", p);
      const ld eps_t = std::numeric_limits<T>::epsilon();
      const ld e_ah_bw =
          (to_ld<T, D>(ah) - ahat_ref[p]).norm() / (eps_t * ahat_backward_scale(ref));
      check_err(e_ah, 3, "ahat (relative to 2mu |F^||B|)", p);
      if (e_ah > tol && printed[3] <= kMaxPrinted)
        std::fprintf(stderr,
                     "  ahat diagnosis: sigma(F^) - 1 = %.3Le .. %.3Le, |F^ - R|/|F^| = %.3Le, "
                     "error = %.3Lf eps * 2mu|F^||B| (backward-stable size)\n",
                     ref.sigma()(0) - 1, ref.sigma()(D - 1) - 1,
                     (ref.f_hat() - ref.rotation()).norm() / ref.f_hat().norm(), e_ah_bw);
      w_ahat_bw.add(e_ah_bw, p);
      check_err(e_cz, 4, "chat_z", p);
      w_bz.add(e_bz, p);
      w_zb.add(e_zb, p);
      w_psi.add(e_psi, p);
      w_ahat.add(e_ah, p);
      w_chat.add(e_cz, p);

      // The reference against finite differences, along Z/‖Z‖.
      const ML e = zl / zl.norm();
      const ld sigma_min_f = std::fabs(ref.sigma()(D - 1)) / ref.ja();  // σ(F) = σ(F̂)/Jᵃ
      const ld h = kFdStep * sigma_min_f / 2;
      const FdResult<D> fa = fd_ahat<D>(ref, e, h);
      AMPM_CHECK(ck, fa.err <= fa.tol,
                 "%s reference Ahat:E vs FD of psi_hat: %.3Le > %.3Le (sample %d)", A::name,
                 fa.err, fa.tol, p);
      const FdResult<D> fc = fd_chat<D>(ref, e, h);
      AMPM_CHECK(ck, fc.err <= fc.tol,
                 "%s reference Chat:E vs FD of Ahat: %.3Le > %.3Le (sample %d)", A::name, fc.err,
                 fc.tol, p);
      w_fd_a.add(fa.err / fa.scale, p);
      w_fd_c.add(fc.err / fc.scale, p);
      w_fd_a_ratio.add(fa.err / fa.tol, p);
      w_fd_c_ratio.add(fc.err / fc.tol, p);
    }

    std::printf("%s, %d samples, acceptance %.0Le (worst relative error, sample):\n", A::name, n,
                tol);
    std::printf("  b_z %.2Le (%d)  z_b %.2Le (%d)  energy_hat/(mu|F^|^2) %.2Le (%d)\n", w_bz.value,
                w_bz.sample, w_zb.value, w_zb.sample, w_psi.value, w_psi.sample);
    std::printf("  ahat %.2Le (%d)  chat_z %.2Le (%d)\n", w_ahat.value, w_ahat.sample,
                w_chat.value, w_chat.sample);
    std::printf("  ahat error / (eps * 2mu|F^||B|): worst %.3Lf (%d)\n", w_ahat_bw.value,
                w_ahat_bw.sample);
    std::printf("  reference vs FD (h = 1e-4 sigma_min/2): Ahat:E rel %.2Le (err/tol %.2Le), "
                "Chat:E rel %.2Le (err/tol %.2Le)\n",
                w_fd_a.value, w_fd_a_ratio.value, w_fd_c.value, w_fd_c_ratio.value);

    batch_all_valid();
    batch_failures();
    std::printf("  SIMD batch vs single, worst |diff|/(eps * scale): ahat %.3Lf (%d)  chat_z "
                "%.3Lf (%d)  (bound 2K = %.0Lf)\n",
                worst_simd[0].value, worst_simd[0].sample, worst_simd[1].value,
                worst_simd[1].sample, kBatchVsSingle<T>());
  }

  // ---- batch calls ----------------------------------------------------------------------

  /// Compares batch outputs, computed on instruction set `isa`, with the single calls and
  /// with the reference:
  ///  - AMPM_ISA_SCALAR runs the single calls' code (no FMA): bit for bit;
  ///  - a SIMD set (FMA): within kBatchVsSingle·ε·scale of the single call (see there), and
  ///    bit-identical to the batch of the first SIMD set (`simd_first`: filled by the first
  ///    SIMD run of this batch, compared against by the others).
  void compare_batch(const std::vector<T>& out, const std::vector<T>& single,
                     const std::vector<ML>& ref, const char* what, int count,
                     const std::vector<bool>& failed, const std::vector<ld>* scale,
                     std::uint32_t isa, std::vector<T>& simd_first) {
    int mismatched = 0, first_mismatch = -1;
    std::uint64_t max_ulps = 0;
    Worst w, w_simd;
    const bool scalar = isa == AMPM_ISA_SCALAR;
    const ld eps = std::numeric_limits<T>::epsilon();
    for (int p = 0; p < count; ++p) {
      if (failed[p]) {
        AMPM_CHECK(ck, all_sentinel(out.data() + p * DD, DD),
                   "%s %s (%s): failed particle %d was written", A::name, what, isa_name(isa), p);
        continue;
      }
      // Â against its natural scale (see ahat_backward_scale), Ĉ:Z relative to itself.
      const ld s = scale ? (*scale)[p] : ref[p].norm();
      if (scalar) {
        if (!same_bits(out.data() + p * DD, single.data() + p * DD, DD)) {
          if (mismatched++ == 0) first_mismatch = p;
          for (int k = 0; k < DD; ++k)
            max_ulps = std::max(max_ulps, ulp_distance(out[p * DD + k], single[p * DD + k]));
        }
      } else {
        const ld diff = (to_ld<T, D>(mat(out, p)) - to_ld<T, D>(mat(single, p))).norm();
        w_simd.add(diff / (eps * s), p);
      }
      w.add((to_ld<T, D>(mat(out, p)) - ref[p]).norm() / s, p);
    }
    if (scalar) {
      AMPM_CHECK(ck, mismatched == 0,
                 "%s %s (scalar ISA): %d of %d valid particles differ from the single call "
                 "(first: %d, max %" PRIu64 " ulps)",
                 A::name, what, mismatched, count, first_mismatch, max_ulps);
      if (mismatched > 0 && first_mismatch >= 0) report_input(first_mismatch);
    } else {
      const ld bound = kBatchVsSingle<T>();
      AMPM_CHECK(ck, w_simd.value <= bound,
                 "%s %s (%s): |batch - single| = %.3Lf eps * scale > %.0Lf (particle %d)",
                 A::name, what, isa_name(isa), w_simd.value, bound, w_simd.sample);
      if (!(w_simd.value <= bound) && w_simd.sample >= 0) report_input(w_simd.sample);
      worst_simd[scale ? 0 : 1].add(w_simd.value, w_simd.sample);
      if (simd_first.empty()) {
        simd_first = out;
      } else {
        int differ = 0, first_differ = -1;
        for (int p = 0; p < count; ++p)
          if (!same_bits(out.data() + p * DD, simd_first.data() + p * DD, DD) &&
              differ++ == 0)
            first_differ = p;
        AMPM_CHECK(ck, differ == 0,
                   "%s %s: %d of %d particles differ between the SIMD instruction sets (%s vs "
                   "the first; first: %d)",
                   A::name, what, differ, count, isa_name(isa), first_differ);
      }
    }
    AMPM_CHECK(ck, w.value <= Accept<T>::tol,
               "%s %s (%s): relative error %.3Le > %.0Le (particle %d)", A::name, what,
               isa_name(isa), w.value, Accept<T>::tol, w.sample);
  }

  /// The instruction sets every batch test runs on: scalar, then each SIMD set of this CPU.
  static std::vector<std::uint32_t> batch_isas() {
    std::vector<std::uint32_t> isas{AMPM_ISA_SCALAR};
    for (std::uint32_t isa : simd_isas()) isas.push_back(isa);
    return isas;
  }

  /// Sets `isa` for the batch calls (restored by the caller's IsaRestore).
  void use_isa(std::uint32_t isa) {
    AMPM_CHECK_STATUS(ck, ampm_set_isa(isa), AMPM_OK);
    AMPM_CHECK(ck, ampm_isa() == isa, "ampm_isa() = %u after ampm_set_isa(%u)", ampm_isa(), isa);
  }

  AmpmStatus call_batch(bool chat, std::size_t count, const T* m, const T* ff, const T* zz,
                        T* out, std::size_t* first_failed) {
    return chat ? A::chat_z_batch(count, m, ff, zz, out, first_failed)
                : A::ahat_batch(count, m, ff, out, first_failed);
  }

  void batch_all_valid() {
    const std::vector<bool> none(n, false);
    for (bool chat : {false, true}) {
      const char* what = chat ? "chat_z_batch" : "ahat_batch";
      std::vector<T> simd_first;
      for (std::uint32_t isa : batch_isas()) {
        const IsaRestore keep;
        use_isa(isa);
        std::vector<T> out(n * DD, sentinel<T>());
        std::size_t ff = 999'999;
        AMPM_CHECK_STATUS(ck,
                          call_batch(chat, n, mu.data(), f.data(), z.data(), out.data(), &ff),
                          AMPM_OK);
        AMPM_CHECK(ck, ff == static_cast<std::size_t>(n),
                   "%s %s (%s): first_failed = %zu, want n = %d", A::name, what, isa_name(isa),
                   ff, n);
        compare_batch(out, chat ? chat1 : ahat1, chat ? chat_ref : ahat_ref, what, n, none,
                      chat ? nullptr : &ahat_scale, isa, simd_first);
      }
    }
  }

  /// A batch of the first 37 samples (not a multiple of any lane count) with bad particles.
  void batch_failures() {
    const int m = std::min(n, 37);
    struct Case {
      const char* name;
      AmpmStatus want;
      int want_index;
      bool null_first_failed;
      // bad particles: NaN F entry, det F < 0, det F = 0, NaN μ, μ < 0, inf Z entry (Ĉ only)
      std::vector<int> nan_f, neg_j, zero_f, nan_mu, neg_mu, inf_z;
    };
    const Case cases[] = {
        {"NaN F first", AMPM_ERR_NON_FINITE, 5, false, {5}, {11}, {}, {20}, {}, {30}},
        {"NaN F first, first_failed NULL", AMPM_ERR_NON_FINITE, 5, true,
         {5}, {11}, {}, {20}, {}, {30}},
        {"det F = 0 first", AMPM_ERR_NON_POSITIVE_J, 3, false, {9}, {}, {3}, {}, {}, {}},
        {"det F < 0 first", AMPM_ERR_NON_POSITIVE_J, 0, false, {}, {0}, {}, {}, {36}, {}},
        {"mu < 0 only", AMPM_ERR_INVALID_ARGUMENT, 17, false, {}, {}, {}, {}, {17}, {}},
        {"NaN mu first", AMPM_ERR_NON_FINITE, 2, false, {}, {}, {}, {2}, {4}, {}},
        {"last particle", AMPM_ERR_NON_POSITIVE_J, 36, false, {}, {36}, {}, {}, {}, {}},
    };
    for (bool chat : {false, true}) {
      for (const Case& c : cases) {
        std::vector<T> mb(mu.begin(), mu.begin() + m), fb(f.begin(), f.begin() + m * DD),
            zb(z.begin(), z.begin() + m * DD);
        std::vector<bool> failed(m, false);
        for (int p : c.nan_f) fb[p * DD + DD - 1] = std::numeric_limits<T>::quiet_NaN();
        for (int p : c.neg_j)
          for (int i = 0; i < D; ++i) fb[p * DD + i] = -fb[p * DD + i];
        for (int p : c.zero_f) std::fill(fb.begin() + p * DD, fb.begin() + (p + 1) * DD, T(0));
        for (int p : c.nan_mu) mb[p] = std::numeric_limits<T>::quiet_NaN();
        for (int p : c.neg_mu) mb[p] = T(-1);
        for (const std::vector<int>* bad : {&c.nan_f, &c.neg_j, &c.zero_f, &c.nan_mu, &c.neg_mu})
          for (int p : *bad) failed[p] = true;
        if (chat) {
          for (int p : c.inf_z) {
            zb[p * DD] = std::numeric_limits<T>::infinity();
            failed[p] = true;
          }
        }
        // With inf Z ignored (Â), the expected first failure is unchanged in every case above.
        const char* what = chat ? "chat_z_batch" : "ahat_batch";
        std::vector<T> simd_first;
        for (std::uint32_t isa : batch_isas()) {
          const IsaRestore keep;
          use_isa(isa);
          std::vector<T> out(m * DD, sentinel<T>());
          std::size_t ff = 999'999;
          const AmpmStatus st = call_batch(chat, m, mb.data(), fb.data(), zb.data(), out.data(),
                                           c.null_first_failed ? nullptr : &ff);
          AMPM_CHECK(ck, st == c.want, "%s %s [%s] (%s): status %s, want %s", A::name, what,
                     c.name, isa_name(isa), status_name(st), status_name(c.want));
          if (!c.null_first_failed)
            AMPM_CHECK(ck, ff == static_cast<std::size_t>(c.want_index),
                       "%s %s [%s] (%s): first_failed = %zu, want %d", A::name, what, c.name,
                       isa_name(isa), ff, c.want_index);
          compare_batch(out, chat ? chat1 : ahat1, chat ? chat_ref : ahat_ref, what, m, failed,
                        chat ? nullptr : &ahat_scale, isa, simd_first);
        }
      }
      // n = 0 with NULL arrays: AMPM_OK and *first_failed = 0.
      std::size_t ff = 999'999;
      AMPM_CHECK_STATUS(ck, call_batch(chat, 0, nullptr, nullptr, nullptr, nullptr, &ff), AMPM_OK);
      AMPM_CHECK(ck, ff == 0, "%s n = 0: first_failed = %zu, want 0", A::name, ff);
      AMPM_CHECK_STATUS(ck, call_batch(chat, 0, nullptr, nullptr, nullptr, nullptr, nullptr),
                        AMPM_OK);
      // n = 0 with an empty std::vector (data() may be NULL)
      std::vector<T> empty;
      AMPM_CHECK_STATUS(ck,
                        call_batch(chat, empty.size(), empty.data(), empty.data(), empty.data(),
                                   empty.data(), &ff),
                        AMPM_OK);
    }
  }
};

/// ampm_set_isa / ampm_isa: the default is the widest instruction set this CPU supports;
/// every supported set can be chosen and is then reported by ampm_isa(); an unknown or
/// unsupported value is refused with AMPM_ERR_INVALID_ARGUMENT and changes nothing. Runs
/// first, before any call has changed the default, and leaves the choice as it found it.
void check_isa_api(Checker& ck) {
  const std::uint32_t initial = ampm_isa();
  const std::vector<std::uint32_t> simd = simd_isas();
  AMPM_CHECK(ck, ampm_isa() == initial, "probing the ISAs changed ampm_isa() from %u to %u",
             initial, ampm_isa());
  const std::uint32_t widest = simd.empty() ? std::uint32_t{AMPM_ISA_SCALAR} : simd.back();
  AMPM_CHECK(ck, initial == widest, "default ampm_isa() = %u (%s), want the widest, %u (%s)",
             initial, isa_name(initial), widest, isa_name(widest));
  std::printf("instruction sets: default %s; SIMD sets of this CPU:", isa_name(initial));
  for (std::uint32_t isa : simd) std::printf(" %s", isa_name(isa));
  std::printf("%s\n", simd.empty() ? " none" : "");

  const IsaRestore keep;
  std::vector<std::uint32_t> all{AMPM_ISA_SCALAR};
  all.insert(all.end(), simd.begin(), simd.end());
  for (std::uint32_t isa : all) {
    AMPM_CHECK_STATUS(ck, ampm_set_isa(isa), AMPM_OK);
    AMPM_CHECK(ck, ampm_isa() == isa, "ampm_isa() = %u after ampm_set_isa(%u)", ampm_isa(), isa);
    for (std::uint32_t bad : {std::uint32_t{3}, std::uint32_t{99}, UINT32_MAX}) {
      AMPM_CHECK_STATUS(ck, ampm_set_isa(bad), AMPM_ERR_INVALID_ARGUMENT);
      AMPM_CHECK(ck, ampm_isa() == isa, "ampm_set_isa(%u) changed ampm_isa() from %u to %u", bad,
                 isa, ampm_isa());
    }
    // A known but unsupported SIMD set is refused the same way.
    for (std::uint32_t other : {std::uint32_t{AMPM_ISA_AVX2}, std::uint32_t{AMPM_ISA_AVX512}}) {
      if (std::find(simd.begin(), simd.end(), other) != simd.end()) continue;
      AMPM_CHECK_STATUS(ck, ampm_set_isa(other), AMPM_ERR_INVALID_ARGUMENT);
      AMPM_CHECK(ck, ampm_isa() == isa, "ampm_set_isa(%u) (unsupported) changed ampm_isa()",
                 other);
    }
  }
}

}  // namespace

int main() {
  Checker ck;
  check_isa_api(ck);
  // One seed per suite, derived from the base seed, so suites are independent of each other.
  Suite<double, 2>(ck, kSeed + 1, kSamples).run();
  Suite<double, 3>(ck, kSeed + 2, kSamples).run();
  Suite<float, 2>(ck, kSeed + 3, kSamples).run();
  Suite<float, 3>(ck, kSeed + 4, kSamples).run();
  ck.summary("test_kernels_eigen");
  return ck.exit_code();
}
