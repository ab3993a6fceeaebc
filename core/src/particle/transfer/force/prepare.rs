//! [`prepare()`]: the per-particle data of the force differential, once per Newton step.

use crate::error::{Error, Result};
use crate::kernel::batch::{dispatch, BatchReal, LaneOp, ScalarRow, WIDE_LANES};
use crate::kernel::chunk::{check_bits, kernel_lane_error};
use crate::kernel::{evaluate, flagged, Dim, LaneDim};
use crate::lane::lmat::LMat;
use crate::lane::{Isa, Lane};
use crate::mat::{Mat, Matrix};
use crate::particle::implicit::{blocks, entries, slot_len, tag};
use crate::particle::transfer::deformation_lanes::{deformation_lanes, lanes_ok};
use crate::particle::transfer::{BatchStatus, Checked, FirstFailure, Particles, Reads};
use crate::particle::update::check_particle;
use crate::particle::{Definiteness, Dilation, Material};
use crate::scalar::Real;
use core::ptr;

/// Prepares the force differential of `n` particles into `slots` (`n·`[`slot_len`]`(d)`
/// scalars): reads `f_e`, `f_p`, `volume0`, `phase` (and `latent` with phase change). A failed
/// particle's slot gets tag 0 only, so that [`super::apply()`] refuses it.
///
/// Errors per particle: invalid particle or material, the kernels' errors, [`Error::Overflow`].
/// Whole-call errors (a null array the material needs) are reported for particle 0.
///
/// # Safety
/// The arrays hold `n` particles; `slots` is valid for `n·slot_len(d)` scalars.
pub unsafe fn prepare<T: BatchReal, const D: usize>(
    isa: Isa,
    material: &Material<T>,
    n: usize,
    ps: &Particles<T>,
    slots: *mut T,
) -> BatchStatus
where
    Dim<D>: LaneDim<D>,
    Mat<T, D>: Matrix<Scalar = T, Vector = [T; D]>,
{
    let reads = Reads::DEFORMATION;
    if n > 0 && (!ps.has(reads, material) || slots.is_null()) {
        return BatchStatus {
            first_failed: 0,
            error: Some(Error::InvalidArgument),
        };
    }
    let mut op = PrepareOp::<T, D> {
        material,
        checked: Checked::new(material),
        n,
        ps,
        slots,
        first: FirstFailure::new(n),
    };
    dispatch::<T, _>(isa, &mut op);
    op.first.status()
}

/// The particle loop of [`prepare()`], run with the instruction set's target features; the
/// first failure is kept in `first`.
struct PrepareOp<'a, T, const D: usize> {
    material: &'a Material<T>,
    checked: Checked,
    n: usize,
    ps: &'a Particles<T>,
    slots: *mut T,
    first: FirstFailure,
}

/// Per particle: `F_E`, `μ`, `α`, `β`, `−V⁰`.
type Pre<T, const D: usize> = (Mat<T, D>, [T; 4]);

impl<T: BatchReal, const D: usize> PrepareOp<'_, T, D>
where
    Mat<T, D>: Matrix<Scalar = T, Vector = [T; D]>,
{
    unsafe fn pre(&self, i: usize) -> Result<Pre<T, D>> {
        let reads = Reads::DEFORMATION;
        let p = self.ps.get::<D>(i, reads, self.material)?;
        self.checked.for_phase(p.phase)?;
        let (j, j_p) = check_particle(&p)?;
        let m = self.material.moduli(p.phase, j_p)?;
        let (alpha, beta) = dilation_factors(self.material.dilation, j, m.inv_lambda);
        if !(alpha.is_finite() && beta.is_finite()) {
            return Err(Error::Overflow);
        }
        Ok((p.f_e, [m.mu, alpha, beta, -p.volume0]))
    }

    /// [`Self::pre`] of particles `start..start + R::LANES` on lanes, into lanes `l0..` of
    /// `fbuf` (`F_E`, entry `i + d·j`) and `sbuf` (`μ`, `α`, `β`, `−V⁰`), with the same
    /// operations and bits ([`deformation_lanes`]); returns whether every particle passed
    /// (else the lanes hold nothing meant to be read, and the caller runs `pre` on each).
    ///
    /// # Safety
    /// As [`Self::pre`], for each of the particles.
    #[inline(always)]
    unsafe fn pre_lanes<R: Lane<Scalar = T>>(
        &self,
        start: usize,
        l0: usize,
        fbuf: &mut [[T; WIDE_LANES]; 9],
        sbuf: &mut [[T; WIDE_LANES]; 4],
    ) -> bool {
        let Some(d) = deformation_lanes::<T, R, D>(self.ps, self.material, &self.checked, start)
        else {
            return false;
        };
        let (alpha, beta) = dilation_factors(self.material.dilation, d.j_e, d.inv_lambda);
        if !R::all(d.ok & alpha.is_finite() & beta.is_finite()) {
            return false;
        }
        let lanes = l0..l0 + R::LANES;
        for (c, x) in d.fe.iter().enumerate().take(D * D) {
            x.store(&mut fbuf[c][lanes.clone()]);
        }
        for (row, x) in sbuf.iter_mut().zip([d.mu, alpha, beta, -d.vol]) {
            x.store(&mut row[lanes.clone()]);
        }
        true
    }
}

impl<T: BatchReal, const D: usize> LaneOp<T> for PrepareOp<'_, T, D>
where
    Dim<D>: LaneDim<D>,
    Mat<T, D>: Matrix<Scalar = T, Vector = [T; D]>,
{
    const AVX512_VL: bool = true;

    #[inline(always)]
    fn run<V: Lane<Scalar = T>>(&mut self) -> BatchStatus {
        // `dispatch` calls `run_rows`; this is its scalar-row form.
        self.run_rows::<V, ScalarRow<T>>()
    }

    #[inline(always)]
    fn run_rows<V: Lane<Scalar = T>, R: Lane<Scalar = T>>(&mut self) -> BatchStatus {
        // Chunks of twice the kernel lanes: the decomposition's rotations are latency-bound.
        self.run_chunks::<V::Wide, R>()
    }
}

impl<T: BatchReal, const D: usize> PrepareOp<'_, T, D>
where
    Dim<D>: LaneDim<D>,
    Mat<T, D>: Matrix<Scalar = T, Vector = [T; D]>,
{
    /// The particle loop on chunks of `V`: each particle's [`Self::pre`] (on the lanes of `R`,
    /// eight particles at once, in `f32`), the kernels on `V`, the slots.
    #[inline(always)]
    fn run_chunks<V: Lane<Scalar = T>, R: Lane<Scalar = T>>(&mut self) -> BatchStatus {
        let lanes = V::LANES;
        let sl = slot_len(D);
        let psd = self.material.hessian == Definiteness::Projected;
        let mut start = 0;
        while start < self.n {
            let len = lanes.min(self.n - start);
            let mut fbuf = [[T::ZERO; WIDE_LANES]; 9];
            let mut sbuf = [[T::ZERO; WIDE_LANES]; 4];
            let mut err: [Option<Error>; WIDE_LANES] = [None; WIDE_LANES];
            // Eight particles at once where they pass on lanes (`f32`, whose eight-lane type
            // transposes records in registers), else each on its own.
            let mut from_lanes = 0u64;
            if lanes_ok::<T>() {
                let mut g = 0;
                while g + R::LANES <= len {
                    // SAFETY: `prepare`'s contract.
                    if unsafe { self.pre_lanes::<R>(start + g, g, &mut fbuf, &mut sbuf) } {
                        from_lanes |= ((1u64 << R::LANES) - 1) << g;
                    }
                    g += R::LANES;
                }
            }
            for l in 0..lanes {
                if from_lanes >> l & 1 == 1 {
                    continue;
                }
                let pre = if l < len {
                    // SAFETY: `prepare`'s contract.
                    unsafe { self.pre(start + l) }
                } else {
                    Err(Error::InvalidArgument)
                };
                match pre {
                    Ok((f, s)) => {
                        for j in 0..D {
                            for r in 0..D {
                                fbuf[r + D * j][l] = f.cols[j][r];
                            }
                        }
                        for (k, x) in s.iter().enumerate() {
                            sbuf[k][l] = *x;
                        }
                    }
                    Err(e) => {
                        err[l] = Some(e);
                        for d in 0..D {
                            fbuf[d * (D + 1)][l] = T::ONE;
                        }
                    }
                }
            }
            let mut f: LMat<V, D> = [[V::splat(T::ZERO); D]; D];
            for j in 0..D {
                for r in 0..D {
                    f[j][r] = V::load(&fbuf[r + D * j][..lanes]);
                }
            }
            let [mu, alpha, beta, nv] = [
                V::load(&sbuf[0][..lanes]),
                V::load(&sbuf[1][..lanes]),
                V::load(&sbuf[2][..lanes]),
                V::load(&sbuf[3][..lanes]),
            ];
            let (co, ck) = evaluate(mu, &f);
            let b = blocks(&co, alpha, beta, nv, psd);
            let bits = check_bits::<V>(&ck);
            let flagged_lanes = flagged(&bits);
            let mut ent = [V::splat(T::ZERO); slot_len(3)];
            entries(&b, &mut ent);
            let mut out = [[T::ZERO; WIDE_LANES]; slot_len(3)];
            let mut chk = V::splat(T::ZERO);
            for (o, v) in ent.iter().enumerate().take(sl).skip(1) {
                // v − v is 0 for finite v and NaN otherwise: one finiteness sum per lane.
                #[allow(clippy::eq_op)]
                {
                    chk += *v - *v;
                }
                v.store(&mut out[o][..lanes]);
            }
            let mut ok_bits = [T::ZERO; WIDE_LANES];
            chk.store(&mut ok_bits[..lanes]);
            for l in 0..len {
                let i = start + l;
                let mut e = err[l];
                if e.is_none() {
                    e = kernel_lane_error(&bits, flagged_lanes, l, sbuf[0][l]);
                }
                if e.is_none() && !ok_bits[l].is_finite() {
                    e = Some(Error::Overflow);
                }
                // SAFETY: `prepare`'s contract: `n` slots.
                unsafe {
                    let slot = self.slots.add(i * sl);
                    match e {
                        None => {
                            for (o, row) in out.iter().enumerate().take(sl).skip(1) {
                                ptr::write_unaligned(slot.add(o), row[l]);
                            }
                            ptr::write_unaligned(slot, tag::<T>(D));
                        }
                        Some(_) => ptr::write_unaligned(slot, T::ZERO),
                    }
                }
                self.first.note(i, e.map_or(Ok(()), Err));
            }
            start += len;
        }
        self.first.status()
    }
}

/// The dilational factors `(α, β)` of the force differential at `J = J_E` (the explicit
/// dilation: `λJ(2J − 1)` and `−λJ(J − 1)`, formed as `(J/(1/λ))·…`; none with the pressure
/// solve), for one particle or a lane of them: one formula, so both passes give the same bits.
#[inline(always)]
fn dilation_factors<V: Lane>(dilation: Dilation, j: V, inv_lambda: V) -> (V, V) {
    let (zero, one) = (V::splat(V::Scalar::ZERO), V::splat(V::Scalar::ONE));
    match dilation {
        Dilation::Explicit => {
            let lj = j / inv_lambda;
            (lj * (j + j - one), -(lj * (j - one)))
        }
        Dilation::PressureSolve => (zero, zero),
    }
}
