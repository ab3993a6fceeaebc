//! Running a chunk loop on an instruction set: the loop is generic over its lane types
//! ([`LaneOp`]) and `#[inline(always)]` down to the intrinsics; [`dispatch`] instantiates it
//! inside a `#[target_feature]` function per instruction set (AVX2, AVX-512 with or without
//! VL, joined rows and narrow chunks) and calls the one an [`Isa`] names. The scalars with
//! SIMD paths ([`BatchReal`]) name their lane types per instruction set, and [`BatchStatus`]
//! is the outcome every batch call reports.

use crate::error::Error;
use crate::lane::{Isa, IsaKind, Lane, Pair, X2};
use crate::scalar::Real;

/// The widest lane type of any path (two `f32×16`).
pub const MAX_LANES: usize = 32;

/// The lanes of [`Lane::Wide`] of the widest lane type (four `f32×16`): the chunks of the
/// particle calls that run the decomposition (P2G, the force differential's prepare), whose
/// Jacobi rotations are latency-bound and fill the FMA pipes better with four independent
/// vectors than with two.
pub const WIDE_LANES: usize = 2 * MAX_LANES;

/// A particle loop generic over its chunk: the lane type `W` and a bound `L ≥ W::LANES` that
/// sizes its buffers (`[T; L]`), run by [`BatchReal::with_chunks`] or
/// [`BatchReal::with_narrow_chunks`].
pub trait WithChunks<T> {
    /// The result.
    type Out;
    /// Runs on chunks of `W` (at most `L` lanes).
    fn run<W: Lane<Scalar = T>, const L: usize>(self) -> Self::Out;
}

/// Outcome of a batch call that ran: the first failed particle and its status.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BatchStatus {
    /// Index of the first particle that failed, or `n` if none did.
    pub first_failed: usize,
    /// Its status (`None` when every particle succeeded).
    pub error: Option<Error>,
}

impl BatchStatus {
    /// `Ok(())` or `Err((first_failed, status))`.
    #[inline]
    pub fn result(self) -> Result<(), (usize, Error)> {
        match self.error {
            None => Ok(()),
            Some(e) => Err((self.first_failed, e)),
        }
    }
}

/// Scalars with SIMD paths: `f32` and `f64` (sealed).
pub trait BatchReal: Real + sealed::Sealed {
    /// Runs P2G's particle loop `f` on the chunks of this scalar for the kernel lanes `V`:
    /// `f32` on [`Lane::Wide`] of `V` (3D f32 elastic P2G on an AVX-512 Intel Xeon 96–98 ns
    /// instead of 103–104, AVX2 116–117 instead of 129), `f64` on `V` itself (on `V::Wide`
    /// its AVX-512 P2G measured slower, liquid 134 ns instead of 123, and its buffers would
    /// need the stack twice).
    fn with_chunks<V: Lane<Scalar = Self>, F: WithChunks<Self>>(f: F) -> F::Out;

    /// Whether [`Self::with_narrow_chunks`] differs from [`Self::with_chunks`] (`f32`).
    const NARROW_DIFFERS: bool;

    /// Runs `f` as [`Self::with_chunks`] but `f32` on `V` itself, two vectors on AVX-512
    /// instead of four ([`Isa::narrow_chunks`]: on AMD Zen 4, whose 512-bit operations take
    /// two 256-bit passes, two vectors already fill the pipes); `f64` as in `with_chunks`.
    fn with_narrow_chunks<V: Lane<Scalar = Self>, F: WithChunks<Self>>(f: F) -> F::Out;
}
impl BatchReal for f32 {
    #[inline(always)]
    fn with_chunks<V: Lane<Scalar = Self>, F: WithChunks<Self>>(f: F) -> F::Out {
        f.run::<V::Wide, WIDE_LANES>()
    }
    const NARROW_DIFFERS: bool = true;
    #[inline(always)]
    fn with_narrow_chunks<V: Lane<Scalar = Self>, F: WithChunks<Self>>(f: F) -> F::Out {
        f.run::<V, MAX_LANES>()
    }
}
impl BatchReal for f64 {
    #[inline(always)]
    fn with_chunks<V: Lane<Scalar = Self>, F: WithChunks<Self>>(f: F) -> F::Out {
        // Two `f64×8`, the widest `f64` lane type.
        f.run::<V, { MAX_LANES / 2 }>()
    }
    const NARROW_DIFFERS: bool = false;
    #[inline(always)]
    fn with_narrow_chunks<V: Lane<Scalar = Self>, F: WithChunks<Self>>(f: F) -> F::Out {
        Self::with_chunks::<V, F>(f)
    }
}

mod sealed {
    /// The vector types of a scalar on each instruction set.
    pub trait Sealed: crate::Real {
        #[cfg(target_arch = "x86_64")]
        type Avx2: crate::lane::Lane<Scalar = Self>;
        #[cfg(target_arch = "x86_64")]
        type Avx512: crate::lane::Lane<Scalar = Self>;
        /// Eight lanes on AVX2 (short per-node vectors, see [`super::LaneOp::run_rows`]).
        #[cfg(target_arch = "x86_64")]
        type Avx2Row: crate::lane::Lane<Scalar = Self>;
        /// Eight lanes on AVX-512.
        #[cfg(target_arch = "x86_64")]
        type Avx512Row: crate::lane::Lane<Scalar = Self>;
        /// Two [`Self::Avx2Row`]s.
        #[cfg(target_arch = "x86_64")]
        type Avx2Pair: crate::lane::Pair<Self::Avx2Row>;
        /// Two [`Self::Avx512Row`]s: one register for `f32`.
        #[cfg(target_arch = "x86_64")]
        type Avx512Pair: crate::lane::Pair<Self::Avx512Row>;
    }
    impl Sealed for f32 {
        #[cfg(target_arch = "x86_64")]
        type Avx2 = crate::lane::X2<crate::lane::F32x8>;
        #[cfg(target_arch = "x86_64")]
        type Avx512 = crate::lane::X2<crate::lane::F32x16>;
        #[cfg(target_arch = "x86_64")]
        type Avx2Row = crate::lane::F32x8;
        #[cfg(target_arch = "x86_64")]
        type Avx512Row = crate::lane::F32x8;
        #[cfg(target_arch = "x86_64")]
        type Avx2Pair = crate::lane::X2<crate::lane::F32x8>;
        #[cfg(target_arch = "x86_64")]
        type Avx512Pair = crate::lane::F32x16;
    }
    impl Sealed for f64 {
        #[cfg(target_arch = "x86_64")]
        type Avx2 = crate::lane::X2<crate::lane::F64x4>;
        #[cfg(target_arch = "x86_64")]
        type Avx512 = crate::lane::X2<crate::lane::F64x8>;
        #[cfg(target_arch = "x86_64")]
        type Avx2Row = crate::lane::X2<crate::lane::F64x4>;
        #[cfg(target_arch = "x86_64")]
        type Avx512Row = crate::lane::F64x8;
        #[cfg(target_arch = "x86_64")]
        type Avx2Pair = crate::lane::X2<Self::Avx2Row>;
        #[cfg(target_arch = "x86_64")]
        type Avx512Pair = crate::lane::X2<crate::lane::F64x8>;
    }
}

/// A chunk loop, generic over the lane type.
pub(crate) trait LaneOp<T> {
    /// Runs the loop on lanes `V`.
    fn run<V: Lane<Scalar = T>>(&mut self) -> BatchStatus;

    /// Runs the loop on lanes `V`, with `R` a lane type of exactly eight lanes of the same
    /// instruction set for short per-item vectors (e.g. the sums of one node).
    #[inline(always)]
    fn run_rows<V: Lane<Scalar = T>, R: Lane<Scalar = T>>(&mut self) -> BatchStatus {
        self.run::<V>()
    }

    /// Runs the loop on lanes `V` and rows `R` as [`Self::run_rows`], with `Q` two rows side
    /// by side (one register on AVX-512 `f32`: two node channels summed by one instruction).
    #[inline(always)]
    fn run_pairs<V: Lane<Scalar = T>, R: Lane<Scalar = T>, Q: Pair<R>>(&mut self) -> BatchStatus {
        self.run_rows::<V, R>()
    }

    /// Whether [`Self::run_pairs`] uses `Q` ([`Isa::joined_rows`] then picks it; other loops
    /// are built once).
    #[cfg_attr(not(target_arch = "x86_64"), allow(dead_code))]
    const JOINS_ROWS: bool = false;

    /// Runs the loop as [`Self::run_pairs`] on narrower chunks where the loop has them
    /// ([`Isa::narrow_chunks`]; `dispatch` calls it only when [`Self::NARROWS_CHUNKS`]).
    #[cfg_attr(not(target_arch = "x86_64"), allow(dead_code))]
    #[inline(always)]
    fn run_narrow<V: Lane<Scalar = T>, R: Lane<Scalar = T>, Q: Pair<R>>(&mut self) -> BatchStatus {
        self.run_pairs::<V, R, Q>()
    }

    /// Whether [`Self::run_narrow`] differs from [`Self::run_pairs`] (other loops are built
    /// once).
    #[cfg_attr(not(target_arch = "x86_64"), allow(dead_code))]
    const NARROWS_CHUNKS: bool = false;

    /// Whether the AVX-512 build of the loop also enables AVX-512 VL, DQ and BW (which
    /// [`IsaKind::Avx512`] guarantees): eight-lane rows then have 32 registers and k-masked
    /// moves. On for P2G and the force differential (AMD Zen 4: the apply about 15 % faster);
    /// off for the kernels, whose 2D f64 batch measured slower with it. G2P runs its AVX2
    /// build under AVX-512 (see `g2p_update`).
    #[cfg_attr(not(target_arch = "x86_64"), allow(dead_code))]
    const AVX512_VL: bool = false;
}

/// Eight scalar lanes (the row type of the scalar path).
pub(crate) type ScalarRow<T> = X2<X2<X2<T>>>;

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
unsafe fn run_avx2<T: BatchReal, O: LaneOp<T>>(op: &mut O) -> BatchStatus {
    op.run_pairs::<T::Avx2, T::Avx2Row, T::Avx2Pair>()
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f,avx2,fma")]
unsafe fn run_avx512<T: BatchReal, O: LaneOp<T>>(op: &mut O) -> BatchStatus {
    op.run_pairs::<T::Avx512, T::Avx512Row, X2<T::Avx512Row>>()
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f,avx512vl,avx512dq,avx512bw,avx2,fma")]
unsafe fn run_avx512_vl<T: BatchReal, O: LaneOp<T>>(op: &mut O) -> BatchStatus {
    op.run_pairs::<T::Avx512, T::Avx512Row, X2<T::Avx512Row>>()
}

/// [`run_avx512_vl`] with joined rows ([`Isa::joined_rows`]): a function of its own, so that
/// the two forms of a loop do not share (and add up) one stack frame.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f,avx512vl,avx512dq,avx512bw,avx2,fma")]
unsafe fn run_avx512_vl_joined<T: BatchReal, O: LaneOp<T>>(op: &mut O) -> BatchStatus {
    op.run_pairs::<T::Avx512, T::Avx512Row, T::Avx512Pair>()
}

/// [`run_avx512_vl`] with narrow chunks ([`Isa::narrow_chunks`]): a function of its own, as
/// [`run_avx512_vl_joined`].
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f,avx512vl,avx512dq,avx512bw,avx2,fma")]
unsafe fn run_avx512_vl_narrow<T: BatchReal, O: LaneOp<T>>(op: &mut O) -> BatchStatus {
    op.run_narrow::<T::Avx512, T::Avx512Row, X2<T::Avx512Row>>()
}

/// Runs `op` on the lanes of `isa`.
#[inline]
pub(crate) fn dispatch<T: BatchReal, O: LaneOp<T>>(isa: Isa, op: &mut O) -> BatchStatus {
    match isa.kind() {
        IsaKind::Scalar => op.run_pairs::<T, ScalarRow<T>, X2<ScalarRow<T>>>(),
        #[cfg(target_arch = "x86_64")]
        // SAFETY: an `Isa` other than scalar certifies the CPU's support (see `Isa`).
        IsaKind::Avx2 => unsafe { run_avx2::<T, O>(op) },
        #[cfg(target_arch = "x86_64")]
        // SAFETY: as above.
        IsaKind::Avx512 if O::AVX512_VL && O::JOINS_ROWS && isa.joined_rows() => unsafe {
            run_avx512_vl_joined::<T, O>(op)
        },
        #[cfg(target_arch = "x86_64")]
        // SAFETY: as above.
        IsaKind::Avx512
            if O::AVX512_VL && O::NARROWS_CHUNKS && T::NARROW_DIFFERS && isa.narrow_chunks() =>
        unsafe { run_avx512_vl_narrow::<T, O>(op) },
        #[cfg(target_arch = "x86_64")]
        // SAFETY: as above.
        IsaKind::Avx512 if O::AVX512_VL => unsafe { run_avx512_vl::<T, O>(op) },
        #[cfg(target_arch = "x86_64")]
        // SAFETY: as above.
        IsaKind::Avx512 => unsafe { run_avx512::<T, O>(op) },
        #[cfg(not(target_arch = "x86_64"))]
        _ => op.run_pairs::<T, ScalarRow<T>, X2<ScalarRow<T>>>(),
    }
}
