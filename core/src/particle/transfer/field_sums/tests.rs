//! The sums of eight particles at once ([`chunk_sums`] of [`node_field_products`], G2P's
//! samples and the force differential's `G` in 3D) against each particle's own
//! [`node_field_sums`], bit for bit, on every row type the CPU has, on separate node arrays
//! and on interleaved nodes.

use super::{chunk_sums, node_field_products, node_field_sums, InChannel, LANES, MAX_OUT};
use crate::kernel::batch::{dispatch, BatchReal, BatchStatus, LaneOp};
use crate::lane::{Isa, Lane};
use crate::particle::stencil::{Grid, Kernel, Stencil};
use crate::particle::transfer::nodes::rel_base;
use crate::particle::transfer::NodeBox;
use crate::scalar::Real;
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;
use std::vec::Vec;

/// Nodes per axis of the test box.
const CELLS: usize = 12;

/// Runs the comparison with the row type of an instruction set.
struct Check<'a, T> {
    kernel: Kernel,
    /// Node values: three components, separate arrays (`[a][node]`).
    sep: &'a [Vec<T>; 3],
    /// The same values interleaved (`[node][a]`).
    inter: &'a [T],
    xs: &'a [[T; 3]],
    /// Chunks compared.
    done: usize,
}

impl<T: Real> Check<'_, T> {
    /// Compares per chunk of eight positions, on both layouts.
    fn rows<R: Lane<Scalar = T>, const K: usize>(&mut self) {
        let n = CELLS as i32;
        let nodes = NodeBox {
            lo: [0; 3],
            dims: [n; 3],
        };
        let c = CELLS as isize;
        let sep: [InChannel<T, 3>; 3] = core::array::from_fn(|a| InChannel {
            data: self.sep[a].as_ptr(),
            stride: [1, c, c * c],
        });
        let inter: [InChannel<T, 3>; 3] = core::array::from_fn(|a| InChannel {
            data: self.inter[a..].as_ptr(),
            stride: [3, 3 * c, 3 * c * c],
        });
        let h = T::ONE;
        for chunk in self.xs.chunks_exact(LANES) {
            let s: [Stencil<T, 3>; LANES] = core::array::from_fn(|k| {
                Stencil::new(self.kernel, Grid::Collocated, h, &chunk[k]).unwrap()
            });
            let rel: [[isize; 3]; LANES] =
                core::array::from_fn(|k| rel_base(&s[k], &nodes).unwrap());
            for ch in [&sep, &inter] {
                // SAFETY: every stencil is inside the box (`rel_base`), whose nodes the
                // channels hold.
                unsafe { self.compare::<R, K>(&s, &rel, ch) };
            }
            self.done += 1;
        }
    }

    /// # Safety
    /// Every stencil is inside the channels' box.
    unsafe fn compare<R: Lane<Scalar = T>, const K: usize>(
        &self,
        s: &[Stencil<T, 3>; LANES],
        rel: &[[isize; 3]; LANES],
        ch: &[InChannel<T, 3>; 3],
    ) {
        let z = R::splat(T::ZERO);
        let mut prods = [[[z; LANES]; 2]; MAX_OUT];
        for k in 0..LANES {
            let (p, ok) = node_field_products::<T, R, 3, K>(&s[k], &rel[k], ch);
            assert!(ok);
            for (pq, x) in prods.iter_mut().zip(&p) {
                for j in 0..2 {
                    pq[j][k] = x[j];
                }
            }
        }
        // got[q][a][k]: output `q`, component `a`, particle `k`.
        let mut got = [[[T::ZERO; LANES]; 3]; MAX_OUT];
        for (gq, pq) in got.iter_mut().zip(&prods).take(7) {
            for j in 0..2 {
                let sums = chunk_sums::<R, K>(pq[j]);
                sums[0].store(&mut gq[2 * j]);
                if j == 0 {
                    sums[1].store(&mut gq[1]);
                }
            }
        }
        for k in 0..LANES {
            let want = node_field_sums::<T, R, 3, K, true>(&s[k], &rel[k], ch, (0, 3));
            assert!(want.finite);
            for a in 0..3 {
                let mut w = std::vec![];
                for b in 0..3 {
                    w.push(want.g.cols[b][a]);
                }
                w.push(want.v[a]);
                for b in 0..3 {
                    w.push(want.mo.cols[b][a]);
                }
                for (q, wq) in w.iter().enumerate() {
                    assert_eq!(
                        got[q][a][k].to_f64().to_bits(),
                        wq.to_f64().to_bits(),
                        "{} lanes, K = {K}: output {q} component {a} particle {k}",
                        R::LANES
                    );
                }
            }
        }
    }
}

impl<T: Real> LaneOp<T> for Check<'_, T> {
    fn run<V: Lane<Scalar = T>>(&mut self) -> BatchStatus {
        BatchStatus {
            first_failed: 0,
            error: None,
        }
    }

    fn run_rows<V: Lane<Scalar = T>, R: Lane<Scalar = T>>(&mut self) -> BatchStatus {
        match self.kernel {
            Kernel::Quadratic => self.rows::<R, 3>(),
            Kernel::Cubic => self.rows::<R, 4>(),
        }
        self.run::<V>()
    }
}

fn compare<T: BatchReal>() {
    let mut rng = Pcg64::seed_from_u64(0x2545_f491_4f6c_dd1d);
    let nn = CELLS * CELLS * CELLS;
    // Values of mixed signs and magnitudes, so that the order of every sum shows in its bits.
    let mut val =
        || T::from_f64((rng.random::<f64>() - 0.5) * libm::exp2(40.0 * rng.random::<f64>() - 20.0));
    let sep: [Vec<T>; 3] = core::array::from_fn(|_| (0..nn).map(|_| val()).collect());
    let mut inter = std::vec![T::ZERO; 3 * nn];
    for (i, x) in inter.iter_mut().enumerate() {
        *x = sep[i % 3][i / 3];
    }
    // Positions (in cells, h = 1) whose stencils stay inside the box.
    let xs: Vec<[T; 3]> = (0..64 * LANES)
        .map(|_| {
            core::array::from_fn(|_| T::from_f64(3.0 + (CELLS as f64 - 6.0) * rng.random::<f64>()))
        })
        .collect();
    let mut total = 0;
    for isa in Isa::available() {
        for kernel in [Kernel::Quadratic, Kernel::Cubic] {
            let mut c = Check {
                kernel,
                sep: &sep,
                inter: &inter,
                xs: &xs,
                done: 0,
            };
            dispatch::<T, _>(isa, &mut c);
            total += c.done;
        }
    }
    assert!(total >= 2 * 64, "{total}");
}

#[test]
fn chunk_sums_give_each_particles_sums_f32() {
    compare::<f32>();
}

#[test]
fn chunk_sums_give_each_particles_sums_f64() {
    compare::<f64>();
}
