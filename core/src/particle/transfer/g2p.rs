//! G2P from a grid view and the particle update.
//!
//! Per particle (Jiang et al. 2015, §5.3 and §6 for MAC grids): `v_p = Σ w_i v_i`,
//! `C_p = Σ w_i v_i (x_i − x_p)ᵀ / (κ h²)` (`κ` = [`Kernel::apic_moment`]), `∇v_p = Σ v_i ∇w_iᵀ`,
//! and with heat on `T_pic = Σ w_i T_iⁿ⁺¹`, `ΔT_flip = Σ w_i (T_iⁿ⁺¹ − T_iⁿ)`; then
//! [`crate::particle::update::update_particle`] (temperature and phase, advection, `F_E` with its remedy, the liquid
//! projection or snow plasticity). On a MAC grid component `a` of `v_p`, row `a` of `C_p` and
//! of `∇v_p` come from face grid `a` with its own stencil; temperatures stay collocated.
//!
//! With `x_i − x_p = (o − fx) h` ([`Stencil::fx`]), `C_p = (Σ w_i v_i oᵀ − v_p fxᵀ)/(κ h)`: no
//! per-node subtraction.

use super::field_sums::{chunk_sums, node_field_sums, pair_products, pair_sums};
use super::lane_sums::chunk_field_sums;
use super::nodes::{rel_base, taint, with_nodes};
use super::update_lanes::{self, ChunkSamples};
use super::{chunk_stencils, BatchStatus, Checked, FirstFailure, InChannel, NodeBox};
use super::{Particles, Reads};
use crate::error::{Error, Result};
use crate::kernel::batch::{dispatch, BatchReal, LaneOp, ScalarRow};
use crate::lane::{Isa, Lane};
use crate::mat::{Mat, Matrix};
use crate::particle::apic::inv_kappa_h;
use crate::particle::stencil::{Grid, Kernel, Stencil, StencilLanes};
use crate::particle::update::{update_validated, G2pSample};
use crate::particle::Material;
use crate::polar::{DefaultSvd, SvdMethod};
use crate::scalar::Real;

/// Where G2P reads: a node box and its channels.
#[derive(Clone, Copy, Debug)]
pub struct G2pView<T, const D: usize> {
    /// The nodes the channels cover.
    pub nodes: NodeBox<D>,
    /// New node velocities `v_iⁿ⁺¹` per axis (m/s).
    pub velocity: [InChannel<T, D>; D],
    /// New node temperatures `T_iⁿ⁺¹` (K); read with heat on.
    pub temperature: InChannel<T, D>,
    /// Old node temperatures `T_iⁿ` (K); read with heat on.
    pub temperature_old: InChannel<T, D>,
}

/// The parameters of a G2P call.
#[derive(Clone, Copy, Debug)]
pub struct G2pArgs<T> {
    /// Interpolation kernel.
    pub kernel: Kernel,
    /// Grid spacing `h` (m).
    pub h: T,
    /// Time step `Δt > 0` (s).
    pub dt: T,
}

/// G2P and the update of `n` particles. `view` is the collocated grid (velocities and, with
/// heat on, temperatures); with `faces` (a MAC grid) velocity component `a` is read from
/// `faces[a].velocity[a]` on face grid `a` instead, and `view`'s velocities are not read.
///
/// Reads every particle array the material needs; writes `x, v, affine, f_e, f_p`, and
/// `temperature`, `latent`, `phase` as the material says. A failed particle keeps its state.
///
/// Errors per particle: those of [`crate::particle::update::update_particle`], [`Error::OutsideGrid`],
/// [`Error::NonFinite`] for a non-finite node value that the particle reads, [`Error::Overflow`]
/// for sums that overflow. Whole-call errors (a null array the material needs, a null velocity
/// channel, null temperature channels with heat on) are reported for particle 0.
///
/// # Safety
/// The arrays of `ps` hold `n` particles; every channel read is valid at every node of its
/// box; no channel aliases a particle array.
pub unsafe fn g2p_update<T: BatchReal, const D: usize>(
    isa: Isa,
    material: &Material<T>,
    args: &G2pArgs<T>,
    n: usize,
    ps: &Particles<T>,
    view: &G2pView<T, D>,
    faces: Option<&[G2pView<T, D>; D]>,
) -> BatchStatus
where
    Mat<T, D>: Matrix<Scalar = T, Vector = [T; D]>,
    DefaultSvd: SvdMethod<Mat<T, D>>,
{
    let bad = |e| BatchStatus {
        first_failed: 0,
        error: Some(e),
    };
    let reads = Reads::ALL;
    let heat = material.heat.is_some();
    let vel_missing = match faces {
        Some(f) => (0..D).any(|a| f[a].velocity[a].data.is_null()),
        None => view.velocity.iter().any(|c| c.data.is_null()),
    };
    let missing = (n > 0 && !ps.has(reads, material))
        || vel_missing
        || (heat && (view.temperature.data.is_null() || view.temperature_old.data.is_null()));
    if missing {
        return bad(Error::InvalidArgument);
    }
    let mut op = G2pOp {
        material,
        checked: Checked::new(material),
        args,
        n,
        ps,
        view,
        faces,
    };
    // This loop's lanes are eight wide (node sums on eight-lane rows, the particle update on
    // chunks of eight), which AVX2 has; its AVX-512 build measured 20–30 % slower than its AVX2
    // build on an AVX-512 Xeon (the per-particle scalar work compiles worse there), with the same
    // bits, and still 8–18% slower on an AVX-512 AMD Zen 4 with the update on lanes.
    dispatch::<T, _>(isa.at_most_avx2(), &mut op)
}

/// The particle loop of [`g2p_update`], run with the instruction set's target features (its
/// per-node arithmetic is written over arrays of nodes for the compiler to vectorise; the
/// lane type itself is not used).
struct G2pOp<'a, T, const D: usize> {
    material: &'a Material<T>,
    checked: Checked,
    args: &'a G2pArgs<T>,
    n: usize,
    ps: &'a Particles<T>,
    view: &'a G2pView<T, D>,
    faces: Option<&'a [G2pView<T, D>; D]>,
}

impl<T: BatchReal, const D: usize> LaneOp<T> for G2pOp<'_, T, D>
where
    Mat<T, D>: Matrix<Scalar = T, Vector = [T; D]>,
    DefaultSvd: SvdMethod<Mat<T, D>>,
{
    #[inline(always)]
    fn run<V: Lane<Scalar = T>>(&mut self) -> BatchStatus {
        // `dispatch` calls `run_rows`; this is its scalar-row form.
        self.run_rows::<V, ScalarRow<T>>()
    }

    #[inline(always)]
    fn run_rows<V: Lane<Scalar = T>, R: Lane<Scalar = T>>(&mut self) -> BatchStatus {
        with_nodes!(self.args.kernel, D, |K, N| self.run_nodes::<R, K, N>())
    }
}

impl<T: BatchReal, const D: usize> G2pOp<'_, T, D>
where
    Mat<T, D>: Matrix<Scalar = T, Vector = [T; D]>,
    DefaultSvd: SvdMethod<Mat<T, D>>,
{
    /// The particle loop for a kernel with `K` nodes per axis (`N = K^d`), in chunks of
    /// [`CHUNK`] particles: first every grid sample of the chunk (stencil and node sums, which
    /// read only the position), then every update. Each half is a short loop whose iterations
    /// do not depend on each other, so the processor overlaps consecutive particles' latency
    /// chains (one particle's whole G2P is longer than its out-of-order window). The statuses
    /// are those of the one-particle order: the particle's own checks come before its sample's.
    #[inline(always)]
    fn run_nodes<R: Lane<Scalar = T>, const K: usize, const N: usize>(&mut self) -> BatchStatus {
        let mut first = FirstFailure::new(self.n);
        // The row types have eight lanes: a chunk's samples and updates run one particle per
        // lane.
        const { assert!(R::LANES == CHUNK) };
        let mut cs = ChunkSamples::new();
        // The chunk's samples and their statuses, written in place: a sample returned by value
        // (in a `Result`) is copied with wide moves right after its fields were stored one by
        // one, and such a copy waits for the stores to reach the cache.
        let zero = G2pSample {
            v: [T::ZERO; D],
            affine: Mat::ZERO,
            grad_v: Mat::ZERO,
            t_pic: T::ZERO,
            t_flip: T::ZERO,
        };
        let mut samples = [zero; CHUNK];
        let mut status = [Ok(()); CHUNK];
        // The chunk's positions and collocated stencils (on lanes, see `Stencil::new_lanes`).
        let (kernel, h) = (self.args.kernel, self.args.h);
        let mut xs = [[T::ZERO; D]; CHUNK];
        let mut stencils = [Stencil::blank(kernel, h); CHUNK];
        // The same stencils on lanes: where a lane's stencil is not done, its particle does
        // not sample (its `Stencil::new` fails), so the lanes of every particle that samples
        // hold its stencil. The velocity sums read the weights from the lanes; only the
        // temperatures' sums and the MAC grid's read them from the stencils.
        let mut lane_stencils = StencilLanes::<R>::new();
        lane_stencils.records = self.faces.is_some() || self.material.heat.is_some();
        let mut start = 0;
        while start < self.n {
            let len = CHUNK.min(self.n - start);
            // SAFETY: `g2p_update`'s contract (particles `start..start + len` of `n`).
            let done = unsafe {
                chunk_stencils::<T, R, D>(
                    kernel,
                    h,
                    self.ps.x,
                    (start, len),
                    &mut xs,
                    &mut stencils,
                    Some(&mut lane_stencils),
                )
            };
            let whole = len == CHUNK;
            // The stencils that the lanes did not make, with their errors.
            for (k, st) in status.iter_mut().enumerate().take(len) {
                *st = if done >> k & 1 == 1 {
                    Ok(())
                } else {
                    Stencil::new(kernel, Grid::Collocated, h, &xs[k]).map(|s| stencils[k] = s)
                };
                debug_assert!(done >> k & 1 == 1 || st.is_err());
            }
            match self.faces {
                // SAFETY: `g2p_update`'s contract.
                None => unsafe {
                    sample_lanes::<T, R, D, K>(
                        self.material,
                        self.args,
                        (&stencils, &lane_stencils, len),
                        self.view,
                        &mut status,
                        &mut cs,
                    )
                },
                Some(faces) => {
                    for (k, (out, st)) in samples.iter_mut().zip(&mut status).enumerate() {
                        if k < len && st.is_ok() {
                            // SAFETY: `g2p_update`'s contract.
                            *st = unsafe {
                                sample_faces::<T, R, D, K, N>(
                                    self.material,
                                    self.args,
                                    &xs[k],
                                    &stencils[k],
                                    self.view,
                                    faces,
                                    out,
                                )
                            };
                            if st.is_ok() {
                                cs.set(k, out);
                            }
                        }
                    }
                }
            }
            let all_ok = status[..len].iter().all(Result::is_ok);
            // SAFETY: as above.
            if whole
                && all_ok
                && unsafe {
                    update_lanes::update::<T, R, D>(
                        self.material,
                        &self.checked,
                        self.args.dt,
                        self.args.h,
                        self.ps,
                        start,
                        &cs,
                    )
                }
            {
                start += len;
                continue;
            }
            if self.faces.is_none() {
                for (k, smp) in samples.iter_mut().enumerate().take(len) {
                    *smp = cs.get(k);
                }
            }
            for (k, (smp, st)) in samples.iter().zip(&status).enumerate().take(len) {
                // SAFETY: as above.
                let r = unsafe {
                    update_one::<T, R, D>(
                        self.material,
                        &self.checked,
                        self.args,
                        self.ps,
                        st.map(|()| smp),
                        start + k,
                    )
                };
                first.note(start + k, r);
            }
            start += len;
        }
        first.status()
    }
}

/// Particles per chunk of [`G2pOp::run_nodes`] (the lanes of [`update_lanes`]).
const CHUNK: usize = update_lanes::LANES;

/// The update of particle `i` from its grid sample (or the sample's error): the particle's
/// checks, then the sample's status, then [`update_validated`] (snow plasticity's step on
/// lanes of the chunk's row type `R`, as the chunks on lanes take it) and the position limit.
#[inline(always)]
unsafe fn update_one<T: Real, R: Lane<Scalar = T>, const D: usize>(
    material: &Material<T>,
    checked: &Checked,
    args: &G2pArgs<T>,
    ps: &Particles<T>,
    sample: Result<&G2pSample<T, D>>,
    i: usize,
) -> Result<()>
where
    Mat<T, D>: Matrix<Scalar = T, Vector = [T; D]>,
    DefaultSvd: SvdMethod<Mat<T, D>>,
{
    let reads = Reads::ALL;
    let p = ps.get::<D>(i, reads, material)?;
    checked.for_phase(p.phase)?;
    let sample = sample?;
    // The material was validated for this phase above (`checked`).
    let (out, _) = update_validated::<T, R, D>(material, args.dt, sample, &p)?;
    if Stencil::<T, D>::check_position(Grid::Collocated, args.h, &out.x).is_err() {
        // The cell index of the new position is beyond the supported range (as g2p_update).
        return Err(Error::Overflow);
    }
    ps.put(i, material, &out);
    Ok(())
}

/// The grid sample of a particle at `x` with collocated stencil `s` on a MAC grid: velocity
/// component `a` from face grid `a` ([`node_field_sums`] over the face stencil), temperatures
/// from the collocated `view`; written to `out` (in part on error).
#[inline(always)]
#[allow(clippy::too_many_arguments)]
unsafe fn sample_faces<
    T: Real,
    R: Lane<Scalar = T>,
    const D: usize,
    const K: usize,
    const N: usize,
>(
    material: &Material<T>,
    args: &G2pArgs<T>,
    x: &[T; D],
    s: &Stencil<T, D>,
    view: &G2pView<T, D>,
    faces: &[G2pView<T, D>; D],
    out: &mut G2pSample<T, D>,
) -> Result<()>
where
    Mat<T, D>: Matrix<Scalar = T, Vector = [T; D]>,
{
    // The collocated box is read for temperatures (heat on).
    let rel = if material.heat.is_some() {
        rel_base(s, &view.nodes)?
    } else {
        [0; D]
    };
    // 1/(κ h): C_p = (Σ w v oᵀ − v fxᵀ)/(κ h).
    let inv_kh = inv_kappa_h(args.kernel, args.h)?;
    out.t_pic = T::ZERO;
    out.t_flip = T::ZERO;
    let mut finite = true;
    for a in 0..D {
        let st = Stencil::new(args.kernel, Grid::Face(a), args.h, x)?;
        let rl = rel_base(&st, &faces[a].nodes)?;
        let sm = node_field_sums::<T, R, D, K, true>(&st, &rl, &faces[a].velocity, (a, a + 1));
        finite &= sm.finite;
        out.v[a] = sm.v[a];
        for b in 0..D {
            out.affine.cols[b][a] = (sm.mo.cols[b][a] - sm.v[a] * st.fx[b]) * inv_kh;
            out.grad_v.cols[b][a] = sm.g.cols[b][a];
        }
    }
    if material.heat.is_some() {
        // Σ w Tⁿ⁺¹ and Σ w (Tⁿ⁺¹ − Tⁿ), by separable contraction.
        let (pic, flip, ok) =
            pair_sums::<T, R, D, K>(s, &rel, &view.temperature, &view.temperature_old);
        finite &= ok;
        out.t_pic = pic;
        out.t_flip = flip;
    }
    if !finite {
        return Err(Error::NonFinite);
    }
    let mut chk = true;
    for a in 0..D {
        taint(&mut chk, out.v[a]);
    }
    taint(&mut chk, out.t_pic);
    taint(&mut chk, out.t_flip);
    if !(chk && out.affine.is_finite() && out.grad_v.is_finite()) {
        return Err(Error::Overflow);
    }
    Ok(())
}

/// The grid samples of the chunk's first `len` particles on the collocated grid (their
/// `stencils`, and the same on lanes, `lanes`, for every lane whose stencil is `Ok` in
/// `status`), one particle per lane of `R`, written to `cs`: the velocity sums of
/// [`chunk_field_sums`]; with heat on each particle's temperature pair ([`pair_sums`], or for a
/// chunk whose eight particles all sample, [`chunk_sums`] of their
/// [`pair_products`] where the row type transposes in registers: the same bits); then
/// `C_p = (Σ w v oᵀ − v fxᵀ)/(κ h)` and the checks on the lanes. On entry `status[k]` is
/// particle `k`'s stencil status; on return its sample's status, with the errors in this
/// order: outside the box, `1/(κ h)` not finite ([`Error::Overflow`]), a node value read that
/// is not finite ([`Error::NonFinite`]), a sum that overflows ([`Error::Overflow`]). Lane `k`
/// of `cs` is the sample where the status is `Ok`.
///
/// # Safety
/// As [`g2p_update`], for the chunk's particles.
#[inline(always)]
unsafe fn sample_lanes<T: Real, R: Lane<Scalar = T>, const D: usize, const K: usize>(
    material: &Material<T>,
    args: &G2pArgs<T>,
    (stencils, lanes, len): (&[Stencil<T, D>; CHUNK], &StencilLanes<R>, usize),
    view: &G2pView<T, D>,
    status: &mut [Result<()>; CHUNK],
    cs: &mut ChunkSamples<T>,
) {
    // The lanes that sample: a stencil inside the box.
    let mut rel = [[0isize; D]; CHUNK];
    let mut live = 0u32;
    for (k, (st, r)) in status.iter_mut().zip(&mut rel).enumerate().take(len) {
        if st.is_ok() {
            match rel_base(&stencils[k], &view.nodes) {
                Ok(x) => {
                    *r = x;
                    live |= 1 << k;
                }
                Err(e) => *st = Err(e),
            }
        }
    }
    if live == 0 {
        return;
    }
    // `1/(κ h)` (a lane with a stencil has a finite positive `h`: only an overflow is left).
    let inv_kh = match inv_kappa_h(args.kernel, args.h) {
        Ok(x) => x,
        Err(e) => {
            for (k, st) in status.iter_mut().enumerate() {
                if live >> k & 1 == 1 {
                    *st = Err(e);
                }
            }
            return;
        }
    };
    let z = R::splat(T::ZERO);
    // Lanes that read a temperature that is not finite.
    let mut heat_bad = 0u64;
    let (mut pic, mut flip) = (z, z);
    if material.heat.is_some() {
        let all = live == (1 << CHUNK) - 1;
        if all && R::TRANSPOSE8_IN_REGISTERS {
            let mut prods = [z; CHUNK];
            for (k, (p, r)) in prods.iter_mut().zip(&rel).enumerate() {
                let (x, ok) = pair_products::<T, R, D, K>(
                    &stencils[k],
                    r,
                    &view.temperature,
                    &view.temperature_old,
                );
                *p = x;
                heat_bad |= u64::from(!ok) << k;
            }
            [pic, flip] = chunk_sums::<R, K>(prods);
        } else {
            let (mut tp, mut tf) = ([T::ZERO; CHUNK], [T::ZERO; CHUNK]);
            for k in 0..len {
                if live >> k & 1 == 1 {
                    let (a, b, ok) = pair_sums::<T, R, D, K>(
                        &stencils[k],
                        &rel[k],
                        &view.temperature,
                        &view.temperature_old,
                    );
                    (tp[k], tf[k]) = (a, b);
                    heat_bad |= u64::from(!ok) << k;
                }
            }
            (pic, flip) = (R::load(&tp), R::load(&tf));
        }
    }
    // The velocity sums after the temperatures' (measured faster in this order).
    let sm = chunk_field_sums::<T, R, D, K>(lanes, &rel, live, &view.velocity);
    let fx = &lanes.fx;
    // As `sample_faces`: `v`, `C_p = (Σ w v oᵀ − v fxᵀ)/(κ h)`, `∇v`, every one finite.
    let inv = R::splat(inv_kh);
    let mut ok = z.eq(z);
    for a in 0..D {
        let v = sm.v[a];
        ok = ok & v.is_finite();
        v.store(&mut cs.v[a]);
        for b in 0..D {
            let c = (sm.mo[b][a] - v * fx[b]) * inv;
            let g = sm.g[b][a];
            ok = ok & c.is_finite() & g.is_finite();
            c.store(&mut cs.affine[a + D * b]);
            g.store(&mut cs.grad_v[a + D * b]);
        }
    }
    ok = ok & pic.is_finite() & flip.is_finite();
    pic.store(&mut cs.t_pic);
    flip.store(&mut cs.t_flip);
    let read_bad = !R::mask_bits(sm.chk.is_finite()) | heat_bad;
    let sums_ok = R::mask_bits(ok);
    for (k, st) in status.iter_mut().enumerate() {
        if live >> k & 1 == 1 {
            *st = if read_bad >> k & 1 == 1 {
                Err(Error::NonFinite)
            } else if sums_ok >> k & 1 == 0 {
                Err(Error::Overflow)
            } else {
                Ok(())
            };
        }
    }
}
