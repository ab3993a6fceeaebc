//! Stability contracts of every polar/SVD method × dim × precision on every family of `F`
//! (`tools/src/families/`), against the double-double reference (`tools/src/reference.rs`);
//! the reference itself; scale invariance; bounded iteration; and the run-time method choice
//! of the C ABI (`ffi/src/methods.rs`).
//!
//! The contracts and error units are those of `ampm_tools::stability` (derivations there).
//! The measurement runs in the reduced size (a seeded subset of the 5⁹ integer matrices, a few
//! draws per parameter), one `#[test]` per dim × precision so the harness runs them in
//! parallel.

use ampm::methods::{
    ampm_ahat_batch_ex_3d_f64, ampm_ahat_ex_2d_f64, ampm_ahat_ex_3d_f32, ampm_ahat_ex_3d_f64,
    ampm_chat_z_batch_ex_3d_f64, ampm_chat_z_ex_3d_f64, ampm_energy_hat_ex_3d_f64,
    ampm_polar_2d_f32, ampm_polar_2d_f64, ampm_polar_3d_f64, ampm_svd_2d_f32, ampm_svd_3d_f32,
    ampm_svd_3d_f64, AmpmOptions, AMPM_METHOD_CLOSED_FORM_2D, AMPM_METHOD_DEFAULT,
    AMPM_METHOD_HIGHAM_NOFERINI, AMPM_METHOD_MCADAMS, AMPM_METHOD_ONE_SIDED_JACOBI, AMPM_METHOD_QR,
};
use ampm::AmpmStatus;
use ampm_core::augmented;
use ampm_core::energy::FixedCorotated;
use ampm_core::polar::{
    ClosedForm2, HighamNoferini, McAdams, OneSidedJacobi, QrSvd, Svd, SvdMethod,
};
use ampm_core::{Error, Mat, Matrix, Real};
use ampm_tools::families::{generate, Family, Size};
use ampm_tools::reference::{self, Dd};
use ampm_tools::stability::{self, Report, BOUND_RECON};
use std::ptr;

fn assert_no_violations(rep: &Report) {
    let v = rep.violations();
    assert!(
        v.is_empty(),
        "{} contract violations:\n{}",
        v.len(),
        v.join("\n")
    );
    // Every method × family actually measured something.
    for c in &rep.cells {
        assert!(c.n_cases > 0, "{:?} {:?} is empty", c.method, c.family);
    }
}

/// Runs the reduced families for one dim × precision and checks every contract.
macro_rules! contract_test {
    ($name:ident, $t:ty, $d:literal) => {
        #[test]
        fn $name() {
            let rep = stability::run_one::<$t, $d>(Size::Reduced, &Family::ALL);
            assert_no_violations(&rep);
            // The chart data: one curve per method on the kink (R) and J → 0 (Â) families,
            // one Haar p99 per method.
            let n_methods = rep
                .cells
                .iter()
                .filter(|c| c.family == Family::Kink)
                .count();
            for (fam, q) in [
                (Family::Kink, stability::Quantity::R),
                (Family::JToZero, stability::Quantity::Ahat),
            ] {
                let curves = stability::curves(&rep, fam, q, $d);
                assert_eq!(curves.len(), n_methods, "{fam:?}");
                for (label, pts) in &curves {
                    assert!(pts.len() >= 5, "{label}: {pts:?}");
                    assert!(pts.windows(2).all(|w| w[0].0 < w[1].0), "{label}: unsorted");
                }
            }
            assert_eq!(stability::haar_p99(&rep).len(), n_methods);
            // The accurate methods are actually accurate on the Haar family (a bound that a
            // wrong reference or a wrong unit would break): p99 of R and Σ below BOUND_RECON.
            for c in rep
                .cells
                .iter()
                .filter(|c| c.family == Family::HaarLogUniform)
            {
                if stability::bound(&c.method, stability::Quantity::R).is_finite() {
                    for q in [stability::Quantity::R, stability::Quantity::Sigma] {
                        let p = c.p99(q, false).expect("measured");
                        assert!(p < BOUND_RECON, "{:?} {q:?} p99 {p}", c.method);
                    }
                }
            }
        }
    };
}

contract_test!(contracts_3d_f64, f64, 3);
contract_test!(contracts_3d_f32, f32, 3);
contract_test!(contracts_2d_f64, f64, 2);
contract_test!(contracts_2d_f32, f32, 2);

/// The reference SVD reconstructs `F` and is orthonormal to double-double accuracy:
/// [`stability::BOUND_REFERENCE`] `= BOUND_RECON·ε_dd ≈ 1.3e-29` (the same backward-error
/// bound as the f64 methods, in units of the double-double ε = 2⁻¹⁰⁴), relative to
/// `max(‖F‖, 2⁻⁹⁶⁹)` (below that the trailing word of a double-double is subnormal), in 2D and
/// 3D, on the matrices of every finite family rounded to f64 and to f32. (The stability
/// measurement checks the same at every case it uses.)
#[test]
fn reference_is_double_double_accurate() {
    fn check<T: Real, const D: usize>(failures: &mut Vec<String>) -> usize
    where
        reference::Dim<D>: reference::ReferenceDim<M = Mat<Dd, D>>,
        Mat<f64, D>: ampm_tools::families::FamilyDim,
        Mat<Dd, D>: Matrix<Scalar = Dd, Vector = [Dd; D]>,
    {
        let mut checked = 0;
        for fam in Family::ALL.into_iter().filter(|f| *f != Family::NonFinite) {
            for case in generate::<T, D>(fam, Size::Reduced).iter().take(200) {
                let svd = reference::svd::<D>(&case.f).expect("finite");
                if let Some(e) = stability::reference_error(&case.f, &svd) {
                    failures.push(format!(
                        "{D}D {} {fam:?} F = {:?}: {e}",
                        T::NAME,
                        case.f.cols
                    ));
                }
                checked += 1;
            }
        }
        checked
    }
    let mut failures = Vec::new();
    let checked = check::<f64, 3>(&mut failures)
        + check::<f32, 3>(&mut failures)
        + check::<f64, 2>(&mut failures)
        + check::<f32, 2>(&mut failures);
    assert!(
        failures.is_empty(),
        "{} of {checked} reference SVDs not accurate, e.g.:\n{}",
        failures.len(),
        failures[..failures.len().min(8)].join("\n")
    );
    assert!(checked > 4000, "{checked}");
}

/// Power-of-two scaling is exact, so every method must commute with it bit for bit: no
/// absolute threshold anywhere (the published QR tolerance max(‖B‖/2, 1)·τ would fail).
#[test]
fn methods_are_scale_invariant() {
    fn check<S: SvdMethod<Mat<f64, 3>> + SvdMethod<Mat<f32, 3>>>(m: S) {
        for case in generate::<f32, 3>(Family::HaarLogUniform, Size::Reduced) {
            for e in [-120, -60, 60, 100] {
                let f = case.f.cast::<f32>();
                let g = f.map(|x| x.scalbn(e));
                // Exact scaling is the premise: skip the (rare) entries that go subnormal.
                if g.map(|x| x.scalbn(-e)) != f {
                    continue;
                }
                let (a, b): (Svd<Mat<f32, 3>>, Svd<Mat<f32, 3>>) =
                    (m.svd(&f).unwrap(), m.svd(&g).unwrap());
                assert_eq!(a.u, b.u, "{m:?}");
                assert_eq!(a.v, b.v, "{m:?}");
                for i in 0..3 {
                    assert_eq!(a.sigma[i].scalbn(e), b.sigma[i], "{m:?}");
                }
                let f = case.f;
                let g = f.map(|x| x.scalbn(8 * e));
                if g.map(|x| x.scalbn(-8 * e)) != f {
                    continue;
                }
                let (a, b): (Svd<Mat<f64, 3>>, Svd<Mat<f64, 3>>) =
                    (m.svd(&f).unwrap(), m.svd(&g).unwrap());
                assert_eq!(a.u, b.u, "{m:?}");
                for i in 0..3 {
                    assert_eq!(a.sigma[i].scalbn(8 * e), b.sigma[i], "{m:?}");
                }
            }
        }
    }
    check(OneSidedJacobi::default());
    check(QrSvd::default());
    check(HighamNoferini::default());
    check(McAdams::default());
}

/// A singular value 1e-20 times the largest (f64) survives in QR: the tolerance is relative
/// to ‖F‖ (ε‖F‖ ≈ 2e-16), not max(‖F‖/2, 1)·τ, so σ₂ = 1e-20·s keeps ~4 digits for every
/// scale s (it is below ε‖F‖, so only absolute accuracy ε‖F‖ is promised; here F is diagonal
/// up to a permutation-free rotation of the first two axes, so σ₂ is not mixed at all).
#[test]
fn qr_keeps_small_singular_values_at_any_scale() {
    for s in [1e-200, 1e-30, 1.0, 1e30] {
        let c = 0.6;
        let sn = 0.8;
        // F = rot₀₁ · diag(1, 0.5, 1e-20) · s.
        let f = Mat::<f64, 3>::from_rows([
            [c * s, -sn * 0.5 * s, 0.0],
            [sn * s, c * 0.5 * s, 0.0],
            [0.0, 0.0, 1e-20 * s],
        ]);
        let svd = QrSvd::default().svd(&f).unwrap();
        let rel = (svd.sigma[2] / (1e-20 * s) - 1.0).abs();
        assert!(rel < 1e-12, "s = {s:e}: σ₂ = {:e}", svd.sigma[2]);
    }
}

/// Every method stops: NaN/inf input is refused before any iteration, and a too-small
/// iteration cap is reported as `NotConverged`, never a hang or a wrong answer.
#[test]
fn iteration_is_bounded() {
    let f = Mat::<f64, 3>::from_rows([[1.0, 0.3, -0.2], [0.1, 0.8, 0.4], [-0.3, 0.5, 1.5]]);
    for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
        let mut g = f;
        g.cols[1][2] = bad;
        assert_eq!(QrSvd::default().svd(&g), Err(Error::NonFinite));
        assert_eq!(HighamNoferini::default().svd(&g), Err(Error::NonFinite));
        assert_eq!(OneSidedJacobi::default().svd(&g), Err(Error::NonFinite));
        assert_eq!(McAdams::default().svd(&g), Err(Error::NonFinite));
    }
    // A full matrix needs at least one QR sweep; with a cap of 0 it must say so.
    assert_eq!(
        QrSvd { max_iterations: 0 }.svd(&f),
        Err(Error::NotConverged)
    );
    assert!(QrSvd { max_iterations: 32 }.svd(&f).is_ok());
    // Jacobi on the 4×4 needs more than one sweep for a generic F.
    assert_eq!(
        HighamNoferini { max_sweeps: 1 }.svd(&f),
        Err(Error::NotConverged)
    );
}

/// Higham–Noferini keeps `det R = +1` for `det F < 0` (no negation step) and gives the same
/// `R` as the other accurate methods there.
#[test]
fn higham_noferini_is_rotation_variant_for_negative_det() {
    // det F = 1.5(−0.48 + 0.03) − 0.2(−0.06 − 0.06) + 0.1(−0.01 − 0.16) = −0.668.
    let f = Mat::<f64, 3>::from_rows([[1.5, 0.2, 0.1], [0.1, 0.8, 0.3], [0.2, -0.1, -0.6]]);
    assert!(f.det() < 0.0);
    let a = HighamNoferini::default().svd(&f).unwrap();
    let b = OneSidedJacobi::default().svd(&f).unwrap();
    let (ra, rb) = (a.rotation(), b.rotation());
    assert!((ra.det() - 1.0).abs() < 1e-14);
    // κ_R = 2σ₀/(σ₁+σ₂) is modest here; both within 64ε·κ of each other.
    let kappa = 2.0 * b.sigma[0] / (b.sigma[1] + b.sigma[2]);
    assert!((ra - rb).max_abs() < 64.0 * f64::EPSILON * kappa);
    assert!(a.sigma[2] < 0.0 && b.sigma[2] < 0.0);
}

/// `F = c·I` plus one off-diagonal `±δ` whose square is subnormal or zero (`δ = 1e-22`,
/// `1e-30` in f32; `1e-161`, `1e-162`, `1e-300` in f64), at either off-diagonal position: the
/// 2D closed form normalises vectors like `(F₀₀ − F₁₁, F₀₁ + F₁₀) ≈ (0, δ/2)` (after scaling
/// `F` to `[0.5, 1)`), and a norm taken as `√(x² + y²)` is off by up to tens of percent where
/// `δ²/4` keeps only a few subnormal bits (f32 `1e-22`, f64 `1e-161`; at `1e-162` it
/// underflows to zero). `U`, `V` must be rotations and `R = UVᵀ = I` (the exact `R` is a
/// rotation by `~δ/(2c)`, far below ε) to `4ε` per entry, through the Rust method and through
/// the C ABI's default 2D polar decomposition.
#[test]
fn closed_form_2d_square_underflow() {
    type Polar<T> =
        unsafe extern "C" fn(*const AmpmOptions, *const T, *mut T, *mut T) -> AmpmStatus;
    fn check<T: Real>(deltas: &[f64], polar: Polar<T>) -> Vec<String> {
        let eps = T::EPSILON.to_f64();
        let id = Mat::<f64, 2>::identity();
        let mut failures = Vec::new();
        for c in [1.0, 0.7, 1.5] {
            for delta in deltas.iter().flat_map(|&d| [d, -d]) {
                for (i, j) in [(0, 1), (1, 0)] {
                    let mut f = Mat::<f64, 2>::identity() * c;
                    f.cols[j][i] = delta;
                    let f = f.cast::<T>();
                    let at = format!("{} c = {c}, F[{i}][{j}] = {delta:e}", T::NAME);
                    let svd = ClosedForm2.svd(&f).expect("finite F");
                    let (u, v) = (svd.u.cast::<f64>(), svd.v.cast::<f64>());
                    let ou = (u.transpose() * u - id).max_abs();
                    let ov = (v.transpose() * v - id).max_abs();
                    let er = (svd.rotation().cast::<f64>() - id).max_abs();
                    if ou > 4.0 * eps || ov > 4.0 * eps || er > 4.0 * eps {
                        failures.push(format!(
                            "{at}: |UᵀU − I| = {ou:e}, |VᵀV − I| = {ov:e}, |R − I| = {er:e} \
                             (4ε = {:e})",
                            4.0 * eps
                        ));
                    }
                    let fc = f.cols.concat();
                    let (mut r, mut s) = ([T::ZERO; 4], [T::ZERO; 4]);
                    let st =
                        unsafe { polar(ptr::null(), fc.as_ptr(), r.as_mut_ptr(), s.as_mut_ptr()) };
                    let r = Mat::<T, 2>::from_col_major(&r)
                        .expect("4 entries")
                        .cast::<f64>();
                    let er = (r - id).max_abs();
                    if st != AmpmStatus::AMPM_OK || er > 4.0 * eps {
                        failures.push(format!("{at}: C ABI polar: {st:?}, |R − I| = {er:e}"));
                    }
                }
            }
        }
        failures
    }
    let mut failures = check::<f32>(&[1e-22, 1e-30], ampm_polar_2d_f32);
    failures.extend(check::<f64>(&[1e-161, 1e-162, 1e-300], ampm_polar_2d_f64));
    assert!(
        failures.is_empty(),
        "{} failures:\n{}",
        failures.len(),
        failures.join("\n")
    );
}

// --- C ABI: run-time method choice -------------------------------------------------------

fn opts(method: u32, sweeps: u32, max_iterations: u32) -> AmpmOptions {
    AmpmOptions {
        method,
        sweeps,
        max_iterations,
    }
}

const F3: [f64; 9] = [1.2, 0.2, -0.3, 0.3, 0.8, 0.1, -0.1, 0.4, 1.5];
const Z3: [f64; 9] = [0.3, 0.5, 0.9, -0.7, 0.1, 0.6, 0.2, -0.4, 0.2];

/// Each `_ex` call equals, bit for bit, the Rust kernel with the same method chosen at
/// compile time; with the default method (as the calls without `_ex`), the fast kernels of
/// `ampm_core::kernel` on the scalar path.
#[test]
fn ffi_ex_matches_compile_time_methods() {
    let f = Mat::<f64, 3>::from_col_major(&F3).unwrap();
    let z = Mat::<f64, 3>::from_col_major(&Z3).unwrap();
    fn expect<S: SvdMethod<Mat<f64, 3>>>(m: S, o: AmpmOptions, f: &Mat<f64, 3>, z: &Mat<f64, 3>) {
        let e = FixedCorotated::with_method(2.0, m);
        let (a, c, p) = if o.method == AMPM_METHOD_DEFAULT {
            use ampm_core::kernel::batch::{ahat_chat_z, Outputs};
            let (mut a, mut c, mut p) = ([0.0; 9], [0.0; 9], [0.0; 1]);
            let out = Outputs {
                ahat: Some(&mut a),
                chat_z: Some(&mut c),
                energy: Some(&mut p),
                psd: false,
            };
            let st =
                ahat_chat_z::<f64, 3>(ampm_core::lane::Isa::SCALAR, &[2.0], &F3, Some(&Z3), out);
            assert_eq!(st.unwrap().error, None);
            (
                Mat::from_col_major(&a).unwrap(),
                Mat::from_col_major(&c).unwrap(),
                p[0],
            )
        } else {
            (
                augmented::ahat(&e, f).unwrap(),
                augmented::chat_z(&e, f, z).unwrap(),
                augmented::psi_hat(&e, f).unwrap(),
            )
        };
        let (mut out, mut psi) = ([0.0; 9], 0.0);
        unsafe {
            assert_eq!(
                ampm_ahat_ex_3d_f64(&o, 2.0, F3.as_ptr(), out.as_mut_ptr()),
                AmpmStatus::AMPM_OK
            );
            assert_eq!(Mat::from_col_major(&out).unwrap(), a, "{o:?}");
            assert_eq!(
                ampm_chat_z_ex_3d_f64(&o, 2.0, F3.as_ptr(), Z3.as_ptr(), out.as_mut_ptr()),
                AmpmStatus::AMPM_OK
            );
            assert_eq!(Mat::from_col_major(&out).unwrap(), c, "{o:?}");
            assert_eq!(
                ampm_energy_hat_ex_3d_f64(&o, 2.0, F3.as_ptr(), &mut psi),
                AmpmStatus::AMPM_OK
            );
            assert_eq!(psi, p);
        }
        let s = m.svd(f).unwrap();
        let (mut u, mut sg, mut v) = ([0.0; 9], [0.0; 3], [0.0; 9]);
        unsafe {
            assert_eq!(
                ampm_svd_3d_f64(
                    &o,
                    F3.as_ptr(),
                    u.as_mut_ptr(),
                    sg.as_mut_ptr(),
                    v.as_mut_ptr()
                ),
                AmpmStatus::AMPM_OK
            );
        }
        assert_eq!(Mat::from_col_major(&u).unwrap(), s.u);
        assert_eq!(sg, s.sigma);
        assert_eq!(Mat::from_col_major(&v).unwrap(), s.v);
    }
    expect(
        OneSidedJacobi::default(),
        opts(AMPM_METHOD_DEFAULT, 0, 0),
        &f,
        &z,
    );
    expect(
        OneSidedJacobi { sweeps: 5 },
        opts(AMPM_METHOD_ONE_SIDED_JACOBI, 0, 5),
        &f,
        &z,
    );
    expect(McAdams::default(), opts(AMPM_METHOD_MCADAMS, 0, 0), &f, &z);
    expect(
        McAdams { sweeps: 7 },
        opts(AMPM_METHOD_MCADAMS, 7, 0),
        &f,
        &z,
    );
    expect(QrSvd::default(), opts(AMPM_METHOD_QR, 0, 0), &f, &z);
    expect(
        HighamNoferini::default(),
        opts(AMPM_METHOD_HIGHAM_NOFERINI, 0, 0),
        &f,
        &z,
    );
    // NULL options = defaults = the plain entry point.
    let mut a = [0.0; 9];
    let mut b = [0.0; 9];
    unsafe {
        assert_eq!(
            ampm_ahat_ex_3d_f64(ptr::null(), 2.0, F3.as_ptr(), a.as_mut_ptr()),
            AmpmStatus::AMPM_OK
        );
        assert_eq!(
            ampm::ampm_ahat_3d_f64(2.0, F3.as_ptr(), b.as_mut_ptr()),
            AmpmStatus::AMPM_OK
        );
    }
    assert_eq!(a, b);
}

/// Invalid choices are `AMPM_ERR_INVALID_ARGUMENT` and write nothing.
#[test]
fn ffi_invalid_options_are_refused() {
    let bad3 = [
        opts(6, 0, 0),
        opts(u32::MAX, 0, 0),
        opts(AMPM_METHOD_CLOSED_FORM_2D, 0, 0),
        opts(AMPM_METHOD_MCADAMS, 1, 0),
        opts(AMPM_METHOD_MCADAMS, 9, 0),
        opts(AMPM_METHOD_QR, 0, 1001),
    ];
    for o in bad3 {
        let mut out = [7.0; 9];
        let mut out32 = [7.0f32; 9];
        let f32m = F3.map(|x| x as f32);
        let mut ff = 42usize;
        unsafe {
            assert_eq!(
                ampm_ahat_ex_3d_f64(&o, 1.0, F3.as_ptr(), out.as_mut_ptr()),
                AmpmStatus::AMPM_ERR_INVALID_ARGUMENT,
                "{o:?}"
            );
            assert_eq!(
                ampm_ahat_ex_3d_f32(&o, 1.0, f32m.as_ptr(), out32.as_mut_ptr()),
                AmpmStatus::AMPM_ERR_INVALID_ARGUMENT
            );
            assert_eq!(
                ampm_ahat_batch_ex_3d_f64(&o, 1, &1.0, F3.as_ptr(), out.as_mut_ptr(), &mut ff),
                AmpmStatus::AMPM_ERR_INVALID_ARGUMENT
            );
            let (mut u, mut s, mut v) = ([7.0f32; 9], [7.0f32; 3], [7.0f32; 9]);
            assert_eq!(
                ampm_svd_3d_f32(
                    &o,
                    f32m.as_ptr(),
                    u.as_mut_ptr(),
                    s.as_mut_ptr(),
                    v.as_mut_ptr()
                ),
                AmpmStatus::AMPM_ERR_INVALID_ARGUMENT
            );
            assert_eq!((u, s, v), ([7.0; 9], [7.0; 3], [7.0; 9]));
        }
        assert_eq!(out, [7.0; 9]);
        assert_eq!(out32, [7.0; 9]);
    }
    // 3D methods in 2D calls.
    let f2 = [1.2, -0.4, 0.3, 0.7];
    for m in [
        AMPM_METHOD_ONE_SIDED_JACOBI,
        AMPM_METHOD_MCADAMS,
        AMPM_METHOD_QR,
        AMPM_METHOD_HIGHAM_NOFERINI,
        17,
    ] {
        let mut out = [7.0; 4];
        let s = unsafe { ampm_ahat_ex_2d_f64(&opts(m, 0, 0), 1.0, f2.as_ptr(), out.as_mut_ptr()) };
        assert_eq!(s, AmpmStatus::AMPM_ERR_INVALID_ARGUMENT);
        assert_eq!(out, [7.0; 4]);
    }
    for m in [AMPM_METHOD_DEFAULT, AMPM_METHOD_CLOSED_FORM_2D] {
        let mut out = [7.0; 4];
        let s = unsafe { ampm_ahat_ex_2d_f64(&opts(m, 0, 0), 1.0, f2.as_ptr(), out.as_mut_ptr()) };
        assert_eq!(s, AmpmStatus::AMPM_OK);
    }
}

/// Decompositions accept any finite F (det ≤ 0 too), refuse NaN, check pointers.
#[test]
fn ffi_svd_and_polar() {
    // det F < 0.
    // The matrix of `higham_noferini_is_rotation_variant_for_negative_det`, det = −0.668.
    let f = [1.5, 0.1, 0.2, 0.2, 0.8, -0.1, 0.1, 0.3, -0.6];
    let fm = Mat::<f64, 3>::from_col_major(&f).unwrap();
    assert!(fm.det() < 0.0);
    for m in [
        AMPM_METHOD_DEFAULT,
        AMPM_METHOD_ONE_SIDED_JACOBI,
        AMPM_METHOD_MCADAMS,
        AMPM_METHOD_QR,
        AMPM_METHOD_HIGHAM_NOFERINI,
    ] {
        let o = opts(m, 8, 0);
        let (mut r, mut s) = ([0.0; 9], [0.0; 9]);
        let st = unsafe { ampm_polar_3d_f64(&o, f.as_ptr(), r.as_mut_ptr(), s.as_mut_ptr()) };
        assert_eq!(st, AmpmStatus::AMPM_OK);
        let (r, s) = (
            Mat::<f64, 3>::from_col_major(&r).unwrap(),
            Mat::<f64, 3>::from_col_major(&s).unwrap(),
        );
        assert!((r.det() - 1.0).abs() < 1e-12, "method {m}");
        assert!((s - s.transpose()).max_abs() < 1e-12, "method {m}");
        assert!((r * s - fm).max_abs() < 1e-12, "method {m}");
        // NaN: refused, nothing written.
        let mut g = f;
        g[4] = f64::NAN;
        let (mut r2, mut s2) = ([7.0; 9], [7.0; 9]);
        let st = unsafe { ampm_polar_3d_f64(&o, g.as_ptr(), r2.as_mut_ptr(), s2.as_mut_ptr()) };
        assert_eq!(st, AmpmStatus::AMPM_ERR_NON_FINITE);
        assert_eq!((r2, s2), ([7.0; 9], [7.0; 9]));
        // NULL output.
        let st = unsafe { ampm_polar_3d_f64(&o, f.as_ptr(), ptr::null_mut(), s2.as_mut_ptr()) };
        assert_eq!(st, AmpmStatus::AMPM_ERR_NULL_POINTER);
    }
    // 2D reflection-like F (det < 0) through the closed form.
    let f2 = [0.5, 1.0, 1.0, -0.25];
    let (mut r, mut s) = ([0.0; 4], [0.0; 4]);
    let o = opts(AMPM_METHOD_CLOSED_FORM_2D, 0, 0);
    let st = unsafe { ampm_polar_2d_f64(&o, f2.as_ptr(), r.as_mut_ptr(), s.as_mut_ptr()) };
    assert_eq!(st, AmpmStatus::AMPM_OK);
    let r = Mat::<f64, 2>::from_col_major(&r).unwrap();
    assert!((r.det() - 1.0).abs() < 1e-14);
    let (mut u, mut sg, mut v) = ([0.0f32; 4], [0.0f32; 2], [0.0f32; 4]);
    let f2s = f2.map(|x| x as f32);
    let st = unsafe {
        ampm_svd_2d_f32(
            ptr::null(),
            f2s.as_ptr(),
            u.as_mut_ptr(),
            sg.as_mut_ptr(),
            v.as_mut_ptr(),
        )
    };
    assert_eq!(st, AmpmStatus::AMPM_OK);
    assert!(sg[0] >= sg[1].abs() && sg[1] < 0.0);
}

/// Batch `_ex`: every valid particle computed with the chosen method, a failed one untouched,
/// the first failure's index reported.
#[test]
fn ffi_batch_ex_first_failure() {
    let mut f = [0.0; 27];
    f[..9].copy_from_slice(&F3);
    f[9..18].copy_from_slice(&[1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, -1.0]); // J < 0
    f[18..].copy_from_slice(&F3);
    let mut z = [0.0; 27];
    for k in 0..3 {
        z[9 * k..9 * k + 9].copy_from_slice(&Z3);
    }
    let mu = [1.0, 1.0, 3.0];
    let o = opts(AMPM_METHOD_QR, 0, 0);
    let mut out = [7.0; 27];
    let mut ff = 0usize;
    let st = unsafe {
        ampm_chat_z_batch_ex_3d_f64(
            &o,
            3,
            mu.as_ptr(),
            f.as_ptr(),
            z.as_ptr(),
            out.as_mut_ptr(),
            &mut ff,
        )
    };
    assert_eq!(st, AmpmStatus::AMPM_ERR_NON_POSITIVE_J);
    assert_eq!(ff, 1);
    assert_eq!(out[9..18], [7.0; 9]);
    let fm = Mat::<f64, 3>::from_col_major(&F3).unwrap();
    let zm = Mat::<f64, 3>::from_col_major(&Z3).unwrap();
    let expect = augmented::chat_z(
        &FixedCorotated::with_method(3.0, QrSvd::default()),
        &fm,
        &zm,
    )
    .unwrap();
    assert_eq!(Mat::from_col_major(&out[18..]).unwrap(), expect);
    // n = 0 with NULL arrays is fine and reports n.
    let st = unsafe {
        ampm_ahat_batch_ex_3d_f64(&o, 0, ptr::null(), ptr::null(), ptr::null_mut(), &mut ff)
    };
    assert_eq!(st, AmpmStatus::AMPM_OK);
    assert_eq!(ff, 0);
}

/// The 2D closed form in the registry stays the only 2D method.
#[test]
fn closed_form_is_the_2d_default() {
    let f = Mat::<f32, 2>::from_rows([[1.2, 0.3], [-0.4, 0.7]]);
    assert_eq!(
        <ampm_core::polar::DefaultSvd as SvdMethod<Mat<f32, 2>>>::NAME,
        <ClosedForm2 as SvdMethod<Mat<f32, 2>>>::NAME
    );
    assert_eq!(
        ampm_core::polar::DefaultSvd.svd(&f).unwrap(),
        ClosedForm2.svd(&f).unwrap()
    );
    assert!(Real::is_finite(f.det()));
}
