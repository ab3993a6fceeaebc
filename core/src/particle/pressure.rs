//! Particle pressures for a host's pressure solve (Chorin projection, Stomakhin et al. 2014
//! §4.3): the particle-level checks around [`dilation::pressure`] and
//! [`dilation::pressure_coefficient`].

use super::dilation;
use super::update::check_particle;
use super::{Material, Particle};
use crate::error::Result;
use crate::mat::{Mat, Matrix};
use crate::scalar::Real;

/// The particle pressure `p = −Ψ_λ'(J_E)/J_P` (Pa) with the particle's (hardened) `λ`
/// ([`dilation::pressure`]).
///
/// Errors: invalid material or particle;
/// [`Error::InvalidArgument`](crate::Error::InvalidArgument) when `1/λ = 0`.
#[inline]
pub fn pressure<T: Real, const D: usize>(material: &Material<T>, p: &Particle<T, D>) -> Result<T>
where
    Mat<T, D>: Matrix<Scalar = T>,
{
    material.validate(p.phase)?;
    let (j_e, j_p) = check_particle(p)?;
    dilation::pressure(j_e, j_p, material.moduli(p.phase, j_p)?.inv_lambda)
}

/// The pressure-solve coefficient `J_P/(Δt λ J_E)` (1/(Pa·s)) of a particle
/// ([`dilation::pressure_coefficient`]), 0 when incompressible.
///
/// Errors: invalid material, particle or `Δt`.
#[inline]
pub fn pressure_coefficient<T: Real, const D: usize>(
    material: &Material<T>,
    p: &Particle<T, D>,
    dt: T,
) -> Result<T>
where
    Mat<T, D>: Matrix<Scalar = T>,
{
    material.validate(p.phase)?;
    let (j_e, j_p) = check_particle(p)?;
    dilation::pressure_coefficient(j_e, j_p, material.moduli(p.phase, j_p)?.inv_lambda, dt)
}
