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
//! down to the intrinsics; they run on the instruction set an [`Isa`] names, instantiated
//! inside one `#[target_feature]` function per instruction set (the crate's `kernel::dispatch`).
//! All paths give the same bits (see [`crate::lane`]).

#![allow(clippy::needless_range_loop, clippy::too_many_arguments)]

use super::chunk::{check_bits, gather, load_mats, none, scatter, store_mats, First};
use super::prepared::{self, MAX_LEN};
use super::{ahat, chat_z, evaluate, flagged, psd_block, Dim, LaneDim};
use crate::error::Error;
use crate::lane::lmat::all_finite;
use crate::lane::{Isa, Lane};
use core::ptr;

pub(crate) use super::dispatch::{dispatch, LaneOp, ScalarRow};
pub use super::dispatch::{BatchReal, BatchStatus, WithChunks, MAX_LANES, WIDE_LANES};

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
    if !sigma.len().is_multiple_of(D) || f.len() != n * e || u.len() != n * e || v.len() != n * e {
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
    if !prepared.len().is_multiple_of(w) {
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
