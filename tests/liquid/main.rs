//! Liquids over long runs, and the contract of the particle update: `Ok` only with a state
//! that the next call accepts, with the statuses of `include/ampm.h` (a finite input whose
//! result is not representable is `Overflow`).
//!
//! One test binary; each module covers one concern:
//!
//! 1. `long_runs`: long runs (10 s simulated, 10⁴ steps, f32 and f64): a sheared and an
//!    extended 2D liquid, a stirred 3D liquid, driven through `update_particle` with a
//!    prescribed `∇v`; the liquid state is `(J_E, J_P)` only.
//! 2. `regressions`: an `F_E` stretched beyond `1/ε` under snow plasticity, a `J_P` or `J_E`
//!    that underflows from valid inputs, a tiny finite `h`, P2G and the force differential
//!    with finite inputs whose results overflow.
//! 3. `property`: a property loop over random inputs at extreme scales: every `Ok` passes
//!    `check_particle` (and the heat-state and hardening checks), and a second call accepts it.
//!
//! The regressions and the property loop run for every scalar × dimension: their modules
//! define the tests as macros, which this file expands in one module per pair (`d2_f32`, …).
//! This file also holds what the modules share: the f64 reference helpers, the materials, the
//! check of an accepted particle and the random inputs.
//!
//! Tolerances are derived where they are stated, in units of the scalar's ε (the spacing at
//! 1, twice the unit roundoff `u`): a determinant evaluated in floating point is off by at
//! most `(d + 2) u · perm(|M|)` (`perm`: the permanent, the sum of the magnitudes of the
//! determinant's terms), and relative entry perturbations `δ` move it by at most
//! `d · δ · perm(|M|)` to first order (Laplace expansion along each row).
#![allow(clippy::needless_range_loop)] // index loops mirror the formulas

#[path = "../common/mod.rs"]
mod common;
#[macro_use]
mod property;
#[macro_use]
mod regressions;
mod long_runs;

use ampm_core::particle::apic;
use ampm_core::particle::deformation::{self, check_det, det_equilibrated};
use ampm_core::particle::thermal::{check_state, ThermalState};
use ampm_core::particle::update::{
    check_particle, force_differential, p2g, update_particle, G2pSample,
};
use ampm_core::particle::{
    g2p_update, Grid, GridSample, Kernel, Material, Particle, Phase, PhaseParams, Snow, Stencil,
};
use ampm_core::polar::{DefaultSvd, SvdMethod};
use ampm_core::{Error, Mat, Matrix, Real};
use ampm_tools::workload::HaarRotation;
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;

use common::heat_material;

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
// Regressions and the property loop, for every scalar × dimension.

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

/// `R diag(σ) Sᵀ` rounded to `T`.
/// (`R`, `S` Haar-random rotations, `ampm_tools::workload::HaarRotation`.)
fn with_singular_values<T: Real, const D: usize>(r: &mut Pcg64, sigma: [f64; D]) -> Mat<T, D>
where
    Mat<f64, D>: HaarRotation,
{
    let a = Mat::<f64, D>::haar(r);
    let b = Mat::<f64, D>::haar(r);
    let mut m = [[0.0; D]; D];
    for i in 0..D {
        for j in 0..D {
            for k in 0..D {
                m[i][j] += a.cols[k][i] * sigma[k] * b.cols[k][j];
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

            regression_tests!();

            property_tests!();
        }
    };
}

contract_tests!(d2_f32, f32, 2);
contract_tests!(d2_f64, f64, 2);
contract_tests!(d3_f32, f32, 3);
contract_tests!(d3_f64, f64, 3);
