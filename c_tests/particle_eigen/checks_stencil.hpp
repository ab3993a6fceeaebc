// Checks of ampm_stencil_* (weights, gradients, base nodes) and ampm_node_range_* on the
// collocated grid and every MAC face grid.
#pragma once

#include "case.hpp"

namespace {

/// Stencils on every grid: weights and gradients; node ranges.
template <class T, int D>
void Case<T, D>::check_stencils() const {
  for (int grid = -1; grid < D; ++grid) {
    std::vector<int> base(n * D);
    std::vector<T> w(n * K), gw(n * K * D);
    std::size_t first = 999;
    AMPM_CHECK_STATUS(ck, (A::stencil(kernel, grid, h, n, soa.x.data(), base.data(), w.data(),
                                      gw.data(), &first)),
                      AMPM_OK);
    AMPM_CHECK(ck, first == n, "%s stencil: first_failed = %zu", A::name, first);
    for (std::size_t i = 0; i < n; ++i) {
      const RefStencil<D> s = ref_stencil<D>(kernel, grid, h, soa.get(i).x);
      for (int a = 0; a < D; ++a)
        AMPM_CHECK(ck, base[D * i + a] == s.base[a], "%s stencil base", A::name);
      for (int r = 0; r < K; ++r) {
        // x/h carries ε·|x/h| ≤ 12ε of rounding, amplified by |N'| ≤ 1 per axis.
        close("weight", i, w[K * i + r], s.w[r], 1 + 12 * D, C);
        for (int a = 0; a < D; ++a)
          close("grad weight", i, gw[(K * i + r) * D + a], s.grad[r](a), (1 + 12 * D) / h, C);
      }
    }
    const Box<D> want = ref_box<T, D>(soa, n, kernel, grid, h);
    int lo[3] = {7, 7, 7}, hi[3] = {7, 7, 7};
    first = 999;
    AMPM_CHECK_STATUS(ck, (A::node_range(kernel, grid, h, n, soa.x.data(), lo, hi, &first)),
                      AMPM_OK);
    AMPM_CHECK(ck, first == n, "%s node_range: first_failed = %zu", A::name, first);
    for (int a = 0; a < D; ++a)
      AMPM_CHECK(ck, lo[a] == want.lo[a] && hi[a] == want.lo[a] + want.dims[a] - 1,
                 "%s node_range grid %d axis %d: [%d, %d], want [%d, %d]", A::name, grid, a,
                 lo[a], hi[a], want.lo[a], want.lo[a] + want.dims[a] - 1);
  }
}

}  // namespace
