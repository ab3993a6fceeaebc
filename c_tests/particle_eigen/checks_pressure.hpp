// Checks of ampm_pressure_*: the pressure and the coefficient of the pressure solve of every
// particle.
#pragma once

#include "case.hpp"

namespace {

/// Pressure and coefficient of every particle against the reference.
template <class T, int D>
void Case<T, D>::check_pressure() const {
  std::vector<T> pr(n, sentinel<T>()), co(n, sentinel<T>());
  std::size_t first = 999;
  AMPM_CHECK_STATUS(ck, (A::pressure(&cm, dt, n, &ps, pr.data(), co.data(), &first)), AMPM_OK);
  for (std::size_t i = 0; i < n; ++i) {
    const RefParticle<D> p = soa.get(i);
    const auto [mu, il] = moduli(mat, p);
    (void)mu;
    const ld je = p.fe.determinant(), jp = p.fp.determinant();
    close("pressure", i, pr[i], -(je - 1) / (il * jp), 1 / il, C);
    close("coefficient", i, co[i], jp * il / (dt * je), il / dt, C);
  }
}

}  // namespace
