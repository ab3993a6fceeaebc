//! The implicit force differential: prepare once per Newton step, apply once per Krylov
//! iteration.

use super::{Module, Op};

pub const MODULE: Module = Module {
    name: "force",
    doc: "The C entry points of the implicit force differential; the generic bodies are in
        `crate::particle::imp`, the types and their docs in `crate::particle`.",
    uses: &[
        "crate::particle::imp",
        "crate::particle::{AmpmForceView, AmpmMaterial, AmpmParticles}",
        "crate::status::AmpmStatus",
        "core::ffi::c_uint",
    ],
    ops: &[
        Op {
            name: "force_prepare",
            doc: "
                Prepares the implicit force differential of n particles ({D}D, {T}), once per Newton step:
                writes n·AMPM_FORCE_SLOT_LEN_{D}D scalars to `slots` (opaque). Reads f_e, f_p, volume0, phase
                (and latent with PHASE_CHANGE); positions are not read. Uses the exact Hessian, or with
                AMPM_MODEL_PSD_HESSIAN its projection onto the negative semi-definite part of the whole force
                differential (dilational part included). Stiffness terms use SIMD lanes of ampm_isa().

                A failed particle's slot is marked (its first scalar set to 0) so that ampm_force_apply_*
                refuses it with AMPM_ERR_NOT_PREPARED; zero-filled memory is refused the same way.
                Whole-call errors: nothing written, *first_failed = 0.

                `material`: the model and its parameters (AmpmMaterial). `n`: number of particles. `particles`: the particle arrays (AmpmParticles). `first_failed`: index of the first failed particle (n if none; 0 after a whole-call error; may be NULL).",
            params: &[
                "material: *const AmpmMaterial<{T}>",
                "n: usize",
                "particles: *const AmpmParticles<{T}>",
                "slots: *mut {T}",
                "first_failed: *mut usize",
            ],
            ret: "AmpmStatus",
            body: "imp::force_prepare::<{T}, {D}>(material, n, particles, slots, first_failed)",
        },
        Op {
            name: "force_apply",
            doc: "
                Applies the prepared force differential of n particles ({D}D, {T}), once per Krylov iteration:
                df_i += Σ_p M_p ∇w_ip with M_p = 𝒜_p(Σ_j du_j ∇w_jpᵀ): the linearisation, for node
                displacements du (m), of the grid force of Stomakhin et al. 2013 (eq. 6),
                f_i(x̂) = −Σ_p V0_p P(F̂_p) F_E,pᵀ ∇w_ip with F̂_p = (I + Σ_j (x̂_j − x_j) ∇w_jpᵀ) F_E,p and
                F_E,p, ∇w held at the prepared state. That is df = K du with the stiffness K = ∂f/∂x̂ (the
                negative Hessian of the elastic energy): symmetric, and negative semi-definite with
                AMPM_MODEL_PSD_HESSIAN.

                `x`: the n·{D} particle positions (m) of the Newton step (the stencils); `kernel`, `h` as
                ampm_p2g_{D}d_{T} (collocated grid); `slots` from ampm_force_prepare_{D}d_{T}; `view`: du and df
                channels, all required; the host zeroes df first.

                Backward Euler (Stomakhin et al. 2013, §4.2): with grid masses m_i, velocities v* = v^n +
                dt f^n/m and x̂ = x + dt v, solve (M − dt² K) v^(n+1) = M v*, i.e. for each CG iteration the
                operator is (A v)_i = m_i v_i − dt·df_i with df = apply(du = dt·v). With the PSD option
                A is symmetric positive definite wherever m_i > 0. Per particle (batch contract):
                AMPM_ERR_NOT_PREPARED, AMPM_ERR_OUTSIDE_GRID, AMPM_ERR_NON_FINITE for a non-finite du read,
                AMPM_ERR_OVERFLOW for a df that would not be finite (node sums per run of nearby particles,
                as ampm_p2g_{D}d_{T}); a failed particle writes nothing.

                `n`: number of particles. `first_failed`: index of the first failed particle (n if none; 0 after a whole-call error; may be NULL).",
            params: &[
                "kernel: c_uint",
                "h: {T}",
                "n: usize",
                "x: *const {T}",
                "slots: *const {T}",
                "view: *const AmpmForceView<{T}>",
                "first_failed: *mut usize",
            ],
            ret: "AmpmStatus",
            body: "imp::force_apply::<{T}, {D}>(kernel, h, n, x, slots, view, first_failed)",
        },
    ],
};
