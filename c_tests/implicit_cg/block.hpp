// The host's data: its particles, its grid, one step's stencils and prepared slots, the
// material, and the elastic block the test steps.
#pragma once

#include "common.hpp"
#include "dense_box.hpp"

#include <algorithm>
#include <array>
#include <vector>

namespace {

using ampm_test::Checker;
using ampm_test::ld;
using ampm_test::log_uniform_sigma;
using ampm_test::MatL;
using ampm_test::random_f_with_sigma;
using ampm_test::Reference;
using ampm_test::Rng;
using ampm_test::status_name;

template <class T>
using Api3 = ampm_test::PartApi<T, 3>;

constexpr int D = 3;
constexpr int K1 = 3;   // quadratic: 3 nodes per axis
constexpr int KD = 27;  // stencil nodes
constexpr std::size_t SL = AMPM_FORCE_SLOT_LEN_3D;
constexpr std::uint64_t kSeed = 0xc9a3'b1e0'2013'0402ULL;

using Vec3L = Eigen::Matrix<ld, 3, 1>;
using Mat9L = Eigen::Matrix<ld, 9, 9>;

/// The host's particles (SoA, the C layout).
template <class T>
struct Parts {
  std::size_t n = 0;
  std::vector<T> x, v, c, fe, fp, m, v0;
  typename Api3<T>::Particles view() {
    return {x.data(), v.data(), c.data(), fe.data(), fp.data(), m.data(), v0.data(),
            nullptr, nullptr, nullptr};
  }
};

/// The host's grid: a node box and dense x-fastest arrays.
template <class T>
struct Grid : ampm_test::DenseBox {
  std::vector<T> mass;
  std::array<std::vector<T>, 3> mom, force, vstar;
  void reset(const int* l, const int* h) {
    set_box(3, l, h);
    mass.assign(count, 0);
    for (int a = 0; a < 3; ++a)
      mom[a].assign(count, 0), force[a].assign(count, 0), vstar[a].assign(count, 0);
  }
  std::size_t at(const int* i) const {
    return static_cast<std::size_t>(i[0] - lo[0]) +
           dims[0] * (static_cast<std::size_t>(i[1] - lo[1]) +
                      dims[1] * static_cast<std::size_t>(i[2] - lo[2]));
  }
  typename Api3<T>::Channel out(T* p) const {
    typename Api3<T>::Channel c;
    c.data = p;
    for (int a = 0; a < 3; ++a) c.stride[a] = stride(a);
    return c;
  }
  typename Api3<T>::ConstChannel in(const T* p) const {
    typename Api3<T>::ConstChannel c;
    c.data = p;
    for (int a = 0; a < 3; ++a) c.stride[a] = stride(a);
    return c;
  }
};

using Field = std::array<std::vector<ld>, 3>;  // a host vector over the box, long double

template <class T>
struct Setup {
  ld mu = 2e4, lambda = 3e4, rho = 1000, h = 0.1;
  int per_axis = 8;
};

template <class T>
typename Api3<T>::Material material(const Setup<T>& s, bool psd) {
  typename Api3<T>::Material m{};
  m.model = psd ? AMPM_MODEL_PSD_HESSIAN : 0;
  m.solid.mu = static_cast<T>(s.mu);
  m.solid.inv_lambda = static_cast<T>(1 / s.lambda);
  m.solid.heat_capacity = 1;
  m.liquid.inv_lambda = static_cast<T>(1 / s.lambda);
  m.liquid.heat_capacity = 1;
  return m;
}

/// Everything the host computes about one step's grid and stencils.
template <class T>
struct Step {
  Grid<T> g;
  std::vector<int> base;
  std::vector<T> w, gw;            // weights and gradients (ampm_stencil)
  std::vector<std::size_t> nodes;  // linear grid index of stencil node r of particle i, [27 i + r]
  std::vector<ld> gnorm;           // |∇w_ip| at [27 i + r]
  std::vector<char> active;
  int n_add = 0;
  std::vector<T> slots;      // prepared (PSD or exact, see prepare())
  std::vector<ld> s_norm;    // ‖S_p‖_F
  std::vector<Mat9L> s_mat;  // S_p
};

/// A block of per_axis³ particles at spacing h/2, F_E with singular values log-uniform in
/// [0.85, 1.15] between Haar rotations (the exact Hessian is indefinite for many of them), a
/// rotation plus a random part of the velocity.
template <class T>
void make_block(const Setup<T>& s, Parts<T>& p, Rng& rng) {
  const int na = s.per_axis;
  p.n = static_cast<std::size_t>(na) * na * na;
  p.x.assign(3 * p.n, 0), p.v.assign(3 * p.n, 0), p.c.assign(9 * p.n, 0);
  p.fe.assign(9 * p.n, 0), p.fp.assign(9 * p.n, 0), p.m.assign(p.n, 0), p.v0.assign(p.n, 0);
  const ld sp = s.h / 2;
  for (std::size_t i = 0; i < p.n; ++i) {
    const int idx[3] = {static_cast<int>(i % na), static_cast<int>((i / na) % na),
                        static_cast<int>(i / (na * na))};
    Vec3L r;
    for (int a = 0; a < 3; ++a) {
      const ld x = 0.2L + sp * (idx[a] + 0.5L) + 0.2L * sp * rng.uniform(-1, 1);
      p.x[3 * i + a] = static_cast<T>(x);
      r(a) = x - (0.2L + sp * na / 2);
    }
    const Vec3L om(0.5L, -1.0L, 0.7L);
    const Vec3L v = om.cross(r);
    for (int a = 0; a < 3; ++a)
      p.v[3 * i + a] = static_cast<T>(v(a) + 0.05L * rng.uniform(-1, 1));
    const MatL<3> fe = random_f_with_sigma<3>(rng, log_uniform_sigma<3>(rng, 0.85, 1.15));
    for (int k = 0; k < 9; ++k) p.fe[9 * i + k] = static_cast<T>(fe.data()[k]);
    for (int a = 0; a < 3; ++a) p.fp[9 * i + 4 * a] = 1;
    p.v0[i] = static_cast<T>(sp * sp * sp);
    p.m[i] = static_cast<T>(s.rho * sp * sp * sp);
  }
}

}  // namespace
