//! `D×D` matrices of lanes, column-major (`m[j][i]` is row `i`, column `j`, as [`Mat`]).
//!
//! Every operation performs exactly the floating-point operations of the matching [`Mat`]
//! operation, in the same order (products accumulate from `0` over `k` ascending, inner
//! products over columns then rows), so a lane of the result has the bits of the scalar result.
//! The dimension-specific parts (determinant, cofactor, `x^{−1/d}`, the SVD) are in [`LDim`].
//!
//! [`Mat`]: crate::mat::Mat

#![allow(clippy::needless_range_loop)]

use super::lane::Lane;
use crate::polar::McAdams;

/// A `D×D` matrix of lanes, column-major.
pub type LMat<S, const D: usize> = [[S; D]; D];

/// `m[j][i] = e` for every entry, by plain loops (no closures: see `lane.rs`).
macro_rules! entries {
    ($like:expr, $j:ident, $i:ident => $e:expr) => {{
        let mut m = *$like;
        for $j in 0..D {
            for $i in 0..D {
                m[$j][$i] = $e;
            }
        }
        m
    }};
}

/// The zero matrix.
#[inline(always)]
#[must_use]
pub fn zero<S: Lane, const D: usize>() -> LMat<S, D> {
    [[S::splat(<S::Scalar as crate::Real>::ZERO); D]; D]
}

/// The identity matrix.
#[inline(always)]
#[must_use]
pub fn identity<S: Lane, const D: usize>() -> LMat<S, D> {
    let mut m = zero::<S, D>();
    for (i, c) in m.iter_mut().enumerate() {
        c[i] = S::splat(<S::Scalar as crate::Real>::ONE);
    }
    m
}

/// `a · b` (as `Mat::mul`).
#[inline(always)]
#[must_use]
pub fn mul<S: Lane, const D: usize>(a: &LMat<S, D>, b: &LMat<S, D>) -> LMat<S, D> {
    let mut m = zero::<S, D>();
    for j in 0..D {
        for k in 0..D {
            let bk = b[j][k];
            for i in 0..D {
                m[j][i] += a[k][i] * bk;
            }
        }
    }
    m
}

/// `aᵀ`.
#[inline(always)]
#[must_use]
pub fn transpose<S: Lane, const D: usize>(a: &LMat<S, D>) -> LMat<S, D> {
    entries!(a, j, i => a[i][j])
}

/// `a : b` (as `Mat::ddot`).
#[inline(always)]
#[must_use]
pub fn ddot<S: Lane, const D: usize>(a: &LMat<S, D>, b: &LMat<S, D>) -> S {
    let mut s = S::splat(<S::Scalar as crate::Real>::ZERO);
    for j in 0..D {
        for i in 0..D {
            s += a[j][i] * b[j][i];
        }
    }
    s
}

/// `a + b`.
#[inline(always)]
#[must_use]
pub fn add<S: Lane, const D: usize>(a: &LMat<S, D>, b: &LMat<S, D>) -> LMat<S, D> {
    entries!(a, j, i => a[j][i] + b[j][i])
}

/// `a − b`.
#[inline(always)]
#[must_use]
pub fn sub<S: Lane, const D: usize>(a: &LMat<S, D>, b: &LMat<S, D>) -> LMat<S, D> {
    entries!(a, j, i => a[j][i] - b[j][i])
}

/// `a · s`.
#[inline(always)]
#[must_use]
pub fn scale<S: Lane, const D: usize>(a: &LMat<S, D>, s: S) -> LMat<S, D> {
    entries!(a, j, i => a[j][i] * s)
}

/// `if m { a } else { b }`, lane-wise.
#[inline(always)]
#[must_use]
pub fn select<S: Lane, const D: usize>(m: S::Mask, a: &LMat<S, D>, b: &LMat<S, D>) -> LMat<S, D> {
    entries!(a, j, i => S::select(m, a[j][i], b[j][i]))
}

/// Lanes whose entries are all finite: `Σ aᵢⱼ·0 == 0` (a finite `x` gives `x·0 = ±0`, an
/// infinite or NaN one gives NaN, which propagates through the sum and fails the test; the
/// sum of zeros cannot overflow). Two vector operations per entry, no integer masks.
#[inline(always)]
#[must_use]
pub fn is_finite<S: Lane, const D: usize>(a: &LMat<S, D>) -> S::Mask {
    let zero = S::splat(<S::Scalar as crate::Real>::ZERO);
    let mut s = zero;
    for c in a {
        for x in c {
            s += *x * zero;
        }
    }
    s.eq(zero)
}

/// `polar::scale_exponent`: the exponent of the largest absolute entry (as `Mat::max_abs`).
#[inline(always)]
#[must_use]
pub fn scale_exponent<S: Lane, const D: usize>(a: &LMat<S, D>) -> S {
    let mut m = S::splat(<S::Scalar as crate::Real>::ZERO);
    for c in a {
        for x in c {
            m = m.max(x.abs());
        }
    }
    m.exponent()
}

/// `a · 2ᵉ`, `e` integer-valued, in three power-of-two factors of at most `3|e|/8` each, so
/// that no factor overflows for any exponent the kernels produce (`|e| ≤ 2·1074 + 2` in f64):
/// `0 · 2ᵉ` stays 0 where a two-factor split gave `0 · inf = NaN`. Exact unless the result
/// leaves the normal range (like `polar::scale_pow2`, which rounds such results once; here an
/// intermediate underflow may round twice, at most one subnormal ulp).
#[inline(always)]
#[must_use]
pub fn scale_pow2<S: Lane, const D: usize>(a: &LMat<S, D>, e: S) -> LMat<S, D> {
    let (p1, p2, p3) = pow2_split(e);
    entries!(a, j, i => a[j][i] * p1 * p2 * p3)
}

/// `x · 2ᵉ` (as [`scale_pow2`] on one entry).
#[inline(always)]
#[must_use]
pub fn scale_pow2_scalar<S: Lane>(x: S, e: S) -> S {
    let (p1, p2, p3) = pow2_split(e);
    x * p1 * p2 * p3
}

/// `2ᵉ = 2^q · 2^h · 2^(e−q−h)` with `q ≈ e/4`, `h ≈ 3e/8`.
#[inline(always)]
fn pow2_split<S: Lane>(e: S) -> (S, S, S) {
    let q = S::half_trunc(S::half_trunc(e));
    let h = S::half_trunc(e - q);
    (S::pow2(q), S::pow2(h), S::pow2(e - q - h))
}

/// Cross product (as `mat::cross`).
#[inline(always)]
#[must_use]
pub fn cross<S: Lane>(a: [S; 3], b: [S; 3]) -> [S; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// The dimension-specific operations on lane matrices (`D` = 2, 3).
pub trait LDim<S: Lane>: Copy {
    /// The dimension.
    const DIM: usize;
    /// Determinant (as `Matrix::det`).
    #[must_use]
    fn det(&self) -> S;
    /// Cofactor matrix (as `Matrix::cofactor`).
    #[must_use]
    fn cofactor(&self) -> Self;
    /// `x^{−1/d}` (as `augmented`'s `inv_root`: `1/sqrt` or `1/cbrt`).
    #[must_use]
    fn inv_root(x: S) -> S;
    /// A vector of `d` lanes (the singular values).
    type Vector: Copy + core::ops::Index<usize, Output = S>;
    /// Rotation-variant SVD `(U, σ, V)`; `sweeps` is used by the 3D method only.
    #[must_use]
    fn svd(&self, sweeps: u32) -> (Self, Self::Vector, Self);
}

impl<S: Lane> LDim<S> for LMat<S, 2> {
    const DIM: usize = 2;
    #[inline(always)]
    fn det(&self) -> S {
        let m = self;
        m[0][0] * m[1][1] - m[1][0] * m[0][1]
    }
    #[inline(always)]
    fn cofactor(&self) -> Self {
        let m = self;
        [[m[1][1], -m[1][0]], [-m[0][1], m[0][0]]]
    }
    #[inline(always)]
    fn inv_root(x: S) -> S {
        S::splat(<S::Scalar as crate::Real>::ONE) / x.sqrt()
    }
    type Vector = [S; 2];
    #[inline(always)]
    fn svd(&self, _sweeps: u32) -> (Self, [S; 2], Self) {
        super::closed2::svd2_lanes(self)
    }
}

impl<S: Lane> LDim<S> for LMat<S, 3> {
    const DIM: usize = 3;
    #[inline(always)]
    fn det(&self) -> S {
        let c = self;
        let x = cross(c[1], c[2]);
        c[0][0] * x[0] + c[0][1] * x[1] + c[0][2] * x[2]
    }
    #[inline(always)]
    fn cofactor(&self) -> Self {
        let c = self;
        [cross(c[1], c[2]), cross(c[2], c[0]), cross(c[0], c[1])]
    }
    #[inline(always)]
    fn inv_root(x: S) -> S {
        S::splat(<S::Scalar as crate::Real>::ONE) / x.cbrt()
    }
    type Vector = [S; 3];
    #[inline(always)]
    fn svd(&self, sweeps: u32) -> (Self, [S; 3], Self) {
        McAdams { sweeps }.svd_lanes(self)
    }
}
