//! One-sided (Hestenes) Jacobi SVD of a 3×3 matrix: branch-free, a fixed number of sweeps,
//! generic over [`Lane`] (the same source runs on one scalar and on SIMD vectors).
//!
//! Source: Hestenes 1958; Demmel & Veselić 1992 ("Jacobi's method is more accurate than QR")
//! for the accuracy argument: rotating the columns of `F` itself (never forming `FᵀF`) gives
//! singular values with relative error `O(ε·κ(F·D))` for the best column scaling `D`, so small
//! singular values keep their relative accuracy. Each rotation (Rutishauser's stable form,
//! [`jacobi_rotation`]) makes two columns orthogonal; a sweep visits the pairs (0,1), (0,2), (1,2). There is
//! no stopping test: cyclic Jacobi converges quadratically, and the sweep count per precision
//! ([`OneSidedJacobi::sweeps_for`]) is the smallest that meets every contract of the stability
//! families (`tests/stability/contracts.rs`, measured by `ampm-report`). A rotation of two already
//! orthogonal columns is the identity to rounding, so extra sweeps cost time, not accuracy.
//! Then `σᵢ = ‖aᵢ‖`, `uᵢ = aᵢ/σᵢ`.
//!
//! Rotation-variant fix-up: columns are sorted by norm (a swap negates one column of `V` so
//! `det V = +1`), `u₁` is re-orthogonalised against `u₀`, `u₂ = u₀ × u₁` (so `det U = +1` in
//! structure, and `U` is orthonormal even when `σ₂ = 0`), and `σ₂ = a₂·u₂` is signed. Norms
//! are taken after scaling by a power of two ([`normalize`]), so columns whose squares
//! underflow keep their direction and order.

use super::lanes::{normalize, scaled_input, LSvd};
use super::{Svd, SvdMethod};
use crate::error::{Error, Result};
use crate::lane::lmat::{c, cross, dot, identity, jacobi_rotation, LMat};
use crate::lane::Lane;
use crate::mat::Mat;
use crate::scalar::Real;

/// One-sided Jacobi SVD on `F` (3D) with a fixed number of sweeps.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct OneSidedJacobi {
    /// Sweeps over the three column pairs; 0 means [`OneSidedJacobi::sweeps_for`] of the
    /// precision.
    pub sweeps: u32,
}

impl OneSidedJacobi {
    /// The default sweep count of a precision with `mantissa_digits` bits: 3 for f32, 4 for f64, 24
    /// for the double-double reference. Measured, not guessed: these are the smallest counts with
    /// which every stability contract (`tests/stability/contracts.rs`, all families, every
    /// instruction set) and the accuracy acceptance of `tests/batch/accuracy.rs` hold; one sweep
    /// fewer leaves relative errors of 2.7e-2 (f32) and 1.9e-7 (f64) on σ ∈ [0.2, 5].
    #[inline]
    #[must_use]
    pub const fn sweeps_for(mantissa_digits: u32) -> u32 {
        if mantissa_digits <= 24 {
            3
        } else if mantissa_digits <= 53 {
            4
        } else {
            24
        }
    }

    /// The sweep count used for scalars of type `T`.
    #[inline]
    #[must_use]
    pub fn sweeps_of<T: Real>(&self) -> u32 {
        if self.sweeps == 0 {
            Self::sweeps_for(T::MANTISSA_DIGITS)
        } else {
            self.sweeps
        }
    }
}

/// A unit vector orthogonal to the unit vector `a`: `e × a` normalised, for the coordinate
/// axis `e` least aligned with `a` (the last one on ties, so `e₀ ↦ e₁`).
#[inline(always)]
fn any_orthogonal<V: Lane>(a: &[V; 3]) -> [V; 3] {
    let (x, y, z) = (a[0].abs(), a[1].abs(), a[2].abs());
    let zero = c::<V>(0.0);
    let pick_z = z.le(x) & z.le(y);
    let pick_y = !pick_z & y.le(x);
    // e_z × a = (−a₁, a₀, 0), e_y × a = (a₂, 0, −a₀), e_x × a = (0, −a₂, a₁).
    let w = [
        V::select(pick_z, -a[1], V::select(pick_y, a[2], zero)),
        V::select(pick_z, a[0], V::select(pick_y, zero, -a[2])),
        V::select(pick_z, zero, V::select(pick_y, -a[0], a[1])),
    ];
    normalize(&w).0
}

/// One Jacobi rotation of columns `p`, `q` of `a` (and of `v`).
#[inline(always)]
///
/// On one scalar (the single-particle path, whose cost is the latency of this chain) a pair
/// already orthogonal to working precision, `|γ| ≤ ε√(αβ)` (Demmel & Veselić's test), is
/// skipped, and the return value says whether a rotation happened; vectors always rotate.
fn rotate<V: Lane>(a: &mut LMat<V, 3>, v: &mut LMat<V, 3>, p: usize, q: usize) -> bool {
    let alpha = dot(&a[p], &a[p]);
    let beta = dot(&a[q], &a[q]);
    let gamma = dot(&a[p], &a[q]);
    if V::LANES == 1 {
        let tol = V::splat(V::Scalar::EPSILON) * alpha.sqrt() * beta.sqrt();
        if V::all(gamma.abs().le(tol)) {
            return false;
        }
    }
    let (cs, sn) = jacobi_rotation(alpha, beta, gamma);
    for i in 0..3 {
        let (ap, aq) = (a[p][i], a[q][i]);
        a[p][i] = cs.mul_add(ap, -(sn * aq));
        a[q][i] = sn.mul_add(ap, cs * aq);
        let (vp, vq) = (v[p][i], v[q][i]);
        v[p][i] = cs.mul_add(vp, -(sn * vq));
        v[q][i] = sn.mul_add(vp, cs * vq);
    }
    true
}

/// The rotation-variant SVD of a scaled `G` (finite; largest entry in `[0.5, 1)`, or 0) by
/// `sweeps` sweeps of one-sided Jacobi.
#[inline(always)]
#[must_use]
pub fn one_sided_jacobi<V: Lane>(g: &LMat<V, 3>, sweeps: u32) -> LSvd<V, 3> {
    let mut a = *g;
    let mut v = identity::<V, 3>();
    let one = c::<V>(1.0);
    for _ in 0..sweeps {
        // Written out so that every index is a constant and a, v stay in registers.
        let r01 = rotate(&mut a, &mut v, 0, 1);
        let r02 = rotate(&mut a, &mut v, 0, 2);
        let r12 = rotate(&mut a, &mut v, 1, 2);
        // One scalar: a sweep without rotation means convergence (vectors: always false).
        if V::LANES == 1 && !(r01 || r02 || r12) {
            break;
        }
    }
    // Sort columns by decreasing norm; a swap negates one column to keep det V = +1.
    let mut n = [normalize(&a[0]).1, normalize(&a[1]).1, normalize(&a[2]).1];
    for (p, q) in [(0usize, 1usize), (1, 2), (0, 1)] {
        let s = n[p].lt(n[q]);
        let (np, nq) = (n[p], n[q]);
        n[p] = V::select(s, nq, np);
        n[q] = V::select(s, np, nq);
        for i in 0..3 {
            let (ap, aq) = (a[p][i], a[q][i]);
            a[p][i] = V::select(s, aq, ap);
            a[q][i] = V::select(s, -ap, aq);
            let (vp, vq) = (v[p][i], v[q][i]);
            v[p][i] = V::select(s, vq, vp);
            v[q][i] = V::select(s, -vp, vq);
        }
    }
    // u₀ = a₀/σ₀ (e₀ when F = 0).
    let (u0, s0) = normalize(&a[0]);
    let f0 = s0.eq(c(0.0));
    let u0 = [
        V::select(f0, one, u0[0]),
        V::select(f0, c(0.0), u0[1]),
        V::select(f0, c(0.0), u0[2]),
    ];
    // u₁: a₁ made orthogonal to u₀ (it is to within ε after convergence), normalised; for
    // rank ≤ 1 any unit vector orthogonal to u₀.
    let d = dot(&u0, &a[1]);
    let w = [
        a[1][0] - d * u0[0],
        a[1][1] - d * u0[1],
        a[1][2] - d * u0[2],
    ];
    let (u1, s1) = normalize(&w);
    // Gram–Schmidt twice ("twice is enough", Giraud et al. 2005): when a₁ is nearly parallel
    // to u₀ (rank ≤ 1), w is mostly rounding and one pass leaves u₁ off orthogonal by more
    // than ε.
    let d1 = dot(&u0, &u1);
    let (u1, n1) = normalize(&[u1[0] - d1 * u0[0], u1[1] - d1 * u0[1], u1[2] - d1 * u0[2]]);
    let alt = any_orthogonal(&u0);
    // Rank ≤ 1 to working precision (σ₁ ≤ ε·σ₀): w is rounding, its direction meaningless;
    // any unit vector orthogonal to u₀ is as good (backward error ≤ ε‖F‖).
    let r1 = s1.le(V::splat(V::Scalar::EPSILON) * s0) | n1.lt(c(0.5));
    let u1 = [
        V::select(r1, alt[0], u1[0]),
        V::select(r1, alt[1], u1[1]),
        V::select(r1, alt[2], u1[2]),
    ];
    let u2 = cross(&u0, &u1);
    let s2 = dot(&a[2], &u2);
    LSvd {
        u: [u0, u1, u2],
        sigma: [s0, s1, s2],
        v,
    }
}

impl<T: Real> SvdMethod<Mat<T, 3>> for OneSidedJacobi {
    const NAME: &'static str = "one-sided-jacobi";

    #[inline]
    fn svd(&self, f: &Mat<T, 3>) -> Result<Svd<Mat<T, 3>>> {
        if !f.is_finite() {
            return Err(Error::NonFinite);
        }
        let (g, k) = scaled_input::<T, 3>(&f.cols);
        Ok(one_sided_jacobi(&g, self.sweeps_of::<T>())
            .unscaled(k)
            .into())
    }
}
