//! Generic bodies of the 𝓑 entry points (`ampm_b_z_*`, `ampm_z_b_*`). The energy kernels
//! (Ψ̂, Â, Ĉ:Z, single and batch) run on `ampm_core::kernel` through [`crate::fast`].

use crate::abi::binary;
use crate::status::AmpmStatus;
use ampm_core::augmented;
use ampm_core::Matrix;

pub(crate) unsafe fn b_z<M: Matrix>(
    f: *const M::Scalar,
    z: *const M::Scalar,
    out: *mut M::Scalar,
) -> AmpmStatus {
    binary::<M>(f, z, out, |f, z| augmented::b_z(f, z))
}

pub(crate) unsafe fn z_b<M: Matrix>(
    f: *const M::Scalar,
    z: *const M::Scalar,
    out: *mut M::Scalar,
) -> AmpmStatus {
    binary::<M>(f, z, out, |f, z| augmented::z_b(f, z))
}
