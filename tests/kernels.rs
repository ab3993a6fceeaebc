//! Quick end-to-end check of the kernels against central finite differences (f64).
use ampm_core::augmented::{self, Augmented};
use ampm_core::energy::FixedCorotated;
use ampm_core::{Mat, Matrix};

fn fd_check<const D: usize>(f: Mat<f64, D>, z: Mat<f64, D>)
where
    Mat<f64, D>: Matrix<Scalar = f64>,
    ampm_core::polar::DefaultSvd: ampm_core::polar::SvdMethod<Mat<f64, D>>,
{
    let e = FixedCorotated::new(3.0);
    let st = Augmented::new(&e, &f).unwrap();
    let ahat = st.ahat().unwrap();
    let cz = st.chat_z(&z).unwrap();
    let h = 1e-5;
    let psi = |g: &Mat<f64, D>| augmented::psi_hat(&e, g).unwrap();
    let fd_a = (psi(&(f + z * h)) - psi(&(f - z * h))) / (2.0 * h);
    let an_a = ahat.ddot(&z);
    assert!(
        (fd_a - an_a).abs() < 1e-7 * (1.0 + an_a.abs()),
        "{fd_a} {an_a}"
    );
    let ap = augmented::ahat(&e, &(f + z * h)).unwrap();
    let am = augmented::ahat(&e, &(f - z * h)).unwrap();
    let fd_c = (ap - am) * (0.5 / h);
    let err = (fd_c - cz).max_abs();
    assert!(err < 1e-6 * (1.0 + cz.max_abs()), "{fd_c:?} {cz:?}");
}

#[test]
fn fd_3d() {
    let f = Mat::<f64, 3>::from_rows([[1.2, 0.3, -0.1], [0.2, 0.8, 0.4], [-0.3, 0.1, 1.5]]);
    let z = Mat::<f64, 3>::from_rows([[0.3, -0.7, 0.2], [0.5, 0.1, -0.4], [0.9, 0.6, 0.2]]);
    fd_check(f, z);
}

#[test]
fn fd_2d() {
    let f = Mat::<f64, 2>::from_rows([[1.2, 0.3], [-0.4, 0.7]]);
    let z = Mat::<f64, 2>::from_rows([[0.3, -0.7], [0.5, 0.1]]);
    fd_check(f, z);
}
