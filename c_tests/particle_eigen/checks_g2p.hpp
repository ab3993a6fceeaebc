// Checks of ampm_g2p_update_* and ampm_g2p_update_mac_*: the grid they read, the particle
// update against the reference, and the batch contract (failed particles, non-finite nodes,
// whole-call errors).
#pragma once

#include "case.hpp"
#include "update.hpp"

namespace {

/// The grid G2P reads: collocated velocities and temperatures, MAC face velocities, and the
/// views over them.
///
/// Node velocities random in [−1, 1]; on the nodes of the last particle's stencils the field
/// v = (−a x, 0, …) with a·Δt = 3, so det(I + Δt∇v) = −2 and the remedy must act. Node
/// temperatures T^(n+1) random in [265, 285], T^n within 2 K of them. Nodes that no stencil
/// reaches hold NaN: the library must not read them.
template <class T, int D>
struct G2pNodes {
  using A = PartApi<T, D>;
  using CCh = typename A::ConstChannel;

  std::vector<std::vector<T>> vel;         // collocated velocities
  std::vector<T> tn, to;                   // collocated temperatures T^(n+1), T^n
  std::vector<Box<D>> fbox;                // MAC face boxes
  std::vector<std::vector<T>> fvel;        // MAC face velocities
  typename A::G2pView gv{};                // the collocated view
  std::vector<typename A::G2pView> faces;  // the MAC face views
  typename A::G2pView thermal{};           // the temperatures of the MAC call

  explicit G2pNodes(Case<T, D>& cs) {
    Rng& rng = cs.rng;
    const int kernel = cs.kernel, K = cs.K;
    const T h = cs.h, dt = cs.dt;
    const std::size_t n = cs.n, nn = cs.nn;
    const Soa<T, D>& soa = cs.soa;
    const Box<D>& box = cs.box;
    const ld nan = std::numeric_limits<ld>::quiet_NaN();
    const ld a_rem = 3.0L / dt;
    // Collocated velocities and temperatures.
    vel.assign(D, std::vector<T>(nn, static_cast<T>(nan)));
    tn.assign(nn, static_cast<T>(nan)), to.assign(nn, static_cast<T>(nan));
    std::vector<char> reached(nn, 0), remedy(nn, 0);
    for (std::size_t i = 0; i < n; ++i) {
      const RefStencil<D> s = ref_stencil<D>(kernel, -1, h, soa.get(i).x);
      for (int r = 0; r < K; ++r) {
        reached[box.at(s.node[r])] = 1;
        if (i == n - 1) remedy[box.at(s.node[r])] = 1;
      }
    }
    for (std::size_t k = 0; k < nn; ++k) {
      if (!reached[k]) continue;
      for (int a = 0; a < D; ++a) vel[a][k] = static_cast<T>(rng.uniform(-1, 1));
      if (remedy[k]) {
        vel[0][k] = static_cast<T>(-a_rem * box.node(k)[0] * static_cast<ld>(h));
        for (int a = 1; a < D; ++a) vel[a][k] = 0;
      }
      tn[k] = static_cast<T>(rng.uniform(265, 285));
      to[k] = static_cast<T>(tn[k] - rng.uniform(-2, 2));
    }
    // MAC face velocities, each on its own face box, the same construction.
    fbox.resize(D);
    fvel.resize(D);
    for (int g = 0; g < D; ++g) {
      fbox[g] = ref_box<T, D>(soa, n, kernel, g, h);
      for (int a = 0; a < D; ++a) fbox[g].lo[a] -= 1, fbox[g].dims[a] += 2;
      fvel[g].assign(fbox[g].count(), static_cast<T>(nan));
      for (std::size_t i = 0; i < n; ++i) {
        const RefStencil<D> s = ref_stencil<D>(kernel, g, h, soa.get(i).x);
        for (int r = 0; r < K; ++r) {
          const std::size_t k = fbox[g].at(s.node[r]);
          if (i == n - 1)
            fvel[g][k] =
                g == 0 ? static_cast<T>(-a_rem * s.node[r][0] * static_cast<ld>(h)) : T(0);
          else
            fvel[g][k] = static_cast<T>(rng.uniform(-1, 1));
        }
      }
    }

    gv.nodes = box.c();
    for (int a = 0; a < D; ++a)
      gv.velocity[a] = channel<CCh>(static_cast<const T*>(vel[a].data()), box);
    gv.temperature = channel<CCh>(static_cast<const T*>(tn.data()), box);
    gv.temperature_old = channel<CCh>(static_cast<const T*>(to.data()), box);
    faces.resize(D);
    for (int g = 0; g < D; ++g) {
      faces[g] = typename A::G2pView{};
      faces[g].nodes = fbox[g].c();
      faces[g].velocity[g] = channel<CCh>(static_cast<const T*>(fvel[g].data()), fbox[g]);
    }
    thermal.nodes = box.c();
    thermal.temperature = gv.temperature;
    thermal.temperature_old = gv.temperature_old;
  }
  G2pNodes(const G2pNodes&) = delete;
  G2pNodes& operator=(const G2pNodes&) = delete;
};

/// G2P and the particle update (collocated, or MAC when `mac`) from `before` against the
/// reference update.
template <class T, int D>
void Case<T, D>::check_g2p_update(const G2pNodes<T, D>& nodes, const Soa<T, D>& before,
                                  bool mac) {
  const auto& vel = nodes.vel;
  const auto& tn = nodes.tn;
  const auto& to = nodes.to;
  const auto& fbox = nodes.fbox;
  const auto& fvel = nodes.fvel;
  const auto& gv = nodes.gv;
  const auto& faces = nodes.faces;
  const auto& thermal = nodes.thermal;
  soa = before;
  ps = soa.ptrs();
  std::size_t first = 999;
  if (mac)
    AMPM_CHECK_STATUS(ck, (A::g2p_mac(&cm, kernel, h, dt, n, &ps, faces.data(), &thermal,
                                      &first)),
                      AMPM_OK);
  else
    AMPM_CHECK_STATUS(ck, (A::g2p(&cm, kernel, h, dt, n, &ps, &gv, &first)), AMPM_OK);
  AMPM_CHECK(ck, first == n, "%s g2p (mac %d): first_failed = %zu", A::name, int(mac), first);
  const char* what = mac ? "MAC" : "collocated";
  for (std::size_t i = 0; i < n; ++i) {
    const RefParticle<D> in = before.get(i);
    RefSample<D> smp;
    const ld kap = kernel == AMPM_KERNEL_QUADRATIC ? 0.25L : 1.0L / 3.0L;
    for (int c = 0; c < D; ++c) {
      const RefStencil<D> s = ref_stencil<D>(kernel, mac ? c : -1, h, in.x);
      for (int r = 0; r < K; ++r) {
        const ld q = mac ? static_cast<ld>(fvel[c][fbox[c].at(s.node[r])])
                         : static_cast<ld>(vel[c][box.at(s.node[r])]);
        smp.v(c) += s.w[r] * q;
        smp.c.row(c) += s.w[r] * q * s.dx[r].transpose() / (kap * h * h);
        smp.gv.row(c) += q * s.grad[r].transpose();
      }
    }
    const RefStencil<D> s = ref_stencil<D>(kernel, -1, h, in.x);
    for (int r = 0; r < K; ++r) {
      const std::size_t k = box.at(s.node[r]);
      smp.t_pic += s.w[r] * tn[k];
      smp.t_flip += s.w[r] * (static_cast<ld>(tn[k]) - to[k]);
    }
    const RefParticle<D> want = ref_update<D>(mat, dt, in, smp);
    const RefParticle<D> got = soa.get(i);
    AMPM_CHECK(ck, got.phase == want.phase, "%s %s particle %zu: phase %d, want %d", A::name,
               what, i, got.phase, want.phase);
    const ld vs = 1 + (i == n - 1 ? 3 / dt * 4 : 0);
    for (int a = 0; a < D; ++a) {
      close("v", i, got.v(a), want.v(a), vs, C);
      close("x", i, got.x(a), want.x(a), 6 + dt * vs, C);
    }
    close("affine", i, (got.c - want.c).norm(), 0, vs / h, C);
    close("F_E", i, (got.fe - want.fe).norm(), 0, 1, C);
    close("F_P", i, (got.fp - want.fp).norm(), 0, 1, C);
    AMPM_CHECK(ck, got.fe.determinant() > 0 && got.fp.determinant() > 0,
               "%s %s particle %zu: J_E or J_P <= 0", A::name, what, i);
    if (got.phase == 1) {
      const MatL<D> off = got.fp - got.fp.trace() / D * MatL<D>::Identity();
      AMPM_CHECK(ck, off.norm() == 0, "%s %s liquid particle %zu: F_P not a multiple of I",
                 A::name, what, i);
    }
    close("temperature", i, got.t, want.t, 300, C);
    close("latent", i, got.u, want.u, 100, C);
    // J = J_E J_P changes by det(I + Δt∇v) only: away from the remedy ≈ 1 + O(Δt|∇v|).
    const ld j_in = in.fe.determinant() * in.fp.determinant();
    const ld j_out = got.fe.determinant() * got.fp.determinant();
    if (i != n - 1)
      AMPM_CHECK(ck, std::fabs(j_out / j_in - 1) < 0.05L, "%s %s particle %zu: J jumped",
                 A::name, what, i);
  }
  // The remedy's particle: k = 1 gives det = (1 − 3/2)² = 1/4.
  const RefParticle<D> in = before.get(n - 1), got = soa.get(n - 1);
  close("remedy J_E ratio", n - 1, got.fe.determinant() / in.fe.determinant(), 0.25L, 1,
           4 * C);
}

/// Batch contract: a failed particle is left as it was, the others are computed.
template <class T, int D>
void Case<T, D>::check_g2p_failed_particles(const G2pNodes<T, D>& nodes,
                                            const Soa<T, D>& before) const {
  const auto& gv = nodes.gv;
  Soa<T, D> bad = before;
  bad.fe[D * D * 3] = std::numeric_limits<T>::quiet_NaN();
  bad.ph[5] = 7;  // invalid phase code
  auto bp = bad.ptrs();
  const Soa<T, D> keep = bad;
  std::size_t first = 999;
  AMPM_CHECK_STATUS(ck, (A::g2p(&cm, kernel, h, dt, n, &bp, &gv, &first)),
                    AMPM_ERR_NON_FINITE);
  AMPM_CHECK(ck, first == 3, "%s: first_failed = %zu, want 3", A::name, first);
  for (std::size_t i : {std::size_t(3), std::size_t(5)}) {
    AMPM_CHECK(ck, same_bits(&bad.x[D * i], &keep.x[D * i], D) &&
                       same_bits(&bad.fe[D * D * i], &keep.fe[D * D * i], D * D) &&
                       same_bits(&bad.t[i], &keep.t[i], 1) && bad.ph[i] == keep.ph[i],
               "%s: failed particle %zu modified", A::name, i);
  }
  AMPM_CHECK(ck, !same_bits(&bad.x[0], &keep.x[0], D), "%s: particle 0 not updated", A::name);
}

/// A non-finite node value inside a stencil fails that particle only.
template <class T, int D>
void Case<T, D>::check_g2p_non_finite_node(const G2pNodes<T, D>& nodes,
                                           const Soa<T, D>& before) const {
  const auto& vel = nodes.vel;
  const auto& gv = nodes.gv;
  Soa<T, D> s2 = before;
  auto sp = s2.ptrs();
  std::vector<T> v0 = vel[0];
  const RefStencil<D> s = ref_stencil<D>(kernel, -1, h, before.get(4).x);
  v0[box.at(s.node[K / 2])] = std::numeric_limits<T>::infinity();
  typename A::G2pView g2 = gv;
  g2.velocity[0] = channel<CCh>(static_cast<const T*>(v0.data()), box);
  std::size_t first = 999;
  AMPM_CHECK_STATUS(ck, (A::g2p(&cm, kernel, h, dt, n, &sp, &g2, &first)),
                    AMPM_ERR_NON_FINITE);
  AMPM_CHECK(ck, first <= 4, "%s non-finite node: first_failed = %zu", A::name, first);
  AMPM_CHECK(ck, same_bits(&s2.x[D * 4], &before.x[D * 4], D),
             "%s: particle 4 moved despite an infinite node velocity", A::name);
}

/// Whole-call errors and n = 0.
template <class T, int D>
void Case<T, D>::check_g2p_call_errors(const G2pNodes<T, D>& nodes,
                                       const Soa<T, D>& before) const {
  const auto& gv = nodes.gv;
  typename A::Particles nul{};
  std::size_t first = 999;
  AMPM_CHECK_STATUS(ck, (A::g2p(&cm, kernel, h, dt, 0, &nul, &gv, &first)), AMPM_OK);
  AMPM_CHECK(ck, first == 0, "%s n = 0: first_failed = %zu", A::name, first);
  first = 999;
  AMPM_CHECK_STATUS(ck, (A::g2p(&cm, kernel, h, dt, 1, &nul, &gv, &first)),
                    AMPM_ERR_NULL_POINTER);
  AMPM_CHECK(ck, first == 0, "%s NULL arrays: first_failed = %zu", A::name, first);
  Soa<T, D> s2 = before;
  auto sp = s2.ptrs();
  typename A::G2pView g2 = gv;
  g2.velocity[D - 1].data = nullptr;
  AMPM_CHECK_STATUS(ck, (A::g2p(&cm, kernel, h, dt, n, &sp, &g2, nullptr)),
                    AMPM_ERR_NULL_POINTER);
  AMPM_CHECK(ck, same_bits(s2.x.data(), before.x.data(), s2.x.size()),
             "%s: a whole-call error wrote particles", A::name);
}

/// G2P and the particle update: the grid (G2pNodes), then the checks above in order.
template <class T, int D>
void Case<T, D>::check_g2p() {
  const G2pNodes<T, D> nodes(*this);
  const Soa<T, D> before = soa;
  for (const bool mac : {false, true}) check_g2p_update(nodes, before, mac);
  check_g2p_failed_particles(nodes, before);
  check_g2p_non_finite_node(nodes, before);
  check_g2p_call_errors(nodes, before);
}

}  // namespace
