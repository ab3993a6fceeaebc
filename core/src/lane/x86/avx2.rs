//! AVX2 + FMA lanes: `f32×8`, `f64×4` (see the parent module for the safety argument).

#![allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]

use super::super::{load_rows_scalar, Lane};
use super::records::{load_records8, store_records8, transpose8};
use core::arch::x86_64::*;
use core::ops::{Add, AddAssign, BitAnd, BitOr, Div, Mul, MulAssign, Neg, Not, Sub, SubAssign};

/// Eight `f32` lanes (AVX2 + FMA).
#[derive(Clone, Copy, Debug)]
#[repr(transparent)]
pub struct F32x8(pub(super) __m256);
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
pub(super) unsafe fn mask8(n: usize) -> __m256i {
    _mm256_cmpgt_epi32(
        _mm256_set1_epi32(n as i32),
        _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7),
    )
}

/// The AVX2 mask of the lanes `i` of eight 32-bit lanes with bit `i` of `bits` set.
#[inline(always)]
unsafe fn mask8_bits(bits: u32) -> __m256i {
    let b = _mm256_setr_epi32(1, 2, 4, 8, 16, 32, 64, 128);
    _mm256_cmpeq_epi32(_mm256_and_si256(_mm256_set1_epi32(bits as i32), b), b)
}

/// The AVX2 mask of the lanes `i` of four 64-bit lanes with bit `i` of `bits` set.
#[inline(always)]
unsafe fn mask4_bits(bits: u32) -> __m256i {
    let b = _mm256_setr_epi64x(1, 2, 4, 8);
    _mm256_cmpeq_epi64(_mm256_and_si256(_mm256_set1_epi64x(bits as i64), b), b)
}

/// The AVX2 mask of lanes `0..n` of four 64-bit lanes (sign bits set).
#[inline(always)]
unsafe fn mask4(n: usize) -> __m256i {
    _mm256_cmpgt_epi64(_mm256_set1_epi64x(n as i64), _mm256_setr_epi64x(0, 1, 2, 3))
}

impl Lane for F32x8 {
    type Scalar = f32;
    type Mask = M32x8;
    type Wide = crate::lane::X2<Self>;
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
    unsafe fn load_records(base: *const f32, rec: usize, out: &mut [Self]) {
        // `F32x8` is `repr(transparent)` around `__m256`.
        let o = core::slice::from_raw_parts_mut(out.as_mut_ptr().cast::<__m256>(), out.len());
        load_records8(base, rec, o);
    }
    #[inline(always)]
    unsafe fn store_records(base: *mut f32, rec: usize, vals: &[Self]) {
        store_records8(
            base,
            rec,
            core::slice::from_raw_parts(vals.as_ptr().cast(), vals.len()),
        );
    }
    #[inline(always)]
    fn to_i32s(self, out: &mut [i32]) {
        let out = &mut out[..8];
        // SAFETY: `out` holds 8 `i32`; unaligned store.
        unsafe { _mm256_storeu_si256(out.as_mut_ptr().cast(), _mm256_cvttps_epi32(self.0)) }
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
    unsafe fn load_rows<const K: usize>(base: *const f32, idx: &[isize], s0: isize) -> [Self; 4] {
        debug_assert!(K <= 4 && idx.len() == 8);
        if s0 != 1 {
            return load_rows_scalar::<Self, K>(base, idx, s0);
        }
        // Row `i` in lanes 0..4 of a 128-bit load (lanes `K..4` masked off: not read), rows `i`
        // and `i + 4` in the two halves of one vector, then a 4 × 4 transpose within each half:
        // `out[o]` holds node `o` of rows 0..4 in lanes 0..4 and of rows 4..8 in lanes 4..8.
        // (No closures: a closure would not inherit the caller's target features.)
        let on = [0, 1, 2, 3].map(|o| if o < K { -1 } else { 0 });
        let m = _mm_setr_epi32(on[0], on[1], on[2], on[3]);
        let mut a = [_mm256_setzero_ps(); 4];
        for (i, ai) in a.iter_mut().enumerate() {
            let lo = _mm256_castps128_ps256(_mm_maskload_ps(base.offset(idx[i]), m));
            *ai = _mm256_insertf128_ps::<1>(lo, _mm_maskload_ps(base.offset(idx[i + 4]), m));
        }
        let [a0, a1, a2, a3] = a;
        let t0 = _mm256_unpacklo_ps(a0, a1);
        let t1 = _mm256_unpackhi_ps(a0, a1);
        let t2 = _mm256_unpacklo_ps(a2, a3);
        let t3 = _mm256_unpackhi_ps(a2, a3);
        [
            F32x8(_mm256_shuffle_ps::<0x44>(t0, t2)),
            F32x8(_mm256_shuffle_ps::<0xEE>(t0, t2)),
            F32x8(_mm256_shuffle_ps::<0x44>(t1, t3)),
            F32x8(_mm256_shuffle_ps::<0xEE>(t1, t3)),
        ]
    }
    #[inline(always)]
    unsafe fn load_mask(p: *const f32, bits: u32) -> Self {
        F32x8(_mm256_maskload_ps(p, mask8_bits(bits)))
    }
    #[inline(always)]
    unsafe fn store_mask(self, p: *mut f32, bits: u32) {
        _mm256_maskstore_ps(p, mask8_bits(bits), self.0)
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
    fn mask_bits(m: M32x8) -> u64 {
        // SAFETY: see the module docs.
        u64::from(unsafe { _mm256_movemask_ps(m.0) } as u32)
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
    #[inline(always)]
    fn cbrt(self) -> Self {
        // SAFETY: see the module docs.
        unsafe { F32x8(cbrt8(self.0)) }
    }
    const QUAD_SUMS_IN_REGISTERS: bool = true;
    const TRANSPOSE8_IN_REGISTERS: bool = true;
    #[inline(always)]
    fn transpose8(v: [Self; 8]) -> [Self; 8] {
        let r = [
            v[0].0, v[1].0, v[2].0, v[3].0, v[4].0, v[5].0, v[6].0, v[7].0,
        ];
        // SAFETY: see the module docs.
        let t = unsafe { transpose8(r) };
        [
            F32x8(t[0]),
            F32x8(t[1]),
            F32x8(t[2]),
            F32x8(t[3]),
            F32x8(t[4]),
            F32x8(t[5]),
            F32x8(t[6]),
            F32x8(t[7]),
        ]
    }
    #[inline(always)]
    fn dup_low_half(self) -> Self {
        // SAFETY: see the module docs. Selector 0 for both halves: the low 128 bits.
        unsafe { F32x8(_mm256_permute2f128_ps::<0x00>(self.0, self.0)) }
    }
    #[inline(always)]
    fn quad_sums(v: [Self; 4]) -> Self {
        // `vhaddps` adds adjacent lane pairs within each 128-bit half: the first level gives
        // `(x₀ + x₁, x₂ + x₃)` of `v[0]`, `v[1]` (then `v[2]`, `v[3]`) per half, the second
        // adds those pairs, leaving `v[i]`'s group `h` in lane `4h + i`.
        // SAFETY: see the module docs.
        unsafe {
            let p = _mm256_hadd_ps(v[0].0, v[1].0);
            let q = _mm256_hadd_ps(v[2].0, v[3].0);
            F32x8(_mm256_hadd_ps(p, q))
        }
    }
}

/// libm's `cbrtf` (FreeBSD `s_cbrtf.c`) on eight lanes, the same operations in the same
/// order: the first guess `t₀` from the bits (`|x|`'s bits / 3 + B1, or for a subnormal those
/// of `x·2²⁴` / 3 + B2, with `x`'s sign), then two Newton steps
/// `t ← t (x + x + t³) / (x + t³ + t³)` in `f64` from `x` itself, rounded to `f32` (to
/// nearest, as `as f32`); `±0` and non-finite `x` as `cbrtf` (`x`, `x + x`). The integer
/// quotient `bits / 3` is formed by a multiply-high ([`third8`]).
///
/// # Safety
/// AVX2 available.
#[inline(always)]
unsafe fn cbrt8(x: __m256) -> __m256 {
    const B1: i32 = 709_958_130;
    const B2: i32 = 642_849_266;
    let bits = _mm256_castps_si256(x);
    let sign = _mm256_and_si256(bits, _mm256_set1_epi32(i32::MIN));
    let hx = _mm256_and_si256(bits, _mm256_set1_epi32(i32::MAX));
    let sub = _mm256_cmpgt_epi32(_mm256_set1_epi32(0x0080_0000), hx);
    let scaled = _mm256_castps_si256(_mm256_mul_ps(x, _mm256_set1_ps(16_777_216.0)));
    let hs = _mm256_and_si256(scaled, _mm256_set1_epi32(i32::MAX));
    let h = _mm256_blendv_epi8(hx, hs, sub);
    let b = _mm256_blendv_epi8(_mm256_set1_epi32(B1), _mm256_set1_epi32(B2), sub);
    let quot = third8(h);
    let t0 = _mm256_castsi256_ps(_mm256_or_si256(sign, _mm256_add_epi32(quot, b)));
    // Helper functions, not closures: a closure is not compiled with the caller's target
    // features.
    let lo = newton4(_mm256_castps256_ps128(t0), _mm256_castps256_ps128(x));
    let hi = newton4(
        _mm256_extractf128_ps::<1>(t0),
        _mm256_extractf128_ps::<1>(x),
    );
    let y = _mm256_set_m128(hi, lo);
    // hx ≥ 0x7f800000 (NaN, ±∞): x + x; hx = 0 (±0): x.
    let special = _mm256_cmpgt_epi32(hx, _mm256_set1_epi32(0x7f7f_ffff));
    let zero = _mm256_cmpeq_epi32(hx, _mm256_setzero_si256());
    let y = _mm256_blendv_ps(y, _mm256_add_ps(x, x), _mm256_castsi256_ps(special));
    _mm256_blendv_ps(y, x, _mm256_castsi256_ps(zero))
}

/// `⌊v / 3⌋` of eight 32-bit integers `v < 2³¹`, as `(v · 0xAAAAAAAB) >> 33` in 64 bits
/// (division by an invariant integer, Granlund and Montgomery 1994): `3 · 0xAAAAAAAB =
/// 2³³ + 1`, so the product over `2³³` is `v/3 + v/(3 · 2³³)`, whose excess is below 1/3 and
/// cannot carry `v/3` (fraction at most 2/3) past the next integer. The even lanes from one
/// `32 × 32 → 64`-bit product, the odd lanes from another, instead of an `f64` division.
///
/// # Safety
/// AVX2 available.
#[inline(always)]
unsafe fn third8(v: __m256i) -> __m256i {
    let m = _mm256_set1_epi64x(0xAAAA_AAAB);
    let even = _mm256_srli_epi64::<33>(_mm256_mul_epu32(v, m));
    // The odd lanes' quotients, shifted to the high halves: (p >> 33) << 32 = (p >> 1) with
    // its low 32 bits dropped by the blend.
    let odd = _mm256_srli_epi64::<1>(_mm256_mul_epu32(_mm256_srli_epi64::<32>(v), m));
    _mm256_blend_epi32::<0b1010_1010>(even, odd)
}

/// The two Newton steps of [`cbrt8`] on four lanes: guess `t`, argument `x`.
///
/// # Safety
/// AVX2 available.
#[inline(always)]
unsafe fn newton4(t: __m128, x: __m128) -> __m128 {
    let xd = _mm256_cvtps_pd(x);
    let mut t = _mm256_cvtps_pd(t);
    for _ in 0..2 {
        // r = t·t·t; t = t·(x + x + r) / (x + r + r), left to right as in C.
        let r = _mm256_mul_pd(_mm256_mul_pd(t, t), t);
        let num = _mm256_add_pd(_mm256_add_pd(xd, xd), r);
        let den = _mm256_add_pd(_mm256_add_pd(xd, r), r);
        t = _mm256_div_pd(_mm256_mul_pd(t, num), den);
    }
    _mm256_cvtpd_ps(t)
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
    type Wide = crate::lane::X2<Self>;
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
    unsafe fn load_mask(p: *const f64, bits: u32) -> Self {
        F64x4(_mm256_maskload_pd(p, mask4_bits(bits)))
    }
    #[inline(always)]
    unsafe fn store_mask(self, p: *mut f64, bits: u32) {
        _mm256_maskstore_pd(p, mask4_bits(bits), self.0)
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
    fn mask_bits(m: M64x4) -> u64 {
        // SAFETY: see the module docs.
        u64::from(unsafe { _mm256_movemask_pd(m.0) } as u32)
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
