//! The force differential: against central differences of the stress force (and the reusable
//! `Stiffness::d_force_matrix`), and negative semi-definite with the PSD projection.
macro_rules! stiffness_tests {
    () => {
        /// The force differential against central differences of the stress force with
        /// `F_Eᵀ` frozen, as an implicit step linearises it (f64 reference in both types).
        #[test]
        fn force_differential_fd() {
            let mut r = rng(9);
            let h = 0.5;
            for dil in [Dilation::Explicit, Dilation::PressureSolve] {
                let mat = Material::<T> {
                    dilation: dil,
                    ..Material::elastic(3.0, 5.0)
                };
                let mat64 = Material::<f64> {
                    dilation: dil,
                    ..Material::elastic(3.0, 5.0)
                };
                for _ in 0..10 {
                    let x = rand_pos(&mut r, h, 4.0);
                    let mut p = Particle::<T, D>::at_rest(x, 1.0, 0.3);
                    p.f_e = M::identity() + rand_mat(&mut r, 0.2);
                    let s = Stencil::<T, D>::new(Kernel::Quadratic, Grid::Collocated, h as T, &x)
                        .unwrap();
                    let du: Vec<[T; D]> =
                        (0..s.len()).map(|_| rand_pos(&mut r, 1.0, 1.0)).collect();
                    let mut df = vec![[0.0 as T; D]; s.len()];
                    force_differential(&mat, Kernel::Quadratic, h as T, &p, &du, &mut df).unwrap();
                    // Reference: P(F) = τ(F) F⁻ᵀ in f64, δF = G F.
                    let f64m = p.f_e.cast::<f64>();
                    let mut g = Mat::<f64, D>::ZERO;
                    for k in 0..s.len() {
                        let gr = s.node(k).grad.map(|v| v as f64);
                        g += Mat::outer(du[k].map(|v| v as f64), gr);
                    }
                    let piola = |f: Mat<f64, D>| {
                        let mut q = Particle::<f64, D>::at_rest([0.0; D], 1.0, 0.3);
                        q.f_e = f;
                        let tau = kirchhoff_stress(&mat64, &q).unwrap();
                        let h = Matrix::cofactor(&f) * (1.0 / Matrix::det(&f));
                        tau * h
                    };
                    let e = 1e-6;
                    let dp = (piola(f64m + g * f64m * e) - piola(f64m - g * f64m * e)) * (0.5 / e);
                    let dfm = dp * f64m.transpose() * (-0.3);
                    let scale = dfm.max_abs() * 4.0 / h + 1.0;
                    for k in 0..s.len() {
                        let want = dfm.mul_vec(s.node(k).grad.map(|v| v as f64));
                        for a in 0..D {
                            // f64: FD error ~ e²·|Ψ‴| ≈ 1e-10; f32: the kernel's own
                            // rounding, ~1e3 ε (κ(F) ≤ 2, Ĉ has O(10) terms).
                            let tol = (1e-7 + 1e3 * EPS) * scale;
                            assert!((df[k][a] as f64 - want[a]).abs() <= tol, "{df:?} {want:?}");
                        }
                    }
                    // Reusable stiffness gives the same matrix.
                    let en = elastic_energy(&mat, &p).unwrap();
                    let st = Stiffness::new(&en, &mat, &p).unwrap();
                    let m1 = st.d_force_matrix(&g.cast::<T>()).unwrap();
                    let m2 = st
                        .d_force_matrix_with(&g.cast::<T>(), |a, z| a.chat_z(z))
                        .unwrap();
                    assert_eq!(m1, m2);
                }
            }
        }

        /// With the PSD projection (and the dilation in the pressure solve) the operator is
        /// negative semi-definite: `Σ_i δu_i·δf_i = −V⁰ δF:Ĉ⁺:δF ≤ 0` for every `δu`; the
        /// exact `Ĉ` is not (Smith et al. 2019), which some random `δu` shows.
        #[test]
        fn psd_force_differential() {
            let mut r = rng(10);
            let h = 0.5;
            let exact = Material::<T> {
                dilation: Dilation::PressureSolve,
                ..Material::elastic(3.0, 5.0)
            };
            let proj = Material::<T> {
                hessian: Definiteness::Projected,
                ..exact
            };
            let mut positive = 0;
            for _ in 0..200 {
                let x = rand_pos(&mut r, h, 4.0);
                let mut p = Particle::<T, D>::at_rest(x, 1.0, 0.3);
                p.f_e = M::identity() + rand_mat(&mut r, 0.4);
                if Matrix::det(&p.f_e) <= 0.2 {
                    continue;
                }
                let n = Kernel::Quadratic.node_count(D);
                let du: Vec<[T; D]> = (0..n).map(|_| rand_pos(&mut r, 1.0, 1.0)).collect();
                let dot = |m: &Material<T>| {
                    let mut df = vec![[0.0 as T; D]; n];
                    force_differential(m, Kernel::Quadratic, h as T, &p, &du, &mut df).unwrap();
                    let (mut s, mut a) = (0.0f64, 0.0f64);
                    for k in 0..n {
                        for c in 0..D {
                            s += (du[k][c] * df[k][c]) as f64;
                            a += (du[k][c] * df[k][c]).abs() as f64;
                        }
                    }
                    (s, a)
                };
                let (s, a) = dot(&proj);
                // A sum of n·d products: (n·d + 2)ε of their magnitudes, plus the
                // kernel's own rounding of Ĉ⁺ (≈ 32ε·κ, κ ≤ 5 here).
                assert!(s <= (n * D + 2 + 160) as f64 * EPS * a, "δu·δf = {s} > 0");
            }
            // Negative curvature of the exact Ĉ: at F = diag(1.5, 1, 0.7) (U = V = I) the
            // skew ("twist") eigenmatrices eᵢeⱼᵀ − eⱼeᵢᵀ of the closer-to-1 pairs have
            // λ_skew < 0 (crate::hessian docs). δu_k = G (x_k − x_p) gives δF = G F
            // exactly (Σ (x_k − x_p) ∇w_kᵀ = I), so G = Z F⁻¹ probes Z:Ĉ:Z.
            let mut f = M::identity();
            f.cols[0][0] = 1.5;
            f.cols[D - 1][D - 1] = 0.7;
            let mut p = Particle::<T, D>::at_rest([1.3 as T; D], 1.0, 0.3);
            p.f_e = f;
            let s =
                Stencil::<T, D>::new(Kernel::Quadratic, Grid::Collocated, h as T, &p.x).unwrap();
            let finv = Matrix::cofactor(&f).transpose() * (1.0 / Matrix::det(&f));
            for (i, j) in [(0, 1), (0, D - 1), (D - 2, D - 1)] {
                let mut z = M::ZERO;
                z.cols[j][i] = 1.0;
                z.cols[i][j] = -1.0;
                let g = z * finv;
                let du: Vec<[T; D]> = s.nodes().map(|nd| g.mul_vec(nd.dx)).collect();
                let mut df = vec![[0.0 as T; D]; s.len()];
                let mut sum = |m: &Material<T>| {
                    force_differential(m, Kernel::Quadratic, h as T, &p, &du, &mut df).unwrap();
                    du.iter()
                        .zip(&df)
                        .map(|(u, f)| (0..D).map(|c| (u[c] * f[c]) as f64).sum::<f64>())
                        .sum::<f64>()
                };
                positive += (sum(&exact) > 0.0) as usize;
                assert!(sum(&proj) <= 64.0 * EPS, "projected: {}", sum(&proj));
            }
            assert!(positive > 0, "the exact Ĉ showed no negative curvature");
        }
    };
}
