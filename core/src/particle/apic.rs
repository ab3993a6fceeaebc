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

/// `1/(κ h²)`, the inverse APIC moment `D_p⁻¹` as a scalar.
#[inline]
#[must_use]
pub fn inv_moment<T: Real>(kernel: Kernel, h: T) -> T {
    T::ONE / (kernel.apic_moment::<T>() * h * h)
}

/// G2P from a collocated grid: node velocities `vel[r]` (m/s) in stencil order.
///
/// Errors: [`Error::InvalidArgument`] when `vel` is shorter than the stencil;
/// [`Error::NonFinite`] when a result is not finite.
#[inline]
pub fn gather<T: Real, const D: usize>(
    s: &Stencil<T, D>,
    vel: &[[T; D]],
) -> Result<Gathered<T, D>> {
    if vel.len() < s.len() {
        return Err(Error::InvalidArgument);
    }
    let mut v = [T::ZERO; D];
    let mut b = Mat::<T, D>::ZERO;
    let mut g = Mat::<T, D>::ZERO;
    for (r, vi) in vel.iter().enumerate().take(s.len()) {
        let n = s.node(r);
        for j in 0..D {
            for i in 0..D {
                b.cols[j][i] += n.weight * vi[i] * n.dx[j];
                g.cols[j][i] += vi[i] * n.grad[j];
            }
        }
        for i in 0..D {
            v[i] += n.weight * vi[i];
        }
    }
    let out = Gathered {
        v,
        affine: b * inv_moment(s.kernel, s.h),
        grad_v: g,
    };
    if v.iter().all(|x| x.is_finite()) && out.affine.is_finite() && g.is_finite() {
        Ok(out)
    } else {
        Err(Error::NonFinite)
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
    let mut value = T::ZERO;
    let mut affine = [T::ZERO; D];
    let mut grad = [T::ZERO; D];
    for (r, &qi) in q.iter().enumerate().take(s.len()) {
        let n = s.node(r);
        value += n.weight * qi;
        for a in 0..D {
            affine[a] += n.weight * qi * n.dx[a];
            grad[a] += qi * n.grad[a];
        }
    }
    let inv = inv_moment(s.kernel, s.h);
    for x in affine.iter_mut() {
        *x *= inv;
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
        Err(Error::NonFinite)
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
