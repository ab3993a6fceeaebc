//! Per-particle quantities for a host's own transfers and solves: stencils (weights and their
//! gradients) and pressures with the pressure solve's coefficients.

use super::{Module, Op};

pub const MODULE: Module = Module {
    name: "fields",
    doc: "The C entry points of the per-particle stencils and pressures; the generic bodies are in
        `crate::particle::imp`, the types and their docs in `crate::particle`.",
    uses: &[
        "crate::particle::imp",
        "crate::particle::{AmpmMaterial, AmpmParticles}",
        "crate::status::AmpmStatus",
        "core::ffi::{c_int, c_uint}",
    ],
    ops: &[
        Op {
            name: "stencil",
            doc: "
                Stencils of n particles ({D}D, {T}): B-spline weights and weight gradients, for host-side
                transfers of its own fields. `kernel`: AMPM_KERNEL_*; `grid`: AMPM_GRID_COLLOCATED or a face
                axis 0..d − 1; `h` > 0 (m); `x`: n·{D} positions (m). Writes `base` (n·{D} grid indices of each
                stencil's first node), `weight` (n·K^d) and, if not NULL, `grad_weight` (n·K^d·{D}, 1/m), with
                K^d = 3^d (quadratic) or 4^d (cubic). Node order: node r of a stencil has offsets
                o_a = (r / K^a) mod K (axis 0 fastest) and grid index base + o; weight of node r of particle p
                at [K^d·p + r], its gradient component a at [(K^d·p + r)·{D} + a]. Batch contract.

                `n`: number of particles. `first_failed`: index of the first failed particle (n if none; 0 after a whole-call error; may be NULL).",
            params: &[
                "kernel: c_uint",
                "grid: c_int",
                "h: {T}",
                "n: usize",
                "x: *const {T}",
                "base: *mut c_int",
                "weight: *mut {T}",
                "grad_weight: *mut {T}",
                "first_failed: *mut usize",
            ],
            ret: "AmpmStatus",
            body: "imp::stencil::<{T}, {D}>(kernel, grid, h, n, x, base, weight, grad_weight, first_failed)",
        },
        Op {
            name: "pressure",
            doc: "
                Particle pressures and pressure-solve coefficients of n particles ({D}D, {T}) for a host's
                Chorin pressure solve (Stomakhin et al. 2014, §5): `pressure` (n, Pa, may be NULL) gets
                p = −λ (J_E − 1)/J_P (needs 1/λ > 0); `coefficient` (n, 1/(Pa·s), may be NULL) gets
                J_P/(dt λ J_E), 0 for an incompressible particle, with the hardened λ of a plastic solid.
                Reads f_e, f_p, volume0, phase (and latent with PHASE_CHANGE). Batch contract.

                `material`: the model and its parameters (AmpmMaterial). `dt`: as documented above. `n`: number of particles. `particles`: the particle arrays (AmpmParticles). `first_failed`: index of the first failed particle (n if none; 0 after a whole-call error; may be NULL).",
            params: &[
                "material: *const AmpmMaterial<{T}>",
                "dt: {T}",
                "n: usize",
                "particles: *const AmpmParticles<{T}>",
                "pressure: *mut {T}",
                "coefficient: *mut {T}",
                "first_failed: *mut usize",
            ],
            ret: "AmpmStatus",
            body: "imp::pressure::<{T}, {D}>(material, dt, n, particles, pressure, coefficient, first_failed)",
        },
    ],
};
