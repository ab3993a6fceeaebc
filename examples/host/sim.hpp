// The step loop: one Sim<D> owns its grid, particles, walls, heat parameters and stepper.
//   sort by cell → P2G (impulse form, coloured slabs) → node velocities + gravity → walls →
//   [implicit: backward Euler + CG on the force differential] → heat solve → G2P and the
//   particle update (positions, F_E, plasticity, temperature, phase change: all the library's)
// StepInfo reports what the tests check (grid mass and momentum after P2G, whether the material
// touched a wall, the heat step's flux, CG's result).
#pragma once

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "boundary.hpp"
#include "heat.hpp"
#include "implicit.hpp"
#include "transfer.hpp"

namespace host {

enum class Stepper { Explicit, Implicit };

struct StepInfo {
  Failure fail;
  long double grid_mass = 0;                 // Σ_i m_i after P2G
  long double grid_mom[3] = {0, 0, 0};       // Σ_i (m v + Δt f)_i after P2G
  long double grid_mom_new[3] = {0, 0, 0};   // Σ_i m_i v_i after the grid update
  bool touched = false;                      // some node with mass was constrained by a wall
  HeatStep heat;
  CgResult cg;
  int max_per_cell = 0;
};

template <int D>
struct Sim {
  Grid<D> g;
  Particles<D> p;
  Slabs<D> slabs;
  Material mat;
  Walls walls;
  HeatParams heat;
  Real gravity[3] = {0, -9.81, 0};
  Stepper stepper = Stepper::Explicit;
  Implicit<D> implicit;
  Real cfl_wave = 0.3;  // explicit: Δt ≤ cfl_wave·h/c, c the (hardened) P-wave speed
  Real cfl_move = 0.5;  // both: Δt ≤ cfl_move·h/max|v_p| (no particle crosses half a cell)
  Real dt_cap = 1e-2;   // largest step a scene allows
  Real time = 0;
  long steps = 0;
  long clamped = 0;     // particles pushed back inside the grid (should stay 0)
  bool want_true_residual = false;

  bool thermal() const { return (mat.c().model & AMPM_MODEL_THERMAL) != 0; }

  /// Largest P-wave speed (m/s): √((λ_h + 2μ_h)/ρ_p), hardened moduli of plastic solids.
  Real wave_speed() const {
    Real c2 = 0;
    const auto& m = mat.c();
    const bool plastic = (m.model & AMPM_MODEL_PLASTIC) != 0;
    for (std::size_t k = 0; k < p.n; ++k) {
      const auto& ph = p.ph[k] == AMPM_PHASE_LIQUID ? m.liquid : m.solid;
      const Real lambda = ph.inv_lambda > 0 ? 1 / ph.inv_lambda : 0;
      Real hard = 1;
      if (plastic && p.ph[k] == AMPM_PHASE_SOLID) hard = std::exp(m.hardening * (1 - p.j_p(k)));
      c2 = std::max(c2, hard * (lambda + 2 * ph.mu) * p.v0[k] / p.m[k]);
    }
    return std::sqrt(c2);
  }
  Real max_speed() const {
    Real v2 = 0;
    for (std::size_t k = 0; k < p.n; ++k) {
      Real s = 0;
      for (int a = 0; a < D; ++a) s += p.v[D * k + a] * p.v[D * k + a];
      v2 = std::max(v2, s);
    }
    return std::sqrt(v2);
  }
  /// The step the scene runs with (capped by `remaining`, the time to the next frame).
  Real suggest_dt(Real remaining) const {
    Real dt = std::min(dt_cap, remaining);
    const Real v = max_speed();
    if (v > 0) dt = std::min(dt, cfl_move * g.h / v);
    if (stepper == Stepper::Explicit) dt = std::min(dt, cfl_wave * g.h / wave_speed());
    return dt;
  }

  /// One step of Δt. On failure the particles may be partly updated (the library leaves a
  /// failed particle unchanged); the caller stops.
  StepInfo step(Real dt) {
    StepInfo info;
    if (!slabs.build(p, g)) {
      info.fail.status = AMPM_ERR_OUTSIDE_GRID, info.fail.what = "particle outside the grid";
      return info;
    }
    info.max_per_cell = slabs.max_per_cell;
    info.fail = slabs.ranges(p, g);
    if (!info.fail.ok()) return info;
    const bool th = thermal();
    g.clear(th);
    info.fail = p2g(mat, dt, p, g, slabs, th);
    if (!info.fail.ok()) return info;
    for (std::size_t k = 0; k < g.count; ++k) {
      info.grid_mass += g.mass[k];
      for (int a = 0; a < D; ++a) info.grid_mom[a] += g.mom[a][k];
    }
    velocities(g, dt, gravity);
    info.touched = apply_walls(g, walls, &mask_);
    if (stepper == Stepper::Implicit) {
      info.fail = implicit.solve(mat, p, g, slabs, dt, mask_, want_true_residual, info.cg);
      if (!info.fail.ok()) return info;
      if (!info.cg.converged) {
        info.fail.status = AMPM_ERR_NOT_CONVERGED, info.fail.what = "CG (host)";
        return info;
      }
      apply_walls(g, walls, nullptr);
    }
    for (std::size_t k = 0; k < g.count; ++k)
      for (int a = 0; a < D; ++a) info.grid_mom_new[a] += static_cast<long double>(g.mass[k]) * g.vel[a][k];
    if (th) info.heat = heat_step(g, dt, heat);
    info.fail = g2p(mat, dt, p, g, th);
    if (!info.fail.ok()) return info;
    // Safety net: keep every stencil inside the grid (x in [h, (res − 1) h]).
    const Real lo = g.h, hi = (g.res - 1) * g.h;
    for (std::size_t k = 0; k < D * p.n; ++k)
      if (p.x[k] < lo || p.x[k] > hi) p.x[k] = std::clamp(p.x[k], lo, hi), ++clamped;
    time += dt;
    ++steps;
    return info;
  }

  /// Every particle field finite and J_E, J_P > 0 (what a host must check each step).
  bool sane(std::string* why) const {
    for (std::size_t k = 0; k < p.n; ++k) {
      bool fin = std::isfinite(p.t[k]) && std::isfinite(p.u[k]);
      for (int a = 0; a < D; ++a) fin = fin && std::isfinite(p.x[D * k + a]) && std::isfinite(p.v[D * k + a]);
      for (int i = 0; i < D * D; ++i)
        fin = fin && std::isfinite(p.fe[D * D * k + i]) && std::isfinite(p.fp[D * D * k + i]) &&
              std::isfinite(p.c[D * D * k + i]);
      if (!fin) {
        if (why) *why = "particle " + std::to_string(k) + " has a non-finite field";
        return false;
      }
      if (!(p.j_e(k) > 0 && p.j_p(k) > 0)) {
        if (why) *why = "particle " + std::to_string(k) + " has J_E = " + std::to_string(p.j_e(k)) + ", J_P = " +
                        std::to_string(p.j_p(k));
        return false;
      }
    }
    return true;
  }

 private:
  std::vector<std::uint8_t> mask_;
};

}  // namespace host
