//! P2G's node loops: the chunked particle loop (stresses, stencils and the per-particle pass on
//! SIMD lanes, `p2g/lanes.rs`), the node tile of a run of nearby particles (`transfer/tile.rs`)
//! and its flush into the grid, and the one-particle scatter that a run whose sums overflow
//! falls back to.

use super::lanes::{fm_lanes, ChunkBufs};
use super::{P2gOp, Pre, Ready, Run};
use crate::error::{Error, Result};
use crate::kernel::batch::{BatchReal, LaneOp, ScalarRow, WithChunks};
use crate::kernel::chunk::{check_bits, kernel_lane_error};
use crate::kernel::{ahat, evaluate, flagged, Dim, LaneDim};
use crate::lane::lmat::{mul_nt, LMat};
use crate::lane::{Lane, Pair, X2};
use crate::mat::{Mat, Matrix};
use crate::particle::stencil::Stencil;
use crate::particle::transfer::deformation_lanes::lanes_ok;
use crate::particle::transfer::nodes::{
    add, node_offsets, nodes, rel_base, restore, table, with_nodes,
};
use crate::particle::transfer::tile::{axis0, set_grad, Coef, Tile, MAX_CH, MAX_RUN, TILE_X};
use crate::particle::transfer::BatchStatus;
use crate::particle::{Dilation, Kernel};
use core::marker::PhantomData;
use core::mem::MaybeUninit;

/// The particle loop's channel sets (its `SET` parameter): mass and momentum along every axis
/// (kinds `0..=D`); those and the three heat channels; any other set (the per-channel form).
const MASS_MOMENTUM: u8 = 1;
const WITH_HEAT: u8 = 2;
const ANY_CHANNELS: u8 = 0;

/// Where a particle's pass is: its scalar pass, or its lane of the chunk's buffers (when that
/// ran on lanes); and its position.
type Source<'b, T, const D: usize, const L: usize> = (
    &'b Pre<T, D>,
    Option<(&'b ChunkBufs<T, L>, usize)>,
    &'b [T; D],
);

impl<T: BatchReal, const D: usize> P2gOp<'_, T, D>
where
    Mat<T, D>: Matrix<Scalar = T, Vector = [T; D]>,
{
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

    /// Sets the tile lane vectors of a particle's node values per active channel (see
    /// [`crate::particle::transfer::tile`]), for lane offset `s0` along axis 0, into `out` (the
    /// other entries are left as they are).
    #[inline(always)]
    fn set_coef<R: Lane<Scalar = T>, const K: usize>(
        &self,
        r: &Ready<'_, T, D>,
        s0: usize,
        out: &mut [Coef<R, D>; MAX_CH],
    ) {
        // With the axis-0 node offsets o₀ of the lanes.
        let lanes = axis0::<T, R, D, K>(r.s, s0);
        let impulse = self.args.impulse_dt != T::ZERO;
        for (c, &kind) in out.iter_mut().zip(&self.kinds[..self.na]) {
            self.channel_coef(r, lanes, kind, (impulse, false), c);
        }
    }

    /// [`Self::set_coef`] for the channel set mass, then momentum along every axis (the
    /// usual collocated P2G), then with `heat` the three heat channels, known at compile time
    /// (and whether `Δt_f ≠ 0`, `B`): the lane vectors stay in registers.
    #[inline(always)]
    fn fixed_coef<R: Lane<Scalar = T>, const K: usize, const B: bool>(
        &self,
        r: &Ready<'_, T, D>,
        s0: usize,
        heat: bool,
        iso: bool,
    ) -> ([Coef<R, D>; 4], [Coef<R, D>; 3]) {
        let lanes = axis0::<T, R, D, K>(r.s, s0);
        let z = Coef::only(R::splat(T::ZERO));
        let (mut mm, mut hc) = ([z; 4], [z; 3]);
        for (kind, c) in mm.iter_mut().enumerate().take(D + 1) {
            self.channel_coef(r, lanes, kind, (B, iso), c);
        }
        if heat {
            for (h, c) in hc.iter_mut().enumerate() {
                self.channel_coef(r, lanes, 7 + h, (B, false), c);
            }
        }
        (mm, hc)
    }

    /// The lane vectors of channel `kind`'s node values (0 mass, `1 + a` momentum, `4 + a`
    /// force, `7..` heat) from the axis-0 lanes `(w, dw, o₀)` of [`axis0`], into `c` (fields
    /// that the channel does not use are left as they are); `impulse`: `Δt_f ≠ 0`; `iso`: the
    /// force is isotropic, `fm = s I` (see [`Tile::add_fixed`]), so the momentum along axis `a`
    /// gets only the terms of `fm`'s diagonal (its other `B_b` stay zero).
    #[inline(always)]
    fn channel_coef<R: Lane<Scalar = T>>(
        &self,
        r: &Ready<'_, T, D>,
        (w, dw, o0): (R, R, R),
        kind: usize,
        (impulse, iso): (bool, bool),
        c: &mut Coef<R, D>,
    ) {
        let sp = R::splat;
        let idt = self.args.impulse_dt;
        match kind {
            0 => *c = Coef::only(w * sp(r.mass)),
            k @ 1..=3 => {
                // w (q₀ + (mCh) o) + Δt_f f.
                let a = k - 1;
                let q = sp(r.mch.cols[0][a]).mul_add(o0, sp(r.q0[a]));
                if !impulse {
                    c.p = w * q;
                    c.has_b = false;
                } else if iso {
                    if a == 0 {
                        c.p = w.mul_add(q, dw * sp(idt * r.fm.cols[0][0]));
                    } else {
                        c.p = w * q;
                        c.b[a] = w * sp(idt * r.fm.cols[a][a]);
                    }
                    c.has_b = true;
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

    /// Adds a ready particle `i` to the tile run, after adding the run to the grid if the
    /// particle does not fit in its tile or the run is full; `iso` when its force is isotropic
    /// (no shear stress: `tau_dev = 0`).
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    unsafe fn tile_add<
        R: Lane<Scalar = T>,
        Q: Pair<R>,
        const K: usize,
        const N: usize,
        const SET: u8,
    >(
        &mut self,
        i: usize,
        r: &Ready<'_, T, D>,
        (tau_dev, iso): (Mat<T, D>, bool),
        tile: &mut Tile<R, Q, D>,
        run: &mut Run<T, D>,
        oc: &[[T; N]; D],
        coef: &mut [Coef<R, D>; MAX_CH],
    ) -> Result<()> {
        let rel = rel_base(r.s, &self.view.nodes)?;
        if run.n == MAX_RUN {
            self.flush::<R, Q, K, N>(tile, run, oc);
        }
        let s = loop {
            if let Some(s) = tile.place::<K>(&rel, &r.s.fx) {
                break s;
            }
            // An empty tile takes any stencil.
            self.flush::<R, Q, K, N>(tile, run, oc);
        };
        let idt = self.args.impulse_dt;
        if SET == ANY_CHANNELS {
            self.set_coef::<R, K>(r, s[0], coef);
            tile.add::<K>(&s, r.s, &coef[..self.na]);
        } else {
            // A constant in each loop (`SET`), so the heat terms fold away or stay.
            let heat = SET == WITH_HEAT;
            if idt == T::ZERO {
                let c = self.fixed_coef::<R, K, false>(r, s[0], heat, false);
                tile.add_fixed::<K, false>(&s, r.s, &c, heat, false);
            } else if iso {
                let c = self.fixed_coef::<R, K, true>(r, s[0], heat, true);
                tile.add_fixed::<K, true>(&s, r.s, &c, heat, true);
            } else {
                let c = self.fixed_coef::<R, K, true>(r, s[0], heat, false);
                tile.add_fixed::<K, true>(&s, r.s, &c, heat, false);
            }
        }
        run.idx[run.n] = i;
        run.tau[run.n] = tau_dev;
        run.n += 1;
        Ok(())
    }

    /// Adds the tile to the grid and empties it; if a new node value is not finite, the grid
    /// is left as it was and the run's particles are added one by one ([`Self::scatter`]),
    /// which refuses the ones that overflow.
    #[inline(always)]
    unsafe fn flush<R: Lane<Scalar = T>, Q: Pair<R>, const K: usize, const N: usize>(
        &mut self,
        tile: &mut Tile<R, Q, D>,
        run: &mut Run<T, D>,
        oc: &[[T; N]; D],
    ) {
        let outs = &self.outs[..self.na];
        if !tile.add_to_grid::<K>(outs) {
            for m in 0..run.n {
                let r = self.rescatter::<R, K, N>(run.idx[m], run.tau[m], oc);
                self.first.note(run.idx[m], r);
            }
        }
        run.n = 0;
    }

    /// Particle `i` of a flushed run (with its `τ` deviator) scatter-added on its own.
    /// `pre` and `ready` succeeded for this particle before, with these inputs. (A method, not
    /// a closure: a closure is not compiled with the caller's target features.)
    #[inline(always)]
    unsafe fn rescatter<R: Lane<Scalar = T>, const K: usize, const N: usize>(
        &self,
        i: usize,
        tau_dev: Mat<T, D>,
        oc: &[[T; N]; D],
    ) -> Result<()> {
        let pre = self.pre(i)?;
        let s = self.stencil(&pre.p.x)?;
        let r = self.ready(&pre, tau_dev, &s)?;
        self.scatter::<R, K, N>(&r, oc)
    }

    /// Adds particle `i` with deviatoric stress `tau_dev` (and `iso` when that is 0 without
    /// a shear modulus) to the tile run: its scalar pass `pre`, or its lane of the chunk's
    /// `ChunkBufs` when its pass ran on lanes; `x` its position; `lane_stencil` its stencil
    /// if the lanes made it.
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    unsafe fn finish<
        R: Lane<Scalar = T>,
        Q: Pair<R>,
        const K: usize,
        const N: usize,
        const SET: u8,
        const L: usize,
    >(
        &mut self,
        i: usize,
        (pre, from_lanes, x): Source<'_, T, D, L>,
        tau @ (tau_dev, _): (Mat<T, D>, bool),
        lane_stencil: Option<&Stencil<T, D>>,
        (tile, run): (&mut Tile<R, Q, D>, &mut Run<T, D>),
        oc: &[[T; N]; D],
        coef: &mut [Coef<R, D>; MAX_CH],
    ) {
        // The stencil from the lanes, or the particle's own (which reports its error).
        let own;
        let s = match lane_stencil {
            Some(s) => s,
            None => match self.stencil(x) {
                Ok(s) => {
                    own = s;
                    &own
                }
                Err(e) => return self.first.note(i, Err(e)),
            },
        };
        let ready = match from_lanes {
            Some((b, l)) => self.ready_lane(b, l, s),
            None => self.ready(pre, tau_dev, s),
        };
        let r = match ready {
            Err(e) => Err(e),
            Ok(r) => self.tile_add::<R, Q, K, N, SET>(i, &r, tau, tile, run, oc, coef),
        };
        self.first.note(i, r);
    }
}

impl<T: BatchReal, const D: usize> LaneOp<T> for P2gOp<'_, T, D>
where
    Dim<D>: LaneDim<D>,
    Mat<T, D>: Matrix<Scalar = T, Vector = [T; D]>,
{
    const AVX512_VL: bool = true;
    const JOINS_ROWS: bool = true;

    #[inline(always)]
    fn run<V: Lane<Scalar = T>>(&mut self) -> BatchStatus {
        // `dispatch` calls `run_rows`; this is its scalar-row form.
        self.run_rows::<V, ScalarRow<T>>()
    }

    #[inline(always)]
    fn run_rows<V: Lane<Scalar = T>, R: Lane<Scalar = T>>(&mut self) -> BatchStatus {
        // In f32 chunks of `V::Wide` (the decomposition's Jacobi rotations are latency-bound,
        // and four independent vectors fill the FMA pipes better than two); see `with_chunks`.
        self.run_pairs::<V, R, X2<R>>()
    }

    #[inline(always)]
    fn run_pairs<V: Lane<Scalar = T>, R: Lane<Scalar = T>, Q: Pair<R>>(&mut self) -> BatchStatus {
        T::with_chunks::<V, _>(Chunks::<'_, '_, T, D, R, Q>(self, PhantomData))
    }

    const NARROWS_CHUNKS: bool = true;

    #[inline(always)]
    fn run_narrow<V: Lane<Scalar = T>, R: Lane<Scalar = T>, Q: Pair<R>>(&mut self) -> BatchStatus {
        T::with_narrow_chunks::<V, _>(Chunks::<'_, '_, T, D, R, Q>(self, PhantomData))
    }
}

/// [`P2gOp`]'s particle loop with rows `R`, on the chunks [`BatchReal::with_chunks`] picks.
struct Chunks<'o, 'a, T, const D: usize, R, Q>(&'o mut P2gOp<'a, T, D>, PhantomData<(R, Q)>);

impl<T: BatchReal, const D: usize, R: Lane<Scalar = T>, Q: Pair<R>> WithChunks<T>
    for Chunks<'_, '_, T, D, R, Q>
where
    Dim<D>: LaneDim<D>,
    Mat<T, D>: Matrix<Scalar = T, Vector = [T; D]>,
{
    type Out = BatchStatus;

    #[inline(always)]
    fn run<V: Lane<Scalar = T>, const L: usize>(self) -> BatchStatus {
        let op = self.0;
        // The usual channel sets get particle loops of their own for the quadratic kernel
        // (the channel terms known at compile time); other sets, and the cubic kernel, run
        // the per-channel form. Chosen once per call.
        match (op.args.kernel, op.fixed) {
            (Kernel::Quadratic, Some(heat)) if D == 2 => op.run_fixed::<V, R, Q, 3, 9, L>(heat),
            (Kernel::Quadratic, Some(heat)) => op.run_fixed::<V, R, Q, 3, 27, L>(heat),
            _ => with_nodes!(op.args.kernel, D, |K, N| {
                op.run_nodes::<V, R, Q, K, N, ANY_CHANNELS, L>()
            }),
        }
    }
}

impl<T: BatchReal, const D: usize> P2gOp<'_, T, D>
where
    Dim<D>: LaneDim<D>,
    Mat<T, D>: Matrix<Scalar = T, Vector = [T; D]>,
{
    /// The particle loop for a fixed channel set: mass and momentum, then with `heat` the
    /// heat channels.
    #[inline(always)]
    fn run_fixed<
        V: Lane<Scalar = T>,
        R: Lane<Scalar = T>,
        Q: Pair<R>,
        const K: usize,
        const N: usize,
        const L: usize,
    >(
        &mut self,
        heat: bool,
    ) -> BatchStatus {
        if heat {
            self.run_nodes::<V, R, Q, K, N, WITH_HEAT, L>()
        } else {
            self.run_nodes::<V, R, Q, K, N, MASS_MOMENTUM, L>()
        }
    }

    /// The particle loop for a kernel with `K` nodes per axis (`N = K^d`), on chunks of `V`
    /// (at most `L` lanes).
    #[inline(always)]
    fn run_nodes<
        V: Lane<Scalar = T>,
        R: Lane<Scalar = T>,
        Q: Pair<R>,
        const K: usize,
        const N: usize,
        const SET: u8,
        const L: usize,
    >(
        &mut self,
    ) -> BatchStatus {
        debug_assert_eq!(R::LANES, TILE_X);
        debug_assert!(V::LANES <= L);
        let oc = node_offsets::<T, D, K, N>();
        let mut tile = Tile::<R, Q, D>::new();
        // The tile lane vectors of the particle being added (filled per particle for the
        // active channels; one buffer, so that no per-particle array is initialised).
        let mut coef = [Coef::only(R::splat(T::ZERO)); MAX_CH];
        let mut run = Run {
            n: 0,
            idx: [0; MAX_RUN],
            tau: [Mat::ZERO; MAX_RUN],
        };
        let lanes = V::LANES;
        // The chunk's per-particle data on lanes (see `p2g/lanes.rs`); bit `l` of `fast` when
        // lane `l`'s pass ran on lanes.
        let mut b = ChunkBufs::<T, L>::new();
        let on_lanes = lanes_ok::<T>();
        let explicit = self.material.dilation == Dilation::Explicit;
        // The scalar passes of the other lanes, built in place (see `pre_into`); `live[l]`
        // when lane `l`'s succeeded.
        let mut pres = [Pre::<T, D>::blank(); L];
        let mut live = [false; L];
        // The chunk's positions and stencils (on lanes, see `Stencil::new_lanes`).
        let (kernel, grid, h) = (self.args.kernel, self.args.grid, self.args.h);
        let mut xs = [[T::ZERO; D]; L];
        let mut stencils = [Stencil::blank(kernel, h); L];
        let mut start = 0;
        while start < self.n {
            let len = lanes.min(self.n - start);
            let mut any_mu = false;
            let mut fast = 0u64;
            let mut g = 0;
            while g < len {
                let gl = R::LANES.min(len - g);
                // SAFETY: `p2g`'s contract: the arrays hold `n` particles.
                let pass = match on_lanes && gl == R::LANES {
                    true => unsafe { self.pre_lanes::<R, L>(start + g, g, &mut b, &mut xs) },
                    false => None,
                };
                if let Some(mu) = pass {
                    any_mu |= mu;
                    fast |= ((1u64 << gl) - 1) << g;
                    for lv in &mut live[g..g + gl] {
                        *lv = true;
                    }
                    g += gl;
                    continue;
                }
                for l in g..g + gl {
                    live[l] = false;
                    b.blank_lane::<D>(l);
                    // SAFETY: as above.
                    match unsafe { self.pre_into(start + l, &mut pres[l]) } {
                        Ok(()) => {
                            let pr = &pres[l];
                            for j in 0..D {
                                for r in 0..D {
                                    b.f[r + D * j][l] = pr.p.f_e.cols[j][r];
                                }
                            }
                            b.mu[l] = pr.mu;
                            any_mu |= pr.mu > T::ZERO;
                            xs[l] = pr.p.x;
                            live[l] = true;
                        }
                        Err(e) => self.first.note(start + l, Err(e)),
                    }
                }
                g += gl;
            }
            for l in len..lanes {
                b.blank_lane::<D>(l);
            }
            let done = Stencil::new_lanes::<V>(kernel, grid, h, &xs[..lanes], &mut stencils, None);
            let mut lane_err: [Option<Error>; L] = [None; L];
            // The deviatoric Kirchhoff stress Â F_Eᵀ of every lane (zero where μ = 0).
            let mut tau: LMat<V, D> = [[V::splat(T::ZERO); D]; D];
            if any_mu {
                let mut f: LMat<V, D> = [[V::splat(T::ZERO); D]; D];
                for j in 0..D {
                    for r in 0..D {
                        f[j][r] = V::load(&b.f[r + D * j][..lanes]);
                    }
                }
                let (co, ck) = evaluate(V::load(&b.mu[..lanes]), &f);
                tau = mul_nt(&ahat(&co), &f);
                let bits = check_bits::<V>(&ck);
                let flagged_lanes = flagged(&bits);
                for (l, e) in lane_err.iter_mut().enumerate().take(len) {
                    *e = kernel_lane_error(&bits, flagged_lanes, l, b.mu[l]);
                }
            }
            if any_mu {
                for j in 0..D {
                    for r in 0..D {
                        tau[j][r].store(&mut b.tau[r + D * j][..lanes]);
                    }
                }
            }
            if fast != 0 {
                fm_lanes(&mut b, &tau, explicit, lanes);
            }
            for l in 0..len {
                if live[l] {
                    if let Some(e) = lane_err[l] {
                        self.first.note(start + l, Err(e));
                        continue;
                    }
                    // No shear stress in the chunk (every μ = 0): an isotropic force.
                    let mut tau = Mat::<T, D>::ZERO;
                    if any_mu {
                        for j in 0..D {
                            for r in 0..D {
                                tau.cols[j][r] = b.tau[r + D * j][l];
                            }
                        }
                    }
                    let from_lanes = (fast >> l & 1 == 1).then_some((&b, l));
                    // SAFETY: `p2g`'s contract: valid channels over the box.
                    unsafe {
                        self.finish::<R, Q, K, N, SET, L>(
                            start + l,
                            (&pres[l], from_lanes, &xs[l]),
                            (tau, !any_mu),
                            (done >> l & 1 == 1).then_some(&stencils[l]),
                            (&mut tile, &mut run),
                            &oc,
                            &mut coef,
                        )
                    };
                }
            }
            start += len;
        }
        // SAFETY: as above.
        unsafe { self.flush::<R, Q, K, N>(&mut tile, &mut run, &oc) };
        self.first.status()
    }
}
