// The timing: the memory floor (a loop moving the combined call's bytes) and the median time
// per particle of a timed call.
#pragma once

#include "bench_kernels/api.hpp"

#include <chrono>

namespace {

/// Moves the bytes of the combined call and does no other work: reads μ, F, Z and writes two
/// d×d outputs per particle (ahat = μF, chat_z = F + Z). noinline so the timed loop is this
/// one, compiled once, not merged into its caller.
template <class T, int D>
__attribute__((noinline)) void memory_floor(std::size_t n, const T* __restrict mu,
                                            const T* __restrict f, const T* __restrict z,
                                            T* __restrict ahat, T* __restrict chat_z) {
  constexpr std::size_t dd = D * D;
  for (std::size_t i = 0; i < n; ++i) {
    const T m = mu[i];
    for (std::size_t k = 0; k < dd; ++k) {
      ahat[i * dd + k] = m * f[i * dd + k];
      chat_z[i * dd + k] = f[i * dd + k] + z[i * dd + k];
    }
  }
}

/// Median over `reps` runs of `body` (after one warm-up run), in ns per particle. `body`
/// returns an AmpmStatus (checked after the clock stops) and writes its first failed index.
template <class Body>
double time_per_particle(const char* what, const char* case_name, std::size_t n, int reps,
                         Body&& body) {
  std::vector<double> ns;
  for (int r = -1; r < reps; ++r) {  // r = −1: warm-up
    std::size_t first_failed = n + 1;
    const auto t0 = std::chrono::steady_clock::now();
    const AmpmStatus st = body(&first_failed);
    const auto t1 = std::chrono::steady_clock::now();
    if (st != AMPM_OK || first_failed != n)
      fail(std::string(case_name) + " " + what + ": status " + status_name(st) +
           ", first_failed " + std::to_string(first_failed) + " (n = " + std::to_string(n) +
           ") during timing");
    if (r >= 0) ns.push_back(std::chrono::duration<double, std::nano>(t1 - t0).count());
  }
  std::sort(ns.begin(), ns.end());
  return ns[ns.size() / 2] / static_cast<double>(n);
}

}  // namespace
