//! G2P's node sums with one particle per SIMD lane: for a chunk of eight particles, the sums
//! over each particle's stencil of a node vector field `u` (the velocities),
//! `Σ_i w_i u_i`, the gradient `Σ_i u_i ∇w_iᵀ` and the moments `Σ_i w_i u_i o_iᵀ` (`o` the
//! node offset from the stencil base), every lane its own particle.
//!
//! **Order.** With the tensor-product weights `w_i = Π_a w_a[o_a]`
//! ([`Stencil`](crate::particle::stencil::Stencil)), per node row (the `K` nodes that differ in
//! axis 0 only; rows in order `o₂` outer, `o₁` inner; 2D has no `o₂`) and component `a`, first
//! the row's axis-0 sums, each a product and then multiply-adds in `o₀` order:
//! `S = Σ_{o₀} w₀[o₀] u`, `S′ = Σ_{o₀} dw₀[o₀] u`, `S° = Σ_{o₀ ≥ 1} (w₀[o₀] o₀) u`;
//! then, with the row factors `c = w₁ w₂` (2D: `w₁`), `c₁ = dw₁ w₂`, `c₂ = w₁ dw₂`, one
//! multiply-add per output into sums that start at 0: `Σ w u += c S`, `G_{a0} += c S′`,
//! `G_{a1} += c₁ S`, `G_{a2} += c₂ S`, moment `a0 += c S°`, `a1 += (c o₁) S` (`o₁ ≥ 1`),
//! `a2 += (c o₂) S` (`o₂ ≥ 1`). The sums equal the node-by-node ones up to rounding; every lane
//! runs the same operations in the same order, so a particle's sums have the same bits in every
//! lane, in a whole or a partial chunk, beside any other particles.
//!
//! **Reads.** Each row of a lane is `K` scalars of one channel (axis-0 stride `s₀`); the rows of
//! the eight lanes are loaded and transposed together ([`Lane::load_rows`]), so that no lane
//! sum crosses lanes and no output is transposed afterwards. A row is addressed as one base
//! pointer (the channel's data plus the row's offset) plus each lane's offset of its first
//! node, formed once per chunk: no per-lane pointers per row. That the values read are finite
//! is tested as `Σ x·0` (NaN exactly when some value read by the lane is not finite), a few
//! multiply-adds per row kept off the sums' chains.

use super::field_sums::node_offset;
use super::InChannel;
use crate::lane::Lane;
use crate::particle::stencil::StencilLanes;
use crate::scalar::Real;

/// Particles per chunk: the eight lanes of the row types.
pub(super) const LANES: usize = super::update_lanes::LANES;

/// The sums of one node vector field over each lane's stencil (component `a`, axis `b`).
pub(super) struct LaneSums<L, const D: usize> {
    /// `Σ_i w_i u_{a,i}`.
    pub v: [L; D],
    /// `g[b][a] = Σ_i u_{a,i} ∂w_i/∂x_b` (1/m times the units of `u`).
    pub g: [[L; D]; D],
    /// `mo[b][a] = Σ_i w_i u_{a,i} o_{i,b}`.
    pub mo: [[L; D]; D],
    /// NaN in a lane exactly when a value that lane read is not finite (else 0).
    pub chk: L,
}

/// The [`LaneSums`] of the field `ch` (components `0..d`) for the lanes' stencils with weights
/// `wt`: `first[a][l]` is the offset (in scalars) from `ch[a].data` of lane `l`'s first
/// stencil node in channel `a` (node offset 0 on every axis), in the order of the module docs.
/// `SAME`: every channel has the strides of channel 0 and `first[0]` serves every channel
/// (the others are not read).
///
/// # Safety
/// Every node of every lane's stencil is valid for reading in each channel.
#[inline(always)]
pub(super) unsafe fn lane_field_sums<
    T: Real,
    L: Lane<Scalar = T>,
    const D: usize,
    const K: usize,
    const SAME: bool,
>(
    wt: &StencilLanes<L>,
    ch: &[InChannel<T, D>; D],
    first: &[[isize; LANES]; D],
) -> LaneSums<L, D> {
    debug_assert!(L::LANES == LANES && K <= 4 && (D == 2 || D == 3));
    let z = L::splat(T::ZERO);
    let (w, dw) = (&wt.w, &wt.dw);
    // The offsets `0..4` on every lane, and `w₀[o₀] o₀` (entry 0 unused). (Arrays, not
    // closures: a closure would not inherit the caller's target features.)
    let mut o = [z; 4];
    let mut w0o = [z; 4];
    for i in 1..4 {
        o[i] = L::splat(T::from_i32(i as i32));
        w0o[i] = w[0][i] * o[i];
    }
    let mut s = LaneSums {
        v: [z; D],
        g: [[z; D]; D],
        mo: [[z; D]; D],
        chk: z,
    };
    // One finiteness sum per component: independent chains.
    let mut chk = [z; 3];
    let outer = if D == 3 { K } else { 1 };
    for o2 in 0..outer {
        for o1 in 0..K {
            // Axis 2 is `D − 1` (3D here); indexing by it keeps the 2D build in bounds.
            let (c, c1, c2) = if D == 3 {
                let (w2, dw2) = (w[D - 1][o2], dw[D - 1][o2]);
                (w[1][o1] * w2, dw[1][o1] * w2, w[1][o1] * dw2)
            } else {
                (w[1][o1], dw[1][o1], z)
            };
            for a in 0..D {
                let (st, lanes) = match SAME {
                    true => (&ch[0].stride, &first[0]),
                    false => (&ch[a].stride, &first[a]),
                };
                let mut off = o1 as isize * st[1];
                if D == 3 {
                    off += o2 as isize * st[D - 1];
                }
                // Each lane's row: the row's base plus the lane's offset, no per-lane pointer.
                let u = L::load_rows::<K>(ch[a].data.wrapping_offset(off), lanes, st[0]);
                let mut zs = u[0] * z;
                let mut sw = u[0] * w[0][0];
                let mut sd = u[0] * dw[0][0];
                let mut so = z;
                for o0 in 1..K {
                    zs = u[o0].mul_add(z, zs);
                    sw = u[o0].mul_add(w[0][o0], sw);
                    sd = u[o0].mul_add(dw[0][o0], sd);
                    so = if o0 == 1 {
                        u[o0] * w0o[o0]
                    } else {
                        u[o0].mul_add(w0o[o0], so)
                    };
                }
                chk[a] += zs;
                s.g[0][a] = c.mul_add(sd, s.g[0][a]);
                s.g[1][a] = c1.mul_add(sw, s.g[1][a]);
                if D == 3 {
                    s.g[D - 1][a] = c2.mul_add(sw, s.g[D - 1][a]);
                }
                s.v[a] = c.mul_add(sw, s.v[a]);
                s.mo[0][a] = c.mul_add(so, s.mo[0][a]);
                if o1 > 0 {
                    s.mo[1][a] = (c * o[o1]).mul_add(sw, s.mo[1][a]);
                }
                if D == 3 && o2 > 0 {
                    s.mo[D - 1][a] = (c * o[o2]).mul_add(sw, s.mo[D - 1][a]);
                }
            }
        }
    }
    s.chk = chk[0] + chk[1] + chk[2];
    s
}

/// [`lane_field_sums`] of the chunk's particles (weights `wt`, box-relative bases `rel`) whose
/// bit is set in `live` (not 0), lane `l` particle `l`; a lane not in `live` reads the nodes
/// of the first lane that is (its sums are not used).
///
/// # Safety
/// Every node of each live lane's stencil is valid for reading in each channel.
#[inline(always)]
pub(super) unsafe fn chunk_field_sums<
    T: Real,
    L: Lane<Scalar = T>,
    const D: usize,
    const K: usize,
>(
    wt: &StencilLanes<L>,
    rel: &[[isize; D]; LANES],
    live: u32,
    ch: &[InChannel<T, D>; D],
) -> LaneSums<L, D> {
    debug_assert!(live != 0);
    let fill = live.trailing_zeros() as usize;
    // Channels with the same strides (separate arrays of one box, the usual layout, or
    // interleaved node structs) share each lane's node offset.
    let same = ch.iter().all(|c| c.stride == ch[0].stride);
    let mut first = [[0isize; LANES]; D];
    for k in 0..LANES {
        let r = &rel[if live >> k & 1 == 1 { k } else { fill }];
        for (a, f) in first.iter_mut().enumerate().take(if same { 1 } else { D }) {
            f[k] = node_offset(&ch[a], r);
        }
    }
    if same {
        lane_field_sums::<T, L, D, K, true>(wt, ch, &first)
    } else {
        lane_field_sums::<T, L, D, K, false>(wt, ch, &first)
    }
}

#[cfg(test)]
mod tests;
