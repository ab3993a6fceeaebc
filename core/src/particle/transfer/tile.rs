//! P2G's node tile: the contributions of a run of particles that lie close together are summed
//! in a small local block of nodes first, and the block is added to the host's grid once.
//!
//! A host sorts its particles by cell, so consecutive particles reach mostly the same nodes.
//! Adding each particle to the grid on its own would load every node row right after the
//! previous particle stored it, through masked vector moves that the store buffer cannot
//! forward (the load waits for the store to reach the cache). The tile is written with whole
//! eight-lane rows, which forward, and the grid is touched once per run.
//!
//! **Geometry.** A tile has an origin node `org` (box-relative) and spans 8 nodes along axis 0
//! (one eight-lane row `R`) and `K + 1` nodes along each other axis (`K` nodes per axis of the
//! kernel). A particle with stencil base `b` joins if `0 ≤ b₀ − org₀ ≤ 8 − K` and
//! `0 ≤ b_a − org_a ≤ 1` (`a ≥ 1`); the first particle of a run sets `org = b − [fx < 1]`
//! per axis, which puts every particle of its grid cell in the tile (a quadratic stencil's base
//! is its cell or the cell before, by `fx`) and up to four more cells along axis 0.
//!
//! **Rows.** Tile row `t = Σ_{a≥1} t_a (K+1)^{a−1}` holds the nodes `org + (l, t₁, …)`,
//! `l = 0..8`, in lanes `l`. A particle's stencil row (axis-0 nodes `b₀ + o₀`, other offsets
//! `o_a`) adds into tile row `t_a = b_a − org_a + o_a` at lanes `s₀ + o₀`, `s₀ = b₀ − org₀`.
//!
//! **Node values.** With `w_a[o]`, `dw_a[o]` the stencil's per-axis weights and derivatives
//! (1/m) and `W`, `W'` the axis-0 ones in their tile lanes, node `o` has weight `w = W c₀` and
//! gradient `(W' c₀, W c₁, W c₂)`, where `c₀ = w₁[o₁] w₂[o₂]` and `c_a` is `c₀` with `dw_a` for
//! `w_a` (a B-spline weight is a product of per-axis factors). Every channel's value in
//! stencil row `(o₁, o₂)` is `c₀ P + Σ_{a≥1} c₀ o_a E_a + Σ_{a≥1} c_a B_a` with per-particle
//! lane vectors `P`, `E_a`, `B_a` ([`Coef`]); e.g. component `k` of the momentum,
//! `w (q₀ + m C h o)_k + Δt_f f_k` with `f = fm ∇w` (`fm = −V⁰ τ`), gives
//! `P = W (q₀ₖ + (mCh)_{k0} o₀) + Δt_f W' fm_{k0}`, `E_a = W (mCh)_{ka}`,
//! `B_a = Δt_f W fm_{ka}`, where `o₀` is the lane's axis-0 offset from the particle's base
//! node. It is summed factored, axis 2 first: per `o₂`,
//! `U = w₂[o₂] (P + o₂ E₂) + dw₂[o₂] B₂`, `V = w₂[o₂] E₁` and `W_B = w₂[o₂] B₁` (in 2D `U = P`,
//! `V = E₁`, `W_B = B₁`), and per `o₁` the row adds `w₁[o₁] (U + o₁ V) + dw₁[o₁] W_B`: two
//! multiply-adds per row and channel instead of one per term, and no per-row factor is formed.
//! The values are those of the per-node formulas up to rounding (products and sums in
//! another order).
//!
//! **Channel pairs.** Where two rows fit one register (`f32` on AVX-512: sixteen lanes), the 3D
//! tile sums two channels with each instruction, channel `2p` in lanes 0–7 and `2p + 1` in lanes
//! 8–15 of pair `p` ([`crate::lane::Pair`]); the node values are the same bits, but that a
//! channel summed beside one with more terms gets `+0` for them, which turns a `−0` sum into
//! `+0` (seen only at a node whose grid value was `−0`).
//!
//! **Failures.** When the tile is added, every new node value is checked; if one is not finite,
//! the old values are put back and the run's particles are added one by one by the
//! per-particle path, which finds the particles that fail. A run's tile sum can be finite where
//! adding its particles one by one would pass through a non-finite value (the sum of two
//! huge opposite contributions): the run is then accepted, with the finite, more accurate sum.

use super::nodes::lane_index;
use super::OutChannel;
use crate::lane::{Lane, Pair};
use crate::mat::Mat;
use crate::particle::stencil::{Stencil, MAX_WIDTH};
use crate::scalar::Real;
use core::marker::PhantomData;
use core::mem::MaybeUninit;

/// Lanes of a tile row (nodes along axis 0): the eight lanes of the row types of
/// [`crate::kernel::batch::LaneOp::run_rows`].
pub(super) const TILE_X: usize = 8;
/// Most tile rows: `(K + 1)^{d−1}` up to the cubic kernel in 3D.
pub(super) const MAX_ROWS: usize = 25;
/// Most particles in a run (kept for the one-by-one path).
pub(super) const MAX_RUN: usize = 48;
/// Most channels written by one P2G call.
pub(super) const MAX_CH: usize = 10;
/// Channel pairs of a joined tile (see [`Tile`]).
const MAX_PAIRS: usize = MAX_CH / 2;
/// Largest dimension.
const MAX_D: usize = 3;
/// Every `B_a` term of a channel (the mask of [`masked_channel`]).
const ALL_B: u8 = u8::MAX;

/// The per-particle lane vectors of one channel's node values (see the module docs). A term
/// that the channel does not have is skipped (`has_e`, `has_b` false). Plain arrays and flags
/// rather than `Option`s: an `Option` of vectors puts them at odd offsets behind its tag, and
/// its copies then load across the smaller stores that wrote them, which the store buffer
/// cannot forward.
#[derive(Clone, Copy)]
pub(super) struct Coef<R, const D: usize> {
    pub p: R,
    /// `E_a` (`a ≥ 1`; entry 0 unused).
    pub e: [R; D],
    /// `B_a` (`a ≥ 1`; entry 0 unused).
    pub b: [R; D],
    pub has_e: bool,
    pub has_b: bool,
}

impl<T: Real, R: Lane<Scalar = T>, const D: usize> Coef<R, D> {
    /// A channel with the `P` term only.
    #[inline(always)]
    pub fn only(p: R) -> Self {
        let z = R::splat(T::ZERO);
        Self {
            p,
            e: [z; D],
            b: [z; D],
            has_e: false,
            has_b: false,
        }
    }

    /// The two channels `lo`, `hi` side by side, every vector as it is: a term that a channel
    /// lacks must be 0 in it (as [`Coef::only`] and [`set_grad`] leave it).
    #[inline(always)]
    fn join_all<Q: Pair<R>>(lo: &Self, hi: &Self) -> Coef<Q, D> {
        let mut c = Coef::only(Q::join(lo.p, hi.p));
        c.has_e = lo.has_e || hi.has_e;
        c.has_b = lo.has_b || hi.has_b;
        for a in 1..D {
            c.e[a] = Q::join(lo.e[a], hi.e[a]);
            c.b[a] = Q::join(lo.b[a], hi.b[a]);
        }
        c
    }

    /// The two channels `lo`, `hi` side by side: the terms either has, a term the other
    /// lacks 0 in its half (whatever its vector held).
    #[inline(always)]
    fn join<Q: Pair<R>>(lo: &Self, hi: &Self) -> Coef<Q, D> {
        Self::join_all(&lo.own_terms(), &hi.own_terms())
    }

    /// The channel with 0 for the vectors of the terms it lacks.
    #[inline(always)]
    fn own_terms(&self) -> Self {
        let mut c = *self;
        for a in 1..D {
            c.e[a] = term(self.has_e, self.e[a]);
            c.b[a] = term(self.has_b, self.b[a]);
        }
        c
    }
}

/// A term `v` of a channel, or 0 if the channel does not have it (its vector may be stale).
#[inline(always)]
fn term<R: Lane>(has: bool, v: R) -> R {
    if has {
        v
    } else {
        R::splat(R::Scalar::ZERO)
    }
}

/// A tile of summed node values per channel. With rows `R` of one channel and `Q` two rows
/// side by side: where `Q` is one register ([`Pair::JOINED`]), channels `2p` and `2p + 1`
/// are summed together as pair `p` (one instruction for both; a channel without a term that
/// its partner has gets `+0` terms, which leave its finite sums as they are, but for the sign
/// of a zero sum), else channel by channel.
pub(super) struct Tile<R, Q, const D: usize> {
    /// Summed node values per channel and row (`acc[j][t]`), or, joined, per channel pair
    /// and row in the same memory ([`Self::pairs`]).
    acc: [[R; MAX_ROWS]; MAX_CH],
    /// Origin node, box-relative.
    pub org: [isize; D],
    /// Lanes written per row (bit `l` for lane `l`); no row written: the tile is empty.
    pub bits: [u32; MAX_ROWS],
    /// Whether any row is written.
    pub used: bool,
    _pair: PhantomData<Q>,
}

impl<T: Real, R: Lane<Scalar = T>, Q: Pair<R>, const D: usize> Tile<R, Q, D> {
    /// Whether channels are summed in pairs: where a pair is one register, in 3D (in 2D, whose
    /// rows are fewer, joining the channels measured slower than the channels one by one).
    const PAIRED: bool = Q::JOINED && D == 3;

    /// An empty tile.
    #[inline(always)]
    pub fn new() -> Self {
        const { assert!(size_of::<R>() == R::LANES * size_of::<T>()) };
        Self {
            acc: [[R::splat(T::ZERO); MAX_ROWS]; MAX_CH],
            org: [0; D],
            bits: [0; MAX_ROWS],
            used: false,
            _pair: PhantomData,
        }
    }

    /// The sums as channel pairs (the joined form): pair `p`, row `t`, half `h` of channel
    /// `2p + h`. Rows of `R`, not `Q`: a tile aligned for `Q` (64 bytes) measured twice the
    /// stack; the pairs are read and written unaligned ([`PairRows`]).
    #[inline(always)]
    fn pairs(&mut self) -> &mut [PairRows<R>; MAX_PAIRS] {
        // SAFETY: the same size and alignment (`MAX_CH` rows of `R` are `MAX_PAIRS` arrays of
        // `MAX_ROWS` pairs of `R`; `PairRows` is `repr(transparent)`), and plain data.
        unsafe { &mut *(&raw mut self.acc).cast::<[PairRows<R>; MAX_PAIRS]>() }
    }

    /// Row `t` of channel `j`.
    #[inline(always)]
    fn row(&mut self, j: usize, t: usize) -> R {
        if Self::PAIRED {
            self.pairs()[j / 2].0[t][j % 2]
        } else {
            self.acc[j][t]
        }
    }

    /// Adds channels `coef` (channel `j` at `j`), in pairs when joined.
    #[inline(always)]
    fn add_all<const K: usize>(
        &mut self,
        rt: &[[usize; MAX_WIDTH]; MAX_WIDTH],
        st: &Stencil<T, D>,
        coef: &[Coef<R, D>],
    ) {
        if Self::PAIRED {
            let none = Coef::only(R::splat(T::ZERO));
            for (p, pair) in coef.chunks(2).enumerate() {
                let c = Coef::join::<Q>(&pair[0], pair.get(1).unwrap_or(&none));
                let acc = &mut self.pairs()[p];
                match (c.has_e, c.has_b) {
                    (false, false) => add_channel::<T, Q, D, K, false, false>(acc, rt, st, &c),
                    (true, false) => add_channel::<T, Q, D, K, true, false>(acc, rt, st, &c),
                    (false, true) => add_channel::<T, Q, D, K, false, true>(acc, rt, st, &c),
                    (true, true) => add_channel::<T, Q, D, K, true, true>(acc, rt, st, &c),
                }
            }
            return;
        }
        for (j, k) in coef.iter().enumerate() {
            let acc = &mut self.acc[j];
            match (k.has_e, k.has_b) {
                (false, false) => add_channel::<T, R, D, K, false, false>(acc, rt, st, k),
                (true, false) => add_channel::<T, R, D, K, true, false>(acc, rt, st, k),
                (false, true) => add_channel::<T, R, D, K, false, true>(acc, rt, st, k),
                (true, true) => add_channel::<T, R, D, K, true, true>(acc, rt, st, k),
            }
        }
    }

    /// The lane offsets `s` of a stencil with box-relative base `rel` in this tile, if it fits
    /// (`K` nodes per axis); on an empty tile, the origin is set first.
    #[inline(always)]
    pub fn place<const K: usize>(&mut self, rel: &[isize; D], fx: &[T; D]) -> Option<[usize; D]> {
        if !self.used {
            for a in 0..D {
                self.org[a] = rel[a] - (fx[a] < T::ONE) as isize;
            }
        }
        let mut s = [0usize; D];
        for a in 0..D {
            let d = rel[a] - self.org[a];
            let lim = if a == 0 { (TILE_X - K) as isize } else { 1 };
            if d < 0 || d > lim {
                return None;
            }
            s[a] = d as usize;
        }
        Some(s)
    }

    /// Adds the node values of one particle with stencil `st` (`K` nodes per axis) at lane
    /// offsets `s`, for channels `0..coef.len()` with the lane vectors `coef`, in the factored
    /// form of the module docs.
    #[inline(always)]
    pub fn add<const K: usize>(&mut self, s: &[usize; D], st: &Stencil<T, D>, coef: &[Coef<R, D>]) {
        let rt = self.mark_rows::<K>(s);
        self.add_all::<K>(&rt, st, coef);
    }

    /// [`Self::add`] for the channels mass (`P` only) and momentum along each axis (`E_a`, and
    /// `B_a` when `B`), `coef.0[0..=D]`, then with `heat` the three heat channels (`P` only),
    /// `coef.1`; the terms are known at compile time (`heat` and `iso` are constants where it
    /// is inlined). With `iso` the force is isotropic (`fm = s I`, a particle without shear
    /// stress): momentum `a` has no `B_b` for `b ≠ a`, and those terms are skipped (the same
    /// sums: they are exact zeros, and a tile row, which starts at `+0`, is never `−0`).
    #[inline(always)]
    pub fn add_fixed<const K: usize, const B: bool>(
        &mut self,
        s: &[usize; D],
        st: &Stencil<T, D>,
        (mm, hc): &([Coef<R, D>; 4], [Coef<R, D>; 3]),
        heat: bool,
        iso: bool,
    ) {
        debug_assert!(mm[1..=D].iter().all(|k| k.has_e && k.has_b == B));
        let rt = self.mark_rows::<K>(s);
        // With an isotropic force the momentum along axis `a` has the term `B_a` only.
        let bm = |a: usize| if iso { 1u8 << a } else { ALL_B };
        if Self::PAIRED {
            // Pairs in channel order (3D): (mass, momentum 0), (momentum 1, momentum 2), then
            // the heat channels.
            let none = Coef::only(R::splat(T::ZERO));
            let pairs = self.pairs();
            let c = Coef::join_all::<Q>(&mm[0], &mm[1]);
            masked_channel::<T, Q, D, K, true, B>(&mut pairs[0], &rt, st, &c, bm(0));
            let c = Coef::join_all::<Q>(&mm[2], &mm[3]);
            add_channel::<T, Q, D, K, true, B>(&mut pairs[1], &rt, st, &c);
            if heat {
                let c = Coef::join_all::<Q>(&hc[0], &hc[1]);
                add_channel::<T, Q, D, K, false, false>(&mut pairs[2], &rt, st, &c);
                let c = Coef::join_all::<Q>(&hc[2], &none);
                add_channel::<T, Q, D, K, false, false>(&mut pairs[3], &rt, st, &c);
            }
            return;
        }
        add_channel::<T, R, D, K, false, false>(&mut self.acc[0], &rt, st, &mm[0]);
        // Written out per axis, so that each `bm` is a constant.
        masked_channel::<T, R, D, K, true, B>(&mut self.acc[1], &rt, st, &mm[1], bm(0));
        masked_channel::<T, R, D, K, true, B>(&mut self.acc[2], &rt, st, &mm[2], bm(1));
        if D == 3 {
            masked_channel::<T, R, D, K, true, B>(&mut self.acc[3], &rt, st, &mm[3], bm(2));
        }
        if heat {
            for (h, k) in hc.iter().enumerate() {
                add_channel::<T, R, D, K, false, false>(&mut self.acc[D + 1 + h], &rt, st, k);
            }
        }
    }

    /// [`Self::add`] for `D` channels that all have the terms `E_a` when `E` and `B_a` when
    /// `B` (the force differential's forces: `B` only), known at compile time.
    #[inline(always)]
    pub fn add_uniform<const K: usize, const E: bool, const B: bool>(
        &mut self,
        s: &[usize; D],
        st: &Stencil<T, D>,
        coef: &[Coef<R, D>; D],
    ) {
        debug_assert!(coef.iter().all(|k| k.has_e == E && k.has_b == B));
        let rt = self.mark_rows::<K>(s);
        if Self::PAIRED {
            let none = Coef::only(R::splat(T::ZERO));
            let pairs = self.pairs();
            // (3D) The forces along axes 0 and 1, then along axis 2.
            let c = Coef::join_all::<Q>(&coef[0], &coef[1]);
            add_channel::<T, Q, D, K, E, B>(&mut pairs[0], &rt, st, &c);
            let c = Coef::join_all::<Q>(&coef[D - 1], &none);
            add_channel::<T, Q, D, K, E, B>(&mut pairs[1], &rt, st, &c);
            return;
        }
        for (acc, k) in self.acc.iter_mut().zip(coef) {
            add_channel::<T, R, D, K, E, B>(acc, &rt, st, k);
        }
    }

    /// Marks the tile lanes of a stencil at lane offsets `s` (`K` nodes per axis) as written,
    /// and returns the tile row of each stencil row (`o₁`, `o₂`): `rt[o₂][o₁]` (`o₂ = 0` only
    /// in 2D).
    #[inline(always)]
    fn mark_rows<const K: usize>(&mut self, s: &[usize; D]) -> [[usize; MAX_WIDTH]; MAX_WIDTH] {
        debug_assert!((2..=MAX_D).contains(&D));
        let lanes = ((1u32 << K) - 1) << s[0];
        let mut rt = [[0usize; MAX_WIDTH]; MAX_WIDTH];
        for (o2, row) in rt.iter_mut().enumerate().take(outer::<D, K>()) {
            for (o1, t) in row.iter_mut().enumerate().take(K) {
                *t = s[1] + o1;
                if D == 3 {
                    *t += (s[2] + o2) * (K + 1);
                }
                self.bits[*t] |= lanes;
            }
        }
        self.used = true;
        rt
    }
}

/// The stencil rows along axis 2 (`K` in 3D, one in 2D).
#[inline(always)]
const fn outer<const D: usize, const K: usize>() -> usize {
    if D == 3 {
        K
    } else {
        1
    }
}

/// The tile rows of one channel (or pair of channels) as [`add_channel`] reads and writes them.
trait Rows<V> {
    /// Row `t`.
    fn get(&self, t: usize) -> V;
    /// Sets row `t`.
    fn set(&mut self, t: usize, v: V);
}

impl<V: Copy> Rows<V> for [V; MAX_ROWS] {
    #[inline(always)]
    fn get(&self, t: usize) -> V {
        self[t]
    }
    #[inline(always)]
    fn set(&mut self, t: usize, v: V) {
        self[t] = v;
    }
}

/// The rows of a channel pair: row `t` holds channel `2p` in half 0 and `2p + 1` in half 1,
/// read and written as one `Q` by unaligned loads and stores.
#[repr(transparent)]
struct PairRows<R>([[R; 2]; MAX_ROWS]);

impl<T: Real, R: Lane<Scalar = T>, Q: Pair<R>> Rows<Q> for PairRows<R> {
    #[inline(always)]
    fn get(&self, t: usize) -> Q {
        // SAFETY: a pair of `R` is `2 R::LANES` scalars (`Tile::new` checks `R`'s size).
        let s =
            unsafe { core::slice::from_raw_parts(self.0[t].as_ptr().cast::<T>(), 2 * R::LANES) };
        Q::load(s)
    }
    #[inline(always)]
    fn set(&mut self, t: usize, v: Q) {
        // SAFETY: as above.
        let s = unsafe {
            core::slice::from_raw_parts_mut(self.0[t].as_mut_ptr().cast::<T>(), 2 * R::LANES)
        };
        v.store(s);
    }
}

/// Adds one channel's node values (lane vectors `k`, terms `E_a` when `E`, `B_a` when `B`)
/// into the tile rows `rt` (see [`Tile::add`]): [`masked_channel`] with every `B_a`.
#[inline(always)]
fn add_channel<
    T: Real,
    R: Lane<Scalar = T>,
    const D: usize,
    const K: usize,
    const E: bool,
    const B: bool,
>(
    acc: &mut impl Rows<R>,
    rt: &[[usize; MAX_WIDTH]; MAX_WIDTH],
    st: &Stencil<T, D>,
    k: &Coef<R, D>,
) {
    masked_channel::<T, R, D, K, E, B>(acc, rt, st, k, ALL_B);
}

/// [`add_channel`] with the terms `B_a` only where bit `a` of `bm` is set: per axis-2 offset
/// `o₂` the vectors `U`, `V`, `W_B` of the module docs, then per axis-1 offset `o₁` two
/// multiply-adds. `bm` is a constant where this is inlined ([`ALL_B`], or the one axis of an
/// isotropic force), so the terms left out cost nothing.
#[inline(always)]
fn masked_channel<
    T: Real,
    R: Lane<Scalar = T>,
    const D: usize,
    const K: usize,
    const E: bool,
    const B: bool,
>(
    acc: &mut impl Rows<R>,
    rt: &[[usize; MAX_WIDTH]; MAX_WIDTH],
    st: &Stencil<T, D>,
    k: &Coef<R, D>,
    bm: u8,
) {
    let sp = R::splat;
    let (b1, b2) = (B && bm & 2 != 0, B && bm & 4 != 0);
    for (o2, row) in rt.iter().enumerate().take(outer::<D, K>()) {
        let (mut u, mut v, mut wb) = (k.p, k.e[1], k.b[1]);
        if D == 3 {
            let w2 = sp(st.w[2][o2]);
            if E {
                u = sp(T::from_i32(o2 as i32)).mul_add(k.e[2], u);
                v = w2 * v;
            }
            u = w2 * u;
            if b2 {
                u = sp(st.dw[2][o2]).mul_add(k.b[2], u);
            }
            if b1 {
                wb = w2 * wb;
            }
        }
        for (o1, &t) in row.iter().enumerate().take(K) {
            let y = if E && o1 > 0 {
                sp(T::from_i32(o1 as i32)).mul_add(v, u)
            } else {
                u
            };
            let mut a = sp(st.w[1][o1]).mul_add(y, acc.get(t));
            if b1 {
                a = sp(st.dw[1][o1]).mul_add(wb, a);
            }
            acc.set(t, a);
        }
    }
}

impl<T: Real, R: Lane<Scalar = T>, Q: Pair<R>, const D: usize> Tile<R, Q, D> {
    /// Adds the tile to the channels `outs` (channel `j` gets `acc[j]`, in order) and empties
    /// it. Returns whether every new node value is finite; if one is not, every old value is
    /// put back (last written first, so that aliased channels are restored too).
    ///
    /// # Safety
    /// Every node of the written lanes is valid for reading and writing in every channel (the
    /// tile's particles passed [`super::nodes::rel_base`]).
    #[inline(always)]
    pub unsafe fn add_to_grid<const K: usize>(&mut self, outs: &[OutChannel<T, D>]) -> bool {
        if !self.used {
            return true;
        }
        let rows = (K + 1).pow(D as u32 - 1);
        let mut old = [[MaybeUninit::<R>::uninit(); MAX_ROWS]; MAX_CH];
        let mut ok = true;
        for (j, ch) in outs.iter().enumerate() {
            for t in 0..rows {
                let bits = self.bits[t];
                if bits == 0 {
                    continue;
                }
                let p = ch.data.wrapping_offset(self.row_offset::<K>(&ch.stride, t));
                let x = load_row::<T, R>(p, ch.stride[0], bits);
                let nv = x + self.row(j, t);
                ok &= R::all(nv.is_finite());
                old[j][t].write(x);
                store_row(nv, p, ch.stride[0], bits);
            }
        }
        if !ok {
            for (j, ch) in outs.iter().enumerate().rev() {
                for t in (0..rows).rev() {
                    let bits = self.bits[t];
                    if bits != 0 {
                        let p = ch.data.wrapping_offset(self.row_offset::<K>(&ch.stride, t));
                        store_row(old[j][t].assume_init(), p, ch.stride[0], bits);
                    }
                }
            }
        }
        for t in 0..rows {
            if self.bits[t] != 0 {
                if Self::PAIRED {
                    for acc in self.pairs().iter_mut().take(outs.len().div_ceil(2)) {
                        acc.0[t] = [R::splat(T::ZERO); 2];
                    }
                } else {
                    for acc in self.acc.iter_mut().take(outs.len()) {
                        acc[t] = R::splat(T::ZERO);
                    }
                }
                self.bits[t] = 0;
            }
        }
        self.used = false;
        ok
    }

    /// The offset (in scalars) of tile row `t` from a channel's node `lo`, for its strides.
    #[inline(always)]
    fn row_offset<const K: usize>(&self, stride: &[isize; D], t: usize) -> isize {
        let mut off = self.org[0] * stride[0];
        let mut q = t;
        for a in 1..D {
            off += (self.org[a] + (q % (K + 1)) as isize) * stride[a];
            q /= K + 1;
        }
        off
    }
}

/// The lanes `bits` of a node row at `p` with axis-0 stride `s0`, the others 0.
///
/// # Safety
/// The nodes of the lanes in `bits` are valid for reading.
#[inline(always)]
unsafe fn load_row<T: Real, R: Lane<Scalar = T>>(p: *const T, s0: isize, bits: u32) -> R {
    if s0 == 1 {
        return R::load_mask(p, bits);
    }
    let mut l = [T::ZERO; TILE_X];
    for (i, x) in l.iter_mut().enumerate() {
        if bits >> i & 1 == 1 {
            *x = p.wrapping_offset(i as isize * s0).read_unaligned();
        }
    }
    R::load(&l)
}

/// Writes the lanes `bits` of `v` to a node row at `p` with axis-0 stride `s0`.
///
/// # Safety
/// The nodes of the lanes in `bits` are valid for writing.
#[inline(always)]
unsafe fn store_row<T: Real, R: Lane<Scalar = T>>(v: R, p: *mut T, s0: isize, bits: u32) {
    if s0 == 1 {
        return v.store_mask(p, bits);
    }
    let mut l = [T::ZERO; TILE_X];
    v.store(&mut l);
    for (i, x) in l.iter().enumerate() {
        if bits >> i & 1 == 1 {
            p.wrapping_offset(i as isize * s0).write_unaligned(*x);
        }
    }
}

/// The axis-0 weights and weight derivatives (1/m) of a stencil in tile lanes `s0..s0 + K`,
/// zero in the other lanes, and every lane's axis-0 node offset `l − s0` from the stencil's
/// base (exact small integers). Put together in registers by lane selects: lanes stored one
/// scalar at a time and then loaded as a vector would wait for the stores to reach the cache.
#[inline(always)]
pub(super) fn axis0<T: Real, R: Lane<Scalar = T>, const D: usize, const K: usize>(
    s: &Stencil<T, D>,
    s0: usize,
) -> (R, R, R) {
    let o = lane_index::<T, R>() - R::splat(T::from_i32(s0 as i32));
    let (mut w, mut dw) = (R::splat(T::ZERO), R::splat(T::ZERO));
    for k in 0..K {
        let here = o.eq(R::splat(T::from_i32(k as i32)));
        w = R::select(here, R::splat(s.w[0][k]), w);
        dw = R::select(here, R::splat(s.dw[0][k]), dw);
    }
    (w, dw, o)
}

/// Sets `c` to the [`Coef`] of the node values `f Σ_b m_{ab} ∂w/∂x_b` (a force: row `a` of
/// `f m` times the weight gradient), from the axis-0 lanes `w`, `dw` of [`axis0`]. Written with
/// loops, not `array::from_fn`: a closure there is not inlined into the caller's target
/// features, and its vector operations become calls.
#[inline(always)]
pub(super) fn set_grad<T: Real, R: Lane<Scalar = T>, const D: usize>(
    c: &mut Coef<R, D>,
    w: R,
    dw: R,
    m: &Mat<T, D>,
    a: usize,
    f: T,
) {
    c.p = dw * R::splat(f * m.cols[0][a]);
    for b in 1..D {
        c.b[b] = w * R::splat(f * m.cols[b][a]);
    }
    c.has_e = false;
    c.has_b = true;
}
