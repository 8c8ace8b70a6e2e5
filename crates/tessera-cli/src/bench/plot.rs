//! SVG line plots of the bench's series (plotters, SVG backend, line series only; text is
//! laid out by plotters' built-in estimate, so no font files are read).

use plotters::coord::ranged1d::{AsRangedCoord, ValueFormatter};
use plotters::prelude::*;
use std::path::Path;

/// One named line: points in drawing order.
pub struct Series {
    pub name: String,
    pub points: Vec<(f64, f64)>,
}

/// Axes of a plot.
pub struct Axes<'a> {
    pub title: &'a str,
    pub x: &'a str,
    pub y: &'a str,
    /// Logarithmic axes (then every value must be positive; others are left out).
    pub log_x: bool,
    pub log_y: bool,
}

/// The range of one axis over every series, padded; for a log axis a factor, else a share.
fn range(values: impl Iterator<Item = f64>, log: bool) -> (f64, f64) {
    let (mut lo, mut hi) = values.fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), v| (l.min(v), h.max(v)));
    if !lo.is_finite() {
        return if log { (1.0, 10.0) } else { (0.0, 1.0) };
    }
    if log {
        if hi <= lo * 1.01 {
            hi = lo * 2.0;
        }
        (lo / 1.3, hi * 1.3)
    } else {
        if hi - lo < 1e-12 {
            hi = lo + lo.abs().max(1.0);
        }
        let pad = 0.05 * (hi - lo);
        lo = if lo >= 0.0 { (lo - pad).max(0.0) } else { lo - pad };
        (lo, hi + pad)
    }
}

/// Writes an SVG line plot of `series` to `path` (with a dot on every point and a legend).
/// Errors name the file.
pub fn lines(path: &Path, axes: &Axes, series: &[Series]) -> Result<(), String> {
    let keep = |v: f64, log: bool| v.is_finite() && (!log || v > 0.0);
    let series: Vec<Series> = series
        .iter()
        .map(|s| Series {
            name: s.name.clone(),
            points: s
                .points
                .iter()
                .copied()
                .filter(|&(x, y)| keep(x, axes.log_x) && keep(y, axes.log_y))
                .collect(),
        })
        .filter(|s| !s.points.is_empty())
        .collect();
    let xs = range(series.iter().flat_map(|s| s.points.iter().map(|p| p.0)), axes.log_x);
    let ys = range(series.iter().flat_map(|s| s.points.iter().map(|p| p.1)), axes.log_y);
    let err = |e: String| format!("{}: {e}", path.display());
    match (axes.log_x, axes.log_y) {
        (true, true) => draw(path, axes, &series, (xs.0..xs.1).log_scale(), (ys.0..ys.1).log_scale()),
        (true, false) => draw(path, axes, &series, (xs.0..xs.1).log_scale(), ys.0..ys.1),
        (false, true) => draw(path, axes, &series, xs.0..xs.1, (ys.0..ys.1).log_scale()),
        (false, false) => draw(path, axes, &series, xs.0..xs.1, ys.0..ys.1),
    }
    .map_err(err)
}

/// An axis label: large numbers as 12k or 1.5M, the rest as they print.
fn label(v: &f64) -> String {
    let trim = |x: f64, unit: &str| {
        format!("{}{unit}", format!("{x:.2}").trim_end_matches('0').trim_end_matches('.'))
    };
    match v.abs() {
        a if a >= 1e6 => trim(v / 1e6, "M"),
        a if a >= 1e4 => trim(v / 1e3, "k"),
        _ => format!("{v}"),
    }
}

fn draw<X, Y>(path: &Path, axes: &Axes, series: &[Series], x: X, y: Y) -> Result<(), String>
where
    X: AsRangedCoord<Value = f64>,
    Y: AsRangedCoord<Value = f64>,
    X::CoordDescType: ValueFormatter<f64>,
    Y::CoordDescType: ValueFormatter<f64>,
{
    let root = SVGBackend::new(path, (860, 540)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| e.to_string())?;
    let mut chart = ChartBuilder::on(&root)
        .caption(axes.title, ("sans-serif", 20))
        .margin(14)
        .x_label_area_size(44)
        .y_label_area_size(72)
        .build_cartesian_2d(x, y)
        .map_err(|e| e.to_string())?;
    chart
        .configure_mesh()
        .x_desc(axes.x)
        .y_desc(axes.y)
        .x_label_formatter(&label)
        .y_label_formatter(&label)
        .light_line_style(WHITE.mix(0.0))
        .draw()
        .map_err(|e| e.to_string())?;
    for (i, s) in series.iter().enumerate() {
        let color = Palette99::pick(i).to_rgba();
        chart
            .draw_series(LineSeries::new(s.points.iter().copied(), color.stroke_width(2)))
            .map_err(|e| e.to_string())?
            .label(s.name.clone())
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], color.stroke_width(2)));
        chart
            .draw_series(s.points.iter().map(|&p| Circle::new(p, 3, color.filled())))
            .map_err(|e| e.to_string())?;
    }
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperRight)
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .draw()
        .map_err(|e| e.to_string())?;
    root.present().map_err(|e| e.to_string())?;
    Ok(())
}
