//! `[[lights]]`, and the visible surfaces of area lights, which join the geometry as emitters.

use glam::DVec3;
use toml::Spanned;

use super::diagnostics::{v3, Ctx, Result, Table};
use crate::geometry::{GeometryBuilder, Quad, Sphere};
use crate::scene::format::LightDesc;
use crate::scene::light::Light;
use crate::scene::material::{Material, MaterialKind};
use crate::scene::SceneObject;
use crate::settings::limits;

/// The keys a `[[lights]]` table gave, for [`Table::only`].
fn given_keys(d: &LightDesc) -> [(&'static str, bool); 12] {
    [
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
    ]
}

/// One `[[lights]]` table, checked; the physics of each kind is on [`Light`].
pub(super) fn light(ctx: &Ctx, k: usize, desc: &Spanned<LightDesc>) -> Result<Light> {
    let d = desc.get_ref();
    let t = Table {
        ctx,
        span: desc.span(),
        name: format!("lights[{k}] ({})", d.kind),
    };
    let given = given_keys(d);
    let color = d.color.as_ref().map(v3).unwrap_or(DVec3::ONE);
    if !color.is_finite() || color.cmplt(DVec3::ZERO).any() || color == DVec3::ZERO {
        return Err(t.err(format!(
            "'color' must be finite, non-negative and not black, got {color}"
        )));
    }
    // The brightest channel of `field` × color, within the stated limit.
    let scaled = |t: &Table, field: &str, value: f64| -> Result<DVec3> {
        let v = color * t.positive(field, value)?;
        limits::light_power(v.max_element()).map_err(|e| t.err(format!("'{field}' {e}")))?;
        Ok(v)
    };
    let power = |t: &Table| -> Result<DVec3> { scaled(t, "power", t.required("power", d.power)?.0) };
    // An area light's power over π × its area: the radiance its surface emits.
    let area_light = |t: &Table, power: DVec3, area: f64| -> Result<DVec3> {
        limits::radiance(power.max_element() / (std::f64::consts::PI * area))
            .map_err(|e| t.err(format!("'power' over the light's area {e}")))?;
        Ok(power)
    };
    match d.kind.as_str() {
        "point" => {
            t.only("point", &given, &["position", "power", "intensity", "color"])?;
            let position = v3(t.required("position", d.position.as_ref())?);
            match (d.power, d.intensity) {
                (Some(_), None) => Ok(Light::point(position, power(&t)?)),
                (None, Some(i)) => Ok(Light::Point {
                    position,
                    intensity: scaled(&t, "intensity", i.0)?,
                }),
                _ => Err(t.err("needs exactly one of 'power' or 'intensity'")),
            }
        }
        "spot" => {
            let allowed = [
                "position",
                "power",
                "color",
                "direction",
                "cone_angle",
                "cone_falloff",
            ];
            t.only("spot", &given, &allowed)?;
            let position = v3(t.required("position", d.position.as_ref())?);
            let direction = t.nonzero("direction", v3(t.required("direction", d.direction.as_ref())?))?;
            let angle = t.required("cone_angle", d.cone_angle)?.0;
            if !(angle > 0.0 && angle < 180.0) {
                return Err(t.err(format!(
                    "'cone_angle' must be between 0 and 180 degrees, got {angle}"
                )));
            }
            let falloff = d.cone_falloff.map_or(5.0, |r| r.0);
            Ok(Light::spot(position, direction, power(&t)?, angle, falloff))
        }
        "sphere" => {
            t.only("sphere", &given, &["center", "radius", "power", "color"])?;
            let center = v3(t.required("center", d.center.as_ref())?);
            let radius = t.positive("radius", t.required("radius", d.radius)?.0)?;
            let area = 4.0 * std::f64::consts::PI * radius * radius;
            Ok(Light::sphere(center, radius, area_light(&t, power(&t)?, area)?))
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
            Ok(Light::quad(
                corner,
                edge_u,
                edge_v,
                area_light(&t, power(&t)?, area)?,
            ))
        }
        other => Err(t.err(format!(
            "unknown light type '{other}' (expected point, spot, sphere or quad)"
        ))),
    }
}

/// Reads every light; area lights' surfaces join the geometry (and `objects`) as emitters that
/// reflect nothing. Returns the lights and, for each, the object of its visible surface.
pub(super) fn add_lights(
    ctx: &Ctx,
    descs: &[Spanned<LightDesc>],
    builder: &mut GeometryBuilder,
    materials: &mut Vec<Material>,
    objects: &mut Vec<SceneObject>,
) -> Result<(Vec<Light>, Vec<Option<u32>>)> {
    let mut lights = Vec::new();
    let mut light_objects = Vec::new();
    let mut emitter_material: Option<usize> = None;
    for (k, desc) in descs.iter().enumerate() {
        let light = light(ctx, k, desc)?;
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
    Ok((lights, light_objects))
}
