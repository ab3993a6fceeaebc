//! Batch transfers between particle arrays and the host's own grid, through grid views: P2G
//! scatter-adds into the host's node arrays, G2P gathers from them, and the force differential
//! of an implicit step maps node displacements to node forces. No per-node buffer is needed.
//!
//! **Grid view.** A [`NodeBox`] names the nodes `[lo, lo + dims)` (grid indices, per axis) that
//! the host's memory covers; a [`Channel`] addresses one scalar per node of the box: node `i` is
//! at `data + Σ_a (i_a − lo_a)·stride[a]`, strides in scalars (not bytes) and possibly negative
//! or zero-free in any order. Separate arrays (`stride = [1, nx, nx·ny]`) and interleaved node
//! structs (`stride = [s, s·nx, s·nx·ny]`, `data` offset to the field) are both views. A box
//! can be the whole grid, a block of it (for threads, see below), or one MAC face grid.
//!
//! **Node positions** are those of [`super::stencil`]: collocated nodes at `i h`, face grid `a`
//! at `i h` along `a` and `(j + ½) h` along the other axes. A particle whose stencil is not
//! inside the box fails with [`crate::Error::OutsideGrid`] and transfers nothing.
//!
//! **Batch contract.** Every particle is processed on its own: a particle that fails writes
//! nothing (no node value, no particle field) and the call goes on; the first failure's index
//! and error are returned ([`BatchStatus`], the failure of lowest index). P2G and the force
//! differential sum a run of consecutive nearby particles in a local node tile before adding it
//! to the grid (see `tile.rs`); if a node value of the tile's sum would not be finite, the grid is
//! left as it was and the run's particles are added one at a time, each checked (old value plus
//! contribution) and refused whole with [`crate::Error::Overflow`] if a value is not finite. A
//! call that returns `Ok` leaves every particle in a state the next call accepts.
//!
//! **Threads.** Calls share no state (apart from the instruction-set choice of
//! [`crate::lane::Isa`]). Two calls may run at once if the nodes they write do not overlap: a
//! host sorts its particles by cell, gives each thread a range of particles and a view of the
//! block of nodes they reach (see [`node_range`]), and adds overlapping block borders itself,
//! or colours blocks so that concurrently running blocks are three (quadratic) or four (cubic)
//! cells apart. No atomics are used.

mod deformation_lanes;
mod field_sums;
pub mod force;
pub mod g2p;
mod lane_sums;
mod nodes;
pub mod p2g;
#[cfg(test)]
mod row_check;
mod tile;
mod update_lanes;

pub use crate::kernel::batch::BatchStatus;

use super::stencil::{Grid, Kernel, Stencil, StencilLanes};
use super::{Material, Particle, Phase};
use crate::error::{Error, Result};
use crate::mat::Mat;
use crate::scalar::Real;
use core::ptr;

/// The nodes `[lo, lo + dims)` per axis that a grid view covers (grid indices).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct NodeBox<const D: usize> {
    /// Grid index of the first node.
    pub lo: [i32; D],
    /// Nodes per axis (≥ 0).
    pub dims: [i32; D],
}

/// One scalar per node of a [`NodeBox`]: node `i` at `data + Σ_a (i_a − lo_a)·stride[a]`
/// (strides in scalars). `P` is `*mut T` for outputs and `*const T` for inputs; a null `data`
/// is an absent channel.
#[derive(Clone, Copy, Debug)]
pub struct Channel<P, const D: usize> {
    /// Address of node `lo`.
    pub data: P,
    /// Distance between neighbouring nodes along each axis, in scalars.
    pub stride: [isize; D],
}

/// An output channel.
pub type OutChannel<T, const D: usize> = Channel<*mut T, D>;
/// An input channel.
pub type InChannel<T, const D: usize> = Channel<*const T, D>;

impl<T, const D: usize> Channel<*mut T, D> {
    /// An absent channel.
    #[inline]
    #[must_use]
    pub const fn none() -> Self {
        Self {
            data: ptr::null_mut(),
            stride: [0; D],
        }
    }
}

impl<T, const D: usize> Channel<*const T, D> {
    /// An absent channel.
    #[inline]
    #[must_use]
    pub const fn none() -> Self {
        Self {
            data: ptr::null(),
            stride: [0; D],
        }
    }
}

/// The inclusive range of grid nodes `[lo, hi]` that the stencils of particles at `x` (`n·d`
/// positions, m) reach on `grid`: the box a view must cover for a transfer of these
/// particles (`dims = hi − lo + 1`).
///
/// Errors: those of [`Stencil::new`] for the first particle that has one (`Err((i, e))`);
/// [`Error::InvalidArgument`] for `n = 0`.
#[inline]
pub fn node_range<T: Real, const D: usize>(
    kernel: Kernel,
    grid: Grid,
    h: T,
    x: &[[T; D]],
) -> core::result::Result<([i32; D], [i32; D]), (usize, Error)> {
    if x.is_empty() {
        return Err((0, Error::InvalidArgument));
    }
    let k = kernel.width() as i32;
    let mut lo = [i32::MAX; D];
    let mut hi = [i32::MIN; D];
    for (i, xp) in x.iter().enumerate() {
        let s = Stencil::new(kernel, grid, h, xp).map_err(|e| (i, e))?;
        for a in 0..D {
            lo[a] = lo[a].min(s.base[a]);
            hi[a] = hi[a].max(s.base[a] + k - 1);
        }
    }
    Ok((lo, hi))
}

/// Which particle fields a call reads besides `f_e`, `f_p`, `volume0` (and `phase`, `latent`
/// with phase change): a call never rejects a value in a field it does not read.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Reads {
    /// Positions.
    pub x: bool,
    /// Velocities and affine matrices.
    pub motion: bool,
    /// Masses (and temperatures with heat on).
    pub mass: bool,
}

impl Reads {
    /// What P2G and G2P read: everything.
    pub const ALL: Reads = Reads {
        x: true,
        motion: true,
        mass: true,
    };
    /// What the force-differential prepare reads: the deformation only.
    pub const DEFORMATION: Reads = Reads {
        x: false,
        motion: false,
        mass: false,
    };
}

/// Structure-of-arrays particle data, as raw pointers (the C layout): particle `p`'s vector
/// is at `[d·p + a]`, its `d × d` matrices column-major at `[d²·p + i + d·j]`, scalars at `[p]`.
/// Units as in [`super`]. Which arrays a call reads and writes is in its docs; the others may
/// be null.
#[derive(Clone, Copy, Debug)]
pub struct Particles<T> {
    /// Positions `x_p` (m, relative to the grid origin), `n·d`.
    pub x: *mut T,
    /// Velocities (m/s), `n·d`.
    pub v: *mut T,
    /// APIC affine matrices `C_p` (1/s), `n·d²`.
    pub affine: *mut T,
    /// Elastic deformation gradients `F_E`, `n·d²`.
    pub f_e: *mut T,
    /// Plastic deformation gradients `F_P`, `n·d²` (a liquid keeps `J_P^{1/d} I`).
    pub f_p: *mut T,
    /// Masses (kg), `n`.
    pub mass: *const T,
    /// Reference volumes `V⁰` (m³), `n`.
    pub volume0: *const T,
    /// Temperatures (K), `n`; read with heat on.
    pub temperature: *mut T,
    /// Latent buffers `U` (J/kg), `n`; read with phase change on.
    pub latent: *mut T,
    /// Phases (0 solid, 1 liquid), `n`; null means all solid (not allowed with phase change).
    pub phase: *mut u8,
}

#[inline(always)]
unsafe fn rd<T: Copy>(p: *const T, i: usize) -> T {
    ptr::read_unaligned(p.add(i))
}

#[inline(always)]
unsafe fn wr<T: Copy>(p: *mut T, i: usize, v: T) {
    ptr::write_unaligned(p.add(i), v)
}

/// The positions of particles `start..start + len` (array `x`, `d` scalars per particle)
/// into `xs`, and their collocated stencils into `out` on the lanes of `R` when a chunk is one
/// row of lanes (`xs.len() == R::LANES`). Returns the lanes whose stencil is done (see
/// [`Stencil::new_lanes`]; none otherwise): the caller builds the others with
/// [`Stencil::new`], which gives their errors. Entries from `len` on are left as they are.
/// With `lanes`, the lane vectors of the done stencils too (see [`Stencil::new_lanes`]).
///
/// # Safety
/// `x` holds particles `start..start + len`; `len ≤ xs.len() = out.len()`.
#[inline(always)]
unsafe fn chunk_stencils<T: Real, R: crate::lane::Lane<Scalar = T>, const D: usize>(
    kernel: Kernel,
    h: T,
    x: *const T,
    (start, len): (usize, usize),
    xs: &mut [[T; D]],
    out: &mut [Stencil<T, D>],
    lanes: Option<&mut StencilLanes<R>>,
) -> u64 {
    for (k, xk) in xs.iter_mut().enumerate().take(len) {
        *xk = rd_vec::<T, D>(x, start + k);
    }
    if xs.len() == R::LANES {
        Stencil::new_lanes::<R>(kernel, Grid::Collocated, h, xs, out, lanes)
    } else {
        0
    }
}

#[inline(always)]
pub(crate) unsafe fn rd_vec<T: Real, const D: usize>(p: *const T, i: usize) -> [T; D] {
    let mut v = [T::ZERO; D];
    for (a, x) in v.iter_mut().enumerate() {
        *x = rd(p, D * i + a);
    }
    v
}

#[inline(always)]
unsafe fn wr_vec<T: Real, const D: usize>(p: *mut T, i: usize, v: &[T; D]) {
    for (a, x) in v.iter().enumerate() {
        wr(p, D * i + a, *x);
    }
}

#[inline(always)]
unsafe fn rd_mat<T: Real, const D: usize>(p: *const T, i: usize) -> Mat<T, D> {
    let mut m = Mat::<T, D>::ZERO;
    for j in 0..D {
        for r in 0..D {
            m.cols[j][r] = rd(p, D * D * i + r + D * j);
        }
    }
    m
}

#[inline(always)]
unsafe fn wr_mat<T: Real, const D: usize>(p: *mut T, i: usize, m: &Mat<T, D>) {
    for j in 0..D {
        for r in 0..D {
            wr(p, D * D * i + r + D * j, m.cols[j][r]);
        }
    }
}

impl<T: Real> Particles<T> {
    /// Whether every array that a call reading `reads` with `material` needs is non-null.
    #[must_use]
    pub fn has(&self, reads: Reads, material: &Material<T>) -> bool {
        let heat = material.heat.is_some();
        let phase_change = material.heat.is_some_and(|h| h.phase_change);
        let mut ok = !self.f_e.is_null() && !self.f_p.is_null() && !self.volume0.is_null();
        if reads.x {
            ok &= !self.x.is_null();
        }
        if reads.motion {
            ok &= !self.v.is_null() && !self.affine.is_null();
        }
        if reads.mass {
            ok &= !self.mass.is_null();
            ok &= !heat || !self.temperature.is_null();
        }
        ok &= !phase_change || (!self.phase.is_null() && !self.latent.is_null());
        ok
    }

    /// Particle `i` (phase solid when `phase` is null), with the fields not in `reads` set to benign values (position 0, at rest,
    /// mass 1) so that the particle checks do not look at them.
    ///
    /// # Safety
    /// The arrays `reads` names hold at least `i + 1` particles.
    #[inline(always)]
    pub unsafe fn get<const D: usize>(
        &self,
        i: usize,
        reads: Reads,
        material: &Material<T>,
    ) -> Result<Particle<T, D>> {
        let mut p = Particle::<T, D>::at_rest([T::ZERO; D], T::ONE, T::ONE);
        self.read_into(i, reads, material, &mut p)?;
        Ok(p)
    }

    /// [`Particles::get`] into `p` (every field is written; on error, the phase is not). For
    /// the transfer loops: a particle built in place is not copied again with wide moves
    /// right after its fields were stored one by one (such a copy waits for the stores to
    /// reach the cache).
    ///
    /// # Safety
    /// As [`Particles::get`].
    #[inline(always)]
    pub(crate) unsafe fn read_into<const D: usize>(
        &self,
        i: usize,
        reads: Reads,
        material: &Material<T>,
        p: &mut Particle<T, D>,
    ) -> Result<()> {
        let heat = material.heat.is_some();
        p.x = if reads.x {
            rd_vec(self.x, i)
        } else {
            [T::ZERO; D]
        };
        if reads.motion {
            p.v = rd_vec(self.v, i);
            p.affine = rd_mat(self.affine, i);
        } else {
            p.v = [T::ZERO; D];
            p.affine = Mat::ZERO;
        }
        p.mass = if reads.mass { rd(self.mass, i) } else { T::ONE };
        p.temperature = if reads.mass && heat {
            rd(self.temperature, i)
        } else {
            T::ZERO
        };
        p.volume0 = rd(self.volume0, i);
        p.f_e = rd_mat(self.f_e, i);
        p.f_p = rd_mat(self.f_p, i);
        p.latent = if material.heat.is_some_and(|h| h.phase_change) {
            rd(self.latent, i)
        } else {
            T::ZERO
        };
        p.phase = if self.phase.is_null() {
            Phase::Solid
        } else {
            Phase::from_code(rd(self.phase, i))?
        };
        Ok(())
    }

    /// Writes back what G2P changes.
    ///
    /// # Safety
    /// As [`Particles::get`] with every field.
    #[inline(always)]
    pub(crate) unsafe fn put<const D: usize>(
        &self,
        i: usize,
        material: &Material<T>,
        p: &Particle<T, D>,
    ) {
        wr_vec(self.x, i, &p.x);
        wr_vec(self.v, i, &p.v);
        wr_mat(self.affine, i, &p.affine);
        wr_mat(self.f_e, i, &p.f_e);
        wr_mat(self.f_p, i, &p.f_p);
        if material.heat.is_some() {
            wr(self.temperature, i, p.temperature);
        }
        if material.heat.is_some_and(|h| h.phase_change) {
            wr(self.latent, i, p.latent);
            wr(self.phase, i, p.phase as u8);
        }
    }
}

/// The material checked once per call for each phase (a particle then takes its phase's
/// result instead of re-validating).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Checked {
    solid: Result<()>,
    liquid: Result<()>,
}

impl Checked {
    pub(crate) fn new<T: Real>(m: &Material<T>) -> Self {
        Self {
            solid: m.validate(Phase::Solid),
            liquid: m.validate(Phase::Liquid),
        }
    }
    #[inline(always)]
    pub(crate) fn for_phase(&self, p: Phase) -> Result<()> {
        match p {
            Phase::Solid => self.solid,
            Phase::Liquid => self.liquid,
        }
    }
}

/// Tracks the first failure of a batch (the [`BatchStatus`] of a loop over particles).
#[derive(Clone, Copy, Debug)]
pub struct FirstFailure {
    n: usize,
    at: usize,
    err: Option<Error>,
}

impl FirstFailure {
    /// No failure yet among `n` particles.
    #[must_use]
    pub fn new(n: usize) -> Self {
        Self {
            n,
            at: n,
            err: None,
        }
    }
    /// Records the result of particle `i` (kept only if it is the failure of lowest index so
    /// far: P2G adds some particles after later ones have failed).
    #[inline(always)]
    pub fn note(&mut self, i: usize, r: Result<()>) {
        if let Err(e) = r {
            if self.err.is_none() || i < self.at {
                self.at = i;
                self.err = Some(e);
            }
        }
    }
    /// The first failure and its index (`n` when none).
    #[must_use]
    pub fn status(self) -> BatchStatus {
        BatchStatus {
            first_failed: if self.err.is_some() { self.at } else { self.n },
            error: self.err,
        }
    }
}
