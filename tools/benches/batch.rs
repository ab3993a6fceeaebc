//! Per-particle cost of one explicit + one implicit step's constitutive work, `Â` and `Ĉ:Z`,
//! through the C ABI batch functions (`ampm_ahat_batch_*` then `ampm_chat_z_batch_*` on the
//! same 4096 particles), against the scalar paths:
//!
//! - `batch`: the vectorized batch functions (what a host calls per step);
//! - `scalar_abi`: a loop over the single-particle C functions (default method: one-sided
//!   Jacobi in 3D);
//! - `scalar_same_method`: the batch's own generic kernel on one scalar lane
//!   (`ampm_core::batch::{ahat_one, chat_z_one}`, same method and sweeps), so
//!   `scalar_same_method / batch` is the gain of vectorization alone.
//!
//! Throughput is in particles (`Throughput::Elements(n)`): criterion's time per element is
//! the ns/particle for `Â + Ĉ:Z`. Inputs: `F = R₁ diag(σ) R₂ᵀ` with `σ` log-uniform in
//! `[0.2, 5]` (the accuracy family of issue 2), `Z` uniform in `[−1, 1]`, `μ = 1`.
//!
//! Targets (issue 3, one core): 3D f32 ≤ 25 ns, 3D f64 ≤ 60 ns, 2D ≤ 8 ns.

use ampm_core::batch::{ahat_one, chat_z_one, BatchKernel};
use ampm_core::{Mat, Matrix, Real};
use ampm_tools::workload::HaarRotation;
use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use rand::{Rng, SeedableRng};
use std::hint::black_box;
use std::time::Duration;

const N: usize = 4096;

/// `n` particles `(F, Z)` of the accuracy family, flattened column-major.
fn particles<T: Real, const D: usize>(n: usize) -> (Vec<T>, Vec<T>, Vec<T>)
where
    Mat<f64, D>: Matrix<Scalar = f64>,
    Mat<f64, D>: HaarRotation,
    Mat<T, D>: Matrix<Scalar = T>,
{
    let mut rng = rand_pcg::Pcg64::seed_from_u64(7);
    let (mut f, mut z) = (Vec::new(), Vec::new());
    for _ in 0..n {
        let s: [f64; D] = std::array::from_fn(|_| rng.random_range(0.2f64.ln()..5f64.ln()).exp());
        let fm = <Mat<f64, D>>::haar(&mut rng)
            * Mat::from_diagonal(s)
            * <Mat<f64, D>>::haar(&mut rng).transpose();
        let zm = Mat::<f64, D>::from_cols(std::array::from_fn(|_| {
            std::array::from_fn(|_| rng.random_range(-1.0..1.0))
        }));
        f.extend_from_slice(Matrix::to_array(&fm.cast::<T>()).as_ref());
        z.extend_from_slice(Matrix::to_array(&zm.cast::<T>()).as_ref());
    }
    (vec![T::ONE; n], f, z)
}

macro_rules! bench_combo {
    ($fname:ident, $t:ident, $d:literal, $ab:ident, $cb:ident, $a1:ident, $c1:ident) => {
        fn $fname(c: &mut Criterion) {
            let (mu, f, z) = particles::<$t, $d>(N);
            let mut out_a = vec![0.0 as $t; N * $d * $d];
            let mut out_c = vec![0.0 as $t; N * $d * $d];
            let mut g = c.benchmark_group(concat!(
                "ahat+chat_z/",
                stringify!($d),
                "d_",
                stringify!($t)
            ));
            g.throughput(Throughput::Elements(N as u64));
            g.bench_function(BenchmarkId::new("batch", N), |b| {
                b.iter(|| unsafe {
                    let mut ff = 0usize;
                    let s1 = ampm::$ab(N, mu.as_ptr(), f.as_ptr(), out_a.as_mut_ptr(), &mut ff);
                    let s2 = ampm::$cb(
                        N,
                        mu.as_ptr(),
                        f.as_ptr(),
                        z.as_ptr(),
                        out_c.as_mut_ptr(),
                        &mut ff,
                    );
                    black_box((s1, s2));
                })
            });
            g.bench_function(BenchmarkId::new("scalar_abi", N), |b| {
                b.iter(|| unsafe {
                    let l = $d * $d;
                    for i in 0..N {
                        let s1 =
                            ampm::$a1(mu[i], f.as_ptr().add(i * l), out_a.as_mut_ptr().add(i * l));
                        let s2 = ampm::$c1(
                            mu[i],
                            f.as_ptr().add(i * l),
                            z.as_ptr().add(i * l),
                            out_c.as_mut_ptr().add(i * l),
                        );
                        black_box((s1, s2));
                    }
                })
            });
            let fm: Vec<Mat<$t, $d>> = f
                .chunks(($d * $d))
                .map(|s| Mat::from_col_major(s).unwrap())
                .collect();
            let zm: Vec<Mat<$t, $d>> = z
                .chunks(($d * $d))
                .map(|s| Mat::from_col_major(s).unwrap())
                .collect();
            let sweeps = <Mat<$t, $d> as BatchKernel>::SWEEPS;
            g.bench_function(BenchmarkId::new("scalar_same_method", N), |b| {
                b.iter(|| {
                    for i in 0..N {
                        black_box(ahat_one(mu[i], black_box(&fm[i]), sweeps).ok());
                        black_box(chat_z_one(mu[i], black_box(&fm[i]), &zm[i], sweeps).ok());
                    }
                })
            });
            g.finish();
        }
    };
}

bench_combo!(
    b2_f32,
    f32,
    2,
    ampm_ahat_batch_2d_f32,
    ampm_chat_z_batch_2d_f32,
    ampm_ahat_2d_f32,
    ampm_chat_z_2d_f32
);
bench_combo!(
    b2_f64,
    f64,
    2,
    ampm_ahat_batch_2d_f64,
    ampm_chat_z_batch_2d_f64,
    ampm_ahat_2d_f64,
    ampm_chat_z_2d_f64
);
bench_combo!(
    b3_f32,
    f32,
    3,
    ampm_ahat_batch_3d_f32,
    ampm_chat_z_batch_3d_f32,
    ampm_ahat_3d_f32,
    ampm_chat_z_3d_f32
);
bench_combo!(
    b3_f64,
    f64,
    3,
    ampm_ahat_batch_3d_f64,
    ampm_chat_z_batch_3d_f64,
    ampm_ahat_3d_f64,
    ampm_chat_z_3d_f64
);

fn config() -> Criterion {
    Criterion::default()
        .sample_size(20)
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(2))
}

criterion_group! {
    name = benches;
    config = config();
    targets = b2_f32, b2_f64, b3_f32, b3_f64
}
criterion_main!(benches);
