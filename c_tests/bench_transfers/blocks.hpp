// Block calls: the transfers over ranges of particles (a threaded host's blocks) against one
// call, and G2P's bit-identity across call sizes.
#pragma once

#include "case.hpp"
#include "checks.hpp"

namespace bench {

/// Particles per call of the block timing (0: the whole batch in one call).
constexpr std::size_t kBlocks[] = {0, 4096, 512, 64};
constexpr int kNumBlocks = sizeof kBlocks / sizeof kBlocks[0];

/// Largest block whose per-call cost the report gives: above it the difference to one call is
/// within the run-to-run spread.
constexpr std::size_t kPerCallMax = 512;

/// " (r)", a ratio to one call.
inline std::string ratio_text(double r) {
  char buf[32];
  std::snprintf(buf, sizeof buf, " (%.2f)", r);
  return buf;
}

/// A host's block calls (one call per range of particles, as a threaded host makes them):
/// lib (P2G sym + G2P) and apply, medians in ns per particle for each size of kBlocks.
struct BlockTiming {
  std::string scene, kase;
  std::size_t n = 0;
  double lib[kNumBlocks] = {}, apply[kNumBlocks] = {};
};

/// `call(i, k, &ff)` over the particles of `cs` in calls of `b` (0: one call), in order; every
/// call must return AMPM_OK.
template <class C, class Call>
void in_blocks(C& cs, std::size_t b, const char* what, Call&& call) {
  const std::size_t n = cs.p.n, step = b == 0 ? n : b;
  std::size_t ff = 0;
  for (std::size_t i = 0; i < n; i += step) {
    const std::size_t k = std::min(step, n - i);
    const AmpmStatus st = call(i, k, &ff);
    if (st != AMPM_OK || ff != k) expect_ok(cs.label(what), st, ff, k);  // no string per call
  }
}

/// G2P in calls of 64 particles leaves every particle bit-identical to one call (a particle's
/// result does not depend on the batch it is in).
template <class T, int D>
void check_blocks(Scene s, int per_axis, CheckLog& log) {
  Case<T, D> cs(s, per_axis);
  auto g2p_state = [&](std::size_t b) {
    cs.restore();
    cs.g.zero_p2g();
    in_blocks(cs, 0, "P2G sym", [&](std::size_t i, std::size_t k, std::size_t* f) { return cs.p2g_sym_range(i, k, f); });
    grid_update(cs.g, cs.thermal);
    in_blocks(cs, b, "G2P", [&](std::size_t i, std::size_t k, std::size_t* f) { return cs.g2p_range(i, k, f); });
    std::vector<T> st;
    for (const auto* f : {&cs.p.x, &cs.p.v, &cs.p.c, &cs.p.fe, &cs.p.fp, &cs.p.t, &cs.p.u})
      st.insert(st.end(), f->begin(), f->end());
    return st;
  };
  const std::vector<T> whole = g2p_state(0), small = g2p_state(64);
  if (whole.size() != small.size() || std::memcmp(whole.data(), small.data(), whole.size() * sizeof(T)) != 0)
    fail(cs.label("G2P in calls of 64") + ": particles differ from one call");
  cs.restore();
  log.add(cs.label("G2P") + ", " + std::to_string(cs.p.n) +
          " particles in calls of 64: bit-identical particles to one call");
}

/// Times lib and apply of one case on the default instruction set, the particles in calls of
/// kBlocks particles (consecutive ranges, every call into the same grid views), the sizes
/// alternating rep by rep (one warm-up round) so that all see the same machine state.
template <class T, int D>
BlockTiming time_blocks(Scene s, int per_axis, int reps) {
  Case<T, D> cs(s, per_axis);
  cs.run_all_once();
  const std::size_t n = cs.p.n;
  auto blocks = [&](std::size_t b, const char* what, auto&& call) { in_blocks(cs, b, what, call); };
  auto clock = [] { return std::chrono::steady_clock::now(); };
  auto ns = [&](auto t0, auto t1) { return ns_per(t0, t1, n); };
  std::vector<double> lib[kNumBlocks], apply[kNumBlocks];
  for (int r = -1; r < reps; ++r)
    for (int j = 0; j < kNumBlocks; ++j) {
      const std::size_t b = kBlocks[j];
      cs.restore();
      cs.g.zero_p2g();
      const auto t0 = clock();
      blocks(b, "P2G sym", [&](std::size_t i, std::size_t k, std::size_t* f) { return cs.p2g_sym_range(i, k, f); });
      const auto t1 = clock();
      grid_update(cs.g, cs.thermal);
      const auto t2 = clock();
      blocks(b, "G2P", [&](std::size_t i, std::size_t k, std::size_t* f) { return cs.g2p_range(i, k, f); });
      const auto t3 = clock();
      cs.restore();  // apply at the positions the slots were prepared for, as in one call's timing
      cs.zero_df();
      const auto t4 = clock();
      blocks(b, "apply", [&](std::size_t i, std::size_t k, std::size_t* f) { return cs.apply_range(i, k, f); });
      const auto t5 = clock();
      if (r >= 0) lib[j].push_back(ns(t0, t1) + ns(t2, t3)), apply[j].push_back(ns(t4, t5));
    }
  cs.restore();
  BlockTiming bt;
  bt.scene = scene_name(s), bt.kase = Api<T, D>::name, bt.n = n;
  for (int j = 0; j < kNumBlocks; ++j) bt.lib[j] = median_of(lib[j]), bt.apply[j] = median_of(apply[j]);
  std::fprintf(stderr, "blocks %s %s: lib", bt.scene.c_str(), bt.kase.c_str());
  for (int j = 0; j < kNumBlocks; ++j) std::fprintf(stderr, " %zu:%.1f", kBlocks[j], bt.lib[j]);
  std::fprintf(stderr, ", apply");
  for (int j = 0; j < kNumBlocks; ++j) std::fprintf(stderr, " %zu:%.1f", kBlocks[j], bt.apply[j]);
  std::fputc('\n', stderr);
  return bt;
}

}  // namespace bench
