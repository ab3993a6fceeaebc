// ampm C++ wrapper, Eigen overloads (compiled when Eigen was included before <ampm.hpp> or
// AMPM_HPP_EIGEN is defined). Include <ampm.hpp>, not this.
//
// Eigen's default storage is column-major, as ampm's matrices, so the overloads pass
// Matrix::data() straight to the C functions: each equals its pointer version bit for bit.
// Only Eigen::Matrix<T, D, D> of T = float/double, D = 2/3 are accepted (not expressions:
// evaluate them first). The value-returning forms return {status, result}; the result is
// zero unless the status is AMPM_OK (outputs are written only on success).
#ifndef AMPM_HPP_EIGEN_HPP
#define AMPM_HPP_EIGEN_HPP

#include "ampm/kernels.hpp"

#include <Eigen/Core>

#include <utility>

namespace ampm {

/// Column-major d×d matrix of T (Eigen's default), the layout of ampm's matrices.
template <class T, int D>
using Matrix = Eigen::Matrix<T, D, D>;
/// The explicit d²×d² Hessian of chat_matrix.
template <class T, int D>
using HessianMatrix = Eigen::Matrix<T, D * D, D * D>;
/// A d-vector (singular values).
template <class T, int D>
using Vector = Eigen::Matrix<T, D, 1>;

/// ampm_b_z into `out`: 𝓑(F):Z.
template <class T, int D>
[[nodiscard]] Status b_z(const Matrix<T, D>& f, const Matrix<T, D>& z, Matrix<T, D>& out) noexcept {
  return Kernels<T, D>::b_z(f.data(), z.data(), out.data());
}
/// ampm_z_b into `out`: Z:𝓑(F).
template <class T, int D>
[[nodiscard]] Status z_b(const Matrix<T, D>& f, const Matrix<T, D>& z, Matrix<T, D>& out) noexcept {
  return Kernels<T, D>::z_b(f.data(), z.data(), out.data());
}
/// ampm_energy_hat into `out`: Ψ̂(F) (J/m³), mu ≥ 0 (Pa).
template <class T, int D>
[[nodiscard]] Status energy_hat(detail::id_t<T> mu, const Matrix<T, D>& f, T& out) noexcept {
  return Kernels<T, D>::energy_hat(mu, f.data(), &out);
}
/// ampm_ahat into `out`: Â (Pa).
template <class T, int D>
[[nodiscard]] Status ahat(detail::id_t<T> mu, const Matrix<T, D>& f, Matrix<T, D>& out) noexcept {
  return Kernels<T, D>::ahat(mu, f.data(), out.data());
}
/// ampm_chat_z into `out`: Ĉ:Z.
template <class T, int D>
[[nodiscard]] Status chat_z(detail::id_t<T> mu, const Matrix<T, D>& f, const Matrix<T, D>& z,
                            Matrix<T, D>& out) noexcept {
  return Kernels<T, D>::chat_z(mu, f.data(), z.data(), out.data());
}
/// ampm_chat_z_psd into `out`: Ĉ⁺:Z.
template <class T, int D>
[[nodiscard]] Status chat_z_psd(detail::id_t<T> mu, const Matrix<T, D>& f, const Matrix<T, D>& z,
                                Matrix<T, D>& out) noexcept {
  return Kernels<T, D>::chat_z_psd(mu, f.data(), z.data(), out.data());
}
/// ampm_chat_matrix into `out`: the explicit d²×d² Hessian Ĉ (vec(Ĉ:Z) = Ĉ·vec(Z)).
template <class T, int D>
[[nodiscard]] Status chat_matrix(detail::id_t<T> mu, const Matrix<T, D>& f,
                                 HessianMatrix<T, D>& out) noexcept {
  return Kernels<T, D>::chat_matrix(mu, f.data(), out.data());
}
/// ampm_chat_psd_matrix into `out`: the explicit d²×d² projection Ĉ⁺.
template <class T, int D>
[[nodiscard]] Status chat_psd_matrix(detail::id_t<T> mu, const Matrix<T, D>& f,
                                     HessianMatrix<T, D>& out) noexcept {
  return Kernels<T, D>::chat_psd_matrix(mu, f.data(), out.data());
}
/// ampm_svd (options `o`, default: all defaults): F = U diag(σ) Vᵀ.
template <class T, int D>
[[nodiscard]] Status svd(const Matrix<T, D>& f, Matrix<T, D>& u, Vector<T, D>& sigma,
                         Matrix<T, D>& v, const Options& o = Options()) noexcept {
  return Kernels<T, D>::svd(o, f.data(), u.data(), sigma.data(), v.data());
}
/// ampm_polar (options `o`, default: all defaults): F = R S.
template <class T, int D>
[[nodiscard]] Status polar(const Matrix<T, D>& f, Matrix<T, D>& r, Matrix<T, D>& s,
                           const Options& o = Options()) noexcept {
  return Kernels<T, D>::polar(o, f.data(), r.data(), s.data());
}

/// ampm_ahat: {status, Â (Pa)}.
template <class T, int D>
[[nodiscard]] std::pair<Status, Matrix<T, D>> ahat(detail::id_t<T> mu,
                                                   const Matrix<T, D>& f) noexcept {
  Matrix<T, D> out = Matrix<T, D>::Zero();
  const Status s = Kernels<T, D>::ahat(mu, f.data(), out.data());
  return {s, out};
}
/// ampm_energy_hat: {status, Ψ̂ (J/m³)}.
template <class T, int D>
[[nodiscard]] std::pair<Status, T> energy_hat(detail::id_t<T> mu, const Matrix<T, D>& f) noexcept {
  T out = 0;
  const Status s = Kernels<T, D>::energy_hat(mu, f.data(), &out);
  return {s, out};
}
/// ampm_chat_z: {status, Ĉ:Z}.
template <class T, int D>
[[nodiscard]] std::pair<Status, Matrix<T, D>> chat_z(detail::id_t<T> mu, const Matrix<T, D>& f,
                                                     const Matrix<T, D>& z) noexcept {
  Matrix<T, D> out = Matrix<T, D>::Zero();
  const Status s = Kernels<T, D>::chat_z(mu, f.data(), z.data(), out.data());
  return {s, out};
}
/// ampm_chat_z_psd: {status, Ĉ⁺:Z}.
template <class T, int D>
[[nodiscard]] std::pair<Status, Matrix<T, D>> chat_z_psd(detail::id_t<T> mu, const Matrix<T, D>& f,
                                                         const Matrix<T, D>& z) noexcept {
  Matrix<T, D> out = Matrix<T, D>::Zero();
  const Status s = Kernels<T, D>::chat_z_psd(mu, f.data(), z.data(), out.data());
  return {s, out};
}

}  // namespace ampm

#endif  // AMPM_HPP_EIGEN_HPP
