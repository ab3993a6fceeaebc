//! Accuracy against an independent method: the generic four-term formulas of `augmented` with
//! the QR SVD (another decomposition, other formulas), 1e-11 relative in f64 and 1e-4 in f32 on
//! σ ∈ [0.2, 5].
use super::*;
use ampm_core::augmented;
use ampm_core::energy::FixedCorotated;
use ampm_core::polar::{QrSvd, SvdMethod};

// ---------------------------------------------------------------------------------------
// 4. Accuracy against an independent method.

fn accuracy<T: BatchReal, const D: usize>(tol: f64)
where
    Dim<D>: LaneDim<D>,
    Mat<f64, D>: Matrix<Scalar = f64, Vector = [f64; D]> + HaarRotation,
    Mat<T, D>: Matrix<Scalar = T>,
    QrSvd: SvdMethod<Mat<f64, D>>,
{
    let e = D * D;
    let mut rng = Pcg64::seed_from_u64(7);
    let n = 400;
    let fs: Vec<Mat<f64, D>> = (0..n).map(|_| family::<D>(&mut rng, 0.2, 5.0)).collect();
    let zs: Vec<Mat<f64, D>> = (0..n)
        .map(|_| {
            Mat::from_cols(std::array::from_fn(|_| {
                std::array::from_fn(|_| rng.random_range(-1.0..1.0))
            }))
        })
        .collect();
    let mu: Vec<T> = vec![T::from_f64(3.0); n];
    let f: Vec<T> = fs
        .iter()
        .flat_map(|m| m.cast::<T>().cols.concat())
        .collect();
    let z: Vec<T> = zs
        .iter()
        .flat_map(|m| m.cast::<T>().cols.concat())
        .collect();
    for isa in Isa::available() {
        let mut a = vec![T::ZERO; e * n];
        let mut c = vec![T::ZERO; e * n];
        let out = Outputs {
            ahat: Some(&mut a),
            chat_z: Some(&mut c),
            energy: None,
            psd: false,
        };
        let st = batch::ahat_chat_z::<T, D>(isa, &mu, &f, Some(&z), out).unwrap();
        assert_eq!(st.error, None);
        let (mut wa, mut wc) = (0.0f64, 0.0f64);
        for i in 0..n {
            // The reference: the inputs as rounded to T, in f64, through the general
            // four-term formulas of `augmented` with another decomposition (QR).
            let fi = fs[i].cast::<T>().cast::<f64>();
            let zi = zs[i].cast::<T>().cast::<f64>();
            let en = FixedCorotated::with_method(3.0, QrSvd::default());
            let ra = augmented::ahat(&en, &fi).unwrap();
            let rc = augmented::chat_z(&en, &fi, &zi).unwrap();
            let na = ra.ddot(&ra).sqrt();
            let nc = rc.ddot(&rc).sqrt();
            wa = wa.max(rel(&a[i * e..(i + 1) * e], &ra.cols.concat(), na.max(3.0)));
            wc = wc.max(rel(&c[i * e..(i + 1) * e], &rc.cols.concat(), nc.max(3.0)));
        }
        assert!(
            wa <= tol && wc <= tol,
            "{isa:?} {D}D {}: Â {wa:e}, Ĉ:Z {wc:e}",
            T::NAME
        );
    }
}

#[test]
fn accuracy_f64() {
    accuracy::<f64, 3>(1e-11);
}
#[test]
fn accuracy_f32() {
    accuracy::<f32, 3>(1e-4);
}
