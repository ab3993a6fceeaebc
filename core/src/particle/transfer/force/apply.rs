//! [`apply()`]: node displacements to node force differentials through the prepared data, once
//! per Krylov iteration.

use super::ForceView;
use crate::error::{Error, Result};
use crate::kernel::batch::{dispatch, BatchReal, LaneOp, ScalarRow};
use crate::lane::{Isa, Lane, Pair, X2};
use crate::mat::{Mat, Matrix};
use crate::particle::implicit::{apply_entries, apply_slot, slot_len, tag};
use crate::particle::stencil::{Grid, Kernel, Stencil};
use crate::particle::transfer::field_sums::node_field_sums;
use crate::particle::transfer::nodes::{add, nodes, rel_base, restore, table, with_nodes};
use crate::particle::transfer::tile::{axis0, set_grad, Coef, Tile, MAX_RUN, TILE_X};
use crate::particle::transfer::{chunk_stencils, rd_vec, BatchStatus, FirstFailure};
use crate::scalar::Real;
use core::mem::MaybeUninit;

/// Applies the prepared differential of `n` particles at positions `x` (`n·d`, m; the positions
/// of the prepare's Newton step) to `view.du`, adding `δf` into `view.df` (collocated grid,
/// spacing `h`).
///
/// Errors per particle: [`Error::NotPrepared`] for a slot no successful prepare wrote, the
/// stencil's errors, [`Error::OutsideGrid`], [`Error::NonFinite`] for a non-finite `δu` read,
/// [`Error::Overflow`] for a `δf` that would not be finite. Whole-call errors (null `x`,
/// `slots` or channel) are reported for particle 0.
///
/// # Safety
/// `x` holds `n·d` scalars, `slots` `n·slot_len(d)`; every channel is valid at every node of
/// `view.nodes`; `df` channels do not alias `du` channels or the slots.
pub unsafe fn apply<T: BatchReal, const D: usize>(
    isa: Isa,
    kernel: Kernel,
    h: T,
    n: usize,
    x: *const T,
    slots: *const T,
    view: &ForceView<T, D>,
) -> BatchStatus
where
    Mat<T, D>: Matrix<Scalar = T, Vector = [T; D]>,
{
    let missing = view.du.iter().any(|c| c.data.is_null())
        || view.df.iter().any(|c| c.data.is_null())
        || (n > 0 && (x.is_null() || slots.is_null()));
    if missing {
        return BatchStatus {
            first_failed: 0,
            error: Some(Error::InvalidArgument),
        };
    }
    let mut op = ApplyOp {
        kernel,
        h,
        n,
        x,
        slots,
        view,
    };
    dispatch::<T, _>(isa, &mut op)
}

/// The particle loop of [`apply()`], run with the instruction set's target features (the
/// per-node arithmetic is written over arrays of nodes for the compiler to vectorise).
struct ApplyOp<'a, T, const D: usize> {
    kernel: Kernel,
    h: T,
    n: usize,
    x: *const T,
    slots: *const T,
    view: &'a ForceView<T, D>,
}

impl<T: BatchReal, const D: usize> LaneOp<T> for ApplyOp<'_, T, D>
where
    Mat<T, D>: Matrix<Scalar = T, Vector = [T; D]>,
{
    const JOINS_ROWS: bool = true;

    const AVX512_VL: bool = true;

    #[inline(always)]
    fn run<V: Lane<Scalar = T>>(&mut self) -> BatchStatus {
        // `dispatch` calls `run_rows`; this is its scalar-row form.
        self.run_rows::<V, ScalarRow<T>>()
    }

    #[inline(always)]
    fn run_rows<V: Lane<Scalar = T>, R: Lane<Scalar = T>>(&mut self) -> BatchStatus {
        self.run_pairs::<V, R, X2<R>>()
    }

    #[inline(always)]
    fn run_pairs<V: Lane<Scalar = T>, R: Lane<Scalar = T>, Q: Pair<R>>(&mut self) -> BatchStatus {
        with_nodes!(self.kernel, D, |K, N| self.run_nodes::<R, Q, K, N>())
    }
}

impl<T: BatchReal, const D: usize> ApplyOp<'_, T, D>
where
    Mat<T, D>: Matrix<Scalar = T, Vector = [T; D]>,
{
    /// The particle loop for a kernel with `K` nodes per axis (`N = K^d`): each particle's
    /// `δf` goes into a node tile ([`crate::particle::transfer::tile`]) that is added to `df` per run of nearby
    /// particles; a run whose sum would not be finite is added again one particle at a time
    /// ([`one`]), which refuses the particles that overflow. Particles go in chunks of
    /// [`TILE_X`]: the chunk's stencils on lanes, then each particle's `G` (reads of `δu`,
    /// written in place), then the chunk's `M = 𝒜(G)` ([`apply_entries`] on lanes when every
    /// particle of a full chunk got its `G`, one by one otherwise: the same formulas, whose
    /// multiply-adds are fused on the vector instruction sets), then the tile (writes of
    /// `δf`, which no read of `δu` sees).
    #[inline(always)]
    fn run_nodes<R: Lane<Scalar = T>, Q: Pair<R>, const K: usize, const N: usize>(
        &mut self,
    ) -> BatchStatus {
        debug_assert_eq!(R::LANES, TILE_X);
        let mut first = FirstFailure::new(self.n);
        let mut tile = Tile::<R, Q, D>::new();
        let mut run = [0usize; MAX_RUN];
        let mut nrun = 0;
        let (kernel, h) = (self.kernel, self.h);
        let mut xs = [[T::ZERO; D]; TILE_X];
        let mut stencils = [Stencil::blank(kernel, h); TILE_X];
        let mut rels = [[0isize; D]; TILE_X];
        let mut gs = [Mat::<T, D>::ZERO; TILE_X];
        let mut ms = [Mat::<T, D>::ZERO; TILE_X];
        let mut live = [false; TILE_X];
        let sl = slot_len(D);
        let mut start = 0;
        while start < self.n {
            let len = TILE_X.min(self.n - start);
            // SAFETY: `apply`'s contract (particles `start..start + len` of `n`).
            let done = unsafe {
                chunk_stencils::<T, R, D>(
                    kernel,
                    h,
                    self.x,
                    (start, len),
                    &mut xs,
                    &mut stencils,
                    None,
                )
            };
            for k in 0..len {
                // SAFETY: as above.
                let r = unsafe {
                    self.gather_with::<R, K, N>(
                        start + k,
                        &xs[k],
                        done >> k & 1 == 1,
                        &mut stencils[k],
                        &mut rels[k],
                        &mut gs[k],
                    )
                };
                live[k] = r.is_ok();
                first.note(start + k, r);
            }
            if len == TILE_X && live.iter().all(|&l| l) {
                // SAFETY: `apply`'s contract: slots `start..start + TILE_X` of `n`; `gs` and
                // `ms` are `repr(C)` matrices of `d²` scalars each.
                unsafe { apply_chunk::<T, R, D>(self.slots.add(start * sl), sl, &gs, &mut ms) };
            } else {
                for k in 0..len {
                    if live[k] {
                        // SAFETY: `apply`'s contract; a live particle's slot was checked.
                        let slot = unsafe { self.slot(start + k) };
                        ms[k] = apply_slot(slot, &gs[k]);
                    }
                }
            }
            for k in 0..len {
                if live[k] {
                    // SAFETY: as above.
                    unsafe {
                        self.tile_add::<R, Q, K, N>(
                            start + k,
                            (&stencils[k], &rels[k], &ms[k]),
                            &mut tile,
                            (&mut run, &mut nrun),
                            &mut first,
                        )
                    };
                }
            }
            start += len;
        }
        // SAFETY: as above.
        unsafe { self.flush::<R, Q, K, N>(&mut tile, &run[..nrun], &mut first) };
        first.status()
    }

    /// Adds particle `i` (its stencil, box-relative base and `M`) to the tile run, after
    /// adding the run to `df` if the particle does not fit or the run is full.
    ///
    /// # Safety
    /// `apply`'s contract.
    #[inline(always)]
    unsafe fn tile_add<R: Lane<Scalar = T>, Q: Pair<R>, const K: usize, const N: usize>(
        &self,
        i: usize,
        (s, rel, m): (&Stencil<T, D>, &[isize; D], &Mat<T, D>),
        tile: &mut Tile<R, Q, D>,
        (run, nrun): (&mut [usize; MAX_RUN], &mut usize),
        first: &mut FirstFailure,
    ) {
        let fits = if *nrun < MAX_RUN {
            tile.place::<K>(rel, &s.fx)
        } else {
            None
        };
        let sp = match fits {
            Some(sp) => sp,
            None => {
                self.flush::<R, Q, K, N>(tile, &run[..*nrun], first);
                *nrun = 0;
                // An empty tile takes any stencil.
                tile.place::<K>(rel, &s.fx).unwrap_or([0; D])
            }
        };
        let (w, dw, _) = axis0::<T, R, D, K>(s, sp[0]);
        let mut coef = [Coef::only(R::splat(T::ZERO)); D];
        for (a, c) in coef.iter_mut().enumerate() {
            set_grad(c, w, dw, m, a, T::ONE);
        }
        tile.add_uniform::<K, false, true>(&sp, s, &coef);
        run[*nrun] = i;
        *nrun += 1;
    }

    /// Particle `i`'s stencil, box-relative base and `M = 𝒜(G)`.
    ///
    /// # Safety
    /// `apply`'s contract.
    #[inline(always)]
    unsafe fn gather<R: Lane<Scalar = T>, const K: usize, const N: usize>(
        &self,
        i: usize,
    ) -> Result<(Stencil<T, D>, [isize; D], Mat<T, D>)> {
        let xp = rd_vec::<T, D>(self.x, i);
        let mut s = Stencil::blank(self.kernel, self.h);
        let (mut rel, mut g) = ([0; D], Mat::ZERO);
        self.gather_with::<R, K, N>(i, &xp, false, &mut s, &mut rel, &mut g)?;
        Ok((s, rel, apply_slot(self.slot(i), &g)))
    }

    /// Particle `i`'s slot.
    ///
    /// # Safety
    /// `apply`'s contract (`i < n`).
    #[inline(always)]
    unsafe fn slot(&self, i: usize) -> &[T] {
        let sl = slot_len(D);
        core::slice::from_raw_parts(self.slots.add(i * sl), sl)
    }

    /// [`Self::gather`] of particle `i` at `xp` into `s`, `rel` and `G` (in part on error; built
    /// in place, for the reason given at [`crate::particle::transfer::Particles::read_into`]); with `lane`, `s`
    /// already holds the stencil of `xp` ([`Stencil::new_lanes`]). Statuses in the order of
    /// the checks: slot, stencil, box, `δu`.
    ///
    /// # Safety
    /// `apply`'s contract.
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    unsafe fn gather_with<R: Lane<Scalar = T>, const K: usize, const N: usize>(
        &self,
        i: usize,
        xp: &[T; D],
        lane: bool,
        s: &mut Stencil<T, D>,
        rel: &mut [isize; D],
        g: &mut Mat<T, D>,
    ) -> Result<()> {
        if self.slot(i)[0] != tag::<T>(D) {
            return Err(Error::NotPrepared);
        }
        if !lane {
            *s = Stencil::new(self.kernel, Grid::Collocated, self.h, xp)?;
        }
        *rel = rel_base(s, &self.view.nodes)?;
        *g = grad_u::<T, R, D, K, N>(s, rel, self.view)?;
        Ok(())
    }

    /// Adds the tile to `df`; if that would write a non-finite value, adds the run's particles
    /// one by one instead.
    ///
    /// # Safety
    /// `apply`'s contract.
    #[inline(always)]
    unsafe fn flush<R: Lane<Scalar = T>, Q: Pair<R>, const K: usize, const N: usize>(
        &self,
        tile: &mut Tile<R, Q, D>,
        run: &[usize],
        first: &mut FirstFailure,
    ) {
        if tile.add_to_grid::<K>(&self.view.df) {
            return;
        }
        for &i in run {
            let r = self
                .gather::<R, K, N>(i)
                .and_then(|(s, rel, m)| one::<T, D, K, N>(&s, &rel, &m, self.view));
            first.note(i, r);
        }
    }
}

/// `M = 𝒜(G)` of [`TILE_X`] consecutive particles on lanes ([`apply_entries`]): `slots` the
/// first one's slot (each `sl` scalars), `gs` their `G`, `ms` their `M`.
///
/// # Safety
/// `slots` is valid for reading `TILE_X·sl` scalars.
#[inline(always)]
unsafe fn apply_chunk<T: Real, R: Lane<Scalar = T>, const D: usize>(
    slots: *const T,
    sl: usize,
    gs: &[Mat<T, D>; TILE_X],
    ms: &mut [Mat<T, D>; TILE_X],
) {
    debug_assert_eq!(R::LANES, TILE_X);
    let z = R::splat(T::ZERO);
    // Slot entries 1.. (after the tag): at most those of a 3D slot.
    let mut e = [z; slot_len(3) - 1];
    R::load_records(slots.add(1), sl, &mut e[..sl - 1]);
    // `Mat` is `repr(C)` around `[[T; D]; D]`: entry (i, j) of particle `l` is scalar
    // `l·d² + j·d + i` of the arrays.
    let (gp, mp) = (gs.as_ptr().cast::<T>(), ms.as_mut_ptr().cast::<T>());
    let mut flat = [z; 9];
    R::load_records(gp, D * D, &mut flat[..D * D]);
    let mut g = [[z; D]; D];
    for (j, col) in g.iter_mut().enumerate() {
        for (i, x) in col.iter_mut().enumerate() {
            *x = flat[j * D + i];
        }
    }
    let m = apply_entries::<R, D>(&e[..sl - 1], &g);
    for (j, col) in m.iter().enumerate() {
        for (i, x) in col.iter().enumerate() {
            flat[j * D + i] = *x;
        }
    }
    R::store_records(mp, D * D, &flat[..D * D]);
}

/// `G = Σ_j δu_j ∇w_jᵀ` over the nodes of stencil `s` (box-relative base `rel`), by the
/// separable contraction of [`node_field_sums`].
///
/// # Safety
/// `apply`'s contract; the stencil is inside the box.
#[inline(always)]
unsafe fn grad_u<T: Real, R: Lane<Scalar = T>, const D: usize, const K: usize, const N: usize>(
    s: &Stencil<T, D>,
    rel: &[isize; D],
    view: &ForceView<T, D>,
) -> Result<Mat<T, D>> {
    let sums = node_field_sums::<T, R, D, K, false>(s, rel, &view.du, (0, D));
    if !sums.finite {
        return Err(Error::NonFinite);
    }
    Ok(sums.g)
}

/// One particle of [`apply()`] added on its own: `δf_i = M ∇w_i` added per channel, with every
/// old value kept and put back on overflow.
///
/// # Safety
/// `apply`'s contract; the stencil is inside the box.
#[inline(always)]
unsafe fn one<T: Real, const D: usize, const K: usize, const N: usize>(
    s: &Stencil<T, D>,
    rel: &[isize; D],
    m: &Mat<T, D>,
    view: &ForceView<T, D>,
) -> Result<()>
where
    Mat<T, D>: Matrix<Scalar = T, Vector = [T; D]>,
{
    let nd = nodes::<T, D, K, N>(s);
    let mut f = [[T::ZERO; N]; D];
    for i in 0..N {
        let mut gi = [T::ZERO; D];
        for (b, g) in gi.iter_mut().enumerate() {
            *g = nd.g[b][i];
        }
        let fi = m.mul_vec(gi);
        for a in 0..D {
            f[a][i] = fi[a];
        }
    }
    let mut old = [[MaybeUninit::<T>::uninit(); N]; D];
    let mut tabs = [[[0isize; 4]; D]; D];
    let mut chk = true;
    for a in 0..D {
        let c = &view.df[a];
        tabs[a] = table(c, rel);
        chk &= add::<T, ScalarRow<T>, D, K, N>(c.data, &tabs[a], c.stride[0], &f[a], &mut old[a]);
    }
    if !chk {
        for a in (0..D).rev() {
            let c = &view.df[a];
            restore::<T, D, K, N>(c.data, &tabs[a], c.stride[0], &old[a]);
        }
        return Err(Error::Overflow);
    }
    Ok(())
}
