//! The stencils on SIMD lanes ([`Stencil::new_lanes`]) against the one-lane [`Stencil::new`]
//! (which `tests/particle/stencil.rs` checks against an independent f64 B-spline), bit for
//! bit, on every lane type the CPU has.

use super::{quadratic_axis, Grid, Kernel, Stencil, StencilLanes, MAX_CELLS, MAX_WIDTH};
use crate::kernel::batch::{dispatch, BatchReal, BatchStatus, LaneOp, WIDE_LANES};
use crate::lane::{Isa, Lane};
use crate::scalar::Real;
use std::vec::Vec;

/// The bits of a stencil (a `Stencil`'s `==` would take −0 for +0).
fn bits<T: Real, const D: usize>(s: &Stencil<T, D>) -> Vec<u64> {
    let mut v = std::vec![s.kernel.width() as u64, s.h.to_f64().to_bits()];
    for a in 0..D {
        v.push(s.base[a] as i64 as u64);
        v.push(s.fx[a].to_f64().to_bits());
        for o in 0..4 {
            v.push(s.w[a][o].to_f64().to_bits());
            v.push(s.dw[a][o].to_f64().to_bits());
        }
    }
    v
}

/// Runs `new_lanes` on the kernel lanes `V`, their wide form `V::Wide` and the row lanes `R` of
/// an instruction set and compares every lane with `Stencil::new`, both the stencils written and
/// their lane vectors ([`StencilLanes`]).
struct Check<'a, T, const D: usize> {
    kernel: Kernel,
    grid: Grid,
    h: T,
    xs: &'a [[T; D]],
    /// Lanes done, summed over both lane types and every chunk.
    done: usize,
}

impl<T: Real, const D: usize> Check<'_, T, D> {
    fn lanes<V: Lane<Scalar = T>>(&mut self) {
        let n = V::LANES;
        for chunk in self.xs.chunks(n) {
            let mut xs = [[T::ZERO; D]; WIDE_LANES];
            xs[..chunk.len()].copy_from_slice(chunk);
            // Placeholders with values that a lane must overwrite.
            let mut blank = Stencil::blank(Kernel::Cubic, T::from_i32(7));
            blank.w = [[T::from_i32(9); 4]; D];
            blank.base = [-5; D];
            let mut out = [blank; WIDE_LANES];
            let mut sl = StencilLanes::<V>::new();
            let (k, h) = (self.kernel, self.h);
            let done = Stencil::new_lanes::<V>(k, self.grid, h, &xs[..n], &mut out, Some(&mut sl));
            // Without `records`: the same lanes, the stencils' weights left as they were.
            let mut out2 = [blank; WIDE_LANES];
            let mut sl2 = StencilLanes::<V>::new();
            sl2.records = false;
            let done2 =
                Stencil::new_lanes::<V>(k, self.grid, h, &xs[..n], &mut out2, Some(&mut sl2));
            assert_eq!(done2, done);
            // Lane `l` of the lane vectors `s`, with the rest of `out[l]`.
            let lane = |s: &StencilLanes<V>, l: usize| {
                let at = |v: V| {
                    let mut a = [T::ZERO; WIDE_LANES];
                    v.store(&mut a[..n]);
                    a[l]
                };
                let mut r = out[l];
                for a in 0..D {
                    r.fx[a] = at(s.fx[a]);
                    for o in 0..4 {
                        (r.w[a][o], r.dw[a][o]) = (at(s.w[a][o]), at(s.dw[a][o]));
                    }
                }
                r
            };
            for (l, x) in xs.iter().enumerate().take(n) {
                let want = Stencil::new(self.kernel, self.grid, self.h, x);
                let on = done >> l & 1 == 1;
                assert_eq!(
                    on,
                    want.is_ok(),
                    "lane {l} of {n} at {x:?}: done vs {want:?}"
                );
                if let Ok(w) = want {
                    assert_eq!(bits(&out[l]), bits(&w), "lane {l} of {n} at {x:?}");
                    assert_eq!(bits(&lane(&sl, l)), bits(&w), "lane vectors {l} of {n}");
                    assert_eq!(bits(&lane(&sl2, l)), bits(&w), "no records: {l} of {n}");
                    let kept = Stencil {
                        w: blank.w,
                        dw: blank.dw,
                        ..w
                    };
                    assert_eq!(
                        bits(&out2[l]),
                        bits(&kept),
                        "no records: {l} of {n} at {x:?}"
                    );
                    self.done += 1;
                }
            }
        }
    }
}

impl<T: Real, const D: usize> LaneOp<T> for Check<'_, T, D> {
    fn run<V: Lane<Scalar = T>>(&mut self) -> BatchStatus {
        self.lanes::<V>();
        // P2G's chunks in `f32` (see `BatchReal::with_chunks`).
        self.lanes::<V::Wide>();
        BatchStatus {
            first_failed: 0,
            error: None,
        }
    }

    fn run_rows<V: Lane<Scalar = T>, R: Lane<Scalar = T>>(&mut self) -> BatchStatus {
        self.lanes::<R>();
        self.run::<V>()
    }
}

/// Positions in cells: random ones, every kernel branch boundary (integers, halves, ±0),
/// negative ones, the position limit on both sides, and non-finite ones.
fn positions<T: Real, const D: usize>(h: f64) -> Vec<[T; D]> {
    let mut rng = 0x2545_f491_4f6c_dd1d_u64;
    let mut next = || {
        rng ^= rng << 13;
        rng ^= rng >> 7;
        rng ^= rng << 17;
        (rng >> 11) as f64 / (1u64 << 53) as f64
    };
    let mut cells: Vec<f64> = std::vec![0.0, -0.0, 0.5, -0.5, 1.0, -1.0, 1.5, 2.0, 2.5, -2.5];
    for k in 1..30 {
        let e = f64::from(k);
        cells.extend([
            2f64.powf(e),
            -2f64.powf(e),
            2f64.powf(e) + 0.5,
            2f64.powf(e) - 0.25,
        ]);
    }
    let lim = MAX_CELLS;
    cells.extend([
        lim,
        -lim,
        lim * (1.0 - 1e-9),
        -lim * (1.0 - 1e-9),
        1e-40,
        -1e-300,
    ]);
    for _ in 0..200 {
        cells.push((next() - 0.5) * 200.0);
        cells.push((next() - 0.5) * 2e6);
    }
    let special = [f64::NAN, f64::INFINITY, f64::NEG_INFINITY, 1e300];
    let mut out = Vec::new();
    for (i, &c) in cells.iter().enumerate() {
        let mut x = [T::ZERO; D];
        for (a, xa) in x.iter_mut().enumerate() {
            // Each axis from another entry, so that axes differ.
            let ca = cells[(i + 7 * a) % cells.len()];
            let cell = if a == 0 { c } else { ca };
            *xa = T::from_f64(cell * h);
        }
        out.push(x);
    }
    for (i, &s) in special.iter().enumerate() {
        let mut x = [T::from_f64(1.25 * h); D];
        x[i % D] = T::from_f64(s);
        out.push(x);
    }
    out
}

fn compare<T: BatchReal, const D: usize>() {
    let mut total = 0;
    for isa in Isa::available() {
        for kernel in [Kernel::Quadratic, Kernel::Cubic] {
            let mut grids = std::vec![Grid::Collocated];
            grids.extend((0..D).map(Grid::Face));
            for grid in grids {
                for h in [1.0, 0.1, 3e-3] {
                    let xs = positions::<T, D>(h);
                    let mut c = Check {
                        kernel,
                        grid,
                        h: T::from_f64(h),
                        xs: &xs,
                        done: 0,
                    };
                    dispatch::<T, _>(isa, &mut c);
                    total += c.done;
                }
            }
        }
    }
    // Most positions are inside the limit: the comparison ran on them.
    assert!(total > 1000, "{total}");
}

#[test]
fn lanes_give_the_scalar_stencils_2d_f32() {
    compare::<f32, 2>();
}

#[test]
fn lanes_give_the_scalar_stencils_3d_f32() {
    compare::<f32, 3>();
}

#[test]
fn lanes_give_the_scalar_stencils_3d_f64() {
    compare::<f64, 3>();
}

/// An invalid spacing or face axis: no lane is done (each lane's `Stencil::new` reports it).
#[test]
fn invalid_spacing_or_face_does_no_lane() {
    let xs = [[0.25f32; 3]; 8];
    let mut out = [Stencil::blank(Kernel::Quadratic, 1.0); 8];
    for h in [0.0, -1.0, f32::NAN, f32::INFINITY, 1e-45] {
        let d =
            Stencil::new_lanes::<f32>(Kernel::Quadratic, Grid::Collocated, h, &xs, &mut out, None);
        assert_eq!(d, 0, "h = {h}");
    }
    let d = Stencil::new_lanes::<f32>(Kernel::Quadratic, Grid::Face(3), 1.0, &xs, &mut out, None);
    assert_eq!(d, 0);
}

/// [`quadratic_axis`] against [`Kernel::n_dn_lanes`] at `fx − o`, bit for bit, at `fx`.
fn quadratic_axis_matches<T: Real>(fx: T) {
    let (mut w, mut dw) = ([T::ZERO; MAX_WIDTH], [T::ZERO; MAX_WIDTH]);
    quadratic_axis(fx, &mut w, &mut dw);
    for o in 0..3 {
        let (n, dn) = Kernel::Quadratic.n_dn_lanes(fx - T::from_i32(o));
        let (a, b) = (w[o as usize].to_f64(), dw[o as usize].to_f64());
        assert_eq!(
            (a.to_bits(), b.to_bits()),
            (n.to_f64().to_bits(), dn.to_f64().to_bits()),
            "fx = {:e}, o = {o}: ({a:e}, {b:e}) against ({:e}, {:e})",
            fx.to_f64(),
            n.to_f64(),
            dn.to_f64()
        );
    }
}

/// The quadratic stencil's piece-free weights are the B-spline's, bit for bit, at every `f32`
/// value of `fx ∈ [½, ³⁄₂]` (the range `new_lanes` forms), and at the ends and a spread of
/// `f64` values.
#[test]
fn quadratic_axis_is_n_dn() {
    let (lo, hi) = (0.5f32.to_bits(), 1.5f32.to_bits());
    for b in lo..=hi {
        quadratic_axis_matches(f32::from_bits(b));
    }
    let (lo, hi) = (0.5f64.to_bits(), 1.5f64.to_bits());
    let step = (hi - lo) / 1_000_003;
    let ends = [lo, lo + 1, lo + 2, hi - 2, hi - 1, hi];
    for b in (lo..=hi).step_by(step as usize).chain(ends) {
        quadratic_axis_matches(f64::from_bits(b));
    }
    for fx in [
        0.5f64,
        0.75,
        1.0,
        1.25,
        1.5,
        1.0 - f64::EPSILON / 2.0,
        1.0 + f64::EPSILON,
    ] {
        quadratic_axis_matches(fx);
    }
}
