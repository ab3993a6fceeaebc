//! Evolution of the deformation gradient `F = F_E F_P`, snow plasticity and the liquid
//! projection.
//!
//! - Update (Stomakhin et al. 2014, §5; Stomakhin et al. 2013, §5): `F_E ← (I + Δt∇v) F_E`.
//!   When `det(I + Δt∇v) ≤ 0` the step would invert the particle; the paper's remedy replaces
//!   the increment by `(I + ½Δt∇v)²`, and this module keeps halving,
//!   `(I + 2⁻ᵏΔt∇v)^{2ᵏ}` (formed by `k` squarings), until the computed determinant is
//!   positive. Every `k ≥ 1` has `det = det(I + 2⁻ᵏΔt∇v)^{2ᵏ} ≥ 0`, zero only when
//!   `I + 2⁻ᵏΔt∇v` is singular; and once `‖2⁻ᵏΔt∇v‖₂ < 1` the factor has no eigenvalue on
//!   `(−∞, 0]`, so a positive determinant is guaranteed (up to underflow) after about
//!   `log₂‖Δt∇v‖` halvings. The increment tends to `exp(Δt∇v)` as `k` grows, so the remedy
//!   is consistent with the flow `Ḟ = ∇v F`. `J = det F` therefore never reaches 0.
//! - Snow plasticity (Stomakhin et al. 2013, §4): `F_E = U Σ Vᵀ`, `Σ̂ = clamp(Σ, 1 − θ_c,
//!   1 + θ_s)`, `F_E ← U Σ̂ Vᵀ`, `F_P ← F_E⁻¹ F = V Σ̂⁻¹ Σ Vᵀ F_P` (no inverse is formed).
//!   This keeps `F = F_E F_P` (up to rounding) and moves `det Σ / det Σ̂` from `J_E` to
//!   `J_P`, so `J = J_E J_P` is kept. The SVD is the default decomposition on lanes (closed
//!   form in 2D, one-sided Jacobi in 3D, [`crate::polar::lanes::default_svd`]), and the step is
//!   written once over lanes (`snow_lanes`): G2P's batch runs it on SIMD lanes.
//! - Liquid (Stomakhin et al. 2014, §4): the paper resets a fluid's `F_E` to `J_E^{1/d} I`
//!   after each update, so that `μ = 0` leaves only `Ψ_λ(J_E)`. What a liquid particle is
//!   ever asked for then depends on two numbers: the stress `λ(J_E − 1) J_E I` and the
//!   pressure `−Ψ_λ'(J_E)/J_P` with its solve coefficient `J_P/(Δt λ J_E)`
//!   ([`super::dilation`]) read `J_E` and `J_P` only. So the state of a liquid is the pair
//!   of volume ratios, and the projection keeps both and nothing else:
//!   `F_E ← J_E^{1/d} I`, `F_P ← J_P^{1/d} I`, with `J_E = det F_E` after the update and
//!   `J_P = det F_P` as it was. Derivation: the update gives
//!   `J_E ← det((I + Δt∇v) F_E) = det(I + Δt∇v) J_E` (the discrete `J̇ = J ∇·v`) and leaves
//!   `F_P` alone, so the liquid step moves no volume between `J_E` and `J_P`, and
//!   `det(F_E F_P) = J_E J_P = J` is kept exactly up to the rounding of the two roots. The
//!   deviatoric (isochoric) part of `F`, i.e. the flow history, is dropped, which is what a
//!   liquid means. An `F_P` that is already `s I` (`s > 0`) is kept bit for bit, so `J_P` of
//!   a liquid does not drift at all; a solid that has just melted has a general `F_P`,
//!   whose determinant is used. A liquid that freezes starts as a solid from the isotropic
//!   `F_E`, `F_P`.
//!
//!   Keeping `F_P ← J_E^{−1/d} F_E F_P` instead (the whole `F` with an isotropic `F_E`)
//!   would store the flow history in `F_P`: its condition number grows without bound in a
//!   steady flow (like `e^{2 ε̇ t}` in an extensional flow with rate `ε̇`), until its
//!   determinant is lost to rounding.
//!
//! **Checked results.** Every result is finite with a positive computed determinant, the
//! condition every particle entry checks on its input, or an error: a determinant that is
//! not finite, or that underflows to 0 although the matrix is not singular to working
//! precision, is [`Error::Overflow`]; a matrix singular to working precision (its
//! determinant on power-of-two-equilibrated columns is not positive) is
//! [`Error::NonPositiveJ`]. See [`check_det`].

use crate::error::{Error, Result};
use crate::kernel::select_mat;
use crate::lane::lmat::{self, mul_diag_nt, LMat};
use crate::lane::Lane;
use crate::mat::{Mat, Matrix};
use crate::polar::lanes::{default_svd, scaled_input};
use crate::scalar::Real;

use super::Snow;

/// Cap on the remedy's halvings; reaching it reports the error of the last try (see
/// [`increment`]).
pub const MAX_HALVINGS: u32 = 64;

/// The increment `A` with `F_E ← A F_E`: `I + Δt∇v`, or `(I + 2⁻ᵏΔt∇v)^{2ᵏ}` with the
/// smallest `k ≥ 1` giving `det A > 0` (see the module docs). Returns `A` and `k`.
///
/// Errors: [`Error::NonFinite`] for non-finite `∇v` or `Δt`; [`Error::Overflow`] when
/// `Δt∇v` overflows; when no `k ≤` [`MAX_HALVINGS`] gives a valid increment (only for
/// `‖Δt∇v‖ ≳ 2⁶⁴`), the [`check_det`] error of the last try: [`Error::Overflow`] when the
/// increment or its determinant is not representable, [`Error::NonPositiveJ`] otherwise.
#[inline]
pub fn increment<T: Real, const D: usize>(grad_v: &Mat<T, D>, dt: T) -> Result<(Mat<T, D>, u32)>
where
    Mat<T, D>: Matrix<Scalar = T>,
{
    if !dt.is_finite() || !grad_v.is_finite() {
        return Err(Error::NonFinite);
    }
    let l = *grad_v * dt;
    if !l.is_finite() {
        return Err(Error::Overflow);
    }
    let id = Mat::<T, D>::identity();
    let a = id + l;
    if Matrix::det(&a) > T::ZERO {
        return Ok((a, 0));
    }
    let mut last = Error::NonPositiveJ;
    for k in 1..=MAX_HALVINGS {
        let mut a = id + l * T::ONE.scalbn(-(k as i32));
        for _ in 0..k {
            a = a * a;
        }
        match check_det(&a) {
            Ok(_) => return Ok((a, k)),
            Err(e) => last = e,
        }
    }
    // With `k` this large the factor is close to I: a failure is the range of
    // `exp(Δt∇v)` (Overflow), or its determinant lost to rounding (NonPositiveJ).
    Err(last)
}

/// `F_E ← A F_E` with the increment of [`increment`]; returns the new `F_E` and the number of
/// halvings the remedy used.
///
/// Errors: as [`increment`]; those of [`check_det`] for the new `F_E` ([`Error::NonPositiveJ`]
/// for an `F_E` singular to working precision, [`Error::Overflow`] when it or its
/// determinant is not representable).
#[inline]
pub fn evolve<T: Real, const D: usize>(
    f_e: &Mat<T, D>,
    grad_v: &Mat<T, D>,
    dt: T,
) -> Result<(Mat<T, D>, u32)>
where
    Mat<T, D>: Matrix<Scalar = T>,
{
    let (f, k, _) = evolve_det(f_e, grad_v, dt)?;
    Ok((f, k))
}

/// [`evolve`], also returning the new `J_E = det F_E` that its check computed (finite,
/// positive).
///
/// Errors: as [`evolve`].
#[inline]
pub fn evolve_det<T: Real, const D: usize>(
    f_e: &Mat<T, D>,
    grad_v: &Mat<T, D>,
    dt: T,
) -> Result<(Mat<T, D>, u32, T)>
where
    Mat<T, D>: Matrix<Scalar = T>,
{
    let (a, k) = increment(grad_v, dt)?;
    let (f, j) = advance(&a, f_e)?;
    Ok((f, k, j))
}

/// `A F_E` for an increment `a` of [`increment`], and its determinant, checked
/// ([`check_det`]).
///
/// Errors: those of [`check_det`] for `A F_E`.
#[inline]
pub fn advance<T: Real, const D: usize>(a: &Mat<T, D>, f_e: &Mat<T, D>) -> Result<(Mat<T, D>, T)>
where
    Mat<T, D>: Matrix<Scalar = T>,
{
    let f = *a * *f_e;
    let j = check_det(&f)?;
    Ok((f, j))
}

/// Snow plasticity: returns `(F_E, F_P)` after clamping the singular values of `f_e` to
/// `[1 − θ_c, 1 + θ_s]` (see the module docs); when no singular value is clamped, `f_e` and
/// `f_p` unchanged. Requires `det f_e > 0`. The step is that of G2P's batch on SIMD lanes
/// (`snow_lanes`), here on one scalar.
///
/// Errors: [`Error::NonFinite`] for a non-finite `f_e`; [`Error::NonPositiveJ`] for a
/// non-positive singular value (`det f_e ≤ 0`); those of [`check_det`] for the new `F_E` and
/// `F_P`.
#[inline]
pub fn snow_plasticity<T: Real, const D: usize>(
    snow: &Snow<T>,
    f_e: &Mat<T, D>,
    f_p: &Mat<T, D>,
) -> Result<(Mat<T, D>, Mat<T, D>)>
where
    Mat<T, D>: Matrix<Scalar = T, Vector = [T; D]>,
{
    snow_plasticity_on::<T, T, D>(snow, f_e, f_p)
}

/// [`snow_plasticity`] with the step evaluated on lanes of `V` (the particle in every lane,
/// lane 0 kept): the bits that every lane of a chunk of `V` gets from [`snow_lanes`]. G2P's
/// batch takes the step on its row type for a particle updated on its own too, so that a
/// particle's result does not depend on whether its chunk ran on lanes.
#[inline(always)]
pub(crate) fn snow_plasticity_on<T: Real, V: Lane<Scalar = T>, const D: usize>(
    snow: &Snow<T>,
    f_e: &Mat<T, D>,
    f_p: &Mat<T, D>,
) -> Result<(Mat<T, D>, Mat<T, D>)>
where
    Mat<T, D>: Matrix<Scalar = T, Vector = [T; D]>,
{
    if !f_e.is_finite() {
        return Err(Error::NonFinite);
    }
    let splat = |m: &Mat<T, D>| m.cols.map(|c| c.map(V::splat));
    let out = snow_lanes(snow_bounds(snow).map(V::splat), &splat(f_e), &splat(f_p));
    if V::mask_bits(out.positive) & 1 == 0 {
        return Err(Error::NonPositiveJ);
    }
    let lane0 = |m: &LMat<V, D>| {
        Mat::from_cols(m.map(|c| {
            c.map(|x| {
                let mut y = T::ZERO;
                // SAFETY: one scalar written to `y`.
                unsafe { x.store_n(&mut y, 1) };
                y
            })
        }))
    };
    let (fe, fp) = (lane0(&out.f_e), lane0(&out.f_p));
    // V diag(σ/σ̂) Vᵀ has condition max(σ/σ̂)/min(σ/σ̂): for an `F_E` stretched beyond ~1/ε
    // the new `F_P` is singular to working precision, and a tiny `J_P` may underflow.
    check_det(&fe)?;
    check_det(&fp)?;
    Ok((fe, fp))
}

/// The clamp bounds `[1 − θ_c, 1 + θ_s]` of snow plasticity.
#[inline(always)]
#[must_use]
pub(crate) fn snow_bounds<T: Real>(snow: &Snow<T>) -> [T; 2] {
    [
        T::ONE - snow.critical_compression,
        T::ONE + snow.critical_stretch,
    ]
}

/// The snow step of every lane ([`snow_lanes`]).
#[derive(Clone, Copy)]
pub(crate) struct SnowLanes<V: Lane, const D: usize> {
    /// The new `F_E`: `U Σ̂ Vᵀ`, or the input where nothing is clamped.
    pub f_e: LMat<V, D>,
    /// The new `F_P`: `(V diag(σ/σ̂) Vᵀ) F_P`, or the input where nothing is clamped.
    pub f_p: LMat<V, D>,
    /// The lanes whose singular values are all positive (`det F_E > 0`); the others' results
    /// are meaningless.
    pub positive: V::Mask,
}

/// Snow plasticity per lane (Stomakhin et al. 2013, §4; see the module docs) of a finite
/// `f_e` with clamp bounds `[lo, hi]` ([`snow_bounds`]): the rotation-variant SVD
/// `F_E = U Σ Vᵀ` of the default decomposition on lanes ([`default_svd`], on the
/// power-of-two-scaled input), `σ̂ = min(max(σ, lo), hi)`, `F_E ← U diag(σ̂) Vᵀ` and
/// `F_P ← (V diag(σ/σ̂) Vᵀ) F_P`. A lane where every `σ/σ̂` is exactly 1 keeps its inputs bit for
/// bit (the step is the identity; rounding it through the products would move them). The
/// one source of the scalar [`snow_plasticity`] (on a lane pair) and of G2P's update on lanes.
///
/// [`default_svd`]: crate::polar::lanes::default_svd
#[inline(always)]
#[must_use]
pub(crate) fn snow_lanes<V: Lane, const D: usize>(
    [lo, hi]: [V; 2],
    f_e: &LMat<V, D>,
    f_p: &LMat<V, D>,
) -> SnowLanes<V, D> {
    let (g, k) = scaled_input(f_e);
    let svd = default_svd(&g).unscaled(k);
    let (zero, one) = (V::splat(V::Scalar::ZERO), V::splat(V::Scalar::ONE));
    let mut positive = zero.le(zero);
    let mut same = positive;
    let mut clamped = svd.sigma;
    let mut ratio = [one; D];
    for i in 0..D {
        let s = svd.sigma[i];
        positive = positive & zero.lt(s);
        clamped[i] = s.max(lo).min(hi);
        ratio[i] = s / clamped[i];
        same = same & ratio[i].eq(one);
    }
    let fe = mul_diag_nt(&svd.u, &clamped, &svd.v);
    let fp = lmat::mul(&mul_diag_nt(&svd.v, &ratio, &svd.v), f_p);
    SnowLanes {
        f_e: select_mat(same, f_e, &fe),
        f_p: select_mat(same, f_p, &fp),
        positive,
    }
}

/// `J^{1/d}` by `sqrt` (d = 2) or `cbrt` (d = 3).
#[inline]
#[must_use]
pub fn root_d<T: Real, const D: usize>(j: T) -> T {
    if D == 2 {
        j.sqrt()
    } else {
        j.cbrt()
    }
}

/// Liquid projection: returns `(J_E^{1/d} I, J_P^{1/d} I)` with `J_E = det f_e` and
/// `J_P = det f_p` (see the module docs); an `f_p = s I` with `s > 0` is returned as it is.
/// The roots are taken on power-of-two-equilibrated columns ([`root_det`]), so they are
/// accurate even where `J_E` or `J_P` themselves are not representable.
///
/// Errors: those of [`root_det`] ([`Error::NonPositiveJ`] for a matrix singular to working
/// precision); [`Error::Overflow`] when a new determinant `J^{1/d}·…` is not representable
/// ([`check_det`]).
#[inline]
pub fn liquid_projection<T: Real, const D: usize>(
    f_e: &Mat<T, D>,
    f_p: &Mat<T, D>,
) -> Result<(Mat<T, D>, Mat<T, D>)>
where
    Mat<T, D>: Matrix<Scalar = T>,
{
    projected(root_det(f_e)?, f_p)
}

/// `(r I, F_P')` with `F_P' = f_p` where `f_p = s I`, `s > 0`, else `J_P^{1/d} I`, both
/// checked ([`check_det`]): the projection once `J_E^{1/d} = r` is known.
#[inline]
fn projected<T: Real, const D: usize>(r: T, f_p: &Mat<T, D>) -> Result<(Mat<T, D>, Mat<T, D>)>
where
    Mat<T, D>: Matrix<Scalar = T>,
{
    let fe = Mat::<T, D>::from_diagonal([r; D]);
    let fp = match isotropic_scale(f_p) {
        Some(s) if s > T::ZERO => *f_p,
        _ => Mat::<T, D>::from_diagonal([root_det(f_p)?; D]),
    };
    check_det(&fe)?;
    check_det(&fp)?;
    Ok((fe, fp))
}

/// One liquid step: `F_E ← A F_E` with the increment `a` of [`increment`], then the projection
/// of [`liquid_projection`]. For `f_e = s I` (`s > 0`: every liquid's `F_E` after a step) the
/// product is not formed: `J_E ← det(A) J_E` (the module docs), so the new `F_E` is
/// `s (det A)^{1/d} I`, the root taken of the computed `det A` when that is a normal number
/// and on equilibrated columns ([`root_det`] of `A`) otherwise. Any other `f_e` (a solid that
/// has just melted) is multiplied out and checked ([`check_det`]) first, then projected.
///
/// Errors: those of [`liquid_projection`]; for a general `f_e`, those of [`check_det`] for
/// `A F_E`; [`Error::Overflow`] when `s (det A)^{1/d}` is not a positive finite number.
#[inline]
pub fn liquid_step<T: Real, const D: usize>(
    f_e: &Mat<T, D>,
    a: &Mat<T, D>,
    f_p: &Mat<T, D>,
) -> Result<(Mat<T, D>, Mat<T, D>)>
where
    Mat<T, D>: Matrix<Scalar = T>,
{
    let s = match isotropic_scale(f_e) {
        Some(s) if s > T::ZERO => s,
        _ => return liquid_projection(&advance(a, f_e)?.0, f_p),
    };
    let det_a = Matrix::det(a);
    let rho = if det_a.is_finite() && det_a >= T::MIN_POSITIVE {
        root_d::<T, D>(det_a)
    } else {
        root_det(a)?
    };
    let r = s * rho;
    if !(r.is_finite() && r > T::ZERO) {
        return Err(Error::Overflow);
    }
    projected(r, f_p)
}

/// `Some(s)` when `m = s I` exactly (every off-diagonal entry 0, equal diagonal entries).
#[inline]
#[must_use]
pub fn isotropic_scale<T: Real, const D: usize>(m: &Mat<T, D>) -> Option<T> {
    let s = m.cols[0][0];
    for j in 0..D {
        for i in 0..D {
            let want = if i == j { s } else { T::ZERO };
            if m.cols[j][i] != want {
                return None;
            }
        }
    }
    Some(s)
}

/// The determinant on power-of-two-equilibrated columns: `(det M̂, e)` with
/// `M = M̂ diag(2^{e_j})`, `e = Σ_j e_j`, each nonzero column of `M̂` having its largest
/// entry in `[½, 1)`, so `det M = det M̂ · 2ᵉ` (the scaling is exact). `det M̂` is the
/// computed `det M` scaled by `2^{−e}` whenever the latter neither under- nor overflows;
/// it is itself representable unless `M` is singular to working precision.
#[inline]
#[must_use]
pub fn det_equilibrated<T: Real, const D: usize>(m: &Mat<T, D>) -> (T, i32)
where
    Mat<T, D>: Matrix<Scalar = T>,
{
    let mut g = *m;
    let mut sum = 0i32;
    for j in 0..D {
        let mut c = T::ZERO;
        for i in 0..D {
            c = c.max(g.cols[j][i].abs());
        }
        let e = c.exponent();
        sum += e;
        for i in 0..D {
            g.cols[j][i] = g.cols[j][i].scalbn(-e);
        }
    }
    (Matrix::det(&g), sum)
}

/// `(det M)^{1/d}` of a finite `M`, from [`det_equilibrated`]: with `det M = det M̂ · 2ᵉ`,
/// `e = d q + ρ`, `0 ≤ ρ < d`, the root is `(det M̂ · 2^ρ)^{1/d} · 2^q` (exact scalings), so
/// it is accurate where `det M` under- or overflows.
///
/// Errors: [`Error::NonFinite`] for a non-finite `M`; [`Error::NonPositiveJ`] when
/// `det M̂ ≤ 0` (`det M ≤ 0`, or `M` singular to working precision); [`Error::Overflow`]
/// when the root itself is not representable.
#[inline]
pub fn root_det<T: Real, const D: usize>(m: &Mat<T, D>) -> Result<T>
where
    Mat<T, D>: Matrix<Scalar = T>,
{
    if !m.is_finite() {
        return Err(Error::NonFinite);
    }
    let (det, e) = det_equilibrated(m);
    // The scaled entries are at most 1 in magnitude, so `det` is finite (never NaN).
    if det <= T::ZERO {
        return Err(Error::NonPositiveJ);
    }
    let d = D as i32;
    let (q, rho) = (e.div_euclid(d), e.rem_euclid(d));
    let r = root_d::<T, D>(det.scalbn(rho)).scalbn(q);
    if r.is_finite() && r > T::ZERO {
        Ok(r)
    } else {
        Err(Error::Overflow)
    }
}

/// Checks a deformation gradient the way every particle entry checks its input: finite, with
/// a finite positive computed determinant, which is returned.
///
/// Errors: [`Error::Overflow`] for a non-finite entry or determinant, or a determinant that
/// underflows to 0 (or below) while the equilibrated determinant ([`det_equilibrated`]) is
/// positive: the matrix is fine, its determinant is not representable;
/// [`Error::NonPositiveJ`] otherwise (`det ≤ 0`, or singular to working precision).
#[inline]
pub fn check_det<T: Real, const D: usize>(m: &Mat<T, D>) -> Result<T>
where
    Mat<T, D>: Matrix<Scalar = T>,
{
    if !m.is_finite() {
        return Err(Error::Overflow);
    }
    let j = Matrix::det(m);
    if !j.is_finite() {
        return Err(Error::Overflow);
    }
    if j > T::ZERO {
        return Ok(j);
    }
    if det_equilibrated(m).0 > T::ZERO {
        Err(Error::Overflow)
    } else {
        Err(Error::NonPositiveJ)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn diag<T: Real, const D: usize>(e: [i32; D]) -> Mat<T, D> {
        Mat::from_diagonal(e.map(|k| T::ONE.scalbn(k)))
    }

    #[test]
    fn check_det_statuses() {
        // det 2⁻¹⁴⁸: subnormal, positive, accepted.
        assert!(check_det(&diag::<f32, 2>([-74, -74])).is_ok());
        // det 2⁻¹⁶⁰ underflows to 0; the matrix is fine: Overflow.
        assert_eq!(check_det(&diag::<f32, 2>([-80, -80])), Err(Error::Overflow));
        assert_eq!(
            check_det(&diag::<f64, 3>([-400, -400, -400])),
            Err(Error::Overflow)
        );
        // det 2¹⁴⁰ overflows.
        assert_eq!(check_det(&diag::<f32, 2>([70, 70])), Err(Error::Overflow));
        // Singular or inverted: NonPositiveJ.
        let s = Mat::<f32, 2>::from_rows([[1.0, 2.0], [2.0, 4.0]]);
        assert_eq!(check_det(&s), Err(Error::NonPositiveJ));
        assert_eq!(
            check_det(&(diag::<f64, 2>([0, 0]) * -1.0)).map(|_| ()),
            Ok(())
        );
        let r = Mat::<f64, 3>::from_diagonal([1.0, 1.0, -1.0]);
        assert_eq!(check_det(&r), Err(Error::NonPositiveJ));
        // Non-finite.
        assert_eq!(
            check_det(&(diag::<f32, 2>([0, 0]) * f32::INFINITY)),
            Err(Error::Overflow)
        );
    }

    #[test]
    fn root_det_beyond_the_range_of_det() {
        assert_eq!(root_det(&diag::<f32, 2>([-100, -60])), Ok(2f32.powi(-80)));
        assert_eq!(root_det(&diag::<f32, 2>([100, 60])), Ok(2f32.powi(80)));
        assert_eq!(
            root_det(&diag::<f32, 3>([-90, -60, -30])),
            Ok(2f32.powi(-60))
        );
        assert_eq!(
            root_det(&diag::<f64, 3>([-700, -701, -702])),
            Ok(2f64.powi(-701))
        );
        assert_eq!(
            root_det(&(diag::<f64, 3>([0, 0, 0]) * -1.0)),
            Err(Error::NonPositiveJ)
        );
        assert_eq!(
            root_det(&(diag::<f32, 2>([0, 0]) * f32::NAN)),
            Err(Error::NonFinite)
        );
    }

    #[test]
    fn liquid_projection_keeps_the_volume_ratios_only() {
        let fe = Mat::<f64, 3>::from_rows([[1.2, 0.3, 0.0], [0.1, 0.9, 0.2], [0.0, -0.1, 1.1]]);
        let fp = Mat::<f64, 3>::from_rows([[1.1, 0.2, 0.05], [-0.1, 0.9, 0.1], [0.03, 0.07, 1.05]]);
        let (je, jp) = (Matrix::det(&fe), Matrix::det(&fp));
        let (fe2, fp2) = liquid_projection(&fe, &fp).unwrap();
        assert!(isotropic_scale(&fe2).is_some() && isotropic_scale(&fp2).is_some());
        // Roots (≤ 1 ulp) cubed, and the determinants' own rounding: 16ε is ample here.
        let tol = 16.0 * f64::EPSILON;
        assert!((Matrix::det(&fe2) / je - 1.0).abs() <= tol);
        assert!((Matrix::det(&fp2) / jp - 1.0).abs() <= tol);
        // An isotropic F_P is kept bit for bit, step after step.
        let shear = Mat::<f32, 2>::from_rows([[1.0, 0.01], [0.0, 1.0]]);
        let mut fe = Mat::<f32, 2>::from_diagonal([0.9; 2]);
        let fp = Mat::<f32, 2>::from_diagonal([1.3; 2]);
        for _ in 0..1000 {
            let (a, b) = liquid_projection(&(shear * fe), &fp).unwrap();
            assert_eq!(b, fp);
            // det(shear) = 1 and √(s²) = s: J_E does not move either.
            assert_eq!(a, fe);
            fe = a;
        }
    }

    #[test]
    fn liquid_step_takes_the_root_of_det_a() {
        let a = Mat::<f64, 3>::from_rows([
            [1.01, 0.003, -0.002],
            [0.001, 0.985, 0.004],
            [-0.003, 0.002, 1.02],
        ]);
        let fp = Mat::<f64, 3>::from_rows([[1.1, 0.2, 0.05], [-0.1, 0.9, 0.1], [0.03, 0.07, 1.05]]);
        let s = 0.97;
        let fe = Mat::<f64, 3>::from_diagonal([s; 3]);
        let (fe2, fp2) = liquid_step(&fe, &a, &fp).unwrap();
        // The isotropic branch: s (det A)^{1/3}, the F_P projection unchanged.
        assert_eq!(fe2, Mat::from_diagonal([s * Matrix::det(&a).cbrt(); 3]));
        assert_eq!(fp2, liquid_projection(&fe, &fp).unwrap().1);
        // The projection of the product A F_E agrees to the rounding of the product, its
        // determinant and the roots (a few ε each): 16ε.
        let (fe3, _) = liquid_projection(&(a * fe), &fp).unwrap();
        assert!((fe2.cols[0][0] / fe3.cols[0][0] - 1.0).abs() <= 16.0 * f64::EPSILON);
        // A general F_E (a solid that has just melted) is multiplied out, as before.
        let g = Mat::<f64, 3>::from_rows([[1.2, 0.3, 0.0], [0.1, 0.9, 0.2], [0.0, -0.1, 1.1]]);
        assert_eq!(liquid_step(&g, &a, &fp), liquid_projection(&(a * g), &fp));
        // det A subnormal (2^-135 in f32): the root on equilibrated columns, exact here.
        let a = diag::<f32, 3>([-64, -64, -7]);
        let fe = Mat::<f32, 3>::from_diagonal([2f32.powi(20); 3]);
        let (fe2, _) = liquid_step(&fe, &a, &fe).unwrap();
        assert_eq!(fe2, Mat::from_diagonal([2f32.powi(-25); 3]));
        // s (det A)^{1/d} overflowing is refused.
        let fe = Mat::<f32, 2>::from_diagonal([2f32.powi(100); 2]);
        let a = diag::<f32, 2>([60, 60]);
        assert_eq!(liquid_step(&fe, &a, &fe), Err(Error::Overflow));
    }

    #[test]
    fn unclamped_snow_is_the_identity() {
        let snow = Snow {
            critical_compression: 0.1f64,
            critical_stretch: 0.1,
            hardening: 10.0,
        };
        let fe = Mat::<f64, 2>::from_rows([[1.01, 0.02], [-0.03, 0.99]]);
        let fp = Mat::<f64, 2>::from_rows([[1.5, 0.7], [0.2, 0.9]]);
        assert_eq!(snow_plasticity(&snow, &fe, &fp), Ok((fe, fp)));
    }
}
