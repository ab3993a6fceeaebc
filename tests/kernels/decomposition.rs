//! The default SVD and polar decomposition: backward checks on structured and random inputs,
//! and for f32 the singular values and rotation against nalgebra's SVD in f64.
use super::*;

// ---------------------------------------------------------------------------------------------
// 8. Polar / SVD (default methods).
// ---------------------------------------------------------------------------------------------

/// Rotation-variant SVD and polar reference from nalgebra (f64): sorted `σ`, `U`, `V` made
/// proper by negating their last columns (and `σ_last`) as needed.
fn reference_svd(f: &DMatrix<f64>) -> (DMatrix<f64>, Vec<f64>, DMatrix<f64>) {
    let svd = f.clone().svd(true, true);
    let (mut u, mut vt) = (svd.u.unwrap(), svd.v_t.unwrap());
    let mut s: Vec<f64> = svd.singular_values.iter().copied().collect();
    let n = s.len();
    if u.determinant() < 0.0 {
        u.column_mut(n - 1).neg_mut();
        s[n - 1] = -s[n - 1];
    }
    if vt.determinant() < 0.0 {
        vt.row_mut(n - 1).neg_mut();
        s[n - 1] = -s[n - 1];
    }
    (u, s, vt.transpose())
}

/// `U, V ∈ SO(d)`, `F = UΣVᵀ`, sorted `|σ|`, only the last negative and only when
/// `det F < 0`; `polar` gives `R = UVᵀ` and a symmetric `S` with `F = RS`, `RᵀF` symmetric;
/// for f32, `|σ|` and `R` against nalgebra's SVD in f64.
///
/// Tolerances, with `c_σ` the backward error constant of the module docs: the computed
/// `U, V` are orthonormal and `UΣVᵀ` reproduces `F` to `c_σ ε` (relative to `1` and `‖F‖`),
/// and each `d`-term product the check itself forms adds `≤ d ε` per factor pair, so
/// `‖UᵀU − I‖_F`, `|det U − 1|` (`det(I + E) ≈ 1 + tr E`), `‖RᵀR − I‖`: `(c_σ + 2d) ε`;
/// `‖UΣVᵀ − F‖`, `‖RS − F‖`: `(c_σ + 2d) ε ‖F‖`; `‖S − Sᵀ‖` (rounding of `VΣVᵀ` only):
/// `2d ε ‖F‖`; `‖RᵀF − FᵀR‖` (`R` is exact for `F + δ`, so `RᵀF = S − Rᵀδ`): `(2c_σ + 2d) ε‖F‖`.
/// Forward (f32 only: the f64 reference is exact to `1e-16 κ`): Weyl gives
/// `| |σᵢ| − σᵢ_ref | ≤ c_σ ε ‖F‖₂`, and `‖δR‖ ≤ 2‖δ‖/min_{i<j}(σᵢ+σⱼ)` (module docs) gives
/// `‖R − R_ref‖ ≤ c_σ ε κ`, `κ = 2σ₀/min_{i<j}(σᵢ+σⱼ)` with signed σ (the rotation-variant `R`
/// has its kink at `σᵢ+σⱼ = 0`).
///
/// nalgebra's SVD is not a reference for f64: on this test's inputs it was off by 7 ulps in
/// a singular value and by 6e-12 in `R` (a 3D input with `σ₀ ≈ σ₁`, det < 0) where the
/// kernels agreed with a 50-digit mpmath SVD; the backward checks above bound the f64 error.
pub(super) fn svd_polar<M: Case>() {
    let mut rng = seeded(90 + M::DIM as u64 + 100 * M::Scalar::MANTISSA_DIGITS as u64);
    let mut w = Worst::new::<M>("SVD and polar");
    let e = eps::<M>();
    let d = dim::<M>();
    let n = M::DIM;
    let cs = c_sigma::<M>();
    let forward = M::Scalar::MANTISSA_DIGITS <= 24;
    let mut inputs: Vec<M> = special_matrices::<M>();
    let n_special = inputs.len();
    for i in 0..N {
        let mut f: M = random_f(&mut rng);
        if i % 2 == 1 {
            for r in 0..n {
                f[(r, 0)] = -f[(r, 0)]; // det F < 0
            }
        }
        inputs.push(f);
    }
    let id = DMatrix::<f64>::identity(n, n);
    for (idx, f) in inputs.iter().enumerate() {
        let ctx = (idx, *f);
        let svd = M::svd(f).unwrap();
        let fa = to_na(f);
        let nf = fa.norm();
        let (u, v) = (to_na(&svd.u), to_na(&svd.v));
        let s: Vec<f64> = svd.sigma.as_ref().iter().map(|x| x.to_f64()).collect();
        let tol_orth = (cs + 2.0 * d) * e;
        for (name, q) in [("U", &u), ("V", &v)] {
            let orth = (q.transpose() * q - &id).norm();
            w.check(&format!("{name}ᵀ{name} − I"), orth, tol_orth, &ctx);
            let det_err = (q.determinant() - 1.0).abs();
            w.check(&format!("det {name} − 1"), det_err, tol_orth, &ctx);
        }
        let rec = to_na(&svd.reconstruct());
        w.check("UΣVᵀ − F", (&rec - &fa).norm(), tol_orth * nf, &ctx);
        for i in 1..n {
            assert!(s[i - 1].abs() >= s[i].abs(), "unsorted {s:?} {ctx:?}");
        }
        for (i, x) in s.iter().enumerate().take(n - 1) {
            assert!(*x >= 0.0, "σ{i} = {x} < 0 {ctx:?}");
        }
        let det = fa.determinant();
        // The sign is decided only where it is unambiguous: |det| above its rounding error
        // (`≤ γ_{2d} per(|F|) ≤ 2d ε ‖F‖ᵈ`); exactly singular inputs may give ±0.
        if det.abs() > 2.0 * d * e * nf.powi(n as i32) {
            assert_eq!(
                s[n - 1] < 0.0,
                det < 0.0,
                "sign of σ_last {s:?}, det {det} {ctx:?}"
            );
        }

        let pol = M::polar(f).unwrap();
        assert_eq!(pol.r, svd.rotation(), "polar R ≠ UVᵀ {ctx:?}");
        let (r, st) = (to_na(&pol.r), to_na(&pol.s));
        w.check("RᵀR − I", (r.transpose() * &r - &id).norm(), tol_orth, &ctx);
        w.check("det R − 1", (r.determinant() - 1.0).abs(), tol_orth, &ctx);
        w.check(
            "S − Sᵀ",
            (&st - st.transpose()).norm(),
            2.0 * d * e * nf,
            &ctx,
        );
        w.check("RS − F", (&r * &st - &fa).norm(), tol_orth * nf, &ctx);
        let rtf = r.transpose() * &fa;
        let tol = (2.0 * cs + 2.0 * d) * e * nf;
        w.check("RᵀF − FᵀR", (&rtf - rtf.transpose()).norm(), tol, &ctx);

        if forward {
            let (ur, sr, vr) = reference_svd(&fa);
            for i in 0..n {
                let err = (s[i].abs() - sr[i].abs()).abs();
                w.check("|σ| vs nalgebra", err, cs * e * sr[0], &ctx);
            }
            if idx >= n_special {
                // Random inputs: full rank, min(σᵢ+σⱼ) > 0 with probability 1.
                let pair_min = (0..n)
                    .flat_map(|i| (i + 1..n).map(move |j| (i, j)))
                    .map(|(i, j)| sr[i] + sr[j])
                    .fold(f64::INFINITY, f64::min);
                let kappa = 2.0 * sr[0] / pair_min;
                let r_ref = ur * vr.transpose();
                w.check("R vs nalgebra", (&r - r_ref).norm(), cs * e * kappa, &ctx);
            }
        }
    }
    let nan = M::identity().map(|_| M::Scalar::from_f64(f64::NAN));
    assert_eq!(M::svd(&nan).err(), Some(Error::NonFinite));
    assert_eq!(M::polar(&nan).err(), Some(Error::NonFinite));
    w.report();
}

/// Structured inputs: identity, −I, diagonal (sorted, unsorted, signed), a rotation, equal
/// singular values, rank-deficient, zero.
fn special_matrices<M: Matrix>() -> Vec<M> {
    let n = M::DIM;
    let t = |x: f64| M::Scalar::from_f64(x);
    let diag = |v: &[f64]| {
        let mut m = M::zero();
        for i in 0..n {
            m[(i, i)] = t(v[i]);
        }
        m
    };
    let mut out = vec![
        M::identity(),
        diag(&[-1.0, -1.0, -1.0]),
        diag(&[3.0, 2.0, 1.0]),
        diag(&[1.0, 2.0, 3.0]),
        diag(&[2.0, -3.0, 1.0]),
        diag(&[-2.0, 3.0, 0.5]),
        diag(&[1e-3, 1.0, 1e3]),
        diag(&[1.0, 1.0, 0.0]),
        M::zero(),
    ];
    // Rotation by 0.7 rad in the (0,1) plane, scaled by 2 (all σ equal).
    let mut rot = M::identity();
    let (c, s) = (0.7f64.cos(), 0.7f64.sin());
    rot[(0, 0)] = t(2.0 * c);
    rot[(1, 1)] = t(2.0 * c);
    rot[(1, 0)] = t(2.0 * s);
    rot[(0, 1)] = t(-2.0 * s);
    out.push(rot);
    // Rank one: u vᵀ.
    let mut r1 = M::zero();
    for i in 0..n {
        for j in 0..n {
            r1[(i, j)] = t((i + 1) as f64 * (j as f64 - 0.5));
        }
    }
    out.push(r1);
    // Nearly a reflection (2D: F₀₀ + F₁₁ = 0 exercises the closed form's special branch).
    let mut refl = M::identity();
    refl[(0, 0)] = t(1.5);
    refl[(1, 1)] = t(-1.5);
    refl[(0, 1)] = t(0.5);
    refl[(1, 0)] = t(0.5);
    out.push(refl);
    out
}
