//! The Hessian of Ψ̂: its PSD-projected action, and the explicit matrices Ĉ and Ĉ⁺.

use super::{Module, Op};

pub const MODULE: Module = Module {
    name: "hessian",
    doc: "The C entry points of the Hessian of Ψ̂ (fixed corotated, default SVD method): the
        PSD-projected action Ĉ⁺:Z, single (scalar path of `crate::fast`) and batch, and the
        explicit d²×d² matrices Ĉ and Ĉ⁺ (bodies in `crate::hessian`).",
    uses: &[
        "crate::fast",
        "crate::hessian",
        "crate::status::AmpmStatus",
        "ampm_core::Mat",
        "core::ptr",
    ],
    ops: &[
        Op {
            name: "chat_z_psd",
            doc: "
                Computes Ĉ⁺:Z, the action of the Hessian of Ψ̂ (fixed corotated, a = {a}) with
                its negative eigenvalues clamped to zero (Smith, de Goes, Kim 2019 eigensystem
                in the SVD basis of F). Use it as the (PSD) operator of a Newton/Krylov solve.

                `mu` ≥ 0 (Pa); `f`, `z`: {DxD} column-major inputs; `out`: {DxD} output (may be
                `f` or `z`).",
            params: &["mu: {T}", "f: *const {T}", "z: *const {T}", "out: *mut {T}"],
            ret: "AmpmStatus",
            body: "
                fast::single::<{T}, {D}>(
                    mu,
                    f,
                    z,
                    ptr::null_mut(),
                    out,
                    ptr::null_mut(),
                    true,
                )",
        },
        Op {
            name: "chat_z_psd_batch",
            doc: "
                Computes Ĉ⁺:Z for n particles: out[i] = Ĉ⁺(mu[i], F[i]):Z[i] (see
                ampm_chat_z_psd_{sfx}).

                `n`: number of particles; `mu`: n values (Pa, ≥ 0); `f`, `z`, `out`: n {DxD}
                column-major matrices back to back ({DD} scalars each; `out` may be `f` or `z`).

                {BATCH}",
            params: &[
                "n: usize",
                "mu: *const {T}",
                "f: *const {T}",
                "z: *const {T}",
                "out: *mut {T}",
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
                    ptr::null_mut(),
                    out,
                    ptr::null_mut(),
                    true,
                    first_failed,
                )",
        },
        Op {
            name: "chat_matrix",
            doc: "
                Computes the explicit {WxW} Hessian Ĉ of Ψ̂ (fixed corotated, a = {a}),
                symmetric and in general indefinite.

                Convention: vec(Z)[i + {D}*j] = Z_ij (column-major), so that
                vec(Ĉ:Z) = Ĉ · vec(Z); out[p + {WW}*q] = Ĉ[p][q] (column-major; Ĉ is symmetric).
                `mu` ≥ 0 (Pa); `f`: {DxD} column-major input; `out`: {WW} scalars.",
            params: &["mu: {T}", "f: *const {T}", "out: *mut {T}"],
            ret: "AmpmStatus",
            body: "hessian::chat_matrix::<Mat<{T}, {D}>>(mu, f, out)",
        },
        Op {
            name: "chat_psd_matrix",
            doc: "
                Computes the explicit {WxW} PSD projection Ĉ⁺ of the Hessian of Ψ̂ (negative
                eigenvalues clamped to zero; the nearest PSD matrix to Ĉ in the Frobenius
                norm).

                Same convention as ampm_chat_matrix_{sfx}: out[p + {WW}*q] = Ĉ⁺[p][q],
                vec(Ĉ⁺:Z) = Ĉ⁺ · vec(Z) with vec(Z)[i + {D}*j] = Z_ij. `mu` ≥ 0 (Pa); `f`: {DxD}
                column-major input; `out`: {WW} scalars.",
            params: &["mu: {T}", "f: *const {T}", "out: *mut {T}"],
            ret: "AmpmStatus",
            body: "hessian::chat_psd_matrix::<Mat<{T}, {D}>>(mu, f, out)",
        },
    ],
};
