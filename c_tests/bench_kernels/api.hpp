// The base of the benchmark: its constants, the C symbols by (scalar, dimension), status names,
// fail(), and 64-byte aligned buffers.
#pragma once

// <cstddef>/<cstdint> before ampm.h, as in common.hpp.
#include <cstddef>
#include <cstdint>

#include "ampm.h"
#include "common.hpp"  // Rng (portable seeded draws), status names

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <new>
#include <string>
#include <vector>

namespace {

using ampm_test::Rng;
using ld = long double;

constexpr std::uint64_t kSeed = 0xbe4c'a3b1'2014'0001ULL;
constexpr std::size_t kDefaultN = 65536;
constexpr std::size_t kCheckN = 1024;
constexpr int kReps = 7;

// ---- the C symbols by (scalar, dimension) --------------------------------------------------

template <class T, int D>
struct Api;

#define AMPM_BENCH_API(T, D, S)                                                    \
  template <>                                                                      \
  struct Api<T, D> {                                                               \
    static constexpr const char* name = #D "D " #S;                                \
    static constexpr auto ahat_batch = ampm_ahat_batch_##D##d_##S;                 \
    static constexpr auto chat_z_batch = ampm_chat_z_batch_##D##d_##S;             \
    static constexpr auto chat_z_psd_batch = ampm_chat_z_psd_batch_##D##d_##S;     \
    static constexpr auto ahat_chat_z_batch = ampm_ahat_chat_z_batch_##D##d_##S;   \
    static constexpr auto hessian_len = ampm_hessian_len_##D##d_##S;               \
    static constexpr auto hessian_prepare = ampm_hessian_prepare_batch_##D##d_##S; \
    static constexpr auto hessian_apply = ampm_hessian_apply_batch_##D##d_##S;     \
  };
AMPM_BENCH_API(float, 2, f32)
AMPM_BENCH_API(float, 3, f32)
AMPM_BENCH_API(double, 2, f64)
AMPM_BENCH_API(double, 3, f64)
#undef AMPM_BENCH_API

/// common.hpp's status names.
const char* status_name(AmpmStatus s) { return ampm_test::status_name(s); }

[[noreturn]] void fail(const std::string& msg) {
  std::fprintf(stderr, "bench_kernels: %s\n", msg.c_str());
  std::exit(1);
}

// ---- buffers -------------------------------------------------------------------------------

/// n scalars, 64-byte aligned (a cache line), so no case pays for a misaligned start.
template <class T>
class Buffer {
 public:
  explicit Buffer(std::size_t n) : n_(n) {
    const std::size_t bytes = ((n * sizeof(T) + 63) / 64) * 64;
    p_ = static_cast<T*>(std::aligned_alloc(64, bytes == 0 ? 64 : bytes));
    if (p_ == nullptr) throw std::bad_alloc();
    std::fill(p_, p_ + n, static_cast<T>(0));
  }
  ~Buffer() { std::free(p_); }
  Buffer(const Buffer&) = delete;
  Buffer& operator=(const Buffer&) = delete;
  T* data() { return p_; }
  const T* data() const { return p_; }
  std::size_t size() const { return n_; }

 private:
  T* p_ = nullptr;
  std::size_t n_ = 0;
};

}  // namespace
