//! Base energies `Ψ(F)` and their derivatives, the inputs of the augmented wrapper.
//!
//! A base energy gives `Ψ`, the first Piola–Kirchhoff stress `A = ∂Ψ/∂F` and the action
//! `C:δF` of its Hessian `C = ∂²Ψ/∂F∂F` (index convention of the seed report:
//! `(C:δF)_ij = C_ijrs δF_rs`). [`crate::augmented`] turns any base energy into the
//! volume-preserving `Ψ̂(F) = Ψ(Jᵃ F)` without knowing which one it is.

mod fixed_corotated;

pub use fixed_corotated::{d_rotation, FixedCorotated, FixedCorotatedState};

use crate::error::Result;
use crate::mat::Matrix;

/// A hyperelastic base energy density `Ψ(F)` (energy per unit reference volume).
pub trait BaseEnergy<M: Matrix> {
    /// What `Ψ`, `A` and `C:δF` share at one `F` (e.g. its polar decomposition).
    type State: Copy + core::fmt::Debug;

    /// Validates the parameters and computes the shared state at `f`.
    fn prepare(&self, f: &M) -> Result<Self::State>;
    /// `Ψ(F)`.
    fn psi(&self, f: &M, st: &Self::State) -> M::Scalar;
    /// `A = ∂Ψ/∂F (F)`.
    fn first_piola(&self, f: &M, st: &Self::State) -> M;
    /// `C:δF`, the Hessian's action on `δF`.
    fn hessian_action(&self, f: &M, st: &Self::State, df: &M) -> M;
}
