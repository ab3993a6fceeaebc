//! Batch entry points (`ahat_batch`, `chat_z_batch`):
//!
//! - Success gives the core API's result bit for bit, that of the instruction set `ampm_isa()`
//!   reports, also in place (`out == F`, `out == Z`).
//! - Batch calls compute every valid particle, leave failed ones untouched, return the first
//!   failure's status and index, accept a NULL `first_failed` and NULL arrays when `n = 0`,
//!   and refuse an `n` whose byte size overflows without touching memory.
use super::*;
use ampm::AmpmStatus::*;
use std::ptr;

// ---------------------------------------------------------------------------------------------
// Batches.
// ---------------------------------------------------------------------------------------------

/// One particle of a batch.
#[derive(Clone, Copy, Debug)]
struct Particle<M: Matrix> {
    mu: M::Scalar,
    f: M,
    z: M,
}

/// A way to spoil a particle: its name, the status it must give, the change.
type Spoiler<M> = (&'static str, AmpmStatus, fn(&mut Particle<M>));

/// Ways to spoil a particle, with the status each must give.
fn spoilers<M: Abi>() -> Vec<Spoiler<M>> {
    vec![
        ("NaN μ", AMPM_ERR_NON_FINITE, |p| p.mu = t::<M>(f64::NAN)),
        ("inf μ", AMPM_ERR_NON_FINITE, |p| {
            p.mu = t::<M>(f64::INFINITY)
        }),
        ("-inf μ", AMPM_ERR_NON_FINITE, |p| {
            p.mu = t::<M>(f64::NEG_INFINITY)
        }),
        ("NaN F", AMPM_ERR_NON_FINITE, |p| {
            p.f[(1, 1)] = t::<M>(f64::NAN)
        }),
        ("inf F", AMPM_ERR_NON_FINITE, |p| {
            p.f[(0, 1)] = t::<M>(f64::INFINITY)
        }),
        ("-inf F", AMPM_ERR_NON_FINITE, |p| {
            p.f[(1, 0)] = t::<M>(f64::NEG_INFINITY)
        }),
        ("NaN Z", AMPM_ERR_NON_FINITE, |p| {
            p.z[(1, 0)] = t::<M>(f64::NAN)
        }),
        ("inf Z", AMPM_ERR_NON_FINITE, |p| {
            p.z[(0, 0)] = t::<M>(f64::INFINITY)
        }),
        ("-inf Z", AMPM_ERR_NON_FINITE, |p| {
            p.z[(0, 1)] = t::<M>(f64::NEG_INFINITY)
        }),
        ("det F < 0", AMPM_ERR_NON_POSITIVE_J, |p| {
            for i in 0..M::DIM {
                p.f[(i, 0)] = -p.f[(i, 0)];
            }
        }),
        ("det F = 0", AMPM_ERR_NON_POSITIVE_J, |p| p.f = M::zero()),
        ("μ < 0", AMPM_ERR_INVALID_ARGUMENT, |p| p.mu = -p.mu),
        ("subnormal F", AMPM_ERR_OVERFLOW, |p| {
            p.f = subnormal_f::<M>()
        }),
    ]
}

/// Flattened batch arrays.
struct Arrays<T> {
    mu: Vec<T>,
    f: Vec<T>,
    z: Vec<T>,
}

fn arrays<M: Matrix>(ps: &[Particle<M>]) -> Arrays<M::Scalar> {
    Arrays {
        mu: ps.iter().map(|p| p.mu).collect(),
        f: ps
            .iter()
            .flat_map(|p| p.f.to_array().as_ref().to_vec())
            .collect(),
        z: ps
            .iter()
            .flat_map(|p| p.z.to_array().as_ref().to_vec())
            .collect(),
    }
}

/// Runs a batch with a sentinel output; returns (status, first_failed or None, output).
fn run_batch<M: Abi>(
    op: BatchOp,
    ps: &[Particle<M>],
    with_first_failed: bool,
) -> (AmpmStatus, Option<usize>, Vec<M::Scalar>) {
    let a = arrays(ps);
    let mut out = sentinel::<M>(ps.len() * M::LEN);
    let mut ff = usize::MAX;
    let ffp: *mut usize = if with_first_failed {
        &mut ff
    } else {
        ptr::null_mut()
    };
    // SAFETY: arrays hold ps.len() particles.
    let st = unsafe {
        call_batch::<M>(
            op,
            ps.len(),
            a.mu.as_ptr(),
            a.f.as_ptr(),
            a.z.as_ptr(),
            out.as_mut_ptr(),
            ffp,
        )
    };
    (st, with_first_failed.then_some(ff), out)
}

/// Checks a batch's outputs against single calls: good particles bit for bit, failed ones
/// untouched, status and `first_failed` of the first failure (`n` if none).
#[track_caller]
fn check_batch<M: Abi>(
    op: BatchOp,
    ps: &[Particle<M>],
    st: AmpmStatus,
    ff: Option<usize>,
    out: &[M::Scalar],
) {
    let mut first = None;
    for (i, p) in ps.iter().enumerate() {
        let chunk = &out[i * M::LEN..(i + 1) * M::LEN];
        match reference_on(c_isa(), op.single(), p.mu, &p.f, &p.z) {
            Ok(want) => assert_eq!(bits(chunk), bits(&want), "{op:?} particle {i} {p:?}"),
            Err(e) => {
                assert_untouched::<M>(chunk, &(op, i, p));
                first.get_or_insert((i, AmpmStatus::from(e)));
            }
        }
    }
    let (idx, status) = first.unwrap_or((ps.len(), AMPM_OK));
    assert_eq!(st, status, "{op:?}");
    if let Some(ff) = ff {
        assert_eq!(ff, idx, "{op:?} first_failed");
    }
}

/// Mixed good and bad particles: each spoiler as the first failure (index 2), followed by a
/// different failure (index 6), good particles and a liquid at a subnormal `F` (index 8);
/// all good; `first_failed` NULL.
pub(crate) fn batch_mixed<M: Abi>() {
    let mut rng = seeded::<M>(7);
    let sp = spoilers::<M>();
    for op in BATCH_OPS {
        for (k, (name, status, spoil)) in sp.iter().enumerate() {
            let mut ps: Vec<Particle<M>> = (0..9)
                .map(|_| Particle {
                    mu: random_mu::<M>(&mut rng),
                    f: random_f::<M>(&mut rng),
                    z: random_z::<M>(&mut rng),
                })
                .collect();
            let (st0, ff0, out0) = run_batch(op, &ps, true);
            check_batch(op, &ps, st0, ff0, &out0);
            assert_eq!((st0, ff0), (AMPM_OK, Some(ps.len())), "all good");

            spoil(&mut ps[2]);
            let (_, _, later) = sp[(k + 1) % sp.len()];
            later(&mut ps[6]);
            // A liquid at a subnormal F: every result is 0 and representable, in the batch
            // path as in the single-particle one.
            ps[8].mu = M::Scalar::ZERO;
            ps[8].f = subnormal_f::<M>();
            if op == BatchOp::Ahat && name.ends_with(" Z") {
                // Â ignores Z: this particle is good for the Â batch.
                assert!(reference(Op::Ahat, ps[2].mu, &ps[2].f, &ps[2].z).is_ok());
            } else {
                assert_eq!(
                    reference(op.single(), ps[2].mu, &ps[2].f, &ps[2].z)
                        .err()
                        .map(AmpmStatus::from),
                    Some(*status),
                    "{name}"
                );
            }
            let (st, ff, out) = run_batch(op, &ps, true);
            check_batch(op, &ps, st, ff, &out);
            let (st_null, ff_null, out_null) = run_batch(op, &ps, false);
            assert_eq!(
                (st_null, ff_null, bits(&out_null)),
                (st, None, bits(&out)),
                "NULL first_failed"
            );
        }
    }
}

/// In place: `out == F` (and `out == Z` for Ĉ:Z) over the whole batch, with a failure inside.
pub(crate) fn batch_in_place<M: Abi>() {
    let mut rng = seeded::<M>(8);
    for op in BATCH_OPS {
        let mut ps: Vec<Particle<M>> = (0..5)
            .map(|_| Particle {
                mu: random_mu::<M>(&mut rng),
                f: random_f::<M>(&mut rng),
                z: random_z::<M>(&mut rng),
            })
            .collect();
        ps[3].mu = -ps[3].mu;
        let (st, ff, out) = run_batch(op, &ps, true);
        let aliases: &[&str] = if op == BatchOp::Chat {
            &["f", "z"]
        } else {
            &["f"]
        };
        for which in aliases {
            let mut a = arrays(&ps);
            let mut ff2 = usize::MAX;
            let buf = if *which == "f" { &mut a.f } else { &mut a.z };
            let p = buf.as_mut_ptr();
            let (fp, zp) = if *which == "f" {
                (p as *const _, a.z.as_ptr())
            } else {
                (a.f.as_ptr(), p as *const _)
            };
            // SAFETY: arrays hold 5 particles; out aliases one input array exactly.
            let st2 = unsafe { call_batch::<M>(op, ps.len(), a.mu.as_ptr(), fp, zp, p, &mut ff2) };
            let buf = if *which == "f" { &a.f } else { &a.z };
            assert_eq!((st2, Some(ff2)), (st, ff), "{op:?} out == {which}");
            for i in 0..ps.len() {
                let chunk = &buf[i * M::LEN..(i + 1) * M::LEN];
                if i == 3 {
                    // Failed particle: its input (= output) is untouched.
                    let orig = if *which == "f" { ps[i].f } else { ps[i].z };
                    assert_eq!(
                        bits(chunk),
                        bits(orig.to_array().as_ref()),
                        "{op:?} {which} {i}"
                    );
                } else {
                    assert_eq!(
                        bits(chunk),
                        bits(&out[i * M::LEN..(i + 1) * M::LEN]),
                        "{op:?} {which} {i}"
                    );
                }
            }
        }
    }
}

/// `n = 0` with NULL arrays → OK (`first_failed` = 0); NULL arrays with `n > 0` → NULL_POINTER;
/// `n` whose byte size overflows (`usize` or `isize::MAX`) → INVALID_ARGUMENT; on both
/// whole-call errors nothing is written but `first_failed` = 0.
pub(crate) fn batch_arguments<M: Abi>() {
    let mut rng = seeded::<M>(9);
    let ps: Vec<Particle<M>> = (0..3)
        .map(|_| Particle {
            mu: random_mu::<M>(&mut rng),
            f: random_f::<M>(&mut rng),
            z: random_z::<M>(&mut rng),
        })
        .collect();
    let a = arrays(&ps);
    let sz = M::LEN * std::mem::size_of::<M::Scalar>();
    for op in BATCH_OPS {
        let mut ff = usize::MAX;
        // SAFETY: n = 0: nothing may be read or written but first_failed.
        let st = unsafe {
            call_batch::<M>(
                op,
                0,
                ptr::null(),
                ptr::null(),
                ptr::null(),
                ptr::null_mut(),
                &mut ff,
            )
        };
        assert_eq!((st, ff), (AMPM_OK, 0), "{op:?} n = 0");
        // SAFETY: as above.
        let st = unsafe {
            call_batch::<M>(
                op,
                0,
                ptr::null(),
                ptr::null(),
                ptr::null(),
                ptr::null_mut(),
                ptr::null_mut(),
            )
        };
        assert_eq!(st, AMPM_OK, "{op:?} n = 0, NULL first_failed");

        let null_args: &[&str] = if op == BatchOp::Chat {
            &["mu", "f", "z", "out"]
        } else {
            &["mu", "f", "out"]
        };
        for which in null_args {
            let mut out = sentinel::<M>(ps.len() * M::LEN);
            let mut ff = usize::MAX;
            let nul = |w: &str, p: *const M::Scalar| if *which == w { ptr::null() } else { p };
            let o = if *which == "out" {
                ptr::null_mut()
            } else {
                out.as_mut_ptr()
            };
            // SAFETY: non-null arrays hold 3 particles.
            let st = unsafe {
                call_batch::<M>(
                    op,
                    ps.len(),
                    nul("mu", a.mu.as_ptr()),
                    nul("f", a.f.as_ptr()),
                    nul("z", a.z.as_ptr()),
                    o,
                    &mut ff,
                )
            };
            assert_eq!(st, AMPM_ERR_NULL_POINTER, "{op:?} NULL {which}");
            assert_untouched::<M>(&out, &(op, which));
            assert_eq!(ff, 0, "{op:?} NULL {which}: first_failed");
        }

        for n in [
            usize::MAX / sz + 1,
            (isize::MAX as usize) / sz + 1,
            usize::MAX,
        ] {
            let mut out = sentinel::<M>(ps.len() * M::LEN);
            let mut ff = usize::MAX - 1;
            // SAFETY: the call must refuse n before touching any array (they hold 3 particles).
            let st = unsafe {
                call_batch::<M>(
                    op,
                    n,
                    a.mu.as_ptr(),
                    a.f.as_ptr(),
                    a.z.as_ptr(),
                    out.as_mut_ptr(),
                    &mut ff,
                )
            };
            assert_eq!(st, AMPM_ERR_INVALID_ARGUMENT, "{op:?} n = {n}");
            assert_untouched::<M>(&out, &(op, n));
            assert_eq!(ff, 0, "{op:?} n = {n}: first_failed");
        }
    }
}
