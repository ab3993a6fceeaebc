//! Per-particle cost of each modelling level of the particle update, 2D and 3D,
//! f32 and f64.
//!
//! `cargo bench -p ampm-tools --bench particle_levels`. Each sample runs P2G
//! (`ampm_core::particle::p2g` plus the per-node contributions, summed so none is optimised
//! away) and the G2P update (`g2p_update`) for a batch of `N` particles with pre-gathered grid
//! values; `Throughput::Elements(N)` makes criterion report particles per second, and the
//! median time per batch divided by `N` is the cost per particle and time step.
//!
//! Levels (each adds to the previous one, except `fluid`):
//! - `fluid`: liquid, `μ = 0`, explicit dilation — no polar decomposition;
//! - `elastic`: fixed corotated `Â` (one decomposition) + dilation;
//! - `plastic`: + snow plasticity (one SVD more in the update);
//! - `thermal`: + heat transfer (temperature gathered, heat P2G);
//! - `phase`: + latent heat and phase change (particles at the melting point);
//! - `implicit-apply`, `implicit-apply-psd`: one Krylov iteration's force differential per
//!   particle (`Stiffness::apply` with `Ĉ` or `Ĉ⁺`, dilation in the pressure solve), the
//!   stiffness prepared once per step and not timed here.

use ampm_core::hessian::HessianDim;
use ampm_core::particle::update::{elastic_energy, Stiffness};
use ampm_core::particle::{
    g2p_update, p2g, Definiteness, Dilation, Grid, GridSample, Heat, Kernel, Material, Particle,
    Phase, PhaseParams, Snow, Stencil,
};
use ampm_core::polar::{DefaultSvd, SvdMethod};
use ampm_core::{Mat, Matrix, Real};
use criterion::measurement::WallTime;
use criterion::{criterion_group, criterion_main, BenchmarkGroup, Criterion, Throughput};
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;
use std::hint::black_box;
use std::time::Duration;

/// Particles per batch.
const N: usize = 1024;
const H: f64 = 0.1;
const DT: f64 = 1e-4;
const KERNEL: Kernel = Kernel::Quadratic;

struct Workload<T, const D: usize> {
    particles: Vec<Particle<T, D>>,
    vel: Vec<Vec<[T; D]>>,
    t_new: Vec<Vec<T>>,
    t_old: Vec<Vec<T>>,
}

fn workload<T: Real, const D: usize>(seed: u64) -> Workload<T, D>
where
    Mat<T, D>: Matrix<Scalar = T, Vector = [T; D]>,
{
    let mut r = Pcg64::seed_from_u64(seed);
    let k = KERNEL.node_count(D);
    let mut w = Workload {
        particles: vec![],
        vel: vec![],
        t_new: vec![],
        t_old: vec![],
    };
    for _ in 0..N {
        let x = core::array::from_fn(|_| T::from_f64(r.random_range(1.0..2.0)));
        let mut p = Particle::<T, D>::at_rest(x, T::from_f64(1e-3), T::from_f64(1e-6));
        for j in 0..D {
            for i in 0..D {
                let d = if i == j { 1.0 } else { 0.0 };
                p.f_e.cols[j][i] = T::from_f64(d + r.random_range(-0.05..0.05));
            }
        }
        // At the melting point with a partly filled buffer: the phase level does its work.
        p.temperature = T::from_f64(273.0);
        p.latent = T::from_f64(50.0);
        w.particles.push(p);
        w.vel.push(
            (0..k)
                .map(|_| core::array::from_fn(|_| T::from_f64(r.random_range(-1.0..1.0))))
                .collect(),
        );
        w.t_new.push(
            (0..k)
                .map(|_| T::from_f64(r.random_range(272.0..275.0)))
                .collect(),
        );
        w.t_old.push((0..k).map(|_| T::from_f64(273.0)).collect());
    }
    w
}

fn material<T: Real>(level: &str) -> Material<T> {
    let f = T::from_f64;
    let mut m = Material {
        solid: PhaseParams {
            mu: f(1e5),
            inv_lambda: f(1e-5),
            heat_capacity: f(2000.0),
            conductivity: f(2.0),
        },
        liquid: PhaseParams {
            mu: T::ZERO,
            inv_lambda: f(1e-5),
            heat_capacity: f(4000.0),
            conductivity: f(0.6),
        },
        plasticity: None,
        heat: None,
        dilation: Dilation::Explicit,
        hessian: Definiteness::Exact,
    };
    let snow = Some(Snow {
        critical_compression: f(0.025),
        critical_stretch: f(0.0075),
        hardening: f(10.0),
    });
    let heat = Heat {
        flip: f(0.95),
        melting_point: f(273.0),
        latent_heat: f(100.0),
        phase_change: false,
    };
    match level {
        "fluid" | "elastic" | "implicit-apply" => {}
        "plastic" => m.plasticity = snow,
        "thermal" => {
            m.plasticity = snow;
            m.heat = Some(heat);
        }
        "phase" => {
            m.plasticity = snow;
            m.heat = Some(Heat {
                phase_change: true,
                ..heat
            });
        }
        _ => unreachable!("unknown level"),
    }
    m
}

/// P2G + G2P update of every particle; returns a checksum.
fn step<T: Real, const D: usize>(m: &Material<T>, w: &Workload<T, D>) -> T
where
    Mat<T, D>: Matrix<Scalar = T, Vector = [T; D]>,
    DefaultSvd: SvdMethod<Mat<T, D>>,
{
    let h = T::from_f64(H);
    let dt = T::from_f64(DT);
    let mut acc = T::ZERO;
    for (i, p) in w.particles.iter().enumerate() {
        let q = p2g(m, KERNEL, h, black_box(p)).expect("p2g");
        for r in 0..q.stencil.len() {
            let n = q.node(r);
            acc += n.mass + n.momentum[0] + n.force[D - 1] + n.thermal_energy;
        }
        let sample = GridSample {
            velocity: &w.vel[i],
            temperature: Some((&w.t_new[i], &w.t_old[i])),
        };
        let (np, _) = g2p_update(m, KERNEL, h, dt, &sample, p).expect("g2p");
        acc += np.f_e.cols[0][0];
    }
    acc
}

fn bench_dim<T: Real, const D: usize>(g: &mut BenchmarkGroup<'_, WallTime>)
where
    Mat<T, D>: Matrix<Scalar = T, Vector = [T; D]> + HessianDim,
    DefaultSvd: SvdMethod<Mat<T, D>>,
{
    let w = workload::<T, D>(D as u64);
    for level in ["fluid", "elastic", "plastic", "thermal", "phase"] {
        let m = material::<T>(level);
        let mut wl = Workload {
            particles: w.particles.clone(),
            vel: w.vel.clone(),
            t_new: w.t_new.clone(),
            t_old: w.t_old.clone(),
        };
        if level == "fluid" {
            for p in wl.particles.iter_mut() {
                p.phase = Phase::Liquid;
            }
        }
        g.bench_function(format!("{level}/{D}d/{}", T::NAME), |b| {
            b.iter(|| black_box(step(black_box(&m), &wl)))
        });
    }
    // Implicit: the per-iteration force differential, stiffness prepared beforehand, with the
    // exact Ĉ and with its PSD projection Ĉ⁺.
    let h = T::from_f64(H);
    for (name, hessian) in [
        ("implicit-apply", Definiteness::Exact),
        ("implicit-apply-psd", Definiteness::Projected),
    ] {
        let m = Material {
            dilation: Dilation::PressureSolve,
            hessian,
            ..material::<T>("implicit-apply")
        };
        let energies: Vec<_> = w
            .particles
            .iter()
            .map(|p| elastic_energy(&m, p).expect("energy"))
            .collect();
        let prepared: Vec<_> = w
            .particles
            .iter()
            .zip(&energies)
            .map(|(p, e)| {
                let s = Stencil::new(KERNEL, Grid::Collocated, h, &p.x).expect("stencil");
                (s, Stiffness::new(e, &m, p).expect("stiffness"))
            })
            .collect();
        let mut df = vec![[T::ZERO; D]; KERNEL.node_count(D)];
        g.bench_function(format!("{name}/{D}d/{}", T::NAME), |b| {
            b.iter(|| {
                let mut acc = T::ZERO;
                for (i, (s, k)) in prepared.iter().enumerate() {
                    k.apply(s, black_box(&w.vel[i]), &mut df).expect("apply");
                    acc += df[0][0];
                }
                black_box(acc)
            })
        });
    }
}

fn levels(c: &mut Criterion) {
    let mut g = c.benchmark_group("particle_levels");
    g.throughput(Throughput::Elements(N as u64));
    bench_dim::<f32, 2>(&mut g);
    bench_dim::<f64, 2>(&mut g);
    bench_dim::<f32, 3>(&mut g);
    bench_dim::<f64, 3>(&mut g);
    g.finish();
}

criterion_group! {
    name = benches;
    // Modest: the machine's two cores are shared.
    config = Criterion::default()
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(2))
        .sample_size(30);
    targets = levels
}
criterion_main!(benches);
