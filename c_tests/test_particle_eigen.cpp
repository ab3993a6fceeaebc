// Issue 4 (MPM particle updates) from C++/Eigen, through the C ABI only:
//   ampm_stencil_<d>_<p>, ampm_p2g_<d>_<p>, ampm_g2p_update_<d>_<p>,
//   ampm_force_differential_<d>_<p>, ampm_pressure_<d>_<p>
// against an independent long-double Eigen implementation of the same updates written here
// from the papers, sharing no code with the library:
//   - B-spline stencils from the textbook piecewise formulas, positions x_i = (base + o)·h
//     (face grids shifted by h/2), derivatives by the chain rule;
//   - APIC (Jiang et al. 2015): m_i = w m, p_i = w m (v + C (x_i − x_p)), v = Σ w v_i,
//     C = (Σ w v_i (x_i − x_p)ᵀ) / (κ h²), ∇v = Σ v_i ∇w_iᵀ;
//   - the stress from common.hpp's `Reference<D>` (Â of the seed's index formulas) plus the
//     dilational P_λ = λ(J − 1) J F⁻ᵀ, force −V⁰ P Fᵀ ∇w;
//   - F_E ← (I + Δt∇v) F_E with the remedy (I + 2⁻ᵏΔt∇v)^(2ᵏ), Eigen::JacobiSVD for the snow
//     clamp, F_E ← J^(1/d) I for liquids;
//   - heat by the enthalpy method: e = c_s (T − T_m) below the melting point, U at it,
//     L + c_l (T − T_m) above; e += q, then back to (T, U, phase) with the buffer's hysteresis;
//   - the force differential from `Reference<D>::chat_z` plus δP_λ differentiated with
//     inverses (δ(F⁻ᵀ) = −F⁻ᵀ δFᵀ F⁻ᵀ), not the library's simplified form.
//
// Tolerance: C·ε·scale with ε of the precision under test and `scale` the magnitude of the
// terms summed (stated per check). Every library quantity is a short chain (≲ 30 operations,
// sums over ≤ 64 nodes) of backward-stable steps on well-conditioned data (κ(F_E) ≤ 1.3), so
// C = 64 + 2·K^d bounds the accumulated rounding; the stress and Hessian go through an SVD and
// Ĉ's four terms, so they get the 32·ε·κ of test_hessian_eigen.cpp times 8 (the products with
// F_E, ∇w and the sums over the stencil).
#include "common.hpp"

#include <algorithm>
#include <vector>

using namespace ampm_test;

namespace {

template <class T, int D>
struct PartApi;

#define AMPM_PART_API(T, D, S, U)                                         \
  template <>                                                             \
  struct PartApi<T, D> {                                                  \
    static constexpr const char* name = #D "d_" #S;                       \
    static constexpr auto stencil = ampm_stencil_##D##d_##S;              \
    static constexpr auto p2g = ampm_p2g_##D##d_##S;                      \
    static constexpr auto g2p = ampm_g2p_update_##D##d_##S;               \
    static constexpr auto dfd = ampm_force_differential_##D##d_##S;       \
    static constexpr auto pressure = ampm_pressure_##D##d_##S;            \
    using Material = AmpmMaterial##U;                                     \
    using Particles = AmpmParticles##U;                                   \
    using Nodes = AmpmP2gNodes##U;                                        \
    using Samples = AmpmGridSamples##U;                                   \
  };
AMPM_PART_API(float, 2, f32, F32)
AMPM_PART_API(float, 3, f32, F32)
AMPM_PART_API(double, 2, f64, F64)
AMPM_PART_API(double, 3, f64, F64)
#undef AMPM_PART_API

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
  std::vector<ld> w;
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
    for (int a = 0; a < D; ++a) {
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

/// First Piola P = Â + P_λ of F_E.
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

/// G2P update of one particle from the gathered node values.
template <int D>
RefParticle<D> ref_update(const RefMaterial& m, int kernel, ld h, ld dt, RefParticle<D> p,
                          const std::vector<Eigen::Matrix<ld, D, 1>>& vel,
                          const std::vector<ld>& tn, const std::vector<ld>& to) {
  const RefStencil<D> s = ref_stencil<D>(kernel, -1, h, p.x);
  if (m.thermal) {
    ld pic = 0, flip = 0;
    for (int r = 0; r < s.n; ++r) pic += s.w[r] * tn[r], flip += s.w[r] * (tn[r] - to[r]);
    const ld t_star = (1 - m.flip) * pic + m.flip * (p.t + flip);
    if (m.phase_change)
      ref_heat(m, p, (p.phase == 0 ? m.c_s : m.c_l) * (t_star - p.t));
    else
      p.t = t_star;
  }
  const ld kappa = kernel == AMPM_KERNEL_QUADRATIC ? 0.25L : 1.0L / 3.0L;
  Eigen::Matrix<ld, D, 1> v = Eigen::Matrix<ld, D, 1>::Zero();
  MatL<D> b = MatL<D>::Zero(), gv = MatL<D>::Zero();
  for (int r = 0; r < s.n; ++r) {
    v += s.w[r] * vel[r];
    b += s.w[r] * vel[r] * s.dx[r].transpose();
    gv += vel[r] * s.grad[r].transpose();
  }
  p.v = v;
  p.c = b / (kappa * h * h);
  p.x += dt * v;
  const MatL<D> id = MatL<D>::Identity();
  MatL<D> a = id + dt * gv;
  for (int k = 1; a.determinant() <= 0 && k <= 64; ++k) {
    a = id + std::ldexp(dt, -k) * gv;
    for (int i = 0; i < k; ++i) a = a * a;
  }
  p.fe = a * p.fe;
  if (p.phase == 1) {
    const ld j = p.fe.determinant();
    const ld r = D == 2 ? std::sqrt(j) : std::cbrt(j);
    p.fp = p.fe * p.fp / r;
    p.fe = r * id;
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

template <class T, int D>
void run(Checker& ck, bool pressure_solve) {
  using A = PartApi<T, D>;
  using Vec = Eigen::Matrix<ld, D, 1>;
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
  const ld C = 64 + 2 * K;  // see the file comment
  auto close = [&](const char* what, std::size_t i, ld got, ld want, ld scale, ld c) {
    AMPM_CHECK(ck, std::fabs(got - want) <= c * eps * scale,
               "%s %s particle %zu: got %.12Le want %.12Le (tol %.3Le)", A::name, what, i, got,
               want, c * eps * scale);
  };

  // Particles: solids below the melting point or melting, liquids above it or freezing.
  const std::size_t n = 12;
  Soa<T, D> soa;
  for (std::size_t i = 0; i < n; ++i) {
    RefParticle<D> p;
    for (int a = 0; a < D; ++a) p.x(a) = rng.uniform(1.0, 3.0), p.v(a) = rng.uniform(-1, 1);
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

  // Stencils on every grid: weights and gradients.
  for (int grid = -1; grid < D; ++grid) {
    std::vector<std::int32_t> base(n * D);
    std::vector<T> w(n * K), gw(n * K * D);
    std::size_t first = 999;
    AMPM_CHECK_STATUS(ck, (A::stencil(n, kernel, grid, h, soa.x.data(), base.data(), w.data(),
                                      gw.data(), &first)),
                      AMPM_OK);
    AMPM_CHECK(ck, first == n, "%s stencil: first_failed = %zu", A::name, first);
    for (std::size_t i = 0; i < n; ++i) {
      const RefStencil<D> s = ref_stencil<D>(kernel, grid, h, soa.get(i).x);
      for (int a = 0; a < D; ++a)
        AMPM_CHECK(ck, base[D * i + a] == s.base[a], "%s stencil base", A::name);
      for (int r = 0; r < K; ++r) {
        // x/h carries ε·|x/h| ≤ 6ε of rounding, amplified by |N'| ≤ 1 per axis.
        close("weight", i, w[K * i + r], s.w[r], 1 + 6 * D, C);
        for (int a = 0; a < D; ++a)
          close("grad weight", i, gw[(K * i + r) * D + a], s.grad[r](a), (1 + 6 * D) / h, C);
      }
    }
  }

  // P2G.
  {
    std::vector<std::int32_t> base(n * D);
    std::vector<T> nm(n * K), nmom(n * K * D), nf(n * K * D), nc(n * K), ne(n * K), nk(n * K);
    typename A::Nodes nodes{base.data(), nullptr,   nm.data(), nmom.data(),
                            nf.data(),   nc.data(), ne.data(), nk.data()};
    std::size_t first = 999;
    AMPM_CHECK_STATUS(ck, (A::p2g(n, &cm, kernel, h, &ps, &nodes, &first)), AMPM_OK);
    for (std::size_t i = 0; i < n; ++i) {
      const RefParticle<D> p = soa.get(i);
      const RefStencil<D> s = ref_stencil<D>(kernel, -1, h, p.x);
      const MatL<D> pk = ref_piola<D>(mat, p);
      const MatL<D> tau = pk * p.fe.transpose();
      const ld c = p.phase == 0 ? mat.c_s : mat.c_l;
      const ld vs = p.v.norm() + p.c.norm() * 2 * h;
      // Stress errors are absolute in units of the moduli (J_E − 1 cancels near 1).
      const auto [mu, il] = moduli(mat, p);
      const ld ts = tau.norm() + mu + 1 / il;
      MatL<D> tau_lib = MatL<D>::Zero();  // −(1/V⁰) Σ f_i (x_i − x_p)ᵀ = τ, as Σ ∇w dxᵀ = I
      for (int r = 0; r < K; ++r) {
        const std::size_t j = K * i + r;
        close("node mass", i, nm[j], s.w[r] * p.m, p.m, C);
        const Vec mom = s.w[r] * p.m * (p.v + p.c * s.dx[r]);
        const Vec f = -p.v0 * tau * s.grad[r];
        for (int a = 0; a < D; ++a) {
          close("node momentum", i, nmom[j * D + a], mom(a), p.m * vs, C);
          close("node force", i, nf[j * D + a], f(a), p.v0 * ts / h, 256);
        }
        Vec fl;
        for (int a = 0; a < D; ++a) fl(a) = nf[j * D + a];
        tau_lib -= fl * s.dx[r].transpose() / p.v0;
        close("node heat capacity", i, nc[j], s.w[r] * p.m * c, p.m * c, C);
        close("node thermal energy", i, ne[j], s.w[r] * p.m * c * p.t, p.m * c * p.t, C);
        const ld kap = p.phase == 0 ? mat.k_s : mat.k_l;
        close("node conductivity", i, nk[j], s.w[r] * p.m * kap, p.m * kap, C);
      }
      // The library's stress of a liquid is isotropic: no deviatoric part.
      if (p.phase == 1) {
        const MatL<D> dev = tau_lib - tau_lib.trace() / D * MatL<D>::Identity();
        AMPM_CHECK(ck, dev.norm() <= 4 * C * eps * ts, "%s liquid deviatoric stress %.3Le",
                   A::name, dev.norm());
      }
    }
  }

  // Force differential, and with the PSD projection: δu·δf ≤ 0.
  {
    std::vector<T> du(n * K * D), df(n * K * D, sentinel<T>());
    for (auto& x : du) x = static_cast<T>(rng.uniform(-1e-3, 1e-3));
    std::size_t first = 999;
    AMPM_CHECK_STATUS(ck, (A::dfd(n, &cm, kernel, h, &ps, du.data(), df.data(), &first)),
                      AMPM_OK);
    for (std::size_t i = 0; i < n; ++i) {
      const RefParticle<D> p = soa.get(i);
      const RefStencil<D> s = ref_stencil<D>(kernel, -1, h, p.x);
      MatL<D> g = MatL<D>::Zero();
      for (int r = 0; r < K; ++r) {
        Vec u;
        for (int a = 0; a < D; ++a) u(a) = du[(K * i + r) * D + a];
        g += u * s.grad[r].transpose();
      }
      const MatL<D> dF = g * p.fe;
      const auto [mu, il] = moduli(mat, p);
      MatL<D> dp = MatL<D>::Zero();
      if (mu > 0) dp += Reference<D>(mu, p.fe).chat_z(dF);
      if (!mat.pressure_solve) {
        const ld j = p.fe.determinant();
        const MatL<D> hm = p.fe.inverse().transpose();
        const ld dj = j * (p.fe.inverse() * dF).trace();
        dp += (2 * j - 1) * dj / il * hm - (j - 1) * j / il * hm * dF.transpose() * hm;
      }
      const MatL<D> mm = -p.v0 * dp * p.fe.transpose();
      for (int r = 0; r < K; ++r) {
        const Vec want = mm * s.grad[r];
        for (int a = 0; a < D; ++a)
          close("force differential", i, df[(K * i + r) * D + a], want(a),
                p.v0 * (mu + 1 / il) * g.norm() * 4 / h, 256);
      }
    }
    if (pressure_solve) {
      auto psd = cm;
      psd.model |= AMPM_MODEL_PSD_HESSIAN;
      AMPM_CHECK_STATUS(ck, (A::dfd(n, &psd, kernel, h, &ps, du.data(), df.data(), &first)),
                        AMPM_OK);
      for (std::size_t i = 0; i < n; ++i) {
        ld dot = 0, scale = 0;
        for (int k = 0; k < K * D; ++k) {
          dot += static_cast<ld>(du[K * D * i + k]) * df[K * D * i + k];
          scale += std::fabs(static_cast<ld>(du[K * D * i + k]) * df[K * D * i + k]);
        }
        AMPM_CHECK(ck, dot <= C * eps * scale, "%s PSD differential: du.df = %.3Le > 0", A::name,
                   dot);
      }
    }
  }

  // Pressure and coefficient.
  {
    std::vector<T> pr(n, sentinel<T>()), co(n, sentinel<T>());
    std::size_t first = 999;
    AMPM_CHECK_STATUS(ck, (A::pressure(n, &cm, dt, &ps, pr.data(), co.data(), &first)), AMPM_OK);
    for (std::size_t i = 0; i < n; ++i) {
      const RefParticle<D> p = soa.get(i);
      const auto [mu, il] = moduli(mat, p);
      (void)mu;
      const ld je = p.fe.determinant(), jp = p.fp.determinant();
      close("pressure", i, pr[i], -(je - 1) / (il * jp), 1 / il, C);
      close("coefficient", i, co[i], jp * il / (dt * je), il / dt, C);
    }
  }

  // G2P update; particle n − 1 gets a velocity field that inverts it without the remedy.
  {
    std::vector<T> vel(n * K * D), tn(n * K), to(n * K);
    for (std::size_t i = 0; i < n; ++i) {
      const RefStencil<D> s = ref_stencil<D>(kernel, -1, h, soa.get(i).x);
      for (int r = 0; r < K; ++r) {
        for (int a = 0; a < D; ++a)
          vel[(K * i + r) * D + a] = static_cast<T>(rng.uniform(-1, 1));
        if (i == n - 1) {  // v = (−a x₀, 0, …) with a·Δt = 3: det(I + Δt∇v) = −2
          const ld x0 = soa.get(i).x(0) + s.dx[r](0);
          vel[(K * i + r) * D] = static_cast<T>(-3.0L / dt * x0);
          for (int a = 1; a < D; ++a) vel[(K * i + r) * D + a] = 0;
        }
        tn[K * i + r] = static_cast<T>(rng.uniform(265, 285));
        to[K * i + r] = static_cast<T>(tn[K * i + r] - rng.uniform(-2, 2));
      }
    }
    Soa<T, D> before = soa;
    typename A::Samples gs{vel.data(), tn.data(), to.data()};
    std::size_t first = 999;
    AMPM_CHECK_STATUS(ck, (A::g2p(n, &cm, kernel, h, dt, &ps, &gs, &first)), AMPM_OK);
    for (std::size_t i = 0; i < n; ++i) {
      std::vector<Vec> v(K);
      std::vector<ld> tnl(K), tol(K);
      for (int r = 0; r < K; ++r) {
        for (int a = 0; a < D; ++a) v[r](a) = vel[(K * i + r) * D + a];
        tnl[r] = tn[K * i + r], tol[r] = to[K * i + r];
      }
      const RefParticle<D> in = before.get(i);
      const RefParticle<D> want = ref_update<D>(mat, kernel, h, dt, in, v, tnl, tol);
      const RefParticle<D> got = soa.get(i);
      AMPM_CHECK(ck, got.phase == want.phase, "%s particle %zu: phase %d, want %d", A::name, i,
                 got.phase, want.phase);
      const ld vs = 1 + (i == n - 1 ? 3 / dt * 4 : 0);
      for (int a = 0; a < D; ++a) {
        close("v", i, got.v(a), want.v(a), vs, C);
        close("x", i, got.x(a), want.x(a), 4 + dt * vs, C);
      }
      close("affine", i, (got.c - want.c).norm(), 0, vs / h, C);
      close("F_E", i, (got.fe - want.fe).norm(), 0, 1, C);
      close("F_P", i, (got.fp - want.fp).norm(), 0, 1, C);
      AMPM_CHECK(ck, got.fe.determinant() > 0, "%s particle %zu: J_E <= 0", A::name, i);
      close("temperature", i, got.t, want.t, 300, C);
      close("latent", i, got.u, want.u, 100, C);
      // J = J_E J_P: the update moved no volume between F_E and F_P beyond F's own change.
      const ld j_in = in.fe.determinant() * in.fp.determinant();
      const ld j_out = got.fe.determinant() * got.fp.determinant();
      if (i != n - 1) {
        // Away from the remedy, J changes by det(I + Δt∇v) ≈ 1 + O(Δt·|∇v|): ≤ 5%.
        AMPM_CHECK(ck, std::fabs(j_out / j_in - 1) < 0.05L, "%s particle %zu: J jumped", A::name,
                   i);
      }
    }
    // The remedy's particle: k = 1 gives det = (1 − 3/2)² = 1/4.
    const RefParticle<D> in = before.get(n - 1), got = soa.get(n - 1);
    close("remedy J_E ratio", n - 1, got.fe.determinant() / in.fe.determinant(), 0.25L, 1, 4 * C);
  }

  // A failed particle is left as it was; the others are computed; n = 0 accepts NULLs.
  {
    Soa<T, D> bad = soa;
    bad.fe[D * D * 3] = std::numeric_limits<T>::quiet_NaN();
    bad.ph[5] = 7;  // invalid phase code
    auto bp = bad.ptrs();
    const Soa<T, D> keep = bad;
    std::vector<T> vel(n * K * D, static_cast<T>(0.1)), tn(n * K, 280), to(n * K, 280);
    typename A::Samples gs{vel.data(), tn.data(), to.data()};
    std::size_t first = 999;
    AMPM_CHECK_STATUS(ck, (A::g2p(n, &cm, kernel, h, dt, &bp, &gs, &first)), AMPM_ERR_NON_FINITE);
    AMPM_CHECK(ck, first == 3, "%s: first_failed = %zu, want 3", A::name, first);
    for (std::size_t i : {std::size_t(3), std::size_t(5)}) {
      AMPM_CHECK(ck, same_bits(&bad.x[D * i], &keep.x[D * i], D) &&
                         same_bits(&bad.fe[D * D * i], &keep.fe[D * D * i], D * D) &&
                         same_bits(&bad.t[i], &keep.t[i], 1) && bad.ph[i] == keep.ph[i],
                 "%s: failed particle %zu modified", A::name, i);
    }
    AMPM_CHECK(ck, !same_bits(&bad.x[0], &keep.x[0], D), "%s: particle 0 not updated", A::name);
    typename A::Particles nul{};
    typename A::Samples gnul{};
    first = 999;
    AMPM_CHECK_STATUS(ck, (A::g2p(0, &cm, kernel, h, dt, &nul, &gnul, &first)), AMPM_OK);
    AMPM_CHECK(ck, first == 0, "%s n = 0: first_failed = %zu", A::name, first);
    AMPM_CHECK_STATUS(ck, (A::g2p(1, &cm, kernel, h, dt, &nul, &gnul, nullptr)),
                      AMPM_ERR_NULL_POINTER);
  }
}

}  // namespace

int main() {
  Checker ck;
  for (bool ps : {false, true}) {
    run<float, 2>(ck, ps);
    run<double, 2>(ck, ps);
    run<float, 3>(ck, ps);
    run<double, 3>(ck, ps);
  }
  ck.summary("test_particle_eigen");
  return ck.exit_code();
}
