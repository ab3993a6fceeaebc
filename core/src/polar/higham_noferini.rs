//! Polar-only method: Higham–Noferini 2016 (dominant eigenvector of a 4×4 symmetric matrix).
//!
//! Source: N. J. Higham, V. Noferini, "An algorithm to compute the polar decomposition of a
//! 3×3 matrix", Numer. Algorithms 73 (2016) 349–369, §2–§3. For `q = (w, x, y, z)` a unit
//! quaternion and `R(q)` its rotation (below), `tr(R(q)ᵀ F) = qᵀ B q` with the symmetric
//! trace-free
//!
//! ```text
//!     ⎡ F₀₀+F₁₁+F₂₂   F₂₁−F₁₂       F₀₂−F₂₀       F₁₀−F₀₁     ⎤
//! B = ⎢ F₂₁−F₁₂       F₀₀−F₁₁−F₂₂   F₀₁+F₁₀       F₀₂+F₂₀     ⎥
//!     ⎢ F₀₂−F₂₀       F₀₁+F₁₀       F₁₁−F₀₀−F₂₂   F₁₂+F₂₁     ⎥
//!     ⎣ F₁₀−F₀₁       F₀₂+F₂₀       F₁₂+F₂₁       F₂₂−F₀₀−F₁₁ ⎦
//! ```
//!
//! (the paper's (2.3) with its `q` conjugated, i.e. written for `R` instead of `Rᵀ`; each entry
//! is the coefficient of `qᵢqⱼ` in `Σ R(q)_ij F_ij`). So the rotation maximising
//! `tr(RᵀF)` over SO(3) — which is exactly `R = U Vᵀ` of the rotation-variant SVD, for
//! `det F < 0` too — comes from the eigenvector of the *largest* eigenvalue of `B`. The paper
//! negates `F` when `det F < 0` to get the orthogonal polar factor in O(3); that step is left
//! out on purpose, which gives the SO(3) factor of the rotation-variant convention.
//!
//! The eigenvalues of `B` are `σ₀+σ₁+σ₂`, `σ₀−σ₁−σ₂`, `σ₁−σ₀−σ₂`, `σ₂−σ₀−σ₁` (signed,
//! rotation-variant `σ`), so the gap below the dominant one is `2(σ₁+σ₂)`.
//!
//! **Eigen-solver chosen.** The paper finds `λ_max` from the characteristic quartic (closed
//! form plus Newton) and the eigenvector from an `LDLᵀ` factorisation of `λI − B` with
//! complete pivoting. Here both come from a cyclic Jacobi iteration on `B` (Golub & Van Loan,
//! *Matrix Computations*, 4th ed., §8.5.2–8.5.3): unconditionally convergent and backward
//! stable, so the eigenvector has the error `O(ε‖B‖/gap) = O(ε‖F‖/(σ₁+σ₂))` that the
//! conditioning allows, with no special cases for nearly repeated or zero eigenvalues — at the
//! price of speed: at most 6 sweeps of 6 rotations on the 4×4 were needed over every family of
//! `tools/src/families/` (4 suffice for all but ~10 % in f64), then a 3×3 Jacobi for `V`;
//! about twice the time of one-sided Jacobi.
//!
//! **Then Σ and V** (so that the method serves the fixed corotated energy, which needs `σᵢ` and
//! `V` for `δR`): `S = sym(RᵀF)` is diagonalised by the same Jacobi iteration (3×3),
//! `U = R V`, and [`super::qr_svd::rotation_variant`] sorts and fixes the signs.
//!
//! **Where it fails.** Near the kink `σ₁ + σ₂ → 0` (only for `det F < 0`) the two largest
//! eigenvalues of `B` tie, and `R` is only determined to `O(ε‖F‖/(σ₁+σ₂))` — the conditioning
//! of the rotation-variant `R` itself, so no method does better in the same precision; when
//! they tie exactly any rotation in the eigenplane is returned (finite, but not `UVᵀ` of any
//! particular SVD). `V` has error `O(ε‖F‖/|σᵢ − σⱼ|)` (eigenvectors of `S`), which only mixes
//! columns within a cluster of nearly equal `σ` and does not affect `R` or `Σ`. The sweep cap
//! ([`HighamNoferini::max_sweeps`]) gives [`Error::NotConverged`] if reached with an
//! off-diagonal entry still above `ε‖·‖_F`; Jacobi's quadratic convergence makes that
//! unobserved with the default cap.

use super::qr_svd::rotation_variant;
use super::{scale_exponent, scale_pow2, Svd, SvdMethod};
use crate::error::{Error, Result};
use crate::mat::Mat;
use crate::scalar::Real;

/// Higham–Noferini 2016 polar decomposition (3D), completed to an SVD.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct HighamNoferini {
    /// Cap on the Jacobi sweeps of each of the two symmetric eigenproblems (4×4 and 3×3).
    pub max_sweeps: u32,
}

impl Default for HighamNoferini {
    /// 16 sweeps: Jacobi converges quadratically; 6 is the largest count observed.
    fn default() -> Self {
        Self { max_sweeps: 16 }
    }
}

/// Cyclic Jacobi eigendecomposition of the symmetric `N×N` matrix `a` (`a[j][i] = A_ij`).
///
/// Returns the eigenvalues (unsorted) and the eigenvectors as the columns of a rotation
/// (`det = +1`: the product of Jacobi rotations). Pairs with `|A_pq| ≤ ε‖A‖_F` are skipped;
/// the iteration stops after a sweep without rotation, or fails with
/// [`Error::NotConverged`] after `max_sweeps`. Rotation: Rutishauser's stable form (GVL
/// Alg. 8.5.1, `sym.schur2`): `τ = (A_qq − A_pp)/(2A_pq)`, `t = sgn τ/(|τ| + √(1+τ²))`,
/// `c = 1/√(1+t²)`, `s = t c`; `A ← JᵀAJ`, `V ← VJ`.
#[inline]
pub(crate) fn sym_jacobi<T: Real, const N: usize>(
    mut a: [[T; N]; N],
    max_sweeps: u32,
) -> Result<([T; N], [[T; N]; N])> {
    let mut v = [[T::ZERO; N]; N];
    let mut norm2 = T::ZERO;
    for (j, col) in a.iter().enumerate() {
        v[j][j] = T::ONE;
        for x in col {
            norm2 += *x * *x;
        }
    }
    let thr = T::EPSILON * norm2.sqrt();
    let mut converged = false;
    for _ in 0..max_sweeps {
        let mut rotated = false;
        for p in 0..N {
            for q in p + 1..N {
                let apq = a[q][p];
                if apq.abs() <= thr {
                    continue;
                }
                rotated = true;
                // |τ| ≤ ‖A‖/(ε‖A‖) = 1/ε, so τ² cannot overflow.
                let tau = (a[q][q] - a[p][p]) / (apq + apq);
                let t = T::ONE.copysign(tau) / (tau.abs() + (T::ONE + tau * tau).sqrt());
                let c = T::ONE / (T::ONE + t * t).sqrt();
                let s = t * c;
                a[p][p] -= t * apq;
                a[q][q] += t * apq;
                a[q][p] = T::ZERO;
                a[p][q] = T::ZERO;
                for r in 0..N {
                    if r != p && r != q {
                        let (arp, arq) = (a[p][r], a[q][r]);
                        let (np, nq) = (c * arp - s * arq, s * arp + c * arq);
                        a[p][r] = np;
                        a[r][p] = np;
                        a[q][r] = nq;
                        a[r][q] = nq;
                    }
                    let (vp, vq) = (v[p][r], v[q][r]);
                    v[p][r] = c * vp - s * vq;
                    v[q][r] = s * vp + c * vq;
                }
            }
        }
        if !rotated {
            converged = true;
            break;
        }
    }
    if !converged {
        // The last sweep rotated: accept if every off-diagonal entry is below the threshold.
        let off = |p: usize| a[p + 1..].iter().any(|aq| aq[p].abs() > thr);
        if (0..N).any(off) {
            return Err(Error::NotConverged);
        }
    }
    let mut d = [T::ZERO; N];
    for (i, x) in d.iter_mut().enumerate() {
        *x = a[i][i];
    }
    Ok((d, v))
}

/// The rotation of the unit quaternion `(w, x, y, z)` (normalised here).
#[inline]
fn quat_to_rot<T: Real>(q: [T; 4]) -> Mat<T, 3> {
    let n2 = q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3];
    let inv = T::ONE / n2.sqrt();
    let [w, x, y, z] = [q[0] * inv, q[1] * inv, q[2] * inv, q[3] * inv];
    let two = T::TWO;
    Mat::from_rows([
        [
            w * w + x * x - y * y - z * z,
            two * (x * y - w * z),
            two * (x * z + w * y),
        ],
        [
            two * (x * y + w * z),
            w * w - x * x + y * y - z * z,
            two * (y * z - w * x),
        ],
        [
            two * (x * z - w * y),
            two * (y * z + w * x),
            w * w - x * x - y * y + z * z,
        ],
    ])
}

/// The 4×4 matrix `B` of the module docs, column-major (`b[j][i] = B_ij`; symmetric).
#[inline]
fn quaternion_matrix<T: Real>(f: &Mat<T, 3>) -> [[T; 4]; 4] {
    let m = |i: usize, j: usize| f[(i, j)];
    let (b00, b11, b22) = (m(0, 0), m(1, 1), m(2, 2));
    let d0 = b00 + b11 + b22;
    let d1 = b00 - b11 - b22;
    let d2 = b11 - b00 - b22;
    let d3 = b22 - b00 - b11;
    let b01 = m(2, 1) - m(1, 2);
    let b02 = m(0, 2) - m(2, 0);
    let b03 = m(1, 0) - m(0, 1);
    let b12 = m(0, 1) + m(1, 0);
    let b13 = m(0, 2) + m(2, 0);
    let b23 = m(1, 2) + m(2, 1);
    [
        [d0, b01, b02, b03],
        [b01, d1, b12, b13],
        [b02, b12, d2, b23],
        [b03, b13, b23, d3],
    ]
}

impl<T: Real> SvdMethod<Mat<T, 3>> for HighamNoferini {
    const NAME: &'static str = "higham-noferini";

    fn svd(&self, f0: &Mat<T, 3>) -> Result<Svd<Mat<T, 3>>> {
        if !f0.is_finite() {
            return Err(Error::NonFinite);
        }
        let k = scale_exponent(f0);
        let g = scale_pow2(f0, -k);
        // R from the dominant eigenvector of B.
        let (lam, vecs) = sym_jacobi(quaternion_matrix(&g), self.max_sweeps)?;
        let mut imax = 0;
        for i in 1..4 {
            if lam[i] > lam[imax] {
                imax = i;
            }
        }
        let r = quat_to_rot(vecs[imax]);
        // S = sym(RᵀG) = V Σ Vᵀ.
        let s = (r.transpose() * g).sym();
        let (sigma, v) = sym_jacobi(s.cols, self.max_sweeps)?;
        let v = Mat::from_cols(v);
        let svd = rotation_variant(r * v, sigma, v);
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
