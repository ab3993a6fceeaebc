// The host's particles, structure of arrays in the C layout (ampm.h, AmpmParticles): vector k
// at [D·k + a], matrix k column-major at [D²·k + i + D·j], scalars at [k]. `view(begin)` points
// the library at particles begin.. (a contiguous range: what each thread of transfer.hpp
// passes), `permute` reorders every array (the sort by cell of transfer.hpp).
#pragma once

#include <cstdint>
#include <vector>

#include "lib.hpp"

namespace host {

template <int D>
struct Particles {
  std::size_t n = 0;
  std::vector<Real> x, v, c, fe, fp, m, v0, t, u;
  std::vector<std::uint8_t> ph;

  void resize(std::size_t k) {
    n = k;
    x.assign(k * D, 0), v.assign(k * D, 0), c.assign(k * D * D, 0);
    fe.assign(k * D * D, 0), fp.assign(k * D * D, 0);
    m.assign(k, 0), v0.assign(k, 0), t.assign(k, 0), u.assign(k, 0);
    ph.assign(k, AMPM_PHASE_SOLID);
  }

  /// Appends a particle at rest, F_E = F_P = I, solid, at temperature `temp`.
  void add(const Real* pos, const Real* vel, Real mass, Real vol, Real temp) {
    for (int a = 0; a < D; ++a) x.push_back(pos[a]), v.push_back(vel[a]);
    for (int i = 0; i < D * D; ++i) {
      const Real id = (i % (D + 1) == 0) ? 1 : 0;
      c.push_back(0), fe.push_back(id), fp.push_back(id);
    }
    m.push_back(mass), v0.push_back(vol), t.push_back(temp), u.push_back(0);
    ph.push_back(AMPM_PHASE_SOLID);
    ++n;
  }

  /// The library's view of particles [begin, begin + count) (size-checked spans, then a slice).
  ampm::Particles<Real, D> view(std::size_t begin, std::size_t count) {
    ampm::Particles<Real, D> all(n);
    all.x(ampm::span<Real>(x)).v(ampm::span<Real>(v)).affine(ampm::span<Real>(c));
    all.f_e(ampm::span<Real>(fe)).f_p(ampm::span<Real>(fp));
    all.mass(ampm::span<const Real>(m)).volume0(ampm::span<const Real>(v0));
    all.temperature(ampm::span<Real>(t)).latent(ampm::span<Real>(u)).phase(ampm::span<unsigned char>(ph));
    return all.slice(begin, count);
  }
  ampm::Particles<Real, D> view() { return view(0, n); }

  /// Reorders every array: new particle k is old particle order[k].
  void permute(const std::vector<std::uint32_t>& order) {
    gather(x, order, D), gather(v, order, D), gather(c, order, D * D);
    gather(fe, order, D * D), gather(fp, order, D * D);
    gather(m, order, 1), gather(v0, order, 1), gather(t, order, 1), gather(u, order, 1);
    std::vector<std::uint8_t> tmp(ph.size());
    for (std::size_t k = 0; k < order.size(); ++k) tmp[k] = ph[order[k]];
    ph.swap(tmp);
  }

  static Real det(const Real* f) {
    if (D == 2) return f[0] * f[3] - f[2] * f[1];
    return f[0] * (f[4] * f[8] - f[7] * f[5]) - f[3] * (f[1] * f[8] - f[7] * f[2]) +
           f[6] * (f[1] * f[5] - f[4] * f[2]);
  }
  Real j_e(std::size_t k) const { return det(&fe[D * D * k]); }
  Real j_p(std::size_t k) const { return det(&fp[D * D * k]); }

 private:
  static void gather(std::vector<Real>& f, const std::vector<std::uint32_t>& order, int w) {
    std::vector<Real> tmp(f.size());
    for (std::size_t k = 0; k < order.size(); ++k)
      for (int j = 0; j < w; ++j) tmp[w * k + j] = f[w * static_cast<std::size_t>(order[k]) + j];
    f.swap(tmp);
  }
};

}  // namespace host
