//! [`X2`]: a lane type made of two vectors of another, twice as wide.

use super::Lane;
use crate::scalar::Real;
use core::ops::{Add, AddAssign, BitAnd, BitOr, Div, Mul, MulAssign, Neg, Not, Sub, SubAssign};

/// Two vectors processed as one lane type of twice the width: every operation is issued on
/// both halves, which are independent, so the long dependency chains of the kernels (a
/// Jacobi rotation waits for its Newton square roots) overlap and the core's pipelines stay
/// full. Same bits as the halves alone.
#[derive(Clone, Copy, Debug)]
pub struct X2<V>(pub [V; 2]);

/// The mask of [`X2`].
#[derive(Clone, Copy, Debug)]
pub struct X2Mask<M>(pub [M; 2]);

impl<M: Copy + BitAnd<Output = M>> BitAnd for X2Mask<M> {
    type Output = Self;
    #[inline(always)]
    fn bitand(self, o: Self) -> Self {
        X2Mask([self.0[0] & o.0[0], self.0[1] & o.0[1]])
    }
}
impl<M: Copy + BitOr<Output = M>> BitOr for X2Mask<M> {
    type Output = Self;
    #[inline(always)]
    fn bitor(self, o: Self) -> Self {
        X2Mask([self.0[0] | o.0[0], self.0[1] | o.0[1]])
    }
}
impl<M: Copy + Not<Output = M>> Not for X2Mask<M> {
    type Output = Self;
    #[inline(always)]
    fn not(self) -> Self {
        X2Mask([!self.0[0], !self.0[1]])
    }
}

macro_rules! x2_binop {
    ($tr:ident, $f:ident, $tra:ident, $fa:ident, $op:tt) => {
        impl<V: Lane> $tr for X2<V> {
            type Output = Self;
            #[inline(always)]
            fn $f(self, o: Self) -> Self {
                X2([self.0[0] $op o.0[0], self.0[1] $op o.0[1]])
            }
        }
        impl<V: Lane> $tra for X2<V> {
            #[inline(always)]
            fn $fa(&mut self, o: Self) {
                *self = *self $op o;
            }
        }
    };
}
x2_binop!(Add, add, AddAssign, add_assign, +);
x2_binop!(Sub, sub, SubAssign, sub_assign, -);
x2_binop!(Mul, mul, MulAssign, mul_assign, *);

impl<V: Lane> Div for X2<V> {
    type Output = Self;
    #[inline(always)]
    fn div(self, o: Self) -> Self {
        X2([self.0[0] / o.0[0], self.0[1] / o.0[1]])
    }
}
impl<V: Lane> Neg for X2<V> {
    type Output = Self;
    #[inline(always)]
    fn neg(self) -> Self {
        X2([-self.0[0], -self.0[1]])
    }
}

impl<V: Lane> Lane for X2<V> {
    type Scalar = V::Scalar;
    type Mask = X2Mask<V::Mask>;
    type Wide = X2<Self>;
    const LANES: usize = 2 * V::LANES;

    #[inline(always)]
    fn splat(x: Self::Scalar) -> Self {
        X2([V::splat(x); 2])
    }
    #[inline(always)]
    fn load(s: &[Self::Scalar]) -> Self {
        X2([V::load(s), V::load(&s[V::LANES..])])
    }
    #[inline(always)]
    fn store(self, s: &mut [Self::Scalar]) {
        self.0[0].store(s);
        self.0[1].store(&mut s[V::LANES..]);
    }
    #[inline(always)]
    unsafe fn gather(base: *const Self::Scalar, stride: usize) -> Self {
        X2([
            V::gather(base, stride),
            V::gather(base.add(V::LANES * stride), stride),
        ])
    }
    #[inline(always)]
    unsafe fn scatter(self, base: *mut Self::Scalar, stride: usize, keep: u32) {
        self.0[0].scatter(base, stride, keep);
        self.0[1].scatter(base.add(V::LANES * stride), stride, keep >> V::LANES);
    }
    #[inline(always)]
    unsafe fn load_records(base: *const Self::Scalar, rec: usize, out: &mut [Self]) {
        let n = out.len();
        let (mut lo, mut hi) = (
            [V::splat(Self::Scalar::ZERO); 32],
            [V::splat(Self::Scalar::ZERO); 32],
        );
        V::load_records(base, rec, &mut lo[..n]);
        V::load_records(base.add(V::LANES * rec), rec, &mut hi[..n]);
        for (o, (l, h)) in out.iter_mut().zip(lo.iter().zip(&hi)) {
            *o = X2([*l, *h]);
        }
    }
    #[inline(always)]
    unsafe fn store_records(base: *mut Self::Scalar, rec: usize, vals: &[Self]) {
        let n = vals.len();
        let (mut lo, mut hi) = (
            [V::splat(Self::Scalar::ZERO); 32],
            [V::splat(Self::Scalar::ZERO); 32],
        );
        for (v, (l, h)) in vals.iter().zip(lo.iter_mut().zip(hi.iter_mut())) {
            [*l, *h] = v.0;
        }
        V::store_records(base, rec, &lo[..n]);
        V::store_records(base.add(V::LANES * rec), rec, &hi[..n]);
    }
    #[inline(always)]
    fn to_i32s(self, out: &mut [i32]) {
        self.0[0].to_i32s(out);
        self.0[1].to_i32s(&mut out[V::LANES..]);
    }
    #[inline(always)]
    fn cbrt(self) -> Self {
        X2([self.0[0].cbrt(), self.0[1].cbrt()])
    }
    #[inline(always)]
    fn dup_low_half(self) -> Self {
        X2([self.0[0], self.0[0]])
    }
    #[inline(always)]
    unsafe fn load_n(p: *const Self::Scalar, n: usize) -> Self {
        if n > V::LANES {
            X2([
                V::load_n(p, V::LANES),
                V::load_n(p.add(V::LANES), n - V::LANES),
            ])
        } else {
            X2([V::load_n(p, n), V::splat(<V::Scalar as Real>::ZERO)])
        }
    }
    #[inline(always)]
    unsafe fn store_n(self, p: *mut Self::Scalar, n: usize) {
        if n > V::LANES {
            self.0[0].store_n(p, V::LANES);
            self.0[1].store_n(p.add(V::LANES), n - V::LANES);
        } else {
            self.0[0].store_n(p, n);
        }
    }
    #[inline(always)]
    unsafe fn load_mask(p: *const Self::Scalar, bits: u32) -> Self {
        let lo = bits & ((1u32 << V::LANES) - 1);
        X2([
            V::load_mask(p, lo),
            V::load_mask(p.wrapping_add(V::LANES), bits >> V::LANES),
        ])
    }
    #[inline(always)]
    unsafe fn store_mask(self, p: *mut Self::Scalar, bits: u32) {
        let lo = bits & ((1u32 << V::LANES) - 1);
        self.0[0].store_mask(p, lo);
        self.0[1].store_mask(p.wrapping_add(V::LANES), bits >> V::LANES);
    }
    #[inline(always)]
    fn mul_add(self, a: Self, b: Self) -> Self {
        X2([
            self.0[0].mul_add(a.0[0], b.0[0]),
            self.0[1].mul_add(a.0[1], b.0[1]),
        ])
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        X2([self.0[0].sqrt(), self.0[1].sqrt()])
    }
    #[inline(always)]
    fn abs(self) -> Self {
        X2([self.0[0].abs(), self.0[1].abs()])
    }
    #[inline(always)]
    fn copysign(self, sign: Self) -> Self {
        X2([self.0[0].copysign(sign.0[0]), self.0[1].copysign(sign.0[1])])
    }
    #[inline(always)]
    fn floor(self) -> Self {
        X2([self.0[0].floor(), self.0[1].floor()])
    }
    #[inline(always)]
    fn rsqrt_guess(self) -> Self {
        X2([self.0[0].rsqrt_guess(), self.0[1].rsqrt_guess()])
    }
    #[inline(always)]
    fn select(m: Self::Mask, a: Self, b: Self) -> Self {
        X2([
            V::select(m.0[0], a.0[0], b.0[0]),
            V::select(m.0[1], a.0[1], b.0[1]),
        ])
    }
    #[inline(always)]
    fn lt(self, o: Self) -> Self::Mask {
        X2Mask([self.0[0].lt(o.0[0]), self.0[1].lt(o.0[1])])
    }
    #[inline(always)]
    fn le(self, o: Self) -> Self::Mask {
        X2Mask([self.0[0].le(o.0[0]), self.0[1].le(o.0[1])])
    }
    #[inline(always)]
    fn eq(self, o: Self) -> Self::Mask {
        X2Mask([self.0[0].eq(o.0[0]), self.0[1].eq(o.0[1])])
    }
    #[inline(always)]
    fn is_finite(self) -> Self::Mask {
        X2Mask([self.0[0].is_finite(), self.0[1].is_finite()])
    }
    #[inline(always)]
    fn mask_bits(m: Self::Mask) -> u64 {
        V::mask_bits(m.0[0]) | V::mask_bits(m.0[1]) << V::LANES
    }
    #[inline(always)]
    fn exponent(self) -> Self {
        X2([self.0[0].exponent(), self.0[1].exponent()])
    }
    #[inline(always)]
    fn pow2(e: Self) -> Self {
        X2([V::pow2(e.0[0]), V::pow2(e.0[1])])
    }
}
