// ampm C++ wrapper, part 2 of 4: the constitutive kernels, `ampm::Kernels<T, D>`. Include
// <ampm.hpp>, not this.
//
// Matrices are d×d column-major (F[i + d*j] = F_ij), batches are structures of arrays (matrix k
// at f + k*d*d, scalar k at mu[k]); units SI (ampm.h, Layouts and Units). Pointer overloads pass
// straight to C. Span overloads take n from their first array (mu, or z for hessian_apply_batch)
// and check every other non-NULL span against it (exact sizes: n*d² per matrix array, n*len per
// prepared array); a mismatch returns AMPM_ERR_INVALID_ARGUMENT with first_failed = 0 and calls
// nothing. A NULL span is passed as NULL, so C reports AMPM_ERR_NULL_POINTER where required.
#ifndef AMPM_HPP_KERNELS_HPP
#define AMPM_HPP_KERNELS_HPP

#include "ampm/core.hpp"

namespace ampm {

/// The constitutive kernels of scalar T (float, double) and dimension D (2, 3) as static
/// functions; each forwards to the ampm_<op>_<D>d_<f32|f64> C function of the same name.
template <class T, int D>
struct Kernels {
  static_assert(D == 2 || D == 3, "ampm: D is 2 or 3");
  static_assert(std::is_same<T, float>::value || std::is_same<T, double>::value,
                "ampm: T is float or double");
  using A = detail::api<T, D>;
  /// Scalars of one d×d matrix.
  static constexpr std::size_t mat = static_cast<std::size_t>(D * D);
  /// Scalars of the explicit Hessian matrix of chat_matrix (d²×d²).
  static constexpr std::size_t hess = mat * mat;

  // -- single particle (outputs written only on AMPM_OK) --

  /// ampm_b_z: 𝓑(F):Z = Jᵃ(Z + a(H:Z)F); `f`, `z`, `out` d×d (out may be f or z).
  [[nodiscard]] static Status b_z(const T* f, const T* z, T* out) noexcept {
    return A::b_z(f, z, out);
  }
  /// ampm_z_b: Z:𝓑(F) = Jᵃ(Z + a(F:Z)H); `f`, `z`, `out` d×d (out may be f or z).
  [[nodiscard]] static Status z_b(const T* f, const T* z, T* out) noexcept {
    return A::z_b(f, z, out);
  }
  /// ampm_energy_hat: Ψ̂(F) (J/m³) into *out; mu ≥ 0 (Pa), `f` d×d.
  [[nodiscard]] static Status energy_hat(T mu, const T* f, T* out) noexcept {
    return A::energy_hat(mu, f, out);
  }
  /// ampm_ahat: Â = ∂Ψ̂/∂F (Pa), d×d; mu ≥ 0 (Pa), `f` d×d (out may be f).
  [[nodiscard]] static Status ahat(T mu, const T* f, T* out) noexcept {
    return A::ahat(mu, f, out);
  }
  /// ampm_chat_z: Ĉ:Z (Pa per unit strain), d×d; out may be f or z.
  [[nodiscard]] static Status chat_z(T mu, const T* f, const T* z, T* out) noexcept {
    return A::chat_z(mu, f, z, out);
  }
  /// ampm_chat_z_psd: Ĉ⁺:Z, the PSD-projected Hessian action, d×d; out may be f or z.
  [[nodiscard]] static Status chat_z_psd(T mu, const T* f, const T* z, T* out) noexcept {
    return A::chat_z_psd(mu, f, z, out);
  }
  /// ampm_chat_matrix: the explicit d²×d² Hessian Ĉ, column-major, `out` d⁴ scalars.
  [[nodiscard]] static Status chat_matrix(T mu, const T* f, T* out) noexcept {
    return A::chat_matrix(mu, f, out);
  }
  /// ampm_chat_psd_matrix: the explicit d²×d² PSD projection Ĉ⁺, `out` d⁴ scalars.
  [[nodiscard]] static Status chat_psd_matrix(T mu, const T* f, T* out) noexcept {
    return A::chat_psd_matrix(mu, f, out);
  }

  // -- single particle with a run-time polar/SVD method (AmpmOptions) --

  /// ampm_energy_hat_ex: Ψ̂(F) (J/m³) with the method of `o`.
  [[nodiscard]] static Status energy_hat(const Options& o, T mu, const T* f, T* out) noexcept {
    return A::energy_hat_ex(&o.c(), mu, f, out);
  }
  /// ampm_ahat_ex: Â (Pa) with the method of `o`.
  [[nodiscard]] static Status ahat(const Options& o, T mu, const T* f, T* out) noexcept {
    return A::ahat_ex(&o.c(), mu, f, out);
  }
  /// ampm_chat_z_ex: Ĉ:Z with the method of `o`.
  [[nodiscard]] static Status chat_z(const Options& o, T mu, const T* f, const T* z,
                                     T* out) noexcept {
    return A::chat_z_ex(&o.c(), mu, f, z, out);
  }
  /// ampm_svd (default method, NULL options): F = U diag(σ) Vᵀ; `u`, `v` d×d, `sigma` d.
  [[nodiscard]] static Status svd(const T* f, T* u, T* sigma, T* v) noexcept {
    return A::svd(nullptr, f, u, sigma, v);
  }
  /// ampm_svd with the method of `o`.
  [[nodiscard]] static Status svd(const Options& o, const T* f, T* u, T* sigma, T* v) noexcept {
    return A::svd(&o.c(), f, u, sigma, v);
  }
  /// ampm_polar (default method, NULL options): F = R S; `r`, `s` d×d.
  [[nodiscard]] static Status polar(const T* f, T* r, T* s) noexcept {
    return A::polar(nullptr, f, r, s);
  }
  /// ampm_polar with the method of `o`.
  [[nodiscard]] static Status polar(const Options& o, const T* f, T* r, T* s) noexcept {
    return A::polar(&o.c(), f, r, s);
  }

  // -- batches, pointer + n (no size checks; batch contract of ampm.h) --

  /// ampm_ahat_batch: out[i] = Â(mu[i], F[i]); mu n, f and out n·d² (out may be f).
  [[nodiscard]] static BatchStatus ahat_batch(std::size_t n, const T* mu, const T* f,
                                              T* out) noexcept {
    std::size_t ff = 0;
    const AmpmStatus s = A::ahat_batch(n, mu, f, out, &ff);
    return {s, ff};
  }
  /// ampm_ahat_batch_ex: as ahat_batch with the method of `o`.
  [[nodiscard]] static BatchStatus ahat_batch(const Options& o, std::size_t n, const T* mu,
                                              const T* f, T* out) noexcept {
    std::size_t ff = 0;
    const AmpmStatus s = A::ahat_batch_ex(&o.c(), n, mu, f, out, &ff);
    return {s, ff};
  }
  /// ampm_chat_z_batch: out[i] = Ĉ(mu[i], F[i]):Z[i]; f, z, out n·d².
  [[nodiscard]] static BatchStatus chat_z_batch(std::size_t n, const T* mu, const T* f,
                                                const T* z, T* out) noexcept {
    std::size_t ff = 0;
    const AmpmStatus s = A::chat_z_batch(n, mu, f, z, out, &ff);
    return {s, ff};
  }
  /// ampm_chat_z_batch_ex: as chat_z_batch with the method of `o`.
  [[nodiscard]] static BatchStatus chat_z_batch(const Options& o, std::size_t n, const T* mu,
                                                const T* f, const T* z, T* out) noexcept {
    std::size_t ff = 0;
    const AmpmStatus s = A::chat_z_batch_ex(&o.c(), n, mu, f, z, out, &ff);
    return {s, ff};
  }
  /// ampm_chat_z_psd_batch: out[i] = Ĉ⁺(mu[i], F[i]):Z[i]; f, z, out n·d².
  [[nodiscard]] static BatchStatus chat_z_psd_batch(std::size_t n, const T* mu, const T* f,
                                                    const T* z, T* out) noexcept {
    std::size_t ff = 0;
    const AmpmStatus s = A::chat_z_psd_batch(n, mu, f, z, out, &ff);
    return {s, ff};
  }
  /// ampm_ahat_chat_z_batch: Â and Ĉ:Z with one decomposition; ahat or chat_z may be NULL
  /// (z may be NULL when chat_z is).
  [[nodiscard]] static BatchStatus ahat_chat_z_batch(std::size_t n, const T* mu, const T* f,
                                                     const T* z, T* ahat, T* chat_z) noexcept {
    std::size_t ff = 0;
    const AmpmStatus s = A::ahat_chat_z_batch(n, mu, f, z, ahat, chat_z, &ff);
    return {s, ff};
  }
  /// ampm_hessian_len: scalars of one prepared-Hessian slot (18 in 2D, 38 in 3D).
  static std::size_t hessian_len() noexcept { return A::hessian_len(); }
  /// ampm_hessian_prepare_batch: prepared n·hessian_len() scalars; ahat n·d² or NULL.
  [[nodiscard]] static BatchStatus hessian_prepare_batch(std::size_t n, const T* mu, const T* f,
                                                         T* ahat, T* prepared) noexcept {
    std::size_t ff = 0;
    const AmpmStatus s = A::hessian_prepare_batch(n, mu, f, ahat, prepared, &ff);
    return {s, ff};
  }
  /// ampm_hessian_apply_batch: out[i] = Ĉ:Z[i] (Ĉ⁺:Z[i] when psd); out may be z.
  [[nodiscard]] static BatchStatus hessian_apply_batch(std::size_t n, const T* prepared,
                                                       const T* z, T* out, bool psd) noexcept {
    std::size_t ff = 0;
    const AmpmStatus s = A::hessian_apply_batch(n, prepared, z, out, psd ? 1 : 0, &ff);
    return {s, ff};
  }

  // -- batches over spans (n from the first array, sizes checked) --

  /// ampm_ahat_batch; n = mu.size(), f and out n·d².
  [[nodiscard]] static BatchStatus ahat_batch(span<const T> mu, span<const T> f,
                                              span<T> out) noexcept {
    const std::size_t n = mu.size();
    if (!detail::fits(f, n * mat) || !detail::fits(out, n * mat)) return bad();
    return ahat_batch(n, mu.data(), f.data(), out.data());
  }
  /// ampm_ahat_batch_ex; n = mu.size(), f and out n·d².
  [[nodiscard]] static BatchStatus ahat_batch(const Options& o, span<const T> mu,
                                              span<const T> f, span<T> out) noexcept {
    const std::size_t n = mu.size();
    if (!detail::fits(f, n * mat) || !detail::fits(out, n * mat)) return bad();
    return ahat_batch(o, n, mu.data(), f.data(), out.data());
  }
  /// ampm_chat_z_batch; n = mu.size(), f, z, out n·d².
  [[nodiscard]] static BatchStatus chat_z_batch(span<const T> mu, span<const T> f,
                                                span<const T> z, span<T> out) noexcept {
    const std::size_t n = mu.size();
    if (!mats_fit(n, f, z, out)) return bad();
    return chat_z_batch(n, mu.data(), f.data(), z.data(), out.data());
  }
  /// ampm_chat_z_batch_ex; n = mu.size(), f, z, out n·d².
  [[nodiscard]] static BatchStatus chat_z_batch(const Options& o, span<const T> mu,
                                                span<const T> f, span<const T> z,
                                                span<T> out) noexcept {
    const std::size_t n = mu.size();
    if (!mats_fit(n, f, z, out)) return bad();
    return chat_z_batch(o, n, mu.data(), f.data(), z.data(), out.data());
  }
  /// ampm_chat_z_psd_batch; n = mu.size(), f, z, out n·d².
  [[nodiscard]] static BatchStatus chat_z_psd_batch(span<const T> mu, span<const T> f,
                                                    span<const T> z, span<T> out) noexcept {
    const std::size_t n = mu.size();
    if (!mats_fit(n, f, z, out)) return bad();
    return chat_z_psd_batch(n, mu.data(), f.data(), z.data(), out.data());
  }
  /// ampm_ahat_chat_z_batch; n = mu.size(); f, z, ahat, chat_z n·d² (z, ahat or chat_z may be
  /// null spans as the C rules allow).
  [[nodiscard]] static BatchStatus ahat_chat_z_batch(span<const T> mu, span<const T> f,
                                                     span<const T> z, span<T> ahat,
                                                     span<T> chat_z) noexcept {
    const std::size_t n = mu.size();
    if (!mats_fit(n, f, z, ahat) || !detail::fits(chat_z, n * mat)) return bad();
    return ahat_chat_z_batch(n, mu.data(), f.data(), z.data(), ahat.data(), chat_z.data());
  }
  /// ampm_hessian_prepare_batch; n = mu.size(), f and ahat n·d² (ahat may be null),
  /// prepared n·hessian_len().
  [[nodiscard]] static BatchStatus hessian_prepare_batch(span<const T> mu, span<const T> f,
                                                         span<T> ahat,
                                                         span<T> prepared) noexcept {
    const std::size_t n = mu.size();
    if (!detail::fits(f, n * mat) || !detail::fits(ahat, n * mat) ||
        !detail::fits(prepared, n * hessian_len()))
      return bad();
    return hessian_prepare_batch(n, mu.data(), f.data(), ahat.data(), prepared.data());
  }
  /// ampm_hessian_apply_batch; n = z.size()/d² (a multiple of d²), prepared n·hessian_len(),
  /// out n·d².
  [[nodiscard]] static BatchStatus hessian_apply_batch(span<const T> prepared, span<const T> z,
                                                       span<T> out, bool psd) noexcept {
    const std::size_t n = z.size() / mat;
    if (z.size() % mat != 0 || !detail::fits(prepared, n * hessian_len()) ||
        !detail::fits(out, n * mat))
      return bad();
    return hessian_apply_batch(n, prepared.data(), z.data(), out.data(), psd);
  }

 private:
  static constexpr BatchStatus bad() noexcept { return {AMPM_ERR_INVALID_ARGUMENT, 0}; }
  static constexpr bool mats_fit(std::size_t n, span<const T> a, span<const T> b,
                                 span<T> c) noexcept {
    return detail::fits(a, n * mat) && detail::fits(b, n * mat) && detail::fits(c, n * mat);
  }
};

/// Kernels of float in 2D.
using Kernels2f = Kernels<float, 2>;
/// Kernels of float in 3D.
using Kernels3f = Kernels<float, 3>;
/// Kernels of double in 2D.
using Kernels2d = Kernels<double, 2>;
/// Kernels of double in 3D.
using Kernels3d = Kernels<double, 3>;

}  // namespace ampm

#endif  // AMPM_HPP_KERNELS_HPP
