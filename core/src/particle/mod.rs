//! MPM particle updates of augmented MPM (Stomakhin, Schroeder, Jiang, Chai, Teran, Selle,
//! SIGGRAPH 2014): everything an MPM host does per particle for solids that melt and liquids
//! that freeze. The grid work (solves, boundary conditions) stays the host's.
//!
//! - [`stencil`]: quadratic / cubic B-spline weights and gradients, collocated or MAC face grid.
//! - [`apic`]: APIC transfers (Jiang et al. 2015): P2G mass and momentum, G2P velocity,
//!   affine matrix and `∇v`.
//! - [`deformation`]: `F_E ← (I + Δt∇v) F_E` with the paper's remedy for
//!   `det(I + Δt∇v) ≤ 0`, snow plasticity (Stomakhin et al. 2013), the liquid projection.
//! - [`dilation`]: `Ψ_λ(J_E) = λ/2 (J_E − 1)²`, pressure and the pressure-solve coefficient,
//!   with `1/λ` stored so the incompressible limit is representable.
//! - [`thermal`]: temperature from the grid (PIC/FLIP), latent heat buffer, phase switch.
//! - [`transfer`]: batch P2G, G2P and the implicit force differential through views of the
//!   host's own grid (no per-node buffers); [`implicit`]: the prepared force differential.
//! - [`update`]: the per-particle entries — [`update::p2g`] (stencil, mass, momentum, stress
//!   force, heat), [`update::g2p_update`] (velocity, affine matrix, position, `F_E`,
//!   plasticity, temperature, phase), [`update::Stiffness`] (the force differential of an
//!   implicit step) — driven by one [`Material`] that says which parts of the model are on,
//!   so a scene pays only for what it uses.
//!
//! **Units** (SI throughout): positions m, velocities m/s, the APIC affine matrix and `∇v` 1/s,
//! grid spacing `h` m, `Δt` s, mass kg, reference volume `V⁰` m³, stresses and `μ`, `λ` Pa
//! (`1/λ` 1/Pa), forces N, temperatures K, heat capacity J/(kg·K), conductivity W/(m·K),
//! latent heat and the latent buffer `U` J/kg (specific: a particle of mass `m` stores
//! `m·U` joules).
//!
//! **Layouts.** Matrices are column-major (`Mat.cols[j][i] = M_ij`); per-node data follows the
//! stencil order of [`stencil`].

// Index loops over several `[T; d]` arrays at once read like the formulas they implement.
#![allow(clippy::needless_range_loop)]

pub mod apic;
pub mod deformation;
pub mod dilation;
pub mod implicit;
pub mod pressure;
pub mod stencil;
pub mod stiffness;
pub mod thermal;
pub mod transfer;
pub mod update;

pub use stencil::{Grid, Kernel, Node, Stencil};
pub use update::{g2p_update, kirchhoff_stress, p2g, GridSample, P2g, Stiffness, UpdateInfo};

use crate::error::{Error, Result};
use crate::mat::Mat;
use crate::scalar::Real;

/// The phase of a particle.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
#[repr(u8)]
pub enum Phase {
    /// Solid: fixed corotated elasticity, optionally snow plasticity.
    #[default]
    Solid = 0,
    /// Liquid: `μ = 0`, `F_E` and `F_P` kept isotropic (`J_E^{1/d} I`, `J_P^{1/d} I`).
    Liquid = 1,
}

impl Phase {
    /// The phase of a C code (0 solid, 1 liquid), [`Error::InvalidArgument`] otherwise.
    #[inline]
    pub fn from_code(c: u8) -> Result<Self> {
        match c {
            0 => Ok(Phase::Solid),
            1 => Ok(Phase::Liquid),
            _ => Err(Error::InvalidArgument),
        }
    }
}

/// Material parameters of one phase.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct PhaseParams<T> {
    /// Shear-like modulus `μ₀ ≥ 0` of the fixed corotated `Ψ_μ` (Pa); must be 0 for the liquid.
    pub mu: T,
    /// `1/λ₀ ≥ 0` (1/Pa), the inverse of the bulk-like modulus of `Ψ_λ`; 0 is incompressible.
    pub inv_lambda: T,
    /// Specific heat capacity `c > 0` (J/(kg·K)); read only when heat is on.
    pub heat_capacity: T,
    /// Thermal conductivity `κ ≥ 0` (W/(m·K)); read only when heat is on.
    pub conductivity: T,
}

/// Snow plasticity (Stomakhin et al. 2013, §4): singular values of `F_E` are clamped to
/// `[1 − θ_c, 1 + θ_s]`, the rest goes to `F_P`; hardening scales `μ` and `λ` by
/// `e^{ξ(1 − J_P)}`.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct Snow<T> {
    /// Critical compression `θ_c ∈ [0, 1)`.
    pub critical_compression: T,
    /// Critical stretch `θ_s ≥ 0`.
    pub critical_stretch: T,
    /// Hardening coefficient `ξ ≥ 0` (dimensionless).
    pub hardening: T,
}

/// Heat transfer and phase change (Stomakhin et al. 2014, §6).
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct Heat<T> {
    /// FLIP fraction `α ∈ [0, 1]` of the temperature transfer (0 = PIC, 1 = FLIP).
    pub flip: T,
    /// Melting point `T_m` (K).
    pub melting_point: T,
    /// Specific latent heat `L ≥ 0` (J/kg): the latent buffer `U` lives in `[0, L]`.
    pub latent_heat: T,
    /// Whether particles melt and freeze (else the temperature just follows the grid).
    pub phase_change: bool,
}

/// Where the dilational energy `Ψ_λ` enters the time step.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
pub enum Dilation {
    /// In the stress force `−V⁰ P F_Eᵀ ∇w` (needs `1/λ > 0`).
    #[default]
    Explicit,
    /// Left to the host's pressure (Chorin) solve, which uses [`dilation::pressure_coefficient`]
    /// (Stomakhin et al. 2014, §5); the force is deviatoric only. Allows `1/λ = 0`.
    PressureSolve,
}

/// Which Hessian of `Ψ̂_μ` the force differential of an implicit step uses.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
pub enum Definiteness {
    /// The exact `Ĉ` (indefinite away from conformal `F`, Smith et al. 2019).
    #[default]
    Exact,
    /// A definite operator for a Krylov solve (CG). The batch force differential
    /// ([`transfer::force`], the C ABI) projects the whole differential, dilational part
    /// included, block by block in the rotated basis of `F_E` ([`implicit`]). The
    /// per-particle [`update::Stiffness`] projects only `Ĉ` (`Ĉ⁺`, [`crate::hessian`]) and adds
    /// the dilational term unprojected (indefinite wherever `Ψ_λ' ≠ 0`).
    Projected,
}

/// What a scene models. Everything off is skipped per particle: `μ = 0` never runs a polar
/// decomposition, no [`Heat`] never touches temperature, no [`Snow`] never clamps.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct Material<T> {
    /// Parameters of solid particles.
    pub solid: PhaseParams<T>,
    /// Parameters of liquid particles (`mu` must be 0).
    pub liquid: PhaseParams<T>,
    /// Snow plasticity of solid particles, if any.
    pub plasticity: Option<Snow<T>>,
    /// Heat transfer (and phase change), if any.
    pub heat: Option<Heat<T>>,
    /// Where `Ψ_λ` enters.
    pub dilation: Dilation,
    /// The Hessian of the implicit force differential ([`update::Stiffness`]).
    pub hessian: Definiteness,
}

/// The effective elastic moduli of one particle (after hardening).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Moduli<T> {
    /// `μ` (Pa).
    pub mu: T,
    /// `1/λ` (1/Pa).
    pub inv_lambda: T,
}

fn finite_nonneg<T: Real>(x: T) -> Result<()> {
    if !x.is_finite() {
        Err(Error::NonFinite)
    } else if x < T::ZERO {
        Err(Error::InvalidArgument)
    } else {
        Ok(())
    }
}

impl<T: Real> Material<T> {
    /// An elastic solid (no plasticity, no heat) with explicit dilation.
    #[inline]
    #[must_use]
    pub fn elastic(mu: T, lambda: T) -> Self {
        Self {
            solid: PhaseParams {
                mu,
                inv_lambda: T::ONE / lambda,
                ..PhaseParams::default()
            },
            ..Self::default()
        }
    }

    /// Validates the parameters that do not depend on a particle (snow, heat, and the phase
    /// parameters a particle in `phase` will read).
    ///
    /// Errors: [`Error::NonFinite`] for NaN/inf, [`Error::InvalidArgument`] for a value
    /// outside its documented domain.
    #[inline]
    pub fn validate(&self, phase: Phase) -> Result<()> {
        if let Some(s) = &self.plasticity {
            finite_nonneg(s.critical_compression)?;
            finite_nonneg(s.critical_stretch)?;
            finite_nonneg(s.hardening)?;
            if s.critical_compression >= T::ONE {
                return Err(Error::InvalidArgument);
            }
        }
        let heat_on = if let Some(h) = &self.heat {
            finite_nonneg(h.flip)?;
            finite_nonneg(h.latent_heat)?;
            if !h.melting_point.is_finite() {
                return Err(Error::NonFinite);
            }
            if h.flip > T::ONE {
                return Err(Error::InvalidArgument);
            }
            true
        } else {
            false
        };
        let phase_change = self.heat.is_some_and(|h| h.phase_change);
        let check = |p: &PhaseParams<T>| -> Result<()> {
            finite_nonneg(p.mu)?;
            finite_nonneg(p.inv_lambda)?;
            if self.dilation == Dilation::Explicit && p.inv_lambda == T::ZERO {
                // λ = ∞ has no explicit force; it needs the pressure solve.
                return Err(Error::InvalidArgument);
            }
            if heat_on {
                finite_nonneg(p.heat_capacity)?;
                finite_nonneg(p.conductivity)?;
                if p.heat_capacity == T::ZERO {
                    return Err(Error::InvalidArgument);
                }
            }
            Ok(())
        };
        if phase_change || phase == Phase::Solid {
            check(&self.solid)?;
        }
        if phase_change || phase == Phase::Liquid {
            check(&self.liquid)?;
            if self.liquid.mu != T::ZERO {
                return Err(Error::InvalidArgument);
            }
        }
        Ok(())
    }

    /// The parameters of `phase`.
    #[inline]
    #[must_use]
    pub fn params(&self, phase: Phase) -> &PhaseParams<T> {
        match phase {
            Phase::Solid => &self.solid,
            Phase::Liquid => &self.liquid,
        }
    }

    /// `μ` and `1/λ` of a particle in `phase` with plastic volume ratio `J_P`: with snow
    /// plasticity a solid hardens, `μ = μ₀ e^{ξ(1 − J_P)}`, `1/λ = (1/λ₀) e^{−ξ(1 − J_P)}`
    /// (Stomakhin et al. 2013, eq. 2); otherwise the phase's `μ₀`, `1/λ₀`.
    ///
    /// Errors: [`Error::Overflow`] when the hardening factor, `μ` or `1/λ` is not
    /// representable.
    #[inline]
    pub fn moduli(&self, phase: Phase, j_p: T) -> Result<Moduli<T>> {
        let p = self.params(phase);
        match (&self.plasticity, phase) {
            (Some(s), Phase::Solid) if s.hardening != T::ZERO => {
                let e = (s.hardening * (T::ONE - j_p)).exp();
                let mu = p.mu * e;
                let inv_lambda = p.inv_lambda / e;
                if !(e.is_finite() && mu.is_finite() && inv_lambda.is_finite()) || e == T::ZERO {
                    return Err(Error::Overflow);
                }
                Ok(Moduli { mu, inv_lambda })
            }
            _ => Ok(Moduli {
                mu: p.mu,
                inv_lambda: p.inv_lambda,
            }),
        }
    }
}

/// The state of one particle (what an MPM host stores per particle).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Particle<T, const D: usize> {
    /// Position `x_p` (m, relative to the grid origin).
    pub x: [T; D],
    /// Velocity `v_p` (m/s).
    pub v: [T; D],
    /// APIC affine matrix `C_p = B_p D_p⁻¹` (1/s), column-major.
    pub affine: Mat<T, D>,
    /// Elastic deformation gradient `F_E`, `J_E = det F_E > 0`.
    pub f_e: Mat<T, D>,
    /// Plastic deformation gradient `F_P`, `F = F_E F_P`, `J_P = det F_P > 0`.
    pub f_p: Mat<T, D>,
    /// Mass `m_p` (kg).
    pub mass: T,
    /// Reference volume `V⁰_p` (m³).
    pub volume0: T,
    /// Temperature `T_p` (K); read only when heat is on.
    pub temperature: T,
    /// Latent heat buffer `U ∈ [0, L]` (J/kg); read only with phase change.
    pub latent: T,
    /// Phase.
    pub phase: Phase,
}

impl<T: Real, const D: usize> Particle<T, D> {
    /// An undeformed solid particle at rest at `x` (temperature 0 K, empty buffer).
    #[inline]
    #[must_use]
    pub fn at_rest(x: [T; D], mass: T, volume0: T) -> Self {
        Self {
            x,
            v: [T::ZERO; D],
            affine: Mat::ZERO,
            f_e: Mat::identity(),
            f_p: Mat::identity(),
            mass,
            volume0,
            temperature: T::ZERO,
            latent: T::ZERO,
            phase: Phase::Solid,
        }
    }
}
