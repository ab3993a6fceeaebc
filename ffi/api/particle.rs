//! The MPM particle transfers through the host's grid views: P2G, G2P with the particle
//! update (collocated and MAC grids), and the node box a batch reaches.

use super::{Module, Op};

pub const MODULE: Module = Module {
    name: "particle",
    doc: "The C entry points of the MPM particle transfers; the generic bodies are in
        `crate::particle::imp`, the types and their docs in `crate::particle`.",
    uses: &[
        "crate::particle::imp",
        "crate::particle::{AmpmG2pView, AmpmMaterial, AmpmP2gView, AmpmParticles}",
        "crate::status::AmpmStatus",
        "core::ffi::{c_int, c_uint}",
    ],
    ops: &[
        Op {
            name: "p2g",
            doc: "
                P2G of n particles ({D}D, {T}) into the host's grid: scatter-adds node mass, APIC momentum,
                stress force and heat into the channels of `view` (see AmpmP2gView for every formula).

                `kernel`: AMPM_KERNEL_*; `grid`: AMPM_GRID_COLLOCATED or a MAC face axis 0..d − 1; `h` > 0:
                grid spacing (m); `impulse_dt` ≥ 0 (s): the momentum channels also receive impulse_dt·f_i (0
                for plain momentum; dt for the symplectic-Euler form m v* + dt f, so the host needs no force
                channel); `particles`: reads x, v, affine, f_e, f_p, mass, volume0, temperature (THERMAL),
                phase (if not NULL; required with PHASE_CHANGE), latent (PHASE_CHANGE); writes nothing.
                Stresses use SIMD lanes of the instruction set of ampm_isa(); a particle's stress and node
                contributions do not depend on its position in the batch.

                Node sums (also ampm_force_apply_*): a run of consecutive particles whose stencils fit in one
                block of 8 × (K + 1)^(d − 1) nodes (K nodes per axis; at most 48 particles) is summed in a
                local block first and the block is added to the grid once, so the rounding of a node value
                depends on the batch order. Sorting particles by cell (axis 0 fastest) makes runs long and
                the call fast; any order gives the same sums to rounding.

                Per particle (batch contract): AMPM_ERR_OUTSIDE_GRID if its stencil leaves view->nodes;
                AMPM_ERR_OVERFLOW if adding it makes a node value non-finite: when a run's block would write a
                non-finite value, the grid is left as it was and the run's particles are added one at a time,
                which refuses exactly those; a run whose block sum is finite is accepted even where adding
                its particles one at a time would pass through a non-finite value (huge opposite
                contributions). The particle errors of AmpmParticles and the kernels; a failed particle
                writes nothing.
                Whole-call errors (NULL material, particles, view or a particle array the material needs;
                bad kernel, grid, h, impulse_dt; dims < 0; n too large): nothing written, *first_failed = 0.
                Threads: concurrent calls are safe when the nodes they write do not overlap.

                `material`: the model and its parameters (AmpmMaterial). `n`: number of particles. `first_failed`: index of the first failed particle (n if none; 0 after a whole-call error; may be NULL).",
            params: &[
                "material: *const AmpmMaterial<{T}>",
                "kernel: c_uint",
                "grid: c_int",
                "h: {T}",
                "impulse_dt: {T}",
                "n: usize",
                "particles: *const AmpmParticles<{T}>",
                "view: *const AmpmP2gView<{T}>",
                "first_failed: *mut usize",
            ],
            ret: "AmpmStatus",
            body: "imp::p2g::<{T}, {D}>(material, kernel, grid, h, impulse_dt, n, particles, view, first_failed)",
        },
        Op {
            name: "g2p_update",
            doc: "
                G2P and particle update of n particles ({D}D, {T}) from the host's collocated grid.

                Per particle: v_p = Σ w_i v_i, C_p = Σ w_i v_i (x_i − x_p)ᵀ / (κ h²) (κ = 1/4 quadratic, 1/3
                cubic), ∇v_p = Σ v_i ∇w_iᵀ; with THERMAL T* = (1 − α) Σ w_i T_i^(n+1) + α (T_p + Σ w_i (T_i^(n+1) −
                T_i^n)), and with PHASE_CHANGE the heat c (T* − T_p) goes through the latent buffer and may
                switch the phase; x_p += dt v_p; F_E ← (I + dt ∇v_p) F_E, replaced by (I + 2^-k dt ∇v_p)^(2^k)
                with the smallest k ≥ 1 (at most 64) giving det > 0 when det(I + dt ∇v_p) ≤ 0; then a liquid
                sets F_E = J_E^(1/d) I, F_P = J_P^(1/d) I, and a plastic solid clamps the singular values of
                F_E.

                `kernel`: AMPM_KERNEL_*; `h` > 0 (m); `dt` > 0 (s); `view`: velocities (required) and, with
                THERMAL, temperatures (required). Reads and writes x, v, affine, f_e, f_p; temperature
                (THERMAL); latent and phase (PHASE_CHANGE); reads mass, volume0. Under AMPM_ISA_AVX512 this
                call runs its AVX2 code, which measured faster (same results; its lanes are eight wide either way).

                Per particle (batch contract): AMPM_ERR_OUTSIDE_GRID; AMPM_ERR_NON_FINITE for a non-finite
                node value it reads; AMPM_ERR_OVERFLOW for a result that is not representable (including
                1/(κ h²)); AMPM_ERR_NON_POSITIVE_J when the update would leave det F_E or det F_P not positive;
                a failed particle keeps its state, and every particle updated with success is accepted by the
                next call. Whole-call errors (NULL pointers the call needs, bad kernel, h, dt): nothing
                written, *first_failed = 0. Threads: concurrent calls on disjoint particles are safe.

                `material`: the model and its parameters (AmpmMaterial). `n`: number of particles. `particles`: the particle arrays (AmpmParticles). `first_failed`: index of the first failed particle (n if none; 0 after a whole-call error; may be NULL).",
            params: &[
                "material: *const AmpmMaterial<{T}>",
                "kernel: c_uint",
                "h: {T}",
                "dt: {T}",
                "n: usize",
                "particles: *const AmpmParticles<{T}>",
                "view: *const AmpmG2pView<{T}>",
                "first_failed: *mut usize",
            ],
            ret: "AmpmStatus",
            body: "imp::g2p_update::<{T}, {D}>(material, kernel, h, dt, n, particles, view, core::ptr::null(), false, first_failed)",
        },
        Op {
            name: "g2p_update_mac",
            doc: "
                G2P and particle update of n particles ({D}D, {T}) from a MAC grid: as ampm_g2p_update_{D}d_{T},
                but velocity component a, row a of C_p and row a of ∇v_p come from face grid a with its own
                stencil: `faces` points to {D} views, faces[a] covering face grid a (nodes at i·h along a,
                (j + 1/2)·h along the other axes) with faces[a].velocity[a] required (the other channels of
                faces[a] are not read). `thermal`: the collocated view of the temperatures, required with
                THERMAL (its velocities are not read), else may be NULL.

                `material`: the model and its parameters (AmpmMaterial). `kernel`: as documented above. `h`: as documented above. `dt`: as documented above. `n`: number of particles. `particles`: the particle arrays (AmpmParticles). `first_failed`: index of the first failed particle (n if none; 0 after a whole-call error; may be NULL).",
            params: &[
                "material: *const AmpmMaterial<{T}>",
                "kernel: c_uint",
                "h: {T}",
                "dt: {T}",
                "n: usize",
                "particles: *const AmpmParticles<{T}>",
                "faces: *const AmpmG2pView<{T}>",
                "thermal: *const AmpmG2pView<{T}>",
                "first_failed: *mut usize",
            ],
            ret: "AmpmStatus",
            body: "imp::g2p_update::<{T}, {D}>(material, kernel, h, dt, n, particles, thermal, faces, true, first_failed)",
        },
        Op {
            name: "node_range",
            doc: "
                The box of grid nodes that the stencils of n ≥ 1 particles ({D}D, {T}) reach: writes lo[a]
                and hi[a] (a < {D}, inclusive) so that a view with nodes.lo = lo, nodes.dims = hi − lo + 1
                covers them. `x`: n·{D} positions (m); `kernel`, `grid`, `h` as ampm_p2g_{D}d_{T}.

                A host running P2G on several threads sorts its particles by cell, calls this per particle
                range, and gives each thread a view of its own block (then adds the overlapping borders), or
                runs blocks at least K cells apart at the same time. On a particle error nothing is written
                and its index goes to *first_failed; n = 0 or NULL pointers are whole-call errors.

                `n`: number of particles. `lo`: {D} grid indices (output). `hi`: {D} grid indices (output). `first_failed`: index of the first failed particle (n if none; 0 after a whole-call error; may be NULL).",
            params: &[
                "kernel: c_uint",
                "grid: c_int",
                "h: {T}",
                "n: usize",
                "x: *const {T}",
                "lo: *mut i32",
                "hi: *mut i32",
                "first_failed: *mut usize",
            ],
            ret: "AmpmStatus",
            body: "imp::node_range::<{T}, {D}>(kernel, grid, h, n, x, lo, hi, first_failed)",
        },
    ],
};
