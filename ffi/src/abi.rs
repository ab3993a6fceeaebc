//! Generic bodies of the C entry points: pointer checks, unaligned reads, all-or-nothing
//! writes, the batch contract, panic containment. The `extern "C"` wrappers (rendered into
//! `generated/`) only name types.
//!
//! Memory contract (all entry points): matrices are `d·d` scalars, column-major
//! (`F[i + d·j] = F_ij`), with no alignment requirement beyond the scalar's. Inputs are read
//! completely before any output is written, so an output may alias an input of the same
//! particle exactly (in place), but must not partially overlap one.

use crate::status::AmpmStatus;
use ampm_core::{Error, Matrix};
use core::ptr;

/// Runs `f`, turning a panic (a bug) into `AMPM_ERR_INTERNAL` instead of unwinding into C.
#[inline]
pub(crate) fn guard(f: impl FnOnce() -> AmpmStatus) -> AmpmStatus {
    match std::panic::catch_unwind(std::panic::AssertUnwindSafe(f)) {
        Ok(s) => s,
        Err(_) => AmpmStatus::AMPM_ERR_INTERNAL,
    }
}

/// Reads one matrix (`M::LEN` scalars) from `p`.
///
/// # Safety
/// `p` must be non-null and valid for reading `M::LEN` scalars.
#[inline]
pub(crate) unsafe fn read_mat<M: Matrix>(p: *const M::Scalar) -> M {
    M::from_array(&ptr::read_unaligned(p.cast::<M::Array>()))
}

/// Writes one matrix to `p`.
///
/// # Safety
/// `p` must be non-null and valid for writing `M::LEN` scalars.
#[inline]
pub(crate) unsafe fn write_mat<M: Matrix>(p: *mut M::Scalar, m: &M) {
    ptr::write_unaligned(p.cast::<M::Array>(), m.to_array());
}

/// Status of a single-particle call computing one matrix from one input matrix.
///
/// # Safety
/// Non-null pointers must be valid for `M::LEN` scalars.
#[inline]
pub(crate) unsafe fn unary<M: Matrix>(
    a: *const M::Scalar,
    out: *mut M::Scalar,
    k: impl FnOnce(&M) -> Result<M, Error>,
) -> AmpmStatus {
    guard(|| {
        if a.is_null() || out.is_null() {
            return AmpmStatus::AMPM_ERR_NULL_POINTER;
        }
        match k(&read_mat::<M>(a)) {
            Ok(r) => {
                write_mat(out, &r);
                AmpmStatus::AMPM_OK
            }
            Err(e) => e.into(),
        }
    })
}

/// Status of a single-particle call computing one matrix from two input matrices.
///
/// # Safety
/// Non-null pointers must be valid for `M::LEN` scalars.
#[inline]
pub(crate) unsafe fn binary<M: Matrix>(
    a: *const M::Scalar,
    b: *const M::Scalar,
    out: *mut M::Scalar,
    k: impl FnOnce(&M, &M) -> Result<M, Error>,
) -> AmpmStatus {
    if b.is_null() {
        return AmpmStatus::AMPM_ERR_NULL_POINTER;
    }
    unary::<M>(a, out, |x| k(x, &read_mat::<M>(b)))
}

/// Runs the body of a batch call with panics contained, and writes `*first_failed` (when
/// non-null): the batch contract of the header.
///
/// `body` returns `Err(status)` for an error of the whole call, found before any record is
/// read or written (a NULL required pointer, `n` too large, an invalid option): then
/// `*first_failed` = 0. Otherwise it returns the call's status and the index of the first
/// failed record (`n` if none), which goes to `*first_failed`. A caught panic (a bug) gives
/// `AMPM_ERR_INTERNAL` and `*first_failed` = 0.
///
/// # Safety
/// `first_failed` null or valid for writing one `usize`.
#[inline]
pub(crate) unsafe fn batch_call(
    first_failed: *mut usize,
    body: impl FnOnce() -> Result<(AmpmStatus, usize), AmpmStatus>,
) -> AmpmStatus {
    let (status, first) = match std::panic::catch_unwind(std::panic::AssertUnwindSafe(body)) {
        Ok(Ok(done)) => done,
        Ok(Err(whole_call)) => (whole_call, 0),
        Err(_) => (AmpmStatus::AMPM_ERR_INTERNAL, 0),
    };
    if !first_failed.is_null() {
        *first_failed = first;
    }
    status
}

/// Batch driver: for each particle `i < n`, `k(i)` computes the result or an error; results
/// are written to `out + i·M::LEN` only on success.
///
/// Returns the first failure's status (or `AMPM_OK`) and its index (`n` when all succeed),
/// for [`batch_call`].
///
/// # Safety
/// `out` must be valid for `n·M::LEN` scalars; `k` reads the inputs of particle `i` only.
#[inline]
pub(crate) unsafe fn batch<M: Matrix>(
    n: usize,
    out: *mut M::Scalar,
    mut k: impl FnMut(usize) -> Result<M, Error>,
) -> (AmpmStatus, usize) {
    let mut status = AmpmStatus::AMPM_OK;
    let mut first = n;
    for i in 0..n {
        match k(i) {
            Ok(r) => write_mat(out.add(i * M::LEN), &r),
            Err(e) => {
                if first == n {
                    first = i;
                    status = e.into();
                }
            }
        }
    }
    (status, first)
}

/// Checks the array pointers and size of a batch call: `Err` is a whole-call error
/// (`AMPM_ERR_NULL_POINTER`, then `AMPM_ERR_INVALID_ARGUMENT` for an `n` whose arrays are not
/// addressable).
///
/// Null arrays are accepted when `n == 0` (an empty `std::vector` has a null `data()`).
#[inline]
pub(crate) fn check_batch<M: Matrix>(n: usize, ptrs: &[bool]) -> Result<(), AmpmStatus> {
    if n == 0 {
        return Ok(());
    }
    if ptrs.iter().any(|&is_null| is_null) {
        return Err(AmpmStatus::AMPM_ERR_NULL_POINTER);
    }
    // n·d² scalars must be addressable.
    match n.checked_mul(M::LEN * core::mem::size_of::<M::Scalar>()) {
        Some(b) if b <= isize::MAX as usize => Ok(()),
        _ => Err(AmpmStatus::AMPM_ERR_INVALID_ARGUMENT),
    }
}
