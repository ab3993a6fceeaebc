//! G2P's particle update for a chunk of particles on SIMD lanes (one particle per lane), for the
//! plain elastic update: no heat, no plasticity, every particle of the chunk solid.
//!
//! The update is that of [`crate::particle::update::update_particle`] for these materials
//! (Stomakhin et al. 2014, §5: APIC velocity and affine matrix, `x ← x + Δt v`,
//! `F_E ← (I + Δt∇v) F_E`, `F_P` kept), with the same operations in the same order (separate
//! multiplications and additions, no fused multiply-add, the matrix products and determinants of
//! [`crate::mat::Mat`]), so every lane gets the bits of the scalar update. Every check of the
//! scalar path is made on all lanes (the input particle as [`check_particle`] checks it, the new
//! position, `det(I + Δt∇v) > 0`, the new `F_E` and its determinant, the position limit); if any
//! lane fails one, or needs the remedy for `det(I + Δt∇v) ≤ 0`, nothing is written and the
//! caller updates the chunk's particles one by one, which gives each its exact status.
//!
//! [`check_particle`]: crate::particle::update::check_particle

use super::Particles;
use crate::lane::lmat::{self, LMat};
use crate::lane::Lane;
use crate::particle::update::G2pSample;
use crate::particle::{Material, Phase};
use crate::scalar::Real;

/// Particles per chunk: the eight lanes of the row types.
pub(super) const LANES: usize = 8;
/// Largest dimension.
const MAX_D: usize = 3;

/// The grid samples of a chunk, transposed: entry `[c][l]` is component `c` of lane `l`
/// (vectors by component, matrices column-major, `c = i + d·j`).
#[derive(Clone, Copy)]
pub(super) struct ChunkSamples<T> {
    v: [[T; LANES]; MAX_D],
    affine: [[T; LANES]; MAX_D * MAX_D],
    grad_v: [[T; LANES]; MAX_D * MAX_D],
}

impl<T: Real> ChunkSamples<T> {
    /// Zeros.
    #[inline(always)]
    pub(super) fn new() -> Self {
        Self {
            v: [[T::ZERO; LANES]; MAX_D],
            affine: [[T::ZERO; LANES]; MAX_D * MAX_D],
            grad_v: [[T::ZERO; LANES]; MAX_D * MAX_D],
        }
    }

    /// Sets lane `l` to `s`.
    #[inline(always)]
    pub(super) fn set<const D: usize>(&mut self, l: usize, s: &G2pSample<T, D>) {
        for a in 0..D {
            self.v[a][l] = s.v[a];
        }
        for j in 0..D {
            for i in 0..D {
                self.affine[i + D * j][l] = s.affine.cols[j][i];
                self.grad_v[i + D * j][l] = s.grad_v.cols[j][i];
            }
        }
    }
}

/// Whether a material's update is the plain elastic one that [`update`] runs.
#[inline(always)]
pub(super) fn plain<T: Real>(material: &Material<T>) -> bool {
    material.heat.is_none() && material.plasticity.is_none()
}

/// A `D × D` matrix of lanes from particle matrices at `p` (`d²` scalars per particle,
/// column-major), particles `start..start + LANES`.
///
/// # Safety
/// The particles are in the array.
#[inline(always)]
unsafe fn gather_mat<T: Real, V: Lane<Scalar = T>, const D: usize>(
    p: *const T,
    start: usize,
) -> LMat<V, D> {
    let mut m = lmat::zero::<V, D>();
    for j in 0..D {
        for i in 0..D {
            m[j][i] = V::gather(p.add(D * D * start + i + D * j), D * D);
        }
    }
    m
}

/// Whether the `len` scalars at `p` (a multiple of the lanes) are all finite.
///
/// # Safety
/// `p` is valid for `len` scalars.
#[inline(always)]
unsafe fn finite_run<T: Real, V: Lane<Scalar = T>>(p: *const T, len: usize) -> bool {
    let s = core::slice::from_raw_parts(p, len);
    let mut ok = true;
    for c in s.chunks_exact(V::LANES) {
        ok &= V::all(V::load(c).is_finite());
    }
    ok
}

/// `m · s` entry by entry.
#[inline(always)]
fn scaled<V: Lane, const D: usize>(m: &LMat<V, D>, s: V) -> LMat<V, D> {
    let mut r = *m;
    for c in r.iter_mut() {
        for x in c.iter_mut() {
            *x = *x * s;
        }
    }
    r
}

/// `a · b` in the order of [`crate::mat::Mat`]'s product: `Σ_k a_ik b_kj` summed from 0 up,
/// starting from zero, multiplications and additions separate.
#[inline(always)]
fn product<V: Lane, const D: usize>(a: &LMat<V, D>, b: &LMat<V, D>) -> LMat<V, D> {
    let mut m = lmat::zero::<V, D>();
    for j in 0..D {
        for k in 0..D {
            let bk = b[j][k];
            for i in 0..D {
                m[j][i] += a[k][i] * bk;
            }
        }
    }
    m
}

/// Updates particles `start..start + LANES` from their transposed samples `cs` (each sample
/// was computed without error) with step `dt` on a collocated grid of spacing `h`, if every
/// lane passes every check of the scalar update (see the module docs); returns whether it did.
/// Writes `x, v, affine, f_e` (`f_p` is kept and not written).
///
/// # Safety
/// The arrays of `ps` hold the chunk's particles; `plain(material)`.
#[inline(always)]
pub(super) unsafe fn update<T: Real, V: Lane<Scalar = T>, const D: usize>(
    material: &Material<T>,
    solid_ok: bool,
    dt: T,
    h: T,
    ps: &Particles<T>,
    start: usize,
    cs: &ChunkSamples<T>,
) -> bool {
    debug_assert!(V::LANES == LANES && plain(material) && D <= MAX_D);
    let inv_h = T::ONE / h;
    if !(solid_ok && dt.is_finite() && dt > T::ZERO && h.is_finite() && h > T::ZERO)
        || !inv_h.is_finite()
    {
        return false;
    }
    if !ps.phase.is_null() {
        let ph = core::slice::from_raw_parts(ps.phase.add(start), LANES);
        if ph.iter().any(|&c| c != Phase::Solid as u8) {
            return false;
        }
    }
    // The input particles, as `check_particle` checks them: v and the affine matrix are only
    // checked (they are replaced), and checked where they lie.
    if !(finite_run::<T, V>(ps.v.add(D * start), D * LANES)
        && finite_run::<T, V>(ps.affine.add(D * D * start), D * D * LANES))
    {
        return false;
    }
    let zero = V::splat(T::ZERO);
    let mut x = [zero; D];
    for (a, xa) in x.iter_mut().enumerate() {
        *xa = V::gather(ps.x.add(D * start + a), D);
    }
    let f_e = gather_mat::<T, V, D>(ps.f_e, start);
    let f_p = gather_mat::<T, V, D>(ps.f_p, start);
    let mass = V::load(core::slice::from_raw_parts(ps.mass.add(start), LANES));
    let vol = V::load(core::slice::from_raw_parts(ps.volume0.add(start), LANES));
    let mut ok = lmat::all_finite(&f_e) & lmat::all_finite(&f_p);
    ok = ok & mass.is_finite() & vol.is_finite() & zero.lt(mass) & zero.lt(vol);
    for xa in &x {
        ok = ok & xa.is_finite();
    }
    let (j_e, j_p) = (lmat::det(&f_e), lmat::det(&f_p));
    ok = ok & j_e.is_finite() & j_p.is_finite() & zero.lt(j_e) & zero.lt(j_p);

    // The sample (finite: the sample stage checked it).
    let dtv = V::splat(dt);
    let mut sv = [zero; D];
    let mut g = lmat::zero::<V, D>();
    for a in 0..D {
        sv[a] = V::load(&cs.v[a]);
    }
    for j in 0..D {
        for i in 0..D {
            g[j][i] = V::load(&cs.grad_v[i + D * j]);
        }
    }
    // x ← x + Δt v, then the position limit |x/h| < 2³⁰ of the stencil.
    let lim = V::splat(T::from_f64(1_073_741_824.0));
    let mut xn = [zero; D];
    for a in 0..D {
        xn[a] = x[a] + dtv * sv[a];
        let xi = xn[a] * V::splat(inv_h);
        ok = ok & xn[a].is_finite() & xi.is_finite() & xi.abs().lt(lim);
    }
    // The increment I + Δt∇v without the remedy: det > 0 required.
    let l = scaled(&g, dtv);
    ok = ok & lmat::all_finite(&l);
    let mut inc = l;
    for (j, c) in inc.iter_mut().enumerate() {
        for (i, x) in c.iter_mut().enumerate() {
            *x = V::splat(if i == j { T::ONE } else { T::ZERO }) + *x;
        }
    }
    ok = ok & zero.lt(lmat::det(&inc));
    // F_E ← A F_E, finite with a finite positive determinant (`check_det`).
    let f = product(&inc, &f_e);
    let j_new = lmat::det(&f);
    ok = ok & lmat::all_finite(&f) & j_new.is_finite() & zero.lt(j_new);
    if !V::all(ok) {
        return false;
    }

    let all = (1u32 << LANES) - 1;
    for a in 0..D {
        xn[a].scatter(ps.x.add(D * start + a), D, all);
        sv[a].scatter(ps.v.add(D * start + a), D, all);
    }
    for j in 0..D {
        for i in 0..D {
            let c = i + D * j;
            V::load(&cs.affine[c]).scatter(ps.affine.add(D * D * start + c), D * D, all);
            f[j][i].scatter(ps.f_e.add(D * D * start + c), D * D, all);
        }
    }
    true
}
