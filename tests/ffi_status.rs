//! The C ABI called from Rust through the `ampm` crate: every one of the 28 entry points
//! (5 single-particle ops + 2 batch ops, × 2D/3D × f32/f64) against its documented status
//! codes and memory contract, generated per type from one generic source.
//!
//! - Each error (NULL pointer, NaN/±inf in `F`, `Z`, `μ`, `det F ≤ 0`, `μ < 0`, overflow)
//!   gives its own status, and the output buffer keeps its sentinel bit for bit.
//! - Success gives the core API's result bit for bit, also in place (`out == F`, `out == Z`):
//!   single calls that of the scalar path of `ampm_core::kernel`, batch calls that of the
//!   instruction set `ampm_isa()` reports.
//! - Batch calls compute every valid particle, leave failed ones untouched, return the first
//!   failure's status and index, accept a NULL `first_failed` and NULL arrays when `n = 0`,
//!   and refuse an `n` whose byte size overflows without touching memory.
//! - A whole-call error of any batch entry point (NULL required pointer, `n` too large, an
//!   invalid option) writes nothing but `*first_failed = 0` (the `whole_call_errors_*` tests).
//!
//! Reachable statuses: `AMPM_OK`, `AMPM_ERR_NULL_POINTER`, `AMPM_ERR_NON_FINITE`,
//! `AMPM_ERR_NON_POSITIVE_J`, `AMPM_ERR_OVERFLOW`, `AMPM_ERR_INVALID_ARGUMENT` are each
//! produced below ([`every_reachable_status`] collects them). Not reachable today:
//! `AMPM_ERR_NOT_CONVERGED` — the default methods are the 2D closed form (no iteration) and the
//! 3D one-sided Jacobi, which stops at its sweep cap and returns its (orthonormal,
//! backward-stable) result instead of failing; `AMPM_ERR_INTERNAL` — only a caught panic
//! produces it, and the entry points have no panicking path.

use ampm::AmpmStatus::{self, *};
use ampm_core::augmented;
use ampm_core::kernel::batch::{self, BatchReal, Outputs};
use ampm_core::kernel::{Dim, LaneDim};
use ampm_core::lane::{Isa, IsaKind};
use ampm_core::{Error, Mat, Matrix, Real};
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;
use std::collections::BTreeSet;
use std::ptr;

type Res<T> = Result<T, Error>;

/// A value no kernel returns for the inputs below (exact in f32 and f64).
const SENTINEL: f64 = -1234.5;

// ---------------------------------------------------------------------------------------------
// The entry points of one type, and the core API they must reproduce.
// ---------------------------------------------------------------------------------------------

type Bin<T> = unsafe extern "C" fn(*const T, *const T, *mut T) -> AmpmStatus;
type MuUn<T> = unsafe extern "C" fn(T, *const T, *mut T) -> AmpmStatus;
type MuBin<T> = unsafe extern "C" fn(T, *const T, *const T, *mut T) -> AmpmStatus;
type BatchUn<T> = unsafe extern "C" fn(usize, *const T, *const T, *mut T, *mut usize) -> AmpmStatus;
type BatchBin<T> =
    unsafe extern "C" fn(usize, *const T, *const T, *const T, *mut T, *mut usize) -> AmpmStatus;

/// The seven entry points of one dimension and precision.
struct Api<T> {
    b_z: Bin<T>,
    z_b: Bin<T>,
    energy_hat: MuUn<T>,
    ahat: MuUn<T>,
    chat_z: MuBin<T>,
    ahat_batch: BatchUn<T>,
    chat_z_batch: BatchBin<T>,
}

/// A matrix type with its entry points and the core kernels they wrap.
trait Abi: Matrix {
    const API: Api<Self::Scalar>;
    fn psi_hat(mu: Self::Scalar, f: &Self) -> Res<Self::Scalar>;
    fn ahat(isa: Isa, mu: Self::Scalar, f: &Self) -> Res<Self>;
    fn chat_z(isa: Isa, mu: Self::Scalar, f: &Self, z: &Self) -> Res<Self>;
}

/// The instruction set the C batch calls use.
fn c_isa() -> Isa {
    Isa::available()
        .into_iter()
        .find(|i| {
            let code = match i.kind() {
                IsaKind::Scalar => ampm::AMPM_ISA_SCALAR,
                IsaKind::Avx2 => ampm::AMPM_ISA_AVX2,
                IsaKind::Avx512 => ampm::AMPM_ISA_AVX512,
            };
            code == ampm::ampm_isa()
        })
        .unwrap_or(Isa::SCALAR)
}

/// One output of the core batch kernels for one particle: 0 = Ψ̂, 1 = Â, 2 = Ĉ:Z.
fn core_one<T: BatchReal, const D: usize>(
    isa: Isa,
    mu: T,
    f: &Mat<T, D>,
    z: &Mat<T, D>,
    what: u8,
) -> Res<Vec<T>>
where
    Dim<D>: LaneDim<D>,
{
    let fv = f.cols.concat();
    let zv = z.cols.concat();
    let mut out = vec![T::ZERO; if what == 0 { 1 } else { D * D }];
    let o = match what {
        0 => Outputs {
            energy: Some(&mut out),
            ..Outputs::default()
        },
        1 => Outputs {
            ahat: Some(&mut out),
            ..Outputs::default()
        },
        _ => Outputs {
            chat_z: Some(&mut out),
            ..Outputs::default()
        },
    };
    let st = batch::ahat_chat_z::<T, D>(isa, &[mu], &fv, (what == 2).then_some(&zv[..]), o)?;
    st.result().map_err(|e| e.1)?;
    Ok(out)
}

macro_rules! impl_abi {
    ($t:ty, $d:literal, $bz:ident, $zb:ident, $e:ident, $a:ident, $c:ident, $ab:ident, $cb:ident) => {
        impl Abi for Mat<$t, $d> {
            const API: Api<$t> = Api {
                b_z: ampm::$bz,
                z_b: ampm::$zb,
                energy_hat: ampm::$e,
                ahat: ampm::$a,
                chat_z: ampm::$c,
                ahat_batch: ampm::$ab,
                chat_z_batch: ampm::$cb,
            };
            fn psi_hat(mu: $t, f: &Self) -> Res<$t> {
                core_one::<$t, $d>(Isa::SCALAR, mu, f, f, 0).map(|v| v[0])
            }
            fn ahat(isa: Isa, mu: $t, f: &Self) -> Res<Self> {
                core_one::<$t, $d>(isa, mu, f, f, 1).map(|v| Mat::from_col_major(&v).unwrap())
            }
            fn chat_z(isa: Isa, mu: $t, f: &Self, z: &Self) -> Res<Self> {
                core_one::<$t, $d>(isa, mu, f, z, 2).map(|v| Mat::from_col_major(&v).unwrap())
            }
        }
    };
}
impl_abi!(
    f32,
    2,
    ampm_b_z_2d_f32,
    ampm_z_b_2d_f32,
    ampm_energy_hat_2d_f32,
    ampm_ahat_2d_f32,
    ampm_chat_z_2d_f32,
    ampm_ahat_batch_2d_f32,
    ampm_chat_z_batch_2d_f32
);
impl_abi!(
    f64,
    2,
    ampm_b_z_2d_f64,
    ampm_z_b_2d_f64,
    ampm_energy_hat_2d_f64,
    ampm_ahat_2d_f64,
    ampm_chat_z_2d_f64,
    ampm_ahat_batch_2d_f64,
    ampm_chat_z_batch_2d_f64
);
impl_abi!(
    f32,
    3,
    ampm_b_z_3d_f32,
    ampm_z_b_3d_f32,
    ampm_energy_hat_3d_f32,
    ampm_ahat_3d_f32,
    ampm_chat_z_3d_f32,
    ampm_ahat_batch_3d_f32,
    ampm_chat_z_batch_3d_f32
);
impl_abi!(
    f64,
    3,
    ampm_b_z_3d_f64,
    ampm_z_b_3d_f64,
    ampm_energy_hat_3d_f64,
    ampm_ahat_3d_f64,
    ampm_chat_z_3d_f64,
    ampm_ahat_batch_3d_f64,
    ampm_chat_z_batch_3d_f64
);

/// The single-particle operations.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Op {
    BZ,
    ZB,
    Psi,
    Ahat,
    Chat,
}
const OPS: [Op; 5] = [Op::BZ, Op::ZB, Op::Psi, Op::Ahat, Op::Chat];

impl Op {
    fn uses_mu(self) -> bool {
        matches!(self, Op::Psi | Op::Ahat | Op::Chat)
    }
    fn uses_z(self) -> bool {
        matches!(self, Op::BZ | Op::ZB | Op::Chat)
    }
    /// Number of scalars written.
    fn out_len<M: Matrix>(self) -> usize {
        if self == Op::Psi {
            1
        } else {
            M::LEN
        }
    }
}

/// Calls the entry point of `op` (raw pointers: NULL and aliasing allowed).
///
/// # Safety
/// Non-null pointers valid for `M::LEN` scalars (`out`: `op.out_len`).
unsafe fn call<M: Abi>(
    op: Op,
    mu: M::Scalar,
    f: *const M::Scalar,
    z: *const M::Scalar,
    out: *mut M::Scalar,
) -> AmpmStatus {
    let a = M::API;
    match op {
        Op::BZ => (a.b_z)(f, z, out),
        Op::ZB => (a.z_b)(f, z, out),
        Op::Psi => (a.energy_hat)(mu, f, out),
        Op::Ahat => (a.ahat)(mu, f, out),
        Op::Chat => (a.chat_z)(mu, f, z, out),
    }
}

/// The core API's result of `op`, flattened column-major.
fn reference<M: Abi>(op: Op, mu: M::Scalar, f: &M, z: &M) -> Res<Vec<M::Scalar>> {
    reference_on(Isa::SCALAR, op, mu, f, z)
}

/// The core result of `op` on the instruction set `isa` (the batch calls run on [`c_isa`]).
fn reference_on<M: Abi>(isa: Isa, op: Op, mu: M::Scalar, f: &M, z: &M) -> Res<Vec<M::Scalar>> {
    let m = match op {
        Op::BZ => augmented::b_z(f, z)?,
        Op::ZB => augmented::z_b(f, z)?,
        Op::Psi => return M::psi_hat(mu, f).map(|p| vec![p]),
        Op::Ahat => M::ahat(isa, mu, f)?,
        Op::Chat => M::chat_z(isa, mu, f, z)?,
    };
    Ok(m.to_array().as_ref().to_vec())
}

/// The batch operations.
#[derive(Clone, Copy, Debug, PartialEq)]
enum BatchOp {
    Ahat,
    Chat,
}
const BATCH_OPS: [BatchOp; 2] = [BatchOp::Ahat, BatchOp::Chat];

impl BatchOp {
    fn single(self) -> Op {
        match self {
            BatchOp::Ahat => Op::Ahat,
            BatchOp::Chat => Op::Chat,
        }
    }
}

/// Calls the batch entry point of `op` (`z` ignored by `Ahat`).
///
/// # Safety
/// Non-null arrays valid for `n` particles; `first_failed` null or valid.
unsafe fn call_batch<M: Abi>(
    op: BatchOp,
    n: usize,
    mu: *const M::Scalar,
    f: *const M::Scalar,
    z: *const M::Scalar,
    out: *mut M::Scalar,
    first_failed: *mut usize,
) -> AmpmStatus {
    match op {
        BatchOp::Ahat => (M::API.ahat_batch)(n, mu, f, out, first_failed),
        BatchOp::Chat => (M::API.chat_z_batch)(n, mu, f, z, out, first_failed),
    }
}

// ---------------------------------------------------------------------------------------------
// Inputs.
// ---------------------------------------------------------------------------------------------

fn t<M: Matrix>(x: f64) -> M::Scalar {
    M::Scalar::from_f64(x)
}

fn sentinel<M: Matrix>(len: usize) -> Vec<M::Scalar> {
    vec![t::<M>(SENTINEL); len]
}

fn bits<T: Real>(v: &[T]) -> Vec<u64> {
    v.iter().map(|x| x.to_f64().to_bits()).collect()
}

#[track_caller]
fn assert_untouched<M: Matrix>(out: &[M::Scalar], ctx: &dyn std::fmt::Debug) {
    assert!(
        out.iter()
            .all(|x| x.to_f64().to_bits() == SENTINEL.to_bits()),
        "output written on failure: {out:?}\n{ctx:?}"
    );
}

/// A random valid `F` (`J > 0`, entries of order 1): `I + 0.3·(uniform in [−1, 1])`, redrawn
/// until `det F ≥ 1/4`.
fn random_f<M: Matrix>(rng: &mut Pcg64) -> M {
    loop {
        let mut f = M::identity();
        for j in 0..M::DIM {
            for i in 0..M::DIM {
                f[(i, j)] += t::<M>(0.3 * rng.random_range(-1.0..1.0));
            }
        }
        if f.det().to_f64() >= 0.25 {
            return f;
        }
    }
}

fn random_z<M: Matrix>(rng: &mut Pcg64) -> M {
    let mut z = M::zero();
    for j in 0..M::DIM {
        for i in 0..M::DIM {
            z[(i, j)] = t::<M>(rng.random_range(-1.0..1.0));
        }
    }
    z
}

fn random_mu<M: Matrix>(rng: &mut Pcg64) -> M::Scalar {
    t::<M>(rng.random_range(0.1..10.0))
}

fn seeded<M: Matrix>(tag: u64) -> Pcg64 {
    Pcg64::seed_from_u64(tag * 1000 + 10 * M::DIM as u64 + M::Scalar::MANTISSA_DIGITS as u64)
}

/// A fixed `G` with few significant bits (so `2ᵏ G` is exact even deep in the subnormals),
/// `det G > 0`, not a multiple of a rotation (so `Â(G) ≠ 0`).
fn coarse_g<M: Matrix>() -> M {
    let mut g = M::identity();
    g[(0, 0)] = t::<M>(1.5);
    g[(0, 1)] = t::<M>(0.5);
    g[(1, 0)] = t::<M>(0.25);
    g
}

/// `2ᵏ G` with `k` chosen so that the entries are subnormal and the results `Â ∝ ‖F‖⁻¹`,
/// `𝓑:Z ∝ ‖F‖⁻¹`, `Ĉ:Z ∝ ‖F‖⁻²` overflow (f64: `2⁻¹⁰⁶⁰`, f32: `2⁻¹⁴⁰`).
fn subnormal_f<M: Matrix>() -> M {
    let k = if M::Scalar::MANTISSA_DIGITS > 24 {
        -1060
    } else {
        -140
    };
    let f = coarse_g::<M>().map(|x| x.scalbn(k));
    assert!(f.max_abs() < M::Scalar::MIN_POSITIVE && f.map(|x| x.scalbn(-k)) == coarse_g());
    f
}

/// `F` with `det F = 0`: rank-deficient, and the zero matrix.
fn singular_fs<M: Matrix>() -> Vec<M> {
    let mut r = M::identity();
    r[(M::DIM - 1, M::DIM - 1)] = M::Scalar::ZERO;
    let mut dup = coarse_g::<M>();
    for i in 0..M::DIM {
        let x = dup[(i, 0)];
        dup[(i, 1)] = x + x; // column 1 = 2 · column 0
    }
    vec![r, dup, M::zero()]
}

/// `F` with `det F < 0`: a reflection, a valid `F` with one column negated, and (3D) `−I`.
fn inverted_fs<M: Matrix>(rng: &mut Pcg64) -> Vec<M> {
    let mut refl = M::identity();
    refl[(0, 0)] = -M::Scalar::ONE;
    let mut g = random_f::<M>(rng);
    for i in 0..M::DIM {
        g[(i, M::DIM - 1)] = -g[(i, M::DIM - 1)];
    }
    let mut out = vec![refl, g];
    if M::DIM % 2 == 1 {
        out.push(-M::identity());
    }
    for m in &out {
        assert!(m.det() < M::Scalar::ZERO, "{m:?}");
    }
    out
}

fn non_finite<M: Matrix>() -> [M::Scalar; 3] {
    [
        t::<M>(f64::NAN),
        t::<M>(f64::INFINITY),
        t::<M>(f64::NEG_INFINITY),
    ]
}

// ---------------------------------------------------------------------------------------------
// Single-particle error cases.
// ---------------------------------------------------------------------------------------------

/// Calls `op` on (`mu`, `f`, `z`) with a sentinel output; asserts the status and, on any
/// error, that the output is untouched; returns the status.
#[track_caller]
fn expect<M: Abi>(op: Op, mu: M::Scalar, f: &M, z: &M, want: AmpmStatus) -> AmpmStatus {
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
fn null_pointers<M: Abi>() {
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
fn non_finite_inputs<M: Abi>() {
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
fn non_positive_j<M: Abi>() {
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
fn negative_mu<M: Abi>() {
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
fn overflow<M: Abi>() {
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

fn success_and_in_place<M: Abi>() {
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

// ---------------------------------------------------------------------------------------------
// Batches.
// ---------------------------------------------------------------------------------------------

/// One particle of a batch.
#[derive(Clone, Copy, Debug)]
struct Particle<M: Matrix> {
    mu: M::Scalar,
    f: M,
    z: M,
}

/// A way to spoil a particle: its name, the status it must give, the change.
type Spoiler<M> = (&'static str, AmpmStatus, fn(&mut Particle<M>));

/// Ways to spoil a particle, with the status each must give.
fn spoilers<M: Abi>() -> Vec<Spoiler<M>> {
    vec![
        ("NaN μ", AMPM_ERR_NON_FINITE, |p| p.mu = t::<M>(f64::NAN)),
        ("inf μ", AMPM_ERR_NON_FINITE, |p| {
            p.mu = t::<M>(f64::INFINITY)
        }),
        ("-inf μ", AMPM_ERR_NON_FINITE, |p| {
            p.mu = t::<M>(f64::NEG_INFINITY)
        }),
        ("NaN F", AMPM_ERR_NON_FINITE, |p| {
            p.f[(1, 1)] = t::<M>(f64::NAN)
        }),
        ("inf F", AMPM_ERR_NON_FINITE, |p| {
            p.f[(0, 1)] = t::<M>(f64::INFINITY)
        }),
        ("-inf F", AMPM_ERR_NON_FINITE, |p| {
            p.f[(1, 0)] = t::<M>(f64::NEG_INFINITY)
        }),
        ("NaN Z", AMPM_ERR_NON_FINITE, |p| {
            p.z[(1, 0)] = t::<M>(f64::NAN)
        }),
        ("inf Z", AMPM_ERR_NON_FINITE, |p| {
            p.z[(0, 0)] = t::<M>(f64::INFINITY)
        }),
        ("-inf Z", AMPM_ERR_NON_FINITE, |p| {
            p.z[(0, 1)] = t::<M>(f64::NEG_INFINITY)
        }),
        ("det F < 0", AMPM_ERR_NON_POSITIVE_J, |p| {
            for i in 0..M::DIM {
                p.f[(i, 0)] = -p.f[(i, 0)];
            }
        }),
        ("det F = 0", AMPM_ERR_NON_POSITIVE_J, |p| p.f = M::zero()),
        ("μ < 0", AMPM_ERR_INVALID_ARGUMENT, |p| p.mu = -p.mu),
        ("subnormal F", AMPM_ERR_OVERFLOW, |p| {
            p.f = subnormal_f::<M>()
        }),
    ]
}

/// Flattened batch arrays.
struct Arrays<T> {
    mu: Vec<T>,
    f: Vec<T>,
    z: Vec<T>,
}

fn arrays<M: Matrix>(ps: &[Particle<M>]) -> Arrays<M::Scalar> {
    Arrays {
        mu: ps.iter().map(|p| p.mu).collect(),
        f: ps
            .iter()
            .flat_map(|p| p.f.to_array().as_ref().to_vec())
            .collect(),
        z: ps
            .iter()
            .flat_map(|p| p.z.to_array().as_ref().to_vec())
            .collect(),
    }
}

/// Runs a batch with a sentinel output; returns (status, first_failed or None, output).
fn run_batch<M: Abi>(
    op: BatchOp,
    ps: &[Particle<M>],
    with_first_failed: bool,
) -> (AmpmStatus, Option<usize>, Vec<M::Scalar>) {
    let a = arrays(ps);
    let mut out = sentinel::<M>(ps.len() * M::LEN);
    let mut ff = usize::MAX;
    let ffp: *mut usize = if with_first_failed {
        &mut ff
    } else {
        ptr::null_mut()
    };
    // SAFETY: arrays hold ps.len() particles.
    let st = unsafe {
        call_batch::<M>(
            op,
            ps.len(),
            a.mu.as_ptr(),
            a.f.as_ptr(),
            a.z.as_ptr(),
            out.as_mut_ptr(),
            ffp,
        )
    };
    (st, with_first_failed.then_some(ff), out)
}

/// Checks a batch's outputs against single calls: good particles bit for bit, failed ones
/// untouched, status and `first_failed` of the first failure (`n` if none).
#[track_caller]
fn check_batch<M: Abi>(
    op: BatchOp,
    ps: &[Particle<M>],
    st: AmpmStatus,
    ff: Option<usize>,
    out: &[M::Scalar],
) {
    let mut first = None;
    for (i, p) in ps.iter().enumerate() {
        let chunk = &out[i * M::LEN..(i + 1) * M::LEN];
        match reference_on(c_isa(), op.single(), p.mu, &p.f, &p.z) {
            Ok(want) => assert_eq!(bits(chunk), bits(&want), "{op:?} particle {i} {p:?}"),
            Err(e) => {
                assert_untouched::<M>(chunk, &(op, i, p));
                first.get_or_insert((i, AmpmStatus::from(e)));
            }
        }
    }
    let (idx, status) = first.unwrap_or((ps.len(), AMPM_OK));
    assert_eq!(st, status, "{op:?}");
    if let Some(ff) = ff {
        assert_eq!(ff, idx, "{op:?} first_failed");
    }
}

/// Mixed good and bad particles: each spoiler as the first failure (index 2), followed by a
/// different failure (index 6), good particles and a liquid at a subnormal `F` (index 8);
/// all good; `first_failed` NULL.
fn batch_mixed<M: Abi>() {
    let mut rng = seeded::<M>(7);
    let sp = spoilers::<M>();
    for op in BATCH_OPS {
        for (k, (name, status, spoil)) in sp.iter().enumerate() {
            let mut ps: Vec<Particle<M>> = (0..9)
                .map(|_| Particle {
                    mu: random_mu::<M>(&mut rng),
                    f: random_f::<M>(&mut rng),
                    z: random_z::<M>(&mut rng),
                })
                .collect();
            let (st0, ff0, out0) = run_batch(op, &ps, true);
            check_batch(op, &ps, st0, ff0, &out0);
            assert_eq!((st0, ff0), (AMPM_OK, Some(ps.len())), "all good");

            spoil(&mut ps[2]);
            let (_, _, later) = sp[(k + 1) % sp.len()];
            later(&mut ps[6]);
            // A liquid at a subnormal F: every result is 0 and representable, in the batch
            // path as in the single-particle one.
            ps[8].mu = M::Scalar::ZERO;
            ps[8].f = subnormal_f::<M>();
            if op == BatchOp::Ahat && name.ends_with(" Z") {
                // Â ignores Z: this particle is good for the Â batch.
                assert!(reference(Op::Ahat, ps[2].mu, &ps[2].f, &ps[2].z).is_ok());
            } else {
                assert_eq!(
                    reference(op.single(), ps[2].mu, &ps[2].f, &ps[2].z)
                        .err()
                        .map(AmpmStatus::from),
                    Some(*status),
                    "{name}"
                );
            }
            let (st, ff, out) = run_batch(op, &ps, true);
            check_batch(op, &ps, st, ff, &out);
            let (st_null, ff_null, out_null) = run_batch(op, &ps, false);
            assert_eq!(
                (st_null, ff_null, bits(&out_null)),
                (st, None, bits(&out)),
                "NULL first_failed"
            );
        }
    }
}

/// In place: `out == F` (and `out == Z` for Ĉ:Z) over the whole batch, with a failure inside.
fn batch_in_place<M: Abi>() {
    let mut rng = seeded::<M>(8);
    for op in BATCH_OPS {
        let mut ps: Vec<Particle<M>> = (0..5)
            .map(|_| Particle {
                mu: random_mu::<M>(&mut rng),
                f: random_f::<M>(&mut rng),
                z: random_z::<M>(&mut rng),
            })
            .collect();
        ps[3].mu = -ps[3].mu;
        let (st, ff, out) = run_batch(op, &ps, true);
        let aliases: &[&str] = if op == BatchOp::Chat {
            &["f", "z"]
        } else {
            &["f"]
        };
        for which in aliases {
            let mut a = arrays(&ps);
            let mut ff2 = usize::MAX;
            let buf = if *which == "f" { &mut a.f } else { &mut a.z };
            let p = buf.as_mut_ptr();
            let (fp, zp) = if *which == "f" {
                (p as *const _, a.z.as_ptr())
            } else {
                (a.f.as_ptr(), p as *const _)
            };
            // SAFETY: arrays hold 5 particles; out aliases one input array exactly.
            let st2 = unsafe { call_batch::<M>(op, ps.len(), a.mu.as_ptr(), fp, zp, p, &mut ff2) };
            let buf = if *which == "f" { &a.f } else { &a.z };
            assert_eq!((st2, Some(ff2)), (st, ff), "{op:?} out == {which}");
            for i in 0..ps.len() {
                let chunk = &buf[i * M::LEN..(i + 1) * M::LEN];
                if i == 3 {
                    // Failed particle: its input (= output) is untouched.
                    let orig = if *which == "f" { ps[i].f } else { ps[i].z };
                    assert_eq!(
                        bits(chunk),
                        bits(orig.to_array().as_ref()),
                        "{op:?} {which} {i}"
                    );
                } else {
                    assert_eq!(
                        bits(chunk),
                        bits(&out[i * M::LEN..(i + 1) * M::LEN]),
                        "{op:?} {which} {i}"
                    );
                }
            }
        }
    }
}

/// `n = 0` with NULL arrays → OK (`first_failed` = 0); NULL arrays with `n > 0` → NULL_POINTER;
/// `n` whose byte size overflows (`usize` or `isize::MAX`) → INVALID_ARGUMENT; on both
/// whole-call errors nothing is written but `first_failed` = 0.
fn batch_arguments<M: Abi>() {
    let mut rng = seeded::<M>(9);
    let ps: Vec<Particle<M>> = (0..3)
        .map(|_| Particle {
            mu: random_mu::<M>(&mut rng),
            f: random_f::<M>(&mut rng),
            z: random_z::<M>(&mut rng),
        })
        .collect();
    let a = arrays(&ps);
    let sz = M::LEN * std::mem::size_of::<M::Scalar>();
    for op in BATCH_OPS {
        let mut ff = usize::MAX;
        // SAFETY: n = 0: nothing may be read or written but first_failed.
        let st = unsafe {
            call_batch::<M>(
                op,
                0,
                ptr::null(),
                ptr::null(),
                ptr::null(),
                ptr::null_mut(),
                &mut ff,
            )
        };
        assert_eq!((st, ff), (AMPM_OK, 0), "{op:?} n = 0");
        // SAFETY: as above.
        let st = unsafe {
            call_batch::<M>(
                op,
                0,
                ptr::null(),
                ptr::null(),
                ptr::null(),
                ptr::null_mut(),
                ptr::null_mut(),
            )
        };
        assert_eq!(st, AMPM_OK, "{op:?} n = 0, NULL first_failed");

        let null_args: &[&str] = if op == BatchOp::Chat {
            &["mu", "f", "z", "out"]
        } else {
            &["mu", "f", "out"]
        };
        for which in null_args {
            let mut out = sentinel::<M>(ps.len() * M::LEN);
            let mut ff = usize::MAX;
            let nul = |w: &str, p: *const M::Scalar| if *which == w { ptr::null() } else { p };
            let o = if *which == "out" {
                ptr::null_mut()
            } else {
                out.as_mut_ptr()
            };
            // SAFETY: non-null arrays hold 3 particles.
            let st = unsafe {
                call_batch::<M>(
                    op,
                    ps.len(),
                    nul("mu", a.mu.as_ptr()),
                    nul("f", a.f.as_ptr()),
                    nul("z", a.z.as_ptr()),
                    o,
                    &mut ff,
                )
            };
            assert_eq!(st, AMPM_ERR_NULL_POINTER, "{op:?} NULL {which}");
            assert_untouched::<M>(&out, &(op, which));
            assert_eq!(ff, 0, "{op:?} NULL {which}: first_failed");
        }

        for n in [
            usize::MAX / sz + 1,
            (isize::MAX as usize) / sz + 1,
            usize::MAX,
        ] {
            let mut out = sentinel::<M>(ps.len() * M::LEN);
            let mut ff = usize::MAX - 1;
            // SAFETY: the call must refuse n before touching any array (they hold 3 particles).
            let st = unsafe {
                call_batch::<M>(
                    op,
                    n,
                    a.mu.as_ptr(),
                    a.f.as_ptr(),
                    a.z.as_ptr(),
                    out.as_mut_ptr(),
                    &mut ff,
                )
            };
            assert_eq!(st, AMPM_ERR_INVALID_ARGUMENT, "{op:?} n = {n}");
            assert_untouched::<M>(&out, &(op, n));
            assert_eq!(ff, 0, "{op:?} n = {n}: first_failed");
        }
    }
}

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

// ---------------------------------------------------------------------------------------------
// Instantiation.
// ---------------------------------------------------------------------------------------------

macro_rules! all_types {
    ($($m:ident: $t:ty, $d:literal;)*) => {$(
        mod $m {
            use super::*;
            type M = Mat<$t, $d>;
            #[test]
            fn null_pointer() {
                null_pointers::<M>();
            }
            #[test]
            fn non_finite() {
                non_finite_inputs::<M>();
            }
            #[test]
            fn non_positive_j() {
                super::non_positive_j::<M>();
            }
            #[test]
            fn negative_mu() {
                super::negative_mu::<M>();
            }
            #[test]
            fn overflow() {
                super::overflow::<M>();
            }
            #[test]
            fn success_bit_for_bit_and_in_place() {
                success_and_in_place::<M>();
            }
            #[test]
            fn batch_mixed_particles() {
                batch_mixed::<M>();
            }
            #[test]
            fn batch_in_place() {
                super::batch_in_place::<M>();
            }
            #[test]
            fn batch_argument_checks() {
                batch_arguments::<M>();
            }
        }
    )*};
}
all_types! {
    f32_2d: f32, 2;
    f32_3d: f32, 3;
    f64_2d: f64, 2;
    f64_3d: f64, 3;
}

// ---------------------------------------------------------------------------------------------
// Whole-call errors of every batch entry point.
// ---------------------------------------------------------------------------------------------

/// A batch call of one case below, given the output arrays (Â, Ĉ:Z, prepared slots) and
/// `first_failed`.
type WholeCall<'a, T> = Box<dyn Fn(*mut T, *mut T, *mut T, *mut usize) -> AmpmStatus + 'a>;

/// Runs each `(name, expected status, call)`, with `first_failed` non-NULL and NULL: the status
/// is the expected whole-call error, no output is written, and `*first_failed` = 0.
fn check_whole_call<T: Copy + PartialEq + std::fmt::Debug>(
    n: usize,
    slot: usize,
    sentinel: T,
    cases: &[(&str, AmpmStatus, WholeCall<'_, T>)],
) {
    let e = 9; // scalars of the largest matrix
    for (name, want, call) in cases {
        for with_ff in [true, false] {
            let mut a = vec![sentinel; n * e];
            let mut c = vec![sentinel; n * e];
            let mut p = vec![sentinel; n * slot];
            let mut ff = 77usize;
            let ffp: *mut usize = if with_ff { &mut ff } else { ptr::null_mut() };
            let st = call(a.as_mut_ptr(), c.as_mut_ptr(), p.as_mut_ptr(), ffp);
            assert_eq!(st, *want, "{name}");
            assert!(
                a.iter().chain(&c).chain(&p).all(|x| *x == sentinel),
                "{name}: output written"
            );
            if with_ff {
                assert_eq!(ff, 0, "{name}: first_failed");
            }
        }
    }
}

macro_rules! whole_call_errors {
    ($($m:ident: $t:ty, $d:literal, $ab:ident, $cb:ident, $psd:ident, $comb:ident, $len:ident,
       $prep:ident, $apply:ident, $aex:ident, $cex:ident;)*) => {$(
        /// Every batch entry point of one type: NULL required pointers, an `n` too large to
        /// address and invalid options are whole-call errors (nothing written,
        /// `*first_failed` = 0); a NULL pointer takes precedence over an invalid option.
        #[test]
        fn $m() {
            use ampm::methods::{AmpmOptions, AMPM_METHOD_CLOSED_FORM_2D, AMPM_METHOD_MCADAMS};
            type T = $t;
            const E: usize = $d * $d;
            let n = 3;
            let mu = vec![2.0 as T; n];
            let mut f = vec![0.0 as T; n * E];
            for i in 0..n {
                for j in 0..$d {
                    f[i * E + j * ($d + 1)] = 1.0 + 0.25 * j as T;
                }
            }
            let z = vec![0.5 as T; n * E];
            let (mu, f, z) = (mu.as_ptr(), f.as_ptr(), z.as_ptr());
            let big = usize::MAX / (E * std::mem::size_of::<T>()) + 1;
            let bad = AmpmOptions {
                method: 99,
                ..AmpmOptions::default()
            };
            let other = AmpmOptions {
                method: if $d == 2 {
                    AMPM_METHOD_CLOSED_FORM_2D
                } else {
                    AMPM_METHOD_MCADAMS
                },
                ..AmpmOptions::default()
            };
            let (bad, other) = (&bad as *const AmpmOptions, &other as *const AmpmOptions);
            let (nul, nulm) = (ptr::null::<T>(), ptr::null_mut::<T>());
            use AmpmStatus::{AMPM_ERR_INVALID_ARGUMENT as INVALID, AMPM_ERR_NULL_POINTER as NULL};
            // SAFETY (every call): non-null arrays hold n records (slots of ampm_hessian_len);
            // the calls must refuse before reading or writing any of them.
            let cases: Vec<(&str, AmpmStatus, WholeCall<'_, T>)> = vec![
                ("ahat_batch NULL mu", NULL, Box::new(|a, _, _, ff| unsafe {
                    ampm::$ab(n, nul, f, a, ff)
                })),
                ("ahat_batch n too large", INVALID, Box::new(|a, _, _, ff| unsafe {
                    ampm::$ab(big, mu, f, a, ff)
                })),
                ("chat_z_batch NULL z", NULL, Box::new(|_, c, _, ff| unsafe {
                    ampm::$cb(n, mu, f, nul, c, ff)
                })),
                ("chat_z_psd_batch NULL f", NULL, Box::new(|_, c, _, ff| unsafe {
                    ampm::hessian::$psd(n, mu, nul, z, c, ff)
                })),
                ("chat_z_psd_batch n too large", INVALID, Box::new(|_, c, _, ff| unsafe {
                    ampm::hessian::$psd(big, mu, f, z, c, ff)
                })),
                ("ahat_chat_z_batch no output", NULL, Box::new(|_, _, _, ff| unsafe {
                    ampm::$comb(n, mu, f, z, nulm, nulm, ff)
                })),
                ("ahat_chat_z_batch NULL z", NULL, Box::new(|a, c, _, ff| unsafe {
                    ampm::$comb(n, mu, f, nul, a, c, ff)
                })),
                ("ahat_chat_z_batch n too large", INVALID, Box::new(|a, c, _, ff| unsafe {
                    ampm::$comb(big, mu, f, z, a, c, ff)
                })),
                ("hessian_prepare_batch NULL prepared", NULL, Box::new(|a, _, _, ff| unsafe {
                    ampm::$prep(n, mu, f, a, nulm, ff)
                })),
                ("hessian_prepare_batch n too large", INVALID, Box::new(|a, _, p, ff| unsafe {
                    ampm::$prep(big, mu, f, a, p, ff)
                })),
                ("hessian_apply_batch NULL z", NULL, Box::new(|_, c, p, ff| unsafe {
                    ampm::$apply(n, p, nul, c, 0, ff)
                })),
                ("hessian_apply_batch n too large", INVALID, Box::new(|_, c, p, ff| unsafe {
                    ampm::$apply(big, p, z, c, 1, ff)
                })),
                ("ahat_batch_ex invalid option", INVALID, Box::new(|a, _, _, ff| unsafe {
                    ampm::methods::$aex(bad, n, mu, f, a, ff)
                })),
                ("ahat_batch_ex invalid option, NULL f", NULL, Box::new(|a, _, _, ff| unsafe {
                    ampm::methods::$aex(bad, n, mu, nul, a, ff)
                })),
                ("ahat_batch_ex method, NULL out", NULL, Box::new(|_, _, _, ff| unsafe {
                    ampm::methods::$aex(other, n, mu, f, nulm, ff)
                })),
                ("ahat_batch_ex default, n too large", INVALID, Box::new(|a, _, _, ff| unsafe {
                    ampm::methods::$aex(ptr::null(), big, mu, f, a, ff)
                })),
                ("chat_z_batch_ex invalid option", INVALID, Box::new(|_, c, _, ff| unsafe {
                    ampm::methods::$cex(bad, n, mu, f, z, c, ff)
                })),
                ("chat_z_batch_ex method, n too large", INVALID, Box::new(|_, c, _, ff| unsafe {
                    ampm::methods::$cex(other, big, mu, f, z, c, ff)
                })),
            ];
            check_whole_call::<T>(n, ampm::$len(), SENTINEL as T, &cases);
            // The same arguments without the fault: every record computed, first_failed = n.
            let mut ff = 0;
            let mut out = vec![SENTINEL as T; n * E];
            // SAFETY: arrays hold n records.
            let st = unsafe { ampm::methods::$cex(other, n, mu, f, z, out.as_mut_ptr(), &mut ff) };
            assert_eq!((st, ff), (AMPM_OK, n));
            assert!(out.iter().all(|x| *x != SENTINEL as T));
        }
    )*};
}
whole_call_errors! {
    whole_call_errors_2d_f32: f32, 2, ampm_ahat_batch_2d_f32, ampm_chat_z_batch_2d_f32,
        ampm_chat_z_psd_batch_2d_f32, ampm_ahat_chat_z_batch_2d_f32, ampm_hessian_len_2d_f32,
        ampm_hessian_prepare_batch_2d_f32, ampm_hessian_apply_batch_2d_f32,
        ampm_ahat_batch_ex_2d_f32, ampm_chat_z_batch_ex_2d_f32;
    whole_call_errors_2d_f64: f64, 2, ampm_ahat_batch_2d_f64, ampm_chat_z_batch_2d_f64,
        ampm_chat_z_psd_batch_2d_f64, ampm_ahat_chat_z_batch_2d_f64, ampm_hessian_len_2d_f64,
        ampm_hessian_prepare_batch_2d_f64, ampm_hessian_apply_batch_2d_f64,
        ampm_ahat_batch_ex_2d_f64, ampm_chat_z_batch_ex_2d_f64;
    whole_call_errors_3d_f32: f32, 3, ampm_ahat_batch_3d_f32, ampm_chat_z_batch_3d_f32,
        ampm_chat_z_psd_batch_3d_f32, ampm_ahat_chat_z_batch_3d_f32, ampm_hessian_len_3d_f32,
        ampm_hessian_prepare_batch_3d_f32, ampm_hessian_apply_batch_3d_f32,
        ampm_ahat_batch_ex_3d_f32, ampm_chat_z_batch_ex_3d_f32;
    whole_call_errors_3d_f64: f64, 3, ampm_ahat_batch_3d_f64, ampm_chat_z_batch_3d_f64,
        ampm_chat_z_psd_batch_3d_f64, ampm_ahat_chat_z_batch_3d_f64, ampm_hessian_len_3d_f64,
        ampm_hessian_prepare_batch_3d_f64, ampm_hessian_apply_batch_3d_f64,
        ampm_ahat_batch_ex_3d_f64, ampm_chat_z_batch_ex_3d_f64;
}
