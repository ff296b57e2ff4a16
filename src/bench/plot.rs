//! The log-log plot of error against time (plotters, drawn into an RGB buffer and written as
//! PNG by the `png` crate). Text uses egui's bundled Ubuntu Light, so no system font is read.

use std::path::Path;
use std::sync::Once;

use plotters::prelude::*;

use super::convergence::Curve;
use crate::files::{write_atomically, WriteError};

/// Plot size in pixels.
pub const SIZE: (u32, u32) = (960, 600);

/// Line colours, one per curve (cycled).
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

/// Draws RMSE against seconds, both axes logarithmic, one line per curve with its fitted slope
/// in the legend; returns the RGB pixels, `SIZE` row by row.
pub fn draw(curves: &[Curve], title: &str) -> Result<Vec<u8>, String> {
    register_font();
    let (w, h) = SIZE;
    let mut pixels = vec![255u8; (w * h * 3) as usize];
    let points = curves
        .iter()
        .flat_map(|c| &c.points)
        .filter(|p| p.secs > 0.0 && p.rmse > 0.0);
    let (mut t0, mut t1, mut e0, mut e1) = (f64::MAX, 0.0f64, f64::MAX, 0.0f64);
    for p in points {
        (t0, t1) = (t0.min(p.secs), t1.max(p.secs));
        (e0, e1) = (e0.min(p.rmse), e1.max(p.rmse));
    }
    if t1 <= 0.0 || e1 <= 0.0 {
        return Err("no checkpoint with a positive time and error to plot".into());
    }
    {
        let root = BitMapBackend::with_buffer(&mut pixels, SIZE).into_drawing_area();
        let err = |e: &dyn std::fmt::Display| e.to_string();
        let mut chart = ChartBuilder::on(&root)
            .caption(title, ("sans-serif", 22))
            .margin(16)
            .x_label_area_size(44)
            .y_label_area_size(72)
            .build_cartesian_2d(
                (t0 * 0.9..t1 * 1.1)
                    .log_scale()
                    .with_key_points(ticks(t0 * 0.9, t1 * 1.1)),
                (e0 * 0.9..e1 * 1.1)
                    .log_scale()
                    .with_key_points(ticks(e0 * 0.9, e1 * 1.1)),
            )
            .map_err(|e| err(&e))?;
        chart
            .configure_mesh()
            .x_desc("seconds")
            .y_desc("RMSE against the reference")
            .x_label_formatter(&|v| compact(*v))
            .y_label_formatter(&|v| format!("{v:.0e}"))
            .light_line_style(RGBColor(238, 238, 238))
            .label_style(("sans-serif", 15))
            .draw()
            .map_err(|e| err(&e))?;
        for (k, curve) in curves.iter().enumerate() {
            let colour = COLOURS[k % COLOURS.len()];
            let line = curve
                .points
                .iter()
                .filter(|p| p.secs > 0.0 && p.rmse > 0.0)
                .map(|p| (p.secs, p.rmse));
            let label = match curve.slope() {
                Some(s) => format!("{} (slope {s:.2})", curve.name),
                None => curve.name.clone(),
            };
            chart
                .draw_series(LineSeries::new(line, colour.stroke_width(2)))
                .map_err(|e| err(&e))?
                .label(label)
                .legend(move |(x, y)| PathElement::new([(x, y), (x + 18, y)], colour.stroke_width(2)));
        }
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .label_font(("sans-serif", 15))
            .position(SeriesLabelPosition::UpperRight)
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
    write_atomically(path, force, |temporary| {
        let file = std::fs::File::create(temporary).map_err(|e| e.to_string())?;
        let mut encoder = png::Encoder::new(std::io::BufWriter::new(file), SIZE.0, SIZE.1);
        encoder.set_color(png::ColorType::Rgb);
        encoder.set_depth(png::BitDepth::Eight);
        let mut writer = encoder.write_header().map_err(|e| e.to_string())?;
        writer.write_image_data(&pixels).map_err(|e| e.to_string())?;
        writer.finish().map_err(|e| e.to_string())
    })
}
