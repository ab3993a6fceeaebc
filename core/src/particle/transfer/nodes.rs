//! Addressing a particle's stencil nodes in a grid view, and the per-node weights.

use super::{Channel, NodeBox};
use crate::error::{Error, Result};
use crate::particle::stencil::Stencil;
use crate::scalar::Real;

/// `base − lo` of a stencil in a box, after checking that all `K^d` nodes are inside it.
#[inline(always)]
pub(crate) fn rel_base<T: Real, const D: usize>(
    s: &Stencil<T, D>,
    b: &NodeBox<D>,
) -> Result<[isize; D]> {
    let k = s.kernel.width() as i64;
    let mut r = [0isize; D];
    for a in 0..D {
        let ra = s.base[a] as i64 - b.lo[a] as i64;
        if ra < 0 || ra + k > b.dims[a] as i64 {
            return Err(Error::OutsideGrid);
        }
        r[a] = ra as isize;
    }
    Ok(r)
}

/// Per-axis offsets `o` of stencil node `r` (axis 0 fastest), `K` nodes per axis.
#[inline(always)]
pub(crate) fn offsets<const D: usize, const K: usize>(r: usize) -> [usize; D] {
    let mut o = [0usize; D];
    let mut q = r;
    for oa in o.iter_mut() {
        *oa = q % K;
        q /= K;
    }
    o
}

/// Clears `ok` if `x` is not finite (a bit test, not a chain of floating-point adds).
#[inline(always)]
pub(crate) fn taint<T: Real>(ok: &mut bool, x: T) {
    *ok &= x.is_finite();
}

/// The nodes of a stencil in stencil order (axis 0 fastest): offsets, weights and weight
/// gradients, with the products of [`Stencil::node`] in its order (`w = w₀·w₁·w₂` left to
/// right; `∂w/∂x_a = dw_a` times the other axes' weights in axis order).
pub(crate) struct Nodes<T, const D: usize> {
    /// Number of nodes, `K^d`.
    pub n: usize,
    /// Per-axis offsets of each node.
    pub o: [[usize; D]; 64],
    /// Weights.
    pub w: [T; 64],
    /// Weight gradients (1/m).
    pub g: [[T; D]; 64],
}

/// The [`Nodes`] of a stencil with `K` nodes per axis.
#[inline(always)]
pub(crate) fn nodes<T: Real, const D: usize, const K: usize>(s: &Stencil<T, D>) -> Nodes<T, D> {
    let mut nd = Nodes {
        n: K.pow(D as u32),
        o: [[0; D]; 64],
        w: [T::ZERO; 64],
        g: [[T::ZERO; D]; 64],
    };
    let (w, dw) = (&s.w, &s.dw);
    for r in 0..nd.n {
        let o = offsets::<D, K>(r);
        let mut wt = w[0][o[0]];
        for a in 1..D {
            wt *= w[a][o[a]];
        }
        for a in 0..D {
            let mut p = dw[a][o[a]];
            for b in 0..D {
                if b != a {
                    p *= w[b][o[b]];
                }
            }
            nd.g[r][a] = p;
        }
        nd.o[r] = o;
        nd.w[r] = wt;
    }
    nd
}

/// Per-axis offset tables of a channel for one stencil: the node with offsets `o` is at
/// `Σ_a t[a][o_a]` from `data`.
#[inline(always)]
pub(crate) fn table<P, const D: usize>(c: &Channel<P, D>, rel: &[isize; D]) -> [[isize; 4]; D] {
    let mut t = [[0isize; 4]; D];
    for a in 0..D {
        for (o, x) in t[a].iter_mut().enumerate() {
            *x = (rel[a] + o as isize) * c.stride[a];
        }
    }
    t
}

/// The offset of node `o` from a table of [`table`].
#[inline(always)]
pub(crate) fn off<const D: usize>(t: &[[isize; 4]; D], o: &[usize; D]) -> isize {
    let mut s = t[0][o[0]];
    for a in 1..D {
        s += t[a][o[a]];
    }
    s
}
