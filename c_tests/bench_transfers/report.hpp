// The markdown report (the cost table, the targets, the Eigen baseline, the hardware floor,
// the wrapper and the block calls) and the timing of every case.
#pragma once

#include <fstream>
#include <sstream>
#include <thread>

#include "bench_floor.hpp"
#include "blocks.hpp"
#include "case.hpp"
#include "eigen_baseline.hpp"
#include "hpp_step.hpp"

namespace bench {

inline std::string fmt(double ns) {
  if (std::isnan(ns)) return "n/a";
  char b[32];
  std::snprintf(b, sizeof b, ns < 10 ? "%.2f" : ns < 100 ? "%.1f" : "%.0f", ns);
  return b;
}

/// Target of the library time (P2G sym + G2P) of a row, ns, or NaN.
inline double lib_target(const Row& r) {
  if (r.kase == "3D f32") {
    if (r.scene == std::string("elastic")) return 100;
    if (r.scene == std::string("fluid")) return 60;
    if (r.scene == std::string("thermal+phase")) return 130;
  }
  if (r.kase == "2D f32" && r.scene == std::string("elastic")) return 30;
  return NAN;
}

inline std::string verdict(double got, double target) {
  if (std::isnan(target)) return "";
  return got <= target ? " ✓" : " ✗";
}

/// The hardware-limit section of the report: per dimension, the floors against the library
/// (default ISA) and, in 3D, the Eigen baseline, all from this run.
inline std::string floor_report(const std::vector<Row>& rows, const Baseline& base, const std::vector<Floor>& floors,
                         std::uint32_t default_isa) {
  std::ostringstream o;
  char buf[64];
  o << "Hardware limit, elastic f32, measured in this run (`c_tests/bench_floor.hpp`). Memory floor: the bytes "
       "each call's interface reads and writes (every particle array it reads, summed; every array it updates, "
       "read and written back; the grid channels), streamed once in order. Arithmetic floor: the node loops' "
       "fused multiply-adds alone (per node 2 + 3d + d² for P2G, d(1 + 2d) for G2P; constitutive model, "
       "weights and checks not counted) at the FMA rate measured on independent accumulators";
  if (!floors.empty()) {
    std::snprintf(buf, sizeof buf, " (%.0f f32 FMAs per ns)", floors.front().fma_per_ns);
    o << buf;
  }
  o << ". The floor is the larger of the two: any implementation of these calls moves these bytes and does at least "
       "these multiply-adds, so it cannot be much faster than the floor on this machine.\n\n";
  o << "| | P2G sym | G2P | P2G + G2P | × floor |\n|---|---:|---:|---:|---:|\n";
  for (const Floor& f : floors) {
    const std::string kase = std::to_string(f.d) + "D f32";
    const Row* lib = nullptr;
    for (const Row& r : rows)
      if (r.isa == isa_name(default_isa) && r.kase == kase && r.scene == std::string("elastic")) lib = &r;
    const double floor = f.p2g() + f.g2p();
    auto line = [&](const std::string& what, double p2g, double g2p) {
      std::snprintf(buf, sizeof buf, "%.1f", (p2g + g2p) / floor);
      o << "| " << kase << " " << what << " | " << fmt(p2g) << " | " << fmt(g2p) << " | " << fmt(p2g + g2p) << " | "
        << buf << " |\n";
    };
    std::snprintf(buf, sizeof buf, "%.0f / %.0f", f.bytes_p2g, f.bytes_g2p);
    line(std::string("memory floor (") + buf + " B per particle)", f.mem_p2g, f.mem_g2p);
    line("arithmetic floor (node loops)", f.fma_p2g, f.fma_g2p);
    line("**floor**", f.p2g(), f.g2p());
    if (f.d == 3) {
      line(std::string("library (") + isa_name(default_isa) + "), alternating with the baseline", base.lib_p2g,
           base.lib_g2p);
      line("Eigen baseline, alternating with the library", base.p2g, base.g2p);
    } else if (lib) {
      line(std::string("library (") + isa_name(default_isa) + ")", lib->p2g_sym, lib->g2p);
    }
    std::snprintf(buf, sizeof buf, "%.1f", f.d == 3 ? 100 / floor : 30 / floor);
    o << "| " << kase << " target (" << (f.d == 3 ? 100 : 30) << " ns) | | | " << (f.d == 3 ? 100 : 30) << " | " << buf
      << " |\n";
  }
  o << "\n";
  return o.str();
}

inline std::string report(const std::vector<Row>& rows, const Baseline& base, const std::vector<Floor>& floors,
                   const HppTiming& hpp, const std::vector<BlockTiming>& blocks, const std::vector<std::string>& checks,
                   int reps, std::uint32_t default_isa, const std::string& load_before) {
  std::ostringstream o;
  o << "# ampm particle transfers in a host's step loop\n\n";
  o << "CPU: " << cpu_model() << "; default instruction set (`ampm_isa()`): " << isa_name(default_isa)
    << "; compiler: " << compiler() << " for the host code and the Eigen baseline; libampm built by cargo "
    << "(release). One thread, no OpenMP. `c_tests/bench_transfers`. Load average (1 min) before / after the "
    << "timing: " << load_before << " / " << load_average() << " on " << std::thread::hardware_concurrency()
    << " hardware threads.\n\n";
  o << "ns per particle per step, median of " << reps
    << " runs after one warm-up run. Quadratic B-splines, 2 particles per cell per axis (spacing h/2), "
       "38³ = 54,872 particles (3D) or 234² = 54,756 (2D), particles sorted by cell, grid sized to the block. "
       "P2G sym: impulse_dt = Δt, no force channel; P2G +f: impulse_dt = 0 and force channels; grid: the "
       "host's update (v = p/m, T = E/C), not library time; G2P: ampm_g2p_update_*; step: zeroing + P2G sym "
       "+ grid + G2P; lib = P2G sym + G2P (the targets); prepare: ampm_force_prepare_* (PSD), once per Newton "
       "step; apply: zeroing df + ampm_force_apply_*, once per CG iteration.\n\n";
  o << "| scene | case | ISA | P2G sym | P2G +f | grid (host) | G2P | step | lib | lib target | prepare | apply | "
       "apply target |\n";
  o << "|---|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n";
  for (const Row& r : rows) {
    const double t = lib_target(r);
    const double at = r.kase == "3D f32" ? 40 : NAN;
    o << "| " << r.scene << " | " << r.kase << " | " << r.isa << " | " << fmt(r.p2g_sym) << " | " << fmt(r.p2g_f) << " | "
      << fmt(r.grid) << " | " << fmt(r.g2p) << " | " << fmt(r.step) << " | " << fmt(r.lib()) << verdict(r.lib(), t)
      << " | " << (std::isnan(t) ? "—" : fmt(t)) << " | " << fmt(r.prepare) << " | " << fmt(r.apply)
      << verdict(r.apply, at) << " | " << (std::isnan(at) ? "—" : fmt(at)) << " |\n";
  }
  o << "\nTargets (on the default instruction set): 3D f32 lib elastic ≤ 100 ns, fluid ≤ 60 ns, thermal+phase ≤ "
       "130 ns; 2D f32 elastic ≤ 30 ns; 3D f32 force apply ≤ 40 ns. ✓ met, ✗ not met.\n\n";
  // Summary against the targets on the default ISA.
  o << "| target (default ISA, " << isa_name(default_isa) << ") | median | fastest run | met (median) |\n"
       "|---|---:|---:|---|\n";
  for (const Row& r : rows) {
    if (r.isa != isa_name(default_isa)) continue;
    const double t = lib_target(r);
    if (!std::isnan(t))
      o << "| " << r.kase << " " << r.scene << " P2G + G2P ≤ " << fmt(t) << " ns | " << fmt(r.lib()) << " | "
        << fmt(r.lib_min()) << " | " << (r.lib() <= t ? "yes" : "no") << " |\n";
    if (r.kase == "3D f32" && r.scene == std::string("elastic"))
      o << "| 3D f32 force apply ≤ 40 ns | " << fmt(r.apply) << " | " << fmt(r.apply_min) << " | "
        << (r.apply <= 40 ? "yes" : "no") << " |\n";
  }
  o << "\n";
  o << "Hand-written Eigen baseline, elastic 3D f32 (" << base.n
    << " particles): the same P2G sym + G2P loop a host writes itself, one `Eigen::JacobiSVD` (full U, V) per "
       "particle for the stress, the same B-spline loops and grid arrays. Timed against the library ("
    << isa_name(default_isa)
    << ") alternately, call by call (library P2G, Eigen P2G, library G2P, Eigen G2P, one warm-up round), so that "
       "both see the same machine state; medians of the rounds.\n\n";
  o << "| | P2G sym | G2P | P2G + G2P | baseline / library |\n|---|---:|---:|---:|---:|\n";
  char ratio[32];
  std::snprintf(ratio, sizeof ratio, "%.2f", (base.p2g + base.g2p) / (base.lib_p2g + base.lib_g2p));
  o << "| library (" << isa_name(default_isa) << ") | " << fmt(base.lib_p2g) << " | " << fmt(base.lib_g2p) << " | "
    << fmt(base.lib_p2g + base.lib_g2p) << " | |\n";
  o << "| Eigen baseline | " << fmt(base.p2g) << " | " << fmt(base.g2p) << " | " << fmt(base.p2g + base.g2p) << " | "
    << ratio << " |\n\n";
  o << floor_report(rows, base, floors, default_isa);
  o << "C++ wrapper `include/ampm.hpp`, elastic 3D f32 (" << hpp.n << " particles, " << isa_name(default_isa)
    << "): the step (zeroing + P2G sym + grid + G2P) through `ampm::p2g` / `ampm::g2p_update` with the "
       "builders made per call, against the same step through the C calls, alternating rep by rep.\n\n";
  char hr[32], hr_min[32];
  std::snprintf(hr, sizeof hr, "%.2f", hpp.hpp / hpp.c);
  std::snprintf(hr_min, sizeof hr_min, "%.2f", hpp.hpp_min / hpp.c_min);
  o << "| | step, C calls | step, ampm.hpp | ampm.hpp / C |\n|---|---:|---:|---:|\n";
  o << "| median | " << fmt(hpp.c) << " | " << fmt(hpp.hpp) << " | " << hr << " |\n";
  o << "| fastest run | " << fmt(hpp.c_min) << " | " << fmt(hpp.hpp_min) << " | " << hr_min << " |\n\n";
  o << "Block calls (" << isa_name(default_isa)
    << "): the same lib (P2G sym + G2P) and apply, each call over a range of consecutive particles (the "
       "sorted order) into the same grid views, as a host that gives each thread its blocks makes them; "
       "the sizes alternate rep by rep. ns per particle per step (ratio to one call); per call: the "
       "difference to one call divided by the extra calls (lib: two calls per block), given for blocks of at "
       "most " << kPerCallMax << " particles (above that the difference is within the spread between runs).\n\n";
  o << "| scene | case | particles per call | lib | apply | per call, lib | per call, apply |\n"
       "|---|---|---:|---:|---:|---:|---:|\n";
  for (const BlockTiming& b : blocks)
    for (int j = 0; j < kNumBlocks; ++j) {
      char row[256];
      const double calls = j == 0 ? 1.0 : std::ceil(static_cast<double>(b.n) / static_cast<double>(kBlocks[j]));
      const double nn = static_cast<double>(b.n);
      if (j == 0 || kBlocks[j] > kPerCallMax)
        std::snprintf(row, sizeof row, "| %s | %s | %s | %s%s | %s%s | — | — |\n", b.scene.c_str(), b.kase.c_str(),
                      j == 0 ? ("all (" + std::to_string(b.n) + ")").c_str() : std::to_string(kBlocks[j]).c_str(),
                      fmt(b.lib[j]).c_str(), j == 0 ? "" : ratio_text(b.lib[j] / b.lib[0]).c_str(),
                      fmt(b.apply[j]).c_str(), j == 0 ? "" : ratio_text(b.apply[j] / b.apply[0]).c_str());
      else
        std::snprintf(row, sizeof row, "| %s | %s | %zu | %s (%.2f) | %s (%.2f) | %.0f ns | %.0f ns |\n",
                      b.scene.c_str(), b.kase.c_str(), kBlocks[j], fmt(b.lib[j]).c_str(), b.lib[j] / b.lib[0],
                      fmt(b.apply[j]).c_str(), b.apply[j] / b.apply[0], (b.lib[j] - b.lib[0]) * nn / (2 * (calls - 1)),
                      (b.apply[j] - b.apply[0]) * nn / (calls - 1));
      o << row;
    }
  o << "\n";
  o << "Agreement checks (run before timing; `bench_transfers --check` runs them alone on 6³ / 14² blocks):\n\n";
  for (const std::string& c : checks) o << "- " << c << "\n";
  return o.str();
}

template <class T, int D>
void time_case(Scene s, int per_axis, int reps, const std::vector<std::uint32_t>& isas, std::vector<Row>& rows) {
  Case<T, D> cs(s, per_axis);
  for (std::uint32_t isa : isas) {
    if (ampm_set_isa(isa) != AMPM_OK) fail("ampm_set_isa failed");
    rows.push_back(cs.time(reps, isa));
    const Row& r = rows.back();
    std::fprintf(stderr, "%-14s %s %-8s P2G sym %6.1f  P2G +f %6.1f  grid %5.1f  G2P %6.1f  step %6.1f  prepare %6.1f  apply %6.1f\n",
                 r.scene.c_str(), r.kase.c_str(), r.isa.c_str(), r.p2g_sym, r.p2g_f, r.grid, r.g2p, r.step, r.prepare, r.apply);
  }
}

inline Baseline time_baseline(int per_axis, int reps) {
  Case<float, 3> cs(Scene::Elastic, per_axis);
  Baseline b;
  b.n = cs.p.n;
  const float mu = static_cast<float>(kMu), lambda = static_cast<float>(kLambda);
  std::size_t ff = 0;
  auto check = [&](const char* what, AmpmStatus st) { expect_ok(std::string("baseline run, library ") + what, st, ff, cs.p.n); };
  auto once = [&](auto&& before, auto&& body) {
    before();
    const auto t0 = std::chrono::steady_clock::now();
    body();
    const auto t1 = std::chrono::steady_clock::now();
    return ns_per(t0, t1, cs.p.n);
  };
  std::vector<double> ep, eg, lp, lg;
  auto zero = [&] { cs.g.zero_p2g(); };
  auto restore = [&] { cs.restore(); };
  for (int r = -1; r < reps; ++r) {
    // P2G: library, then Eigen; the grid update from Eigen's P2G feeds both G2Ps (the two P2G
    // grids agree to rounding, checked before timing).
    const double a = once(zero, [&] { check("P2G sym", cs.p2g_sym(&ff)); });
    const double b2 = once(zero, [&] { eigen_p2g<float, 3>(cs.p, cs.g, cs.h, cs.dt, mu, lambda, nullptr); });
    grid_update(cs.g, false);
    const double c = once(restore, [&] { check("G2P", cs.g2p(&ff)); });
    const double d = once(restore, [&] { eigen_g2p<float, 3>(cs.p, cs.g, cs.h, cs.dt); });
    if (r >= 0) lp.push_back(a), ep.push_back(b2), lg.push_back(c), eg.push_back(d);
  }
  cs.restore();
  b.p2g = median_of(ep), b.g2p = median_of(eg), b.lib_p2g = median_of(lp), b.lib_g2p = median_of(lg);
  return b;
}

template <int D>
Floor time_floor(int per_axis, int reps, double fma_per_ns) {
  Case<float, D> cs(Scene::Elastic, per_axis);
  auto& p = cs.p;
  auto& g = cs.g;
  // The arrays the elastic calls read and write (include/ampm.h): P2G reads every particle
  // array and adds into mass and momentum; G2P reads mass, volume and the node velocities,
  // and updates x, v, affine, F_E, F_P.
  bench_floor::Streams<float> p2g{{&p.x, &p.v, &p.c, &p.fe, &p.fp, &p.m, &p.v0}, {&g.mass}};
  bench_floor::Streams<float> g2p{{&p.m, &p.v0}, {&p.x, &p.v, &p.c, &p.fe, &p.fp}};
  for (int a = 0; a < D; ++a) p2g.update.push_back(&g.mom[a]), g2p.read.push_back(&g.vel[a]);
  volatile float one_v = 1.0f;
  const float one = one_v;
  Floor f;
  f.d = D;
  const auto n = static_cast<double>(p.n);
  f.bytes_p2g = static_cast<double>(p2g.bytes()) / n;
  f.bytes_g2p = static_cast<double>(g2p.bytes()) / n;
  f.mem_p2g = median_ns(reps, p.n, [] {}, [&] { bench_floor::stream(p2g, one); });
  f.mem_g2p = median_ns(reps, p.n, [] {}, [&] { bench_floor::stream(g2p, one); });
  f.fma_per_ns = fma_per_ns;
  f.fma_p2g = bench_floor::p2g_fmas(D) / fma_per_ns;
  f.fma_g2p = bench_floor::g2p_fmas(D) / fma_per_ns;
  return f;
}

}  // namespace bench
