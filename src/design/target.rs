//! The picture a design aims at: an image (PNG, JPEG, OpenEXR or PFM) taken as luminance and
//! laid onto the receiver, its top-left pixel at `corner + edge_v`, `x` along `edge_u`, rows
//! running towards `corner`; resampled to the grid the photons are gathered in.

use std::path::Path;

use crate::color::srgb_to_linear;

/// The largest target side read, in pixels.
const MAX_SIDE: u32 = 16384;

/// A target: linear luminance, row 0 at the top.
#[derive(Clone, Debug, PartialEq)]
pub struct Target {
    /// Pixels per row.
    pub width: usize,
    /// Rows.
    pub height: usize,
    /// `width × height` luminances, not negative, not all zero.
    pub values: Vec<f64>,
}

/// The luminance of a linear RGB pixel.
fn luminance(rgb: [f32; 3]) -> f64 {
    crate::color::luminance(glam::Vec3::from(rgb).as_dvec3())
}

/// Reads the target at `path`: a `.pfm` or `.exr` is linear already; other images (PNG,
/// JPEG) are sRGB and made linear.
pub fn load_target(path: &Path) -> Result<Target, String> {
    crate::input_file::regular_file(path).map_err(|why| format!("the target {why}"))?;
    let extension = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    let (width, height, values) = if extension.as_deref() == Some("pfm") {
        let bytes = crate::input_file::read_bytes(path, crate::input_file::MAX_TEXT_BYTES)
            .map_err(|why| format!("the target {why}"))?;
        let image = crate::render::compare::read_pfm(&bytes)?;
        let values: Vec<f64> = image.pixels.iter().map(|&p| luminance(p)).collect();
        (image.width as usize, image.height as usize, values)
    } else {
        let mut reader = image::ImageReader::open(path)
            .map_err(|e| format!("the target cannot be opened: {e}"))?
            .with_guessed_format()
            .map_err(|e| format!("the target cannot be read: {e}"))?;
        let mut limits = image::Limits::default();
        limits.max_image_width = Some(MAX_SIDE);
        limits.max_image_height = Some(MAX_SIDE);
        reader.limits(limits);
        let decoded = reader
            .decode()
            .map_err(|e| format!("the target is not a readable image: {e}"))?;
        let linear = extension.as_deref() == Some("exr");
        let rgb = decoded.to_rgb32f();
        let values: Vec<f64> = rgb
            .pixels()
            .map(|p| {
                let c = if linear {
                    p.0
                } else {
                    p.0.map(|x| srgb_to_linear(f64::from(x)) as f32)
                };
                luminance(c)
            })
            .collect();
        (rgb.width() as usize, rgb.height() as usize, values)
    };
    if let Some(bad) = values.iter().find(|v: &&f64| !(v.is_finite() && **v >= 0.0)) {
        return Err(format!(
            "the target holds a luminance of {bad}; it must be finite and not negative"
        ));
    }
    if !values.iter().any(|&v| v > 0.0) {
        return Err("the target is black everywhere: there is nothing to aim the light at".into());
    }
    Ok(Target {
        width,
        height,
        values,
    })
}

impl Target {
    /// The target averaged over an `nx × ny` grid (row 0 at the top), each pixel shared among
    /// the cells it overlaps by area, scaled to sum to 1.
    pub fn resampled(&self, nx: usize, ny: usize) -> Vec<f64> {
        // Each source pixel `[x, x+1)` covers `[x·n/w, (x+1)·n/w)` in cell units.
        let overlaps = |pixels: usize, cells: usize| -> Vec<Vec<(usize, f64)>> {
            (0..pixels)
                .map(|x| {
                    let (a, b) = (
                        x as f64 * cells as f64 / pixels as f64,
                        (x + 1) as f64 * cells as f64 / pixels as f64,
                    );
                    (a.floor() as usize..(b.ceil() as usize).min(cells))
                        .map(|c| (c, (b.min(c as f64 + 1.0) - a.max(c as f64)).max(0.0)))
                        .filter(|(_, w)| *w > 0.0)
                        .collect()
                })
                .collect()
        };
        let (along_x, along_y) = (overlaps(self.width, nx), overlaps(self.height, ny));
        let mut out = vec![0.0; nx * ny];
        for (y, ys) in along_y.iter().enumerate() {
            for (x, xs) in along_x.iter().enumerate() {
                let value = self.values[y * self.width + x];
                for &(cy, wy) in ys {
                    for &(cx, wx) in xs {
                        out[cy * nx + cx] += value * wx * wy;
                    }
                }
            }
        }
        let sum: f64 = out.iter().sum();
        out.iter_mut().for_each(|v| *v /= sum);
        out
    }
}

/// Pearson's correlation of two pictures of the same size (1: the same up to brightness and
/// offset; 0 where either is flat).
pub fn correlation(a: &[f64], b: &[f64]) -> f64 {
    let n = a.len().min(b.len()) as f64;
    if n == 0.0 {
        return 0.0;
    }
    let (ma, mb) = (a.iter().sum::<f64>() / n, b.iter().sum::<f64>() / n);
    let (mut ab, mut aa, mut bb) = (0.0, 0.0, 0.0);
    for (x, y) in a.iter().zip(b) {
        ab += (x - ma) * (y - mb);
        aa += (x - ma) * (x - ma);
        bb += (y - mb) * (y - mb);
    }
    if aa > 0.0 && bb > 0.0 {
        ab / (aa * bb).sqrt()
    } else {
        0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn resampling_keeps_a_uniform_image_uniform_and_the_rows_in_place() {
        let flat = Target {
            width: 64,
            height: 64,
            values: vec![1.0; 64 * 64],
        };
        let grid = flat.resampled(48, 36);
        assert!(
            grid.iter().all(|v| (v - 1.0 / (48.0 * 36.0)).abs() < 1e-12),
            "{grid:?}"
        );
        let mut top = flat.clone();
        top.values.iter_mut().skip(32 * 64).for_each(|v| *v = 0.0);
        let grid = top.resampled(4, 4);
        assert!(grid[..8].iter().all(|&v| v > 0.0) && grid[8..].iter().all(|&v| v == 0.0));
    }
}
