//! A property loop over random inputs at extreme scales, for every scalar × dimension
//! (expanded in `main.rs`, one module per pair): every `Ok` passes `check_particle` (and the
//! heat-state and hardening checks), and a second call accepts it; through the grid, P2G
//! accepts what G2P returns.

/// The property tests of one scalar × dimension (`T`, `D`, `M` and `MAX_EXP` of
/// `contract_tests!` in scope).
macro_rules! property_tests {
    () => {
        /// Random inputs at extreme scales (deformation gradients with singular values
        /// over most of the exponent range, velocities and gradients up to near the
        /// overflow threshold, tiny and huge `Δt`, `h`, masses), every material level:
        /// `Ok` ⇒ the result passes every input check and a second call accepts it;
        /// an invalid input is refused with the error `check_particle` gives.
        #[test]
        fn ok_implies_next_call_accepts() {
            let mut r = rng(99);
            let e_mat = 0.9 * (MAX_EXP as f64) / D as f64;
            let e_big = 0.95 * MAX_EXP as f64;
            let mut counts = [0usize; 3];
            for case in 0..20_000 {
                let mat = match case % 5 {
                    0 => Material::<T>::elastic(10.0, 10.0),
                    1 => plastic::<T>(),
                    2 => liquid_material::<T>(),
                    3 => heat_material::<T>(false),
                    _ => heat_material::<T>(true),
                };
                let mut p = Particle::<T, D>::at_rest(
                    core::array::from_fn(|_| log_uniform(&mut r, 20.0)),
                    log_uniform::<T>(&mut r, e_mat).abs(),
                    log_uniform::<T>(&mut r, e_mat).abs(),
                );
                p.phase = if case % 5 == 2 || (case % 5 == 4 && r.random_bool(0.5)) {
                    Phase::Liquid
                } else {
                    Phase::Solid
                };
                let scale = |r: &mut Pcg64, e: f64| -> [f64; D] {
                    core::array::from_fn(|_| 2f64.powf(r.random_range(-e..e)))
                };
                let se = if r.random_bool(0.5) { e_mat } else { 4.0 };
                let sp = if r.random_bool(0.5) { e_mat } else { 4.0 };
                let sig_e = scale(&mut r, se);
                let sig_p = scale(&mut r, sp);
                p.f_e = with_singular_values::<T, D>(&mut r, sig_e);
                p.f_p = with_singular_values::<T, D>(&mut r, sig_p);
                if p.phase == Phase::Liquid && r.random_bool(0.5) {
                    p.f_e = M::identity() * (sig_e[0] as T);
                    p.f_p = M::identity() * (sig_p[0] as T);
                }
                p.v = core::array::from_fn(|_| log_uniform(&mut r, e_big));
                p.affine = M::from_diagonal(core::array::from_fn(|_| log_uniform(&mut r, 10.0)));
                // A valid thermal state (heat on): T_m with a partial buffer, or away.
                if let Some(h) = &mat.heat {
                    let (tm, l) = (h.melting_point, h.latent_heat);
                    match (p.phase, r.random_range(0..3)) {
                        (_, 0) => {
                            p.temperature = tm;
                            p.latent = r.random_range(0.0..1.0) * l;
                        }
                        (Phase::Solid, _) => {
                            p.temperature = tm - log_uniform::<T>(&mut r, 10.0).abs();
                            p.latent = 0.0;
                        }
                        (Phase::Liquid, _) => {
                            p.temperature = tm + log_uniform::<T>(&mut r, 10.0).abs();
                            p.latent = l;
                        }
                    }
                    if !h.phase_change {
                        p.latent = 0.0;
                    }
                }
                let e_s = if r.random_bool(0.3) { e_big } else { 8.0 };
                let mut s = G2pSample::<T, D> {
                    v: core::array::from_fn(|_| log_uniform(&mut r, e_s)),
                    affine: M::ZERO,
                    grad_v: M::ZERO,
                    t_pic: p.temperature + log_uniform::<T>(&mut r, 12.0),
                    t_flip: log_uniform::<T>(&mut r, 12.0),
                };
                for j in 0..D {
                    for i in 0..D {
                        s.affine.cols[j][i] = log_uniform(&mut r, e_s);
                        s.grad_v.cols[j][i] = log_uniform(&mut r, e_s);
                    }
                }
                let dt = log_uniform::<T>(&mut r, 30.0).abs();
                let valid = mat.validate(p.phase).and(check_particle(&p).map(|_| ()));
                match update_particle(&mat, dt, &s, &p) {
                    Ok((q, _)) => {
                        assert_eq!(valid, Ok(()));
                        assert_accepted(&mat, &q, "update_particle");
                        counts[0] += 1;
                    }
                    Err(e) => {
                        if let Err(v) = valid {
                            assert_eq!(e, v);
                            counts[2] += 1;
                        } else {
                            assert!(matches!(e, Error::Overflow | Error::NonPositiveJ), "{e:?}");
                            counts[1] += 1;
                        }
                    }
                }
            }
            println!(
                "{} d={D}: ok {}, refused {}, invalid input {}",
                T::NAME,
                counts[0],
                counts[1],
                counts[2]
            );
            assert!(counts.iter().all(|&c| c > 1000), "{counts:?}");
        }

        /// As above through the grid: random `h` over the exponent range, random node
        /// velocities and temperatures; `Ok` ⇒ accepted, inside the position limit, and
        /// P2G refuses nothing about the state (a liquid's P2G is `Ok` or Overflow).
        #[test]
        fn g2p_ok_implies_p2g_accepts() {
            let mut r = rng(7);
            let mut ok = 0;
            for case in 0..5000 {
                let mat = match case % 4 {
                    0 => Material::<T>::elastic(10.0, 10.0),
                    1 => plastic::<T>(),
                    2 => liquid_material::<T>(),
                    _ => heat_material::<T>(true),
                };
                let kernel = if r.random_bool(0.5) {
                    Kernel::Quadratic
                } else {
                    Kernel::Cubic
                };
                let h = log_uniform::<T>(&mut r, 0.95 * MAX_EXP as f64).abs();
                let x: [T; D] = core::array::from_fn(|_| {
                    let lim = (1u64 << 29) as f64;
                    h * r.random_range(-lim..lim) as T
                });
                let mut p = Particle::<T, D>::at_rest(x, 1.0, 1.0);
                if case % 4 == 2 {
                    p.phase = Phase::Liquid;
                }
                let sigma: [f64; D] =
                    core::array::from_fn(|_| 2f64.powf(r.random_range(-3.0..3.0)));
                p.f_e = with_singular_values::<T, D>(&mut r, sigma);
                if let Some(hh) = &mat.heat {
                    p.temperature = hh.melting_point - 5.0;
                }
                let Ok(st) = Stencil::<T, D>::new(kernel, Grid::Collocated, h, &p.x) else {
                    continue;
                };
                let e_v = if r.random_bool(0.3) {
                    0.9 * MAX_EXP as f64
                } else {
                    6.0
                };
                let vel: Vec<[T; D]> = (0..st.len())
                    .map(|_| core::array::from_fn(|_| log_uniform::<T>(&mut r, e_v) * h))
                    .collect();
                let tn: Vec<T> = (0..st.len())
                    .map(|_| 273.0 + r.random_range(-50.0..50.0) as T)
                    .collect();
                let to: Vec<T> = tn.iter().map(|t| t - 1.0).collect();
                let grid = GridSample {
                    velocity: &vel,
                    temperature: Some((&tn, &to)),
                };
                let dt = log_uniform::<T>(&mut r, 20.0).abs();
                let Ok((q, _)) = g2p_update(&mat, kernel, h, dt, &grid, &p) else {
                    continue;
                };
                ok += 1;
                assert_accepted(&mat, &q, "g2p_update");
                assert_eq!(
                    Stencil::<T, D>::check_position(Grid::Collocated, h, &q.x),
                    Ok(())
                );
                match p2g(&mat, kernel, h, &q) {
                    Ok(out) => {
                        for r in 0..out.stencil.len() {
                            assert!(out.node_checked(r).is_ok());
                        }
                    }
                    Err(Error::Overflow) => {}
                    Err(Error::NonPositiveJ) if q.phase == Phase::Solid => {}
                    Err(e) => panic!("p2g refused a g2p result: {e:?} for {q:?}"),
                }
            }
            assert!(ok > 1000, "{ok}");
        }
    };
}
