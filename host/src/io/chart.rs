//! SVG charts with `plotters` (SVG needs no font files, so it works on any machine).

use std::path::Path;

use anyhow::{anyhow, ensure, Result};
use plotters::prelude::*;

/// One named line of a chart.
#[derive(Debug, Clone, PartialEq)]
pub struct Series {
    /// Legend label.
    pub name: String,
    /// `(x, y)` points, drawn in order.
    pub points: Vec<(f64, f64)>,
}

const COLOURS: [RGBColor; 8] = [
    RGBColor(31, 119, 180),
    RGBColor(214, 39, 40),
    RGBColor(44, 160, 44),
    RGBColor(255, 127, 14),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(23, 190, 207),
];

fn range(vals: impl Iterator<Item = f64>) -> Result<(f64, f64)> {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for v in vals.filter(|v| v.is_finite()) {
        lo = lo.min(v);
        hi = hi.max(v);
    }
    ensure!(lo <= hi, "nothing finite to plot");
    if lo == hi {
        lo -= 0.5;
        hi += 0.5;
    }
    let pad = 0.03 * (hi - lo);
    Ok((lo - pad, hi + pad))
}

/// A line chart of several series with markers and a legend, written as SVG.
pub fn line_chart(
    path: impl AsRef<Path>,
    title: &str,
    x_label: &str,
    y_label: &str,
    series: &[Series],
) -> Result<()> {
    chart(path.as_ref(), title, x_label, y_label, series, false)
}

/// [`line_chart`] with a logarithmic y axis (points with `y <= 0` are left out).
pub fn line_chart_log_y(
    path: impl AsRef<Path>,
    title: &str,
    x_label: &str,
    y_label: &str,
    series: &[Series],
) -> Result<()> {
    chart(path.as_ref(), title, x_label, y_label, series, true)
}

fn chart(
    path: &Path,
    title: &str,
    x_label: &str,
    y_label: &str,
    series: &[Series],
    log_y: bool,
) -> Result<()> {
    super::ensure_parent(path)?;
    let shown = |p: &(f64, f64)| p.0.is_finite() && p.1.is_finite() && (!log_y || p.1 > 0.0);
    let (x0, x1) = range(
        series
            .iter()
            .flat_map(|s| s.points.iter().filter(|p| shown(p)).map(|p| p.0)),
    )?;
    let ys = || {
        series
            .iter()
            .flat_map(|s| s.points.iter().filter(|p| shown(p)).map(|p| p.1))
    };
    // Linear axes pad the range; a log axis takes the shown (positive) values alone: padding
    // below zero and clamping to f64::MIN_POSITIVE made plotters' tick search never end.
    let (y0, y1) = if log_y {
        ensure!(
            ys().next().is_some(),
            "nothing positive to plot on a log axis"
        );
        ys().fold((f64::INFINITY, 0.0f64), |(a, b), v| (a.min(v), b.max(v)))
    } else {
        range(ys())?
    };
    let root = SVGBackend::new(path, (900, 600)).into_drawing_area();
    let e = |e: DrawingAreaErrorKind<_>| anyhow!("plotting {}: {e:?}", path.display());
    root.fill(&WHITE).map_err(e)?;
    let mut builder = ChartBuilder::on(&root);
    builder
        .caption(title, ("sans-serif", 22))
        .margin(15)
        .x_label_area_size(45)
        .y_label_area_size(60);
    macro_rules! draw {
        ($chart:expr) => {{
            let mut chart = $chart.map_err(e)?;
            chart
                .configure_mesh()
                .x_desc(x_label)
                .y_desc(y_label)
                .draw()
                .map_err(e)?;
            for (k, s) in series.iter().enumerate() {
                let col = COLOURS[k % COLOURS.len()];
                let pts: Vec<(f64, f64)> = s.points.iter().copied().filter(|p| shown(p)).collect();
                chart
                    .draw_series(LineSeries::new(pts.clone(), col.stroke_width(2)))
                    .map_err(e)?
                    .label(s.name.clone())
                    .legend(move |(x, y)| {
                        PathElement::new(vec![(x, y), (x + 20, y)], col.stroke_width(2))
                    });
                chart
                    .draw_series(pts.iter().map(|&p| Circle::new(p, 3, col.filled())))
                    .map_err(e)?;
            }
            chart
                .configure_series_labels()
                .background_style(WHITE.mix(0.8))
                .border_style(BLACK)
                .draw()
                .map_err(e)?;
        }};
    }
    if log_y {
        draw!(builder.build_cartesian_2d(x0..x1, (y0 * 0.8..y1 * 1.25).log_scale()));
    } else {
        draw!(builder.build_cartesian_2d(x0..x1, y0..y1));
    }
    root.present().map_err(e)?;
    Ok(())
}

/// Overlaid histograms (as step outlines, normalised to densities) of several samples
/// over a common range, written as SVG.
pub fn histogram(
    path: impl AsRef<Path>,
    title: &str,
    x_label: &str,
    samples: &[(String, Vec<f64>)],
    bins: usize,
) -> Result<()> {
    ensure!(bins > 0, "a histogram needs at least one bin");
    let (lo, hi) = range(samples.iter().flat_map(|s| s.1.iter().copied()))?;
    let width = (hi - lo) / bins as f64;
    let series: Vec<Series> = samples
        .iter()
        .map(|(name, xs)| {
            let mut counts = vec![0usize; bins];
            let mut n = 0usize;
            for &x in xs.iter().filter(|x| x.is_finite()) {
                let b = (((x - lo) / width) as usize).min(bins - 1);
                counts[b] += 1;
                n += 1;
            }
            let mut points = Vec::with_capacity(2 * bins + 2);
            points.push((lo, 0.0));
            for (b, &c) in counts.iter().enumerate() {
                let d = c as f64 / (n.max(1) as f64 * width);
                points.push((lo + b as f64 * width, d));
                points.push((lo + (b + 1) as f64 * width, d));
            }
            points.push((hi, 0.0));
            Series {
                name: name.clone(),
                points,
            }
        })
        .collect();
    line_chart(path, title, x_label, "density", &series)
}

/// One cell of a [`heatmap`]: `[x0, x1) x [y0, y1)` with a value.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Cell {
    /// Lower x edge.
    pub x0: f64,
    /// Upper x edge.
    pub x1: f64,
    /// Lower y edge.
    pub y0: f64,
    /// Upper y edge.
    pub y1: f64,
    /// Value (mapped linearly from its minimum, white, to its maximum, black).
    pub value: f64,
}

/// A grey-scale map of `cells` with `tracks` drawn over it as coloured markers, written as
/// SVG (e.g. the power of every frame and bin with a detector's estimates).
pub fn heatmap(
    path: impl AsRef<Path>,
    title: &str,
    x_label: &str,
    y_label: &str,
    cells: &[Cell],
    tracks: &[Series],
) -> Result<()> {
    let path = path.as_ref();
    super::ensure_parent(path)?;
    let (x0, x1) = range(cells.iter().flat_map(|c| [c.x0, c.x1]))?;
    let (y0, y1) = range(cells.iter().flat_map(|c| [c.y0, c.y1]))?;
    let (v0, v1) = range(cells.iter().map(|c| c.value))?;
    let root = SVGBackend::new(path, (900, 600)).into_drawing_area();
    let e = |e: DrawingAreaErrorKind<_>| anyhow!("plotting {}: {e:?}", path.display());
    root.fill(&WHITE).map_err(e)?;
    let mut chart = ChartBuilder::on(&root)
        .caption(title, ("sans-serif", 22))
        .margin(15)
        .x_label_area_size(45)
        .y_label_area_size(60)
        .build_cartesian_2d(x0..x1, y0..y1)
        .map_err(e)?;
    chart
        .configure_mesh()
        .disable_mesh()
        .x_desc(x_label)
        .y_desc(y_label)
        .draw()
        .map_err(e)?;
    chart
        .draw_series(cells.iter().filter(|c| c.value.is_finite()).map(|c| {
            let g = (255.0 * (1.0 - (c.value - v0) / (v1 - v0))).clamp(0.0, 255.0) as u8;
            Rectangle::new([(c.x0, c.y0), (c.x1, c.y1)], RGBColor(g, g, g).filled())
        }))
        .map_err(e)?;
    markers(&mut chart, tracks, e)?;
    root.present().map_err(e)?;
    Ok(())
}

/// A scatter of `background` points (small, grey) with `series` over them as coloured
/// markers and a legend, written as SVG (e.g. every plot of every scan with the tracks
/// found in them).
pub fn scatter(
    path: impl AsRef<Path>,
    title: &str,
    x_label: &str,
    y_label: &str,
    background: &[(f64, f64)],
    series: &[Series],
) -> Result<()> {
    let path = path.as_ref();
    super::ensure_parent(path)?;
    let all = || {
        background
            .iter()
            .copied()
            .chain(series.iter().flat_map(|s| s.points.iter().copied()))
    };
    let (x0, x1) = range(all().map(|p| p.0))?;
    let (y0, y1) = range(all().map(|p| p.1))?;
    let root = SVGBackend::new(path, (900, 800)).into_drawing_area();
    let e = |e: DrawingAreaErrorKind<_>| anyhow!("plotting {}: {e:?}", path.display());
    root.fill(&WHITE).map_err(e)?;
    let mut chart = ChartBuilder::on(&root)
        .caption(title, ("sans-serif", 22))
        .margin(15)
        .x_label_area_size(45)
        .y_label_area_size(60)
        .build_cartesian_2d(x0..x1, y0..y1)
        .map_err(e)?;
    chart
        .configure_mesh()
        .x_desc(x_label)
        .y_desc(y_label)
        .draw()
        .map_err(e)?;
    let grey = RGBColor(190, 190, 190);
    chart
        .draw_series(
            background
                .iter()
                .filter(|p| p.0.is_finite() && p.1.is_finite())
                .map(|&p| Circle::new(p, 1, grey.filled())),
        )
        .map_err(e)?;
    markers(&mut chart, series, e)?;
    root.present().map_err(e)?;
    Ok(())
}

type Chart<'a, 'b> = ChartContext<
    'a,
    SVGBackend<'b>,
    Cartesian2d<plotters::coord::types::RangedCoordf64, plotters::coord::types::RangedCoordf64>,
>;

/// Draws each series as filled markers with a legend entry.
fn markers<'a, 'b: 'a, E>(
    chart: &mut Chart<'a, 'b>,
    series: &[Series],
    e: impl Fn(DrawingAreaErrorKind<<SVGBackend<'b> as DrawingBackend>::ErrorType>) -> E,
) -> std::result::Result<(), E> {
    for (k, s) in series.iter().enumerate() {
        let col = COLOURS[k % COLOURS.len()];
        chart
            .draw_series(
                s.points
                    .iter()
                    .filter(|p| p.0.is_finite() && p.1.is_finite())
                    .map(|&p| Circle::new(p, 3, col.filled())),
            )
            .map_err(&e)?
            .label(s.name.clone())
            .legend(move |(x, y)| Circle::new((x + 10, y), 3, col.filled()));
    }
    if !series.is_empty() {
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.8))
            .border_style(BLACK)
            .draw()
            .map_err(&e)?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn writes_svg() {
        let dir = std::env::temp_dir().join(format!("faint-plot-{}", std::process::id()));
        let p = dir.join("c.svg");
        line_chart(
            &p,
            "Pd vs SNR",
            "SNR (dB)",
            "Pd",
            &[Series {
                name: "a".into(),
                points: vec![(0.0, 0.1), (1.0, 0.5), (2.0, f64::NAN)],
            }],
        )
        .unwrap();
        let s = std::fs::read_to_string(&p).unwrap();
        assert!(s.starts_with("<svg") && s.contains("Pd vs SNR"));
        histogram(
            dir.join("h.svg"),
            "h",
            "x",
            &[("a".into(), vec![0.0, 1.0, 1.0])],
            4,
        )
        .unwrap();
        assert!(line_chart(dir.join("e.svg"), "t", "x", "y", &[]).is_err());
        // Regression: a log axis over small rates and zeros (Fig. 10 of the MHT-TBD
        // reproduction) once never finished.
        line_chart_log_y(
            dir.join("log.svg"),
            "rates",
            "x",
            "rate",
            &[Series {
                name: "r".into(),
                points: vec![(0.0, 0.0), (1.0, 1e-4), (2.0, 3e-3), (3.0, 0.0)],
            }],
        )
        .unwrap();
        let track = [Series {
            name: "track".into(),
            points: vec![(0.5, 0.5)],
        }];
        let cell = |x: f64, v: f64| Cell {
            x0: x,
            x1: x + 1.0,
            y0: 0.0,
            y1: 1.0,
            value: v,
        };
        heatmap(
            dir.join("m.svg"),
            "map",
            "x",
            "y",
            &[cell(0.0, 1.0), cell(1.0, 2.0)],
            &track,
        )
        .unwrap();
        scatter(
            dir.join("s.svg"),
            "sc",
            "x",
            "y",
            &[(0.0, 0.0), (1.0, 2.0)],
            &track,
        )
        .unwrap();
        let m = std::fs::read_to_string(dir.join("m.svg")).unwrap();
        assert!(m.contains("<rect") && m.contains("track"));
        std::fs::remove_dir_all(&dir).ok();
    }
}
