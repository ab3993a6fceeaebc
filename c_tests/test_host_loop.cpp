// An MPM host written against include/ampm.h only (no Eigen, no test helpers): the explicit
// time step loop a C or C++ engine runs with the particle API, in 2D and 3D, f32 and f64, and
// the conservation laws that loop must keep.
//
// The host owns its grid: each step it asks ampm_node_range_* for the node box its particles
// reach (its lower corner moves and may be negative), allocates dense x-fastest arrays over it,
// zeroes them and points the view channels at them. One step:
//   P2G (ampm_p2g_*, impulse_dt = 0, separate force channels) → grid update
//   v_i = (p_i + Δt f_i)/m_i (no gravity, no boundaries: free flight) → G2P (ampm_g2p_update_*).
//
// Asserted every step (ε of the precision; A = K^d stencil nodes; n_add = the most particles
// whose stencils share one node, counted from ampm_stencil_* each step):
//   - mass: Σ_i m_i = Σ_p m_p. Each particle's weights sum to 1 up to (A + 6d)·ε (per-axis
//     weights of ~4 operations, products of d factors, w·m), and a node sums ≤ n_add terms
//     (recursive summation, n_add·ε of the sum of magnitudes): (n_add + A + 6d)·ε·Σ_p m_p.
//   - momentum, stage by stage, per component a, with S_a = Σ_p m_p (|v_pa| + 3.5 h Σ_b |C_ab|)
//     (|x_i − x_p| ≤ 3.5 h per axis in the library's q0 + m C h o form, |fx| ≤ 1.5, o ≤ 2) and
//     F_a = Σ_p Σ_i |f_ip,a| (measured by a one-particle P2G of each particle into a scratch
//     view of its own stencil):
//       P2G      |Σ_i p_ia − Σ_p m_p v_pa| ≤ c_P·ε·S_a,   c_P = n_add + A + 6d + 8
//                (Σ_i w_i (x_i − x_p) = 0 for B-splines);
//       forces   |Σ_i f_ia| ≤ c_P·ε·F_a  (Σ_i ∇w_i = 0);
//       impulse  P2G with impulse_dt = Δt and no force channel gives p + Δt f:
//                Σ_i |p'_ia − (p_ia + Δt f_ia)| ≤ 2(c_P + 2)·ε·(S_a + Δt F_a);
//       G2P      |Σ_p m_p v'_pa − Σ_i m_i v_ia| ≤ (n_add + A + 4)·ε·Σ_i m_i |v_ia|
//                (v'_p = Σ_i w_ip v_i, and Σ_p w_ip m_p = m_i up to n_add·ε);
//     and over the run |P_t − P_0| ≤ Σ_steps c_step·ε·(S_a + Δt F_a),
//     c_step = 2 n_add + 2A + 6d + 13 (the stages above plus the 3 roundings of the grid
//     update): ε × steps × Σ|m v| with the operation counts made explicit.
//   - J_E·J_P > 0 and every particle field finite.
//
// Heat (AMPM_MODEL_THERMAL, no phase change), PIC (flip = 0) and FLIP (flip = 1). The host's
// heat step, written out: T_i = thermal_energy_i / heat_capacity_i, κ_i = conductivity_i / m_i,
// material fraction θ_i = min(1, m_i/(ρ h^d)), face coefficients k_ij = h^(d−2)·½(κ_i + κ_j)·
// min(θ_i, θ_j) between face neighbours that both have mass (no flux elsewhere: an insulated
// box), and explicit conservative steps on the node energies E_i = C_i T_i:
//   Φ_ij = Δt_h k_ij (T_j − T_i), E_i += Φ_ij, E_j −= Φ_ij,
// with Δt_h = Δt/n_sub ≤ ½ min_i C_i/Σ_j k_ij (monotone: each new T_i is a convex combination).
// What is conserved, exactly in exact arithmetic, with the same weights w_ip in P2G and G2P
// (G2P samples before it moves the particle) and c_p fixed (no phase change):
//   P2G       Σ_i E_i = Σ_i Σ_p w_ip m_p c_p T_p = Σ_p m_p c_p T_p          (Σ_i w_ip = 1);
//   diffusion Σ_i E_i unchanged (each face flux is added once and subtracted once);
//   G2P, PIC  Σ_p m_p c_p T'_p = Σ_p m_p c_p Σ_i w_ip T_i = Σ_i C_i T_i = Σ_i E_i^new;
//   G2P, FLIP Σ_p m_p c_p (T_p + Σ_i w_ip (T_i^new − T_i^old)) = Σ_p m c T_p + Σ_i (E_i^new − E_i^old)
//             = Σ_i E_i^new as well.
// So PIC G2P of temperature does conserve the total heat here: it smooths (the spread shrinks,
// asserted as the max principle max/min T non-increasing/non-decreasing for PIC), it does not
// lose heat. Bounds with H = Σ_p m c T_p (T > 0): P2G (n_add + A + 6d + 4)·ε·H; diffusion
// (2d + 1)·ε·(Σ_i E_i + Σ|Φ|) per substep; G2P (2 n_add + A + 6d + 10)·ε·H.
//
// Phase change (AMPM_MODEL_PHASE_CHANGE): an ice block at 260 K; the host's heat step also
// couples every massive node to a warm ambient at T_amb across each face whose neighbour has
// no mass (Φ = Δt_h h^(d−2) κ_i θ_i (T_amb − T_i)) and records the heat Q_in it injects. The
// library turns the grid's temperature change into q_p = c_phase (T*_p − T_p) (J/kg) and spends
// it on the enthalpy e(T, U, phase) = c_s (T − T_m) (solid below T_m), U (at T_m),
// L + c_l (T − T_m) (liquid above), i.e. m Δe = m (c_s ΔT_s + ΔU + c_l ΔT_l) across phase
// switches. The host computes T*_p itself from ampm_stencil_* weights and asserts per particle
// |Δe − q| ≤ ε [(2A + 28) c T_scale + 14 L] (its T* and the library's, (A + 4)·ε·T_scale each;
// q, 2 roundings; ≤ 4 segments of ≤ 3 roundings in the library; the host's e, 2 each side), and
// globally Σ_p m_p Δe_p = Q_in (PIC: Σ_p m c T*_p = Σ_i E_i^new as above), with the grid-side
// bounds added. Some particles must melt.
//
// Sizes: a block of 2 particles per cell per axis (spacing h/2), 24² (2D) or 10³ (3D)
// particles, 40 steps (the ice block 16² or 8³, 60 steps); a few seconds in Release, most of it
// in the one-particle P2G calls that measure Σ|f|.
#include <cstddef>
#include <cstdint>

#include "ampm.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <random>
#include <vector>

namespace {

using ld = long double;

// ---- checks --------------------------------------------------------------------------------

long g_checks = 0, g_failures = 0;

#define CHECK(cond, ...)                                                        \
  do {                                                                          \
    ++g_checks;                                                                 \
    if (!(cond)) {                                                              \
      ++g_failures;                                                             \
      std::fprintf(stderr, "%s:%d: FAIL %s: ", __FILE__, __LINE__, #cond);      \
      std::fprintf(stderr, __VA_ARGS__);                                        \
      std::fputc('\n', stderr);                                                 \
    }                                                                           \
  } while (0)

#define CHECK_OK(call, n)                                                                  \
  do {                                                                                     \
    std::size_t ff_ = static_cast<std::size_t>(-1);                                        \
    const AmpmStatus st_ = (call)(&ff_);                                                   \
    CHECK(st_ == AMPM_OK && ff_ == (n), "status %d, first_failed %zu (n = %zu)", int(st_), \
          ff_, static_cast<std::size_t>(n));                                               \
  } while (0)

// ---- the C symbols by (scalar, dimension) --------------------------------------------------

template <class T, int D>
struct Api;

#define HOST_API(T, D, S)                                             \
  template <>                                                         \
  struct Api<T, D> {                                                  \
    static constexpr const char* name = #D "D " #S;                   \
    static constexpr auto p2g = ampm_p2g_##D##d_##S;                  \
    static constexpr auto g2p = ampm_g2p_update_##D##d_##S;           \
    static constexpr auto node_range = ampm_node_range_##D##d_##S;    \
    static constexpr auto stencil = ampm_stencil_##D##d_##S;          \
    using Material = AmpmMaterial_##S;                                \
    using Particles = AmpmParticles_##S;                              \
    using Channel = AmpmChannel_##S;                                  \
    using ConstChannel = AmpmConstChannel_##S;                        \
    using P2gView = AmpmP2gView_##S;                                  \
    using G2pView = AmpmG2pView_##S;                                  \
  };
HOST_API(float, 2, f32)
HOST_API(float, 3, f32)
HOST_API(double, 2, f64)
HOST_API(double, 3, f64)
#undef HOST_API

constexpr int K1 = 3;  // quadratic B-spline: 3 nodes per axis

template <int D>
constexpr int stencil_nodes() {
  return D == 2 ? K1 * K1 : K1 * K1 * K1;
}

// ---- the host's data -----------------------------------------------------------------------

template <class T, int D>
struct Particles {
  std::size_t n = 0;
  std::vector<T> x, v, c, fe, fp, m, v0, t, u;
  std::vector<std::uint8_t> ph;
  void resize(std::size_t k) {
    n = k;
    x.assign(k * D, 0), v.assign(k * D, 0), c.assign(k * D * D, 0);
    fe.assign(k * D * D, 0), fp.assign(k * D * D, 0);
    m.assign(k, 0), v0.assign(k, 0), t.assign(k, 0), u.assign(k, 0);
    ph.assign(k, AMPM_PHASE_SOLID);
  }
  typename Api<T, D>::Particles view() {
    return {x.data(), v.data(), c.data(), fe.data(), fp.data(), m.data(),
            v0.data(), t.data(), u.data(), ph.data()};
  }
};

/// The host's grid over a node box, dense arrays, x fastest.
template <class T, int D>
struct Grid {
  int lo[3] = {0, 0, 0}, dims[3] = {1, 1, 1};
  std::size_t count = 0;
  std::vector<T> mass, hc, te, cond, tnew, told;
  std::vector<T> mom[3], force[3], vel[3], mom2[3];

  void reset(const int* l, const int* h) {
    count = 1;
    for (int a = 0; a < 3; ++a) {
      lo[a] = a < D ? l[a] : 0;
      dims[a] = a < D ? h[a] - l[a] + 1 : 1;
      count *= static_cast<std::size_t>(dims[a]);
    }
    for (auto* f : {&mass, &hc, &te, &cond, &tnew, &told}) f->assign(count, 0);
    for (int a = 0; a < 3; ++a)
      for (auto* f : {&mom[a], &force[a], &vel[a], &mom2[a]}) f->assign(count, 0);
  }
  std::ptrdiff_t stride(int a) const {
    return a == 0 ? 1 : a == 1 ? dims[0] : static_cast<std::ptrdiff_t>(dims[0]) * dims[1];
  }
  AmpmNodeBox box() const {
    AmpmNodeBox b;
    for (int a = 0; a < 3; ++a) b.lo[a] = lo[a], b.dims[a] = dims[a];
    return b;
  }
  typename Api<T, D>::Channel out(std::vector<T>& f) const {
    typename Api<T, D>::Channel c;
    c.data = f.data();
    for (int a = 0; a < 3; ++a) c.stride[a] = stride(a);
    return c;
  }
  typename Api<T, D>::ConstChannel in(const std::vector<T>& f) const {
    typename Api<T, D>::ConstChannel c;
    c.data = f.data();
    for (int a = 0; a < 3; ++a) c.stride[a] = stride(a);
    return c;
  }
  static typename Api<T, D>::Channel none() {
    typename Api<T, D>::Channel c;
    c.data = nullptr;
    for (int a = 0; a < 3; ++a) c.stride[a] = 0;
    return c;
  }
  /// Linear index of grid node `i` (must be inside the box).
  std::size_t at(const int* i) const {
    std::size_t k = 0;
    for (int a = D - 1; a >= 0; --a) k = k * dims[a] + static_cast<std::size_t>(i[a] - lo[a]);
    return k;
  }
  void node(std::size_t k, int* i) const {
    for (int a = 0; a < D; ++a) {
      i[a] = lo[a] + static_cast<int>(k % static_cast<std::size_t>(dims[a]));
      k /= static_cast<std::size_t>(dims[a]);
    }
  }
};

template <class T>
T det2(const T* f) {
  return f[0] * f[3] - f[2] * f[1];
}
template <class T>
T det3(const T* f) {  // column-major f[i + 3j]
  return f[0] * (f[4] * f[8] - f[7] * f[5]) - f[3] * (f[1] * f[8] - f[7] * f[2]) +
         f[6] * (f[1] * f[5] - f[4] * f[2]);
}
template <class T, int D>
T det(const T* f) {
  return D == 2 ? det2(f) : det3(f);
}

struct Scene {
  unsigned model = 0;
  double mu = 2e4, lambda = 3e4, rho = 1000, h = 0.1;
  double c_s = 2, c_l = 4, k_s = 0, k_l = 0, tm = 273, latent = 0, flip = 0;
  int per_axis = 0;  // particles per axis of the block
  int steps = 40;
  double t_init = 300;
  bool warm_ambient = false;
  double t_ambient = 0;
  bool moving = true;
};

template <class T, int D>
typename Api<T, D>::Material material(const Scene& s) {
  typename Api<T, D>::Material m{};
  m.model = s.model;
  m.solid.mu = static_cast<T>(s.mu);
  m.solid.inv_lambda = static_cast<T>(1 / s.lambda);
  m.solid.heat_capacity = static_cast<T>(s.c_s);
  m.solid.conductivity = static_cast<T>(s.k_s);
  m.liquid.mu = 0;
  m.liquid.inv_lambda = static_cast<T>(1 / s.lambda);
  m.liquid.heat_capacity = static_cast<T>(s.c_l);
  m.liquid.conductivity = static_cast<T>(s.k_l);
  m.flip = static_cast<T>(s.flip);
  m.melting_point = static_cast<T>(s.tm);
  m.latent_heat = static_cast<T>(s.latent);
  return m;
}

/// The block: per_axis^d particles, spacing h/2, starting at −0.3 m on every axis (negative
/// node indices), with a rigid rotation, a stretch and a small random part of the velocity,
/// the matching APIC C, F_E = F_P = I. Temperature t_init, or 250 K / 350 K on either half.
template <class T, int D>
void make_block(const Scene& s, Particles<T, D>& p, bool halves, std::mt19937_64& rng) {
  int np = 1;
  for (int a = 0; a < D; ++a) np *= s.per_axis;
  p.resize(static_cast<std::size_t>(np));
  const double sp = s.h / 2, x0 = -0.3;
  const double centre = x0 + sp * (s.per_axis - 1) / 2;
  std::uniform_real_distribution<double> uni(-1, 1);
  // ∇v of the smooth part: rotation ω plus a traceless stretch.
  double g[3][3] = {{0.3, -0.8, 0.2}, {0.8, -0.2, -0.5}, {-0.2, 0.5, -0.1}};
  if (D == 2) g[0][0] = 0.3, g[1][1] = -0.3, g[0][1] = -0.8, g[1][0] = 0.8;
  const double v_lin[3] = {0.5, -0.3, 0.2};
  for (int k = 0; k < np; ++k) {
    int idx[3] = {0, 0, 0};
    for (int a = 0, q = k; a < D; ++a, q /= s.per_axis) idx[a] = q % s.per_axis;
    double r[3] = {0, 0, 0};
    for (int a = 0; a < D; ++a) {
      const double xa = x0 + sp * idx[a] + 0.25 * sp * uni(rng);
      p.x[D * k + a] = static_cast<T>(xa);
      r[a] = xa - centre;
    }
    for (int a = 0; a < D; ++a) {
      double va = s.moving ? v_lin[a] : 0;
      for (int b = 0; b < D; ++b) {
        if (s.moving) va += g[a][b] * r[b];
        p.c[D * D * k + a + D * b] = static_cast<T>(s.moving ? g[a][b] : 0);
      }
      if (s.moving) va += 0.05 * uni(rng);
      p.v[D * k + a] = static_cast<T>(va);
      p.fe[D * D * k + a * (D + 1)] = 1;
      p.fp[D * D * k + a * (D + 1)] = 1;
    }
    double vol = 1;
    for (int a = 0; a < D; ++a) vol *= sp;
    p.v0[k] = static_cast<T>(vol);
    p.m[k] = static_cast<T>(s.rho * vol);
    p.t[k] = static_cast<T>(halves ? (r[0] < 0 ? 250.0 : 350.0) : s.t_init);
    p.u[k] = 0;
    p.ph[k] = AMPM_PHASE_SOLID;
  }
}

/// Per-axis sums.
struct Vec3 {
  ld a[3] = {0, 0, 0};
};

/// The enthalpy per unit mass of a thermal state (see the file comment).
ld enthalpy(ld t, ld u, int phase, ld c_s, ld c_l, ld tm, ld latent) {
  if (phase == AMPM_PHASE_SOLID && t < tm) return c_s * (t - tm);
  if (phase == AMPM_PHASE_LIQUID && t > tm) return latent + c_l * (t - tm);
  return u;
}

/// One run of the host loop; `thermal` selects the heat checks, `melt` the phase-change ones.
template <class T, int D>
void run(const Scene& s, const char* label) {
  using A = Api<T, D>;
  const auto t_start = std::chrono::steady_clock::now();
  constexpr int KD = stencil_nodes<D>();
  const ld eps = std::numeric_limits<T>::epsilon();
  const bool thermal = (s.model & AMPM_MODEL_THERMAL) != 0;
  const bool melt = (s.model & AMPM_MODEL_PHASE_CHANGE) != 0;
  std::mt19937_64 rng(0x40571007 + 10 * D);
  Particles<T, D> p;
  make_block<T, D>(s, p, thermal && !melt, rng);
  const std::size_t n = p.n;
  auto pv = p.view();
  const auto mat = material<T, D>(s);
  const T h = static_cast<T>(s.h);
  // Δt: a quarter of the elastic wave's cell-crossing time (explicit stability).
  const double wave = std::sqrt((s.lambda + 2 * s.mu) / s.rho);
  const T dt = static_cast<T>(0.25 * s.h / (wave + 2.0));
  const unsigned kernel = AMPM_KERNEL_QUADRATIC;
  Grid<T, D> g;
  double hd = 1;
  for (int a = 0; a < D; ++a) hd *= s.h;
  const ld m_full = s.rho * hd;  // mass of a full cell

  Vec3 p0;
  ld sum_m = 0;
  for (std::size_t i = 0; i < n; ++i) {
    sum_m += p.m[i];
    for (int a = 0; a < D; ++a) p0.a[a] += static_cast<ld>(p.m[i]) * p.v[D * i + a];
  }
  Vec3 budget;  // Σ over the steps of the per-step momentum bounds
  ld heat_budget = 0, heat0 = 0;
  for (std::size_t i = 0; i < n; ++i)
    heat0 += static_cast<ld>(p.m[i]) * (p.ph[i] ? s.c_l : s.c_s) * p.t[i];
  ld t_max0 = 0, t_min0 = 1e30L;
  for (std::size_t i = 0; i < n; ++i) t_max0 = std::max<ld>(t_max0, p.t[i]), t_min0 = std::min<ld>(t_min0, p.t[i]);
  ld q_in_total = 0, enthalpy_change_total = 0, melt_budget = 0;
  std::vector<int> base(n * D);
  std::vector<T> w(n * KD), gw(n * KD * D);

  for (int step = 0; step < s.steps; ++step) {
    // ---- the node box and the host's arrays ----
    int lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0};
    CHECK_OK([&](std::size_t* f) { return A::node_range(kernel, AMPM_GRID_COLLOCATED, h, n, p.x.data(), lo, hi, f); }, n);
    g.reset(lo, hi);
    CHECK_OK([&](std::size_t* f) { return A::stencil(kernel, AMPM_GRID_COLLOCATED, h, n, p.x.data(), base.data(), w.data(), gw.data(), f); }, n);
    std::vector<int> share(g.count, 0);
    int n_add = 0;
    for (std::size_t i = 0; i < n; ++i)
      for (int r = 0; r < KD; ++r) {
        int idx[3] = {0, 0, 0};
        for (int a = 0, q = r; a < D; ++a, q /= K1) idx[a] = base[D * i + a] + q % K1;
        n_add = std::max(n_add, ++share[g.at(idx)]);
      }
    const ld c_p = n_add + KD + 6 * D + 8;

    // ---- P2G ----
    typename A::P2gView pview{};
    pview.nodes = g.box();
    pview.mass = g.out(g.mass);
    for (int a = 0; a < 3; ++a) {
      pview.momentum[a] = a < D ? g.out(g.mom[a]) : Grid<T, D>::none();
      pview.force[a] = a < D ? g.out(g.force[a]) : Grid<T, D>::none();
    }
    pview.heat_capacity = thermal ? g.out(g.hc) : Grid<T, D>::none();
    pview.thermal_energy = thermal ? g.out(g.te) : Grid<T, D>::none();
    pview.conductivity = thermal ? g.out(g.cond) : Grid<T, D>::none();
    CHECK_OK([&](std::size_t* f) { return A::p2g(&mat, kernel, AMPM_GRID_COLLOCATED, h, T(0), n, &pv, &pview, f); }, n);

    // The symplectic form: impulse_dt = Δt, no force channel.
    typename A::P2gView iview{};
    iview.nodes = g.box();
    iview.mass = Grid<T, D>::none();
    for (int a = 0; a < 3; ++a) {
      iview.momentum[a] = a < D ? g.out(g.mom2[a]) : Grid<T, D>::none();
      iview.force[a] = Grid<T, D>::none();
    }
    iview.heat_capacity = iview.thermal_energy = iview.conductivity = Grid<T, D>::none();
    CHECK_OK([&](std::size_t* f) { return A::p2g(&mat, kernel, AMPM_GRID_COLLOCATED, h, dt, n, &pv, &iview, f); }, n);

    // Σ_p Σ_i |f_ip| by a one-particle P2G of each particle into a view of its own stencil.
    Vec3 fabs_sum;
    {
      std::vector<T> fs[3];
      for (int a = 0; a < D; ++a) fs[a].assign(KD, 0);
      for (std::size_t i = 0; i < n; ++i) {
        typename A::P2gView one{};
        for (int a = 0; a < 3; ++a) {
          one.nodes.lo[a] = a < D ? base[D * i + a] : 0;
          one.nodes.dims[a] = a < D ? K1 : 1;
        }
        one.mass = Grid<T, D>::none();
        for (int a = 0; a < 3; ++a) {
          one.momentum[a] = Grid<T, D>::none();
          one.force[a] = Grid<T, D>::none();
          if (a < D) {
            std::fill(fs[a].begin(), fs[a].end(), T(0));
            one.force[a].data = fs[a].data();
            one.force[a].stride[0] = 1, one.force[a].stride[1] = K1, one.force[a].stride[2] = K1 * K1;
          }
        }
        one.heat_capacity = one.thermal_energy = one.conductivity = Grid<T, D>::none();
        typename A::Particles pi = pv;
        pi.x += D * i, pi.v += D * i, pi.affine += D * D * i, pi.f_e += D * D * i, pi.f_p += D * D * i;
        pi.mass += i, pi.volume0 += i, pi.temperature += i, pi.latent += i, pi.phase += i;
        CHECK_OK([&](std::size_t* f) { return A::p2g(&mat, kernel, AMPM_GRID_COLLOCATED, h, T(0), 1, &pi, &one, f); }, 1u);
        for (int a = 0; a < D; ++a)
          for (int r = 0; r < KD; ++r) fabs_sum.a[a] += std::fabs(static_cast<ld>(fs[a][r]));
      }
    }

    // Mass and momentum after P2G.
    ld grid_m = 0;
    Vec3 grid_p, grid_f, part_p, s_abs;
    for (std::size_t k = 0; k < g.count; ++k) {
      grid_m += g.mass[k];
      for (int a = 0; a < D; ++a) grid_p.a[a] += g.mom[a][k], grid_f.a[a] += g.force[a][k];
    }
    for (std::size_t i = 0; i < n; ++i)
      for (int a = 0; a < D; ++a) {
        part_p.a[a] += static_cast<ld>(p.m[i]) * p.v[D * i + a];
        ld cs = 0;
        for (int b = 0; b < D; ++b) cs += std::fabs(static_cast<ld>(p.c[D * D * i + a + D * b]));
        s_abs.a[a] += static_cast<ld>(p.m[i]) * (std::fabs(static_cast<ld>(p.v[D * i + a])) + 3.5L * h * cs);
      }
    const ld tol_m = (n_add + KD + 6 * D) * eps * sum_m;
    CHECK(std::fabs(grid_m - sum_m) <= tol_m, "%s %s step %d: grid mass %.12Le, particles %.12Le (tol %.3Le)",
          A::name, label, step, grid_m, sum_m, tol_m);
    for (int a = 0; a < D; ++a) {
      const ld tp = c_p * eps * s_abs.a[a], tf = c_p * eps * fabs_sum.a[a];
      CHECK(std::fabs(grid_p.a[a] - part_p.a[a]) <= tp, "%s %s step %d axis %d: P2G momentum %.12Le vs %.12Le (tol %.3Le)",
            A::name, label, step, a, grid_p.a[a], part_p.a[a], tp);
      CHECK(std::fabs(grid_f.a[a]) <= tf, "%s %s step %d axis %d: Σ f = %.3Le (tol %.3Le)", A::name, label, step, a,
            grid_f.a[a], tf);
      ld diff = 0;
      for (std::size_t k = 0; k < g.count; ++k)
        diff += std::fabs(static_cast<ld>(g.mom2[a][k]) - (static_cast<ld>(g.mom[a][k]) + static_cast<ld>(dt) * g.force[a][k]));
      const ld ti = 2 * (c_p + 2) * eps * (s_abs.a[a] + dt * fabs_sum.a[a]);
      CHECK(diff <= ti, "%s %s step %d axis %d: impulse P2G differs from p + dt f by %.3Le (tol %.3Le)", A::name, label,
            step, a, diff, ti);
      budget.a[a] += (2 * n_add + 2 * KD + 6 * D + 13) * eps * (s_abs.a[a] + dt * fabs_sum.a[a]);
    }

    // ---- grid update: free flight ----
    for (std::size_t k = 0; k < g.count; ++k)
      for (int a = 0; a < D; ++a)
        g.vel[a][k] = g.mass[k] > 0 ? (g.mom[a][k] + dt * g.force[a][k]) / g.mass[k] : T(0);

    // ---- heat on the grid ----
    ld heat_p2g = 0, heat_part = 0, heat_grid_new = 0, q_in = 0;
    if (thermal) {
      ld hc_sum = 0, mc_sum = 0;
      for (std::size_t i = 0; i < n; ++i) {
        const ld c = p.ph[i] ? s.c_l : s.c_s;
        heat_part += static_cast<ld>(p.m[i]) * c * p.t[i];
        mc_sum += static_cast<ld>(p.m[i]) * c;
      }
      for (std::size_t k = 0; k < g.count; ++k) heat_p2g += g.te[k], hc_sum += g.hc[k];
      const ld c_h = n_add + KD + 6 * D + 4;
      CHECK(std::fabs(heat_p2g - heat_part) <= c_h * eps * heat_part,
            "%s %s step %d: P2G heat %.12Le vs particles %.12Le", A::name, label, step, heat_p2g, heat_part);
      CHECK(std::fabs(hc_sum - mc_sum) <= c_h * eps * mc_sum, "%s %s step %d: P2G heat capacity %.12Le vs %.12Le",
            A::name, label, step, hc_sum, mc_sum);
      heat_budget += c_h * eps * heat_part;

      // T_i, κ_i, θ_i; massless nodes get T = 0 (finite: G2P may read a node of zero weight).
      std::vector<T> e(g.count), kap(g.count), theta(g.count);
      for (std::size_t k = 0; k < g.count; ++k) {
        const bool massive = g.mass[k] > 0;
        g.told[k] = massive ? g.te[k] / g.hc[k] : T(0);
        e[k] = massive ? g.te[k] : T(0);
        kap[k] = massive ? g.cond[k] / g.mass[k] : T(0);
        theta[k] = massive ? static_cast<T>(std::min<ld>(1, g.mass[k] / m_full)) : T(0);
      }
      // Face coefficients: the neighbour of node k along +a, if both have mass; and the
      // ambient coupling of a massive node across each face whose neighbour has none.
      const T hd2 = static_cast<T>(std::pow(s.h, D - 2));
      auto neighbour = [&](std::size_t k, int a, int dir, std::size_t* out) {
        int idx[3] = {0, 0, 0};
        g.node(k, idx);
        idx[a] += dir;
        if (idx[a] < g.lo[a] || idx[a] >= g.lo[a] + g.dims[a]) return false;
        *out = g.at(idx);
        return true;
      };
      std::vector<T> ksum(g.count, 0);
      for (std::size_t k = 0; k < g.count; ++k) {
        if (!(g.mass[k] > 0)) continue;
        for (int a = 0; a < D; ++a)
          for (int dir : {-1, 1}) {
            std::size_t j = 0;
            const bool in = neighbour(k, a, dir, &j);
            if (in && g.mass[j] > 0)
              ksum[k] += hd2 * T(0.5) * (kap[k] + kap[j]) * std::min(theta[k], theta[j]);
            else if (s.warm_ambient)
              ksum[k] += hd2 * kap[k] * theta[k];
          }
      }
      ld limit = std::numeric_limits<ld>::infinity();
      for (std::size_t k = 0; k < g.count; ++k)
        if (g.mass[k] > 0 && ksum[k] > 0) limit = std::min<ld>(limit, static_cast<ld>(g.hc[k]) / ksum[k]);
      const int n_sub = std::max(1, static_cast<int>(std::ceil(dt / (0.5L * limit))));
      const T dth = dt / static_cast<T>(n_sub);
      std::vector<T> tt(g.count);
      for (int sub = 0; sub < n_sub; ++sub) {
        for (std::size_t k = 0; k < g.count; ++k) tt[k] = g.mass[k] > 0 ? e[k] / g.hc[k] : T(0);
        ld e_before = 0, flux_abs = 0;
        for (std::size_t k = 0; k < g.count; ++k) e_before += e[k];
        for (std::size_t k = 0; k < g.count; ++k) {
          if (!(g.mass[k] > 0)) continue;
          for (int a = 0; a < D; ++a) {
            std::size_t j = 0;
            const bool in_up = neighbour(k, a, +1, &j);
            if (in_up && g.mass[j] > 0) {
              const T phi = dth * (hd2 * T(0.5) * (kap[k] + kap[j]) * std::min(theta[k], theta[j])) * (tt[j] - tt[k]);
              e[k] += phi, e[j] -= phi;
              flux_abs += 2 * std::fabs(static_cast<ld>(phi));
            }
            if (!s.warm_ambient) continue;
            for (int dir : {-1, 1}) {
              std::size_t jj = 0;
              const bool in = neighbour(k, a, dir, &jj);
              if (!in || !(g.mass[jj] > 0)) {
                const T phi = dth * (hd2 * kap[k] * theta[k]) * (static_cast<T>(s.t_ambient) - tt[k]);
                e[k] += phi;
                q_in += phi;
                flux_abs += std::fabs(static_cast<ld>(phi));
              }
            }
          }
        }
        ld e_after = 0;
        for (std::size_t k = 0; k < g.count; ++k) e_after += e[k];
        const ld tol_d = (2 * D + 1) * eps * (e_before + flux_abs);
        if (!s.warm_ambient)
          CHECK(std::fabs(e_after - e_before) <= tol_d, "%s %s step %d: diffusion changed Σ E by %.3Le (tol %.3Le)",
                A::name, label, step, e_after - e_before, tol_d);
        heat_budget += tol_d;
      }
      if (s.warm_ambient) {
        // Σ E changed by exactly the injected heat, up to the rounding of the additions.
        ld e_new = 0;
        for (std::size_t k = 0; k < g.count; ++k) e_new += e[k];
        const ld tol = n_sub * (2 * D + 1) * eps * (heat_p2g + std::fabs(q_in)) * 2;
        CHECK(std::fabs(e_new - heat_p2g - q_in) <= tol, "%s %s step %d: Σ E changed by %.12Le, injected %.12Le",
              A::name, label, step, e_new - heat_p2g, q_in);
      }
      for (std::size_t k = 0; k < g.count; ++k) {
        g.tnew[k] = g.mass[k] > 0 ? e[k] / g.hc[k] : T(0);
        heat_grid_new += static_cast<ld>(g.hc[k]) * g.tnew[k];
      }
    }

    // ---- the host's own T*_p and q_p (phase change), before G2P ----
    std::vector<ld> q_host(n, 0), e_before(n, 0);
    if (melt) {
      for (std::size_t i = 0; i < n; ++i) {
        ld pic = 0, fl = 0;
        for (int r = 0; r < KD; ++r) {
          int idx[3] = {0, 0, 0};
          for (int a = 0, q = r; a < D; ++a, q /= K1) idx[a] = base[D * i + a] + q % K1;
          const std::size_t k = g.at(idx);
          pic += static_cast<ld>(w[KD * i + r]) * g.tnew[k];
          fl += static_cast<ld>(w[KD * i + r]) * (static_cast<ld>(g.tnew[k]) - g.told[k]);
        }
        const ld tstar = (1 - s.flip) * pic + s.flip * (p.t[i] + fl);
        q_host[i] = (p.ph[i] ? s.c_l : s.c_s) * (tstar - p.t[i]);
        e_before[i] = enthalpy(p.t[i], p.u[i], p.ph[i], s.c_s, s.c_l, s.tm, s.latent);
      }
    }

    // ---- G2P ----
    typename A::G2pView gview{};
    gview.nodes = g.box();
    for (int a = 0; a < 3; ++a) {
      gview.velocity[a].data = a < D ? g.vel[a].data() : nullptr;
      for (int b = 0; b < 3; ++b) gview.velocity[a].stride[b] = g.stride(b);
    }
    gview.temperature = g.in(g.tnew);
    gview.temperature_old = g.in(g.told);
    Vec3 grid_mv, grid_mv_abs;
    for (std::size_t k = 0; k < g.count; ++k)
      for (int a = 0; a < D; ++a) {
        grid_mv.a[a] += static_cast<ld>(g.mass[k]) * g.vel[a][k];
        grid_mv_abs.a[a] += std::fabs(static_cast<ld>(g.mass[k]) * g.vel[a][k]);
      }
    CHECK_OK([&](std::size_t* f) { return A::g2p(&mat, kernel, h, dt, n, &pv, &gview, f); }, n);

    // ---- after the step ----
    Vec3 pt;
    bool finite = true, positive = true;
    for (std::size_t i = 0; i < n; ++i) {
      for (int a = 0; a < D; ++a) {
        pt.a[a] += static_cast<ld>(p.m[i]) * p.v[D * i + a];
        finite &= std::isfinite(p.x[D * i + a]) && std::isfinite(p.v[D * i + a]);
      }
      for (int k = 0; k < D * D; ++k)
        finite &= std::isfinite(p.c[D * D * i + k]) && std::isfinite(p.fe[D * D * i + k]) &&
                  std::isfinite(p.fp[D * D * i + k]);
      finite &= std::isfinite(p.t[i]) && std::isfinite(p.u[i]);
      const T je = det<T, D>(&p.fe[D * D * i]), jp = det<T, D>(&p.fp[D * D * i]);
      positive &= je > 0 && jp > 0 && je * jp > 0;
    }
    CHECK(finite, "%s %s step %d: a particle field is not finite", A::name, label, step);
    CHECK(positive, "%s %s step %d: J_E·J_P <= 0", A::name, label, step);
    for (int a = 0; a < D; ++a) {
      const ld tg = (n_add + KD + 4) * eps * grid_mv_abs.a[a];
      CHECK(std::fabs(pt.a[a] - grid_mv.a[a]) <= tg, "%s %s step %d axis %d: G2P momentum %.12Le vs grid %.12Le (tol %.3Le)",
            A::name, label, step, a, pt.a[a], grid_mv.a[a], tg);
      CHECK(std::fabs(pt.a[a] - p0.a[a]) <= budget.a[a], "%s %s step %d axis %d: momentum %.12Le, initial %.12Le (tol %.3Le)",
            A::name, label, step, a, pt.a[a], p0.a[a], budget.a[a]);
    }
    if (thermal && !melt) {
      ld heat_after = 0, tmax = 0, tmin = 1e30L;
      for (std::size_t i = 0; i < n; ++i) {
        heat_after += static_cast<ld>(p.m[i]) * s.c_s * p.t[i];
        tmax = std::max<ld>(tmax, p.t[i]), tmin = std::min<ld>(tmin, p.t[i]);
      }
      const ld tol_g = (2 * n_add + KD + 6 * D + 10) * eps * heat_after;
      CHECK(std::fabs(heat_after - heat_grid_new) <= tol_g, "%s %s step %d: G2P heat %.12Le vs grid %.12Le (tol %.3Le)",
            A::name, label, step, heat_after, heat_grid_new, tol_g);
      heat_budget += tol_g;
      CHECK(std::fabs(heat_after - heat0) <= heat_budget, "%s %s step %d: total heat %.12Le, initial %.12Le (tol %.3Le)",
            A::name, label, step, heat_after, heat0, heat_budget);
      if (s.flip == 0) {
        // Max principle: P2G, the monotone diffusion and PIC G2P are convex combinations.
        const ld slack = (2 * KD + 16) * eps * 350;
        CHECK(tmax <= t_max0 + slack && tmin >= t_min0 - slack, "%s %s step %d: T range [%.9Lf, %.9Lf] left [%.9Lf, %.9Lf]",
              A::name, label, step, tmin, tmax, t_min0, t_max0);
        t_max0 = tmax, t_min0 = tmin;
      }
    }
    if (melt) {
      const ld c_max = std::max(s.c_s, s.c_l);
      ld dsum = 0, qsum = 0, tol_sum = 0;
      for (std::size_t i = 0; i < n; ++i) {
        const ld e_after = enthalpy(p.t[i], p.u[i], p.ph[i], s.c_s, s.c_l, s.tm, s.latent);
        const ld t_scale = std::max<ld>({std::fabs(static_cast<ld>(p.t[i])), s.tm, s.t_ambient});
        const ld tol = eps * ((2 * KD + 28) * c_max * t_scale + 14 * s.latent);
        CHECK(std::fabs((e_after - e_before[i]) - q_host[i]) <= tol,
              "%s %s step %d particle %zu: Δe = %.12Le, q = %.12Le (tol %.3Le)", A::name, label, step, i,
              e_after - e_before[i], q_host[i], tol);
        // The library's invariants of the thermal state.
        const bool ok = p.u[i] >= 0 && p.u[i] <= static_cast<T>(s.latent) &&
                        (p.ph[i] == AMPM_PHASE_SOLID
                             ? (p.t[i] < static_cast<T>(s.tm) && p.u[i] == 0) || p.t[i] == static_cast<T>(s.tm)
                             : (p.t[i] > static_cast<T>(s.tm) && p.u[i] == static_cast<T>(s.latent)) ||
                                   p.t[i] == static_cast<T>(s.tm));
        CHECK(ok, "%s %s step %d particle %zu: thermal state T %.9g U %.9g phase %d", A::name, label, step, i,
              double(p.t[i]), double(p.u[i]), int(p.ph[i]));
        dsum += static_cast<ld>(p.m[i]) * (e_after - e_before[i]);
        qsum += static_cast<ld>(p.m[i]) * q_host[i];
        tol_sum += static_cast<ld>(p.m[i]) * tol;
      }
      // Σ m q = Σ_i E^new − Σ_i E^P2G = Q_in (PIC), with the grid-side bounds.
      const ld tol_grid = (n_add + KD + 6 * D + 4 + 2 * n_add + KD + 6 * D + 10) * eps * heat_part +
                          (2 * D + 1) * eps * 4 * (heat_p2g + std::fabs(q_in));
      CHECK(std::fabs(qsum - q_in) <= tol_grid + tol_sum, "%s %s step %d: Σ m q = %.12Le, injected %.12Le (tol %.3Le)",
            A::name, label, step, qsum, q_in, tol_grid + tol_sum);
      q_in_total += q_in;
      enthalpy_change_total += dsum;
      melt_budget += tol_grid + 2 * tol_sum;
      CHECK(std::fabs(enthalpy_change_total - q_in_total) <= melt_budget,
            "%s %s step %d: Σ m Δe = %.12Le, Σ Q_in = %.12Le (tol %.3Le)", A::name, label, step, enthalpy_change_total,
            q_in_total, melt_budget);
    }
  }
  if (melt) {
    std::size_t liquid = 0, at_tm = 0;
    for (std::size_t i = 0; i < n; ++i) {
      liquid += p.ph[i] == AMPM_PHASE_LIQUID;
      at_tm += p.t[i] == static_cast<T>(s.tm);
    }
    std::printf("  %s %s: %zu of %zu particles liquid, %zu at T_m, heat injected %.6Lg J\n", A::name, label, liquid, n,
                at_tm, q_in_total);
    CHECK(liquid > 0, "%s %s: no particle melted", A::name, label);
    CHECK(liquid < n, "%s %s: every particle melted (the test wants both phases)", A::name, label);
  }
  std::printf("  %s %s: %zu particles, %d steps, %.2f s\n", A::name, label, n, s.steps,
              std::chrono::duration<double>(std::chrono::steady_clock::now() - t_start).count());
}

template <class T, int D>
void all() {
  Scene mech;
  mech.model = 0;
  mech.per_axis = D == 2 ? 24 : 10;
  run<T, D>(mech, "elastic free flight");

  for (double flip : {0.0, 1.0}) {
    Scene heat = mech;
    heat.model = AMPM_MODEL_THERMAL;
    heat.k_s = 200;
    heat.flip = flip;
    run<T, D>(heat, flip == 0 ? "heat, PIC" : "heat, FLIP");
  }

  Scene ice;
  ice.model = AMPM_MODEL_THERMAL | AMPM_MODEL_PHASE_CHANGE;
  ice.per_axis = D == 2 ? 16 : 8;
  ice.k_s = ice.k_l = D == 2 ? 1000 : 400;
  ice.steps = 60;
  ice.c_s = 2, ice.c_l = 4, ice.latent = 40, ice.tm = 273;
  ice.t_init = 260;
  ice.warm_ambient = true;
  ice.t_ambient = 500;
  ice.moving = false;
  ice.flip = 0;
  run<T, D>(ice, "ice block, warm ambient");
}

}  // namespace

int main() {
  all<float, 2>();
  all<double, 2>();
  all<float, 3>();
  all<double, 3>();
  std::printf("test_host_loop: %ld checks, %ld failures\n", g_checks, g_failures);
  return g_failures == 0 ? 0 : 1;
}
