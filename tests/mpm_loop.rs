//! A small 2D explicit MPM loop written here (collocated grid, APIC, symplectic Euler) around
//! the particle entries of `ampm_core::particle`, checking what a time step must preserve:
//! - an elastic block spinning in free flight: mass exact, linear and angular momentum
//!   conserved to rounding, `J > 0`, no NaN;
//! - an elastic block falling on the floor: `J > 0`, no NaN, it stops on the floor;
//! - a block of ice heated past its melting point: the latent-heat bookkeeping per particle,
//!   every particle melts, liquid particles carry no deviatoric stress;
//! - the remedy: a grid velocity with `det(I + Δt∇v) < 0` still gives `J > 0`.
//!
//! Sized to run in about a second per test in debug mode (64 particles, 16² cells,
//! 100–250 steps).
#![allow(clippy::needless_range_loop)] // index loops mirror the formulas

use ampm_core::particle::update::{p2g, P2g};
use ampm_core::particle::{
    g2p_update, kirchhoff_stress, Definiteness, Dilation, Grid, GridSample, Heat, Kernel, Material,
    Particle, Phase, PhaseParams, Stencil,
};
use ampm_core::{Mat, Matrix};

type P = Particle<f64, 2>;
const EPS: f64 = f64::EPSILON;
const KERNEL: Kernel = Kernel::Quadratic;

/// A dense collocated grid of `n × n` nodes at `(i h, j h)`.
struct Grid2 {
    n: usize,
    h: f64,
    mass: Vec<f64>,
    mom: Vec<[f64; 2]>,
    vel: Vec<[f64; 2]>,
    heat_cap: Vec<f64>,
    energy: Vec<f64>,
    t_old: Vec<f64>,
    t_new: Vec<f64>,
}

impl Grid2 {
    fn new(n: usize, h: f64) -> Self {
        Self {
            n,
            h,
            mass: vec![0.0; n * n],
            mom: vec![[0.0; 2]; n * n],
            vel: vec![[0.0; 2]; n * n],
            heat_cap: vec![0.0; n * n],
            energy: vec![0.0; n * n],
            t_old: vec![0.0; n * n],
            t_new: vec![0.0; n * n],
        }
    }
    fn id(&self, idx: [i32; 2]) -> usize {
        assert!(
            idx.iter().all(|&c| c >= 0 && (c as usize) < self.n),
            "particle left the grid"
        );
        idx[0] as usize + self.n * idx[1] as usize
    }
}

struct Scene {
    mat: Material<f64>,
    gravity: f64,
    floor: bool,
    /// Newton heating of the grid toward this temperature at this rate (1/s).
    heater: Option<(f64, f64)>,
}

/// Per-step record of what the checks need.
struct StepOut {
    p2g: Vec<P2g<f64, 2>>,
    grid_mass: f64,
    /// Per particle, the blended `T*` recomputed here from the grid (PIC/FLIP).
    t_star: Vec<f64>,
    heat_in: Vec<f64>,
}

fn step(g: &mut Grid2, ps: &mut [P], sc: &Scene, dt: f64) -> StepOut {
    let nn = g.n * g.n;
    g.mass.iter_mut().for_each(|m| *m = 0.0);
    g.mom.iter_mut().for_each(|m| *m = [0.0; 2]);
    g.heat_cap.iter_mut().for_each(|m| *m = 0.0);
    g.energy.iter_mut().for_each(|m| *m = 0.0);
    let mut force = vec![[0.0f64; 2]; nn];
    // P2G.
    let mut out = Vec::with_capacity(ps.len());
    for p in ps.iter() {
        let q = p2g(&sc.mat, KERNEL, g.h, p).expect("p2g");
        for r in 0..q.stencil.len() {
            let nd = q.node(r);
            let i = g.id(nd.index);
            g.mass[i] += nd.mass;
            for a in 0..2 {
                g.mom[i][a] += nd.momentum[a];
                force[i][a] += nd.force[a];
            }
            g.heat_cap[i] += nd.heat_capacity;
            g.energy[i] += nd.thermal_energy;
        }
        out.push(q);
    }
    let grid_mass = g.mass.iter().sum();
    // Grid update: symplectic Euler, boundary, heat.
    for i in 0..nn {
        if g.mass[i] == 0.0 {
            g.vel[i] = [0.0; 2];
            continue;
        }
        let mut v = [0.0; 2];
        for a in 0..2 {
            v[a] = (g.mom[i][a] + dt * force[i][a]) / g.mass[i];
        }
        v[1] += dt * sc.gravity;
        let (ix, iy) = (i % g.n, i / g.n);
        if sc.floor {
            if iy < 3 {
                v = [0.0; 2]; // sticky floor
            }
            if ix < 3 || ix + 3 >= g.n {
                v[0] = 0.0;
            }
        }
        g.vel[i] = v;
        if g.heat_cap[i] > 0.0 {
            let t = g.energy[i] / g.heat_cap[i];
            g.t_old[i] = t;
            g.t_new[i] = match sc.heater {
                Some((t_env, rate)) => t + dt * rate * (t_env - t),
                None => t,
            };
        }
    }
    // G2P.
    let mut t_star = Vec::new();
    let mut heat_in = Vec::new();
    for (p, q) in ps.iter_mut().zip(&out) {
        let s = &q.stencil;
        let idx: Vec<usize> = (0..s.len()).map(|r| g.id(s.node(r).index)).collect();
        let vel: Vec<[f64; 2]> = idx.iter().map(|&i| g.vel[i]).collect();
        let tn: Vec<f64> = idx.iter().map(|&i| g.t_new[i]).collect();
        let to: Vec<f64> = idx.iter().map(|&i| g.t_old[i]).collect();
        let sample = GridSample {
            velocity: &vel,
            temperature: Some((&tn, &to)),
        };
        if let Some(h) = &sc.mat.heat {
            // Independent PIC/FLIP blend, Stomakhin et al. 2014 §6.
            let (mut pic, mut d) = (0.0, 0.0);
            for r in 0..s.len() {
                let w = s.node(r).weight;
                pic += w * tn[r];
                d += w * (tn[r] - to[r]);
            }
            t_star.push((1.0 - h.flip) * pic + h.flip * (p.temperature + d));
        }
        let (np, info) = g2p_update(&sc.mat, KERNEL, g.h, dt, &sample, p).expect("g2p");
        heat_in.push(p.mass * (info.heat.solid + info.heat.latent + info.heat.liquid));
        *p = np;
    }
    StepOut {
        p2g: out,
        grid_mass,
        t_star,
        heat_in,
    }
}

fn block(x0: [f64; 2], side: f64, h: f64, rho: f64) -> Vec<P> {
    let dx = h / 2.0; // 4 particles per cell
    let k = (side / dx).round() as usize;
    let mut ps = Vec::new();
    for j in 0..k {
        for i in 0..k {
            let x = [x0[0] + (i as f64 + 0.5) * dx, x0[1] + (j as f64 + 0.5) * dx];
            ps.push(P::at_rest(x, rho * dx * dx, dx * dx));
        }
    }
    ps
}

fn check_particles(ps: &[P]) {
    for p in ps {
        let je = Matrix::det(&p.f_e);
        let jp = Matrix::det(&p.f_p);
        assert!(je > 0.0 && jp > 0.0, "J_E = {je}, J_P = {jp}");
        assert!(p.x.iter().chain(&p.v).all(|c| c.is_finite()));
        assert!(p.f_e.is_finite() && p.f_p.is_finite() && p.affine.is_finite());
    }
}

fn elastic() -> Material<f64> {
    Material::elastic(10.0, 10.0)
}

/// APIC angular momentum of a particle (Jiang et al. 2015, §5.3):
/// `m (x × v) + m κh² (C₁₀ − C₀₁)`, the grid angular momentum it transfers.
fn angular(p: &P, h: f64) -> f64 {
    let k = KERNEL.apic_moment::<f64>() * h * h;
    p.mass * (p.x[0] * p.v[1] - p.x[1] * p.v[0] + k * (p.affine[(1, 0)] - p.affine[(0, 1)]))
}

#[test]
fn free_flight_conserves_momentum() {
    let h = 1.0 / 16.0;
    let mut g = Grid2::new(17, h);
    let mut ps = block([0.375, 0.375], 0.25, h, 1.0);
    // Spin about the block centre, drift, and a sheared F_E so the stress is not zero.
    let (c, omega) = ([0.5, 0.5], 3.0);
    for p in ps.iter_mut() {
        p.v = [0.2 - omega * (p.x[1] - c[1]), 0.1 + omega * (p.x[0] - c[0])];
        p.affine = Mat::from_rows([[0.0, -omega], [omega, 0.0]]);
        p.f_e = Mat::from_rows([[1.05, 0.1], [0.0, 0.97]]);
    }
    let sc = Scene {
        mat: elastic(),
        gravity: 0.0,
        floor: false,
        heater: None,
    };
    let mass0: f64 = ps.iter().map(|p| p.mass).sum();
    let mom = |ps: &[P]| -> [f64; 2] {
        let mut m = [0.0; 2];
        for p in ps {
            m[0] += p.mass * p.v[0];
            m[1] += p.mass * p.v[1];
        }
        m
    };
    let p0 = mom(&ps);
    let l0: f64 = ps.iter().map(|p| angular(p, h)).sum();
    // Scale of the terms summed: Σ m(|x||v| + κh²|C|).
    let scale: f64 = ps
        .iter()
        .map(|p| p.mass * (1.0 * (p.v[0].abs() + p.v[1].abs()) + h * h * omega))
        .sum();
    let steps = 100;
    for n in 1..=steps {
        let out = step(&mut g, &mut ps, &sc, 1e-3);
        check_particles(&ps);
        // Mass: particle masses never change; the grid receives them up to the rounding of
        // the partition of unity (9 weights, ≤ 16ε each).
        assert_eq!(ps.iter().map(|p| p.mass).sum::<f64>(), mass0);
        assert!((out.grid_mass - mass0).abs() <= 16.0 * 9.0 * EPS * mass0);
        // Per step, every particle adds ~ (9 nodes × a few ops) roundings of its terms:
        // bound 64ε·scale per step, accumulated over n steps.
        let tol = 64.0 * EPS * scale * n as f64;
        let p = mom(&ps);
        assert!(
            (p[0] - p0[0]).abs() <= tol && (p[1] - p0[1]).abs() <= tol,
            "{p:?} {p0:?}"
        );
        let l: f64 = ps.iter().map(|p| angular(p, h)).sum();
        assert!(
            (l - l0).abs() <= tol,
            "step {n}: L = {l}, L0 = {l0}, tol {tol}"
        );
    }
    // The stress did act: F_E changed.
    assert!(ps
        .iter()
        .any(|p| (p.f_e - Mat::from_rows([[1.05, 0.1], [0.0, 0.97]])).max_abs() > 1e-3));
}

#[test]
fn elastic_block_falls_on_floor() {
    let h = 1.0 / 16.0;
    let mut g = Grid2::new(17, h);
    let y0 = 0.4;
    let mut ps = block([0.375, y0], 0.25, h, 1.0);
    let sc = Scene {
        mat: elastic(),
        gravity: -9.8,
        floor: true,
        heater: None,
    };
    let mass0: f64 = ps.iter().map(|p| p.mass).sum();
    let mut min_y = f64::MAX;
    let mut min_je = f64::MAX;
    for _ in 0..250 {
        let out = step(&mut g, &mut ps, &sc, 2e-3);
        check_particles(&ps);
        assert!((out.grid_mass - mass0).abs() <= 16.0 * 9.0 * EPS * mass0);
        min_y = ps.iter().map(|p| p.x[1]).fold(min_y, f64::min);
        min_je = ps
            .iter()
            .map(|p| Matrix::det(&p.f_e))
            .fold(min_je, f64::min);
    }
    // Free fall from y0 to the sticky floor nodes (y < 3h) takes √(2·0.21/9.8) ≈ 0.21 s of
    // the 0.5 s run: the block reached the floor (a particle below 3.5h has sticky nodes in
    // its stencil) and did not pass through it (below 1.5h it would touch sticky nodes only).
    assert!(min_y < 3.5 * h, "min y {min_y}");
    assert!(min_y > 1.5 * h, "min y {min_y}");
    // The impact compressed it.
    assert!(min_je < 0.99, "min J_E {min_je}");
}

#[test]
fn ice_block_melts() {
    let h = 1.0 / 16.0;
    let mut g = Grid2::new(17, h);
    let mut ps = block([0.375, 3.0 * h], 0.25, h, 1.0);
    let (tm, cs, cl, lat) = (273.0, 2.0, 4.0, 20.0);
    for p in ps.iter_mut() {
        p.temperature = 263.0;
    }
    let mat = Material {
        solid: PhaseParams {
            mu: 10.0,
            inv_lambda: 0.1,
            heat_capacity: cs,
            conductivity: 1.0,
        },
        liquid: PhaseParams {
            mu: 0.0,
            inv_lambda: 0.1,
            heat_capacity: cl,
            conductivity: 0.5,
        },
        plasticity: None,
        heat: Some(Heat {
            flip: 0.95,
            melting_point: tm,
            latent_heat: lat,
            phase_change: true,
        }),
        dilation: Dilation::Explicit,
        hessian: Definiteness::Exact,
    };
    let sc = Scene {
        mat,
        gravity: -9.8,
        floor: true,
        heater: Some((400.0, 5.0)),
    };
    let start: Vec<P> = ps.clone();
    let mut heat_total = vec![0.0f64; ps.len()];
    let mut melted_at = None;
    let steps = 250;
    for n in 0..steps {
        let before = ps.clone();
        let out = step(&mut g, &mut ps, &sc, 2e-3);
        check_particles(&ps);
        for (k, p) in ps.iter().enumerate() {
            let b = &before[k];
            // The heat the particle received is m c (T* − T) with T* the PIC/FLIP blend
            // computed here and c of its phase before the step.
            let c = if b.phase == Phase::Solid { cs } else { cl };
            let q = p.mass * c * (out.t_star[k] - b.temperature);
            assert!(
                (out.heat_in[k] - q).abs() <= 8.0 * EPS * p.mass * c * 400.0,
                "{} {q}",
                out.heat_in[k]
            );
            heat_total[k] += q;
            // Liquids: isotropic F_E and no deviatoric stress.
            if p.phase == Phase::Liquid {
                assert_eq!(p.f_e[(0, 1)], 0.0);
                assert_eq!(p.f_e[(1, 0)], 0.0);
                assert_eq!(p.f_e[(0, 0)], p.f_e[(1, 1)]);
                let tau = kirchhoff_stress(&sc.mat, p).unwrap();
                let iso = tau.trace() / 2.0;
                assert!((tau - Mat::identity() * iso).max_abs() <= 8.0 * EPS * iso.abs());
            }
        }
        // The forces a liquid particle put on the grid this step were −V⁰ τ ∇w with τ
        // isotropic: its force matrix has no deviatoric part.
        for (q, b) in out.p2g.iter().zip(&before) {
            if b.phase == Phase::Liquid {
                let iso = q.force.trace() / 2.0;
                assert!((q.force - Mat::identity() * iso).max_abs() <= 8.0 * EPS * iso.abs());
            }
        }
        if melted_at.is_none() && ps.iter().all(|p| p.phase == Phase::Liquid) {
            melted_at = Some(n);
        }
    }
    let melted_at = melted_at.expect("every particle melted");
    // At most c_s Δt β (400 − 263 K) ≈ 2.7 J/kg per step reach a solid particle, and melting
    // needs c_s·10 K + L = 40 J/kg: not before step 14.
    assert!(melted_at >= 14, "melted at step {melted_at}");
    // Latent-heat bookkeeping over the run: total heat in = m (c_s ΔT_s + ΔU + c_l ΔT_l),
    // each particle having gone 263 K → T_m (solid), 0 → L (buffer), T_m → T (liquid).
    for (k, p) in ps.iter().enumerate() {
        let s = &start[k];
        assert_eq!(p.latent, lat);
        let want = p.mass * (cs * (tm - s.temperature) + lat + cl * (p.temperature - tm));
        assert!(p.temperature > tm);
        // `steps` additions of terms ≤ m·c·400 K.
        let tol = steps as f64 * 8.0 * EPS * p.mass * cl * 400.0;
        assert!(
            (heat_total[k] - want).abs() <= tol,
            "{} {want}",
            heat_total[k]
        );
    }
}

#[test]
fn remedy_keeps_j_positive() {
    // A grid velocity v = (−a x, 0) with a Δt = 3 compresses past inversion:
    // det(I + Δt∇v) = 1 − 3 = −2 < 0; the remedy gives (1 − 3/2)² = ¼.
    let h = 0.1;
    let dt = 0.01;
    let a = 300.0;
    let p = P::at_rest([0.55, 0.55], 1.0, 0.01);
    let s = Stencil::<f64, 2>::new(KERNEL, Grid::Collocated, h, &p.x).unwrap();
    let vel: Vec<[f64; 2]> = s
        .nodes()
        .map(|n| [-a * n.index[0] as f64 * h, 0.0])
        .collect();
    let sample = GridSample {
        velocity: &vel,
        temperature: None,
    };
    let (np, info) = g2p_update(&elastic(), KERNEL, h, dt, &sample, &p).unwrap();
    assert!(info.halvings >= 1);
    let je = Matrix::det(&np.f_e);
    assert!(je > 0.0);
    assert!((np.f_e[(0, 0)] - 0.25).abs() <= 1e-12, "{:?}", np.f_e);
}
