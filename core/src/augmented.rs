//! The volume-preserving ("augmented") energy `Ψ̂(F) = Ψ(Jᵃ F)`, `a = −1/d`, and its
//! derivatives 𝓑, `Â` and `Ĉ:Z`, over any [`BaseEnergy`].
//!
//! Source: the augmented-MPM tech report (Stomakhin et al. 2014), whose `J^{−1/a}` and `α`
//! are typos for `Jᵃ`. With `H = F⁻ᵀ`:
//! - `𝓑:Z = Jᵃ(Z + a(H:Z)F)`, `Z:𝓑 = Jᵃ(Z + a(F:Z)H)` (𝓑 = ∂(JᵃF)/∂F),
//! - `Â = A:𝓑`, `A = ∂Ψ/∂F(Jᵃ F)`,
//! - `Ĉ:Z = (C:(𝓑:Z)):𝓑 + a(H:Z) A:𝓑 + aJᵃ(A:Z)H − aJᵃ(A:F) H Zᵀ H`,
//!
//! `A` and `C` are evaluated at `F̂ = Jᵃ F`; `H` and the contractions with `F` use `F` itself.
//!
//! **Scaling.** Write `F = 2ᵏ G` with `G`'s largest entry in `[0.5, 1)` (exact). Then
//! `F̂ = Ĝ` (since `det(2ᵏG)^a 2ᵏ = det(G)^a`), `Jᵃ = 2⁻ᵏ det(G)ᵃ`, `H = 2⁻ᵏ G⁻ᵀ`, and every
//! formula above is homogeneous: `𝓑(F):Z = 2⁻ᵏ 𝓑(G):Z`, `Â(F) = 2⁻ᵏ Â(G)`,
//! `Ĉ(F):Z = 2⁻²ᵏ Ĉ(G):Z`, `Ψ̂(F) = Ψ̂(G)`. So every kernel works on `G`, no threshold is
//! absolute, `J` is never formed (it overflows for entries near 1e103 in f64), and the only
//! overflow left is in the final power of two, which is reported as [`Error::Overflow`].

use crate::energy::BaseEnergy;
use crate::error::{Error, Result};
use crate::mat::Matrix;
use crate::polar::{scale_exponent, scale_pow2};
use crate::scalar::Real;

/// `a = −1/d`.
#[inline]
#[must_use]
pub fn exponent_a<M: Matrix>() -> M::Scalar {
    -M::Scalar::ONE / M::Scalar::from_i32(M::DIM as i32)
}

/// `(x·2ᵏ)^{−1/d}` for `x > 0` ([`crate::lane::lmat::inv_root_exp`] on one scalar).
#[inline]
fn inv_root_exp<M: Matrix>(x: M::Scalar, k: i32) -> M::Scalar {
    let k = M::Scalar::from_i32(k);
    if M::DIM == 2 {
        crate::lane::lmat::inv_root_exp::<M::Scalar, 2>(x, k)
    } else {
        crate::lane::lmat::inv_root_exp::<M::Scalar, 3>(x, k)
    }
}

/// The kinematic quantities of one `F` shared by all kernels, computed on the scaled `G`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Kinematics<M: Matrix> {
    /// `G = 2⁻ᵏ F`, largest entry in `[0.5, 1)`.
    pub g: M,
    /// The exponent `k` of `F = 2ᵏ G`.
    pub k: i32,
    /// `det G > 0`.
    pub det_g: M::Scalar,
    /// `G⁻ᵀ`.
    pub h_g: M,
    /// `det(G)ᵃ`.
    pub ja_g: M::Scalar,
    /// `F̂ = Jᵃ F = det(G)ᵃ G`, `det F̂ = 1` up to rounding.
    pub f_hat: M,
}

impl<M: Matrix> Kinematics<M> {
    /// Validates `f` (finite, `J > 0`) and computes the shared quantities.
    #[inline]
    pub fn new(f: &M) -> Result<Self> {
        if !f.is_finite() {
            return Err(Error::NonFinite);
        }
        let k = scale_exponent(f);
        let g = scale_pow2(f, -k);
        // The determinant on power-of-two-equilibrated columns, G = Ĝ·diag(2^{e_j}) (exact):
        // det G = det Ĝ·2^{Σe}, G⁻ᵀ = cof(Ĝ)/det Ĝ · diag(2^{−e_j}). Columns of very different
        // sizes (1 and 1e-20 in f32) put det G below the normal range although F is well
        // conditioned after column scaling; this way nothing under- or overflows there.
        let mut gh = g;
        let mut ce = [0i32; 3];
        for j in 0..M::DIM {
            let mut m = M::Scalar::ZERO;
            for i in 0..M::DIM {
                m = m.max(g[(i, j)].abs());
            }
            ce[j] = m.exponent();
            for i in 0..M::DIM {
                gh[(i, j)] = g[(i, j)].scalbn(-ce[j]);
            }
        }
        let sum_e: i32 = ce.iter().sum();
        let det_h = gh.det();
        // Also catches F = 0 (det 0) and det G that is NaN-free but not positive. Below the
        // smallest normal number, det Ĝ says F is singular to working precision (Hadamard
        // ratio ∏‖g_j‖/|det G| beyond 1/MIN_POSITIVE ≫ 1/ε).
        // Negated, so that a NaN determinant fails the check too.
        #[allow(clippy::neg_cmp_op_on_partial_ord)]
        if !(det_h >= M::Scalar::MIN_POSITIVE) {
            return Err(Error::NonPositiveJ);
        }
        let det_g = det_h.scalbn(sum_e);
        let mut h_g = gh.cofactor() * (M::Scalar::ONE / det_h);
        for j in 0..M::DIM {
            for i in 0..M::DIM {
                h_g[(i, j)] = h_g[(i, j)].scalbn(-ce[j]);
            }
        }
        let ja_g = inv_root_exp::<M>(det_h, sum_e);
        let f_hat = g * ja_g;
        if !(h_g.is_finite() && ja_g.is_finite() && f_hat.is_finite()) {
            // det G so small (below ~ε^d) that G⁻ᵀ or det(G)ᵃ overflow: singular to working
            // precision.
            return Err(Error::NonPositiveJ);
        }
        Ok(Self {
            g,
            k,
            det_g,
            h_g,
            ja_g,
            f_hat,
        })
    }

    /// `J = det F` (may overflow to inf for huge `F`; the kernels never use it).
    #[inline]
    #[must_use]
    pub fn j(&self) -> M::Scalar {
        self.det_g.scalbn(self.k * M::DIM as i32)
    }

    /// `𝓑(G):Z`, unscaled.
    #[inline]
    fn b_z_g(&self, z: &M) -> M {
        let a = exponent_a::<M>();
        (*z + self.g * (a * self.h_g.ddot(z))) * self.ja_g
    }

    /// `Z:𝓑(G)`, unscaled.
    #[inline]
    fn z_b_g(&self, z: &M) -> M {
        let a = exponent_a::<M>();
        (*z + self.h_g * (a * self.g.ddot(z))) * self.ja_g
    }

    /// `𝓑(F):Z = Jᵃ(Z + a(H:Z)F)`.
    #[inline]
    pub fn b_z(&self, z: &M) -> Result<M> {
        finite(scale_pow2(&self.b_z_g(z), -self.k))
    }

    /// `Z:𝓑(F) = Jᵃ(Z + a(F:Z)H)`.
    #[inline]
    pub fn z_b(&self, z: &M) -> Result<M> {
        finite(scale_pow2(&self.z_b_g(z), -self.k))
    }
}

#[inline]
fn finite<M: Matrix>(m: M) -> Result<M> {
    if m.is_finite() {
        Ok(m)
    } else {
        Err(Error::Overflow)
    }
}

/// `Ψ̂`, `Â` and `Ĉ:Z` of a base energy at one `F`, sharing one decomposition.
///
/// Build it once per particle with [`Augmented::new`], then ask for what the time step
/// needs: an explicit step needs only [`Augmented::ahat`]; an implicit one also calls
/// [`Augmented::chat_z`] once per Krylov iteration without recomputing the decomposition.
#[derive(Clone, Copy, Debug)]
pub struct Augmented<'e, M: Matrix, E: BaseEnergy<M>> {
    energy: &'e E,
    kin: Kinematics<M>,
    state: E::State,
    /// `A = ∂Ψ/∂F(F̂)` (scale-free).
    a: M,
    /// `Â(G) = A:𝓑(G)`, unscaled.
    ahat_g: M,
}

impl<'e, M: Matrix, E: BaseEnergy<M>> Augmented<'e, M, E> {
    /// Validates `f` and the energy's parameters, decomposes `F̂` once.
    #[inline]
    pub fn new(energy: &'e E, f: &M) -> Result<Self> {
        let kin = Kinematics::new(f)?;
        let state = energy.prepare(&kin.f_hat)?;
        let a = energy.first_piola(&kin.f_hat, &state);
        let ahat_g = kin.z_b_g(&a);
        Ok(Self {
            energy,
            kin,
            state,
            a,
            ahat_g,
        })
    }

    /// The shared kinematics (`G`, `k`, `F̂`, …).
    #[inline]
    #[must_use]
    pub fn kinematics(&self) -> &Kinematics<M> {
        &self.kin
    }

    /// The base energy's state at `F̂` (e.g. its SVD).
    #[inline]
    #[must_use]
    pub fn base_state(&self) -> &E::State {
        &self.state
    }

    /// `Ψ̂(F) = Ψ(F̂)`, energy per unit reference volume.
    #[inline]
    pub fn psi_hat(&self) -> Result<M::Scalar> {
        let p = self.energy.psi(&self.kin.f_hat, &self.state);
        if p.is_finite() {
            Ok(p)
        } else {
            Err(Error::Overflow)
        }
    }

    /// `Â = ∂Ψ̂/∂F = A:𝓑`, the first Piola–Kirchhoff stress of `Ψ̂`.
    #[inline]
    pub fn ahat(&self) -> Result<M> {
        finite(scale_pow2(&self.ahat_g, -self.kin.k))
    }

    /// `Ĉ:Z`, the action of the Hessian `∂²Ψ̂/∂F∂F` on `Z`.
    #[inline]
    pub fn chat_z(&self, z: &M) -> Result<M> {
        if !z.is_finite() {
            return Err(Error::NonFinite);
        }
        finite(scale_pow2(&self.chat_z_g(z), -2 * self.kin.k))
    }

    /// `Ĉ(G):Z`, unscaled: the seed's four terms, each on `G`.
    #[inline]
    fn chat_z_g(&self, z: &M) -> M {
        let kin = &self.kin;
        let a = exponent_a::<M>();
        let bz = kin.b_z_g(z);
        let c_bz = self.energy.hessian_action(&kin.f_hat, &self.state, &bz);
        let t1 = kin.z_b_g(&c_bz);
        let t2 = self.ahat_g * (a * kin.h_g.ddot(z));
        let aj = a * kin.ja_g;
        let t3 = kin.h_g * (aj * self.a.ddot(z));
        let t4 = kin.h_g * z.transpose() * kin.h_g * (aj * self.a.ddot(&kin.g));
        t1 + t2 + t3 - t4
    }
}

/// `𝓑(F):Z`.
#[inline]
pub fn b_z<M: Matrix>(f: &M, z: &M) -> Result<M> {
    if !z.is_finite() {
        return Err(Error::NonFinite);
    }
    Kinematics::new(f)?.b_z(z)
}

/// `Z:𝓑(F)`.
#[inline]
pub fn z_b<M: Matrix>(f: &M, z: &M) -> Result<M> {
    if !z.is_finite() {
        return Err(Error::NonFinite);
    }
    Kinematics::new(f)?.z_b(z)
}

/// `Ψ̂(F)` of a base energy.
#[inline]
pub fn psi_hat<M: Matrix, E: BaseEnergy<M>>(energy: &E, f: &M) -> Result<M::Scalar> {
    Augmented::new(energy, f)?.psi_hat()
}

/// `Â(F)` of a base energy.
#[inline]
pub fn ahat<M: Matrix, E: BaseEnergy<M>>(energy: &E, f: &M) -> Result<M> {
    Augmented::new(energy, f)?.ahat()
}

/// `Ĉ(F):Z` of a base energy.
#[inline]
pub fn chat_z<M: Matrix, E: BaseEnergy<M>>(energy: &E, f: &M, z: &M) -> Result<M> {
    Augmented::new(energy, f)?.chat_z(z)
}
