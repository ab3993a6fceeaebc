//! Ĉ, Ĉ⁺ and their explicit matrices against the brute-force reference (f64, independent
//! of `ampm_core::hessian`), on every family of `F`: the SVD-basis Hessian equals the
//! generic Ĉ, Ĉ⁺:Z and Ĉ⁺ equal the brute-force projection (Ĉ⁺ symmetric, PSD, the Moreau
//! decomposition), the analytic eigenvalues are the brute-force ones, and the explicit
//! matrices give the actions.

/// The brute-force comparisons of one dimension × precision (the helpers of
/// `hessian_tests!` in scope).
macro_rules! brute_force_tests {
    ($modname:ident, $d:literal, $n:literal) => {
        /// Step 2 of the issue: the SVD-basis Hessian equals the generic Ĉ as matrices.
        #[test]
        fn svd_hessian_matches_generic_chat_z() {
            let mut worst = 0.0f64;
            for (family, moderate, ft, f) in cases() {
                let c_ref = ref_chat_matrix(MU, &f);
                let c: W = hessian::chat_matrix(&energy(), &ft).unwrap();
                let rel = fro(&(wide_to_dmatrix(&c) - &c_ref)) / fro(&c_ref);
                worst = worst.max(rel / (T::EPSILON.to_f64() * kappa(&f)));
                check("Ĉ_mat vs generic", family, moderate, &f, rel);
            }
            eprintln!(
                "{}: max err/(εκ) of Ĉ_mat = {worst:.2}",
                stringify!($modname)
            );
        }

        /// The acceptance test: Ĉ⁺:Z against the brute-force projection.
        #[test]
        fn psd_action_matches_brute_force() {
            let mut rng = Pcg64::seed_from_u64(7);
            let mut worst = 0.0f64;
            let mut worst_moderate = 0.0f64;
            for (family, moderate, ft, f) in cases() {
                let c_ref = ref_chat_matrix(MU, &f);
                let p_ref = ref_psd(&c_ref);
                for _ in 0..4 {
                    let z: M = random_z::<$d>(&mut rng).cast();
                    let zv = vec_of(&z);
                    let got = hessian::chat_psd_z(&energy(), &ft, &z).unwrap();
                    let want = &p_ref * &zv;
                    let rel = (vec_of(&got) - want).norm() / (fro(&c_ref) * zv.norm());
                    worst = worst.max(rel / (T::EPSILON.to_f64() * kappa(&f)));
                    if moderate {
                        worst_moderate = worst_moderate.max(rel);
                    }
                    check("Ĉ⁺:Z vs brute force", family, moderate, &f, rel);
                }
            }
            eprintln!(
                "{}: max err/(εκ) of Ĉ⁺:Z = {worst:.2}; max rel err (moderate) = \
                 {worst_moderate:e}",
                stringify!($modname)
            );
        }

        /// Ĉ⁺ is symmetric, PSD, the brute-force projection, and the Moreau decomposition
        /// `Ĉ = Ĉ⁺ − Ĉ⁻`, `Ĉ⁻ ⪰ 0`, `Ĉ⁺Ĉ⁻ = 0` holds: Ĉ⁺ is exactly Ĉ restricted to its
        /// positive eigenspace (this characterisation is unique).
        #[test]
        fn psd_matrix_is_the_projection() {
            for (family, moderate, ft, f) in cases() {
                let c_ref = ref_chat_matrix(MU, &f);
                let n = fro(&c_ref);
                let pw: W = hessian::chat_psd_matrix(&energy(), &ft).unwrap();
                for p in 0..$n {
                    for q in 0..$n {
                        assert_eq!(pw.cols[q][p], pw.cols[p][q], "Ĉ⁺ not symmetric");
                    }
                }
                let p = wide_to_dmatrix(&pw);
                let rel = fro(&(&p - ref_psd(&c_ref))) / n;
                check("Ĉ⁺_mat vs brute force", family, moderate, &f, rel);
                let tol = tol(&f) * n;
                let (min_p, _) = min_max_eig(&p);
                assert!(min_p >= -tol, "[{family}] Ĉ⁺ not PSD: {min_p:e}");
                let cw: W = hessian::chat_matrix(&energy(), &ft).unwrap();
                let c = wide_to_dmatrix(&cw);
                let minus = &p - &c;
                let (min_m, _) = min_max_eig(&minus);
                assert!(min_m >= -tol, "[{family}] Ĉ⁻ not PSD: {min_m:e}");
                // Normalised by ‖Ĉ‖ (so no product under- or overflows): with Ĉ⁺, Ĉ⁻ each
                // within tol of the exact pair, ‖Ĉ⁺Ĉ⁻‖ ≤ ‖Ĉ⁺‖‖ΔĈ⁻‖ + ‖ΔĈ⁺‖‖Ĉ⁻‖ ≤ 2·tol.
                let cross = fro(&((&p / n) * (&minus / n)));
                assert!(cross <= 2.0 * tol / n, "[{family}] Ĉ⁺Ĉ⁻ ≠ 0: {cross:e}");
            }
        }

        /// The analytic eigenvalues (Jacobi on the scaling block + closed-form pairs) are
        /// those of the brute-force matrix (Weyl: each moves by at most ‖ΔĈ‖₂).
        #[test]
        fn eigenvalues_match_brute_force() {
            for (family, _, ft, f) in cases() {
                let c_ref = ref_chat_matrix(MU, &f);
                let want = sorted_eigenvalues(&c_ref);
                let es = HessianEigensystem::new(&energy(), &ft).unwrap();
                let mut got: Vec<f64> = es
                    .eigenvalues()
                    .unwrap()
                    .iter()
                    .map(|x| x.to_f64())
                    .collect();
                got.sort_by(|a, b| a.total_cmp(b));
                let tol = tol(&f) * fro(&c_ref);
                for (g, w) in got.iter().zip(&want) {
                    assert!((g - w).abs() <= tol, "[{family}] eig {g:e} vs {w:e}");
                }
                // The projected system's eigenvalues are the clamped ones.
                let mut gp: Vec<f64> = es
                    .psd()
                    .unwrap()
                    .eigenvalues()
                    .unwrap()
                    .iter()
                    .map(|x| x.to_f64())
                    .collect();
                gp.sort_by(|a, b| a.total_cmp(b));
                for (g, w) in gp.iter().zip(&want) {
                    assert!((g - w.max(0.0)).abs() <= tol, "[{family}] psd eig");
                }
            }
        }

        /// `vec(Ĉ:Z) = Ĉ_mat · vec(Z)`, for Ĉ (against the generic `chat_z`, same
        /// precision) and Ĉ⁺ (against `chat_psd_z`).
        #[test]
        fn explicit_matrix_matches_action() {
            let mut rng = Pcg64::seed_from_u64(11);
            for (family, moderate, ft, f) in cases() {
                let e = energy();
                let c = wide_to_dmatrix::<T, $n>(&hessian::chat_matrix(&e, &ft).unwrap());
                let p = wide_to_dmatrix::<T, $n>(&hessian::chat_psd_matrix(&e, &ft).unwrap());
                let aug = Augmented::new(&e, &ft).unwrap();
                let es = HessianEigensystem::new(&e, &ft).unwrap();
                let n = fro(&c);
                for _ in 0..3 {
                    let z: M = random_z::<$d>(&mut rng).cast();
                    let zv = vec_of(&z);
                    let cz = vec_of(&aug.chat_z(&z).unwrap());
                    let rel = (&c * &zv - &cz).norm() / (n * zv.norm());
                    check("Ĉ_mat·z vs chat_z", family, moderate, &f, rel);
                    let ez = vec_of(&es.apply(&z).unwrap());
                    let rel = (&c * &zv - &ez).norm() / (n * zv.norm());
                    check("Ĉ_mat·z vs eigensystem", family, moderate, &f, rel);
                    let pz = vec_of(&hessian::chat_psd_z(&e, &ft, &z).unwrap());
                    let rel = (&p * &zv - &pz).norm() / (n * zv.norm());
                    check("Ĉ⁺_mat·z vs Ĉ⁺:Z", family, moderate, &f, rel);
                }
            }
        }
    };
}
