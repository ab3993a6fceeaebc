//! # ampm-core
//!
//! Constitutive kernels and particle updates of *augmented MPM* (Stomakhin, Schroeder, Jiang,
//! Chai, Teran, Selle, SIGGRAPH 2014), `no_std` and allocation-free.
//!
//! - [`mat`]: fixed-size column-major matrices `Mat<T, D>` (`D` = 2, 3; `T` = f32, f64),
//!   convertible to and from glam's `Mat2`, `Mat3`, `DMat2`, `DMat3`.
//! - [`polar`]: rotation-variant SVD / polar decompositions (the method is a type parameter).
//! - [`energy`]: base energies (fixed corotated) behind the [`energy::BaseEnergy`] trait.
//! - [`augmented`]: the volume-preserving `Ψ̂(F) = Ψ(Jᵃ F)`, `a = −1/d`, and its derivatives
//!   `𝓑:Z`, `Z:𝓑`, `Â`, `Ĉ:Z`, over any base energy.
//!
//! Every kernel returns a finite result or an [`Error`]; none panics on any input.
//!
//! ```
//! use ampm_core::{augmented, energy::FixedCorotated, Mat3};
//! let f = Mat3::<f64>::from_rows([[1.1, 0.1, 0.0], [0.0, 0.9, 0.2], [0.0, 0.0, 1.0]]);
//! let e = FixedCorotated::new(10.0);
//! let st = augmented::Augmented::new(&e, &f).unwrap();
//! let ahat = st.ahat().unwrap();
//! // Ψ̂ is invariant under F → sF, so F:Â = 0.
//! assert!(f.ddot(&ahat).abs() < 1e-12);
//! ```
#![no_std]
#![deny(missing_docs)]

#[cfg(feature = "std")]
extern crate std;

pub mod augmented;
pub mod energy;
pub mod error;
pub mod hessian;
pub mod kernel;
pub mod lane;
pub mod mat;
pub mod particle;
pub mod polar;
pub mod scalar;

pub use error::{Error, Result};
pub use mat::{Mat, Mat2, Mat3, Matrix};
pub use scalar::Real;
