//! Building blocks of the generators: the dimensions ([`FamilyDim`]: rotated diagonal
//! matrices), rounding to `T`, the `δ = 10⁻ᵏ` sweeps, the scale range and uniform noise.

use crate::workload::HaarRotation;
use ampm_core::{Mat, Real};
use rand::Rng;
use rand_pcg::Pcg64;

/// Dimensions the families are defined for (2 and 3).
pub trait FamilyDim: HaarRotation {
    /// `Mat<f64, D>` as a column-major array constructor.
    #[must_use]
    fn diag_rot(rng: &mut Pcg64, sigma: &[f64], rotate: bool) -> Self;
}

impl<const D: usize> FamilyDim for Mat<f64, D>
where
    Mat<f64, D>: HaarRotation,
{
    fn diag_rot(rng: &mut Pcg64, sigma: &[f64], rotate: bool) -> Self {
        let mut d = [0.0; D];
        d.copy_from_slice(&sigma[..D]);
        let s = Mat::from_diagonal(d);
        if rotate {
            let q = <Self as HaarRotation>::haar(rng);
            let w = <Self as HaarRotation>::haar(rng);
            q * s * w.transpose()
        } else {
            s
        }
    }
}

/// Rounds every entry to `T` (exactly representable afterwards).
#[inline]
#[must_use]
pub fn round_to<T: Real, const D: usize>(f: &Mat<f64, D>) -> Mat<f64, D> {
    f.map(|x| T::from_f64(x).to_f64())
}

/// `10⁻ᵏ` for `k = 1 ..= kmax` (`kmax` beyond the precision, to cross `ε`).
pub(super) fn decades(kmax: i32) -> impl Iterator<Item = f64> {
    (1..=kmax).map(|k| 10f64.powi(-k))
}

/// Decimal digits of `T` plus a margin: the `δ = 10⁻ᵏ` sweeps run past `ε` into the regime
/// where the rounding of `F` dominates.
pub(super) fn kmax<T: Real>() -> i32 {
    if T::MANTISSA_DIGITS <= 24 {
        9
    } else {
        18
    }
}

/// Exponent range `±e` of the scaled families: 20 for f32, 150 for f64.
pub(super) fn scale_exp<T: Real>() -> i32 {
    if T::MANTISSA_DIGITS <= 24 {
        20
    } else {
        150
    }
}

/// A random matrix with entries uniform in `[−1, 1]`.
pub(super) fn noise<const D: usize>(rng: &mut Pcg64) -> Mat<f64, D> {
    let mut m = Mat::<f64, D>::ZERO;
    for j in 0..D {
        for i in 0..D {
            m.cols[j][i] = rng.random_range(-1.0..=1.0);
        }
    }
    m
}
