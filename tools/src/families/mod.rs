//! Families of deformation gradients with stated contracts.
//!
//! Every family is a deterministic (seeded) generator of `d×d` matrices, parameterised by the
//! precision `T` it targets (its `ε`, its exponent range) and by a [`Size`]. The entries are
//! rounded to `T` before they are returned (as `f64`, exactly), so a method run in `T` and the
//! double-double reference see the same matrix.
//!
//! **Contracts.** The condition numbers are not taken from the nominal construction but from
//! the double-double SVD of the matrix actually returned (rounding to `T` moves `σ` by `~ε‖F‖`,
//! which matters at the kink or at `J → 0`); see [`crate::stability`] for the error measures.
//! - [`Contract::Accurate`]: `J > 0`. Every kernel (Ψ̂, Â, Ĉ:Z) and every decomposition
//!   succeeds with finite results, errors within the stated multiple of `ε·κ`. Where `F` is
//!   singular to working precision (`ε·σ₀/σ_min ≥ 1/8`, the rounding of `F` itself can flip
//!   the sign of `J`) the kernels may instead return `NonPositiveJ`.
//! - [`Contract::Scaled`]: as `Accurate`, but the kernels' results scale like `‖F‖⁻¹` (Â) and
//!   `‖F‖⁻²` (Ĉ:Z): where the true result exceeds the range of `T` the status is `Overflow`,
//!   and results below the normal range are only accurate to an absolute `T::MIN_POSITIVE`.
//! - [`Contract::Refused`]: `J ≤ 0` (at the reference). The decompositions are still defined
//!   and accurate (rotation-variant SVD, `R ∈ SO(d)`); every kernel returns `NonPositiveJ`.
//! - [`Contract::NonFinite`]: a NaN or infinite entry. Every call returns `NonFinite`, at
//!   once (no iteration is entered).

mod generator;
mod integer;
mod sampling;
mod under_overflow;

pub use generator::generate;
pub use integer::{signed_perm, signed_perm_count};
pub use sampling::{round_to, FamilyDim};

use ampm_core::Mat;

/// What a family promises (see the module docs).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Contract {
    /// `J > 0`: everything succeeds, error ≤ stated multiple of `ε·κ`.
    Accurate,
    /// `J > 0` over the whole exponent range: `Overflow` allowed where the true result is not
    /// representable, absolute accuracy `T::MIN_POSITIVE` below the normal range.
    Scaled,
    /// `J ≤ 0`: decompositions accurate, kernels return `NonPositiveJ`.
    Refused,
    /// NaN or ±inf entries: every call returns `NonFinite`.
    NonFinite,
}

/// The families. [`Family::ALL`] lists them in report order.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Family {
    /// `I + 256ε·N`, `N` entries uniform in `[−1, 1]`.
    NearIdentityEps,
    /// `I + 10⁻³·N`.
    NearIdentity1e3,
    /// `s·I`, `s = 10ᵉ` over the exponent range of `T` (1e-20…1e20 f32, 1e-150…1e150 f64).
    ScaledIdentity,
    /// `s·Q diag(σ) Wᵀ`, `σ` log-uniform in `[0.5, 2]`, `s` over the same range.
    ScaledRandom,
    /// Exactly repeated `σ` (`(2,2,1)`, `(2,1,1)`, `(1,1,1)`; 2D `(1,1)`, `(2,2)`), rotated.
    RepeatedSigma,
    /// Nearly repeated `σ`: `(1+δ, 1, 0.5)` and `(2, 1+δ, 1)` (2D `(1+δ, 1)`), `δ = 10⁻ᵏ`.
    NearlyRepeatedSigma,
    /// Graded `σ = (1e4, 1, 1e-4)` (2D `(1e2, 1e-2)`), rotated.
    Graded,
    /// Two small singular values `σ = (1, δ, δ)`, `δ = 10⁻ᵏ` (2D: `(1, δ)`).
    TwoSmall,
    /// Rank deficient: `σ = (1, 0.5, 0)`, `(1, 0, 0)`, `0` (2D `(1, 0)`, `0`), rotated.
    RankDeficient,
    /// `J → 0⁺`: `σ = (1, 1, δ)` (2D `(1, δ)`), `J = δ = 10⁻ᵏ`, rotated.
    JToZero,
    /// `J ≤ 0`: `σ = (1, 0.5, −δ)` (2D `(1, −δ)`), `δ = 10⁻ᵏ` and `δ = 0.3`, rotated.
    JNonPositive,
    /// The kink of `δR`: `diag(2, 1, −1 + δ)` (2D `diag(1, −1 + δ)`), `δ = 10⁻ᵏ`, as is and
    /// rotated: `σ₁ + σ₂ = δ`.
    Kink,
    /// All `5^(d²)` integer matrices with entries in `{−2, …, 2}` (a seeded subset in the
    /// reduced size).
    Integer,
    /// The integer matrices plus `256ε·N`.
    IntegerPerturbed,
    /// `Q diag(σ) Wᵀ`, `Q`, `W` Haar on SO(d), `σᵢ` log-uniform in `[1e-4, 1e4]`.
    HaarLogUniform,
    /// Subnormal entries: `s·I` and `s·(random F)` with `s` subnormal, and `I` plus subnormal
    /// off-diagonal entries.
    Subnormal,
    /// Entries whose squares or products under- or overflow unless the method scales: `c·I`
    /// plus one tiny off-diagonal `±δ·c` (every position, `δ` from just below `√MIN_POSITIVE`,
    /// whose square is subnormal, down to `MIN_POSITIVE/ε`, whose square is zero); nearly
    /// diagonal matrices (repeated, distinct and negative diagonals) with every off-diagonal
    /// that tiny; `s·Q` and `s·Q diag(σ) Wᵀ` at `s` near `√MAX`, `MAX/16`, `√MIN_POSITIVE` and
    /// `MIN_POSITIVE/ε`; and matrices mixing entries of size 1 with entries of size
    /// `t < √MIN_POSITIVE` (`t ≈ 1e-20` in f32, `1e-160` in f64; with two small columns `J`
    /// itself is below the normal range). The members with `J ≤ 0` (negative diagonal, random
    /// entries) are held to the [`Contract::Refused`] case, decided like every other case by
    /// the sign of `J` at the reference.
    ProductUnderOverflow,
    /// NaN, +inf or −inf in one entry (every position), or everywhere.
    NonFinite,
}

impl Family {
    /// Every family, in report order.
    pub const ALL: [Family; 18] = [
        Family::NearIdentityEps,
        Family::NearIdentity1e3,
        Family::ScaledIdentity,
        Family::ScaledRandom,
        Family::RepeatedSigma,
        Family::NearlyRepeatedSigma,
        Family::Graded,
        Family::TwoSmall,
        Family::RankDeficient,
        Family::JToZero,
        Family::JNonPositive,
        Family::Kink,
        Family::Integer,
        Family::IntegerPerturbed,
        Family::HaarLogUniform,
        Family::Subnormal,
        Family::ProductUnderOverflow,
        Family::NonFinite,
    ];

    /// Short name for tables and charts.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Family::NearIdentityEps => "near-identity 256ε",
            Family::NearIdentity1e3 => "near-identity 1e-3",
            Family::ScaledIdentity => "scaled identity",
            Family::ScaledRandom => "scaled random",
            Family::RepeatedSigma => "repeated σ",
            Family::NearlyRepeatedSigma => "nearly repeated σ",
            Family::Graded => "graded σ",
            Family::TwoSmall => "two small σ",
            Family::RankDeficient => "rank deficient",
            Family::JToZero => "J → 0⁺",
            Family::JNonPositive => "J ≤ 0",
            Family::Kink => "kink σᵢ+σⱼ → 0",
            Family::Integer => "integer {−2..2}",
            Family::IntegerPerturbed => "integer + 256ε",
            Family::HaarLogUniform => "Haar, log-uniform σ",
            Family::Subnormal => "subnormal entries",
            Family::ProductUnderOverflow => "products under/overflow",
            Family::NonFinite => "NaN / ±inf",
        }
    }

    /// The family's contract. `Accurate` families may contain a few `J ≤ 0` or singular
    /// matrices after rounding (integer, two-small, `J → 0⁺`): the contract of each case is
    /// decided by the sign of `J` at the reference (see [`crate::stability`]).
    #[must_use]
    pub fn contract(self) -> Contract {
        match self {
            Family::ScaledIdentity
            | Family::ScaledRandom
            | Family::Subnormal
            | Family::ProductUnderOverflow => Contract::Scaled,
            Family::RankDeficient | Family::JNonPositive | Family::Kink => Contract::Refused,
            Family::NonFinite => Contract::NonFinite,
            _ => Contract::Accurate,
        }
    }

    /// What the family parameter of [`Case::param`] is, for the families that have one
    /// (the x axis of the stability chart).
    #[must_use]
    pub fn param_desc(self) -> Option<&'static str> {
        match self {
            Family::ScaledIdentity | Family::ScaledRandom => Some("scale s"),
            Family::NearlyRepeatedSigma => Some("relative gap δ = 10⁻ᵏ"),
            Family::TwoSmall => Some("small σ = δ = 10⁻ᵏ"),
            Family::JToZero => Some("J = δ = 10⁻ᵏ (distance to J = 0)"),
            Family::JNonPositive => Some("−σ_min = δ"),
            Family::Kink => Some("σ₁+σ₂ = δ = 10⁻ᵏ (distance to the kink)"),
            Family::ProductUnderOverflow => Some("tiny entries / largest entry (δ or t)"),
            _ => None,
        }
    }
}

/// How many matrices to generate.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Size {
    /// For tests: a few dozen per family and 4 000 integer matrices (seeded subset).
    Reduced,
    /// For the report: every integer matrix and a few hundred per random family.
    Full,
}

impl Size {
    /// Random draws per parameter value (or per family without parameter).
    #[must_use]
    fn draws(self) -> usize {
        match self {
            Size::Reduced => 4,
            Size::Full => 24,
        }
    }
    /// Draws for the families without parameter.
    #[must_use]
    fn flat_draws(self) -> usize {
        match self {
            Size::Reduced => 48,
            Size::Full => 2000,
        }
    }
}

/// One generated matrix.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Case<const D: usize> {
    /// `F`, with entries exactly representable in the target precision.
    pub f: Mat<f64, D>,
    /// The family parameter (see [`Family::param_desc`]), NaN when the family has none.
    pub param: f64,
    /// For the full integer families, which are generated orbit by orbit under
    /// `F ↦ P F Q` (`P`, `Q` signed permutations, `det P · det Q = +1`): `(rep, p, q)` says
    /// that `f = P·cases[rep].f·Q` exactly, `P = signed_perm(p)`, `Q = signed_perm(q)`, so
    /// every exact quantity follows from the representative's (`R ↦ PRQ`, `σ` unchanged,
    /// `Â ↦ PÂQ`, …). `None` for a representative or any other case.
    pub orbit: Option<(u32, u8, u8)>,
}
