//! Regressions, for every scalar × dimension (expanded in `main.rs`, one module per pair): an
//! `F_E` stretched beyond `1/ε` under snow plasticity, a `J_P` or `J_E` that underflows from
//! valid inputs, a tiny finite `h`, P2G and the force differential with finite inputs whose
//! results overflow.

/// The regression tests of one scalar × dimension (`T`, `D`, `M`, the constants and
/// `zero_sample` of `contract_tests!` in scope).
macro_rules! regression_tests {
    () => {
        /// An `F_E` stretched beyond `1/ε` (`F_P = I`) under snow plasticity: the new
        /// `F_P = V diag(σ/σ̂) Vᵀ` is singular to working precision, and its computed
        /// determinant is often ≤ 0. The update refuses those (before, it returned them
        /// with `Ok`), and those whose positive but meaningless `J_P` makes the hardening
        /// overflow; everything it returns is accepted.
        #[test]
        fn ill_conditioned_plastic_flow_is_refused() {
            let mat = plastic::<T>();
            let snow = mat.plasticity.unwrap();
            let mut r = rng(11);
            let (mut bad_raw, mut refused, mut ok) = (0, 0, 0);
            let top = (1.0 / EPS).log10() + 2.0;
            for _ in 0..4000 {
                let big = 10f64.powf(r.random_range(1.0..top));
                let mut sigma = [1.0; D];
                sigma[0] = big;
                sigma[D - 1] = 1.0 / big;
                let mut p = Particle::<T, D>::at_rest([0.3; D], 1.0, 1.0);
                p.f_e = with_singular_values::<T, D>(&mut r, sigma);
                if check_particle(&p).is_err() {
                    continue;
                }
                // The new F_P as snow plasticity forms it, unchecked.
                let svd = DefaultSvd.svd(&p.f_e).unwrap();
                let lo = 1.0 - snow.critical_compression;
                let hi = 1.0 + snow.critical_stretch;
                let ratio = svd.sigma.map(|s| s / s.max(lo).min(hi));
                let raw = svd.v * M::from_diagonal(ratio) * svd.v.transpose();
                let res = update_particle(&mat, 1e-3, &zero_sample(), &p);
                if svd.sigma.iter().any(|&s| s <= 0.0) {
                    // The SVD itself finds F_E singular to working precision (also
                    // refused before).
                    assert_eq!(res.map(|_| ()), Err(Error::NonPositiveJ));
                    continue;
                }
                let raw_ok = raw.is_finite() && Matrix::det(&raw) > 0.0;
                bad_raw += (!raw_ok) as usize;
                match res {
                    Ok((q, _)) => {
                        assert!(raw_ok, "Ok although det F_P = {}", Matrix::det(&raw));
                        assert_accepted(&mat, &q, "plastic");
                        ok += 1;
                    }
                    Err(e) if raw_ok => {
                        // A positive but meaningless J_P (rounding noise of size ε·κ) whose
                        // hardening e^{ξ(1 − J_P)} underflows.
                        assert_eq!(e, Error::Overflow);
                        assert!(mat.moduli(Phase::Solid, Matrix::det(&raw)).is_err());
                        refused += 1;
                    }
                    Err(e) => {
                        assert!(matches!(e, Error::NonPositiveJ | Error::Overflow), "{e:?}");
                        refused += 1;
                    }
                }
            }
            println!(
                "{}: raw det ≤ 0 {bad_raw}, refused {refused}, ok {ok}",
                T::NAME
            );
            assert!(bad_raw > 50 && refused >= bad_raw && ok > 500);
        }

        /// A liquid with an `F_E` and an `F_P` stretched beyond `1/ε` (a solid that melts
        /// after a long plastic history): the projection needs only `det F_E` and
        /// `det F_P`, so the update succeeds with a valid, isotropic state (before, the
        /// whole-`F` rule returned an `F_P` with `det ≤ 0`).
        #[test]
        fn ill_conditioned_liquid_history_is_kept_valid() {
            let mat = Material::<T> {
                liquid: PhaseParams {
                    inv_lambda: 0.1,
                    ..PhaseParams::default()
                },
                ..Material::default()
            };
            let mut r = rng(12);
            let top = (1.0 / EPS).log10() / 2.0 + 1.0;
            let mut n = 0;
            for _ in 0..2000 {
                let mut p = Particle::<T, D>::at_rest([0.3; D], 1.0, 1.0);
                p.phase = Phase::Liquid;
                for f in [&mut p.f_e, &mut p.f_p] {
                    let big = 10f64.powf(r.random_range(1.0..top));
                    let mut sigma = [1.0; D];
                    sigma[0] = big;
                    sigma[D - 1] = 1.0 / big;
                    *f = with_singular_values::<T, D>(&mut r, sigma);
                }
                let Ok((j_e, j_p)) = check_particle(&p) else {
                    continue;
                };
                let (q, _) = update_particle(&mat, 1e-3, &zero_sample(), &p).unwrap();
                assert_accepted(&mat, &q, "liquid");
                assert!(iso(&q.f_e).is_some() && iso(&q.f_p).is_some());
                // J_E, J_P as computed by check_particle: the equilibrated determinant
                // is the same computation scaled by a power of two (nothing under- or
                // overflows here), so only the root (≤ 1 ulp, 2u, times d) and the
                // state's det of r I ((d − 1) roundings) remain: 3d·u.
                for (m, j) in [(q.f_e, j_e), (q.f_p, j_p)] {
                    let tol = (3 * D) as f64 * 0.5 * EPS * j as f64;
                    let got = Matrix::det(&m) as f64;
                    assert!((got - j as f64).abs() <= tol, "{got} vs {j}");
                }
                n += 1;
            }
            assert!(n > 1000, "{n}");
        }

        /// `J_P` that underflows from valid inputs: `F_P = 2^k I` with `J_P` at the
        /// bottom of the normal range, `F_E = c I` with `c ≪ 1 − θ_c`: the plastic flow
        /// multiplies `J_P` by `(c/(1 − θ_c))^d < 2^{−(p+7)}` (`p` mantissa digits),
        /// far below the smallest subnormal. Before, the update returned `det F_P = 0` with `Ok`.
        #[test]
        fn plastic_j_p_underflow_is_refused() {
            let mat = plastic::<T>();
            let k = (1 - MAX_EXP + 1 + D as i32 - 1).div_euclid(D as i32);
            let ke = -(DIGITS + 8 + D as i32 - 1) / D as i32;
            let mut p = Particle::<T, D>::at_rest([0.3; D], 1.0, 1.0);
            p.f_p = M::from_diagonal([(1.0 as T).scalbn(k); D]);
            p.f_e = M::from_diagonal([(1.0 as T).scalbn(ke); D]);
            let (_, j_p) = check_particle(&p).expect("valid input");
            assert!(
                j_p >= T::MIN_POSITIVE && j_p <= (2.0 as T).powi(D as i32 - 1) * T::MIN_POSITIVE
            );
            assert_eq!(
                update_particle(&mat, 1e-3, &zero_sample(), &p).map(|_| ()),
                Err(Error::Overflow)
            );
            // The same through the grid.
            let s = Stencil::<T, D>::new(Kernel::Quadratic, Grid::Collocated, 0.5, &p.x).unwrap();
            let vel = vec![[0.0 as T; D]; s.len()];
            let grid = GridSample {
                velocity: &vel,
                temperature: None,
            };
            assert_eq!(
                g2p_update(&mat, Kernel::Quadratic, 0.5, 1e-3, &grid, &p).map(|_| ()),
                Err(Error::Overflow)
            );
        }

        /// `J_E` that underflows from a valid input: `F_E = 2^k I` with a subnormal
        /// `J_E = 2^{dk}`, compressed by `1/4` per axis, is Overflow (the matrix is fine,
        /// its determinant is not representable), not NonPositiveJ.
        #[test]
        fn j_e_underflow_is_overflow() {
            let k = MIN_SUB_EXP.div_euclid(D as i32) + 1;
            for phase in [Phase::Solid, Phase::Liquid] {
                let mat = if phase == Phase::Solid {
                    Material::<T>::elastic(10.0, 10.0)
                } else {
                    liquid_material::<T>()
                };
                let mut p = Particle::<T, D>::at_rest([0.3; D], 1.0, 1.0);
                p.phase = phase;
                p.f_e = M::from_diagonal([(1.0 as T).scalbn(k); D]);
                let (j_e, _) = check_particle(&p).expect("valid input");
                assert!(j_e > 0.0 && j_e < T::MIN_POSITIVE);
                let mut s = zero_sample();
                s.grad_v = M::from_diagonal([-750.0; D]);
                assert_eq!(
                    update_particle(&mat, 1e-3, &s, &p).map(|_| ()),
                    Err(Error::Overflow)
                );
                let det = deformation::evolve(&p.f_e, &s.grad_v, 1e-3);
                assert_eq!(det.map(|_| ()), Err(Error::Overflow));
            }
            // A singular matrix stays NonPositiveJ.
            let mut f = M::identity();
            f.cols[0] = f.cols[1];
            assert_eq!(check_det(&f), Err(Error::NonPositiveJ));
            assert!(det_equilibrated(&f).0 <= 0.0);
        }

        /// A tiny finite `h`: where `1/h` or `1/(κ h)` is not representable the status is
        /// Overflow; where only `1/(κ h²)` is not, G2P succeeds (it forms `C_p` in cell
        /// units) with the exact `C_p = 0` of a uniform velocity to rounding.
        #[test]
        fn tiny_h_is_overflow() {
            let x = [0.0 as T; D];
            // 1/h = 2^{MAX_EXP + 2}: not representable.
            let h0 = (1.0 as T).scalbn(-MAX_EXP - 2);
            assert!(h0 > 0.0);
            for kernel in [Kernel::Quadratic, Kernel::Cubic] {
                for grid in [Grid::Collocated, Grid::Face(0), Grid::Face(D - 1)] {
                    assert_eq!(
                        Stencil::<T, D>::new(kernel, grid, h0, &x),
                        Err(Error::Overflow)
                    );
                    assert_eq!(
                        Stencil::<T, D>::check_position(grid, h0, &x),
                        Err(Error::Overflow)
                    );
                }
                assert_eq!(apic::inv_moment(kernel, h0), Err(Error::Overflow));
            }
            // The position limit stays InvalidArgument.
            let far = [(1.0 as T).scalbn(31); D];
            assert_eq!(
                Stencil::<T, D>::new(Kernel::Quadratic, Grid::Collocated, 1.0, &far),
                Err(Error::InvalidArgument)
            );

            // 1/h = 2^{MAX_EXP − 1} is finite, 1/(κh) = 2^{MAX_EXP + 1} is not.
            let h1 = (1.0 as T).scalbn(1 - MAX_EXP);
            let s = Stencil::<T, D>::new(Kernel::Quadratic, Grid::Collocated, h1, &x)
                .expect("1/h finite");
            let vel = vec![[1.0 as T; D]; s.len()];
            assert_eq!(apic::gather(&s, &vel), Err(Error::Overflow));
            assert_eq!(
                apic::gather_scalar(&s, &[1.0 as T; 64]),
                Err(Error::Overflow)
            );
            let p = Particle::<T, D>::at_rest(x, 1.0, 1.0);
            let el = Material::<T>::elastic(10.0, 10.0);
            let grid = GridSample {
                velocity: &vel,
                temperature: None,
            };
            assert_eq!(
                g2p_update(&el, Kernel::Quadratic, h1, h1, &grid, &p).map(|_| ()),
                Err(Error::Overflow)
            );

            // h² underflows and 1/(κh²) overflows, 1/(κh) is fine.
            let h2 = (1.0 as T).scalbn(-MAX_EXP / 2 - 4);
            assert_eq!(
                apic::inv_moment(Kernel::Quadratic, h2),
                Err(Error::Overflow)
            );
            let x2 = [h2 * 0.3; D];
            let s = Stencil::<T, D>::new(Kernel::Quadratic, Grid::Collocated, h2, &x2).unwrap();
            let n = s.len();
            let vel = vec![[1.0 as T; D]; n];
            let grid = GridSample {
                velocity: &vel,
                temperature: None,
            };
            let mut p = Particle::<T, D>::at_rest(x2, 1.0, 1.0);
            p.v = [1.0; D];
            let (q, _) = g2p_update(&el, Kernel::Quadratic, h2, h2, &grid, &p)
                .expect("representable result");
            assert_accepted(&el, &q, "tiny h");
            // Σ w_i (o − fx) = 0 exactly; computed: the sum's (n + 2)u and the weights'
            // 4d·u relative errors, times |o − fx| ≤ 2, divided by κ h.
            let bound = (n + 2 + 4 * D) as f64 * EPS / (0.25 * h2 as f64);
            assert!(
                q.affine.max_abs() as f64 <= bound,
                "{:?} > {bound}",
                q.affine
            );

            // ∇v = Σ v_i ∇w_iᵀ of finite velocities overflows: |∇w| ∼ 1/h.
            let h3 = (1.0 as T).scalbn(-60);
            let x3 = [h3 * 0.3; D];
            let s = Stencil::<T, D>::new(Kernel::Quadratic, Grid::Collocated, h3, &x3).unwrap();
            let big = T::MAX.scalbn(-40);
            let vel: Vec<[T; D]> = (0..s.len())
                .map(|r| [if r % 2 == 0 { big } else { -big }; D])
                .collect();
            assert_eq!(apic::gather(&s, &vel).map(|_| ()), Err(Error::Overflow));
            let p = Particle::<T, D>::at_rest(x3, 1.0, 1.0);
            let grid = GridSample {
                velocity: &vel,
                temperature: None,
            };
            assert_eq!(
                g2p_update(&el, Kernel::Quadratic, h3, 1e-3, &grid, &p).map(|_| ()),
                Err(Error::Overflow)
            );
            // A NaN node value stays NonFinite.
            let mut vel = vec![[0.0 as T; D]; s.len()];
            vel[3][0] = T::NAN;
            assert_eq!(apic::gather(&s, &vel).map(|_| ()), Err(Error::NonFinite));
        }

        /// P2G with finite inputs whose node values overflow is Overflow; near the
        /// threshold, where only the cheap bound overflows, the nodes are checked one by
        /// one and P2G succeeds.
        #[test]
        fn p2g_overflow() {
            let el = Material::<T>::elastic(10.0, 10.0);
            let x = [0.3 as T; D];
            let root = T::MAX.sqrt();
            // m |v| > MAX.
            // (The largest quadratic weight here is ≥ 0.59^d ≥ 1/64.)
            let mut p = Particle::<T, D>::at_rest(x, root * 64.0, 1.0);
            p.v[0] = root;
            assert_eq!(
                p2g(&el, Kernel::Quadratic, 0.5, &p).map(|_| ()),
                Err(Error::Overflow)
            );
            // m |v| = MAX/2 and m |C| 2h = 0.52 MAX: the bound overflows, while every
            // node has |v + C (x_i − x_p)| ≤ (0.5 + 0.39) MAX (|x_i − x_p| ≤ 1.5h).
            let mut p = Particle::<T, D>::at_rest(x, 1.0, 1.0);
            p.v[0] = T::MAX * 0.5;
            p.affine.cols[0][0] = T::MAX * 0.26;
            let q = p2g(&el, Kernel::Quadratic, 1.0, &p).expect("every node finite");
            for r in 0..q.stencil.len() {
                assert_eq!(q.node_checked(r), Ok(q.node(r)));
            }
            assert_eq!(q.node_checked(q.stencil.len()), Err(Error::InvalidArgument));
            // Heat: m c and m c T.
            let mut hm = heat_material::<T>(false);
            let mut p = Particle::<T, D>::at_rest(x, 4.0, 1.0);
            p.temperature = 300.0;
            hm.solid.heat_capacity = T::MAX * 0.5;
            assert_eq!(
                p2g(&hm, Kernel::Quadratic, 0.5, &p).map(|_| ()),
                Err(Error::Overflow)
            );
            hm.solid.heat_capacity = root;
            p.mass = 1.0;
            p.temperature = root * 64.0;
            assert_eq!(
                p2g(&hm, Kernel::Quadratic, 0.5, &p).map(|_| ()),
                Err(Error::Overflow)
            );
            // The stress force −V⁰ τ ∇w with |∇w| ∼ 1/h.
            let h = (1.0 as T).scalbn(8 - MAX_EXP);
            let stiff = Material::<T>::elastic(1e4, 1e4);
            let mut p = Particle::<T, D>::at_rest([h * 0.3; D], 1.0, 1.0);
            p.f_e = M::identity() * 1.5;
            assert_eq!(
                p2g(&stiff, Kernel::Quadratic, h, &p).map(|_| ()),
                Err(Error::Overflow)
            );
        }

        /// The force differential of finite inputs: `G = Σ δu ∇wᵀ` or the node forces
        /// overflow → Overflow, and `df` is not written.
        #[test]
        fn force_differential_overflow() {
            let sentinel = -7.25 as T;
            let mat = Material::<T>::elastic(1e3, 1e3);
            let n = Kernel::Quadratic.node_count(D);
            // Node forces ∼ μ δu / h².
            let h = (1.0 as T).scalbn(2 - MAX_EXP / 2);
            let p = Particle::<T, D>::at_rest([h * 0.3; D], 1.0, 1.0);
            let mut r = rng(5);
            let du: Vec<[T; D]> = (0..n)
                .map(|_| core::array::from_fn(|_| r.random_range(-1.0..1.0)))
                .collect();
            let mut df = vec![[sentinel; D]; n];
            assert_eq!(
                force_differential(&mat, Kernel::Quadratic, h, &p, &du, &mut df),
                Err(Error::Overflow)
            );
            assert!(df.iter().flatten().all(|&x| x == sentinel));
            // G itself overflows.
            let du = vec![[T::MAX * 0.5; D]; n];
            let p = Particle::<T, D>::at_rest([0.3; D], 1.0, 1.0);
            assert_eq!(
                force_differential(&mat, Kernel::Quadratic, 0.01, &p, &du, &mut df),
                Err(Error::Overflow)
            );
            assert!(df.iter().flatten().all(|&x| x == sentinel));
            // A NaN δu stays NonFinite; a normal call writes finite values.
            let mut du = vec![[1e-3 as T; D]; n];
            du[2][0] = T::NAN;
            assert_eq!(
                force_differential(&mat, Kernel::Quadratic, 0.5, &p, &du, &mut df),
                Err(Error::NonFinite)
            );
            du[2][0] = 0.0;
            force_differential(&mat, Kernel::Quadratic, 0.5, &p, &du, &mut df).unwrap();
            assert!(df.iter().flatten().all(|x| x.is_finite()));
        }
    };
}
