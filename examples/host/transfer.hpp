// Threaded particle transfers without atomics, following ampm.h's threads contract
// ("concurrent calls are safe when the nodes they write do not overlap"; G2P: "concurrent calls
// on disjoint particles are safe").
//
// Scatter (P2G, force differential): two-colour slabs. Each step the particles are sorted by
// cell (counting sort, last axis slowest), so the particles of a slab — W = 3 cell rows along
// the last axis — are contiguous. A particle in cell row c has its quadratic stencil in node
// rows c−1..c+2, so slab s writes node rows sW−1..sW+W+1, and slabs s and s+2 are disjoint as
// soon as W ≥ 3 (sW+W+1 < (s+2)W−1 ⇔ W > 2). All even slabs run at once (OpenMP, dynamic
// schedule), then all odd slabs; each call gets a view of its own rows of the one shared grid
// (the box ampm_node_range_* reports for the slab, checked disjoint from its same-colour
// neighbours). Why colouring rather than private grids plus a reduction: no extra grid memory
// and no reduction pass over every node, and the result is deterministic (every node's sum is
// taken in particle order, whatever the thread count); the price is one barrier between the
// colours and load imbalance when few slabs hold particles (a 2-core machine only needs 2).
//
// Gather (G2P, force prepare): disjoint particle ranges, one call per chunk.
#pragma once

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <vector>

#include "grid.hpp"
#include "particles.hpp"

namespace host {

/// The first failure of a threaded transfer: which call, which particle (global index).
struct Failure {
  AmpmStatus status = AMPM_OK;
  std::size_t particle = 0;
  const char* what = "";
  bool ok() const { return status == AMPM_OK; }
  void note(const ampm::BatchStatus& b, std::size_t begin, const char* w) {
    if (b.ok()) return;
#pragma omp critical(host_failure)
    if (status == AMPM_OK || begin + b.first_failed < particle)
      status = b.code(), particle = begin + b.first_failed, what = w;
  }
};

template <int D>
struct Slabs {
  static constexpr int W = 3;           // cell rows per slab (≥ 3, see above)
  std::vector<std::size_t> start;       // particles start[s] .. start[s+1] − 1 in slab s
  std::vector<int> lo, hi;              // node rows each slab writes
  int max_per_cell = 0;                 // most particles in one cell (for rounding bounds)

  /// Sorts `p` by cell and builds the slabs. Returns false if a particle is outside the grid.
  bool build(Particles<D>& p, const Grid<D>& g) {
    const int res = g.res;
    std::size_t cells = 1;
    for (int a = 0; a < D; ++a) cells *= static_cast<std::size_t>(res);
    std::vector<std::uint32_t> key(p.n), count(cells + 1, 0);
    for (std::size_t k = 0; k < p.n; ++k) {
      std::size_t id = 0;
      for (int a = D - 1; a >= 0; --a) {
        int c = static_cast<int>(p.x[D * k + a] / g.h);
        if (!(c >= 0 && c < res)) return false;
        id = id * static_cast<std::size_t>(res) + static_cast<std::size_t>(c);
      }
      key[k] = static_cast<std::uint32_t>(id);
      ++count[id + 1];
    }
    max_per_cell = 0;
    for (std::size_t c = 1; c <= cells; ++c) max_per_cell = std::max<int>(max_per_cell, count[c]);
    for (std::size_t c = 0; c < cells; ++c) count[c + 1] += count[c];
    std::vector<std::uint32_t> order(p.n);
    {
      std::vector<std::uint32_t> next(count.begin(), count.end() - 1);
      for (std::size_t k = 0; k < p.n; ++k) order[next[key[k]]++] = static_cast<std::uint32_t>(k);
    }
    p.permute(order);
    // Slab s: cell rows sW .. sW+W−1 along the last axis = cell ids [sW·R, (s+1)W·R).
    std::size_t row_cells = cells / static_cast<std::size_t>(res);
    const int ns = (res + W - 1) / W;
    start.assign(ns + 1, 0);
    for (int s = 0; s <= ns; ++s)
      start[s] = count[std::min<std::size_t>(cells, static_cast<std::size_t>(s) * W * row_cells)];
    lo.assign(ns, 0), hi.assign(ns, -1);
    return true;
  }

  int size() const { return static_cast<int>(start.size()) - 1; }

  /// Node rows of every non-empty slab (ampm_node_range_*), and the colouring check.
  Failure ranges(Particles<D>& p, const Grid<D>& g) {
    Failure f;
    int prev_hi[2] = {-1000000, -1000000};
    for (int s = 0; s < size(); ++s) {
      const std::size_t b = start[s], e = start[s + 1];
      if (b == e) continue;
      AmpmNodeBox nb{};
      f.note(ampm::node_range(kKernel, kGrid, g.h, p.view(b, e - b), nb), b, "node_range");
      if (!f.ok()) return f;
      for (int a = 0; a < D; ++a)
        if (nb.lo[a] < 0 || nb.lo[a] + nb.dims[a] > g.n[a]) {
          f.status = AMPM_ERR_OUTSIDE_GRID, f.particle = b, f.what = "slab outside the grid";
          return f;
        }
      lo[s] = nb.lo[D - 1], hi[s] = nb.lo[D - 1] + nb.dims[D - 1] - 1;
      if (lo[s] <= prev_hi[s % 2]) {  // cannot happen with W ≥ 3; a bug if it does
        std::fprintf(stderr, "slab %d rows %d..%d overlap a same-colour slab (..%d)\n", s, lo[s], hi[s],
                     prev_hi[s % 2]);
        f.status = AMPM_ERR_INTERNAL, f.what = "slab colouring";
        return f;
      }
      prev_hi[s % 2] = hi[s];
    }
    return f;
  }

  /// Runs `body(s, begin, end)` over the non-empty slabs, even colour first, then odd.
  template <class Body>
  void coloured(Body&& body) const {
    const int ns = size();
    for (int colour = 0; colour < 2; ++colour) {
#pragma omp parallel for schedule(dynamic, 1) if (parallel_particles(start.back()))
      for (int s = colour; s < ns; s += 2)
        if (start[s + 1] > start[s]) body(s, start[s], start[s + 1]);
    }
  }
};

/// Runs `body(begin, end)` over ~4 chunks per thread of [0, n) in parallel.
template <class Body>
void chunked(std::size_t n, Body&& body) {
  const std::size_t chunks = std::max<std::size_t>(1, std::min<std::size_t>(n / 64 + 1, 4 * threads()));
#pragma omp parallel for schedule(dynamic, 1) if (parallel_particles(n))
  for (std::size_t c = 0; c < chunks; ++c) {
    const std::size_t b = n * c / chunks, e = n * (c + 1) / chunks;
    if (e > b) body(b, e);
  }
}

/// P2G of every particle (slabs built), impulse form: momentum gets m v + impulse_dt·f.
template <int D>
Failure p2g(const Material& mat, Real impulse_dt, Particles<D>& p, Grid<D>& g, const Slabs<D>& sl,
            bool thermal) {
  Failure f;
  sl.coloured([&](int s, std::size_t b, std::size_t e) {
    const auto v = g.p2g_view(sl.lo[s], sl.hi[s], thermal);
    f.note(ampm::p2g(mat, kKernel, kGrid, g.h, impulse_dt, p.view(b, e - b), v), b, "p2g");
  });
  return f;
}

/// G2P and particle update of every particle.
template <int D>
Failure g2p(const Material& mat, Real dt, Particles<D>& p, const Grid<D>& g, bool thermal) {
  Failure f;
  const auto v = g.g2p_view(thermal);
  chunked(p.n, [&](std::size_t b, std::size_t e) {
    f.note(ampm::g2p_update(mat, kKernel, g.h, dt, p.view(b, e - b), v), b, "g2p_update");
  });
  return f;
}

/// ampm_force_prepare_* of every particle into `slots`.
template <int D>
Failure force_prepare(const Material& mat, Particles<D>& p, std::vector<Real>& slots) {
  Failure f;
  constexpr std::size_t L = ampm::force_slot_len<D>();
  slots.resize(p.n * L);
  chunked(p.n, [&](std::size_t b, std::size_t e) {
    f.note(ampm::force_prepare(mat, p.view(b, e - b), ampm::span<Real>(slots.data() + L * b, L * (e - b))), b,
           "force_prepare");
  });
  return f;
}

/// df = K du (the host zeroes df first), slab-coloured like P2G.
template <int D>
Failure force_apply(Particles<D>& p, const Grid<D>& g, const Slabs<D>& sl, const std::vector<Real>& slots,
                    const NodeField<D>& du, NodeField<D>& df) {
  Failure f;
  constexpr std::size_t L = ampm::force_slot_len<D>();
  sl.coloured([&](int s, std::size_t b, std::size_t e) {
    std::array<const Real*, D> u{};
    std::array<Real*, D> o{};
    for (int a = 0; a < D; ++a) u[a] = g.row(du[a], sl.lo[s]), o[a] = g.row(df[a], sl.lo[s]);
    const auto v = ampm::ForceView<Real, D>::separate(g.slab_box(sl.lo[s], sl.hi[s]), u, o);
    f.note(ampm::force_apply(kKernel, g.h, p.view(b, e - b), ampm::span<const Real>(slots.data() + L * b, L * (e - b)), v),
           b, "force_apply");
  });
  return f;
}

}  // namespace host
