//! The accuracy side of the speed–accuracy chart, from the library's stability module
//! ([`ampm_tools::stability`], errors against the double-double reference): its table, its
//! curves for the stability chart, and the p99 errors that pair with [`crate::methods`]'
//! timings in the speed–accuracy chart.

use crate::charts::{Curve, KernelPoint, Panel, SpeedPoint};
use crate::methods::MethodTiming;
use ampm_tools::families::{Family, Size};
use ampm_tools::stability::{self, HaarP99, MethodSpec, Quantity, Report};

/// Progress-bar steps of [`measure`]: one per family.
pub const STEPS: usize = Family::ALL.len();

/// The quantity on the speed–accuracy chart's y axis: the polar rotation `R`, what a method
/// delivers to the energy (`A = 2μ(F̂ − R)`). On this family the kernels' own errors (`Â`,
/// `Ĉ:Z`) are dominated by the conditioning of `J` and `F⁻ᵀ` (σ spans 8 decades), the same
/// for every method, so they would not tell the methods apart; the table lists them too.
pub const CHART_QUANTITY: Quantity = Quantity::R;

/// The stability chart's panels: family (with a parameter), quantity, dimension. `J → 0⁺`
/// and the scale family measure the kernels (`J > 0`); at the kink (`J ≤ 0`) the kernels
/// refuse, so the panel shows the polar rotation, whose condition `2σ₀/(σ₁+σ₂)` blows up.
const PANELS: [(Family, Quantity, usize); 6] = [
    (Family::JToZero, Quantity::Ahat, 3),
    (Family::Kink, Quantity::R, 3),
    (Family::ScaledRandom, Quantity::Ahat, 3),
    (Family::NearlyRepeatedSigma, Quantity::R, 3),
    (Family::JToZero, Quantity::Ahat, 2),
    (Family::Kink, Quantity::R, 2),
];

/// What the methods table and the speed–accuracy chart show.
pub const METHODS_NOTE: &str = "Time per particle (median, one core) of Â + Ĉ:Z with each \
     SVD method, and of the SVD alone, over the family \"Haar, log-uniform σ\" (σᵢ in \
     [1e-4, 1e4], Haar rotations, rounded to the precision); errors: p99 over the same family \
     of the relative error against the double-double reference (the chart shows R).";

/// Display name of a method (`SvdMethod::NAME` → chart legend).
#[must_use]
#[inline]
pub fn display_name(key: &str) -> &str {
    match key {
        "closed-form-2d" => "closed form",
        "one-sided-jacobi" => "one-sided Jacobi",
        "mcadams" => "McAdams",
        "qr" => "implicit QR",
        "higham-noferini" => "Higham–Noferini",
        other => other,
    }
}

/// "McAdams 4", "one-sided Jacobi".
fn display_spec(m: &MethodSpec) -> String {
    match m.sweeps {
        Some(s) => format!("{} {s}", display_name(m.key)),
        None => display_name(m.key).to_string(),
    }
}

/// Everything the report takes from the stability module.
#[derive(Clone, Debug)]
pub struct Accuracy {
    /// The family size the measurement ran at.
    pub size: Size,
    /// `docs/stability-table.md`.
    pub table_md: String,
    /// Contract violations found (as the stability module reports them).
    pub violations: Vec<String>,
    /// The stability chart, one panel per family × quantity × dimension.
    pub panels: Vec<Panel>,
    /// The stability chart's y axis.
    pub y_desc: String,
    /// p99 errors on the Haar log-uniform family, for the speed–accuracy chart.
    pub p99: Vec<HaarP99>,
}

/// Runs the stability measurement family by family (one progress step each).
#[inline]
#[must_use]
pub fn measure(size: Size, mut progress: impl FnMut()) -> Accuracy {
    let mut report = Report {
        size,
        cells: Vec::new(),
    };
    for fam in Family::ALL {
        report
            .cells
            .extend(stability::run_families(size, &[fam]).cells);
        progress();
    }
    let panels = PANELS
        .iter()
        .map(|&(fam, q, dim)| Panel {
            title: format!("{} ({dim}D): {}", fam.name(), q.name()),
            x_desc: fam.param_desc().unwrap_or("parameter").to_string(),
            curves: stability::curves(&report, fam, q, dim)
                .into_iter()
                .map(|(name, points)| to_curve(&report, &name, points))
                .collect(),
        })
        .collect();
    Accuracy {
        size,
        table_md: stability::table_markdown(&report),
        violations: report.violations(),
        panels,
        y_desc: "max relative error vs double-double".into(),
        p99: stability::haar_p99(&report),
    }
}

/// A curve of `stability::curves` (named "`label` `precision`") with its display name.
fn to_curve(report: &Report, name: &str, points: Vec<(f64, f64)>) -> Curve {
    let spec = report
        .cells
        .iter()
        .find(|c| format!("{} {}", c.method.label(), c.precision) == name);
    Curve {
        method: spec.map_or_else(|| name.to_string(), |c| display_spec(&c.method)),
        is_f32: spec.map_or(name.ends_with("f32"), |c| c.precision == "f32"),
        points,
    }
}

/// The p99 errors measured for a timed configuration, if any.
fn p99_of<'a>(t: &MethodTiming, acc: &'a Accuracy) -> Option<&'a HaarP99> {
    acc.p99.iter().find(|p| {
        p.method.key == t.key
            && p.method.sweeps == t.sweeps
            && p.method.dim == t.dim
            && p.precision == t.precision
    })
}

/// Index of `q` in the stability module's per-quantity arrays.
fn qi(q: Quantity) -> usize {
    Quantity::ALL.iter().position(|&x| x == q).unwrap_or(0)
}

/// The methods table: timings and p99 errors.
#[must_use]
#[inline]
pub fn render_methods(timings: &[MethodTiming], acc: &Accuracy) -> String {
    let shown = [
        Quantity::R,
        Quantity::Sigma,
        Quantity::Ahat,
        Quantity::ChatZ,
    ];
    let mut headers = vec![
        "method".to_string(),
        "d".into(),
        "type".into(),
        "ns/particle Â+Ĉ:Z".into(),
        "ns/particle SVD".into(),
    ];
    headers.extend(shown.iter().map(|q| format!("p99 err {}", q.name())));
    let h: Vec<&str> = headers.iter().map(String::as_str).collect();
    let mut t = crate::table::markdown(&h);
    for m in timings {
        let p = p99_of(m, acc);
        let mut row = vec![
            m.label(),
            format!("{}D", m.dim),
            m.precision.to_string(),
            format!("{:.1}", m.ns_kernels),
            format!("{:.1}", m.ns_svd),
        ];
        row.extend(shown.iter().map(|&q| {
            p.and_then(|p| p.raw[qi(q)])
                .map_or("n/a".into(), |e| format!("{e:.1e}"))
        }));
        t.add_row(row);
    }
    crate::table::right_align(&mut t, &[3, 4, 5, 6, 7, 8]);
    t.to_string()
}

/// The points of the speed–accuracy chart: the timed configurations that have an error.
#[must_use]
#[inline]
pub fn speed_points(timings: &[MethodTiming], acc: &Accuracy) -> Vec<SpeedPoint> {
    timings
        .iter()
        .filter_map(|t| {
            Some(SpeedPoint {
                method: t.method.clone(),
                label: format!("{} {}D {}", t.label(), t.dim, t.precision),
                is_f32: t.precision == "f32",
                ns_kernels: t.ns_kernels,
                ns_svd: t.ns_svd,
                p99: p99_of(t, acc)?.raw[qi(CHART_QUANTITY)]?,
            })
        })
        .collect()
}

/// The `SvdMethod::NAME` of the default decomposition of dimension `dim` (the one the fast
/// path runs on lanes): the closed form in 2D, one-sided Jacobi in 3D.
fn default_key(dim: usize) -> &'static str {
    if dim == 2 {
        "closed-form-2d"
    } else {
        "one-sided-jacobi"
    }
}

/// The generic single-particle path with the default decomposition, per dim × precision: its
/// time of `Â + Ĉ:Z` ([`crate::methods`]) and its p99 errors of `Â`, `Ĉ:Z` on the same family
/// (the stability measurement), the comparison points of the chart's lower panel.
#[must_use]
#[inline]
pub fn generic_kernel_points(timings: &[MethodTiming], acc: &Accuracy) -> Vec<KernelPoint> {
    timings
        .iter()
        .filter(|t| t.key == default_key(t.dim) && t.sweeps.is_none())
        .filter_map(|t| {
            let p = p99_of(t, acc)?;
            Some(KernelPoint {
                series: t.method.clone(),
                legend: format!("{} (generic single-particle path)", t.method),
                label: format!("generic {}D {}", t.dim, t.precision),
                is_f32: t.precision == "f32",
                ns: t.ns_kernels,
                p99_ahat: p.raw[qi(Quantity::Ahat)]?,
                p99_chat_z: p.raw[qi(Quantity::ChatZ)]?,
            })
        })
        .collect()
}

/// The generic path's row of the fast-path table: `(ns Â + Ĉ:Z, p99 Â, p99 Ĉ:Z)`.
#[must_use]
#[inline]
pub fn generic_row(
    timings: &[MethodTiming],
    acc: &Accuracy,
    dim: usize,
    precision: &str,
) -> Option<(f64, Option<f64>, Option<f64>)> {
    let t = timings.iter().find(|t| {
        t.key == default_key(dim) && t.sweeps.is_none() && t.dim == dim && t.precision == precision
    })?;
    let p = p99_of(t, acc);
    Some((
        t.ns_kernels,
        p.and_then(|p| p.raw[qi(Quantity::Ahat)]),
        p.and_then(|p| p.raw[qi(Quantity::ChatZ)]),
    ))
}
