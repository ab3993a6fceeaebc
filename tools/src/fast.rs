//! The fast batch path on every instruction set this CPU supports (`Isa::available()`):
//! `ampm_core::kernel::batch::ahat_chat_z`, Â and Ĉ:Z of fixed corotated Ψ̂ with one
//! decomposition per particle (one-sided Jacobi in 3D, the closed form in 2D, both run on
//! lanes), the kernels behind the C batch calls.
//!
//! Per case (2D/3D × f32/f64) and instruction set:
//! - **time on the chart's family**: median ns per particle over the batch of
//!   [`crate::methods`] (the "Haar, log-uniform σ" matrices, σᵢ in [1e-4, 1e4], rounded to the
//!   precision, with unit directions `Z`), the batch the SVD methods are timed on;
//! - **time on the C benchmark's workload**: the same call on
//!   [`batch_workload`] (the distribution of `c_tests/bench_kernels`, σᵢ in [0.5, 2]), which
//!   is what its hand-written Eigen baseline is timed on;
//! - **errors on the chart's family**: per particle the relative Frobenius error
//!   `‖x − x_ref‖/‖x_ref‖` of Â and of Ĉ:Z against the double-double reference
//!   ([`ampm_tools::reference`], the one the stability measurement uses), differences taken in
//!   double-double; p99 by nearest rank. As in the stability measurement, a particle is left
//!   out when `F` is singular to working precision (`4dε·κ_J ≥ 1`, `κ_J = ∏ⱼ‖F eⱼ‖ / |det F|`
//!   from the reference's σ: no kernel has a correct digit there) or when the reference
//!   kernels refuse it.
//!
//! The fast path's polar rotation `R` is internal to the lane kernels (no per-instruction-set
//! entry point returns it), so its points carry the errors of its outputs, Â and Ĉ:Z, not of
//! `R` like the SVD methods' points.

use crate::bench_c::BenchC;
use crate::charts::KernelPoint;
use crate::timing::median_ns_per_particle;
use ampm_core::kernel::batch::{ahat_chat_z, BatchReal, Outputs};
use ampm_core::kernel::{Dim as LaneDimOf, LaneDim};
use ampm_core::lane::Isa;
use ampm_core::{Mat, Matrix, Real};
use ampm_tools::families::{FamilyDim, Size};
use ampm_tools::reference::{self, Dd, Dim as RefDim, ReferenceDim};
use ampm_tools::workload::{batch_workload, HaarRotation};
use std::hint::black_box;

/// Progress-bar steps of [`measure`]: one per dimension × precision.
pub const STEPS: usize = 4;

/// The fast path on one instruction set for one dimension × precision.
#[derive(Clone, Debug)]
pub struct FastRow {
    /// "scalar", "avx2" or "avx512".
    pub isa: &'static str,
    /// 2 or 3.
    pub dim: usize,
    /// "f32" or "f64".
    pub precision: &'static str,
    /// Median ns per particle of `ahat_chat_z` (both outputs) on the chart's family.
    pub ns_chart: f64,
    /// Particles of the chart's family.
    pub n_chart: usize,
    /// Median ns per particle of the same call on [`batch_workload`].
    pub ns_workload: f64,
    /// Particles of that workload.
    pub n_workload: usize,
    /// Particles of that workload the call refused (expected 0: `J > 0`, finite).
    pub workload_failed: usize,
    /// p99 relative error of Â against the reference.
    pub p99_ahat: Option<f64>,
    /// p99 relative error of Ĉ:Z against the reference.
    pub p99_chat_z: Option<f64>,
    /// Particles whose errors were measured.
    pub compared: usize,
    /// Particles left out (singular to working precision, or refused by the reference).
    pub left_out: usize,
    /// Particles the reference computes (not left out) that the fast path refused.
    pub refused: usize,
    /// Particles whose Â and Ĉ:Z have the same bits as on the widest instruction set.
    pub same_bits_as_widest: usize,
}

/// p99 by nearest rank.
fn p99(mut v: Vec<f64>) -> Option<f64> {
    if v.is_empty() {
        return None;
    }
    v.sort_by(f64::total_cmp);
    let rank = ((v.len() as f64) * 0.99).ceil().max(1.0) as usize;
    Some(v[rank.min(v.len()) - 1])
}

/// `‖x − r‖_F / ‖r‖_F`, `x` one column-major `d×d` record, the difference in double-double.
fn rel_err<T: Real, const D: usize>(x: &[T], r: &Mat<Dd, D>) -> f64 {
    let (mut num, mut den) = (0.0f64, 0.0f64);
    for j in 0..D {
        for i in 0..D {
            let rr = r.cols[j][i];
            let d = (Dd::exact(x[i + D * j].to_f64()) - rr).to_f64();
            let rf = rr.to_f64();
            num += d * d;
            den += rf * rf;
        }
    }
    num.sqrt() / den.sqrt().max(f64::MIN_POSITIVE)
}

/// `4dε·κ_J ≥ 1` with `κ_J = ∏ⱼ‖F eⱼ‖ / ∏ᵢ|σᵢ|` (logarithms: no overflow), the criterion of
/// the stability measurement for "singular to working precision".
fn near_singular<T: Real, const D: usize>(f: &Mat<f64, D>, sigma: &[f64]) -> bool {
    let log_cols: f64 = f
        .cols
        .iter()
        .map(|c| c.iter().map(|x| x * x).sum::<f64>().sqrt().ln())
        .sum();
    let log_j: f64 = sigma.iter().map(|s| s.abs().ln()).sum();
    let kappa_j = (log_cols - log_j).exp();
    // NaN (0/0, inf/inf) counts as singular, as in the stability measurement.
    kappa_j.is_nan() || 4.0 * D as f64 * T::EPSILON.to_f64() * kappa_j >= 1.0
}

/// `Â` and `Ĉ:Z` of every particle on `isa`; NaN where the call refused a particle (a refused
/// particle's outputs are left untouched).
fn run<T: BatchReal, const D: usize>(isa: Isa, mu: &[T], f: &[T], z: &[T]) -> (Vec<T>, Vec<T>)
where
    LaneDimOf<D>: LaneDim<D>,
{
    let nan = T::from_f64(f64::NAN);
    let mut a = vec![nan; f.len()];
    let mut c = vec![nan; f.len()];
    let out = Outputs {
        ahat: Some(&mut a[..]),
        chat_z: Some(&mut c[..]),
        ..Outputs::default()
    };
    // Length errors are impossible here (the slices are built together).
    let _ = ahat_chat_z::<T, D>(isa, mu, f, Some(z), out);
    (a, c)
}

/// Median ns per particle of `ahat_chat_z` with both outputs on `isa`.
fn time<T: BatchReal, const D: usize>(isa: Isa, mu: &[T], f: &[T], z: &[T], reps: usize) -> f64
where
    LaneDimOf<D>: LaneDim<D>,
{
    let mut a = vec![T::ZERO; f.len()];
    let mut c = vec![T::ZERO; f.len()];
    median_ns_per_particle(mu.len(), reps, || {
        let out = Outputs {
            ahat: Some(&mut a[..]),
            chat_z: Some(&mut c[..]),
            ..Outputs::default()
        };
        let _ = black_box(ahat_chat_z::<T, D>(
            isa,
            black_box(mu),
            black_box(f),
            Some(black_box(z)),
            out,
        ));
    })
}

/// Every instruction set for one dimension × precision.
fn measure_case<T: BatchReal, const D: usize>(
    size: Size,
    reps: usize,
    n_workload: usize,
) -> Vec<FastRow>
where
    LaneDimOf<D>: LaneDim<D>,
    RefDim<D>: ReferenceDim<M = Mat<Dd, D>>,
    Mat<f64, D>: FamilyDim + HaarRotation,
    Mat<T, D>: Matrix<Scalar = T>,
    Mat<Dd, D>: Matrix<Scalar = Dd, Vector = [Dd; D]>,
{
    let e = D * D;
    let parts = crate::methods::batch::<T, D>(size);
    let n = parts.len();
    let mu = vec![T::ONE; n];
    let (mut f, mut z) = (Vec::with_capacity(n * e), Vec::with_capacity(n * e));
    for (fi, zi) in &parts {
        f.extend_from_slice(fi.to_array().as_ref());
        z.extend_from_slice(zi.to_array().as_ref());
    }
    // The reference Â and Ĉ:Z of each particle that is measured (μ = 1 as in `mu`); the
    // inputs are exactly representable in T, so widening them to f64 is exact.
    let refs: Vec<Option<(Mat<Dd, D>, Mat<Dd, D>)>> = parts
        .iter()
        .map(|(fi, zi)| {
            let (f64_, z64) = (fi.cast::<f64>(), zi.cast::<f64>());
            let rf = reference::reference::<D>(1.0, &f64_, &z64).ok()?;
            let sigma: Vec<f64> = rf.svd.sigma.iter().map(|s| s.to_f64()).collect();
            if near_singular::<T, D>(&f64_, &sigma) {
                return None;
            }
            let k = rf.kernels?;
            Some((k.ahat.ok()?, k.chat_z.ok()?))
        })
        .collect();
    let left_out = refs.iter().filter(|r| r.is_none()).count();

    let (wmu, wf, wz) = batch_workload::<T, D>(n_workload, 0xbe4c_0000 + D as u64);
    let isas = Isa::available();
    let outputs: Vec<(Vec<T>, Vec<T>)> =
        isas.iter().map(|&i| run::<T, D>(i, &mu, &f, &z)).collect();
    let widest = outputs.last().cloned().unwrap_or_default();
    let bits = |x: &[T]| -> Vec<u64> { x.iter().map(|v| v.to_f64().to_bits()).collect() };
    let (wa, wc) = (bits(&widest.0), bits(&widest.1));

    isas.iter()
        .zip(&outputs)
        .map(|(&isa, (a, c))| {
            let (mut ea, mut ec) = (Vec::new(), Vec::new());
            let mut refused = 0;
            for (p, r) in refs.iter().enumerate() {
                let Some((ar, cr)) = r else { continue };
                let (xa, xc) = (&a[p * e..(p + 1) * e], &c[p * e..(p + 1) * e]);
                if xa.iter().chain(xc).any(|v| v.to_f64().is_nan()) {
                    refused += 1;
                    continue;
                }
                ea.push(rel_err::<T, D>(xa, ar));
                ec.push(rel_err::<T, D>(xc, cr));
            }
            let (ba, bc) = (bits(a), bits(c));
            let same_bits_as_widest = (0..n)
                .filter(|&p| {
                    let s = p * e..(p + 1) * e;
                    ba[s.clone()] == wa[s.clone()] && bc[s.clone()] == wc[s]
                })
                .count();
            let compared = ea.len();
            // The workload is J > 0 and finite throughout: any refusal is worth a look.
            let (xa, _) = run::<T, D>(isa, &wmu, &wf, &wz);
            let workload_failed = xa
                .chunks(e)
                .filter(|m| m.iter().any(|v| v.to_f64().is_nan()))
                .count();
            FastRow {
                isa: isa.name(),
                dim: D,
                precision: T::NAME,
                ns_chart: time::<T, D>(isa, &mu, &f, &z, reps),
                n_chart: n,
                ns_workload: time::<T, D>(isa, &wmu, &wf, &wz, reps),
                n_workload,
                workload_failed,
                p99_ahat: p99(ea),
                p99_chat_z: p99(ec),
                compared,
                left_out,
                refused,
                same_bits_as_widest,
            }
        })
        .collect()
}

/// Every dimension × precision × instruction set, calling `progress` after each case.
/// `n_workload`: particles of the C benchmark's workload to time on.
#[must_use]
pub fn measure(
    size: Size,
    reps: usize,
    n_workload: usize,
    mut progress: impl FnMut(),
) -> Vec<FastRow> {
    let mut out = measure_case::<f32, 2>(size, reps, n_workload);
    progress();
    out.extend(measure_case::<f64, 2>(size, reps, n_workload));
    progress();
    out.extend(measure_case::<f32, 3>(size, reps, n_workload));
    progress();
    out.extend(measure_case::<f64, 3>(size, reps, n_workload));
    progress();
    out
}

/// The chart's lower-panel points of the fast path (its time on the chart's family).
#[must_use]
pub fn kernel_points(rows: &[FastRow]) -> Vec<KernelPoint> {
    rows.iter()
        .filter_map(|r| {
            Some(KernelPoint {
                series: format!("fast {}", r.isa),
                legend: format!("fast batch path, {}", r.isa),
                label: format!("fast {} {}D {}", r.isa, r.dim, r.precision),
                is_f32: r.precision == "f32",
                ns: r.ns_chart,
                p99_ahat: r.p99_ahat?,
                p99_chat_z: r.p99_chat_z?,
            })
        })
        .collect()
}

/// `1.2e-7`, or "n/a".
fn fmt_err(x: Option<f64>) -> String {
    x.map_or("n/a".into(), |e| format!("{e:.1e}"))
}

/// ns with three significant digits at most one decimal: `7.26`, `73.1`, `1344`.
fn fmt_ns(ns: f64) -> String {
    if ns < 10.0 {
        format!("{ns:.2}")
    } else if ns < 100.0 {
        format!("{ns:.1}")
    } else {
        format!("{ns:.0}")
    }
}

/// The fast-path table: per case and instruction set the two times and the errors, with the
/// generic single-particle path (`generic(dim, precision)`: its time and p99 errors on the
/// chart's family) for comparison.
#[must_use]
pub fn render(
    rows: &[FastRow],
    generic: impl Fn(usize, &str) -> Option<(f64, Option<f64>, Option<f64>)>,
) -> String {
    let n_workload = rows.first().map_or(0, |r| r.n_workload);
    let ns_workload = format!("ns/particle, σ in [0.5, 2] (N = {n_workload})");
    let mut t = crate::table::markdown(&[
        "case",
        "path",
        "ns/particle, chart family",
        &ns_workload,
        "p99 err Â",
        "p99 err Ĉ:Z",
        "compared",
        "left out",
        "refused",
        "same bits as widest ISA",
    ]);
    let mut cases: Vec<(usize, &str)> = Vec::new();
    for r in rows {
        if !cases.contains(&(r.dim, r.precision)) {
            cases.push((r.dim, r.precision));
        }
    }
    for (dim, prec) in cases {
        let case = format!("{dim}D {prec}");
        for r in rows.iter().filter(|r| r.dim == dim && r.precision == prec) {
            let failed = if r.workload_failed > 0 {
                format!(" ({} refused!)", r.workload_failed)
            } else {
                String::new()
            };
            t.add_row(vec![
                case.clone(),
                format!("fast {}", r.isa),
                fmt_ns(r.ns_chart),
                format!("{}{failed}", fmt_ns(r.ns_workload)),
                fmt_err(r.p99_ahat),
                fmt_err(r.p99_chat_z),
                r.compared.to_string(),
                r.left_out.to_string(),
                r.refused.to_string(),
                format!("{} / {}", r.same_bits_as_widest, r.n_chart),
            ]);
        }
        if let Some((ns, a, c)) = generic(dim, prec) {
            let method = if dim == 2 {
                "closed form"
            } else {
                "one-sided Jacobi"
            };
            t.add_row(vec![
                case.clone(),
                format!("generic ({method})"),
                fmt_ns(ns),
                "—".into(),
                fmt_err(a),
                fmt_err(c),
                "—".into(),
                "—".into(),
                "—".into(),
                "—".into(),
            ]);
        }
    }
    crate::table::right_align(&mut t, &[2, 3, 4, 5, 6, 7, 8, 9]);
    t.to_string()
}

/// The "fast path vs Eigen" table: per case the fast path's time on the C benchmark's
/// workload per instruction set, the same program's `ampm_ahat_chat_z_batch` and Eigen times,
/// and the ratios Eigen / fast path.
#[must_use]
pub fn render_vs_eigen(rows: &[FastRow], bench: &BenchC) -> String {
    let mut isas: Vec<&str> = Vec::new();
    for r in rows {
        if !isas.contains(&r.isa) {
            isas.push(r.isa);
        }
    }
    let mut headers: Vec<String> = vec!["case".into()];
    headers.extend(isas.iter().map(|i| format!("fast {i}, ns")));
    headers.push("bench_kernels: combined, ns".into());
    headers.push("bench_kernels: Eigen, ns".into());
    headers.extend(isas.iter().map(|i| format!("Eigen / fast {i}")));
    let h: Vec<&str> = headers.iter().map(String::as_str).collect();
    let mut t = crate::table::markdown(&h);
    for (dim, prec) in [(3, "f32"), (3, "f64"), (2, "f32"), (2, "f64")] {
        let mine: Vec<Option<&FastRow>> = isas
            .iter()
            .map(|i| {
                rows.iter()
                    .find(|r| r.dim == dim && r.precision == prec && r.isa == *i)
            })
            .collect();
        let b = bench.row(dim, prec);
        let mut row = vec![format!("{dim}D {prec}")];
        row.extend(
            mine.iter()
                .map(|r| r.map_or("—".into(), |r| fmt_ns(r.ns_workload))),
        );
        row.push(b.map_or("—".into(), |b| fmt_ns(b.combined)));
        row.push(b.map_or("—".into(), |b| fmt_ns(b.eigen)));
        row.extend(mine.iter().map(|r| match (r, b) {
            (Some(r), Some(b)) => format!("{:.1}", b.eigen / r.ns_workload),
            _ => "—".into(),
        }));
        t.add_row(row);
    }
    let n = headers.len();
    crate::table::right_align(&mut t, &(1..n).collect::<Vec<_>>());
    t.to_string()
}
