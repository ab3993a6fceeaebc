//! The kernels over batches of particles: Â and Ĉ:Z on the SIMD lanes.

use super::{Module, Op};

pub const MODULE: Module = Module {
    name: "kernels_batch",
    doc: "The C entry points of the batch kernels: Â and Ĉ:Z of n particles on the SIMD lanes
        of the instruction set of `ampm_isa`, through `crate::fast`.",
    uses: &["crate::fast", "crate::status::AmpmStatus", "core::ptr"],
    ops: &[
        Op {
            name: "ahat_batch",
            doc: "
                Computes Â for n particles: out[i] = Â(mu[i], F[i]) (see ampm_ahat_{sfx}).

                `n`: number of particles; `mu`: n values (Pa, ≥ 0); `f`, `out`: n {DxD}
                column-major matrices back to back ({DD} scalars each; `out` may be `f`).

                {BATCH}",
            params: &[
                "n: usize",
                "mu: *const {T}",
                "f: *const {T}",
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
                    ptr::null(),
                    out,
                    ptr::null_mut(),
                    ptr::null_mut(),
                    false,
                    first_failed,
                )",
        },
        Op {
            name: "chat_z_batch",
            doc: "
                Computes Ĉ:Z for n particles: out[i] = Ĉ(mu[i], F[i]):Z[i] (see
                ampm_chat_z_{sfx}).

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
                    false,
                    first_failed,
                )",
        },
    ],
};
