// The solver: Host::cg, CG preconditioned by the node masses on the backward-Euler system,
// with its iteration bound and the bound on the gap between its recursive and true residuals.
#pragma once

#include "implicit_cg/host.hpp"

namespace {

template <class T>
int Host<T>::cg(const Step<T>& st, T dt, ld tol, std::array<std::vector<T>, 3>& v,
                const char* what) {
  const std::size_t nc = st.g.count;
  const auto& m = st.g.mass;
  std::array<std::vector<T>, 3> b, r, z, pd, ap;
  for (int a = 0; a < 3; ++a) {
    b[a].assign(nc, 0);
    v[a] = st.g.vstar[a];
    for (std::size_t k = 0; k < nc; ++k) b[a][k] = st.active[k] ? m[k] * st.g.vstar[a][k] : T(0);
  }
  auto mdot = [&](const std::array<std::vector<T>, 3>& x, const std::array<std::vector<T>, 3>& y) {
    ld s = 0;
    for (int a = 0; a < 3; ++a)
      for (std::size_t k = 0; k < nc; ++k)
        if (st.active[k]) s += static_cast<ld>(x[a][k]) * y[a][k];
    return s;
  };
  auto inv_m_norm = [&](const std::array<std::vector<T>, 3>& x) {  // ‖x‖_(M⁻¹)
    ld s = 0;
    for (int a = 0; a < 3; ++a)
      for (std::size_t k = 0; k < nc; ++k)
        if (st.active[k]) s += static_cast<ld>(x[a][k]) * x[a][k] / m[k];
    return std::sqrt(s);
  };
  op(st, dt, v, ap);
  for (int a = 0; a < 3; ++a) {
    r[a].assign(nc, 0), z[a].assign(nc, 0);
    for (std::size_t k = 0; k < nc; ++k)
      if (st.active[k]) r[a][k] = b[a][k] - ap[a][k], z[a][k] = r[a][k] / m[k];
  }
  pd = z;
  ld rz = mdot(r, z);
  const ld bn = inv_m_norm(b), r0 = inv_m_norm(r);
  const ld kappa = kappa_bound(st, dt);
  const int k_max = static_cast<int>(
      std::ceil(0.5L * std::sqrt(kappa) *
                std::log(std::max<ld>(2 * std::sqrt(kappa) * r0 / (tol * bn), 1))));
  // The gap between the recursive residual r_k and the true b − A v_k grows by the rounding
  // of each iteration's updates (Greenbaum 1997): in the M⁻¹ norm at most
  // ε (c_g ‖σ(α p)‖ + ‖r‖ + ‖α A p‖ + 2‖σ(v)‖), σ(u)_i = m_i|u_i| + Δt² Σ_p ‖S_p‖_F g_p(u)
  // |∇w_ip| the node scale of (A u)_i's rounding (c_g·ε relative, see the comment of
  // test_implicit_cg.cpp).
  const ld eps = std::numeric_limits<T>::epsilon();
  const ld c_g = 2 * (st.n_add + KD + 8 * D + 8);
  auto sigma_norm = [&](const std::array<std::vector<T>, 3>& u, ld scale) {
    const std::vector<ld> gu = gabs(st, u);
    std::vector<ld> sig(nc, 0);
    for (std::size_t k = 0; k < nc; ++k)
      if (st.active[k]) sig[k] = static_cast<ld>(m[k]) * Vec3L(u[0][k], u[1][k], u[2][k]).norm();
    const ld dt2 = static_cast<ld>(dt) * dt;
    for (std::size_t i = 0; i < p_.n; ++i)
      for (int r2 = 0; r2 < KD; ++r2)
        sig[node(st, i, r2)] += dt2 * st.s_norm[i] * gu[i] * st.gnorm[KD * i + r2];
    ld q = 0;
    for (std::size_t k = 0; k < nc; ++k)
      if (st.active[k]) q += sig[k] * sig[k] / m[k];
    return std::fabs(scale) * std::sqrt(q);
  };
  ld gap = c_g * eps * sigma_norm(v, 1);
  int it = 0;
  while (inv_m_norm(r) > tol * bn && it < 4 * k_max + 10) {
    op(st, dt, pd, ap);
    const ld alpha = rz / mdot(pd, ap);
    gap += eps * (c_g * sigma_norm(pd, alpha) + inv_m_norm(r) + std::fabs(alpha) * inv_m_norm(ap));
    for (int a = 0; a < 3; ++a)
      for (std::size_t k = 0; k < nc; ++k)
        if (st.active[k]) {
          v[a][k] += static_cast<T>(alpha * pd[a][k]);
          r[a][k] -= static_cast<T>(alpha * ap[a][k]);
          z[a][k] = r[a][k] / m[k];
        }
    gap += 2 * eps * sigma_norm(v, 1);
    const ld rz_new = mdot(r, z);
    const ld beta = rz_new / rz;
    rz = rz_new;
    for (int a = 0; a < 3; ++a)
      for (std::size_t k = 0; k < nc; ++k)
        if (st.active[k]) pd[a][k] = static_cast<T>(z[a][k] + beta * pd[a][k]);
    ++it;
  }
  // The true residual with a fresh apply (its own rounding is in `gap`'s first term).
  op(st, dt, v, ap);
  std::array<std::vector<T>, 3> res;
  for (int a = 0; a < 3; ++a) {
    res[a].assign(nc, 0);
    for (std::size_t k = 0; k < nc; ++k)
      if (st.active[k]) res[a][k] = static_cast<T>(static_cast<ld>(b[a][k]) - ap[a][k]);
  }
  const ld rel = inv_m_norm(res) / bn;
  std::printf("  %s %s: CG %d iterations (bound %d, κ ≤ %.3Lg), relative residual %.3Le "
              "(tol %.0Le, rounding gap ≤ %.2Le)\n",
              A::name, what, it, k_max, kappa, rel, tol, gap / bn);
  AMPM_CHECK(ck_, it <= k_max, "%s %s: CG took %d iterations, bound %d", A::name, what, it,
             k_max);
  AMPM_CHECK(ck_, rel <= tol + gap / bn, "%s %s: true relative residual %.3Le > %.3Le", A::name,
             what, rel, tol + gap / bn);
  return it;
}

}  // namespace
