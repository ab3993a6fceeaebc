//! Batch entry points of the fast kernels: chunks of `V::LANES` particles through
//! [`super::evaluate`], on the instruction set an [`Isa`] names.
//!
//! **Layout.** A batch is `n` column-major `d×d` matrices back to back (`F[i·d² + r + d·c]` is
//! `F_rc` of particle `i`), `n` values of μ, and for prepared data `n` slots of
//! [`prepared::len`]`(d)` scalars.
//!
//! **Contract.** Every particle is computed independently: a particle that fails a check
//! leaves its outputs untouched (a failed prepare marks its slot unprepared, see
//! [`prepared`]); the call reports the first failure's index and status ([`BatchStatus`]). A
//! short last chunk is padded with `F = I`, `μ = 0`, whose results are dropped, so a
//! particle's result does not depend on `n` or on its position in the batch. Each chunk is
//! read completely before any of its outputs is written, so an output may alias an input of
//! the same particles exactly (in place).
//!
//! **Instruction sets.** The chunk loops are generic over [`Lane`] and `#[inline(always)]`
//! down to the intrinsics; `run_avx2` and `run_avx512` instantiate them inside
//! `#[target_feature]` functions. All paths give the same bits (see [`crate::lane`]).

#![allow(clippy::needless_range_loop, clippy::too_many_arguments)]

use super::chunk::{check_bits, gather, load_mats, none, scatter, store_mats, First};
use super::prepared::{self, MAX_LEN};
use super::{ahat, chat_z, evaluate, flagged, psd_block, Dim, LaneDim};
use crate::error::Error;
use crate::lane::lmat::all_finite;
use crate::lane::{Isa, IsaKind, Lane, Pair, X2};
use crate::scalar::Real;
use core::ptr;

/// The widest lane type of any path (two `f32×16`).
pub const MAX_LANES: usize = 32;

/// The lanes of [`Lane::Wide`] of the widest lane type (four `f32×16`): the chunks of the
/// particle calls that run the decomposition (P2G, the force differential's prepare), whose
/// Jacobi rotations are latency-bound and fill the FMA pipes better with four independent
/// vectors than with two.
pub const WIDE_LANES: usize = 2 * MAX_LANES;

/// A particle loop generic over its chunk: the lane type `W` and a bound `L ≥ W::LANES` that
/// sizes its buffers (`[T; L]`), run by [`BatchReal::with_chunks`].
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
}
impl BatchReal for f32 {
    #[inline(always)]
    fn with_chunks<V: Lane<Scalar = Self>, F: WithChunks<Self>>(f: F) -> F::Out {
        f.run::<V::Wide, WIDE_LANES>()
    }
}
impl BatchReal for f64 {
    #[inline(always)]
    fn with_chunks<V: Lane<Scalar = Self>, F: WithChunks<Self>>(f: F) -> F::Out {
        // Two `f64×8`, the widest `f64` lane type.
        f.run::<V, { MAX_LANES / 2 }>()
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
        IsaKind::Avx512 if O::AVX512_VL => unsafe { run_avx512_vl::<T, O>(op) },
        #[cfg(target_arch = "x86_64")]
        // SAFETY: as above.
        IsaKind::Avx512 => unsafe { run_avx512::<T, O>(op) },
        #[cfg(not(target_arch = "x86_64"))]
        _ => op.run_pairs::<T, ScalarRow<T>, X2<ScalarRow<T>>>(),
    }
}

/// Raw arguments of [`kernels_raw`]: null output pointers are not computed.
#[derive(Clone, Copy, Debug)]
pub struct KernelArgs<T> {
    /// Particles.
    pub n: usize,
    /// `n` values of μ (Pa).
    pub mu: *const T,
    /// `n` matrices `F`.
    pub f: *const T,
    /// `n` matrices `Z` (may be null when `chat_z` is null).
    pub z: *const T,
    /// `n` matrices `Â` (null: not computed).
    pub ahat: *mut T,
    /// `n` matrices `Ĉ:Z` or `Ĉ⁺:Z` (null: not computed).
    pub chat_z: *mut T,
    /// `n` energy densities `Ψ̂` (null: not computed).
    pub energy: *mut T,
    /// `chat_z` gets the PSD-projected `Ĉ⁺:Z`.
    pub psd: bool,
}

struct KernelOp<T, const D: usize>(KernelArgs<T>);

impl<T: BatchReal, const D: usize> LaneOp<T> for KernelOp<T, D>
where
    Dim<D>: LaneDim<D>,
{
    #[inline(always)]
    fn run<V: Lane<Scalar = T>>(&mut self) -> BatchStatus {
        let a = self.0;
        let e = D * D;
        let mut first = First::new(a.n);
        let mut start = 0;
        while start < a.n {
            let len = V::LANES.min(a.n - start);
            // SAFETY: the caller of `kernels_raw` guarantees `n` records behind each non-null
            // pointer (and a non-null `z` when `chat_z` is non-null).
            unsafe {
                let mut mu1 = [V::splat(T::ZERO); 1];
                gather::<V, 1>(a.mu.add(start), 1, 1, len, |_| T::ZERO, &mut mu1);
                let f = load_mats::<V, D>(a.f.add(start * e), len, true);
                let (co, ck) = evaluate(mu1[0], &f);
                let mut bad_z = none::<V>();
                let mut ovf = none::<V>();
                let a_m = if a.ahat.is_null() {
                    None
                } else {
                    let m = ahat(&co);
                    ovf = ovf | !all_finite(&m);
                    Some(m)
                };
                let c_m = if a.chat_z.is_null() {
                    None
                } else {
                    let z = load_mats::<V, D>(a.z.add(start * e), len, false);
                    bad_z = !all_finite(&z);
                    let m = if a.psd {
                        chat_z(&co.psd(), &z)
                    } else {
                        chat_z(&co, &z)
                    };
                    ovf = ovf | !all_finite(&m);
                    Some(m)
                };
                if !a.energy.is_null() {
                    ovf = ovf | !co.energy.is_finite();
                }
                let [b0, b1, b2, b3, b4] = check_bits::<V>(&ck);
                let bits = [
                    b0,
                    b1,
                    b2,
                    b3,
                    b4,
                    (V::mask_bits(bad_z), Error::NonFinite),
                    (V::mask_bits(ovf), Error::Overflow),
                ];
                let skip = flagged(&bits);
                if let Some(m) = a_m {
                    store_mats::<V, D>(&m, a.ahat.add(start * e), len, skip);
                }
                if let Some(m) = c_m {
                    store_mats::<V, D>(&m, a.chat_z.add(start * e), len, skip);
                }
                if !a.energy.is_null() {
                    scatter::<V, 1>(&[co.energy], 1, a.energy.add(start), 1, len, skip);
                }
                first.note(start, &bits, len);
            }
            start += len;
        }
        first.status()
    }
}

/// The decompositions alone: `U`, `σ`, `V` per particle (rotation-variant, see
/// [`crate::polar`]), by the default method on lanes.
struct SvdOp<'a, T, const D: usize> {
    f: &'a [T],
    u: &'a mut [T],
    sigma: &'a mut [T],
    v: &'a mut [T],
}

impl<T: BatchReal, const D: usize> LaneOp<T> for SvdOp<'_, T, D>
where
    Dim<D>: LaneDim<D>,
{
    #[inline(always)]
    fn run<V: Lane<Scalar = T>>(&mut self) -> BatchStatus {
        let e = D * D;
        let n = self.sigma.len() / D;
        let mut first = First::new(n);
        let mut start = 0;
        while start < n {
            let len = V::LANES.min(n - start);
            // SAFETY: `svd` checked the lengths: `n` matrices and `n·d` values.
            unsafe {
                let f = load_mats::<V, D>(self.f.as_ptr().add(start * e), len, true);
                let ok = all_finite(&f);
                let f = super::select_mat(ok, &f, &crate::lane::lmat::identity());
                let (g, k) = crate::polar::lanes::scaled_input(&f);
                let s = Dim::<D>::svd(&g).unscaled(k);
                let bits = [(V::mask_bits(!ok), Error::NonFinite)];
                let skip = bits[0].0;
                store_mats::<V, D>(&s.u, self.u.as_mut_ptr().add(start * e), len, skip);
                store_mats::<V, D>(&s.v, self.v.as_mut_ptr().add(start * e), len, skip);
                let mut sg = [s.sigma[0]; 9];
                sg[..D].copy_from_slice(&s.sigma);
                scatter::<V, 9>(&sg, D, self.sigma.as_mut_ptr().add(start * D), D, len, skip);
                first.note(start, &bits, len);
            }
            start += len;
        }
        first.status()
    }
}

/// The rotation-variant SVD `F = U diag(σ) Vᵀ` of each particle by the default method (2D
/// closed form, 3D one-sided Jacobi) on the lanes of `isa`: `f`, `u`, `v` hold `n` matrices,
/// `sigma` `n·d` values. Non-finite `F` gives [`Error::NonFinite`] for that particle (outputs
/// untouched); lengths that disagree give `Err(Error::InvalidArgument)`.
#[inline]
pub fn svd<T: BatchReal, const D: usize>(
    isa: Isa,
    f: &[T],
    u: &mut [T],
    sigma: &mut [T],
    v: &mut [T],
) -> Result<BatchStatus, Error>
where
    Dim<D>: LaneDim<D>,
{
    let e = D * D;
    let n = sigma.len() / D;
    if sigma.len() % D != 0 || f.len() != n * e || u.len() != n * e || v.len() != n * e {
        return Err(Error::InvalidArgument);
    }
    Ok(dispatch::<T, _>(isa, &mut SvdOp::<T, D> { f, u, sigma, v }))
}

/// Raw arguments of [`prepare_raw`].
#[derive(Clone, Copy, Debug)]
pub struct PrepareArgs<T> {
    /// Particles.
    pub n: usize,
    /// `n` values of μ.
    pub mu: *const T,
    /// `n` matrices `F`.
    pub f: *const T,
    /// `n` matrices `Â` (null: not computed).
    pub ahat: *mut T,
    /// `n` slots of [`prepared::len`]`(d)` scalars.
    pub prepared: *mut T,
}

struct PrepareOp<T, const D: usize>(PrepareArgs<T>);

impl<T: BatchReal, const D: usize> LaneOp<T> for PrepareOp<T, D>
where
    Dim<D>: LaneDim<D>,
{
    #[inline(always)]
    fn run<V: Lane<Scalar = T>>(&mut self) -> BatchStatus {
        let a = self.0;
        let e = D * D;
        let w = prepared::len(D);
        let mut first = First::new(a.n);
        let mut start = 0;
        while start < a.n {
            let len = V::LANES.min(a.n - start);
            // SAFETY: the caller of `prepare_raw` guarantees `n` records behind each pointer.
            unsafe {
                let mut mu1 = [V::splat(T::ZERO); 1];
                gather::<V, 1>(a.mu.add(start), 1, 1, len, |_| T::ZERO, &mut mu1);
                let f = load_mats::<V, D>(a.f.add(start * e), len, true);
                let (co, ck) = evaluate(mu1[0], &f);
                let block_psd = psd_block(&co.block, Dim::<D>::eigen_sweeps::<T>());
                let mut slot = [V::splat(T::ZERO); MAX_LEN];
                prepared::pack(&co, &block_psd, &mut slot);
                let mut ovf = none::<V>();
                for x in slot.iter().take(w) {
                    ovf = ovf | !x.is_finite();
                }
                let a_m = if a.ahat.is_null() {
                    None
                } else {
                    let m = ahat(&co);
                    ovf = ovf | !all_finite(&m);
                    Some(m)
                };
                let [b0, b1, b2, b3, b4] = check_bits::<V>(&ck);
                let bits = [b0, b1, b2, b3, b4, (V::mask_bits(ovf), Error::Overflow)];
                let skip = flagged(&bits);
                if let Some(m) = a_m {
                    store_mats::<V, D>(&m, a.ahat.add(start * e), len, skip);
                }
                let dst = a.prepared.add(start * w);
                scatter::<V, MAX_LEN>(&slot, w, dst, w, len, skip);
                // A failed particle's slot is marked unprepared (its tag only).
                for l in 0..len {
                    if skip >> l & 1 == 1 {
                        ptr::write_unaligned(dst.add(l * w), T::ZERO);
                    }
                }
                first.note(start, &bits, len);
            }
            start += len;
        }
        first.status()
    }
}

/// Raw arguments of [`apply_raw`].
#[derive(Clone, Copy, Debug)]
pub struct ApplyArgs<T> {
    /// Particles.
    pub n: usize,
    /// `n` slots written by [`prepare_raw`].
    pub prepared: *const T,
    /// `n` matrices `Z`.
    pub z: *const T,
    /// `n` matrices `Ĉ:Z` or `Ĉ⁺:Z`.
    pub out: *mut T,
    /// Apply the PSD-projected `Ĉ⁺`.
    pub psd: bool,
}

struct ApplyOp<T, const D: usize>(ApplyArgs<T>);

impl<T: BatchReal, const D: usize> LaneOp<T> for ApplyOp<T, D>
where
    Dim<D>: LaneDim<D>,
{
    #[inline(always)]
    fn run<V: Lane<Scalar = T>>(&mut self) -> BatchStatus {
        let a = self.0;
        let e = D * D;
        let w = prepared::len(D);
        let mut first = First::new(a.n);
        let mut start = 0;
        while start < a.n {
            let len = V::LANES.min(a.n - start);
            // SAFETY: the caller of `apply_raw` guarantees `n` records behind each pointer.
            unsafe {
                let mut slot = [V::splat(T::ZERO); MAX_LEN];
                let t = prepared::tag::<T>(D);
                gather::<V, MAX_LEN>(
                    a.prepared.add(start * w),
                    w,
                    w,
                    len,
                    |m| if m == 0 { t } else { T::ZERO },
                    &mut slot,
                );
                let (co, tag_ok) = prepared::unpack::<V, D>(&slot, a.psd);
                let z = load_mats::<V, D>(a.z.add(start * e), len, false);
                let m = chat_z(&co, &z);
                let bits = [
                    (V::mask_bits(!tag_ok), Error::NotPrepared),
                    (V::mask_bits(!all_finite(&z)), Error::NonFinite),
                    (V::mask_bits(!all_finite(&m)), Error::Overflow),
                ];
                let skip = flagged(&bits);
                store_mats::<V, D>(&m, a.out.add(start * e), len, skip);
                first.note(start, &bits, len);
            }
            start += len;
        }
        first.status()
    }
}

/// `Â`, `Ĉ:Z` (or `Ĉ⁺:Z`) and `Ψ̂` of fixed corotated per particle, one decomposition each,
/// on raw pointers (the C ABI's form; outputs may alias inputs exactly).
///
/// # Safety
/// Every non-null pointer is valid for `n` records (μ: 1 scalar, matrices: `d²`, energy: 1);
/// `z` is non-null when `chat_z` is; `mu` and `f` are non-null when `n > 0`; outputs do not
/// partially overlap inputs or each other.
#[inline]
pub unsafe fn kernels_raw<T: BatchReal, const D: usize>(
    isa: Isa,
    args: KernelArgs<T>,
) -> BatchStatus
where
    Dim<D>: LaneDim<D>,
{
    dispatch::<T, _>(isa, &mut KernelOp::<T, D>(args))
}

/// Prepares the Hessian of each particle for [`apply_raw`] (and `Â` when `ahat` is non-null).
///
/// # Safety
/// As [`kernels_raw`]; `prepared` valid for `n` slots of [`prepared::len`]`(d)` scalars.
#[inline]
pub unsafe fn prepare_raw<T: BatchReal, const D: usize>(
    isa: Isa,
    args: PrepareArgs<T>,
) -> BatchStatus
where
    Dim<D>: LaneDim<D>,
{
    dispatch::<T, _>(isa, &mut PrepareOp::<T, D>(args))
}

/// `Ĉ:Z` (or `Ĉ⁺:Z`) per particle from prepared slots.
///
/// # Safety
/// Every pointer valid for `n` records (slots of [`prepared::len`]`(d)`, matrices of `d²`).
#[inline]
pub unsafe fn apply_raw<T: BatchReal, const D: usize>(isa: Isa, args: ApplyArgs<T>) -> BatchStatus
where
    Dim<D>: LaneDim<D>,
{
    dispatch::<T, _>(isa, &mut ApplyOp::<T, D>(args))
}

/// The optional outputs of [`ahat_chat_z`].
#[derive(Debug, Default)]
pub struct Outputs<'a, T> {
    /// `Â` per particle (`n·d²`).
    pub ahat: Option<&'a mut [T]>,
    /// `Ĉ:Z` per particle (`n·d²`), or `Ĉ⁺:Z` with `psd`.
    pub chat_z: Option<&'a mut [T]>,
    /// `Ψ̂` per particle (`n`).
    pub energy: Option<&'a mut [T]>,
    /// Project `Ĉ` onto its PSD part.
    pub psd: bool,
}

/// `Â`, `Ĉ:Z` and `Ψ̂` per particle with one decomposition each (safe form of
/// [`kernels_raw`]): `mu` has `n` entries, `f` `n·d²`, `z` (needed for `chat_z`) `n·d²`.
///
/// Errors: slice lengths that disagree, or `chat_z` without `z`, give
/// `Err(Error::InvalidArgument)` and nothing is written.
#[inline]
pub fn ahat_chat_z<T: BatchReal, const D: usize>(
    isa: Isa,
    mu: &[T],
    f: &[T],
    z: Option<&[T]>,
    out: Outputs<'_, T>,
) -> Result<BatchStatus, Error>
where
    Dim<D>: LaneDim<D>,
{
    let n = mu.len();
    let e = D * D;
    let mat_ok = |s: Option<usize>| s.is_none_or(|l| Some(l) == n.checked_mul(e));
    if !mat_ok(Some(f.len()))
        || !mat_ok(z.map(<[T]>::len))
        || !mat_ok(out.ahat.as_deref().map(<[T]>::len))
        || !mat_ok(out.chat_z.as_deref().map(<[T]>::len))
        || out.energy.as_deref().is_some_and(|s| s.len() != n)
        || (out.chat_z.is_some() && z.is_none())
    {
        return Err(Error::InvalidArgument);
    }
    let args = KernelArgs {
        n,
        mu: mu.as_ptr(),
        f: f.as_ptr(),
        z: z.map_or(ptr::null(), <[T]>::as_ptr),
        ahat: out.ahat.map_or(ptr::null_mut(), <[T]>::as_mut_ptr),
        chat_z: out.chat_z.map_or(ptr::null_mut(), <[T]>::as_mut_ptr),
        energy: out.energy.map_or(ptr::null_mut(), <[T]>::as_mut_ptr),
        psd: out.psd,
    };
    // SAFETY: lengths checked above; distinct borrows cannot overlap.
    Ok(unsafe { kernels_raw::<T, D>(isa, args) })
}

/// Prepares each particle's Hessian into `prepared` (`n` slots of [`prepared::len`]`(d)`),
/// and `Â` when `ahat` is given (safe form of [`prepare_raw`]).
#[inline]
pub fn prepare<T: BatchReal, const D: usize>(
    isa: Isa,
    mu: &[T],
    f: &[T],
    ahat: Option<&mut [T]>,
    prepared: &mut [T],
) -> Result<BatchStatus, Error>
where
    Dim<D>: LaneDim<D>,
{
    let n = mu.len();
    if Some(f.len()) != n.checked_mul(D * D)
        || ahat.as_deref().is_some_and(|a| a.len() != f.len())
        || Some(prepared.len()) != n.checked_mul(prepared::len(D))
    {
        return Err(Error::InvalidArgument);
    }
    let args = PrepareArgs {
        n,
        mu: mu.as_ptr(),
        f: f.as_ptr(),
        ahat: ahat.map_or(ptr::null_mut(), <[T]>::as_mut_ptr),
        prepared: prepared.as_mut_ptr(),
    };
    // SAFETY: lengths checked above.
    Ok(unsafe { prepare_raw::<T, D>(isa, args) })
}

/// `Ĉ:Z` (or `Ĉ⁺:Z` with `psd`) per particle from prepared slots (safe form of
/// [`apply_raw`]).
#[inline]
pub fn apply<T: BatchReal, const D: usize>(
    isa: Isa,
    prepared: &[T],
    z: &[T],
    out: &mut [T],
    psd: bool,
) -> Result<BatchStatus, Error>
where
    Dim<D>: LaneDim<D>,
{
    let w = prepared::len(D);
    if prepared.len() % w != 0 {
        return Err(Error::InvalidArgument);
    }
    let n = prepared.len() / w;
    if Some(z.len()) != n.checked_mul(D * D) || out.len() != z.len() {
        return Err(Error::InvalidArgument);
    }
    let args = ApplyArgs {
        n,
        prepared: prepared.as_ptr(),
        z: z.as_ptr(),
        out: out.as_mut_ptr(),
        psd,
    };
    // SAFETY: lengths checked above.
    Ok(unsafe { apply_raw::<T, D>(isa, args) })
}
