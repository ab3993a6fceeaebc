//! Statistics: the errors of one case, kernel statuses, log histograms, cells, the report.

use super::{MethodSpec, Quantity};
use crate::families::{Family, Size};

/// Errors of one case: normalised (units of `ε·κ`) and raw relative, `None` where not
/// measured.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CaseErr {
    /// The family parameter of the case (NaN if none).
    pub param: f64,
    /// Errors in units of `ε·κ`, indexed like [`Quantity::ALL`].
    pub err: [Option<f64>; 5],
    /// Raw relative errors, indexed like [`Quantity::ALL`].
    pub raw: [Option<f64>; 5],
}

/// Statuses seen in one cell.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct StatusCounts {
    /// Kernels that returned a result.
    pub ok: usize,
    /// `NonPositiveJ`.
    pub non_positive_j: usize,
    /// `Overflow`.
    pub overflow: usize,
    /// `NonFinite`.
    pub non_finite: usize,
    /// Any other error (`NotConverged`, …): always a violation.
    pub other: usize,
}

/// Streaming statistics of one error measure: count, exact maximum, and a log histogram
/// (50 bins per decade over `[1e-40, 1e40)`, so a quantile is resolved to 4.7 %).
#[derive(Clone, Debug, Default)]
pub struct Stat {
    n: u64,
    zeros: u64,
    max: Option<f64>,
    bins: Vec<u32>,
}

const BINS_PER_DECADE: f64 = 50.0;
const LOG_MIN: f64 = -40.0;
const N_BINS: usize = 4000;

impl Stat {
    fn add(&mut self, x: f64) {
        self.n += 1;
        self.max = Some(self.max.map_or(x, |m| m.max(x)));
        if x <= 0.0 {
            self.zeros += 1;
            return;
        }
        if self.bins.is_empty() {
            self.bins = vec![0; N_BINS];
        }
        let b = ((x.log10() - LOG_MIN) * BINS_PER_DECADE).floor();
        let b = if b.is_nan() {
            N_BINS - 1
        } else {
            b.clamp(0.0, (N_BINS - 1) as f64) as usize
        };
        self.bins[b] += 1;
    }

    /// Number of values.
    #[must_use]
    pub fn count(&self) -> u64 {
        self.n
    }

    /// Exact maximum.
    #[must_use]
    pub fn max(&self) -> Option<f64> {
        self.max
    }

    /// Quantile `p` (nearest rank), as the upper edge of its histogram bin (capped by the
    /// maximum).
    #[must_use]
    pub fn quantile(&self, p: f64) -> Option<f64> {
        if self.n == 0 {
            return None;
        }
        let rank = ((self.n as f64) * p).ceil().max(1.0) as u64;
        if rank <= self.zeros {
            return Some(0.0);
        }
        let mut cum = self.zeros;
        for (b, &c) in self.bins.iter().enumerate() {
            cum += u64::from(c);
            if cum >= rank {
                let edge = 10f64.powf(LOG_MIN + (b as f64 + 1.0) / BINS_PER_DECADE);
                return Some(edge.min(self.max.unwrap_or(edge)));
            }
        }
        self.max
    }
}

/// Results of one method × family × precision.
#[derive(Clone, Debug)]
pub struct Cell {
    /// The method.
    pub method: MethodSpec,
    /// "f32" or "f64".
    pub precision: &'static str,
    /// The family.
    pub family: Family,
    /// Number of matrices.
    pub n_cases: usize,
    /// Errors in units of `ε·κ`, indexed like [`Quantity::ALL`].
    pub err: [Stat; 5],
    /// Raw relative errors, indexed like [`Quantity::ALL`].
    pub raw: [Stat; 5],
    /// Every case's errors, for the families with a parameter (the chart's curves).
    pub points: Vec<CaseErr>,
    /// Kernel statuses (of `Augmented::new`).
    pub statuses: StatusCounts,
    /// Contract violations (the first 8 messages).
    pub violations: Vec<String>,
    /// Number of violations.
    pub n_violations: usize,
}

impl Cell {
    pub(super) fn record(&mut self, ce: CaseErr) {
        self.n_cases += 1;
        for i in 0..5 {
            if let Some(e) = ce.err[i] {
                self.err[i].add(e);
            }
            if let Some(e) = ce.raw[i] {
                self.raw[i].add(e);
            }
        }
        if self.family.param_desc().is_some() {
            self.points.push(ce);
        }
    }

    /// Maximum error of quantity `q` (units of `ε·κ`), `None` if never measured.
    #[must_use]
    pub fn max(&self, q: Quantity) -> Option<f64> {
        self.err[qi(q)].max()
    }

    /// 99th percentile of the error of `q` (units of `ε·κ`; raw relative if `raw`).
    #[must_use]
    pub fn p99(&self, q: Quantity, raw: bool) -> Option<f64> {
        if raw {
            self.raw[qi(q)].quantile(0.99)
        } else {
            self.err[qi(q)].quantile(0.99)
        }
    }
}

pub(super) fn qi(q: Quantity) -> usize {
    Quantity::ALL.iter().position(|&x| x == q).unwrap_or(0)
}

/// Everything measured.
#[derive(Clone, Debug)]
pub struct Report {
    /// The size the families were generated at.
    pub size: Size,
    /// One cell per method × family × precision (× dim, in the method).
    pub cells: Vec<Cell>,
}

impl Report {
    /// Every violation message, prefixed with its cell.
    #[must_use]
    pub fn violations(&self) -> Vec<String> {
        let mut out = Vec::new();
        for c in &self.cells {
            for v in &c.violations {
                out.push(format!(
                    "{} {}D {} / {}: {v}",
                    c.method.label(),
                    c.method.dim,
                    c.precision,
                    c.family.name()
                ));
            }
            if c.n_violations > c.violations.len() {
                out.push(format!(
                    "{} {}D {} / {}: … {} violations in all",
                    c.method.label(),
                    c.method.dim,
                    c.precision,
                    c.family.name(),
                    c.n_violations
                ));
            }
        }
        out
    }
}
