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
//! 3. [`g2p_update`] per particle: temperature and phase, velocity and affine matrix, position,
//!    `F_E` (with the remedy for `det(I + Δt∇v) ≤ 0`), then the liquid projection or the snow
//!    plasticity.
//!
//! Every entry validates its inputs and returns a new value (or fills caller-provided
//! per-node slices only on success), so a failed particle is left as it was.

use super::apic::{self, gather};
use super::deformation::{evolve, liquid_projection, snow_plasticity};
use super::dilation;
use super::stencil::{Grid, Kernel, Stencil};
use super::thermal::{self, HeatSplit, ThermalState};
use super::{Definiteness, Dilation, Material, Particle, Phase};
use crate::augmented::Augmented;
use crate::energy::FixedCorotated;
use crate::error::{Error, Result};
use crate::hessian::{HessianDim, HessianEigensystem};
use crate::mat::{Mat, Matrix};
use crate::polar::{DefaultSvd, SvdMethod};
use crate::scalar::Real;

/// Checks the fields every entry reads: finite state, positive mass and volume, `J_E`,
/// `J_P > 0`. Returns `(J_E, J_P)`.
#[inline]
fn check_particle<T: Real, const D: usize>(p: &Particle<T, D>) -> Result<(T, T)>
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

#[inline]
fn kirchhoff_unchecked<T: Real, const D: usize>(
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
    /// The contribution to stencil node `r < stencil.len()`.
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
}

/// P2G of one particle on a collocated grid with spacing `h` (m): stencil, mass, momentum,
/// stress force and heat (see [`P2g`]).
///
/// Errors: invalid material, particle or stencil; the stress kernels' errors.
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
    Ok(P2g {
        stencil,
        mass: p.mass,
        v: p.v,
        affine: p.affine,
        force,
        heat_capacity,
        temperature,
        conductivity,
    })
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

/// What [`g2p_update`] did besides the new state.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct UpdateInfo<T> {
    /// Halvings used by the remedy for `det(I + Δt∇v) ≤ 0` (0 when it was not needed).
    pub halvings: u32,
    /// Heat received per unit mass (J/kg), by destination; zero without phase change.
    pub heat: HeatSplit<T>,
}

/// G2P and the particle update of one particle (collocated grid, spacing `h` m, step `Δt` s):
/// 1. heat (if on): `T* ` by PIC/FLIP; with phase change the heat `q = c (T* − T_p)` goes
///    through the latent buffer and may switch the phase ([`thermal::absorb`]);
/// 2. APIC: `v_p`, `C_p`, `∇v_p` ([`apic::gather`]), `x_p ← x_p + Δt v_p`;
/// 3. `F_E ← (I + Δt∇v) F_E` with the remedy ([`evolve`]);
/// 4. a liquid drops the deviatoric part of `F_E` ([`liquid_projection`]); a solid with snow
///    plasticity clamps ([`snow_plasticity`]); an elastic solid does neither.
///
/// Returns the new particle; the input is not modified, so a failure leaves it as it was.
///
/// Errors: invalid material, particle, `h`, `Δt ≤ 0`, short grid slices, missing temperatures
/// with heat on ([`Error::InvalidArgument`]); the kernels' errors.
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
    material.validate(p.phase)?;
    check_particle(p)?;
    if !dt.is_finite() {
        return Err(Error::NonFinite);
    }
    if dt <= T::ZERO {
        return Err(Error::InvalidArgument);
    }
    let stencil = Stencil::new(kernel, Grid::Collocated, h, &p.x)?;
    let mut out = *p;
    let mut info = UpdateInfo::default();

    // 1. Heat and phase.
    if let Some(heat) = &material.heat {
        let (t_new, t_old) = grid.temperature.ok_or(Error::InvalidArgument)?;
        let n = stencil.len();
        if t_new.len() < n || t_old.len() < n || !p.temperature.is_finite() {
            return Err(if p.temperature.is_finite() {
                Error::InvalidArgument
            } else {
                Error::NonFinite
            });
        }
        let (mut pic, mut flip) = (T::ZERO, T::ZERO);
        for r in 0..n {
            let w = stencil.node(r).weight;
            pic += w * t_new[r];
            flip += w * (t_new[r] - t_old[r]);
        }
        let t_star = thermal::blend(heat.flip, p.temperature, pic, flip);
        if !t_star.is_finite() {
            return Err(Error::NonFinite);
        }
        if heat.phase_change {
            let c = material.params(p.phase).heat_capacity;
            let q = c * (t_star - p.temperature);
            let st = ThermalState {
                temperature: p.temperature,
                latent: p.latent,
                phase: p.phase,
            };
            let (st, split) = thermal::absorb(
                heat,
                material.solid.heat_capacity,
                material.liquid.heat_capacity,
                &st,
                q,
            )?;
            out.temperature = st.temperature;
            out.latent = st.latent;
            out.phase = st.phase;
            info.heat = split;
        } else {
            out.temperature = t_star;
        }
    }

    // 2. APIC G2P and advection.
    let g = gather(&stencil, grid.velocity)?;
    out.v = g.v;
    out.affine = g.affine;
    for a in 0..D {
        out.x[a] = p.x[a] + dt * g.v[a];
        if !out.x[a].is_finite() {
            return Err(Error::Overflow);
        }
    }

    // 3. Elastic deformation gradient, with the remedy.
    let (f_e, k) = evolve(&p.f_e, &g.grad_v, dt)?;
    info.halvings = k;

    // 4. Liquid projection or plasticity.
    let (f_e, f_p) = match (out.phase, &material.plasticity) {
        (Phase::Liquid, _) => liquid_projection(&f_e, &p.f_p)?,
        (Phase::Solid, Some(snow)) => snow_plasticity(snow, &f_e, &p.f_p)?,
        (Phase::Solid, None) => (f_e, p.f_p),
    };
    out.f_e = f_e;
    out.f_p = f_p;
    Ok((out, info))
}

/// The fixed corotated energy of a particle, with its (hardened) `μ`, for [`Stiffness::new`].
///
/// Errors: invalid material or particle.
#[inline]
pub fn elastic_energy<T: Real, const D: usize>(
    material: &Material<T>,
    p: &Particle<T, D>,
) -> Result<FixedCorotated<T>>
where
    Mat<T, D>: Matrix<Scalar = T>,
{
    material.validate(p.phase)?;
    let (_, j_p) = check_particle(p)?;
    Ok(FixedCorotated::new(material.moduli(p.phase, j_p)?.mu))
}

/// The force differential of one particle for an implicit solve: for node displacements
/// `δu_j` (m; `Δt δv_j` for backward Euler) the particle's `δF_E = G F_E`,
/// `G = Σ_j δu_j ∇w_jᵀ`, and the node force differentials are
/// `δf_i = −V⁰ (Ĉ:δF_E + δP_λ) F_Eᵀ ∇w_i` (N), the issue's `δf = −V⁰ (Ĉ:(Σ_j δv_j ∇w_jᵀ F))
/// Fᵀ ∇w`, with the dilational term [`dilation::d_kirchhoff`] only for
/// [`Dilation::Explicit`].
///
/// Built once per particle and time step (one decomposition), applied once per Krylov
/// iteration. The energy is borrowed, so a Rust host keeps the energies (from
/// [`elastic_energy`]) alive next to the stiffnesses.
///
/// With [`Definiteness::Projected`] the material asks for the PSD projection `Ĉ⁺`
/// ([`crate::hessian::HessianEigensystem::psd`]) in place of `Ĉ`, built once here too.
/// [`Stiffness::d_force_matrix_with`] takes any other Hessian action in place of `Ĉ:Z`.
#[derive(Clone, Copy, Debug)]
pub struct Stiffness<'e, T: Real, const D: usize>
where
    Mat<T, D>: Matrix<Scalar = T> + HessianDim,
    DefaultSvd: SvdMethod<Mat<T, D>>,
{
    aug: Option<Augmented<'e, Mat<T, D>, FixedCorotated<T>>>,
    psd: Option<HessianEigensystem<Mat<T, D>>>,
    f_e: Mat<T, D>,
    j_e: T,
    inv_lambda: Option<T>,
    volume0: T,
}

impl<'e, T: Real, const D: usize> Stiffness<'e, T, D>
where
    Mat<T, D>: Matrix<Scalar = T, Vector = [T; D]> + HessianDim,
    DefaultSvd: SvdMethod<Mat<T, D>>,
{
    /// Prepares the differential of particle `p` with `energy` (from [`elastic_energy`];
    /// `μ = 0` skips the deviatoric part and its decomposition), with the material's
    /// [`Definiteness`].
    ///
    /// Errors: invalid material or particle; the kernels' errors.
    #[inline]
    pub fn new(
        energy: &'e FixedCorotated<T>,
        material: &Material<T>,
        p: &Particle<T, D>,
    ) -> Result<Self> {
        material.validate(p.phase)?;
        let (j_e, j_p) = check_particle(p)?;
        let (aug, psd) = match (energy.mu == T::ZERO, material.hessian) {
            (true, _) => (None, None),
            (false, Definiteness::Exact) => (Some(Augmented::new(energy, &p.f_e)?), None),
            (false, Definiteness::Projected) => {
                (None, Some(HessianEigensystem::new(energy, &p.f_e)?.psd()?))
            }
        };
        let inv_lambda = match material.dilation {
            Dilation::Explicit => Some(material.moduli(p.phase, j_p)?.inv_lambda),
            Dilation::PressureSolve => None,
        };
        Ok(Self {
            aug,
            psd,
            f_e: p.f_e,
            j_e,
            inv_lambda,
            volume0: p.volume0,
        })
    }

    /// `−V⁰ (Ĉ:(G F_E) + δP_λ) F_Eᵀ` (N·m), `Ĉ⁺` with [`Definiteness::Projected`]: the node
    /// force differential is this times `∇w_i`.
    #[inline]
    pub fn d_force_matrix(&self, g: &Mat<T, D>) -> Result<Mat<T, D>> {
        if let Some(psd) = &self.psd {
            if !g.is_finite() {
                return Err(Error::NonFinite);
            }
            let mut m = psd.apply(&(*g * self.f_e))? * self.f_e.transpose();
            if let Some(il) = self.inv_lambda {
                m += dilation::d_kirchhoff(self.j_e, il, g)?;
            }
            return self.finish(m);
        }
        self.d_force_matrix_with(g, |aug, z| aug.chat_z(z))
    }

    #[inline]
    fn finish(&self, m: Mat<T, D>) -> Result<Mat<T, D>> {
        let m = m * (-self.volume0);
        if m.is_finite() {
            Ok(m)
        } else {
            Err(Error::Overflow)
        }
    }

    /// As [`Stiffness::d_force_matrix`] with `chat(aug, Z)` in place of `Ĉ:Z` (called only
    /// when `μ > 0` and the material's Hessian is [`Definiteness::Exact`]).
    #[inline]
    pub fn d_force_matrix_with(
        &self,
        g: &Mat<T, D>,
        chat: impl FnOnce(&Augmented<'e, Mat<T, D>, FixedCorotated<T>>, &Mat<T, D>) -> Result<Mat<T, D>>,
    ) -> Result<Mat<T, D>> {
        if !g.is_finite() {
            return Err(Error::NonFinite);
        }
        let mut m = Mat::<T, D>::ZERO;
        if let Some(aug) = &self.aug {
            let df = *g * self.f_e;
            m = chat(aug, &df)? * self.f_e.transpose();
        }
        if let Some(il) = self.inv_lambda {
            m += dilation::d_kirchhoff(self.j_e, il, g)?;
        }
        self.finish(m)
    }

    /// Applies the differential on the particle's stencil: reads `du[r]` (m), writes `df[r]`
    /// (N) for every node `r`, only on success.
    ///
    /// Errors: [`Error::InvalidArgument`] for slices shorter than the stencil; the kernels'.
    #[inline]
    pub fn apply(&self, s: &Stencil<T, D>, du: &[[T; D]], df: &mut [[T; D]]) -> Result<()> {
        let n = s.len();
        if du.len() < n || df.len() < n {
            return Err(Error::InvalidArgument);
        }
        let mut g = Mat::<T, D>::ZERO;
        for (r, u) in du.iter().enumerate().take(n) {
            g += Mat::outer(*u, s.node(r).grad);
        }
        let m = self.d_force_matrix(&g)?;
        for (r, out) in df.iter_mut().enumerate().take(n) {
            *out = m.mul_vec(s.node(r).grad);
        }
        Ok(())
    }
}

/// One-shot force differential of a particle on its collocated stencil (see [`Stiffness`]):
/// builds the energy and the stiffness, then applies them to `du` (m), writing `df` (N).
///
/// Errors: as [`Stiffness::new`] and [`Stiffness::apply`].
#[inline]
pub fn force_differential<T: Real, const D: usize>(
    material: &Material<T>,
    kernel: Kernel,
    h: T,
    p: &Particle<T, D>,
    du: &[[T; D]],
    df: &mut [[T; D]],
) -> Result<()>
where
    Mat<T, D>: Matrix<Scalar = T, Vector = [T; D]> + HessianDim,
    DefaultSvd: SvdMethod<Mat<T, D>>,
{
    let s = Stencil::new(kernel, Grid::Collocated, h, &p.x)?;
    let e = elastic_energy(material, p)?;
    Stiffness::new(&e, material, p)?.apply(&s, du, df)
}

/// The particle pressure `p = −Ψ_λ'(J_E)/J_P` (Pa) with the particle's (hardened) `λ`
/// ([`dilation::pressure`]).
///
/// Errors: invalid material or particle; [`Error::InvalidArgument`] when `1/λ = 0`.
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
