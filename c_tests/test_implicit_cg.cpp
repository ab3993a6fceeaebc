// One backward-Euler step of an elastic block with conjugate gradients on the prepared force
// differential (ampm_force_prepare_3d_* once per Newton step, ampm_force_apply_3d_* once per
// CG iteration), 3D, f64 and f32, the host owning its grid arrays.
//
// The step (Stomakhin et al. 2013, §4.2; the apply's documentation): P2G gives node masses m_i,
// momenta p_i and stress forces f_i; v*_i = (p_i + Δt f_i)/m_i; then
//   (M − Δt² K) v = M v*,   (A v)_i = m_i v_i − Δt·df_i,   df = apply(du = Δt·v),
// on the nodes with mass (the unknowns; du = 0 elsewhere). With AMPM_MODEL_PSD_HESSIAN the
// stiffness K = ∂f/∂x is symmetric negative semi-definite, so A is symmetric positive definite.
// CG is preconditioned by M (Jacobi on the mass): the preconditioned operator M⁻¹A is
// self-adjoint in the M inner product with spectrum in [1, λ_max].
//
// Asserted (ε of the precision; A_K = 27 stencil nodes; n_add = the most particles sharing a
// node; d = 3):
//   - per particle, the operator G ↦ M_p(G) (node force differential M_p ∇w_i for
//     G = Σ_j du_j ∇w_jᵀ), probed through one-particle applies with du_j = e_a (x_j − x_p)_b
//     (then G = e_a e_bᵀ, since Σ_j ∇w_j (x_j − x_p)ᵀ = I) and read back as
//     M = Σ_i df_i (x_i − x_p)ᵀ: the 9×9 matrix S_p is symmetric and, with the PSD option,
//     negative semi-definite, to c_S·ε·‖S_p‖_F with c_S = 4(A_K + 8d)·2√d (the probe's and the
//     read-back's sums over 27 nodes, |∇w||x_i − x_p| ≤ 2√d, and the apply's ≈ 8d operations);
//   - A symmetric: |⟨u, A w⟩ − ⟨w, A u⟩| ≤ c_g·ε·(Σ_i m_i|u_i||w_i| + Δt² Σ_p ‖S_p‖_F g_p(u)
//     g_p(w)), g_p(u) = Σ_j |u_j||∇w_jp|, c_g = 2(n_add + A_K + 8d + 8), for random u, w;
//   - A positive definite on random u: ⟨u, A u⟩ − ⟨u, M u⟩ = −Δt²⟨u, K u⟩ ≥ −(that bound);
//   - CG's recursive residual reaches ‖r‖_(M⁻¹) ≤ tol·‖b‖_(M⁻¹) (tol 1e-8 in f64, 1e-4 in
//     f32) within k_max = ⌈½√κ ln(2√κ ‖r_0‖/(tol ‖b‖))⌉ iterations (the CG bound
//     ‖r_k‖ ≤ 2√κ ((√κ − 1)/(√κ + 1))^k ‖r_0‖ in the M⁻¹ norm), where κ is bounded above by
//     Gershgorin: λ_max(M⁻¹A) ≤ 1 + Δt² max_i (√d/m_i) Σ_p ‖S_p‖_F |∇w_ip| Σ_j |∇w_jp|; and the
//     true residual ‖b − A v‖ (a fresh apply) is within tol plus the accumulated rounding gap
//     between the recursive and the true residual (Greenbaum 1997), bounded per iteration as in
//     cg() below. In f64 that gap is ≲ 2e-9 and the check is sharp; in f32 at Δt = 20 h/c the
//     worst-case gap reaches ~1 (ε·κ·c_g·iterations), so there the true residual (printed,
//     ~1.1–1.7e-4) is asserted only that loosely: ε·κ ≈ 1e-4 is the floor of an f32 apply.
//   - the linearisation (exact Hessian, no projection) against central differences of the
//     force it linearises, the energy gradient f_i(x̂) = −V⁰ P(F̂) F_Eᵀ ∇w_i at
//     F̂ = (I + δ G_p) F_E, G_p = Σ_j du_j ∇w_jpᵀ (positions, hence stencils, unchanged; F_E in
//     the transposed factor is the prepared one): the host gets τ' = P(F̂) F̂ᵀ of each particle
//     from a one-particle P2G with F_E replaced by F̂ (τ' = −(1/V⁰) Σ_i f_i (x_i − x_p)ᵀ) and
//     assembles f_i(δ) = Σ_p −V⁰ τ'_p (I + δ G_p)⁻ᵀ ∇w_ip. FD(δ) = (f(+δ) − f(−δ))/(2δ):
//     ‖FD(δ) − apply(du)‖ ≤ 2·‖FD(2δ) − FD(δ)‖/3 (twice the Richardson estimate of the O(δ²)
//     truncation error of FD(δ)) + the rounding ‖c_τ·ε·Φ/δ + c_g·ε·Ψ‖, c_τ = 256 + 2√d·A_K
//     (the stress's 256·ε of ‖τ‖ + μ + λ ≤ 3(μ + λ) for these singular values, as in
//     test_particle_eigen.cpp, and the recovery's sum), node scales
//     Φ_i = Σ_p V⁰_p·3(μ + λ)·|∇w_ip| and Ψ_i = Σ_p ‖S_p‖_F g_p(du) |∇w_ip|; checked at strains
//     δ·‖G‖ = (c_τ ε)^(1/3)·2^j, j = 0..3. (The P2G force with F_E replaced, −V⁰ τ' ∇w_i, has
//     the extra first-order geometric term −V⁰ τ Gᵀ ∇w_i, not symmetric in du and not part of
//     the differential; its distance from the apply is printed.)
//   - a large step, Δt = 20× the explicit limit h/c, repeated: no NaN, J_E > 0, every CG
//     converges within its bound, and the mechanical energy E = Σ_p ½ m |v|² + V⁰ (Ψ̂_μ + Ψ_λ)
//     never exceeds its initial value: backward Euler with a definite stiffness is dissipative
//     (the linear step is a contraction in the energy norm), so energy cannot grow (the kinetic
//     energy grows only by taking the elastic energy the block starts with). An explicit step at
//     the same Δt is printed for contrast, not asserted.
#include "common.hpp"

#include <algorithm>
#include <array>
#include <vector>

using namespace ampm_test;

namespace {

template <class T>
using Api3 = ampm_test::PartApi<T, 3>;

constexpr int D = 3;
constexpr int K1 = 3;   // quadratic: 3 nodes per axis
constexpr int KD = 27;  // stencil nodes
constexpr std::size_t SL = AMPM_FORCE_SLOT_LEN_3D;
constexpr std::uint64_t kSeed = 0xc9a3'b1e0'2013'0402ULL;

using Vec3L = Eigen::Matrix<ld, 3, 1>;
using Mat9L = Eigen::Matrix<ld, 9, 9>;

/// The host's particles (SoA, the C layout).
template <class T>
struct Parts {
  std::size_t n = 0;
  std::vector<T> x, v, c, fe, fp, m, v0;
  typename Api3<T>::Particles view() {
    return {x.data(), v.data(), c.data(), fe.data(), fp.data(), m.data(), v0.data(),
            nullptr, nullptr, nullptr};
  }
};

/// The host's grid: a node box and dense x-fastest arrays.
template <class T>
struct Grid {
  std::array<int, 3> lo{}, dims{};
  std::size_t count = 0;
  std::vector<T> mass;
  std::array<std::vector<T>, 3> mom, force, vstar;
  void reset(const int* l, const int* h) {
    count = 1;
    for (int a = 0; a < 3; ++a) lo[a] = l[a], dims[a] = h[a] - l[a] + 1, count *= dims[a];
    mass.assign(count, 0);
    for (int a = 0; a < 3; ++a) mom[a].assign(count, 0), force[a].assign(count, 0), vstar[a].assign(count, 0);
  }
  std::ptrdiff_t stride(int a) const {
    return a == 0 ? 1 : a == 1 ? dims[0] : static_cast<std::ptrdiff_t>(dims[0]) * dims[1];
  }
  AmpmNodeBox box() const {
    AmpmNodeBox b;
    for (int a = 0; a < 3; ++a) b.lo[a] = lo[a], b.dims[a] = dims[a];
    return b;
  }
  std::size_t at(const int* i) const {
    return static_cast<std::size_t>(i[0] - lo[0]) +
           dims[0] * (static_cast<std::size_t>(i[1] - lo[1]) + dims[1] * static_cast<std::size_t>(i[2] - lo[2]));
  }
  typename Api3<T>::Channel out(T* p) const {
    typename Api3<T>::Channel c;
    c.data = p;
    for (int a = 0; a < 3; ++a) c.stride[a] = stride(a);
    return c;
  }
  typename Api3<T>::ConstChannel in(const T* p) const {
    typename Api3<T>::ConstChannel c;
    c.data = p;
    for (int a = 0; a < 3; ++a) c.stride[a] = stride(a);
    return c;
  }
};

using Field = std::array<std::vector<ld>, 3>;  // a host vector over the box, long double

template <class T>
struct Setup {
  ld mu = 2e4, lambda = 3e4, rho = 1000, h = 0.1;
  int per_axis = 8;
};

template <class T>
typename Api3<T>::Material material(const Setup<T>& s, bool psd) {
  typename Api3<T>::Material m{};
  m.model = psd ? AMPM_MODEL_PSD_HESSIAN : 0;
  m.solid.mu = static_cast<T>(s.mu);
  m.solid.inv_lambda = static_cast<T>(1 / s.lambda);
  m.solid.heat_capacity = 1;
  m.liquid.inv_lambda = static_cast<T>(1 / s.lambda);
  m.liquid.heat_capacity = 1;
  return m;
}

/// Everything the host computes about one step's grid and stencils.
template <class T>
struct Step {
  Grid<T> g;
  std::vector<int> base;
  std::vector<T> w, gw;  // weights and gradients (ampm_stencil)
  std::vector<std::size_t> nodes;  // linear grid index of stencil node r of particle i at [27 i + r]
  std::vector<ld> gnorm;           // |∇w_ip| at [27 i + r]
  std::vector<char> active;
  int n_add = 0;
  std::vector<T> slots;      // prepared (PSD or exact, see prepare())
  std::vector<ld> s_norm;    // ‖S_p‖_F
  std::vector<Mat9L> s_mat;  // S_p
};

template <class T>
class Host {
 public:
  using A = Api3<T>;
  Host(Checker& ck, const Setup<T>& s, Parts<T>& p) : ck_(ck), s_(s), p_(p) {}

  /// P2G at the current state into a fresh box; stencils; active nodes; v* for step dt.
  void p2g(Step<T>& st, T dt) {
    const std::size_t n = p_.n;
    int lo[3], hi[3];
    std::size_t ff = 0;
    AMPM_CHECK_STATUS(ck_, A::node_range(AMPM_KERNEL_QUADRATIC, AMPM_GRID_COLLOCATED, h(), n, p_.x.data(), lo, hi, &ff),
                      AMPM_OK);
    st.g.reset(lo, hi);
    st.base.assign(n * D, 0), st.w.assign(n * KD, 0), st.gw.assign(n * KD * D, 0);
    AMPM_CHECK_STATUS(ck_, A::stencil(AMPM_KERNEL_QUADRATIC, AMPM_GRID_COLLOCATED, h(), n, p_.x.data(), st.base.data(),
                                      st.w.data(), st.gw.data(), &ff),
                      AMPM_OK);
    st.nodes.assign(n * KD, 0);
    st.gnorm.assign(n * KD, 0);
    for (std::size_t i = 0; i < n; ++i)
      for (int r = 0; r < KD; ++r) {
        int idx[3];
        for (int a = 0, q = r; a < 3; ++a, q /= K1) idx[a] = st.base[3 * i + a] + q % K1;
        st.nodes[KD * i + r] = st.g.at(idx);
        st.gnorm[KD * i + r] = grad(st, i, r).norm();
      }
    std::vector<int> share(st.g.count, 0);
    st.n_add = 0;
    for (std::size_t i = 0; i < n; ++i)
      for (int r = 0; r < KD; ++r) st.n_add = std::max(st.n_add, ++share[node(st, i, r)]);
    typename A::P2gView v{};
    v.nodes = st.g.box();
    v.mass = st.g.out(st.g.mass.data());
    for (int a = 0; a < 3; ++a) v.momentum[a] = st.g.out(st.g.mom[a].data()), v.force[a] = st.g.out(st.g.force[a].data());
    const auto mat = material(s_, true);
    auto pv = p_.view();
    ff = 0;
    AMPM_CHECK_STATUS(ck_, A::p2g(&mat, AMPM_KERNEL_QUADRATIC, AMPM_GRID_COLLOCATED, h(), T(0), n, &pv, &v, &ff), AMPM_OK);
    AMPM_CHECK(ck_, ff == n, "%s p2g first_failed %zu", A::name, ff);
    st.active.assign(st.g.count, 0);
    for (std::size_t k = 0; k < st.g.count; ++k) {
      st.active[k] = st.g.mass[k] > 0;
      for (int a = 0; a < 3; ++a)
        st.g.vstar[a][k] = st.active[k] ? (st.g.mom[a][k] + dt * st.g.force[a][k]) / st.g.mass[k] : T(0);
    }
  }

  /// Grid index (linear) of stencil node r of particle i.
  std::size_t node(const Step<T>& st, std::size_t i, int r) const { return st.nodes[KD * i + r]; }
  /// x_i − x_p of stencil node r of particle i (long double).
  Vec3L dx(const Step<T>& st, std::size_t i, int r) const {
    Vec3L d;
    for (int a = 0, q = r; a < 3; ++a, q /= K1)
      d(a) = static_cast<ld>(st.base[3 * i + a] + q % K1) * static_cast<ld>(h()) - static_cast<ld>(p_.x[3 * i + a]);
    return d;
  }
  Vec3L grad(const Step<T>& st, std::size_t i, int r) const {
    Vec3L g;
    for (int a = 0; a < 3; ++a) g(a) = st.gw[(KD * i + r) * 3 + a];
    return g;
  }

  /// Prepares the slots (PSD or exact) and probes every particle's operator S_p.
  void prepare(Step<T>& st, bool psd) {
    const std::size_t n = p_.n;
    const auto mat = material(s_, psd);
    auto pv = p_.view();
    st.slots.assign(n * SL, 0);
    std::size_t ff = 0;
    AMPM_CHECK_STATUS(ck_, A::prepare(&mat, n, &pv, st.slots.data(), &ff), AMPM_OK);
    AMPM_CHECK(ck_, ff == n, "%s prepare first_failed %zu", A::name, ff);
    st.s_norm.assign(n, 0);
    st.s_mat.assign(n, Mat9L::Zero());
    const ld eps = std::numeric_limits<T>::epsilon();
    const ld c_s = 4 * (KD + 8 * D) * 2 * std::sqrt(ld(D));
    std::array<std::vector<T>, 3> du, df;
    for (int a = 0; a < 3; ++a) du[a].assign(KD, 0), df[a].assign(KD, 0);
    for (std::size_t i = 0; i < n; ++i) {
      typename A::ForceView fv{};
      for (int a = 0; a < 3; ++a) fv.nodes.lo[a] = st.base[3 * i + a], fv.nodes.dims[a] = K1;
      for (int a = 0; a < 3; ++a) {
        fv.du[a].data = du[a].data();
        fv.df[a].data = df[a].data();
        fv.du[a].stride[0] = fv.df[a].stride[0] = 1;
        fv.du[a].stride[1] = fv.df[a].stride[1] = K1;
        fv.du[a].stride[2] = fv.df[a].stride[2] = K1 * K1;
      }
      Mat9L s;
      for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 3; ++b) {
          for (int c = 0; c < 3; ++c)
            for (int r = 0; r < KD; ++r) {
              du[c][r] = c == a ? static_cast<T>(dx(st, i, r)(b)) : T(0);
              df[c][r] = 0;
            }
          std::size_t f1 = 0;
          AMPM_CHECK_STATUS(ck_, A::apply(AMPM_KERNEL_QUADRATIC, h(), 1, p_.x.data() + 3 * i, st.slots.data() + SL * i, &fv, &f1),
                            AMPM_OK);
          MatL<3> m = MatL<3>::Zero();
          for (int r = 0; r < KD; ++r) {
            Vec3L f;
            for (int c = 0; c < 3; ++c) f(c) = df[c][r];
            m += f * dx(st, i, r).transpose();
          }
          for (int k = 0; k < 9; ++k) s(k, a + 3 * b) = m.data()[k];
        }
      st.s_mat[i] = s;
      st.s_norm[i] = s.norm();
      const ld tol = c_s * eps * s.norm();
      AMPM_CHECK(ck_, (s - s.transpose()).norm() <= tol, "%s particle %zu: operator asymmetry %.3Le (tol %.3Le)", A::name, i,
                 (s - s.transpose()).norm(), tol);
      if (psd) {
        const ld top = Eigen::SelfAdjointEigenSolver<Mat9L>((s + s.transpose()) / 2, Eigen::EigenvaluesOnly).eigenvalues()(8);
        AMPM_CHECK(ck_, top <= tol, "%s particle %zu: PSD operator has eigenvalue %.3Le > %.3Le", A::name, i, top, tol);
      }
    }
  }

  /// df = apply(du) over the box (du, df in T, zeroed df first).
  void apply(const Step<T>& st, const std::array<std::vector<T>, 3>& du, std::array<std::vector<T>, 3>& df) {
    typename A::ForceView fv{};
    fv.nodes = st.g.box();
    for (int a = 0; a < 3; ++a) {
      std::fill(df[a].begin(), df[a].end(), T(0));
      fv.du[a] = st.g.in(du[a].data());
      fv.df[a] = st.g.out(df[a].data());
    }
    std::size_t ff = 0;
    AMPM_CHECK_STATUS(ck_, A::apply(AMPM_KERNEL_QUADRATIC, h(), p_.n, p_.x.data(), st.slots.data(), &fv, &ff), AMPM_OK);
    AMPM_CHECK(ck_, ff == p_.n, "%s apply first_failed %zu", A::name, ff);
  }

  /// (A v)_i = m_i v_i − Δt·apply(Δt v)_i on the active nodes (0 elsewhere); v in T.
  void op(const Step<T>& st, T dt, const std::array<std::vector<T>, 3>& v, std::array<std::vector<T>, 3>& out) {
    std::array<std::vector<T>, 3> du, df;
    for (int a = 0; a < 3; ++a) {
      du[a].assign(st.g.count, 0);
      df[a].assign(st.g.count, 0);
      for (std::size_t k = 0; k < st.g.count; ++k) du[a][k] = st.active[k] ? dt * v[a][k] : T(0);
    }
    apply(st, du, df);
    for (int a = 0; a < 3; ++a) {
      out[a].assign(st.g.count, 0);
      for (std::size_t k = 0; k < st.g.count; ++k)
        out[a][k] = st.active[k] ? st.g.mass[k] * v[a][k] - dt * df[a][k] : T(0);
    }
  }

  /// g_p(u) = Σ_j |u_j||∇w_jp| per particle.
  std::vector<ld> gabs(const Step<T>& st, const std::array<std::vector<T>, 3>& u) const {
    std::vector<ld> un(st.g.count), out(p_.n, 0);
    for (std::size_t k = 0; k < st.g.count; ++k) un[k] = Vec3L(u[0][k], u[1][k], u[2][k]).norm();
    for (std::size_t i = 0; i < p_.n; ++i)
      for (int r = 0; r < KD; ++r) out[i] += un[node(st, i, r)] * st.gnorm[KD * i + r];
    return out;
  }

  /// Gershgorin bound on κ(M⁻¹A).
  ld kappa_bound(const Step<T>& st, T dt) const {
    std::vector<ld> row(st.g.count, 0);
    for (std::size_t i = 0; i < p_.n; ++i) {
      ld g1 = 0;
      for (int r = 0; r < KD; ++r) g1 += grad(st, i, r).norm();
      for (int r = 0; r < KD; ++r) row[node(st, i, r)] += st.s_norm[i] * grad(st, i, r).norm() * g1;
    }
    ld worst = 0;
    for (std::size_t k = 0; k < st.g.count; ++k)
      if (st.active[k]) worst = std::max(worst, std::sqrt(ld(D)) * row[k] / st.g.mass[k]);
    return 1 + static_cast<ld>(dt) * dt * worst;
  }

  /// Preconditioned CG for A v = M v*, v starting at v*. Returns the iterations; v gets the
  /// solution; asserts convergence within the bound.
  int cg(const Step<T>& st, T dt, ld tol, std::array<std::vector<T>, 3>& v, const char* what) {
    const std::size_t nc = st.g.count;
    const auto& m = st.g.mass;
    std::array<std::vector<T>, 3> b, r, z, pd, ap;
    for (int a = 0; a < 3; ++a) {
      b[a].assign(nc, 0);
      v[a] = st.g.vstar[a];
      for (std::size_t k = 0; k < nc; ++k) b[a][k] = st.active[k] ? m[k] * st.g.vstar[a][k] : T(0);
    }
    auto mdot = [&](const std::array<std::vector<T>, 3>& x, const std::array<std::vector<T>, 3>& y) {
      ld s = 0;
      for (int a = 0; a < 3; ++a)
        for (std::size_t k = 0; k < nc; ++k)
          if (st.active[k]) s += static_cast<ld>(x[a][k]) * y[a][k];
      return s;
    };
    auto inv_m_norm = [&](const std::array<std::vector<T>, 3>& x) {  // ‖x‖_(M⁻¹)
      ld s = 0;
      for (int a = 0; a < 3; ++a)
        for (std::size_t k = 0; k < nc; ++k)
          if (st.active[k]) s += static_cast<ld>(x[a][k]) * x[a][k] / m[k];
      return std::sqrt(s);
    };
    op(st, dt, v, ap);
    for (int a = 0; a < 3; ++a) {
      r[a].assign(nc, 0), z[a].assign(nc, 0);
      for (std::size_t k = 0; k < nc; ++k)
        if (st.active[k]) r[a][k] = b[a][k] - ap[a][k], z[a][k] = r[a][k] / m[k];
    }
    pd = z;
    ld rz = mdot(r, z);
    const ld bn = inv_m_norm(b), r0 = inv_m_norm(r);
    const ld kappa = kappa_bound(st, dt);
    const int k_max = static_cast<int>(std::ceil(0.5L * std::sqrt(kappa) *
                                                 std::log(std::max<ld>(2 * std::sqrt(kappa) * r0 / (tol * bn), 1))));
    // The gap between the recursive residual r_k and the true b − A v_k grows by the rounding
    // of each iteration's updates (Greenbaum 1997): in the M⁻¹ norm at most
    // ε (c_g ‖σ(α p)‖ + ‖r‖ + ‖α A p‖ + 2‖σ(v)‖), σ(u)_i = m_i|u_i| + Δt² Σ_p ‖S_p‖_F g_p(u)
    // |∇w_ip| the node scale of (A u)_i's rounding (c_g·ε relative, see the file comment).
    const ld eps = std::numeric_limits<T>::epsilon();
    const ld c_g = 2 * (st.n_add + KD + 8 * D + 8);
    auto sigma_norm = [&](const std::array<std::vector<T>, 3>& u, ld scale) {
      const std::vector<ld> gu = gabs(st, u);
      std::vector<ld> sig(nc, 0);
      for (std::size_t k = 0; k < nc; ++k)
        if (st.active[k]) sig[k] = static_cast<ld>(m[k]) * Vec3L(u[0][k], u[1][k], u[2][k]).norm();
      const ld dt2 = static_cast<ld>(dt) * dt;
      for (std::size_t i = 0; i < p_.n; ++i)
        for (int r2 = 0; r2 < KD; ++r2) sig[node(st, i, r2)] += dt2 * st.s_norm[i] * gu[i] * st.gnorm[KD * i + r2];
      ld q = 0;
      for (std::size_t k = 0; k < nc; ++k)
        if (st.active[k]) q += sig[k] * sig[k] / m[k];
      return std::fabs(scale) * std::sqrt(q);
    };
    ld gap = c_g * eps * sigma_norm(v, 1);
    int it = 0;
    while (inv_m_norm(r) > tol * bn && it < 4 * k_max + 10) {
      op(st, dt, pd, ap);
      const ld alpha = rz / mdot(pd, ap);
      gap += eps * (c_g * sigma_norm(pd, alpha) + inv_m_norm(r) + std::fabs(alpha) * inv_m_norm(ap));
      for (int a = 0; a < 3; ++a)
        for (std::size_t k = 0; k < nc; ++k)
          if (st.active[k]) {
            v[a][k] += static_cast<T>(alpha * pd[a][k]);
            r[a][k] -= static_cast<T>(alpha * ap[a][k]);
            z[a][k] = r[a][k] / m[k];
          }
      gap += 2 * eps * sigma_norm(v, 1);
      const ld rz_new = mdot(r, z);
      const ld beta = rz_new / rz;
      rz = rz_new;
      for (int a = 0; a < 3; ++a)
        for (std::size_t k = 0; k < nc; ++k)
          if (st.active[k]) pd[a][k] = static_cast<T>(z[a][k] + beta * pd[a][k]);
      ++it;
    }
    // The true residual with a fresh apply (its own rounding is in `gap`'s first term).
    op(st, dt, v, ap);
    std::array<std::vector<T>, 3> res;
    for (int a = 0; a < 3; ++a) {
      res[a].assign(nc, 0);
      for (std::size_t k = 0; k < nc; ++k)
        if (st.active[k]) res[a][k] = static_cast<T>(static_cast<ld>(b[a][k]) - ap[a][k]);
    }
    const ld rel = inv_m_norm(res) / bn;
    std::printf("  %s %s: CG %d iterations (bound %d, κ ≤ %.3Lg), relative residual %.3Le (tol %.0Le, rounding gap ≤ %.2Le)\n",
                A::name, what, it, k_max, kappa, rel, tol, gap / bn);
    AMPM_CHECK(ck_, it <= k_max, "%s %s: CG took %d iterations, bound %d", A::name, what, it, k_max);
    AMPM_CHECK(ck_, rel <= tol + gap / bn, "%s %s: true relative residual %.3Le > %.3Le", A::name, what, rel, tol + gap / bn);
    return it;
  }

  /// G2P with grid velocities v.
  void g2p(const Step<T>& st, T dt, const std::array<std::vector<T>, 3>& v) {
    typename A::G2pView gv{};
    gv.nodes = st.g.box();
    for (int a = 0; a < 3; ++a) gv.velocity[a] = st.g.in(v[a].data());
    const auto mat = material(s_, true);
    auto pv = p_.view();
    std::size_t ff = 0;
    AMPM_CHECK_STATUS(ck_, A::g2p(&mat, AMPM_KERNEL_QUADRATIC, h(), dt, p_.n, &pv, &gv, &ff), AMPM_OK);
    AMPM_CHECK(ck_, ff == p_.n, "%s g2p first_failed %zu", A::name, ff);
  }

  /// Σ_p ½ m |v|² and Σ_p V⁰ (Ψ̂_μ + Ψ_λ) (common.hpp's long-double reference).
  std::pair<ld, ld> energy() const {
    ld ke = 0, pe = 0;
    for (std::size_t i = 0; i < p_.n; ++i) {
      ld v2 = 0;
      for (int a = 0; a < 3; ++a) v2 += static_cast<ld>(p_.v[3 * i + a]) * p_.v[3 * i + a];
      ke += 0.5L * p_.m[i] * v2;
      MatL<3> f;
      for (int k = 0; k < 9; ++k) f.data()[k] = p_.fe[9 * i + k];
      const ld j = f.determinant();
      pe += static_cast<ld>(p_.v0[i]) * (Reference<3>(s_.mu, f).psi_hat() + s_.lambda / 2 * (j - 1) * (j - 1));
    }
    return {ke, pe};
  }

  T h() const { return static_cast<T>(s_.h); }

 private:
  Checker& ck_;
  const Setup<T>& s_;
  Parts<T>& p_;
};

/// A block of per_axis³ particles at spacing h/2, F_E with singular values log-uniform in
/// [0.85, 1.15] between Haar rotations (the exact Hessian is indefinite for many of them), a
/// rotation plus a random part of the velocity.
template <class T>
void make_block(const Setup<T>& s, Parts<T>& p, Rng& rng) {
  const int na = s.per_axis;
  p.n = static_cast<std::size_t>(na) * na * na;
  p.x.assign(3 * p.n, 0), p.v.assign(3 * p.n, 0), p.c.assign(9 * p.n, 0);
  p.fe.assign(9 * p.n, 0), p.fp.assign(9 * p.n, 0), p.m.assign(p.n, 0), p.v0.assign(p.n, 0);
  const ld sp = s.h / 2;
  for (std::size_t i = 0; i < p.n; ++i) {
    const int idx[3] = {static_cast<int>(i % na), static_cast<int>((i / na) % na), static_cast<int>(i / (na * na))};
    Vec3L r;
    for (int a = 0; a < 3; ++a) {
      const ld x = 0.2L + sp * (idx[a] + 0.5L) + 0.2L * sp * rng.uniform(-1, 1);
      p.x[3 * i + a] = static_cast<T>(x);
      r(a) = x - (0.2L + sp * na / 2);
    }
    const Vec3L om(0.5L, -1.0L, 0.7L);
    const Vec3L v = om.cross(r);
    for (int a = 0; a < 3; ++a) p.v[3 * i + a] = static_cast<T>(v(a) + 0.05L * rng.uniform(-1, 1));
    const MatL<3> fe = random_f_with_sigma<3>(rng, log_uniform_sigma<3>(rng, 0.85, 1.15));
    for (int k = 0; k < 9; ++k) p.fe[9 * i + k] = static_cast<T>(fe.data()[k]);
    for (int a = 0; a < 3; ++a) p.fp[9 * i + 4 * a] = 1;
    p.v0[i] = static_cast<T>(sp * sp * sp);
    p.m[i] = static_cast<T>(s.rho * sp * sp * sp);
  }
}

template <class T>
void run(Checker& ck) {
  using A = Api3<T>;
  const ld eps = std::numeric_limits<T>::epsilon();
  const ld tol = sizeof(T) == 8 ? 1e-8L : 1e-4L;
  Setup<T> s;
  Rng rng(kSeed);
  Parts<T> p;
  make_block<T>(s, p, rng);
  Host<T> host(ck, s, p);
  const ld wave = std::sqrt((s.lambda + 2 * s.mu) / s.rho);
  const ld dt_cfl = s.h / wave;
  const T dt = static_cast<T>(4 * dt_cfl);
  const ld c_g_base = 8 + KD + 8 * D;

  Step<T> st;
  host.p2g(st, dt);
  const std::size_t nc = st.g.count;
  const ld c_g = 2 * (st.n_add + c_g_base);

  // ---- the PSD operator: symmetric, positive definite ----
  host.prepare(st, true);
  for (int trial = 0; trial < 6; ++trial) {
    std::array<std::vector<T>, 3> u, w, au, aw;
    for (int a = 0; a < 3; ++a) {
      u[a].assign(nc, 0), w[a].assign(nc, 0);
      for (std::size_t k = 0; k < nc; ++k)
        if (st.active[k]) u[a][k] = static_cast<T>(rng.uniform(-1, 1)), w[a][k] = static_cast<T>(rng.uniform(-1, 1));
    }
    host.op(st, dt, u, au);
    host.op(st, dt, w, aw);
    ld uaw = 0, wau = 0, uau = 0, umu = 0, mass_term = 0, mass_uu = 0;
    for (int a = 0; a < 3; ++a)
      for (std::size_t k = 0; k < nc; ++k) {
        uaw += static_cast<ld>(u[a][k]) * aw[a][k];
        wau += static_cast<ld>(w[a][k]) * au[a][k];
        uau += static_cast<ld>(u[a][k]) * au[a][k];
        umu += static_cast<ld>(st.g.mass[k]) * u[a][k] * u[a][k];
        mass_term += std::fabs(static_cast<ld>(st.g.mass[k]) * u[a][k] * w[a][k]);
        mass_uu += std::fabs(static_cast<ld>(st.g.mass[k]) * u[a][k] * u[a][k]);
      }
    const std::vector<ld> gu = host.gabs(st, u), gw = host.gabs(st, w);
    ld stiff = 0, stiff_uu = 0;
    for (std::size_t i = 0; i < p.n; ++i) stiff += st.s_norm[i] * gu[i] * gw[i], stiff_uu += st.s_norm[i] * gu[i] * gu[i];
    const ld dt2 = static_cast<ld>(dt) * dt;
    const ld tol_sym = c_g * eps * (mass_term + dt2 * stiff);
    AMPM_CHECK(ck, std::fabs(uaw - wau) <= tol_sym, "%s: <u,Aw> = %.15Le, <w,Au> = %.15Le (tol %.3Le)", A::name, uaw, wau,
               tol_sym);
    const ld tol_pd = c_g * eps * (mass_uu + dt2 * stiff_uu);
    AMPM_CHECK(ck, uau - umu >= -tol_pd, "%s: <u,Au> − <u,Mu> = %.6Le < 0 (tol %.3Le)", A::name, uau - umu, tol_pd);
    AMPM_CHECK(ck, uau > 0, "%s: <u,Au> = %.6Le not positive", A::name, uau);
  }

  // ---- CG on the backward-Euler system ----
  std::array<std::vector<T>, 3> vnew;
  host.cg(st, dt, tol, vnew, "Δt = 4 h/c");

  // ---- the linearisation against central differences of the P2G force (exact Hessian) ----
  {
    Step<T> ex = st;
    host.prepare(ex, false);
    std::array<std::vector<T>, 3> du, df;
    for (int a = 0; a < 3; ++a) {
      du[a].assign(nc, 0), df[a].assign(nc, 0);
      for (std::size_t k = 0; k < nc; ++k)
        if (st.active[k]) du[a][k] = static_cast<T>(rng.uniform(-1, 1) * 1e-3);
    }
    host.apply(ex, du, df);
    // G_p and the perturbed P2G forces.
    std::vector<MatL<3>> g(p.n);
    ld gmax = 0;
    for (std::size_t i = 0; i < p.n; ++i) {
      g[i].setZero();
      for (int r = 0; r < KD; ++r) {
        const std::size_t k = host.node(st, i, r);
        g[i] += Vec3L(du[0][k], du[1][k], du[2][k]) * host.grad(st, i, r).transpose();
      }
      gmax = std::max(gmax, g[i].norm());
    }
    // The function the differential linearises is the energy gradient at x̂ = x + δ du:
    // f_i(δ) = −V⁰ P((I + δG) F_E) F_Eᵀ ∇w_i (F_E in the transposed factor stays the prepared
    // one; implicit.rs, Stomakhin et al. 2013 eq. 6–7), which is symmetric in du. P2G of a
    // particle whose F_E is replaced by F' = (I + δG) F_E returns −V⁰ τ' ∇w_i with
    // τ' = P(F') F'ᵀ, so the host recovers τ' from a one-particle P2G (τ' = −(1/V⁰) Σ_i f_i
    // (x_i − x_p)ᵀ, since Σ_i ∇w_i (x_i − x_p)ᵀ = I) and assembles
    // f_i(δ) = Σ_p −V⁰ τ'_p (I + δ G_p)⁻ᵀ ∇w_ip in long double. (The P2G force itself,
    // f_i = −V⁰ τ' ∇w_i, differs at first order by the geometric term −V⁰ τ Gᵀ ∇w_i, which is
    // not symmetric in du; its size is printed below.)
    // δ: a strain δ·‖G‖ = (c_τ ε)^(1/3), balancing the O(δ²) truncation and the c_τ·ε/δ
    // rounding of the central difference (c_τ = 256 + 2√d·A_K: the stress's rounding and the
    // recovery's sum over 27 nodes).
    const ld c_tau = 256 + 2 * std::sqrt(ld(D)) * KD;
    const ld delta = std::cbrt(c_tau * eps) / gmax;
    std::vector<T> fs[3];
    for (int a = 0; a < 3; ++a) fs[a].assign(KD, 0);
    auto tau_of = [&](Parts<T>& q, std::size_t i) {
      typename A::P2gView one{};
      for (int a = 0; a < 3; ++a) {
        one.nodes.lo[a] = st.base[3 * i + a], one.nodes.dims[a] = K1;
        std::fill(fs[a].begin(), fs[a].end(), T(0));
        one.force[a].data = fs[a].data();
        one.force[a].stride[0] = 1, one.force[a].stride[1] = K1, one.force[a].stride[2] = K1 * K1;
      }
      typename A::Particles pi = q.view();
      pi.x += 3 * i, pi.v += 3 * i, pi.affine += 9 * i, pi.f_e += 9 * i, pi.f_p += 9 * i, pi.mass += i, pi.volume0 += i;
      const auto mat = material(s, false);
      std::size_t ff = 0;
      AMPM_CHECK_STATUS(ck, A::p2g(&mat, AMPM_KERNEL_QUADRATIC, AMPM_GRID_COLLOCATED, host.h(), T(0), 1, &pi, &one, &ff), AMPM_OK);
      MatL<3> tau = MatL<3>::Zero();
      for (int r = 0; r < KD; ++r) tau -= Vec3L(fs[0][r], fs[1][r], fs[2][r]) * host.dx(st, i, r).transpose() / static_cast<ld>(p.v0[i]);
      return tau;
    };
    // energy: the energy gradient; raw: the P2G force −V⁰ τ' ∇w_i.
    auto force_at = [&](ld d, Field& energy, Field& raw) {
      Parts<T> q = p;
      for (std::size_t i = 0; i < p.n; ++i) {
        MatL<3> fe;
        for (int k = 0; k < 9; ++k) fe.data()[k] = p.fe[9 * i + k];
        const MatL<3> f2 = (MatL<3>::Identity() + d * g[i]) * fe;
        for (int k = 0; k < 9; ++k) q.fe[9 * i + k] = static_cast<T>(f2.data()[k]);
      }
      for (int a = 0; a < 3; ++a) energy[a].assign(nc, 0), raw[a].assign(nc, 0);
      for (std::size_t i = 0; i < p.n; ++i) {
        const MatL<3> tau = tau_of(q, i);
        const MatL<3> m_energy = -static_cast<ld>(p.v0[i]) * tau * (MatL<3>::Identity() + d * g[i]).inverse().transpose();
        const MatL<3> m_raw = -static_cast<ld>(p.v0[i]) * tau;
        for (int r = 0; r < KD; ++r) {
          const std::size_t k = host.node(st, i, r);
          const Vec3L fe = m_energy * host.grad(st, i, r), fr = m_raw * host.grad(st, i, r);
          for (int a = 0; a < 3; ++a) energy[a][k] += fe(a), raw[a][k] += fr(a);
        }
      }
    };
    // Node scales of the rounding.
    std::vector<ld> phi(nc, 0), psi(nc, 0);
    const std::vector<ld> gd = host.gabs(ex, du);
    for (std::size_t i = 0; i < p.n; ++i)
      for (int r = 0; r < KD; ++r) {
        const std::size_t k = host.node(st, i, r);
        const ld gn = host.grad(st, i, r).norm();
        phi[k] += static_cast<ld>(p.v0[i]) * 3 * (s.mu + s.lambda) * gn;
        psi[k] += ex.s_norm[i] * gd[i] * gn;
      }
    // Forces at ±δ·2^j, j = 0..4; FD_j = FD(δ·2^j) is checked against its own bound for
    // j = 0..3 (each bound is valid; the smallest says how sharp the check is).
    constexpr int J = 5;
    std::array<Field, J> fp, fm, rp, rm;
    for (int j = 0; j < J; ++j) force_at(std::ldexp(delta, j), fp[j], rp[j]), force_at(-std::ldexp(delta, j), fm[j], rm[j]);
    ld ref = 0;
    for (int a = 0; a < 3; ++a)
      for (std::size_t k = 0; k < nc; ++k) ref += static_cast<ld>(df[a][k]) * df[a][k];
    ref = std::sqrt(ref);
    ld best = std::numeric_limits<ld>::infinity();
    for (int j = 0; j + 1 < J; ++j) {
      const ld dj = std::ldexp(delta, j);
      ld err = 0, rich = 0, rnd = 0, raw_err = 0;
      for (int a = 0; a < 3; ++a)
        for (std::size_t k = 0; k < nc; ++k) {
          const ld fd1 = (fp[j][a][k] - fm[j][a][k]) / (2 * dj);
          const ld fd2 = (fp[j + 1][a][k] - fm[j + 1][a][k]) / (4 * dj);
          const ld raw1 = (rp[j][a][k] - rm[j][a][k]) / (2 * dj);
          err += (fd1 - df[a][k]) * (fd1 - df[a][k]);
          raw_err += (raw1 - df[a][k]) * (raw1 - df[a][k]);
          rich += (fd2 - fd1) * (fd2 - fd1);
          const ld rb = c_tau * eps * phi[k] / dj + c_g * eps * psi[k];
          rnd += rb * rb;
        }
      err = std::sqrt(err), rich = std::sqrt(rich), rnd = std::sqrt(rnd), raw_err = std::sqrt(raw_err);
      const ld bound = 2 * rich / 3 + rnd;
      best = std::min(best, bound);
      std::printf("  %s: linearisation, strain %.2Le: ‖FD − apply‖ = %.3Le (‖apply‖ = %.3Le; bound %.3Le = truncation %.3Le + "
                  "rounding %.3Le); FD of the P2G force itself: %.3Le off (geometric term −V⁰ τ Gᵀ ∇w)\n",
                  A::name, dj * gmax, err, ref, bound, 2 * rich / 3, rnd, raw_err);
      AMPM_CHECK(ck, err <= bound, "%s: linearisation error %.3Le > %.3Le at strain %.2Le", A::name, err, bound, dj * gmax);
    }
    const ld bound = best;
    AMPM_CHECK(ck, bound < 0.05L * ref, "%s: the FD bound %.3Le is no test against ‖apply‖ = %.3Le", A::name, bound, ref);
  }

  // ---- large implicit steps ----
  {
    Parts<T> q = p;
    Host<T> big(ck, s, q);
    const T dt_big = static_cast<T>(20 * dt_cfl);
    const auto e0 = big.energy();
    const ld energy0 = e0.first + e0.second;
    std::printf("  %s: Δt = 20 h/c = %.3Le s, initial energy %.6Le J (kinetic %.6Le)\n", A::name, static_cast<ld>(dt_big),
                energy0, e0.first);
    for (int step = 0; step < 6; ++step) {
      Step<T> sb;
      big.p2g(sb, dt_big);
      big.prepare(sb, true);
      std::array<std::vector<T>, 3> v;
      char what[64];
      std::snprintf(what, sizeof what, "large step %d", step);
      big.cg(sb, dt_big, tol, v, what);
      big.g2p(sb, dt_big, v);
      bool finite = true, positive = true;
      for (T x : q.x) finite &= std::isfinite(x);
      for (T x : q.v) finite &= std::isfinite(x);
      for (T x : q.fe) finite &= std::isfinite(x);
      for (T x : q.c) finite &= std::isfinite(x);
      for (std::size_t i = 0; i < q.n; ++i) {
        MatL<3> f;
        for (int k = 0; k < 9; ++k) f.data()[k] = q.fe[9 * i + k];
        positive &= f.determinant() > 0;
      }
      AMPM_CHECK(ck, finite, "%s large step %d: non-finite particle field", A::name, step);
      AMPM_CHECK(ck, positive, "%s large step %d: J_E <= 0", A::name, step);
      const auto e = big.energy();
      std::printf("    energy %.6Le J (kinetic %.6Le, elastic %.6Le)\n", e.first + e.second, e.first, e.second);
      AMPM_CHECK(ck, e.first + e.second <= energy0, "%s large step %d: energy %.6Le > initial %.6Le", A::name, step,
                 e.first + e.second, energy0);
    }
  }

  // For contrast (printed, not asserted): symplectic Euler at the same large Δt.
  {
    Parts<T> q = p;
    const T dt_big = static_cast<T>(20 * dt_cfl);
    const auto mat = material(s, false);
    std::printf("  %s: explicit steps at the same Δt:", A::name);
    for (int step = 0; step < 6; ++step) {
      int lo[3], hi[3];
      std::size_t ff = 0;
      if (A::node_range(AMPM_KERNEL_QUADRATIC, AMPM_GRID_COLLOCATED, static_cast<T>(s.h), q.n, q.x.data(), lo, hi, &ff) != AMPM_OK) {
        std::printf(" node_range failed");
        break;
      }
      Grid<T> g;
      g.reset(lo, hi);
      typename A::P2gView v{};
      v.nodes = g.box();
      v.mass = g.out(g.mass.data());
      for (int a = 0; a < 3; ++a) v.momentum[a] = g.out(g.mom[a].data());
      auto qv = q.view();
      const AmpmStatus s1 = A::p2g(&mat, AMPM_KERNEL_QUADRATIC, AMPM_GRID_COLLOCATED, static_cast<T>(s.h), dt_big, q.n, &qv, &v, &ff);
      for (std::size_t k = 0; k < g.count; ++k)
        for (int a = 0; a < 3; ++a) g.vstar[a][k] = g.mass[k] > 0 ? g.mom[a][k] / g.mass[k] : T(0);
      typename A::G2pView gv{};
      gv.nodes = g.box();
      for (int a = 0; a < 3; ++a) gv.velocity[a] = g.in(g.vstar[a].data());
      const AmpmStatus s2 = A::g2p(&mat, AMPM_KERNEL_QUADRATIC, static_cast<T>(s.h), dt_big, q.n, &qv, &gv, &ff);
      ld ke = 0;
      for (std::size_t i = 0; i < q.n; ++i)
        for (int a = 0; a < 3; ++a) ke += 0.5L * q.m[i] * q.v[3 * i + a] * q.v[3 * i + a];
      std::printf(" KE %.3Le (%s/%s)", ke, status_name(s1), status_name(s2));
      if (s1 != AMPM_OK || s2 != AMPM_OK || !std::isfinite(ke)) break;
    }
    std::printf("\n");
  }
}

}  // namespace

int main() {
  Checker ck;
  run<double>(ck);
  run<float>(ck);
  ck.summary("test_implicit_cg");
  return ck.exit_code();
}
