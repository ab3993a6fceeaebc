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

mod contracts;
mod driver;
mod measures;
mod output;
mod runners;
mod stats;

pub use contracts::reference_error;
pub use driver::{run, run_families, run_one, Measure};
pub use output::{curves, haar_p99, table_markdown, HaarP99};
pub use runners::{bound, MethodSpec, MCADAMS_SWEEPS};
pub use stats::{CaseErr, Cell, Report, Stat, StatusCounts};

// The module docs link these.
#[cfg(doc)]
use crate::families::{Contract, Family};
use crate::reference::Dd;
use ampm_core::Real;

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
