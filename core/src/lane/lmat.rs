//! `D×D` matrices of lanes, column-major (`m[j][i]` is row `i`, column `j`, as
//! [`crate::Mat::cols`]), and the few operations the lane kernels need.
//!
//! Products accumulate over `k` ascending with [`Lane::mul_add`], so the vector paths compute
//! the same bits (see [`crate::lane`]).

#![allow(clippy::needless_range_loop)]

use super::Lane;
use crate::scalar::Real;

/// A `D×D` matrix of lanes, column-major.
pub type LMat<V, const D: usize> = [[V; D]; D];

/// `x` as a lane.
#[inline(always)]
#[must_use]
pub fn c<V: Lane>(x: f64) -> V {
    V::splat(V::Scalar::from_f64(x))
}

/// The zero matrix.
#[inline(always)]
#[must_use]
pub fn zero<V: Lane, const D: usize>() -> LMat<V, D> {
    [[c::<V>(0.0); D]; D]
}

/// The identity matrix.
#[inline(always)]
#[must_use]
pub fn identity<V: Lane, const D: usize>() -> LMat<V, D> {
    let mut m = zero::<V, D>();
    for i in 0..D {
        m[i][i] = c(1.0);
    }
    m
}

/// `a · b`.
#[inline(always)]
#[must_use]
pub fn mul<V: Lane, const D: usize>(a: &LMat<V, D>, b: &LMat<V, D>) -> LMat<V, D> {
    let mut m = zero::<V, D>();
    for j in 0..D {
        for i in 0..D {
            let mut s = a[0][i] * b[j][0];
            for k in 1..D {
                s = a[k][i].mul_add(b[j][k], s);
            }
            m[j][i] = s;
        }
    }
    m
}

/// `aᵀ · b`.
#[inline(always)]
#[must_use]
pub fn mul_tn<V: Lane, const D: usize>(a: &LMat<V, D>, b: &LMat<V, D>) -> LMat<V, D> {
    let mut m = zero::<V, D>();
    for j in 0..D {
        for i in 0..D {
            m[j][i] = dot(&a[i], &b[j]);
        }
    }
    m
}

/// `a · bᵀ`.
#[inline(always)]
#[must_use]
pub fn mul_nt<V: Lane, const D: usize>(a: &LMat<V, D>, b: &LMat<V, D>) -> LMat<V, D> {
    let mut m = zero::<V, D>();
    for j in 0..D {
        for i in 0..D {
            let mut s = a[0][i] * b[0][j];
            for k in 1..D {
                s = a[k][i].mul_add(b[k][j], s);
            }
            m[j][i] = s;
        }
    }
    m
}

/// `a · diag(d) · bᵀ` (the SVD reassembly `U diag(σ) Vᵀ`).
#[inline(always)]
#[must_use]
pub fn mul_diag_nt<V: Lane, const D: usize>(
    a: &LMat<V, D>,
    d: &[V; D],
    b: &LMat<V, D>,
) -> LMat<V, D> {
    let mut ad = *a;
    for k in 0..D {
        for i in 0..D {
            ad[k][i] *= d[k];
        }
    }
    mul_nt(&ad, b)
}

/// `u · v` of two columns.
#[inline(always)]
#[must_use]
pub fn dot<V: Lane, const D: usize>(u: &[V; D], v: &[V; D]) -> V {
    let mut s = u[0] * v[0];
    for i in 1..D {
        s = u[i].mul_add(v[i], s);
    }
    s
}

/// `u × v` of 3-vectors.
#[inline(always)]
#[must_use]
pub fn cross<V: Lane>(a: &[V; 3], b: &[V; 3]) -> [V; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// `det m` (2D: `m₀₀m₁₁ − m₁₀m₀₁`; 3D: `c₀ · (c₁ × c₂)`, as [`crate::Matrix::det`]).
#[inline(always)]
#[must_use]
pub fn det<V: Lane, const D: usize>(m: &LMat<V, D>) -> V {
    if D == 2 {
        m[0][0] * m[1][1] - m[0][1] * m[1][0]
    } else {
        let x = cross(&[m[1][0], m[1][1], m[1][2]], &[m[2][0], m[2][1], m[2][2]]);
        m[0][0] * x[0] + m[0][1] * x[1] + m[0][2] * x[2]
    }
}

/// Largest `|m_ij|`.
#[inline(always)]
#[must_use]
pub fn max_abs<V: Lane, const D: usize>(m: &LMat<V, D>) -> V {
    let mut r = m[0][0].abs();
    for j in 0..D {
        for i in 0..D {
            r = r.max(m[j][i].abs());
        }
    }
    r
}

/// Every entry finite.
#[inline(always)]
#[must_use]
pub fn all_finite<V: Lane, const D: usize>(m: &LMat<V, D>) -> V::Mask {
    let mut r = m[0][0].is_finite();
    for j in 0..D {
        for i in 0..D {
            r = r & m[j][i].is_finite();
        }
    }
    r
}

/// `m · s`.
#[inline(always)]
#[must_use]
pub fn scale<V: Lane, const D: usize>(m: &LMat<V, D>, s: V) -> LMat<V, D> {
    let mut r = *m;
    for j in 0..D {
        for i in 0..D {
            r[j][i] *= s;
        }
    }
    r
}

/// The three factors `2^e₁, 2^e₂, 2^e₃` with `e₁ + e₂ + e₃ = e`, each exponent clamped to the
/// normal range, for an integer-valued `e` with `|e| ≤ 3·(bias − 1)` (every exponent the
/// kernels use: `±2k` with `|k|` at most the exponent range plus the mantissa digits).
#[inline(always)]
#[must_use]
pub fn pow2_factors<V: Lane>(e: V) -> [V; 3] {
    // The normal exponents: [1 − bias, bias], bias = MAX_EXP − 1.
    let hi = c::<V>(f64::from(<V::Scalar as Real>::MAX_EXP - 1));
    let lo = c::<V>(f64::from(2 - <V::Scalar as Real>::MAX_EXP));
    let e1 = e.max(lo).min(hi);
    let r = e - e1;
    let e2 = r.max(lo).min(hi);
    let e3 = (r - e2).max(lo).min(hi);
    [V::pow2(e1), V::pow2(e2), V::pow2(e3)]
}

/// `x · 2ᵉ` (integer-valued `e`, see [`pow2_factors`]). Exact unless the result over- or
/// underflows; a subnormal result may be rounded twice (at most one subnormal ulp), on every
/// path alike. `0 · 2ᵉ = 0` for every `e` (no `0 · inf`).
#[inline(always)]
#[must_use]
pub fn scale_pow2<V: Lane, const D: usize>(m: &LMat<V, D>, e: V) -> LMat<V, D> {
    let [p1, p2, p3] = pow2_factors(e);
    let mut r = *m;
    for j in 0..D {
        for i in 0..D {
            r[j][i] = r[j][i] * p1 * p2 * p3;
        }
    }
    r
}

/// `x^{−1/d}` for `x > 0` (any finite positive `x`, subnormals included), `d` = 2 or 3.
///
/// `x = m·2ᵉ`, `m ∈ [0.5, 1)` (split exactly in two power-of-two steps, so subnormal and huge
/// `x` need no special case), `e = d·q + r` with `0 ≤ r < d`; then
/// `x^{−1/d} = m^{−1/d} · 2^{−r/d} · 2^{−q}`.
/// - 2D: [`rsqrt`]`(m·2ʳ)`.
/// - 3D: a cubic least-squares fit of `m^{−1/3}` on `[0.5, 1]` (relative error < 1.9e-3), then
///   Newton steps `t ← t(4 − y t³)/3`, whose relative error goes as `e ↦ 2e²`: 2 steps for
///   f32 (< 1e-10), 3 for f64 (< 2e-20), 4 for wider scalars, on `y = m·2ʳ` from the guess
///   times the constant `2^{−r/3}`. A few ulps in all.
///
/// Returns NaN for `x ≤ 0` or non-finite `x`.
#[inline(always)]
#[must_use]
pub fn inv_root<V: Lane, const D: usize>(x: V) -> V {
    inv_root_exp::<V, D>(x, c(0.0))
}

/// `(x·2ᵏ)^{−1/d}` for `x > 0` and an integer-valued `k` whose `x·2ᵏ` need not be
/// representable (a determinant computed on power-of-two-scaled columns): as [`inv_root`],
/// with `k` added to the exponent of `x`.
#[inline(always)]
#[must_use]
pub fn inv_root_exp<V: Lane, const D: usize>(x: V, k: V) -> V {
    let ex = x.exponent();
    let h = (ex * c(0.5)).floor();
    let m = x * V::pow2(-h) * V::pow2(h - ex);
    let e = ex + k;
    let dd = c::<V>(D as f64);
    let q = ((e + c(0.5)) / dd).floor();
    let r = e - q * dd;
    let t = if D == 2 {
        rsqrt(m * V::pow2(r))
    } else {
        // 2^{−1/3}, 2^{−2/3} (rounded; the Newton steps below remove the rounding).
        let k1 = V::Scalar::from_f64(0.793_700_525_984_099_8);
        let k2 = V::Scalar::from_f64(0.629_960_524_947_436_6);
        let f = V::select(
            r.eq(c(1.0)),
            V::splat(k1),
            V::select(r.eq(c(2.0)), V::splat(k2), c(1.0)),
        );
        let mut t = (c::<V>(1.890_999_3)
            + m * (c::<V>(-1.841_537_5) + m * (c::<V>(1.348_814_2) - m * c::<V>(0.398_308_82))))
            * f;
        let y = m * V::pow2(r);
        let steps = match <V::Scalar as Real>::MANTISSA_DIGITS {
            0..=24 => 2,
            25..=53 => 3,
            _ => 4,
        };
        let third = c::<V>(1.0 / 3.0);
        for _ in 0..steps {
            t = t * (-y).mul_add(t * t * t, c(4.0)) * third;
        }
        t
    };
    let [p1, p2, p3] = pow2_factors(-q);
    let out = t * p1 * p2 * p3;
    let ok = c::<V>(0.0).lt(x) & x.is_finite();
    V::select(ok, out, c(f64::NAN))
}

/// `1/√x` for a positive normal `x` (a few ulps): [`Lane::rsqrt_guess`] (relative error
/// `e₀ < 3.5e-2`), then Newton steps `y ← y(3/2 − (x/2)y²)`, whose error goes as
/// `e ↦ 3e²/2`: 3 steps for f32 (< 5e-11), 4 for f64 (< 4e-21), 6 for wider scalars. Plain
/// `×` and `−`, so every path computes the same bits, and no division or square-root
/// instruction (their throughput dominates the kernels otherwise).
#[inline(always)]
#[must_use]
pub fn rsqrt_newton<V: Lane>(x: V) -> V {
    let steps = match <V::Scalar as Real>::MANTISSA_DIGITS {
        0..=24 => 3,
        25..=53 => 4,
        _ => 6,
    };
    rsqrt_steps(x, steps)
}

/// [`Lane::rsqrt_guess`] and `steps` Newton steps (relative error after `k` steps below
/// `1.5^(2^k−1)·0.035^(2^k)`: 1.7e-3, 4.6e-6, 3.2e-11, 1.5e-21).
#[inline(always)]
#[must_use]
pub fn rsqrt_steps<V: Lane>(x: V, steps: u32) -> V {
    let hx = x * c(0.5);
    let mut y = x.rsqrt_guess();
    for _ in 0..steps {
        y = y * (-(hx * y)).mul_add(y, c(1.5));
    }
    y
}

/// [`Lane::rsqrt`].
#[inline(always)]
#[must_use]
pub fn rsqrt<V: Lane>(x: V) -> V {
    x.rsqrt()
}

/// [`Lane::recip`].
#[inline(always)]
#[must_use]
pub fn recip<V: Lane>(x: V) -> V {
    x.recip()
}

/// One Newton step toward unit length for a vector `v` with `‖v‖² = 1 + η`, `|η|` a few ulps:
/// `v·(3/2 − ‖v‖²/2)`, so `‖v‖² = 1 + O(η²)` up to the rounding of this step (about one ulp).
/// It makes the rotations and unit vectors built with the Newton reciprocal square roots
/// orthonormal to the accuracy of correctly rounded ones.
#[inline(always)]
#[must_use]
pub fn renormalize<V: Lane, const N: usize>(v: [V; N]) -> [V; N] {
    let n2 = dot(&v, &v);
    let k = (-c::<V>(0.5)).mul_add(n2, c(1.5));
    let mut r = v;
    for x in &mut r {
        *x *= k;
    }
    r
}

/// Column equilibration by powers of two: `(Ĝ, e)` with `G = Ĝ·diag(2^{e_j})` and each
/// column of `Ĝ` with its largest entry in `[0.5, 1)` (a zero column stays zero, `e_j = 0`).
/// `det G = det Ĝ · 2^{Σe_j}` without under- or overflow: columns of very different sizes
/// (one of 1 and two of 1e-20 in f32) have a `det G` below the normal range although `G` is
/// well conditioned after column scaling (Hadamard ratio `∏‖g_j‖/|det G|` small).
#[inline(always)]
#[must_use]
pub fn equilibrate_columns<V: Lane, const D: usize>(g: &LMat<V, D>) -> (LMat<V, D>, [V; D]) {
    let mut gh = *g;
    let mut e = [c::<V>(0.0); D];
    for j in 0..D {
        let mut m = g[j][0].abs();
        for i in 1..D {
            m = m.max(g[j][i].abs());
        }
        e[j] = m.exponent();
        let h = (e[j] * c(0.5)).floor();
        let (p1, p2) = (V::pow2(-h), V::pow2(h - e[j]));
        for i in 0..D {
            gh[j][i] = gh[j][i] * p1 * p2;
        }
    }
    (gh, e)
}

/// The Jacobi rotation of a symmetric 2×2 `[[α, γ], [γ, β]]` (a Gram matrix of two columns,
/// or a pivot block): `(c, s)` with `c² + s² = 1` to about an ulp, such that
/// `[[c, s], [−s, c]]ᵀ [[α, γ], [γ, β]] [[c, s], [−s, c]]` is diagonal.
///
/// Rutishauser's `t = sgn(ζ)/(|ζ| + √(1+ζ²))`, `ζ = (β−α)/(2γ)` (Golub & Van Loan, Alg.
/// 8.5.1), in half-angle form without division: with `h = √((β−α)² + 4γ²)`,
/// `cos 2θ = |β−α|/h`, `sin 2θ = 2γ·sgn(β−α)/h`, `c² = (1 + |β−α|/h)/2 ∈ [1/2, 1]`,
/// `s = γ·sgn(β−α)/(h·c)`. On vectors the two reciprocal square roots are Newton iterates
/// ([`rsqrt_steps`]: 2 steps in f32, 3 in f64) whose error only tilts the angle by a few
/// 1e-6 (f32) or 1e-11 (f64) — the next sweep removes what the tilted rotation leaves — and
/// [`renormalize`] makes `(c, s)` unit to an ulp, which is what keeps the accumulated
/// rotations orthogonal. Scalars use correctly rounded `1/√x`. Below the smallest normal
/// number (`γ` and `β − α` both under `√min`) there is no rotation.
#[inline(always)]
#[must_use]
pub fn jacobi_rotation<V: Lane>(alpha: V, beta: V, gamma: V) -> (V, V) {
    let one = c::<V>(1.0);
    let d = beta - alpha;
    let den2 = d.mul_add(d, c::<V>(4.0) * gamma * gamma);
    let tiny = den2.lt(V::splat(V::Scalar::MIN_POSITIVE));
    let steps = match <V::Scalar as Real>::MANTISSA_DIGITS {
        0..=24 => 2,
        25..=53 => 3,
        _ => 5,
    };
    let rs = |x: V| {
        if V::LANES == 1 {
            x.rsqrt()
        } else {
            rsqrt_steps(x, steps)
        }
    };
    let r1 = rs(V::select(tiny, one, den2));
    let cc = (c::<V>(0.5) * d.abs()).mul_add(r1, c(0.5));
    let r2 = rs(cc);
    let [cs, sn] = renormalize([cc * r2, gamma * one.copysign(d) * r1 * r2]);
    (V::select(tiny, one, cs), V::select(tiny, c(0.0), sn))
}
