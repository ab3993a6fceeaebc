//! One-sided (Hestenes) Jacobi SVD of a 3×3 matrix.
//!
//! Source: Hestenes 1958; Demmel & Veselić 1992 ("Jacobi's method is more accurate than QR")
//! for the accuracy argument: rotating the columns of `F` itself (never forming `FᵀF`) gives
//! singular values with relative error `O(ε·κ(F·D))` for the best column scaling `D`, so small
//! singular values keep their relative accuracy. Each rotation makes two columns orthogonal;
//! sweeps over the pairs (0,1), (0,2), (1,2) stop when every pair satisfies
//! `|a_p·a_q| ≤ ε‖a_p‖‖a_q‖`, or at the sweep cap (quadratic convergence makes 4–6 sweeps the
//! norm in f64). Then `σᵢ = ‖aᵢ‖`, `uᵢ = aᵢ/σᵢ`.
//!
//! Rotation-variant fix-up: columns are sorted by norm (swaps negate one column of `V` so
//! `det V = +1`), `u₁` is re-orthogonalised against `u₀`, `u₂ = u₀ × u₁` (so `det U = +1`
//! exactly in structure, and `U` is orthonormal even when `σ₂ = 0`), and `σ₂ = a₂·u₂` is signed.

use super::{scale_exponent, scale_pow2, Svd, SvdMethod};
use crate::error::{Error, Result};
use crate::mat::{cross, Mat};
use crate::scalar::Real;

/// One-sided Jacobi SVD on `F` (3D), with a sweep cap.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct OneSidedJacobi {
    /// Maximum number of sweeps over the three column pairs.
    pub max_sweeps: u32,
}

impl Default for OneSidedJacobi {
    fn default() -> Self {
        Self { max_sweeps: 12 }
    }
}

#[inline]
fn dot3<T: Real>(a: &[T; 3], b: &[T; 3]) -> T {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

#[inline]
fn normalize3<T: Real>(a: [T; 3]) -> [T; 3] {
    let n = dot3(&a, &a).sqrt();
    if n == T::ZERO {
        a
    } else {
        [a[0] / n, a[1] / n, a[2] / n]
    }
}

/// A unit vector orthogonal to the unit vector `a` (for rank-deficient inputs).
#[inline]
fn any_orthogonal<T: Real>(a: [T; 3]) -> [T; 3] {
    // Cross with the coordinate axis least aligned with `a`.
    let (x, y, z) = (a[0].abs(), a[1].abs(), a[2].abs());
    let e = if x <= y && x <= z {
        [T::ONE, T::ZERO, T::ZERO]
    } else if y <= z {
        [T::ZERO, T::ONE, T::ZERO]
    } else {
        [T::ZERO, T::ZERO, T::ONE]
    };
    normalize3(cross(a, e))
}

impl<T: Real> SvdMethod<Mat<T, 3>> for OneSidedJacobi {
    const NAME: &'static str = "one-sided-jacobi";

    fn svd(&self, f0: &Mat<T, 3>) -> Result<Svd<Mat<T, 3>>> {
        if !f0.is_finite() {
            return Err(Error::NonFinite);
        }
        let k = scale_exponent(f0);
        let mut a = scale_pow2(f0, -k).cols;
        let mut v = Mat::<T, 3>::identity().cols;
        let tol = T::EPSILON;
        for _ in 0..self.max_sweeps {
            let mut rotated = false;
            for (p, q) in [(0usize, 1usize), (0, 2), (1, 2)] {
                let alpha = dot3(&a[p], &a[p]);
                let beta = dot3(&a[q], &a[q]);
                let gamma = dot3(&a[p], &a[q]);
                if gamma.abs() <= tol * alpha.sqrt() * beta.sqrt() {
                    continue;
                }
                rotated = true;
                // Rutishauser's stable rotation: ζ = (β−α)/(2γ), t = sgn(ζ)/(|ζ| + √(1+ζ²)).
                let zeta = (beta - alpha) / (gamma + gamma);
                let t = T::ONE.copysign(zeta) / (zeta.abs() + (T::ONE + zeta * zeta).sqrt());
                let c = T::ONE / (T::ONE + t * t).sqrt();
                let s = c * t;
                for i in 0..3 {
                    let (ap, aq) = (a[p][i], a[q][i]);
                    a[p][i] = c * ap - s * aq;
                    a[q][i] = s * ap + c * aq;
                    let (vp, vq) = (v[p][i], v[q][i]);
                    v[p][i] = c * vp - s * vq;
                    v[q][i] = s * vp + c * vq;
                }
            }
            if !rotated {
                break;
            }
        }
        // Sort columns by decreasing norm; a swap negates one column to keep det V = +1.
        let mut n = [dot3(&a[0], &a[0]), dot3(&a[1], &a[1]), dot3(&a[2], &a[2])];
        for (p, q) in [(0usize, 1usize), (1, 2), (0, 1)] {
            if n[q] > n[p] {
                n.swap(p, q);
                a.swap(p, q);
                v.swap(p, q);
                for i in 0..3 {
                    a[q][i] = -a[q][i];
                    v[q][i] = -v[q][i];
                }
            }
        }
        let s0 = n[0].sqrt();
        if s0 == T::ZERO {
            // F = 0: U = V = I, Σ = 0.
            let id = Mat::<T, 3>::identity();
            return Ok(Svd {
                u: id,
                sigma: [T::ZERO; 3],
                v: id,
            });
        }
        let u0 = [a[0][0] / s0, a[0][1] / s0, a[0][2] / s0];
        // u₁: a₁ made orthogonal to u₀ (it is to within ε after convergence), normalised;
        // for rank ≤ 1 any unit vector orthogonal to u₀.
        let d = dot3(&u0, &a[1]);
        let w = [
            a[1][0] - d * u0[0],
            a[1][1] - d * u0[1],
            a[1][2] - d * u0[2],
        ];
        let s1 = dot3(&w, &w).sqrt();
        let u1 = if s1 > T::ZERO {
            [w[0] / s1, w[1] / s1, w[2] / s1]
        } else {
            any_orthogonal(u0)
        };
        let u2 = cross(u0, u1);
        let s2 = dot3(&a[2], &u2);
        Ok(Svd {
            u: Mat::from_cols([u0, u1, u2]),
            sigma: [s0.scalbn(k), s1.scalbn(k), s2.scalbn(k)],
            v: Mat::from_cols(v),
        })
    }
}
