// Benchmark of the particle transfers of include/ampm.h in a host's time-step loop, against the
// loop a host would write itself with Eigen, in one run (`docs/bench-transfers.md`).
//
//   bench_transfers [--out FILE] [--reps R]   time every case, markdown table to stdout and FILE
//                                             (default docs/bench-transfers.md)
//   bench_transfers --check                   tiny sizes, agreement checks only (for ctest)
//   bench_transfers --ab A.so B.so [--reps R] two builds of libampm.so, loaded with dlopen, timed
//                                             alternately call by call (A/B comparison)
//
// Workload (fixed seed): a block of particles, 2 per cell per axis (spacing h/2, jittered by
// ±h/8), 38³ = 54,872 particles in 3D and 234² = 54,756 in 2D, h = 1 cm, quadratic B-splines,
// the collocated grid sized to the block by ampm_node_range_*, dense x-fastest arrays. The
// particles are shuffled, then sorted by cell (x fastest) as a host does before its transfers.
// Scene levels (AmpmMaterial):
//   elastic   solid, fixed corotated, explicit dilation (μ = λ = 1e5 Pa), F_E = R1 diag(σ) R2,
//             σ in [0.95, 1.05];
//   fluid     liquid particles (μ = 0), explicit dilation λ = 1e5 Pa, F_E = J^(1/d) I;
//   thermal   AMPM_MODEL_THERMAL | AMPM_MODEL_PHASE_CHANGE, ice at 260 K, particles at the
//             melting point with a half-filled latent buffer, water at 290 K; the grid is 0.5 K
//             warmer after the host's (stand-in) heat step, FLIP 0.95;
//   snow      AMPM_MODEL_PLASTIC (θ_c = 0.025, θ_s = 0.0075, ξ = 10), σ near the clamp.
// Timed, one thread, std::chrono::steady_clock, one warm-up run and the median of R = 7 runs
// (--reps), in ns per particle per step:
//   P2G sym     ampm_p2g_* with impulse_dt = Δt and no force channel (m v* + Δt f into the
//               momentum channel: the symplectic-Euler form), plus heat channels when thermal;
//   P2G +f      ampm_p2g_* with impulse_dt = 0 and separate force channels;
//   grid        the host's grid update (v = p/m; T = E/C), not library time, reported per
//               particle for comparison;
//   G2P         ampm_g2p_update_* (the particle state is restored between runs, untimed);
//   step        zeroing the grid + P2G sym + grid update + G2P, everything a step does;
//   lib         P2G sym + G2P, the library's share of a step (the targets are on this);
//   prepare     ampm_force_prepare_* with AMPM_MODEL_PSD_HESSIAN (once per Newton step);
//   apply       zeroing df + ampm_force_apply_* (once per CG iteration).
// Every case runs on every instruction set ampm_set_isa accepts (AVX-512, AVX2, scalar).
// Eigen baseline (elastic 3D f32): the same P2G sym + G2P loop written by hand as a host
// would: per particle one Eigen::JacobiSVD (full U, V) for the polar decomposition of the
// stress, the same B-spline loops, the same grid arrays, built with the flags below. It is timed
// alternately with the library's P2G sym and G2P, call by call, so that a change of the machine's
// speed during the run (other tenants of a virtual machine) affects both alike.
// Hardware limit (elastic, 3D and 2D f32; c_tests/bench_floor.hpp): the memory floor (the
// bytes of each call's interface streamed once) and the arithmetic floor (the node loops'
// FMAs at the measured FMA rate), timed in the same run and set against the library and the
// baseline.
//
// ampm.hpp (zero-cost check): the elastic 3D f32 step (zeroing + P2G sym + grid + G2P) written
// against the C++ wrapper include/ampm.hpp (Material, Particles and view builders, ampm::p2g,
// ampm::g2p_update; builders made where the C path fills its structs) is timed in the same run,
// alternating with the C step rep by rep on the default instruction set; the ratio hpp / C of
// the medians is reported (≈ 1.00 when the wrapper costs nothing). Before timing, and in
// --check, the wrapper's step must give bit-identical grids and particles to the C step.
//
// Block calls (elastic and fluid 3D f32, elastic 2D f32, default instruction set): lib and apply
// with the particles in calls of 4096, 512 and 64 consecutive particles (a threaded host's
// blocks; every call into the same grid views) against one call, the sizes alternating rep by
// rep; the report gives the ratio to one call and the cost per extra call. Before timing, G2P
// in calls of 64 must leave the particles bit-identical to one call (a particle's result does
// not depend on the batch it is in).
//
// --ab: two builds of the library (say, before and after a change) in one process, each
// loaded from its own libampm.so with dlopen (its own copy of the library's state). For every
// scene but snow, 3D and 2D f32, every instruction set both accept: lib (P2G sym + G2P, each
// build its own P2G, grid update and G2P), prepare and apply (zeroing df + apply), the two
// builds alternating rep by rep (which goes first alternates too), so that both see the same
// machine state; medians of R reps (default 31) and the ratio B / A. A change of a few
// percent, below the spread between separate runs of the benchmark, shows in the ratio. Both
// builds must return AMPM_OK and the same results, bit for bit (P2G's node channels; G2P's
// particle positions, velocities, C, F_E, F_P, temperatures, latent buffers and phases;
// prepare's slots; apply's forces), checked before timing: a performance change must not
// change them.
//
// --check (and every timing run, before timing): on tiny blocks (6³, 14²), every call returns
// AMPM_OK with first_failed = n and finite results; for the elastic scene the library's and the
// baseline's P2G grids and G2P particles agree with the same loop evaluated in long double
// (tolerances C·ε·scale as in c_tests/test_particle_eigen.cpp: C = 256 + n_add for node sums
// involving the stress, 64 + 2·K^d + n_add otherwise, scale = the sum of the magnitudes of the
// terms); P2G sym equals P2G +f's momentum + Δt·force to the same bound; AVX2 and AVX-512 give
// bit-identical grids and prepared slots, the scalar path agrees to the bound.
#include <cstddef>
#include <cstdint>

#include "ampm.h"

#include <Eigen/Dense>

#include "ampm.hpp"

#include <dlfcn.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <limits>
#include <numeric>
#include <random>
#include <sstream>
#include <string>
#include <thread>
#include <type_traits>
#include <utility>
#include <vector>

#include "bench_floor.hpp"

namespace {

using ld = long double;

constexpr std::uint64_t kSeed = 0xbe4c'7a25'f3e5'0001ULL;
constexpr int kDefaultReps = 7;
constexpr int K1 = 3;  // quadratic: 3 nodes per axis

// ---- the C symbols by (scalar, dimension) --------------------------------------------------

template <class T, int D>
struct Api;

#define BENCH_API(T, D, S)                                              \
  template <>                                                           \
  struct Api<T, D> {                                                    \
    static constexpr const char* name = #D "D " #S;                     \
    static constexpr auto p2g = ampm_p2g_##D##d_##S;                    \
    static constexpr auto g2p = ampm_g2p_update_##D##d_##S;             \
    static constexpr auto node_range = ampm_node_range_##D##d_##S;      \
    static constexpr auto prepare = ampm_force_prepare_##D##d_##S;      \
    static constexpr auto apply = ampm_force_apply_##D##d_##S;          \
    /* The same symbols by name, for a build loaded with dlopen (--ab). */ \
    static constexpr const char* p2g_sym = "ampm_p2g_" #D "d_" #S;      \
    static constexpr const char* g2p_sym = "ampm_g2p_update_" #D "d_" #S; \
    static constexpr const char* prepare_sym = "ampm_force_prepare_" #D "d_" #S; \
    static constexpr const char* apply_sym = "ampm_force_apply_" #D "d_" #S; \
    static constexpr std::size_t slot_len =                             \
        D == 2 ? AMPM_FORCE_SLOT_LEN_2D : AMPM_FORCE_SLOT_LEN_3D;       \
    using Material = AmpmMaterial_##S;                                  \
    using Particles = AmpmParticles_##S;                                \
    using Channel = AmpmChannel_##S;                                    \
    using ConstChannel = AmpmConstChannel_##S;                          \
    using P2gView = AmpmP2gView_##S;                                    \
    using G2pView = AmpmG2pView_##S;                                    \
    using ForceView = AmpmForceView_##S;                                \
  };
BENCH_API(float, 2, f32)
BENCH_API(float, 3, f32)
BENCH_API(double, 2, f64)
BENCH_API(double, 3, f64)
#undef BENCH_API

[[noreturn]] void fail(const std::string& msg) {
  std::fprintf(stderr, "bench_transfers: %s\n", msg.c_str());
  std::exit(1);
}

const char* status_name(AmpmStatus s) {
  switch (s) {
    case AMPM_OK: return "AMPM_OK";
    case AMPM_ERR_NULL_POINTER: return "AMPM_ERR_NULL_POINTER";
    case AMPM_ERR_NON_FINITE: return "AMPM_ERR_NON_FINITE";
    case AMPM_ERR_NON_POSITIVE_J: return "AMPM_ERR_NON_POSITIVE_J";
    case AMPM_ERR_OVERFLOW: return "AMPM_ERR_OVERFLOW";
    case AMPM_ERR_INVALID_ARGUMENT: return "AMPM_ERR_INVALID_ARGUMENT";
    case AMPM_ERR_NOT_CONVERGED: return "AMPM_ERR_NOT_CONVERGED";
    case AMPM_ERR_INTERNAL: return "AMPM_ERR_INTERNAL";
    case AMPM_ERR_NOT_PREPARED: return "AMPM_ERR_NOT_PREPARED";
    case AMPM_ERR_OUTSIDE_GRID: return "AMPM_ERR_OUTSIDE_GRID";
  }
  return "(unknown AmpmStatus)";
}

const char* isa_name(std::uint32_t isa) {
  switch (isa) {
    case AMPM_ISA_SCALAR: return "scalar";
    case AMPM_ISA_AVX2: return "AVX2";
    case AMPM_ISA_AVX512: return "AVX-512";
  }
  return "(unknown ISA)";
}

void expect_ok(const std::string& what, AmpmStatus st, std::size_t first, std::size_t n) {
  if (st != AMPM_OK || first != n)
    fail(what + ": " + status_name(st) + ", first_failed " + std::to_string(first) + " (n = " +
         std::to_string(n) + ")");
}

// ---- scenes ----------------------------------------------------------------------------------

enum class Scene { Elastic, Fluid, Thermal, Snow };
constexpr Scene kScenes[] = {Scene::Elastic, Scene::Fluid, Scene::Thermal, Scene::Snow};

const char* scene_name(Scene s) {
  switch (s) {
    case Scene::Elastic: return "elastic";
    case Scene::Fluid: return "fluid";
    case Scene::Thermal: return "thermal+phase";
    case Scene::Snow: return "snow";
  }
  return "?";
}

constexpr double kMu = 1e5, kLambda = 1e5, kRho = 1000, kH = 0.01, kDt = 1e-4;
constexpr double kTm = 273.15, kLatent = 334000, kCs = 2100, kCl = 4200;

template <class T, int D>
typename Api<T, D>::Material material(Scene s, bool psd) {
  typename Api<T, D>::Material m{};
  m.model = 0;
  m.solid.mu = static_cast<T>(kMu);
  m.solid.inv_lambda = static_cast<T>(1 / kLambda);
  m.solid.heat_capacity = static_cast<T>(kCs);
  m.solid.conductivity = static_cast<T>(2.2);
  m.liquid.mu = 0;
  m.liquid.inv_lambda = static_cast<T>(1 / kLambda);
  m.liquid.heat_capacity = static_cast<T>(kCl);
  m.liquid.conductivity = static_cast<T>(0.6);
  m.melting_point = static_cast<T>(kTm);
  m.latent_heat = static_cast<T>(kLatent);
  m.flip = static_cast<T>(0.95);
  m.critical_compression = static_cast<T>(0.025);
  m.critical_stretch = static_cast<T>(0.0075);
  m.hardening = static_cast<T>(10);
  if (s == Scene::Thermal) m.model |= AMPM_MODEL_THERMAL | AMPM_MODEL_PHASE_CHANGE;
  if (s == Scene::Snow) m.model |= AMPM_MODEL_PLASTIC;
  if (psd) m.model |= AMPM_MODEL_PSD_HESSIAN;
  return m;
}

// ---- particles -----------------------------------------------------------------------------

template <class T, int D>
struct Parts {
  std::size_t n = 0;
  std::vector<T> x, v, c, fe, fp, m, v0, t, u;
  std::vector<std::uint8_t> ph;
  template <class U = T>
  typename Api<U, D>::Particles view() {
    return view_at<U>(0);
  }
  /// The view of particles i.. (each array advanced by i records).
  template <class U = T>
  typename Api<U, D>::Particles view_at(std::size_t i) {
    const std::size_t d = D, dd = D * D;
    return {x.data() + i * d, v.data() + i * d, c.data() + i * dd, fe.data() + i * dd, fp.data() + i * dd,
            m.data() + i, v0.data() + i, t.data() + i, u.data() + i, ph.data() + i};
  }
};

/// Haar rotation: angle uniform in [0, 2π) in 2D; in 3D the unit quaternion of a normalised
/// standard Gaussian 4-vector (uniform on S³, mapped to the Haar measure on SO(3)).
template <int D>
Eigen::Matrix<double, D, D> rotation(std::mt19937_64& g) {
  std::normal_distribution<double> nd;
  Eigen::Matrix<double, D, D> r;
  if constexpr (D == 2) {
    const double t = std::uniform_real_distribution<double>(0, 6.283185307179586)(g);
    r << std::cos(t), -std::sin(t), std::sin(t), std::cos(t);
  } else {
    Eigen::Vector4d q;
    do {
      for (int k = 0; k < 4; ++k) q(k) = nd(g);
    } while (q.norm() < 1e-6);
    q.normalize();
    r = Eigen::Quaterniond(q(0), q(1), q(2), q(3)).toRotationMatrix();
  }
  return r;
}

/// The block of `scene`, `per_axis` particles per axis, shuffled then sorted by cell.
template <class T, int D>
Parts<T, D> make_parts(Scene scene, int per_axis) {
  std::mt19937_64 g(kSeed + static_cast<std::uint64_t>(D) * 16 + static_cast<int>(scene));
  std::uniform_real_distribution<double> uni(-1, 1);
  std::size_t n = 1;
  for (int a = 0; a < D; ++a) n *= static_cast<std::size_t>(per_axis);
  // Draw in double (the same particles for f32 and f64 up to rounding).
  std::vector<double> x(n * D), v(n * D), c(n * D * D), fe(n * D * D), fp(n * D * D), t(n), u(n);
  std::vector<std::uint8_t> ph(n, AMPM_PHASE_SOLID);
  const double sp = kH / 2;
  for (std::size_t i = 0; i < n; ++i) {
    std::size_t q = i;
    for (int a = 0; a < D; ++a) {
      const int k = static_cast<int>(q % per_axis);
      q /= per_axis;
      x[D * i + a] = 2 * kH + sp * (k + 0.5) + sp * 0.25 * uni(g);
      v[D * i + a] = 0.1 * uni(g);
      for (int b = 0; b < D; ++b) c[D * D * i + a + D * b] = 2.0 * uni(g);
    }
    Eigen::Matrix<double, D, D> f = Eigen::Matrix<double, D, D>::Identity(),
                                p = Eigen::Matrix<double, D, D>::Identity();
    Eigen::Matrix<double, D, 1> sig;
    const int kind = static_cast<int>(i % 3);
    switch (scene) {
      case Scene::Elastic:
        for (int a = 0; a < D; ++a) sig(a) = 1 + 0.05 * uni(g);
        f = rotation<D>(g) * sig.asDiagonal() * rotation<D>(g);
        t[i] = 0;
        break;
      case Scene::Fluid: {
        ph[i] = AMPM_PHASE_LIQUID;
        const double j = 1 + 0.02 * uni(g);
        f *= D == 2 ? std::sqrt(j) : std::cbrt(j);
        p *= D == 2 ? std::sqrt(1 + 0.05 * uni(g)) : std::cbrt(1 + 0.05 * uni(g));
        break;
      }
      case Scene::Thermal:
        if (kind == 0) {  // ice
          for (int a = 0; a < D; ++a) sig(a) = 1 + 0.02 * uni(g);
          f = rotation<D>(g) * sig.asDiagonal() * rotation<D>(g);
          t[i] = 260, u[i] = 0;
        } else if (kind == 1) {  // at the melting point, half melted
          ph[i] = (i / 3) % 2 ? AMPM_PHASE_LIQUID : AMPM_PHASE_SOLID;
          t[i] = kTm, u[i] = kLatent / 2;
          if (ph[i] == AMPM_PHASE_SOLID) {
            for (int a = 0; a < D; ++a) sig(a) = 1 + 0.02 * uni(g);
            f = rotation<D>(g) * sig.asDiagonal() * rotation<D>(g);
          }
        } else {  // water
          ph[i] = AMPM_PHASE_LIQUID;
          t[i] = 290, u[i] = kLatent;
        }
        break;
      case Scene::Snow:
        for (int a = 0; a < D; ++a) sig(a) = 1 + (uni(g) < 0 ? -0.025 : 0.0075) * std::fabs(uni(g));
        f = rotation<D>(g) * sig.asDiagonal() * rotation<D>(g);
        for (int a = 0; a < D; ++a) sig(a) = 1 + 0.05 * uni(g);
        p = rotation<D>(g) * sig.asDiagonal() * rotation<D>(g);
        break;
    }
    std::copy(f.data(), f.data() + D * D, fe.begin() + D * D * i);
    std::copy(p.data(), p.data() + D * D, fp.begin() + D * D * i);
  }
  // Shuffle, then sort by cell, x fastest, as a host does.
  std::vector<std::size_t> order(n);
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::shuffle(order.begin(), order.end(), g);
  std::vector<std::int64_t> key(n);
  for (std::size_t i = 0; i < n; ++i) {
    std::int64_t k = 0;
    for (int a = D - 1; a >= 0; --a) k = k * 4096 + static_cast<std::int64_t>(std::floor(x[D * i + a] / kH));
    key[i] = k;
  }
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return key[a] < key[b]; });
  Parts<T, D> p;
  p.n = n;
  p.x.resize(n * D), p.v.resize(n * D), p.c.resize(n * D * D), p.fe.resize(n * D * D), p.fp.resize(n * D * D);
  p.m.resize(n), p.v0.resize(n), p.t.resize(n), p.u.resize(n), p.ph.resize(n);
  double vol = 1;
  for (int a = 0; a < D; ++a) vol *= sp;
  for (std::size_t j = 0; j < n; ++j) {
    const std::size_t i = order[j];
    for (int a = 0; a < D; ++a) p.x[D * j + a] = static_cast<T>(x[D * i + a]), p.v[D * j + a] = static_cast<T>(v[D * i + a]);
    for (int k = 0; k < D * D; ++k) {
      p.c[D * D * j + k] = static_cast<T>(c[D * D * i + k]);
      p.fe[D * D * j + k] = static_cast<T>(fe[D * D * i + k]);
      p.fp[D * D * j + k] = static_cast<T>(fp[D * D * i + k]);
    }
    p.m[j] = static_cast<T>(kRho * vol), p.v0[j] = static_cast<T>(vol);
    p.t[j] = static_cast<T>(t[i]), p.u[j] = static_cast<T>(u[i]), p.ph[j] = ph[i];
  }
  return p;
}

// ---- the host's grid -----------------------------------------------------------------------

template <class T, int D>
struct Grid {
  int lo[3] = {0, 0, 0}, dims[3] = {1, 1, 1};
  std::size_t count = 1;
  std::vector<T> mass, hc, te, cond, tn, to;
  std::array<std::vector<T>, 3> mom, force, vel, mom2, du, df;

  void reset(const int* l, const int* h) {
    count = 1;
    for (int a = 0; a < 3; ++a) {
      lo[a] = a < D ? l[a] : 0;
      dims[a] = a < D ? h[a] - l[a] + 1 : 1;
      count *= static_cast<std::size_t>(dims[a]);
    }
    for (auto* f : {&mass, &hc, &te, &cond, &tn, &to}) f->assign(count, 0);
    for (int a = 0; a < 3; ++a)
      for (auto* f : {&mom[a], &force[a], &vel[a], &mom2[a], &du[a], &df[a]}) f->assign(count, 0);
  }
  std::ptrdiff_t stride(int a) const {
    return a == 0 ? 1 : a == 1 ? dims[0] : static_cast<std::ptrdiff_t>(dims[0]) * dims[1];
  }
  AmpmNodeBox box() const {
    AmpmNodeBox b;
    for (int a = 0; a < 3; ++a) b.lo[a] = lo[a], b.dims[a] = dims[a];
    return b;
  }
  template <class U = T>
  typename Api<U, D>::Channel out(std::vector<U>& f) const {
    typename Api<U, D>::Channel c;
    c.data = f.data();
    for (int a = 0; a < 3; ++a) c.stride[a] = stride(a);
    return c;
  }
  template <class U = T>
  typename Api<U, D>::ConstChannel in(const std::vector<U>& f) const {
    typename Api<U, D>::ConstChannel c;
    c.data = f.data();
    for (int a = 0; a < 3; ++a) c.stride[a] = stride(a);
    return c;
  }
  template <class U = T>
  static typename Api<U, D>::Channel none() {
    typename Api<U, D>::Channel c;
    c.data = nullptr;
    c.stride[0] = c.stride[1] = c.stride[2] = 0;
    return c;
  }
  void zero_p2g() {
    std::fill(mass.begin(), mass.end(), T(0));
    for (int a = 0; a < D; ++a) {
      std::fill(mom[a].begin(), mom[a].end(), T(0));
      std::fill(force[a].begin(), force[a].end(), T(0));
    }
    std::fill(hc.begin(), hc.end(), T(0));
    std::fill(te.begin(), te.end(), T(0));
    std::fill(cond.begin(), cond.end(), T(0));
  }
};

/// The views of a scene: P2G sym (impulse, no force), P2G +f, G2P, force.
template <class T, int D>
struct Views {
  typename Api<T, D>::P2gView sym{}, plus_f{};
  typename Api<T, D>::G2pView g2p{};
  typename Api<T, D>::ForceView force{};
};

template <class T, int D>
Views<T, D> make_views(Grid<T, D>& g, bool thermal) {
  Views<T, D> v;
  for (auto* pv : {&v.sym, &v.plus_f}) {
    pv->nodes = g.box();
    pv->mass = g.out(g.mass);
    for (int a = 0; a < 3; ++a) {
      pv->momentum[a] = a < D ? g.out(g.mom[a]) : Grid<T, D>::none();
      pv->force[a] = Grid<T, D>::none();
    }
    pv->heat_capacity = thermal ? g.out(g.hc) : Grid<T, D>::none();
    pv->thermal_energy = thermal ? g.out(g.te) : Grid<T, D>::none();
    pv->conductivity = thermal ? g.out(g.cond) : Grid<T, D>::none();
  }
  for (int a = 0; a < D; ++a) v.plus_f.force[a] = g.out(g.force[a]);
  v.g2p.nodes = g.box();
  for (int a = 0; a < 3; ++a) {
    v.g2p.velocity[a].data = a < D ? g.vel[a].data() : nullptr;
    for (int b = 0; b < 3; ++b) v.g2p.velocity[a].stride[b] = g.stride(b);
  }
  v.g2p.temperature = g.in(g.tn);
  v.g2p.temperature_old = g.in(g.to);
  v.force.nodes = g.box();
  for (int a = 0; a < 3; ++a) {
    v.force.du[a] = g.in(a < D ? g.du[a] : g.du[0]);
    v.force.df[a] = g.out(a < D ? g.df[a] : g.df[0]);
  }
  return v;
}

/// The host's grid update of the symplectic form: v = p/m; with heat T = E/C, the heat step
/// stand-in T^(n+1) = T^n + 0.5 K. `noinline` so the timed loop is this one.
template <class T, int D>
__attribute__((noinline)) void grid_update(Grid<T, D>& g, bool thermal) {
  const std::size_t n = g.count;
  const T* __restrict m = g.mass.data();
  for (int a = 0; a < D; ++a) {
    const T* __restrict p = g.mom[a].data();
    T* __restrict v = g.vel[a].data();
    for (std::size_t k = 0; k < n; ++k) v[k] = m[k] > 0 ? p[k] / m[k] : T(0);
  }
  if (thermal) {
    const T* __restrict c = g.hc.data();
    const T* __restrict e = g.te.data();
    T* __restrict tn = g.tn.data();
    T* __restrict to = g.to.data();
    for (std::size_t k = 0; k < n; ++k) {
      const T t = m[k] > 0 ? e[k] / c[k] : T(0);
      to[k] = t;
      tn[k] = t + T(0.5);
    }
  }
}

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
      for (int a = 0, q = r; a < D; ++a, q /= K1) o[a] = q % K1;
      T wt = 1, gr[D];
      std::ptrdiff_t k = k0;
      for (int a = 0; a < D; ++a) {
        wt *= w[a][o[a]];
        k += o[a] * st[a];
        T ga = dw[a][o[a]];
        for (int b = 0; b < D; ++b)
          if (b != a) ga *= w[b][o[b]];
        gr[a] = ga;
      }
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
      for (int a = 0, q = r; a < D; ++a, q /= K1) o[a] = q % K1;
      T wt = 1, gr[D];
      std::ptrdiff_t k = k0;
      for (int a = 0; a < D; ++a) {
        wt *= w[a][o[a]];
        k += o[a] * st[a];
        T ga = dw[a][o[a]];
        for (int c = 0; c < D; ++c)
          if (c != a) ga *= w[c][o[c]];
        gr[a] = ga;
      }
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

// ---- timing --------------------------------------------------------------------------------

/// Median and minimum over `reps` runs of `body` after one warm-up, in ns per particle;
/// `before` runs untimed before each run (restoring state, zeroing outputs).
struct Timing {
  double median = NAN, min = NAN;
};

template <class Before, class Body>
Timing time_ns(int reps, std::size_t n, Before&& before, Body&& body) {
  std::vector<double> ns;
  for (int r = -1; r < reps; ++r) {
    before();
    const auto t0 = std::chrono::steady_clock::now();
    body();
    const auto t1 = std::chrono::steady_clock::now();
    if (r >= 0) ns.push_back(std::chrono::duration<double, std::nano>(t1 - t0).count());
  }
  std::sort(ns.begin(), ns.end());
  return {ns[ns.size() / 2] / static_cast<double>(n), ns.front() / static_cast<double>(n)};
}

template <class Before, class Body>
double median_ns(int reps, std::size_t n, Before&& before, Body&& body) {
  return time_ns(reps, n, before, body).median;
}

struct Row {
  std::string scene, kase, isa;
  std::size_t n = 0, nodes = 0;
  double p2g_sym = NAN, p2g_f = NAN, grid = NAN, g2p = NAN, step = NAN, prepare = NAN, apply = NAN;
  double p2g_sym_min = NAN, g2p_min = NAN, apply_min = NAN;  // fastest run (least disturbed)
  double lib() const { return p2g_sym + g2p; }
  double lib_min() const { return p2g_sym_min + g2p_min; }
};

/// The Eigen baseline and the library (default ISA), elastic 3D f32, timed alternately rep by
/// rep so that both see the same machine state: medians, ns per particle.
struct Baseline {
  std::size_t n = 0;
  double p2g = NAN, g2p = NAN;          // Eigen
  double lib_p2g = NAN, lib_g2p = NAN;  // library, P2G sym + G2P
};

/// The hardware limit of the elastic f32 step in one dimension (c_tests/bench_floor.hpp):
/// memory floors of P2G and G2P (ns per particle) and their bytes per particle, and the
/// arithmetic floors at the measured FMA rate.
struct Floor {
  int d = 0;
  double mem_p2g = NAN, mem_g2p = NAN, bytes_p2g = NAN, bytes_g2p = NAN;
  double fma_per_ns = NAN, fma_p2g = NAN, fma_g2p = NAN;
  double p2g() const { return std::max(mem_p2g, fma_p2g); }
  double g2p() const { return std::max(mem_g2p, fma_g2p); }
};

// ---- one case ------------------------------------------------------------------------------

template <class T, int D>
struct Case {
  using A = Api<T, D>;
  Scene scene;
  Parts<T, D> p0;  // the initial state (restored before every run)
  Parts<T, D> p;
  Grid<T, D> g;
  Views<T, D> v;
  std::vector<T> slots;
  bool thermal;
  T h = static_cast<T>(kH), dt = static_cast<T>(kDt);

  Case(Scene s, int per_axis) : scene(s), p0(make_parts<T, D>(s, per_axis)), p(p0), thermal(s == Scene::Thermal) {
    int lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0};
    std::size_t ff = 0;
    {
      const AmpmStatus st_ = A::node_range(AMPM_KERNEL_QUADRATIC, AMPM_GRID_COLLOCATED, h, p.n, p.x.data(), lo, hi, &ff);
      expect_ok(std::string(A::name) + " node_range", st_, ff, p.n);
    }
    // One node of margin on each side: the block moves by at most |v|·Δt per step.
    for (int a = 0; a < D; ++a) lo[a] -= 1, hi[a] += 1;
    g.reset(lo, hi);
    v = make_views(g, thermal);
    slots.assign(p.n * A::slot_len, 0);
    for (int a = 0; a < D; ++a)
      for (std::size_t k = 0; k < g.count; ++k) g.du[a][k] = static_cast<T>(1e-6 * std::sin(0.37 * k + a));
  }
  std::string label(const char* what) const { return std::string(A::name) + " " + scene_name(scene) + " " + what; }
  void restore() {
    std::copy(p0.x.begin(), p0.x.end(), p.x.begin());
    std::copy(p0.v.begin(), p0.v.end(), p.v.begin());
    std::copy(p0.c.begin(), p0.c.end(), p.c.begin());
    std::copy(p0.fe.begin(), p0.fe.end(), p.fe.begin());
    std::copy(p0.fp.begin(), p0.fp.end(), p.fp.begin());
    std::copy(p0.t.begin(), p0.t.end(), p.t.begin());
    std::copy(p0.u.begin(), p0.u.end(), p.u.begin());
    std::copy(p0.ph.begin(), p0.ph.end(), p.ph.begin());
  }
  // Each call through `f`: this binary's symbol by default, another build's with --ab.
  AmpmStatus p2g_sym(std::size_t* ff, decltype(A::p2g) f = A::p2g) {
    const auto m = material<T, D>(scene, false);
    auto pv = p.view();
    return f(&m, AMPM_KERNEL_QUADRATIC, AMPM_GRID_COLLOCATED, h, dt, p.n, &pv, &v.sym, ff);
  }
  AmpmStatus p2g_f(std::size_t* ff) {
    const auto m = material<T, D>(scene, false);
    auto pv = p.view();
    return A::p2g(&m, AMPM_KERNEL_QUADRATIC, AMPM_GRID_COLLOCATED, h, T(0), p.n, &pv, &v.plus_f, ff);
  }
  AmpmStatus g2p(std::size_t* ff, decltype(A::g2p) f = A::g2p) {
    const auto m = material<T, D>(scene, false);
    auto pv = p.view();
    return f(&m, AMPM_KERNEL_QUADRATIC, h, dt, p.n, &pv, &v.g2p, ff);
  }
  AmpmStatus prepare(std::size_t* ff, decltype(A::prepare) f = A::prepare) {
    const auto m = material<T, D>(scene, true);
    auto pv = p.view();
    return f(&m, p.n, &pv, slots.data(), ff);
  }
  AmpmStatus apply(std::size_t* ff, decltype(A::apply) f = A::apply) {
    return f(AMPM_KERNEL_QUADRATIC, h, p.n, p.x.data(), slots.data(), &v.force, ff);
  }
  // The same calls over particles [i, i + k) (a host's block of particles), with `ff` relative to i.
  AmpmStatus p2g_sym_range(std::size_t i, std::size_t k, std::size_t* ff) {
    const auto m = material<T, D>(scene, false);
    auto pv = p.view_at(i);
    return A::p2g(&m, AMPM_KERNEL_QUADRATIC, AMPM_GRID_COLLOCATED, h, dt, k, &pv, &v.sym, ff);
  }
  AmpmStatus g2p_range(std::size_t i, std::size_t k, std::size_t* ff) {
    const auto m = material<T, D>(scene, false);
    auto pv = p.view_at(i);
    return A::g2p(&m, AMPM_KERNEL_QUADRATIC, h, dt, k, &pv, &v.g2p, ff);
  }
  AmpmStatus apply_range(std::size_t i, std::size_t k, std::size_t* ff) {
    return A::apply(AMPM_KERNEL_QUADRATIC, h, k, p.x.data() + i * D, slots.data() + i * A::slot_len, &v.force, ff);
  }
  void zero_df() {
    for (int a = 0; a < D; ++a) std::fill(g.df[a].begin(), g.df[a].end(), T(0));
  }
  /// One untimed step of every call, with status checks; leaves the P2G sym grid, its
  /// velocities, and the particles after G2P.
  void run_all_once() {
    std::size_t ff = 0;
    restore();
    g.zero_p2g();
    {
      const AmpmStatus st_ = p2g_f(&ff);
      expect_ok(label("P2G +f"), st_, ff, p.n);
    }
    for (int a = 0; a < D; ++a) g.mom2[a] = g.mom[a];
    g.zero_p2g();
    {
      const AmpmStatus st_ = p2g_sym(&ff);
      expect_ok(label("P2G sym"), st_, ff, p.n);
    }
    grid_update(g, thermal);
    {
      const AmpmStatus st_ = g2p(&ff);
      expect_ok(label("G2P"), st_, ff, p.n);
    }
    restore();
    {
      const AmpmStatus st_ = prepare(&ff);
      expect_ok(label("prepare"), st_, ff, p.n);
    }
    zero_df();
    {
      const AmpmStatus st_ = apply(&ff);
      expect_ok(label("apply"), st_, ff, p.n);
    }
    restore();
  }

  Row time(int reps, std::uint32_t isa) {
    Row r;
    r.scene = scene_name(scene);
    r.kase = A::name;
    r.isa = isa_name(isa);
    r.n = p.n;
    r.nodes = g.count;
    const std::size_t n = p.n;
    std::size_t ff = 0;
    auto check = [&](const char* what, AmpmStatus st) { expect_ok(label(what), st, ff, n); };
    run_all_once();
    const Timing ts = time_ns(reps, n, [&] { g.zero_p2g(); }, [&] { check("P2G sym", p2g_sym(&ff)); });
    r.p2g_sym = ts.median, r.p2g_sym_min = ts.min;
    r.p2g_f = median_ns(reps, n, [&] { g.zero_p2g(); }, [&] { check("P2G +f", p2g_f(&ff)); });
    g.zero_p2g();
    check("P2G sym", p2g_sym(&ff));
    r.grid = median_ns(reps, n, [] {}, [&] { grid_update(g, thermal); });
    const Timing tg = time_ns(reps, n, [&] { restore(); }, [&] { check("G2P", g2p(&ff)); });
    r.g2p = tg.median, r.g2p_min = tg.min;
    r.step = median_ns(reps, n, [&] { restore(); }, [&] {
      g.zero_p2g();
      check("P2G sym", p2g_sym(&ff));
      grid_update(g, thermal);
      check("G2P", g2p(&ff));
    });
    restore();
    r.prepare = median_ns(reps, n, [] {}, [&] { check("prepare", prepare(&ff)); });
    const Timing ta = time_ns(reps, n, [] {}, [&] {
      zero_df();
      check("apply", apply(&ff));
    });
    r.apply = ta.median, r.apply_min = ta.min;
    restore();
    return r;
  }
};

// ---- agreement checks ----------------------------------------------------------------------

template <class T>
bool finite_all(const std::vector<T>& v) {
  for (T x : v)
    if (!std::isfinite(x)) return false;
  return true;
}

/// Max over nodes of |x − ref|/(c·ε·scale) (≤ 1 agrees); scale 0 demands equality.
template <class T>
ld worst_ratio(const std::vector<T>& x, const std::vector<ld>& ref, const std::vector<ld>& scale, ld c) {
  const ld eps = std::numeric_limits<T>::epsilon();
  ld w = 0;
  for (std::size_t k = 0; k < x.size(); ++k) {
    const ld d = std::fabs(static_cast<ld>(x[k]) - ref[k]);
    if (d == 0) continue;
    const ld t = c * eps * scale[k];
    w = std::max(w, t > 0 ? d / t : std::numeric_limits<ld>::infinity());
  }
  return w;
}

struct CheckLog {
  std::vector<std::string> lines;
  void add(const std::string& s) {
    lines.push_back(s);
    std::printf("  %s\n", s.c_str());
  }
};

int n_add_of(int d) { return d == 2 ? 36 : 216; }  // 2 particles per cell per axis: (3·2)^d

/// The elastic scene of (T, D): library and Eigen baseline vs the long-double loop.
template <class T, int D>
void check_elastic(int per_axis, CheckLog& log) {
  using A = Api<T, D>;
  Case<T, D> cs(Scene::Elastic, per_axis);
  cs.run_all_once();
  const std::size_t nc = cs.g.count;
  const int KD = D == 2 ? 9 : 27;
  const ld n_add = n_add_of(D);
  // Library P2G sym and P2G +f.
  Grid<T, D>& g = cs.g;
  g.zero_p2g();
  std::size_t ff = 0;
  {
    const AmpmStatus st_ = cs.p2g_f(&ff);
    expect_ok(cs.label("P2G +f"), st_, ff, cs.p.n);
  }
  std::array<std::vector<T>, 3> mom_f, force_f;
  for (int a = 0; a < D; ++a) mom_f[a] = g.mom[a], force_f[a] = g.force[a];
  g.zero_p2g();
  {
    const AmpmStatus st_ = cs.p2g_sym(&ff);
    expect_ok(cs.label("P2G sym"), st_, ff, cs.p.n);
  }
  const std::vector<T> lib_mass = g.mass;
  std::array<std::vector<T>, 3> lib_mom;
  for (int a = 0; a < D; ++a) lib_mom[a] = g.mom[a];
  // The baseline in T.
  Grid<T, D> gb = g;
  gb.zero_p2g();
  eigen_p2g<T, D>(cs.p, gb, cs.h, cs.dt, static_cast<T>(kMu), static_cast<T>(kLambda), nullptr);
  // The long-double loop with magnitudes.
  Parts<ld, D> pl;
  pl.n = cs.p.n;
  auto cv = [](const std::vector<T>& s) { return std::vector<ld>(s.begin(), s.end()); };
  pl.x = cv(cs.p.x), pl.v = cv(cs.p.v), pl.c = cv(cs.p.c), pl.fe = cv(cs.p.fe), pl.fp = cv(cs.p.fp);
  pl.m = cv(cs.p.m), pl.v0 = cv(cs.p.v0);
  Grid<ld, D> gl;
  gl.lo[0] = g.lo[0], gl.lo[1] = g.lo[1], gl.lo[2] = g.lo[2];
  int hi[3];
  for (int a = 0; a < 3; ++a) hi[a] = g.lo[a] + g.dims[a] - 1;
  gl.reset(g.lo, hi);
  Mags mags;
  mags.mass.assign(nc, 0);
  for (int a = 0; a < 3; ++a) mags.mom[a].assign(nc, 0);
  eigen_p2g<ld, D>(pl, gl, static_cast<ld>(cs.h), static_cast<ld>(cs.dt), static_cast<ld>(static_cast<T>(kMu)),
                   static_cast<ld>(static_cast<T>(kLambda)), &mags);
  const ld c_mass = 64 + 2 * KD + n_add, c_mom = 256 + n_add;
  ld w_lib = worst_ratio(lib_mass, gl.mass, mags.mass, c_mass), w_base = worst_ratio(gb.mass, gl.mass, mags.mass, c_mass);
  ld w_sym = 0;
  for (int a = 0; a < D; ++a) {
    w_lib = std::max(w_lib, worst_ratio(lib_mom[a], gl.mom[a], mags.mom[a], c_mom));
    w_base = std::max(w_base, worst_ratio(gb.mom[a], gl.mom[a], mags.mom[a], c_mom));
    std::vector<ld> plus(nc);
    for (std::size_t k = 0; k < nc; ++k) plus[k] = static_cast<ld>(mom_f[a][k]) + static_cast<ld>(cs.dt) * force_f[a][k];
    std::vector<ld> two(nc);
    for (std::size_t k = 0; k < nc; ++k) two[k] = 2 * mags.mom[a][k];
    w_sym = std::max(w_sym, worst_ratio(lib_mom[a], plus, two, c_mom));
  }
  char b[256];
  std::snprintf(b, sizeof b, "%s elastic P2G vs long double: library %.3Lg, Eigen baseline %.3Lg; P2G sym vs P2G +f: %.3Lg (of the bound)",
                A::name, w_lib, w_base, w_sym);
  log.add(b);
  if (!(w_lib <= 1 && w_base <= 1 && w_sym <= 1)) fail(std::string("disagreement: ") + b);

  // G2P from the library's grid velocities: library, baseline and long double.
  grid_update(g, false);
  const Parts<T, D> before = cs.p;
  {
    const AmpmStatus st_ = cs.g2p(&ff);
    expect_ok(cs.label("G2P"), st_, ff, cs.p.n);
  }
  Parts<T, D> pb = before;
  eigen_g2p<T, D>(pb, g, cs.h, cs.dt);
  for (int a = 0; a < D; ++a) gl.vel[a].assign(g.vel[a].begin(), g.vel[a].end());
  eigen_g2p<ld, D>(pl, gl, static_cast<ld>(cs.h), static_cast<ld>(cs.dt));
  // Scales: |v_i| ≤ vmax; v and x (C = 64 + 2K^d): vmax; C: vmax·(4/h²)·1.5h√d; F_E: 1 + Δt·Σ|v_i||∇w|.
  ld vmax = 0;
  for (int a = 0; a < D; ++a)
    for (T x : g.vel[a]) vmax = std::max(vmax, std::fabs(static_cast<ld>(x)));
  const ld c = 64 + 2 * KD, eps = std::numeric_limits<T>::epsilon();
  const ld hh = static_cast<ld>(cs.h);
  auto cmp = [&](const Parts<T, D>& q) {
    ld w = 0;
    for (std::size_t i = 0; i < q.n; ++i) {
      for (int a = 0; a < D; ++a) {
        w = std::max(w, std::fabs(q.v[D * i + a] - pl.v[D * i + a]) / (c * eps * vmax));
        w = std::max(w, std::fabs(q.x[D * i + a] - pl.x[D * i + a]) / (c * eps * (std::fabs(pl.x[D * i + a]) + kDt * vmax)));
      }
      for (int k = 0; k < D * D; ++k) {
        w = std::max(w, std::fabs(q.c[D * D * i + k] - pl.c[D * D * i + k]) / (c * eps * vmax * 6 * std::sqrt(ld(D)) / hh));
        w = std::max(w, std::fabs(q.fe[D * D * i + k] - pl.fe[D * D * i + k]) / (c * eps * (2 + kDt * vmax * KD * 2 / hh)));
      }
    }
    return w;
  };
  const ld g_lib = cmp(cs.p), g_base = cmp(pb);
  std::snprintf(b, sizeof b, "%s elastic G2P vs long double: library %.3Lg, Eigen baseline %.3Lg (of the bound)", A::name, g_lib, g_base);
  log.add(b);
  if (!(g_lib <= 1 && g_base <= 1)) fail(std::string("disagreement: ") + b);
}

/// Every scene on every ISA: statuses, finiteness; AVX2 and AVX-512 bit-identical, scalar within
/// the bound of the P2G momenta.
template <class T, int D>
void check_isas(Scene s, int per_axis, const std::vector<std::uint32_t>& isas, CheckLog& log) {
  using A = Api<T, D>;
  struct Out {
    std::uint32_t isa;
    std::vector<T> mass, slots, x, fe;
    std::array<std::vector<T>, 3> mom, df;
  };
  std::vector<Out> outs;
  for (std::uint32_t isa : isas) {
    if (ampm_set_isa(isa) != AMPM_OK) fail("ampm_set_isa failed");
    Case<T, D> cs(s, per_axis);
    cs.run_all_once();
    std::size_t ff = 0;
    cs.g.zero_p2g();
    {
      const AmpmStatus st_ = cs.p2g_sym(&ff);
      expect_ok(cs.label("P2G sym"), st_, ff, cs.p.n);
    }
    Out o;
    o.isa = isa;
    o.mass = cs.g.mass;
    for (int a = 0; a < D; ++a) o.mom[a] = cs.g.mom[a];
    grid_update(cs.g, cs.thermal);
    {
      const AmpmStatus st_ = cs.g2p(&ff);
      expect_ok(cs.label("G2P"), st_, ff, cs.p.n);
    }
    o.x = cs.p.x, o.fe = cs.p.fe;
    cs.restore();
    {
      const AmpmStatus st_ = cs.prepare(&ff);
      expect_ok(cs.label("prepare"), st_, ff, cs.p.n);
    }
    cs.zero_df();
    {
      const AmpmStatus st_ = cs.apply(&ff);
      expect_ok(cs.label("apply"), st_, ff, cs.p.n);
    }
    o.slots = cs.slots;
    for (int a = 0; a < D; ++a) o.df[a] = cs.g.df[a];
    bool fin = finite_all(o.mass) && finite_all(o.x) && finite_all(o.fe) && finite_all(o.slots);
    for (int a = 0; a < D; ++a) fin = fin && finite_all(o.mom[a]) && finite_all(o.df[a]);
    if (!fin) fail(cs.label("non-finite result"));
    outs.push_back(std::move(o));
  }
  const Out* avx2 = nullptr;
  const Out* avx512 = nullptr;
  const Out* scalar = nullptr;
  for (const Out& o : outs) {
    if (o.isa == AMPM_ISA_AVX2) avx2 = &o;
    if (o.isa == AMPM_ISA_AVX512) avx512 = &o;
    if (o.isa == AMPM_ISA_SCALAR) scalar = &o;
  }
  std::string msg = std::string(A::name) + " " + scene_name(s) + ": all calls AMPM_OK on";
  for (const Out& o : outs) msg += std::string(" ") + isa_name(o.isa);
  if (avx2 && avx512) {
    bool same = avx2->mass == avx512->mass && avx2->slots == avx512->slots && avx2->x == avx512->x && avx2->fe == avx512->fe;
    for (int a = 0; a < D; ++a) same = same && avx2->mom[a] == avx512->mom[a] && avx2->df[a] == avx512->df[a];
    if (!same) fail(msg + ": AVX2 and AVX-512 results differ");
    msg += "; AVX2 = AVX-512 bit for bit";
  }
  const Out* simd = avx512 ? avx512 : avx2;
  if (scalar && simd) {
    // Momentum node sums: each differs from the exact sum by at most (256 + n_add)·ε of the
    // sum of the magnitudes of its terms, w m (|v| + 3.5 h Σ_b|C_ab|) + Δt V⁰ (‖τ‖ + μ + λ)|∇w|
    // per particle, with ‖τ‖ ≤ 2(μ + λ) for the singular values here and |∇w| ≤ √d/h; a node
    // has at most n_add terms: scale = n_add·max_p(that), and the two paths differ by ≤ twice.
    const ld eps = std::numeric_limits<T>::epsilon();
    const Parts<T, D> pp = make_parts<T, D>(s, per_axis);
    ld term = 0, worst = 0;
    for (std::size_t i = 0; i < pp.n; ++i)
      for (int a = 0; a < D; ++a) {
        ld cs = 0;
        for (int b2 = 0; b2 < D; ++b2) cs += std::fabs(static_cast<ld>(pp.c[D * D * i + a + D * b2]));
        term = std::max(term, static_cast<ld>(pp.m[i]) * (std::fabs(static_cast<ld>(pp.v[D * i + a])) + 3.5L * kH * cs) +
                                  kDt * static_cast<ld>(pp.v0[i]) * 3 * (kMu + kLambda) * std::sqrt(ld(D)) / kH);
      }
    const ld scale = 2 * n_add_of(D) * term;
    for (int a = 0; a < D; ++a)
      for (std::size_t k = 0; k < scalar->mom[a].size(); ++k)
        worst = std::max(worst, std::fabs(static_cast<ld>(scalar->mom[a][k]) - simd->mom[a][k]) /
                                    ((256 + n_add_of(D)) * eps * scale));
    char b[96];
    std::snprintf(b, sizeof b, "; scalar vs %s P2G momentum %.3Lg of the bound", isa_name(simd->isa), worst);
    msg += b;
    if (!(worst <= 1)) fail(msg + ": scalar and SIMD P2G disagree");
  }
  log.add(msg);
}

// ---- machine and report --------------------------------------------------------------------

std::string trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t"), e = s.find_last_not_of(" \t");
  return b == std::string::npos ? std::string() : s.substr(b, e - b + 1);
}

std::string cpu_model() {
  std::ifstream in("/proc/cpuinfo");
  std::string line;
  while (std::getline(in, line)) {
    const auto colon = line.find(':');
    if (colon != std::string::npos && trim(line.substr(0, colon)) == "model name") return trim(line.substr(colon + 1));
  }
  return "unknown CPU";
}

/// /proc/loadavg's 1-minute load average (other processes compete for the cores when it is
/// near or above the core count), or "unknown".
std::string load_average() {
  std::ifstream in("/proc/loadavg");
  std::string l;
  return in >> l ? l : std::string("unknown");
}

std::string compiler() {
#if defined(__clang__)
  std::string c = "clang " __clang_version__;
#elif defined(__GNUC__)
  std::string c = "g++ " __VERSION__;
#else
  std::string c = "unknown compiler";
#endif
#ifdef AMPM_BENCH_CXX_FLAGS
  c += " (" AMPM_BENCH_CXX_FLAGS ")";
#endif
  return c;
}

// ---- the same step through ampm.hpp -------------------------------------------------------

/// The elastic scene's material, built with ampm.hpp's named setters (the fields the C path's
/// material() sets; equal bytes, checked in check_hpp).
inline ampm::Material<float> hpp_material() {
  const auto c = material<float, 3>(Scene::Elastic, false);
  return ampm::Material<float>()
      .model(c.model)
      .solid(ampm::PhaseParams<float>().mu(c.solid.mu).inv_lambda(c.solid.inv_lambda)
                 .heat_capacity(c.solid.heat_capacity).conductivity(c.solid.conductivity))
      .liquid(ampm::PhaseParams<float>().mu(c.liquid.mu).inv_lambda(c.liquid.inv_lambda)
                  .heat_capacity(c.liquid.heat_capacity).conductivity(c.liquid.conductivity))
      .melting_point(c.melting_point)
      .latent_heat(c.latent_heat)
      .flip(c.flip)
      .critical_compression(c.critical_compression)
      .critical_stretch(c.critical_stretch)
      .hardening(c.hardening);
}

/// One host step (zero + P2G sym + grid + G2P) of the elastic 3D f32 case through ampm.hpp:
/// the material and particle builders are made per call, as the C path fills its structs.
struct HppStep {
  Case<float, 3>& cs;
  ampm::P2gView<float, 3> p2g_view;
  ampm::G2pView<float, 3> g2p_view;
  explicit HppStep(Case<float, 3>& c)
      : cs(c),
        p2g_view(ampm::P2gView<float, 3>::separate(c.g.box(), c.g.mass.data(),
                                                   {c.g.mom[0].data(), c.g.mom[1].data(), c.g.mom[2].data()})),
        g2p_view(ampm::G2pView<float, 3>::separate(c.g.box(), {c.g.vel[0].data(), c.g.vel[1].data(), c.g.vel[2].data()})) {}
  ampm::Particles<float, 3> particles() {
    auto& p = cs.p;
    ampm::Particles<float, 3> q(p.n);
    q.x(p.x.data()).v(p.v.data()).affine(p.c.data()).f_e(p.fe.data()).f_p(p.fp.data()).mass(p.m.data())
        .volume0(p.v0.data()).temperature(p.t.data()).latent(p.u.data()).phase(p.ph.data());
    return q;
  }
  void step() {
    cs.g.zero_p2g();
    const auto a = ampm::p2g(hpp_material(), AMPM_KERNEL_QUADRATIC, AMPM_GRID_COLLOCATED, cs.h, cs.dt, particles(), p2g_view);
    expect_ok("ampm.hpp P2G sym", a.code(), a.first_failed, cs.p.n);
    grid_update(cs.g, false);
    const auto b = ampm::g2p_update(hpp_material(), AMPM_KERNEL_QUADRATIC, cs.h, cs.dt, particles(), g2p_view);
    expect_ok("ampm.hpp G2P", b.code(), b.first_failed, cs.p.n);
  }
};

/// The C step of the elastic case (the `step` column's body).
void c_step(Case<float, 3>& cs) {
  std::size_t ff = 0;
  cs.g.zero_p2g();
  const AmpmStatus a = cs.p2g_sym(&ff);
  expect_ok(cs.label("P2G sym"), a, ff, cs.p.n);
  grid_update(cs.g, false);
  const AmpmStatus b = cs.g2p(&ff);
  expect_ok(cs.label("G2P"), b, ff, cs.p.n);
}

/// ampm.hpp's step equals the C step bit for bit (grid and particles), and its structs are the
/// C path's bytes.
void check_hpp(int per_axis, CheckLog& log) {
  Case<float, 3> a(Scene::Elastic, per_axis), b(Scene::Elastic, per_axis);
  HppStep hs(b);
  const auto cm = material<float, 3>(Scene::Elastic, false);
  const auto hm = hpp_material();
  auto pv = b.p.view();
  const bool structs = std::memcmp(&cm, &hm.c(), sizeof cm) == 0 &&
                       std::memcmp(&pv, &hs.particles().c(), sizeof pv) == 0;
  bool same = structs;
  for (int step = 0; step < 3; ++step) {
    c_step(a);
    hs.step();
    auto eq = [](const std::vector<float>& x, const std::vector<float>& y) {
      return x.size() == y.size() && std::memcmp(x.data(), y.data(), x.size() * sizeof(float)) == 0;
    };
    same = same && eq(a.g.mass, b.g.mass) && eq(a.p.x, b.p.x) && eq(a.p.v, b.p.v) && eq(a.p.c, b.p.c) &&
           eq(a.p.fe, b.p.fe);
    for (int d = 0; d < 3; ++d) same = same && eq(a.g.mom[d], b.g.mom[d]);
  }
  const std::string line = std::string("3D f32 elastic step through ampm.hpp vs the C calls, 3 steps: ") +
                           (same ? "same struct bytes, bit-identical grids and particles"
                                 : structs ? "DIFFERENT results" : "DIFFERENT struct bytes");
  log.add(line);
  if (!same) fail(line);
}

struct HppTiming {
  std::size_t n = 0;
  double c = NAN, hpp = NAN, c_min = NAN, hpp_min = NAN;
};

/// The C step and the ampm.hpp step, alternating rep by rep (one warm-up each), ns per particle.
HppTiming time_hpp(int per_axis, int reps) {
  Case<float, 3> cs(Scene::Elastic, per_axis);
  HppStep hs(cs);
  std::vector<double> tc, th;
  auto once = [&](auto&& body) {
    cs.restore();
    const auto t0 = std::chrono::steady_clock::now();
    body();
    const auto t1 = std::chrono::steady_clock::now();
    return std::chrono::duration<double, std::nano>(t1 - t0).count() / static_cast<double>(cs.p.n);
  };
  for (int r = -1; r < reps; ++r) {
    const double a = once([&] { c_step(cs); });
    const double b = once([&] { hs.step(); });
    if (r >= 0) tc.push_back(a), th.push_back(b);
  }
  std::sort(tc.begin(), tc.end());
  std::sort(th.begin(), th.end());
  cs.restore();
  return {cs.p.n, tc[tc.size() / 2], th[th.size() / 2], tc.front(), th.front()};
}

/// Particles per call of the block timing (0: the whole batch in one call).
constexpr std::size_t kBlocks[] = {0, 4096, 512, 64};
constexpr int kNumBlocks = sizeof kBlocks / sizeof kBlocks[0];

/// Largest block whose per-call cost the report gives: above it the difference to one call is
/// within the run-to-run spread.
constexpr std::size_t kPerCallMax = 512;

/// " (r)", a ratio to one call.
std::string ratio_text(double r) {
  char buf[32];
  std::snprintf(buf, sizeof buf, " (%.2f)", r);
  return buf;
}

/// A host's block calls (one call per range of particles, as a threaded host makes them):
/// lib (P2G sym + G2P) and apply, medians in ns per particle for each size of kBlocks.
struct BlockTiming {
  std::string scene, kase;
  std::size_t n = 0;
  double lib[kNumBlocks] = {}, apply[kNumBlocks] = {};
};

/// `call(i, k, &ff)` over the particles of `cs` in calls of `b` (0: one call), in order; every
/// call must return AMPM_OK.
template <class C, class Call>
void in_blocks(C& cs, std::size_t b, const char* what, Call&& call) {
  const std::size_t n = cs.p.n, step = b == 0 ? n : b;
  std::size_t ff = 0;
  for (std::size_t i = 0; i < n; i += step) {
    const std::size_t k = std::min(step, n - i);
    const AmpmStatus st = call(i, k, &ff);
    if (st != AMPM_OK || ff != k) expect_ok(cs.label(what), st, ff, k);  // no string per call
  }
}

/// G2P in calls of 64 particles leaves every particle bit-identical to one call (a particle's
/// result does not depend on the batch it is in).
template <class T, int D>
void check_blocks(Scene s, int per_axis, CheckLog& log) {
  Case<T, D> cs(s, per_axis);
  auto g2p_state = [&](std::size_t b) {
    cs.restore();
    cs.g.zero_p2g();
    in_blocks(cs, 0, "P2G sym", [&](std::size_t i, std::size_t k, std::size_t* f) { return cs.p2g_sym_range(i, k, f); });
    grid_update(cs.g, cs.thermal);
    in_blocks(cs, b, "G2P", [&](std::size_t i, std::size_t k, std::size_t* f) { return cs.g2p_range(i, k, f); });
    std::vector<T> st;
    for (const auto* f : {&cs.p.x, &cs.p.v, &cs.p.c, &cs.p.fe, &cs.p.fp, &cs.p.t, &cs.p.u})
      st.insert(st.end(), f->begin(), f->end());
    return st;
  };
  const std::vector<T> whole = g2p_state(0), small = g2p_state(64);
  if (whole.size() != small.size() || std::memcmp(whole.data(), small.data(), whole.size() * sizeof(T)) != 0)
    fail(cs.label("G2P in calls of 64") + ": particles differ from one call");
  cs.restore();
  log.add(cs.label("G2P") + ", " + std::to_string(cs.p.n) +
          " particles in calls of 64: bit-identical particles to one call");
}

/// Times lib and apply of one case on the default instruction set, the particles in calls of
/// kBlocks particles (consecutive ranges, every call into the same grid views), the sizes
/// alternating rep by rep (one warm-up round) so that all see the same machine state.
template <class T, int D>
BlockTiming time_blocks(Scene s, int per_axis, int reps) {
  Case<T, D> cs(s, per_axis);
  cs.run_all_once();
  const std::size_t n = cs.p.n;
  auto blocks = [&](std::size_t b, const char* what, auto&& call) { in_blocks(cs, b, what, call); };
  auto clock = [] { return std::chrono::steady_clock::now(); };
  auto ns = [&](auto t0, auto t1) { return std::chrono::duration<double, std::nano>(t1 - t0).count() / static_cast<double>(n); };
  std::vector<double> lib[kNumBlocks], apply[kNumBlocks];
  for (int r = -1; r < reps; ++r)
    for (int j = 0; j < kNumBlocks; ++j) {
      const std::size_t b = kBlocks[j];
      cs.restore();
      cs.g.zero_p2g();
      const auto t0 = clock();
      blocks(b, "P2G sym", [&](std::size_t i, std::size_t k, std::size_t* f) { return cs.p2g_sym_range(i, k, f); });
      const auto t1 = clock();
      grid_update(cs.g, cs.thermal);
      const auto t2 = clock();
      blocks(b, "G2P", [&](std::size_t i, std::size_t k, std::size_t* f) { return cs.g2p_range(i, k, f); });
      const auto t3 = clock();
      cs.zero_df();
      const auto t4 = clock();
      blocks(b, "apply", [&](std::size_t i, std::size_t k, std::size_t* f) { return cs.apply_range(i, k, f); });
      const auto t5 = clock();
      if (r >= 0) lib[j].push_back(ns(t0, t1) + ns(t2, t3)), apply[j].push_back(ns(t4, t5));
    }
  cs.restore();
  auto median = [](std::vector<double>& v) {
    std::sort(v.begin(), v.end());
    return v[v.size() / 2];
  };
  BlockTiming bt;
  bt.scene = scene_name(s), bt.kase = Api<T, D>::name, bt.n = n;
  for (int j = 0; j < kNumBlocks; ++j) bt.lib[j] = median(lib[j]), bt.apply[j] = median(apply[j]);
  std::fprintf(stderr, "blocks %s %s: lib", bt.scene.c_str(), bt.kase.c_str());
  for (int j = 0; j < kNumBlocks; ++j) std::fprintf(stderr, " %zu:%.1f", kBlocks[j], bt.lib[j]);
  std::fprintf(stderr, ", apply");
  for (int j = 0; j < kNumBlocks; ++j) std::fprintf(stderr, " %zu:%.1f", kBlocks[j], bt.apply[j]);
  std::fputc('\n', stderr);
  return bt;
}

std::string fmt(double ns) {
  if (std::isnan(ns)) return "n/a";
  char b[32];
  std::snprintf(b, sizeof b, ns < 10 ? "%.2f" : ns < 100 ? "%.1f" : "%.0f", ns);
  return b;
}

/// Target of the library time (P2G sym + G2P) of a row, ns, or NaN.
double lib_target(const Row& r) {
  if (r.kase == "3D f32") {
    if (r.scene == std::string("elastic")) return 100;
    if (r.scene == std::string("fluid")) return 60;
    if (r.scene == std::string("thermal+phase")) return 130;
  }
  if (r.kase == "2D f32" && r.scene == std::string("elastic")) return 30;
  return NAN;
}

std::string verdict(double got, double target) {
  if (std::isnan(target)) return "";
  return got <= target ? " ✓" : " ✗";
}

/// The hardware-limit section of the report: per dimension, the floors against the library
/// (default ISA) and, in 3D, the Eigen baseline, all from this run.
std::string floor_report(const std::vector<Row>& rows, const Baseline& base, const std::vector<Floor>& floors,
                         std::uint32_t default_isa) {
  std::ostringstream o;
  char buf[64];
  o << "Hardware limit, elastic f32, measured in this run (`c_tests/bench_floor.hpp`). Memory floor: the bytes "
       "each call's interface reads and writes (every particle array it reads, summed; every array it updates, "
       "read and written back; the grid channels), streamed once in order. Arithmetic floor: the node loops' "
       "fused multiply-adds alone (per node 2 + 3d + d² for P2G, d(1 + 2d) for G2P; constitutive model, "
       "weights and checks not counted) at the FMA rate measured on independent accumulators";
  if (!floors.empty()) {
    std::snprintf(buf, sizeof buf, " (%.0f f32 FMAs per ns)", floors.front().fma_per_ns);
    o << buf;
  }
  o << ". The floor is the larger of the two: any implementation of these calls moves these bytes and does at least "
       "these multiply-adds, so it cannot be much faster than the floor on this machine.\n\n";
  o << "| | P2G sym | G2P | P2G + G2P | × floor |\n|---|---:|---:|---:|---:|\n";
  for (const Floor& f : floors) {
    const std::string kase = std::to_string(f.d) + "D f32";
    const Row* lib = nullptr;
    for (const Row& r : rows)
      if (r.isa == isa_name(default_isa) && r.kase == kase && r.scene == std::string("elastic")) lib = &r;
    const double floor = f.p2g() + f.g2p();
    auto line = [&](const std::string& what, double p2g, double g2p) {
      std::snprintf(buf, sizeof buf, "%.1f", (p2g + g2p) / floor);
      o << "| " << kase << " " << what << " | " << fmt(p2g) << " | " << fmt(g2p) << " | " << fmt(p2g + g2p) << " | "
        << buf << " |\n";
    };
    std::snprintf(buf, sizeof buf, "%.0f / %.0f", f.bytes_p2g, f.bytes_g2p);
    line(std::string("memory floor (") + buf + " B per particle)", f.mem_p2g, f.mem_g2p);
    line("arithmetic floor (node loops)", f.fma_p2g, f.fma_g2p);
    line("**floor**", f.p2g(), f.g2p());
    if (f.d == 3) {
      line(std::string("library (") + isa_name(default_isa) + "), alternating with the baseline", base.lib_p2g,
           base.lib_g2p);
      line("Eigen baseline, alternating with the library", base.p2g, base.g2p);
    } else if (lib) {
      line(std::string("library (") + isa_name(default_isa) + ")", lib->p2g_sym, lib->g2p);
    }
    std::snprintf(buf, sizeof buf, "%.1f", f.d == 3 ? 100 / floor : 30 / floor);
    o << "| " << kase << " target (" << (f.d == 3 ? 100 : 30) << " ns) | | | " << (f.d == 3 ? 100 : 30) << " | " << buf
      << " |\n";
  }
  o << "\n";
  return o.str();
}

std::string report(const std::vector<Row>& rows, const Baseline& base, const std::vector<Floor>& floors,
                   const HppTiming& hpp, const std::vector<BlockTiming>& blocks, const std::vector<std::string>& checks,
                   int reps, std::uint32_t default_isa, const std::string& load_before) {
  std::ostringstream o;
  o << "# ampm particle transfers in a host's step loop\n\n";
  o << "CPU: " << cpu_model() << "; default instruction set (`ampm_isa()`): " << isa_name(default_isa)
    << "; compiler: " << compiler() << " for the host code and the Eigen baseline; libampm built by cargo "
    << "(release). One thread, no OpenMP. `c_tests/bench_transfers`. Load average (1 min) before / after the "
    << "timing: " << load_before << " / " << load_average() << " on " << std::thread::hardware_concurrency()
    << " hardware threads.\n\n";
  o << "ns per particle per step, median of " << reps
    << " runs after one warm-up run. Quadratic B-splines, 2 particles per cell per axis (spacing h/2), "
       "38³ = 54,872 particles (3D) or 234² = 54,756 (2D), particles sorted by cell, grid sized to the block. "
       "P2G sym: impulse_dt = Δt, no force channel; P2G +f: impulse_dt = 0 and force channels; grid: the "
       "host's update (v = p/m, T = E/C), not library time; G2P: ampm_g2p_update_*; step: zeroing + P2G sym "
       "+ grid + G2P; lib = P2G sym + G2P (the targets); prepare: ampm_force_prepare_* (PSD), once per Newton "
       "step; apply: zeroing df + ampm_force_apply_*, once per CG iteration.\n\n";
  o << "| scene | case | ISA | P2G sym | P2G +f | grid (host) | G2P | step | lib | lib target | prepare | apply | "
       "apply target |\n";
  o << "|---|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n";
  for (const Row& r : rows) {
    const double t = lib_target(r);
    const double at = r.kase == "3D f32" ? 40 : NAN;
    o << "| " << r.scene << " | " << r.kase << " | " << r.isa << " | " << fmt(r.p2g_sym) << " | " << fmt(r.p2g_f) << " | "
      << fmt(r.grid) << " | " << fmt(r.g2p) << " | " << fmt(r.step) << " | " << fmt(r.lib()) << verdict(r.lib(), t)
      << " | " << (std::isnan(t) ? "—" : fmt(t)) << " | " << fmt(r.prepare) << " | " << fmt(r.apply)
      << verdict(r.apply, at) << " | " << (std::isnan(at) ? "—" : fmt(at)) << " |\n";
  }
  o << "\nTargets (on the default instruction set): 3D f32 lib elastic ≤ 100 ns, fluid ≤ 60 ns, thermal+phase ≤ "
       "130 ns; 2D f32 elastic ≤ 30 ns; 3D f32 force apply ≤ 40 ns. ✓ met, ✗ not met.\n\n";
  // Summary against the targets on the default ISA.
  o << "| target (default ISA, " << isa_name(default_isa) << ") | median | fastest run | met (median) |\n"
       "|---|---:|---:|---|\n";
  for (const Row& r : rows) {
    if (r.isa != isa_name(default_isa)) continue;
    const double t = lib_target(r);
    if (!std::isnan(t))
      o << "| " << r.kase << " " << r.scene << " P2G + G2P ≤ " << fmt(t) << " ns | " << fmt(r.lib()) << " | "
        << fmt(r.lib_min()) << " | " << (r.lib() <= t ? "yes" : "no") << " |\n";
    if (r.kase == "3D f32" && r.scene == std::string("elastic"))
      o << "| 3D f32 force apply ≤ 40 ns | " << fmt(r.apply) << " | " << fmt(r.apply_min) << " | "
        << (r.apply <= 40 ? "yes" : "no") << " |\n";
  }
  o << "\n";
  o << "Hand-written Eigen baseline, elastic 3D f32 (" << base.n
    << " particles): the same P2G sym + G2P loop a host writes itself, one `Eigen::JacobiSVD` (full U, V) per "
       "particle for the stress, the same B-spline loops and grid arrays. Timed against the library ("
    << isa_name(default_isa)
    << ") alternately, call by call (library P2G, Eigen P2G, library G2P, Eigen G2P, one warm-up round), so that "
       "both see the same machine state; medians of the rounds.\n\n";
  o << "| | P2G sym | G2P | P2G + G2P | baseline / library |\n|---|---:|---:|---:|---:|\n";
  char ratio[32];
  std::snprintf(ratio, sizeof ratio, "%.2f", (base.p2g + base.g2p) / (base.lib_p2g + base.lib_g2p));
  o << "| library (" << isa_name(default_isa) << ") | " << fmt(base.lib_p2g) << " | " << fmt(base.lib_g2p) << " | "
    << fmt(base.lib_p2g + base.lib_g2p) << " | |\n";
  o << "| Eigen baseline | " << fmt(base.p2g) << " | " << fmt(base.g2p) << " | " << fmt(base.p2g + base.g2p) << " | "
    << ratio << " |\n\n";
  o << floor_report(rows, base, floors, default_isa);
  o << "C++ wrapper `include/ampm.hpp`, elastic 3D f32 (" << hpp.n << " particles, " << isa_name(default_isa)
    << "): the step (zeroing + P2G sym + grid + G2P) through `ampm::p2g` / `ampm::g2p_update` with the "
       "builders made per call, against the same step through the C calls, alternating rep by rep.\n\n";
  char hr[32], hr_min[32];
  std::snprintf(hr, sizeof hr, "%.2f", hpp.hpp / hpp.c);
  std::snprintf(hr_min, sizeof hr_min, "%.2f", hpp.hpp_min / hpp.c_min);
  o << "| | step, C calls | step, ampm.hpp | ampm.hpp / C |\n|---|---:|---:|---:|\n";
  o << "| median | " << fmt(hpp.c) << " | " << fmt(hpp.hpp) << " | " << hr << " |\n";
  o << "| fastest run | " << fmt(hpp.c_min) << " | " << fmt(hpp.hpp_min) << " | " << hr_min << " |\n\n";
  o << "Block calls (" << isa_name(default_isa)
    << "): the same lib (P2G sym + G2P) and apply, each call over a range of consecutive particles (the "
       "sorted order) into the same grid views, as a host that gives each thread its blocks makes them; "
       "the sizes alternate rep by rep. ns per particle per step (ratio to one call); per call: the "
       "difference to one call divided by the extra calls (lib: two calls per block), given for blocks of at "
       "most " << kPerCallMax << " particles (above that the difference is within the spread between runs).\n\n";
  o << "| scene | case | particles per call | lib | apply | per call, lib | per call, apply |\n"
       "|---|---|---:|---:|---:|---:|---:|\n";
  for (const BlockTiming& b : blocks)
    for (int j = 0; j < kNumBlocks; ++j) {
      char row[256];
      const double calls = j == 0 ? 1.0 : std::ceil(static_cast<double>(b.n) / static_cast<double>(kBlocks[j]));
      const double nn = static_cast<double>(b.n);
      if (j == 0 || kBlocks[j] > kPerCallMax)
        std::snprintf(row, sizeof row, "| %s | %s | %s | %s%s | %s%s | — | — |\n", b.scene.c_str(), b.kase.c_str(),
                      j == 0 ? ("all (" + std::to_string(b.n) + ")").c_str() : std::to_string(kBlocks[j]).c_str(),
                      fmt(b.lib[j]).c_str(), j == 0 ? "" : ratio_text(b.lib[j] / b.lib[0]).c_str(),
                      fmt(b.apply[j]).c_str(), j == 0 ? "" : ratio_text(b.apply[j] / b.apply[0]).c_str());
      else
        std::snprintf(row, sizeof row, "| %s | %s | %zu | %s (%.2f) | %s (%.2f) | %.0f ns | %.0f ns |\n",
                      b.scene.c_str(), b.kase.c_str(), kBlocks[j], fmt(b.lib[j]).c_str(), b.lib[j] / b.lib[0],
                      fmt(b.apply[j]).c_str(), b.apply[j] / b.apply[0], (b.lib[j] - b.lib[0]) * nn / (2 * (calls - 1)),
                      (b.apply[j] - b.apply[0]) * nn / (calls - 1));
      o << row;
    }
  o << "\n";
  o << "Agreement checks (run before timing; `bench_transfers --check` runs them alone on 6³ / 14² blocks):\n\n";
  for (const std::string& c : checks) o << "- " << c << "\n";
  return o.str();
}

template <class T, int D>
void time_case(Scene s, int per_axis, int reps, const std::vector<std::uint32_t>& isas, std::vector<Row>& rows) {
  Case<T, D> cs(s, per_axis);
  for (std::uint32_t isa : isas) {
    if (ampm_set_isa(isa) != AMPM_OK) fail("ampm_set_isa failed");
    rows.push_back(cs.time(reps, isa));
    const Row& r = rows.back();
    std::fprintf(stderr, "%-14s %s %-8s P2G sym %6.1f  P2G +f %6.1f  grid %5.1f  G2P %6.1f  step %6.1f  prepare %6.1f  apply %6.1f\n",
                 r.scene.c_str(), r.kase.c_str(), r.isa.c_str(), r.p2g_sym, r.p2g_f, r.grid, r.g2p, r.step, r.prepare, r.apply);
  }
}

Baseline time_baseline(int per_axis, int reps) {
  Case<float, 3> cs(Scene::Elastic, per_axis);
  Baseline b;
  b.n = cs.p.n;
  const float mu = static_cast<float>(kMu), lambda = static_cast<float>(kLambda);
  std::size_t ff = 0;
  auto check = [&](const char* what, AmpmStatus st) { expect_ok(std::string("baseline run, library ") + what, st, ff, cs.p.n); };
  auto once = [&](auto&& before, auto&& body) {
    before();
    const auto t0 = std::chrono::steady_clock::now();
    body();
    const auto t1 = std::chrono::steady_clock::now();
    return std::chrono::duration<double, std::nano>(t1 - t0).count() / static_cast<double>(cs.p.n);
  };
  std::vector<double> ep, eg, lp, lg;
  auto zero = [&] { cs.g.zero_p2g(); };
  auto restore = [&] { cs.restore(); };
  for (int r = -1; r < reps; ++r) {
    // P2G: library, then Eigen; the grid update from Eigen's P2G feeds both G2Ps (the two P2G
    // grids agree to rounding, checked before timing).
    const double a = once(zero, [&] { check("P2G sym", cs.p2g_sym(&ff)); });
    const double b2 = once(zero, [&] { eigen_p2g<float, 3>(cs.p, cs.g, cs.h, cs.dt, mu, lambda, nullptr); });
    grid_update(cs.g, false);
    const double c = once(restore, [&] { check("G2P", cs.g2p(&ff)); });
    const double d = once(restore, [&] { eigen_g2p<float, 3>(cs.p, cs.g, cs.h, cs.dt); });
    if (r >= 0) lp.push_back(a), ep.push_back(b2), lg.push_back(c), eg.push_back(d);
  }
  cs.restore();
  auto median = [](std::vector<double>& v) {
    std::sort(v.begin(), v.end());
    return v[v.size() / 2];
  };
  b.p2g = median(ep), b.g2p = median(eg), b.lib_p2g = median(lp), b.lib_g2p = median(lg);
  return b;
}

template <int D>
Floor time_floor(int per_axis, int reps, double fma_per_ns) {
  Case<float, D> cs(Scene::Elastic, per_axis);
  auto& p = cs.p;
  auto& g = cs.g;
  // The arrays the elastic calls read and write (include/ampm.h): P2G reads every particle
  // array and adds into mass and momentum; G2P reads mass, volume and the node velocities,
  // and updates x, v, affine, F_E, F_P.
  bench_floor::Streams<float> p2g{{&p.x, &p.v, &p.c, &p.fe, &p.fp, &p.m, &p.v0}, {&g.mass}};
  bench_floor::Streams<float> g2p{{&p.m, &p.v0}, {&p.x, &p.v, &p.c, &p.fe, &p.fp}};
  for (int a = 0; a < D; ++a) p2g.update.push_back(&g.mom[a]), g2p.read.push_back(&g.vel[a]);
  volatile float one_v = 1.0f;
  const float one = one_v;
  Floor f;
  f.d = D;
  const auto n = static_cast<double>(p.n);
  f.bytes_p2g = static_cast<double>(p2g.bytes()) / n;
  f.bytes_g2p = static_cast<double>(g2p.bytes()) / n;
  f.mem_p2g = median_ns(reps, p.n, [] {}, [&] { bench_floor::stream(p2g, one); });
  f.mem_g2p = median_ns(reps, p.n, [] {}, [&] { bench_floor::stream(g2p, one); });
  f.fma_per_ns = fma_per_ns;
  f.fma_p2g = bench_floor::p2g_fmas(D) / fma_per_ns;
  f.fma_g2p = bench_floor::g2p_fmas(D) / fma_per_ns;
  return f;
}

// ---- A/B: two builds of the library, alternately -------------------------------------------

/// One build of the library, loaded with dlopen (RTLD_LOCAL: its own symbols and state).
struct AbLib {
  std::string path;
  void* handle = nullptr;
  AmpmStatus (*set_isa)(std::uint32_t) = nullptr;

  explicit AbLib(std::string p) : path(std::move(p)) {
    handle = dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
    if (handle == nullptr) fail("dlopen " + path + ": " + dlerror());
    set_isa = sym<AmpmStatus (*)(std::uint32_t)>("ampm_set_isa");
  }
  AbLib(const AbLib&) = delete;
  AbLib& operator=(const AbLib&) = delete;
  template <class F>
  F sym(const std::string& name) const {
    void* f = dlsym(handle, name.c_str());
    if (f == nullptr) fail(path + " has no symbol " + name);
    return reinterpret_cast<F>(f);
  }
};

/// The calls of one build for `Api<T, D>`, resolved by name.
template <class T, int D>
struct AbFns {
  using A = Api<T, D>;
  std::remove_const_t<decltype(A::p2g)> p2g;
  std::remove_const_t<decltype(A::g2p)> g2p;
  std::remove_const_t<decltype(A::prepare)> prepare;
  std::remove_const_t<decltype(A::apply)> apply;

  explicit AbFns(const AbLib& l)
      : p2g(l.sym<decltype(p2g)>(A::p2g_sym)),
        g2p(l.sym<decltype(g2p)>(A::g2p_sym)),
        prepare(l.sym<decltype(prepare)>(A::prepare_sym)),
        apply(l.sym<decltype(apply)>(A::apply_sym)) {}
};

/// The calls an A/B row times, in its columns' order.
constexpr const char* kAbCalls[] = {"lib", "prepare", "apply"};
constexpr int kAbN = sizeof kAbCalls / sizeof kAbCalls[0];

/// One A/B row: medians (ns per particle) of both builds, per call of kAbCalls.
struct AbRow {
  std::string scene, kase, isa;
  double t[kAbN][2] = {};
};

/// Times one case on instruction set `isa` with both builds alternately (see the header).
template <class T, int D>
void ab_case(Scene s, int per_axis, int reps, std::uint32_t isa, const AbLib* libs[2], std::vector<AbRow>& rows) {
  for (int k = 0; k < 2; ++k)
    if (libs[k]->set_isa(isa) != AMPM_OK) return;
  Case<T, D> cs(s, per_axis);
  const AbFns<T, D> fns[2] = {AbFns<T, D>(*libs[0]), AbFns<T, D>(*libs[1])};
  const std::size_t n = cs.p.n;
  std::size_t ff = 0;
  auto check = [&](int k, const char* what, AmpmStatus st) {
    expect_ok(cs.label(what) + " (" + libs[k]->path + ")", st, ff, n);
  };
  auto p2g = [&](int k) { check(k, "P2G sym", cs.p2g_sym(&ff, fns[k].p2g)); };
  auto g2p = [&](int k) { check(k, "G2P", cs.g2p(&ff, fns[k].g2p)); };
  auto prepare = [&](int k) { check(k, "prepare", cs.prepare(&ff, fns[k].prepare)); };
  auto apply = [&](int k) {
    cs.zero_df();
    check(k, "apply", cs.apply(&ff, fns[k].apply));
  };
  auto clock = [] { return std::chrono::steady_clock::now(); };
  auto ns = [&](auto t0, auto t1) { return std::chrono::duration<double, std::nano>(t1 - t0).count() / static_cast<double>(n); };
  // Results first: the same grids, particles and forces from both builds, bit for bit.
  std::vector<T> grid[2], parts[2], slots[2], df[2];
  std::vector<std::uint8_t> phase[2];
  auto append = [](std::vector<T>& to, const std::vector<T>& from) { to.insert(to.end(), from.begin(), from.end()); };
  for (int k = 0; k < 2; ++k) {
    cs.restore();
    cs.g.zero_p2g();
    p2g(k);
    for (const auto* ch : {&cs.g.mass, &cs.g.hc, &cs.g.te, &cs.g.cond}) append(grid[k], *ch);
    for (int a = 0; a < D; ++a) append(grid[k], cs.g.mom[a]);
    grid_update(cs.g, cs.thermal);
    g2p(k);
    for (const auto* f : {&cs.p.x, &cs.p.v, &cs.p.c, &cs.p.fe, &cs.p.fp, &cs.p.t, &cs.p.u}) append(parts[k], *f);
    phase[k] = cs.p.ph;
    cs.restore();
    prepare(k);
    slots[k] = cs.slots;
    apply(k);
    for (int a = 0; a < D; ++a) append(df[k], cs.g.df[a]);
  }
  auto same = [](const std::vector<T>& a, const std::vector<T>& b) {
    return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0;
  };
  if (!same(grid[0], grid[1]) || !same(parts[0], parts[1]) || !same(slots[0], slots[1]) || !same(df[0], df[1]) ||
      phase[0] != phase[1])
    fail(cs.label("results") + " on " + isa_name(isa) + ": the two builds differ");
  std::vector<double> times[kAbN][2];  // per call of kAbCalls and build
  for (int r = -1; r < reps; ++r) {
    for (int j = 0; j < 2; ++j) {
      const int k = (r + j + 2) % 2;
      cs.restore();
      cs.g.zero_p2g();
      const auto t0 = clock();
      p2g(k);
      const auto t1 = clock();
      grid_update(cs.g, cs.thermal);
      const auto t2 = clock();
      g2p(k);
      const auto t3 = clock();
      cs.restore();
      const auto t4 = clock();
      prepare(k);
      const auto t5 = clock();
      apply(k);
      const auto t6 = clock();
      if (r >= 0) {
        times[0][k].push_back(ns(t0, t1) + ns(t2, t3));
        times[1][k].push_back(ns(t4, t5));
        times[2][k].push_back(ns(t5, t6));
      }
    }
  }
  cs.restore();
  auto median = [](std::vector<double>& v) {
    std::sort(v.begin(), v.end());
    return v[v.size() / 2];
  };
  AbRow row;
  row.scene = scene_name(s), row.kase = Api<T, D>::name, row.isa = isa_name(isa);
  std::fprintf(stderr, "%-14s %s %-8s", row.scene.c_str(), row.kase.c_str(), row.isa.c_str());
  for (int c = 0; c < kAbN; ++c) {
    for (int k = 0; k < 2; ++k) row.t[c][k] = median(times[c][k]);
    std::fprintf(stderr, "  %s %6.1f / %6.1f (%.3f)", kAbCalls[c], row.t[c][0], row.t[c][1], row.t[c][1] / row.t[c][0]);
  }
  std::fputc('\n', stderr);
  rows.push_back(row);
}

/// The A/B comparison (--ab): a markdown table of both builds' medians and their ratio.
int run_ab(const std::string& a, const std::string& b, int reps) {
  const AbLib la(a), lb(b);
  const AbLib* libs[2] = {&la, &lb};
  std::vector<AbRow> rows;
  for (Scene s : {Scene::Elastic, Scene::Fluid, Scene::Thermal})
    for (std::uint32_t isa : {std::uint32_t{AMPM_ISA_AVX512}, std::uint32_t{AMPM_ISA_AVX2}}) {
      ab_case<float, 3>(s, 38, reps, isa, libs, rows);
      ab_case<float, 2>(s, 234, reps, isa, libs, rows);
    }
  std::ostringstream o;
  o << "A/B (bench_transfers --ab, " << reps << " reps, alternating): A = `" << a << "`, B = `" << b << "`\n"
    << "CPU: " << cpu_model() << "; load before: " << load_average() << "\n\n"
    << "| scene | case | ISA |";
  for (const char* c : kAbCalls) o << " " << c << " A | " << c << " B | B / A |";
  o << "\n|---|---|---|";
  for (int c = 0; c < kAbN; ++c) o << "---|---|---|";
  o << "\n";
  char buf[64];
  auto num = [&](double x, const char* f) {
    std::snprintf(buf, sizeof buf, f, x);
    return std::string(buf);
  };
  for (const AbRow& r : rows) {
    o << "| " << r.scene << " | " << r.kase << " | " << r.isa << " |";
    for (const auto& t : r.t)
      o << " " << num(t[0], "%.1f") << " | " << num(t[1], "%.1f") << " | " << num(t[1] / t[0], "%.3f") << " |";
    o << "\n";
  }
  std::fputs(o.str().c_str(), stdout);
  return 0;
}

[[noreturn]] void usage(int code) {
  std::fprintf(code == 0 ? stdout : stderr,
               "usage: bench_transfers [--out FILE] [--reps R]   time every case (default FILE docs/bench-transfers.md)\n"
               "       bench_transfers --check                   agreement checks only, tiny sizes\n"
               "       bench_transfers --ab A.so B.so [--reps R] two builds of libampm.so timed alternately\n");
  std::exit(code);
}

}  // namespace

int main(int argc, char** argv) {
  bool check = false;
  int reps = kDefaultReps;
  std::string out = "docs/bench-transfers.md";
  bool out_given = false;
  std::string ab[2];
  bool reps_given = false;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--check") {
      check = true;
    } else if (arg == "--ab" && i + 2 < argc) {
      ab[0] = argv[++i];
      ab[1] = argv[++i];
    } else if (arg == "--out" && i + 1 < argc) {
      out = argv[++i];
      out_given = true;
    } else if (arg == "--reps" && i + 1 < argc) {
      reps = std::atoi(argv[++i]);
      if (reps < 1 || reps > 1000) fail("--reps wants 1..1000");
      reps_given = true;
    } else if (arg == "--help" || arg == "-h") {
      usage(0);
    } else {
      std::fprintf(stderr, "bench_transfers: unknown or incomplete argument '%s'\n", arg.c_str());
      usage(2);
    }
  }
  if (!ab[0].empty()) return run_ab(ab[0], ab[1], reps_given ? reps : 31);
  const std::uint32_t default_isa = ampm_isa();
  std::vector<std::uint32_t> isas;
  for (std::uint32_t isa : {std::uint32_t{AMPM_ISA_AVX512}, std::uint32_t{AMPM_ISA_AVX2}, std::uint32_t{AMPM_ISA_SCALAR}})
    if (ampm_set_isa(isa) == AMPM_OK) isas.push_back(isa);
  ampm_set_isa(default_isa);

  // ---- agreement checks (always) ----
  CheckLog log;
  check_elastic<float, 3>(6, log);
  check_elastic<double, 3>(6, log);
  check_elastic<float, 2>(14, log);
  check_elastic<double, 2>(14, log);
  for (Scene s : kScenes) {
    check_isas<float, 3>(s, 6, isas, log);
    check_isas<double, 3>(s, 6, isas, log);
    check_isas<float, 2>(s, 14, isas, log);
    check_isas<double, 2>(s, 14, isas, log);
  }
  ampm_set_isa(default_isa);
  for (Scene s : kScenes) {
    check_blocks<float, 3>(s, 6, log);
    check_blocks<float, 2>(s, 14, log);
  }
  check_hpp(6, log);
  if (check) {
    std::printf("bench_transfers --check: all results agree\n");
    if (!out_given) return 0;
  }

  // ---- timing ----
  const std::string load_before = load_average();
  std::vector<Row> rows;
  const int n3 = check ? 6 : 38, n2 = check ? 14 : 234;
  for (Scene s : kScenes) {
    time_case<float, 3>(s, n3, reps, isas, rows);
    time_case<double, 3>(s, n3, reps, isas, rows);
    time_case<float, 2>(s, n2, reps, isas, rows);
    time_case<double, 2>(s, n2, reps, isas, rows);
  }
  ampm_set_isa(default_isa);
  const Baseline base = time_baseline(n3, reps);
  const double fma_rate = bench_floor::fma_per_ns(reps);
  const std::vector<Floor> floors{time_floor<3>(n3, reps, fma_rate), time_floor<2>(n2, reps, fma_rate)};
  for (const Floor& f : floors)
    std::fprintf(stderr, "floor %dD f32: memory P2G %.1f G2P %.1f ns (%.0f / %.0f B), arithmetic %.1f / %.1f ns\n", f.d,
                 f.mem_p2g, f.mem_g2p, f.bytes_p2g, f.bytes_g2p, f.fma_p2g, f.fma_g2p);
  const HppTiming hpp = time_hpp(n3, reps);
  std::fprintf(stderr, "ampm.hpp elastic 3D f32 step: C %.1f ns, ampm.hpp %.1f ns, ratio %.3f (fastest %.3f)\n", hpp.c,
               hpp.hpp, hpp.hpp / hpp.c, hpp.hpp_min / hpp.c_min);
  std::vector<BlockTiming> blocks;
  blocks.push_back(time_blocks<float, 3>(Scene::Elastic, n3, reps));
  blocks.push_back(time_blocks<float, 3>(Scene::Fluid, n3, reps));
  blocks.push_back(time_blocks<float, 2>(Scene::Elastic, n2, reps));
  const std::string text = report(rows, base, floors, hpp, blocks, log.lines, reps, default_isa, load_before);
  std::fputs(text.c_str(), stdout);
  std::ofstream f(out);
  f << text;
  f.close();
  if (!f) fail("cannot write " + out);
  return 0;
}
