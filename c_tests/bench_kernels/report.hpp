// The machine (CPU model and ISA flags, the compiler and its flags) and the markdown report.
#pragma once

#include "bench_kernels/agreement.hpp"
#include "bench_kernels/api.hpp"
#include "bench_kernels/case.hpp"
#include "bench_machine.hpp"

#include <fstream>
#include <sstream>

namespace {

struct Machine {
  std::string model = "unknown CPU";
  bool have_flags = false, avx512f = false, avx2 = false, fma = false;
};

using bench_machine::trim;

/// CPU model and ISA flags from the first processor of /proc/cpuinfo (Linux).
Machine read_machine() {
  Machine m;
  std::ifstream in("/proc/cpuinfo");
  std::string line;
  bool have_model = false;
  while (std::getline(in, line)) {
    const auto colon = line.find(':');
    if (colon == std::string::npos) continue;
    const std::string key = trim(line.substr(0, colon)), val = trim(line.substr(colon + 1));
    if (key == "model name" && !have_model) {
      m.model = val;
      have_model = true;
    } else if (key == "flags" && !m.have_flags) {
      m.have_flags = true;
      std::istringstream ss(val);
      std::string flag;
      while (ss >> flag) {
        m.avx512f |= flag == "avx512f";
        m.avx2 |= flag == "avx2";
        m.fma |= flag == "fma";
      }
    }
    if (have_model && m.have_flags) break;
  }
  return m;
}

using bench_machine::compiler;

/// The ISA extensions this binary (the Eigen baseline and the memory floor) was compiled for.
std::string compiled_for() {
  std::string s;
#ifdef __AVX512F__
  s += " avx512f";
#endif
#ifdef __AVX2__
  s += " avx2";
#endif
#ifdef __FMA__
  s += " fma";
#endif
  return s.empty() ? " baseline x86-64 / none of avx512f, avx2, fma" : s;
}

std::string fmt(double ns) {
  if (std::isnan(ns)) return "n/a";
  char b[32];
  std::snprintf(b, sizeof b, ns < 10 ? "%.2f" : ns < 100 ? "%.1f" : "%.0f", ns);
  return b;
}

std::string report(const std::vector<Row>& rows, const std::vector<Agreement>& agreements,
                   std::size_t n, bool timing) {
  const Machine m = read_machine();
  auto yn = [&](bool b) { return m.have_flags ? (b ? "yes" : "no") : "unknown"; };
  std::ostringstream o;
  o << "# ampm C batch calls vs a hand-written Eigen baseline\n\n";
  o << "CPU: " << m.model << "; ISA (/proc/cpuinfo): avx512f " << yn(m.avx512f) << ", avx2 "
    << yn(m.avx2) << ", fma " << yn(m.fma) << "; N = " << n << "; compiler: " << compiler()
    << ", baseline built for" << compiled_for() << "\n\n";
  if (timing) {
    o << "ns per particle, one thread, median of " << kReps
      << " runs over the whole batch after one warm-up run (`c_tests/bench_kernels`). "
         "F = R1·diag(σ)·R2, σ log-uniform in [0.5, 2], R1, R2 Haar, μ = 1, Z uniform in "
         "[−1, 1].\n\n";
    o << "| case | separate calls | combined | prepare | apply | apply psd | Eigen | memory "
         "floor | Eigen/combined |\n";
    o << "|---|---:|---:|---:|---:|---:|---:|---:|---:|\n";
    for (const Row& r : rows) {
      std::string ratio = "n/a";
      if (!std::isnan(r.combined) && r.combined > 0) {
        char b[32];
        std::snprintf(b, sizeof b, "%.2f", r.eigen / r.combined);
        ratio = b;
      }
      o << "| " << r.name << " | " << fmt(r.separate) << " | " << fmt(r.combined) << " | "
        << fmt(r.prepare) << " | " << fmt(r.apply) << " | " << fmt(r.apply_psd) << " | "
        << fmt(r.eigen) << " | " << fmt(r.floor) << " | " << ratio << " |\n";
    }
    o << "\n";
    o << "- separate calls: `ampm_ahat_batch` + `ampm_chat_z_batch`; combined: "
         "`ampm_ahat_chat_z_batch` (both outputs); prepare: `ampm_hessian_prepare_batch` with "
         "Â; apply / apply psd: `ampm_hessian_apply_batch` with psd = 0 (Ĉ:Z) / 1 (Ĉ⁺:Z).\n";
    o << "- Eigen: per particle one `Eigen::JacobiSVD` (full U, V), Â and Ĉ:Z from README "
         "\"The math in short\", fixed-size types, no heap.\n";
    o << "- memory floor: a loop that reads μ, F, Z and writes two d×d outputs (";
    for (std::size_t i = 0; i < rows.size(); ++i)
      o << (i ? ", " : "") << rows[i].name << ": " << rows[i].floor_bytes << " B";
    o << " per particle), the bytes the combined call moves; it fits in whatever cache level "
         "that working set fits at this N.\n";
    o << "\n";
  }
  o << "Agreement with the separate calls (`ampm_ahat_batch`, `ampm_chat_z_batch`; for Ĉ⁺:Z "
       "`ampm_chat_z_psd_batch`), per particle: relative Frobenius error "
       "‖x − y‖/‖y‖ in long double at most the tolerance; for Â also accepted: "
       "‖x − y‖ ≤ " << static_cast<int>(kAhatFloor)
    << "·ε·2μ‖F̂‖ (Â → 0 as F becomes conformal while its rounding error does not; such "
       "particles are counted). Every status AMPM_OK, every first_failed = n.\n\n";
  o << "| case | result | max rel err | tolerance | within the Â floor only | bit-identical "
       "particles |\n";
  o << "|---|---|---:|---:|---:|---:|\n";
  for (const Agreement& a : agreements) {
    char e[32], t[32];
    std::snprintf(e, sizeof e, "%.2Le", a.max_err);
    std::snprintf(t, sizeof t, "%.0Le", a.tol);
    o << "| " << a.case_name << " | " << a.what << " | " << e << " | " << t << " | "
      << (a.has_floor ? std::to_string(a.by_floor) : std::string("—")) << " | " << a.identical
      << " / " << a.n << " |\n";
  }
  return o.str();
}

}  // namespace
