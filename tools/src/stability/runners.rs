//! The methods under test: their specs and error bounds, and the runners of each dimension.

use super::{Quantity, BOUND_RECON, MU};
use crate::reference::Dim;
use ampm_core::augmented::Augmented;
use ampm_core::energy::FixedCorotated;
use ampm_core::kernel::batch::{self as kbatch, BatchReal};
use ampm_core::kernel::{Dim as KDim, LaneDim};
use ampm_core::lane::{Isa, IsaKind};
use ampm_core::polar::{
    ClosedForm2, HighamNoferini, McAdams, OneSidedJacobi, QrSvd, Svd, SvdMethod,
};
use ampm_core::{Error, Mat, Matrix, Real};

/// One method configuration.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct MethodSpec {
    /// `SvdMethod::NAME`.
    pub key: &'static str,
    /// Sweep count, for the methods with a fixed one (McAdams).
    pub sweeps: Option<u32>,
    /// 2 or 3.
    pub dim: usize,
}

impl MethodSpec {
    /// Label for tables and charts, e.g. `mcadams(4)`.
    #[must_use]
    pub fn label(&self) -> String {
        match self.sweeps {
            Some(s) => format!("{}({s})", self.key),
            None => self.key.to_string(),
        }
    }
}

/// Error bound of a method for a quantity, in units of `ε·κ` of the [module docs](super).
///
/// Derivation for the backward-stable methods (one-sided Jacobi, QR, Higham–Noferini, the 2D
/// closed form): their backward error is `≤ BOUND_RECON·ε‖F‖` (see there), hence
/// `‖ΔR‖_F ≤ 2‖ΔF‖_F/m ≤ 2·√d·BOUND_RECON·ε σ₀/m`, i.e. `√d·BOUND_RECON` in units of
/// `ε κ_R`, and `|Δσ| ≤ ‖ΔF‖₂ ≤ √d·BOUND_RECON·ε σ₀` (Weyl). The kernels add a bounded
/// number of products and one `det`, `cbrt` and cofactor matrix, each `O(ε κ_K)` relative
/// (counted in `κ_J`, `σ₀/σ_min`), so the same `√d·BOUND_RECON` in units of `ε κ_K`.
///
/// McAdams (Jacobi on `FᵀF`, approximate rotations, no convergence test): squaring `F` makes
/// every error `O(ε κ²)`, and a fixed sweep count leaves an off-diagonal that is not a
/// rounding error at all; its contract is the structural one only (finite, orthonormal
/// `U, V`, sorted, statuses), and its errors are reported, not bounded: `f64::INFINITY`.
#[must_use]
pub fn bound(method: &MethodSpec, _q: Quantity) -> f64 {
    if method.key == <McAdams as SvdMethod<Mat<f64, 3>>>::NAME {
        f64::INFINITY
    } else {
        (method.dim as f64).sqrt() * BOUND_RECON
    }
}

/// The kernel results of one method at one `F`.
type KernelOut<T, const D: usize> = (
    core::result::Result<T, Error>,
    core::result::Result<Mat<T, D>, Error>,
    core::result::Result<Mat<T, D>, Error>,
);

/// A method, type-erased for the measurement loop.
pub(super) trait Runner<T: Real, const D: usize>
where
    Mat<T, D>: Matrix,
{
    fn spec(&self) -> MethodSpec;
    fn svd(&self, f: &Mat<T, D>) -> ampm_core::Result<Svd<Mat<T, D>>>;
    fn kernels(&self, f: &Mat<T, D>, z: &Mat<T, D>) -> ampm_core::Result<KernelOut<T, D>>;
}

struct With<S>(S, Option<u32>);

impl<T: Real, const D: usize, S: SvdMethod<Mat<T, D>>> Runner<T, D> for With<S>
where
    Mat<T, D>: Matrix<Scalar = T>,
{
    fn spec(&self) -> MethodSpec {
        MethodSpec {
            key: S::NAME,
            sweeps: self.1,
            dim: D,
        }
    }
    fn svd(&self, f: &Mat<T, D>) -> ampm_core::Result<Svd<Mat<T, D>>> {
        self.0.svd(f)
    }
    fn kernels(&self, f: &Mat<T, D>, z: &Mat<T, D>) -> ampm_core::Result<KernelOut<T, D>> {
        let e = FixedCorotated::with_method(T::from_f64(MU), self.0);
        let st = Augmented::new(&e, f)?;
        Ok((st.psi_hat(), st.ahat(), st.chat_z(z)))
    }
}

/// The fast batch kernels of `ampm_core::kernel` on one instruction set, one particle per call
/// (a padded chunk of lanes): the instantiation the C batch calls run. The decomposition is
/// the default method on lanes; the kernels each run alone, so each has its own status.
struct Fast(Isa, &'static str);

impl<T: BatchReal, const D: usize> Runner<T, D> for Fast
where
    KDim<D>: LaneDim<D>,
    Mat<T, D>: Matrix<Scalar = T, Vector = [T; D]>,
{
    fn spec(&self) -> MethodSpec {
        MethodSpec {
            key: self.1,
            sweeps: None,
            dim: D,
        }
    }
    fn svd(&self, f: &Mat<T, D>) -> ampm_core::Result<Svd<Mat<T, D>>> {
        let mut u = [T::ZERO; 9];
        let mut v = [T::ZERO; 9];
        let mut s = [T::ZERO; 3];
        let st = kbatch::svd::<T, D>(
            self.0,
            &f.cols.concat(),
            &mut u[..D * D],
            &mut s[..D],
            &mut v[..D * D],
        )?;
        st.result().map_err(|e| e.1)?;
        let sigma: [T; D] = s[..D].try_into().expect("D values");
        Ok(Svd {
            u: Mat::from_col_major(&u[..D * D]).expect("d² entries"),
            sigma,
            v: Mat::from_col_major(&v[..D * D]).expect("d² entries"),
        })
    }
    fn kernels(&self, f: &Mat<T, D>, z: &Mat<T, D>) -> ampm_core::Result<KernelOut<T, D>> {
        let mu = [T::from_f64(MU)];
        let (fv, zv) = (f.cols.concat(), z.cols.concat());
        let one = |what: u8| -> ampm_core::Result<Vec<T>> {
            let mut out = vec![T::ZERO; if what == 0 { 1 } else { D * D }];
            let o = match what {
                0 => kbatch::Outputs {
                    energy: Some(&mut out),
                    ..Default::default()
                },
                1 => kbatch::Outputs {
                    ahat: Some(&mut out),
                    ..Default::default()
                },
                _ => kbatch::Outputs {
                    chat_z: Some(&mut out),
                    ..Default::default()
                },
            };
            kbatch::ahat_chat_z::<T, D>(self.0, &mu, &fv, Some(&zv), o)?
                .result()
                .map_err(|e| e.1)?;
            Ok(out)
        };
        let m = |v: Vec<T>| Mat::from_col_major(&v).expect("d² entries");
        let (p, a, c) = (one(0), one(1), one(2));
        // A check that fails for every kernel (F, J, μ) is the call's status, as for the
        // generic runners; per-kernel statuses (overflow) stay per kernel.
        match (&p, &a, &c) {
            (Err(x), Err(y), Err(w)) if x == y && y == w => Err(*x),
            _ => Ok((p.map(|v| v[0]), a.map(m), c.map(m))),
        }
    }
}

/// Scalars with fast batch kernels: the [`Fast`] runner of each instruction set of this CPU.
pub(super) trait FastPaths<const D: usize>: Real {
    fn fast_runners() -> Vec<Box<dyn Runner<Self, D>>>;
}

macro_rules! fast_paths {
    ($t:ty) => {
        impl<const D: usize> FastPaths<D> for $t
        where
            KDim<D>: LaneDim<D>,
            Mat<$t, D>: Matrix<Scalar = $t, Vector = [$t; D]>,
        {
            fn fast_runners() -> Vec<Box<dyn Runner<$t, D>>> {
                Isa::available()
                    .into_iter()
                    .map(|isa| {
                        let key = match isa.kind() {
                            IsaKind::Scalar => "fast-scalar",
                            IsaKind::Avx2 => "fast-avx2",
                            IsaKind::Avx512 => "fast-avx512",
                        };
                        Box::new(Fast(isa, key)) as Box<dyn Runner<$t, D>>
                    })
                    .collect()
            }
        }
    };
}
fast_paths!(f32);
fast_paths!(f64);

/// The methods of each dimension.
pub(super) trait MethodsOf<T: Real, const D: usize>
where
    Mat<T, D>: Matrix,
{
    /// The methods; `all_sweeps` adds the McAdams sweep counts other than the default.
    fn methods(all_sweeps: bool) -> Vec<Box<dyn Runner<T, D>>>;
}

impl<T: Real + FastPaths<2>> MethodsOf<T, 2> for Dim<2> {
    fn methods(_all_sweeps: bool) -> Vec<Box<dyn Runner<T, 2>>> {
        let mut v: Vec<Box<dyn Runner<T, 2>>> = vec![Box::new(With(ClosedForm2, None))];
        v.extend(T::fast_runners());
        v
    }
}

/// McAdams sweep counts measured (the range is 2–8): all of them in the reduced size
/// and on the Haar family, the default (4) elsewhere in the full size.
pub const MCADAMS_SWEEPS: [u32; 3] = [2, 4, 8];

impl<T: Real + FastPaths<3>> MethodsOf<T, 3> for Dim<3> {
    fn methods(all_sweeps: bool) -> Vec<Box<dyn Runner<T, 3>>> {
        let mut v: Vec<Box<dyn Runner<T, 3>>> =
            vec![Box::new(With(OneSidedJacobi::default(), None))];
        for s in MCADAMS_SWEEPS {
            if all_sweeps || s == McAdams::default().sweeps {
                v.push(Box::new(With(McAdams { sweeps: s }, Some(s))));
            }
        }
        v.push(Box::new(With(QrSvd::default(), None)));
        v.push(Box::new(With(HighamNoferini::default(), None)));
        v.extend(T::fast_runners());
        v
    }
}
