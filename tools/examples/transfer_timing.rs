//! Quick split timing of P2G, G2P and the force differential's apply (f32 quadratic, 3D, or 2D
//! with `AMPM_TT_DIM=2`): `cargo run --release -p ampm-tools --example transfer_timing --
//! <fluid|elastic|thermal|snow>` (a development aid; the benchmarks are `c_tests/bench_transfers`
//! and `tools/benches/particle_levels.rs`). Environment: `AMPM_TT_REPS` (runs, best kept),
//! `AMPM_TT_ISA` (`avx2`, `avx512`, ...: that instruction set only), `AMPM_TT_SIDE` (particles
//! per axis), `AMPM_TT_PAD` (more grid nodes per axis), `AMPM_TT_JOINED` (`0` or `1`: AVX-512
//! without or with joined rows, `Isa::joined_rows`; default the CPU's), `AMPM_TT_NARROW` (`0`
//! or `1`: AVX-512 P2G on four or two vectors, `Isa::narrow_chunks`; default the CPU's).
use ampm_core::lane::Isa;
use ampm_core::particle::implicit::slot_len;
use ampm_core::particle::transfer::force::{self, ForceView};
use ampm_core::particle::transfer::g2p::{self, G2pArgs, G2pView};
use ampm_core::particle::transfer::p2g::{self, P2gArgs, P2gView};
use ampm_core::particle::transfer::{Channel, NodeBox, Particles};
use ampm_core::particle::{Grid, Heat, Kernel, Material, Phase, PhaseParams, Snow};

/// CPU time of this thread (s): unlike wall time, it does not count the time other
/// processes on a shared machine hold the core.
struct Cpu(f64);
impl Cpu {
    fn now() -> Self {
        #[repr(C)]
        struct Ts {
            s: i64,
            ns: i64,
        }
        extern "C" {
            fn clock_gettime(clk: i32, ts: *mut Ts) -> i32;
        }
        let mut ts = Ts { s: 0, ns: 0 };
        // SAFETY: CLOCK_THREAD_CPUTIME_ID = 3 on Linux; `ts` is a valid timespec.
        unsafe { clock_gettime(3, &mut ts) };
        Cpu(ts.s as f64 + ts.ns as f64 * 1e-9)
    }
    fn elapsed(&self) -> std::time::Duration {
        std::time::Duration::from_secs_f64(Cpu::now().0 - self.0)
    }
}

/// The environment variable `name` as a count, `default` when unset or not a count.
fn env_usize(name: &str, default: usize) -> usize {
    std::env::var(name)
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(default)
}

fn main() {
    match std::env::var("AMPM_TT_DIM").as_deref() {
        Ok("2") => run::<2>(),
        _ => run::<3>(),
    }
}

/// The timing loop in `D` dimensions.
fn run<const D: usize>()
where
    ampm_core::kernel::Dim<D>: ampm_core::kernel::LaneDim<D>,
    ampm_core::mat::Mat<f32, D>: ampm_core::mat::Matrix<Scalar = f32, Vector = [f32; D]>,
    ampm_core::polar::DefaultSvd: ampm_core::polar::SvdMethod<ampm_core::mat::Mat<f32, D>>,
{
    let dd = D * D;
    let level = std::env::args().nth(1).unwrap_or_else(|| "elastic".into());
    let liquid = level == "fluid";
    // `thermal`: the elastic level with heat and phase change (solids at 270 K, melting at
    // 273.15 K).
    let thermal = level == "thermal";
    // `snow`: the elastic level with snow plasticity (the benchmark's parameters).
    let snow = level == "snow";
    // 54,872 particles in 3D, 262,144 in 2D.
    // `AMPM_TT_SIDE`: particles per axis instead (a small side keeps the particles and the
    // grid in the cache).
    let s = env_usize("AMPM_TT_SIDE", if D == 3 { 38 } else { 512 });
    let n = s.pow(D as u32);
    let h = 0.02f32;
    // A lattice at spacing h/2, shuffled and then sorted by cell (x fastest), as a host and
    // the C++ benchmark order their particles.
    let mut order: Vec<usize> = (0..n).collect();
    let mut g = 0x9e37_79b9_7f4a_7c15u64;
    for i in (1..n).rev() {
        g ^= g << 13;
        g ^= g >> 7;
        g ^= g << 17;
        order.swap(i, (g % (i as u64 + 1)) as usize);
    }
    let key = |i: usize| {
        let (mut q, mut k, mut m) = (i, 0, 1);
        for _ in 0..D {
            k += q % s / 2 * m;
            q /= s;
            m *= s;
        }
        k
    };
    order.sort_by_key(|&i| key(i));
    let mut x = Vec::new();
    for &i in &order {
        let mut q = i;
        for _ in 0..D {
            x.push((4.0 + ((q % s) as f32 + 0.5) * 0.5) * h);
            q /= s;
        }
    }
    let mut v = vec![0.01f32; n * D];
    let mut affine = vec![0.0f32; n * dd];
    let mut f_e = vec![0.0f32; n * dd];
    let mut f_p = vec![0.0f32; n * dd];
    for i in 0..n {
        for d in 0..D {
            f_e[dd * i + (D + 1) * d] = if liquid { 1.0 } else { 1.0 + 0.01 * (d as f32) };
            f_p[dd * i + (D + 1) * d] = 1.0;
        }
        if !liquid {
            f_e[dd * i + 1] = 0.02;
        }
    }
    let mass = vec![1e-3f32; n];
    let vol = vec![1e-6f32; n];
    let mut t = vec![if thermal { 270.0f32 } else { 0.0 }; n];
    let mut u = vec![0.0f32; n];
    let mut ph = vec![if liquid { Phase::Liquid } else { Phase::Solid } as u8; n];
    let ps = Particles {
        x: x.as_mut_ptr(),
        v: v.as_mut_ptr(),
        affine: affine.as_mut_ptr(),
        f_e: f_e.as_mut_ptr(),
        f_p: f_p.as_mut_ptr(),
        mass: mass.as_ptr(),
        volume0: vol.as_ptr(),
        temperature: t.as_mut_ptr(),
        latent: u.as_mut_ptr(),
        phase: ph.as_mut_ptr(),
    };
    let p = PhaseParams {
        mu: 1e5,
        inv_lambda: 1e-5,
        heat_capacity: 1.0,
        conductivity: 1.0,
    };
    let mat = Material {
        solid: p,
        liquid: PhaseParams { mu: 0.0, ..p },
        heat: thermal.then_some(Heat {
            flip: 0.95,
            melting_point: 273.15,
            latent_heat: 3.34e5,
            phase_change: true,
        }),
        plasticity: snow.then_some(Snow {
            critical_compression: 2.5e-2,
            critical_stretch: 7.5e-3,
            hardening: 10.0,
        }),
        ..Material::default()
    };
    // `AMPM_TT_PAD`: that many more nodes per axis (a larger grid for the same particles).
    let pad = env_usize("AMPM_TT_PAD", 0);
    let dims = [(s / 2 + 8 + pad) as i32; D];
    let nn: usize = dims.iter().map(|&d| d as usize).product();
    let mut stride = [1isize; D];
    for a in 1..D {
        stride[a] = stride[a - 1] * dims[a - 1] as isize;
    }
    // Mass, momentum (3), heat capacity, thermal energy, conductivity, temperatures new, old.
    let mut grid = vec![vec![0.0f32; nn]; 9];
    let nodes = NodeBox { lo: [0; D], dims };
    // The heat channels, with heat on only.
    let heat_ch = |g: &mut Vec<Vec<f32>>, c: usize| {
        if thermal {
            Channel {
                data: g[c].as_mut_ptr(),
                stride,
            }
        } else {
            Channel::<*mut f32, D>::none()
        }
    };
    let temp_ch = |g: &Vec<Vec<f32>>, c: usize| {
        if thermal {
            Channel {
                data: g[c].as_ptr(),
                stride,
            }
        } else {
            Channel::<*const f32, D>::none()
        }
    };
    let only = std::env::var("AMPM_TT_ISA").ok();
    let mut isas = Isa::available();
    if std::env::var("AMPM_TT_FORCE_AVX2").is_ok() {
        // For instruction counts under valgrind, whose CPUID hides AVX2 on some hosts.
        // SAFETY: only on a CPU with AVX2 and FMA (the caller's promise).
        isas = vec![unsafe { Isa::assume(ampm_core::lane::IsaKind::Avx2) }];
    }
    for isa in isas {
        if only.as_deref().is_some_and(|o| o != isa.name()) {
            continue;
        }
        let isa = match std::env::var("AMPM_TT_JOINED").as_deref() {
            Ok("0") => isa.with_joined_rows(false),
            Ok("1") => isa.with_joined_rows(true),
            _ => isa,
        };
        let isa = match std::env::var("AMPM_TT_NARROW").as_deref() {
            Ok("0") => isa.with_narrow_chunks(false),
            Ok("1") => isa.with_narrow_chunks(true),
            _ => isa,
        };
        let args = P2gArgs {
            kernel: Kernel::Quadratic,
            grid: Grid::Collocated,
            h,
            impulse_dt: 1e-4,
        };
        let reps = env_usize("AMPM_TT_REPS", 10);
        let mut best = (f64::MAX, f64::MAX, f64::MAX);
        // The force differential, prepared once from the initial state.
        let mut slots = vec![0.0f32; n * slot_len(D)];
        // SAFETY: n particles, slots sized for them.
        let st = unsafe { force::prepare::<f32, D>(isa, &mat, n, &ps, slots.as_mut_ptr()) };
        assert_eq!(st.error, None);
        let x0 = x.clone();
        let du = vec![vec![1e-6f32; nn]; D];
        let mut df = vec![vec![0.0f32; nn]; D];
        for _ in 0..reps {
            df.iter_mut()
                .for_each(|c| c.iter_mut().for_each(|x| *x = 0.0));
            let fv = ForceView {
                nodes,
                du: std::array::from_fn(|c| Channel {
                    data: du[c].as_ptr(),
                    stride,
                }),
                df: std::array::from_fn(|c| Channel {
                    data: df[c].as_mut_ptr(),
                    stride,
                }),
            };
            let t0 = Cpu::now();
            // SAFETY: n positions and slots, channels cover the box, df does not alias du.
            let st = unsafe {
                force::apply(
                    isa,
                    Kernel::Quadratic,
                    h,
                    n,
                    x0.as_ptr(),
                    slots.as_ptr(),
                    &fv,
                )
            };
            let t3 = t0.elapsed().as_secs_f64();
            assert_eq!(st.error, None);
            for c in grid.iter_mut() {
                c.iter_mut().for_each(|x| *x = 0.0);
            }
            let view = P2gView {
                nodes,
                mass: Channel {
                    data: grid[0].as_mut_ptr(),
                    stride,
                },
                momentum: std::array::from_fn(|c| Channel {
                    data: grid[1 + c].as_mut_ptr(),
                    stride,
                }),
                force: [Channel::<*mut f32, D>::none(); D],
                heat_capacity: heat_ch(&mut grid, 4),
                thermal_energy: heat_ch(&mut grid, 5),
                conductivity: heat_ch(&mut grid, 6),
            };
            let t0 = Cpu::now();
            // SAFETY: n particles, channels cover the box.
            let st = unsafe { p2g::p2g(isa, &mat, &args, n, &ps, &view) };
            let t1 = t0.elapsed().as_secs_f64();
            assert_eq!(st.error, None);
            grid[7].iter_mut().for_each(|x| *x = 270.0);
            grid[8].iter_mut().for_each(|x| *x = 269.9);
            for c in 1..=D {
                grid[c].iter_mut().for_each(|x| *x = 1e-3);
            }
            let gv = G2pView {
                nodes,
                velocity: std::array::from_fn(|c| Channel {
                    data: grid[1 + c].as_ptr(),
                    stride,
                }),
                temperature: temp_ch(&grid, 7),
                temperature_old: temp_ch(&grid, 8),
            };
            let gargs = G2pArgs {
                kernel: Kernel::Quadratic,
                h,
                dt: 1e-4,
            };
            let t0 = Cpu::now();
            // SAFETY: as above.
            let st = unsafe { g2p::g2p_update(isa, &mat, &gargs, n, &ps, &gv, None) };
            let t2 = t0.elapsed().as_secs_f64();
            assert_eq!(st.error, None);
            best = (best.0.min(t1), best.1.min(t2), best.2.min(t3));
        }
        println!(
            "{level}{} {}{}: p2g {:.1} ns, g2p {:.1} ns, apply {:.1} ns per particle (best of {reps})",
            if D == 2 { " 2d" } else { "" },
            isa.name(),
            match (isa.joined_rows(), isa.narrow_chunks()) {
                (true, _) => " joined",
                (false, true) => " narrow",
                _ => "",
            },
            best.0 / n as f64 * 1e9,
            best.1 / n as f64 * 1e9,
            best.2 / n as f64 * 1e9
        );
    }
}
