// Shared helpers of the C++/Eigen tests of the ampm C ABI (c_tests/test_*.cpp).
//
// - `Checker` and AMPM_CHECK: count checks, print failures with file:line, exit status.
// - `Rng`: seeded std::mt19937_64 with portable uniform/normal draws (same numbers with any
//   standard library, unlike std::*_distribution).
// - Random inputs: Haar rotations, F with prescribed singular values, random Z.
// - Error helpers: relative errors, ulp distances, bitwise equality, sentinels.
// - `Reference<D>`: an INDEPENDENT long-double reference of the fixed corotated energy and its
//   augmented derivatives. It shares no code or formula with the library beyond the seed's
//   definitions: R comes from Eigen's JacobiSVD, δR from solving the defining Sylvester
//   equation, 𝓑 and Ĉ are explicit 4-index tensors built from the seed's index formulas.
//   test_kernels_eigen.cpp checks it against central finite differences.
// - `Api<T, D>`: the 14 kernel symbols of one (scalar, dimension), for generic tests.
// - `IsaRestore`, `simd_isas()`, `isa_name()`: the instruction set of the batch calls
//   (`ampm_set_isa` / `ampm_isa`), for running a batch test on each one.
//
// Conventions: matrices are column-major, as in the C ABI (`F[i + d*j] = F_ij`) and Eigen's
// default, so `Eigen::Matrix<T, D, D>::data()` can be passed straight to the library. A 4-index
// tensor `X_ijkl` is stored as an (d²×d²) matrix `X(vec(i,j), vec(k,l))`, `vec(i,j) = i + d*j`
// (the index of M_ij in `M.data()`), so `vec(X:Z) = X * vec(Z)` and `vec(Z:X) = Xᵀ vec(Z)`.
#ifndef AMPM_C_TESTS_COMMON_HPP
#define AMPM_C_TESTS_COMMON_HPP

// <cstdint>/<cstddef> first: whether ampm.h is self-contained is the job of the header_c99 and
// header_cxx17 tests, not a reason for every functional test to stop compiling.
#include <cstddef>
#include <cstdint>

#include "ampm.h"

#include <Eigen/Dense>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <random>
#include <type_traits>
#include <vector>

namespace ampm_test {

using ld = long double;

template <class T, int D>
using Mat = Eigen::Matrix<T, D, D>;  // column-major (Eigen's default)
template <int D>
using MatL = Mat<ld, D>;

// ---- checks --------------------------------------------------------------------------------

/// Counts checks and failures; `main` returns `checker.exit_code()`.
struct Checker {
  long checks = 0;
  long failures = 0;
  /// Records one check; returns `ok`. On failure prints `file:line: FAIL what` (the caller
  /// then prints details; see AMPM_CHECK).
  bool record(bool ok, const char* file, int line, const char* what) {
    ++checks;
    if (!ok) {
      ++failures;
      std::fprintf(stderr, "%s:%d: FAIL %s: ", file, line, what);
    }
    return ok;
  }
  int exit_code() const { return failures == 0 ? 0 : 1; }
  void summary(const char* name) const {
    std::printf("%s: %ld checks, %ld failures\n", name, checks, failures);
  }
};

/// AMPM_CHECK(checker, cond, printf-format, args...): on failure prints the format + newline.
#define AMPM_CHECK(ck, cond, ...)                                      \
  do {                                                                 \
    if (!(ck).record(static_cast<bool>(cond), __FILE__, __LINE__, #cond)) { \
      std::fprintf(stderr, __VA_ARGS__);                               \
      std::fputc('\n', stderr);                                        \
    }                                                                  \
  } while (0)

inline const char* status_name(AmpmStatus s) {
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

#define AMPM_CHECK_STATUS(ck, call, expected)                                               \
  do {                                                                                      \
    const AmpmStatus ampm_st_ = (call);                                                     \
    AMPM_CHECK(ck, ampm_st_ == (expected), "%s returned %s, expected %s", #call,            \
               ::ampm_test::status_name(ampm_st_), ::ampm_test::status_name(expected));     \
  } while (0)

// ---- instruction sets of the batch calls ---------------------------------------------------

inline const char* isa_name(std::uint32_t isa) {
  switch (isa) {
    case AMPM_ISA_SCALAR: return "scalar";
    case AMPM_ISA_AVX2: return "AVX2";
    case AMPM_ISA_AVX512: return "AVX-512";
  }
  return "(unknown ISA)";
}

/// Restores the instruction set of the batch calls (`ampm_isa()` at construction) when it
/// goes out of scope, so a test that switches ISAs leaves the process as it found it.
class IsaRestore {
 public:
  IsaRestore() : prev_(ampm_isa()) {}
  ~IsaRestore() { ampm_set_isa(prev_); }
  IsaRestore(const IsaRestore&) = delete;
  IsaRestore& operator=(const IsaRestore&) = delete;
  std::uint32_t previous() const { return prev_; }

 private:
  std::uint32_t prev_;
};

/// The SIMD instruction sets this CPU supports, narrowest first: those of AMPM_ISA_AVX2 and
/// AMPM_ISA_AVX512 that `ampm_set_isa` accepts (AMPM_ERR_INVALID_ARGUMENT = unsupported,
/// skipped). The current choice is restored before returning.
inline std::vector<std::uint32_t> simd_isas() {
  const IsaRestore keep;
  std::vector<std::uint32_t> out;
  for (std::uint32_t isa : {std::uint32_t{AMPM_ISA_AVX2}, std::uint32_t{AMPM_ISA_AVX512}})
    if (ampm_set_isa(isa) == AMPM_OK) out.push_back(isa);
  return out;
}

// ---- random numbers ------------------------------------------------------------------------

/// Seeded generator with portable draws (bit-identical sequences on every platform that has
/// IEEE doubles and the same libm; std::*_distribution differ between standard libraries).
class Rng {
 public:
  explicit Rng(std::uint64_t seed) : gen_(seed) {}

  /// Uniform in [0, 1), 53 random bits.
  double uniform01() { return static_cast<double>(gen_() >> 11) * 0x1.0p-53; }
  /// Uniform in [lo, hi).
  double uniform(double lo, double hi) { return lo + (hi - lo) * uniform01(); }
  /// Log-uniform in [lo, hi), lo > 0: ln x uniform in [ln lo, ln hi).
  double log_uniform(double lo, double hi) {
    return std::exp(uniform(std::log(lo), std::log(hi)));
  }
  /// Standard normal (Box–Muller; u1 in (0, 1] so the log is finite).
  double normal() {
    const double u1 = static_cast<double>((gen_() >> 11) + 1) * 0x1.0p-53;
    const double u2 = uniform01();
    return std::sqrt(-2.0 * std::log(u1)) * std::cos(6.283185307179586476925 * u2);
  }
  std::mt19937_64& engine() { return gen_; }

 private:
  std::mt19937_64 gen_;
};

/// Matrix of independent standard normal entries.
template <int D>
MatL<D> gaussian(Rng& rng) {
  MatL<D> g;
  for (int j = 0; j < D; ++j)
    for (int i = 0; i < D; ++i) g(i, j) = static_cast<ld>(rng.normal());
  return g;
}

/// Haar-distributed rotation in SO(d): Q of the QR factorisation of a Gaussian matrix with the
/// signs fixed so that diag(R) > 0 (this makes Q Haar on O(d); Mezzadri 2007, "How to generate
/// random matrices from the classical compact groups"), then one column negated if det Q < 0.
/// Negating a fixed column commutes with left multiplication by rotations, so the result is
/// Haar on SO(d).
template <int D>
MatL<D> haar_rotation(Rng& rng) {
  const Eigen::HouseholderQR<MatL<D>> qr(gaussian<D>(rng));
  MatL<D> q = qr.householderQ();
  const MatL<D> r = qr.matrixQR().template triangularView<Eigen::Upper>();
  for (int j = 0; j < D; ++j)
    if (r(j, j) < 0) q.col(j) = -q.col(j);
  if (q.determinant() < 0) q.col(0) = -q.col(0);
  return q;
}

/// F = U diag(σ) Vᵀ with U, V independent Haar rotations (so det F = Πσᵢ).
template <int D>
MatL<D> random_f_with_sigma(Rng& rng, const Eigen::Matrix<ld, D, 1>& sigma) {
  return haar_rotation<D>(rng) * sigma.asDiagonal() * haar_rotation<D>(rng).transpose();
}

/// Singular values drawn independently log-uniform in [lo, hi].
template <int D>
Eigen::Matrix<ld, D, 1> log_uniform_sigma(Rng& rng, double lo, double hi) {
  Eigen::Matrix<ld, D, 1> s;
  for (int i = 0; i < D; ++i) s(i) = static_cast<ld>(rng.log_uniform(lo, hi));
  return s;
}

/// A random direction Z (Gaussian entries).
template <int D>
MatL<D> random_z(Rng& rng) {
  return gaussian<D>(rng);
}

// ---- conversions and error measures -------------------------------------------------------

/// Rounds a long-double matrix to T (the library's input); convert back with `to_ld` so the
/// reference sees exactly the input the library saw.
template <class T, int D>
Mat<T, D> round_to(const MatL<D>& m) {
  return m.template cast<T>();
}

template <class T, int D>
MatL<D> to_ld(const Mat<T, D>& m) {
  return m.template cast<ld>();
}

/// ‖x − ref‖_F / scale.
template <class T, int D>
ld rel_err(const Mat<T, D>& x, const MatL<D>& ref, ld scale) {
  return (to_ld<T, D>(x) - ref).norm() / scale;
}

/// ‖x − ref‖_F / ‖ref‖_F (the reference must be non-zero).
template <class T, int D>
ld rel_err(const Mat<T, D>& x, const MatL<D>& ref) {
  return rel_err<T, D>(x, ref, ref.norm());
}

/// Frobenius inner product A:B = Σ A_ij B_ij.
template <int D>
ld ddot(const MatL<D>& a, const MatL<D>& b) {
  return a.cwiseProduct(b).sum();
}

/// Bitwise equality of n scalars (distinguishes −0 from +0 and NaN payloads).
template <class T>
bool same_bits(const T* a, const T* b, std::size_t n) {
  return std::memcmp(a, b, n * sizeof(T)) == 0;
}

/// Distance in units in the last place between two finite values of the same type (the number
/// of representable values between them; 0 when bit-identical or ±0).
template <class T>
std::uint64_t ulp_distance(T a, T b) {
  static_assert(std::is_floating_point<T>::value && (sizeof(T) == 4 || sizeof(T) == 8), "f32/f64");
  using I = typename std::conditional<sizeof(T) == 4, std::int32_t, std::int64_t>::type;
  using U = typename std::conditional<sizeof(T) == 4, std::uint32_t, std::uint64_t>::type;
  auto ordered = [](T x) {
    I i;
    std::memcpy(&i, &x, sizeof x);
    // Map the sign-magnitude bit patterns onto a monotone integer line.
    return i < 0 ? static_cast<I>(std::numeric_limits<I>::min() - i) : i;
  };
  const I ia = ordered(a), ib = ordered(b);
  return ia > ib ? static_cast<std::uint64_t>(static_cast<U>(ia) - static_cast<U>(ib))
                 : static_cast<std::uint64_t>(static_cast<U>(ib) - static_cast<U>(ia));
}

/// A value no kernel produces from the tests' inputs: marks "not written".
template <class T>
constexpr T sentinel() {
  return static_cast<T>(-12345.625);
}

template <class T>
bool all_sentinel(const T* x, std::size_t n) {
  const T s = sentinel<T>();
  for (std::size_t i = 0; i < n; ++i)
    if (std::memcmp(&x[i], &s, sizeof(T)) != 0) return false;
  return true;
}

/// Prints a matrix with hexadecimal floats (exact, for reproducing a failure).
template <class T, int D>
void print_exact(const char* name, const Mat<T, D>& m) {
  std::fprintf(stderr, "  %s (column-major) = {", name);
  for (int k = 0; k < D * D; ++k)
    std::fprintf(stderr, "%s%a", k ? ", " : "", static_cast<double>(m.data()[k]));
  std::fprintf(stderr, "}\n");
}

// ---- the long-double reference -------------------------------------------------------------

/// Independent long-double reference of Ψ̂, Â, 𝓑 and Ĉ for the fixed corotated energy, from
/// the definitions of the augmented-MPM tech report (Stomakhin et al. 2014; its J^{−1/a} and α
/// are typos for Jᵃ):
///   Ψ̂(F) = Ψ(Jᵃ F), a = −1/d, H = F⁻ᵀ, F̂ = Jᵃ F,
///   Ψ(F̂) = μ‖F̂ − R‖² = μ Σ(σᵢ − 1)², A = 2μ(F̂ − R), C:δF = 2μ(δF − δR)  (paper §4),
///   𝓑_kmij = ∂(JᵃF_km)/∂F_ij = Jᵃ δ_ik δ_jm + a Jᵃ F_km H_ij,
///   Â_ij = A_km 𝓑_kmij,
///   Ĉ_ijrs = C_kmtu 𝓑_turs 𝓑_kmij + a A_km 𝓑_kmij H_rs + a Jᵃ A_rs H_ij
///            − a Jᵃ A_km F_km H_rj H_is,
/// with A and C evaluated at F̂ (the report's index derivation, before it is contracted
/// into matrix form). Requires det F > 0.
template <int D>
class Reference {
 public:
  static constexpr int N = D * D;
  using M = MatL<D>;
  using Vec = Eigen::Matrix<ld, N, 1>;
  using Tensor = Eigen::Matrix<ld, N, N>;

  /// a = −1/d.
  static ld a() { return -1.0L / static_cast<ld>(D); }

  Reference(ld mu, const M& f) : mu_(mu), f_(f) {
    j_ = f.determinant();
    // Jᵃ by sqrt/cbrt (correctly rounded in long double) rather than pow(J, −1/d), whose
    // exponent −1/3 is itself rounded.
    ja_ = D == 2 ? 1.0L / std::sqrt(j_) : 1.0L / std::cbrt(j_);
    h_ = f.inverse().transpose();
    f_hat_ = ja_ * f;

    // Rotation-variant SVD of F̂ from Eigen's two-sided Jacobi SVD (σ ≥ 0 sorted decreasing,
    // U, V orthogonal): make U and V proper rotations by negating their last columns, each
    // negation moving a sign onto the last (smallest) singular value.
    const Eigen::JacobiSVD<M> svd(f_hat_, Eigen::ComputeFullU | Eigen::ComputeFullV);
    u_ = svd.matrixU();
    v_ = svd.matrixV();
    sigma_ = svd.singularValues();
    if (u_.determinant() < 0) {
      u_.col(D - 1) = -u_.col(D - 1);
      sigma_(D - 1) = -sigma_(D - 1);
    }
    if (v_.determinant() < 0) {
      v_.col(D - 1) = -v_.col(D - 1);
      sigma_(D - 1) = -sigma_(D - 1);
    }
    r_ = u_ * v_.transpose();
    s_ = v_ * sigma_.asDiagonal() * v_.transpose();

    ld psi = 0;
    for (int i = 0; i < D; ++i) psi += (sigma_(i) - 1) * (sigma_(i) - 1);
    psi_hat_ = mu_ * psi;
    a_ = 2 * mu_ * (f_hat_ - r_);

    // 𝓑 as an explicit tensor, entry by entry from the index formula.
    for (int k = 0; k < D; ++k)
      for (int m = 0; m < D; ++m)
        for (int i = 0; i < D; ++i)
          for (int j = 0; j < D; ++j)
            b_(idx(k, m), idx(i, j)) =
                ja_ * ((i == k && j == m) ? 1.0L : 0.0L) + a() * ja_ * f_(k, m) * h_(i, j);
    ahat_ = unvec(b_.transpose() * vec(a_));  // Â_ij = A_km 𝓑_kmij
  }

  ld mu() const { return mu_; }
  const M& f() const { return f_; }
  const M& h() const { return h_; }
  ld j() const { return j_; }
  ld ja() const { return ja_; }
  const M& f_hat() const { return f_hat_; }
  const M& rotation() const { return r_; }
  const Eigen::Matrix<ld, D, 1>& sigma() const { return sigma_; }
  /// A = ∂Ψ/∂F at F̂.
  const M& first_piola() const { return a_; }
  /// The tensor 𝓑.
  const Tensor& b_tensor() const { return b_; }

  /// Ψ̂(F).
  ld psi_hat() const { return psi_hat_; }
  /// Â(F) = A:𝓑.
  const M& ahat() const { return ahat_; }
  /// 𝓑:Z.
  M b_z(const M& z) const { return unvec(b_ * vec(z)); }
  /// Z:𝓑.
  M z_b(const M& z) const { return unvec(b_.transpose() * vec(z)); }
  /// Ĉ:Z.
  M chat_z(const M& z) const { return unvec(chat_tensor() * vec(z)); }

  /// δR at F̂ in direction δF, from its definition: F̂ = R S with S symmetric gives
  /// RᵀδF = W S + δS, W = RᵀδR skew, so RᵀδF − δFᵀR = W S + S W, a Sylvester equation with a
  /// unique solution for S positive definite; solved here as a d²×d² linear system.
  M d_rotation(const M& df) const {
    const M rhs = r_.transpose() * df - df.transpose() * r_;
    const M w = unvec(sylvester().solve(vec(rhs)));
    return r_ * w;
  }

  /// C = ∂A/∂F̂ as a tensor: column vec(t,u) is C:E_tu = 2μ(E_tu − δR(E_tu)).
  const Tensor& c_tensor() const {
    if (!have_c_) {
      for (int n = 0; n < N; ++n) {
        M e = M::Zero();
        e.data()[n] = 1;
        c_.col(n) = vec(2 * mu_ * (e - d_rotation(e)));
      }
      have_c_ = true;
    }
    return c_;
  }

  /// Ĉ as a tensor, from the index formula (see the class comment).
  const Tensor& chat_tensor() const {
    if (!have_chat_) {
      const Tensor& c = c_tensor();
      const ld a_f = ddot<D>(a_, f_);  // A_km F_km
      for (int i = 0; i < D; ++i)
        for (int j = 0; j < D; ++j)
          for (int r = 0; r < D; ++r)
            for (int s = 0; s < D; ++s) {
              ld t1 = 0;  // C_kmtu 𝓑_turs 𝓑_kmij
              for (int km = 0; km < N; ++km)
                for (int tu = 0; tu < N; ++tu)
                  t1 += c(km, tu) * b_(tu, idx(r, s)) * b_(km, idx(i, j));
              ld t2 = 0;  // A_km 𝓑_kmij H_rs
              for (int km = 0; km < N; ++km) t2 += a_.data()[km] * b_(km, idx(i, j));
              t2 *= a() * h_(r, s);
              const ld t3 = a() * ja_ * a_(r, s) * h_(i, j);
              const ld t4 = a() * ja_ * a_f * h_(r, j) * h_(i, s);
              chat_(idx(i, j), idx(r, s)) = t1 + t2 + t3 - t4;
            }
      have_chat_ = true;
    }
    return chat_;
  }

  static int idx(int i, int j) { return i + D * j; }
  static Vec vec(const M& m) { return Eigen::Map<const Vec>(m.data()); }
  static M unvec(const Vec& v) { return Eigen::Map<const M>(v.data()); }

 private:
  const Eigen::FullPivLU<Tensor>& sylvester() const {
    if (!have_lu_) {
      Tensor k;
      for (int n = 0; n < N; ++n) {
        M w = M::Zero();
        w.data()[n] = 1;
        k.col(n) = vec(w * s_ + s_ * w);
      }
      lu_.compute(k);
      have_lu_ = true;
    }
    return lu_;
  }

  ld mu_;
  M f_, h_, f_hat_, u_, v_, r_, s_, a_, ahat_;
  Eigen::Matrix<ld, D, 1> sigma_;
  ld j_ = 0, ja_ = 0, psi_hat_ = 0;
  Tensor b_;
  mutable Tensor c_, chat_;
  mutable Eigen::FullPivLU<Tensor> lu_;
  mutable bool have_c_ = false, have_chat_ = false, have_lu_ = false;
};

// ---- the kernel symbols by (scalar, dimension) ---------------------------------------------

template <class T, int D>
struct Api;

#define AMPM_TEST_API(T, D, S)                                                        \
  template <>                                                                         \
  struct Api<T, D> {                                                                  \
    static constexpr const char* name = #D "d_" #S;                                   \
    static constexpr auto b_z = ampm_b_z_##D##d_##S;                                  \
    static constexpr auto z_b = ampm_z_b_##D##d_##S;                                  \
    static constexpr auto energy_hat = ampm_energy_hat_##D##d_##S;                    \
    static constexpr auto ahat = ampm_ahat_##D##d_##S;                                \
    static constexpr auto chat_z = ampm_chat_z_##D##d_##S;                            \
    static constexpr auto ahat_batch = ampm_ahat_batch_##D##d_##S;                    \
    static constexpr auto chat_z_batch = ampm_chat_z_batch_##D##d_##S;                \
  };
AMPM_TEST_API(float, 2, f32)
AMPM_TEST_API(float, 3, f32)
AMPM_TEST_API(double, 2, f64)
AMPM_TEST_API(double, 3, f64)
#undef AMPM_TEST_API

// ---- the particle-call symbols by (scalar, dimension) ---------------------------------------
// One table for the tests and benchmarks of the particle calls (test_host_loop.cpp keeps its
// own: it is a host written against ampm.h alone).

template <class T, int D>
struct PartApi;

#define AMPM_PART_API(T, D, S)                                                          \
  template <>                                                                           \
  struct PartApi<T, D> {                                                                \
    static constexpr const char* name = #D "D " #S;                                     \
    static constexpr auto stencil = ampm_stencil_##D##d_##S;                            \
    static constexpr auto node_range = ampm_node_range_##D##d_##S;                      \
    static constexpr auto p2g = ampm_p2g_##D##d_##S;                                    \
    static constexpr auto g2p = ampm_g2p_update_##D##d_##S;                             \
    static constexpr auto g2p_mac = ampm_g2p_update_mac_##D##d_##S;                     \
    static constexpr auto prepare = ampm_force_prepare_##D##d_##S;                      \
    static constexpr auto apply = ampm_force_apply_##D##d_##S;                          \
    static constexpr auto pressure = ampm_pressure_##D##d_##S;                          \
    /* The same symbols by name, for a build loaded with dlopen (bench_transfers --ab). */ \
    static constexpr const char* p2g_sym = "ampm_p2g_" #D "d_" #S;                      \
    static constexpr const char* g2p_sym = "ampm_g2p_update_" #D "d_" #S;               \
    static constexpr const char* prepare_sym = "ampm_force_prepare_" #D "d_" #S;        \
    static constexpr const char* apply_sym = "ampm_force_apply_" #D "d_" #S;            \
    static constexpr std::size_t slot_len =                                             \
        D == 2 ? AMPM_FORCE_SLOT_LEN_2D : AMPM_FORCE_SLOT_LEN_3D;                       \
    using Material = AmpmMaterial_##S;                                                  \
    using Particles = AmpmParticles_##S;                                                \
    using Channel = AmpmChannel_##S;                                                    \
    using ConstChannel = AmpmConstChannel_##S;                                          \
    using P2gView = AmpmP2gView_##S;                                                    \
    using G2pView = AmpmG2pView_##S;                                                    \
    using ForceView = AmpmForceView_##S;                                                \
  };
AMPM_PART_API(float, 2, f32)
AMPM_PART_API(float, 3, f32)
AMPM_PART_API(double, 2, f64)
AMPM_PART_API(double, 3, f64)
#undef AMPM_PART_API

}  // namespace ampm_test

#endif  // AMPM_C_TESTS_COMMON_HPP
