//! The dilational energy `Ψ_λ(J_E) = λ/2 (J_E − 1)²` (Stomakhin et al. 2014, §4), its
//! stress, the particle pressure and the coefficient of the host's pressure solve (§5).
//!
//! `λ` is passed as `1/λ` so that the incompressible limit `λ → ∞` is `1/λ = 0`; the
//! quantities that are infinite there (energy, explicit stress, pressure as a function of
//! `J_E`) refuse it with [`Error::InvalidArgument`] — the pressure is then the host's
//! Lagrange multiplier.
//!
//! Derivations (`F = F_E`, `J = J_E`, `H = F⁻ᵀ`):
//! - `∂Ψ_λ/∂F_E = Ψ_λ'(J) J H` and `Ψ_λ' = λ(J − 1)`, so the Kirchhoff stress
//!   `P_λ F_Eᵀ = λ(J − 1) J I` needs no inverse.
//! - The Cauchy stress is `σ = (1/(J_E J_P)) P F_Eᵀ` (the current volume is `J_E J_P V⁰`), so
//!   `σ_λ = λ(J_E − 1)/J_P I` and `p = −Ψ_λ'(J_E)/J_P`.
//! - With `J_P` fixed during a step, `J̇_E = J_E ∇·v`, so `ṗ = −(λ J_E / J_P) ∇·v`; the implicit
//!   discretisation `∇·v^{n+1} = −(J_P/(Δt λ J_E)) (p^{n+1} − p^n)` is the Chorin-style
//!   pressure equation with the per-particle coefficient `J_P/(Δt λ J_E)`, 0 when
//!   incompressible.
//! - Differential for `δF = G F_E`: with `s(J) = λ(J − 1)J`, `δJ = J tr G`,
//!   `δH = −H δFᵀ H`, one gets `δP_λ F_Eᵀ = λ J ((2J − 1) tr(G) I − (J − 1) Gᵀ)`.

use crate::error::{Error, Result};
use crate::mat::Mat;
use crate::scalar::Real;

#[inline]
fn finite<T: Real>(x: T) -> Result<T> {
    if x.is_finite() {
        Ok(x)
    } else {
        Err(Error::Overflow)
    }
}

#[inline]
fn check<T: Real>(xs: &[T]) -> Result<()> {
    if xs.iter().any(|x| !x.is_finite()) {
        Err(Error::NonFinite)
    } else {
        Ok(())
    }
}

#[inline]
fn finite_lambda<T: Real>(inv_lambda: T) -> Result<()> {
    if inv_lambda <= T::ZERO {
        Err(Error::InvalidArgument)
    } else {
        Ok(())
    }
}

/// `Ψ_λ(J_E) = (J_E − 1)² / (2/λ)` (J/m³); needs `1/λ > 0`.
#[inline]
pub fn energy<T: Real>(j_e: T, inv_lambda: T) -> Result<T> {
    check(&[j_e, inv_lambda])?;
    finite_lambda(inv_lambda)?;
    let d = j_e - T::ONE;
    finite(d * d / (inv_lambda + inv_lambda))
}

/// `Ψ_λ'(J_E) J_E = (J_E − 1) J_E / (1/λ)` (Pa): the Kirchhoff stress `P_λ F_Eᵀ` is this
/// times `I`; needs `1/λ > 0`.
#[inline]
pub fn kirchhoff<T: Real>(j_e: T, inv_lambda: T) -> Result<T> {
    check(&[j_e, inv_lambda])?;
    finite_lambda(inv_lambda)?;
    finite((j_e - T::ONE) * j_e / inv_lambda)
}

/// `δP_λ F_Eᵀ = λ J_E ((2J_E − 1) tr(G) I − (J_E − 1) Gᵀ)` for `δF_E = G F_E` (Pa per unit
/// `G`); needs `1/λ > 0`.
#[inline]
pub fn d_kirchhoff<T: Real, const D: usize>(
    j_e: T,
    inv_lambda: T,
    g: &Mat<T, D>,
) -> Result<Mat<T, D>> {
    check(&[j_e, inv_lambda])?;
    finite_lambda(inv_lambda)?;
    if !g.is_finite() {
        return Err(Error::NonFinite);
    }
    let lj = j_e / inv_lambda;
    let iso = Mat::<T, D>::from_diagonal([(j_e + j_e - T::ONE) * g.trace(); D]);
    let m = (iso - g.transpose() * (j_e - T::ONE)) * lj;
    if m.is_finite() {
        Ok(m)
    } else {
        Err(Error::Overflow)
    }
}

/// Particle pressure `p = −Ψ_λ'(J_E)/J_P = −(J_E − 1)/((1/λ) J_P)` (Pa); needs `1/λ > 0`.
#[inline]
pub fn pressure<T: Real>(j_e: T, j_p: T, inv_lambda: T) -> Result<T> {
    check(&[j_e, j_p, inv_lambda])?;
    finite_lambda(inv_lambda)?;
    if j_p <= T::ZERO {
        return Err(Error::NonPositiveJ);
    }
    finite(-(j_e - T::ONE) / (inv_lambda * j_p))
}

/// The pressure-solve coefficient `J_P/(Δt λ J_E) = J_P (1/λ) / (Δt J_E)` (1/(Pa·s)); 0 for
/// an incompressible particle (`1/λ = 0`).
///
/// Errors: [`Error::NonFinite`], [`Error::NonPositiveJ`] for `J_E` or `J_P ≤ 0`,
/// [`Error::InvalidArgument`] for `Δt ≤ 0` or `1/λ < 0`, [`Error::Overflow`].
#[inline]
pub fn pressure_coefficient<T: Real>(j_e: T, j_p: T, inv_lambda: T, dt: T) -> Result<T> {
    check(&[j_e, j_p, inv_lambda, dt])?;
    if j_e <= T::ZERO || j_p <= T::ZERO {
        return Err(Error::NonPositiveJ);
    }
    if dt <= T::ZERO || inv_lambda < T::ZERO {
        return Err(Error::InvalidArgument);
    }
    finite(j_p * inv_lambda / (dt * j_e))
}
