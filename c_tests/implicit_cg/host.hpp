// The host's calls of one step: P2G into a fresh box with its stencils and v*, the prepared
// slots with every particle's operator S_p probed, the apply and the operator A, the bounds
// built from them (g_p, κ), G2P and the mechanical energy. Its CG is in cg.hpp.
#pragma once

#include "implicit_cg/block.hpp"

#include <utility>

namespace {

template <class T>
class Host {
 public:
  using A = Api3<T>;
  Host(Checker& ck, const Setup<T>& s, Parts<T>& p) : ck_(ck), s_(s), p_(p) {}

  /// P2G at the current state into a fresh box; stencils; active nodes; v* for step dt.
  void p2g(Step<T>& st, T dt) {
    const std::size_t n = p_.n;
    int lo[3], hi[3];
    std::size_t ff = 0;
    AMPM_CHECK_STATUS(ck_,
                      A::node_range(AMPM_KERNEL_QUADRATIC, AMPM_GRID_COLLOCATED, h(), n,
                                    p_.x.data(), lo, hi, &ff),
                      AMPM_OK);
    st.g.reset(lo, hi);
    st.base.assign(n * D, 0), st.w.assign(n * KD, 0), st.gw.assign(n * KD * D, 0);
    AMPM_CHECK_STATUS(ck_,
                      A::stencil(AMPM_KERNEL_QUADRATIC, AMPM_GRID_COLLOCATED, h(), n,
                                 p_.x.data(), st.base.data(), st.w.data(), st.gw.data(), &ff),
                      AMPM_OK);
    st.nodes.assign(n * KD, 0);
    st.gnorm.assign(n * KD, 0);
    for (std::size_t i = 0; i < n; ++i)
      for (int r = 0; r < KD; ++r) {
        int idx[3];
        for (int a = 0, q = r; a < 3; ++a, q /= K1) idx[a] = st.base[3 * i + a] + q % K1;
        st.nodes[KD * i + r] = st.g.at(idx);
        st.gnorm[KD * i + r] = grad(st, i, r).norm();
      }
    std::vector<int> share(st.g.count, 0);
    st.n_add = 0;
    for (std::size_t i = 0; i < n; ++i)
      for (int r = 0; r < KD; ++r) st.n_add = std::max(st.n_add, ++share[node(st, i, r)]);
    typename A::P2gView v{};
    v.nodes = st.g.box();
    v.mass = st.g.out(st.g.mass.data());
    for (int a = 0; a < 3; ++a)
      v.momentum[a] = st.g.out(st.g.mom[a].data()), v.force[a] = st.g.out(st.g.force[a].data());
    const auto mat = material(s_, true);
    auto pv = p_.view();
    ff = 0;
    AMPM_CHECK_STATUS(ck_,
                      A::p2g(&mat, AMPM_KERNEL_QUADRATIC, AMPM_GRID_COLLOCATED, h(), T(0), n,
                             &pv, &v, &ff),
                      AMPM_OK);
    AMPM_CHECK(ck_, ff == n, "%s p2g first_failed %zu", A::name, ff);
    st.active.assign(st.g.count, 0);
    for (std::size_t k = 0; k < st.g.count; ++k) {
      st.active[k] = st.g.mass[k] > 0;
      for (int a = 0; a < 3; ++a)
        st.g.vstar[a][k] =
            st.active[k] ? (st.g.mom[a][k] + dt * st.g.force[a][k]) / st.g.mass[k] : T(0);
    }
  }

  /// Grid index (linear) of stencil node r of particle i.
  std::size_t node(const Step<T>& st, std::size_t i, int r) const {
    return st.nodes[KD * i + r];
  }
  /// x_i − x_p of stencil node r of particle i (long double).
  Vec3L dx(const Step<T>& st, std::size_t i, int r) const {
    Vec3L d;
    for (int a = 0, q = r; a < 3; ++a, q /= K1)
      d(a) = static_cast<ld>(st.base[3 * i + a] + q % K1) * static_cast<ld>(h()) -
             static_cast<ld>(p_.x[3 * i + a]);
    return d;
  }
  Vec3L grad(const Step<T>& st, std::size_t i, int r) const {
    Vec3L g;
    for (int a = 0; a < 3; ++a) g(a) = st.gw[(KD * i + r) * 3 + a];
    return g;
  }

  /// Prepares the slots (PSD or exact) and probes every particle's operator S_p.
  void prepare(Step<T>& st, bool psd) {
    const std::size_t n = p_.n;
    const auto mat = material(s_, psd);
    auto pv = p_.view();
    st.slots.assign(n * SL, 0);
    std::size_t ff = 0;
    AMPM_CHECK_STATUS(ck_, A::prepare(&mat, n, &pv, st.slots.data(), &ff), AMPM_OK);
    AMPM_CHECK(ck_, ff == n, "%s prepare first_failed %zu", A::name, ff);
    st.s_norm.assign(n, 0);
    st.s_mat.assign(n, Mat9L::Zero());
    const ld eps = std::numeric_limits<T>::epsilon();
    const ld c_s = 4 * (KD + 8 * D) * 2 * std::sqrt(ld(D));
    std::array<std::vector<T>, 3> du, df;
    for (int a = 0; a < 3; ++a) du[a].assign(KD, 0), df[a].assign(KD, 0);
    for (std::size_t i = 0; i < n; ++i) {
      const Mat9L s = probe(st, i, du, df);
      st.s_mat[i] = s;
      st.s_norm[i] = s.norm();
      const ld tol = c_s * eps * s.norm();
      AMPM_CHECK(ck_, (s - s.transpose()).norm() <= tol,
                 "%s particle %zu: operator asymmetry %.3Le (tol %.3Le)", A::name, i,
                 (s - s.transpose()).norm(), tol);
      if (psd) {
        const ld top = Eigen::SelfAdjointEigenSolver<Mat9L>((s + s.transpose()) / 2,
                                                            Eigen::EigenvaluesOnly)
                           .eigenvalues()(8);
        AMPM_CHECK(ck_, top <= tol, "%s particle %zu: PSD operator has eigenvalue %.3Le > %.3Le",
                   A::name, i, top, tol);
      }
    }
  }

  /// df = apply(du) over the box (du, df in T, zeroed df first).
  void apply(const Step<T>& st, const std::array<std::vector<T>, 3>& du,
             std::array<std::vector<T>, 3>& df) {
    typename A::ForceView fv{};
    fv.nodes = st.g.box();
    for (int a = 0; a < 3; ++a) {
      std::fill(df[a].begin(), df[a].end(), T(0));
      fv.du[a] = st.g.in(du[a].data());
      fv.df[a] = st.g.out(df[a].data());
    }
    std::size_t ff = 0;
    AMPM_CHECK_STATUS(ck_,
                      A::apply(AMPM_KERNEL_QUADRATIC, h(), p_.n, p_.x.data(), st.slots.data(),
                               &fv, &ff),
                      AMPM_OK);
    AMPM_CHECK(ck_, ff == p_.n, "%s apply first_failed %zu", A::name, ff);
  }

  /// (A v)_i = m_i v_i − Δt·apply(Δt v)_i on the active nodes (0 elsewhere); v in T.
  void op(const Step<T>& st, T dt, const std::array<std::vector<T>, 3>& v,
          std::array<std::vector<T>, 3>& out) {
    std::array<std::vector<T>, 3> du, df;
    for (int a = 0; a < 3; ++a) {
      du[a].assign(st.g.count, 0);
      df[a].assign(st.g.count, 0);
      for (std::size_t k = 0; k < st.g.count; ++k) du[a][k] = st.active[k] ? dt * v[a][k] : T(0);
    }
    apply(st, du, df);
    for (int a = 0; a < 3; ++a) {
      out[a].assign(st.g.count, 0);
      for (std::size_t k = 0; k < st.g.count; ++k)
        out[a][k] = st.active[k] ? st.g.mass[k] * v[a][k] - dt * df[a][k] : T(0);
    }
  }

  /// g_p(u) = Σ_j |u_j||∇w_jp| per particle.
  std::vector<ld> gabs(const Step<T>& st, const std::array<std::vector<T>, 3>& u) const {
    std::vector<ld> un(st.g.count), out(p_.n, 0);
    for (std::size_t k = 0; k < st.g.count; ++k) un[k] = Vec3L(u[0][k], u[1][k], u[2][k]).norm();
    for (std::size_t i = 0; i < p_.n; ++i)
      for (int r = 0; r < KD; ++r) out[i] += un[node(st, i, r)] * st.gnorm[KD * i + r];
    return out;
  }

  /// Gershgorin bound on κ(M⁻¹A).
  ld kappa_bound(const Step<T>& st, T dt) const {
    std::vector<ld> row(st.g.count, 0);
    for (std::size_t i = 0; i < p_.n; ++i) {
      ld g1 = 0;
      for (int r = 0; r < KD; ++r) g1 += grad(st, i, r).norm();
      for (int r = 0; r < KD; ++r)
        row[node(st, i, r)] += st.s_norm[i] * grad(st, i, r).norm() * g1;
    }
    ld worst = 0;
    for (std::size_t k = 0; k < st.g.count; ++k)
      if (st.active[k]) worst = std::max(worst, std::sqrt(ld(D)) * row[k] / st.g.mass[k]);
    return 1 + static_cast<ld>(dt) * dt * worst;
  }

  /// Preconditioned CG for A v = M v*, v starting at v*. Returns the iterations; v gets the
  /// solution; asserts convergence within the bound. (Defined in cg.hpp.)
  int cg(const Step<T>& st, T dt, ld tol, std::array<std::vector<T>, 3>& v, const char* what);

  /// G2P with grid velocities v.
  void g2p(const Step<T>& st, T dt, const std::array<std::vector<T>, 3>& v) {
    typename A::G2pView gv{};
    gv.nodes = st.g.box();
    for (int a = 0; a < 3; ++a) gv.velocity[a] = st.g.in(v[a].data());
    const auto mat = material(s_, true);
    auto pv = p_.view();
    std::size_t ff = 0;
    AMPM_CHECK_STATUS(ck_, A::g2p(&mat, AMPM_KERNEL_QUADRATIC, h(), dt, p_.n, &pv, &gv, &ff),
                      AMPM_OK);
    AMPM_CHECK(ck_, ff == p_.n, "%s g2p first_failed %zu", A::name, ff);
  }

  /// Σ_p ½ m |v|² and Σ_p V⁰ (Ψ̂_μ + Ψ_λ) (common.hpp's long-double reference).
  std::pair<ld, ld> energy() const {
    ld ke = 0, pe = 0;
    for (std::size_t i = 0; i < p_.n; ++i) {
      ld v2 = 0;
      for (int a = 0; a < 3; ++a) v2 += static_cast<ld>(p_.v[3 * i + a]) * p_.v[3 * i + a];
      ke += 0.5L * p_.m[i] * v2;
      MatL<3> f;
      for (int k = 0; k < 9; ++k) f.data()[k] = p_.fe[9 * i + k];
      const ld j = f.determinant();
      pe += static_cast<ld>(p_.v0[i]) *
            (Reference<3>(s_.mu, f).psi_hat() + s_.lambda / 2 * (j - 1) * (j - 1));
    }
    return {ke, pe};
  }

  T h() const { return static_cast<T>(s_.h); }

 private:
  /// S_p of particle i, probed through one-particle applies (du_j = e_a (x_j − x_p)_b, read
  /// back as Σ_i df_i (x_i − x_p)ᵀ); du, df are its stencil's scratch channels.
  Mat9L probe(const Step<T>& st, std::size_t i, std::array<std::vector<T>, 3>& du,
              std::array<std::vector<T>, 3>& df) {
    typename A::ForceView fv{};
    for (int a = 0; a < 3; ++a) fv.nodes.lo[a] = st.base[3 * i + a], fv.nodes.dims[a] = K1;
    for (int a = 0; a < 3; ++a) {
      fv.du[a].data = du[a].data();
      fv.df[a].data = df[a].data();
      fv.du[a].stride[0] = fv.df[a].stride[0] = 1;
      fv.du[a].stride[1] = fv.df[a].stride[1] = K1;
      fv.du[a].stride[2] = fv.df[a].stride[2] = K1 * K1;
    }
    Mat9L s;
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b) {
        for (int c = 0; c < 3; ++c)
          for (int r = 0; r < KD; ++r) {
            du[c][r] = c == a ? static_cast<T>(dx(st, i, r)(b)) : T(0);
            df[c][r] = 0;
          }
        std::size_t f1 = 0;
        AMPM_CHECK_STATUS(ck_,
                          A::apply(AMPM_KERNEL_QUADRATIC, h(), 1, p_.x.data() + 3 * i,
                                   st.slots.data() + SL * i, &fv, &f1),
                          AMPM_OK);
        MatL<3> m = MatL<3>::Zero();
        for (int r = 0; r < KD; ++r) {
          Vec3L f;
          for (int c = 0; c < 3; ++c) f(c) = df[c][r];
          m += f * dx(st, i, r).transpose();
        }
        for (int k = 0; k < 9; ++k) s(k, a + 3 * b) = m.data()[k];
      }
    return s;
  }

  Checker& ck_;
  const Setup<T>& s_;
  Parts<T>& p_;
};

}  // namespace
