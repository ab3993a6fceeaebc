//! Per-particle cost of a host-style MPM step through grid views, per modelling level, 2D and
//! 3D, f32 and f64, quadratic kernel, on every instruction set of this CPU.
//!
//! `cargo bench -p ampm-tools --bench particle_levels`. A block of particles (2 per cell per
//! axis, sorted by cell as a host keeps them) in a dense grid (separate arrays, axis 0
//! fastest). Each sample of `step/<level>/<case>/<isa>` runs what a host runs per step: zero
//! the grid, P2G (`transfer::p2g::p2g` with `impulse_dt = Δt`: mass and `m v* + Δt f`, no
//! force channel), and G2P with the particle update (`transfer::g2p::g2p_update`) from fixed
//! node velocities (the grid solve between them is the host's and not timed).
//! `Throughput::Elements(n)`: criterion's time per element is ns per particle per step.
//!
//! Levels:
//! - `fluid`: liquid particles, `μ = 0`, explicit dilation — no decomposition anywhere;
//! - `elastic`: fixed corotated `Â` (one SIMD decomposition in P2G) + dilation;
//! - `plastic`: + snow plasticity (one SVD more in the update);
//! - `thermal`: + heat transfer and phase change (heat channels, temperatures gathered).
//!
//! `force_apply/<case>/<isa>` is one Krylov iteration of an implicit step: the prepared force
//! differential (`transfer::force::apply`, PSD option) from node displacements to node forces;
//! `force_prepare/<case>/<isa>` its once-per-Newton-step preparation.

use ampm_core::kernel::batch::BatchReal;
use ampm_core::kernel::{Dim, LaneDim};
use ampm_core::lane::Isa;
use ampm_core::particle::implicit::slot_len;
use ampm_core::particle::transfer::force::{self, ForceView};
use ampm_core::particle::transfer::g2p::{self, G2pArgs, G2pView};
use ampm_core::particle::transfer::p2g::{self, P2gArgs, P2gView};
use ampm_core::particle::transfer::{Channel, NodeBox, Particles};
use ampm_core::particle::{
    Definiteness, Dilation, Grid, Heat, Kernel, Material, Phase, PhaseParams, Snow,
};
use ampm_core::polar::{DefaultSvd, SvdMethod};
use ampm_core::{Mat, Matrix, Real};
use criterion::measurement::WallTime;
use criterion::{criterion_group, criterion_main, BenchmarkGroup, Criterion, Throughput};
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;
use std::hint::black_box;
use std::time::Duration;

const H: f64 = 0.02;
const DT: f64 = 1e-4;
const TM: f64 = 273.15;

/// Particles per axis of the block: 38³ = 54,872 in 3D, 234² = 54,756 in 2D.
fn side(d: usize) -> usize {
    if d == 3 {
        38
    } else {
        234
    }
}

fn material<T: Real>(level: &str) -> Material<T> {
    let c = T::from_f64;
    let solid = PhaseParams {
        mu: c(3.0e5),
        inv_lambda: c(1.0 / 5.0e5),
        heat_capacity: c(2100.0),
        conductivity: c(2.2),
    };
    let liquid = PhaseParams {
        mu: T::ZERO,
        inv_lambda: c(1.0 / 2.0e5),
        heat_capacity: c(4200.0),
        conductivity: c(0.6),
    };
    let base = Material {
        solid,
        liquid,
        hessian: Definiteness::Projected,
        ..Material::default()
    };
    match level {
        "plastic" => Material {
            plasticity: Some(Snow {
                critical_compression: c(0.025),
                critical_stretch: c(0.0075),
                hardening: c(10.0),
            }),
            ..base
        },
        "thermal" => Material {
            heat: Some(Heat {
                flip: c(0.95),
                melting_point: c(TM),
                latent_heat: c(3.34e5),
                phase_change: true,
            }),
            ..base
        },
        "fluid" => Material {
            dilation: Dilation::Explicit,
            ..base
        },
        _ => base,
    }
}

/// Owned particle arrays and a dense grid.
struct Scene<T, const D: usize> {
    n: usize,
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
    dims: [i32; D],
    grid: Vec<Vec<T>>,
}

impl<T: Real, const D: usize> Scene<T, D> {
    fn new(level: &str) -> Self {
        let s = side(D);
        let n = s.pow(D as u32);
        let mut rng = Pcg64::seed_from_u64(1);
        let liquid = level == "fluid";
        let mut sc = Scene {
            n,
            x: Vec::with_capacity(n * D),
            v: Vec::with_capacity(n * D),
            affine: vec![T::ZERO; n * D * D],
            f_e: Vec::with_capacity(n * D * D),
            f_p: Vec::with_capacity(n * D * D),
            mass: vec![T::from_f64(1000.0 * (H / 2.0).powi(D as i32)); n],
            volume0: vec![T::from_f64((H / 2.0).powi(D as i32)); n],
            temperature: vec![T::from_f64(TM - 5.0); n],
            latent: vec![T::ZERO; n],
            phase: vec![if liquid { Phase::Liquid } else { Phase::Solid } as u8; n],
            dims: [(s / 2 + 8) as i32; D],
            grid: Vec::new(),
        };
        for i in 0..n {
            let mut q = i;
            for _ in 0..D {
                // Particles at (k + ¼ + jitter)·h/2 from 4 cells in: sorted by cell.
                let k = q % s;
                q /= s;
                let jitter = rng.random_range(-0.1..0.1);
                sc.x.push(T::from_f64((4.0 + (k as f64 + 0.5 + jitter) * 0.5) * H));
                sc.v.push(T::from_f64(rng.random_range(-0.1..0.1)));
            }
            for j in 0..D {
                for r in 0..D {
                    let id = if r == j { 1.0 } else { 0.0 };
                    let e = if liquid {
                        0.0
                    } else {
                        rng.random_range(-0.05..0.05)
                    };
                    sc.f_e.push(T::from_f64(id + e));
                    sc.f_p.push(T::from_f64(id));
                }
            }
        }
        let nodes: usize = sc.dims.iter().map(|&d| d as usize).product();
        sc.grid = vec![vec![T::ZERO; nodes]; 2 + D];
        sc
    }

    fn particles(&mut self) -> Particles<T> {
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

    fn stride(&self) -> [isize; D] {
        let mut s = [1isize; D];
        for a in 1..D {
            s[a] = s[a - 1] * self.dims[a - 1] as isize;
        }
        s
    }

    fn nodes(&self) -> NodeBox<D> {
        NodeBox {
            lo: [0; D],
            dims: self.dims,
        }
    }
}

fn step<T: BatchReal, const D: usize>(g: &mut BenchmarkGroup<WallTime>, level: &str, name: &str)
where
    Dim<D>: LaneDim<D>,
    Mat<T, D>: Matrix<Scalar = T, Vector = [T; D]>,
    DefaultSvd: SvdMethod<Mat<T, D>>,
{
    let mat = material::<T>(level);
    let mut sc = Scene::<T, D>::new(level);
    let heat = mat.heat.is_some();
    // Channels: 0 mass, 1..=D momentum (velocities for G2P), D+1 heat capacity / T new,
    // and thermal energy / T old reuse the last one (timing only).
    let stride = sc.stride();
    let ps = sc.particles();
    let p2g_args = P2gArgs {
        kernel: Kernel::Quadratic,
        grid: Grid::Collocated,
        h: T::from_f64(H),
        impulse_dt: T::from_f64(DT),
    };
    let g2p_args = G2pArgs {
        kernel: Kernel::Quadratic,
        h: T::from_f64(H),
        dt: T::from_f64(DT),
    };
    let n = sc.n;
    g.throughput(Throughput::Elements(n as u64));
    for isa in Isa::available() {
        g.bench_function(format!("step/{level}/{name}/{}", isa.name()), |b| {
            b.iter(|| {
                for c in sc.grid.iter_mut() {
                    c.iter_mut().for_each(|x| *x = T::ZERO);
                }
                let out = |c: usize, grid: &mut Vec<Vec<T>>| Channel {
                    data: grid[c].as_mut_ptr(),
                    stride,
                };
                let view = P2gView {
                    nodes: NodeBox {
                        lo: [0; D],
                        dims: sc.dims,
                    },
                    mass: out(0, &mut sc.grid),
                    momentum: std::array::from_fn(|a| out(1 + a, &mut sc.grid)),
                    force: [Channel::<*mut T, D>::none(); D],
                    heat_capacity: if heat {
                        out(D + 1, &mut sc.grid)
                    } else {
                        Channel::<*mut T, D>::none()
                    },
                    thermal_energy: if heat {
                        out(D + 1, &mut sc.grid)
                    } else {
                        Channel::<*mut T, D>::none()
                    },
                    conductivity: Channel::<*mut T, D>::none(),
                };
                // SAFETY: the arrays hold n particles; the channels cover the box.
                let s1 = unsafe { p2g::p2g(isa, &mat, &p2g_args, n, &ps, &view) };
                // Node velocities: small and fixed (the host's solve is not timed).
                for c in 1..=D {
                    sc.grid[c].iter_mut().for_each(|x| *x = T::from_f64(1e-3));
                }
                if heat {
                    sc.grid[D + 1]
                        .iter_mut()
                        .for_each(|x| *x = T::from_f64(TM - 4.0));
                }
                let inp = |c: usize| Channel {
                    data: sc.grid[c].as_ptr(),
                    stride,
                };
                let gv = G2pView {
                    nodes: sc.nodes(),
                    velocity: std::array::from_fn(|a| inp(1 + a)),
                    temperature: inp(D + 1),
                    temperature_old: inp(D + 1),
                };
                // SAFETY: as above.
                let s2 = unsafe { g2p::g2p_update(isa, &mat, &g2p_args, n, &ps, &gv, None) };
                black_box((s1, s2));
            })
        });
    }
}

fn implicit<T: BatchReal, const D: usize>(g: &mut BenchmarkGroup<WallTime>, name: &str)
where
    Dim<D>: LaneDim<D>,
    Mat<T, D>: Matrix<Scalar = T, Vector = [T; D]>,
{
    let mat = material::<T>("elastic");
    let mut sc = Scene::<T, D>::new("elastic");
    let n = sc.n;
    let stride = sc.stride();
    let ps = sc.particles();
    let mut slots = vec![T::ZERO; n * slot_len(D)];
    g.throughput(Throughput::Elements(n as u64));
    for isa in Isa::available() {
        g.bench_function(format!("force_prepare/{name}/{}", isa.name()), |b| {
            // SAFETY: n particles, n slots.
            b.iter(|| unsafe { force::prepare::<T, D>(isa, &mat, n, &ps, slots.as_mut_ptr()) })
        });
    }
    // SAFETY: n particles, n slots (prepared here too, so that a filtered run applies valid
    // slots).
    let st = unsafe { force::prepare::<T, D>(Isa::detect(), &mat, n, &ps, slots.as_mut_ptr()) };
    assert_eq!(st.error, None);
    let mut du: Vec<Vec<T>> = vec![vec![T::from_f64(1e-6); sc.grid[0].len()]; D];
    let mut df: Vec<Vec<T>> = vec![vec![T::ZERO; sc.grid[0].len()]; D];
    let view = ForceView {
        nodes: sc.nodes(),
        du: std::array::from_fn(|a| Channel {
            data: du[a].as_ptr(),
            stride,
        }),
        df: std::array::from_fn(|a| Channel {
            data: df[a].as_mut_ptr(),
            stride,
        }),
    };
    for isa in Isa::available() {
        g.bench_function(format!("force_apply/{name}/{}", isa.name()), |b| {
            b.iter(|| {
                // SAFETY: as above.
                unsafe {
                    force::apply::<T, D>(
                        isa,
                        Kernel::Quadratic,
                        T::from_f64(H),
                        n,
                        sc.x.as_ptr(),
                        slots.as_ptr(),
                        &view,
                    )
                }
            })
        });
    }
    du.clear();
    df.clear();
}

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("particle");
    g.sample_size(10)
        .warm_up_time(Duration::from_millis(300))
        .measurement_time(Duration::from_secs(2));
    for level in ["fluid", "elastic", "plastic", "thermal"] {
        step::<f32, 3>(&mut g, level, "3d_f32");
        step::<f32, 2>(&mut g, level, "2d_f32");
        step::<f64, 3>(&mut g, level, "3d_f64");
        step::<f64, 2>(&mut g, level, "2d_f64");
    }
    implicit::<f32, 3>(&mut g, "3d_f32");
    implicit::<f64, 3>(&mut g, "3d_f64");
    implicit::<f32, 2>(&mut g, "2d_f32");
    implicit::<f64, 2>(&mut g, "2d_f64");
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
