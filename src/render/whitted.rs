//! The Whitted ray tracer (Whitted 1980; seed report §3.1): Lambert + Phong shading with a
//! shadow ray per point light and stratified shadow samples per area light, recursive mirror
//! reflection and Fresnel-weighted reflection + refraction for glass, thin-lens depth of field
//! by aperture sampling (§3.1.1), and the seed's edge-adaptive anti-aliasing (§3.1.2): each
//! pixel's centre ray records a hash of every object its path touched and of which lights it
//! saw; only pixels whose hash differs from a 4-neighbour's are re-sampled with a 4×4 grid.
//!
//! Radiance is physically scaled: a diffuse surface of reflectance ρ lit by a point light of
//! intensity I at distance r reflects `ρ/π · I cos θ / r²`.

use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::Instant;

use glam::{DVec2, DVec3};
use rand::Rng;
use rand_pcg::Pcg64Mcg;
use rayon::prelude::*;

use super::bsdf::Bsdf;
use super::film::Image;
use super::rng::{mix64, stream_rng, streams};
use super::spectrum::channel_wavelengths;
use super::wavelength::Wavelength;
use crate::geometry::{Hit, Ray};
use crate::scene::camera::{concentric_disk, EyeRays};
use crate::scene::{Scene, Surface};

/// What a render did.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize)]
pub struct WhittedStats {
    /// Camera rays traced.
    pub camera_rays: u64,
    /// Pixels re-sampled by the edge-adaptive anti-aliasing.
    pub edge_pixels: u64,
    /// Wall-clock seconds.
    pub elapsed_secs: f64,
}

/// Per-path state: the hash of what the path touched, the RNG for light samples, and the
/// wavelength the path traces after a dispersive glass split it.
struct PathState<'r> {
    id: u64,
    rng: &'r mut Pcg64Mcg,
    wavelength: Wavelength,
}

impl<'r> PathState<'r> {
    /// A path of white light, having touched nothing yet.
    fn new(rng: &'r mut Pcg64Mcg) -> Self {
        Self {
            id: 0,
            rng,
            wavelength: Wavelength::WHITE,
        }
    }

    fn touch(&mut self, v: u64) {
        self.id = mix64(self.id ^ v.wrapping_mul(0x9e37_79b9_7f4a_7c15));
    }
}

struct Tracer<'s> {
    scene: &'s Scene,
    /// The camera's eye rays, their constants computed once.
    eye_rays: EyeRays<'s>,
}

impl Tracer<'_> {
    /// The first pass's colour of pixel `(x, y)` and its path/shadow hash: one centre ray,
    /// or every lens sample (stratified) when the aperture is open.
    fn first_sample(&self, x: u32, y: u32, rays: &AtomicUsize) -> (DVec3, u64) {
        let (scene, camera, eye) = (self.scene, &self.scene.camera, &self.eye_rays);
        let index = (y as u64) * camera.width as u64 + x as u64;
        let mut rng = stream_rng(scene.params.seed, streams::WHITTED_PIXEL, index);
        if camera.aperture > 0.0 {
            let n = scene.params.dof_samples;
            let grid = (n as f64).sqrt().ceil() as u32;
            let mut sum = DVec3::ZERO;
            for s in 0..n {
                let cell = DVec2::new((s % grid) as f64, (s / grid % grid) as f64);
                let lens = concentric_disk((cell + DVec2::new(rng.random(), rng.random())) / grid as f64);
                let px = DVec2::new(x as f64 + rng.random::<f64>(), y as f64 + rng.random::<f64>());
                let mut state = PathState::new(&mut rng);
                sum += self.trace(&eye.ray(px, lens), 0, &mut state);
            }
            rays.fetch_add(n as usize, Ordering::Relaxed);
            (sum / n as f64, 0)
        } else {
            let mut state = PathState::new(&mut rng);
            let px = Scene::pixel_center(x, y);
            let c = self.trace(&eye.ray(px, DVec2::ZERO), 0, &mut state);
            rays.fetch_add(1, Ordering::Relaxed);
            (c, state.id)
        }
    }

    /// The mean of a 4×4 grid of rays over pixel `i` = `(x, y)` (edge anti-aliasing).
    fn edge_samples(&self, i: usize, x: i64, y: i64) -> DVec3 {
        let eye = &self.eye_rays;
        let mut rng = stream_rng(self.scene.params.seed, streams::WHITTED_EDGE, i as u64);
        let mut sum = DVec3::ZERO;
        for sy in 0..4 {
            for sx in 0..4 {
                let px = DVec2::new(
                    x as f64 + (sx as f64 + 0.5) / 4.0,
                    y as f64 + (sy as f64 + 0.5) / 4.0,
                );
                let mut state = PathState::new(&mut rng);
                sum += self.trace(&eye.ray(px, DVec2::ZERO), 0, &mut state);
            }
        }
        sum / 16.0
    }

    /// Radiance arriving along `ray` after at most `max_depth - depth` more bounces.
    fn trace(&self, ray: &Ray, depth: u32, state: &mut PathState) -> DVec3 {
        let scene = self.scene;
        let Some(hit) = scene.geometry.intersect(ray, f64::INFINITY) else {
            state.touch(u64::MAX);
            return scene.background;
        };
        state.touch(hit.object as u64);
        let emitted = scene.emission(&hit, ray.dir);
        if scene.objects[hit.object as usize].emission.is_some() || depth >= scene.params.max_depth {
            return emitted;
        }
        let surface = scene.surface(&hit, ray.dir);
        if surface.material.is_dispersive() && state.wavelength.nm().is_none() {
            // A dispersive glass splits white light into one wavelength per channel, each
            // carrying its channel only: chromatic fringes without noise.
            let mut split = DVec3::ZERO;
            for (c, nm) in channel_wavelengths().into_iter().enumerate() {
                state.wavelength = Wavelength::fixed(nm);
                split[c] = self.shade(&hit, &surface, ray, depth, state)[c];
            }
            state.wavelength = Wavelength::WHITE;
            return emitted + split;
        }
        emitted + self.shade(&hit, &surface, ray, depth, state)
    }

    /// The light a smooth or specular surface at `hit` sends back along `ray` (emission
    /// aside), after at most `max_depth - depth` more bounces.
    fn shade(&self, hit: &Hit, surface: &Surface, ray: &Ray, depth: u32, state: &mut PathState) -> DVec3 {
        let scene = self.scene;
        let bsdf = Bsdf::at(surface, state.wavelength);
        let wo = -ray.dir;
        let mut radiance = DVec3::ZERO;
        if bsdf.has_smooth() {
            radiance += scene.params.ambient * bsdf.diffuse_reflectance();
            radiance = self.add_direct_light(radiance, hit, &bsdf, wo, state);
        }
        // Rough mirrors, metals and glass are followed as polished ones (beside their
        // highlights): a ray tracer follows delta lobes only.
        for lobe in bsdf.smooth_lobes(wo).iter() {
            radiance += lobe.share * lobe.tint * self.trace(&hit.spawn(lobe.wi), depth + 1, state);
        }
        radiance
    }

    /// `radiance` plus the light arriving straight from each light at a smooth surface,
    /// reflected towards `wo`: point and spot lights by one shadow ray, area lights by
    /// `light_samples` stratified ones.
    fn add_direct_light(
        &self,
        mut radiance: DVec3,
        hit: &Hit,
        bsdf: &Bsdf,
        wo: DVec3,
        state: &mut PathState,
    ) -> DVec3 {
        let scene = self.scene;
        let n = bsdf.normal();
        for (k, light) in scene.lights.iter().enumerate() {
            let samples = if light.is_area() {
                scene.params.light_samples
            } else {
                1
            };
            let grid = (samples as f64).sqrt().ceil() as u32;
            let mut sum = DVec3::ZERO;
            let mut visible = 0u32;
            for s in 0..samples {
                // Stratified over a grid × grid square, jittered.
                let cell = DVec2::new((s % grid) as f64, (s / grid % grid) as f64);
                let jitter = DVec2::new(state.rng.random(), state.rng.random());
                let u = (cell + jitter) / grid as f64;
                let Some(ls) = light.sample(hit.point, u) else {
                    continue;
                };
                let cos = n.dot(ls.wi);
                if cos <= 0.0 {
                    continue;
                }
                if scene.occluded_from_hit(hit, k, &ls) {
                    continue;
                }
                visible += 1;
                sum += bsdf.eval(wo, ls.wi) * ls.incident * cos;
            }
            // Shadow boundaries are edges too: fully lit, partly lit, or dark.
            let lit = if visible == 0 {
                0
            } else if visible == samples {
                2
            } else {
                1
            };
            state.touch(((k as u64) << 2) | lit);
            radiance += sum / samples as f64;
        }
        radiance
    }
}

/// Renders `scene` with the ray tracer. `progress(rows)` is called as rows finish (from any
/// thread). Deterministic: the same scene and seed give the same image for any thread count.
pub fn render_whitted(scene: &Scene, progress: &(dyn Fn(usize) + Sync)) -> (Image, WhittedStats) {
    render_whitted_until(scene, progress, &|| false).expect("a render nobody cancels completes")
}

/// [`render_whitted`] that gives up (returning `None`) soon after `cancelled()` turns true:
/// it is asked before every row and every pixel of the anti-aliasing pass. The viewer uses it
/// so that a slider moved during a ray-traced frame restarts the frame at once.
pub fn render_whitted_until(
    scene: &Scene,
    progress: &(dyn Fn(usize) + Sync),
    cancelled: &(dyn Fn() -> bool + Sync),
) -> Option<(Image, WhittedStats)> {
    let start = Instant::now();
    let camera = &scene.camera;
    let (w, h) = (camera.width, camera.height);
    let tracer = Tracer {
        scene,
        eye_rays: camera.eye_rays(),
    };
    let dof = camera.aperture > 0.0;
    let rays = AtomicUsize::new(0);

    // Pass 1: one centre ray per pixel (or all lens samples when the aperture is open).
    let first: Vec<(DVec3, u64)> = (0..h)
        .into_par_iter()
        .flat_map_iter(|y| {
            if cancelled() {
                return vec![(DVec3::ZERO, 0); w as usize];
            }
            let row: Vec<(DVec3, u64)> = (0..w).map(|x| tracer.first_sample(x, y, &rays)).collect();
            progress(1);
            row
        })
        .collect();
    if cancelled() {
        return None;
    }

    // Pass 2: re-sample pixels on an edge of object ids or shadow states with a 4×4 grid.
    let antialias = scene.params.antialias && !dof;
    let id = |x: i64, y: i64| first[(y * w as i64 + x) as usize].1;
    let edge_pixels = AtomicUsize::new(0);
    let pixels: Vec<[f32; 3]> = (0..(w as usize * h as usize))
        .into_par_iter()
        .map(|i| {
            let (x, y) = ((i % w as usize) as i64, (i / w as usize) as i64);
            let (color, own) = first[i];
            let on_edge = antialias
                && [(-1, 0), (1, 0), (0, -1), (0, 1)].iter().any(|(dx, dy)| {
                    let (nx, ny) = (x + dx, y + dy);
                    nx >= 0 && ny >= 0 && nx < w as i64 && ny < h as i64 && id(nx, ny) != own
                });
            let c = if on_edge && !cancelled() {
                edge_pixels.fetch_add(1, Ordering::Relaxed);
                rays.fetch_add(16, Ordering::Relaxed);
                tracer.edge_samples(i, x, y)
            } else {
                color
            };
            [c.x as f32, c.y as f32, c.z as f32]
        })
        .collect();
    if cancelled() {
        return None;
    }

    let stats = WhittedStats {
        camera_rays: rays.load(Ordering::Relaxed) as u64,
        edge_pixels: edge_pixels.load(Ordering::Relaxed) as u64,
        elapsed_secs: start.elapsed().as_secs_f64(),
    };
    Some((
        Image {
            width: w,
            height: h,
            pixels,
        },
        stats,
    ))
}
