// Checks of the force differential, ampm_force_prepare_* + ampm_force_apply_*: exact and
// NSD-projected node sums against the reference, du.df <= 0 per particle with the projection,
// and slots that no successful prepare wrote.
#pragma once

#include "case.hpp"

namespace {

/// The force view of `box` reading du from `du` and summing df into `df`.
template <class T, int D>
typename PartApi<T, D>::ForceView force_view(const std::vector<std::vector<T>>& du,
                                             std::vector<std::vector<T>>& df, const Box<D>& box) {
  using A = PartApi<T, D>;
  typename A::ForceView fv{};
  fv.nodes = box.c();
  for (int a = 0; a < D; ++a) {
    fv.du[a] = channel<typename A::ConstChannel>(du[a].data(), box);
    fv.df[a] = channel<typename A::Channel>(df[a].data(), box);
  }
  return fv;
}

/// Per particle (one-particle applies), random du on its stencil: du·df = G:M(G) ≤ 0
/// with the projection, to 256·ε of V⁰(μ + λ)·4·g_abs², g_abs = Σ_j |du_j||∇w_j|.
template <class T, int D>
void Case<T, D>::check_nsd_particles(const std::vector<T>& slots) {
  const std::size_t sl = A::slot_len;
  for (std::size_t i = 0; i < n; ++i) {
    const RefParticle<D> p = soa.get(i);
    const RefStencil<D> s = ref_stencil<D>(kernel, -1, h, p.x);
    const auto [mu, il] = moduli(mat, p);
    for (int trial = 0; trial < 4; ++trial) {
      std::vector<std::vector<T>> u(D, std::vector<T>(nn, 0)), f(D, std::vector<T>(nn, 0));
      ld gabs = 0;
      for (int r = 0; r < K; ++r) {
        const std::size_t k = box.at(s.node[r]);
        for (int a = 0; a < D; ++a) u[a][k] = static_cast<T>(rng.uniform(-1, 1));
        Vec uu;
        for (int a = 0; a < D; ++a) uu(a) = u[a][k];
        gabs += uu.norm() * s.grad[r].norm();
      }
      typename A::ForceView one = force_view(u, f, box);
      std::size_t f1 = 999;
      AMPM_CHECK_STATUS(ck, (A::apply(kernel, h, 1, soa.x.data() + D * i,
                                      slots.data() + sl * i, &one, &f1)),
                        AMPM_OK);
      ld dot = 0;
      for (int a = 0; a < D; ++a)
        for (std::size_t k = 0; k < nn; ++k)
          dot += static_cast<ld>(u[a][k]) * static_cast<ld>(f[a][k]);
      const ld tol = 256 * eps * p.v0 * (mu + 1 / il) * 4 * gabs * gabs;
      AMPM_CHECK(ck, dot <= tol, "%s NSD differential particle %zu: du.df = %.3Le > %.3Le",
                 A::name, i, dot, tol);
    }
  }
}

/// Prepare (exact, or with AMPM_MODEL_PSD_HESSIAN when `psd`) and apply(du) against the
/// reference node sums; with the projection, then check_nsd_particles.
template <class T, int D>
void Case<T, D>::check_force_apply(const Grids& du, bool psd) {
  const std::size_t sl = A::slot_len;
  auto cmat = cm;
  if (psd) cmat.model |= AMPM_MODEL_PSD_HESSIAN;
  std::vector<T> slots(n * sl, sentinel<T>());
  std::size_t first = 999;
  AMPM_CHECK_STATUS(ck, (A::prepare(&cmat, n, &ps, slots.data(), &first)), AMPM_OK);
  AMPM_CHECK(ck, first == n, "%s prepare: first_failed = %zu", A::name, first);
  std::vector<std::vector<T>> df(D, std::vector<T>(nn, 0));
  typename A::ForceView fv = force_view(du, df, box);
  first = 999;
  AMPM_CHECK_STATUS(ck, (A::apply(kernel, h, n, soa.x.data(), slots.data(), &fv, &first)),
                    AMPM_OK);
  AMPM_CHECK(ck, first == n, "%s apply: first_failed = %zu", A::name, first);
  std::vector<RefField> ref(D, RefField(nn));
  for (std::size_t i = 0; i < n; ++i) {
    const RefParticle<D> p = soa.get(i);
    const RefStencil<D> s = ref_stencil<D>(kernel, -1, h, p.x);
    MatL<D> g = MatL<D>::Zero();
    for (int r = 0; r < K; ++r) {
      Vec u;
      for (int a = 0; a < D; ++a) u(a) = du[a][box.at(s.node[r])];
      g += u * s.grad[r].transpose();
    }
    const auto [mu, il] = moduli(mat, p);
    const Reference<D> refp(mu > 0 ? mu : 1, p.fe);
    ld asym = 0;
    const MatL<D> mm = psd ? ref_dforce_nsd<D>(mat, p, &refp, g, &asym)
                           : ref_dforce<D>(mat, p, &refp, g);
    if (psd)  // the reference operator is symmetric to its own (long-double) rounding
      AMPM_CHECK(ck, asym <= 1e-12L, "%s reference operator asymmetry %.3Le", A::name, asym);
    for (int r = 0; r < K; ++r) {
      const Vec want = mm * s.grad[r];
      for (int a = 0; a < D; ++a)
        ref[a].add(box.at(s.node[r]), want(a), p.v0 * (mu + 1 / il) * g.norm() * 4 / h);
    }
  }
  for (int a = 0; a < D; ++a)
    for (std::size_t k = 0; k < nn; ++k)
      close(psd ? "force differential (NSD)" : "force differential", k, df[a][k],
               ref[a].sum[k], ref[a].scale[k], Sn);

  if (psd) check_nsd_particles(slots);
}

/// Slots that no successful prepare wrote: zero-filled memory, and the slot of a particle
/// whose prepare failed, are refused with AMPM_ERR_NOT_PREPARED; the other particles apply.
template <class T, int D>
void Case<T, D>::check_unprepared_slots(const Grids& du) const {
  const std::size_t sl = A::slot_len;
  std::vector<T> slots(n * sl, T(0));
  std::vector<std::vector<T>> df(D, std::vector<T>(nn, 0));
  typename A::ForceView fv = force_view(du, df, box);
  std::size_t first = 999;
  AMPM_CHECK_STATUS(ck, (A::apply(kernel, h, n, soa.x.data(), slots.data(), &fv, &first)),
                    AMPM_ERR_NOT_PREPARED);
  AMPM_CHECK(ck, first == 0, "%s apply of zero slots: first_failed = %zu", A::name, first);
  Soa<T, D> bad = soa;
  bad.fe[D * D * 2] = std::numeric_limits<T>::quiet_NaN();
  auto bp = bad.ptrs();
  first = 999;
  AMPM_CHECK_STATUS(ck, (A::prepare(&cm, n, &bp, slots.data(), &first)), AMPM_ERR_NON_FINITE);
  AMPM_CHECK(ck, first == 2, "%s prepare with NaN F_E: first_failed = %zu", A::name, first);
  first = 999;
  AMPM_CHECK_STATUS(ck, (A::apply(kernel, h, n, soa.x.data(), slots.data(), &fv, &first)),
                    AMPM_ERR_NOT_PREPARED);
  AMPM_CHECK(ck, first == 2, "%s apply after a failed prepare: first_failed = %zu", A::name,
             first);
  ld total = 0;
  for (int a = 0; a < D; ++a)
    for (T x : df[a]) total += std::fabs(static_cast<ld>(x));
  AMPM_CHECK(ck, total > 0, "%s apply after a failed prepare wrote nothing", A::name);
}

/// The force differential: du random on every node of the box; df = apply(du) after
/// prepare, exact Hessian and the NSD projection, against the reference node sums
/// Σ_p M_p(G_p) ∇w_ip.
template <class T, int D>
void Case<T, D>::check_force_differential() {
  std::vector<std::vector<T>> du(D, std::vector<T>(nn));
  for (auto& c : du)
    for (auto& x : c) x = static_cast<T>(rng.uniform(-1e-3, 1e-3));
  for (const bool psd : {false, true}) check_force_apply(du, psd);
  check_unprepared_slots(du);
}

}  // namespace
