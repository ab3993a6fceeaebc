//! C entry points of the Hessian matrices and the PSD-projected action.
//!
//! For every dimension × precision: `ampm_chat_z_psd_<d>_<p>` (Ĉ⁺:Z), its batch form, and
//! the explicit d²×d² matrices `ampm_chat_matrix_<d>_<p>` (Ĉ) and
//! `ampm_chat_psd_matrix_<d>_<p>` (Ĉ⁺), fixed corotated base energy, default SVD method.
//! Each `extern "C"` wrapper is written out (cbindgen does not expand macros) and delegates
//! to one generic body in [`imp`], which uses the helpers of `abi.rs`.
#![allow(clippy::missing_safety_doc)]

use crate::status::AmpmStatus;
use ampm_core::Mat;
use core::ptr;

/// Generic bodies of the entry points of this module.
mod imp {
    use crate::abi::{guard, read_mat};
    use crate::status::AmpmStatus;
    use ampm_core::energy::FixedCorotated;
    use ampm_core::hessian::{self, HessianDim};
    use ampm_core::polar::{DefaultSvd, SvdMethod};
    use ampm_core::Error;
    use core::ptr;

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

    pub(super) unsafe fn chat_matrix<M: HessianDim>(
        mu: M::Scalar,
        f: *const M::Scalar,
        out: *mut M::Scalar,
    ) -> AmpmStatus
    where
        DefaultSvd: SvdMethod<M>,
    {
        wide_unary::<M>(mu, f, out, |e, f| hessian::chat_matrix(e, f))
    }

    pub(super) unsafe fn chat_psd_matrix<M: HessianDim>(
        mu: M::Scalar,
        f: *const M::Scalar,
        out: *mut M::Scalar,
    ) -> AmpmStatus
    where
        DefaultSvd: SvdMethod<M>,
    {
        wide_unary::<M>(mu, f, out, |e, f| hessian::chat_psd_matrix(e, f))
    }
}

/// Computes Ĉ⁺:Z, the action of the Hessian of Ψ̂ (fixed corotated, a = −1/2) with its negative eigenvalues clamped to zero (Smith, de Goes, Kim 2019 eigensystem in the SVD basis of F). Use it as the (PSD) operator of a Newton/Krylov solve.
///
/// `mu` ≥ 0; `f`, `z`: 2×2 column-major inputs; `out`: 2×2 output, written only on `AMPM_OK` (may alias `z` exactly).
///
/// # Safety
/// Non-null pointers must be valid for the sizes above.
#[no_mangle]
pub unsafe extern "C" fn ampm_chat_z_psd_2d_f32(
    mu: f32,
    f: *const f32,
    z: *const f32,
    out: *mut f32,
) -> AmpmStatus {
    crate::fast::single::<f32, 2>(mu, f, z, ptr::null_mut(), out, ptr::null_mut(), true)
}

/// Computes Ĉ⁺:Z for n particles: `out[i]` = Ĉ⁺(mu[i], F[i]):Z[i].
///
/// `mu`: n values; `f`, `z`, `out`: n 2×2 column-major matrices, contiguous. Every valid particle is computed; a failed particle's output is untouched. Returns the first failure's status and writes its index (n if none) to `first_failed` (may be NULL). Arrays may be NULL when n = 0.
///
/// # Safety
/// Non-null pointers must be valid for the sizes above.
#[no_mangle]
pub unsafe extern "C" fn ampm_chat_z_psd_batch_2d_f32(
    n: usize,
    mu: *const f32,
    f: *const f32,
    z: *const f32,
    out: *mut f32,
    first_failed: *mut usize,
) -> AmpmStatus {
    crate::fast::kernels::<f32, 2>(
        crate::fast::isa(),
        n,
        mu,
        f,
        z,
        ptr::null_mut(),
        out,
        ptr::null_mut(),
        true,
        first_failed,
    )
}

/// Computes the explicit 4×4 Hessian Ĉ of Ψ̂ (fixed corotated, a = −1/2), symmetric and in general indefinite.
///
/// Convention: vec(Z)[i + 2*j] = Z_ij (column-major), so vec(Ĉ:Z) = Ĉ · vec(Z); `out[p + 4*q]` = Ĉ[p][q] (column-major; Ĉ is symmetric). `mu` ≥ 0; `f`: 2×2 column-major input; `out`: 16 scalars, written only on `AMPM_OK`.
///
/// # Safety
/// Non-null pointers must be valid for the sizes above.
#[no_mangle]
pub unsafe extern "C" fn ampm_chat_matrix_2d_f32(
    mu: f32,
    f: *const f32,
    out: *mut f32,
) -> AmpmStatus {
    imp::chat_matrix::<Mat<f32, 2>>(mu, f, out)
}

/// Computes the explicit 4×4 PSD projection Ĉ⁺ of the Hessian of Ψ̂ (negative eigenvalues clamped to zero; the nearest PSD matrix to Ĉ in the Frobenius norm).
///
/// Same convention as `ampm_chat_matrix_2d_f32`: `out[p + 4*q]` = Ĉ⁺[p][q], vec(Ĉ⁺:Z) = Ĉ⁺ · vec(Z) with vec(Z)[i + 2*j] = Z_ij. `mu` ≥ 0; `f`: 2×2 column-major input; `out`: 16 scalars, written only on `AMPM_OK`.
///
/// # Safety
/// Non-null pointers must be valid for the sizes above.
#[no_mangle]
pub unsafe extern "C" fn ampm_chat_psd_matrix_2d_f32(
    mu: f32,
    f: *const f32,
    out: *mut f32,
) -> AmpmStatus {
    imp::chat_psd_matrix::<Mat<f32, 2>>(mu, f, out)
}

/// Computes Ĉ⁺:Z, the action of the Hessian of Ψ̂ (fixed corotated, a = −1/2) with its negative eigenvalues clamped to zero (Smith, de Goes, Kim 2019 eigensystem in the SVD basis of F). Use it as the (PSD) operator of a Newton/Krylov solve.
///
/// `mu` ≥ 0; `f`, `z`: 2×2 column-major inputs; `out`: 2×2 output, written only on `AMPM_OK` (may alias `z` exactly).
///
/// # Safety
/// Non-null pointers must be valid for the sizes above.
#[no_mangle]
pub unsafe extern "C" fn ampm_chat_z_psd_2d_f64(
    mu: f64,
    f: *const f64,
    z: *const f64,
    out: *mut f64,
) -> AmpmStatus {
    crate::fast::single::<f64, 2>(mu, f, z, ptr::null_mut(), out, ptr::null_mut(), true)
}

/// Computes Ĉ⁺:Z for n particles: `out[i]` = Ĉ⁺(mu[i], F[i]):Z[i].
///
/// `mu`: n values; `f`, `z`, `out`: n 2×2 column-major matrices, contiguous. Every valid particle is computed; a failed particle's output is untouched. Returns the first failure's status and writes its index (n if none) to `first_failed` (may be NULL). Arrays may be NULL when n = 0.
///
/// # Safety
/// Non-null pointers must be valid for the sizes above.
#[no_mangle]
pub unsafe extern "C" fn ampm_chat_z_psd_batch_2d_f64(
    n: usize,
    mu: *const f64,
    f: *const f64,
    z: *const f64,
    out: *mut f64,
    first_failed: *mut usize,
) -> AmpmStatus {
    crate::fast::kernels::<f64, 2>(
        crate::fast::isa(),
        n,
        mu,
        f,
        z,
        ptr::null_mut(),
        out,
        ptr::null_mut(),
        true,
        first_failed,
    )
}

/// Computes the explicit 4×4 Hessian Ĉ of Ψ̂ (fixed corotated, a = −1/2), symmetric and in general indefinite.
///
/// Convention: vec(Z)[i + 2*j] = Z_ij (column-major), so vec(Ĉ:Z) = Ĉ · vec(Z); `out[p + 4*q]` = Ĉ[p][q] (column-major; Ĉ is symmetric). `mu` ≥ 0; `f`: 2×2 column-major input; `out`: 16 scalars, written only on `AMPM_OK`.
///
/// # Safety
/// Non-null pointers must be valid for the sizes above.
#[no_mangle]
pub unsafe extern "C" fn ampm_chat_matrix_2d_f64(
    mu: f64,
    f: *const f64,
    out: *mut f64,
) -> AmpmStatus {
    imp::chat_matrix::<Mat<f64, 2>>(mu, f, out)
}

/// Computes the explicit 4×4 PSD projection Ĉ⁺ of the Hessian of Ψ̂ (negative eigenvalues clamped to zero; the nearest PSD matrix to Ĉ in the Frobenius norm).
///
/// Same convention as `ampm_chat_matrix_2d_f64`: `out[p + 4*q]` = Ĉ⁺[p][q], vec(Ĉ⁺:Z) = Ĉ⁺ · vec(Z) with vec(Z)[i + 2*j] = Z_ij. `mu` ≥ 0; `f`: 2×2 column-major input; `out`: 16 scalars, written only on `AMPM_OK`.
///
/// # Safety
/// Non-null pointers must be valid for the sizes above.
#[no_mangle]
pub unsafe extern "C" fn ampm_chat_psd_matrix_2d_f64(
    mu: f64,
    f: *const f64,
    out: *mut f64,
) -> AmpmStatus {
    imp::chat_psd_matrix::<Mat<f64, 2>>(mu, f, out)
}

/// Computes Ĉ⁺:Z, the action of the Hessian of Ψ̂ (fixed corotated, a = −1/3) with its negative eigenvalues clamped to zero (Smith, de Goes, Kim 2019 eigensystem in the SVD basis of F). Use it as the (PSD) operator of a Newton/Krylov solve.
///
/// `mu` ≥ 0; `f`, `z`: 3×3 column-major inputs; `out`: 3×3 output, written only on `AMPM_OK` (may alias `z` exactly).
///
/// # Safety
/// Non-null pointers must be valid for the sizes above.
#[no_mangle]
pub unsafe extern "C" fn ampm_chat_z_psd_3d_f32(
    mu: f32,
    f: *const f32,
    z: *const f32,
    out: *mut f32,
) -> AmpmStatus {
    crate::fast::single::<f32, 3>(mu, f, z, ptr::null_mut(), out, ptr::null_mut(), true)
}

/// Computes Ĉ⁺:Z for n particles: `out[i]` = Ĉ⁺(mu[i], F[i]):Z[i].
///
/// `mu`: n values; `f`, `z`, `out`: n 3×3 column-major matrices, contiguous. Every valid particle is computed; a failed particle's output is untouched. Returns the first failure's status and writes its index (n if none) to `first_failed` (may be NULL). Arrays may be NULL when n = 0.
///
/// # Safety
/// Non-null pointers must be valid for the sizes above.
#[no_mangle]
pub unsafe extern "C" fn ampm_chat_z_psd_batch_3d_f32(
    n: usize,
    mu: *const f32,
    f: *const f32,
    z: *const f32,
    out: *mut f32,
    first_failed: *mut usize,
) -> AmpmStatus {
    crate::fast::kernels::<f32, 3>(
        crate::fast::isa(),
        n,
        mu,
        f,
        z,
        ptr::null_mut(),
        out,
        ptr::null_mut(),
        true,
        first_failed,
    )
}

/// Computes the explicit 9×9 Hessian Ĉ of Ψ̂ (fixed corotated, a = −1/3), symmetric and in general indefinite.
///
/// Convention: vec(Z)[i + 3*j] = Z_ij (column-major), so vec(Ĉ:Z) = Ĉ · vec(Z); `out[p + 9*q]` = Ĉ[p][q] (column-major; Ĉ is symmetric). `mu` ≥ 0; `f`: 3×3 column-major input; `out`: 81 scalars, written only on `AMPM_OK`.
///
/// # Safety
/// Non-null pointers must be valid for the sizes above.
#[no_mangle]
pub unsafe extern "C" fn ampm_chat_matrix_3d_f32(
    mu: f32,
    f: *const f32,
    out: *mut f32,
) -> AmpmStatus {
    imp::chat_matrix::<Mat<f32, 3>>(mu, f, out)
}

/// Computes the explicit 9×9 PSD projection Ĉ⁺ of the Hessian of Ψ̂ (negative eigenvalues clamped to zero; the nearest PSD matrix to Ĉ in the Frobenius norm).
///
/// Same convention as `ampm_chat_matrix_3d_f32`: `out[p + 9*q]` = Ĉ⁺[p][q], vec(Ĉ⁺:Z) = Ĉ⁺ · vec(Z) with vec(Z)[i + 3*j] = Z_ij. `mu` ≥ 0; `f`: 3×3 column-major input; `out`: 81 scalars, written only on `AMPM_OK`.
///
/// # Safety
/// Non-null pointers must be valid for the sizes above.
#[no_mangle]
pub unsafe extern "C" fn ampm_chat_psd_matrix_3d_f32(
    mu: f32,
    f: *const f32,
    out: *mut f32,
) -> AmpmStatus {
    imp::chat_psd_matrix::<Mat<f32, 3>>(mu, f, out)
}

/// Computes Ĉ⁺:Z, the action of the Hessian of Ψ̂ (fixed corotated, a = −1/3) with its negative eigenvalues clamped to zero (Smith, de Goes, Kim 2019 eigensystem in the SVD basis of F). Use it as the (PSD) operator of a Newton/Krylov solve.
///
/// `mu` ≥ 0; `f`, `z`: 3×3 column-major inputs; `out`: 3×3 output, written only on `AMPM_OK` (may alias `z` exactly).
///
/// # Safety
/// Non-null pointers must be valid for the sizes above.
#[no_mangle]
pub unsafe extern "C" fn ampm_chat_z_psd_3d_f64(
    mu: f64,
    f: *const f64,
    z: *const f64,
    out: *mut f64,
) -> AmpmStatus {
    crate::fast::single::<f64, 3>(mu, f, z, ptr::null_mut(), out, ptr::null_mut(), true)
}

/// Computes Ĉ⁺:Z for n particles: `out[i]` = Ĉ⁺(mu[i], F[i]):Z[i].
///
/// `mu`: n values; `f`, `z`, `out`: n 3×3 column-major matrices, contiguous. Every valid particle is computed; a failed particle's output is untouched. Returns the first failure's status and writes its index (n if none) to `first_failed` (may be NULL). Arrays may be NULL when n = 0.
///
/// # Safety
/// Non-null pointers must be valid for the sizes above.
#[no_mangle]
pub unsafe extern "C" fn ampm_chat_z_psd_batch_3d_f64(
    n: usize,
    mu: *const f64,
    f: *const f64,
    z: *const f64,
    out: *mut f64,
    first_failed: *mut usize,
) -> AmpmStatus {
    crate::fast::kernels::<f64, 3>(
        crate::fast::isa(),
        n,
        mu,
        f,
        z,
        ptr::null_mut(),
        out,
        ptr::null_mut(),
        true,
        first_failed,
    )
}

/// Computes the explicit 9×9 Hessian Ĉ of Ψ̂ (fixed corotated, a = −1/3), symmetric and in general indefinite.
///
/// Convention: vec(Z)[i + 3*j] = Z_ij (column-major), so vec(Ĉ:Z) = Ĉ · vec(Z); `out[p + 9*q]` = Ĉ[p][q] (column-major; Ĉ is symmetric). `mu` ≥ 0; `f`: 3×3 column-major input; `out`: 81 scalars, written only on `AMPM_OK`.
///
/// # Safety
/// Non-null pointers must be valid for the sizes above.
#[no_mangle]
pub unsafe extern "C" fn ampm_chat_matrix_3d_f64(
    mu: f64,
    f: *const f64,
    out: *mut f64,
) -> AmpmStatus {
    imp::chat_matrix::<Mat<f64, 3>>(mu, f, out)
}

/// Computes the explicit 9×9 PSD projection Ĉ⁺ of the Hessian of Ψ̂ (negative eigenvalues clamped to zero; the nearest PSD matrix to Ĉ in the Frobenius norm).
///
/// Same convention as `ampm_chat_matrix_3d_f64`: `out[p + 9*q]` = Ĉ⁺[p][q], vec(Ĉ⁺:Z) = Ĉ⁺ · vec(Z) with vec(Z)[i + 3*j] = Z_ij. `mu` ≥ 0; `f`: 3×3 column-major input; `out`: 81 scalars, written only on `AMPM_OK`.
///
/// # Safety
/// Non-null pointers must be valid for the sizes above.
#[no_mangle]
pub unsafe extern "C" fn ampm_chat_psd_matrix_3d_f64(
    mu: f64,
    f: *const f64,
    out: *mut f64,
) -> AmpmStatus {
    imp::chat_psd_matrix::<Mat<f64, 3>>(mu, f, out)
}
