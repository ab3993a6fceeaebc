// The node box of a host's dense grid (header only, no Eigen): nodes lo..hi per axis as
// ampm_node_range_* returns them, stored x fastest; a 2D box has one node along axis 2.
#pragma once

#include <cstddef>

#include "ampm.h"

namespace ampm_test {

/// Lower corner, nodes per axis and node count of a dense x-fastest box.
struct DenseBox {
  int lo[3] = {0, 0, 0}, dims[3] = {1, 1, 1};
  std::size_t count = 1;

  /// The box of nodes `l..h` (inclusive) along the first `d` axes, one node along the others.
  void set_box(int d, const int* l, const int* h) {
    count = 1;
    for (int a = 0; a < 3; ++a) {
      lo[a] = a < d ? l[a] : 0;
      dims[a] = a < d ? h[a] - l[a] + 1 : 1;
      count *= static_cast<std::size_t>(dims[a]);
    }
  }
  /// Stride (in elements) of axis `a` in an array of `count` nodes.
  std::ptrdiff_t stride(int a) const {
    return a == 0 ? 1 : a == 1 ? dims[0] : static_cast<std::ptrdiff_t>(dims[0]) * dims[1];
  }
  /// The box as the C ABI's view describes it.
  AmpmNodeBox box() const {
    AmpmNodeBox b;
    for (int a = 0; a < 3; ++a) b.lo[a] = lo[a], b.dims[a] = dims[a];
    return b;
  }
};

}  // namespace ampm_test
