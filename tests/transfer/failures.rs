//! Failures of P2G and G2P: the status, the first index, and nothing written.
use crate::isas;
use crate::{materials, particles, DenseGrid, Store, HC, MOM, TM};
use ampm_core::particle::transfer::g2p::{self, G2pArgs};
use ampm_core::particle::transfer::p2g::{self, P2gArgs};
use ampm_core::particle::{Grid, Kernel, Particle};
use ampm_core::Error;
use rand::SeedableRng;
use rand_pcg::Pcg64;

/// Failures: the status, the first index, nothing written.
#[test]
fn failures_write_nothing() {
    type T = f32;
    const D: usize = 3;
    let (cells, hf) = (12, 0.05f64);
    let h = hf as T;
    let (_, thermal) = materials::<T>()[2];
    for isa in isas() {
        let mut rng = Pcg64::seed_from_u64(1);
        let base = particles::<T, D>(&mut rng, 20, hf, cells, &thermal);
        type Case = (&'static str, usize, Box<dyn Fn(&mut Particle<T, D>)>, Error);
        let cases: Vec<Case> = vec![
            (
                "outside",
                3,
                Box::new(|p| p.x[1] = -0.1),
                Error::OutsideGrid,
            ),
            (
                "m·v overflows",
                4,
                Box::new(|p| {
                    p.mass = 1.0e30;
                    p.v[0] = 1.0e10;
                }),
                Error::Overflow,
            ),
            (
                "m·c·T overflows",
                5,
                Box::new(|p| p.temperature = 1.0e38),
                Error::Overflow,
            ),
            (
                "NaN velocity",
                6,
                Box::new(|p| p.v[2] = T::NAN),
                Error::NonFinite,
            ),
        ];
        for (name, k, spoil, err) in cases {
            let mut ps = base.clone();
            spoil(&mut ps[k]);
            let mut store = Store::from(&ps);
            let mut g = DenseGrid::<T, D>::new([-1; D], [cells + 2; D]);
            let args = P2gArgs {
                kernel: Kernel::Quadratic,
                grid: Grid::Collocated,
                h,
                impulse_dt: 0.0,
            };
            // Only particle k, then everything: the grid of the batch equals that of the batch
            // without particle k (bit for bit: same order of sums).
            let raw = store.raw();
            // SAFETY: the arrays hold the particles; the channels cover the box.
            let st = unsafe { p2g::p2g(isa, &thermal, &args, ps.len(), &raw, &g.p2g_view()) };
            assert_eq!(
                (st.first_failed, st.error),
                (k, Some(err)),
                "{name} {isa:?}"
            );
            let mut without = ps.clone();
            without.remove(k);
            let mut s2 = Store::from(&without);
            let mut g2 = DenseGrid::<T, D>::new([-1; D], [cells + 2; D]);
            // SAFETY: as above.
            unsafe {
                p2g::p2g(
                    isa,
                    &thermal,
                    &args,
                    without.len(),
                    &s2.raw(),
                    &g2.p2g_view(),
                )
            };
            assert_eq!(
                g.bits(),
                g2.bits(),
                "{name}: the failed particle wrote nothing"
            );
        }
        // Sums that would overflow a node value: the particle is refused, the node untouched.
        let mut ps = base.clone();
        ps[2].mass = 1.0e30;
        ps[2].v = [5.0e7; D];
        let mut store = Store::from(&ps);
        let mut g = DenseGrid::<T, D>::new([-1; D], [cells + 2; D]);
        for x in g.ch[MOM].iter_mut() {
            *x = 3.3e38;
        }
        let before = g.bits();
        let args = P2gArgs {
            kernel: Kernel::Quadratic,
            grid: Grid::Collocated,
            h,
            impulse_dt: 0.0,
        };
        let one = [ps[2]];
        let mut s1 = Store::from(&one);
        // SAFETY: as above.
        let st = unsafe { p2g::p2g(isa, &thermal, &args, 1, &s1.raw(), &g.p2g_view()) };
        assert_eq!(st.error, Some(Error::Overflow));
        assert_eq!(g.bits(), before);
        let _ = &mut store;
        // A tiny finite h with a velocity field that varies across the stencil: every input
        // is finite, so the result is either finite or Overflow (never NonFinite), and a
        // failure writes nothing. (1/(κh²) is never formed: C_p uses 1/(κh).)
        for hh in [1.0e-30 as T, 1.0e-37] {
            let mut tiny = base[..1].to_vec();
            tiny[0].x = [3.3 * hh; D];
            let mut s3 = Store::from(&tiny);
            let mut g3 = DenseGrid::<T, D>::new([-1; D], [8; D]);
            for k in 0..g3.ch[0].len() {
                g3.ch[MOM][k] = (k % 5) as T;
            }
            g3.ch[HC].iter_mut().for_each(|x| *x = TM as T);
            g3.ch[HC + 1].iter_mut().for_each(|x| *x = TM as T);
            let gargs = G2pArgs {
                kernel: Kernel::Quadratic,
                h: hh,
                dt: 1.0e-3,
            };
            let raw = s3.raw();
            // SAFETY: as above.
            let st =
                unsafe { g2p::g2p_update(isa, &thermal, &gargs, 1, &raw, &g3.g2p_view(), None) };
            match st.error {
                None => {
                    let q = s3.get::<D>(0);
                    assert!(q.affine.is_finite() && q.f_e.is_finite(), "h = {hh}");
                }
                Some(e) => {
                    assert_eq!(e, Error::Overflow, "h = {hh}");
                    assert_eq!(s3, Store::from(&tiny));
                }
            }
        }
    }
}
