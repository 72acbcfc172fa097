//! SVG plots of bench results (plotters, SVG backend only): frame time along the fly-through
//! per method, a stacked stage breakdown per method, and suite sweeps (mean frame time over a
//! swept parameter, one line per method).

use std::path::{Path, PathBuf};

use plotters::prelude::*;

use crate::error::CliError;

fn plot_err(path: &Path, e: impl std::fmt::Display) -> CliError {
    CliError::Other(format!("{}: could not draw the plot: {e}", path.display()))
}

/// `out.svg` -> `out-stages.svg` (same directory).
pub fn stages_path(path: &Path) -> PathBuf {
    let stem = path.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_else(|| "bench".into());
    path.with_file_name(format!("{stem}-stages.svg"))
}

/// `out.svg` -> `out-TAG.svg`.
pub fn tagged_path(path: &Path, tag: &str) -> PathBuf {
    let stem = path.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_else(|| "bench".into());
    let tag: String = tag.chars().map(|c| if c.is_ascii_alphanumeric() || c == '-' { c } else { '_' }).collect();
    path.with_file_name(format!("{stem}-{tag}.svg"))
}

fn color(i: usize) -> RGBColor {
    // Distinguishable on white; cycles after 10.
    const C: [(u8, u8, u8); 10] = [
        (31, 119, 180),
        (255, 127, 14),
        (44, 160, 44),
        (214, 39, 40),
        (148, 103, 189),
        (140, 86, 75),
        (227, 119, 194),
        (127, 127, 127),
        (188, 189, 34),
        (23, 190, 207),
    ];
    let (r, g, b) = C[i % C.len()];
    RGBColor(r, g, b)
}

/// One line per series: (name, points (x, y)). Log-scale x when `log_x` (sweeps over
/// triangle counts).
pub fn lines(
    path: &Path,
    title: &str,
    x_desc: &str,
    y_desc: &str,
    series: &[(String, Vec<(f64, f64)>)],
    log_x: bool,
) -> Result<(), CliError> {
    let pts = series.iter().flat_map(|(_, p)| p.iter()).filter(|(x, y)| x.is_finite() && y.is_finite());
    let (mut x0, mut x1, mut y1) = (f64::INFINITY, f64::NEG_INFINITY, 0.0f64);
    for &(x, y) in pts {
        x0 = x0.min(x);
        x1 = x1.max(x);
        y1 = y1.max(y);
    }
    if !x0.is_finite() {
        (x0, x1) = (0.0, 1.0);
    }
    if x1 <= x0 {
        x1 = x0 + 1.0;
    }
    let y1 = if y1 > 0.0 { y1 * 1.1 } else { 1.0 };
    let root = SVGBackend::new(path, (960, 540)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| plot_err(path, e))?;
    let mut builder = ChartBuilder::on(&root);
    builder.caption(title, ("sans-serif", 20)).margin(12).x_label_area_size(40).y_label_area_size(60);
    macro_rules! draw {
        ($chart:expr) => {{
            let mut chart = $chart;
            chart.configure_mesh().x_desc(x_desc).y_desc(y_desc).draw().map_err(|e| plot_err(path, e))?;
            for (i, (name, p)) in series.iter().enumerate() {
                let c = color(i);
                chart
                    .draw_series(LineSeries::new(p.iter().copied(), c.stroke_width(2)))
                    .map_err(|e| plot_err(path, e))?
                    .label(name.as_str())
                    .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], c.stroke_width(2)));
                chart
                    .draw_series(p.iter().map(|&(x, y)| Circle::new((x, y), 3, c.filled())))
                    .map_err(|e| plot_err(path, e))?;
            }
            chart
                .configure_series_labels()
                .position(SeriesLabelPosition::UpperLeft)
                .background_style(WHITE.mix(0.85))
                .border_style(BLACK)
                .draw()
                .map_err(|e| plot_err(path, e))?;
        }};
    }
    if log_x && x0 > 0.0 {
        draw!(builder.build_cartesian_2d((x0 * 0.9..x1 * 1.1).log_scale(), 0f64..y1).map_err(|e| plot_err(path, e))?);
    } else {
        draw!(builder.build_cartesian_2d(x0..x1, 0f64..y1).map_err(|e| plot_err(path, e))?);
    }
    root.present().map_err(|e| plot_err(path, e))
}

/// Horizontal stacked bars, one per row (e.g. method): segments = stages in `stage_names`
/// order, lengths in ms; each bar labelled with its row name and total.
pub fn stacked_bars(
    path: &Path,
    title: &str,
    stage_names: &[String],
    rows: &[(String, Vec<f64>)],
) -> Result<(), CliError> {
    let total = |v: &Vec<f64>| v.iter().copied().filter(|x| x.is_finite()).sum::<f64>();
    let max = rows.iter().map(|(_, v)| total(v)).fold(0.0f64, f64::max);
    let x1 = if max > 0.0 { max * 1.6 } else { 1.0 };
    let n = rows.len().max(1) as f64;
    let height = (120 + 40 * rows.len()).clamp(240, 1400) as u32;
    let root = SVGBackend::new(path, (960, height)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| plot_err(path, e))?;
    let mut chart = ChartBuilder::on(&root)
        .caption(title, ("sans-serif", 20))
        .margin(12)
        .x_label_area_size(40)
        .y_label_area_size(10)
        .build_cartesian_2d(0f64..x1, -0.5f64..n - 0.5)
        .map_err(|e| plot_err(path, e))?;
    chart
        .configure_mesh()
        .disable_y_mesh()
        .y_labels(0)
        .x_desc("ms per frame (mean)")
        .draw()
        .map_err(|e| plot_err(path, e))?;
    for (s, name) in stage_names.iter().enumerate() {
        let c = color(s);
        let bars: Vec<Rectangle<(f64, f64)>> = rows
            .iter()
            .enumerate()
            .filter_map(|(r, (_, v))| {
                let start: f64 = v.iter().take(s).copied().filter(|x| x.is_finite()).sum();
                let len = v.get(s).copied().filter(|x| x.is_finite() && *x > 0.0)?;
                let y = (rows.len() - 1 - r) as f64;
                Some(Rectangle::new([(start, y - 0.35), (start + len, y + 0.35)], c.filled()))
            })
            .collect();
        chart
            .draw_series(bars)
            .map_err(|e| plot_err(path, e))?
            .label(name.as_str())
            .legend(move |(x, y)| Rectangle::new([(x, y - 5), (x + 12, y + 5)], c.filled()));
    }
    let labels: Vec<Text<(f64, f64), String>> = rows
        .iter()
        .enumerate()
        .map(|(r, (name, v))| {
            let y = (rows.len() - 1 - r) as f64;
            Text::new(format!(" {name}: {:.1} ms", total(v)), (total(v), y + 0.1), ("sans-serif", 14).into_font())
        })
        .collect();
    chart.draw_series(labels).map_err(|e| plot_err(path, e))?;
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::LowerRight)
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .draw()
        .map_err(|e| plot_err(path, e))?;
    root.present().map_err(|e| plot_err(path, e))
}
