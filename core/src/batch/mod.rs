//! Structure-of-arrays batch kernels that the compiler vectorizes (issue 3).
//!
//! A batch is the C ABI's array of matrices (`n` contiguous column-major `d×d` matrices and
//! `n` values of `μ`). It is processed in chunks of [`BatchKernel::LANES`] particles (8 in
//! f32, 4 in f64: one AVX2 register per matrix entry): a chunk is transposed into lane
//! matrices ([`lmat::LMat`] of [`lane::L`]), the kernel of [`kernel`] runs on all lanes at
//! once with selects instead of branches, and the results are transposed back. A short last
//! chunk is padded with `F = I`, `μ = 0` (valid and cheap), whose results are dropped.
//!
//! The same generic kernel instantiated with one scalar (`S = f32`, `f64`) is the plain
//! scalar fallback; there is no explicit SIMD besides the baseline SSE2 square root of
//! [`lane::Bits::sqrt_n`] (portable `libm` elsewhere), so the module stays `no_std` and builds
//! for any target. Wider code (AVX2) comes from compiling the same source inside a function
//! with `#[target_feature]` (done by the C ABI with runtime detection).
//!
//! **Method and equality.** 2D uses the closed form ([`crate::polar::ClosedForm2`]); 3D uses
//! [`McAdams`] with [`BatchKernel::SWEEPS`] sweeps, chosen per precision by measurement
//! (`tests/batch.rs`, `tools/benches/batch.rs`). Every lane's result and status equal, bit for
//! bit, those of the scalar kernels `augmented::ahat` / `Augmented::chat_z` with
//! `FixedCorotated::with_method(μ, BatchKernel::method())`.

// Index loops over lanes and entries are the form LLVM vectorizes best here.
#![allow(clippy::needless_range_loop)]

pub mod closed2;
pub mod kernel;
pub mod lane;
pub mod lmat;

use crate::error::Error;
use crate::mat::{Mat, Matrix};
use crate::polar::{ClosedForm2, McAdams, SvdMethod};
use kernel::{ahat_lanes, chat_z_lanes, Checks};
use lane::{Bits, L};
use lmat::{LDim, LMat};

/// Largest [`BatchKernel::LANES`] of any implementation (size of callers' chunk buffers).
pub const MAX_LANES: usize = 8;

/// A matrix type with a vectorized batch kernel: `Mat<f32|f64, 2|3>`.
pub trait BatchKernel: Matrix {
    /// Particles per chunk.
    const LANES: usize;
    /// Jacobi sweeps of the 3D method ([`McAdams`]); unused in 2D.
    const SWEEPS: u32;
    /// The SVD method whose scalar kernels the batch reproduces bit for bit.
    type Method: SvdMethod<Self>;

    /// The method value ([`ClosedForm2`] or `McAdams { sweeps: SWEEPS }`).
    #[must_use]
    fn method() -> Self::Method;

    /// `out[i] = Â(μᵢ, Fᵢ)`, `err[i] = None`; or `err[i] = Some(status)` with `out[i]`
    /// unspecified. All slices have the same length `≤ LANES`.
    fn ahat_chunk(mu: &[Self::Scalar], f: &[Self], out: &mut [Self], err: &mut [Option<Error>]);

    /// `Â` of one particle by the same generic kernel on one scalar lane ([`ahat_one`]).
    fn ahat_scalar(mu: Self::Scalar, f: &Self) -> Result<Self>;

    /// `Ĉ:Z` of one particle by the generic kernel on one scalar lane ([`chat_z_one`]).
    fn chat_z_scalar(mu: Self::Scalar, f: &Self, z: &Self) -> Result<Self>;

    /// `out[i] = Ĉ(μᵢ, Fᵢ):Zᵢ`, `err` as in [`BatchKernel::ahat_chunk`].
    fn chat_z_chunk(
        mu: &[Self::Scalar],
        f: &[Self],
        z: &[Self],
        out: &mut [Self],
        err: &mut [Option<Error>],
    );
}

/// Transposes up to `N` matrices into lanes, padding with `pad`.
#[inline(always)]
fn load<T: Bits, const N: usize, const D: usize>(
    src: &[Mat<T, D>],
    pad: &Mat<T, D>,
) -> LMat<L<T, N>, D> {
    let mut r = [[L([T::ZERO; N]); D]; D];
    if let Ok(full) = <&[Mat<T, D>; N]>::try_from(src) {
        // Whole chunk (every chunk but a batch's last): no per-lane choice.
        for (l, m) in full.iter().enumerate() {
            for j in 0..D {
                for i in 0..D {
                    r[j][i].0[l] = m.cols[j][i];
                }
            }
        }
    } else {
        for l in 0..N {
            let m = src.get(l).unwrap_or(pad);
            for j in 0..D {
                for i in 0..D {
                    r[j][i].0[l] = m.cols[j][i];
                }
            }
        }
    }
    r
}

/// Transposes lanes back into `out.len() ≤ N` matrices and decodes the statuses.
#[inline(always)]
fn store<T: Bits, const N: usize, const D: usize>(
    m: &LMat<L<T, N>, D>,
    checks: &Checks<lane::LMask<T::MaskInt, N>>,
    out: &mut [Mat<T, D>],
    err: &mut [Option<Error>],
) {
    let all = checks.all_ok::<L<T, N>>(out.len());
    for (l, (o, e)) in out.iter_mut().zip(err.iter_mut()).enumerate().take(N) {
        for j in 0..D {
            for i in 0..D {
                o.cols[j][i] = m[j][i].0[l];
            }
        }
        *e = if all {
            None
        } else {
            checks.error::<L<T, N>>(l)
        };
    }
}

#[inline(always)]
fn mu_lanes<T: Bits, const N: usize>(mu: &[T]) -> L<T, N> {
    let mut r = L([T::ZERO; N]);
    for l in 0..N {
        r.0[l] = mu.get(l).copied().unwrap_or(T::ZERO);
    }
    r
}

macro_rules! impl_batch {
    ($t:ident, $d:literal, $n:literal, $sweeps:literal, $m:ty, $method:expr) => {
        impl BatchKernel for Mat<$t, $d> {
            const LANES: usize = $n;
            const SWEEPS: u32 = $sweeps;
            type Method = $m;
            #[inline]
            fn method() -> $m {
                $method
            }
            #[inline]
            fn ahat_scalar(mu: $t, f: &Self) -> Result<Self> {
                ahat_one(mu, f, $sweeps)
            }
            #[inline]
            fn chat_z_scalar(mu: $t, f: &Self, z: &Self) -> Result<Self> {
                chat_z_one(mu, f, z, $sweeps)
            }
            #[inline(always)]
            fn ahat_chunk(mu: &[$t], f: &[Self], out: &mut [Self], err: &mut [Option<Error>]) {
                let id = Mat::identity();
                let (r, c) = ahat_lanes::<L<$t, $n>, $d>(mu_lanes(mu), &load(f, &id), $sweeps);
                store(&r, &c, out, err);
            }
            #[inline(always)]
            fn chat_z_chunk(
                mu: &[$t],
                f: &[Self],
                z: &[Self],
                out: &mut [Self],
                err: &mut [Option<Error>],
            ) {
                let id = Mat::identity();
                let (r, c) = chat_z_lanes::<L<$t, $n>, $d>(
                    mu_lanes(mu),
                    &load(f, &id),
                    &load(z, &id),
                    $sweeps,
                );
                store(&r, &c, out, err);
            }
        }
    };
}

impl_batch!(f32, 2, 8, 0, ClosedForm2, ClosedForm2);
impl_batch!(f64, 2, 4, 0, ClosedForm2, ClosedForm2);
impl_batch!(f32, 3, 8, 6, McAdams, McAdams { sweeps: 6 });
impl_batch!(f64, 3, 4, 8, McAdams, McAdams { sweeps: 8 });

/// `Â` and the lane checks of one particle by the same generic kernel on one scalar (the
/// plain scalar fallback; equal to a lane of the vector path).
#[inline]
pub fn ahat_one<T: Real, const D: usize>(mu: T, f: &Mat<T, D>, sweeps: u32) -> Result<Mat<T, D>>
where
    LMat<T, D>: LDim<T>,
{
    let (r, c) = ahat_lanes::<T, D>(mu, &f.cols, sweeps);
    match c.error::<T>(0) {
        None => Ok(Mat::from_cols(r)),
        Some(e) => Err(e),
    }
}

/// `Ĉ:Z` of one particle by the generic kernel on one scalar (see [`ahat_one`]).
#[inline]
pub fn chat_z_one<T: Real, const D: usize>(
    mu: T,
    f: &Mat<T, D>,
    z: &Mat<T, D>,
    sweeps: u32,
) -> Result<Mat<T, D>>
where
    LMat<T, D>: LDim<T>,
{
    let (r, c) = chat_z_lanes::<T, D>(mu, &f.cols, &z.cols, sweeps);
    match c.error::<T>(0) {
        None => Ok(Mat::from_cols(r)),
        Some(e) => Err(e),
    }
}

/// Runs `chunk` over `f` in chunks of `M::LANES`, writing successful particles to `out` and
/// returning the first failure `(index, error)`.
#[inline(always)]
fn drive<M: BatchKernel>(
    n: usize,
    out: &mut [M],
    mut chunk: impl FnMut(core::ops::Range<usize>, &mut [M], &mut [Option<Error>]),
) -> core::result::Result<(), (usize, Error)> {
    let mut first: Option<(usize, Error)> = None;
    let mut buf = [M::zero(); MAX_LANES];
    let mut err = [None; MAX_LANES];
    let mut start = 0;
    while start < n {
        let len = M::LANES.min(n - start);
        chunk(start..start + len, &mut buf[..len], &mut err[..len]);
        for l in 0..len {
            match err[l] {
                None => out[start + l] = buf[l],
                Some(e) => {
                    if first.is_none() {
                        first = Some((start + l, e));
                    }
                }
            }
        }
        start += len;
    }
    match first {
        None => Ok(()),
        Some(x) => Err(x),
    }
}

/// `out[i] = Â(mu[i], f[i])` for every valid particle; a failed particle's `out[i]` is left
/// untouched. Returns the first failure's index and error. Lengths must agree
/// ([`Error::InvalidArgument`] at index 0 otherwise).
#[inline]
pub fn ahat_batch<M: BatchKernel>(
    mu: &[M::Scalar],
    f: &[M],
    out: &mut [M],
) -> core::result::Result<(), (usize, Error)> {
    let n = f.len();
    if mu.len() != n || out.len() != n {
        return Err((0, Error::InvalidArgument));
    }
    drive::<M>(n, out, |r, o, e| M::ahat_chunk(&mu[r.clone()], &f[r], o, e))
}

/// `out[i] = Ĉ(mu[i], f[i]):z[i]`, with the conventions of [`ahat_batch`].
#[inline]
pub fn chat_z_batch<M: BatchKernel>(
    mu: &[M::Scalar],
    f: &[M],
    z: &[M],
    out: &mut [M],
) -> core::result::Result<(), (usize, Error)> {
    let n = f.len();
    if mu.len() != n || z.len() != n || out.len() != n {
        return Err((0, Error::InvalidArgument));
    }
    drive::<M>(n, out, |r, o, e| {
        M::chat_z_chunk(&mu[r.clone()], &f[r.clone()], &z[r], o, e)
    })
}

use crate::error::Result;
use crate::scalar::Real;
