//! Generic bodies of the kernel entry points (fixed corotated base energy, default method).

use crate::abi::{batch, binary, check_batch, guard, read_mat, unary};
use crate::status::AmpmStatus;
use ampm_core::augmented::{self, Augmented};
use ampm_core::energy::FixedCorotated;
use ampm_core::polar::{DefaultSvd, SvdMethod};
use ampm_core::Matrix;
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

pub(crate) unsafe fn ahat_batch<M: Matrix>(
    n: usize,
    mu: *const M::Scalar,
    f: *const M::Scalar,
    out: *mut M::Scalar,
    first_failed: *mut usize,
) -> AmpmStatus
where
    DefaultSvd: SvdMethod<M>,
{
    guard(|| {
        let st = check_batch::<M>(n, &[mu.is_null(), f.is_null(), out.is_null()]);
        if st != AmpmStatus::AMPM_OK {
            return st;
        }
        batch::<M>(n, out, first_failed, |i| {
            let e = FixedCorotated::new(ptr::read_unaligned(mu.add(i)));
            augmented::ahat(&e, &read_mat::<M>(f.add(i * M::LEN)))
        })
    })
}

pub(crate) unsafe fn chat_z_batch<M: Matrix>(
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
    guard(|| {
        let st = check_batch::<M>(n, &[mu.is_null(), f.is_null(), z.is_null(), out.is_null()]);
        if st != AmpmStatus::AMPM_OK {
            return st;
        }
        batch::<M>(n, out, first_failed, |i| {
            let e = FixedCorotated::new(ptr::read_unaligned(mu.add(i)));
            let zi = read_mat::<M>(z.add(i * M::LEN));
            Augmented::new(&e, &read_mat::<M>(f.add(i * M::LEN)))?.chat_z(&zi)
        })
    })
}
