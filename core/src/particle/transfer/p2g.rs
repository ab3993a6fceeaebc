//! P2G into a grid view: node masses, APIC momenta, stress forces and heat, scatter-added.
//!
//! Per particle `p` and stencil node `i` (Jiang et al. 2015 for APIC, Stomakhin et al. 2013
//! eq. 6 and 2014 §5–§6 for the forces and heat; formulas as in [`crate::particle::update`]):
//! - mass `w m`; momentum `w m (v + C (x_i − x_p)) + Δt_f f_i` (`Δt_f` = [`P2gArgs::impulse_dt`],
//!   0 for the plain momentum; `Δt` gives the symplectic-Euler form `m v* + Δt f`);
//! - force `f_i = −V⁰ τ ∇w_i`, `τ = Â F_Eᵀ + λ(J_E − 1)J_E I` (the dilational term only when
//!   the dilation is explicit; `Â` only when `μ > 0`, so a liquid runs no decomposition);
//! - heat capacity `w m c`, thermal energy `w m c T`, conductivity mass `w m κ` (heat on).
//!
//! The stresses of a chunk of particles are computed on SIMD lanes ([`crate::kernel`]), and so
//! are the reads, checks and per-particle factors of each whole group of eight
//! (`p2g/lanes.rs`); the node values of a run of nearby particles are summed in a node tile
//! (`transfer/tile.rs`) that is added to the grid once per run (the loops: `p2g/run.rs`).

use super::nodes::taint;
use super::tile::{MAX_CH, MAX_RUN};
use super::{BatchStatus, Checked, FirstFailure, NodeBox, OutChannel, Particles, Reads};
use crate::error::{Error, Result};
use crate::kernel::batch::{dispatch, BatchReal};
use crate::kernel::{Dim, LaneDim};
use crate::lane::Isa;
use crate::mat::{Mat, Matrix};
use crate::particle::dilation;
use crate::particle::stencil::{Grid, Kernel, Stencil};
use crate::particle::update::check_particle;
use crate::particle::{Dilation, Material, Particle};
use crate::scalar::Real;

/// Where P2G writes: a node box and the channels to scatter-add into (absent channels are
/// skipped). On a MAC face grid `a` only `mass`, `momentum[a]` and `force[a]` are written.
#[derive(Clone, Copy, Debug)]
pub struct P2gView<T, const D: usize> {
    /// The nodes the channels cover.
    pub nodes: NodeBox<D>,
    /// Node mass (kg).
    pub mass: OutChannel<T, D>,
    /// Node momentum per axis (kg·m/s), plus `impulse_dt · force`.
    pub momentum: [OutChannel<T, D>; D],
    /// Node stress force per axis (N).
    pub force: [OutChannel<T, D>; D],
    /// Node heat capacity `Σ w m c` (J/K); heat on, collocated grid.
    pub heat_capacity: OutChannel<T, D>,
    /// Node thermal energy `Σ w m c T` (J); heat on, collocated grid.
    pub thermal_energy: OutChannel<T, D>,
    /// Node conductivity mass `Σ w m κ` (kg·W/(m·K)); heat on, collocated grid.
    pub conductivity: OutChannel<T, D>,
}

/// The parameters of a P2G call.
#[derive(Clone, Copy, Debug)]
pub struct P2gArgs<T> {
    /// Interpolation kernel.
    pub kernel: Kernel,
    /// Collocated grid or one MAC face grid.
    pub grid: Grid,
    /// Grid spacing `h` (m).
    pub h: T,
    /// `Δt_f ≥ 0` (s): the momentum channel also receives `Δt_f f_i`.
    pub impulse_dt: T,
}

/// The particles of the current tile run (index and deviatoric stress), for the one-by-one
/// path: it forms their [`Ready`] again (a copy of each would cost more than the rare redo).
struct Run<T, const D: usize> {
    n: usize,
    idx: [usize; MAX_RUN],
    tau: [Mat<T, D>; MAX_RUN],
}

/// A particle ready for its node loop.
#[derive(Clone, Copy)]
struct Ready<'s, T, const D: usize> {
    s: &'s Stencil<T, D>,
    /// `m v − m C h fx`: the momentum density at offset 0.
    q0: [T; D],
    /// `m C h`: the momentum density grows by column `b` per unit offset along `b`.
    mch: Mat<T, D>,
    /// `−V⁰ τ` (N·m).
    fm: Mat<T, D>,
    mass: T,
    heat: [T; 3],
}

/// P2G of `n` particles into `view` (see the module docs). Reads `x, v, affine, f_e, f_p,
/// mass, volume0`, `temperature` with heat on, `phase` (if non-null).
///
/// Errors per particle as [`crate::particle::update::p2g`], plus [`Error::OutsideGrid`] and
/// [`Error::Overflow`] for a node value that adding the particle would make non-finite (node
/// sums per run of nearby particles, see `transfer/tile.rs`). A whole-call error (material
/// flags, a null array the material needs, `impulse_dt` not finite or negative, a face axis
/// `≥ d`) is reported for particle 0 and nothing is written.
///
/// # Safety
/// The arrays of `ps` that the material needs hold `n` particles; each non-null channel is
/// valid for reading and writing at every node of `view.nodes`; no channel aliases a particle
/// array.
pub unsafe fn p2g<T: BatchReal, const D: usize>(
    isa: Isa,
    material: &Material<T>,
    args: &P2gArgs<T>,
    n: usize,
    ps: &Particles<T>,
    view: &P2gView<T, D>,
) -> BatchStatus
where
    Dim<D>: LaneDim<D>,
    Mat<T, D>: Matrix<Scalar = T, Vector = [T; D]>,
{
    let bad = |e| BatchStatus {
        first_failed: 0,
        error: Some(e),
    };
    if !args.impulse_dt.is_finite() {
        return bad(Error::NonFinite);
    }
    if args.impulse_dt < T::ZERO || matches!(args.grid, Grid::Face(a) if a >= D) {
        return bad(Error::InvalidArgument);
    }
    let reads = Reads::ALL;
    if n > 0 && !ps.has(reads, material) {
        return bad(Error::InvalidArgument);
    }
    let mut op = P2gOp::<T, D> {
        material,
        checked: Checked::new(material),
        args,
        n,
        ps,
        view,
        first: FirstFailure::new(n),
        outs: [OutChannel::none(); MAX_CH],
        kinds: [0; MAX_CH],
        na: 0,
        fixed: None,
    };
    op.active();
    dispatch::<T, _>(isa, &mut op);
    op.first.status()
}

struct P2gOp<'a, T, const D: usize> {
    material: &'a Material<T>,
    checked: Checked,
    args: &'a P2gArgs<T>,
    n: usize,
    ps: &'a Particles<T>,
    view: &'a P2gView<T, D>,
    first: FirstFailure,
    /// The output channels written, in the order they are added, and their kinds (0 mass,
    /// `1 + a` momentum, `4 + a` force, 7 heat capacity, 8 thermal energy, 9 conductivity).
    outs: [OutChannel<T, D>; MAX_CH],
    kinds: [usize; MAX_CH],
    na: usize,
    /// The channels are mass, then momentum along every axis (kinds `0..=D`), then
    /// (`Some(true)`) the three heat channels (kinds `7..=9`) and nothing else: a channel set
    /// that the tile add knows at compile time. `None`: another set.
    fixed: Option<bool>,
}

/// The momentum density at a stencil's offset 0, `q₀ = m v − (m C h) fx` (the particle's
/// `m v`, `m C h` and stencil `fx`), summed from zero in index order: the one formula of the
/// scalar pass and of the pass on lanes (`p2g/lanes.rs`), so that both give the same bits.
#[inline(always)]
fn momentum0<T: Real, const D: usize>(mv: &[T; D], mch: &Mat<T, D>, fx: &[T; D]) -> [T; D] {
    let mut q0 = [T::ZERO; D];
    for r in 0..D {
        let mut c = T::ZERO;
        for b in 0..D {
            c += mch.cols[b][r] * fx[b];
        }
        q0[r] = mv[r] - c;
    }
    q0
}

/// What the scalar pass knows about a particle before its stress.
#[derive(Clone, Copy)]
struct Pre<T, const D: usize> {
    p: Particle<T, D>,
    j_e: T,
    inv_lambda: T,
    mu: T,
}

impl<T: Real, const D: usize> Pre<T, D> {
    /// A placeholder to be overwritten by [`P2gOp::pre_into`].
    #[inline(always)]
    fn blank() -> Self {
        Self {
            p: Particle::at_rest([T::ZERO; D], T::ONE, T::ONE),
            j_e: T::ONE,
            inv_lambda: T::ZERO,
            mu: T::ZERO,
        }
    }
}

impl<T: BatchReal, const D: usize> P2gOp<'_, T, D>
where
    Mat<T, D>: Matrix<Scalar = T, Vector = [T; D]>,
{
    /// The scalar pass of particle `i`, into `out` (in part on error): built in place, for
    /// the reason given at [`Particles::read_into`].
    #[inline(always)]
    unsafe fn pre_into(&self, i: usize, out: &mut Pre<T, D>) -> Result<()> {
        let reads = Reads::ALL;
        self.ps
            .read_into::<D>(i, reads, self.material, &mut out.p)?;
        let p = &out.p;
        self.checked.for_phase(p.phase)?;
        let (j_e, j_p) = check_particle(p)?;
        if self.material.heat.is_some() && !p.temperature.is_finite() {
            return Err(Error::NonFinite);
        }
        let m = self.material.moduli(p.phase, j_p)?;
        out.j_e = j_e;
        out.inv_lambda = m.inv_lambda;
        out.mu = m.mu;
        Ok(())
    }

    /// [`Self::pre_into`], returned.
    #[inline(always)]
    unsafe fn pre(&self, i: usize) -> Result<Pre<T, D>> {
        let mut out = Pre::blank();
        self.pre_into(i, &mut out)?;
        Ok(out)
    }

    /// The stencil of a particle at `x` on this call's grid.
    #[inline(always)]
    fn stencil(&self, x: &[T; D]) -> Result<Stencil<T, D>> {
        let a = self.args;
        Stencil::new(a.kernel, a.grid, a.h, x)
    }

    /// The node loop inputs of a particle with deviatoric Kirchhoff stress `tau_dev` and
    /// stencil `s` ([`Self::stencil`] of its position).
    #[inline(always)]
    fn ready<'s>(
        &self,
        pre: &Pre<T, D>,
        tau_dev: Mat<T, D>,
        s: &'s Stencil<T, D>,
    ) -> Result<Ready<'s, T, D>> {
        let p = &pre.p;
        let a = self.args;
        let mut tau = tau_dev;
        if self.material.dilation == Dilation::Explicit {
            let k = dilation::kirchhoff(pre.j_e, pre.inv_lambda)?;
            for d in 0..D {
                tau.cols[d][d] += k;
            }
        }
        let fm = tau * (-p.volume0);
        let mch = p.affine * (p.mass * a.h);
        let mut mv = [T::ZERO; D];
        for r in 0..D {
            mv[r] = p.mass * p.v[r];
        }
        let q0 = momentum0(&mv, &mch, &s.fx);
        let heat = match &self.material.heat {
            Some(_) => {
                let pp = self.material.params(p.phase);
                let mc = p.mass * pp.heat_capacity;
                [mc, mc * p.temperature, p.mass * pp.conductivity]
            }
            None => [T::ZERO; 3],
        };
        let mut chk = true;
        for x in q0.iter().chain(heat.iter()) {
            taint(&mut chk, *x);
        }
        if !(chk && fm.is_finite() && mch.is_finite()) {
            return Err(Error::Overflow);
        }
        Ok(Ready {
            s,
            q0,
            mch,
            fm,
            mass: p.mass,
            heat,
        })
    }

    /// The velocity components a call writes: all on the collocated grid, `a` on face grid `a`.
    #[inline(always)]
    fn comps(&self) -> (usize, usize) {
        match self.args.grid {
            Grid::Collocated => (0, D),
            Grid::Face(a) => (a, a + 1),
        }
    }

    /// The output channels a call writes, in the order they are added.
    fn active(&mut self) {
        let v = self.view;
        let comps = self.comps();
        let heat_on = self.material.heat.is_some() && self.args.grid == Grid::Collocated;
        let mut add = |kind: usize, ch: &OutChannel<T, D>| {
            if !ch.data.is_null() {
                self.outs[self.na] = *ch;
                self.kinds[self.na] = kind;
                self.na += 1;
            }
        };
        add(0, &v.mass);
        for a in comps.0..comps.1 {
            add(1 + a, &v.momentum[a]);
            add(4 + a, &v.force[a]);
        }
        if heat_on {
            add(7, &v.heat_capacity);
            add(8, &v.thermal_energy);
            add(9, &v.conductivity);
        }
        let mm = self.na > D && (0..=D).all(|k| self.kinds[k] == k);
        self.fixed = match self.na - D - 1 {
            0 if mm => Some(false),
            3 if mm && (0..3).all(|h| self.kinds[D + 1 + h] == 7 + h) => Some(true),
            _ => None,
        };
    }
}

mod lanes;
mod run;
