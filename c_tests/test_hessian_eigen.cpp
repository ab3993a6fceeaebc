// The definiteness of Ĉ (PSD projection, explicit matrices) from C++/Eigen, through the C ABI only:
//   ampm_chat_matrix_<d>_<p>      explicit d²×d² Hessian Ĉ,
//   ampm_chat_psd_matrix_<d>_<p>  its PSD projection Ĉ⁺,
//   ampm_chat_z_psd_<d>_<p>       the action Ĉ⁺:Z, and ampm_chat_z_psd_batch_<d>_<p>,
// against a brute force a host could write: the independent long-double Ĉ tensor of
// common.hpp (`Reference<D>::chat_tensor`, the seed's index formula), symmetrised,
// eigen-decomposed by Eigen::SelfAdjointEigenSolver, negative eigenvalues clamped, recomposed.
//
// Layout: the d²×d² outputs are column-major with vec(Z)[i + d*j] = Z_ij, the convention of
// common.hpp's tensors, so `Eigen::Matrix<T, d², d²>::data()` receives Ĉ with
// vec(Ĉ:Z) = Ĉ · vec(Z).
//
// Tolerance: 32·ε·κ relative to ‖Ĉ‖_F (actions: ‖Ĉ‖_F‖Z‖_F), κ = σ_max/σ_min of F, ε of the
// precision under test; derived in tests/hessian/main.rs: a backward-stable SVD (≈ 2d·ε·‖F‖ in F),
// Ĉ homogeneous of degree −2 with σᵢσⱼ denominators (relative sensitivity 2/σ_min), the PSD
// projection 1-Lipschitz in the Frobenius norm; that budget (8d ≤ 24 < 32) counts two
// double-precision sides, here the reference is long double, so it holds with margin. On top,
// the acceptance bound, 1e-10 relative in f64, is checked on every case.
#include "common.hpp"

#include <algorithm>
#include <vector>

using namespace ampm_test;

namespace {

template <class T, int D>
struct HessApi;

#define AMPM_HESS_API(T, D, S)                                            \
  template <>                                                             \
  struct HessApi<T, D> {                                                  \
    static constexpr const char* name = #D "d_" #S;                       \
    static constexpr auto psd_z = ampm_chat_z_psd_##D##d_##S;             \
    static constexpr auto psd_z_batch = ampm_chat_z_psd_batch_##D##d_##S; \
    static constexpr auto matrix = ampm_chat_matrix_##D##d_##S;           \
    static constexpr auto psd_matrix = ampm_chat_psd_matrix_##D##d_##S;   \
  };
AMPM_HESS_API(float, 2, f32)
AMPM_HESS_API(float, 3, f32)
AMPM_HESS_API(double, 2, f64)
AMPM_HESS_API(double, 3, f64)
#undef AMPM_HESS_API

constexpr std::uint64_t kSeed = 0x5eed'a3b1'2014'0003ULL;
constexpr double kMu = 3.7;
constexpr ld kTolC = 32;
constexpr ld kAccept = 1e-10L;
// Batch (SIMD) vs single call, ‖batch − single‖_F ≤ kBatchVsSingle·ε·κ·‖Ĉ‖_F‖Z‖_F. Both run
// the same generic source (~10³ operations per particle); they differ only in whether a·b + c
// is rounded once (fused, the SIMD batch) or twice (the scalar single call), ≤ 1 ulp per
// operation, and that perturbation of the intermediate values (F̂, the SVD, the 1/(σᵢ+σⱼ)
// terms) is amplified by at most the κ the accuracy bound above already carries. So the bound
// is derived from the accuracy bound, not measured: the batch and the single call each meet
// ‖x − Ĉ⁺:Z‖ ≤ kTolC·ε·κ·‖Ĉ‖‖Z‖ against the long-double reference (checked below for both),
// hence their distance is at most twice that: K = 2·kTolC.
constexpr ld kBatchVsSingle = 2 * kTolC;

template <int D>
using Big = Eigen::Matrix<ld, D * D, D * D>;

/// Clamped recomposition V max(Λ, 0) Vᵀ of the symmetric part.
template <int D>
Big<D> psd_project(const Big<D>& c) {
  const Big<D> sym = (c + c.transpose()) / 2;
  const Eigen::SelfAdjointEigenSolver<Big<D>> es(sym);
  return es.eigenvectors() * es.eigenvalues().cwiseMax(ld(0)).asDiagonal() *
         es.eigenvectors().transpose();
}

template <int D>
ld min_eigenvalue(const Big<D>& c) {
  const Big<D> sym = (c + c.transpose()) / 2;
  return Eigen::SelfAdjointEigenSolver<Big<D>>(sym, Eigen::EigenvaluesOnly).eigenvalues()(0);
}

template <int D>
ld kappa(const MatL<D>& f) {
  const Eigen::JacobiSVD<MatL<D>> svd(f);
  return svd.singularValues()(0) / svd.singularValues()(D - 1);
}

template <class T, int D>
void check_case(Checker& ck, Rng& rng, const char* family, const MatL<D>& f_exact) {
  using A = HessApi<T, D>;
  constexpr int N = D * D;
  using BigT = Eigen::Matrix<T, N, N>;
  using VecL = Eigen::Matrix<ld, N, 1>;

  const Mat<T, D> f = round_to<T, D>(f_exact);
  const MatL<D> fl = to_ld<T, D>(f);  // exactly the library's input
  const T mu = static_cast<T>(kMu);
  const Reference<D> ref(static_cast<ld>(mu), fl);
  const Big<D> c = ref.chat_tensor();
  const Big<D> p = psd_project<D>(c);
  const ld norm = c.norm();
  const ld tol = kTolC * static_cast<ld>(std::numeric_limits<T>::epsilon()) * kappa<D>(fl);
  auto check_rel = [&](const char* what, ld rel) {
    AMPM_CHECK(ck, rel <= tol, "%s [%s] %s: rel err %.3Le > %.3Le", A::name, family, what, rel,
               tol);
    if (sizeof(T) == 8)
      AMPM_CHECK(ck, rel <= kAccept, "%s [%s] %s: rel err %.3Le > 1e-10", A::name, family, what,
                 rel);
  };

  BigT cm, pm;
  AMPM_CHECK_STATUS(ck, (A::matrix(mu, f.data(), cm.data())), AMPM_OK);
  AMPM_CHECK_STATUS(ck, (A::psd_matrix(mu, f.data(), pm.data())), AMPM_OK);
  const Big<D> cml = cm.template cast<ld>(), pml = pm.template cast<ld>();
  check_rel("chat_matrix vs reference", (cml - c).norm() / norm);
  check_rel("chat_psd_matrix vs projected reference", (pml - p).norm() / norm);
  AMPM_CHECK(ck, (pm == pm.transpose()), "%s [%s]: C+ not exactly symmetric", A::name, family);
  const ld lmin = min_eigenvalue<D>(pml);
  AMPM_CHECK(ck, lmin >= -tol * norm, "%s [%s]: C+ not PSD, min eigenvalue %.3Le", A::name,
             family, lmin);

  for (int k = 0; k < 3; ++k) {
    const Mat<T, D> z = round_to<T, D>(random_z<D>(rng));
    Mat<T, D> out;
    AMPM_CHECK_STATUS(ck, (A::psd_z(mu, f.data(), z.data(), out.data())), AMPM_OK);
    const VecL zv = Reference<D>::vec(to_ld<T, D>(z));
    const VecL ov = Reference<D>::vec(to_ld<T, D>(out));
    check_rel("chat_z_psd vs projected reference", (ov - p * zv).norm() / (norm * zv.norm()));
  }
}

template <class T, int D>
void run(Checker& ck) {
  using A = HessApi<T, D>;
  constexpr int N = D * D;
  using VecS = Eigen::Matrix<ld, D, 1>;
  using VecL = Eigen::Matrix<ld, N, 1>;
  Rng rng(kSeed + 10 * D + sizeof(T));

  check_case<T, D>(ck, rng, "identity", MatL<D>::Identity());
  check_case<T, D>(ck, rng, "conformal", haar_rotation<D>(rng) * ld(1.7));
  for (int i = 0; i < 8; ++i)
    check_case<T, D>(ck, rng, "O(1) strain",
                     random_f_with_sigma<D>(rng, log_uniform_sigma<D>(rng, 0.5, 2.0)));
  for (int i = 0; i < 8; ++i)
    check_case<T, D>(ck, rng, "large strain",
                     random_f_with_sigma<D>(rng, log_uniform_sigma<D>(rng, 0.05, 20.0)));
  if (D == 3) {  // exactly repeated singular values of a non-conformal F
    VecS s = VecS::Constant(2);
    s(D - 1) = 0.25L;
    check_case<T, D>(ck, rng, "repeated", MatL<D>(s.asDiagonal()));
    check_case<T, D>(ck, rng, "repeated", random_f_with_sigma<D>(rng, s));
  }
  for (ld delta : {1e-6L, 1e-12L}) {
    VecS s = log_uniform_sigma<D>(rng, 0.5, 2.0);
    s(1) = s(0) * (1 - delta);
    check_case<T, D>(ck, rng, "near-repeated", random_f_with_sigma<D>(rng, s));
  }

  // The projection matters: at O(1) strain Ĉ has a clearly negative eigenvalue.
  {
    VecS s = VecS::Ones();
    s(0) = 1.5L;
    s(D - 1) = 0.7L;
    const Mat<T, D> f = round_to<T, D>(random_f_with_sigma<D>(rng, s));
    Eigen::Matrix<T, N, N> cm, pm;
    AMPM_CHECK_STATUS(ck, (A::matrix(static_cast<T>(kMu), f.data(), cm.data())), AMPM_OK);
    AMPM_CHECK_STATUS(ck, (A::psd_matrix(static_cast<T>(kMu), f.data(), pm.data())), AMPM_OK);
    const Big<D> cml = cm.template cast<ld>();
    const Eigen::SelfAdjointEigenSolver<Big<D>> es(cml, Eigen::EigenvaluesOnly);
    const ld lmin = es.eigenvalues()(0), lmax = es.eigenvalues()(N - 1);
    AMPM_CHECK(ck, lmin < -1e-3L * lmax, "%s: expected a negative eigenvalue, got %.3Le", A::name,
               lmin);
    // ‖Ĉ⁺ − Ĉ‖_F ≥ |λ_min| (the clamped part), up to rounding.
    AMPM_CHECK(ck, (pm.template cast<ld>() - cml).norm() >= -lmin * (1 - 1e-3L), "%s: C+ = C",
               A::name);
    std::printf("%s: lambda_min/lambda_max of Chat at sigma = (1.5, .., 0.7): %.3Lf\n", A::name,
                lmin / lmax);
  }

  // Batch: particle 2 has a NaN. On the scalar instruction set the others equal the single
  // calls bit for bit; on each SIMD instruction set (fused multiply-add, which the scalar
  // single calls do not use) they are bit-identical across SIMD sets and within twice the
  // accuracy bound of the single calls (see `kBatchVsSingle`).
  {
    const std::size_t n = 4;
    std::vector<T> mus(n, static_cast<T>(kMu)), fs(n * N), zs(n * N);
    for (std::size_t i = 0; i < n; ++i) {
      const Mat<T, D> f =
          round_to<T, D>(random_f_with_sigma<D>(rng, log_uniform_sigma<D>(rng, 0.5, 2.0)));
      const Mat<T, D> z = round_to<T, D>(random_z<D>(rng));
      std::copy(f.data(), f.data() + N, fs.begin() + i * N);
      std::copy(z.data(), z.data() + N, zs.begin() + i * N);
    }
    fs[2 * N + 1] = std::numeric_limits<T>::quiet_NaN();
    std::vector<T> single(n * N, sentinel<T>());
    for (std::size_t i = 0; i < n; ++i)
      if (i != 2)
        AMPM_CHECK_STATUS(ck, (A::psd_z(mus[i], &fs[i * N], &zs[i * N], &single[i * N])),
                          AMPM_OK);
    std::size_t first = 12345;
    auto run_batch = [&](const char* isa) {
      std::vector<T> out(n * N, sentinel<T>());
      first = 12345;
      AMPM_CHECK_STATUS(ck,
                        (A::psd_z_batch(n, mus.data(), fs.data(), zs.data(), out.data(), &first)),
                        AMPM_ERR_NON_FINITE);
      AMPM_CHECK(ck, first == 2, "%s batch (%s): first_failed = %zu, want 2", A::name, isa,
                 first);
      AMPM_CHECK(ck, all_sentinel(out.data() + 2 * N, N), "%s (%s): failed particle written",
                 A::name, isa);
      return out;
    };

    // (a) The scalar instruction set runs the single calls' code: bit for bit.
    {
      const IsaRestore keep;
      AMPM_CHECK_STATUS(ck, ampm_set_isa(AMPM_ISA_SCALAR), AMPM_OK);
      const std::vector<T> out = run_batch("scalar");
      for (std::size_t i = 0; i < n; ++i) {
        if (i == 2) continue;
        AMPM_CHECK(ck, same_bits(&single[i * N], out.data() + i * N, N),
                   "%s: scalar batch != single (%zu)", A::name, i);
      }
    }

    // (b) Every SIMD instruction set of this CPU.
    std::vector<T> simd_first;
    ld worst = 0;  // max ‖batch − single‖_F / (ε·κ·‖Ĉ‖_F‖Z‖_F)
    for (const std::uint32_t isa : simd_isas()) {
      const IsaRestore keep;
      AMPM_CHECK_STATUS(ck, ampm_set_isa(isa), AMPM_OK);
      AMPM_CHECK(ck, ampm_isa() == isa, "ampm_isa() = %u after setting %u", ampm_isa(), isa);
      const std::vector<T> out = run_batch(isa_name(isa));
      if (simd_first.empty())
        simd_first = out;
      else
        AMPM_CHECK(ck, same_bits(simd_first.data(), out.data(), n * N),
                   "%s: batch on %s != batch on %s", A::name, isa_name(isa),
                   isa_name(simd_isas().front()));
      for (std::size_t i = 0; i < n; ++i) {
        if (i == 2) continue;
        const Mat<T, D> fi = Eigen::Map<const Mat<T, D>>(&fs[i * N]);
        const MatL<D> fl = to_ld<T, D>(fi);
        const Reference<D> ref(static_cast<ld>(mus[i]), fl);
        const Big<D> c = ref.chat_tensor();
        const Big<D> p = psd_project<D>(c);
        const ld norm = c.norm();
        const ld k = kappa<D>(fl);
        const ld eps = static_cast<ld>(std::numeric_limits<T>::epsilon());
        const VecL zv = Eigen::Map<const Eigen::Matrix<T, N, 1>>(&zs[i * N]).template cast<ld>();
        const VecL bv = Eigen::Map<const Eigen::Matrix<T, N, 1>>(out.data() + i * N)
                            .template cast<ld>();
        const VecL sv = Eigen::Map<const Eigen::Matrix<T, N, 1>>(&single[i * N])
                            .template cast<ld>();
        // The premise of the bound: batch and single call each meet the accuracy bound.
        const ld tol = kTolC * eps * k;
        const ld rel_b = (bv - p * zv).norm() / (norm * zv.norm());
        const ld rel_s = (sv - p * zv).norm() / (norm * zv.norm());
        AMPM_CHECK(ck, rel_b <= tol, "%s (%s) batch %zu vs projected reference: %.3Le > %.3Le",
                   A::name, isa_name(isa), i, rel_b, tol);
        AMPM_CHECK(ck, rel_s <= tol, "%s single %zu vs projected reference: %.3Le > %.3Le",
                   A::name, i, rel_s, tol);
        const ld ratio = (bv - sv).norm() / (eps * k * norm * zv.norm());
        worst = std::max(worst, ratio);
        AMPM_CHECK(ck, ratio <= kBatchVsSingle,
                   "%s (%s) particle %zu: |batch - single| = %.3Le eps kappa |C||Z| > %.0Le",
                   A::name, isa_name(isa), i, ratio, kBatchVsSingle);
      }
    }
    std::printf("%s: SIMD batch vs single Chat+:Z, worst |diff|/(eps kappa |C||Z|) = %.3Lf "
                "(bound %.0Lf)\n",
                A::name, worst, kBatchVsSingle);

    std::vector<T> out(n * N, sentinel<T>());
    first = 12345;
    AMPM_CHECK_STATUS(ck, (A::psd_z_batch(0, nullptr, nullptr, nullptr, nullptr, &first)),
                      AMPM_OK);
    AMPM_CHECK(ck, first == 0, "%s n = 0: first_failed = %zu", A::name, first);
    AMPM_CHECK_STATUS(ck, (A::psd_z_batch(n, mus.data(), nullptr, zs.data(), out.data(), nullptr)),
                      AMPM_ERR_NULL_POINTER);
  }

  // Errors write nothing.
  {
    Mat<T, D> f = Mat<T, D>::Identity();
    f(0, 0) = T(-1);  // J < 0
    std::vector<T> big(N * N, sentinel<T>());
    AMPM_CHECK_STATUS(ck, (A::matrix(static_cast<T>(kMu), f.data(), big.data())),
                      AMPM_ERR_NON_POSITIVE_J);
    AMPM_CHECK_STATUS(ck, (A::psd_matrix(static_cast<T>(kMu), nullptr, big.data())),
                      AMPM_ERR_NULL_POINTER);
    f(0, 0) = T(1);
    AMPM_CHECK_STATUS(ck, (A::psd_matrix(T(-1), f.data(), big.data())),
                      AMPM_ERR_INVALID_ARGUMENT);
    AMPM_CHECK(ck, all_sentinel(big.data(), big.size()), "%s: output written on error", A::name);
  }
}

}  // namespace

int main() {
  Checker ck;
  run<double, 2>(ck);
  run<double, 3>(ck);
  run<float, 2>(ck);
  run<float, 3>(ck);
  ck.summary("test_hessian_eigen");
  return ck.exit_code();
}
