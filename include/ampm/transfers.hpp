// ampm C++ wrapper, part 4 of 4: the grid views (P2gView, G2pView, ForceView) and the particle
// transfers (p2g, g2p_update, g2p_update_mac, node_range, force_prepare, force_apply, stencil,
// pressure). Include <ampm.hpp>, not this.
//
// Each transfer forwards to ampm_<op>_<D>d_<f32|f64> with n = particles.size(); the batch
// contract, the per-particle statuses and the threads rules are those of ampm.h. Before calling
// C a transfer returns AMPM_ERR_INVALID_ARGUMENT (first_failed = 0) when the particles carry a
// size error (Particles::sizes_ok) or a non-NULL output span holds fewer scalars than n
// particles need (slots n·AMPM_FORCE_SLOT_LEN_<D>D, stencil base n·d, weight n·K^d, gradient
// n·K^d·d, pressure and coefficient n).
#ifndef AMPM_HPP_TRANSFERS_HPP
#define AMPM_HPP_TRANSFERS_HPP

#include "ampm/particles.hpp"

namespace ampm {

namespace detail {
/// A span holds `need` elements when it is NULL (C decides) or has at least `need`.
template <class T>
constexpr bool holds(span<T> s, std::size_t need) noexcept {
  return s.data() == nullptr || s.size() >= need;
}
/// The channel of member `m` of node structs `nodes` (absent when either is null).
template <class T, int D, class Node, class Owner, class M>
auto member_channel(Node* nodes, M Owner::*m, const AmpmNodeBox& b) noexcept {
  static_assert(std::is_same<std::remove_const_t<Node>, Owner>::value, "ampm: member of Node");
  using C = Channel<T, D>;
  if constexpr (std::is_const<Node>::value) {
    if (nodes == nullptr || m == nullptr) return C::none_in();
    return C::interleaved(nodes, &(nodes->*m), b);
  } else {
    if (nodes == nullptr || m == nullptr) return C::none();
    return C::interleaved(nodes, &(nodes->*m), b);
  }
}
/// Moves a channel from box `from` to its sub-box `to` (same strides; NULL stays NULL).
template <class Ch>
Ch shift(Ch c, const AmpmNodeBox& from, const AmpmNodeBox& to) noexcept {
  if (c.data == nullptr) return c;
  std::ptrdiff_t off = 0;
  for (int a = 0; a < 3; ++a) off += static_cast<std::ptrdiff_t>(to.lo[a] - from.lo[a]) * c.stride[a];
  c.data += off;
  return c;
}
}  // namespace detail

// ---- views --------------------------------------------------------------------------------

/// Builder of AmpmP2gView_<f32|f64> (where P2G scatter-adds; see AmpmP2gView in ampm.h for the
/// formulas and units). Channels not set are absent (data = NULL).
template <class T, int D>
class P2gView {
 public:
  using c_type = typename detail::api<T, D>::p2g_view;
  using C = Channel<T, D>;
  /// A view of an empty box with every channel absent.
  P2gView() noexcept : P2gView(AmpmNodeBox{{0, 0, 0}, {0, 0, 0}}) {}
  /// A view of box `b` with every channel absent.
  explicit P2gView(const AmpmNodeBox& b) noexcept {
    std::memset(&c_, 0, sizeof c_);
    c_.nodes = b;
  }
  /// Separate dense x-fastest arrays over `b` (stride {1, nx, nx·ny}): node mass (kg),
  /// momentum per axis (kg·m/s), and force per axis (N; null entries absent).
  static P2gView separate(const AmpmNodeBox& b, T* mass, const std::array<T*, D>& momentum,
                          const std::array<T*, D>& force = {}) noexcept {
    P2gView v(b);
    v.mass(mass);
    for (int a = 0; a < D; ++a) {
      v.momentum(a, momentum[static_cast<std::size_t>(a)]);
      v.force(a, force[static_cast<std::size_t>(a)]);
    }
    return v;
  }
  /// An x-fastest array of node structs over `b`: `mass`, `momentum` (and `force`) name T
  /// members of Node (a null member pointer: absent); strides in scalars from sizeof(Node).
  template <class Node>
  static P2gView interleaved(const AmpmNodeBox& b, Node* nodes, T Node::*mass,
                             const std::array<T Node::*, D>& momentum,
                             const std::array<T Node::*, D>& force = {}) noexcept {
    P2gView v(b);
    v.c_.mass = detail::member_channel<T, D>(nodes, mass, b);
    for (std::size_t a = 0; a < D; ++a) {
      v.c_.momentum[a] = detail::member_channel<T, D>(nodes, momentum[a], b);
      v.c_.force[a] = detail::member_channel<T, D>(nodes, force[a], b);
    }
    return v;
  }
  /// Node mass channel (kg), any strides.
  P2gView& mass(const typename C::out& ch) noexcept { c_.mass = ch; return *this; }
  /// Node mass as a dense x-fastest array over the box (NULL: absent).
  P2gView& mass(T* data) noexcept { return mass(dense(data)); }
  /// Momentum channel of axis a < D (kg·m/s).
  P2gView& momentum(int a, const typename C::out& ch) noexcept { c_.momentum[a] = ch; return *this; }
  /// Momentum of axis a as a dense array (NULL: absent).
  P2gView& momentum(int a, T* data) noexcept { return momentum(a, dense(data)); }
  /// Force channel of axis a < D (N).
  P2gView& force(int a, const typename C::out& ch) noexcept { c_.force[a] = ch; return *this; }
  /// Force of axis a as a dense array (NULL: absent).
  P2gView& force(int a, T* data) noexcept { return force(a, dense(data)); }
  /// Heat capacity channel (J/K), AMPM_MODEL_THERMAL.
  P2gView& heat_capacity(const typename C::out& ch) noexcept { c_.heat_capacity = ch; return *this; }
  /// Heat capacity as a dense array (NULL: absent).
  P2gView& heat_capacity(T* data) noexcept { return heat_capacity(dense(data)); }
  /// Thermal energy channel (J), AMPM_MODEL_THERMAL.
  P2gView& thermal_energy(const typename C::out& ch) noexcept { c_.thermal_energy = ch; return *this; }
  /// Thermal energy as a dense array (NULL: absent).
  P2gView& thermal_energy(T* data) noexcept { return thermal_energy(dense(data)); }
  /// Conductivity mass channel (kg·W/(m·K)), AMPM_MODEL_THERMAL.
  P2gView& conductivity(const typename C::out& ch) noexcept { c_.conductivity = ch; return *this; }
  /// Conductivity mass as a dense array (NULL: absent).
  P2gView& conductivity(T* data) noexcept { return conductivity(dense(data)); }
  /// The node box.
  const AmpmNodeBox& box() const noexcept { return c_.nodes; }
  /// The same arrays restricted to `sub`, a box inside this view's box (not checked): each
  /// channel's data moves to node sub.lo, strides unchanged. For disjoint per-thread blocks.
  P2gView block(const AmpmNodeBox& sub) const noexcept {
    P2gView v(*this);
    v.c_.nodes = sub;
    v.c_.mass = detail::shift(c_.mass, c_.nodes, sub);
    for (int a = 0; a < 3; ++a) {
      v.c_.momentum[a] = detail::shift(c_.momentum[a], c_.nodes, sub);
      v.c_.force[a] = detail::shift(c_.force[a], c_.nodes, sub);
    }
    v.c_.heat_capacity = detail::shift(c_.heat_capacity, c_.nodes, sub);
    v.c_.thermal_energy = detail::shift(c_.thermal_energy, c_.nodes, sub);
    v.c_.conductivity = detail::shift(c_.conductivity, c_.nodes, sub);
    return v;
  }
  /// The C struct.
  const c_type& c() const noexcept { return c_; }

 private:
  typename C::out dense(T* data) const noexcept {
    return data == nullptr ? C::none() : C::dense(data, c_.nodes);
  }
  c_type c_;
};

/// Builder of AmpmG2pView_<f32|f64> (what G2P reads: new node velocities, m/s, and with
/// AMPM_MODEL_THERMAL new and old node temperatures, K).
template <class T, int D>
class G2pView {
 public:
  using c_type = typename detail::api<T, D>::g2p_view;
  using C = Channel<T, D>;
  /// A view of an empty box with every channel absent.
  G2pView() noexcept : G2pView(AmpmNodeBox{{0, 0, 0}, {0, 0, 0}}) {}
  /// A view of box `b` with every channel absent.
  explicit G2pView(const AmpmNodeBox& b) noexcept {
    std::memset(&c_, 0, sizeof c_);
    c_.nodes = b;
  }
  /// Separate dense x-fastest arrays over `b`: velocity per axis; temperatures (may be NULL).
  static G2pView separate(const AmpmNodeBox& b, const std::array<const T*, D>& velocity,
                          const T* temperature = nullptr,
                          const T* temperature_old = nullptr) noexcept {
    G2pView v(b);
    for (int a = 0; a < D; ++a) v.velocity(a, velocity[static_cast<std::size_t>(a)]);
    v.temperature(temperature);
    v.temperature_old(temperature_old);
    return v;
  }
  /// An x-fastest array of node structs over `b`; members as P2gView::interleaved.
  template <class Node>
  static G2pView interleaved(const AmpmNodeBox& b, const Node* nodes,
                             const std::array<T Node::*, D>& velocity,
                             T Node::*temperature = nullptr,
                             T Node::*temperature_old = nullptr) noexcept {
    G2pView v(b);
    for (std::size_t a = 0; a < D; ++a)
      v.c_.velocity[a] = detail::member_channel<T, D>(nodes, velocity[a], b);
    v.c_.temperature = detail::member_channel<T, D>(nodes, temperature, b);
    v.c_.temperature_old = detail::member_channel<T, D>(nodes, temperature_old, b);
    return v;
  }
  /// Velocity channel of axis a < D (m/s).
  G2pView& velocity(int a, const typename C::in& ch) noexcept { c_.velocity[a] = ch; return *this; }
  /// Velocity of axis a as a dense array (NULL: absent).
  G2pView& velocity(int a, const T* data) noexcept { return velocity(a, dense(data)); }
  /// New temperature channel T^(n+1) (K).
  G2pView& temperature(const typename C::in& ch) noexcept { c_.temperature = ch; return *this; }
  /// New temperature as a dense array (NULL: absent).
  G2pView& temperature(const T* data) noexcept { return temperature(dense(data)); }
  /// Old temperature channel T^n (K).
  G2pView& temperature_old(const typename C::in& ch) noexcept { c_.temperature_old = ch; return *this; }
  /// Old temperature as a dense array (NULL: absent).
  G2pView& temperature_old(const T* data) noexcept { return temperature_old(dense(data)); }
  /// The node box.
  const AmpmNodeBox& box() const noexcept { return c_.nodes; }
  /// The same arrays restricted to `sub`, a box inside this view's box (not checked): each
  /// channel's data moves to node sub.lo, strides unchanged. For disjoint per-thread blocks.
  G2pView block(const AmpmNodeBox& sub) const noexcept {
    G2pView v(*this);
    v.c_.nodes = sub;
    for (int a = 0; a < 3; ++a) v.c_.velocity[a] = detail::shift(c_.velocity[a], c_.nodes, sub);
    v.c_.temperature = detail::shift(c_.temperature, c_.nodes, sub);
    v.c_.temperature_old = detail::shift(c_.temperature_old, c_.nodes, sub);
    return v;
  }
  /// The C struct.
  const c_type& c() const noexcept { return c_; }

 private:
  typename C::in dense(const T* data) const noexcept {
    return data == nullptr ? C::none_in() : C::dense(data, c_.nodes);
  }
  c_type c_;
};

/// Builder of AmpmForceView_<f32|f64>: node displacements du (m, read) and force differentials
/// df (N, scatter-added); all 2·d channels are required and df must not alias du.
template <class T, int D>
class ForceView {
 public:
  using c_type = typename detail::api<T, D>::force_view;
  using C = Channel<T, D>;
  /// A view of an empty box with every channel absent.
  ForceView() noexcept : ForceView(AmpmNodeBox{{0, 0, 0}, {0, 0, 0}}) {}
  /// A view of box `b` with every channel absent.
  explicit ForceView(const AmpmNodeBox& b) noexcept {
    std::memset(&c_, 0, sizeof c_);
    c_.nodes = b;
  }
  /// Separate dense x-fastest arrays over `b`: du and df per axis.
  static ForceView separate(const AmpmNodeBox& b, const std::array<const T*, D>& du,
                            const std::array<T*, D>& df) noexcept {
    ForceView v(b);
    for (std::size_t a = 0; a < D; ++a) {
      v.c_.du[a] = du[a] == nullptr ? C::none_in() : C::dense(du[a], b);
      v.c_.df[a] = df[a] == nullptr ? C::none() : C::dense(df[a], b);
    }
    return v;
  }
  /// x-fastest arrays of node structs over `b`: du members of `du_nodes`, df members of
  /// `df_nodes` (the two arrays may be the same).
  template <class NodeA, class NodeB>
  static ForceView interleaved(const AmpmNodeBox& b, const NodeA* du_nodes,
                               const std::array<T NodeA::*, D>& du, NodeB* df_nodes,
                               const std::array<T NodeB::*, D>& df) noexcept {
    ForceView v(b);
    for (std::size_t a = 0; a < D; ++a) {
      v.c_.du[a] = detail::member_channel<T, D>(du_nodes, du[a], b);
      v.c_.df[a] = detail::member_channel<T, D>(df_nodes, df[a], b);
    }
    return v;
  }
  /// du channel of axis a < D (m).
  ForceView& du(int a, const typename C::in& ch) noexcept { c_.du[a] = ch; return *this; }
  /// df channel of axis a < D (N).
  ForceView& df(int a, const typename C::out& ch) noexcept { c_.df[a] = ch; return *this; }
  /// The node box.
  const AmpmNodeBox& box() const noexcept { return c_.nodes; }
  /// The same arrays restricted to `sub`, a box inside this view's box (not checked): each
  /// channel's data moves to node sub.lo, strides unchanged. For disjoint per-thread blocks.
  ForceView block(const AmpmNodeBox& sub) const noexcept {
    ForceView v(*this);
    v.c_.nodes = sub;
    for (int a = 0; a < 3; ++a) {
      v.c_.du[a] = detail::shift(c_.du[a], c_.nodes, sub);
      v.c_.df[a] = detail::shift(c_.df[a], c_.nodes, sub);
    }
    return v;
  }
  /// The C struct.
  const c_type& c() const noexcept { return c_; }

 private:
  c_type c_;
};

// ---- transfers ----------------------------------------------------------------------------

/// AMPM_FORCE_SLOT_LEN_<D>D: scalars per particle of the prepared force differential.
template <int D>
constexpr std::size_t force_slot_len() noexcept {
  return D == 2 ? AMPM_FORCE_SLOT_LEN_2D : AMPM_FORCE_SLOT_LEN_3D;
}

/// ampm_p2g: scatter-adds (+=) mass, APIC momentum (+ impulse_dt·force), force and heat of the
/// particles into `view`; `kernel` AMPM_KERNEL_*, `grid` AMPM_GRID_COLLOCATED or a face axis,
/// h > 0 (m), impulse_dt ≥ 0 (s).
template <class T, int D>
[[nodiscard]] BatchStatus p2g(const Material<T>& m, unsigned kernel, int grid, detail::id_t<T> h,
                              detail::id_t<T> impulse_dt, const Particles<T, D>& p,
                              const P2gView<T, D>& view) noexcept {
  if (!p.sizes_ok()) return {AMPM_ERR_INVALID_ARGUMENT, 0};
  std::size_t ff = 0;
  const AmpmStatus s = detail::api<T, D>::p2g(&m.c(), kernel, grid, h, impulse_dt, p.size(),
                                              &p.c(), &view.c(), &ff);
  return {s, ff};
}

/// ampm_g2p_update: G2P and the particle update from the collocated grid; h > 0 (m), dt > 0 (s).
template <class T, int D>
[[nodiscard]] BatchStatus g2p_update(const Material<T>& m, unsigned kernel, detail::id_t<T> h,
                                     detail::id_t<T> dt, const Particles<T, D>& p,
                                     const G2pView<T, D>& view) noexcept {
  if (!p.sizes_ok()) return {AMPM_ERR_INVALID_ARGUMENT, 0};
  std::size_t ff = 0;
  const AmpmStatus s =
      detail::api<T, D>::g2p_update(&m.c(), kernel, h, dt, p.size(), &p.c(), &view.c(), &ff);
  return {s, ff};
}

/// ampm_g2p_update_mac: G2P from a MAC grid; faces[a] covers face grid a (its velocity[a] is
/// read); `thermal` the collocated temperature view (required with THERMAL, else may be NULL).
template <class T, int D>
[[nodiscard]] BatchStatus g2p_update_mac(const Material<T>& m, unsigned kernel,
                                         detail::id_t<T> h, detail::id_t<T> dt,
                                         const Particles<T, D>& p,
                                         const detail::id_t<std::array<G2pView<T, D>, D>>& faces,
                                         const G2pView<T, D>* thermal) noexcept {
  if (!p.sizes_ok()) return {AMPM_ERR_INVALID_ARGUMENT, 0};
  typename G2pView<T, D>::c_type f[D];
  for (std::size_t a = 0; a < D; ++a) f[a] = faces[a].c();
  std::size_t ff = 0;
  const AmpmStatus s = detail::api<T, D>::g2p_update_mac(
      &m.c(), kernel, h, dt, p.size(), &p.c(), f, thermal ? &thermal->c() : nullptr, &ff);
  return {s, ff};
}

/// ampm_node_range: on AMPM_OK sets `box` to the nodes the particles' stencils reach
/// (lo, dims = hi − lo + 1; [2] = 0, 1 in 2D); n ≥ 1 particles, positions read.
template <class T, int D>
[[nodiscard]] BatchStatus node_range(unsigned kernel, int grid, detail::id_t<T> h,
                                     const Particles<T, D>& p, AmpmNodeBox& box) noexcept {
  if (!p.sizes_ok()) return {AMPM_ERR_INVALID_ARGUMENT, 0};
  std::int32_t lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0};
  std::size_t ff = 0;
  const AmpmStatus s =
      detail::api<T, D>::node_range(kernel, grid, h, p.size(), p.c().x, lo, hi, &ff);
  if (s == AMPM_OK) {
    for (int a = 0; a < 3; ++a) {
      box.lo[a] = a < D ? lo[a] : 0;
      box.dims[a] = a < D ? hi[a] - lo[a] + 1 : 1;
    }
  }
  return {s, ff};
}

/// ampm_force_prepare: the force differential of each particle into `slots`
/// (n·force_slot_len<D>() scalars, opaque), once per Newton step.
template <class T, int D>
[[nodiscard]] BatchStatus force_prepare(const Material<T>& m, const Particles<T, D>& p,
                                        span<detail::id_t<T>> slots) noexcept {
  if (!p.sizes_ok() || !detail::holds(slots, p.size() * force_slot_len<D>()))
    return {AMPM_ERR_INVALID_ARGUMENT, 0};
  std::size_t ff = 0;
  const AmpmStatus s =
      detail::api<T, D>::force_prepare(&m.c(), p.size(), &p.c(), slots.data(), &ff);
  return {s, ff};
}

/// ampm_force_apply: df += K du of the prepared particles (positions x of the Newton step);
/// h > 0 (m), collocated grid; the host zeroes df first.
template <class T, int D>
[[nodiscard]] BatchStatus force_apply(unsigned kernel, detail::id_t<T> h, const Particles<T, D>& p,
                                      span<const detail::id_t<T>> slots, const ForceView<T, D>& view) noexcept {
  if (!p.sizes_ok() || !detail::holds(slots, p.size() * force_slot_len<D>()))
    return {AMPM_ERR_INVALID_ARGUMENT, 0};
  std::size_t ff = 0;
  const AmpmStatus s = detail::api<T, D>::force_apply(kernel, h, p.size(), p.c().x, slots.data(),
                                                      &view.c(), &ff);
  return {s, ff};
}

/// ampm_stencil: base (n·d grid indices), weight (n·K^d) and, if not null, grad_weight
/// (n·K^d·d, 1/m) of the particles' B-spline stencils; node order as ampm_stencil_* documents.
template <class T, int D>
[[nodiscard]] BatchStatus stencil(unsigned kernel, int grid, detail::id_t<T> h,
                                  const Particles<T, D>& p, span<int> base, span<detail::id_t<T>> weight,
                                  span<detail::id_t<T>> grad_weight) noexcept {
  const std::size_t n = p.size();
  const std::size_t k1 = kernel == AMPM_KERNEL_QUADRATIC ? 3 : kernel == AMPM_KERNEL_CUBIC ? 4 : 0;
  const std::size_t kd = D == 2 ? k1 * k1 : k1 * k1 * k1;
  if (!p.sizes_ok() || !detail::holds(base, n * D) || !detail::holds(weight, n * kd) ||
      !detail::holds(grad_weight, n * kd * D))
    return {AMPM_ERR_INVALID_ARGUMENT, 0};
  std::size_t ff = 0;
  const AmpmStatus s = detail::api<T, D>::stencil(kernel, grid, h, n, p.c().x, base.data(),
                                                  weight.data(), grad_weight.data(), &ff);
  return {s, ff};
}

/// ampm_pressure: particle pressures (Pa) and pressure-solve coefficients (1/(Pa·s)), n each,
/// either may be null; dt > 0 (s).
template <class T, int D>
[[nodiscard]] BatchStatus pressure(const Material<T>& m, detail::id_t<T> dt,
                                   const Particles<T, D>& p, span<detail::id_t<T>> pressure,
                                   span<detail::id_t<T>> coefficient) noexcept {
  if (!p.sizes_ok() || !detail::holds(pressure, p.size()) ||
      !detail::holds(coefficient, p.size()))
    return {AMPM_ERR_INVALID_ARGUMENT, 0};
  std::size_t ff = 0;
  const AmpmStatus s = detail::api<T, D>::pressure(&m.c(), dt, p.size(), &p.c(), pressure.data(),
                                                   coefficient.data(), &ff);
  return {s, ff};
}

}  // namespace ampm

#endif  // AMPM_HPP_TRANSFERS_HPP
