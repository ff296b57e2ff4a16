//! The film: a linear RGB image, its tonemapping (exposure in stops, then the sRGB transfer
//! curve), and writers for PNG (8-bit sRGB, text chunks) and OpenEXR (linear 32-bit float,
//! custom string attributes) carrying the render's metadata. Files are written to a temporary
//! name beside the target and renamed, so a failed write never leaves half a file.

use crate::color::linear_to_srgb;
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

/// A single-channel per-pixel layer written into EXR files beside RGB (as channel
/// `<name>.Y`, the convention tev and OpenEXR viewers group by); PNG files leave it out.
#[derive(Clone, Copy, Debug)]
pub struct Layer<'a> {
    /// The layer's name (`radius`, `photons`, `error`).
    pub name: &'a str,
    /// `width × height` values, rows from the top.
    pub values: &'a [f32],
}

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
        self.save_with_layers(path, exposure_stops, metadata, &[], overwrite)
    }

    /// [`Image::save`], with extra per-pixel `layers` in an EXR file (each must hold one
    /// value per pixel; a PNG file has no room for them and leaves them out).
    pub fn save_with_layers(
        &self,
        path: &Path,
        exposure_stops: f32,
        metadata: &Metadata,
        layers: &[Layer],
        overwrite: bool,
    ) -> Result<(), FilmError> {
        let format = Format::from_path(path).ok_or_else(|| FilmError::UnknownFormat(path.to_owned()))?;
        let result = crate::files::write_atomically(path, overwrite, |tmp| match format {
            Format::Png => self.write_png(tmp, exposure_stops, metadata),
            Format::Exr => self.write_exr(tmp, metadata, layers),
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

    fn write_exr(&self, path: &Path, metadata: &Metadata, layers: &[Layer]) -> Result<(), String> {
        use exr::prelude::*;
        let n = self.pixels.len();
        let channel = |k: usize| FlatSamples::F32(self.pixels.iter().map(|p| p[k]).collect());
        let mut list: SmallVec<[AnyChannel<FlatSamples>; 4]> = ["R", "G", "B"]
            .iter()
            .enumerate()
            .map(|(k, name)| AnyChannel::new(*name, channel(k)))
            .collect();
        for layer in layers {
            if layer.values.len() != n {
                return Err(format!(
                    "layer {} has {} values for {n} pixels",
                    layer.name,
                    layer.values.len()
                ));
            }
            let name = format!("{}.Y", layer.name);
            list.push(AnyChannel::new(
                name.as_str(),
                FlatSamples::F32(layer.values.to_vec()),
            ));
        }
        let size = (self.width as usize, self.height as usize);
        let mut image = Image::from_channels(size, AnyChannels::sort(list));
        // OpenEXR strings are bytes; these are UTF-8 (`exr`'s checked constructor takes
        // Latin-1 only and panics on anything else, such as the "é" of a scene comment).
        for (k, v) in metadata {
            image.layer_data.attributes.other.insert(
                Text::from_slice_unchecked(k.as_bytes()),
                AttributeValue::Text(Text::from_slice_unchecked(v.as_bytes())),
            );
        }
        image.write().to_file(path).map_err(|e| e.to_string())
    }
}

/// The text metadata of an image this program wrote: EXR string attributes or PNG text
/// chunks, in file order.
pub fn read_metadata(path: &Path) -> Result<Metadata, String> {
    crate::input_file::regular_file(path).map_err(|why| format!("the file {why}"))?;
    match Format::from_path(path) {
        Some(Format::Exr) => {
            let meta = exr::meta::MetaData::read_from_file(path, false).map_err(|e| e.to_string())?;
            let header = meta.headers.first().ok_or("the file has no image")?;
            let mut pairs = exr_text_attributes(header.own_attributes.other.iter());
            pairs.sort();
            Ok(pairs)
        }
        Some(Format::Png) => {
            let file = std::fs::File::open(path).map_err(|e| e.to_string())?;
            let reader = png::Decoder::new(std::io::BufReader::new(file))
                .read_info()
                .map_err(|e| e.to_string())?;
            let info = reader.info();
            let mut pairs: Metadata = info
                .utf8_text
                .iter()
                .filter_map(|t| Some((t.keyword.clone(), t.get_text().ok()?)))
                .collect();
            pairs.extend(
                info.uncompressed_latin1_text
                    .iter()
                    .map(|t| (t.keyword.clone(), t.text.clone())),
            );
            Ok(pairs)
        }
        None => Err("not a .png or .exr file".into()),
    }
}

/// The string attributes among an EXR header's `attributes`, as UTF-8 pairs (in their order).
pub fn exr_text_attributes<'a>(
    attributes: impl Iterator<
        Item = (
            &'a exr::meta::attribute::Text,
            &'a exr::meta::attribute::AttributeValue,
        ),
    >,
) -> Metadata {
    attributes
        .filter_map(|(k, v)| match v {
            exr::meta::attribute::AttributeValue::Text(t) => Some((
                String::from_utf8_lossy(k.bytes()).into_owned(),
                String::from_utf8_lossy(t.bytes()).into_owned(),
            )),
            _ => None,
        })
        .collect()
}

/// The names of the channels of an EXR file (sorted, as OpenEXR stores them).
pub fn exr_channel_names(path: &Path) -> Result<Vec<String>, String> {
    let meta = exr::meta::MetaData::read_from_file(path, false).map_err(|e| e.to_string())?;
    let header = meta.headers.first().ok_or("the file has no image")?;
    Ok(header.channels.list.iter().map(|c| c.name.to_string()).collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn srgb_curve_endpoints() {
        let img = Image {
            width: 1,
            height: 1,
            pixels: vec![[0.5, 2.0, 0.0]],
        };
        assert_eq!(img.to_srgb8(0.0), vec![188, 255, 0]);
        assert_eq!(img.to_srgb8(1.0), vec![255, 255, 0]);
    }

    #[test]
    fn exr_layers_and_metadata_read_back() {
        let dir = tempfile::tempdir().expect("dir");
        let img = Image {
            width: 2,
            height: 1,
            pixels: vec![[1.0, 2.0, 3.0], [0.5, 0.25, 0.0]],
        };
        let meta: Metadata = vec![
            ("caustic:scene_text".into(), "# Bézier ∂ patches".into()),
            ("caustic:seed".into(), "7".into()),
        ];
        let radius = [0.1f32, 0.2];
        let layers = [Layer {
            name: "radius",
            values: &radius,
        }];
        let exr = dir.path().join("a.exr");
        img.save_with_layers(&exr, 0.0, &meta, &layers, false)
            .expect("exr");
        assert_eq!(
            exr_channel_names(&exr).expect("channels"),
            ["B", "G", "R", "radius.Y"]
        );
        assert_eq!(read_metadata(&exr).expect("meta"), meta);
        let rgb = image::open(&exr).expect("decode").to_rgb32f();
        assert_eq!(rgb.get_pixel(0, 0).0, [1.0, 2.0, 3.0]);
        let png = dir.path().join("a.png");
        img.save_with_layers(&png, 0.0, &meta, &layers, false)
            .expect("png");
        assert_eq!(read_metadata(&png).expect("meta"), meta);
        let short = [Layer {
            name: "radius",
            values: &radius[..1],
        }];
        let message = img
            .save_with_layers(&dir.path().join("b.exr"), 0.0, &meta, &short, false)
            .expect_err("short layer")
            .to_string();
        assert!(message.contains("radius"), "{message}");
    }
}
