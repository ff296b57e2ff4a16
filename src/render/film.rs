//! The film: a linear RGB image, its tonemapping (exposure in stops, then the sRGB transfer
//! curve), and writers for PNG (8-bit sRGB, text chunks) and OpenEXR (linear 32-bit float,
//! custom string attributes) carrying the render's metadata. Files are written to a temporary
//! name beside the target and renamed, so a failed write never leaves half a file.

use std::path::{Path, PathBuf};

/// A linear RGB image, rows from the top.
#[derive(Clone, Debug, PartialEq)]
pub struct Image {
    /// Pixels per row.
    pub width: u32,
    /// Rows.
    pub height: u32,
    /// `width × height` linear RGB radiance values.
    pub pixels: Vec<[f32; 3]>,
}

/// Key/value pairs stored in the output file (scene, settings, time…).
pub type Metadata = Vec<(String, String)>;

/// Writing an image failed.
#[derive(Debug, thiserror::Error)]
pub enum FilmError {
    /// Output format not recognised from the extension.
    #[error("{}: unknown image format (use .png or .exr)", .0.display())]
    UnknownFormat(PathBuf),
    /// The file exists and overwriting was not asked for.
    #[error("{}: the file exists; choose another name or pass --force to overwrite it", .0.display())]
    Exists(PathBuf),
    /// I/O or encoder failure.
    #[error("{}: cannot write the image: {message}", path.display())]
    Write {
        /// The file.
        path: PathBuf,
        /// What failed.
        message: String,
    },
}

/// The sRGB transfer pair (IEC 61966-2-1): the encoded value of a linear one in [0, 1]...
pub fn linear_to_srgb(v: f32) -> f32 {
    if v <= 0.003_130_8 {
        12.92 * v
    } else {
        1.055 * v.powf(1.0 / 2.4) - 0.055
    }
}

/// ...and the linear value of an encoded one in [0, 1] (texture images are read with it).
pub fn srgb_to_linear(c: f64) -> f64 {
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

/// The output formats.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    /// 8-bit sRGB PNG, tonemapped.
    Png,
    /// 32-bit float linear OpenEXR.
    Exr,
}

impl Format {
    /// The format named by a path's extension.
    pub fn from_path(path: &Path) -> Option<Format> {
        match path.extension()?.to_str()?.to_ascii_lowercase().as_str() {
            "png" => Some(Format::Png),
            "exr" => Some(Format::Exr),
            _ => None,
        }
    }
}

/// Tonemapped 8-bit sRGB bytes of linear RGB pixels: linear × 2^stops, clamped,
/// sRGB-encoded (the viewer tonemaps frames with it without copying them into an [`Image`]).
pub fn srgb8(pixels: &[[f32; 3]], exposure_stops: f32) -> Vec<u8> {
    let scale = exposure_stops.exp2();
    pixels
        .iter()
        .flat_map(|p| p.map(|c| (linear_to_srgb((c * scale).clamp(0.0, 1.0)) * 255.0 + 0.5) as u8))
        .collect()
}

impl Image {
    /// A black image.
    pub fn new(width: u32, height: u32) -> Self {
        Self {
            width,
            height,
            pixels: vec![[0.0; 3]; width as usize * height as usize],
        }
    }

    /// The pixel at `(x, y)`.
    pub fn get(&self, x: u32, y: u32) -> [f32; 3] {
        self.pixels[(y * self.width + x) as usize]
    }

    /// Tonemapped 8-bit sRGB bytes (RGB, rows from the top): see [`srgb8`].
    pub fn to_srgb8(&self, exposure_stops: f32) -> Vec<u8> {
        srgb8(&self.pixels, exposure_stops)
    }

    /// Mean of all pixels' channels (a quick brightness figure for summaries and tests).
    pub fn mean(&self) -> f64 {
        let sum: f64 = self
            .pixels
            .iter()
            .map(|p| p.iter().map(|&c| c as f64).sum::<f64>())
            .sum();
        sum / (3.0 * self.pixels.len().max(1) as f64)
    }

    /// Writes the image in the format of `path`'s extension. Refuses to replace an existing
    /// file unless `overwrite`.
    pub fn save(
        &self,
        path: &Path,
        exposure_stops: f32,
        metadata: &Metadata,
        overwrite: bool,
    ) -> Result<(), FilmError> {
        let format = Format::from_path(path).ok_or_else(|| FilmError::UnknownFormat(path.to_owned()))?;
        let result = crate::files::write_atomically(path, overwrite, |tmp| match format {
            Format::Png => self.write_png(tmp, exposure_stops, metadata),
            Format::Exr => self.write_exr(tmp, metadata),
        });
        result.map_err(|e| match e {
            crate::files::WriteError::Exists(p) => FilmError::Exists(p),
            crate::files::WriteError::Failed { path, message } => FilmError::Write { path, message },
        })
    }

    fn write_png(&self, path: &Path, exposure_stops: f32, metadata: &Metadata) -> Result<(), String> {
        let file = std::fs::File::create(path).map_err(|e| e.to_string())?;
        let mut encoder = png::Encoder::new(std::io::BufWriter::new(file), self.width, self.height);
        encoder.set_color(png::ColorType::Rgb);
        encoder.set_depth(png::BitDepth::Eight);
        encoder.set_source_srgb(png::SrgbRenderingIntent::Perceptual);
        for (k, v) in metadata {
            encoder
                .add_itxt_chunk(k.clone(), v.clone())
                .map_err(|e| e.to_string())?;
        }
        let mut writer = encoder.write_header().map_err(|e| e.to_string())?;
        writer
            .write_image_data(&self.to_srgb8(exposure_stops))
            .map_err(|e| e.to_string())?;
        writer.finish().map_err(|e| e.to_string())
    }

    fn write_exr(&self, path: &Path, metadata: &Metadata) -> Result<(), String> {
        use exr::prelude::*;
        let w = self.width as usize;
        let channels = SpecificChannels::rgb(|Vec2(x, y): Vec2<usize>| {
            let p = self.pixels[y * w + x];
            (p[0], p[1], p[2])
        });
        let mut image = Image::from_channels((w, self.height as usize), channels);
        for (k, v) in metadata {
            image.layer_data.attributes.other.insert(
                Text::from(k.as_str()),
                AttributeValue::Text(Text::from(v.as_str())),
            );
        }
        image.write().to_file(path).map_err(|e| e.to_string())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn srgb_curve_endpoints() {
        assert_eq!(linear_to_srgb(0.0), 0.0);
        assert!((linear_to_srgb(1.0) - 1.0).abs() < 1e-6);
        let img = Image {
            width: 1,
            height: 1,
            pixels: vec![[0.5, 2.0, 0.0]],
        };
        assert_eq!(img.to_srgb8(0.0), vec![188, 255, 0]);
        assert_eq!(img.to_srgb8(1.0), vec![255, 255, 0]);
    }
}
