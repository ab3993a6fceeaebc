//! G2P's particle update for a chunk of particles on SIMD lanes (one particle per lane): solids,
//! with or without snow plasticity, and liquids (solids and liquids may share a chunk).
//!
//! The update is that of [`crate::particle::update::update_particle`] for these particles
//! (Stomakhin et al. 2014, §5: APIC velocity and affine matrix, `x ← x + Δt v`,
//! `F_E ← (I + Δt∇v) F_E`; an elastic solid keeps `F_P`, a snow solid clamps both by
//! [`snow_lanes`], a liquid's isotropic `F_E` takes the root of `det(I + Δt∇v)` and its `F_P` is
//! projected to its volume ratio by [`liquid_step`]), with the same operations in the same order
//! (separate multiplications and additions, no fused multiply-add, the matrix products and
//! determinants of [`crate::mat::Mat`], the power-of-two scalings and roots of [`root_det`]), so
//! every lane gets the bits of the scalar update. The snow step is written once, on lanes (with
//! the fused multiply-adds and Newton roots of the lane type): G2P's batch takes it on lanes of
//! its row type for a particle updated on its own too ([`snow_plasticity_on`], the particle in
//! every lane), so both paths give the same bits. With
//! heat, the heat step (temperature, latent buffer, phase) is made on the lanes when every lane
//! stays in its segment of the latent-heat model, else by the scalar [`thermal::step`] per lane
//! ([`heat`]). Every check of the scalar path is made on all lanes (the input particle as
//! [`check_particle`] checks it, the new position, `det(I + Δt∇v) > 0`, the new `F_E` and `F_P`
//! and their determinants, the position limit); if any lane fails one, needs the remedy for
//! `det(I + Δt∇v) ≤ 0`, lies where [`root_det`]'s scalings leave the normal range, or is a
//! liquid whose `F_E` is not isotropic (a solid that has just melted) or whose
//! `det(I + Δt∇v)` is not normal, nothing is written and the caller updates the chunk's
//! particles one by one, which gives each its exact status.
//!
//! [`check_particle`]: crate::particle::update::check_particle
//! [`thermal::step`]: crate::particle::thermal::step
//! [`liquid_step`]: crate::particle::deformation::liquid_step
//! [`root_det`]: crate::particle::deformation::root_det
//! [`snow_lanes`]: crate::particle::deformation::snow_lanes
//! [`snow_plasticity_on`]: crate::particle::deformation::snow_plasticity_on

mod heat;

use super::{rd, wr, Checked, Particles};
use crate::kernel::select_mat;
use crate::lane::lmat::{self, LMat};
use crate::lane::Lane;
use crate::particle::deformation::{snow_bounds, snow_lanes};
use crate::particle::thermal::ThermalState;
use crate::particle::update::G2pSample;
use crate::particle::{Material, Phase, Snow};
use crate::scalar::Real;

/// Particles per chunk: the eight lanes of the row types.
pub(super) const LANES: usize = 8;
/// Largest dimension.
const MAX_D: usize = 3;

/// The grid samples of a chunk, transposed: entry `[c][l]` is component `c` of lane `l`
/// (vectors by component, matrices column-major, `c = i + d·j`).
#[derive(Clone, Copy)]
pub(super) struct ChunkSamples<T> {
    /// `v_p` by component.
    pub(super) v: [[T; LANES]; MAX_D],
    /// `C_p`, column-major.
    pub(super) affine: [[T; LANES]; MAX_D * MAX_D],
    /// `∇v_p`, column-major.
    pub(super) grad_v: [[T; LANES]; MAX_D * MAX_D],
    /// `T_pic`.
    pub(super) t_pic: [T; LANES],
    /// `ΔT_flip`.
    pub(super) t_flip: [T; LANES],
}

impl<T: Real> ChunkSamples<T> {
    /// Zeros.
    #[inline(always)]
    pub(super) fn new() -> Self {
        Self {
            v: [[T::ZERO; LANES]; MAX_D],
            affine: [[T::ZERO; LANES]; MAX_D * MAX_D],
            grad_v: [[T::ZERO; LANES]; MAX_D * MAX_D],
            t_pic: [T::ZERO; LANES],
            t_flip: [T::ZERO; LANES],
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
        self.t_pic[l] = s.t_pic;
        self.t_flip[l] = s.t_flip;
    }

    /// Lane `l` (the inverse of [`ChunkSamples::set`]).
    #[inline(always)]
    pub(super) fn get<const D: usize>(&self, l: usize) -> G2pSample<T, D> {
        let mut s = G2pSample {
            v: [T::ZERO; D],
            affine: crate::mat::Mat::ZERO,
            grad_v: crate::mat::Mat::ZERO,
            t_pic: self.t_pic[l],
            t_flip: self.t_flip[l],
        };
        for a in 0..D {
            s.v[a] = self.v[a][l];
        }
        for j in 0..D {
            for i in 0..D {
                s.affine.cols[j][i] = self.affine[i + D * j][l];
                s.grad_v.cols[j][i] = self.grad_v[i + D * j][l];
            }
        }
        s
    }
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
    let z = V::splat(T::ZERO);
    let mut e = [z; MAX_D * MAX_D];
    V::load_records(p.add(D * D * start), D * D, &mut e[..D * D]);
    let mut m = lmat::zero::<V, D>();
    for j in 0..D {
        for i in 0..D {
            m[j][i] = e[i + D * j];
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
            *x *= s;
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

/// The phase of each particle of the chunk at `start` (solid when `phase` is null), or `None`
/// if a code is invalid or the material is not valid for a lane's phase (`checked`).
///
/// # Safety
/// `phase` is null or holds the chunk's particles.
#[inline(always)]
unsafe fn chunk_phases(
    phase: *const u8,
    start: usize,
    checked: &Checked,
) -> Option<[Phase; LANES]> {
    let mut out = [Phase::Solid; LANES];
    for (l, p) in out.iter_mut().enumerate() {
        if !phase.is_null() {
            *p = Phase::from_code(rd(phase, start + l)).ok()?;
        }
        checked.for_phase(*p).ok()?;
    }
    Some(out)
}

/// `(det M)^{1/d}` per lane with the bits of [`root_det`] (column equilibration by powers of
/// two, `det M = det M̂ · 2ᵉ`, `e = d q + ρ`, root `(det M̂ · 2^ρ)^{1/d} · 2^q`), and the lanes
/// where it is that root: finite `M` whose column maxima are normal and below `2^{bias−1}`
/// (so every scaling is one multiplication by a normal power of two, as `scalbn` does it in that
/// range), `det M̂ > 0`, and a finite positive root. The square root is correctly rounded on
/// every path; the cube root has the bits of the scalar [`Real::cbrt`] ([`Lane::cbrt`]).
///
/// [`root_det`]: crate::particle::deformation::root_det
#[inline(always)]
fn root_det<T: Real, V: Lane<Scalar = T>, const D: usize>(m: &LMat<V, D>) -> (V, V::Mask) {
    let zero = V::splat(T::ZERO);
    let e_max = V::splat(T::from_i32(T::MAX_EXP - 2));
    let mut ok = lmat::all_finite(m);
    let mut g = *m;
    let mut e = zero;
    for j in 0..D {
        // As `det_equilibrated`: the column maximum from 0, its frexp exponent, `x · 2^{−e_j}`.
        let mut c = zero;
        for i in 0..D {
            c = c.max(m[j][i].abs());
        }
        let ej = c.exponent();
        let col_ok = V::splat(T::MIN_POSITIVE).le(c) & ej.le(e_max);
        ok = ok & col_ok;
        let ej = V::select(col_ok, ej, zero);
        let p = V::pow2(-ej);
        for x in g[j].iter_mut() {
            *x *= p;
        }
        e += ej;
    }
    let det = lmat::det(&g);
    ok = ok & zero.lt(det);
    // `e.div_euclid(d)`: `e / d` is within half an ulp of `q + ρ/d`, never across an integer.
    let d = V::splat(T::from_i32(D as i32));
    let q = (e / d).floor();
    let rho = e - d * q;
    let y = det * V::pow2(rho);
    let root = if D == 2 { y.sqrt() } else { y.cbrt() };
    // |q| ≤ bias − 1 by the column bounds: one multiplication, as `scalbn`.
    let r = root * V::pow2(q);
    (r, ok & r.is_finite() & zero.lt(r))
}

/// Snow plasticity of a chunk's solids ([`snow_lanes`], the bits of [`snow_plasticity_on`]
/// with this lane type) from their `A F_E` (`f`) and `F_P`: the new `(F_E, F_P)` and the lanes
/// where the scalar update accepts them: positive singular values, both results passing
/// [`check_det`], and the hardened moduli at the new `J_P` finite ([`Material::moduli`], which
/// the next entry checks; by one scalar call per solid lane). Liquid lanes (`liquid_flags`
/// nonzero) are not checked.
///
/// [`snow_plasticity_on`]: crate::particle::deformation::snow_plasticity_on
/// [`check_det`]: crate::particle::deformation::check_det
#[inline(always)]
fn snow<T: Real, V: Lane<Scalar = T>, const D: usize>(
    material: &Material<T>,
    sn: &Snow<T>,
    f: &LMat<V, D>,
    f_p: &LMat<V, D>,
    liquid_flags: &[T; LANES],
) -> (LMat<V, D>, LMat<V, D>, V::Mask) {
    let out = snow_lanes(snow_bounds(sn).map(V::splat), f, f_p);
    let mut ok = out.positive & det_ok(&out.f_e) & det_ok(&out.f_p);
    if sn.hardening != T::ZERO {
        let mut j_p = [T::ZERO; LANES];
        lmat::det(&out.f_p).store(&mut j_p);
        let mut hard = [T::ZERO; LANES];
        for ((h, &j), &fl) in hard.iter_mut().zip(&j_p).zip(liquid_flags) {
            if fl == T::ZERO && material.moduli(Phase::Solid, j).is_ok() {
                *h = T::ONE;
            }
        }
        ok = ok & V::splat(T::ZERO).lt(V::load(&hard));
    }
    (out.f_e, out.f_p, ok)
}

/// `s I`.
#[inline(always)]
fn diagonal<V: Lane, const D: usize>(s: V) -> LMat<V, D> {
    let mut m = lmat::zero::<V, D>();
    for (j, c) in m.iter_mut().enumerate() {
        c[j] = s;
    }
    m
}

/// Finite entries and a finite positive determinant ([`check_det`] and [`check_particle`]
/// accept it).
///
/// [`check_det`]: crate::particle::deformation::check_det
/// [`check_particle`]: crate::particle::update::check_particle
#[inline(always)]
fn det_ok<V: Lane, const D: usize>(m: &LMat<V, D>) -> V::Mask {
    let j = lmat::det(m);
    lmat::all_finite(m) & j.is_finite() & V::splat(V::Scalar::ZERO).lt(j)
}

/// [`liquid_step`] per lane for `F_E = s I`: `(s (det A)^{1/d} I, F_P')` from `det A` (`det_a`,
/// the increment's computed determinant) with `F_P' = F_P` where `F_P = s I`, `s > 0` exactly
/// or where `liq` is false (a solid keeps its `F_P`), else `J_P^{1/d} I` (`None`: `F_P` kept on
/// every lane), and the lanes where both are the scalar results and pass [`check_det`]
/// (`F_P`'s own determinant is checked by the caller). A liquid lane whose `F_E` is not
/// isotropic (a solid that has just melted) or whose `det A` is not a normal number is not
/// among them: the scalar step multiplies out or equilibrates there.
///
/// [`liquid_step`]: crate::particle::deformation::liquid_step
/// [`check_det`]: crate::particle::deformation::check_det
#[inline(always)]
fn liquid<T: Real, V: Lane<Scalar = T>, const D: usize>(
    f_e: &LMat<V, D>,
    det_a: V,
    f_p: &LMat<V, D>,
    liq: V::Mask,
) -> (LMat<V, D>, Option<LMat<V, D>>, V::Mask) {
    let zero = V::splat(T::ZERO);
    let root = if D == 2 { det_a.sqrt() } else { det_a.cbrt() };
    let r = f_e[0][0] * root;
    let fe = diagonal::<V, D>(r);
    let normal = V::splat(T::MIN_POSITIVE).le(det_a) & det_a.is_finite();
    let mut ok = isotropic_mask(f_e) & normal & r.is_finite() & zero.lt(r) & det_ok(&fe);
    let keep = isotropic_mask(f_p) | !liq;
    if V::all(keep) {
        return (fe, None, ok);
    }
    let (r_p, ok_p) = root_det(f_p);
    let fp = select_mat(keep, f_p, &diagonal::<V, D>(r_p));
    ok = ok & (keep | (ok_p & det_ok(&fp)));
    (fe, Some(fp), ok)
}

/// The lanes where `m = s I` with `s > 0` exactly, as [`isotropic_scale`] and a positive
/// scale: off-diagonal entries 0, diagonal entries equal to `m[0][0] > 0`.
///
/// [`isotropic_scale`]: crate::particle::deformation::isotropic_scale
#[inline(always)]
fn isotropic_mask<T: Real, V: Lane<Scalar = T>, const D: usize>(m: &LMat<V, D>) -> V::Mask {
    let zero = V::splat(T::ZERO);
    let s = m[0][0];
    let mut iso = zero.lt(s);
    for (j, c) in m.iter().enumerate() {
        for (i, x) in c.iter().enumerate() {
            iso = iso & x.eq(if i == j { s } else { zero });
        }
    }
    iso
}

/// Updates particles `start..start + LANES` from their transposed samples `cs` (each sample
/// was computed without error) with step `dt` on a collocated grid of spacing `h`, if every
/// lane passes every check of the scalar update (see the module docs); returns whether it did.
/// Writes `x, v, affine, f_e`, `f_p` where a liquid's or a snow solid's changes, and with heat
/// the temperature (with phase change also the latent buffer and the phase).
///
/// # Safety
/// The arrays of `ps` that the update reads and writes hold the chunk's particles.
#[inline(always)]
pub(super) unsafe fn update<T: Real, V: Lane<Scalar = T>, const D: usize>(
    material: &Material<T>,
    checked: &Checked,
    dt: T,
    h: T,
    ps: &Particles<T>,
    start: usize,
    cs: &ChunkSamples<T>,
) -> bool {
    debug_assert!(V::LANES == LANES && D <= MAX_D);
    let inv_h = T::ONE / h;
    if !(dt.is_finite() && dt > T::ZERO && h.is_finite() && h > T::ZERO && inv_h.is_finite()) {
        return false;
    }
    let mut heat_new = [ThermalState {
        temperature: T::ZERO,
        latent: T::ZERO,
        phase: Phase::Solid,
    }; LANES];
    // The phase of each lane after its heat step (the phase of the update's step 4).
    let phases = match &material.heat {
        None => match chunk_phases(ps.phase, start, checked) {
            Some(p) => p,
            None => return false,
        },
        Some(heat) => {
            let chunk = heat::HeatChunk {
                material,
                checked,
                ps,
                start,
                cs,
                heat,
            };
            if !heat::step::<T, V>(&chunk, &mut heat_new) {
                return false;
            }
            heat_new.map(|st| st.phase)
        }
    };
    let mut liquid_flags = [T::ZERO; LANES];
    for (fl, p) in liquid_flags.iter_mut().zip(&phases) {
        if *p == Phase::Liquid {
            *fl = T::ONE;
        }
    }
    let any_liquid = phases.contains(&Phase::Liquid);
    // The input particles, as `check_particle` checks them: v and the affine matrix are only
    // checked (they are replaced), and checked where they lie.
    if !(finite_run::<T, V>(ps.v.add(D * start), D * LANES)
        && finite_run::<T, V>(ps.affine.add(D * D * start), D * D * LANES))
    {
        return false;
    }
    let zero = V::splat(T::ZERO);
    let mut x = [zero; D];
    V::load_records(ps.x.add(D * start), D, &mut x);
    let f_e = gather_mat::<T, V, D>(ps.f_e, start);
    let f_p = gather_mat::<T, V, D>(ps.f_p, start);
    let mass = V::load(core::slice::from_raw_parts(ps.mass.add(start), LANES));
    let vol = V::load(core::slice::from_raw_parts(ps.volume0.add(start), LANES));
    // `F_E`, `F_P` finite with finite positive determinants, as `check_particle` requires.
    let mut ok = det_ok(&f_e) & det_ok(&f_p);
    ok = ok & mass.is_finite() & vol.is_finite() & zero.lt(mass) & zero.lt(vol);
    for xa in &x {
        ok = ok & xa.is_finite();
    }

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
    let det_a = lmat::det(&inc);
    ok = ok & zero.lt(det_a);
    // A solid: F_E ← A F_E, finite with a finite positive determinant (`check_det`); without
    // plasticity it keeps `F_P`, with snow plasticity both are clamped (`snow`). A liquid keeps
    // its volume ratios only, from `det A` (`liquid_step`). In a chunk of both, every lane
    // computes both and takes its own (the other's checks do not apply); a chunk of liquids
    // alone forms no product.
    let liq = zero.lt(V::load(&liquid_flags));
    let all_liquid = any_liquid && V::all(liq);
    let (f, snow_fp) = if all_liquid {
        (f_e, None) // not read: every lane takes the liquid's F_E below
    } else {
        let f = product(&inc, &f_e);
        ok = ok & (det_ok(&f) | liq);
        match &material.plasticity {
            Some(sn) => {
                let (fe, fp, snow_ok) = snow(material, sn, &f, &f_p, &liquid_flags);
                ok = ok & (snow_ok | liq);
                (fe, Some(fp))
            }
            None => (f, None),
        }
    };
    let (f, f_p_new) = if any_liquid {
        // The solid lanes' `F_P` is selected inside `liquid`, not by `Option::map` here: a
        // closure is not compiled with the caller's target features.
        let (fe, fp, proj_ok) = liquid(&f_e, det_a, &f_p, liq);
        ok = ok & (proj_ok | !liq);
        let f = if all_liquid {
            fe
        } else {
            select_mat(liq, &fe, &f)
        };
        // Snow solids beside liquids: each lane its own `F_P`.
        let fp = match snow_fp {
            Some(sf) => Some(select_mat(liq, &fp.unwrap_or(f_p), &sf)),
            None => fp,
        };
        (f, fp)
    } else {
        (f, snow_fp)
    };
    if !V::all(ok) {
        return false;
    }

    if let Some(heat) = &material.heat {
        for (l, st) in heat_new.iter().enumerate() {
            wr(ps.temperature, start + l, st.temperature);
            if heat.phase_change {
                wr(ps.latent, start + l, st.latent);
                wr(ps.phase, start + l, st.phase as u8);
            }
        }
    }
    store_records::<T, V>(ps.x.add(D * start), D, &xn);
    store_records::<T, V>(ps.v.add(D * start), D, &sv);
    let mut flat = [zero; MAX_D * MAX_D];
    for (c, e) in flat.iter_mut().enumerate().take(D * D) {
        *e = V::load(&cs.affine[c]);
    }
    store_records::<T, V>(ps.affine.add(D * D * start), D * D, &flat[..D * D]);
    store_mat(ps.f_e, start, &f);
    if let Some(fp) = &f_p_new {
        store_mat(ps.f_p, start, fp);
    }
    true
}

/// The inverse of [`gather_mat`]: writes `m` to the particle matrices at `p` (column-major),
/// particles `start..start + LANES`.
///
/// # Safety
/// The particles are in the array.
#[inline(always)]
unsafe fn store_mat<T: Real, V: Lane<Scalar = T>, const D: usize>(
    p: *mut T,
    start: usize,
    m: &LMat<V, D>,
) {
    let mut e = [V::splat(T::ZERO); MAX_D * MAX_D];
    for j in 0..D {
        for i in 0..D {
            e[i + D * j] = m[j][i];
        }
    }
    store_records::<T, V>(p.add(D * D * start), D * D, &e[..D * D]);
}

/// Writes `vals[c]` lane `l` to `base[l·rec + c]`: in `f32` as whole records transposed in
/// registers ([`Lane::store_records`]); in `f64` by one strided store per component, which
/// measured faster there (3D f64 fluid G2P 157 ns against 172 with record stores, AVX-512).
/// The `f64` row types are lane pairs ([`crate::lane::X2`]), whose record stores go through
/// two 32-entry buffers per call; whether those buffers are the whole cost is not measured.
///
/// # Safety
/// Every such address is valid for writing.
#[inline(always)]
unsafe fn store_records<T: Real, V: Lane<Scalar = T>>(base: *mut T, rec: usize, vals: &[V]) {
    if core::mem::size_of::<T>() == 4 {
        V::store_records(base, rec, vals);
    } else {
        let all = (1u32 << LANES) - 1;
        for (c, v) in vals.iter().enumerate() {
            v.scatter(base.add(c), rec, all);
        }
    }
}
