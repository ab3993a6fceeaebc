// Checks of ampm_p2g_*: the collocated node sums, the same P2G through an interleaved and
// reversed view and with impulse_dt, each particle's stress through a one-particle P2G, the
// MAC face grids, and particles outside the grid.
#pragma once

#include "case.hpp"

namespace {

/// The channels of the collocated P2G grid: 0 mass, 1..D momentum, D+1..2D force, 2D+1.. heat
/// capacity, thermal energy, conductivity.
template <int D>
constexpr int kNch = 1 + 2 * D + 3;

/// The P2G view of `box` with every channel (kNch) over the arrays `grid` of that layout.
template <class T, int D>
typename PartApi<T, D>::P2gView p2g_view(std::vector<std::vector<T>>& grid, const Box<D>& box) {
  using Ch = typename PartApi<T, D>::Channel;
  typename PartApi<T, D>::P2gView view{};
  view.nodes = box.c();
  view.mass = channel<Ch>(grid[0].data(), box);
  for (int a = 0; a < D; ++a) {
    view.momentum[a] = channel<Ch>(grid[1 + a].data(), box);
    view.force[a] = channel<Ch>(grid[1 + D + a].data(), box);
  }
  view.heat_capacity = channel<Ch>(grid[2 * D + 1].data(), box);
  view.thermal_energy = channel<Ch>(grid[2 * D + 2].data(), box);
  view.conductivity = channel<Ch>(grid[2 * D + 3].data(), box);
  return view;
}

/// P2G on the collocated grid, every channel (kNch), against the reference node sums.
/// Returns the node arrays of the channels (the reference of the checks below).
template <class T, int D>
std::vector<std::vector<T>> Case<T, D>::check_p2g() const {
  const int NCH = kNch<D>;
  std::vector<std::vector<T>> grid_a(NCH, std::vector<T>(nn, 0));
  typename A::P2gView view = p2g_view(grid_a, box);
  std::size_t first = 999;
  AMPM_CHECK_STATUS(ck, (A::p2g(&cm, kernel, AMPM_GRID_COLLOCATED, h, T(0), n, &ps, &view,
                                &first)),
                    AMPM_OK);
  AMPM_CHECK(ck, first == n, "%s p2g: first_failed = %zu", A::name, first);

  std::vector<RefField> ref(NCH, RefField(nn));
  std::vector<ld> cst(NCH, Cn);
  for (int a = 0; a < D; ++a) cst[1 + D + a] = Sn;
  for (std::size_t i = 0; i < n; ++i) {
    const RefParticle<D> p = soa.get(i);
    const RefStencil<D> s = ref_stencil<D>(kernel, -1, h, p.x);
    const MatL<D> tau = ref_piola<D>(mat, p) * p.fe.transpose();
    const ld c = p.phase == 0 ? mat.c_s : mat.c_l;
    const ld kap = p.phase == 0 ? mat.k_s : mat.k_l;
    const ld vs = p.v.norm() + p.c.norm() * 2 * h;
    // Stress errors are absolute in units of the moduli (J_E − 1 cancels near 1).
    const auto [mu, il] = moduli(mat, p);
    const ld ts = tau.norm() + mu + 1 / il;
    for (int r = 0; r < K; ++r) {
      const std::size_t k = box.at(s.node[r]);
      const Vec mom = s.w[r] * p.m * (p.v + p.c * s.dx[r]);
      const Vec f = -p.v0 * tau * s.grad[r];
      ref[0].add(k, s.w[r] * p.m, p.m);
      for (int a = 0; a < D; ++a) {
        ref[1 + a].add(k, mom(a), p.m * vs);
        ref[1 + D + a].add(k, f(a), p.v0 * ts / h);
      }
      ref[2 * D + 1].add(k, s.w[r] * p.m * c, p.m * c);
      ref[2 * D + 2].add(k, s.w[r] * p.m * c * p.t, p.m * c * p.t);
      ref[2 * D + 3].add(k, s.w[r] * p.m * kap, p.m * kap);
    }
  }
  static const char* names[] = {"mass", "momentum", "momentum", "momentum", "force",
                                "force", "force", "heat capacity", "thermal energy",
                                "conductivity"};
  for (int ch = 0; ch < NCH; ++ch) {
    const int nm = ch == 0 ? 0 : ch <= D ? 1 : ch <= 2 * D ? 4 : 7 + (ch - 2 * D - 1);
    for (std::size_t k = 0; k < nn; ++k)
      close(names[nm], k, grid_a[ch][k], ref[ch].sum[k], ref[ch].scale[k], cst[ch]);
  }
  return grid_a;
}

/// The same P2G through an interleaved node struct of NCH scalars, axis D−1 fastest and axis
/// 0 reversed (negative stride): the same sums in the same order, so bit for bit the same.
template <class T, int D>
void Case<T, D>::check_p2g_interleaved(const Grids& grid_a) const {
  const int NCH = kNch<D>;
  std::vector<std::ptrdiff_t> st(D);
  st[D - 1] = NCH;
  for (int a = D - 2; a >= 0; --a) st[a] = st[a + 1] * box.dims[a + 1];
  st[0] = -st[0];
  const std::ptrdiff_t origin = -st[0] * (box.dims[0] - 1);  // node lo sits at the end
  std::vector<T> blob(nn * NCH, 0);
  auto ich = [&](int ch) {
    Ch c{};
    c.data = blob.data() + origin + ch;
    for (int a = 0; a < D; ++a) c.stride[a] = st[a];
    return c;
  };
  typename A::P2gView view{};
  view.nodes = box.c();
  view.mass = ich(0);
  for (int a = 0; a < D; ++a) view.momentum[a] = ich(1 + a), view.force[a] = ich(1 + D + a);
  view.heat_capacity = ich(2 * D + 1);
  view.thermal_energy = ich(2 * D + 2);
  view.conductivity = ich(2 * D + 3);
  std::size_t first = 999;
  AMPM_CHECK_STATUS(ck, (A::p2g(&cm, kernel, AMPM_GRID_COLLOCATED, h, T(0), n, &ps, &view,
                                &first)),
                    AMPM_OK);
  bool same = true;
  for (std::size_t k = 0; k < nn; ++k) {
    const auto idx = box.node(k);
    std::ptrdiff_t off = origin;
    for (int a = 0; a < D; ++a) off += (idx[a] - box.lo[a]) * st[a];
    for (int ch = 0; ch < NCH; ++ch) same &= same_bits(&blob[off + ch], &grid_a[ch][k], 1);
  }
  AMPM_CHECK(ck, same, "%s p2g: interleaved, reversed view differs from separate arrays",
             A::name);
}

/// impulse_dt = Δt without a force channel: momentum + Δt·force of the plain form (each
/// contribution rounds once more, so the node sums agree to (C + n)·ε of the magnitudes).
template <class T, int D>
void Case<T, D>::check_p2g_impulse(const Grids& grid_a) const {
  const T idt = static_cast<T>(0.01);
  std::vector<T> m(nn, 0);
  std::vector<std::vector<T>> mom(D, std::vector<T>(nn, 0));
  typename A::P2gView view{};
  view.nodes = box.c();
  view.mass = channel<Ch>(m.data(), box);
  for (int a = 0; a < D; ++a) view.momentum[a] = channel<Ch>(mom[a].data(), box);
  std::size_t first = 999;
  AMPM_CHECK_STATUS(ck, (A::p2g(&cm, kernel, AMPM_GRID_COLLOCATED, h, idt, n, &ps, &view,
                                &first)),
                    AMPM_OK);
  std::vector<ld> sc(nn, 0);
  for (std::size_t i = 0; i < n; ++i) {
    const RefParticle<D> p = soa.get(i);
    const RefStencil<D> s = ref_stencil<D>(kernel, -1, h, p.x);
    const MatL<D> tau = ref_piola<D>(mat, p) * p.fe.transpose();
    const auto [mu, il] = moduli(mat, p);
    for (int r = 0; r < K; ++r)
      sc[box.at(s.node[r])] += p.m * (p.v.norm() + p.c.norm() * 2 * h) +
                               idt * p.v0 * (tau.norm() + mu + 1 / il) / h;
  }
  for (std::size_t k = 0; k < nn; ++k) {
    AMPM_CHECK(ck, same_bits(&m[k], &grid_a[0][k], 1), "%s impulse p2g: mass differs",
               A::name);
    for (int a = 0; a < D; ++a)
      close("impulse momentum", k, mom[a][k],
               static_cast<ld>(grid_a[1 + a][k]) + static_cast<ld>(idt) * grid_a[1 + D + a][k],
               sc[k], Sn);
  }
}

/// The stress of every particle through its own one-particle P2G (force channel only, the
/// others absent): τ = −(1/V⁰) Σ_i f_i (x_i − x_p)ᵀ since Σ_i ∇w_i (x_i − x_p)ᵀ = I; a
/// liquid's is isotropic. The sum has K^d terms of size ≤ V⁰‖τ‖·|∇w||x_i − x_p| ≤
/// V⁰‖τ‖·2√d, hence 256·K^d·2√d.
template <class T, int D>
void Case<T, D>::check_stress() const {
  for (std::size_t i = 0; i < n; ++i) {
    const RefParticle<D> p = soa.get(i);
    const RefStencil<D> s = ref_stencil<D>(kernel, -1, h, p.x);
    Box<D> sb;
    for (int a = 0; a < D; ++a) sb.lo[a] = s.base[a], sb.dims[a] = s.k;
    std::vector<std::vector<T>> f(D, std::vector<T>(sb.count(), 0));
    typename A::P2gView view{};
    view.nodes = sb.c();
    for (int a = 0; a < D; ++a) view.force[a] = channel<Ch>(f[a].data(), sb);
    typename A::Particles one = ps;
    one.x += D * i, one.v += D * i, one.affine += D * D * i, one.f_e += D * D * i,
        one.f_p += D * D * i, one.mass += i, one.volume0 += i, one.temperature += i,
        one.latent += i, one.phase += i;
    std::size_t first = 999;
    AMPM_CHECK_STATUS(ck, (A::p2g(&cm, kernel, AMPM_GRID_COLLOCATED, h, T(0), 1, &one, &view,
                                  &first)),
                      AMPM_OK);
    MatL<D> tau_lib = MatL<D>::Zero();
    for (int r = 0; r < K; ++r) {
      Vec fl;
      for (int a = 0; a < D; ++a) fl(a) = f[a][sb.at(s.node[r])];
      tau_lib -= fl * s.dx[r].transpose() / p.v0;
    }
    const MatL<D> tau = ref_piola<D>(mat, p) * p.fe.transpose();
    const auto [mu, il] = moduli(mat, p);
    const ld ts = tau.norm() + mu + 1 / il;
    const ld c_tau = 256 * K * 2 * std::sqrt(ld(D));
    close("stress from one-particle p2g", i, (tau_lib - tau).norm(), 0, ts, c_tau);
    if (p.phase == 1) {
      const MatL<D> dev = tau_lib - tau_lib.trace() / D * MatL<D>::Identity();
      AMPM_CHECK(ck, dev.norm() <= c_tau * eps * ts, "%s liquid deviatoric stress %.3Le",
                 A::name, dev.norm());
    }
  }
}

/// P2G on each MAC face grid a: mass, momentum[a] and force[a] with the face stencil; the
/// other channels of the view stay untouched.
template <class T, int D>
void Case<T, D>::check_p2g_faces() const {
  const int NCH = kNch<D>;
  for (int g = 0; g < D; ++g) {
    Box<D> fb = ref_box<T, D>(soa, n, kernel, g, h);
    for (int a = 0; a < D; ++a) fb.lo[a] -= 1, fb.dims[a] += 2;
    const std::size_t fn = fb.count();
    std::vector<std::vector<T>> fg(NCH, std::vector<T>(fn, 0));
    typename A::P2gView view = p2g_view(fg, fb);
    std::size_t first = 999;
    AMPM_CHECK_STATUS(ck, (A::p2g(&cm, kernel, g, h, T(0), n, &ps, &view, &first)), AMPM_OK);
    RefField rm(fn), rq(fn), rf(fn);
    for (std::size_t i = 0; i < n; ++i) {
      const RefParticle<D> p = soa.get(i);
      const RefStencil<D> s = ref_stencil<D>(kernel, g, h, p.x);
      const MatL<D> tau = ref_piola<D>(mat, p) * p.fe.transpose();
      const auto [mu, il] = moduli(mat, p);
      for (int r = 0; r < K; ++r) {
        const std::size_t k = fb.at(s.node[r]);
        rm.add(k, s.w[r] * p.m, p.m);
        rq.add(k, s.w[r] * p.m * (p.v + p.c * s.dx[r])(g),
               p.m * (p.v.norm() + p.c.norm() * 2 * h));
        rf.add(k, (-p.v0 * tau * s.grad[r])(g), p.v0 * (tau.norm() + mu + 1 / il) / h);
      }
    }
    bool untouched = true;
    for (std::size_t k = 0; k < fn; ++k) {
      close("face mass", k, fg[0][k], rm.sum[k], rm.scale[k], Cn);
      close("face momentum", k, fg[1 + g][k], rq.sum[k], rq.scale[k], Cn);
      close("face force", k, fg[1 + D + g][k], rf.sum[k], rf.scale[k], Sn);
      for (int ch = 1; ch < NCH; ++ch)
        if (ch != 1 + g && ch != 1 + D + g) untouched &= fg[ch][k] == T(0);
    }
    AMPM_CHECK(ck, untouched, "%s face p2g %d wrote a channel of another component or heat",
               A::name, g);
  }
}

/// A box one node short on axis 0: the particles reaching its last layer fail with
/// AMPM_ERR_OUTSIDE_GRID and transfer nothing; the others sum to the same bits as a batch of
/// only them, in the same order (node sums are formed per run of nearby particles, and a
/// failed particle does not change the runs).
template <class T, int D>
void Case<T, D>::check_p2g_outside_grid() const {
  Box<D> sb = ref_box<T, D>(soa, n, kernel, -1, h);
  const int last = sb.lo[0] + sb.dims[0] - 1;
  sb.dims[0] -= 1;
  std::vector<T> m(sb.count(), 0), m_good(sb.count(), 0);
  typename A::P2gView view{};
  view.nodes = sb.c();
  view.mass = channel<Ch>(m.data(), sb);
  std::size_t first = 999, want_first = n;
  AMPM_CHECK_STATUS(ck, (A::p2g(&cm, kernel, AMPM_GRID_COLLOCATED, h, T(0), n, &ps, &view,
                                &first)),
                    AMPM_ERR_OUTSIDE_GRID);
  view.mass = channel<Ch>(m_good.data(), sb);
  Soa<T, D> inside;
  std::size_t n_inside = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const RefStencil<D> s = ref_stencil<D>(kernel, -1, h, soa.get(i).x);
    if (s.base[0] + s.k - 1 == last) {
      want_first = std::min(want_first, i);
      continue;
    }
    inside.push(soa.get(i));
    ++n_inside;
  }
  typename A::Particles only = inside.ptrs();
  std::size_t f1 = 999;
  AMPM_CHECK_STATUS(ck, (A::p2g(&cm, kernel, AMPM_GRID_COLLOCATED, h, T(0), n_inside, &only,
                                &view, &f1)),
                    AMPM_OK);
  AMPM_CHECK(ck, first == want_first, "%s outside grid: first_failed = %zu, want %zu",
             A::name, first, want_first);
  AMPM_CHECK(ck, same_bits(m.data(), m_good.data(), m.size()),
             "%s outside grid: the particles inside did not sum as a batch of only them", A::name);
}

}  // namespace
