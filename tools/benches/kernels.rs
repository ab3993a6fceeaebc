//! Per-particle cost of `Â + Ĉ:Z` on a batch of random particles, each dim × precision,
//! through the generic Rust path and through the C ABI batch entry points.
//!
//! `cargo bench -p ampm-tools --bench kernels`. Criterion reports time per batch and, through
//! `Throughput::Elements(n)`, particles per second; ns per particle = 1e9 / that rate.
//!
//! - `core`: one `Augmented` per particle (one decomposition), then `ahat()` and `chat_z(Z)`.
//! - `c-abi`: `ampm_ahat_batch_*` then `ampm_chat_z_batch_*` over the arrays, as a C caller
//!   does; each call decomposes `F̂` again, so this path pays for two decompositions.

use ampm_core::augmented::Augmented;
use ampm_core::energy::FixedCorotated;
use ampm_core::polar::{DefaultSvd, SvdMethod};
use ampm_core::{Mat, Matrix, Real};
use ampm_tools::workload::{cast_particles, particles, FfiArrays, FfiBatch, HaarRotation};
use criterion::measurement::WallTime;
use criterion::{criterion_group, criterion_main, BenchmarkGroup, Criterion, Throughput};
use std::hint::black_box;
use std::time::Duration;

/// Particles per batch: large enough to amortise the loop, small enough for L1/L2.
const N: usize = 1024;

fn bench_one<T: Real, const D: usize>(g: &mut BenchmarkGroup<'_, WallTime>)
where
    Mat<T, D>: Matrix<Scalar = T> + FfiBatch,
    Mat<f64, D>: HaarRotation,
    DefaultSvd: SvdMethod<Mat<T, D>>,
{
    let parts = cast_particles::<T, D>(&particles::<D>(N, D as u64));
    let e = FixedCorotated::new(T::ONE);
    g.bench_function(format!("core/{D}d/{}", T::NAME), |b| {
        b.iter(|| {
            for (f, z) in &parts {
                if let Ok(st) = Augmented::new(black_box(&e), black_box(f)) {
                    let _ = black_box(st.ahat());
                    let _ = black_box(st.chat_z(black_box(z)));
                }
            }
        });
    });
    let mut arrays = FfiArrays::new(T::ONE, &parts);
    g.bench_function(format!("c-abi/{D}d/{}", T::NAME), |b| {
        b.iter(|| {
            let a = black_box(&mut arrays);
            black_box(a.ahat());
            black_box(a.chat_z());
        });
    });
}

fn kernels(c: &mut Criterion) {
    let mut g = c.benchmark_group("ahat+chat_z");
    g.throughput(Throughput::Elements(N as u64));
    bench_one::<f32, 2>(&mut g);
    bench_one::<f64, 2>(&mut g);
    bench_one::<f32, 3>(&mut g);
    bench_one::<f64, 3>(&mut g);
    g.finish();
}

criterion_group! {
    name = benches;
    // Modest: the machine's two cores are shared.
    config = Criterion::default()
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(2))
        .sample_size(30);
    targets = kernels
}
criterion_main!(benches);
