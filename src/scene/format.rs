//! The scene file format: TOML read through serde into these description types, which keep
//! each table's span so that validation errors can name the line.
//!
//! ```toml
//! [camera]
//! position = [0, -8, 4]      # scene units
//! look_at = [0, 0, 1]
//! up = [0, 0, 1]             # default [0, 1, 0]
//! fov = 40                   # vertical field of view, degrees
//! aperture = 0.05            # lens radius (0 = pinhole)
//! focal_distance = 8.5       # default: distance to look_at
//! width = 640
//! height = 480
//!
//! [render]
//! renderer = "whitted"       # or "ppm"
//! max_depth = 8
//! seed = 1
//!
//! [materials.floor]
//! type = "diffuse"           # diffuse | phong | mirror | glass
//! color = [0.8, 0.8, 0.8]
//! texture = { file = "checker.png", mapping = "planar", scale = 0.5 }
//!
//! [[lights]]
//! type = "point"             # point | spot | sphere | quad
//! position = [2, -3, 6]
//! power = 800                # watts-like, total flux; or color = [...] with power
//!
//! [[objects]]
//! type = "patches"           # sphere | plane | quad | mesh | patches
//! file = "../assets/teapot.bpt"
//! material = "floor"
//! transform = { rotate = [0, 0, 30], scale = 1.0, translate = [0, 0, 0] }
//! ```
//!
//! The full reference is `scenes/FORMAT.md`.

use std::collections::BTreeMap;

use serde::{Deserialize, Deserializer};
use toml::Spanned;

/// A finite number: NaN and infinities are rejected while parsing, with the line and key.
#[derive(Clone, Copy, Debug, PartialEq, PartialOrd)]
pub struct Real(pub f64);

impl<'de> Deserialize<'de> for Real {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct RealVisitor;
        impl serde::de::Visitor<'_> for RealVisitor {
            type Value = Real;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("a finite number")
            }
            fn visit_f64<E: serde::de::Error>(self, v: f64) -> Result<Real, E> {
                if v.is_finite() {
                    Ok(Real(v))
                } else {
                    Err(E::custom(format!("expected a finite number, found {v}")))
                }
            }
            fn visit_i64<E: serde::de::Error>(self, v: i64) -> Result<Real, E> {
                Ok(Real(v as f64))
            }
            fn visit_u64<E: serde::de::Error>(self, v: u64) -> Result<Real, E> {
                Ok(Real(v as f64))
            }
        }
        d.deserialize_any(RealVisitor)
    }
}

/// Three finite numbers.
pub type Vec3 = [Real; 3];

/// The whole file.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneFile {
    /// `[camera]`.
    pub camera: Spanned<CameraDesc>,
    /// `[render]`: the render parameters themselves (defaults for what it leaves out).
    #[serde(default)]
    pub render: Option<Spanned<crate::settings::RenderParams>>,
    /// Radiance of rays that leave the scene (default black).
    #[serde(default)]
    pub background: Option<Vec3>,
    /// `[materials.NAME]`.
    #[serde(default)]
    pub materials: BTreeMap<String, Spanned<MaterialDesc>>,
    /// `[[lights]]`.
    #[serde(default)]
    pub lights: Vec<Spanned<LightDesc>>,
    /// `[[objects]]`.
    #[serde(default)]
    pub objects: Vec<Spanned<ObjectDesc>>,
}

/// `[camera]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CameraDesc {
    /// Eye position.
    pub position: Vec3,
    /// Point looked at.
    pub look_at: Vec3,
    /// Up direction (default `[0, 1, 0]`).
    pub up: Option<Vec3>,
    /// Vertical field of view in degrees.
    pub fov: Real,
    /// Lens radius; 0 is a pinhole.
    pub aperture: Option<Real>,
    /// Distance of the plane in focus; default the distance to `look_at`.
    pub focal_distance: Option<Real>,
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// Eye rays start on the plane this far along the view axis (a near clip plane).
    pub near: Option<Real>,
}

/// A texture reference inside a material.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TextureDesc {
    /// Image file, relative to the scene file.
    pub file: Option<String>,
    /// A procedural checkerboard instead of a file: `[[r,g,b], [r,g,b]]`.
    pub checker: Option<[Vec3; 2]>,
    /// `"uv"` (the surface's own parameters: patch (u,v), mesh texcoords, …), `"planar"` or
    /// `"spherical"`.
    pub mapping: Option<String>,
    /// Texture repeats per unit of the mapping's coordinates: a number or `[su, sv]`.
    pub scale: Option<ScaleDesc>,
    /// Offset added to the coordinates before lookup.
    pub offset: Option<[Real; 2]>,
    /// Planar mapping: the plane's normal (default `[0, 0, 1]`).
    pub normal: Option<Vec3>,
    /// Spherical mapping: the sphere's centre (default the origin).
    pub center: Option<Vec3>,
}

/// A uniform or per-axis scale.
#[derive(Clone, Copy, Debug, Deserialize)]
#[serde(untagged)]
pub enum ScaleDesc {
    /// The same on every axis.
    Uniform(Real),
    /// Two axes (texture) or three (transform).
    PerAxis2([Real; 2]),
    /// Three axes.
    PerAxis3([Real; 3]),
}

/// `[materials.NAME]`: one flat table; which keys apply depends on `type`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MaterialDesc {
    /// `"diffuse"`, `"phong"`, `"mirror"`, `"metal"` or `"glass"`.
    #[serde(rename = "type")]
    pub kind: String,
    /// Reflectance (diffuse, phong), tint (mirror, glass); components in [0, 1].
    pub color: Option<Vec3>,
    /// Replaces `color` by a texture lookup (diffuse, phong).
    pub texture: Option<TextureDesc>,
    /// Phong specular reflectance in [0, 1].
    pub specular: Option<Real>,
    /// Phong exponent.
    pub shininess: Option<Real>,
    /// Glass index of refraction (at 587.56 nm when it varies).
    pub ior: Option<Real>,
    /// A named glass whose index varies with the wavelength: BK7, F2, SF11, fused silica.
    pub glass: Option<String>,
    /// A glass's Abbe number, with `ior`: its index varies with the wavelength.
    pub abbe: Option<Real>,
    /// GGX roughness α of mirrors and metals, in [0, 1] (0: smooth).
    pub roughness: Option<Real>,
    /// A named metal (`metal`): gold, silver, copper, aluminium.
    pub conductor: Option<String>,
    /// A metal's index of refraction per channel, instead of `conductor`.
    pub eta: Option<Vec3>,
    /// A metal's extinction coefficient per channel, with `eta`.
    pub k: Option<Vec3>,
}

/// `[[lights]]`: one flat table; which keys apply depends on `type`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LightDesc {
    /// `"point"`, `"spot"`, `"sphere"` or `"quad"`.
    #[serde(rename = "type")]
    pub kind: String,
    /// Point and spot lights: where.
    pub position: Option<Vec3>,
    /// Total emitted flux (a number, multiplied by `color`).
    pub power: Option<Real>,
    /// Point lights: radiant intensity per steradian instead of `power`.
    pub intensity: Option<Real>,
    /// Spectral tint, default white.
    pub color: Option<Vec3>,
    /// Spot lights: direction of the cone's axis.
    pub direction: Option<Vec3>,
    /// Spot lights: full cone angle in degrees.
    pub cone_angle: Option<Real>,
    /// Spot lights: width of the soft edge in degrees (default 5).
    pub cone_falloff: Option<Real>,
    /// Sphere lights: centre.
    pub center: Option<Vec3>,
    /// Sphere lights: radius.
    pub radius: Option<Real>,
    /// Quad lights: a corner.
    pub corner: Option<Vec3>,
    /// Quad lights: first edge (emission on the side of `edge_u × edge_v`).
    pub edge_u: Option<Vec3>,
    /// Quad lights: second edge.
    pub edge_v: Option<Vec3>,
}

/// `[[objects]]`: one flat table; which keys apply depends on `type`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ObjectDesc {
    /// `"sphere"`, `"plane"`, `"quad"`, `"mesh"` or `"patches"`.
    #[serde(rename = "type")]
    pub kind: String,
    /// Name of a `[materials.NAME]` table.
    pub material: String,
    /// Optional name (shown in statistics and errors).
    pub name: Option<String>,
    /// Sphere centre.
    pub center: Option<Vec3>,
    /// Sphere radius.
    pub radius: Option<Real>,
    /// Plane: a point on it.
    pub point: Option<Vec3>,
    /// Plane: its normal.
    pub normal: Option<Vec3>,
    /// Quad: a corner.
    pub corner: Option<Vec3>,
    /// Quad: first edge.
    pub edge_u: Option<Vec3>,
    /// Quad: second edge.
    pub edge_v: Option<Vec3>,
    /// Mesh (`.obj`) or patches (`.bpt`, free-form `.obj`, USD `.usda`/`.usdz`/`.usd`; `.usdc` is refused)
    /// file, relative to the scene file.
    pub file: Option<String>,
    /// With a USD `file`: `false` reads only its `Mesh` and `Sphere` prims, not its
    /// `NurbsPatch` surfaces (Save scene writes it when those surfaces were edited and saved
    /// as an OBJ file). Default `true`.
    pub nurbs: Option<bool>,
    /// Patches built into the program instead of a file: `"teapot"`.
    pub builtin: Option<String>,
    /// Patches written inline: each a list of 16 points `[x, y, z]`, row by row.
    pub patches: Option<Vec<Vec<Vec3>>>,
    /// With inline `patches`: each patch's `(u,v)` window `[u0, u1, v0, v1]` in the parameters
    /// of the surface it was cut from (a B-spline span), so textures follow that surface.
    pub domains: Option<Vec<[Real; 4]>>,
    /// With inline `patches`: each patch's 16 control-point weights (positive), for rational
    /// patches; absent, every weight is 1.
    pub weights: Option<Vec<Vec<Real>>>,
    /// With inline `patches`: trimmed surfaces, each the patches its loops cut.
    pub trims: Option<Vec<TrimDesc>>,
    /// Placement (mesh, patches, quad, sphere).
    pub transform: Option<TransformDesc>,
}

/// One trimmed surface among inline patches: which patches it is made of and its loops, in the
/// `(u,v)` of the patches' `domains`.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TrimDesc {
    /// The patches (0-based, among the object's inline `patches`) the loops cut.
    pub patches: Vec<usize>,
    /// The outer loops and holes.
    pub loops: Vec<TrimLoopDesc>,
}

/// One closed trim loop: cubic rational Bézier segments end to end.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TrimLoopDesc {
    /// A hole (its inside is cut away); otherwise an outer loop (its inside is kept).
    #[serde(default)]
    pub hole: bool,
    /// Each segment's four control points `u, v, w` in a row (12 numbers; `w` above 0).
    pub segments: Vec<[Real; 12]>,
}

/// Scale, then rotate (degrees about x, then y, then z), then translate.
#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TransformDesc {
    /// Uniform or per-axis scale.
    pub scale: Option<ScaleDesc>,
    /// Rotation in degrees about x, y, z, applied in that order.
    pub rotate: Option<Vec3>,
    /// Translation.
    pub translate: Option<Vec3>,
}
