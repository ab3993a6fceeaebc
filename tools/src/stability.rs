//! Error of each method × family × precision against the double-double reference.
//!
//! For every matrix `F` of every [`Family`] (rounded to the precision `T` under test) the
//! reference ([`crate::reference`]) is computed once in double-double; then every SVD method
//! of the dimension runs in `T`, alone and inside the fixed corotated kernels (`μ = 1`, `Z` a
//! seeded random direction with `‖Z‖_F = 1`), and each result is compared with the reference
//! (differences taken in double-double).
//!
//! # Error measures (units of `ε·κ`, `ε` of `T`)
//!
//! `σ` are the reference's rotation-variant singular values of `F` (only `σ_{d−1}` may be
//! negative), `σ̂ = Jᵃσ` those of `F̂ = JᵃF`, `m = min_{i<j}(σᵢ+σⱼ) = σ_{d−2}+σ_{d−1}`.
//! - **R**: `‖R − R_ref‖_F / (ε κ_R)`, `κ_R = 2σ₀/m` — the polar perturbation bound
//!   `‖ΔR‖_F ≤ 2‖ΔF‖_F/m` (R.-C. Li 1995) applied to a backward error `‖ΔF‖ ~ ε‖F‖`. Not
//!   measured where `m ≤ 0` (at the kink, or rank ≤ d−2, `R` is not unique).
//! - **Σ**: `max |σᵢ − σᵢ,ref| / (ε max(σ₀, MIN_POSITIVE))` — Weyl: singular values are
//!   perfectly conditioned in absolute terms (`κ = 1`); the floor is the subnormal spacing.
//! - For `J > 0`, the kernels, with `κ_K = max(κ_R, σ₀/σ_min, κ_J)`, `κ_J = ∏ⱼ‖fⱼ‖₂/|J|`
//!   (Hadamard ratio: the relative rounding error of `det F` by cofactor expansion, which the
//!   kernels use for `Jᵃ` and `H = F⁻ᵀ`; `σ₀/σ_min` is the condition of `H`), and
//!   `s_B = Jᵃ(1 + |a|‖F‖_F‖F⁻¹‖_F)`, a bound on the operator norm of `Z ↦ Z:𝓑`:
//!   - **Ψ̂**: `|ΔΨ̂| / (ε κ_K · 2μ σ̂₀ (‖σ̂ − 1‖₂ + ε σ̂₀))` — first order, `δΨ̂ = Σ 2μ(σ̂ᵢ−1)δσ̂ᵢ`
//!     with `|δσ̂ᵢ| ≤ εκ_K σ̂₀`; the `ε σ̂₀` term is the second-order `μΣδσ̂ᵢ²` at `F̂ = R̂`.
//!   - **Â**: `‖ΔÂ‖_F / (ε κ_K · 2μ σ̂₀ s_B)` — `Â = A:𝓑`, `‖A‖ = 2μ‖F̂ − R̂‖ ≤ 4√d μ σ̂₀`,
//!     `A` and `𝓑` each with relative error `O(ε κ_K)`.
//!   - **Ĉ:Z**: `‖ΔĈ:Z‖_F / (ε κ_K · 2μ‖Z‖_F s_B² (1 + 2/m̂))` — the base Hessian has norm
//!     `≤ 2μ(1 + 2/m̂)` (`δR` divides by `σ̂ᵢ+σ̂ⱼ`), sandwiched between two 𝓑's; the three
//!     `A`-terms of `Ĉ:Z` are bounded by `O(μ s_B²‖Z‖)` as well (`‖H‖ ≤ s_B/(|a|‖F̂‖)`).
//!
//!   Kernel denominators have the floor `T::MIN_POSITIVE`: below the normal range only absolute
//!   accuracy is promised.
//!
//! Besides these, the raw relative errors (`‖ΔR‖_F`, `max|Δσ|/σ₀`, `‖Δ·‖/‖ref‖`) are kept
//! for the charts.
//!
//! # Contracts checked ([`Report::violations`])
//!
//! Per case, from the family's [`Contract`] and the reference (the sign of `J` is the
//! reference's; a reference SVD that misses [`BOUND_REFERENCE`], or reference kernels that
//! refuse a `J > 0` not singular to working precision, is itself a violation, and what it
//! would be compared with is not measured): decompositions always succeed for finite `F`
//! (finite, `U`, `V` orthonormal to `16ε` per entry with `det = +1`, `|σ|` sorted up to
//! [`SORT_SLACK`]`·ε|σ₀|` plus twice the case's Σ error, only the last negative, `UΣVᵀ = F` to
//! [`BOUND_RECON`]`·ε‖F‖_F`, R and Σ errors within [`bound`]); kernels succeed for `J > 0`
//! with errors within [`bound`], or return an error status only where `F` is singular to
//! working precision (`4d·ε·κ_J ≥ 1`: the rounding error of the computed `det` can reach
//! `|J|`, so `J`, `H` and `σ̂` have no correct digit; `NonPositiveJ` is the usual answer, a
//! noisy `σ̂ᵢ + σ̂ⱼ ≈ 0` may give `Overflow`), or
//! `Overflow` only where the true result is beyond `T::MAX/2`; for `J ≤ 0` they return
//! `NonPositiveJ` (or, singular to working precision, anything finite); non-finite input gives
//! `NonFinite` everywhere.

use crate::families::{generate, signed_perm, Case, Contract, Family, FamilyDim, Size};
use crate::reference::{self, Dd, Dim, ReferenceDim};
use ampm_core::augmented::Augmented;
use ampm_core::energy::FixedCorotated;
use ampm_core::kernel::batch::{self as kbatch, BatchReal};
use ampm_core::kernel::{Dim as KDim, LaneDim};
use ampm_core::lane::{Isa, IsaKind};
use ampm_core::polar::{
    ClosedForm2, HighamNoferini, McAdams, OneSidedJacobi, QrSvd, Svd, SvdMethod,
};
use ampm_core::{Error, Mat, Matrix, Real};
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;
use std::fmt::Write as _;

/// `μ` of the fixed corotated energy in the kernel measurements.
pub const MU: f64 = 1.0;

/// Reconstruction bound `‖UΣVᵀ − F‖_F ≤ BOUND_RECON·ε‖F‖_F` of every method: the backward
/// error of at most ~40 plane rotations (Jacobi or QR sweeps), each `≤ 6ε` relative
/// (Higham, *Accuracy and Stability*, Lemma 19.8), plus the final `UΣVᵀ` product (`≤ 2dε`).
/// McAdams' fixed sweeps leave an off-diagonal that is not a rounding error; its own bound
/// is [`bound`].
pub const BOUND_RECON: f64 = 256.0;

/// Ties in the order of `|σ|` tolerated, in units of `ε|σ₀|`, on top of twice the method's own
/// Σ error at that case: the methods sort by a proxy (the squared column norm in the Jacobi
/// methods, a column norm of `GV` before the QR step in McAdams) computed with a few roundings
/// more or less than the returned `σ`, so nearly equal values may come out of order by a few
/// ulps (harmless: every formula using `σ` is symmetric in equal values). An order violation
/// beyond that would pair a `σ` with the wrong singular vectors.
pub const SORT_SLACK: f64 = 8.0;

/// Accuracy the reference SVD must reach at every case it is used for: `U`, `V` orthonormal to
/// `BOUND_REFERENCE` per entry and `‖UΣVᵀ − F‖_F ≤ BOUND_REFERENCE·max(‖F‖_F, Dd::MIN_POSITIVE)`
/// — the methods' backward-error bound [`BOUND_RECON`] in units of the double-double `ε`
/// (`≈ 1.3e-29`), absolute below the double-double normal range (`2⁻⁹⁶⁹`, where its trailing
/// word is subnormal). An SVD that meets it is the exact SVD of a matrix within `~1e-29‖F‖` of
/// `F`, so it measures any `f64` error to 13 digits. The reference runs the core's own
/// generic methods: where they break (a normalisation of a vector whose squared norm
/// underflows, say) it breaks the same way and would agree with the method under test; this
/// check turns that into a violation instead.
pub const BOUND_REFERENCE: f64 = BOUND_RECON * Dd::EPSILON.hi;

/// The measured quantities.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Quantity {
    /// The polar rotation `R`.
    R,
    /// The singular values.
    Sigma,
    /// `Ψ̂`.
    Psi,
    /// `Â`.
    Ahat,
    /// `Ĉ:Z`.
    ChatZ,
}

impl Quantity {
    /// All quantities, in table order.
    pub const ALL: [Quantity; 5] = [
        Quantity::R,
        Quantity::Sigma,
        Quantity::Psi,
        Quantity::Ahat,
        Quantity::ChatZ,
    ];

    /// Short name.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Quantity::R => "R",
            Quantity::Sigma => "Σ",
            Quantity::Psi => "Ψ̂",
            Quantity::Ahat => "Â",
            Quantity::ChatZ => "Ĉ:Z",
        }
    }
}

/// One method configuration.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct MethodSpec {
    /// `SvdMethod::NAME`.
    pub key: &'static str,
    /// Sweep count, for the methods with a fixed one (McAdams).
    pub sweeps: Option<u32>,
    /// 2 or 3.
    pub dim: usize,
}

impl MethodSpec {
    /// Label for tables and charts, e.g. `mcadams(4)`.
    #[must_use]
    pub fn label(&self) -> String {
        match self.sweeps {
            Some(s) => format!("{}({s})", self.key),
            None => self.key.to_string(),
        }
    }
}

/// Error bound of a method for a quantity, in units of `ε·κ` of the [module docs](self).
///
/// Derivation for the backward-stable methods (one-sided Jacobi, QR, Higham–Noferini, the 2D
/// closed form): their backward error is `≤ BOUND_RECON·ε‖F‖` (see there), hence
/// `‖ΔR‖_F ≤ 2‖ΔF‖_F/m ≤ 2·√d·BOUND_RECON·ε σ₀/m`, i.e. `√d·BOUND_RECON` in units of
/// `ε κ_R`, and `|Δσ| ≤ ‖ΔF‖₂ ≤ √d·BOUND_RECON·ε σ₀` (Weyl). The kernels add a bounded
/// number of products and one `det`, `cbrt` and cofactor matrix, each `O(ε κ_K)` relative
/// (counted in `κ_J`, `σ₀/σ_min`), so the same `√d·BOUND_RECON` in units of `ε κ_K`.
///
/// McAdams (Jacobi on `FᵀF`, approximate rotations, no convergence test): squaring `F` makes
/// every error `O(ε κ²)`, and a fixed sweep count leaves an off-diagonal that is not a
/// rounding error at all; its contract is the structural one only (finite, orthonormal
/// `U, V`, sorted, statuses), and its errors are reported, not bounded: `f64::INFINITY`.
#[must_use]
pub fn bound(method: &MethodSpec, _q: Quantity) -> f64 {
    if method.key == <McAdams as SvdMethod<Mat<f64, 3>>>::NAME {
        f64::INFINITY
    } else {
        (method.dim as f64).sqrt() * BOUND_RECON
    }
}

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
    fn record(&mut self, ce: CaseErr) {
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

fn qi(q: Quantity) -> usize {
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

/// The kernel results of one method at one `F`.
type KernelOut<T, const D: usize> = (
    core::result::Result<T, Error>,
    core::result::Result<Mat<T, D>, Error>,
    core::result::Result<Mat<T, D>, Error>,
);

/// A method, type-erased for the measurement loop.
trait Runner<T: Real, const D: usize>
where
    Mat<T, D>: Matrix,
{
    fn spec(&self) -> MethodSpec;
    fn svd(&self, f: &Mat<T, D>) -> ampm_core::Result<Svd<Mat<T, D>>>;
    fn kernels(&self, f: &Mat<T, D>, z: &Mat<T, D>) -> ampm_core::Result<KernelOut<T, D>>;
}

struct With<S>(S, Option<u32>);

impl<T: Real, const D: usize, S: SvdMethod<Mat<T, D>>> Runner<T, D> for With<S>
where
    Mat<T, D>: Matrix<Scalar = T>,
{
    fn spec(&self) -> MethodSpec {
        MethodSpec {
            key: S::NAME,
            sweeps: self.1,
            dim: D,
        }
    }
    fn svd(&self, f: &Mat<T, D>) -> ampm_core::Result<Svd<Mat<T, D>>> {
        self.0.svd(f)
    }
    fn kernels(&self, f: &Mat<T, D>, z: &Mat<T, D>) -> ampm_core::Result<KernelOut<T, D>> {
        let e = FixedCorotated::with_method(T::from_f64(MU), self.0);
        let st = Augmented::new(&e, f)?;
        Ok((st.psi_hat(), st.ahat(), st.chat_z(z)))
    }
}

/// The fast batch kernels of `ampm_core::kernel` on one instruction set, one particle per call
/// (a padded chunk of lanes): the instantiation the C batch calls run. The decomposition is
/// the default method on lanes; the kernels each run alone, so each has its own status.
struct Fast(Isa, &'static str);

impl<T: BatchReal, const D: usize> Runner<T, D> for Fast
where
    KDim<D>: LaneDim<D>,
    Mat<T, D>: Matrix<Scalar = T, Vector = [T; D]>,
{
    fn spec(&self) -> MethodSpec {
        MethodSpec {
            key: self.1,
            sweeps: None,
            dim: D,
        }
    }
    fn svd(&self, f: &Mat<T, D>) -> ampm_core::Result<Svd<Mat<T, D>>> {
        let mut u = [T::ZERO; 9];
        let mut v = [T::ZERO; 9];
        let mut s = [T::ZERO; 3];
        let st = kbatch::svd::<T, D>(
            self.0,
            &f.cols.concat(),
            &mut u[..D * D],
            &mut s[..D],
            &mut v[..D * D],
        )?;
        st.result().map_err(|e| e.1)?;
        let sigma: [T; D] = s[..D].try_into().expect("D values");
        Ok(Svd {
            u: Mat::from_col_major(&u[..D * D]).expect("d² entries"),
            sigma,
            v: Mat::from_col_major(&v[..D * D]).expect("d² entries"),
        })
    }
    fn kernels(&self, f: &Mat<T, D>, z: &Mat<T, D>) -> ampm_core::Result<KernelOut<T, D>> {
        let mu = [T::from_f64(MU)];
        let (fv, zv) = (f.cols.concat(), z.cols.concat());
        let one = |what: u8| -> ampm_core::Result<Vec<T>> {
            let mut out = vec![T::ZERO; if what == 0 { 1 } else { D * D }];
            let o = match what {
                0 => kbatch::Outputs {
                    energy: Some(&mut out),
                    ..Default::default()
                },
                1 => kbatch::Outputs {
                    ahat: Some(&mut out),
                    ..Default::default()
                },
                _ => kbatch::Outputs {
                    chat_z: Some(&mut out),
                    ..Default::default()
                },
            };
            kbatch::ahat_chat_z::<T, D>(self.0, &mu, &fv, Some(&zv), o)?
                .result()
                .map_err(|e| e.1)?;
            Ok(out)
        };
        let m = |v: Vec<T>| Mat::from_col_major(&v).expect("d² entries");
        let (p, a, c) = (one(0), one(1), one(2));
        // A check that fails for every kernel (F, J, μ) is the call's status, as for the
        // generic runners; per-kernel statuses (overflow) stay per kernel.
        match (&p, &a, &c) {
            (Err(x), Err(y), Err(w)) if x == y && y == w => Err(*x),
            _ => Ok((p.map(|v| v[0]), a.map(m), c.map(m))),
        }
    }
}

/// Scalars with fast batch kernels: the [`Fast`] runner of each instruction set of this CPU.
trait FastPaths<const D: usize>: Real {
    fn fast_runners() -> Vec<Box<dyn Runner<Self, D>>>;
}

macro_rules! fast_paths {
    ($t:ty) => {
        impl<const D: usize> FastPaths<D> for $t
        where
            KDim<D>: LaneDim<D>,
            Mat<$t, D>: Matrix<Scalar = $t, Vector = [$t; D]>,
        {
            fn fast_runners() -> Vec<Box<dyn Runner<$t, D>>> {
                Isa::available()
                    .into_iter()
                    .map(|isa| {
                        let key = match isa.kind() {
                            IsaKind::Scalar => "fast-scalar",
                            IsaKind::Avx2 => "fast-avx2",
                            IsaKind::Avx512 => "fast-avx512",
                        };
                        Box::new(Fast(isa, key)) as Box<dyn Runner<$t, D>>
                    })
                    .collect()
            }
        }
    };
}
fast_paths!(f32);
fast_paths!(f64);

/// The methods of each dimension.
trait MethodsOf<T: Real, const D: usize>
where
    Mat<T, D>: Matrix,
{
    /// The methods; `all_sweeps` adds the McAdams sweep counts other than the default.
    fn methods(all_sweeps: bool) -> Vec<Box<dyn Runner<T, D>>>;
}

impl<T: Real + FastPaths<2>> MethodsOf<T, 2> for Dim<2> {
    fn methods(_all_sweeps: bool) -> Vec<Box<dyn Runner<T, 2>>> {
        let mut v: Vec<Box<dyn Runner<T, 2>>> = vec![Box::new(With(ClosedForm2, None))];
        v.extend(T::fast_runners());
        v
    }
}

/// McAdams sweep counts measured (the range is 2–8): all of them in the reduced size
/// and on the Haar family, the default (4) elsewhere in the full size.
pub const MCADAMS_SWEEPS: [u32; 3] = [2, 4, 8];

impl<T: Real + FastPaths<3>> MethodsOf<T, 3> for Dim<3> {
    fn methods(all_sweeps: bool) -> Vec<Box<dyn Runner<T, 3>>> {
        let mut v: Vec<Box<dyn Runner<T, 3>>> =
            vec![Box::new(With(OneSidedJacobi::default(), None))];
        for s in MCADAMS_SWEEPS {
            if all_sweeps || s == McAdams::default().sweeps {
                v.push(Box::new(With(McAdams { sweeps: s }, Some(s))));
            }
        }
        v.push(Box::new(With(QrSvd::default(), None)));
        v.push(Box::new(With(HighamNoferini::default(), None)));
        v.extend(T::fast_runners());
        v
    }
}

/// `‖a − b‖_F` with the difference taken in double-double (exact to ~1e-32 relative of `b`)
/// and the norm in f64 (relative error ~1e-16 of the distance itself, plenty).
fn dist<T: Real, const D: usize>(a: &Mat<T, D>, b: &Mat<Dd, D>) -> f64 {
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
fn norm_scaled(v: &[f64]) -> f64 {
    let m = v.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    if m == 0.0 || !m.is_finite() {
        return m;
    }
    v.iter().map(|x| (x / m) * (x / m)).sum::<f64>().sqrt() * m
}

/// `‖U diag(σ) Vᵀ − F‖_F`, the products in double-double for f64 (every `uᵢₖσₖ` and the sum
/// exact to ~1e-32), in f64 for f32 input (error ~1e-16, far below the f32 `ε` it is
/// compared with).
fn recon_err<T: Real, const D: usize>(
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

fn norm_dd<const D: usize>(b: &Mat<Dd, D>) -> f64 {
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
struct Scales {
    /// `κ_R` (inf where `m ≤ 0`, NaN for `F = 0`).
    kappa_r: f64,
    /// `σ₀`.
    sigma0: f64,
    /// `4d·ε·κ_J ≥ 1`.
    near_singular: bool,
    /// `κ_K`.
    kappa_k: f64,
    /// `s_B`.
    s_b: f64,
    /// `σ̂` (J > 0 only).
    sigma_hat: Vec<f64>,
    /// `J > 0` (the sign of `∏σ`).
    j_positive: bool,
    /// The reference's kernels refused `F` although `J > 0` and `F` is not singular to
    /// working precision (set by the caller): nothing to compare the kernels with.
    reference_kernels_failed: bool,
}

fn scales<T: Real, const D: usize>(
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

/// Collects violations of one cell.
struct Viol {
    msgs: Vec<String>,
    n: usize,
}

impl Viol {
    fn add(&mut self, f: &Mat<f64, 3>, d: usize, msg: String) {
        self.n += 1;
        if self.msgs.len() < 8 {
            let mut e = String::new();
            for j in 0..d {
                for i in 0..d {
                    let _ = write!(e, "{:e},", f.cols[j][i]);
                }
            }
            self.msgs.push(format!("{msg} at F(col-major)=[{e}]"));
        }
    }
}

fn pad3<const D: usize>(f: &Mat<f64, D>) -> Mat<f64, 3> {
    let mut m = Mat::<f64, 3>::ZERO;
    for j in 0..D {
        for i in 0..D {
            m.cols[j][i] = f.cols[j][i];
        }
    }
    m
}

fn status_of(e: Error, st: &mut StatusCounts) {
    match e {
        Error::NonPositiveJ => st.non_positive_j += 1,
        Error::Overflow => st.overflow += 1,
        Error::NonFinite => st.non_finite += 1,
        _ => st.other += 1,
    }
}

/// Measures one case for one method; appends errors and violations.
#[allow(clippy::too_many_arguments)]
fn measure_case<T: Real, const D: usize>(
    run: &dyn Runner<T, D>,
    contract: Contract,
    case: &Case<D>,
    z64: &Mat<f64, D>,
    rf: &Option<reference::Reference<D>>,
    sc: &Option<Scales>,
    cell: &mut Cell,
    viol: &mut Viol,
) where
    Mat<T, D>: Matrix<Scalar = T, Vector = [T; D]>,
    Mat<f64, D>: Matrix<Scalar = f64>,
    Mat<Dd, D>: Matrix<Scalar = Dd, Vector = [Dd; D]>,
{
    let eps = T::EPSILON.to_f64();
    let tiny = T::MIN_POSITIVE.to_f64();
    let f: Mat<T, D> = case.f.cast::<T>();
    let z: Mat<T, D> = z64.cast::<T>();
    let spec = run.spec();
    let bnd = |q: Quantity| bound(&spec, q);
    let fp = pad3(&case.f);
    let mut ce = CaseErr {
        param: case.param,
        err: [None; 5],
        raw: [None; 5],
    };
    let (rf, sc) = match (contract, rf, sc) {
        (Contract::NonFinite, _, _) | (_, None, _) | (_, _, None) => {
            // Non-finite input: everything must say NonFinite.
            if !matches!(run.svd(&f), Err(Error::NonFinite)) {
                viol.add(
                    &fp,
                    D,
                    "svd of non-finite F did not return NonFinite".into(),
                );
            }
            match run.kernels(&f, &z) {
                Err(e) => status_of(e, &mut cell.statuses),
                Ok(_) => cell.statuses.ok += 1,
            }
            if !matches!(run.kernels(&f, &z), Err(Error::NonFinite)) {
                viol.add(
                    &fp,
                    D,
                    "kernels of non-finite F did not return NonFinite".into(),
                );
            }
            cell.record(ce);
            return;
        }
        (_, Some(r), Some(s)) => (r, s),
    };
    // --- decomposition -----------------------------------------------------------------
    match run.svd(&f) {
        Err(e) => viol.add(&fp, D, format!("svd failed: {e:?}")),
        Ok(svd) => {
            let (u, v) = (svd.u, svd.v);
            let finite = u.is_finite() && v.is_finite() && svd.sigma.iter().all(|x| x.is_finite());
            if !finite {
                viol.add(&fp, D, "svd not finite".into());
            } else {
                let (u64_, v64) = (u.cast::<f64>(), v.cast::<f64>());
                let id = Mat::<f64, D>::identity();
                let ou = (u64_.transpose() * u64_ - id).max_abs();
                let ov = (v64.transpose() * v64 - id).max_abs();
                if ou > 16.0 * eps || ov > 16.0 * eps || u64_.det() < 0.0 || v64.det() < 0.0 {
                    viol.add(&fp, D, format!("U or V not a rotation: {ou:e} {ov:e}"));
                }
                let s: Vec<f64> = svd.sigma.iter().map(|x| x.to_f64()).collect();
                // Σ error against the (sorted) reference.
                let mut ds = 0.0f64;
                for i in 0..D {
                    ds = ds.max((Dd::exact(s[i]) - rf.svd.sigma[i]).abs().to_f64());
                }
                // Sorted up to the method's own Σ error (if |σᵢ| and |σᵢ,ref| differ by at most
                // ds, a sorted reference allows |σᵢ₊₁| − |σᵢ| ≤ 2ds) plus SORT_SLACK·ε|σ₀|.
                let slack = SORT_SLACK * eps * s[0].abs() + 2.0 * ds;
                let sorted = (0..D - 1).all(|i| s[i + 1].abs() - s[i].abs() <= slack);
                let signs = (0..D - 1).all(|i| s[i] >= 0.0);
                if !sorted || !signs {
                    viol.add(&fp, D, format!("σ not rotation-variant: {s:?}"));
                }
                // Reconstruction, relative to ‖F‖_F.
                let nf = {
                    let mut v = [0.0f64; 9];
                    for j in 0..D {
                        for i in 0..D {
                            v[i + D * j] = case.f.cols[j][i];
                        }
                    }
                    norm_scaled(&v[..D * D])
                };
                let rec_err = recon_err(&u, &s, &v, &case.f) / (eps * nf.max(tiny));
                if rec_err > BOUND_RECON && bnd(Quantity::R).is_finite() {
                    viol.add(&fp, D, format!("reconstruction error {rec_err:.3e} ε‖F‖"));
                }
                // Σ.
                let es = ds / (eps * sc.sigma0.max(tiny));
                ce.err[1] = Some(es);
                ce.raw[1] = Some(if sc.sigma0 > 0.0 { ds / sc.sigma0 } else { ds });
                if es > bnd(Quantity::Sigma) {
                    viol.add(&fp, D, format!("Σ error {es:.3e} ε > bound"));
                }
                // R.
                if sc.kappa_r.is_finite() {
                    let dr = dist(&svd.rotation(), &rf.r);
                    let er = dr / (eps * sc.kappa_r);
                    ce.err[0] = Some(er);
                    ce.raw[0] = Some(dr);
                    if er > bnd(Quantity::R) {
                        viol.add(
                            &fp,
                            D,
                            format!("R error {er:.3e} εκ (κ = {:.3e})", sc.kappa_r),
                        );
                    }
                }
            }
        }
    }
    // --- kernels -----------------------------------------------------------------------
    if sc.reference_kernels_failed {
        // Reported once per case by the caller.
        cell.record(ce);
        return;
    }
    let k = run.kernels(&f, &z);
    match &k {
        Err(e) => status_of(*e, &mut cell.statuses),
        Ok(_) => cell.statuses.ok += 1,
    }
    match (&rf.kernels, k) {
        (None, Ok(_)) if !sc.near_singular => {
            viol.add(&fp, D, "kernels accepted J ≤ 0".into());
        }
        (None, Err(e)) if e != Error::NonPositiveJ && !sc.near_singular => {
            viol.add(&fp, D, format!("kernels on J ≤ 0 returned {e:?}"));
        }
        (None, _) => {}
        // Singular to working precision: the computed J, H, σ̂ carry no correct digit, so
        // any status is acceptable (never NaN/inf: the kernels return Result).
        (Some(_), Err(_)) if sc.near_singular => {}
        (Some(_), Err(e)) => viol.add(&fp, D, format!("kernels on J > 0 returned {e:?}")),
        (Some(kr), Ok((psi, ahat, chat))) => {
            // Singular to working precision: any per-kernel status, no bound (still measured).
            let check = !sc.near_singular;
            let mut viol_k = |fp: &Mat<f64, 3>, msg: String| {
                if check {
                    viol.add(fp, D, msg);
                }
            };
            let ek = eps * sc.kappa_k;
            let mu = MU;
            let sh = &sc.sigma_hat;
            let s_hat0 = sh[0];
            let dev: f64 = sh.iter().map(|x| (x - 1.0) * (x - 1.0)).sum::<f64>().sqrt();
            let m_hat = sh[D - 2] + sh[D - 1];
            let allow_overflow = |r: &ampm_core::Result<Mat<Dd, D>>| match r {
                Err(Error::Overflow) => true,
                Ok(m) => m.cast::<f64>().max_abs() >= T::MAX.to_f64() * 0.5,
                Err(_) => false,
            };
            // Ψ̂.
            match (psi, &kr.psi) {
                (Ok(p), Ok(pr)) => {
                    let d = (Dd::exact(p.to_f64()) - *pr).abs().to_f64();
                    let e = d / (ek * 2.0 * mu * s_hat0 * (dev + eps * s_hat0));
                    ce.err[2] = Some(e);
                    ce.raw[2] = Some(d / pr.to_f64().abs().max(f64::MIN_POSITIVE));
                    if e > bnd(Quantity::Psi) {
                        viol_k(
                            &fp,
                            format!("Ψ̂ error {e:.3e} εκ (κ_K = {:.3e})", sc.kappa_k),
                        );
                    }
                }
                (r, rr) => viol_k(&fp, format!("Ψ̂: {r:?} vs reference {rr:?}")),
            }
            // Â.
            match (ahat, &kr.ahat) {
                (Ok(a), Ok(ar)) => {
                    let d = dist(&a, ar);
                    let e = d / (ek * 2.0 * mu * s_hat0 * sc.s_b).max(tiny);
                    ce.err[3] = Some(e);
                    ce.raw[3] = Some(d / norm_dd(ar).max(f64::MIN_POSITIVE));
                    if e > bnd(Quantity::Ahat) {
                        viol_k(
                            &fp,
                            format!("Â error {e:.3e} εκ (κ_K = {:.3e})", sc.kappa_k),
                        );
                    }
                }
                (Err(Error::Overflow), r) if allow_overflow(r) => {}
                (r, rr) => viol_k(&fp, format!("Â: {:?} vs reference {:?}", r.err(), rr.err())),
            }
            // Ĉ:Z.
            match (chat, &kr.chat_z) {
                (Ok(c), Ok(cr)) => {
                    let d = dist(&c, cr);
                    let nz = z64.norm_squared().sqrt();
                    let scale = 2.0 * mu * nz * sc.s_b * sc.s_b * (1.0 + 2.0 / m_hat);
                    let e = d / (ek * scale).max(tiny);
                    ce.err[4] = Some(e);
                    ce.raw[4] = Some(d / norm_dd(cr).max(f64::MIN_POSITIVE));
                    if e > bnd(Quantity::ChatZ) {
                        viol_k(
                            &fp,
                            format!("Ĉ:Z error {e:.3e} εκ (κ_K = {:.3e})", sc.kappa_k),
                        );
                    }
                }
                (Err(Error::Overflow), r) if allow_overflow(r) => {}
                (r, rr) => viol_k(
                    &fp,
                    format!("Ĉ:Z: {:?} vs reference {:?}", r.err(), rr.err()),
                ),
            }
        }
    }
    // Kernel errors of matrices singular to working precision are outside every contract
    // (and would dominate the statistics): not counted.
    if sc.near_singular {
        for i in 2..5 {
            ce.err[i] = None;
            ce.raw[i] = None;
        }
    }
    cell.record(ce);
}

/// The reference at `P F Q` from the one at `F` (`P`, `Q` signed permutations,
/// `det P · det Q = +1`, `Z ↦ P Z Q`): `U ↦ sPU`, `V ↦ sQᵀV` (`s = det P`, so both stay
/// rotations), `σ`, `σ̂`, `Ψ̂` unchanged, `R ↦ PRQ`, `Â ↦ PÂQ`, `Ĉ:Z ↦ P(Ĉ:Z)Q` (isotropy and
/// frame indifference of `Ψ̂`). Exact: the products only permute and negate entries.
fn transform<const D: usize>(
    r: &reference::Reference<D>,
    p: &Mat<f64, D>,
    q: &Mat<f64, D>,
) -> reference::Reference<D>
where
    Mat<Dd, D>: Matrix<Scalar = Dd, Vector = [Dd; D]>,
    Mat<f64, D>: Matrix<Scalar = f64>,
{
    let neg = p.det() < 0.0;
    let sgn = |m: Mat<Dd, D>| if neg { -m } else { m };
    let tr = |m: &Mat<Dd, D>| perm_right(&perm_left(p, m), q);
    reference::Reference {
        svd: Svd {
            u: sgn(perm_left(p, &r.svd.u)),
            sigma: r.svd.sigma,
            v: sgn(perm_left(&q.transpose(), &r.svd.v)),
        },
        r: tr(&r.r),
        kernels: r.kernels.map(|k| reference::KernelRef {
            psi: k.psi,
            ahat: k.ahat.map(|m| tr(&m)),
            chat_z: k.chat_z.map(|m| tr(&m)),
            sigma_hat: k.sigma_hat,
        }),
    }
}

/// `P M` for a signed permutation matrix `P` (row `j` of `M` goes to the row of column `j`'s
/// nonzero of `P`, times its sign): exact, no arithmetic but negation.
fn perm_left<const D: usize>(p: &Mat<f64, D>, m: &Mat<Dd, D>) -> Mat<Dd, D> {
    let mut out = *m;
    for j in 0..D {
        for i in 0..D {
            let s = p.cols[j][i];
            if s != 0.0 {
                for c in 0..D {
                    let x = m.cols[c][j];
                    out.cols[c][i] = if s < 0.0 { -x } else { x };
                }
            }
        }
    }
    out
}

/// `M Q` for a signed permutation matrix `Q`: column `j` of the result is column `k` of `M`
/// times `Q_kj`, the nonzero of column `j` of `Q`.
fn perm_right<const D: usize>(m: &Mat<Dd, D>, q: &Mat<f64, D>) -> Mat<Dd, D> {
    let mut out = *m;
    for j in 0..D {
        for k in 0..D {
            let s = q.cols[j][k];
            if s != 0.0 {
                for r in 0..D {
                    let x = m.cols[k][r];
                    out.cols[j][r] = if s < 0.0 { -x } else { x };
                }
            }
        }
    }
    out
}

/// Why `svd`, a reference SVD of `f`, misses [`BOUND_REFERENCE`]; `None` if it meets it. The
/// reconstruction is formed after scaling `F` and `σ` by the power of two that brings
/// `max|Fᵢⱼ|` to `[0.5, 1)` (exact), so the double-double products neither overflow near
/// `f64::MAX` nor lose their trailing word near the subnormal range.
#[must_use]
pub fn reference_error<const D: usize>(f: &Mat<f64, D>, svd: &Svd<Mat<Dd, D>>) -> Option<String>
where
    Mat<Dd, D>: Matrix<Scalar = Dd, Vector = [Dd; D]>,
    Mat<f64, D>: Matrix<Scalar = f64>,
{
    let id = Mat::<Dd, D>::identity();
    let ou = (svd.u.transpose() * svd.u - id).max_abs().to_f64();
    let ov = (svd.v.transpose() * svd.v - id).max_abs().to_f64();
    let e = f.max_abs().exponent();
    let fs = reference::to_dd(f).map(|x| x.scalbn(-e));
    let scaled = Svd {
        u: svd.u,
        sigma: svd.sigma.map(|x| x.scalbn(-e)),
        v: svd.v,
    };
    let rec = (scaled.reconstruct() - fs).norm_squared().sqrt().to_f64();
    let floor = Dd::MIN_POSITIVE.scalbn(-e).to_f64();
    let rel = rec / fs.norm_squared().sqrt().to_f64().max(floor);
    let det_ok = svd.u.det() > Dd::ZERO && svd.v.det() > Dd::ZERO;
    // Written so that a NaN anywhere fails.
    let ok = ou <= BOUND_REFERENCE && ov <= BOUND_REFERENCE && rel <= BOUND_REFERENCE;
    (!ok || !det_ok).then(|| {
        format!(
            "reference SVD not accurate (UᵀU − I: {ou:e}, VᵀV − I: {ov:e}, \
             ‖UΣVᵀ − F‖/‖F‖: {rel:e}, bound {BOUND_REFERENCE:e}; det U, det V > 0: {det_ok})"
        )
    })
}

/// A unit-Frobenius random direction rounded to `T`.
fn direction<T: Real, const D: usize>(rng: &mut Pcg64) -> Mat<f64, D> {
    let mut m = Mat::<f64, D>::ZERO;
    for j in 0..D {
        for i in 0..D {
            m.cols[j][i] = rng.random_range(-1.0..=1.0);
        }
    }
    let n = m.norm_squared().sqrt();
    crate::families::round_to::<T, D>(&(m * (1.0 / n)))
}

/// Runs every method of dimension `D` in precision `T` over `families`.
fn run_dim<T: Real, const D: usize>(size: Size, families: &[Family], cells: &mut Vec<Cell>)
where
    Dim<D>: ReferenceDim<M = Mat<Dd, D>> + MethodsOf<T, D>,
    Mat<f64, D>: FamilyDim,
    Mat<T, D>: Matrix<Scalar = T, Vector = [T; D]>,
    Mat<Dd, D>: Matrix<Scalar = Dd, Vector = [Dd; D]>,
{
    for &fam in families {
        // The McAdams sweep variants (for the speed–accuracy chart) run on every family in the
        // reduced size, only on the Haar family in the full size (to keep it under 2 minutes).
        let all_sweeps = size == Size::Reduced || fam == Family::HaarLogUniform;
        let runners = <Dim<D> as MethodsOf<T, D>>::methods(all_sweeps);
        let cases = generate::<T, D>(fam, size);
        let mut rng = Pcg64::seed_from_u64(0x2e_f00d ^ (fam as u64));
        let mut fam_cells: Vec<(Cell, Viol)> = runners
            .iter()
            .map(|r| {
                (
                    Cell {
                        method: r.spec(),
                        precision: T::NAME,
                        family: fam,
                        n_cases: 0,
                        err: Default::default(),
                        raw: Default::default(),
                        points: Vec::new(),
                        statuses: StatusCounts::default(),
                        violations: Vec::new(),
                        n_violations: 0,
                    },
                    Viol {
                        msgs: Vec::new(),
                        n: 0,
                    },
                )
            })
            .collect();
        // The representative of the current orbit (full integer families), see `Case::orbit`.
        let mut rep: Option<(u32, reference::Reference<D>, Mat<f64, D>)> = None;
        for (index, case) in cases.iter().enumerate() {
            let (z, rf) = match (case.orbit, &rep) {
                (Some((r, p, q)), Some((ri, rr, rz))) if r == *ri => {
                    let (p, q) = (signed_perm::<D>(p), signed_perm::<D>(q));
                    (p * *rz * q, Some(transform(rr, &p, &q)))
                }
                _ => {
                    let z = direction::<T, D>(&mut rng);
                    let rf = if case.f.is_finite() {
                        reference::reference::<D>(MU, &case.f, &z).ok()
                    } else {
                        None
                    };
                    if let Some(msg) = rf.as_ref().and_then(|r| reference_error(&case.f, &r.svd)) {
                        // The reference's own method fails here: nothing can be measured.
                        let fp = pad3(&case.f);
                        for (cell, viol) in &mut fam_cells {
                            viol.add(&fp, D, format!("{msg}: case not measured"));
                            cell.n_cases += 1;
                        }
                        rep = None;
                        continue;
                    }
                    if let Some(r) = &rf {
                        rep = Some((index as u32, *r, z));
                    }
                    (z, rf)
                }
            };
            let sc = rf.as_ref().map(|r| {
                let s: Vec<f64> = r.svd.sigma.iter().map(|x| x.to_f64()).collect();
                let sh: Option<Vec<f64>> = r
                    .kernels
                    .as_ref()
                    .map(|k| k.sigma_hat.iter().map(|x| x.to_f64()).collect());
                let mut sc = scales::<T, D>(&case.f, &s, sh.as_deref());
                // The reference's kernels are the library's own generic ones run in
                // double-double: refusing a J > 0 that is not singular to working precision
                // is their failure, and would pass off the same failure of the method's
                // kernels as the J ≤ 0 contract.
                sc.reference_kernels_failed =
                    r.kernels.is_none() && sc.j_positive && !sc.near_singular;
                if sc.reference_kernels_failed {
                    let fp = pad3(&case.f);
                    for (_, viol) in &mut fam_cells {
                        viol.add(
                            &fp,
                            D,
                            "reference kernels refused J > 0 (not singular to working \
                             precision): kernels not measured"
                                .into(),
                        );
                    }
                }
                sc
            });
            for (r, (cell, viol)) in runners.iter().zip(fam_cells.iter_mut()) {
                measure_case::<T, D>(r.as_ref(), fam.contract(), case, &z, &rf, &sc, cell, viol);
            }
        }
        for (mut cell, viol) in fam_cells {
            cell.violations = viol.msgs;
            cell.n_violations = viol.n;
            cells.push(cell);
        }
    }
}

/// A dimension the stability measurement runs in (2 and 3), for any precision `T`.
pub trait Measure<T: Real> {
    /// Appends the cells of every method of this dimension over `families` to `cells`.
    fn measure(size: Size, families: &[Family], cells: &mut Vec<Cell>);
}

impl<T: Real + FastPaths<2>> Measure<T> for Dim<2> {
    fn measure(size: Size, families: &[Family], cells: &mut Vec<Cell>) {
        run_dim::<T, 2>(size, families, cells);
    }
}

impl<T: Real + FastPaths<3>> Measure<T> for Dim<3> {
    fn measure(size: Size, families: &[Family], cells: &mut Vec<Cell>) {
        run_dim::<T, 3>(size, families, cells);
    }
}

/// Runs every method of one dimension `D` in one precision `T` over `families`.
#[must_use]
pub fn run_one<T: Real, const D: usize>(size: Size, families: &[Family]) -> Report
where
    Dim<D>: Measure<T>,
{
    let mut cells = Vec::new();
    <Dim<D> as Measure<T>>::measure(size, families, &mut cells);
    Report { size, cells }
}

/// Runs every method × family × precision × dim at `size`.
#[must_use]
pub fn run(size: Size) -> Report {
    run_families(size, &Family::ALL)
}

/// Runs every method × precision × dim over the given families.
#[must_use]
pub fn run_families(size: Size, families: &[Family]) -> Report {
    let mut cells = Vec::new();
    run_dim::<f64, 3>(size, families, &mut cells);
    run_dim::<f32, 3>(size, families, &mut cells);
    run_dim::<f64, 2>(size, families, &mut cells);
    run_dim::<f32, 2>(size, families, &mut cells);
    Report { size, cells }
}

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
