//! AVX-512F lanes: `f32×16`, `f64×8` (see the parent module for the safety argument).

#![allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]

use super::super::Lane;
use super::records::{load_records8, store_records8};
use core::arch::x86_64::*;
use core::ops::{Add, AddAssign, BitAnd, BitOr, Div, Mul, MulAssign, Neg, Not, Sub, SubAssign};

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

/// Two `f32×8` rows in one register: half 0 in lanes 0–7, half 1 in lanes 8–15.
impl crate::lane::Pair<super::F32x8> for F32x16 {
    const JOINED: bool = true;
    #[inline(always)]
    fn join(lo: super::F32x8, hi: super::F32x8) -> Self {
        // SAFETY: AVX-512F (this type's instruction set).
        unsafe {
            let lo = _mm512_castpd256_pd512(_mm256_castps_pd(lo.0));
            let pd = _mm512_insertf64x4::<1>(lo, _mm256_castps_pd(hi.0));
            F32x16(_mm512_castpd_ps(pd))
        }
    }
}

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
     $cmp:ident, $getexp:ident, $scalef:ident, { $($extra:tt)* }) => {
        impl Lane for $v {
            type Scalar = $t;
            type Mask = $k;
            type Wide = crate::lane::X2<Self>;
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
            unsafe fn load_mask(p: *const $t, bits: u32) -> Self {
                $v($maskz_loadu(bits as $kraw, p.cast()))
            }
            #[inline(always)]
            unsafe fn store_mask(self, p: *mut $t, bits: u32) {
                $mask_storeu(p.cast(), bits as $kraw, self.0)
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
            fn mask_bits(m: $k) -> u64 {
                u64::from(m.0)
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
            $($extra)*
        }
    };
}

/// The low and high eight lanes of `v` (AVX-512F instructions only).
#[inline(always)]
unsafe fn halves(v: __m512) -> [__m256; 2] {
    [
        _mm512_castps512_ps256(v),
        _mm256_castpd_ps(_mm512_extractf64x4_pd::<1>(_mm512_castps_pd(v))),
    ]
}

/// `[lo, hi]` as sixteen lanes.
#[inline(always)]
unsafe fn join(lo: __m256, hi: __m256) -> __m512 {
    _mm512_castpd_ps(_mm512_insertf64x4::<1>(
        _mm512_castpd256_pd512(_mm256_castps_pd(lo)),
        _mm256_castps_pd(hi),
    ))
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
    _mm512_scalef_ps,
    {
        // Records in two halves of eight lanes, each transposed as on AVX2.
        #[inline(always)]
        unsafe fn load_records(base: *const f32, rec: usize, out: &mut [Self]) {
            let n = out.len();
            let mut lo = [_mm256_setzero_ps(); 32];
            let mut hi = [_mm256_setzero_ps(); 32];
            load_records8(base, rec, &mut lo[..n]);
            load_records8(base.add(8 * rec), rec, &mut hi[..n]);
            for (o, (l, h)) in out.iter_mut().zip(lo.iter().zip(&hi)) {
                *o = F32x16(join(*l, *h));
            }
        }
        #[inline(always)]
        unsafe fn store_records(base: *mut f32, rec: usize, vals: &[Self]) {
            let n = vals.len();
            let mut lo = [_mm256_setzero_ps(); 32];
            let mut hi = [_mm256_setzero_ps(); 32];
            for (v, (l, h)) in vals.iter().zip(lo.iter_mut().zip(hi.iter_mut())) {
                [*l, *h] = halves(v.0);
            }
            store_records8(base, rec, &lo[..n]);
            store_records8(base.add(8 * rec), rec, &hi[..n]);
        }
        #[inline(always)]
        fn to_i32s(self, out: &mut [i32]) {
            let out = &mut out[..16];
            // SAFETY: `out` holds 16 `i32`; unaligned store.
            unsafe { _mm512_storeu_si512(out.as_mut_ptr().cast(), _mm512_cvttps_epi32(self.0)) }
        }
    }
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
    _mm512_scalef_pd,
    {}
);
