//! The stability chart (SVG): per family of `F`, each method's error against the family's
//! parameter, log–log, f64 solid and f32 dashed.

use super::{color, err, log_range, sci, DrawResult, ERROR_FLOOR};
use ampm_tools::font::FONT;
use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::Path;

/// One curve of the stability chart: name ("method f32"), whether f32 (dashed), points.
#[derive(Clone, Debug)]
pub struct Curve {
    /// Method name (one color per method).
    pub method: String,
    /// f32 curves are dashed, f64 solid.
    pub is_f32: bool,
    /// `(family parameter, error)`.
    pub points: Vec<(f64, f64)>,
}

/// One panel of the stability chart (one family of `F`).
#[derive(Clone, Debug)]
pub struct Panel {
    /// Title, e.g. "distance to J = 0".
    pub title: String,
    /// Description of the x axis.
    pub x_desc: String,
    /// The curves.
    pub curves: Vec<Curve>,
}

fn draw_panel<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    panel: &Panel,
    methods: &[String],
    y_desc: &str,
) -> DrawResult
where
    DB::ErrorType: 'static,
{
    let all = || panel.curves.iter().flat_map(|c| c.points.iter());
    let xr = log_range(all().map(|p| p.0), f64::MIN_POSITIVE);
    let yr = log_range(all().map(|p| p.1), ERROR_FLOOR);
    let mut chart = ChartBuilder::on(area)
        .caption(&panel.title, (FONT, 18))
        .margin(12)
        .x_label_area_size(44)
        .y_label_area_size(68)
        .build_cartesian_2d(xr.log_scale(), yr.log_scale())
        .map_err(err)?;
    chart
        .configure_mesh()
        .x_desc(format!("{} (solid: f64, dashed: f32)", panel.x_desc))
        .y_desc(y_desc)
        .x_label_formatter(&sci)
        .y_label_formatter(&sci)
        .label_style((FONT, 12))
        .axis_desc_style((FONT, 13))
        .draw()
        .map_err(err)?;
    let mut legend: Vec<&str> = Vec::new();
    for c in &panel.curves {
        let mi = methods.iter().position(|m| *m == c.method).unwrap_or(0);
        let col = color(mi);
        let pts: Vec<(f64, f64)> = c
            .points
            .iter()
            .filter(|p| p.0 > 0.0 && p.1.is_finite())
            .map(|&(x, y)| (x, y.max(ERROR_FLOOR)))
            .collect();
        let anno = if c.is_f32 {
            chart
                .draw_series(DashedLineSeries::new(
                    pts.clone(),
                    6,
                    4,
                    col.stroke_width(2),
                ))
                .map_err(err)?
        } else {
            chart
                .draw_series(LineSeries::new(pts.clone(), col.stroke_width(2)))
                .map_err(err)?
        };
        // One legend entry per method (color); the line style tells the precision.
        if !legend.contains(&c.method.as_str()) {
            legend.push(&c.method);
            anno.label(c.method.clone()).legend(move |(x, y)| {
                PathElement::new(vec![(x, y), (x + 16, y)], col.stroke_width(2))
            });
        }
        chart
            .draw_series(pts.iter().map(|&p| Circle::new(p, 2, col.filled())))
            .map_err(err)?;
    }
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperLeft)
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .label_font((FONT, 11))
        .draw()
        .map_err(err)
}

/// Writes the stability chart (one panel per family) as SVG.
#[inline]
pub fn stability(panels: &[Panel], y_desc: &str, svg: &Path) -> DrawResult {
    let mut methods: Vec<String> = Vec::new();
    for c in panels.iter().flat_map(|p| p.curves.iter()) {
        if !methods.contains(&c.method) {
            methods.push(c.method.clone());
        }
    }
    let cols = panels.len().clamp(1, 2);
    let rows = panels.len().div_ceil(cols).max(1);
    let root = SVGBackend::new(svg, (700 * cols as u32, 520 * rows as u32)).into_drawing_area();
    root.fill(&WHITE).map_err(err)?;
    for (area, panel) in root.split_evenly((rows, cols)).iter().zip(panels) {
        draw_panel(area, panel, &methods, y_desc)?;
    }
    root.present().map_err(err)
}
