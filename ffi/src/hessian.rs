//! C entry points of the Hessian matrices and the PSD-projected action.
//!
//! For every dimension × precision: `ampm_chat_z_psd_<d>_<p>` (Ĉ⁺:Z), its batch form, and
//! the explicit d²×d² matrices `ampm_chat_matrix_<d>_<p>` (Ĉ) and
//! `ampm_chat_psd_matrix_<d>_<p>` (Ĉ⁺), fixed corotated base energy, default SVD method.
//! The `extern "C"` wrappers are rendered from `ffi/api/hessian.rs` into
//! `generated/hessian.rs`; the action runs on `crate::fast`, the matrices on the generic
//! bodies below, which use the helpers of `abi.rs`.

use crate::abi::{guard, read_mat};
use crate::status::AmpmStatus;
use ampm_core::energy::FixedCorotated;
use ampm_core::hessian::{self, HessianDim};
use ampm_core::polar::{DefaultSvd, SvdMethod};
use ampm_core::Error;
use core::ptr;

pub use crate::generated::hessian::*;

/// Single-particle call producing one d²×d² matrix (`M::LEN²` scalars) from `mu` and `F`.
/// Reads `F` completely before writing; writes `out` only on success.
///
/// # Safety
/// Non-null `f` valid for `M::LEN` scalars, non-null `out` for `M::LEN²` scalars.
#[inline]
unsafe fn wide_unary<M: HessianDim>(
    mu: M::Scalar,
    f: *const M::Scalar,
    out: *mut M::Scalar,
    k: impl FnOnce(&FixedCorotated<M::Scalar>, &M) -> Result<M::Wide, Error>,
) -> AmpmStatus {
    guard(|| {
        if f.is_null() || out.is_null() {
            return AmpmStatus::AMPM_ERR_NULL_POINTER;
        }
        match k(&FixedCorotated::new(mu), &read_mat::<M>(f)) {
            Ok(w) => {
                // `M::Wide` is `Mat<T, d²>`: repr(C) columns, i.e. column-major d²×d².
                ptr::write_unaligned(out.cast::<M::Wide>(), w);
                AmpmStatus::AMPM_OK
            }
            Err(e) => e.into(),
        }
    })
}

/// Body of `ampm_chat_matrix_*`.
///
/// # Safety
/// As [`wide_unary`].
pub(crate) unsafe fn chat_matrix<M: HessianDim>(
    mu: M::Scalar,
    f: *const M::Scalar,
    out: *mut M::Scalar,
) -> AmpmStatus
where
    DefaultSvd: SvdMethod<M>,
{
    wide_unary::<M>(mu, f, out, |e, f| hessian::chat_matrix(e, f))
}

/// Body of `ampm_chat_psd_matrix_*`.
///
/// # Safety
/// As [`wide_unary`].
pub(crate) unsafe fn chat_psd_matrix<M: HessianDim>(
    mu: M::Scalar,
    f: *const M::Scalar,
    out: *mut M::Scalar,
) -> AmpmStatus
where
    DefaultSvd: SvdMethod<M>,
{
    wide_unary::<M>(mu, f, out, |e, f| hessian::chat_psd_matrix(e, f))
}
