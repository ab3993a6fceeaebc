//! P2G: reference match, node layouts and batch positions, MAC conservation, overflowing runs.
use crate::isas;
use crate::{materials, particles, runs_of_particles, DenseGrid, Store, CH, FORCE, HC, MASS, MOM};
use ampm_core::kernel::batch::BatchReal;
use ampm_core::kernel::{Dim, LaneDim};
use ampm_core::lane::{Isa, IsaKind};
use ampm_core::particle::transfer::p2g::{self, P2gArgs, P2gView};
use ampm_core::particle::transfer::{Channel, NodeBox};
use ampm_core::particle::update;
use ampm_core::particle::{Grid, Kernel, Material, Particle, Phase, Stencil};
use ampm_core::polar::{DefaultSvd, SvdMethod};
use ampm_core::{Error, Mat, Matrix, Real};
use ampm_tools::workload::HaarRotation;
use rand::SeedableRng;
use rand_pcg::Pcg64;

/// Reference node sums in f64 and the sums of the contributions' magnitudes (the scale of
/// their rounding).
fn p2g_reference<T: Real, const D: usize>(
    mat: &Material<T>,
    kernel: Kernel,
    h: T,
    idt: T,
    ps: &[Particle<T, D>],
    g: &DenseGrid<T, D>,
) -> (Vec<Vec<f64>>, Vec<Vec<f64>>)
where
    Mat<T, D>: Matrix<Scalar = T, Vector = [T; D]>,
    DefaultSvd: SvdMethod<Mat<T, D>>,
{
    let len = g.ch[0].len();
    let mut sum = vec![vec![0.0; len]; CH];
    let mut mag = vec![vec![0.0; len]; CH];
    for p in ps {
        let r = update::p2g(mat, kernel, h, p).expect("reference p2g");
        let fmax = (0..D)
            .flat_map(|j| (0..D).map(move |i| (j, i)))
            .map(|(j, i)| r.force.cols[j][i].to_f64().abs())
            .fold(0.0, f64::max);
        for k in 0..r.stencil.len() {
            let nd = r.node(k);
            let i = g.index(nd.index);
            let gsum: f64 = nd.force.iter().map(|_| 0.0).sum::<f64>()
                + r.stencil
                    .node(k)
                    .grad
                    .iter()
                    .map(|x| x.to_f64().abs())
                    .sum::<f64>();
            let fscale = fmax * gsum;
            let mut add = |c: usize, v: f64, m: f64| {
                sum[c][i] += v;
                mag[c][i] += m;
            };
            add(MASS, nd.mass.to_f64(), nd.mass.to_f64().abs());
            for a in 0..D {
                let f = nd.force[a].to_f64();
                let m = nd.momentum[a].to_f64() + idt.to_f64() * f;
                // |w m (v + C dx)| ≤ w m (|v| + Σ|C||dx|): the scale of its rounding.
                let wm = nd.mass.to_f64();
                let vs = p.v[a].to_f64().abs()
                    + (0..D)
                        .map(|b| (p.affine.cols[b][a].to_f64() * nd_dx(&r.stencil, k, b)).abs())
                        .sum::<f64>();
                add(MOM + a, m, wm * vs + idt.to_f64() * fscale);
                add(FORCE + a, f, fscale);
            }
            add(
                HC,
                nd.heat_capacity.to_f64(),
                nd.heat_capacity.to_f64().abs(),
            );
            add(
                HC + 1,
                nd.thermal_energy.to_f64(),
                nd.thermal_energy.to_f64().abs(),
            );
            add(
                HC + 2,
                nd.conductivity.to_f64(),
                nd.conductivity.to_f64().abs(),
            );
        }
    }
    (sum, mag)
}

fn nd_dx<T: Real, const D: usize>(s: &Stencil<T, D>, k: usize, b: usize) -> f64 {
    s.node(k).dx[b].to_f64()
}

/// A bound on the difference between the transfer and the reference at one node: the SIMD
/// stress differs from the scalar one by at most 512ε of its scale (tests/batch/paths.rs bounds the
/// kernels at that), each contribution carries ≤ 16 roundings, and the node sums ≤ 64 more.
fn p2g_tol<T: Real>() -> f64 {
    (512.0 + 16.0 + 64.0) * T::EPSILON.to_f64()
}

fn p2g_matches<T: BatchReal, const D: usize>()
where
    Dim<D>: LaneDim<D>,
    Mat<T, D>: Matrix<Scalar = T, Vector = [T; D]>,
    Mat<f64, D>: Matrix<Scalar = f64, Vector = [f64; D]> + HaarRotation,
    DefaultSvd: SvdMethod<Mat<T, D>>,
{
    let cells = 12;
    let hf = 0.05;
    let h = T::from_f64(hf);
    for (name, mat) in materials::<T>() {
        for kernel in [Kernel::Quadratic, Kernel::Cubic] {
            for isa in isas() {
                let mut rng = Pcg64::seed_from_u64(7);
                let ps = particles::<T, D>(&mut rng, 77, hf, cells, &mat);
                let mut store = Store::from(&ps);
                let mut g = DenseGrid::<T, D>::new([-1; D], [cells + 2; D]);
                let idt = T::from_f64(1e-4);
                let args = P2gArgs {
                    kernel,
                    grid: Grid::Collocated,
                    h,
                    impulse_dt: idt,
                };
                let view = g.p2g_view();
                let raw = store.raw();
                // SAFETY: the arrays hold 77 particles; the channels cover the box.
                let st = unsafe { p2g::p2g(isa, &mat, &args, ps.len(), &raw, &view) };
                assert_eq!(st.error, None, "{name} {kernel:?} {isa:?}");
                assert_eq!(st.first_failed, ps.len());
                let (sum, mag) = p2g_reference(&mat, kernel, h, idt, &ps, &g);
                let tol = p2g_tol::<T>();
                let heat = mat.heat.is_some();
                for c in 0..CH {
                    if (c >= FORCE + D && c < HC) || (c >= MOM + D && c < FORCE) {
                        continue;
                    }
                    for i in 0..sum[c].len() {
                        let got = g.ch[c][i].to_f64();
                        let want = if c >= HC && !heat { 0.0 } else { sum[c][i] };
                        let bound = tol * mag[c][i] + f64::from(T::MIN_POSITIVE.to_f64() as f32);
                        assert!(
                            (got - want).abs() <= bound,
                            "{name} {kernel:?} {isa:?} channel {c} node {i}: {got} vs {want} \
                             (bound {bound})"
                        );
                    }
                }
                assert_eq!(store, Store::from(&ps), "P2G writes no particle field");
            }
        }
    }
}

#[test]
fn p2g_matches_reference_2d_f32() {
    p2g_matches::<f32, 2>();
}
#[test]
fn p2g_matches_reference_2d_f64() {
    p2g_matches::<f64, 2>();
}
#[test]
fn p2g_matches_reference_3d_f32() {
    p2g_matches::<f32, 3>();
}
#[test]
fn p2g_matches_reference_3d_f64() {
    p2g_matches::<f64, 3>();
}

/// Interleaved node structs (all channels of a node adjacent, reversed axis order in memory)
/// give the same bits as separate arrays; a particle's contribution does not depend on its
/// index in the batch (lanes are independent).
#[test]
fn layouts_and_positions_give_the_same_bits() {
    type T = f32;
    const D: usize = 3;
    let (cells, hf) = (12, 0.05);
    let h = hf as T;
    let mat = materials::<T>()[0].1;
    let mut rng = Pcg64::seed_from_u64(3);
    let ps = particles::<T, D>(&mut rng, 40, hf, cells, &mat);
    let dims = [cells + 2; D];
    let lo = [-1; D];
    let args = P2gArgs {
        kernel: Kernel::Quadratic,
        grid: Grid::Collocated,
        h,
        impulse_dt: 0.0,
    };
    for isa in isas() {
        let mut sep = DenseGrid::<T, D>::new(lo, dims);
        let mut store = Store::from(&ps);
        let raw = store.raw();
        // SAFETY: as above.
        unsafe { p2g::p2g(isa, &mat, &args, ps.len(), &raw, &sep.p2g_view()) };
        // Interleaved: node struct of CH scalars, axis 2 fastest.
        let n: usize = dims.iter().map(|&d| d as usize).product();
        let mut il = vec![0.0 as T; n * CH];
        let s2 = CH as isize;
        let s1 = s2 * dims[2] as isize;
        let s0 = s1 * dims[1] as isize;
        let ch = |c: usize, il: &mut Vec<T>| Channel {
            // SAFETY: offset within the allocation.
            data: unsafe { il.as_mut_ptr().add(c) },
            stride: [s0, s1, s2],
        };
        let view = P2gView {
            nodes: NodeBox { lo, dims },
            mass: ch(MASS, &mut il),
            momentum: std::array::from_fn(|a| ch(MOM + a, &mut il)),
            force: std::array::from_fn(|a| ch(FORCE + a, &mut il)),
            heat_capacity: Channel::<*mut T, D>::none(),
            thermal_energy: Channel::<*mut T, D>::none(),
            conductivity: Channel::<*mut T, D>::none(),
        };
        // SAFETY: the interleaved array covers the box.
        unsafe { p2g::p2g(isa, &mat, &args, ps.len(), &raw, &view) };
        for c in 0..FORCE + D {
            for (k, idx) in (0..n).map(|k| (k, k)) {
                let i = [
                    (idx % dims[0] as usize) as isize,
                    ((idx / dims[0] as usize) % dims[1] as usize) as isize,
                    (idx / (dims[0] * dims[1]) as usize) as isize,
                ];
                let off = (i[0] * s0 + i[1] * s1 + i[2] * s2) as usize + c;
                assert_eq!(sep.ch[c][k].to_bits(), il[off].to_bits(), "{isa:?} ch {c}");
            }
        }
        // Position independence: a particle alone gives the bits it gives at any index of a
        // batch whose other particles are ≥ 4 cells away along axis 0 (disjoint stencils).
        let mut near: Vec<Particle<T, D>> = ps.clone();
        for q in near.iter_mut() {
            q.x[0] = 4.0 * h + (q.x[0] / h).fract() * h;
        }
        for k in [0usize, 5, 17, 31, 39] {
            let mut p = near[k];
            p.x[0] += 5.0 * h;
            let mut batch = near.clone();
            batch[k] = p;
            let mut s1 = Store::from(&[p]);
            let mut g1 = DenseGrid::<T, D>::new(lo, dims);
            // SAFETY: one particle.
            unsafe { p2g::p2g(isa, &mat, &args, 1, &s1.raw(), &g1.p2g_view()) };
            let mut sb = Store::from(&batch);
            let mut gb = DenseGrid::<T, D>::new(lo, dims);
            // SAFETY: as above.
            unsafe { p2g::p2g(isa, &mat, &args, batch.len(), &sb.raw(), &gb.p2g_view()) };
            let i = k;
            let s = Stencil::new(Kernel::Quadratic, Grid::Collocated, h, &p.x).unwrap();
            for nd in s.nodes() {
                let ix = g1.index(nd.index);
                for c in 0..FORCE + D {
                    assert_eq!(
                        g1.ch[c][ix].to_bits(),
                        gb.ch[c][ix].to_bits(),
                        "{isa:?} particle at batch index {i}, channel {c}"
                    );
                }
            }
        }
    }
}

/// A particle's contribution has the same bits alone and at any index of a batch, for every
/// material, with the impulse term and (with heat) the heat channels: in a batch, whole groups
/// of eight particles take their per-particle pass (reads, checks, moduli, stress factors) on
/// lanes in f32, and a particle alone takes it on its own. The batch's other particles are ≥ 4 cells
/// away along axis 0 (disjoint stencils); one of them is invalid, so that its group of eight
/// takes the pass one by one. The batch of 80 spans two chunks of the widest lanes (64 in
/// `f32` on AVX-512), and the particle moves through lanes on both sides of 32 and of 64.
fn batch_index_independent<T: BatchReal, const D: usize>()
where
    Dim<D>: LaneDim<D>,
    Mat<T, D>: Matrix<Scalar = T, Vector = [T; D]>,
    Mat<f64, D>: Matrix<Scalar = f64, Vector = [f64; D]> + HaarRotation,
    DefaultSvd: SvdMethod<Mat<T, D>>,
{
    let (cells, hf) = (12, 0.05);
    let h = T::from_f64(hf);
    let (lo, dims) = ([-1; D], [cells + 2; D]);
    let args = P2gArgs {
        kernel: Kernel::Quadratic,
        grid: Grid::Collocated,
        h,
        impulse_dt: T::from_f64(1e-4),
    };
    for (name, mat) in materials::<T>() {
        let mut rng = Pcg64::seed_from_u64(5);
        let mut near = particles::<T, D>(&mut rng, 80, hf, cells, &mat);
        for q in near.iter_mut() {
            let c = q.x[0] / h;
            q.x[0] = T::from_f64(4.0) * h + (c - c.floor()) * h;
        }
        // Particle 33 (group 32..40) has a NaN velocity.
        near[33].v[0] = T::from_f64(f64::NAN);
        for isa in isas() {
            for k in [0usize, 5, 17, 31, 36, 39, 47, 63, 64, 79] {
                let mut p = near[k];
                p.x[0] += T::from_f64(5.0) * h;
                let mut batch = near.clone();
                batch[k] = p;
                let mut s1 = Store::from(&[p]);
                let mut g1 = DenseGrid::<T, D>::new(lo, dims);
                // SAFETY: one particle; the channels cover the box.
                let st = unsafe { p2g::p2g(isa, &mat, &args, 1, &s1.raw(), &g1.p2g_view()) };
                assert_eq!(st.error, None, "{name} {isa:?} alone");
                let mut sb = Store::from(&batch);
                let mut gb = DenseGrid::<T, D>::new(lo, dims);
                // SAFETY: as above.
                let st =
                    unsafe { p2g::p2g(isa, &mat, &args, batch.len(), &sb.raw(), &gb.p2g_view()) };
                assert_eq!(
                    (st.first_failed, st.error),
                    (33, Some(Error::NonFinite)),
                    "{name} {isa:?} batch"
                );
                let s = Stencil::new(Kernel::Quadratic, Grid::Collocated, h, &p.x).unwrap();
                let mut written = false;
                for nd in s.nodes() {
                    let ix = g1.index(nd.index);
                    for c in 0..CH {
                        written |= g1.ch[c][ix] != T::ZERO;
                        assert_eq!(
                            g1.ch[c][ix].to_f64().to_bits(),
                            gb.ch[c][ix].to_f64().to_bits(),
                            "{name} {isa:?} {D}D particle at batch index {k}, channel {c}"
                        );
                    }
                }
                assert!(written, "{name} {isa:?}: the particle wrote its nodes");
            }
        }
    }
}

#[test]
fn batch_index_independent_2d_f32() {
    batch_index_independent::<f32, 2>();
}
#[test]
fn batch_index_independent_3d_f32() {
    batch_index_independent::<f32, 3>();
}
#[test]
fn batch_index_independent_3d_f64() {
    batch_index_independent::<f64, 3>();
}

/// MAC P2G: on every face grid, node masses sum to the particle masses, momentum component
/// `a` to `Σ m v_a` (APIC adds `m C Σ w (x_i − x_p) = 0`), and the forces to zero
/// (`Σ ∇w_i = 0`), each within the rounding of its sum.
fn mac_p2g_conserves<T: BatchReal, const D: usize>()
where
    Dim<D>: LaneDim<D>,
    Mat<T, D>: Matrix<Scalar = T, Vector = [T; D]>,
    Mat<f64, D>: Matrix<Scalar = f64, Vector = [f64; D]> + HaarRotation,
{
    let (cells, hf) = (12, 0.05);
    let h = T::from_f64(hf);
    let mat = materials::<T>()[1].1;
    let eps = T::EPSILON.to_f64();
    for kernel in [Kernel::Quadratic, Kernel::Cubic] {
        for isa in isas() {
            let mut rng = Pcg64::seed_from_u64(11);
            let ps = particles::<T, D>(&mut rng, 50, hf, cells, &mat);
            let mut store = Store::from(&ps);
            for a in 0..D {
                let mut g = DenseGrid::<T, D>::new([-2; D], [cells + 4; D]);
                let args = P2gArgs {
                    kernel,
                    grid: Grid::Face(a),
                    h,
                    impulse_dt: T::ZERO,
                };
                let raw = store.raw();
                // SAFETY: as above.
                let st = unsafe { p2g::p2g(isa, &mat, &args, ps.len(), &raw, &g.p2g_view()) };
                assert_eq!(st.error, None);
                let total = |c: usize| g.ch[c].iter().map(|x| x.to_f64()).sum::<f64>();
                let abs = |c: usize| g.ch[c].iter().map(|x| x.to_f64().abs()).sum::<f64>();
                let m: f64 = ps.iter().map(|p| p.mass.to_f64()).sum();
                let mv: f64 = ps.iter().map(|p| (p.mass * p.v[a]).to_f64()).sum();
                let mv_abs: f64 = ps
                    .iter()
                    .map(|p| p.mass.to_f64() * (p.v[a].to_f64().abs() + 3.0 * D as f64 * hf))
                    .sum();
                let k = kernel.node_count(D) as f64;
                assert!(
                    (total(MASS) - m).abs() <= 8.0 * k * eps * m,
                    "mass face {a}"
                );
                assert!(
                    (total(MOM + a) - mv).abs() <= 16.0 * k * eps * mv_abs,
                    "momentum face {a}: {} vs {mv}",
                    total(MOM + a)
                );
                assert!(
                    total(FORCE + a).abs() <= 16.0 * k * eps * abs(FORCE + a).max(1e-30) * 8.0,
                    "force face {a}: {}",
                    total(FORCE + a)
                );
                for b in (0..D).filter(|&b| b != a) {
                    assert!(
                        g.ch[MOM + b].iter().all(|x| *x == T::ZERO),
                        "only component a"
                    );
                }
                assert!(
                    g.ch[HC].iter().all(|x| *x == T::ZERO),
                    "no heat on a face grid"
                );
            }
        }
    }
}

#[test]
fn mac_p2g_conserves_2d_f32() {
    mac_p2g_conserves::<f32, 2>();
}
#[test]
fn mac_p2g_conserves_3d_f64() {
    mac_p2g_conserves::<f64, 3>();
}

/// A run whose tile sum is not finite is added one particle at a time: the particles that
/// overflow (here every stencil of the first cell reaches a NaN node) are refused and write
/// nothing, the first failure is the lowest index, and the other runs are written.
#[test]
fn p2g_run_that_overflows_is_added_one_by_one() {
    type T = f32;
    const D: usize = 3;
    let h = 0.05;
    let mat = Material::<T>::elastic(10.0, 100.0);
    let ps = runs_of_particles::<T, D>(h);
    let args = P2gArgs {
        kernel: Kernel::Quadratic,
        grid: Grid::Collocated,
        h: h as T,
        impulse_dt: 1.0e-3,
    };
    for isa in isas() {
        let mut g = DenseGrid::<T, D>::new([0; D], [16; D]);
        // Node (6, 6, 6) is in the stencil of every particle of cell 5 and of none of cell 9.
        let poisoned = g.index([6; D]);
        g.ch[MASS][poisoned] = T::NAN;
        let mut only2 = g.clone();
        let mut s1 = Store::from(&ps);
        // SAFETY: six particles; the channels cover the box.
        let st = unsafe { p2g::p2g(isa, &mat, &args, 6, &s1.raw(), &g.p2g_view()) };
        assert_eq!(
            (st.first_failed, st.error),
            (0, Some(Error::Overflow)),
            "{isa:?}"
        );
        let mut s2 = Store::from(&ps[2..3]);
        // SAFETY: one particle.
        let st = unsafe { p2g::p2g(isa, &mat, &args, 1, &s2.raw(), &only2.p2g_view()) };
        assert_eq!(st.error, None);
        assert_eq!(
            g.bits(),
            only2.bits(),
            "{isa:?}: only particle 2 was written"
        );
        // A later particle's own failure (NaN velocity, noted before its run is added) does
        // not hide an earlier particle's overflow in that run; without the bad node, the NaN
        // velocity is the first failure.
        let mut clean = DenseGrid::<T, D>::new([0; D], [16; D]);
        let mut bad = ps.clone();
        bad[4].v[1] = T::NAN;
        clean.ch[MASS][poisoned] = T::INFINITY;
        let mut s3 = Store::from(&bad);
        // SAFETY: six particles.
        let st = unsafe { p2g::p2g(isa, &mat, &args, 6, &s3.raw(), &clean.p2g_view()) };
        assert_eq!(
            (st.first_failed, st.error),
            (0, Some(Error::Overflow)),
            "{isa:?}"
        );
        clean.ch[MASS][poisoned] = 0.0;
        let st = unsafe { p2g::p2g(isa, &mat, &args, 6, &s3.raw(), &clean.p2g_view()) };
        assert_eq!(
            (st.first_failed, st.error),
            (4, Some(Error::NonFinite)),
            "{isa:?}"
        );
    }
}

/// The usual channel sets (mass and momentum, then optionally the heat channels, with no force
/// channel) have particle loops of their own, with the channel terms known at compile time.
/// Their node sums have the bits of the per-channel form (the same channels with the force
/// channels also written), and the same bits on every vector instruction set, with and
/// without the impulse term. The particles are sorted by cell, as a host sorts them, so that
/// long runs share a node tile. Each material also runs as a batch of liquid particles only
/// (`μ = 0`), whose chunks sum an isotropic force without the terms of its zero entries.
fn fixed_channel_sets_give_the_per_channel_bits<T: BatchReal, const D: usize>()
where
    Dim<D>: LaneDim<D>,
    Mat<T, D>: Matrix<Scalar = T, Vector = [T; D]>,
    Mat<f64, D>: Matrix<Scalar = f64, Vector = [f64; D]> + HaarRotation,
    DefaultSvd: SvdMethod<Mat<T, D>>,
{
    let (cells, hf) = (10, 0.05);
    let h = T::from_f64(hf);
    let (lo, dims) = ([-1; D], [cells + 2; D]);
    let all = materials::<T>().into_iter();
    for (name, mat, liquid) in all.flat_map(|(n, m)| [(n, m, false), (n, m, true)]) {
        let mut rng = Pcg64::seed_from_u64(13);
        let mut ps = particles::<T, D>(&mut rng, 300, hf, cells, &mat);
        if liquid {
            for p in &mut ps {
                // A liquid's thermal state: above the melting point, its latent heat taken.
                p.phase = Phase::Liquid;
                p.temperature = T::from_f64(crate::TM + 5.0);
                p.latent = T::from_f64(crate::LATENT);
            }
        }
        let name = if liquid {
            format!("{name} (liquid)")
        } else {
            name.to_string()
        };
        let cell = |p: &Particle<T, D>| -> [i64; D] {
            let mut c = [0i64; D];
            for a in 0..D {
                c[D - 1 - a] = (p.x[a] / h).to_f64().floor() as i64;
            }
            c
        };
        ps.sort_by_key(cell);
        let heat = mat.heat.is_some();
        // Mass and momentum, then the heat channels when the material has heat.
        let written: Vec<usize> = (0..CH)
            .filter(|&c| c < MOM + D || (heat && c >= HC))
            .collect();
        for idt in [0.0, 1e-4] {
            let args = P2gArgs {
                kernel: Kernel::Quadratic,
                grid: Grid::Collocated,
                h,
                impulse_dt: T::from_f64(idt),
            };
            let mut vector_bits: Option<(Isa, Vec<Vec<u64>>)> = None;
            for isa in isas() {
                let label = format!("{D}D {} {name} impulse {idt} {isa:?}", T::NAME);
                let mut full = DenseGrid::<T, D>::new(lo, dims);
                let mut store = Store::from(&ps);
                let raw = store.raw();
                // SAFETY: the arrays hold the particles; the channels cover the box.
                let st = unsafe { p2g::p2g(isa, &mat, &args, ps.len(), &raw, &full.p2g_view()) };
                assert_eq!(st.error, None, "{label}");
                let mut fixed = DenseGrid::<T, D>::new(lo, dims);
                let mut view = fixed.p2g_view();
                view.force = [Channel::<*mut T, D>::none(); D];
                if !heat {
                    view.heat_capacity = Channel::<*mut T, D>::none();
                    view.thermal_energy = Channel::<*mut T, D>::none();
                    view.conductivity = Channel::<*mut T, D>::none();
                }
                let mut store = Store::from(&ps);
                let raw = store.raw();
                // SAFETY: as above.
                let st = unsafe { p2g::p2g(isa, &mat, &args, ps.len(), &raw, &view) };
                assert_eq!(st.error, None, "{label}");
                let (fb, xb) = (full.bits(), fixed.bits());
                let mut sums = Vec::new();
                for &c in &written {
                    assert!(
                        xb[c].iter().any(|&b| b != 0),
                        "{label}: channel {c} written"
                    );
                    assert_eq!(fb[c], xb[c], "{label}: channel {c}, fixed set against full");
                    sums.push(xb[c].clone());
                }
                if isa.kind() == IsaKind::Scalar {
                    continue;
                }
                match &vector_bits {
                    None => vector_bits = Some((isa, sums)),
                    Some((first, want)) => assert_eq!(&sums, want, "{label} against {first:?}"),
                }
            }
        }
    }
}

#[test]
fn fixed_channel_sets_give_the_per_channel_bits_2d_f32() {
    fixed_channel_sets_give_the_per_channel_bits::<f32, 2>();
}

#[test]
fn fixed_channel_sets_give_the_per_channel_bits_3d_f32() {
    fixed_channel_sets_give_the_per_channel_bits::<f32, 3>();
}

#[test]
fn fixed_channel_sets_give_the_per_channel_bits_3d_f64() {
    fixed_channel_sets_give_the_per_channel_bits::<f64, 3>();
}
