//! `ampm-report`: the main job. Measures every kernel and SVD method and regenerates `docs/`.
//!
//! ```text
//! cargo run --release -p ampm-tools --bin ampm-report [-- --quick] [-- --out DIR] [-- --bench-c FILE]
//! ```
//!
//! - Issue 2: per kernel (`𝓑:Z`, `Z:𝓑`, `Ψ̂`, `Â`, `Ĉ:Z`, batch `Â`, `Ĉ:Z` through the C ABI),
//!   dim and precision, the median time per call and the error against central finite
//!   differences (f64) or against the f64 kernels (f32): stdout and `docs/report.md`.
//! - Issue 3: the speed–accuracy chart (`docs/speed-accuracy.svg`, `.png`), the stability chart
//!   (`docs/stability.svg`) and table (`docs/stability-table.md`), from data measured in the
//!   same run. Everything but the timings is deterministic (seeded particles).
//! - The fast batch path (`ampm_core::kernel::batch::ahat_chat_z`) on every instruction set
//!   of this CPU: time and errors of Â and Ĉ:Z on the chart's family (the chart's lower
//!   panel), and time on the workload of `c_tests/bench_kernels`, set against the hand-written
//!   Eigen baseline that program timed (read from `docs/bench-c.md`, which the main job
//!   writes before running this report).

mod accuracy;
mod bench_c;
mod charts;
mod fast;
mod kernel_table;
mod methods;
mod table;
mod timing;

use ampm_tools::families::Size;
use ampm_tools::workload::{particles, SEED, SIGMA_MAX, SIGMA_MIN};
use indicatif::{ProgressBar, ProgressStyle};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

/// Command-line options.
struct Options {
    /// Fewer particles and repetitions: a quick look, not the published numbers.
    quick: bool,
    /// Output directory (default: the workspace's `docs/`).
    out: PathBuf,
    /// The markdown of `c_tests/bench_kernels` (default: the workspace's `docs/bench-c.md`).
    bench_c: PathBuf,
}

fn parse_args() -> Result<Options, String> {
    let mut o = Options {
        quick: false,
        out: Path::new(env!("CARGO_MANIFEST_DIR")).join("../docs"),
        bench_c: Path::new(env!("CARGO_MANIFEST_DIR")).join("../docs/bench-c.md"),
    };
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        match a.as_str() {
            "--quick" => o.quick = true,
            "--out" => o.out = args.next().ok_or("--out needs a directory")?.into(),
            "--bench-c" => o.bench_c = args.next().ok_or("--bench-c needs a file")?.into(),
            "-h" | "--help" => {
                return Err(
                    "usage: ampm-report [--quick] [--out DIR] [--bench-c FILE]\n\
                     Measures the kernels and SVD methods and regenerates DIR (default docs/);\n\
                     reads the Eigen baseline from FILE (default docs/bench-c.md) if present."
                        .into(),
                )
            }
            other => return Err(format!("unknown argument {other:?} (try --help)")),
        }
    }
    Ok(o)
}

/// The CPU the timings were taken on (Linux), for the report's header.
fn cpu_model() -> String {
    std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("model name"))
                .and_then(|l| l.split(':').nth(1))
                .map(|m| m.trim().to_string())
        })
        .unwrap_or_else(|| "unknown CPU".into())
}

fn write(path: &Path, text: &str) -> Result<(), String> {
    std::fs::write(path, text).map_err(|e| format!("writing {}: {e}", path.display()))
}

fn run() -> Result<(), String> {
    let opt = parse_args()?;
    let font = ampm_tools::font::init_font()?;
    std::fs::create_dir_all(&opt.out)
        .map_err(|e| format!("creating {}: {e}", opt.out.display()))?;
    let out = opt
        .out
        .canonicalize()
        .map_err(|e| format!("{}: {e}", opt.out.display()))?;
    // Read before measuring: its age is then relative to the start of this run.
    let bench_c = bench_c::read(&opt.bench_c).unwrap_or_else(|e| {
        eprintln!("ampm-report: warning: {e}; no Eigen comparison");
        None
    });
    let cfg = kernel_table::Config {
        particles: if opt.quick { 512 } else { 4096 },
        reps: if opt.quick { 5 } else { 31 },
    };

    let kernel_steps = 4 * kernel_table::Kernel::ALL.len();
    let method_steps = 2 * methods::CONFIGS;
    let pb = ProgressBar::new((kernel_steps + method_steps + fast::STEPS + accuracy::STEPS) as u64);
    pb.set_style(
        ProgressStyle::with_template("{elapsed_precise} [{bar:40}] {pos}/{len} {msg}")
            .map_err(|e| e.to_string())?
            .progress_chars("=> "),
    );

    let p2 = particles::<2>(cfg.particles, 2);
    let p3 = particles::<3>(cfg.particles, 3);

    pb.set_message("kernels");
    let tick = || pb.inc(1);
    let mut rows = kernel_table::measure::<f32, 2>(cfg, &p2, tick);
    rows.extend(kernel_table::measure::<f64, 2>(cfg, &p2, tick));
    rows.extend(kernel_table::measure::<f32, 3>(cfg, &p3, tick));
    rows.extend(kernel_table::measure::<f64, 3>(cfg, &p3, tick));

    pb.set_message("SVD methods");
    let size = if opt.quick { Size::Reduced } else { Size::Full };
    let mut timings = methods::measure::<f32>(size, cfg.reps, tick);
    timings.extend(methods::measure::<f64>(size, cfg.reps, tick));

    pb.set_message("fast batch path");
    // The particle count of c_tests/bench_kernels (its kDefaultN), so that both programs
    // time the same working-set size.
    let n_workload = if opt.quick { 4096 } else { 65536 };
    let fast_rows = fast::measure(size, cfg.reps, n_workload, tick);

    pb.set_message("stability (double-double reference)");
    let acc = accuracy::measure(size, tick);
    pb.finish_and_clear();

    // Issue 2's table.
    let kernels_md = kernel_table::render(&rows);
    let batch_ok = rows
        .iter()
        .filter_map(|r| r.batch_matches_single)
        .all(|same| same);
    let methods_md = accuracy::render_methods(&timings, &acc);

    let mut report = String::new();
    let _ = writeln!(report, "# ampm report\n");
    let _ = writeln!(
        report,
        "Generated by `cargo run --release -p ampm-tools --bin ampm-report`{}. \
         Timings are medians of {} passes over {} random particles on one core ({}); \
         they vary from run to run, everything else is deterministic.\n",
        if opt.quick { " -- --quick" } else { "" },
        cfg.reps,
        cfg.particles,
        cpu_model()
    );
    let _ = writeln!(
        report,
        "Random particles: `F = U diag(σ) Vᵀ`, σᵢ log-uniform in [{SIGMA_MIN}, {SIGMA_MAX}], \
         U, V Haar on SO(d); `Z` uniform entries, ‖Z‖_F = 1; μ = 1; seed {SEED:#x}.\n"
    );
    let _ = writeln!(report, "## Kernels\n");
    let _ = writeln!(
        report,
        "Norm-wise relative errors. f64 rows: against central finite differences with \
         h = ε^(1/3) (Â against the gradient of Ψ̂, Ĉ:Z against the derivative of Â along Z, \
         𝓑:Z and Z:𝓑 against the derivative of JᵃF), where O(h²) truncation and O(ε/h) \
         rounding put a correct kernel near ε^(2/3) ≈ 4e-11. f32 rows: against the f64 kernels \
         on the same f32-representable inputs, also in units of ε₃₂ = 2⁻²³. \
         p50 is a kernel's typical accuracy; the max comes from particles near the rest shape \
         (F̂ ≈ R), where Ψ̂ ∝ ‖F̂ − R‖² and Â ∝ ‖F̂ − R‖ vanish, so their relative error has no \
         floor (cancellation in F̂ − R), not from a wrong term. \
         \"C batch\" rows go through the C ABI batch entry points (ns per particle); their \
         outputs are {} the single-particle kernels'.\n",
        if batch_ok {
            "bitwise equal to"
        } else {
            "NOT all bitwise equal to"
        }
    );
    let _ = writeln!(report, "{kernels_md}\n");
    let _ = writeln!(report, "## SVD methods\n");
    let _ = writeln!(report, "{}\n", accuracy::METHODS_NOTE);
    let _ = writeln!(report, "{methods_md}\n");
    let _ = writeln!(
        report,
        "Stability measurement (`ampm_tools::stability`, family size {:?}): {} contract \
         violation(s).\n",
        acc.size,
        acc.violations.len()
    );
    for v in acc.violations.iter().take(20) {
        let _ = writeln!(report, "- {v}");
    }
    if !acc.violations.is_empty() {
        let _ = writeln!(report);
    }
    let fast_md = fast::render(&fast_rows, |d, p| {
        accuracy::generic_row(&timings, &acc, d, p)
    });
    let _ = writeln!(report, "## Fast batch path per instruction set\n");
    let _ = writeln!(report, "{FAST_NOTE}\n");
    let _ = writeln!(report, "{fast_md}\n");
    let _ = writeln!(report, "### Fast path vs Eigen\n");
    let eigen_md = bench_c
        .as_ref()
        .map(|b| fast::render_vs_eigen(&fast_rows, b));
    match (&bench_c, &eigen_md) {
        (Some(b), Some(md)) => {
            let age = b.age_minutes.map_or("of unknown age".into(), |m| {
                format!("written {m:.0} min before this report started")
            });
            let cpu_here = cpu_model();
            let same_cpu = if b.cpu == cpu_here {
                "the same CPU model as this report".to_string()
            } else {
                format!("CPU {:?}, NOT the CPU of this report ({cpu_here:?})", b.cpu)
            };
            let _ = writeln!(
                report,
                "The Eigen and \"combined\" columns are read from `{}` ({age}; {same_cpu}), \
                 written by `c_tests/bench_kernels`: one `Eigen::JacobiSVD` per particle with \
                 Â and Ĉ:Z written by hand, and `ampm_ahat_chat_z_batch` on the library's \
                 default (widest) instruction set, both timed in that program's run on its own \
                 particles ({} per case). The \"fast\" columns are this report's median ns per \
                 particle of the same kernels (`ahat_chat_z`, both outputs) per instruction set \
                 on {n_workload} particles of the same distribution \
                 (`ampm_tools::workload::batch_workload`: σᵢ log-uniform in [0.5, 2], Haar \
                 rotations, μ = 1, Z entries in [−1, 1]; other draws). The ratios divide \
                 times of two processes: their spread between runs is that of the times.\n",
                b.path,
                b.n.map_or("count not stated".into(), |n| n.to_string())
            );
            let _ = writeln!(report, "{md}\n");
        }
        _ => {
            let _ = writeln!(
                report,
                "`{}` was not found or not readable when this report ran: no Eigen comparison \
                 (the main job, `.ci/main`, runs `c_tests/build/bench_kernels --out \
                 docs/bench-c.md` first).\n",
                opt.bench_c.display()
            );
        }
    }
    let _ = writeln!(
        report,
        "![speed and accuracy](speed-accuracy.svg)\n\n\
         Stability against the families of F: [table](stability-table.md), \
         ![stability](stability.svg)\n"
    );

    println!("{kernels_md}\n");
    println!("{methods_md}\n");
    println!("{fast_md}\n");
    if let Some(md) = &eigen_md {
        println!("{md}\n");
    }

    write(&out.join("report.md"), &report)?;
    write(&out.join("stability-table.md"), &acc.table_md)?;
    let mut lower = charts::KernelPanel {
        title: "Kernel outputs: fast batch path per instruction set vs the generic path \
                (same family)"
            .into(),
        points: fast::kernel_points(&fast_rows),
        lines: Vec::new(),
        lines_legend: "hand-written Eigen (JacobiSVD), bench_kernels; σ in [0.5, 2]".into(),
    };
    lower
        .points
        .extend(accuracy::generic_kernel_points(&timings, &acc));
    if let Some(b) = &bench_c {
        lower.lines = b
            .rows
            .iter()
            .map(|r| charts::TimeLine {
                label: format!("Eigen {}D {}", r.dim, r.precision),
                ns: r.eigen,
            })
            .collect();
    }
    charts::speed_accuracy(
        &accuracy::speed_points(&timings, &acc),
        &lower,
        &out.join("speed-accuracy.svg"),
        &out.join("speed-accuracy.png"),
    )?;
    charts::stability(&acc.panels, &acc.y_desc, &out.join("stability.svg"))?;
    eprintln!(
        "wrote report.md, stability-table.md, speed-accuracy.svg, speed-accuracy.png, \
         stability.svg to {} (font: {font})",
        out.display()
    );
    Ok(())
}

fn main() -> ExitCode {
    match run() {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("ampm-report: {e}");
            ExitCode::FAILURE
        }
    }
}

/// What the fast-path table of `docs/report.md` shows.
const FAST_NOTE: &str = "`ampm_core::kernel::batch::ahat_chat_z` (Â and Ĉ:Z with one \
     decomposition per particle: one-sided Jacobi in 3D, the closed form in 2D, on lanes; the \
     kernels of the C batch calls) on each instruction set of this CPU, one core. \"chart \
     family\": median ns per particle over the batch the SVD methods are timed on (\"Haar, \
     log-uniform σ\", σᵢ in [1e-4, 1e4], rounded to the precision, unit Z); \"σ in [0.5, 2]\": \
     the same call on the workload of `c_tests/bench_kernels` (table below). Errors: p99 over \
     the chart family of the relative Frobenius error of Â and of Ĉ:Z against the \
     double-double reference. Left out (as in the stability measurement): F singular to \
     working precision (4dε·κ_J ≥ 1, κ_J = ∏‖F eⱼ‖/|det F|) and particles the reference \
     refuses; refused: particles the reference computes that the fast path refused. The fast \
     path's R is internal to its lane kernels, so the chart's lower panel plots these errors \
     of its outputs, next to the generic single-particle path with the same decomposition \
     (its time from the methods table, its p99 errors of Â and Ĉ:Z from the stability \
     measurement, with that measurement's directions Z).";
