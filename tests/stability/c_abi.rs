//! The run-time method choice of the C ABI (`ffi/src/methods.rs`): the `_ex` calls equal the
//! compile-time methods bit for bit, invalid options are refused, decompositions accept any
//! finite `F`, and batch `_ex` calls report the first failure.
use ampm::methods::{
    ampm_ahat_batch_ex_3d_f64, ampm_ahat_ex_2d_f64, ampm_ahat_ex_3d_f32, ampm_ahat_ex_3d_f64,
    ampm_chat_z_batch_ex_3d_f64, ampm_chat_z_ex_3d_f64, ampm_energy_hat_ex_3d_f64,
    ampm_polar_2d_f64, ampm_polar_3d_f64, ampm_svd_2d_f32, ampm_svd_3d_f32, ampm_svd_3d_f64,
    AmpmOptions, AMPM_METHOD_CLOSED_FORM_2D, AMPM_METHOD_DEFAULT, AMPM_METHOD_HIGHAM_NOFERINI,
    AMPM_METHOD_MCADAMS, AMPM_METHOD_ONE_SIDED_JACOBI, AMPM_METHOD_QR,
};
use ampm::AmpmStatus;
use ampm_core::augmented;
use ampm_core::energy::FixedCorotated;
use ampm_core::polar::{HighamNoferini, McAdams, OneSidedJacobi, QrSvd, SvdMethod};
use ampm_core::{Mat, Matrix};
use std::ptr;

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
