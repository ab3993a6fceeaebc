// The thermal half of a step: the host's heat step on the grid (P2G's heat checked, explicit
// conservative diffusion, the warm ambient of the phase-change scene), the host's own T*_p and
// q_p, and the heat and phase-change checks after G2P.
#pragma once

#include "host_loop/check.hpp"
#include "host_loop/run.hpp"

namespace {

/// The enthalpy per unit mass of a thermal state (see test_host_loop.cpp's comment).
ld enthalpy(ld t, ld u, int phase, ld c_s, ld c_l, ld tm, ld latent) {
  if (phase == AMPM_PHASE_SOLID && t < tm) return c_s * (t - tm);
  if (phase == AMPM_PHASE_LIQUID && t > tm) return latent + c_l * (t - tm);
  return u;
}

/// One step's heat sums: after P2G on the grid and on the particles, on the grid after the
/// heat step, and the heat the ambient injected.
struct Heat {
  ld heat_p2g = 0, heat_part = 0, heat_grid_new = 0, q_in = 0;
};

/// P2G's heat and heat capacity against the particles' m c T and m c; adds its bound to the
/// run's heat budget.
template <class T, int D>
void check_p2g_heat(Run<T, D>& r, int step, int n_add, Heat& heat) {
  using A = Api<T, D>;
  constexpr int KD = Run<T, D>::KD;
  const Scene& s = r.s;
  const Particles<T, D>& p = r.p;
  const Grid<T, D>& g = r.g;
  const ld eps = r.eps;
  const char* label = r.label;
  ld hc_sum = 0, mc_sum = 0;
  for (std::size_t i = 0; i < r.n; ++i) {
    const ld c = p.ph[i] ? s.c_l : s.c_s;
    heat.heat_part += static_cast<ld>(p.m[i]) * c * p.t[i];
    mc_sum += static_cast<ld>(p.m[i]) * c;
  }
  for (std::size_t k = 0; k < g.count; ++k) heat.heat_p2g += g.te[k], hc_sum += g.hc[k];
  const ld c_h = n_add + KD + 6 * D + 4;
  CHECK(std::fabs(heat.heat_p2g - heat.heat_part) <= c_h * eps * heat.heat_part,
        "%s %s step %d: P2G heat %.12Le vs particles %.12Le", A::name, label, step,
        heat.heat_p2g, heat.heat_part);
  CHECK(std::fabs(hc_sum - mc_sum) <= c_h * eps * mc_sum,
        "%s %s step %d: P2G heat capacity %.12Le vs %.12Le", A::name, label, step, hc_sum,
        mc_sum);
  r.heat_budget += c_h * eps * heat.heat_part;
}

/// The neighbour of node k along ±a (dir = ±1) into *out, if it is inside the box.
template <class T, int D>
bool neighbour(const Grid<T, D>& g, std::size_t k, int a, int dir, std::size_t* out) {
  int idx[3] = {0, 0, 0};
  g.node(k, idx);
  idx[a] += dir;
  if (idx[a] < g.lo[a] || idx[a] >= g.lo[a] + g.dims[a]) return false;
  *out = g.at(idx);
  return true;
}

/// The number of substeps n_sub with Δt/n_sub ≤ ½ min_i C_i/Σ_j k_ij: face coefficients to the
/// neighbour of node k along ±a, if both have mass, and the ambient coupling of a massive node
/// across each face whose neighbour has none.
template <class T, int D>
int substeps(const Run<T, D>& r, const std::vector<T>& kap, const std::vector<T>& theta, T hd2) {
  const Grid<T, D>& g = r.g;
  std::vector<T> ksum(g.count, 0);
  for (std::size_t k = 0; k < g.count; ++k) {
    if (!(g.mass[k] > 0)) continue;
    for (int a = 0; a < D; ++a)
      for (int dir : {-1, 1}) {
        std::size_t j = 0;
        const bool in = neighbour(g, k, a, dir, &j);
        if (in && g.mass[j] > 0)
          ksum[k] += hd2 * T(0.5) * (kap[k] + kap[j]) * std::min(theta[k], theta[j]);
        else if (r.s.warm_ambient)
          ksum[k] += hd2 * kap[k] * theta[k];
      }
  }
  ld limit = std::numeric_limits<ld>::infinity();
  for (std::size_t k = 0; k < g.count; ++k)
    if (g.mass[k] > 0 && ksum[k] > 0)
      limit = std::min<ld>(limit, static_cast<ld>(g.hc[k]) / ksum[k]);
  return std::max(1, static_cast<int>(std::ceil(r.dt / (0.5L * limit))));
}

/// Explicit conservative diffusion of the node energies e over Δt in n_sub substeps, and the
/// ambient's heat into heat.q_in; checks Σ E (unchanged, or changed by the injected heat) and
/// adds each substep's bound to the run's heat budget.
template <class T, int D>
void diffuse(Run<T, D>& r, int step, Heat& heat, std::vector<T>& e, const std::vector<T>& kap,
             const std::vector<T>& theta) {
  using A = Api<T, D>;
  const Scene& s = r.s;
  const Grid<T, D>& g = r.g;
  const ld eps = r.eps;
  const char* label = r.label;
  // Face coefficients: the neighbour of node k along +a, if both have mass; and the
  // ambient coupling of a massive node across each face whose neighbour has none.
  const T hd2 = static_cast<T>(std::pow(s.h, D - 2));
  const int n_sub = substeps(r, kap, theta, hd2);
  const T dth = r.dt / static_cast<T>(n_sub);
  std::vector<T> tt(g.count);
  for (int sub = 0; sub < n_sub; ++sub) {
    for (std::size_t k = 0; k < g.count; ++k) tt[k] = g.mass[k] > 0 ? e[k] / g.hc[k] : T(0);
    ld e_before = 0, flux_abs = 0;
    for (std::size_t k = 0; k < g.count; ++k) e_before += e[k];
    for (std::size_t k = 0; k < g.count; ++k) {
      if (!(g.mass[k] > 0)) continue;
      for (int a = 0; a < D; ++a) {
        std::size_t j = 0;
        const bool in_up = neighbour(g, k, a, +1, &j);
        if (in_up && g.mass[j] > 0) {
          const T phi = dth * (hd2 * T(0.5) * (kap[k] + kap[j]) * std::min(theta[k], theta[j])) *
                        (tt[j] - tt[k]);
          e[k] += phi, e[j] -= phi;
          flux_abs += 2 * std::fabs(static_cast<ld>(phi));
        }
        if (!s.warm_ambient) continue;
        for (int dir : {-1, 1}) {
          std::size_t jj = 0;
          const bool in = neighbour(g, k, a, dir, &jj);
          if (!in || !(g.mass[jj] > 0)) {
            const T phi = dth * (hd2 * kap[k] * theta[k]) * (static_cast<T>(s.t_ambient) - tt[k]);
            e[k] += phi;
            heat.q_in += phi;
            flux_abs += std::fabs(static_cast<ld>(phi));
          }
        }
      }
    }
    ld e_after = 0;
    for (std::size_t k = 0; k < g.count; ++k) e_after += e[k];
    const ld tol_d = (2 * D + 1) * eps * (e_before + flux_abs);
    if (!s.warm_ambient)
      CHECK(std::fabs(e_after - e_before) <= tol_d,
            "%s %s step %d: diffusion changed Σ E by %.3Le (tol %.3Le)", A::name, label, step,
            e_after - e_before, tol_d);
    r.heat_budget += tol_d;
  }
  if (s.warm_ambient) {
    // Σ E changed by exactly the injected heat, up to the rounding of the additions.
    ld e_new = 0;
    for (std::size_t k = 0; k < g.count; ++k) e_new += e[k];
    const ld tol = n_sub * (2 * D + 1) * eps * (heat.heat_p2g + std::fabs(heat.q_in)) * 2;
    CHECK(std::fabs(e_new - heat.heat_p2g - heat.q_in) <= tol,
          "%s %s step %d: Σ E changed by %.12Le, injected %.12Le", A::name, label, step,
          e_new - heat.heat_p2g, heat.q_in);
  }
}

/// The host's heat step on the grid: P2G's heat checked, T_i = E_i/C_i (the old temperature),
/// κ_i and θ_i, the diffusion, and the new temperature.
template <class T, int D>
void heat_step(Run<T, D>& r, int step, int n_add, Heat& heat) {
  Grid<T, D>& g = r.g;
  check_p2g_heat(r, step, n_add, heat);

  // T_i, κ_i, θ_i; massless nodes get T = 0 (finite: G2P may read a node of zero weight).
  std::vector<T> e(g.count), kap(g.count), theta(g.count);
  for (std::size_t k = 0; k < g.count; ++k) {
    const bool massive = g.mass[k] > 0;
    g.told[k] = massive ? g.te[k] / g.hc[k] : T(0);
    e[k] = massive ? g.te[k] : T(0);
    kap[k] = massive ? g.cond[k] / g.mass[k] : T(0);
    theta[k] = massive ? static_cast<T>(std::min<ld>(1, g.mass[k] / r.m_full)) : T(0);
  }
  diffuse(r, step, heat, e, kap, theta);
  for (std::size_t k = 0; k < g.count; ++k) {
    g.tnew[k] = g.mass[k] > 0 ? e[k] / g.hc[k] : T(0);
    heat.heat_grid_new += static_cast<ld>(g.hc[k]) * g.tnew[k];
  }
}

/// The host's own T*_p (from the step's stencil weights) and q_p = c (T*_p − T_p), and each
/// particle's enthalpy, before G2P (phase change).
template <class T, int D>
void host_t_star(const Run<T, D>& r, std::vector<ld>& q_host, std::vector<ld>& e_before) {
  constexpr int KD = Run<T, D>::KD;
  const Scene& s = r.s;
  const Particles<T, D>& p = r.p;
  const Grid<T, D>& g = r.g;
  for (std::size_t i = 0; i < r.n; ++i) {
    ld pic = 0, fl = 0;
    for (int rr = 0; rr < KD; ++rr) {
      int idx[3] = {0, 0, 0};
      for (int a = 0, q = rr; a < D; ++a, q /= K1) idx[a] = r.base[D * i + a] + q % K1;
      const std::size_t k = g.at(idx);
      pic += static_cast<ld>(r.w[KD * i + rr]) * g.tnew[k];
      fl += static_cast<ld>(r.w[KD * i + rr]) * (static_cast<ld>(g.tnew[k]) - g.told[k]);
    }
    const ld tstar = (1 - s.flip) * pic + s.flip * (p.t[i] + fl);
    q_host[i] = (p.ph[i] ? s.c_l : s.c_s) * (tstar - p.t[i]);
    e_before[i] = enthalpy(p.t[i], p.u[i], p.ph[i], s.c_s, s.c_l, s.tm, s.latent);
  }
}

/// Heat without phase change after G2P: the particles' heat against the grid's and the initial
/// heat (within the run's heat budget), and for PIC the max principle.
template <class T, int D>
void check_heat(Run<T, D>& r, int step, int n_add, const Heat& heat) {
  using A = Api<T, D>;
  constexpr int KD = Run<T, D>::KD;
  const Scene& s = r.s;
  const Particles<T, D>& p = r.p;
  const ld eps = r.eps;
  const char* label = r.label;
  ld heat_after = 0, tmax = 0, tmin = 1e30L;
  for (std::size_t i = 0; i < r.n; ++i) {
    heat_after += static_cast<ld>(p.m[i]) * s.c_s * p.t[i];
    tmax = std::max<ld>(tmax, p.t[i]), tmin = std::min<ld>(tmin, p.t[i]);
  }
  const ld tol_g = (2 * n_add + KD + 6 * D + 10) * eps * heat_after;
  CHECK(std::fabs(heat_after - heat.heat_grid_new) <= tol_g,
        "%s %s step %d: G2P heat %.12Le vs grid %.12Le (tol %.3Le)", A::name, label, step,
        heat_after, heat.heat_grid_new, tol_g);
  r.heat_budget += tol_g;
  CHECK(std::fabs(heat_after - r.heat0) <= r.heat_budget,
        "%s %s step %d: total heat %.12Le, initial %.12Le (tol %.3Le)", A::name, label, step,
        heat_after, r.heat0, r.heat_budget);
  if (s.flip == 0) {
    // Max principle: P2G, the monotone diffusion and PIC G2P are convex combinations.
    const ld slack = (2 * KD + 16) * eps * 350;
    CHECK(tmax <= r.t_max0 + slack && tmin >= r.t_min0 - slack,
          "%s %s step %d: T range [%.9Lf, %.9Lf] left [%.9Lf, %.9Lf]", A::name, label, step, tmin,
          tmax, r.t_min0, r.t_max0);
    r.t_max0 = tmax, r.t_min0 = tmin;
  }
}

/// Phase change after G2P: per particle Δe against the host's q and the library's invariants
/// of the thermal state; Σ m q against the injected heat, this step and over the run.
template <class T, int D>
void check_melt(Run<T, D>& r, int step, int n_add, const Heat& heat,
                const std::vector<ld>& q_host, const std::vector<ld>& e_before) {
  using A = Api<T, D>;
  constexpr int KD = Run<T, D>::KD;
  const Scene& s = r.s;
  const Particles<T, D>& p = r.p;
  const ld eps = r.eps;
  const char* label = r.label;
  const ld c_max = std::max(s.c_s, s.c_l);
  ld dsum = 0, qsum = 0, tol_sum = 0;
  for (std::size_t i = 0; i < r.n; ++i) {
    const ld e_after = enthalpy(p.t[i], p.u[i], p.ph[i], s.c_s, s.c_l, s.tm, s.latent);
    const ld t_scale = std::max<ld>({std::fabs(static_cast<ld>(p.t[i])), s.tm, s.t_ambient});
    const ld tol = eps * ((2 * KD + 28) * c_max * t_scale + 14 * s.latent);
    CHECK(std::fabs((e_after - e_before[i]) - q_host[i]) <= tol,
          "%s %s step %d particle %zu: Δe = %.12Le, q = %.12Le (tol %.3Le)", A::name, label, step,
          i, e_after - e_before[i], q_host[i], tol);
    // The library's invariants of the thermal state.
    const T tm = static_cast<T>(s.tm), latent = static_cast<T>(s.latent);
    const bool ok = p.u[i] >= 0 && p.u[i] <= latent &&
                    (p.ph[i] == AMPM_PHASE_SOLID
                         ? (p.t[i] < tm && p.u[i] == 0) || p.t[i] == tm
                         : (p.t[i] > tm && p.u[i] == latent) || p.t[i] == tm);
    CHECK(ok, "%s %s step %d particle %zu: thermal state T %.9g U %.9g phase %d", A::name, label,
          step, i, double(p.t[i]), double(p.u[i]), int(p.ph[i]));
    dsum += static_cast<ld>(p.m[i]) * (e_after - e_before[i]);
    qsum += static_cast<ld>(p.m[i]) * q_host[i];
    tol_sum += static_cast<ld>(p.m[i]) * tol;
  }
  // Σ m q = Σ_i E^new − Σ_i E^P2G = Q_in (PIC), with the grid-side bounds.
  const ld tol_grid =
      (n_add + KD + 6 * D + 4 + 2 * n_add + KD + 6 * D + 10) * eps * heat.heat_part +
      (2 * D + 1) * eps * 4 * (heat.heat_p2g + std::fabs(heat.q_in));
  CHECK(std::fabs(qsum - heat.q_in) <= tol_grid + tol_sum,
        "%s %s step %d: Σ m q = %.12Le, injected %.12Le (tol %.3Le)", A::name, label, step, qsum,
        heat.q_in, tol_grid + tol_sum);
  r.q_in_total += heat.q_in;
  r.enthalpy_change_total += dsum;
  r.melt_budget += tol_grid + 2 * tol_sum;
  CHECK(std::fabs(r.enthalpy_change_total - r.q_in_total) <= r.melt_budget,
        "%s %s step %d: Σ m Δe = %.12Le, Σ Q_in = %.12Le (tol %.3Le)", A::name, label, step,
        r.enthalpy_change_total, r.q_in_total, r.melt_budget);
}

/// After the last step of the phase-change scene: how many particles melted (some must, not
/// all), printed.
template <class T, int D>
void check_melted(const Run<T, D>& r) {
  using A = Api<T, D>;
  const Scene& s = r.s;
  const Particles<T, D>& p = r.p;
  const std::size_t n = r.n;
  const char* label = r.label;
  std::size_t liquid = 0, at_tm = 0;
  for (std::size_t i = 0; i < n; ++i) {
    liquid += p.ph[i] == AMPM_PHASE_LIQUID;
    at_tm += p.t[i] == static_cast<T>(s.tm);
  }
  std::printf("  %s %s: %zu of %zu particles liquid, %zu at T_m, heat injected %.6Lg J\n",
              A::name, label, liquid, n, at_tm, r.q_in_total);
  CHECK(liquid > 0, "%s %s: no particle melted", A::name, label);
  CHECK(liquid < n, "%s %s: every particle melted (the test wants both phases)", A::name, label);
}

}  // namespace
