//! Batch transfers through grid views (`ampm_core::particle::transfer`), on every instruction
//! set of this CPU. One test binary; each module covers one transfer:
//!
//! 1. `p2g`: P2G equals the per-particle reference (`update::p2g` and `P2g::node`, accumulated
//!    in f64) within the rounding of the SIMD stress (bounded in tests/batch/paths.rs) and of the
//!    sums; interleaved node structs give the same bits as separate arrays; a particle's
//!    contribution does not depend on its index in the batch (for every material: the
//!    per-particle pass on lanes gives the bits of the one-by-one pass). MAC P2G conserves
//!    mass and momentum on every face grid and its forces sum to zero.
//! 2. `g2p`: G2P equals the per-particle reference (`g2p_update` on the gathered stencil
//!    values); a batch (with and without heat) gives the bits of calls of one particle.
//! 3. `g2p_nodes`: on a linear velocity field (collocated and MAC) G2P reproduces
//!    `v = v₀ + A x`, `C = A`, `∇v = A` (B-splines reproduce linear functions; an independent
//!    check of the node loops). NaN in a node that is read fails the particle; NaN in nodes no
//!    stencil reads is harmless.
//! 4. `failures`: outside the box, overflow (large m·v, large heat capacity, tiny h): the
//!    status, the first index, and nothing written (grid and particle bits unchanged).
//! 5. `force`: the force differential: exact mode equals `Stiffness::d_force_matrix` (itself
//!    checked by finite differences in tests/particle/stiffness.rs); `K` is symmetric; with the PSD
//!    option `⟨δu, K δu⟩ ≤ 0` for every `δu`, including a dilational part that is indefinite,
//!    and it equals the exact differential where that is already definite; unprepared slots
//!    are refused.
//! 6. `layouts`: G2P and the force differential give the same bits on separate node arrays,
//!    interleaved node structs and arrays of different strides (the read paths of the node
//!    sums), and the same bits on every vector instruction set.
//!
//! This file holds what the modules share: the dense test grid, the particle arrays, and the
//! materials and particles the tests run.
mod failures;
mod force;
mod g2p;
mod g2p_nodes;
mod layouts;
mod p2g;

use ampm_core::lane::{Isa, IsaKind};
use ampm_core::particle::transfer::g2p::G2pView;
use ampm_core::particle::transfer::p2g::P2gView;
use ampm_core::particle::transfer::{Channel, NodeBox, Particles};
use ampm_core::particle::{Dilation, Heat, Material, Particle, Phase, PhaseParams, Snow};
use ampm_core::{Mat, Matrix, Real};
use ampm_tools::workload::HaarRotation;
use rand::Rng;
use rand_pcg::Pcg64;

const CH: usize = 10;
const MASS: usize = 0;
const MOM: usize = 1;
const FORCE: usize = 4;
const HC: usize = 7;

/// A dense grid of `CH` channels (separate arrays, axis 0 fastest) over a node box.
#[derive(Clone)]
struct DenseGrid<T, const D: usize> {
    lo: [i32; D],
    dims: [i32; D],
    ch: Vec<Vec<T>>,
}

impl<T: Real, const D: usize> DenseGrid<T, D> {
    fn new(lo: [i32; D], dims: [i32; D]) -> Self {
        let len = dims.iter().map(|&d| d as usize).product();
        Self {
            lo,
            dims,
            ch: vec![vec![T::ZERO; len]; CH],
        }
    }
    fn stride(&self) -> [isize; D] {
        let mut s = [1isize; D];
        for a in 1..D {
            s[a] = s[a - 1] * self.dims[a - 1] as isize;
        }
        s
    }
    fn index(&self, idx: [i32; D]) -> usize {
        let s = self.stride();
        (0..D)
            .map(|a| (idx[a] - self.lo[a]) as isize * s[a])
            .sum::<isize>() as usize
    }
    fn nodes(&self) -> NodeBox<D> {
        NodeBox {
            lo: self.lo,
            dims: self.dims,
        }
    }
    fn out(&mut self, c: usize) -> Channel<*mut T, D> {
        Channel {
            data: self.ch[c].as_mut_ptr(),
            stride: self.stride(),
        }
    }
    fn inp(&self, c: usize) -> Channel<*const T, D> {
        Channel {
            data: self.ch[c].as_ptr(),
            stride: self.stride(),
        }
    }
    fn p2g_view(&mut self) -> P2gView<T, D> {
        P2gView {
            nodes: self.nodes(),
            mass: self.out(MASS),
            momentum: std::array::from_fn(|a| self.out(MOM + a)),
            force: std::array::from_fn(|a| self.out(FORCE + a)),
            heat_capacity: self.out(HC),
            thermal_energy: self.out(HC + 1),
            conductivity: self.out(HC + 2),
        }
    }
    /// Velocities in channels `MOM..`, temperatures new/old in `HC`, `HC + 1`.
    fn g2p_view(&self) -> G2pView<T, D> {
        G2pView {
            nodes: self.nodes(),
            velocity: std::array::from_fn(|a| self.inp(MOM + a)),
            temperature: self.inp(HC),
            temperature_old: self.inp(HC + 1),
        }
    }
    fn bits(&self) -> Vec<Vec<u64>> {
        self.ch
            .iter()
            .map(|c| c.iter().map(|x| x.to_f64().to_bits()).collect())
            .collect()
    }
}

/// Particle arrays owned by the test.
#[derive(Clone, Debug, PartialEq)]
struct Store<T> {
    x: Vec<T>,
    v: Vec<T>,
    affine: Vec<T>,
    f_e: Vec<T>,
    f_p: Vec<T>,
    mass: Vec<T>,
    volume0: Vec<T>,
    temperature: Vec<T>,
    latent: Vec<T>,
    phase: Vec<u8>,
}

impl<T: Real> Store<T> {
    fn from<const D: usize>(ps: &[Particle<T, D>]) -> Self {
        let mut s = Store {
            x: vec![],
            v: vec![],
            affine: vec![],
            f_e: vec![],
            f_p: vec![],
            mass: vec![],
            volume0: vec![],
            temperature: vec![],
            latent: vec![],
            phase: vec![],
        };
        for p in ps {
            s.x.extend_from_slice(&p.x);
            s.v.extend_from_slice(&p.v);
            for m in [&p.affine, &p.f_e, &p.f_p] {
                let dst = if std::ptr::eq(m, &p.affine) {
                    &mut s.affine
                } else if std::ptr::eq(m, &p.f_e) {
                    &mut s.f_e
                } else {
                    &mut s.f_p
                };
                for j in 0..D {
                    dst.extend_from_slice(&m.cols[j]);
                }
            }
            s.mass.push(p.mass);
            s.volume0.push(p.volume0);
            s.temperature.push(p.temperature);
            s.latent.push(p.latent);
            s.phase.push(p.phase as u8);
        }
        s
    }
    fn get<const D: usize>(&self, i: usize) -> Particle<T, D> {
        let mat = |v: &[T]| {
            Mat::<T, D>::from_cols(std::array::from_fn(|j| {
                std::array::from_fn(|r| v[D * D * i + D * j + r])
            }))
        };
        Particle {
            x: std::array::from_fn(|a| self.x[D * i + a]),
            v: std::array::from_fn(|a| self.v[D * i + a]),
            affine: mat(&self.affine),
            f_e: mat(&self.f_e),
            f_p: mat(&self.f_p),
            mass: self.mass[i],
            volume0: self.volume0[i],
            temperature: self.temperature[i],
            latent: self.latent[i],
            phase: if self.phase[i] == 0 {
                Phase::Solid
            } else {
                Phase::Liquid
            },
        }
    }
    /// The bits of every array G2P writes (positions, velocities, `C`, `F_E`, `F_P`,
    /// temperatures, latent heat, phases).
    fn bits(&self) -> Vec<u64> {
        [
            &self.x,
            &self.v,
            &self.affine,
            &self.f_e,
            &self.f_p,
            &self.temperature,
            &self.latent,
        ]
        .iter()
        .flat_map(|v| v.iter().map(|x| x.to_f64().to_bits()))
        .chain(self.phase.iter().map(|&c| u64::from(c)))
        .collect()
    }
    fn raw(&mut self) -> Particles<T> {
        Particles {
            x: self.x.as_mut_ptr(),
            v: self.v.as_mut_ptr(),
            affine: self.affine.as_mut_ptr(),
            f_e: self.f_e.as_mut_ptr(),
            f_p: self.f_p.as_mut_ptr(),
            mass: self.mass.as_ptr(),
            volume0: self.volume0.as_ptr(),
            temperature: self.temperature.as_mut_ptr(),
            latent: self.latent.as_mut_ptr(),
            phase: self.phase.as_mut_ptr(),
        }
    }
}

/// Every instruction set of this CPU, AVX-512 in each of its forms (`Isa::joined_rows`: two
/// eight-lane node rows in one register; `Isa::narrow_chunks`: P2G's `f32` chunks of two
/// vectors), so that every form is tested on any AVX-512 machine whichever is its default.
fn isas() -> Vec<Isa> {
    Isa::available()
        .into_iter()
        .flat_map(|i| match i.kind() {
            IsaKind::Avx512 => vec![
                i.with_joined_rows(false).with_narrow_chunks(false),
                i.with_joined_rows(true).with_narrow_chunks(false),
                i.with_joined_rows(false).with_narrow_chunks(true),
            ],
            _ => vec![i],
        })
        .collect()
}

fn rand_mat<const D: usize>(rng: &mut Pcg64, r: f64) -> Mat<f64, D>
where
    Mat<f64, D>: Matrix<Scalar = f64>,
{
    Mat::from_cols(std::array::from_fn(|_| {
        std::array::from_fn(|_| rng.random_range(-r..r))
    }))
}

/// `F = R₁ diag(σ) R₂ᵀ`, σ in `[lo, hi]`.
fn deformation<const D: usize>(rng: &mut Pcg64, lo: f64, hi: f64) -> Mat<f64, D>
where
    Mat<f64, D>: Matrix<Scalar = f64, Vector = [f64; D]> + HaarRotation,
{
    let s: [f64; D] = std::array::from_fn(|_| rng.random_range(lo..hi));
    <Mat<f64, D>>::haar(rng) * Mat::from_diagonal(s) * <Mat<f64, D>>::haar(rng).transpose()
}

const TM: f64 = 273.15;
const LATENT: f64 = 3.34e5;

/// The materials the tests run: elastic, snow, ice/water with heat and phase change (mixed
/// phases), a liquid with the pressure solve.
fn materials<T: Real>() -> Vec<(&'static str, Material<T>)> {
    let c = T::from_f64;
    let solid = PhaseParams {
        mu: c(3.0e4),
        inv_lambda: c(1.0 / 5.0e4),
        heat_capacity: c(2100.0),
        conductivity: c(2.2),
    };
    let liquid = PhaseParams {
        mu: T::ZERO,
        inv_lambda: c(1.0 / 2.0e4),
        heat_capacity: c(4200.0),
        conductivity: c(0.6),
    };
    let elastic = Material {
        solid,
        liquid,
        ..Material::default()
    };
    let snow = Material {
        plasticity: Some(Snow {
            critical_compression: c(0.025),
            critical_stretch: c(0.0075),
            hardening: c(10.0),
        }),
        ..elastic
    };
    let thermal = Material {
        heat: Some(Heat {
            flip: c(0.95),
            melting_point: c(TM),
            latent_heat: c(LATENT),
            phase_change: true,
        }),
        ..elastic
    };
    let fluid = Material {
        dilation: Dilation::PressureSolve,
        ..elastic
    };
    vec![
        ("elastic", elastic),
        ("snow", snow),
        ("thermal", thermal),
        ("pressure-solve", fluid),
    ]
}

/// `n` particles inside `[4h, (cells − 4)h]^d`, valid for `mat`.
fn particles<T: Real, const D: usize>(
    rng: &mut Pcg64,
    n: usize,
    h: f64,
    cells: i32,
    mat: &Material<T>,
) -> Vec<Particle<T, D>>
where
    Mat<f64, D>: Matrix<Scalar = f64, Vector = [f64; D]> + HaarRotation,
    Mat<T, D>: Matrix<Scalar = T>,
{
    let phase_change = mat.heat.is_some_and(|h| h.phase_change);
    (0..n)
        .map(|i| {
            let x: [f64; D] =
                std::array::from_fn(|_| rng.random_range(4.0 * h..(cells as f64 - 4.0) * h));
            let liquid = phase_change && i % 3 == 1;
            let f_e = if liquid {
                Mat::<f64, D>::identity() * rng.random_range(0.9..1.1)
            } else {
                deformation::<D>(rng, 0.7, 1.4)
            };
            let f_p = if mat.plasticity.is_some() {
                deformation::<D>(rng, 0.9, 1.1)
            } else if liquid {
                Mat::<f64, D>::identity() * rng.random_range(0.95..1.05)
            } else {
                Mat::identity()
            };
            let (temperature, latent) = match (liquid, i % 3) {
                (true, _) => (TM + rng.random_range(0.0..20.0), LATENT),
                (false, 2) => (TM, rng.random_range(0.0..LATENT)),
                _ => (TM - rng.random_range(0.0..20.0), 0.0),
            };
            let p = Particle::<f64, D> {
                x,
                v: std::array::from_fn(|_| rng.random_range(-2.0..2.0)),
                affine: rand_mat::<D>(rng, 3.0),
                f_e,
                f_p,
                mass: rng.random_range(0.5..2.0) * h.powi(D as i32) * 1000.0,
                volume0: rng.random_range(0.5..2.0) * h.powi(D as i32),
                temperature,
                latent,
                phase: if liquid { Phase::Liquid } else { Phase::Solid },
            };
            cast_particle(&p)
        })
        .collect()
}

fn cast_particle<T: Real, const D: usize>(p: &Particle<f64, D>) -> Particle<T, D>
where
    Mat<f64, D>: Matrix<Scalar = f64>,
    Mat<T, D>: Matrix<Scalar = T>,
{
    Particle {
        x: p.x.map(T::from_f64),
        v: p.v.map(T::from_f64),
        affine: p.affine.cast(),
        f_e: p.f_e.cast(),
        f_p: p.f_p.cast(),
        mass: T::from_f64(p.mass),
        volume0: T::from_f64(p.volume0),
        temperature: T::from_f64(p.temperature),
        latent: T::from_f64(p.latent),
        phase: p.phase,
    }
}

/// Six particles: 0, 1 and 3, 4, 5 around node (6, 6, 6), 2 far away (P2G and apply sum a run
/// of nearby particles before touching the grid).
fn runs_of_particles<T: Real, const D: usize>(h: f64) -> Vec<Particle<T, D>> {
    (0..6)
        .map(|k| {
            let c = if k == 2 { 9.0 } else { 5.0 };
            let x = std::array::from_fn(|a| T::from_f64((c + 0.1 + 0.13 * (k + a) as f64) * h));
            let mut p = Particle::<T, D>::at_rest(x, T::from_f64(1.0e-3), T::from_f64(1.0e-6));
            p.v = std::array::from_fn(|a| T::from_f64(0.1 * (a + 1) as f64));
            p.f_e.cols[0][0] = T::from_f64(1.01 + 0.01 * k as f64);
            p
        })
        .collect()
}
