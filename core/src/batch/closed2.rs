//! The closed-form 2D SVD on lanes: a branch-free transcription of
//! [`ClosedForm2`](crate::polar::ClosedForm2) (see `polar/closed_form_2d.rs` for the
//! derivation). Both branches of each `if` there are computed and the lane's branch selected,
//! with the same operations in the same order, so every lane has the bits of the scalar method
//! (checked by `tests/batch.rs`).

#![allow(clippy::needless_range_loop)]

use super::lane::Lane;
use super::lmat::{
    identity, mul, scale_exponent, scale_pow2, scale_pow2_scalar, select, transpose, LDim, LMat,
};
use crate::scalar::Real;

/// The rotation `[[c, −s], [s, c]]` (columns `(c, s)`, `(−s, c)`).
#[inline(always)]
fn rot2<S: Lane>(c: S, s: S) -> LMat<S, 2> {
    [[c, s], [-s, c]]
}

/// `(cos β, sin β)` from `(cos 2β, sin 2β)`, the stable half-angle formula of each lane.
#[inline(always)]
fn half_angle<S: Lane>(c2: S, s2: S) -> (S, S) {
    let one = S::splat(S::Scalar::ONE);
    let half = S::splat(S::Scalar::HALF);
    let pos = S::splat(S::Scalar::ZERO).le(c2);
    // c2 ≥ 0
    let c = ((one + c2) * half).sqrt();
    let (ca, sa) = (c, s2 / (c + c));
    // c2 < 0
    let s = ((one - c2) * half).sqrt().copysign(s2);
    let (cb, sb) = (s2 / (s + s), s);
    (S::select(pos, ca, cb), S::select(pos, sa, sb))
}

/// `(U, σ, V)` of each lane, as `ClosedForm2::svd` on that lane (finite input).
#[inline(always)]
#[must_use]
pub fn svd2_lanes<S: Lane>(f0: &LMat<S, 2>) -> (LMat<S, 2>, [S; 2], LMat<S, 2>) {
    let zero = S::splat(S::Scalar::ZERO);
    let half = S::splat(S::Scalar::HALF);
    let k = scale_exponent(f0);
    let f = scale_pow2(f0, -k);
    // f[j][i] = F_ij: e = F₀₀ + F₁₁, h = F₁₀ − F₀₁.
    let (e, h) = (f[0][0] + f[1][1], f[0][1] - f[1][0]);
    let q2 = (e * e + h * h).sqrt();
    let refl = q2.eq(zero);
    let r = rot2(e / q2, h / q2);
    let s = mul(&transpose(&r), &f);
    let s01 = (s[1][0] + s[0][1]) * half;
    // Regular lanes: (x, y) from S = RᵀF; reflection lanes: from F (`reflection_svd`).
    let x = S::select(refl, f[0][0] - f[1][1], s[0][0] - s[1][1]);
    let y = S::select(refl, f[0][1] + f[1][0], s01 + s01);
    let r2 = (x * x + y * y).sqrt();
    let (c, sn) = half_angle(x / r2, y / r2);
    let v = select(r2.eq(zero), &identity(), &rot2(c, sn));
    let sigma0 = (q2 + r2) * half;
    let sigma1 = f.det() / sigma0;
    let rr = r2 * half;
    let u = select(refl, &v, &mul(&r, &v));
    let s0 = S::select(refl, rr, sigma0);
    let s1 = S::select(refl, -rr, sigma1);
    (u, [scale_pow2_scalar(s0, k), scale_pow2_scalar(s1, k)], v)
}
