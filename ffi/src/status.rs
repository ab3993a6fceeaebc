//! The status codes returned by every C entry point.

use ampm_core::Error;

/// Result of every `ampm_*` call. `AMPM_OK` is 0; every error has its own non-zero value.
///
/// On any status other than `AMPM_OK`, a single-particle call has written nothing; a batch
/// call has left each failed particle's output untouched (see the batch functions).
#[allow(non_camel_case_types)]
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum AmpmStatus {
    /// Success.
    AMPM_OK = 0,
    /// A required pointer argument is NULL.
    AMPM_ERR_NULL_POINTER = 1,
    /// An input (matrix entry or material parameter) is NaN or infinite.
    AMPM_ERR_NON_FINITE = 2,
    /// J = det F ≤ 0, or F is singular to working precision.
    AMPM_ERR_NON_POSITIVE_J = 3,
    /// The inputs are valid but the result is not representable (overflow).
    AMPM_ERR_OVERFLOW = 4,
    /// A parameter is outside its documented domain (negative mu, unknown option, n too large).
    AMPM_ERR_INVALID_ARGUMENT = 5,
    /// An iterative method hit its iteration cap before its tolerance.
    AMPM_ERR_NOT_CONVERGED = 6,
    /// An internal error was caught at the ABI boundary (a bug: please report it).
    AMPM_ERR_INTERNAL = 7,
    /// A prepared-Hessian slot that no successful `ampm_hessian_prepare_batch_*` wrote
    /// (zero-filled memory, or the slot of a particle whose prepare failed).
    AMPM_ERR_NOT_PREPARED = 8,
    /// A particle's stencil reaches outside the node box of the grid view passed to a
    /// transfer (P2G, G2P, force differential): nothing of that particle was transferred.
    AMPM_ERR_OUTSIDE_GRID = 9,
}

impl From<Error> for AmpmStatus {
    #[inline]
    fn from(e: Error) -> Self {
        match e {
            Error::NonFinite => AmpmStatus::AMPM_ERR_NON_FINITE,
            Error::NonPositiveJ => AmpmStatus::AMPM_ERR_NON_POSITIVE_J,
            Error::Overflow => AmpmStatus::AMPM_ERR_OVERFLOW,
            Error::InvalidArgument => AmpmStatus::AMPM_ERR_INVALID_ARGUMENT,
            Error::NotConverged => AmpmStatus::AMPM_ERR_NOT_CONVERGED,
            Error::NotPrepared => AmpmStatus::AMPM_ERR_NOT_PREPARED,
            Error::OutsideGrid => AmpmStatus::AMPM_ERR_OUTSIDE_GRID,
        }
    }
}

impl From<Result<(), Error>> for AmpmStatus {
    #[inline]
    fn from(r: Result<(), Error>) -> Self {
        match r {
            Ok(()) => AmpmStatus::AMPM_OK,
            Err(e) => e.into(),
        }
    }
}
