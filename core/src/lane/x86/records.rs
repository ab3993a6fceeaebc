//! Record loads and stores of eight `f32` lanes (AVX2): the in-register transposes behind
//! [`Lane::load_records`] and [`Lane::store_records`] of the eight-lane `f32` type, used by
//! the AVX-512 sixteen-lane type on each half too.

#![allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]

use super::super::Lane;
use super::avx2::{mask8, F32x8};
use core::arch::x86_64::*;

/// The transpose of the 8 × 8 matrix whose rows are `r` (the usual unpack, shuffle,
/// 128-bit permute sequence: 24 shuffles).
#[inline(always)]
pub(super) unsafe fn transpose8(r: [__m256; 8]) -> [__m256; 8] {
    let t0 = _mm256_unpacklo_ps(r[0], r[1]);
    let t1 = _mm256_unpackhi_ps(r[0], r[1]);
    let t2 = _mm256_unpacklo_ps(r[2], r[3]);
    let t3 = _mm256_unpackhi_ps(r[2], r[3]);
    let t4 = _mm256_unpacklo_ps(r[4], r[5]);
    let t5 = _mm256_unpackhi_ps(r[4], r[5]);
    let t6 = _mm256_unpacklo_ps(r[6], r[7]);
    let t7 = _mm256_unpackhi_ps(r[6], r[7]);
    let s0 = _mm256_shuffle_ps::<0x44>(t0, t2);
    let s1 = _mm256_shuffle_ps::<0xEE>(t0, t2);
    let s2 = _mm256_shuffle_ps::<0x44>(t1, t3);
    let s3 = _mm256_shuffle_ps::<0xEE>(t1, t3);
    let s4 = _mm256_shuffle_ps::<0x44>(t4, t6);
    let s5 = _mm256_shuffle_ps::<0xEE>(t4, t6);
    let s6 = _mm256_shuffle_ps::<0x44>(t5, t7);
    let s7 = _mm256_shuffle_ps::<0xEE>(t5, t7);
    [
        _mm256_permute2f128_ps::<0x20>(s0, s4),
        _mm256_permute2f128_ps::<0x20>(s1, s5),
        _mm256_permute2f128_ps::<0x20>(s2, s6),
        _mm256_permute2f128_ps::<0x20>(s3, s7),
        _mm256_permute2f128_ps::<0x31>(s0, s4),
        _mm256_permute2f128_ps::<0x31>(s1, s5),
        _mm256_permute2f128_ps::<0x31>(s2, s6),
        _mm256_permute2f128_ps::<0x31>(s3, s7),
    ]
}

/// [`Lane::load_records`] on eight `f32` lanes: blocks of up to eight components, one
/// (masked) load per record and an 8 × 8 transpose (blocks of three or four: 128-bit loads
/// and two 4 × 4 transposes); a last two components as a pair ([`load_pairs8`]), a last one
/// as a vector (`rec = 1`) or a gather.
///
/// # Safety
/// As [`Lane::load_records`]; AVX2 available.
#[inline(always)]
pub(super) unsafe fn load_records8(base: *const f32, rec: usize, out: &mut [__m256]) {
    debug_assert!(out.len() <= rec);
    let mut c0 = 0;
    while out.len() - c0 >= 3 {
        let m = (out.len() - c0).min(8);
        if m <= 4 {
            // Records `l` and `l + 4` in the two halves, then 4 × 4 transposes.
            let mut q = [_mm256_setzero_ps(); 4];
            for (l, x) in q.iter_mut().enumerate() {
                let (p, p4) = (base.add(rec * l + c0), base.add(rec * (l + 4) + c0));
                let (lo, hi) = if m == 4 {
                    (_mm_loadu_ps(p), _mm_loadu_ps(p4))
                } else {
                    let k = _mm256_castsi256_si128(mask8(m));
                    (_mm_maskload_ps(p, k), _mm_maskload_ps(p4, k))
                };
                *x = _mm256_insertf128_ps::<1>(_mm256_castps128_ps256(lo), hi);
            }
            let t = transpose4x2(q);
            out[c0..c0 + m].copy_from_slice(&t[..m]);
        } else {
            let mut r = [_mm256_setzero_ps(); 8];
            for (l, x) in r.iter_mut().enumerate() {
                let p = base.add(rec * l + c0);
                *x = if m == 8 {
                    _mm256_loadu_ps(p)
                } else {
                    _mm256_maskload_ps(p, mask8(m))
                };
            }
            out[c0..c0 + m].copy_from_slice(&transpose8(r)[..m]);
        }
        c0 += m;
    }
    // The last one or two components: two as a pair; one as a vector (one-component records)
    // or a gather (on AMD Zen 4 one gather costs less than the pair loads and shuffles).
    match out.len() - c0 {
        0 => {}
        2 => [out[c0], out[c0 + 1]] = load_pairs8(base.add(c0), rec),
        _ if rec == 1 => out[0] = _mm256_loadu_ps(base),
        _ => out[c0] = F32x8::gather(base.add(c0), rec).0,
    }
}

/// Components 0 and 1 of eight records of `rec` scalars at `p`, as two vectors (one 64-bit
/// load per record, then a de-interleave by shuffles).
///
/// # Safety
/// `p.add(rec·l)` is valid for reading two scalars, `l < 8`; AVX2 available.
#[inline(always)]
unsafe fn load_pairs8(p: *const f32, rec: usize) -> [__m256; 2] {
    let q = |l: usize| p.add(rec * l).cast::<i64>().read_unaligned();
    // [r0 r1 | r4 r5] and [r2 r3 | r6 r7] (each rᵢ = aᵢ bᵢ).
    let x = _mm256_castsi256_ps(_mm256_set_epi64x(q(5), q(4), q(1), q(0)));
    let y = _mm256_castsi256_ps(_mm256_set_epi64x(q(7), q(6), q(3), q(2)));
    [
        _mm256_shuffle_ps::<0x88>(x, y),
        _mm256_shuffle_ps::<0xDD>(x, y),
    ]
}

/// The inverse of [`load_pairs8`]: lane `l` of `a` and `b` to components 0 and 1 of record
/// `l` at `p` (one 64-bit store per record).
///
/// # Safety
/// `p.add(rec·l)` is valid for writing two scalars, `l < 8`; AVX2 available.
#[inline(always)]
unsafe fn store_pairs8(p: *mut f32, rec: usize, a: __m256, b: __m256) {
    let mut lo = [0i64; 4];
    let mut hi = [0i64; 4];
    // [r0 r1 | r4 r5] and [r2 r3 | r6 r7].
    _mm256_storeu_si256(
        lo.as_mut_ptr().cast(),
        _mm256_castps_si256(_mm256_unpacklo_ps(a, b)),
    );
    _mm256_storeu_si256(
        hi.as_mut_ptr().cast(),
        _mm256_castps_si256(_mm256_unpackhi_ps(a, b)),
    );
    // Volatile (a pair is 4-byte aligned, as its scalars): plain stores would be vectorised
    // into two scatter instructions on AVX-512, which are slow on AMD Zen 4.
    let w = |l: usize, v: i64| {
        let pair = core::mem::transmute::<i64, [u32; 2]>(v);
        core::ptr::write_volatile(p.add(rec * l).cast::<[u32; 2]>(), pair);
    };
    w(0, lo[0]);
    w(1, lo[1]);
    w(2, hi[0]);
    w(3, hi[1]);
    w(4, lo[2]);
    w(5, lo[3]);
    w(6, hi[2]);
    w(7, hi[3]);
}

/// Writes lanes `0..m` of `x` to `p[0..m]` with plain stores of 4, 2 and 1 lanes (a masked
/// store, `vmaskmovps`, is several times slower on AMD Zen).
///
/// # Safety
/// `p[0..m]` is valid for writing; `m ≤ 8`.
#[inline(always)]
unsafe fn store_first(p: *mut f32, x: __m256, m: usize) {
    if m == 8 {
        return _mm256_storeu_ps(p, x);
    }
    let (mut rest, mut off, mut r) = (_mm256_castps256_ps128(x), 0, m);
    if r >= 4 {
        _mm_storeu_ps(p, rest);
        (rest, off, r) = (_mm256_extractf128_ps::<1>(x), 4, r - 4);
    }
    if r >= 2 {
        _mm_storeu_si64(p.add(off).cast(), _mm_castps_si128(rest));
        (rest, off, r) = (_mm_movehl_ps(rest, rest), off + 2, r - 2);
    }
    if r == 1 {
        _mm_store_ss(p.add(off), rest);
    }
}

/// [`Lane::store_records`] on eight `f32` lanes: the transposes of [`load_records8`] (each is
/// its own inverse), plain stores of each record's block; a last two components as a pair
/// ([`store_pairs8`]), a last one as a vector (`rec = 1`) or scalars.
///
/// # Safety
/// As [`Lane::store_records`]; AVX2 available.
#[inline(always)]
pub(super) unsafe fn store_records8(base: *mut f32, rec: usize, vals: &[__m256]) {
    debug_assert!(vals.len() <= rec);
    let mut c0 = 0;
    while vals.len() - c0 >= 3 {
        let m = (vals.len() - c0).min(8);
        if m <= 4 {
            let mut r = [_mm256_setzero_ps(); 4];
            r[..m].copy_from_slice(&vals[c0..c0 + m]);
            for (l, x) in transpose4x2(r).iter().enumerate() {
                store_first(base.add(rec * l + c0), *x, m);
                let hi = _mm256_castps128_ps256(_mm256_extractf128_ps::<1>(*x));
                store_first(base.add(rec * (l + 4) + c0), hi, m);
            }
        } else {
            let mut r = [_mm256_setzero_ps(); 8];
            r[..m].copy_from_slice(&vals[c0..c0 + m]);
            for (l, x) in transpose8(r).iter().enumerate() {
                store_first(base.add(rec * l + c0), *x, m);
            }
        }
        c0 += m;
    }
    // The last one or two components: two as a pair; one as a vector (one-component records)
    // or scalars.
    match vals.len() - c0 {
        0 => {}
        2 => store_pairs8(base.add(c0), rec, vals[c0], vals[c0 + 1]),
        _ if rec == 1 => _mm256_storeu_ps(base, vals[0]),
        _ => {
            let mut b = [0.0f32; 8];
            _mm256_storeu_ps(b.as_mut_ptr(), vals[c0]);
            for (i, x) in b.iter().enumerate() {
                // Volatile: not merged into a scatter instruction.
                core::ptr::write_volatile(base.add(i * rec + c0), *x);
            }
        }
    }
}

/// The 4 × 4 transposes of the two 128-bit halves of `r` (8 shuffles): with `r[c]` the
/// component-`c` lanes of eight records, half `h` of output `l` is the first four components
/// of record `l + 4h`, and the same map takes those back to components.
#[inline(always)]
unsafe fn transpose4x2(r: [__m256; 4]) -> [__m256; 4] {
    let t0 = _mm256_unpacklo_ps(r[0], r[1]);
    let t1 = _mm256_unpackhi_ps(r[0], r[1]);
    let t2 = _mm256_unpacklo_ps(r[2], r[3]);
    let t3 = _mm256_unpackhi_ps(r[2], r[3]);
    [
        _mm256_shuffle_ps::<0x44>(t0, t2),
        _mm256_shuffle_ps::<0xEE>(t0, t2),
        _mm256_shuffle_ps::<0x44>(t1, t3),
        _mm256_shuffle_ps::<0xEE>(t1, t3),
    ]
}
