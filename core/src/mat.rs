//! Fixed-size square matrices, column-major, generic over the scalar and the dimension.
//!
//! `Mat<T, D>` stores `cols[j][i] = M_ij`, so its memory is the column-major layout of glam,
//! Eigen and the C ABI (`M[i + D·j] = M_ij`). The dimension-specific operations (determinant,
//! cofactor matrix) live in the [`Matrix`] trait, implemented for `D = 2` and `D = 3`; kernels
//! are written once as `fn k<M: Matrix>(…)`.

use crate::scalar::Real;
use core::ops::{Add, AddAssign, Index, IndexMut, Mul, Neg, Sub, SubAssign};

/// A `D×D` matrix stored column-major: `cols[j][i]` is row `i`, column `j`.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C)]
pub struct Mat<T, const D: usize> {
    /// The columns.
    pub cols: [[T; D]; D],
}

// SAFETY: `Mat<T, D>` is `repr(C)` around `[[T; D]; D]` with `T: Pod`: no padding, any bit
// pattern valid.
unsafe impl<T: Real, const D: usize> bytemuck::Zeroable for Mat<T, D> {}
// SAFETY: see above.
unsafe impl<T: Real, const D: usize> bytemuck::Pod for Mat<T, D> {}

/// 2×2 matrix.
pub type Mat2<T> = Mat<T, 2>;
/// 3×3 matrix.
pub type Mat3<T> = Mat<T, 3>;

impl<T: Real, const D: usize> Mat<T, D> {
    /// The zero matrix.
    pub const ZERO: Self = Self {
        cols: [[T::ZERO; D]; D],
    };

    /// The identity matrix.
    #[inline]
    #[must_use]
    pub fn identity() -> Self {
        Self::from_diagonal([T::ONE; D])
    }

    /// Diagonal matrix from its diagonal.
    #[inline]
    #[must_use]
    pub fn from_diagonal(d: [T; D]) -> Self {
        let mut m = Self::ZERO;
        for (i, x) in d.into_iter().enumerate() {
            m.cols[i][i] = x;
        }
        m
    }

    /// Matrix from its columns.
    #[inline]
    #[must_use]
    pub const fn from_cols(cols: [[T; D]; D]) -> Self {
        Self { cols }
    }

    /// Matrix from rows (as written on paper).
    #[inline]
    #[must_use]
    pub fn from_rows(rows: [[T; D]; D]) -> Self {
        Self { cols: rows }.transpose()
    }

    /// Matrix from a column-major slice of at least `D·D` entries (`s[i + D·j] = M_ij`).
    ///
    /// Returns `None` when the slice is too short.
    #[inline]
    #[must_use]
    pub fn from_col_major(s: &[T]) -> Option<Self> {
        if s.len() < D * D {
            return None;
        }
        let mut m = Self::ZERO;
        for j in 0..D {
            for i in 0..D {
                m.cols[j][i] = s[i + D * j];
            }
        }
        Some(m)
    }

    /// Writes the matrix column-major into the first `D·D` entries of `s`.
    ///
    /// Returns `false` (writing nothing) when the slice is too short.
    #[inline]
    pub fn write_col_major(&self, s: &mut [T]) -> bool {
        if s.len() < D * D {
            return false;
        }
        for j in 0..D {
            for i in 0..D {
                s[i + D * j] = self.cols[j][i];
            }
        }
        true
    }

    /// Entry `(i, j)`.
    #[inline]
    #[must_use]
    pub fn get(&self, i: usize, j: usize) -> T {
        self.cols[j][i]
    }

    /// Transpose.
    #[inline]
    #[must_use]
    pub fn transpose(&self) -> Self {
        let mut t = Self::ZERO;
        for j in 0..D {
            for i in 0..D {
                t.cols[i][j] = self.cols[j][i];
            }
        }
        t
    }

    /// Trace.
    #[inline]
    #[must_use]
    pub fn trace(&self) -> T {
        let mut s = T::ZERO;
        for i in 0..D {
            s += self.cols[i][i];
        }
        s
    }

    /// Frobenius inner product `A : B = Σ A_ij B_ij`.
    #[inline]
    #[must_use]
    pub fn ddot(&self, o: &Self) -> T {
        let mut s = T::ZERO;
        for j in 0..D {
            for i in 0..D {
                s += self.cols[j][i] * o.cols[j][i];
            }
        }
        s
    }

    /// Squared Frobenius norm.
    #[inline]
    #[must_use]
    pub fn norm_squared(&self) -> T {
        self.ddot(self)
    }

    /// Largest absolute entry (max norm).
    #[inline]
    #[must_use]
    pub fn max_abs(&self) -> T {
        let mut m = T::ZERO;
        for j in 0..D {
            for i in 0..D {
                m = m.max(self.cols[j][i].abs());
            }
        }
        m
    }

    /// Entry-wise map.
    #[inline]
    #[must_use]
    pub fn map(&self, f: impl Fn(T) -> T) -> Self {
        let mut m = *self;
        for j in 0..D {
            for i in 0..D {
                m.cols[j][i] = f(m.cols[j][i]);
            }
        }
        m
    }

    /// True when every entry is finite.
    #[inline]
    #[must_use]
    pub fn is_finite(&self) -> bool {
        let mut ok = true;
        for j in 0..D {
            for i in 0..D {
                ok &= self.cols[j][i].is_finite();
            }
        }
        ok
    }

    /// Matrix–vector product.
    #[inline]
    #[must_use]
    pub fn mul_vec(&self, v: [T; D]) -> [T; D] {
        let mut r = [T::ZERO; D];
        for (col, vj) in self.cols.iter().zip(v) {
            for (ri, cij) in r.iter_mut().zip(col) {
                *ri += *cij * vj;
            }
        }
        r
    }

    /// Outer product `a bᵀ`.
    #[inline]
    #[must_use]
    pub fn outer(a: [T; D], b: [T; D]) -> Self {
        let mut m = Self::ZERO;
        for (col, bj) in m.cols.iter_mut().zip(b) {
            for (mij, ai) in col.iter_mut().zip(a) {
                *mij = ai * bj;
            }
        }
        m
    }

    /// Symmetric part `(M + Mᵀ)/2`.
    #[inline]
    #[must_use]
    pub fn sym(&self) -> Self {
        (*self + self.transpose()) * T::HALF
    }

    /// Converts the scalar type entry by entry (through `f64`).
    #[inline]
    #[must_use]
    pub fn cast<U: Real>(&self) -> Mat<U, D> {
        let mut m = Mat::<U, D>::ZERO;
        for j in 0..D {
            for i in 0..D {
                m.cols[j][i] = U::from_f64(self.cols[j][i].to_f64());
            }
        }
        m
    }
}

impl<T: Real, const D: usize> Index<(usize, usize)> for Mat<T, D> {
    type Output = T;
    #[inline]
    fn index(&self, (i, j): (usize, usize)) -> &T {
        &self.cols[j][i]
    }
}

impl<T: Real, const D: usize> IndexMut<(usize, usize)> for Mat<T, D> {
    #[inline]
    fn index_mut(&mut self, (i, j): (usize, usize)) -> &mut T {
        &mut self.cols[j][i]
    }
}

impl<T: Real, const D: usize> Add for Mat<T, D> {
    type Output = Self;
    #[inline]
    fn add(mut self, o: Self) -> Self {
        self += o;
        self
    }
}

impl<T: Real, const D: usize> AddAssign for Mat<T, D> {
    #[inline]
    fn add_assign(&mut self, o: Self) {
        for j in 0..D {
            for i in 0..D {
                self.cols[j][i] += o.cols[j][i];
            }
        }
    }
}

impl<T: Real, const D: usize> Sub for Mat<T, D> {
    type Output = Self;
    #[inline]
    fn sub(mut self, o: Self) -> Self {
        self -= o;
        self
    }
}

impl<T: Real, const D: usize> SubAssign for Mat<T, D> {
    #[inline]
    fn sub_assign(&mut self, o: Self) {
        for j in 0..D {
            for i in 0..D {
                self.cols[j][i] -= o.cols[j][i];
            }
        }
    }
}

impl<T: Real, const D: usize> Neg for Mat<T, D> {
    type Output = Self;
    #[inline]
    fn neg(self) -> Self {
        self.map(|x| -x)
    }
}

impl<T: Real, const D: usize> Mul<T> for Mat<T, D> {
    type Output = Self;
    #[inline]
    fn mul(self, s: T) -> Self {
        self.map(|x| x * s)
    }
}

impl<T: Real, const D: usize> Mul for Mat<T, D> {
    type Output = Self;
    #[inline]
    fn mul(self, o: Self) -> Self {
        let mut m = Self::ZERO;
        for j in 0..D {
            for k in 0..D {
                let b = o.cols[j][k];
                for i in 0..D {
                    m.cols[j][i] += self.cols[k][i] * b;
                }
            }
        }
        m
    }
}

/// The dimension-specific operations: implemented for `Mat<T, 2>` and `Mat<T, 3>`.
///
/// Kernels are generic over `M: Matrix`, so one source serves 2D/3D and f32/f64.
pub trait Matrix:
    Copy
    + core::fmt::Debug
    + PartialEq
    + Add<Output = Self>
    + Sub<Output = Self>
    + Neg<Output = Self>
    + Mul<Output = Self>
    + Mul<<Self as Matrix>::Scalar, Output = Self>
    + AddAssign
    + SubAssign
    + Index<(usize, usize), Output = <Self as Matrix>::Scalar>
    + IndexMut<(usize, usize)>
    + bytemuck::Pod
    + Send
    + Sync
    + 'static
{
    /// The scalar type.
    type Scalar: Real;
    /// The dimension `d` (2 or 3).
    const DIM: usize;
    /// Number of entries, `d²`.
    const LEN: usize;
    /// A column-major array of `d²` scalars (`[T; 4]` or `[T; 9]`).
    type Array: Copy + AsRef<[Self::Scalar]> + AsMut<[Self::Scalar]> + Default + core::fmt::Debug;
    /// A vector of `d` scalars (`[T; d]`).
    type Vector: Copy
        + AsRef<[Self::Scalar]>
        + AsMut<[Self::Scalar]>
        + Default
        + core::fmt::Debug
        + PartialEq
        + Index<usize, Output = Self::Scalar>
        + IndexMut<usize>;

    /// The zero matrix.
    #[must_use]
    fn zero() -> Self;
    /// The identity matrix.
    #[must_use]
    fn identity() -> Self;
    /// `s·I`.
    #[must_use]
    fn scaled_identity(s: Self::Scalar) -> Self;
    /// From a column-major array.
    #[must_use]
    fn from_array(a: &Self::Array) -> Self;
    /// To a column-major array.
    #[must_use]
    fn to_array(&self) -> Self::Array;
    /// Transpose.
    #[must_use]
    fn transpose(&self) -> Self;
    /// Trace.
    #[must_use]
    fn trace(&self) -> Self::Scalar;
    /// Frobenius inner product `A : B`.
    #[must_use]
    fn ddot(&self, o: &Self) -> Self::Scalar;
    /// Largest absolute entry.
    #[must_use]
    fn max_abs(&self) -> Self::Scalar;
    /// True when every entry is finite.
    #[must_use]
    fn is_finite(&self) -> bool;
    /// Determinant.
    #[must_use]
    fn det(&self) -> Self::Scalar;
    /// Cofactor matrix `cof(M) = det(M)·M⁻ᵀ` (defined for singular `M` too).
    #[must_use]
    fn cofactor(&self) -> Self;
    /// Entry-wise map.
    #[must_use]
    fn map(&self, f: impl Fn(Self::Scalar) -> Self::Scalar) -> Self;
    /// Diagonal matrix.
    #[must_use]
    fn from_diagonal(d: Self::Vector) -> Self;
    /// Matrix–vector product.
    #[must_use]
    fn mul_vec(&self, v: Self::Vector) -> Self::Vector;
    /// Outer product `a bᵀ`.
    #[must_use]
    fn outer(a: Self::Vector, b: Self::Vector) -> Self;
    /// Column `j`.
    #[must_use]
    fn col(&self, j: usize) -> Self::Vector;
}

macro_rules! impl_matrix_common {
    ($d:literal) => {
        type Scalar = T;
        const DIM: usize = $d;
        const LEN: usize = $d * $d;
        type Array = [T; $d * $d];
        type Vector = [T; $d];
        #[inline]
        fn from_diagonal(d: [T; $d]) -> Self {
            Mat::from_diagonal(d)
        }
        #[inline]
        fn mul_vec(&self, v: [T; $d]) -> [T; $d] {
            Mat::mul_vec(self, v)
        }
        #[inline]
        fn outer(a: [T; $d], b: [T; $d]) -> Self {
            Mat::outer(a, b)
        }
        #[inline]
        fn col(&self, j: usize) -> [T; $d] {
            self.cols[j]
        }
        #[inline]
        fn zero() -> Self {
            Self::ZERO
        }
        #[inline]
        fn identity() -> Self {
            Mat::identity()
        }
        #[inline]
        fn scaled_identity(s: T) -> Self {
            Mat::from_diagonal([s; $d])
        }
        #[inline]
        fn from_array(a: &Self::Array) -> Self {
            bytemuck::cast(*a)
        }
        #[inline]
        fn to_array(&self) -> Self::Array {
            bytemuck::cast(*self)
        }
        #[inline]
        fn transpose(&self) -> Self {
            Mat::transpose(self)
        }
        #[inline]
        fn trace(&self) -> T {
            Mat::trace(self)
        }
        #[inline]
        fn ddot(&self, o: &Self) -> T {
            Mat::ddot(self, o)
        }
        #[inline]
        fn max_abs(&self) -> T {
            Mat::max_abs(self)
        }
        #[inline]
        fn is_finite(&self) -> bool {
            Mat::is_finite(self)
        }
        #[inline]
        fn map(&self, f: impl Fn(T) -> T) -> Self {
            Mat::map(self, f)
        }
    };
}

impl<T: Real> Matrix for Mat<T, 2> {
    impl_matrix_common!(2);
    #[inline]
    fn det(&self) -> T {
        let m = &self.cols;
        m[0][0] * m[1][1] - m[1][0] * m[0][1]
    }
    #[inline]
    fn cofactor(&self) -> Self {
        let m = &self.cols;
        // cof(M)_ij = (-1)^{i+j} minor_ij; in 2D: [[m11, -m10], [-m01, m00]].
        Mat::from_cols([[m[1][1], -m[1][0]], [-m[0][1], m[0][0]]])
    }
}

impl<T: Real> Matrix for Mat<T, 3> {
    impl_matrix_common!(3);
    #[inline]
    fn det(&self) -> T {
        // det = c0 · (c1 × c2)
        let c = &self.cols;
        let x = cross(c[1], c[2]);
        c[0][0] * x[0] + c[0][1] * x[1] + c[0][2] * x[2]
    }
    #[inline]
    fn cofactor(&self) -> Self {
        // The columns of cof(M) are the cross products of pairs of columns of M:
        // cof(M) = [c1×c2, c2×c0, c0×c1], because M ᵀ cof(M) = det(M) I.
        let c = &self.cols;
        Mat::from_cols([cross(c[1], c[2]), cross(c[2], c[0]), cross(c[0], c[1])])
    }
}

/// Cross product of 3-vectors.
#[inline]
#[must_use]
pub fn cross<T: Real>(a: [T; 3], b: [T; 3]) -> [T; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

macro_rules! glam_conv {
    ($g:ty, $t:ty, $d:literal) => {
        impl From<$g> for Mat<$t, $d> {
            #[inline]
            fn from(m: $g) -> Self {
                <Self as Matrix>::from_array(&m.to_cols_array())
            }
        }
        impl From<Mat<$t, $d>> for $g {
            #[inline]
            fn from(m: Mat<$t, $d>) -> Self {
                <$g>::from_cols_array(&Matrix::to_array(&m))
            }
        }
    };
}
glam_conv!(glam::Mat2, f32, 2);
glam_conv!(glam::Mat3, f32, 3);
glam_conv!(glam::DMat2, f64, 2);
glam_conv!(glam::DMat3, f64, 3);
