//! Textures: an image (sRGB decoded to linear) or a procedural checkerboard, looked up with
//! bilinear filtering and repeat wrapping through one of three mappings (seed report §2.4 and
//! §1.2: patch-(u,v), planar and spherical).

use std::path::{Path, PathBuf};

use glam::{DVec2, DVec3};

/// Where texture coordinates come from.
#[derive(Clone, Debug, PartialEq)]
pub enum Mapping {
    /// The surface's own parameters: a patch's original `(u,v)`, mesh texture coordinates, a
    /// quad's `(a,b)`, a sphere's `(φ/2π, θ/π)`, a plane's in-plane coordinates.
    Uv,
    /// Projection onto the plane with this unit normal (scene units).
    Planar {
        /// First in-plane axis.
        axis_u: DVec3,
        /// Second in-plane axis.
        axis_v: DVec3,
    },
    /// Longitude/latitude around `center` (z up).
    Spherical {
        /// Centre of the sphere of directions.
        center: DVec3,
    },
}

/// What the texture shows.
#[derive(Clone, Debug, PartialEq)]
pub enum TextureSource {
    /// Linear RGB texels, rows from the top.
    Image {
        /// Texels per row.
        width: usize,
        /// Rows.
        height: usize,
        /// `width × height` linear RGB values.
        texels: Vec<DVec3>,
        /// Where it came from.
        path: PathBuf,
    },
    /// Alternating squares of two colours, one per unit of the coordinates.
    Checker([DVec3; 2]),
}

/// A texture with its mapping.
#[derive(Clone, Debug, PartialEq)]
pub struct Texture {
    /// Texels.
    pub source: TextureSource,
    /// Coordinate source.
    pub mapping: Mapping,
    /// Repeats per unit of the mapping's coordinates.
    pub scale: DVec2,
    /// Added to the coordinates after scaling.
    pub offset: DVec2,
}

/// Decoding an image failed.
#[derive(Debug, thiserror::Error)]
#[error("{}: cannot read texture image: {source}", path.display())]
pub struct TextureError {
    /// The file.
    pub path: PathBuf,
    /// The decoder's error.
    pub source: image::ImageError,
}

/// An 8-bit sRGB-encoded channel as linear.
fn srgb_to_linear(c: u8) -> f64 {
    crate::color::srgb_to_linear(c as f64 / 255.0)
}

impl TextureSource {
    /// Reads an 8-bit image file (PNG or JPEG), decoding sRGB to linear.
    pub fn load(path: &Path) -> Result<Self, TextureError> {
        let img = image::open(path).map_err(|source| TextureError {
            path: path.to_owned(),
            source,
        })?;
        Ok(Self::from_image(img, path))
    }

    /// Decodes an image file's bytes (PNG or JPEG, by their content); `path` names it in
    /// errors and in the texture.
    pub fn decode(bytes: &[u8], path: &Path) -> Result<Self, TextureError> {
        let img = image::load_from_memory(bytes).map_err(|source| TextureError {
            path: path.to_owned(),
            source,
        })?;
        Ok(Self::from_image(img, path))
    }

    fn from_image(img: image::DynamicImage, path: &Path) -> Self {
        let rgb = img.to_rgb8();
        let (width, height) = (rgb.width() as usize, rgb.height() as usize);
        let lut: Vec<f64> = (0..=255u8).map(srgb_to_linear).collect();
        let texels = rgb
            .pixels()
            .map(|p| DVec3::new(lut[p[0] as usize], lut[p[1] as usize], lut[p[2] as usize]))
            .collect();
        TextureSource::Image {
            width,
            height,
            texels,
            path: path.to_owned(),
        }
    }
}

impl Texture {
    /// Texture coordinates for a surface point.
    pub fn coordinates(&self, point: DVec3, surface_uv: DVec2) -> DVec2 {
        let st = match &self.mapping {
            Mapping::Uv => surface_uv,
            Mapping::Planar { axis_u, axis_v } => DVec2::new(point.dot(*axis_u), point.dot(*axis_v)),
            Mapping::Spherical { center } => {
                let d = (point - *center).normalize_or_zero();
                let u = d.y.atan2(d.x) / std::f64::consts::TAU + 0.5;
                let v = 1.0 - d.z.clamp(-1.0, 1.0).acos() / std::f64::consts::PI;
                DVec2::new(u, v)
            }
        };
        st * self.scale + self.offset
    }

    /// The linear colour at a surface point.
    pub fn lookup(&self, point: DVec3, surface_uv: DVec2) -> DVec3 {
        let st = self.coordinates(point, surface_uv);
        self.sample(st)
    }

    /// The colour at texture coordinates `st` (repeating; `v` up, so `v = 0` is the image's
    /// bottom row), bilinearly filtered.
    pub fn sample(&self, st: DVec2) -> DVec3 {
        match &self.source {
            TextureSource::Checker(colors) => {
                let parity = (st.x.floor() as i64 + st.y.floor() as i64).rem_euclid(2);
                colors[parity as usize]
            }
            TextureSource::Image {
                width,
                height,
                texels,
                ..
            } => {
                let (w, h) = (*width as i64, *height as i64);
                let x = st.x.rem_euclid(1.0) * w as f64 - 0.5;
                let y = (1.0 - st.y.rem_euclid(1.0)) * h as f64 - 0.5;
                let (x0, y0) = (x.floor(), y.floor());
                let (fx, fy) = (x - x0, y - y0);
                let texel = |i: i64, j: i64| texels[(j.rem_euclid(h) * w + i.rem_euclid(w)) as usize];
                let (i, j) = (x0 as i64, y0 as i64);
                let top = texel(i, j) * (1.0 - fx) + texel(i + 1, j) * fx;
                let bottom = texel(i, j + 1) * (1.0 - fx) + texel(i + 1, j + 1) * fx;
                top * (1.0 - fy) + bottom * fy
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn two_by_one() -> Texture {
        Texture {
            source: TextureSource::Image {
                width: 2,
                height: 1,
                texels: vec![DVec3::ZERO, DVec3::ONE],
                path: PathBuf::new(),
            },
            mapping: Mapping::Uv,
            scale: DVec2::ONE,
            offset: DVec2::ZERO,
        }
    }

    #[test]
    fn bilinear_between_texel_centres() {
        let t = two_by_one();
        assert_eq!(t.sample(DVec2::new(0.25, 0.5)), DVec3::ZERO);
        assert_eq!(t.sample(DVec2::new(0.75, 0.5)), DVec3::ONE);
        assert!((t.sample(DVec2::new(0.5, 0.5)) - DVec3::splat(0.5)).length() < 1e-12);
        // Repeat wrapping: halfway between the last and the first texel.
        assert!((t.sample(DVec2::new(1.0, 0.5)) - DVec3::splat(0.5)).length() < 1e-12);
    }

    #[test]
    fn srgb_endpoints() {
        assert_eq!(srgb_to_linear(0), 0.0);
        assert!((srgb_to_linear(255) - 1.0).abs() < 1e-12);
        assert!((srgb_to_linear(188) - 0.5029).abs() < 1e-3);
    }
}
