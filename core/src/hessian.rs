//! Explicit Hessian matrices of Ψ̂ and the PSD-projected action Ĉ⁺:Z (its definiteness).
//!
//! For the fixed corotated base energy, `Ψ̂(F) = μ Σᵢ (σ̂ᵢ − 1)²` with `σ̂ᵢ = J^{−1/d} σᵢ` is an
//! isotropic function of the singular values of `F`, so its Hessian `Ĉ` has an analytic
//! eigensystem in the SVD basis (Smith, de Goes, Kim 2019, "Analytic eigensystems for
//! isotropic distortion energies", ACM TOG 38(1), the scaling/twist/flip eigenmatrices): a
//! `d×d` *scaling* block acting on `Uᵀ Z V`'s diagonal, and for every pair `i < j` two
//! eigenmatrices `U (eᵢeⱼᵀ ± eⱼeᵢᵀ) Vᵀ / √2`. The derivation below is self-contained.
//!
//! ```
//! use ampm_core::{energy::FixedCorotated, hessian, Mat3};
//! let f = Mat3::<f64>::from_rows([[1.3, 0.1, 0.0], [0.0, 0.9, 0.2], [0.1, 0.0, 0.8]]);
//! let z = Mat3::<f64>::from_rows([[0.2, -0.5, 0.1], [0.4, 0.3, -0.2], [0.0, 0.6, -0.1]]);
//! let e = FixedCorotated::new(10.0);
//! let cz = hessian::chat_psd_z(&e, &f, &z).unwrap();
//! // Ĉ⁺ is positive semi-definite: Z:Ĉ⁺:Z ≥ 0 for every Z (Ĉ itself is indefinite here).
//! assert!(z.ddot(&cz) >= 0.0);
//! let c = hessian::chat_matrix(&e, &f).unwrap(); // 9×9, column-major
//! assert_eq!(c.cols[2][7], c.cols[7][2]);
//! ```
//!
//! # Derivation (all formulas in this module come from here)
//!
//! Notation: `F = U diag(σ) Vᵀ` rotation-variant (see [`crate::polar`]); `J = Πσₖ > 0`, so
//! every `σₖ > 0`. `s = J^{−1/d}` (the `Jᵃ` of the seed report), `xₖ = s σₖ = σ̂ₖ` the singular
//! values of `F̂ = Jᵃ F` (the base energy's SVD, so `Πxₖ = 1`), `φ(x) = μ Σ(xₖ − 1)²`,
//! `φₖ = 2μ(xₖ − 1)`.
//!
//! *Chain rule.* `ln xₖ = ln σₖ − (1/d) Σₘ ln σₘ`, so with `cₖⱼ = δₖⱼ − 1/d`:
//! `∂xₖ/∂σⱼ = xₖ cₖⱼ / σⱼ` and `∂²xₖ/∂σⱼ∂σₗ = xₖ cₖⱼ cₖₗ /(σⱼσₗ) − δⱼₗ xₖ cₖⱼ / σⱼ²`.
//!
//! *Gradient.* `ψⱼ = ∂Ψ̂/∂σⱼ = Σₖ φₖ ∂xₖ/∂σⱼ = (s/xⱼ)(vⱼ − V/d)` with `vₖ = φₖxₖ`,
//! `V = Σvₖ = 2μq`, `q = Σₖ xₖ(xₖ − 1)`; i.e. `ψⱼ = 2μs (xⱼ − 1 − q/(d xⱼ))`.
//!
//! *Scaling block.* `Kⱼₗ = ∂²Ψ̂/∂σⱼ∂σₗ = Σₖ 2μ (∂xₖ/∂σⱼ)(∂xₖ/∂σₗ) + Σₖ φₖ ∂²xₖ/∂σⱼ∂σₗ`
//! `= s²/(xⱼxₗ) [Σₖ wₖ cₖⱼ cₖₗ − δⱼₗ Σₖ vₖ cₖⱼ]` with `wₖ = 2μxₖ² + vₖ = 2μ xₖ(2xₖ − 1)`.
//! Expanding the sums (`W = Σwₖ`, and `wⱼ − vⱼ = 2μxⱼ²`):
//! `Kⱼₗ = (2μs²/(xⱼxₗ)) [δⱼₗ (xⱼ² + q/d) − (ŵⱼ + ŵₗ)/d + Ŵ/d²]`, `ŵ = x(2x − 1)`, `Ŵ = Σŵ`.
//!
//! *Pairs.* For an isotropic function of the singular values, `P = ∂Ψ̂/∂F = U diag(ψ) Vᵀ`.
//! Differentiate `F = UΣVᵀ` and `P` with `δU = UΩ_U`, `δV = VΩ_V` (`Ω` skew) and
//! `Ũ = UᵀZV`: off the diagonal `Ũᵢⱼ = ω_U σⱼ − σᵢ ω_V`, `Ũⱼᵢ = σⱼ ω_V − ω_U σᵢ`
//! (`ω = Ωᵢⱼ`), and the same with `ψ` for `Uᵀ δP V`. Eliminating `ω_U, ω_V` (for `σᵢ ≠ σⱼ`)
//! gives, on `(Ũᵢⱼ, Ũⱼᵢ)`, the block `[[α, β], [β, α]]`, `α = (σᵢψᵢ − σⱼψⱼ)/(σᵢ² − σⱼ²)`,
//! `β = (σⱼψᵢ − σᵢψⱼ)/(σᵢ² − σⱼ²)`, with eigenvalues `α + β = (ψᵢ − ψⱼ)/(σᵢ − σⱼ)`
//! on the symmetric eigenmatrix `U(eᵢeⱼᵀ + eⱼeᵢᵀ)Vᵀ/√2` (Smith et al.'s "flip"/stretch-shear
//! mode) and `α − β = (ψᵢ + ψⱼ)/(σᵢ + σⱼ)` on the skew one `U(eᵢeⱼᵀ − eⱼeᵢᵀ)Vᵀ/√2` (the
//! "twist": at `F = I` it is an infinitesimal rotation, to which `Ψ̂` is blind, and indeed its
//! eigenvalue is 0 there). Substituting `ψ` and `σ = x/s`:
//! - `ψᵢ − ψⱼ = 2μs (xᵢ − xⱼ)(1 + q/(d xᵢxⱼ))`, so the difference quotient has the exact,
//!   cancellation-free closed form `λ_sym = 2μs² (1 + q/(d xᵢxⱼ))`, valid (by continuity) at
//!   `σᵢ = σⱼ` with no special case;
//! - `λ_skew = 2μs² ((xᵢ − 1 + xⱼ − 1)/(xᵢ + xⱼ) − q/(d xᵢxⱼ))`, using
//!   `(1/xᵢ + 1/xⱼ)/(xᵢ + xⱼ) = 1/(xᵢxⱼ)`.
//!
//! *Definiteness.* In 2D, `x = (t, 1/t)`, `u = t + 1/t ≥ 2` gives `q = (u − 2)(u + 1)` and
//! `λ_skew = 2μs² (u − 2)(1/u − (u + 1)/2) < 0` for every non-conformal `F`; in 3D
//! `λ_skew,ij ≈ 2μs² (eᵢ + eⱼ)/2` for `x = 1 + e` (with `Σe ≈ 0`), negative for some pair at
//! every small deviatoric strain. So `Ĉ` is PSD only on the conformal set `F = cR`, where its
//! eigenvalues are `0` (the scaling direction `F`, since `Ψ̂(cF) = Ψ̂(F)`, and the `d(d−1)/2`
//! twists) and `2μs²` (the rest). [`HessianEigensystem::psd`] clamps the negative eigenvalues
//! to zero: the twist/flip eigenvalues directly, the scaling block through a small cyclic
//! Jacobi eigen-decomposition ([`symmetric_eigen`]).
//!
//! # Conventions
//!
//! - Everything is computed on `G = 2⁻ᵏ F` (see [`crate::augmented`]), where `s = det(G)^{−1/d}`,
//!   and scaled at the end: `Ĉ(F) = 2⁻²ᵏ Ĉ(G)`.
//! - The explicit `d²×d²` matrix uses `vec(Z)[i + d·j] = Z_ij` (column-major, as all matrices
//!   here), so that `vec(Ĉ:Z) = Ĉ_mat · vec(Z)`; `Ĉ_mat` is stored column-major too
//!   (`Mat<T, d²>`: `cols[q][p] = Ĉ_mat[p, q] = ∂²Ψ̂/∂F_{p}∂F_{q}`), and it is symmetric.
//!   With `W = V ⊗ U` (orthogonal, `vec(U X Vᵀ) = W vec(X)`), `Ĉ_mat = W D Wᵀ`, `D` the
//!   Hessian in the SVD basis.

use crate::augmented::Augmented;
use crate::energy::FixedCorotated;
use crate::error::{Error, Result};
use crate::kernel;
use crate::mat::{Mat, Matrix};
use crate::polar::{scale_pow2, Svd, SvdMethod};
use crate::scalar::Real;
use core::ops::{Index, IndexMut};

/// A `d×d` matrix type that also names its `d²×d²` companion, the type of explicit Hessians.
pub trait HessianDim: Matrix {
    /// The `d²×d²` matrix type, column-major: `Mat<T, 4>` in 2D, `Mat<T, 9>` in 3D.
    type Wide: Copy
        + core::fmt::Debug
        + PartialEq
        + bytemuck::Pod
        + Send
        + Sync
        + 'static
        + Index<(usize, usize), Output = Self::Scalar>
        + IndexMut<(usize, usize)>;

    /// The zero `d²×d²` matrix.
    #[must_use]
    fn wide_zero() -> Self::Wide;

    /// The scaling block `K`, and `λ_sym`, `λ_skew` of each pair `(i, j)` at entry `(i, j)`,
    /// of fixed corotated `Ĉ(G)` from the SVD of `F̂` (singular values `x > 0`) and
    /// `s = det(G)^{−1/d}`: [`crate::kernel::coefficients`] on one scalar lane.
    #[must_use]
    fn coefficients(mu: Self::Scalar, svd: &Svd<Self>, s: Self::Scalar) -> (Self, Self, Self);
}

impl<T: Real> HessianDim for Mat<T, 2> {
    type Wide = Mat<T, 4>;
    #[inline]
    fn wide_zero() -> Mat<T, 4> {
        Mat::ZERO
    }
    #[inline]
    fn coefficients(mu: T, svd: &Svd<Self>, s: T) -> (Self, Self, Self) {
        coefficients_of::<T, 2>(mu, svd, s)
    }
}

impl<T: Real> HessianDim for Mat<T, 3> {
    type Wide = Mat<T, 9>;
    #[inline]
    fn wide_zero() -> Mat<T, 9> {
        Mat::ZERO
    }
    #[inline]
    fn coefficients(mu: T, svd: &Svd<Self>, s: T) -> (Self, Self, Self) {
        coefficients_of::<T, 3>(mu, svd, s)
    }
}

/// [`HessianDim::coefficients`] for `Mat<T, D>`.
#[inline]
fn coefficients_of<T: Real, const D: usize>(
    mu: T,
    svd: &Svd<Mat<T, D>>,
    s: T,
) -> (Mat<T, D>, Mat<T, D>, Mat<T, D>)
where
    Mat<T, D>: Matrix<Scalar = T, Vector = [T; D]>,
{
    let co = kernel::coefficients::<T, D>(mu, &svd.u.cols, &svd.v.cols, &svd.sigma, s, T::ZERO);
    let mut sym = Mat::<T, D>::ZERO;
    let mut skew = Mat::<T, D>::ZERO;
    for (p, &(i, j)) in kernel::PAIRS.iter().take(kernel::pairs(D)).enumerate() {
        sym.cols[j][i] = co.sym[p];
        skew.cols[j][i] = co.skew[p];
    }
    (Mat::from_cols(co.block), sym, skew)
}

/// Sweep cap of [`symmetric_eigen`], a safety bound: cyclic Jacobi converges quadratically
/// (G&VL §8.5.3), so a 2×2 or 3×3 matrix meets the stopping test after a few sweeps.
const MAX_JACOBI_SWEEPS: u32 = 20;

/// Eigen-decomposition `A = Q diag(λ) Qᵀ` of the symmetric part of a small matrix, by cyclic
/// Jacobi rotations (Golub & Van Loan, *Matrix Computations*, 4th ed., §8.5.2, Alg. 8.5.1–2).
///
/// Returns `(λ, Q)` with `Q` orthogonal (columns are eigenvectors), eigenvalues unsorted. A
/// pair `(p, q)` is skipped when `|a_pq| ≤ ε·max(√|a_pp a_qq|, ε‖A‖_F)`: the relative test of
/// Demmel & Veselić where the diagonal allows it, an absolute floor `ε²‖A‖` otherwise (so a
/// zero diagonal entry cannot stall the iteration). Each rotation is backward stable, so the
/// result reproduces `A` to `O(ε‖A‖)`. Errors: non-finite input → `NonFinite`; sweep cap
/// reached → `NotConverged` (not observed on finite input).
#[inline]
pub fn symmetric_eigen<M: Matrix>(a: &M) -> Result<(M::Vector, M)> {
    type T<M> = <M as Matrix>::Scalar;
    if !a.is_finite() {
        return Err(Error::NonFinite);
    }
    let mut a = (*a + a.transpose()) * T::<M>::HALF;
    let mut q = M::identity();
    let eps = T::<M>::EPSILON;
    let floor = eps * eps * a.ddot(&a).sqrt();
    for _ in 0..MAX_JACOBI_SWEEPS {
        let mut rotated = false;
        for qi in 1..M::DIM {
            for p in 0..qi {
                let apq = a[(p, qi)];
                let rel = eps * (a[(p, p)].abs() * a[(qi, qi)].abs()).sqrt();
                if apq.abs() <= rel.max(floor) {
                    continue;
                }
                rotated = true;
                // G&VL Alg. 8.5.1 (sym.schur2): τ = (a_qq − a_pp)/(2a_pq), t the smaller root
                // of t² + 2τt − 1 = 0, c = 1/√(1+t²), s = tc; J = [[c, s], [−s, c]] on (p, q)
                // makes (JᵀAJ)_pq = 0. hypot avoids overflow of τ² for tiny a_pq.
                let tau = (a[(qi, qi)] - a[(p, p)]) / (apq + apq);
                let t = T::<M>::ONE.copysign(tau) / (tau.abs() + T::<M>::ONE.hypot(tau));
                let c = T::<M>::ONE / T::<M>::ONE.hypot(t);
                let s = t * c;
                // A ← JᵀAJ, kept exactly symmetric: the (p, q) block becomes
                // diag(a_pp − t a_pq, a_qq + t a_pq); the other rows rotate.
                a[(p, p)] -= t * apq;
                a[(qi, qi)] += t * apq;
                a[(p, qi)] = T::<M>::ZERO;
                a[(qi, p)] = T::<M>::ZERO;
                for r in 0..M::DIM {
                    if r != p && r != qi {
                        let (arp, arq) = (a[(r, p)], a[(r, qi)]);
                        let np = c * arp - s * arq;
                        let nq = s * arp + c * arq;
                        a[(r, p)] = np;
                        a[(p, r)] = np;
                        a[(r, qi)] = nq;
                        a[(qi, r)] = nq;
                    }
                }
                // Q ← QJ.
                for r in 0..M::DIM {
                    let (qp, qq) = (q[(r, p)], q[(r, qi)]);
                    q[(r, p)] = c * qp - s * qq;
                    q[(r, qi)] = s * qp + c * qq;
                }
            }
        }
        if !rotated {
            let mut lam = M::Vector::default();
            for i in 0..M::DIM {
                lam[i] = a[(i, i)];
            }
            return Ok((lam, q));
        }
    }
    Err(Error::NotConverged)
}

/// The analytic eigensystem of `Ĉ(F)` for fixed corotated, in the SVD basis of `F`.
///
/// Build it once per particle with [`HessianEigensystem::new`]; [`HessianEigensystem::psd`]
/// gives the projected `Ĉ⁺`, [`HessianEigensystem::apply`] the action, and
/// [`HessianEigensystem::to_matrix`] the explicit `d²×d²` matrix. Values are stored for
/// `G = 2⁻ᵏF` and scaled by `2⁻²ᵏ` on output (see the module docs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HessianEigensystem<M: Matrix> {
    /// Left rotation of the SVD of `F` (that of `F̂`).
    u: M,
    /// Right rotation of the SVD of `F`.
    v: M,
    /// Scaling block `K(G)` (symmetric `d×d`), acting on `diag(UᵀZV)`.
    block: M,
    /// `(i, j)`, `i < j`: eigenvalue `λ_sym(G)` of `U(eᵢeⱼᵀ + eⱼeᵢᵀ)Vᵀ/√2`.
    sym: M,
    /// `(i, j)`, `i < j`: eigenvalue `λ_skew(G)` of `U(eᵢeⱼᵀ − eⱼeᵢᵀ)Vᵀ/√2`.
    skew: M,
    /// `F = 2ᵏ G`.
    k: i32,
}

impl<M: HessianDim> HessianEigensystem<M> {
    /// Validates `f` and `μ`, decomposes `F̂` once (through [`Augmented::new`]) and evaluates the
    /// closed-form eigenvalues. `μ = 0` gives the zero Hessian without any decomposition.
    ///
    /// Errors as the other kernels: non-finite `F` or `μ` → `NonFinite`, `J ≤ 0` (or `F`
    /// singular to working precision) → `NonPositiveJ`, `μ < 0` → `InvalidArgument`,
    /// non-representable eigenvalues → `Overflow`.
    #[inline]
    pub fn new<S: SvdMethod<M>>(energy: &FixedCorotated<M::Scalar, S>, f: &M) -> Result<Self> {
        let aug = Augmented::new(energy, f)?;
        let kin = *aug.kinematics();
        let zero = Self {
            u: M::identity(),
            v: M::identity(),
            block: M::zero(),
            sym: M::zero(),
            skew: M::zero(),
            k: kin.k,
        };
        let Some((svd, _)) = aug.base_state().svd else {
            return Ok(zero); // μ = 0
        };
        for i in 0..M::DIM {
            if svd.sigma[i] <= M::Scalar::ZERO {
                return Err(Error::NonPositiveJ);
            }
        }
        // The formulas: `crate::kernel::coefficients` (one source with the batch kernels).
        let (block, sym, skew) = M::coefficients(energy.mu, &svd, kin.ja_g);
        if !(block.is_finite() && sym.is_finite() && skew.is_finite()) {
            return Err(Error::Overflow);
        }
        Ok(Self {
            u: svd.u,
            v: svd.v,
            block,
            sym,
            skew,
            k: kin.k,
        })
    }

    /// The PSD projection `Ĉ⁺`: the same eigenbasis with every negative eigenvalue set to 0
    /// (the nearest PSD matrix to `Ĉ` in the Frobenius norm).
    #[inline]
    pub fn psd(&self) -> Result<Self> {
        let zero = M::Scalar::ZERO;
        let (lam, qm) = symmetric_eigen(&self.block)?;
        // K⁺ = Q diag(max(λ, 0)) Qᵀ, upper triangle mirrored so it is exactly symmetric.
        let mut block = M::zero();
        for j in 0..M::DIM {
            for i in 0..=j {
                let mut s = zero;
                for m in 0..M::DIM {
                    s += lam[m].max(zero) * qm[(i, m)] * qm[(j, m)];
                }
                block[(i, j)] = s;
                block[(j, i)] = s;
            }
        }
        Ok(Self {
            block,
            sym: self.sym.map(|l| l.max(zero)),
            skew: self.skew.map(|l| l.max(zero)),
            ..*self
        })
    }

    /// All `d²` eigenvalues of `Ĉ(F)` (or of `Ĉ⁺` for a projected system): the scaling
    /// block's `d` (unsorted), then for each pair `(0,1)`, `(0,2)`, `(1,2)` its `λ_sym`,
    /// `λ_skew`.
    #[inline]
    pub fn eigenvalues(&self) -> Result<M::Array> {
        let (lam, _) = symmetric_eigen(&self.block)?;
        let mut out = M::Array::default();
        let o = out.as_mut();
        let mut n = 0;
        for i in 0..M::DIM {
            o[n] = lam[i];
            n += 1;
        }
        for j in 1..M::DIM {
            for i in 0..j {
                o[n] = self.sym[(i, j)];
                o[n + 1] = self.skew[(i, j)];
                n += 2;
            }
        }
        let e = -2 * self.k;
        for v in o.iter_mut() {
            // One rounding, and 0·2ᵉ = 0 even where 2ᵉ itself overflows.
            *v = v.scalbn(e);
            if !v.is_finite() {
                return Err(Error::Overflow);
            }
        }
        Ok(out)
    }

    /// The action `Ĉ:Z` (or `Ĉ⁺:Z` for a projected system).
    #[inline]
    pub fn apply(&self, z: &M) -> Result<M> {
        if !z.is_finite() {
            return Err(Error::NonFinite);
        }
        let half = M::Scalar::HALF;
        let ut = self.u.transpose() * *z * self.v;
        let mut r = M::zero();
        for i in 0..M::DIM {
            let mut s = M::Scalar::ZERO;
            for l in 0..M::DIM {
                s += self.block[(i, l)] * ut[(l, l)];
            }
            r[(i, i)] = s;
        }
        for j in 1..M::DIM {
            for i in 0..j {
                let a = (ut[(i, j)] + ut[(j, i)]) * half;
                let b = (ut[(i, j)] - ut[(j, i)]) * half;
                let (ls, lk) = (self.sym[(i, j)] * a, self.skew[(i, j)] * b);
                r[(i, j)] = ls + lk;
                r[(j, i)] = ls - lk;
            }
        }
        let out = scale_pow2(&(self.u * r * self.v.transpose()), -2 * self.k);
        if out.is_finite() {
            Ok(out)
        } else {
            Err(Error::Overflow)
        }
    }

    /// The explicit `d²×d²` matrix `Ĉ_mat = W D Wᵀ` (or `Ĉ⁺`), `W = V ⊗ U`, in the
    /// convention `vec(Ĉ:Z) = Ĉ_mat · vec(Z)`, `vec(Z)[i + d·j] = Z_ij` (module docs).
    /// Exactly symmetric (the upper triangle is mirrored).
    #[inline]
    pub fn to_matrix(&self) -> Result<M::Wide> {
        let d = M::DIM;
        let half = M::Scalar::HALF;
        // W[p, (i,j)] = vec(uᵢ vⱼᵀ)[p] = U[r,i] V[c,j], p = r + d·c.
        let w = |p: usize, i: usize, j: usize| self.u[(p % d, i)] * self.v[(p / d, j)];
        let e = -2 * self.k;
        let mut out = M::wide_zero();
        for qc in 0..M::LEN {
            for p in 0..=qc {
                // (W D Wᵀ)[p, q]: the scaling block couples the (l,l)–(m,m) columns of W; each
                // pair's 2×2 block [[α, β], [β, α]], α = (λ_sym + λ_skew)/2,
                // β = (λ_sym − λ_skew)/2, couples (i,j)–(j,i).
                let mut s = M::Scalar::ZERO;
                for l in 0..d {
                    let wpl = w(p, l, l);
                    for m in 0..d {
                        s += self.block[(l, m)] * wpl * w(qc, m, m);
                    }
                }
                for j in 1..d {
                    for i in 0..j {
                        let (ls, lk) = (self.sym[(i, j)], self.skew[(i, j)]);
                        let alpha = (ls + lk) * half;
                        let beta = (ls - lk) * half;
                        let (pij, pji) = (w(p, i, j), w(p, j, i));
                        let (qij, qji) = (w(qc, i, j), w(qc, j, i));
                        s += alpha * (pij * qij + pji * qji) + beta * (pij * qji + pji * qij);
                    }
                }
                let v = s.scalbn(e);
                if !v.is_finite() {
                    return Err(Error::Overflow);
                }
                out[(p, qc)] = v;
                out[(qc, p)] = v;
            }
        }
        Ok(out)
    }
}

/// `Ĉ⁺(F):Z`, the action of the Hessian of `Ψ̂` with its negative eigenvalues clamped to 0
/// (fixed corotated base energy).
#[inline]
pub fn chat_psd_z<M: HessianDim, S: SvdMethod<M>>(
    energy: &FixedCorotated<M::Scalar, S>,
    f: &M,
    z: &M,
) -> Result<M> {
    if !z.is_finite() {
        return Err(Error::NonFinite);
    }
    HessianEigensystem::new(energy, f)?.psd()?.apply(z)
}

/// The explicit `d²×d²` Hessian `Ĉ(F)` of `Ψ̂`, column-major, `vec(Ĉ:Z) = Ĉ_mat · vec(Z)`
/// with `vec(Z)[i + d·j] = Z_ij`.
#[inline]
pub fn chat_matrix<M: HessianDim, S: SvdMethod<M>>(
    energy: &FixedCorotated<M::Scalar, S>,
    f: &M,
) -> Result<M::Wide> {
    HessianEigensystem::new(energy, f)?.to_matrix()
}

/// The explicit `d²×d²` PSD projection `Ĉ⁺(F)`, same convention as [`chat_matrix`].
#[inline]
pub fn chat_psd_matrix<M: HessianDim, S: SvdMethod<M>>(
    energy: &FixedCorotated<M::Scalar, S>,
    f: &M,
) -> Result<M::Wide> {
    HessianEigensystem::new(energy, f)?.psd()?.to_matrix()
}
