//! The deformation gradient update: the remedy for `det(I + Δt∇v) ≤ 0`, snow plasticity, and
//! the liquid projection.
macro_rules! deformation_gradient_tests {
    () => {
        /// The remedy: `∇v` with `det(I + Δt∇v) < 0` gives `J > 0`; the halvings are the
        /// ones worked out by hand, and `k = 1` is exactly `(I + ½Δt∇v)²`.
        #[test]
        fn remedy() {
            let dt: T = 0.5;
            let id = M::identity();
            // Δt∇v = diag(−3, 0, …): det(I + L) = −2; (I + L/2)² = diag(¼, 1, …), k = 1.
            let mut gv = M::ZERO;
            gv.cols[0][0] = -3.0 / dt;
            let (a, k) = increment(&gv, dt).unwrap();
            assert_eq!(k, 1);
            let half = id + gv * (dt * 0.5);
            assert_eq!(a, half * half);
            assert_eq!(a.cols[0][0], 0.25);
            // Δt∇v = diag(−2, 0, …): k = 1 gives diag(0, …), det 0; k = 2 gives (½)⁴.
            gv.cols[0][0] = -2.0 / dt;
            let (a, k) = increment(&gv, dt).unwrap();
            assert_eq!(k, 2);
            assert_eq!(a.cols[0][0], 0.0625);
            // Random violent ∇v: J > 0 always, and F_E = A F_E exactly as documented.
            let mut r = rng(5);
            let mut hit = 0;
            for _ in 0..2000 {
                let gv = rand_mat(&mut r, 20.0);
                let f = id + rand_mat(&mut r, 0.3);
                if Matrix::det(&f) <= 0.0 {
                    continue;
                }
                let (fnew, k) = evolve(&f, &gv, 0.1).unwrap();
                hit += (k > 0) as usize;
                assert!(Matrix::det(&fnew) > 0.0);
                assert!(fnew.is_finite());
            }
            assert!(hit > 100, "the remedy was exercised {hit} times");
            assert_eq!(increment(&gv, T::NAN), Err(Error::NonFinite));
        }

        /// Snow plasticity: singular values within the clamp, `J = J_E J_P` preserved
        /// (`F_E F_P` unchanged up to rounding), hardening as `e^{ξ(1 − J_P)}`.
        #[test]
        fn snow() {
            let snow = Snow::<T> {
                critical_compression: 0.025,
                critical_stretch: 0.0075,
                hardening: 10.0,
            };
            let mut r = rng(6);
            for _ in 0..200 {
                let fe = M::identity() + rand_mat(&mut r, 0.2);
                let fp = M::identity() + rand_mat(&mut r, 0.1);
                if Matrix::det(&fe) <= 0.0 || Matrix::det(&fp) <= 0.0 {
                    continue;
                }
                let (fe2, fp2) = deformation::snow_plasticity(&snow, &fe, &fp).unwrap();
                let svd = <ampm_core::polar::DefaultSvd as ampm_core::polar::SvdMethod<M>>::svd(
                    &ampm_core::polar::DefaultSvd,
                    &fe2,
                )
                .unwrap();
                for s in svd.sigma {
                    // Reconstruction and re-decomposition: a few ε·κ, κ ≤ 2 here.
                    assert!(s as f64 >= 0.975 - 64.0 * EPS && s as f64 <= 1.0075 + 64.0 * EPS);
                }
                let before = fe * fp;
                let after = fe2 * fp2;
                // Products of O(1) matrices with κ(F) ≤ ~3: 64ε covers the
                // decomposition's backward error times the condition.
                assert!(
                    (before - after).max_abs() as f64 <= 64.0 * EPS,
                    "{before:?} {after:?}"
                );
            }
            let mat = Material::<T> {
                plasticity: Some(snow),
                ..Material::elastic(10.0, 20.0)
            };
            let m = mat.moduli(Phase::Solid, 0.9).unwrap();
            let e = (10.0f64 * 0.1).exp();
            assert!((m.mu as f64 - 10.0 * e).abs() <= 8.0 * EPS * 10.0 * e);
            assert!((m.inv_lambda as f64 - 0.05 / e).abs() <= 8.0 * EPS * 0.05 / e);
        }

        /// Liquid projection: `F_E = J_E^{1/d} I`, `F_P = J_P^{1/d} I`, `J_E` and `J_P`
        /// unchanged, so `J = det F` unchanged (the deviatoric part of `F` is dropped).
        #[test]
        fn liquid() {
            let mut r = rng(7);
            for _ in 0..100 {
                let fe = M::identity() + rand_mat(&mut r, 0.3);
                let fp = M::identity() + rand_mat(&mut r, 0.1);
                if Matrix::det(&fe) <= 0.0 || Matrix::det(&fp) <= 0.0 {
                    continue;
                }
                let (fe2, fp2) = liquid_projection(&fe, &fp).unwrap();
                let je = Matrix::det(&fe) as f64;
                for i in 0..D {
                    for j in 0..D {
                        if i != j {
                            assert_eq!(fe2.cols[j][i], 0.0);
                        } else {
                            assert_eq!(fe2.cols[j][i], fe2.cols[0][0]);
                        }
                    }
                }
                assert!((Matrix::det(&fe2) as f64 - je).abs() <= 16.0 * EPS * je);
                let jp = Matrix::det(&fp) as f64;
                assert!((Matrix::det(&fp2) as f64 - jp).abs() <= 64.0 * EPS * jp);
                for i in 0..D {
                    for j in 0..D {
                        let want = if i == j { fp2.cols[0][0] } else { 0.0 };
                        assert_eq!(fp2.cols[j][i], want);
                    }
                }
                // J = J_E J_P: the two roots (ε each, d·ε in their d-th powers) and the
                // product's d roundings, on top of the J_P bound above.
                let j2 = Matrix::det(&(fe2 * fp2)) as f64;
                assert!((j2 - je * jp).abs() <= (64 + 3 * D) as f64 * EPS * je * jp);
                // A liquid carries no deviatoric stress: τ is a multiple of I.
                let mut p = Particle::<T, D>::at_rest([0.0; D], 1.0, 1.0);
                p.f_e = fe2;
                p.f_p = fp2;
                p.phase = Phase::Liquid;
                let mat = Material::<T> {
                    liquid: PhaseParams {
                        inv_lambda: 0.1,
                        ..PhaseParams::default()
                    },
                    ..Material::default()
                };
                let tau = kirchhoff_stress(&mat, &p).unwrap();
                let iso = tau.trace() / D as T;
                assert!(
                    (tau - M::identity() * iso).max_abs() as f64 <= 8.0 * EPS * iso.abs() as f64
                );
                let k = (je - 1.0) * je / 0.1;
                assert!((iso as f64 - k).abs() <= 64.0 * EPS * (1.0 + k.abs()));
            }
        }
    };
}
