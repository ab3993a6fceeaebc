//! Integration tests of the core kernels (`ampm_core::augmented`, `ampm_core::polar`) with the
//! fixed corotated base energy, generated for 2D/3D × f32/f64 from one generic source.
//!
//! One test binary. The checks are generic over the matrix type; this file instantiates them
//! (one module per type) and holds what the modules share: the per-type interface [`Case`],
//! conversions and random inputs, the scales of one input ([`Geom`]), the rounding constants,
//! and [`Worst`]. Each module covers one concern:
//!
//! 1. `precision`: `Â:Z` and `Ĉ:Z` against central differences (f64), and the f32 kernels
//!    against the f64 kernels on the same input.
//! 2. `identities`: symmetry of the Hessian, the identities of a scale-invariant energy,
//!    rotation invariance (left and right), and `𝓑` (adjointness, the seed's index formula).
//! 3. `scaling`: powers of two (bit for bit) and of ten across the exponent range, overflow
//!    reported as `Error::Overflow`, and a liquid (`μ = 0`).
//! 4. `decomposition`: the default SVD and polar decomposition, against nalgebra for f32.
//!
//! The `glam` conversions are checked here.
//!
//! Inputs are drawn from a seeded PCG: `F = U diag(σ) Vᵀ` with `U, V` Haar-distributed in SO(d)
//! (QR of a Gaussian matrix with the sign fix of Mezzadri 2007, then one column flipped if
//! needed), `σᵢ` log-uniform in `[0.2, 5]` (so `J > 0`), `μ` log-uniform in `[0.1, 10]`,
//! directions `Z` Gaussian with `‖Z‖_F = 1`. All inputs are rounded to the type under test
//! first; every reference quantity is then computed from that rounded input.
//!
//! # Units of the tolerances
//! Everything is measured against a *scale*: a bound on the magnitude of the terms a kernel
//! sums (not of the result, which may cancel), computed in f64 from the singular values of the
//! input (see [`Geom`]). With `F̂ = JᵃF`, `H = F⁻ᵀ`, `ℓ = ‖F̂‖_F + √d`, `b = Jᵃ(1 + ‖F‖‖H‖/d)`:
//! - `M = μℓ²` bounds `Ψ̂ = μ‖F̂ − R‖²`;
//! - `a_scale = 2μℓ·b` bounds `‖Â‖ = ‖A:𝓑‖` (`‖A‖ ≤ 2μℓ`, `‖𝓑‖ ≤ b`);
//! - `c_scale` bounds `‖Ĉ:Z‖/‖Z‖`, the sum of the bounds of the seed's four terms, with
//!   `‖C‖ ≤ 2μ(1 + 2/min(σ̂ᵢ+σ̂ⱼ))` (`‖δR‖ ≤ 2‖δF‖/min(σ̂ᵢ+σ̂ⱼ)`, from `W_ij` in
//!   `energy::d_rotation`).
//!
//! The rounding error of one kernel evaluation is stated in units of `ε·scale`, times
//! `κ = 2σ_max/min_{i<j}(σᵢ+σⱼ)` for `Â` and `Ĉ:Z`. Derivation: every kernel is a backward
//! stable computation of `F̂` (exact power-of-two scaling, `det`, `cbrt`/`sqrt`) followed by a
//! backward stable SVD of `F̂` (the computed factors are exact for `F̂ + δ`, `‖δ‖ ≲ c_σ ε‖F̂‖`)
//! and a short assembly (sums of ≤ 2d products). The singular values are perfectly conditioned
//! (Weyl: `|δσ| ≤ ‖δ‖`), so `Ψ = μΣ(σ̂ᵢ−1)²` has error `≤ 2μ Σ|σ̂ᵢ−1|·c_σ ε‖F̂‖ ≤ 2√d c_σ ε M`.
//! The rotation `R` is the only ill-conditioned piece: `‖δR‖ ≤ 2‖δ‖/min(σ̂ᵢ+σ̂ⱼ) =
//! c_σ ε κ` (the same `W_ij` bound, scale-free), and it enters `A`, `C` and hence `Â`, `Ĉ:Z`
//! linearly relative to their scales. With `c_σ = 2d` (each computed `σᵢ` and rotation angle
//! passes through ≤ 2d dependent roundings: in 2D sum, square root, product by `Rᵀ`,
//! half-sum; in 3D the Jacobi rotations after the first sweep are within O(ε) of the
//! identity, so each column pair contributes its O(ε) about twice), and a factor 2 for the
//! assembly (sums of ≤ 2d products):
//! - [`k_psi`]` = 2√d·c_σ` ulps of `M` for `Ψ̂`,
//! - [`k_ker`]` = 2c_σ` units of `ε κ a_scale` / `ε κ c_scale ‖Z‖` for `Â` / `Ĉ:Z`.
//!
//! `c_σ` is checked directly for f32 against nalgebra's SVD in f64 (singular values within
//! `c_σ ε ‖F‖₂`, rotation within `c_σ ε κ`), and indirectly by every test below.
//!
//! `c_σ` is the only assumed constant; every test adds the terms its own arithmetic
//! introduces (rounded inputs, products with `Q`, dot products), each derived where used.
//! `𝓑` alone involves no decomposition but `H = F⁻ᵀ`, so its unit is `ε κ₂`,
//! `κ₂ = σ_max/σ_min` (see [`precision::f32_vs_f64`]).
//! Each test prints the largest `error / tolerance` it saw (`--nocapture`).

mod decomposition;
mod identities;
mod precision;
mod scaling;

use decomposition::svd_polar;
use identities::{b_operator, hessian_symmetry, rotation_invariance, scale_identities};
use scaling::{mu_zero, scale_pow10, scale_pow2};

use ampm_core::augmented;
use ampm_core::energy::FixedCorotated;
use ampm_core::polar::{self, DefaultSvd, Polar, Svd, SvdMethod};
use ampm_core::{Error, Mat, Matrix, Real};
use nalgebra::{DMatrix, DVector};
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;

type Res<T> = Result<T, Error>;

/// Number of random inputs per test and type.
const N: usize = 400;

// ---------------------------------------------------------------------------------------------
// The per-type interface: the kernels at the default SVD method, instantiated by a macro.
// ---------------------------------------------------------------------------------------------

/// A matrix type under test with the fixed corotated kernels at the default SVD method.
trait Case: Matrix {
    /// `Ψ̂(F)`.
    fn psi_hat(mu: Self::Scalar, f: &Self) -> Res<Self::Scalar>;
    /// `Â(F)`.
    fn ahat(mu: Self::Scalar, f: &Self) -> Res<Self>;
    /// `Ĉ(F):Z`.
    fn chat_z(mu: Self::Scalar, f: &Self, z: &Self) -> Res<Self>;
    /// The default rotation-variant SVD.
    fn svd(f: &Self) -> Res<Svd<Self>>;
    /// The default polar decomposition.
    fn polar(f: &Self) -> Res<Polar<Self>>;
}

macro_rules! impl_case {
    ($t:ty, $d:literal) => {
        impl Case for Mat<$t, $d> {
            fn psi_hat(mu: $t, f: &Self) -> Res<$t> {
                augmented::psi_hat(&FixedCorotated::new(mu), f)
            }
            fn ahat(mu: $t, f: &Self) -> Res<Self> {
                augmented::ahat(&FixedCorotated::new(mu), f)
            }
            fn chat_z(mu: $t, f: &Self, z: &Self) -> Res<Self> {
                augmented::chat_z(&FixedCorotated::new(mu), f, z)
            }
            fn svd(f: &Self) -> Res<Svd<Self>> {
                DefaultSvd.svd(f)
            }
            fn polar(f: &Self) -> Res<Polar<Self>> {
                polar::polar(f)
            }
        }
    };
}
impl_case!(f32, 2);
impl_case!(f32, 3);
impl_case!(f64, 2);
impl_case!(f64, 3);

// ---------------------------------------------------------------------------------------------
// Conversions, random inputs, norms.
// ---------------------------------------------------------------------------------------------

/// Entry-wise conversion through f64 (exact when widening).
fn cast<A: Matrix, B: Matrix>(m: &A) -> B {
    let mut r = B::zero();
    for j in 0..A::DIM {
        for i in 0..A::DIM {
            r[(i, j)] = B::Scalar::from_f64(m[(i, j)].to_f64());
        }
    }
    r
}

fn to_na<M: Matrix>(m: &M) -> DMatrix<f64> {
    DMatrix::from_fn(M::DIM, M::DIM, |i, j| m[(i, j)].to_f64())
}

/// Rounds an f64 nalgebra matrix to the type under test.
fn from_na<M: Matrix>(m: &DMatrix<f64>) -> M {
    let mut r = M::zero();
    for j in 0..M::DIM {
        for i in 0..M::DIM {
            r[(i, j)] = M::Scalar::from_f64(m[(i, j)]);
        }
    }
    r
}

/// Frobenius norm, in f64.
fn fro<M: Matrix>(m: &M) -> f64 {
    to_na(m).norm()
}

/// Frobenius norm of a difference, in f64 (exact inputs, no cancellation in the type).
fn dist<M: Matrix>(a: &M, b: &M) -> f64 {
    (to_na(a) - to_na(b)).norm()
}

fn eps<M: Matrix>() -> f64 {
    M::Scalar::EPSILON.to_f64()
}

fn dim<M: Matrix>() -> f64 {
    M::DIM as f64
}

/// Standard normal by Box–Muller.
fn gauss(rng: &mut Pcg64) -> f64 {
    let u1: f64 = 1.0 - rng.random::<f64>(); // (0, 1]
    let u2: f64 = rng.random::<f64>();
    (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
}

/// Haar-distributed rotation in SO(d), in f64: QR of a Gaussian matrix with `diag(R) > 0`
/// (Mezzadri 2007: then `Q` is Haar on O(d)); negating one column maps O⁻(d) onto SO(d)
/// preserving the measure.
fn haar(d: usize, rng: &mut Pcg64) -> DMatrix<f64> {
    let qr = DMatrix::from_fn(d, d, |_, _| gauss(rng)).qr();
    let (mut q, r) = (qr.q(), qr.r());
    for j in 0..d {
        if r[(j, j)] < 0.0 {
            q.column_mut(j).neg_mut();
        }
    }
    if q.determinant() < 0.0 {
        q.column_mut(0).neg_mut();
    }
    q
}

fn log_uniform(rng: &mut Pcg64, lo: f64, hi: f64) -> f64 {
    (lo.ln() + (hi.ln() - lo.ln()) * rng.random::<f64>()).exp()
}

/// `U diag(σ) Vᵀ`, `σᵢ` log-uniform in `[0.2, 5]`, rounded to `M`.
fn random_f<M: Matrix>(rng: &mut Pcg64) -> M {
    let d = M::DIM;
    let s = DMatrix::from_diagonal(&DVector::from_fn(d, |_, _| log_uniform(rng, 0.2, 5.0)));
    from_na(&(haar(d, rng) * s * haar(d, rng).transpose()))
}

/// Gaussian direction with `‖Z‖_F = 1` (before rounding).
fn random_z<M: Matrix>(rng: &mut Pcg64) -> M {
    let z = DMatrix::from_fn(M::DIM, M::DIM, |_, _| gauss(rng));
    let n = z.norm();
    from_na(&(z / n))
}

fn random_mu<M: Matrix>(rng: &mut Pcg64) -> M::Scalar {
    M::Scalar::from_f64(log_uniform(rng, 0.1, 10.0))
}

fn random_rotation<M: Matrix>(rng: &mut Pcg64) -> M {
    from_na(&haar(M::DIM, rng))
}

fn seeded(tag: u64) -> Pcg64 {
    Pcg64::seed_from_u64(0xA3_0000 + tag)
}

// ---------------------------------------------------------------------------------------------
// Scales and condition numbers of one input (f64, from nalgebra's SVD of the rounded input).
// ---------------------------------------------------------------------------------------------

/// Geometry of one `F` (with `J > 0`) and the scales of the module docs.
#[derive(Clone, Copy, Debug)]
struct Geom {
    /// `2σ_max / min_{i<j}(σᵢ + σⱼ)`: condition of the polar rotation.
    kappa: f64,
    /// `σ_max / σ_min`: condition of `F` (and of `H = F⁻ᵀ`).
    kappa2: f64,
    /// `σ_min`: distance to the nearest singular matrix.
    smin: f64,
    /// `‖F‖_F`.
    f_fro: f64,
    /// Bound of `‖𝓑‖` (and `Jᵃ(1 + ‖F‖‖H‖/d)`).
    b: f64,
    /// `M`, bound of `Ψ̂`.
    psi: f64,
    /// Bound of `‖Â‖`.
    ahat: f64,
    /// Bound of `‖Ĉ:Z‖ / ‖Z‖`.
    chat: f64,
}

fn geom<M: Matrix>(f: &M, mu: f64) -> Geom {
    let d = dim::<M>();
    let fa = to_na(f);
    let s: Vec<f64> = fa
        .clone()
        .svd(false, false)
        .singular_values
        .iter()
        .copied()
        .collect();
    let n = s.len();
    let (smax, smin) = (s[0], s[n - 1]);
    let pair_min = s[n - 2] + s[n - 1];
    let ja = s.iter().product::<f64>().powf(-1.0 / d);
    let f_fro = fa.norm();
    let h_fro = s.iter().map(|x| x.powi(-2)).sum::<f64>().sqrt();
    let ell = ja * f_fro + d.sqrt();
    let b = ja * (1.0 + f_fro * h_fro / d);
    let a_norm = 2.0 * mu * ell;
    let ahat = a_norm * b;
    let c_norm = 2.0 * mu * (1.0 + 2.0 / (ja * pair_min));
    // The seed's four terms: (C:(𝓑:Z)):𝓑, a(H:Z)Â, aJᵃ(A:Z)H, aJᵃ(A:F)HZᵀH.
    let chat = c_norm * b * b
        + h_fro / d * ahat
        + ja / d * a_norm * h_fro
        + ja / d * a_norm * f_fro * h_fro * h_fro;
    Geom {
        kappa: 2.0 * smax / pair_min,
        kappa2: smax / smin,
        smin,
        f_fro,
        b,
        psi: mu * ell * ell,
        ahat,
        chat,
    }
}

/// Backward error constant of the default SVD: the computed factors are exact for `F + δ`,
/// `‖δ‖ ≤ c_σ ε ‖F‖` (module docs), `c_σ = 2d`.
fn c_sigma<M: Matrix>() -> f64 {
    2.0 * dim::<M>()
}

/// Rounding constant of `Ψ̂` in units of `ε M` (module docs: `2√d·c_σ`).
fn k_psi<M: Matrix>() -> f64 {
    2.0 * dim::<M>().sqrt() * c_sigma::<M>()
}

/// Rounding constant of `Â`, `Ĉ:Z` in units of `ε κ scale` (module docs: `2 c_σ`).
fn k_ker<M: Matrix>() -> f64 {
    2.0 * c_sigma::<M>()
}

/// Tracks the largest `error / tolerance` of each check of a test; fails on a ratio above 1.
struct Worst {
    name: String,
    max: std::collections::BTreeMap<String, f64>,
}

impl Worst {
    fn new<M: Matrix>(test: &str) -> Self {
        Self {
            name: format!("{test} [{}d {}]", M::DIM, M::Scalar::NAME),
            max: Default::default(),
        }
    }

    #[track_caller]
    fn check(&mut self, what: &str, err: f64, tol: f64, ctx: &dyn std::fmt::Debug) {
        assert!(
            err <= tol,
            "{}: {what}: error {err:e} > tolerance {tol:e} (ratio {:.3})\n{ctx:#?}",
            self.name,
            err / tol
        );
        let m = self.max.entry(what.to_string()).or_insert(0.0);
        *m = m.max(err / tol);
    }

    fn report(&self) {
        let parts: Vec<String> = self
            .max
            .iter()
            .map(|(k, v)| format!("{k} {v:.3}"))
            .collect();
        eprintln!("{}: max error/tolerance: {}", self.name, parts.join(", "));
    }
}

// ---------------------------------------------------------------------------------------------
// 9. glam conversions.
// ---------------------------------------------------------------------------------------------

/// `Mat ↔ glam` round-trips exactly and keeps the column-major layout:
/// `glam.col(j)[i] = M_ij`.
macro_rules! glam_roundtrip {
    ($name:ident, $t:ty, $d:literal, $g:ty) => {
        #[test]
        fn $name() {
            let mut rng = seeded(200 + $d);
            for _ in 0..N {
                let m: Mat<$t, $d> = random_f(&mut rng);
                let gm: $g = m.into();
                for j in 0..$d {
                    for i in 0..$d {
                        assert_eq!(gm.col(j)[i].to_bits(), m[(i, j)].to_bits());
                        assert_eq!(gm.row(i)[j].to_bits(), m[(i, j)].to_bits());
                    }
                }
                let back: Mat<$t, $d> = gm.into();
                assert_eq!(back, m);
                assert_eq!(<$g>::from_cols_array(&m.to_array()), gm);
            }
        }
    };
}
glam_roundtrip!(glam_mat2, f32, 2, glam::Mat2);
glam_roundtrip!(glam_mat3, f32, 3, glam::Mat3);
glam_roundtrip!(glam_dmat2, f64, 2, glam::DMat2);
glam_roundtrip!(glam_dmat3, f64, 3, glam::DMat3);

// ---------------------------------------------------------------------------------------------
// Instantiation: one module per type.
// ---------------------------------------------------------------------------------------------

macro_rules! all_types {
    ($($m:ident: $t:ty, $d:literal;)*) => {$(
        mod $m {
            use super::*;
            type M = Mat<$t, $d>;
            #[test]
            fn hessian_is_symmetric() {
                hessian_symmetry::<M>();
            }
            #[test]
            fn scale_invariance_identities() {
                scale_identities::<M>();
            }
            #[test]
            fn rotation_invariance_left_and_right() {
                rotation_invariance::<M>();
            }
            #[test]
            fn b_adjoint_and_index_formula() {
                b_operator::<M>();
            }
            #[test]
            fn scale_by_powers_of_two_is_exact() {
                scale_pow2::<M>();
            }
            #[test]
            fn scale_by_powers_of_ten() {
                scale_pow10::<M>();
            }
            #[test]
            fn mu_zero_is_zero() {
                mu_zero::<M>();
            }
            #[test]
            fn svd_and_polar() {
                svd_polar::<M>();
            }
        }
    )*};
}
all_types! {
    f32_2d: f32, 2;
    f32_3d: f32, 3;
    f64_2d: f64, 2;
    f64_3d: f64, 3;
}
