//! A unidirectional path tracer: an unbiased cross-check of photon mapping in the same
//! program (Kajiya 1986), in the manner of pbrt-v4's `PathIntegrator`:
//!
//! - scattering asked of the BSDF seam ([`crate::render::bsdf`]): at a vertex with a smooth
//!   part, next-event estimation (one shadow ray to each light; for area lights, spheres and
//!   quads, weighted by multiple importance sampling against the BSDF sample that may hit the
//!   same light: Veach 1997, the power heuristic, with the light's own density
//!   [`crate::scene::Light::pdf`]) and a direction sampled from the BSDF; at a specular one,
//!   one delta lobe picked with its share (glass: reflection or refraction by its Fresnel
//!   reflectance);
//! - Russian roulette on the path throughput after the third bounce;
//! - one sample per pixel per pass, the pixel position on Sobol's (0,2)-sequence and the lens
//!   position on R4, randomised per pixel, as the photon mapper's stochastic eye pass places
//!   its rays ([`crate::render::sequence`]);
//! - every random number from `(seed, stream, pass · pixels + pixel)`: the image is the same
//!   for any number of threads.
//!
//! The image is the mean of the passes' samples. Emitters reflect nothing (as everywhere in
//! caustic); a path ends when it meets one.

use std::time::Instant;

use glam::{DVec2, DVec3};
use rand::Rng;
use rand_pcg::Pcg64Mcg;
use rayon::prelude::*;

use super::{Integrator, PassPlan, Setup};
use crate::geometry::{Hit, Ray};
use crate::render::frame::{Frame, FrameStats, StatRow};
use super::Control;
use crate::render::provenance;
use crate::render::rng::stream_rng;
use crate::render::sequence;
use crate::render::bsdf::Bsdf;
use crate::render::mis::power_heuristic;
use crate::render::wavelength::Wavelength;
use crate::scene::Scene;
use crate::settings::RendererKind;

/// Random streams of the path tracer (the photon mapper's are 10–13).
mod streams {
    /// The numbers of one pixel's path in one pass.
    pub const PATH: u64 = 20;
    /// Each pixel's fixed offsets of its sample sequences.
    pub const OFFSETS: u64 = 21;
}

/// Rows of pixels traced between two questions to the caller.
const BATCH_ROWS: usize = 8;

/// What a path-traced render did.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize)]
pub struct PathStats {
    /// Completed passes (samples per pixel).
    pub passes: u32,
    /// Path segments traced (eye and bounce rays; shadow rays not counted).
    pub segments: u64,
    /// Shadow rays traced.
    pub shadow_rays: u64,
    /// Seconds spent in completed passes.
    pub elapsed_secs: f64,
}

/// A path-traced render of one epoch: each pixel's sum of samples.
pub struct PathTracer {
    setup: Setup,
    size: (u32, u32),
    sums: Vec<DVec3>,
    stats: PathStats,
}

impl PathTracer {
    /// Nothing traced yet.
    pub fn new(scene: &Scene, setup: &Setup) -> Self {
        let size = (scene.camera.width, scene.camera.height);
        Self {
            setup: setup.clone(),
            size,
            sums: vec![DVec3::ZERO; size.0 as usize * size.1 as usize],
            stats: PathStats::default(),
        }
    }
}

/// One pixel sample's path: its radiance and how many segments and shadow rays it traced.
struct Path<'s> {
    scene: &'s Scene,
    /// For each object, the light whose visible surface it is.
    light_of: &'s [Option<usize>],
    rng: Pcg64Mcg,
    segments: u64,
    shadow_rays: u64,
}

impl Path<'_> {
    /// Light sampled at a vertex with a smooth BSDF: one shadow ray to each light, area
    /// lights weighted against the BSDF sample.
    fn next_event(&mut self, hit: &Hit, bsdf: &Bsdf, wo: DVec3) -> DVec3 {
        let n = bsdf.normal();
        let scene = self.scene;
        let mut sum = DVec3::ZERO;
        for (k, light) in scene.lights.iter().enumerate() {
            let u = DVec2::new(self.rng.random(), self.rng.random());
            let Some(ls) = light.sample(hit.point, u) else {
                continue;
            };
            // Either side of the surface: f is zero where the BSDF takes no light.
            let f = bsdf.eval(wo, ls.wi);
            if f == DVec3::ZERO {
                continue;
            }
            let cos = n.dot(ls.wi).abs();
            self.shadow_rays += 1;
            if scene.occluded_from_hit(hit, k, &ls) {
                continue;
            }
            let weight = if light.is_area() {
                let on = hit.point + ls.wi * ls.distance;
                power_heuristic(light.pdf(hit.point, on), bsdf.pdf(wo, ls.wi))
            } else {
                1.0
            };
            sum += f * ls.incident * cos * weight;
        }
        sum
    }

    /// The radiance arriving along `ray` (Kajiya's estimator, one path).
    fn radiance(&mut self, mut ray: Ray) -> DVec3 {
        let scene = self.scene;
        let max_bounces = scene.params.max_depth.max(1) * 4;
        let (mut radiance, mut beta) = (DVec3::ZERO, DVec3::ONE);
        let mut wavelength = Wavelength::WHITE;
        // The last bounce's origin and BSDF density (None: a specular lobe or the camera).
        let mut last_diffuse: Option<(DVec3, f64)> = None;
        for bounce in 0..=max_bounces {
            self.segments += 1;
            let Some(hit) = scene.geometry.intersect(&ray, f64::INFINITY) else {
                return radiance + beta * scene.background;
            };
            let emitted = scene.emission(&hit, ray.dir);
            if emitted != DVec3::ZERO {
                let weight = match (last_diffuse, self.light_of[hit.object as usize]) {
                    (Some((from, bsdf_pdf)), Some(k)) => {
                        power_heuristic(bsdf_pdf, scene.lights[k].pdf(from, hit.point))
                    }
                    _ => 1.0,
                };
                radiance += beta * emitted * weight;
            }
            if scene.objects[hit.object as usize].emission.is_some() || bounce == max_bounces {
                return radiance;
            }
            let surface = scene.surface(&hit, ray.dir);
            beta *= wavelength.meet(surface.material, || self.rng.random());
            let bsdf = Bsdf::at(&surface, wavelength);
            let wo = -ray.dir;
            if bsdf.has_smooth() {
                radiance += beta * self.next_event(&hit, &bsdf, wo);
                let Some(s) = bsdf.sample(wo, &mut self.rng) else {
                    return radiance;
                };
                beta *= s.weight;
                last_diffuse = Some((hit.point, s.pdf));
                ray = hit.spawn(s.wi);
            } else {
                let lobes = bsdf.specular_lobes(wo);
                let Some(lobe) = lobes.choose(|| self.rng.random()) else {
                    return radiance;
                };
                beta *= lobe.tint;
                last_diffuse = None;
                ray = hit.spawn(lobe.wi);
            }
            // Russian roulette after the third bounce, on the throughput.
            if bounce >= 3 {
                let survive = beta.max_element().min(1.0);
                if survive <= 0.0 || self.rng.random::<f64>() >= survive {
                    return radiance;
                }
                beta /= survive;
            }
        }
        radiance
    }
}

impl PathTracer {
    /// One sample of pixel `i` in pass `pass`: its radiance, segments and shadow rays.
    fn sample(&self, scene: &Scene, light_of: &[Option<usize>], pass: u64, i: u64) -> (DVec3, u64, u64) {
        let (w, h) = (self.size.0 as u64, self.size.1 as u64);
        let seed = scene.params.seed;
        let ray = sequence::pixel_ray(&scene.camera, pass, i, &mut stream_rng(seed, streams::OFFSETS, i));
        let mut path = Path {
            scene,
            light_of,
            rng: stream_rng(seed, streams::PATH, pass * w * h + i),
            segments: 0,
            shadow_rays: 0,
        };
        let l = path.radiance(ray);
        // A path that met a numerical accident carries no light rather than a NaN.
        let l = if l.is_finite() { l } else { DVec3::ZERO };
        (l, path.segments, path.shadow_rays)
    }
}

impl Integrator for PathTracer {
    fn render_pass(&mut self, scene: &Scene, plan: &PassPlan, control: &mut dyn FnMut(&mut crate::settings::RenderParams) -> Control) -> bool {
        let start = Instant::now();
        let width = self.size.0 as usize;
        let pass = self.stats.passes as u64;
        let light_of = scene.light_of_objects();
        let mut samples = vec![DVec3::ZERO; self.sums.len()];
        let (mut segments, mut shadow_rays) = (0, 0);
        // The path tracer has no live setting: the settings it gets back are left alone.
        let mut live = plan.params.clone();
        for (batch, rows) in samples.chunks_mut(BATCH_ROWS * width).enumerate() {
            if control(&mut live) == Control::Abort || self.setup.interrupted() {
                return false;
            }
            let first = (batch * BATCH_ROWS * width) as u64;
            let counts: (u64, u64) = rows
                .par_iter_mut()
                .enumerate()
                .map(|(k, out)| {
                    let (l, s, r) = self.sample(scene, &light_of, pass, first + k as u64);
                    *out = l;
                    (s, r)
                })
                .reduce(|| (0, 0), |a, b| (a.0 + b.0, a.1 + b.1));
            segments += counts.0;
            shadow_rays += counts.1;
        }
        if self.setup.interrupted() {
            return false;
        }
        for (sum, s) in self.sums.iter_mut().zip(&samples) {
            *sum += *s;
        }
        self.stats.passes += 1;
        self.stats.segments += segments;
        self.stats.shadow_rays += shadow_rays;
        self.stats.elapsed_secs += start.elapsed().as_secs_f64();
        true
    }

    fn passes(&self) -> u32 {
        self.stats.passes
    }

    fn frame(&self, epoch: u64, elapsed_secs: f64) -> Frame {
        let n = self.stats.passes.max(1) as f64;
        let radiance = self.sums.iter().map(|s| (*s / n).as_vec3().to_array()).collect();
        let mut frame = Frame::of_radiance(self.size, radiance, self.stats.passes, (epoch, elapsed_secs), frame_stats(&self.stats));
        // Paths traced: what error estimates scale by, as photons are for photon mapping.
        frame.photons = self.stats.passes as u64 * self.sums.len() as u64;
        frame
    }
}

/// The path tracer's statistics as a frame's.
fn frame_stats(s: &PathStats) -> FrameStats {
    let segment_rate = s.segments as f64 / s.elapsed_secs.max(1e-9);
    FrameStats {
        kind: RendererKind::Path,
        seconds: s.elapsed_secs,
        rows: vec![
            StatRow::new("Samples", s.passes.to_string(), "Paths traced per pixel (one a pass)"),
            StatRow::new(
                "Segments/s",
                format!("{segment_rate:.0}"),
                "Path segments (eye and bounce rays) traced per second",
            ),
        ],
        summary: vec![format!(
            ", {} samples per pixel in {:.2} s ({} path segments, {} shadow rays, {segment_rate:.0} segments/s)",
            s.passes, s.elapsed_secs, s.segments, s.shadow_rays
        )],
        skipped: Vec::new(),
        json: serde_json::json!({ "path_tracing": s }),
        metadata: vec![
            (provenance::PASSES.into(), s.passes.to_string()),
            ("caustic:elapsed_secs".into(), format!("{:.3}", s.elapsed_secs)),
        ],
        progress: String::new(),
    }
}
