//! Branch-free 3×3 SVD: Jacobi on `FᵀF` with approximate Givens rotations (McAdams et al. 2011).
//!
//! Source: A. McAdams, A. Selle, R. Tamstorf, J. Teran, E. Sifakis, "Computing the Singular
//! Value Decomposition of 3×3 matrices with minimal branching and elementary floating point
//! operations", UW–Madison TR1690 (2011), §2–§4:
//!
//! 1. **Symmetric eigenproblem** (§2): `S = GᵀG` (`G = 2⁻ᵏF`, largest entry in `[0.5, 1)`,
//!    exact) is diagonalised by `sweeps` cyclic Jacobi sweeps over the pairs (0,1), (0,2),
//!    (1,2). Each conjugation `S ← QᵀSQ` uses the *approximate* Givens rotation of half-angle
//!    `(ch, sh) ∝ (2(S_pp − S_qq), S_pq)` (small-angle form of `tan 2θ = 2S_pq/(S_pp − S_qq)`,
//!    since `tan(θ/2) ≈ θ/2`), replaced by the fixed angle `θ/2 = π/8` when
//!    `ω·sh² ≥ ch²`, `ω = 3 + 2√2 = cot²(π/8)` (the small-angle form would exceed `π/4` there).
//!    Both choices strictly shrink `|S_pq|` (paper §2.2), so no test on convergence is needed.
//!    The product of the rotations, `V`, is accumulated as a quaternion (§2.3) and turned into
//!    a matrix once.
//! 2. **Sorting** (§3): `B = GV`; its columns are sorted by decreasing norm with swaps that
//!    negate one of the swapped columns (of `B` and `V`), keeping `det V = +1`.
//! 3. **QR by Givens rotations** (§4): three exact Givens rotations (half-angle form, computed
//!    with one square root each) reduce `B` to upper triangular `R`, `U` = their product, and
//!    `σ = diag(R)`. The first two diagonal entries come out `≥ 0`; the last carries the sign
//!    of `det F` — the rotation-variant convention of [`crate::polar`].
//!
//! Every data-dependent choice is a select, so the same source runs on SIMD lanes
//! ([`crate::kernel::batch`]) and gives, lane by lane, the bits of this scalar method.
//!
//! **Accuracy.** Working on `FᵀF` squares the condition number: the eigenvalues `σᵢ²` are
//! found to absolute accuracy `~ε σ₀²`, so `σ_min` has relative error `~ε (σ_max/σ_min)²`
//! (and `V` resolves close singular values only to `ε κ²`). Reconstruction `‖UΣVᵀ − F‖` is
//! limited by the Jacobi off-diagonal left after the last sweep: the approximate rotation
//! reduces `|S_pq|` by at least the factor of the `π/8` fallback (paper §2.2) in the first
//! sweeps and converges quadratically once the angles are small; 4 sweeps reach f32 rounding
//! for well-conditioned `F`, f64 needs more (measured by `tests/batch/mcadams.rs` and the report).
//! Sweep counts 2–8 are the sensible range; [`McAdams::new`] accepts 1–16.

#![allow(clippy::needless_range_loop)]

use super::{Svd, SvdMethod};
use crate::lane::lmat::{max_abs, pow2_factors, scale_pow2, LMat};
use crate::lane::Lane;

/// `x · 2ᵉ` (as [`scale_pow2`] on one entry).
#[inline(always)]
fn scale_pow2_scalar<S: Lane>(x: S, e: S) -> S {
    let [p1, p2, p3] = pow2_factors(e);
    x * p1 * p2 * p3
}
use crate::error::{Error, Result};
use crate::mat::Mat;
use crate::scalar::Real;

/// McAdams et al. 2011 branch-free SVD (3D), with a fixed number of Jacobi sweeps.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct McAdams {
    /// Jacobi sweeps over the three pairs; clamped to `1..=16` when used.
    pub sweeps: u32,
}

impl Default for McAdams {
    /// Four sweeps, the paper's choice for single precision.
    fn default() -> Self {
        Self { sweeps: 4 }
    }
}

impl McAdams {
    /// Smallest accepted sweep count.
    pub const MIN_SWEEPS: u32 = 1;
    /// Largest accepted sweep count.
    pub const MAX_SWEEPS: u32 = 16;

    /// The method with `sweeps` Jacobi sweeps; [`Error::InvalidArgument`] outside `1..=16`.
    #[inline]
    pub fn new(sweeps: u32) -> Result<Self> {
        if (Self::MIN_SWEEPS..=Self::MAX_SWEEPS).contains(&sweeps) {
            Ok(Self { sweeps })
        } else {
            Err(Error::InvalidArgument)
        }
    }
}

/// One Jacobi conjugation of the symmetric `S` in the plane `(p, q)`, `r` the third index.
///
/// `a = S_pp`, `d = S_qq`, `b = S_pq`, `pr = S_pr`, `qr = S_qr`. The rotation `Q` maps
/// `e_p → c e_p + s e_q`, `e_q → −s e_p + c e_q`, i.e. angle `θ` about `e_p × e_q = sign·e_r`;
/// its quaternion `(cos θ/2, sin θ/2 · sign·e_r)` multiplies `quat` on the right (`V ← VQ`).
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn conjugate<S: Lane>(
    a: &mut S,
    d: &mut S,
    b: &mut S,
    pr: &mut S,
    qr: &mut S,
    quat: &mut [S; 4],
    r: usize,
    sign: S::Scalar,
) {
    let one = S::splat(S::Scalar::ONE);
    let two = S::splat(S::Scalar::TWO);
    // ω = 3 + 2√2 = cot²(π/8); (cos, sin)(π/8).
    let omega = S::splat(S::Scalar::from_f64(5.828_427_124_746_19));
    let cstar = S::splat(S::Scalar::from_f64(0.923_879_532_511_286_7));
    let sstar = S::splat(S::Scalar::from_f64(0.382_683_432_365_089_8));
    let ch0 = two * (*a - *d);
    let sh0 = *b;
    let small = (omega * sh0 * sh0).lt(ch0 * ch0);
    // When ch0 = sh0 = 0 the rsqrt is inf, but `small` is false there: the π/8 branch wins.
    let w = one / (ch0 * ch0 + sh0 * sh0).sqrt();
    let ch = S::select(small, w * ch0, cstar);
    let sh = S::select(small, w * sh0, sstar);
    // Double angle: c = cos θ, s = sin θ.
    let (ch2, sh2) = (ch * ch, sh * sh);
    let c = ch2 - sh2;
    let s = two * ch * sh;
    let (cc, ss, cs) = (c * c, s * s, c * s);
    let (a0, d0, b0, pr0, qr0) = (*a, *d, *b, *pr, *qr);
    // QᵀSQ on the (p, q) block and the coupling to r.
    *a = cc * a0 + two * cs * b0 + ss * d0;
    *d = ss * a0 - two * cs * b0 + cc * d0;
    *b = (cc - ss) * b0 - cs * (a0 - d0);
    *pr = c * pr0 + s * qr0;
    *qr = c * qr0 - s * pr0;
    // quat ⊗ (ch, t·e_r), t = ±sh (Hamilton product, quat = (w, x, y, z)).
    let t = sh * S::splat(sign);
    let [qw, qx, qy, qz] = *quat;
    *quat = match r {
        0 => [
            qw * ch - qx * t,
            qx * ch + qw * t,
            qy * ch + qz * t,
            qz * ch - qy * t,
        ],
        1 => [
            qw * ch - qy * t,
            qx * ch - qz * t,
            qy * ch + qw * t,
            qz * ch + qx * t,
        ],
        _ => [
            qw * ch - qz * t,
            qx * ch + qy * t,
            qy * ch - qx * t,
            qz * ch + qw * t,
        ],
    };
}

/// Exact Givens rotation (half-angle form) taking `(a1, a2)` to `(ρ, 0)`, `ρ = ‖(a1, a2)‖`:
/// returns `(cos θ, sin θ) = (a1, a2)/ρ`, or the identity (up to sign) when `ρ < tiny`.
///
/// `tan(θ/2) = a2/(ρ + a1) = (ρ − a1)/a2`; the first form is used for `a1 ≥ 0`, the second
/// (swapping the unnormalised `ch`, `sh`) for `a1 < 0`, so nothing cancels (paper §4).
#[inline(always)]
fn givens<S: Lane>(a1: S, a2: S, tiny: S) -> (S, S) {
    let one = S::splat(S::Scalar::ONE);
    let zero = S::splat(S::Scalar::ZERO);
    let rho = (a1 * a1 + a2 * a2).sqrt();
    let sh0 = S::select(rho.lt(tiny), zero, a2);
    let ch0 = a1.abs() + rho.max(tiny);
    let neg = a1.lt(zero);
    let (ch, sh) = (S::select(neg, sh0, ch0), S::select(neg, ch0, sh0));
    let w = one / (ch * ch + sh * sh).sqrt();
    let (ch, sh) = (ch * w, sh * w);
    (ch * ch - sh * sh, S::splat(S::Scalar::TWO) * ch * sh)
}

/// Applies the Givens rotation `(c, s)` in the plane `(p, q)`: `B ← QᵀB` (rows), `U ← UQ`.
#[inline(always)]
fn apply_givens<S: Lane>(b: &mut LMat<S, 3>, u: &mut LMat<S, 3>, p: usize, q: usize, c: S, s: S) {
    for j in 0..3 {
        let (bp, bq) = (b[j][p], b[j][q]);
        b[j][p] = c * bp + s * bq;
        b[j][q] = c * bq - s * bp;
    }
    for i in 0..3 {
        let (up, uq) = (u[p][i], u[q][i]);
        u[p][i] = c * up + s * uq;
        u[q][i] = c * uq - s * up;
    }
}

/// Swaps columns `p`, `q` of `b` and `v` where `cond`, negating the new column `q`.
#[inline(always)]
fn cond_swap<S: Lane>(
    cond: S::Mask,
    b: &mut LMat<S, 3>,
    v: &mut LMat<S, 3>,
    n: &mut [S; 3],
    p: usize,
    q: usize,
) {
    for i in 0..3 {
        let (bp, bq) = (b[p][i], b[q][i]);
        b[p][i] = S::select(cond, bq, bp);
        b[q][i] = S::select(cond, -bp, bq);
        let (vp, vq) = (v[p][i], v[q][i]);
        v[p][i] = S::select(cond, vq, vp);
        v[q][i] = S::select(cond, -vp, vq);
    }
    let (np, nq) = (n[p], n[q]);
    n[p] = S::select(cond, nq, np);
    n[q] = S::select(cond, np, nq);
}

#[inline(always)]
fn dot3<S: Lane>(a: &[S; 3], b: &[S; 3]) -> S {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

impl McAdams {
    /// The SVD of each lane of `f0` (finite input): `(U, σ, V)`, column-major lane matrices.
    ///
    /// One generic source for one scalar (`S = f32`, `f64`, behind [`SvdMethod`]) and for
    /// `N` lanes ([`crate::kernel::batch`]).
    #[inline(always)]
    #[must_use]
    pub fn svd_lanes<S: Lane>(&self, f0: &LMat<S, 3>) -> (LMat<S, 3>, [S; 3], LMat<S, 3>) {
        svd3_lanes(f0, self.sweeps)
    }
}

#[inline(always)]
fn svd3_lanes<S: Lane>(f0: &LMat<S, 3>, sweeps: u32) -> (LMat<S, 3>, [S; 3], LMat<S, 3>) {
    let zero = S::splat(S::Scalar::ZERO);
    let one = S::splat(S::Scalar::ONE);
    let two = S::splat(S::Scalar::TWO);
    let k = max_abs(f0).exponent();
    let g = scale_pow2(f0, -k);
    // S = GᵀG (entries are dot products of columns).
    let mut s00 = dot3(&g[0], &g[0]);
    let mut s11 = dot3(&g[1], &g[1]);
    let mut s22 = dot3(&g[2], &g[2]);
    let mut s01 = dot3(&g[0], &g[1]);
    let mut s02 = dot3(&g[0], &g[2]);
    let mut s12 = dot3(&g[1], &g[2]);
    let mut quat = [one, zero, zero, zero];
    let (pos, neg) = (S::Scalar::ONE, -S::Scalar::ONE);
    for _ in 0..sweeps.clamp(McAdams::MIN_SWEEPS, McAdams::MAX_SWEEPS) {
        // (p, q, r) = (0, 1, 2): axis e₀ × e₁ = +e₂.
        conjugate(
            &mut s00, &mut s11, &mut s01, &mut s02, &mut s12, &mut quat, 2, pos,
        );
        // (0, 2, 1): e₀ × e₂ = −e₁. S_pr = S₀₁, S_qr = S₂₁.
        conjugate(
            &mut s00, &mut s22, &mut s02, &mut s01, &mut s12, &mut quat, 1, neg,
        );
        // (1, 2, 0): e₁ × e₂ = +e₀. S_pr = S₁₀, S_qr = S₂₀.
        conjugate(
            &mut s11, &mut s22, &mut s12, &mut s01, &mut s02, &mut quat, 0, pos,
        );
    }
    // V = matrix of the normalised quaternion.
    let [qw, qx, qy, qz] = quat;
    let inv = one / (qw * qw + qx * qx + qy * qy + qz * qz).sqrt();
    let (qw, qx, qy, qz) = (qw * inv, qx * inv, qy * inv, qz * inv);
    let (xx, yy, zz) = (qx * qx, qy * qy, qz * qz);
    let (xy, xz, yz) = (qx * qy, qx * qz, qy * qz);
    let (wx, wy, wz) = (qw * qx, qw * qy, qw * qz);
    let mut v: LMat<S, 3> = [
        [one - two * (yy + zz), two * (xy + wz), two * (xz - wy)],
        [two * (xy - wz), one - two * (xx + zz), two * (yz + wx)],
        [two * (xz + wy), two * (yz - wx), one - two * (xx + yy)],
    ];
    // B = G V.
    let mut b = [[zero; 3]; 3];
    for j in 0..3 {
        for i in 0..3 {
            b[j][i] = g[0][i] * v[j][0] + g[1][i] * v[j][1] + g[2][i] * v[j][2];
        }
    }
    let mut n = [dot3(&b[0], &b[0]), dot3(&b[1], &b[1]), dot3(&b[2], &b[2])];
    for (p, q) in [(0, 1), (0, 2), (1, 2)] {
        let c = n[p].lt(n[q]);
        cond_swap(c, &mut b, &mut v, &mut n, p, q);
    }
    // QR: zero B₁₀, B₂₀, B₂₁. `tiny` = ε² relative to the scaled ‖G‖ ~ 1: below it a column
    // is zero to working precision (and tiny² stays normal).
    let tiny = S::splat(S::Scalar::EPSILON * S::Scalar::EPSILON);
    let mut u: LMat<S, 3> = [[one, zero, zero], [zero, one, zero], [zero, zero, one]];
    for (p, q) in [(0, 1), (0, 2), (1, 2)] {
        let (c, s) = givens(b[p][p], b[p][q], tiny);
        apply_givens(&mut b, &mut u, p, q, c, s);
    }
    let sigma = [
        scale_pow2_scalar(b[0][0], k),
        scale_pow2_scalar(b[1][1], k),
        scale_pow2_scalar(b[2][2], k),
    ];
    (u, sigma, v)
}

impl<T: Real> SvdMethod<Mat<T, 3>> for McAdams {
    const NAME: &'static str = "mcadams";

    #[inline]
    fn svd(&self, f: &Mat<T, 3>) -> Result<Svd<Mat<T, 3>>> {
        if !f.is_finite() {
            return Err(Error::NonFinite);
        }
        let (u, sigma, v) = self.svd_lanes::<T>(&f.cols);
        Ok(Svd {
            u: Mat::from_cols(u),
            sigma,
            v: Mat::from_cols(v),
        })
    }
}
