//! Tests of the MPM particle updates (`ampm_core::particle`), generated for every scalar ×
//! dimension by one macro (the batch transfers and their C ABI are in tests/transfer/).
//!
//! Tolerances are in units of the scalar's ε and are derived where they are stated: a sum of
//! `n` products of `k` rounded factors, each factor `O(1)`, has an error of at most about
//! `(n + k)·ε` times the sum of the magnitudes.
#![allow(clippy::needless_range_loop)] // index loops mirror the formulas

use ampm_core::particle::apic;
use ampm_core::particle::deformation::{self, evolve, increment, liquid_projection};
use ampm_core::particle::dilation;
use ampm_core::particle::thermal::{absorb, HeatSplit, ThermalState};
use ampm_core::particle::update::{self, elastic_energy, force_differential, Stiffness};
use ampm_core::particle::{
    g2p_update, kirchhoff_stress, Definiteness, Dilation, Grid, GridSample, Heat, Kernel, Material,
    Particle, Phase, PhaseParams, Snow, Stencil,
};
use ampm_core::{Error, Mat, Matrix, Real};
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;

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

fn heat_material<T: Real>() -> Material<T> {
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
            phase_change: true,
        }),
        dilation: Dilation::Explicit,
        hessian: Definiteness::Exact,
    }
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

            /// Partition of unity, linear reproduction, zero-sum gradients, `Σ dx ∇wᵀ = I`,
            /// the APIC moment, and agreement with the independent f64 B-spline.
            #[test]
            fn stencil_identities() {
                let mut r = rng(1);
                let h = 0.37;
                for kernel in [Kernel::Quadratic, Kernel::Cubic] {
                    let n = kernel.node_count(D);
                    // n terms of d+1 rounded factors each (see the file header).
                    let tol = (n + 2 * D + 4) as f64 * EPS;
                    for grid in grids() {
                        for _ in 0..200 {
                            let x = rand_pos(&mut r, h, 1000.0);
                            let s = Stencil::<T, D>::new(kernel, grid, h as T, &x).unwrap();
                            assert_eq!(s.len(), n);
                            let mut sw = 0.0f64;
                            let mut swdx = [0.0f64; D];
                            let mut sg = [0.0f64; D];
                            let mut sdxg = [[0.0f64; D]; D];
                            let mut mom = [[0.0f64; D]; D];
                            for node in s.nodes() {
                                assert!(node.weight >= 0.0);
                                sw += node.weight as f64;
                                for a in 0..D {
                                    swdx[a] += (node.weight * node.dx[a]) as f64;
                                    sg[a] += node.grad[a] as f64;
                                    for b in 0..D {
                                        sdxg[a][b] += (node.dx[a] * node.grad[b]) as f64;
                                        mom[a][b] += (node.weight * node.dx[a] * node.dx[b]) as f64;
                                    }
                                }
                                // Independent weight from the node's position. The particle
                                // position x/h − shift carries ε|x/h| of rounding.
                                let mut w = 1.0;
                                for a in 0..D {
                                    let shift = match grid {
                                        Grid::Face(f) if f != a => 0.5,
                                        _ => 0.0,
                                    };
                                    let xi = (node.index[a] as f64 + shift) * h;
                                    w *= bspline(kernel, (x[a] as f64 - xi) / h);
                                }
                                let pos_err = 1000.0 * EPS * 4.0;
                                assert!(
                                    (w - node.weight as f64).abs() <= tol + pos_err,
                                    "{w} {}",
                                    node.weight
                                );
                            }
                            assert!(
                                (sw - 1.0).abs() <= tol,
                                "{kernel:?} {grid:?} Σw−1 = {}",
                                sw - 1.0
                            );
                            let kappa = kernel.apic_moment::<f64>();
                            for a in 0..D {
                                assert!(swdx[a].abs() <= 2.0 * tol * h, "Σ w dx = {swdx:?}");
                                assert!(sg[a].abs() <= 4.0 * tol / h, "Σ ∇w = {sg:?}");
                                for b in 0..D {
                                    let id = if a == b { 1.0 } else { 0.0 };
                                    assert!(
                                        (sdxg[a][b] - id).abs() <= 4.0 * tol,
                                        "Σ dx ∇wᵀ = {sdxg:?}"
                                    );
                                    assert!(
                                        (mom[a][b] - id * kappa * h * h).abs() <= 4.0 * tol * h * h,
                                        "D_p = {mom:?}"
                                    );
                                }
                            }
                        }
                    }
                }
            }

            /// Central differences of the weights against the gradients (f64 reference).
            #[test]
            fn stencil_gradients() {
                let mut r = rng(2);
                let h = 0.5;
                for kernel in [Kernel::Quadratic, Kernel::Cubic] {
                    for _ in 0..50 {
                        let x = rand_pos(&mut r, h, 10.0);
                        let s = Stencil::<T, D>::new(kernel, Grid::Collocated, h as T, &x).unwrap();
                        for node in s.nodes() {
                            for a in 0..D {
                                let e = 1e-6;
                                let w_at = |dx: f64| {
                                    let mut w = 1.0;
                                    for b in 0..D {
                                        let xb = x[b] as f64 + if a == b { dx } else { 0.0 };
                                        w *= bspline(kernel, (xb - node.index[b] as f64 * h) / h);
                                    }
                                    w
                                };
                                let fd = (w_at(e) - w_at(-e)) / (2.0 * e);
                                // FD truncation O(e²·N‴/h³) ≈ 1e-11 plus the kink of the
                                // quadratic at |d| = ½ (one-sided within e): 4e/h².
                                let tol = 200.0 * EPS / h + 4.0 * e / (h * h);
                                assert!(
                                    (fd - node.grad[a] as f64).abs() <= tol,
                                    "{fd} {:?}",
                                    node.grad
                                );
                            }
                        }
                    }
                }
            }

            #[test]
            fn stencil_rejects() {
                let x = [0.0 as T; D];
                let q = Kernel::Quadratic;
                assert_eq!(
                    Stencil::<T, D>::new(q, Grid::Collocated, 0.0, &x),
                    Err(Error::InvalidArgument)
                );
                assert_eq!(
                    Stencil::<T, D>::new(q, Grid::Collocated, T::NAN, &x),
                    Err(Error::NonFinite)
                );
                assert_eq!(
                    Stencil::<T, D>::new(q, Grid::Face(D), 1.0, &x),
                    Err(Error::InvalidArgument)
                );
                let mut y = x;
                y[0] = T::INFINITY;
                assert_eq!(
                    Stencil::<T, D>::new(q, Grid::Collocated, 1.0, &y),
                    Err(Error::NonFinite)
                );
                y[0] = 1e10;
                assert_eq!(
                    Stencil::<T, D>::new(q, Grid::Collocated, 1.0, &y),
                    Err(Error::InvalidArgument)
                );
            }

            /// An affine grid velocity `v(x) = b + A x` is reproduced exactly by G2P:
            /// `v_p = v(x_p)`, `C_p = A`, `∇v_p = A`, on collocated and face grids.
            #[test]
            fn apic_affine_reproduction() {
                let mut r = rng(3);
                let h = 0.25;
                for kernel in [Kernel::Quadratic, Kernel::Cubic] {
                    let n = kernel.node_count(D);
                    let tol = 8.0 * (n + 2 * D + 4) as f64 * EPS;
                    for _ in 0..50 {
                        let x = rand_pos(&mut r, h, 8.0);
                        let a = rand_mat(&mut r, 1.0);
                        let b = rand_pos(&mut r, 1.0, 1.0);
                        let field = |p: [f64; D]| -> [f64; D] {
                            let mut v = [0.0; D];
                            for i in 0..D {
                                v[i] = b[i] as f64;
                                for j in 0..D {
                                    v[i] += a.cols[j][i] as f64 * p[j];
                                }
                            }
                            v
                        };
                        // Scale of the values: |b| + |A| |x| ≤ 1 + d·8h.
                        let scale = 1.0 + D as f64 * 8.0 * h;
                        let s = Stencil::<T, D>::new(kernel, Grid::Collocated, h as T, &x).unwrap();
                        let vel: Vec<[T; D]> = s
                            .nodes()
                            .map(|nd| {
                                let p = core::array::from_fn(|c| nd.index[c] as f64 * h);
                                field(p).map(|v| v as T)
                            })
                            .collect();
                        let g = apic::gather(&s, &vel).unwrap();
                        let vp = field(core::array::from_fn(|c| x[c] as f64));
                        for i in 0..D {
                            assert!((g.v[i] as f64 - vp[i]).abs() <= tol * scale);
                            for j in 0..D {
                                let aij = a.cols[j][i] as f64;
                                assert!(
                                    (g.affine.cols[j][i] as f64 - aij).abs() <= tol * scale / h,
                                    "C"
                                );
                                assert!(
                                    (g.grad_v.cols[j][i] as f64 - aij).abs() <= tol * scale / h,
                                    "∇v"
                                );
                            }
                        }
                        // MAC: component c on its face grid.
                        for c in 0..D {
                            let s =
                                Stencil::<T, D>::new(kernel, Grid::Face(c), h as T, &x).unwrap();
                            let q: Vec<T> = s
                                .nodes()
                                .map(|nd| {
                                    let p = core::array::from_fn(|e| {
                                        (nd.index[e] as f64 + if e == c { 0.0 } else { 0.5 }) * h
                                    });
                                    field(p)[c] as T
                                })
                                .collect();
                            let g = apic::gather_scalar(&s, &q).unwrap();
                            assert!((g.value as f64 - vp[c]).abs() <= tol * scale);
                            for j in 0..D {
                                let acj = a.cols[j][c] as f64;
                                assert!((g.affine[j] as f64 - acj).abs() <= tol * scale / h);
                                assert!((g.grad[j] as f64 - acj).abs() <= tol * scale / h);
                            }
                        }
                    }
                }
            }

            /// P2G then G2P of one particle with an affine velocity field: the node momenta sum
            /// to `m v_p`, the node masses to `m`, and the particle's own affine motion is
            /// recovered from the nodal velocities `p_i/m_i` (exact for APIC: Jiang et al. 2015).
            #[test]
            fn apic_round_trip() {
                let mut r = rng(4);
                let h = 0.5;
                let mat = Material::<T>::elastic(1.0, 1.0);
                for kernel in [Kernel::Quadratic, Kernel::Cubic] {
                    let n = kernel.node_count(D);
                    let tol = 16.0 * (n + 2 * D + 4) as f64 * EPS;
                    let x = rand_pos(&mut r, h, 5.0);
                    let mut p = Particle::<T, D>::at_rest(x, 2.0, 0.1);
                    p.v = rand_pos(&mut r, 1.0, 1.0);
                    p.affine = rand_mat(&mut r, 1.0);
                    let out = update::p2g(&mat, kernel, h as T, &p).unwrap();
                    let (mut m, mut mv) = (0.0f64, [0.0f64; D]);
                    let mut vel = Vec::new();
                    for k in 0..n {
                        let nd = out.node(k);
                        m += nd.mass as f64;
                        for a in 0..D {
                            mv[a] += nd.momentum[a] as f64;
                        }
                        vel.push(nd.momentum.map(|q| q / nd.mass));
                        // Undeformed, at rest in F: no stress, no force.
                        assert!(nd.force.iter().all(|f| *f == 0.0));
                    }
                    assert!((m - 2.0).abs() <= tol * 2.0);
                    for a in 0..D {
                        assert!((mv[a] - 2.0 * p.v[a] as f64).abs() <= tol * 4.0);
                    }
                    let g = apic::gather(&out.stencil, &vel).unwrap();
                    for a in 0..D {
                        assert!((g.v[a] - p.v[a]).abs() as f64 <= tol * 4.0);
                    }
                    assert!((g.affine - p.affine).max_abs() as f64 <= tol * 4.0 / h);
                }
            }

            /// The remedy: `∇v` with `det(I + Δt∇v) < 0` gives `J > 0`; the halvings are the
            /// ones worked out by hand, and `k = 1` is exactly `(I + ½Δt∇v)²`.
            #[test]
            fn remedy() {
                let dt: T = 0.5;
                let id = M::identity();
                // Δt∇v = diag(−3, 0, …): det(I + L) = −2; (I + L/2)² = diag(¼, 1, …), k = 1.
                let mut gv = M::ZERO;
                gv.cols[0][0] = -3.0 / dt;
                let (a, k) = increment(&gv, dt).unwrap();
                assert_eq!(k, 1);
                let half = id + gv * (dt * 0.5);
                assert_eq!(a, half * half);
                assert_eq!(a.cols[0][0], 0.25);
                // Δt∇v = diag(−2, 0, …): k = 1 gives diag(0, …), det 0; k = 2 gives (½)⁴.
                gv.cols[0][0] = -2.0 / dt;
                let (a, k) = increment(&gv, dt).unwrap();
                assert_eq!(k, 2);
                assert_eq!(a.cols[0][0], 0.0625);
                // Random violent ∇v: J > 0 always, and F_E = A F_E exactly as documented.
                let mut r = rng(5);
                let mut hit = 0;
                for _ in 0..2000 {
                    let gv = rand_mat(&mut r, 20.0);
                    let f = id + rand_mat(&mut r, 0.3);
                    if Matrix::det(&f) <= 0.0 {
                        continue;
                    }
                    let (fnew, k) = evolve(&f, &gv, 0.1).unwrap();
                    hit += (k > 0) as usize;
                    assert!(Matrix::det(&fnew) > 0.0);
                    assert!(fnew.is_finite());
                }
                assert!(hit > 100, "the remedy was exercised {hit} times");
                assert_eq!(increment(&gv, T::NAN), Err(Error::NonFinite));
            }

            /// Snow plasticity: singular values within the clamp, `J = J_E J_P` preserved
            /// (`F_E F_P` unchanged up to rounding), hardening as `e^{ξ(1 − J_P)}`.
            #[test]
            fn snow() {
                let snow = Snow::<T> {
                    critical_compression: 0.025,
                    critical_stretch: 0.0075,
                    hardening: 10.0,
                };
                let mut r = rng(6);
                for _ in 0..200 {
                    let fe = M::identity() + rand_mat(&mut r, 0.2);
                    let fp = M::identity() + rand_mat(&mut r, 0.1);
                    if Matrix::det(&fe) <= 0.0 || Matrix::det(&fp) <= 0.0 {
                        continue;
                    }
                    let (fe2, fp2) = deformation::snow_plasticity(&snow, &fe, &fp).unwrap();
                    let svd =
                        <ampm_core::polar::DefaultSvd as ampm_core::polar::SvdMethod<M>>::svd(
                            &ampm_core::polar::DefaultSvd,
                            &fe2,
                        )
                        .unwrap();
                    for s in svd.sigma {
                        // Reconstruction and re-decomposition: a few ε·κ, κ ≤ 2 here.
                        assert!(s as f64 >= 0.975 - 64.0 * EPS && s as f64 <= 1.0075 + 64.0 * EPS);
                    }
                    let before = fe * fp;
                    let after = fe2 * fp2;
                    // Products of O(1) matrices with κ(F) ≤ ~3: 64ε covers the
                    // decomposition's backward error times the condition.
                    assert!(
                        (before - after).max_abs() as f64 <= 64.0 * EPS,
                        "{before:?} {after:?}"
                    );
                }
                let mat = Material::<T> {
                    plasticity: Some(snow),
                    ..Material::elastic(10.0, 20.0)
                };
                let m = mat.moduli(Phase::Solid, 0.9).unwrap();
                let e = (10.0f64 * 0.1).exp();
                assert!((m.mu as f64 - 10.0 * e).abs() <= 8.0 * EPS * 10.0 * e);
                assert!((m.inv_lambda as f64 - 0.05 / e).abs() <= 8.0 * EPS * 0.05 / e);
            }

            /// Liquid projection: `F_E = J_E^{1/d} I`, `F_P = J_P^{1/d} I`, `J_E` and `J_P`
            /// unchanged, so `J = det F` unchanged (the deviatoric part of `F` is dropped).
            #[test]
            fn liquid() {
                let mut r = rng(7);
                for _ in 0..100 {
                    let fe = M::identity() + rand_mat(&mut r, 0.3);
                    let fp = M::identity() + rand_mat(&mut r, 0.1);
                    if Matrix::det(&fe) <= 0.0 || Matrix::det(&fp) <= 0.0 {
                        continue;
                    }
                    let (fe2, fp2) = liquid_projection(&fe, &fp).unwrap();
                    let je = Matrix::det(&fe) as f64;
                    for i in 0..D {
                        for j in 0..D {
                            if i != j {
                                assert_eq!(fe2.cols[j][i], 0.0);
                            } else {
                                assert_eq!(fe2.cols[j][i], fe2.cols[0][0]);
                            }
                        }
                    }
                    assert!((Matrix::det(&fe2) as f64 - je).abs() <= 16.0 * EPS * je);
                    let jp = Matrix::det(&fp) as f64;
                    assert!((Matrix::det(&fp2) as f64 - jp).abs() <= 64.0 * EPS * jp);
                    for i in 0..D {
                        for j in 0..D {
                            let want = if i == j { fp2.cols[0][0] } else { 0.0 };
                            assert_eq!(fp2.cols[j][i], want);
                        }
                    }
                    // J = J_E J_P: the two roots (ε each, d·ε in their d-th powers) and the
                    // product's d roundings, on top of the J_P bound above.
                    let j2 = Matrix::det(&(fe2 * fp2)) as f64;
                    assert!((j2 - je * jp).abs() <= (64 + 3 * D) as f64 * EPS * je * jp);
                    // A liquid carries no deviatoric stress: τ is a multiple of I.
                    let mut p = Particle::<T, D>::at_rest([0.0; D], 1.0, 1.0);
                    p.f_e = fe2;
                    p.f_p = fp2;
                    p.phase = Phase::Liquid;
                    let mat = Material::<T> {
                        liquid: PhaseParams {
                            inv_lambda: 0.1,
                            ..PhaseParams::default()
                        },
                        ..Material::default()
                    };
                    let tau = kirchhoff_stress(&mat, &p).unwrap();
                    let iso = tau.trace() / D as T;
                    assert!(
                        (tau - M::identity() * iso).max_abs() as f64
                            <= 8.0 * EPS * iso.abs() as f64
                    );
                    let k = (je - 1.0) * je / 0.1;
                    assert!((iso as f64 - k).abs() <= 64.0 * EPS * (1.0 + k.abs()));
                }
            }

            /// Pressure and the pressure-solve coefficient, with λ = ∞ (`1/λ = 0`).
            #[test]
            fn pressure() {
                let (je, jp, il, dt): (T, T, T, T) = (0.9, 1.25, 0.01, 0.002);
                let p = dilation::pressure(je, jp, il).unwrap() as f64;
                let want = -(0.9f64 - 1.0) / (0.01 * 1.25); // −λ(J_E − 1)/J_P = 8
                assert!((p - want).abs() <= 8.0 * EPS * want.abs(), "{p}");
                let c = dilation::pressure_coefficient(je, jp, il, dt).unwrap() as f64;
                let want = 1.25 * 0.01 / (0.002 * 0.9);
                assert!((c - want).abs() <= 8.0 * EPS * want);
                assert_eq!(dilation::pressure_coefficient(je, jp, 0.0, dt), Ok(0.0));
                assert_eq!(dilation::pressure(je, jp, 0.0), Err(Error::InvalidArgument));
                assert_eq!(dilation::kirchhoff(je, 0.0), Err(Error::InvalidArgument));
                assert_eq!(
                    dilation::pressure_coefficient(je, jp, il, 0.0),
                    Err(Error::InvalidArgument)
                );
                // Incompressible material: valid with the pressure solve, refused explicit.
                let mut mat = Material::<T> {
                    solid: PhaseParams {
                        mu: 1.0,
                        ..PhaseParams::default()
                    },
                    dilation: Dilation::PressureSolve,
                    ..Material::default()
                };
                let part = Particle::<T, D>::at_rest([0.0; D], 1.0, 1.0);
                assert_eq!(update::pressure_coefficient(&mat, &part, dt), Ok(0.0));
                assert!(kirchhoff_stress(&mat, &part).is_ok());
                mat.dilation = Dilation::Explicit;
                assert_eq!(kirchhoff_stress(&mat, &part), Err(Error::InvalidArgument));
            }

            /// Latent heat bookkeeping against values worked out by hand
            /// (c_s = 2, c_l = 4, T_m = 273, L = 100).
            #[test]
            fn latent_heat() {
                let mat = heat_material::<T>();
                let heat = mat.heat.unwrap();
                let st = |t: T, u: T, ph| ThermalState {
                    temperature: t,
                    latent: u,
                    phase: ph,
                };
                // Ice at 263 K gets 200 J/kg: 20 warm it to 273, 100 melt it, 80 warm the
                // water by 20 K.
                let (s, q) = absorb(&heat, 2.0, 4.0, &st(263.0, 0.0, Phase::Solid), 200.0).unwrap();
                assert_eq!(s, st(293.0, 100.0, Phase::Liquid));
                assert_eq!(
                    q,
                    HeatSplit {
                        solid: 20.0,
                        latent: 100.0,
                        liquid: 80.0
                    }
                );
                // And back: −200 J/kg returns it to ice at 263 K.
                let (s2, q2) = absorb(&heat, 2.0, 4.0, &s, -200.0).unwrap();
                assert_eq!(s2, st(263.0, 0.0, Phase::Solid));
                assert_eq!(
                    q2,
                    HeatSplit {
                        solid: -20.0,
                        latent: -100.0,
                        liquid: -80.0
                    }
                );
                // Half a melt: temperature held at T_m.
                let (s3, _) = absorb(&heat, 2.0, 4.0, &st(273.0, 0.0, Phase::Solid), 50.0).unwrap();
                assert_eq!(s3, st(273.0, 50.0, Phase::Solid));
                // Invariants refused.
                for bad in [
                    st(280.0, 0.0, Phase::Solid),
                    st(260.0, 10.0, Phase::Solid),
                    st(300.0, 50.0, Phase::Liquid),
                    st(273.0, 101.0, Phase::Liquid),
                    st(273.0, -1.0, Phase::Solid),
                ] {
                    assert_eq!(
                        absorb(&heat, 2.0, 4.0, &bad, 1.0),
                        Err(Error::InvalidArgument)
                    );
                }
                // Random heats: q is split exactly (up to the additions' rounding) and the
                // split matches the state change.
                let mut r = rng(8);
                let mut s = st(250.0, 0.0, Phase::Solid);
                for _ in 0..2000 {
                    let q: T = r.random_range(-60.0..60.0);
                    let (n, sp) = absorb(&heat, 2.0, 4.0, &s, q).unwrap();
                    let total = (sp.solid + sp.latent + sp.liquid) as f64;
                    assert!((total - q as f64).abs() <= 4.0 * EPS * 300.0, "{total} {q}");
                    assert!(
                        (sp.latent as f64 - (n.latent - s.latent) as f64).abs()
                            <= 2.0 * EPS * 100.0
                    );
                    // m c ΔT per phase: the temperature path through T_m.
                    let tm = 273.0f64;
                    let (t0, t1) = (s.temperature as f64, n.temperature as f64);
                    let sens_s = 2.0 * (t1.min(tm) - t0.min(tm));
                    let sens_l = 4.0 * (t1.max(tm) - t0.max(tm));
                    assert!(
                        (sp.solid as f64 - sens_s).abs() <= 8.0 * EPS * 600.0,
                        "{sp:?} {sens_s}"
                    );
                    assert!(
                        (sp.liquid as f64 - sens_l).abs() <= 8.0 * EPS * 1200.0,
                        "{sp:?} {sens_l}"
                    );
                    s = n;
                }
            }

            /// The force differential against central differences of the stress force with
            /// `F_Eᵀ` frozen, as an implicit step linearises it (f64 reference in both types).
            #[test]
            fn force_differential_fd() {
                let mut r = rng(9);
                let h = 0.5;
                for dil in [Dilation::Explicit, Dilation::PressureSolve] {
                    let mat = Material::<T> {
                        dilation: dil,
                        ..Material::elastic(3.0, 5.0)
                    };
                    let mat64 = Material::<f64> {
                        dilation: dil,
                        ..Material::elastic(3.0, 5.0)
                    };
                    for _ in 0..10 {
                        let x = rand_pos(&mut r, h, 4.0);
                        let mut p = Particle::<T, D>::at_rest(x, 1.0, 0.3);
                        p.f_e = M::identity() + rand_mat(&mut r, 0.2);
                        let s =
                            Stencil::<T, D>::new(Kernel::Quadratic, Grid::Collocated, h as T, &x)
                                .unwrap();
                        let du: Vec<[T; D]> =
                            (0..s.len()).map(|_| rand_pos(&mut r, 1.0, 1.0)).collect();
                        let mut df = vec![[0.0 as T; D]; s.len()];
                        force_differential(&mat, Kernel::Quadratic, h as T, &p, &du, &mut df)
                            .unwrap();
                        // Reference: P(F) = τ(F) F⁻ᵀ in f64, δF = G F.
                        let f64m = p.f_e.cast::<f64>();
                        let mut g = Mat::<f64, D>::ZERO;
                        for k in 0..s.len() {
                            let gr = s.node(k).grad.map(|v| v as f64);
                            g += Mat::outer(du[k].map(|v| v as f64), gr);
                        }
                        let piola = |f: Mat<f64, D>| {
                            let mut q = Particle::<f64, D>::at_rest([0.0; D], 1.0, 0.3);
                            q.f_e = f;
                            let tau = kirchhoff_stress(&mat64, &q).unwrap();
                            let h = Matrix::cofactor(&f) * (1.0 / Matrix::det(&f));
                            tau * h
                        };
                        let e = 1e-6;
                        let dp =
                            (piola(f64m + g * f64m * e) - piola(f64m - g * f64m * e)) * (0.5 / e);
                        let dfm = dp * f64m.transpose() * (-0.3);
                        let scale = dfm.max_abs() * 4.0 / h + 1.0;
                        for k in 0..s.len() {
                            let want = dfm.mul_vec(s.node(k).grad.map(|v| v as f64));
                            for a in 0..D {
                                // f64: FD error ~ e²·|Ψ‴| ≈ 1e-10; f32: the kernel's own
                                // rounding, ~1e3 ε (κ(F) ≤ 2, Ĉ has O(10) terms).
                                let tol = (1e-7 + 1e3 * EPS) * scale;
                                assert!(
                                    (df[k][a] as f64 - want[a]).abs() <= tol,
                                    "{df:?} {want:?}"
                                );
                            }
                        }
                        // Reusable stiffness gives the same matrix.
                        let en = elastic_energy(&mat, &p).unwrap();
                        let st = Stiffness::new(&en, &mat, &p).unwrap();
                        let m1 = st.d_force_matrix(&g.cast::<T>()).unwrap();
                        let m2 = st
                            .d_force_matrix_with(&g.cast::<T>(), |a, z| a.chat_z(z))
                            .unwrap();
                        assert_eq!(m1, m2);
                    }
                }
            }

            /// With the PSD projection (and the dilation in the pressure solve) the operator is
            /// negative semi-definite: `Σ_i δu_i·δf_i = −V⁰ δF:Ĉ⁺:δF ≤ 0` for every `δu`; the
            /// exact `Ĉ` is not (Smith et al. 2019), which some random `δu` shows.
            #[test]
            fn psd_force_differential() {
                let mut r = rng(10);
                let h = 0.5;
                let exact = Material::<T> {
                    dilation: Dilation::PressureSolve,
                    ..Material::elastic(3.0, 5.0)
                };
                let proj = Material::<T> {
                    hessian: Definiteness::Projected,
                    ..exact
                };
                let mut positive = 0;
                for _ in 0..200 {
                    let x = rand_pos(&mut r, h, 4.0);
                    let mut p = Particle::<T, D>::at_rest(x, 1.0, 0.3);
                    p.f_e = M::identity() + rand_mat(&mut r, 0.4);
                    if Matrix::det(&p.f_e) <= 0.2 {
                        continue;
                    }
                    let n = Kernel::Quadratic.node_count(D);
                    let du: Vec<[T; D]> = (0..n).map(|_| rand_pos(&mut r, 1.0, 1.0)).collect();
                    let dot = |m: &Material<T>| {
                        let mut df = vec![[0.0 as T; D]; n];
                        force_differential(m, Kernel::Quadratic, h as T, &p, &du, &mut df).unwrap();
                        let (mut s, mut a) = (0.0f64, 0.0f64);
                        for k in 0..n {
                            for c in 0..D {
                                s += (du[k][c] * df[k][c]) as f64;
                                a += (du[k][c] * df[k][c]).abs() as f64;
                            }
                        }
                        (s, a)
                    };
                    let (s, a) = dot(&proj);
                    // A sum of n·d products: (n·d + 2)ε of their magnitudes, plus the
                    // kernel's own rounding of Ĉ⁺ (≈ 32ε·κ, κ ≤ 5 here).
                    assert!(s <= (n * D + 2 + 160) as f64 * EPS * a, "δu·δf = {s} > 0");
                }
                // Negative curvature of the exact Ĉ: at F = diag(1.5, 1, 0.7) (U = V = I) the
                // skew ("twist") eigenmatrices eᵢeⱼᵀ − eⱼeᵢᵀ of the closer-to-1 pairs have
                // λ_skew < 0 (crate::hessian docs). δu_k = G (x_k − x_p) gives δF = G F
                // exactly (Σ (x_k − x_p) ∇w_kᵀ = I), so G = Z F⁻¹ probes Z:Ĉ:Z.
                let mut f = M::identity();
                f.cols[0][0] = 1.5;
                f.cols[D - 1][D - 1] = 0.7;
                let mut p = Particle::<T, D>::at_rest([1.3 as T; D], 1.0, 0.3);
                p.f_e = f;
                let s = Stencil::<T, D>::new(Kernel::Quadratic, Grid::Collocated, h as T, &p.x)
                    .unwrap();
                let finv = Matrix::cofactor(&f).transpose() * (1.0 / Matrix::det(&f));
                for (i, j) in [(0, 1), (0, D - 1), (D - 2, D - 1)] {
                    let mut z = M::ZERO;
                    z.cols[j][i] = 1.0;
                    z.cols[i][j] = -1.0;
                    let g = z * finv;
                    let du: Vec<[T; D]> = s.nodes().map(|nd| g.mul_vec(nd.dx)).collect();
                    let mut df = vec![[0.0 as T; D]; s.len()];
                    let mut sum = |m: &Material<T>| {
                        force_differential(m, Kernel::Quadratic, h as T, &p, &du, &mut df).unwrap();
                        du.iter()
                            .zip(&df)
                            .map(|(u, f)| (0..D).map(|c| (u[c] * f[c]) as f64).sum::<f64>())
                            .sum::<f64>()
                    };
                    positive += (sum(&exact) > 0.0) as usize;
                    assert!(sum(&proj) <= 64.0 * EPS, "projected: {}", sum(&proj));
                }
                assert!(positive > 0, "the exact Ĉ showed no negative curvature");
            }

            /// What is off is skipped: an isothermal scene never reads the temperature (NaN
            /// passes through), an elastic solid never clamps, liquids lose their deviatoric
            /// part, and `μ = 0` needs no decomposition (a liquid's stress is isotropic).
            #[test]
            fn levels_skip() {
                let h: T = 0.5;
                let x = [1.1 as T; D];
                let mut p = Particle::<T, D>::at_rest(x, 1.0, 0.1);
                p.temperature = T::NAN;
                let s = Stencil::<T, D>::new(Kernel::Quadratic, Grid::Collocated, h, &x).unwrap();
                // Grid velocity: a strong stretch along axis 0.
                let vel: Vec<[T; D]> = s
                    .nodes()
                    .map(|nd| {
                        let mut v = [0.0 as T; D];
                        v[0] = nd.index[0] as T * h * 2.0;
                        v
                    })
                    .collect();
                let grid = GridSample {
                    velocity: &vel,
                    temperature: None,
                };
                let el = Material::<T>::elastic(10.0, 10.0);
                let (q, info) = g2p_update(&el, Kernel::Quadratic, h, 0.1, &grid, &p).unwrap();
                assert!(q.temperature.is_nan());
                assert_eq!(info.halvings, 0);
                // F_E = I + 0.2 e₀e₀ᵀ exactly up to rounding, F_P untouched: no clamp.
                assert!((q.f_e.cols[0][0] as f64 - 1.2).abs() <= 64.0 * EPS);
                assert_eq!(q.f_p, M::identity());
                let plastic = Material::<T> {
                    plasticity: Some(Snow {
                        critical_compression: 0.025,
                        critical_stretch: 0.0075,
                        hardening: 10.0,
                    }),
                    ..el
                };
                let (q2, _) = g2p_update(&plastic, Kernel::Quadratic, h, 0.1, &grid, &p).unwrap();
                assert!((q2.f_e.cols[0][0] as f64 - 1.0075).abs() <= 64.0 * EPS);
                let jp = Matrix::det(&q2.f_p) as f64;
                assert!((jp - 1.2 / 1.0075).abs() <= 64.0 * EPS);
                // Heat on without temperatures is refused, the particle left as it was.
                let hm = heat_material::<T>();
                assert_eq!(
                    g2p_update(&hm, Kernel::Quadratic, h, 0.1, &grid, &p).map(|_| ()),
                    Err(Error::InvalidArgument)
                );
            }
        }
    };
}

particle_tests!(d2_f32, f32, 2);
particle_tests!(d2_f64, f64, 2);
particle_tests!(d3_f32, f32, 3);
particle_tests!(d3_f64, f64, 3);
