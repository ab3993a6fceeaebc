//! The temperature pair's sums of eight particles at once ([`chunk_sums`] of
//! [`pair_products`], G2P's chunks) against each particle's own [`pair_sums`], bit for bit, on
//! every row type the CPU has, on separate node arrays and on interleaved nodes.

use super::{chunk_sums, pair_products, pair_sums, InChannel, LANES};
use crate::kernel::batch::{dispatch, BatchReal};
use crate::lane::{Isa, Lane};
use crate::particle::stencil::{Grid, Kernel, Stencil};
use crate::particle::transfer::nodes::rel_base;
use crate::particle::transfer::row_check::{ByRows, RowCheck};
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
    fn rows_on<R: Lane<Scalar = T>, const K: usize>(&mut self) {
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
        // The pair (new, old) from components 0 and 1: values of mixed magnitudes, so that
        // their differences round too.
        let z = R::splat(T::ZERO);
        let mut prods = [z; LANES];
        for k in 0..LANES {
            let (p, ok) = pair_products::<T, R, 3, K>(&s[k], &rel[k], &ch[0], &ch[1]);
            assert!(ok);
            prods[k] = p;
        }
        let mut got = [[T::ZERO; LANES]; 2];
        for (g, x) in got.iter_mut().zip(chunk_sums::<R, K>(prods)) {
            x.store(g);
        }
        for k in 0..LANES {
            let (pic, flip, ok) = pair_sums::<T, R, 3, K>(&s[k], &rel[k], &ch[0], &ch[1]);
            assert!(ok);
            for (q, want) in [pic, flip].iter().enumerate() {
                assert_eq!(
                    got[q][k].to_f64().to_bits(),
                    want.to_f64().to_bits(),
                    "{} lanes, K = {K}: output {q} particle {k}",
                    R::LANES
                );
            }
        }
    }
}

impl<T: Real> RowCheck<T> for Check<'_, T> {
    fn kernel(&self) -> Kernel {
        self.kernel
    }

    fn rows<R: Lane<Scalar = T>, const K: usize>(&mut self) {
        self.rows_on::<R, K>();
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
            dispatch::<T, _>(isa, &mut ByRows(&mut c));
            total += c.done;
        }
    }
    assert!(total >= 2 * 64, "{total}");
}

#[test]
fn chunk_pair_sums_give_each_particles_sums_f32() {
    compare::<f32>();
}

#[test]
fn chunk_pair_sums_give_each_particles_sums_f64() {
    compare::<f64>();
}
