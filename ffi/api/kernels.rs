//! The kernels at one point: the actions of 𝓑(F), and Ψ̂, Â, Ĉ:Z.

use super::{Module, Op};

pub const MODULE: Module = Module {
    name: "kernels",
    doc: "The C entry points of the kernels at one point: the actions of 𝓑(F), and Ψ̂, Â, Ĉ:Z
        (their batch forms are in `kernels_batch`). The 𝓑 bodies are in `crate::kernels_impl`;
        the energy kernels run on `ampm_core::kernel` through `crate::fast`.",
    uses: &[
        "crate::fast",
        "crate::kernels_impl",
        "crate::status::AmpmStatus",
        "ampm_core::Mat",
        "core::ptr",
    ],
    ops: &[
        Op {
            name: "b_z",
            doc: "
                Computes 𝓑(F):Z = Jᵃ(Z + a(H:Z)F), a = {a}, H = F⁻ᵀ: the derivative of JᵃF in
                the direction Z.

                `f`, `z`: {DxD} column-major inputs; `out`: {DxD} output (may be `f` or `z`).",
            params: &["f: *const {T}", "z: *const {T}", "out: *mut {T}"],
            ret: "AmpmStatus",
            body: "kernels_impl::b_z::<Mat<{T}, {D}>>(f, z, out)",
        },
        Op {
            name: "z_b",
            doc: "
                Computes Z:𝓑(F) = Jᵃ(Z + a(F:Z)H), a = {a}, H = F⁻ᵀ: the adjoint action of
                𝓑(F).

                `f`, `z`: {DxD} column-major inputs; `out`: {DxD} output (may be `f` or `z`).",
            params: &["f: *const {T}", "z: *const {T}", "out: *mut {T}"],
            ret: "AmpmStatus",
            body: "kernels_impl::z_b::<Mat<{T}, {D}>>(f, z, out)",
        },
        Op {
            name: "energy_hat",
            doc: "
                Computes Ψ̂(F) = μ‖F̂ − R̂‖², F̂ = J^({a}) F, R̂ the rotation of F̂: the fixed
                corotated energy density of the volume-preserving part of F.

                `mu` ≥ 0 (Pa); `f`: {DxD} column-major input; `out`: one scalar, Ψ̂ (J/m³).",
            params: &["mu: {T}", "f: *const {T}", "out: *mut {T}"],
            ret: "AmpmStatus",
            body: "
                fast::single::<{T}, {D}>(
                    mu,
                    f,
                    ptr::null(),
                    ptr::null_mut(),
                    ptr::null_mut(),
                    out,
                    false,
                )",
        },
        Op {
            name: "ahat",
            doc: "
                Computes Â = ∂Ψ̂/∂F, the first Piola–Kirchhoff stress of the volume-preserving
                fixed corotated energy Ψ̂ (see ampm_energy_hat_{sfx}).

                `mu` ≥ 0 (Pa); `f`: {DxD} column-major input; `out`: {DxD} stress (Pa; may be
                `f`).",
            params: &["mu: {T}", "f: *const {T}", "out: *mut {T}"],
            ret: "AmpmStatus",
            body: "
                fast::single::<{T}, {D}>(
                    mu,
                    f,
                    ptr::null(),
                    out,
                    ptr::null_mut(),
                    ptr::null_mut(),
                    false,
                )",
        },
        Op {
            name: "chat_z",
            doc: "
                Computes Ĉ:Z, the action on Z of the Hessian Ĉ = ∂²Ψ̂/∂F∂F of the
                volume-preserving fixed corotated energy Ψ̂.

                `mu` ≥ 0 (Pa); `f`, `z`: {DxD} column-major inputs; `out`: {DxD} output (Pa per
                unit strain; may be `f` or `z`).",
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
                    false,
                )",
        },
    ],
};
