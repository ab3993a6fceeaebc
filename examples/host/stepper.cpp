// Explicit against implicit on the elastic drop: the largest stable Δt of each stepper and what
// a simulated second costs at that Δt.
//
// A trial runs the drop (lowest corner 0.15 m above the floor: impact at ≈ 0.17 s, then the
// bounce) for T = 0.4 s at one fixed Δt, with no CFL cap. It is stable when, at every step:
// no library call fails and CG converges (≤ 500 iterations, ‖r‖_(M⁻¹) ≤ 1e-6 ‖b‖_(M⁻¹)); every
// particle field is finite; 0.2 ≤ J_E ≤ 5 (a sane range: the corner that hits the floor first
// reaches J_E ≈ 0.45 for a moment in a stable run, a blow-up leaves the range at once); the
// kinetic energy stays below 1.5× the potential energy the drop can release (Σ m g (y − y_floor)
// at t = 0: an instability creates energy); and no particle had to be pushed back inside the
// grid (a step so large that material tunnels through the floor wall is not a usable step).
//
// Search: from Δt_0 (explicit: 0.25 h/c with c the P-wave speed; implicit: the explicit
// result), halve until stable, double until unstable (or Δt = T/10, the cap), then 4 bisection
// steps on log Δt between the last stable and the first unstable. dt_max is the largest stable
// Δt found; the cost is the wall time of that trial divided by T (on the threads given), and
// cpu_per_sim_second_s the process CPU time of that trial divided by T.
#include <chrono>
#include <ctime>
#include <cmath>
#include <cstdio>
#include <fstream>

#include "scenes.hpp"
#include "setup.hpp"

namespace host {

namespace {

struct Trial {
  bool stable = false;
  std::string why;
  double wall = 0;
  double cpu = 0;  // process CPU time (all threads): less sensitive to a loaded machine
  long steps = 0;
  double cg_mean = 0;
  double energy_ratio = 0;  // (KE + gravity PE) at the end / at the start
  std::size_t particles = 0;
};

template <int D>
double energy(const Sim<D>& s, double y_floor, double* ke_out) {
  double ke = 0, pe = 0;
  for (std::size_t k = 0; k < s.p.n; ++k) {
    for (int a = 0; a < D; ++a) ke += 0.5 * s.p.m[k] * s.p.v[D * k + a] * s.p.v[D * k + a];
    pe += s.p.m[k] * 9.81 * (s.p.x[D * k + 1] - y_floor);
  }
  if (ke_out) *ke_out = ke;
  return ke + pe;
}

template <int D>
Trial trial(bool implicit, double dt, const SceneConfig& c0, double t_end) {
  SceneConfig c = c0;
  c.implicit = implicit;
  Sim<D> s;
  build_elastic(s, c, 0.15);
  const double y_floor = floor_y(c.res, s.walls.margin);
  const double e0 = energy(s, y_floor, nullptr);
  Trial t;
  t.particles = s.p.n;
  const long n = std::max(1L, std::lround(t_end / dt));
  const auto t0 = std::chrono::steady_clock::now();
  const std::clock_t cpu0 = std::clock();
  long cg = 0;
  for (long k = 0; k < n; ++k) {
    const StepInfo info = s.step(dt);
    if (!info.fail.ok()) {
      t.why = std::string(info.fail.what) + " " + status_name(info.fail.status);
      break;
    }
    cg += info.cg.iterations;
    if (!s.sane(&t.why)) break;
    bool j_ok = true;
    for (std::size_t q = 0; q < s.p.n && j_ok; ++q) j_ok = s.p.j_e(q) >= 0.2 && s.p.j_e(q) <= 5;
    if (!j_ok) {
      t.why = "J_E outside [0.2, 5]";
      break;
    }
    double ke = 0;
    energy(s, y_floor, &ke);
    if (!(ke <= 1.5 * e0)) {
      t.why = "kinetic energy above 1.5x the drop's potential energy";
      break;
    }
    if (s.clamped) {
      t.why = "particles tunnelled into the floor wall";
      break;
    }
    t.steps = k + 1;
  }
  t.wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  t.cpu = static_cast<double>(std::clock() - cpu0) / CLOCKS_PER_SEC;
  t.stable = t.steps == n;
  t.cg_mean = t.steps ? static_cast<double>(cg) / t.steps : 0;
  t.energy_ratio = energy(s, y_floor, nullptr) / e0;
  return t;
}

template <int D>
bool study(const RunOptions& opt, const std::string& csv, bool header) {
  SceneConfig c;
  c.res = opt.res > 0 ? opt.res : default_res(D);
  c.ppc = opt.ppc;
  const double t_end = opt.short_run ? 0.25 : 0.4, cap = t_end / 10;
  Sim<D> probe;
  build_elastic(probe, c, 0.15);
  const double c_wave = probe.wave_speed(), h = probe.g.h;
  std::printf("[stepper %dD] elastic drop: %zu particles, %d cells, h = %.4g m, P-wave speed %.1f m/s, T = %.2f s\n", D,
              probe.p.n, c.res, h, c_wave, t_end);
  std::FILE* out = std::fopen(csv.c_str(), header ? "w" : "a");
  if (!out) {
    std::fprintf(stderr, "cannot write %s\n", csv.c_str());
    return false;
  }
  if (header)
    std::fprintf(out,
                 "stepper,dim,dt_max,cost_per_sim_second_s,steps_per_sim_second,mean_cg_iterations,dt_max_over_h_by_c,"
                 "limited_by,first_unstable_dt,first_unstable_reason,energy_ratio_end,cpu_per_sim_second_s,particles,res,"
                 "threads\n");
  double dt_explicit = 0;
  for (int which = 0; which < 2; ++which) {
    const bool implicit = which == 1;
    const char* name = implicit ? "implicit" : "explicit";
    auto run = [&](double dt) {
      Trial t = trial<D>(implicit, dt, c, t_end);
      std::printf("[stepper %dD] %s dt = %.4g s (%.3g h/c): %s%s  %.2f s wall, %ld steps%s\n", D, name, dt, dt * c_wave / h,
                  t.stable ? "stable" : "UNSTABLE: ", t.stable ? "" : t.why.c_str(), t.wall, t.steps,
                  implicit ? (", CG " + std::to_string(static_cast<int>(std::lround(t.cg_mean))) + " it/step").c_str() : "");
      std::fflush(stdout);
      return t;
    };
    double lo = implicit ? dt_explicit : 0.25 * h / c_wave, hi = 0;
    Trial best = run(lo), bad;
    for (int k = 0; k < 8 && !best.stable; ++k) hi = lo, bad = best, lo /= 2, best = run(lo);
    if (!best.stable) {
      std::fprintf(stderr, "[stepper %dD] %s: no stable dt found\n", D, name);
      std::fclose(out);
      return false;
    }
    if (hi == 0)
      while (lo < cap) {
        const double next = std::min(cap, 2 * lo);
        Trial t = run(next);
        if (!t.stable) {
          hi = next, bad = t;
          break;
        }
        lo = next, best = t;
      }
    for (int k = 0; k < 4 && hi > 0; ++k) {
      const double mid = std::sqrt(lo * hi);
      Trial t = run(mid);
      if (t.stable) lo = mid, best = t;
      else hi = mid, bad = t;
    }
    if (!implicit) dt_explicit = lo;
    const double cost = best.wall / t_end;
    std::printf("[stepper %dD] %s: dt_max = %.4g s (%.3g h/c), %.3g s of wall (%.3g s CPU) per simulated second, %.0f "
                "steps/s%s\n",
                D, name, lo, lo * c_wave / h, cost, best.cpu / t_end, 1 / lo, hi > 0 ? "" : " (reached the cap T/10)");
    std::fprintf(out, "%s,%d,%.6g,%.6g,%.6g,%.3g,%.4g,%s,%.6g,\"%s\",%.4g,%.6g,%zu,%d,%d\n", name, D, lo, cost, 1 / lo,
                 best.cg_mean, lo * c_wave / h, hi > 0 ? "instability" : "cap", hi, hi > 0 ? bad.why.c_str() : "",
                 best.energy_ratio, best.cpu / t_end, best.particles, c.res, threads());
  }
  std::fclose(out);
  return true;
}

}  // namespace

bool stepper_study(int dim, const RunOptions& opt, const std::string& csv, bool write_header) {
  return dim == 2 ? study<2>(opt, csv, write_header) : study<3>(opt, csv, write_header);
}

}  // namespace host
