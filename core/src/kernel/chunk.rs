//! Moving a chunk of particles between the callers' column-major records and lanes, and
//! the bookkeeping of statuses: what every chunk loop of [`super::batch`] shares.

use super::batch::MAX_LANES;
use super::{flagged, lane_error, Checks};
use crate::error::Error;
use crate::lane::lmat::LMat;
use crate::lane::Lane;
use crate::scalar::Real;
use core::ptr;
/// Transposes `len ≤ V::LANES` records of `W ≤ WMAX` scalars (record `i` at `src + i·stride`)
/// into lanes; lanes past `len` get `pad(entry)`.
///
/// # Safety
/// `src` valid for reading `len` records.
#[inline(always)]
pub(crate) unsafe fn gather<V: Lane, const WMAX: usize>(
    src: *const V::Scalar,
    stride: usize,
    w: usize,
    len: usize,
    pad: impl Fn(usize) -> V::Scalar,
    out: &mut [V; WMAX],
) {
    if len == V::LANES {
        // A whole chunk (every one but a batch's last): hardware gathers, no padding.
        for m in 0..w {
            out[m] = V::gather(src.add(m), stride);
        }
        return;
    }
    let mut buf = [[<V::Scalar as Real>::ZERO; MAX_LANES]; WMAX];
    for i in 0..len {
        let p = src.add(i * stride);
        for m in 0..w {
            buf[m][i] = ptr::read_unaligned(p.add(m));
        }
    }
    for i in len..V::LANES {
        for m in 0..w {
            buf[m][i] = pad(m);
        }
    }
    for m in 0..w {
        out[m] = V::load(&buf[m]);
    }
}

/// Writes the lanes `i < len` with bit `i` of `skip` clear as records of `w` scalars.
///
/// # Safety
/// `dst` valid for writing `len` records.
#[inline(always)]
pub(crate) unsafe fn scatter<V: Lane, const WMAX: usize>(
    src: &[V; WMAX],
    w: usize,
    dst: *mut V::Scalar,
    stride: usize,
    len: usize,
    skip: u64,
) {
    if len == V::LANES {
        // The batch kernels' chunks have at most 32 lanes (`MAX_LANES`): `Lane::scatter`
        // takes 32 bits.
        debug_assert!(V::LANES <= MAX_LANES);
        let keep = !skip as u32;
        for m in 0..w {
            src[m].scatter(dst.add(m), stride, keep);
        }
        return;
    }
    let mut buf = [[<V::Scalar as Real>::ZERO; MAX_LANES]; WMAX];
    for m in 0..w {
        src[m].store(&mut buf[m]);
    }
    for i in 0..len {
        if skip >> i & 1 == 0 {
            let p = dst.add(i * stride);
            for m in 0..w {
                ptr::write_unaligned(p.add(m), buf[m][i]);
            }
        }
    }
}

/// Loads a chunk of matrices (`I` padding).
///
/// # Safety
/// `src` valid for `len` matrices.
#[inline(always)]
pub(crate) unsafe fn load_mats<V: Lane, const D: usize>(
    src: *const V::Scalar,
    len: usize,
    pad_identity: bool,
) -> LMat<V, D> {
    let mut flat = [V::splat(<V::Scalar as Real>::ZERO); 9];
    let one = <V::Scalar as Real>::ONE;
    let zero = <V::Scalar as Real>::ZERO;
    gather::<V, 9>(
        src,
        D * D,
        D * D,
        len,
        |m| {
            if pad_identity && m % (D + 1) == 0 {
                one
            } else {
                zero
            }
        },
        &mut flat,
    );
    let mut r = [[flat[0]; D]; D];
    for j in 0..D {
        for i in 0..D {
            r[j][i] = flat[i + D * j];
        }
    }
    r
}

/// Stores a chunk of matrices for the lanes not in `skip`.
///
/// # Safety
/// `dst` valid for `len` matrices.
#[inline(always)]
pub(crate) unsafe fn store_mats<V: Lane, const D: usize>(
    m: &LMat<V, D>,
    dst: *mut V::Scalar,
    len: usize,
    skip: u64,
) {
    let mut flat = [m[0][0]; 9];
    for j in 0..D {
        for i in 0..D {
            flat[i + D * j] = m[j][i];
        }
    }
    scatter::<V, 9>(&flat, D * D, dst, D * D, len, skip);
}

/// The first failure of a chunk, if any, as `(lane, status)`.
#[inline(always)]
pub(crate) fn first_error(bits: &[(u64, Error)], len: usize) -> Option<(usize, Error)> {
    let all = flagged(bits) & (u64::MAX >> (64 - len as u32));
    if all == 0 {
        return None;
    }
    let l = all.trailing_zeros() as usize;
    lane_error(bits, l).map(|e| (l, e))
}

/// Tracks the first failure over the chunks of a batch.
#[derive(Clone, Copy)]
pub(crate) struct First {
    n: usize,
    at: usize,
    err: Option<Error>,
}

impl First {
    #[inline(always)]
    pub(crate) fn new(n: usize) -> Self {
        Self {
            n,
            at: n,
            err: None,
        }
    }
    #[inline(always)]
    pub(crate) fn note(&mut self, start: usize, bits: &[(u64, Error)], len: usize) {
        if self.err.is_none() {
            if let Some((l, e)) = first_error(bits, len) {
                self.at = start + l;
                self.err = Some(e);
            }
        }
    }
    #[inline(always)]
    pub(crate) fn status(self) -> super::batch::BatchStatus {
        super::batch::BatchStatus {
            first_failed: if self.err.is_some() { self.at } else { self.n },
            error: self.err,
        }
    }
}

/// An all-false mask.
#[inline(always)]
pub(crate) fn none<V: Lane>() -> V::Mask {
    V::splat(<V::Scalar as Real>::ONE).lt(V::splat(<V::Scalar as Real>::ZERO))
}

/// The check masks of [`super::evaluate`] as bit sets with their statuses, in order of precedence.
#[inline(always)]
pub(crate) fn check_bits<V: Lane>(ck: &Checks<V::Mask>) -> [(u64, Error); 5] {
    [
        (V::mask_bits(ck.f_non_finite), Error::NonFinite),
        (V::mask_bits(ck.j_non_positive), Error::NonPositiveJ),
        (V::mask_bits(ck.mu_non_finite), Error::NonFinite),
        (V::mask_bits(ck.mu_negative), Error::InvalidArgument),
        (V::mask_bits(ck.singular), Error::NonPositiveJ),
    ]
}

/// The status of lane `l` from the kernel's [`check_bits`], whose [`flagged`] lanes are
/// `flagged_lanes`, for a particle with shear modulus `mu`: looked up only for a flagged lane
/// (usually none), and `None` where `μ = 0` (a liquid's lane runs no decomposition in the
/// scalar path either, so its checks of `F` do not apply).
#[inline(always)]
pub(crate) fn kernel_lane_error<T: Real>(
    bits: &[(u64, Error)],
    flagged_lanes: u64,
    l: usize,
    mu: T,
) -> Option<Error> {
    if flagged_lanes >> l & 1 == 1 && mu > T::ZERO {
        lane_error(bits, l)
    } else {
        None
    }
}
