//! The charts of the report, drawn with plotters: the speed–accuracy chart (SVG and PNG) and the
//! stability chart (SVG, `stability.rs`).
//!
//! Text: plotters' `ab_glyph` backend with a TrueType font read at run time and registered as
//! "sans-serif" (no system library at build time). The font is DejaVu Sans from Debian's
//! `fonts-dejavu-core`; `AMPM_FONT=/path/to/font.ttf` overrides it.

use ampm_tools::font::FONT;
use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::Path;

mod stability;
pub use stability::{stability, Curve, Panel};

/// A categorical palette (Tableau 10), assigned to methods in a fixed order.
const PALETTE: [RGBColor; 10] = [
    RGBColor(31, 119, 180),
    RGBColor(255, 127, 14),
    RGBColor(44, 160, 44),
    RGBColor(214, 39, 40),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(127, 127, 127),
    RGBColor(188, 189, 34),
    RGBColor(23, 190, 207),
];

/// Color of the `i`-th method.
fn color(i: usize) -> RGBColor {
    PALETTE[i % PALETTE.len()]
}

/// One point of the speed–accuracy chart.
#[derive(Clone, Debug)]
pub struct SpeedPoint {
    /// Method family (one color and one legend entry each), e.g. "McAdams".
    pub method: String,
    /// Label next to the point, e.g. "McAdams 4, 3D f32".
    pub label: String,
    /// Precision: f32 points are triangles, f64 points circles.
    pub is_f32: bool,
    /// ns per particle of `Â + Ĉ:Z` with this method (filled marker).
    pub ns_kernels: f64,
    /// ns per particle of the SVD alone (hollow marker, same height).
    pub ns_svd: f64,
    /// p99 error against the double-double reference.
    pub p99: f64,
}

/// One point of the speed–accuracy chart's lower panel (kernel outputs): a configuration's
/// time of `Â + Ĉ:Z` and its p99 errors of `Â` (filled marker) and `Ĉ:Z` (hollow marker).
#[derive(Clone, Debug)]
pub struct KernelPoint {
    /// Color key: a method name of the upper panel (same color there) or a new series.
    pub series: String,
    /// Legend text of the series.
    pub legend: String,
    /// Label next to the `Â` marker, e.g. "avx512 3D f32".
    pub label: String,
    /// Precision: f32 points are triangles, f64 points circles.
    pub is_f32: bool,
    /// ns per particle of `Â + Ĉ:Z`.
    pub ns: f64,
    /// p99 relative error of `Â` against the double-double reference.
    pub p99_ahat: f64,
    /// p99 relative error of `Ĉ:Z` against the double-double reference.
    pub p99_chat_z: f64,
}

/// A time without an error on the reference's scale: a vertical dashed line.
#[derive(Clone, Debug)]
pub struct TimeLine {
    /// Label at the top of the line, e.g. "Eigen 3D f32".
    pub label: String,
    /// ns per particle.
    pub ns: f64,
}

/// The speed–accuracy chart's lower panel.
#[derive(Clone, Debug, Default)]
pub struct KernelPanel {
    /// Caption.
    pub title: String,
    /// Points with errors.
    pub points: Vec<KernelPoint>,
    /// Vertical lines (times without a measured error).
    pub lines: Vec<TimeLine>,
    /// Legend text of the vertical lines.
    pub lines_legend: String,
}

/// Errors below this are drawn at this value (a log axis has no zero).
pub const ERROR_FLOOR: f64 = 1e-18;

/// A log range covering `values` with some margin, whole decades.
fn log_range(values: impl Iterator<Item = f64>, floor: f64) -> std::ops::Range<f64> {
    let (mut lo, mut hi) = (f64::INFINITY, 0.0f64);
    for v in values.filter(|v| v.is_finite()) {
        let v = v.max(floor);
        lo = lo.min(v);
        hi = hi.max(v);
    }
    if !lo.is_finite() || hi <= 0.0 {
        return 1e-1..1e1;
    }
    10f64.powf(lo.log10().floor())..10f64.powf((hi.log10() + 0.01).ceil())
}

/// Tick label of a log axis: `1e-7`.
fn sci(v: &f64) -> String {
    format!("{v:.0e}")
}

type DrawResult = Result<(), String>;

fn err<E: std::fmt::Display>(e: E) -> String {
    e.to_string()
}

/// A label box in pixels: `(left, top, right, bottom)`.
type LabelBox = (i32, i32, i32, i32);

/// Offsets of a point's label (text box `w × h`) from the point, in order of preference.
fn beside(w: i32, h: i32) -> Vec<(i32, i32)> {
    vec![
        (8, 2),
        (8, -h - 2),
        (8, h + 4),
        (8, -2 * h - 4),
        (8, 2 * h + 6),
        (-w - 8, 2),
        (-w - 8, -h - 2),
        (-w - 8, h + 4),
    ]
}

/// Offsets of a vertical line's label from the line's top end: right of the line, stepping
/// down one text line at a time.
fn below(_w: i32, h: i32) -> Vec<(i32, i32)> {
    (0..8).map(|k| (4, 4 + k * (h + 2))).collect()
}

/// Draws each label (anchor in backend pixels, text) at the first offset of `offsets` whose
/// box overlaps no label in `placed` (which it then joins).
fn place_labels<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    labels: &[((i32, i32), String)],
    offsets: fn(i32, i32) -> Vec<(i32, i32)>,
    placed: &mut Vec<LabelBox>,
) -> DrawResult
where
    DB::ErrorType: 'static,
{
    let font: TextStyle = (FONT, 11).into();
    let (bx, by) = area.get_base_pixel();
    for ((px, py), text) in labels {
        let (px, py) = (px - bx, py - by);
        let (w, h) = area.estimate_text_size(text, &font).map_err(err)?;
        let (w, h) = (w as i32, h as i32);
        let candidates = offsets(w, h);
        let free = |x: i32, y: i32| {
            placed
                .iter()
                .all(|&(a, b, c, d)| x + w <= a || x >= c || y + h <= b || y >= d)
        };
        let (dx, dy) = candidates
            .iter()
            .copied()
            .find(|&(dx, dy)| free(px + dx, py + dy))
            .unwrap_or(candidates[0]);
        let (x, y) = (px + dx, py + dy);
        placed.push((x, y, x + w, y + h));
        area.draw(&Text::new(text.clone(), (x, y), font.clone()))
            .map_err(err)?;
    }
    Ok(())
}

/// The color of a series: its position in `keys` (the upper panel's methods first).
fn series_color(keys: &[String], key: &str) -> RGBColor {
    color(keys.iter().position(|k| k == key).unwrap_or(0))
}

/// Draws the upper panel: SVD methods, p99 error of `R` against time.
fn draw_speed<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    pts: &[SpeedPoint],
    xr: std::ops::Range<f64>,
    keys: &[String],
) -> DrawResult
where
    DB::ErrorType: 'static,
{
    let yr = log_range(pts.iter().map(|p| p.p99), ERROR_FLOOR);
    let mut chart = ChartBuilder::on(root)
        .caption(
            "SVD methods: cost per particle vs accuracy (Haar F, log-uniform σ in [1e-4, 1e4])",
            (FONT, 22),
        )
        .margin(16)
        .x_label_area_size(48)
        .y_label_area_size(72)
        .build_cartesian_2d(xr.log_scale(), yr.log_scale())
        .map_err(err)?;
    chart
        .configure_mesh()
        .x_desc("time per particle, ns (filled: Â + Ĉ:Z, hollow: the SVD alone; ● f64, ▲ f32)")
        .y_desc("p99 relative error of R vs double-double")
        .x_label_formatter(&|v| format!("{v:.0}"))
        .y_label_formatter(&sci)
        .label_style((FONT, 14))
        .axis_desc_style((FONT, 15))
        .draw()
        .map_err(err)?;

    let mut methods: Vec<&str> = Vec::new();
    for p in pts {
        if !methods.contains(&p.method.as_str()) {
            methods.push(&p.method);
        }
    }
    for m in &methods {
        let c = series_color(keys, m);
        let mine: Vec<&SpeedPoint> = pts.iter().filter(|p| p.method == *m).collect();
        // The SVD alone → the full Â + Ĉ:Z, at the same error.
        for p in &mine {
            let y = p.p99.max(ERROR_FLOOR);
            chart
                .draw_series(std::iter::once(PathElement::new(
                    vec![(p.ns_svd, y), (p.ns_kernels, y)],
                    c.mix(0.35).stroke_width(1),
                )))
                .map_err(err)?;
            // Hollow marker: the colored shape with a white one inside.
            let (outer, inner) = (c.filled(), WHITE.filled());
            if p.is_f32 {
                chart
                    .draw_series(std::iter::once(
                        EmptyElement::at((p.ns_svd, y))
                            + TriangleMarker::new((0, 0), 7, outer)
                            + TriangleMarker::new((0, 0), 3, inner),
                    ))
                    .map_err(err)?;
            } else {
                chart
                    .draw_series(std::iter::once(
                        EmptyElement::at((p.ns_svd, y))
                            + Circle::new((0, 0), 5, outer)
                            + Circle::new((0, 0), 3, inner),
                    ))
                    .map_err(err)?;
            }
        }
        let filled = c.filled();
        let at = |p: &SpeedPoint| (p.ns_kernels, p.p99.max(ERROR_FLOOR));
        let f64s = chart
            .draw_series(
                mine.iter()
                    .filter(|p| !p.is_f32)
                    .map(|p| EmptyElement::at(at(p)) + Circle::new((0, 0), 5, filled)),
            )
            .map_err(err)?;
        let f64_count = mine.iter().filter(|p| !p.is_f32).count();
        if f64_count > 0 {
            f64s.label(m.to_string())
                .legend(move |(x, y)| Circle::new((x + 8, y), 5, filled));
        }
        let f32s = chart
            .draw_series(
                mine.iter()
                    .filter(|p| p.is_f32)
                    .map(|p| EmptyElement::at(at(p)) + TriangleMarker::new((0, 0), 7, filled)),
            )
            .map_err(err)?;
        if f64_count == 0 {
            f32s.label(m.to_string())
                .legend(move |(x, y)| TriangleMarker::new((x + 8, y), 7, filled));
        }
    }
    // Labels last, so that none is hidden under a marker.
    let labels: Vec<((i32, i32), String)> = pts
        .iter()
        .map(|p| {
            (
                chart.backend_coord(&(p.ns_kernels, p.p99.max(ERROR_FLOOR))),
                p.label.clone(),
            )
        })
        .collect();
    place_labels(root, &labels, beside, &mut Vec::new())?;
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::LowerRight)
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .label_font((FONT, 14))
        .draw()
        .map_err(err)?;
    Ok(())
}

/// Draws the lower panel: p99 errors of `Â` (filled) and `Ĉ:Z` (hollow) against the time of
/// `Â + Ĉ:Z`, and the vertical lines of times without an error.
fn draw_kernels<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    panel: &KernelPanel,
    xr: std::ops::Range<f64>,
    keys: &[String],
) -> DrawResult
where
    DB::ErrorType: 'static,
{
    let yr = log_range(
        panel.points.iter().flat_map(|p| [p.p99_ahat, p.p99_chat_z]),
        ERROR_FLOOR,
    );
    let mut chart = ChartBuilder::on(root)
        .caption(&panel.title, (FONT, 20))
        .margin(16)
        .x_label_area_size(48)
        .y_label_area_size(72)
        .build_cartesian_2d(xr.log_scale(), yr.clone().log_scale())
        .map_err(err)?;
    chart
        .configure_mesh()
        .x_desc("time per particle of Â + Ĉ:Z, ns (● f64, ▲ f32)")
        .y_desc("p99 rel. error vs double-double (filled: Â, hollow: Ĉ:Z)")
        .x_label_formatter(&|v| format!("{v:.0}"))
        .y_label_formatter(&sci)
        .label_style((FONT, 14))
        .axis_desc_style((FONT, 15))
        .draw()
        .map_err(err)?;

    // Vertical lines first (under the markers), one legend entry for all.
    let dark = RGBColor(60, 60, 60);
    for (i, l) in panel.lines.iter().enumerate() {
        let s = chart
            .draw_series(DashedLineSeries::new(
                vec![(l.ns, yr.start), (l.ns, yr.end)],
                5,
                4,
                dark.stroke_width(2),
            ))
            .map_err(err)?;
        if i == 0 {
            s.label(panel.lines_legend.clone()).legend(move |(x, y)| {
                PathElement::new(vec![(x, y), (x + 16, y)], dark.stroke_width(2))
            });
        }
    }

    let mut series: Vec<(&str, &str)> = Vec::new();
    for p in &panel.points {
        if !series.iter().any(|(k, _)| *k == p.series) {
            series.push((&p.series, &p.legend));
        }
    }
    for (key, legend) in &series {
        let c = series_color(keys, key);
        let mine: Vec<&KernelPoint> = panel.points.iter().filter(|p| p.series == *key).collect();
        for p in &mine {
            let (ya, yc) = (p.p99_ahat.max(ERROR_FLOOR), p.p99_chat_z.max(ERROR_FLOOR));
            chart
                .draw_series(std::iter::once(PathElement::new(
                    vec![(p.ns, ya), (p.ns, yc)],
                    c.mix(0.35).stroke_width(1),
                )))
                .map_err(err)?;
            let (outer, inner) = (c.filled(), WHITE.filled());
            if p.is_f32 {
                chart
                    .draw_series(std::iter::once(
                        EmptyElement::at((p.ns, yc))
                            + TriangleMarker::new((0, 0), 7, outer)
                            + TriangleMarker::new((0, 0), 3, inner),
                    ))
                    .map_err(err)?;
            } else {
                chart
                    .draw_series(std::iter::once(
                        EmptyElement::at((p.ns, yc))
                            + Circle::new((0, 0), 5, outer)
                            + Circle::new((0, 0), 3, inner),
                    ))
                    .map_err(err)?;
            }
        }
        let filled = c.filled();
        let at = |p: &KernelPoint| (p.ns, p.p99_ahat.max(ERROR_FLOOR));
        let f64s = chart
            .draw_series(
                mine.iter()
                    .filter(|p| !p.is_f32)
                    .map(|p| EmptyElement::at(at(p)) + Circle::new((0, 0), 5, filled)),
            )
            .map_err(err)?;
        let has_f64 = mine.iter().any(|p| !p.is_f32);
        if has_f64 {
            f64s.label(legend.to_string())
                .legend(move |(x, y)| Circle::new((x + 8, y), 5, filled));
        }
        let f32s = chart
            .draw_series(
                mine.iter()
                    .filter(|p| p.is_f32)
                    .map(|p| EmptyElement::at(at(p)) + TriangleMarker::new((0, 0), 7, filled)),
            )
            .map_err(err)?;
        if !has_f64 {
            f32s.label(legend.to_string())
                .legend(move |(x, y)| TriangleMarker::new((x + 8, y), 7, filled));
        }
    }
    // Labels: the lines' at the top of the plot, then the points' (next to the Â marker).
    let mut placed = Vec::new();
    let line_labels: Vec<((i32, i32), String)> = panel
        .lines
        .iter()
        .map(|l| (chart.backend_coord(&(l.ns, yr.end)), l.label.clone()))
        .collect();
    place_labels(root, &line_labels, below, &mut placed)?;
    let labels: Vec<((i32, i32), String)> = panel
        .points
        .iter()
        .map(|p| {
            (
                chart.backend_coord(&(p.ns, p.p99_ahat.max(ERROR_FLOOR))),
                p.label.clone(),
            )
        })
        .collect();
    place_labels(root, &labels, beside, &mut placed)?;
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::LowerRight)
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .label_font((FONT, 14))
        .draw()
        .map_err(err)?;
    Ok(())
}

/// Draws both panels on `root`, over one time axis.
fn draw_speed_accuracy<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    pts: &[SpeedPoint],
    panel: &KernelPanel,
) -> DrawResult
where
    DB::ErrorType: 'static,
{
    root.fill(&WHITE).map_err(err)?;
    let xr = log_range(
        pts.iter()
            .flat_map(|p| [p.ns_kernels, p.ns_svd])
            .chain(panel.points.iter().map(|p| p.ns))
            .chain(panel.lines.iter().map(|l| l.ns)),
        ERROR_FLOOR,
    );
    // Colors: the upper panel's methods in order, then the lower panel's other series.
    let mut keys: Vec<String> = Vec::new();
    for k in pts
        .iter()
        .map(|p| &p.method)
        .chain(panel.points.iter().map(|p| &p.series))
    {
        if !keys.contains(k) {
            keys.push(k.clone());
        }
    }
    let (upper, lower) = root.split_vertically(SPEED_UPPER_HEIGHT);
    draw_speed(&upper, pts, xr.clone(), &keys)?;
    draw_kernels(&lower, panel, xr, &keys)?;
    root.present().map_err(err)
}

/// Size of the speed–accuracy chart, and the height of its upper panel.
const SPEED_SIZE: (u32, u32) = (1200, 1500);
const SPEED_UPPER_HEIGHT: u32 = 780;

/// Writes the speed–accuracy chart as SVG and PNG: the SVD methods (upper panel) and the
/// kernel outputs (lower panel).
#[inline]
pub fn speed_accuracy(
    pts: &[SpeedPoint],
    panel: &KernelPanel,
    svg: &Path,
    png: &Path,
) -> DrawResult {
    draw_speed_accuracy(
        &SVGBackend::new(svg, SPEED_SIZE).into_drawing_area(),
        pts,
        panel,
    )?;
    draw_speed_accuracy(
        &BitMapBackend::new(png, SPEED_SIZE).into_drawing_area(),
        pts,
        panel,
    )
}
