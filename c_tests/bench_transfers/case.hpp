// Timing helpers, the result rows, and one case (scene, scalar, dimension): its particles,
// grid, views and every call the benchmark times.
#pragma once

#include <chrono>

#include "host.hpp"

namespace bench {

// ---- timing --------------------------------------------------------------------------------

/// Median and minimum over `reps` runs of `body` after one warm-up, in ns per particle;
/// `before` runs untimed before each run (restoring state, zeroing outputs).
struct Timing {
  double median = NAN, min = NAN;
};

/// The median of `v` (sorted in place; the upper middle of an even count), as every timing here
/// reports it.
inline double median_of(std::vector<double>& v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

/// The steady-clock interval `t0..t1` in ns per particle of `n`.
inline double ns_per(std::chrono::steady_clock::time_point t0, std::chrono::steady_clock::time_point t1,
                     std::size_t n) {
  return std::chrono::duration<double, std::nano>(t1 - t0).count() / static_cast<double>(n);
}

template <class Before, class Body>
Timing time_ns(int reps, std::size_t n, Before&& before, Body&& body) {
  std::vector<double> ns;
  for (int r = -1; r < reps; ++r) {
    before();
    const auto t0 = std::chrono::steady_clock::now();
    body();
    const auto t1 = std::chrono::steady_clock::now();
    if (r >= 0) ns.push_back(std::chrono::duration<double, std::nano>(t1 - t0).count());
  }
  const double mid = median_of(ns);
  return {mid / static_cast<double>(n), ns.front() / static_cast<double>(n)};
}

template <class Before, class Body>
double median_ns(int reps, std::size_t n, Before&& before, Body&& body) {
  return time_ns(reps, n, before, body).median;
}

struct Row {
  std::string scene, kase, isa;
  std::size_t n = 0, nodes = 0;
  double p2g_sym = NAN, p2g_f = NAN, grid = NAN, g2p = NAN, step = NAN, prepare = NAN, apply = NAN;
  double p2g_sym_min = NAN, g2p_min = NAN, apply_min = NAN;  // fastest run (least disturbed)
  double lib() const { return p2g_sym + g2p; }
  double lib_min() const { return p2g_sym_min + g2p_min; }
};

/// The Eigen baseline and the library (default ISA), elastic 3D f32, timed alternately rep by
/// rep so that both see the same machine state: medians, ns per particle.
struct Baseline {
  std::size_t n = 0;
  double p2g = NAN, g2p = NAN;          // Eigen
  double lib_p2g = NAN, lib_g2p = NAN;  // library, P2G sym + G2P
};

/// The hardware limit of the elastic f32 step in one dimension (c_tests/bench_floor.hpp):
/// memory floors of P2G and G2P (ns per particle) and their bytes per particle, and the
/// arithmetic floors at the measured FMA rate.
struct Floor {
  int d = 0;
  double mem_p2g = NAN, mem_g2p = NAN, bytes_p2g = NAN, bytes_g2p = NAN;
  double fma_per_ns = NAN, fma_p2g = NAN, fma_g2p = NAN;
  double p2g() const { return std::max(mem_p2g, fma_p2g); }
  double g2p() const { return std::max(mem_g2p, fma_g2p); }
};

// ---- one case ------------------------------------------------------------------------------

template <class T, int D>
struct Case {
  using A = Api<T, D>;
  Scene scene;
  Parts<T, D> p0;  // the initial state (restored before every run)
  Parts<T, D> p;
  Grid<T, D> g;
  Views<T, D> v;
  std::vector<T> slots;
  bool thermal;
  T h = static_cast<T>(kH), dt = static_cast<T>(kDt);

  Case(Scene s, int per_axis) : scene(s), p0(make_parts<T, D>(s, per_axis)), p(p0), thermal(s == Scene::Thermal) {
    int lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0};
    std::size_t ff = 0;
    {
      const AmpmStatus st_ = A::node_range(AMPM_KERNEL_QUADRATIC, AMPM_GRID_COLLOCATED, h, p.n, p.x.data(), lo, hi, &ff);
      expect_ok(std::string(A::name) + " node_range", st_, ff, p.n);
    }
    // One node of margin on each side: the block moves by at most |v|·Δt per step.
    for (int a = 0; a < D; ++a) lo[a] -= 1, hi[a] += 1;
    g.reset(lo, hi);
    v = make_views(g, thermal);
    slots.assign(p.n * A::slot_len, 0);
    for (int a = 0; a < D; ++a)
      for (std::size_t k = 0; k < g.count; ++k) g.du[a][k] = static_cast<T>(1e-6 * std::sin(0.37 * k + a));
  }
  std::string label(const char* what) const { return std::string(A::name) + " " + scene_name(scene) + " " + what; }
  void restore() {
    std::copy(p0.x.begin(), p0.x.end(), p.x.begin());
    std::copy(p0.v.begin(), p0.v.end(), p.v.begin());
    std::copy(p0.c.begin(), p0.c.end(), p.c.begin());
    std::copy(p0.fe.begin(), p0.fe.end(), p.fe.begin());
    std::copy(p0.fp.begin(), p0.fp.end(), p.fp.begin());
    std::copy(p0.t.begin(), p0.t.end(), p.t.begin());
    std::copy(p0.u.begin(), p0.u.end(), p.u.begin());
    std::copy(p0.ph.begin(), p0.ph.end(), p.ph.begin());
  }
  // The calls over particles [i, i + k) (the whole batch by default, or a host's block of
  // particles, with `ff` relative to i), through `f`: this binary's symbol by default, another
  // build's with --ab.
  AmpmStatus p2g_sym(std::size_t* ff, decltype(A::p2g) f = A::p2g) { return p2g_sym_range(0, p.n, ff, f); }
  AmpmStatus p2g_sym_range(std::size_t i, std::size_t k, std::size_t* ff, decltype(A::p2g) f = A::p2g) {
    const auto m = material<T, D>(scene, false);
    auto pv = p.view_at(i);
    return f(&m, AMPM_KERNEL_QUADRATIC, AMPM_GRID_COLLOCATED, h, dt, k, &pv, &v.sym, ff);
  }
  AmpmStatus p2g_f(std::size_t* ff) {
    const auto m = material<T, D>(scene, false);
    auto pv = p.view();
    return A::p2g(&m, AMPM_KERNEL_QUADRATIC, AMPM_GRID_COLLOCATED, h, T(0), p.n, &pv, &v.plus_f, ff);
  }
  AmpmStatus g2p(std::size_t* ff, decltype(A::g2p) f = A::g2p) { return g2p_range(0, p.n, ff, f); }
  AmpmStatus g2p_range(std::size_t i, std::size_t k, std::size_t* ff, decltype(A::g2p) f = A::g2p) {
    const auto m = material<T, D>(scene, false);
    auto pv = p.view_at(i);
    return f(&m, AMPM_KERNEL_QUADRATIC, h, dt, k, &pv, &v.g2p, ff);
  }
  AmpmStatus prepare(std::size_t* ff, decltype(A::prepare) f = A::prepare) {
    const auto m = material<T, D>(scene, true);
    auto pv = p.view();
    return f(&m, p.n, &pv, slots.data(), ff);
  }
  AmpmStatus apply(std::size_t* ff, decltype(A::apply) f = A::apply) { return apply_range(0, p.n, ff, f); }
  AmpmStatus apply_range(std::size_t i, std::size_t k, std::size_t* ff, decltype(A::apply) f = A::apply) {
    return f(AMPM_KERNEL_QUADRATIC, h, k, p.x.data() + i * D, slots.data() + i * A::slot_len, &v.force, ff);
  }
  void zero_df() {
    for (int a = 0; a < D; ++a) std::fill(g.df[a].begin(), g.df[a].end(), T(0));
  }
  /// One untimed step of every call, with status checks; leaves the P2G sym grid, its
  /// velocities, and the particles after G2P.
  void run_all_once() {
    std::size_t ff = 0;
    restore();
    g.zero_p2g();
    {
      const AmpmStatus st_ = p2g_f(&ff);
      expect_ok(label("P2G +f"), st_, ff, p.n);
    }
    for (int a = 0; a < D; ++a) g.mom2[a] = g.mom[a];
    g.zero_p2g();
    {
      const AmpmStatus st_ = p2g_sym(&ff);
      expect_ok(label("P2G sym"), st_, ff, p.n);
    }
    grid_update(g, thermal);
    {
      const AmpmStatus st_ = g2p(&ff);
      expect_ok(label("G2P"), st_, ff, p.n);
    }
    restore();
    {
      const AmpmStatus st_ = prepare(&ff);
      expect_ok(label("prepare"), st_, ff, p.n);
    }
    zero_df();
    {
      const AmpmStatus st_ = apply(&ff);
      expect_ok(label("apply"), st_, ff, p.n);
    }
    restore();
  }

  Row time(int reps, std::uint32_t isa) {
    Row r;
    r.scene = scene_name(scene);
    r.kase = A::name;
    r.isa = isa_name(isa);
    r.n = p.n;
    r.nodes = g.count;
    const std::size_t n = p.n;
    std::size_t ff = 0;
    auto check = [&](const char* what, AmpmStatus st) { expect_ok(label(what), st, ff, n); };
    run_all_once();
    const Timing ts = time_ns(reps, n, [&] { g.zero_p2g(); }, [&] { check("P2G sym", p2g_sym(&ff)); });
    r.p2g_sym = ts.median, r.p2g_sym_min = ts.min;
    r.p2g_f = median_ns(reps, n, [&] { g.zero_p2g(); }, [&] { check("P2G +f", p2g_f(&ff)); });
    g.zero_p2g();
    check("P2G sym", p2g_sym(&ff));
    r.grid = median_ns(reps, n, [] {}, [&] { grid_update(g, thermal); });
    const Timing tg = time_ns(reps, n, [&] { restore(); }, [&] { check("G2P", g2p(&ff)); });
    r.g2p = tg.median, r.g2p_min = tg.min;
    r.step = median_ns(reps, n, [&] { restore(); }, [&] {
      g.zero_p2g();
      check("P2G sym", p2g_sym(&ff));
      grid_update(g, thermal);
      check("G2P", g2p(&ff));
    });
    restore();
    r.prepare = median_ns(reps, n, [] {}, [&] { check("prepare", prepare(&ff)); });
    const Timing ta = time_ns(reps, n, [] {}, [&] {
      zero_df();
      check("apply", apply(&ff));
    });
    r.apply = ta.median, r.apply_min = ta.min;
    restore();
    return r;
  }
};

}  // namespace bench
