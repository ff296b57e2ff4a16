//! `[[objects]]`: spheres, planes, quads, meshes and Bézier patches, placed by their
//! transform into the geometry.

use std::collections::BTreeMap;

use glam::{DAffine3, DMat3, DVec3};
use toml::Spanned;

use super::diagnostics::{v3, Ctx, Result, Table};
use super::usd_objects::UsdExtras;
use crate::geometry::freeform::{place_pieces, DomainPatch};
use crate::geometry::rational::{weights_error, Weights};
use crate::geometry::usd::{is_usd_file, load_usd, UsdContents};
use crate::geometry::{
    load_bpt, load_freeform_obj, BezierPatch, GeometryBuilder, Plane, Quad, Sphere, TriangleMesh, Window,
};
use crate::scene::format::{ObjectDesc, Real, ScaleDesc, TransformDesc};
use crate::scene::SceneObject;

pub(super) fn transform(t: &Table, d: Option<&TransformDesc>) -> Result<(DAffine3, Option<f64>)> {
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

/// Adds object `k` to the builder and the list; a USD file's meshes and spheres go to
/// `extras`, to be added after the scene's own objects.
pub(super) fn object(
    ctx: &Ctx,
    (k, desc): (usize, &Spanned<ObjectDesc>),
    materials: &BTreeMap<String, usize>,
    builder: &mut GeometryBuilder,
    objects: &mut Vec<SceneObject>,
    extras: &mut Vec<UsdExtras>,
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
    let material = material_index(&t, &d.material, materials)?;
    let id = objects.len() as u32;
    let name = d.name.clone().unwrap_or_else(|| format!("{} {k}", d.kind));
    if let Some(usd) = add_shape(&t, d, &label, builder, id)? {
        extras.push(UsdExtras::new(&t, usd, (&name, material), d.transform.as_ref())?);
    }
    objects.push(SceneObject {
        name,
        material,
        emission: None,
    });
    Ok(())
}

/// Adds the shape of object `id` (its `type`'s keys checked, placed by its transform); a USD
/// file's contents beside its surfaces are returned.
fn add_shape(
    t: &Table,
    d: &ObjectDesc,
    label: &str,
    builder: &mut GeometryBuilder,
    id: u32,
) -> Result<Option<UsdContents>> {
    let given = given_keys(d);
    let (m, uniform_scale) = transform(t, d.transform.as_ref())?;
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
            let path = t.ctx.resolve(&t.span, &format!("{label}: 'file'"), file)?;
            builder.add_mesh(placed_mesh(t, &path, &m)?, id);
        }
        "patches" => return add_patches(t, (d, label), builder, &m, id),
        other => {
            return Err(t.err(format!(
                "unknown object type '{other}' (expected sphere, plane, quad, mesh or patches)"
            )))
        }
    }
    Ok(None)
}

/// A `patches` object's patches, placed by `m`, into the builder; what a USD file holds
/// besides is returned.
fn add_patches(
    t: &Table,
    (d, label): (&ObjectDesc, &str),
    builder: &mut GeometryBuilder,
    m: &DAffine3,
    id: u32,
) -> Result<Option<UsdContents>> {
    let given = given_keys(d);
    t.only(
        "patches",
        &given,
        &[
            "file",
            "builtin",
            "patches",
            "domains",
            "weights",
            "trims",
            "transform",
            "nurbs",
        ],
    )?;
    let (list, usd) = patch_list(t, d, label)?;
    let limit = crate::settings::limits::MAX_PATCHES;
    if builder.patch_count() + list.len() > limit {
        return Err(t.err(format!(
            "its {} patches make the scene's {}; a scene holds at most {limit}",
            list.len(),
            builder.patch_count() + list.len()
        )));
    }
    for piece in place_pieces(list, m) {
        builder.add_surface_patch(piece, id);
    }
    Ok(usd)
}

/// Applies inline `domains` (one `[u0, u1, v0, v1]` per patch, each range increasing).
pub(super) fn patch_domains(t: &Table, patches: &mut [DomainPatch], domains: &[[Real; 4]]) -> Result<()> {
    if domains.len() != patches.len() {
        return Err(t.err(format!(
            "'domains' has {} entries for {} patches",
            domains.len(),
            patches.len()
        )));
    }
    for (i, (DomainPatch { window, .. }, d)) in patches.iter_mut().zip(domains).enumerate() {
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

/// Applies inline `weights` (16 positive numbers per patch): the patches become rational.
fn patch_weights(t: &Table, patches: &mut [DomainPatch], weights: &[Vec<Real>]) -> Result<()> {
    if weights.len() != patches.len() {
        return Err(t.err(format!(
            "'weights' has {} entries for {} patches",
            weights.len(),
            patches.len()
        )));
    }
    for (i, (DomainPatch { weights: out, .. }, w)) in patches.iter_mut().zip(weights).enumerate() {
        let w: Weights = w
            .iter()
            .map(|r| r.0)
            .collect::<Vec<f64>>()
            .try_into()
            .map_err(|w: Vec<f64>| t.err(format!("'weights[{i}]' must have 16 weights, has {}", w.len())))?;
        if let Some(why) = weights_error(&w) {
            return Err(t.err(format!("'weights[{i}]': {why}")));
        }
        *out = Some(w);
    }
    Ok(())
}

/// The index of material `name`, or an error listing the defined ones.
fn material_index(t: &Table, name: &str, materials: &BTreeMap<String, usize>) -> Result<usize> {
    materials.get(name).copied().ok_or_else(|| {
        let known: Vec<&str> = materials.keys().map(String::as_str).collect();
        t.err(format!(
            "unknown material '{name}' (defined: {})",
            if known.is_empty() {
                "none".to_owned()
            } else {
                known.join(", ")
            }
        ))
    })
}

/// The keys an `[[objects]]` table gave, for [`Table::only`].
fn given_keys(d: &ObjectDesc) -> [(&'static str, bool); 15] {
    [
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
        ("weights", d.weights.is_some()),
        ("trims", d.trims.is_some()),
        ("transform", d.transform.is_some()),
        ("nurbs", d.nurbs.is_some()),
    ]
}

/// A triangle mesh read from `path`, placed by `m`.
fn placed_mesh(t: &Table, path: &std::path::Path, m: &DAffine3) -> Result<TriangleMesh> {
    let mut mesh = TriangleMesh::load_obj(path).map_err(|e| t.err(e))?;
    place_mesh(&mut mesh, m);
    Ok(mesh)
}

/// A mesh's points (and normals, by the inverse transpose) placed by `m`.
pub(super) fn place_mesh(mesh: &mut TriangleMesh, m: &DAffine3) {
    let normal_matrix = m.matrix3.inverse().transpose();
    for p in &mut mesh.positions {
        *p = m.transform_point3(*p);
    }
    for n in &mut mesh.normals {
        *n = (normal_matrix * *n).normalize_or_zero();
    }
}

/// The patches of a `patches` object, each with its `(u,v)` window: from a `.bpt`, a
/// free-form `.obj` or a USD file (with what else the USD file holds), built in, or written
/// inline (with optional `domains`).
fn patch_list(t: &Table, d: &ObjectDesc, label: &str) -> Result<(Vec<DomainPatch>, Option<UsdContents>)> {
    if d.domains.is_some() && d.patches.is_none() {
        return Err(t.err("'domains' applies only to inline 'patches'"));
    }
    if d.trims.is_some() && d.patches.is_none() {
        return Err(t.err(
            "'trims' applies only to inline 'patches' (an OBJ file's trimmed surfaces carry their own)",
        ));
    }
    if d.weights.is_some() && d.patches.is_none() {
        return Err(t.err(
            "'weights' applies only to inline 'patches' (an OBJ file's rational surfaces carry their own)",
        ));
    }
    let usd_file = d.file.as_deref().is_some_and(is_usd_file);
    if d.nurbs.is_some() && !usd_file {
        return Err(t.err("'nurbs' applies only to a USD 'file' (.usda, .usdc, .usdz, .usd)"));
    }
    let whole = |patches: Vec<BezierPatch>| patches.into_iter().map(DomainPatch::whole).collect();
    let list = match (d.file.as_deref(), d.builtin.as_deref(), &d.patches) {
        (Some(file), None, None) => {
            let path = t.ctx.resolve(&t.span, &format!("{label}: 'file'"), file)?;
            if usd_file {
                let mut usd = load_usd(&path).map_err(|e| t.err(e))?;
                let patches = std::mem::take(&mut usd.patches);
                let patches = if d.nurbs == Some(false) {
                    Vec::new()
                } else {
                    patches
                };
                return Ok((patches, Some(usd)));
            }
            if path.extension().is_some_and(|e| e.eq_ignore_ascii_case("obj")) {
                load_freeform_obj(&path).map_err(|e| t.err(e))
            } else {
                Ok(whole(load_bpt(&path).map_err(|e| t.err(e))?))
            }
        }
        (None, Some("teapot"), None) => Ok(whole(crate::assets::teapot())),
        (None, Some(other), None) => {
            Err(t.err(format!("unknown 'builtin' patches '{other}' (available: teapot)")))
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
                out.push(DomainPatch::whole(BezierPatch::new(std::array::from_fn(|j| {
                    v3(&points[j])
                }))));
            }
            if out.is_empty() {
                return Err(t.err("'patches' is empty"));
            }
            if let Some(domains) = &d.domains {
                patch_domains(t, &mut out, domains)?;
            }
            if let Some(weights) = &d.weights {
                patch_weights(t, &mut out, weights)?;
            }
            if let Some(trims) = &d.trims {
                super::trims::patch_trims(t, &mut out, trims)?;
            }
            Ok(out)
        }
        _ => Err(t.err("needs exactly one of 'file', 'builtin' or 'patches'")),
    };
    Ok((list?, None))
}
