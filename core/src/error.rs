//! Errors of the kernels. The C ABI maps each to its own `AmpmStatus` code.

/// Why a kernel refused its input or could not produce a representable result.
///
/// Every kernel either returns a finite result or one of these; it never returns NaN or inf.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Error {
    /// An input entry (matrix entry or material parameter) is NaN or infinite.
    NonFinite,
    /// `J = det F ≤ 0`, or `F` is singular to working precision: `Ψ̂(F) = Ψ(Jᵃ F)` is
    /// undefined there (2D), or blind to inversion (3D), so both dimensions refuse it.
    NonPositiveJ,
    /// The inputs are valid but the result overflows the scalar type (e.g. a subnormal `F`,
    /// whose `Ĉ` scales like `‖F‖⁻²`).
    Overflow,
    /// A parameter is outside its documented domain (negative μ, zero count, bad option).
    InvalidArgument,
    /// An iterative method reached its iteration cap without meeting its tolerance.
    NotConverged,
    /// A prepared-Hessian slot that no successful prepare wrote (zero-filled, or marked by a
    /// failed prepare): applying it would use stale or meaningless data.
    NotPrepared,
    /// A particle's stencil reaches outside the node box of the grid view it transfers to or
    /// from.
    OutsideGrid,
}

/// Result type of the kernels.
pub type Result<T> = core::result::Result<T, Error>;

impl core::fmt::Display for Error {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str(match self {
            Error::NonFinite => "an input is NaN or infinite",
            Error::NonPositiveJ => "J = det F is not positive",
            Error::Overflow => "the result is not representable (overflow)",
            Error::InvalidArgument => "a parameter is outside its domain",
            Error::NotConverged => "iteration cap reached before convergence",
            Error::OutsideGrid => "the particle's stencil reaches outside the grid view",
            Error::NotPrepared => {
                "the prepared-Hessian slot was not written by a successful prepare"
            }
        })
    }
}
