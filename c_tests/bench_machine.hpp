// What the C benchmarks (bench_kernels, bench_transfers) say about the machine and the build
// they ran on: the CPU model, the compiler and its flags, the load average.
#pragma once

#include <fstream>
#include <string>

namespace bench_machine {

/// `s` without leading and trailing blanks and tabs.
inline std::string trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t"), e = s.find_last_not_of(" \t");
  return b == std::string::npos ? std::string() : s.substr(b, e - b + 1);
}

/// The first "model name" of /proc/cpuinfo (Linux), or "unknown CPU".
inline std::string cpu_model() {
  std::ifstream in("/proc/cpuinfo");
  std::string line;
  while (std::getline(in, line)) {
    const auto colon = line.find(':');
    if (colon != std::string::npos && trim(line.substr(0, colon)) == "model name") return trim(line.substr(colon + 1));
  }
  return "unknown CPU";
}

/// /proc/loadavg's 1-minute load average (other processes compete for the cores when it is
/// near or above the core count), or "unknown".
inline std::string load_average() {
  std::ifstream in("/proc/loadavg");
  std::string l;
  return in >> l ? l : std::string("unknown");
}

/// The compiler of this binary, with the flags the build passed in AMPM_BENCH_CXX_FLAGS.
inline std::string compiler() {
#if defined(__clang__)
  std::string c = "clang " __clang_version__;
#elif defined(__GNUC__)
  std::string c = "g++ " __VERSION__;
#else
  std::string c = "unknown compiler";
#endif
#ifdef AMPM_BENCH_CXX_FLAGS
  c += " (" AMPM_BENCH_CXX_FLAGS ")";
#endif
  return c;
}

}  // namespace bench_machine
