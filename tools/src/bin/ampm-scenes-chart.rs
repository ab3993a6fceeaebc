//! `ampm-scenes-chart`: the explicit-against-implicit chart of the example scenes.
//!
//! ```text
//! cargo run --release -p ampm-tools --bin ampm-scenes-chart -- [docs/scenes/stepper.csv] [OUT_STEM]
//! ```
//!
//! Reads the `stepper.csv` that `ampm_scenes --scene stepper` (or `all`) writes (columns
//! `stepper, dim, dt_max, cost_per_sim_second_s, steps_per_sim_second, mean_cg_iterations, ...`)
//! and draws `OUT_STEM.png` and `OUT_STEM.svg` (default: `stepper` next to the CSV): two bar
//! panels, the largest stable Δt of each stepper and dimension, and the wall-clock seconds one
//! simulated second costs at that Δt (both log scale).
//!
//! Text uses the report's font ([`ampm_tools::font`]: DejaVu Sans read at run time, or
//! `$AMPM_FONT`).

use ampm_tools::font::{init_font, FONT};
use plotters::coord::Shift;
use plotters::prelude::*;
use std::error::Error;
use std::path::{Path, PathBuf};

const SIZE: (u32, u32) = (1100, 460);

/// One row of stepper.csv.
struct Row {
    stepper: String,
    dim: u32,
    dt_max: f64,
    cost: f64,
    cg: f64,
    limited_by: String,
}

/// Splits one CSV line (double quotes protect commas).
fn fields(line: &str) -> Vec<String> {
    let (mut out, mut cur, mut quoted) = (Vec::new(), String::new(), false);
    for ch in line.chars() {
        match ch {
            '"' => quoted = !quoted,
            ',' if !quoted => out.push(std::mem::take(&mut cur)),
            _ => cur.push(ch),
        }
    }
    out.push(cur);
    out
}

fn read(csv: &Path) -> Result<Vec<Row>, Box<dyn Error>> {
    let text = std::fs::read_to_string(csv).map_err(|e| format!("{}: {e}", csv.display()))?;
    let mut lines = text.lines();
    let header = fields(lines.next().ok_or("empty CSV")?);
    let col = |name: &str| {
        header
            .iter()
            .position(|h| h == name)
            .ok_or_else(|| format!("column {name} missing"))
    };
    let (s, d, t, c, g, l) = (
        col("stepper")?,
        col("dim")?,
        col("dt_max")?,
        col("cost_per_sim_second_s")?,
        col("mean_cg_iterations")?,
        col("limited_by")?,
    );
    let mut rows = Vec::new();
    for line in lines.filter(|l| !l.trim().is_empty()) {
        let f = fields(line);
        let get = |i: usize| f.get(i).cloned().unwrap_or_default();
        rows.push(Row {
            stepper: get(s),
            dim: get(d).parse()?,
            dt_max: get(t).parse()?,
            cost: get(c).parse()?,
            cg: get(g).parse().unwrap_or(0.0),
            limited_by: get(l),
        });
    }
    if rows.is_empty() {
        return Err("no rows".into());
    }
    Ok(rows)
}

fn colour(stepper: &str) -> RGBColor {
    if stepper == "implicit" {
        RGBColor(255, 127, 14)
    } else {
        RGBColor(31, 119, 180)
    }
}

/// `y` in plain decimals, as many as its leading digit needs (0.05, 0.2, 2, 40).
fn decimal(y: f64) -> String {
    let places = if y > 0.0 && y < 1.0 {
        (-y.log10().floor()) as usize
    } else {
        0
    };
    format!("{y:.places$}")
}

fn panel<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    rows: &[Row],
    title: &str,
    y_desc: &str,
    value: impl Fn(&Row) -> f64,
    label: impl Fn(&Row) -> String,
) -> Result<(), Box<dyn Error>>
where
    DB::ErrorType: 'static,
{
    let vals: Vec<f64> = rows.iter().map(&value).collect();
    let lo = vals.iter().cloned().fold(f64::INFINITY, f64::min);
    let hi = vals.iter().cloned().fold(0.0, f64::max);
    let (ylo, yhi) = (lo / 4.0, hi * 6.0);
    let n = rows.len() as f64;
    let mut chart = ChartBuilder::on(area)
        .caption(title, (FONT, 18))
        .margin(14)
        .x_label_area_size(36)
        .y_label_area_size(70)
        .build_cartesian_2d(-0.5..n - 0.5, (ylo..yhi).log_scale())?;
    let names: Vec<String> = rows
        .iter()
        .map(|r| format!("{} {}D", r.stepper, r.dim))
        .collect();
    chart
        .configure_mesh()
        .disable_x_mesh()
        .x_labels(rows.len())
        .x_label_formatter(&|x: &f64| {
            let i = x.round();
            if (x - i).abs() < 1e-6 && i >= 0.0 && (i as usize) < names.len() {
                names[i as usize].clone()
            } else {
                String::new()
            }
        })
        .y_desc(y_desc)
        // A few decimal labels and one light line between them: a log axis over less than
        // two decades otherwise gets a label and a line at every 1–9 × 10ᵏ, which run together.
        .y_labels(6)
        .y_max_light_lines(1)
        .y_label_formatter(&|y: &f64| decimal(*y))
        .label_style((FONT, 13))
        .axis_desc_style((FONT, 13))
        .draw()?;
    for (i, r) in rows.iter().enumerate() {
        let x = i as f64;
        let v = value(r);
        chart.draw_series(std::iter::once(Rectangle::new(
            [(x - 0.3, ylo), (x + 0.3, v)],
            colour(&r.stepper).filled(),
        )))?;
        chart.draw_series(std::iter::once(Text::new(
            label(r),
            (x - 0.3, v * 1.25),
            (FONT, 12).into_font().color(&BLACK),
        )))?;
    }
    Ok(())
}

fn draw<DB: DrawingBackend>(
    root: DrawingArea<DB, Shift>,
    rows: &[Row],
    note: &str,
) -> Result<(), Box<dyn Error>>
where
    DB::ErrorType: 'static,
{
    root.fill(&WHITE)?;
    let (top, bottom) = root.split_vertically(SIZE.1 - 28);
    let halves = top.split_evenly((1, 2));
    panel(
        &halves[0],
        rows,
        "Largest stable time step",
        "dt_max (s)",
        |r| r.dt_max,
        |r| {
            let cap = if r.limited_by == "cap" { " (cap)" } else { "" };
            format!("{:.2e} s{cap}", r.dt_max)
        },
    )?;
    panel(
        &halves[1],
        rows,
        "Cost of one simulated second at dt_max",
        "wall-clock s per simulated s",
        |r| r.cost,
        |r| {
            if r.stepper == "implicit" {
                format!("{:.3} s ({:.0} CG it)", r.cost, r.cg)
            } else {
                format!("{:.3} s", r.cost)
            }
        },
    )?;
    bottom.draw(&Text::new(
        note.to_string(),
        (14, 6),
        (FONT, 13).into_font().color(&RGBColor(80, 80, 80)),
    ))?;
    root.present()?;
    Ok(())
}

fn main() -> Result<(), Box<dyn Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let csv = PathBuf::from(
        args.first()
            .map(String::as_str)
            .unwrap_or("docs/scenes/stepper.csv"),
    );
    let stem = match args.get(1) {
        Some(s) => PathBuf::from(s),
        None => csv.with_file_name("stepper"),
    };
    init_font()?;
    let rows = read(&csv)?;
    let note = "Elastic block dropped on a slip floor (E = 1 MPa). Implicit: backward Euler + CG on \
                ampm_force_prepare/apply (PSD). Stable: no failed call or NaN, 0.2 ≤ J ≤ 5, bounded KE, no tunnelling.";
    let (png, svg) = (stem.with_extension("png"), stem.with_extension("svg"));
    draw(
        BitMapBackend::new(&png, SIZE).into_drawing_area(),
        &rows,
        note,
    )?;
    draw(SVGBackend::new(&svg, SIZE).into_drawing_area(), &rows, note)?;
    println!("wrote {} and {}", png.display(), svg.display());
    Ok(())
}
