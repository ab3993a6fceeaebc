//! x86-64 SIMD lanes: `f32×8` and `f64×4` (AVX2 + FMA), `f32×16` and `f64×8` (AVX-512F).
//!
//! Each method is `#[inline(always)]` around one or a few `core::arch` intrinsics. The types
//! are crate-private and are only ever created inside the `#[target_feature]` functions of
//! [`crate::kernel`], which are reached only with an [`crate::lane::Isa`] proving the CPU has
//! the instructions: that is the safety argument of every `unsafe` block here. Once inlined
//! into such a function, LLVM emits the vector instructions directly.
//!
//! Every operation is the IEEE-754 operation of the scalar instantiation (see the module
//! docs of [`crate::lane`]): `vfmadd` rounds once, `vsqrt`/`vdiv` are correctly rounded, `floor` is `vround`/`vrndscale` toward
//! −∞, [`Lane::exponent`] and [`Lane::pow2`] are exact.

#![allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]

use super::Lane;
use core::arch::x86_64::*;
use core::ops::{Add, AddAssign, BitAnd, BitOr, Div, Mul, MulAssign, Neg, Not, Sub, SubAssign};

/// Arithmetic operator impls for a vector newtype.
macro_rules! arith {
    ($v:ident, $add:ident, $sub:ident, $mul:ident, $div:ident, $xor:ident, $set1:ident, $z:literal) => {
        impl Add for $v {
            type Output = Self;
            #[inline(always)]
            fn add(self, o: Self) -> Self {
                // SAFETY: see the module docs (the type exists only on supporting CPUs).
                unsafe { $v($add(self.0, o.0)) }
            }
        }
        impl Sub for $v {
            type Output = Self;
            #[inline(always)]
            fn sub(self, o: Self) -> Self {
                // SAFETY: see the module docs.
                unsafe { $v($sub(self.0, o.0)) }
            }
        }
        impl Mul for $v {
            type Output = Self;
            #[inline(always)]
            fn mul(self, o: Self) -> Self {
                // SAFETY: see the module docs.
                unsafe { $v($mul(self.0, o.0)) }
            }
        }
        impl Div for $v {
            type Output = Self;
            #[inline(always)]
            fn div(self, o: Self) -> Self {
                // SAFETY: see the module docs.
                unsafe { $v($div(self.0, o.0)) }
            }
        }
        impl Neg for $v {
            type Output = Self;
            #[inline(always)]
            fn neg(self) -> Self {
                // SAFETY: see the module docs. Flips the sign bit only (as scalar `-x`).
                unsafe { $v($xor(self.0, $set1($z))) }
            }
        }
        impl AddAssign for $v {
            #[inline(always)]
            fn add_assign(&mut self, o: Self) {
                *self = *self + o;
            }
        }
        impl SubAssign for $v {
            #[inline(always)]
            fn sub_assign(&mut self, o: Self) {
                *self = *self - o;
            }
        }
        impl MulAssign for $v {
            #[inline(always)]
            fn mul_assign(&mut self, o: Self) {
                *self = *self * o;
            }
        }
        // SAFETY (Send/Sync): plain vector registers.
        unsafe impl Send for $v {}
        unsafe impl Sync for $v {}
    };
}

/// Mask newtype over a full-width vector (AVX2: all-ones or all-zeros lanes).
macro_rules! vmask {
    ($m:ident, $raw:ty, $and:ident, $or:ident, $xor:ident, $ones:expr) => {
        #[derive(Clone, Copy, Debug)]
        #[repr(transparent)]
        pub struct $m(pub(crate) $raw);
        impl BitAnd for $m {
            type Output = Self;
            #[inline(always)]
            fn bitand(self, o: Self) -> Self {
                // SAFETY: see the module docs.
                unsafe { $m($and(self.0, o.0)) }
            }
        }
        impl BitOr for $m {
            type Output = Self;
            #[inline(always)]
            fn bitor(self, o: Self) -> Self {
                // SAFETY: see the module docs.
                unsafe { $m($or(self.0, o.0)) }
            }
        }
        impl Not for $m {
            type Output = Self;
            #[inline(always)]
            fn not(self) -> Self {
                // SAFETY: see the module docs.
                unsafe { $m($xor(self.0, $ones)) }
            }
        }
    };
}

/// Mask newtype over an AVX-512 mask register value.
macro_rules! kmask {
    ($m:ident, $raw:ty) => {
        #[derive(Clone, Copy, Debug)]
        #[repr(transparent)]
        pub struct $m(pub(crate) $raw);
        impl BitAnd for $m {
            type Output = Self;
            #[inline(always)]
            fn bitand(self, o: Self) -> Self {
                $m(self.0 & o.0)
            }
        }
        impl BitOr for $m {
            type Output = Self;
            #[inline(always)]
            fn bitor(self, o: Self) -> Self {
                $m(self.0 | o.0)
            }
        }
        impl Not for $m {
            type Output = Self;
            #[inline(always)]
            fn not(self) -> Self {
                $m(!self.0)
            }
        }
    };
}

// ---------------------------------------------------------------------------------------
// AVX2 + FMA
// ---------------------------------------------------------------------------------------

/// Eight `f32` lanes (AVX2 + FMA).
#[derive(Clone, Copy, Debug)]
#[repr(transparent)]
pub struct F32x8(__m256);
arith!(
    F32x8,
    _mm256_add_ps,
    _mm256_sub_ps,
    _mm256_mul_ps,
    _mm256_div_ps,
    _mm256_xor_ps,
    _mm256_set1_ps,
    -0.0f32
);
vmask!(
    M32x8,
    __m256,
    _mm256_and_ps,
    _mm256_or_ps,
    _mm256_xor_ps,
    _mm256_castsi256_ps(_mm256_set1_epi32(-1))
);

/// The AVX2 mask of lanes `0..n` of eight 32-bit lanes (sign bits set).
#[inline(always)]
unsafe fn mask8(n: usize) -> __m256i {
    _mm256_cmpgt_epi32(
        _mm256_set1_epi32(n as i32),
        _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7),
    )
}

/// The AVX2 mask of lanes `0..n` of four 64-bit lanes (sign bits set).
#[inline(always)]
unsafe fn mask4(n: usize) -> __m256i {
    _mm256_cmpgt_epi64(_mm256_set1_epi64x(n as i64), _mm256_setr_epi64x(0, 1, 2, 3))
}

impl Lane for F32x8 {
    type Scalar = f32;
    type Mask = M32x8;
    const LANES: usize = 8;

    #[inline(always)]
    fn splat(x: f32) -> Self {
        // SAFETY: see the module docs.
        unsafe { F32x8(_mm256_set1_ps(x)) }
    }
    #[inline(always)]
    fn load(s: &[f32]) -> Self {
        let s = &s[..8];
        // SAFETY: `s` holds 8 scalars; unaligned load.
        unsafe { F32x8(_mm256_loadu_ps(s.as_ptr())) }
    }
    #[inline(always)]
    fn store(self, s: &mut [f32]) {
        let s = &mut s[..8];
        // SAFETY: `s` holds 8 scalars; unaligned store.
        unsafe { _mm256_storeu_ps(s.as_mut_ptr(), self.0) }
    }
    #[inline(always)]
    unsafe fn gather(base: *const f32, stride: usize) -> Self {
        let s = stride as i32;
        let idx = _mm256_mullo_epi32(
            _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7),
            _mm256_set1_epi32(s),
        );
        F32x8(_mm256_i32gather_ps::<4>(base, idx))
    }
    #[inline(always)]
    unsafe fn load_n(p: *const f32, n: usize) -> Self {
        F32x8(_mm256_maskload_ps(p, mask8(n)))
    }
    #[inline(always)]
    unsafe fn store_n(self, p: *mut f32, n: usize) {
        _mm256_maskstore_ps(p, mask8(n), self.0)
    }
    #[inline(always)]
    unsafe fn scatter(self, base: *mut f32, stride: usize, keep: u32) {
        let mut b = [0.0f32; 8];
        _mm256_storeu_ps(b.as_mut_ptr(), self.0);
        for (i, x) in b.iter().enumerate() {
            if keep >> i & 1 == 1 {
                base.add(i * stride).write_unaligned(*x);
            }
        }
    }
    #[inline(always)]
    fn mul_add(self, a: Self, b: Self) -> Self {
        // SAFETY: see the module docs (FMA is part of the AVX2 path).
        unsafe { F32x8(_mm256_fmadd_ps(self.0, a.0, b.0)) }
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        // SAFETY: see the module docs.
        unsafe { F32x8(_mm256_sqrt_ps(self.0)) }
    }
    #[inline(always)]
    fn abs(self) -> Self {
        // SAFETY: see the module docs.
        unsafe { F32x8(_mm256_andnot_ps(_mm256_set1_ps(-0.0), self.0)) }
    }
    #[inline(always)]
    fn copysign(self, sign: Self) -> Self {
        // SAFETY: see the module docs.
        unsafe {
            let m = _mm256_set1_ps(-0.0);
            F32x8(_mm256_or_ps(
                _mm256_andnot_ps(m, self.0),
                _mm256_and_ps(m, sign.0),
            ))
        }
    }
    #[inline(always)]
    fn floor(self) -> Self {
        // SAFETY: see the module docs.
        unsafe { F32x8(_mm256_floor_ps(self.0)) }
    }
    #[inline(always)]
    fn rsqrt_guess(self) -> Self {
        // SAFETY: see the module docs. As `Real::rsqrt_guess`: magic − (bits >> 1).
        unsafe {
            let i = _mm256_srli_epi32::<1>(_mm256_castps_si256(self.0));
            F32x8(_mm256_castsi256_ps(_mm256_sub_epi32(
                _mm256_set1_epi32(0x5f37_5a86),
                i,
            )))
        }
    }
    #[inline(always)]
    fn select(m: M32x8, a: Self, b: Self) -> Self {
        // SAFETY: see the module docs.
        unsafe { F32x8(_mm256_blendv_ps(b.0, a.0, m.0)) }
    }
    #[inline(always)]
    fn lt(self, o: Self) -> M32x8 {
        // SAFETY: see the module docs.
        unsafe { M32x8(_mm256_cmp_ps::<_CMP_LT_OQ>(self.0, o.0)) }
    }
    #[inline(always)]
    fn le(self, o: Self) -> M32x8 {
        // SAFETY: see the module docs.
        unsafe { M32x8(_mm256_cmp_ps::<_CMP_LE_OQ>(self.0, o.0)) }
    }
    #[inline(always)]
    fn eq(self, o: Self) -> M32x8 {
        // SAFETY: see the module docs.
        unsafe { M32x8(_mm256_cmp_ps::<_CMP_EQ_OQ>(self.0, o.0)) }
    }
    #[inline(always)]
    fn is_finite(self) -> M32x8 {
        self.abs().lt(Self::splat(f32::INFINITY))
    }
    #[inline(always)]
    fn mask_bits(m: M32x8) -> u32 {
        // SAFETY: see the module docs.
        unsafe { _mm256_movemask_ps(m.0) as u32 }
    }
    #[inline(always)]
    fn exponent(self) -> Self {
        // frexp exponent: biased field − 126; a subnormal is first scaled by 2²³ (exact).
        let a = self.abs();
        let sub = a.lt(Self::splat(f32::MIN_POSITIVE));
        let y = Self::select(sub, a * Self::splat(8_388_608.0), a);
        // SAFETY: see the module docs.
        let field = unsafe {
            F32x8(_mm256_cvtepi32_ps(_mm256_srli_epi32::<23>(
                _mm256_castps_si256(y.0),
            )))
        };
        let e = field - Self::splat(126.0) - Self::select(sub, Self::splat(23.0), Self::splat(0.0));
        let special = a.eq(Self::splat(0.0)) | !self.is_finite();
        Self::select(special, Self::splat(0.0), e)
    }
    #[inline(always)]
    fn pow2(e: Self) -> Self {
        // SAFETY: see the module docs. `e` is an integer in [−126, 127].
        unsafe {
            let i = _mm256_add_epi32(_mm256_cvtps_epi32(e.0), _mm256_set1_epi32(127));
            F32x8(_mm256_castsi256_ps(_mm256_slli_epi32::<23>(i)))
        }
    }
}

/// Four `f64` lanes (AVX2 + FMA).
#[derive(Clone, Copy, Debug)]
#[repr(transparent)]
pub struct F64x4(__m256d);
arith!(
    F64x4,
    _mm256_add_pd,
    _mm256_sub_pd,
    _mm256_mul_pd,
    _mm256_div_pd,
    _mm256_xor_pd,
    _mm256_set1_pd,
    -0.0f64
);
vmask!(
    M64x4,
    __m256d,
    _mm256_and_pd,
    _mm256_or_pd,
    _mm256_xor_pd,
    _mm256_castsi256_pd(_mm256_set1_epi32(-1))
);

/// `1.5·2⁵²`: adding it to an integer-valued `|e| < 2⁵¹` puts `e` in the low mantissa bits.
const MAGIC_F64: f64 = 6_755_399_441_055_744.0;
/// `2⁵²`, whose bits OR-ed with a small integer `m` give the double `2⁵² + m`.
const TWO52: f64 = 4_503_599_627_370_496.0;

impl Lane for F64x4 {
    type Scalar = f64;
    type Mask = M64x4;
    const LANES: usize = 4;

    #[inline(always)]
    fn splat(x: f64) -> Self {
        // SAFETY: see the module docs.
        unsafe { F64x4(_mm256_set1_pd(x)) }
    }
    #[inline(always)]
    fn load(s: &[f64]) -> Self {
        let s = &s[..4];
        // SAFETY: `s` holds 4 scalars; unaligned load.
        unsafe { F64x4(_mm256_loadu_pd(s.as_ptr())) }
    }
    #[inline(always)]
    fn store(self, s: &mut [f64]) {
        let s = &mut s[..4];
        // SAFETY: `s` holds 4 scalars; unaligned store.
        unsafe { _mm256_storeu_pd(s.as_mut_ptr(), self.0) }
    }
    #[inline(always)]
    unsafe fn gather(base: *const f64, stride: usize) -> Self {
        let s = stride as i32;
        let idx = _mm_mullo_epi32(_mm_setr_epi32(0, 1, 2, 3), _mm_set1_epi32(s));
        F64x4(_mm256_i32gather_pd::<8>(base, idx))
    }
    #[inline(always)]
    unsafe fn load_n(p: *const f64, n: usize) -> Self {
        F64x4(_mm256_maskload_pd(p, mask4(n)))
    }
    #[inline(always)]
    unsafe fn store_n(self, p: *mut f64, n: usize) {
        _mm256_maskstore_pd(p, mask4(n), self.0)
    }
    #[inline(always)]
    unsafe fn scatter(self, base: *mut f64, stride: usize, keep: u32) {
        let mut b = [0.0f64; 4];
        _mm256_storeu_pd(b.as_mut_ptr(), self.0);
        for (i, x) in b.iter().enumerate() {
            if keep >> i & 1 == 1 {
                base.add(i * stride).write_unaligned(*x);
            }
        }
    }
    #[inline(always)]
    fn mul_add(self, a: Self, b: Self) -> Self {
        // SAFETY: see the module docs (FMA is part of the AVX2 path).
        unsafe { F64x4(_mm256_fmadd_pd(self.0, a.0, b.0)) }
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        // SAFETY: see the module docs.
        unsafe { F64x4(_mm256_sqrt_pd(self.0)) }
    }
    #[inline(always)]
    fn abs(self) -> Self {
        // SAFETY: see the module docs.
        unsafe { F64x4(_mm256_andnot_pd(_mm256_set1_pd(-0.0), self.0)) }
    }
    #[inline(always)]
    fn copysign(self, sign: Self) -> Self {
        // SAFETY: see the module docs.
        unsafe {
            let m = _mm256_set1_pd(-0.0);
            F64x4(_mm256_or_pd(
                _mm256_andnot_pd(m, self.0),
                _mm256_and_pd(m, sign.0),
            ))
        }
    }
    #[inline(always)]
    fn floor(self) -> Self {
        // SAFETY: see the module docs.
        unsafe { F64x4(_mm256_floor_pd(self.0)) }
    }
    #[inline(always)]
    fn rsqrt_guess(self) -> Self {
        // SAFETY: see the module docs. As `Real::rsqrt_guess`: magic − (bits >> 1).
        unsafe {
            let i = _mm256_srli_epi64::<1>(_mm256_castpd_si256(self.0));
            let m = _mm256_set1_epi64x(0x5fe6_eb50_c7b5_37a9_u64 as i64);
            F64x4(_mm256_castsi256_pd(_mm256_sub_epi64(m, i)))
        }
    }
    #[inline(always)]
    fn select(m: M64x4, a: Self, b: Self) -> Self {
        // SAFETY: see the module docs.
        unsafe { F64x4(_mm256_blendv_pd(b.0, a.0, m.0)) }
    }
    #[inline(always)]
    fn lt(self, o: Self) -> M64x4 {
        // SAFETY: see the module docs.
        unsafe { M64x4(_mm256_cmp_pd::<_CMP_LT_OQ>(self.0, o.0)) }
    }
    #[inline(always)]
    fn le(self, o: Self) -> M64x4 {
        // SAFETY: see the module docs.
        unsafe { M64x4(_mm256_cmp_pd::<_CMP_LE_OQ>(self.0, o.0)) }
    }
    #[inline(always)]
    fn eq(self, o: Self) -> M64x4 {
        // SAFETY: see the module docs.
        unsafe { M64x4(_mm256_cmp_pd::<_CMP_EQ_OQ>(self.0, o.0)) }
    }
    #[inline(always)]
    fn is_finite(self) -> M64x4 {
        self.abs().lt(Self::splat(f64::INFINITY))
    }
    #[inline(always)]
    fn mask_bits(m: M64x4) -> u32 {
        // SAFETY: see the module docs.
        unsafe { _mm256_movemask_pd(m.0) as u32 }
    }
    #[inline(always)]
    fn exponent(self) -> Self {
        // frexp exponent: biased field − 1022; a subnormal is first scaled by 2⁵² (exact). The
        // 11-bit field becomes a double by OR-ing it into the mantissa of 2⁵².
        let a = self.abs();
        let sub = a.lt(Self::splat(f64::MIN_POSITIVE));
        let y = Self::select(sub, a * Self::splat(TWO52), a);
        // SAFETY: see the module docs.
        let field = unsafe {
            let f = _mm256_srli_epi64::<52>(_mm256_castpd_si256(y.0));
            let t = _mm256_or_si256(f, _mm256_castpd_si256(_mm256_set1_pd(TWO52)));
            F64x4(_mm256_castsi256_pd(t)) - Self::splat(TWO52)
        };
        let e =
            field - Self::splat(1022.0) - Self::select(sub, Self::splat(52.0), Self::splat(0.0));
        let special = a.eq(Self::splat(0.0)) | !self.is_finite();
        Self::select(special, Self::splat(0.0), e)
    }
    #[inline(always)]
    fn pow2(e: Self) -> Self {
        // SAFETY: see the module docs. `e` is an integer in [−1022, 1023]: the bits of
        // `e + 1.5·2⁵²` are those of 1.5·2⁵² plus `e`.
        unsafe {
            let t = _mm256_castpd_si256(_mm256_add_pd(e.0, _mm256_set1_pd(MAGIC_F64)));
            let bias = _mm256_sub_epi64(
                _mm256_set1_epi64x(1023),
                _mm256_castpd_si256(_mm256_set1_pd(MAGIC_F64)),
            );
            F64x4(_mm256_castsi256_pd(_mm256_slli_epi64::<52>(
                _mm256_add_epi64(t, bias),
            )))
        }
    }
}

// ---------------------------------------------------------------------------------------
// AVX-512F
// ---------------------------------------------------------------------------------------

/// `vrndscale` immediate: round toward −∞ (1), suppress exceptions (8).
const FLOOR_IMM: i32 = 0x09;

/// Sixteen `f32` lanes (AVX-512F).
#[derive(Clone, Copy, Debug)]
#[repr(transparent)]
pub struct F32x16(__m512);
arith!(
    F32x16,
    _mm512_add_ps,
    _mm512_sub_ps,
    _mm512_mul_ps,
    _mm512_div_ps,
    xor_ps512,
    _mm512_set1_ps,
    -0.0f32
);
kmask!(K16, __mmask16);

/// `a ^ b` bitwise on `f32×16` (AVX-512F has it on integers only).
#[inline(always)]
unsafe fn xor_ps512(a: __m512, b: __m512) -> __m512 {
    _mm512_castsi512_ps(_mm512_xor_si512(
        _mm512_castps_si512(a),
        _mm512_castps_si512(b),
    ))
}

/// `a ^ b` bitwise on `f64×8`.
#[inline(always)]
unsafe fn xor_pd512(a: __m512d, b: __m512d) -> __m512d {
    _mm512_castsi512_pd(_mm512_xor_si512(
        _mm512_castpd_si512(a),
        _mm512_castpd_si512(b),
    ))
}

/// `[0, s, 2s, …, 15s]` as 32-bit indices.
#[inline(always)]
unsafe fn idx16(s: i32) -> __m512i {
    _mm512_mullo_epi32(
        _mm512_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15),
        _mm512_set1_epi32(s),
    )
}

/// `[0, s, …, 7s]` as 32-bit indices.
#[inline(always)]
unsafe fn idx8(s: i32) -> __m256i {
    _mm256_mullo_epi32(
        _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7),
        _mm256_set1_epi32(s),
    )
}

/// Sixteen-lane and eight-lane AVX-512 impls share everything but names and constants.
macro_rules! avx512_lane {
    ($v:ident, $t:ty, $k:ident, $kraw:ty, $gather:ident, $scatter:ident, $idx:ident, $n:literal, $set1:ident, $loadu:ident, $storeu:ident,
     $maskz_loadu:ident, $mask_storeu:ident,
     $fmadd:ident, $sqrt:ident, $abs:ident, $cast_i:ident, $cast_f:ident, $and_i:ident,
     $or_i:ident, $andnot_i:ident, $set1_i:ident, $sign:expr, $srli:ident, $sub_i:ident,
     $magic:expr, $rnd:ident, $blend:ident,
     $cmp:ident, $getexp:ident, $scalef:ident) => {
        impl Lane for $v {
            type Scalar = $t;
            type Mask = $k;
            const LANES: usize = $n;

            #[inline(always)]
            fn splat(x: $t) -> Self {
                // SAFETY: see the module docs.
                unsafe { $v($set1(x)) }
            }
            #[inline(always)]
            fn load(s: &[$t]) -> Self {
                let s = &s[..$n];
                // SAFETY: `s` holds LANES scalars; unaligned load.
                unsafe { $v($loadu(s.as_ptr().cast())) }
            }
            #[inline(always)]
            fn store(self, s: &mut [$t]) {
                let s = &mut s[..$n];
                // SAFETY: `s` holds LANES scalars; unaligned store.
                unsafe { $storeu(s.as_mut_ptr().cast(), self.0) }
            }
            #[inline(always)]
            unsafe fn gather(base: *const $t, stride: usize) -> Self {
                $v($gather::<{ core::mem::size_of::<$t>() as i32 }>(
                    $idx(stride as i32),
                    base.cast(),
                ))
            }
            #[inline(always)]
            unsafe fn load_n(p: *const $t, n: usize) -> Self {
                $v($maskz_loadu(((1u32 << n) - 1) as $kraw, p.cast()))
            }
            #[inline(always)]
            unsafe fn store_n(self, p: *mut $t, n: usize) {
                $mask_storeu(p.cast(), ((1u32 << n) - 1) as $kraw, self.0)
            }
            #[inline(always)]
            unsafe fn scatter(self, base: *mut $t, stride: usize, keep: u32) {
                $scatter::<{ core::mem::size_of::<$t>() as i32 }>(
                    base.cast(),
                    keep as $kraw,
                    $idx(stride as i32),
                    self.0,
                );
            }
            #[inline(always)]
            fn mul_add(self, a: Self, b: Self) -> Self {
                // SAFETY: see the module docs.
                unsafe { $v($fmadd(self.0, a.0, b.0)) }
            }
            #[inline(always)]
            fn sqrt(self) -> Self {
                // SAFETY: see the module docs.
                unsafe { $v($sqrt(self.0)) }
            }
            #[inline(always)]
            fn abs(self) -> Self {
                // SAFETY: see the module docs.
                unsafe { $v($abs(self.0)) }
            }
            #[inline(always)]
            fn copysign(self, sign: Self) -> Self {
                // SAFETY: see the module docs.
                unsafe {
                    let m = $set1_i($sign);
                    $v($cast_f($or_i(
                        $andnot_i(m, $cast_i(self.0)),
                        $and_i(m, $cast_i(sign.0)),
                    )))
                }
            }
            #[inline(always)]
            fn floor(self) -> Self {
                // SAFETY: see the module docs.
                unsafe { $v($rnd::<FLOOR_IMM>(self.0)) }
            }
            #[inline(always)]
            fn rsqrt_guess(self) -> Self {
                // SAFETY: see the module docs. As `Real::rsqrt_guess`: magic − (bits >> 1).
                unsafe {
                    $v($cast_f($sub_i(
                        $set1_i($magic),
                        $srli::<1>($cast_i(self.0)),
                    )))
                }
            }
            #[inline(always)]
            fn select(m: $k, a: Self, b: Self) -> Self {
                // SAFETY: see the module docs. `blend(k, b, a)` takes `a` where `k` is set.
                unsafe { $v($blend(m.0, b.0, a.0)) }
            }
            #[inline(always)]
            fn lt(self, o: Self) -> $k {
                // SAFETY: see the module docs.
                unsafe { $k($cmp::<_CMP_LT_OQ>(self.0, o.0)) }
            }
            #[inline(always)]
            fn le(self, o: Self) -> $k {
                // SAFETY: see the module docs.
                unsafe { $k($cmp::<_CMP_LE_OQ>(self.0, o.0)) }
            }
            #[inline(always)]
            fn eq(self, o: Self) -> $k {
                // SAFETY: see the module docs.
                unsafe { $k($cmp::<_CMP_EQ_OQ>(self.0, o.0)) }
            }
            #[inline(always)]
            fn is_finite(self) -> $k {
                self.abs().lt(Self::splat(<$t>::INFINITY))
            }
            #[inline(always)]
            fn mask_bits(m: $k) -> u32 {
                u32::from(m.0)
            }
            #[inline(always)]
            fn exponent(self) -> Self {
                // `vgetexp` gives ⌊log₂|x|⌋ exactly, subnormals included; frexp's is one more.
                // SAFETY: see the module docs.
                let g = unsafe { $v($getexp(self.0)) };
                let special = self.abs().eq(Self::splat(0.0)) | !self.is_finite();
                Self::select(special, Self::splat(0.0), g + Self::splat(1.0))
            }
            #[inline(always)]
            fn pow2(e: Self) -> Self {
                // `vscalef(1, e)` = 2^⌊e⌋, exact for an integer in the normal range.
                // SAFETY: see the module docs.
                unsafe { $v($scalef($set1(1.0), e.0)) }
            }
        }
    };
}

avx512_lane!(
    F32x16,
    f32,
    K16,
    u16,
    _mm512_i32gather_ps,
    _mm512_mask_i32scatter_ps,
    idx16,
    16,
    _mm512_set1_ps,
    _mm512_loadu_ps,
    _mm512_storeu_ps,
    _mm512_maskz_loadu_ps,
    _mm512_mask_storeu_ps,
    _mm512_fmadd_ps,
    _mm512_sqrt_ps,
    _mm512_abs_ps,
    _mm512_castps_si512,
    _mm512_castsi512_ps,
    _mm512_and_si512,
    _mm512_or_si512,
    _mm512_andnot_si512,
    _mm512_set1_epi32,
    i32::MIN,
    _mm512_srli_epi32,
    _mm512_sub_epi32,
    0x5f37_5a86,
    _mm512_roundscale_ps,
    _mm512_mask_blend_ps,
    _mm512_cmp_ps_mask,
    _mm512_getexp_ps,
    _mm512_scalef_ps
);

/// Eight `f64` lanes (AVX-512F).
#[derive(Clone, Copy, Debug)]
#[repr(transparent)]
pub struct F64x8(__m512d);
arith!(
    F64x8,
    _mm512_add_pd,
    _mm512_sub_pd,
    _mm512_mul_pd,
    _mm512_div_pd,
    xor_pd512,
    _mm512_set1_pd,
    -0.0f64
);
kmask!(K8, __mmask8);

avx512_lane!(
    F64x8,
    f64,
    K8,
    u8,
    _mm512_i32gather_pd,
    _mm512_mask_i32scatter_pd,
    idx8,
    8,
    _mm512_set1_pd,
    _mm512_loadu_pd,
    _mm512_storeu_pd,
    _mm512_maskz_loadu_pd,
    _mm512_mask_storeu_pd,
    _mm512_fmadd_pd,
    _mm512_sqrt_pd,
    _mm512_abs_pd,
    _mm512_castpd_si512,
    _mm512_castsi512_pd,
    _mm512_and_si512,
    _mm512_or_si512,
    _mm512_andnot_si512,
    _mm512_set1_epi64,
    i64::MIN,
    _mm512_srli_epi64,
    _mm512_sub_epi64,
    0x5fe6_eb50_c7b5_37a9_u64 as i64,
    _mm512_roundscale_pd,
    _mm512_mask_blend_pd,
    _mm512_cmp_pd_mask,
    _mm512_getexp_pd,
    _mm512_scalef_pd
);
