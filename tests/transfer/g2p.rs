//! G2P: reference match, batch chunks (with and without heat) against single particles.
use crate::isas;
use crate::{deformation, materials, particles, DenseGrid, Store, HC, LATENT, MOM, TM};
use ampm_core::kernel::batch::BatchReal;
use ampm_core::lane::Isa;
use ampm_core::particle::transfer::g2p::{self, G2pArgs};
use ampm_core::particle::transfer::Particles;
use ampm_core::particle::{
    g2p_update, Grid, GridSample, Heat, Kernel, Material, Particle, Phase, Stencil,
};
use ampm_core::polar::{DefaultSvd, SvdMethod};
use ampm_core::{Error, Mat, Matrix, Real};
use ampm_tools::workload::HaarRotation;
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;

/// A grid over `[-1, cells + 1)` per axis with random node velocities in `[-1, 1)` m/s and
/// new and old node temperatures within 5 K of `TM` (what G2P reads), from `seed`.
pub(super) fn g2p_grid<T: Real, const D: usize>(cells: i32, seed: u64) -> DenseGrid<T, D> {
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
    for isa in isas() {
        for (name, mat) in materials::<T>() {
            for kernel in [Kernel::Quadratic, Kernel::Cubic] {
                let mut rng = Pcg64::seed_from_u64(5);
                let ps = particles::<T, D>(&mut rng, 60, hf, cells, &mat);
                let g = g2p_grid::<T, D>(cells, 9);
                let mut store = Store::from(&ps);
                let args = G2pArgs { kernel, h, dt };
                let raw = store.raw();
                // SAFETY: the arrays hold the particles; the grid covers their stencils.
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
/// and material, for solid and for liquid batches: the batch updates chunks of solids (elastic,
/// and snow with its SVD) and of liquids on SIMD lanes, a call of one particle updates it alone
/// (the scalar update, with the snow step on the lanes of the same row type).
/// The batch mixes chunks that stay on lanes (one with a particle of the other phase among
/// them) with chunks that must fall back: a particle with a NaN `F_P`, one whose `F_E` is
/// inverted, one needing the remedy for `det(I + Δt∇v) ≤ 0` (a strongly compressive node
/// velocity), and one whose `F_E` has a subnormal column. A liquid's `F_E` is `s I` (the state
/// every liquid step leaves, whose new `F_E` comes from `det(I + Δt∇v)` on the lanes), with
/// `s` over a wide range, and its `F_P` isotropic or general, in chunks that stay on lanes;
/// liquid batches also have chunks with a liquid of general `F_E` (a solid that has just
/// melted, which the lanes leave to the scalar step), one with columns of very different
/// scales (the projection's root on equilibrated columns).
fn g2p_chunks_match_single<T: BatchReal, const D: usize>()
where
    Mat<T, D>: Matrix<Scalar = T, Vector = [T; D]>,
    Mat<f64, D>: Matrix<Scalar = f64, Vector = [f64; D]> + HaarRotation,
    DefaultSvd: SvdMethod<Mat<T, D>>,
{
    let (cells, hf) = (12, 0.05);
    let h = T::from_f64(hf);
    let dt = T::from_f64(1e-3);
    for isa in isas() {
        for ((name, mat), liquid) in materials::<T>()
            .into_iter()
            .flat_map(|m| [(m.clone(), false), (m, true)])
        {
            let mut rng = Pcg64::seed_from_u64(11);
            let mut ps = particles::<T, D>(&mut rng, 75, hf, cells, &mat);
            let (this, other) = if liquid {
                (Phase::Liquid, Phase::Solid)
            } else {
                (Phase::Solid, Phase::Liquid)
            };
            for (i, p) in ps.iter_mut().enumerate() {
                p.phase = this;
                if liquid && !matches!(i, 44 | 60 | 70) {
                    // J_E^{1/d} from 2^{∓bias/4} to 2^{±bias/4}, mostly near 1.
                    let e = if i % 5 == 0 { T::MAX_EXP / 4 } else { 0 };
                    let s =
                        T::from_f64(rng.random_range(0.9..1.1)).scalbn(e * (i % 2 * 2) as i32 - e);
                    p.f_e = Mat::identity() * s;
                }
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
            let label = format!("{name} {liquid} {isa:?}");
            let first = batch_matches_single(isa, &mat, &args, &ps, &g, &label);
            assert!(first.is_some(), "{label}: the NaN particle fails");
        }
    }
}

/// Runs G2P over `ps` on `isa` as one batch and particle by particle (calls of one particle:
/// the scalar update), asserts the same first failure, status and bits of every particle
/// array, and returns the first failure.
fn batch_matches_single<T: BatchReal, const D: usize>(
    isa: Isa,
    mat: &Material<T>,
    args: &G2pArgs<T>,
    ps: &[Particle<T, D>],
    g: &DenseGrid<T, D>,
    label: &str,
) -> Option<(usize, Error)>
where
    Mat<T, D>: Matrix<Scalar = T, Vector = [T; D]>,
    DefaultSvd: SvdMethod<Mat<T, D>>,
{
    let mut batch = Store::from(ps);
    let raw = batch.raw();
    // SAFETY: the arrays hold the particles; the grid covers their stencils.
    let st = unsafe { g2p::g2p_update(isa, mat, args, ps.len(), &raw, &g.g2p_view(), None) };
    let mut one = Store::from(ps);
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
            g2p::g2p_update(isa, mat, args, 1, &at, &g.g2p_view(), None)
        };
        if let (None, Some(e)) = (first, st1.error) {
            first = Some((i, e));
        }
    }
    assert_eq!(
        first.map(|f| f.0).unwrap_or(ps.len()),
        st.first_failed,
        "{label}"
    );
    assert_eq!(first.map(|f| f.1), st.error, "{label}");
    assert_eq!(batch.bits(), one.bits(), "{label}");
    first
}

/// With heat, G2P's batch equals calls of one particle, bit for bit and status for status: the
/// batch updates a chunk on SIMD lanes after each particle's heat step (on the lanes when every
/// lane stays in its segment, else the scalar step per lane), solids and liquids alike.
/// Chunks of 8 on a grid that warms every particle by about 3 K and on one that cools it by
/// about 3 K: solids below the melting point; liquids; solids at it with a buffer within half
/// of empty (emptying when cooled: some freeze on); solids at it with a nearly full buffer
/// (melting when warmed); solids of which half melt (solids and liquids in one chunk); a NaN
/// temperature; an invalid thermal state (a liquid below the melting point); liquids with
/// general `F_P`, some within 3 K of the melting point (reaching it when cooled); a partial
/// chunk. With and without phase change.
fn g2p_heat_chunks_match_single<T: BatchReal, const D: usize>()
where
    Mat<T, D>: Matrix<Scalar = T, Vector = [T; D]>,
    Mat<f64, D>: Matrix<Scalar = f64, Vector = [f64; D]> + HaarRotation,
    DefaultSvd: SvdMethod<Mat<T, D>>,
{
    let (cells, hf) = (12, 0.05);
    let args = G2pArgs {
        kernel: Kernel::Quadratic,
        h: T::from_f64(hf),
        dt: T::from_f64(1e-3),
    };
    let (_, thermal) = materials::<T>()
        .into_iter()
        .find(|(n, _)| *n == "thermal")
        .unwrap();
    let heat = thermal.heat.unwrap();
    let no_change = Material {
        heat: Some(Heat {
            phase_change: false,
            ..heat
        }),
        ..thermal.clone()
    };
    let grid = |warm: f64| {
        let mut g = g2p_grid::<T, D>(cells, 5);
        let mut rg = Pcg64::seed_from_u64(6);
        for k in 0..g.ch[HC].len() {
            g.ch[HC][k] = T::from_f64(TM + warm * (3.0 + rg.random_range(0.0..1.0)));
            g.ch[HC + 1][k] = T::from_f64(TM + rg.random_range(-0.5..0.5));
        }
        g
    };
    let grids = [("warming", grid(1.0)), ("cooling", grid(-1.0))];
    let mats = [("phase change", &thermal), ("no phase change", &no_change)];
    for isa in isas() {
        for ((name, mat), (gname, g)) in mats.iter().flat_map(|m| grids.iter().map(move |g| (m, g)))
        {
            let mut rng = Pcg64::seed_from_u64(12);
            let mut ps = particles::<T, D>(&mut rng, 83, hf, cells, mat);
            let c = T::from_f64;
            for (i, p) in ps.iter_mut().enumerate() {
                let (chunk, lane) = (i / 8, i % 8);
                let liquid = matches!(chunk, 1 | 6 | 9);
                let state = match chunk {
                    _ if liquid => (TM + rng.random_range(0.5..20.0), LATENT),
                    2 => (TM, rng.random_range(0.0..0.5 * LATENT)),
                    3 => (TM, LATENT - rng.random_range(0.0..100.0)),
                    4 if lane % 2 == 0 => (TM, LATENT - rng.random_range(0.0..100.0)),
                    4 => (TM, rng.random_range(0.0..0.5 * LATENT)),
                    _ => (TM - rng.random_range(10.0..20.0), 0.0),
                };
                p.temperature = c(state.0);
                p.latent = c(state.1);
                p.phase = if liquid { Phase::Liquid } else { Phase::Solid };
                p.f_p = if liquid && chunk == 9 {
                    deformation::<D>(&mut rng, 0.8, 1.25).cast()
                } else if liquid {
                    Mat::identity() * c(rng.random_range(0.9..1.1))
                } else {
                    Mat::identity()
                };
            }
            ps[5 * 8 + 3].temperature = c(f64::NAN);
            ps[6 * 8 + 5].temperature = c(TM - 1.0);
            let label = format!("{name} {gname} {isa:?}");
            let first = batch_matches_single(isa, mat, &args, &ps, g, &label);
            assert_eq!(first, Some((43, Error::NonFinite)), "{label}");
        }
    }
}

#[test]
fn g2p_heat_chunks_match_single_2d_f32() {
    g2p_heat_chunks_match_single::<f32, 2>();
}
#[test]
fn g2p_heat_chunks_match_single_3d_f32() {
    g2p_heat_chunks_match_single::<f32, 3>();
}
#[test]
fn g2p_heat_chunks_match_single_3d_f64() {
    g2p_heat_chunks_match_single::<f64, 3>();
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
