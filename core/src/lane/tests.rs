//! Tests of the lane types: partial, masked and record (transposing) loads and stores on every
//! lane type the CPU has.

use super::{Lane, X2};

/// `load_n` reads lanes `0..n` and zeroes the rest; `store_n` writes lanes `0..n` only;
/// `load_mask` / `store_mask` do the same for every set of lanes.
fn partial<V: Lane>() {
    let src: [V::Scalar; 32] = core::array::from_fn(|i| V::Scalar::from_i32(i as i32 + 1));
    for n in 0..=V::LANES {
        // SAFETY: `src` holds 32 ≥ LANES scalars.
        let v = unsafe { V::load_n(src.as_ptr(), n) };
        let mut all = [V::Scalar::from_i32(-7); 32];
        v.store(&mut all);
        for (i, x) in all[..V::LANES].iter().enumerate() {
            let want = if i < n { src[i] } else { V::Scalar::ZERO };
            assert_eq!(x.to_f64(), want.to_f64(), "load_n {n} lane {i}");
        }
        let mut dst = [V::Scalar::from_i32(-7); 32];
        // SAFETY: `dst` holds 32 ≥ LANES scalars.
        unsafe { V::load(&src).store_n(dst.as_mut_ptr(), n) };
        for (i, x) in dst.iter().enumerate() {
            let want = if i < n {
                src[i]
            } else {
                V::Scalar::from_i32(-7)
            };
            assert_eq!(x.to_f64(), want.to_f64(), "store_n {n} lane {i}");
        }
    }
    // Arbitrary lane sets, from a pointer one before the buffer (lane 0 never set then).
    for bits in 0..1u32 << V::LANES {
        for shift in 0..2usize {
            let bits = bits & !(shift as u32);
            let base = src.as_ptr().wrapping_add(1).wrapping_sub(shift);
            // SAFETY: lane `i` is read only with bit `i` set, at `src[i + 1 - shift]`,
            // inside `src` (`LANES ≤ 16 < 32`).
            let v = unsafe { V::load_mask(base, bits) };
            let mut all = [V::Scalar::from_i32(-7); 32];
            v.store(&mut all);
            for (i, x) in all[..V::LANES].iter().enumerate() {
                let want = if bits >> i & 1 == 1 {
                    src[i + 1 - shift]
                } else {
                    V::Scalar::ZERO
                };
                assert_eq!(x.to_f64(), want.to_f64(), "load_mask {bits:#x} lane {i}");
            }
            let mut dst = [V::Scalar::from_i32(-7); 32];
            let b = dst.as_mut_ptr().wrapping_add(1).wrapping_sub(shift);
            // SAFETY: as above, in `dst`.
            unsafe { V::load(&src).store_mask(b, bits) };
            for (i, x) in dst.iter().enumerate() {
                let lane = (i + shift).wrapping_sub(1);
                let want = if lane < V::LANES && bits >> lane & 1 == 1 {
                    src[lane]
                } else {
                    V::Scalar::from_i32(-7)
                };
                assert_eq!(x.to_f64(), want.to_f64(), "store_mask {bits:#x} at {i}");
            }
        }
    }
}

/// `load_records` / `store_records` agree with the definition (lane `i`, component `c` at
/// `i·rec + c`) for every record length up to 26 and every component count, and
/// `store_records` writes nothing else.
fn records<V: Lane>() {
    let sentinel = V::Scalar::from_i32(-7);
    for rec in 1..=26usize {
        let len = V::LANES * rec;
        let src: std::vec::Vec<V::Scalar> = (0..len)
            .map(|i| V::Scalar::from_i32(i as i32 + 1))
            .collect();
        for n in 1..=rec {
            let mut out = [V::splat(V::Scalar::ZERO); 26];
            // SAFETY: `src` holds LANES records of `rec ≥ n` scalars.
            unsafe { V::load_records(src.as_ptr(), rec, &mut out[..n]) };
            let mut dst = std::vec![sentinel; len];
            // SAFETY: as above, for writing.
            unsafe { V::store_records(dst.as_mut_ptr(), rec, &out[..n]) };
            for (c, v) in out[..n].iter().enumerate() {
                let mut lanes = [V::Scalar::ZERO; 32];
                v.store(&mut lanes);
                for (i, x) in lanes[..V::LANES].iter().enumerate() {
                    let want = src[i * rec + c].to_f64();
                    assert_eq!(
                        x.to_f64(),
                        want,
                        "load_records rec {rec} n {n} c {c} lane {i}"
                    );
                }
            }
            for (k, x) in dst.iter().enumerate() {
                let want = if k % rec < n { src[k] } else { sentinel };
                assert_eq!(
                    x.to_f64(),
                    want.to_f64(),
                    "store_records rec {rec} n {n} at {k}"
                );
            }
        }
    }
}

/// `dup_low_half` repeats lanes `0..LANES/2` in the high half, signed zeros and NaN kept.
fn dup_low<V: Lane>() {
    let mut src: [V::Scalar; 32] = core::array::from_fn(|i| V::Scalar::from_i32(i as i32 + 1));
    src[0] = -V::Scalar::ZERO;
    src[1] = V::Scalar::from_f64(f64::NAN);
    let mut got = [V::Scalar::from_i32(-7); 32];
    V::load(&src).dup_low_half().store(&mut got);
    let h = V::LANES / 2;
    for (i, x) in got[..V::LANES].iter().enumerate() {
        let want = if V::LANES == 1 { src[0] } else { src[i % h] };
        assert_eq!(x.to_f64().to_bits(), want.to_f64().to_bits(), "lane {i}");
    }
}

/// `transpose8` on an eight-lane type: lane `l` of result `i` is lane `i` of input `l`, with
/// signed zeros, infinities and NaN kept.
fn transpose<V: Lane>() {
    let mut src: [[V::Scalar; 32]; 8] = core::array::from_fn(|l| {
        core::array::from_fn(|i| V::Scalar::from_i32(8 * l as i32 + i as i32 + 1))
    });
    src[0][1] = -V::Scalar::ZERO;
    src[3][5] = V::Scalar::from_f64(f64::NAN);
    src[7][2] = V::Scalar::from_f64(f64::NEG_INFINITY);
    let t = V::transpose8(core::array::from_fn(|l| V::load(&src[l])));
    for (i, ti) in t.iter().enumerate() {
        let mut got = [V::Scalar::ZERO; 32];
        ti.store(&mut got);
        for (l, x) in got[..8].iter().enumerate() {
            assert_eq!(
                x.to_f64().to_bits(),
                src[l][i].to_f64().to_bits(),
                "lane {l} of {i}"
            );
        }
    }
}

/// Every test above on lane type `V`.
fn all<V: Lane>() {
    partial::<V>();
    records::<V>();
    dup_low::<V>();
    if V::LANES == 8 {
        transpose::<V>();
    }
}

use crate::scalar::Real;

/// `Lane::cbrt` has the bits of [`Real::cbrt`] (libm's `cbrtf`) on every lane: every `f32`
/// in [1, 8) (three binades, every residue of the exponent mod 3) and every positive
/// subnormal, every 7th of their negatives, zeros, infinities, NaN, and every 251st bit
/// pattern of the whole range.
fn cbrt_bits<V: Lane<Scalar = f32>>() {
    let check = |start: u32, end: u32, step: u32| {
        let mut i = start;
        while i < end {
            let xs: [f32; 32] = core::array::from_fn(|l| {
                f32::from_bits(i.saturating_add(step.saturating_mul(l as u32)).min(end - 1))
            });
            let mut got = [0.0f32; 32];
            V::load(&xs).cbrt().store(&mut got);
            for (x, g) in xs.iter().zip(&got).take(V::LANES) {
                let want = Real::cbrt(*x);
                assert_eq!(
                    g.to_bits(),
                    want.to_bits(),
                    "cbrt({x:e}) bits {:#x}",
                    x.to_bits()
                );
            }
            i = i.saturating_add(step.saturating_mul(V::LANES as u32));
            if i == u32::MAX {
                break;
            }
        }
    };
    let (one, eight) = (1.0f32.to_bits(), 8.0f32.to_bits());
    check(one, eight, 1);
    check(one | 1 << 31, eight | 1 << 31, 7);
    check(0, 0x0080_0000, 1);
    check(1 << 31, (1 << 31) | 0x0080_0000, 7);
    check(0, u32::MAX, 251);
    let special = [
        f32::INFINITY,
        f32::NEG_INFINITY,
        f32::NAN,
        -f32::NAN,
        0.0,
        -0.0,
    ];
    for x in special {
        check(x.to_bits(), x.to_bits() + 1, 1);
    }
}

#[test]
fn cbrt_has_the_scalar_bits() {
    #[cfg(target_arch = "x86_64")]
    {
        #[target_feature(enable = "avx2,fma")]
        unsafe fn avx2() {
            cbrt_bits::<super::F32x8>();
            cbrt_bits::<X2<super::F32x8>>();
        }
        if has_avx2() {
            // SAFETY: the CPU has AVX2 and FMA.
            unsafe { avx2() };
        }
    }
}

#[test]
fn partial_and_record_loads_and_stores() {
    all::<f32>();
    all::<X2<X2<X2<f32>>>>();
    all::<X2<X2<X2<f64>>>>();
    #[cfg(target_arch = "x86_64")]
    {
        #[target_feature(enable = "avx2,fma")]
        unsafe fn avx2() {
            all::<super::F32x8>();
            all::<super::F64x4>();
            all::<X2<super::F64x4>>();
            all::<X2<super::F32x8>>();
        }
        #[target_feature(enable = "avx512f,avx512vl,avx512dq,avx512bw,avx2,fma")]
        unsafe fn avx512() {
            all::<super::F32x16>();
            all::<super::F64x8>();
            all::<X2<super::F64x8>>();
        }
        if has_avx2() {
            // SAFETY: the CPU has AVX2 and FMA.
            unsafe { avx2() };
        }
        if has_avx512() {
            // SAFETY: the CPU has AVX-512 F/VL/DQ/BW, AVX2 and FMA.
            unsafe { avx512() };
        }
    }
}

/// `quad_sums` on one lane type: every output lane is `(x₀ + x₁) + (x₂ + x₃)` of its group
/// and vector, in that order (values where another order rounds differently), with signed
/// zeros and infinities kept.
fn quad_sum_bits<V: Lane>() {
    let mut seed = 0x9e37_79b9u32;
    let mut next = || {
        seed ^= seed << 13;
        seed ^= seed >> 17;
        seed ^= seed << 5;
        seed
    };
    // Magnitudes from 2⁻⁴⁰ to 2⁴⁰ and both signs, so that sums cancel and round (in f64 too:
    // 24 random mantissa bits over 80 binades).
    let mut cases: std::vec::Vec<[f64; 32]> = (0..2000)
        .map(|_| {
            core::array::from_fn(|_| {
                let r = next();
                let m = 1.0 + (r >> 9) as f64 / (1u32 << 23) as f64;
                let e = (next() % 81) as i32 - 40;
                let s = if r & 256 != 0 { -1.0 } else { 1.0 };
                s * m * 2f64.powi(e)
            })
        })
        .collect();
    // (1e8 + 1) + (−1e8 + 1) is 0 in f32; ((1e8 + 1) − 1e8) + 1 is 1 (1e17 likewise in f64).
    cases.push(core::array::from_fn(|l| [1e8, 1.0, -1e8, 1.0][l % 4]));
    cases.push(core::array::from_fn(|l| [1e17, 1.0, -1e17, 1.0][l % 4]));
    cases.push(core::array::from_fn(|l| [-0.0, -0.0, 0.0, -0.0][l % 4]));
    cases.push(core::array::from_fn(|l| {
        [f64::INFINITY, 1.0, 2.0, -0.0][l % 4]
    }));
    let c = V::Scalar::from_f64;
    for cs in cases.chunks(4).filter(|cs| cs.len() == 4) {
        let x: [[V::Scalar; 32]; 4] = core::array::from_fn(|i| cs[i].map(c));
        let v: [V; 4] = core::array::from_fn(|i| V::load(&x[i]));
        let mut got = [V::Scalar::ZERO; 32];
        V::quad_sums(v).store(&mut got);
        for h in 0..V::LANES / 4 {
            for (i, xi) in x.iter().enumerate() {
                let g = &xi[4 * h..];
                let want = (g[0] + g[1]) + (g[2] + g[3]);
                assert_eq!(
                    got[4 * h + i].to_f64().to_bits(),
                    want.to_f64().to_bits(),
                    "group {h} vector {i}"
                );
            }
        }
    }
}

#[test]
fn quad_sums_pair_lanes_in_order() {
    quad_sum_bits::<X2<X2<X2<f32>>>>();
    quad_sum_bits::<X2<X2<X2<f64>>>>();
    quad_sum_bits::<X2<X2<f64>>>();
    #[cfg(target_arch = "x86_64")]
    {
        #[target_feature(enable = "avx2,fma")]
        unsafe fn avx2() {
            quad_sum_bits::<super::F32x8>();
            quad_sum_bits::<X2<super::F32x8>>();
            quad_sum_bits::<super::F64x4>();
            quad_sum_bits::<X2<super::F64x4>>();
        }
        #[target_feature(enable = "avx512f,avx512vl,avx512dq,avx512bw,avx2,fma")]
        unsafe fn avx512() {
            quad_sum_bits::<super::F64x8>();
            quad_sum_bits::<super::F32x16>();
        }
        if has_avx2() {
            // SAFETY: the CPU has AVX2 and FMA.
            unsafe { avx2() };
        }
        if has_avx512() {
            // SAFETY: the CPU has AVX-512 F/VL/DQ/BW, AVX2 and FMA.
            unsafe { avx512() };
        }
    }
}

/// The CPU has AVX2 and FMA (the AVX2 lane types' features).
#[cfg(target_arch = "x86_64")]
fn has_avx2() -> bool {
    std::is_x86_feature_detected!("avx2") && std::is_x86_feature_detected!("fma")
}

/// The CPU has AVX-512 F/VL/DQ/BW, AVX2 and FMA (the AVX-512 lane types' features).
#[cfg(target_arch = "x86_64")]
fn has_avx512() -> bool {
    std::is_x86_feature_detected!("avx512f")
        && std::is_x86_feature_detected!("avx512vl")
        && std::is_x86_feature_detected!("avx512dq")
        && std::is_x86_feature_detected!("avx512bw")
        && has_avx2()
}
