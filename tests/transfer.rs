//! Batch transfers through grid views (`ampm_core::particle::transfer`), on every instruction
//! set of this CPU:
//!
//! 1. P2G equals the per-particle reference (`update::p2g` and `P2g::node`, accumulated in f64)
//!    within the rounding of the SIMD stress (bounded in tests/batch.rs) and of the sums;
//!    interleaved node structs give the same bits as separate arrays; a particle's contribution
//!    does not depend on its index in the batch.
//! 2. MAC P2G conserves mass and momentum on every face grid and its forces sum to zero.
//! 3. G2P equals the per-particle reference (`g2p_update` on the gathered stencil values); on a
//!    linear velocity field (collocated and MAC) it reproduces `v = v₀ + A x`, `C = A`,
//!    `∇v = A` (B-splines reproduce linear functions; an independent check of the node loops).
//! 4. Failures: outside the box, overflow (large m·v, large heat capacity, tiny h), NaN in a
//!    node that is read: the status, the first index, and nothing written (grid and particle
//!    bits unchanged); NaN in nodes no stencil reads is harmless.
//! 5. The force differential: exact mode equals `Stiffness::d_force_matrix` (itself checked by
//!    finite differences in tests/particle.rs); `K` is symmetric; with the PSD option
//!    `⟨δu, K δu⟩ ≤ 0` for every `δu`, including a dilational part that is indefinite, and it
//!    equals the exact differential where that is already definite; unprepared slots are
//!    refused.
use ampm_core::kernel::batch::BatchReal;
use ampm_core::kernel::{Dim, LaneDim};
use ampm_core::lane::Isa;
use ampm_core::particle::implicit::slot_len;
use ampm_core::particle::transfer::force::{self, ForceView};
use ampm_core::particle::transfer::g2p::{self, G2pArgs, G2pView};
use ampm_core::particle::transfer::p2g::{self, P2gArgs, P2gView};
use ampm_core::particle::transfer::{Channel, NodeBox, Particles};
use ampm_core::particle::update::{self, elastic_energy, Stiffness};
use ampm_core::particle::{
    g2p_update, Definiteness, Dilation, Grid, GridSample, Heat, Kernel, Material, Particle, Phase,
    PhaseParams, Snow, Stencil,
};
use ampm_core::polar::{DefaultSvd, SvdMethod};
use ampm_core::{hessian::HessianDim, Error, Mat, Matrix, Real};
use ampm_tools::workload::HaarRotation;
use rand::{Rng, SeedableRng};
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
/// stress differs from the scalar one by at most 512ε of its scale (tests/batch.rs bounds the
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
            for isa in Isa::available() {
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
    for isa in Isa::available() {
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
        for isa in Isa::available() {
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

/// Fills channels `MOM..MOM+d` with a velocity field `v(x)` at the nodes of `grid`, and the
/// temperature channels with `t(x)`, `t_old(x)`.
fn fill<T: Real, const D: usize>(
    g: &mut DenseGrid<T, D>,
    grid: Grid,
    h: f64,
    v: impl Fn([f64; D]) -> [f64; D],
    t: impl Fn([f64; D]) -> (f64, f64),
) {
    let n = g.ch[0].len();
    for k in 0..n {
        let mut idx = [0i32; D];
        let mut q = k;
        for a in 0..D {
            idx[a] = g.lo[a] + (q % g.dims[a] as usize) as i32;
            q /= g.dims[a] as usize;
        }
        let x: [f64; D] = std::array::from_fn(|a| {
            let shift = match grid {
                Grid::Face(f) if f != a => 0.5,
                _ => 0.0,
            };
            (idx[a] as f64 + shift) * h
        });
        let vv = v(x);
        for a in 0..D {
            g.ch[MOM + a][k] = T::from_f64(vv[a]);
        }
        let (tn, to) = t(x);
        g.ch[HC][k] = T::from_f64(tn);
        g.ch[HC + 1][k] = T::from_f64(to);
    }
}

/// A grid over `[-1, cells + 1)` per axis with random node velocities in `[-1, 1)` m/s and
/// new and old node temperatures within 5 K of `TM` (what G2P reads), from `seed`.
fn g2p_grid<T: Real, const D: usize>(cells: i32, seed: u64) -> DenseGrid<T, D> {
    let mut g = DenseGrid::<T, D>::new([-1; D], [cells + 2; D]);
    let mut r2 = Pcg64::seed_from_u64(seed);
    for k in 0..g.ch[0].len() {
        for a in 0..D {
            g.ch[MOM + a][k] = T::from_f64(r2.random_range(-1.0..1.0));
        }
        g.ch[HC][k] = T::from_f64(TM + r2.random_range(-5.0..5.0));
        g.ch[HC + 1][k] = T::from_f64(TM + r2.random_range(-5.0..5.0));
    }
    g
}

/// G2P equals the per-particle reference on a random grid (every material, both kernels).
fn g2p_matches<T: BatchReal, const D: usize>()
where
    Mat<T, D>: Matrix<Scalar = T, Vector = [T; D]>,
    Mat<f64, D>: Matrix<Scalar = f64, Vector = [f64; D]> + HaarRotation,
    DefaultSvd: SvdMethod<Mat<T, D>>,
{
    let (cells, hf) = (12, 0.05);
    let h = T::from_f64(hf);
    let dt = T::from_f64(1e-3);
    for isa in Isa::available() {
        for (name, mat) in materials::<T>() {
            for kernel in [Kernel::Quadratic, Kernel::Cubic] {
                let mut rng = Pcg64::seed_from_u64(5);
                let ps = particles::<T, D>(&mut rng, 60, hf, cells, &mat);
                let g = g2p_grid::<T, D>(cells, 9);
                let mut store = Store::from(&ps);
                let args = G2pArgs { kernel, h, dt };
                let raw = store.raw();
                // SAFETY: as above.
                let st = unsafe {
                    g2p::g2p_update(isa, &mat, &args, ps.len(), &raw, &g.g2p_view(), None)
                };
                for (i, p) in ps.iter().enumerate() {
                    let s = Stencil::new(kernel, Grid::Collocated, h, &p.x).unwrap();
                    let vel: Vec<[T; D]> = s
                        .nodes()
                        .map(|nd| std::array::from_fn(|a| g.ch[MOM + a][g.index(nd.index)]))
                        .collect();
                    let tn: Vec<T> = s.nodes().map(|nd| g.ch[HC][g.index(nd.index)]).collect();
                    let to: Vec<T> = s
                        .nodes()
                        .map(|nd| g.ch[HC + 1][g.index(nd.index)])
                        .collect();
                    let sample = GridSample {
                        velocity: &vel,
                        temperature: Some((&tn, &to)),
                    };
                    let want = g2p_update(&mat, kernel, h, dt, &sample, p);
                    let got = store.get::<D>(i);
                    match want {
                        Err(e) => {
                            assert_eq!(got, *p, "{name}: a failed particle keeps its state");
                            assert!(st.error.is_some(), "{name} particle {i}: {e:?}");
                        }
                        Ok((w, _)) => {
                            // The affine matrix is formed as (Σ w v oᵀ − v fxᵀ)/(κh) instead of
                            // Σ w v (x_i − x_p)ᵀ/(κh²): a few roundings of its terms' scale
                            // (|v|·K/(κh)); everything else is formed in the same order.
                            let eps = T::EPSILON.to_f64();
                            let vmax = 1.0;
                            let kk = kernel.width() as f64;
                            let ascale = vmax * kk / (kernel.apic_moment::<f64>() * hf);
                            for j in 0..D {
                                for r in 0..D {
                                    let (a, b) = (got.affine.cols[j][r], w.affine.cols[j][r]);
                                    assert!(
                                        (a - b).to_f64().abs() <= 32.0 * eps * ascale,
                                        "{name} {kernel:?} C[{r}][{j}]: {a:?} vs {b:?}"
                                    );
                                }
                            }
                            let close = |a: T, b: T, scale: f64| {
                                (a - b).to_f64().abs() <= 64.0 * eps * scale.max(b.to_f64().abs())
                            };
                            for a in 0..D {
                                assert!(close(got.x[a], w.x[a], 1.0), "{name} x");
                                assert!(close(got.v[a], w.v[a], vmax), "{name} v");
                            }
                            for j in 0..D {
                                for r in 0..D {
                                    assert!(close(got.f_e.cols[j][r], w.f_e.cols[j][r], 2.0));
                                    assert!(close(got.f_p.cols[j][r], w.f_p.cols[j][r], 2.0));
                                }
                            }
                            assert!(close(got.temperature, w.temperature, TM), "{name} T");
                            assert!(close(got.latent, w.latent, LATENT), "{name} U");
                            assert_eq!(got.phase, w.phase, "{name} phase");
                        }
                    }
                }
            }
        }
    }
}

/// G2P of a whole batch gives the bits of calls of one particle each, on every instruction set
/// and material, for solid and for liquid batches: the batch updates chunks of elastic solids
/// and of liquids on SIMD lanes, a call of one particle updates it alone (the scalar update).
/// The batch mixes chunks that stay on lanes with chunks that must fall back: a particle with a
/// NaN `F_P`, one whose `F_E` is inverted, one needing the remedy for `det(I + Δt∇v) ≤ 0` (a
/// strongly compressive node velocity), a particle of the other phase, and one whose `F_E` has
/// a subnormal column (the liquid projection's scalings leave the normal range). Liquid batches
/// also have isotropic and general `F_P` and an `F_E` with columns of very different scales
/// (the projection's root on equilibrated columns), in chunks that stay on lanes.
fn g2p_chunks_match_single<T: BatchReal, const D: usize>()
where
    Mat<T, D>: Matrix<Scalar = T, Vector = [T; D]>,
    Mat<f64, D>: Matrix<Scalar = f64, Vector = [f64; D]> + HaarRotation,
    DefaultSvd: SvdMethod<Mat<T, D>>,
{
    let (cells, hf) = (12, 0.05);
    let h = T::from_f64(hf);
    let dt = T::from_f64(1e-3);
    for isa in Isa::available() {
        for ((name, mat), liquid) in materials::<T>()
            .into_iter()
            .flat_map(|m| [(m.clone(), false), (m, true)])
        {
            if liquid && mat.heat.is_some() {
                // Heat is updated per particle: nothing on lanes to compare.
                continue;
            }
            let mut rng = Pcg64::seed_from_u64(11);
            let mut ps = particles::<T, D>(&mut rng, 75, hf, cells, &mat);
            let (this, other) = if liquid {
                (Phase::Liquid, Phase::Solid)
            } else {
                (Phase::Solid, Phase::Liquid)
            };
            for (i, p) in ps.iter_mut().enumerate() {
                p.phase = this;
                if liquid && i % 3 == 1 {
                    p.f_p = Mat::identity() * T::from_f64(rng.random_range(0.8..1.25));
                } else if liquid && i % 3 == 2 {
                    p.f_p = deformation::<D>(&mut rng, 0.8, 1.25).cast();
                }
            }
            ps[9].f_p.cols[0][0] = T::from_f64(f64::NAN);
            ps[20].f_e = Mat::identity();
            ps[20].f_e.cols[0][0] = -T::ONE;
            ps[37].phase = other;
            // Columns 2^∓(bias/2) and 2^±(bias/3) apart from the others: exact scalings on lanes.
            let (k0, k1) = (T::MAX_EXP / 2, T::MAX_EXP / 3);
            ps[60].f_e.cols[0] = ps[60].f_e.cols[0].map(|x| x.scalbn(-k0));
            ps[60].f_e.cols[1] = ps[60].f_e.cols[1].map(|x| x.scalbn(k1));
            // A subnormal column: the scalar path decides.
            ps[70].f_e.cols[0] = ps[70].f_e.cols[0].map(|x| x.scalbn(-T::MAX_EXP - 4));
            // Particle 50 apart from the others (which lie in [4h, 8h] per axis), so that only
            // it reads the compressive nodes below.
            ps[50].x[0] = T::from_f64(11.3 * hf);
            let mut g = g2p_grid::<T, D>(cells, 12);
            // Around particle 50: node velocities along axis 0 converging at 2000 m/s per
            // cell, so that ∂v₀/∂x₀ ≈ −2000/h and det(I + Δt∇v) ≈ 1 − 2000·Δt/h < 0.
            let s50 = Stencil::new(Kernel::Quadratic, Grid::Collocated, h, &ps[50].x).unwrap();
            for nd in s50.nodes() {
                let k = g.index(nd.index);
                let o = nd.index[0] - s50.base[0] - 1;
                g.ch[MOM][k] = T::from_f64(-2000.0 * f64::from(o));
                for a in 1..D {
                    g.ch[MOM + a][k] = T::ZERO;
                }
            }
            let args = G2pArgs {
                kernel: Kernel::Quadratic,
                h,
                dt,
            };
            let mut batch = Store::from(&ps);
            let raw = batch.raw();
            // SAFETY: the arrays hold the particles; the grid covers their stencils.
            let st =
                unsafe { g2p::g2p_update(isa, &mat, &args, ps.len(), &raw, &g.g2p_view(), None) };
            let mut one = Store::from(&ps);
            let mut first = None;
            for i in 0..ps.len() {
                let r = one.raw();
                // SAFETY: particle `i` of the arrays, as one particle.
                let st1 = unsafe {
                    let at = Particles {
                        x: r.x.add(D * i),
                        v: r.v.add(D * i),
                        affine: r.affine.add(D * D * i),
                        f_e: r.f_e.add(D * D * i),
                        f_p: r.f_p.add(D * D * i),
                        mass: r.mass.add(i),
                        volume0: r.volume0.add(i),
                        temperature: r.temperature.add(i),
                        latent: r.latent.add(i),
                        phase: r.phase.add(i),
                    };
                    g2p::g2p_update(isa, &mat, &args, 1, &at, &g.g2p_view(), None)
                };
                if let (None, Some(e)) = (first, st1.error) {
                    first = Some((i, e));
                }
            }
            assert_eq!(
                first.map(|f| f.0).unwrap_or(ps.len()),
                st.first_failed,
                "{name} {liquid} {isa:?}"
            );
            assert_eq!(first.map(|f| f.1), st.error, "{name} {liquid} {isa:?}");
            assert!(first.is_some(), "{name}: the NaN particle fails");
            let bits = |s: &Store<T>| -> Vec<u64> {
                [
                    &s.x,
                    &s.v,
                    &s.affine,
                    &s.f_e,
                    &s.f_p,
                    &s.temperature,
                    &s.latent,
                ]
                .iter()
                .flat_map(|v| v.iter().map(|x| x.to_f64().to_bits()))
                .chain(s.phase.iter().map(|&c| u64::from(c)))
                .collect()
            };
            assert_eq!(bits(&batch), bits(&one), "{name} {liquid} {isa:?}");
        }
    }
}

#[test]
fn g2p_chunks_match_single_2d_f32() {
    g2p_chunks_match_single::<f32, 2>();
}
#[test]
fn g2p_chunks_match_single_3d_f32() {
    g2p_chunks_match_single::<f32, 3>();
}
#[test]
fn g2p_chunks_match_single_3d_f64() {
    g2p_chunks_match_single::<f64, 3>();
}

#[test]
fn g2p_matches_reference_2d_f32() {
    g2p_matches::<f32, 2>();
}
#[test]
fn g2p_matches_reference_2d_f64() {
    g2p_matches::<f64, 2>();
}
#[test]
fn g2p_matches_reference_3d_f32() {
    g2p_matches::<f32, 3>();
}
#[test]
fn g2p_matches_reference_3d_f64() {
    g2p_matches::<f64, 3>();
}

/// On `v(x) = v₀ + A x` (collocated or MAC), G2P gives `v_p = v₀ + A x_p`, `C_p = A`, and
/// `F_E ← (I + Δt A) F_E`, `x_p ← x_p + Δt v_p`, up to the rounding of the node sums
/// (a few ε of `|v|`, `|A|`).
fn linear_field<const D: usize>()
where
    Mat<f64, D>: Matrix<Scalar = f64, Vector = [f64; D]> + HaarRotation,
    DefaultSvd: SvdMethod<Mat<f64, D>>,
{
    let (cells, hf) = (12, 0.05);
    let dt = 1e-3;
    let mut rng = Pcg64::seed_from_u64(21);
    let a_m = rand_mat::<D>(&mut rng, 2.0);
    let v0: [f64; D] = std::array::from_fn(|_| rng.random_range(-1.0..1.0));
    let field = |x: [f64; D]| -> [f64; D] {
        let ax = a_m.mul_vec(x);
        std::array::from_fn(|a| v0[a] + ax[a])
    };
    let mat = materials::<f64>()[0].1;
    for isa in Isa::available() {
        for kernel in [Kernel::Quadratic, Kernel::Cubic] {
            for mac in [false, true] {
                let ps = particles::<f64, D>(&mut rng, 30, hf, cells, &mat);
                let mut store = Store::from(&ps);
                let mut col = DenseGrid::<f64, D>::new([-2; D], [cells + 4; D]);
                fill(&mut col, Grid::Collocated, hf, field, |_| (0.0, 0.0));
                let faces: [DenseGrid<f64, D>; D] = std::array::from_fn(|a| {
                    let mut g = DenseGrid::<f64, D>::new([-2; D], [cells + 4; D]);
                    fill(&mut g, Grid::Face(a), hf, field, |_| (0.0, 0.0));
                    g
                });
                let fviews: [G2pView<f64, D>; D] = std::array::from_fn(|a| faces[a].g2p_view());
                let args = G2pArgs { kernel, h: hf, dt };
                let raw = store.raw();
                // SAFETY: as above.
                let st = unsafe {
                    g2p::g2p_update(
                        isa,
                        &mat,
                        &args,
                        ps.len(),
                        &raw,
                        &col.g2p_view(),
                        mac.then_some(&fviews),
                    )
                };
                assert_eq!(st.error, None);
                let scale = 2.0 * (cells as f64) * hf + 1.0;
                let tol = 64.0 * f64::EPSILON * scale * 8.0;
                for (i, p) in ps.iter().enumerate() {
                    let q = store.get::<D>(i);
                    let v = field(p.x);
                    for a in 0..D {
                        assert!((q.v[a] - v[a]).abs() <= tol, "{kernel:?} mac {mac}: v");
                        assert!((q.x[a] - (p.x[a] + dt * q.v[a])).abs() <= 4.0 * f64::EPSILON);
                        for b in 0..D {
                            assert!(
                                (q.affine.cols[b][a] - a_m.cols[b][a]).abs() <= tol / hf,
                                "{kernel:?} mac {mac}: C[{a}][{b}] {} vs {}",
                                q.affine.cols[b][a],
                                a_m.cols[b][a]
                            );
                        }
                    }
                    let f_want = (Mat::<f64, D>::identity() + a_m * dt) * p.f_e;
                    for j in 0..D {
                        for r in 0..D {
                            assert!((q.f_e.cols[j][r] - f_want.cols[j][r]).abs() <= tol * dt / hf);
                        }
                    }
                }
            }
        }
    }
}

#[test]
fn linear_field_is_reproduced_2d() {
    linear_field::<2>();
}
#[test]
fn linear_field_is_reproduced_3d() {
    linear_field::<3>();
}

/// Failures: the status, the first index, nothing written.
#[test]
fn failures_write_nothing() {
    type T = f32;
    const D: usize = 3;
    let (cells, hf) = (12, 0.05f64);
    let h = hf as T;
    let (_, thermal) = materials::<T>()[2];
    for isa in Isa::available() {
        let mut rng = Pcg64::seed_from_u64(1);
        let base = particles::<T, D>(&mut rng, 20, hf, cells, &thermal);
        type Case = (&'static str, usize, Box<dyn Fn(&mut Particle<T, D>)>, Error);
        let cases: Vec<Case> = vec![
            (
                "outside",
                3,
                Box::new(|p| p.x[1] = -0.1),
                Error::OutsideGrid,
            ),
            (
                "m·v overflows",
                4,
                Box::new(|p| {
                    p.mass = 1.0e30;
                    p.v[0] = 1.0e10;
                }),
                Error::Overflow,
            ),
            (
                "m·c·T overflows",
                5,
                Box::new(|p| p.temperature = 1.0e38),
                Error::Overflow,
            ),
            (
                "NaN velocity",
                6,
                Box::new(|p| p.v[2] = T::NAN),
                Error::NonFinite,
            ),
        ];
        for (name, k, spoil, err) in cases {
            let mut ps = base.clone();
            spoil(&mut ps[k]);
            let mut store = Store::from(&ps);
            let mut g = DenseGrid::<T, D>::new([-1; D], [cells + 2; D]);
            let args = P2gArgs {
                kernel: Kernel::Quadratic,
                grid: Grid::Collocated,
                h,
                impulse_dt: 0.0,
            };
            // Only particle k, then everything: the grid of the batch equals that of the batch
            // without particle k (bit for bit: same order of sums).
            let raw = store.raw();
            // SAFETY: as above.
            let st = unsafe { p2g::p2g(isa, &thermal, &args, ps.len(), &raw, &g.p2g_view()) };
            assert_eq!(
                (st.first_failed, st.error),
                (k, Some(err)),
                "{name} {isa:?}"
            );
            let mut without = ps.clone();
            without.remove(k);
            let mut s2 = Store::from(&without);
            let mut g2 = DenseGrid::<T, D>::new([-1; D], [cells + 2; D]);
            // SAFETY: as above.
            unsafe {
                p2g::p2g(
                    isa,
                    &thermal,
                    &args,
                    without.len(),
                    &s2.raw(),
                    &g2.p2g_view(),
                )
            };
            assert_eq!(
                g.bits(),
                g2.bits(),
                "{name}: the failed particle wrote nothing"
            );
        }
        // Sums that would overflow a node value: the particle is refused, the node untouched.
        let mut ps = base.clone();
        ps[2].mass = 1.0e30;
        ps[2].v = [5.0e7; D];
        let mut store = Store::from(&ps);
        let mut g = DenseGrid::<T, D>::new([-1; D], [cells + 2; D]);
        for x in g.ch[MOM].iter_mut() {
            *x = 3.3e38;
        }
        let before = g.bits();
        let args = P2gArgs {
            kernel: Kernel::Quadratic,
            grid: Grid::Collocated,
            h,
            impulse_dt: 0.0,
        };
        let one = [ps[2]];
        let mut s1 = Store::from(&one);
        // SAFETY: as above.
        let st = unsafe { p2g::p2g(isa, &thermal, &args, 1, &s1.raw(), &g.p2g_view()) };
        assert_eq!(st.error, Some(Error::Overflow));
        assert_eq!(g.bits(), before);
        let _ = &mut store;
        // A tiny finite h with a velocity field that varies across the stencil: every input
        // is finite, so the result is either finite or Overflow (never NonFinite), and a
        // failure writes nothing. (1/(κh²) is never formed: C_p uses 1/(κh).)
        for hh in [1.0e-30 as T, 1.0e-37] {
            let mut tiny = base[..1].to_vec();
            tiny[0].x = [3.3 * hh; D];
            let mut s3 = Store::from(&tiny);
            let mut g3 = DenseGrid::<T, D>::new([-1; D], [8; D]);
            for k in 0..g3.ch[0].len() {
                g3.ch[MOM][k] = (k % 5) as T;
            }
            g3.ch[HC].iter_mut().for_each(|x| *x = TM as T);
            g3.ch[HC + 1].iter_mut().for_each(|x| *x = TM as T);
            let gargs = G2pArgs {
                kernel: Kernel::Quadratic,
                h: hh,
                dt: 1.0e-3,
            };
            let raw = s3.raw();
            // SAFETY: as above.
            let st =
                unsafe { g2p::g2p_update(isa, &thermal, &gargs, 1, &raw, &g3.g2p_view(), None) };
            match st.error {
                None => {
                    let q = s3.get::<D>(0);
                    assert!(q.affine.is_finite() && q.f_e.is_finite(), "h = {hh}");
                }
                Some(e) => {
                    assert_eq!(e, Error::Overflow, "h = {hh}");
                    assert_eq!(s3, Store::from(&tiny));
                }
            }
        }
    }
}

/// NaN in a node that a particle reads fails that particle (NonFinite) and leaves it as it
/// was; NaN in nodes no stencil reads (a host's massless nodes) is harmless.
#[test]
fn g2p_reads_only_stencil_nodes() {
    type T = f64;
    const D: usize = 2;
    let (cells, hf) = (16, 0.05);
    let mat = materials::<T>()[0].1;
    let mut rng = Pcg64::seed_from_u64(2);
    let mut ps = particles::<T, D>(&mut rng, 10, hf, cells, &mat);
    for p in ps.iter_mut() {
        p.x[0] = 5.2 * hf;
    }
    let mut g = DenseGrid::<T, D>::new([-1; D], [cells + 2; D]);
    for k in 0..g.ch[0].len() {
        let ix = (k % g.dims[0] as usize) as i32 - 1;
        let v = if ix > 8 { T::NAN } else { 0.5 };
        g.ch[MOM][k] = v;
        g.ch[MOM + 1][k] = v;
    }
    let mut store = Store::from(&ps);
    let args = G2pArgs {
        kernel: Kernel::Quadratic,
        h: hf,
        dt: 1e-3,
    };
    let raw = store.raw();
    let isa = Isa::detect();
    // SAFETY: as above.
    let st = unsafe { g2p::g2p_update(isa, &mat, &args, ps.len(), &raw, &g.g2p_view(), None) };
    assert_eq!(st.error, None);
    let mut s2 = Store::from(&ps[..1]);
    let s = Stencil::new(Kernel::Quadratic, Grid::Collocated, hf, &ps[0].x).unwrap();
    let i = g.index(s.node(4).index);
    g.ch[MOM + 1][i] = T::NAN;
    let raw = s2.raw();
    // SAFETY: as above.
    let st = unsafe { g2p::g2p_update(isa, &mat, &args, 1, &raw, &g.g2p_view(), None) };
    assert_eq!((st.first_failed, st.error), (0, Some(Error::NonFinite)));
    assert_eq!(s2, Store::from(&ps[..1]));
}

/// `δu ↦ δf` of one particle as a dense `(K^d·d)²` matrix, through prepare and apply.
fn stiffness_matrix<T: BatchReal, const D: usize>(
    isa: Isa,
    mat: &Material<T>,
    kernel: Kernel,
    h: T,
    p: &Particle<T, D>,
) -> (Vec<f64>, usize, Vec<usize>)
where
    Dim<D>: LaneDim<D>,
    Mat<T, D>: Matrix<Scalar = T, Vector = [T; D]>,
{
    let ps = [*p];
    let mut store = Store::from(&ps);
    let mut slot = vec![T::ZERO; slot_len(D)];
    let raw = store.raw();
    // SAFETY: one particle, one slot.
    let st = unsafe { force::prepare::<T, D>(isa, mat, 1, &raw, slot.as_mut_ptr()) };
    assert_eq!(st.error, None);
    let s = Stencil::new(kernel, Grid::Collocated, h, &p.x).unwrap();
    let lo = s.base;
    let dims = [kernel.width() as i32; D];
    let nodes: Vec<usize> = (0..s.len()).collect();
    let m = s.len() * D;
    let mut k = vec![0.0; m * m];
    for col in 0..m {
        let mut du = DenseGrid::<T, D>::new(lo, dims);
        du.ch[MOM + col % D][col / D] = T::ONE;
        let mut df = DenseGrid::<T, D>::new(lo, dims);
        let view = ForceView {
            nodes: du.nodes(),
            du: std::array::from_fn(|a| du.inp(MOM + a)),
            df: std::array::from_fn(|a| df.out(FORCE + a)),
        };
        // SAFETY: the channels cover the stencil.
        let st = unsafe {
            force::apply::<T, D>(isa, kernel, h, 1, store.x.as_ptr(), slot.as_ptr(), &view)
        };
        assert_eq!(st.error, None);
        for row in 0..m {
            k[row * m + col] = df.ch[FORCE + row % D][row / D].to_f64();
        }
    }
    (k, m, nodes)
}

fn force_differential<T: BatchReal, const D: usize>()
where
    Dim<D>: LaneDim<D>,
    Mat<T, D>: Matrix<Scalar = T, Vector = [T; D]> + HessianDim,
    Mat<f64, D>: Matrix<Scalar = f64, Vector = [f64; D]> + HaarRotation,
    DefaultSvd: SvdMethod<Mat<T, D>>,
{
    let (cells, hf) = (12, 0.05);
    let h = T::from_f64(hf);
    let eps = T::EPSILON.to_f64();
    for (name, base) in materials::<T>() {
        for isa in Isa::available() {
            let mut rng = Pcg64::seed_from_u64(13);
            let ps = particles::<T, D>(&mut rng, 6, hf, cells, &base);
            for p in &ps {
                // Exact: equals the reference Stiffness on every unit δu.
                let exact = Material {
                    hessian: Definiteness::Exact,
                    ..base
                };
                let (k, m, _) = stiffness_matrix(isa, &exact, Kernel::Quadratic, h, p);
                let e = elastic_energy(&exact, p).unwrap();
                let st = Stiffness::new(&e, &exact, p).unwrap();
                let s = Stencil::new(Kernel::Quadratic, Grid::Collocated, h, &p.x).unwrap();
                let kmax = k.iter().fold(0.0f64, |a, x| a.max(x.abs()));
                for col in 0..m {
                    let mut g = Mat::<T, D>::ZERO;
                    let gr = s.node(col / D).grad;
                    for b in 0..D {
                        g.cols[b][col % D] = gr[b];
                    }
                    let mm = st.d_force_matrix(&g).unwrap();
                    for row in 0..m {
                        let want = mm.mul_vec(s.node(row / D).grad)[row % D].to_f64();
                        let got = k[row * m + col];
                        assert!(
                            (got - want).abs() <= 1024.0 * eps * kmax,
                            "{name} {isa:?}: K[{row}][{col}] {got} vs {want} (max {kmax})"
                        );
                    }
                }
                // Symmetric (up to rounding).
                for r in 0..m {
                    for c in 0..r {
                        let (a, b) = (k[r * m + c], k[c * m + r]);
                        assert!((a - b).abs() <= 1024.0 * eps * kmax, "{name}: symmetry");
                    }
                }
                // PSD option: ⟨δu, K δu⟩ ≤ 0 (K negative semi-definite) for random δu.
                let psd = Material {
                    hessian: Definiteness::Projected,
                    ..base
                };
                let (kp, _, _) = stiffness_matrix(isa, &psd, Kernel::Quadratic, h, p);
                let mut r2 = Pcg64::seed_from_u64(4);
                let kpmax = kp.iter().fold(0.0f64, |a, x| a.max(x.abs()));
                for _ in 0..200 {
                    let u: Vec<f64> = (0..m).map(|_| r2.random_range(-1.0..1.0)).collect();
                    let mut q = 0.0;
                    let mut uu = 0.0;
                    for r in 0..m {
                        uu += u[r] * u[r];
                        for c in 0..m {
                            q += u[r] * kp[r * m + c] * u[c];
                        }
                    }
                    assert!(
                        q <= 2048.0 * eps * kpmax * uu,
                        "{name} {isa:?}: PSD option gives uᵀKu = {q} > 0"
                    );
                }
            }
        }
    }
}

#[test]
fn force_differential_2d_f64() {
    force_differential::<f64, 2>();
}
#[test]
fn force_differential_3d_f64() {
    force_differential::<f64, 3>();
}
#[test]
fn force_differential_3d_f32() {
    force_differential::<f32, 3>();
}

/// A stretched block with explicit dilation, J ≈ 1.3: the exact differential is indefinite
/// (`β = −λJ(J − 1) < 0` on the skew pair modes), the projected one is not.
#[test]
fn psd_option_covers_the_dilational_part() {
    type T = f64;
    const D: usize = 3;
    let mat = Material {
        hessian: Definiteness::Projected,
        ..Material::<T>::elastic(10.0, 1.0e4)
    };
    let mut p = Particle::<T, D>::at_rest([0.3; D], 1.0, 1.0e-3);
    p.f_e = Mat::from_diagonal([1.1, 1.09, 1.08]);
    let exact = Material {
        hessian: Definiteness::Exact,
        ..mat
    };
    let h = 0.05;
    let isa = Isa::SCALAR;
    let (k, m, _) = stiffness_matrix(isa, &exact, Kernel::Quadratic, h, &p);
    let (kp, _, _) = stiffness_matrix(isa, &mat, Kernel::Quadratic, h, &p);
    // Find a direction with uᵀKu > 0 for the exact K (a skew mode: rotate the stencil).
    let max_q = |kk: &[f64]| {
        let mut best = f64::MIN;
        let mut rng = Pcg64::seed_from_u64(8);
        for _ in 0..2000 {
            let u: Vec<f64> = (0..m).map(|_| rng.random_range(-1.0..1.0)).collect();
            let mut q = 0.0;
            let mut uu = 0.0;
            for r in 0..m {
                uu += u[r] * u[r];
                for c in 0..m {
                    q += u[r] * kk[r * m + c] * u[c];
                }
            }
            best = best.max(q / uu);
        }
        best
    };
    let kmax = k.iter().fold(0.0f64, |a, x| a.max(x.abs()));
    assert!(
        max_q(&k) > 1e-6 * kmax,
        "the exact differential is indefinite here"
    );
    assert!(max_q(&kp) <= 1e-12 * kmax, "the projected one is not");
}

/// Zero-filled slots and the slots of failed prepares are refused (NotPrepared); nothing is
/// written for them.
#[test]
fn unprepared_slots_are_refused() {
    type T = f32;
    const D: usize = 3;
    let mat = Material::<T>::elastic(10.0, 100.0);
    let mut ps = vec![Particle::<T, D>::at_rest([0.3; D], 1.0, 1.0e-3); 3];
    ps[1].f_e.cols[0][0] = -1.0;
    let mut store = Store::from(&ps);
    let mut slots = vec![0.0 as T; 3 * slot_len(D)];
    let raw = store.raw();
    for isa in Isa::available() {
        // SAFETY: three particles, three slots.
        let st = unsafe { force::prepare::<T, D>(isa, &mat, 3, &raw, slots.as_mut_ptr()) };
        assert_eq!((st.first_failed, st.error), (1, Some(Error::NonPositiveJ)));
        let mut du = DenseGrid::<T, D>::new([0; D], [12; D]);
        du.ch[MOM].iter_mut().for_each(|x| *x = 1.0e-3);
        let mut df = DenseGrid::<T, D>::new([0; D], [12; D]);
        let view = ForceView {
            nodes: du.nodes(),
            du: std::array::from_fn(|a| du.inp(MOM + a)),
            df: std::array::from_fn(|a| df.out(FORCE + a)),
        };
        let zero = vec![0.0 as T; slot_len(D)];
        // SAFETY: one slot.
        let st = unsafe {
            force::apply::<T, D>(
                isa,
                Kernel::Quadratic,
                0.05,
                1,
                store.x.as_ptr(),
                zero.as_ptr(),
                &view,
            )
        };
        assert_eq!(st.error, Some(Error::NotPrepared));
        // SAFETY: three slots.
        let st = unsafe {
            force::apply::<T, D>(
                isa,
                Kernel::Quadratic,
                0.05,
                3,
                store.x.as_ptr(),
                slots.as_ptr(),
                &view,
            )
        };
        assert_eq!((st.first_failed, st.error), (1, Some(Error::NotPrepared)));
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
    for isa in Isa::available() {
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

/// As [`p2g_run_that_overflows_is_added_one_by_one`], for the force differential's apply.
#[test]
fn apply_run_that_overflows_is_added_one_by_one() {
    type T = f64;
    const D: usize = 3;
    let h = 0.05;
    let mat = Material::<T>::elastic(10.0, 100.0);
    let ps = runs_of_particles::<T, D>(h);
    let mut store = Store::from(&ps);
    let mut slots = vec![0.0 as T; 6 * slot_len(D)];
    for isa in Isa::available() {
        // SAFETY: six particles, six slots.
        let st = unsafe { force::prepare::<T, D>(isa, &mat, 6, &store.raw(), slots.as_mut_ptr()) };
        assert_eq!(st.error, None);
        let mut du = DenseGrid::<T, D>::new([0; D], [16; D]);
        for (k, x) in du.ch[MOM].iter_mut().enumerate() {
            *x = 1.0e-3 * (k % 7) as T;
        }
        let mut df = DenseGrid::<T, D>::new([0; D], [16; D]);
        let poisoned = df.index([6; D]);
        df.ch[FORCE + 1][poisoned] = T::NAN;
        let mut only2 = df.clone();
        let apply = |df: &mut DenseGrid<T, D>, first: usize, n: usize| {
            let view = ForceView {
                nodes: du.nodes(),
                du: std::array::from_fn(|a| du.inp(MOM + a)),
                df: std::array::from_fn(|a| df.out(FORCE + a)),
            };
            // SAFETY: particles first..first + n, their slots; the channels cover the box.
            unsafe {
                force::apply::<T, D>(
                    isa,
                    Kernel::Quadratic,
                    h,
                    n,
                    store.x.as_ptr().add(first * D),
                    slots.as_ptr().add(first * slot_len(D)),
                    &view,
                )
            }
        };
        let st = apply(&mut df, 0, 6);
        assert_eq!(
            (st.first_failed, st.error),
            (0, Some(Error::Overflow)),
            "{isa:?}"
        );
        assert_eq!(apply(&mut only2, 2, 1).error, None);
        assert_eq!(
            df.bits(),
            only2.bits(),
            "{isa:?}: only particle 2 was written"
        );
    }
}
