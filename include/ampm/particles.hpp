// ampm C++ wrapper, part 3 of 4: builders of the particle-API structs (AmpmMaterial,
// AmpmParticles, AmpmNodeBox, AmpmChannel, AmpmP2gView, AmpmG2pView, AmpmForceView). Include
// <ampm.hpp>, not this.
//
// Each builder owns one C struct, zero-filled (padding included) at construction, and fills it
// by name; `c()` gives the struct, byte for byte what a host would fill by hand. Strides count
// scalars, not bytes (AmpmChannel). The boxes and views of 2D set lo[2] = 0, dims[2] = 1; C
// ignores entries [2] in 2D.
#ifndef AMPM_HPP_PARTICLES_HPP
#define AMPM_HPP_PARTICLES_HPP

#include "ampm/core.hpp"

namespace ampm {

// ---- material -----------------------------------------------------------------------------

/// Builder of AmpmPhaseParams_<f32|f64>: one phase's parameters (SI units).
template <class T>
class PhaseParams {
 public:
  using c_type = typename detail::scalar_api<T>::phase_params;
  /// All parameters 0.
  PhaseParams() noexcept { std::memset(&c_, 0, sizeof c_); }
  /// Shear modulus mu ≥ 0 (Pa); 0 for the liquid.
  PhaseParams& mu(T v) noexcept { c_.mu = v; return *this; }
  /// 1/lambda ≥ 0 (1/Pa); 0 is incompressible (needs AMPM_MODEL_PRESSURE_SOLVE).
  PhaseParams& inv_lambda(T v) noexcept { c_.inv_lambda = v; return *this; }
  /// Sets inv_lambda = 1/lambda (lambda in Pa; +inf gives 0, incompressible).
  PhaseParams& lambda(T v) noexcept { c_.inv_lambda = T(1) / v; return *this; }
  /// Specific heat capacity c > 0 (J/(kg·K)), read with AMPM_MODEL_THERMAL.
  PhaseParams& heat_capacity(T v) noexcept { c_.heat_capacity = v; return *this; }
  /// Thermal conductivity kappa ≥ 0 (W/(m·K)), read with AMPM_MODEL_THERMAL.
  PhaseParams& conductivity(T v) noexcept { c_.conductivity = v; return *this; }
  /// The C struct.
  const c_type& c() const noexcept { return c_; }

 private:
  c_type c_;
};

/// Builder of AmpmMaterial_<f32|f64>: model bits and parameters (fields of parts that are
/// off are not read by C). Setters without a phase prefix set the solid phase.
template <class T>
class Material {
 public:
  using c_type = typename detail::scalar_api<T>::material;
  /// model = 0 and every parameter 0.
  Material() noexcept { std::memset(&c_, 0, sizeof c_); }
  /// Wraps a filled C struct.
  Material(const c_type& c) noexcept : c_(c) {}
  /// model = `bits` (OR of AMPM_MODEL_*), replacing the previous bits.
  Material& model(unsigned bits) noexcept { c_.model = bits; return *this; }
  /// model |= `bits`.
  Material& enable(unsigned bits) noexcept { c_.model |= bits; return *this; }
  /// model &= ~`bits`.
  Material& disable(unsigned bits) noexcept { c_.model &= ~bits; return *this; }
  /// The solid phase's parameters.
  Material& solid(const PhaseParams<T>& p) noexcept { c_.solid = p.c(); return *this; }
  /// The liquid phase's parameters (mu must be 0).
  Material& liquid(const PhaseParams<T>& p) noexcept { c_.liquid = p.c(); return *this; }
  /// Solid mu ≥ 0 (Pa).
  Material& mu(T v) noexcept { c_.solid.mu = v; return *this; }
  /// Solid 1/lambda ≥ 0 (1/Pa).
  Material& inv_lambda(T v) noexcept { c_.solid.inv_lambda = v; return *this; }
  /// Solid inv_lambda = 1/lambda (lambda in Pa).
  Material& lambda(T v) noexcept { c_.solid.inv_lambda = T(1) / v; return *this; }
  /// Solid heat capacity c > 0 (J/(kg·K)).
  Material& heat_capacity(T v) noexcept { c_.solid.heat_capacity = v; return *this; }
  /// Solid conductivity kappa ≥ 0 (W/(m·K)).
  Material& conductivity(T v) noexcept { c_.solid.conductivity = v; return *this; }
  /// Liquid 1/lambda ≥ 0 (1/Pa).
  Material& liquid_inv_lambda(T v) noexcept { c_.liquid.inv_lambda = v; return *this; }
  /// Liquid inv_lambda = 1/lambda (lambda in Pa).
  Material& liquid_lambda(T v) noexcept { c_.liquid.inv_lambda = T(1) / v; return *this; }
  /// Liquid heat capacity c > 0 (J/(kg·K)).
  Material& liquid_heat_capacity(T v) noexcept { c_.liquid.heat_capacity = v; return *this; }
  /// Liquid conductivity kappa ≥ 0 (W/(m·K)).
  Material& liquid_conductivity(T v) noexcept { c_.liquid.conductivity = v; return *this; }
  /// Snow critical compression theta_c in [0, 1) (AMPM_MODEL_PLASTIC).
  Material& critical_compression(T v) noexcept { c_.critical_compression = v; return *this; }
  /// Snow critical stretch theta_s ≥ 0 (AMPM_MODEL_PLASTIC).
  Material& critical_stretch(T v) noexcept { c_.critical_stretch = v; return *this; }
  /// Hardening xi ≥ 0 (AMPM_MODEL_PLASTIC).
  Material& hardening(T v) noexcept { c_.hardening = v; return *this; }
  /// FLIP fraction alpha in [0, 1] of the temperature transfer (AMPM_MODEL_THERMAL).
  Material& flip(T v) noexcept { c_.flip = v; return *this; }
  /// Melting point T_m (K) (AMPM_MODEL_PHASE_CHANGE).
  Material& melting_point(T v) noexcept { c_.melting_point = v; return *this; }
  /// Specific latent heat L ≥ 0 (J/kg) (AMPM_MODEL_PHASE_CHANGE).
  Material& latent_heat(T v) noexcept { c_.latent_heat = v; return *this; }
  /// The C struct.
  const c_type& c() const noexcept { return c_; }

 private:
  c_type c_;
};

// ---- particles ----------------------------------------------------------------------------

/// Builder of AmpmParticles_<f32|f64> for n particles of dimension D (structure of arrays:
/// vectors n·d, matrices n·d² column-major, scalars n; SI units, see AmpmParticles in ampm.h).
/// Pointer setters are unchecked; span setters record a size error when a non-NULL span holds
/// fewer than the scalars n particles need, and every call on these particles then returns
/// AMPM_ERR_INVALID_ARGUMENT (first_failed = 0) without calling C.
template <class T, int D>
class Particles {
 public:
  using c_type = typename detail::api<T, D>::particles;
  static constexpr std::size_t vec = static_cast<std::size_t>(D);
  static constexpr std::size_t mat = static_cast<std::size_t>(D * D);
  /// n particles, every array NULL.
  explicit Particles(std::size_t n = 0) noexcept : n_(n) { std::memset(&c_, 0, sizeof c_); }
  /// Wraps a filled C struct of n particles.
  Particles(std::size_t n, const c_type& c) noexcept : c_(c), n_(n) {}
  /// Number of particles.
  std::size_t size() const noexcept { return n_; }
  /// False when a span setter got too few scalars (or slice() left the range).
  bool sizes_ok() const noexcept { return ok_; }

  /// Positions x_p (m, relative to the grid origin), n·d.
  Particles& x(T* p) noexcept { c_.x = p; return *this; }
  /// Positions, checked to hold n·d.
  Particles& x(span<T> s) noexcept { c_.x = note(s, vec); return *this; }
  /// Velocities (m/s), n·d.
  Particles& v(T* p) noexcept { c_.v = p; return *this; }
  /// Velocities, checked to hold n·d.
  Particles& v(span<T> s) noexcept { c_.v = note(s, vec); return *this; }
  /// APIC affine matrices C_p (1/s), n·d².
  Particles& affine(T* p) noexcept { c_.affine = p; return *this; }
  /// APIC matrices, checked to hold n·d².
  Particles& affine(span<T> s) noexcept { c_.affine = note(s, mat); return *this; }
  /// Elastic deformation gradients F_E, n·d².
  Particles& f_e(T* p) noexcept { c_.f_e = p; return *this; }
  /// F_E, checked to hold n·d².
  Particles& f_e(span<T> s) noexcept { c_.f_e = note(s, mat); return *this; }
  /// Plastic deformation gradients F_P, n·d² (identity for a purely elastic solid).
  Particles& f_p(T* p) noexcept { c_.f_p = p; return *this; }
  /// F_P, checked to hold n·d².
  Particles& f_p(span<T> s) noexcept { c_.f_p = note(s, mat); return *this; }
  /// Masses m_p (kg), n.
  Particles& mass(const T* p) noexcept { c_.mass = p; return *this; }
  /// Masses, checked to hold n.
  Particles& mass(span<const T> s) noexcept { c_.mass = note(s, 1); return *this; }
  /// Reference volumes V0_p (m³), n.
  Particles& volume0(const T* p) noexcept { c_.volume0 = p; return *this; }
  /// Reference volumes, checked to hold n.
  Particles& volume0(span<const T> s) noexcept { c_.volume0 = note(s, 1); return *this; }
  /// Temperatures (K), n (AMPM_MODEL_THERMAL; else may be NULL).
  Particles& temperature(T* p) noexcept { c_.temperature = p; return *this; }
  /// Temperatures, checked to hold n.
  Particles& temperature(span<T> s) noexcept { c_.temperature = note(s, 1); return *this; }
  /// Latent buffers U (J/kg), n (AMPM_MODEL_PHASE_CHANGE; else may be NULL).
  Particles& latent(T* p) noexcept { c_.latent = p; return *this; }
  /// Latent buffers, checked to hold n.
  Particles& latent(span<T> s) noexcept { c_.latent = note(s, 1); return *this; }
  /// Phases AMPM_PHASE_*, n (required with PHASE_CHANGE; NULL means all solid).
  Particles& phase(unsigned char* p) noexcept { c_.phase = p; return *this; }
  /// Phases, checked to hold n.
  Particles& phase(span<unsigned char> s) noexcept { c_.phase = note(s, 1); return *this; }

  /// Particles [first, first + count) of these (every non-NULL array offset); a range past
  /// size() gives particles whose calls return AMPM_ERR_INVALID_ARGUMENT.
  Particles slice(std::size_t first, std::size_t count) const noexcept {
    Particles s(count, c_);
    s.ok_ = ok_ && first <= n_ && count <= n_ - first;
    if (!s.ok_) return s;
    s.c_.x = off(c_.x, first * vec);
    s.c_.v = off(c_.v, first * vec);
    s.c_.affine = off(c_.affine, first * mat);
    s.c_.f_e = off(c_.f_e, first * mat);
    s.c_.f_p = off(c_.f_p, first * mat);
    s.c_.mass = off(c_.mass, first);
    s.c_.volume0 = off(c_.volume0, first);
    s.c_.temperature = off(c_.temperature, first);
    s.c_.latent = off(c_.latent, first);
    s.c_.phase = off(c_.phase, first);
    return s;
  }
  /// The C struct.
  const c_type& c() const noexcept { return c_; }

 private:
  template <class U>
  U* note(span<U> s, std::size_t per) noexcept {
    if (s.data() != nullptr && s.size() < n_ * per) ok_ = false;
    return s.data();
  }
  template <class U>
  static U* off(U* p, std::size_t k) noexcept { return p == nullptr ? p : p + k; }
  c_type c_;
  std::size_t n_;
  bool ok_ = true;
};

// ---- node boxes and channels --------------------------------------------------------------

/// AmpmNodeBox of nodes lo[a] ≤ i_a < lo[a] + dims[a] (entries [2] = 0 and 1 in 2D).
template <int D>
AmpmNodeBox node_box(const std::array<std::int32_t, D>& lo,
                     const std::array<std::int32_t, D>& dims) noexcept {
  static_assert(D == 2 || D == 3, "ampm: D is 2 or 3");
  AmpmNodeBox b;
  for (int a = 0; a < 3; ++a) {
    b.lo[a] = a < D ? lo[static_cast<std::size_t>(a)] : 0;
    b.dims[a] = a < D ? dims[static_cast<std::size_t>(a)] : 1;
  }
  return b;
}

/// Number of nodes of a box in dimension D (the product of dims[0..D)); 0 if any is ≤ 0.
template <int D>
std::size_t node_count(const AmpmNodeBox& b) noexcept {
  std::size_t c = 1;
  for (int a = 0; a < D; ++a) c *= b.dims[a] > 0 ? static_cast<std::size_t>(b.dims[a]) : 0;
  return c;
}

/// Channel builders of scalar T over a box of dimension D: `out` is AmpmChannel_<f32|f64>
/// (written by P2G / force_apply), `in` is AmpmConstChannel_<f32|f64> (read by G2P / force_apply).
template <class T, int D>
struct Channel {
  using out = typename detail::api<T, D>::channel;
  using in = typename detail::api<T, D>::const_channel;

  /// Dense x-fastest array over `b`, `e` scalars per node at `data` (e = 1: separate arrays,
  /// stride {1, nx, nx·ny}; e = s: a node struct of s scalars, stride {s, s·nx, s·nx·ny}).
  static out dense(T* data, const AmpmNodeBox& b, std::ptrdiff_t e = 1) noexcept {
    out c;
    c.data = data;
    set_strides(c.stride, b, e);
    return c;
  }
  /// Read-only dense x-fastest array over `b` (see dense).
  static in dense(const T* data, const AmpmNodeBox& b, std::ptrdiff_t e = 1) noexcept {
    in c;
    c.data = data;
    set_strides(c.stride, b, e);
    return c;
  }
  /// Field `field` (a pointer into nodes[0]) of an x-fastest array of node structs `Node`
  /// over `b`; strides sizeof(Node)/sizeof(T) times the separate-array strides.
  template <class Node, class P>
  static auto interleaved(Node* nodes, P* field, const AmpmNodeBox& b) noexcept {
    static_assert(sizeof(Node) % sizeof(T) == 0, "ampm: node struct size not a multiple of T");
    static_assert(std::is_same<std::remove_const_t<P>, T>::value, "ampm: field is not a T");
    (void)nodes;
    return dense(field, b, static_cast<std::ptrdiff_t>(sizeof(Node) / sizeof(T)));
  }
  /// An absent channel (data = NULL, strides 0).
  static out none() noexcept {
    out c;
    std::memset(&c, 0, sizeof c);
    return c;
  }
  /// An absent read-only channel.
  static in none_in() noexcept {
    in c;
    std::memset(&c, 0, sizeof c);
    return c;
  }

 private:
  static void set_strides(std::ptrdiff_t* s, const AmpmNodeBox& b, std::ptrdiff_t e) noexcept {
    s[0] = e;
    s[1] = e * b.dims[0];
    s[2] = e * b.dims[0] * static_cast<std::ptrdiff_t>(b.dims[1]);
  }
};

}  // namespace ampm

#endif  // AMPM_HPP_PARTICLES_HPP
