//! The stability contracts of every method × dim × precision on every family, and the
//! double-double reference itself.
//!
//! The contracts and error units are those of `ampm_tools::stability` (derivations there).
//! The measurement runs in the reduced size (a seeded subset of the 5⁹ integer matrices, a few
//! draws per parameter), one `#[test]` per dim × precision so the harness runs them in
//! parallel.
use ampm_core::{Mat, Matrix, Real};
use ampm_tools::families::{generate, Family, Size};
use ampm_tools::reference::{self, Dd};
use ampm_tools::stability::{self, Report, BOUND_RECON};

fn assert_no_violations(rep: &Report) {
    let v = rep.violations();
    assert!(
        v.is_empty(),
        "{} contract violations:\n{}",
        v.len(),
        v.join("\n")
    );
    // Every method × family actually measured something.
    for c in &rep.cells {
        assert!(c.n_cases > 0, "{:?} {:?} is empty", c.method, c.family);
    }
}

/// Runs the reduced families for one dim × precision and checks every contract.
macro_rules! contract_test {
    ($name:ident, $t:ty, $d:literal) => {
        #[test]
        fn $name() {
            let rep = stability::run_one::<$t, $d>(Size::Reduced, &Family::ALL);
            assert_no_violations(&rep);
            // The chart data: one curve per method on the kink (R) and J → 0 (Â) families,
            // one Haar p99 per method.
            let n_methods = rep
                .cells
                .iter()
                .filter(|c| c.family == Family::Kink)
                .count();
            for (fam, q) in [
                (Family::Kink, stability::Quantity::R),
                (Family::JToZero, stability::Quantity::Ahat),
            ] {
                let curves = stability::curves(&rep, fam, q, $d);
                assert_eq!(curves.len(), n_methods, "{fam:?}");
                for (label, pts) in &curves {
                    assert!(pts.len() >= 5, "{label}: {pts:?}");
                    assert!(pts.windows(2).all(|w| w[0].0 < w[1].0), "{label}: unsorted");
                }
            }
            assert_eq!(stability::haar_p99(&rep).len(), n_methods);
            // The accurate methods are actually accurate on the Haar family (a bound that a
            // wrong reference or a wrong unit would break): p99 of R and Σ below BOUND_RECON.
            for c in rep
                .cells
                .iter()
                .filter(|c| c.family == Family::HaarLogUniform)
            {
                if stability::bound(&c.method, stability::Quantity::R).is_finite() {
                    for q in [stability::Quantity::R, stability::Quantity::Sigma] {
                        let p = c.p99(q, false).expect("measured");
                        assert!(p < BOUND_RECON, "{:?} {q:?} p99 {p}", c.method);
                    }
                }
            }
        }
    };
}

contract_test!(contracts_3d_f64, f64, 3);
contract_test!(contracts_3d_f32, f32, 3);
contract_test!(contracts_2d_f64, f64, 2);
contract_test!(contracts_2d_f32, f32, 2);

/// The reference SVD reconstructs `F` and is orthonormal to double-double accuracy:
/// [`stability::BOUND_REFERENCE`] `= BOUND_RECON·ε_dd ≈ 1.3e-29` (the same backward-error
/// bound as the f64 methods, in units of the double-double ε = 2⁻¹⁰⁴), relative to
/// `max(‖F‖, 2⁻⁹⁶⁹)` (below that the trailing word of a double-double is subnormal), in 2D and
/// 3D, on the matrices of every finite family rounded to f64 and to f32. (The stability
/// measurement checks the same at every case it uses.)
#[test]
fn reference_is_double_double_accurate() {
    fn check<T: Real, const D: usize>(failures: &mut Vec<String>) -> usize
    where
        reference::Dim<D>: reference::ReferenceDim<M = Mat<Dd, D>>,
        Mat<f64, D>: ampm_tools::families::FamilyDim,
        Mat<Dd, D>: Matrix<Scalar = Dd, Vector = [Dd; D]>,
    {
        let mut checked = 0;
        for fam in Family::ALL.into_iter().filter(|f| *f != Family::NonFinite) {
            for case in generate::<T, D>(fam, Size::Reduced).iter().take(200) {
                let svd = reference::svd::<D>(&case.f).expect("finite");
                if let Some(e) = stability::reference_error(&case.f, &svd) {
                    failures.push(format!(
                        "{D}D {} {fam:?} F = {:?}: {e}",
                        T::NAME,
                        case.f.cols
                    ));
                }
                checked += 1;
            }
        }
        checked
    }
    let mut failures = Vec::new();
    let checked = check::<f64, 3>(&mut failures)
        + check::<f32, 3>(&mut failures)
        + check::<f64, 2>(&mut failures)
        + check::<f32, 2>(&mut failures);
    assert!(
        failures.is_empty(),
        "{} of {checked} reference SVDs not accurate, e.g.:\n{}",
        failures.len(),
        failures[..failures.len().min(8)].join("\n")
    );
    assert!(checked > 4000, "{checked}");
}
