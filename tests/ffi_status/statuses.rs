//! Every reachable status, and the documented status values.
//!
//! Reachable statuses: `AMPM_OK`, `AMPM_ERR_NULL_POINTER`, `AMPM_ERR_NON_FINITE`,
//! `AMPM_ERR_NON_POSITIVE_J`, `AMPM_ERR_OVERFLOW`, `AMPM_ERR_INVALID_ARGUMENT` are each
//! produced below ([`every_reachable_status`] collects them). Not reachable today:
//! `AMPM_ERR_NOT_CONVERGED` — the default methods are the 2D closed form (no iteration) and the
//! 3D one-sided Jacobi, which stops at its sweep cap and returns its (orthonormal,
//! backward-stable) result instead of failing; `AMPM_ERR_INTERNAL` — only a caught panic
//! produces it, and the entry points have no panicking path.
use super::single::expect;
use super::*;
use ampm::AmpmStatus::*;
use std::collections::BTreeSet;
use std::ptr;

// ---------------------------------------------------------------------------------------------
// Every reachable status.
// ---------------------------------------------------------------------------------------------

/// One call producing each reachable status (the module docs say why the other two are not).
fn statuses<M: Abi>() -> BTreeSet<u32> {
    let mut rng = seeded::<M>(10);
    let (f, z, mu) = (
        random_f::<M>(&mut rng),
        random_z::<M>(&mut rng),
        random_mu::<M>(&mut rng),
    );
    let mut nan_f = f;
    nan_f[(0, 0)] = t::<M>(f64::NAN);
    let mut out = sentinel::<M>(M::LEN);
    let fa = f.to_array();
    // SAFETY: out is valid; f is NULL on purpose.
    let null = unsafe {
        call::<M>(
            Op::Ahat,
            mu,
            ptr::null(),
            fa.as_ref().as_ptr(),
            out.as_mut_ptr(),
        )
    };
    [
        expect(Op::Ahat, mu, &f, &z, AMPM_OK),
        null,
        expect(Op::Ahat, mu, &nan_f, &z, AMPM_ERR_NON_FINITE),
        expect(Op::Ahat, mu, &M::zero(), &z, AMPM_ERR_NON_POSITIVE_J),
        expect(Op::Ahat, mu, &subnormal_f::<M>(), &z, AMPM_ERR_OVERFLOW),
        expect(Op::Ahat, -mu, &f, &z, AMPM_ERR_INVALID_ARGUMENT),
    ]
    .into_iter()
    .map(|s| s as u32)
    .collect()
}

#[test]
fn every_reachable_status() {
    let want: BTreeSet<u32> = [
        AMPM_OK,
        AMPM_ERR_NULL_POINTER,
        AMPM_ERR_NON_FINITE,
        AMPM_ERR_NON_POSITIVE_J,
        AMPM_ERR_OVERFLOW,
        AMPM_ERR_INVALID_ARGUMENT,
    ]
    .into_iter()
    .map(|s| s as u32)
    .collect();
    assert_eq!(statuses::<Mat<f32, 2>>(), want);
    assert_eq!(statuses::<Mat<f32, 3>>(), want);
    assert_eq!(statuses::<Mat<f64, 2>>(), want);
    assert_eq!(statuses::<Mat<f64, 3>>(), want);
    // The status values are the documented ones (the header's enum).
    let codes = [
        (AMPM_OK, 0),
        (AMPM_ERR_NULL_POINTER, 1),
        (AMPM_ERR_NON_FINITE, 2),
        (AMPM_ERR_NON_POSITIVE_J, 3),
        (AMPM_ERR_OVERFLOW, 4),
        (AMPM_ERR_INVALID_ARGUMENT, 5),
        (AMPM_ERR_NOT_CONVERGED, 6),
        (AMPM_ERR_INTERNAL, 7),
    ];
    for (s, c) in codes {
        assert_eq!(s as u32, c, "{s:?}");
    }
}
