//! The eye pass: visible points traced through the pixels — once for classic PPM (pinhole,
//! no anti-aliasing; glass paths split), every pass for stochastic PPM (Hachisuka & Jensen
//! 2009: one jittered point per pixel) — and light sampled at them for direct light.

use std::time::Instant;

use glam::{DVec2, DVec3, Vec3};
use rand::Rng;
use rand_pcg::Pcg64Mcg;
use rayon::prelude::*;

use super::points::{self, Shade, VisiblePoints};
use super::visible::{trace_eye, Branching, VisiblePoint};

use super::{direct, global, seen, streams, Estimate, Ppm, Slot};
use crate::render::rng::stream_rng;
use crate::render::sequence;
use crate::scene::Scene;

impl Ppm {
    /// Stochastic PPM's eye pass: one eye ray per pixel (jittered, through the lens), in
    /// parallel, written in place: each pixel's visible point (at most one: glass is chosen,
    /// not split) into `points` at the pixel's index, its directly seen light into
    /// `pass_direct`; pixels without a point are then squeezed out. Nothing is allocated per
    /// pixel, and the buffers keep their capacity from pass to pass. `false` when interrupted
    /// (the pass is then traced again, so the half-written buffers do not matter).
    pub(super) fn trace_stochastic_eye_pass(&mut self, scene: &Scene) -> bool {
        let (w, h) = (self.width as u64, self.height as u64);
        let pass = self.stream_pass();
        let (direct_light, seed) = (self.direct_light, self.seed);
        let sequences = self
            .stratified_eye_rays
            .then(|| (sequence::r4(pass)[0], sequence::golden(pass)));
        let interrupt = self.interrupt.as_deref();
        let skipped = std::sync::atomic::AtomicBool::new(false);
        let pixels = (w * h) as usize;
        // New points: the grid over the old ones no longer holds them.
        self.kept_grid = None;
        self.points.reset(pixels);
        self.pass_direct.clear();
        self.pass_direct.resize(pixels, Vec3::ZERO);
        let rays = scene.camera.eye_rays();
        let subsampler = seen::Subsampler {
            scene,
            rays: &rays,
            seed,
            pass,
            pixels: w * h,
            stratified: self.stratified_eye_rays,
            direct_light,
        };
        let seen = &self.seen;
        let VisiblePoints { reach, shade } = &mut self.points;
        reach
            .par_iter_mut()
            .zip(shade.par_iter_mut())
            .zip(self.pass_direct.par_iter_mut())
            .enumerate()
            .for_each(|(i, ((reach, shade), direct))| {
                if interrupt.is_some_and(|f| f()) {
                    skipped.store(true, std::sync::atomic::Ordering::Relaxed);
                    return;
                }
                let i = i as u64;
                let (x, y) = (i % w, i / w);
                let mut rng = stream_rng(seed, streams::EYE, pass * w * h + i);
                let (jitter, lens, first) = eye_sample(seed, pass, i, sequences, &mut rng);
                let px = DVec2::new(x as f64, y as f64) + jitter;
                let mut sink = |vp: VisiblePoint| {
                    debug_assert!(shade.slot == Shade::NONE, "a chosen path ends once");
                    (*reach, *shade) = points::split(&vp);
                };
                // A supersampled pixel's light seen comes from its extra rays alone, so its
                // own ray needs no shadow rays (they draw no random numbers: the point is the
                // same).
                let chosen = seen.chosen(i as usize);
                let seen_once = trace_eye(
                    scene,
                    &rays.ray_with_lens_sample(px, lens),
                    i as u32,
                    Branching::Choose { first },
                    direct_light && !chosen,
                    &mut rng,
                    &mut sink,
                );
                *direct = if chosen {
                    subsampler.light_seen(i, x, y, seen.subsamples(i as usize))
                } else {
                    seen_once
                }
                .as_vec3();
            });
        if skipped.into_inner() {
            return false;
        }
        if self.global.as_ref().is_none_or(global::Global::learning) {
            self.seen.observe(&self.pass_direct, w as usize);
        }
        self.points.drop_empty();
        true
    }

    /// Classic PPM's one eye pass: an eye ray through each pixel centre, split at glass, rows
    /// in parallel. Per pixel: the directly seen light; per visible point: the point, its
    /// `slot` holding its pixel. `None` when interrupted.
    pub(super) fn trace_classic_eye_pass(&self, scene: &Scene) -> Option<(Vec<DVec3>, Vec<VisiblePoint>)> {
        let (w, h) = (self.width as u64, self.height as u64);
        let pass = self.stream_pass();
        let (direct_light, seed) = (self.direct_light, self.seed);
        let interrupt = self.interrupt.as_deref();
        let skipped = std::sync::atomic::AtomicBool::new(false);
        let rays = scene.camera.eye_rays();
        let rows: Vec<(Vec<DVec3>, Vec<VisiblePoint>)> = (0..h)
            .into_par_iter()
            .map(|y| {
                let (mut direct, mut points) = (Vec::with_capacity(w as usize), Vec::new());
                if interrupt.is_some_and(|f| f()) {
                    skipped.store(true, std::sync::atomic::Ordering::Relaxed);
                    return (direct, points);
                }
                for x in 0..w {
                    let i = y * w + x;
                    let mut rng = stream_rng(seed, streams::EYE, pass * w * h + i);
                    let px = Scene::pixel_center(x as u32, y as u32);
                    direct.push(trace_eye(
                        scene,
                        &rays.ray(px, DVec2::ZERO),
                        i as u32,
                        Branching::Split,
                        direct_light,
                        &mut rng,
                        &mut |vp| points.push(vp),
                    ));
                }
                (direct, points)
            })
            .collect();
        if skipped.into_inner() {
            return None;
        }
        let mut direct = Vec::with_capacity((w * h) as usize);
        let mut points = Vec::new();
        for (d, p) in rows {
            direct.extend(d);
            points.extend(p);
        }
        Some((direct, points))
    }

    /// Traces the eye pass; `false` when interrupted (nothing the next pass needs changed then).
    pub(super) fn eye_pass(&mut self, scene: &Scene) -> bool {
        if self.stochastic {
            // A stochastic pass's directly seen light counts only when the pass completes.
            if !self.trace_stochastic_eye_pass(scene) {
                return false;
            }
            if self.slots.is_empty() {
                self.slots = (0..self.width * self.height).map(Slot::new).collect();
            }
        } else {
            // Classic PPM keeps its one eye pass at once: a slot per visible point.
            let Some((direct, points)) = self.trace_classic_eye_pass(scene) else {
                return false;
            };
            self.stats.eye_passes += 1;
            for (d, p) in self.direct.iter_mut().zip(direct) {
                *d += p;
            }
            self.kept_grid = None;
            self.points = points.into_iter().collect();
            for shade in &mut self.points.shade {
                let pixel = shade.slot;
                shade.slot = self.slots.len() as u32;
                self.slots.push(Slot::new(pixel));
            }
        }
        if self.stats.passes == 0 && self.slots.iter().all(|s| s.primary.radius2() == 0.0) {
            let r0 = self
                .initial_radius
                .unwrap_or_else(|| self.automatic_radius(scene));
            let indirect = self.indirect_scale.initial_radius(r0);
            let primary = self.first_pass_radius2(r0 * r0);
            for s in &mut self.slots {
                s.primary = Estimate::empty(primary);
                s.indirect = Estimate::empty(indirect * indirect);
            }
            self.initial_radius2 = r0 * r0;
        }
        if self.stats.passes == 0 && self.inherited.is_some() {
            self.stats.kept_share = self.keep_unmoved();
        }
        true
    }

    /// Adds one light sample of every area light at each visible point of this pass to the
    /// per-pixel sums (when direct light is on; see [`direct`]).
    pub(super) fn sample_area_lights(&mut self, scene: &Scene) {
        if !self.direct_light || !direct::has_area_lights(scene) {
            return;
        }
        let start = Instant::now();
        let (pass, seed) = (self.stream_pass(), self.seed);
        let shade = &self.points.shade;
        let key = |k: usize| shade[k].slot as u64;
        let (slots, stochastic) = (&self.slots, self.stochastic);
        let (pass_direct, area_direct) = (&mut self.pass_direct, &mut self.area_direct);
        direct::area_light_pass(scene, &self.points, key, pass, seed, |k, l| {
            let pixel = slots[shade[k].slot as usize].pixel as usize;
            if stochastic {
                pass_direct[pixel] += l.as_vec3();
            } else {
                area_direct[pixel] += l;
            }
        });
        self.stats.direct_secs += start.elapsed().as_secs_f64();
    }
}

/// Pixel `i`'s eye-ray numbers in pass `pass`: its place in the pixel, its place on the lens
/// and the number of its first choice at glass. With `sequences` (this pass's points of R4 over
/// the lens and of the golden-ratio sequence) they are the pass's points of the pixel's
/// sequences, shifted by the pixel's own offsets, the same every pass (their own stream, so
/// the path's other random numbers stay as they were); without, independent numbers from `rng`.
fn eye_sample(
    seed: u64,
    pass: u64,
    i: u64,
    sequences: Option<(DVec2, f64)>,
    rng: &mut Pcg64Mcg,
) -> (DVec2, DVec2, Option<f64>) {
    match sequences {
        Some((lens, choice)) => {
            let mut offsets = stream_rng(seed, streams::EYE_OFFSETS, i);
            let jitter = sequence::sobol(pass, offsets.random());
            let offset = DVec2::new(offsets.random(), offsets.random());
            let first = sequence::rotated_1d(choice, offsets.random());
            (jitter, sequence::rotated(lens, offset), Some(first))
        }
        None => (
            DVec2::new(rng.random(), rng.random()),
            DVec2::new(rng.random(), rng.random()),
            None,
        ),
    }
}
