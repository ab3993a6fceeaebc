//! Material options: the pressure and the pressure-solve coefficient, latent heat bookkeeping,
//! and what the levels that are off skip.
macro_rules! material_tests {
    () => {
        /// Pressure and the pressure-solve coefficient, with λ = ∞ (`1/λ = 0`).
        #[test]
        fn pressure() {
            let (je, jp, il, dt): (T, T, T, T) = (0.9, 1.25, 0.01, 0.002);
            let p = dilation::pressure(je, jp, il).unwrap() as f64;
            let want = -(0.9f64 - 1.0) / (0.01 * 1.25); // −λ(J_E − 1)/J_P = 8
            assert!((p - want).abs() <= 8.0 * EPS * want.abs(), "{p}");
            let c = dilation::pressure_coefficient(je, jp, il, dt).unwrap() as f64;
            let want = 1.25 * 0.01 / (0.002 * 0.9);
            assert!((c - want).abs() <= 8.0 * EPS * want);
            assert_eq!(dilation::pressure_coefficient(je, jp, 0.0, dt), Ok(0.0));
            assert_eq!(dilation::pressure(je, jp, 0.0), Err(Error::InvalidArgument));
            assert_eq!(dilation::kirchhoff(je, 0.0), Err(Error::InvalidArgument));
            assert_eq!(
                dilation::pressure_coefficient(je, jp, il, 0.0),
                Err(Error::InvalidArgument)
            );
            // Incompressible material: valid with the pressure solve, refused explicit.
            let mut mat = Material::<T> {
                solid: PhaseParams {
                    mu: 1.0,
                    ..PhaseParams::default()
                },
                dilation: Dilation::PressureSolve,
                ..Material::default()
            };
            let part = Particle::<T, D>::at_rest([0.0; D], 1.0, 1.0);
            assert_eq!(update::pressure_coefficient(&mat, &part, dt), Ok(0.0));
            assert!(kirchhoff_stress(&mat, &part).is_ok());
            mat.dilation = Dilation::Explicit;
            assert_eq!(kirchhoff_stress(&mat, &part), Err(Error::InvalidArgument));
        }

        /// Latent heat bookkeeping against values worked out by hand
        /// (c_s = 2, c_l = 4, T_m = 273, L = 100).
        #[test]
        fn latent_heat() {
            let mat = heat_material::<T>(true);
            let heat = mat.heat.unwrap();
            let st = |t: T, u: T, ph| ThermalState {
                temperature: t,
                latent: u,
                phase: ph,
            };
            // Ice at 263 K gets 200 J/kg: 20 warm it to 273, 100 melt it, 80 warm the
            // water by 20 K.
            let (s, q) = absorb(&heat, 2.0, 4.0, &st(263.0, 0.0, Phase::Solid), 200.0).unwrap();
            assert_eq!(s, st(293.0, 100.0, Phase::Liquid));
            assert_eq!(
                q,
                HeatSplit {
                    solid: 20.0,
                    latent: 100.0,
                    liquid: 80.0
                }
            );
            // And back: −200 J/kg returns it to ice at 263 K.
            let (s2, q2) = absorb(&heat, 2.0, 4.0, &s, -200.0).unwrap();
            assert_eq!(s2, st(263.0, 0.0, Phase::Solid));
            assert_eq!(
                q2,
                HeatSplit {
                    solid: -20.0,
                    latent: -100.0,
                    liquid: -80.0
                }
            );
            // Half a melt: temperature held at T_m.
            let (s3, _) = absorb(&heat, 2.0, 4.0, &st(273.0, 0.0, Phase::Solid), 50.0).unwrap();
            assert_eq!(s3, st(273.0, 50.0, Phase::Solid));
            // Invariants refused.
            for bad in [
                st(280.0, 0.0, Phase::Solid),
                st(260.0, 10.0, Phase::Solid),
                st(300.0, 50.0, Phase::Liquid),
                st(273.0, 101.0, Phase::Liquid),
                st(273.0, -1.0, Phase::Solid),
            ] {
                assert_eq!(
                    absorb(&heat, 2.0, 4.0, &bad, 1.0),
                    Err(Error::InvalidArgument)
                );
            }
            // Random heats: q is split exactly (up to the additions' rounding) and the
            // split matches the state change.
            let mut r = rng(8);
            let mut s = st(250.0, 0.0, Phase::Solid);
            for _ in 0..2000 {
                let q: T = r.random_range(-60.0..60.0);
                let (n, sp) = absorb(&heat, 2.0, 4.0, &s, q).unwrap();
                let total = (sp.solid + sp.latent + sp.liquid) as f64;
                assert!((total - q as f64).abs() <= 4.0 * EPS * 300.0, "{total} {q}");
                assert!(
                    (sp.latent as f64 - (n.latent - s.latent) as f64).abs() <= 2.0 * EPS * 100.0
                );
                // m c ΔT per phase: the temperature path through T_m.
                let tm = 273.0f64;
                let (t0, t1) = (s.temperature as f64, n.temperature as f64);
                let sens_s = 2.0 * (t1.min(tm) - t0.min(tm));
                let sens_l = 4.0 * (t1.max(tm) - t0.max(tm));
                assert!(
                    (sp.solid as f64 - sens_s).abs() <= 8.0 * EPS * 600.0,
                    "{sp:?} {sens_s}"
                );
                assert!(
                    (sp.liquid as f64 - sens_l).abs() <= 8.0 * EPS * 1200.0,
                    "{sp:?} {sens_l}"
                );
                s = n;
            }
        }

        /// What is off is skipped: an isothermal scene never reads the temperature (NaN
        /// passes through), an elastic solid never clamps, liquids lose their deviatoric
        /// part, and `μ = 0` needs no decomposition (a liquid's stress is isotropic).
        #[test]
        fn levels_skip() {
            let h: T = 0.5;
            let x = [1.1 as T; D];
            let mut p = Particle::<T, D>::at_rest(x, 1.0, 0.1);
            p.temperature = T::NAN;
            let s = Stencil::<T, D>::new(Kernel::Quadratic, Grid::Collocated, h, &x).unwrap();
            // Grid velocity: a strong stretch along axis 0.
            let vel: Vec<[T; D]> = s
                .nodes()
                .map(|nd| {
                    let mut v = [0.0 as T; D];
                    v[0] = nd.index[0] as T * h * 2.0;
                    v
                })
                .collect();
            let grid = GridSample {
                velocity: &vel,
                temperature: None,
            };
            let el = Material::<T>::elastic(10.0, 10.0);
            let (q, info) = g2p_update(&el, Kernel::Quadratic, h, 0.1, &grid, &p).unwrap();
            assert!(q.temperature.is_nan());
            assert_eq!(info.halvings, 0);
            // F_E = I + 0.2 e₀e₀ᵀ exactly up to rounding, F_P untouched: no clamp.
            assert!((q.f_e.cols[0][0] as f64 - 1.2).abs() <= 64.0 * EPS);
            assert_eq!(q.f_p, M::identity());
            let plastic = Material::<T> {
                plasticity: Some(Snow {
                    critical_compression: 0.025,
                    critical_stretch: 0.0075,
                    hardening: 10.0,
                }),
                ..el
            };
            let (q2, _) = g2p_update(&plastic, Kernel::Quadratic, h, 0.1, &grid, &p).unwrap();
            assert!((q2.f_e.cols[0][0] as f64 - 1.0075).abs() <= 64.0 * EPS);
            let jp = Matrix::det(&q2.f_p) as f64;
            assert!((jp - 1.2 / 1.0075).abs() <= 64.0 * EPS);
            // Heat on without temperatures is refused, the particle left as it was.
            let hm = heat_material::<T>(true);
            assert_eq!(
                g2p_update(&hm, Kernel::Quadratic, h, 0.1, &grid, &p).map(|_| ()),
                Err(Error::InvalidArgument)
            );
        }
    };
}
