//! What the branch-free decompositions share: the SVD of lanes, the exact power-of-two input
//! scaling, and scaled norms.

use super::Svd;
use crate::lane::lmat::{c, max_abs, pow2_factors, renormalize, rsqrt, scale_pow2, LMat};
use crate::lane::Lane;
use crate::mat::Mat;
use crate::scalar::Real;

/// A rotation-variant SVD `U diag(σ) Vᵀ` of lanes (conventions of [`crate::polar`]).
#[derive(Clone, Copy, Debug)]
pub struct LSvd<V, const D: usize> {
    /// Left rotation.
    pub u: LMat<V, D>,
    /// Singular values, decreasing in magnitude; only the last may be negative.
    pub sigma: [V; D],
    /// Right rotation.
    pub v: LMat<V, D>,
}

impl<V: Lane, const D: usize> LSvd<V, D> {
    /// The SVD of `2ᵏ G` from that of `G`: `σ · 2ᵏ`.
    #[inline(always)]
    #[must_use]
    pub fn unscaled(mut self, k: V) -> Self {
        let [p1, p2, p3] = pow2_factors(k);
        for s in &mut self.sigma {
            *s = *s * p1 * p2 * p3;
        }
        self
    }
}

impl<T: Real, const D: usize> From<LSvd<T, D>> for Svd<Mat<T, D>>
where
    Mat<T, D>: crate::Matrix<Scalar = T, Vector = [T; D]>,
{
    #[inline]
    fn from(s: LSvd<T, D>) -> Self {
        Svd {
            u: Mat::from_cols(s.u),
            sigma: s.sigma,
            v: Mat::from_cols(s.v),
        }
    }
}

/// The default decomposition of a scaled `G` (finite, largest entry in `[0.5, 1)`, or 0) on
/// lanes, for either dimension: [`closed_form_2d`] in 2D, [`one_sided_jacobi`] with the
/// precision's sweeps ([`OneSidedJacobi::sweeps_for`]) in 3D. On vectors and on `X2` lane pairs
/// of scalars it runs branch-free, so each lane's bits are the same on every path.
///
/// [`closed_form_2d`]: super::closed_form_2d
/// [`one_sided_jacobi`]: super::one_sided_jacobi
/// [`OneSidedJacobi::sweeps_for`]: super::OneSidedJacobi::sweeps_for
#[inline(always)]
#[must_use]
pub fn default_svd<V: Lane, const D: usize>(g: &LMat<V, D>) -> LSvd<V, D> {
    if D == 2 {
        super::closed_form_2d(&resized::<V, D, 2>(g)).resized()
    } else {
        let sweeps = super::OneSidedJacobi::sweeps_for(V::Scalar::MANTISSA_DIGITS);
        super::one_sided_jacobi(&resized::<V, D, 3>(g), sweeps).resized()
    }
}

/// `m` as a matrix of size `B` (called where `A = B`: the generic dimension as the concrete
/// one of a decomposition, and back). Loops, not `array::from_fn`: its closures are not
/// compiled with the caller's target features, and the copy of the vectors became a call to
/// `memcpy` (seen in a profile of the batch calls).
#[inline(always)]
fn resized<V: Copy, const A: usize, const B: usize>(m: &[[V; A]; A]) -> [[V; B]; B] {
    debug_assert_eq!(A, B);
    let mut r = [[m[0][0]; B]; B];
    for (rj, mj) in r.iter_mut().zip(m) {
        for (x, y) in rj.iter_mut().zip(mj) {
            *x = *y;
        }
    }
    r
}

impl<V: Lane, const A: usize> LSvd<V, A> {
    /// The same decomposition typed with size `B` (`A = B`).
    #[inline(always)]
    fn resized<const B: usize>(&self) -> LSvd<V, B> {
        debug_assert_eq!(A, B);
        let mut sigma = [self.sigma[0]; B];
        for (x, y) in sigma.iter_mut().zip(&self.sigma) {
            *x = *y;
        }
        LSvd {
            u: resized(&self.u),
            sigma,
            v: resized(&self.v),
        }
    }
}

/// `(G, k)` with `F = 2ᵏ G` and `G`'s largest entry in `[0.5, 1)` (exact; `k = 0`, `G = 0`
/// for `F = 0`). `F` must be finite.
#[inline(always)]
#[must_use]
pub fn scaled_input<V: Lane, const D: usize>(f: &LMat<V, D>) -> (LMat<V, D>, V) {
    let k = max_abs(f).exponent();
    (scale_pow2(f, -k), k)
}

/// `(a/‖a‖, ‖a‖)`, computed on `a·2⁻ᵉ` with `2ᵉ` the power of two of `a`'s largest entry
/// (exact), so no square under- or overflows. `(a, 0)` for `a = 0`.
#[inline(always)]
#[must_use]
pub fn normalize<V: Lane, const D: usize>(a: &[V; D]) -> ([V; D], V) {
    let mut m = a[0].abs();
    for x in a.iter().skip(1) {
        m = m.max(x.abs());
    }
    let e = m.exponent();
    let h = (e * c(0.5)).floor();
    let (p1, p2) = (V::pow2(-h), V::pow2(h - e));
    let mut s = *a;
    for x in &mut s {
        *x = *x * p1 * p2;
    }
    let mut n2 = s[0] * s[0];
    for x in s.iter().skip(1) {
        n2 += *x * *x;
    }
    let zero = m.eq(c(0.0));
    // n2 ∈ [1/4, D] after the scaling: a Newton reciprocal square root is accurate there.
    let inv = rsqrt(V::select(zero, c(1.0), n2));
    let n = n2 * inv;
    for x in &mut s {
        *x *= inv;
    }
    let s = renormalize(s);
    let norm = n * V::pow2(h) * V::pow2(e - h);
    (s, V::select(zero, c(0.0), norm))
}
