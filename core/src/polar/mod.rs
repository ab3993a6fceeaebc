//! Singular value and polar decompositions in the rotation-variant convention.
//!
//! Convention (Irving, Teran, Fedkiw 2004; the one fixed corotated MPM codes use):
//! `F = U Σ Vᵀ` with `U, V ∈ SO(d)` (proper rotations), `|σ₀| ≥ |σ₁| ≥ … `, every `σᵢ ≥ 0`
//! except possibly the last, which carries the sign of `det F`. The polar decomposition is
//! `F = R S` with `R = U Vᵀ ∈ SO(d)` and `S = V Σ Vᵀ` symmetric (indefinite when `det F < 0`).
//!
//! Methods implement [`SvdMethod`]; the kernels are generic over it, so the choice is made
//! at compile time. [`DefaultSvd`] is a closed form in 2D and one-sided Jacobi in 3D.
//!
//! The methods (the C ABI selects among the same ones at run time, `ffi/src/methods.rs`):
//!
//! | method | dim | idea | accuracy (`κ = 2σ₀/min(σᵢ+σⱼ)`) |
//! |---|---|---|---|
//! | [`ClosedForm2`] | 2D | closed form, `R` from normalised `(F₀₀+F₁₁, F₁₀−F₀₁)` | `O(ε κ)` |
//! | [`OneSidedJacobi`] | 3D | Hestenes one-sided Jacobi on `F` | `O(ε κ)`, small `σ` to high relative accuracy |
//! | [`McAdams`] | 3D | branch-free Jacobi on `FᵀF`, approximate Givens, fixed sweeps | `O(ε κ²)` at best; sweep-limited |
//! | [`QrSvd`] | 3D | Gast et al. 2016 implicit-shifted QR on `F`, tolerance relative to `‖F‖` | `O(ε κ)` |
//! | [`HighamNoferini`] | 3D | dominant eigenvector of a 4×4 symmetric matrix (quaternion), then `eig(S)` | `O(ε κ)` |
//!
//! The measured errors per family of `F` are in `docs/stability-table.md` (`ampm-report`).

mod closed_form_2d;
mod higham_noferini;
pub mod lanes;
mod mcadams;
mod one_sided_jacobi;
mod qr_svd;

pub use closed_form_2d::{closed_form_2d, normalize2, ClosedForm2};
pub use higham_noferini::HighamNoferini;
pub use mcadams::McAdams;
pub use one_sided_jacobi::{one_sided_jacobi, OneSidedJacobi};
pub use qr_svd::QrSvd;

use crate::error::Result;
use crate::mat::{Mat, Matrix};
use crate::scalar::Real;

/// A singular value decomposition `F = U diag(σ) Vᵀ`, rotation-variant (see module docs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Svd<M: Matrix> {
    /// Left rotation, `det U = +1`.
    pub u: M,
    /// Singular values, sorted by decreasing magnitude; only the last may be negative.
    pub sigma: M::Vector,
    /// Right rotation, `det V = +1`.
    pub v: M,
}

impl<M: Matrix> Svd<M> {
    /// The rotation of the polar decomposition, `R = U Vᵀ`.
    #[inline]
    #[must_use]
    pub fn rotation(&self) -> M {
        self.u * self.v.transpose()
    }

    /// The symmetric factor of the polar decomposition, `S = V Σ Vᵀ`.
    #[inline]
    #[must_use]
    pub fn stretch(&self) -> M {
        self.v * M::from_diagonal(self.sigma) * self.v.transpose()
    }

    /// Reassembles `U Σ Vᵀ`.
    #[inline]
    #[must_use]
    pub fn reconstruct(&self) -> M {
        self.u * M::from_diagonal(self.sigma) * self.v.transpose()
    }
}

/// A polar decomposition `F = R S`, `R ∈ SO(d)`, `S` symmetric.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Polar<M: Matrix> {
    /// The rotation.
    pub r: M,
    /// The symmetric stretch.
    pub s: M,
}

/// A method computing the rotation-variant SVD of a `d×d` matrix.
///
/// Contract: for finite `F` the result is finite, `U` and `V` are rotations, the singular
/// values are sorted by magnitude with only the last possibly negative, and the method stops
/// after a bounded number of steps. Non-finite input gives [`crate::Error::NonFinite`].
pub trait SvdMethod<M: Matrix>: Copy + Default + core::fmt::Debug + Send + Sync + 'static {
    /// Short name for reports and charts.
    const NAME: &'static str;
    /// The decomposition of `f`.
    fn svd(&self, f: &M) -> Result<Svd<M>>;
}

/// The default method of each dimension: [`ClosedForm2`] in 2D, [`OneSidedJacobi`] in 3D.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct DefaultSvd;

impl<T: Real> SvdMethod<Mat<T, 2>> for DefaultSvd {
    const NAME: &'static str = "closed-form-2d";
    #[inline]
    fn svd(&self, f: &Mat<T, 2>) -> Result<Svd<Mat<T, 2>>> {
        ClosedForm2.svd(f)
    }
}

impl<T: Real> SvdMethod<Mat<T, 3>> for DefaultSvd {
    const NAME: &'static str = "one-sided-jacobi";
    #[inline]
    fn svd(&self, f: &Mat<T, 3>) -> Result<Svd<Mat<T, 3>>> {
        OneSidedJacobi::default().svd(f)
    }
}

/// The polar decomposition of `f` by the default method.
#[inline]
pub fn polar<M: Matrix>(f: &M) -> Result<Polar<M>>
where
    DefaultSvd: SvdMethod<M>,
{
    let svd = DefaultSvd.svd(f)?;
    Ok(Polar {
        r: svd.rotation(),
        s: svd.stretch(),
    })
}

/// Power-of-two exponent `k` such that `f · 2⁻ᵏ` has its largest entry in `[0.5, 1)`.
///
/// Scaling by a power of two is exact, so methods that pre-scale do not depend on absolute
/// thresholds and do not overflow when squaring entries.
#[inline]
#[must_use]
pub fn scale_exponent<M: Matrix>(f: &M) -> i32 {
    f.max_abs().exponent()
}

/// `f · 2ᵉ`, rounded once (exact unless an entry over- or underflows), for any `e`.
///
/// When `2ᵉ` is a normal number one multiplication per entry is exact; otherwise (|e| beyond
/// the exponent range, e.g. the `2⁻²ᵏ` of `Ĉ` for a subnormal `F`) each entry goes through
/// `scalbn`, so `0 · 2ᵉ = 0` and no `0 · inf = NaN` can appear.
#[inline]
#[must_use]
pub fn scale_pow2<M: Matrix>(f: &M, e: i32) -> M {
    let p = M::Scalar::ONE.scalbn(e);
    if p >= M::Scalar::MIN_POSITIVE && p.is_finite() {
        f.map(|x| x * p)
    } else {
        f.map(|x| x.scalbn(e))
    }
}
