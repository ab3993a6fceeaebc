//! The C ABI called from Rust through the `ampm` crate: every one of the 28 entry points
//! (5 single-particle ops + 2 batch ops, × 2D/3D × f32/f64) against its documented status
//! codes and memory contract, generated per type from one generic source. One test binary;
//! each module covers one part of the contract:
//!
//! 1. `single`: each error of a single-particle call gives its own status and leaves the output
//!    untouched; success gives the core API's result bit for bit, also in place.
//! 2. `batches`: batch calls compute every valid particle, leave failed ones untouched, report
//!    the first failure, and check their arguments.
//! 3. `whole_call`: a whole-call error of any batch entry point writes nothing but
//!    `*first_failed = 0`.
//! 4. `statuses`: every reachable status is produced, and the status values are the documented
//!    ones.
//!
//! This file holds what the modules share: the entry points of one type and the core API they
//! must reproduce, the inputs, and the instantiation of the generic checks of `single` and
//! `batches` per type (`f32_2d`, `f32_3d`, `f64_2d`, `f64_3d`).
mod batches;
mod single;
mod statuses;
mod whole_call;

use ampm::AmpmStatus;
use ampm_core::augmented;
use ampm_core::kernel::batch::{self, BatchReal, Outputs};
use ampm_core::kernel::{Dim, LaneDim};
use ampm_core::lane::{Isa, IsaKind};
use ampm_core::{Error, Mat, Matrix, Real};
use batches::{batch_arguments, batch_in_place, batch_mixed};
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;
use single::{
    negative_mu, non_finite_inputs, non_positive_j, null_pointers, overflow, success_and_in_place,
};

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
