// The checks of the operator A = M − Δt² K: symmetric and positive definite with the PSD
// option on random vectors, and the exact Hessian's apply against central differences of the
// force it linearises.
#pragma once

#include "implicit_cg/host.hpp"

namespace {

/// ⟨u, A w⟩ = ⟨w, A u⟩ and ⟨u, A u⟩ ≥ ⟨u, M u⟩ up to c_g·ε of their scales, for 6 random
/// pairs u, w on the active nodes of `st` (prepared with the PSD option).
template <class T>
void check_symmetric_definite(Checker& ck, Host<T>& host, const Parts<T>& p, const Step<T>& st,
                              T dt, ld c_g, Rng& rng) {
  using A = Api3<T>;
  const ld eps = std::numeric_limits<T>::epsilon();
  const std::size_t nc = st.g.count;
  for (int trial = 0; trial < 6; ++trial) {
    std::array<std::vector<T>, 3> u, w, au, aw;
    for (int a = 0; a < 3; ++a) {
      u[a].assign(nc, 0), w[a].assign(nc, 0);
      for (std::size_t k = 0; k < nc; ++k)
        if (st.active[k])
          u[a][k] = static_cast<T>(rng.uniform(-1, 1)),
          w[a][k] = static_cast<T>(rng.uniform(-1, 1));
    }
    host.op(st, dt, u, au);
    host.op(st, dt, w, aw);
    ld uaw = 0, wau = 0, uau = 0, umu = 0, mass_term = 0, mass_uu = 0;
    for (int a = 0; a < 3; ++a)
      for (std::size_t k = 0; k < nc; ++k) {
        uaw += static_cast<ld>(u[a][k]) * aw[a][k];
        wau += static_cast<ld>(w[a][k]) * au[a][k];
        uau += static_cast<ld>(u[a][k]) * au[a][k];
        umu += static_cast<ld>(st.g.mass[k]) * u[a][k] * u[a][k];
        mass_term += std::fabs(static_cast<ld>(st.g.mass[k]) * u[a][k] * w[a][k]);
        mass_uu += std::fabs(static_cast<ld>(st.g.mass[k]) * u[a][k] * u[a][k]);
      }
    const std::vector<ld> gu = host.gabs(st, u), gw = host.gabs(st, w);
    ld stiff = 0, stiff_uu = 0;
    for (std::size_t i = 0; i < p.n; ++i)
      stiff += st.s_norm[i] * gu[i] * gw[i], stiff_uu += st.s_norm[i] * gu[i] * gu[i];
    const ld dt2 = static_cast<ld>(dt) * dt;
    const ld tol_sym = c_g * eps * (mass_term + dt2 * stiff);
    AMPM_CHECK(ck, std::fabs(uaw - wau) <= tol_sym,
               "%s: <u,Aw> = %.15Le, <w,Au> = %.15Le (tol %.3Le)", A::name, uaw, wau, tol_sym);
    const ld tol_pd = c_g * eps * (mass_uu + dt2 * stiff_uu);
    AMPM_CHECK(ck, uau - umu >= -tol_pd, "%s: <u,Au> − <u,Mu> = %.6Le < 0 (tol %.3Le)", A::name,
               uau - umu, tol_pd);
    AMPM_CHECK(ck, uau > 0, "%s: <u,Au> = %.6Le not positive", A::name, uau);
  }
}

/// The function the differential linearises, evaluated by the host: the energy gradient at
/// x̂ = x + δ du, f_i(δ) = −V⁰ P((I + δG) F_E) F_Eᵀ ∇w_i (F_E in the transposed factor stays the
/// prepared one; implicit.rs, Stomakhin et al. 2013 eq. 6–7), which is symmetric in du. P2G of
/// a particle whose F_E is replaced by F' = (I + δG) F_E returns −V⁰ τ' ∇w_i with
/// τ' = P(F') F'ᵀ, so the host recovers τ' from a one-particle P2G (τ' = −(1/V⁰) Σ_i f_i
/// (x_i − x_p)ᵀ, since Σ_i ∇w_i (x_i − x_p)ᵀ = I) and assembles
/// f_i(δ) = Σ_p −V⁰ τ'_p (I + δ G_p)⁻ᵀ ∇w_ip in long double. (The P2G force itself,
/// f_i = −V⁰ τ' ∇w_i, differs at first order by the geometric term −V⁰ τ Gᵀ ∇w_i, which is
/// not symmetric in du; its size is printed.)
template <class T>
struct PerturbedForce {
  using A = Api3<T>;
  Checker& ck;
  const Setup<T>& s;
  const Parts<T>& p;
  const Host<T>& host;
  const Step<T>& st;
  std::vector<MatL<3>> g;            // G_p = Σ_j du_j ∇w_jpᵀ
  std::array<std::vector<T>, 3> fs;  // one particle's stencil: the P2G force channels

  /// τ' of particle i of q (p with F_E perturbed), from a one-particle P2G.
  MatL<3> tau_of(Parts<T>& q, std::size_t i) {
    typename A::P2gView one{};
    for (int a = 0; a < 3; ++a) {
      one.nodes.lo[a] = st.base[3 * i + a], one.nodes.dims[a] = K1;
      std::fill(fs[a].begin(), fs[a].end(), T(0));
      one.force[a].data = fs[a].data();
      one.force[a].stride[0] = 1, one.force[a].stride[1] = K1, one.force[a].stride[2] = K1 * K1;
    }
    typename A::Particles pi = q.view();
    pi.x += 3 * i, pi.v += 3 * i, pi.affine += 9 * i, pi.f_e += 9 * i, pi.f_p += 9 * i,
        pi.mass += i, pi.volume0 += i;
    const auto mat = material(s, false);
    std::size_t ff = 0;
    AMPM_CHECK_STATUS(ck,
                      A::p2g(&mat, AMPM_KERNEL_QUADRATIC, AMPM_GRID_COLLOCATED, host.h(), T(0), 1,
                             &pi, &one, &ff),
                      AMPM_OK);
    MatL<3> tau = MatL<3>::Zero();
    for (int r = 0; r < KD; ++r)
      tau -= Vec3L(fs[0][r], fs[1][r], fs[2][r]) * host.dx(st, i, r).transpose() /
             static_cast<ld>(p.v0[i]);
    return tau;
  }

  /// energy: the energy gradient f(d); raw: the P2G force −V⁰ τ' ∇w_i, at F_E → (I + d G) F_E.
  void at(ld d, Field& energy, Field& raw) {
    const std::size_t nc = st.g.count;
    Parts<T> q = p;
    for (std::size_t i = 0; i < p.n; ++i) {
      MatL<3> fe;
      for (int k = 0; k < 9; ++k) fe.data()[k] = p.fe[9 * i + k];
      const MatL<3> f2 = (MatL<3>::Identity() + d * g[i]) * fe;
      for (int k = 0; k < 9; ++k) q.fe[9 * i + k] = static_cast<T>(f2.data()[k]);
    }
    for (int a = 0; a < 3; ++a) energy[a].assign(nc, 0), raw[a].assign(nc, 0);
    for (std::size_t i = 0; i < p.n; ++i) {
      const MatL<3> tau = tau_of(q, i);
      const MatL<3> m_energy = -static_cast<ld>(p.v0[i]) * tau *
                               (MatL<3>::Identity() + d * g[i]).inverse().transpose();
      const MatL<3> m_raw = -static_cast<ld>(p.v0[i]) * tau;
      for (int r = 0; r < KD; ++r) {
        const std::size_t k = host.node(st, i, r);
        const Vec3L fe = m_energy * host.grad(st, i, r), fr = m_raw * host.grad(st, i, r);
        for (int a = 0; a < 3; ++a) energy[a][k] += fe(a), raw[a][k] += fr(a);
      }
    }
  }
};

/// G_p = Σ_j du_j ∇w_jpᵀ of every particle, and gmax = max_p ‖G_p‖.
template <class T>
std::vector<MatL<3>> strain_directions(const Host<T>& host, const Parts<T>& p, const Step<T>& st,
                                       const std::array<std::vector<T>, 3>& du, ld& gmax) {
  std::vector<MatL<3>> g(p.n);
  gmax = 0;
  for (std::size_t i = 0; i < p.n; ++i) {
    g[i].setZero();
    for (int r = 0; r < KD; ++r) {
      const std::size_t k = host.node(st, i, r);
      g[i] += Vec3L(du[0][k], du[1][k], du[2][k]) * host.grad(st, i, r).transpose();
    }
    gmax = std::max(gmax, g[i].norm());
  }
  return g;
}

/// The linearisation (exact Hessian, no projection) against central differences of the force
/// it linearises (see PerturbedForce), at strains δ·‖G‖ = (c_τ ε)^(1/3)·2^j, j = 0..3, with
/// the bound of test_implicit_cg.cpp's comment.
template <class T>
void check_linearisation(Checker& ck, const Setup<T>& s, const Parts<T>& p, Host<T>& host,
                         const Step<T>& st, ld c_g, Rng& rng) {
  using A = Api3<T>;
  const ld eps = std::numeric_limits<T>::epsilon();
  const std::size_t nc = st.g.count;
  Step<T> ex = st;
  host.prepare(ex, false);
  std::array<std::vector<T>, 3> du, df;
  for (int a = 0; a < 3; ++a) {
    du[a].assign(nc, 0), df[a].assign(nc, 0);
    for (std::size_t k = 0; k < nc; ++k)
      if (st.active[k]) du[a][k] = static_cast<T>(rng.uniform(-1, 1) * 1e-3);
  }
  host.apply(ex, du, df);
  // G_p and the perturbed P2G forces.
  ld gmax = 0;
  PerturbedForce<T> force{ck, s, p, host, st, strain_directions(host, p, st, du, gmax), {}};
  // δ: a strain δ·‖G‖ = (c_τ ε)^(1/3), balancing the O(δ²) truncation and the c_τ·ε/δ
  // rounding of the central difference (c_τ = 256 + 2√d·A_K: the stress's rounding and the
  // recovery's sum over 27 nodes).
  const ld c_tau = 256 + 2 * std::sqrt(ld(D)) * KD;
  const ld delta = std::cbrt(c_tau * eps) / gmax;
  for (int a = 0; a < 3; ++a) force.fs[a].assign(KD, 0);
  // Node scales of the rounding.
  std::vector<ld> phi(nc, 0), psi(nc, 0);
  const std::vector<ld> gd = host.gabs(ex, du);
  for (std::size_t i = 0; i < p.n; ++i)
    for (int r = 0; r < KD; ++r) {
      const std::size_t k = host.node(st, i, r);
      const ld gn = host.grad(st, i, r).norm();
      phi[k] += static_cast<ld>(p.v0[i]) * 3 * (s.mu + s.lambda) * gn;
      psi[k] += ex.s_norm[i] * gd[i] * gn;
    }
  // Forces at ±δ·2^j, j = 0..4; FD_j = FD(δ·2^j) is checked against its own bound for
  // j = 0..3 (each bound is valid; the smallest says how sharp the check is).
  constexpr int J = 5;
  std::array<Field, J> fp, fm, rp, rm;
  for (int j = 0; j < J; ++j)
    force.at(std::ldexp(delta, j), fp[j], rp[j]), force.at(-std::ldexp(delta, j), fm[j], rm[j]);
  ld ref = 0;
  for (int a = 0; a < 3; ++a)
    for (std::size_t k = 0; k < nc; ++k) ref += static_cast<ld>(df[a][k]) * df[a][k];
  ref = std::sqrt(ref);
  ld best = std::numeric_limits<ld>::infinity();
  for (int j = 0; j + 1 < J; ++j) {
    const ld dj = std::ldexp(delta, j);
    ld err = 0, rich = 0, rnd = 0, raw_err = 0;
    for (int a = 0; a < 3; ++a)
      for (std::size_t k = 0; k < nc; ++k) {
        const ld fd1 = (fp[j][a][k] - fm[j][a][k]) / (2 * dj);
        const ld fd2 = (fp[j + 1][a][k] - fm[j + 1][a][k]) / (4 * dj);
        const ld raw1 = (rp[j][a][k] - rm[j][a][k]) / (2 * dj);
        err += (fd1 - df[a][k]) * (fd1 - df[a][k]);
        raw_err += (raw1 - df[a][k]) * (raw1 - df[a][k]);
        rich += (fd2 - fd1) * (fd2 - fd1);
        const ld rb = c_tau * eps * phi[k] / dj + c_g * eps * psi[k];
        rnd += rb * rb;
      }
    err = std::sqrt(err), rich = std::sqrt(rich), rnd = std::sqrt(rnd);
    raw_err = std::sqrt(raw_err);
    const ld bound = 2 * rich / 3 + rnd;
    best = std::min(best, bound);
    std::printf("  %s: linearisation, strain %.2Le: ‖FD − apply‖ = %.3Le (‖apply‖ = %.3Le; "
                "bound %.3Le = truncation %.3Le + rounding %.3Le); FD of the P2G force itself: "
                "%.3Le off (geometric term −V⁰ τ Gᵀ ∇w)\n",
                A::name, dj * gmax, err, ref, bound, 2 * rich / 3, rnd, raw_err);
    AMPM_CHECK(ck, err <= bound, "%s: linearisation error %.3Le > %.3Le at strain %.2Le", A::name,
               err, bound, dj * gmax);
  }
  const ld bound = best;
  AMPM_CHECK(ck, bound < 0.05L * ref,
             "%s: the FD bound %.3Le is no test against ‖apply‖ = %.3Le", A::name, bound, ref);
}

}  // namespace
