//! Properties of the methods themselves: scale invariance, bounded iteration, and the edge
//! cases of single methods (QR, Higham–Noferini, the 2D closed form).
use ampm::methods::{ampm_polar_2d_f32, ampm_polar_2d_f64, AmpmOptions};
use ampm::AmpmStatus;
use ampm_core::polar::{
    ClosedForm2, HighamNoferini, McAdams, OneSidedJacobi, QrSvd, Svd, SvdMethod,
};
use ampm_core::{Error, Mat, Matrix, Real};
use ampm_tools::families::{generate, Family, Size};
use std::ptr;

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
