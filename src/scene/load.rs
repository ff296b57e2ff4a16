//! Reading and validating scene files. Every error names the file, the line of the table it
//! concerns, the table (`objects[2] (sphere)`) and the field, and says what was expected.

use std::collections::BTreeMap;
use std::ops::Range;
use std::path::{Path, PathBuf};

use glam::{DAffine3, DMat3, DVec2, DVec3};
use toml::Spanned;

use super::camera::Camera;
use super::format::{
    CameraDesc, LightDesc, MaterialDesc, ObjectDesc, Real, ScaleDesc, SceneFile, TextureDesc, TransformDesc,
    Vec3,
};
use super::light::Light;
use super::material::{Material, MaterialKind};
use super::texture::{Mapping, Texture, TextureSource};
use super::{RenderParams, Scene, SceneObject};
use crate::geometry::{
    load_bpt, load_freeform_obj, BezierPatch, GeometryBuilder, Plane, Quad, Sphere, TriangleMesh, Window,
};
use crate::settings::limits;

/// A scene file that cannot be used: where, and why.
#[derive(Debug, thiserror::Error)]
#[error("{}:{line}: {message}", path.display())]
pub struct SceneError {
    /// The scene file.
    pub path: PathBuf,
    /// 1-based line (0 when the file could not be read).
    pub line: usize,
    /// What is wrong, naming the table and field.
    pub message: String,
}

pub(super) fn load_file(path: &Path) -> Result<Scene> {
    let text = std::fs::read_to_string(path).map_err(|e| SceneError {
        path: path.to_owned(),
        line: 0,
        message: format!("cannot read the scene file: {e}"),
    })?;
    let base = path.parent().map(Path::to_owned).unwrap_or_default();
    load_str(&text, path, Some(&base))
}

/// Where the errors point.
struct Ctx<'a> {
    path: &'a Path,
    text: &'a str,
    base_dir: Option<&'a Path>,
}

type Result<T> = std::result::Result<T, SceneError>;

impl Ctx<'_> {
    fn line(&self, span: &Range<usize>) -> usize {
        self.text[..span.start.min(self.text.len())].matches('\n').count() + 1
    }

    fn err(&self, span: &Range<usize>, message: impl Into<String>) -> SceneError {
        SceneError {
            path: self.path.to_owned(),
            line: self.line(span),
            message: message.into(),
        }
    }

    /// A file named in the scene, resolved against the scene's folder and checked to exist.
    fn resolve(&self, span: &Range<usize>, what: &str, file: &str) -> Result<PathBuf> {
        let Some(base) = self.base_dir else {
            return Err(self.err(
                span,
                format!("{what}: '{file}': a built-in scene cannot refer to files"),
            ));
        };
        let path = base.join(file);
        if !path.is_file() {
            return Err(self.err(span, format!("{what}: file '{}' does not exist", path.display())));
        }
        Ok(path)
    }
}

fn v3(v: &Vec3) -> DVec3 {
    DVec3::new(v[0].0, v[1].0, v[2].0)
}

/// Checks of one table: its name for messages and its span for the line.
struct Table<'a, 'c> {
    ctx: &'a Ctx<'c>,
    span: Range<usize>,
    name: String,
}

impl Table<'_, '_> {
    fn err(&self, message: impl std::fmt::Display) -> SceneError {
        self.ctx.err(&self.span, format!("{}: {message}", self.name))
    }

    fn required<T: Copy>(&self, field: &str, value: Option<T>) -> Result<T> {
        value.ok_or_else(|| self.err(format!("missing '{field}'")))
    }

    fn positive(&self, field: &str, v: f64) -> Result<f64> {
        if v > 0.0 {
            Ok(v)
        } else {
            Err(self.err(format!("'{field}' must be positive, got {v}")))
        }
    }

    fn non_negative(&self, field: &str, v: f64) -> Result<f64> {
        if v >= 0.0 {
            Ok(v)
        } else {
            Err(self.err(format!("'{field}' must not be negative, got {v}")))
        }
    }

    fn nonzero(&self, field: &str, v: DVec3) -> Result<DVec3> {
        if v.length_squared() > 0.0 {
            Ok(v)
        } else {
            Err(self.err(format!("'{field}' must not be the zero vector")))
        }
    }

    fn reflectance(&self, field: &str, v: DVec3) -> Result<DVec3> {
        if v.cmpge(DVec3::ZERO).all() && v.cmple(DVec3::ONE).all() {
            Ok(v)
        } else {
            Err(self.err(format!("'{field}' components must be between 0 and 1, got {v}")))
        }
    }

    /// Rejects keys given that this table's `type` does not use.
    fn only(&self, kind: &str, given: &[(&str, bool)], allowed: &[&str]) -> Result<()> {
        for (key, present) in given {
            if *present && !allowed.contains(key) {
                return Err(self.err(format!(
                    "'{key}' does not apply to type '{kind}' (it takes: {})",
                    allowed.join(", ")
                )));
            }
        }
        Ok(())
    }
}

pub(super) fn load_str(text: &str, path: &Path, base_dir: Option<&Path>) -> Result<Scene> {
    let ctx = Ctx { path, text, base_dir };
    let file: SceneFile = toml::from_str(text).map_err(|e| {
        let span = e.span().unwrap_or(0..0);
        ctx.err(&span, e.message().trim().to_owned())
    })?;

    let camera = camera(&ctx, &file.camera)?;
    let params = match &file.render {
        Some(r) => render_params(&ctx, r)?,
        None => RenderParams::default(),
    };
    let background = file.background.as_ref().map(v3).unwrap_or(DVec3::ZERO);
    if background.cmplt(DVec3::ZERO).any() {
        return Err(ctx.err(
            &(0..0),
            format!("'background' must not be negative, got {background}"),
        ));
    }

    let mut materials = Vec::new();
    let mut textures = Vec::new();
    let mut material_index = BTreeMap::new();
    for (name, desc) in &file.materials {
        let m = material(&ctx, name, desc, &mut textures)?;
        material_index.insert(name.clone(), materials.len());
        materials.push(m);
    }

    let mut builder = GeometryBuilder::default();
    let mut objects = Vec::new();
    for (k, desc) in file.objects.iter().enumerate() {
        object(&ctx, k, desc, &material_index, &mut builder, &mut objects)?;
    }

    let mut lights = Vec::new();
    let mut light_objects = Vec::new();
    let mut emitter_material: Option<usize> = None;
    for (k, desc) in file.lights.iter().enumerate() {
        let light = light(&ctx, k, desc)?;
        // Area lights are visible: their surface joins the geometry as an emitter.
        let id = objects.len() as u32;
        let emission = match &light {
            Light::Sphere {
                center,
                radius,
                radiance,
            } => {
                builder.add_sphere(
                    Sphere {
                        center: *center,
                        radius: *radius,
                    },
                    id,
                );
                Some(*radiance)
            }
            Light::Quad {
                corner,
                edge_u,
                edge_v,
                radiance,
            } => {
                builder.add_quad(
                    Quad {
                        corner: *corner,
                        edge_u: *edge_u,
                        edge_v: *edge_v,
                    },
                    id,
                );
                Some(*radiance)
            }
            Light::Point { .. } | Light::Spot { .. } => None,
        };
        light_objects.push(emission.map(|_| id));
        if let Some(radiance) = emission {
            // Emitters reflect nothing: one shared black material serves them all.
            let material = *emitter_material.get_or_insert_with(|| {
                materials.push(Material {
                    name: "area light".to_owned(),
                    kind: MaterialKind::Diffuse {
                        specular: 0.0,
                        shininess: 0.0,
                    },
                    color: DVec3::ZERO,
                    texture: None,
                });
                materials.len() - 1
            });
            objects.push(SceneObject {
                name: format!("lights[{k}]"),
                material,
                emission: Some(radiance),
            });
        }
        lights.push(light);
    }
    if lights.is_empty() {
        return Err(ctx.err(&(0..0), "the scene has no [[lights]]: nothing would be visible"));
    }
    if objects.is_empty() {
        return Err(ctx.err(&(0..0), "the scene has no [[objects]]"));
    }

    Ok(Scene {
        source: path.to_owned(),
        camera,
        params,
        background,
        materials,
        textures,
        objects,
        lights,
        light_objects,
        geometry: builder.build(),
        text: text.into(),
        base_dir: base_dir.map(Path::to_path_buf),
    })
}

fn camera(ctx: &Ctx, desc: &Spanned<CameraDesc>) -> Result<Camera> {
    let t = Table {
        ctx,
        span: desc.span(),
        name: "[camera]".into(),
    };
    let d = desc.get_ref();
    let position = v3(&d.position);
    let look_at = v3(&d.look_at);
    let up = d.up.as_ref().map(v3).unwrap_or(DVec3::Y);
    let view = look_at - position;
    if view.length_squared() == 0.0 {
        return Err(t.err("'look_at' equals 'position': no view direction"));
    }
    if view.normalize().cross(up.normalize_or_zero()).length() < 1e-9 {
        return Err(t.err("'up' is parallel to the view direction (or zero)"));
    }
    let fov = d.fov.0;
    if !(fov > 0.0 && fov < 180.0) {
        return Err(t.err(format!("'fov' must be between 0 and 180 degrees, got {fov}")));
    }
    for (field, v) in [("width", d.width), ("height", d.height)] {
        limits::image_side(v).map_err(|e| t.err(format!("'{field}' {e}")))?;
    }
    let aperture = t.non_negative("aperture", d.aperture.map_or(0.0, |r| r.0))?;
    let focal_distance = d
        .focal_distance
        .map(|r| t.positive("focal_distance", r.0))
        .transpose()?;
    let mut camera = Camera::look_at(
        position,
        look_at,
        up,
        fov,
        d.width,
        d.height,
        aperture,
        focal_distance,
    );
    camera.near = t.non_negative("near", d.near.map_or(0.0, |r| r.0))?;
    Ok(camera)
}

/// The `[render]` table (read straight into [`RenderParams`]), checked by its one `validate`.
fn render_params(ctx: &Ctx, desc: &Spanned<RenderParams>) -> Result<RenderParams> {
    let t = Table {
        ctx,
        span: desc.span(),
        name: "[render]".into(),
    };
    let params = desc.get_ref().clone();
    params.validate().map_err(|e| t.err(e))?;
    Ok(params)
}

fn material(
    ctx: &Ctx,
    name: &str,
    desc: &Spanned<MaterialDesc>,
    textures: &mut Vec<Texture>,
) -> Result<Material> {
    let d = desc.get_ref();
    let t = Table {
        ctx,
        span: desc.span(),
        name: format!("[materials.{name}] ({})", d.kind),
    };
    let given = [
        ("color", d.color.is_some()),
        ("texture", d.texture.is_some()),
        ("specular", d.specular.is_some()),
        ("shininess", d.shininess.is_some()),
        ("ior", d.ior.is_some()),
    ];
    let color = d
        .color
        .as_ref()
        .map(v3)
        .map(|c| t.reflectance("color", c))
        .transpose()?;
    let kind = match d.kind.as_str() {
        "diffuse" => {
            t.only("diffuse", &given, &["color", "texture"])?;
            MaterialKind::Diffuse {
                specular: 0.0,
                shininess: 0.0,
            }
        }
        "phong" => {
            t.only("phong", &given, &["color", "texture", "specular", "shininess"])?;
            let specular = d.specular.map_or(0.2, |r| r.0);
            if !(0.0..=1.0).contains(&specular) {
                return Err(t.err(format!("'specular' must be between 0 and 1, got {specular}")));
            }
            MaterialKind::Diffuse {
                specular,
                shininess: t.non_negative("shininess", d.shininess.map_or(32.0, |r| r.0))?,
            }
        }
        "mirror" => {
            t.only("mirror", &given, &["color"])?;
            MaterialKind::Mirror
        }
        "glass" => {
            t.only("glass", &given, &["color", "ior"])?;
            MaterialKind::Glass {
                ior: t.positive("ior", d.ior.map_or(1.5, |r| r.0))?,
            }
        }
        other => {
            return Err(t.err(format!(
                "unknown material type '{other}' (expected diffuse, phong, mirror or glass)"
            )))
        }
    };
    let texture = match &d.texture {
        Some(desc) => {
            textures.push(texture(&t, desc)?);
            Some(textures.len() - 1)
        }
        None => None,
    };
    Ok(Material {
        name: name.to_owned(),
        kind,
        color: color.unwrap_or(DVec3::splat(0.75)),
        texture,
    })
}

fn texture(t: &Table, d: &TextureDesc) -> Result<Texture> {
    let source = match (&d.file, &d.checker) {
        (Some(file), None) => {
            let path = t
                .ctx
                .resolve(&t.span, &format!("{}: 'texture.file'", t.name), file)?;
            TextureSource::load(&path).map_err(|e| t.err(format!("'texture.file': {e}")))?
        }
        (None, Some([a, b])) => TextureSource::Checker([
            t.reflectance("texture.checker", v3(a))?,
            t.reflectance("texture.checker", v3(b))?,
        ]),
        _ => return Err(t.err("'texture' needs exactly one of 'file' or 'checker'")),
    };
    let mapping = match d.mapping.as_deref() {
        None | Some("uv") => Mapping::Uv,
        Some("planar") => {
            let n = t
                .nonzero("texture.normal", d.normal.as_ref().map(v3).unwrap_or(DVec3::Z))?
                .normalize();
            let (axis_u, axis_v) = n.any_orthonormal_pair();
            Mapping::Planar { axis_u, axis_v }
        }
        Some("spherical") => Mapping::Spherical {
            center: d.center.as_ref().map(v3).unwrap_or(DVec3::ZERO),
        },
        Some(other) => {
            return Err(t.err(format!(
                "'texture.mapping' must be \"uv\", \"planar\" or \"spherical\", got \"{other}\""
            )))
        }
    };
    let scale = match d.scale {
        None => DVec2::ONE,
        Some(ScaleDesc::Uniform(s)) => DVec2::splat(s.0),
        Some(ScaleDesc::PerAxis2([a, b])) => DVec2::new(a.0, b.0),
        Some(ScaleDesc::PerAxis3(_)) => return Err(t.err("'texture.scale' takes one or two numbers")),
    };
    if scale.x == 0.0 || scale.y == 0.0 {
        return Err(t.err("'texture.scale' must not be zero"));
    }
    Ok(Texture {
        source,
        mapping,
        scale,
        offset: d.offset.map_or(DVec2::ZERO, |[a, b]| DVec2::new(a.0, b.0)),
    })
}

fn transform(t: &Table, d: Option<&TransformDesc>) -> Result<(DAffine3, Option<f64>)> {
    let Some(d) = d else {
        return Ok((DAffine3::IDENTITY, Some(1.0)));
    };
    let scale = match d.scale {
        None => DVec3::ONE,
        Some(ScaleDesc::Uniform(s)) => DVec3::splat(s.0),
        Some(ScaleDesc::PerAxis3(s)) => v3(&s),
        Some(ScaleDesc::PerAxis2(_)) => return Err(t.err("'transform.scale' takes one or three numbers")),
    };
    if scale.cmpeq(DVec3::ZERO).any() {
        return Err(t.err(format!(
            "'transform.scale' must not be zero on any axis, got {scale}"
        )));
    }
    let r = d.rotate.as_ref().map(v3).unwrap_or(DVec3::ZERO);
    let rotation = DMat3::from_rotation_z(r.z.to_radians())
        * DMat3::from_rotation_y(r.y.to_radians())
        * DMat3::from_rotation_x(r.x.to_radians());
    let translate = d.translate.as_ref().map(v3).unwrap_or(DVec3::ZERO);
    let m = DAffine3::from_mat3_translation(rotation * DMat3::from_diagonal(scale), translate);
    let uniform = (scale.x.abs() == scale.y.abs() && scale.y.abs() == scale.z.abs()).then_some(scale.x.abs());
    Ok((m, uniform))
}

fn object(
    ctx: &Ctx,
    k: usize,
    desc: &Spanned<ObjectDesc>,
    materials: &BTreeMap<String, usize>,
    builder: &mut GeometryBuilder,
    objects: &mut Vec<SceneObject>,
) -> Result<()> {
    let d = desc.get_ref();
    let label = match &d.name {
        Some(n) => format!("objects[{k}] ({} \"{n}\")", d.kind),
        None => format!("objects[{k}] ({})", d.kind),
    };
    let t = Table {
        ctx,
        span: desc.span(),
        name: label.clone(),
    };
    let material = *materials.get(&d.material).ok_or_else(|| {
        let known: Vec<&str> = materials.keys().map(String::as_str).collect();
        t.err(format!(
            "unknown material '{}' (defined: {})",
            d.material,
            if known.is_empty() {
                "none".to_owned()
            } else {
                known.join(", ")
            }
        ))
    })?;
    let given = [
        ("center", d.center.is_some()),
        ("radius", d.radius.is_some()),
        ("point", d.point.is_some()),
        ("normal", d.normal.is_some()),
        ("corner", d.corner.is_some()),
        ("edge_u", d.edge_u.is_some()),
        ("edge_v", d.edge_v.is_some()),
        ("file", d.file.is_some()),
        ("builtin", d.builtin.is_some()),
        ("patches", d.patches.is_some()),
        ("domains", d.domains.is_some()),
        ("transform", d.transform.is_some()),
    ];
    let id = objects.len() as u32;
    let (m, uniform_scale) = transform(&t, d.transform.as_ref())?;
    match d.kind.as_str() {
        "sphere" => {
            t.only("sphere", &given, &["center", "radius", "transform"])?;
            let center = v3(t.required("center", d.center.as_ref())?);
            let radius = t.positive("radius", t.required("radius", d.radius)?.0)?;
            let Some(s) = uniform_scale else {
                return Err(t.err("a sphere's 'transform.scale' must be uniform"));
            };
            builder.add_sphere(
                Sphere {
                    center: m.transform_point3(center),
                    radius: radius * s,
                },
                id,
            );
        }
        "plane" => {
            t.only("plane", &given, &["point", "normal"])?;
            let point = v3(t.required("point", d.point.as_ref())?);
            let normal = t.nonzero("normal", v3(t.required("normal", d.normal.as_ref())?))?;
            builder.add_plane(
                Plane {
                    point,
                    normal: normal.normalize(),
                },
                id,
            );
        }
        "quad" => {
            t.only("quad", &given, &["corner", "edge_u", "edge_v", "transform"])?;
            let corner = v3(t.required("corner", d.corner.as_ref())?);
            let edge_u = v3(t.required("edge_u", d.edge_u.as_ref())?);
            let edge_v = v3(t.required("edge_v", d.edge_v.as_ref())?);
            if edge_u.cross(edge_v).length_squared() == 0.0 {
                return Err(t.err("'edge_u' and 'edge_v' are parallel (or zero): the quad has no area"));
            }
            builder.add_quad(
                Quad {
                    corner: m.transform_point3(corner),
                    edge_u: m.transform_vector3(edge_u),
                    edge_v: m.transform_vector3(edge_v),
                },
                id,
            );
        }
        "mesh" => {
            t.only("mesh", &given, &["file", "transform"])?;
            let file = t.required("file", d.file.as_deref())?;
            let path = ctx.resolve(&t.span, &format!("{label}: 'file'"), file)?;
            let mut mesh = TriangleMesh::load_obj(&path).map_err(|e| t.err(e))?;
            let normal_matrix = m.matrix3.inverse().transpose();
            for p in &mut mesh.positions {
                *p = m.transform_point3(*p);
            }
            for n in &mut mesh.normals {
                *n = (normal_matrix * *n).normalize_or_zero();
            }
            builder.add_mesh(mesh, id);
        }
        "patches" => {
            t.only(
                "patches",
                &given,
                &["file", "builtin", "patches", "domains", "transform"],
            )?;
            let whole = |patches: Vec<BezierPatch>| patches.into_iter().map(|p| (p, Window::FULL)).collect();
            let patches: Vec<(BezierPatch, Window)> =
                match (d.file.as_deref(), d.builtin.as_deref(), &d.patches) {
                    (Some(file), None, None) => {
                        let path = ctx.resolve(&t.span, &format!("{label}: 'file'"), file)?;
                        let obj = path.extension().is_some_and(|e| e.eq_ignore_ascii_case("obj"));
                        if obj {
                            load_freeform_obj(&path).map_err(|e| t.err(e))?
                        } else {
                            whole(load_bpt(&path).map_err(|e| t.err(e))?)
                        }
                    }
                    (None, Some("teapot"), None) => whole(crate::assets::teapot()),
                    (None, Some(other), None) => {
                        return Err(t.err(format!("unknown 'builtin' patches '{other}' (available: teapot)")))
                    }
                    (None, None, Some(list)) => {
                        let mut out = Vec::new();
                        for (i, points) in list.iter().enumerate() {
                            if points.len() != 16 {
                                return Err(t.err(format!(
                                    "'patches[{i}]' must have 16 control points, has {}",
                                    points.len()
                                )));
                            }
                            out.push((
                                BezierPatch::new(std::array::from_fn(|j| v3(&points[j]))),
                                Window::FULL,
                            ));
                        }
                        if out.is_empty() {
                            return Err(t.err("'patches' is empty"));
                        }
                        if let Some(domains) = &d.domains {
                            patch_domains(&t, &mut out, domains)?;
                        }
                        out
                    }
                    _ => return Err(t.err("needs exactly one of 'file', 'builtin' or 'patches'")),
                };
            if d.domains.is_some() && d.patches.is_none() {
                return Err(t.err("'domains' applies only to inline 'patches'"));
            }
            for (p, domain) in patches {
                builder.add_patch_in(p.transformed(&m), domain, id);
            }
        }
        other => {
            return Err(t.err(format!(
                "unknown object type '{other}' (expected sphere, plane, quad, mesh or patches)"
            )))
        }
    }
    objects.push(SceneObject {
        name: d.name.clone().unwrap_or_else(|| format!("{} {k}", d.kind)),
        material,
        emission: None,
    });
    Ok(())
}

/// Applies inline `domains` (one `[u0, u1, v0, v1]` per patch, each range increasing).
fn patch_domains(t: &Table, patches: &mut [(BezierPatch, Window)], domains: &[[Real; 4]]) -> Result<()> {
    if domains.len() != patches.len() {
        return Err(t.err(format!(
            "'domains' has {} entries for {} patches",
            domains.len(),
            patches.len()
        )));
    }
    for (i, ((_, window), d)) in patches.iter_mut().zip(domains).enumerate() {
        let [u0, u1, v0, v1] = d.map(|r| r.0);
        if !(u0 < u1 && v0 < v1) {
            return Err(t.err(format!(
                "'domains[{i}]' must be [u0, u1, v0, v1] with u0 < u1 and v0 < v1, got [{u0}, {u1}, {v0}, {v1}]"
            )));
        }
        *window = Window { u0, u1, v0, v1 };
    }
    Ok(())
}

fn light(ctx: &Ctx, k: usize, desc: &Spanned<LightDesc>) -> Result<Light> {
    use std::f64::consts::PI;
    let d = desc.get_ref();
    let t = Table {
        ctx,
        span: desc.span(),
        name: format!("lights[{k}] ({})", d.kind),
    };
    let given = [
        ("position", d.position.is_some()),
        ("power", d.power.is_some()),
        ("intensity", d.intensity.is_some()),
        ("color", d.color.is_some()),
        ("direction", d.direction.is_some()),
        ("cone_angle", d.cone_angle.is_some()),
        ("cone_falloff", d.cone_falloff.is_some()),
        ("center", d.center.is_some()),
        ("radius", d.radius.is_some()),
        ("corner", d.corner.is_some()),
        ("edge_u", d.edge_u.is_some()),
        ("edge_v", d.edge_v.is_some()),
    ];
    let color = d.color.as_ref().map(v3).unwrap_or(DVec3::ONE);
    if color.cmplt(DVec3::ZERO).any() || color == DVec3::ZERO {
        return Err(t.err(format!("'color' must be non-negative and not black, got {color}")));
    }
    let power =
        |t: &Table| -> Result<DVec3> { Ok(color * t.positive("power", t.required("power", d.power)?.0)?) };
    match d.kind.as_str() {
        "point" => {
            t.only("point", &given, &["position", "power", "intensity", "color"])?;
            let position = v3(t.required("position", d.position.as_ref())?);
            let intensity = match (d.power, d.intensity) {
                (Some(_), None) => power(&t)? / (4.0 * PI),
                (None, Some(i)) => color * t.positive("intensity", i.0)?,
                _ => return Err(t.err("needs exactly one of 'power' or 'intensity'")),
            };
            Ok(Light::Point { position, intensity })
        }
        "spot" => {
            t.only(
                "spot",
                &given,
                &[
                    "position",
                    "power",
                    "color",
                    "direction",
                    "cone_angle",
                    "cone_falloff",
                ],
            )?;
            let position = v3(t.required("position", d.position.as_ref())?);
            let direction = t
                .nonzero("direction", v3(t.required("direction", d.direction.as_ref())?))?
                .normalize();
            let angle = t.required("cone_angle", d.cone_angle)?.0;
            if !(angle > 0.0 && angle < 180.0) {
                return Err(t.err(format!(
                    "'cone_angle' must be between 0 and 180 degrees, got {angle}"
                )));
            }
            let falloff = d.cone_falloff.map_or(5.0, |r| r.0).clamp(0.0, angle);
            let cos_outer = (0.5 * angle).to_radians().cos();
            let cos_inner = (0.5 * (angle - falloff)).to_radians().cos();
            let solid = 2.0 * PI * (1.0 - 0.5 * (cos_inner + cos_outer));
            Ok(Light::Spot {
                position,
                direction,
                intensity: power(&t)? / solid,
                cos_inner,
                cos_outer,
            })
        }
        "sphere" => {
            t.only("sphere", &given, &["center", "radius", "power", "color"])?;
            let center = v3(t.required("center", d.center.as_ref())?);
            let radius = t.positive("radius", t.required("radius", d.radius)?.0)?;
            Ok(Light::Sphere {
                center,
                radius,
                radiance: power(&t)? / (4.0 * PI * PI * radius * radius),
            })
        }
        "quad" => {
            t.only("quad", &given, &["corner", "edge_u", "edge_v", "power", "color"])?;
            let corner = v3(t.required("corner", d.corner.as_ref())?);
            let edge_u = v3(t.required("edge_u", d.edge_u.as_ref())?);
            let edge_v = v3(t.required("edge_v", d.edge_v.as_ref())?);
            let area = edge_u.cross(edge_v).length();
            if area == 0.0 {
                return Err(t.err("'edge_u' and 'edge_v' are parallel (or zero): the light has no area"));
            }
            Ok(Light::Quad {
                corner,
                edge_u,
                edge_v,
                radiance: power(&t)? / (PI * area),
            })
        }
        other => Err(t.err(format!(
            "unknown light type '{other}' (expected point, spot, sphere or quad)"
        ))),
    }
}
