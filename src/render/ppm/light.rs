//! The light each pixel sees directly, beside the photons' estimate: emission seen directly or
//! through mirrors and glass, point lights by shadow ray at the visible points (both from the
//! eye pass), and area lights sampled at the visible points ([`super::direct`]), each summed
//! over the passes that count it; supersampled where it changes within a pixel
//! ([`super::seen`]); and what a warm restart kept of it ([`PriorLight`]).

use glam::{DVec3, Vec3};
use rayon::prelude::*;

use super::config::Config;
use super::direct;
use super::estimate::Slot;
use super::points::VisiblePoints;
use super::seen::SeenLight;
use crate::scene::Scene;
use crate::settings::RadiusSchedule;

/// A pixel's light seen directly, kept by a warm restart: sums over as many earlier eye passes
/// (emission and point lights) and passes (area lights), added to the epoch's own.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PriorLight {
    /// Emission and point lights, summed over `direct_passes` eye passes.
    pub direct: DVec3,
    /// The eye passes `direct` sums.
    pub direct_passes: f64,
    /// Area lights, summed over `area_passes` passes.
    pub area: DVec3,
    /// The passes `area` sums.
    pub area_passes: f64,
}

impl PriorLight {
    /// The same means, counted as at most `passes` passes, scaled by `factor`.
    pub fn capped(self, passes: f64, factor: DVec3) -> Self {
        let d = self.direct_passes.min(passes);
        let a = self.area_passes.min(passes);
        Self {
            direct: self.direct / self.direct_passes.max(1.0) * d * factor,
            direct_passes: d,
            area: self.area / self.area_passes.max(1.0) * a * factor,
            area_passes: a,
        }
    }
}

/// Per pixel, the light seen directly over the passes so far.
pub struct LightSeen {
    /// Emission and point lights, summed over completed eye passes.
    direct: Vec<DVec3>,
    /// This stochastic pass's directly seen light, added to `direct` when the pass completes
    /// (f32: one pass's value, summed in f64).
    pass_direct: Vec<Vec3>,
    /// Area light sampled at the visible points, summed over completed passes (empty unless
    /// direct light is on, the scene has area lights and the eye pass is classic: a
    /// stochastic pass adds its samples to `pass_direct`, which counts the same passes; at
    /// 1920×1080 that is 48 MiB less).
    area_direct: Vec<DVec3>,
    /// What a warm restart kept (empty when cold).
    prior: Vec<PriorLight>,
    /// Which pixels' light seen is supersampled, learned from completed stochastic passes.
    seen: SeenLight,
    /// Each pixel whose light seen started again (at its first supersampled pass), with the
    /// photons emitted before that pass, in the order they started.
    restarts: Vec<(u32, u64)>,
}

impl LightSeen {
    /// Nothing seen yet, for a render of `scene` with `config`.
    pub fn new(scene: &Scene, config: &Config) -> Self {
        let pixels = config.pixels();
        let stochastic = config.stochastic;
        Self {
            direct: vec![DVec3::ZERO; pixels],
            pass_direct: Vec::new(),
            area_direct: if config.direct_light && direct::has_area_lights(scene) && !stochastic {
                vec![DVec3::ZERO; pixels]
            } else {
                Vec::new()
            },
            prior: Vec::new(),
            // On the global schedule every pass depends on (seed, pass) alone: its choices are
            // the pilot's one pass, too few for a variance.
            seen: if stochastic && scene.params.supersample_light_seen {
                SeenLight::new(pixels, scene.params.radius_schedule != RadiusSchedule::Global)
            } else {
                SeenLight::default()
            },
            restarts: Vec::new(),
        }
    }

    /// Pixels in the image.
    pub fn pixels(&self) -> usize {
        self.direct.len()
    }

    /// Pixel `i`'s mean light seen directly after `eye_passes` eye passes and `passes` passes
    /// (emission, and lights sampled at its visible points), with what a warm restart kept of
    /// it counted as earlier passes.
    pub fn pixel(&self, i: usize, eye_passes: u32, passes: u32) -> DVec3 {
        let prior = self.prior.get(i).copied().unwrap_or_default();
        let eye = self.seen.passes(i, eye_passes) as f64 + prior.direct_passes;
        let passes = passes as f64 + prior.area_passes;
        let mut light = (self.direct[i] + prior.direct) / eye.max(1.0);
        if let Some(a) = self.area_direct.get(i) {
            light += (*a + prior.area) / passes.max(1.0);
        }
        light
    }

    /// Before a stochastic eye pass: which pixels are supersampled, and this pass's light seen
    /// per pixel, zeroed (keeping its memory) for the pass to write.
    pub fn start_stochastic_pass(&mut self) -> (&SeenLight, &mut [Vec3]) {
        self.pass_direct.clear();
        self.pass_direct.resize(self.direct.len(), Vec3::ZERO);
        (&self.seen, &mut self.pass_direct)
    }

    /// This stochastic pass's light seen per pixel so far (its eye pass's, and its area-light
    /// samples once taken).
    pub fn pass_light(&self) -> &[Vec3] {
        &self.pass_direct
    }

    /// This stochastic pass's light seen per pixel, to add to.
    pub fn pass_light_mut(&mut self) -> &mut [Vec3] {
        &mut self.pass_direct
    }

    /// After a complete stochastic eye pass of a `width`-pixel-wide image: the candidates for
    /// supersampling, from the light it saw ([`SeenLight::observe`]).
    pub fn observe(&mut self, width: usize) {
        self.seen.observe(&self.pass_direct, width);
    }

    /// Adds classic PPM's one eye pass's light seen per pixel.
    pub fn add_eye_pass(&mut self, direct: Vec<DVec3>) {
        for (d, p) in self.direct.iter_mut().zip(direct) {
            *d += p;
        }
    }

    /// A completed stochastic pass, the `eye_passes`th, before which `photons` photons were
    /// emitted: its light seen joins the sums (after the sums of the pixels it supersampled for
    /// the first time are emptied, [`super::seen`]; they are [`LightSeen::restarts`]) and the
    /// next pixels to supersample are chosen. Returns the share of the pixels supersampled.
    pub fn complete_stochastic_pass(&mut self, eye_passes: u32, photons: u64) -> f64 {
        for i in self.forget_before_supersampling() {
            self.restarts.push((i, photons));
        }
        self.seen.tally(&self.pass_direct);
        for (d, p) in self.direct.iter_mut().zip(self.pass_direct.drain(..)) {
            *d += p.as_dvec3();
        }
        self.seen.choose(eye_passes);
        self.seen.choose_by_variance(&self.direct, eye_passes);
        self.seen.count() as f64 / self.direct.len().max(1) as f64
    }

    /// Each pixel whose light seen started again, at its first supersampled pass, with the
    /// photons emitted before that pass: its light seen counts only that pass and those since.
    pub fn restarts(&self) -> &[(u32, u64)] {
        &self.restarts
    }

    /// Empties the light seen so far of the pixels chosen to be supersampled before this pass,
    /// their first supersampled one, and of what a warm restart kept for them ([`super::seen`]);
    /// returns those pixels.
    fn forget_before_supersampling(&mut self) -> Vec<u32> {
        let pending = self.seen.take_pending();
        for &i in &pending {
            self.direct[i as usize] = DVec3::ZERO;
            if let Some(prior) = self.prior.get_mut(i as usize) {
                prior.direct = DVec3::ZERO;
                prior.direct_passes = 0.0;
            }
        }
        pending
    }

    /// Adds one light sample of every area light at each of `points` (their slots among
    /// `slots`) in pass `pass` to the per-pixel sums: to this pass's light seen when
    /// `stochastic`, to the area lights' sums otherwise ([`direct::area_light_pass`]).
    pub fn sample_area_lights(
        &mut self,
        scene: &Scene,
        (points, slots): (&VisiblePoints, &[Slot]),
        (pass, seed): (u64, u64),
        (stochastic, skip): (bool, Option<&(dyn Fn(usize) -> bool + Sync)>),
    ) {
        let shade = &points.shade;
        let key = |k: usize| shade[k].slot as u64;
        let (pass_direct, area_direct) = (&mut self.pass_direct, &mut self.area_direct);
        direct::area_light_pass(scene, points, key, (pass, seed), skip, |k, l| {
            // No light adds nothing: the points in shadow and those skipped cost no look-up
            // of their pixel (the points lie in the spatial index's order).
            if l == DVec3::ZERO {
                return;
            }
            let pixel = slots[shade[k].slot as usize].pixel as usize;
            if stochastic {
                pass_direct[pixel] += l.as_vec3();
            } else {
                area_direct[pixel] += l;
            }
        });
    }

    /// Forgets the area lights' sums (each pass of the global schedule stands alone).
    pub fn clear_area(&mut self) {
        self.area_direct.iter_mut().for_each(|a| *a = DVec3::ZERO);
    }

    /// Pixel `i`'s light seen in this pass alone, on the global schedule: this pass's eye
    /// pass when `stochastic`, or classic PPM's one eye pass over its `eye_passes`; plus the
    /// area lights' samples.
    pub fn pass_value(&self, i: usize, stochastic: bool, eye_passes: u32) -> DVec3 {
        let seen = if stochastic {
            self.pass_direct[i].as_dvec3()
        } else {
            self.direct[i] / eye_passes.max(1) as f64
        };
        seen + self.area_direct.get(i).copied().unwrap_or_default()
    }

    /// Per pixel, the sums a warm restart keeps after `eye_passes` eye passes and `passes`
    /// passes (with what this epoch inherited).
    pub fn kept(&self, eye_passes: u32, passes: u32) -> Vec<PriorLight> {
        (0..self.direct.len())
            .into_par_iter()
            .with_min_len(4096)
            .map(|i| {
                let prior = self.prior.get(i).copied().unwrap_or_default();
                PriorLight {
                    direct: self.direct[i] + prior.direct,
                    direct_passes: self.seen.passes(i, eye_passes) as f64 + prior.direct_passes,
                    area: self.area_direct.get(i).copied().unwrap_or_default() + prior.area,
                    area_passes: passes as f64 + prior.area_passes,
                }
            })
            .collect()
    }

    /// What a warm restart kept, per pixel.
    pub fn set_prior(&mut self, prior: Vec<PriorLight>) {
        self.prior = prior;
    }
}
