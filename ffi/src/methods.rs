//! C entry points taking a run-time polar/SVD method choice: the `_ex` variants.
//!
//! A method is chosen at run time by an [`AmpmOptions`] (NULL = defaults). Its `method` field
//! is a plain `uint32_t` holding one of the `AMPM_METHOD_*` values, never a C enum read as a
//! Rust enum: an unknown value is `AMPM_ERR_INVALID_ARGUMENT`, not undefined behaviour. The
//! methods are those of `ampm_core::polar` (see its table): 2D accepts `AMPM_METHOD_DEFAULT`
//! and `AMPM_METHOD_CLOSED_FORM_2D` only.
//!
//! Every function here is a thin wrapper (written out, because cbindgen does not expand
//! macros) around one generic body below, which uses the helpers of `abi.rs`: pointer checks,
//! all inputs read before any output is written, outputs written only on success, no panic
//! crossing into C. The run-time choice is [`RuntimeSvd`], an enum that implements
//! `SvdMethod` by dispatching to the chosen method, so the kernels are the very same generic
//! code as the compile-time path.
#![allow(clippy::missing_safety_doc)]

use crate::abi::{batch, binary, check_batch, guard, read_mat, unary, write_mat};
use crate::status::AmpmStatus;
use ampm_core::augmented::{self, Augmented};
use ampm_core::energy::FixedCorotated;
use ampm_core::polar::{
    ClosedForm2, HighamNoferini, McAdams, OneSidedJacobi, QrSvd, Svd, SvdMethod,
};
use ampm_core::{Error, Mat, Matrix, Real};
use core::ptr;

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
unsafe fn options<M: Matrix>(opts: *const AmpmOptions) -> Result<RuntimeSvd, Error> {
    let o = if opts.is_null() {
        AmpmOptions::default()
    } else {
        ptr::read_unaligned(opts)
    };
    RuntimeSvd::from_options(&o, M::DIM)
}

/// The default method runs the same fast kernels as the entry points without `_ex`, so NULL
/// options give exactly their results.
trait Fast: Matrix {
    /// [`crate::fast::kernels`] on the batch instruction set (`batch`) or the scalar path.
    #[allow(clippy::too_many_arguments)]
    unsafe fn fast(
        batch: bool,
        n: usize,
        mu: *const Self::Scalar,
        f: *const Self::Scalar,
        z: *const Self::Scalar,
        ahat: *mut Self::Scalar,
        chat_z: *mut Self::Scalar,
        energy: *mut Self::Scalar,
        first_failed: *mut usize,
    ) -> AmpmStatus;
}

macro_rules! impl_fast {
    ($t:ty, $d:literal) => {
        impl Fast for Mat<$t, $d> {
            unsafe fn fast(
                batch: bool,
                n: usize,
                mu: *const $t,
                f: *const $t,
                z: *const $t,
                ahat: *mut $t,
                chat_z: *mut $t,
                energy: *mut $t,
                first_failed: *mut usize,
            ) -> AmpmStatus {
                let isa = if batch {
                    crate::fast::isa()
                } else {
                    ampm_core::lane::Isa::SCALAR
                };
                crate::fast::kernels::<$t, $d>(
                    isa,
                    n,
                    mu,
                    f,
                    z,
                    ahat,
                    chat_z,
                    energy,
                    false,
                    first_failed,
                )
            }
        }
    };
}
impl_fast!(f32, 2);
impl_fast!(f64, 2);
impl_fast!(f32, 3);
impl_fast!(f64, 3);

/// `true` when `opts` selects the default method (NULL, or `method = AMPM_METHOD_DEFAULT`).
///
/// # Safety
/// `opts` is NULL or valid for reading one `AmpmOptions`.
unsafe fn is_default<M: Matrix>(opts: *const AmpmOptions) -> bool {
    matches!(options::<M>(opts), Ok(RuntimeSvd::Default))
}

unsafe fn energy_hat_ex<M: Fast>(
    opts: *const AmpmOptions,
    mu: M::Scalar,
    f: *const M::Scalar,
    out: *mut M::Scalar,
) -> AmpmStatus
where
    RuntimeSvd: SvdMethod<M>,
{
    if is_default::<M>(opts) {
        let mu = [mu];
        return M::fast(
            false,
            1,
            mu.as_ptr(),
            f,
            ptr::null(),
            ptr::null_mut(),
            ptr::null_mut(),
            out,
            ptr::null_mut(),
        );
    }
    guard(|| {
        if f.is_null() || out.is_null() {
            return AmpmStatus::AMPM_ERR_NULL_POINTER;
        }
        let m = match options::<M>(opts) {
            Ok(m) => m,
            Err(e) => return e.into(),
        };
        match augmented::psi_hat(&FixedCorotated::with_method(mu, m), &read_mat::<M>(f)) {
            Ok(p) => {
                ptr::write_unaligned(out, p);
                AmpmStatus::AMPM_OK
            }
            Err(e) => e.into(),
        }
    })
}

unsafe fn ahat_ex<M: Fast>(
    opts: *const AmpmOptions,
    mu: M::Scalar,
    f: *const M::Scalar,
    out: *mut M::Scalar,
) -> AmpmStatus
where
    RuntimeSvd: SvdMethod<M>,
{
    if is_default::<M>(opts) {
        let mu = [mu];
        return M::fast(
            false,
            1,
            mu.as_ptr(),
            f,
            ptr::null(),
            out,
            ptr::null_mut(),
            ptr::null_mut(),
            ptr::null_mut(),
        );
    }
    unary::<M>(f, out, |f| {
        augmented::ahat(&FixedCorotated::with_method(mu, options::<M>(opts)?), f)
    })
}

unsafe fn chat_z_ex<M: Fast>(
    opts: *const AmpmOptions,
    mu: M::Scalar,
    f: *const M::Scalar,
    z: *const M::Scalar,
    out: *mut M::Scalar,
) -> AmpmStatus
where
    RuntimeSvd: SvdMethod<M>,
{
    if is_default::<M>(opts) {
        let mu = [mu];
        return M::fast(
            false,
            1,
            mu.as_ptr(),
            f,
            z,
            ptr::null_mut(),
            out,
            ptr::null_mut(),
            ptr::null_mut(),
        );
    }
    binary::<M>(f, z, out, |f, z| {
        augmented::chat_z(&FixedCorotated::with_method(mu, options::<M>(opts)?), f, z)
    })
}

unsafe fn ahat_batch_ex<M: Fast>(
    opts: *const AmpmOptions,
    n: usize,
    mu: *const M::Scalar,
    f: *const M::Scalar,
    out: *mut M::Scalar,
    first_failed: *mut usize,
) -> AmpmStatus
where
    RuntimeSvd: SvdMethod<M>,
{
    if is_default::<M>(opts) {
        return M::fast(
            true,
            n,
            mu,
            f,
            ptr::null(),
            out,
            ptr::null_mut(),
            ptr::null_mut(),
            first_failed,
        );
    }
    guard(|| {
        let st = check_batch::<M>(n, &[mu.is_null(), f.is_null(), out.is_null()]);
        if st != AmpmStatus::AMPM_OK {
            return st;
        }
        let m = match options::<M>(opts) {
            Ok(m) => m,
            Err(e) => return e.into(),
        };
        batch::<M>(n, out, first_failed, |i| {
            let e = FixedCorotated::with_method(ptr::read_unaligned(mu.add(i)), m);
            augmented::ahat(&e, &read_mat::<M>(f.add(i * M::LEN)))
        })
    })
}

unsafe fn chat_z_batch_ex<M: Fast>(
    opts: *const AmpmOptions,
    n: usize,
    mu: *const M::Scalar,
    f: *const M::Scalar,
    z: *const M::Scalar,
    out: *mut M::Scalar,
    first_failed: *mut usize,
) -> AmpmStatus
where
    RuntimeSvd: SvdMethod<M>,
{
    if is_default::<M>(opts) {
        return M::fast(
            true,
            n,
            mu,
            f,
            z,
            ptr::null_mut(),
            out,
            ptr::null_mut(),
            first_failed,
        );
    }
    guard(|| {
        let st = check_batch::<M>(n, &[mu.is_null(), f.is_null(), z.is_null(), out.is_null()]);
        if st != AmpmStatus::AMPM_OK {
            return st;
        }
        let m = match options::<M>(opts) {
            Ok(m) => m,
            Err(e) => return e.into(),
        };
        batch::<M>(n, out, first_failed, |i| {
            let e = FixedCorotated::with_method(ptr::read_unaligned(mu.add(i)), m);
            let zi = read_mat::<M>(z.add(i * M::LEN));
            Augmented::new(&e, &read_mat::<M>(f.add(i * M::LEN)))?.chat_z(&zi)
        })
    })
}

unsafe fn svd_ex<M: Matrix>(
    opts: *const AmpmOptions,
    f: *const M::Scalar,
    u: *mut M::Scalar,
    sigma: *mut M::Scalar,
    v: *mut M::Scalar,
) -> AmpmStatus
where
    RuntimeSvd: SvdMethod<M>,
{
    guard(|| {
        if f.is_null() || u.is_null() || sigma.is_null() || v.is_null() {
            return AmpmStatus::AMPM_ERR_NULL_POINTER;
        }
        let m = match options::<M>(opts) {
            Ok(m) => m,
            Err(e) => return e.into(),
        };
        match m.svd(&read_mat::<M>(f)) {
            Ok(s) => {
                write_mat(u, &s.u);
                for i in 0..M::DIM {
                    ptr::write_unaligned(sigma.add(i), s.sigma[i]);
                }
                write_mat(v, &s.v);
                AmpmStatus::AMPM_OK
            }
            Err(e) => e.into(),
        }
    })
}

unsafe fn polar_ex<M: Matrix>(
    opts: *const AmpmOptions,
    f: *const M::Scalar,
    r: *mut M::Scalar,
    s: *mut M::Scalar,
) -> AmpmStatus
where
    RuntimeSvd: SvdMethod<M>,
{
    guard(|| {
        if f.is_null() || r.is_null() || s.is_null() {
            return AmpmStatus::AMPM_ERR_NULL_POINTER;
        }
        let m = match options::<M>(opts) {
            Ok(m) => m,
            Err(e) => return e.into(),
        };
        match m.svd(&read_mat::<M>(f)) {
            Ok(d) => {
                let (rot, st) = (d.rotation(), d.stretch());
                if !(rot.is_finite() && st.is_finite()) {
                    return AmpmStatus::AMPM_ERR_OVERFLOW;
                }
                write_mat(r, &rot);
                write_mat(s, &st);
                AmpmStatus::AMPM_OK
            }
            Err(e) => e.into(),
        }
    })
}

/// Computes Ψ̂(F) = μ‖F̂ − R̂‖², F̂ = J^(-1/2) F, with a run-time choice of the polar method.
///
/// `opts`: method choice, NULL for the defaults (see `AmpmOptions`); an invalid choice gives `AMPM_ERR_INVALID_ARGUMENT`. `mu` ≥ 0 (Pa); `f`: 2×2 column-major; `out[0]` receives Ψ̂ (J/m³), only on `AMPM_OK`.
///
/// # Safety
/// `opts` is NULL or valid for one `AmpmOptions`; other non-null pointers must be valid for
/// the sizes above.
#[no_mangle]
pub unsafe extern "C" fn ampm_energy_hat_ex_2d_f32(
    opts: *const AmpmOptions,
    mu: f32,
    f: *const f32,
    out: *mut f32,
) -> AmpmStatus {
    energy_hat_ex::<Mat<f32, 2>>(opts, mu, f, out)
}

/// Computes Â = ∂Ψ̂/∂F (volume-preserving fixed corotated) with a run-time choice of the polar method.
///
/// `opts`: method choice, NULL for the defaults (see `AmpmOptions`); an invalid choice gives `AMPM_ERR_INVALID_ARGUMENT`. `mu` ≥ 0 (Pa); `f`: 2×2 column-major; `out`: 2×2 stress (Pa), written only on `AMPM_OK`.
///
/// # Safety
/// `opts` is NULL or valid for one `AmpmOptions`; other non-null pointers must be valid for
/// the sizes above.
#[no_mangle]
pub unsafe extern "C" fn ampm_ahat_ex_2d_f32(
    opts: *const AmpmOptions,
    mu: f32,
    f: *const f32,
    out: *mut f32,
) -> AmpmStatus {
    ahat_ex::<Mat<f32, 2>>(opts, mu, f, out)
}

/// Computes Ĉ:Z, the Hessian action of the volume-preserving fixed corotated energy, with a run-time choice of the polar method.
///
/// `opts`: method choice, NULL for the defaults (see `AmpmOptions`); an invalid choice gives `AMPM_ERR_INVALID_ARGUMENT`. `mu` ≥ 0 (Pa); `f`, `z`: 2×2 column-major; `out`: 2×2, written only on `AMPM_OK`.
///
/// # Safety
/// `opts` is NULL or valid for one `AmpmOptions`; other non-null pointers must be valid for
/// the sizes above.
#[no_mangle]
pub unsafe extern "C" fn ampm_chat_z_ex_2d_f32(
    opts: *const AmpmOptions,
    mu: f32,
    f: *const f32,
    z: *const f32,
    out: *mut f32,
) -> AmpmStatus {
    chat_z_ex::<Mat<f32, 2>>(opts, mu, f, z, out)
}

/// Computes Â for n particles, `out[i]` = Â(mu[i], F[i]), with a run-time choice of the polar method.
///
/// `opts`: method choice, NULL for the defaults (see `AmpmOptions`); an invalid choice gives `AMPM_ERR_INVALID_ARGUMENT`. `mu`: n values; `f`, `out`: n 2×2 column-major matrices, contiguous. Every valid particle is computed; a failed particle's output is untouched. Returns the first failure's status and writes its index (n if none) to `first_failed` (may be NULL). Arrays may be NULL when n = 0.
///
/// # Safety
/// `opts` is NULL or valid for one `AmpmOptions`; other non-null pointers must be valid for
/// the sizes above.
#[no_mangle]
pub unsafe extern "C" fn ampm_ahat_batch_ex_2d_f32(
    opts: *const AmpmOptions,
    n: usize,
    mu: *const f32,
    f: *const f32,
    out: *mut f32,
    first_failed: *mut usize,
) -> AmpmStatus {
    ahat_batch_ex::<Mat<f32, 2>>(opts, n, mu, f, out, first_failed)
}

/// Computes Ĉ:Z for n particles, `out[i]` = Ĉ(mu[i], F[i]):Z[i], with a run-time choice of the polar method.
///
/// `opts`: method choice, NULL for the defaults (see `AmpmOptions`); an invalid choice gives `AMPM_ERR_INVALID_ARGUMENT`. `mu`: n values; `f`, `z`, `out`: n 2×2 column-major matrices, contiguous. Every valid particle is computed; a failed particle's output is untouched. Returns the first failure's status and writes its index (n if none) to `first_failed` (may be NULL). Arrays may be NULL when n = 0.
///
/// # Safety
/// `opts` is NULL or valid for one `AmpmOptions`; other non-null pointers must be valid for
/// the sizes above.
#[no_mangle]
pub unsafe extern "C" fn ampm_chat_z_batch_ex_2d_f32(
    opts: *const AmpmOptions,
    n: usize,
    mu: *const f32,
    f: *const f32,
    z: *const f32,
    out: *mut f32,
    first_failed: *mut usize,
) -> AmpmStatus {
    chat_z_batch_ex::<Mat<f32, 2>>(opts, n, mu, f, z, out, first_failed)
}

/// Computes the rotation-variant SVD F = U diag(σ) Vᵀ: U, V rotations (det +1), σ sorted by decreasing magnitude, only σ[1] may be negative (sign of det F).
///
/// `opts`: method choice, NULL for the defaults (see `AmpmOptions`); an invalid choice gives `AMPM_ERR_INVALID_ARGUMENT`. `f`: 2×2 column-major, any finite F (det F ≤ 0 included); `u`, `v`: 2×2 outputs; `sigma`: 2 values. All written only on `AMPM_OK`.
///
/// # Safety
/// `opts` is NULL or valid for one `AmpmOptions`; other non-null pointers must be valid for
/// the sizes above.
#[no_mangle]
pub unsafe extern "C" fn ampm_svd_2d_f32(
    opts: *const AmpmOptions,
    f: *const f32,
    u: *mut f32,
    sigma: *mut f32,
    v: *mut f32,
) -> AmpmStatus {
    svd_ex::<Mat<f32, 2>>(opts, f, u, sigma, v)
}

/// Computes the rotation-variant polar decomposition F = R S: R = U Vᵀ a rotation (det +1), S = V Σ Vᵀ symmetric (indefinite when det F < 0).
///
/// `opts`: method choice, NULL for the defaults (see `AmpmOptions`); an invalid choice gives `AMPM_ERR_INVALID_ARGUMENT`. `f`: 2×2 column-major, any finite F (det F ≤ 0 included); `r`, `s`: 2×2 outputs, written only on `AMPM_OK`.
///
/// # Safety
/// `opts` is NULL or valid for one `AmpmOptions`; other non-null pointers must be valid for
/// the sizes above.
#[no_mangle]
pub unsafe extern "C" fn ampm_polar_2d_f32(
    opts: *const AmpmOptions,
    f: *const f32,
    r: *mut f32,
    s: *mut f32,
) -> AmpmStatus {
    polar_ex::<Mat<f32, 2>>(opts, f, r, s)
}

/// Computes Ψ̂(F) = μ‖F̂ − R̂‖², F̂ = J^(-1/2) F, with a run-time choice of the polar method.
///
/// `opts`: method choice, NULL for the defaults (see `AmpmOptions`); an invalid choice gives `AMPM_ERR_INVALID_ARGUMENT`. `mu` ≥ 0 (Pa); `f`: 2×2 column-major; `out[0]` receives Ψ̂ (J/m³), only on `AMPM_OK`.
///
/// # Safety
/// `opts` is NULL or valid for one `AmpmOptions`; other non-null pointers must be valid for
/// the sizes above.
#[no_mangle]
pub unsafe extern "C" fn ampm_energy_hat_ex_2d_f64(
    opts: *const AmpmOptions,
    mu: f64,
    f: *const f64,
    out: *mut f64,
) -> AmpmStatus {
    energy_hat_ex::<Mat<f64, 2>>(opts, mu, f, out)
}

/// Computes Â = ∂Ψ̂/∂F (volume-preserving fixed corotated) with a run-time choice of the polar method.
///
/// `opts`: method choice, NULL for the defaults (see `AmpmOptions`); an invalid choice gives `AMPM_ERR_INVALID_ARGUMENT`. `mu` ≥ 0 (Pa); `f`: 2×2 column-major; `out`: 2×2 stress (Pa), written only on `AMPM_OK`.
///
/// # Safety
/// `opts` is NULL or valid for one `AmpmOptions`; other non-null pointers must be valid for
/// the sizes above.
#[no_mangle]
pub unsafe extern "C" fn ampm_ahat_ex_2d_f64(
    opts: *const AmpmOptions,
    mu: f64,
    f: *const f64,
    out: *mut f64,
) -> AmpmStatus {
    ahat_ex::<Mat<f64, 2>>(opts, mu, f, out)
}

/// Computes Ĉ:Z, the Hessian action of the volume-preserving fixed corotated energy, with a run-time choice of the polar method.
///
/// `opts`: method choice, NULL for the defaults (see `AmpmOptions`); an invalid choice gives `AMPM_ERR_INVALID_ARGUMENT`. `mu` ≥ 0 (Pa); `f`, `z`: 2×2 column-major; `out`: 2×2, written only on `AMPM_OK`.
///
/// # Safety
/// `opts` is NULL or valid for one `AmpmOptions`; other non-null pointers must be valid for
/// the sizes above.
#[no_mangle]
pub unsafe extern "C" fn ampm_chat_z_ex_2d_f64(
    opts: *const AmpmOptions,
    mu: f64,
    f: *const f64,
    z: *const f64,
    out: *mut f64,
) -> AmpmStatus {
    chat_z_ex::<Mat<f64, 2>>(opts, mu, f, z, out)
}

/// Computes Â for n particles, `out[i]` = Â(mu[i], F[i]), with a run-time choice of the polar method.
///
/// `opts`: method choice, NULL for the defaults (see `AmpmOptions`); an invalid choice gives `AMPM_ERR_INVALID_ARGUMENT`. `mu`: n values; `f`, `out`: n 2×2 column-major matrices, contiguous. Every valid particle is computed; a failed particle's output is untouched. Returns the first failure's status and writes its index (n if none) to `first_failed` (may be NULL). Arrays may be NULL when n = 0.
///
/// # Safety
/// `opts` is NULL or valid for one `AmpmOptions`; other non-null pointers must be valid for
/// the sizes above.
#[no_mangle]
pub unsafe extern "C" fn ampm_ahat_batch_ex_2d_f64(
    opts: *const AmpmOptions,
    n: usize,
    mu: *const f64,
    f: *const f64,
    out: *mut f64,
    first_failed: *mut usize,
) -> AmpmStatus {
    ahat_batch_ex::<Mat<f64, 2>>(opts, n, mu, f, out, first_failed)
}

/// Computes Ĉ:Z for n particles, `out[i]` = Ĉ(mu[i], F[i]):Z[i], with a run-time choice of the polar method.
///
/// `opts`: method choice, NULL for the defaults (see `AmpmOptions`); an invalid choice gives `AMPM_ERR_INVALID_ARGUMENT`. `mu`: n values; `f`, `z`, `out`: n 2×2 column-major matrices, contiguous. Every valid particle is computed; a failed particle's output is untouched. Returns the first failure's status and writes its index (n if none) to `first_failed` (may be NULL). Arrays may be NULL when n = 0.
///
/// # Safety
/// `opts` is NULL or valid for one `AmpmOptions`; other non-null pointers must be valid for
/// the sizes above.
#[no_mangle]
pub unsafe extern "C" fn ampm_chat_z_batch_ex_2d_f64(
    opts: *const AmpmOptions,
    n: usize,
    mu: *const f64,
    f: *const f64,
    z: *const f64,
    out: *mut f64,
    first_failed: *mut usize,
) -> AmpmStatus {
    chat_z_batch_ex::<Mat<f64, 2>>(opts, n, mu, f, z, out, first_failed)
}

/// Computes the rotation-variant SVD F = U diag(σ) Vᵀ: U, V rotations (det +1), σ sorted by decreasing magnitude, only σ[1] may be negative (sign of det F).
///
/// `opts`: method choice, NULL for the defaults (see `AmpmOptions`); an invalid choice gives `AMPM_ERR_INVALID_ARGUMENT`. `f`: 2×2 column-major, any finite F (det F ≤ 0 included); `u`, `v`: 2×2 outputs; `sigma`: 2 values. All written only on `AMPM_OK`.
///
/// # Safety
/// `opts` is NULL or valid for one `AmpmOptions`; other non-null pointers must be valid for
/// the sizes above.
#[no_mangle]
pub unsafe extern "C" fn ampm_svd_2d_f64(
    opts: *const AmpmOptions,
    f: *const f64,
    u: *mut f64,
    sigma: *mut f64,
    v: *mut f64,
) -> AmpmStatus {
    svd_ex::<Mat<f64, 2>>(opts, f, u, sigma, v)
}

/// Computes the rotation-variant polar decomposition F = R S: R = U Vᵀ a rotation (det +1), S = V Σ Vᵀ symmetric (indefinite when det F < 0).
///
/// `opts`: method choice, NULL for the defaults (see `AmpmOptions`); an invalid choice gives `AMPM_ERR_INVALID_ARGUMENT`. `f`: 2×2 column-major, any finite F (det F ≤ 0 included); `r`, `s`: 2×2 outputs, written only on `AMPM_OK`.
///
/// # Safety
/// `opts` is NULL or valid for one `AmpmOptions`; other non-null pointers must be valid for
/// the sizes above.
#[no_mangle]
pub unsafe extern "C" fn ampm_polar_2d_f64(
    opts: *const AmpmOptions,
    f: *const f64,
    r: *mut f64,
    s: *mut f64,
) -> AmpmStatus {
    polar_ex::<Mat<f64, 2>>(opts, f, r, s)
}

/// Computes Ψ̂(F) = μ‖F̂ − R̂‖², F̂ = J^(-1/3) F, with a run-time choice of the polar method.
///
/// `opts`: method choice, NULL for the defaults (see `AmpmOptions`); an invalid choice gives `AMPM_ERR_INVALID_ARGUMENT`. `mu` ≥ 0 (Pa); `f`: 3×3 column-major; `out[0]` receives Ψ̂ (J/m³), only on `AMPM_OK`.
///
/// # Safety
/// `opts` is NULL or valid for one `AmpmOptions`; other non-null pointers must be valid for
/// the sizes above.
#[no_mangle]
pub unsafe extern "C" fn ampm_energy_hat_ex_3d_f32(
    opts: *const AmpmOptions,
    mu: f32,
    f: *const f32,
    out: *mut f32,
) -> AmpmStatus {
    energy_hat_ex::<Mat<f32, 3>>(opts, mu, f, out)
}

/// Computes Â = ∂Ψ̂/∂F (volume-preserving fixed corotated) with a run-time choice of the polar method.
///
/// `opts`: method choice, NULL for the defaults (see `AmpmOptions`); an invalid choice gives `AMPM_ERR_INVALID_ARGUMENT`. `mu` ≥ 0 (Pa); `f`: 3×3 column-major; `out`: 3×3 stress (Pa), written only on `AMPM_OK`.
///
/// # Safety
/// `opts` is NULL or valid for one `AmpmOptions`; other non-null pointers must be valid for
/// the sizes above.
#[no_mangle]
pub unsafe extern "C" fn ampm_ahat_ex_3d_f32(
    opts: *const AmpmOptions,
    mu: f32,
    f: *const f32,
    out: *mut f32,
) -> AmpmStatus {
    ahat_ex::<Mat<f32, 3>>(opts, mu, f, out)
}

/// Computes Ĉ:Z, the Hessian action of the volume-preserving fixed corotated energy, with a run-time choice of the polar method.
///
/// `opts`: method choice, NULL for the defaults (see `AmpmOptions`); an invalid choice gives `AMPM_ERR_INVALID_ARGUMENT`. `mu` ≥ 0 (Pa); `f`, `z`: 3×3 column-major; `out`: 3×3, written only on `AMPM_OK`.
///
/// # Safety
/// `opts` is NULL or valid for one `AmpmOptions`; other non-null pointers must be valid for
/// the sizes above.
#[no_mangle]
pub unsafe extern "C" fn ampm_chat_z_ex_3d_f32(
    opts: *const AmpmOptions,
    mu: f32,
    f: *const f32,
    z: *const f32,
    out: *mut f32,
) -> AmpmStatus {
    chat_z_ex::<Mat<f32, 3>>(opts, mu, f, z, out)
}

/// Computes Â for n particles, `out[i]` = Â(mu[i], F[i]), with a run-time choice of the polar method.
///
/// `opts`: method choice, NULL for the defaults (see `AmpmOptions`); an invalid choice gives `AMPM_ERR_INVALID_ARGUMENT`. `mu`: n values; `f`, `out`: n 3×3 column-major matrices, contiguous. Every valid particle is computed; a failed particle's output is untouched. Returns the first failure's status and writes its index (n if none) to `first_failed` (may be NULL). Arrays may be NULL when n = 0.
///
/// # Safety
/// `opts` is NULL or valid for one `AmpmOptions`; other non-null pointers must be valid for
/// the sizes above.
#[no_mangle]
pub unsafe extern "C" fn ampm_ahat_batch_ex_3d_f32(
    opts: *const AmpmOptions,
    n: usize,
    mu: *const f32,
    f: *const f32,
    out: *mut f32,
    first_failed: *mut usize,
) -> AmpmStatus {
    ahat_batch_ex::<Mat<f32, 3>>(opts, n, mu, f, out, first_failed)
}

/// Computes Ĉ:Z for n particles, `out[i]` = Ĉ(mu[i], F[i]):Z[i], with a run-time choice of the polar method.
///
/// `opts`: method choice, NULL for the defaults (see `AmpmOptions`); an invalid choice gives `AMPM_ERR_INVALID_ARGUMENT`. `mu`: n values; `f`, `z`, `out`: n 3×3 column-major matrices, contiguous. Every valid particle is computed; a failed particle's output is untouched. Returns the first failure's status and writes its index (n if none) to `first_failed` (may be NULL). Arrays may be NULL when n = 0.
///
/// # Safety
/// `opts` is NULL or valid for one `AmpmOptions`; other non-null pointers must be valid for
/// the sizes above.
#[no_mangle]
pub unsafe extern "C" fn ampm_chat_z_batch_ex_3d_f32(
    opts: *const AmpmOptions,
    n: usize,
    mu: *const f32,
    f: *const f32,
    z: *const f32,
    out: *mut f32,
    first_failed: *mut usize,
) -> AmpmStatus {
    chat_z_batch_ex::<Mat<f32, 3>>(opts, n, mu, f, z, out, first_failed)
}

/// Computes the rotation-variant SVD F = U diag(σ) Vᵀ: U, V rotations (det +1), σ sorted by decreasing magnitude, only σ[2] may be negative (sign of det F).
///
/// `opts`: method choice, NULL for the defaults (see `AmpmOptions`); an invalid choice gives `AMPM_ERR_INVALID_ARGUMENT`. `f`: 3×3 column-major, any finite F (det F ≤ 0 included); `u`, `v`: 3×3 outputs; `sigma`: 3 values. All written only on `AMPM_OK`.
///
/// # Safety
/// `opts` is NULL or valid for one `AmpmOptions`; other non-null pointers must be valid for
/// the sizes above.
#[no_mangle]
pub unsafe extern "C" fn ampm_svd_3d_f32(
    opts: *const AmpmOptions,
    f: *const f32,
    u: *mut f32,
    sigma: *mut f32,
    v: *mut f32,
) -> AmpmStatus {
    svd_ex::<Mat<f32, 3>>(opts, f, u, sigma, v)
}

/// Computes the rotation-variant polar decomposition F = R S: R = U Vᵀ a rotation (det +1), S = V Σ Vᵀ symmetric (indefinite when det F < 0).
///
/// `opts`: method choice, NULL for the defaults (see `AmpmOptions`); an invalid choice gives `AMPM_ERR_INVALID_ARGUMENT`. `f`: 3×3 column-major, any finite F (det F ≤ 0 included); `r`, `s`: 3×3 outputs, written only on `AMPM_OK`.
///
/// # Safety
/// `opts` is NULL or valid for one `AmpmOptions`; other non-null pointers must be valid for
/// the sizes above.
#[no_mangle]
pub unsafe extern "C" fn ampm_polar_3d_f32(
    opts: *const AmpmOptions,
    f: *const f32,
    r: *mut f32,
    s: *mut f32,
) -> AmpmStatus {
    polar_ex::<Mat<f32, 3>>(opts, f, r, s)
}

/// Computes Ψ̂(F) = μ‖F̂ − R̂‖², F̂ = J^(-1/3) F, with a run-time choice of the polar method.
///
/// `opts`: method choice, NULL for the defaults (see `AmpmOptions`); an invalid choice gives `AMPM_ERR_INVALID_ARGUMENT`. `mu` ≥ 0 (Pa); `f`: 3×3 column-major; `out[0]` receives Ψ̂ (J/m³), only on `AMPM_OK`.
///
/// # Safety
/// `opts` is NULL or valid for one `AmpmOptions`; other non-null pointers must be valid for
/// the sizes above.
#[no_mangle]
pub unsafe extern "C" fn ampm_energy_hat_ex_3d_f64(
    opts: *const AmpmOptions,
    mu: f64,
    f: *const f64,
    out: *mut f64,
) -> AmpmStatus {
    energy_hat_ex::<Mat<f64, 3>>(opts, mu, f, out)
}

/// Computes Â = ∂Ψ̂/∂F (volume-preserving fixed corotated) with a run-time choice of the polar method.
///
/// `opts`: method choice, NULL for the defaults (see `AmpmOptions`); an invalid choice gives `AMPM_ERR_INVALID_ARGUMENT`. `mu` ≥ 0 (Pa); `f`: 3×3 column-major; `out`: 3×3 stress (Pa), written only on `AMPM_OK`.
///
/// # Safety
/// `opts` is NULL or valid for one `AmpmOptions`; other non-null pointers must be valid for
/// the sizes above.
#[no_mangle]
pub unsafe extern "C" fn ampm_ahat_ex_3d_f64(
    opts: *const AmpmOptions,
    mu: f64,
    f: *const f64,
    out: *mut f64,
) -> AmpmStatus {
    ahat_ex::<Mat<f64, 3>>(opts, mu, f, out)
}

/// Computes Ĉ:Z, the Hessian action of the volume-preserving fixed corotated energy, with a run-time choice of the polar method.
///
/// `opts`: method choice, NULL for the defaults (see `AmpmOptions`); an invalid choice gives `AMPM_ERR_INVALID_ARGUMENT`. `mu` ≥ 0 (Pa); `f`, `z`: 3×3 column-major; `out`: 3×3, written only on `AMPM_OK`.
///
/// # Safety
/// `opts` is NULL or valid for one `AmpmOptions`; other non-null pointers must be valid for
/// the sizes above.
#[no_mangle]
pub unsafe extern "C" fn ampm_chat_z_ex_3d_f64(
    opts: *const AmpmOptions,
    mu: f64,
    f: *const f64,
    z: *const f64,
    out: *mut f64,
) -> AmpmStatus {
    chat_z_ex::<Mat<f64, 3>>(opts, mu, f, z, out)
}

/// Computes Â for n particles, `out[i]` = Â(mu[i], F[i]), with a run-time choice of the polar method.
///
/// `opts`: method choice, NULL for the defaults (see `AmpmOptions`); an invalid choice gives `AMPM_ERR_INVALID_ARGUMENT`. `mu`: n values; `f`, `out`: n 3×3 column-major matrices, contiguous. Every valid particle is computed; a failed particle's output is untouched. Returns the first failure's status and writes its index (n if none) to `first_failed` (may be NULL). Arrays may be NULL when n = 0.
///
/// # Safety
/// `opts` is NULL or valid for one `AmpmOptions`; other non-null pointers must be valid for
/// the sizes above.
#[no_mangle]
pub unsafe extern "C" fn ampm_ahat_batch_ex_3d_f64(
    opts: *const AmpmOptions,
    n: usize,
    mu: *const f64,
    f: *const f64,
    out: *mut f64,
    first_failed: *mut usize,
) -> AmpmStatus {
    ahat_batch_ex::<Mat<f64, 3>>(opts, n, mu, f, out, first_failed)
}

/// Computes Ĉ:Z for n particles, `out[i]` = Ĉ(mu[i], F[i]):Z[i], with a run-time choice of the polar method.
///
/// `opts`: method choice, NULL for the defaults (see `AmpmOptions`); an invalid choice gives `AMPM_ERR_INVALID_ARGUMENT`. `mu`: n values; `f`, `z`, `out`: n 3×3 column-major matrices, contiguous. Every valid particle is computed; a failed particle's output is untouched. Returns the first failure's status and writes its index (n if none) to `first_failed` (may be NULL). Arrays may be NULL when n = 0.
///
/// # Safety
/// `opts` is NULL or valid for one `AmpmOptions`; other non-null pointers must be valid for
/// the sizes above.
#[no_mangle]
pub unsafe extern "C" fn ampm_chat_z_batch_ex_3d_f64(
    opts: *const AmpmOptions,
    n: usize,
    mu: *const f64,
    f: *const f64,
    z: *const f64,
    out: *mut f64,
    first_failed: *mut usize,
) -> AmpmStatus {
    chat_z_batch_ex::<Mat<f64, 3>>(opts, n, mu, f, z, out, first_failed)
}

/// Computes the rotation-variant SVD F = U diag(σ) Vᵀ: U, V rotations (det +1), σ sorted by decreasing magnitude, only σ[2] may be negative (sign of det F).
///
/// `opts`: method choice, NULL for the defaults (see `AmpmOptions`); an invalid choice gives `AMPM_ERR_INVALID_ARGUMENT`. `f`: 3×3 column-major, any finite F (det F ≤ 0 included); `u`, `v`: 3×3 outputs; `sigma`: 3 values. All written only on `AMPM_OK`.
///
/// # Safety
/// `opts` is NULL or valid for one `AmpmOptions`; other non-null pointers must be valid for
/// the sizes above.
#[no_mangle]
pub unsafe extern "C" fn ampm_svd_3d_f64(
    opts: *const AmpmOptions,
    f: *const f64,
    u: *mut f64,
    sigma: *mut f64,
    v: *mut f64,
) -> AmpmStatus {
    svd_ex::<Mat<f64, 3>>(opts, f, u, sigma, v)
}

/// Computes the rotation-variant polar decomposition F = R S: R = U Vᵀ a rotation (det +1), S = V Σ Vᵀ symmetric (indefinite when det F < 0).
///
/// `opts`: method choice, NULL for the defaults (see `AmpmOptions`); an invalid choice gives `AMPM_ERR_INVALID_ARGUMENT`. `f`: 3×3 column-major, any finite F (det F ≤ 0 included); `r`, `s`: 3×3 outputs, written only on `AMPM_OK`.
///
/// # Safety
/// `opts` is NULL or valid for one `AmpmOptions`; other non-null pointers must be valid for
/// the sizes above.
#[no_mangle]
pub unsafe extern "C" fn ampm_polar_3d_f64(
    opts: *const AmpmOptions,
    f: *const f64,
    r: *mut f64,
    s: *mut f64,
) -> AmpmStatus {
    polar_ex::<Mat<f64, 3>>(opts, f, r, s)
}
