//! Paths: for every dim × precision and every instruction set of this CPU, the combined call
//! gives the same statuses on every path; the AVX2 and AVX-512 paths give identical bits; the
//! scalar path (unfused `a·b + c`) agrees within a stated bound; a particle's result does not
//! depend on `n` or on its index; failed outputs are untouched and `first_failed` / the status
//! are the first failure's; in place (`ahat == f`) gives the same.
use super::*;
use ampm_core::lane::IsaKind;

/// The bound on the scalar path against the vector paths, in units of ε of the natural
/// scale: both are the same sequence of ~10³ operations per particle whose roundings differ
/// only where the vector paths fuse `a·b + c`; each such rounding is ≤ ε relative, amplified
/// by at most κ ≤ 4·d on this family (σ ∈ [0.5, 2]) through the SVD and the reciprocals.
/// Measured worst cases are below 40ε.
const SCALAR_VS_SIMD: f64 = 512.0;

fn paths_agree<T: BatchReal, const D: usize>()
where
    Dim<D>: LaneDim<D>,
    Mat<f64, D>: Matrix<Scalar = f64, Vector = [f64; D]> + HaarRotation,
    Mat<T, D>: Matrix<Scalar = T>,
{
    let e = D * D;
    let eps = T::EPSILON.to_f64();
    let isas = Isa::available();
    let mut worst = 0.0f64;
    for (k, n) in [0usize, 1, 3, 8, 17, 32, 33, 70].into_iter().enumerate() {
        let cs = cases::<T, D>(n, 11 + k as u64);
        for psd in [false, true] {
            let runs: Vec<Run<T>> = isas.iter().map(|&i| run::<T, D>(i, &cs, psd)).collect();
            // Statuses, untouched outputs, first failure.
            let first = cs.iter().position(|c| c.expect.is_some());
            for (r, isa) in runs.iter().zip(&isas) {
                assert_eq!(r.2.first_failed, first.unwrap_or(n), "{isa:?} n={n}");
                assert_eq!(r.2.error, first.and_then(|i| cs[i].expect), "{isa:?} n={n}");
                for (i, c) in cs.iter().enumerate() {
                    let a = &r.0[i * e..(i + 1) * e];
                    let cz = &r.1[i * e..(i + 1) * e];
                    if c.expect.is_some() {
                        assert!(
                            a.iter().chain(cz).all(|&x| x == T::from_f64(-7.25)),
                            "{isa:?} {i} written"
                        );
                    } else {
                        assert!(a.iter().chain(cz).all(|x| x.is_finite()), "{isa:?} {i}");
                        if c.mu == T::ZERO {
                            assert!(a.iter().chain(cz).all(|&x| x == T::ZERO), "liquid {i}");
                        }
                    }
                }
            }
            // AVX2 and AVX-512: identical bits.
            let simd: Vec<&Run<T>> = runs
                .iter()
                .zip(&isas)
                .filter(|(_, i)| i.kind() != IsaKind::Scalar)
                .map(|(r, _)| r)
                .collect();
            for w in simd.windows(2) {
                let bits = |v: &[T]| v.iter().map(|x| x.to_f64().to_bits()).collect::<Vec<_>>();
                assert_eq!(bits(&w[0].0), bits(&w[1].0), "Â differs between SIMD paths");
                assert_eq!(
                    bits(&w[0].1),
                    bits(&w[1].1),
                    "Ĉ:Z differs between SIMD paths"
                );
            }
            // Scalar against SIMD: within the stated bound.
            if let Some(v) = simd.first() {
                for (i, c) in cs.iter().enumerate().filter(|(_, c)| c.expect.is_none()) {
                    let fnorm = c.f.cast::<f64>().ddot(&c.f.cast::<f64>()).sqrt();
                    let sa = c.mu.to_f64().abs().max(1.0) * (1.0 + fnorm * fnorm);
                    let sz = sa * c.z.cast::<f64>().ddot(&c.z.cast::<f64>()).sqrt().max(1.0);
                    let r = &runs[0];
                    let ea = rel(&r.0[i * e..(i + 1) * e], &v.0[i * e..(i + 1) * e], sa) / eps;
                    let ec = rel(&r.1[i * e..(i + 1) * e], &v.1[i * e..(i + 1) * e], sz) / eps;
                    worst = worst.max(ea).max(ec);
                    assert!(
                        ea <= SCALAR_VS_SIMD && ec <= SCALAR_VS_SIMD,
                        "particle {i}: {ea} {ec} ε"
                    );
                }
            }
            // Position and n independence: each particle alone equals its lane in the batch.
            for (r, &isa) in runs.iter().zip(&isas) {
                for i in (0..n).step_by(5) {
                    let one = run::<T, D>(isa, &cs[i..=i], psd);
                    assert_eq!(one.0[..], r.0[i * e..(i + 1) * e], "{isa:?} Â of {i} alone");
                    assert_eq!(
                        one.1[..],
                        r.1[i * e..(i + 1) * e],
                        "{isa:?} Ĉ:Z of {i} alone"
                    );
                }
            }
        }
    }
    eprintln!("{}D {}: scalar vs SIMD worst {worst:.1} ε", D, T::NAME);
}

#[test]
fn paths_agree_2d_f32() {
    paths_agree::<f32, 2>();
}
#[test]
fn paths_agree_2d_f64() {
    paths_agree::<f64, 2>();
}
#[test]
fn paths_agree_3d_f32() {
    paths_agree::<f32, 3>();
}
#[test]
fn paths_agree_3d_f64() {
    paths_agree::<f64, 3>();
}

#[test]
fn in_place_equals_out_of_place() {
    let cs = cases::<f32, 3>(40, 5);
    let isa = *Isa::available().last().unwrap();
    let (a, _, st) = run::<f32, 3>(isa, &cs, false);
    let mu: Vec<f32> = cs.iter().map(|c| c.mu).collect();
    let mut f: Vec<f32> = cs.iter().flat_map(|c| c.f.cols.concat()).collect();
    let f0 = f.clone();
    let st2 = unsafe {
        ampm::ampm_ahat_batch_3d_f32(
            40,
            mu.as_ptr(),
            f.as_ptr(),
            f.as_mut_ptr(),
            std::ptr::null_mut(),
        )
    };
    let fa = cs.iter().position(|c| c.expect_ahat().is_some()).unwrap();
    assert_eq!(st2, cs[fa].expect_ahat().unwrap().into());
    let _ = st;
    for i in 0..40 {
        let r = &f[9 * i..9 * i + 9];
        if cs[i].z_only {
            assert!(r.iter().all(|x| x.is_finite()), "{i}");
        } else if cs[i].expect.is_none() {
            assert_eq!(r, &a[9 * i..9 * i + 9]);
        } else {
            let bits = |v: &[f32]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
            assert_eq!(
                bits(r),
                bits(&f0[9 * i..9 * i + 9]),
                "failed particle {i} overwritten"
            );
        }
    }
}
