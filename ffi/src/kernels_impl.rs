//! Generic bodies of the kernel entry points (fixed corotated base energy, default method).

//!
//! Batch functions use the default method of each dimension, so a batch result equals the
//! single-particle call bit for bit:
//! - 2D: the vectorized closed form of `ampm_core::batch`, dispatched at run time to an AVX2
//!   compiled copy when the CPU has it (bit-identical to the scalar closed form,
//!   `tests/batch.rs`);
//! - 3D: one-sided Jacobi, particle by particle. The vectorized McAdams path of
//!   `ampm_core::batch` was measured only ~1.25× faster than this (tools/benches/batch.rs) at
//!   the price of `O(ε κ²)` small singular values and results that differ from the single
//!   calls, so it is not the default (README, "Choosing a method").

use crate::abi::{
    batch_mu_f, batch_mu_f_z, binary, check_batch, guard, read_mat, unary, write_mat,
};
use crate::status::AmpmStatus;
use ampm_core::augmented;
use ampm_core::batch::{BatchKernel, MAX_LANES};
use ampm_core::energy::FixedCorotated;
use ampm_core::polar::{DefaultSvd, SvdMethod};
use ampm_core::{Matrix, Real};
use core::ptr;

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

pub(crate) unsafe fn energy_hat<M: Matrix>(
    mu: M::Scalar,
    f: *const M::Scalar,
    out: *mut M::Scalar,
) -> AmpmStatus
where
    DefaultSvd: SvdMethod<M>,
{
    guard(|| {
        if f.is_null() || out.is_null() {
            return AmpmStatus::AMPM_ERR_NULL_POINTER;
        }
        match augmented::psi_hat(&FixedCorotated::new(mu), &read_mat::<M>(f)) {
            Ok(p) => {
                ptr::write_unaligned(out, p);
                AmpmStatus::AMPM_OK
            }
            Err(e) => e.into(),
        }
    })
}

pub(crate) unsafe fn ahat<M: Matrix>(
    mu: M::Scalar,
    f: *const M::Scalar,
    out: *mut M::Scalar,
) -> AmpmStatus
where
    DefaultSvd: SvdMethod<M>,
{
    unary::<M>(f, out, |f| augmented::ahat(&FixedCorotated::new(mu), f))
}

pub(crate) unsafe fn chat_z<M: Matrix>(
    mu: M::Scalar,
    f: *const M::Scalar,
    z: *const M::Scalar,
    out: *mut M::Scalar,
) -> AmpmStatus
where
    DefaultSvd: SvdMethod<M>,
{
    binary::<M>(f, z, out, |f, z| {
        augmented::chat_z(&FixedCorotated::new(mu), f, z)
    })
}

/// The chunk loop of the batch functions: reads each chunk of `M::LANES` particles completely
/// (so `out == f` or `out == z` in place is fine), runs the vectorized kernel of
/// `ampm_core::batch`, writes the successful particles and records the first failure.
///
/// # Safety
/// `mu` valid for `n` scalars; `f`, `out` (and `z` when `Some`) for `n·M::LEN` scalars.
#[inline(always)]
unsafe fn run_batch<M: BatchKernel>(
    n: usize,
    mu: *const M::Scalar,
    f: *const M::Scalar,
    z: Option<*const M::Scalar>,
    out: *mut M::Scalar,
    first_failed: *mut usize,
) -> AmpmStatus {
    let mut status = AmpmStatus::AMPM_OK;
    let mut first = n;
    let mut mub = [<M::Scalar as Real>::ZERO; MAX_LANES];
    let mut fb = [M::zero(); MAX_LANES];
    let mut zb = [M::zero(); MAX_LANES];
    let mut ob = [M::zero(); MAX_LANES];
    let mut eb = [None; MAX_LANES];
    let lanes = M::LANES.min(MAX_LANES);
    let mut start = 0;
    while start < n {
        let len = lanes.min(n - start);
        for l in 0..len {
            let i = start + l;
            mub[l] = ptr::read_unaligned(mu.add(i));
            fb[l] = read_mat::<M>(f.add(i * M::LEN));
            if let Some(z) = z {
                zb[l] = read_mat::<M>(z.add(i * M::LEN));
            }
        }
        match z {
            None => M::ahat_chunk(&mub[..len], &fb[..len], &mut ob[..len], &mut eb[..len]),
            Some(_) => M::chat_z_chunk(
                &mub[..len],
                &fb[..len],
                &zb[..len],
                &mut ob[..len],
                &mut eb[..len],
            ),
        }
        for l in 0..len {
            match eb[l] {
                None => write_mat(out.add((start + l) * M::LEN), &ob[l]),
                Some(e) => {
                    if first == n {
                        first = start + l;
                        status = e.into();
                    }
                }
            }
        }
        start += len;
    }
    if !first_failed.is_null() {
        *first_failed = first;
    }
    status
}

/// [`run_batch`] compiled for AVX2 (the same source: LLVM widens the lane loops to 256 bits).
///
/// # Safety
/// As [`run_batch`], and the CPU must support AVX2.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn run_batch_avx2<M: BatchKernel>(
    n: usize,
    mu: *const M::Scalar,
    f: *const M::Scalar,
    z: Option<*const M::Scalar>,
    out: *mut M::Scalar,
    first_failed: *mut usize,
) -> AmpmStatus {
    run_batch::<M>(n, mu, f, z, out, first_failed)
}

/// Runtime dispatch to the AVX2 copy of [`run_batch`] when the CPU supports it. All copies
/// give identical bits (IEEE operations only, no FMA contraction in Rust).
///
/// # Safety
/// As [`run_batch`].
#[inline]
unsafe fn dispatch<M: BatchKernel>(
    n: usize,
    mu: *const M::Scalar,
    f: *const M::Scalar,
    z: Option<*const M::Scalar>,
    out: *mut M::Scalar,
    first_failed: *mut usize,
) -> AmpmStatus {
    #[cfg(target_arch = "x86_64")]
    {
        if std::is_x86_feature_detected!("avx2") {
            // SAFETY: the feature was detected at run time.
            return run_batch_avx2::<M>(n, mu, f, z, out, first_failed);
        }
    }
    run_batch::<M>(n, mu, f, z, out, first_failed)
}

pub(crate) unsafe fn ahat_batch<M: BatchKernel>(
    n: usize,
    mu: *const M::Scalar,
    f: *const M::Scalar,
    out: *mut M::Scalar,
    first_failed: *mut usize,
) -> AmpmStatus {
    guard(|| {
        let st = check_batch::<M>(n, &[mu.is_null(), f.is_null(), out.is_null()]);
        if st != AmpmStatus::AMPM_OK {
            return st;
        }
        dispatch::<M>(n, mu, f, None, out, first_failed)
    })
}

pub(crate) unsafe fn chat_z_batch<M: BatchKernel>(
    n: usize,
    mu: *const M::Scalar,
    f: *const M::Scalar,
    z: *const M::Scalar,
    out: *mut M::Scalar,
    first_failed: *mut usize,
) -> AmpmStatus {
    guard(|| {
        let st = check_batch::<M>(n, &[mu.is_null(), f.is_null(), z.is_null(), out.is_null()]);
        if st != AmpmStatus::AMPM_OK {
            return st;
        }
        dispatch::<M>(n, mu, f, Some(z), out, first_failed)
    })
}

/// `ahat_batch` particle by particle with the default method (3D).
pub(crate) unsafe fn ahat_batch_per_particle<M: Matrix>(
    n: usize,
    mu: *const M::Scalar,
    f: *const M::Scalar,
    out: *mut M::Scalar,
    first_failed: *mut usize,
) -> AmpmStatus
where
    DefaultSvd: SvdMethod<M>,
{
    batch_mu_f::<M>(n, mu, f, out, first_failed, |mu, f| {
        augmented::ahat(&FixedCorotated::new(mu), f)
    })
}

/// `chat_z_batch` particle by particle with the default method (3D).
pub(crate) unsafe fn chat_z_batch_per_particle<M: Matrix>(
    n: usize,
    mu: *const M::Scalar,
    f: *const M::Scalar,
    z: *const M::Scalar,
    out: *mut M::Scalar,
    first_failed: *mut usize,
) -> AmpmStatus
where
    DefaultSvd: SvdMethod<M>,
{
    batch_mu_f_z::<M>(n, mu, f, z, out, first_failed, |mu, f, z| {
        augmented::chat_z(&FixedCorotated::new(mu), f, z)
    })
}
