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

use super::apic::{self, gather};
use super::deformation::{advance, check_det, increment, liquid_step, snow_plasticity};
use super::dilation;
use super::stencil::{Grid, Kernel, Stencil};
use super::thermal::{self, HeatSplit, ThermalState};
use super::{Dilation, Material, Particle, Phase};
use crate::augmented::Augmented;
use crate::energy::FixedCorotated;
use crate::error::{Error, Result};
use crate::mat::{Mat, Matrix};
use crate::polar::{DefaultSvd, SvdMethod};
use crate::scalar::Real;

pub use super::stiffness::{elastic_energy, force_differential, Stiffness};

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

/// The Kirchhoff stress `τ = P F_Eᵀ` of a particle (Pa), `P = Â + P_λ`:
/// - `Â = ∂Ψ̂_μ/∂F_E` of the fixed corotated energy with the particle's (hardened) `μ`
///   ([`crate::augmented`]); skipped, with no decomposition, when `μ = 0` (liquids);
/// - `P_λ F_Eᵀ = λ(J_E − 1) J_E I` ([`dilation::kirchhoff`]) when the material's dilation is
///   [`Dilation::Explicit`]; left to the host's pressure solve otherwise.
///
/// Errors: invalid material or particle, or the kernels' errors.
#[inline]
pub fn kirchhoff_stress<T: Real, const D: usize>(
    material: &Material<T>,
    p: &Particle<T, D>,
) -> Result<Mat<T, D>>
where
    Mat<T, D>: Matrix<Scalar = T, Vector = [T; D]>,
    DefaultSvd: SvdMethod<Mat<T, D>>,
{
    material.validate(p.phase)?;
    let (j_e, j_p) = check_particle(p)?;
    kirchhoff_unchecked(material, p, j_e, j_p)
}

/// [`kirchhoff_stress`] of a particle already checked by [`check_particle`] (which returned
/// `(j_e, j_p)`) with a material already validated for its phase.
///
/// Errors: the kernels' errors; [`Error::Overflow`] for a stress that is not representable.
#[inline]
pub fn kirchhoff_unchecked<T: Real, const D: usize>(
    material: &Material<T>,
    p: &Particle<T, D>,
    j_e: T,
    j_p: T,
) -> Result<Mat<T, D>>
where
    Mat<T, D>: Matrix<Scalar = T, Vector = [T; D]>,
    DefaultSvd: SvdMethod<Mat<T, D>>,
{
    let m = material.moduli(p.phase, j_p)?;
    let mut tau = Mat::<T, D>::ZERO;
    if m.mu > T::ZERO {
        let e = FixedCorotated::new(m.mu);
        let ahat = Augmented::new(&e, &p.f_e)?.ahat()?;
        tau = ahat * p.f_e.transpose();
    }
    if material.dilation == Dilation::Explicit {
        let k = dilation::kirchhoff(j_e, m.inv_lambda)?;
        tau += Mat::from_diagonal([k; D]);
    }
    if tau.is_finite() {
        Ok(tau)
    } else {
        Err(Error::Overflow)
    }
}

/// A particle's P2G data; [`P2g::node`] gives its contribution to each stencil node.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct P2g<T, const D: usize> {
    /// The particle's stencil on the collocated grid.
    pub stencil: Stencil<T, D>,
    /// `m_p` (kg).
    pub mass: T,
    /// `v_p` (m/s).
    pub v: [T; D],
    /// `C_p` (1/s).
    pub affine: Mat<T, D>,
    /// `−V⁰ τ` (N·m): the force on node `i` is this times `∇w_i`.
    pub force: Mat<T, D>,
    /// `m_p c_p` (J/K), 0 when heat is off.
    pub heat_capacity: T,
    /// `T_p` (K), 0 when heat is off.
    pub temperature: T,
    /// `m_p κ_p` (kg·W/(m·K)), 0 when heat is off: a host dividing the node sum by the node
    /// mass gets the mass-weighted conductivity.
    pub conductivity: T,
}

/// One node's share of a particle's P2G.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NodeP2g<T, const D: usize> {
    /// Grid index of the node.
    pub index: [i32; D],
    /// `w_i`.
    pub weight: T,
    /// `w_i m_p` (kg).
    pub mass: T,
    /// `w_i m_p (v_p + C_p (x_i − x_p))` (kg·m/s).
    pub momentum: [T; D],
    /// `−V⁰ τ ∇w_i` (N).
    pub force: [T; D],
    /// `w_i m_p c_p` (J/K).
    pub heat_capacity: T,
    /// `w_i m_p c_p T_p` (J).
    pub thermal_energy: T,
    /// `w_i m_p κ_p`.
    pub conductivity: T,
}

impl<T: Real, const D: usize> P2g<T, D>
where
    Mat<T, D>: Matrix<Scalar = T>,
{
    /// The contribution to stencil node `r < stencil.len()`. Finite for every `r` when this
    /// came from [`p2g`]; [`P2g::node_checked`] checks.
    #[inline]
    #[must_use]
    pub fn node(&self, r: usize) -> NodeP2g<T, D> {
        let n = self.stencil.node(r);
        NodeP2g {
            index: n.index,
            weight: n.weight,
            mass: n.weight * self.mass,
            momentum: apic::node_momentum(&self.stencil, r, self.mass, &self.v, &self.affine),
            force: self.force.mul_vec(n.grad),
            heat_capacity: n.weight * self.heat_capacity,
            thermal_energy: n.weight * self.heat_capacity * self.temperature,
            conductivity: n.weight * self.conductivity,
        }
    }

    /// [`P2g::node`], checked.
    ///
    /// Errors: [`Error::InvalidArgument`] for `r ≥ stencil.len()`; [`Error::Overflow`] when
    /// a value of the contribution is not finite.
    #[inline]
    pub fn node_checked(&self, r: usize) -> Result<NodeP2g<T, D>> {
        if r >= self.stencil.len() {
            return Err(Error::InvalidArgument);
        }
        let n = self.node(r);
        let mut chk = n.weight * T::ZERO
            + n.mass * T::ZERO
            + n.heat_capacity * T::ZERO
            + n.thermal_energy * T::ZERO
            + n.conductivity * T::ZERO;
        for a in 0..D {
            chk += n.momentum[a] * T::ZERO + n.force[a] * T::ZERO;
        }
        // x·0 is 0 for finite x and NaN for NaN/inf.
        if chk == T::ZERO {
            Ok(n)
        } else {
            Err(Error::Overflow)
        }
    }

    /// Whether every node contribution is finite.
    ///
    /// First a bound: rounding is monotone and `|fl(a + b)| ≤ fl(|a| + |b|)`, so a value
    /// computed with the same operations from upper bounds of the factors' magnitudes bounds
    /// the computed node value. With `w_i ≤ 1`, `|x_i − x_p| ≤ 2h` (computed as `(o − fx) h`,
    /// `|o − fx| ≤ 2`) and `|∇w_i|_a ≤ 1/h` (`|N'| ≤ 1`, the other factors `≤ 1`), every
    /// node value is at most one of `m_p (|v_a| + Σ_b |C_ab| 2h)`, `Σ_b |f_ab| / h`, `m_p`,
    /// `m_p c_p`, `m_p c_p |T_p|`, `m_p κ_p`; when these are finite, so is every node. Only
    /// when one is not (within a small factor of the overflow threshold) are the nodes
    /// checked one by one, so the answer is exact.
    #[inline]
    fn nodes_finite(&self) -> bool {
        let h = self.stencil.h;
        let dx = [h + h; D];
        let g = [T::ONE / h; D];
        let c = self.affine.map(|x| x.abs()).mul_vec(dx);
        let f = self.force.map(|x| x.abs()).mul_vec(g);
        let mut chk = self.mass * T::ZERO
            + self.heat_capacity * T::ZERO
            + (self.heat_capacity * self.temperature.abs()) * T::ZERO
            + self.conductivity * T::ZERO;
        for a in 0..D {
            chk += (self.mass * (self.v[a].abs() + c[a])) * T::ZERO + f[a] * T::ZERO;
        }
        chk == T::ZERO || (0..self.stencil.len()).all(|r| self.node_checked(r).is_ok())
    }
}

/// P2G of one particle on a collocated grid with spacing `h` (m): stencil, mass, momentum,
/// stress force and heat (see [`P2g`]). On success every [`P2g::node`] is finite.
///
/// Errors: invalid material, particle or stencil; the stress kernels' errors;
/// [`Error::Overflow`] when a node contribution of the finite inputs is not representable
/// (e.g. `m_p |v_p|`, `m_p c_p T_p`, or a force `∼ V⁰ |τ| / h` beyond the largest finite
/// value).
#[inline]
pub fn p2g<T: Real, const D: usize>(
    material: &Material<T>,
    kernel: Kernel,
    h: T,
    p: &Particle<T, D>,
) -> Result<P2g<T, D>>
where
    Mat<T, D>: Matrix<Scalar = T, Vector = [T; D]>,
    DefaultSvd: SvdMethod<Mat<T, D>>,
{
    material.validate(p.phase)?;
    let (j_e, j_p) = check_particle(p)?;
    let stencil = Stencil::new(kernel, Grid::Collocated, h, &p.x)?;
    let tau = kirchhoff_unchecked(material, p, j_e, j_p)?;
    let force = tau * (-p.volume0);
    if !force.is_finite() {
        return Err(Error::Overflow);
    }
    let (heat_capacity, temperature, conductivity) = match &material.heat {
        Some(_) => {
            if !p.temperature.is_finite() {
                return Err(Error::NonFinite);
            }
            let pp = material.params(p.phase);
            (
                p.mass * pp.heat_capacity,
                p.temperature,
                p.mass * pp.conductivity,
            )
        }
        None => (T::ZERO, T::ZERO, T::ZERO),
    };
    let out = P2g {
        stencil,
        mass: p.mass,
        v: p.v,
        affine: p.affine,
        force,
        heat_capacity,
        temperature,
        conductivity,
    };
    if !(heat_capacity.is_finite() && conductivity.is_finite() && out.nodes_finite()) {
        return Err(Error::Overflow);
    }
    Ok(out)
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
///    of step 3); a solid with snow plasticity clamps ([`snow_plasticity`]); an
///    elastic solid does neither.
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
    update_checked(material, dt, s, p, j_p)
}

/// [`update_particle`] for a caller that has validated the material for the particle's phase
/// (`material.validate(p.phase)`, as the batch transfers do once per call): the particle,
/// `dt` and temperature checks and the update, inlined into the caller's loop.
#[inline(always)]
pub(crate) fn update_validated<T: Real, const D: usize>(
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
    update_checked(material, dt, s, p, j_p)
}

/// [`update_particle`] after its input checks ([`check_update_inputs`], the temperature), which
/// gave `j_p = det F_P`.
#[inline(always)]
fn update_checked<T: Real, const D: usize>(
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
                    let (fe, fp) = snow_plasticity(snow, &f_e, &p.f_p)?;
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
    let (out, info) = update_checked(material, dt, &sample, p, j_p)?;
    if Stencil::<T, D>::check_position(Grid::Collocated, h, &out.x).is_err() {
        // The cell index of the new position is beyond the supported range.
        return Err(Error::Overflow);
    }
    Ok((out, info))
}

pub use super::pressure::{pressure, pressure_coefficient};

#[cfg(test)]
mod tests;
