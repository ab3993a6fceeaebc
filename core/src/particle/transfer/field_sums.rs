//! Sums over a stencil's nodes of a node vector field by separable contraction: the gradient
//! `G = Σ_i u_i ∇w_iᵀ` (the force differential's `δu`) and, for G2P on a MAC grid's faces, also
//! `Σ_i w_i v_i` and the moments `Σ_i w_i v_i o_iᵀ` (`o` the node offset from the stencil base);
//! and G2P's temperature pair ([`pair_sums`]). (G2P's collocated velocity sums run one particle
//! per lane instead, in `lane_sums.rs`.)
//!
//! With the tensor-product weights `w_i = Π_a w_a[o_a]` and `∂w_i/∂x_b` the same product with
//! `dw_b` for `w_b` ([`Stencil`]), each sum factors axis by axis (3D; 2D drops the `o₂` level):
//!
//! `S[o₀](o₂) = Σ_{o₁} w₁[o₁] u(o₀, o₁, o₂)`, `S'` with `dw₁`, `S°` with `w₁[o₁] o₁`;
//! `A₀[o₀] = Σ_{o₂} w₂ S`, `A₁ = Σ_{o₂} w₂ S'`, `A₂ = Σ_{o₂} dw₂ S`, `A₃ = Σ_{o₂} w₂ S°`,
//! `A₄ = Σ_{o₂} w₂ o₂ S`;
//!
//! `G_{a0} = Σ_{o₀} dw₀ A₀`, `G_{ab} = Σ_{o₀} w₀ A_b` (`b ≥ 1`), `Σ w v = Σ_{o₀} w₀ A₀`, and the
//! moments `Σ_{o₀} w₀ o₀ A₀`, `Σ_{o₀} w₀ A₃`, `Σ_{o₀} w₀ A₄`, per component `a` of `u`. The
//! gradient alone costs `2K^{d−1} + d K^{d−2}` multiply-adds per component and axis-0 offset in
//! 3D and `2K` in 2D, about the `d K^{d−1}` of the node-by-node sum, but no per-node weight is
//! formed and few lanes below carry a sum that is not used. Terms with a zero offset factor
//! (`o = 0`) are skipped: they add `±0` to a finite sum.
//!
//! **Lanes.** A node row (the `K ≤ 4` nodes that differ in axis 0 only) of every component is
//! read into eight-lane vectors: component `a` in vector `a / 2`, lanes `4 (a mod 2) + o₀`, the
//! other lanes 0. Each multiply-add of the contraction above then runs for two components'
//! `K` axis-0 offsets at once, and the last level is one product per vector followed by sums of
//! each component's `K` lanes: in 3D in order, `((l₀ + l₁) + l₂) + l₃`; in 2D (one vector per
//! output, both components) pairwise, `(l₀ + l₁) + (l₂ + l₃)` with the lanes past `K` 0: four
//! outputs at a time in registers where [`Lane::quad_sums`] runs there (horizontal adds on the
//! eight-lane `f32` type, which saved a tenth of 2D G2P), else from the stored lanes (the
//! `f64` and scalar rows, where the regrouping in registers measured slower; in 3D, with two
//! vectors per output, horizontal adds measured slower in the C library too). Every lane's
//! operations, in order, are the same on every eight-lane row type and instruction set, so
//! they give the same bits. A chunk of eight particles can instead have the temperature pair's
//! lane sums made for all eight at once, one particle per lane ([`chunk_sums`] of
//! [`pair_products`]): one 8 × 8 transpose in registers instead of eight particles' stored
//! lanes.

use super::InChannel;
use crate::lane::Lane;
use crate::mat::Mat;
use crate::particle::stencil::Stencil;
use crate::scalar::Real;

/// Lanes of the row vectors.
const LANES: usize = 8;
/// Lanes per component in a row vector.
const SLOT: usize = 4;

/// The sums of one node vector field over a stencil, per component `a` (rows of [`Mat`] as
/// in `Mat::cols[b][a]`).
pub(crate) struct Sums<T, const D: usize> {
    /// `Σ_i w_i u_{a,i}` (with `FULL`).
    pub v: [T; D],
    /// `mo.cols[b][a] = Σ_i w_i u_{a,i} o_{i,b}` (with `FULL`).
    pub mo: Mat<T, D>,
    /// `g.cols[b][a] = Σ_i u_{a,i} ∂w_i/∂x_b`.
    pub g: Mat<T, D>,
    /// Every value read is finite.
    pub finite: bool,
}

impl<T: Real, const D: usize> Sums<T, D> {
    /// Sets component `a` of output `q`: `g` column `q` for `q < d`, then `Σ w u`, then the
    /// moments.
    #[inline(always)]
    fn put(&mut self, q: usize, a: usize, sum: T) {
        match q {
            _ if q < D => self.g.cols[q][a] = sum,
            _ if q == D => self.v[a] = sum,
            _ => self.mo.cols[q - D - 1][a] = sum,
        }
    }
}

/// The [`Sums`] over the `N = K^d` nodes of stencil `s` (`K ≤ 4`, `d` 2 or 3) of the components
/// `a ∈ comps.0..comps.1` read from `ch[a]` at box-relative base `rel` (the others 0, not
/// read); `FULL`: also `Σ w u` and the moments, else only `g`.
///
/// # Safety
/// Every stencil node is inside the box of each channel read (checked by `rel_base`).
#[inline(always)]
pub(crate) unsafe fn node_field_sums<
    T: Real,
    R: Lane<Scalar = T>,
    const D: usize,
    const K: usize,
    const FULL: bool,
>(
    s: &Stencil<T, D>,
    rel: &[isize; D],
    ch: &[InChannel<T, D>; D],
    comps: (usize, usize),
) -> Sums<T, D> {
    debug_assert!(R::LANES == LANES && K <= SLOT && (D == 2 || D == 3));
    let z = R::splat(T::ZERO);
    let pv = D.div_ceil(2);
    let on = |a: usize| comps.0 <= a && a < comps.1;
    let (acc, finite, [f_w, f_dw, f_wo]) = contract_rows::<T, R, D, K, FULL>(ch, rel, s, comps);
    let mut out = Sums {
        v: [T::ZERO; D],
        mo: Mat::ZERO,
        g: Mat::ZERO,
        finite,
    };
    let mut f = [z; 8];
    // (acc index, factor) per output: g₀, g₁, g₂, then with FULL Σ w u, moments 0, 1, 2.
    let mut k = [0usize; 8];
    let mut nq = 0;
    for b in 0..D {
        k[nq] = b;
        f[nq] = if b == 0 { f_dw } else { f_w };
        nq += 1;
    }
    if FULL {
        k[nq] = 0;
        f[nq] = f_w;
        nq += 1;
        k[nq] = 0;
        f[nq] = f_wo;
        nq += 1;
        for b in 1..D {
            k[nq] = 2 + b;
            f[nq] = f_w;
            nq += 1;
        }
    }
    if D == 2 && R::QUAD_SUMS_IN_REGISTERS {
        // Four outputs at a time: the products' slot sums land in lanes `q mod 4` (component
        // 0) and `4 + q mod 4` (component 1); lanes `K..4` of a slot are 0 and add nothing.
        let mut l = [T::ZERO; LANES];
        for q0 in (0..nq).step_by(4) {
            let mut v = [z; 4];
            for (i, x) in v.iter_mut().enumerate() {
                if q0 + i < nq {
                    *x = acc[k[q0 + i]][0] * f[q0 + i];
                }
            }
            R::quad_sums(v).store(&mut l);
            for i in 0..4.min(nq - q0) {
                for a in 0..D {
                    if on(a) {
                        out.put(q0 + i, a, l[SLOT * a + i]);
                    }
                }
            }
        }
    } else if D == 2 {
        // The same sums from each output's stored product.
        let mut l = [T::ZERO; LANES];
        for q in 0..nq {
            (acc[k[q]][0] * f[q]).store(&mut l);
            for a in 0..D {
                if on(a) {
                    let g = &l[SLOT * a..];
                    out.put(q, a, (g[0] + g[1]) + (g[2] + g[3]));
                }
            }
        }
    } else {
        // Each output's product stored, then its `K` lanes summed in order.
        let mut l = [[[T::ZERO; LANES]; 2]; 8];
        for q in 0..nq {
            for j in 0..pv {
                (acc[k[q]][j] * f[q]).store(&mut l[q][j]);
            }
        }
        for q in 0..nq {
            for a in 0..D {
                if !on(a) {
                    continue;
                }
                let lanes = &l[q][a / 2][SLOT * (a % 2)..];
                let mut sum = lanes[0];
                for x in &lanes[1..K] {
                    sum += *x;
                }
                out.put(q, a, sum);
            }
        }
    }
    out
}

/// The lane sums of one product vector of eight particles at once: `[s₀, s₁]`, lane `l` of
/// `s_c` the sum of `v[l]`'s slot `c` (lanes `4c..4c + K`) in order from lane `4c`, as
/// [`pair_sums`] forms it. One 8 × 8 transpose ([`Lane::transpose8`]) puts particle `l`'s lanes
/// in lane `l`, so the sums are vector adds.
#[inline(always)]
pub(crate) fn chunk_sums<R: Lane, const K: usize>(v: [R; LANES]) -> [R; 2] {
    debug_assert!(R::LANES == LANES && K <= SLOT);
    let t = R::transpose8(v);
    let mut out = [t[0], t[SLOT]];
    for (c, o) in out.iter_mut().enumerate() {
        for x in &t[SLOT * c + 1..SLOT * c + K] {
            *o += *x;
        }
    }
    out
}

/// [`contract`] of the components `comps` with its layout chosen (separate node arrays of one
/// box, the usual layout, share their strides: one row offset for every component, and
/// whole-row loads), and the axis-0 factors `[w, w′, w·o₀]` in the lanes of their offsets:
/// for [`node_field_sums`].
///
/// # Safety
/// As [`node_field_sums`].
#[inline(always)]
unsafe fn contract_rows<
    T: Real,
    R: Lane<Scalar = T>,
    const D: usize,
    const K: usize,
    const FULL: bool,
>(
    ch: &[InChannel<T, D>; D],
    rel: &[isize; D],
    s: &Stencil<T, D>,
    comps: (usize, usize),
) -> ([[R; 2]; 5], bool, [R; 3]) {
    let mut same = true;
    for (a, c) in ch.iter().enumerate() {
        let on = comps.0 <= a && a < comps.1;
        same &= !on || (c.stride == ch[comps.0].stride && c.stride[0] == 1);
    }
    let (acc, finite) = if same {
        contract::<T, R, D, K, true, FULL>(ch, rel, s, comps)
    } else {
        contract::<T, R, D, K, false, FULL>(ch, rel, s, comps)
    };
    let (w, dw) = (&s.w, &s.dw);
    let f_w = in_slots::<T, R, K>(|o0| w[0][o0]);
    let f_dw = in_slots::<T, R, K>(|o0| dw[0][o0]);
    let f_wo = in_slots::<T, R, K>(|o0| w[0][o0] * T::from_i32(o0 as i32));
    (acc, finite, [f_w, f_dw, f_wo])
}

/// The sums `A_k` of the module docs as packed vectors (`acc[k][j]`, vector `j`; `A₃`, `A₄`
/// with `FULL`), and whether every value read is finite. `SAME`: every channel read has unit
/// axis-0 stride and the strides of channel `comps.0`.
///
/// # Safety
/// As [`node_field_sums`].
#[inline(always)]
unsafe fn contract<
    T: Real,
    R: Lane<Scalar = T>,
    const D: usize,
    const K: usize,
    const SAME: bool,
    const FULL: bool,
>(
    ch: &[InChannel<T, D>; D],
    rel: &[isize; D],
    s: &Stencil<T, D>,
    comps: (usize, usize),
) -> ([[R; 2]; 5], bool) {
    let z = R::splat(T::ZERO);
    let sp = R::splat;
    let (w, dw) = (&s.w, &s.dw);
    let pv = D.div_ceil(2);
    let o = |i: usize| T::from_i32(i as i32);
    // The stencil's first node in each channel read (with `SAME`, one offset for all).
    let shared = if SAME {
        node_offset(&ch[comps.0], rel)
    } else {
        0
    };
    let mut p = [core::ptr::null::<T>(); D];
    for (a, pa) in p.iter_mut().enumerate() {
        if comps.0 <= a && a < comps.1 {
            let off = if SAME {
                shared
            } else {
                node_offset(&ch[a], rel)
            };
            *pa = ch[a].data.offset(off);
        }
    }
    // Σ x·0 over every vector read: NaN exactly when some value read is not finite (a
    // multiply per vector instead of a compare and a mask test). A row's vectors are combined
    // off the chain, which is one addition per row: a chain of a multiply-add per vector was
    // the longest in a particle's sums.
    let mut chk = z;
    let mut acc = [[z; 2]; 5];
    if D == 2 {
        for o1 in 0..K {
            let u = row::<T, R, D, K, SAME>(ch, &p, [o1, 0], comps);
            chk += zeros(&u, pv);
            for j in 0..pv {
                acc[0][j] = u[j].mul_add(sp(w[1][o1]), acc[0][j]);
                acc[1][j] = u[j].mul_add(sp(dw[1][o1]), acc[1][j]);
                if FULL && o1 > 0 {
                    acc[3][j] = u[j].mul_add(sp(w[1][o1] * o(o1)), acc[3][j]);
                }
            }
        }
    } else {
        for o2 in 0..K {
            let (mut sw, mut sd, mut so) = ([z; 2], [z; 2], [z; 2]);
            for o1 in 0..K {
                let u = row::<T, R, D, K, SAME>(ch, &p, [o1, o2], comps);
                chk += zeros(&u, pv);
                for j in 0..pv {
                    sw[j] = u[j].mul_add(sp(w[1][o1]), sw[j]);
                    sd[j] = u[j].mul_add(sp(dw[1][o1]), sd[j]);
                    if FULL && o1 > 0 {
                        so[j] = u[j].mul_add(sp(w[1][o1] * o(o1)), so[j]);
                    }
                }
            }
            // Axis 2 is `D - 1` (3D here); indexing by it keeps the 2D build in bounds.
            let (w2, dw2) = (w[D - 1][o2], dw[D - 1][o2]);
            for j in 0..pv {
                acc[0][j] = sw[j].mul_add(sp(w2), acc[0][j]);
                acc[1][j] = sd[j].mul_add(sp(w2), acc[1][j]);
                acc[2][j] = sw[j].mul_add(sp(dw2), acc[2][j]);
                if FULL {
                    acc[3][j] = so[j].mul_add(sp(w2), acc[3][j]);
                    if o2 > 0 {
                        acc[4][j] = sw[j].mul_add(sp(w2 * o(o2)), acc[4][j]);
                    }
                }
            }
        }
    }
    let ok = R::all(chk.is_finite());
    (acc, ok)
}

/// `Σ_j u[j]·0` over the first `pv` vectors of a row (NaN exactly when a lane is not finite).
#[inline(always)]
fn zeros<R: Lane>(u: &[R; 2], pv: usize) -> R {
    let z = R::splat(R::Scalar::ZERO);
    if pv == 2 {
        u[0].mul_add(z, u[1] * z)
    } else {
        u[0] * z
    }
}

/// The node row with offsets `o₁ = o[0]`, `o₂ = o[1]` of the components read, packed into two
/// vectors as in the module docs (`p` the stencil's first node per channel; `SAME` as in
/// [`contract`]). A function rather than a closure: a closure would not inherit the
/// instruction set's target features, and its vector intrinsics would become calls.
///
/// # Safety
/// As [`node_field_sums`].
#[inline(always)]
unsafe fn row<T: Real, R: Lane<Scalar = T>, const D: usize, const K: usize, const SAME: bool>(
    ch: &[InChannel<T, D>; D],
    p: &[*const T; D],
    o: [usize; 2],
    comps: (usize, usize),
) -> [R; 2] {
    let mut v = [R::splat(T::ZERO); 2];
    for a in 0..D {
        if a < comps.0 || a >= comps.1 {
            continue;
        }
        let st = if SAME {
            &ch[comps.0].stride
        } else {
            &ch[a].stride
        };
        let mut off = 0;
        for b in 1..D {
            off += o[b - 1] as isize * st[b];
        }
        let pa = p[a].offset(off);
        let sh = SLOT * (a % 2);
        let x = if SAME || st[0] == 1 {
            // Lanes `sh..sh + K` from `pa[0..K]` (the other lanes are not accessed).
            R::load_mask(pa.wrapping_sub(sh), ((1u32 << K) - 1) << sh)
        } else {
            let mut b = [T::ZERO; LANES];
            for o0 in 0..K {
                b[sh + o0] = pa.offset(o0 as isize * st[0]).read_unaligned();
            }
            R::load(&b)
        };
        // Disjoint lanes: adding zeros is exact.
        v[a / 2] += x;
    }
    v
}

/// `Σ_i w_i a_i` and `Σ_i w_i (a_i − b_i)` over the `N = K^d` nodes of stencil `s` for two
/// scalar node channels `a`, `b` (G2P's `Tⁿ⁺¹` and `Tⁿ`) at box-relative base `rel`, by the
/// contraction of the module docs with `A₀` only: a node row of `a` in lanes `0..K` and of
/// `a − b` in lanes `4..4 + K` (the node difference is exact when the two are within a factor
/// 2, Sterbenz). And whether every value read is finite: `a` and `b` are tested, not their
/// difference, so that a difference that overflows is left to the caller's check of the sums.
///
/// # Safety
/// Every stencil node is inside the box of both channels (checked by `rel_base`).
#[inline(always)]
pub(crate) unsafe fn pair_sums<T: Real, R: Lane<Scalar = T>, const D: usize, const K: usize>(
    s: &Stencil<T, D>,
    rel: &[isize; D],
    a: &InChannel<T, D>,
    b: &InChannel<T, D>,
) -> (T, T, bool) {
    let (p, finite) = pair_products::<T, R, D, K>(s, rel, a, b);
    let mut l = [T::ZERO; LANES];
    p.store(&mut l);
    let (mut pic, mut flip) = (l[0], l[SLOT]);
    for o0 in 1..K {
        pic += l[o0];
        flip += l[SLOT + o0];
    }
    (pic, flip, finite)
}

/// The product vector of [`pair_sums`] before its lane sums (`Σ w a` in slot 0, `Σ w (a − b)`
/// in slot 1, each summed in order from lane `4c`), and whether every value read is finite.
///
/// # Safety
/// As [`pair_sums`].
#[inline(always)]
pub(crate) unsafe fn pair_products<T: Real, R: Lane<Scalar = T>, const D: usize, const K: usize>(
    s: &Stencil<T, D>,
    rel: &[isize; D],
    a: &InChannel<T, D>,
    b: &InChannel<T, D>,
) -> (R, bool) {
    debug_assert!(R::LANES == LANES && K <= SLOT && (D == 2 || D == 3));
    let z = R::splat(T::ZERO);
    let sp = R::splat;
    let w = &s.w;
    let (pa, pb) = (first_node(a, rel), first_node(b, rel));
    let contiguous = a.stride[0] == 1 && b.stride[0] == 1;
    let mut chk = z;
    let mut acc = z;
    // Axis 2 is `D - 1` in 3D; in 2D there is one level (`o₂ = 0` only, weight 1 not applied).
    let levels = if D == 3 { K } else { 1 };
    for o2 in 0..levels {
        let mut sw = z;
        for o1 in 0..K {
            let o = [o1, o2];
            let (va, vb) = pair_row::<T, R, D, K>(pa, pb, &a.stride, &b.stride, o, contiguous);
            // `a·0 + b·0` formed off the chain: one addition per row on it, not two FMAs.
            chk += zeros(&[va, vb], 2);
            sw = (va - vb).mul_add(sp(w[1][o1]), sw);
        }
        acc = if D == 3 {
            sw.mul_add(sp(w[D - 1][o2]), acc)
        } else {
            sw
        };
    }
    let f_w = in_slots::<T, R, K>(|o0| w[0][o0]);
    (acc * f_w, R::all(chk.is_finite()))
}

/// Node row `o` (offsets along axes 1, 2) of two scalar channels for [`pair_sums`]: `a` in
/// lanes `0..K` and `4..4 + K`, and `b` in lanes `4..4 + K` (others 0), from the stencil's
/// first node `pa`, `pb` of each.
///
/// # Safety
/// As [`pair_sums`].
#[inline(always)]
unsafe fn pair_row<T: Real, R: Lane<Scalar = T>, const D: usize, const K: usize>(
    pa: *const T,
    pb: *const T,
    sa: &[isize; D],
    sb: &[isize; D],
    o: [usize; 2],
    contiguous: bool,
) -> (R, R) {
    let (mut oa, mut ob) = (0isize, 0isize);
    for d in 1..D {
        oa += o[d - 1] as isize * sa[d];
        ob += o[d - 1] as isize * sb[d];
    }
    let (ra, rb) = (pa.offset(oa), pb.offset(ob));
    let low = (1u32 << K) - 1;
    if contiguous {
        // One masked load per channel; `a`'s row repeated in the high half in registers.
        let va = R::load_mask(ra, low).dup_low_half();
        let vb = R::load_mask(rb.wrapping_sub(SLOT), low << SLOT);
        return (va, vb);
    }
    let (mut la, mut lb) = ([T::ZERO; LANES], [T::ZERO; LANES]);
    for o0 in 0..K {
        let x = ra.offset(o0 as isize * sa[0]).read_unaligned();
        la[o0] = x;
        la[SLOT + o0] = x;
        lb[SLOT + o0] = rb.offset(o0 as isize * sb[0]).read_unaligned();
    }
    (R::load(&la), R::load(&lb))
}

/// The address of a stencil's first node (box-relative base `rel`) in channel `c`.
///
/// # Safety
/// The node is inside the channel's box.
#[inline(always)]
pub(super) unsafe fn first_node<T, const D: usize>(
    c: &InChannel<T, D>,
    rel: &[isize; D],
) -> *const T {
    c.data.offset(node_offset(c, rel))
}

/// The offset (in scalars) from `c.data` of a stencil's first node (box-relative base `rel`)
/// in channel `c`.
#[inline(always)]
pub(super) fn node_offset<T, const D: usize>(c: &InChannel<T, D>, rel: &[isize; D]) -> isize {
    let mut off = 0;
    for d in 0..D {
        off += rel[d] * c.stride[d];
    }
    off
}

/// `f(o₀)` in lanes `o₀` and `4 + o₀` of a row vector (`o₀ < K`; the other lanes 0), put
/// together by lane selects: a vector load of scalars just stored would wait for the stores
/// to reach the cache (no store forwarding). `f` computes scalars only.
#[inline(always)]
fn in_slots<T: Real, R: Lane<Scalar = T>, const K: usize>(f: impl Fn(usize) -> T) -> R {
    let mut idx = [T::ZERO; LANES];
    for (l, x) in idx.iter_mut().enumerate() {
        *x = T::from_i32((l % SLOT) as i32);
    }
    let idx = R::load(&idx);
    let mut v = R::splat(T::ZERO);
    for o0 in 0..K {
        v = R::select(idx.eq(R::splat(T::from_i32(o0 as i32))), R::splat(f(o0)), v);
    }
    v
}

#[cfg(test)]
mod tests;
