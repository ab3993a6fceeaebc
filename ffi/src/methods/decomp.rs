//! Generic bodies of the decompositions with a run-time method choice (`ampm_svd_*`,
//! `ampm_polar_*`).

use super::{options, AmpmOptions, RuntimeSvd};
use crate::abi::{guard, read_mat, write_mat};
use crate::status::AmpmStatus;
use ampm_core::polar::SvdMethod;
use ampm_core::Matrix;
use core::ptr;

/// Body of `ampm_svd_*`.
///
/// # Safety
/// `opts` NULL or valid for one `AmpmOptions`; other non-null pointers valid for one record.
pub(crate) unsafe fn svd<M: Matrix>(
    opts: *const AmpmOptions,
    f: *const M::Scalar,
    u: *mut M::Scalar,
    sigma: *mut M::Scalar,
    v: *mut M::Scalar,
) -> AmpmStatus
where
    RuntimeSvd: SvdMethod<M>,
{
    guard(|| {
        if f.is_null() || u.is_null() || sigma.is_null() || v.is_null() {
            return AmpmStatus::AMPM_ERR_NULL_POINTER;
        }
        let m = match options::<M>(opts) {
            Ok(m) => m,
            Err(e) => return e.into(),
        };
        match m.svd(&read_mat::<M>(f)) {
            Ok(s) => {
                write_mat(u, &s.u);
                for i in 0..M::DIM {
                    ptr::write_unaligned(sigma.add(i), s.sigma[i]);
                }
                write_mat(v, &s.v);
                AmpmStatus::AMPM_OK
            }
            Err(e) => e.into(),
        }
    })
}

/// Body of `ampm_polar_*`.
///
/// # Safety
/// `opts` NULL or valid for one `AmpmOptions`; other non-null pointers valid for one record.
pub(crate) unsafe fn polar<M: Matrix>(
    opts: *const AmpmOptions,
    f: *const M::Scalar,
    r: *mut M::Scalar,
    s: *mut M::Scalar,
) -> AmpmStatus
where
    RuntimeSvd: SvdMethod<M>,
{
    guard(|| {
        if f.is_null() || r.is_null() || s.is_null() {
            return AmpmStatus::AMPM_ERR_NULL_POINTER;
        }
        let m = match options::<M>(opts) {
            Ok(m) => m,
            Err(e) => return e.into(),
        };
        match m.svd(&read_mat::<M>(f)) {
            Ok(d) => {
                let (rot, st) = (d.rotation(), d.stretch());
                if !(rot.is_finite() && st.is_finite()) {
                    return AmpmStatus::AMPM_ERR_OVERFLOW;
                }
                write_mat(r, &rot);
                write_mat(s, &st);
                AmpmStatus::AMPM_OK
            }
            Err(e) => e.into(),
        }
    })
}
