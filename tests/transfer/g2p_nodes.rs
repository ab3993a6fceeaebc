//! G2P's node sums: a linear velocity field is reproduced (collocated and MAC), only the
//! nodes of a stencil are read, and non-finite or overflowing node values fail exactly the
//! particles that read them.
use crate::g2p::g2p_grid;
use crate::isas;
use crate::{materials, particles, rand_mat, DenseGrid, Store, HC, MOM};
use ampm_core::kernel::batch::BatchReal;
use ampm_core::lane::Isa;
use ampm_core::particle::transfer::g2p::{self, G2pArgs, G2pView};
use ampm_core::particle::{Grid, Kernel, Particle, Stencil};
use ampm_core::polar::{DefaultSvd, SvdMethod};
use ampm_core::{Error, Mat, Matrix, Real};
use ampm_tools::workload::HaarRotation;
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;

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
    for isa in isas() {
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

/// The node sums' statuses on every instruction set, for whole chunks of particles: a node
/// value of ±∞ or NaN (a velocity component, or with heat the new or the old temperature)
/// fails exactly the particles whose stencil reads it, with `NonFinite` (however small their
/// weight there), and leaves them as they were, while the others get the bits of a clean grid;
/// finite node values whose sums overflow (`T::MAX` at every node: the gradient sums
/// `Σ v ∂w/∂x` pass ±∞ in their partial sums) give `Overflow`, not `NonFinite`, and change no
/// particle.
fn g2p_node_statuses<T: BatchReal, const D: usize>()
where
    Mat<T, D>: Matrix<Scalar = T, Vector = [T; D]>,
    Mat<f64, D>: Matrix<Scalar = f64, Vector = [f64; D]> + HaarRotation,
    DefaultSvd: SvdMethod<Mat<T, D>>,
{
    let (cells, hf) = (12, 0.05);
    let h = T::from_f64(hf);
    let mats = materials::<T>();
    let thermal = mats.iter().find(|(n, _)| *n == "thermal").unwrap();
    // (material, the channel that holds the bad value).
    let cases = [
        (&mats[0], MOM + 1),
        (thermal, MOM + 1),
        (thermal, HC),
        (thermal, HC + 1),
    ];
    let args = G2pArgs {
        kernel: Kernel::Quadratic,
        h,
        dt: T::from_f64(1e-3),
    };
    let stencil = |p: &Particle<T, D>| {
        Stencil::new(Kernel::Quadratic, Grid::Collocated, h, &p.x).expect("inside")
    };
    let clean = g2p_grid::<T, D>(cells, 3);
    for ((name, mat), channel) in cases {
        let mut rng = Pcg64::seed_from_u64(5);
        let ps = particles::<T, D>(&mut rng, 40, hf, cells, mat);
        // Node 4 of particle 21's stencil (the chunk of particles 16..24), and who reads it.
        let node = stencil(&ps[21]).node(4).index;
        let readers: Vec<usize> = (0..ps.len())
            .filter(|&i| stencil(&ps[i]).nodes().any(|nd| nd.index == node))
            .collect();
        assert!(readers.contains(&21));
        assert!(
            readers.len() < ps.len(),
            "some particles do not read the node"
        );
        for isa in isas() {
            let label = format!("{name} {}D {} {isa:?} channel {channel}", D, T::NAME);
            let mut ok = Store::from(&ps);
            let raw = ok.raw();
            // SAFETY: `raw` holds `ps.len()` particles; the grid covers every stencil.
            let st = unsafe {
                g2p::g2p_update(isa, mat, &args, ps.len(), &raw, &clean.g2p_view(), None)
            };
            assert_eq!(st.error, None, "{label}");
            for bad in [f64::INFINITY, f64::NEG_INFINITY, f64::NAN] {
                let mut g = clean.clone();
                let k = g.index(node);
                g.ch[channel][k] = T::from_f64(bad);
                let mut s = Store::from(&ps);
                let raw = s.raw();
                // SAFETY: as above.
                let st = unsafe {
                    g2p::g2p_update(isa, mat, &args, ps.len(), &raw, &g.g2p_view(), None)
                };
                assert_eq!(
                    (st.first_failed, st.error),
                    (readers[0], Some(Error::NonFinite)),
                    "{label} {bad}"
                );
                for i in 0..ps.len() {
                    let want = if readers.contains(&i) {
                        ps[i]
                    } else {
                        ok.get::<D>(i)
                    };
                    assert_eq!(s.get::<D>(i), want, "{label} {bad}: particle {i}");
                }
            }
            let mut g = clean.clone();
            g.ch[MOM].iter_mut().for_each(|v| *v = T::MAX);
            let mut s = Store::from(&ps);
            let raw = s.raw();
            // SAFETY: as above.
            let st =
                unsafe { g2p::g2p_update(isa, mat, &args, ps.len(), &raw, &g.g2p_view(), None) };
            assert_eq!(
                (st.first_failed, st.error),
                (0, Some(Error::Overflow)),
                "{label}"
            );
            assert_eq!(s, Store::from(&ps), "{label}: no particle changes");
        }
    }
}

#[test]
fn g2p_node_statuses_2d_f32() {
    g2p_node_statuses::<f32, 2>();
}
#[test]
fn g2p_node_statuses_3d_f32() {
    g2p_node_statuses::<f32, 3>();
}
#[test]
fn g2p_node_statuses_2d_f64() {
    g2p_node_statuses::<f64, 2>();
}
#[test]
fn g2p_node_statuses_3d_f64() {
    g2p_node_statuses::<f64, 3>();
}
