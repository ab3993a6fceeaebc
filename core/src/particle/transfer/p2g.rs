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
//! The stresses of a chunk of particles are computed on SIMD lanes ([`crate::kernel`]); the
//! node values of a run of nearby particles are summed in a node tile (`transfer/tile.rs`) that is
//! added to the grid once per run.

use super::nodes::{add, node_offsets, nodes, rel_base, restore, table, taint, with_nodes};
use super::tile::{axis0, factors, set_grad, Coef, Tile, MAX_CH, MAX_RUN, TILE_X};
use super::{BatchStatus, Checked, FirstFailure, NodeBox, OutChannel, Particles, Reads};
use crate::error::{Error, Result};
use crate::kernel::batch::{dispatch, BatchReal, LaneOp, ScalarRow, MAX_LANES};
use crate::kernel::chunk::check_bits;
use crate::kernel::{ahat, evaluate, lane_error, Dim, LaneDim};
use crate::lane::lmat::{mul_nt, LMat};
use crate::lane::{Isa, Lane};
use crate::mat::{Mat, Matrix};
use crate::particle::dilation;
use crate::particle::stencil::{Grid, Kernel, Stencil};
use crate::particle::update::check_particle;
use crate::particle::{Dilation, Material, Particle};
use crate::scalar::Real;
use core::mem::MaybeUninit;

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
    let reads = Reads {
        x: true,
        motion: true,
        mass: true,
    };
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
        let reads = Reads {
            x: true,
            motion: true,
            mass: true,
        };
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
        let mut q0 = [T::ZERO; D];
        for r in 0..D {
            let mut c = T::ZERO;
            for b in 0..D {
                c += mch.cols[b][r] * s.fx[b];
            }
            q0[r] = p.mass * p.v[r] - c;
        }
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

    /// Scatter-adds one particle (`K` nodes per axis, `N = K^d`; `oc` from [`node_offsets`]).
    /// The node values of each channel are formed as an array over the nodes, then added;
    /// every old value is kept, and if a new one is not finite the old values are put back
    /// (in reverse order, so that aliased channels are restored too) and the particle fails.
    #[inline(always)]
    unsafe fn scatter<R: Lane<Scalar = T>, const K: usize, const N: usize>(
        &self,
        r: &Ready<'_, T, D>,
        oc: &[[T; N]; D],
    ) -> Result<()> {
        let rel = rel_base(r.s, &self.view.nodes)?;
        let comps = self.comps();
        let act = self.outs[..self.na].iter().zip(&self.kinds[..self.na]);
        let nd = nodes::<T, D, K, N>(r.s);
        let idt = self.args.impulse_dt;
        // The force on the nodes along axis `a`.
        // The node forces along the written axes, once for the momentum and force channels.
        let mut force = [[T::ZERO; N]; D];
        for (a, f) in force.iter_mut().enumerate() {
            if a < comps.0 || a >= comps.1 {
                continue;
            }
            for i in 0..N {
                for b in 0..D {
                    f[i] += r.fm.cols[b][a] * nd.g[b][i];
                }
            }
        }
        let mut old = [[MaybeUninit::<T>::uninit(); N]; MAX_CH];
        let mut ok = true;
        for (j, (ch, &kind)) in act.enumerate() {
            let t = table(ch, &rel);
            let mut val = [T::ZERO; N];
            match kind {
                0 => {
                    for i in 0..N {
                        val[i] = nd.w[i] * r.mass;
                    }
                }
                1..=3 => {
                    let a = kind - 1;
                    let f = &force[a];
                    for i in 0..N {
                        let mut q = r.q0[a];
                        for b in 0..D {
                            q += r.mch.cols[b][a] * oc[b][i];
                        }
                        val[i] = nd.w[i] * q + idt * f[i];
                    }
                }
                4..=6 => val = force[kind - 4],
                k => {
                    for i in 0..N {
                        val[i] = nd.w[i] * r.heat[k - 7];
                    }
                }
            }
            ok &= add::<T, R, D, K, N>(ch.data, &t, ch.stride[0], &val, &mut old[j]);
        }
        if ok {
            return Ok(());
        }
        for (j, ch) in self.outs[..self.na].iter().enumerate().rev() {
            let t = table(ch, &rel);
            restore::<T, D, K, N>(ch.data, &t, ch.stride[0], &old[j]);
        }
        Err(Error::Overflow)
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
    }

    /// Sets the tile lane vectors of a particle's node values per active channel (see
    /// [`super::tile`]), for lane offset `s0` along axis 0, into `out` (the other entries are
    /// left as they are).
    #[inline(always)]
    fn set_coef<R: Lane<Scalar = T>, const K: usize>(
        &self,
        r: &Ready<'_, T, D>,
        s0: usize,
        out: &mut [Coef<R, D>; MAX_CH],
    ) {
        let sp = R::splat;
        let (w, dw) = axis0::<T, R, D, K>(r.s, s0);
        // The axis-0 node offsets o₀ of the lanes (exact small integers).
        let mut lane = [T::ZERO; TILE_X];
        for (l, x) in lane.iter_mut().enumerate() {
            *x = T::from_i32(l as i32 - s0 as i32);
        }
        let o0 = R::load(&lane);
        let idt = self.args.impulse_dt;
        for (c, &kind) in out.iter_mut().zip(&self.kinds[..self.na]) {
            match kind {
                0 => *c = Coef::only(w * sp(r.mass)),
                k @ 1..=3 => {
                    // w (q₀ + (mCh) o) + Δt_f f.
                    let a = k - 1;
                    let q = sp(r.mch.cols[0][a]).mul_add(o0, sp(r.q0[a]));
                    if idt == T::ZERO {
                        c.p = w * q;
                        c.has_b = false;
                    } else {
                        set_grad(c, w, dw, &r.fm, a, idt);
                        c.p = w.mul_add(q, c.p);
                    }
                    for b in 1..D {
                        c.e[b] = w * sp(r.mch.cols[b][a]);
                    }
                    c.has_e = true;
                }
                k @ 4..=6 => set_grad(c, w, dw, &r.fm, k - 4, T::ONE),
                k => *c = Coef::only(w * sp(r.heat[k - 7])),
            }
        }
    }

    /// Adds a ready particle `i` to the tile run, after adding the run to the grid if the
    /// particle does not fit in its tile or the run is full.
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    unsafe fn tile_add<R: Lane<Scalar = T>, const K: usize, const N: usize>(
        &mut self,
        i: usize,
        r: &Ready<'_, T, D>,
        tau_dev: Mat<T, D>,
        tile: &mut Tile<R, D>,
        run: &mut Run<T, D>,
        oc: &[[T; N]; D],
        coef: &mut [Coef<R, D>; MAX_CH],
    ) -> Result<()> {
        let rel = rel_base(r.s, &self.view.nodes)?;
        if run.n == MAX_RUN {
            self.flush::<R, K, N>(tile, run, oc);
        }
        let s = loop {
            if let Some(s) = tile.place::<K>(&rel, &r.s.fx) {
                break s;
            }
            // An empty tile takes any stencil.
            self.flush::<R, K, N>(tile, run, oc);
        };
        self.set_coef::<R, K>(r, s[0], coef);
        tile.add::<K, N>(&s, &factors::<T, D, K, N>(r.s), &coef[..self.na]);
        run.idx[run.n] = i;
        run.tau[run.n] = tau_dev;
        run.n += 1;
        Ok(())
    }

    /// Adds the tile to the grid and empties it; if a new node value is not finite, the grid
    /// is left as it was and the run's particles are added one by one ([`Self::scatter`]),
    /// which refuses the ones that overflow.
    #[inline(always)]
    unsafe fn flush<R: Lane<Scalar = T>, const K: usize, const N: usize>(
        &mut self,
        tile: &mut Tile<R, D>,
        run: &mut Run<T, D>,
        oc: &[[T; N]; D],
    ) {
        let outs = &self.outs[..self.na];
        if !tile.add_to_grid::<K>(outs) {
            for m in 0..run.n {
                // `pre` and `ready` succeeded for this particle before, with these inputs.
                let r = self.pre(run.idx[m]).and_then(|pre| {
                    let s = self.stencil(&pre.p.x)?;
                    let r = self.ready(&pre, run.tau[m], &s)?;
                    self.scatter::<R, K, N>(&r, oc)
                });
                self.first.note(run.idx[m], r);
            }
        }
        run.n = 0;
    }

    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    unsafe fn finish<R: Lane<Scalar = T>, const K: usize, const N: usize>(
        &mut self,
        i: usize,
        pre: &Pre<T, D>,
        tau_dev: Mat<T, D>,
        lane_stencil: Option<&Stencil<T, D>>,
        tile: &mut Tile<R, D>,
        run: &mut Run<T, D>,
        oc: &[[T; N]; D],
        coef: &mut [Coef<R, D>; MAX_CH],
    ) {
        // The stencil from the lanes, or the particle's own (which reports its error).
        let own;
        let s = match lane_stencil {
            Some(s) => s,
            None => match self.stencil(&pre.p.x) {
                Ok(s) => {
                    own = s;
                    &own
                }
                Err(e) => return self.first.note(i, Err(e)),
            },
        };
        let r = match self.ready(pre, tau_dev, s) {
            Err(e) => Err(e),
            Ok(r) => self.tile_add::<R, K, N>(i, &r, tau_dev, tile, run, oc, coef),
        };
        self.first.note(i, r);
    }
}

impl<T: BatchReal, const D: usize> LaneOp<T> for P2gOp<'_, T, D>
where
    Dim<D>: LaneDim<D>,
    Mat<T, D>: Matrix<Scalar = T, Vector = [T; D]>,
{
    #[inline(always)]
    fn run<V: Lane<Scalar = T>>(&mut self) -> BatchStatus {
        // `dispatch` calls `run_rows`; this is its scalar-row form.
        self.run_rows::<V, ScalarRow<T>>()
    }

    #[inline(always)]
    fn run_rows<V: Lane<Scalar = T>, R: Lane<Scalar = T>>(&mut self) -> BatchStatus {
        with_nodes!(self.args.kernel, D, |K, N| self.run_nodes::<V, R, K, N>())
    }
}

impl<T: BatchReal, const D: usize> P2gOp<'_, T, D>
where
    Dim<D>: LaneDim<D>,
    Mat<T, D>: Matrix<Scalar = T, Vector = [T; D]>,
{
    /// The particle loop for a kernel with `K` nodes per axis (`N = K^d`).
    #[inline(always)]
    fn run_nodes<V: Lane<Scalar = T>, R: Lane<Scalar = T>, const K: usize, const N: usize>(
        &mut self,
    ) -> BatchStatus {
        debug_assert_eq!(R::LANES, TILE_X);
        let oc = node_offsets::<T, D, K, N>();
        let mut tile = Tile::<R, D>::new();
        // The tile lane vectors of the particle being added (filled per particle for the
        // active channels; one buffer, so that no per-particle array is initialised).
        let mut coef = [Coef::only(R::splat(T::ZERO)); MAX_CH];
        let mut run = Run {
            n: 0,
            idx: [0; MAX_RUN],
            tau: [Mat::ZERO; MAX_RUN],
        };
        let lanes = V::LANES;
        // The chunk's scalar passes, built in place (see `pre_into`); `live[l]` when lane
        // `l`'s succeeded.
        let mut pres = [Pre::<T, D>::blank(); MAX_LANES];
        let mut live = [false; MAX_LANES];
        // The chunk's positions and stencils (on lanes, see `Stencil::new_lanes`).
        let (kernel, grid, h) = (self.args.kernel, self.args.grid, self.args.h);
        let mut xs = [[T::ZERO; D]; MAX_LANES];
        let mut stencils = [Stencil::blank(kernel, h); MAX_LANES];
        let mut start = 0;
        while start < self.n {
            let len = lanes.min(self.n - start);
            let mut fbuf = [[T::ZERO; MAX_LANES]; 9];
            let mut mubuf = [T::ZERO; MAX_LANES];
            let mut any_mu = false;
            for l in 0..len {
                // SAFETY: `p2g`'s contract: the arrays hold `n` particles.
                live[l] = false;
                match unsafe { self.pre_into(start + l, &mut pres[l]) } {
                    Ok(()) => {
                        let pr = &pres[l];
                        for j in 0..D {
                            for r in 0..D {
                                fbuf[r + D * j][l] = pr.p.f_e.cols[j][r];
                            }
                        }
                        mubuf[l] = pr.mu;
                        any_mu |= pr.mu > T::ZERO;
                        live[l] = true;
                    }
                    Err(e) => self.first.note(start + l, Err(e)),
                }
            }
            for l in len..lanes {
                for d in 0..D {
                    fbuf[d * (D + 1)][l] = T::ONE;
                }
            }
            for (x, pr) in xs.iter_mut().zip(&pres).take(len) {
                *x = pr.p.x;
            }
            let done = Stencil::new_lanes::<V>(kernel, grid, h, &xs[..lanes], &mut stencils);
            let mut tbuf = [[T::ZERO; MAX_LANES]; 9];
            let mut lane_err: [Option<Error>; MAX_LANES] = [None; MAX_LANES];
            if any_mu {
                // The deviatoric Kirchhoff stress Â F_Eᵀ of every lane (zero where μ = 0).
                let mut f: LMat<V, D> = [[V::splat(T::ZERO); D]; D];
                for j in 0..D {
                    for r in 0..D {
                        f[j][r] = V::load(&fbuf[r + D * j][..lanes]);
                    }
                }
                let (co, ck) = evaluate(V::load(&mubuf[..lanes]), &f);
                let tau = mul_nt(&ahat(&co), &f);
                for j in 0..D {
                    for r in 0..D {
                        tau[j][r].store(&mut tbuf[r + D * j][..lanes]);
                    }
                }
                let bits = check_bits::<V>(&ck);
                for (l, e) in lane_err.iter_mut().enumerate().take(len) {
                    // Lanes with μ = 0 ran no decomposition in the scalar path either.
                    if mubuf[l] > T::ZERO {
                        *e = lane_error(&bits, l);
                    }
                }
            }
            for l in 0..len {
                if live[l] {
                    if let Some(e) = lane_err[l] {
                        self.first.note(start + l, Err(e));
                        continue;
                    }
                    let mut tau = Mat::<T, D>::ZERO;
                    for j in 0..D {
                        for r in 0..D {
                            tau.cols[j][r] = tbuf[r + D * j][l];
                        }
                    }
                    // SAFETY: `p2g`'s contract: valid channels over the box.
                    unsafe {
                        self.finish::<R, K, N>(
                            start + l,
                            &pres[l],
                            tau,
                            (done >> l & 1 == 1).then_some(&stencils[l]),
                            &mut tile,
                            &mut run,
                            &oc,
                            &mut coef,
                        )
                    };
                }
            }
            start += len;
        }
        // SAFETY: as above.
        unsafe { self.flush::<R, K, N>(&mut tile, &mut run, &oc) };
        self.first.status()
    }
}
