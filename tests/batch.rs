//! The vectorized batch path (`ampm_core::batch`, `ampm_*_batch_*`) and the McAdams SVD.
//!
//! 1. Lane primitives equal their scalar counterparts bit for bit (the basis of 2.).
//! 2. The C ABI batch functions equal, bit for bit and status for status, the single-particle
//!    kernels with the default method, and the core lane path (`batch::ahat_batch`, the one
//!    behind the 2D C functions) equals the scalar kernels with its method
//!    (`BatchKernel::method()`: closed form in 2D, McAdams in 3D), for every dim × precision, for
//!    n = 0..2N+3 (every remainder), with invalid particles of every kind sprinkled in;
//!    failed outputs are untouched, `first_failed` and the status are the first failure's;
//!    in place (`out == f`) gives the same; NULL arrays only for n = 0.
//! 3. Accuracy acceptance (issue 2) against an independent method: the scalar kernels in f64
//!    with nalgebra's SVD: 1e-11 relative (f64 batch) and 1e-4 (f32 batch), σ in [0.2, 5].
//! 4. McAdams: U, V ∈ SO(3), sorted σ, sign convention, reconstruction, sweeps 2..8.
use ampm::AmpmStatus;
use ampm_core::augmented::{self, Augmented};
use ampm_core::batch::lane::{Lane, L};
use ampm_core::batch::{self, BatchKernel};
use ampm_core::energy::FixedCorotated;
use ampm_core::polar::{DefaultSvd, McAdams, Svd, SvdMethod};
use ampm_core::{Error, Mat, Matrix, Real};
use ampm_tools::workload::HaarRotation;
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;

/// `F = R₁ diag(σ) R₂ᵀ`, σ log-uniform in `[lo, hi]` (det F > 0).
fn family<const D: usize>(rng: &mut Pcg64, lo: f64, hi: f64) -> Mat<f64, D>
where
    Mat<f64, D>: Matrix<Scalar = f64, Vector = [f64; D]>,
    Mat<f64, D>: HaarRotation,
{
    let s: [f64; D] = std::array::from_fn(|_| rng.random_range(lo.ln()..hi.ln()).exp());
    <Mat<f64, D>>::haar(rng) * Mat::from_diagonal(s) * <Mat<f64, D>>::haar(rng).transpose()
}

fn random_z<const D: usize>(rng: &mut Pcg64) -> Mat<f64, D>
where
    Mat<f64, D>: Matrix<Scalar = f64>,
    Mat<f64, D>: HaarRotation,
{
    Mat::from_cols(std::array::from_fn(|_| {
        std::array::from_fn(|_| rng.random_range(-1.0..1.0))
    }))
}

fn bits<T: Real, const D: usize>(m: &Mat<T, D>) -> Vec<u64> {
    m.cols
        .iter()
        .flatten()
        .map(|x| x.to_f64().to_bits())
        .collect()
}

// ---------------------------------------------------------------------------------------
// 1. Lane primitives.

macro_rules! lane_primitive_test {
    ($name:ident, $t:ident, $n:literal) => {
        #[test]
        fn $name() {
            let t = |x: f64| x as $t;
            let specials: Vec<$t> = vec![
                0.0,
                -0.0,
                1.0,
                -1.0,
                0.75,
                3.0,
                $t::MIN_POSITIVE,
                $t::MIN_POSITIVE / 2.0,
                $t::MIN_POSITIVE / 1024.0,
                <$t>::from_bits(1),
                $t::MAX,
                -$t::MAX,
                $t::EPSILON,
                $t::INFINITY,
                $t::NEG_INFINITY,
                $t::NAN,
                t(1e-30),
                t(7.5e20),
            ];
            for chunk in specials.chunks($n) {
                let mut x = L::<$t, $n>::splat(1.0);
                for (i, v) in chunk.iter().enumerate() {
                    x.set(i, *v);
                }
                let (e, a, fin) = (x.exponent(), x.abs(), x.is_finite());
                let (sq, cs) = (x.abs().sqrt(), x.copysign(L::splat(-1.0)));
                for i in 0..$n {
                    let v = x.get(i);
                    assert_eq!(e.get(i), <$t as Lane>::exponent(v), "exponent({v:e})");
                    assert_eq!(a.get(i).to_bits(), Real::abs(v).to_bits(), "abs({v:e})");
                    assert_eq!(<L<$t, $n> as Lane>::mask_get(fin, i), Real::is_finite(v));
                    assert_eq!(sq.get(i).to_bits(), Real::sqrt(Real::abs(v)).to_bits());
                    assert_eq!(cs.get(i).to_bits(), Real::copysign(v, -1.0).to_bits());
                }
            }
            // 2ᵉ over the whole range and beyond (inf above, subnormals and 0 below), and the
            // truncated halving of the two-step scaling.
            let emax = Real::exponent(<$t as Real>::MAX) + 2;
            let emin = -(<$t as Real>::MANTISSA_DIGITS as i32) - emax - 4;
            for e0 in (emin..emax).step_by($n) {
                let e = L::<$t, $n>(std::array::from_fn(|i| (e0 + i as i32) as $t));
                let (p, h) = (L::pow2(e), L::half_trunc(e));
                for i in 0..$n {
                    let ei = e0 + i as i32;
                    assert_eq!(
                        p.get(i).to_bits(),
                        Real::scalbn(1.0 as $t, ei).to_bits(),
                        "2^{ei}"
                    );
                    assert_eq!(h.get(i), (ei / 2) as $t);
                }
            }
        }
    };
}

lane_primitive_test!(lanes_f32, f32, 8);
lane_primitive_test!(lanes_f64, f64, 4);

// ---------------------------------------------------------------------------------------
// 2. Batch = scalar kernels with the same method, bit for bit, every status.

/// The kinds of particle sprinkled into the batches (index `i` gets kind `KIND[i % len]`).
#[derive(Clone, Copy, Debug, PartialEq)]
enum Kind {
    Good,
    NanF,
    InfF,
    NegJ,
    ZeroF,
    NanMu,
    NegMu,
    ZeroMu,
    NanZ,
    Overflow,
    NanFNegMu,
}

const KINDS: [Kind; 17] = [
    Kind::Good,
    Kind::NanF,
    Kind::Good,
    Kind::InfF,
    Kind::Good,
    Kind::NegJ,
    Kind::ZeroF,
    Kind::Good,
    Kind::NanMu,
    Kind::NegMu,
    Kind::Good,
    Kind::ZeroMu,
    Kind::NanZ,
    Kind::Good,
    Kind::Overflow,
    Kind::NanFNegMu,
    Kind::Good,
];

/// Particles `(μ, F, Z)` in precision `T`; `kinds` chooses each particle's kind.
fn make<T: Real, const D: usize>(
    rng: &mut Pcg64,
    kinds: &[Kind],
) -> (Vec<T>, Vec<Mat<T, D>>, Vec<Mat<T, D>>)
where
    Mat<f64, D>: Matrix<Scalar = f64, Vector = [f64; D]>,
    Mat<f64, D>: HaarRotation,
    Mat<T, D>: Matrix<Scalar = T>,
{
    let (mut mu, mut f, mut z) = (vec![], vec![], vec![]);
    for &k in kinds {
        let mut fi = family::<D>(rng, 0.2, 5.0).cast::<T>();
        let mut zi = random_z::<D>(rng).cast::<T>();
        let mut m = T::from_f64(rng.random_range(0.1..10.0));
        let nan = T::from_f64(f64::NAN);
        match k {
            Kind::Good => {}
            Kind::NanF => fi.cols[D - 1][0] = nan,
            Kind::InfF => fi.cols[0][D - 1] = T::from_f64(f64::INFINITY),
            Kind::NegJ => fi.cols[0] = fi.cols[0].map(|x| -x),
            Kind::ZeroF => fi = Mat::ZERO,
            Kind::NanMu => m = nan,
            Kind::NegMu => m = -m,
            Kind::ZeroMu => m = T::ZERO,
            Kind::NanZ => zi.cols[0][0] = nan,
            Kind::Overflow => {
                // Â ∝ ‖F‖⁻¹ and Ĉ ∝ ‖F‖⁻²: a subnormal F (not a multiple of a rotation, so
                // Â ≠ 0) makes both overflow; J > 0 is still decided on the scaled G.
                let mut d = [T::ONE; D];
                d[0] = T::TWO;
                fi = Mat::from_diagonal(d) * T::MIN_POSITIVE.scalbn(-20);
            }
            Kind::NanFNegMu => {
                fi.cols[0][0] = nan;
                m = -m;
            }
        }
        mu.push(m);
        f.push(fi);
        z.push(zi);
    }
    (mu, f, z)
}

type AhatFn<T> = unsafe extern "C" fn(usize, *const T, *const T, *mut T, *mut usize) -> AmpmStatus;
type ChatFn<T> =
    unsafe extern "C" fn(usize, *const T, *const T, *const T, *mut T, *mut usize) -> AmpmStatus;

/// Checks one batch call's outputs against the per-particle expectations.
fn check_outputs<T: Real, const D: usize>(
    what: &str,
    expected: &[Result<Mat<T, D>, Error>],
    out: &[Mat<T, D>],
    sentinel: &[Mat<T, D>],
    status: AmpmStatus,
    first_failed: usize,
) {
    let n = expected.len();
    let first = expected.iter().position(|r| r.is_err());
    assert_eq!(
        first_failed,
        first.unwrap_or(n),
        "{what}: first_failed (n = {n})"
    );
    let want_status = match first {
        None => AmpmStatus::AMPM_OK,
        Some(i) => expected[i]
            .err()
            .map_or(AmpmStatus::AMPM_OK, AmpmStatus::from),
    };
    assert_eq!(status, want_status, "{what}: status (n = {n})");
    for i in 0..n {
        match &expected[i] {
            Ok(m) => assert_eq!(bits(&out[i]), bits(m), "{what}: particle {i} of {n}"),
            Err(_) => assert_eq!(
                bits(&out[i]),
                bits(&sentinel[i]),
                "{what}: failed {i} written"
            ),
        }
    }
}

/// `abi`: the SVD method the C ABI batch functions use for this dimension (the default
/// method, so that batch and single calls agree); the core lane path is checked against
/// `BatchKernel::method()`.
fn batch_equals_scalar<T: Real, const D: usize, A: SvdMethod<Mat<T, D>>>(
    ahat_fn: AhatFn<T>,
    chat_fn: ChatFn<T>,
    abi: A,
) where
    Mat<f64, D>: Matrix<Scalar = f64, Vector = [f64; D]>,
    Mat<f64, D>: HaarRotation,
    Mat<T, D>: BatchKernel<Scalar = T>,
{
    let lanes = <Mat<T, D> as BatchKernel>::LANES;
    let method = <Mat<T, D> as BatchKernel>::method();
    let mut rng = Pcg64::seed_from_u64(11);
    for n in 0..=2 * lanes + 3 {
        for offset in [0, 5, 11] {
            let kinds: Vec<Kind> = (0..n).map(|i| KINDS[(i + offset) % KINDS.len()]).collect();
            let (mu, f, z) = make::<T, D>(&mut rng, &kinds);
            let exp_a: Vec<_> = (0..n)
                .map(|i| augmented::ahat(&FixedCorotated::with_method(mu[i], method), &f[i]))
                .collect();
            let exp_c: Vec<_> = (0..n)
                .map(|i| {
                    Augmented::new(&FixedCorotated::with_method(mu[i], method), &f[i])
                        .and_then(|s| s.chat_z(&z[i]))
                })
                .collect();
            let abi_a: Vec<_> = (0..n)
                .map(|i| augmented::ahat(&FixedCorotated::with_method(mu[i], abi), &f[i]))
                .collect();
            let abi_c: Vec<_> = (0..n)
                .map(|i| {
                    Augmented::new(&FixedCorotated::with_method(mu[i], abi), &f[i])
                        .and_then(|s| s.chat_z(&z[i]))
                })
                .collect();
            // The generic kernel on one scalar lane agrees too.
            for i in 0..n {
                let one = <Mat<T, D> as BatchKernel>::ahat_scalar(mu[i], &f[i]);
                assert_eq!(
                    one.map(|m| bits(&m)),
                    exp_a[i].map(|m| bits(&m)),
                    "ahat_one {i}"
                );
                let one = <Mat<T, D> as BatchKernel>::chat_z_scalar(mu[i], &f[i], &z[i]);
                assert_eq!(
                    one.map(|m| bits(&m)),
                    exp_c[i].map(|m| bits(&m)),
                    "chat_one {i}"
                );
            }
            let sentinel: Vec<Mat<T, D>> = (0..n)
                .map(|i| Mat::identity() * T::from_i32(i as i32 + 7))
                .collect();
            let fp = f.as_ptr().cast::<T>();
            let zp = z.as_ptr().cast::<T>();
            // Separate output.
            let mut out = sentinel.clone();
            let mut ff = usize::MAX;
            let st = unsafe { ahat_fn(n, mu.as_ptr(), fp, out.as_mut_ptr().cast(), &mut ff) };
            check_outputs("ahat", &abi_a, &out, &sentinel, st, ff);
            let mut out = sentinel.clone();
            let mut ff = usize::MAX;
            let st = unsafe { chat_fn(n, mu.as_ptr(), fp, zp, out.as_mut_ptr().cast(), &mut ff) };
            check_outputs("chat_z", &abi_c, &out, &sentinel, st, ff);
            // In place: out == f (ahat), out == z (chat); failed particles keep their input.
            let mut inplace = f.clone();
            let p = inplace.as_mut_ptr().cast::<T>();
            let st = unsafe { ahat_fn(n, mu.as_ptr(), p, p, std::ptr::null_mut()) };
            check_outputs("ahat in place", &abi_a, &inplace, &f, st, {
                abi_a.iter().position(|r| r.is_err()).unwrap_or(n)
            });
            let mut inplace = z.clone();
            let p = inplace.as_mut_ptr().cast::<T>();
            let st = unsafe { chat_fn(n, mu.as_ptr(), fp, p, p, std::ptr::null_mut()) };
            check_outputs("chat_z in place (z)", &abi_c, &inplace, &z, st, {
                abi_c.iter().position(|r| r.is_err()).unwrap_or(n)
            });
            let mut inplace = f.clone();
            let p = inplace.as_mut_ptr().cast::<T>();
            let st = unsafe { chat_fn(n, mu.as_ptr(), p, zp, p, std::ptr::null_mut()) };
            check_outputs("chat_z in place (f)", &abi_c, &inplace, &f, st, {
                abi_c.iter().position(|r| r.is_err()).unwrap_or(n)
            });
            // The safe slice API of core.
            let mut out = sentinel.clone();
            let r = batch::ahat_batch(&mu, &f, &mut out);
            let first = exp_a
                .iter()
                .enumerate()
                .find_map(|(i, r)| r.err().map(|e| (i, e)));
            assert_eq!(r.err(), first, "core ahat_batch");
            for i in 0..n {
                if let Ok(m) = &exp_a[i] {
                    assert_eq!(bits(&out[i]), bits(m));
                }
            }
        }
    }
    // NULL arrays: allowed for n = 0 only.
    let null = std::ptr::null::<T>();
    let nullm = std::ptr::null_mut::<T>();
    let mut ff = usize::MAX;
    assert_eq!(
        unsafe { ahat_fn(0, null, null, nullm, &mut ff) },
        AmpmStatus::AMPM_OK
    );
    assert_eq!(ff, 0);
    assert_eq!(
        unsafe { chat_fn(0, null, null, null, nullm, &mut ff) },
        AmpmStatus::AMPM_OK
    );
    let (mu, f, _) = make::<T, D>(&mut rng, &[Kind::Good]);
    let mut out = f.clone();
    let o = out.as_mut_ptr().cast::<T>();
    let fp = f.as_ptr().cast::<T>();
    for (m, ff_, ol) in [
        (null, fp, o),
        (mu.as_ptr(), null, o),
        (mu.as_ptr(), fp, nullm),
    ] {
        let st = unsafe { ahat_fn(1, m, ff_, ol, std::ptr::null_mut()) };
        assert_eq!(st, AmpmStatus::AMPM_ERR_NULL_POINTER);
    }
    let st = unsafe { chat_fn(1, mu.as_ptr(), fp, null, o, std::ptr::null_mut()) };
    assert_eq!(st, AmpmStatus::AMPM_ERR_NULL_POINTER);
    assert_eq!(
        bits(&out[0]),
        bits(&f[0]),
        "nothing written on a NULL error"
    );
}

#[test]
fn batch_2d_f32() {
    batch_equals_scalar::<f32, 2, _>(
        ampm::ampm_ahat_batch_2d_f32,
        ampm::ampm_chat_z_batch_2d_f32,
        DefaultSvd,
    );
}
#[test]
fn batch_2d_f64() {
    batch_equals_scalar::<f64, 2, _>(
        ampm::ampm_ahat_batch_2d_f64,
        ampm::ampm_chat_z_batch_2d_f64,
        DefaultSvd,
    );
}
#[test]
fn batch_3d_f32() {
    batch_equals_scalar::<f32, 3, _>(
        ampm::ampm_ahat_batch_3d_f32,
        ampm::ampm_chat_z_batch_3d_f32,
        DefaultSvd,
    );
}
#[test]
fn batch_3d_f64() {
    batch_equals_scalar::<f64, 3, _>(
        ampm::ampm_ahat_batch_3d_f64,
        ampm::ampm_chat_z_batch_3d_f64,
        DefaultSvd,
    );
}

// ---------------------------------------------------------------------------------------
// 3. Accuracy acceptance of the batch functions against an independent method.

/// An independent SVD for the reference: nalgebra's (Golub–Kahan bidiagonalisation + implicit
/// QR) in f64, brought to the rotation-variant convention (a reflection in `U` or `V` is moved
/// into the sign of the last σ).
#[derive(Clone, Copy, Debug, Default)]
struct NalgebraSvd;

macro_rules! nalgebra_svd {
    ($d:literal) => {
        impl SvdMethod<Mat<f64, $d>> for NalgebraSvd {
            const NAME: &'static str = "nalgebra";
            fn svd(&self, f: &Mat<f64, $d>) -> ampm_core::Result<Svd<Mat<f64, $d>>> {
                let m = nalgebra::SMatrix::<f64, $d, $d>::from_fn(|i, j| f[(i, j)]);
                let svd = m.svd(true, true);
                let (u, vt) = (svd.u.unwrap(), svd.v_t.unwrap());
                let mut order: Vec<usize> = (0..$d).collect();
                order.sort_by(|&a, &b| svd.singular_values[b].total_cmp(&svd.singular_values[a]));
                let mut out = Svd {
                    u: Mat::<f64, $d>::identity(),
                    sigma: [0.0; $d],
                    v: Mat::<f64, $d>::identity(),
                };
                for (c, &k) in order.iter().enumerate() {
                    out.sigma[c] = svd.singular_values[k];
                    for i in 0..$d {
                        out.u[(i, c)] = u[(i, k)];
                        out.v[(i, c)] = vt[(k, i)];
                    }
                }
                for q in [&mut out.u, &mut out.v] {
                    if q.det() < 0.0 {
                        for i in 0..$d {
                            q[(i, $d - 1)] = -q[(i, $d - 1)];
                        }
                        out.sigma[$d - 1] = -out.sigma[$d - 1];
                    }
                }
                Ok(out)
            }
        }
    };
}
nalgebra_svd!(2);
nalgebra_svd!(3);

/// Largest relative error over 2000 particles of the family, against the f64 scalar kernels
/// with nalgebra's SVD (an algorithm independent of the batch's closed form and McAdams) on
/// the same input.
///
/// Relative to `max(‖ref‖, s)` with `s` the size of the terms the result is a difference of:
/// `Â = 2μ(F̂ − R):𝓑` cancels as `F̂ → R` (σ₀ ≈ σ₁ ≈ …), where `‖Â‖ → 0` while its rounding
/// error stays `~ε·2μJᵃ‖F̂‖`; so `s = 2μJᵃ max(‖F̂‖, 1)` for `Â` and `s = 2μJ²ᵃ‖Z‖` for `Ĉ:Z`
/// (each of its terms is `μ J²ᵃ O(‖Z‖)` for `‖F̂‖ = O(1)`). Norms are max norms.
fn batch_accuracy<T: Real, const D: usize>(ahat_fn: AhatFn<T>, chat_fn: ChatFn<T>) -> (f64, f64)
where
    Mat<f64, D>: Matrix<Scalar = f64, Vector = [f64; D]>,
    Mat<f64, D>: HaarRotation,
    Mat<T, D>: BatchKernel<Scalar = T>,
    NalgebraSvd: SvdMethod<Mat<f64, D>>,
{
    let n = 2000;
    let mut rng = Pcg64::seed_from_u64(5);
    let (mu, f, z) = make::<T, D>(&mut rng, &vec![Kind::Good; n]);
    let (mut oa, mut oc) = (f.clone(), f.clone());
    let mut ff = 0;
    unsafe {
        let st = ahat_fn(
            n,
            mu.as_ptr(),
            f.as_ptr().cast(),
            oa.as_mut_ptr().cast(),
            &mut ff,
        );
        assert_eq!(st, AmpmStatus::AMPM_OK);
        let st = chat_fn(
            n,
            mu.as_ptr(),
            f.as_ptr().cast(),
            z.as_ptr().cast(),
            oc.as_mut_ptr().cast(),
            &mut ff,
        );
        assert_eq!(st, AmpmStatus::AMPM_OK);
    }
    let (mut ea, mut ec) = (0.0f64, 0.0f64);
    for i in 0..n {
        let e = FixedCorotated::with_method(mu[i].to_f64(), NalgebraSvd);
        let st = Augmented::new(&e, &f[i].cast::<f64>()).unwrap();
        let ra = st.ahat().unwrap();
        let zi = z[i].cast::<f64>();
        let rc = st.chat_z(&zi).unwrap();
        let fi = f[i].cast::<f64>();
        let ja = fi.det().powf(-1.0 / D as f64);
        let two_mu = 2.0 * mu[i].to_f64();
        let sa = ra.max_abs().max(two_mu * ja * (fi * ja).max_abs().max(1.0));
        let sc = rc.max_abs().max(two_mu * ja * ja * zi.max_abs());
        ea = ea.max((oa[i].cast::<f64>() - ra).max_abs() / sa);
        ec = ec.max((oc[i].cast::<f64>() - rc).max_abs() / sc);
    }
    (ea, ec)
}

macro_rules! accuracy_test {
    ($name:ident, $t:ident, $d:literal, $a:ident, $c:ident, $tol:expr) => {
        #[test]
        fn $name() {
            let (ea, ec) = batch_accuracy::<$t, $d>(ampm::$a, ampm::$c);
            eprintln!("{}: Â {ea:.2e}, Ĉ:Z {ec:.2e}", stringify!($name));
            assert!(
                ea <= $tol && ec <= $tol,
                "Â {ea:e}, Ĉ:Z {ec:e} > {:e}",
                $tol
            );
        }
    };
}

// The issue-2 acceptance bounds, stated there (not derived here): 1e-11 (f64), 1e-4 (f32).
accuracy_test!(
    accuracy_2d_f64,
    f64,
    2,
    ampm_ahat_batch_2d_f64,
    ampm_chat_z_batch_2d_f64,
    1e-11
);
accuracy_test!(
    accuracy_3d_f64,
    f64,
    3,
    ampm_ahat_batch_3d_f64,
    ampm_chat_z_batch_3d_f64,
    1e-11
);
accuracy_test!(
    accuracy_2d_f32,
    f32,
    2,
    ampm_ahat_batch_2d_f32,
    ampm_chat_z_batch_2d_f32,
    1e-4
);
accuracy_test!(
    accuracy_3d_f32,
    f32,
    3,
    ampm_ahat_batch_3d_f32,
    ampm_chat_z_batch_3d_f32,
    1e-4
);

// ---------------------------------------------------------------------------------------
// 4. McAdams.

/// Sweep-limited part of the reconstruction error, `‖UΣVᵀ − F‖_max / ‖F‖_max`, for the
/// family σ ∈ [0.2, 5] (κ ≤ 25), *stated* (not derived): the approximate rotations reduce a
/// pivot by at least the factor 0.6 of the π/8 fallback (McAdams et al. §2.2) but the cyclic
/// order re-couples the pairs, so no useful a-priori bound exists; these are 4× the largest
/// errors measured over 20000 matrices of the family (f64; 2 → 0.27, 3 → 0.077, 4 → 6e-3,
/// 5 → 3e-4, 6 → 1.7e-7, ≥ 7 → at rounding level), independent of the precision.
fn sweep_limit(sweeps: u32) -> f64 {
    match sweeps {
        0..=2 => 1.1,
        3 => 0.31,
        4 => 2.4e-2,
        5 => 1.2e-3,
        6 => 7e-7,
        _ => 0.0,
    }
}

fn mcadams_properties<T: Real>() {
    let eps = T::EPSILON.to_f64();
    let mut rng = Pcg64::seed_from_u64(99);
    let fs: Vec<Mat<f64, 3>> = (0..3000)
        .map(|i| {
            let f = family::<3>(&mut rng, 0.2, 5.0);
            // Every third has det < 0 (sign convention), scaled over a wide range.
            let s = 2f64.powi(rng.random_range(-40..40));
            let f = if i % 3 == 0 { -f } else { f };
            f * s
        })
        .collect();
    for sweeps in 2..=8 {
        let m = McAdams::new(sweeps).unwrap();
        for f64m in &fs {
            let f = f64m.cast::<T>();
            let svd = m.svd(&f).unwrap();
            let (u, v, s) = (svd.u.cast::<f64>(), svd.v.cast::<f64>(), svd.sigma);
            // Orthogonality and det = +1: U and V are built from normalised quaternions and
            // Givens rotations of unit (c, s); each entry carries O(10) roundings: 16ε.
            let id = Mat::<f64, 3>::identity();
            for (name, q) in [("U", u), ("V", v)] {
                let e = (q.transpose() * q - id).max_abs();
                assert!(
                    e <= 16.0 * eps,
                    "{name}ᵀ{name} − I = {e:e}, sweeps {sweeps}"
                );
                assert!(
                    (q.det() - 1.0).abs() <= 16.0 * eps,
                    "det {name}, sweeps {sweeps}"
                );
            }
            // Sign convention: σ₀, σ₁ ≥ 0; σ₂ has the sign of det F.
            let s64 = s.map(|x| x.to_f64());
            assert!(s64[0] >= 0.0 && s64[1] >= 0.0, "{s64:?}");
            assert_eq!(s64[2] < 0.0, f.cast::<f64>().det() < 0.0, "{s64:?}");
            // Sorted by magnitude, up to the rounding of the QR diagonal (8ε relative) and,
            // before convergence, the sweep-limited error.
            let tol = 8.0 * eps + sweep_limit(sweeps);
            assert!(s64[1] <= s64[0] * (1.0 + tol), "{s64:?}");
            assert!(s64[2].abs() <= s64[1] * (1.0 + tol), "{s64:?}");
            // Reconstruction: ε‖F‖ times a rounding factor (S = GᵀG, 3 sweeps of rotations
            // with O(10) roundings each contribute relative errors in V of a few ε; forming
            // B = GV, three Givens and UΣVᵀ add O(30) roundings: 64ε), plus the sweep limit.
            let fm = f.cast::<f64>();
            let rec = (svd.reconstruct().cast::<f64>() - fm).max_abs() / fm.max_abs();
            let bound = 64.0 * eps + sweep_limit(sweeps);
            assert!(
                rec <= bound,
                "reconstruction {rec:e} > {bound:e}, sweeps {sweeps}"
            );
        }
    }
}

#[test]
fn mcadams_f32() {
    mcadams_properties::<f32>();
}

#[test]
fn mcadams_f64() {
    mcadams_properties::<f64>();
}

#[test]
fn mcadams_sweep_count_is_validated() {
    assert_eq!(McAdams::new(0), Err(Error::InvalidArgument));
    assert_eq!(McAdams::new(17), Err(Error::InvalidArgument));
    assert!(McAdams::new(1).is_ok() && McAdams::new(16).is_ok());
    // A field set out of range is clamped, never looped 0 or 2³² times.
    let f = Mat::<f64, 3>::from_rows([[1.0, 0.2, 0.0], [0.1, 1.0, 0.3], [0.0, 0.0, 0.9]]);
    let a = McAdams { sweeps: 0 }.svd(&f).unwrap();
    let b = McAdams { sweeps: 1 }.svd(&f).unwrap();
    assert_eq!(a, b);
    let a = McAdams { sweeps: u32::MAX }.svd(&f).unwrap();
    let b = McAdams { sweeps: 16 }.svd(&f).unwrap();
    assert_eq!(a, b);
    assert_eq!(
        McAdams::default().svd(&(f * f64::NAN)),
        Err(Error::NonFinite)
    );
}
