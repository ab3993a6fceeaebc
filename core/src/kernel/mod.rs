//! The fast kernels of fixed corotated Ψ̂: one source for scalars and SIMD lanes.
//!
//! `Ψ̂(F) = μ Σₖ (σ̂ₖ − 1)²`, `σ̂ = J^{−1/d}σ`, is an isotropic function of the singular values
//! of `F`, so `Â` and `Ĉ` have closed forms in the SVD basis (derivation, conventions and
//! sources in [`crate::hessian`]):
//! - `Â = U diag(ψ) Vᵀ`, `ψⱼ = 2μs(xⱼ − 1 − q/(d xⱼ))`;
//! - `Ĉ:Z = U [K·diag(Z̃) ⊕ pair blocks] Vᵀ`, `Z̃ = UᵀZV`: the `d×d` scaling block `K` acts on
//!   the diagonal of `Z̃`, and each pair `i < j` scales `(Z̃ᵢⱼ + Z̃ⱼᵢ)/2` by `λ_sym` and
//!   `(Z̃ᵢⱼ − Z̃ⱼᵢ)/2` by `λ_skew`;
//! - `Ĉ⁺` clamps the negative eigenvalues (`K` through a small Jacobi eigen-solve).
//!
//! with `s = det(G)^{−1/d}`, `x = sσ`, `q = Σ xₖ(xₖ − 1)`. Everything is computed on
//! `G = 2⁻ᵏF` and scaled at the end (`Â(F) = 2⁻ᵏÂ(G)`, `Ĉ(F) = 2⁻²ᵏĈ(G)`), so no threshold is
//! absolute and `J` is never formed. The general four-term formulas of [`crate::augmented`]
//! (any base energy) compute the same quantities another way; the tests hold each against
//! the other and against the double-double reference.
//!
//! [`evaluate`] is generic over [`Lane`]: the single-particle API runs it on one `f32`/`f64`,
//! the batch entry points of [`batch`] on AVX2 or AVX-512 vectors, with identical bits (see
//! [`crate::lane`]). It has no data-dependent branch; invalid lanes are computed on `F = I`
//! and reported through [`Checks`].

#![allow(clippy::needless_range_loop)]

pub mod batch;
pub(crate) mod chunk;
mod dispatch;
pub mod prepared;

use crate::error::Error;
use crate::lane::lmat::{
    all_finite, c, det, equilibrate_columns, identity, inv_root_exp, jacobi_rotation, mul_diag_nt,
    mul_nt, mul_tn, pow2_factors, recip, scale_pow2, LMat,
};
use crate::lane::Lane;
use crate::polar::lanes::{default_svd, scaled_input, LSvd};
use crate::scalar::Real;

/// The index pairs `i < j` of the SVD basis, in storage order (2D uses the first).
pub const PAIRS: [(usize, usize); 3] = [(0, 1), (0, 2), (1, 2)];

/// Number of pairs `i < j` in dimension `d`.
#[inline(always)]
#[must_use]
pub const fn pairs(d: usize) -> usize {
    d * (d - 1) / 2
}

/// The default decomposition of each dimension, on lanes.
pub trait LaneDim<const D: usize> {
    /// The rotation-variant SVD of a scaled `G` ([`default_svd`]: closed form or one-sided Jacobi
    /// with the precision's default sweeps).
    fn svd<V: Lane>(g: &LMat<V, D>) -> LSvd<V, D>;
    /// Sweeps of the symmetric eigen-solve of the scaling block ([`psd_block`]).
    fn eigen_sweeps<T: Real>() -> u32;
}

/// Dimension marker for [`LaneDim`].
#[derive(Clone, Copy, Debug)]
pub struct Dim<const D: usize>;

impl LaneDim<2> for Dim<2> {
    #[inline(always)]
    fn svd<V: Lane>(g: &LMat<V, 2>) -> LSvd<V, 2> {
        default_svd(g)
    }
    #[inline(always)]
    fn eigen_sweeps<T: Real>() -> u32 {
        // One rotation diagonalises a 2×2 symmetric matrix; a second removes what the Newton
        // iterate of its angle leaves (see `psd_block`).
        2
    }
}

impl LaneDim<3> for Dim<3> {
    #[inline(always)]
    fn svd<V: Lane>(g: &LMat<V, 3>) -> LSvd<V, 3> {
        default_svd(g)
    }
    #[inline(always)]
    fn eigen_sweeps<T: Real>() -> u32 {
        // Cyclic Jacobi on a 3×3 symmetric matrix converges quadratically. Measured: the
        // smallest counts that pass the long-double PSD checks (c_tests/test_hessian_eigen)
        // and tests/hessian/; one fewer fails them.
        if T::MANTISSA_DIGITS <= 24 {
            3
        } else if T::MANTISSA_DIGITS <= 53 {
            4
        } else {
            12
        }
    }
}

/// The per-particle quantities every output is made of, at `G = 2⁻ᵏF`.
#[derive(Clone, Copy, Debug)]
pub struct Coeffs<V, const D: usize> {
    /// Left rotation of the SVD.
    pub u: LMat<V, D>,
    /// Right rotation of the SVD.
    pub v: LMat<V, D>,
    /// The exponent `k` of `F = 2ᵏG` (integer-valued).
    pub k: V,
    /// `ψ = ∂Ψ̂/∂σ` of `G`: `Â(G) = U diag(ψ) Vᵀ`.
    pub psi: [V; D],
    /// `Ψ̂` (scale-free).
    pub energy: V,
    /// The symmetric scaling block `K` of `Ĉ(G)` on `diag(UᵀZV)`.
    pub block: LMat<V, D>,
    /// `λ_sym` of each pair of [`PAIRS`].
    pub sym: [V; 3],
    /// `λ_skew` of each pair of [`PAIRS`].
    pub skew: [V; 3],
    /// The singular values `x = sσ` of `F̂ = Jᵃ F` (1 on liquid and failed lanes).
    pub x: [V; D],
    /// `s = det(G)^{−1/d}`: `x/s` are the singular values of `G = 2⁻ᵏF`.
    pub s: V,
}

/// Lane masks of the input checks, in the order of precedence of their statuses.
#[derive(Clone, Copy, Debug)]
pub struct Checks<M> {
    /// An entry of `F` is NaN or infinite ([`Error::NonFinite`]).
    pub f_non_finite: M,
    /// `J ≤ 0`, or `F` singular to working precision: the determinant of `2⁻ᵏF` with its
    /// columns scaled by powers of two to unit size is below the smallest normal number
    /// ([`Error::NonPositiveJ`]).
    pub j_non_positive: M,
    /// μ is NaN or infinite ([`Error::NonFinite`]).
    pub mu_non_finite: M,
    /// μ < 0 ([`Error::InvalidArgument`]).
    pub mu_negative: M,
    /// μ > 0 and the last singular value is not positive (`F` singular to working precision,
    /// [`Error::NonPositiveJ`]).
    pub singular: M,
}

impl<M: Copy + core::ops::BitOr<Output = M>> Checks<M> {
    /// Any check failed.
    #[inline(always)]
    #[must_use]
    pub fn any(&self) -> M {
        self.f_non_finite
            | self.j_non_positive
            | self.mu_non_finite
            | self.mu_negative
            | self.singular
    }
}

/// The status of lane `l` from check masks given as bit sets (`Lane::mask_bits`), `None` if
/// it passed, in order of precedence.
#[inline]
#[must_use]
pub fn lane_error(bits: &[(u64, Error)], l: usize) -> Option<Error> {
    bits.iter().find(|(b, _)| b >> l & 1 == 1).map(|&(_, e)| e)
}

/// The lanes that any check of `bits` flags (bit `l` for lane `l`): [`lane_error`] is `None`
/// for every other lane, so a caller looks up only these (usually none).
#[inline(always)]
#[must_use]
pub fn flagged(bits: &[(u64, Error)]) -> u64 {
    bits.iter().fold(0u64, |a, (b, _)| a | b)
}

/// `if m { a } else { b }` entry-wise.
#[inline(always)]
#[must_use]
pub fn select_mat<V: Lane, const D: usize>(
    m: V::Mask,
    a: &LMat<V, D>,
    b: &LMat<V, D>,
) -> LMat<V, D> {
    let mut r = *b;
    for j in 0..D {
        for i in 0..D {
            r[j][i] = V::select(m, a[j][i], b[j][i]);
        }
    }
    r
}

/// Decomposes `F` and computes the SVD-basis coefficients of fixed corotated Ψ̂ with shear
/// parameter `μ`, lane-wise, with the checks of each lane.
///
/// Source: [`crate::hessian`] (derivation). Lanes that fail a check are computed on `F = I`,
/// `μ = 0` so that nothing in them is NaN; lanes with `μ = 0` have zero coefficients (a liquid).
#[inline(always)]
#[must_use]
pub fn evaluate<V: Lane, const D: usize>(mu: V, f: &LMat<V, D>) -> (Coeffs<V, D>, Checks<V::Mask>)
where
    Dim<D>: LaneDim<D>,
{
    let zero = c::<V>(0.0);
    let one = c::<V>(1.0);
    let f_ok = all_finite(f);
    let f = select_mat(f_ok, f, &identity());
    let (g, k) = scaled_input(&f);
    // det G on power-of-two-equilibrated columns (exact scaling): `det G = det Ĝ·2^{Σe}`.
    // Below the smallest normal number det Ĝ says `F` is singular to working precision (its
    // Hadamard ratio ∏‖g_j‖/|det G| exceeds 1/MIN_POSITIVE ≫ 1/ε), or `J ≤ 0`.
    let (gh, ce) = equilibrate_columns(&g);
    let det_h = det(&gh);
    let mut sum_e = ce[0];
    for x in ce.iter().skip(1) {
        sum_e += *x;
    }
    let j_ok = V::splat(V::Scalar::MIN_POSITIVE).le(det_h);
    let mu_ok = mu.is_finite();
    let mu_neg = mu.lt(zero);
    let valid = f_ok & j_ok & mu_ok & !mu_neg;
    let mu = V::select(valid, mu, zero);
    let liquid = mu.eq(zero);

    let svd = Dim::<D>::svd(&g);
    let s = inv_root_exp::<V, D>(V::select(j_ok, det_h, one), V::select(j_ok, sum_e, zero));
    let mut sigma = svd.sigma;
    // Where rounding gave the last singular value the wrong sign although det G > 0 (tiny
    // columns whose squares underflow, or F near singular), take it from the determinant:
    // σ_last = det G / (σ₀⋯σ_{d−2}), positive by the check above.
    let mut lead = sigma[0];
    for x in sigma.iter().take(D - 1).skip(1) {
        lead *= *x;
    }
    let [p1, p2, p3] = pow2_factors(sum_e);
    let from_det = det_h / V::select(lead.eq(zero), one, lead) * p1 * p2 * p3;
    sigma[D - 1] = V::select(zero.lt(sigma[D - 1]), sigma[D - 1], from_det);
    let mut x = sigma;
    for xi in &mut x {
        *xi = V::select(liquid, one, s * *xi);
    }
    let singular = !liquid & !zero.lt(sigma[D - 1]);
    // A singular lane continues on x = 1 (no NaN); its status is reported instead.
    for xi in &mut x {
        *xi = V::select(singular, one, *xi);
    }

    let co = coefficients(mu, &svd.u, &svd.v, &x, s, k);
    (
        co,
        Checks {
            f_non_finite: !f_ok,
            j_non_positive: f_ok & !j_ok,
            mu_non_finite: !mu_ok,
            mu_negative: mu_neg,
            singular: singular & valid,
        },
    )
}

/// The SVD-basis coefficients of fixed corotated Ψ̂ from the SVD `U, V` of `G = 2⁻ᵏF`, the
/// singular values `x = sσ` of `F̂ = Jᵃ F` (all positive) and `s = det(G)^{−1/d}`.
///
/// Source: the derivation in [`crate::hessian`]: with `q = Σ xₖ(xₖ − 1)`,
/// `ŵₖ = xₖ(2xₖ − 1)`, `Ŵ = Σŵₖ` and `c = 2μs²`:
/// `ψⱼ = 2μs(xⱼ − 1 − q/(d xⱼ))`,
/// `Kⱼₗ = (c/(xⱼxₗ)) [δⱼₗ (xⱼ² + q/d) − (ŵⱼ + ŵₗ)/d + Ŵ/d²]`,
/// `λ_sym = c (1 + q/(d xᵢxⱼ))`, `λ_skew = c ((xᵢ − 1 + xⱼ − 1)/(xᵢ + xⱼ) − q/(d xᵢxⱼ))`,
/// `Ψ̂ = μ Σ(xₖ − 1)²` — every one free of cancellation at `σᵢ = σⱼ`.
#[inline(always)]
#[must_use]
pub fn coefficients<V: Lane, const D: usize>(
    mu: V,
    u: &LMat<V, D>,
    v: &LMat<V, D>,
    x: &[V; D],
    s: V,
    k: V,
) -> Coeffs<V, D> {
    let zero = c::<V>(0.0);
    let one = c::<V>(1.0);
    let two_mu = mu + mu;
    let cst = two_mu * s * s;
    let mut q = zero;
    let mut w_hat = [zero; D];
    let mut w_sum = zero;
    let mut energy = zero;
    let mut inv_x = [zero; D];
    for i in 0..D {
        q += x[i] * (x[i] - one);
        w_hat[i] = x[i] * (x[i] + x[i] - one);
        w_sum += w_hat[i];
        energy += (x[i] - one) * (x[i] - one);
        inv_x[i] = recip(x[i]);
    }
    let inv_d = c::<V>(1.0 / D as f64);
    let q_d = q * inv_d;
    let w_d2 = w_sum * (inv_d * inv_d);
    let mut psi = [zero; D];
    for i in 0..D {
        psi[i] = two_mu * s * (x[i] - one - q_d * inv_x[i]);
    }
    let mut block = [[zero; D]; D];
    for l in 0..D {
        for j in 0..=l {
            let mut t = w_d2 - (w_hat[j] + w_hat[l]) * inv_d;
            if j == l {
                t += x[j] * x[j] + q_d;
            }
            // Exactly symmetric (the prepared form stores one triangle).
            let k = cst * t * inv_x[j] * inv_x[l];
            block[l][j] = k;
            block[j][l] = k;
        }
    }
    let mut sym = [zero; 3];
    let mut skew = [zero; 3];
    for (p, &(i, j)) in PAIRS.iter().take(pairs(D)).enumerate() {
        let qx = q_d * inv_x[i] * inv_x[j];
        sym[p] = cst * (one + qx);
        skew[p] = cst * (((x[i] - one) + (x[j] - one)) * recip(x[i] + x[j]) - qx);
    }
    Coeffs {
        u: *u,
        v: *v,
        k,
        psi,
        energy: mu * energy,
        block,
        sym,
        skew,
        x: *x,
        s,
    }
}

/// `Â(F) = 2⁻ᵏ U diag(ψ) Vᵀ`.
#[inline(always)]
#[must_use]
pub fn ahat<V: Lane, const D: usize>(co: &Coeffs<V, D>) -> LMat<V, D> {
    scale_pow2(&mul_diag_nt(&co.u, &co.psi, &co.v), -co.k)
}

/// `Ĉ(F):Z` (or `Ĉ⁺(F):Z` with the projected coefficients of [`Coeffs::psd`]).
#[inline(always)]
#[must_use]
pub fn chat_z<V: Lane, const D: usize>(co: &Coeffs<V, D>, z: &LMat<V, D>) -> LMat<V, D> {
    let half = c::<V>(0.5);
    let zt = mul_tn(&co.u, &crate::lane::lmat::mul(z, &co.v));
    let mut r = [[c::<V>(0.0); D]; D];
    for i in 0..D {
        let mut s = co.block[0][i] * zt[0][0];
        for l in 1..D {
            s += co.block[l][i] * zt[l][l];
        }
        r[i][i] = s;
    }
    for (p, &(i, j)) in PAIRS.iter().take(pairs(D)).enumerate() {
        let a = (zt[j][i] + zt[i][j]) * half;
        let b = (zt[j][i] - zt[i][j]) * half;
        let (ls, lk) = (co.sym[p] * a, co.skew[p] * b);
        r[j][i] = ls + lk;
        r[i][j] = ls - lk;
    }
    let out = mul_nt(&crate::lane::lmat::mul(&co.u, &r), &co.v);
    scale_pow2(&out, -(co.k + co.k))
}

impl<V: Lane, const D: usize> Coeffs<V, D> {
    /// The coefficients of `Ĉ⁺`: negative pair eigenvalues clamped to 0, the scaling block
    /// projected by [`psd_block`].
    #[inline(always)]
    #[must_use]
    pub fn psd(&self) -> Self
    where
        Dim<D>: LaneDim<D>,
    {
        let zero = c::<V>(0.0);
        let mut r = *self;
        r.block = psd_block(&self.block, Dim::<D>::eigen_sweeps::<V::Scalar>());
        for p in 0..3 {
            r.sym[p] = self.sym[p].max(zero);
            r.skew[p] = self.skew[p].max(zero);
        }
        r
    }
}

/// `Q diag(max(λ, 0)) Qᵀ` of a symmetric `a = Q diag(λ) Qᵀ`, by `sweeps` sweeps of cyclic
/// Jacobi (Golub & Van Loan, *Matrix Computations*, 4th ed., Alg. 8.5.2) with the rotations
/// of [`jacobi_rotation`] (branch-free; a pair with `a_pq = 0` gets the identity).
#[inline(always)]
#[must_use]
pub fn psd_block<V: Lane, const D: usize>(a0: &LMat<V, D>, sweeps: u32) -> LMat<V, D> {
    let zero = c::<V>(0.0);
    let mut a = *a0;
    let mut q = identity::<V, D>();
    for _ in 0..sweeps {
        for qi in 1..D {
            for p in 0..qi {
                let (app, aqq, apq) = (a[p][p], a[qi][qi], a[qi][p]);
                let (cs, sn) = jacobi_rotation(app, aqq, apq);
                // The pivot block of JᵀAJ from the orthonormal (c, s) (backward stable). The
                // new a_pq is kept, not set to 0: on vectors the rotation angle is a Newton
                // iterate, and what it leaves is removed by the next sweep instead of dropped.
                let two_cs_apq = c::<V>(2.0) * cs * sn * apq;
                a[p][p] = (cs * cs).mul_add(app, (sn * sn).mul_add(aqq, -two_cs_apq));
                a[qi][qi] = (sn * sn).mul_add(app, (cs * cs).mul_add(aqq, two_cs_apq));
                let off = (cs * sn).mul_add(app - aqq, (cs * cs - sn * sn) * apq);
                a[qi][p] = off;
                a[p][qi] = off;
                for r in 0..D {
                    if r != p && r != qi {
                        let (arp, arq) = (a[p][r], a[qi][r]);
                        let np = cs * arp - sn * arq;
                        let nq = sn * arp + cs * arq;
                        a[p][r] = np;
                        a[r][p] = np;
                        a[qi][r] = nq;
                        a[r][qi] = nq;
                    }
                }
                for r in 0..D {
                    let (qp, qq) = (q[p][r], q[qi][r]);
                    q[p][r] = cs * qp - sn * qq;
                    q[qi][r] = sn * qp + cs * qq;
                }
            }
        }
    }
    let mut lam = [zero; D];
    for i in 0..D {
        lam[i] = a[i][i].max(zero);
    }
    let mut out = mul_diag_nt(&q, &lam, &q);
    // Exactly symmetric.
    for j in 1..D {
        for i in 0..j {
            out[i][j] = out[j][i];
        }
    }
    out
}
