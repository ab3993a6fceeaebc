// The hand-written Eigen baseline of the elastic step (P2G sym and G2P as a host writes them)
// and its long-double reference.
#pragma once

#include "host.hpp"

namespace bench {

// ---- the Eigen baseline --------------------------------------------------------------------

#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif

/// Kirchhoff stress τ = Â F_Eᵀ + λ(J − 1)J I of the augmented fixed corotated energy, as a host
/// writes it: one Eigen::JacobiSVD for R; Â Fᵀ = dev(A F̂ᵀ) with F̂ = J^(−1/d) F, A = 2μ(F̂ − R).
template <class T, int D>
Eigen::Matrix<T, D, D> eigen_tau(T mu, T lambda, const Eigen::Matrix<T, D, D>& f) {
  using M = Eigen::Matrix<T, D, D>;
  const T j = f.determinant();
  const T ja = D == 2 ? T(1) / std::sqrt(j) : T(1) / std::cbrt(j);
  const Eigen::JacobiSVD<M> svd(f, Eigen::ComputeFullU | Eigen::ComputeFullV);
  M u = svd.matrixU(), v = svd.matrixV();
  if (u.determinant() < 0) u.col(D - 1) = -u.col(D - 1);
  if (v.determinant() < 0) v.col(D - 1) = -v.col(D - 1);
  const M fh = ja * f;
  const M x = T(2) * mu * (fh - u * v.transpose()) * fh.transpose();
  M tau = x - (x.trace() / T(D)) * M::Identity();
  tau.diagonal().array() += lambda * (j - T(1)) * j;
  return tau;
}

/// Quadratic B-spline weights and derivatives (1/h) along one axis at fx ∈ [0.5, 1.5).
template <class T>
inline void bspline(T fx, T inv_h, T* w, T* dw) {
  const T a = T(1.5) - fx, b = fx - T(1), c = fx - T(0.5);
  w[0] = T(0.5) * a * a, w[1] = T(0.75) - b * b, w[2] = T(0.5) * c * c;
  dw[0] = -a * inv_h, dw[1] = T(-2) * b * inv_h, dw[2] = c * inv_h;
}

/// Magnitudes of a reference P2G (long double only): per node, the sums of |terms|.
struct Mags {
  std::vector<ld> mass;
  std::array<std::vector<ld>, 3> mom;
};

/// P2G sym of the elastic scene by hand: mass, APIC momentum + Δt f. Eigen for the per-particle
/// matrices, plain arrays in the node loop (GCC 12 spills Eigen's fixed 3-vectors through the
/// stack there, which costs a store-forwarding stall per node). With `mags` (the long-double
/// reference) also the per-node magnitudes.
/// Stencil node `r` (axis 0 fastest) of per-axis weights `w`, `dw`: its offsets `o` from the
/// base node, weight `wt`, weight gradient `gr` and grid index (`k0` the index of the base node,
/// `st` the strides).
template <class T, int D>
inline std::ptrdiff_t stencil_node(int r, const T (&w)[D][K1], const T (&dw)[D][K1], std::ptrdiff_t k0,
                                   const std::ptrdiff_t* st, int (&o)[D], T& wt, T (&gr)[D]) {
  for (int a = 0, q = r; a < D; ++a, q /= K1) o[a] = q % K1;
  wt = 1;
  std::ptrdiff_t k = k0;
  for (int a = 0; a < D; ++a) {
    wt *= w[a][o[a]];
    k += o[a] * st[a];
    T ga = dw[a][o[a]];
    for (int b = 0; b < D; ++b)
      if (b != a) ga *= w[b][o[b]];
    gr[a] = ga;
  }
  return k;
}

template <class T, int D>
__attribute__((noinline)) void eigen_p2g(const Parts<T, D>& p, Grid<T, D>& g, T h, T dt, T mu, T lambda,
                                         Mags* mags) {
  using M = Eigen::Matrix<T, D, D>;
  constexpr int KD = D == 2 ? 9 : 27;
  const T inv_h = T(1) / h;
  T* mom[D];
  for (int a = 0; a < D; ++a) mom[a] = g.mom[a].data();
  T* mass = g.mass.data();
  const std::ptrdiff_t st[3] = {1, g.dims[0], static_cast<std::ptrdiff_t>(g.dims[0]) * g.dims[1]};
  for (std::size_t i = 0; i < p.n; ++i) {
    const M f = Eigen::Map<const M>(&p.fe[D * D * i]);
    const M fm = (-p.v0[i] * dt) * eigen_tau<T, D>(mu, lambda, f);  // Δt·(−V⁰ τ)
    const T m = p.m[i];
    const M mch = (m * h) * Eigen::Map<const M>(&p.c[D * D * i]);  // m C h: momentum per unit offset
    int base[D];
    T fx[D], w[D][3], dw[D][3], q0[D];
    std::ptrdiff_t k0 = 0;
    for (int a = 0; a < D; ++a) {
      const T xi = p.x[D * i + a] * inv_h;
      base[a] = static_cast<int>(std::floor(xi - T(0.5)));
      fx[a] = xi - T(base[a]);
      bspline(fx[a], inv_h, w[a], dw[a]);
      k0 += (base[a] - g.lo[a]) * st[a];
    }
    for (int a = 0; a < D; ++a) {  // m v − m C h fx: the momentum density at offset 0
      T c = 0;
      for (int b = 0; b < D; ++b) c += mch(a, b) * fx[b];
      q0[a] = m * p.v[D * i + a] - c;
    }
    for (int r = 0; r < KD; ++r) {
      int o[D];
      T wt, gr[D];
      const std::ptrdiff_t k = stencil_node<T, D>(r, w, dw, k0, st, o, wt, gr);
      mass[k] += wt * m;
      for (int a = 0; a < D; ++a) {
        T q = q0[a], f = 0;
        for (int b = 0; b < D; ++b) q += mch(a, b) * T(o[b]), f += fm(a, b) * gr[b];
        mom[a][k] += wt * q + f;
      }
      if (mags) {
        mags->mass[k] += std::fabs(static_cast<ld>(wt * m));
        const ld ts = static_cast<ld>(fm.norm()) + static_cast<ld>(p.v0[i] * dt) * static_cast<ld>(mu + lambda);
        ld gn = 0;
        for (int a = 0; a < D; ++a) gn += static_cast<ld>(gr[a]) * gr[a];
        for (int a = 0; a < D; ++a) {
          ld cs = 0;
          for (int b = 0; b < D; ++b) cs += std::fabs(static_cast<ld>(p.c[D * D * i + a + D * b]));
          mags->mom[a][k] += std::fabs(static_cast<ld>(wt * m)) * (std::fabs(static_cast<ld>(p.v[D * i + a])) + cs * 3.5L * static_cast<ld>(h)) +
                             ts * std::sqrt(gn);
        }
      }
    }
  }
}

/// G2P and the elastic update by hand (no remedy: the steps here never invert a particle);
/// plain arrays in the node loop as in eigen_p2g.
template <class T, int D>
__attribute__((noinline)) void eigen_g2p(Parts<T, D>& p, const Grid<T, D>& g, T h, T dt) {
  using M = Eigen::Matrix<T, D, D>;
  constexpr int KD = D == 2 ? 9 : 27;
  const T inv_h = T(1) / h, inv_kh = T(4) / h;  // C = (Σ w v oᵀ − v fxᵀ)/(κ h), κ = 1/4
  const T* vel[D];
  for (int a = 0; a < D; ++a) vel[a] = g.vel[a].data();
  const std::ptrdiff_t st[3] = {1, g.dims[0], static_cast<std::ptrdiff_t>(g.dims[0]) * g.dims[1]};
  for (std::size_t i = 0; i < p.n; ++i) {
    int base[D];
    T fx[D], w[D][3], dw[D][3];
    std::ptrdiff_t k0 = 0;
    for (int a = 0; a < D; ++a) {
      const T xi = p.x[D * i + a] * inv_h;
      base[a] = static_cast<int>(std::floor(xi - T(0.5)));
      fx[a] = xi - T(base[a]);
      bspline(fx[a], inv_h, w[a], dw[a]);
      k0 += (base[a] - g.lo[a]) * st[a];
    }
    T v[D] = {}, so[D][D] = {}, gv[D][D] = {};
    for (int r = 0; r < KD; ++r) {
      int o[D];
      T wt, gr[D];
      const std::ptrdiff_t k = stencil_node<T, D>(r, w, dw, k0, st, o, wt, gr);
      for (int a = 0; a < D; ++a) {
        const T vi = vel[a][k], wv = wt * vi;
        v[a] += wv;
        for (int b = 0; b < D; ++b) so[a][b] += wv * T(o[b]), gv[a][b] += vi * gr[b];
      }
    }
    M gradv, c;
    for (int a = 0; a < D; ++a)
      for (int b = 0; b < D; ++b) gradv(a, b) = gv[a][b], c(a, b) = (so[a][b] - v[a] * fx[b]) * inv_kh;
    for (int a = 0; a < D; ++a) p.v[D * i + a] = v[a], p.x[D * i + a] += dt * v[a];
    Eigen::Map<M>(&p.c[D * D * i]) = c;
    Eigen::Map<M> f(&p.fe[D * D * i]);
    f = (M::Identity() + dt * gradv) * f;
  }
}

#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic pop
#endif

}  // namespace bench
