// The MPM particle transfers from C++/Eigen, through the C ABI only:
//   ampm_stencil_<d>_<p>, ampm_node_range_<d>_<p>, ampm_p2g_<d>_<p> (collocated and MAC face
//   grids), ampm_g2p_update_<d>_<p>, ampm_g2p_update_mac_<d>_<p>, ampm_force_prepare_<d>_<p> +
//   ampm_force_apply_<d>_<p> (exact and PSD-projected), ampm_pressure_<d>_<p>
// against an independent long-double Eigen implementation of the same updates written here
// from the papers, sharing no code with the library. The host owns dense grid arrays over a
// node box (x fastest, or an interleaved node struct with a reversed axis), points the views'
// channels at them, and the reference computes the same node sums and particle updates:
//   - B-spline stencils from the textbook piecewise formulas, positions x_i = (base + o)·h
//     (face grids shifted by h/2), derivatives by the chain rule;
//   - APIC (Jiang et al. 2015): m_i = Σ w m, p_i = Σ w m (v + C (x_i − x_p)), v = Σ w v_i,
//     C = (Σ w v_i (x_i − x_p)ᵀ) / (κ h²), ∇v = Σ v_i ∇w_iᵀ; on a MAC grid component a, row a
//     of C and row a of ∇v from face grid a;
//   - the stress from common.hpp's `Reference<D>` (Â of the seed's index formulas) plus the
//     dilational P_λ = λ(J − 1) J F⁻ᵀ, node force f_i = Σ −V⁰ P Fᵀ ∇w;
//   - F_E ← (I + Δt∇v) F_E with the remedy (I + 2⁻ᵏΔt∇v)^(2ᵏ), Eigen::JacobiSVD for the snow
//     clamp; a liquid keeps only its volume history: F_E ← J_E^(1/d) I, F_P ← J_P^(1/d) I;
//   - heat by the enthalpy method: e = c_s (T − T_m) below the melting point, U at it,
//     L + c_l (T − T_m) above; e += q, then back to (T, U, phase) with the buffer's hysteresis;
//   - the force differential from `Reference<D>::chat_z` plus δP_λ differentiated with
//     inverses (δ(F⁻ᵀ) = −F⁻ᵀ δFᵀ F⁻ᵀ), not the library's rotated-basis form; its projection
//     onto the negative semi-definite part as the eigen-decomposition (Eigen's
//     SelfAdjointEigenSolver in long double) of the whole d²×d² particle operator G ↦ M(G),
//     dilational part included, with positive eigenvalues set to 0 (the spectral projection is
//     unique, so it equals the library's block-by-block projection in the basis of F_E).
//
// Tolerance: C·ε·scale with ε of the precision under test and `scale` the sum of the magnitudes
// of the terms summed (stated per check). Every library quantity is a short chain (≲ 30
// operations, sums over ≤ 64 stencil nodes) of backward-stable steps on well-conditioned data
// (κ(F_E) ≤ 1.3), so C = 64 + 2·K^d bounds the accumulated rounding of one particle's
// contribution; a node sums the contributions of at most n particles, which adds n·ε relative
// to the sum of their magnitudes (recursive summation), so node sums get C + n. The stress and
// the Hessian go through an SVD and Ĉ's four terms, so they get the 32·ε·κ of
// test_hessian_eigen.cpp times 8 (the products with F_E, ∇w and the sums over the stencil):
// 256, plus n for the node sums. The NSD projection is 1-Lipschitz in the Frobenius norm
// (for symmetric matrices, X ↦ min(X, 0) inherits the Lipschitz constant of the scalar map), so
// the projected differential keeps the tolerance of the exact one.
#include "common.hpp"

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <array>
#include <vector>

using namespace ampm_test;

namespace {

constexpr std::uint64_t kSeed = 0x5eed'a3b1'2014'0004ULL;

// ---- the independent reference ------------------------------------------------------------

struct RefMaterial {
  bool plastic, thermal, phase_change, pressure_solve;
  ld mu_s, il_s, c_s, il_l, c_l, k_s, k_l;
  ld theta_c, theta_s, xi, flip, tm, latent;
};

template <int D>
struct RefParticle {
  Eigen::Matrix<ld, D, 1> x, v;
  MatL<D> c, fe, fp;
  ld m, v0, t, u;
  int phase;  // 0 solid, 1 liquid
};

/// Centred B-spline N(d) and N'(d) (d in cells).
inline ld spline(int kernel, ld d) {
  const ld a = std::fabs(d);
  if (kernel == AMPM_KERNEL_QUADRATIC) {
    if (a < 0.5L) return 0.75L - a * a;
    if (a < 1.5L) return 0.5L * (1.5L - a) * (1.5L - a);
    return 0;
  }
  if (a < 1) return 0.5L * a * a * a - a * a + 2.0L / 3.0L;
  if (a < 2) return (2 - a) * (2 - a) * (2 - a) / 6.0L;
  return 0;
}
inline ld dspline(int kernel, ld d) {
  const ld a = std::fabs(d), s = d < 0 ? -1.0L : 1.0L;
  if (kernel == AMPM_KERNEL_QUADRATIC) {
    if (a < 0.5L) return -2 * d;
    if (a < 1.5L) return -s * (1.5L - a);
    return 0;
  }
  if (a < 1) return s * (1.5L * a * a - 2 * a);
  if (a < 2) return -s * 0.5L * (2 - a) * (2 - a);
  return 0;
}

template <int D>
struct RefStencil {
  int k = 0, n = 0;
  int base[D];
  std::vector<std::array<int, D>> node;           // grid index base + o
  std::vector<ld> w;                              // w_i
  std::vector<Eigen::Matrix<ld, D, 1>> grad, dx;  // ∇w_i, x_i − x_p
};

/// Stencil of a particle at x on grid `grid` (−1 collocated, else face axis).
template <int D>
RefStencil<D> ref_stencil(int kernel, int grid, ld h, const Eigen::Matrix<ld, D, 1>& x) {
  RefStencil<D> s;
  s.k = kernel == AMPM_KERNEL_QUADRATIC ? 3 : 4;
  s.n = 1;
  for (int a = 0; a < D; ++a) s.n *= s.k;
  ld shift[D];
  for (int a = 0; a < D; ++a) {
    shift[a] = (grid >= 0 && grid != a) ? 0.5L : 0.0L;
    const ld xi = x(a) / h - shift[a];
    // Quadratic: the three nodes nearest x; cubic: two on each side.
    s.base[a] = kernel == AMPM_KERNEL_QUADRATIC ? static_cast<int>(std::floor(xi - 0.5L))
                                                : static_cast<int>(std::floor(xi)) - 1;
  }
  for (int r = 0; r < s.n; ++r) {
    int o[D];
    for (int a = 0, q = r; a < D; ++a, q /= s.k) o[a] = q % s.k;
    Eigen::Matrix<ld, D, 1> d, xi_minus_xp;
    std::array<int, D> idx;
    for (int a = 0; a < D; ++a) {
      idx[a] = s.base[a] + o[a];
      const ld xi = (s.base[a] + o[a] + shift[a]) * h;
      xi_minus_xp(a) = xi - x(a);
      d(a) = (x(a) - xi) / h;
    }
    ld w = 1;
    Eigen::Matrix<ld, D, 1> g;
    for (int a = 0; a < D; ++a) w *= spline(kernel, d(a));
    for (int a = 0; a < D; ++a) {
      g(a) = dspline(kernel, d(a)) / h;
      for (int b = 0; b < D; ++b)
        if (b != a) g(a) *= spline(kernel, d(b));
    }
    s.node.push_back(idx);
    s.w.push_back(w);
    s.grad.push_back(g);
    s.dx.push_back(xi_minus_xp);
  }
  return s;
}

/// (μ, 1/λ) of a particle after hardening (Stomakhin et al. 2013, eq. 2).
template <int D>
std::pair<ld, ld> moduli(const RefMaterial& m, const RefParticle<D>& p) {
  if (p.phase == 1) return {0, m.il_l};
  if (!m.plastic) return {m.mu_s, m.il_s};
  const ld e = std::exp(m.xi * (1 - p.fp.determinant()));
  return {m.mu_s * e, m.il_s / e};
}

/// First Piola P = Â + P_λ of F_E (P_λ only with the dilation in the stress).
template <int D>
MatL<D> ref_piola(const RefMaterial& m, const RefParticle<D>& p) {
  const auto [mu, il] = moduli(m, p);
  MatL<D> pk = MatL<D>::Zero();
  if (mu > 0) pk += Reference<D>(mu, p.fe).ahat();
  if (!m.pressure_solve) {
    const ld j = p.fe.determinant();
    pk += (j - 1) * j / il * p.fe.inverse().transpose();
  }
  return pk;
}

/// The exact force-differential matrix M(G) = −V⁰ (Ĉ:(G F_E) + δP_λ) F_Eᵀ: node i receives
/// M ∇w_i for G = Σ_j δu_j ∇w_jᵀ. `ref` is Reference(μ, F_E) when μ > 0 (built once per
/// particle by the caller, it caches Ĉ).
template <int D>
MatL<D> ref_dforce(const RefMaterial& mat, const RefParticle<D>& p, const Reference<D>* ref,
                   const MatL<D>& g) {
  const MatL<D> dF = g * p.fe;
  const auto [mu, il] = moduli(mat, p);
  MatL<D> dp = MatL<D>::Zero();
  if (mu > 0) dp += ref->chat_z(dF);
  if (!mat.pressure_solve) {
    const ld j = p.fe.determinant();
    const MatL<D> hm = p.fe.inverse().transpose();
    const ld dj = j * (p.fe.inverse() * dF).trace();
    dp += (2 * j - 1) * dj / il * hm - (j - 1) * j / il * hm * dF.transpose() * hm;
  }
  return -p.v0 * dp * p.fe.transpose();
}

/// The particle operator G ↦ M(G) as a d²×d² matrix on vec(G) (column k = vec M(E_k)),
/// symmetrised; `asym` gets ‖S − Sᵀ‖/‖S‖ of the unsymmetrised matrix (a check of the
/// reference itself: the operator is −V⁰ times a Hessian).
template <int D>
Eigen::Matrix<ld, D * D, D * D> ref_operator(const RefMaterial& mat, const RefParticle<D>& p,
                                             const Reference<D>* ref, ld* asym) {
  constexpr int N = D * D;
  Eigen::Matrix<ld, N, N> s;
  for (int k = 0; k < N; ++k) {
    MatL<D> e = MatL<D>::Zero();
    e.data()[k] = 1;
    const MatL<D> m = ref_dforce<D>(mat, p, ref, e);
    for (int l = 0; l < N; ++l) s(l, k) = m.data()[l];
  }
  *asym = (s - s.transpose()).norm() / std::max(s.norm(), ld(1e-300L));
  return (s + s.transpose()) / 2;
}

/// M(G) with the particle operator projected onto its negative semi-definite part.
template <int D>
MatL<D> ref_dforce_nsd(const RefMaterial& mat, const RefParticle<D>& p, const Reference<D>* ref,
                       const MatL<D>& g, ld* asym) {
  constexpr int N = D * D;
  const Eigen::Matrix<ld, N, N> s = ref_operator<D>(mat, p, ref, asym);
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix<ld, N, N>> es(s);
  Eigen::Matrix<ld, N, 1> lam = es.eigenvalues();
  for (int k = 0; k < N; ++k) lam(k) = std::min(lam(k), ld(0));
  const Eigen::Matrix<ld, N, N> sm = es.eigenvectors() * lam.asDiagonal() *
                                     es.eigenvectors().transpose();
  Eigen::Matrix<ld, N, 1> gv;
  for (int k = 0; k < N; ++k) gv(k) = g.data()[k];
  const Eigen::Matrix<ld, N, 1> mv = sm * gv;
  MatL<D> out;
  for (int k = 0; k < N; ++k) out.data()[k] = mv(k);
  return out;
}

/// Enthalpy-method heat update (see the file comment); q in J/kg.
template <int D>
void ref_heat(const RefMaterial& m, RefParticle<D>& p, ld q) {
  ld e = p.t < m.tm ? m.c_s * (p.t - m.tm) : p.t > m.tm ? m.latent + m.c_l * (p.t - m.tm) : p.u;
  e += q;
  if (e < 0) {
    p.phase = 0, p.u = 0, p.t = m.tm + e / m.c_s;
  } else if (e > m.latent) {
    p.phase = 1, p.u = m.latent, p.t = m.tm + (e - m.latent) / m.c_l;
  } else {
    p.t = m.tm, p.u = e;  // the phase switches only when the buffer leaves [0, L]
  }
}

/// What G2P gathers for one particle: v, C, ∇v and the temperature sums.
template <int D>
struct RefSample {
  Eigen::Matrix<ld, D, 1> v = Eigen::Matrix<ld, D, 1>::Zero();
  MatL<D> c = MatL<D>::Zero(), gv = MatL<D>::Zero();
  ld t_pic = 0, t_flip = 0;
};

/// G2P update of one particle from its gathered sample.
template <int D>
RefParticle<D> ref_update(const RefMaterial& m, ld dt, RefParticle<D> p,
                          const RefSample<D>& s) {
  if (m.thermal) {
    const ld t_star = (1 - m.flip) * s.t_pic + m.flip * (p.t + s.t_flip);
    if (m.phase_change)
      ref_heat(m, p, (p.phase == 0 ? m.c_s : m.c_l) * (t_star - p.t));
    else
      p.t = t_star;
  }
  p.v = s.v;
  p.c = s.c;
  p.x += dt * s.v;
  const MatL<D> id = MatL<D>::Identity();
  MatL<D> a = id + dt * s.gv;
  for (int k = 1; a.determinant() <= 0 && k <= 64; ++k) {
    a = id + std::ldexp(dt, -k) * s.gv;
    for (int i = 0; i < k; ++i) a = a * a;
  }
  p.fe = a * p.fe;
  if (p.phase == 1) {
    // A liquid keeps only its volume history: J_E and J_P, each as a multiple of I.
    const ld je = p.fe.determinant(), jp = p.fp.determinant();
    p.fe = (D == 2 ? std::sqrt(je) : std::cbrt(je)) * id;
    p.fp = (D == 2 ? std::sqrt(jp) : std::cbrt(jp)) * id;
  } else if (m.plastic) {
    const Eigen::JacobiSVD<MatL<D>> svd(p.fe, Eigen::ComputeFullU | Eigen::ComputeFullV);
    Eigen::Matrix<ld, D, 1> sig = svd.singularValues(), cl = sig;
    for (int i = 0; i < D; ++i) cl(i) = std::min(std::max(sig(i), 1 - m.theta_c), 1 + m.theta_s);
    const MatL<D> u = svd.matrixU(), vv = svd.matrixV();
    p.fe = u * cl.asDiagonal() * vv.transpose();
    p.fp = vv * sig.cwiseQuotient(cl).asDiagonal() * vv.transpose() * p.fp;
  }
  return p;
}

// ---- the host's grid -----------------------------------------------------------------------

/// A box of grid nodes [lo, lo + dims) and its dense x-fastest indexing.
template <int D>
struct Box {
  std::array<int, D> lo{}, dims{};
  std::size_t count() const {
    std::size_t c = 1;
    for (int a = 0; a < D; ++a) c *= static_cast<std::size_t>(dims[a]);
    return c;
  }
  std::ptrdiff_t stride(int a) const {
    std::ptrdiff_t s = 1;
    for (int b = 0; b < a; ++b) s *= dims[b];
    return s;
  }
  bool contains(const std::array<int, D>& i) const {
    for (int a = 0; a < D; ++a)
      if (i[a] < lo[a] || i[a] >= lo[a] + dims[a]) return false;
    return true;
  }
  std::size_t at(const std::array<int, D>& i) const {
    std::size_t k = 0;
    for (int a = D - 1; a >= 0; --a) k = k * dims[a] + static_cast<std::size_t>(i[a] - lo[a]);
    return k;
  }
  std::array<int, D> node(std::size_t k) const {
    std::array<int, D> i;
    for (int a = 0; a < D; ++a) {
      i[a] = lo[a] + static_cast<int>(k % dims[a]);
      k /= dims[a];
    }
    return i;
  }
  AmpmNodeBox c() const {
    AmpmNodeBox b{};
    for (int a = 0; a < 3; ++a) b.lo[a] = 0, b.dims[a] = 1;
    for (int a = 0; a < D; ++a) b.lo[a] = lo[a], b.dims[a] = dims[a];
    return b;
  }
};

/// A channel over separate x-fastest arrays of `box` (data NULL: absent).
template <class Ch, class P, int D>
Ch channel(P data, const Box<D>& box) {
  Ch c{};
  c.data = data;
  for (int a = 0; a < 3; ++a) c.stride[a] = a < D ? box.stride(a) : 0;
  return c;
}

/// Per node of a box, the reference sum and the sum of the magnitudes of its terms.
struct RefField {
  std::vector<ld> sum, scale;
  explicit RefField(std::size_t n = 0) : sum(n, 0), scale(n, 0) {}
  void add(std::size_t k, ld v, ld s) { sum[k] += v, scale[k] += s; }
};

// ---- SoA data as the C ABI sees it ---------------------------------------------------------

template <class T, int D>
struct Soa {
  std::vector<T> x, v, c, fe, fp, m, v0, t, u;
  std::vector<std::uint8_t> ph;

  void push(const RefParticle<D>& p) {
    for (int a = 0; a < D; ++a) x.push_back(static_cast<T>(p.x(a))), v.push_back(static_cast<T>(p.v(a)));
    for (int k = 0; k < D * D; ++k) {
      c.push_back(static_cast<T>(p.c.data()[k]));
      fe.push_back(static_cast<T>(p.fe.data()[k]));
      fp.push_back(static_cast<T>(p.fp.data()[k]));
    }
    m.push_back(static_cast<T>(p.m)), v0.push_back(static_cast<T>(p.v0));
    t.push_back(static_cast<T>(p.t)), u.push_back(static_cast<T>(p.u));
    ph.push_back(static_cast<std::uint8_t>(p.phase));
  }
  /// Particle i exactly as stored (so the reference sees the library's input).
  RefParticle<D> get(std::size_t i) const {
    RefParticle<D> p;
    for (int a = 0; a < D; ++a) p.x(a) = x[D * i + a], p.v(a) = v[D * i + a];
    for (int k = 0; k < D * D; ++k) {
      p.c.data()[k] = c[D * D * i + k];
      p.fe.data()[k] = fe[D * D * i + k];
      p.fp.data()[k] = fp[D * D * i + k];
    }
    p.m = m[i], p.v0 = v0[i], p.t = t[i], p.u = u[i], p.phase = ph[i];
    return p;
  }
  typename PartApi<T, D>::Particles ptrs() {
    return {x.data(), v.data(), c.data(), fe.data(), fp.data(), m.data(),
            v0.data(), t.data(), u.data(), ph.data()};
  }
};

template <class T, int D>
typename PartApi<T, D>::Material c_material(const RefMaterial& r) {
  typename PartApi<T, D>::Material m{};
  m.model = (r.plastic ? AMPM_MODEL_PLASTIC : 0) | (r.thermal ? AMPM_MODEL_THERMAL : 0) |
            (r.phase_change ? AMPM_MODEL_PHASE_CHANGE : 0) |
            (r.pressure_solve ? AMPM_MODEL_PRESSURE_SOLVE : 0);
  m.solid.mu = static_cast<T>(r.mu_s);
  m.solid.inv_lambda = static_cast<T>(r.il_s);
  m.solid.heat_capacity = static_cast<T>(r.c_s);
  m.solid.conductivity = static_cast<T>(r.k_s);
  m.liquid.mu = 0;
  m.liquid.inv_lambda = static_cast<T>(r.il_l);
  m.liquid.heat_capacity = static_cast<T>(r.c_l);
  m.liquid.conductivity = static_cast<T>(r.k_l);
  m.critical_compression = static_cast<T>(r.theta_c);
  m.critical_stretch = static_cast<T>(r.theta_s);
  m.hardening = static_cast<T>(r.xi);
  m.flip = static_cast<T>(r.flip);
  m.melting_point = static_cast<T>(r.tm);
  m.latent_heat = static_cast<T>(r.latent);
  return m;
}

/// The material's parameters rounded to T (what the library sees).
template <class T>
RefMaterial rounded(RefMaterial r) {
  for (ld* f : {&r.mu_s, &r.il_s, &r.c_s, &r.il_l, &r.c_l, &r.k_s, &r.k_l, &r.theta_c,
                &r.theta_s, &r.xi, &r.flip, &r.tm, &r.latent})
    *f = static_cast<T>(*f);
  return r;
}

/// The node box of the reference stencils of `soa`'s particles on `grid`.
template <class T, int D>
Box<D> ref_box(const Soa<T, D>& soa, std::size_t n, int kernel, int grid, ld h) {
  Box<D> b;
  std::array<int, D> hi;
  for (int a = 0; a < D; ++a) b.lo[a] = 1 << 30, hi[a] = -(1 << 30);
  for (std::size_t i = 0; i < n; ++i) {
    const RefStencil<D> s = ref_stencil<D>(kernel, grid, h, soa.get(i).x);
    for (int a = 0; a < D; ++a) {
      b.lo[a] = std::min(b.lo[a], s.base[a]);
      hi[a] = std::max(hi[a], s.base[a] + s.k - 1);
    }
  }
  for (int a = 0; a < D; ++a) b.dims[a] = hi[a] - b.lo[a] + 1;
  return b;
}

template <class T, int D>
void run(Checker& ck, bool pressure_solve) {
  using A = PartApi<T, D>;
  using Vec = Eigen::Matrix<ld, D, 1>;
  using Ch = typename A::Channel;
  using CCh = typename A::ConstChannel;
  const ld eps = std::numeric_limits<T>::epsilon();
  Rng rng(kSeed + 10 * D + sizeof(T) + (pressure_solve ? 100 : 0));
  const RefMaterial mat = rounded<T>({true, true, true, pressure_solve, 40.0L, 0.02L, 2.0L, 0.05L,
                                      4.0L, 1.5L, 0.6L, 0.025L, 0.0075L, 10.0L, 0.9L, 273.0L,
                                      100.0L});
  const auto cm = c_material<T, D>(mat);
  const int kernel = D == 2 ? AMPM_KERNEL_CUBIC : AMPM_KERNEL_QUADRATIC;
  const int kk = kernel == AMPM_KERNEL_QUADRATIC ? 3 : 4;
  const int K = D == 2 ? kk * kk : kk * kk * kk;
  const T h = static_cast<T>(0.5), dt = static_cast<T>(1e-3);
  const std::size_t n = 12;
  const ld C = 64 + 2 * K;                     // one particle's contribution (file comment)
  const ld Cn = C + static_cast<ld>(n);        // a node sum of ≤ n contributions
  const ld Sn = 256 + static_cast<ld>(n);      // stress and Hessian node sums
  auto close = [&](const char* what, std::size_t i, ld got, ld want, ld scale, ld c) {
    AMPM_CHECK(ck, std::fabs(got - want) <= c * eps * scale,
               "%s %s %zu: got %.12Le want %.12Le (tol %.3Le)", A::name, what, i, got, want,
               c * eps * scale);
  };

  // Particles: solids below the melting point or melting, liquids above it or freezing, in
  // [1, 3]^d; the last one (the remedy's, see G2P) on its own at x_0 in [5.1, 5.4], so that no
  // other particle's stencil shares a node with it.
  Soa<T, D> soa;
  for (std::size_t i = 0; i < n; ++i) {
    RefParticle<D> p;
    for (int a = 0; a < D; ++a) p.x(a) = rng.uniform(1.0, 3.0), p.v(a) = rng.uniform(-1, 1);
    if (i == n - 1) p.x(0) = rng.uniform(5.1, 5.4);
    p.c = gaussian<D>(rng);
    p.phase = static_cast<int>(i % 2);
    Eigen::Matrix<ld, D, 1> sig = log_uniform_sigma<D>(rng, 0.9, 1.1);
    if (p.phase == 1) sig.setConstant(sig(0));  // a liquid's F_E is isotropic
    p.fe = random_f_with_sigma<D>(rng, sig);
    p.fp = random_f_with_sigma<D>(rng, log_uniform_sigma<D>(rng, 0.95, 1.05));
    p.m = rng.uniform(0.5, 2.0), p.v0 = rng.uniform(0.01, 0.1);
    const int kind = static_cast<int>(i / 2) % 3;  // 0: away from T_m, 1-2: at T_m
    if (p.phase == 0)
      p.t = kind == 0 ? 268.0L : 273.0L, p.u = kind == 0 ? 0.0L : 30.0L * kind;
    else
      p.t = kind == 0 ? 278.0L : 273.0L, p.u = kind == 0 ? 100.0L : 30.0L * kind;
    soa.push(p);
  }
  auto ps = soa.ptrs();

  // Stencils on every grid: weights and gradients; node ranges.
  for (int grid = -1; grid < D; ++grid) {
    std::vector<int> base(n * D);
    std::vector<T> w(n * K), gw(n * K * D);
    std::size_t first = 999;
    AMPM_CHECK_STATUS(ck, (A::stencil(kernel, grid, h, n, soa.x.data(), base.data(), w.data(),
                                      gw.data(), &first)),
                      AMPM_OK);
    AMPM_CHECK(ck, first == n, "%s stencil: first_failed = %zu", A::name, first);
    for (std::size_t i = 0; i < n; ++i) {
      const RefStencil<D> s = ref_stencil<D>(kernel, grid, h, soa.get(i).x);
      for (int a = 0; a < D; ++a)
        AMPM_CHECK(ck, base[D * i + a] == s.base[a], "%s stencil base", A::name);
      for (int r = 0; r < K; ++r) {
        // x/h carries ε·|x/h| ≤ 12ε of rounding, amplified by |N'| ≤ 1 per axis.
        close("weight", i, w[K * i + r], s.w[r], 1 + 12 * D, C);
        for (int a = 0; a < D; ++a)
          close("grad weight", i, gw[(K * i + r) * D + a], s.grad[r](a), (1 + 12 * D) / h, C);
      }
    }
    const Box<D> want = ref_box<T, D>(soa, n, kernel, grid, h);
    int lo[3] = {7, 7, 7}, hi[3] = {7, 7, 7};
    first = 999;
    AMPM_CHECK_STATUS(ck, (A::node_range(kernel, grid, h, n, soa.x.data(), lo, hi, &first)),
                      AMPM_OK);
    AMPM_CHECK(ck, first == n, "%s node_range: first_failed = %zu", A::name, first);
    for (int a = 0; a < D; ++a)
      AMPM_CHECK(ck, lo[a] == want.lo[a] && hi[a] == want.lo[a] + want.dims[a] - 1,
                 "%s node_range grid %d axis %d: [%d, %d], want [%d, %d]", A::name, grid, a,
                 lo[a], hi[a], want.lo[a], want.lo[a] + want.dims[a] - 1);
  }

  // The host's collocated box: the particles' nodes plus a margin of 2 below and 1 above, so
  // that nodes no stencil reaches are in the view too (and must stay untouched).
  Box<D> box = ref_box<T, D>(soa, n, kernel, -1, h);
  for (int a = 0; a < D; ++a) box.lo[a] -= 2, box.dims[a] += 3;
  const std::size_t nn = box.count();

  // ---- P2G on the collocated grid ----
  // Channels 0 mass, 1..D momentum, D+1..2D force, 2D+1.. heat capacity, thermal energy,
  // conductivity.
  const int NCH = 1 + 2 * D + 3;
  std::vector<std::vector<T>> grid_a(NCH, std::vector<T>(nn, 0));
  {
    typename A::P2gView view{};
    view.nodes = box.c();
    view.mass = channel<Ch>(grid_a[0].data(), box);
    for (int a = 0; a < D; ++a) {
      view.momentum[a] = channel<Ch>(grid_a[1 + a].data(), box);
      view.force[a] = channel<Ch>(grid_a[1 + D + a].data(), box);
    }
    view.heat_capacity = channel<Ch>(grid_a[2 * D + 1].data(), box);
    view.thermal_energy = channel<Ch>(grid_a[2 * D + 2].data(), box);
    view.conductivity = channel<Ch>(grid_a[2 * D + 3].data(), box);
    std::size_t first = 999;
    AMPM_CHECK_STATUS(ck, (A::p2g(&cm, kernel, AMPM_GRID_COLLOCATED, h, T(0), n, &ps, &view,
                                  &first)),
                      AMPM_OK);
    AMPM_CHECK(ck, first == n, "%s p2g: first_failed = %zu", A::name, first);

    std::vector<RefField> ref(NCH, RefField(nn));
    std::vector<ld> cst(NCH, Cn);
    for (int a = 0; a < D; ++a) cst[1 + D + a] = Sn;
    for (std::size_t i = 0; i < n; ++i) {
      const RefParticle<D> p = soa.get(i);
      const RefStencil<D> s = ref_stencil<D>(kernel, -1, h, p.x);
      const MatL<D> tau = ref_piola<D>(mat, p) * p.fe.transpose();
      const ld c = p.phase == 0 ? mat.c_s : mat.c_l;
      const ld kap = p.phase == 0 ? mat.k_s : mat.k_l;
      const ld vs = p.v.norm() + p.c.norm() * 2 * h;
      // Stress errors are absolute in units of the moduli (J_E − 1 cancels near 1).
      const auto [mu, il] = moduli(mat, p);
      const ld ts = tau.norm() + mu + 1 / il;
      for (int r = 0; r < K; ++r) {
        const std::size_t k = box.at(s.node[r]);
        const Vec mom = s.w[r] * p.m * (p.v + p.c * s.dx[r]);
        const Vec f = -p.v0 * tau * s.grad[r];
        ref[0].add(k, s.w[r] * p.m, p.m);
        for (int a = 0; a < D; ++a) {
          ref[1 + a].add(k, mom(a), p.m * vs);
          ref[1 + D + a].add(k, f(a), p.v0 * ts / h);
        }
        ref[2 * D + 1].add(k, s.w[r] * p.m * c, p.m * c);
        ref[2 * D + 2].add(k, s.w[r] * p.m * c * p.t, p.m * c * p.t);
        ref[2 * D + 3].add(k, s.w[r] * p.m * kap, p.m * kap);
      }
    }
    static const char* names[] = {"mass", "momentum", "momentum", "momentum", "force",
                                  "force", "force", "heat capacity", "thermal energy",
                                  "conductivity"};
    for (int ch = 0; ch < NCH; ++ch) {
      const int nm = ch == 0 ? 0 : ch <= D ? 1 : ch <= 2 * D ? 4 : 7 + (ch - 2 * D - 1);
      for (std::size_t k = 0; k < nn; ++k)
        close(names[nm], k, grid_a[ch][k], ref[ch].sum[k], ref[ch].scale[k], cst[ch]);
    }
  }

  // The same P2G through an interleaved node struct of NCH scalars, axis D−1 fastest and axis
  // 0 reversed (negative stride): the same sums in the same order, so bit for bit the same.
  {
    std::vector<std::ptrdiff_t> st(D);
    st[D - 1] = NCH;
    for (int a = D - 2; a >= 0; --a) st[a] = st[a + 1] * box.dims[a + 1];
    st[0] = -st[0];
    const std::ptrdiff_t origin = -st[0] * (box.dims[0] - 1);  // node lo sits at the end
    std::vector<T> blob(nn * NCH, 0);
    auto ich = [&](int ch) {
      Ch c{};
      c.data = blob.data() + origin + ch;
      for (int a = 0; a < D; ++a) c.stride[a] = st[a];
      return c;
    };
    typename A::P2gView view{};
    view.nodes = box.c();
    view.mass = ich(0);
    for (int a = 0; a < D; ++a) view.momentum[a] = ich(1 + a), view.force[a] = ich(1 + D + a);
    view.heat_capacity = ich(2 * D + 1);
    view.thermal_energy = ich(2 * D + 2);
    view.conductivity = ich(2 * D + 3);
    std::size_t first = 999;
    AMPM_CHECK_STATUS(ck, (A::p2g(&cm, kernel, AMPM_GRID_COLLOCATED, h, T(0), n, &ps, &view,
                                  &first)),
                      AMPM_OK);
    bool same = true;
    for (std::size_t k = 0; k < nn; ++k) {
      const auto idx = box.node(k);
      std::ptrdiff_t off = origin;
      for (int a = 0; a < D; ++a) off += (idx[a] - box.lo[a]) * st[a];
      for (int ch = 0; ch < NCH; ++ch) same &= same_bits(&blob[off + ch], &grid_a[ch][k], 1);
    }
    AMPM_CHECK(ck, same, "%s p2g: interleaved, reversed view differs from separate arrays",
               A::name);
  }

  // impulse_dt = Δt without a force channel: momentum + Δt·force of the plain form (each
  // contribution rounds once more, so the node sums agree to (C + n)·ε of the magnitudes).
  {
    const T idt = static_cast<T>(0.01);
    std::vector<T> m(nn, 0);
    std::vector<std::vector<T>> mom(D, std::vector<T>(nn, 0));
    typename A::P2gView view{};
    view.nodes = box.c();
    view.mass = channel<Ch>(m.data(), box);
    for (int a = 0; a < D; ++a) view.momentum[a] = channel<Ch>(mom[a].data(), box);
    std::size_t first = 999;
    AMPM_CHECK_STATUS(ck, (A::p2g(&cm, kernel, AMPM_GRID_COLLOCATED, h, idt, n, &ps, &view,
                                  &first)),
                      AMPM_OK);
    std::vector<ld> sc(nn, 0);
    for (std::size_t i = 0; i < n; ++i) {
      const RefParticle<D> p = soa.get(i);
      const RefStencil<D> s = ref_stencil<D>(kernel, -1, h, p.x);
      const MatL<D> tau = ref_piola<D>(mat, p) * p.fe.transpose();
      const auto [mu, il] = moduli(mat, p);
      for (int r = 0; r < K; ++r)
        sc[box.at(s.node[r])] += p.m * (p.v.norm() + p.c.norm() * 2 * h) +
                                 idt * p.v0 * (tau.norm() + mu + 1 / il) / h;
    }
    for (std::size_t k = 0; k < nn; ++k) {
      AMPM_CHECK(ck, same_bits(&m[k], &grid_a[0][k], 1), "%s impulse p2g: mass differs",
                 A::name);
      for (int a = 0; a < D; ++a)
        close("impulse momentum", k, mom[a][k],
              static_cast<ld>(grid_a[1 + a][k]) + static_cast<ld>(idt) * grid_a[1 + D + a][k],
              sc[k], Sn);
    }
  }

  // The stress of every particle through its own one-particle P2G (force channel only, the
  // others absent): τ = −(1/V⁰) Σ_i f_i (x_i − x_p)ᵀ since Σ_i ∇w_i (x_i − x_p)ᵀ = I; a
  // liquid's is isotropic. The sum has K^d terms of size ≤ V⁰‖τ‖·|∇w||x_i − x_p| ≤
  // V⁰‖τ‖·2√d, hence 256·K^d·2√d.
  for (std::size_t i = 0; i < n; ++i) {
    const RefParticle<D> p = soa.get(i);
    const RefStencil<D> s = ref_stencil<D>(kernel, -1, h, p.x);
    Box<D> sb;
    for (int a = 0; a < D; ++a) sb.lo[a] = s.base[a], sb.dims[a] = s.k;
    std::vector<std::vector<T>> f(D, std::vector<T>(sb.count(), 0));
    typename A::P2gView view{};
    view.nodes = sb.c();
    for (int a = 0; a < D; ++a) view.force[a] = channel<Ch>(f[a].data(), sb);
    typename A::Particles one = ps;
    one.x += D * i, one.v += D * i, one.affine += D * D * i, one.f_e += D * D * i,
        one.f_p += D * D * i, one.mass += i, one.volume0 += i, one.temperature += i,
        one.latent += i, one.phase += i;
    std::size_t first = 999;
    AMPM_CHECK_STATUS(ck, (A::p2g(&cm, kernel, AMPM_GRID_COLLOCATED, h, T(0), 1, &one, &view,
                                  &first)),
                      AMPM_OK);
    MatL<D> tau_lib = MatL<D>::Zero();
    for (int r = 0; r < K; ++r) {
      Vec fl;
      for (int a = 0; a < D; ++a) fl(a) = f[a][sb.at(s.node[r])];
      tau_lib -= fl * s.dx[r].transpose() / p.v0;
    }
    const MatL<D> tau = ref_piola<D>(mat, p) * p.fe.transpose();
    const auto [mu, il] = moduli(mat, p);
    const ld ts = tau.norm() + mu + 1 / il;
    const ld c_tau = 256 * K * 2 * std::sqrt(ld(D));
    close("stress from one-particle p2g", i, (tau_lib - tau).norm(), 0, ts, c_tau);
    if (p.phase == 1) {
      const MatL<D> dev = tau_lib - tau_lib.trace() / D * MatL<D>::Identity();
      AMPM_CHECK(ck, dev.norm() <= c_tau * eps * ts, "%s liquid deviatoric stress %.3Le",
                 A::name, dev.norm());
    }
  }

  // P2G on each MAC face grid a: mass, momentum[a] and force[a] with the face stencil; the
  // other channels of the view stay untouched.
  for (int g = 0; g < D; ++g) {
    Box<D> fb = ref_box<T, D>(soa, n, kernel, g, h);
    for (int a = 0; a < D; ++a) fb.lo[a] -= 1, fb.dims[a] += 2;
    const std::size_t fn = fb.count();
    std::vector<std::vector<T>> fg(NCH, std::vector<T>(fn, 0));
    typename A::P2gView view{};
    view.nodes = fb.c();
    view.mass = channel<Ch>(fg[0].data(), fb);
    for (int a = 0; a < D; ++a) {
      view.momentum[a] = channel<Ch>(fg[1 + a].data(), fb);
      view.force[a] = channel<Ch>(fg[1 + D + a].data(), fb);
    }
    view.heat_capacity = channel<Ch>(fg[2 * D + 1].data(), fb);
    view.thermal_energy = channel<Ch>(fg[2 * D + 2].data(), fb);
    view.conductivity = channel<Ch>(fg[2 * D + 3].data(), fb);
    std::size_t first = 999;
    AMPM_CHECK_STATUS(ck, (A::p2g(&cm, kernel, g, h, T(0), n, &ps, &view, &first)), AMPM_OK);
    RefField rm(fn), rq(fn), rf(fn);
    for (std::size_t i = 0; i < n; ++i) {
      const RefParticle<D> p = soa.get(i);
      const RefStencil<D> s = ref_stencil<D>(kernel, g, h, p.x);
      const MatL<D> tau = ref_piola<D>(mat, p) * p.fe.transpose();
      const auto [mu, il] = moduli(mat, p);
      for (int r = 0; r < K; ++r) {
        const std::size_t k = fb.at(s.node[r]);
        rm.add(k, s.w[r] * p.m, p.m);
        rq.add(k, s.w[r] * p.m * (p.v + p.c * s.dx[r])(g),
               p.m * (p.v.norm() + p.c.norm() * 2 * h));
        rf.add(k, (-p.v0 * tau * s.grad[r])(g), p.v0 * (tau.norm() + mu + 1 / il) / h);
      }
    }
    bool untouched = true;
    for (std::size_t k = 0; k < fn; ++k) {
      close("face mass", k, fg[0][k], rm.sum[k], rm.scale[k], Cn);
      close("face momentum", k, fg[1 + g][k], rq.sum[k], rq.scale[k], Cn);
      close("face force", k, fg[1 + D + g][k], rf.sum[k], rf.scale[k], Sn);
      for (int ch = 1; ch < NCH; ++ch)
        if (ch != 1 + g && ch != 1 + D + g) untouched &= fg[ch][k] == T(0);
    }
    AMPM_CHECK(ck, untouched, "%s face p2g %d wrote a channel of another component or heat",
               A::name, g);
  }

  // A box one node short on axis 0: the particles reaching its last layer fail with
  // AMPM_ERR_OUTSIDE_GRID and transfer nothing; the others sum to the same bits as a batch of
  // only them, in the same order (node sums are formed per run of nearby particles, and a
  // failed particle does not change the runs).
  {
    Box<D> sb = ref_box<T, D>(soa, n, kernel, -1, h);
    const int last = sb.lo[0] + sb.dims[0] - 1;
    sb.dims[0] -= 1;
    std::vector<T> m(sb.count(), 0), m_good(sb.count(), 0);
    typename A::P2gView view{};
    view.nodes = sb.c();
    view.mass = channel<Ch>(m.data(), sb);
    std::size_t first = 999, want_first = n;
    AMPM_CHECK_STATUS(ck, (A::p2g(&cm, kernel, AMPM_GRID_COLLOCATED, h, T(0), n, &ps, &view,
                                  &first)),
                      AMPM_ERR_OUTSIDE_GRID);
    view.mass = channel<Ch>(m_good.data(), sb);
    Soa<T, D> inside;
    std::size_t n_inside = 0;
    for (std::size_t i = 0; i < n; ++i) {
      const RefStencil<D> s = ref_stencil<D>(kernel, -1, h, soa.get(i).x);
      if (s.base[0] + s.k - 1 == last) {
        want_first = std::min(want_first, i);
        continue;
      }
      inside.push(soa.get(i));
      ++n_inside;
    }
    typename A::Particles only = inside.ptrs();
    std::size_t f1 = 999;
    AMPM_CHECK_STATUS(ck, (A::p2g(&cm, kernel, AMPM_GRID_COLLOCATED, h, T(0), n_inside, &only,
                                  &view, &f1)),
                      AMPM_OK);
    AMPM_CHECK(ck, first == want_first, "%s outside grid: first_failed = %zu, want %zu",
               A::name, first, want_first);
    AMPM_CHECK(ck, same_bits(m.data(), m_good.data(), m.size()),
               "%s outside grid: the particles inside did not sum as a batch of only them", A::name);
  }

  // ---- force differential ----
  // du random on every node of the box; df = apply(du) after prepare, exact Hessian and the NSD
  // projection, against the reference node sums Σ_p M_p(G_p) ∇w_ip.
  {
    const std::size_t sl = A::slot_len;
    std::vector<std::vector<T>> du(D, std::vector<T>(nn));
    for (auto& c : du)
      for (auto& x : c) x = static_cast<T>(rng.uniform(-1e-3, 1e-3));
    for (const bool psd : {false, true}) {
      auto cmat = cm;
      if (psd) cmat.model |= AMPM_MODEL_PSD_HESSIAN;
      std::vector<T> slots(n * sl, sentinel<T>());
      std::size_t first = 999;
      AMPM_CHECK_STATUS(ck, (A::prepare(&cmat, n, &ps, slots.data(), &first)), AMPM_OK);
      AMPM_CHECK(ck, first == n, "%s prepare: first_failed = %zu", A::name, first);
      std::vector<std::vector<T>> df(D, std::vector<T>(nn, 0));
      typename A::ForceView fv{};
      fv.nodes = box.c();
      for (int a = 0; a < D; ++a) {
        fv.du[a] = channel<CCh>(static_cast<const T*>(du[a].data()), box);
        fv.df[a] = channel<Ch>(df[a].data(), box);
      }
      first = 999;
      AMPM_CHECK_STATUS(ck, (A::apply(kernel, h, n, soa.x.data(), slots.data(), &fv, &first)),
                        AMPM_OK);
      AMPM_CHECK(ck, first == n, "%s apply: first_failed = %zu", A::name, first);
      std::vector<RefField> ref(D, RefField(nn));
      for (std::size_t i = 0; i < n; ++i) {
        const RefParticle<D> p = soa.get(i);
        const RefStencil<D> s = ref_stencil<D>(kernel, -1, h, p.x);
        MatL<D> g = MatL<D>::Zero();
        for (int r = 0; r < K; ++r) {
          Vec u;
          for (int a = 0; a < D; ++a) u(a) = du[a][box.at(s.node[r])];
          g += u * s.grad[r].transpose();
        }
        const auto [mu, il] = moduli(mat, p);
        const Reference<D> refp(mu > 0 ? mu : 1, p.fe);
        ld asym = 0;
        const MatL<D> mm = psd ? ref_dforce_nsd<D>(mat, p, &refp, g, &asym)
                               : ref_dforce<D>(mat, p, &refp, g);
        if (psd)  // the reference operator is symmetric to its own (long-double) rounding
          AMPM_CHECK(ck, asym <= 1e-12L, "%s reference operator asymmetry %.3Le", A::name, asym);
        for (int r = 0; r < K; ++r) {
          const Vec want = mm * s.grad[r];
          for (int a = 0; a < D; ++a)
            ref[a].add(box.at(s.node[r]), want(a), p.v0 * (mu + 1 / il) * g.norm() * 4 / h);
        }
      }
      for (int a = 0; a < D; ++a)
        for (std::size_t k = 0; k < nn; ++k)
          close(psd ? "force differential (NSD)" : "force differential", k, df[a][k],
                ref[a].sum[k], ref[a].scale[k], Sn);

      // Per particle (one-particle applies), random du on its stencil: du·df = G:M(G) ≤ 0
      // with the projection, to 256·ε of V⁰(μ + λ)·4·g_abs², g_abs = Σ_j |du_j||∇w_j|.
      if (psd) {
        for (std::size_t i = 0; i < n; ++i) {
          const RefParticle<D> p = soa.get(i);
          const RefStencil<D> s = ref_stencil<D>(kernel, -1, h, p.x);
          const auto [mu, il] = moduli(mat, p);
          for (int trial = 0; trial < 4; ++trial) {
            std::vector<std::vector<T>> u(D, std::vector<T>(nn, 0)), f(D, std::vector<T>(nn, 0));
            ld gabs = 0;
            for (int r = 0; r < K; ++r) {
              const std::size_t k = box.at(s.node[r]);
              for (int a = 0; a < D; ++a) u[a][k] = static_cast<T>(rng.uniform(-1, 1));
              Vec uu;
              for (int a = 0; a < D; ++a) uu(a) = u[a][k];
              gabs += uu.norm() * s.grad[r].norm();
            }
            typename A::ForceView one{};
            one.nodes = box.c();
            for (int a = 0; a < D; ++a) {
              one.du[a] = channel<CCh>(static_cast<const T*>(u[a].data()), box);
              one.df[a] = channel<Ch>(f[a].data(), box);
            }
            std::size_t f1 = 999;
            AMPM_CHECK_STATUS(ck, (A::apply(kernel, h, 1, soa.x.data() + D * i,
                                            slots.data() + sl * i, &one, &f1)),
                              AMPM_OK);
            ld dot = 0;
            for (int a = 0; a < D; ++a)
              for (std::size_t k = 0; k < nn; ++k)
                dot += static_cast<ld>(u[a][k]) * static_cast<ld>(f[a][k]);
            const ld tol = 256 * eps * p.v0 * (mu + 1 / il) * 4 * gabs * gabs;
            AMPM_CHECK(ck, dot <= tol, "%s NSD differential particle %zu: du.df = %.3Le > %.3Le",
                       A::name, i, dot, tol);
          }
        }
      }
    }

    // Slots that no successful prepare wrote: zero-filled memory, and the slot of a particle
    // whose prepare failed, are refused with AMPM_ERR_NOT_PREPARED; the other particles apply.
    {
      std::vector<T> slots(n * sl, T(0));
      std::vector<std::vector<T>> df(D, std::vector<T>(nn, 0));
      typename A::ForceView fv{};
      fv.nodes = box.c();
      for (int a = 0; a < D; ++a) {
        fv.du[a] = channel<CCh>(static_cast<const T*>(du[a].data()), box);
        fv.df[a] = channel<Ch>(df[a].data(), box);
      }
      std::size_t first = 999;
      AMPM_CHECK_STATUS(ck, (A::apply(kernel, h, n, soa.x.data(), slots.data(), &fv, &first)),
                        AMPM_ERR_NOT_PREPARED);
      AMPM_CHECK(ck, first == 0, "%s apply of zero slots: first_failed = %zu", A::name, first);
      Soa<T, D> bad = soa;
      bad.fe[D * D * 2] = std::numeric_limits<T>::quiet_NaN();
      auto bp = bad.ptrs();
      first = 999;
      AMPM_CHECK_STATUS(ck, (A::prepare(&cm, n, &bp, slots.data(), &first)), AMPM_ERR_NON_FINITE);
      AMPM_CHECK(ck, first == 2, "%s prepare with NaN F_E: first_failed = %zu", A::name, first);
      first = 999;
      AMPM_CHECK_STATUS(ck, (A::apply(kernel, h, n, soa.x.data(), slots.data(), &fv, &first)),
                        AMPM_ERR_NOT_PREPARED);
      AMPM_CHECK(ck, first == 2, "%s apply after a failed prepare: first_failed = %zu", A::name,
                 first);
      ld total = 0;
      for (int a = 0; a < D; ++a)
        for (T x : df[a]) total += std::fabs(static_cast<ld>(x));
      AMPM_CHECK(ck, total > 0, "%s apply after a failed prepare wrote nothing", A::name);
    }
  }

  // ---- pressure and coefficient ----
  {
    std::vector<T> pr(n, sentinel<T>()), co(n, sentinel<T>());
    std::size_t first = 999;
    AMPM_CHECK_STATUS(ck, (A::pressure(&cm, dt, n, &ps, pr.data(), co.data(), &first)), AMPM_OK);
    for (std::size_t i = 0; i < n; ++i) {
      const RefParticle<D> p = soa.get(i);
      const auto [mu, il] = moduli(mat, p);
      (void)mu;
      const ld je = p.fe.determinant(), jp = p.fp.determinant();
      close("pressure", i, pr[i], -(je - 1) / (il * jp), 1 / il, C);
      close("coefficient", i, co[i], jp * il / (dt * je), il / dt, C);
    }
  }

  // ---- G2P and the particle update ----
  // Node velocities random in [−1, 1]; on the nodes of the last particle's stencils the field
  // v = (−a x, 0, …) with a·Δt = 3, so det(I + Δt∇v) = −2 and the remedy must act. Node
  // temperatures T^(n+1) random in [265, 285], T^n within 2 K of them. Nodes that no stencil
  // reaches hold NaN: the library must not read them.
  {
    const ld nan = std::numeric_limits<ld>::quiet_NaN();
    const ld a_rem = 3.0L / dt;
    // Collocated velocities and temperatures.
    std::vector<std::vector<T>> vel(D, std::vector<T>(nn, static_cast<T>(nan)));
    std::vector<T> tn(nn, static_cast<T>(nan)), to(nn, static_cast<T>(nan));
    std::vector<char> reached(nn, 0), remedy(nn, 0);
    for (std::size_t i = 0; i < n; ++i) {
      const RefStencil<D> s = ref_stencil<D>(kernel, -1, h, soa.get(i).x);
      for (int r = 0; r < K; ++r) {
        reached[box.at(s.node[r])] = 1;
        if (i == n - 1) remedy[box.at(s.node[r])] = 1;
      }
    }
    for (std::size_t k = 0; k < nn; ++k) {
      if (!reached[k]) continue;
      for (int a = 0; a < D; ++a) vel[a][k] = static_cast<T>(rng.uniform(-1, 1));
      if (remedy[k]) {
        vel[0][k] = static_cast<T>(-a_rem * box.node(k)[0] * static_cast<ld>(h));
        for (int a = 1; a < D; ++a) vel[a][k] = 0;
      }
      tn[k] = static_cast<T>(rng.uniform(265, 285));
      to[k] = static_cast<T>(tn[k] - rng.uniform(-2, 2));
    }
    // MAC face velocities, each on its own face box, the same construction.
    std::vector<Box<D>> fbox(D);
    std::vector<std::vector<T>> fvel(D);
    for (int g = 0; g < D; ++g) {
      fbox[g] = ref_box<T, D>(soa, n, kernel, g, h);
      for (int a = 0; a < D; ++a) fbox[g].lo[a] -= 1, fbox[g].dims[a] += 2;
      fvel[g].assign(fbox[g].count(), static_cast<T>(nan));
      for (std::size_t i = 0; i < n; ++i) {
        const RefStencil<D> s = ref_stencil<D>(kernel, g, h, soa.get(i).x);
        for (int r = 0; r < K; ++r) {
          const std::size_t k = fbox[g].at(s.node[r]);
          if (i == n - 1)
            fvel[g][k] = g == 0 ? static_cast<T>(-a_rem * s.node[r][0] * static_cast<ld>(h)) : T(0);
          else
            fvel[g][k] = static_cast<T>(rng.uniform(-1, 1));
        }
      }
    }

    typename A::G2pView gv{};
    gv.nodes = box.c();
    for (int a = 0; a < D; ++a) gv.velocity[a] = channel<CCh>(static_cast<const T*>(vel[a].data()), box);
    gv.temperature = channel<CCh>(static_cast<const T*>(tn.data()), box);
    gv.temperature_old = channel<CCh>(static_cast<const T*>(to.data()), box);
    std::vector<typename A::G2pView> faces(D);
    for (int g = 0; g < D; ++g) {
      faces[g] = typename A::G2pView{};
      faces[g].nodes = fbox[g].c();
      faces[g].velocity[g] = channel<CCh>(static_cast<const T*>(fvel[g].data()), fbox[g]);
    }
    typename A::G2pView thermal{};
    thermal.nodes = box.c();
    thermal.temperature = gv.temperature;
    thermal.temperature_old = gv.temperature_old;

    const Soa<T, D> before = soa;
    for (const bool mac : {false, true}) {
      soa = before;
      ps = soa.ptrs();
      std::size_t first = 999;
      if (mac)
        AMPM_CHECK_STATUS(ck, (A::g2p_mac(&cm, kernel, h, dt, n, &ps, faces.data(), &thermal,
                                          &first)),
                          AMPM_OK);
      else
        AMPM_CHECK_STATUS(ck, (A::g2p(&cm, kernel, h, dt, n, &ps, &gv, &first)), AMPM_OK);
      AMPM_CHECK(ck, first == n, "%s g2p (mac %d): first_failed = %zu", A::name, int(mac), first);
      const char* what = mac ? "MAC" : "collocated";
      for (std::size_t i = 0; i < n; ++i) {
        const RefParticle<D> in = before.get(i);
        RefSample<D> smp;
        const ld kap = kernel == AMPM_KERNEL_QUADRATIC ? 0.25L : 1.0L / 3.0L;
        for (int c = 0; c < D; ++c) {
          const RefStencil<D> s = ref_stencil<D>(kernel, mac ? c : -1, h, in.x);
          for (int r = 0; r < K; ++r) {
            const ld q = mac ? static_cast<ld>(fvel[c][fbox[c].at(s.node[r])])
                             : static_cast<ld>(vel[c][box.at(s.node[r])]);
            smp.v(c) += s.w[r] * q;
            smp.c.row(c) += s.w[r] * q * s.dx[r].transpose() / (kap * h * h);
            smp.gv.row(c) += q * s.grad[r].transpose();
          }
        }
        const RefStencil<D> s = ref_stencil<D>(kernel, -1, h, in.x);
        for (int r = 0; r < K; ++r) {
          const std::size_t k = box.at(s.node[r]);
          smp.t_pic += s.w[r] * tn[k];
          smp.t_flip += s.w[r] * (static_cast<ld>(tn[k]) - to[k]);
        }
        const RefParticle<D> want = ref_update<D>(mat, dt, in, smp);
        const RefParticle<D> got = soa.get(i);
        AMPM_CHECK(ck, got.phase == want.phase, "%s %s particle %zu: phase %d, want %d", A::name,
                   what, i, got.phase, want.phase);
        const ld vs = 1 + (i == n - 1 ? 3 / dt * 4 : 0);
        for (int a = 0; a < D; ++a) {
          close("v", i, got.v(a), want.v(a), vs, C);
          close("x", i, got.x(a), want.x(a), 6 + dt * vs, C);
        }
        close("affine", i, (got.c - want.c).norm(), 0, vs / h, C);
        close("F_E", i, (got.fe - want.fe).norm(), 0, 1, C);
        close("F_P", i, (got.fp - want.fp).norm(), 0, 1, C);
        AMPM_CHECK(ck, got.fe.determinant() > 0 && got.fp.determinant() > 0,
                   "%s %s particle %zu: J_E or J_P <= 0", A::name, what, i);
        if (got.phase == 1) {
          const MatL<D> off = got.fp - got.fp.trace() / D * MatL<D>::Identity();
          AMPM_CHECK(ck, off.norm() == 0, "%s %s liquid particle %zu: F_P not a multiple of I",
                     A::name, what, i);
        }
        close("temperature", i, got.t, want.t, 300, C);
        close("latent", i, got.u, want.u, 100, C);
        // J = J_E J_P changes by det(I + Δt∇v) only: away from the remedy ≈ 1 + O(Δt|∇v|).
        const ld j_in = in.fe.determinant() * in.fp.determinant();
        const ld j_out = got.fe.determinant() * got.fp.determinant();
        if (i != n - 1)
          AMPM_CHECK(ck, std::fabs(j_out / j_in - 1) < 0.05L, "%s %s particle %zu: J jumped",
                     A::name, what, i);
      }
      // The remedy's particle: k = 1 gives det = (1 − 3/2)² = 1/4.
      const RefParticle<D> in = before.get(n - 1), got = soa.get(n - 1);
      close("remedy J_E ratio", n - 1, got.fe.determinant() / in.fe.determinant(), 0.25L, 1,
            4 * C);
    }

    // Batch contract: a failed particle is left as it was, the others are computed.
    {
      Soa<T, D> bad = before;
      bad.fe[D * D * 3] = std::numeric_limits<T>::quiet_NaN();
      bad.ph[5] = 7;  // invalid phase code
      auto bp = bad.ptrs();
      const Soa<T, D> keep = bad;
      std::size_t first = 999;
      AMPM_CHECK_STATUS(ck, (A::g2p(&cm, kernel, h, dt, n, &bp, &gv, &first)),
                        AMPM_ERR_NON_FINITE);
      AMPM_CHECK(ck, first == 3, "%s: first_failed = %zu, want 3", A::name, first);
      for (std::size_t i : {std::size_t(3), std::size_t(5)}) {
        AMPM_CHECK(ck, same_bits(&bad.x[D * i], &keep.x[D * i], D) &&
                           same_bits(&bad.fe[D * D * i], &keep.fe[D * D * i], D * D) &&
                           same_bits(&bad.t[i], &keep.t[i], 1) && bad.ph[i] == keep.ph[i],
                   "%s: failed particle %zu modified", A::name, i);
      }
      AMPM_CHECK(ck, !same_bits(&bad.x[0], &keep.x[0], D), "%s: particle 0 not updated", A::name);
    }
    // A non-finite node value inside a stencil fails that particle only.
    {
      Soa<T, D> s2 = before;
      auto sp = s2.ptrs();
      std::vector<T> v0 = vel[0];
      const RefStencil<D> s = ref_stencil<D>(kernel, -1, h, before.get(4).x);
      v0[box.at(s.node[K / 2])] = std::numeric_limits<T>::infinity();
      typename A::G2pView g2 = gv;
      g2.velocity[0] = channel<CCh>(static_cast<const T*>(v0.data()), box);
      std::size_t first = 999;
      AMPM_CHECK_STATUS(ck, (A::g2p(&cm, kernel, h, dt, n, &sp, &g2, &first)),
                        AMPM_ERR_NON_FINITE);
      AMPM_CHECK(ck, first <= 4, "%s non-finite node: first_failed = %zu", A::name, first);
      AMPM_CHECK(ck, same_bits(&s2.x[D * 4], &before.x[D * 4], D),
                 "%s: particle 4 moved despite an infinite node velocity", A::name);
    }
    // Whole-call errors and n = 0.
    {
      typename A::Particles nul{};
      std::size_t first = 999;
      AMPM_CHECK_STATUS(ck, (A::g2p(&cm, kernel, h, dt, 0, &nul, &gv, &first)), AMPM_OK);
      AMPM_CHECK(ck, first == 0, "%s n = 0: first_failed = %zu", A::name, first);
      first = 999;
      AMPM_CHECK_STATUS(ck, (A::g2p(&cm, kernel, h, dt, 1, &nul, &gv, &first)),
                        AMPM_ERR_NULL_POINTER);
      AMPM_CHECK(ck, first == 0, "%s NULL arrays: first_failed = %zu", A::name, first);
      Soa<T, D> s2 = before;
      auto sp = s2.ptrs();
      typename A::G2pView g2 = gv;
      g2.velocity[D - 1].data = nullptr;
      AMPM_CHECK_STATUS(ck, (A::g2p(&cm, kernel, h, dt, n, &sp, &g2, nullptr)),
                        AMPM_ERR_NULL_POINTER);
      AMPM_CHECK(ck, same_bits(s2.x.data(), before.x.data(), s2.x.size()),
                 "%s: a whole-call error wrote particles", A::name);
    }
  }
}

}  // namespace

int main() {
  Checker ck;
  std::vector<std::uint32_t> isas{AMPM_ISA_SCALAR};
  for (std::uint32_t isa : simd_isas()) isas.push_back(isa);
  for (std::uint32_t isa : isas) {
    const IsaRestore keep;
    AMPM_CHECK_STATUS(ck, ampm_set_isa(isa), AMPM_OK);
    std::printf("instruction set %s\n", isa_name(isa));
    for (bool ps : {false, true}) {
      run<float, 2>(ck, ps);
      run<double, 2>(ck, ps);
      run<float, 3>(ck, ps);
      run<double, 3>(ck, ps);
    }
  }
  ck.summary("test_particle_eigen");
  return ck.exit_code();
}
