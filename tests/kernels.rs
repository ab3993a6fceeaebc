//! Integration tests of the core kernels (`ampm_core::augmented`, `ampm_core::polar`) with the
//! fixed corotated base energy, generated for 2D/3D × f32/f64 from one generic source.
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
//! `κ₂ = σ_max/σ_min` (see [`f32_vs_f64`]).
//! Each test prints the largest `error / tolerance` it saw (`--nocapture`).

use ampm_core::augmented::{self, Kinematics};
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
// 1. Finite differences (f64) and f32 against f64.
// ---------------------------------------------------------------------------------------------

/// `Â:Z` against the central difference of `Ψ̂`, and `Ĉ:Z` against that of `Â` (f64).
///
/// Derivation of the tolerance. `φ(t) = Ψ̂(F + tZ)`, `‖Z‖ = 1`. Central difference:
/// `(φ(h) − φ(−h))/2h = φ'(0) + h²φ'''(ξ)/6`. `Ψ̂` is analytic in a ball of radius `σ_min`
/// around `F` (the nearest singular matrix, where `H` and `Jᵃ` blow up; the polar kink
/// `σᵢ+σⱼ = 0` is farther) and bounded by `M` there, so by the Cauchy estimates its k-th
/// directional derivative is `≲ k!·M/σ_min^k`. Each evaluation carries the rounding error
/// `k_psi·ε·M`, which the quotient divides by `h` (two evaluations over `2h`). With
/// `h = ε^{1/3} σ_min` (the optimum up to a constant, balancing `h²` against `ε/h`):
///   `|fd − Â:Z| ≤ ε^{2/3} (1 + k_psi) M/σ_min`.
/// Same for `Â` one order up: truncation `h²/6 · 4! M/σ_min⁴`, rounding `k_ker ε κ a_scale/h`:
///   `‖fd − Ĉ:Z‖ ≤ ε^{2/3} (4 M/σ_min² + k_ker κ a_scale/σ_min)`.
/// The steps are taken exactly: `F± = fl(F ± hZ)` and the direction is `Z' = (F₊ − F₋)/2h`
/// (each entry's error ≤ ε relative), so the rounding of `F ± hZ` does not enter divided by
/// `h`; the midpoint `(F₊+F₋)/2` is within `ε‖F‖` of `F`, which moves the derivative by at
/// most `ε‖F‖·(next scale)`, added below with the kernel's own `O(ε)` error.
fn fd_check<M: Case<Scalar = f64>>() {
    let mut rng = seeded(1 + M::DIM as u64);
    let mut w_a = Worst::new::<M>("fd: Â:Z vs Ψ̂");
    let mut w_c = Worst::new::<M>("fd: Ĉ:Z vs Â");
    let e = eps::<M>();
    let e23 = e.powf(2.0 / 3.0);
    for _ in 0..N {
        let f: M = random_f(&mut rng);
        let z: M = random_z(&mut rng);
        let mu = random_mu::<M>(&mut rng);
        let g = geom(&f, mu);
        let h = e.powf(1.0 / 3.0) * g.smin;
        let (fp, fm) = (f + z * h, f - z * h);
        let zd = (fp - fm) * (0.5 / h);
        let nz = fro(&zd);

        let fd = (M::psi_hat(mu, &fp).unwrap() - M::psi_hat(mu, &fm).unwrap()) / (2.0 * h);
        let an = M::ahat(mu, &f).unwrap().ddot(&zd);
        let tol = e23 * (1.0 + k_psi::<M>()) * g.psi / g.smin * nz.powi(3)
            + e * (k_ker::<M>() * g.kappa * g.ahat + g.f_fro * g.chat) * nz;
        w_a.check("Â:Z", (fd - an).abs(), tol, &(f, z, mu));

        let fd = (M::ahat(mu, &fp).unwrap() - M::ahat(mu, &fm).unwrap()) * (0.5 / h);
        let an = M::chat_z(mu, &f, &zd).unwrap();
        let s3 = 3.0 * g.chat / g.smin; // third-derivative scale, Cauchy as above
        let tol = e23
            * (4.0 * g.psi / (g.smin * g.smin) * nz.powi(3)
                + k_ker::<M>() * g.kappa * g.ahat / g.smin * nz)
            + e * (k_ker::<M>() * g.kappa * g.chat + g.f_fro * s3) * nz;
        w_c.check("Ĉ:Z", dist(&fd, &an), tol, &(f, z, mu));
    }
    w_a.report();
    w_c.report();
}

/// The f32 kernels against the f64 kernels on the same (f32) input, `ε = ε_f32`.
///
/// The f64 result is exact to `ε_f64 κ` (1e-16 relative at worst here), so the difference is
/// the f32 kernel's own error, bounded (module docs) by `k_psi ε M`, `k_ker ε κ a_scale`,
/// `k_ker ε κ c_scale ‖Z‖`. `𝓑:Z` and `Z:𝓑` involve no decomposition but `H = cof(G)/det G`,
/// whose relative error is `O(ε κ₂)` (`κ₂ = σ_max/σ_min`, the condition of the inverse);
/// `‖𝓑:Z‖ ≤ b‖Z‖` term by term, so they get `k_ker ε κ₂ b ‖Z‖`.
fn f32_vs_f64<M: Case<Scalar = f32>, W: Case<Scalar = f64>>() {
    let mut rng = seeded(10 + M::DIM as u64);
    let mut w = Worst::new::<M>("f32 vs f64");
    let e = eps::<M>();
    for _ in 0..N {
        let f: M = random_f(&mut rng);
        let z: M = random_z(&mut rng);
        let mu = random_mu::<M>(&mut rng);
        let (fw, zw, muw): (W, W, f64) = (cast(&f), cast(&z), mu.to_f64());
        let g = geom(&f, muw);
        let nz = fro(&z);
        let ctx = (f, z, mu);

        let p = M::psi_hat(mu, &f).unwrap().to_f64();
        let pw = W::psi_hat(muw, &fw).unwrap();
        w.check("Ψ̂", (p - pw).abs(), k_psi::<M>() * e * g.psi, &ctx);

        let a: W = cast(&M::ahat(mu, &f).unwrap());
        let aw = W::ahat(muw, &fw).unwrap();
        w.check(
            "Â",
            dist(&a, &aw),
            k_ker::<M>() * e * g.kappa * g.ahat,
            &ctx,
        );

        let c: W = cast(&M::chat_z(mu, &f, &z).unwrap());
        let cw = W::chat_z(muw, &fw, &zw).unwrap();
        let tol = k_ker::<M>() * e * g.kappa * g.chat * nz;
        w.check("Ĉ:Z", dist(&c, &cw), tol, &ctx);

        let tol = k_ker::<M>() * e * g.kappa2 * g.b * nz;
        let bz: W = cast(&augmented::b_z(&f, &z).unwrap());
        w.check(
            "𝓑:Z",
            dist(&bz, &augmented::b_z(&fw, &zw).unwrap()),
            tol,
            &ctx,
        );
        let zb: W = cast(&augmented::z_b(&f, &z).unwrap());
        w.check(
            "Z:𝓑",
            dist(&zb, &augmented::z_b(&fw, &zw).unwrap()),
            tol,
            &ctx,
        );
    }
    w.report();
}

// ---------------------------------------------------------------------------------------------
// 2. Symmetry of the Hessian.
// ---------------------------------------------------------------------------------------------

/// `Y:(Ĉ:Z) = Z:(Ĉ:Y)`: `Ĉ` is a Hessian. Each side differs from the exact value by
/// `‖Y‖·k_ker ε κ c_scale ‖Z‖` (kernel) plus the dot product's `d² ε ‖Y‖‖Ĉ:Z‖`.
fn hessian_symmetry<M: Case>() {
    let mut rng = seeded(20 + M::DIM as u64 + 100 * M::Scalar::MANTISSA_DIGITS as u64);
    let mut w = Worst::new::<M>("Hessian symmetry");
    let e = eps::<M>();
    let d = dim::<M>();
    for _ in 0..N {
        let f: M = random_f(&mut rng);
        let (y, z): (M, M) = (random_z(&mut rng), random_z(&mut rng));
        let mu = random_mu::<M>(&mut rng);
        let g = geom(&f, mu.to_f64());
        let yz = y.ddot(&M::chat_z(mu, &f, &z).unwrap()).to_f64();
        let zy = z.ddot(&M::chat_z(mu, &f, &y).unwrap()).to_f64();
        let tol = 2.0 * (k_ker::<M>() * g.kappa + d * d) * e * g.chat * fro(&y) * fro(&z);
        w.check("Y:(Ĉ:Z) − Z:(Ĉ:Y)", (yz - zy).abs(), tol, &(f, y, z, mu));
    }
    w.report();
}

// ---------------------------------------------------------------------------------------------
// 3. Identities of a scale-invariant energy.
// ---------------------------------------------------------------------------------------------

/// Scale invariance and its consequences, for random `s ∈ [1/4, 4]` (not a power of two).
///
/// Derivations (a = −1/d):
/// - `Ψ̂(sF) = Ψ̂(F)`: `det(sF) = sᵈ J`, so `(det sF)ᵃ sF = s^{−1} J^a s F = JᵃF`.
/// - `F:Â(F) = 0`: differentiate `Ψ̂(sF) = Ψ̂(F)` in `s` at `s = 1`:
///   `d/ds Ψ̂(sF) = Â(sF):F = 0`.
/// - `Â(sF) = Â(F)/s`: differentiate `Ψ̂(sF) = Ψ̂(F)` in `F`: `s·Â(sF) = Â(F)`.
/// - `Ĉ(F):F = −Â(F)`: differentiate `Â(sF) = Â(F)/s` in `s` at 1; the left side gives
///   `Ĉ(F):F` (`Ĉ:Z` is the derivative of `Â` in direction `Z`), the right `−Â(F)`.
///   (It also follows from the seed's formula: `𝓑:F = Jᵃ(F + a·d·F) = 0` kills the first
///   term, `a(H:F)Â = a·d·Â = −Â`, and `HFᵀH = H` makes the last two cancel.)
/// - `F:(Ĉ(F):F) = −F:Â(F) = 0`.
///
/// Tolerances: `sF` is rounded (`‖ΔF‖ ≤ ε/2‖sF‖`), which moves `Ψ̂`, `Â`, `Ĉ:Z` by at most
/// `ε/2·‖F‖` times the next scale (`a_scale`, `c_scale`, `3 c_scale/σ_min`), measured at `F`
/// (all three are homogeneous of degrees 0, −1, −2, like the quantities compared); the
/// products by `s` and `1/s` are rounded (`ε/2` relative each); the kernels add `k_psi ε M`,
/// `k_ker ε κ scale` per evaluation; a dot product with `F` adds `d² ε ‖F‖·‖·‖`.
fn scale_identities<M: Case>() {
    let mut rng = seeded(30 + M::DIM as u64 + 100 * M::Scalar::MANTISSA_DIGITS as u64);
    let mut w = Worst::new::<M>("scale identities");
    let e = eps::<M>();
    let d = dim::<M>();
    let (kp, kk) = (k_psi::<M>(), k_ker::<M>());
    for _ in 0..N {
        let f: M = random_f(&mut rng);
        let z: M = random_z(&mut rng);
        let mu = random_mu::<M>(&mut rng);
        let s = M::Scalar::from_f64(log_uniform(&mut rng, 0.25, 4.0));
        let sf = f * s;
        let g = geom(&f, mu.to_f64());
        let (nf, nz) = (g.f_fro, fro(&z));
        let ctx = (f, z, mu, s);
        let ka = kk * g.kappa;

        let p = M::psi_hat(mu, &f).unwrap().to_f64();
        let ps = M::psi_hat(mu, &sf).unwrap().to_f64();
        let tol = 0.5 * e * nf * g.ahat + 2.0 * kp * e * g.psi;
        w.check("Ψ̂(sF) − Ψ̂(F)", (ps - p).abs(), tol, &ctx);

        let a = M::ahat(mu, &f).unwrap();
        let tol = (ka + d * d) * e * nf * g.ahat;
        w.check("F:Â", f.ddot(&a).to_f64().abs(), tol, &ctx);

        let as_ = M::ahat(mu, &sf).unwrap() * s;
        let tol = 0.5 * e * nf * g.chat + (2.0 * ka + 1.0) * e * g.ahat;
        w.check("s·Â(sF) − Â(F)", dist(&as_, &a), tol, &ctx);

        let s2 = s * s;
        let cs = M::chat_z(mu, &sf, &z).unwrap() * s2;
        let c = M::chat_z(mu, &f, &z).unwrap();
        let tol = (0.5 * e * nf * 3.0 * g.chat / g.smin + (2.0 * ka + 2.0) * e * g.chat) * nz;
        w.check("s²·Ĉ(sF):Z − Ĉ(F):Z", dist(&cs, &c), tol, &ctx);

        let cf = M::chat_z(mu, &f, &f).unwrap();
        let tol = ka * e * (g.chat * nf + g.ahat);
        w.check("Ĉ:F + Â", dist(&(cf + a), &M::zero()), tol, &ctx);

        let tol = (ka + d * d) * e * nf * g.chat * nf;
        w.check("F:(Ĉ:F)", f.ddot(&cf).to_f64().abs(), tol, &ctx);
    }
    w.report();
}

// ---------------------------------------------------------------------------------------------
// 4. Rotation invariance.
// ---------------------------------------------------------------------------------------------

/// `Ψ̂(QF) = Ψ̂(F)`, `Â(QF) = QÂ(F)`, `Ĉ(QF):(QZ) = Q(Ĉ(F):Z)` (differentiate the first
/// in `F` along `δF`: `Â(QF):QδF = Â(F):δF`, then the second along `δF`), and the same on the
/// right for the isotropic `Ψ̂`: `Ψ̂(FQ) = Ψ̂(F)`, `Â(FQ) = Â(F)Q`, `Ĉ(FQ):(ZQ) = (Ĉ(F):Z)Q`.
///
/// Tolerances: `Q` is rounded to the type (`‖Q − Q₀‖_F ≤ √d ε/2` for an exact rotation
/// `Q₀`), and every product with it is a `d`-term dot product per entry (error
/// `≤ γ_d |Q||X|`, `‖|Q|‖₂ ≤ √d`): each product `QX` is within `ρ ε ‖X‖` of `Q₀X`,
/// `ρ = d√d + √d`. A perturbation of `F` by `ρε‖F‖` moves `Ψ̂`, `Â`, `Ĉ:Z` by the next scale
/// times it (`a_scale`, `c_scale`, `3 c_scale/σ_min`); perturbing `Z` or an output by `ρε`
/// relative moves `Ĉ:Z` or `Â` by `ρε` times their scale; plus both kernels' errors.
fn rotation_invariance<M: Case>() {
    let mut rng = seeded(40 + M::DIM as u64 + 100 * M::Scalar::MANTISSA_DIGITS as u64);
    let mut w = Worst::new::<M>("rotation invariance");
    let e = eps::<M>();
    let d = dim::<M>();
    let rho = d * d.sqrt() + d.sqrt();
    let (kp, kk) = (k_psi::<M>(), k_ker::<M>());
    for _ in 0..N {
        let f: M = random_f(&mut rng);
        let z: M = random_z(&mut rng);
        let q: M = random_rotation(&mut rng);
        let mu = random_mu::<M>(&mut rng);
        let g = geom(&f, mu.to_f64());
        let (nf, nz) = (g.f_fro, fro(&z));
        let ctx = (f, z, q, mu);
        let ka = kk * g.kappa;
        let p = M::psi_hat(mu, &f).unwrap().to_f64();
        let a = M::ahat(mu, &f).unwrap();
        let c = M::chat_z(mu, &f, &z).unwrap();
        let tol_p = rho * e * nf * g.ahat + 2.0 * kp * e * g.psi;
        let tol_a = rho * e * nf * g.chat + (2.0 * ka + rho) * e * g.ahat;
        let tol_c =
            (rho * e * nf * 3.0 * g.chat / g.smin + (2.0 * ka + 2.0 * rho) * e * g.chat) * nz;
        for side in ["left", "right"] {
            let rot = |x: &M| if side == "left" { q * *x } else { *x * q };
            let fq = rot(&f);
            let pq = M::psi_hat(mu, &fq).unwrap().to_f64();
            w.check(&format!("Ψ̂ ({side})"), (pq - p).abs(), tol_p, &ctx);
            let aq = M::ahat(mu, &fq).unwrap();
            w.check(&format!("Â ({side})"), dist(&aq, &rot(&a)), tol_a, &ctx);
            let cq = M::chat_z(mu, &fq, &rot(&z)).unwrap();
            w.check(&format!("Ĉ:Z ({side})"), dist(&cq, &rot(&c)), tol_c, &ctx);
        }
    }
    w.report();
}

// ---------------------------------------------------------------------------------------------
// 5. 𝓑: adjointness and the seed's index formula.
// ---------------------------------------------------------------------------------------------

/// `Y:(𝓑:Z) = (Y:𝓑):Z`, and both actions against `𝓑_kmij = Jᵃδ_ikδ_jm + aJᵃF_kmH_ij`
/// contracted with explicit loops (`(𝓑:Z)_km = Σ_ij 𝓑_kmij Z_ij`,
/// `(Z:𝓑)_ij = Σ_km Z_km 𝓑_kmij`), with `J` and `H = F⁻ᵀ` from nalgebra's LU in f64.
///
/// Tolerance: the kernels' `H = cof(G)/det G` has relative error `O(ε κ₂)` (module docs),
/// so each action is within `k_ker ε κ₂ b ‖Z‖`; the reference is f64 (same bound at
/// `ε_f64`); a dot product adds `d² ε ‖Y‖ b ‖Z‖`.
fn b_operator<M: Case>() {
    let mut rng = seeded(50 + M::DIM as u64 + 100 * M::Scalar::MANTISSA_DIGITS as u64);
    let mut w = Worst::new::<M>("𝓑 adjoint and index formula");
    let e = eps::<M>();
    let n = M::DIM;
    let d = dim::<M>();
    for _ in 0..N {
        let f: M = random_f(&mut rng);
        let (y, z): (M, M) = (random_z(&mut rng), random_z(&mut rng));
        let g = geom(&f, 1.0);
        let (ny, nz) = (fro(&y), fro(&z));
        let ctx = (f, y, z);
        let kin = Kinematics::new(&f).unwrap();
        let bz = kin.b_z(&z).unwrap();
        let yb = kin.z_b(&y).unwrap();
        let lhs = y.ddot(&bz).to_f64();
        let rhs = yb.ddot(&z).to_f64();
        let tol = 2.0 * (k_ker::<M>() * g.kappa2 + d * d) * e * g.b * ny * nz;
        w.check("Y:(𝓑:Z) − (Y:𝓑):Z", (lhs - rhs).abs(), tol, &ctx);

        let fa = to_na(&f);
        let j = fa.determinant();
        let h = fa.clone().try_inverse().unwrap().transpose();
        let a = -1.0 / d;
        let ja = j.powf(a);
        let delta = |p: usize, q: usize| if p == q { 1.0 } else { 0.0 };
        let b4 = |k: usize, m: usize, i: usize, jj: usize| {
            ja * delta(i, k) * delta(jj, m) + a * ja * fa[(k, m)] * h[(i, jj)]
        };
        let (za, ya) = (to_na(&z), to_na(&y));
        let mut bz_ref = DMatrix::zeros(n, n);
        let mut yb_ref = DMatrix::zeros(n, n);
        for k in 0..n {
            for m in 0..n {
                for i in 0..n {
                    for jj in 0..n {
                        bz_ref[(k, m)] += b4(k, m, i, jj) * za[(i, jj)];
                        yb_ref[(i, jj)] += ya[(k, m)] * b4(k, m, i, jj);
                    }
                }
            }
        }
        let tol = 2.0 * k_ker::<M>() * e * g.kappa2 * g.b;
        w.check(
            "𝓑:Z vs index formula",
            (to_na(&bz) - bz_ref).norm(),
            tol * nz,
            &ctx,
        );
        w.check(
            "Y:𝓑 vs index formula",
            (to_na(&yb) - yb_ref).norm(),
            tol * ny,
            &ctx,
        );
    }
    w.report();
}

// ---------------------------------------------------------------------------------------------
// 6. Scale robustness: powers of two (exact) and of ten; overflow.
// ---------------------------------------------------------------------------------------------

/// `x · 2ᵉ` with one rounding (libm's `scalbn`), inf on overflow.
fn scalbn_mat<M: Matrix>(m: &M, e: i32) -> M {
    m.map(|x| x.scalbn(e))
}

/// Expected result `x_ref · 2ᵉ` of a kernel whose result is exactly `2ᵉ` times the reference:
/// `Err(Overflow)` when that overflows, else every entry equal, except that a subnormal entry
/// may differ by one unit of the subnormal spacing (the kernel scales in two steps, which may
/// round twice below `MIN_POSITIVE`; the exact value is not representable there anyway).
#[track_caller]
fn assert_scaled<M: Matrix>(got: Res<M>, reference: &M, e: i32, ctx: &dyn std::fmt::Debug) {
    let want = scalbn_mat(reference, e);
    if !want.is_finite() {
        assert_eq!(got, Err(Error::Overflow), "2^{e} · {reference:?}\n{ctx:#?}");
        return;
    }
    let got = got.unwrap_or_else(|err| panic!("{err:?} for 2^{e} · {reference:?}\n{ctx:#?}"));
    let tiny = M::Scalar::MIN_POSITIVE.to_f64() * eps::<M>(); // subnormal spacing
    for j in 0..M::DIM {
        for i in 0..M::DIM {
            let (g, w) = (got[(i, j)], want[(i, j)]);
            let ok = if w.abs() >= M::Scalar::MIN_POSITIVE {
                g.to_f64().to_bits() == w.to_f64().to_bits()
            } else {
                (g.to_f64() - w.to_f64()).abs() <= tiny
            };
            assert!(ok, "entry ({i},{j}): {g:?} != {w:?} (2^{e})\n{ctx:#?}");
        }
    }
}

/// `F = 2ᵏ G`: `Ψ̂(F) = Ψ̂(G)`, `Â(F) = 2⁻ᵏ Â(G)`, `Ĉ(F):Z = 2⁻²ᵏ Ĉ(G):Z`, bit for bit, for
/// `k` across the whole exponent range (f64: `1e-150 … 1e150` densely, then out to the
/// subnormals and near `MAX`; f32: `1e-18 … 1e18`, then out). Where `2⁻ᵏÂ(G)` or
/// `2⁻²ᵏĈ(G):Z` overflows, the kernel must return `Error::Overflow`, never inf or NaN.
///
/// The kernels pre-scale by a power of two, so `F` and `G` are reduced to the same matrix
/// and every bit of the result must agree. When `2ᵏG` is subnormal it is rounded: then `G`
/// is replaced by `G' = 2⁻ᵏ F` (exact), the matrix `F` actually represents.
fn scale_pow2<M: Case>() {
    let mut rng = seeded(60 + M::DIM as u64 + 100 * M::Scalar::MANTISSA_DIGITS as u64);
    let wide = M::Scalar::MANTISSA_DIGITS > 24;
    // 2^498 ≈ 1e150, 2^59 ≈ 1e18.
    let (span, extremes): (i32, &[i32]) = if wide {
        (
            498,
            &[
                -1060, -1040, -1022, -1000, -700, -600, -540, -520, 520, 700, 1000, 1020,
            ],
        )
    } else {
        (
            59,
            &[
                -140, -130, -126, -100, -80, -66, -62, 62, 66, 80, 100, 120, 125,
            ],
        )
    };
    let mut ks: Vec<i32> = (-span..=span).step_by(if wide { 17 } else { 3 }).collect();
    ks.extend_from_slice(extremes);
    let (mut n_overflow, mut n_ok) = (0, 0);
    for _ in 0..N / 8 {
        let g: M = random_f(&mut rng);
        let z: M = random_z(&mut rng);
        let mu = random_mu::<M>(&mut rng);
        for &k in &ks {
            let f = scalbn_mat(&g, k);
            if !f.is_finite() {
                continue;
            }
            let g1 = scalbn_mat(&f, -k); // = g unless f is subnormal
            let ctx = (g, z, mu, k);
            let Ok(p) = M::psi_hat(mu, &g1) else {
                // G' lost its positive determinant to the subnormal rounding: F must agree.
                assert_eq!(M::psi_hat(mu, &f), M::psi_hat(mu, &g1), "{ctx:?}");
                continue;
            };
            let pf = M::psi_hat(mu, &f).unwrap();
            assert_eq!(pf.to_f64().to_bits(), p.to_f64().to_bits(), "Ψ̂ {ctx:?}");
            let a = M::ahat(mu, &g1).unwrap();
            let af = M::ahat(mu, &f);
            n_overflow += usize::from(af.is_err());
            n_ok += usize::from(af.is_ok());
            assert_scaled(af, &a, -k, &ctx);
            let c = M::chat_z(mu, &g1, &z).unwrap();
            assert_scaled(M::chat_z(mu, &f, &z), &c, -2 * k, &ctx);
        }
    }
    // The extremes must reach both outcomes, or the test proves nothing about overflow.
    assert!(
        n_overflow > 0 && n_ok > 0,
        "{n_overflow} overflows, {n_ok} ok"
    );
}

/// `F = fl(10ᵏ G)`: the same identities to rounding accuracy (f64: `k ∈ [−150, 150]`, f32:
/// `[−18, 18]`), plus beyond, where the result must be `Error::Overflow` when its magnitude
/// exceeds `MAX` (checked only outside a band of the tolerance around `MAX`).
///
/// Tolerances as in [`scale_identities`] (input rounding `ε/2‖F‖`, kernel errors), with the
/// comparison done in f64 (`10ᵏ`, `10²ᵏ` and the products exact to `ε_f64`); a result entry
/// that is subnormal also carries an absolute error of one subnormal spacing (two roundings:
/// see [`assert_scaled`]), scaled back by `s` or `s²`.
fn scale_pow10<M: Case>() {
    let mut rng = seeded(70 + M::DIM as u64 + 100 * M::Scalar::MANTISSA_DIGITS as u64);
    let mut w = Worst::new::<M>("powers of ten");
    let wide = M::Scalar::MANTISSA_DIGITS > 24;
    let (span, extremes): (i32, &[i32]) = if wide {
        (150, &[-200, -160, 160, 200, 300])
    } else {
        (18, &[-30, -22, -20, 20, 22, 30])
    };
    let e = eps::<M>();
    let (kp, kk) = (k_psi::<M>(), k_ker::<M>());
    let max = M::Scalar::MAX.to_f64();
    let under = M::Scalar::MIN_POSITIVE.to_f64() * e * dim::<M>();
    let mut ks: Vec<i32> = (-span..=span).step_by(if wide { 5 } else { 1 }).collect();
    ks.extend_from_slice(extremes);
    let mut n_overflow = 0;
    for _ in 0..N / 8 {
        let g: M = random_f(&mut rng);
        let z: M = random_z(&mut rng);
        let mu = random_mu::<M>(&mut rng);
        let geo = geom(&g, mu.to_f64());
        let nz = fro(&z);
        let ka = kk * geo.kappa;
        let p = M::psi_hat(mu, &g).unwrap().to_f64();
        let a = to_na(&M::ahat(mu, &g).unwrap());
        let c = to_na(&M::chat_z(mu, &g, &z).unwrap());
        for &k in &ks {
            let s = 10f64.powi(k);
            let f = g * M::Scalar::from_f64(s);
            let ctx = (g, z, mu, k);
            let pf = M::psi_hat(mu, &f).unwrap().to_f64();
            let tol = 0.5 * e * geo.f_fro * geo.ahat + 2.0 * kp * e * geo.psi;
            w.check("Ψ̂(sG) − Ψ̂(G)", (pf - p).abs(), tol, &ctx);

            let rel_a = (0.5 * e * geo.f_fro * geo.chat + 2.0 * ka * e * geo.ahat) / a.norm();
            let want_a = a.amax() / s;
            match M::ahat(mu, &f) {
                Ok(af) => {
                    assert!(want_a <= max * (1.0 + rel_a), "Â should overflow {ctx:?}");
                    let tol = rel_a * a.norm() + under * s;
                    w.check("s·Â(sG) − Â(G)", (to_na(&af) * s - &a).norm(), tol, &ctx);
                }
                Err(err) => {
                    assert_eq!(err, Error::Overflow, "{ctx:?}");
                    assert!(want_a >= max * (1.0 - rel_a), "spurious overflow {ctx:?}");
                    n_overflow += 1;
                }
            }
            let s3 = 3.0 * geo.chat / geo.smin;
            let abs_c = (0.5 * e * geo.f_fro * s3 + 2.0 * ka * e * geo.chat) * nz;
            let rel_c = abs_c / c.norm();
            let want_c = c.amax() / (s * s);
            match M::chat_z(mu, &f, &z) {
                Ok(cf) if !(s * s).is_finite() => {
                    // s² > f64::MAX: the result is below the smallest normal, all underflow.
                    let tiny = M::Scalar::MIN_POSITIVE.to_f64();
                    assert!(cf.max_abs().to_f64() <= tiny, "{cf:?} {ctx:?}");
                }
                Ok(cf) => {
                    assert!(want_c <= max * (1.0 + rel_c), "Ĉ should overflow {ctx:?}");
                    let tol = abs_c + under * s * s;
                    w.check(
                        "s²·Ĉ(sG):Z − Ĉ(G):Z",
                        (to_na(&cf) * (s * s) - &c).norm(),
                        tol,
                        &ctx,
                    );
                }
                Err(err) => {
                    assert_eq!(err, Error::Overflow, "{ctx:?}");
                    assert!(want_c >= max * (1.0 - rel_c), "spurious overflow {ctx:?}");
                    n_overflow += 1;
                }
            }
        }
    }
    assert!(n_overflow > 0, "the extremes never overflowed");
    w.report();
}

// ---------------------------------------------------------------------------------------------
// 7. μ = 0.
// ---------------------------------------------------------------------------------------------

/// A liquid (`μ = 0`): `Ψ̂ = 0`, `Â = 0`, `Ĉ:Z = 0` exactly, for any valid `F` — including a
/// subnormal one, whose zero result is representable (not an overflow); likewise `Ĉ:0 = 0`
/// for any `μ`; an invalid `F` is still refused.
fn mu_zero<M: Case>() {
    let mut rng = seeded(80 + M::DIM as u64 + 100 * M::Scalar::MANTISSA_DIGITS as u64);
    let zero = M::Scalar::ZERO;
    // Largest entry of G in [0.25, 5]; 2^-(MANTISSA+…) makes F subnormal with ≥ 10 bits.
    let sub = if M::Scalar::MANTISSA_DIGITS > 24 {
        -1050
    } else {
        -135
    };
    for i in 0..N {
        let g: M = random_f(&mut rng);
        let z: M = random_z(&mut rng);
        let f = if i % 4 == 3 { scalbn_mat(&g, sub) } else { g };
        assert_eq!(M::psi_hat(zero, &f), Ok(zero), "{f:?}");
        assert_eq!(M::ahat(zero, &f), Ok(M::zero()), "{f:?}");
        assert_eq!(M::chat_z(zero, &f, &z), Ok(M::zero()), "{f:?} {z:?}");
        // Ĉ:0 = 0 for any μ, also representable for a subnormal F.
        let mu = random_mu::<M>(&mut rng);
        assert_eq!(
            M::chat_z(mu, &f, &M::zero()),
            Ok(M::zero()),
            "{f:?} μ = {mu:?}"
        );
    }
    let mut bad = M::identity();
    bad[(0, 0)] = -M::Scalar::ONE;
    assert_eq!(M::ahat(zero, &bad), Err(Error::NonPositiveJ));
    bad[(0, 0)] = M::Scalar::from_f64(f64::NAN);
    assert_eq!(M::psi_hat(zero, &bad), Err(Error::NonFinite));
}

// ---------------------------------------------------------------------------------------------
// 8. Polar / SVD (default methods).
// ---------------------------------------------------------------------------------------------

/// Rotation-variant SVD and polar reference from nalgebra (f64): sorted `σ`, `U`, `V` made
/// proper by negating their last columns (and `σ_last`) as needed.
fn reference_svd(f: &DMatrix<f64>) -> (DMatrix<f64>, Vec<f64>, DMatrix<f64>) {
    let svd = f.clone().svd(true, true);
    let (mut u, mut vt) = (svd.u.unwrap(), svd.v_t.unwrap());
    let mut s: Vec<f64> = svd.singular_values.iter().copied().collect();
    let n = s.len();
    if u.determinant() < 0.0 {
        u.column_mut(n - 1).neg_mut();
        s[n - 1] = -s[n - 1];
    }
    if vt.determinant() < 0.0 {
        vt.row_mut(n - 1).neg_mut();
        s[n - 1] = -s[n - 1];
    }
    (u, s, vt.transpose())
}

/// `U, V ∈ SO(d)`, `F = UΣVᵀ`, sorted `|σ|`, only the last negative and only when
/// `det F < 0`; `polar` gives `R = UVᵀ` and a symmetric `S` with `F = RS`, `RᵀF` symmetric;
/// for f32, `|σ|` and `R` against nalgebra's SVD in f64.
///
/// Tolerances, with `c_σ` the backward error constant of the module docs: the computed
/// `U, V` are orthonormal and `UΣVᵀ` reproduces `F` to `c_σ ε` (relative to `1` and `‖F‖`),
/// and each `d`-term product the check itself forms adds `≤ d ε` per factor pair, so
/// `‖UᵀU − I‖_F`, `|det U − 1|` (`det(I + E) ≈ 1 + tr E`), `‖RᵀR − I‖`: `(c_σ + 2d) ε`;
/// `‖UΣVᵀ − F‖`, `‖RS − F‖`: `(c_σ + 2d) ε ‖F‖`; `‖S − Sᵀ‖` (rounding of `VΣVᵀ` only):
/// `2d ε ‖F‖`; `‖RᵀF − FᵀR‖` (`R` is exact for `F + δ`, so `RᵀF = S − Rᵀδ`): `(2c_σ + 2d) ε‖F‖`.
/// Forward (f32 only: the f64 reference is exact to `1e-16 κ`): Weyl gives
/// `| |σᵢ| − σᵢ_ref | ≤ c_σ ε ‖F‖₂`, and `‖δR‖ ≤ 2‖δ‖/min_{i<j}(σᵢ+σⱼ)` (module docs) gives
/// `‖R − R_ref‖ ≤ c_σ ε κ`, `κ = 2σ₀/min_{i<j}(σᵢ+σⱼ)` with signed σ (the rotation-variant `R`
/// has its kink at `σᵢ+σⱼ = 0`).
///
/// nalgebra's SVD is not a reference for f64: on this test's inputs it was off by 7 ulps in
/// a singular value and by 6e-12 in `R` (a 3D input with `σ₀ ≈ σ₁`, det < 0) where the
/// kernels agreed with a 50-digit mpmath SVD; the backward checks above bound the f64 error.
fn svd_polar<M: Case>() {
    let mut rng = seeded(90 + M::DIM as u64 + 100 * M::Scalar::MANTISSA_DIGITS as u64);
    let mut w = Worst::new::<M>("SVD and polar");
    let e = eps::<M>();
    let d = dim::<M>();
    let n = M::DIM;
    let cs = c_sigma::<M>();
    let forward = M::Scalar::MANTISSA_DIGITS <= 24;
    let mut inputs: Vec<M> = special_matrices::<M>();
    let n_special = inputs.len();
    for i in 0..N {
        let mut f: M = random_f(&mut rng);
        if i % 2 == 1 {
            for r in 0..n {
                f[(r, 0)] = -f[(r, 0)]; // det F < 0
            }
        }
        inputs.push(f);
    }
    let id = DMatrix::<f64>::identity(n, n);
    for (idx, f) in inputs.iter().enumerate() {
        let ctx = (idx, *f);
        let svd = M::svd(f).unwrap();
        let fa = to_na(f);
        let nf = fa.norm();
        let (u, v) = (to_na(&svd.u), to_na(&svd.v));
        let s: Vec<f64> = svd.sigma.as_ref().iter().map(|x| x.to_f64()).collect();
        let tol_orth = (cs + 2.0 * d) * e;
        for (name, q) in [("U", &u), ("V", &v)] {
            let orth = (q.transpose() * q - &id).norm();
            w.check(&format!("{name}ᵀ{name} − I"), orth, tol_orth, &ctx);
            let det_err = (q.determinant() - 1.0).abs();
            w.check(&format!("det {name} − 1"), det_err, tol_orth, &ctx);
        }
        let rec = to_na(&svd.reconstruct());
        w.check("UΣVᵀ − F", (&rec - &fa).norm(), tol_orth * nf, &ctx);
        for i in 1..n {
            assert!(s[i - 1].abs() >= s[i].abs(), "unsorted {s:?} {ctx:?}");
        }
        for (i, x) in s.iter().enumerate().take(n - 1) {
            assert!(*x >= 0.0, "σ{i} = {x} < 0 {ctx:?}");
        }
        let det = fa.determinant();
        // The sign is decided only where it is unambiguous: |det| above its rounding error
        // (`≤ γ_{2d} per(|F|) ≤ 2d ε ‖F‖ᵈ`); exactly singular inputs may give ±0.
        if det.abs() > 2.0 * d * e * nf.powi(n as i32) {
            assert_eq!(
                s[n - 1] < 0.0,
                det < 0.0,
                "sign of σ_last {s:?}, det {det} {ctx:?}"
            );
        }

        let pol = M::polar(f).unwrap();
        assert_eq!(pol.r, svd.rotation(), "polar R ≠ UVᵀ {ctx:?}");
        let (r, st) = (to_na(&pol.r), to_na(&pol.s));
        w.check("RᵀR − I", (r.transpose() * &r - &id).norm(), tol_orth, &ctx);
        w.check("det R − 1", (r.determinant() - 1.0).abs(), tol_orth, &ctx);
        w.check(
            "S − Sᵀ",
            (&st - st.transpose()).norm(),
            2.0 * d * e * nf,
            &ctx,
        );
        w.check("RS − F", (&r * &st - &fa).norm(), tol_orth * nf, &ctx);
        let rtf = r.transpose() * &fa;
        let tol = (2.0 * cs + 2.0 * d) * e * nf;
        w.check("RᵀF − FᵀR", (&rtf - rtf.transpose()).norm(), tol, &ctx);

        if forward {
            let (ur, sr, vr) = reference_svd(&fa);
            for i in 0..n {
                let err = (s[i].abs() - sr[i].abs()).abs();
                w.check("|σ| vs nalgebra", err, cs * e * sr[0], &ctx);
            }
            if idx >= n_special {
                // Random inputs: full rank, min(σᵢ+σⱼ) > 0 with probability 1.
                let pair_min = (0..n)
                    .flat_map(|i| (i + 1..n).map(move |j| (i, j)))
                    .map(|(i, j)| sr[i] + sr[j])
                    .fold(f64::INFINITY, f64::min);
                let kappa = 2.0 * sr[0] / pair_min;
                let r_ref = ur * vr.transpose();
                w.check("R vs nalgebra", (&r - r_ref).norm(), cs * e * kappa, &ctx);
            }
        }
    }
    let nan = M::identity().map(|_| M::Scalar::from_f64(f64::NAN));
    assert_eq!(M::svd(&nan).err(), Some(Error::NonFinite));
    assert_eq!(M::polar(&nan).err(), Some(Error::NonFinite));
    w.report();
}

/// Structured inputs: identity, −I, diagonal (sorted, unsorted, signed), a rotation, equal
/// singular values, rank-deficient, zero.
fn special_matrices<M: Matrix>() -> Vec<M> {
    let n = M::DIM;
    let t = |x: f64| M::Scalar::from_f64(x);
    let diag = |v: &[f64]| {
        let mut m = M::zero();
        for i in 0..n {
            m[(i, i)] = t(v[i]);
        }
        m
    };
    let mut out = vec![
        M::identity(),
        diag(&[-1.0, -1.0, -1.0]),
        diag(&[3.0, 2.0, 1.0]),
        diag(&[1.0, 2.0, 3.0]),
        diag(&[2.0, -3.0, 1.0]),
        diag(&[-2.0, 3.0, 0.5]),
        diag(&[1e-3, 1.0, 1e3]),
        diag(&[1.0, 1.0, 0.0]),
        M::zero(),
    ];
    // Rotation by 0.7 rad in the (0,1) plane, scaled by 2 (all σ equal).
    let mut rot = M::identity();
    let (c, s) = (0.7f64.cos(), 0.7f64.sin());
    rot[(0, 0)] = t(2.0 * c);
    rot[(1, 1)] = t(2.0 * c);
    rot[(1, 0)] = t(2.0 * s);
    rot[(0, 1)] = t(-2.0 * s);
    out.push(rot);
    // Rank one: u vᵀ.
    let mut r1 = M::zero();
    for i in 0..n {
        for j in 0..n {
            r1[(i, j)] = t((i + 1) as f64 * (j as f64 - 0.5));
        }
    }
    out.push(r1);
    // Nearly a reflection (2D: F₀₀ + F₁₁ = 0 exercises the closed form's special branch).
    let mut refl = M::identity();
    refl[(0, 0)] = t(1.5);
    refl[(1, 1)] = t(-1.5);
    refl[(0, 1)] = t(0.5);
    refl[(1, 0)] = t(0.5);
    out.push(refl);
    out
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

#[test]
fn finite_differences_2d_f64() {
    fd_check::<Mat<f64, 2>>();
}
#[test]
fn finite_differences_3d_f64() {
    fd_check::<Mat<f64, 3>>();
}
#[test]
fn f32_against_f64_2d() {
    f32_vs_f64::<Mat<f32, 2>, Mat<f64, 2>>();
}
#[test]
fn f32_against_f64_3d() {
    f32_vs_f64::<Mat<f32, 3>, Mat<f64, 3>>();
}
