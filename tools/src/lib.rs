//! Shared by the report binary, the benchmarks and the integration tests:
//! the double-double reference, the families of test matrices and the charts' font.
#![deny(missing_docs)]

pub mod families;
pub mod font;
pub mod reference;
pub mod stability;
pub mod workload;
