//! The sums of one particle per lane ([`lane_field_sums`]): a particle's sums have the same
//! bits in whatever lane and beside whatever particles (on every row type the CPU has, both
//! kernels, separate and interleaved node arrays, 2D and 3D); they match a node-by-node `f64`
//! sum within a rounding bound derived from their operation count; a value read that is not
//! finite shows in exactly the lanes that read it.

use super::{lane_field_sums, LaneSums, LANES};
use crate::kernel::batch::{dispatch, BatchReal};
use crate::lane::{Isa, Lane};
use crate::particle::stencil::{Grid, Kernel, Stencil, StencilLanes};
use crate::particle::transfer::field_sums::node_offset;
use crate::particle::transfer::nodes::rel_base;
use crate::particle::transfer::row_check::{ByRows, RowCheck};
use crate::particle::transfer::{InChannel, NodeBox};
use crate::scalar::Real;
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;
use std::vec::Vec;

/// Nodes per axis of the test box.
const CELLS: usize = 12;

/// The node values, separate (`[a][node]`) and interleaved (`[node][a]`), and the positions.
struct Data<T, const D: usize> {
    sep: [Vec<T>; D],
    inter: Vec<T>,
    xs: Vec<[T; D]>,
}

/// One lane's sums as `f64`: `(v[a], g[b][a], mo[b][a], chk)`.
type Out<const D: usize> = ([f64; D], [[f64; D]; D], [[f64; D]; D], f64);

fn lane<T: Real, L: Lane<Scalar = T>, const D: usize>(s: &LaneSums<L, D>, l: usize) -> Out<D> {
    let at = |x: L| {
        let mut b = [T::ZERO; 16];
        x.store(&mut b);
        b[l].to_f64()
    };
    (
        core::array::from_fn(|a| at(s.v[a])),
        core::array::from_fn(|b| core::array::from_fn(|a| at(s.g[b][a]))),
        core::array::from_fn(|b| core::array::from_fn(|a| at(s.mo[b][a]))),
        at(s.chk),
    )
}

fn bits<const D: usize>(o: &Out<D>) -> Vec<u64> {
    let mut v: Vec<u64> = o.0.iter().map(|x| x.to_bits()).collect();
    for b in 0..D {
        v.extend(o.1[b].iter().chain(&o.2[b]).map(|x| x.to_bits()));
    }
    v.push(o.3.to_bits());
    v
}

struct Check<'a, T, const D: usize> {
    kernel: Kernel,
    data: &'a Data<T, D>,
    /// Chunks compared.
    done: usize,
}

impl<T: Real, const D: usize> Check<'_, T, D> {
    fn channels(&self) -> [[InChannel<T, D>; D]; 2] {
        let c = CELLS as isize;
        let stride = |s0: isize| core::array::from_fn(|b| s0 * c.pow(b as u32));
        [
            core::array::from_fn(|a| InChannel {
                data: self.data.sep[a].as_ptr(),
                stride: stride(1),
            }),
            core::array::from_fn(|a| InChannel {
                data: self.data.inter[a..].as_ptr(),
                stride: stride(D as isize),
            }),
        ]
    }

    /// The sums of the particles `idx` (one per lane) from channels `ch`.
    ///
    /// # Safety
    /// Every stencil is inside the channels' box.
    unsafe fn sums<L: Lane<Scalar = T>, const K: usize>(
        &self,
        idx: [usize; LANES],
        ch: &[InChannel<T, D>; D],
    ) -> (LaneSums<L, D>, [Stencil<T, D>; LANES]) {
        let nodes = NodeBox {
            lo: [0; D],
            dims: [CELLS as i32; D],
        };
        let s: [Stencil<T, D>; LANES] = core::array::from_fn(|k| {
            Stencil::new(self.kernel, Grid::Collocated, T::ONE, &self.data.xs[idx[k]]).unwrap()
        });
        let mut first = [[0isize; LANES]; D];
        for (k, st) in s.iter().enumerate() {
            let rel = rel_base(st, &nodes).unwrap();
            for a in 0..D {
                first[a][k] = node_offset(&ch[a], &rel);
            }
        }
        let wt = StencilLanes::<L>::of::<D, K>(&s);
        // Both layouts have one stride set for every channel: the sums that share channel 0's
        // offsets and the ones that read each channel's are the same.
        let own = lane_field_sums::<T, L, D, K, false>(&wt, ch, &first);
        let shared = lane_field_sums::<T, L, D, K, true>(&wt, ch, &first);
        for k in 0..LANES {
            assert_eq!(bits(&lane(&own, k)), bits(&lane(&shared, k)));
        }
        (own, s)
    }

    fn rows_on<L: Lane<Scalar = T>, const K: usize>(&mut self) {
        for ch in self.channels() {
            for c in 0..self.data.xs.len() / LANES {
                let idx: [usize; LANES] = core::array::from_fn(|k| c * LANES + k);
                // SAFETY: the positions keep every stencil inside the box.
                let (s, st) = unsafe { self.sums::<L, K>(idx, &ch) };
                for k in 0..LANES {
                    let got = lane(&s, k);
                    // The same particle in every lane, and in the reversed lane.
                    let (alone, _) = unsafe { self.sums::<L, K>([idx[k]; LANES], &ch) };
                    let mut rev = idx;
                    rev.reverse();
                    let (r, _) = unsafe { self.sums::<L, K>(rev, &ch) };
                    for other in [lane(&alone, k), lane(&alone, 0), lane(&r, LANES - 1 - k)] {
                        assert_eq!(bits(&got), bits(&other), "{} lanes, K = {K}", L::LANES);
                    }
                    self.against_reference::<K>(&got, &st[k], &ch);
                }
                self.done += 1;
            }
        }
        self.non_finite::<L, K>();
    }

    /// The sums against the node-by-node sums in `f64` (from the same stencil weights): the
    /// error of each is at most `γ_m Σ|terms|`, `γ_m = mε/(1 − mε)`, with `m = K + K^{d−1} + 3`
    /// roundings on a term's path (its row factor and axis-0 product, `K − 1` row additions,
    /// the moment's offset factor, one multiply-add per row), and the reference's own error at
    /// most `γ_r Σ|terms|` in `f64`, `r = K^d + d + 2` (its weight and term products, one
    /// addition per node).
    fn against_reference<const K: usize>(
        &self,
        got: &Out<D>,
        s: &Stencil<T, D>,
        ch: &[InChannel<T, D>; D],
    ) {
        let m = (K + K.pow(D as u32 - 1) + 3) as f64;
        let eps = T::EPSILON.to_f64() / 2.0;
        let r = (K.pow(D as u32) + D + 2) as f64;
        let e64 = f64::EPSILON / 2.0;
        let gamma = m * eps / (1.0 - m * eps) + r * e64 / (1.0 - r * e64);
        let nodes = NodeBox {
            lo: [0; D],
            dims: [CELLS as i32; D],
        };
        let rel = rel_base(s, &nodes).unwrap();
        let mut want: Out<D> = ([0.0; D], [[0.0; D]; D], [[0.0; D]; D], 0.0);
        let mut mag: Out<D> = ([0.0; D], [[0.0; D]; D], [[0.0; D]; D], 0.0);
        for n in 0..K.pow(D as u32) {
            let o: [usize; D] = core::array::from_fn(|a| n / K.pow(a as u32) % K);
            let w: f64 = (0..D).map(|a| s.w[a][o[a]].to_f64()).product();
            let dw: [f64; D] = core::array::from_fn(|b| {
                (0..D)
                    .map(|a| if a == b { s.dw[a][o[a]] } else { s.w[a][o[a]] }.to_f64())
                    .product()
            });
            for a in 0..D {
                let off: isize = (0..D)
                    .map(|b| (rel[b] + o[b] as isize) * ch[a].stride[b])
                    .sum();
                // SAFETY: the node is inside the box.
                let u = unsafe { ch[a].data.offset(off).read() }.to_f64();
                want.0[a] += w * u;
                mag.0[a] += (w * u).abs();
                for b in 0..D {
                    want.1[b][a] += dw[b] * u;
                    mag.1[b][a] += (dw[b] * u).abs();
                    want.2[b][a] += w * u * o[b] as f64;
                    mag.2[b][a] += (w * u * o[b] as f64).abs();
                }
            }
        }
        let close = |g: f64, w: f64, m: f64, what: &str| {
            assert!(
                (g - w).abs() <= gamma * m,
                "{what}: {g} against {w} (Σ|terms| {m})"
            );
        };
        for a in 0..D {
            close(got.0[a], want.0[a], mag.0[a], "Σ w u");
            for b in 0..D {
                close(got.1[b][a], want.1[b][a], mag.1[b][a], "G");
                close(got.2[b][a], want.2[b][a], mag.2[b][a], "moment");
            }
        }
        assert_eq!(got.3, 0.0);
    }

    /// A value that is not finite at one node: exactly the lanes whose stencil holds it get a
    /// `chk` that is not finite, on both layouts.
    fn non_finite<L: Lane<Scalar = T>, const K: usize>(&mut self) {
        let nodes = NodeBox {
            lo: [0; D],
            dims: [CELLS as i32; D],
        };
        let idx: [usize; LANES] = core::array::from_fn(|k| k);
        for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY].map(T::from_f64) {
            for comp in 0..D {
                // The last node of particle 0's stencil.
                let s0 =
                    Stencil::new(self.kernel, Grid::Collocated, T::ONE, &self.data.xs[0]).unwrap();
                let r0 = rel_base(&s0, &nodes).unwrap();
                let node: [isize; D] = core::array::from_fn(|a| r0[a] + K as isize - 1);
                let mut data = Data {
                    sep: self.data.sep.clone(),
                    inter: self.data.inter.clone(),
                    xs: self.data.xs.clone(),
                };
                let flat: isize = (0..D)
                    .map(|a| node[a] * (CELLS as isize).pow(a as u32))
                    .sum();
                data.sep[comp][flat as usize] = bad;
                data.inter[D * flat as usize + comp] = bad;
                let c = Check {
                    kernel: self.kernel,
                    data: &data,
                    done: 0,
                };
                for ch in c.channels() {
                    // SAFETY: as in `rows`.
                    let (s, st) = unsafe { c.sums::<L, K>(idx, &ch) };
                    for (k, stk) in st.iter().enumerate() {
                        let r = rel_base(stk, &nodes).unwrap();
                        let reads = (0..D).all(|a| r[a] <= node[a] && node[a] < r[a] + K as isize);
                        assert_eq!(!lane(&s, k).3.is_finite(), reads, "lane {k}");
                        if k == 0 {
                            assert!(reads);
                        }
                    }
                }
            }
        }
    }
}

impl<T: Real, const D: usize> RowCheck<T> for Check<'_, T, D> {
    fn kernel(&self) -> Kernel {
        self.kernel
    }

    fn rows<R: Lane<Scalar = T>, const K: usize>(&mut self) {
        self.rows_on::<R, K>();
    }
}

fn compare<T: BatchReal, const D: usize>() {
    let mut rng = Pcg64::seed_from_u64(0x2545_f491_4f6c_dd1d);
    let nn = CELLS.pow(D as u32);
    // Values of mixed signs and magnitudes, so that the order of every sum shows in its bits.
    let mut val =
        || T::from_f64((rng.random::<f64>() - 0.5) * libm::exp2(40.0 * rng.random::<f64>() - 20.0));
    let sep: [Vec<T>; D] = core::array::from_fn(|_| (0..nn).map(|_| val()).collect());
    let mut inter = std::vec![T::ZERO; D * nn];
    for (i, x) in inter.iter_mut().enumerate() {
        *x = sep[i % D][i / D];
    }
    // Positions (in cells, h = 1) whose stencils stay inside the box.
    let xs: Vec<[T; D]> = (0..16 * LANES)
        .map(|_| {
            core::array::from_fn(|_| T::from_f64(3.0 + (CELLS as f64 - 6.0) * rng.random::<f64>()))
        })
        .collect();
    let data = Data { sep, inter, xs };
    let mut total = 0;
    for isa in Isa::available() {
        for kernel in [Kernel::Quadratic, Kernel::Cubic] {
            let mut c = Check {
                kernel,
                data: &data,
                done: 0,
            };
            dispatch::<T, _>(isa, &mut ByRows(&mut c));
            total += c.done;
        }
    }
    assert!(total >= 2 * 2 * 16, "{total}");
}

#[test]
fn lane_sums_3d_f32() {
    compare::<f32, 3>();
}

#[test]
fn lane_sums_3d_f64() {
    compare::<f64, 3>();
}

#[test]
fn lane_sums_2d_f32() {
    compare::<f32, 2>();
}

#[test]
fn lane_sums_2d_f64() {
    compare::<f64, 2>();
}
