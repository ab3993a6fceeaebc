// The heat solve on the grid: the worked example of turning the node heat data of P2G into
// temperatures and one diffusion step.
//
// Equation. Stomakhin et al. 2014 transport temperature with the material and diffuse it on the
// grid: ρ c DT/Dt = ∇·(κ∇T) (the seed tech report in /work/shared/seed derives only the
// elastic-energy derivatives; the heat equation is the paper's). In the library's
// discretisation (ampm.h, AmpmP2gView) P2G gives, per node i,
//   C_i = Σ_p w_ip m_p c_p      heat capacity (J/K)         — channel heat_capacity
//   E_i = Σ_p w_ip m_p c_p T_p  thermal energy (J)          — channel thermal_energy
//   K_i = Σ_p w_ip m_p κ_p      conductivity mass            — channel conductivity
// and the node temperature and conductivity are T_i = E_i / C_i, κ_i = K_i / m_i. The grid
// equation is C_i dT_i/dt = (∇·κ∇T)_i, with the divergence a finite-volume sum over the 2d face
// neighbours j of i (both with mass; a massless neighbour is air, insulating):
//   (∇·κ∇T)_i ≈ Σ_j k_ij (T_j − T_i),  k_ij = h^(d−2) · ½(κ_i + κ_j) · min(θ_i, θ_j),
// θ_i = min(1, m_i / (ρ_ref h^d)) the fraction of the node's cell that holds material (a
// half-filled surface node conducts through half a face). h^(d−2) is face area / distance.
// The floor is a hot plate at T_f: a node whose −y neighbour lies inside the floor gets
// k_i^f (T_f − T_i) with k_i^f = h^(d−2) κ_i θ_i, and that heat is Q_in, the only heat that
// enters the material.
//
// Time integration: explicit (forward Euler) on the node energies, in n_sub substeps of Δt_h:
//   E_i ← E_i + Δt_h [Σ_j k_ij (T_j − T_i) + k_i^f (T_f − T_i)],   T = E / C.
// Written per node as a gather (no atomics, OpenMP over nodes), it is still conservative to
// rounding: the flux i→j is Δt_h k_ij (T_j − T_i) and j→i is Δt_h k_ji (T_i − T_j), the exact
// negation (k_ij = k_ji bit for bit: + and min commute, and a − b = −(b − a) in IEEE).
// Stability: the new T_i is T_i (1 − Δt_h S_i / C_i) + Δt_h Σ_j k_ij T_j / C_i + …,
// S_i = Σ_j k_ij + k_i^f, a convex combination of old temperatures (no new extremum, so no
// oscillation or blow-up) iff Δt_h ≤ min_i C_i / S_i. For a full uniform grid C = ρ c h^d and
// S = 2d κ h^(d−2), which is the classical FTCS limit Δt_h ≤ h² / (2d α), α = κ / (ρ c).
// We take n_sub = ⌈Δt / min_i(C_i/S_i)⌉. (Backward Euler would have no limit but needs a
// linear solve per step; with the conductivities of the scenes one substep almost always
// suffices, so explicit is the cheaper choice here.)
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "grid.hpp"

namespace host {

struct HeatParams {
  Real rho_ref = 1000;   // kg/m^d of a full cell (θ)
  bool hot_floor = false;
  Real t_floor = 300;    // K
  int floor_rows = 3;    // node rows y < floor_rows are inside the floor (Walls::margin)
};

/// What one heat step did (for the heat-balance check of the tests).
struct HeatStep {
  long double q_in = 0;      // J that entered through the floor
  long double e_before = 0;  // Σ E_i after P2G
  long double e_after = 0;   // Σ E_i after diffusion
  long double flux_abs = 0;  // Σ over substeps of Σ_i (|Φ_i^f| + Σ_j |Φ_ij|)
  int substeps = 0;
};

/// Heat step of Δt: fills g.t_old, g.t_new from the P2G channels (massless nodes get 0: no
/// particle reads them with a non-zero weight, and G2P only needs them finite).
template <int D>
HeatStep heat_step(Grid<D>& g, Real dt, const HeatParams& hp) {
  HeatStep out;
  const std::size_t nn = g.count;
  const Real hd2 = std::pow(g.h, D - 2), full = hp.rho_ref * std::pow(g.h, D);
  std::vector<Real> e(nn), kap(nn), theta(nn), s(nn, 0), plate(nn, 0);
#pragma omp parallel for schedule(static) if (parallel_nodes(g.count))
  for (std::ptrdiff_t k = 0; k < static_cast<std::ptrdiff_t>(nn); ++k) {
    const bool massive = g.mass[k] > 0;
    e[k] = massive ? g.te[k] : Real(0);
    g.t_old[k] = massive ? g.te[k] / g.hc[k] : Real(0);
    kap[k] = massive ? g.cond[k] / g.mass[k] : Real(0);
    theta[k] = massive ? std::min<Real>(1, g.mass[k] / full) : Real(0);
  }
  // Conductances: k_ij on the fly; the plate's k_i^f; S_i for the stability limit.
  auto face = [&](std::size_t k, std::size_t j) { return hd2 * Real(0.5) * (kap[k] + kap[j]) * std::min(theta[k], theta[j]); };
  Real limit = std::numeric_limits<Real>::infinity();
#pragma omp parallel for schedule(static) reduction(min : limit) if (parallel_nodes(g.count))
  for (std::ptrdiff_t kk = 0; kk < static_cast<std::ptrdiff_t>(nn); ++kk) {
    const std::size_t k = static_cast<std::size_t>(kk);
    if (!(g.mass[k] > 0)) continue;
    int i[3] = {0, 0, 0};
    g.coords(k, i);
    Real sum = 0;
    for (int a = 0; a < D; ++a)
      for (int dir = -1; dir <= 1; dir += 2) {
        const int ia = i[a] + dir;
        if (ia < 0 || ia >= g.n[a]) continue;
        const std::size_t j = static_cast<std::size_t>(static_cast<std::ptrdiff_t>(k) + dir * g.stride[a]);
        if (g.mass[j] > 0) sum += face(k, j);
      }
    if (hp.hot_floor && i[1] - 1 < hp.floor_rows) plate[k] = hd2 * kap[k] * theta[k], sum += plate[k];
    s[k] = sum;
    if (sum > 0) limit = std::min(limit, g.hc[k] / sum);
  }
  out.substeps = std::isfinite(limit) ? std::max(1, static_cast<int>(std::ceil(dt / limit))) : 1;
  const Real dth = dt / out.substeps;
  for (std::size_t k = 0; k < nn; ++k) out.e_before += e[k];

  std::vector<Real> t(nn), e_new(nn), q(nn, 0), fabs_node(nn, 0);
  for (int sub = 0; sub < out.substeps; ++sub) {
#pragma omp parallel for schedule(static) if (parallel_nodes(g.count))
    for (std::ptrdiff_t k = 0; k < static_cast<std::ptrdiff_t>(nn); ++k) t[k] = g.mass[k] > 0 ? e[k] / g.hc[k] : Real(0);
#pragma omp parallel for schedule(static) if (parallel_nodes(g.count))
    for (std::ptrdiff_t kk = 0; kk < static_cast<std::ptrdiff_t>(nn); ++kk) {
      const std::size_t k = static_cast<std::size_t>(kk);
      e_new[k] = e[k];
      q[k] = 0, fabs_node[k] = 0;
      if (!(g.mass[k] > 0)) continue;
      int i[3] = {0, 0, 0};
      g.coords(k, i);
      Real acc = e[k], fa = 0;
      for (int a = 0; a < D; ++a)
        for (int dir = -1; dir <= 1; dir += 2) {
          const int ia = i[a] + dir;
          if (ia < 0 || ia >= g.n[a]) continue;
          const std::size_t j = static_cast<std::size_t>(static_cast<std::ptrdiff_t>(k) + dir * g.stride[a]);
          if (!(g.mass[j] > 0)) continue;
          const Real phi = dth * face(k, j) * (t[j] - t[k]);
          acc += phi, fa += std::fabs(phi);
        }
      if (plate[k] > 0) {
        const Real phi = dth * plate[k] * (hp.t_floor - t[k]);
        acc += phi, fa += std::fabs(phi), q[k] = phi;
      }
      e_new[k] = acc, fabs_node[k] = fa;
    }
    e.swap(e_new);
    for (std::size_t k = 0; k < nn; ++k) out.q_in += q[k], out.flux_abs += fabs_node[k];
  }
#pragma omp parallel for schedule(static) if (parallel_nodes(g.count))
  for (std::ptrdiff_t k = 0; k < static_cast<std::ptrdiff_t>(nn); ++k) g.t_new[k] = g.mass[k] > 0 ? e[k] / g.hc[k] : Real(0);
  for (std::size_t k = 0; k < nn; ++k) out.e_after += e[k];
  return out;
}

}  // namespace host
