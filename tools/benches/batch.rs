//! Per-particle cost of the fast kernels of fixed corotated Ψ̂ (`ampm_core::kernel::batch`)
//! on each instruction set this CPU supports (`Isa::available()`: scalar, avx2, avx512), per
//! case 2D/3D × f32/f64, on `N` = 4096 particles:
//!
//! - `combined/<case>/<isa>`: `ahat_chat_z` with both outputs (Â and Ĉ:Z, one decomposition);
//! - `separate/<case>/<isa>`: an Â-only call, then a Ĉ:Z-only call (two decompositions, what
//!   `ampm_ahat_batch` + `ampm_chat_z_batch` cost);
//! - `prepare/<case>/<isa>`: `prepare` with Â (decomposition + prepared Hessian slots);
//! - `apply/<case>/<isa>`, `apply_psd/<case>/<isa>`: `apply` of the prepared slots to Z
//!   (Ĉ:Z, and the PSD-projected Ĉ⁺:Z);
//! - `single/<case>`: a loop over the single-particle C functions `ampm_ahat_<d>d_<t>` +
//!   `ampm_chat_z_<d>d_<t>` (scalar lanes, two decompositions per particle).
//!
//! Throughput is in particles (`Throughput::Elements(N)`), so criterion's time per element is
//! ns/particle. Workload: `ampm_tools::workload::batch_workload`, the distribution of
//! `c_tests/bench_kernels` (`F = R₁ diag(σ) R₂ᵀ`, σᵢ log-uniform in [0.5, 2], R₁, R₂ Haar on
//! SO(d), μ = 1, Z with entries uniform in [−1, 1]), rounded to the case's precision.
//!
//! `cargo bench -p ampm-tools --bench batch` (short by design: 10 samples of ~1 s each).

use ampm_core::kernel::batch::{ahat_chat_z, apply, prepare, BatchReal, Outputs};
use ampm_core::kernel::{prepared, Dim, LaneDim};
use ampm_core::lane::Isa;
use ampm_core::Mat;
use ampm_tools::workload::{batch_workload, HaarRotation};
use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use std::hint::black_box;
use std::time::Duration;

/// Particles per batch.
const N: usize = 4096;

/// The single-particle C functions of one case.
trait Single: BatchReal {
    /// `ampm_ahat_<d>d_<t>` then `ampm_chat_z_<d>d_<t>` for one particle.
    ///
    /// # Safety
    /// `f`, `z`, `a`, `c` valid for `d²` scalars.
    unsafe fn ahat_chat_z<const D: usize>(
        mu: Self,
        f: *const Self,
        z: *const Self,
        a: *mut Self,
        c: *mut Self,
    );
}

macro_rules! single {
    ($t:ty, $a2:ident, $c2:ident, $a3:ident, $c3:ident) => {
        impl Single for $t {
            #[inline]
            unsafe fn ahat_chat_z<const D: usize>(
                mu: $t,
                f: *const $t,
                z: *const $t,
                a: *mut $t,
                c: *mut $t,
            ) {
                if D == 2 {
                    black_box(ampm::$a2(mu, f, a));
                    black_box(ampm::$c2(mu, f, z, c));
                } else {
                    black_box(ampm::$a3(mu, f, a));
                    black_box(ampm::$c3(mu, f, z, c));
                }
            }
        }
    };
}
single!(
    f32,
    ampm_ahat_2d_f32,
    ampm_chat_z_2d_f32,
    ampm_ahat_3d_f32,
    ampm_chat_z_3d_f32
);
single!(
    f64,
    ampm_ahat_2d_f64,
    ampm_chat_z_2d_f64,
    ampm_ahat_3d_f64,
    ampm_chat_z_3d_f64
);

/// Every group of one case ("3d_f32").
fn bench_case<T: Single, const D: usize>(c: &mut Criterion)
where
    Dim<D>: LaneDim<D>,
    Mat<f64, D>: HaarRotation,
{
    let case = format!("{D}d_{}", T::NAME);
    let (mu, f, z) = batch_workload::<T, D>(N, 0xba7c + D as u64);
    let (mu, f, z) = (&mu[..], &f[..], &z[..]);
    let mut out_a = vec![T::ZERO; N * D * D];
    let mut out_c = vec![T::ZERO; N * D * D];
    let mut slots = vec![T::ZERO; N * prepared::len(D)];
    let isas = Isa::available();

    // Every call below must succeed on this workload (J > 0, finite): checked once, outside
    // the timed loops, so a failure cannot pass for a fast time.
    for &isa in &isas {
        let st = ahat_chat_z::<T, D>(
            isa,
            mu,
            f,
            Some(z),
            Outputs {
                ahat: Some(&mut out_a),
                chat_z: Some(&mut out_c),
                ..Outputs::default()
            },
        );
        assert_eq!(st.map(|s| s.error), Ok(None), "{case} {}", isa.name());
        let st = prepare::<T, D>(isa, mu, f, Some(&mut out_a[..]), &mut slots);
        assert_eq!(st.map(|s| s.error), Ok(None), "{case} {}", isa.name());
    }

    let mut g = c.benchmark_group(format!("combined/{case}"));
    g.throughput(Throughput::Elements(N as u64));
    for &isa in &isas {
        g.bench_function(isa.name(), |b| {
            b.iter(|| {
                let out = Outputs {
                    ahat: Some(&mut out_a[..]),
                    chat_z: Some(&mut out_c[..]),
                    ..Outputs::default()
                };
                black_box(ahat_chat_z::<T, D>(
                    isa,
                    black_box(mu),
                    black_box(f),
                    Some(z),
                    out,
                ))
            });
        });
    }
    g.finish();

    let mut g = c.benchmark_group(format!("separate/{case}"));
    g.throughput(Throughput::Elements(N as u64));
    for &isa in &isas {
        g.bench_function(isa.name(), |b| {
            b.iter(|| {
                let a = Outputs {
                    ahat: Some(&mut out_a[..]),
                    ..Outputs::default()
                };
                black_box(ahat_chat_z::<T, D>(
                    isa,
                    black_box(mu),
                    black_box(f),
                    None,
                    a,
                ))
                .ok();
                let cz = Outputs {
                    chat_z: Some(&mut out_c[..]),
                    ..Outputs::default()
                };
                black_box(ahat_chat_z::<T, D>(
                    isa,
                    black_box(mu),
                    black_box(f),
                    Some(z),
                    cz,
                ))
            });
        });
    }
    g.finish();

    let mut g = c.benchmark_group(format!("prepare/{case}"));
    g.throughput(Throughput::Elements(N as u64));
    for &isa in &isas {
        g.bench_function(isa.name(), |b| {
            b.iter(|| {
                black_box(prepare::<T, D>(
                    isa,
                    black_box(mu),
                    black_box(f),
                    Some(&mut out_a[..]),
                    &mut slots,
                ))
            });
        });
    }
    g.finish();

    for (name, psd) in [("apply", false), ("apply_psd", true)] {
        let mut g = c.benchmark_group(format!("{name}/{case}"));
        g.throughput(Throughput::Elements(N as u64));
        for &isa in &isas {
            // Slots written on the same path (a slot is the same on every path up to rounding).
            prepare::<T, D>(isa, mu, f, None, &mut slots).ok();
            g.bench_function(isa.name(), |b| {
                b.iter(|| {
                    black_box(apply::<T, D>(
                        isa,
                        black_box(&slots),
                        black_box(z),
                        &mut out_c,
                        psd,
                    ))
                });
            });
        }
        g.finish();
    }

    let mut g = c.benchmark_group(format!("single/{case}"));
    g.throughput(Throughput::Elements(N as u64));
    g.bench_function("scalar", |b| {
        b.iter(|| {
            let e = D * D;
            for (i, &m) in mu.iter().enumerate() {
                // SAFETY: every array holds N particles of d² scalars.
                unsafe {
                    T::ahat_chat_z::<D>(
                        black_box(m),
                        f.as_ptr().add(i * e),
                        z.as_ptr().add(i * e),
                        out_a.as_mut_ptr().add(i * e),
                        out_c.as_mut_ptr().add(i * e),
                    );
                }
            }
        });
    });
    g.finish();
}

fn b2_f32(c: &mut Criterion) {
    bench_case::<f32, 2>(c);
}
fn b2_f64(c: &mut Criterion) {
    bench_case::<f64, 2>(c);
}
fn b3_f32(c: &mut Criterion) {
    bench_case::<f32, 3>(c);
}
fn b3_f64(c: &mut Criterion) {
    bench_case::<f64, 3>(c);
}

/// Short runs: 10 samples, 1 s of measurement per benchmark (the whole file takes ~2 min
/// with three instruction sets).
fn config() -> Criterion {
    Criterion::default()
        .sample_size(10)
        .warm_up_time(Duration::from_millis(300))
        .measurement_time(Duration::from_secs(1))
}

criterion_group! {
    name = benches;
    config = config();
    targets = b2_f32, b2_f64, b3_f32, b3_f64
}
criterion_main!(benches);
