//! Issue 2, item 7: time per call and error of every kernel, per dimension and precision.
//!
//! Errors are norm-wise relative, `‖x − x_ref‖₂ / ‖x_ref‖₂` over the entries:
//! - **f64 rows, against central finite differences** (step `h = ε^{1/3}`, `‖Z‖_F = 1`,
//!   entries of `F` in `[0.2, 5]`): truncation `O(h²)` plus rounding `O(ε/h)` makes
//!   `~ε^{2/3} ≈ 4·10⁻¹¹` times a modest condition factor the level of a correct kernel; a
//!   wrong term shows up as an error of order one. References: `𝓑:Z` against the difference
//!   quotient of `F̂(F) = Jᵃ F` along `Z`; `Z:𝓑` against the gradient of `F ↦ Z:F̂(F)`
//!   (difference quotients along every `E_ij`); `Â` against the gradient of `Ψ̂`; `Ĉ:Z` against
//!   the difference quotient of `Â` along `Z`. `Ψ̂` itself has no difference reference.
//! - **f32 rows, against the f64 kernels** on the same, f32-representable inputs (`F`, `Z`
//!   rounded to f32, then widened exactly): the f32 kernel's own rounding error, also shown in
//!   units of `ε₃₂ = 2⁻²³`.

use crate::timing::median_ns_per_particle;
use ampm::AmpmStatus;
use ampm_core::augmented;
use ampm_core::energy::FixedCorotated;
use ampm_core::polar::{DefaultSvd, SvdMethod};
use ampm_core::{Mat, Matrix, Real};
use ampm_tools::workload::{cast_particles, FfiArrays, FfiBatch};
use std::hint::black_box;

/// The kernels of the table.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kernel {
    /// `𝓑:Z`.
    BZ,
    /// `Z:𝓑`.
    ZB,
    /// `Ψ̂`.
    PsiHat,
    /// `Â`.
    AHat,
    /// `Ĉ:Z`.
    ChatZ,
    /// `Â` through the C ABI batch entry point.
    AHatBatch,
    /// `Ĉ:Z` through the C ABI batch entry point.
    ChatZBatch,
}

impl Kernel {
    /// Every kernel, in table order.
    pub const ALL: [Kernel; 7] = [
        Kernel::BZ,
        Kernel::ZB,
        Kernel::PsiHat,
        Kernel::AHat,
        Kernel::ChatZ,
        Kernel::AHatBatch,
        Kernel::ChatZBatch,
    ];

    /// Name in the table.
    #[must_use]
    #[inline]
    pub fn name(self) -> &'static str {
        match self {
            Kernel::BZ => "𝓑:Z",
            Kernel::ZB => "Z:𝓑",
            Kernel::PsiHat => "Ψ̂",
            Kernel::AHat => "Â",
            Kernel::ChatZ => "Ĉ:Z",
            Kernel::AHatBatch => "Â, C batch",
            Kernel::ChatZBatch => "Ĉ:Z, C batch",
        }
    }
}

/// Median and maximum of a sample of errors, and how many particles failed.
#[derive(Clone, Copy, Debug, Default)]
pub struct Stats {
    /// Median.
    pub p50: f64,
    /// Maximum.
    pub max: f64,
    /// Particles for which the kernel (or its reference) returned an error.
    pub failed: usize,
}

impl Stats {
    fn of(mut errs: Vec<f64>, failed: usize) -> Self {
        if errs.is_empty() {
            return Self {
                p50: f64::NAN,
                max: f64::NAN,
                failed,
            };
        }
        errs.sort_by(f64::total_cmp);
        Self {
            p50: errs[errs.len() / 2],
            max: errs[errs.len() - 1],
            failed,
        }
    }
}

/// One row of the table.
#[derive(Clone, Debug)]
pub struct Row {
    /// The kernel.
    pub kernel: Kernel,
    /// 2 or 3.
    pub dim: usize,
    /// "f32" or "f64".
    pub precision: &'static str,
    /// Median time per call (per particle for the batch rows), ns.
    pub ns: f64,
    /// f64 rows: error against central finite differences.
    pub vs_fd: Option<Stats>,
    /// f32 rows: error against the f64 kernel on the same inputs.
    pub vs_f64: Option<Stats>,
    /// Batch rows: every output bitwise equal to the single-particle kernel's.
    pub batch_matches_single: Option<bool>,
}

/// Sizes of the measurement.
#[derive(Clone, Copy, Debug)]
pub struct Config {
    /// Random particles per dimension.
    pub particles: usize,
    /// Timed passes over the batch (the median is reported).
    pub reps: usize,
}

/// Flattens a matrix to `f64` entries.
fn flat<M: Matrix>(m: &M) -> Vec<f64> {
    m.to_array().as_ref().iter().map(|x| x.to_f64()).collect()
}

/// `‖x − r‖₂ / ‖r‖₂`.
fn rel_err(x: &[f64], r: &[f64]) -> f64 {
    let num: f64 = x.iter().zip(r).map(|(a, b)| (a - b) * (a - b)).sum();
    let den: f64 = r.iter().map(|b| b * b).sum();
    (num / den).sqrt()
}

/// The single-particle result of `k` at `(f, z)`, entries widened to `f64`.
fn eval<M: Matrix>(k: Kernel, f: &M, z: &M) -> Option<Vec<f64>>
where
    DefaultSvd: SvdMethod<M>,
{
    let e = FixedCorotated::new(M::Scalar::ONE);
    match k {
        Kernel::BZ => augmented::b_z(f, z).ok().map(|m| flat(&m)),
        Kernel::ZB => augmented::z_b(f, z).ok().map(|m| flat(&m)),
        Kernel::PsiHat => augmented::psi_hat(&e, f).ok().map(|p| vec![p.to_f64()]),
        Kernel::AHat | Kernel::AHatBatch => augmented::ahat(&e, f).ok().map(|m| flat(&m)),
        Kernel::ChatZ | Kernel::ChatZBatch => augmented::chat_z(&e, f, z).ok().map(|m| flat(&m)),
    }
}

/// Central difference `(g(F + hZ) − g(F − hZ)) / 2h` of a matrix-valued `g`, flattened.
fn central<M: Matrix<Scalar = f64>>(
    g: &impl Fn(&M) -> Option<M>,
    f: &M,
    z: &M,
    h: f64,
) -> Option<Vec<f64>> {
    let p = g(&(*f + *z * h))?;
    let m = g(&(*f - *z * h))?;
    Some(flat(&((p - m) * (0.5 / h))))
}

/// Gradient of a scalar `g` by central differences along every `E_ij`, flattened
/// column-major like the kernels' outputs.
fn gradient<M: Matrix<Scalar = f64>>(
    g: &impl Fn(&M) -> Option<f64>,
    f: &M,
    h: f64,
) -> Option<Vec<f64>> {
    let mut out = vec![0.0; M::LEN];
    for j in 0..M::DIM {
        for i in 0..M::DIM {
            let mut e = M::zero();
            e[(i, j)] = h;
            out[i + M::DIM * j] = (g(&(*f + e))? - g(&(*f - e))?) / (2.0 * h);
        }
    }
    Some(out)
}

/// `F̂ = Jᵃ F`, `a = −1/d`, straight from the definition (the reference for `𝓑`).
fn f_hat<M: Matrix<Scalar = f64>>(f: &M) -> Option<M> {
    let j = f.det();
    (j > 0.0).then(|| *f * j.powf(-1.0 / M::DIM as f64))
}

/// The finite-difference reference of `k` at `(f, z)` (`None` for `Ψ̂`, or on failure).
fn fd_reference<M: Matrix<Scalar = f64>>(k: Kernel, f: &M, z: &M) -> Option<Vec<f64>>
where
    DefaultSvd: SvdMethod<M>,
{
    let h = f64::EPSILON.cbrt();
    let e = FixedCorotated::new(1.0);
    match k {
        Kernel::BZ => central(&f_hat::<M>, f, z, h),
        Kernel::ZB => gradient(&|g: &M| f_hat(g).map(|fh| z.ddot(&fh)), f, h),
        Kernel::PsiHat => None,
        Kernel::AHat | Kernel::AHatBatch => gradient(&|g: &M| augmented::psi_hat(&e, g).ok(), f, h),
        Kernel::ChatZ | Kernel::ChatZBatch => {
            central(&|g: &M| augmented::ahat(&e, g).ok(), f, z, h)
        }
    }
}

/// Median ns per call of `k` over the particles.
fn time<M: Matrix + FfiBatch>(k: Kernel, parts: &[(M, M)], reps: usize) -> f64
where
    DefaultSvd: SvdMethod<M>,
{
    let n = parts.len();
    let e = FixedCorotated::new(M::Scalar::ONE);
    match k {
        Kernel::BZ => median_ns_per_particle(n, reps, || {
            for (f, z) in parts {
                let _ = black_box(augmented::b_z(black_box(f), black_box(z)));
            }
        }),
        Kernel::ZB => median_ns_per_particle(n, reps, || {
            for (f, z) in parts {
                let _ = black_box(augmented::z_b(black_box(f), black_box(z)));
            }
        }),
        Kernel::PsiHat => median_ns_per_particle(n, reps, || {
            for (f, _) in parts {
                let _ = black_box(augmented::psi_hat(black_box(&e), black_box(f)));
            }
        }),
        Kernel::AHat => median_ns_per_particle(n, reps, || {
            for (f, _) in parts {
                let _ = black_box(augmented::ahat(black_box(&e), black_box(f)));
            }
        }),
        Kernel::ChatZ => median_ns_per_particle(n, reps, || {
            for (f, z) in parts {
                let _ = black_box(augmented::chat_z(black_box(&e), black_box(f), black_box(z)));
            }
        }),
        Kernel::AHatBatch => {
            let mut a = FfiArrays::new(M::Scalar::ONE, parts);
            median_ns_per_particle(n, reps, || {
                black_box(black_box(&mut a).ahat());
            })
        }
        Kernel::ChatZBatch => {
            let mut a = FfiArrays::new(M::Scalar::ONE, parts);
            median_ns_per_particle(n, reps, || {
                black_box(black_box(&mut a).chat_z());
            })
        }
    }
}

/// Outputs of the C ABI batch call for `k` (a batch kernel), and whether every particle's
/// output equals the single-particle kernel's bit for bit.
fn batch_outputs<M: Matrix + FfiBatch>(k: Kernel, parts: &[(M, M)]) -> (Vec<Option<Vec<f64>>>, bool)
where
    DefaultSvd: SvdMethod<M>,
{
    let mut a = FfiArrays::new(M::Scalar::ONE, parts);
    let (st, _) = if k == Kernel::AHatBatch {
        a.ahat()
    } else {
        a.chat_z()
    };
    let mut same = true;
    let outs = parts
        .iter()
        .enumerate()
        .map(|(i, (f, z))| {
            // A failed particle's output is untouched: take the single kernel's verdict.
            let single = eval(k, f, z);
            let batch = single.as_ref().map(|_| flat(&a.out_mat(i)));
            same &= single == batch;
            batch
        })
        .collect::<Vec<_>>();
    let all_ok = outs.iter().all(Option::is_some);
    // The batch status is AMPM_OK exactly when every single-particle call succeeds.
    (outs, same && ((st == AmpmStatus::AMPM_OK) == all_ok))
}

/// A reference result at `(F, Z)` in f64 (`None` where there is none).
type Reference<'a, const D: usize> = dyn Fn(&Mat<f64, D>, &Mat<f64, D>) -> Option<Vec<f64>> + 'a;

/// The rows of one dimension × precision, measured on `parts` (drawn in f64, rounded to `T`).
#[inline]
#[must_use]
pub fn measure<T: Real, const D: usize>(
    cfg: Config,
    parts64: &[(Mat<f64, D>, Mat<f64, D>)],
    mut progress: impl FnMut(),
) -> Vec<Row>
where
    Mat<T, D>: Matrix<Scalar = T> + FfiBatch,
    Mat<f64, D>: Matrix<Scalar = f64> + FfiBatch,
    DefaultSvd: SvdMethod<Mat<T, D>> + SvdMethod<Mat<f64, D>>,
{
    let parts = cast_particles::<T, D>(parts64);
    // The same inputs, widened exactly: the f64 comparison run and the FD base points.
    let wide: Vec<(Mat<f64, D>, Mat<f64, D>)> =
        parts.iter().map(|(f, z)| (f.cast(), z.cast())).collect();
    let is_f64 = T::MANTISSA_DIGITS == f64::MANTISSA_DIGITS;
    Kernel::ALL
        .iter()
        .map(|&k| {
            let ns = time(k, &parts, cfg.reps);
            let (outs, same) = match k {
                Kernel::AHatBatch | Kernel::ChatZBatch => {
                    let (o, s) = batch_outputs(k, &parts);
                    (o, Some(s))
                }
                _ => (parts.iter().map(|(f, z)| eval(k, f, z)).collect(), None),
            };
            let compare = |reference: &Reference<'_, D>| {
                let mut errs = Vec::with_capacity(outs.len());
                let mut failed = 0;
                for (o, (f, z)) in outs.iter().zip(&wide) {
                    match (o, reference(f, z)) {
                        (Some(x), Some(r)) => errs.push(rel_err(x, &r)),
                        _ => failed += 1,
                    }
                }
                Stats::of(errs, failed)
            };
            let (vs_fd, vs_f64) = if is_f64 {
                let fd = (k != Kernel::PsiHat).then(|| compare(&|f, z| fd_reference(k, f, z)));
                (fd, None)
            } else {
                (None, Some(compare(&|f, z| eval(k, f, z))))
            };
            progress();
            Row {
                kernel: k,
                dim: D,
                precision: T::NAME,
                ns,
                vs_fd,
                vs_f64,
                batch_matches_single: same,
            }
        })
        .collect()
}

/// Formats an error statistic: `1.2e-11`, with `(3.4ε)` in units of f32's ε when asked.
fn fmt_err(x: f64, in_eps32: bool) -> String {
    if x.is_nan() {
        return "n/a".into();
    }
    if in_eps32 {
        format!("{x:.1e} ({:.1}ε)", x / f64::from(f32::EPSILON))
    } else {
        format!("{x:.1e}")
    }
}

/// The table as aligned markdown.
#[must_use]
#[inline]
pub fn render(rows: &[Row]) -> String {
    let mut t = crate::table::markdown(&[
        "kernel",
        "d",
        "type",
        "ns/call",
        "vs FD, p50",
        "vs FD, max",
        "vs f64, p50",
        "vs f64, max",
        "failed",
    ]);
    for r in rows {
        let dash = || "—".to_string();
        let (fd50, fdmax) = r.vs_fd.map_or((dash(), dash()), |s| {
            (fmt_err(s.p50, false), fmt_err(s.max, false))
        });
        let (w50, wmax) = r.vs_f64.map_or((dash(), dash()), |s| {
            (fmt_err(s.p50, true), fmt_err(s.max, true))
        });
        let failed = r.vs_fd.or(r.vs_f64).map_or(0, |s| s.failed);
        t.add_row(vec![
            r.kernel.name().to_string(),
            format!("{}D", r.dim),
            r.precision.to_string(),
            format!("{:.1}", r.ns),
            fd50,
            fdmax,
            w50,
            wmax,
            failed.to_string(),
        ]);
    }
    crate::table::right_align(&mut t, &[3, 4, 5, 6, 7, 8]);
    t.to_string()
}
