// Benchmark of the particle transfers of include/ampm.h in a host's time-step loop, against the
// loop a host would write itself with Eigen, in one run (`docs/bench-transfers.md`).
//
//   bench_transfers [--out FILE] [--reps R]   time every case, markdown table to stdout and FILE
//                                             (default docs/bench-transfers.md)
//   bench_transfers --check                   tiny sizes, agreement checks only (for ctest)
//   bench_transfers --ab A.so B.so [--reps R] [--block N] [--only TEXT]
//                                             two builds of libampm.so, loaded with dlopen, timed
//                                             alternately call by call (A/B comparison); with
//                                             --block, P2G, G2P and apply in calls of N particles;
//                                             with --only, the cases whose label ("elastic 2D f32
//                                             AVX-512") contains TEXT (for a profiler)
//
// This file holds the command line; the parts are in c_tests/bench_transfers/: host.hpp (the
// workload: scenes, particles, the host's grid), eigen_baseline.hpp, case.hpp (one case and
// its timed calls), checks.hpp, hpp_step.hpp (the ampm.hpp step), blocks.hpp (block calls),
// report.hpp (the markdown report and the timing of every case) and ab.hpp (--ab).
//
// Workload (fixed seed): a block of particles, 2 per cell per axis (spacing h/2, jittered by
// ±h/8), 38³ = 54,872 particles in 3D and 234² = 54,756 in 2D, h = 1 cm, quadratic B-splines,
// the collocated grid sized to the block by ampm_node_range_*, dense x-fastest arrays. The
// particles are shuffled, then sorted by cell (x fastest) as a host does before its transfers.
// Scene levels (AmpmMaterial):
//   elastic   solid, fixed corotated, explicit dilation (μ = λ = 1e5 Pa), F_E = R1 diag(σ) R2,
//             σ in [0.95, 1.05];
//   fluid     liquid particles (μ = 0), explicit dilation λ = 1e5 Pa, F_E = J^(1/d) I;
//   thermal   AMPM_MODEL_THERMAL | AMPM_MODEL_PHASE_CHANGE, ice at 260 K, particles at the
//             melting point with a half-filled latent buffer, water at 290 K; the grid is 0.5 K
//             warmer after the host's (stand-in) heat step, FLIP 0.95;
//   snow      AMPM_MODEL_PLASTIC (θ_c = 0.025, θ_s = 0.0075, ξ = 10), σ near the clamp.
// Timed, one thread, std::chrono::steady_clock, one warm-up run and the median of R = 7 runs
// (--reps), in ns per particle per step:
//   P2G sym     ampm_p2g_* with impulse_dt = Δt and no force channel (m v* + Δt f into the
//               momentum channel: the symplectic-Euler form), plus heat channels when thermal;
//   P2G +f      ampm_p2g_* with impulse_dt = 0 and separate force channels;
//   grid        the host's grid update (v = p/m; T = E/C), not library time, reported per
//               particle for comparison;
//   G2P         ampm_g2p_update_* (the particle state is restored between runs, untimed);
//   step        zeroing the grid + P2G sym + grid update + G2P, everything a step does;
//   lib         P2G sym + G2P, the library's share of a step (the targets are on this);
//   prepare     ampm_force_prepare_* with AMPM_MODEL_PSD_HESSIAN (once per Newton step);
//   apply       zeroing df + ampm_force_apply_* (once per CG iteration).
// Every case runs on every instruction set ampm_set_isa accepts (AVX-512, AVX2, scalar).
// Eigen baseline (elastic 3D f32): the same P2G sym + G2P loop written by hand as a host
// would: per particle one Eigen::JacobiSVD (full U, V) for the polar decomposition of the
// stress, the same B-spline loops, the same grid arrays, built with the flags below. It is timed
// alternately with the library's P2G sym and G2P, call by call, so that a change of the machine's
// speed during the run (other tenants of a virtual machine) affects both alike.
// Hardware limit (elastic, 3D and 2D f32; c_tests/bench_floor.hpp): the memory floor (the
// bytes of each call's interface streamed once) and the arithmetic floor (the node loops'
// FMAs at the measured FMA rate), timed in the same run and set against the library and the
// baseline.
//
// ampm.hpp (zero-cost check): the elastic 3D f32 step (zeroing + P2G sym + grid + G2P) written
// against the C++ wrapper include/ampm.hpp (Material, Particles and view builders, ampm::p2g,
// ampm::g2p_update; builders made where the C path fills its structs) is timed in the same run,
// alternating with the C step rep by rep on the default instruction set; the ratio hpp / C of
// the medians is reported (≈ 1.00 when the wrapper costs nothing). Before timing, and in
// --check, the wrapper's step must give bit-identical grids and particles to the C step.
//
// Block calls (elastic and fluid 3D f32, elastic 2D f32, default instruction set): lib and apply
// with the particles in calls of 4096, 512 and 64 consecutive particles (a threaded host's
// blocks; every call into the same grid views) against one call, the sizes alternating rep by
// rep; the report gives the ratio to one call and the cost per extra call. Before timing, G2P
// in calls of 64 must leave the particles bit-identical to one call (a particle's result does
// not depend on the batch it is in).
//
// --ab: two builds of the library (say, before and after a change) in one process, each
// loaded from its own libampm.so with dlopen (its own copy of the library's state). For every
// scene but snow, 3D and 2D f32, every instruction set both accept: lib (P2G sym + G2P, each
// build its own P2G, grid update and G2P), prepare and apply (zeroing df + apply), the two
// builds alternating rep by rep (which goes first alternates too), so that both see the same
// machine state; medians of R reps (default 31) and the ratio B / A. A change of a few
// percent, below the spread between separate runs of the benchmark, shows in the ratio. Both
// builds must return AMPM_OK and the same results, bit for bit (P2G's node channels; G2P's
// particle positions, velocities, C, F_E, F_P, temperatures, latent buffers and phases;
// prepare's slots; apply's forces), checked before timing: a performance change must not
// change them. With --block N, P2G, G2P and apply run in calls of N consecutive particles (a
// threaded host's blocks, as in the block timing), which weighs each call's fixed cost.
//
// --check (and every timing run, before timing): on tiny blocks (6³, 14²), every call returns
// AMPM_OK with first_failed = n and finite results; for the elastic scene the library's and the
// baseline's P2G grids and G2P particles agree with the same loop evaluated in long double
// (tolerances C·ε·scale as in c_tests/test_particle_eigen.cpp: C = 256 + n_add for node sums
// involving the stress, 64 + 2·K^d + n_add otherwise, scale = the sum of the magnitudes of the
// terms); P2G sym equals P2G +f's momentum + Δt·force to the same bound; AVX2 and AVX-512 give
// bit-identical grids and prepared slots, the scalar path agrees to the bound.
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "ampm.h"

#include "bench_transfers/host.hpp"
#include "bench_transfers/eigen_baseline.hpp"
#include "bench_transfers/case.hpp"
#include "bench_transfers/checks.hpp"
#include "bench_transfers/hpp_step.hpp"
#include "bench_transfers/blocks.hpp"
#include "bench_transfers/report.hpp"
#include "bench_transfers/ab.hpp"

namespace bench {

[[noreturn]] inline void usage(int code) {
  std::fprintf(code == 0 ? stdout : stderr,
               "usage: bench_transfers [--out FILE] [--reps R]   time every case (default FILE docs/bench-transfers.md)\n"
               "       bench_transfers --check                   agreement checks only, tiny sizes\n"
               "       bench_transfers --ab A.so B.so [--reps R] [--block N] [--only TEXT]\n"
               "                 two builds of libampm.so timed alternately (P2G, G2P and apply in calls of\n"
               "                 N particles with --block; default one call); with --only, the cases whose\n"
               "                 label (\"elastic 2D f32 AVX-512\") contains TEXT\n");
  std::exit(code);
}

}  // namespace bench

using namespace bench;


int main(int argc, char** argv) {
  bool check = false;
  int reps = kDefaultReps;
  std::string out = "docs/bench-transfers.md";
  bool out_given = false;
  std::string ab[2];
  bool reps_given = false;
  std::size_t block = 0;
  std::string only;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--check") {
      check = true;
    } else if (arg == "--ab" && i + 2 < argc) {
      ab[0] = argv[++i];
      ab[1] = argv[++i];
    } else if (arg == "--out" && i + 1 < argc) {
      out = argv[++i];
      out_given = true;
    } else if (arg == "--block" && i + 1 < argc) {
      const long b = std::atol(argv[++i]);
      if (b < 1) fail("--block wants a positive particle count");
      block = static_cast<std::size_t>(b);
    } else if (arg == "--only" && i + 1 < argc) {
      only = argv[++i];
    } else if (arg == "--reps" && i + 1 < argc) {
      reps = std::atoi(argv[++i]);
      if (reps < 1 || reps > 1000) fail("--reps wants 1..1000");
      reps_given = true;
    } else if (arg == "--help" || arg == "-h") {
      usage(0);
    } else {
      std::fprintf(stderr, "bench_transfers: unknown or incomplete argument '%s'\n", arg.c_str());
      usage(2);
    }
  }
  if (!ab[0].empty()) return run_ab(ab[0], ab[1], reps_given ? reps : 31, block, only);
  const std::uint32_t default_isa = ampm_isa();
  std::vector<std::uint32_t> isas;
  for (std::uint32_t isa : {std::uint32_t{AMPM_ISA_AVX512}, std::uint32_t{AMPM_ISA_AVX2}, std::uint32_t{AMPM_ISA_SCALAR}})
    if (ampm_set_isa(isa) == AMPM_OK) isas.push_back(isa);
  ampm_set_isa(default_isa);

  // ---- agreement checks (always) ----
  CheckLog log;
  check_elastic<float, 3>(6, log);
  check_elastic<double, 3>(6, log);
  check_elastic<float, 2>(14, log);
  check_elastic<double, 2>(14, log);
  for (Scene s : kScenes) {
    check_isas<float, 3>(s, 6, isas, log);
    check_isas<double, 3>(s, 6, isas, log);
    check_isas<float, 2>(s, 14, isas, log);
    check_isas<double, 2>(s, 14, isas, log);
  }
  ampm_set_isa(default_isa);
  for (Scene s : kScenes) {
    check_blocks<float, 3>(s, 6, log);
    check_blocks<float, 2>(s, 14, log);
  }
  check_hpp(6, log);
  if (check) {
    std::printf("bench_transfers --check: all results agree\n");
    if (!out_given) return 0;
  }

  // ---- timing ----
  const std::string load_before = load_average();
  std::vector<Row> rows;
  const int n3 = check ? 6 : 38, n2 = check ? 14 : 234;
  for (Scene s : kScenes) {
    time_case<float, 3>(s, n3, reps, isas, rows);
    time_case<double, 3>(s, n3, reps, isas, rows);
    time_case<float, 2>(s, n2, reps, isas, rows);
    time_case<double, 2>(s, n2, reps, isas, rows);
  }
  ampm_set_isa(default_isa);
  const Baseline base = time_baseline(n3, reps);
  const double fma_rate = bench_floor::fma_per_ns(reps);
  const std::vector<Floor> floors{time_floor<3>(n3, reps, fma_rate), time_floor<2>(n2, reps, fma_rate)};
  for (const Floor& f : floors)
    std::fprintf(stderr, "floor %dD f32: memory P2G %.1f G2P %.1f ns (%.0f / %.0f B), arithmetic %.1f / %.1f ns\n", f.d,
                 f.mem_p2g, f.mem_g2p, f.bytes_p2g, f.bytes_g2p, f.fma_p2g, f.fma_g2p);
  const HppTiming hpp = time_hpp(n3, reps);
  std::fprintf(stderr, "ampm.hpp elastic 3D f32 step: C %.1f ns, ampm.hpp %.1f ns, ratio %.3f (fastest %.3f)\n", hpp.c,
               hpp.hpp, hpp.hpp / hpp.c, hpp.hpp_min / hpp.c_min);
  std::vector<BlockTiming> blocks;
  blocks.push_back(time_blocks<float, 3>(Scene::Elastic, n3, reps));
  blocks.push_back(time_blocks<float, 3>(Scene::Fluid, n3, reps));
  blocks.push_back(time_blocks<float, 2>(Scene::Elastic, n2, reps));
  const std::string text = report(rows, base, floors, hpp, blocks, log.lines, reps, default_isa, load_before);
  std::fputs(text.c_str(), stdout);
  std::ofstream f(out);
  f << text;
  f.close();
  if (!f) fail("cannot write " + out);
  return 0;
}
