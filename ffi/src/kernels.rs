//! The C entry points of the kernels: one thin wrapper per
//! op × dim × precision, each delegating to one generic body in `kernels_impl`.
//!
//! The wrappers are written out (not macro-generated) because cbindgen reads the source
//! without expanding macros; each carries the doc comment that reaches `ampm.h`.
#![allow(clippy::missing_safety_doc)]

use crate::fast;
use crate::kernels_impl as k;
use crate::status::AmpmStatus;
use ampm_core::Mat;
use core::ptr;

/// Computes 𝓑(F):Z = Jᵃ(Z + a(H:Z)F), a = −1/2, H = F⁻ᵀ, the derivative of JᵃF in direction Z.
///
/// `f`, `z`: 2×2 column-major inputs; `out`: 2×2 output, written only on `AMPM_OK`.
///
/// # Safety
/// Non-null pointers must be valid for the sizes above.
#[no_mangle]
pub unsafe extern "C" fn ampm_b_z_2d_f32(
    f: *const f32,
    z: *const f32,
    out: *mut f32,
) -> AmpmStatus {
    k::b_z::<Mat<f32, 2>>(f, z, out)
}

/// Computes 𝓑(F):Z = Jᵃ(Z + a(H:Z)F), a = −1/2, H = F⁻ᵀ, the derivative of JᵃF in direction Z.
///
/// `f`, `z`: 2×2 column-major inputs; `out`: 2×2 output, written only on `AMPM_OK`.
///
/// # Safety
/// Non-null pointers must be valid for the sizes above.
#[no_mangle]
pub unsafe extern "C" fn ampm_b_z_2d_f64(
    f: *const f64,
    z: *const f64,
    out: *mut f64,
) -> AmpmStatus {
    k::b_z::<Mat<f64, 2>>(f, z, out)
}

/// Computes 𝓑(F):Z = Jᵃ(Z + a(H:Z)F), a = −1/3, H = F⁻ᵀ, the derivative of JᵃF in direction Z.
///
/// `f`, `z`: 3×3 column-major inputs; `out`: 3×3 output, written only on `AMPM_OK`.
///
/// # Safety
/// Non-null pointers must be valid for the sizes above.
#[no_mangle]
pub unsafe extern "C" fn ampm_b_z_3d_f32(
    f: *const f32,
    z: *const f32,
    out: *mut f32,
) -> AmpmStatus {
    k::b_z::<Mat<f32, 3>>(f, z, out)
}

/// Computes 𝓑(F):Z = Jᵃ(Z + a(H:Z)F), a = −1/3, H = F⁻ᵀ, the derivative of JᵃF in direction Z.
///
/// `f`, `z`: 3×3 column-major inputs; `out`: 3×3 output, written only on `AMPM_OK`.
///
/// # Safety
/// Non-null pointers must be valid for the sizes above.
#[no_mangle]
pub unsafe extern "C" fn ampm_b_z_3d_f64(
    f: *const f64,
    z: *const f64,
    out: *mut f64,
) -> AmpmStatus {
    k::b_z::<Mat<f64, 3>>(f, z, out)
}

/// Computes Z:𝓑(F) = Jᵃ(Z + a(F:Z)H), a = −1/2, H = F⁻ᵀ (the adjoint action).
///
/// `f`, `z`: 2×2 column-major inputs; `out`: 2×2 output, written only on `AMPM_OK`.
///
/// # Safety
/// Non-null pointers must be valid for the sizes above.
#[no_mangle]
pub unsafe extern "C" fn ampm_z_b_2d_f32(
    f: *const f32,
    z: *const f32,
    out: *mut f32,
) -> AmpmStatus {
    k::z_b::<Mat<f32, 2>>(f, z, out)
}

/// Computes Z:𝓑(F) = Jᵃ(Z + a(F:Z)H), a = −1/2, H = F⁻ᵀ (the adjoint action).
///
/// `f`, `z`: 2×2 column-major inputs; `out`: 2×2 output, written only on `AMPM_OK`.
///
/// # Safety
/// Non-null pointers must be valid for the sizes above.
#[no_mangle]
pub unsafe extern "C" fn ampm_z_b_2d_f64(
    f: *const f64,
    z: *const f64,
    out: *mut f64,
) -> AmpmStatus {
    k::z_b::<Mat<f64, 2>>(f, z, out)
}

/// Computes Z:𝓑(F) = Jᵃ(Z + a(F:Z)H), a = −1/3, H = F⁻ᵀ (the adjoint action).
///
/// `f`, `z`: 3×3 column-major inputs; `out`: 3×3 output, written only on `AMPM_OK`.
///
/// # Safety
/// Non-null pointers must be valid for the sizes above.
#[no_mangle]
pub unsafe extern "C" fn ampm_z_b_3d_f32(
    f: *const f32,
    z: *const f32,
    out: *mut f32,
) -> AmpmStatus {
    k::z_b::<Mat<f32, 3>>(f, z, out)
}

/// Computes Z:𝓑(F) = Jᵃ(Z + a(F:Z)H), a = −1/3, H = F⁻ᵀ (the adjoint action).
///
/// `f`, `z`: 3×3 column-major inputs; `out`: 3×3 output, written only on `AMPM_OK`.
///
/// # Safety
/// Non-null pointers must be valid for the sizes above.
#[no_mangle]
pub unsafe extern "C" fn ampm_z_b_3d_f64(
    f: *const f64,
    z: *const f64,
    out: *mut f64,
) -> AmpmStatus {
    k::z_b::<Mat<f64, 3>>(f, z, out)
}

/// Computes Ψ̂(F) = μ‖F̂ − R̂‖², F̂ = J^(−1/2) F: the fixed corotated energy density of the volume-preserving part.
///
/// `mu` ≥ 0 (Pa); `f`: 2×2 column-major; `out[0]` receives Ψ̂ (J/m³), only on `AMPM_OK`.
///
/// # Safety
/// Non-null pointers must be valid for the sizes above.
#[no_mangle]
pub unsafe extern "C" fn ampm_energy_hat_2d_f32(
    mu: f32,
    f: *const f32,
    out: *mut f32,
) -> AmpmStatus {
    fast::single::<f32, 2>(
        mu,
        f,
        ptr::null(),
        ptr::null_mut(),
        ptr::null_mut(),
        out,
        false,
    )
}

/// Computes Ψ̂(F) = μ‖F̂ − R̂‖², F̂ = J^(−1/2) F: the fixed corotated energy density of the volume-preserving part.
///
/// `mu` ≥ 0 (Pa); `f`: 2×2 column-major; `out[0]` receives Ψ̂ (J/m³), only on `AMPM_OK`.
///
/// # Safety
/// Non-null pointers must be valid for the sizes above.
#[no_mangle]
pub unsafe extern "C" fn ampm_energy_hat_2d_f64(
    mu: f64,
    f: *const f64,
    out: *mut f64,
) -> AmpmStatus {
    fast::single::<f64, 2>(
        mu,
        f,
        ptr::null(),
        ptr::null_mut(),
        ptr::null_mut(),
        out,
        false,
    )
}

/// Computes Ψ̂(F) = μ‖F̂ − R̂‖², F̂ = J^(−1/3) F: the fixed corotated energy density of the volume-preserving part.
///
/// `mu` ≥ 0 (Pa); `f`: 3×3 column-major; `out[0]` receives Ψ̂ (J/m³), only on `AMPM_OK`.
///
/// # Safety
/// Non-null pointers must be valid for the sizes above.
#[no_mangle]
pub unsafe extern "C" fn ampm_energy_hat_3d_f32(
    mu: f32,
    f: *const f32,
    out: *mut f32,
) -> AmpmStatus {
    fast::single::<f32, 3>(
        mu,
        f,
        ptr::null(),
        ptr::null_mut(),
        ptr::null_mut(),
        out,
        false,
    )
}

/// Computes Ψ̂(F) = μ‖F̂ − R̂‖², F̂ = J^(−1/3) F: the fixed corotated energy density of the volume-preserving part.
///
/// `mu` ≥ 0 (Pa); `f`: 3×3 column-major; `out[0]` receives Ψ̂ (J/m³), only on `AMPM_OK`.
///
/// # Safety
/// Non-null pointers must be valid for the sizes above.
#[no_mangle]
pub unsafe extern "C" fn ampm_energy_hat_3d_f64(
    mu: f64,
    f: *const f64,
    out: *mut f64,
) -> AmpmStatus {
    fast::single::<f64, 3>(
        mu,
        f,
        ptr::null(),
        ptr::null_mut(),
        ptr::null_mut(),
        out,
        false,
    )
}

/// Computes Â = ∂Ψ̂/∂F, the first Piola–Kirchhoff stress of the volume-preserving fixed corotated energy.
///
/// `mu` ≥ 0 (Pa); `f`: 2×2 column-major; `out`: 2×2 stress (Pa), written only on `AMPM_OK`.
///
/// # Safety
/// Non-null pointers must be valid for the sizes above.
#[no_mangle]
pub unsafe extern "C" fn ampm_ahat_2d_f32(mu: f32, f: *const f32, out: *mut f32) -> AmpmStatus {
    fast::single::<f32, 2>(
        mu,
        f,
        ptr::null(),
        out,
        ptr::null_mut(),
        ptr::null_mut(),
        false,
    )
}

/// Computes Â = ∂Ψ̂/∂F, the first Piola–Kirchhoff stress of the volume-preserving fixed corotated energy.
///
/// `mu` ≥ 0 (Pa); `f`: 2×2 column-major; `out`: 2×2 stress (Pa), written only on `AMPM_OK`.
///
/// # Safety
/// Non-null pointers must be valid for the sizes above.
#[no_mangle]
pub unsafe extern "C" fn ampm_ahat_2d_f64(mu: f64, f: *const f64, out: *mut f64) -> AmpmStatus {
    fast::single::<f64, 2>(
        mu,
        f,
        ptr::null(),
        out,
        ptr::null_mut(),
        ptr::null_mut(),
        false,
    )
}

/// Computes Â = ∂Ψ̂/∂F, the first Piola–Kirchhoff stress of the volume-preserving fixed corotated energy.
///
/// `mu` ≥ 0 (Pa); `f`: 3×3 column-major; `out`: 3×3 stress (Pa), written only on `AMPM_OK`.
///
/// # Safety
/// Non-null pointers must be valid for the sizes above.
#[no_mangle]
pub unsafe extern "C" fn ampm_ahat_3d_f32(mu: f32, f: *const f32, out: *mut f32) -> AmpmStatus {
    fast::single::<f32, 3>(
        mu,
        f,
        ptr::null(),
        out,
        ptr::null_mut(),
        ptr::null_mut(),
        false,
    )
}

/// Computes Â = ∂Ψ̂/∂F, the first Piola–Kirchhoff stress of the volume-preserving fixed corotated energy.
///
/// `mu` ≥ 0 (Pa); `f`: 3×3 column-major; `out`: 3×3 stress (Pa), written only on `AMPM_OK`.
///
/// # Safety
/// Non-null pointers must be valid for the sizes above.
#[no_mangle]
pub unsafe extern "C" fn ampm_ahat_3d_f64(mu: f64, f: *const f64, out: *mut f64) -> AmpmStatus {
    fast::single::<f64, 3>(
        mu,
        f,
        ptr::null(),
        out,
        ptr::null_mut(),
        ptr::null_mut(),
        false,
    )
}

/// Computes Ĉ:Z, the action of the Hessian ∂²Ψ̂/∂F∂F of the volume-preserving fixed corotated energy on Z.
///
/// `mu` ≥ 0 (Pa); `f`, `z`: 2×2 column-major; `out`: 2×2, written only on `AMPM_OK`.
///
/// # Safety
/// Non-null pointers must be valid for the sizes above.
#[no_mangle]
pub unsafe extern "C" fn ampm_chat_z_2d_f32(
    mu: f32,
    f: *const f32,
    z: *const f32,
    out: *mut f32,
) -> AmpmStatus {
    fast::single::<f32, 2>(mu, f, z, ptr::null_mut(), out, ptr::null_mut(), false)
}

/// Computes Ĉ:Z, the action of the Hessian ∂²Ψ̂/∂F∂F of the volume-preserving fixed corotated energy on Z.
///
/// `mu` ≥ 0 (Pa); `f`, `z`: 2×2 column-major; `out`: 2×2, written only on `AMPM_OK`.
///
/// # Safety
/// Non-null pointers must be valid for the sizes above.
#[no_mangle]
pub unsafe extern "C" fn ampm_chat_z_2d_f64(
    mu: f64,
    f: *const f64,
    z: *const f64,
    out: *mut f64,
) -> AmpmStatus {
    fast::single::<f64, 2>(mu, f, z, ptr::null_mut(), out, ptr::null_mut(), false)
}

/// Computes Ĉ:Z, the action of the Hessian ∂²Ψ̂/∂F∂F of the volume-preserving fixed corotated energy on Z.
///
/// `mu` ≥ 0 (Pa); `f`, `z`: 3×3 column-major; `out`: 3×3, written only on `AMPM_OK`.
///
/// # Safety
/// Non-null pointers must be valid for the sizes above.
#[no_mangle]
pub unsafe extern "C" fn ampm_chat_z_3d_f32(
    mu: f32,
    f: *const f32,
    z: *const f32,
    out: *mut f32,
) -> AmpmStatus {
    fast::single::<f32, 3>(mu, f, z, ptr::null_mut(), out, ptr::null_mut(), false)
}

/// Computes Ĉ:Z, the action of the Hessian ∂²Ψ̂/∂F∂F of the volume-preserving fixed corotated energy on Z.
///
/// `mu` ≥ 0 (Pa); `f`, `z`: 3×3 column-major; `out`: 3×3, written only on `AMPM_OK`.
///
/// # Safety
/// Non-null pointers must be valid for the sizes above.
#[no_mangle]
pub unsafe extern "C" fn ampm_chat_z_3d_f64(
    mu: f64,
    f: *const f64,
    z: *const f64,
    out: *mut f64,
) -> AmpmStatus {
    fast::single::<f64, 3>(mu, f, z, ptr::null_mut(), out, ptr::null_mut(), false)
}

/// Computes Â for n particles: `out[i]` = Â(mu[i], F[i]).
///
/// `mu`: n values; `f`, `out`: n 2×2 column-major matrices, contiguous. Every valid particle is computed; a failed particle's output is untouched. Returns the first failure's status and writes its index (n if none) to `first_failed` (may be NULL). Arrays may be NULL when n = 0.
///
/// # Safety
/// Non-null pointers must be valid for the sizes above.
#[no_mangle]
pub unsafe extern "C" fn ampm_ahat_batch_2d_f32(
    n: usize,
    mu: *const f32,
    f: *const f32,
    out: *mut f32,
    first_failed: *mut usize,
) -> AmpmStatus {
    fast::kernels::<f32, 2>(
        fast::isa(),
        n,
        mu,
        f,
        ptr::null(),
        out,
        ptr::null_mut(),
        ptr::null_mut(),
        false,
        first_failed,
    )
}

/// Computes Â for n particles: `out[i]` = Â(mu[i], F[i]).
///
/// `mu`: n values; `f`, `out`: n 2×2 column-major matrices, contiguous. Every valid particle is computed; a failed particle's output is untouched. Returns the first failure's status and writes its index (n if none) to `first_failed` (may be NULL). Arrays may be NULL when n = 0.
///
/// # Safety
/// Non-null pointers must be valid for the sizes above.
#[no_mangle]
pub unsafe extern "C" fn ampm_ahat_batch_2d_f64(
    n: usize,
    mu: *const f64,
    f: *const f64,
    out: *mut f64,
    first_failed: *mut usize,
) -> AmpmStatus {
    fast::kernels::<f64, 2>(
        fast::isa(),
        n,
        mu,
        f,
        ptr::null(),
        out,
        ptr::null_mut(),
        ptr::null_mut(),
        false,
        first_failed,
    )
}

/// Computes Â for n particles: `out[i]` = Â(mu[i], F[i]).
///
/// `mu`: n values; `f`, `out`: n 3×3 column-major matrices, contiguous. Every valid particle is computed; a failed particle's output is untouched. Returns the first failure's status and writes its index (n if none) to `first_failed` (may be NULL). Arrays may be NULL when n = 0.
///
/// # Safety
/// Non-null pointers must be valid for the sizes above.
#[no_mangle]
pub unsafe extern "C" fn ampm_ahat_batch_3d_f32(
    n: usize,
    mu: *const f32,
    f: *const f32,
    out: *mut f32,
    first_failed: *mut usize,
) -> AmpmStatus {
    fast::kernels::<f32, 3>(
        fast::isa(),
        n,
        mu,
        f,
        ptr::null(),
        out,
        ptr::null_mut(),
        ptr::null_mut(),
        false,
        first_failed,
    )
}

/// Computes Â for n particles: `out[i]` = Â(mu[i], F[i]).
///
/// `mu`: n values; `f`, `out`: n 3×3 column-major matrices, contiguous. Every valid particle is computed; a failed particle's output is untouched. Returns the first failure's status and writes its index (n if none) to `first_failed` (may be NULL). Arrays may be NULL when n = 0.
///
/// # Safety
/// Non-null pointers must be valid for the sizes above.
#[no_mangle]
pub unsafe extern "C" fn ampm_ahat_batch_3d_f64(
    n: usize,
    mu: *const f64,
    f: *const f64,
    out: *mut f64,
    first_failed: *mut usize,
) -> AmpmStatus {
    fast::kernels::<f64, 3>(
        fast::isa(),
        n,
        mu,
        f,
        ptr::null(),
        out,
        ptr::null_mut(),
        ptr::null_mut(),
        false,
        first_failed,
    )
}

/// Computes Ĉ:Z for n particles: `out[i]` = Ĉ(mu[i], F[i]):Z[i].
///
/// `mu`: n values; `f`, `z`, `out`: n 2×2 column-major matrices, contiguous. Every valid particle is computed; a failed particle's output is untouched. Returns the first failure's status and writes its index (n if none) to `first_failed` (may be NULL). Arrays may be NULL when n = 0.
///
/// # Safety
/// Non-null pointers must be valid for the sizes above.
#[no_mangle]
pub unsafe extern "C" fn ampm_chat_z_batch_2d_f32(
    n: usize,
    mu: *const f32,
    f: *const f32,
    z: *const f32,
    out: *mut f32,
    first_failed: *mut usize,
) -> AmpmStatus {
    fast::kernels::<f32, 2>(
        fast::isa(),
        n,
        mu,
        f,
        z,
        ptr::null_mut(),
        out,
        ptr::null_mut(),
        false,
        first_failed,
    )
}

/// Computes Ĉ:Z for n particles: `out[i]` = Ĉ(mu[i], F[i]):Z[i].
///
/// `mu`: n values; `f`, `z`, `out`: n 2×2 column-major matrices, contiguous. Every valid particle is computed; a failed particle's output is untouched. Returns the first failure's status and writes its index (n if none) to `first_failed` (may be NULL). Arrays may be NULL when n = 0.
///
/// # Safety
/// Non-null pointers must be valid for the sizes above.
#[no_mangle]
pub unsafe extern "C" fn ampm_chat_z_batch_2d_f64(
    n: usize,
    mu: *const f64,
    f: *const f64,
    z: *const f64,
    out: *mut f64,
    first_failed: *mut usize,
) -> AmpmStatus {
    fast::kernels::<f64, 2>(
        fast::isa(),
        n,
        mu,
        f,
        z,
        ptr::null_mut(),
        out,
        ptr::null_mut(),
        false,
        first_failed,
    )
}

/// Computes Ĉ:Z for n particles: `out[i]` = Ĉ(mu[i], F[i]):Z[i].
///
/// `mu`: n values; `f`, `z`, `out`: n 3×3 column-major matrices, contiguous. Every valid particle is computed; a failed particle's output is untouched. Returns the first failure's status and writes its index (n if none) to `first_failed` (may be NULL). Arrays may be NULL when n = 0.
///
/// # Safety
/// Non-null pointers must be valid for the sizes above.
#[no_mangle]
pub unsafe extern "C" fn ampm_chat_z_batch_3d_f32(
    n: usize,
    mu: *const f32,
    f: *const f32,
    z: *const f32,
    out: *mut f32,
    first_failed: *mut usize,
) -> AmpmStatus {
    fast::kernels::<f32, 3>(
        fast::isa(),
        n,
        mu,
        f,
        z,
        ptr::null_mut(),
        out,
        ptr::null_mut(),
        false,
        first_failed,
    )
}

/// Computes Ĉ:Z for n particles: `out[i]` = Ĉ(mu[i], F[i]):Z[i].
///
/// `mu`: n values; `f`, `z`, `out`: n 3×3 column-major matrices, contiguous. Every valid particle is computed; a failed particle's output is untouched. Returns the first failure's status and writes its index (n if none) to `first_failed` (may be NULL). Arrays may be NULL when n = 0.
///
/// # Safety
/// Non-null pointers must be valid for the sizes above.
#[no_mangle]
pub unsafe extern "C" fn ampm_chat_z_batch_3d_f64(
    n: usize,
    mu: *const f64,
    f: *const f64,
    z: *const f64,
    out: *mut f64,
    first_failed: *mut usize,
) -> AmpmStatus {
    fast::kernels::<f64, 3>(
        fast::isa(),
        n,
        mu,
        f,
        z,
        ptr::null_mut(),
        out,
        ptr::null_mut(),
        false,
        first_failed,
    )
}
