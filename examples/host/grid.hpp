// The host's dense collocated grid: nodes i·h, 0 ≤ i_a ≤ res on each axis of a cube of side
// res·h, one std::vector per channel (x fastest), and the grid views the library reads and
// writes. A view may cover the whole grid or a slab of it (node rows lo..hi along the last
// axis): the slab view points its channels at the slab's first node, so the parallel P2G of
// transfer.hpp can give each thread its own disjoint slab of the same arrays.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "lib.hpp"

#ifdef _OPENMP
#include <omp.h>
#endif

namespace host {

/// Below these sizes a loop runs on one thread: a parallel region costs a barrier, and on a
/// loaded machine (more runnable threads than cores) a barrier can cost a whole time slice.
constexpr std::size_t kParallelParticles = 4096, kParallelNodes = 1u << 16;
inline bool parallel_particles(std::size_t n) { return n >= kParallelParticles; }
inline bool parallel_nodes(std::size_t n) { return n >= kParallelNodes; }

inline int threads() {
#ifdef _OPENMP
  return omp_get_max_threads();
#else
  return 1;
#endif
}


template <int D>
struct Grid {
  int res = 0;             // cells per axis
  Real h = 0;              // spacing (m)
  int n[3] = {1, 1, 1};    // nodes per axis (res + 1; 1 on an unused axis)
  std::size_t count = 0;   // nodes
  std::ptrdiff_t stride[3] = {0, 0, 0};

  // P2G channels.
  std::vector<Real> mass;              // kg
  std::array<std::vector<Real>, 3> mom;  // kg·m/s (with impulse_dt = Δt: m v + Δt f)
  std::vector<Real> hc, te, cond;      // J/K, J, kg·W/(m·K)
  // Grid update.
  std::array<std::vector<Real>, 3> vel;  // m/s, new node velocity
  std::vector<Real> t_old, t_new;        // K, node temperatures before/after the heat solve

  void init(int cells, Real spacing) {
    res = cells;
    h = spacing;
    count = 1;
    for (int a = 0; a < 3; ++a) {
      n[a] = a < D ? res + 1 : 1;
      count *= static_cast<std::size_t>(n[a]);
    }
    stride[0] = 1;
    stride[1] = n[0];
    stride[2] = static_cast<std::ptrdiff_t>(n[0]) * n[1];
    for (auto* f : {&mass, &hc, &te, &cond, &t_old, &t_new}) f->assign(count, 0);
    for (int a = 0; a < 3; ++a) {
      mom[a].assign(a < D ? count : 0, 0);
      vel[a].assign(a < D ? count : 0, 0);
    }
  }

  /// Zeroes the P2G channels (the library scatter-adds).
  void clear(bool thermal) {
    std::fill(mass.begin(), mass.end(), Real(0));
    for (int a = 0; a < D; ++a) std::fill(mom[a].begin(), mom[a].end(), Real(0));
    if (thermal)
      for (auto* f : {&hc, &te, &cond}) std::fill(f->begin(), f->end(), Real(0));
  }

  std::size_t index(const int* i) const {
    std::size_t k = 0;
    for (int a = D - 1; a >= 0; --a) k = k * static_cast<std::size_t>(n[a]) + static_cast<std::size_t>(i[a]);
    return k;
  }
  void coords(std::size_t k, int* i) const {
    for (int a = 0; a < D; ++a) {
      i[a] = static_cast<int>(k % static_cast<std::size_t>(n[a]));
      k /= static_cast<std::size_t>(n[a]);
    }
  }

  /// The node box of node rows lo..hi (inclusive) along the last axis, whole along the others.
  AmpmNodeBox slab_box(int lo, int hi) const {
    std::array<std::int32_t, D> l{}, d{};
    for (int a = 0; a < D; ++a) d[a] = n[a];
    l[D - 1] = lo, d[D - 1] = hi - lo + 1;
    return ampm::node_box<D>(l, d);
  }
  AmpmNodeBox box() const { return slab_box(0, n[D - 1] - 1); }

  /// Address of node row `lo` of a field (a slab view's channels start there; a slab's strides
  /// are the whole grid's, {1, nx, nx·ny}, since it is whole along the other axes).
  Real* row(std::vector<Real>& f, int lo) const { return f.data() + static_cast<std::ptrdiff_t>(lo) * stride[D - 1]; }
  const Real* row(const std::vector<Real>& f, int lo) const {
    return f.data() + static_cast<std::ptrdiff_t>(lo) * stride[D - 1];
  }

  /// P2G view of rows lo..hi: mass, momentum, and the heat channels when `thermal`.
  ampm::P2gView<Real, D> p2g_view(int lo, int hi, bool thermal) {
    std::array<Real*, D> m{};
    for (int a = 0; a < D; ++a) m[a] = row(mom[a], lo);
    auto v = ampm::P2gView<Real, D>::separate(slab_box(lo, hi), row(mass, lo), m);
    if (thermal) v.heat_capacity(row(hc, lo)).thermal_energy(row(te, lo)).conductivity(row(cond, lo));
    return v;
  }

  /// G2P view of the whole grid: new velocities and, when `thermal`, T^(n+1) and T^n.
  ampm::G2pView<Real, D> g2p_view(bool thermal) const {
    std::array<const Real*, D> v{};
    for (int a = 0; a < D; ++a) v[a] = vel[a].data();
    return ampm::G2pView<Real, D>::separate(box(), v, thermal ? t_new.data() : nullptr,
                                            thermal ? t_old.data() : nullptr);
  }
};

/// A vector field over the grid nodes (D components), for the implicit solver.
template <int D>
using NodeField = std::array<std::vector<Real>, D>;

}  // namespace host
