//! # ampm (C ABI)
//!
//! Builds `libampm.a` and `libampm.so`. Every entry point is named
//! `ampm_<op>_<2d|3d>_<f32|f64>`, checks its pointers, returns an [`AmpmStatus`], and never
//! lets a panic cross into C. A single call writes only on success; a batch call computes every
//! valid record, leaves a failed record's outputs untouched and reports the first failure; a
//! whole-call error writes nothing (the contracts are stated in `include/ampm.h`). Matrices are
//! column-major: `F[i + d·j] = F_ij`, the layout of Eigen and glam.
//! The header `include/ampm.h` is generated from this crate by cbindgen (see `tests/header.rs`).

mod abi;
mod fast;
mod generated;
pub mod hessian;
pub mod kernels;
mod kernels_impl;
pub mod methods;
pub mod particle;
pub mod prepared;
pub mod status;

pub use kernels::*;
pub use prepared::*;
pub use status::AmpmStatus;
