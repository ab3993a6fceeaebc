//! The reads and checks that P2G's and the force differential's per-particle passes share, for
//! eight consecutive particles at once (the lanes of a row type `R`): the phases and the
//! material's validity for each, `F_E`, `F_P` and `V⁰` with the checks of
//! [`crate::particle::update::check_particle`] on them, `J_E` and the moduli (hardened at
//! `J_P` where the plasticity hardens). In `f32`, whose eight-lane type loads the particle
//! records by in-register transposes.
//!
//! The lanes make the operations of the scalar pass (the determinants of [`crate::mat::Mat`],
//! [`crate::particle::Material::moduli`] per lane), so every value has the scalar pass's bits.
//! Where a particle fails a check, the caller runs the scalar pass on the eight, which gives
//! each its exact error.

use super::update_lanes::LANES;
use super::{rd, Checked, Particles};
use crate::lane::lmat::{self, LMat};
use crate::lane::Lane;
use crate::particle::{Material, Phase};
use crate::scalar::Real;

/// Whether a call's particles take the passes on lanes: in `f32`, whose eight-lane type loads
/// records by in-register transposes (the `f64` row types gather each component, and on AMD
/// Zen 4 that made 3D `f64` P2G 20–40 ns per particle slower than the scalar pass).
#[inline(always)]
pub(super) fn lanes_ok<T>() -> bool {
    size_of::<T>() == 4
}

/// The deformation of eight particles on lanes ([`deformation_lanes`]).
pub(super) struct DeformationLanes<R: Lane> {
    /// `F_E`, entry `i + d·j` row `i`, column `j` (entries `d²..` unused).
    pub fe: [R; 9],
    /// `J_E = det F_E`.
    pub j_e: R,
    /// `V⁰`.
    pub vol: R,
    /// `μ` at each lane's phase (and `J_P`).
    pub mu: R,
    /// `1/λ` at each lane's phase (and `J_P`).
    pub inv_lambda: R,
    /// The liquid lanes.
    pub liq: R::Mask,
    /// The lanes whose `F_E`, `F_P` and `V⁰` pass `check_particle`: finite entries, `V⁰ > 0`,
    /// finite positive determinants.
    pub ok: R::Mask,
}

/// The [`DeformationLanes`] of particles `start..start + R::LANES` of `ps`; `None` if a phase
/// code is invalid, the material refuses a phase present, or a hardened modulus does not exist
/// (the scalar pass reports each).
///
/// # Safety
/// The arrays `f_e`, `f_p`, `volume0` (and `phase` if not null) hold these particles.
#[inline(always)]
pub(super) unsafe fn deformation_lanes<T: Real, R: Lane<Scalar = T>, const D: usize>(
    ps: &Particles<T>,
    m: &Material<T>,
    checked: &Checked,
    start: usize,
) -> Option<DeformationLanes<R>> {
    let n = R::LANES;
    debug_assert!(n == LANES);
    let zero = R::splat(T::ZERO);
    // Phases (solid when `phase` is null) and the material's validity for each.
    let mut liq = [T::ZERO; LANES];
    let (mut solids, mut liquids) = (ps.phase.is_null(), false);
    if !ps.phase.is_null() {
        for (l, f) in liq.iter_mut().enumerate().take(n) {
            match Phase::from_code(rd(ps.phase as *const u8, start + l)).ok()? {
                Phase::Solid => solids = true,
                Phase::Liquid => {
                    liquids = true;
                    *f = T::ONE;
                }
            }
        }
    }
    if (solids && checked.for_phase(Phase::Solid).is_err())
        || (liquids && checked.for_phase(Phase::Liquid).is_err())
    {
        return None;
    }
    let liq_flags = liq;
    let liq = zero.lt(R::load(&liq_flags[..n]));

    let mut fe = [zero; 9];
    let mut fp = [zero; 9];
    R::load_records(ps.f_e.add(D * D * start), D * D, &mut fe[..D * D]);
    R::load_records(ps.f_p.add(D * D * start), D * D, &mut fp[..D * D]);
    let vol = R::load(core::slice::from_raw_parts(ps.volume0.add(start), n));
    let mut ok = vol.is_finite();
    for c in 0..D * D {
        ok = ok & fe[c].is_finite() & fp[c].is_finite();
    }
    ok = ok & zero.lt(vol);
    let (j_e, j_p) = (
        lmat::det(&lmat_of::<R, D>(&fe)),
        lmat::det(&lmat_of::<R, D>(&fp)),
    );
    ok = ok & j_e.is_finite() & j_p.is_finite() & zero.lt(j_e) & zero.lt(j_p);
    let (mu, inv_lambda) = if matches!(&m.plasticity, Some(s) if s.hardening != T::ZERO) {
        // Hardened moduli at each lane's `J_P` (`Material::moduli`, one scalar call per
        // lane); where they do not exist the scalar pass reports it.
        let mut jp = [T::ZERO; LANES];
        j_p.store(&mut jp[..n]);
        let (mut mus, mut ils) = ([T::ZERO; LANES], [T::ZERO; LANES]);
        for l in 0..n {
            let phase = match liq_flags[l] == T::ZERO {
                true => Phase::Solid,
                false => Phase::Liquid,
            };
            let md = m.moduli(phase, jp[l]).ok()?;
            (mus[l], ils[l]) = (md.mu, md.inv_lambda);
        }
        (R::load(&mus[..n]), R::load(&ils[..n]))
    } else {
        (
            pick::<T, R>(liq, m.solid.mu, m.liquid.mu),
            pick::<T, R>(liq, m.solid.inv_lambda, m.liquid.inv_lambda),
        )
    };
    Some(DeformationLanes {
        fe,
        j_e,
        vol,
        mu,
        inv_lambda,
        liq,
        ok,
    })
}

/// `s` on the lanes of `liq` false, `l` on the others (a free function, not a closure: a
/// closure is not compiled with the caller's target features).
#[inline(always)]
pub(super) fn pick<T: Real, R: Lane<Scalar = T>>(liq: R::Mask, s: T, l: T) -> R {
    R::select(liq, R::splat(l), R::splat(s))
}

/// The `D × D` lane matrix of column-major entries `e`.
#[inline(always)]
fn lmat_of<R: Lane, const D: usize>(e: &[R; 9]) -> LMat<R, D> {
    let mut m = lmat::zero::<R, D>();
    for j in 0..D {
        for i in 0..D {
            m[j][i] = e[i + D * j];
        }
    }
    m
}
