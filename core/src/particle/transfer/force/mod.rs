//! The force differential of an implicit step through a grid view: [`prepare()`] once per Newton
//! step, [`apply()`] once per Krylov iteration (the math is in [`crate::particle::implicit`]).
//!
//! `apply` maps node displacements `δu_j` (m; `Δt δv_j` for backward Euler) to node force
//! differentials `δf_i = Σ_p M_p ∇w_ip` (N), `M_p = 𝒜_p(Σ_j δu_j ∇w_jpᵀ)`, scatter-added into the
//! `df` channels: the host zeroes them before the call. This is `δf = K δu` with the stiffness
//! `K = ∂f/∂x` (symmetric; negative semi-definite with the projected Hessian). A backward-Euler
//! step solves `(M − Δt² K) v = M v* + Δt f` on the grid: the host's operator is
//! `v ↦ m_i v_i − Δt · apply(Δt v)_i`.
//!
//! [`prepare()`] is in `prepare.rs`, [`apply()`] in `apply.rs`.

use super::{InChannel, NodeBox, OutChannel};

mod apply;
mod prepare;

pub use apply::apply;
pub use prepare::prepare;

/// The channels of the force differential: displacements read, force differentials added.
#[derive(Clone, Copy, Debug)]
pub struct ForceView<T, const D: usize> {
    /// The nodes the channels cover.
    pub nodes: NodeBox<D>,
    /// Node displacements `δu` per axis (m).
    pub du: [InChannel<T, D>; D],
    /// Node force differentials `δf` per axis (N), scatter-added.
    pub df: [OutChannel<T, D>; D],
}
