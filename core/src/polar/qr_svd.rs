//! Implicit-shifted QR SVD on `F` itself (Gast, Fu, Jiang, Teran 2016).
//!
//! Source: T. F. Gast, C. Fu, C. Jiang, J. Teran, "Implicit-shifted Symmetric QR Singular Value
//! Decomposition of 3×3 Matrices", UCLA CAM report 16-19 (2016):
//! - §2 (bidiagonalisation): Givens rotations from the left zero `F₁₀`, `F₂₀`, one from the
//!   right zeroes `F₀₂`, a last one from the left zeroes `F₂₁`, giving `F = U B Vᵀ` with `B`
//!   upper bidiagonal (`α₀, α₁, α₂` on the diagonal, `β₀ = B₀₁`, `β₁ = B₁₂`) and `U, V ∈ SO(3)`
//!   by construction (products of rotations).
//! - §3 (implicit symmetric QR on `BᵀB` without forming it): Wilkinson shift `μ` = the
//!   eigenvalue of the trailing 2×2 block of `BᵀB` closer to its last entry, then the
//!   Golub–Kahan bulge chase (Golub & Van Loan, *Matrix Computations*, 4th ed., Alg. 8.6.1)
//!   with four Givens rotations per sweep.
//! - §3.1 (deflation): when `|β₁|` or `|β₀|` is below the tolerance the problem splits into a
//!   1×1 and a 2×2 block; the 2×2 block is solved in closed form (here by [`ClosedForm2`], the
//!   same polar-based construction as the paper's §4; a negligible `β` of that block is
//!   deflated first, so the closed form never squares an off-diagonal that is tiny relative to
//!   its block). When a diagonal `|αᵢ|` is below the tolerance it is set to zero and its row
//!   (or, for `α₂`, its column) is chased out with two Givens rotations (Golub & Van Loan
//!   §8.6.2), which makes a `β` exactly zero.
//! - §5 (sign and order): the rotation-variant convention of [`crate::polar`] by
//!   [`rotation_variant`].
//!
//! **Tolerance.** The paper deflates when `|β| ≤ τ·max(‖B‖/2, 1)`, an absolute floor of `τ`
//! that silently drops singular values below `τ` when `‖F‖ ≪ 1`. Here `F` is first scaled by
//! an exact power of two so its largest entry lies in `[0.5, 1)` ([`scale_exponent`]), and the
//! tolerance is `ε·‖G‖_F` for the scaled `G`: purely relative to `‖F‖`. Setting an entry of
//! size `≤ ε‖G‖_F` to zero is a backward error of the same size as one rounding of `G`, so the
//! singular values keep absolute error `O(ε‖F‖)` and `R` the error `O(ε‖F‖/(σᵢ+σⱼ))` (polar
//! perturbation bound `‖ΔR‖_F ≤ 2‖ΔF‖_F/(σ_{d−1}+σ_d)`, R.-C. Li 1995), whatever the scale.
//!
//! **Iteration cap.** Each sweep reduces the last off-diagonal `β₁` cubically once it is small
//! (Wilkinson shift): over every family of `tools/src/families/` (about 30 000 matrices per
//! precision) the largest number of sweeps needed is 6 in f64 and 5 in f32, against the
//! default cap of 32. The method returns
//! [`Error::NotConverged`] only if both `β` are still above the tolerance after
//! `max_iterations` sweeps (it has never been observed; the shifted QR iteration is globally
//! convergent for symmetric tridiagonal `BᵀB`, Wilkinson 1968).

use super::{scale_exponent, scale_pow2, ClosedForm2, Svd, SvdMethod};
use crate::error::{Error, Result};
use crate::mat::Mat;
use crate::scalar::Real;

/// Implicit-shifted QR SVD of a 3×3 matrix (Gast et al. 2016), with an iteration cap.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct QrSvd {
    /// Maximum number of implicit QR sweeps (each four Givens rotations) before
    /// [`Error::NotConverged`]; 0 allows none (the input must then deflate at once).
    pub max_iterations: u32,
}

impl Default for QrSvd {
    /// 32 sweeps: five times the largest count observed (6, f64).
    fn default() -> Self {
        Self { max_iterations: 32 }
    }
}

/// `√(x² + y²)` without spurious underflow: below `MIN_POSITIVE^¼` (`2⁻²⁵⁵` in f64, `2⁻³¹` in
/// f32) the operands are first scaled by an exact power of two (their squares would be
/// subnormal or zero). Above it the direct formula is exact enough and cheaper than
/// `libm::hypot`; after the pre-scaling every operand is `O(1)`, so it cannot overflow.
#[inline]
fn norm2<T: Real>(x: T, y: T) -> T {
    let (xs, ys, e) = unit_scale(x, y);
    (xs * xs + ys * ys).sqrt().scalbn(e)
}

/// `(x·2⁻ᵉ, y·2⁻ᵉ, e)`, exact, with `e = 0` unless `max(|x|, |y|)` is below `MIN_POSITIVE^¼`,
/// where `e` brings the larger to `[0.5, 1)`.
#[inline]
fn unit_scale<T: Real>(x: T, y: T) -> (T, T, i32) {
    let m = x.abs().max(y.abs());
    if m >= T::MIN_POSITIVE.sqrt().sqrt() || m == T::ZERO {
        (x, y, 0)
    } else {
        let e = m.exponent();
        (x.scalbn(-e), y.scalbn(-e), e)
    }
}

/// Givens pair `(c, s)` with `c x + s y = r`, `−s x + c y = 0`, `c² + s² = 1`. `c` and `s`
/// are formed from the scaled operands, so they stay accurate (and the rotation orthogonal)
/// when `x`, `y` are subnormal.
#[inline]
fn givens<T: Real>(x: T, y: T) -> (T, T) {
    let (xs, ys, _) = unit_scale(x, y);
    let r = (xs * xs + ys * ys).sqrt();
    if r == T::ZERO {
        (T::ONE, T::ZERO)
    } else {
        (xs / r, ys / r)
    }
}

/// Rows `i`, `k` of `m` ← `[[c, s], [−s, c]]` · (rows `i`, `k`). With `(c, s)` from
/// [`givens`] of `(m_ij, m_kj)` this zeroes `m_kj`.
#[inline]
fn rot_rows<T: Real>(m: &mut Mat<T, 3>, i: usize, k: usize, c: T, s: T) {
    for j in 0..3 {
        let (x, y) = (m[(i, j)], m[(k, j)]);
        m[(i, j)] = c * x + s * y;
        m[(k, j)] = c * y - s * x;
    }
}

/// Columns `i`, `k` of `m` ← (columns `i`, `k`) · `[[c, −s], [s, c]]`. With `(c, s)` from
/// [`givens`] of `(m_ri, m_rk)` this zeroes `m_rk`. Applying a row rotation to `B` in
/// `F = U B Vᵀ` is compensated by the same column rotation of `U` (`U Gᵀ G B`), a column
/// rotation of `B` by the same column rotation of `V`.
#[inline]
fn rot_cols<T: Real>(m: &mut Mat<T, 3>, i: usize, k: usize, c: T, s: T) {
    for r in 0..3 {
        let (x, y) = (m[(r, i)], m[(r, k)]);
        m[(r, i)] = c * x + s * y;
        m[(r, k)] = c * y - s * x;
    }
}

/// `B`, `U`, `V` of `F = U B Vᵀ` during the iteration.
struct State<T: Real> {
    b: Mat<T, 3>,
    u: Mat<T, 3>,
    v: Mat<T, 3>,
}

impl<T: Real> State<T> {
    /// Left rotation zeroing `b_kj` against `b_ij`.
    #[inline]
    fn left(&mut self, i: usize, k: usize, j: usize) {
        let (c, s) = givens(self.b[(i, j)], self.b[(k, j)]);
        rot_rows(&mut self.b, i, k, c, s);
        rot_cols(&mut self.u, i, k, c, s);
        self.b[(k, j)] = T::ZERO;
    }

    /// Right rotation zeroing `b_rk` against `b_ri`.
    #[inline]
    fn right(&mut self, i: usize, k: usize, r: usize) {
        let (c, s) = givens(self.b[(r, i)], self.b[(r, k)]);
        rot_cols(&mut self.b, i, k, c, s);
        rot_cols(&mut self.v, i, k, c, s);
        self.b[(r, k)] = T::ZERO;
    }

    /// Sets the entries below the diagonal and `b₀₂` to their structural zero.
    #[inline]
    fn clean(&mut self) {
        self.b[(1, 0)] = T::ZERO;
        self.b[(2, 0)] = T::ZERO;
        self.b[(2, 1)] = T::ZERO;
        self.b[(0, 2)] = T::ZERO;
    }

    /// One Golub–Kahan SVD step with Wilkinson shift (Gast et al. §3; GVL Alg. 8.6.1).
    #[inline]
    fn qr_sweep(&mut self) {
        let b = &self.b;
        let (a0, a1, a2) = (b[(0, 0)], b[(1, 1)], b[(2, 2)]);
        let (b0, b1) = (b[(0, 1)], b[(1, 2)]);
        // Trailing 2×2 block of T = BᵀB: [[a1² + b0², a1 b1], [a1 b1, a2² + b1²]].
        let t11 = a1 * a1 + b0 * b0;
        let t22 = a2 * a2 + b1 * b1;
        let t12 = a1 * b1;
        // Wilkinson shift: μ = t22 − t12² / (d + sign(d)·√(d² + t12²)), d = (t11 − t22)/2.
        let d = (t11 - t22) * T::HALF;
        let den = d + norm2(d, t12).copysign(d);
        let mu = if den == T::ZERO {
            t22
        } else {
            t22 - t12 * t12 / den
        };
        // First rotation from the first column of T − μI: (a0² − μ, a0 b0).
        let (c, s) = givens(a0 * a0 - mu, a0 * b0);
        rot_cols(&mut self.b, 0, 1, c, s);
        rot_cols(&mut self.v, 0, 1, c, s);
        // Chase the bulge: b10, then b02, then b21.
        self.left(0, 1, 0);
        self.right(1, 2, 0);
        self.left(1, 2, 1);
        self.clean();
    }

    /// `α₀ ≈ 0`: chase `β₀` out of row 0 with left rotations against rows 1 and 2.
    #[inline]
    fn chase_row0(&mut self) {
        self.b[(0, 0)] = T::ZERO;
        // Zero b01 against b11 (rotation of rows 1, 0), fill-in at b02.
        self.left(1, 0, 1);
        // Zero b02 against b22.
        self.left(2, 0, 2);
        self.clean();
        self.b[(0, 1)] = T::ZERO;
    }

    /// `α₁ ≈ 0`: chase `β₁` out of row 1 with a left rotation against row 2.
    #[inline]
    fn chase_row1(&mut self) {
        self.b[(1, 1)] = T::ZERO;
        self.left(2, 1, 2);
        self.clean();
    }

    /// `α₂ ≈ 0`: chase `β₁` out of column 2 with right rotations against columns 1 and 0.
    #[inline]
    fn chase_col2(&mut self) {
        self.b[(2, 2)] = T::ZERO;
        // Zero b12 against b11 (columns 1, 2), fill-in at b02.
        self.right(1, 2, 1);
        // Zero b02 against b00 (columns 0, 2).
        self.right(0, 2, 0);
        self.clean();
        self.b[(1, 2)] = T::ZERO;
    }

    /// Deflated: the 2×2 block at `(p, p+1)` by [`ClosedForm2`], the 1×1 block `q` as is.
    #[inline]
    fn finish(self, p: usize, q: usize) -> Result<Svd<Mat<T, 3>>> {
        let b = &self.b;
        let m2 = Mat::<T, 2>::from_cols([
            [b[(p, p)], b[(p + 1, p)]],
            [b[(p, p + 1)], b[(p + 1, p + 1)]],
        ]);
        let s2 = ClosedForm2.svd(&m2)?;
        let embed = |r: &Mat<T, 2>| {
            let mut m = Mat::<T, 3>::identity();
            for j in 0..2 {
                for i in 0..2 {
                    m[(p + i, p + j)] = r[(i, j)];
                }
            }
            m
        };
        let mut sigma = [T::ZERO; 3];
        sigma[p] = s2.sigma[0];
        sigma[p + 1] = s2.sigma[1];
        sigma[q] = b[(q, q)];
        Ok(rotation_variant(
            self.u * embed(&s2.u),
            sigma,
            self.v * embed(&s2.v),
        ))
    }
}

/// Puts `F = U diag(σ) Vᵀ` (`U, V ∈ SO(3)`, `σ` of any signs and order) into the
/// rotation-variant convention of [`crate::polar`]: sorted by decreasing `|σᵢ|`, all `σᵢ ≥ 0`
/// except possibly the last.
///
/// Negative values are made positive in pairs by negating the two matching columns of `U`
/// (`det U` unchanged); a swap of two entries swaps the columns of `U` and `V` and negates one
/// column of each (both determinants unchanged, the product unchanged); a single remaining
/// negative value moves its sign to the smallest entry (negating two columns of `U` again).
#[inline]
#[must_use]
pub(crate) fn rotation_variant<T: Real>(
    u: Mat<T, 3>,
    mut sigma: [T; 3],
    v: Mat<T, 3>,
) -> Svd<Mat<T, 3>> {
    let (mut u, mut v) = (u.cols, v.cols);
    let neg = |c: &mut [T; 3]| {
        for x in c.iter_mut() {
            *x = -*x;
        }
    };
    // Pair up negative values.
    for (i, j) in [(0usize, 1usize), (0, 2), (1, 2)] {
        if sigma[i] < T::ZERO && sigma[j] < T::ZERO {
            sigma[i] = -sigma[i];
            sigma[j] = -sigma[j];
            neg(&mut u[i]);
            neg(&mut u[j]);
        }
    }
    // Sort by decreasing magnitude (three compare-swaps).
    for (p, q) in [(0usize, 1usize), (1, 2), (0, 1)] {
        if sigma[q].abs() > sigma[p].abs() {
            sigma.swap(p, q);
            u.swap(p, q);
            v.swap(p, q);
            neg(&mut u[q]);
            neg(&mut v[q]);
        }
    }
    // At most one negative value is left; move its sign to the last (smallest) one.
    for i in 0..2 {
        if sigma[i] < T::ZERO {
            sigma[i] = -sigma[i];
            sigma[2] = -sigma[2];
            neg(&mut u[i]);
            neg(&mut u[2]);
        }
    }
    Svd {
        u: Mat::from_cols(u),
        sigma,
        v: Mat::from_cols(v),
    }
}

impl<T: Real> SvdMethod<Mat<T, 3>> for QrSvd {
    const NAME: &'static str = "qr";

    fn svd(&self, f0: &Mat<T, 3>) -> Result<Svd<Mat<T, 3>>> {
        if !f0.is_finite() {
            return Err(Error::NonFinite);
        }
        let k = scale_exponent(f0);
        let g = scale_pow2(f0, -k);
        let tol = T::EPSILON * g.norm_squared().sqrt();
        let id = Mat::<T, 3>::identity();
        let mut st = State { b: g, u: id, v: id };
        // §2: bidiagonalisation.
        st.left(0, 1, 0);
        st.left(0, 2, 0);
        st.right(1, 2, 0);
        st.left(1, 2, 1);
        st.clean();
        let mut sweeps = 0u32;
        let svd = loop {
            let b = &st.b;
            if b[(1, 2)].abs() <= tol {
                st.b[(1, 2)] = T::ZERO;
                // A negligible β₀ is deflated too (the same backward error, ≤ ε‖G‖, as one
                // rounding of G) instead of being left to the 2×2 closed form, which would
                // square an off-diagonal of relative size below √MIN_POSITIVE into the
                // subnormal range. The norms it takes of the block [[α₀, β₀], [0, α₁]],
                // σ₀ + σ₁ = ‖(α₀ + α₁, β₀)‖ and σ₀ − σ₁ = ‖(α₀ − α₁, β₀)‖, are ≥ |β₀| > ε‖G‖
                // for any β₀ kept, far above that range.
                if st.b[(0, 1)].abs() <= tol {
                    st.b[(0, 1)] = T::ZERO;
                }
                break st.finish(0, 2)?;
            }
            if b[(0, 1)].abs() <= tol {
                st.b[(0, 1)] = T::ZERO;
                break st.finish(1, 0)?;
            }
            // A negligible diagonal entry: chase its off-diagonal out (makes a β zero, so
            // the next pass deflates).
            if b[(0, 0)].abs() <= tol {
                st.chase_row0();
                continue;
            }
            if b[(1, 1)].abs() <= tol {
                st.chase_row1();
                continue;
            }
            if b[(2, 2)].abs() <= tol {
                st.chase_col2();
                continue;
            }
            if sweeps >= self.max_iterations {
                return Err(Error::NotConverged);
            }
            sweeps += 1;
            st.qr_sweep();
        };
        Ok(Svd {
            sigma: [
                svd.sigma[0].scalbn(k),
                svd.sigma[1].scalbn(k),
                svd.sigma[2].scalbn(k),
            ],
            ..svd
        })
    }
}
