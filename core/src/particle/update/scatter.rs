//! Step 1 of the time step for one particle: its Kirchhoff stress and its P2G contributions
//! (stencil, mass, APIC momentum, stress force, heat), see the parent module.

use super::check_particle;
use crate::augmented::Augmented;
use crate::energy::FixedCorotated;
use crate::error::{Error, Result};
use crate::mat::{Mat, Matrix};
use crate::particle::stencil::{Grid, Kernel, Stencil};
use crate::particle::{apic, dilation};
use crate::particle::{Dilation, Material, Particle};
use crate::polar::{DefaultSvd, SvdMethod};
use crate::scalar::Real;

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
