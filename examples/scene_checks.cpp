// scene_checks: short versions of the example scenes with physical checks that can fail
// (ctest runs each in 2D and in a tiny 3D; see CMakeLists.txt).
//
//   scene_checks <ice|snowball|elastic-explicit|elastic-implicit> --dim 2|3 [--res CELLS]
//
// Checked at every step (ε = 2^-52, A = 3^d stencil nodes, n_add = the most particles whose
// stencils share a node, bounded by 4^d × the most particles in one cell: a node is in the
// stencil of the particles of 4 cells per axis):
//   - particles: the same count, and the multiset of particle masses unchanged bit for bit
//     (mass is conserved exactly: nothing lost, duplicated or altered by the sort);
//   - P2G: |Σ_i m_i − Σ_p m_p| ≤ (n_add + A + 6d)·ε·Σ_p m_p (c_tests/test_host_loop.cpp's bound:
//     each particle's weights sum to 1 within (A + 6d)ε, each node sums ≤ n_add terms);
//   - every particle field finite and J_E, J_P > 0 (Sim::sane);
//   - free flight (until the first step in which a wall constrains a node with mass), per axis a:
//     P^(n+1)_a − P^n_a = Δt g_a Σ_p m_p up to the rounding budget of the step's stages,
//       P2G      2(c_P + 2)·ε·(S_a + Δt F_a),  c_P = n_add + A + 6d + 8, S_a = Σ_p m_p (|v_pa| +
//                3.5 h Σ_b |C_p,ab|), F_a = Σ_p V0_p ‖τ_p‖_F · 2d/h ≥ Σ_p Σ_i |f_ip,a| (τ_p from
//                ampm::Kernels::ahat with the hardened μ, |∂_a w| summed over a stencil ≤ 2/h);
//       grid     3ε Σ_i (|m v* − Δt m g|_a + m_i Δt |g_a|) (the division and the gravity add);
//       G2P      (n_add + A + 4)·ε·Σ_i m_i |v_ia|;
//       gravity  Δt |g_a| (n_add + A + 6d)·ε·Σ_p m_p (Σ_i m_i vs Σ_p m_p);
//     implicit stepper: plus Σ_i |b − A v|_a, CG's true residual (the momentum the linear solve
//     leaves unbalanced: Σ_i (A v)_i = Σ_i m_i v_i − Δt Σ_i (K Δt v)_i and Σ_i (K u)_i = 0);
//     at least 20 free-flight steps must be checked (not in the ice scene: it starts on the floor);
//   - ice: heat balance: Σ_p m_p e_p(t) − Σ_p m_p e_p(0) = Σ Q_in (the heat that entered
//     through the floor), e the enthalpy per mass (c_s (T − T_m) solid below T_m; U at T_m;
//     L + c_l (T − T_m) liquid above), within the sum over steps of c_tests/test_host_loop.cpp's
//     per-stage bounds: P2G (n_add + A + 6d + 4)·ε·H, diffusion (2d + 1)·ε·(Σ_i E_i + Σ|Φ|) per
//     substep, G2P (2 n_add + A + 6d + 10)·ε·H (H = Σ_p m_p c_p T_p), and the library's phase
//     update ε·Σ_p m_p ((2A + 28) c_max T_scale + 14 L); and at the end at least the stated
//     fraction of the particles is liquid.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <string>
#include <vector>

#include "host/setup.hpp"

namespace {

using host::Real;
using ld = long double;
constexpr ld kEps = std::numeric_limits<Real>::epsilon();

long g_checks = 0, g_fail = 0;
#define CHECK(cond, ...)                                                \
  do {                                                                  \
    ++g_checks;                                                         \
    if (!(cond)) {                                                      \
      if (++g_fail <= 10) {                                             \
        std::fprintf(stderr, "%s:%d: FAIL %s: ", __FILE__, __LINE__, #cond); \
        std::fprintf(stderr, __VA_ARGS__);                              \
        std::fputc('\n', stderr);                                       \
      }                                                                 \
    }                                                                   \
  } while (0)

ld enthalpy(ld t, ld u, int phase, ld c_s, ld c_l, ld tm, ld latent) {
  if (phase == AMPM_PHASE_SOLID && t < tm) return c_s * (t - tm);
  if (phase == AMPM_PHASE_LIQUID && t > tm) return latent + c_l * (t - tm);
  (void)latent;
  return u;
}

/// Σ_p V0_p ‖τ_p‖_F (an upper bound on the stress scale of P2G's force).
template <int D>
ld stress_scale(const host::Sim<D>& s) {
  const auto& m = s.mat.c();
  ld sum = 0;
  for (std::size_t k = 0; k < s.p.n; ++k) {
    const bool liquid = s.p.ph[k] == AMPM_PHASE_LIQUID;
    const auto& ph = liquid ? m.liquid : m.solid;
    Real hard = 1;
    if ((m.model & AMPM_MODEL_PLASTIC) && !liquid) hard = std::exp(m.hardening * (1 - s.p.j_p(k)));
    const Real mu = ph.mu * hard, lambda = ph.inv_lambda > 0 ? hard / ph.inv_lambda : 0;
    const Real* f = &s.p.fe[D * D * k];
    Real a[D * D] = {};
    ld a_norm = 0, f_norm = 0;
    if (mu > 0) {
      if (!ampm::Kernels<Real, D>::ahat(mu, f, a).ok()) return std::numeric_limits<ld>::infinity();
      for (int i = 0; i < D * D; ++i) a_norm += static_cast<ld>(a[i]) * a[i];
    }
    for (int i = 0; i < D * D; ++i) f_norm += static_cast<ld>(f[i]) * f[i];
    const ld j = s.p.j_e(k);
    sum += s.p.v0[k] * (std::sqrt(a_norm * f_norm) + std::sqrt(ld(D)) * std::fabs(lambda * (j - 1) * j));
  }
  return sum;
}

template <int D>
int run(const std::string& scene, int res) {
  host::SceneConfig c;
  c.res = res > 0 ? res : (D == 2 ? 32 : 16);
  host::Sim<D> s;
  double t_end = 0, melt_min = 0;
  if (scene == "ice") {
    c.thermal_speedup = 1e4;  // faster than the scene's, to melt within a short test
    host::build_ice(s, c);
    t_end = 1.5;
    melt_min = D == 2 ? 0.3 : 0.1;  // 3D: less floor area per mass
  } else if (scene == "snowball") {
    host::build_snowball(s, c);
    t_end = 0.15;
  } else if (scene == "elastic-explicit" || scene == "elastic-implicit") {
    c.implicit = scene == "elastic-implicit";
    host::build_elastic(s, c, 0.1);
    t_end = 0.3;
    s.want_true_residual = true;
  } else {
    std::fprintf(stderr, "unknown scene %s\n", scene.c_str());
    return 2;
  }
  const auto& m = s.mat.c();
  const bool melt = (m.model & AMPM_MODEL_PHASE_CHANGE) != 0;
  const int KD = D == 2 ? 9 : 27;
  const std::size_t n0 = s.p.n;
  std::vector<Real> masses0 = s.p.m;
  std::sort(masses0.begin(), masses0.end());
  ld sum_m = 0;
  for (Real v : masses0) sum_m += v;
  auto momentum = [&](int a) {
    ld p = 0;
    for (std::size_t k = 0; k < s.p.n; ++k) p += static_cast<ld>(s.p.m[k]) * s.p.v[D * k + a];
    return p;
  };
  auto total_enthalpy = [&]() {
    ld e = 0;
    for (std::size_t k = 0; k < s.p.n; ++k)
      e += static_cast<ld>(s.p.m[k]) * enthalpy(s.p.t[k], s.p.u[k], s.p.ph[k], m.solid.heat_capacity,
                                                  m.liquid.heat_capacity, m.melting_point, m.latent_heat);
    return e;
  };
  const ld e0 = melt ? total_enthalpy() : 0;
  ld q_total = 0, heat_budget = 0;
  bool free_flight = true;
  long free_steps = 0;
  std::printf("scene_checks %s %dD: %zu particles, %d cells, %.2f s\n", scene.c_str(), D, s.p.n, c.res, t_end);
  while (s.time < t_end - 1e-12 && g_fail == 0) {
    const Real dt = s.suggest_dt(t_end - s.time);
    // Before the step: the free-flight budget's particle terms.
    ld p_before[3] = {0, 0, 0}, s_abs[3] = {0, 0, 0}, h_heat = 0, phase_tol = 0;
    const ld f_scale = free_flight ? stress_scale(s) * 2 * D / s.g.h : 0;
    for (int a = 0; a < D; ++a) p_before[a] = momentum(a);
    for (std::size_t k = 0; k < s.p.n; ++k) {
      for (int a = 0; a < D; ++a) {
        ld cs = 0;
        for (int b = 0; b < D; ++b) cs += std::fabs(static_cast<ld>(s.p.c[D * D * k + a + D * b]));
        s_abs[a] += s.p.m[k] * (std::fabs(static_cast<ld>(s.p.v[D * k + a])) + 3.5L * s.g.h * cs);
      }
      if (melt) {
        const bool liq = s.p.ph[k] == AMPM_PHASE_LIQUID;
        h_heat += static_cast<ld>(s.p.m[k]) * (liq ? m.liquid.heat_capacity : m.solid.heat_capacity) * s.p.t[k];
        const ld t_scale = std::max<ld>({std::fabs(static_cast<ld>(s.p.t[k])), m.melting_point, s.heat.t_floor});
        phase_tol += s.p.m[k] * kEps *
                     ((2 * KD + 28) * std::max(m.solid.heat_capacity, m.liquid.heat_capacity) * t_scale + 14 * m.latent_heat);
      }
    }
    const host::StepInfo info = s.step(dt);
    std::string why;
    CHECK(info.fail.ok(), "step %ld: %s %s (particle %zu)", s.steps, info.fail.what, host::status_name(info.fail.status),
          info.fail.particle);
    if (!info.fail.ok()) break;
    CHECK(s.sane(&why), "step %ld: %s", s.steps, why.c_str());
    // Mass.
    std::vector<Real> masses = s.p.m;
    std::sort(masses.begin(), masses.end());
    CHECK(s.p.n == n0 && masses == masses0, "step %ld: the particle masses changed", s.steps);
    const ld n_add = std::pow(4.0L, D) * info.max_per_cell;
    const ld tol_m = (n_add + KD + 6 * D) * kEps * sum_m;
    CHECK(std::fabs(info.grid_mass - sum_m) <= tol_m, "step %ld: grid mass %.17Lg, particles %.17Lg (tol %.3Lg)", s.steps,
          info.grid_mass, sum_m, tol_m);
    // Momentum in free flight.
    if (free_flight && info.touched) free_flight = false;
    if (free_flight) {
      ++free_steps;
      ld node_abs[3] = {0, 0, 0}, mv_abs[3] = {0, 0, 0};
      for (std::size_t k = 0; k < s.g.count; ++k)
        for (int a = 0; a < D; ++a) {
          const ld mv = static_cast<ld>(s.g.mass[k]) * s.g.vel[a][k];
          node_abs[a] += std::fabs(mv) + 2 * s.g.mass[k] * dt * std::fabs(s.gravity[a]);
          mv_abs[a] += std::fabs(mv);
        }
      const ld c_p = n_add + KD + 6 * D + 8;
      for (int a = 0; a < D; ++a) {
        const ld got = momentum(a) - p_before[a], want = dt * static_cast<ld>(s.gravity[a]) * sum_m;
        ld tol = kEps * (2 * (c_p + 2) * (s_abs[a] + dt * f_scale) + 3 * node_abs[a] + (n_add + KD + 4) * mv_abs[a] +
                         dt * std::fabs(s.gravity[a]) * (n_add + KD + 6 * D) * sum_m);
        if (s.stepper == host::Stepper::Implicit) tol += info.cg.true_residual[a];
        CHECK(std::fabs(got - want) <= tol, "step %ld axis %d: momentum change %.12Lg, gravity impulse %.12Lg (tol %.3Lg)",
              s.steps, a, got, want, tol);
      }
    }
    // Heat.
    if (melt) {
      q_total += info.heat.q_in;
      heat_budget += kEps * ((n_add + KD + 6 * D + 4) * h_heat +
                             (2 * D + 1) * (info.heat.e_before + info.heat.e_after + info.heat.flux_abs) +
                             (2 * n_add + KD + 6 * D + 10) * h_heat) +
                     phase_tol;
      const ld de = total_enthalpy() - e0;
      CHECK(std::fabs(de - q_total) <= heat_budget, "step %ld: enthalpy change %.12Lg J, heat in %.12Lg J (tol %.3Lg)",
            s.steps, de, q_total, heat_budget);
    }
  }
  if (!melt) CHECK(free_steps >= 20, "only %ld free-flight steps were checked", free_steps);  // ice starts on the floor
  if (melt) {
    std::size_t liquid = 0;
    for (std::size_t k = 0; k < s.p.n; ++k) liquid += s.p.ph[k] == AMPM_PHASE_LIQUID;
    const double frac = static_cast<double>(liquid) / s.p.n;
    std::printf("  liquid fraction %.3f at t = %.2f s (required >= %.2f); heat in %.6Lg J, enthalpy change %.6Lg J, "
                "budget %.3Lg J\n",
                frac, s.time, melt_min, q_total, total_enthalpy() - e0, heat_budget);
    CHECK(frac >= melt_min, "liquid fraction %.3f < %.2f at t = %.2f s", frac, melt_min, s.time);
  }
  std::printf("  %ld steps (%ld in free flight), %ld checks, %ld failures\n", s.steps, free_steps, g_checks, g_fail);
  return g_fail == 0 ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: scene_checks <ice|snowball|elastic-explicit|elastic-implicit> --dim 2|3 [--res N]\n");
    return 2;
  }
  const std::string scene = argv[1];
  int dim = 2, res = 0;
  for (int i = 2; i + 1 < argc; i += 2) {
    const std::string a = argv[i];
    if (a == "--dim") dim = std::atoi(argv[i + 1]);
    else if (a == "--res") res = std::atoi(argv[i + 1]);
  }
  return dim == 3 ? run<3>(scene, res) : run<2>(scene, res);
}
