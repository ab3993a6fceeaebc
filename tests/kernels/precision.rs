//! Precision against independent references: `Â:Z` and `Ĉ:Z` against central differences of
//! `Ψ̂` and `Â` (f64), and the f32 kernels against the f64 kernels on the same (f32) input.
use super::*;

// ---------------------------------------------------------------------------------------------
// 1. Finite differences (f64) and f32 against f64.
// ---------------------------------------------------------------------------------------------

/// `Â:Z` against the central difference of `Ψ̂`, and `Ĉ:Z` against that of `Â` (f64).
///
/// Derivation of the tolerance. `φ(t) = Ψ̂(F + tZ)`, `‖Z‖ = 1`. Central difference:
/// `(φ(h) − φ(−h))/2h = φ'(0) + h²φ'''(ξ)/6`. `Ψ̂` is analytic in a ball of radius `σ_min`
/// around `F` (the nearest singular matrix, where `H` and `Jᵃ` blow up; the polar kink
/// `σᵢ+σⱼ = 0` is farther) and bounded by `M` there, so by the Cauchy estimates its k-th
/// directional derivative is `≲ k!·M/σ_min^k`. Each evaluation carries the rounding error
/// `k_psi·ε·M`, which the quotient divides by `h` (two evaluations over `2h`). With
/// `h = ε^{1/3} σ_min` (the optimum up to a constant, balancing `h²` against `ε/h`):
///   `|fd − Â:Z| ≤ ε^{2/3} (1 + k_psi) M/σ_min`.
/// Same for `Â` one order up: truncation `h²/6 · 4! M/σ_min⁴`, rounding `k_ker ε κ a_scale/h`:
///   `‖fd − Ĉ:Z‖ ≤ ε^{2/3} (4 M/σ_min² + k_ker κ a_scale/σ_min)`.
/// The steps are taken exactly: `F± = fl(F ± hZ)` and the direction is `Z' = (F₊ − F₋)/2h`
/// (each entry's error ≤ ε relative), so the rounding of `F ± hZ` does not enter divided by
/// `h`; the midpoint `(F₊+F₋)/2` is within `ε‖F‖` of `F`, which moves the derivative by at
/// most `ε‖F‖·(next scale)`, added below with the kernel's own `O(ε)` error.
fn fd_check<M: Case<Scalar = f64>>() {
    let mut rng = seeded(1 + M::DIM as u64);
    let mut w_a = Worst::new::<M>("fd: Â:Z vs Ψ̂");
    let mut w_c = Worst::new::<M>("fd: Ĉ:Z vs Â");
    let e = eps::<M>();
    let e23 = e.powf(2.0 / 3.0);
    for _ in 0..N {
        let f: M = random_f(&mut rng);
        let z: M = random_z(&mut rng);
        let mu = random_mu::<M>(&mut rng);
        let g = geom(&f, mu);
        let h = e.powf(1.0 / 3.0) * g.smin;
        let (fp, fm) = (f + z * h, f - z * h);
        let zd = (fp - fm) * (0.5 / h);
        let nz = fro(&zd);

        let fd = (M::psi_hat(mu, &fp).unwrap() - M::psi_hat(mu, &fm).unwrap()) / (2.0 * h);
        let an = M::ahat(mu, &f).unwrap().ddot(&zd);
        let tol = e23 * (1.0 + k_psi::<M>()) * g.psi / g.smin * nz.powi(3)
            + e * (k_ker::<M>() * g.kappa * g.ahat + g.f_fro * g.chat) * nz;
        w_a.check("Â:Z", (fd - an).abs(), tol, &(f, z, mu));

        let fd = (M::ahat(mu, &fp).unwrap() - M::ahat(mu, &fm).unwrap()) * (0.5 / h);
        let an = M::chat_z(mu, &f, &zd).unwrap();
        let s3 = 3.0 * g.chat / g.smin; // third-derivative scale, Cauchy as above
        let tol = e23
            * (4.0 * g.psi / (g.smin * g.smin) * nz.powi(3)
                + k_ker::<M>() * g.kappa * g.ahat / g.smin * nz)
            + e * (k_ker::<M>() * g.kappa * g.chat + g.f_fro * s3) * nz;
        w_c.check("Ĉ:Z", dist(&fd, &an), tol, &(f, z, mu));
    }
    w_a.report();
    w_c.report();
}

/// The f32 kernels against the f64 kernels on the same (f32) input, `ε = ε_f32`.
///
/// The f64 result is exact to `ε_f64 κ` (1e-16 relative at worst here), so the difference is
/// the f32 kernel's own error, bounded (module docs) by `k_psi ε M`, `k_ker ε κ a_scale`,
/// `k_ker ε κ c_scale ‖Z‖`. `𝓑:Z` and `Z:𝓑` involve no decomposition but `H = cof(G)/det G`,
/// whose relative error is `O(ε κ₂)` (`κ₂ = σ_max/σ_min`, the condition of the inverse);
/// `‖𝓑:Z‖ ≤ b‖Z‖` term by term, so they get `k_ker ε κ₂ b ‖Z‖`.
fn f32_vs_f64<M: Case<Scalar = f32>, W: Case<Scalar = f64>>() {
    let mut rng = seeded(10 + M::DIM as u64);
    let mut w = Worst::new::<M>("f32 vs f64");
    let e = eps::<M>();
    for _ in 0..N {
        let f: M = random_f(&mut rng);
        let z: M = random_z(&mut rng);
        let mu = random_mu::<M>(&mut rng);
        let (fw, zw, muw): (W, W, f64) = (cast(&f), cast(&z), mu.to_f64());
        let g = geom(&f, muw);
        let nz = fro(&z);
        let ctx = (f, z, mu);

        let p = M::psi_hat(mu, &f).unwrap().to_f64();
        let pw = W::psi_hat(muw, &fw).unwrap();
        w.check("Ψ̂", (p - pw).abs(), k_psi::<M>() * e * g.psi, &ctx);

        let a: W = cast(&M::ahat(mu, &f).unwrap());
        let aw = W::ahat(muw, &fw).unwrap();
        w.check(
            "Â",
            dist(&a, &aw),
            k_ker::<M>() * e * g.kappa * g.ahat,
            &ctx,
        );

        let c: W = cast(&M::chat_z(mu, &f, &z).unwrap());
        let cw = W::chat_z(muw, &fw, &zw).unwrap();
        let tol = k_ker::<M>() * e * g.kappa * g.chat * nz;
        w.check("Ĉ:Z", dist(&c, &cw), tol, &ctx);

        let tol = k_ker::<M>() * e * g.kappa2 * g.b * nz;
        let bz: W = cast(&augmented::b_z(&f, &z).unwrap());
        w.check(
            "𝓑:Z",
            dist(&bz, &augmented::b_z(&fw, &zw).unwrap()),
            tol,
            &ctx,
        );
        let zb: W = cast(&augmented::z_b(&f, &z).unwrap());
        w.check(
            "Z:𝓑",
            dist(&zb, &augmented::z_b(&fw, &zw).unwrap()),
            tol,
            &ctx,
        );
    }
    w.report();
}

#[test]
fn finite_differences_2d_f64() {
    fd_check::<Mat<f64, 2>>();
}
#[test]
fn finite_differences_3d_f64() {
    fd_check::<Mat<f64, 3>>();
}
#[test]
fn f32_against_f64_2d() {
    f32_vs_f64::<Mat<f32, 2>, Mat<f64, 2>>();
}
#[test]
fn f32_against_f64_3d() {
    f32_vs_f64::<Mat<f32, 3>, Mat<f64, 3>>();
}
