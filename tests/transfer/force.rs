//! The force differential: reference stiffness (one particle and batches), PSD option, unprepared
//! slots, overflowing runs.
use crate::isas;
use crate::{materials, particles, runs_of_particles, DenseGrid, Store, FORCE, MOM};
use ampm_core::kernel::batch::BatchReal;
use ampm_core::kernel::{Dim, LaneDim};
use ampm_core::lane::Isa;
use ampm_core::particle::implicit::slot_len;
use ampm_core::particle::transfer::force::{self, ForceView};
use ampm_core::particle::update::{elastic_energy, Stiffness};
use ampm_core::particle::{Definiteness, Dilation, Grid, Kernel, Material, Particle, Stencil};
use ampm_core::polar::{DefaultSvd, SvdMethod};
use ampm_core::{hessian::HessianDim, Error, Mat, Matrix, Real};
use ampm_tools::workload::HaarRotation;
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;

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
        for isa in isas() {
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
    for isa in isas() {
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

/// As [`crate::p2g::p2g_run_that_overflows_is_added_one_by_one`], for the force
/// differential's apply.
#[test]
fn apply_run_that_overflows_is_added_one_by_one() {
    type T = f64;
    const D: usize = 3;
    let h = 0.05;
    let mat = Material::<T>::elastic(10.0, 100.0);
    let ps = runs_of_particles::<T, D>(h);
    let mut store = Store::from(&ps);
    let mut slots = vec![0.0 as T; 6 * slot_len(D)];
    for isa in isas() {
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

/// `prepare` and `apply` over many particles (full chunks of lanes and a partial one, on every
/// instruction set: 70 particles are one full chunk of prepare's 64 `f32` lanes on AVX-512 and
/// a partial one, and eight full chunks of apply's eight and a partial one: each full chunk's
/// `M` on lanes but the one with the refused slot, whose particles go one by one) against the
/// reference [`Stiffness`] of each particle: `δf_i = Σ_p M_p ∇w_ip` with
/// `M_p = d_force_matrix(Σ_j δu_j ∇w_jpᵀ)`, summed in f64. Tolerance per node component:
/// the single-particle test's `1024 ε` times the sum over particles of each one's largest
/// node contribution.
fn apply_batch_matches_reference<T: BatchReal, const D: usize>()
where
    Dim<D>: LaneDim<D>,
    Mat<T, D>: Matrix<Scalar = T, Vector = [T; D]> + HessianDim,
    Mat<f64, D>: Matrix<Scalar = f64, Vector = [f64; D]> + HaarRotation,
    DefaultSvd: SvdMethod<Mat<T, D>>,
{
    let (cells, hf, n) = (12, 0.05, 70);
    // A particle whose slot is zeroed after the prepare: refused, the rest of its chunk of
    // eight (particles 8..16) still applied.
    const REFUSED: usize = 11;
    let h = T::from_f64(hf);
    let eps = T::EPSILON.to_f64();
    for (name, base) in materials::<T>() {
        let mat = Material {
            hessian: Definiteness::Exact,
            ..base
        };
        let mut rng = Pcg64::seed_from_u64(29);
        let ps = particles::<T, D>(&mut rng, n, hf, cells, &mat);
        let mut du = DenseGrid::<T, D>::new([0; D], [cells; D]);
        for a in 0..D {
            for x in du.ch[MOM + a].iter_mut() {
                *x = T::from_f64(rng.random_range(-1.0e-3..1.0e-3));
            }
        }
        // The reference, and per node component the tolerance's scale.
        let len = du.ch[MOM].len();
        let mut want = vec![[0.0f64; D]; len];
        let mut scale = 0.0f64;
        for (i, p) in ps.iter().enumerate() {
            if i == REFUSED {
                continue;
            }
            let e = elastic_energy(&mat, p).unwrap();
            let st = Stiffness::new(&e, &mat, p).unwrap();
            let s = Stencil::new(Kernel::Quadratic, Grid::Collocated, h, &p.x).unwrap();
            let mut g = Mat::<T, D>::ZERO;
            for j in 0..s.len() {
                let nd = s.node(j);
                let k = du.index(nd.index);
                for a in 0..D {
                    for b in 0..D {
                        g.cols[b][a] += du.ch[MOM + a][k] * nd.grad[b];
                    }
                }
            }
            let m = st.d_force_matrix(&g).unwrap();
            let mut largest = 0.0f64;
            for i in 0..s.len() {
                let nd = s.node(i);
                let f = m.mul_vec(nd.grad);
                for a in 0..D {
                    want[du.index(nd.index)][a] += f[a].to_f64();
                    largest = largest.max(f[a].to_f64().abs());
                }
            }
            scale += largest;
        }
        let mut store = Store::from(&ps);
        // The first vector instruction set's `δf` bits: every other one gives the same (the
        // same operations in the same order per lane, whatever the register width).
        let mut vector_bits: Option<(Isa, Vec<u64>)> = None;
        for isa in isas() {
            let mut slots = vec![T::ZERO; n * slot_len(D)];
            // SAFETY: n particles, n slots.
            let st =
                unsafe { force::prepare::<T, D>(isa, &mat, n, &store.raw(), slots.as_mut_ptr()) };
            assert_eq!(st.error, None, "{name} {isa:?}");
            slots[REFUSED * slot_len(D)..(REFUSED + 1) * slot_len(D)].fill(T::ZERO);
            let mut df = DenseGrid::<T, D>::new([0; D], [cells; D]);
            let view = ForceView {
                nodes: du.nodes(),
                du: std::array::from_fn(|a| du.inp(MOM + a)),
                df: std::array::from_fn(|a| df.out(FORCE + a)),
            };
            // SAFETY: n particles and slots; the channels cover every stencil.
            let st = unsafe {
                force::apply::<T, D>(
                    isa,
                    Kernel::Quadratic,
                    h,
                    n,
                    store.x.as_ptr(),
                    slots.as_ptr(),
                    &view,
                )
            };
            assert_eq!(
                (st.first_failed, st.error),
                (REFUSED, Some(Error::NotPrepared)),
                "{name} {isa:?}"
            );
            for (k, w) in want.iter().enumerate() {
                for a in 0..D {
                    let got = df.ch[FORCE + a][k].to_f64();
                    assert!(
                        (got - w[a]).abs() <= 1024.0 * eps * scale,
                        "{name} {isa:?}: node {k} axis {a}: {got} vs {} (scale {scale})",
                        w[a]
                    );
                }
            }
            if isa != Isa::SCALAR {
                let bits: Vec<u64> = (0..D)
                    .flat_map(|a| df.ch[FORCE + a].iter().map(|x| x.to_f64().to_bits()))
                    .collect();
                match &vector_bits {
                    None => vector_bits = Some((isa, bits)),
                    Some((first, b)) => assert!(*b == bits, "{name}: {isa:?} against {first:?}"),
                }
            }
        }
    }
}

#[test]
fn apply_batch_matches_reference_3d_f32() {
    apply_batch_matches_reference::<f32, 3>();
}

#[test]
fn apply_batch_matches_reference_3d_f64() {
    apply_batch_matches_reference::<f64, 3>();
}

#[test]
fn apply_batch_matches_reference_2d_f64() {
    apply_batch_matches_reference::<f64, 2>();
}

/// Particle `i` of `s` as arrays of one particle (every field as stored, the phase code too).
fn one_particle<T: Real, const D: usize>(s: &Store<T>, i: usize) -> Store<T> {
    let rec = |a: &[T], k: usize| a[k * i..k * (i + 1)].to_vec();
    Store {
        x: rec(&s.x, D),
        v: rec(&s.v, D),
        affine: rec(&s.affine, D * D),
        f_e: rec(&s.f_e, D * D),
        f_p: rec(&s.f_p, D * D),
        mass: rec(&s.mass, 1),
        volume0: rec(&s.volume0, 1),
        temperature: rec(&s.temperature, 1),
        latent: rec(&s.latent, 1),
        phase: vec![s.phase[i]],
    }
}

/// `prepare` of a batch gives every particle the slot (bit for bit) or the error of the same
/// particle prepared on its own, and the batch reports the first error. Among 70 particles: a NaN
/// entry of `F_E` (3), `det F_P < 0` (20), `V⁰ = 0` (37), an invalid phase code (42), an `F_E`
/// whose dilational factor `α` overflows (50; with the explicit dilation), each in a group of eight
/// otherwise valid particles, then groups of valid ones and a partial group (`f32` prepares the
/// valid groups of eight on lanes, the others one by one; a single particle always takes the scalar
/// pass).
fn prepare_matches_one_by_one<T: BatchReal, const D: usize>()
where
    Dim<D>: LaneDim<D>,
    Mat<T, D>: Matrix<Scalar = T, Vector = [T; D]>,
    Mat<f64, D>: Matrix<Scalar = f64, Vector = [f64; D]> + HaarRotation,
{
    let (cells, hf, n, sl) = (12, 0.05, 70, slot_len(D));
    // `J = s^d` is finite, `α = λ J (2J − 1)` is not.
    let s = T::from_f64(if size_of::<T>() == 4 { 1.0e12 } else { 1.0e100 });
    for (name, base) in materials::<T>() {
        for hessian in [Definiteness::Exact, Definiteness::Projected] {
            let mat = Material { hessian, ..base };
            let mut rng = Pcg64::seed_from_u64(31);
            let ps = particles::<T, D>(&mut rng, n, hf, cells, &mat);
            let mut store = Store::from(&ps);
            store.f_e[D * D * 3 + 1] = T::from_f64(f64::NAN);
            for r in 0..D {
                store.f_p[D * D * 20 + r] = -store.f_p[D * D * 20 + r];
            }
            store.volume0[37] = T::ZERO;
            store.phase[42] = 7;
            for j in 0..D {
                for r in 0..D {
                    store.f_e[D * D * 50 + D * j + r] = if j == r { s } else { T::ZERO };
                }
            }
            for isa in isas() {
                let mut slots = vec![T::ZERO; n * sl];
                // SAFETY: n particles, n slots.
                let st = unsafe {
                    force::prepare::<T, D>(isa, &mat, n, &store.raw(), slots.as_mut_ptr())
                };
                let mut first = (n, None);
                for i in 0..n {
                    let mut one = one_particle::<T, D>(&store, i);
                    let mut slot = vec![T::ZERO; sl];
                    // SAFETY: one particle, one slot.
                    let e = unsafe {
                        force::prepare::<T, D>(isa, &mat, 1, &one.raw(), slot.as_mut_ptr())
                    }
                    .error;
                    let bad = [3, 20, 37, 42].contains(&i)
                        || (i == 50 && mat.dilation == Dilation::Explicit);
                    assert_eq!(e.is_some(), bad, "{name} {hessian:?} {isa:?}: particle {i}");
                    if e.is_some() && first.1.is_none() {
                        first = (i, e);
                    }
                    let got: Vec<u64> = slots[i * sl..(i + 1) * sl]
                        .iter()
                        .map(|x| x.to_f64().to_bits())
                        .collect();
                    let want: Vec<u64> = slot.iter().map(|x| x.to_f64().to_bits()).collect();
                    // A failed slot holds tag 0 only; the rest is as the caller left it.
                    let k = if bad { 1 } else { sl };
                    assert_eq!(
                        got[..k],
                        want[..k],
                        "{name} {hessian:?} {isa:?}: particle {i}"
                    );
                }
                assert_eq!(
                    (st.first_failed, st.error),
                    first,
                    "{name} {hessian:?} {isa:?}"
                );
            }
        }
    }
}

#[test]
fn prepare_matches_one_by_one_3d_f32() {
    prepare_matches_one_by_one::<f32, 3>();
}

#[test]
fn prepare_matches_one_by_one_2d_f32() {
    prepare_matches_one_by_one::<f32, 2>();
}

#[test]
fn prepare_matches_one_by_one_3d_f64() {
    prepare_matches_one_by_one::<f64, 3>();
}
