// --ab: two builds of libampm.so loaded with dlopen and timed alternately, their results
// compared bit for bit.
#pragma once

#include <dlfcn.h>

#include "blocks.hpp"
#include "case.hpp"

namespace bench {

// ---- A/B: two builds of the library, alternately -------------------------------------------

/// One build of the library, loaded with dlopen (RTLD_LOCAL: its own symbols and state).
struct AbLib {
  std::string path;
  void* handle = nullptr;
  AmpmStatus (*set_isa)(std::uint32_t) = nullptr;

  explicit AbLib(std::string p) : path(std::move(p)) {
    handle = dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
    if (handle == nullptr) fail("dlopen " + path + ": " + dlerror());
    set_isa = sym<AmpmStatus (*)(std::uint32_t)>("ampm_set_isa");
  }
  AbLib(const AbLib&) = delete;
  AbLib& operator=(const AbLib&) = delete;
  template <class F>
  F sym(const std::string& name) const {
    void* f = dlsym(handle, name.c_str());
    if (f == nullptr) fail(path + " has no symbol " + name);
    return reinterpret_cast<F>(f);
  }
};

/// The calls of one build for `Api<T, D>`, resolved by name.
template <class T, int D>
struct AbFns {
  using A = Api<T, D>;
  std::remove_const_t<decltype(A::p2g)> p2g;
  std::remove_const_t<decltype(A::g2p)> g2p;
  std::remove_const_t<decltype(A::prepare)> prepare;
  std::remove_const_t<decltype(A::apply)> apply;

  explicit AbFns(const AbLib& l)
      : p2g(l.sym<decltype(p2g)>(A::p2g_sym)),
        g2p(l.sym<decltype(g2p)>(A::g2p_sym)),
        prepare(l.sym<decltype(prepare)>(A::prepare_sym)),
        apply(l.sym<decltype(apply)>(A::apply_sym)) {}
};

/// The calls an A/B row times, in its columns' order.
constexpr const char* kAbCalls[] = {"lib", "prepare", "apply"};
constexpr int kAbN = sizeof kAbCalls / sizeof kAbCalls[0];

/// One A/B row: medians (ns per particle) of both builds, per call of kAbCalls.
struct AbRow {
  std::string scene, kase, isa;
  double t[kAbN][2] = {};
};

/// Times one case on instruction set `isa` with both builds alternately (see the header), the
/// particles in calls of `block` (0: one call per transfer); only if its label ("elastic 2D f32
/// AVX-512") contains `only`.
template <class T, int D>
void ab_case(Scene s, int per_axis, int reps, std::size_t block, const std::string& only, std::uint32_t isa,
             const AbLib* libs[2], std::vector<AbRow>& rows) {
  const std::string label = std::string(scene_name(s)) + " " + Api<T, D>::name + " " + isa_name(isa);
  if (label.find(only) == std::string::npos) return;
  for (int k = 0; k < 2; ++k)
    if (libs[k]->set_isa(isa) != AMPM_OK) return;
  Case<T, D> cs(s, per_axis);
  const AbFns<T, D> fns[2] = {AbFns<T, D>(*libs[0]), AbFns<T, D>(*libs[1])};
  const std::size_t n = cs.p.n;
  std::size_t ff = 0;
  // A call's name with its build's path, made once, so that a failure says which build failed.
  auto named = [&](const char* call) {
    return std::array<std::string, 2>{std::string(call) + " (" + libs[0]->path + ")",
                                      std::string(call) + " (" + libs[1]->path + ")"};
  };
  const auto p2g_name = named("P2G sym"), g2p_name = named("G2P"), apply_name = named("apply");
  const auto prepare_name = named("prepare");
  auto p2g = [&](int k) {
    in_blocks(cs, block, p2g_name[k].c_str(), [&](std::size_t i, std::size_t m, std::size_t* f) {
      return cs.p2g_sym_range(i, m, f, fns[k].p2g);
    });
  };
  auto g2p = [&](int k) {
    in_blocks(cs, block, g2p_name[k].c_str(),
              [&](std::size_t i, std::size_t m, std::size_t* f) { return cs.g2p_range(i, m, f, fns[k].g2p); });
  };
  auto prepare = [&](int k) {
    const AmpmStatus st = cs.prepare(&ff, fns[k].prepare);  // before `ff` is read
    expect_ok(cs.label(prepare_name[k].c_str()), st, ff, n);
  };
  auto apply = [&](int k) {
    cs.zero_df();
    in_blocks(cs, block, apply_name[k].c_str(),
              [&](std::size_t i, std::size_t m, std::size_t* f) { return cs.apply_range(i, m, f, fns[k].apply); });
  };
  auto clock = [] { return std::chrono::steady_clock::now(); };
  auto ns = [&](auto t0, auto t1) { return ns_per(t0, t1, n); };
  // Results first: the same grids, particles and forces from both builds, bit for bit.
  std::vector<T> grid[2], parts[2], slots[2], df[2];
  std::vector<std::uint8_t> phase[2];
  auto append = [](std::vector<T>& to, const std::vector<T>& from) { to.insert(to.end(), from.begin(), from.end()); };
  for (int k = 0; k < 2; ++k) {
    cs.restore();
    cs.g.zero_p2g();
    p2g(k);
    for (const auto* ch : {&cs.g.mass, &cs.g.hc, &cs.g.te, &cs.g.cond}) append(grid[k], *ch);
    for (int a = 0; a < D; ++a) append(grid[k], cs.g.mom[a]);
    grid_update(cs.g, cs.thermal);
    g2p(k);
    for (const auto* f : {&cs.p.x, &cs.p.v, &cs.p.c, &cs.p.fe, &cs.p.fp, &cs.p.t, &cs.p.u}) append(parts[k], *f);
    phase[k] = cs.p.ph;
    cs.restore();
    prepare(k);
    slots[k] = cs.slots;
    apply(k);
    for (int a = 0; a < D; ++a) append(df[k], cs.g.df[a]);
  }
  auto same = [](const std::vector<T>& a, const std::vector<T>& b) {
    return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0;
  };
  if (!same(grid[0], grid[1]) || !same(parts[0], parts[1]) || !same(slots[0], slots[1]) || !same(df[0], df[1]) ||
      phase[0] != phase[1])
    fail(cs.label("results") + " on " + isa_name(isa) + ": the two builds differ");
  std::vector<double> times[kAbN][2];  // per call of kAbCalls and build
  for (int r = -1; r < reps; ++r) {
    for (int j = 0; j < 2; ++j) {
      const int k = (r + j + 2) % 2;
      cs.restore();
      cs.g.zero_p2g();
      const auto t0 = clock();
      p2g(k);
      const auto t1 = clock();
      grid_update(cs.g, cs.thermal);
      const auto t2 = clock();
      g2p(k);
      const auto t3 = clock();
      cs.restore();
      const auto t4 = clock();
      prepare(k);
      const auto t5 = clock();
      apply(k);
      const auto t6 = clock();
      if (r >= 0) {
        times[0][k].push_back(ns(t0, t1) + ns(t2, t3));
        times[1][k].push_back(ns(t4, t5));
        times[2][k].push_back(ns(t5, t6));
      }
    }
  }
  cs.restore();
  AbRow row;
  row.scene = scene_name(s), row.kase = Api<T, D>::name, row.isa = isa_name(isa);
  std::fprintf(stderr, "%-14s %s %-8s", row.scene.c_str(), row.kase.c_str(), row.isa.c_str());
  for (int c = 0; c < kAbN; ++c) {
    for (int k = 0; k < 2; ++k) row.t[c][k] = median_of(times[c][k]);
    std::fprintf(stderr, "  %s %6.1f / %6.1f (%.3f)", kAbCalls[c], row.t[c][0], row.t[c][1], row.t[c][1] / row.t[c][0]);
  }
  std::fputc('\n', stderr);
  rows.push_back(row);
}

/// The A/B comparison (--ab): a markdown table of both builds' medians and their ratio.
inline int run_ab(const std::string& a, const std::string& b, int reps, std::size_t block, const std::string& only) {
  const AbLib la(a), lb(b);
  const AbLib* libs[2] = {&la, &lb};
  std::vector<AbRow> rows;
  for (Scene s : {Scene::Elastic, Scene::Fluid, Scene::Thermal})
    for (std::uint32_t isa : {std::uint32_t{AMPM_ISA_AVX512}, std::uint32_t{AMPM_ISA_AVX2}}) {
      ab_case<float, 3>(s, 38, reps, block, only, isa, libs, rows);
      ab_case<float, 2>(s, 234, reps, block, only, isa, libs, rows);
    }
  std::ostringstream o;
  o << "A/B (bench_transfers --ab, " << reps << " reps, alternating, "
    << (block == 0 ? std::string("one call per transfer") : "calls of " + std::to_string(block) + " particles")
    << "): A = `" << a << "`, B = `" << b << "`\n"
    << "CPU: " << cpu_model() << "; load before: " << load_average() << "\n\n"
    << "| scene | case | ISA |";
  for (const char* c : kAbCalls) o << " " << c << " A | " << c << " B | B / A |";
  o << "\n|---|---|---|";
  for (int c = 0; c < kAbN; ++c) o << "---|---|---|";
  o << "\n";
  char buf[64];
  auto num = [&](double x, const char* f) {
    std::snprintf(buf, sizeof buf, f, x);
    return std::string(buf);
  };
  for (const AbRow& r : rows) {
    o << "| " << r.scene << " | " << r.kase << " | " << r.isa << " |";
    for (const auto& t : r.t)
      o << " " << num(t[0], "%.1f") << " | " << num(t[1], "%.1f") << " | " << num(t[1] / t[0], "%.3f") << " |";
    o << "\n";
  }
  std::fputs(o.str().c_str(), stdout);
  return 0;
}

}  // namespace bench
