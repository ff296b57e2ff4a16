//! The photons a design traces: fixed rays from the scene's point and spot lights through
//! points spread evenly over the designed surface as it starts (a stratified grid on each
//! patch, only where the light sees the surface first), each carrying the power the light
//! sends into its share of solid angle. The same rays are traced at every step, so that the
//! loss changes only because the surface does.

use glam::DVec3;

use crate::color::luminance;
use crate::geometry::Ray;
use crate::scene::light::{spot_falloff, Light};
use crate::scene::Scene;

/// One photon: its ray and its power (luminance).
#[derive(Clone, Copy, Debug)]
pub struct DesignPhoton {
    /// Where it leaves the light, and its direction.
    pub ray: Ray,
    /// Its share of the light's power.
    pub weight: f64,
}

/// The luminance a point or spot light sends towards `d` (0 for other lights).
fn intensity(light: &Light, d: DVec3) -> f64 {
    match *light {
        Light::Point { intensity, .. } => luminance(intensity),
        Light::Spot {
            direction,
            intensity,
            cos_inner,
            cos_outer,
            ..
        } => luminance(intensity) * spot_falloff(d.dot(direction), cos_inner, cos_outer),
        _ => 0.0,
    }
}

/// The lights a design traces photons from, with their positions: the scene's point and spot
/// lights (an error when it has none).
pub fn design_lights(scene: &Scene) -> Result<Vec<(DVec3, &Light)>, String> {
    let lights: Vec<(DVec3, &Light)> = scene
        .lights
        .iter()
        .filter_map(|light| match light {
            Light::Point { position, .. } | Light::Spot { position, .. } => Some((*position, light)),
            _ => None,
        })
        .collect();
    if lights.is_empty() {
        return Err("the scene has no point or spot light: a design traces photons from those".into());
    }
    Ok(lights)
}

/// About `count` photons from every point and spot light through `object`'s patches.
pub fn design_photons(scene: &Scene, object: u32, count: usize) -> Result<Vec<DesignPhoton>, String> {
    let patches: Vec<usize> = (0..scene.geometry.patches().len())
        .filter(|&k| scene.geometry.patches()[k].1 == object)
        .collect();
    let lights = design_lights(scene)?;
    let per_patch = (count / (patches.len() * lights.len()).max(1)).max(1);
    let n = (per_patch as f64).sqrt().ceil() as usize;
    let mut out = Vec::with_capacity(n * n * patches.len() * lights.len());
    for &(position, light) in &lights {
        for &k in &patches {
            let patch = &scene.geometry.patches()[k].0;
            for i in 0..n {
                for j in 0..n {
                    let (u, v) = ((i as f64 + 0.5) / n as f64, (j as f64 + 0.5) / n as f64);
                    let s = patch.eval_with_derivs(u, v);
                    let to = s.position - position;
                    let r2 = to.length_squared();
                    let Some(dir) = to.try_normalize() else { continue };
                    let ray = Ray::new(position, dir);
                    // Only where the light sees this point of the surface first.
                    let seen = scene
                        .geometry
                        .intersect(&ray, f64::INFINITY)
                        .is_some_and(|h| h.point.distance(s.position) <= 1e-6 * r2.sqrt().max(1.0));
                    let normal = s.dp_du.cross(s.dp_dv);
                    let solid_angle = normal.dot(dir).abs() / (n * n) as f64 / r2;
                    let weight = intensity(light, dir) * solid_angle;
                    if seen && weight > 0.0 && weight.is_finite() {
                        out.push(DesignPhoton { ray, weight });
                    }
                }
            }
        }
    }
    if out.is_empty() {
        return Err("no light shines on the surface".into());
    }
    Ok(out)
}
