// Agreement checks run before timing: the elastic scene against long double, every scene on
// every instruction set.
#pragma once

#include "case.hpp"
#include "eigen_baseline.hpp"

namespace bench {

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

inline int n_add_of(int d) { return d == 2 ? 36 : 216; }  // 2 particles per cell per axis: (3·2)^d

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

}  // namespace bench
