//! `Â` and `Ĉ:Z` of the augmented fixed corotated energy on lanes.
//!
//! A transcription, on lane matrices, of [`crate::augmented`] (Kinematics, `Augmented::new`,
//! `ahat`, `chat_z`) and [`crate::energy::FixedCorotated`] (`prepare`, `first_piola`,
//! `hessian_action`, `d_rotation`); the formulas and their sources are documented there:
//! `𝓑:Z = Jᵃ(Z + a(H:Z)F)`, `Z:𝓑 = Jᵃ(Z + a(F:Z)H)`, `Â = A:𝓑`,
//! `Ĉ:Z = (C:(𝓑:Z)):𝓑 + a(H:Z) A:𝓑 + aJᵃ(A:Z)H − aJᵃ(A:F) H Zᵀ H`, `A = 2μ(F̂ − R)`,
//! `C:δF = 2μ(δF − δR)`, all on the power-of-two scaled `G = 2⁻ᵏF`.
//!
//! The same operations run in the same order as the scalar code, and the validation is the
//! same sequence of tests, evaluated as masks for every lane: so each lane's result and status
//! equal those of `augmented::ahat` / `Augmented::chat_z` with the same SVD method (2D:
//! `ClosedForm2`; 3D: `McAdams`), bit for bit (checked by `tests/batch.rs`). Lanes that fail a
//! test still compute (on garbage, harmlessly: no branch depends on a lane's value); their
//! results are discarded by the caller.

#![allow(clippy::needless_range_loop)]

use super::lane::Lane;
use super::lmat::{
    add, ddot, is_finite, mul, scale, scale_exponent, scale_pow2, select, sub, transpose, zero,
    LDim, LMat,
};
use crate::error::Error;
use crate::scalar::Real;

/// Lane-wise outcome of the validation, in the order of the scalar tests.
#[derive(Clone, Copy, Debug)]
pub struct Checks<M> {
    /// `F` finite.
    pub f_finite: M,
    /// `det G > 0` and `G⁻ᵀ`, `det(G)ᵃ`, `F̂` finite (else `NonPositiveJ`).
    pub j_ok: M,
    /// `μ` finite.
    pub mu_finite: M,
    /// `μ ≥ 0` (else `InvalidArgument`).
    pub mu_ok: M,
    /// `Z` finite (always true for `Â`).
    pub z_finite: M,
    /// The result finite (else `Overflow`).
    pub out_finite: M,
}

impl<M: Copy> Checks<M> {
    /// The status of lane `i`, as the scalar kernel would return it.
    #[inline(always)]
    #[must_use]
    pub fn error<S: Lane<Mask = M>>(&self, i: usize) -> Option<Error> {
        let t = |m: M| S::mask_get(m, i);
        if !t(self.f_finite) {
            Some(Error::NonFinite)
        } else if !t(self.j_ok) {
            Some(Error::NonPositiveJ)
        } else if !t(self.mu_finite) {
            Some(Error::NonFinite)
        } else if !t(self.mu_ok) {
            Some(Error::InvalidArgument)
        } else if !t(self.z_finite) {
            Some(Error::NonFinite)
        } else if !t(self.out_finite) {
            Some(Error::Overflow)
        } else {
            None
        }
    }

    /// True when every lane passed every test.
    #[inline(always)]
    #[must_use]
    pub fn all_ok<S: Lane<Mask = M>>(&self, lanes: usize) -> bool
    where
        M: core::ops::BitAnd<Output = M>,
    {
        let ok = self.f_finite
            & self.j_ok
            & self.mu_finite
            & self.mu_ok
            & self.z_finite
            & self.out_finite;
        (0..lanes).all(|i| S::mask_get(ok, i))
    }
}

/// What `Â` and `Ĉ:Z` share at one `F` (lanes): `Kinematics` + `FixedCorotatedState` +
/// `Augmented`'s `A` and `Â(G)`.
struct Prepared<S: Lane, const D: usize>
where
    LMat<S, D>: LDim<S>,
{
    g: LMat<S, D>,
    k: S,
    h_g: LMat<S, D>,
    ja_g: S,
    u: LMat<S, D>,
    sigma: <LMat<S, D> as LDim<S>>::Vector,
    v: LMat<S, D>,
    two_mu: S,
    mu_zero: S::Mask,
    a: LMat<S, D>,
    ahat_g: LMat<S, D>,
    checks: Checks<S::Mask>,
}

/// `a = −1/d` (as `augmented::exponent_a`).
#[inline(always)]
fn exponent_a<S: Lane>(d: usize) -> S {
    S::splat(-S::Scalar::ONE / S::Scalar::from_i32(d as i32))
}

/// `Z:𝓑(G) = Jᵃ(Z + a(G:Z)H)`, unscaled.
#[inline(always)]
fn z_b_g<S: Lane, const D: usize>(p: &Prepared<S, D>, z: &LMat<S, D>) -> LMat<S, D>
where
    LMat<S, D>: LDim<S>,
{
    let a = exponent_a::<S>(D);
    scale(&add(z, &scale(&p.h_g, a * ddot(&p.g, z))), p.ja_g)
}

#[inline(always)]
fn prepare<S: Lane, const D: usize>(mu: S, f: &LMat<S, D>, sweeps: u32) -> Prepared<S, D>
where
    LMat<S, D>: LDim<S>,
{
    let zero_s = S::splat(S::Scalar::ZERO);
    let one = S::splat(S::Scalar::ONE);
    // Kinematics::new
    let f_finite = is_finite(f);
    let k = scale_exponent(f);
    let g = scale_pow2(f, -k);
    let det_g = g.det();
    let h_g = scale(&g.cofactor(), one / det_g);
    let ja_g = <LMat<S, D> as LDim<S>>::inv_root(det_g);
    let f_hat = scale(&g, ja_g);
    let j_ok = zero_s.lt(det_g) & is_finite(&h_g) & ja_g.is_finite() & is_finite(&f_hat);
    // FixedCorotated::prepare (μ = 0 skips the decomposition: A = 0, C = 0).
    let mu_finite = mu.is_finite();
    let mu_ok = zero_s.le(mu);
    let mu_zero = mu.eq(zero_s);
    let (u, sigma, v) = f_hat.svd(sweeps);
    let r = mul(&u, &transpose(&v));
    let two_mu = mu + mu;
    let a = select(mu_zero, &zero(), &scale(&sub(&f_hat, &r), two_mu));
    let mut p = Prepared {
        g,
        k,
        h_g,
        ja_g,
        u,
        sigma,
        v,
        two_mu,
        mu_zero,
        a,
        ahat_g: zero(),
        checks: Checks {
            f_finite,
            j_ok,
            mu_finite,
            mu_ok,
            // All-true masks (`m | !m`); set by `ahat_lanes` / `chat_z_lanes`.
            z_finite: f_finite | !f_finite,
            out_finite: f_finite | !f_finite,
        },
    };
    p.ahat_g = z_b_g(&p, &p.a);
    p
}

/// `Â` of each lane and the lane checks (`Augmented::new` + `ahat`).
#[inline(always)]
#[must_use]
pub fn ahat_lanes<S: Lane, const D: usize>(
    mu: S,
    f: &LMat<S, D>,
    sweeps: u32,
) -> (LMat<S, D>, Checks<S::Mask>)
where
    LMat<S, D>: LDim<S>,
{
    let p = prepare(mu, f, sweeps);
    let out = scale_pow2(&p.ahat_g, -p.k);
    let mut checks = p.checks;
    checks.out_finite = is_finite(&out);
    (out, checks)
}

/// `Ĉ:Z` of each lane and the lane checks (`Augmented::new` + `chat_z`).
#[inline(always)]
#[must_use]
pub fn chat_z_lanes<S: Lane, const D: usize>(
    mu: S,
    f: &LMat<S, D>,
    z: &LMat<S, D>,
    sweeps: u32,
) -> (LMat<S, D>, Checks<S::Mask>)
where
    LMat<S, D>: LDim<S>,
{
    let p = prepare(mu, f, sweeps);
    let a = exponent_a::<S>(D);
    // 𝓑(G):Z
    let bz = scale(&add(z, &scale(&p.g, a * ddot(&p.h_g, z))), p.ja_g);
    // C:(𝓑:Z) = 2μ(δF − δR), δR = U W Vᵀ, W_ij = (Ũ_ij − Ũ_ji)/(σᵢ + σⱼ), Ũ = Uᵀ δF V.
    let ut = mul(&mul(&transpose(&p.u), &bz), &p.v);
    let mut w = zero::<S, D>();
    for j in 1..D {
        for i in 0..j {
            let x = (ut[j][i] - ut[i][j]) / (p.sigma[i] + p.sigma[j]);
            w[j][i] = x;
            w[i][j] = -x;
        }
    }
    let dr = mul(&mul(&p.u, &w), &transpose(&p.v));
    let c_bz = select(p.mu_zero, &zero(), &scale(&sub(&bz, &dr), p.two_mu));
    let t1 = z_b_g(&p, &c_bz);
    let t2 = scale(&p.ahat_g, a * ddot(&p.h_g, z));
    let aj = a * p.ja_g;
    let t3 = scale(&p.h_g, aj * ddot(&p.a, z));
    let t4 = scale(
        &mul(&mul(&p.h_g, &transpose(z)), &p.h_g),
        aj * ddot(&p.a, &p.g),
    );
    let res = sub(&add(&add(&t1, &t2), &t3), &t4);
    let out = scale_pow2(&res, -(p.k + p.k));
    let mut checks = p.checks;
    checks.z_finite = is_finite(z);
    checks.out_finite = is_finite(&out);
    (out, checks)
}
