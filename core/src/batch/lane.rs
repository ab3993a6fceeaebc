//! Lane types: the arithmetic the batch formulas need, on one scalar or on `N` scalars at once.
//!
//! [`Lane`] is implemented for every [`Real`] (one lane, `Mask = bool`) and for [`L<T, N>`]
//! (`N` lanes in a plain array, `Mask = LMask<N>`). Every operation of `L` is an element-wise
//! loop over a fixed-size array with no data-dependent branch, which LLVM turns into vector
//! instructions of the target (SSE2 by default, AVX2 inside an AVX2 function).
//!
//! **Bit-identity.** Each lane operation gives exactly the bits of the scalar operation on that
//! lane: `+ − × ÷` and `sqrt` are IEEE-754 correctly rounded everywhere, `cbrt` calls the
//! same `libm` function per lane, and `exponent`/`pow2` are exact bit manipulations that agree
//! with [`Real::exponent`] and [`Real::scalbn`] (tested). Rust never contracts `a·b + c` into
//! an FMA, so the baseline and AVX2 builds give the same bits too. A generic lane algorithm run
//! on `L<T, N>` therefore equals the same algorithm run on `T` lane by lane.

use crate::scalar::Real;
use core::fmt::Debug;
use core::ops::{Add, AddAssign, BitAnd, BitOr, Div, Mul, MulAssign, Neg, Not, Sub, SubAssign};

/// `[e(0), …, e(N−1)]` by a plain loop over the const `N` in scope, without closures (which
/// LLVM vectorizes; `core::array::from_fn` and closures are not always inlined).
macro_rules! lanes {
    ($init:expr, $i:ident => $e:expr) => {{
        let mut r = [$init; N];
        for $i in 0..N {
            r[$i] = $e;
        }
        r
    }};
}

/// A scalar or a vector of scalars with lane-wise arithmetic, comparisons and selection.
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
{
    /// The element type.
    type Scalar: Real;
    /// Lane-wise booleans.
    type Mask: Copy
        + Debug
        + BitAnd<Output = Self::Mask>
        + BitOr<Output = Self::Mask>
        + Not<Output = Self::Mask>;
    /// Number of lanes.
    const LANES: usize;

    /// Every lane `x`.
    #[must_use]
    fn splat(x: Self::Scalar) -> Self;
    /// Lane `i` (`i < LANES`).
    #[must_use]
    fn get(self, i: usize) -> Self::Scalar;
    /// Sets lane `i` (`i < LANES`).
    fn set(&mut self, i: usize, x: Self::Scalar);
    /// Lane `i` of a mask.
    #[must_use]
    fn mask_get(m: Self::Mask, i: usize) -> bool;
    /// Correctly rounded square root.
    #[must_use]
    fn sqrt(self) -> Self;
    /// Cube root (`libm`, per lane).
    #[must_use]
    fn cbrt(self) -> Self;
    /// Absolute value.
    #[must_use]
    fn abs(self) -> Self;
    /// Magnitude of `self`, sign of `sign`.
    #[must_use]
    fn copysign(self, sign: Self) -> Self;
    /// `if m { a } else { b }`, lane-wise.
    #[must_use]
    fn select(m: Self::Mask, a: Self, b: Self) -> Self;
    /// `self < o`.
    #[must_use]
    fn lt(self, o: Self) -> Self::Mask;
    /// `self <= o`.
    #[must_use]
    fn le(self, o: Self) -> Self::Mask;
    /// `self == o`.
    #[must_use]
    fn eq(self, o: Self) -> Self::Mask;
    /// Neither NaN nor infinite.
    #[must_use]
    fn is_finite(self) -> Self::Mask;
    /// The larger of two values (either one when they compare equal; NaN-ignoring).
    #[must_use]
    fn max(self, o: Self) -> Self;
    /// [`Real::exponent`] as an integer-valued scalar.
    #[must_use]
    fn exponent(self) -> Self;
    /// `2ᵉ` for an integer-valued `e` (as `Real::scalbn(1, e)`: exact, `inf` or `0` outside
    /// the range of the type).
    #[must_use]
    fn pow2(e: Self) -> Self;
    /// `trunc(e/2)` for an integer-valued `e` (Rust's `i32` division by 2).
    #[must_use]
    fn half_trunc(e: Self) -> Self;
}

impl<T: Real> Lane for T {
    type Scalar = T;
    type Mask = bool;
    const LANES: usize = 1;

    #[inline(always)]
    fn splat(x: T) -> T {
        x
    }
    #[inline(always)]
    fn get(self, _i: usize) -> T {
        self
    }
    #[inline(always)]
    fn set(&mut self, _i: usize, x: T) {
        *self = x;
    }
    #[inline(always)]
    fn mask_get(m: bool, _i: usize) -> bool {
        m
    }
    #[inline(always)]
    fn sqrt(self) -> T {
        Real::sqrt(self)
    }
    #[inline(always)]
    fn cbrt(self) -> T {
        Real::cbrt(self)
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
    fn max(self, o: T) -> T {
        Real::max(self, o)
    }
    #[inline(always)]
    fn exponent(self) -> T {
        T::from_i32(Real::exponent(self))
    }
    #[inline(always)]
    fn pow2(e: T) -> T {
        T::ONE.scalbn(e.to_f64() as i32)
    }
    #[inline(always)]
    fn half_trunc(e: T) -> T {
        T::from_i32((e.to_f64() as i32) / 2)
    }
}

/// `N` lanes of `T` in a plain array (structure-of-arrays: lane `i` is particle `i`).
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(transparent)]
pub struct L<T, const N: usize>(pub [T; N]);

/// `N` lane-wise booleans as integers of the lane width (`0` false, `−1` true), the form of a
/// vector comparison's result, so masks stay in vector registers (a `[bool; N]` does not).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(transparent)]
pub struct LMask<I, const N: usize>(pub [I; N]);

impl<I: MaskInt, const N: usize> BitAnd for LMask<I, N> {
    type Output = Self;
    #[inline(always)]
    fn bitand(self, o: Self) -> Self {
        LMask(lanes!(I::FALSE, i => self.0[i] & o.0[i]))
    }
}

impl<I: MaskInt, const N: usize> BitOr for LMask<I, N> {
    type Output = Self;
    #[inline(always)]
    fn bitor(self, o: Self) -> Self {
        LMask(lanes!(I::FALSE, i => self.0[i] | o.0[i]))
    }
}

impl<I: MaskInt, const N: usize> Not for LMask<I, N> {
    type Output = Self;
    #[inline(always)]
    fn not(self) -> Self {
        LMask(lanes!(I::FALSE, i => !self.0[i]))
    }
}

/// The integer of a mask lane (`i32` for `f32`, `i64` for `f64`).
pub trait MaskInt:
    Copy + Debug + PartialEq + BitAnd<Output = Self> + BitOr<Output = Self> + Not<Output = Self>
{
    /// All bits clear.
    const FALSE: Self;
    /// All bits set.
    const TRUE: Self;
}

impl MaskInt for i32 {
    const FALSE: Self = 0;
    const TRUE: Self = -1;
}

impl MaskInt for i64 {
    const FALSE: Self = 0;
    const TRUE: Self = -1;
}

/// `−1` for true, `0` for false (a sign-extended comparison: one vector compare).
#[inline(always)]
fn m<I: MaskInt>(b: bool) -> I {
    if b {
        I::TRUE
    } else {
        I::FALSE
    }
}

macro_rules! lane_binop {
    ($tr:ident, $f:ident, $tra:ident, $fa:ident, $op:tt) => {
        impl<T: Bits, const N: usize> $tr for L<T, N> {
            type Output = Self;
            #[inline(always)]
            fn $f(self, o: Self) -> Self {
                L(lanes!(T::ZERO, i => self.0[i] $op o.0[i]))
            }
        }
        impl<T: Bits, const N: usize> $tra for L<T, N> {
            #[inline(always)]
            fn $fa(&mut self, o: Self) {
                *self = *self $op o;
            }
        }
    };
}
lane_binop!(Add, add, AddAssign, add_assign, +);
lane_binop!(Sub, sub, SubAssign, sub_assign, -);
lane_binop!(Mul, mul, MulAssign, mul_assign, *);

impl<T: Bits, const N: usize> Div for L<T, N> {
    type Output = Self;
    #[inline(always)]
    fn div(self, o: Self) -> Self {
        L(lanes!(T::ZERO, i => self.0[i] / o.0[i]))
    }
}

impl<T: Bits, const N: usize> Neg for L<T, N> {
    type Output = Self;
    #[inline(always)]
    fn neg(self) -> Self {
        L(lanes!(T::ZERO, i => -self.0[i]))
    }
}

/// The per-type bit manipulations behind [`L`] (implemented for `f32` and `f64`).
pub trait Bits: Real {
    /// The mask integer of the same width.
    type MaskInt: MaskInt;
    /// Correctly rounded square roots of `N` values (SSE2 `sqrtps`/`sqrtpd` on x86-64, which
    /// LLVM widens to AVX inside AVX functions; `libm` per lane elsewhere).
    #[must_use]
    fn sqrt_n<const N: usize>(x: [Self; N]) -> [Self; N];
    /// `|x|` (clears the sign bit).
    #[must_use]
    fn abs_bits(x: Self) -> Self;
    /// Magnitude of `x`, sign of `s`.
    #[must_use]
    fn copysign_bits(x: Self, s: Self) -> Self;
    /// [`Real::exponent`] from the bits (integer-valued result).
    #[must_use]
    fn exponent_bits(x: Self) -> Self;
    /// `2ᵉ` from the bits, `e` integer-valued (as `scalbn(1, e)`).
    #[must_use]
    fn pow2_bits(e: Self) -> Self;
    /// Finite test (`|x| < ∞`, false for NaN).
    #[must_use]
    fn finite_bits(x: Self) -> bool;
    /// `trunc(e/2)` for an integer-valued `e`, through `i32`.
    #[must_use]
    fn half_trunc_bits(e: Self) -> Self;
    /// An integer-valued `e` with `|e| ≤ 2²⁰` as `i32` (other values: some `i32`).
    #[must_use]
    fn small_int(e: Self) -> i32;
}

macro_rules! impl_bits {
    ($t:ident, $u:ident, $mi:ident, $mant:literal, $bias:literal, $vw:literal,
     $load:ident, $sqrt:ident, $store:ident) => {
        impl Bits for $t {
            type MaskInt = $mi;
            #[inline(always)]
            fn sqrt_n<const N: usize>(x: [$t; N]) -> [$t; N] {
                #[cfg(target_arch = "x86_64")]
                {
                    use core::arch::x86_64::{$load, $sqrt, $store};
                    let mut r = x;
                    let mut c = 0;
                    while c + $vw <= N {
                        // SAFETY: SSE2 is part of the x86-64 baseline; `c + $vw <= N`
                        // keeps the unaligned load and store inside `r`.
                        #[allow(unused_unsafe)]
                        unsafe {
                            let v = $load(r.as_ptr().add(c));
                            $store(r.as_mut_ptr().add(c), $sqrt(v));
                        }
                        c += $vw;
                    }
                    while c < N {
                        r[c] = Real::sqrt(r[c]);
                        c += 1;
                    }
                    r
                }
                #[cfg(not(target_arch = "x86_64"))]
                {
                    let mut r = x;
                    for v in r.iter_mut() {
                        *v = Real::sqrt(*v);
                    }
                    r
                }
            }
            #[inline(always)]
            fn abs_bits(x: $t) -> $t {
                let sign: $u = 1 << (<$u>::BITS - 1);
                $t::from_bits(x.to_bits() & !sign)
            }
            #[inline(always)]
            fn copysign_bits(x: $t, s: $t) -> $t {
                let sign: $u = 1 << (<$u>::BITS - 1);
                $t::from_bits((x.to_bits() & !sign) | (s.to_bits() & sign))
            }
            #[inline(always)]
            fn exponent_bits(x: $t) -> $t {
                // frexp: x = m·2ᵉ with 0.5 ≤ |m| < 1, so e = biased − (bias − 1) for normal x.
                // Subnormals are first scaled by 2^MANT (exact) and the exponent corrected.
                let sign: $u = 1 << (<$u>::BITS - 1);
                let mag = x.to_bits() & !sign;
                let sub = mag < (1 << $mant);
                let y = x * if sub {
                    $t::from_bits((($bias + $mant) as $u) << $mant)
                } else {
                    1.0
                };
                let biased = ((y.to_bits() & !sign) >> $mant) as i32;
                let e = biased - ($bias - 1) - if sub { $mant } else { 0 };
                let special = mag == 0 || biased == 2 * $bias + 1;
                if special {
                    0.0
                } else {
                    e as $t
                }
            }
            #[inline(always)]
            fn pow2_bits(e: $t) -> $t {
                // 2ᵉ = 2^e₁ · 2^e₂ with e₁ = clamp(e, 1 − bias, bias) and e₂ the clamped rest:
                // both factors are normal powers built from the exponent field, and the one
                // rounding of the product gives exactly scalbn(1, e): inf above the range,
                // the subnormal power or 0 (round to nearest even) below it. Only the
                // magic-constant conversion and integer min/max/add/shift: vectorizable.
                let ei = Self::small_int(e);
                let e1 = ei.max(1 - $bias).min($bias);
                let e2 = (ei - e1).max(1 - $bias).min($bias);
                let field = |x: i32| $t::from_bits(((x + $bias) as $u) << $mant);
                field(e1) * field(e2)
            }
            #[inline(always)]
            fn small_int(e: $t) -> i32 {
                // Round-to-integer by the magic constant 1.5·2^MANT: for |e| < 2^(MANT−1) the
                // sum's low mantissa bits are e in two's complement. Pure float add and bit
                // operations (vectorizable, unlike Rust's saturating `as`). Callers pass
                // integer-valued |e| ≤ 2²⁰ (other values give some i32, never UB).
                let magic: $t = 1.5 * ((1 as $u) << $mant) as $t;
                ((e + magic).to_bits().wrapping_sub(magic.to_bits())) as i32
            }
            #[inline(always)]
            fn half_trunc_bits(e: $t) -> $t {
                (Self::small_int(e) / 2) as $t
            }
            #[inline(always)]
            fn finite_bits(x: $t) -> bool {
                // |x| < inf is false for ±inf and NaN: one and + one compare per vector.
                Self::abs_bits(x) < $t::INFINITY
            }
        }
    };
}

impl_bits!(
    f32,
    u32,
    i32,
    23,
    127,
    4,
    _mm_loadu_ps,
    _mm_sqrt_ps,
    _mm_storeu_ps
);
impl_bits!(
    f64,
    u64,
    i64,
    52,
    1023,
    2,
    _mm_loadu_pd,
    _mm_sqrt_pd,
    _mm_storeu_pd
);

impl<T: Bits, const N: usize> Lane for L<T, N> {
    type Scalar = T;
    type Mask = LMask<T::MaskInt, N>;
    const LANES: usize = N;

    #[inline(always)]
    fn splat(x: T) -> Self {
        L([x; N])
    }
    #[inline(always)]
    fn get(self, i: usize) -> T {
        self.0[i]
    }
    #[inline(always)]
    fn set(&mut self, i: usize, x: T) {
        self.0[i] = x;
    }
    #[inline(always)]
    fn mask_get(m: Self::Mask, i: usize) -> bool {
        m.0[i] != T::MaskInt::FALSE
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        L(T::sqrt_n(self.0))
    }
    #[inline(always)]
    fn cbrt(self) -> Self {
        L(lanes!(T::ZERO, i => Real::cbrt(self.0[i])))
    }
    #[inline(always)]
    fn abs(self) -> Self {
        L(lanes!(T::ZERO, i => T::abs_bits(self.0[i])))
    }
    #[inline(always)]
    fn copysign(self, sign: Self) -> Self {
        L(lanes!(T::ZERO, i => T::copysign_bits(self.0[i], sign.0[i])))
    }
    #[inline(always)]
    fn select(m: Self::Mask, a: Self, b: Self) -> Self {
        L(lanes!(T::ZERO, i => if m.0[i] != T::MaskInt::FALSE { a.0[i] } else { b.0[i] }))
    }
    #[inline(always)]
    fn lt(self, o: Self) -> Self::Mask {
        LMask(lanes!(T::MaskInt::FALSE, i => m(self.0[i] < o.0[i])))
    }
    #[inline(always)]
    fn le(self, o: Self) -> Self::Mask {
        LMask(lanes!(T::MaskInt::FALSE, i => m(self.0[i] <= o.0[i])))
    }
    #[inline(always)]
    fn eq(self, o: Self) -> Self::Mask {
        LMask(lanes!(T::MaskInt::FALSE, i => m(self.0[i] == o.0[i])))
    }
    #[inline(always)]
    fn is_finite(self) -> Self::Mask {
        LMask(lanes!(T::MaskInt::FALSE, i => m(T::finite_bits(self.0[i]))))
    }
    #[inline(always)]
    fn max(self, o: Self) -> Self {
        // Equal values give `self`; a NaN `o` is ignored (the max_abs fold starts at 0).
        L(lanes!(T::ZERO, i => if self.0[i] < o.0[i] { o.0[i] } else { self.0[i] }))
    }
    #[inline(always)]
    fn exponent(self) -> Self {
        L(lanes!(T::ZERO, i => T::exponent_bits(self.0[i])))
    }
    #[inline(always)]
    fn pow2(e: Self) -> Self {
        L(lanes!(T::ZERO, i => T::pow2_bits(e.0[i])))
    }
    #[inline(always)]
    fn half_trunc(e: Self) -> Self {
        L(lanes!(T::ZERO, i => T::half_trunc_bits(e.0[i])))
    }
}
