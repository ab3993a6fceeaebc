//! APIC: an affine grid velocity is reproduced exactly by G2P (collocated and face grids), and
//! P2G then G2P of one particle recovers its mass, momentum and affine motion.
macro_rules! affine_tests {
    () => {
        /// An affine grid velocity `v(x) = b + A x` is reproduced exactly by G2P:
        /// `v_p = v(x_p)`, `C_p = A`, `∇v_p = A`, on collocated and face grids.
        #[test]
        fn apic_affine_reproduction() {
            let mut r = rng(3);
            let h = 0.25;
            for kernel in [Kernel::Quadratic, Kernel::Cubic] {
                let n = kernel.node_count(D);
                let tol = 8.0 * (n + 2 * D + 4) as f64 * EPS;
                for _ in 0..50 {
                    let x = rand_pos(&mut r, h, 8.0);
                    let a = rand_mat(&mut r, 1.0);
                    let b = rand_pos(&mut r, 1.0, 1.0);
                    let field = |p: [f64; D]| -> [f64; D] {
                        let mut v = [0.0; D];
                        for i in 0..D {
                            v[i] = b[i] as f64;
                            for j in 0..D {
                                v[i] += a.cols[j][i] as f64 * p[j];
                            }
                        }
                        v
                    };
                    // Scale of the values: |b| + |A| |x| ≤ 1 + d·8h.
                    let scale = 1.0 + D as f64 * 8.0 * h;
                    let s = Stencil::<T, D>::new(kernel, Grid::Collocated, h as T, &x).unwrap();
                    let vel: Vec<[T; D]> = s
                        .nodes()
                        .map(|nd| {
                            let p = core::array::from_fn(|c| nd.index[c] as f64 * h);
                            field(p).map(|v| v as T)
                        })
                        .collect();
                    let g = apic::gather(&s, &vel).unwrap();
                    let vp = field(core::array::from_fn(|c| x[c] as f64));
                    for i in 0..D {
                        assert!((g.v[i] as f64 - vp[i]).abs() <= tol * scale);
                        for j in 0..D {
                            let aij = a.cols[j][i] as f64;
                            assert!(
                                (g.affine.cols[j][i] as f64 - aij).abs() <= tol * scale / h,
                                "C"
                            );
                            assert!(
                                (g.grad_v.cols[j][i] as f64 - aij).abs() <= tol * scale / h,
                                "∇v"
                            );
                        }
                    }
                    // MAC: component c on its face grid.
                    for c in 0..D {
                        let s = Stencil::<T, D>::new(kernel, Grid::Face(c), h as T, &x).unwrap();
                        let q: Vec<T> = s
                            .nodes()
                            .map(|nd| {
                                let p = core::array::from_fn(|e| {
                                    (nd.index[e] as f64 + if e == c { 0.0 } else { 0.5 }) * h
                                });
                                field(p)[c] as T
                            })
                            .collect();
                        let g = apic::gather_scalar(&s, &q).unwrap();
                        assert!((g.value as f64 - vp[c]).abs() <= tol * scale);
                        for j in 0..D {
                            let acj = a.cols[j][c] as f64;
                            assert!((g.affine[j] as f64 - acj).abs() <= tol * scale / h);
                            assert!((g.grad[j] as f64 - acj).abs() <= tol * scale / h);
                        }
                    }
                }
            }
        }

        /// P2G then G2P of one particle with an affine velocity field: the node momenta sum
        /// to `m v_p`, the node masses to `m`, and the particle's own affine motion is
        /// recovered from the nodal velocities `p_i/m_i` (exact for APIC: Jiang et al. 2015).
        #[test]
        fn apic_round_trip() {
            let mut r = rng(4);
            let h = 0.5;
            let mat = Material::<T>::elastic(1.0, 1.0);
            for kernel in [Kernel::Quadratic, Kernel::Cubic] {
                let n = kernel.node_count(D);
                let tol = 16.0 * (n + 2 * D + 4) as f64 * EPS;
                let x = rand_pos(&mut r, h, 5.0);
                let mut p = Particle::<T, D>::at_rest(x, 2.0, 0.1);
                p.v = rand_pos(&mut r, 1.0, 1.0);
                p.affine = rand_mat(&mut r, 1.0);
                let out = update::p2g(&mat, kernel, h as T, &p).unwrap();
                let (mut m, mut mv) = (0.0f64, [0.0f64; D]);
                let mut vel = Vec::new();
                for k in 0..n {
                    let nd = out.node(k);
                    m += nd.mass as f64;
                    for a in 0..D {
                        mv[a] += nd.momentum[a] as f64;
                    }
                    vel.push(nd.momentum.map(|q| q / nd.mass));
                    // Undeformed, at rest in F: no stress, no force.
                    assert!(nd.force.iter().all(|f| *f == 0.0));
                }
                assert!((m - 2.0).abs() <= tol * 2.0);
                for a in 0..D {
                    assert!((mv[a] - 2.0 * p.v[a] as f64).abs() <= tol * 4.0);
                }
                let g = apic::gather(&out.stencil, &vel).unwrap();
                for a in 0..D {
                    assert!((g.v[a] - p.v[a]).abs() as f64 <= tol * 4.0);
                }
                assert!((g.affine - p.affine).max_abs() as f64 <= tol * 4.0 / h);
            }
        }
    };
}
