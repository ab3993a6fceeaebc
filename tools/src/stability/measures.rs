//! Error measures against the double-double reference: distances, norms, per-case scales.

use crate::reference::Dd;
use ampm_core::{Mat, Matrix, Real};

/// `‖a − b‖_F` with the difference taken in double-double (exact to ~1e-32 relative of `b`)
/// and the norm in f64 (relative error ~1e-16 of the distance itself, plenty).
pub(super) fn dist<T: Real, const D: usize>(a: &Mat<T, D>, b: &Mat<Dd, D>) -> f64 {
    let mut d = [0.0f64; 9];
    for j in 0..D {
        for i in 0..D {
            d[i + D * j] = (Dd::exact(a.cols[j][i].to_f64()) - b.cols[j][i]).to_f64();
        }
    }
    norm_scaled(&d[..D * D])
}

/// Euclidean norm of `v`, scaled by its largest entry so that no square overflows (the
/// kernels' results span 1e-300…1e300 in f64).
pub(super) fn norm_scaled(v: &[f64]) -> f64 {
    let m = v.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    if m == 0.0 || !m.is_finite() {
        return m;
    }
    v.iter().map(|x| (x / m) * (x / m)).sum::<f64>().sqrt() * m
}

/// `‖U diag(σ) Vᵀ − F‖_F`, the products in double-double for f64 (every `uᵢₖσₖ` and the sum
/// exact to ~1e-32), in f64 for f32 input (error ~1e-16, far below the f32 `ε` it is
/// compared with).
pub(super) fn recon_err<T: Real, const D: usize>(
    u: &Mat<T, D>,
    s: &[f64],
    v: &Mat<T, D>,
    f: &Mat<f64, D>,
) -> f64 {
    let mut d = [0.0f64; 9];
    for j in 0..D {
        for i in 0..D {
            d[i + D * j] = if T::MANTISSA_DIGITS <= 24 {
                let mut x = -f.cols[j][i];
                for k in 0..D {
                    x += u.cols[k][i].to_f64() * s[k] * v.cols[k][j].to_f64();
                }
                x
            } else {
                let mut x = Dd::exact(-f.cols[j][i]);
                for k in 0..D {
                    x += Dd::exact(u.cols[k][i].to_f64())
                        * Dd::exact(s[k])
                        * Dd::exact(v.cols[k][j].to_f64());
                }
                x.to_f64()
            };
        }
    }
    norm_scaled(&d[..D * D])
}

pub(super) fn norm_dd<const D: usize>(b: &Mat<Dd, D>) -> f64 {
    let m = b.cast::<f64>();
    let mut v = [0.0f64; 9];
    for j in 0..D {
        for i in 0..D {
            v[i + D * j] = m.cols[j][i];
        }
    }
    norm_scaled(&v[..D * D])
}

/// Reference-derived scales of one case.
pub(super) struct Scales {
    /// `κ_R` (inf where `m ≤ 0`, NaN for `F = 0`).
    pub(super) kappa_r: f64,
    /// `σ₀`.
    pub(super) sigma0: f64,
    /// `4d·ε·κ_J ≥ 1`.
    pub(super) near_singular: bool,
    /// `κ_K`.
    pub(super) kappa_k: f64,
    /// `s_B`.
    pub(super) s_b: f64,
    /// `σ̂` (J > 0 only).
    pub(super) sigma_hat: Vec<f64>,
    /// `J > 0` (the sign of `∏σ`).
    pub(super) j_positive: bool,
    /// The reference's kernels refused `F` although `J > 0` and `F` is not singular to
    /// working precision (set by the caller): nothing to compare the kernels with.
    pub(super) reference_kernels_failed: bool,
}

pub(super) fn scales<T: Real, const D: usize>(
    f: &Mat<f64, D>,
    sigma: &[f64],
    sigma_hat: Option<&[f64]>,
) -> Scales
where
    Mat<f64, D>: Matrix<Scalar = f64>,
{
    let eps = T::EPSILON.to_f64();
    let s0 = sigma[0].abs();
    let m = sigma[D - 2] + sigma[D - 1];
    let kappa_r = if s0 == 0.0 {
        f64::NAN
    } else if m > 0.0 {
        2.0 * s0 / m
    } else {
        f64::INFINITY
    };
    // Hadamard ratio with the determinant from the reference σ (exact to ~1e-30). It is
    // invariant under F ↦ 2ᵉF: both products are formed after scaling σ and the columns by the
    // power of two of σ₀, so neither over- nor underflows unless the σ themselves span more
    // than the exponent range.
    let e = s0.exponent();
    let j: f64 = sigma.iter().map(|x| libm::scalbn(*x, -e)).product();
    let mut colprod = 1.0;
    for c in &f.cols {
        colprod *= norm_scaled(&c.map(|x| libm::scalbn(x, -e)));
    }
    let kappa_j = if j == 0.0 {
        f64::INFINITY
    } else {
        colprod / j.abs()
    };
    let near_singular = kappa_j.is_nan() || 4.0 * D as f64 * eps * kappa_j >= 1.0;
    let smin = sigma[D - 1].abs();
    let kappa2 = if smin == 0.0 {
        f64::INFINITY
    } else {
        s0 / smin
    };
    let kappa_k = kappa_r.max(kappa2).max(kappa_j);
    let (s_b, sh) = match sigma_hat {
        Some(sh) => {
            let ja = sh[0] / s0;
            let nf: f64 = sh.iter().map(|x| x * x).sum::<f64>().sqrt();
            let nh: f64 = sh.iter().map(|x| 1.0 / (x * x)).sum::<f64>().sqrt();
            (ja * (1.0 + nf * nh / D as f64), sh.to_vec())
        }
        None => (f64::NAN, Vec::new()),
    };
    Scales {
        kappa_r,
        sigma0: s0,
        near_singular,
        kappa_k,
        s_b,
        sigma_hat: sh,
        j_positive: j > 0.0,
        reference_kernels_failed: false,
    }
}
