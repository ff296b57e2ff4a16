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

use std::ops::Range;

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

/// Points [`area_light_pass`] samples at a time: their light takes 24 bytes a point, which
/// for a whole pass's points at 1920×1080 would be 50 MiB of the render's peak, and for a
/// block is 1.5 MiB. Large enough that each block keeps every thread busy.
const BLOCK: usize = 1 << 16;

/// Reflected radiance from every area light at each point (one sample each; none at the
/// points `skip` names), handed to `add(k, light)` in point order:
/// `point.weight(wi) × L × cos θ / pdf` where the shadow ray is clear. `key(k)` names point
/// `k` stably across passes (its statistics slot), for the stratification. Sampled `BLOCK`
/// points at a time, in parallel.
pub fn area_light_pass(
    scene: &Scene,
    points: &VisiblePoints,
    key: impl Fn(usize) -> u64 + Sync,
    (pass, seed): (u64, u64),
    skip: Option<&(dyn Fn(usize) -> bool + Sync)>,
    mut add: impl FnMut(usize, DVec3),
) {
    let mut sampler = Sampler::new(scene, points, key, pass, seed);
    sampler.skip = skip;
    let mut light = Vec::with_capacity(BLOCK.min(points.len()));
    for first in (0..points.len()).step_by(BLOCK) {
        sampler.sample(first..(first + BLOCK).min(points.len()), &mut light);
        for (k, &l) in (first..).zip(&light) {
            add(k, l);
        }
    }
}

/// What sampling the area lights at a pass's points needs.
struct Sampler<'a, K> {
    scene: &'a Scene,
    points: &'a VisiblePoints,
    key: K,
    pass: u64,
    seed: u64,
    /// The scene's area lights with their indices.
    lights: Vec<(u64, &'a crate::scene::Light)>,
    /// Points whose light is known already (a copy of the previous pass's,
    /// [`super::reuse`]): they are handed no light.
    skip: Option<&'a (dyn Fn(usize) -> bool + Sync)>,
}

impl<'a, K: Fn(usize) -> u64 + Sync> Sampler<'a, K> {
    fn new(scene: &'a Scene, points: &'a VisiblePoints, key: K, pass: u64, seed: u64) -> Self {
        Self {
            scene,
            points,
            key,
            pass,
            seed,
            lights: (0u64..).zip(&scene.lights).filter(|(_, l)| l.is_area()).collect(),
            skip: None,
        }
    }

    /// The numbers of point `k`'s sample of light `l` in this pass.
    fn numbers(&self, k: usize, l: u64) -> DVec2 {
        let count = self.scene.lights.len() as u64;
        let mut rng = stream_rng(self.seed, OFFSET_STREAM, (self.key)(k) * count + l);
        let offset = DVec2::new(rng.random(), rng.random());
        sequence::rotated(sequence::r4(self.pass)[1], offset)
    }

    /// The light at the points `block`, in point order, into `light` (replacing what it held,
    /// keeping its memory).
    fn sample(&self, block: Range<usize>, light: &mut Vec<DVec3>) {
        let scene = self.scene;
        let first = block.start;
        self.points.reach[block.clone()]
            .par_iter()
            .zip(&self.points.shade[block])
            .enumerate()
            .map(|(i, (reach, shade))| {
                let k = first + i;
                let (position, normal) = (reach.position, shade.normal.as_dvec3());
                if self.skip.is_some_and(|skip| skip(k)) {
                    return DVec3::ZERO;
                }
                let mut sum = DVec3::ZERO;
                for &(l, light) in &self.lights {
                    let Some(ls) = light.sample(position, self.numbers(k, l)) else {
                        continue;
                    };
                    // Zero below the surface, unless the point refracts.
                    let weight = self.points.weight(k, ls.wi);
                    if weight == DVec3::ZERO {
                        continue;
                    }
                    if !scene.occluded_from(position, normal, l as usize, &ls) {
                        sum += weight * ls.incident * normal.dot(ls.wi).abs();
                    }
                }
                sum
            })
            .collect_into_vec(light);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::ppm::visible::VisiblePoint;

    /// The light of points sampled in blocks is the light of all of them sampled at once, bit
    /// for bit: a point's sample depends on its key, the pass and the seed, not on which
    /// block it is in, so the blocks that bound a pass's memory leave the image as it was.
    #[test]
    fn blocks_sample_the_same_light_as_one_pass() {
        // The built-in scene: a sphere light above a floor at z = 0, a teapot casting shadows.
        let scene = Scene::builtin();
        let n = 3000;
        let points: VisiblePoints = (0..n)
            .map(|k| VisiblePoint {
                slot: k as u32,
                position: DVec3::new((k % 60) as f64 * 0.1 - 3.0, (k / 60) as f64 * 0.1 - 2.5, 1e-6),
                normal: DVec3::Z,
                weight: DVec3::ONE,
                radius2: 0.0,
                glossy: None,
            })
            .collect();
        let key = |k: usize| 7 * k as u64 + 3;
        let sampler = Sampler::new(&scene, &points, key, 5, 11);
        let mut whole = Vec::new();
        sampler.sample(0..n, &mut whole);
        assert_eq!(whole.len(), n);
        let lit = whole.iter().filter(|l| l.max_element() > 0.0).count();
        assert!(
            lit > n / 4 && lit < n,
            "{lit} of {n} points lit: some should be in shadow"
        );
        let (mut blocked, mut block) = (Vec::new(), Vec::new());
        for range in [0..1, 1..1000, 1000..1000, 1000..n - 1, n - 1..n] {
            sampler.sample(range, &mut block);
            blocked.extend_from_slice(&block);
        }
        assert_eq!(whole, blocked);
        // The pass hands every point's light once, in point order.
        let mut handed = Vec::new();
        area_light_pass(&scene, &points, key, (5, 11), None, |k, l| handed.push((k, l)));
        assert_eq!(handed, whole.into_iter().enumerate().collect::<Vec<_>>());
    }
}
