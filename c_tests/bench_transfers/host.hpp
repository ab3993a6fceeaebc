// The workload: the C symbols by (scalar, dimension), statuses, the scenes' materials and
// particles, the host's grid and views, and the host's grid update.
#pragma once

#include <cstddef>
#include <cstdint>

#include "ampm.h"
#include "bench_machine.hpp"  // cpu_model, compiler, load_average
#include "common.hpp"         // status_name, isa_name
#include "dense_box.hpp"

#include <Eigen/Dense>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <limits>
#include <numeric>
#include <random>
#include <sstream>
#include <string>
#include <thread>
#include <type_traits>
#include <utility>
#include <vector>

namespace bench {

using ampm_test::isa_name;
using ampm_test::status_name;
using bench_machine::compiler;
using bench_machine::cpu_model;
using bench_machine::load_average;

using ld = long double;

constexpr std::uint64_t kSeed = 0xbe4c'7a25'f3e5'0001ULL;
constexpr int kDefaultReps = 7;
constexpr int K1 = 3;  // quadratic: 3 nodes per axis

// ---- the C symbols by (scalar, dimension) --------------------------------------------------

template <class T, int D>
using Api = ampm_test::PartApi<T, D>;

[[noreturn]] inline void fail(const std::string& msg) {
  std::fprintf(stderr, "bench_transfers: %s\n", msg.c_str());
  std::exit(1);
}

inline void expect_ok(const std::string& what, AmpmStatus st, std::size_t first, std::size_t n) {
  if (st != AMPM_OK || first != n)
    fail(what + ": " + status_name(st) + ", first_failed " + std::to_string(first) + " (n = " +
         std::to_string(n) + ")");
}

// ---- scenes ----------------------------------------------------------------------------------

enum class Scene { Elastic, Fluid, Thermal, Snow };
constexpr Scene kScenes[] = {Scene::Elastic, Scene::Fluid, Scene::Thermal, Scene::Snow};

inline const char* scene_name(Scene s) {
  switch (s) {
    case Scene::Elastic: return "elastic";
    case Scene::Fluid: return "fluid";
    case Scene::Thermal: return "thermal+phase";
    case Scene::Snow: return "snow";
  }
  return "?";
}

constexpr double kMu = 1e5, kLambda = 1e5, kRho = 1000, kH = 0.01, kDt = 1e-4;
constexpr double kTm = 273.15, kLatent = 334000, kCs = 2100, kCl = 4200;

template <class T, int D>
typename Api<T, D>::Material material(Scene s, bool psd) {
  typename Api<T, D>::Material m{};
  m.model = 0;
  m.solid.mu = static_cast<T>(kMu);
  m.solid.inv_lambda = static_cast<T>(1 / kLambda);
  m.solid.heat_capacity = static_cast<T>(kCs);
  m.solid.conductivity = static_cast<T>(2.2);
  m.liquid.mu = 0;
  m.liquid.inv_lambda = static_cast<T>(1 / kLambda);
  m.liquid.heat_capacity = static_cast<T>(kCl);
  m.liquid.conductivity = static_cast<T>(0.6);
  m.melting_point = static_cast<T>(kTm);
  m.latent_heat = static_cast<T>(kLatent);
  m.flip = static_cast<T>(0.95);
  m.critical_compression = static_cast<T>(0.025);
  m.critical_stretch = static_cast<T>(0.0075);
  m.hardening = static_cast<T>(10);
  if (s == Scene::Thermal) m.model |= AMPM_MODEL_THERMAL | AMPM_MODEL_PHASE_CHANGE;
  if (s == Scene::Snow) m.model |= AMPM_MODEL_PLASTIC;
  if (psd) m.model |= AMPM_MODEL_PSD_HESSIAN;
  return m;
}

// ---- particles -----------------------------------------------------------------------------

template <class T, int D>
struct Parts {
  std::size_t n = 0;
  std::vector<T> x, v, c, fe, fp, m, v0, t, u;
  std::vector<std::uint8_t> ph;
  template <class U = T>
  typename Api<U, D>::Particles view() {
    return view_at<U>(0);
  }
  /// The view of particles i.. (each array advanced by i records).
  template <class U = T>
  typename Api<U, D>::Particles view_at(std::size_t i) {
    const std::size_t d = D, dd = D * D;
    return {x.data() + i * d, v.data() + i * d, c.data() + i * dd, fe.data() + i * dd, fp.data() + i * dd,
            m.data() + i, v0.data() + i, t.data() + i, u.data() + i, ph.data() + i};
  }
};

/// Haar rotation: angle uniform in [0, 2π) in 2D; in 3D the unit quaternion of a normalised
/// standard Gaussian 4-vector (uniform on S³, mapped to the Haar measure on SO(3)).
template <int D>
Eigen::Matrix<double, D, D> rotation(std::mt19937_64& g) {
  std::normal_distribution<double> nd;
  Eigen::Matrix<double, D, D> r;
  if constexpr (D == 2) {
    const double t = std::uniform_real_distribution<double>(0, 6.283185307179586)(g);
    r << std::cos(t), -std::sin(t), std::sin(t), std::cos(t);
  } else {
    Eigen::Vector4d q;
    do {
      for (int k = 0; k < 4; ++k) q(k) = nd(g);
    } while (q.norm() < 1e-6);
    q.normalize();
    r = Eigen::Quaterniond(q(0), q(1), q(2), q(3)).toRotationMatrix();
  }
  return r;
}

/// The block of `scene`, `per_axis` particles per axis, shuffled then sorted by cell.
template <class T, int D>
Parts<T, D> make_parts(Scene scene, int per_axis) {
  std::mt19937_64 g(kSeed + static_cast<std::uint64_t>(D) * 16 + static_cast<int>(scene));
  std::uniform_real_distribution<double> uni(-1, 1);
  std::size_t n = 1;
  for (int a = 0; a < D; ++a) n *= static_cast<std::size_t>(per_axis);
  // Draw in double (the same particles for f32 and f64 up to rounding).
  std::vector<double> x(n * D), v(n * D), c(n * D * D), fe(n * D * D), fp(n * D * D), t(n), u(n);
  std::vector<std::uint8_t> ph(n, AMPM_PHASE_SOLID);
  const double sp = kH / 2;
  for (std::size_t i = 0; i < n; ++i) {
    std::size_t q = i;
    for (int a = 0; a < D; ++a) {
      const int k = static_cast<int>(q % per_axis);
      q /= per_axis;
      x[D * i + a] = 2 * kH + sp * (k + 0.5) + sp * 0.25 * uni(g);
      v[D * i + a] = 0.1 * uni(g);
      for (int b = 0; b < D; ++b) c[D * D * i + a + D * b] = 2.0 * uni(g);
    }
    Eigen::Matrix<double, D, D> f = Eigen::Matrix<double, D, D>::Identity(),
                                p = Eigen::Matrix<double, D, D>::Identity();
    Eigen::Matrix<double, D, 1> sig;
    const int kind = static_cast<int>(i % 3);
    switch (scene) {
      case Scene::Elastic:
        for (int a = 0; a < D; ++a) sig(a) = 1 + 0.05 * uni(g);
        f = rotation<D>(g) * sig.asDiagonal() * rotation<D>(g);
        t[i] = 0;
        break;
      case Scene::Fluid: {
        ph[i] = AMPM_PHASE_LIQUID;
        const double j = 1 + 0.02 * uni(g);
        f *= D == 2 ? std::sqrt(j) : std::cbrt(j);
        p *= D == 2 ? std::sqrt(1 + 0.05 * uni(g)) : std::cbrt(1 + 0.05 * uni(g));
        break;
      }
      case Scene::Thermal:
        if (kind == 0) {  // ice
          for (int a = 0; a < D; ++a) sig(a) = 1 + 0.02 * uni(g);
          f = rotation<D>(g) * sig.asDiagonal() * rotation<D>(g);
          t[i] = 260, u[i] = 0;
        } else if (kind == 1) {  // at the melting point, half melted
          ph[i] = (i / 3) % 2 ? AMPM_PHASE_LIQUID : AMPM_PHASE_SOLID;
          t[i] = kTm, u[i] = kLatent / 2;
          if (ph[i] == AMPM_PHASE_SOLID) {
            for (int a = 0; a < D; ++a) sig(a) = 1 + 0.02 * uni(g);
            f = rotation<D>(g) * sig.asDiagonal() * rotation<D>(g);
          }
        } else {  // water
          ph[i] = AMPM_PHASE_LIQUID;
          t[i] = 290, u[i] = kLatent;
        }
        break;
      case Scene::Snow:
        for (int a = 0; a < D; ++a) sig(a) = 1 + (uni(g) < 0 ? -0.025 : 0.0075) * std::fabs(uni(g));
        f = rotation<D>(g) * sig.asDiagonal() * rotation<D>(g);
        for (int a = 0; a < D; ++a) sig(a) = 1 + 0.05 * uni(g);
        p = rotation<D>(g) * sig.asDiagonal() * rotation<D>(g);
        break;
    }
    std::copy(f.data(), f.data() + D * D, fe.begin() + D * D * i);
    std::copy(p.data(), p.data() + D * D, fp.begin() + D * D * i);
  }
  // Shuffle, then sort by cell, x fastest, as a host does.
  std::vector<std::size_t> order(n);
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::shuffle(order.begin(), order.end(), g);
  std::vector<std::int64_t> key(n);
  for (std::size_t i = 0; i < n; ++i) {
    std::int64_t k = 0;
    for (int a = D - 1; a >= 0; --a) k = k * 4096 + static_cast<std::int64_t>(std::floor(x[D * i + a] / kH));
    key[i] = k;
  }
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return key[a] < key[b]; });
  Parts<T, D> p;
  p.n = n;
  p.x.resize(n * D), p.v.resize(n * D), p.c.resize(n * D * D), p.fe.resize(n * D * D), p.fp.resize(n * D * D);
  p.m.resize(n), p.v0.resize(n), p.t.resize(n), p.u.resize(n), p.ph.resize(n);
  double vol = 1;
  for (int a = 0; a < D; ++a) vol *= sp;
  for (std::size_t j = 0; j < n; ++j) {
    const std::size_t i = order[j];
    for (int a = 0; a < D; ++a) p.x[D * j + a] = static_cast<T>(x[D * i + a]), p.v[D * j + a] = static_cast<T>(v[D * i + a]);
    for (int k = 0; k < D * D; ++k) {
      p.c[D * D * j + k] = static_cast<T>(c[D * D * i + k]);
      p.fe[D * D * j + k] = static_cast<T>(fe[D * D * i + k]);
      p.fp[D * D * j + k] = static_cast<T>(fp[D * D * i + k]);
    }
    p.m[j] = static_cast<T>(kRho * vol), p.v0[j] = static_cast<T>(vol);
    p.t[j] = static_cast<T>(t[i]), p.u[j] = static_cast<T>(u[i]), p.ph[j] = ph[i];
  }
  return p;
}

// ---- the host's grid -----------------------------------------------------------------------

template <class T, int D>
struct Grid : ampm_test::DenseBox {
  std::vector<T> mass, hc, te, cond, tn, to;
  std::array<std::vector<T>, 3> mom, force, vel, mom2, du, df;

  void reset(const int* l, const int* h) {
    set_box(D, l, h);
    for (auto* f : {&mass, &hc, &te, &cond, &tn, &to}) f->assign(count, 0);
    for (int a = 0; a < 3; ++a)
      for (auto* f : {&mom[a], &force[a], &vel[a], &mom2[a], &du[a], &df[a]}) f->assign(count, 0);
  }
  template <class U = T>
  typename Api<U, D>::Channel out(std::vector<U>& f) const {
    typename Api<U, D>::Channel c;
    c.data = f.data();
    for (int a = 0; a < 3; ++a) c.stride[a] = stride(a);
    return c;
  }
  template <class U = T>
  typename Api<U, D>::ConstChannel in(const std::vector<U>& f) const {
    typename Api<U, D>::ConstChannel c;
    c.data = f.data();
    for (int a = 0; a < 3; ++a) c.stride[a] = stride(a);
    return c;
  }
  template <class U = T>
  static typename Api<U, D>::Channel none() {
    typename Api<U, D>::Channel c;
    c.data = nullptr;
    c.stride[0] = c.stride[1] = c.stride[2] = 0;
    return c;
  }
  void zero_p2g() {
    std::fill(mass.begin(), mass.end(), T(0));
    for (int a = 0; a < D; ++a) {
      std::fill(mom[a].begin(), mom[a].end(), T(0));
      std::fill(force[a].begin(), force[a].end(), T(0));
    }
    std::fill(hc.begin(), hc.end(), T(0));
    std::fill(te.begin(), te.end(), T(0));
    std::fill(cond.begin(), cond.end(), T(0));
  }
};

/// The views of a scene: P2G sym (impulse, no force), P2G +f, G2P, force.
template <class T, int D>
struct Views {
  typename Api<T, D>::P2gView sym{}, plus_f{};
  typename Api<T, D>::G2pView g2p{};
  typename Api<T, D>::ForceView force{};
};

template <class T, int D>
Views<T, D> make_views(Grid<T, D>& g, bool thermal) {
  Views<T, D> v;
  for (auto* pv : {&v.sym, &v.plus_f}) {
    pv->nodes = g.box();
    pv->mass = g.out(g.mass);
    for (int a = 0; a < 3; ++a) {
      pv->momentum[a] = a < D ? g.out(g.mom[a]) : Grid<T, D>::none();
      pv->force[a] = Grid<T, D>::none();
    }
    pv->heat_capacity = thermal ? g.out(g.hc) : Grid<T, D>::none();
    pv->thermal_energy = thermal ? g.out(g.te) : Grid<T, D>::none();
    pv->conductivity = thermal ? g.out(g.cond) : Grid<T, D>::none();
  }
  for (int a = 0; a < D; ++a) v.plus_f.force[a] = g.out(g.force[a]);
  v.g2p.nodes = g.box();
  for (int a = 0; a < 3; ++a) {
    v.g2p.velocity[a].data = a < D ? g.vel[a].data() : nullptr;
    for (int b = 0; b < 3; ++b) v.g2p.velocity[a].stride[b] = g.stride(b);
  }
  v.g2p.temperature = g.in(g.tn);
  v.g2p.temperature_old = g.in(g.to);
  v.force.nodes = g.box();
  for (int a = 0; a < 3; ++a) {
    v.force.du[a] = g.in(a < D ? g.du[a] : g.du[0]);
    v.force.df[a] = g.out(a < D ? g.df[a] : g.df[0]);
  }
  return v;
}

/// The host's grid update of the symplectic form: v = p/m; with heat T = E/C, the heat step
/// stand-in T^(n+1) = T^n + 0.5 K. `noinline` so the timed loop is this one.
template <class T, int D>
__attribute__((noinline)) void grid_update(Grid<T, D>& g, bool thermal) {
  const std::size_t n = g.count;
  const T* __restrict m = g.mass.data();
  for (int a = 0; a < D; ++a) {
    const T* __restrict p = g.mom[a].data();
    T* __restrict v = g.vel[a].data();
    for (std::size_t k = 0; k < n; ++k) v[k] = m[k] > 0 ? p[k] / m[k] : T(0);
  }
  if (thermal) {
    const T* __restrict c = g.hc.data();
    const T* __restrict e = g.te.data();
    T* __restrict tn = g.tn.data();
    T* __restrict to = g.to.data();
    for (std::size_t k = 0; k < n; ++k) {
      const T t = m[k] > 0 ? e[k] / c[k] : T(0);
      to[k] = t;
      tn[k] = t + T(0.5);
    }
  }
}

}  // namespace bench
