//! Generic bodies of the entry points that run on the fast kernels of `ampm_core::kernel`
//! (fixed corotated, default decomposition): the batch calls on the widest instruction set of
//! the CPU (detected once, or chosen with `ampm_set_isa`), the single-particle calls on the
//! scalar instantiation of the same source.

use crate::abi::batch_call;
use crate::status::AmpmStatus;
use ampm_core::kernel::batch::{
    apply_raw, kernels_raw, prepare_raw, ApplyArgs, BatchReal, BatchStatus, KernelArgs, PrepareArgs,
};
use ampm_core::kernel::{prepared, Dim, LaneDim};
use ampm_core::lane::{Isa, IsaKind};
use core::ptr;
use std::sync::atomic::{AtomicU8, Ordering};

/// The instruction set of the batch calls: 0 = not chosen yet, else [`encode`]d. Each batch
/// call decodes it instead of detecting again: detection runs `cpuid`, which a virtual machine
/// traps (7.6 µs measured on a cloud VM, as long as P2G and G2P of about 100 particles).
static ISA: AtomicU8 = AtomicU8::new(0);

/// The [`IsaKind`]s in the order of their `AMPM_ISA_*` values (0, 1, 2).
const KINDS: [IsaKind; 3] = [IsaKind::Scalar, IsaKind::Avx2, IsaKind::Avx512];

/// `AMPM_ISA_*` value of an [`IsaKind`].
fn code(k: IsaKind) -> u32 {
    KINDS.iter().position(|&x| x == k).unwrap_or(0) as u32
}

/// `1 + AMPM_ISA_*` in bits 0–1, [`Isa::joined_rows`] in bit 2, [`Isa::narrow_chunks`] in
/// bit 3 (never 0).
fn encode(i: Isa) -> u8 {
    (code(i.kind()) as u8 + 1) | u8::from(i.joined_rows()) << 2 | u8::from(i.narrow_chunks()) << 3
}

/// The [`Isa`] of a non-zero [`encode`] value.
fn decode(c: u8) -> Isa {
    let kind = KINDS[usize::from(c & 3).saturating_sub(1)];
    // SAFETY: every value stored in `ISA` encodes an `Isa` that `Isa::available` returned, so
    // the CPU supports its instructions.
    unsafe { Isa::assume(kind) }
        .with_joined_rows(c & 4 != 0)
        .with_narrow_chunks(c & 8 != 0)
}

/// The instruction set the batch calls use: the widest this CPU supports, detected on first
/// use, unless `ampm_set_isa` chose another.
pub(crate) fn isa() -> Isa {
    let c = ISA.load(Ordering::Relaxed);
    if c != 0 {
        return decode(c);
    }
    let best = Isa::available().last().copied().unwrap_or(Isa::SCALAR);
    ISA.store(encode(best), Ordering::Relaxed);
    best
}

/// Body of `ampm_set_isa`.
pub(crate) fn set_isa(isa: u32) -> AmpmStatus {
    match Isa::available().into_iter().find(|i| code(i.kind()) == isa) {
        Some(i) => {
            ISA.store(encode(i), Ordering::Relaxed);
            AmpmStatus::AMPM_OK
        }
        None => AmpmStatus::AMPM_ERR_INVALID_ARGUMENT,
    }
}

/// Body of `ampm_isa`.
pub(crate) fn current_isa() -> u32 {
    code(isa().kind())
}

/// `n` records of `w` scalars of `T` are addressable.
fn size_ok<T>(n: usize, w: usize) -> bool {
    n.checked_mul(w * core::mem::size_of::<T>())
        .is_some_and(|b| b <= isize::MAX as usize)
}

/// The outcome of the records of a batch, for [`batch_call`].
fn finish(st: BatchStatus) -> Result<(AmpmStatus, usize), AmpmStatus> {
    Ok((
        st.error.map_or(AmpmStatus::AMPM_OK, Into::into),
        st.first_failed,
    ))
}

/// A batch of the kernels: `Â`, `Ĉ:Z`/`Ĉ⁺:Z`, `Ψ̂`, each output optional (null), at least one
/// requested; `z` required with `chat_z`. Follows the batch contract of [`batch_call`].
///
/// # Safety
/// Non-null pointers valid for `n` records.
#[allow(clippy::too_many_arguments)]
pub(crate) unsafe fn kernels<T: BatchReal, const D: usize>(
    isa: Isa,
    n: usize,
    mu: *const T,
    f: *const T,
    z: *const T,
    ahat: *mut T,
    chat_z: *mut T,
    energy: *mut T,
    psd: bool,
    first_failed: *mut usize,
) -> AmpmStatus
where
    Dim<D>: LaneDim<D>,
{
    batch_call(first_failed, || {
        let no_output = ahat.is_null() && chat_z.is_null() && energy.is_null();
        if n > 0 && (no_output || mu.is_null() || f.is_null() || (!chat_z.is_null() && z.is_null()))
        {
            return Err(AmpmStatus::AMPM_ERR_NULL_POINTER);
        }
        if !size_ok::<T>(n, D * D) {
            return Err(AmpmStatus::AMPM_ERR_INVALID_ARGUMENT);
        }
        let args = KernelArgs {
            n,
            mu,
            f,
            z,
            ahat,
            chat_z,
            energy,
            psd,
        };
        finish(kernels_raw::<T, D>(isa, args))
    })
}

/// One particle through the scalar instantiation: `Â`, `Ĉ:Z`/`Ĉ⁺:Z` or `Ψ̂` (exactly one
/// output non-null). Writes only on success.
///
/// # Safety
/// Non-null pointers valid for one record.
#[allow(clippy::too_many_arguments)]
pub(crate) unsafe fn single<T: BatchReal, const D: usize>(
    mu: T,
    f: *const T,
    z: *const T,
    ahat: *mut T,
    chat_z: *mut T,
    energy: *mut T,
    psd: bool,
) -> AmpmStatus
where
    Dim<D>: LaneDim<D>,
{
    let mu = [mu];
    kernels::<T, D>(
        Isa::SCALAR,
        1,
        mu.as_ptr(),
        f,
        z,
        ahat,
        chat_z,
        energy,
        psd,
        ptr::null_mut(),
    )
}

/// Body of `ampm_hessian_prepare_batch_*`.
///
/// # Safety
/// Non-null pointers valid for `n` records.
pub(crate) unsafe fn prepare<T: BatchReal, const D: usize>(
    n: usize,
    mu: *const T,
    f: *const T,
    ahat: *mut T,
    prep: *mut T,
    first_failed: *mut usize,
) -> AmpmStatus
where
    Dim<D>: LaneDim<D>,
{
    batch_call(first_failed, || {
        if n > 0 && (mu.is_null() || f.is_null() || prep.is_null()) {
            return Err(AmpmStatus::AMPM_ERR_NULL_POINTER);
        }
        if !size_ok::<T>(n, prepared::len(D)) {
            return Err(AmpmStatus::AMPM_ERR_INVALID_ARGUMENT);
        }
        let args = PrepareArgs {
            n,
            mu,
            f,
            ahat,
            prepared: prep,
        };
        finish(prepare_raw::<T, D>(isa(), args))
    })
}

/// Body of `ampm_hessian_apply_batch_*`.
///
/// # Safety
/// Non-null pointers valid for `n` records.
pub(crate) unsafe fn apply<T: BatchReal, const D: usize>(
    n: usize,
    prep: *const T,
    z: *const T,
    out: *mut T,
    psd: bool,
    first_failed: *mut usize,
) -> AmpmStatus
where
    Dim<D>: LaneDim<D>,
{
    batch_call(first_failed, || {
        if n > 0 && (prep.is_null() || z.is_null() || out.is_null()) {
            return Err(AmpmStatus::AMPM_ERR_NULL_POINTER);
        }
        if !size_ok::<T>(n, prepared::len(D)) {
            return Err(AmpmStatus::AMPM_ERR_INVALID_ARGUMENT);
        }
        let args = ApplyArgs {
            n,
            prepared: prep,
            z,
            out,
            psd,
        };
        finish(apply_raw::<T, D>(isa(), args))
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every instruction set of this CPU survives the stored form with its joined-rows and
    /// narrow-chunks flags, every value of the flags round-trips, and `set_isa` then `isa`
    /// gives back what `Isa::available` listed (the choice is restored afterwards).
    #[test]
    fn stored_isa_round_trips() {
        for i in Isa::available() {
            assert_eq!(decode(encode(i)), i);
            for joined in [false, true] {
                for narrow in [false, true] {
                    let j = i.with_joined_rows(joined).with_narrow_chunks(narrow);
                    assert_eq!(decode(encode(j)), j);
                }
            }
        }
        let before = isa();
        for i in Isa::available() {
            assert_eq!(set_isa(code(i.kind())), AmpmStatus::AMPM_OK);
            assert_eq!(isa(), i);
            assert_eq!(current_isa(), code(i.kind()));
        }
        assert_eq!(set_isa(code(before.kind())), AmpmStatus::AMPM_OK);
        assert_eq!(isa(), before);
    }
}
