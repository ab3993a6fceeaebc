//! Shared by the report binary, the benchmarks and the integration tests:
//! the double-double reference and the families of test matrices.
#![deny(missing_docs)]

pub mod families;
pub mod reference;
pub mod stability;
pub mod workload;
