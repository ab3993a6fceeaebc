// The independent long-double reference of the particle transfers (see test_particle_eigen.cpp):
// the material and particle, the B-spline stencils, the stress, and the force differential
// with its projection onto the negative semi-definite part.
#pragma once

#include "common.hpp"

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <array>
#include <vector>

namespace {

using namespace ampm_test;  // the parts of one test file (test_particle_eigen.cpp)

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

}  // namespace
