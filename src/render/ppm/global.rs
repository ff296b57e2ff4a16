//! The global radius schedule (Knaus & Zwicker 2011, "Progressive photon mapping: a
//! probabilistic approach", §4): pass `i` (0-based) gathers photons at the radius
//! `r_{i+1}² = r_1² · Π_{k=1}^{i} (k + α)/(k + 1)` — the paper's `r²_{i+1} = r²_i (i + α)/(i + 1)` —
//! and its estimate `Φ/(π r² N_emitted)` stands alone: no photon count or flux carries to
//! the next pass. The image is the mean of the passes, whose variance falls and whose bias
//! shrinks with the radius as per-point PPM's do; since the passes are independent, they can be
//! rendered in any order on any machine ([`crate::render::shard`]).
//!
//! What per-point PPM learns from earlier passes is fixed here by a **pilot pass** that every
//! process repeats identically (it depends only on the scene and its seed): the initial radius,
//! each pixel's (or point's) automatic indirect radius and adaptive narrowing — its `r_1` —
//! and the emission guide, which learns from the pilot only and then stays as it is. The pilot
//! is not one of the image's passes. Pass `i` uses the eye-pass and light-sample streams of
//! pass `i + 1` and the photon streams from `(i + 1)·2³²` (a pass holds fewer than 2³²
//! photons), so its numbers depend on `(seed, i)` alone.

use std::time::Instant;

use glam::DVec3;

use super::estimate::{mean_primary_radius, Slot};
use super::gathered::Gathered;
use super::radius::IndirectScale;
use super::{Control, Estimate, PassOutcome, Ppm, Restart};
use crate::render::shard::{PassSet, PassSums};
use crate::scene::Scene;

/// `r_{i+1}² / r_1²` for pass `i` (0-based) of the global schedule with `alpha`:
/// `Π_{k=1}^{i} (k + α)/(k + 1)`, multiplied in order (the same bits on every machine).
pub fn schedule_factor(pass: u64, alpha: f64) -> f64 {
    (1..=pass).fold(1.0, |f, k| f * (k as f64 + alpha) / (k as f64 + 1.0))
}

/// The global schedule's state in a [`Ppm`].
pub(super) struct Global {
    passes: PassSet,
    /// α, fixed for the render.
    alpha: f64,
    /// Per slot, the pilot's radii² `r_1²` (primary, indirect); `None` before the pilot.
    pilot: Option<Vec<(f64, f64)>>,
    /// Its passes completed.
    done: u32,
    /// The stream position: 0 for the pilot, `i + 1` for pass `i`.
    stream: u64,
    /// The passes' exact sums.
    pub(super) sums: PassSums,
}

impl Global {
    /// Before the pilot pass, for every pass of a `width`×`height` render with `alpha`.
    pub(super) fn new(alpha: f64, width: u32, height: u32) -> Self {
        Self {
            passes: PassSet::default(),
            alpha,
            pilot: None,
            done: 0,
            stream: 0,
            sums: PassSums::new(width, height),
        }
    }

    /// Whether the pilot pass is still to complete: what per-point PPM learns from its passes
    /// is learned from the pilot only.
    pub(super) fn learning(&self) -> bool {
        self.pilot.is_none()
    }

    /// The pass index of the eye pass's and light samples' streams.
    pub(super) fn stream_pass(&self) -> u64 {
        self.stream
    }

    /// The stream index of the pass's first photon.
    pub(super) fn first_photon(&self) -> u64 {
        self.stream << 32
    }
}

impl Ppm {
    /// With the global radius schedule, renders only `passes` of the render (a shard's, or a
    /// part's own list), in order, instead of every pass; nothing otherwise.
    pub fn render_only(&mut self, passes: PassSet) {
        if let Some(g) = &mut self.global {
            g.passes = passes;
        }
    }

    /// The next pass of this process's shard: the pilot first (once), then the pass's own eye
    /// pass, photons at the scheduled radii and its estimate added to the sums.
    pub(super) fn run_global_pass(
        &mut self,
        scene: &Scene,
        control: &mut dyn FnMut(&mut f64) -> Control,
    ) -> PassOutcome {
        if self.global.as_ref().is_some_and(|g| g.pilot.is_none()) {
            // Stream position 0 until the pilot completes.
            if self.run_statistics_pass(scene, control) == PassOutcome::Aborted {
                return PassOutcome::Aborted;
            }
            self.finish_pilot();
        }
        let start = Instant::now();
        let Some(g) = &mut self.global else {
            return PassOutcome::Aborted;
        };
        let pass = g.passes.pass(g.done);
        g.stream = pass + 1;
        if self.interrupted() || (self.stochastic && !self.trace_stochastic_eye_pass(scene)) {
            return PassOutcome::Aborted;
        }
        self.schedule_radii(pass);
        self.stats.eye_secs += start.elapsed().as_secs_f64();
        let Some(gathered) = self.gather(scene, control) else {
            return PassOutcome::Aborted;
        };
        self.area_direct.iter_mut().for_each(|a| *a = DVec3::ZERO);
        self.sample_area_lights(scene);
        let values = self.pass_values(&gathered);
        // Each estimate's count is this pass's photons (what the probe and the photons layer
        // show: nothing accumulates from pass to pass).
        for (k, s) in self.slots.iter_mut().enumerate() {
            s.primary.set_n(gathered.count(k, 0) as f64);
            s.indirect.set_n(gathered.count(k, 1) as f64);
        }
        if let Some(g) = &mut self.global {
            g.sums.add_pass(pass as u32, &values, self.pass_photons);
            g.done += 1;
        }
        self.count_pass(gathered.counts);
        self.stats.elapsed_secs += start.elapsed().as_secs_f64();
        PassOutcome::Completed
    }

    /// Every slot's estimates emptied and set to pass `pass`'s radii, `r_1² ·` [`schedule_factor`].
    fn schedule_radii(&mut self, pass: u64) {
        let Some((g, pilot)) = self.global.as_ref().and_then(|g| Some((g, g.pilot.as_ref()?))) else {
            return;
        };
        let factor = schedule_factor(pass, g.alpha);
        for (s, &(primary, indirect)) in self.slots.iter_mut().zip(pilot) {
            s.primary = Estimate::empty(primary * factor);
            s.indirect = Estimate::empty(indirect * factor);
        }
    }

    /// This pass's estimate per pixel: the flux `phi` each slot's estimates gathered over
    /// `π r² N_emitted`, plus the light the pass saw directly.
    fn pass_values(&self, gathered: &Gathered) -> Vec<DVec3> {
        let emitted = self.pass_photons as f64;
        let mut values = vec![DVec3::ZERO; self.direct.len()];
        for (k, s) in self.slots.iter().enumerate() {
            let primary = Estimate::new(s.primary.radius2(), 0.0, gathered.flux(k, 0));
            let indirect = Estimate::new(s.indirect.radius2(), 0.0, gathered.flux(k, 1));
            values[s.pixel as usize] += primary.radiance(emitted) + indirect.radiance(emitted);
        }
        // Light seen directly: this pass's eye pass, or classic PPM's one eye pass (the pilot's).
        let eye_passes = self.stats.eye_passes.max(1) as f64;
        for (i, v) in values.iter_mut().enumerate() {
            let seen = if self.stochastic {
                self.pass_direct[i].as_dvec3()
            } else {
                self.direct[i] / eye_passes
            };
            *v += seen + self.area_direct.get(i).copied().unwrap_or_default();
        }
        values
    }

    /// A completed pass in the statistics.
    fn count_pass(&mut self, counts: super::photon::PhotonCounts) {
        let s = &mut self.stats;
        s.passes += 1;
        if self.stochastic {
            s.eye_passes += 1;
        }
        s.photons += self.pass_photons;
        s.bounces += counts.bounces;
        s.deposits += counts.deposits;
        s.useful_paths += counts.useful;
        s.visible_points = self.points.len();
        s.mean_radius = mean_primary_radius(&self.slots, Slot::has_radius).unwrap_or(0.0);
    }

    /// After the pilot pass: each slot's `r_1` (the initial radius, narrowed where the pilot
    /// found photons dense; the indirect estimate's chosen scale); the statistics start again
    /// at pass 0 (the pilot's time stays in the elapsed time; classic PPM keeps its one eye
    /// pass and the light it saw directly).
    fn finish_pilot(&mut self) {
        let r0_2 = self.initial_radius2;
        let indirect = match self.indirect_scale {
            IndirectScale::Fixed(k) => r0_2 * k * k,
            _ => 0.0,
        };
        let pilot: Vec<(f64, f64)> = self
            .slots
            .iter()
            .map(|s| {
                let primary = if s.restart == Restart::Pending {
                    s.primary.radius2()
                } else {
                    r0_2
                };
                (primary, indirect)
            })
            .collect();
        for s in &mut self.slots {
            s.restart = Restart::None;
        }
        if let Some(g) = &mut self.global {
            g.pilot = Some(pilot);
        }
        let s = &mut self.stats;
        s.passes = 0;
        s.photons = 0;
        s.bounces = 0;
        s.deposits = 0;
        s.useful_paths = 0;
        if self.stochastic {
            s.eye_passes = 0;
        }
        s.skipped.push(
            "per-point statistics: every pass is an independent estimate (global radius schedule)".into(),
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_schedule_follows_the_recurrence() {
        let alpha = 0.7;
        let mut r2 = 1.0;
        for i in 1..50u64 {
            // r²_{i+1} = r²_i (i + α)/(i + 1), with pass i (0-based) at r_{i+1}.
            r2 *= (i as f64 + alpha) / (i as f64 + 1.0);
            assert!((schedule_factor(i, alpha) - r2).abs() < 1e-15);
        }
        assert_eq!(schedule_factor(0, alpha), 1.0);
        assert_eq!(schedule_factor(10, 1.0), 1.0, "α = 1 keeps the radius");
    }
}
