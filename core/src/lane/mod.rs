//! Lanes: one source of arithmetic for a scalar and for a SIMD vector of scalars.
//!
//! The default decompositions ([`crate::polar::ClosedForm2`], [`crate::polar::OneSidedJacobi`])
//! and the SVD-basis kernels of fixed corotated Ψ̂ ([`crate::kernel`]) are written once, generic
//! over [`Lane`], and contain no data-dependent branch: every choice is a [`Lane::select`] on a
//! mask. The same source runs
//! - on one `f32` or `f64` ([`Lane`] is implemented for every [`Real`]): the single-particle
//!   API, and the only form on targets without SIMD (`no_std`, `thumbv7em-none-eabihf`);
//! - on x86-64 vectors (`x86` module, crate-private): `f32×8`/`f64×4` with AVX2+FMA and
//!   `f32×16`/`f64×8` with AVX-512 (F, VL, DQ, BW). They are reachable only through the batch
//!   entry points of [`crate::kernel`], which take an [`Isa`] that proves the CPU supports them.
//!
//! **Bits.** The vector paths use only operations that round the same way on AVX2 and
//! AVX-512: `+ − × ÷`, `sqrt`, `floor`, the fused [`Lane::mul_add`] (one rounding), and exact
//! bit manipulations (`abs`, `copysign`, [`Lane::exponent`], [`Lane::pow2`], the integer seed
//! [`Lane::rsqrt_guess`] of the Newton iterations in [`lmat`]). The hardware's approximate
//! `rsqrt`/`rcp` instructions are not used: their bits differ between AVX2 and AVX-512. So
//! the AVX2 and AVX-512 paths give identical bits, and a particle's result does not depend on
//! its lane. The scalar instantiation differs on purpose: without an FMA instruction a fused
//! multiply-add is a ~6 ns software routine, so it rounds `a·b + c` twice; its reciprocal
//! square roots are `1/√x` (lower latency for one particle than a Newton chain); and it skips
//! Jacobi rotations of pairs already orthogonal. It agrees with the vector paths to a few
//! roundings amplified by the conditioning of `F` (bounds tested in `tests/batch/paths.rs` and
//! `c_tests/`).

use crate::scalar::Real;
use core::fmt::Debug;
use core::ops::{Add, AddAssign, BitAnd, BitOr, Div, Mul, MulAssign, Neg, Not, Sub, SubAssign};

mod isa;
pub mod lmat;
pub use isa::{Isa, IsaKind};
mod x2;
pub use x2::{X2Mask, X2};
#[cfg(target_arch = "x86_64")]
mod x86;
#[cfg(target_arch = "x86_64")]
pub(crate) use x86::{F32x16, F32x8, F64x4, F64x8};

/// A scalar or a SIMD vector of scalars with lane-wise arithmetic, comparisons and selection.
pub trait Lane:
    Copy
    + Debug
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
    + AddAssign
    + SubAssign
    + MulAssign
    + Send
    + Sync
    + 'static
{
    /// The element type.
    type Scalar: Real;
    /// Lane-wise booleans.
    type Mask: Copy
        + Debug
        + BitAnd<Output = Self::Mask>
        + BitOr<Output = Self::Mask>
        + Not<Output = Self::Mask>;
    /// Twice these lanes in two independent vectors ([`X2`]); one scalar stays one scalar.
    /// Loops whose per-lane work is a long dependency chain (the decomposition's Jacobi
    /// rotations, each waiting on the last) fill the FMA pipes better with more independent
    /// vectors.
    type Wide: Lane<Scalar = Self::Scalar>;
    /// Number of lanes.
    const LANES: usize;
    /// Whether [`Lane::quad_sums`] runs in registers (else through memory, and a caller
    /// summing stored lanes itself in the same order is faster).
    const QUAD_SUMS_IN_REGISTERS: bool = false;
    /// Whether [`Lane::transpose8`] runs in registers (else through memory, and a caller
    /// that can work on the vectors' stored lanes instead is faster).
    const TRANSPOSE8_IN_REGISTERS: bool = false;

    /// Every lane `x`.
    #[must_use]
    fn splat(x: Self::Scalar) -> Self;
    /// Lanes `s[0..LANES]` (`s.len() ≥ LANES`).
    #[must_use]
    fn load(s: &[Self::Scalar]) -> Self;
    /// Writes the lanes to `s[0..LANES]` (`s.len() ≥ LANES`).
    fn store(self, s: &mut [Self::Scalar]);
    /// Lane `i` from `*base.add(i·stride)` (a hardware gather on the vector paths).
    ///
    /// # Safety
    /// Every `base.add(i·stride)`, `i < LANES`, is valid for reading; `i·stride < 2³¹`.
    #[must_use]
    unsafe fn gather(base: *const Self::Scalar, stride: usize) -> Self;
    /// Writes lane `i` to `*base.add(i·stride)` for every `i` with bit `i` of `keep` set.
    ///
    /// # Safety
    /// Every such `base.add(i·stride)` is valid for writing; `i·stride < 2³¹`.
    unsafe fn scatter(self, base: *mut Self::Scalar, stride: usize, keep: u32);
    /// One short node row per lane, transposed: `out[o]` lane `i` is
    /// `*base.offset(idx[i] + o·s0)` for `o < K ≤ 4` (lanes `K..4` of `out` are 0);
    /// `idx.len() == LANES`. A base pointer and per-lane offsets (scalars), so that a caller
    /// that reads several rows of the same lanes forms no per-lane pointers: each read is
    /// addressed as base plus a lane's offset. Scalar loads by default; the eight-lane `f32`
    /// type loads each row as one masked 4-lane vector when `s0 = 1` and transposes in
    /// registers (the same values).
    ///
    /// # Safety
    /// Every `base.offset(idx[i] + o·s0)`, `i < LANES`, `o < K`, is valid for reading.
    #[inline(always)]
    #[must_use]
    unsafe fn load_rows<const K: usize>(
        base: *const Self::Scalar,
        idx: &[isize],
        s0: isize,
    ) -> [Self; 4] {
        load_rows_scalar::<Self, K>(base, idx, s0)
    }
    /// Structure-of-arrays view of `LANES` consecutive records of `rec` scalars: `out[c]`
    /// lane `i` is `*base.add(i·rec + c)` for `c < out.len() ≤ rec` (a particle array of
    /// `d × d` matrices, say). Gathers by default; the eight-lane `f32` type loads the records
    /// and transposes them in registers (same values, fewer and cheaper instructions).
    ///
    /// # Safety
    /// Every `base.add(i·rec + c)`, `i < LANES`, `c < out.len()`, is valid for reading;
    /// `LANES·rec < 2³¹`.
    #[inline(always)]
    unsafe fn load_records(base: *const Self::Scalar, rec: usize, out: &mut [Self]) {
        for (c, o) in out.iter_mut().enumerate() {
            *o = Self::gather(base.add(c), rec);
        }
    }
    /// The inverse of [`Lane::load_records`]: writes `vals[c]` lane `i` to
    /// `*base.add(i·rec + c)` for `c < vals.len() ≤ rec`, every lane. By default one scalar
    /// store per value (volatile, so that the compiler does not turn them into scatter
    /// instructions, which are slow on AMD Zen 4); the `f32` vector types transpose in
    /// registers and store whole records.
    ///
    /// # Safety
    /// Every such address is valid for writing; `LANES·rec < 2³¹`; `LANES ≤ 32`.
    #[inline(always)]
    unsafe fn store_records(base: *mut Self::Scalar, rec: usize, vals: &[Self]) {
        let mut b = [Self::Scalar::ZERO; 32];
        for (c, v) in vals.iter().enumerate() {
            v.store(&mut b);
            for (i, x) in b.iter().enumerate().take(Self::LANES) {
                core::ptr::write_volatile(base.add(i * rec + c), *x);
            }
        }
    }
    /// Lane `i` truncated toward zero into `out[i]` (`out.len() ≥ LANES ≤ 32`); exact for an
    /// integer in the range of `i32`, unspecified (but no fault) for any other lane value.
    #[inline(always)]
    fn to_i32s(self, out: &mut [i32]) {
        let mut b = [Self::Scalar::ZERO; 32];
        self.store(&mut b);
        for (o, x) in out.iter_mut().zip(&b[..Self::LANES]) {
            *o = x.to_f64() as i32;
        }
    }
    /// Lanes `0..n` from `p[0..n]`, the others 0 (`n ≤ LANES`).
    ///
    /// # Safety
    /// `p[0..n]` is valid for reading.
    #[must_use]
    unsafe fn load_n(p: *const Self::Scalar, n: usize) -> Self;
    /// Writes lanes `0..n` to `p[0..n]` (`n ≤ LANES`).
    ///
    /// # Safety
    /// `p[0..n]` is valid for writing.
    unsafe fn store_n(self, p: *mut Self::Scalar, n: usize);
    /// Lane `i` from `p[i]` for every `i` with bit `i` of `bits` set, the others 0 (bits
    /// `LANES..` clear).
    ///
    /// # Safety
    /// Every such `p.wrapping_add(i)` is valid for reading (`p` itself need not be: the other
    /// lanes are not accessed and do not fault).
    #[must_use]
    unsafe fn load_mask(p: *const Self::Scalar, bits: u32) -> Self;
    /// Writes lane `i` to `p[i]` for every `i` with bit `i` of `bits` set (bits `LANES..`
    /// clear).
    ///
    /// # Safety
    /// Every such `p.wrapping_add(i)` is valid for writing.
    unsafe fn store_mask(self, p: *mut Self::Scalar, bits: u32);
    /// `self·a + b`: fused (one rounding) on the SIMD paths, which all have an FMA
    /// instruction; two roundings on scalars (a software FMA costs ~6 ns without one).
    #[must_use]
    fn mul_add(self, a: Self, b: Self) -> Self;
    /// Correctly rounded square root.
    #[must_use]
    fn sqrt(self) -> Self;
    /// Absolute value (clears the sign bit).
    #[must_use]
    fn abs(self) -> Self;
    /// Magnitude of `self` with the sign bit of `sign`.
    #[must_use]
    fn copysign(self, sign: Self) -> Self;
    /// Largest integer not above `self`.
    #[must_use]
    fn floor(self) -> Self;
    /// [`Real::rsqrt_guess`] lane-wise (the same integer operation on every path).
    #[must_use]
    fn rsqrt_guess(self) -> Self;
    /// `if m { a } else { b }`, lane-wise.
    #[must_use]
    fn select(m: Self::Mask, a: Self, b: Self) -> Self;
    /// `self < o` (false for NaN).
    #[must_use]
    fn lt(self, o: Self) -> Self::Mask;
    /// `self ≤ o` (false for NaN).
    #[must_use]
    fn le(self, o: Self) -> Self::Mask;
    /// `self == o` (false for NaN).
    #[must_use]
    fn eq(self, o: Self) -> Self::Mask;
    /// Neither NaN nor infinite.
    #[must_use]
    fn is_finite(self) -> Self::Mask;
    /// Bit `i` set when lane `i` of `m` is true (at most 64 lanes).
    #[must_use]
    fn mask_bits(m: Self::Mask) -> u64;
    /// Binary exponent `e` with `self = m·2ᵉ`, `0.5 ≤ |m| < 1` (0 for zero or non-finite), as
    /// an integer-valued lane; exact for subnormals too (as `frexp`).
    #[must_use]
    fn exponent(self) -> Self;
    /// `2ᵉ` for an integer-valued `e` in the normal range `[1 − bias, bias]`, built from the
    /// exponent field (exact).
    #[must_use]
    fn pow2(e: Self) -> Self;

    /// [`Real::cbrt`] lane by lane, with its bits on every path: by default the scalar
    /// function per lane; the eight-lane `f32` type evaluates the same algorithm (libm's
    /// `cbrtf`, from FreeBSD's `s_cbrtf.c`) on lanes.
    #[inline(always)]
    #[must_use]
    fn cbrt(self) -> Self {
        let mut a = [Self::Scalar::ZERO; 32];
        self.store(&mut a);
        for x in a.iter_mut().take(Self::LANES) {
            *x = Real::cbrt(*x);
        }
        Self::load(&a)
    }

    /// Lanes `0..LANES/2` repeated in lanes `LANES/2..LANES` (at most 32 lanes). By default
    /// through memory; lane pairs repeat their low half, the eight-lane `f32` type permutes.
    #[inline(always)]
    #[must_use]
    fn dup_low_half(self) -> Self {
        let mut b = [Self::Scalar::ZERO; 32];
        self.store(&mut b);
        let h = Self::LANES / 2;
        for i in 0..h {
            b[h + i] = b[i];
        }
        Self::load(&b)
    }

    /// Sums of four-lane groups of four vectors (`LANES` a multiple of 4, at most 32): lane
    /// `4h + i` of the result is `(x₀ + x₁) + (x₂ + x₃)`, `x_k` lane `4h + k` of `v[i]`. By
    /// default through memory (`quad_sums_in_memory`); the eight-lane `f32` type uses two
    /// levels of horizontal adds, which pair the same lanes in the same order (the same bits).
    #[inline(always)]
    #[must_use]
    fn quad_sums(v: [Self; 4]) -> Self {
        quad_sums_in_memory(v)
    }

    /// The transpose of the 8 × 8 matrix whose rows are `v` (`LANES = 8`): lane `l` of result
    /// `i` is lane `i` of `v[l]`, bits unchanged. By default through memory; the eight-lane
    /// `f32` type shuffles in registers (unpacks, shuffles and 128-bit permutes).
    #[inline(always)]
    #[must_use]
    fn transpose8(v: [Self; 8]) -> [Self; 8] {
        debug_assert!(Self::LANES == 8);
        let mut b = [[Self::Scalar::ZERO; 8]; 8];
        for (r, x) in b.iter_mut().zip(&v) {
            x.store(r);
        }
        let mut out = v;
        for (i, o) in out.iter_mut().enumerate() {
            let mut col = [Self::Scalar::ZERO; 8];
            for (c, r) in col.iter_mut().zip(&b) {
                *c = r[i];
            }
            *o = Self::load(&col);
        }
        out
    }

    /// `1/√self` for a positive normal `self`, to a few ulps. Vector paths: the Newton
    /// iteration [`lmat::rsqrt_newton`] (no division or square-root instruction, whose
    /// throughput would dominate the kernels); scalars: `1/√x` with the correctly rounded
    /// instructions (lower latency for one particle, and within one ulp of each rounding).
    #[inline(always)]
    #[must_use]
    fn rsqrt(self) -> Self {
        lmat::rsqrt_newton(self)
    }
    /// `1/self` for a positive normal `self`: `rsqrt(x)²` on the vector paths, a correctly
    /// rounded division on scalars.
    #[inline(always)]
    #[must_use]
    fn recip(self) -> Self {
        let r = self.rsqrt();
        r * r
    }
    /// The larger of two lanes (`o` where either is NaN: callers mask NaN separately).
    #[inline(always)]
    #[must_use]
    fn max(self, o: Self) -> Self {
        Self::select(o.lt(self), self, o)
    }
    /// The smaller of two lanes.
    #[inline(always)]
    #[must_use]
    fn min(self, o: Self) -> Self {
        Self::select(self.lt(o), self, o)
    }
    /// Every lane of `m` true.
    #[inline(always)]
    #[must_use]
    fn all(m: Self::Mask) -> bool {
        Self::mask_bits(m) == (u64::MAX >> (64 - Self::LANES as u32))
    }
    /// Some lane of `m` true.
    #[inline(always)]
    #[must_use]
    fn any(m: Self::Mask) -> bool {
        Self::mask_bits(m) != 0
    }
}

/// A lane type made of two vectors `R` side by side (halves 0 and 1): for short per-item rows
/// that can share one register. Where the pair is one register ([`Pair::JOINED`], `f32×16`
/// holding two `f32×8` on AVX-512), an operation on the pair costs one instruction for both
/// halves; otherwise ([`X2`]) it costs two, and a caller may as well work on the halves.
pub trait Pair<R: Lane>: Lane<Scalar = R::Scalar> {
    /// Both halves are one register.
    const JOINED: bool;
    /// The pair with `lo` in half 0 and `hi` in half 1.
    fn join(lo: R, hi: R) -> Self;
}

impl<R: Lane> Pair<R> for X2<R> {
    const JOINED: bool = false;
    #[inline(always)]
    fn join(lo: R, hi: R) -> Self {
        X2([lo, hi])
    }
}

/// [`Lane::load_rows`] by scalar reads (any axis-0 stride `s0`): its default, and the strided
/// case of the types that override it.
///
/// # Safety
/// As [`Lane::load_rows`].
#[inline(always)]
pub(crate) unsafe fn load_rows_scalar<L: Lane, const K: usize>(
    base: *const L::Scalar,
    idx: &[isize],
    s0: isize,
) -> [L; 4] {
    debug_assert!(K <= 4 && idx.len() == L::LANES && L::LANES <= 16);
    let mut b = [[L::Scalar::ZERO; 16]; 4];
    for (i, &q) in idx.iter().enumerate() {
        for (o, bo) in b.iter_mut().enumerate().take(K) {
            bo[i] = base.offset(q + o as isize * s0).read_unaligned();
        }
    }
    [
        L::load(&b[0]),
        L::load(&b[1]),
        L::load(&b[2]),
        L::load(&b[3]),
    ]
}

/// [`Lane::quad_sums`] through memory: each vector stored, its groups summed as scalars.
#[inline(always)]
#[must_use]
pub(crate) fn quad_sums_in_memory<V: Lane>(v: [V; 4]) -> V {
    debug_assert!(V::LANES % 4 == 0 && V::LANES <= 32);
    let (mut b, mut o) = ([V::Scalar::ZERO; 32], [V::Scalar::ZERO; 32]);
    for (i, x) in v.iter().enumerate() {
        x.store(&mut b);
        for h in 0..V::LANES / 4 {
            let g = &b[4 * h..4 * h + 4];
            o[4 * h + i] = (g[0] + g[1]) + (g[2] + g[3]);
        }
    }
    V::load(&o)
}

/// The scalar instantiation: one lane, `Mask = bool`. The operations are those of [`Real`]
/// (`libm`), so this is also what `no_std` targets run.
impl<T: Real> Lane for T {
    type Scalar = T;
    type Mask = bool;
    type Wide = T;
    const LANES: usize = 1;

    #[inline(always)]
    fn splat(x: T) -> T {
        x
    }
    #[inline(always)]
    fn load(s: &[T]) -> T {
        s[0]
    }
    #[inline(always)]
    fn store(self, s: &mut [T]) {
        s[0] = self;
    }
    #[inline(always)]
    unsafe fn gather(base: *const T, _stride: usize) -> T {
        base.read_unaligned()
    }
    #[inline(always)]
    unsafe fn scatter(self, base: *mut T, _stride: usize, keep: u32) {
        if keep & 1 == 1 {
            base.write_unaligned(self);
        }
    }
    #[inline(always)]
    unsafe fn load_n(p: *const T, n: usize) -> T {
        if n > 0 {
            p.read_unaligned()
        } else {
            T::ZERO
        }
    }
    #[inline(always)]
    unsafe fn store_n(self, p: *mut T, n: usize) {
        if n > 0 {
            p.write_unaligned(self);
        }
    }
    #[inline(always)]
    unsafe fn load_mask(p: *const T, bits: u32) -> T {
        if bits & 1 == 1 {
            p.read_unaligned()
        } else {
            T::ZERO
        }
    }
    #[inline(always)]
    unsafe fn store_mask(self, p: *mut T, bits: u32) {
        if bits & 1 == 1 {
            p.write_unaligned(self);
        }
    }
    #[inline(always)]
    fn mul_add(self, a: T, b: T) -> T {
        self * a + b
    }
    #[inline(always)]
    fn sqrt(self) -> T {
        Real::sqrt(self)
    }
    #[inline(always)]
    fn abs(self) -> T {
        Real::abs(self)
    }
    #[inline(always)]
    fn copysign(self, sign: T) -> T {
        Real::copysign(self, sign)
    }
    #[inline(always)]
    fn floor(self) -> T {
        Real::floor(self)
    }
    #[inline(always)]
    fn rsqrt_guess(self) -> T {
        Real::rsqrt_guess(self)
    }
    #[inline(always)]
    fn rsqrt(self) -> T {
        T::ONE / Real::sqrt(self)
    }
    #[inline(always)]
    fn recip(self) -> T {
        T::ONE / self
    }
    #[inline(always)]
    fn select(m: bool, a: T, b: T) -> T {
        if m {
            a
        } else {
            b
        }
    }
    #[inline(always)]
    fn lt(self, o: T) -> bool {
        self < o
    }
    #[inline(always)]
    fn le(self, o: T) -> bool {
        self <= o
    }
    #[inline(always)]
    fn eq(self, o: T) -> bool {
        self == o
    }
    #[inline(always)]
    fn is_finite(self) -> bool {
        Real::is_finite(self)
    }
    #[inline(always)]
    fn mask_bits(m: bool) -> u64 {
        u64::from(m)
    }
    #[inline(always)]
    fn exponent(self) -> T {
        T::from_i32(Real::exponent(self))
    }
    #[inline(always)]
    fn pow2(e: T) -> T {
        T::pow2i(e.to_f64() as i32)
    }
}

#[cfg(all(test, feature = "std"))]
mod tests;
