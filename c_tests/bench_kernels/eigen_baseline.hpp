// The Eigen baseline: Â and Ĉ:Z per particle as an engine author would write them with one
// Eigen::JacobiSVD, and over a batch in the layout of the C batch calls.
#pragma once

#include "bench_kernels/api.hpp"

namespace {

// GCC 12 reports -Wmaybe-uninitialized inside Eigen 3.4's JacobiSVD once it is inlined at -O3
// (its singular values are written by compute() before any read); silenced for the baseline only.
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif

/// Â and Ĉ:Z of the augmented fixed-corotated energy for one particle, as an engine author
/// would write them from README "The math in short" (Stomakhin et al. 2014, augmented MPM tech
/// report, with its J^{−1/a} read as Jᵃ): fixed-size Eigen types, no heap, one
/// Eigen::JacobiSVD per particle. Returns false when J ≤ 0 or J is not finite.
template <class T, int D>
bool eigen_particle(T mu, const Eigen::Matrix<T, D, D>& f, const Eigen::Matrix<T, D, D>& z,
                    Eigen::Matrix<T, D, D>& ahat, Eigen::Matrix<T, D, D>& chat_z) {
  using M = Eigen::Matrix<T, D, D>;
  using V = Eigen::Matrix<T, D, 1>;
  const T a = T(-1) / T(D);  // a = −1/d

  // J = det F, Jᵃ (sqrt/cbrt rather than pow with a rounded exponent), H = F⁻ᵀ.
  const T j = f.determinant();
  if (!(j > 0) || !std::isfinite(j)) return false;
  const T ja = D == 2 ? T(1) / std::sqrt(j) : T(1) / std::cbrt(j);
  const M h = f.inverse().transpose();

  // Rotation-variant SVD (README "The math in short"): U, V ∈ SO(d), only the last singular
  // value may be negative. JacobiSVD gives σ ≥ 0 sorted and U, V orthogonal; negate the last
  // column of a reflection and move the sign onto the last σ. F̂ = JᵃF has the same U, V and
  // σ̂ = Jᵃσ.
  const Eigen::JacobiSVD<M> svd(f, Eigen::ComputeFullU | Eigen::ComputeFullV);
  M u = svd.matrixU(), v = svd.matrixV();
  V s_hat = ja * svd.singularValues();
  if (u.determinant() < 0) {
    u.col(D - 1) = -u.col(D - 1);
    s_hat(D - 1) = -s_hat(D - 1);
  }
  if (v.determinant() < 0) {
    v.col(D - 1) = -v.col(D - 1);
    s_hat(D - 1) = -s_hat(D - 1);
  }
  const M r = u * v.transpose();  // R = U Vᵀ

  // Fixed corotated at F̂: A = 2μ(F̂ − R).
  const M fa = ja * f;
  const M pa = T(2) * mu * (fa - r);

  // Â = A:𝓑 with Z:𝓑 = Jᵃ(Z + a(F:Z)H).
  const T a_f = pa.cwiseProduct(f).sum();  // A:F
  ahat = ja * (pa + a * a_f * h);

  // 𝓑:Z = Jᵃ(Z + a(H:Z)F).
  const T h_z = h.cwiseProduct(z).sum();  // H:Z
  const M bz = ja * (z + a * h_z * f);

  // C:δF = 2μ(δF − δR) at F̂, δR = U W Vᵀ, W_ij = (Ũ_ij − Ũ_ji)/(σ̂ᵢ + σ̂ⱼ), Ũ = Uᵀ δF V.
  const M ut = u.transpose() * bz * v;
  M w = M::Zero();
  for (int c = 0; c < D; ++c)
    for (int rr = 0; rr < D; ++rr)
      if (rr != c) w(rr, c) = (ut(rr, c) - ut(c, rr)) / (s_hat(rr) + s_hat(c));
  const M c_bz = T(2) * mu * (bz - u * w * v.transpose());  // C:(𝓑:Z)

  // Ĉ:Z = (C:(𝓑:Z)):𝓑 + a(H:Z)A:𝓑 + aJᵃ(A:Z)H − aJᵃ(A:F)HZᵀH.
  const T fc = f.cwiseProduct(c_bz).sum();  // F:(C:(𝓑:Z)), for (C:(𝓑:Z)):𝓑
  const T a_z = pa.cwiseProduct(z).sum();   // A:Z
  chat_z = ja * (c_bz + a * fc * h) + a * h_z * ahat + (a * ja * a_z) * h -
           (a * ja * a_f) * (h * z.transpose() * h);
  return true;
}

/// The baseline over a batch (same layout as the C batch calls); returns the first failed
/// particle, or n.
template <class T, int D>
std::size_t eigen_batch(std::size_t n, const T* mu, const T* f, const T* z, T* ahat, T* chat_z) {
  using M = Eigen::Matrix<T, D, D>;
  constexpr std::size_t dd = D * D;
  std::size_t first_failed = n;
  for (std::size_t i = 0; i < n; ++i) {
    M a, c;
    if (!eigen_particle<T, D>(mu[i], Eigen::Map<const M>(f + i * dd),
                              Eigen::Map<const M>(z + i * dd), a, c)) {
      if (first_failed == n) first_failed = i;
      continue;
    }
    Eigen::Map<M>(ahat + i * dd) = a;
    Eigen::Map<M>(chat_z + i * dd) = c;
  }
  return first_failed;
}

#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic pop
#endif

}  // namespace
