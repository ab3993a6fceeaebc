//! G2P and the force differential read node vector fields in three layouts that take different
//! read paths: separate arrays with shared strides (whole-row loads, one row offset for every
//! component), interleaved node structs (strided reads), and separate arrays with different
//! strides (whole-row loads per channel), for node velocities and (with heat) node
//! temperatures. All three give the same bits, and every vector instruction set gives the same
//! bits as the others.
use crate::isas;
use crate::{materials, particles, DenseGrid, Store, FORCE, TM};
use ampm_core::kernel::batch::BatchReal;
use ampm_core::kernel::{Dim, LaneDim};
use ampm_core::lane::{Isa, IsaKind};
use ampm_core::particle::implicit::slot_len;
use ampm_core::particle::transfer::force::{self, ForceView};
use ampm_core::particle::transfer::g2p::{self, G2pArgs, G2pView};
use ampm_core::particle::transfer::{Channel, NodeBox};
use ampm_core::particle::Kernel;
use ampm_core::polar::{DefaultSvd, SvdMethod};
use ampm_core::{Mat, Matrix, Real};
use ampm_tools::workload::HaarRotation;
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;

/// One node vector field (`D` components) over a box, stored in the three layouts.
struct Layouts<T, const D: usize> {
    nodes: NodeBox<D>,
    /// Separate arrays, axis 0 fastest (shared strides).
    sep: Vec<Vec<T>>,
    /// Node structs of `D` scalars, axis `D − 1` fastest.
    il: Vec<T>,
    /// Separate arrays; component `a` with a row pitch of `dims[0] + 3 a` (different strides).
    pad: Vec<Vec<T>>,
}

impl<T: Real, const D: usize> Layouts<T, D> {
    /// Values uniform in `[lo, hi)`.
    fn new(rng: &mut Pcg64, cells: i32, (lo, hi): (f64, f64)) -> Self {
        let dims = [cells; D];
        let n: usize = dims.iter().map(|&d| d as usize).product();
        let sep: Vec<Vec<T>> = (0..D)
            .map(|_| {
                (0..n)
                    .map(|_| T::from_f64(rng.random_range(lo..hi)))
                    .collect()
            })
            .collect();
        let mut l = Self {
            nodes: NodeBox { lo: [0; D], dims },
            il: vec![T::ZERO; n * D],
            pad: (0..D)
                .map(|a| vec![T::ZERO; n / dims[0] as usize * (dims[0] as usize + 3 * a)])
                .collect(),
            sep,
        };
        for k in 0..n {
            let idx = Self::index(dims, k);
            for a in 0..D {
                let v = l.sep[a][k];
                l.il[Self::offset(&Self::il_stride(dims), &idx) as usize + a] = v;
                l.pad[a][Self::offset(&Self::pad_stride(dims, a), &idx) as usize] = v;
            }
        }
        l
    }
    fn index(dims: [i32; D], mut k: usize) -> [isize; D] {
        std::array::from_fn(|a| {
            let i = k % dims[a] as usize;
            k /= dims[a] as usize;
            i as isize
        })
    }
    fn offset(s: &[isize; D], idx: &[isize; D]) -> isize {
        (0..D).map(|a| s[a] * idx[a]).sum()
    }
    fn sep_stride(dims: [i32; D]) -> [isize; D] {
        Self::pad_stride(dims, 0)
    }
    fn il_stride(dims: [i32; D]) -> [isize; D] {
        let mut s = [D as isize; D];
        for a in (0..D - 1).rev() {
            s[a] = s[a + 1] * dims[a + 1] as isize;
        }
        s
    }
    fn pad_stride(dims: [i32; D], a: usize) -> [isize; D] {
        let mut s = [1isize; D];
        s[1] = dims[0] as isize + 3 * a as isize;
        for b in 2..D {
            s[b] = s[b - 1] * dims[b - 1] as isize;
        }
        s
    }
    /// The channels of layout `which` (0 separate, 1 interleaved, 2 padded).
    fn channels(&self, which: usize) -> [Channel<*const T, D>; D] {
        let dims = self.nodes.dims;
        std::array::from_fn(|a| match which {
            0 => Channel {
                data: self.sep[a].as_ptr(),
                stride: Self::sep_stride(dims),
            },
            1 => Channel {
                // SAFETY: within the allocation.
                data: unsafe { self.il.as_ptr().add(a) },
                stride: Self::il_stride(dims),
            },
            _ => Channel {
                data: self.pad[a].as_ptr(),
                stride: Self::pad_stride(dims, a),
            },
        })
    }
}

/// G2P and the force differential's apply on every layout and instruction set: the bits of
/// the particle arrays (G2P) and of `δf` (apply), per instruction set and layout.
fn run<T: BatchReal, const D: usize>(kernel: Kernel, material: usize)
where
    Dim<D>: LaneDim<D>,
    Mat<T, D>: Matrix<Scalar = T, Vector = [T; D]>,
    Mat<f64, D>: Matrix<Scalar = f64, Vector = [f64; D]> + HaarRotation,
    DefaultSvd: SvdMethod<Mat<T, D>>,
{
    let (cells, hf, n) = (13, 0.05, 37);
    let h = T::from_f64(hf);
    let (mat_name, mat) = materials::<T>()[material];
    let mut rng = Pcg64::seed_from_u64(41);
    let ps = particles::<T, D>(&mut rng, n, hf, cells - 1, &mat);
    let field = Layouts::<T, D>::new(&mut rng, cells, (-1.0, 1.0));
    // Node temperatures (K) near the melting point: new in component 0, old in component 1.
    let temps = Layouts::<T, D>::new(&mut rng, cells, (TM - 3.0, TM + 3.0));
    let name = format!("{D}D {} {kernel:?} {mat_name}", T::NAME);
    let mut vector_bits: Option<(Isa, Vec<u64>, Vec<u64>)> = None;
    for isa in isas() {
        let (mut g2p_bits, mut df_bits) = (None::<Vec<u64>>, None::<Vec<u64>>);
        for which in 0..3 {
            let label = format!("{name} {isa:?} layout {which}");
            let ch = field.channels(which);
            let tc = temps.channels(which);
            // G2P with the field as node velocities.
            let mut store = Store::from(&ps);
            let raw = store.raw();
            let view = G2pView {
                nodes: field.nodes,
                velocity: ch,
                temperature: tc[0],
                temperature_old: tc[1],
            };
            let args = G2pArgs {
                kernel,
                h,
                dt: T::from_f64(1e-4),
            };
            // SAFETY: n particles; the channels cover the box.
            let st = unsafe { g2p::g2p_update(isa, &mat, &args, n, &raw, &view, None) };
            assert_eq!(st.error, None, "{label}");
            let b = store.bits();
            match &g2p_bits {
                None => g2p_bits = Some(b),
                Some(want) => assert_eq!(&b, want, "{label}: G2P"),
            }
            // The force differential with the field as δu.
            let store = Store::from(&ps);
            let mut slots = vec![T::ZERO; n * slot_len(D)];
            let mut raw = store.clone();
            // SAFETY: n particles, n slots.
            let st =
                unsafe { force::prepare::<T, D>(isa, &mat, n, &raw.raw(), slots.as_mut_ptr()) };
            assert_eq!(st.error, None, "{label}");
            let mut df = DenseGrid::<T, D>::new([0; D], [cells; D]);
            let fv = ForceView {
                nodes: field.nodes,
                du: ch,
                df: std::array::from_fn(|a| df.out(FORCE + a)),
            };
            // SAFETY: n particles and slots; the channels cover every stencil.
            let st = unsafe {
                force::apply::<T, D>(isa, kernel, h, n, store.x.as_ptr(), slots.as_ptr(), &fv)
            };
            assert_eq!(st.error, None, "{label}");
            let b: Vec<u64> = df.bits()[FORCE..FORCE + D].concat();
            assert!(b.iter().any(|&x| x != 0), "{label}: forces written");
            match &df_bits {
                None => df_bits = Some(b),
                Some(want) => assert_eq!(&b, want, "{label}: apply"),
            }
        }
        if isa.kind() == IsaKind::Scalar {
            continue;
        }
        let (g, d) = (g2p_bits.unwrap(), df_bits.unwrap());
        match &vector_bits {
            None => vector_bits = Some((isa, g, d)),
            Some((first, wg, wd)) => {
                assert_eq!(&g, wg, "{name}: G2P on {isa:?} against {first:?}");
                assert_eq!(&d, wd, "{name}: apply on {isa:?} against {first:?}");
            }
        }
    }
}

/// Elastic (velocities only) and thermal with phase change (velocities and temperatures).
const MATERIALS: [usize; 2] = [0, 2];

#[test]
fn layouts_and_isas_give_the_same_bits_3d_f32() {
    for m in MATERIALS {
        run::<f32, 3>(Kernel::Quadratic, m);
        run::<f32, 3>(Kernel::Cubic, m);
    }
}

#[test]
fn layouts_and_isas_give_the_same_bits_2d_f64() {
    for m in MATERIALS {
        run::<f64, 2>(Kernel::Quadratic, m);
        run::<f64, 2>(Kernel::Cubic, m);
    }
}

#[test]
fn layouts_and_isas_give_the_same_bits_3d_f64() {
    for m in MATERIALS {
        run::<f64, 3>(Kernel::Quadratic, m);
    }
}
