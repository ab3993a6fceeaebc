//! The per-particle entries of a time step, driven by a [`Material`]: the parts of the model
//! that are off are skipped (see [`Material`]).
//!
//! A time step of augmented MPM (Stomakhin et al. 2014, §5–§7) as a host runs it:
//! 1. [`p2g`] per particle: stencil, node masses and APIC momenta (Jiang et al. 2015), the
//!    stress force `f_i = −V⁰ P F_Eᵀ ∇w_i` (Stomakhin et al. 2013, eq. 6 with
//!    `V_p = J V⁰`, `σ = P F_Eᵀ / J`), and node heat capacities and thermal energies.
//! 2. The host's grid work: velocities, boundary conditions, an implicit solve applying
//!    [`Stiffness`] per Krylov iteration, a pressure solve with
//!    [`pressure_coefficient`], a heat solve.
//! 3. [`g2p_update`] per particle: the gather ([`apic::gather`], [`thermal::gather`]) into a
//!    [`G2pSample`], then [`update_particle`]: temperature and phase, velocity and affine
//!    matrix, position, `F_E` (with the remedy for `det(I + Δt∇v) ≤ 0`), then the liquid
//!    projection or the snow plasticity. A host that gathers itself (a MAC grid, its own
//!    grid layout) calls [`update_particle`] directly.
//!
//! Every entry validates its inputs and returns a new value (or fills caller-provided
//! per-node slices only on success), so a failed particle is left as it was.
//!
//! **Statuses.** A NaN/inf input is [`Error::NonFinite`]; a result of finite inputs that is
//! not representable is [`Error::Overflow`] (also a determinant that underflows); an `F_E`
//! or `F_P` singular to working precision is [`Error::NonPositiveJ`]. What an entry returns
//! with `Ok` is finite; the particle that [`update_particle`] and [`g2p_update`] return is
//! accepted by every entry ([`check_particle`], [`thermal::check_state`],
//! [`Material::moduli`]), so a step that succeeds never leaves a particle that the next
//! step refuses.
//!
//! [`apic::gather`]: super::apic::gather

use super::apic::gather;
use super::deformation::{advance, check_det, increment, liquid_step, snow_plasticity_on};
use super::stencil::{Grid, Kernel, Stencil};
use super::thermal::{self, HeatSplit, ThermalState};
use super::{Material, Particle, Phase};
use crate::error::{Error, Result};
use crate::lane::Lane;
use crate::mat::{Mat, Matrix};
use crate::polar::{DefaultSvd, SvdMethod};
use crate::scalar::Real;

pub use super::stiffness::{elastic_energy, force_differential, Stiffness};

mod scatter;
pub use scatter::{kirchhoff_stress, kirchhoff_unchecked, p2g, NodeP2g, P2g};

/// Checks the fields every entry reads: finite state, positive mass and volume, `J_E`,
/// `J_P > 0` (computed determinants, finite). Returns `(J_E, J_P)`.
///
/// Errors: [`Error::NonFinite`] for a NaN/inf field, [`Error::InvalidArgument`] for
/// `m ≤ 0` or `V⁰ ≤ 0`, [`Error::Overflow`] for a determinant that overflows,
/// [`Error::NonPositiveJ`] for `J_E ≤ 0` or `J_P ≤ 0`.
#[inline]
pub fn check_particle<T: Real, const D: usize>(p: &Particle<T, D>) -> Result<(T, T)>
where
    Mat<T, D>: Matrix<Scalar = T>,
{
    let vec_ok = p.x.iter().chain(p.v.iter()).all(|c| c.is_finite());
    if !(vec_ok
        && p.affine.is_finite()
        && p.f_e.is_finite()
        && p.f_p.is_finite()
        && p.mass.is_finite()
        && p.volume0.is_finite())
    {
        return Err(Error::NonFinite);
    }
    if p.mass <= T::ZERO || p.volume0 <= T::ZERO {
        return Err(Error::InvalidArgument);
    }
    let j_e = Matrix::det(&p.f_e);
    let j_p = Matrix::det(&p.f_p);
    if !(j_e.is_finite() && j_p.is_finite()) {
        return Err(Error::Overflow);
    }
    if j_e <= T::ZERO || j_p <= T::ZERO {
        return Err(Error::NonPositiveJ);
    }
    Ok((j_e, j_p))
}

/// The grid values G2P reads, gathered by the host in stencil order (see
/// [`super::stencil`]) from the particle's collocated stencil.
#[derive(Clone, Copy, Debug)]
pub struct GridSample<'a, T, const D: usize> {
    /// Node velocities `v_iⁿ⁺¹` (m/s).
    pub velocity: &'a [[T; D]],
    /// Node temperatures `(T_iⁿ⁺¹, T_iⁿ)` (K); required when heat is on, else ignored.
    pub temperature: Option<(&'a [T], &'a [T])>,
}

/// What [`update_particle`] (and [`g2p_update`]) did besides the new state.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct UpdateInfo<T> {
    /// Halvings used by the remedy for `det(I + Δt∇v) ≤ 0` (0 when it was not needed).
    pub halvings: u32,
    /// Heat received per unit mass (J/kg), by destination; zero without phase change.
    pub heat: HeatSplit<T>,
}

/// What G2P gathered for one particle from the grid (collocated or MAC): the input of
/// [`update_particle`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct G2pSample<T, const D: usize> {
    /// `v_p = Σ w_i v_iⁿ⁺¹` (m/s).
    pub v: [T; D],
    /// APIC `C_p = B_p D_p⁻¹` (1/s), column-major.
    pub affine: Mat<T, D>,
    /// `∇v_p = Σ v_iⁿ⁺¹ ∇w_iᵀ` (1/s), column-major.
    pub grad_v: Mat<T, D>,
    /// `Σ w_i T_iⁿ⁺¹` (K); read only when heat is on.
    pub t_pic: T,
    /// `Σ w_i (T_iⁿ⁺¹ − T_iⁿ)` (K); read only when heat is on.
    pub t_flip: T,
}

/// The input checks of [`update_particle`] but the temperature: material, particle, `Δt`.
/// Returns `J_P` ([`check_particle`]).
#[inline]
fn check_update_inputs<T: Real, const D: usize>(
    material: &Material<T>,
    dt: T,
    p: &Particle<T, D>,
) -> Result<T>
where
    Mat<T, D>: Matrix<Scalar = T>,
{
    material.validate(p.phase)?;
    check_particle_dt(p, dt)
}

/// The particle and `Δt` checks of [`update_particle`]. Returns `J_P` ([`check_particle`]).
#[inline(always)]
fn check_particle_dt<T: Real, const D: usize>(p: &Particle<T, D>, dt: T) -> Result<T>
where
    Mat<T, D>: Matrix<Scalar = T>,
{
    let (_, j_p) = check_particle(p)?;
    if !dt.is_finite() {
        return Err(Error::NonFinite);
    }
    if dt <= T::ZERO {
        return Err(Error::InvalidArgument);
    }
    Ok(j_p)
}

/// The particle's temperature, read when heat is on.
#[inline]
fn check_temperature<T: Real, const D: usize>(
    material: &Material<T>,
    p: &Particle<T, D>,
) -> Result<()> {
    if material.heat.is_some() && !p.temperature.is_finite() {
        return Err(Error::NonFinite);
    }
    Ok(())
}

/// The particle update of one particle from what G2P gathered (step `Δt` s):
/// 1. heat (if on): `T*` by PIC/FLIP ([`thermal::blend`] of `s.t_pic`, `s.t_flip`); with
///    phase change the heat `q = c (T* − T_p)` goes through the latent buffer and may switch
///    the phase ([`thermal::absorb`]);
/// 2. APIC: `v_p ← s.v`, `C_p ← s.affine`, `x_p ← x_p + Δt v_p`;
/// 3. `F_E ← (I + Δt∇v) F_E` with the remedy ([`evolve`](super::deformation::evolve));
/// 4. a liquid keeps its volume ratios only ([`liquid_step`]: `F_E ← J_E^{1/d} I`,
///    `F_P ← J_P^{1/d} I`, for an isotropic `F_E` from `det(I + Δt∇v)` without the product
///    of step 3); a solid with snow plasticity clamps ([`snow_plasticity`]); an elastic solid
///    does neither.
///
/// The phase of step 4 is the one after step 1 (a solid that melts is projected at once).
/// The new particle is checked as the next call will check it ([`check_particle`],
/// [`thermal::check_state`] with phase change, [`Material::moduli`]), so `Ok` never carries
/// a state that a later entry refuses. The input is not modified, so a failure leaves it as
/// it was. `h` is not known here: the position limit of [`Stencil::new`] is checked by
/// [`g2p_update`], or by the caller.
///
/// Errors: invalid material or particle ([`check_particle`]), `Δt` NaN/inf
/// ([`Error::NonFinite`]) or `≤ 0` ([`Error::InvalidArgument`]); a NaN/inf value of `s` that
/// is read ([`Error::NonFinite`]; the temperatures only with heat on); [`Error::Overflow`]
/// for a new value that is not representable (a temperature, position, `F_E`, `F_P`, their
/// determinants, or the hardening factor of the new `J_P`); [`Error::NonPositiveJ`] for a new
/// `F_E` or `F_P` singular to working precision (e.g. the plastic flow of an `F_E` stretched
/// beyond `~1/ε`); the kernels' errors.
///
/// [`snow_plasticity`]: super::deformation::snow_plasticity
#[inline]
pub fn update_particle<T: Real, const D: usize>(
    material: &Material<T>,
    dt: T,
    s: &G2pSample<T, D>,
    p: &Particle<T, D>,
) -> Result<(Particle<T, D>, UpdateInfo<T>)>
where
    Mat<T, D>: Matrix<Scalar = T, Vector = [T; D]>,
    DefaultSvd: SvdMethod<Mat<T, D>>,
{
    let j_p = check_update_inputs(material, dt, p)?;
    check_temperature(material, p)?;
    update_checked::<T, T, D>(material, dt, s, p, j_p)
}

/// [`update_particle`] for a caller that has validated the material for the particle's phase
/// (`material.validate(p.phase)`, as the batch transfers do once per call): the particle,
/// `dt` and temperature checks and the update, inlined into the caller's loop. Snow
/// plasticity's step runs on lanes of `V` ([`snow_plasticity_on`]: the bits of the batch's
/// chunks of `V`).
///
/// [`snow_plasticity_on`]: super::deformation::snow_plasticity_on
#[inline(always)]
pub(crate) fn update_validated<T: Real, V: Lane<Scalar = T>, const D: usize>(
    material: &Material<T>,
    dt: T,
    s: &G2pSample<T, D>,
    p: &Particle<T, D>,
) -> Result<(Particle<T, D>, UpdateInfo<T>)>
where
    Mat<T, D>: Matrix<Scalar = T, Vector = [T; D]>,
    DefaultSvd: SvdMethod<Mat<T, D>>,
{
    let j_p = check_particle_dt(p, dt)?;
    check_temperature(material, p)?;
    update_checked::<T, V, D>(material, dt, s, p, j_p)
}

/// [`update_particle`] after its input checks ([`check_update_inputs`], the temperature), which
/// gave `j_p = det F_P`; snow plasticity's step on lanes of `V`.
#[inline(always)]
fn update_checked<T: Real, V: Lane<Scalar = T>, const D: usize>(
    material: &Material<T>,
    dt: T,
    s: &G2pSample<T, D>,
    p: &Particle<T, D>,
    j_p: T,
) -> Result<(Particle<T, D>, UpdateInfo<T>)>
where
    Mat<T, D>: Matrix<Scalar = T, Vector = [T; D]>,
    DefaultSvd: SvdMethod<Mat<T, D>>,
{
    if !(s.v.iter().all(|c| c.is_finite()) && s.affine.is_finite() && s.grad_v.is_finite()) {
        return Err(Error::NonFinite);
    }
    let mut out = *p;
    let mut info = UpdateInfo::default();

    // 1. Heat and phase.
    if let Some(heat) = &material.heat {
        let st = ThermalState {
            temperature: p.temperature,
            latent: p.latent,
            phase: p.phase,
        };
        let (st, split) = thermal::step(material, heat, &st, s.t_pic, s.t_flip)?;
        out.temperature = st.temperature;
        out.latent = st.latent;
        out.phase = st.phase;
        info.heat = split;
    }

    // 2. APIC velocity, affine matrix and advection.
    out.v = s.v;
    out.affine = s.affine;
    for a in 0..D {
        out.x[a] = p.x[a] + dt * s.v[a];
        if !out.x[a].is_finite() {
            return Err(Error::Overflow);
        }
    }

    // 3. and 4. Elastic deformation gradient with the remedy, then the liquid projection
    // (a liquid's `F_E = s I` takes `det A` only) or plasticity. A kept `F_P` keeps its
    // checked `J_P`.
    let (a, k) = increment(&s.grad_v, dt)?;
    info.halvings = k;
    let (f_e, f_p, kept) = match (out.phase, &material.plasticity) {
        (Phase::Liquid, _) => {
            let (fe, fp) = liquid_step(&p.f_e, &a, &p.f_p)?;
            (fe, fp, None)
        }
        (Phase::Solid, plasticity) => {
            let (f_e, j_e) = advance(&a, &p.f_e)?;
            match plasticity {
                Some(snow) => {
                    let (fe, fp) = snow_plasticity_on::<T, V, D>(snow, &f_e, &p.f_p)?;
                    (fe, fp, None)
                }
                None => (f_e, p.f_p, Some((j_e, j_p))),
            }
        }
    };
    out.f_e = f_e;
    out.f_p = f_p;

    check_result(material, &out, kept)?;
    Ok((out, info))
}

/// Checks a new particle as the next entry will check it, with the statuses of a result:
/// a non-finite value or a determinant that under- or overflows is [`Error::Overflow`]
/// ([`check_det`]), a singular `F_E` or `F_P` [`Error::NonPositiveJ`].
///
/// `known = Some((J_E, J_P))` when the caller has established what [`check_particle`] would
/// return: `x`, `v`, `affine` checked finite, `F_E` from [`evolve_det`] (finite, `J_E` its
/// positive finite determinant), `F_P`, mass and volume the input's, `J_P` its checked
/// determinant. Then only the temperature, phase and moduli checks are left.
#[inline]
fn check_result<T: Real, const D: usize>(
    material: &Material<T>,
    p: &Particle<T, D>,
    known: Option<(T, T)>,
) -> Result<()>
where
    Mat<T, D>: Matrix<Scalar = T>,
{
    let checked = match known {
        Some(j) => Ok(j),
        None => check_particle(p),
    };
    debug_assert!(known.is_none() || check_particle(p) == checked);
    let j_p = match checked {
        Ok((_, j_p)) => j_p,
        Err(Error::NonFinite) => return Err(Error::Overflow),
        Err(Error::NonPositiveJ) => {
            check_det(&p.f_e)?;
            check_det(&p.f_p)?;
            // Unreachable: check_det accepts exactly what check_particle does.
            return Err(Error::NonPositiveJ);
        }
        Err(e) => return Err(e),
    };
    if let Some(heat) = &material.heat {
        let st = ThermalState {
            temperature: p.temperature,
            latent: p.latent,
            phase: p.phase,
        };
        thermal::check_result(heat, &st)?;
    }
    material.moduli(p.phase, j_p)?;
    Ok(())
}

/// G2P and the particle update of one particle (collocated grid, spacing `h` m, step `Δt` s):
/// the stencil, [`apic::gather`] of the node velocities, [`thermal::gather`] of the node
/// temperatures (heat on), then [`update_particle`]; finally the new position is checked
/// against the position limit of [`Stencil::new`] for `h`.
///
/// [`apic::gather`]: super::apic::gather
///
/// Returns the new particle; the input is not modified, so a failure leaves it as it was.
///
/// Errors: invalid material, particle, `h`, `Δt ≤ 0`, short grid slices, missing temperatures
/// with heat on ([`Error::InvalidArgument`]); those of the gathers (NaN/inf node values
/// [`Error::NonFinite`], sums that overflow or a tiny `h` [`Error::Overflow`]); those of
/// [`update_particle`]; [`Error::Overflow`] when the new position is beyond the position
/// limit `|x/h| < 2³⁰`.
#[inline]
pub fn g2p_update<T: Real, const D: usize>(
    material: &Material<T>,
    kernel: Kernel,
    h: T,
    dt: T,
    grid: &GridSample<'_, T, D>,
    p: &Particle<T, D>,
) -> Result<(Particle<T, D>, UpdateInfo<T>)>
where
    Mat<T, D>: Matrix<Scalar = T, Vector = [T; D]>,
    DefaultSvd: SvdMethod<Mat<T, D>>,
{
    let j_p = check_update_inputs(material, dt, p)?;
    let stencil = Stencil::new(kernel, Grid::Collocated, h, &p.x)?;
    let (t_pic, t_flip) = match material.heat {
        Some(_) => {
            let (t_new, t_old) = grid.temperature.ok_or(Error::InvalidArgument)?;
            check_temperature(material, p)?;
            thermal::gather(&stencil, t_new, t_old)?
        }
        None => (T::ZERO, T::ZERO),
    };
    let g = gather(&stencil, grid.velocity)?;
    let sample = G2pSample {
        v: g.v,
        affine: g.affine,
        grad_v: g.grad_v,
        t_pic,
        t_flip,
    };
    let (out, info) = update_checked::<T, T, D>(material, dt, &sample, p, j_p)?;
    if Stencil::<T, D>::check_position(Grid::Collocated, h, &out.x).is_err() {
        // The cell index of the new position is beyond the supported range.
        return Err(Error::Overflow);
    }
    Ok((out, info))
}

pub use super::pressure::{pressure, pressure_coefficient};

#[cfg(test)]
mod tests;
