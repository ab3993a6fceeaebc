//! The combined kernel call and the prepared Hessian (prepare once per Newton step, apply once
//! per Krylov iteration).

use super::{Module, Op};

pub const MODULE: Module = Module {
    name: "prepared",
    doc: "The C entry points of the combined kernel call and of the prepared Hessian (prepare
        once per Newton step, apply once per Krylov iteration), on the fast kernels of
        `crate::fast`.",
    uses: &[
        "crate::fast",
        "crate::status::AmpmStatus",
        "core::ffi::c_int",
        "core::ptr",
    ],
    ops: &[
        Op {
            name: "ahat_chat_z_batch",
            doc: "
                Computes Â and Ĉ:Z of n particles with one decomposition each:
                ahat[i] = Â(mu[i], F[i]), chat_z[i] = Ĉ(mu[i], F[i]):Z[i] (fixed corotated Ψ̂,
                a = {a}, default decomposition).

                `n`: number of particles; `mu`: n shear moduli (Pa, ≥ 0; 0 is a liquid: both
                outputs 0); `f`, `z`, `ahat`, `chat_z`: n {DxD} column-major matrices back to
                back ({DD} scalars each). `ahat` (Pa) or `chat_z` (Pa per unit strain) may be
                NULL: that output is not computed, and `z` may be NULL when `chat_z` is; both
                NULL is AMPM_ERR_NULL_POINTER when n > 0. Outputs may be `f` or `z` (in place).
                A particle fails with AMPM_ERR_NON_FINITE, AMPM_ERR_NON_POSITIVE_J,
                AMPM_ERR_INVALID_ARGUMENT (mu < 0) or AMPM_ERR_OVERFLOW, and then leaves both
                outputs untouched. A particle's result does not depend on n or on its index.

                {BATCH}",
            params: &[
                "n: usize",
                "mu: *const {T}",
                "f: *const {T}",
                "z: *const {T}",
                "ahat: *mut {T}",
                "chat_z: *mut {T}",
                "first_failed: *mut usize",
            ],
            ret: "AmpmStatus",
            body: "
                fast::kernels::<{T}, {D}>(
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
                )",
        },
        Op {
            name: "hessian_len",
            doc: "
                The number of scalars ({PREP}) of one particle's prepared-Hessian slot, for
                ampm_hessian_prepare_batch_{sfx} and ampm_hessian_apply_batch_{sfx}.",
            params: &[],
            ret: "usize",
            body: "{PREP}",
        },
        Op {
            name: "hessian_prepare_batch",
            doc: "
                Prepares the Hessian Ĉ of n particles once (per Newton step) for any number of
                ampm_hessian_apply_batch_{sfx} calls, and optionally computes Â.

                `n`: number of particles; `mu`: n values (Pa, ≥ 0); `f`: n {DxD} column-major
                matrices; `ahat`: n matrices, or NULL (not computed); `prepared`: n slots of
                ampm_hessian_len_{sfx}() = {PREP} scalars, slot i at prepared + i*{PREP},
                opaque, not overlapping the inputs. A slot holds the decomposition and the
                SVD-basis eigenvalues of Ĉ and of its PSD projection Ĉ⁺, so that apply can give
                either. A failed particle leaves `ahat[i]` untouched and marks slot i unprepared
                (only its first scalar is written), so that a later apply refuses it
                (AMPM_ERR_NOT_PREPARED) instead of using data of an earlier step. Per-particle
                statuses as ampm_ahat_chat_z_batch_{sfx}.

                {BATCH}",
            params: &[
                "n: usize",
                "mu: *const {T}",
                "f: *const {T}",
                "ahat: *mut {T}",
                "prepared: *mut {T}",
                "first_failed: *mut usize",
            ],
            ret: "AmpmStatus",
            body: "fast::prepare::<{T}, {D}>(n, mu, f, ahat, prepared, first_failed)",
        },
        Op {
            name: "hessian_apply_batch",
            doc: "
                Applies prepared Hessians: out[i] = Ĉ:Z[i], or the PSD-projected Ĉ⁺:Z[i] when
                `psd` ≠ 0 (Pa per unit strain), without any decomposition.

                `n`: number of particles; `prepared`: n slots written by
                ampm_hessian_prepare_batch_{sfx} ({PREP} scalars each); `z`, `out`: n {DxD}
                column-major matrices (`out` may be `z`). A slot that no successful prepare
                wrote (zero-filled memory, or the slot of a failed particle) fails with
                AMPM_ERR_NOT_PREPARED; a non-finite Z with AMPM_ERR_NON_FINITE, an
                unrepresentable result with AMPM_ERR_OVERFLOW. The result agrees with
                ampm_chat_z_batch_{sfx} (or ampm_chat_z_psd_batch_{sfx}) on the same
                instruction set to a few ulps.

                {BATCH}",
            params: &[
                "n: usize",
                "prepared: *const {T}",
                "z: *const {T}",
                "out: *mut {T}",
                "psd: c_int",
                "first_failed: *mut usize",
            ],
            ret: "AmpmStatus",
            body: "fast::apply::<{T}, {D}>(n, prepared, z, out, psd != 0, first_failed)",
        },
    ],
};
