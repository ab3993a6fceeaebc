//! The batch kernels of `ampm_core::kernel` (one math source on scalars, AVX2 and AVX-512
//! lanes), their C entry points, and the McAdams SVD. One test binary; each module covers one
//! concern:
//!
//! 1. `paths`: every instruction set gives the same statuses, identical SIMD bits, a scalar
//!    path within a stated bound, results independent of `n` and position; in place.
//! 2. `c_abi`: the C batch and single-particle calls equal the core calls bit for bit.
//! 3. `prepare`: prepare once, apply many (core and C ABI), refused slots, NULL rules.
//! 4. `accuracy`: against an independent method (the four-term formulas with the QR SVD).
//! 5. `mcadams`: the McAdams SVD.
//!
//! This file holds what the modules share: the family of test matrices, the test batches with
//! their expected statuses, the combined call, and the relative error.
mod accuracy;
mod c_abi;
mod mcadams;
mod paths;
mod prepare;

use ampm_core::kernel::batch::{self, BatchReal, Outputs};
use ampm_core::kernel::{Dim, LaneDim};
use ampm_core::lane::Isa;
use ampm_core::{Error, Mat, Matrix, Real};
use ampm_tools::workload::HaarRotation;
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;

/// `F = R₁ diag(σ) R₂ᵀ`, σ log-uniform in `[lo, hi]` (det F > 0).
fn family<const D: usize>(rng: &mut Pcg64, lo: f64, hi: f64) -> Mat<f64, D>
where
    Mat<f64, D>: Matrix<Scalar = f64, Vector = [f64; D]>,
    Mat<f64, D>: HaarRotation,
{
    let s: [f64; D] = std::array::from_fn(|_| rng.random_range(lo.ln()..hi.ln()).exp());
    <Mat<f64, D>>::haar(rng) * Mat::from_diagonal(s) * <Mat<f64, D>>::haar(rng).transpose()
}

/// One particle of a test batch and what it should give.
#[derive(Clone, Copy, Debug)]
struct Case<T, const D: usize> {
    mu: T,
    f: Mat<T, D>,
    z: Mat<T, D>,
    /// The status the kernels must report (`None`: success).
    expect: Option<Error>,
    /// Only `Z` is invalid (`Â` alone succeeds).
    z_only: bool,
}

impl<T, const D: usize> Case<T, D> {
    /// The status of `Â` alone.
    fn expect_ahat(&self) -> Option<Error> {
        if self.z_only {
            None
        } else {
            self.expect
        }
    }
}

/// `n` particles of the family σ ∈ [0.5, 2] with every kind of invalid input sprinkled in
/// (index-dependent, so each kind lands in different lanes for different `n`).
fn cases<T: Real, const D: usize>(n: usize, seed: u64) -> Vec<Case<T, D>>
where
    Mat<f64, D>: Matrix<Scalar = f64, Vector = [f64; D]> + HaarRotation,
    Mat<T, D>: Matrix<Scalar = T>,
{
    let mut rng = Pcg64::seed_from_u64(seed);
    (0..n)
        .map(|i| {
            let f = family::<D>(&mut rng, 0.5, 2.0).cast::<T>();
            let z = Mat::<f64, D>::from_cols(std::array::from_fn(|_| {
                std::array::from_fn(|_| rng.random_range(-1.0..1.0))
            }))
            .cast::<T>();
            let mu = T::from_f64(rng.random_range(0.5..50.0));
            let mut c = Case {
                mu,
                f,
                z,
                expect: None,
                z_only: false,
            };
            match (i * 7 + seed as usize) % 13 {
                0 => {
                    c.f.cols[1][0] = T::from_f64(f64::NAN);
                    c.expect = Some(Error::NonFinite);
                }
                1 => {
                    // A reflection: one column negated, det F < 0.
                    for x in &mut c.f.cols[0] {
                        *x = -*x;
                    }
                    c.expect = Some(Error::NonPositiveJ);
                }
                2 => {
                    c.mu = T::from_f64(-1.0);
                    c.expect = Some(Error::InvalidArgument);
                }
                3 => {
                    c.mu = T::from_f64(f64::INFINITY);
                    c.expect = Some(Error::NonFinite);
                }
                4 => {
                    c.z.cols[0][0] = T::from_f64(f64::NAN);
                    c.expect = Some(Error::NonFinite);
                    c.z_only = true;
                }
                5 => c.mu = T::ZERO,
                _ => {}
            }
            c
        })
        .collect()
}

/// The combined call on `isa`: `(Â, Ĉ:Z, status)` of every particle (outputs start as a
/// sentinel, so an untouched output is visible).
type Run<T> = (Vec<T>, Vec<T>, batch::BatchStatus);

fn run<T: BatchReal, const D: usize>(isa: Isa, cs: &[Case<T, D>], psd: bool) -> Run<T>
where
    Dim<D>: LaneDim<D>,
{
    let e = D * D;
    let mu: Vec<T> = cs.iter().map(|c| c.mu).collect();
    let f: Vec<T> = cs.iter().flat_map(|c| c.f.cols.concat()).collect();
    let z: Vec<T> = cs.iter().flat_map(|c| c.z.cols.concat()).collect();
    let sentinel = T::from_f64(-7.25);
    let mut a = vec![sentinel; e * cs.len()];
    let mut cz = vec![sentinel; e * cs.len()];
    let st = batch::ahat_chat_z::<T, D>(
        isa,
        &mu,
        &f,
        Some(&z),
        Outputs {
            ahat: Some(&mut a),
            chat_z: Some(&mut cz),
            energy: None,
            psd,
        },
    )
    .expect("lengths");
    (a, cz, st)
}

/// `‖x − y‖_F` over one particle's entries, relative to the natural scale of the kernels on
/// the family (|μ|·(1 + ‖F‖²) for Â, times ‖Z‖ for Ĉ:Z; σ ∈ [0.5, 2] keeps ‖F⁻¹‖ ≤ 2√d).
fn rel<A: Real, B: Real>(x: &[A], y: &[B], scale: f64) -> f64 {
    let d: f64 = x
        .iter()
        .zip(y)
        .map(|(a, b)| (a.to_f64() - b.to_f64()).powi(2))
        .sum();
    d.sqrt() / scale
}
