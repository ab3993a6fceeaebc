//! The scalar trait: one source for `f32` and `f64`.
//!
//! Every kernel in this crate is written once, generic over [`Real`], and instantiated for
//! `f32` and `f64`. The elementary functions come from `libm`, so the crate stays `no_std`
//! and gives the same results on every target.

use core::fmt::Debug;
use core::ops::{Add, AddAssign, Div, DivAssign, Mul, MulAssign, Neg, Sub, SubAssign};

/// A floating-point scalar (`f32` or `f64`) with the operations the kernels need.
pub trait Real:
    Copy
    + Debug
    + Default
    + PartialEq
    + PartialOrd
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
    + AddAssign
    + SubAssign
    + MulAssign
    + DivAssign
    + bytemuck::Pod
    + Send
    + Sync
    + 'static
{
    /// 0.
    const ZERO: Self;
    /// 1.
    const ONE: Self;
    /// 2.
    const TWO: Self;
    /// 1/2.
    const HALF: Self;
    /// Machine epsilon (distance from 1 to the next representable number).
    const EPSILON: Self;
    /// Largest finite value.
    const MAX: Self;
    /// Smallest positive normal value.
    const MIN_POSITIVE: Self;
    /// `frexp` exponent of [`Real::MAX`] (128 or 1024): the exponent bias is `MAX_EXP − 1`.
    const MAX_EXP: i32;
    /// Number of mantissa bits including the implicit one (24 or 53).
    const MANTISSA_DIGITS: u32;
    /// Short name used in reports and symbol names ("f32" or "f64").
    const NAME: &'static str;

    /// Nearest value to an `f64` constant.
    #[must_use]
    fn from_f64(x: f64) -> Self;
    /// Widening (or identity) conversion to `f64`.
    #[must_use]
    fn to_f64(self) -> f64;
    /// Conversion from a small integer.
    #[must_use]
    fn from_i32(x: i32) -> Self;
    /// Square root.
    #[must_use]
    fn sqrt(self) -> Self;
    /// Cube root.
    #[must_use]
    fn cbrt(self) -> Self;
    /// Absolute value.
    #[must_use]
    fn abs(self) -> Self;
    /// `self^e` for a real exponent.
    #[must_use]
    fn powf(self, e: Self) -> Self;
    /// Natural exponential.
    #[must_use]
    fn exp(self) -> Self;
    /// Natural logarithm.
    #[must_use]
    fn ln(self) -> Self;
    /// `sqrt(self² + other²)` without undue overflow or underflow.
    #[must_use]
    fn hypot(self, other: Self) -> Self;
    /// Fused multiply-add `self·a + b` (one rounding).
    #[must_use]
    fn mul_add(self, a: Self, b: Self) -> Self;
    /// `self · 2^e`, exact unless the result over- or underflows.
    #[must_use]
    fn scalbn(self, e: i32) -> Self;
    /// Binary exponent `e` with `self = m · 2^e`, `0.5 ≤ |m| < 1` (0 for zero or non-finite).
    #[must_use]
    fn exponent(self) -> i32;
    /// Largest integer not above `self`.
    #[must_use]
    fn floor(self) -> Self;
    /// `2ᵉ` for `e` in the normal range `[1 − bias, bias]` (exact).
    #[must_use]
    fn pow2i(e: i32) -> Self;
    /// A first guess of `1/√self` for a positive normal `self`, relative error below 3.5e-2,
    /// from the exponent bits alone (Lomont's constants for f32/f64): the seed of
    /// [`crate::lane::lmat::rsqrt`]'s Newton steps. Integer operations only, so every path
    /// (scalar, AVX2, AVX-512) gives the same bits.
    #[must_use]
    fn rsqrt_guess(self) -> Self;
    /// Magnitude of `self` with the sign of `sign`.
    #[must_use]
    fn copysign(self, sign: Self) -> Self;
    /// True when neither NaN nor infinite.
    #[must_use]
    fn is_finite(self) -> bool;
    /// The larger of two values (NaN-ignoring, as `libm::fmax`).
    #[must_use]
    fn max(self, other: Self) -> Self;
    /// The smaller of two values (NaN-ignoring, as `libm::fmin`).
    #[must_use]
    fn min(self, other: Self) -> Self;
    /// Sine and cosine at once.
    #[must_use]
    fn sin_cos(self) -> (Self, Self);
    /// Four-quadrant arctangent of `self / x`.
    #[must_use]
    fn atan2(self, x: Self) -> Self;
}

macro_rules! impl_real {
    ($t:ident, $m:literal, $sqrt:path, $cbrt:path, $fabs:path, $pow:path, $exp:path, $ln:path,
     $hypot:path, $fma:path, $scalbn:path, $frexp:path, $copysign:path, $fmax:path, $fmin:path,
     $sincos:path, $atan2:path, $floor:path, $magic:literal) => {
        impl Real for $t {
            const ZERO: Self = 0.0;
            const ONE: Self = 1.0;
            const TWO: Self = 2.0;
            const HALF: Self = 0.5;
            const EPSILON: Self = $t::EPSILON;
            const MAX: Self = $t::MAX;
            const MIN_POSITIVE: Self = $t::MIN_POSITIVE;
            const MANTISSA_DIGITS: u32 = $m;
            const MAX_EXP: i32 = $t::MAX_EXP;
            const NAME: &'static str = stringify!($t);

            #[inline]
            fn from_f64(x: f64) -> Self {
                x as $t
            }
            #[inline]
            fn to_f64(self) -> f64 {
                self as f64
            }
            #[inline]
            fn from_i32(x: i32) -> Self {
                x as $t
            }
            #[inline]
            fn sqrt(self) -> Self {
                $sqrt(self)
            }
            #[inline]
            fn cbrt(self) -> Self {
                $cbrt(self)
            }
            #[inline]
            fn abs(self) -> Self {
                $fabs(self)
            }
            #[inline]
            fn powf(self, e: Self) -> Self {
                $pow(self, e)
            }
            #[inline]
            fn exp(self) -> Self {
                $exp(self)
            }
            #[inline]
            fn ln(self) -> Self {
                $ln(self)
            }
            #[inline]
            fn hypot(self, other: Self) -> Self {
                $hypot(self, other)
            }
            #[inline]
            fn mul_add(self, a: Self, b: Self) -> Self {
                $fma(self, a, b)
            }
            #[inline]
            fn scalbn(self, e: i32) -> Self {
                $scalbn(self, e)
            }
            #[inline]
            fn exponent(self) -> i32 {
                // frexp's exponent from the bits: biased field − (bias − 1); a subnormal is
                // scaled by 2^digits first (exact).
                if self == 0.0 || !self.is_finite() {
                    return 0;
                }
                let a = self.abs();
                let (y, adj) = if a < $t::MIN_POSITIVE {
                    (a * $t::pow2i($m), $m)
                } else {
                    (a, 0)
                };
                let field = (y.to_bits() >> ($m - 1)) as i32;
                field - ($t::MAX_EXP - 2) - adj
            }
            #[inline]
            fn floor(self) -> Self {
                // Values of magnitude ≥ 2^(digits−1) (and NaN, inf) are integers already; below
                // that the truncating conversion is exact, then corrected toward −∞.
                if self.abs() < (1u64 << ($m - 1)) as $t {
                    let t = (self as i64) as $t;
                    if t > self {
                        t - 1.0
                    } else {
                        t
                    }
                } else {
                    $floor(self)
                }
            }
            #[inline]
            fn pow2i(e: i32) -> Self {
                $t::from_bits((((e + $t::MAX_EXP - 1) as u64) << ($m - 1)) as _)
            }
            #[inline]
            fn rsqrt_guess(self) -> Self {
                $t::from_bits($magic - (self.to_bits() >> 1))
            }
            #[inline]
            fn copysign(self, sign: Self) -> Self {
                $copysign(self, sign)
            }
            #[inline]
            fn is_finite(self) -> bool {
                $t::is_finite(self)
            }
            #[inline]
            fn max(self, other: Self) -> Self {
                $fmax(self, other)
            }
            #[inline]
            fn min(self, other: Self) -> Self {
                $fmin(self, other)
            }
            #[inline]
            fn sin_cos(self) -> (Self, Self) {
                $sincos(self)
            }
            #[inline]
            fn atan2(self, x: Self) -> Self {
                $atan2(self, x)
            }
        }
    };
}

impl_real!(
    f32,
    24,
    libm::sqrtf,
    libm::cbrtf,
    libm::fabsf,
    libm::powf,
    libm::expf,
    libm::logf,
    libm::hypotf,
    libm::fmaf,
    libm::scalbnf,
    libm::frexpf,
    libm::copysignf,
    libm::fmaxf,
    libm::fminf,
    libm::sincosf,
    libm::atan2f,
    libm::floorf,
    0x5f37_5a86_u32
);
impl_real!(
    f64,
    53,
    libm::sqrt,
    libm::cbrt,
    libm::fabs,
    libm::pow,
    libm::exp,
    libm::log,
    libm::hypot,
    libm::fma,
    libm::scalbn,
    libm::frexp,
    libm::copysign,
    libm::fmax,
    libm::fmin,
    libm::sincos,
    libm::atan2,
    libm::floor,
    0x5fe6_eb50_c7b5_37a9_u64
);
