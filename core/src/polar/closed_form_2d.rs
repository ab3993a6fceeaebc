//! Closed-form rotation-variant SVD of a 2×2 matrix, branch-free and generic over [`Lane`].
//!
//! Derivation: write `F = [[a, b], [c, d]]` (rows). With `E = (a+d)/2`, `H = (c−b)/2`,
//! `P = (a−d)/2`, `G = (c+b)/2`, `F = Q·rot(θ) + r·refl(φ)` where `Q = √(E²+H²)`,
//! `r = √(P²+G²)`; hence `σ₀ = Q + r ≥ |σ₁|` and `σ₀σ₁ = det F`. The rotation of the polar
//! decomposition is `R = rot(θ)` with `(cos θ, sin θ) = (E, H)/Q`, i.e. the normalised
//! `(F₀₀+F₁₁, F₁₀−F₀₁)`. `V` diagonalises the symmetric `S = RᵀF` (half-angle formulas, no
//! trigonometric calls) and `U = R V`. `σ₁ = det F / σ₀` avoids the cancellation in `Q − r`.
//!
//! Robustness: the input is pre-scaled by a power of two (largest entry in `[0.5, 1)`), and
//! each 2-vector is normalised after scaling it by the power of two of its own largest
//! component ([`normalize2`]), so no square underflows or overflows: `F = c·I` plus an
//! off-diagonal entry whose square is subnormal still gives orthonormal `U`, `V`. When
//! `F₀₀+F₁₁ = F₁₀−F₀₁ = 0` (`F` a multiple of a reflection, `det F ≤ 0`) the same formulas give
//! `R = I`, `U = V`, `σ = (r, −r)`; for `F = 0`, `U = V = I`, `σ = 0`.

use super::lanes::{scaled_input, LSvd};
use super::{Svd, SvdMethod};
use crate::error::{Error, Result};
use crate::lane::lmat::{c, det, recip, renormalize, rsqrt, LMat};
use crate::lane::Lane;
use crate::mat::Mat;
use crate::scalar::Real;

/// Closed-form 2D SVD (no iteration, no trigonometric calls, no branch).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ClosedForm2;

/// `(x, y)/‖(x, y)‖` and `‖(x, y)‖`, computed on `(x, y)·2⁻ᵉ` with `2ᵉ` the power of two of
/// `max(|x|, |y|)` (exact), so neither square under- nor overflows. `(1, 0)` and 0 for
/// `x = y = 0`.
#[inline(always)]
#[must_use]
pub fn normalize2<V: Lane>(x: V, y: V) -> (V, V, V) {
    let m = x.abs().max(y.abs());
    let e = m.exponent();
    let h = (e * c(0.5)).floor();
    let (p1, p2) = (V::pow2(-h), V::pow2(h - e));
    let (xs, ys) = (x * p1 * p2, y * p1 * p2);
    let zero = m.eq(c(0.0));
    // r² ∈ [1/4, 2] after the scaling: a Newton reciprocal square root is accurate there.
    let r2 = xs * xs + ys * ys;
    let inv = rsqrt(V::select(zero, c(1.0), r2));
    let r = r2 * inv;
    let [cs, sn] = renormalize([xs * inv, ys * inv]);
    let cs = V::select(zero, c(1.0), cs);
    let sn = V::select(zero, c(0.0), sn);
    let norm = r * V::pow2(h) * V::pow2(e - h);
    (cs, sn, V::select(zero, c(0.0), norm))
}

/// `(cos β, sin β)` from a unit `(cos 2β, sin 2β)`: of the two half-angle formulas, the one
/// that divides by the larger of `cos β`, `|sin β|` (both computed, one selected).
#[inline(always)]
#[must_use]
fn half_angle<V: Lane>(c2: V, s2: V) -> (V, V) {
    // Each formula is used where its argument lies in [1/2, 1].
    let hp = (c::<V>(1.0) + c2) * c(0.5);
    let rp = rsqrt(hp);
    let (cp, sp) = (hp * rp, s2 * c(0.5) * rp);
    let hn = (c::<V>(1.0) - c2) * c(0.5);
    let rn = rsqrt(hn);
    let (sn, cn) = ((hn * rn).copysign(s2), s2.abs() * c(0.5) * rn);
    let neg = c2.lt(c(0.0));
    let [cs, sn] = renormalize([V::select(neg, cn, cp), V::select(neg, sn, sp)]);
    (cs, sn)
}

/// The rotation `[[c, −s], [s, c]]`, column-major.
#[inline(always)]
#[must_use]
fn rot<V: Lane>(cs: V, sn: V) -> LMat<V, 2> {
    [[cs, sn], [-sn, cs]]
}

/// The rotation-variant SVD of a scaled `G` (finite; largest entry in `[0.5, 1)`, or 0).
#[inline(always)]
#[must_use]
pub fn closed_form_2d<V: Lane>(g: &LMat<V, 2>) -> LSvd<V, 2> {
    // (F₀₀ + F₁₁, F₁₀ − F₀₁); column-major g[j][i] = F_ij.
    let (cr, sr, q2) = normalize2(g[0][0] + g[1][1], g[0][1] - g[1][0]);
    // S = RᵀG.
    let s00 = cr * g[0][0] + sr * g[0][1];
    let s10 = cr * g[0][1] - sr * g[0][0];
    let s01 = cr * g[1][0] + sr * g[1][1];
    let s11 = cr * g[1][1] - sr * g[1][0];
    let sym = (s01 + s10) * c(0.5);
    // (S₀₀ − S₁₁, 2 S₀₁) = 2r (cos 2β, sin 2β).
    let (c2, s2, r2) = normalize2(s00 - s11, sym + sym);
    let (cv, sv) = half_angle(c2, s2);
    let v = rot(cv, sv);
    let r = rot(cr, sr);
    let u = crate::lane::lmat::mul(&r, &v);
    let s0 = (q2 + r2) * c(0.5);
    let zero = s0.eq(c(0.0));
    // σ₀ ≥ max|Gᵢⱼ| ≥ 1/2 unless G = 0. |σ₁| ≤ σ₀ holds exactly; at σ₁ ≈ σ₀ (F a scaled
    // rotation) the rounding of det/σ₀ could exceed σ₀ by an ulp, so it is clamped.
    let s1 = V::select(zero, c(0.0), det(g) * recip(V::select(zero, c(1.0), s0)));
    let s1 = s1.abs().min(s0).copysign(s1);
    LSvd {
        u,
        sigma: [s0, s1],
        v,
    }
}

impl<T: Real> SvdMethod<Mat<T, 2>> for ClosedForm2 {
    const NAME: &'static str = "closed-form-2d";

    #[inline]
    fn svd(&self, f: &Mat<T, 2>) -> Result<Svd<Mat<T, 2>>> {
        if !f.is_finite() {
            return Err(Error::NonFinite);
        }
        let (g, k) = scaled_input::<T, 2>(&f.cols);
        Ok(closed_form_2d(&g).unscaled(k).into())
    }
}
