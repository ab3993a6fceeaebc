// ampm C++ wrapper, part 1 of 4: Status, BatchStatus, span, the (scalar, dimension) → C symbol
// map `detail::api<T, D>`, Options, and the instruction-set calls. Include <ampm.hpp>, not this.
//
// Every rule of the C ABI (layouts, units, NULL pointers, the batch contract, threads) is the one
// documented in ampm.h; this header adds no behaviour of its own except the size checks of the
// span overloads, which return AMPM_ERR_INVALID_ARGUMENT (first_failed = 0) before calling C.
#ifndef AMPM_HPP_CORE_HPP
#define AMPM_HPP_CORE_HPP

#include <cstddef>
#include <cstdint>
#include <cstring>

#include "ampm.h"

#include <array>
#include <type_traits>
#include <vector>

#if defined(AMPM_HPP_EXCEPTIONS)
#if !defined(__cpp_exceptions) && !defined(__EXCEPTIONS) && !defined(_CPPUNWIND)
#error "AMPM_HPP_EXCEPTIONS is defined but C++ exceptions are disabled (-fno-exceptions)"
#endif
#include <stdexcept>
#include <string>
#endif

namespace ampm {

// ---- status ------------------------------------------------------------------------------

/// The symbolic name of a status code ("AMPM_OK", "AMPM_ERR_NULL_POINTER", ...).
inline const char* status_name(AmpmStatus s) noexcept {
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
  return "AMPM_ERR_UNKNOWN";
}

/// A one-line English description of a status code (the AmpmStatus documentation of ampm.h).
inline const char* status_message(AmpmStatus s) noexcept {
  switch (s) {
    case AMPM_OK: return "success";
    case AMPM_ERR_NULL_POINTER: return "a required pointer argument is NULL";
    case AMPM_ERR_NON_FINITE: return "an input is NaN or infinite";
    case AMPM_ERR_NON_POSITIVE_J: return "det F <= 0, or F is singular to working precision";
    case AMPM_ERR_OVERFLOW: return "the inputs are valid but the result is not representable";
    case AMPM_ERR_INVALID_ARGUMENT: return "a parameter is outside its documented domain";
    case AMPM_ERR_NOT_CONVERGED: return "an iterative method hit its iteration cap";
    case AMPM_ERR_INTERNAL: return "internal error caught at the ABI boundary (a bug)";
    case AMPM_ERR_NOT_PREPARED: return "a prepared slot that no successful prepare wrote";
    case AMPM_ERR_OUTSIDE_GRID: return "a particle's stencil leaves the node box of the view";
  }
  return "unknown status code";
}

/// The result of a single (one-particle) call: an AmpmStatus with names and tests.
class [[nodiscard]] Status {
 public:
  /// Wraps a C status (default AMPM_OK).
  constexpr Status(AmpmStatus code = AMPM_OK) noexcept : code_(code) {}
  /// The C status code.
  constexpr AmpmStatus code() const noexcept { return code_; }
  /// True for AMPM_OK.
  constexpr bool ok() const noexcept { return code_ == AMPM_OK; }
  /// True for AMPM_OK (so `if (auto s = call(...))` tests success).
  constexpr explicit operator bool() const noexcept { return ok(); }
  /// The symbolic name, e.g. "AMPM_ERR_NON_POSITIVE_J".
  const char* name() const noexcept { return status_name(code_); }
  /// A one-line description of the code.
  const char* message() const noexcept { return status_message(code_); }
  /// Equal codes.
  friend constexpr bool operator==(Status a, Status b) noexcept { return a.code_ == b.code_; }
  /// Different codes.
  friend constexpr bool operator!=(Status a, Status b) noexcept { return a.code_ != b.code_; }

 private:
  AmpmStatus code_;
};

/// The result of a batch call: the status of the first failed record (or of the whole call)
/// and `first_failed`, its index (n on success, 0 after a whole-call error), as ampm.h's batch
/// contract.
class [[nodiscard]] BatchStatus : public Status {
 public:
  /// Index of the first failed record (n if none; 0 after a whole-call error).
  std::size_t first_failed = 0;
  /// Wraps a C status and its first_failed index.
  constexpr BatchStatus(AmpmStatus code = AMPM_OK, std::size_t first = 0) noexcept
      : Status(code), first_failed(first) {}
  /// The status alone.
  constexpr Status status() const noexcept { return Status(code()); }
};

#if defined(AMPM_HPP_EXCEPTIONS)
/// Thrown by ampm::check (only with AMPM_HPP_EXCEPTIONS): a failed status and its index.
class Error : public std::runtime_error {
 public:
  /// An error of `status`; `first_failed` is the failed record of a batch call (0 otherwise).
  explicit Error(AmpmStatus status, std::size_t first_failed = 0)
      : std::runtime_error(std::string(status_name(status)) + ": " + status_message(status) +
                           " (first_failed " + std::to_string(first_failed) + ")"),
        status_(status),
        first_failed_(first_failed) {}
  /// The failed status.
  Status status() const noexcept { return status_; }
  /// The index of the first failed record (batch calls; 0 for single calls).
  std::size_t first_failed() const noexcept { return first_failed_; }

 private:
  AmpmStatus status_;
  std::size_t first_failed_;
};

/// Throws ampm::Error unless `s` is AMPM_OK (only with AMPM_HPP_EXCEPTIONS).
inline void check(Status s) {
  if (!s.ok()) throw Error(s.code(), 0);
}
/// Throws ampm::Error (with first_failed) unless `s` is AMPM_OK (only with AMPM_HPP_EXCEPTIONS).
inline void check(const BatchStatus& s) {
  if (!s.ok()) throw Error(s.code(), s.first_failed);
}
#endif

// ---- span ---------------------------------------------------------------------------------

/// A non-owning view of `size()` contiguous `T` (a minimal std::span for C++17). A
/// default-constructed span is {nullptr, 0}, i.e. the C NULL pointer.
template <class T>
class span {
 public:
  /// The empty span {nullptr, 0}.
  constexpr span() noexcept = default;
  /// `size` elements at `data`.
  constexpr span(T* data, std::size_t size) noexcept : data_(data), size_(size) {}
  /// The null span (passes NULL to C).
  constexpr span(std::nullptr_t) noexcept {}
  /// A whole C array.
  template <std::size_t N>
  constexpr span(T (&a)[N]) noexcept : data_(a), size_(N) {}
  /// A whole std::vector (const T from a const vector).
  template <class U, class A,
            class = std::enable_if_t<std::is_convertible<U (*)[], T (*)[]>::value>>
  span(std::vector<U, A>& v) noexcept : data_(v.data()), size_(v.size()) {}
  /// A whole const std::vector (for span<const T>).
  template <class U, class A,
            class = std::enable_if_t<std::is_convertible<const U (*)[], T (*)[]>::value>>
  span(const std::vector<U, A>& v) noexcept : data_(v.data()), size_(v.size()) {}
  /// A whole std::array.
  template <class U, std::size_t N,
            class = std::enable_if_t<std::is_convertible<U (*)[], T (*)[]>::value>>
  constexpr span(std::array<U, N>& a) noexcept : data_(a.data()), size_(N) {}
  /// A whole const std::array (for span<const T>).
  template <class U, std::size_t N,
            class = std::enable_if_t<std::is_convertible<const U (*)[], T (*)[]>::value>>
  constexpr span(const std::array<U, N>& a) noexcept : data_(a.data()), size_(N) {}
  /// span<T> → span<const T>.
  template <class U, class = std::enable_if_t<std::is_convertible<U (*)[], T (*)[]>::value>>
  constexpr span(span<U> s) noexcept : data_(s.data()), size_(s.size()) {}
  /// First element (NULL for the null span).
  constexpr T* data() const noexcept { return data_; }
  /// Number of elements.
  constexpr std::size_t size() const noexcept { return size_; }
  /// True when size() is 0.
  constexpr bool empty() const noexcept { return size_ == 0; }
  /// Element i (unchecked).
  constexpr T& operator[](std::size_t i) const noexcept { return data_[i]; }
  /// Elements [offset, offset + count) (unchecked).
  constexpr span subspan(std::size_t offset, std::size_t count) const noexcept {
    return span(data_ + offset, count);
  }
  /// Begin iterator.
  constexpr T* begin() const noexcept { return data_; }
  /// End iterator.
  constexpr T* end() const noexcept { return data_ + size_; }

 private:
  T* data_ = nullptr;
  std::size_t size_ = 0;
};

namespace detail {

/// Blocks template argument deduction (scalars follow the deduced T of the arrays).
template <class T>
struct identity {
  using type = T;
};
template <class T>
using id_t = typename identity<T>::type;

/// A span agrees with `need` elements when it is NULL (C then reports AMPM_ERR_NULL_POINTER
/// where the pointer is required) or holds exactly `need` elements.
template <class T>
constexpr bool fits(span<T> s, std::size_t need) noexcept {
  return s.data() == nullptr || s.size() == need;
}

/// The C symbols of one (scalar, dimension); specialised for (float|double, 2|3) only.
template <class T, int D>
struct api;

#define AMPM_HPP_API(T, D, S)                                                   \
  template <>                                                                   \
  struct api<T, D> {                                                            \
    using material = AmpmMaterial_##S;                                          \
    using phase_params = AmpmPhaseParams_##S;                                   \
    using particles = AmpmParticles_##S;                                        \
    using channel = AmpmChannel_##S;                                            \
    using const_channel = AmpmConstChannel_##S;                                 \
    using p2g_view = AmpmP2gView_##S;                                           \
    using g2p_view = AmpmG2pView_##S;                                           \
    using force_view = AmpmForceView_##S;                                       \
    static constexpr std::size_t force_slot_len =                             \
        D == 2 ? AMPM_FORCE_SLOT_LEN_2D : AMPM_FORCE_SLOT_LEN_3D;               \
    static constexpr auto b_z = ampm_b_z_##D##d_##S;                            \
    static constexpr auto z_b = ampm_z_b_##D##d_##S;                            \
    static constexpr auto energy_hat = ampm_energy_hat_##D##d_##S;              \
    static constexpr auto ahat = ampm_ahat_##D##d_##S;                          \
    static constexpr auto chat_z = ampm_chat_z_##D##d_##S;                      \
    static constexpr auto chat_z_psd = ampm_chat_z_psd_##D##d_##S;              \
    static constexpr auto chat_matrix = ampm_chat_matrix_##D##d_##S;            \
    static constexpr auto chat_psd_matrix = ampm_chat_psd_matrix_##D##d_##S;    \
    static constexpr auto ahat_batch = ampm_ahat_batch_##D##d_##S;              \
    static constexpr auto chat_z_batch = ampm_chat_z_batch_##D##d_##S;          \
    static constexpr auto chat_z_psd_batch = ampm_chat_z_psd_batch_##D##d_##S;  \
    static constexpr auto ahat_chat_z_batch = ampm_ahat_chat_z_batch_##D##d_##S; \
    static constexpr auto hessian_len = ampm_hessian_len_##D##d_##S;            \
    static constexpr auto hessian_prepare_batch =                               \
        ampm_hessian_prepare_batch_##D##d_##S;                                  \
    static constexpr auto hessian_apply_batch = ampm_hessian_apply_batch_##D##d_##S; \
    static constexpr auto energy_hat_ex = ampm_energy_hat_ex_##D##d_##S;        \
    static constexpr auto ahat_ex = ampm_ahat_ex_##D##d_##S;                    \
    static constexpr auto chat_z_ex = ampm_chat_z_ex_##D##d_##S;                \
    static constexpr auto ahat_batch_ex = ampm_ahat_batch_ex_##D##d_##S;        \
    static constexpr auto chat_z_batch_ex = ampm_chat_z_batch_ex_##D##d_##S;    \
    static constexpr auto svd = ampm_svd_##D##d_##S;                            \
    static constexpr auto polar = ampm_polar_##D##d_##S;                        \
    static constexpr auto p2g = ampm_p2g_##D##d_##S;                            \
    static constexpr auto g2p_update = ampm_g2p_update_##D##d_##S;              \
    static constexpr auto g2p_update_mac = ampm_g2p_update_mac_##D##d_##S;      \
    static constexpr auto node_range = ampm_node_range_##D##d_##S;              \
    static constexpr auto force_prepare = ampm_force_prepare_##D##d_##S;        \
    static constexpr auto force_apply = ampm_force_apply_##D##d_##S;            \
    static constexpr auto stencil = ampm_stencil_##D##d_##S;                    \
    static constexpr auto pressure = ampm_pressure_##D##d_##S;                  \
  };
AMPM_HPP_API(float, 2, f32)
AMPM_HPP_API(float, 3, f32)
AMPM_HPP_API(double, 2, f64)
AMPM_HPP_API(double, 3, f64)
#undef AMPM_HPP_API

/// The C material/phase types of one scalar (dimension-independent).
template <class T>
struct scalar_api {
  using material = typename api<T, 3>::material;
  using phase_params = typename api<T, 3>::phase_params;
};

}  // namespace detail

// ---- options ------------------------------------------------------------------------------

/// Builder of AmpmOptions (the polar/SVD method of the `_ex` calls); all fields 0 = defaults.
class Options {
 public:
  /// All defaults (every field 0).
  Options() noexcept { std::memset(&c_, 0, sizeof c_); }
  /// Wraps a filled C struct.
  Options(const AmpmOptions& c) noexcept : c_(c) {}
  /// AMPM_METHOD_* (0 = the default of the dimension).
  Options& method(std::uint32_t m) noexcept { c_.method = m; return *this; }
  /// Jacobi sweeps of AMPM_METHOD_MCADAMS (0 = default 4, else 2..=8).
  Options& sweeps(std::uint32_t s) noexcept { c_.sweeps = s; return *this; }
  /// Sweep count / iteration cap (0 = default, else 1..=1000; see AmpmOptions).
  Options& max_iterations(std::uint32_t k) noexcept { c_.max_iterations = k; return *this; }
  /// The C struct.
  const AmpmOptions& c() const noexcept { return c_; }

 private:
  AmpmOptions c_;
};

// ---- instruction set ----------------------------------------------------------------------

/// ampm_set_isa: chooses the instruction set of every batch call (AMPM_ISA_*); process-wide,
/// set it once at start-up before other threads call the library (ampm.h, Threads).
[[nodiscard]] inline Status set_isa(std::uint32_t isa) noexcept { return ampm_set_isa(isa); }
/// ampm_isa: the instruction set the batch calls use (AMPM_ISA_*).
inline std::uint32_t isa() noexcept { return ampm_isa(); }

}  // namespace ampm

#endif  // AMPM_HPP_CORE_HPP
