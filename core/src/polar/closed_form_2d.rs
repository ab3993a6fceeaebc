//! Closed-form rotation-variant SVD of a 2×2 matrix.
//!
//! Derivation: write `F = [[a, b], [c, d]]` (rows). With `E = (a+d)/2`, `H = (c−b)/2`,
//! `P = (a−d)/2`, `G = (c+b)/2`, `F = Q·rot(θ) + r·refl(φ)` where `Q = √(E²+H²)`,
//! `r = √(P²+G²)`; hence `σ₀ = Q + r ≥ |σ₁|` and `σ₀σ₁ = det F`. The rotation of the polar
//! decomposition is `R = rot(θ)` with `(cos θ, sin θ) = (E, H)/Q`, i.e. the normalised
//! `(F₀₀+F₁₁, F₁₀−F₀₁)`. `V` diagonalises the symmetric `S = RᵀF` (half-angle formulas, no
//! trigonometric calls) and `U = R V`. `σ₁ = det F / σ₀` avoids the cancellation in `Q − r`.
//! Input is pre-scaled by a power of two, so no threshold is absolute.

use super::{scale_exponent, scale_pow2, Svd, SvdMethod};
use crate::error::{Error, Result};
use crate::mat::{Mat, Matrix};
use crate::scalar::Real;

/// Closed-form 2D SVD (no iteration, no trigonometric calls).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ClosedForm2;

/// The rotation `[[c, −s], [s, c]]`.
#[inline]
#[must_use]
pub(crate) fn rot2<T: Real>(c: T, s: T) -> Mat<T, 2> {
    Mat::from_cols([[c, s], [-s, c]])
}

impl<T: Real> SvdMethod<Mat<T, 2>> for ClosedForm2 {
    const NAME: &'static str = "closed-form-2d";

    #[inline]
    fn svd(&self, f0: &Mat<T, 2>) -> Result<Svd<Mat<T, 2>>> {
        if !f0.is_finite() {
            return Err(Error::NonFinite);
        }
        let id = Mat::<T, 2>::identity();
        let k = scale_exponent(f0);
        let f = scale_pow2(f0, -k);
        let (e, h) = (f[(0, 0)] + f[(1, 1)], f[(1, 0)] - f[(0, 1)]);
        let q2 = (e * e + h * h).sqrt(); // 2Q = σ₀ + σ₁
        if q2 == T::ZERO {
            // F = r·reflection (or 0): det F = −r² ≤ 0, R = I by convention.
            return reflection_svd(&f, k);
        }
        let r = rot2(e / q2, h / q2);
        let s = r.transpose() * f;
        // Symmetric part: S is symmetric up to rounding.
        let s01 = (s[(0, 1)] + s[(1, 0)]) * T::HALF;
        let (x, y) = (s[(0, 0)] - s[(1, 1)], s01 + s01); // = 2r (cos 2β, sin 2β)
        let r2 = (x * x + y * y).sqrt(); // 2r = σ₀ − σ₁
        let v = if r2 == T::ZERO {
            id
        } else {
            let (c2, s2) = (x / r2, y / r2);
            let (c, s) = half_angle(c2, s2);
            rot2(c, s)
        };
        let sigma0 = (q2 + r2) * T::HALF;
        let sigma1 = f.det() / sigma0;
        Ok(Svd {
            u: r * v,
            sigma: [sigma0.scalbn(k), sigma1.scalbn(k)],
            v,
        })
    }
}

/// `(cos β, sin β)` from `(cos 2β, sin 2β)`, choosing the stable half-angle formula.
#[inline]
fn half_angle<T: Real>(c2: T, s2: T) -> (T, T) {
    if c2 >= T::ZERO {
        let c = ((T::ONE + c2) * T::HALF).sqrt();
        (c, s2 / (c + c))
    } else {
        let s = ((T::ONE - c2) * T::HALF).sqrt().copysign(s2);
        (s2 / (s + s), s)
    }
}

/// SVD of a (scaled) reflection-times-scalar `F = [[p, g], [g, −p]]`, where `F₀₀+F₁₁ = 0` and
/// `F₁₀ = F₀₁`: `R = I`, `S = F`, `σ = (r, −r)`.
fn reflection_svd<T: Real>(f: &Mat<T, 2>, k: i32) -> Result<Svd<Mat<T, 2>>> {
    let (x, y) = (f[(0, 0)] - f[(1, 1)], f[(1, 0)] + f[(0, 1)]);
    let r2 = (x * x + y * y).sqrt();
    let v = if r2 == T::ZERO {
        Mat::identity()
    } else {
        let (c, s) = half_angle(x / r2, y / r2);
        rot2(c, s)
    };
    let r = r2 * T::HALF;
    Ok(Svd {
        u: v,
        sigma: [r.scalbn(k), (-r).scalbn(k)],
        v,
    })
}
