//! Unit tests of the particle update's checks.

use super::*;

fn plastic() -> Material<f32> {
    Material {
        plasticity: Some(super::super::Snow {
            critical_compression: 0.025,
            critical_stretch: 0.0075,
            hardening: 10.0,
        }),
        ..Material::elastic(10.0, 10.0)
    }
}

fn still() -> G2pSample<f32, 2> {
    G2pSample {
        v: [0.0; 2],
        affine: Mat::ZERO,
        grad_v: Mat::ZERO,
        t_pic: f32::NAN,
        t_flip: f32::NAN,
    }
}

/// `J_P = 2⁻¹²⁶` compressed by `(2⁻¹⁶/0.975)²` underflows to 0: Overflow, not `Ok`.
#[test]
fn j_p_underflow_is_overflow() {
    let mut p = Particle::<f32, 2>::at_rest([0.3; 2], 1.0, 1.0);
    p.f_p = Mat::from_diagonal([2f32.powi(-63); 2]);
    p.f_e = Mat::from_diagonal([2f32.powi(-16); 2]);
    assert!(check_particle(&p).is_ok());
    assert_eq!(
        update_particle(&plastic(), 1e-3, &still(), &p).map(|_| ()),
        Err(Error::Overflow)
    );
}

/// An `F_E` and `F_P` stretched past `1/ε`: the plastic flow's `F_P` loses its
/// determinant (refused); the liquid projection needs the determinants only (kept).
#[test]
fn ill_conditioned_flow() {
    let mut p = Particle::<f32, 2>::at_rest([0.3; 2], 1.0, 1.0);
    p.f_e = Mat::from_cols([[-843.1956, -1033.6561], [-235.58327, -288.79782]]);
    p.f_p = Mat::from_cols([[-566.16144, -1102.0168], [282.9347, 550.7224]]);
    assert!(check_particle(&p).is_ok());
    let r = update_particle(&plastic(), 1e-3, &still(), &p);
    assert!(
        matches!(r, Err(Error::NonPositiveJ | Error::Overflow)),
        "{r:?}"
    );
    p.phase = Phase::Liquid;
    let liquid = Material {
        liquid: super::super::PhaseParams {
            inv_lambda: 0.1,
            ..Default::default()
        },
        ..Material::default()
    };
    let (q, _) = update_particle(&liquid, 1e-3, &still(), &p).unwrap();
    assert!(check_particle(&q).is_ok());
}

/// `m |v| > MAX`: Overflow, where every node used to be written as inf.
#[test]
fn p2g_momentum_overflow() {
    let mut p = Particle::<f32, 2>::at_rest([0.3; 2], 1e30, 1.0);
    p.v = [1e10, 0.0];
    let m = Material::elastic(10.0, 10.0);
    assert_eq!(
        p2g(&m, Kernel::Quadratic, 0.5, &p).map(|_| ()),
        Err(Error::Overflow)
    );
    p.v = [1e7, 0.0];
    let q = p2g(&m, Kernel::Quadratic, 0.5, &p).unwrap();
    assert!((0..q.stencil.len()).all(|r| q.node_checked(r).is_ok()));
}
