//! x86-64 SIMD lanes: `f32×8` and `f64×4` (AVX2 + FMA), `f32×16` and `f64×8` (AVX-512F).
//!
//! Each method is `#[inline(always)]` around one or a few `core::arch` intrinsics. The types
//! are crate-private and are only ever created inside the `#[target_feature]` functions of
//! [`crate::kernel`], which are reached only with an [`crate::lane::Isa`] proving the CPU has
//! the instructions: that is the safety argument of every `unsafe` block here. Once inlined
//! into such a function, LLVM emits the vector instructions directly.
//!
//! Every operation is the IEEE-754 operation of the scalar instantiation (see the module
//! docs of [`crate::lane`]): `vfmadd` rounds once, `vsqrt`/`vdiv` are correctly rounded,
//! `floor` is `vround`/`vrndscale` toward −∞, [`Lane::exponent`](crate::lane::Lane::exponent)
//! and [`Lane::pow2`](crate::lane::Lane::pow2) are exact.

#![allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]

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

mod avx2;
mod avx512;
mod records;

pub(crate) use avx2::{F32x8, F64x4};
pub(crate) use avx512::{F32x16, F64x8};
