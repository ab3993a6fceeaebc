// One run's state: its scene, the host's particles and grid, the step size, the stencils of
// the current step, and the sums and bounds its checks carry from step to step.
#pragma once

#include "host_loop/scene.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace {

/// Per-axis sums.
struct Vec3 {
  ld a[3] = {0, 0, 0};
};

/// The state of one run of the host loop; `thermal` selects the heat checks, `melt` the
/// phase-change ones. Holds views into its own particles: neither copied nor moved.
template <class T, int D>
struct Run {
  using A = Api<T, D>;
  static constexpr int KD = stencil_nodes<D>();
  static constexpr unsigned kernel = AMPM_KERNEL_QUADRATIC;

  const Scene& s;
  const char* label;
  ld eps = 0;
  bool thermal = false, melt = false;
  Particles<T, D> p;
  std::size_t n = 0;
  typename A::Particles pv{};
  typename A::Material mat{};
  T h = 0, dt = 0;
  Grid<T, D> g;
  ld m_full = 0;  // mass of a full cell

  Vec3 p0;
  ld sum_m = 0;
  Vec3 budget;  // Σ over the steps of the per-step momentum bounds
  ld heat_budget = 0, heat0 = 0;
  ld t_max0 = 0, t_min0 = 1e30L;
  ld q_in_total = 0, enthalpy_change_total = 0, melt_budget = 0;
  std::vector<int> base;
  std::vector<T> w, gw;

  Run(const Scene& scene, const char* what) : s(scene), label(what) {
    eps = std::numeric_limits<T>::epsilon();
    thermal = (s.model & AMPM_MODEL_THERMAL) != 0;
    melt = (s.model & AMPM_MODEL_PHASE_CHANGE) != 0;
    std::mt19937_64 rng(0x40571007 + 10 * D);
    make_block<T, D>(s, p, thermal && !melt, rng);
    n = p.n;
    pv = p.view();
    mat = material<T, D>(s);
    h = static_cast<T>(s.h);
    // Δt: a quarter of the elastic wave's cell-crossing time (explicit stability).
    const double wave = std::sqrt((s.lambda + 2 * s.mu) / s.rho);
    dt = static_cast<T>(0.25 * s.h / (wave + 2.0));
    double hd = 1;
    for (int a = 0; a < D; ++a) hd *= s.h;
    m_full = s.rho * hd;

    for (std::size_t i = 0; i < n; ++i) {
      sum_m += p.m[i];
      for (int a = 0; a < D; ++a) p0.a[a] += static_cast<ld>(p.m[i]) * p.v[D * i + a];
    }
    for (std::size_t i = 0; i < n; ++i)
      heat0 += static_cast<ld>(p.m[i]) * (p.ph[i] ? s.c_l : s.c_s) * p.t[i];
    for (std::size_t i = 0; i < n; ++i)
      t_max0 = std::max<ld>(t_max0, p.t[i]), t_min0 = std::min<ld>(t_min0, p.t[i]);
    base.assign(n * D, 0);
    w.assign(n * KD, 0), gw.assign(n * KD * D, 0);
  }
  Run(const Run&) = delete;
  Run& operator=(const Run&) = delete;
};

}  // namespace
