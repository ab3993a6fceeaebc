//! Scale robustness: `F = 2ᵏG` gives the bits of `G` scaled (subnormals and overflow
//! included), `F = fl(10ᵏG)` the same to rounding; a result that is not representable is
//! `Error::Overflow`. A liquid (`μ = 0`) gives exact zeros, also for a subnormal `F`.
use super::*;

// ---------------------------------------------------------------------------------------------
// 6. Scale robustness: powers of two (exact) and of ten; overflow.
// ---------------------------------------------------------------------------------------------

/// `x · 2ᵉ` with one rounding (libm's `scalbn`), inf on overflow.
fn scalbn_mat<M: Matrix>(m: &M, e: i32) -> M {
    m.map(|x| x.scalbn(e))
}

/// Expected result `x_ref · 2ᵉ` of a kernel whose result is exactly `2ᵉ` times the reference:
/// `Err(Overflow)` when that overflows, else every entry equal, except that a subnormal entry
/// may differ by one unit of the subnormal spacing (the kernel scales in two steps, which may
/// round twice below `MIN_POSITIVE`; the exact value is not representable there anyway).
#[track_caller]
fn assert_scaled<M: Matrix>(got: Res<M>, reference: &M, e: i32, ctx: &dyn std::fmt::Debug) {
    let want = scalbn_mat(reference, e);
    if !want.is_finite() {
        assert_eq!(got, Err(Error::Overflow), "2^{e} · {reference:?}\n{ctx:#?}");
        return;
    }
    let got = got.unwrap_or_else(|err| panic!("{err:?} for 2^{e} · {reference:?}\n{ctx:#?}"));
    let tiny = M::Scalar::MIN_POSITIVE.to_f64() * eps::<M>(); // subnormal spacing
    for j in 0..M::DIM {
        for i in 0..M::DIM {
            let (g, w) = (got[(i, j)], want[(i, j)]);
            let ok = if w.abs() >= M::Scalar::MIN_POSITIVE {
                g.to_f64().to_bits() == w.to_f64().to_bits()
            } else {
                (g.to_f64() - w.to_f64()).abs() <= tiny
            };
            assert!(ok, "entry ({i},{j}): {g:?} != {w:?} (2^{e})\n{ctx:#?}");
        }
    }
}

/// `F = 2ᵏ G`: `Ψ̂(F) = Ψ̂(G)`, `Â(F) = 2⁻ᵏ Â(G)`, `Ĉ(F):Z = 2⁻²ᵏ Ĉ(G):Z`, bit for bit, for
/// `k` across the whole exponent range (f64: `1e-150 … 1e150` densely, then out to the
/// subnormals and near `MAX`; f32: `1e-18 … 1e18`, then out). Where `2⁻ᵏÂ(G)` or
/// `2⁻²ᵏĈ(G):Z` overflows, the kernel must return `Error::Overflow`, never inf or NaN.
///
/// The kernels pre-scale by a power of two, so `F` and `G` are reduced to the same matrix
/// and every bit of the result must agree. When `2ᵏG` is subnormal it is rounded: then `G`
/// is replaced by `G' = 2⁻ᵏ F` (exact), the matrix `F` actually represents.
pub(super) fn scale_pow2<M: Case>() {
    let mut rng = seeded(60 + M::DIM as u64 + 100 * M::Scalar::MANTISSA_DIGITS as u64);
    let wide = M::Scalar::MANTISSA_DIGITS > 24;
    // 2^498 ≈ 1e150, 2^59 ≈ 1e18.
    let (span, extremes): (i32, &[i32]) = if wide {
        (
            498,
            &[
                -1060, -1040, -1022, -1000, -700, -600, -540, -520, 520, 700, 1000, 1020,
            ],
        )
    } else {
        (
            59,
            &[
                -140, -130, -126, -100, -80, -66, -62, 62, 66, 80, 100, 120, 125,
            ],
        )
    };
    let mut ks: Vec<i32> = (-span..=span).step_by(if wide { 17 } else { 3 }).collect();
    ks.extend_from_slice(extremes);
    let (mut n_overflow, mut n_ok) = (0, 0);
    for _ in 0..N / 8 {
        let g: M = random_f(&mut rng);
        let z: M = random_z(&mut rng);
        let mu = random_mu::<M>(&mut rng);
        for &k in &ks {
            let f = scalbn_mat(&g, k);
            if !f.is_finite() {
                continue;
            }
            let g1 = scalbn_mat(&f, -k); // = g unless f is subnormal
            let ctx = (g, z, mu, k);
            let Ok(p) = M::psi_hat(mu, &g1) else {
                // G' lost its positive determinant to the subnormal rounding: F must agree.
                assert_eq!(M::psi_hat(mu, &f), M::psi_hat(mu, &g1), "{ctx:?}");
                continue;
            };
            let pf = M::psi_hat(mu, &f).unwrap();
            assert_eq!(pf.to_f64().to_bits(), p.to_f64().to_bits(), "Ψ̂ {ctx:?}");
            let a = M::ahat(mu, &g1).unwrap();
            let af = M::ahat(mu, &f);
            n_overflow += usize::from(af.is_err());
            n_ok += usize::from(af.is_ok());
            assert_scaled(af, &a, -k, &ctx);
            let c = M::chat_z(mu, &g1, &z).unwrap();
            assert_scaled(M::chat_z(mu, &f, &z), &c, -2 * k, &ctx);
        }
    }
    // The extremes must reach both outcomes, or the test proves nothing about overflow.
    assert!(
        n_overflow > 0 && n_ok > 0,
        "{n_overflow} overflows, {n_ok} ok"
    );
}

/// `F = fl(10ᵏ G)`: the same identities to rounding accuracy (f64: `k ∈ [−150, 150]`, f32:
/// `[−18, 18]`), plus beyond, where the result must be `Error::Overflow` when its magnitude
/// exceeds `MAX` (checked only outside a band of the tolerance around `MAX`).
///
/// Tolerances as in [`scale_identities`] (input rounding `ε/2‖F‖`, kernel errors), with the
/// comparison done in f64 (`10ᵏ`, `10²ᵏ` and the products exact to `ε_f64`); a result entry
/// that is subnormal also carries an absolute error of one subnormal spacing (two roundings:
/// see [`assert_scaled`]), scaled back by `s` or `s²`.
pub(super) fn scale_pow10<M: Case>() {
    let mut rng = seeded(70 + M::DIM as u64 + 100 * M::Scalar::MANTISSA_DIGITS as u64);
    let mut w = Worst::new::<M>("powers of ten");
    let wide = M::Scalar::MANTISSA_DIGITS > 24;
    let (span, extremes): (i32, &[i32]) = if wide {
        (150, &[-200, -160, 160, 200, 300])
    } else {
        (18, &[-30, -22, -20, 20, 22, 30])
    };
    let e = eps::<M>();
    let (kp, kk) = (k_psi::<M>(), k_ker::<M>());
    let max = M::Scalar::MAX.to_f64();
    let under = M::Scalar::MIN_POSITIVE.to_f64() * e * dim::<M>();
    let mut ks: Vec<i32> = (-span..=span).step_by(if wide { 5 } else { 1 }).collect();
    ks.extend_from_slice(extremes);
    let mut n_overflow = 0;
    for _ in 0..N / 8 {
        let g: M = random_f(&mut rng);
        let z: M = random_z(&mut rng);
        let mu = random_mu::<M>(&mut rng);
        let geo = geom(&g, mu.to_f64());
        let nz = fro(&z);
        let ka = kk * geo.kappa;
        let p = M::psi_hat(mu, &g).unwrap().to_f64();
        let a = to_na(&M::ahat(mu, &g).unwrap());
        let c = to_na(&M::chat_z(mu, &g, &z).unwrap());
        for &k in &ks {
            let s = 10f64.powi(k);
            let f = g * M::Scalar::from_f64(s);
            let ctx = (g, z, mu, k);
            let pf = M::psi_hat(mu, &f).unwrap().to_f64();
            let tol = 0.5 * e * geo.f_fro * geo.ahat + 2.0 * kp * e * geo.psi;
            w.check("Ψ̂(sG) − Ψ̂(G)", (pf - p).abs(), tol, &ctx);

            let rel_a = (0.5 * e * geo.f_fro * geo.chat + 2.0 * ka * e * geo.ahat) / a.norm();
            let want_a = a.amax() / s;
            match M::ahat(mu, &f) {
                Ok(af) => {
                    assert!(want_a <= max * (1.0 + rel_a), "Â should overflow {ctx:?}");
                    let tol = rel_a * a.norm() + under * s;
                    w.check("s·Â(sG) − Â(G)", (to_na(&af) * s - &a).norm(), tol, &ctx);
                }
                Err(err) => {
                    assert_eq!(err, Error::Overflow, "{ctx:?}");
                    assert!(want_a >= max * (1.0 - rel_a), "spurious overflow {ctx:?}");
                    n_overflow += 1;
                }
            }
            let s3 = 3.0 * geo.chat / geo.smin;
            let abs_c = (0.5 * e * geo.f_fro * s3 + 2.0 * ka * e * geo.chat) * nz;
            let rel_c = abs_c / c.norm();
            let want_c = c.amax() / (s * s);
            match M::chat_z(mu, &f, &z) {
                Ok(cf) if !(s * s).is_finite() => {
                    // s² > f64::MAX: the result is below the smallest normal, all underflow.
                    let tiny = M::Scalar::MIN_POSITIVE.to_f64();
                    assert!(cf.max_abs().to_f64() <= tiny, "{cf:?} {ctx:?}");
                }
                Ok(cf) => {
                    assert!(want_c <= max * (1.0 + rel_c), "Ĉ should overflow {ctx:?}");
                    let tol = abs_c + under * s * s;
                    w.check(
                        "s²·Ĉ(sG):Z − Ĉ(G):Z",
                        (to_na(&cf) * (s * s) - &c).norm(),
                        tol,
                        &ctx,
                    );
                }
                Err(err) => {
                    assert_eq!(err, Error::Overflow, "{ctx:?}");
                    assert!(want_c >= max * (1.0 - rel_c), "spurious overflow {ctx:?}");
                    n_overflow += 1;
                }
            }
        }
    }
    assert!(n_overflow > 0, "the extremes never overflowed");
    w.report();
}

// ---------------------------------------------------------------------------------------------
// 7. μ = 0.
// ---------------------------------------------------------------------------------------------

/// A liquid (`μ = 0`): `Ψ̂ = 0`, `Â = 0`, `Ĉ:Z = 0` exactly, for any valid `F` — including a
/// subnormal one, whose zero result is representable (not an overflow); likewise `Ĉ:0 = 0`
/// for any `μ`; an invalid `F` is still refused.
pub(super) fn mu_zero<M: Case>() {
    let mut rng = seeded(80 + M::DIM as u64 + 100 * M::Scalar::MANTISSA_DIGITS as u64);
    let zero = M::Scalar::ZERO;
    // Largest entry of G in [0.25, 5]; 2^-(MANTISSA+…) makes F subnormal with ≥ 10 bits.
    let sub = if M::Scalar::MANTISSA_DIGITS > 24 {
        -1050
    } else {
        -135
    };
    for i in 0..N {
        let g: M = random_f(&mut rng);
        let z: M = random_z(&mut rng);
        let f = if i % 4 == 3 { scalbn_mat(&g, sub) } else { g };
        assert_eq!(M::psi_hat(zero, &f), Ok(zero), "{f:?}");
        assert_eq!(M::ahat(zero, &f), Ok(M::zero()), "{f:?}");
        assert_eq!(M::chat_z(zero, &f, &z), Ok(M::zero()), "{f:?} {z:?}");
        // Ĉ:0 = 0 for any μ, also representable for a subnormal F.
        let mu = random_mu::<M>(&mut rng);
        assert_eq!(
            M::chat_z(mu, &f, &M::zero()),
            Ok(M::zero()),
            "{f:?} μ = {mu:?}"
        );
    }
    let mut bad = M::identity();
    bad[(0, 0)] = -M::Scalar::ONE;
    assert_eq!(M::ahat(zero, &bad), Err(Error::NonPositiveJ));
    bad[(0, 0)] = M::Scalar::from_f64(f64::NAN);
    assert_eq!(M::psi_hat(zero, &bad), Err(Error::NonFinite));
}
