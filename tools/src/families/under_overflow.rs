//! The matrices of [`Family::ProductUnderOverflow`]: entries whose squares or products under-
//! or overflow unless the method scales.

use super::{FamilyDim, Size};
use crate::workload::HaarRotation;
use ampm_core::{Mat, Real};
use rand::Rng;
use rand_pcg::Pcg64;

// The docs link this.
#[cfg(doc)]
use super::Family;

/// The matrices of [`Family::ProductUnderOverflow`] (before rounding to `T`) with their
/// parameter: the relative size of the tiny entries (`δ`, `t`), NaN for the scaled matrices.
///
/// Every threshold comes from `T`: with `eₘᵢₙ`, `eₘₐₓ` the exponents of `MIN_POSITIVE` and
/// `MAX` (`x = m·2ᵉ`, `m ∈ [0.5, 1)`) and `p` the mantissa digits, a number of exponent
/// `e ≤ (eₘᵢₙ − 1)/2` has a subnormal square (or zero, from `e ≤ (eₘᵢₙ − p − 1)/2`), and a
/// product of two entries of exponent `> eₘₐₓ/2` overflows.
pub(super) fn product_under_overflow<T: Real, const D: usize>(
    size: Size,
    rng: &mut Pcg64,
) -> Vec<(Mat<f64, D>, f64)>
where
    Mat<f64, D>: FamilyDim,
{
    let full = size == Size::Full;
    let emin = T::MIN_POSITIVE.exponent();
    let emax = T::MAX.exponent();
    let p = T::MANTISSA_DIGITS as i32;
    let min_pos = T::MIN_POSITIVE.to_f64();
    // Largest exponent whose square is subnormal: f32 −63, f64 −511.
    let e_top = (emin - 1) / 2;
    // δ·ε still normal (δ ≈ MIN_POSITIVE/ε): f32 −102, f64 −969.
    let e_bot = emin + p - 1;
    // Exponents of the relative size δ of the tiny entries: δ² subnormal with most of its bits
    // (e_top), with half of them (e_top − p/4), with one to three bits, none or zero around
    // e_top − p/2 (which one depends on c: the methods first scale F by the power of two that
    // brings c to [0.5, 1), where a normalisation by √(x² + y²) is off by up to tens of
    // percent), zero (e_top − p and below), down to e_bot. f32: −63, −69, −72, −73, −74, −87,
    // −94, −102; f64: −511, −524, −534, −535, −536, −564, −766, −969.
    let deltas: Vec<i32> = vec![
        e_top,
        e_top - p / 4,
        e_top - p / 2 + 3,
        e_top - p / 2 + 2,
        e_top - p / 2 + 1,
        e_top - p,
        (e_top - p + e_bot) / 2,
        e_bot,
    ];
    let mantissa = |rng: &mut Pcg64| rng.random_range(0.5..1.0f64);
    let sign = |rng: &mut Pcg64| if rng.random::<bool>() { 1.0 } else { -1.0 };
    let id = Mat::<f64, D>::identity();
    let offdiag: Vec<(usize, usize)> = (0..D)
        .flat_map(|j| (0..D).filter(move |&i| i != j).map(move |i| (i, j)))
        .collect();
    let mut out = Vec::new();

    // c·I + δc·eᵢeⱼᵀ. The closed forms normalise vectors like (F₀₀ − F₁₁, F₀₁ + F₁₀) ≈ (0, δc):
    // after the methods' power-of-two scaling their squared norm is subnormal. c = 1 (also the
    // absolute case), a non-power of two, near √MAX (c² finite, 2c² not) and a small scale at
    // which δc is still normal.
    let cs = [
        1.0,
        0.7,
        0.75 * 2f64.powi(emax / 2),
        0.75 * 2f64.powi(emin / 4),
    ];
    for (ci, &c) in cs.iter().enumerate() {
        for (di, &e) in deltas.iter().enumerate() {
            let delta = mantissa(rng) * 2f64.powi(e);
            if c * delta < min_pos {
                continue;
            }
            // Reduced size: every position and sign at c = 1 for the two δ whose squares keep
            // three bits or fewer after the scaling, and for the smallest δ; one position
            // (cycling) and a random sign otherwise.
            let all = full || (ci == 0 && matches!(di, 2 | 3 | 7));
            for (k, &(i, j)) in offdiag.iter().enumerate() {
                if !all && k != (ci + di) % offdiag.len() {
                    continue;
                }
                let signs: &[f64] = if all { &[1.0, -1.0] } else { &[0.0] };
                for &sg in signs {
                    let sg = if sg == 0.0 { sign(rng) } else { sg };
                    let mut f = id * c;
                    f.cols[j][i] = sg * c * delta;
                    out.push((f, delta));
                }
            }
        }
    }

    // Nearly diagonal: every off-diagonal ±δ·m, on repeated, distinct and (J ≤ 0) negative
    // diagonals; diag(1, …, −1) is also the kink σ₁ + σ₂ = 0.
    let diags: &[[f64; 3]] = if D == 2 {
        &[
            [1.0, 1.0, 0.0],
            [1.0, 0.6, 0.0],
            [1.0, -0.6, 0.0],
            [1.0, -1.0, 0.0],
        ]
    } else {
        &[
            [1.0, 1.0, 1.0],
            [1.0, 1.0, 0.5],
            [1.0, 0.6, 0.3],
            [1.0, 0.6, -0.3],
            [1.0, 1.0, -1.0],
        ]
    };
    for (pi, dg) in diags.iter().enumerate() {
        for (di, &e) in deltas.iter().enumerate() {
            if !full && (pi + di) % 2 == 1 {
                continue;
            }
            for _ in 0..if full { 4 } else { 1 } {
                let mut f = Mat::<f64, D>::from_diagonal(core::array::from_fn(|i| dg[i]));
                for &(i, j) in &offdiag {
                    f.cols[j][i] = sign(rng) * mantissa(rng) * 2f64.powi(e);
                }
                out.push((f, 2f64.powi(e)));
            }
        }
    }

    // s·Q and s·Q diag(σ) Wᵀ, σ log-uniform in [0.5, 2]: products of entries overflow at
    // s ≈ √MAX, every sum of two entries but one would at s ≈ MAX/16; products underflow at
    // s ≈ √MIN_POSITIVE and vanish at s ≈ MIN_POSITIVE/ε.
    let scales = [
        0.75 * 2f64.powi(emax / 2),
        0.9 * 2f64.powi(emax - 4),
        0.75 * 2f64.powi(e_top),
        0.75 * 2f64.powi(e_bot),
    ];
    for s in scales {
        for _ in 0..if full { 8 } else { 1 } {
            let q = <Mat<f64, D> as HaarRotation>::haar(rng);
            out.push((q * s, f64::NAN));
            let mut sg = [0.0; 3];
            for x in &mut sg {
                *x = rng.random_range(0.5f64.ln()..2f64.ln()).exp();
            }
            out.push((Mat::diag_rot(rng, &sg, true) * s, f64::NAN));
        }
    }

    // Entries of size ~1 and of size ~t (random signs and mantissas): products of two small
    // entries underflow. t ≈ 1e-20 (f32), 1e-160 (f64), and t with a zero square. The fixed
    // patterns put the small entries where the methods form their products: a single large
    // entry (a small trailing block), one large column, one large row (orthogonalising the
    // columns leaves columns of size t), a large anti-diagonal, each with both signs of J; then
    // each entry large or small at random.
    for e in [e_top - 3, e_top - p] {
        let t = 2f64.powi(e);
        let patterns: [fn(usize, usize) -> bool; 4] = [
            |i, j| i == 0 && j == 0,
            |_, j| j == 0,
            |i, _| i == 0,
            |i, j| i + j == D - 1,
        ];
        let draws = if full { 200 } else { 8 };
        for k in 0..patterns.len() + draws {
            let mut f = Mat::<f64, D>::ZERO;
            for j in 0..D {
                for i in 0..D {
                    let big = match patterns.get(k) {
                        Some(pat) => pat(i, j),
                        None => rng.random::<bool>(),
                    };
                    f.cols[j][i] = sign(rng) * mantissa(rng) * if big { 1.0 } else { t };
                }
            }
            out.push((f, t));
            if k < patterns.len() {
                // The same with the first column negated: the pattern with either sign of J.
                let mut g = f;
                g.cols[0] = g.cols[0].map(|x| -x);
                out.push((g, t));
            }
        }
    }
    out
}
