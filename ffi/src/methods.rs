//! C entry points taking a run-time polar/SVD method choice: the `_ex` variants of the
//! kernels and the SVD and polar decompositions.
//!
//! A method is chosen at run time by an [`AmpmOptions`] (NULL = defaults). Its `method` field
//! is a plain `uint32_t` holding one of the `AMPM_METHOD_*` values, never a C enum read as a
//! Rust enum: an unknown value is `AMPM_ERR_INVALID_ARGUMENT`, not undefined behaviour. The
//! methods are those of `ampm_core::polar` (see its table): 2D accepts `AMPM_METHOD_DEFAULT`
//! and `AMPM_METHOD_CLOSED_FORM_2D` only.
//!
//! The `extern "C"` wrappers are rendered from `ffi/api/methods.rs` into
//! `generated/methods.rs`; each calls one generic body of `ex` (the kernels) or `decomp`
//! (the decompositions), which use the helpers of `abi.rs`: pointer checks, all inputs read
//! before any output is written, the single-call and batch contracts, no panic crossing into
//! C. The run-time choice is [`RuntimeSvd`], an enum that implements `SvdMethod` by
//! dispatching to the chosen method, so the kernels are the very same generic code as the
//! compile-time path.

pub(crate) mod decomp;
pub(crate) mod ex;

use ampm_core::polar::{
    ClosedForm2, HighamNoferini, McAdams, OneSidedJacobi, QrSvd, Svd, SvdMethod,
};
use ampm_core::{Error, Mat, Matrix, Real};
use core::ptr;

pub use crate::generated::methods::*;

/// `AmpmOptions::method`: the default of the dimension (2D closed form, 3D one-sided Jacobi).
pub const AMPM_METHOD_DEFAULT: u32 = 0;
/// `AmpmOptions::method`: one-sided (Hestenes) Jacobi on F, 3D; `max_iterations` sets the
/// number of sweeps.
pub const AMPM_METHOD_ONE_SIDED_JACOBI: u32 = 1;
/// `AmpmOptions::method`: McAdams et al. 2011 branch-free Jacobi on FᵀF, 3D; `sweeps` sweeps.
pub const AMPM_METHOD_MCADAMS: u32 = 2;
/// `AmpmOptions::method`: Gast et al. 2016 implicit-shifted QR on F, 3D; `max_iterations`
/// caps the QR sweeps.
pub const AMPM_METHOD_QR: u32 = 3;
/// `AmpmOptions::method`: Higham–Noferini 2016 quaternion polar decomposition, 3D;
/// `max_iterations` caps each Jacobi eigen-solve.
pub const AMPM_METHOD_HIGHAM_NOFERINI: u32 = 4;
/// `AmpmOptions::method`: the 2D closed form (the only 2D method).
pub const AMPM_METHOD_CLOSED_FORM_2D: u32 = 5;
/// Smallest accepted `AmpmOptions::sweeps` (other than 0 = default).
pub const AMPM_MCADAMS_MIN_SWEEPS: u32 = 2;
/// Largest accepted `AmpmOptions::sweeps`.
pub const AMPM_MCADAMS_MAX_SWEEPS: u32 = 8;
/// Largest accepted `AmpmOptions::max_iterations`.
pub const AMPM_MAX_ITERATIONS_LIMIT: u32 = 1000;

/// Run-time choice of the polar/SVD method. Pass NULL for all defaults.
///
/// Every field's 0 means "the default"; a field a method does not use is ignored.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct AmpmOptions {
    /// One of the `AMPM_METHOD_*` values; anything else gives `AMPM_ERR_INVALID_ARGUMENT`, and
    /// so does a 3D method in a 2D call (or the 2D closed form in a 3D call).
    pub method: u32,
    /// Jacobi sweeps of `AMPM_METHOD_MCADAMS`: 0 (default, 4) or 2..=8.
    pub sweeps: u32,
    /// Sweeps of `AMPM_METHOD_ONE_SIDED_JACOBI` (a fixed count; default 3
    /// in f32, 4 in f64), iteration cap of `AMPM_METHOD_QR` (QR sweeps, default 32) and of
    /// `AMPM_METHOD_HIGHAM_NOFERINI` (Jacobi sweeps per eigen-solve, default 16): 0 (default)
    /// or 1..=1000. Reaching a cap without convergence is `AMPM_ERR_NOT_CONVERGED` (QR,
    /// Higham–Noferini).
    pub max_iterations: u32,
}

/// The method chosen at run time; implements `SvdMethod` in 2D and 3D by dispatch.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum RuntimeSvd {
    /// The default of the dimension.
    #[default]
    Default,
    /// The 2D closed form.
    ClosedForm2,
    /// One-sided Jacobi (3D).
    OneSidedJacobi(OneSidedJacobi),
    /// McAdams et al. (3D).
    McAdams(McAdams),
    /// Gast et al. QR (3D).
    Qr(QrSvd),
    /// Higham–Noferini (3D).
    HighamNoferini(HighamNoferini),
}

impl RuntimeSvd {
    /// Validates `opts` for dimension `dim` (2 or 3).
    ///
    /// # Errors
    /// `Error::InvalidArgument` for an unknown method, a method of the other dimension, or a
    /// field outside its range.
    pub fn from_options(opts: &AmpmOptions, dim: usize) -> Result<Self, Error> {
        let iters = |default: u32| match opts.max_iterations {
            0 => Ok(default),
            n if n <= AMPM_MAX_ITERATIONS_LIMIT => Ok(n),
            _ => Err(Error::InvalidArgument),
        };
        match (opts.method, dim) {
            (AMPM_METHOD_DEFAULT, 2 | 3) => Ok(RuntimeSvd::Default),
            (AMPM_METHOD_CLOSED_FORM_2D, 2) => Ok(RuntimeSvd::ClosedForm2),
            (AMPM_METHOD_ONE_SIDED_JACOBI, 3) => Ok(RuntimeSvd::OneSidedJacobi(OneSidedJacobi {
                sweeps: iters(0)?,
            })),
            (AMPM_METHOD_MCADAMS, 3) => match opts.sweeps {
                0 => Ok(RuntimeSvd::McAdams(McAdams::default())),
                s if (AMPM_MCADAMS_MIN_SWEEPS..=AMPM_MCADAMS_MAX_SWEEPS).contains(&s) => {
                    Ok(RuntimeSvd::McAdams(McAdams { sweeps: s }))
                }
                _ => Err(Error::InvalidArgument),
            },
            (AMPM_METHOD_QR, 3) => Ok(RuntimeSvd::Qr(QrSvd {
                max_iterations: iters(QrSvd::default().max_iterations)?,
            })),
            (AMPM_METHOD_HIGHAM_NOFERINI, 3) => Ok(RuntimeSvd::HighamNoferini(HighamNoferini {
                max_sweeps: iters(HighamNoferini::default().max_sweeps)?,
            })),
            _ => Err(Error::InvalidArgument),
        }
    }
}

impl<T: Real> SvdMethod<Mat<T, 2>> for RuntimeSvd {
    const NAME: &'static str = "runtime";
    #[inline]
    fn svd(&self, f: &Mat<T, 2>) -> ampm_core::Result<Svd<Mat<T, 2>>> {
        match self {
            RuntimeSvd::Default | RuntimeSvd::ClosedForm2 => ClosedForm2.svd(f),
            _ => Err(Error::InvalidArgument),
        }
    }
}

impl<T: Real> SvdMethod<Mat<T, 3>> for RuntimeSvd {
    const NAME: &'static str = "runtime";
    #[inline]
    fn svd(&self, f: &Mat<T, 3>) -> ampm_core::Result<Svd<Mat<T, 3>>> {
        match self {
            RuntimeSvd::Default => OneSidedJacobi::default().svd(f),
            RuntimeSvd::OneSidedJacobi(m) => m.svd(f),
            RuntimeSvd::McAdams(m) => m.svd(f),
            RuntimeSvd::Qr(m) => m.svd(f),
            RuntimeSvd::HighamNoferini(m) => m.svd(f),
            RuntimeSvd::ClosedForm2 => Err(Error::InvalidArgument),
        }
    }
}

/// Reads and validates the options (NULL = defaults).
///
/// # Safety
/// `opts` is NULL or valid for reading one `AmpmOptions`.
#[inline]
pub(crate) unsafe fn options<M: Matrix>(opts: *const AmpmOptions) -> Result<RuntimeSvd, Error> {
    let o = if opts.is_null() {
        AmpmOptions::default()
    } else {
        ptr::read_unaligned(opts)
    };
    RuntimeSvd::from_options(&o, M::DIM)
}

/// `true` when `opts` selects the default method (NULL, or `method = AMPM_METHOD_DEFAULT`).
///
/// # Safety
/// `opts` is NULL or valid for reading one `AmpmOptions`.
pub(crate) unsafe fn is_default<M: Matrix>(opts: *const AmpmOptions) -> bool {
    matches!(options::<M>(opts), Ok(RuntimeSvd::Default))
}
