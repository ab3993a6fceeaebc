//! Single-particle entry points:
//!
//! - Each error (NULL pointer, NaN/±inf in `F`, `Z`, `μ`, `det F ≤ 0`, `μ < 0`, overflow)
//!   gives its own status, and the output buffer keeps its sentinel bit for bit.
//! - Success gives the core API's result bit for bit (that of the scalar path of
//!   `ampm_core::kernel`), also in place (`out == F`, `out == Z`).
use super::*;
use ampm::AmpmStatus::*;
use std::ptr;

// ---------------------------------------------------------------------------------------------
// Single-particle error cases.
// ---------------------------------------------------------------------------------------------

/// Calls `op` on (`mu`, `f`, `z`) with a sentinel output; asserts the status and, on any
/// error, that the output is untouched; returns the status.
#[track_caller]
pub(crate) fn expect<M: Abi>(op: Op, mu: M::Scalar, f: &M, z: &M, want: AmpmStatus) -> AmpmStatus {
    let (fa, za) = (f.to_array(), z.to_array());
    let mut out = sentinel::<M>(op.out_len::<M>());
    // SAFETY: all buffers are valid for the sizes `call` reads and writes.
    let st = unsafe {
        call::<M>(
            op,
            mu,
            fa.as_ref().as_ptr(),
            za.as_ref().as_ptr(),
            out.as_mut_ptr(),
        )
    };
    let ctx = (op, mu, f, z);
    assert_eq!(st, want, "{ctx:?}");
    if st != AMPM_OK {
        assert_untouched::<M>(&out, &ctx);
    }
    st
}

/// Which pointer is NULL, and the (`f`, `z`, `out`) pointers passed.
type NullCase<T> = (&'static str, *const T, *const T, *mut T);

/// NULL for each pointer argument, one at a time → `AMPM_ERR_NULL_POINTER`, output untouched.
pub(crate) fn null_pointers<M: Abi>() {
    let mut rng = seeded::<M>(1);
    let (f, z, mu) = (
        random_f::<M>(&mut rng),
        random_z::<M>(&mut rng),
        random_mu::<M>(&mut rng),
    );
    let (fa, za) = (f.to_array(), z.to_array());
    let (fp, zp) = (fa.as_ref().as_ptr(), za.as_ref().as_ptr());
    for op in OPS {
        let mut out = sentinel::<M>(op.out_len::<M>());
        let op_ = out.as_mut_ptr();
        let mut cases: Vec<NullCase<M::Scalar>> = vec![
            ("f", ptr::null(), zp, op_),
            ("out", fp, zp, ptr::null_mut()),
        ];
        if op.uses_z() {
            cases.push(("z", fp, ptr::null(), op_));
        }
        for (which, f_, z_, o_) in cases {
            // SAFETY: non-null pointers are valid; NULL ones must not be dereferenced.
            let st = unsafe { call::<M>(op, mu, f_, z_, o_) };
            assert_eq!(st, AMPM_ERR_NULL_POINTER, "{op:?}: NULL {which}");
            assert_untouched::<M>(&out, &(op, which));
        }
    }
}

/// NaN, +inf, −inf in each entry of `F`, each entry of `Z`, and in `μ` → `NON_FINITE`.
pub(crate) fn non_finite_inputs<M: Abi>() {
    let mut rng = seeded::<M>(2);
    let (f, z, mu) = (
        random_f::<M>(&mut rng),
        random_z::<M>(&mut rng),
        random_mu::<M>(&mut rng),
    );
    for op in OPS {
        for v in non_finite::<M>() {
            for p in 0..M::LEN {
                let mut fa = f.to_array();
                fa.as_mut()[p] = v;
                expect(op, mu, &M::from_array(&fa), &z, AMPM_ERR_NON_FINITE);
                if op.uses_z() {
                    let mut za = z.to_array();
                    za.as_mut()[p] = v;
                    expect(op, mu, &f, &M::from_array(&za), AMPM_ERR_NON_FINITE);
                }
            }
            if op.uses_mu() {
                expect(op, v, &f, &z, AMPM_ERR_NON_FINITE);
            }
        }
    }
}

/// `det F = 0` and `det F < 0` → `NON_POSITIVE_J` for every op (`Ψ̂(F) = Ψ(JᵃF)` is undefined
/// or blind to inversion there; 𝓑 needs `H = F⁻ᵀ`).
pub(crate) fn non_positive_j<M: Abi>() {
    let mut rng = seeded::<M>(3);
    let (z, mu) = (random_z::<M>(&mut rng), random_mu::<M>(&mut rng));
    let inv = inverted_fs::<M>(&mut rng);
    for op in OPS {
        for f in singular_fs::<M>().iter().chain(inv.iter()) {
            expect(op, mu, f, &z, AMPM_ERR_NON_POSITIVE_J);
        }
    }
}

/// `μ < 0` (including the largest negative subnormal) → `INVALID_ARGUMENT`; `μ = −0` is
/// `μ = 0` (a valid liquid).
pub(crate) fn negative_mu<M: Abi>() {
    let mut rng = seeded::<M>(4);
    let (f, z) = (random_f::<M>(&mut rng), random_z::<M>(&mut rng));
    let tiny = M::Scalar::MIN_POSITIVE * M::Scalar::EPSILON;
    for op in OPS.into_iter().filter(|o| o.uses_mu()) {
        for mu in [-M::Scalar::ONE, -tiny, -M::Scalar::MAX] {
            expect(op, mu, &f, &z, AMPM_ERR_INVALID_ARGUMENT);
        }
        expect(op, -M::Scalar::ZERO, &f, &z, AMPM_OK);
    }
}

/// Valid inputs whose result overflows → `OVERFLOW`, output untouched: a subnormal `F`
/// (`Â`, `𝓑:Z`, `Z:𝓑` scale like `‖F‖⁻¹`, `Ĉ:Z` like `‖F‖⁻²`; `Ψ̂` is scale-invariant and
/// stays valid), and `μ = MAX` with `F` far from a rotation (`Ψ̂ = μ‖F̂ − R‖²`, `Â`, `Ĉ:Z`).
pub(crate) fn overflow<M: Abi>() {
    let mut rng = seeded::<M>(5);
    let (z, mu) = (random_z::<M>(&mut rng), random_mu::<M>(&mut rng));
    let f = subnormal_f::<M>();
    for op in OPS {
        let want = if op == Op::Psi {
            AMPM_OK
        } else {
            AMPM_ERR_OVERFLOW
        };
        expect(op, mu, &f, &z, want);
    }
    // Ψ̂ of the subnormal F is that of G, bit for bit (the kernels pre-scale exactly).
    let (psi_f, psi_g) = (
        M::psi_hat(mu, &f).unwrap(),
        M::psi_hat(mu, &coarse_g()).unwrap(),
    );
    assert_eq!(psi_f.to_f64().to_bits(), psi_g.to_f64().to_bits());
    // F = diag(16, 1, …): F̂ = Jᵃ F has σ̂ = (4, 1/4) in 2D, (16^{2/3}, 16^{−1/3}, 16^{−1/3}) in
    // 3D, so ‖F̂ − R‖² = Σ(σ̂ᵢ − 1)² > 9 and μ = MAX overflows Ψ̂; Â = 2μ(F̂ − R):𝓑 and Ĉ:Z too.
    let mut g = M::identity();
    g[(0, 0)] = t::<M>(16.0);
    for op in [Op::Psi, Op::Ahat, Op::Chat] {
        expect(op, M::Scalar::MAX, &g, &z, AMPM_ERR_OVERFLOW);
    }
}

// ---------------------------------------------------------------------------------------------
// Single-particle success: bit-for-bit equal to the core API, also in place.
// ---------------------------------------------------------------------------------------------

pub(crate) fn success_and_in_place<M: Abi>() {
    let mut rng = seeded::<M>(6);
    for i in 0..200 {
        let (f, z) = (random_f::<M>(&mut rng), random_z::<M>(&mut rng));
        // Include μ = 0 (the liquid) now and then.
        let mu = if i % 10 == 0 {
            M::Scalar::ZERO
        } else {
            random_mu::<M>(&mut rng)
        };
        for op in OPS {
            let want = bits(&reference(op, mu, &f, &z).unwrap());
            let ctx = (op, mu, f, z);
            expect(op, mu, &f, &z, AMPM_OK);
            let (fa, za) = (f.to_array(), z.to_array());
            let mut out = sentinel::<M>(op.out_len::<M>());
            // SAFETY: valid buffers.
            let st = unsafe {
                call::<M>(
                    op,
                    mu,
                    fa.as_ref().as_ptr(),
                    za.as_ref().as_ptr(),
                    out.as_mut_ptr(),
                )
            };
            assert_eq!((st, bits(&out)), (AMPM_OK, want.clone()), "{ctx:?}");

            // out == F: F is read completely before the result overwrites it (for Ψ̂ only
            // F[0] is overwritten).
            let mut buf = f.to_array();
            let p = buf.as_mut().as_mut_ptr();
            // SAFETY: `p` is valid for M::LEN scalars; the ABI allows exact aliasing.
            let st = unsafe { call::<M>(op, mu, p, za.as_ref().as_ptr(), p) };
            let n = op.out_len::<M>();
            assert_eq!(
                (st, bits(&buf.as_ref()[..n])),
                (AMPM_OK, want.clone()),
                "out == F {ctx:?}"
            );
            if op.uses_z() {
                let mut buf = z.to_array();
                let p = buf.as_mut().as_mut_ptr();
                // SAFETY: as above.
                let st = unsafe { call::<M>(op, mu, fa.as_ref().as_ptr(), p, p) };
                assert_eq!(
                    (st, bits(buf.as_ref())),
                    (AMPM_OK, want.clone()),
                    "out == Z {ctx:?}"
                );
            }
        }
    }
}
