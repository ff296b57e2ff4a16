//! Log-log plots — error against time, and any lines with point labels and markers (plotters, drawn into an RGB buffer and written as
//! PNG by the `png` crate). Text uses egui's bundled Ubuntu Light, so no system font is read.

use std::path::Path;
use std::sync::Once;

use plotters::prelude::*;

use super::error_curves::Curve;
use crate::files::{write_atomically, WriteError};

/// Plot size in pixels.
pub const SIZE: (u32, u32) = (960, 600);

/// Line colours, one per curve (cycled).
const COLOURS: [RGBColor; 10] = [
    RGBColor(31, 119, 180),
    RGBColor(214, 39, 40),
    RGBColor(44, 160, 44),
    RGBColor(255, 127, 14),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(23, 190, 207),
    RGBColor(127, 127, 127),
    RGBColor(188, 189, 34),
];

fn register_font() {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        // Fails only for bytes that are not a font; these are egui's own.
        let _ = plotters::style::register_font(
            "sans-serif",
            FontStyle::Normal,
            epaint_default_fonts::UBUNTU_LIGHT,
        );
    });
}

/// Axis ticks for a logarithmic axis over `[lo, hi]`: 1, 2, 5 × 10ᵏ, or every 1…9 × 10ᵏ when
/// that gives fewer than four.
fn ticks(lo: f64, hi: f64) -> Vec<f64> {
    let within = |mantissas: &[f64]| -> Vec<f64> {
        let (k0, k1) = (lo.log10().floor() as i32, hi.log10().ceil() as i32);
        (k0..=k1)
            .flat_map(|k| mantissas.iter().map(move |m| m * 10f64.powi(k)))
            .filter(|v| (lo..=hi).contains(v))
            .collect()
    };
    let coarse = within(&[1.0, 2.0, 5.0]);
    if coarse.len() >= 4 {
        coarse
    } else {
        within(&[1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0])
    }
}

/// A number with as few digits as its size needs (axis labels).
fn compact(v: f64) -> String {
    if v >= 10.0 {
        format!("{v:.0}")
    } else if v >= 1.0 {
        format!("{v:.1}")
    } else {
        format!("{v:.2}")
    }
}

/// One line of a plot: its legend name, its points and (optionally) a label beside each point.
#[derive(Clone, Debug, Default)]
pub struct Series {
    /// Legend text.
    pub name: String,
    /// `(x, y)` points; those not positive on both axes are left out (log scales).
    pub points: Vec<(f64, f64)>,
    /// Text beside each point (empty: none).
    pub point_labels: Vec<String>,
}

/// What a log-log plot shows besides its lines.
#[derive(Clone, Debug, Default)]
pub struct Frame<'a> {
    /// Title above the plot.
    pub title: &'a str,
    /// The x axis' description.
    pub x: &'a str,
    /// The y axis' description.
    pub y: &'a str,
    /// Vertical marker lines: legend text and x position.
    pub markers: Vec<(String, f64)>,
    /// Put the legend in the lower left corner (where falling error curves leave room)
    /// instead of the upper right.
    pub legend_lower_left: bool,
}

/// Draws RMSE against seconds, both axes logarithmic, one line per curve with its fitted slope
/// in the legend; returns the RGB pixels, `SIZE` row by row.
pub fn draw(curves: &[Curve], title: &str) -> Result<Vec<u8>, String> {
    let series: Vec<Series> = curves
        .iter()
        .map(|curve| Series {
            name: match curve.slope() {
                Some(s) => format!("{} (slope {s:.2})", curve.name),
                None => curve.name.clone(),
            },
            points: curve.points.iter().map(|p| (p.secs, p.rmse)).collect(),
            point_labels: Vec::new(),
        })
        .collect();
    let frame = Frame {
        title,
        x: "seconds",
        y: "RMSE against the reference",
        markers: Vec::new(),
        legend_lower_left: true,
    };
    draw_series(&series, &frame)
}

/// Draws lines on log-log axes (ticks 1, 2, 5 × 10ᵏ), with point labels and vertical markers;
/// Whether a point can be drawn on log-log axes.
fn positive(&(x, y): &(f64, f64)) -> bool {
    x > 0.0 && y > 0.0 && x.is_finite() && y.is_finite()
}

/// The x and y ranges of the log-log axes: every drawable point and marker, with a margin.
fn log_ranges(series: &[Series], frame: &Frame) -> Result<[(f64, f64); 2], String> {
    let (mut x0, mut x1, mut y0, mut y1) = (f64::MAX, 0.0f64, f64::MAX, 0.0f64);
    for &(x, y) in series.iter().flat_map(|s| &s.points).filter(|p| positive(p)) {
        (x0, x1) = (x0.min(x), x1.max(x));
        (y0, y1) = (y0.min(y), y1.max(y));
    }
    for &(_, x) in frame.markers.iter().filter(|(_, x)| *x > 0.0) {
        (x0, x1) = (x0.min(x), x1.max(x));
    }
    if x1 <= 0.0 || y1 <= 0.0 {
        return Err("no point with positive coordinates to plot".into());
    }
    Ok([(x0 * 0.8, x1 * 1.25), (y0 * 0.8, y1 * 1.25)])
}

/// returns the RGB pixels, `SIZE` row by row.
pub fn draw_series(series: &[Series], frame: &Frame) -> Result<Vec<u8>, String> {
    register_font();
    let (w, h) = SIZE;
    let mut pixels = vec![255u8; (w * h * 3) as usize];
    let [xr, yr] = log_ranges(series, frame)?;
    {
        let root = BitMapBackend::with_buffer(&mut pixels, SIZE).into_drawing_area();
        let err = |e: &dyn std::fmt::Display| e.to_string();
        let mut chart = ChartBuilder::on(&root)
            .caption(frame.title, ("sans-serif", 22))
            .margin(16)
            .x_label_area_size(44)
            .y_label_area_size(72)
            .build_cartesian_2d(
                (xr.0..xr.1).log_scale().with_key_points(ticks(xr.0, xr.1)),
                (yr.0..yr.1).log_scale().with_key_points(ticks(yr.0, yr.1)),
            )
            .map_err(|e| err(&e))?;
        chart
            .configure_mesh()
            .x_desc(frame.x)
            .y_desc(frame.y)
            .x_label_formatter(&|v| compact(*v))
            .y_label_formatter(&|v| format!("{v:.0e}"))
            .light_line_style(RGBColor(238, 238, 238))
            .label_style(("sans-serif", 15))
            .draw()
            .map_err(|e| err(&e))?;
        for (k, line) in series.iter().enumerate() {
            let colour = COLOURS[k % COLOURS.len()];
            let points: Vec<(f64, f64)> = line.points.iter().copied().filter(positive).collect();
            chart
                .draw_series(LineSeries::new(points.clone(), colour.stroke_width(2)))
                .map_err(|e| err(&e))?
                .label(line.name.clone())
                .legend(move |(x, y)| PathElement::new([(x, y), (x + 18, y)], colour.stroke_width(2)));
            let labelled = line
                .points
                .iter()
                .zip(&line.point_labels)
                .filter(|(p, _)| positive(p));
            chart
                .draw_series(labelled.map(|(&(x, y), text)| {
                    EmptyElement::at((x, y))
                        + Circle::new((0, 0), 3, colour.filled())
                        + Text::new(text.clone(), (6, -16), ("sans-serif", 14))
                }))
                .map_err(|e| err(&e))?;
        }
        for (k, (name, x)) in frame.markers.iter().enumerate() {
            let colour = COLOURS[(series.len() + k) % COLOURS.len()];
            chart
                .draw_series(LineSeries::new([(*x, yr.0), (*x, yr.1)], colour.stroke_width(2)))
                .map_err(|e| err(&e))?
                .label(name.clone())
                .legend(move |(x, y)| PathElement::new([(x, y), (x + 18, y)], colour.stroke_width(2)));
        }
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .label_font(("sans-serif", 15))
            .position(if frame.legend_lower_left {
                SeriesLabelPosition::LowerLeft
            } else {
                SeriesLabelPosition::UpperRight
            })
            .draw()
            .map_err(|e| err(&e))?;
        root.present().map_err(|e| err(&e))?;
    }
    Ok(pixels)
}

/// Draws the plot ([`draw`]) and writes it to `path` as PNG (replacing it only when `force`).
pub fn write_plot(curves: &[Curve], title: &str, path: &Path, force: bool) -> Result<(), WriteError> {
    let pixels = draw(curves, title).map_err(|message| WriteError::Failed {
        path: path.to_owned(),
        message,
    })?;
    write_png(&pixels, path, force)
}

/// Writes plot pixels (`SIZE`, RGB) to `path` as PNG (replacing it only when `force`).
pub fn write_png(pixels: &[u8], path: &Path, force: bool) -> Result<(), WriteError> {
    write_atomically(path, force, |temporary| {
        let file = std::fs::File::create(temporary).map_err(|e| e.to_string())?;
        let mut encoder = png::Encoder::new(std::io::BufWriter::new(file), SIZE.0, SIZE.1);
        encoder.set_color(png::ColorType::Rgb);
        encoder.set_depth(png::BitDepth::Eight);
        let mut writer = encoder.write_header().map_err(|e| e.to_string())?;
        writer.write_image_data(pixels).map_err(|e| e.to_string())?;
        writer.finish().map_err(|e| e.to_string())
    })
}
