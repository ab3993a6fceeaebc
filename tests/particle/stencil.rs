//! Stencils: partition of unity, linear reproduction, zero-sum gradients, `Σ dx ∇wᵀ = I`, the
//! APIC moment and agreement with an independent f64 B-spline; gradients against central
//! differences; invalid spacings, faces and positions refused.
macro_rules! stencil_tests {
    () => {
        /// Partition of unity, linear reproduction, zero-sum gradients, `Σ dx ∇wᵀ = I`,
        /// the APIC moment, and agreement with the independent f64 B-spline.
        #[test]
        fn stencil_identities() {
            let mut r = rng(1);
            let h = 0.37;
            for kernel in [Kernel::Quadratic, Kernel::Cubic] {
                let n = kernel.node_count(D);
                // n terms of d+1 rounded factors each (see the file header).
                let tol = (n + 2 * D + 4) as f64 * EPS;
                for grid in grids() {
                    for _ in 0..200 {
                        let x = rand_pos(&mut r, h, 1000.0);
                        let s = Stencil::<T, D>::new(kernel, grid, h as T, &x).unwrap();
                        assert_eq!(s.len(), n);
                        let mut sw = 0.0f64;
                        let mut swdx = [0.0f64; D];
                        let mut sg = [0.0f64; D];
                        let mut sdxg = [[0.0f64; D]; D];
                        let mut mom = [[0.0f64; D]; D];
                        for node in s.nodes() {
                            assert!(node.weight >= 0.0);
                            sw += node.weight as f64;
                            for a in 0..D {
                                swdx[a] += (node.weight * node.dx[a]) as f64;
                                sg[a] += node.grad[a] as f64;
                                for b in 0..D {
                                    sdxg[a][b] += (node.dx[a] * node.grad[b]) as f64;
                                    mom[a][b] += (node.weight * node.dx[a] * node.dx[b]) as f64;
                                }
                            }
                            // Independent weight from the node's position. The particle
                            // position x/h − shift carries ε|x/h| of rounding.
                            let mut w = 1.0;
                            for a in 0..D {
                                let shift = match grid {
                                    Grid::Face(f) if f != a => 0.5,
                                    _ => 0.0,
                                };
                                let xi = (node.index[a] as f64 + shift) * h;
                                w *= bspline(kernel, (x[a] as f64 - xi) / h);
                            }
                            let pos_err = 1000.0 * EPS * 4.0;
                            assert!(
                                (w - node.weight as f64).abs() <= tol + pos_err,
                                "{w} {}",
                                node.weight
                            );
                        }
                        assert!(
                            (sw - 1.0).abs() <= tol,
                            "{kernel:?} {grid:?} Σw−1 = {}",
                            sw - 1.0
                        );
                        let kappa = kernel.apic_moment::<f64>();
                        for a in 0..D {
                            assert!(swdx[a].abs() <= 2.0 * tol * h, "Σ w dx = {swdx:?}");
                            assert!(sg[a].abs() <= 4.0 * tol / h, "Σ ∇w = {sg:?}");
                            for b in 0..D {
                                let id = if a == b { 1.0 } else { 0.0 };
                                assert!(
                                    (sdxg[a][b] - id).abs() <= 4.0 * tol,
                                    "Σ dx ∇wᵀ = {sdxg:?}"
                                );
                                assert!(
                                    (mom[a][b] - id * kappa * h * h).abs() <= 4.0 * tol * h * h,
                                    "D_p = {mom:?}"
                                );
                            }
                        }
                    }
                }
            }
        }

        /// Central differences of the weights against the gradients (f64 reference).
        #[test]
        fn stencil_gradients() {
            let mut r = rng(2);
            let h = 0.5;
            for kernel in [Kernel::Quadratic, Kernel::Cubic] {
                for _ in 0..50 {
                    let x = rand_pos(&mut r, h, 10.0);
                    let s = Stencil::<T, D>::new(kernel, Grid::Collocated, h as T, &x).unwrap();
                    for node in s.nodes() {
                        for a in 0..D {
                            let e = 1e-6;
                            let w_at = |dx: f64| {
                                let mut w = 1.0;
                                for b in 0..D {
                                    let xb = x[b] as f64 + if a == b { dx } else { 0.0 };
                                    w *= bspline(kernel, (xb - node.index[b] as f64 * h) / h);
                                }
                                w
                            };
                            let fd = (w_at(e) - w_at(-e)) / (2.0 * e);
                            // FD truncation O(e²·N‴/h³) ≈ 1e-11 plus the kink of the
                            // quadratic at |d| = ½ (one-sided within e): 4e/h².
                            let tol = 200.0 * EPS / h + 4.0 * e / (h * h);
                            assert!(
                                (fd - node.grad[a] as f64).abs() <= tol,
                                "{fd} {:?}",
                                node.grad
                            );
                        }
                    }
                }
            }
        }

        #[test]
        fn stencil_rejects() {
            let x = [0.0 as T; D];
            let q = Kernel::Quadratic;
            assert_eq!(
                Stencil::<T, D>::new(q, Grid::Collocated, 0.0, &x),
                Err(Error::InvalidArgument)
            );
            assert_eq!(
                Stencil::<T, D>::new(q, Grid::Collocated, T::NAN, &x),
                Err(Error::NonFinite)
            );
            assert_eq!(
                Stencil::<T, D>::new(q, Grid::Face(D), 1.0, &x),
                Err(Error::InvalidArgument)
            );
            let mut y = x;
            y[0] = T::INFINITY;
            assert_eq!(
                Stencil::<T, D>::new(q, Grid::Collocated, 1.0, &y),
                Err(Error::NonFinite)
            );
            y[0] = 1e10;
            assert_eq!(
                Stencil::<T, D>::new(q, Grid::Collocated, 1.0, &y),
                Err(Error::InvalidArgument)
            );
        }
    };
}
