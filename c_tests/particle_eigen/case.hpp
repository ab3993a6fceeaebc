// One case of the test (scalar T, dimension D, with or without the pressure solve): its sizes
// and tolerances, the material, the particles, and the host's collocated box, shared by the
// checks. The checks are member functions of the case, so that they see its fields by name (ck,
// kernel, h, soa, ...); they are declared here and defined in checks_*.hpp.
#pragma once

#include "host.hpp"

namespace {

constexpr std::uint64_t kSeed = 0x5eed'a3b1'2014'0004ULL;

template <class T, int D>
struct G2pNodes;

template <class T, int D>
struct Case {
  using A = PartApi<T, D>;
  using Ch = typename A::Channel;
  using CCh = typename A::ConstChannel;
  using Vec = Eigen::Matrix<ld, D, 1>;
  using Grids = std::vector<std::vector<T>>;  // per-channel node arrays

  Checker& ck;
  const ld eps = std::numeric_limits<T>::epsilon();
  Rng rng;
  const RefMaterial mat;
  const typename A::Material cm;
  const int kernel = D == 2 ? AMPM_KERNEL_CUBIC : AMPM_KERNEL_QUADRATIC;
  const int kk = kernel == AMPM_KERNEL_QUADRATIC ? 3 : 4;
  const int K = D == 2 ? kk * kk : kk * kk * kk;
  const T h = static_cast<T>(0.5), dt = static_cast<T>(1e-3);
  const std::size_t n = 12;
  const ld C = 64 + 2 * K;                     // one particle's contribution (file comment)
  const ld Cn = C + static_cast<ld>(n);        // a node sum of ≤ n contributions
  const ld Sn = 256 + static_cast<ld>(n);      // stress and Hessian node sums
  Soa<T, D> soa;
  typename A::Particles ps{};
  Box<D> box;
  std::size_t nn = 0;

  Case(Checker& checker, bool pressure_solve)
      : ck(checker),
        rng(kSeed + 10 * D + sizeof(T) + (pressure_solve ? 100 : 0)),
        mat(rounded<T>({true, true, true, pressure_solve, 40.0L, 0.02L, 2.0L, 0.05L, 4.0L, 1.5L,
                        0.6L, 0.025L, 0.0075L, 10.0L, 0.9L, 273.0L, 100.0L})),
        cm(c_material<T, D>(mat)) {
    // Particles: solids below the melting point or melting, liquids above it or freezing, in
    // [1, 3]^d; the last one (the remedy's, see G2P) on its own at x_0 in [5.1, 5.4], so that no
    // other particle's stencil shares a node with it.
    for (std::size_t i = 0; i < n; ++i) {
      RefParticle<D> p;
      for (int a = 0; a < D; ++a) p.x(a) = rng.uniform(1.0, 3.0), p.v(a) = rng.uniform(-1, 1);
      if (i == n - 1) p.x(0) = rng.uniform(5.1, 5.4);
      p.c = gaussian<D>(rng);
      p.phase = static_cast<int>(i % 2);
      Eigen::Matrix<ld, D, 1> sig = log_uniform_sigma<D>(rng, 0.9, 1.1);
      if (p.phase == 1) sig.setConstant(sig(0));  // a liquid's F_E is isotropic
      p.fe = random_f_with_sigma<D>(rng, sig);
      p.fp = random_f_with_sigma<D>(rng, log_uniform_sigma<D>(rng, 0.95, 1.05));
      p.m = rng.uniform(0.5, 2.0), p.v0 = rng.uniform(0.01, 0.1);
      const int kind = static_cast<int>(i / 2) % 3;  // 0: away from T_m, 1-2: at T_m
      if (p.phase == 0)
        p.t = kind == 0 ? 268.0L : 273.0L, p.u = kind == 0 ? 0.0L : 30.0L * kind;
      else
        p.t = kind == 0 ? 278.0L : 273.0L, p.u = kind == 0 ? 100.0L : 30.0L * kind;
      soa.push(p);
    }
    ps = soa.ptrs();

    // The host's collocated box: the particles' nodes plus a margin of 2 below and 1 above, so
    // that nodes no stencil reaches are in the view too (and must stay untouched).
    box = ref_box<T, D>(soa, n, kernel, -1, h);
    for (int a = 0; a < D; ++a) box.lo[a] -= 2, box.dims[a] += 3;
    nn = box.count();
  }
  Case(const Case&) = delete;
  Case& operator=(const Case&) = delete;

  /// Checks |got − want| ≤ c·ε·scale.
  void close(const char* what, std::size_t i, ld got, ld want, ld scale, ld c) const {
    AMPM_CHECK(ck, std::fabs(got - want) <= c * eps * scale,
               "%s %s %zu: got %.12Le want %.12Le (tol %.3Le)", A::name, what, i, got, want,
               c * eps * scale);
  }

  // The checks, in the order run() calls them. checks_stencil.hpp:
  void check_stencils() const;
  // checks_p2g.hpp:
  Grids check_p2g() const;
  void check_p2g_interleaved(const Grids& grid_a) const;
  void check_p2g_impulse(const Grids& grid_a) const;
  void check_stress() const;
  void check_p2g_faces() const;
  void check_p2g_outside_grid() const;
  // checks_force.hpp:
  void check_force_differential();
  void check_force_apply(const Grids& du, bool psd);
  void check_nsd_particles(const std::vector<T>& slots);
  void check_unprepared_slots(const Grids& du) const;
  // checks_pressure.hpp:
  void check_pressure() const;
  // checks_g2p.hpp:
  void check_g2p();
  void check_g2p_update(const G2pNodes<T, D>& nodes, const Soa<T, D>& before, bool mac);
  void check_g2p_failed_particles(const G2pNodes<T, D>& nodes, const Soa<T, D>& before) const;
  void check_g2p_non_finite_node(const G2pNodes<T, D>& nodes, const Soa<T, D>& before) const;
  void check_g2p_call_errors(const G2pNodes<T, D>& nodes, const Soa<T, D>& before) const;
};

}  // namespace
