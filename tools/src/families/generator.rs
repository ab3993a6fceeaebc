//! The generator: the matrices of each family for a precision `T` and a dimension `D`.

use super::integer::{integer_index, integer_indices, integer_matrix};
use super::sampling::{decades, kmax, noise, scale_exp};
use super::under_overflow::product_under_overflow;
use super::{round_to, signed_perm, signed_perm_count, Case, Family, FamilyDim, Size};
use ampm_core::{Mat, Real};
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;

/// The matrices of `family` for precision `T` and dimension `D`, deterministic.
#[must_use]
pub fn generate<T: Real, const D: usize>(family: Family, size: Size) -> Vec<Case<D>>
where
    Mat<f64, D>: FamilyDim,
{
    let seed = 0xa3a0_2014_u64
        ^ ((family as u64) << 8)
        ^ ((D as u64) << 16)
        ^ (u64::from(T::MANTISSA_DIGITS) << 24);
    let mut rng = Pcg64::seed_from_u64(seed);
    let rng = &mut rng;
    let eps = T::EPSILON.to_f64();
    let id = Mat::<f64, D>::identity();
    let nan = f64::NAN;
    let mut out: Vec<Case<D>> = Vec::new();
    let push = |out: &mut Vec<Case<D>>, f: Mat<f64, D>, param: f64| {
        out.push(Case {
            f: round_to::<T, D>(&f),
            param,
            orbit: None,
        });
    };
    let three = |a: f64, b: f64, c: f64| [a, b, c];
    let sig = |s3: [f64; 3], s2: [f64; 2]| -> [f64; 3] {
        if D == 2 {
            [s2[0], s2[1], 0.0]
        } else {
            s3
        }
    };
    match family {
        Family::NearIdentityEps | Family::NearIdentity1e3 => {
            let h = if family == Family::NearIdentityEps {
                256.0 * eps
            } else {
                1e-3
            };
            for _ in 0..size.flat_draws() {
                push(&mut out, id + noise::<D>(rng) * h, nan);
            }
        }
        Family::ScaledIdentity | Family::ScaledRandom => {
            let e = scale_exp::<T>();
            let step = if matches!(size, Size::Reduced) { 5 } else { 1 };
            for k in (-e..=e).step_by(step) {
                let s = 10f64.powi(k);
                if family == Family::ScaledIdentity {
                    push(&mut out, id * s, s);
                } else {
                    for _ in 0..size.draws() {
                        let mut sg = [0.0; 3];
                        for x in &mut sg {
                            *x = (rng.random_range(0.5f64.ln()..2f64.ln())).exp();
                        }
                        push(&mut out, Mat::diag_rot(rng, &sg, true) * s, s);
                    }
                }
            }
        }
        Family::RepeatedSigma => {
            let pats: &[[f64; 3]] = if D == 2 {
                &[[1.0, 1.0, 0.0], [2.0, 2.0, 0.0]]
            } else {
                &[[2.0, 2.0, 1.0], [2.0, 1.0, 1.0], [1.0, 1.0, 1.0]]
            };
            for p in pats {
                push(&mut out, Mat::diag_rot(rng, p, false), nan);
                for _ in 0..size.flat_draws() / pats.len() {
                    push(&mut out, Mat::diag_rot(rng, p, true), nan);
                }
            }
        }
        Family::NearlyRepeatedSigma => {
            for d in decades(kmax::<T>()) {
                for _ in 0..size.draws() {
                    push(
                        &mut out,
                        Mat::diag_rot(rng, &sig(three(1.0 + d, 1.0, 0.5), [1.0 + d, 1.0]), true),
                        d,
                    );
                    push(
                        &mut out,
                        Mat::diag_rot(rng, &sig(three(2.0, 1.0 + d, 1.0), [1.0 + d, 1.0]), true),
                        d,
                    );
                }
            }
        }
        Family::Graded => {
            let s = sig(three(1e4, 1.0, 1e-4), [1e2, 1e-2]);
            push(&mut out, Mat::diag_rot(rng, &s, false), nan);
            for _ in 0..size.flat_draws() {
                push(&mut out, Mat::diag_rot(rng, &s, true), nan);
            }
        }
        Family::TwoSmall | Family::JToZero => {
            for d in decades(kmax::<T>() + 4) {
                let s = if family == Family::TwoSmall {
                    sig(three(1.0, d, d), [1.0, d])
                } else {
                    sig(three(1.0, 1.0, d), [1.0, d])
                };
                push(&mut out, Mat::diag_rot(rng, &s, false), d);
                for _ in 0..size.draws() {
                    push(&mut out, Mat::diag_rot(rng, &s, true), d);
                }
            }
        }
        Family::RankDeficient => {
            let pats: &[[f64; 3]] = if D == 2 {
                &[[1.0, 0.0, 0.0], [0.0, 0.0, 0.0]]
            } else {
                &[[1.0, 0.5, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 0.0]]
            };
            for p in pats {
                push(&mut out, Mat::diag_rot(rng, p, false), nan);
                for _ in 0..size.flat_draws() / pats.len() {
                    push(&mut out, Mat::diag_rot(rng, p, true), nan);
                }
            }
        }
        Family::JNonPositive => {
            for d in decades(kmax::<T>()).chain([0.3]) {
                let s = sig(three(1.0, 0.5, -d), [1.0, -d]);
                push(&mut out, Mat::diag_rot(rng, &s, false), d);
                for _ in 0..size.draws() {
                    push(&mut out, Mat::diag_rot(rng, &s, true), d);
                }
            }
        }
        Family::Kink => {
            for d in decades(kmax::<T>()) {
                let s = sig(three(2.0, 1.0, -1.0 + d), [1.0, -1.0 + d]);
                push(&mut out, Mat::diag_rot(rng, &s, false), d);
                for _ in 0..size.draws() {
                    push(&mut out, Mat::diag_rot(rng, &s, true), d);
                }
            }
        }
        Family::Integer | Family::IntegerPerturbed => {
            let perturb = family == Family::IntegerPerturbed;
            if size == Size::Full {
                // Orbit by orbit (see `Case::orbit`): the representative is perturbed and
                // rounded, the members are its exact transforms.
                let n = 5u64.pow((D * D) as u32);
                let ng = signed_perm_count::<D>();
                let group: Vec<(Mat<f64, D>, f64)> = (0..ng)
                    .map(|i| {
                        let p = signed_perm::<D>(i as u8);
                        let det = if D == 2 {
                            p.cols[0][0] * p.cols[1][1] - p.cols[1][0] * p.cols[0][1]
                        } else {
                            let c = &p.cols;
                            c[0][0] * (c[1][1] * c[2][2] - c[1][2] * c[2][1])
                                - c[1][0] * (c[0][1] * c[2][2] - c[0][2] * c[2][1])
                                + c[2][0] * (c[0][1] * c[1][2] - c[0][2] * c[1][1])
                        };
                        (p, det)
                    })
                    .collect();
                let mut seen = vec![false; n as usize];
                for idx in 0..n {
                    if seen[idx as usize] {
                        continue;
                    }
                    seen[idx as usize] = true;
                    let int = integer_matrix::<D>(idx);
                    let mut rep = int;
                    if perturb {
                        rep += noise::<D>(rng) * (256.0 * eps);
                    }
                    let rep = round_to::<T, D>(&rep);
                    let rep_index = out.len() as u32;
                    out.push(Case {
                        f: rep,
                        param: nan,
                        orbit: None,
                    });
                    for (pi, (p, dp)) in group.iter().enumerate() {
                        for (qi, (q, dq)) in group.iter().enumerate() {
                            if dp * dq < 0.0 {
                                continue;
                            }
                            let k = integer_index::<D>(&(*p * int * *q)) as usize;
                            if seen[k] {
                                continue;
                            }
                            seen[k] = true;
                            out.push(Case {
                                f: *p * rep * *q,
                                param: nan,
                                orbit: Some((rep_index, pi as u8, qi as u8)),
                            });
                        }
                    }
                }
            } else {
                for idx in integer_indices::<D>(size, rng) {
                    let mut f = integer_matrix::<D>(idx);
                    if perturb {
                        f += noise::<D>(rng) * (256.0 * eps);
                    }
                    push(&mut out, f, nan);
                }
            }
        }
        Family::HaarLogUniform => {
            let (lo, hi) = (1e-4f64.ln(), 1e4f64.ln());
            for _ in 0..size.flat_draws() {
                let mut s = [0.0; 3];
                for x in &mut s {
                    *x = rng.random_range(lo..hi).exp();
                }
                push(&mut out, Mat::diag_rot(rng, &s, true), nan);
            }
        }
        Family::Subnormal => {
            // Subnormal scales of T: 2^(emin − 1 − j·(p/4)).
            let emin = T::MIN_POSITIVE.exponent();
            let p = T::MANTISSA_DIGITS as i32;
            for j in 1..4 {
                let s = 1f64 * 2f64.powi(emin - 1 - j * p / 4);
                push(&mut out, id * s, s);
                for _ in 0..size.draws() {
                    let mut sg = [0.0; 3];
                    for x in &mut sg {
                        *x = (rng.random_range(0.5f64.ln()..2f64.ln())).exp();
                    }
                    push(&mut out, Mat::diag_rot(rng, &sg, true) * s, s);
                    let mut g = id;
                    g.cols[1][0] = s * rng.random_range(-1.0..1.0);
                    g.cols[0][D - 1] = s * rng.random_range(-1.0..1.0);
                    push(&mut out, g, s);
                }
            }
        }
        Family::ProductUnderOverflow => {
            for (f, param) in product_under_overflow::<T, D>(size, rng) {
                push(&mut out, f, param);
            }
        }
        Family::NonFinite => {
            for v in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
                for j in 0..D {
                    for i in 0..D {
                        let mut f = id + noise::<D>(rng) * 0.1;
                        f.cols[j][i] = v;
                        push(&mut out, f, nan);
                    }
                }
                push(&mut out, Mat::<f64, D>::ZERO.map(|_| v), nan);
            }
        }
    }
    out
}
