//! The layout of prepared Hessian data: what one particle's slot holds between a prepare and
//! the applies of a Newton step.
//!
//! A slot is [`len`]`(d)` scalars (18 in 2D, 38 in 3D), opaque to callers:
//!
//! | offset | what |
//! |---|---|
//! | 0 | tag: [`tag`]`(d)` when a prepare succeeded; 0 after a failed prepare |
//! | 1 | `k` of `F = 2ᵏG` (an integer) |
//! | 2 | `U` (`d²`, column-major) |
//! | 2 + d² | `V` |
//! | 2 + 2d² | scaling block `K`, upper triangle column by column (`d(d+1)/2`) |
//! | … | the projected `K⁺`, same order |
//! | … | `λ_sym` of each pair, then `λ_skew` of each pair ([`super::PAIRS`] order) |
//!
//! The tag is a value no successful computation stores there by accident and that a
//! zero-filled buffer does not hold, so an apply on a slot that no successful prepare wrote is
//! refused ([`crate::Error::NotPrepared`]) instead of applying stale or meaningless data.

use super::{pairs, Coeffs};
use crate::lane::lmat::{c, LMat};
use crate::lane::Lane;
use crate::scalar::Real;

/// Scalars of one particle's prepared slot in dimension `d`.
#[inline]
#[must_use]
pub const fn len(d: usize) -> usize {
    2 + 2 * d * d + d * (d + 1) + 2 * pairs(d)
}

/// The largest [`len`] (3D).
pub const MAX_LEN: usize = len(3);

/// The tag of a valid slot of dimension `d`: `−(1 + d/8)·2⁻¹⁰⁰` (exact in f32 and f64).
#[inline]
#[must_use]
pub fn tag<T: Real>(d: usize) -> T {
    T::from_f64(-(1.0 + d as f64 / 8.0) * 7.888_609_052_210_118e-31)
}

/// Writes the coefficients (exact and projected block) into `out[0..len(D)]` as lanes: entry
/// `m` of the slot is `out[m]`.
#[inline(always)]
pub fn pack<V: Lane, const D: usize>(co: &Coeffs<V, D>, block_psd: &LMat<V, D>, out: &mut [V]) {
    out[0] = V::splat(tag::<V::Scalar>(D));
    out[1] = co.k;
    let mut o = 2;
    for m in [&co.u, &co.v] {
        for j in 0..D {
            for i in 0..D {
                out[o] = m[j][i];
                o += 1;
            }
        }
    }
    for m in [&co.block, block_psd] {
        for j in 0..D {
            for i in 0..=j {
                out[o] = m[j][i];
                o += 1;
            }
        }
    }
    for p in 0..pairs(D) {
        out[o] = co.sym[p];
        out[o + pairs(D)] = co.skew[p];
        o += 1;
    }
}

/// Reads a slot (as lanes) back into coefficients, with the projected ones when `psd`; also
/// the mask of lanes whose tag is valid.
#[inline(always)]
#[must_use]
pub fn unpack<V: Lane, const D: usize>(s: &[V], psd: bool) -> (Coeffs<V, D>, V::Mask) {
    let zero = c::<V>(0.0);
    let ok = s[0].eq(V::splat(tag::<V::Scalar>(D)));
    let mut co = Coeffs {
        u: [[zero; D]; D],
        v: [[zero; D]; D],
        k: s[1],
        psi: [zero; D],
        energy: zero,
        block: [[zero; D]; D],
        sym: [zero; 3],
        skew: [zero; 3],
        x: [zero; D],
        s: zero,
    };
    let mut o = 2;
    for m in [&mut co.u, &mut co.v] {
        for j in 0..D {
            for i in 0..D {
                m[j][i] = s[o];
                o += 1;
            }
        }
    }
    let tri = D * (D + 1) / 2;
    let b0 = if psd { o + tri } else { o };
    let mut b = b0;
    for j in 0..D {
        for i in 0..=j {
            co.block[j][i] = s[b];
            co.block[i][j] = s[b];
            b += 1;
        }
    }
    o += 2 * tri;
    for p in 0..pairs(D) {
        let (sy, sk) = (s[o + p], s[o + pairs(D) + p]);
        co.sym[p] = if psd { sy.max(zero) } else { sy };
        co.skew[p] = if psd { sk.max(zero) } else { sk };
    }
    // A lane with a wrong tag holds anything: make it a harmless identity so no NaN spreads.
    co.k = V::select(ok, co.k, zero);
    (co, ok)
}
