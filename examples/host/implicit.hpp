// Backward Euler on the grid (Stomakhin et al. 2013, §4.2; ampm.h, ampm_force_apply_*): with
// node masses m_i and v*_i = (p_i + Δt f_i)/m_i + Δt g (the P2G impulse form plus gravity,
// walls applied), solve one linearised step
//   (M − Δt² K) v = M v*,   (A u)_i = m_i u_i − Δt·df_i,   df = K du,  du = Δt·u,
// where K = ∂f/∂x̂ is the stiffness of the prepared particles (ampm_force_prepare_* once per
// step, ampm_force_apply_* once per iteration). With AMPM_MODEL_PSD_HESSIAN, K is negative
// semi-definite, so A is symmetric positive definite on the nodes with mass, and conjugate
// gradients apply.
//
// Walls: the node components that boundary.hpp constrains (from v*) are fixed at 0 and left out
// of the unknowns: A is replaced by P A P with P the diagonal 0/1 projection, still SPD on the
// free components (projected CG). CG is preconditioned by M (Jacobi on the mass), with the
// stopping test ‖r‖_(M⁻¹) ≤ tol ‖b‖_(M⁻¹), as c_tests/test_implicit_cg.cpp does for one step.
#pragma once

#include <cmath>
#include <cstdint>
#include <vector>

#include "transfer.hpp"

namespace host {

struct CgResult {
  int iterations = 0;
  bool converged = false;
  Real rel_residual = 0;          // recursive, ‖r‖_(M⁻¹)/‖b‖_(M⁻¹)
  long double true_residual[3] = {0, 0, 0};  // Σ_i |b − A v|_a (only if asked)
};

template <int D>
class Implicit {
 public:
  Real tol = 1e-6;
  int max_iterations = 500;

  /// Solves for g.vel (holding v*, walls applied, `mask` the constrained bits per node).
  /// Particles must be sorted into `sl` (as for P2G). `mat` must have AMPM_MODEL_PSD_HESSIAN.
  Failure solve(const Material& mat, Particles<D>& p, Grid<D>& g, const Slabs<D>& sl, Real dt,
                const std::vector<std::uint8_t>& mask, bool want_true_residual, CgResult& res) {
    res = CgResult{};
    Failure f = force_prepare(mat, p, slots_);
    if (!f.ok()) return f;
    const std::size_t nn = g.count;
    free_.assign(nn, 0);
    for (std::size_t k = 0; k < nn; ++k)
      if (g.mass[k] > 0) free_[k] = static_cast<std::uint8_t>(((1u << D) - 1) & ~unsigned(mask[k]));
    for (auto* fld : {&x_, &r_, &z_, &d_, &ad_, &du_, &df_, &b_})
      for (int a = 0; a < D; ++a) (*fld)[a].assign(nn, 0);
    for (int a = 0; a < D; ++a)
      for (std::size_t k = 0; k < nn; ++k)
        if (free_[k] >> a & 1u) x_[a][k] = g.vel[a][k], b_[a][k] = g.mass[k] * g.vel[a][k];
    f = op(p, g, sl, dt, x_, ad_);
    if (!f.ok()) return f;
    for (int a = 0; a < D; ++a)
      for (std::size_t k = 0; k < nn; ++k)
        if (free_[k] >> a & 1u) r_[a][k] = b_[a][k] - ad_[a][k], z_[a][k] = r_[a][k] / g.mass[k];
    d_ = z_;
    Real rz = dot(r_, z_, g);
    const Real bn = std::sqrt(inv_m_dot(b_, g));
    Real rn = std::sqrt(inv_m_dot(r_, g));
    while (!(rn <= tol * bn) && res.iterations < max_iterations) {
      f = op(p, g, sl, dt, d_, ad_);
      if (!f.ok()) return f;
      const Real dad = dot(d_, ad_, g);
      if (!(dad > 0)) break;  // not SPD (cannot happen with the PSD option) or breakdown
      const Real alpha = rz / dad;
      for (int a = 0; a < D; ++a) {
        auto &x = x_[a], &r = r_[a], &z = z_[a];
        const auto &d = d_[a], &ad = ad_[a];
#pragma omp parallel for schedule(static) if (parallel_nodes(g.count))
        for (std::ptrdiff_t k = 0; k < static_cast<std::ptrdiff_t>(nn); ++k)
          if (free_[k] >> a & 1u) x[k] += alpha * d[k], r[k] -= alpha * ad[k], z[k] = r[k] / g.mass[k];
      }
      const Real rz_new = dot(r_, z_, g), beta = rz_new / rz;
      rz = rz_new;
      for (int a = 0; a < D; ++a) {
        auto& d = d_[a];
        const auto& z = z_[a];
#pragma omp parallel for schedule(static) if (parallel_nodes(g.count))
        for (std::ptrdiff_t k = 0; k < static_cast<std::ptrdiff_t>(nn); ++k)
          if (free_[k] >> a & 1u) d[k] = z[k] + beta * d[k];
      }
      rn = std::sqrt(inv_m_dot(r_, g));
      ++res.iterations;
    }
    res.converged = rn <= tol * bn;
    res.rel_residual = bn > 0 ? rn / bn : 0;
    if (want_true_residual) {
      f = op(p, g, sl, dt, x_, ad_);
      if (!f.ok()) return f;
      for (int a = 0; a < D; ++a)
        for (std::size_t k = 0; k < nn; ++k)
          if (free_[k] >> a & 1u) res.true_residual[a] += std::fabs(static_cast<long double>(b_[a][k]) - ad_[a][k]);
    }
    for (int a = 0; a < D; ++a)
      for (std::size_t k = 0; k < nn; ++k) g.vel[a][k] = (free_[k] >> a & 1u) ? x_[a][k] : Real(0);
    return f;
  }

 private:
  std::vector<Real> slots_;
  std::vector<std::uint8_t> free_;
  NodeField<D> x_, r_, z_, d_, ad_, du_, df_, b_;

  /// out = P (M − Δt² K) P u.
  Failure op(Particles<D>& p, const Grid<D>& g, const Slabs<D>& sl, Real dt, const NodeField<D>& u, NodeField<D>& out) {
    const std::size_t nn = g.count;
    for (int a = 0; a < D; ++a) {
      auto& du = du_[a];
      auto& df = df_[a];
      const auto& ua = u[a];
#pragma omp parallel for schedule(static) if (parallel_nodes(g.count))
      for (std::ptrdiff_t k = 0; k < static_cast<std::ptrdiff_t>(nn); ++k)
        du[k] = (free_[k] >> a & 1u) ? dt * ua[k] : Real(0), df[k] = 0;
    }
    Failure f = force_apply<D>(p, g, sl, slots_, du_, df_);
    for (int a = 0; a < D; ++a) {
      auto& o = out[a];
      const auto &ua = u[a], &df = df_[a];
#pragma omp parallel for schedule(static) if (parallel_nodes(g.count))
      for (std::ptrdiff_t k = 0; k < static_cast<std::ptrdiff_t>(nn); ++k)
        o[k] = (free_[k] >> a & 1u) ? g.mass[k] * ua[k] - dt * df[k] : Real(0);
    }
    return f;
  }
  Real dot(const NodeField<D>& x, const NodeField<D>& y, const Grid<D>& g) const {
    Real s = 0;
    for (int a = 0; a < D; ++a) {
      const auto &xa = x[a], &ya = y[a];
#pragma omp parallel for schedule(static) reduction(+ : s) if (parallel_nodes(g.count))
      for (std::ptrdiff_t k = 0; k < static_cast<std::ptrdiff_t>(g.count); ++k)
        if (free_[k] >> a & 1u) s += xa[k] * ya[k];
    }
    return s;
  }
  Real inv_m_dot(const NodeField<D>& x, const Grid<D>& g) const {
    Real s = 0;
    for (int a = 0; a < D; ++a) {
      const auto& xa = x[a];
#pragma omp parallel for schedule(static) reduction(+ : s) if (parallel_nodes(g.count))
      for (std::ptrdiff_t k = 0; k < static_cast<std::ptrdiff_t>(g.count); ++k)
        if (free_[k] >> a & 1u) s += xa[k] * xa[k] / g.mass[k];
    }
    return s;
  }
};

}  // namespace host
