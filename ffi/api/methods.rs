//! The `_ex` variants (a run-time choice of the polar/SVD method) and the decompositions.

use super::{Module, Op};

pub const MODULE: Module = Module {
    name: "methods",
    doc: "The C entry points taking a run-time choice of the polar/SVD method (`AmpmOptions`):
        the `_ex` variants of the kernels (bodies in `crate::methods::ex`) and the SVD and polar
        decompositions (bodies in `crate::methods::decomp`).",
    uses: &[
        "crate::methods::{decomp, ex, AmpmOptions}",
        "crate::status::AmpmStatus",
        "ampm_core::Mat",
    ],
    ops: &[
        Op {
            name: "energy_hat_ex",
            doc: "
                Computes Ψ̂(F) = μ‖F̂ − R̂‖², F̂ = J^({a}) F, with a run-time choice of the polar
                method (see ampm_energy_hat_{sfx}, which the default method reproduces exactly).

                {OPTS}
                `mu` ≥ 0 (Pa); `f`: {DxD} column-major input; `out`: one scalar, Ψ̂ (J/m³).",
            params: &[
                "opts: *const AmpmOptions",
                "mu: {T}",
                "f: *const {T}",
                "out: *mut {T}",
            ],
            ret: "AmpmStatus",
            body: "ex::energy_hat_ex::<Mat<{T}, {D}>>(opts, mu, f, out)",
        },
        Op {
            name: "ahat_ex",
            doc: "
                Computes Â = ∂Ψ̂/∂F (volume-preserving fixed corotated) with a run-time choice
                of the polar method (see ampm_ahat_{sfx}, which the default method reproduces
                exactly).

                {OPTS}
                `mu` ≥ 0 (Pa); `f`: {DxD} column-major input; `out`: {DxD} stress (Pa; may be
                `f`).",
            params: &[
                "opts: *const AmpmOptions",
                "mu: {T}",
                "f: *const {T}",
                "out: *mut {T}",
            ],
            ret: "AmpmStatus",
            body: "ex::ahat_ex::<Mat<{T}, {D}>>(opts, mu, f, out)",
        },
        Op {
            name: "chat_z_ex",
            doc: "
                Computes Ĉ:Z, the Hessian action of the volume-preserving fixed corotated
                energy, with a run-time choice of the polar method (see ampm_chat_z_{sfx},
                which the default method reproduces exactly).

                {OPTS}
                `mu` ≥ 0 (Pa); `f`, `z`: {DxD} column-major inputs; `out`: {DxD} output (may be
                `f` or `z`).",
            params: &[
                "opts: *const AmpmOptions",
                "mu: {T}",
                "f: *const {T}",
                "z: *const {T}",
                "out: *mut {T}",
            ],
            ret: "AmpmStatus",
            body: "ex::chat_z_ex::<Mat<{T}, {D}>>(opts, mu, f, z, out)",
        },
        Op {
            name: "ahat_batch_ex",
            doc: "
                Computes Â for n particles, out[i] = Â(mu[i], F[i]), with a run-time choice of
                the polar method (see ampm_ahat_batch_{sfx}, which the default method
                reproduces exactly).

                {OPTS}
                `n`: number of particles; `mu`: n values (Pa, ≥ 0); `f`, `out`: n {DxD}
                column-major matrices back to back ({DD} scalars each; `out` may be `f`).

                {BATCH}",
            params: &[
                "opts: *const AmpmOptions",
                "n: usize",
                "mu: *const {T}",
                "f: *const {T}",
                "out: *mut {T}",
                "first_failed: *mut usize",
            ],
            ret: "AmpmStatus",
            body: "ex::ahat_batch_ex::<Mat<{T}, {D}>>(opts, n, mu, f, out, first_failed)",
        },
        Op {
            name: "chat_z_batch_ex",
            doc: "
                Computes Ĉ:Z for n particles, out[i] = Ĉ(mu[i], F[i]):Z[i], with a run-time
                choice of the polar method (see ampm_chat_z_batch_{sfx}, which the default
                method reproduces exactly).

                {OPTS}
                `n`: number of particles; `mu`: n values (Pa, ≥ 0); `f`, `z`, `out`: n {DxD}
                column-major matrices back to back ({DD} scalars each; `out` may be `f` or `z`).

                {BATCH}",
            params: &[
                "opts: *const AmpmOptions",
                "n: usize",
                "mu: *const {T}",
                "f: *const {T}",
                "z: *const {T}",
                "out: *mut {T}",
                "first_failed: *mut usize",
            ],
            ret: "AmpmStatus",
            body: "ex::chat_z_batch_ex::<Mat<{T}, {D}>>(opts, n, mu, f, z, out, first_failed)",
        },
        Op {
            name: "svd",
            doc: "
                Computes the rotation-variant SVD F = U diag(σ) Vᵀ: U, V rotations (det +1), σ
                sorted by decreasing magnitude, only σ[{last}] may be negative (the sign of
                det F).

                {OPTS}
                `f`: {DxD} column-major input, any finite F (det F ≤ 0 included); `u`, `v`:
                {DxD} outputs; `sigma`: {D} values.",
            params: &[
                "opts: *const AmpmOptions",
                "f: *const {T}",
                "u: *mut {T}",
                "sigma: *mut {T}",
                "v: *mut {T}",
            ],
            ret: "AmpmStatus",
            body: "decomp::svd::<Mat<{T}, {D}>>(opts, f, u, sigma, v)",
        },
        Op {
            name: "polar",
            doc: "
                Computes the rotation-variant polar decomposition F = R S: R = U Vᵀ a rotation
                (det +1), S = V Σ Vᵀ symmetric (indefinite when det F < 0).

                {OPTS}
                `f`: {DxD} column-major input, any finite F (det F ≤ 0 included); `r`, `s`:
                {DxD} outputs.",
            params: &[
                "opts: *const AmpmOptions",
                "f: *const {T}",
                "r: *mut {T}",
                "s: *mut {T}",
            ],
            ret: "AmpmStatus",
            body: "decomp::polar::<Mat<{T}, {D}>>(opts, f, r, s)",
        },
    ],
};
