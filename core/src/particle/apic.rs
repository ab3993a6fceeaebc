//! APIC transfers of one particle (Jiang, Schroeder, Selle, Teran, Stomakhin 2015, "The affine
//! particle-in-cell method", §5.3 and §6 for MAC grids).
//!
//! With `D_p = Σ_i w_i (x_i − x_p)(x_i − x_p)ᵀ = κ h² I` (`κ` = [`Kernel::apic_moment`]: ¼
//! quadratic, ⅓ cubic, exact for every particle position) and the affine matrix
//! `C_p = B_p D_p⁻¹`:
//! - P2G: `m_i += w_i m_p`, `(m v)_i += w_i m_p (v_p + C_p (x_i − x_p))`;
//! - G2P: `v_p = Σ w_i v_i`, `B_p = Σ w_i v_i (x_i − x_p)ᵀ`, `C_p = B_p D_p⁻¹`, and
//!   `∇v_p = Σ v_i ∇w_iᵀ` for the deformation update.
//!
//! On a MAC grid each component `a` is transferred on its own face grid
//! ([`super::Grid::Face`]) with the scalar versions below: row `a` of `C_p` and `∇v_p`.
//! Per-node slices are in stencil order (see [`super::stencil`]).

use super::stencil::{Kernel, Stencil};
use crate::error::{Error, Result};
use crate::mat::Mat;
use crate::scalar::Real;

/// What G2P gathers from a collocated grid.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Gathered<T, const D: usize> {
    /// `v_p = Σ w_i v_i` (m/s).
    pub v: [T; D],
    /// `C_p = B_p D_p⁻¹` (1/s).
    pub affine: Mat<T, D>,
    /// `∇v_p = Σ v_i ∇w_iᵀ` (1/s).
    pub grad_v: Mat<T, D>,
}

/// What G2P gathers for one scalar component (a MAC face component or a temperature).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GatheredScalar<T, const D: usize> {
    /// `Σ w_i q_i`.
    pub value: T,
    /// `(Σ w_i q_i (x_i − x_p)) / (κ h²)`: the APIC affine row (units of `q` per m).
    pub affine: [T; D],
    /// `Σ q_i ∇w_i` (units of `q` per m).
    pub grad: [T; D],
}

/// `1/(κ h²)` (1/m²), the inverse APIC moment `D_p⁻¹` as a scalar, formed as
/// `(1/(κ h))/h` so that `h²` never under- or overflows on its own.
///
/// Errors: [`Error::NonFinite`] for a NaN/inf `h`, [`Error::InvalidArgument`] for `h ≤ 0`,
/// [`Error::Overflow`] when the result is not representable (inf for a tiny `h`, 0 for a
/// huge one).
#[inline]
pub fn inv_moment<T: Real>(kernel: Kernel, h: T) -> Result<T> {
    let inv_kh = inv_kappa_h(kernel, h)?;
    let m = inv_kh / h;
    if m.is_finite() && m > T::ZERO {
        Ok(m)
    } else {
        Err(Error::Overflow)
    }
}

/// `1/(κ h)` (1/m): the gathers form `C_p = (Σ_i w_i q_i ((x_i − x_p)/h)ᵀ) / (κ h)` with the
/// offsets in cells, `(x_i − x_p)/h = o − fx` (see [`super::stencil`]), so no `h²` appears.
///
/// Errors: as [`inv_moment`] (a positive finite `h` has `1/(κ h) > 0`, so only inf
/// overflows).
#[inline]
pub(crate) fn inv_kappa_h<T: Real>(kernel: Kernel, h: T) -> Result<T> {
    if !h.is_finite() {
        return Err(Error::NonFinite);
    }
    if h <= T::ZERO {
        return Err(Error::InvalidArgument);
    }
    let inv_kh = T::ONE / (kernel.apic_moment::<T>() * h);
    if inv_kh.is_finite() {
        Ok(inv_kh)
    } else {
        Err(Error::Overflow)
    }
}

/// `(x_i − x_p)/h = o − fx` of node `r`, in cells (`|·| ≤ 2`).
#[inline]
fn cell_offsets<T: Real, const D: usize>(s: &Stencil<T, D>, r: usize) -> [T; D] {
    let o = s.offsets(r);
    let mut e = [T::ZERO; D];
    for a in 0..D {
        e[a] = T::from_i32(o[a] as i32) - s.fx[a];
    }
    e
}

/// G2P from a collocated grid: node velocities `vel[r]` (m/s) in stencil order.
///
/// Errors: [`Error::InvalidArgument`] when `vel` is shorter than the stencil;
/// [`Error::NonFinite`] for a NaN/inf node velocity; [`Error::Overflow`] when a result of
/// finite inputs is not representable (also `1/(κ h)` for a tiny finite `h`).
#[inline]
pub fn gather<T: Real, const D: usize>(
    s: &Stencil<T, D>,
    vel: &[[T; D]],
) -> Result<Gathered<T, D>> {
    if vel.len() < s.len() {
        return Err(Error::InvalidArgument);
    }
    let inv_kh = inv_kappa_h(s.kernel, s.h)?;
    let mut v = [T::ZERO; D];
    let mut b = Mat::<T, D>::ZERO;
    let mut g = Mat::<T, D>::ZERO;
    let mut inputs_finite = true;
    for (r, vi) in vel.iter().enumerate().take(s.len()) {
        let n = s.node(r);
        let e = cell_offsets(s, r);
        for j in 0..D {
            for i in 0..D {
                b.cols[j][i] += n.weight * vi[i] * e[j];
                g.cols[j][i] += vi[i] * n.grad[j];
            }
        }
        for i in 0..D {
            inputs_finite &= vi[i].is_finite();
            v[i] += n.weight * vi[i];
        }
    }
    if !inputs_finite {
        return Err(Error::NonFinite);
    }
    let out = Gathered {
        v,
        affine: b * inv_kh,
        grad_v: g,
    };
    if v.iter().all(|x| x.is_finite()) && out.affine.is_finite() && g.is_finite() {
        Ok(out)
    } else {
        Err(Error::Overflow)
    }
}

/// G2P of one scalar field `q[r]` in stencil order (a MAC component on its face stencil, or a
/// temperature).
///
/// Errors: as [`gather`].
#[inline]
pub fn gather_scalar<T: Real, const D: usize>(
    s: &Stencil<T, D>,
    q: &[T],
) -> Result<GatheredScalar<T, D>> {
    if q.len() < s.len() {
        return Err(Error::InvalidArgument);
    }
    let inv_kh = inv_kappa_h(s.kernel, s.h)?;
    let mut value = T::ZERO;
    let mut affine = [T::ZERO; D];
    let mut grad = [T::ZERO; D];
    let mut inputs_finite = true;
    for (r, &qi) in q.iter().enumerate().take(s.len()) {
        let n = s.node(r);
        let e = cell_offsets(s, r);
        inputs_finite &= qi.is_finite();
        value += n.weight * qi;
        for a in 0..D {
            affine[a] += n.weight * qi * e[a];
            grad[a] += qi * n.grad[a];
        }
    }
    if !inputs_finite {
        return Err(Error::NonFinite);
    }
    for x in affine.iter_mut() {
        *x *= inv_kh;
    }
    let ok = value.is_finite()
        && affine.iter().all(|x| x.is_finite())
        && grad.iter().all(|x| x.is_finite());
    if ok {
        Ok(GatheredScalar {
            value,
            affine,
            grad,
        })
    } else {
        Err(Error::Overflow)
    }
}

/// P2G momentum of node `r` on a collocated grid: `w_i m_p (v_p + C_p (x_i − x_p))` (kg·m/s).
#[inline]
#[must_use]
pub fn node_momentum<T: Real, const D: usize>(
    s: &Stencil<T, D>,
    r: usize,
    mass: T,
    v: &[T; D],
    affine: &Mat<T, D>,
) -> [T; D] {
    let n = s.node(r);
    let c = affine.mul_vec(n.dx);
    let wm = n.weight * mass;
    let mut p = [T::ZERO; D];
    for a in 0..D {
        p[a] = wm * (v[a] + c[a]);
    }
    p
}

/// P2G momentum component of node `r` on a face grid: `w_i m_p (v_a + c_a·(x_i − x_p))`,
/// with `c_a` row `a` of `C_p`.
#[inline]
#[must_use]
pub fn node_momentum_scalar<T: Real, const D: usize>(
    s: &Stencil<T, D>,
    r: usize,
    mass: T,
    v_a: T,
    affine_row: &[T; D],
) -> T {
    let n = s.node(r);
    let mut c = T::ZERO;
    for a in 0..D {
        c += affine_row[a] * n.dx[a];
    }
    n.weight * mass * (v_a + c)
}
