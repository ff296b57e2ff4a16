//! A reference image to compare a render against — the converged render of another program
//! or a long run of this one — read from OpenEXR (through `image`) or PFM (the portable float
//! map of Debevec's HDRShop and pbrt: `PF`/`Pf`, width, height, a scale whose sign gives the
//! byte order, then float rows from the bottom), and the error of a frame against it.

use std::path::{Path, PathBuf};

use super::error::errors;
use super::Image;

/// Why a reference could not be used.
#[derive(Debug, thiserror::Error)]
pub enum ReferenceError {
    /// The file could not be read or decoded.
    #[error("{}: cannot read the reference image: {message}", path.display())]
    Read {
        /// The file.
        path: PathBuf,
        /// What failed.
        message: String,
    },
    /// The reference and the render differ in size.
    #[error("{}: the reference is {}x{} but the render is {}x{}; render at the reference's size (--width/--height) or choose another reference", path.display(), reference.0, reference.1, render.0, render.1)]
    SizeMismatch {
        /// The file.
        path: PathBuf,
        /// The reference's width and height.
        reference: (u32, u32),
        /// The render's width and height.
        render: (u32, u32),
    },
}

/// A reference image and where it came from.
#[derive(Clone, Debug)]
pub struct Reference {
    /// The file it was read from.
    pub path: PathBuf,
    /// Its linear RGB pixels.
    pub image: Image,
}

/// A frame's error against a reference.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct ReferenceErrors {
    /// Root-mean-square error over pixels and channels.
    pub rmse: f64,
    /// pbrt's relative MSE: mean of `(x − r)² / (r² + 0.01)`.
    pub rel_mse: f64,
}

impl Reference {
    /// Reads an `.exr` or `.pfm` file (the extension decides; anything else is an error).
    pub fn open(path: &Path) -> Result<Reference, ReferenceError> {
        let read_error = |message: String| ReferenceError::Read {
            path: path.to_owned(),
            message,
        };
        let extension = path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase);
        let image = match extension.as_deref() {
            Some("pfm") => {
                crate::input_file::regular_file(path).map_err(read_error)?;
                let bytes = std::fs::read(path).map_err(|e| read_error(e.to_string()))?;
                read_pfm(&bytes).map_err(read_error)?
            }
            Some("exr") => {
                crate::input_file::regular_file(path).map_err(read_error)?;
                let decoded = image::open(path).map_err(|e| read_error(e.to_string()))?;
                let rgb = decoded.to_rgb32f();
                Image {
                    width: rgb.width(),
                    height: rgb.height(),
                    pixels: rgb.pixels().map(|p| p.0).collect(),
                }
            }
            _ => return Err(read_error("not an OpenEXR (.exr) or PFM (.pfm) file".into())),
        };
        if let Some(bad) = image.pixels.iter().flatten().find(|c| !c.is_finite()) {
            return Err(read_error(format!(
                "it holds a non-finite value ({bad}); a reference must be finite everywhere"
            )));
        }
        Ok(Reference {
            path: path.to_owned(),
            image,
        })
    }

    /// Checks that a `width × height` render can be compared with this reference.
    pub fn check_size(&self, width: u32, height: u32) -> Result<(), ReferenceError> {
        let reference = (self.image.width, self.image.height);
        if reference == (width, height) {
            return Ok(());
        }
        Err(ReferenceError::SizeMismatch {
            path: self.path.clone(),
            reference,
            render: (width, height),
        })
    }

    /// The error of `pixels` (a render of the reference's size) against the reference; `None`
    /// for another size.
    pub fn errors(&self, pixels: &[[f32; 3]]) -> Option<ReferenceErrors> {
        if pixels.len() != self.image.pixels.len() {
            return None;
        }
        let (rmse, rel_mse) = errors(pixels, &self.image.pixels);
        Some(ReferenceErrors { rmse, rel_mse })
    }
}

/// Decodes a PFM file: colour (`PF`) or greyscale (`Pf`, copied to the three channels).
pub fn read_pfm(bytes: &[u8]) -> Result<Image, String> {
    // Header: four whitespace-separated tokens, then exactly one whitespace byte.
    let mut tokens = Vec::new();
    let mut at = 0;
    while tokens.len() < 4 {
        while at < bytes.len() && bytes[at].is_ascii_whitespace() {
            at += 1;
        }
        let start = at;
        while at < bytes.len() && !bytes[at].is_ascii_whitespace() {
            at += 1;
        }
        if start == at {
            return Err("the PFM header ends early".into());
        }
        tokens.push(String::from_utf8_lossy(&bytes[start..at]).into_owned());
    }
    let data = bytes.get(at + 1..).unwrap_or_default();
    let channels = match tokens[0].as_str() {
        "PF" => 3,
        "Pf" => 1,
        other => return Err(format!("not a PFM file (it starts with {other:?}, not PF or Pf)")),
    };
    let side = |s: &str, what: &str| -> Result<u32, String> {
        match s.parse::<u32>() {
            Ok(v) if crate::settings::limits::IMAGE_SIDE.contains(&v) => Ok(v),
            _ => Err(format!(
                "the PFM {what} {s:?} is not a whole number between 1 and {}",
                crate::settings::limits::IMAGE_SIDE.end()
            )),
        }
    };
    let (width, height) = (side(&tokens[1], "width")?, side(&tokens[2], "height")?);
    let scale: f32 = tokens[3]
        .parse()
        .ok()
        .filter(|s: &f32| s.is_finite() && *s != 0.0)
        .ok_or_else(|| format!("the PFM scale {:?} is not a non-zero number", tokens[3]))?;
    let values = width as usize * height as usize * channels;
    if data.len() < values * 4 {
        return Err(format!(
            "the PFM data is {} bytes; a {width}x{height} image needs {}",
            data.len(),
            values * 4
        ));
    }
    let float = |k: usize| {
        let b = [data[4 * k], data[4 * k + 1], data[4 * k + 2], data[4 * k + 3]];
        if scale < 0.0 {
            f32::from_le_bytes(b)
        } else {
            f32::from_be_bytes(b)
        }
    };
    let (w, h) = (width as usize, height as usize);
    let mut pixels = Vec::with_capacity(w * h);
    for y in 0..h {
        let row = h - 1 - y; // PFM rows run from the bottom
        for x in 0..w {
            let k = (row * w + x) * channels;
            pixels.push(if channels == 3 {
                [float(k), float(k + 1), float(k + 2)]
            } else {
                [float(k); 3]
            });
        }
    }
    Ok(Image {
        width,
        height,
        pixels,
    })
}

/// Encodes a colour PFM, little-endian (for tests and for programs that want one).
pub fn write_pfm(image: &Image) -> Vec<u8> {
    let mut out = format!("PF\n{} {}\n-1.0\n", image.width, image.height).into_bytes();
    let w = image.width as usize;
    for row in image.pixels.chunks(w.max(1)).rev() {
        for p in row {
            for c in p {
                out.extend_from_slice(&c.to_le_bytes());
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn image() -> Image {
        Image {
            width: 3,
            height: 2,
            pixels: (0..6).map(|k| [k as f32, 0.5 * k as f32, -1.0]).collect(),
        }
    }

    #[test]
    fn pfm_round_trips_and_reads_big_endian_and_grey() {
        let img = image();
        assert_eq!(read_pfm(&write_pfm(&img)), Ok(img.clone()));
        // Greyscale, big-endian (positive scale), two pixels, bottom row first.
        let mut grey = b"Pf 2 1\n1.0\n".to_vec();
        for v in [0.25f32, 4.0] {
            grey.extend_from_slice(&v.to_be_bytes());
        }
        let g = read_pfm(&grey).expect("grey");
        assert_eq!(g.pixels, vec![[0.25; 3], [4.0; 3]]);
    }

    #[test]
    fn bad_pfm_files_say_why() {
        assert!(read_pfm(b"P6 2 2 255\n").expect_err("ppm").contains("not a PFM"));
        assert!(read_pfm(b"PF 2 2\n-1.0\n\0\0")
            .expect_err("short")
            .contains("needs 48"));
        assert!(read_pfm(b"PF 0 2\n-1.0\n").expect_err("zero").contains("width"));
        assert!(read_pfm(b"PF 2").expect_err("header").contains("ends early"));
    }

    #[test]
    fn errors_against_itself_an_offset_and_another_size() {
        let dir = tempfile::tempdir().expect("dir");
        let path = dir.path().join("ref.pfm");
        std::fs::write(&path, write_pfm(&image())).expect("write");
        let reference = Reference::open(&path).expect("open");
        assert_eq!(
            reference.errors(&image().pixels),
            Some(ReferenceErrors {
                rmse: 0.0,
                rel_mse: 0.0
            })
        );
        let shifted: Vec<[f32; 3]> = image().pixels.iter().map(|p| p.map(|c| c + 0.25)).collect();
        let e = reference.errors(&shifted).expect("same size");
        assert!((e.rmse - 0.25).abs() < 1e-6, "{e:?}");
        assert_eq!(reference.errors(&shifted[..2]), None);
        let message = reference.check_size(4, 2).expect_err("size").to_string();
        assert!(message.contains("3x2") && message.contains("4x2"), "{message}");
        let missing = Reference::open(&dir.path().join("none.exr")).expect_err("missing");
        assert!(missing.to_string().contains("none.exr"));
    }
}
