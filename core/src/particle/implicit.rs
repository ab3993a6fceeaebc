//! The force differential of an implicit step in the rotated basis of `F_E`: prepared once per
//! Newton step, applied once per Krylov iteration with a few dozen multiply-adds.
//!
//! **Derivation.** A particle's node forces are `f_i = −V⁰ P(F) F_Eᵀ ∇w_i` with `F = (I + G) F_E`,
//! `G = Σ_j u_j ∇w_jᵀ` for node displacements `u_j` (Stomakhin et al. 2013, eq. 6–7). So
//! `δf_i = M ∇w_i` with `M = 𝒜(G) = −V⁰ (∂²Ψ/∂F²:(G F_E)) F_Eᵀ`, a linear map of `G` that is
//! symmetric (it is `−V⁰ ∂²Ψ((I + G)F_E)/∂G²`), and `Ψ = Ψ̂_μ + Ψ_λ`.
//!
//! With `F_E = U Σ Vᵀ` and `Ĝ = Uᵀ G U`: `Uᵀ (G F_E) V = Ĝ Σ` and
//! `Uᵀ (Z F_Eᵀ) U = (Uᵀ Z V) Σ`. The Hessian of the augmented fixed corotated energy is block
//! diagonal on `Uᵀ δF V` ([`crate::hessian`]): the scaling block `K` on the diagonal, and per pair
//! `i < j` the eigenvalues `λ_sym`, `λ_skew` on `(δF̂_ij ± δF̂_ji)/√2`. Hence `𝒜` is block
//! diagonal on `Ĝ` too:
//! - diagonal `(Ĝ_11, …, Ĝ_dd)`: `H_il = σ_i K_il σ_l + α + β δ_il`;
//! - pair `(Ĝ_ij, Ĝ_ji)`: `[[p σ_j², q σ_iσ_j + β], [q σ_iσ_j + β, p σ_i²]]` with
//!   `p = (λ_sym + λ_skew)/2`, `q = (λ_sym − λ_skew)/2`;
//!
//! and `M = U (−V⁰ H(Ĝ)) Uᵀ`. The dilational terms come from `δP_λ F_Eᵀ = λ J ((2J − 1) tr(G) I −
//! (J − 1) Gᵀ)` ([`super::dilation`]), which commutes with `Ĝ = Uᵀ G U`: `α = λ J (2J − 1)` on
//! `tr(Ĝ) I` and `β = −λ J (J − 1)` on `Ĝᵀ`; both are 0 when the dilation is left to the
//! pressure solve. Singular values are those of `G = 2⁻ᵏF_E` and the coefficients those of
//! [`crate::kernel::evaluate`] at that scale: the powers of two cancel in `M`.
//!
//! **Definiteness.** Because the blocks are invariant subspaces, projecting each block onto its
//! non-negative eigenvalues projects the whole differential, dilational part included: with
//! [`crate::particle::Definiteness::Projected`] `−𝒜` is positive semi-definite, so the
//! backward-Euler matrix `M_grid − Δt² K` is positive definite and CG applies.
//!
//! **Slot** ([`slot_len`] scalars: 11 in 2D, 25 in 3D): the tag [`tag`] (0 after a failed
//! prepare), `U` column-major, the diagonal block `−V⁰H` (upper triangle column by column), then
//! per pair ([`crate::kernel::PAIRS`] order) `(a, b, c)` of `−V⁰ [[a, b], [b, c]]`.

use crate::kernel::{pairs, psd_block, Coeffs, Dim, LaneDim, PAIRS};
use crate::lane::lmat::{c, mul, mul_nt, mul_tn, LMat};
use crate::lane::Lane;
use crate::mat::Mat;
use crate::scalar::Real;

/// Scalars of one particle's slot: `1 + d² + d(d+1)/2 + 3·d(d−1)/2`.
#[inline]
#[must_use]
pub const fn slot_len(d: usize) -> usize {
    1 + d * d + d * (d + 1) / 2 + 3 * pairs(d)
}

/// The tag of a valid slot: `−(1 + d/8)·2⁻⁹⁸`, exact in f32 and f64, distinct from the Hessian
/// slots of [`crate::kernel::prepared`] so that one is never applied as the other.
#[inline]
#[must_use]
pub fn tag<T: Real>(d: usize) -> T {
    T::from_f64(-(1.0 + d as f64 / 8.0) * 3.155_443_620_884_047e-30)
}

/// The prepared differential of one particle (lanes or scalars).
#[derive(Clone, Copy, Debug)]
pub struct Blocks<V, const D: usize> {
    /// `U` of `F_E = U Σ Vᵀ`.
    pub u: LMat<V, D>,
    /// `−V⁰ H` on the diagonal of `Ĝ` (symmetric).
    pub diag: LMat<V, D>,
    /// `−V⁰ (a, b, c)` of each pair block.
    pub pair: [[V; 3]; 3],
}

/// `max(0, ·)` projection of a symmetric 2×2 `[[a, b], [b, c]]`, branch-free: with eigenvalues
/// `λ₋ ≤ λ₊`, the matrix if `λ₋ ≥ 0`, zero if `λ₊ ≤ 0`, else `λ₊ (A − λ₋ I)/(λ₊ − λ₋)`.
#[inline(always)]
#[must_use]
pub fn psd_2x2<V: Lane>(a: V, b: V, cc: V) -> [V; 3] {
    let zero = c::<V>(0.0);
    let half = c::<V>(0.5);
    let m = (a + cc) * half;
    let h = (a - cc) * half;
    let r = (h * h + b * b).sqrt();
    let (lp, lm) = (m + r, m - r);
    let mixed = zero.lt(lp) & lm.lt(zero);
    let f = lp / V::select(mixed, r + r, c::<V>(1.0));
    let pa = V::select(mixed, f * (a - lm), a);
    let pb = V::select(mixed, f * b, b);
    let pc = V::select(mixed, f * (cc - lm), cc);
    let none = !zero.lt(lp);
    [
        V::select(none, zero, pa),
        V::select(none, zero, pb),
        V::select(none, zero, pc),
    ]
}

/// The blocks of a particle from the coefficients of [`crate::kernel::evaluate`] (zero for a
/// liquid), the dilational `α`, `β` and `−V⁰`; projected when `psd`.
#[inline(always)]
#[must_use]
pub fn blocks<V: Lane, const D: usize>(
    co: &Coeffs<V, D>,
    alpha: V,
    beta: V,
    neg_vol: V,
    psd: bool,
) -> Blocks<V, D>
where
    Dim<D>: LaneDim<D>,
{
    let zero = c::<V>(0.0);
    let inv_s = c::<V>(1.0) / co.s;
    let mut sg = [zero; D];
    for i in 0..D {
        sg[i] = co.x[i] * inv_s;
    }
    let mut h = [[zero; D]; D];
    for l in 0..D {
        for i in 0..D {
            let mut t = sg[i] * co.block[l][i] * sg[l] + alpha;
            if i == l {
                t += beta;
            }
            h[l][i] = t;
        }
    }
    if psd {
        h = psd_block(&h, Dim::<D>::eigen_sweeps::<V::Scalar>());
    }
    let mut diag = [[zero; D]; D];
    for l in 0..D {
        for i in 0..D {
            diag[l][i] = neg_vol * h[l][i];
        }
    }
    let mut pair = [[zero; 3]; 3];
    let half = c::<V>(0.5);
    for (p, &(i, j)) in PAIRS.iter().take(pairs(D)).enumerate() {
        let pp = (co.sym[p] + co.skew[p]) * half;
        let qq = (co.sym[p] - co.skew[p]) * half;
        let mut abc = [
            pp * sg[j] * sg[j],
            qq * sg[i] * sg[j] + beta,
            pp * sg[i] * sg[i],
        ];
        if psd {
            abc = psd_2x2(abc[0], abc[1], abc[2]);
        }
        pair[p] = [neg_vol * abc[0], neg_vol * abc[1], neg_vol * abc[2]];
    }
    Blocks {
        u: co.u,
        diag,
        pair,
    }
}

/// The slot entries of a prepared particle in slot order: `out[o]` for `o` in
/// `1..slot_len(D)` (0 is the tag's place and is left alone) is `U`, the diagonal block's upper
/// triangle column by column, the pairs' `(a, b, c)`. (An array, not a callback: a closure is
/// not compiled with the caller's target features, so lane operations in it would be calls.)
#[inline(always)]
pub fn entries<V: Lane, const D: usize>(b: &Blocks<V, D>, out: &mut [V; slot_len(3)]) {
    let mut o = 1;
    for j in 0..D {
        for i in 0..D {
            out[o] = b.u[j][i];
            o += 1;
        }
    }
    for j in 0..D {
        for i in 0..=j {
            out[o] = b.diag[j][i];
            o += 1;
        }
    }
    for p in b.pair.iter().take(pairs(D)) {
        for x in p {
            out[o] = *x;
            o += 1;
        }
    }
}

/// `M = U (−V⁰ H(Uᵀ G U)) Uᵀ` from a slot (scalars): the node force differential is `M ∇w_i`.
/// [`apply_entries`] on one lane.
#[inline(always)]
#[must_use]
pub fn apply_slot<T: Real, const D: usize>(slot: &[T], g: &Mat<T, D>) -> Mat<T, D> {
    Mat {
        cols: apply_entries::<T, D>(&slot[1..], &g.cols),
    }
}

/// [`apply_slot`] on lanes: `e[k]` is slot entry `1 + k` of each lane's particle, `g` its `G`
/// (column-major, `g[j][i] = G_ij`); returns `M` column-major.
#[inline(always)]
#[must_use]
pub fn apply_entries<V: Lane, const D: usize>(e: &[V], g: &LMat<V, D>) -> LMat<V, D> {
    let z = V::splat(V::Scalar::ZERO);
    let mut u = [[z; D]; D];
    let mut o = 0;
    for col in u.iter_mut() {
        for x in col.iter_mut() {
            *x = e[o];
            o += 1;
        }
    }
    // Ĝ = Uᵀ (G U).
    let gh = mul_tn(&u, &mul(g, &u));
    // M̂: the diagonal block on (Ĝ_11, …, Ĝ_dd), the pair blocks on (Ĝ_ij, Ĝ_ji).
    let mut mh = [[z; D]; D];
    let mut dg = [z; D];
    for j in 0..D {
        for i in 0..=j {
            let v = e[o];
            o += 1;
            dg[i] += v * gh[j][j];
            if i != j {
                dg[j] += v * gh[i][i];
            }
        }
    }
    for i in 0..D {
        mh[i][i] = dg[i];
    }
    for &(i, j) in PAIRS.iter().take(pairs(D)) {
        let (a, b, cc) = (e[o], e[o + 1], e[o + 2]);
        o += 3;
        let (gij, gji) = (gh[j][i], gh[i][j]);
        mh[j][i] = a * gij + b * gji;
        mh[i][j] = b * gij + cc * gji;
    }
    // M = (U M̂) Uᵀ.
    mul_nt(&mul(&u, &mh), &u)
}
