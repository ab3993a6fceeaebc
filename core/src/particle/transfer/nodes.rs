//! Addressing a particle's stencil nodes in a grid view, and the per-node weights.

use super::{Channel, NodeBox};
use crate::error::{Error, Result};
use crate::lane::Lane;
use crate::particle::stencil::Stencil;
use crate::scalar::Real;
use core::mem::MaybeUninit;
use core::ptr;

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

/// Per-axis offsets of the `N = K^d` stencil nodes (axis 0 fastest), a compile-time table.
pub(crate) struct Offsets<const D: usize, const K: usize, const N: usize>;

impl<const D: usize, const K: usize, const N: usize> Offsets<D, K, N> {
    /// `O[i][a]`: the offset along axis `a` of node `i = Σ_a o_a K^a`.
    pub(crate) const O: [[usize; D]; N] = {
        let mut o = [[0usize; D]; N];
        let mut r = 0;
        while r < N {
            let mut q = r;
            let mut a = 0;
            while a < D {
                o[r][a] = q % K;
                q /= K;
                a += 1;
            }
            r += 1;
        }
        o
    };
}

/// Clears `ok` if `x` is not finite (a bit test, not a chain of floating-point adds).
#[inline(always)]
pub(crate) fn taint<T: Real>(ok: &mut bool, x: T) {
    *ok &= x.is_finite();
}

/// The nodes of a stencil as arrays over the node index `i = Σ_a o_a K^a` (axis 0 fastest,
/// `N = K^d` nodes): weights and weight gradients (1/m). Formed row by row (a row is the `K`
/// nodes that differ in axis 0 only): with `c = w₁·w₂` (the other axes' weights, in axis
/// order) and `c_a` the same product with `dw_a` in place of `w_a`, `w = w₀·c`,
/// `∂w/∂x₀ = dw₀·c`, `∂w/∂x_a = w₀·c_a` (`a ≥ 1`). Arrays over nodes let the per-node
/// arithmetic of a particle run on SIMD lanes.
pub(crate) struct Nodes<T, const D: usize, const N: usize> {
    /// Weights.
    pub w: [T; N],
    /// Weight gradients per axis (1/m).
    pub g: [[T; N]; D],
}

/// The factors of stencil row `r` (the nodes `r·K .. r·K + K`): `c[0]` the product of the
/// weights of axes `1..d` in axis order, `c[a]` (`a ≥ 1`) the same with `dw_a` for `w_a`.
#[inline(always)]
pub(crate) fn row_factors<T: Real, const D: usize, const K: usize, const N: usize>(
    s: &Stencil<T, D>,
    r: usize,
) -> [T; D] {
    let o = Offsets::<D, K, N>::O[r * K];
    let mut c = [T::ONE; D];
    for a in 1..D {
        for (b, cb) in c.iter_mut().enumerate() {
            *cb *= if b == a { s.dw[a][o[a]] } else { s.w[a][o[a]] };
        }
    }
    c
}

/// The [`Nodes`] of a stencil with `K` nodes per axis (`N = K^d`).
#[inline(always)]
pub(crate) fn nodes<T: Real, const D: usize, const K: usize, const N: usize>(
    s: &Stencil<T, D>,
) -> Nodes<T, D, N> {
    debug_assert_eq!(N, K.pow(D as u32));
    let mut nd = Nodes {
        w: [T::ZERO; N],
        g: [[T::ZERO; N]; D],
    };
    let (w, dw) = (&s.w, &s.dw);
    for r in 0..N / K {
        let c = row_factors::<T, D, K, N>(s, r);
        for o0 in 0..K {
            let i = r * K + o0;
            nd.w[i] = w[0][o0] * c[0];
            nd.g[0][i] = dw[0][o0] * c[0];
            for a in 1..D {
                nd.g[a][i] = w[0][o0] * c[a];
            }
        }
    }
    nd
}

/// The lane indices `[0, 1, …, 7]` as scalars (a constant vector).
#[inline(always)]
pub(crate) fn lane_index<T: Real, R: Lane<Scalar = T>>() -> R {
    let mut l = [T::ZERO; ROW_LANES];
    for (i, x) in l.iter_mut().enumerate() {
        *x = T::from_i32(i as i32);
    }
    R::load(&l)
}

/// Evaluates `body` with the constants `K` (nodes per axis of `kernel`) and `N = K^d` (nodes
/// of a stencil in dimension `d`) in scope, for the const-generic node loops.
macro_rules! with_nodes {
    ($kernel:expr, $d:expr, |$k:ident, $n:ident| $body:expr) => {
        match ($kernel, $d == 2) {
            ($crate::particle::stencil::Kernel::Quadratic, true) => {
                const $k: usize = 3;
                const $n: usize = 9;
                $body
            }
            ($crate::particle::stencil::Kernel::Quadratic, false) => {
                const $k: usize = 3;
                const $n: usize = 27;
                $body
            }
            ($crate::particle::stencil::Kernel::Cubic, true) => {
                const $k: usize = 4;
                const $n: usize = 16;
                $body
            }
            ($crate::particle::stencil::Kernel::Cubic, false) => {
                const $k: usize = 4;
                const $n: usize = 64;
                $body
            }
        }
    };
}
pub(crate) use with_nodes;

/// The offsets `o_a` of every node as scalars, per axis (`N = K^d` nodes, as [`Nodes`]).
#[inline(always)]
pub(crate) fn node_offsets<T: Real, const D: usize, const K: usize, const N: usize>() -> [[T; N]; D]
{
    let c = [T::ZERO, T::ONE, T::TWO, T::from_i32(3)];
    let mut oc = [[T::ZERO; N]; D];
    for r in 0..N {
        let o = Offsets::<D, K, N>::O[r];
        for a in 0..D {
            oc[a][r] = c[o[a]];
        }
    }
    oc
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

/// The offset of the first node of stencil row `r` from a table of [`table`]: row `r` holds
/// the `K` nodes `r·K .. r·K + K`, which differ in axis 0 only (node `r·K + o₀` is `o₀·stride[0]`
/// further).
#[inline(always)]
pub(crate) fn row_off<const D: usize, const K: usize, const N: usize>(
    t: &[[isize; 4]; D],
    r: usize,
) -> isize {
    let o = Offsets::<D, K, N>::O[r * K];
    let mut s = t[0][0];
    for a in 1..D {
        s += t[a][o[a]];
    }
    s
}

/// Lanes of the row vectors: the eight lanes of the row types of
/// [`crate::kernel::batch::LaneOp::run_rows`].
const ROW_LANES: usize = 8;

/// Adds `val` to an output channel at the `N = K^d` stencil nodes, keeping each old value in
/// `old`. Returns whether every new value is finite (all are written either way; [`restore`]
/// puts the old ones back). With `s0 = 1` (separate node arrays) a row of `K` nodes is one
/// contiguous partial vector.
///
/// # Safety
/// Every stencil node is inside the channel's box (checked by [`rel_base`]), and the channel
/// is valid for reading and writing.
#[inline(always)]
pub(crate) unsafe fn add<
    T: Real,
    R: Lane<Scalar = T>,
    const D: usize,
    const K: usize,
    const N: usize,
>(
    data: *mut T,
    t: &[[isize; 4]; D],
    s0: isize,
    val: &[T; N],
    old: &mut [MaybeUninit<T>; N],
) -> bool {
    let mut ok = true;
    if s0 == 1 && K <= R::LANES {
        // A row as one partial vector (lanes `K..` are 0 in both terms, so finite).
        for r in 0..N / K {
            let p = data.offset(row_off::<D, K, N>(t, r));
            let x = R::load_n(p, K);
            let nv = x + R::load_n(val.as_ptr().add(r * K), K);
            ok &= R::all(nv.is_finite());
            x.store_n(old.as_mut_ptr().add(r * K).cast::<T>(), K);
            nv.store_n(p, K);
        }
        return ok;
    }
    for r in 0..N / K {
        let p = data.offset(row_off::<D, K, N>(t, r));
        let x: [T; K] = if s0 == 1 {
            ptr::read_unaligned(p as *const [T; K])
        } else {
            core::array::from_fn(|o| ptr::read_unaligned(p.offset(o as isize * s0)))
        };
        let mut nv = x;
        for o in 0..K {
            nv[o] += val[r * K + o];
            taint(&mut ok, nv[o]);
            old[r * K + o].write(x[o]);
        }
        if s0 == 1 {
            ptr::write_unaligned(p as *mut [T; K], nv);
        } else {
            for o in 0..K {
                ptr::write_unaligned(p.offset(o as isize * s0), nv[o]);
            }
        }
    }
    ok
}

/// Puts back the old values that [`add`] kept, last written first (so that a node reached
/// twice through aliased channels gets its first old value back).
///
/// # Safety
/// As [`add`], with `old` filled by it for the same channel and stencil.
#[inline(always)]
pub(crate) unsafe fn restore<T: Real, const D: usize, const K: usize, const N: usize>(
    data: *mut T,
    t: &[[isize; 4]; D],
    s0: isize,
    old: &[MaybeUninit<T>; N],
) {
    for r in (0..N / K).rev() {
        let p = data.offset(row_off::<D, K, N>(t, r));
        for o in (0..K).rev() {
            ptr::write_unaligned(p.offset(o as isize * s0), old[r * K + o].assume_init());
        }
    }
}
