// The mechanical half of a step: the node box and stencils, P2G (with separate force channels
// and in the impulse form), Σ|f| by one-particle P2G, the mass and momentum checks of P2G, the
// free-flight grid update, G2P, and the checks of the particles after it.
#pragma once

#include "host_loop/check.hpp"
#include "host_loop/run.hpp"

namespace {

/// The node box the particles reach, the host's arrays over it and the step's stencils;
/// returns n_add, the most particles whose stencils share one node.
template <class T, int D>
int node_box(Run<T, D>& r) {
  using A = Api<T, D>;
  constexpr int KD = Run<T, D>::KD;
  const unsigned kernel = Run<T, D>::kernel;
  const Particles<T, D>& p = r.p;
  Grid<T, D>& g = r.g;
  const std::size_t n = r.n;
  const T h = r.h;
  int lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0};
  CHECK_OK([&](std::size_t* f) {
    return A::node_range(kernel, AMPM_GRID_COLLOCATED, h, n, p.x.data(), lo, hi, f);
  }, n);
  g.reset(lo, hi);
  CHECK_OK([&](std::size_t* f) {
    return A::stencil(kernel, AMPM_GRID_COLLOCATED, h, n, p.x.data(), r.base.data(), r.w.data(),
                      r.gw.data(), f);
  }, n);
  std::vector<int> share(g.count, 0);
  int n_add = 0;
  for (std::size_t i = 0; i < n; ++i)
    for (int rr = 0; rr < KD; ++rr) {
      int idx[3] = {0, 0, 0};
      for (int a = 0, q = rr; a < D; ++a, q /= K1) idx[a] = r.base[D * i + a] + q % K1;
      n_add = std::max(n_add, ++share[g.at(idx)]);
    }
  return n_add;
}

/// P2G with impulse_dt = 0 and separate force channels (mass, momentum, forces and, thermal,
/// the heat channels), then the symplectic form: impulse_dt = Δt, no force channel.
template <class T, int D>
void p2g(Run<T, D>& r) {
  using A = Api<T, D>;
  const unsigned kernel = Run<T, D>::kernel;
  Grid<T, D>& g = r.g;
  const std::size_t n = r.n;
  const T h = r.h, dt = r.dt;
  typename A::P2gView pview{};
  pview.nodes = g.box();
  pview.mass = g.out(g.mass);
  for (int a = 0; a < 3; ++a) {
    pview.momentum[a] = a < D ? g.out(g.mom[a]) : Grid<T, D>::none();
    pview.force[a] = a < D ? g.out(g.force[a]) : Grid<T, D>::none();
  }
  pview.heat_capacity = r.thermal ? g.out(g.hc) : Grid<T, D>::none();
  pview.thermal_energy = r.thermal ? g.out(g.te) : Grid<T, D>::none();
  pview.conductivity = r.thermal ? g.out(g.cond) : Grid<T, D>::none();
  CHECK_OK([&](std::size_t* f) {
    return A::p2g(&r.mat, kernel, AMPM_GRID_COLLOCATED, h, T(0), n, &r.pv, &pview, f);
  }, n);

  // The symplectic form: impulse_dt = Δt, no force channel.
  typename A::P2gView iview{};
  iview.nodes = g.box();
  iview.mass = Grid<T, D>::none();
  for (int a = 0; a < 3; ++a) {
    iview.momentum[a] = a < D ? g.out(g.mom2[a]) : Grid<T, D>::none();
    iview.force[a] = Grid<T, D>::none();
  }
  iview.heat_capacity = iview.thermal_energy = iview.conductivity = Grid<T, D>::none();
  CHECK_OK([&](std::size_t* f) {
    return A::p2g(&r.mat, kernel, AMPM_GRID_COLLOCATED, h, dt, n, &r.pv, &iview, f);
  }, n);
}

/// Σ_p Σ_i |f_ip| per axis, by a one-particle P2G of each particle into a view of its own
/// stencil.
template <class T, int D>
Vec3 force_magnitudes(Run<T, D>& r) {
  using A = Api<T, D>;
  constexpr int KD = Run<T, D>::KD;
  const unsigned kernel = Run<T, D>::kernel;
  const std::size_t n = r.n;
  const T h = r.h;
  Vec3 fabs_sum;
  std::vector<T> fs[3];
  for (int a = 0; a < D; ++a) fs[a].assign(KD, 0);
  for (std::size_t i = 0; i < n; ++i) {
    typename A::P2gView one{};
    for (int a = 0; a < 3; ++a) {
      one.nodes.lo[a] = a < D ? r.base[D * i + a] : 0;
      one.nodes.dims[a] = a < D ? K1 : 1;
    }
    one.mass = Grid<T, D>::none();
    for (int a = 0; a < 3; ++a) {
      one.momentum[a] = Grid<T, D>::none();
      one.force[a] = Grid<T, D>::none();
      if (a < D) {
        std::fill(fs[a].begin(), fs[a].end(), T(0));
        one.force[a].data = fs[a].data();
        one.force[a].stride[0] = 1, one.force[a].stride[1] = K1, one.force[a].stride[2] = K1 * K1;
      }
    }
    one.heat_capacity = one.thermal_energy = one.conductivity = Grid<T, D>::none();
    typename A::Particles pi = r.pv;
    pi.x += D * i, pi.v += D * i, pi.affine += D * D * i, pi.f_e += D * D * i, pi.f_p += D * D * i;
    pi.mass += i, pi.volume0 += i, pi.temperature += i, pi.latent += i, pi.phase += i;
    CHECK_OK([&](std::size_t* f) {
      return A::p2g(&r.mat, kernel, AMPM_GRID_COLLOCATED, h, T(0), 1, &pi, &one, f);
    }, 1u);
    for (int a = 0; a < D; ++a)
      for (int rr = 0; rr < KD; ++rr) fabs_sum.a[a] += std::fabs(static_cast<ld>(fs[a][rr]));
  }
  return fabs_sum;
}

/// Mass and momentum after P2G, the force sum and the impulse form, each against its bound;
/// adds this step's momentum bound to the run's budget.
template <class T, int D>
void check_p2g(Run<T, D>& r, int step, int n_add, const Vec3& fabs_sum) {
  using A = Api<T, D>;
  constexpr int KD = Run<T, D>::KD;
  const Particles<T, D>& p = r.p;
  const Grid<T, D>& g = r.g;
  const std::size_t n = r.n;
  const T h = r.h, dt = r.dt;
  const ld eps = r.eps;
  const char* label = r.label;
  const ld c_p = n_add + KD + 6 * D + 8;
  ld grid_m = 0;
  Vec3 grid_p, grid_f, part_p, s_abs;
  for (std::size_t k = 0; k < g.count; ++k) {
    grid_m += g.mass[k];
    for (int a = 0; a < D; ++a) grid_p.a[a] += g.mom[a][k], grid_f.a[a] += g.force[a][k];
  }
  for (std::size_t i = 0; i < n; ++i)
    for (int a = 0; a < D; ++a) {
      part_p.a[a] += static_cast<ld>(p.m[i]) * p.v[D * i + a];
      ld cs = 0;
      for (int b = 0; b < D; ++b) cs += std::fabs(static_cast<ld>(p.c[D * D * i + a + D * b]));
      s_abs.a[a] +=
          static_cast<ld>(p.m[i]) * (std::fabs(static_cast<ld>(p.v[D * i + a])) + 3.5L * h * cs);
    }
  const ld tol_m = (n_add + KD + 6 * D) * eps * r.sum_m;
  CHECK(std::fabs(grid_m - r.sum_m) <= tol_m,
        "%s %s step %d: grid mass %.12Le, particles %.12Le (tol %.3Le)", A::name, label, step,
        grid_m, r.sum_m, tol_m);
  for (int a = 0; a < D; ++a) {
    const ld tp = c_p * eps * s_abs.a[a], tf = c_p * eps * fabs_sum.a[a];
    CHECK(std::fabs(grid_p.a[a] - part_p.a[a]) <= tp,
          "%s %s step %d axis %d: P2G momentum %.12Le vs %.12Le (tol %.3Le)", A::name, label,
          step, a, grid_p.a[a], part_p.a[a], tp);
    CHECK(std::fabs(grid_f.a[a]) <= tf, "%s %s step %d axis %d: Σ f = %.3Le (tol %.3Le)",
          A::name, label, step, a, grid_f.a[a], tf);
    ld diff = 0;
    for (std::size_t k = 0; k < g.count; ++k)
      diff += std::fabs(static_cast<ld>(g.mom2[a][k]) -
                        (static_cast<ld>(g.mom[a][k]) + static_cast<ld>(dt) * g.force[a][k]));
    const ld ti = 2 * (c_p + 2) * eps * (s_abs.a[a] + dt * fabs_sum.a[a]);
    CHECK(diff <= ti,
          "%s %s step %d axis %d: impulse P2G differs from p + dt f by %.3Le (tol %.3Le)",
          A::name, label, step, a, diff, ti);
    r.budget.a[a] += (2 * n_add + 2 * KD + 6 * D + 13) * eps * (s_abs.a[a] + dt * fabs_sum.a[a]);
  }
}

/// The grid update of free flight: v_i = (p_i + Δt f_i)/m_i (0 on massless nodes).
template <class T, int D>
void grid_update(Run<T, D>& r) {
  Grid<T, D>& g = r.g;
  const T dt = r.dt;
  for (std::size_t k = 0; k < g.count; ++k)
    for (int a = 0; a < D; ++a)
      g.vel[a][k] = g.mass[k] > 0 ? (g.mom[a][k] + dt * g.force[a][k]) / g.mass[k] : T(0);
}

/// G2P with the grid velocities and temperatures; grid_mv and grid_mv_abs get Σ_i m_i v_i and
/// Σ_i |m_i v_i| per axis, taken before the call.
template <class T, int D>
void g2p(Run<T, D>& r, Vec3& grid_mv, Vec3& grid_mv_abs) {
  using A = Api<T, D>;
  const unsigned kernel = Run<T, D>::kernel;
  const Grid<T, D>& g = r.g;
  const std::size_t n = r.n;
  const T h = r.h, dt = r.dt;
  typename A::G2pView gview{};
  gview.nodes = g.box();
  for (int a = 0; a < 3; ++a) {
    gview.velocity[a].data = a < D ? g.vel[a].data() : nullptr;
    for (int b = 0; b < 3; ++b) gview.velocity[a].stride[b] = g.stride(b);
  }
  gview.temperature = g.in(g.tnew);
  gview.temperature_old = g.in(g.told);
  for (std::size_t k = 0; k < g.count; ++k)
    for (int a = 0; a < D; ++a) {
      grid_mv.a[a] += static_cast<ld>(g.mass[k]) * g.vel[a][k];
      grid_mv_abs.a[a] += std::fabs(static_cast<ld>(g.mass[k]) * g.vel[a][k]);
    }
  CHECK_OK([&](std::size_t* f) { return A::g2p(&r.mat, kernel, h, dt, n, &r.pv, &gview, f); }, n);
}

/// After G2P: every particle field finite, J_E·J_P > 0, the particles' momentum against the
/// grid's and against the initial momentum (within the run's budget).
template <class T, int D>
void check_particles(const Run<T, D>& r, int step, int n_add, const Vec3& grid_mv,
                     const Vec3& grid_mv_abs) {
  using A = Api<T, D>;
  constexpr int KD = Run<T, D>::KD;
  const Particles<T, D>& p = r.p;
  const std::size_t n = r.n;
  const ld eps = r.eps;
  const char* label = r.label;
  Vec3 pt;
  bool finite = true, positive = true;
  for (std::size_t i = 0; i < n; ++i) {
    for (int a = 0; a < D; ++a) {
      pt.a[a] += static_cast<ld>(p.m[i]) * p.v[D * i + a];
      finite &= std::isfinite(p.x[D * i + a]) && std::isfinite(p.v[D * i + a]);
    }
    for (int k = 0; k < D * D; ++k)
      finite &= std::isfinite(p.c[D * D * i + k]) && std::isfinite(p.fe[D * D * i + k]) &&
                std::isfinite(p.fp[D * D * i + k]);
    finite &= std::isfinite(p.t[i]) && std::isfinite(p.u[i]);
    const T je = det<T, D>(&p.fe[D * D * i]), jp = det<T, D>(&p.fp[D * D * i]);
    positive &= je > 0 && jp > 0 && je * jp > 0;
  }
  CHECK(finite, "%s %s step %d: a particle field is not finite", A::name, label, step);
  CHECK(positive, "%s %s step %d: J_E·J_P <= 0", A::name, label, step);
  for (int a = 0; a < D; ++a) {
    const ld tg = (n_add + KD + 4) * eps * grid_mv_abs.a[a];
    CHECK(std::fabs(pt.a[a] - grid_mv.a[a]) <= tg,
          "%s %s step %d axis %d: G2P momentum %.12Le vs grid %.12Le (tol %.3Le)", A::name, label,
          step, a, pt.a[a], grid_mv.a[a], tg);
    CHECK(std::fabs(pt.a[a] - r.p0.a[a]) <= r.budget.a[a],
          "%s %s step %d axis %d: momentum %.12Le, initial %.12Le (tol %.3Le)", A::name, label,
          step, a, pt.a[a], r.p0.a[a], r.budget.a[a]);
  }
}

}  // namespace
