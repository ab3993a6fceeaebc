//! A whole-call error of any batch entry point (NULL required pointer, `n` too large, an
//! invalid option) writes nothing but `*first_failed = 0` (the `whole_call_errors_*` tests).
use super::*;
use ampm::AmpmStatus::*;
use std::ptr;

// ---------------------------------------------------------------------------------------------
// Whole-call errors of every batch entry point.
// ---------------------------------------------------------------------------------------------

/// A batch call of one case below, given the output arrays (Â, Ĉ:Z, prepared slots) and
/// `first_failed`.
type WholeCall<'a, T> = Box<dyn Fn(*mut T, *mut T, *mut T, *mut usize) -> AmpmStatus + 'a>;

/// Runs each `(name, expected status, call)`, with `first_failed` non-NULL and NULL: the status
/// is the expected whole-call error, no output is written, and `*first_failed` = 0.
fn check_whole_call<T: Copy + PartialEq + std::fmt::Debug>(
    n: usize,
    slot: usize,
    sentinel: T,
    cases: &[(&str, AmpmStatus, WholeCall<'_, T>)],
) {
    let e = 9; // scalars of the largest matrix
    for (name, want, call) in cases {
        for with_ff in [true, false] {
            let mut a = vec![sentinel; n * e];
            let mut c = vec![sentinel; n * e];
            let mut p = vec![sentinel; n * slot];
            let mut ff = 77usize;
            let ffp: *mut usize = if with_ff { &mut ff } else { ptr::null_mut() };
            let st = call(a.as_mut_ptr(), c.as_mut_ptr(), p.as_mut_ptr(), ffp);
            assert_eq!(st, *want, "{name}");
            assert!(
                a.iter().chain(&c).chain(&p).all(|x| *x == sentinel),
                "{name}: output written"
            );
            if with_ff {
                assert_eq!(ff, 0, "{name}: first_failed");
            }
        }
    }
}

macro_rules! whole_call_errors {
    ($($m:ident: $t:ty, $d:literal, $ab:ident, $cb:ident, $psd:ident, $comb:ident, $len:ident,
       $prep:ident, $apply:ident, $aex:ident, $cex:ident;)*) => {$(
        /// Every batch entry point of one type: NULL required pointers, an `n` too large to
        /// address and invalid options are whole-call errors (nothing written,
        /// `*first_failed` = 0); a NULL pointer takes precedence over an invalid option.
        #[test]
        fn $m() {
            use ampm::methods::{AmpmOptions, AMPM_METHOD_CLOSED_FORM_2D, AMPM_METHOD_MCADAMS};
            type T = $t;
            const E: usize = $d * $d;
            let n = 3;
            let mu = vec![2.0 as T; n];
            let mut f = vec![0.0 as T; n * E];
            for i in 0..n {
                for j in 0..$d {
                    f[i * E + j * ($d + 1)] = 1.0 + 0.25 * j as T;
                }
            }
            let z = vec![0.5 as T; n * E];
            let (mu, f, z) = (mu.as_ptr(), f.as_ptr(), z.as_ptr());
            let big = usize::MAX / (E * std::mem::size_of::<T>()) + 1;
            let bad = AmpmOptions {
                method: 99,
                ..AmpmOptions::default()
            };
            let other = AmpmOptions {
                method: if $d == 2 {
                    AMPM_METHOD_CLOSED_FORM_2D
                } else {
                    AMPM_METHOD_MCADAMS
                },
                ..AmpmOptions::default()
            };
            let (bad, other) = (&bad as *const AmpmOptions, &other as *const AmpmOptions);
            let (nul, nulm) = (ptr::null::<T>(), ptr::null_mut::<T>());
            use AmpmStatus::{AMPM_ERR_INVALID_ARGUMENT as INVALID, AMPM_ERR_NULL_POINTER as NULL};
            // SAFETY (every call): non-null arrays hold n records (slots of ampm_hessian_len);
            // the calls must refuse before reading or writing any of them.
            let cases: Vec<(&str, AmpmStatus, WholeCall<'_, T>)> = vec![
                ("ahat_batch NULL mu", NULL, Box::new(|a, _, _, ff| unsafe {
                    ampm::$ab(n, nul, f, a, ff)
                })),
                ("ahat_batch n too large", INVALID, Box::new(|a, _, _, ff| unsafe {
                    ampm::$ab(big, mu, f, a, ff)
                })),
                ("chat_z_batch NULL z", NULL, Box::new(|_, c, _, ff| unsafe {
                    ampm::$cb(n, mu, f, nul, c, ff)
                })),
                ("chat_z_psd_batch NULL f", NULL, Box::new(|_, c, _, ff| unsafe {
                    ampm::hessian::$psd(n, mu, nul, z, c, ff)
                })),
                ("chat_z_psd_batch n too large", INVALID, Box::new(|_, c, _, ff| unsafe {
                    ampm::hessian::$psd(big, mu, f, z, c, ff)
                })),
                ("ahat_chat_z_batch no output", NULL, Box::new(|_, _, _, ff| unsafe {
                    ampm::$comb(n, mu, f, z, nulm, nulm, ff)
                })),
                ("ahat_chat_z_batch NULL z", NULL, Box::new(|a, c, _, ff| unsafe {
                    ampm::$comb(n, mu, f, nul, a, c, ff)
                })),
                ("ahat_chat_z_batch n too large", INVALID, Box::new(|a, c, _, ff| unsafe {
                    ampm::$comb(big, mu, f, z, a, c, ff)
                })),
                ("hessian_prepare_batch NULL prepared", NULL, Box::new(|a, _, _, ff| unsafe {
                    ampm::$prep(n, mu, f, a, nulm, ff)
                })),
                ("hessian_prepare_batch n too large", INVALID, Box::new(|a, _, p, ff| unsafe {
                    ampm::$prep(big, mu, f, a, p, ff)
                })),
                ("hessian_apply_batch NULL z", NULL, Box::new(|_, c, p, ff| unsafe {
                    ampm::$apply(n, p, nul, c, 0, ff)
                })),
                ("hessian_apply_batch n too large", INVALID, Box::new(|_, c, p, ff| unsafe {
                    ampm::$apply(big, p, z, c, 1, ff)
                })),
                ("ahat_batch_ex invalid option", INVALID, Box::new(|a, _, _, ff| unsafe {
                    ampm::methods::$aex(bad, n, mu, f, a, ff)
                })),
                ("ahat_batch_ex invalid option, NULL f", NULL, Box::new(|a, _, _, ff| unsafe {
                    ampm::methods::$aex(bad, n, mu, nul, a, ff)
                })),
                ("ahat_batch_ex method, NULL out", NULL, Box::new(|_, _, _, ff| unsafe {
                    ampm::methods::$aex(other, n, mu, f, nulm, ff)
                })),
                ("ahat_batch_ex default, n too large", INVALID, Box::new(|a, _, _, ff| unsafe {
                    ampm::methods::$aex(ptr::null(), big, mu, f, a, ff)
                })),
                ("chat_z_batch_ex invalid option", INVALID, Box::new(|_, c, _, ff| unsafe {
                    ampm::methods::$cex(bad, n, mu, f, z, c, ff)
                })),
                ("chat_z_batch_ex method, n too large", INVALID, Box::new(|_, c, _, ff| unsafe {
                    ampm::methods::$cex(other, big, mu, f, z, c, ff)
                })),
            ];
            check_whole_call::<T>(n, ampm::$len(), SENTINEL as T, &cases);
            // The same arguments without the fault: every record computed, first_failed = n.
            let mut ff = 0;
            let mut out = vec![SENTINEL as T; n * E];
            // SAFETY: arrays hold n records.
            let st = unsafe { ampm::methods::$cex(other, n, mu, f, z, out.as_mut_ptr(), &mut ff) };
            assert_eq!((st, ff), (AMPM_OK, n));
            assert!(out.iter().all(|x| *x != SENTINEL as T));
        }
    )*};
}
whole_call_errors! {
    whole_call_errors_2d_f32: f32, 2, ampm_ahat_batch_2d_f32, ampm_chat_z_batch_2d_f32,
        ampm_chat_z_psd_batch_2d_f32, ampm_ahat_chat_z_batch_2d_f32, ampm_hessian_len_2d_f32,
        ampm_hessian_prepare_batch_2d_f32, ampm_hessian_apply_batch_2d_f32,
        ampm_ahat_batch_ex_2d_f32, ampm_chat_z_batch_ex_2d_f32;
    whole_call_errors_2d_f64: f64, 2, ampm_ahat_batch_2d_f64, ampm_chat_z_batch_2d_f64,
        ampm_chat_z_psd_batch_2d_f64, ampm_ahat_chat_z_batch_2d_f64, ampm_hessian_len_2d_f64,
        ampm_hessian_prepare_batch_2d_f64, ampm_hessian_apply_batch_2d_f64,
        ampm_ahat_batch_ex_2d_f64, ampm_chat_z_batch_ex_2d_f64;
    whole_call_errors_3d_f32: f32, 3, ampm_ahat_batch_3d_f32, ampm_chat_z_batch_3d_f32,
        ampm_chat_z_psd_batch_3d_f32, ampm_ahat_chat_z_batch_3d_f32, ampm_hessian_len_3d_f32,
        ampm_hessian_prepare_batch_3d_f32, ampm_hessian_apply_batch_3d_f32,
        ampm_ahat_batch_ex_3d_f32, ampm_chat_z_batch_ex_3d_f32;
    whole_call_errors_3d_f64: f64, 3, ampm_ahat_batch_3d_f64, ampm_chat_z_batch_3d_f64,
        ampm_chat_z_psd_batch_3d_f64, ampm_ahat_chat_z_batch_3d_f64, ampm_hessian_len_3d_f64,
        ampm_hessian_prepare_batch_3d_f64, ampm_hessian_apply_batch_3d_f64,
        ampm_ahat_batch_ex_3d_f64, ampm_chat_z_batch_ex_3d_f64;
}
