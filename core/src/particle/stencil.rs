//! Interpolation stencils: quadratic and cubic B-spline weights and weight gradients of one
//! particle, on a collocated grid or on one MAC face grid.
//!
//! **Grids.** The host's grid has spacing `h` (m) and its origin at position 0: the host
//! passes particle positions relative to its grid origin. Cells are `[i h, (i+1) h]` per axis.
//! - [`Grid::Collocated`]: nodes at `x_i = i h` (cell corners), all velocity components there.
//! - [`Grid::Face`]`(a)`: the grid of the `a`-th velocity component of a MAC grid, nodes at
//!   `i h` along axis `a` and at cell centres `(j + ½) h` along every other axis.
//!
//! The position limit is `|x/h| < 2³⁰` per axis (cell indices well inside `i32`): beyond it
//! a stencil is refused with [`Error::InvalidArgument`]. A finite `h > 0` so small that
//! `1/h` is not representable is [`Error::Overflow`].
//!
//! **Node indexing.** A stencil covers `K^d` nodes, `K = 3` (quadratic) or `4` (cubic): the
//! grid nodes `base + o`, `o ∈ {0, …, K−1}^d`. Node `r ∈ [0, K^d)` has offsets
//! `o_a = (r / K^a) mod K` (axis 0 fastest), so `r = Σ_a o_a K^a`. Every per-node array of the
//! particle module (Rust slices and C arrays) is in this order.
//!
//! **Kernels.** Tensor products `w_i = Π_a N((x_p,a − x_i,a)/h)` of the centred B-splines
//! (Steffen, Kirby, Berzins 2008; the MPM choice of Stomakhin et al. 2013 §5 and 2014 §7):
//! - quadratic: `N(d) = ¾ − d²` for `|d| < ½`, `½(³⁄₂ − |d|)²` for `½ ≤ |d| < ³⁄₂`, else 0;
//! - cubic: `N(d) = ½|d|³ − d² + ⅔` for `|d| < 1`, `(2 − |d|)³/6` for `1 ≤ |d| < 2`, else 0.
//!
//! `∇w_i = ∂w_i/∂x_p` (1/m), component `a` being `N'(d_a)/h · Π_{b≠a} N(d_b)`.
//!
//! **Precision.** The particle's position inside the stencil is kept in cell units
//! (`fx_a = x_a/h − s_a − base_a ∈ [½, ³⁄₂)` quadratic, `[1, 2)` cubic); the fractional part
//! `ξ − ⌊ξ⌋` is exact in binary floating point, so the weights do not lose accuracy far from
//! the origin, and `x_i − x_p = (o − fx) h` is formed without cancellation.

use crate::error::{Error, Result};
use crate::lane::Lane;
use crate::scalar::Real;
use core::mem::size_of;
use core::ptr::{addr_of_mut, write_volatile};

/// Most nodes per axis of a stencil (the cubic kernel).
pub(crate) const MAX_WIDTH: usize = 4;

/// The B-spline interpolation kernel.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Kernel {
    /// Quadratic B-spline, 3 nodes per axis.
    Quadratic,
    /// Cubic B-spline, 4 nodes per axis.
    Cubic,
}

impl Kernel {
    /// Nodes per axis, `K` (3 or 4).
    #[inline]
    #[must_use]
    pub const fn width(self) -> usize {
        match self {
            Kernel::Quadratic => 3,
            Kernel::Cubic => 4,
        }
    }

    /// Nodes of the stencil, `K^d`.
    #[inline]
    #[must_use]
    pub const fn node_count(self, d: usize) -> usize {
        let k = self.width();
        if d == 2 {
            k * k
        } else {
            k * k * k
        }
    }

    /// `D_p / h²` of APIC, the kernel's second moment: `Σ_i w_i (x_i − x_p)(x_i − x_p)ᵀ =
    /// (D_p/h²) h² I`, independent of the particle's position: ¼ (quadratic), ⅓ (cubic)
    /// (Jiang et al. 2015, "The affine particle-in-cell method", §5.3).
    #[inline]
    #[must_use]
    pub fn apic_moment<T: Real>(self) -> T {
        match self {
            Kernel::Quadratic => T::from_f64(0.25),
            Kernel::Cubic => T::ONE / T::from_i32(3),
        }
    }

    /// `N(d)`, the 1D B-spline at signed distance `d` (in cells).
    #[inline]
    #[must_use]
    pub fn n<T: Real>(self, d: T) -> T {
        self.n_dn(d).0
    }

    /// `(N(d), N'(d))`: the 1D B-spline and its derivative at signed distance `d` (cells).
    #[inline(always)]
    #[must_use]
    pub fn n_dn<T: Real>(self, d: T) -> (T, T) {
        self.n_dn_lanes(d)
    }

    /// [`Kernel::n_dn`] on every lane of `d`: each piece is evaluated and the lane takes the
    /// piece of its `|d|` (the scalar path is this with one lane). The pieces are written
    /// with separate multiplications and additions, never fused, so that the lanes and the
    /// scalar give the same bits.
    #[inline(always)]
    pub(crate) fn n_dn_lanes<V: Lane>(self, d: V) -> (V, V) {
        let c = |x: f64| V::splat(V::Scalar::from_f64(x));
        let ad = d.abs();
        let zero = c(0.0);
        match self {
            Kernel::Quadratic => {
                // |d| < ½: ¾ − d², −2d; ½ ≤ |d| < ³⁄₂: ½ e², −sign(d) e with e = ³⁄₂ − |d|.
                let e = c(1.5) - ad;
                let (n1, dn1) = (c(0.75) - d * d, -(d + d));
                let (n2, dn2) = (c(0.5) * e * e, -(e.copysign(d)));
                let (inner, outer) = (ad.lt(c(0.5)), ad.lt(c(1.5)));
                (
                    V::select(inner, n1, V::select(outer, n2, zero)),
                    V::select(inner, dn1, V::select(outer, dn2, zero)),
                )
            }
            Kernel::Cubic => {
                // |d| < 1: ½|d|³ − d² + ⅔, (3/2)|d|d − 2d; 1 ≤ |d| < 2: e³/6, −sign(d) ½e²
                // with e = 2 − |d|.
                let two = V::Scalar::TWO;
                let third2 = V::splat(two / V::Scalar::from_i32(3));
                let n1 = (c(0.5) * ad - c(1.0)) * d * d + third2;
                let dn1 = (c(1.5) * ad - c(2.0)) * d;
                let e = c(2.0) - ad;
                let n2 = e * e * e / c(6.0);
                let dn2 = -((c(0.5) * e * e).copysign(d));
                let (inner, outer) = (ad.lt(c(1.0)), ad.lt(c(2.0)));
                (
                    V::select(inner, n1, V::select(outer, n2, zero)),
                    V::select(inner, dn1, V::select(outer, dn2, zero)),
                )
            }
        }
    }
}

/// Which grid the stencil interpolates from (see the module docs for node positions).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Grid {
    /// Nodes at `i h`.
    Collocated,
    /// The MAC face grid of velocity component `a < d`: nodes at `i h` along `a`, at
    /// `(j + ½) h` along the other axes.
    Face(usize),
}

/// One node of a stencil.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Node<T, const D: usize> {
    /// Integer grid index `base + o` of the node.
    pub index: [i32; D],
    /// Weight `w_i` (dimensionless).
    pub weight: T,
    /// Weight gradient `∇w_i = ∂w_i/∂x_p` (1/m).
    pub grad: [T; D],
    /// `x_i − x_p` (m).
    pub dx: [T; D],
}

/// The B-spline stencil of one particle: per-axis weights, their derivatives, and the base
/// node (see the module docs for the node order).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Stencil<T, const D: usize> {
    /// The kernel (3 or 4 nodes per axis).
    pub kernel: Kernel,
    /// Grid spacing `h` (m).
    pub h: T,
    /// Grid index of node `o = 0`.
    pub base: [i32; D],
    /// Particle position relative to the base node, in cells (`[½, ³⁄₂)` or `[1, 2)`).
    pub fx: [T; D],
    /// Per-axis weights `N(fx_a − o)`, `o < K` (unused entries 0).
    pub w: [[T; MAX_WIDTH]; D],
    /// Per-axis derivatives `N'(fx_a − o)/h` (1/m).
    pub dw: [[T; MAX_WIDTH]; D],
}

/// The position limit: positions with `|x/h| ≥ 2³⁰` (cell indices that do not fit
/// comfortably in `i32`) are refused.
const MAX_CELLS: f64 = 1_073_741_824.0; // 2^30

/// The stencils of a chunk on SIMD lanes, stencil `l` in lane `l`: per axis `fx`, the weights
/// `w[a][o]` and the derivatives `dw[a][o]` (1/m) of [`Stencil`] (`o < K`; the other entries
/// 0), as [`Stencil::new_lanes`] computes them, the values it writes into the stencils (so
/// that a caller that sums on lanes does not read them back from the stencils).
pub(crate) struct StencilLanes<V> {
    pub fx: [V; 3],
    pub w: [[V; MAX_WIDTH]; 3],
    pub dw: [[V; MAX_WIDTH]; 3],
    /// Whether `new_lanes` also writes the weights and derivatives into the stencils (`true`
    /// from [`StencilLanes::new`]); if not, the stencils' `w` and `dw` are left as they are,
    /// for a caller that reads them only from the lanes.
    pub records: bool,
}

impl<T: Real, V: Lane<Scalar = T>> StencilLanes<V> {
    /// Every entry 0; the stencils' weights written too.
    #[inline(always)]
    pub fn new() -> Self {
        let z = V::splat(T::ZERO);
        Self {
            fx: [z; 3],
            w: [[z; MAX_WIDTH]; 3],
            dw: [[z; MAX_WIDTH]; 3],
            records: true,
        }
    }

    /// `fx`, the weights and derivatives of `stencils[0..V::LANES]` (`K` nodes per axis),
    /// stencil `l` in lane `l`, read from the stencils.
    #[cfg(test)]
    pub fn of<const D: usize, const K: usize>(stencils: &[Stencil<T, D>]) -> Self {
        debug_assert!(stencils.len() >= V::LANES && K <= MAX_WIDTH);
        let mut s = Self::new();
        // Scalars per stencil: `Stencil` holds only `T`, `i32` and a one-byte enum (see
        // `Stencil::new_lanes`).
        let rec = size_of::<Stencil<T, D>>() / size_of::<T>();
        let first = stencils.as_ptr();
        // SAFETY: `stencils` holds `V::LANES` records of `rec` scalars; a field of record 0
        // starts `rec·l` scalars before the same field of record `l`; `fx` has `D` scalars,
        // `w[a]` and `dw[a]` have `MAX_WIDTH`.
        unsafe {
            V::load_records(
                core::ptr::addr_of!((*first).fx).cast::<T>(),
                rec,
                &mut s.fx[..D],
            );
            for a in 0..D {
                let pw = core::ptr::addr_of!((*first).w[a]).cast::<T>();
                let pd = core::ptr::addr_of!((*first).dw[a]).cast::<T>();
                V::load_records(pw, rec, &mut s.w[a][..K]);
                V::load_records(pd, rec, &mut s.dw[a][..K]);
            }
        }
        s
    }
}

impl<T: Real, const D: usize> Stencil<T, D> {
    /// The stencil of a particle at `x` (m, relative to the grid origin) on grid `grid` with
    /// spacing `h` (m).
    ///
    /// Errors: [`Error::NonFinite`] for a NaN/inf position or spacing;
    /// [`Error::InvalidArgument`] for `h ≤ 0`, a face axis `≥ d`, or a position beyond the
    /// position limit `|x/h| < 2³⁰` (also when `x/h` overflows); [`Error::Overflow`] for a
    /// finite `h > 0` so small that `1/h` is not representable.
    #[inline(always)]
    pub fn new(kernel: Kernel, grid: Grid, h: T, x: &[T; D]) -> Result<Self> {
        // The checks give the statuses; the formulas are those of `new_lanes` on one lane.
        Self::check_position(grid, h, x)?;
        let mut s = [Self::blank(kernel, h)];
        if Self::new_lanes::<T>(kernel, grid, h, core::slice::from_ref(x), &mut s, None) & 1 == 0 {
            // Not reached: `check_position` accepts exactly the lanes `new_lanes` does.
            return Err(Error::InvalidArgument);
        }
        Ok(s[0])
    }

    /// A stencil with every weight 0 and base 0 (a placeholder to be overwritten).
    #[inline(always)]
    pub(crate) fn blank(kernel: Kernel, h: T) -> Self {
        Self {
            kernel,
            h,
            base: [0; D],
            fx: [T::ZERO; D],
            w: [[T::ZERO; MAX_WIDTH]; D],
            dw: [[T::ZERO; MAX_WIDTH]; D],
        }
    }

    /// Checks what [`Stencil::new`] checks about `h` and `x` without building the stencil:
    /// `Ok` exactly when `Stencil::new(_, grid, h, x)` is.
    ///
    /// Errors: as [`Stencil::new`].
    #[inline]
    pub fn check_position(grid: Grid, h: T, x: &[T; D]) -> Result<()> {
        let inv_h = Self::inv_spacing(grid, h, x)?;
        for a in 0..D {
            cell_coordinate(grid, a, inv_h, x[a])?;
        }
        Ok(())
    }

    /// The stencils of `V::LANES` particles at once (positions `xs[l]`) on SIMD lanes, into
    /// `out[l]`; [`Stencil::new`] is this on one lane. Returns the lanes done (bit `l` for
    /// lane `l`): there `out[l]` is `Stencil::new(kernel, grid, h, &xs[l])`. A lane is not
    /// done when its `Stencil::new` would fail (or `h` or `grid` is invalid: no lane is done);
    /// the caller calls `Stencil::new` there and gets its error. With `lanes`, the lane vectors
    /// of `fx`, the weights and the derivatives are written there too (lane `l` of a done lane
    /// is `out[l]`'s), and without [`StencilLanes::records`] the weights and derivatives of
    /// `out` are left as they are.
    ///
    /// Per axis: `ξ = x/h − shift`; `⌊ξ⌋` (exact: `|ξ| < 2³⁰` is checked, and a value of `T`
    /// that large is an integer); `frac = ξ − ⌊ξ⌋`, exact (Sterbenz for `|ξ| ≥ 1`, trivially
    /// below), in `[0, 1)`; the base node (quadratic: `⌊ξ − ½⌋`, the nearest node is base + 1;
    /// cubic: `⌊ξ⌋ − 1`, two nodes on each side) and `fx`, the particle's distance from it in
    /// cells; then [`Kernel::n_dn_lanes`] at `fx − o`, the derivative times `1/h` (finite:
    /// `|N'| ≤ 1` for both kernels).
    #[inline(always)]
    pub(crate) fn new_lanes<V: Lane<Scalar = T>>(
        kernel: Kernel,
        grid: Grid,
        h: T,
        xs: &[[T; D]],
        out: &mut [Self],
        mut lanes: Option<&mut StencilLanes<V>>,
    ) -> u64 {
        // The widest chunk of any caller (P2G's `f32` chunks on AVX-512).
        const MAX: usize = crate::kernel::batch::WIDE_LANES;
        let n = V::LANES;
        debug_assert!(n <= MAX && xs.len() >= n && out.len() >= n);
        let inv_h = T::ONE / h;
        let bad_face = matches!(grid, Grid::Face(f) if f >= D);
        if !(h.is_finite() && h > T::ZERO && inv_h.is_finite()) || bad_face {
            return 0;
        }
        let mut done = u64::MAX >> (64 - n);
        // Per axis, the lane vectors `⌊ξ⌋` (as integers), `fx` and the K weights and
        // derivatives, written into the stencils as records (`Lane::store_records`: `f32`
        // lanes transpose in registers and store whole rows; others store scalars, never
        // scatter instructions, which are slow on AMD Zen 4).
        let mut fl_buf = [[0i32; MAX]; 3];
        let mut lo_bits = [0u64; 3];
        let zero = V::splat(T::ZERO);
        let mut fxs = [zero; 3];
        let mut xa = [T::ZERO; MAX];
        let k = kernel.width();
        // Scalars per stencil: `Stencil` holds only `T`, `i32` and a one-byte enum, so its
        // size is a multiple of `T`'s.
        let rec = size_of::<Self>() / size_of::<T>();
        debug_assert_eq!(size_of::<Self>() % size_of::<T>(), 0);
        let first = out.as_mut_ptr();
        // The positions per axis: on `f32` chunks wider than eight lanes, the records
        // transposed in registers ([`Lane::load_records`]), since the copy's scalar stores
        // cannot forward to the wide load that follows them; otherwise copied through `xa`
        // (faster on eight lanes; `f64` record loads are gathers). Measurements:
        // `docs/transfer-performance.md`, "What limits the targets".
        let mut xv = [zero; D];
        let records = size_of::<T>() == 4 && n > 8;
        if records {
            // SAFETY: `xs` holds `n = LANES` contiguous records of `D` scalars.
            unsafe { V::load_records(xs.as_ptr().cast::<T>(), D, &mut xv) };
        }
        for a in 0..D {
            if !records {
                for (b, x) in xa.iter_mut().zip(xs).take(n) {
                    *b = x[a];
                }
                xv[a] = V::load(&xa[..n]);
            }
            let shift = match grid {
                Grid::Face(f) if f != a => T::HALF,
                _ => T::ZERO,
            };
            let xi = xv[a] * V::splat(inv_h) - V::splat(shift);
            // Finite and inside the position limit (false for NaN and infinities).
            done &= V::mask_bits(xi.abs().lt(V::splat(T::from_f64(MAX_CELLS))));
            let fl = xi.floor();
            let frac = xi - fl;
            let one = V::splat(T::ONE);
            // Quadratic: base ⌊ξ − ½⌋ (one less where frac < ½); cubic: ⌊ξ⌋ − 1. Lane `l`'s
            // `lo` is bit `l` of `lo_bits[a]` (subtracted as an integer: exact).
            let lo = match kernel {
                Kernel::Quadratic => {
                    let below = frac.lt(V::splat(T::HALF));
                    lo_bits[a] = V::mask_bits(below);
                    V::select(below, one, zero)
                }
                Kernel::Cubic => {
                    lo_bits[a] = u64::MAX;
                    one
                }
            };
            let fx = frac + lo;
            // Exact where the lane is done (|⌊ξ⌋| < 2³⁰).
            fl.to_i32s(&mut fl_buf[a]);
            fxs[a] = fx;
            // Unused entries are 0, as in `Stencil::new`.
            let (mut w, mut dw) = ([zero; MAX_WIDTH], [zero; MAX_WIDTH]);
            match kernel {
                Kernel::Quadratic => quadratic_axis(fx, &mut w, &mut dw),
                Kernel::Cubic => {
                    for o in 0..k {
                        (w[o], dw[o]) = kernel.n_dn_lanes(fx - V::splat(T::from_i32(o as i32)));
                    }
                }
            }
            for d in dw.iter_mut().take(k) {
                *d *= V::splat(inv_h);
            }
            if let Some(sl) = lanes.as_deref_mut() {
                (sl.fx[a], sl.w[a], sl.dw[a]) = (fx, w, dw);
            }
            if lanes.as_ref().is_none_or(|sl| sl.records) {
                // SAFETY: `out` holds `n = LANES` stencils; record `l` of `rec` scalars from
                // the field of `out[0]` is the same field of `out[l]`, and `w[a]`, `dw[a]` are
                // `MAX_WIDTH` scalars.
                unsafe {
                    V::store_records(addr_of_mut!((*first).w[a]).cast::<T>(), rec, &w);
                    V::store_records(addr_of_mut!((*first).dw[a]).cast::<T>(), rec, &dw);
                }
            }
        }
        // SAFETY: as above; `fx` is `D` scalars.
        unsafe { V::store_records(addr_of_mut!((*first).fx).cast::<T>(), rec, &fxs[..D]) };
        for (l, st) in out.iter_mut().enumerate().take(n) {
            for a in 0..D {
                let base = fl_buf[a][l].wrapping_sub((lo_bits[a] >> l & 1) as i32);
                // Volatile, so that the lane loop is not vectorised into scatters.
                // SAFETY: a field of `st`, valid for writes.
                unsafe { write_volatile(&mut st.base[a], base) };
            }
            st.kernel = kernel;
            st.h = h;
        }
        done
    }

    /// Validates `grid`, `h` and the finiteness of `x`; returns `1/h`.
    #[inline(always)]
    fn inv_spacing(grid: Grid, h: T, x: &[T; D]) -> Result<T> {
        if !h.is_finite() || x.iter().any(|c| !c.is_finite()) {
            return Err(Error::NonFinite);
        }
        if h <= T::ZERO {
            return Err(Error::InvalidArgument);
        }
        if let Grid::Face(a) = grid {
            if a >= D {
                return Err(Error::InvalidArgument);
            }
        }
        let inv_h = T::ONE / h;
        if !inv_h.is_finite() {
            // A finite h > 0 whose inverse is not representable.
            return Err(Error::Overflow);
        }
        Ok(inv_h)
    }

    /// Number of nodes, `K^d`.
    #[inline]
    #[must_use]
    pub fn len(&self) -> usize {
        self.kernel.node_count(D)
    }

    /// Always false (a stencil has at least 9 nodes).
    #[inline]
    #[must_use]
    pub fn is_empty(&self) -> bool {
        false
    }

    /// Per-axis offsets `o` of node `r` (axis 0 fastest).
    #[inline]
    #[must_use]
    pub fn offsets(&self, r: usize) -> [usize; D] {
        let k = self.kernel.width();
        let mut o = [0usize; D];
        let mut q = r;
        for oa in o.iter_mut() {
            *oa = q % k;
            q /= k;
        }
        o
    }

    /// Node `r < len()`: grid index, weight, weight gradient and `x_i − x_p`.
    #[inline]
    #[must_use]
    pub fn node(&self, r: usize) -> Node<T, D> {
        let o = self.offsets(r);
        let mut index = [0i32; D];
        let mut dx = [T::ZERO; D];
        let mut weight = T::ONE;
        for a in 0..D {
            index[a] = self.base[a] + o[a] as i32;
            dx[a] = (T::from_i32(o[a] as i32) - self.fx[a]) * self.h;
            weight *= self.w[a][o[a]];
        }
        let mut grad = [T::ZERO; D];
        for (a, g) in grad.iter_mut().enumerate() {
            let mut p = self.dw[a][o[a]];
            for b in 0..D {
                if b != a {
                    p *= self.w[b][o[b]];
                }
            }
            *g = p;
        }
        Node {
            index,
            weight,
            grad,
            dx,
        }
    }

    /// Iterator over the nodes in stencil order.
    #[inline]
    pub fn nodes(&self) -> impl Iterator<Item = Node<T, D>> + '_ {
        (0..self.len()).map(move |r| self.node(r))
    }
}

/// The quadratic B-spline's weights `N(fx − o)` and derivatives `N'(fx − o)` (per cell) at the
/// three offsets `o` of a stencil, for `fx ∈ [½, ³⁄₂]` (the range [`Stencil::new_lanes`]
/// forms: `⌊ξ⌋` fraction plus 0 or 1, where the sum may round up to `³⁄₂`): there `fx − o` lies
/// in the outer piece for `o = 0` and `o = 2` and in the inner piece for `o = 1`, so no piece is
/// chosen per lane. The operations are those of [`Kernel::n_dn_lanes`] on its piece, in the
/// same order, and at the ends, where [`Kernel::n_dn_lanes`] takes the other piece or 0, the
/// two pieces agree exactly (`fx = ½`: ¾ − ¼ = ½·1·1, and `e = 0` for `o = 2`; `fx = ³⁄₂`:
/// the same for `o = 1`, and `o = 0`, whose `−e` would be `−0`, keeps the select of `+0`), so
/// the values are the same bits (`quadratic_axis_is_n_dn` checks every `f32` value of `fx`).
#[inline(always)]
fn quadratic_axis<V: Lane>(fx: V, w: &mut [V; MAX_WIDTH], dw: &mut [V; MAX_WIDTH]) {
    let c = |x: f64| V::splat(V::Scalar::from_f64(x));
    // o = 0: d = fx ∈ [½, ³⁄₂], outer piece ½e², −e with e = ³⁄₂ − d (0 at d = ³⁄₂).
    let e0 = c(1.5) - fx;
    w[0] = c(0.5) * e0 * e0;
    dw[0] = V::select(fx.lt(c(1.5)), -e0, c(0.0));
    // o = 1: d = fx − 1 ∈ [−½, ½] (exact), inner piece ¾ − d², −2d.
    let d1 = fx - c(1.0);
    w[1] = c(0.75) - d1 * d1;
    dw[1] = -(d1 + d1);
    // o = 2: d = fx − 2 < 0, outer piece with e = ³⁄₂ − |d| = ³⁄₂ + d (the same real, so the
    // same rounding) and −sign(d) e = e.
    let e2 = c(1.5) + (fx - c(2.0));
    w[2] = c(0.5) * e2 * e2;
    dw[2] = e2;
}

/// The cell coordinate `ξ = x/h − shift` of axis `a` (`shift = ½` on the cell-centred axes of
/// a face grid), in `T` and in `f64`.
///
/// Errors: [`Error::InvalidArgument`] beyond the position limit `|ξ| < 2³⁰` (also when `x/h`
/// overflows).
#[inline(always)]
fn cell_coordinate<T: Real>(grid: Grid, a: usize, inv_h: T, x: T) -> Result<(T, f64)> {
    let shift = match grid {
        Grid::Face(f) if f != a => T::HALF,
        _ => T::ZERO,
    };
    let xi = x * inv_h - shift;
    let xi64 = xi.to_f64();
    if !xi.is_finite() || xi64.abs() >= MAX_CELLS {
        return Err(Error::InvalidArgument);
    }
    Ok((xi, xi64))
}

#[cfg(all(test, feature = "std"))]
mod tests;
