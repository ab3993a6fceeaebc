//! Issue 3, the speed side of the speed–accuracy chart: what each SVD method costs.
//!
//! Two times per method × sweeps × dim × precision, per particle over a batch on one core:
//! what users pay, `Â` and `Ĉ:Z` of fixed corotated with that method
//! (`FixedCorotated::with_method` + one `Augmented` per particle, which decomposes `F̂` once),
//! and the SVD of `F` alone. The batch is the family the chart's errors are measured on
//! ([`Family::HaarLogUniform`], rounded to the precision), so both coordinates of a point
//! come from the same matrices; the iterative methods' cost depends on the conditioning.

use crate::timing::median_ns_per_particle;
use ampm_core::augmented::Augmented;
use ampm_core::energy::FixedCorotated;
use ampm_core::polar::{ClosedForm2, HighamNoferini, McAdams, OneSidedJacobi, QrSvd, SvdMethod};
use ampm_core::{Mat, Matrix, Real};
use ampm_tools::families::{generate, Family, FamilyDim, Size};
use ampm_tools::stability::MCADAMS_SWEEPS;
use ampm_tools::workload::{random_direction, rng, HaarRotation};
use std::hint::black_box;

/// The cost of one method configuration.
#[derive(Clone, Debug)]
pub struct MethodTiming {
    /// Method family, e.g. "McAdams" (one color in the chart).
    pub method: String,
    /// Sweep count, for the methods that take one.
    pub sweeps: Option<u32>,
    /// 2 or 3.
    pub dim: usize,
    /// "f32" or "f64".
    pub precision: &'static str,
    /// `SvdMethod::NAME` of the method (the key the accuracy measurement uses too).
    pub key: &'static str,
    /// Median ns per particle of `Â + Ĉ:Z`.
    pub ns_kernels: f64,
    /// Median ns per particle of the SVD alone.
    pub ns_svd: f64,
}

impl MethodTiming {
    /// "McAdams 4" or "one-sided Jacobi".
    #[must_use]
    #[inline]
    pub fn label(&self) -> String {
        match self.sweeps {
            Some(s) => format!("{} {s}", self.method),
            None => self.method.clone(),
        }
    }
}

/// Times one method on the particles (already in precision `T`).
fn time_method<T: Real, const D: usize, S: SvdMethod<Mat<T, D>>>(
    sweeps: Option<u32>,
    method: S,
    parts: &[(Mat<T, D>, Mat<T, D>)],
    reps: usize,
) -> MethodTiming
where
    Mat<T, D>: Matrix<Scalar = T>,
{
    let n = parts.len();
    let e = FixedCorotated::with_method(T::ONE, method);
    let ns_kernels = median_ns_per_particle(n, reps, || {
        for (f, z) in parts {
            if let Ok(st) = Augmented::new(black_box(&e), black_box(f)) {
                let _ = black_box(st.ahat());
                let _ = black_box(st.chat_z(black_box(z)));
            }
        }
    });
    let ns_svd = median_ns_per_particle(n, reps, || {
        for (f, _) in parts {
            let _ = black_box(black_box(&method).svd(black_box(f)));
        }
    });
    MethodTiming {
        method: crate::accuracy::display_name(S::NAME).to_string(),
        sweeps,
        dim: D,
        precision: T::NAME,
        key: S::NAME,
        ns_kernels,
        ns_svd,
    }
}

/// Number of configurations [`measure`] times per precision (for the progress bar).
pub const CONFIGS: usize = 4 + MCADAMS_SWEEPS.len();

/// The timing batch of dimension `D` in precision `T`: the family's matrices (exactly
/// representable in `T`) with seeded unit directions `Z`.
pub(crate) fn batch<T: Real, const D: usize>(size: Size) -> Vec<(Mat<T, D>, Mat<T, D>)>
where
    Mat<f64, D>: FamilyDim + HaarRotation,
{
    let mut r = rng(100 + D as u64);
    generate::<T, D>(Family::HaarLogUniform, size)
        .iter()
        .map(|c| {
            let z = random_direction::<Mat<f64, D>>(&mut r);
            (c.f.cast(), z.cast())
        })
        .collect()
}

/// Times every method configuration in precision `T`, calling `progress` after each.
#[inline]
#[must_use]
pub fn measure<T: Real>(size: Size, reps: usize, mut progress: impl FnMut()) -> Vec<MethodTiming> {
    let q2 = batch::<T, 2>(size);
    let q3 = batch::<T, 3>(size);
    let mut out = Vec::with_capacity(CONFIGS);
    let mut push = |t: MethodTiming| {
        out.push(t);
        progress();
    };
    push(time_method(None, ClosedForm2, &q2, reps));
    push(time_method(None, OneSidedJacobi::default(), &q3, reps));
    for sweeps in MCADAMS_SWEEPS {
        push(time_method(Some(sweeps), McAdams { sweeps }, &q3, reps));
    }
    push(time_method(None, QrSvd::default(), &q3, reps));
    push(time_method(None, HighamNoferini::default(), &q3, reps));
    out
}
