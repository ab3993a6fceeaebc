// Benchmark of the C batch calls of include/ampm.h against a hand-written Eigen baseline and
// the memory floor of the batch, in one run (the main job writes docs/bench-c.md with it).
//
//   bench_kernels [--n N] [--out FILE]   time every case, print a markdown table (and to FILE)
//   bench_kernels --check [--n N]        agreement check only (N = 1024 by default), for ctest
//
// Workload (fixed seed, the same for every run): N particles (default 65,536),
// F = R1·diag(σ)·R2 with σᵢ log-uniform in [0.5, 2] and R1, R2 Haar rotations, μ = 1, Z with
// entries uniform in [−1, 1]. F, Z and μ are drawn in double and rounded to the precision of the
// case, so f32 and f64 see the same particles. Layout as in README "Conventions": d·d scalars
// per particle, column-major, back to back.
//
// Cases 3D f32, 3D f64, 2D f32, 2D f64. Per case, one thread, std::chrono::steady_clock, one
// warm-up run, then the median of 7 runs over the whole batch, in ns per particle:
//   separate calls  ampm_ahat_batch + ampm_chat_z_batch (two calls, both outputs)
//   combined        ampm_ahat_chat_z_batch (Â and Ĉ:Z from one call)
//   prepare         ampm_hessian_prepare_batch, with Â
//   apply           ampm_hessian_apply_batch with psd = 0 (Ĉ:Z)
//   apply psd       ampm_hessian_apply_batch with psd = 1 (Ĉ⁺:Z)
//   Eigen           the baseline below: one Eigen::JacobiSVD per particle, Â and Ĉ:Z
//   memory floor    a loop moving the bytes of the combined call (reads μ, F, Z; writes two
//                   d×d outputs) and nothing else
//
// Before any timing (and alone in --check mode), the combined call (also with either output
// NULL), prepare + apply(psd = 0) (also prepared without Â) and the Eigen baseline must agree
// with the two separate calls, and apply(psd = 1) with ampm_chat_z_psd_batch: relative
// Frobenius error ‖x − y‖/‖y‖ per particle, in long double, at most 1e-4 (f32) or 1e-10 (f64),
// every status AMPM_OK and every first_failed = n. For Â alone a particle also agrees when
// ‖x − y‖ ≤ 64·ε·2μ‖F̂‖ (see kAhatFloor: Â vanishes at conformal F, its rounding error does
// not); the table counts those particles. Any disagreement exits with status 1 and names the
// particle.
//
// This file holds the command line; the parts are in c_tests/bench_kernels/: api.hpp (the
// constants, the C symbols, aligned buffers), workload.hpp, eigen_baseline.hpp, timing.hpp
// (the memory floor and the timed runs), agreement.hpp, case.hpp (one case: its checked calls,
// comparisons and timings) and report.hpp (the machine and the markdown report).
#include "bench_kernels/api.hpp"
#include "bench_kernels/workload.hpp"
#include "bench_kernels/eigen_baseline.hpp"
#include "bench_kernels/timing.hpp"
#include "bench_kernels/agreement.hpp"
#include "bench_kernels/case.hpp"
#include "bench_kernels/report.hpp"

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>
#include <vector>

namespace {

[[noreturn]] void usage(int code) {
  std::fprintf(code == 0 ? stdout : stderr,
               "usage: bench_kernels [--n N] [--out FILE]   time every case, markdown table\n"
               "       bench_kernels --check [--n N]        agreement check only (N = %zu)\n"
               "default N = %zu particles\n",
               kCheckN, kDefaultN);
  std::exit(code);
}

}  // namespace

int main(int argc, char** argv) {
  bool check = false;
  std::size_t n = 0;
  const char* out = nullptr;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--check") {
      check = true;
    } else if (arg == "--n" && i + 1 < argc) {
      const char* s = argv[++i];
      char* end = nullptr;
      const unsigned long long v = std::strtoull(s, &end, 10);
      if (*s == '\0' || *s == '-' || *end != '\0' || v == 0 || v > (1ULL << 32)) {
        std::fprintf(stderr, "bench_kernels: --n wants an integer in [1, 2^32], got '%s'\n", s);
        return 2;
      }
      n = static_cast<std::size_t>(v);
    } else if (arg == "--out" && i + 1 < argc) {
      out = argv[++i];
    } else if (arg == "--help" || arg == "-h") {
      usage(0);
    } else {
      std::fprintf(stderr, "bench_kernels: unknown or incomplete argument '%s'\n", arg.c_str());
      usage(2);
    }
  }
  if (n == 0) n = check ? kCheckN : kDefaultN;
  const bool timing = !check;

  std::vector<Row> rows;
  std::vector<Agreement> agreements;
  {
    const Workload w3 = make_workload(3, n);
    rows.push_back(run_case<float, 3>(w3, timing, agreements));
    rows.push_back(run_case<double, 3>(w3, timing, agreements));
  }
  {
    const Workload w2 = make_workload(2, n);
    rows.push_back(run_case<float, 2>(w2, timing, agreements));
    rows.push_back(run_case<double, 2>(w2, timing, agreements));
  }

  const std::string text = report(rows, agreements, n, timing);
  std::fputs(text.c_str(), stdout);
  if (out != nullptr) {
    std::ofstream f(out);
    f << text;
    f.close();
    if (!f) {
      std::fprintf(stderr, "bench_kernels: cannot write %s\n", out);
      return 1;
    }
  }
  if (check) std::printf("bench_kernels --check: all results agree (N = %zu)\n", n);
  return 0;
}
