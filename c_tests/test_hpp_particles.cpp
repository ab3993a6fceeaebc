// include/ampm.hpp, particle API: the builders (Material, PhaseParams, Particles, node_box,
// Channel, P2gView, G2pView, ForceView) produce byte for byte the C structs a host fills by hand
// (zero-filled first, padding included), and every transfer wrapper (p2g, g2p_update,
// g2p_update_mac, node_range, stencil, force_prepare, force_apply, pressure) gives
// bit-identical outputs, statuses and first_failed to the direct C call, for the four
// (scalar, dimension) pairs. P2G, G2P and the force differential through an interleaved
// node-struct grid (strides from the struct layout) equal the separate-array grid bit for bit.
// Invalid inputs (a NaN particle, a box too small, a NULL array) give the C statuses; arrays too
// short for n give AMPM_ERR_INVALID_ARGUMENT with first_failed = 0 and write nothing.
#include <cstddef>
#include <cstdint>

#include "ampm.hpp"
#include "plain_check.hpp"

#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <random>
#include <vector>

namespace {

template <class S>
bool bytes_eq(const S& a, const S& b) {
  return std::memcmp(&a, &b, sizeof(S)) == 0;
}
template <class T>
bool same(const std::vector<T>& a, const std::vector<T>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0;
}

/// Node structs of an interleaved host grid (T members only, so strides are whole scalars).
template <class T>
struct P2gNode {
  T mass, px, py, pz, fx, fy, fz, hc, te, cond;
};
template <class T>
struct G2pNode {
  T vx, vy, vz, tn, to, pad;
};
template <class T>
struct ForceNode {
  T dux, duy, duz, dfx, dfy, dfz;
};

template <class T, int D>
struct Fixture {
  using A = ampm::detail::api<T, D>;
  using PD = typename A::particles;
  std::size_t n;
  std::vector<T> x, v, c, fe, fp, m, v0, t, u;
  std::vector<unsigned char> ph;
  T h = T(0.1), dt = T(1e-3);

  explicit Fixture(std::uint64_t seed) {
    std::mt19937_64 g(seed);
    auto r = [&] { return static_cast<T>(static_cast<double>(g() >> 11) * 0x1.0p-53 - 0.5); };
    const int per = D == 2 ? 7 : 4;
    n = 1;
    for (int a = 0; a < D; ++a) n *= per;
    x.resize(n * D), v.resize(n * D), c.resize(n * D * D), fe.resize(n * D * D);
    fp.assign(n * D * D, 0), m.resize(n), v0.resize(n), t.resize(n), u.assign(n, 0);
    ph.assign(n, AMPM_PHASE_SOLID);
    for (std::size_t p = 0; p < n; ++p) {
      std::size_t k = p;
      for (int a = 0; a < D; ++a, k /= per)
        x[p * D + a] = h * (T(1.3) + T(0.5) * T(k % per) + T(0.2) * r());
      for (int a = 0; a < D; ++a) v[p * D + a] = r();
      for (int e = 0; e < D * D; ++e) {
        c[p * D * D + e] = T(0.5) * r();
        fe[p * D * D + e] = (e % (D + 1) == 0 ? T(1) : T(0)) + T(0.1) * r();
        fp[p * D * D + e] = e % (D + 1) == 0 ? T(1) : T(0);
      }
      m[p] = T(1e-3) * (T(1) + T(0.2) * r());
      v0[p] = T(1e-6);
      t[p] = T(260) + T(10) * r();
    }
  }
  PD hand() {
    PD s;
    std::memset(&s, 0, sizeof s);
    s.x = x.data(), s.v = v.data(), s.affine = c.data(), s.f_e = fe.data(), s.f_p = fp.data();
    s.mass = m.data(), s.volume0 = v0.data(), s.temperature = t.data(), s.latent = u.data();
    s.phase = ph.data();
    return s;
  }
  ampm::Particles<T, D> built() {
    ampm::Particles<T, D> p(n);
    p.x(x).v(v).affine(c).f_e(fe).f_p(fp).mass(m).volume0(v0).temperature(t).latent(u).phase(ph);
    return p;
  }
  std::vector<std::vector<T>*> state() { return {&x, &v, &c, &fe, &fp, &t, &u}; }
};

template <class T>
ampm::Material<T> material(unsigned extra) {
  return ampm::Material<T>()
      .model(AMPM_MODEL_THERMAL)
      .enable(extra)
      .mu(T(1e5))
      .lambda(T(1e5))
      .heat_capacity(T(2100))
      .conductivity(T(2.2))
      .liquid(ampm::PhaseParams<T>().mu(0).lambda(T(2e5)).heat_capacity(T(4200)).conductivity(T(0.6)))
      .flip(T(0.5))
      .melting_point(T(273.15))
      .latent_heat(T(334000))
      .critical_compression(T(0.025))
      .critical_stretch(T(0.0075))
      .hardening(T(10));
}

/// The first D of three members (axis order x, y, z).
template <int D, class M>
std::array<M, D> first(M a, M b, M c) {
  if constexpr (D == 2) {
    (void)c;
    return {a, b};
  } else {
    return {a, b, c};
  }
}

template <int D>
AmpmNodeBox test_box() {
  if constexpr (D == 2) {
    return ampm::node_box<D>({-2, 3}, {5, 4});
  } else {
    return ampm::node_box<D>({-2, 3, 1}, {5, 4, 3});
  }
}

template <class T, int D>
void test_builders(const char* name) {
  using A = ampm::detail::api<T, D>;
  // Material: every field by name equals the hand-filled struct (padding zero).
  typename A::material hm;
  std::memset(&hm, 0, sizeof hm);
  hm.model = AMPM_MODEL_THERMAL | AMPM_MODEL_PSD_HESSIAN;
  hm.solid.mu = T(1e5), hm.solid.inv_lambda = T(1) / T(1e5), hm.solid.heat_capacity = T(2100);
  hm.solid.conductivity = T(2.2);
  hm.liquid.mu = 0, hm.liquid.inv_lambda = T(1) / T(2e5), hm.liquid.heat_capacity = T(4200);
  hm.liquid.conductivity = T(0.6);
  hm.flip = T(0.5), hm.melting_point = T(273.15), hm.latent_heat = T(334000);
  hm.critical_compression = T(0.025), hm.critical_stretch = T(0.0075), hm.hardening = T(10);
  const auto bm = material<T>(AMPM_MODEL_PSD_HESSIAN);
  CHECK(bytes_eq(bm.c(), hm), "%s Material bytes", name);
  auto m2 = bm;
  m2.disable(AMPM_MODEL_THERMAL).inv_lambda(T(3)).liquid_inv_lambda(T(4)).liquid_lambda(T(8))
      .liquid_heat_capacity(T(5)).liquid_conductivity(T(6));
  hm.model = AMPM_MODEL_PSD_HESSIAN, hm.solid.inv_lambda = T(3), hm.liquid.inv_lambda = T(1) / T(8);
  hm.liquid.heat_capacity = T(5), hm.liquid.conductivity = T(6);
  CHECK(bytes_eq(m2.c(), hm), "%s Material setters", name);
  // Particles.
  Fixture<T, D> f(7);
  CHECK(bytes_eq(f.built().c(), f.hand()), "%s Particles bytes", name);
  CHECK(f.built().sizes_ok() && f.built().size() == f.n, "%s Particles size", name);
  auto sl = f.built().slice(3, 5);
  auto hs = f.hand();
  hs.x += 3 * D, hs.v += 3 * D, hs.affine += 3 * D * D, hs.f_e += 3 * D * D, hs.f_p += 3 * D * D;
  hs.mass += 3, hs.volume0 += 3, hs.temperature += 3, hs.latent += 3, hs.phase += 3;
  CHECK(bytes_eq(sl.c(), hs) && sl.size() == 5 && sl.sizes_ok(), "%s Particles::slice", name);
  CHECK(!f.built().slice(f.n - 1, 2).sizes_ok(), "%s slice past the end", name);
  ampm::Particles<T, D> nulls(f.n);
  nulls.temperature(nullptr).latent(ampm::span<T>()).phase(nullptr);
  typename A::particles hn;
  std::memset(&hn, 0, sizeof hn);
  CHECK(bytes_eq(nulls.c(), hn) && nulls.sizes_ok(), "%s null arrays", name);
  // Node box and views.
  const AmpmNodeBox box = test_box<D>();
  AmpmNodeBox hb;
  hb.lo[0] = -2, hb.lo[1] = 3, hb.lo[2] = D == 3 ? 1 : 0;
  hb.dims[0] = 5, hb.dims[1] = 4, hb.dims[2] = D == 3 ? 3 : 1;
  CHECK(bytes_eq(box, hb), "%s node_box", name);
  CHECK(ampm::node_count<D>(box) == (D == 2 ? 20u : 60u), "%s node_count", name);
  std::vector<T> a0(60), a1(60), a2(60), a3(60), a4(60), a5(60);
  auto ch = [&](T* d) {
    typename A::channel c;
    c.data = d, c.stride[0] = 1, c.stride[1] = 5, c.stride[2] = 20;
    return c;
  };
  auto cch = [&](const T* d) {
    typename A::const_channel c;
    c.data = d, c.stride[0] = 1, c.stride[1] = 5, c.stride[2] = 20;
    return c;
  };
  typename A::p2g_view hp;
  std::memset(&hp, 0, sizeof hp);
  hp.nodes = hb, hp.mass = ch(a0.data());
  std::array<T*, D> mom, frc;
  std::array<const T*, D> cm;
  T* arrs[] = {a1.data(), a2.data(), a3.data(), a4.data(), a5.data(), a0.data()};
  for (int a = 0; a < D; ++a) {
    mom[a] = arrs[a], frc[a] = arrs[a + 3], cm[a] = arrs[a];
    hp.momentum[a] = ch(arrs[a]), hp.force[a] = ch(arrs[a + 3]);
  }
  hp.heat_capacity = ch(a5.data());
  auto bp = ampm::P2gView<T, D>::separate(box, a0.data(), mom, frc);
  bp.heat_capacity(a5.data());
  CHECK(bytes_eq(bp.c(), hp), "%s P2gView::separate", name);
  typename A::g2p_view hg;
  std::memset(&hg, 0, sizeof hg);
  hg.nodes = hb;
  for (int a = 0; a < D; ++a) hg.velocity[a] = cch(arrs[a]);
  hg.temperature = cch(a4.data()), hg.temperature_old = cch(a5.data());
  CHECK(bytes_eq(ampm::G2pView<T, D>::separate(box, cm, a4.data(), a5.data()).c(), hg),
        "%s G2pView::separate", name);
  typename A::force_view hf;
  std::memset(&hf, 0, sizeof hf);
  hf.nodes = hb;
  for (int a = 0; a < D; ++a) hf.du[a] = cch(arrs[a]), hf.df[a] = ch(arrs[a + 3]);
  CHECK(bytes_eq(ampm::ForceView<T, D>::separate(box, cm, frc).c(), hf), "%s ForceView::separate", name);
  // Interleaved strides: s scalars per node → {s, s·nx, s·nx·ny}, data at the field of node 0.
  std::vector<P2gNode<T>> nodes(60);
  auto ip = ampm::P2gView<T, D>::interleaved(box, nodes.data(), &P2gNode<T>::mass,
                                             first<D>(&P2gNode<T>::px, &P2gNode<T>::py, &P2gNode<T>::pz));
  const std::ptrdiff_t s = sizeof(P2gNode<T>) / sizeof(T);
  CHECK(s == 10 && ip.c().mass.data == &nodes[0].mass && ip.c().mass.stride[0] == s &&
            ip.c().mass.stride[1] == 5 * s && ip.c().mass.stride[2] == 20 * s &&
            ip.c().momentum[1].data == &nodes[0].py && ip.c().force[0].data == nullptr,
        "%s interleaved strides", name);
}

template <class T, int D>
void test_transfers(const char* name) {
  using A = ampm::detail::api<T, D>;
  constexpr unsigned Q = AMPM_KERNEL_QUADRATIC;
  constexpr int COL = AMPM_GRID_COLLOCATED;
  Fixture<T, D> f(11);
  const std::size_t n = f.n;
  const auto mat = material<T>(0);
  auto P = f.built();
  // node_range
  AmpmNodeBox box{};
  const auto br = ampm::node_range(Q, COL, f.h, P, box);
  std::int32_t lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0};
  std::size_t ff = 99;
  const AmpmStatus sr = A::node_range(Q, COL, f.h, n, f.x.data(), lo, hi, &ff);
  bool box_ok = br.code() == sr && br.first_failed == ff && sr == AMPM_OK;
  for (int a = 0; a < D; ++a) box_ok = box_ok && box.lo[a] == lo[a] && box.dims[a] == hi[a] - lo[a] + 1;
  CHECK(box_ok, "%s node_range %s", name, br.name());
  for (int a = 0; a < D; ++a) box.lo[a] -= 1, box.dims[a] += 2;
  const std::size_t N = ampm::node_count<D>(box);
  // P2G: separate arrays through the wrapper vs the hand-filled view through C.
  using V = std::vector<T>;
  auto fresh = [&] { return std::vector<V>(10, V(N, T(0))); };  // mass, p[3], f[3], hc, te, cond
  auto view_of = [&](std::vector<V>& g) {
    std::array<T*, D> mom, frc;
    for (int a = 0; a < D; ++a) mom[a] = g[1 + a].data(), frc[a] = g[4 + a].data();
    auto v = ampm::P2gView<T, D>::separate(box, g[0].data(), mom, frc);
    v.heat_capacity(g[7].data()).thermal_energy(g[8].data()).conductivity(g[9].data());
    return v;
  };
  auto gw = fresh(), gc = fresh();
  const auto bw = ampm::p2g(mat, Q, COL, f.h, f.dt, P, view_of(gw));
  auto hv = view_of(gc).c();  // equal bytes to the hand-filled view, checked in test_builders
  const auto pc = f.hand();
  const AmpmStatus sc = A::p2g(&mat.c(), Q, COL, f.h, f.dt, n, &pc, &hv, &ff);
  CHECK(bw.code() == sc && sc == AMPM_OK && bw.first_failed == ff && gw == gc, "%s p2g %s", name, bw.name());
  bool same_grid = true;
  for (int i = 0; i < 10; ++i) same_grid = same_grid && same(gw[i], gc[i]);
  CHECK(same_grid, "%s p2g grids bitwise", name);
  // P2G into an interleaved node-struct grid equals the separate arrays bit for bit.
  std::vector<P2gNode<T>> pn(N, P2gNode<T>{});
  using PN = P2gNode<T>;
  auto iv = ampm::P2gView<T, D>::interleaved(box, pn.data(), &PN::mass, first<D>(&PN::px, &PN::py, &PN::pz),
                                             first<D>(&PN::fx, &PN::fy, &PN::fz));
  using C = ampm::Channel<T, D>;
  iv.heat_capacity(C::interleaved(pn.data(), &pn[0].hc, box))
      .thermal_energy(C::interleaved(pn.data(), &pn[0].te, box))
      .conductivity(C::interleaved(pn.data(), &pn[0].cond, box));
  const auto bi = ampm::p2g(mat, Q, COL, f.h, f.dt, P, iv);
  bool inter = bi.ok();
  T PN::*fields[] = {&PN::mass, &PN::px, &PN::py, &PN::pz, &PN::fx, &PN::fy, &PN::fz, &PN::hc, &PN::te, &PN::cond};
  for (int i = 0; i < 10; ++i) {
    if ((i == 3 || i == 6) && D == 2) continue;
    V col(N);
    for (std::size_t k = 0; k < N; ++k) col[k] = pn[k].*fields[i];
    inter = inter && same(col, gw[i]);
  }
  CHECK(inter, "%s interleaved P2G == separate P2G bitwise", name);
  // Grid update stand-in, then G2P through the wrapper (separate and interleaved) and C.
  std::vector<G2pNode<T>> gn(N);
  V vel[3] = {V(N), V(N), V(N)}, tn(N), to(N);
  for (std::size_t k = 0; k < N; ++k) {
    const T mk = gw[0][k];
    for (int a = 0; a < D; ++a) vel[a][k] = mk > 0 ? gw[1 + a][k] / mk : T(0);
    to[k] = mk > 0 ? gw[8][k] / gw[7][k] : T(0);
    tn[k] = to[k] + T(0.5);
    gn[k] = {vel[0][k], vel[1][k], vel[2][k], tn[k], to[k], T(0)};
  }
  std::array<const T*, D> cv;
  for (int a = 0; a < D; ++a) cv[a] = vel[a].data();
  const auto gsep = ampm::G2pView<T, D>::separate(box, cv, tn.data(), to.data());
  using GN = G2pNode<T>;
  const auto gint = ampm::G2pView<T, D>::interleaved(
      box, static_cast<const GN*>(gn.data()),
      first<D>(&GN::vx, &GN::vy, &GN::vz),
      &GN::tn, &GN::to);
  Fixture<T, D> fw = f, fi = f, fc = f;
  const auto b1 = ampm::g2p_update(mat, Q, f.h, f.dt, fw.built(), gsep);
  const auto b2 = ampm::g2p_update(mat, Q, f.h, f.dt, fi.built(), gint);
  const auto pcc = fc.hand();
  const AmpmStatus s3 = A::g2p_update(&mat.c(), Q, f.h, f.dt, n, &pcc, &gsep.c(), &ff);
  bool g2p_same = b1.code() == s3 && b2.code() == s3 && s3 == AMPM_OK && b1.first_failed == ff;
  for (std::size_t i = 0; i < fw.state().size(); ++i)
    g2p_same = g2p_same && same(*fw.state()[i], *fc.state()[i]) && same(*fi.state()[i], *fc.state()[i]);
  CHECK(g2p_same, "%s g2p_update (separate, interleaved) == C bitwise: %s %s", name, b1.name(), b2.name());
  // g2p_update_mac: each face grid gets its own box and a smooth velocity.
  std::array<ampm::G2pView<T, D>, D> faces;
  typename A::g2p_view cfaces[D];
  std::vector<V> fvel(D);
  for (int a = 0; a < D; ++a) {
    AmpmNodeBox fb{};
    const auto bf = ampm::node_range(Q, a, f.h, P, fb);
    CHECK(bf.ok(), "%s node_range face %d", name, a);
    fvel[a].resize(ampm::node_count<D>(fb));
    for (std::size_t k = 0; k < fvel[a].size(); ++k) fvel[a][k] = T(0.01) * std::sin(T(0.3) * T(k) + T(a));
    faces[a] = ampm::G2pView<T, D>(fb).velocity(a, fvel[a].data());
    cfaces[a] = faces[a].c();
  }
  Fixture<T, D> mw = f, mc = f;
  const auto bm = ampm::g2p_update_mac(mat, Q, f.h, f.dt, mw.built(), faces, &gsep);
  const auto pm = mc.hand();
  const AmpmStatus sm = A::g2p_update_mac(&mat.c(), Q, f.h, f.dt, n, &pm, cfaces, &gsep.c(), &ff);
  bool mac_same = bm.code() == sm && sm == AMPM_OK && bm.first_failed == ff;
  for (std::size_t i = 0; i < mw.state().size(); ++i) mac_same = mac_same && same(*mw.state()[i], *mc.state()[i]);
  CHECK(mac_same, "%s g2p_update_mac == C bitwise: %s", name, bm.name());
  // stencil
  constexpr std::size_t KD = D == 2 ? 9 : 27;
  std::vector<int> base_w(n * D, -7), base_c(n * D, -7);
  V w_w(n * KD, -1), w_c(n * KD, -1), dw_w(n * KD * D, -1), dw_c(n * KD * D, -1);
  const auto bs = ampm::stencil(Q, COL, f.h, P, base_w, w_w, dw_w);
  const AmpmStatus ss = A::stencil(Q, COL, f.h, n, f.x.data(), base_c.data(), w_c.data(), dw_c.data(), &ff);
  CHECK(bs.code() == ss && ss == AMPM_OK && base_w == base_c && same(w_w, w_c) && same(dw_w, dw_c),
        "%s stencil %s", name, bs.name());
  const auto bs2 = ampm::stencil(Q, COL, f.h, P, base_w, ampm::span<T>(w_w.data(), n * KD - 1), nullptr);
  CHECK(bs2.code() == AMPM_ERR_INVALID_ARGUMENT && bs2.first_failed == 0, "%s stencil short", name);
  // force_prepare / force_apply (separate and interleaved) / pressure
  const auto mpsd = material<T>(AMPM_MODEL_PSD_HESSIAN);
  const std::size_t SL = ampm::force_slot_len<D>();
  V sw(n * SL, -1), sc2(n * SL, -1);
  const auto bp = ampm::force_prepare(mpsd, P, sw);
  const AmpmStatus sp = A::force_prepare(&mpsd.c(), n, &pc, sc2.data(), &ff);
  CHECK(bp.code() == sp && sp == AMPM_OK && same(sw, sc2), "%s force_prepare %s", name, bp.name());
  std::vector<ForceNode<T>> fnodes(N, ForceNode<T>{});
  V du[3] = {V(N), V(N), V(N)}, dfw[3] = {V(N, 0), V(N, 0), V(N, 0)}, dfc[3] = {V(N, 0), V(N, 0), V(N, 0)};
  for (std::size_t k = 0; k < N; ++k) {
    for (int a = 0; a < 3; ++a) du[a][k] = T(1e-4) * std::sin(T(0.37) * T(k) + T(a));
    fnodes[k].dux = du[0][k], fnodes[k].duy = du[1][k], fnodes[k].duz = du[2][k];
  }
  std::array<const T*, D> cdu;
  std::array<T*, D> pdw, pdc;
  for (int a = 0; a < D; ++a) cdu[a] = du[a].data(), pdw[a] = dfw[a].data(), pdc[a] = dfc[a].data();
  const auto fvw = ampm::ForceView<T, D>::separate(box, cdu, pdw);
  const auto fvc = ampm::ForceView<T, D>::separate(box, cdu, pdc).c();
  using FN = ForceNode<T>;
  const auto fvi = ampm::ForceView<T, D>::interleaved(
      box, static_cast<const FN*>(fnodes.data()),
      first<D>(&FN::dux, &FN::duy, &FN::duz),
      fnodes.data(),
      first<D>(&FN::dfx, &FN::dfy, &FN::dfz));
  const auto ba = ampm::force_apply(Q, f.h, P, sw, fvw);
  const auto bai = ampm::force_apply(Q, f.h, P, sw, fvi);
  const AmpmStatus sa = A::force_apply(Q, f.h, n, f.x.data(), sc2.data(), &fvc, &ff);
  bool fa = ba.code() == sa && bai.code() == sa && sa == AMPM_OK && ba.first_failed == ff;
  T FN::*dfm[] = {&FN::dfx, &FN::dfy, &FN::dfz};
  for (int a = 0; a < D; ++a) {
    V col(N);
    for (std::size_t k = 0; k < N; ++k) col[k] = fnodes[k].*dfm[a];
    fa = fa && same(dfw[a], dfc[a]) && same(col, dfc[a]);
  }
  CHECK(fa, "%s force_apply (separate, interleaved) == C bitwise: %s", name, ba.name());
  const auto mp = ampm::Material<T>(mat).enable(0);
  V pw(n, -1), pcw(n, -1), pc_(n, -1), pcc_(n, -1);
  const auto bpr = ampm::pressure(mp, f.dt, P, pw, pcw);
  const AmpmStatus spr = A::pressure(&mp.c(), f.dt, n, &pc, pc_.data(), pcc_.data(), &ff);
  CHECK(bpr.code() == spr && spr == AMPM_OK && same(pw, pc_) && same(pcw, pcc_), "%s pressure %s", name, bpr.name());

  // ---- invalid inputs ----
  // A NaN velocity at particle 7: same status, first_failed and grid as C.
  Fixture<T, D> bad = f;
  bad.v[7 * D] = std::numeric_limits<T>::quiet_NaN();
  auto g1 = fresh(), g2 = fresh();
  const auto bn = ampm::p2g(mat, Q, COL, f.h, f.dt, bad.built(), view_of(g1));
  const auto hb = bad.hand();
  const auto hv2 = view_of(g2).c();
  const AmpmStatus sn = A::p2g(&mat.c(), Q, COL, f.h, f.dt, n, &hb, &hv2, &ff);
  CHECK(bn.code() == sn && sn == AMPM_ERR_NON_FINITE && bn.first_failed == ff && ff == 7 && g1 == g2,
        "%s p2g NaN: %s/%zu vs %d/%zu", name, bn.name(), bn.first_failed, int(sn), ff);
  // A box one node short: AMPM_ERR_OUTSIDE_GRID from both.
  AmpmNodeBox small = box;
  small.dims[0] -= 2;
  auto g3 = fresh();
  std::array<T*, D> m3{};
  for (int a = 0; a < D; ++a) m3[a] = g3[1 + a].data();
  const auto vsmall = ampm::P2gView<T, D>::separate(small, g3[0].data(), m3);
  const auto bo = ampm::p2g(mat, Q, COL, f.h, f.dt, P, vsmall);
  const AmpmStatus so = A::p2g(&mat.c(), Q, COL, f.h, f.dt, n, &pc, &vsmall.c(), &ff);
  CHECK(bo.code() == so && so == AMPM_ERR_OUTSIDE_GRID && bo.first_failed == ff, "%s outside grid: %s", name, bo.name());
  // A NULL required array: C's AMPM_ERR_NULL_POINTER, first_failed 0.
  auto pnull = f.built();
  pnull.f_e(nullptr);
  auto hnull = f.hand();
  hnull.f_e = nullptr;
  auto g4 = fresh();
  const auto bz = ampm::p2g(mat, Q, COL, f.h, f.dt, pnull, view_of(g4));
  const AmpmStatus sz = A::p2g(&mat.c(), Q, COL, f.h, f.dt, n, &hnull, &hv, &ff);
  CHECK(bz.code() == sz && sz == AMPM_ERR_NULL_POINTER && bz.first_failed == 0 && ff == 0,
        "%s NULL f_e: %s", name, bz.name());
  // Arrays too short for n: every call refuses before C, nothing written.
  auto pshort = f.built();
  pshort.mass(ampm::span<const T>(f.m.data(), n - 1));
  CHECK(!pshort.sizes_ok(), "%s short mass noted", name);
  auto g5 = fresh();
  Fixture<T, D> fs = f;
  auto ps2 = fs.built();
  ps2.f_e(ampm::span<T>(fs.fe.data(), n * D * D - 1));
  V slots_short(n * SL - 1, -1), before = slots_short;
  const ampm::BatchStatus shorts[] = {
      ampm::p2g(mat, Q, COL, f.h, f.dt, pshort, view_of(g5)),
      ampm::g2p_update(mat, Q, f.h, f.dt, ps2, gsep),
      ampm::g2p_update_mac(mat, Q, f.h, f.dt, ps2, faces, &gsep),
      ampm::node_range(Q, COL, f.h, pshort, box),
      ampm::force_prepare(mpsd, P, slots_short),
      ampm::force_apply(Q, f.h, P, ampm::span<const T>(slots_short), fvw),
      ampm::pressure(mp, f.dt, P, ampm::span<T>(pw.data(), n - 1), nullptr)};
  bool all_refused = true;
  for (const auto& s : shorts) all_refused = all_refused && s.code() == AMPM_ERR_INVALID_ARGUMENT && s.first_failed == 0;
  bool untouched = g5 == fresh() && same(slots_short, before);
  for (std::size_t i = 0; i < fs.state().size(); ++i) untouched = untouched && same(*fs.state()[i], *f.state()[i]);
  CHECK(all_refused && untouched, "%s short arrays refused (%d) and nothing written (%d)", name,
        int(all_refused), int(untouched));
}

}  // namespace

int main() {
  test_builders<float, 2>("2D f32");
  test_builders<float, 3>("3D f32");
  test_builders<double, 2>("2D f64");
  test_builders<double, 3>("3D f64");
  test_transfers<float, 2>("2D f32");
  test_transfers<float, 3>("3D f32");
  test_transfers<double, 2>("2D f64");
  test_transfers<double, 3>("3D f64");
  std::printf("test_hpp_particles: %ld checks, %ld failures\n", g_checks, g_failures);
  return g_failures == 0 ? 0 : 1;
}
