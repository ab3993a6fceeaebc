//! Particle temperature, latent heat and phase change (Stomakhin et al. 2014, §6).
//!
//! **Transfer.** The host solves the heat equation on its grid; G2P gives the particle the
//! PIC/FLIP blend `T* = (1 − α) Σ w_i T_iⁿ⁺¹ + α (T_p + Σ w_i (T_iⁿ⁺¹ − T_iⁿ))`. Without phase
//! change the particle simply takes `T*`.
//!
//! **Latent heat.** With phase change the grid's temperature change is turned into heat
//! per unit mass `q = c_phase (T* − T_p)` (J/kg, `c` of the particle's current phase), and
//! [`absorb`] spends it piece by piece (the paper's latent buffer `U ∈ [0, L]`, J/kg):
//! a solid below `T_m` warms (`c_solid`); at `T_m` heat fills `U` with the temperature held;
//! when `U = L` the particle becomes liquid, and further heat warms the liquid (`c_liquid`).
//! Cooling runs the same path backwards; `U = 0` turns a liquid at `T_m` solid. Every piece of
//! `q` is booked in exactly one of the three terms of [`HeatSplit`], so the heat received is
//! `Q = m q = m (c_s ΔT_s + ΔU + c_l ΔT_l)` across any phase switch.
//!
//! **Invariants** (checked when phase change is on; [`Error::InvalidArgument`] otherwise):
//! `0 ≤ U ≤ L`; a solid has `T ≤ T_m`, a liquid `T ≥ T_m`; a partly filled buffer
//! (`0 < U < L`) only at `T = T_m`, and `U = L` for a liquid above `T_m`, `U = 0` for a solid
//! below it. So liquid water at 300 K has `U = L`, ice at 250 K has `U = 0`.

use super::stencil::Stencil;
use super::{Heat, Material, Phase};
use crate::error::{Error, Result};
use crate::scalar::Real;

/// The thermal state of one particle.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ThermalState<T> {
    /// Temperature (K).
    pub temperature: T,
    /// Latent buffer `U` (J/kg).
    pub latent: T,
    /// Phase.
    pub phase: Phase,
}

/// Where the heat `q` (J/kg) went: `q = solid + latent + liquid` (up to the rounding of the
/// additions).
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct HeatSplit<T> {
    /// `c_s ΔT` spent warming or cooling the solid (J/kg).
    pub solid: T,
    /// `ΔU` spent on the latent buffer (J/kg).
    pub latent: T,
    /// `c_l ΔT` spent warming or cooling the liquid (J/kg).
    pub liquid: T,
}

/// The G2P sums of the temperature transfer from node temperatures `(T_iⁿ⁺¹, T_iⁿ)` (K) in
/// stencil order: `(Σ w_i T_iⁿ⁺¹, Σ w_i (T_iⁿ⁺¹ − T_iⁿ))`, the `t_pic` and `t_flip` of
/// [`super::update::G2pSample`].
///
/// Errors: [`Error::InvalidArgument`] for slices shorter than the stencil;
/// [`Error::NonFinite`] for a NaN/inf node temperature; [`Error::Overflow`] when a sum of
/// finite temperatures is not representable.
#[inline]
pub fn gather<T: Real, const D: usize>(
    s: &Stencil<T, D>,
    t_new: &[T],
    t_old: &[T],
) -> Result<(T, T)> {
    let n = s.len();
    if t_new.len() < n || t_old.len() < n {
        return Err(Error::InvalidArgument);
    }
    let (mut pic, mut flip) = (T::ZERO, T::ZERO);
    let mut inputs_finite = true;
    for r in 0..n {
        let w = s.node(r).weight;
        inputs_finite &= t_new[r].is_finite() && t_old[r].is_finite();
        pic += w * t_new[r];
        flip += w * (t_new[r] - t_old[r]);
    }
    if !inputs_finite {
        Err(Error::NonFinite)
    } else if pic.is_finite() && flip.is_finite() {
        Ok((pic, flip))
    } else {
        Err(Error::Overflow)
    }
}

/// The PIC/FLIP blend `T* = (1 − α) T_pic + α (T_p + ΔT_flip)` (K).
#[inline]
#[must_use]
pub fn blend<T: Real>(flip: T, t_p: T, t_pic: T, dt_flip: T) -> T {
    (T::ONE - flip) * t_pic + flip * (t_p + dt_flip)
}

/// Step 1 of the particle update ([`super::update::update_particle`]): the new thermal state
/// of a particle in state `st` from its G2P sums `(t_pic, t_flip)` ([`gather`]) under `heat`.
/// `T*` is the [`blend`]; without phase change the particle takes `T*`; with it, the heat
/// `q = c (T* − T_p)` (J/kg, `c` of the particle's current phase) goes through [`absorb`],
/// whose split is returned (zero without phase change).
///
/// Errors: [`Error::NonFinite`] for a NaN/inf sum; [`Error::Overflow`] for a `T*` or `q` that
/// is not finite; those of [`absorb`].
#[inline(always)]
pub(crate) fn step<T: Real>(
    material: &Material<T>,
    heat: &Heat<T>,
    st: &ThermalState<T>,
    t_pic: T,
    t_flip: T,
) -> Result<(ThermalState<T>, HeatSplit<T>)> {
    if !(t_pic.is_finite() && t_flip.is_finite()) {
        return Err(Error::NonFinite);
    }
    let t_star = blend(heat.flip, st.temperature, t_pic, t_flip);
    if !t_star.is_finite() {
        return Err(Error::Overflow);
    }
    if !heat.phase_change {
        let new = ThermalState {
            temperature: t_star,
            ..*st
        };
        return Ok((new, HeatSplit::default()));
    }
    let c = material.params(st.phase).heat_capacity;
    let q = c * (t_star - st.temperature);
    if !q.is_finite() {
        return Err(Error::Overflow);
    }
    absorb(
        heat,
        material.solid.heat_capacity,
        material.liquid.heat_capacity,
        st,
        q,
    )
}

/// Checks a new thermal state as the next call checks it: a finite temperature
/// ([`Error::Overflow`] otherwise, a result), and with phase change [`check_state`].
#[inline(always)]
pub(crate) fn check_result<T: Real>(heat: &Heat<T>, st: &ThermalState<T>) -> Result<()> {
    if !st.temperature.is_finite() {
        return Err(Error::Overflow);
    }
    if heat.phase_change {
        check_state(heat, st)?;
    }
    Ok(())
}

/// Checks the invariants of the module docs.
#[inline]
pub fn check_state<T: Real>(heat: &Heat<T>, st: &ThermalState<T>) -> Result<()> {
    let (t, u, tm, l) = (
        st.temperature,
        st.latent,
        heat.melting_point,
        heat.latent_heat,
    );
    if !(t.is_finite() && u.is_finite()) {
        return Err(Error::NonFinite);
    }
    let ok = u >= T::ZERO
        && u <= l
        && match st.phase {
            Phase::Solid => t < tm && u == T::ZERO || t == tm,
            Phase::Liquid => t > tm && u == l || t == tm,
        };
    if ok {
        Ok(())
    } else {
        Err(Error::InvalidArgument)
    }
}

/// Spends `q` (J/kg, positive in) on a particle (see the module docs); `c_solid`, `c_liquid`
/// in J/(kg·K). Returns the new state and where the heat went.
///
/// Errors: [`Error::NonFinite`]; [`Error::InvalidArgument`] for a state violating the
/// invariants; [`Error::Overflow`] for a temperature that is not finite.
#[inline]
pub fn absorb<T: Real>(
    heat: &Heat<T>,
    c_solid: T,
    c_liquid: T,
    st: &ThermalState<T>,
    q: T,
) -> Result<(ThermalState<T>, HeatSplit<T>)> {
    if !q.is_finite() {
        return Err(Error::NonFinite);
    }
    check_state(heat, st)?;
    let (tm, l) = (heat.melting_point, heat.latent_heat);
    let mut s = *st;
    let mut q = q;
    let mut split = HeatSplit::default();
    // Each pass spends all of q, or ends one segment (T reaches T_m, U reaches 0 or L), or
    // switches the phase. The longest path, solid below T_m to liquid above it (or back), is
    // T → T_m, U → L, switch, warm the liquid: four passes.
    for _ in 0..4 {
        if q == T::ZERO {
            break;
        }
        let heating = q > T::ZERO;
        match (s.phase, heating) {
            (Phase::Solid, true) if s.temperature < tm => {
                let room = c_solid * (tm - s.temperature);
                if q < room {
                    // q < c (T_m − T), but q/c may round to one ulp above T_m − T: clamp, so
                    // that a solid stays at or below T_m.
                    s.temperature = (s.temperature + q / c_solid).min(tm);
                    split.solid += q;
                    q = T::ZERO;
                } else {
                    s.temperature = tm;
                    split.solid += room;
                    q -= room;
                }
            }
            (Phase::Solid, true) | (Phase::Liquid, true) if s.latent < l => {
                let room = l - s.latent;
                if q < room {
                    s.latent += q;
                    split.latent += q;
                    q = T::ZERO;
                } else {
                    s.latent = l;
                    split.latent += room;
                    q -= room;
                }
            }
            (Phase::Solid, true) => {
                // At T_m with a full buffer: melt, then warm the liquid on the next pass.
                s.phase = Phase::Liquid;
            }
            (Phase::Liquid, true) => {
                s.temperature += q / c_liquid;
                split.liquid += q;
                q = T::ZERO;
            }
            (Phase::Liquid, false) if s.temperature > tm => {
                let room = c_liquid * (s.temperature - tm);
                if -q < room {
                    // As above: a liquid stays at or above T_m.
                    s.temperature = (s.temperature + q / c_liquid).max(tm);
                    split.liquid += q;
                    q = T::ZERO;
                } else {
                    s.temperature = tm;
                    split.liquid -= room;
                    q += room;
                }
            }
            (Phase::Liquid, false) | (Phase::Solid, false) if s.latent > T::ZERO => {
                if -q < s.latent {
                    s.latent += q;
                    split.latent += q;
                    q = T::ZERO;
                } else {
                    split.latent -= s.latent;
                    q += s.latent;
                    s.latent = T::ZERO;
                }
            }
            (Phase::Liquid, false) => {
                // At T_m with an empty buffer: freeze, then cool the solid on the next pass.
                s.phase = Phase::Solid;
            }
            (Phase::Solid, false) => {
                s.temperature += q / c_solid;
                split.solid += q;
                q = T::ZERO;
            }
        }
    }
    if q != T::ZERO {
        // Unreachable by the segment count above; refuse rather than lose heat.
        return Err(Error::NotConverged);
    }
    if !s.temperature.is_finite() {
        return Err(Error::Overflow);
    }
    Ok((s, split))
}
