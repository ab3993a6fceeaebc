//! C entry points of the combined kernel call, the prepared Hessian (prepare once per Newton
//! step, apply once per Krylov iteration) and the instruction-set choice of the batch calls.
//! Each `extern "C"` wrapper is written out (cbindgen reads the source without expanding
//! macros) and delegates to one generic body in [`crate::fast`].
#![allow(clippy::missing_safety_doc)]

use crate::fast;
use crate::status::AmpmStatus;
use core::ffi::c_int;
use core::ptr;

/// `ampm_set_isa` / `ampm_isa`: one particle per lane, no SIMD (every CPU).
pub const AMPM_ISA_SCALAR: u32 = 0;
/// `ampm_set_isa` / `ampm_isa`: x86-64 AVX2 + FMA, 16 f32 or 8 f64 particles per step.
pub const AMPM_ISA_AVX2: u32 = 1;
/// `ampm_set_isa` / `ampm_isa`: x86-64 AVX-512F, 32 f32 or 16 f64 particles per step.
pub const AMPM_ISA_AVX512: u32 = 2;

/// Chooses the instruction set of every batch call (`AMPM_ISA_*`); by default the widest the
/// CPU supports, detected on first use.
///
/// Returns `AMPM_ERR_INVALID_ARGUMENT` (and changes nothing) for a value this CPU does not
/// support. Results are identical on the AVX2 and AVX-512 paths; the scalar path agrees with
/// them to a few ulps times the conditioning of F. Call it before starting threads that use
/// the library (the choice is one process-wide value).
#[no_mangle]
pub extern "C" fn ampm_set_isa(isa: u32) -> AmpmStatus {
    fast::set_isa(isa)
}

/// The instruction set the batch calls use (`AMPM_ISA_*`).
#[no_mangle]
pub extern "C" fn ampm_isa() -> u32 {
    fast::current_isa()
}

/// Computes Â and Ĉ:Z of n particles with one decomposition each: `ahat[i]` = Â(mu[i], F[i]),
/// `chat_z[i]` = Ĉ(mu[i], F[i]):Z[i] (fixed corotated Ψ̂, a = -1/2, default decomposition).
///
/// `mu`: n shear moduli (Pa, ≥ 0; 0 is a liquid: both outputs 0); `f`, `z`, `ahat`,
/// `chat_z`: n 2×2 column-major matrices back to back (4 scalars each). `ahat` (Pa) or
/// `chat_z` (Pa per unit strain) may be NULL: that output is not computed, and `z` may be NULL
/// when `chat_z` is; both NULL is `AMPM_ERR_NULL_POINTER` when n > 0. Every valid particle is
/// computed; a failed particle leaves both outputs untouched. Returns the first failure's
/// status (`AMPM_ERR_NON_FINITE`, `AMPM_ERR_NON_POSITIVE_J`, `AMPM_ERR_INVALID_ARGUMENT` for
/// mu < 0, `AMPM_ERR_OVERFLOW`) and writes its index (n if none) to `first_failed` (may be
/// NULL; not written on a whole-call error such as a NULL array). Outputs may alias `f` or
/// `z` exactly (in place). A particle's result does not depend on n or on its index.
///
/// # Safety
/// Non-null pointers must be valid for the sizes above.
#[no_mangle]
pub unsafe extern "C" fn ampm_ahat_chat_z_batch_2d_f32(
    n: usize,
    mu: *const f32,
    f: *const f32,
    z: *const f32,
    ahat: *mut f32,
    chat_z: *mut f32,
    first_failed: *mut usize,
) -> AmpmStatus {
    fast::kernels::<f32, 2>(
        fast::isa(),
        n,
        mu,
        f,
        z,
        ahat,
        chat_z,
        ptr::null_mut(),
        false,
        first_failed,
    )
}

/// Scalars (18) of one particle's prepared-Hessian slot for
/// `ampm_hessian_prepare_batch_2d_f32` / `ampm_hessian_apply_batch_2d_f32`.
#[no_mangle]
pub extern "C" fn ampm_hessian_len_2d_f32() -> usize {
    18
}

/// Prepares the Hessian Ĉ of n particles once (per Newton step) for any number of
/// `ampm_hessian_apply_batch_2d_f32` calls, and optionally computes Â.
///
/// `mu`: n values (Pa, ≥ 0); `f`: n 2×2 column-major matrices; `ahat`: n matrices or NULL
/// (not computed); `prepared`: n slots of `ampm_hessian_len_2d_f32()` = 18 scalars, slot i
/// at `prepared + i·18`, opaque. The slot holds the decomposition and the SVD-basis
/// eigenvalues of Ĉ and of its PSD projection Ĉ⁺, so apply can give either. A failed
/// particle leaves `ahat[i]` untouched and marks slot i unprepared (only its first scalar is
/// written), so that a later apply refuses it (`AMPM_ERR_NOT_PREPARED`) instead of using data
/// from an earlier step. Statuses and `first_failed` as `ampm_ahat_chat_z_batch_2d_f32`.
///
/// # Safety
/// Non-null pointers must be valid for the sizes above; `prepared` must not overlap the
/// inputs.
#[no_mangle]
pub unsafe extern "C" fn ampm_hessian_prepare_batch_2d_f32(
    n: usize,
    mu: *const f32,
    f: *const f32,
    ahat: *mut f32,
    prepared: *mut f32,
    first_failed: *mut usize,
) -> AmpmStatus {
    fast::prepare::<f32, 2>(n, mu, f, ahat, prepared, first_failed)
}

/// Applies prepared Hessians: `out[i]` = Ĉ:Z[i], or the PSD-projected Ĉ⁺:Z[i] when `psd` ≠ 0
/// (Pa per unit strain), without any decomposition.
///
/// `prepared`: n slots written by `ampm_hessian_prepare_batch_2d_f32` (18 scalars each);
/// `z`, `out`: n 2×2 column-major matrices (`out` may alias `z` exactly). A slot that no
/// successful prepare wrote (zero-filled memory, or the slot of a failed particle) gives
/// `AMPM_ERR_NOT_PREPARED` for that particle; a non-finite Z gives `AMPM_ERR_NON_FINITE`, an
/// unrepresentable result `AMPM_ERR_OVERFLOW`. Failed particles leave `out` untouched; the
/// first failure's status is returned and its index (n if none) written to `first_failed`
/// (may be NULL). The result agrees with `ampm_chat_z_batch_2d_f32` (or
/// `ampm_chat_z_psd_batch_2d_f32`) on the same instruction set to a few ulps.
///
/// # Safety
/// Non-null pointers must be valid for the sizes above.
#[no_mangle]
pub unsafe extern "C" fn ampm_hessian_apply_batch_2d_f32(
    n: usize,
    prepared: *const f32,
    z: *const f32,
    out: *mut f32,
    psd: c_int,
    first_failed: *mut usize,
) -> AmpmStatus {
    fast::apply::<f32, 2>(n, prepared, z, out, psd != 0, first_failed)
}

/// Computes Â and Ĉ:Z of n particles with one decomposition each: `ahat[i]` = Â(mu[i], F[i]),
/// `chat_z[i]` = Ĉ(mu[i], F[i]):Z[i] (fixed corotated Ψ̂, a = -1/2, default decomposition).
///
/// `mu`: n shear moduli (Pa, ≥ 0; 0 is a liquid: both outputs 0); `f`, `z`, `ahat`,
/// `chat_z`: n 2×2 column-major matrices back to back (4 scalars each). `ahat` (Pa) or
/// `chat_z` (Pa per unit strain) may be NULL: that output is not computed, and `z` may be NULL
/// when `chat_z` is; both NULL is `AMPM_ERR_NULL_POINTER` when n > 0. Every valid particle is
/// computed; a failed particle leaves both outputs untouched. Returns the first failure's
/// status (`AMPM_ERR_NON_FINITE`, `AMPM_ERR_NON_POSITIVE_J`, `AMPM_ERR_INVALID_ARGUMENT` for
/// mu < 0, `AMPM_ERR_OVERFLOW`) and writes its index (n if none) to `first_failed` (may be
/// NULL; not written on a whole-call error such as a NULL array). Outputs may alias `f` or
/// `z` exactly (in place). A particle's result does not depend on n or on its index.
///
/// # Safety
/// Non-null pointers must be valid for the sizes above.
#[no_mangle]
pub unsafe extern "C" fn ampm_ahat_chat_z_batch_2d_f64(
    n: usize,
    mu: *const f64,
    f: *const f64,
    z: *const f64,
    ahat: *mut f64,
    chat_z: *mut f64,
    first_failed: *mut usize,
) -> AmpmStatus {
    fast::kernels::<f64, 2>(
        fast::isa(),
        n,
        mu,
        f,
        z,
        ahat,
        chat_z,
        ptr::null_mut(),
        false,
        first_failed,
    )
}

/// Scalars (18) of one particle's prepared-Hessian slot for
/// `ampm_hessian_prepare_batch_2d_f64` / `ampm_hessian_apply_batch_2d_f64`.
#[no_mangle]
pub extern "C" fn ampm_hessian_len_2d_f64() -> usize {
    18
}

/// Prepares the Hessian Ĉ of n particles once (per Newton step) for any number of
/// `ampm_hessian_apply_batch_2d_f64` calls, and optionally computes Â.
///
/// `mu`: n values (Pa, ≥ 0); `f`: n 2×2 column-major matrices; `ahat`: n matrices or NULL
/// (not computed); `prepared`: n slots of `ampm_hessian_len_2d_f64()` = 18 scalars, slot i
/// at `prepared + i·18`, opaque. The slot holds the decomposition and the SVD-basis
/// eigenvalues of Ĉ and of its PSD projection Ĉ⁺, so apply can give either. A failed
/// particle leaves `ahat[i]` untouched and marks slot i unprepared (only its first scalar is
/// written), so that a later apply refuses it (`AMPM_ERR_NOT_PREPARED`) instead of using data
/// from an earlier step. Statuses and `first_failed` as `ampm_ahat_chat_z_batch_2d_f64`.
///
/// # Safety
/// Non-null pointers must be valid for the sizes above; `prepared` must not overlap the
/// inputs.
#[no_mangle]
pub unsafe extern "C" fn ampm_hessian_prepare_batch_2d_f64(
    n: usize,
    mu: *const f64,
    f: *const f64,
    ahat: *mut f64,
    prepared: *mut f64,
    first_failed: *mut usize,
) -> AmpmStatus {
    fast::prepare::<f64, 2>(n, mu, f, ahat, prepared, first_failed)
}

/// Applies prepared Hessians: `out[i]` = Ĉ:Z[i], or the PSD-projected Ĉ⁺:Z[i] when `psd` ≠ 0
/// (Pa per unit strain), without any decomposition.
///
/// `prepared`: n slots written by `ampm_hessian_prepare_batch_2d_f64` (18 scalars each);
/// `z`, `out`: n 2×2 column-major matrices (`out` may alias `z` exactly). A slot that no
/// successful prepare wrote (zero-filled memory, or the slot of a failed particle) gives
/// `AMPM_ERR_NOT_PREPARED` for that particle; a non-finite Z gives `AMPM_ERR_NON_FINITE`, an
/// unrepresentable result `AMPM_ERR_OVERFLOW`. Failed particles leave `out` untouched; the
/// first failure's status is returned and its index (n if none) written to `first_failed`
/// (may be NULL). The result agrees with `ampm_chat_z_batch_2d_f64` (or
/// `ampm_chat_z_psd_batch_2d_f64`) on the same instruction set to a few ulps.
///
/// # Safety
/// Non-null pointers must be valid for the sizes above.
#[no_mangle]
pub unsafe extern "C" fn ampm_hessian_apply_batch_2d_f64(
    n: usize,
    prepared: *const f64,
    z: *const f64,
    out: *mut f64,
    psd: c_int,
    first_failed: *mut usize,
) -> AmpmStatus {
    fast::apply::<f64, 2>(n, prepared, z, out, psd != 0, first_failed)
}

/// Computes Â and Ĉ:Z of n particles with one decomposition each: `ahat[i]` = Â(mu[i], F[i]),
/// `chat_z[i]` = Ĉ(mu[i], F[i]):Z[i] (fixed corotated Ψ̂, a = -1/3, default decomposition).
///
/// `mu`: n shear moduli (Pa, ≥ 0; 0 is a liquid: both outputs 0); `f`, `z`, `ahat`,
/// `chat_z`: n 3×3 column-major matrices back to back (9 scalars each). `ahat` (Pa) or
/// `chat_z` (Pa per unit strain) may be NULL: that output is not computed, and `z` may be NULL
/// when `chat_z` is; both NULL is `AMPM_ERR_NULL_POINTER` when n > 0. Every valid particle is
/// computed; a failed particle leaves both outputs untouched. Returns the first failure's
/// status (`AMPM_ERR_NON_FINITE`, `AMPM_ERR_NON_POSITIVE_J`, `AMPM_ERR_INVALID_ARGUMENT` for
/// mu < 0, `AMPM_ERR_OVERFLOW`) and writes its index (n if none) to `first_failed` (may be
/// NULL; not written on a whole-call error such as a NULL array). Outputs may alias `f` or
/// `z` exactly (in place). A particle's result does not depend on n or on its index.
///
/// # Safety
/// Non-null pointers must be valid for the sizes above.
#[no_mangle]
pub unsafe extern "C" fn ampm_ahat_chat_z_batch_3d_f32(
    n: usize,
    mu: *const f32,
    f: *const f32,
    z: *const f32,
    ahat: *mut f32,
    chat_z: *mut f32,
    first_failed: *mut usize,
) -> AmpmStatus {
    fast::kernels::<f32, 3>(
        fast::isa(),
        n,
        mu,
        f,
        z,
        ahat,
        chat_z,
        ptr::null_mut(),
        false,
        first_failed,
    )
}

/// Scalars (38) of one particle's prepared-Hessian slot for
/// `ampm_hessian_prepare_batch_3d_f32` / `ampm_hessian_apply_batch_3d_f32`.
#[no_mangle]
pub extern "C" fn ampm_hessian_len_3d_f32() -> usize {
    38
}

/// Prepares the Hessian Ĉ of n particles once (per Newton step) for any number of
/// `ampm_hessian_apply_batch_3d_f32` calls, and optionally computes Â.
///
/// `mu`: n values (Pa, ≥ 0); `f`: n 3×3 column-major matrices; `ahat`: n matrices or NULL
/// (not computed); `prepared`: n slots of `ampm_hessian_len_3d_f32()` = 38 scalars, slot i
/// at `prepared + i·38`, opaque. The slot holds the decomposition and the SVD-basis
/// eigenvalues of Ĉ and of its PSD projection Ĉ⁺, so apply can give either. A failed
/// particle leaves `ahat[i]` untouched and marks slot i unprepared (only its first scalar is
/// written), so that a later apply refuses it (`AMPM_ERR_NOT_PREPARED`) instead of using data
/// from an earlier step. Statuses and `first_failed` as `ampm_ahat_chat_z_batch_3d_f32`.
///
/// # Safety
/// Non-null pointers must be valid for the sizes above; `prepared` must not overlap the
/// inputs.
#[no_mangle]
pub unsafe extern "C" fn ampm_hessian_prepare_batch_3d_f32(
    n: usize,
    mu: *const f32,
    f: *const f32,
    ahat: *mut f32,
    prepared: *mut f32,
    first_failed: *mut usize,
) -> AmpmStatus {
    fast::prepare::<f32, 3>(n, mu, f, ahat, prepared, first_failed)
}

/// Applies prepared Hessians: `out[i]` = Ĉ:Z[i], or the PSD-projected Ĉ⁺:Z[i] when `psd` ≠ 0
/// (Pa per unit strain), without any decomposition.
///
/// `prepared`: n slots written by `ampm_hessian_prepare_batch_3d_f32` (38 scalars each);
/// `z`, `out`: n 3×3 column-major matrices (`out` may alias `z` exactly). A slot that no
/// successful prepare wrote (zero-filled memory, or the slot of a failed particle) gives
/// `AMPM_ERR_NOT_PREPARED` for that particle; a non-finite Z gives `AMPM_ERR_NON_FINITE`, an
/// unrepresentable result `AMPM_ERR_OVERFLOW`. Failed particles leave `out` untouched; the
/// first failure's status is returned and its index (n if none) written to `first_failed`
/// (may be NULL). The result agrees with `ampm_chat_z_batch_3d_f32` (or
/// `ampm_chat_z_psd_batch_3d_f32`) on the same instruction set to a few ulps.
///
/// # Safety
/// Non-null pointers must be valid for the sizes above.
#[no_mangle]
pub unsafe extern "C" fn ampm_hessian_apply_batch_3d_f32(
    n: usize,
    prepared: *const f32,
    z: *const f32,
    out: *mut f32,
    psd: c_int,
    first_failed: *mut usize,
) -> AmpmStatus {
    fast::apply::<f32, 3>(n, prepared, z, out, psd != 0, first_failed)
}

/// Computes Â and Ĉ:Z of n particles with one decomposition each: `ahat[i]` = Â(mu[i], F[i]),
/// `chat_z[i]` = Ĉ(mu[i], F[i]):Z[i] (fixed corotated Ψ̂, a = -1/3, default decomposition).
///
/// `mu`: n shear moduli (Pa, ≥ 0; 0 is a liquid: both outputs 0); `f`, `z`, `ahat`,
/// `chat_z`: n 3×3 column-major matrices back to back (9 scalars each). `ahat` (Pa) or
/// `chat_z` (Pa per unit strain) may be NULL: that output is not computed, and `z` may be NULL
/// when `chat_z` is; both NULL is `AMPM_ERR_NULL_POINTER` when n > 0. Every valid particle is
/// computed; a failed particle leaves both outputs untouched. Returns the first failure's
/// status (`AMPM_ERR_NON_FINITE`, `AMPM_ERR_NON_POSITIVE_J`, `AMPM_ERR_INVALID_ARGUMENT` for
/// mu < 0, `AMPM_ERR_OVERFLOW`) and writes its index (n if none) to `first_failed` (may be
/// NULL; not written on a whole-call error such as a NULL array). Outputs may alias `f` or
/// `z` exactly (in place). A particle's result does not depend on n or on its index.
///
/// # Safety
/// Non-null pointers must be valid for the sizes above.
#[no_mangle]
pub unsafe extern "C" fn ampm_ahat_chat_z_batch_3d_f64(
    n: usize,
    mu: *const f64,
    f: *const f64,
    z: *const f64,
    ahat: *mut f64,
    chat_z: *mut f64,
    first_failed: *mut usize,
) -> AmpmStatus {
    fast::kernels::<f64, 3>(
        fast::isa(),
        n,
        mu,
        f,
        z,
        ahat,
        chat_z,
        ptr::null_mut(),
        false,
        first_failed,
    )
}

/// Scalars (38) of one particle's prepared-Hessian slot for
/// `ampm_hessian_prepare_batch_3d_f64` / `ampm_hessian_apply_batch_3d_f64`.
#[no_mangle]
pub extern "C" fn ampm_hessian_len_3d_f64() -> usize {
    38
}

/// Prepares the Hessian Ĉ of n particles once (per Newton step) for any number of
/// `ampm_hessian_apply_batch_3d_f64` calls, and optionally computes Â.
///
/// `mu`: n values (Pa, ≥ 0); `f`: n 3×3 column-major matrices; `ahat`: n matrices or NULL
/// (not computed); `prepared`: n slots of `ampm_hessian_len_3d_f64()` = 38 scalars, slot i
/// at `prepared + i·38`, opaque. The slot holds the decomposition and the SVD-basis
/// eigenvalues of Ĉ and of its PSD projection Ĉ⁺, so apply can give either. A failed
/// particle leaves `ahat[i]` untouched and marks slot i unprepared (only its first scalar is
/// written), so that a later apply refuses it (`AMPM_ERR_NOT_PREPARED`) instead of using data
/// from an earlier step. Statuses and `first_failed` as `ampm_ahat_chat_z_batch_3d_f64`.
///
/// # Safety
/// Non-null pointers must be valid for the sizes above; `prepared` must not overlap the
/// inputs.
#[no_mangle]
pub unsafe extern "C" fn ampm_hessian_prepare_batch_3d_f64(
    n: usize,
    mu: *const f64,
    f: *const f64,
    ahat: *mut f64,
    prepared: *mut f64,
    first_failed: *mut usize,
) -> AmpmStatus {
    fast::prepare::<f64, 3>(n, mu, f, ahat, prepared, first_failed)
}

/// Applies prepared Hessians: `out[i]` = Ĉ:Z[i], or the PSD-projected Ĉ⁺:Z[i] when `psd` ≠ 0
/// (Pa per unit strain), without any decomposition.
///
/// `prepared`: n slots written by `ampm_hessian_prepare_batch_3d_f64` (38 scalars each);
/// `z`, `out`: n 3×3 column-major matrices (`out` may alias `z` exactly). A slot that no
/// successful prepare wrote (zero-filled memory, or the slot of a failed particle) gives
/// `AMPM_ERR_NOT_PREPARED` for that particle; a non-finite Z gives `AMPM_ERR_NON_FINITE`, an
/// unrepresentable result `AMPM_ERR_OVERFLOW`. Failed particles leave `out` untouched; the
/// first failure's status is returned and its index (n if none) written to `first_failed`
/// (may be NULL). The result agrees with `ampm_chat_z_batch_3d_f64` (or
/// `ampm_chat_z_psd_batch_3d_f64`) on the same instruction set to a few ulps.
///
/// # Safety
/// Non-null pointers must be valid for the sizes above.
#[no_mangle]
pub unsafe extern "C" fn ampm_hessian_apply_batch_3d_f64(
    n: usize,
    prepared: *const f64,
    z: *const f64,
    out: *mut f64,
    psd: c_int,
    first_failed: *mut usize,
) -> AmpmStatus {
    fast::apply::<f64, 3>(n, prepared, z, out, psd != 0, first_failed)
}
