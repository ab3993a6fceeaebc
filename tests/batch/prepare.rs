//! Prepare once, apply many: apply equals the combined call's `Ĉ:Z` and `Ĉ⁺:Z` within the
//! stated bound; zero-filled slots and the slots of failed prepares are refused
//! (`NotPrepared`), never applied, including a slot that held an earlier valid prepare. The C
//! entry points of prepare and apply, and their NULL rules.
use super::*;
use ampm::AmpmStatus;
use ampm_core::kernel::prepared;

// ---------------------------------------------------------------------------------------
// 3. Prepare once, apply many.

fn prepare_apply<T: BatchReal, const D: usize>()
where
    Dim<D>: LaneDim<D>,
    Mat<f64, D>: Matrix<Scalar = f64, Vector = [f64; D]> + HaarRotation,
    Mat<T, D>: Matrix<Scalar = T>,
{
    let e = D * D;
    let w = prepared::len(D);
    let eps = T::EPSILON.to_f64();
    let sentinel = T::from_f64(-7.25);
    for isa in Isa::available() {
        let cs = cases::<T, D>(53, 21);
        let n = cs.len();
        let mu: Vec<T> = cs.iter().map(|c| c.mu).collect();
        let f: Vec<T> = cs.iter().flat_map(|c| c.f.cols.concat()).collect();
        let z: Vec<T> = cs.iter().flat_map(|c| c.z.cols.concat()).collect();
        // The buffer first holds a valid prepare of other matrices (an earlier Newton step).
        let mut prep = vec![T::ZERO; w * n];
        let mu0 = vec![T::ONE; n];
        let f0: Vec<T> = cases::<T, D>(n, 99)
            .iter()
            .flat_map(|c| {
                let mut m = c.f;
                if m.det() <= T::ZERO || !m.is_finite() {
                    m = Mat::identity();
                }
                m.cols.concat()
            })
            .collect();
        let s0 = batch::prepare::<T, D>(isa, &mu0, &f0, None, &mut prep).unwrap();
        assert_eq!(s0.error, None);
        let mut ahat = vec![sentinel; e * n];
        let st = batch::prepare::<T, D>(isa, &mu, &f, Some(&mut ahat), &mut prep).unwrap();
        let first = cs.iter().position(|c| c.expect_ahat().is_some());
        assert_eq!(st.first_failed, first.unwrap_or(n));
        let (ra, _, _) = run::<T, D>(isa, &cs, false);
        for psd in [false, true] {
            let (_, rc, _) = run::<T, D>(isa, &cs, psd);
            let mut out = vec![sentinel; e * n];
            let st = batch::apply::<T, D>(isa, &prep, &z, &mut out, psd).unwrap();
            let first = cs.iter().position(|c| c.expect.is_some()).unwrap_or(n);
            assert_eq!(st.first_failed, first, "{isa:?}");
            for (i, c) in cs.iter().enumerate() {
                let o = &out[i * e..(i + 1) * e];
                if c.expect_ahat().is_some() {
                    // A failed prepare's slot: refused, never applied, although it held a
                    // valid prepare of an earlier step.
                    let mut one = vec![sentinel; e];
                    let s = batch::apply::<T, D>(
                        isa,
                        &prep[i * w..(i + 1) * w],
                        &c.z.cols.concat(),
                        &mut one,
                        psd,
                    )
                    .unwrap();
                    assert_eq!(s.error, Some(Error::NotPrepared), "{isa:?} slot {i}");
                    assert!(o.iter().chain(&one).all(|&x| x == sentinel), "{i} applied");
                    assert!(
                        ahat[i * e..(i + 1) * e].iter().all(|&x| x == sentinel),
                        "{i} Â written"
                    );
                } else if c.expect.is_some() {
                    assert!(o.iter().all(|&x| x == sentinel), "{i}: NaN Z applied");
                } else {
                    assert_eq!(
                        ahat[i * e..(i + 1) * e],
                        ra[i * e..(i + 1) * e],
                        "prepare Â {i}"
                    );
                    let fnorm = c.f.cast::<f64>().ddot(&c.f.cast::<f64>()).sqrt();
                    let s = c.mu.to_f64().max(1.0)
                        * (1.0 + fnorm * fnorm)
                        * c.z.cast::<f64>().ddot(&c.z.cast::<f64>()).sqrt().max(1.0);
                    let r = rel(o, &rc[i * e..(i + 1) * e], s) / eps;
                    // Apply uses the coefficients the combined call computes, stored and read
                    // back unchanged: the same operations, the same bits.
                    assert!(r == 0.0, "{isa:?} psd={psd} particle {i}: {r} ε");
                }
            }
        }
        // Zero-filled slots are refused, and nothing is written.
        let zeros = vec![T::ZERO; w * 3];
        let mut out = vec![sentinel; e * 3];
        let s = batch::apply::<T, D>(isa, &zeros, &z[..3 * e], &mut out, false).unwrap();
        assert_eq!((s.first_failed, s.error), (0, Some(Error::NotPrepared)));
        assert!(out.iter().all(|&x| x == sentinel));
        // Lengths that disagree: a whole-call error.
        let r = batch::apply::<T, D>(isa, &zeros[1..], &z[..3 * e], &mut out, false);
        assert_eq!(r, Err(Error::InvalidArgument));
    }
}

#[test]
fn prepare_apply_2d_f32() {
    prepare_apply::<f32, 2>();
}
#[test]
fn prepare_apply_2d_f64() {
    prepare_apply::<f64, 2>();
}
#[test]
fn prepare_apply_3d_f32() {
    prepare_apply::<f32, 3>();
}
#[test]
fn prepare_apply_3d_f64() {
    prepare_apply::<f64, 3>();
}

#[test]
fn c_prepare_apply_and_null_rules() {
    let cs = cases::<f64, 3>(20, 8);
    let n = cs.len();
    let len = ampm::ampm_hessian_len_3d_f64();
    assert_eq!(len, prepared::len(3));
    assert_eq!(ampm::ampm_hessian_len_2d_f32(), prepared::len(2));
    let mu: Vec<f64> = cs.iter().map(|c| c.mu).collect();
    let f: Vec<f64> = cs.iter().flat_map(|c| c.f.cols.concat()).collect();
    let z: Vec<f64> = cs.iter().flat_map(|c| c.z.cols.concat()).collect();
    let mut prep = vec![0.0; len * n];
    let mut ff = usize::MAX;
    let null = std::ptr::null_mut::<f64>();
    let s = unsafe {
        ampm::ampm_hessian_prepare_batch_3d_f64(
            n,
            mu.as_ptr(),
            f.as_ptr(),
            null,
            prep.as_mut_ptr(),
            &mut ff,
        )
    };
    let fa = cs.iter().position(|c| c.expect_ahat().is_some()).unwrap();
    assert_eq!((s, ff), (cs[fa].expect_ahat().unwrap().into(), fa));
    let mut out = vec![0.0; 9 * n];
    let s = unsafe {
        ampm::ampm_hessian_apply_batch_3d_f64(
            n,
            prep.as_ptr(),
            z.as_ptr(),
            out.as_mut_ptr(),
            1,
            &mut ff,
        )
    };
    assert_eq!((s, ff), (AmpmStatus::AMPM_ERR_NOT_PREPARED, fa));
    // NULL rules.
    let s = unsafe {
        ampm::ampm_hessian_apply_batch_3d_f64(
            n,
            std::ptr::null(),
            z.as_ptr(),
            out.as_mut_ptr(),
            0,
            &mut ff,
        )
    };
    assert_eq!(s, AmpmStatus::AMPM_ERR_NULL_POINTER);
    let s = unsafe {
        ampm::ampm_hessian_apply_batch_3d_f64(
            0,
            std::ptr::null(),
            std::ptr::null(),
            null,
            0,
            &mut ff,
        )
    };
    assert_eq!((s, ff), (AmpmStatus::AMPM_OK, 0));
    let s = unsafe {
        ampm::ampm_ahat_chat_z_batch_3d_f64(
            n,
            mu.as_ptr(),
            f.as_ptr(),
            std::ptr::null(),
            null,
            null,
            &mut ff,
        )
    };
    assert_eq!(s, AmpmStatus::AMPM_ERR_NULL_POINTER, "no output");
    let s = unsafe {
        ampm::ampm_ahat_chat_z_batch_3d_f64(
            n,
            mu.as_ptr(),
            f.as_ptr(),
            std::ptr::null(),
            null,
            out.as_mut_ptr(),
            &mut ff,
        )
    };
    assert_eq!(s, AmpmStatus::AMPM_ERR_NULL_POINTER, "Ĉ:Z without Z");
    // The instruction-set choice: an unsupported value changes nothing.
    let cur = ampm::ampm_isa();
    assert_eq!(
        ampm::ampm_set_isa(99),
        AmpmStatus::AMPM_ERR_INVALID_ARGUMENT
    );
    assert_eq!(ampm::ampm_isa(), cur);
}
