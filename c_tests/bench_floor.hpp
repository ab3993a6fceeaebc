// The hardware limit of a transfer step, measured in the run that times the library
// (c_tests/bench_transfers.cpp): lower bounds on the time of P2G and G2P for any implementation
// of the same interface on this machine.
//
// Both are floors in practice, not proofs: an implementation of these calls has to move these
// bytes and do at least these multiply-adds, at rates a simple loop reaches on this machine.
//
// Memory floor: the bytes a call's interface reads and writes, each array streamed once in
// order at the rate this machine sustains (every particle array the call reads, summed; every
// particle array it writes, read and written back; the grid channels read, or read and
// written for P2G's scatter-add), timed like the calls. It is the time to move the data once
// with no arithmetic, no gathers and no reuse misses.
//
// Arithmetic floor: the fused multiply-adds of the node loops alone, counted per node (below),
// at the FMA rate this machine sustains on independent accumulators of the widest vectors the
// host code is compiled for. The constitutive model, stencil weights and checks are not
// counted, so it is a lower bound too.
//   P2G per node: weight 1, mass 1, momentum 2d (affine term and weight), force d² (τ∇w),
//                 weight gradient d: 2 + 3d + d² (20 in 3D, 12 in 2D).
//   G2P per node: per velocity component 1 (Σ w v) + d (Σ w v (x_i − x_p)ᵀ) + d (Σ v ∇wᵀ):
//                 d (1 + 2d) (21 in 3D, 10 in 2D).
// Nodes per particle: 3^d (quadratic).
#pragma once

#if defined(__x86_64__) || defined(__i386__)
#include <immintrin.h>
#endif

#include <chrono>
#include <cstddef>
#include <vector>

namespace bench_floor {

/// The bytes a call moves, as lists of arrays: read only, read and written (particles or grid
/// channels updated in place).
template <class T>
struct Streams {
  std::vector<const std::vector<T>*> read;
  std::vector<std::vector<T>*> update;
  std::size_t bytes() const {
    std::size_t b = 0;
    for (const auto* a : read) b += a->size() * sizeof(T);
    for (const auto* a : update) b += 2 * a->size() * sizeof(T);
    return b;
  }
};

/// Where `keep` stores.
inline volatile double sink = 0;

/// Keeps a value alive so that the reads that produce it are not removed.
template <class T>
void keep(T x) {
  sink = static_cast<double>(x);
}

/// Sum of `a` with 16 independent partial sums (vectorised without reassociation).
template <class T>
T read_sum(const std::vector<T>& a) {
  T s[16] = {};
  const std::size_t n = a.size(), m = n - n % 16;
  for (std::size_t i = 0; i < m; i += 16)
    for (int j = 0; j < 16; ++j) s[j] += a[i + j];
  for (std::size_t i = m; i < n; ++i) s[0] += a[i];
  T t = 0;
  for (T x : s) t += x;
  return t;
}

/// `a[i] = a[i] · k` with `k` = 1 known only at run time: every value read and written back
/// unchanged.
template <class T>
void update(std::vector<T>& a, T k) {
  T* p = a.data();
  const std::size_t n = a.size();
  for (std::size_t i = 0; i < n; ++i) p[i] *= k;
}

/// One pass over the streams of a call.
template <class T>
void stream(const Streams<T>& s, T one) {
  T t = 0;
  for (const auto* a : s.read) t += read_sum(*a);
  for (auto* a : s.update) update(*a, one);
  keep(t);
}

/// Fused multiply-adds per ns on independent accumulators (f32, the widest vectors of the
/// host build), the best of `reps` runs of about 10⁸ FMAs each.
inline double fma_per_ns(int reps) {
#if defined(__AVX512F__)
  using V = __m512;
  constexpr int kLanes = 16;
  auto fma = [](V a, V b, V c) { return _mm512_fmadd_ps(a, b, c); };
  auto splat = [](float x) { return _mm512_set1_ps(x); };
  auto lane0 = [](V a) { return _mm512_cvtss_f32(a); };
#elif defined(__FMA__)
  using V = __m256;
  constexpr int kLanes = 8;
  auto fma = [](V a, V b, V c) { return _mm256_fmadd_ps(a, b, c); };
  auto splat = [](float x) { return _mm256_set1_ps(x); };
  auto lane0 = [](V a) { return _mm256_cvtss_f32(a); };
#elif defined(__SSE__)
  using V = __m128;
  constexpr int kLanes = 4;
  // No FMA: a multiply and an add per lane (counted as one fused operation).
  auto fma = [](V a, V b, V c) { return _mm_add_ps(_mm_mul_ps(a, b), c); };
  auto splat = [](float x) { return _mm_set1_ps(x); };
  auto lane0 = [](V a) { return _mm_cvtss_f32(a); };
#else
  // Not x86: scalar multiply-adds (the compiler may vectorise the accumulators).
  using V = float;
  constexpr int kLanes = 1;
  auto fma = [](V a, V b, V c) { return a * b + c; };
  auto splat = [](float x) { return x; };
  auto lane0 = [](V a) { return a; };
#endif
  constexpr int kAcc = 16;  // enough independent chains for two FMA ports of latency 4–6
  constexpr long kIters = 400'000;
  double best = 0;
  for (int r = 0; r < reps; ++r) {
    V acc[kAcc];
    for (int j = 0; j < kAcc; ++j) acc[j] = splat(1.0f + 1e-3f * j);
    volatile float mv = 0.999999f, av = 1e-7f;
    const V m = splat(mv), a = splat(av);
    const auto t0 = std::chrono::steady_clock::now();
    for (long i = 0; i < kIters; ++i)
      for (int j = 0; j < kAcc; ++j) acc[j] = fma(acc[j], m, a);
    const auto t1 = std::chrono::steady_clock::now();
    float s = 0;
    for (int j = 0; j < kAcc; ++j) s += lane0(acc[j]);
    keep(s);
    const double ns = std::chrono::duration<double, std::nano>(t1 - t0).count();
    const double rate = static_cast<double>(kIters) * kAcc * kLanes / ns;
    if (rate > best) best = rate;
  }
  return best;
}

/// Node-loop FMAs per particle of P2G and G2P (quadratic, see the file header).
inline double p2g_fmas(int d) { return (d == 3 ? 27 : 9) * (2.0 + 3 * d + d * d); }
inline double g2p_fmas(int d) { return (d == 3 ? 27 : 9) * (d * (1.0 + 2 * d)); }

}  // namespace bench_floor
