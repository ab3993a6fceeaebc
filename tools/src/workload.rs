//! The workload that the report (`ampm-report`) and the criterion benches time: seeded random
//! particles, and the C ABI batch entry points reached through one generic trait.
//!
//! Random particles: `F = U diag(σ) Vᵀ`, every `σᵢ` log-uniform in `[0.2, 5]` (stretch and
//! compression up to 5×, `J > 0`), `U` and `V` Haar-distributed on `SO(d)`. `Z` (the direction
//! of `𝓑:Z`, `Ĉ:Z`) has entries uniform in `[−1, 1]`, scaled to unit Frobenius norm. Everything
//! is drawn in `f64` from a seeded PCG, so every run sees the same particles.

use ampm::AmpmStatus;
use ampm_core::{Mat, Matrix};
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;

/// Smallest singular value of the random particles.
pub const SIGMA_MIN: f64 = 0.2;
/// Largest singular value of the random particles.
pub const SIGMA_MAX: f64 = 5.0;
/// Seed of every random stream of the report and the benches.
pub const SEED: u64 = 0x5eed_a3a0_2014;

/// A seeded generator; distinct `stream`s give independent sequences.
#[inline]
#[must_use]
pub fn rng(stream: u64) -> Pcg64 {
    Pcg64::seed_from_u64(SEED.wrapping_add(stream.wrapping_mul(0x9e37_79b9_7f4a_7c15)))
}

/// Square `f64` matrices of a dimension that has a Haar-random rotation (2 and 3).
pub trait HaarRotation: Matrix<Scalar = f64> {
    /// A rotation drawn from the Haar (uniform) measure on `SO(d)`.
    #[must_use]
    fn haar(rng: &mut impl Rng) -> Self;
}

impl HaarRotation for Mat<f64, 2> {
    /// `SO(2)` is the circle: the angle is uniform in `[0, 2π)`.
    #[inline]
    fn haar(rng: &mut impl Rng) -> Self {
        let t = rng.random_range(0.0..std::f64::consts::TAU);
        let (s, c) = t.sin_cos();
        Mat::from_rows([[c, -s], [s, c]])
    }
}

impl HaarRotation for Mat<f64, 3> {
    /// Shoemake, "Uniform random rotations" (Graphics Gems III, 1992): a unit quaternion
    /// uniform on `S³` from three uniforms, then the usual quaternion-to-matrix formula.
    #[inline]
    fn haar(rng: &mut impl Rng) -> Self {
        use std::f64::consts::TAU;
        let (u1, u2, u3): (f64, f64, f64) = (rng.random(), rng.random(), rng.random());
        let (r1, r2) = ((1.0 - u1).sqrt(), u1.sqrt());
        let (x, y) = ((TAU * u2).sin() * r1, (TAU * u2).cos() * r1);
        let (z, w) = ((TAU * u3).sin() * r2, (TAU * u3).cos() * r2);
        Mat::from_rows([
            [
                1.0 - 2.0 * (y * y + z * z),
                2.0 * (x * y - w * z),
                2.0 * (x * z + w * y),
            ],
            [
                2.0 * (x * y + w * z),
                1.0 - 2.0 * (x * x + z * z),
                2.0 * (y * z - w * x),
            ],
            [
                2.0 * (x * z - w * y),
                2.0 * (y * z + w * x),
                1.0 - 2.0 * (x * x + y * y),
            ],
        ])
    }
}

/// One random deformation gradient (see the module docs for the distribution).
#[inline]
#[must_use]
pub fn random_f<M: HaarRotation>(rng: &mut impl Rng) -> M {
    let (lo, hi) = (SIGMA_MIN.ln(), SIGMA_MAX.ln());
    let mut sigma = M::Vector::default();
    for i in 0..M::DIM {
        sigma[i] = rng.random_range(lo..hi).exp();
    }
    let u = M::haar(rng);
    let v = M::haar(rng);
    u * M::from_diagonal(sigma) * v.transpose()
}

/// One random direction `Z`, unit Frobenius norm.
#[inline]
#[must_use]
pub fn random_direction<M: Matrix<Scalar = f64>>(rng: &mut impl Rng) -> M {
    let mut z = M::zero();
    for j in 0..M::DIM {
        for i in 0..M::DIM {
            z[(i, j)] = rng.random_range(-1.0..1.0);
        }
    }
    z * (1.0 / z.ddot(&z).sqrt())
}

/// `n` random particles `(F, Z)` of dimension `D`, from stream `stream`.
#[must_use]
#[inline]
pub fn particles<const D: usize>(n: usize, stream: u64) -> Vec<(Mat<f64, D>, Mat<f64, D>)>
where
    Mat<f64, D>: HaarRotation,
{
    let mut r = rng(stream);
    (0..n)
        .map(|_| {
            let f = random_f::<Mat<f64, D>>(&mut r);
            (f, random_direction::<Mat<f64, D>>(&mut r))
        })
        .collect()
}

/// The C ABI batch entry points of one dimension × precision, reached generically.
pub trait FfiBatch: Matrix {
    /// `ampm_ahat_batch_<d>d_<t>`.
    ///
    /// # Safety
    /// As the C function: arrays valid for `n` particles, or null when `n = 0`.
    unsafe fn ahat_batch(
        n: usize,
        mu: *const Self::Scalar,
        f: *const Self::Scalar,
        out: *mut Self::Scalar,
        first_failed: *mut usize,
    ) -> AmpmStatus;
    /// `ampm_chat_z_batch_<d>d_<t>`.
    ///
    /// # Safety
    /// As the C function: arrays valid for `n` particles, or null when `n = 0`.
    unsafe fn chat_z_batch(
        n: usize,
        mu: *const Self::Scalar,
        f: *const Self::Scalar,
        z: *const Self::Scalar,
        out: *mut Self::Scalar,
        first_failed: *mut usize,
    ) -> AmpmStatus;
}

macro_rules! ffi_batch {
    ($t:ty, $d:literal, $ahat:ident, $chat:ident) => {
        impl FfiBatch for Mat<$t, $d> {
            #[inline]
            unsafe fn ahat_batch(
                n: usize,
                mu: *const $t,
                f: *const $t,
                out: *mut $t,
                first_failed: *mut usize,
            ) -> AmpmStatus {
                ampm::$ahat(n, mu, f, out, first_failed)
            }
            #[inline]
            unsafe fn chat_z_batch(
                n: usize,
                mu: *const $t,
                f: *const $t,
                z: *const $t,
                out: *mut $t,
                first_failed: *mut usize,
            ) -> AmpmStatus {
                ampm::$chat(n, mu, f, z, out, first_failed)
            }
        }
    };
}
ffi_batch!(f32, 2, ampm_ahat_batch_2d_f32, ampm_chat_z_batch_2d_f32);
ffi_batch!(f64, 2, ampm_ahat_batch_2d_f64, ampm_chat_z_batch_2d_f64);
ffi_batch!(f32, 3, ampm_ahat_batch_3d_f32, ampm_chat_z_batch_3d_f32);
ffi_batch!(f64, 3, ampm_ahat_batch_3d_f64, ampm_chat_z_batch_3d_f64);

/// Structure of arrays for the C ABI batch calls: `n` values of `μ`, `F`, `Z` (column-major,
/// contiguous) and an output array, all in the precision of `M`.
#[derive(Clone, Debug)]
pub struct FfiArrays<M: Matrix> {
    /// Number of particles.
    pub n: usize,
    /// `μ` of each particle.
    pub mu: Vec<M::Scalar>,
    /// `F` of each particle, `d²` scalars each.
    pub f: Vec<M::Scalar>,
    /// `Z` of each particle, `d²` scalars each.
    pub z: Vec<M::Scalar>,
    /// Output, `d²` scalars per particle.
    pub out: Vec<M::Scalar>,
}

impl<M: Matrix + FfiBatch> FfiArrays<M> {
    /// Packs particles (already in the precision of `M`) with a common `μ`.
    #[must_use]
    #[inline]
    pub fn new(mu: M::Scalar, parts: &[(M, M)]) -> Self {
        let n = parts.len();
        let mut f = Vec::with_capacity(n * M::LEN);
        let mut z = Vec::with_capacity(n * M::LEN);
        for (fi, zi) in parts {
            f.extend_from_slice(fi.to_array().as_ref());
            z.extend_from_slice(zi.to_array().as_ref());
        }
        Self {
            n,
            mu: vec![mu; n],
            f,
            z,
            out: vec![M::Scalar::default(); n * M::LEN],
        }
    }

    /// `Â` of every particle into `out` (C ABI); the status and the first failed index.
    #[inline]
    #[must_use]
    pub fn ahat(&mut self) -> (AmpmStatus, usize) {
        let mut first = usize::MAX;
        // SAFETY: every array holds `n` particles (built by `new`).
        let st = unsafe {
            M::ahat_batch(
                self.n,
                self.mu.as_ptr(),
                self.f.as_ptr(),
                self.out.as_mut_ptr(),
                &mut first,
            )
        };
        (st, first)
    }

    /// `Ĉ:Z` of every particle into `out` (C ABI); the status and the first failed index.
    #[inline]
    #[must_use]
    pub fn chat_z(&mut self) -> (AmpmStatus, usize) {
        let mut first = usize::MAX;
        // SAFETY: every array holds `n` particles (built by `new`).
        let st = unsafe {
            M::chat_z_batch(
                self.n,
                self.mu.as_ptr(),
                self.f.as_ptr(),
                self.z.as_ptr(),
                self.out.as_mut_ptr(),
                &mut first,
            )
        };
        (st, first)
    }

    /// Output of particle `i`.
    #[inline]
    #[must_use]
    pub fn out_mat(&self, i: usize) -> M {
        let mut a = M::Array::default();
        a.as_mut()
            .copy_from_slice(&self.out[i * M::LEN..(i + 1) * M::LEN]);
        M::from_array(&a)
    }
}

/// Rounds `f64` particles to the precision `T` (the inputs of the `T` kernels; cast back to
/// `f64` they are the exactly representable inputs of the `f64` comparison run).
#[must_use]
#[inline]
pub fn cast_particles<T: ampm_core::Real, const D: usize>(
    parts: &[(Mat<f64, D>, Mat<f64, D>)],
) -> Vec<(Mat<T, D>, Mat<T, D>)> {
    parts.iter().map(|(f, z)| (f.cast(), z.cast())).collect()
}

/// Smallest singular value of the batch workload of `c_tests/bench_kernels` (and of the
/// `batch` bench and the report's fast-path timings, which reproduce its distribution).
pub const BATCH_SIGMA_MIN: f64 = 0.5;
/// Largest singular value of that workload.
pub const BATCH_SIGMA_MAX: f64 = 2.0;

/// `n` particles in the distribution of `c_tests/bench_kernels` (not its draws: that program
/// has its own generator), flattened for the batch calls: `(μ, F, Z)` with `μ = 1`,
/// `F = R₁ diag(σ) R₂ᵀ`, σᵢ log-uniform in [0.5, 2] ([`BATCH_SIGMA_MIN`],
/// [`BATCH_SIGMA_MAX`]), `R₁`, `R₂` Haar on `SO(d)`, `Z` entries uniform in `[−1, 1]`; drawn in
/// `f64` from stream `stream` and rounded to `T`; `d²` column-major scalars per particle.
#[must_use]
pub fn batch_workload<T: ampm_core::Real, const D: usize>(
    n: usize,
    stream: u64,
) -> (Vec<T>, Vec<T>, Vec<T>)
where
    Mat<f64, D>: HaarRotation,
{
    let mut r = rng(stream);
    let (lo, hi) = (BATCH_SIGMA_MIN.ln(), BATCH_SIGMA_MAX.ln());
    let (mut f, mut z) = (Vec::with_capacity(n * D * D), Vec::with_capacity(n * D * D));
    for _ in 0..n {
        let mut sigma = [0.0; D];
        for s in &mut sigma {
            *s = r.random_range(lo..hi).exp();
        }
        let fm = <Mat<f64, D>>::haar(&mut r)
            * Mat::from_diagonal(sigma)
            * <Mat<f64, D>>::haar(&mut r).transpose();
        for j in 0..D {
            for i in 0..D {
                f.push(T::from_f64(fm.cols[j][i]));
                z.push(T::from_f64(r.random_range(-1.0..1.0)));
            }
        }
    }
    (vec![T::ONE; n], f, z)
}
