// The run-time method choice of the C ABI (ffi/src/methods.rs) against an independent
// long-double reference: Eigen's JacobiSVD for the rotation-variant SVD and polar
// decomposition, and common.hpp's `Reference` (the seed's index formulas) for Ψ̂, Â and Ĉ:Z.
//
// For every method of every dimension × precision, on random F = U diag(σ) Vᵀ (σ log-uniform in
// [0.2, 5], the last one negated for half the samples so det F < 0 is covered):
// - ampm_svd_*: status OK, U and V rotations (orthonormal to 16ε per entry, det > 0), |σ| sorted
//   and only the last negative, |σ − σ_ref| ≤ C·ε·σ₀;
// - ampm_polar_*: ‖R − R_ref‖_F ≤ C·ε·κ_R, κ_R = 2σ₀/(σ_{d−2} + σ_{d−1}), S symmetric, RS = F;
// - for det F > 0, ampm_*_ex_*: Ψ̂, Â, Ĉ:Z within C·ε·κ_K of the reference, in the units of
//   tools/src/stability.rs (κ_K = max(κ_R, σ₀/σ_min, ∏‖fⱼ‖/|J|); Â relative to 2μσ̂₀·s_B, Ĉ:Z to
//   2μ‖Z‖·s_B²(1 + 2/(σ̂_{d−2}+σ̂_{d−1})), s_B = Jᵃ(1 + ‖F‖‖F⁻¹‖/d); Ψ̂ to
//   2μσ̂₀(‖σ̂ − 1‖ + εσ̂₀));
// - for det F ≤ 0 the kernels return AMPM_ERR_NON_POSITIVE_J and write nothing;
// - invalid options (unknown method, a 3D method in 2D, sweeps outside 2..8, an iteration cap
//   above 1000) return AMPM_ERR_INVALID_ARGUMENT and write nothing; NULL options = defaults,
//   bit-identical to the plain entry points.
//
// C = 256·√d: the backward error bound of every accurate method (≤ ~40 plane rotations of ≤ 6ε
// each, Higham, Accuracy and Stability, Lemma 19.8, plus the products) times the √d between
// the Frobenius and spectral norms; the same constant as the Rust contracts
// (`ampm_tools::stability::bound`). McAdams is run with 8 sweeps here: with fewer its Jacobi
// iteration on FᵀF has not converged in f64 and it has no ε-level contract.

#include "common.hpp"

#include <vector>

using namespace ampm_test;

namespace {

constexpr std::uint64_t kSeed = 0x5eed'a3b1'2014'0003ULL;
constexpr int kSamples = 300;  // per (dimension, scalar type)

template <class T, int D>
struct MApi;

#define AMPM_METHODS_API(T, D, SUF)                                                              \
  template <>                                                                                 \
  struct MApi<T, D> {                                                           \
    static constexpr const char* name = #SUF;                                                 \
    static AmpmStatus svd(const AmpmOptions* o, const T* f, T* u, T* s, T* v) {               \
      return ampm_svd_##SUF(o, f, u, s, v);                                                   \
    }                                                                                         \
    static AmpmStatus polar(const AmpmOptions* o, const T* f, T* r, T* s) {                   \
      return ampm_polar_##SUF(o, f, r, s);                                                    \
    }                                                                                         \
    static AmpmStatus energy(const AmpmOptions* o, T mu, const T* f, T* out) {                \
      return ampm_energy_hat_ex_##SUF(o, mu, f, out);                                         \
    }                                                                                         \
    static AmpmStatus ahat(const AmpmOptions* o, T mu, const T* f, T* out) {                  \
      return ampm_ahat_ex_##SUF(o, mu, f, out);                                               \
    }                                                                                         \
    static AmpmStatus chat_z(const AmpmOptions* o, T mu, const T* f, const T* z, T* out) {    \
      return ampm_chat_z_ex_##SUF(o, mu, f, z, out);                                          \
    }                                                                                         \
    static AmpmStatus ahat_batch(const AmpmOptions* o, size_t n, const T* mu, const T* f,     \
                                 T* out, size_t* ff) {                                        \
      return ampm_ahat_batch_ex_##SUF(o, n, mu, f, out, ff);                                  \
    }                                                                                         \
    static AmpmStatus ahat_plain(T mu, const T* f, T* out) { return ampm_ahat_##SUF(mu, f, out); } \
  };

AMPM_METHODS_API(float, 2, 2d_f32)
AMPM_METHODS_API(double, 2, 2d_f64)
AMPM_METHODS_API(float, 3, 3d_f32)
AMPM_METHODS_API(double, 3, 3d_f64)

/// The methods accepted in dimension D, with the options used for the accuracy checks.
template <int D>
std::vector<AmpmOptions> methods() {
  if (D == 2) {
    return {AmpmOptions{AMPM_METHOD_DEFAULT, 0, 0}, AmpmOptions{AMPM_METHOD_CLOSED_FORM_2D, 0, 0}};
  }
  return {AmpmOptions{AMPM_METHOD_DEFAULT, 0, 0},
          AmpmOptions{AMPM_METHOD_ONE_SIDED_JACOBI, 0, 0},
          AmpmOptions{AMPM_METHOD_MCADAMS, 8, 0},
          AmpmOptions{AMPM_METHOD_QR, 0, 0},
          AmpmOptions{AMPM_METHOD_HIGHAM_NOFERINI, 0, 0}};
}

/// Rotation-variant SVD of a long-double matrix from Eigen's JacobiSVD (σ ≥ 0 sorted): each
/// improper factor gets its last column negated, which moves a sign onto the last σ.
template <int D>
struct RvSvd {
  MatL<D> u, v;
  Eigen::Matrix<ld, D, 1> sigma;
  explicit RvSvd(const MatL<D>& f) {
    const Eigen::JacobiSVD<MatL<D>> svd(f, Eigen::ComputeFullU | Eigen::ComputeFullV);
    u = svd.matrixU();
    v = svd.matrixV();
    sigma = svd.singularValues();
    if (u.determinant() < 0) {
      u.col(D - 1) = -u.col(D - 1);
      sigma(D - 1) = -sigma(D - 1);
    }
    if (v.determinant() < 0) {
      v.col(D - 1) = -v.col(D - 1);
      sigma(D - 1) = -sigma(D - 1);
    }
  }
  MatL<D> rotation() const { return u * v.transpose(); }
};

template <class T, int D>
struct Suite {
  using A = MApi<T, D>;
  Checker& ck;
  Rng rng;
  const ld eps = std::numeric_limits<T>::epsilon();
  const ld c = 256.0L * std::sqrt(static_cast<ld>(D));

  Suite(Checker& c_, std::uint64_t seed) : ck(c_), rng(seed) {}

  void accuracy() {
    ld worst_sigma = 0, worst_r = 0, worst_k = 0;
    for (int p = 0; p < kSamples; ++p) {
      Eigen::Matrix<ld, D, 1> s = log_uniform_sigma<D>(rng, 0.2, 5.0);
      if (p % 2 == 1) s(D - 1) = -s(D - 1);
      const Mat<T, D> f = round_to<T, D>(random_f_with_sigma<D>(rng, s));
      const MatL<D> fl = to_ld<T, D>(f);
      const Mat<T, D> z = round_to<T, D>(random_z<D>(rng));
      const RvSvd<D> ref(fl);
      const ld s0 = ref.sigma(0);
      const ld kappa_r = 2 * s0 / (ref.sigma(D - 2) + ref.sigma(D - 1));
      const bool positive = fl.determinant() > 0;
      const Reference<D>* kref = positive ? new Reference<D>(1.0L, fl) : nullptr;
      for (const AmpmOptions& o : methods<D>()) {
        // SVD.
        Mat<T, D> u, v;
        Eigen::Matrix<T, D, 1> sg;
        AMPM_CHECK_STATUS(ck, A::svd(&o, f.data(), u.data(), sg.data(), v.data()), AMPM_OK);
        const MatL<D> ul = to_ld<T, D>(u), vl = to_ld<T, D>(v);
        const ld ou = (ul.transpose() * ul - MatL<D>::Identity()).cwiseAbs().maxCoeff();
        const ld ov = (vl.transpose() * vl - MatL<D>::Identity()).cwiseAbs().maxCoeff();
        AMPM_CHECK(ck, ou <= 16 * eps && ov <= 16 * eps && ul.determinant() > 0 && vl.determinant() > 0,
                   "%s method %u: U, V not rotations (%Le %Le), sample %d", A::name, o.method, ou, ov, p);
        for (int i = 0; i + 1 < D; ++i) {
          AMPM_CHECK(ck, sg(i) >= 0 && std::abs(sg(i)) >= std::abs(sg(i + 1)),
                     "%s method %u: sigma not rotation-variant, sample %d", A::name, o.method, p);
        }
        ld es = 0;
        for (int i = 0; i < D; ++i) es = std::max(es, std::abs(static_cast<ld>(sg(i)) - ref.sigma(i)));
        es /= eps * s0;
        worst_sigma = std::max(worst_sigma, es);
        AMPM_CHECK(ck, es <= c, "%s method %u: sigma error %.2Lf eps*sigma0, sample %d", A::name,
                   o.method, es, p);
        // Polar.
        Mat<T, D> r, st;
        AMPM_CHECK_STATUS(ck, A::polar(&o, f.data(), r.data(), st.data()), AMPM_OK);
        const ld er = (to_ld<T, D>(r) - ref.rotation()).norm() / (eps * kappa_r);
        worst_r = std::max(worst_r, er);
        AMPM_CHECK(ck, er <= c, "%s method %u: R error %.2Lf eps*kappa (kappa %.3Le), sample %d",
                   A::name, o.method, er, kappa_r, p);
        const MatL<D> sl = to_ld<T, D>(st);
        AMPM_CHECK(ck, (sl - sl.transpose()).norm() <= 16 * eps * fl.norm() &&
                           (to_ld<T, D>(r) * sl - fl).norm() <= c * eps * fl.norm(),
                   "%s method %u: S not symmetric or RS != F, sample %d", A::name, o.method, p);
        // Kernels.
        T psi = sentinel<T>();
        Mat<T, D> ah, cz;
        ah.fill(sentinel<T>());
        cz.fill(sentinel<T>());
        if (!positive) {
          AMPM_CHECK_STATUS(ck, A::energy(&o, T(1), f.data(), &psi), AMPM_ERR_NON_POSITIVE_J);
          AMPM_CHECK_STATUS(ck, A::ahat(&o, T(1), f.data(), ah.data()), AMPM_ERR_NON_POSITIVE_J);
          AMPM_CHECK_STATUS(ck, A::chat_z(&o, T(1), f.data(), z.data(), cz.data()),
                            AMPM_ERR_NON_POSITIVE_J);
          AMPM_CHECK(ck, psi == sentinel<T>() && all_sentinel(ah.data(), D * D) &&
                             all_sentinel(cz.data(), D * D),
                     "%s method %u: output written on error", A::name, o.method);
          continue;
        }
        AMPM_CHECK_STATUS(ck, A::energy(&o, T(1), f.data(), &psi), AMPM_OK);
        AMPM_CHECK_STATUS(ck, A::ahat(&o, T(1), f.data(), ah.data()), AMPM_OK);
        AMPM_CHECK_STATUS(ck, A::chat_z(&o, T(1), f.data(), z.data(), cz.data()), AMPM_OK);
        const Eigen::Matrix<ld, D, 1> sh = ref.sigma * kref->ja();
        ld colprod = 1;
        for (int j = 0; j < D; ++j) colprod *= fl.col(j).norm();
        const ld kappa_k = std::max({kappa_r, s0 / std::abs(ref.sigma(D - 1)),
                                     colprod / std::abs(fl.determinant())});
        const ld nf = sh.norm();
        ld nh = 0;
        for (int i = 0; i < D; ++i) nh += 1 / (sh(i) * sh(i));
        const ld s_b = kref->ja() * (1 + nf * std::sqrt(nh) / D);
        ld dev = 0;
        for (int i = 0; i < D; ++i) dev += (sh(i) - 1) * (sh(i) - 1);
        const ld e_psi = std::abs(static_cast<ld>(psi) - kref->psi_hat()) /
                         (eps * kappa_k * 2 * sh(0) * (std::sqrt(dev) + eps * sh(0)));
        const ld e_a = (to_ld<T, D>(ah) - kref->ahat()).norm() / (eps * kappa_k * 2 * sh(0) * s_b);
        const MatL<D> zl = to_ld<T, D>(z);
        const ld e_c = (to_ld<T, D>(cz) - kref->chat_z(zl)).norm() /
                       (eps * kappa_k * 2 * zl.norm() * s_b * s_b * (1 + 2 / (sh(D - 2) + sh(D - 1))));
        worst_k = std::max({worst_k, e_psi, e_a, e_c});
        AMPM_CHECK(ck, e_psi <= c && e_a <= c && e_c <= c,
                   "%s method %u: kernel errors psi %.2Lf ahat %.2Lf chat %.2Lf eps*kappa, sample %d",
                   A::name, o.method, e_psi, e_a, e_c, p);
      }
      delete kref;
    }
    std::printf("  %s: worst sigma %.2Lf eps*sigma0, R %.2Lf eps*kappa_R, kernels %.2Lf eps*kappa_K (bound %.0Lf)\n",
                A::name, worst_sigma, worst_r, worst_k, c);
  }

  void options() {
    const MatL<D> fl = random_f_with_sigma<D>(rng, log_uniform_sigma<D>(rng, 0.5, 2.0));
    const Mat<T, D> f = round_to<T, D>(fl);
    std::vector<AmpmOptions> bad = {{6, 0, 0}, {0xffffffffu, 0, 0}, {99, 0, 0}};
    if (D == 2) {
      for (std::uint32_t m : {AMPM_METHOD_ONE_SIDED_JACOBI, AMPM_METHOD_MCADAMS, AMPM_METHOD_QR,
                              AMPM_METHOD_HIGHAM_NOFERINI})
        bad.push_back({m, 0, 0});
    } else {
      bad.push_back({AMPM_METHOD_CLOSED_FORM_2D, 0, 0});
      bad.push_back({AMPM_METHOD_MCADAMS, 1, 0});
      bad.push_back({AMPM_METHOD_MCADAMS, 9, 0});
      bad.push_back({AMPM_METHOD_QR, 0, 1001});
      bad.push_back({AMPM_METHOD_HIGHAM_NOFERINI, 0, 5000});
    }
    for (const AmpmOptions& o : bad) {
      Mat<T, D> u, v, out;
      Eigen::Matrix<T, D, 1> sg;
      u.fill(sentinel<T>());
      v.fill(sentinel<T>());
      out.fill(sentinel<T>());
      sg.fill(sentinel<T>());
      size_t ff = 12345;
      const T mu = 1;
      AMPM_CHECK_STATUS(ck, A::svd(&o, f.data(), u.data(), sg.data(), v.data()),
                        AMPM_ERR_INVALID_ARGUMENT);
      AMPM_CHECK_STATUS(ck, A::ahat(&o, mu, f.data(), out.data()), AMPM_ERR_INVALID_ARGUMENT);
      AMPM_CHECK_STATUS(ck, A::ahat_batch(&o, 1, &mu, f.data(), out.data(), &ff),
                        AMPM_ERR_INVALID_ARGUMENT);
      AMPM_CHECK(ck, all_sentinel(u.data(), D * D) && all_sentinel(v.data(), D * D) &&
                         all_sentinel(sg.data(), D) && all_sentinel(out.data(), D * D),
                 "%s: output written for invalid method %u", A::name, o.method);
    }
    // NULL options: the defaults, bit-identical to the plain entry point.
    Mat<T, D> a, b;
    AMPM_CHECK_STATUS(ck, A::ahat(nullptr, T(2), f.data(), a.data()), AMPM_OK);
    AMPM_CHECK_STATUS(ck, A::ahat_plain(T(2), f.data(), b.data()), AMPM_OK);
    AMPM_CHECK(ck, same_bits(a.data(), b.data(), D * D), "%s: NULL options differ from default",
               A::name);
    // NaN input: refused by every method, nothing written.
    Mat<T, D> g = f;
    g(0, D - 1) = std::numeric_limits<T>::quiet_NaN();
    for (const AmpmOptions& o : methods<D>()) {
      Mat<T, D> r, s;
      r.fill(sentinel<T>());
      s.fill(sentinel<T>());
      AMPM_CHECK_STATUS(ck, A::polar(&o, g.data(), r.data(), s.data()), AMPM_ERR_NON_FINITE);
      AMPM_CHECK(ck, all_sentinel(r.data(), D * D) && all_sentinel(s.data(), D * D),
                 "%s: output written for NaN input", A::name);
    }
  }
};

}  // namespace

int main() {
  Checker ck;
  {
    Suite<double, 3> s(ck, kSeed + 1);
    s.accuracy();
    s.options();
  }
  {
    Suite<float, 3> s(ck, kSeed + 2);
    s.accuracy();
    s.options();
  }
  {
    Suite<double, 2> s(ck, kSeed + 3);
    s.accuracy();
    s.options();
  }
  {
    Suite<float, 2> s(ck, kSeed + 4);
    s.accuracy();
    s.options();
  }
  ck.summary("test_methods_eigen");
  return ck.exit_code();
}
