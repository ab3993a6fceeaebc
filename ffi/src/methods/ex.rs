//! Generic bodies of the `_ex` kernels (`ampm_*_ex_*`): the default method runs the fast
//! kernels of the entry points without `_ex` (so NULL options give exactly their results),
//! any other method the generic kernels of `ampm_core::augmented` with a [`RuntimeSvd`].

use super::{is_default, options, AmpmOptions, RuntimeSvd};
use crate::abi::{batch, batch_call, binary, check_batch, guard, read_mat, unary};
use crate::status::AmpmStatus;
use ampm_core::augmented::{self, Augmented};
use ampm_core::energy::FixedCorotated;
use ampm_core::polar::SvdMethod;
use ampm_core::{Mat, Matrix};
use core::ptr;

/// The default method runs the same fast kernels as the entry points without `_ex`, so NULL
/// options give exactly their results.
pub(crate) trait Fast: Matrix {
    /// [`crate::fast::kernels`] on the batch instruction set (`batch`) or the scalar path.
    #[allow(clippy::too_many_arguments)]
    unsafe fn fast(
        batch: bool,
        n: usize,
        mu: *const Self::Scalar,
        f: *const Self::Scalar,
        z: *const Self::Scalar,
        ahat: *mut Self::Scalar,
        chat_z: *mut Self::Scalar,
        energy: *mut Self::Scalar,
        first_failed: *mut usize,
    ) -> AmpmStatus;
}

macro_rules! impl_fast {
    ($t:ty, $d:literal) => {
        impl Fast for Mat<$t, $d> {
            unsafe fn fast(
                batch: bool,
                n: usize,
                mu: *const $t,
                f: *const $t,
                z: *const $t,
                ahat: *mut $t,
                chat_z: *mut $t,
                energy: *mut $t,
                first_failed: *mut usize,
            ) -> AmpmStatus {
                let isa = if batch {
                    crate::fast::isa()
                } else {
                    ampm_core::lane::Isa::SCALAR
                };
                crate::fast::kernels::<$t, $d>(
                    isa,
                    n,
                    mu,
                    f,
                    z,
                    ahat,
                    chat_z,
                    energy,
                    false,
                    first_failed,
                )
            }
        }
    };
}
impl_fast!(f32, 2);
impl_fast!(f64, 2);
impl_fast!(f32, 3);
impl_fast!(f64, 3);

/// Body of `ampm_energy_hat_ex_*`.
///
/// # Safety
/// `opts` NULL or valid for one `AmpmOptions`; other non-null pointers valid for their records.
pub(crate) unsafe fn energy_hat_ex<M: Fast>(
    opts: *const AmpmOptions,
    mu: M::Scalar,
    f: *const M::Scalar,
    out: *mut M::Scalar,
) -> AmpmStatus
where
    RuntimeSvd: SvdMethod<M>,
{
    if is_default::<M>(opts) {
        let mu = [mu];
        return M::fast(
            false,
            1,
            mu.as_ptr(),
            f,
            ptr::null(),
            ptr::null_mut(),
            ptr::null_mut(),
            out,
            ptr::null_mut(),
        );
    }
    guard(|| {
        if f.is_null() || out.is_null() {
            return AmpmStatus::AMPM_ERR_NULL_POINTER;
        }
        let m = match options::<M>(opts) {
            Ok(m) => m,
            Err(e) => return e.into(),
        };
        match augmented::psi_hat(&FixedCorotated::with_method(mu, m), &read_mat::<M>(f)) {
            Ok(p) => {
                ptr::write_unaligned(out, p);
                AmpmStatus::AMPM_OK
            }
            Err(e) => e.into(),
        }
    })
}

/// Body of `ampm_ahat_ex_*`.
///
/// # Safety
/// `opts` NULL or valid for one `AmpmOptions`; other non-null pointers valid for their records.
pub(crate) unsafe fn ahat_ex<M: Fast>(
    opts: *const AmpmOptions,
    mu: M::Scalar,
    f: *const M::Scalar,
    out: *mut M::Scalar,
) -> AmpmStatus
where
    RuntimeSvd: SvdMethod<M>,
{
    if is_default::<M>(opts) {
        let mu = [mu];
        return M::fast(
            false,
            1,
            mu.as_ptr(),
            f,
            ptr::null(),
            out,
            ptr::null_mut(),
            ptr::null_mut(),
            ptr::null_mut(),
        );
    }
    unary::<M>(f, out, |f| {
        augmented::ahat(&FixedCorotated::with_method(mu, options::<M>(opts)?), f)
    })
}

/// Body of `ampm_chat_z_ex_*`.
///
/// # Safety
/// `opts` NULL or valid for one `AmpmOptions`; other non-null pointers valid for their records.
pub(crate) unsafe fn chat_z_ex<M: Fast>(
    opts: *const AmpmOptions,
    mu: M::Scalar,
    f: *const M::Scalar,
    z: *const M::Scalar,
    out: *mut M::Scalar,
) -> AmpmStatus
where
    RuntimeSvd: SvdMethod<M>,
{
    if is_default::<M>(opts) {
        let mu = [mu];
        return M::fast(
            false,
            1,
            mu.as_ptr(),
            f,
            z,
            ptr::null_mut(),
            out,
            ptr::null_mut(),
            ptr::null_mut(),
        );
    }
    binary::<M>(f, z, out, |f, z| {
        augmented::chat_z(&FixedCorotated::with_method(mu, options::<M>(opts)?), f, z)
    })
}

/// Body of `ampm_ahat_batch_ex_*`.
///
/// # Safety
/// `opts` NULL or valid for one `AmpmOptions`; other non-null pointers valid for their records.
pub(crate) unsafe fn ahat_batch_ex<M: Fast>(
    opts: *const AmpmOptions,
    n: usize,
    mu: *const M::Scalar,
    f: *const M::Scalar,
    out: *mut M::Scalar,
    first_failed: *mut usize,
) -> AmpmStatus
where
    RuntimeSvd: SvdMethod<M>,
{
    if is_default::<M>(opts) {
        return M::fast(
            true,
            n,
            mu,
            f,
            ptr::null(),
            out,
            ptr::null_mut(),
            ptr::null_mut(),
            first_failed,
        );
    }
    batch_call(first_failed, || {
        check_batch::<M>(n, &[mu.is_null(), f.is_null(), out.is_null()])?;
        let m = options::<M>(opts).map_err(AmpmStatus::from)?;
        Ok(batch::<M>(n, out, |i| {
            let e = FixedCorotated::with_method(ptr::read_unaligned(mu.add(i)), m);
            augmented::ahat(&e, &read_mat::<M>(f.add(i * M::LEN)))
        }))
    })
}

/// Body of `ampm_chat_z_batch_ex_*`.
///
/// # Safety
/// `opts` NULL or valid for one `AmpmOptions`; other non-null pointers valid for their records.
pub(crate) unsafe fn chat_z_batch_ex<M: Fast>(
    opts: *const AmpmOptions,
    n: usize,
    mu: *const M::Scalar,
    f: *const M::Scalar,
    z: *const M::Scalar,
    out: *mut M::Scalar,
    first_failed: *mut usize,
) -> AmpmStatus
where
    RuntimeSvd: SvdMethod<M>,
{
    if is_default::<M>(opts) {
        return M::fast(
            true,
            n,
            mu,
            f,
            z,
            ptr::null_mut(),
            out,
            ptr::null_mut(),
            first_failed,
        );
    }
    batch_call(first_failed, || {
        check_batch::<M>(n, &[mu.is_null(), f.is_null(), z.is_null(), out.is_null()])?;
        let m = options::<M>(opts).map_err(AmpmStatus::from)?;
        Ok(batch::<M>(n, out, |i| {
            let e = FixedCorotated::with_method(ptr::read_unaligned(mu.add(i)), m);
            let zi = read_mat::<M>(z.add(i * M::LEN));
            Augmented::new(&e, &read_mat::<M>(f.add(i * M::LEN)))?.chat_z(&zi)
        }))
    })
}
