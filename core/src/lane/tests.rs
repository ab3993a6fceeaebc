//! Tests of the lane types: partial and masked loads and stores on every lane type the CPU has.

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

use crate::scalar::Real;

#[test]
fn partial_loads_and_stores() {
    partial::<f32>();
    partial::<X2<X2<X2<f64>>>>();
    #[cfg(target_arch = "x86_64")]
    {
        #[target_feature(enable = "avx2,fma")]
        unsafe fn avx2() {
            partial::<super::F32x8>();
            partial::<super::F64x4>();
            partial::<X2<super::F32x8>>();
        }
        #[target_feature(enable = "avx512f,avx512vl,avx512dq,avx512bw,avx2,fma")]
        unsafe fn avx512() {
            partial::<super::F32x16>();
            partial::<super::F64x8>();
            partial::<X2<super::F64x8>>();
        }
        if std::is_x86_feature_detected!("avx2") && std::is_x86_feature_detected!("fma") {
            // SAFETY: the CPU has AVX2 and FMA.
            unsafe { avx2() };
        }
        if std::is_x86_feature_detected!("avx512f")
            && std::is_x86_feature_detected!("avx512vl")
            && std::is_x86_feature_detected!("avx512dq")
            && std::is_x86_feature_detected!("avx512bw")
            && std::is_x86_feature_detected!("avx2")
            && std::is_x86_feature_detected!("fma")
        {
            // SAFETY: the CPU has AVX-512 F/VL/DQ/BW, AVX2 and FMA.
            unsafe { avx512() };
        }
    }
}
