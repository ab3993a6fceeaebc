//! The heat step of a G2P chunk (step 1 of [`update_particle`], Stomakhin et al. 2014, §6:
//! the PIC/FLIP temperature blend, and with phase change the heat `q = c (T* − T_p)` spent on
//! the latent buffer as [`thermal::absorb`] spends it).
//!
//! [`on_lanes`] makes it on the SIMD lanes when every lane stays in the segment it starts in
//! (a solid below the melting point warming short of it or cooling, a liquid above it cooling
//! short of it or warming, a particle at it whose buffer neither fills nor empties), with the
//! operations of the scalar step in the same order, so the bits are the same; [`per_lane`]
//! makes it with the scalar [`thermal::step`] per lane, for chunks where some lane leaves its
//! segment (melts, freezes, reaches the melting point) or fails.
//!
//! [`update_particle`]: crate::particle::update::update_particle

use super::{chunk_phases, rd, Checked, ChunkSamples, Particles, LANES};
use crate::lane::Lane;
use crate::particle::thermal::{self, ThermalState};
use crate::particle::{Heat, Material, Phase};
use crate::scalar::Real;

/// What the heat step of a chunk reads: the material (`checked` for each phase), the particle
/// arrays, the chunk's first particle and its samples (`t_pic`, `t_flip`), the heat model.
#[derive(Clone, Copy)]
pub(super) struct HeatChunk<'a, T> {
    pub(super) material: &'a Material<T>,
    pub(super) checked: &'a Checked,
    pub(super) ps: &'a Particles<T>,
    pub(super) start: usize,
    pub(super) cs: &'a ChunkSamples<T>,
    pub(super) heat: &'a Heat<T>,
}

/// The heat step of the chunk, written to `out`: on the lanes ([`on_lanes`]) when every lane
/// stays in its segment, else per lane ([`per_lane`]). Returns whether every lane's step
/// succeeded and passed the checks of the next call (else the caller updates the chunk
/// particle by particle, which gives each its exact status).
///
/// # Safety
/// The temperature array (and with phase change the latent array) holds the chunk's
/// particles; `phase` is null or holds them.
#[inline(always)]
pub(super) unsafe fn step<T: Real, V: Lane<Scalar = T>>(
    c: &HeatChunk<'_, T>,
    out: &mut [ThermalState<T>; LANES],
) -> bool {
    // The input phases, each valid for the material (as the scalar update checks them).
    let Some(phases) = chunk_phases(c.ps.phase, c.start, c.checked) else {
        return false;
    };
    on_lanes::<T, V>(c, &phases, out) || per_lane(c, &phases, out)
}

/// The heat step of the chunk at `start` on lanes from the input `phases` (valid codes, each
/// valid for the material: [`chunk_phases`]), written to `out`, if every lane's input state is
/// finite and in one segment of [`thermal`]'s invariants, and its step stays in that segment
/// with a result that [`thermal::check_result`] accepts. Returns whether it did (else nothing
/// is written).
///
/// Without phase change the step is the blend `T* = (1 − α) T_pic + α (T_p + ΔT_flip)`
/// ([`thermal::blend`]). With it, `q = c (T* − T_p)` with `c` of the particle's phase, then
/// as [`thermal::absorb`]'s one pass per segment:
/// - a solid at `T < T_m`, `U = 0`: `T ← min(T + q/c_s, T_m)` when `q < c_s (T_m − T)`
///   (warming; the `min` is the scalar clamp, and a no-op when cooling);
/// - a liquid at `T > T_m`, `U = L`: `T ← max(T + q/c_l, T_m)` when `−q < c_l (T − T_m)`;
/// - either phase at `T = T_m`: `U ← U + q` when `q < L − U` (warming, `U < L`) or `−q < U`
///   (cooling, `U > 0`);
/// - `q = 0`: unchanged.
///
/// # Safety
/// The temperature array (and with phase change the latent array) holds the chunk's
/// particles; `phase` is null or holds them.
#[inline(always)]
unsafe fn on_lanes<T: Real, V: Lane<Scalar = T>>(
    c: &HeatChunk<'_, T>,
    phases: &[Phase; LANES],
    out: &mut [ThermalState<T>; LANES],
) -> bool {
    let HeatChunk {
        material,
        ps,
        start,
        cs,
        heat,
        ..
    } = *c;
    let mut liquid_flags = [T::ZERO; LANES];
    for (fl, p) in liquid_flags.iter_mut().zip(phases) {
        if *p == Phase::Liquid {
            *fl = T::ONE;
        }
    }
    let zero = V::splat(T::ZERO);
    let t = V::load(core::slice::from_raw_parts(
        ps.temperature.add(start),
        LANES,
    ));
    let (t_pic, t_flip) = (V::load(&cs.t_pic), V::load(&cs.t_flip));
    let mut ok = t.is_finite() & t_pic.is_finite() & t_flip.is_finite();
    // `blend`: (1 − α) T_pic + α (T_p + ΔT_flip), `1 − α` in the scalar type.
    let t_star = V::splat(T::ONE - heat.flip) * t_pic + V::splat(heat.flip) * (t + t_flip);
    ok = ok & t_star.is_finite();
    let (t_new, u_new) = if !heat.phase_change {
        // The particle takes T*; the latent buffer is not kept (zero, as the scalar state).
        (t_star, zero)
    } else {
        let u = V::load(core::slice::from_raw_parts(ps.latent.add(start), LANES));
        let liq = zero.lt(V::load(&liquid_flags));
        let (tm, l) = (V::splat(heat.melting_point), V::splat(heat.latent_heat));
        let (c_s, c_l) = (
            V::splat(material.solid.heat_capacity),
            V::splat(material.liquid.heat_capacity),
        );
        let c = V::select(liq, c_l, c_s);
        let q = c * (t_star - t);
        ok = ok & q.is_finite() & u.is_finite();
        let warming = zero.lt(q);
        let cooling = q.lt(zero);
        // The three segments, each with the condition that the step ends inside it.
        let solid_seg = !liq & t.lt(tm) & u.eq(zero) & (!warming | q.lt(c_s * (tm - t)));
        let liquid_seg = liq & tm.lt(t) & u.eq(l) & (!cooling | (-q).lt(c_l * (t - tm)));
        let at_tm = t.eq(tm) & zero.le(u) & u.le(l);
        let latent_seg =
            at_tm & !(warming & !(u.lt(l) & q.lt(l - u))) & !(cooling & !(zero.lt(u) & (-q).lt(u)));
        ok = ok & (solid_seg | liquid_seg | latent_seg);
        let step = t + q / c;
        let t_seg = V::select(liq, step.max(tm), step.min(tm));
        let still = q.eq(zero);
        let t_new = V::select(still | latent_seg, t, t_seg);
        let u_new = V::select(latent_seg & !still, u + q, u);
        // The result as `check_state` checks it: `0 ≤ U ≤ L` (rounding of `U + q`).
        ok = ok & zero.le(u_new) & u_new.le(l);
        (t_new, u_new)
    };
    ok = ok & t_new.is_finite();
    if !V::all(ok) {
        return false;
    }
    let (mut ts, mut us) = ([T::ZERO; LANES], [T::ZERO; LANES]);
    t_new.store(&mut ts);
    u_new.store(&mut us);
    for (l, st) in out.iter_mut().enumerate() {
        *st = ThermalState {
            temperature: ts[l],
            latent: us[l],
            phase: phases[l],
        };
    }
    true
}

/// The heat step of the chunk at `start`, per lane as the scalar update makes it, from the
/// input `phases` ([`chunk_phases`]): a finite input temperature, then [`thermal::step`] and [`thermal::check_result`] of the new state, written
/// to `out`. Returns whether every lane passed.
///
/// # Safety
/// The temperature array (and with phase change the latent array) holds the chunk's
/// particles; `phase` is null or holds them.
#[inline(always)]
unsafe fn per_lane<T: Real>(
    c: &HeatChunk<'_, T>,
    phases: &[Phase; LANES],
    out: &mut [ThermalState<T>; LANES],
) -> bool {
    let HeatChunk {
        material,
        ps,
        start,
        cs,
        heat,
        ..
    } = *c;
    for (l, (new, &phase)) in out.iter_mut().zip(phases).enumerate() {
        let i = start + l;
        let st = ThermalState {
            temperature: rd(ps.temperature, i),
            latent: if heat.phase_change {
                rd(ps.latent, i)
            } else {
                T::ZERO
            },
            phase,
        };
        if !st.temperature.is_finite() {
            return false;
        }
        match thermal::step(material, heat, &st, cs.t_pic[l], cs.t_flip[l]) {
            Ok((st, _)) if thermal::check_result(heat, &st).is_ok() => *new = st,
            _ => return false,
        }
    }
    true
}

#[cfg(test)]
mod tests {
    //! [`on_lanes`] against the scalar step per lane ([`per_lane`]), on chunks drawn around
    //! every segment boundary of the latent-heat model.

    use super::*;
    use crate::lane::X2;
    use crate::particle::PhaseParams;
    use rand::seq::IndexedRandom;
    use rand::{Rng, SeedableRng};
    use rand_pcg::Pcg64;

    const TM: f64 = 273.15;
    const L: f64 = 334_000.0;

    fn material<T: Real>(flip: f64, phase_change: bool) -> Material<T> {
        let c = T::from_f64;
        let phase = |mu: f64, hc: f64| PhaseParams {
            mu: c(mu),
            inv_lambda: c(1.0e-4),
            heat_capacity: c(hc),
            conductivity: c(1.0),
        };
        Material {
            solid: phase(1.0e4, 2100.0),
            liquid: phase(0.0, 4200.0),
            heat: Some(Heat {
                flip: c(flip),
                melting_point: c(TM),
                latent_heat: c(L),
                phase_change,
            }),
            ..Material::default()
        }
    }

    /// One lane's input state `(T, U, phase)` and node sums `(T_pic, ΔT_flip)`, near a segment
    /// boundary: at, just below or above the melting point, with an empty, full, nearly full
    /// or partial buffer (some invalid combinations on purpose), heated or cooled by up to a
    /// few kelvin, or by exactly nothing.
    fn lane_state(r: &mut Pcg64) -> (f64, f64, u8, f64, f64) {
        let liquid = r.random::<u64>() % 2;
        let t = match r.random::<u64>() % 5 {
            0 | 1 => TM,
            2 => TM - 20.0 * r.random::<f64>(),
            3 => TM + 20.0 * r.random::<f64>(),
            _ => TM + *[-1e-4, 1e-4, -0.5, 0.5].choose(r).unwrap(),
        };
        let u = match r.random::<u64>() % 6 {
            0 => 0.0,
            1 => L,
            2 => L - 2000.0 * r.random::<f64>(),
            3 => 2000.0 * r.random::<f64>(),
            4 => L * r.random::<f64>(),
            _ => *[0.0, L].choose(r).unwrap(),
        };
        // Valid segment states mostly: snap `U` to the phase's value away from `T_m`.
        let (u, liquid) = if t < TM && r.random::<u64>() % 8 != 0 {
            (0.0, 0)
        } else if t > TM && r.random::<u64>() % 8 != 0 {
            (L, 1)
        } else {
            (u, liquid)
        };
        let dt = *[0.0, 1.0, -1.0].choose(r).unwrap() * 4.0 * r.random::<f64>();
        let (pic, flip) = if r.random::<u64>() % 2 == 0 {
            (t + dt, dt)
        } else if r.random::<u64>() % 4 == 0 {
            // Heated or cooled exactly to `T_m` when `α = 0` (`q` is then exactly the room
            // left in the temperature segment).
            (TM, dt)
        } else {
            (t + dt * r.random::<f64>(), dt * r.random::<f64>())
        };
        (t, u, liquid as u8, pic, flip)
    }

    /// Runs both paths on random chunks; where the lanes accept, every lane has the scalar
    /// step's bits. Returns how many chunks the lanes accepted of those the scalar accepted.
    fn compare<T: Real, V: Lane<Scalar = T>>(
        mat: &Material<T>,
        seed: u64,
        chunks: usize,
    ) -> (usize, usize) {
        let heat = mat.heat.unwrap();
        let checked = Checked::new(mat);
        let mut r = Pcg64::seed_from_u64(seed);
        let (mut lanes_ok, mut scalar_ok) = (0, 0);
        for _ in 0..chunks {
            let mut t = [T::ZERO; LANES];
            let mut u = [T::ZERO; LANES];
            let mut ph = [0u8; LANES];
            let mut cs = super::super::ChunkSamples::<T>::new();
            // Mostly chunks of in-segment lanes; some draw every lane near a boundary.
            let risky = r.random::<u64>() % 4 == 0;
            for l in 0..LANES {
                let (tt, uu, p, pic, fl) = loop {
                    let s = lane_state(&mut r);
                    let segment = match (s.0 < TM, s.0 > TM) {
                        (true, _) => s.1 == 0.0 && s.2 == 0,
                        (_, true) => s.1 == L && s.2 == 1,
                        _ => s.1 > 2000.0 && s.1 < L - 2000.0,
                    };
                    if risky || segment && s.4.abs() < 0.01 && (s.3 - s.0).abs() < 0.01 {
                        break s;
                    }
                };
                t[l] = T::from_f64(tt);
                u[l] = T::from_f64(uu);
                ph[l] = p;
                cs.t_pic[l] = T::from_f64(pic);
                cs.t_flip[l] = T::from_f64(fl);
            }
            let null = core::ptr::null_mut();
            let ps = Particles {
                x: null,
                v: null,
                affine: null,
                f_e: null,
                f_p: null,
                mass: null,
                volume0: null,
                temperature: t.as_mut_ptr(),
                latent: u.as_mut_ptr(),
                phase: ph.as_mut_ptr(),
            };
            let blank = ThermalState {
                temperature: T::ZERO,
                latent: T::ZERO,
                phase: Phase::Solid,
            };
            let (mut a, mut b) = ([blank; LANES], [blank; LANES]);
            // SAFETY: the arrays hold the chunk's particles.
            let c = HeatChunk {
                material: mat,
                checked: &checked,
                ps: &ps,
                start: 0,
                cs: &cs,
                heat: &heat,
            };
            // SAFETY: the arrays hold the chunk's particles.
            let (ok_l, ok_s) = unsafe {
                match chunk_phases(c.ps.phase, 0, &checked) {
                    Some(ph) => (on_lanes::<T, V>(&c, &ph, &mut a), per_lane(&c, &ph, &mut b)),
                    None => (step::<T, V>(&c, &mut a), false),
                }
            };
            if ok_l {
                assert!(
                    ok_s,
                    "lanes accepted a chunk the scalar step refuses: {t:?} {u:?}"
                );
                for l in 0..LANES {
                    let (x, y) = (a[l], b[l]);
                    assert_eq!(
                        x.temperature.to_f64().to_bits(),
                        y.temperature.to_f64().to_bits()
                    );
                    assert_eq!(x.latent.to_f64().to_bits(), y.latent.to_f64().to_bits());
                    assert_eq!(x.phase, y.phase);
                }
            }
            lanes_ok += ok_l as usize;
            scalar_ok += ok_s as usize;
        }
        (lanes_ok, scalar_ok)
    }

    fn all<T: Real, V: Lane<Scalar = T>>() {
        for (k, (flip, pc)) in [(0.95, true), (0.0, true), (1.0, true), (0.95, false)]
            .into_iter()
            .enumerate()
        {
            let (lanes, scalar) =
                compare::<T, V>(&material(flip, pc), 0x9e37_79b9 + k as u64, 4000);
            // The in-segment chunks (three in four) stay on the lanes.
            assert!(
                lanes * 2 > scalar && scalar > 2000,
                "flip {flip} {pc}: {lanes} of {scalar}"
            );
        }
    }

    #[test]
    fn lanes_give_the_scalar_step() {
        all::<f32, X2<X2<X2<f32>>>>();
        all::<f64, X2<X2<X2<f64>>>>();
        #[cfg(target_arch = "x86_64")]
        {
            #[target_feature(enable = "avx2,fma")]
            unsafe fn avx2() {
                all::<f32, crate::lane::F32x8>();
                all::<f64, X2<crate::lane::F64x4>>();
            }
            if std::is_x86_feature_detected!("avx2") && std::is_x86_feature_detected!("fma") {
                // SAFETY: the CPU has AVX2 and FMA.
                unsafe { avx2() };
            }
        }
    }
}
