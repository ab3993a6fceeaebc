//! The C ABI: `ampm_ahat_chat_z_batch`, `ampm_ahat_batch`, `ampm_chat_z_batch` and
//! `ampm_chat_z_psd_batch` equal the core call on the same instruction set bit for bit; the
//! single-particle calls equal the core scalar path bit for bit.
use super::*;
use ampm::AmpmStatus;
use ampm_core::lane::IsaKind;

/// The C batch and single calls against the core calls.
macro_rules! c_abi_test {
    ($name:ident, $t:ty, $d:literal, $comb:ident, $ahat_b:ident, $chat_b:ident, $psd_b:ident,
     $ahat:ident, $chat:ident, $psd:ident) => {
        #[test]
        fn $name() {
            const E: usize = $d * $d;
            // The instruction set the C batch calls use.
            let cur = *Isa::available()
                .iter()
                .find(|i| match i.kind() {
                    IsaKind::Scalar => ampm::ampm_isa() == ampm::AMPM_ISA_SCALAR,
                    IsaKind::Avx2 => ampm::ampm_isa() == ampm::AMPM_ISA_AVX2,
                    IsaKind::Avx512 => ampm::ampm_isa() == ampm::AMPM_ISA_AVX512,
                })
                .unwrap();
            let cs = cases::<$t, $d>(45, 3);
            let n = cs.len();
            let mu: Vec<$t> = cs.iter().map(|c| c.mu).collect();
            let f: Vec<$t> = cs.iter().flat_map(|c| c.f.cols.concat()).collect();
            let z: Vec<$t> = cs.iter().flat_map(|c| c.z.cols.concat()).collect();
            let status = |e: Option<Error>| e.map_or(AmpmStatus::AMPM_OK, AmpmStatus::from);
            for psd in [false, true] {
                let (ra, rc, st) = run::<$t, $d>(cur, &cs, psd);
                let mut c = vec![-7.25 as $t; E * n];
                let mut ff = usize::MAX;
                let s1 = unsafe {
                    if psd {
                        ampm::hessian::$psd_b(
                            n,
                            mu.as_ptr(),
                            f.as_ptr(),
                            z.as_ptr(),
                            c.as_mut_ptr(),
                            &mut ff,
                        )
                    } else {
                        let mut a = vec![-7.25 as $t; E * n];
                        let s = ampm::$comb(
                            n,
                            mu.as_ptr(),
                            f.as_ptr(),
                            z.as_ptr(),
                            a.as_mut_ptr(),
                            c.as_mut_ptr(),
                            &mut ff,
                        );
                        assert_eq!(a, ra, "combined Â");
                        // The two separate calls.
                        let mut a2 = vec![-7.25 as $t; E * n];
                        let mut c2 = vec![-7.25 as $t; E * n];
                        let mut ff2 = usize::MAX;
                        let s2 =
                            ampm::$ahat_b(n, mu.as_ptr(), f.as_ptr(), a2.as_mut_ptr(), &mut ff2);
                        let fa = cs.iter().position(|c| c.expect_ahat().is_some());
                        assert_eq!(ff2, fa.unwrap_or(n));
                        assert_eq!(s2, status(fa.and_then(|i| cs[i].expect_ahat())));
                        for i in 0..n {
                            if cs[i].z_only {
                                assert!(
                                    a2[i * E..(i + 1) * E].iter().all(|x| x.is_finite()),
                                    "Â {i}"
                                );
                            } else if cs[i].expect_ahat().is_none() {
                                assert_eq!(a2[i * E..(i + 1) * E], ra[i * E..(i + 1) * E], "Â {i}");
                            } else {
                                assert!(
                                    a2[i * E..(i + 1) * E].iter().all(|&x| x == -7.25),
                                    "{i} written"
                                );
                            }
                        }
                        let s3 = ampm::$chat_b(
                            n,
                            mu.as_ptr(),
                            f.as_ptr(),
                            z.as_ptr(),
                            c2.as_mut_ptr(),
                            std::ptr::null_mut(),
                        );
                        assert_eq!(s3, s);
                        assert_eq!(c2, rc, "separate Ĉ:Z");
                        s
                    }
                };
                assert_eq!(s1, status(st.error));
                assert_eq!(ff, st.first_failed);
                assert_eq!(c, rc);
                // Single calls: the scalar path, bit for bit.
                let (sa, sc, _) = run::<$t, $d>(Isa::SCALAR, &cs, psd);
                for (i, cse) in cs.iter().enumerate() {
                    let fp: *const $t = cse.f.cols.as_ptr().cast();
                    let zp: *const $t = cse.z.cols.as_ptr().cast();
                    let mut o = [-7.25 as $t; E];
                    let st = unsafe {
                        if psd {
                            ampm::hessian::$psd(cse.mu, fp, zp, o.as_mut_ptr())
                        } else {
                            ampm::$chat(cse.mu, fp, zp, o.as_mut_ptr())
                        }
                    };
                    assert_eq!(st, status(cse.expect), "single {i}");
                    assert_eq!(o[..], sc[i * E..(i + 1) * E], "single Ĉ:Z {i}");
                    let mut o = [-7.25 as $t; E];
                    let st = unsafe { ampm::$ahat(cse.mu, fp, o.as_mut_ptr()) };
                    assert_eq!(st, status(cse.expect_ahat()), "single Â {i}");
                    if st == AmpmStatus::AMPM_OK && cse.expect.is_none() {
                        assert_eq!(o[..], sa[i * E..(i + 1) * E], "single Â {i}");
                    }
                }
            }
        }
    };
}

c_abi_test!(
    c_abi_2d_f32,
    f32,
    2,
    ampm_ahat_chat_z_batch_2d_f32,
    ampm_ahat_batch_2d_f32,
    ampm_chat_z_batch_2d_f32,
    ampm_chat_z_psd_batch_2d_f32,
    ampm_ahat_2d_f32,
    ampm_chat_z_2d_f32,
    ampm_chat_z_psd_2d_f32
);
c_abi_test!(
    c_abi_2d_f64,
    f64,
    2,
    ampm_ahat_chat_z_batch_2d_f64,
    ampm_ahat_batch_2d_f64,
    ampm_chat_z_batch_2d_f64,
    ampm_chat_z_psd_batch_2d_f64,
    ampm_ahat_2d_f64,
    ampm_chat_z_2d_f64,
    ampm_chat_z_psd_2d_f64
);
c_abi_test!(
    c_abi_3d_f32,
    f32,
    3,
    ampm_ahat_chat_z_batch_3d_f32,
    ampm_ahat_batch_3d_f32,
    ampm_chat_z_batch_3d_f32,
    ampm_chat_z_psd_batch_3d_f32,
    ampm_ahat_3d_f32,
    ampm_chat_z_3d_f32,
    ampm_chat_z_psd_3d_f32
);
c_abi_test!(
    c_abi_3d_f64,
    f64,
    3,
    ampm_ahat_chat_z_batch_3d_f64,
    ampm_ahat_batch_3d_f64,
    ampm_chat_z_batch_3d_f64,
    ampm_chat_z_psd_batch_3d_f64,
    ampm_ahat_3d_f64,
    ampm_chat_z_3d_f64,
    ampm_chat_z_psd_3d_f64
);
