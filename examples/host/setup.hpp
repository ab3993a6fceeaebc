// The scenes' initial states: a unit cube (square in 2D) of res cells, walls `margin` nodes
// thick, particles on a lattice of ppc per cell per axis, and the three materials.
//
//   ice       an ice block at 263 K on a floor plate at 340 K; thermal + phase change. The
//             conductivities are the real ones (ice 2.2, water 0.6 W/(m·K)) times
//             thermal_speedup: the heat equation with κ·S is the real one with time t·S, so
//             the melt runs S times faster than real ice would (mechanics are not scaled).
//   snowball  a ball of snow thrown at a sticky wall at 10 m/s: Stomakhin et al. 2013 snow (E = 1.4e5 Pa,
//             ν = 0.2, ρ = 400 kg/m³, θ_c = 2.5e-2, θ_s = 7.5e-3, ξ = 10).
//   elastic   a tilted rubber block (E = 1e6 Pa, ν = 0.3, ρ = 1000 kg/m³) dropped on a slip
//             floor, with the explicit or the implicit stepper.
#pragma once

#include <cmath>
#include <string>

#include "sim.hpp"

namespace host {

struct SceneConfig {
  int res = 64;        // cells per axis of the unit cube
  int ppc = 2;         // particles per cell per axis
  bool implicit = false;
  double thermal_speedup = 4e3;
};

/// (μ, λ) from Young's modulus and Poisson's ratio.
inline void lame(double e, double nu, double* mu, double* lambda) {
  *mu = e / (2 * (1 + nu));
  *lambda = e * nu / ((1 + nu) * (1 - 2 * nu));
}

template <int D>
void init_grid(Sim<D>& s, const SceneConfig& c) {
  s.g.init(c.res, 1.0 / c.res);
  s.walls.margin = 3;
  s.heat.floor_rows = s.walls.margin;
}

/// Fills the set {inside(x)} with a lattice of ppc particles per cell per axis, density rho,
/// velocity vel, temperature temp. `inside` gets the lattice point x (D reals).
template <int D, class Inside>
void fill(Sim<D>& s, const SceneConfig& c, double rho, const double* vel, double temp, Inside&& inside) {
  const double sp = s.g.h / c.ppc;
  const int n = c.res * c.ppc;
  double vol = 1;
  for (int a = 0; a < D; ++a) vol *= sp;
  long total = 1;
  for (int a = 0; a < D; ++a) total *= n;
  for (long id = 0; id < total; ++id) {
    double x[3] = {0, 0, 0};
    long q = id;
    for (int a = 0; a < D; ++a, q /= n) x[a] = sp * (static_cast<double>(q % n) + 0.5);
    if (inside(x)) s.p.add(x, vel, rho * vol, vol, temp);
  }
}

inline double floor_y(int res, int margin) { return static_cast<double>(margin) / res; }

template <int D>
void build_ice(Sim<D>& s, const SceneConfig& c) {
  init_grid(s, c);
  double mu, lambda;
  lame(4e5, 0.3, &mu, &lambda);
  const double S = c.thermal_speedup;
  s.mat = Material()
              .model(AMPM_MODEL_THERMAL | AMPM_MODEL_PHASE_CHANGE)
              .solid(Phase().mu(mu).lambda(lambda).heat_capacity(2100).conductivity(2.2 * S))
              .liquid(Phase().mu(0).lambda(1e5).heat_capacity(4186).conductivity(0.6 * S))
              .flip(0)  // PIC temperature transfer
              .melting_point(273.15)
              .latent_heat(334e3);
  s.heat.rho_ref = 917;
  s.heat.hot_floor = true;
  s.heat.t_floor = 340;
  const double y0 = floor_y(c.res, s.walls.margin), half = D == 2 ? 0.15 : 0.125, height = D == 2 ? 0.2 : 0.25;
  const double zero[3] = {0, 0, 0};
  fill(s, c, 917, zero, 263.15, [&](const double* x) {
    bool in = x[1] >= y0 && x[1] < y0 + height && std::fabs(x[0] - 0.5) < half;
    if (D == 3) in = in && std::fabs(x[2] - 0.5) < half;
    return in;
  });
  s.dt_cap = 2e-3;
}

template <int D>
void build_snowball(Sim<D>& s, const SceneConfig& c) {
  init_grid(s, c);
  double mu, lambda;
  lame(1.4e5, 0.2, &mu, &lambda);
  s.mat = Material()
              .model(AMPM_MODEL_PLASTIC)
              .solid(Phase().mu(mu).lambda(lambda).heat_capacity(1))
              .liquid(Phase().mu(0).lambda(lambda).heat_capacity(1))
              .critical_compression(2.5e-2)
              .critical_stretch(7.5e-3)
              .hardening(10);
  s.walls.upper[0] = Wall::Sticky;  // the wall it hits
  const double centre[3] = {0.3, 0.4, 0.5}, r = 0.1, vel[3] = {10.0, 0.5, 0.0};
  fill(s, c, 400, vel, 273, [&](const double* x) {
    double q = 0;
    for (int a = 0; a < D; ++a) q += (x[a] - centre[a]) * (x[a] - centre[a]);
    return q < r * r;
  });
  s.dt_cap = 1e-3;
}

/// The elastic block, tilted by 0.35 rad about z, its lowest corner `drop` above the floor.
template <int D>
void build_elastic(Sim<D>& s, const SceneConfig& c, double drop = 0.3) {
  init_grid(s, c);
  double mu, lambda;
  lame(1e6, 0.3, &mu, &lambda);
  s.mat = Material()
              .model(c.implicit ? AMPM_MODEL_PSD_HESSIAN : 0u)
              .solid(Phase().mu(mu).lambda(lambda).heat_capacity(1))
              .liquid(Phase().mu(0).lambda(lambda).heat_capacity(1));
  s.stepper = c.implicit ? Stepper::Implicit : Stepper::Explicit;
  const double half = 0.1, th = 0.35, ct = std::cos(th), st = std::sin(th);
  // Lowest corner of the rotated square: the centre minus half·(|cos| + |sin|) in y.
  const double cy = floor_y(c.res, s.walls.margin) + drop + half * (ct + st);
  const double zero[3] = {0, 0, 0};
  fill(s, c, 1000, zero, 273, [&](const double* x) {
    const double dx = x[0] - 0.5, dy = x[1] - cy;
    const double u = ct * dx + st * dy, w = -st * dx + ct * dy;  // body frame
    bool in = std::fabs(u) < half && std::fabs(w) < half;
    if (D == 3) in = in && std::fabs(x[2] - 0.5) < half;
    return in;
  });
  s.dt_cap = c.implicit ? 4e-3 : 1e-3;
}

}  // namespace host
