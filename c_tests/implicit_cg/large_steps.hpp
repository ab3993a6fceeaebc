// The large steps, Δt = 20× the explicit limit: repeated backward-Euler steps (finite, J_E > 0,
// CG within its bound, energy never above its initial value), and for contrast explicit steps
// at the same Δt (printed, not asserted).
#pragma once

#include "implicit_cg/cg.hpp"

namespace {

/// Every particle field of q finite.
template <class T>
bool all_finite(const Parts<T>& q) {
  bool finite = true;
  for (T x : q.x) finite &= std::isfinite(x);
  for (T x : q.v) finite &= std::isfinite(x);
  for (T x : q.fe) finite &= std::isfinite(x);
  for (T x : q.c) finite &= std::isfinite(x);
  return finite;
}

/// J_E = det F_E > 0 for every particle of q.
template <class T>
bool all_positive_j(const Parts<T>& q) {
  bool positive = true;
  for (std::size_t i = 0; i < q.n; ++i) {
    MatL<3> f;
    for (int k = 0; k < 9; ++k) f.data()[k] = q.fe[9 * i + k];
    positive &= f.determinant() > 0;
  }
  return positive;
}

/// Six backward-Euler steps of a copy of p at Δt = 20 h/c.
template <class T>
void check_large_steps(Checker& ck, const Setup<T>& s, const Parts<T>& p, ld dt_cfl, ld tol) {
  using A = Api3<T>;
  Parts<T> q = p;
  Host<T> big(ck, s, q);
  const T dt_big = static_cast<T>(20 * dt_cfl);
  const auto e0 = big.energy();
  const ld energy0 = e0.first + e0.second;
  std::printf("  %s: Δt = 20 h/c = %.3Le s, initial energy %.6Le J (kinetic %.6Le)\n", A::name,
              static_cast<ld>(dt_big), energy0, e0.first);
  for (int step = 0; step < 6; ++step) {
    Step<T> sb;
    big.p2g(sb, dt_big);
    big.prepare(sb, true);
    std::array<std::vector<T>, 3> v;
    char what[64];
    std::snprintf(what, sizeof what, "large step %d", step);
    big.cg(sb, dt_big, tol, v, what);
    big.g2p(sb, dt_big, v);
    const bool finite = all_finite(q), positive = all_positive_j(q);
    AMPM_CHECK(ck, finite, "%s large step %d: non-finite particle field", A::name, step);
    AMPM_CHECK(ck, positive, "%s large step %d: J_E <= 0", A::name, step);
    const auto e = big.energy();
    std::printf("    energy %.6Le J (kinetic %.6Le, elastic %.6Le)\n", e.first + e.second, e.first,
                e.second);
    AMPM_CHECK(ck, e.first + e.second <= energy0, "%s large step %d: energy %.6Le > initial %.6Le",
               A::name, step, e.first + e.second, energy0);
  }
}

/// For contrast (printed, not asserted): symplectic Euler at the same large Δt.
template <class T>
void print_explicit_steps(const Setup<T>& s, const Parts<T>& p, ld dt_cfl) {
  using A = Api3<T>;
  Parts<T> q = p;
  const T dt_big = static_cast<T>(20 * dt_cfl);
  const auto mat = material(s, false);
  const T h = static_cast<T>(s.h);
  std::printf("  %s: explicit steps at the same Δt:", A::name);
  for (int step = 0; step < 6; ++step) {
    int lo[3], hi[3];
    std::size_t ff = 0;
    if (A::node_range(AMPM_KERNEL_QUADRATIC, AMPM_GRID_COLLOCATED, h, q.n, q.x.data(), lo, hi,
                      &ff) != AMPM_OK) {
      std::printf(" node_range failed");
      break;
    }
    Grid<T> g;
    g.reset(lo, hi);
    typename A::P2gView v{};
    v.nodes = g.box();
    v.mass = g.out(g.mass.data());
    for (int a = 0; a < 3; ++a) v.momentum[a] = g.out(g.mom[a].data());
    auto qv = q.view();
    const AmpmStatus s1 = A::p2g(&mat, AMPM_KERNEL_QUADRATIC, AMPM_GRID_COLLOCATED, h, dt_big,
                                 q.n, &qv, &v, &ff);
    for (std::size_t k = 0; k < g.count; ++k)
      for (int a = 0; a < 3; ++a)
        g.vstar[a][k] = g.mass[k] > 0 ? g.mom[a][k] / g.mass[k] : T(0);
    typename A::G2pView gv{};
    gv.nodes = g.box();
    for (int a = 0; a < 3; ++a) gv.velocity[a] = g.in(g.vstar[a].data());
    const AmpmStatus s2 = A::g2p(&mat, AMPM_KERNEL_QUADRATIC, h, dt_big, q.n, &qv, &gv, &ff);
    ld ke = 0;
    for (std::size_t i = 0; i < q.n; ++i)
      for (int a = 0; a < 3; ++a) ke += 0.5L * q.m[i] * q.v[3 * i + a] * q.v[3 * i + a];
    std::printf(" KE %.3Le (%s/%s)", ke, status_name(s1), status_name(s2));
    if (s1 != AMPM_OK || s2 != AMPM_OK || !std::isfinite(ke)) break;
  }
  std::printf("\n");
}

}  // namespace
