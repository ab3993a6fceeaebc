// Concurrent calls, as ampm.h's threads contract promises: "Concurrent calls are safe when no
// call writes memory that another call reads or writes", and ampm_set_isa is one process-wide
// value "set once at start-up, before other threads call the library" (so it is called here only
// while no other thread runs: before each round of threads, never during one).
//
// Four std::threads run, on disjoint data, the batch kernels (ahat_chat_z_batch 3D f32,
// hessian_prepare_batch + hessian_apply_batch 3D f64) and the particle transfers (3D f32: P2G
// into disjoint node blocks of one shared grid, force_prepare into disjoint slot ranges,
// force_apply into disjoint df blocks; 3D f64: g2p_update of disjoint particle ranges reading one
// shared grid). Every output must equal, bit for bit (memcmp), the same calls run serially on
// one thread. The first round runs before any other batch call of the library (only the
// node_range calls that size the grid precede it), so the instruction-set detection on first use
// happens concurrently too. Then 5 rounds per instruction set the CPU
// accepts. The serial blocks are also compared with one P2G / force_apply of all particles at
// once (the blocks share no node, and a particle's result does not depend on its position in
// the batch), which shows that the blocks cover the whole transfer.
#include <cstddef>
#include <cstdint>

#include "ampm.hpp"
#include "plain_check.hpp"

#include <cmath>
#include <cstdio>
#include <cstring>
#include <random>
#include <thread>
#include <vector>

namespace {

constexpr int kThreads = 4;
constexpr int kCellsX = 8;    // cells per thread slab along x
constexpr int kGapX = 4;      // empty cells between slabs (> stencil width: no shared node)
constexpr int kCellsYZ = 6;
constexpr std::size_t kKernelN = 1500;  // kernel batch records per thread
constexpr unsigned Q = AMPM_KERNEL_QUADRATIC;

template <class T>
bool same(const std::vector<T>& a, const std::vector<T>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0;
}

struct Rand {
  std::mt19937_64 g;
  explicit Rand(std::uint64_t s) : g(s) {}
  double u() { return static_cast<double>(g() >> 11) * 0x1.0p-53 - 0.5; }  // [-0.5, 0.5)
};

/// One 3D particle set (SoA), thread t's particles at [t·per, (t + 1)·per), in slab t.
template <class T>
struct Parts {
  std::size_t n = 0, per = 0;
  std::vector<T> x, v, c, fe, fp, m, v0;
  T h = T(0.05);
  explicit Parts(std::uint64_t seed) {
    Rand r(seed);
    per = static_cast<std::size_t>(2 * kCellsX) * (2 * kCellsYZ) * (2 * kCellsYZ);
    n = per * kThreads;
    x.resize(n * 3), v.resize(n * 3), c.resize(n * 9), fe.resize(n * 9), fp.assign(n * 9, 0);
    m.resize(n), v0.assign(n, T(1e-5));
    std::size_t p = 0;
    for (int t = 0; t < kThreads; ++t)
      for (int k = 0; k < 2 * kCellsYZ; ++k)
        for (int j = 0; j < 2 * kCellsYZ; ++j)
          for (int i = 0; i < 2 * kCellsX; ++i, ++p) {
            const double cell[3] = {2.0 + t * (kCellsX + kGapX) + 0.5 * i, 2.0 + 0.5 * j, 2.0 + 0.5 * k};
            for (int a = 0; a < 3; ++a) {
              x[p * 3 + a] = static_cast<T>((cell[a] + 0.25 + 0.2 * r.u()) * static_cast<double>(h));
              v[p * 3 + a] = static_cast<T>(r.u());
            }
            for (int e = 0; e < 9; ++e) {
              c[p * 9 + e] = static_cast<T>(r.u());
              fe[p * 9 + e] = static_cast<T>((e % 4 == 0 ? 1.0 : 0.0) + 0.1 * r.u());
              fp[p * 9 + e] = e % 4 == 0 ? T(1) : T(0);
            }
            m[p] = static_cast<T>(1e-2 * (1 + 0.2 * r.u()));
          }
  }
  ampm::Particles<T, 3> view() {
    ampm::Particles<T, 3> p(n);
    p.x(x).v(v).affine(c).f_e(fe).f_p(fp).mass(m).volume0(v0);
    return p;
  }
  std::vector<std::vector<T>*> state() { return {&x, &v, &c, &fe, &fp}; }
};

/// Runs body(t) on kThreads threads (concurrent) or in order on this thread (serial).
template <class F>
void run(bool concurrent, F&& body) {
  if (!concurrent) {
    for (int t = 0; t < kThreads; ++t) body(t);
    return;
  }
  std::vector<std::thread> th;
  for (int t = 0; t < kThreads; ++t) th.emplace_back([&body, t] { body(t); });
  for (auto& x : th) x.join();
}

/// Everything one round computes; compared between rounds with memcmp.
struct Outputs {
  std::vector<float> ahat, chat_z;                       // ahat_chat_z_batch 3D f32
  std::vector<double> prepared, applied, applied_psd;    // hessian 3D f64
  std::vector<float> mass, mom0, mom1, mom2;             // P2G 3D f32 (shared grid)
  std::vector<float> slots, df0, df1, df2;               // force differential 3D f32
  std::vector<double> state;                             // g2p_update 3D f64 (all fields)
  bool statuses_ok = true;
};

bool equal(const Outputs& a, const Outputs& b) {
  return same(a.ahat, b.ahat) && same(a.chat_z, b.chat_z) && same(a.prepared, b.prepared) &&
         same(a.applied, b.applied) && same(a.applied_psd, b.applied_psd) && same(a.mass, b.mass) &&
         same(a.mom0, b.mom0) && same(a.mom1, b.mom1) && same(a.mom2, b.mom2) &&
         same(a.slots, b.slots) && same(a.df0, b.df0) && same(a.df1, b.df1) && same(a.df2, b.df2) &&
         same(a.state, b.state);
}

struct Inputs {
  std::vector<float> mu_f, f_f, z_f;
  std::vector<double> mu_d, f_d, z_d;
  Parts<float> pf{17};
  Parts<double> pd{19};
  AmpmNodeBox grid{};                  // the whole grid (f32 P2G and force, f64 G2P)
  AmpmNodeBox block[kThreads] = {};    // each thread's nodes
  std::vector<float> du[3];
  std::vector<double> vel[3];
  Inputs() {
    Rand r(23);
    const std::size_t n = kKernelN * kThreads;
    mu_f.assign(n, 1e5f), mu_d.assign(n, 1e5);
    f_f.resize(n * 9), z_f.resize(n * 9), f_d.resize(n * 9), z_d.resize(n * 9);
    for (std::size_t k = 0; k < n * 9; ++k) {
      const double fv = ((k % 9) % 4 == 0 ? 1.0 : 0.0) + 0.3 * r.u();
      f_f[k] = static_cast<float>(fv), f_d[k] = fv;
      z_f[k] = static_cast<float>(r.u()), z_d[k] = r.u();
    }
    mu_f[77] = -1;  // one failing record: the same status and index every time
    auto pv = pf.view();
    bool ok = ampm::node_range(Q, AMPM_GRID_COLLOCATED, pf.h, pv, grid).ok();
    for (int a = 0; a < 3; ++a) grid.lo[a] -= 1, grid.dims[a] += 2;
    for (int t = 0; t < kThreads; ++t)
      ok = ok && ampm::node_range(Q, AMPM_GRID_COLLOCATED, pf.h, pv.slice(t * pf.per, pf.per), block[t]).ok();
    CHECK(ok, "node ranges");
    // The blocks must not share a node along x.
    for (int t = 0; t + 1 < kThreads; ++t)
      CHECK(block[t].lo[0] + block[t].dims[0] <= block[t + 1].lo[0], "blocks %d, %d overlap", t, t + 1);
    const std::size_t nodes = ampm::node_count<3>(grid);
    for (int a = 0; a < 3; ++a) {
      du[a].resize(nodes), vel[a].resize(nodes);
      for (std::size_t k = 0; k < nodes; ++k) {
        du[a][k] = static_cast<float>(1e-4 * std::sin(0.37 * static_cast<double>(k) + a));
        vel[a][k] = 0.1 * std::cos(0.21 * static_cast<double>(k) + a);
      }
    }
  }
};

Outputs round(Inputs& in, bool concurrent) {
  Outputs o;
  const std::size_t n = kKernelN * kThreads;
  using K3f = ampm::Kernels<float, 3>;
  using K3d = ampm::Kernels<double, 3>;
  const std::size_t L = K3d::hessian_len();
  o.ahat.assign(n * 9, 0), o.chat_z.assign(n * 9, 0);
  o.prepared.assign(n * L, 0), o.applied.assign(n * 9, 0), o.applied_psd.assign(n * 9, 0);
  const std::size_t nodes = ampm::node_count<3>(in.grid);
  o.mass.assign(nodes, 0), o.mom0.assign(nodes, 0), o.mom1.assign(nodes, 0), o.mom2.assign(nodes, 0);
  o.slots.assign(in.pf.n * ampm::force_slot_len<3>(), 0);
  o.df0.assign(nodes, 0), o.df1.assign(nodes, 0), o.df2.assign(nodes, 0);
  Parts<double> pd = in.pd;  // g2p_update updates a copy
  bool st[kThreads][7] = {};
  const auto mat_f = ampm::Material<float>().mu(1e5f).lambda(1e5f).enable(AMPM_MODEL_PSD_HESSIAN);
  const auto mat_d = ampm::Material<double>().mu(1e5).lambda(1e5);
  const auto p2g_view = ampm::P2gView<float, 3>::separate(in.grid, o.mass.data(), {o.mom0.data(), o.mom1.data(), o.mom2.data()});
  const auto force_view = ampm::ForceView<float, 3>::separate(in.grid, {in.du[0].data(), in.du[1].data(), in.du[2].data()},
                                                              {o.df0.data(), o.df1.data(), o.df2.data()});
  const auto g2p_view = ampm::G2pView<double, 3>::separate(in.grid, {in.vel[0].data(), in.vel[1].data(), in.vel[2].data()});
  const auto pf_all = in.pf.view();
  const auto pd_all = pd.view();
  run(concurrent, [&](int t) {
    const std::size_t k0 = static_cast<std::size_t>(t) * kKernelN, K = kKernelN;
    const auto a = K3f::ahat_chat_z_batch(K, &in.mu_f[k0], &in.f_f[k0 * 9], &in.z_f[k0 * 9], &o.ahat[k0 * 9], &o.chat_z[k0 * 9]);
    st[t][0] = t == 0 ? (a.code() == AMPM_ERR_INVALID_ARGUMENT && a.first_failed == 77) : a.ok();
    st[t][1] = K3d::hessian_prepare_batch(K, &in.mu_d[k0], &in.f_d[k0 * 9], nullptr, &o.prepared[k0 * L]).ok();
    st[t][2] = K3d::hessian_apply_batch(K, &o.prepared[k0 * L], &in.z_d[k0 * 9], &o.applied[k0 * 9], false).ok() &&
               K3d::hessian_apply_batch(K, &o.prepared[k0 * L], &in.z_d[k0 * 9], &o.applied_psd[k0 * 9], true).ok();
    const auto mine = pf_all.slice(static_cast<std::size_t>(t) * in.pf.per, in.pf.per);
    st[t][3] = ampm::p2g(mat_f, Q, AMPM_GRID_COLLOCATED, in.pf.h, 1e-3f, mine, p2g_view.block(in.block[t])).ok();
    const std::size_t sl = ampm::force_slot_len<3>();
    ampm::span<float> slots(&o.slots[static_cast<std::size_t>(t) * in.pf.per * sl], in.pf.per * sl);
    st[t][4] = ampm::force_prepare(mat_f, mine, slots).ok();
    st[t][5] = ampm::force_apply(Q, in.pf.h, mine, ampm::span<const float>(slots), force_view.block(in.block[t])).ok();
    st[t][6] = ampm::g2p_update(mat_d, Q, pd.h, 1e-3, pd_all.slice(static_cast<std::size_t>(t) * pd.per, pd.per), g2p_view).ok();
  });
  for (auto& row : st)
    for (bool b : row) o.statuses_ok = o.statuses_ok && b;
  for (auto* v : pd.state()) o.state.insert(o.state.end(), v->begin(), v->end());
  return o;
}

}  // namespace

int main() {
  Inputs in;
  // Round 0: the threads make the library's first batch calls (instruction-set detection).
  const Outputs first = round(in, true);
  const Outputs serial = round(in, false);
  CHECK(first.statuses_ok && serial.statuses_ok, "statuses of the first round");
  CHECK(equal(first, serial), "first concurrent round == serial, bitwise");
  // The blocks together equal one P2G and one force_apply of all particles.
  {
    Outputs whole = serial;
    std::fill(whole.mass.begin(), whole.mass.end(), 0.f);
    for (auto* v : {&whole.mom0, &whole.mom1, &whole.mom2, &whole.df0, &whole.df1, &whole.df2})
      std::fill(v->begin(), v->end(), 0.f);
    const auto mat_f = ampm::Material<float>().mu(1e5f).lambda(1e5f).enable(AMPM_MODEL_PSD_HESSIAN);
    const auto pv = ampm::P2gView<float, 3>::separate(in.grid, whole.mass.data(), {whole.mom0.data(), whole.mom1.data(), whole.mom2.data()});
    const auto fv = ampm::ForceView<float, 3>::separate(in.grid, {in.du[0].data(), in.du[1].data(), in.du[2].data()},
                                                        {whole.df0.data(), whole.df1.data(), whole.df2.data()});
    const auto b1 = ampm::p2g(mat_f, Q, AMPM_GRID_COLLOCATED, in.pf.h, 1e-3f, in.pf.view(), pv);
    const auto b2 = ampm::force_apply(Q, in.pf.h, in.pf.view(), ampm::span<const float>(serial.slots), fv);
    CHECK(b1.ok() && b2.ok() && equal(whole, serial), "blocks == one call over all particles (%s, %s)", b1.name(), b2.name());
  }
  const std::uint32_t start_isa = ampm::isa();
  int isas = 0;
  for (std::uint32_t isa : {AMPM_ISA_AVX512, AMPM_ISA_AVX2, AMPM_ISA_SCALAR}) {
    if (!ampm::set_isa(isa).ok()) continue;  // no other thread runs here
    ++isas;
    const Outputs ref = round(in, false);
    CHECK(ref.statuses_ok, "statuses, isa %u", isa);
    for (int rep = 0; rep < 5; ++rep) {
      const Outputs got = round(in, true);
      CHECK(got.statuses_ok && equal(got, ref), "isa %u repetition %d: concurrent == serial bitwise", isa, rep);
    }
  }
  CHECK(isas >= 1 && ampm::set_isa(start_isa).ok(), "instruction sets run: %d", isas);
  std::printf("test_threads: %ld checks, %ld failures (%d instruction sets, %d threads)\n", g_checks,
              g_failures, isas, kThreads);
  return g_failures == 0 ? 0 : 1;
}
