//! Contract checks: violations per cell, one case against the reference, the reference's accuracy.

use super::measures::{dist, norm_dd, norm_scaled, recon_err, Scales};
use super::runners::Runner;
use super::stats::{CaseErr, Cell, StatusCounts};
use super::{bound, Quantity, BOUND_RECON, BOUND_REFERENCE, MU, SORT_SLACK};
use crate::families::{Case, Contract};
use crate::reference::{self, Dd};
use ampm_core::polar::Svd;
use ampm_core::{Error, Mat, Matrix, Real};
use std::fmt::Write as _;

/// Collects violations of one cell.
pub(super) struct Viol {
    pub(super) msgs: Vec<String>,
    pub(super) n: usize,
}

impl Viol {
    pub(super) fn add(&mut self, f: &Mat<f64, 3>, d: usize, msg: String) {
        self.n += 1;
        if self.msgs.len() < 8 {
            let mut e = String::new();
            for j in 0..d {
                for i in 0..d {
                    let _ = write!(e, "{:e},", f.cols[j][i]);
                }
            }
            self.msgs.push(format!("{msg} at F(col-major)=[{e}]"));
        }
    }
}

pub(super) fn pad3<const D: usize>(f: &Mat<f64, D>) -> Mat<f64, 3> {
    let mut m = Mat::<f64, 3>::ZERO;
    for j in 0..D {
        for i in 0..D {
            m.cols[j][i] = f.cols[j][i];
        }
    }
    m
}

fn status_of(e: Error, st: &mut StatusCounts) {
    match e {
        Error::NonPositiveJ => st.non_positive_j += 1,
        Error::Overflow => st.overflow += 1,
        Error::NonFinite => st.non_finite += 1,
        _ => st.other += 1,
    }
}

/// Measures one case for one method; appends errors and violations.
#[allow(clippy::too_many_arguments)]
pub(super) fn measure_case<T: Real, const D: usize>(
    run: &dyn Runner<T, D>,
    contract: Contract,
    case: &Case<D>,
    z64: &Mat<f64, D>,
    rf: &Option<reference::Reference<D>>,
    sc: &Option<Scales>,
    cell: &mut Cell,
    viol: &mut Viol,
) where
    Mat<T, D>: Matrix<Scalar = T, Vector = [T; D]>,
    Mat<f64, D>: Matrix<Scalar = f64>,
    Mat<Dd, D>: Matrix<Scalar = Dd, Vector = [Dd; D]>,
{
    let eps = T::EPSILON.to_f64();
    let tiny = T::MIN_POSITIVE.to_f64();
    let f: Mat<T, D> = case.f.cast::<T>();
    let z: Mat<T, D> = z64.cast::<T>();
    let spec = run.spec();
    let bnd = |q: Quantity| bound(&spec, q);
    let fp = pad3(&case.f);
    let mut ce = CaseErr {
        param: case.param,
        err: [None; 5],
        raw: [None; 5],
    };
    let (rf, sc) = match (contract, rf, sc) {
        (Contract::NonFinite, _, _) | (_, None, _) | (_, _, None) => {
            // Non-finite input: everything must say NonFinite.
            if !matches!(run.svd(&f), Err(Error::NonFinite)) {
                viol.add(
                    &fp,
                    D,
                    "svd of non-finite F did not return NonFinite".into(),
                );
            }
            match run.kernels(&f, &z) {
                Err(e) => status_of(e, &mut cell.statuses),
                Ok(_) => cell.statuses.ok += 1,
            }
            if !matches!(run.kernels(&f, &z), Err(Error::NonFinite)) {
                viol.add(
                    &fp,
                    D,
                    "kernels of non-finite F did not return NonFinite".into(),
                );
            }
            cell.record(ce);
            return;
        }
        (_, Some(r), Some(s)) => (r, s),
    };
    // --- decomposition -----------------------------------------------------------------
    match run.svd(&f) {
        Err(e) => viol.add(&fp, D, format!("svd failed: {e:?}")),
        Ok(svd) => {
            let (u, v) = (svd.u, svd.v);
            let finite = u.is_finite() && v.is_finite() && svd.sigma.iter().all(|x| x.is_finite());
            if !finite {
                viol.add(&fp, D, "svd not finite".into());
            } else {
                let (u64_, v64) = (u.cast::<f64>(), v.cast::<f64>());
                let id = Mat::<f64, D>::identity();
                let ou = (u64_.transpose() * u64_ - id).max_abs();
                let ov = (v64.transpose() * v64 - id).max_abs();
                if ou > 16.0 * eps || ov > 16.0 * eps || u64_.det() < 0.0 || v64.det() < 0.0 {
                    viol.add(&fp, D, format!("U or V not a rotation: {ou:e} {ov:e}"));
                }
                let s: Vec<f64> = svd.sigma.iter().map(|x| x.to_f64()).collect();
                // Σ error against the (sorted) reference.
                let mut ds = 0.0f64;
                for i in 0..D {
                    ds = ds.max((Dd::exact(s[i]) - rf.svd.sigma[i]).abs().to_f64());
                }
                // Sorted up to the method's own Σ error (if |σᵢ| and |σᵢ,ref| differ by at most
                // ds, a sorted reference allows |σᵢ₊₁| − |σᵢ| ≤ 2ds) plus SORT_SLACK·ε|σ₀|.
                let slack = SORT_SLACK * eps * s[0].abs() + 2.0 * ds;
                let sorted = (0..D - 1).all(|i| s[i + 1].abs() - s[i].abs() <= slack);
                let signs = (0..D - 1).all(|i| s[i] >= 0.0);
                if !sorted || !signs {
                    viol.add(&fp, D, format!("σ not rotation-variant: {s:?}"));
                }
                // Reconstruction, relative to ‖F‖_F.
                let nf = {
                    let mut v = [0.0f64; 9];
                    for j in 0..D {
                        for i in 0..D {
                            v[i + D * j] = case.f.cols[j][i];
                        }
                    }
                    norm_scaled(&v[..D * D])
                };
                let rec_err = recon_err(&u, &s, &v, &case.f) / (eps * nf.max(tiny));
                if rec_err > BOUND_RECON && bnd(Quantity::R).is_finite() {
                    viol.add(&fp, D, format!("reconstruction error {rec_err:.3e} ε‖F‖"));
                }
                // Σ.
                let es = ds / (eps * sc.sigma0.max(tiny));
                ce.err[1] = Some(es);
                ce.raw[1] = Some(if sc.sigma0 > 0.0 { ds / sc.sigma0 } else { ds });
                if es > bnd(Quantity::Sigma) {
                    viol.add(&fp, D, format!("Σ error {es:.3e} ε > bound"));
                }
                // R.
                if sc.kappa_r.is_finite() {
                    let dr = dist(&svd.rotation(), &rf.r);
                    let er = dr / (eps * sc.kappa_r);
                    ce.err[0] = Some(er);
                    ce.raw[0] = Some(dr);
                    if er > bnd(Quantity::R) {
                        viol.add(
                            &fp,
                            D,
                            format!("R error {er:.3e} εκ (κ = {:.3e})", sc.kappa_r),
                        );
                    }
                }
            }
        }
    }
    // --- kernels -----------------------------------------------------------------------
    if sc.reference_kernels_failed {
        // Reported once per case by the caller.
        cell.record(ce);
        return;
    }
    let k = run.kernels(&f, &z);
    match &k {
        Err(e) => status_of(*e, &mut cell.statuses),
        Ok(_) => cell.statuses.ok += 1,
    }
    match (&rf.kernels, k) {
        (None, Ok(_)) if !sc.near_singular => {
            viol.add(&fp, D, "kernels accepted J ≤ 0".into());
        }
        (None, Err(e)) if e != Error::NonPositiveJ && !sc.near_singular => {
            viol.add(&fp, D, format!("kernels on J ≤ 0 returned {e:?}"));
        }
        (None, _) => {}
        // Singular to working precision: the computed J, H, σ̂ carry no correct digit, so
        // any status is acceptable (never NaN/inf: the kernels return Result).
        (Some(_), Err(_)) if sc.near_singular => {}
        (Some(_), Err(e)) => viol.add(&fp, D, format!("kernels on J > 0 returned {e:?}")),
        (Some(kr), Ok((psi, ahat, chat))) => {
            // Singular to working precision: any per-kernel status, no bound (still measured).
            let check = !sc.near_singular;
            let mut viol_k = |fp: &Mat<f64, 3>, msg: String| {
                if check {
                    viol.add(fp, D, msg);
                }
            };
            let ek = eps * sc.kappa_k;
            let mu = MU;
            let sh = &sc.sigma_hat;
            let s_hat0 = sh[0];
            let dev: f64 = sh.iter().map(|x| (x - 1.0) * (x - 1.0)).sum::<f64>().sqrt();
            let m_hat = sh[D - 2] + sh[D - 1];
            let allow_overflow = |r: &ampm_core::Result<Mat<Dd, D>>| match r {
                Err(Error::Overflow) => true,
                Ok(m) => m.cast::<f64>().max_abs() >= T::MAX.to_f64() * 0.5,
                Err(_) => false,
            };
            // Ψ̂.
            match (psi, &kr.psi) {
                (Ok(p), Ok(pr)) => {
                    let d = (Dd::exact(p.to_f64()) - *pr).abs().to_f64();
                    let e = d / (ek * 2.0 * mu * s_hat0 * (dev + eps * s_hat0));
                    ce.err[2] = Some(e);
                    ce.raw[2] = Some(d / pr.to_f64().abs().max(f64::MIN_POSITIVE));
                    if e > bnd(Quantity::Psi) {
                        viol_k(
                            &fp,
                            format!("Ψ̂ error {e:.3e} εκ (κ_K = {:.3e})", sc.kappa_k),
                        );
                    }
                }
                (r, rr) => viol_k(&fp, format!("Ψ̂: {r:?} vs reference {rr:?}")),
            }
            // Â.
            match (ahat, &kr.ahat) {
                (Ok(a), Ok(ar)) => {
                    let d = dist(&a, ar);
                    let e = d / (ek * 2.0 * mu * s_hat0 * sc.s_b).max(tiny);
                    ce.err[3] = Some(e);
                    ce.raw[3] = Some(d / norm_dd(ar).max(f64::MIN_POSITIVE));
                    if e > bnd(Quantity::Ahat) {
                        viol_k(
                            &fp,
                            format!("Â error {e:.3e} εκ (κ_K = {:.3e})", sc.kappa_k),
                        );
                    }
                }
                (Err(Error::Overflow), r) if allow_overflow(r) => {}
                (r, rr) => viol_k(&fp, format!("Â: {:?} vs reference {:?}", r.err(), rr.err())),
            }
            // Ĉ:Z.
            match (chat, &kr.chat_z) {
                (Ok(c), Ok(cr)) => {
                    let d = dist(&c, cr);
                    let nz = z64.norm_squared().sqrt();
                    let scale = 2.0 * mu * nz * sc.s_b * sc.s_b * (1.0 + 2.0 / m_hat);
                    let e = d / (ek * scale).max(tiny);
                    ce.err[4] = Some(e);
                    ce.raw[4] = Some(d / norm_dd(cr).max(f64::MIN_POSITIVE));
                    if e > bnd(Quantity::ChatZ) {
                        viol_k(
                            &fp,
                            format!("Ĉ:Z error {e:.3e} εκ (κ_K = {:.3e})", sc.kappa_k),
                        );
                    }
                }
                (Err(Error::Overflow), r) if allow_overflow(r) => {}
                (r, rr) => viol_k(
                    &fp,
                    format!("Ĉ:Z: {:?} vs reference {:?}", r.err(), rr.err()),
                ),
            }
        }
    }
    // Kernel errors of matrices singular to working precision are outside every contract
    // (and would dominate the statistics): not counted.
    if sc.near_singular {
        for i in 2..5 {
            ce.err[i] = None;
            ce.raw[i] = None;
        }
    }
    cell.record(ce);
}

/// Why `svd`, a reference SVD of `f`, misses [`BOUND_REFERENCE`]; `None` if it meets it. The
/// reconstruction is formed after scaling `F` and `σ` by the power of two that brings
/// `max|Fᵢⱼ|` to `[0.5, 1)` (exact), so the double-double products neither overflow near
/// `f64::MAX` nor lose their trailing word near the subnormal range.
#[must_use]
pub fn reference_error<const D: usize>(f: &Mat<f64, D>, svd: &Svd<Mat<Dd, D>>) -> Option<String>
where
    Mat<Dd, D>: Matrix<Scalar = Dd, Vector = [Dd; D]>,
    Mat<f64, D>: Matrix<Scalar = f64>,
{
    let id = Mat::<Dd, D>::identity();
    let ou = (svd.u.transpose() * svd.u - id).max_abs().to_f64();
    let ov = (svd.v.transpose() * svd.v - id).max_abs().to_f64();
    let e = f.max_abs().exponent();
    let fs = reference::to_dd(f).map(|x| x.scalbn(-e));
    let scaled = Svd {
        u: svd.u,
        sigma: svd.sigma.map(|x| x.scalbn(-e)),
        v: svd.v,
    };
    let rec = (scaled.reconstruct() - fs).norm_squared().sqrt().to_f64();
    let floor = Dd::MIN_POSITIVE.scalbn(-e).to_f64();
    let rel = rec / fs.norm_squared().sqrt().to_f64().max(floor);
    let det_ok = svd.u.det() > Dd::ZERO && svd.v.det() > Dd::ZERO;
    // Written so that a NaN anywhere fails.
    let ok = ou <= BOUND_REFERENCE && ov <= BOUND_REFERENCE && rel <= BOUND_REFERENCE;
    (!ok || !det_ok).then(|| {
        format!(
            "reference SVD not accurate (UᵀU − I: {ou:e}, VᵀV − I: {ov:e}, \
             ‖UΣVᵀ − F‖/‖F‖: {rel:e}, bound {BOUND_REFERENCE:e}; det U, det V > 0: {det_ok})"
        )
    })
}
