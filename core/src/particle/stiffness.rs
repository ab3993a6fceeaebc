//! The force differential of one particle for an implicit solve, per particle (the batch form
//! through grid views is [`super::transfer::force`], built on [`super::implicit`]).

use super::dilation;
use super::stencil::{Grid, Kernel, Stencil};
use super::update::check_particle;
use super::{Definiteness, Dilation, Material, Particle};
use crate::augmented::Augmented;
use crate::energy::FixedCorotated;
use crate::error::{Error, Result};
use crate::hessian::{HessianDim, HessianEigensystem};
use crate::mat::{Mat, Matrix};
use crate::polar::{DefaultSvd, SvdMethod};
use crate::scalar::Real;

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
/// `δf_i = −V⁰ (Ĉ:δF_E + δP_λ) F_Eᵀ ∇w_i` (N), i.e. `δf = −V⁰ (Ĉ:(Σ_j δv_j ∇w_jᵀ F)) Fᵀ ∇w`
/// for `δu = δv`, with the dilational term [`dilation::d_kirchhoff`] only for
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
    /// (N) for every node `r`, only on success (every written value is finite).
    ///
    /// Errors: [`Error::InvalidArgument`] for slices shorter than the stencil;
    /// [`Error::NonFinite`] for a NaN/inf `du`; [`Error::Overflow`] when `G`, the force
    /// matrix or a node force of finite inputs is not representable; the kernels'.
    #[inline]
    pub fn apply(&self, s: &Stencil<T, D>, du: &[[T; D]], df: &mut [[T; D]]) -> Result<()> {
        let n = s.len();
        if du.len() < n || df.len() < n {
            return Err(Error::InvalidArgument);
        }
        let mut g = Mat::<T, D>::ZERO;
        let mut inputs_finite = true;
        for (r, u) in du.iter().enumerate().take(n) {
            inputs_finite &= u.iter().all(|c| c.is_finite());
            g += Mat::outer(*u, s.node(r).grad);
        }
        if !inputs_finite {
            return Err(Error::NonFinite);
        }
        if !g.is_finite() {
            return Err(Error::Overflow);
        }
        let m = self.d_force_matrix(&g)?;
        // Every stencil has at most 4³ nodes; nothing is written before all are checked.
        let mut buf = [[T::ZERO; D]; 64];
        let mut chk = T::ZERO;
        for (r, out) in buf.iter_mut().enumerate().take(n) {
            *out = m.mul_vec(s.node(r).grad);
            for c in out.iter() {
                // x·0 is 0 for finite x and NaN for NaN/inf.
                chk += *c * T::ZERO;
            }
        }
        if chk != T::ZERO {
            return Err(Error::Overflow);
        }
        df[..n].copy_from_slice(&buf[..n]);
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
