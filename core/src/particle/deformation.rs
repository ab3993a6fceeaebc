//! Evolution of the deformation gradient `F = F_E F_P`, snow plasticity and the liquid
//! projection.
//!
//! - Update (Stomakhin et al. 2014, §5; Stomakhin et al. 2013, §5): `F_E ← (I + Δt∇v) F_E`.
//!   When `det(I + Δt∇v) ≤ 0` the step would invert the particle; the paper's remedy replaces
//!   the increment by `(I + ½Δt∇v)²`, and this module keeps halving,
//!   `(I + 2⁻ᵏΔt∇v)^{2ᵏ}` (formed by `k` squarings), until the computed determinant is
//!   positive. Every `k ≥ 1` has `det = det(I + 2⁻ᵏΔt∇v)^{2ᵏ} ≥ 0`, zero only when
//!   `I + 2⁻ᵏΔt∇v` is singular; and once `‖2⁻ᵏΔt∇v‖₂ < 1` the factor has no eigenvalue on
//!   `(−∞, 0]`, so a positive determinant is guaranteed (up to underflow) after about
//!   `log₂‖Δt∇v‖` halvings. The increment tends to `exp(Δt∇v)` as `k` grows, so the remedy
//!   is consistent with the flow `Ḟ = ∇v F`. `J = det F` therefore never reaches 0.
//! - Snow plasticity (Stomakhin et al. 2013, §4): `F_E = U Σ Vᵀ`, `Σ̂ = clamp(Σ, 1 − θ_c,
//!   1 + θ_s)`, `F_E ← U Σ̂ Vᵀ`, `F_P ← F_E⁻¹ F = V Σ̂⁻¹ Σ Vᵀ F_P` (no inverse is formed).
//! - Liquid (Stomakhin et al. 2014, §4): the deviatoric part of `F_E` is dropped,
//!   `F_E ← J_E^{1/d} I`, `F_P ← F_E⁻¹ F = J_E^{−1/d} F_E F_P`.
//!
//! All three keep `F = F_E F_P` (up to rounding) and `J = J_E J_P`, with `J_E = det F_E` and
//! `J_P = det F_P`: the plastic step moves `det Σ / det Σ̂` from `J_E` to `J_P`, the liquid
//! step moves none.

use crate::error::{Error, Result};
use crate::mat::{Mat, Matrix};
use crate::polar::{DefaultSvd, SvdMethod};
use crate::scalar::Real;

use super::Snow;

/// Cap on the remedy's halvings; reaching it reports [`Error::NonPositiveJ`].
pub const MAX_HALVINGS: u32 = 64;

/// The increment `A` with `F_E ← A F_E`: `I + Δt∇v`, or `(I + 2⁻ᵏΔt∇v)^{2ᵏ}` with the
/// smallest `k ≥ 1` giving `det A > 0` (see the module docs). Returns `A` and `k`.
///
/// Errors: [`Error::NonFinite`] for non-finite `∇v` or `Δt`; [`Error::NonPositiveJ`] when no
/// `k ≤` [`MAX_HALVINGS`] gives a positive determinant (only for `‖Δt∇v‖ ≳ 2⁶⁴`, or when the
/// determinant underflows).
#[inline]
pub fn increment<T: Real, const D: usize>(grad_v: &Mat<T, D>, dt: T) -> Result<(Mat<T, D>, u32)>
where
    Mat<T, D>: Matrix<Scalar = T>,
{
    let l = *grad_v * dt;
    if !dt.is_finite() || !l.is_finite() {
        return Err(Error::NonFinite);
    }
    let id = Mat::<T, D>::identity();
    let a = id + l;
    if Matrix::det(&a) > T::ZERO {
        return Ok((a, 0));
    }
    for k in 1..=MAX_HALVINGS {
        let mut a = id + l * T::ONE.scalbn(-(k as i32));
        for _ in 0..k {
            a = a * a;
        }
        let det = Matrix::det(&a);
        if a.is_finite() && det > T::ZERO && det.is_finite() {
            return Ok((a, k));
        }
    }
    Err(Error::NonPositiveJ)
}

/// `F_E ← A F_E` with the increment of [`increment`]; returns the new `F_E` and the number of
/// halvings the remedy used.
///
/// Errors: as [`increment`]; [`Error::NonPositiveJ`] when the product's computed determinant
/// is not positive (an `F_E` singular to working precision); [`Error::Overflow`] when it is
/// not finite.
#[inline]
pub fn evolve<T: Real, const D: usize>(
    f_e: &Mat<T, D>,
    grad_v: &Mat<T, D>,
    dt: T,
) -> Result<(Mat<T, D>, u32)>
where
    Mat<T, D>: Matrix<Scalar = T>,
{
    let (a, k) = increment(grad_v, dt)?;
    let f = a * *f_e;
    if !f.is_finite() {
        return Err(Error::Overflow);
    }
    let j = Matrix::det(&f);
    if !j.is_finite() {
        return Err(Error::Overflow);
    }
    if j <= T::ZERO {
        return Err(Error::NonPositiveJ);
    }
    Ok((f, k))
}

/// Snow plasticity: returns `(F_E, F_P)` after clamping the singular values of `f_e` to
/// `[1 − θ_c, 1 + θ_s]` (see the module docs). Requires `det f_e > 0`.
///
/// Errors: those of the SVD; [`Error::NonPositiveJ`] for `det f_e ≤ 0`.
#[inline]
pub fn snow_plasticity<T: Real, const D: usize>(
    snow: &Snow<T>,
    f_e: &Mat<T, D>,
    f_p: &Mat<T, D>,
) -> Result<(Mat<T, D>, Mat<T, D>)>
where
    Mat<T, D>: Matrix<Scalar = T, Vector = [T; D]>,
    DefaultSvd: SvdMethod<Mat<T, D>>,
{
    let svd = DefaultSvd.svd(f_e)?;
    let lo = T::ONE - snow.critical_compression;
    let hi = T::ONE + snow.critical_stretch;
    let mut clamped = svd.sigma;
    let mut ratio = [T::ONE; D];
    for i in 0..D {
        let s = svd.sigma[i];
        if s <= T::ZERO {
            // Rotation-variant SVD: only det F_E ≤ 0 gives a non-positive σ.
            return Err(Error::NonPositiveJ);
        }
        clamped[i] = s.max(lo).min(hi);
        ratio[i] = s / clamped[i];
    }
    let fe = svd.u * Mat::from_diagonal(clamped) * svd.v.transpose();
    let fp = svd.v * Mat::from_diagonal(ratio) * svd.v.transpose() * *f_p;
    if fe.is_finite() && fp.is_finite() {
        Ok((fe, fp))
    } else {
        Err(Error::Overflow)
    }
}

/// `J^{1/d}` by `sqrt` (d = 2) or `cbrt` (d = 3).
#[inline]
#[must_use]
pub fn root_d<T: Real, const D: usize>(j: T) -> T {
    if D == 2 {
        j.sqrt()
    } else {
        j.cbrt()
    }
}

/// Liquid projection: returns `(J_E^{1/d} I, J_E^{−1/d} F_E F_P)` (see the module docs).
///
/// Errors: [`Error::NonPositiveJ`] for `det f_e ≤ 0`; [`Error::Overflow`] for a result that
/// is not finite.
#[inline]
pub fn liquid_projection<T: Real, const D: usize>(
    f_e: &Mat<T, D>,
    f_p: &Mat<T, D>,
) -> Result<(Mat<T, D>, Mat<T, D>)>
where
    Mat<T, D>: Matrix<Scalar = T>,
{
    let j_e = Matrix::det(f_e);
    if !j_e.is_finite() {
        return Err(Error::Overflow);
    }
    if j_e <= T::ZERO {
        return Err(Error::NonPositiveJ);
    }
    let r = root_d::<T, D>(j_e);
    let fe = Mat::<T, D>::from_diagonal([r; D]);
    let fp = (*f_e * (T::ONE / r)) * *f_p;
    if fp.is_finite() && r.is_finite() && r > T::ZERO {
        Ok((fe, fp))
    } else {
        Err(Error::Overflow)
    }
}
