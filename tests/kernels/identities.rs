//! Identities the exact kernels satisfy: `Ĉ` is a Hessian (symmetric), the identities of a
//! scale-invariant energy, rotation invariance on the left and on the right, and `𝓑`
//! (adjointness, the seed's index formula).
use super::*;
use ampm_core::augmented::Kinematics;

// ---------------------------------------------------------------------------------------------
// 2. Symmetry of the Hessian.
// ---------------------------------------------------------------------------------------------

/// `Y:(Ĉ:Z) = Z:(Ĉ:Y)`: `Ĉ` is a Hessian. Each side differs from the exact value by
/// `‖Y‖·k_ker ε κ c_scale ‖Z‖` (kernel) plus the dot product's `d² ε ‖Y‖‖Ĉ:Z‖`.
pub(super) fn hessian_symmetry<M: Case>() {
    let mut rng = seeded(20 + M::DIM as u64 + 100 * M::Scalar::MANTISSA_DIGITS as u64);
    let mut w = Worst::new::<M>("Hessian symmetry");
    let e = eps::<M>();
    let d = dim::<M>();
    for _ in 0..N {
        let f: M = random_f(&mut rng);
        let (y, z): (M, M) = (random_z(&mut rng), random_z(&mut rng));
        let mu = random_mu::<M>(&mut rng);
        let g = geom(&f, mu.to_f64());
        let yz = y.ddot(&M::chat_z(mu, &f, &z).unwrap()).to_f64();
        let zy = z.ddot(&M::chat_z(mu, &f, &y).unwrap()).to_f64();
        let tol = 2.0 * (k_ker::<M>() * g.kappa + d * d) * e * g.chat * fro(&y) * fro(&z);
        w.check("Y:(Ĉ:Z) − Z:(Ĉ:Y)", (yz - zy).abs(), tol, &(f, y, z, mu));
    }
    w.report();
}

// ---------------------------------------------------------------------------------------------
// 3. Identities of a scale-invariant energy.
// ---------------------------------------------------------------------------------------------

/// Scale invariance and its consequences, for random `s ∈ [1/4, 4]` (not a power of two).
///
/// Derivations (a = −1/d):
/// - `Ψ̂(sF) = Ψ̂(F)`: `det(sF) = sᵈ J`, so `(det sF)ᵃ sF = s^{−1} J^a s F = JᵃF`.
/// - `F:Â(F) = 0`: differentiate `Ψ̂(sF) = Ψ̂(F)` in `s` at `s = 1`:
///   `d/ds Ψ̂(sF) = Â(sF):F = 0`.
/// - `Â(sF) = Â(F)/s`: differentiate `Ψ̂(sF) = Ψ̂(F)` in `F`: `s·Â(sF) = Â(F)`.
/// - `Ĉ(F):F = −Â(F)`: differentiate `Â(sF) = Â(F)/s` in `s` at 1; the left side gives
///   `Ĉ(F):F` (`Ĉ:Z` is the derivative of `Â` in direction `Z`), the right `−Â(F)`.
///   (It also follows from the seed's formula: `𝓑:F = Jᵃ(F + a·d·F) = 0` kills the first
///   term, `a(H:F)Â = a·d·Â = −Â`, and `HFᵀH = H` makes the last two cancel.)
/// - `F:(Ĉ(F):F) = −F:Â(F) = 0`.
///
/// Tolerances: `sF` is rounded (`‖ΔF‖ ≤ ε/2‖sF‖`), which moves `Ψ̂`, `Â`, `Ĉ:Z` by at most
/// `ε/2·‖F‖` times the next scale (`a_scale`, `c_scale`, `3 c_scale/σ_min`), measured at `F`
/// (all three are homogeneous of degrees 0, −1, −2, like the quantities compared); the
/// products by `s` and `1/s` are rounded (`ε/2` relative each); the kernels add `k_psi ε M`,
/// `k_ker ε κ scale` per evaluation; a dot product with `F` adds `d² ε ‖F‖·‖·‖`.
pub(super) fn scale_identities<M: Case>() {
    let mut rng = seeded(30 + M::DIM as u64 + 100 * M::Scalar::MANTISSA_DIGITS as u64);
    let mut w = Worst::new::<M>("scale identities");
    let e = eps::<M>();
    let d = dim::<M>();
    let (kp, kk) = (k_psi::<M>(), k_ker::<M>());
    for _ in 0..N {
        let f: M = random_f(&mut rng);
        let z: M = random_z(&mut rng);
        let mu = random_mu::<M>(&mut rng);
        let s = M::Scalar::from_f64(log_uniform(&mut rng, 0.25, 4.0));
        let sf = f * s;
        let g = geom(&f, mu.to_f64());
        let (nf, nz) = (g.f_fro, fro(&z));
        let ctx = (f, z, mu, s);
        let ka = kk * g.kappa;

        let p = M::psi_hat(mu, &f).unwrap().to_f64();
        let ps = M::psi_hat(mu, &sf).unwrap().to_f64();
        let tol = 0.5 * e * nf * g.ahat + 2.0 * kp * e * g.psi;
        w.check("Ψ̂(sF) − Ψ̂(F)", (ps - p).abs(), tol, &ctx);

        let a = M::ahat(mu, &f).unwrap();
        let tol = (ka + d * d) * e * nf * g.ahat;
        w.check("F:Â", f.ddot(&a).to_f64().abs(), tol, &ctx);

        let as_ = M::ahat(mu, &sf).unwrap() * s;
        let tol = 0.5 * e * nf * g.chat + (2.0 * ka + 1.0) * e * g.ahat;
        w.check("s·Â(sF) − Â(F)", dist(&as_, &a), tol, &ctx);

        let s2 = s * s;
        let cs = M::chat_z(mu, &sf, &z).unwrap() * s2;
        let c = M::chat_z(mu, &f, &z).unwrap();
        let tol = (0.5 * e * nf * 3.0 * g.chat / g.smin + (2.0 * ka + 2.0) * e * g.chat) * nz;
        w.check("s²·Ĉ(sF):Z − Ĉ(F):Z", dist(&cs, &c), tol, &ctx);

        let cf = M::chat_z(mu, &f, &f).unwrap();
        let tol = ka * e * (g.chat * nf + g.ahat);
        w.check("Ĉ:F + Â", dist(&(cf + a), &M::zero()), tol, &ctx);

        let tol = (ka + d * d) * e * nf * g.chat * nf;
        w.check("F:(Ĉ:F)", f.ddot(&cf).to_f64().abs(), tol, &ctx);
    }
    w.report();
}

// ---------------------------------------------------------------------------------------------
// 4. Rotation invariance.
// ---------------------------------------------------------------------------------------------

/// `Ψ̂(QF) = Ψ̂(F)`, `Â(QF) = QÂ(F)`, `Ĉ(QF):(QZ) = Q(Ĉ(F):Z)` (differentiate the first
/// in `F` along `δF`: `Â(QF):QδF = Â(F):δF`, then the second along `δF`), and the same on the
/// right for the isotropic `Ψ̂`: `Ψ̂(FQ) = Ψ̂(F)`, `Â(FQ) = Â(F)Q`, `Ĉ(FQ):(ZQ) = (Ĉ(F):Z)Q`.
///
/// Tolerances: `Q` is rounded to the type (`‖Q − Q₀‖_F ≤ √d ε/2` for an exact rotation
/// `Q₀`), and every product with it is a `d`-term dot product per entry (error
/// `≤ γ_d |Q||X|`, `‖|Q|‖₂ ≤ √d`): each product `QX` is within `ρ ε ‖X‖` of `Q₀X`,
/// `ρ = d√d + √d`. A perturbation of `F` by `ρε‖F‖` moves `Ψ̂`, `Â`, `Ĉ:Z` by the next scale
/// times it (`a_scale`, `c_scale`, `3 c_scale/σ_min`); perturbing `Z` or an output by `ρε`
/// relative moves `Ĉ:Z` or `Â` by `ρε` times their scale; plus both kernels' errors.
pub(super) fn rotation_invariance<M: Case>() {
    let mut rng = seeded(40 + M::DIM as u64 + 100 * M::Scalar::MANTISSA_DIGITS as u64);
    let mut w = Worst::new::<M>("rotation invariance");
    let e = eps::<M>();
    let d = dim::<M>();
    let rho = d * d.sqrt() + d.sqrt();
    let (kp, kk) = (k_psi::<M>(), k_ker::<M>());
    for _ in 0..N {
        let f: M = random_f(&mut rng);
        let z: M = random_z(&mut rng);
        let q: M = random_rotation(&mut rng);
        let mu = random_mu::<M>(&mut rng);
        let g = geom(&f, mu.to_f64());
        let (nf, nz) = (g.f_fro, fro(&z));
        let ctx = (f, z, q, mu);
        let ka = kk * g.kappa;
        let p = M::psi_hat(mu, &f).unwrap().to_f64();
        let a = M::ahat(mu, &f).unwrap();
        let c = M::chat_z(mu, &f, &z).unwrap();
        let tol_p = rho * e * nf * g.ahat + 2.0 * kp * e * g.psi;
        let tol_a = rho * e * nf * g.chat + (2.0 * ka + rho) * e * g.ahat;
        let tol_c =
            (rho * e * nf * 3.0 * g.chat / g.smin + (2.0 * ka + 2.0 * rho) * e * g.chat) * nz;
        for side in ["left", "right"] {
            let rot = |x: &M| if side == "left" { q * *x } else { *x * q };
            let fq = rot(&f);
            let pq = M::psi_hat(mu, &fq).unwrap().to_f64();
            w.check(&format!("Ψ̂ ({side})"), (pq - p).abs(), tol_p, &ctx);
            let aq = M::ahat(mu, &fq).unwrap();
            w.check(&format!("Â ({side})"), dist(&aq, &rot(&a)), tol_a, &ctx);
            let cq = M::chat_z(mu, &fq, &rot(&z)).unwrap();
            w.check(&format!("Ĉ:Z ({side})"), dist(&cq, &rot(&c)), tol_c, &ctx);
        }
    }
    w.report();
}

// ---------------------------------------------------------------------------------------------
// 5. 𝓑: adjointness and the seed's index formula.
// ---------------------------------------------------------------------------------------------

/// `Y:(𝓑:Z) = (Y:𝓑):Z`, and both actions against `𝓑_kmij = Jᵃδ_ikδ_jm + aJᵃF_kmH_ij`
/// contracted with explicit loops (`(𝓑:Z)_km = Σ_ij 𝓑_kmij Z_ij`,
/// `(Z:𝓑)_ij = Σ_km Z_km 𝓑_kmij`), with `J` and `H = F⁻ᵀ` from nalgebra's LU in f64.
///
/// Tolerance: the kernels' `H = cof(G)/det G` has relative error `O(ε κ₂)` (module docs),
/// so each action is within `k_ker ε κ₂ b ‖Z‖`; the reference is f64 (same bound at
/// `ε_f64`); a dot product adds `d² ε ‖Y‖ b ‖Z‖`.
pub(super) fn b_operator<M: Case>() {
    let mut rng = seeded(50 + M::DIM as u64 + 100 * M::Scalar::MANTISSA_DIGITS as u64);
    let mut w = Worst::new::<M>("𝓑 adjoint and index formula");
    let e = eps::<M>();
    let n = M::DIM;
    let d = dim::<M>();
    for _ in 0..N {
        let f: M = random_f(&mut rng);
        let (y, z): (M, M) = (random_z(&mut rng), random_z(&mut rng));
        let g = geom(&f, 1.0);
        let (ny, nz) = (fro(&y), fro(&z));
        let ctx = (f, y, z);
        let kin = Kinematics::new(&f).unwrap();
        let bz = kin.b_z(&z).unwrap();
        let yb = kin.z_b(&y).unwrap();
        let lhs = y.ddot(&bz).to_f64();
        let rhs = yb.ddot(&z).to_f64();
        let tol = 2.0 * (k_ker::<M>() * g.kappa2 + d * d) * e * g.b * ny * nz;
        w.check("Y:(𝓑:Z) − (Y:𝓑):Z", (lhs - rhs).abs(), tol, &ctx);

        let fa = to_na(&f);
        let j = fa.determinant();
        let h = fa.clone().try_inverse().unwrap().transpose();
        let a = -1.0 / d;
        let ja = j.powf(a);
        let delta = |p: usize, q: usize| if p == q { 1.0 } else { 0.0 };
        let b4 = |k: usize, m: usize, i: usize, jj: usize| {
            ja * delta(i, k) * delta(jj, m) + a * ja * fa[(k, m)] * h[(i, jj)]
        };
        let (za, ya) = (to_na(&z), to_na(&y));
        let mut bz_ref = DMatrix::zeros(n, n);
        let mut yb_ref = DMatrix::zeros(n, n);
        for k in 0..n {
            for m in 0..n {
                for i in 0..n {
                    for jj in 0..n {
                        bz_ref[(k, m)] += b4(k, m, i, jj) * za[(i, jj)];
                        yb_ref[(i, jj)] += ya[(k, m)] * b4(k, m, i, jj);
                    }
                }
            }
        }
        let tol = 2.0 * k_ker::<M>() * e * g.kappa2 * g.b;
        w.check(
            "𝓑:Z vs index formula",
            (to_na(&bz) - bz_ref).norm(),
            tol * nz,
            &ctx,
        );
        w.check(
            "Y:𝓑 vs index formula",
            (to_na(&yb) - yb_ref).norm(),
            tol * ny,
            &ctx,
        );
    }
    w.report();
}
