//! P2G's per-particle pass on lanes: the reads, input checks and moduli of
//! [`P2gOp::pre_into`] and the per-particle factors of [`P2gOp::ready`] for eight consecutive
//! particles at once (the lanes of a tile row `R`), transposed into a [`ChunkBufs`]; in `f32`
//! (see [`lanes_ok`](crate::particle::transfer::deformation_lanes::lanes_ok)).
//!
//! The lanes make the same operations as the scalar pass (separate multiplications and
//! additions, no fused multiply-add; the determinants of [`crate::mat::Mat`]; the dilational
//! Kirchhoff stress of [`crate::particle::dilation::kirchhoff`]), so every particle gets the
//! bits of the scalar pass. The phases, `F_E`, `F_P`, `V⁰` and the moduli come from the pass
//! that the force differential's prepare shares ([`super::super::deformation_lanes`]). If any
//! of the eight particles fails a check of the scalar pass
//! (phase code and material, the checks of [`crate::particle::update::check_particle`], the
//! temperature with heat on, `1/λ` for the explicit dilation), nothing is kept and the caller
//! runs the scalar pass on the eight, which gives each its exact error. A factor that overflows
//! (the `Ready` check) marks only its own particle, which then fails with
//! [`Error::Overflow`] as in the scalar pass.

use super::{momentum0, P2gOp, Ready};
use crate::error::{Error, Result};
use crate::kernel::batch::BatchReal;
use crate::lane::lmat::LMat;
use crate::lane::Lane;
use crate::mat::{Mat, Matrix};
use crate::particle::stencil::Stencil;
use crate::particle::transfer::deformation_lanes::{deformation_lanes, pick};
use crate::particle::transfer::nodes::taint;
use crate::particle::Dilation;
use crate::scalar::Real;

/// The transposed per-particle data of a chunk of at most `L` particles (entry `[c][l]`:
/// component `c` of lane `l`; matrices column-major, `c = i + d·j`).
pub(super) struct ChunkBufs<T, const L: usize> {
    /// `F_E`, the stress kernels' input.
    pub f: [[T; L]; 9],
    /// `μ` (0: no decomposition).
    pub mu: [T; L],
    /// The deviatoric Kirchhoff stress `Â F_Eᵀ` (0 where `μ = 0`).
    pub tau: [[T; L]; 9],
    /// The dilational Kirchhoff stress `λ(J_E − 1)J_E` (0 unless the dilation is explicit).
    pub k: [T; L],
    /// `−V⁰`.
    pub nvol: [T; L],
    /// `−V⁰ τ`.
    pub fm: [[T; L]; 9],
    /// `m C h`.
    pub mch: [[T; L]; 9],
    /// `m v`.
    pub mv: [[T; L]; 3],
    /// `m`.
    pub mass: [T; L],
    /// `m c`, `m c T`, `m κ` (heat on).
    pub heat: [[T; L]; 3],
    /// Lanes whose factors are finite (bit `l` for lane `l`).
    pub finite: u64,
}

impl<T: Real, const L: usize> ChunkBufs<T, L> {
    /// Zeros.
    #[inline(always)]
    pub fn new() -> Self {
        let z = [T::ZERO; L];
        Self {
            f: [z; 9],
            mu: z,
            tau: [z; 9],
            k: z,
            nvol: z,
            fm: [z; 9],
            mch: [z; 9],
            mv: [z; 3],
            mass: z,
            heat: [z; 3],
            finite: 0,
        }
    }

    /// Lane `l` as a particle that runs no decomposition (`F_E = I`, `μ = 0`).
    #[inline(always)]
    pub fn blank_lane<const D: usize>(&mut self, l: usize) {
        for j in 0..D {
            for i in 0..D {
                self.f[i + D * j][l] = if i == j { T::ONE } else { T::ZERO };
            }
        }
        self.mu[l] = T::ZERO;
    }
}

/// `R::LANES` scalars from `p + i`.
///
/// # Safety
/// They are valid for reading.
#[inline(always)]
unsafe fn load<T: Real, R: Lane<Scalar = T>>(p: *const T, i: usize) -> R {
    R::load(core::slice::from_raw_parts(p.add(i), R::LANES))
}

/// `R::LANES` scalars to `b[l0..]`.
#[inline(always)]
fn put<T: Real, R: Lane<Scalar = T>, const L: usize>(b: &mut [T; L], l0: usize, v: R) {
    v.store(&mut b[l0..l0 + R::LANES]);
}

impl<T: BatchReal, const D: usize> P2gOp<'_, T, D>
where
    Mat<T, D>: Matrix<Scalar = T, Vector = [T; D]>,
{
    /// The pass of particles `start..start + R::LANES` into lanes `l0..` of `b`, and their
    /// positions into `xs[l0..]`; returns whether every particle passed (else nothing is
    /// meant to be read from those lanes). Also returns whether any lane has `μ > 0`.
    ///
    /// # Safety
    /// The particle arrays of [`super::p2g`]'s contract hold these particles.
    #[inline(always)]
    pub(super) unsafe fn pre_lanes<R: Lane<Scalar = T>, const L: usize>(
        &self,
        start: usize,
        l0: usize,
        b: &mut ChunkBufs<T, L>,
        xs: &mut [[T; D]],
    ) -> Option<bool> {
        let (ps, m) = (self.ps, self.material);
        let n = R::LANES;
        let zero = R::splat(T::ZERO);
        let d = deformation_lanes::<T, R, D>(ps, m, &self.checked, start)?;

        // The rest of the particle, as `check_particle` checks it.
        let mut x = [zero; D];
        let mut v = [zero; D];
        let mut a = [zero; 9];
        R::load_records(ps.x.add(D * start), D, &mut x);
        R::load_records(ps.v.add(D * start), D, &mut v);
        R::load_records(ps.affine.add(D * D * start), D * D, &mut a[..D * D]);
        let mass: R = load(ps.mass, start);
        let mut ok = d.ok & mass.is_finite() & zero.lt(mass);
        for c in x.iter().chain(&v) {
            ok = ok & c.is_finite();
        }
        for c in a.iter().take(D * D) {
            ok = ok & c.is_finite();
        }
        let temp = if m.heat.is_some() {
            let t: R = load(ps.temperature, start);
            ok = ok & t.is_finite();
            t
        } else {
            zero
        };
        // `dilation::kirchhoff`'s own checks: `1/λ` finite and positive.
        let explicit = m.dilation == Dilation::Explicit;
        if explicit {
            ok = ok & d.inv_lambda.is_finite() & zero.lt(d.inv_lambda);
        }
        if !R::all(ok) {
            return None;
        }

        // The factors of `ready` that do not depend on the stress.
        let one = R::splat(T::ONE);
        let k = if explicit {
            (d.j_e - one) * d.j_e / d.inv_lambda
        } else {
            zero
        };
        let mut fin = k.is_finite();
        let mh = mass * R::splat(self.args.h);
        for c in 0..D * D {
            let y = a[c] * mh;
            fin = fin & y.is_finite();
            put(&mut b.mch[c], l0, y);
            put(&mut b.f[c], l0, d.fe[c]);
        }
        for r in 0..D {
            put(&mut b.mv[r], l0, mass * v[r]);
        }
        if m.heat.is_some() {
            let mc = mass * pick::<T, R>(d.liq, m.solid.heat_capacity, m.liquid.heat_capacity);
            let h = [
                mc,
                mc * temp,
                mass * pick::<T, R>(d.liq, m.solid.conductivity, m.liquid.conductivity),
            ];
            for (c, y) in h.iter().enumerate() {
                fin = fin & y.is_finite();
                put(&mut b.heat[c], l0, *y);
            }
        }
        put(&mut b.mu, l0, d.mu);
        put(&mut b.k, l0, k);
        put(&mut b.nvol, l0, -d.vol);
        put(&mut b.mass, l0, mass);
        let all = (1u64 << n) - 1;
        b.finite = b.finite & !(all << l0) | R::mask_bits(fin) << l0;
        R::store_records(xs.as_mut_ptr().add(l0) as *mut T, D, &x);
        Some(R::any(zero.lt(d.mu)))
    }

    /// The node loop inputs of lane `l` of `b` (its pass ran on lanes; `fm` and its check set
    /// by [`fm_lanes`]), for its stencil `s`: [`Self::ready`]'s values and errors.
    #[inline(always)]
    pub(super) fn ready_lane<'s, const L: usize>(
        &self,
        b: &ChunkBufs<T, L>,
        l: usize,
        s: &'s Stencil<T, D>,
    ) -> Result<Ready<'s, T, D>> {
        let mut fm = Mat::<T, D>::ZERO;
        let mut mch = Mat::<T, D>::ZERO;
        for j in 0..D {
            for i in 0..D {
                fm.cols[j][i] = b.fm[i + D * j][l];
                mch.cols[j][i] = b.mch[i + D * j][l];
            }
        }
        let mut mv = [T::ZERO; D];
        for (r, m) in mv.iter_mut().enumerate() {
            *m = b.mv[r][l];
        }
        let q0 = momentum0(&mv, &mch, &s.fx);
        let mut chk = b.finite >> l & 1 == 1;
        for x in q0 {
            taint(&mut chk, x);
        }
        let heat = [b.heat[0][l], b.heat[1][l], b.heat[2][l]];
        if !chk {
            return Err(Error::Overflow);
        }
        Ok(Ready {
            s,
            q0,
            mch,
            fm,
            mass: b.mass[l],
            heat,
        })
    }
}

/// `fm = −V⁰ (τ_dev + k I)` on the lanes `..lanes` of `b` from `tau` (the deviatoric stress
/// on lanes), as [`P2gOp::ready`] forms it: the diagonal sum (only when the dilation is
/// `explicit`), then the product; a lane whose `fm` is not finite is cleared in `b.finite`
/// (a finite stress times a finite `−V⁰` can still overflow).
#[inline(always)]
pub(super) fn fm_lanes<T: Real, V: Lane<Scalar = T>, const D: usize, const L: usize>(
    b: &mut ChunkBufs<T, L>,
    tau: &LMat<V, D>,
    explicit: bool,
    lanes: usize,
) {
    let nv = V::load(&b.nvol[..lanes]);
    let k = V::load(&b.k[..lanes]);
    let mut fin = nv.is_finite();
    for j in 0..D {
        for i in 0..D {
            let mut t = tau[j][i];
            if explicit && i == j {
                t += k;
            }
            let y = t * nv;
            fin = fin & y.is_finite();
            y.store(&mut b.fm[i + D * j][..lanes]);
        }
    }
    b.finite &= V::mask_bits(fin);
}
