//! Tests of the MPM particle updates (`ampm_core::particle`), generated for every scalar ×
//! dimension (modules `d2_f32`, `d2_f64`, `d3_f32`, `d3_f64`) by one macro (the batch transfers
//! and their C ABI are in tests/transfer/). One test binary; each module defines the tests of one
//! concern as a macro that `particle_tests!` expands in every scalar × dimension module:
//!
//! 1. `stencil`: B-spline stencils (identities, gradients, refused inputs).
//! 2. `affine`: APIC affine reproduction and the P2G/G2P round trip.
//! 3. `deformation_gradient`: the remedy, snow plasticity, the liquid projection.
//! 4. `material`: pressure, latent heat, the levels that are off.
//! 5. `stiffness`: the force differential (finite differences, PSD projection).
//!
//! Tolerances are in units of the scalar's ε and are derived where they are stated: a sum of
//! `n` products of `k` rounded factors, each factor `O(1)`, has an error of at most about
//! `(n + k)·ε` times the sum of the magnitudes.
#![allow(clippy::needless_range_loop)] // index loops mirror the formulas

#[path = "../common/mod.rs"]
mod common;
#[macro_use]
mod affine;
#[macro_use]
mod deformation_gradient;
#[macro_use]
mod material;
#[macro_use]
mod stencil;
#[macro_use]
mod stiffness;

use ampm_core::particle::apic;
use ampm_core::particle::deformation::{self, evolve, increment, liquid_projection};
use ampm_core::particle::dilation;
use ampm_core::particle::thermal::{absorb, HeatSplit, ThermalState};
use ampm_core::particle::update::{self, elastic_energy, force_differential, Stiffness};
use ampm_core::particle::{
    g2p_update, kirchhoff_stress, Definiteness, Dilation, Grid, GridSample, Kernel, Material,
    Particle, Phase, PhaseParams, Snow, Stencil,
};
use ampm_core::{Error, Mat, Matrix, Real};
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;

use common::heat_material;

/// Independent 1D B-splines in f64 (Steffen, Kirby, Berzins 2008, written out again).
fn bspline(k: Kernel, d: f64) -> f64 {
    let a = d.abs();
    match k {
        Kernel::Quadratic if a < 0.5 => 0.75 - a * a,
        Kernel::Quadratic if a < 1.5 => 0.5 * (1.5 - a).powi(2),
        Kernel::Cubic if a < 1.0 => 0.5 * a.powi(3) - a * a + 2.0 / 3.0,
        Kernel::Cubic if a < 2.0 => (2.0 - a).powi(3) / 6.0,
        _ => 0.0,
    }
}

fn rng(seed: u64) -> Pcg64 {
    Pcg64::seed_from_u64(seed)
}

macro_rules! particle_tests {
    ($m:ident, $t:ty, $d:literal) => {
        mod $m {
            use super::*;
            type T = $t;
            const D: usize = $d;
            type M = Mat<T, D>;
            const EPS: f64 = <T as Real>::EPSILON as f64;

            fn rand_pos(r: &mut Pcg64, h: f64, cells: f64) -> [T; D] {
                let mut x = [0.0 as T; D];
                for c in x.iter_mut() {
                    *c = (r.random_range(-cells..cells) * h) as T;
                }
                x
            }

            fn rand_mat(r: &mut Pcg64, s: f64) -> M {
                let mut m = M::ZERO;
                for j in 0..D {
                    for i in 0..D {
                        m.cols[j][i] = (r.random_range(-1.0..1.0) * s) as T;
                    }
                }
                m
            }

            fn grids() -> Vec<Grid> {
                let mut g = vec![Grid::Collocated];
                for a in 0..D {
                    g.push(Grid::Face(a));
                }
                g
            }

            stencil_tests!();
            affine_tests!();
            deformation_gradient_tests!();
            material_tests!();
            stiffness_tests!();
        }
    };
}

particle_tests!(d2_f32, f32, 2);
particle_tests!(d2_f64, f64, 2);
particle_tests!(d3_f32, f32, 3);
particle_tests!(d3_f64, f64, 3);
