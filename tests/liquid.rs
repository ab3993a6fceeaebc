//! Liquids over long runs, and the contract of the particle update: `Ok` only with a state
//! that the next call accepts, with the statuses of `include/ampm.h` (a finite input whose
//! result is not representable is `Overflow`).
//!
//! - Long runs (10 s simulated, 10⁴ steps, f32 and f64): a sheared and an extended 2D liquid,
//!   a stirred 3D liquid, driven through `update_particle` with a prescribed `∇v`. The liquid
//!   state is `(J_E, J_P)` only (Stomakhin et al. 2014, §4 and §7): `F_E = J_E^{1/d} I`,
//!   `F_P = J_P^{1/d} I`, `J_P` constant, `J_E` following `det(I + Δt∇v)` step by step.
//! - Regressions: an `F_E` stretched beyond `1/ε` under snow plasticity, a `J_P` or `J_E`
//!   that underflows from valid inputs, a tiny finite `h`, P2G and the force differential
//!   with finite inputs whose results overflow.
//! - A property loop over random inputs at extreme scales: every `Ok` passes
//!   `check_particle` (and the heat-state and hardening checks), and a second call accepts it.
//!
//! Tolerances are derived where they are stated, in units of the scalar's ε (the spacing at
//! 1, twice the unit roundoff `u`): a determinant evaluated in floating point is off by at
//! most `(d + 2) u · perm(|M|)` (`perm`: the permanent, the sum of the magnitudes of the
//! determinant's terms), and relative entry perturbations `δ` move it by at most
//! `d · δ · perm(|M|)` to first order (Laplace expansion along each row).
#![allow(clippy::needless_range_loop)] // index loops mirror the formulas

use ampm_core::particle::apic;
use ampm_core::particle::deformation::{self, check_det, det_equilibrated};
use ampm_core::particle::thermal::{check_state, ThermalState};
use ampm_core::particle::update::{
    check_particle, force_differential, p2g, update_particle, G2pSample,
};
use ampm_core::particle::{
    g2p_update, Definiteness, Dilation, Grid, GridSample, Heat, Kernel, Material, Particle, Phase,
    PhaseParams, Snow, Stencil,
};
use ampm_core::polar::{DefaultSvd, SvdMethod};
use ampm_core::{Error, Mat, Matrix, Real};
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;

fn rng(seed: u64) -> Pcg64 {
    Pcg64::seed_from_u64(seed)
}

// ---------------------------------------------------------------------------------------
// f64 reference helpers (row-major `[[f64; D]; D]`).

fn to_f64<T: Real, const D: usize>(m: &Mat<T, D>) -> [[f64; D]; D] {
    let mut r = [[0.0; D]; D];
    for i in 0..D {
        for j in 0..D {
            r[i][j] = m.cols[j][i].to_f64();
        }
    }
    r
}

fn det64<const D: usize>(a: &[[f64; D]; D]) -> f64 {
    match D {
        2 => a[0][0] * a[1][1] - a[0][1] * a[1][0],
        _ => {
            a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1])
                - a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0])
                + a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0])
        }
    }
}

/// The permanent of `|a|`: the sum of the magnitudes of the terms of `det a`.
fn perm_abs64<const D: usize>(a: &[[f64; D]; D]) -> f64 {
    let b = a.map(|r| r.map(f64::abs));
    match D {
        2 => b[0][0] * b[1][1] + b[0][1] * b[1][0],
        _ => {
            b[0][0] * (b[1][1] * b[2][2] + b[1][2] * b[2][1])
                + b[0][1] * (b[1][0] * b[2][2] + b[1][2] * b[2][0])
                + b[0][2] * (b[1][0] * b[2][1] + b[1][1] * b[2][0])
        }
    }
}

/// Frobenius condition number `‖M‖_F ‖M⁻¹‖_F = ‖M‖_F ‖cof M‖_F / |det M|` (≥ the 2-norm
/// one), in f64; `d` for `s I`.
fn kappa_f64<const D: usize>(a: &[[f64; D]; D]) -> f64 {
    let n2: f64 = a.iter().flatten().map(|x| x * x).sum();
    let mut c2 = 0.0;
    for i in 0..D {
        for j in 0..D {
            // Minor of (i, j).
            let mut m = [[0.0; 2]; 2];
            let mut ri = 0;
            for r in 0..D {
                if r == i {
                    continue;
                }
                let mut ci = 0;
                for c in 0..D {
                    if c == j {
                        continue;
                    }
                    if ri < 2 && ci < 2 {
                        m[ri][ci] = a[r][c];
                    }
                    ci += 1;
                }
                ri += 1;
            }
            let minor = if D == 2 { m[0][0] } else { det64(&m) };
            c2 += minor * minor;
        }
    }
    (n2 * c2).sqrt() / det64(a).abs()
}

fn mat_from_rows<T: Real, const D: usize>(r: &[[f64; D]; D]) -> Mat<T, D> {
    let mut m = Mat::<T, D>::ZERO;
    for i in 0..D {
        for j in 0..D {
            m.cols[j][i] = T::from_f64(r[i][j]);
        }
    }
    m
}

/// `Some(s)` when `m = s I` exactly.
fn iso<T: Real, const D: usize>(m: &Mat<T, D>) -> Option<T> {
    deformation::isotropic_scale(m)
}

// ---------------------------------------------------------------------------------------
// Long runs.

fn liquid_material<T: Real>() -> Material<T> {
    Material {
        liquid: PhaseParams {
            mu: T::ZERO,
            inv_lambda: T::from_f64(1e-3),
            ..PhaseParams::default()
        },
        ..Material::default()
    }
}

/// What a long run saw.
struct RunReport {
    /// Largest Frobenius condition number of `F_P` under the projection kept by the
    /// particle update (`d` for `s I`).
    kappa_max: f64,
    /// The same for the rule `F_P ← J_E^{−1/d} F_E F_P` (the whole `F` kept), run alongside
    /// on the same `F_E`: where it reached `1/ε`, and where its `det F_P` was lost.
    old_kappa_max: f64,
    old_kappa_past_precision_at: Option<f64>,
    old_det_lost_at: Option<f64>,
    /// `|J_E / J_E,ref − 1|` at the end and its derived bound.
    j_e_drift: f64,
    j_e_bound: f64,
}

/// Drives a liquid that has just melted (`F_E = 0.98 I`, a general `F_P`) through
/// `update_particle` with `∇v = flow(t)` for `steps` steps of `dt`, checking every step.
fn long_run<T: Real, const D: usize>(
    flow: &dyn Fn(f64) -> [[f64; D]; D],
    dt: f64,
    steps: usize,
) -> RunReport
where
    Mat<T, D>: Matrix<Scalar = T, Vector = [T; D]>,
    DefaultSvd: SvdMethod<Mat<T, D>>,
{
    let eps = T::EPSILON.to_f64();
    let u = 0.5 * eps;
    let u64_ = 0.5 * f64::EPSILON;
    let d = D as f64;
    let mat = liquid_material::<T>();
    let dt_t = T::from_f64(dt);
    let dt64 = dt_t.to_f64();

    let mut p = Particle::<T, D>::at_rest([T::from_f64(0.3); D], T::ONE, T::from_f64(1e-3));
    p.phase = Phase::Liquid;
    p.f_e = Mat::from_diagonal([T::from_f64(0.98); D]);
    let fp_rows = [[1.1, 0.2, 0.05], [-0.1, 0.9, 0.1], [0.03, 0.07, 1.05]];
    let mut fp0 = [[0.0; D]; D];
    for i in 0..D {
        for j in 0..D {
            fp0[i][j] = fp_rows[i][j];
        }
    }
    p.f_p = mat_from_rows::<T, D>(&fp0);
    let fp0 = to_f64(&p.f_p);
    let j_p0 = det64(&fp0);
    // First step: det F_P in T ((d + 2)u·perm), its d-th root (≤ 1 ulp, 2u, times d), the
    // state's det of r I measured in f64 ((d − 1) u64).
    let first_tol = (u * ((d + 2.0) * perm_abs64(&fp0) / j_p0 + 2.0 * d) + (d - 1.0) * u64_) * j_p0;

    let mut j_e_ref = det64(&to_f64(&p.f_e));
    let mut drift_bound = 0.0f64;
    let mut f_p1: Option<Mat<T, D>> = None;
    let mut report = RunReport {
        kappa_max: 0.0,
        old_kappa_max: 0.0,
        old_kappa_past_precision_at: None,
        old_det_lost_at: None,
        j_e_drift: 0.0,
        j_e_bound: 0.0,
    };
    let mut old_fp = p.f_p;

    for n in 0..steps {
        let t = n as f64 * dt;
        let l64 = flow(t);
        let l = mat_from_rows::<T, D>(&l64);
        // Temperatures are not read without heat: NaN checks that.
        let s = G2pSample {
            v: [T::ZERO; D],
            affine: l,
            grad_v: l,
            t_pic: T::from_f64(f64::NAN),
            t_flip: T::from_f64(f64::NAN),
        };
        let (q, info) = update_particle(&mat, dt_t, &s, &p)
            .unwrap_or_else(|e| panic!("{} d={D} t={t}: {e:?}", T::NAME));
        assert_eq!(info.halvings, 0);
        assert_eq!(check_particle(&q).map(|_| ()), Ok(()));
        assert_eq!(q.affine, l);

        // F_E and F_P isotropic: exactly s I.
        assert!(iso(&q.f_e).is_some(), "F_E not isotropic: {:?}", q.f_e);
        let sp = iso(&q.f_p).unwrap_or_else(|| panic!("F_P not isotropic: {:?}", q.f_p));
        assert!(sp > T::ZERO);
        report.kappa_max = report.kappa_max.max(kappa_f64(&to_f64(&q.f_p)));

        // J_P: the melted F_P's determinant after the first step, then bit for bit.
        match f_p1 {
            None => {
                let j_p1 = det64(&to_f64(&q.f_p));
                assert!(
                    (j_p1 - j_p0).abs() <= first_tol,
                    "J_P {j_p1} vs {j_p0}, tol {first_tol}"
                );
                f_p1 = Some(q.f_p);
            }
            Some(f) => assert_eq!(q.f_p, f, "J_P changed at t = {t}"),
        }

        // J_E bookkeeping: J_E ← J_E det(I + Δt∇v). Per step (relative, see the header):
        // the entries of Δt∇v, I + Δt∇v and A·(r I) rounded (≤ 3u each: 3u·d·P), det on the
        // equilibrated F_E ((d + 2)u·P), the root (≤ 2u, times d), plus the f64 reference's
        // own rounding; P = perm(|A|)/|det A|.
        let mut a = [[0.0; D]; D];
        for i in 0..D {
            for j in 0..D {
                a[i][j] = dt64 * l.cols[j][i].to_f64() + if i == j { 1.0 } else { 0.0 };
            }
        }
        let inc = det64(&a);
        let pr = perm_abs64(&a) / inc.abs();
        let step_tol =
            u * ((3.0 * d + d + 2.0) * pr + 2.0 * d) + u64_ * ((4.0 * d + 4.0) * pr + 2.0 * d);
        let j_old = det64(&to_f64(&p.f_e));
        let j_new = det64(&to_f64(&q.f_e));
        assert!(
            (j_new / (j_old * inc) - 1.0).abs() <= step_tol,
            "{} d={D} t={t}: J_E step {} > {step_tol}",
            T::NAME,
            (j_new / (j_old * inc) - 1.0).abs()
        );
        j_e_ref *= inc;
        drift_bound = (1.0 + drift_bound) * (1.0 + step_tol) - 1.0;
        report.j_e_drift = (j_new / j_e_ref - 1.0).abs();
        report.j_e_bound = drift_bound;
        assert!(report.j_e_drift <= drift_bound);

        // The whole-F rule on the same F_E, for comparison.
        if report.old_det_lost_at.is_none() {
            let (fe, _) = deformation::evolve(&p.f_e, &l, dt_t).unwrap();
            let r = deformation::root_d::<T, D>(Matrix::det(&fe));
            old_fp = (fe * (T::ONE / r)) * old_fp;
            let jd = Matrix::det(&old_fp);
            if !(old_fp.is_finite() && jd.is_finite() && jd > T::ZERO) {
                report.old_det_lost_at = Some(t);
            } else {
                let k = kappa_f64(&to_f64(&old_fp));
                report.old_kappa_max = report.old_kappa_max.max(k);
                if k * eps > 1.0 && report.old_kappa_past_precision_at.is_none() {
                    report.old_kappa_past_precision_at = Some(t);
                }
            }
        }
        p = q;
    }
    // J = J_E J_P kept: J_E followed its bookkeeping, J_P its start value.
    assert!(report.kappa_max <= d * (1.0 + 4.0 * u64_));
    report
}

const DT: f64 = 1e-3;
const STEPS: usize = 10_000; // 10 s

/// Simple shear `∇v = [[0, γ̇], [0, 0]]`, `γ̇ = 5/s`: `det(I + Δt∇v) = 1`, so `J_E` must stay
/// at its start value to rounding.
fn shear2(_t: f64) -> [[f64; 2]; 2] {
    [[0.0, 5.0], [0.0, 0.0]]
}

/// Planar extension along the diagonals, `∇v = ε̇ [[0, 1], [1, 0]]`, `ε̇ = 2.5/s`: the
/// whole-`F` rule's `F_P` has eigenvalues `e^{±ε̇t}`, so its condition passes `1/ε` after
/// `ln(1/ε)/(2ε̇)` (3.2 s in f32, 7.2 s in f64).
fn extension2(_t: f64) -> [[f64; 2]; 2] {
    [[0.0, 2.5], [2.5, 0.0]]
}

/// A stirred 3D liquid: a vortex `Ω = 2/s` about z plus a shear `γ̇ = 3/s` of the z-planes
/// whose direction turns at `ω = 1.5/s`.
fn stirred3(t: f64) -> [[f64; 3]; 3] {
    let (g, om, w) = (3.0, 2.0, 1.5);
    let (s, c) = (w * t).sin_cos();
    [[0.0, -om, g * c], [om, 0.0, g * s], [0.0, 0.0, 0.0]]
}

fn check_report(r: &RunReport, name: &str) {
    println!(
        "{name}: κ(F_P) ≤ {:.3}; whole-F rule: κ ≤ {:.3e}, past 1/ε at {:?} s, det lost at {:?} \
         s; J_E drift {:.2e} ≤ {:.2e}",
        r.kappa_max,
        r.old_kappa_max,
        r.old_kappa_past_precision_at,
        r.old_det_lost_at,
        r.j_e_drift,
        r.j_e_bound
    );
}

#[test]
fn long_run_sheared_2d() {
    for r in [
        long_run::<f32, 2>(&shear2, DT, STEPS),
        long_run::<f64, 2>(&shear2, DT, STEPS),
    ] {
        check_report(&r, "shear 2D");
        // det(I + Δt∇v) = 1 exactly and √(s²) = s: J_E does not move at all.
        assert_eq!(r.j_e_drift, 0.0);
        // The whole-F rule keeps growing: κ ≈ (γ̇ t)² = 2500 at 10 s.
        assert!(r.old_kappa_max > 2000.0, "{}", r.old_kappa_max);
    }
}

#[test]
fn long_run_extended_2d() {
    let r32 = long_run::<f32, 2>(&extension2, DT, STEPS);
    let r64 = long_run::<f64, 2>(&extension2, DT, STEPS);
    for (r, name) in [(&r32, "extension 2D f32"), (&r64, "extension 2D f64")] {
        check_report(r, name);
        // The regime that used to fail: the whole-F rule's F_P is singular to working
        // precision within the run; the particle update's F_P stays s I.
        assert!(
            r.old_kappa_past_precision_at.is_some() || r.old_det_lost_at.is_some(),
            "{name}: κ ≤ {}",
            r.old_kappa_max
        );
    }
    assert!(r32.old_kappa_past_precision_at.unwrap_or(0.0) < 4.0);
}

#[test]
fn long_run_stirred_3d() {
    for r in [
        long_run::<f32, 3>(&stirred3, DT, STEPS),
        long_run::<f64, 3>(&stirred3, DT, STEPS),
    ] {
        check_report(&r, "stirred 3D");
    }
}

// ---------------------------------------------------------------------------------------
// Regressions and the property loop, for every scalar × dimension.

fn plastic<T: Real>() -> Material<T> {
    Material {
        plasticity: Some(Snow {
            critical_compression: T::from_f64(0.025),
            critical_stretch: T::from_f64(0.0075),
            hardening: T::from_f64(10.0),
        }),
        ..Material::elastic(T::from_f64(10.0), T::from_f64(10.0))
    }
}

fn heat_material<T: Real>(phase_change: bool) -> Material<T> {
    let f = T::from_f64;
    Material {
        solid: PhaseParams {
            mu: f(10.0),
            inv_lambda: f(0.05),
            heat_capacity: f(2.0),
            conductivity: f(1.0),
        },
        liquid: PhaseParams {
            mu: T::ZERO,
            inv_lambda: f(0.05),
            heat_capacity: f(4.0),
            conductivity: f(0.5),
        },
        plasticity: None,
        heat: Some(Heat {
            flip: f(0.9),
            melting_point: f(273.0),
            latent_heat: f(100.0),
            phase_change,
        }),
        dilation: Dilation::Explicit,
        hessian: Definiteness::Exact,
    }
}

fn quiet<T: Real, const D: usize>(p: &Particle<T, D>) -> G2pSample<T, D> {
    G2pSample {
        v: [T::ZERO; D],
        affine: Mat::ZERO,
        grad_v: Mat::ZERO,
        t_pic: p.temperature,
        t_flip: T::ZERO,
    }
}

/// What every entry checks on a particle, plus a second update with a quiet grid.
fn assert_accepted<T: Real, const D: usize>(mat: &Material<T>, q: &Particle<T, D>, what: &str)
where
    Mat<T, D>: Matrix<Scalar = T, Vector = [T; D]>,
    DefaultSvd: SvdMethod<Mat<T, D>>,
{
    let (_, j_p) = check_particle(q).unwrap_or_else(|e| panic!("{what}: {e:?} for {q:?}"));
    if let Some(h) = &mat.heat {
        assert!(q.temperature.is_finite(), "{what}: {q:?}");
        if h.phase_change {
            let st = ThermalState {
                temperature: q.temperature,
                latent: q.latent,
                phase: q.phase,
            };
            assert_eq!(check_state(h, &st), Ok(()), "{what}: {q:?}");
        }
    }
    assert!(mat.moduli(q.phase, j_p).is_ok(), "{what}: {q:?}");
    // A second step on a quiet grid: `F_E` unchanged by the flow, no clamping of an
    // unclamped `F_E`, an isotropic `F_P` kept bit for bit. Only a plastic solid whose
    // `F_E` sits on the clamp may be re-clamped (by a rounding of its SVD), which multiplies
    // an `F_P` near singular by `≈ I` and may lose it: that is a result, not a refusal.
    let again = update_particle(mat, T::from_f64(1e-3), &quiet(q), q);
    match again {
        Ok(_) => {}
        Err(Error::NonPositiveJ | Error::Overflow)
            if mat.plasticity.is_some() && q.phase == Phase::Solid => {}
        Err(e) => panic!("{what}: second call {e:?} for {q:?}"),
    }
}

/// A random rotation: an angle in 2D, a unit quaternion in 3D.
fn rotation<const D: usize>(r: &mut Pcg64) -> [[f64; D]; D] {
    let mut m = [[0.0; D]; D];
    if D == 2 {
        let (s, c) = r.random_range(0.0..core::f64::consts::TAU).sin_cos();
        m[0][0] = c;
        m[0][1] = -s;
        m[1][0] = s;
        m[1][1] = c;
        return m;
    }
    let q = loop {
        let q: [f64; 4] = core::array::from_fn(|_| r.random_range(-1.0..1.0));
        let n = q.iter().map(|x| x * x).sum::<f64>();
        if n > 0.01 && n <= 1.0 {
            let n = n.sqrt();
            break q.map(|x| x / n);
        }
    };
    let [w, x, y, z] = q;
    let rm = [
        [
            1.0 - 2.0 * (y * y + z * z),
            2.0 * (x * y - w * z),
            2.0 * (x * z + w * y),
        ],
        [
            2.0 * (x * y + w * z),
            1.0 - 2.0 * (x * x + z * z),
            2.0 * (y * z - w * x),
        ],
        [
            2.0 * (x * z - w * y),
            2.0 * (y * z + w * x),
            1.0 - 2.0 * (x * x + y * y),
        ],
    ];
    for i in 0..D {
        for j in 0..D {
            m[i][j] = rm[i][j];
        }
    }
    m
}

/// `R diag(σ) Sᵀ` rounded to `T`.
fn with_singular_values<T: Real, const D: usize>(r: &mut Pcg64, sigma: [f64; D]) -> Mat<T, D> {
    let a = rotation::<D>(r);
    let b = rotation::<D>(r);
    let mut m = [[0.0; D]; D];
    for i in 0..D {
        for j in 0..D {
            for k in 0..D {
                m[i][j] += a[i][k] * sigma[k] * b[j][k];
            }
        }
    }
    mat_from_rows(&m)
}

/// `±2^U(−e, e)`.
fn log_uniform<T: Real>(r: &mut Pcg64, e: f64) -> T {
    let x = T::from_f64(2f64.powf(r.random_range(-e..e)));
    if r.random_bool(0.5) {
        -x
    } else {
        x
    }
}

macro_rules! contract_tests {
    ($m:ident, $t:ty, $d:literal) => {
        mod $m {
            use super::*;
            type T = $t;
            const D: usize = $d;
            type M = Mat<T, D>;
            const EPS: f64 = <T as Real>::EPSILON as f64;
            const MAX_EXP: i32 = <T as Real>::MAX_EXP;
            const DIGITS: i32 = <T as Real>::MANTISSA_DIGITS as i32;
            /// Exponent of the smallest subnormal.
            const MIN_SUB_EXP: i32 = 3 - MAX_EXP - DIGITS;

            fn zero_sample() -> G2pSample<T, D> {
                G2pSample {
                    v: [0.0; D],
                    affine: M::ZERO,
                    grad_v: M::ZERO,
                    t_pic: 0.0,
                    t_flip: 0.0,
                }
            }

            /// An `F_E` stretched beyond `1/ε` (`F_P = I`) under snow plasticity: the new
            /// `F_P = V diag(σ/σ̂) Vᵀ` is singular to working precision, and its computed
            /// determinant is often ≤ 0. The update refuses those (before, it returned them
            /// with `Ok`), and those whose positive but meaningless `J_P` makes the hardening
            /// overflow; everything it returns is accepted.
            #[test]
            fn ill_conditioned_plastic_flow_is_refused() {
                let mat = plastic::<T>();
                let snow = mat.plasticity.unwrap();
                let mut r = rng(11);
                let (mut bad_raw, mut refused, mut ok) = (0, 0, 0);
                let top = (1.0 / EPS).log10() + 2.0;
                for _ in 0..4000 {
                    let big = 10f64.powf(r.random_range(1.0..top));
                    let mut sigma = [1.0; D];
                    sigma[0] = big;
                    sigma[D - 1] = 1.0 / big;
                    let mut p = Particle::<T, D>::at_rest([0.3; D], 1.0, 1.0);
                    p.f_e = with_singular_values::<T, D>(&mut r, sigma);
                    if check_particle(&p).is_err() {
                        continue;
                    }
                    // The new F_P as snow plasticity forms it, unchecked.
                    let svd = DefaultSvd.svd(&p.f_e).unwrap();
                    let lo = 1.0 - snow.critical_compression;
                    let hi = 1.0 + snow.critical_stretch;
                    let ratio = svd.sigma.map(|s| s / s.max(lo).min(hi));
                    let raw = svd.v * M::from_diagonal(ratio) * svd.v.transpose();
                    let res = update_particle(&mat, 1e-3, &zero_sample(), &p);
                    if svd.sigma.iter().any(|&s| s <= 0.0) {
                        // The SVD itself finds F_E singular to working precision (also
                        // refused before).
                        assert_eq!(res.map(|_| ()), Err(Error::NonPositiveJ));
                        continue;
                    }
                    let raw_ok = raw.is_finite() && Matrix::det(&raw) > 0.0;
                    bad_raw += (!raw_ok) as usize;
                    match res {
                        Ok((q, _)) => {
                            assert!(raw_ok, "Ok although det F_P = {}", Matrix::det(&raw));
                            assert_accepted(&mat, &q, "plastic");
                            ok += 1;
                        }
                        Err(e) if raw_ok => {
                            // A positive but meaningless J_P (rounding noise of size ε·κ) whose
                            // hardening e^{ξ(1 − J_P)} underflows.
                            assert_eq!(e, Error::Overflow);
                            assert!(mat.moduli(Phase::Solid, Matrix::det(&raw)).is_err());
                            refused += 1;
                        }
                        Err(e) => {
                            assert!(matches!(e, Error::NonPositiveJ | Error::Overflow), "{e:?}");
                            refused += 1;
                        }
                    }
                }
                println!(
                    "{}: raw det ≤ 0 {bad_raw}, refused {refused}, ok {ok}",
                    T::NAME
                );
                assert!(bad_raw > 50 && refused >= bad_raw && ok > 500);
            }

            /// A liquid with an `F_E` and an `F_P` stretched beyond `1/ε` (a solid that melts
            /// after a long plastic history): the projection needs only `det F_E` and
            /// `det F_P`, so the update succeeds with a valid, isotropic state (before, the
            /// whole-`F` rule returned an `F_P` with `det ≤ 0`).
            #[test]
            fn ill_conditioned_liquid_history_is_kept_valid() {
                let mat = Material::<T> {
                    liquid: PhaseParams {
                        inv_lambda: 0.1,
                        ..PhaseParams::default()
                    },
                    ..Material::default()
                };
                let mut r = rng(12);
                let top = (1.0 / EPS).log10() / 2.0 + 1.0;
                let mut n = 0;
                for _ in 0..2000 {
                    let mut p = Particle::<T, D>::at_rest([0.3; D], 1.0, 1.0);
                    p.phase = Phase::Liquid;
                    for f in [&mut p.f_e, &mut p.f_p] {
                        let big = 10f64.powf(r.random_range(1.0..top));
                        let mut sigma = [1.0; D];
                        sigma[0] = big;
                        sigma[D - 1] = 1.0 / big;
                        *f = with_singular_values::<T, D>(&mut r, sigma);
                    }
                    let Ok((j_e, j_p)) = check_particle(&p) else {
                        continue;
                    };
                    let (q, _) = update_particle(&mat, 1e-3, &zero_sample(), &p).unwrap();
                    assert_accepted(&mat, &q, "liquid");
                    assert!(iso(&q.f_e).is_some() && iso(&q.f_p).is_some());
                    // J_E, J_P as computed by check_particle: the equilibrated determinant
                    // is the same computation scaled by a power of two (nothing under- or
                    // overflows here), so only the root (≤ 1 ulp, 2u, times d) and the
                    // state's det of r I ((d − 1) roundings) remain: 3d·u.
                    for (m, j) in [(q.f_e, j_e), (q.f_p, j_p)] {
                        let tol = (3 * D) as f64 * 0.5 * EPS * j as f64;
                        let got = Matrix::det(&m) as f64;
                        assert!((got - j as f64).abs() <= tol, "{got} vs {j}");
                    }
                    n += 1;
                }
                assert!(n > 1000, "{n}");
            }

            /// `J_P` that underflows from valid inputs: `F_P = 2^k I` with `J_P` at the
            /// bottom of the normal range, `F_E = c I` with `c ≪ 1 − θ_c`: the plastic flow
            /// multiplies `J_P` by `(c/(1 − θ_c))^d < 2^{−(p+7)}` (`p` mantissa digits),
            /// far below the smallest subnormal. Before, the update returned `det F_P = 0` with `Ok`.
            #[test]
            fn plastic_j_p_underflow_is_refused() {
                let mat = plastic::<T>();
                let k = (1 - MAX_EXP + 1 + D as i32 - 1).div_euclid(D as i32);
                let ke = -(DIGITS + 8 + D as i32 - 1) / D as i32;
                let mut p = Particle::<T, D>::at_rest([0.3; D], 1.0, 1.0);
                p.f_p = M::from_diagonal([(1.0 as T).scalbn(k); D]);
                p.f_e = M::from_diagonal([(1.0 as T).scalbn(ke); D]);
                let (_, j_p) = check_particle(&p).expect("valid input");
                assert!(
                    j_p >= T::MIN_POSITIVE
                        && j_p <= (2.0 as T).powi(D as i32 - 1) * T::MIN_POSITIVE
                );
                assert_eq!(
                    update_particle(&mat, 1e-3, &zero_sample(), &p).map(|_| ()),
                    Err(Error::Overflow)
                );
                // The same through the grid.
                let s =
                    Stencil::<T, D>::new(Kernel::Quadratic, Grid::Collocated, 0.5, &p.x).unwrap();
                let vel = vec![[0.0 as T; D]; s.len()];
                let grid = GridSample {
                    velocity: &vel,
                    temperature: None,
                };
                assert_eq!(
                    g2p_update(&mat, Kernel::Quadratic, 0.5, 1e-3, &grid, &p).map(|_| ()),
                    Err(Error::Overflow)
                );
            }

            /// `J_E` that underflows from a valid input: `F_E = 2^k I` with a subnormal
            /// `J_E = 2^{dk}`, compressed by `1/4` per axis, is Overflow (the matrix is fine,
            /// its determinant is not representable), not NonPositiveJ.
            #[test]
            fn j_e_underflow_is_overflow() {
                let k = MIN_SUB_EXP.div_euclid(D as i32) + 1;
                for phase in [Phase::Solid, Phase::Liquid] {
                    let mat = if phase == Phase::Solid {
                        Material::<T>::elastic(10.0, 10.0)
                    } else {
                        liquid_material::<T>()
                    };
                    let mut p = Particle::<T, D>::at_rest([0.3; D], 1.0, 1.0);
                    p.phase = phase;
                    p.f_e = M::from_diagonal([(1.0 as T).scalbn(k); D]);
                    let (j_e, _) = check_particle(&p).expect("valid input");
                    assert!(j_e > 0.0 && j_e < T::MIN_POSITIVE);
                    let mut s = zero_sample();
                    s.grad_v = M::from_diagonal([-750.0; D]);
                    assert_eq!(
                        update_particle(&mat, 1e-3, &s, &p).map(|_| ()),
                        Err(Error::Overflow)
                    );
                    let det = deformation::evolve(&p.f_e, &s.grad_v, 1e-3);
                    assert_eq!(det.map(|_| ()), Err(Error::Overflow));
                }
                // A singular matrix stays NonPositiveJ.
                let mut f = M::identity();
                f.cols[0] = f.cols[1];
                assert_eq!(check_det(&f), Err(Error::NonPositiveJ));
                assert!(det_equilibrated(&f).0 <= 0.0);
            }

            /// A tiny finite `h`: where `1/h` or `1/(κ h)` is not representable the status is
            /// Overflow; where only `1/(κ h²)` is not, G2P succeeds (it forms `C_p` in cell
            /// units) with the exact `C_p = 0` of a uniform velocity to rounding.
            #[test]
            fn tiny_h_is_overflow() {
                let x = [0.0 as T; D];
                // 1/h = 2^{MAX_EXP + 2}: not representable.
                let h0 = (1.0 as T).scalbn(-MAX_EXP - 2);
                assert!(h0 > 0.0);
                for kernel in [Kernel::Quadratic, Kernel::Cubic] {
                    for grid in [Grid::Collocated, Grid::Face(0), Grid::Face(D - 1)] {
                        assert_eq!(
                            Stencil::<T, D>::new(kernel, grid, h0, &x),
                            Err(Error::Overflow)
                        );
                        assert_eq!(
                            Stencil::<T, D>::check_position(grid, h0, &x),
                            Err(Error::Overflow)
                        );
                    }
                    assert_eq!(apic::inv_moment(kernel, h0), Err(Error::Overflow));
                }
                // The position limit stays InvalidArgument.
                let far = [(1.0 as T).scalbn(31); D];
                assert_eq!(
                    Stencil::<T, D>::new(Kernel::Quadratic, Grid::Collocated, 1.0, &far),
                    Err(Error::InvalidArgument)
                );

                // 1/h = 2^{MAX_EXP − 1} is finite, 1/(κh) = 2^{MAX_EXP + 1} is not.
                let h1 = (1.0 as T).scalbn(1 - MAX_EXP);
                let s = Stencil::<T, D>::new(Kernel::Quadratic, Grid::Collocated, h1, &x)
                    .expect("1/h finite");
                let vel = vec![[1.0 as T; D]; s.len()];
                assert_eq!(apic::gather(&s, &vel), Err(Error::Overflow));
                assert_eq!(
                    apic::gather_scalar(&s, &[1.0 as T; 64]),
                    Err(Error::Overflow)
                );
                let p = Particle::<T, D>::at_rest(x, 1.0, 1.0);
                let el = Material::<T>::elastic(10.0, 10.0);
                let grid = GridSample {
                    velocity: &vel,
                    temperature: None,
                };
                assert_eq!(
                    g2p_update(&el, Kernel::Quadratic, h1, h1, &grid, &p).map(|_| ()),
                    Err(Error::Overflow)
                );

                // h² underflows and 1/(κh²) overflows, 1/(κh) is fine.
                let h2 = (1.0 as T).scalbn(-MAX_EXP / 2 - 4);
                assert_eq!(
                    apic::inv_moment(Kernel::Quadratic, h2),
                    Err(Error::Overflow)
                );
                let x2 = [h2 * 0.3; D];
                let s = Stencil::<T, D>::new(Kernel::Quadratic, Grid::Collocated, h2, &x2).unwrap();
                let n = s.len();
                let vel = vec![[1.0 as T; D]; n];
                let grid = GridSample {
                    velocity: &vel,
                    temperature: None,
                };
                let mut p = Particle::<T, D>::at_rest(x2, 1.0, 1.0);
                p.v = [1.0; D];
                let (q, _) = g2p_update(&el, Kernel::Quadratic, h2, h2, &grid, &p)
                    .expect("representable result");
                assert_accepted(&el, &q, "tiny h");
                // Σ w_i (o − fx) = 0 exactly; computed: the sum's (n + 2)u and the weights'
                // 4d·u relative errors, times |o − fx| ≤ 2, divided by κ h.
                let bound = (n + 2 + 4 * D) as f64 * EPS / (0.25 * h2 as f64);
                assert!(
                    q.affine.max_abs() as f64 <= bound,
                    "{:?} > {bound}",
                    q.affine
                );

                // ∇v = Σ v_i ∇w_iᵀ of finite velocities overflows: |∇w| ∼ 1/h.
                let h3 = (1.0 as T).scalbn(-60);
                let x3 = [h3 * 0.3; D];
                let s = Stencil::<T, D>::new(Kernel::Quadratic, Grid::Collocated, h3, &x3).unwrap();
                let big = T::MAX.scalbn(-40);
                let vel: Vec<[T; D]> = (0..s.len())
                    .map(|r| [if r % 2 == 0 { big } else { -big }; D])
                    .collect();
                assert_eq!(apic::gather(&s, &vel).map(|_| ()), Err(Error::Overflow));
                let p = Particle::<T, D>::at_rest(x3, 1.0, 1.0);
                let grid = GridSample {
                    velocity: &vel,
                    temperature: None,
                };
                assert_eq!(
                    g2p_update(&el, Kernel::Quadratic, h3, 1e-3, &grid, &p).map(|_| ()),
                    Err(Error::Overflow)
                );
                // A NaN node value stays NonFinite.
                let mut vel = vec![[0.0 as T; D]; s.len()];
                vel[3][0] = T::NAN;
                assert_eq!(apic::gather(&s, &vel).map(|_| ()), Err(Error::NonFinite));
            }

            /// P2G with finite inputs whose node values overflow is Overflow; near the
            /// threshold, where only the cheap bound overflows, the nodes are checked one by
            /// one and P2G succeeds.
            #[test]
            fn p2g_overflow() {
                let el = Material::<T>::elastic(10.0, 10.0);
                let x = [0.3 as T; D];
                let root = T::MAX.sqrt();
                // m |v| > MAX.
                // (The largest quadratic weight here is ≥ 0.59^d ≥ 1/64.)
                let mut p = Particle::<T, D>::at_rest(x, root * 64.0, 1.0);
                p.v[0] = root;
                assert_eq!(
                    p2g(&el, Kernel::Quadratic, 0.5, &p).map(|_| ()),
                    Err(Error::Overflow)
                );
                // m |v| = MAX/2 and m |C| 2h = 0.52 MAX: the bound overflows, while every
                // node has |v + C (x_i − x_p)| ≤ (0.5 + 0.39) MAX (|x_i − x_p| ≤ 1.5h).
                let mut p = Particle::<T, D>::at_rest(x, 1.0, 1.0);
                p.v[0] = T::MAX * 0.5;
                p.affine.cols[0][0] = T::MAX * 0.26;
                let q = p2g(&el, Kernel::Quadratic, 1.0, &p).expect("every node finite");
                for r in 0..q.stencil.len() {
                    assert_eq!(q.node_checked(r), Ok(q.node(r)));
                }
                assert_eq!(q.node_checked(q.stencil.len()), Err(Error::InvalidArgument));
                // Heat: m c and m c T.
                let mut hm = heat_material::<T>(false);
                let mut p = Particle::<T, D>::at_rest(x, 4.0, 1.0);
                p.temperature = 300.0;
                hm.solid.heat_capacity = T::MAX * 0.5;
                assert_eq!(
                    p2g(&hm, Kernel::Quadratic, 0.5, &p).map(|_| ()),
                    Err(Error::Overflow)
                );
                hm.solid.heat_capacity = root;
                p.mass = 1.0;
                p.temperature = root * 64.0;
                assert_eq!(
                    p2g(&hm, Kernel::Quadratic, 0.5, &p).map(|_| ()),
                    Err(Error::Overflow)
                );
                // The stress force −V⁰ τ ∇w with |∇w| ∼ 1/h.
                let h = (1.0 as T).scalbn(8 - MAX_EXP);
                let stiff = Material::<T>::elastic(1e4, 1e4);
                let mut p = Particle::<T, D>::at_rest([h * 0.3; D], 1.0, 1.0);
                p.f_e = M::identity() * 1.5;
                assert_eq!(
                    p2g(&stiff, Kernel::Quadratic, h, &p).map(|_| ()),
                    Err(Error::Overflow)
                );
            }

            /// The force differential of finite inputs: `G = Σ δu ∇wᵀ` or the node forces
            /// overflow → Overflow, and `df` is not written.
            #[test]
            fn force_differential_overflow() {
                let sentinel = -7.25 as T;
                let mat = Material::<T>::elastic(1e3, 1e3);
                let n = Kernel::Quadratic.node_count(D);
                // Node forces ∼ μ δu / h².
                let h = (1.0 as T).scalbn(2 - MAX_EXP / 2);
                let p = Particle::<T, D>::at_rest([h * 0.3; D], 1.0, 1.0);
                let mut r = rng(5);
                let du: Vec<[T; D]> = (0..n)
                    .map(|_| core::array::from_fn(|_| r.random_range(-1.0..1.0)))
                    .collect();
                let mut df = vec![[sentinel; D]; n];
                assert_eq!(
                    force_differential(&mat, Kernel::Quadratic, h, &p, &du, &mut df),
                    Err(Error::Overflow)
                );
                assert!(df.iter().flatten().all(|&x| x == sentinel));
                // G itself overflows.
                let du = vec![[T::MAX * 0.5; D]; n];
                let p = Particle::<T, D>::at_rest([0.3; D], 1.0, 1.0);
                assert_eq!(
                    force_differential(&mat, Kernel::Quadratic, 0.01, &p, &du, &mut df),
                    Err(Error::Overflow)
                );
                assert!(df.iter().flatten().all(|&x| x == sentinel));
                // A NaN δu stays NonFinite; a normal call writes finite values.
                let mut du = vec![[1e-3 as T; D]; n];
                du[2][0] = T::NAN;
                assert_eq!(
                    force_differential(&mat, Kernel::Quadratic, 0.5, &p, &du, &mut df),
                    Err(Error::NonFinite)
                );
                du[2][0] = 0.0;
                force_differential(&mat, Kernel::Quadratic, 0.5, &p, &du, &mut df).unwrap();
                assert!(df.iter().flatten().all(|x| x.is_finite()));
            }

            /// Random inputs at extreme scales (deformation gradients with singular values
            /// over most of the exponent range, velocities and gradients up to near the
            /// overflow threshold, tiny and huge `Δt`, `h`, masses), every material level:
            /// `Ok` ⇒ the result passes every input check and a second call accepts it;
            /// an invalid input is refused with the error `check_particle` gives.
            #[test]
            fn ok_implies_next_call_accepts() {
                let mut r = rng(99);
                let e_mat = 0.9 * (MAX_EXP as f64) / D as f64;
                let e_big = 0.95 * MAX_EXP as f64;
                let mut counts = [0usize; 3];
                for case in 0..20_000 {
                    let mat = match case % 5 {
                        0 => Material::<T>::elastic(10.0, 10.0),
                        1 => plastic::<T>(),
                        2 => liquid_material::<T>(),
                        3 => heat_material::<T>(false),
                        _ => heat_material::<T>(true),
                    };
                    let mut p = Particle::<T, D>::at_rest(
                        core::array::from_fn(|_| log_uniform(&mut r, 20.0)),
                        log_uniform::<T>(&mut r, e_mat).abs(),
                        log_uniform::<T>(&mut r, e_mat).abs(),
                    );
                    p.phase = if case % 5 == 2 || (case % 5 == 4 && r.random_bool(0.5)) {
                        Phase::Liquid
                    } else {
                        Phase::Solid
                    };
                    let scale = |r: &mut Pcg64, e: f64| -> [f64; D] {
                        core::array::from_fn(|_| 2f64.powf(r.random_range(-e..e)))
                    };
                    let se = if r.random_bool(0.5) { e_mat } else { 4.0 };
                    let sp = if r.random_bool(0.5) { e_mat } else { 4.0 };
                    let sig_e = scale(&mut r, se);
                    let sig_p = scale(&mut r, sp);
                    p.f_e = with_singular_values::<T, D>(&mut r, sig_e);
                    p.f_p = with_singular_values::<T, D>(&mut r, sig_p);
                    if p.phase == Phase::Liquid && r.random_bool(0.5) {
                        p.f_e = M::identity() * (sig_e[0] as T);
                        p.f_p = M::identity() * (sig_p[0] as T);
                    }
                    p.v = core::array::from_fn(|_| log_uniform(&mut r, e_big));
                    p.affine =
                        M::from_diagonal(core::array::from_fn(|_| log_uniform(&mut r, 10.0)));
                    // A valid thermal state (heat on): T_m with a partial buffer, or away.
                    if let Some(h) = &mat.heat {
                        let (tm, l) = (h.melting_point, h.latent_heat);
                        match (p.phase, r.random_range(0..3)) {
                            (_, 0) => {
                                p.temperature = tm;
                                p.latent = r.random_range(0.0..1.0) * l;
                            }
                            (Phase::Solid, _) => {
                                p.temperature = tm - log_uniform::<T>(&mut r, 10.0).abs();
                                p.latent = 0.0;
                            }
                            (Phase::Liquid, _) => {
                                p.temperature = tm + log_uniform::<T>(&mut r, 10.0).abs();
                                p.latent = l;
                            }
                        }
                        if !h.phase_change {
                            p.latent = 0.0;
                        }
                    }
                    let e_s = if r.random_bool(0.3) { e_big } else { 8.0 };
                    let mut s = G2pSample::<T, D> {
                        v: core::array::from_fn(|_| log_uniform(&mut r, e_s)),
                        affine: M::ZERO,
                        grad_v: M::ZERO,
                        t_pic: p.temperature + log_uniform::<T>(&mut r, 12.0),
                        t_flip: log_uniform::<T>(&mut r, 12.0),
                    };
                    for j in 0..D {
                        for i in 0..D {
                            s.affine.cols[j][i] = log_uniform(&mut r, e_s);
                            s.grad_v.cols[j][i] = log_uniform(&mut r, e_s);
                        }
                    }
                    let dt = log_uniform::<T>(&mut r, 30.0).abs();
                    let valid = mat.validate(p.phase).and(check_particle(&p).map(|_| ()));
                    match update_particle(&mat, dt, &s, &p) {
                        Ok((q, _)) => {
                            assert_eq!(valid, Ok(()));
                            assert_accepted(&mat, &q, "update_particle");
                            counts[0] += 1;
                        }
                        Err(e) => {
                            if let Err(v) = valid {
                                assert_eq!(e, v);
                                counts[2] += 1;
                            } else {
                                assert!(
                                    matches!(e, Error::Overflow | Error::NonPositiveJ),
                                    "{e:?}"
                                );
                                counts[1] += 1;
                            }
                        }
                    }
                }
                println!(
                    "{} d={D}: ok {}, refused {}, invalid input {}",
                    T::NAME,
                    counts[0],
                    counts[1],
                    counts[2]
                );
                assert!(counts.iter().all(|&c| c > 1000), "{counts:?}");
            }

            /// As above through the grid: random `h` over the exponent range, random node
            /// velocities and temperatures; `Ok` ⇒ accepted, inside the position limit, and
            /// P2G refuses nothing about the state (a liquid's P2G is `Ok` or Overflow).
            #[test]
            fn g2p_ok_implies_p2g_accepts() {
                let mut r = rng(7);
                let mut ok = 0;
                for case in 0..5000 {
                    let mat = match case % 4 {
                        0 => Material::<T>::elastic(10.0, 10.0),
                        1 => plastic::<T>(),
                        2 => liquid_material::<T>(),
                        _ => heat_material::<T>(true),
                    };
                    let kernel = if r.random_bool(0.5) {
                        Kernel::Quadratic
                    } else {
                        Kernel::Cubic
                    };
                    let h = log_uniform::<T>(&mut r, 0.95 * MAX_EXP as f64).abs();
                    let x: [T; D] = core::array::from_fn(|_| {
                        let lim = (1u64 << 29) as f64;
                        h * r.random_range(-lim..lim) as T
                    });
                    let mut p = Particle::<T, D>::at_rest(x, 1.0, 1.0);
                    if case % 4 == 2 {
                        p.phase = Phase::Liquid;
                    }
                    let sigma: [f64; D] =
                        core::array::from_fn(|_| 2f64.powf(r.random_range(-3.0..3.0)));
                    p.f_e = with_singular_values::<T, D>(&mut r, sigma);
                    if let Some(hh) = &mat.heat {
                        p.temperature = hh.melting_point - 5.0;
                    }
                    let Ok(st) = Stencil::<T, D>::new(kernel, Grid::Collocated, h, &p.x) else {
                        continue;
                    };
                    let e_v = if r.random_bool(0.3) {
                        0.9 * MAX_EXP as f64
                    } else {
                        6.0
                    };
                    let vel: Vec<[T; D]> = (0..st.len())
                        .map(|_| core::array::from_fn(|_| log_uniform::<T>(&mut r, e_v) * h))
                        .collect();
                    let tn: Vec<T> = (0..st.len())
                        .map(|_| 273.0 + r.random_range(-50.0..50.0) as T)
                        .collect();
                    let to: Vec<T> = tn.iter().map(|t| t - 1.0).collect();
                    let grid = GridSample {
                        velocity: &vel,
                        temperature: Some((&tn, &to)),
                    };
                    let dt = log_uniform::<T>(&mut r, 20.0).abs();
                    let Ok((q, _)) = g2p_update(&mat, kernel, h, dt, &grid, &p) else {
                        continue;
                    };
                    ok += 1;
                    assert_accepted(&mat, &q, "g2p_update");
                    assert_eq!(
                        Stencil::<T, D>::check_position(Grid::Collocated, h, &q.x),
                        Ok(())
                    );
                    match p2g(&mat, kernel, h, &q) {
                        Ok(out) => {
                            for r in 0..out.stencil.len() {
                                assert!(out.node_checked(r).is_ok());
                            }
                        }
                        Err(Error::Overflow) => {}
                        Err(Error::NonPositiveJ) if q.phase == Phase::Solid => {}
                        Err(e) => panic!("p2g refused a g2p result: {e:?} for {q:?}"),
                    }
                }
                assert!(ok > 1000, "{ok}");
            }
        }
    };
}

contract_tests!(d2_f32, f32, 2);
contract_tests!(d2_f64, f64, 2);
contract_tests!(d3_f32, f32, 3);
contract_tests!(d3_f64, f64, 3);
