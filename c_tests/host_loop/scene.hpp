// The scenes: what a run simulates (material, block size, steps, temperatures), the C material
// of a scene, and the block of particles it starts from.
#pragma once

#include "host_loop/host.hpp"

#include <random>

namespace {

struct Scene {
  unsigned model = 0;
  double mu = 2e4, lambda = 3e4, rho = 1000, h = 0.1;
  double c_s = 2, c_l = 4, k_s = 0, k_l = 0, tm = 273, latent = 0, flip = 0;
  int per_axis = 0;  // particles per axis of the block
  int steps = 40;
  double t_init = 300;
  bool warm_ambient = false;
  double t_ambient = 0;
  bool moving = true;
};

template <class T, int D>
typename Api<T, D>::Material material(const Scene& s) {
  typename Api<T, D>::Material m{};
  m.model = s.model;
  m.solid.mu = static_cast<T>(s.mu);
  m.solid.inv_lambda = static_cast<T>(1 / s.lambda);
  m.solid.heat_capacity = static_cast<T>(s.c_s);
  m.solid.conductivity = static_cast<T>(s.k_s);
  m.liquid.mu = 0;
  m.liquid.inv_lambda = static_cast<T>(1 / s.lambda);
  m.liquid.heat_capacity = static_cast<T>(s.c_l);
  m.liquid.conductivity = static_cast<T>(s.k_l);
  m.flip = static_cast<T>(s.flip);
  m.melting_point = static_cast<T>(s.tm);
  m.latent_heat = static_cast<T>(s.latent);
  return m;
}

/// The block: per_axis^d particles, spacing h/2, starting at −0.3 m on every axis (negative
/// node indices), with a rigid rotation, a stretch and a small random part of the velocity,
/// the matching APIC C, F_E = F_P = I. Temperature t_init, or 250 K / 350 K on either half.
template <class T, int D>
void make_block(const Scene& s, Particles<T, D>& p, bool halves, std::mt19937_64& rng) {
  int np = 1;
  for (int a = 0; a < D; ++a) np *= s.per_axis;
  p.resize(static_cast<std::size_t>(np));
  const double sp = s.h / 2, x0 = -0.3;
  const double centre = x0 + sp * (s.per_axis - 1) / 2;
  std::uniform_real_distribution<double> uni(-1, 1);
  // ∇v of the smooth part: rotation ω plus a traceless stretch.
  double g[3][3] = {{0.3, -0.8, 0.2}, {0.8, -0.2, -0.5}, {-0.2, 0.5, -0.1}};
  if (D == 2) g[0][0] = 0.3, g[1][1] = -0.3, g[0][1] = -0.8, g[1][0] = 0.8;
  const double v_lin[3] = {0.5, -0.3, 0.2};
  for (int k = 0; k < np; ++k) {
    int idx[3] = {0, 0, 0};
    for (int a = 0, q = k; a < D; ++a, q /= s.per_axis) idx[a] = q % s.per_axis;
    double r[3] = {0, 0, 0};
    for (int a = 0; a < D; ++a) {
      const double xa = x0 + sp * idx[a] + 0.25 * sp * uni(rng);
      p.x[D * k + a] = static_cast<T>(xa);
      r[a] = xa - centre;
    }
    for (int a = 0; a < D; ++a) {
      double va = s.moving ? v_lin[a] : 0;
      for (int b = 0; b < D; ++b) {
        if (s.moving) va += g[a][b] * r[b];
        p.c[D * D * k + a + D * b] = static_cast<T>(s.moving ? g[a][b] : 0);
      }
      if (s.moving) va += 0.05 * uni(rng);
      p.v[D * k + a] = static_cast<T>(va);
      p.fe[D * D * k + a * (D + 1)] = 1;
      p.fp[D * D * k + a * (D + 1)] = 1;
    }
    double vol = 1;
    for (int a = 0; a < D; ++a) vol *= sp;
    p.v0[k] = static_cast<T>(vol);
    p.m[k] = static_cast<T>(s.rho * vol);
    p.t[k] = static_cast<T>(halves ? (r[0] < 0 ? 250.0 : 350.0) : s.t_init);
    p.u[k] = 0;
    p.ph[k] = AMPM_PHASE_SOLID;
  }
}

}  // namespace
