//! The driver: runs every method over the families, reusing the reference along orbits.

use super::contracts::{measure_case, pad3, reference_error, Viol};
use super::measures::scales;
use super::runners::{FastPaths, MethodsOf};
use super::stats::{Cell, Report, StatusCounts};
use super::MU;
use crate::families::{generate, signed_perm, Family, FamilyDim, Size};
use crate::reference::{self, Dd, Dim, ReferenceDim};
use ampm_core::polar::Svd;
use ampm_core::{Mat, Matrix, Real};
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;

/// The reference at `P F Q` from the one at `F` (`P`, `Q` signed permutations,
/// `det P · det Q = +1`, `Z ↦ P Z Q`): `U ↦ sPU`, `V ↦ sQᵀV` (`s = det P`, so both stay
/// rotations), `σ`, `σ̂`, `Ψ̂` unchanged, `R ↦ PRQ`, `Â ↦ PÂQ`, `Ĉ:Z ↦ P(Ĉ:Z)Q` (isotropy and
/// frame indifference of `Ψ̂`). Exact: the products only permute and negate entries.
fn transform<const D: usize>(
    r: &reference::Reference<D>,
    p: &Mat<f64, D>,
    q: &Mat<f64, D>,
) -> reference::Reference<D>
where
    Mat<Dd, D>: Matrix<Scalar = Dd, Vector = [Dd; D]>,
    Mat<f64, D>: Matrix<Scalar = f64>,
{
    let neg = p.det() < 0.0;
    let sgn = |m: Mat<Dd, D>| if neg { -m } else { m };
    let tr = |m: &Mat<Dd, D>| perm_right(&perm_left(p, m), q);
    reference::Reference {
        svd: Svd {
            u: sgn(perm_left(p, &r.svd.u)),
            sigma: r.svd.sigma,
            v: sgn(perm_left(&q.transpose(), &r.svd.v)),
        },
        r: tr(&r.r),
        kernels: r.kernels.map(|k| reference::KernelRef {
            psi: k.psi,
            ahat: k.ahat.map(|m| tr(&m)),
            chat_z: k.chat_z.map(|m| tr(&m)),
            sigma_hat: k.sigma_hat,
        }),
    }
}

/// `P M` for a signed permutation matrix `P` (row `j` of `M` goes to the row of column `j`'s
/// nonzero of `P`, times its sign): exact, no arithmetic but negation.
fn perm_left<const D: usize>(p: &Mat<f64, D>, m: &Mat<Dd, D>) -> Mat<Dd, D> {
    let mut out = *m;
    for j in 0..D {
        for i in 0..D {
            let s = p.cols[j][i];
            if s != 0.0 {
                for c in 0..D {
                    let x = m.cols[c][j];
                    out.cols[c][i] = if s < 0.0 { -x } else { x };
                }
            }
        }
    }
    out
}

/// `M Q` for a signed permutation matrix `Q`: column `j` of the result is column `k` of `M`
/// times `Q_kj`, the nonzero of column `j` of `Q`.
fn perm_right<const D: usize>(m: &Mat<Dd, D>, q: &Mat<f64, D>) -> Mat<Dd, D> {
    let mut out = *m;
    for j in 0..D {
        for k in 0..D {
            let s = q.cols[j][k];
            if s != 0.0 {
                for r in 0..D {
                    let x = m.cols[k][r];
                    out.cols[j][r] = if s < 0.0 { -x } else { x };
                }
            }
        }
    }
    out
}

/// A unit-Frobenius random direction rounded to `T`.
fn direction<T: Real, const D: usize>(rng: &mut Pcg64) -> Mat<f64, D> {
    let mut m = Mat::<f64, D>::ZERO;
    for j in 0..D {
        for i in 0..D {
            m.cols[j][i] = rng.random_range(-1.0..=1.0);
        }
    }
    let n = m.norm_squared().sqrt();
    crate::families::round_to::<T, D>(&(m * (1.0 / n)))
}

/// Runs every method of dimension `D` in precision `T` over `families`.
fn run_dim<T: Real, const D: usize>(size: Size, families: &[Family], cells: &mut Vec<Cell>)
where
    Dim<D>: ReferenceDim<M = Mat<Dd, D>> + MethodsOf<T, D>,
    Mat<f64, D>: FamilyDim,
    Mat<T, D>: Matrix<Scalar = T, Vector = [T; D]>,
    Mat<Dd, D>: Matrix<Scalar = Dd, Vector = [Dd; D]>,
{
    for &fam in families {
        // The McAdams sweep variants (for the speed–accuracy chart) run on every family in the
        // reduced size, only on the Haar family in the full size (to keep it under 2 minutes).
        let all_sweeps = size == Size::Reduced || fam == Family::HaarLogUniform;
        let runners = <Dim<D> as MethodsOf<T, D>>::methods(all_sweeps);
        let cases = generate::<T, D>(fam, size);
        let mut rng = Pcg64::seed_from_u64(0x2e_f00d ^ (fam as u64));
        let mut fam_cells: Vec<(Cell, Viol)> = runners
            .iter()
            .map(|r| {
                (
                    Cell {
                        method: r.spec(),
                        precision: T::NAME,
                        family: fam,
                        n_cases: 0,
                        err: Default::default(),
                        raw: Default::default(),
                        points: Vec::new(),
                        statuses: StatusCounts::default(),
                        violations: Vec::new(),
                        n_violations: 0,
                    },
                    Viol {
                        msgs: Vec::new(),
                        n: 0,
                    },
                )
            })
            .collect();
        // The representative of the current orbit (full integer families), see `Case::orbit`.
        let mut rep: Option<(u32, reference::Reference<D>, Mat<f64, D>)> = None;
        for (index, case) in cases.iter().enumerate() {
            let (z, rf) = match (case.orbit, &rep) {
                (Some((r, p, q)), Some((ri, rr, rz))) if r == *ri => {
                    let (p, q) = (signed_perm::<D>(p), signed_perm::<D>(q));
                    (p * *rz * q, Some(transform(rr, &p, &q)))
                }
                _ => {
                    let z = direction::<T, D>(&mut rng);
                    let rf = if case.f.is_finite() {
                        reference::reference::<D>(MU, &case.f, &z).ok()
                    } else {
                        None
                    };
                    if let Some(msg) = rf.as_ref().and_then(|r| reference_error(&case.f, &r.svd)) {
                        // The reference's own method fails here: nothing can be measured.
                        let fp = pad3(&case.f);
                        for (cell, viol) in &mut fam_cells {
                            viol.add(&fp, D, format!("{msg}: case not measured"));
                            cell.n_cases += 1;
                        }
                        rep = None;
                        continue;
                    }
                    if let Some(r) = &rf {
                        rep = Some((index as u32, *r, z));
                    }
                    (z, rf)
                }
            };
            let sc = rf.as_ref().map(|r| {
                let s: Vec<f64> = r.svd.sigma.iter().map(|x| x.to_f64()).collect();
                let sh: Option<Vec<f64>> = r
                    .kernels
                    .as_ref()
                    .map(|k| k.sigma_hat.iter().map(|x| x.to_f64()).collect());
                let mut sc = scales::<T, D>(&case.f, &s, sh.as_deref());
                // The reference's kernels are the library's own generic ones run in
                // double-double: refusing a J > 0 that is not singular to working precision
                // is their failure, and would pass off the same failure of the method's
                // kernels as the J ≤ 0 contract.
                sc.reference_kernels_failed =
                    r.kernels.is_none() && sc.j_positive && !sc.near_singular;
                if sc.reference_kernels_failed {
                    let fp = pad3(&case.f);
                    for (_, viol) in &mut fam_cells {
                        viol.add(
                            &fp,
                            D,
                            "reference kernels refused J > 0 (not singular to working \
                             precision): kernels not measured"
                                .into(),
                        );
                    }
                }
                sc
            });
            for (r, (cell, viol)) in runners.iter().zip(fam_cells.iter_mut()) {
                measure_case::<T, D>(r.as_ref(), fam.contract(), case, &z, &rf, &sc, cell, viol);
            }
        }
        for (mut cell, viol) in fam_cells {
            cell.violations = viol.msgs;
            cell.n_violations = viol.n;
            cells.push(cell);
        }
    }
}

/// A dimension the stability measurement runs in (2 and 3), for any precision `T`.
pub trait Measure<T: Real> {
    /// Appends the cells of every method of this dimension over `families` to `cells`.
    fn measure(size: Size, families: &[Family], cells: &mut Vec<Cell>);
}

impl<T: Real + FastPaths<2>> Measure<T> for Dim<2> {
    fn measure(size: Size, families: &[Family], cells: &mut Vec<Cell>) {
        run_dim::<T, 2>(size, families, cells);
    }
}

impl<T: Real + FastPaths<3>> Measure<T> for Dim<3> {
    fn measure(size: Size, families: &[Family], cells: &mut Vec<Cell>) {
        run_dim::<T, 3>(size, families, cells);
    }
}

/// Runs every method of one dimension `D` in one precision `T` over `families`.
#[must_use]
pub fn run_one<T: Real, const D: usize>(size: Size, families: &[Family]) -> Report
where
    Dim<D>: Measure<T>,
{
    let mut cells = Vec::new();
    <Dim<D> as Measure<T>>::measure(size, families, &mut cells);
    Report { size, cells }
}

/// Runs every method × family × precision × dim at `size`.
#[must_use]
pub fn run(size: Size) -> Report {
    run_families(size, &Family::ALL)
}

/// Runs every method × precision × dim over the given families.
#[must_use]
pub fn run_families(size: Size, families: &[Family]) -> Report {
    let mut cells = Vec::new();
    run_dim::<f64, 3>(size, families, &mut cells);
    run_dim::<f32, 3>(size, families, &mut cells);
    run_dim::<f64, 2>(size, families, &mut cells);
    run_dim::<f32, 2>(size, families, &mut cells);
    Report { size, cells }
}
