// The host's side of the C ABI: the C symbols by (scalar, dimension), its particles (SoA, the
// C layout) and its grid over a node box, and determinants of the deformation gradients.
#pragma once

#include <cstddef>
#include <cstdint>

#include "ampm.h"
#include "dense_box.hpp"

#include <vector>

namespace {

using ld = long double;

// ---- the C symbols by (scalar, dimension) --------------------------------------------------

template <class T, int D>
struct Api;

#define HOST_API(T, D, S)                                             \
  template <>                                                         \
  struct Api<T, D> {                                                  \
    static constexpr const char* name = #D "D " #S;                   \
    static constexpr auto p2g = ampm_p2g_##D##d_##S;                  \
    static constexpr auto g2p = ampm_g2p_update_##D##d_##S;           \
    static constexpr auto node_range = ampm_node_range_##D##d_##S;    \
    static constexpr auto stencil = ampm_stencil_##D##d_##S;          \
    using Material = AmpmMaterial_##S;                                \
    using Particles = AmpmParticles_##S;                              \
    using Channel = AmpmChannel_##S;                                  \
    using ConstChannel = AmpmConstChannel_##S;                        \
    using P2gView = AmpmP2gView_##S;                                  \
    using G2pView = AmpmG2pView_##S;                                  \
  };
HOST_API(float, 2, f32)
HOST_API(float, 3, f32)
HOST_API(double, 2, f64)
HOST_API(double, 3, f64)
#undef HOST_API

constexpr int K1 = 3;  // quadratic B-spline: 3 nodes per axis

template <int D>
constexpr int stencil_nodes() {
  return D == 2 ? K1 * K1 : K1 * K1 * K1;
}

// ---- the host's data -----------------------------------------------------------------------

template <class T, int D>
struct Particles {
  std::size_t n = 0;
  std::vector<T> x, v, c, fe, fp, m, v0, t, u;
  std::vector<std::uint8_t> ph;
  void resize(std::size_t k) {
    n = k;
    x.assign(k * D, 0), v.assign(k * D, 0), c.assign(k * D * D, 0);
    fe.assign(k * D * D, 0), fp.assign(k * D * D, 0);
    m.assign(k, 0), v0.assign(k, 0), t.assign(k, 0), u.assign(k, 0);
    ph.assign(k, AMPM_PHASE_SOLID);
  }
  typename Api<T, D>::Particles view() {
    return {x.data(), v.data(), c.data(), fe.data(), fp.data(), m.data(),
            v0.data(), t.data(), u.data(), ph.data()};
  }
};

/// The host's grid over a node box, dense arrays, x fastest.
template <class T, int D>
struct Grid : ampm_test::DenseBox {
  std::vector<T> mass, hc, te, cond, tnew, told;
  std::vector<T> mom[3], force[3], vel[3], mom2[3];

  void reset(const int* l, const int* h) {
    set_box(D, l, h);
    for (auto* f : {&mass, &hc, &te, &cond, &tnew, &told}) f->assign(count, 0);
    for (int a = 0; a < 3; ++a)
      for (auto* f : {&mom[a], &force[a], &vel[a], &mom2[a]}) f->assign(count, 0);
  }
  typename Api<T, D>::Channel out(std::vector<T>& f) const {
    typename Api<T, D>::Channel c;
    c.data = f.data();
    for (int a = 0; a < 3; ++a) c.stride[a] = stride(a);
    return c;
  }
  typename Api<T, D>::ConstChannel in(const std::vector<T>& f) const {
    typename Api<T, D>::ConstChannel c;
    c.data = f.data();
    for (int a = 0; a < 3; ++a) c.stride[a] = stride(a);
    return c;
  }
  static typename Api<T, D>::Channel none() {
    typename Api<T, D>::Channel c;
    c.data = nullptr;
    for (int a = 0; a < 3; ++a) c.stride[a] = 0;
    return c;
  }
  /// Linear index of grid node `i` (must be inside the box).
  std::size_t at(const int* i) const {
    std::size_t k = 0;
    for (int a = D - 1; a >= 0; --a) k = k * dims[a] + static_cast<std::size_t>(i[a] - lo[a]);
    return k;
  }
  void node(std::size_t k, int* i) const {
    for (int a = 0; a < D; ++a) {
      i[a] = lo[a] + static_cast<int>(k % static_cast<std::size_t>(dims[a]));
      k /= static_cast<std::size_t>(dims[a]);
    }
  }
};

template <class T>
T det2(const T* f) {
  return f[0] * f[3] - f[2] * f[1];
}
template <class T>
T det3(const T* f) {  // column-major f[i + 3j]
  return f[0] * (f[4] * f[8] - f[7] * f[5]) - f[3] * (f[1] * f[8] - f[7] * f[2]) +
         f[6] * (f[1] * f[5] - f[4] * f[2]);
}
template <class T, int D>
T det(const T* f) {
  return D == 2 ? det2(f) : det3(f);
}

}  // namespace
