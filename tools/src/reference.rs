//! Double-double reference for R, Σ, Ψ̂, Â and Ĉ:Z.
//!
//! [`Dd`] is a double-double scalar (`hi + lo`, unevaluated sum of two non-overlapping `f64`)
//! whose arithmetic is the `twofloat` crate's (Joldes, Muller, Popescu 2017 algorithms, relative
//! error of `+ − ×` at most a few `u²`, `u = 2⁻⁵³`; `√` by Karp–Markstein) except division,
//! which is done here by long division because twofloat 0.8's is only f64-accurate (see
//! [`Dd`]'s `Div`). It implements
//! [`ampm_core::Real`], so the core's own generic kernels — [`OneSidedJacobi`] (3D),
//! [`ClosedForm2`] (2D), [`ampm_core::augmented::Augmented`] over
//! [`ampm_core::energy::FixedCorotated`] — run unchanged in double-double and give the
//! reference.
//!
//! **Why that is an adequate reference for measuring f64 (and f32) rounding error.** The
//! methods are backward stable: run in a precision with unit roundoff `u'`, their error is
//! `≤ c·u'·κ` with a modest `c` and the condition `κ` of the problem at that input. Run in
//! double-double, `u' ≈ 2⁻¹⁰⁴ ≈ 5e-32`, so the reference's own error is `~1e-15` of the f64
//! error being measured (in units of `ε_f64·κ` it contributes `≤ 1e-15·c`), and every input is
//! converted to double-double exactly (the reference sees the very `F` the method saw, after its
//! rounding to f32 or f64). What this cannot catch is an error in the *formulas* (the same generic
//! source computes both sides); those are checked independently: `Â` and `Ĉ:Z` against finite
//! differences of `Ψ̂` (`tests/kernels/precision.rs`, `tests/hessian/brute_force.rs`) and against
//! an Eigen implementation of the seed's formulas in long double (`c_tests/`). The reference SVD
//! itself is checked in `tests/stability/contracts.rs`: it reconstructs `F` to `~1e-30` relative
//! and `U`, `V` are orthonormal to that level.
//!
//! The transcendental functions of `twofloat` (`exp`, `ln`, `powf`, `sin_cos`, `atan2`) are
//! "preliminary" in its own words; the kernels do not use them (only `+ − × ÷ √ ∛`).

use ampm_core::augmented::Augmented;
use ampm_core::energy::FixedCorotated;
use ampm_core::polar::{ClosedForm2, OneSidedJacobi, Svd, SvdMethod};
use ampm_core::{Mat, Matrix, Real, Result};
use core::cmp::Ordering;
use core::ops::{Add, AddAssign, Div, DivAssign, Mul, MulAssign, Neg, Sub, SubAssign};
use twofloat::TwoFloat;

/// A double-double number `hi + lo`, `|lo| ≤ ulp(hi)/2` (normalised as `twofloat` leaves it).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[repr(C)]
pub struct Dd {
    /// Leading part, `fl(hi + lo)`.
    pub hi: f64,
    /// Trailing part.
    pub lo: f64,
}

// SAFETY: `repr(C)` struct of two `f64`: no padding, every bit pattern is a valid value.
unsafe impl bytemuck::Zeroable for Dd {}
// SAFETY: see above.
unsafe impl bytemuck::Pod for Dd {}

impl Dd {
    /// The value as a `TwoFloat`. `TwoSum(hi, lo)` is exact and returns `(hi, lo)` for a
    /// normalised pair, without `TwoFloat::try_from`'s overlap check (an `exp2` per call).
    #[inline]
    #[must_use]
    pub fn tf(self) -> TwoFloat {
        TwoFloat::new_add(self.hi, self.lo)
    }

    /// From a `TwoFloat`.
    #[inline]
    #[must_use]
    pub fn from_tf(t: TwoFloat) -> Self {
        Self {
            hi: t.hi(),
            lo: t.lo(),
        }
    }

    /// Exact conversion of an `f64`.
    #[inline]
    #[must_use]
    pub const fn exact(x: f64) -> Self {
        Self { hi: x, lo: 0.0 }
    }
}

impl PartialOrd for Dd {
    #[inline]
    fn partial_cmp(&self, o: &Self) -> Option<Ordering> {
        // Lexicographic on normalised pairs is the order of the values.
        match self.hi.partial_cmp(&o.hi)? {
            Ordering::Equal => self.lo.partial_cmp(&o.lo),
            c => Some(c),
        }
    }
}

/// The double-double operations of twofloat assume finite operands and results (an `inf`
/// becomes `NaN` in the error-free transformations). IEEE semantics are kept instead: when
/// the plain f64 operation on the leading parts is not finite, or an operand is not, that
/// f64 result is returned. The core's generic kernels rely on them (one-sided Jacobi lets
/// `ζ²` overflow to `inf` on a rank-deficient column, giving the rotation `t = 0`).
macro_rules! dd_binop {
    ($tr:ident, $f:ident, $tra:ident, $fa:ident, $op:tt) => {
        impl $tr for Dd {
            type Output = Dd;
            #[inline]
            fn $f(self, o: Dd) -> Dd {
                let p = self.hi $op o.hi;
                if !(p.is_finite() && self.is_finite() && o.is_finite()) {
                    return Dd::exact(p);
                }
                Dd::from_tf(self.tf() $op o.tf())
            }
        }
        impl $tra for Dd {
            #[inline]
            fn $fa(&mut self, o: Dd) {
                *self = *self $op o;
            }
        }
    };
}
dd_binop!(Add, add, AddAssign, add_assign, +);
dd_binop!(Sub, sub, SubAssign, sub_assign, -);
dd_binop!(Mul, mul, MulAssign, mul_assign, *);

/// Division by long division (the QD library's `sloppy_div` plus one more correction step):
/// `q₁ = a_hi/b_hi`, `r = a − q₁b`, `q₂ = r_hi/b_hi`, `r ← r − q₂b`, `q₃ = r_hi/b_hi`,
/// `q = q₁ + q₂ + q₃`. Each remainder is formed with twofloat's accurate `TwoFloat × f64`
/// (Joldes et al. Alg. 9) and `TwoFloat − TwoFloat` (Alg. 6), so `q` has relative error
/// `O(2⁻¹⁰⁴)`. twofloat 0.8's own `TwoFloat / TwoFloat` (its Alg. 18) computes the residual
/// `1 − b_hi·t_h` in plain f64 without an FMA, which rounds it to zero: its quotient is only
/// f64-accurate (`(1/3)·3 − 1 = −5.6e-17`), hence this replacement.
impl Div for Dd {
    type Output = Dd;
    #[inline]
    fn div(self, o: Dd) -> Dd {
        let p = self.hi / o.hi;
        if !(p.is_finite() && self.is_finite() && o.is_finite()) {
            return Dd::exact(p);
        }
        let (a, b) = (self.tf(), o.tf());
        let q1 = a.hi() / b.hi();
        let r = a - b * q1;
        let q2 = r.hi() / b.hi();
        let r = r - b * q2;
        let q3 = r.hi() / b.hi();
        Dd::from_tf(TwoFloat::new_add(q1, q2) + q3)
    }
}

impl DivAssign for Dd {
    #[inline]
    fn div_assign(&mut self, o: Dd) {
        *self = *self / o;
    }
}

impl Neg for Dd {
    type Output = Dd;
    #[inline]
    fn neg(self) -> Dd {
        Dd {
            hi: -self.hi,
            lo: -self.lo,
        }
    }
}

impl Real for Dd {
    const ZERO: Self = Dd::exact(0.0);
    const ONE: Self = Dd::exact(1.0);
    const TWO: Self = Dd::exact(2.0);
    const HALF: Self = Dd::exact(0.5);
    /// `2⁻¹⁰⁴`: twice the double-double unit roundoff `2⁻¹⁰⁵`, the accuracy its `+ − × ÷`
    /// actually reach (a few `u²`); used by the kernels only as a relative tolerance.
    const EPSILON: Self = Dd::exact(4.930_380_657_631_324e-32);
    const MAX: Self = Dd::exact(f64::MAX);
    /// `2⁻⁹⁶⁹`: below it the trailing part would be subnormal (fewer than 106 bits).
    const MIN_POSITIVE: Self = Dd::exact(2.004_168_360_008_973e-292);
    const MANTISSA_DIGITS: u32 = 106;
    const MAX_EXP: i32 = f64::MAX_EXP;
    const NAME: &'static str = "dd";

    #[inline]
    fn from_f64(x: f64) -> Self {
        Dd::exact(x)
    }
    #[inline]
    fn to_f64(self) -> f64 {
        self.hi + self.lo
    }
    #[inline]
    fn from_i32(x: i32) -> Self {
        Dd::exact(f64::from(x))
    }
    #[inline]
    fn sqrt(self) -> Self {
        if !self.hi.is_finite() || self.hi < 0.0 {
            return Dd::exact(self.hi.sqrt());
        }
        Dd::from_tf(self.tf().sqrt())
    }
    #[inline]
    fn floor(self) -> Self {
        let h = self.hi.floor();
        if h == self.hi {
            // An integer leading part: the trailing part decides (hi + lo is not rounded).
            let l = self.lo.floor();
            let s = h + l;
            Dd {
                hi: s,
                lo: l - (s - h),
            }
        } else {
            Dd::exact(h)
        }
    }
    #[inline]
    fn pow2i(e: i32) -> Self {
        Dd::exact(f64::pow2i(e))
    }
    #[inline]
    fn rsqrt_guess(self) -> Self {
        Dd::exact(Real::rsqrt_guess(self.hi))
    }
    #[inline]
    fn cbrt(self) -> Self {
        // twofloat's Newton step divides by x², 0/0 at zero.
        if self.hi == 0.0 {
            self
        } else {
            Dd::from_tf(self.tf().cbrt())
        }
    }
    #[inline]
    fn abs(self) -> Self {
        if self.hi < 0.0 {
            -self
        } else {
            self
        }
    }
    #[inline]
    fn powf(self, e: Self) -> Self {
        Dd::from_tf(self.tf().powf(e.tf()))
    }
    #[inline]
    fn exp(self) -> Self {
        Dd::from_tf(self.tf().exp())
    }
    #[inline]
    fn ln(self) -> Self {
        Dd::from_tf(self.tf().ln())
    }
    #[inline]
    fn hypot(self, other: Self) -> Self {
        // Scaled by an exact power of two so the squares neither overflow nor underflow.
        let m = self.abs().max(other.abs());
        if m.hi == 0.0 || !m.is_finite() {
            return m;
        }
        let e = m.exponent();
        let (a, b) = (self.scalbn(-e), other.scalbn(-e));
        (a * a + b * b).sqrt().scalbn(e)
    }
    #[inline]
    fn mul_add(self, a: Self, b: Self) -> Self {
        self * a + b
    }
    #[inline]
    fn scalbn(self, e: i32) -> Self {
        Dd {
            hi: libm::scalbn(self.hi, e),
            lo: libm::scalbn(self.lo, e),
        }
    }
    #[inline]
    fn exponent(self) -> i32 {
        if self.hi == 0.0 || !self.is_finite() {
            return 0;
        }
        let (m, e) = libm::frexp(self.hi);
        // hi = ±2^(e−1) exactly and lo of the other sign: the value is just below 2^(e−1).
        if m.abs() == 0.5 && self.lo != 0.0 && (self.lo < 0.0) != (self.hi < 0.0) {
            e - 1
        } else {
            e
        }
    }
    #[inline]
    fn copysign(self, sign: Self) -> Self {
        if self.hi.is_sign_negative() == sign.hi.is_sign_negative() {
            self
        } else {
            -self
        }
    }
    #[inline]
    fn is_finite(self) -> bool {
        self.hi.is_finite() && self.lo.is_finite()
    }
    #[inline]
    fn max(self, other: Self) -> Self {
        if self.hi.is_nan() || other > self {
            other
        } else {
            self
        }
    }
    #[inline]
    fn min(self, other: Self) -> Self {
        if self.hi.is_nan() || other < self {
            other
        } else {
            self
        }
    }
    #[inline]
    fn sin_cos(self) -> (Self, Self) {
        let (s, c) = self.tf().sin_cos();
        (Dd::from_tf(s), Dd::from_tf(c))
    }
    #[inline]
    fn atan2(self, x: Self) -> Self {
        Dd::from_tf(self.tf().atan2(x.tf()))
    }
}

/// A matrix of `f64` (or of values first rounded to `f32`) converted exactly to double-double.
#[inline]
#[must_use]
pub fn to_dd<const D: usize>(m: &Mat<f64, D>) -> Mat<Dd, D> {
    let mut r = Mat::<Dd, D>::ZERO;
    for j in 0..D {
        for i in 0..D {
            r.cols[j][i] = Dd::exact(m.cols[j][i]);
        }
    }
    r
}

/// A double-double matrix rounded to `f64`.
#[inline]
#[must_use]
pub fn to_f64<const D: usize>(m: &Mat<Dd, D>) -> Mat<f64, D> {
    m.cast::<f64>()
}

/// Sweep cap of the reference one-sided Jacobi: Jacobi converges quadratically, so the one or
/// two sweeps that take an f64-accurate result to double-double accuracy fit easily; the cap
/// only bounds a pathological case.
pub const REFERENCE_SWEEPS: u32 = 24;

/// The reference SVD method of each dimension, run in double-double.
pub trait ReferenceDim: Sized {
    /// `Mat<Dd, D>`.
    type M: Matrix<Scalar = Dd>;
    /// The method: [`ClosedForm2`] in 2D, [`OneSidedJacobi`] (24 sweeps) in 3D.
    type Method: SvdMethod<Self::M>;
    /// An instance of the method.
    #[must_use]
    fn method() -> Self::Method;
}

/// Dimension marker, `D` = 2 or 3.
#[derive(Clone, Copy, Debug, Default)]
pub struct Dim<const D: usize>;

impl ReferenceDim for Dim<2> {
    type M = Mat<Dd, 2>;
    type Method = ClosedForm2;
    #[inline]
    fn method() -> ClosedForm2 {
        ClosedForm2
    }
}

impl ReferenceDim for Dim<3> {
    type M = Mat<Dd, 3>;
    type Method = OneSidedJacobi;
    #[inline]
    fn method() -> OneSidedJacobi {
        OneSidedJacobi {
            sweeps: REFERENCE_SWEEPS,
        }
    }
}

/// The reference quantities at one `F` (all in double-double).
#[derive(Clone, Copy, Debug)]
pub struct Reference<const D: usize>
where
    Mat<Dd, D>: Matrix,
{
    /// The rotation-variant SVD of `F`.
    pub svd: Svd<Mat<Dd, D>>,
    /// `R = U Vᵀ`.
    pub r: Mat<Dd, D>,
    /// `Ψ̂(F)`, `Â(F)`, `Ĉ(F):Z` for fixed corotated with the given `μ`; `None` when the
    /// kernels refuse `F` in double-double (`J ≤ 0`).
    pub kernels: Option<KernelRef<D>>,
}

/// The reference kernel values at one `F` with `J > 0` (each may still overflow `f64`).
#[derive(Clone, Copy, Debug)]
pub struct KernelRef<const D: usize> {
    /// `Ψ̂(F)`.
    pub psi: Result<Dd>,
    /// `Â(F)`.
    pub ahat: Result<Mat<Dd, D>>,
    /// `Ĉ(F):Z`.
    pub chat_z: Result<Mat<Dd, D>>,
    /// The singular values of `F̂ = Jᵃ F` (for the error scales).
    pub sigma_hat: [Dd; D],
}

/// The reference SVD of `f` (exact conversion to double-double, then the core's method).
///
/// # Errors
/// Those of the method (non-finite input).
pub fn svd<const D: usize>(f: &Mat<f64, D>) -> Result<Svd<Mat<Dd, D>>>
where
    Dim<D>: ReferenceDim<M = Mat<Dd, D>>,
    Mat<Dd, D>: Matrix,
{
    <Dim<D> as ReferenceDim>::method().svd(&to_dd(f))
}

/// All reference quantities at `f` (`μ > 0` and `Z` for the kernels).
///
/// When `J > 0` the SVD of `F` is taken from the kernels' SVD of `F̂ = Jᵃ F = 2ᵏ det(G)ᵃ G`
/// (same `U`, `V`; `σ(F) = 2ᵏ σ(F̂)/det(G)ᵃ`, one double-double division), which halves the
/// cost; otherwise it is computed directly.
///
/// # Errors
/// Those of the SVD (non-finite input).
pub fn reference<const D: usize>(mu: f64, f: &Mat<f64, D>, z: &Mat<f64, D>) -> Result<Reference<D>>
where
    Dim<D>: ReferenceDim<M = Mat<Dd, D>>,
    Mat<Dd, D>: Matrix<Scalar = Dd, Vector = [Dd; D]>,
{
    let fd = to_dd(f);
    let e = FixedCorotated::with_method(Dd::exact(mu), <Dim<D> as ReferenceDim>::method());
    if let Ok(st) = Augmented::new(&e, &fd) {
        if let Some((s_hat, _)) = st.base_state().svd {
            let kin = st.kinematics();
            let mut sigma = s_hat.sigma;
            for x in &mut sigma {
                *x = (*x / kin.ja_g).scalbn(kin.k);
            }
            let svd = Svd {
                u: s_hat.u,
                sigma,
                v: s_hat.v,
            };
            return Ok(Reference {
                svd,
                r: svd.rotation(),
                kernels: Some(KernelRef {
                    psi: st.psi_hat(),
                    ahat: st.ahat(),
                    chat_z: st.chat_z(&to_dd(z)),
                    sigma_hat: s_hat.sigma,
                }),
            });
        }
    }
    let svd = svd(f)?;
    Ok(Reference {
        svd,
        r: svd.rotation(),
        kernels: None,
    })
}
