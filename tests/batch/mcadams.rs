//! McAdams: U, V ∈ SO(3), sorted σ, sign convention, reconstruction, sweeps 2..8.
use super::*;
use ampm_core::polar::{McAdams, SvdMethod};

// ---------------------------------------------------------------------------------------
// 5. McAdams.

/// Sweep-limited part of the reconstruction error, `‖UΣVᵀ − F‖_max / ‖F‖_max`, for the
/// family σ ∈ [0.2, 5] (κ ≤ 25), *stated* (not derived): the approximate rotations reduce a
/// pivot by at least the factor 0.6 of the π/8 fallback (McAdams et al. §2.2) but the cyclic
/// order re-couples the pairs, so no useful a-priori bound exists; these are 4× the largest
/// errors measured over 20000 matrices of the family (f64; 2 → 0.27, 3 → 0.077, 4 → 6e-3,
/// 5 → 3e-4, 6 → 1.7e-7, ≥ 7 → at rounding level), independent of the precision.
fn sweep_limit(sweeps: u32) -> f64 {
    match sweeps {
        0..=2 => 1.1,
        3 => 0.31,
        4 => 2.4e-2,
        5 => 1.2e-3,
        6 => 7e-7,
        _ => 0.0,
    }
}

fn mcadams_properties<T: Real>() {
    let eps = T::EPSILON.to_f64();
    let mut rng = Pcg64::seed_from_u64(99);
    let fs: Vec<Mat<f64, 3>> = (0..3000)
        .map(|i| {
            let f = family::<3>(&mut rng, 0.2, 5.0);
            // Every third has det < 0 (sign convention), scaled over a wide range.
            let s = 2f64.powi(rng.random_range(-40..40));
            let f = if i % 3 == 0 { -f } else { f };
            f * s
        })
        .collect();
    for sweeps in 2..=8 {
        let m = McAdams::new(sweeps).unwrap();
        for f64m in &fs {
            let f = f64m.cast::<T>();
            let svd = m.svd(&f).unwrap();
            let (u, v, s) = (svd.u.cast::<f64>(), svd.v.cast::<f64>(), svd.sigma);
            // Orthogonality and det = +1: U and V are built from normalised quaternions and
            // Givens rotations of unit (c, s); each entry carries O(10) roundings: 16ε.
            let id = Mat::<f64, 3>::identity();
            for (name, q) in [("U", u), ("V", v)] {
                let e = (q.transpose() * q - id).max_abs();
                assert!(
                    e <= 16.0 * eps,
                    "{name}ᵀ{name} − I = {e:e}, sweeps {sweeps}"
                );
                assert!(
                    (q.det() - 1.0).abs() <= 16.0 * eps,
                    "det {name}, sweeps {sweeps}"
                );
            }
            // Sign convention: σ₀, σ₁ ≥ 0; σ₂ has the sign of det F.
            let s64 = s.map(|x| x.to_f64());
            assert!(s64[0] >= 0.0 && s64[1] >= 0.0, "{s64:?}");
            assert_eq!(s64[2] < 0.0, f.cast::<f64>().det() < 0.0, "{s64:?}");
            // Sorted by magnitude, up to the rounding of the QR diagonal (8ε relative) and,
            // before convergence, the sweep-limited error.
            let tol = 8.0 * eps + sweep_limit(sweeps);
            assert!(s64[1] <= s64[0] * (1.0 + tol), "{s64:?}");
            assert!(s64[2].abs() <= s64[1] * (1.0 + tol), "{s64:?}");
            // Reconstruction: ε‖F‖ times a rounding factor (S = GᵀG, 3 sweeps of rotations
            // with O(10) roundings each contribute relative errors in V of a few ε; forming
            // B = GV, three Givens and UΣVᵀ add O(30) roundings: 64ε), plus the sweep limit.
            let fm = f.cast::<f64>();
            let rec = (svd.reconstruct().cast::<f64>() - fm).max_abs() / fm.max_abs();
            let bound = 64.0 * eps + sweep_limit(sweeps);
            assert!(
                rec <= bound,
                "reconstruction {rec:e} > {bound:e}, sweeps {sweeps}"
            );
        }
    }
}

#[test]
fn mcadams_f32() {
    mcadams_properties::<f32>();
}

#[test]
fn mcadams_f64() {
    mcadams_properties::<f64>();
}

#[test]
fn mcadams_sweep_count_is_validated() {
    assert_eq!(McAdams::new(0), Err(Error::InvalidArgument));
    assert_eq!(McAdams::new(17), Err(Error::InvalidArgument));
    assert!(McAdams::new(1).is_ok() && McAdams::new(16).is_ok());
    // A field set out of range is clamped, never looped 0 or 2³² times.
    let f = Mat::<f64, 3>::from_rows([[1.0, 0.2, 0.0], [0.1, 1.0, 0.3], [0.0, 0.0, 0.9]]);
    let a = McAdams { sweeps: 0 }.svd(&f).unwrap();
    let b = McAdams { sweeps: 1 }.svd(&f).unwrap();
    assert_eq!(a, b);
    let a = McAdams { sweeps: u32::MAX }.svd(&f).unwrap();
    let b = McAdams { sweeps: 16 }.svd(&f).unwrap();
    assert_eq!(a, b);
    assert_eq!(
        McAdams::default().svd(&(f * f64::NAN)),
        Err(Error::NonFinite)
    );
}
