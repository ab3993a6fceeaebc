//! Per-particle cost of each SVD method on a batch of random particles, each dim × precision.
//!
//! `cargo bench -p ampm-tools --bench methods`. `Throughput::Elements(n)` makes criterion
//! report particles per second; ns per particle = 1e9 / that rate.

use ampm_core::polar::{ClosedForm2, HighamNoferini, McAdams, OneSidedJacobi, QrSvd, SvdMethod};
use ampm_core::{Mat, Matrix, Real};
use ampm_tools::workload::{cast_particles, particles, HaarRotation};
use criterion::measurement::WallTime;
use criterion::{criterion_group, criterion_main, BenchmarkGroup, Criterion, Throughput};
use std::hint::black_box;
use std::time::Duration;

/// Particles per batch.
const N: usize = 1024;

fn bench_method<T: Real, const D: usize, S: SvdMethod<Mat<T, D>>>(
    g: &mut BenchmarkGroup<'_, WallTime>,
    label: &str,
    method: S,
) where
    Mat<T, D>: Matrix<Scalar = T>,
    Mat<f64, D>: HaarRotation,
{
    let parts = cast_particles::<T, D>(&particles::<D>(N, D as u64));
    g.bench_function(format!("{label}/{D}d/{}", T::NAME), |b| {
        b.iter(|| {
            for (f, _) in &parts {
                let _ = black_box(black_box(&method).svd(black_box(f)));
            }
        });
    });
}

/// Every method in precision `T`.
fn all_methods<T: Real>(g: &mut BenchmarkGroup<'_, WallTime>) {
    bench_method::<T, 2, _>(g, "closed-form", ClosedForm2);
    bench_method::<T, 3, _>(g, "one-sided-jacobi", OneSidedJacobi::default());
    for sweeps in [2, 4, 8] {
        bench_method::<T, 3, _>(g, &format!("mcadams-{sweeps}"), McAdams { sweeps });
    }
    bench_method::<T, 3, _>(g, "qr", QrSvd::default());
    bench_method::<T, 3, _>(g, "higham-noferini", HighamNoferini::default());
}

fn methods(c: &mut Criterion) {
    let mut g = c.benchmark_group("svd");
    g.throughput(Throughput::Elements(N as u64));
    all_methods::<f32>(&mut g);
    all_methods::<f64>(&mut g);
    g.finish();
}

criterion_group! {
    name = benches;
    // Modest: the machine's two cores are shared.
    config = Criterion::default()
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(2))
        .sample_size(30);
    targets = methods
}
criterion_main!(benches);
