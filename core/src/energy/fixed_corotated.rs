//! Fixed corotated elasticity, the deviatoric energy of Stomakhin et al. 2014, §4.
//!
//! `Ψ_μ(F) = μ‖F − R‖²_F = μ Σᵢ (σᵢ − 1)²`, `A = 2μ(F − R)`, `C:δF = 2μ(δF − δR)`,
//! with `R` the rotation of the rotation-variant polar decomposition (see [`crate::polar`]).
//!
//! `δR` in the SVD basis (one formula for 2D and 3D): with `Ũ = Uᵀ δF V`,
//! `δR = U W Vᵀ`, `W` skew, `W_ij = (Ũ_ij − Ũ_ji) / (σᵢ + σⱼ)`. Derivation: `F = RS` gives
//! `RᵀδF − (RᵀδF)ᵀ = WS + SW` with `W = RᵀδR`; in the basis of `V` this is
//! `(σᵢ + σⱼ) W_ij`. In 2D it is the seed's `ω = ((RᵀδF)₁₀ − (RᵀδF)₀₁)/tr S`; in 3D it equals
//! `R Ŝ(M − Mᵀ)Ŝ / det Ŝ`, `Ŝ = tr(S) I − S`, without forming `det Ŝ`, whose absolute
//! rounding error would swamp a small `σᵢ + σⱼ`. The formula breaks where `σᵢ + σⱼ → 0`
//! (the kink; only reachable for `det F ≤ 0`, which the augmented wrapper refuses).

use super::BaseEnergy;
use crate::error::{Error, Result};
use crate::mat::Matrix;
use crate::polar::{DefaultSvd, Svd, SvdMethod};
use crate::scalar::Real;

/// Fixed corotated energy with shear modulus-like parameter `μ` (units of stress, Pa),
/// using the SVD method `S` (chosen at compile time).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FixedCorotated<T, S = DefaultSvd> {
    /// `μ ≥ 0`. `μ = 0` (a liquid) skips the decomposition entirely.
    pub mu: T,
    /// The SVD method.
    pub method: S,
}

impl<T: Real> FixedCorotated<T, DefaultSvd> {
    /// Fixed corotated energy with the default SVD method.
    #[inline]
    #[must_use]
    pub fn new(mu: T) -> Self {
        Self {
            mu,
            method: DefaultSvd,
        }
    }
}

impl<T: Real, S> FixedCorotated<T, S> {
    /// Fixed corotated energy with an explicit SVD method.
    #[inline]
    #[must_use]
    pub fn with_method(mu: T, method: S) -> Self {
        Self { mu, method }
    }
}

/// What fixed corotated shares at one `F`: its SVD and rotation (`None` when `μ = 0`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FixedCorotatedState<M: Matrix> {
    /// The SVD and `R = U Vᵀ`, absent when `μ = 0`.
    pub svd: Option<(Svd<M>, M)>,
}

/// `δR`, the differential of the polar rotation of `F = U Σ Vᵀ` in direction `df`.
///
/// Requires `σᵢ + σⱼ ≠ 0` for all `i < j`; true whenever `det F > 0`.
#[inline]
#[must_use]
pub fn d_rotation<M: Matrix>(svd: &Svd<M>, df: &M) -> M {
    let ut = svd.u.transpose() * *df * svd.v;
    let mut w = M::zero();
    for j in 1..M::DIM {
        for i in 0..j {
            let x = (ut[(i, j)] - ut[(j, i)]) / (svd.sigma[i] + svd.sigma[j]);
            w[(i, j)] = x;
            w[(j, i)] = -x;
        }
    }
    svd.u * w * svd.v.transpose()
}

impl<M, S> BaseEnergy<M> for FixedCorotated<M::Scalar, S>
where
    M: Matrix,
    S: SvdMethod<M>,
{
    type State = FixedCorotatedState<M>;

    #[inline]
    fn prepare(&self, f: &M) -> Result<Self::State> {
        if !self.mu.is_finite() {
            return Err(Error::NonFinite);
        }
        if self.mu < M::Scalar::ZERO {
            return Err(Error::InvalidArgument);
        }
        if self.mu == M::Scalar::ZERO {
            return Ok(FixedCorotatedState { svd: None });
        }
        let svd = self.method.svd(f)?;
        let r = svd.rotation();
        Ok(FixedCorotatedState {
            svd: Some((svd, r)),
        })
    }

    #[inline]
    fn psi(&self, _f: &M, st: &Self::State) -> M::Scalar {
        match &st.svd {
            None => M::Scalar::ZERO,
            Some((svd, _)) => {
                let mut s = M::Scalar::ZERO;
                for i in 0..M::DIM {
                    let d = svd.sigma[i] - M::Scalar::ONE;
                    s += d * d;
                }
                self.mu * s
            }
        }
    }

    #[inline]
    fn first_piola(&self, f: &M, st: &Self::State) -> M {
        match &st.svd {
            None => M::zero(),
            Some((_, r)) => (*f - *r) * (self.mu + self.mu),
        }
    }

    #[inline]
    fn hessian_action(&self, _f: &M, st: &Self::State, df: &M) -> M {
        match &st.svd {
            None => M::zero(),
            Some((svd, _)) => (*df - d_rotation(svd, df)) * (self.mu + self.mu),
        }
    }
}
