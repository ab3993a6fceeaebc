// The elastic 3D f32 step through the C++ wrapper include/ampm.hpp: bit-identity with the C
// step, and the two timed alternately.
#pragma once

#include "ampm.hpp"

#include "case.hpp"
#include "checks.hpp"

namespace bench {

// ---- the same step through ampm.hpp -------------------------------------------------------

/// The elastic scene's material, built with ampm.hpp's named setters (the fields the C path's
/// material() sets; equal bytes, checked in check_hpp).
inline ampm::Material<float> hpp_material() {
  const auto c = material<float, 3>(Scene::Elastic, false);
  return ampm::Material<float>()
      .model(c.model)
      .solid(ampm::PhaseParams<float>().mu(c.solid.mu).inv_lambda(c.solid.inv_lambda)
                 .heat_capacity(c.solid.heat_capacity).conductivity(c.solid.conductivity))
      .liquid(ampm::PhaseParams<float>().mu(c.liquid.mu).inv_lambda(c.liquid.inv_lambda)
                  .heat_capacity(c.liquid.heat_capacity).conductivity(c.liquid.conductivity))
      .melting_point(c.melting_point)
      .latent_heat(c.latent_heat)
      .flip(c.flip)
      .critical_compression(c.critical_compression)
      .critical_stretch(c.critical_stretch)
      .hardening(c.hardening);
}

/// One host step (zero + P2G sym + grid + G2P) of the elastic 3D f32 case through ampm.hpp:
/// the material and particle builders are made per call, as the C path fills its structs.
struct HppStep {
  Case<float, 3>& cs;
  ampm::P2gView<float, 3> p2g_view;
  ampm::G2pView<float, 3> g2p_view;
  explicit HppStep(Case<float, 3>& c)
      : cs(c),
        p2g_view(ampm::P2gView<float, 3>::separate(c.g.box(), c.g.mass.data(),
                                                   {c.g.mom[0].data(), c.g.mom[1].data(), c.g.mom[2].data()})),
        g2p_view(ampm::G2pView<float, 3>::separate(c.g.box(), {c.g.vel[0].data(), c.g.vel[1].data(), c.g.vel[2].data()})) {}
  ampm::Particles<float, 3> particles() {
    auto& p = cs.p;
    ampm::Particles<float, 3> q(p.n);
    q.x(p.x.data()).v(p.v.data()).affine(p.c.data()).f_e(p.fe.data()).f_p(p.fp.data()).mass(p.m.data())
        .volume0(p.v0.data()).temperature(p.t.data()).latent(p.u.data()).phase(p.ph.data());
    return q;
  }
  void step() {
    cs.g.zero_p2g();
    const auto a = ampm::p2g(hpp_material(), AMPM_KERNEL_QUADRATIC, AMPM_GRID_COLLOCATED, cs.h, cs.dt, particles(), p2g_view);
    expect_ok("ampm.hpp P2G sym", a.code(), a.first_failed, cs.p.n);
    grid_update(cs.g, false);
    const auto b = ampm::g2p_update(hpp_material(), AMPM_KERNEL_QUADRATIC, cs.h, cs.dt, particles(), g2p_view);
    expect_ok("ampm.hpp G2P", b.code(), b.first_failed, cs.p.n);
  }
};

/// The C step of the elastic case (the `step` column's body).
inline void c_step(Case<float, 3>& cs) {
  std::size_t ff = 0;
  cs.g.zero_p2g();
  const AmpmStatus a = cs.p2g_sym(&ff);
  expect_ok(cs.label("P2G sym"), a, ff, cs.p.n);
  grid_update(cs.g, false);
  const AmpmStatus b = cs.g2p(&ff);
  expect_ok(cs.label("G2P"), b, ff, cs.p.n);
}

/// ampm.hpp's step equals the C step bit for bit (grid and particles), and its structs are the
/// C path's bytes.
inline void check_hpp(int per_axis, CheckLog& log) {
  Case<float, 3> a(Scene::Elastic, per_axis), b(Scene::Elastic, per_axis);
  HppStep hs(b);
  const auto cm = material<float, 3>(Scene::Elastic, false);
  const auto hm = hpp_material();
  auto pv = b.p.view();
  const bool structs = std::memcmp(&cm, &hm.c(), sizeof cm) == 0 &&
                       std::memcmp(&pv, &hs.particles().c(), sizeof pv) == 0;
  bool same = structs;
  for (int step = 0; step < 3; ++step) {
    c_step(a);
    hs.step();
    auto eq = [](const std::vector<float>& x, const std::vector<float>& y) {
      return x.size() == y.size() && std::memcmp(x.data(), y.data(), x.size() * sizeof(float)) == 0;
    };
    same = same && eq(a.g.mass, b.g.mass) && eq(a.p.x, b.p.x) && eq(a.p.v, b.p.v) && eq(a.p.c, b.p.c) &&
           eq(a.p.fe, b.p.fe);
    for (int d = 0; d < 3; ++d) same = same && eq(a.g.mom[d], b.g.mom[d]);
  }
  const std::string line = std::string("3D f32 elastic step through ampm.hpp vs the C calls, 3 steps: ") +
                           (same ? "same struct bytes, bit-identical grids and particles"
                                 : structs ? "DIFFERENT results" : "DIFFERENT struct bytes");
  log.add(line);
  if (!same) fail(line);
}

struct HppTiming {
  std::size_t n = 0;
  double c = NAN, hpp = NAN, c_min = NAN, hpp_min = NAN;
};

/// The C step and the ampm.hpp step, alternating rep by rep (one warm-up each), ns per particle.
inline HppTiming time_hpp(int per_axis, int reps) {
  Case<float, 3> cs(Scene::Elastic, per_axis);
  HppStep hs(cs);
  std::vector<double> tc, th;
  auto once = [&](auto&& body) {
    cs.restore();
    const auto t0 = std::chrono::steady_clock::now();
    body();
    const auto t1 = std::chrono::steady_clock::now();
    return ns_per(t0, t1, cs.p.n);
  };
  for (int r = -1; r < reps; ++r) {
    const double a = once([&] { c_step(cs); });
    const double b = once([&] { hs.step(); });
    if (r >= 0) tc.push_back(a), th.push_back(b);
  }
  const double c = median_of(tc), hpp = median_of(th);  // both sorted: front() is the fastest
  cs.restore();
  return {cs.p.n, c, hpp, tc.front(), th.front()};
}

}  // namespace bench
