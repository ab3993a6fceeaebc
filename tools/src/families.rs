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

use crate::workload::HaarRotation;
use ampm_core::{Mat, Real};
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;

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

/// The `i`-th signed permutation matrix of dimension `D` (`i < 2ᴰ·D!`): permutation
/// `i / 2ᴰ` in lexicographic order, sign bits `i % 2ᴰ` (bit `j` negates column `j`).
#[must_use]
pub fn signed_perm<const D: usize>(i: u8) -> Mat<f64, D> {
    let signs = usize::from(i) % (1 << D);
    let mut k = usize::from(i) >> D;
    // Lehmer code → permutation.
    let mut avail: Vec<usize> = (0..D).collect();
    let mut perm = [0usize; D];
    let mut fact: usize = (1..D).product();
    for (j, p) in perm.iter_mut().enumerate() {
        let idx = k / fact.max(1);
        k %= fact.max(1);
        *p = avail.remove(idx);
        if j + 1 < D {
            fact /= D - 1 - j;
        }
    }
    let mut m = Mat::<f64, D>::ZERO;
    for (j, &p) in perm.iter().enumerate() {
        m.cols[j][p] = if signs >> j & 1 == 1 { -1.0 } else { 1.0 };
    }
    m
}

/// Number of signed permutations of dimension `D`, `2ᴰ·D!`.
#[must_use]
pub fn signed_perm_count<const D: usize>() -> usize {
    (1 << D) * (1..=D).product::<usize>()
}

/// Index (base-5 digits of the entries + 2, column-major) of an integer matrix.
fn integer_index<const D: usize>(m: &Mat<f64, D>) -> u64 {
    let mut idx = 0u64;
    for j in (0..D).rev() {
        for i in (0..D).rev() {
            idx = idx * 5 + (m.cols[j][i] + 2.0) as u64;
        }
    }
    idx
}

/// Dimensions the families are defined for (2 and 3).
pub trait FamilyDim: HaarRotation {
    /// `Mat<f64, D>` as a column-major array constructor.
    #[must_use]
    fn diag_rot(rng: &mut Pcg64, sigma: &[f64], rotate: bool) -> Self;
}

impl<const D: usize> FamilyDim for Mat<f64, D>
where
    Mat<f64, D>: HaarRotation,
{
    fn diag_rot(rng: &mut Pcg64, sigma: &[f64], rotate: bool) -> Self {
        let mut d = [0.0; D];
        d.copy_from_slice(&sigma[..D]);
        let s = Mat::from_diagonal(d);
        if rotate {
            let q = <Self as HaarRotation>::haar(rng);
            let w = <Self as HaarRotation>::haar(rng);
            q * s * w.transpose()
        } else {
            s
        }
    }
}

/// Rounds every entry to `T` (exactly representable afterwards).
#[inline]
#[must_use]
pub fn round_to<T: Real, const D: usize>(f: &Mat<f64, D>) -> Mat<f64, D> {
    f.map(|x| T::from_f64(x).to_f64())
}

/// `10⁻ᵏ` for `k = 1 ..= kmax` (`kmax` beyond the precision, to cross `ε`).
fn decades(kmax: i32) -> impl Iterator<Item = f64> {
    (1..=kmax).map(|k| 10f64.powi(-k))
}

/// Decimal digits of `T` plus a margin: the `δ = 10⁻ᵏ` sweeps run past `ε` into the regime
/// where the rounding of `F` dominates.
fn kmax<T: Real>() -> i32 {
    if T::MANTISSA_DIGITS <= 24 {
        9
    } else {
        18
    }
}

/// Exponent range `±e` of the scaled families: 20 for f32, 150 for f64.
fn scale_exp<T: Real>() -> i32 {
    if T::MANTISSA_DIGITS <= 24 {
        20
    } else {
        150
    }
}

/// A random matrix with entries uniform in `[−1, 1]`.
fn noise<const D: usize>(rng: &mut Pcg64) -> Mat<f64, D> {
    let mut m = Mat::<f64, D>::ZERO;
    for j in 0..D {
        for i in 0..D {
            m.cols[j][i] = rng.random_range(-1.0..=1.0);
        }
    }
    m
}

/// The integer matrix of index `idx < 5^(d²)`: base-5 digits minus 2, column-major.
fn integer_matrix<const D: usize>(mut idx: u64) -> Mat<f64, D> {
    let mut m = Mat::<f64, D>::ZERO;
    for j in 0..D {
        for i in 0..D {
            m.cols[j][i] = (idx % 5) as f64 - 2.0;
            idx /= 5;
        }
    }
    m
}

/// Indices of the integer matrices of the reduced size: a seeded subset of 4 000 (in 2D all
/// 625). (The full size goes orbit by orbit, see [`generate`].)
fn integer_indices<const D: usize>(size: Size, rng: &mut Pcg64) -> Vec<u64> {
    let total = 5u64.pow((D * D) as u32);
    match size {
        Size::Full => (0..total).collect(),
        Size::Reduced if total <= 4000 => (0..total).collect(),
        Size::Reduced => (0..4000).map(|_| rng.random_range(0..total)).collect(),
    }
}

/// The matrices of `family` for precision `T` and dimension `D`, deterministic.
#[must_use]
pub fn generate<T: Real, const D: usize>(family: Family, size: Size) -> Vec<Case<D>>
where
    Mat<f64, D>: FamilyDim,
{
    let seed = 0xa3a0_2014_u64
        ^ ((family as u64) << 8)
        ^ ((D as u64) << 16)
        ^ (u64::from(T::MANTISSA_DIGITS) << 24);
    let mut rng = Pcg64::seed_from_u64(seed);
    let rng = &mut rng;
    let eps = T::EPSILON.to_f64();
    let id = Mat::<f64, D>::identity();
    let nan = f64::NAN;
    let mut out: Vec<Case<D>> = Vec::new();
    let push = |out: &mut Vec<Case<D>>, f: Mat<f64, D>, param: f64| {
        out.push(Case {
            f: round_to::<T, D>(&f),
            param,
            orbit: None,
        });
    };
    let three = |a: f64, b: f64, c: f64| [a, b, c];
    let sig = |s3: [f64; 3], s2: [f64; 2]| -> [f64; 3] {
        if D == 2 {
            [s2[0], s2[1], 0.0]
        } else {
            s3
        }
    };
    match family {
        Family::NearIdentityEps | Family::NearIdentity1e3 => {
            let h = if family == Family::NearIdentityEps {
                256.0 * eps
            } else {
                1e-3
            };
            for _ in 0..size.flat_draws() {
                push(&mut out, id + noise::<D>(rng) * h, nan);
            }
        }
        Family::ScaledIdentity | Family::ScaledRandom => {
            let e = scale_exp::<T>();
            let step = if matches!(size, Size::Reduced) { 5 } else { 1 };
            for k in (-e..=e).step_by(step) {
                let s = 10f64.powi(k);
                if family == Family::ScaledIdentity {
                    push(&mut out, id * s, s);
                } else {
                    for _ in 0..size.draws() {
                        let mut sg = [0.0; 3];
                        for x in &mut sg {
                            *x = (rng.random_range(0.5f64.ln()..2f64.ln())).exp();
                        }
                        push(&mut out, Mat::diag_rot(rng, &sg, true) * s, s);
                    }
                }
            }
        }
        Family::RepeatedSigma => {
            let pats: &[[f64; 3]] = if D == 2 {
                &[[1.0, 1.0, 0.0], [2.0, 2.0, 0.0]]
            } else {
                &[[2.0, 2.0, 1.0], [2.0, 1.0, 1.0], [1.0, 1.0, 1.0]]
            };
            for p in pats {
                push(&mut out, Mat::diag_rot(rng, p, false), nan);
                for _ in 0..size.flat_draws() / pats.len() {
                    push(&mut out, Mat::diag_rot(rng, p, true), nan);
                }
            }
        }
        Family::NearlyRepeatedSigma => {
            for d in decades(kmax::<T>()) {
                for _ in 0..size.draws() {
                    push(
                        &mut out,
                        Mat::diag_rot(rng, &sig(three(1.0 + d, 1.0, 0.5), [1.0 + d, 1.0]), true),
                        d,
                    );
                    push(
                        &mut out,
                        Mat::diag_rot(rng, &sig(three(2.0, 1.0 + d, 1.0), [1.0 + d, 1.0]), true),
                        d,
                    );
                }
            }
        }
        Family::Graded => {
            let s = sig(three(1e4, 1.0, 1e-4), [1e2, 1e-2]);
            push(&mut out, Mat::diag_rot(rng, &s, false), nan);
            for _ in 0..size.flat_draws() {
                push(&mut out, Mat::diag_rot(rng, &s, true), nan);
            }
        }
        Family::TwoSmall | Family::JToZero => {
            for d in decades(kmax::<T>() + 4) {
                let s = if family == Family::TwoSmall {
                    sig(three(1.0, d, d), [1.0, d])
                } else {
                    sig(three(1.0, 1.0, d), [1.0, d])
                };
                push(&mut out, Mat::diag_rot(rng, &s, false), d);
                for _ in 0..size.draws() {
                    push(&mut out, Mat::diag_rot(rng, &s, true), d);
                }
            }
        }
        Family::RankDeficient => {
            let pats: &[[f64; 3]] = if D == 2 {
                &[[1.0, 0.0, 0.0], [0.0, 0.0, 0.0]]
            } else {
                &[[1.0, 0.5, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 0.0]]
            };
            for p in pats {
                push(&mut out, Mat::diag_rot(rng, p, false), nan);
                for _ in 0..size.flat_draws() / pats.len() {
                    push(&mut out, Mat::diag_rot(rng, p, true), nan);
                }
            }
        }
        Family::JNonPositive => {
            for d in decades(kmax::<T>()).chain([0.3]) {
                let s = sig(three(1.0, 0.5, -d), [1.0, -d]);
                push(&mut out, Mat::diag_rot(rng, &s, false), d);
                for _ in 0..size.draws() {
                    push(&mut out, Mat::diag_rot(rng, &s, true), d);
                }
            }
        }
        Family::Kink => {
            for d in decades(kmax::<T>()) {
                let s = sig(three(2.0, 1.0, -1.0 + d), [1.0, -1.0 + d]);
                push(&mut out, Mat::diag_rot(rng, &s, false), d);
                for _ in 0..size.draws() {
                    push(&mut out, Mat::diag_rot(rng, &s, true), d);
                }
            }
        }
        Family::Integer | Family::IntegerPerturbed => {
            let perturb = family == Family::IntegerPerturbed;
            if size == Size::Full {
                // Orbit by orbit (see `Case::orbit`): the representative is perturbed and
                // rounded, the members are its exact transforms.
                let n = 5u64.pow((D * D) as u32);
                let ng = signed_perm_count::<D>();
                let group: Vec<(Mat<f64, D>, f64)> = (0..ng)
                    .map(|i| {
                        let p = signed_perm::<D>(i as u8);
                        let det = if D == 2 {
                            p.cols[0][0] * p.cols[1][1] - p.cols[1][0] * p.cols[0][1]
                        } else {
                            let c = &p.cols;
                            c[0][0] * (c[1][1] * c[2][2] - c[1][2] * c[2][1])
                                - c[1][0] * (c[0][1] * c[2][2] - c[0][2] * c[2][1])
                                + c[2][0] * (c[0][1] * c[1][2] - c[0][2] * c[1][1])
                        };
                        (p, det)
                    })
                    .collect();
                let mut seen = vec![false; n as usize];
                for idx in 0..n {
                    if seen[idx as usize] {
                        continue;
                    }
                    seen[idx as usize] = true;
                    let int = integer_matrix::<D>(idx);
                    let mut rep = int;
                    if perturb {
                        rep += noise::<D>(rng) * (256.0 * eps);
                    }
                    let rep = round_to::<T, D>(&rep);
                    let rep_index = out.len() as u32;
                    out.push(Case {
                        f: rep,
                        param: nan,
                        orbit: None,
                    });
                    for (pi, (p, dp)) in group.iter().enumerate() {
                        for (qi, (q, dq)) in group.iter().enumerate() {
                            if dp * dq < 0.0 {
                                continue;
                            }
                            let k = integer_index::<D>(&(*p * int * *q)) as usize;
                            if seen[k] {
                                continue;
                            }
                            seen[k] = true;
                            out.push(Case {
                                f: *p * rep * *q,
                                param: nan,
                                orbit: Some((rep_index, pi as u8, qi as u8)),
                            });
                        }
                    }
                }
            } else {
                for idx in integer_indices::<D>(size, rng) {
                    let mut f = integer_matrix::<D>(idx);
                    if perturb {
                        f += noise::<D>(rng) * (256.0 * eps);
                    }
                    push(&mut out, f, nan);
                }
            }
        }
        Family::HaarLogUniform => {
            let (lo, hi) = (1e-4f64.ln(), 1e4f64.ln());
            for _ in 0..size.flat_draws() {
                let mut s = [0.0; 3];
                for x in &mut s {
                    *x = rng.random_range(lo..hi).exp();
                }
                push(&mut out, Mat::diag_rot(rng, &s, true), nan);
            }
        }
        Family::Subnormal => {
            // Subnormal scales of T: 2^(emin − 1 − j·(p/4)).
            let emin = T::MIN_POSITIVE.exponent();
            let p = T::MANTISSA_DIGITS as i32;
            for j in 1..4 {
                let s = 1f64 * 2f64.powi(emin - 1 - j * p / 4);
                push(&mut out, id * s, s);
                for _ in 0..size.draws() {
                    let mut sg = [0.0; 3];
                    for x in &mut sg {
                        *x = (rng.random_range(0.5f64.ln()..2f64.ln())).exp();
                    }
                    push(&mut out, Mat::diag_rot(rng, &sg, true) * s, s);
                    let mut g = id;
                    g.cols[1][0] = s * rng.random_range(-1.0..1.0);
                    g.cols[0][D - 1] = s * rng.random_range(-1.0..1.0);
                    push(&mut out, g, s);
                }
            }
        }
        Family::ProductUnderOverflow => {
            for (f, param) in product_under_overflow::<T, D>(size, rng) {
                push(&mut out, f, param);
            }
        }
        Family::NonFinite => {
            for v in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
                for j in 0..D {
                    for i in 0..D {
                        let mut f = id + noise::<D>(rng) * 0.1;
                        f.cols[j][i] = v;
                        push(&mut out, f, nan);
                    }
                }
                push(&mut out, Mat::<f64, D>::ZERO.map(|_| v), nan);
            }
        }
    }
    out
}

/// The matrices of [`Family::ProductUnderOverflow`] (before rounding to `T`) with their
/// parameter: the relative size of the tiny entries (`δ`, `t`), NaN for the scaled matrices.
///
/// Every threshold comes from `T`: with `eₘᵢₙ`, `eₘₐₓ` the exponents of `MIN_POSITIVE` and
/// `MAX` (`x = m·2ᵉ`, `m ∈ [0.5, 1)`) and `p` the mantissa digits, a number of exponent
/// `e ≤ (eₘᵢₙ − 1)/2` has a subnormal square (or zero, from `e ≤ (eₘᵢₙ − p − 1)/2`), and a
/// product of two entries of exponent `> eₘₐₓ/2` overflows.
fn product_under_overflow<T: Real, const D: usize>(
    size: Size,
    rng: &mut Pcg64,
) -> Vec<(Mat<f64, D>, f64)>
where
    Mat<f64, D>: FamilyDim,
{
    let full = size == Size::Full;
    let emin = T::MIN_POSITIVE.exponent();
    let emax = T::MAX.exponent();
    let p = T::MANTISSA_DIGITS as i32;
    let min_pos = T::MIN_POSITIVE.to_f64();
    // Largest exponent whose square is subnormal: f32 −63, f64 −511.
    let e_top = (emin - 1) / 2;
    // δ·ε still normal (δ ≈ MIN_POSITIVE/ε): f32 −102, f64 −969.
    let e_bot = emin + p - 1;
    // Exponents of the relative size δ of the tiny entries: δ² subnormal with most of its bits
    // (e_top), with half of them (e_top − p/4), with one to three bits, none or zero around
    // e_top − p/2 (which one depends on c: the methods first scale F by the power of two that
    // brings c to [0.5, 1), where a normalisation by √(x² + y²) is off by up to tens of
    // percent), zero (e_top − p and below), down to e_bot. f32: −63, −69, −72, −73, −74, −87,
    // −94, −102; f64: −511, −524, −534, −535, −536, −564, −766, −969.
    let deltas: Vec<i32> = vec![
        e_top,
        e_top - p / 4,
        e_top - p / 2 + 3,
        e_top - p / 2 + 2,
        e_top - p / 2 + 1,
        e_top - p,
        (e_top - p + e_bot) / 2,
        e_bot,
    ];
    let mantissa = |rng: &mut Pcg64| rng.random_range(0.5..1.0f64);
    let sign = |rng: &mut Pcg64| if rng.random::<bool>() { 1.0 } else { -1.0 };
    let id = Mat::<f64, D>::identity();
    let offdiag: Vec<(usize, usize)> = (0..D)
        .flat_map(|j| (0..D).filter(move |&i| i != j).map(move |i| (i, j)))
        .collect();
    let mut out = Vec::new();

    // c·I + δc·eᵢeⱼᵀ. The closed forms normalise vectors like (F₀₀ − F₁₁, F₀₁ + F₁₀) ≈ (0, δc):
    // after the methods' power-of-two scaling their squared norm is subnormal. c = 1 (also the
    // absolute case), a non-power of two, near √MAX (c² finite, 2c² not) and a small scale at
    // which δc is still normal.
    let cs = [
        1.0,
        0.7,
        0.75 * 2f64.powi(emax / 2),
        0.75 * 2f64.powi(emin / 4),
    ];
    for (ci, &c) in cs.iter().enumerate() {
        for (di, &e) in deltas.iter().enumerate() {
            let delta = mantissa(rng) * 2f64.powi(e);
            if c * delta < min_pos {
                continue;
            }
            // Reduced size: every position and sign at c = 1 for the two δ whose squares keep
            // three bits or fewer after the scaling, and for the smallest δ; one position
            // (cycling) and a random sign otherwise.
            let all = full || (ci == 0 && matches!(di, 2 | 3 | 7));
            for (k, &(i, j)) in offdiag.iter().enumerate() {
                if !all && k != (ci + di) % offdiag.len() {
                    continue;
                }
                let signs: &[f64] = if all { &[1.0, -1.0] } else { &[0.0] };
                for &sg in signs {
                    let sg = if sg == 0.0 { sign(rng) } else { sg };
                    let mut f = id * c;
                    f.cols[j][i] = sg * c * delta;
                    out.push((f, delta));
                }
            }
        }
    }

    // Nearly diagonal: every off-diagonal ±δ·m, on repeated, distinct and (J ≤ 0) negative
    // diagonals; diag(1, …, −1) is also the kink σ₁ + σ₂ = 0.
    let diags: &[[f64; 3]] = if D == 2 {
        &[
            [1.0, 1.0, 0.0],
            [1.0, 0.6, 0.0],
            [1.0, -0.6, 0.0],
            [1.0, -1.0, 0.0],
        ]
    } else {
        &[
            [1.0, 1.0, 1.0],
            [1.0, 1.0, 0.5],
            [1.0, 0.6, 0.3],
            [1.0, 0.6, -0.3],
            [1.0, 1.0, -1.0],
        ]
    };
    for (pi, dg) in diags.iter().enumerate() {
        for (di, &e) in deltas.iter().enumerate() {
            if !full && (pi + di) % 2 == 1 {
                continue;
            }
            for _ in 0..if full { 4 } else { 1 } {
                let mut f = Mat::<f64, D>::from_diagonal(core::array::from_fn(|i| dg[i]));
                for &(i, j) in &offdiag {
                    f.cols[j][i] = sign(rng) * mantissa(rng) * 2f64.powi(e);
                }
                out.push((f, 2f64.powi(e)));
            }
        }
    }

    // s·Q and s·Q diag(σ) Wᵀ, σ log-uniform in [0.5, 2]: products of entries overflow at
    // s ≈ √MAX, every sum of two entries but one would at s ≈ MAX/16; products underflow at
    // s ≈ √MIN_POSITIVE and vanish at s ≈ MIN_POSITIVE/ε.
    let scales = [
        0.75 * 2f64.powi(emax / 2),
        0.9 * 2f64.powi(emax - 4),
        0.75 * 2f64.powi(e_top),
        0.75 * 2f64.powi(e_bot),
    ];
    for s in scales {
        for _ in 0..if full { 8 } else { 1 } {
            let q = <Mat<f64, D> as HaarRotation>::haar(rng);
            out.push((q * s, f64::NAN));
            let mut sg = [0.0; 3];
            for x in &mut sg {
                *x = rng.random_range(0.5f64.ln()..2f64.ln()).exp();
            }
            out.push((Mat::diag_rot(rng, &sg, true) * s, f64::NAN));
        }
    }

    // Entries of size ~1 and of size ~t (random signs and mantissas): products of two small
    // entries underflow. t ≈ 1e-20 (f32), 1e-160 (f64), and t with a zero square. The fixed
    // patterns put the small entries where the methods form their products: a single large
    // entry (a small trailing block), one large column, one large row (orthogonalising the
    // columns leaves columns of size t), a large anti-diagonal, each with both signs of J; then
    // each entry large or small at random.
    for e in [e_top - 3, e_top - p] {
        let t = 2f64.powi(e);
        let patterns: [fn(usize, usize) -> bool; 4] = [
            |i, j| i == 0 && j == 0,
            |_, j| j == 0,
            |i, _| i == 0,
            |i, j| i + j == D - 1,
        ];
        let draws = if full { 200 } else { 8 };
        for k in 0..patterns.len() + draws {
            let mut f = Mat::<f64, D>::ZERO;
            for j in 0..D {
                for i in 0..D {
                    let big = match patterns.get(k) {
                        Some(pat) => pat(i, j),
                        None => rng.random::<bool>(),
                    };
                    f.cols[j][i] = sign(rng) * mantissa(rng) * if big { 1.0 } else { t };
                }
            }
            out.push((f, t));
            if k < patterns.len() {
                // The same with the first column negated: the pattern with either sign of J.
                let mut g = f;
                g.cols[0] = g.cols[0].map(|x| -x);
                out.push((g, t));
            }
        }
    }
    out
}
