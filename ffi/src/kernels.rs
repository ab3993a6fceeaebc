//! The C entry points of the kernels: the actions of 𝓑(F) (`ampm_b_z_*`, `ampm_z_b_*`) and the
//! fixed corotated Ψ̂, Â, Ĉ:Z, single and batch, for every dimension × precision.
//!
//! The `extern "C"` wrappers are rendered from `ffi/api/kernels.rs` (one point) and
//! `ffi/api/kernels_batch.rs` (batches) into `generated/` (cbindgen does not expand macros, so
//! they are written out there, and the header's documentation of each comes from that one
//! description). Their bodies are in `kernels_impl` (𝓑) and `fast` (the energy kernels on
//! `ampm_core::kernel`).

pub use crate::generated::kernels::*;
pub use crate::generated::kernels_batch::*;
