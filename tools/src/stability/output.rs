//! The report's outputs: the markdown stability table, the chart's curves, the Haar p99s.

use super::stats::{qi, Report};
use super::{MethodSpec, Quantity};
use crate::families::Family;
use std::fmt::Write as _;

fn fmt_err(x: Option<f64>) -> String {
    match x {
        None => "–".into(),
        Some(0.0) => "0".into(),
        Some(v) if v.is_infinite() => "∞".into(),
        Some(v) if !(1e-2..1e4).contains(&v) => format!("{v:.1e}"),
        Some(v) => format!("{v:.2}"),
    }
}

/// The stability table (markdown): per dim × precision, one row per family × method with the
/// max and p99 error of each quantity in units of `ε·κ` (see the module docs), the statuses of
/// the kernels, and the number of contract violations.
#[must_use]
pub fn table_markdown(report: &Report) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "# Stability of the SVD/polar methods and the kernels\n\n\
         Errors against a double-double reference (`tools/src/reference.rs`), in units of \
         ε·κ (ε of the precision; κ per quantity as defined in `tools/src/stability.rs`: \
         κ_R = 2σ₀/min(σᵢ+σⱼ) for R, 1 for Σ relative to σ₀, κ_K = max(κ_R, σ₀/σ_min, \
         ∏‖fⱼ‖/|J|) for Ψ̂, Â, Ĉ:Z with their scales). \"max / p99\" over the family's \
         matrices; – where not measured (no J > 0, or R not unique); kernel errors of matrices \
         singular to working precision (4d·ε·∏‖fⱼ‖/|J| ≥ 1) are not counted. Statuses: kernels \
         ok / NonPositiveJ / Overflow / NonFinite. Family size: {:?}.\n",
        report.size
    );
    let mut groups: Vec<(usize, &str)> = Vec::new();
    for c in &report.cells {
        if !groups.contains(&(c.method.dim, c.precision)) {
            groups.push((c.method.dim, c.precision));
        }
    }
    for (dim, prec) in groups {
        let _ = writeln!(s, "## {dim}D, {prec}\n");
        let _ = write!(s, "| family | method | n |");
        for q in Quantity::ALL {
            let _ = write!(s, " {} max / p99 |", q.name());
        }
        let _ = writeln!(s, " statuses | violations |");
        let _ = write!(s, "|---|---|---:|");
        for _ in Quantity::ALL {
            let _ = write!(s, "---:|");
        }
        let _ = writeln!(s, "---|---:|");
        for c in report
            .cells
            .iter()
            .filter(|c| c.method.dim == dim && c.precision == prec)
        {
            let _ = write!(
                s,
                "| {} | {} | {} |",
                c.family.name(),
                c.method.label(),
                c.n_cases
            );
            for q in Quantity::ALL {
                let _ = write!(s, " {} / {} |", fmt_err(c.max(q)), fmt_err(c.p99(q, false)));
            }
            let st = c.statuses;
            let _ = writeln!(
                s,
                " {}/{}/{}/{} | {} |",
                st.ok,
                st.non_positive_j,
                st.overflow,
                st.non_finite + st.other,
                c.n_violations
            );
        }
        let _ = writeln!(s);
    }
    s
}

/// Curves for the stability chart: for `family` (one with a parameter), quantity `q` and
/// dimension `dim`, one curve per method × precision, labelled "`method` `precision`", with
/// points `(parameter, max raw relative error over the draws at that parameter)` sorted by
/// parameter. Raw errors (not divided by `ε·κ`) so the growth towards the singular end shows.
#[must_use]
pub fn curves(
    report: &Report,
    family: Family,
    q: Quantity,
    dim: usize,
) -> Vec<(String, Vec<(f64, f64)>)> {
    let qx = qi(q);
    let mut out = Vec::new();
    for c in report
        .cells
        .iter()
        .filter(|c| c.family == family && c.method.dim == dim)
    {
        let mut pts: Vec<(f64, f64)> = Vec::new();
        for ce in &c.points {
            let Some(e) = ce.raw[qx] else { continue };
            if !ce.param.is_finite() {
                continue;
            }
            match pts.iter_mut().find(|p| p.0 == ce.param) {
                Some(p) => p.1 = p.1.max(e),
                None => pts.push((ce.param, e)),
            }
        }
        pts.sort_by(|a, b| a.0.total_cmp(&b.0));
        if !pts.is_empty() {
            out.push((format!("{} {}", c.method.label(), c.precision), pts));
        }
    }
    out
}

/// The p99 errors of one method × dim × precision on the Haar log-uniform family.
#[derive(Clone, Debug, PartialEq)]
pub struct HaarP99 {
    /// The method.
    pub method: MethodSpec,
    /// "f32" or "f64".
    pub precision: &'static str,
    /// p99 raw relative error per quantity (indexed like [`Quantity::ALL`]).
    pub raw: [Option<f64>; 5],
    /// p99 error in units of `ε·κ` per quantity.
    pub units: [Option<f64>; 5],
}

/// Per method × dim × precision, the p99 errors on [`Family::HaarLogUniform`] (for the
/// speed–accuracy chart). Empty if that family was not run.
#[must_use]
pub fn haar_p99(report: &Report) -> Vec<HaarP99> {
    report
        .cells
        .iter()
        .filter(|c| c.family == Family::HaarLogUniform)
        .map(|c| HaarP99 {
            method: c.method,
            precision: c.precision,
            raw: Quantity::ALL.map(|q| c.p99(q, true)),
            units: Quantity::ALL.map(|q| c.p99(q, false)),
        })
        .collect()
}
