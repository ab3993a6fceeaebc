//! The C entry points (`ampm::hessian`): the same results as core, the statuses, nothing
//! written on error, batch semantics.

/// The C ABI test of one dimension × precision, through the entry points named by the
/// arguments (the helpers of `hessian_tests!` in scope).
macro_rules! c_abi_tests {
    ($d:literal, $n:literal, $psd_z:ident, $psd_z_batch:ident,
     $matrix:ident, $psd_matrix:ident) => {
        /// The C entry points: same results as core, statuses, nothing written on error,
        /// batch semantics.
        #[test]
        fn c_abi() {
            use ampm::hessian::{$matrix, $psd_matrix, $psd_z, $psd_z_batch};
            let mu = T::from_f64(MU);
            let e = energy();
            let mut rng = Pcg64::seed_from_u64(13);
            let ft: M = random_f::<$d>(&mut rng, 0.5, 2.0).cast();
            let z: M = random_z::<$d>(&mut rng).cast();
            let fa = ft.to_array();
            let za = z.to_array();
            let sentinel = T::from_f64(-12345.0);
            // Single action.
            let mut out = [sentinel; $d * $d];
            let st = unsafe { $psd_z(mu, fa.as_ptr(), za.as_ptr(), out.as_mut_ptr()) };
            assert_eq!(st, AmpmStatus::AMPM_OK);
            // The C calls run the lane kernels (bit for bit those of `ampm_core::kernel`,
            // tests/batch/c_abi.rs); `HessianEigensystem` decomposes F̂ and projects with a
            // converged eigen-solve: the two agree to rounding (64ε of the natural scale
            // μ‖F‖²‖Z‖ of Ĉ:Z on this family, σ ∈ [0.5, 2]).
            let close = |a: &M, b: &M, f: &M, z: &M, mu: T| {
                let d = (*a - *b)
                    .to_array()
                    .iter()
                    .map(|x| x.to_f64().powi(2))
                    .sum::<f64>()
                    .sqrt();
                let fs = f.to_array().iter().map(|x| x.to_f64().powi(2)).sum::<f64>();
                let zs = z
                    .to_array()
                    .iter()
                    .map(|x| x.to_f64().powi(2))
                    .sum::<f64>()
                    .sqrt();
                d <= 64.0 * T::EPSILON.to_f64() * mu.to_f64() * (1.0 + fs) * zs.max(1.0)
            };
            assert!(close(
                &M::from_array(&out),
                &hessian::chat_psd_z(&e, &ft, &z).unwrap(),
                &ft,
                &z,
                mu
            ));
            // In place (out aliases Z exactly).
            let mut inplace = za;
            let st = unsafe { $psd_z(mu, fa.as_ptr(), inplace.as_ptr(), inplace.as_mut_ptr()) };
            assert_eq!(st, AmpmStatus::AMPM_OK);
            assert_eq!(inplace, out);
            // Matrices.
            let mut big = [sentinel; $n * $n];
            let st = unsafe { $matrix(mu, fa.as_ptr(), big.as_mut_ptr()) };
            assert_eq!(st, AmpmStatus::AMPM_OK);
            let cw: W = hessian::chat_matrix(&e, &ft).unwrap();
            assert_eq!(
                big.to_vec(),
                cw.cols.iter().flatten().copied().collect::<Vec<_>>()
            );
            let st = unsafe { $psd_matrix(mu, fa.as_ptr(), big.as_mut_ptr()) };
            assert_eq!(st, AmpmStatus::AMPM_OK);
            let pw: W = hessian::chat_psd_matrix(&e, &ft).unwrap();
            assert_eq!(
                big.to_vec(),
                pw.cols.iter().flatten().copied().collect::<Vec<_>>()
            );
            // Errors write nothing.
            let null = core::ptr::null_mut::<T>();
            let mut untouched = [sentinel; $n * $n];
            unsafe {
                assert_eq!(
                    $psd_z(mu, core::ptr::null(), za.as_ptr(), untouched.as_mut_ptr()),
                    AmpmStatus::AMPM_ERR_NULL_POINTER
                );
                assert_eq!(
                    $psd_z(mu, fa.as_ptr(), core::ptr::null(), untouched.as_mut_ptr()),
                    AmpmStatus::AMPM_ERR_NULL_POINTER
                );
                assert_eq!(
                    $psd_z(mu, fa.as_ptr(), za.as_ptr(), null),
                    AmpmStatus::AMPM_ERR_NULL_POINTER
                );
                assert_eq!(
                    $matrix(mu, fa.as_ptr(), null),
                    AmpmStatus::AMPM_ERR_NULL_POINTER
                );
                assert_eq!(
                    $psd_matrix(mu, core::ptr::null(), untouched.as_mut_ptr()),
                    AmpmStatus::AMPM_ERR_NULL_POINTER
                );
                let mut flip = fa;
                // Negating one column flips the sign of det F.
                for i in 0..D {
                    flip[i] = -flip[i];
                }
                assert_eq!(
                    $matrix(mu, flip.as_ptr(), untouched.as_mut_ptr()),
                    AmpmStatus::AMPM_ERR_NON_POSITIVE_J
                );
                assert_eq!(
                    $psd_matrix(T::from_f64(f64::NAN), fa.as_ptr(), untouched.as_mut_ptr()),
                    AmpmStatus::AMPM_ERR_NON_FINITE
                );
                assert_eq!(
                    $psd_z(-mu, fa.as_ptr(), za.as_ptr(), untouched.as_mut_ptr()),
                    AmpmStatus::AMPM_ERR_INVALID_ARGUMENT
                );
            }
            assert!(untouched.iter().all(|&x| x == sentinel));
            // Batch: particle 1 has J < 0, particle 3 a NaN Z; the others are computed.
            let n = 5;
            let mut fs = Vec::new();
            let mut zs = Vec::new();
            let mut mus = Vec::new();
            for i in 0..n {
                let fi: M = random_f::<$d>(&mut rng, 0.5, 2.0).cast();
                let zi: M = random_z::<$d>(&mut rng).cast();
                fs.extend_from_slice(&fi.to_array());
                zs.extend_from_slice(&zi.to_array());
                mus.push(mu * T::from_i32(i as i32 + 1));
            }
            let l = $d * $d;
            // Negating one column of F₁ flips the sign of its determinant.
            for i in 0..D {
                fs[l + i] = -fs[l + i];
            }
            zs[3 * l + 2] = T::from_f64(f64::NAN);
            let mut outs = vec![sentinel; n * l];
            let mut first = usize::MAX;
            let st = unsafe {
                $psd_z_batch(
                    n,
                    mus.as_ptr(),
                    fs.as_ptr(),
                    zs.as_ptr(),
                    outs.as_mut_ptr(),
                    &mut first,
                )
            };
            assert_eq!(st, AmpmStatus::AMPM_ERR_NON_POSITIVE_J);
            assert_eq!(first, 1);
            for i in 0..n {
                let o = &outs[i * l..(i + 1) * l];
                if i == 1 || i == 3 {
                    assert!(
                        o.iter().all(|&x| x == sentinel),
                        "failed particle {i} written"
                    );
                } else {
                    let fi = M::from_array(&fs[i * l..(i + 1) * l].try_into().unwrap());
                    let zi = M::from_array(&zs[i * l..(i + 1) * l].try_into().unwrap());
                    let want = hessian::chat_psd_z(&FixedCorotated::new(mus[i]), &fi, &zi);
                    assert!(
                        close(
                            &M::from_array(&o.try_into().unwrap()),
                            &want.unwrap(),
                            &fi,
                            &zi,
                            mus[i]
                        ),
                        "{i}"
                    );
                }
            }
            // first_failed may be NULL; arrays may be NULL when n = 0; not otherwise.
            unsafe {
                let st = $psd_z_batch(
                    n,
                    mus.as_ptr(),
                    fs.as_ptr(),
                    zs.as_ptr(),
                    outs.as_mut_ptr(),
                    core::ptr::null_mut(),
                );
                assert_eq!(st, AmpmStatus::AMPM_ERR_NON_POSITIVE_J);
                let mut first = usize::MAX;
                let st = $psd_z_batch(
                    0,
                    core::ptr::null(),
                    core::ptr::null(),
                    core::ptr::null(),
                    core::ptr::null_mut(),
                    &mut first,
                );
                assert_eq!((st, first), (AmpmStatus::AMPM_OK, 0));
                let st = $psd_z_batch(
                    n,
                    mus.as_ptr(),
                    core::ptr::null(),
                    zs.as_ptr(),
                    outs.as_mut_ptr(),
                    &mut first,
                );
                assert_eq!(st, AmpmStatus::AMPM_ERR_NULL_POINTER);
            }
        }
    };
}
