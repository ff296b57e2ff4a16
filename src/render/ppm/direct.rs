//! Direct light from area lights (spheres, quads) at the visible points, by light sampling, as
//! pbrt-v4's SPPM integrator does: each pass, every visible point takes one sample of every
//! area light — the cone a sphere subtends, a quad's area — and one shadow ray. Photons then
//! skip their first diffuse deposit (that is this term), so they carry only what light
//! sampling cannot: caustics (light → specular → diffuse) and indirect light.
//!
//! Samples are stratified over passes: point `k` and light `l` take the low-discrepancy
//! sequence of [`crate::render::sequence`] (R4's light pair) at the pass number, shifted by a
//! random offset fixed for `(k, l)` (Cranley–Patterson rotation), so a point that persists
//! over passes (classic PPM) sweeps its light evenly, and a pixel whose eye rays are
//! stratified too (Sobol's pair, R4's lens pair) does not tie its light samples to them.

use glam::{DVec2, DVec3};
use rand::Rng;
use rayon::prelude::*;

use super::points::VisiblePoints;
use crate::render::rng::stream_rng;
use crate::render::sequence;
use crate::scene::Scene;

/// Random stream of the per-point offsets.
const OFFSET_STREAM: u64 = 12;

/// Whether the scene has lights that [`area_light_pass`] samples.
pub fn has_area_lights(scene: &Scene) -> bool {
    scene.lights.iter().any(|l| l.is_area())
}

/// Reflected radiance from every area light at each point (one sample each), in point order:
/// `point.weight × L × cos θ / pdf` where the shadow ray is clear. `key(k)` names point `k`
/// stably across passes (its statistics slot), for the stratification.
pub fn area_light_pass(
    scene: &Scene,
    points: &VisiblePoints,
    key: impl Fn(usize) -> u64 + Sync,
    pass: u64,
    seed: u64,
) -> Vec<DVec3> {
    let lights: Vec<(u64, &crate::scene::Light)> =
        (0u64..).zip(&scene.lights).filter(|(_, l)| l.is_area()).collect();
    let count = scene.lights.len() as u64;
    points
        .reach
        .par_iter()
        .zip(&points.shade)
        .enumerate()
        .map(|(k, (reach, shade))| {
            let (position, normal) = (reach.position, shade.normal.as_dvec3());
            let mut sum = DVec3::ZERO;
            for &(l, light) in &lights {
                let mut rng = stream_rng(seed, OFFSET_STREAM, key(k) * count + l);
                let offset = DVec2::new(rng.random(), rng.random());
                let u = sequence::rotated(sequence::r4(pass)[1], offset);
                let Some(ls) = light.sample(position, u) else {
                    continue;
                };
                let cos = normal.dot(ls.wi);
                if cos <= 0.0 {
                    continue;
                }
                if !scene.occluded_from(position, normal, l as usize, &ls) {
                    sum += shade.weight.as_dvec3() * ls.incident * cos;
                }
            }
            sum
        })
        .collect()
}
