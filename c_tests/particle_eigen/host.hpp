// The host's side: node boxes and channels over dense arrays, reference node sums, the
// particles as SoA arrays the C ABI sees, the material as the C struct, and the node box of the
// reference stencils.
#pragma once

#include "reference.hpp"

namespace {

// ---- the host's grid -----------------------------------------------------------------------

/// A box of grid nodes [lo, lo + dims) and its dense x-fastest indexing.
template <int D>
struct Box {
  std::array<int, D> lo{}, dims{};
  std::size_t count() const {
    std::size_t c = 1;
    for (int a = 0; a < D; ++a) c *= static_cast<std::size_t>(dims[a]);
    return c;
  }
  std::ptrdiff_t stride(int a) const {
    std::ptrdiff_t s = 1;
    for (int b = 0; b < a; ++b) s *= dims[b];
    return s;
  }
  bool contains(const std::array<int, D>& i) const {
    for (int a = 0; a < D; ++a)
      if (i[a] < lo[a] || i[a] >= lo[a] + dims[a]) return false;
    return true;
  }
  std::size_t at(const std::array<int, D>& i) const {
    std::size_t k = 0;
    for (int a = D - 1; a >= 0; --a) k = k * dims[a] + static_cast<std::size_t>(i[a] - lo[a]);
    return k;
  }
  std::array<int, D> node(std::size_t k) const {
    std::array<int, D> i;
    for (int a = 0; a < D; ++a) {
      i[a] = lo[a] + static_cast<int>(k % dims[a]);
      k /= dims[a];
    }
    return i;
  }
  AmpmNodeBox c() const {
    AmpmNodeBox b{};
    for (int a = 0; a < 3; ++a) b.lo[a] = 0, b.dims[a] = 1;
    for (int a = 0; a < D; ++a) b.lo[a] = lo[a], b.dims[a] = dims[a];
    return b;
  }
};

/// A channel over separate x-fastest arrays of `box` (data NULL: absent).
template <class Ch, class P, int D>
Ch channel(P data, const Box<D>& box) {
  Ch c{};
  c.data = data;
  for (int a = 0; a < 3; ++a) c.stride[a] = a < D ? box.stride(a) : 0;
  return c;
}

/// Per node of a box, the reference sum and the sum of the magnitudes of its terms.
struct RefField {
  std::vector<ld> sum, scale;
  explicit RefField(std::size_t n = 0) : sum(n, 0), scale(n, 0) {}
  void add(std::size_t k, ld v, ld s) { sum[k] += v, scale[k] += s; }
};

// ---- SoA data as the C ABI sees it ---------------------------------------------------------

template <class T, int D>
struct Soa {
  std::vector<T> x, v, c, fe, fp, m, v0, t, u;
  std::vector<std::uint8_t> ph;

  void push(const RefParticle<D>& p) {
    for (int a = 0; a < D; ++a)
      x.push_back(static_cast<T>(p.x(a))), v.push_back(static_cast<T>(p.v(a)));
    for (int k = 0; k < D * D; ++k) {
      c.push_back(static_cast<T>(p.c.data()[k]));
      fe.push_back(static_cast<T>(p.fe.data()[k]));
      fp.push_back(static_cast<T>(p.fp.data()[k]));
    }
    m.push_back(static_cast<T>(p.m)), v0.push_back(static_cast<T>(p.v0));
    t.push_back(static_cast<T>(p.t)), u.push_back(static_cast<T>(p.u));
    ph.push_back(static_cast<std::uint8_t>(p.phase));
  }
  /// Particle i exactly as stored (so the reference sees the library's input).
  RefParticle<D> get(std::size_t i) const {
    RefParticle<D> p;
    for (int a = 0; a < D; ++a) p.x(a) = x[D * i + a], p.v(a) = v[D * i + a];
    for (int k = 0; k < D * D; ++k) {
      p.c.data()[k] = c[D * D * i + k];
      p.fe.data()[k] = fe[D * D * i + k];
      p.fp.data()[k] = fp[D * D * i + k];
    }
    p.m = m[i], p.v0 = v0[i], p.t = t[i], p.u = u[i], p.phase = ph[i];
    return p;
  }
  typename PartApi<T, D>::Particles ptrs() {
    return {x.data(), v.data(), c.data(), fe.data(), fp.data(), m.data(),
            v0.data(), t.data(), u.data(), ph.data()};
  }
};

template <class T, int D>
typename PartApi<T, D>::Material c_material(const RefMaterial& r) {
  typename PartApi<T, D>::Material m{};
  m.model = (r.plastic ? AMPM_MODEL_PLASTIC : 0) | (r.thermal ? AMPM_MODEL_THERMAL : 0) |
            (r.phase_change ? AMPM_MODEL_PHASE_CHANGE : 0) |
            (r.pressure_solve ? AMPM_MODEL_PRESSURE_SOLVE : 0);
  m.solid.mu = static_cast<T>(r.mu_s);
  m.solid.inv_lambda = static_cast<T>(r.il_s);
  m.solid.heat_capacity = static_cast<T>(r.c_s);
  m.solid.conductivity = static_cast<T>(r.k_s);
  m.liquid.mu = 0;
  m.liquid.inv_lambda = static_cast<T>(r.il_l);
  m.liquid.heat_capacity = static_cast<T>(r.c_l);
  m.liquid.conductivity = static_cast<T>(r.k_l);
  m.critical_compression = static_cast<T>(r.theta_c);
  m.critical_stretch = static_cast<T>(r.theta_s);
  m.hardening = static_cast<T>(r.xi);
  m.flip = static_cast<T>(r.flip);
  m.melting_point = static_cast<T>(r.tm);
  m.latent_heat = static_cast<T>(r.latent);
  return m;
}

/// The material's parameters rounded to T (what the library sees).
template <class T>
RefMaterial rounded(RefMaterial r) {
  for (ld* f : {&r.mu_s, &r.il_s, &r.c_s, &r.il_l, &r.c_l, &r.k_s, &r.k_l, &r.theta_c,
                &r.theta_s, &r.xi, &r.flip, &r.tm, &r.latent})
    *f = static_cast<T>(*f);
  return r;
}

/// The node box of the reference stencils of `soa`'s particles on `grid`.
template <class T, int D>
Box<D> ref_box(const Soa<T, D>& soa, std::size_t n, int kernel, int grid, ld h) {
  Box<D> b;
  std::array<int, D> hi;
  for (int a = 0; a < D; ++a) b.lo[a] = 1 << 30, hi[a] = -(1 << 30);
  for (std::size_t i = 0; i < n; ++i) {
    const RefStencil<D> s = ref_stencil<D>(kernel, grid, h, soa.get(i).x);
    for (int a = 0; a < D; ++a) {
      b.lo[a] = std::min(b.lo[a], s.base[a]);
      hi[a] = std::max(hi[a], s.base[a] + s.k - 1);
    }
  }
  for (int a = 0; a < D; ++a) b.dims[a] = hi[a] - b.lo[a] + 1;
  return b;
}

}  // namespace
