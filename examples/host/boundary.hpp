// Grid update: node velocities from the P2G momentum (impulse form, so m v + Δt f is already
// summed), gravity, and the walls of the box.
//
// Walls: the `margin` outermost node layers of each face of the cube are inside a wall. A
// node inside a wall has its velocity constrained: STICKY zeroes all of it (the material
// sticks), SLIP zeroes only the normal component and only when it points into the wall
// (frictionless, separating: the material may leave the wall). The constraint is a diagonal
// projection per node and axis, which the implicit solver also uses (its unknowns are the free
// components; see implicit.hpp).
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "grid.hpp"

namespace host {

enum class Wall : std::uint8_t { Open, Slip, Sticky };

struct Walls {
  int margin = 3;                 // node layers inside each wall
  Wall lower[3] = {Wall::Slip, Wall::Slip, Wall::Slip};  // x = 0, y = 0 (the floor), z = 0
  Wall upper[3] = {Wall::Slip, Wall::Slip, Wall::Slip};  // x = L, y = L (ceiling), z = L
};

/// v_i = mom_i/m_i + Δt g on the nodes with mass (0 elsewhere).
template <int D>
void velocities(Grid<D>& g, Real dt, const Real* gravity) {
#pragma omp parallel for schedule(static) if (parallel_nodes(g.count))
  for (std::ptrdiff_t k = 0; k < static_cast<std::ptrdiff_t>(g.count); ++k) {
    const Real m = g.mass[k];
    for (int a = 0; a < D; ++a) g.vel[a][k] = m > 0 ? g.mom[a][k] / m + dt * gravity[a] : Real(0);
  }
}

/// The constrained components of node k's velocity v (bit a set: component a is fixed to 0).
template <int D>
unsigned constrained(const Grid<D>& g, const Walls& w, std::size_t k, const Real* v) {
  int i[3] = {0, 0, 0};
  g.coords(k, i);
  unsigned fixed = 0;
  for (int a = 0; a < D; ++a) {
    const bool low = i[a] < w.margin, high = i[a] > g.res - w.margin;
    const Wall kind = low ? w.lower[a] : high ? w.upper[a] : Wall::Open;
    if (kind == Wall::Sticky) return (1u << D) - 1;
    if (kind == Wall::Slip && ((low && v[a] < 0) || (high && v[a] > 0))) fixed |= 1u << a;
  }
  return fixed;
}

/// Applies the walls to g.vel; writes each node's constraint bits to `mask` (if not null).
/// Returns true when some node with mass was constrained (the material touches a wall).
template <int D>
bool apply_walls(Grid<D>& g, const Walls& w, std::vector<std::uint8_t>* mask) {
  if (mask) mask->assign(g.count, 0);
  bool touched = false;
#pragma omp parallel for schedule(static) reduction(|| : touched) if (parallel_nodes(g.count))
  for (std::ptrdiff_t k = 0; k < static_cast<std::ptrdiff_t>(g.count); ++k) {
    if (!(g.mass[k] > 0)) continue;
    Real v[3] = {0, 0, 0};
    for (int a = 0; a < D; ++a) v[a] = g.vel[a][k];
    const unsigned fixed = constrained<D>(g, w, static_cast<std::size_t>(k), v);
    if (!fixed) continue;
    touched = true;
    for (int a = 0; a < D; ++a)
      if (fixed & (1u << a)) g.vel[a][k] = 0;
    if (mask) (*mask)[k] = static_cast<std::uint8_t>(fixed);
  }
  return touched;
}

}  // namespace host
