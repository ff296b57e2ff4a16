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

use glam::DVec3;

use super::estimate::{Estimate, Restart, Slot};
use super::gathered::Gathered;
use super::radius::{IndirectScale, RadiusPolicy};
use crate::render::shard::{PassSet, PassSums};

/// `r_{i+1}² / r_1²` for pass `i` (0-based) of the global schedule with `alpha`:
/// `Π_{k=1}^{i} (k + α)/(k + 1)`, multiplied in order (the same bits on every machine).
pub fn schedule_factor(pass: u64, alpha: f64) -> f64 {
    (1..=pass).fold(1.0, |f, k| f * (k as f64 + alpha) / (k as f64 + 1.0))
}

/// The global schedule's state in a render.
pub struct Global {
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
    pub sums: PassSums,
}

impl Global {
    /// Before the pilot pass, for every pass of a `width`×`height` render with `alpha`.
    pub fn new(alpha: f64, width: u32, height: u32) -> Self {
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
    pub fn learning(&self) -> bool {
        self.pilot.is_none()
    }

    /// The pass index of the eye pass's and light samples' streams.
    pub fn stream_pass(&self) -> u64 {
        self.stream
    }

    /// The stream index of the pass's first photon.
    pub fn first_photon(&self) -> u64 {
        self.stream << 32
    }
}

impl Global {
    /// Renders only `passes` of the render (a shard's, or a part's own list), in order.
    pub fn render_only(&mut self, passes: PassSet) {
        self.passes = passes;
    }

    /// Starts the next pass of this process's shard: moves the streams to it and returns
    /// its index in the render.
    pub fn next_pass(&mut self) -> u64 {
        let pass = self.passes.pass(self.done);
        self.stream = pass + 1;
        pass
    }

    /// Every slot's estimates emptied and set to pass `pass`'s radii, `r_1² ·`
    /// [`schedule_factor`] (nothing before the pilot).
    pub fn schedule_radii(&self, pass: u64, slots: &mut [Slot]) {
        let Some(pilot) = &self.pilot else {
            return;
        };
        let factor = schedule_factor(pass, self.alpha);
        for (s, &(primary, indirect)) in slots.iter_mut().zip(pilot) {
            s.primary = Estimate::empty(primary * factor);
            s.indirect = Estimate::empty(indirect * factor);
        }
    }

    /// Adds pass `pass`'s estimate of `emitted` photons — the flux each of `slots` gathered
    /// over `π r² N_emitted`, plus the light the pass saw directly — to the sums; each slot's
    /// count becomes this pass's photons (what the probe and the photons layer show: nothing
    /// accumulates from pass to pass).
    pub fn add_pass(
        &mut self,
        pass: u64,
        slots: &mut [Slot],
        gathered: &Gathered,
        seen: impl Fn(usize) -> DVec3,
        emitted: u64,
    ) {
        let (width, height) = self.sums.size();
        let values = pass_values(slots, gathered, seen, emitted, width as usize * height as usize);
        for (k, s) in slots.iter_mut().enumerate() {
            s.primary.set_n(gathered.count(k, 0) as f64);
            s.indirect.set_n(gathered.count(k, 1) as f64);
        }
        self.sums.add_pass(pass as u32, &values, emitted);
        self.done += 1;
    }

    /// After the pilot pass: each slot's `r_1` (the initial radius, narrowed where the pilot
    /// found photons dense; the indirect estimate's chosen scale, from `radius`); the slots'
    /// restarts are forgotten.
    pub fn finish_pilot(&mut self, slots: &mut [Slot], radius: &RadiusPolicy) {
        let r0_2 = radius.initial_radius2;
        let indirect = match radius.indirect_scale {
            IndirectScale::Fixed(k) => r0_2 * k * k,
            _ => 0.0,
        };
        let pilot: Vec<(f64, f64)> = slots
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
        for s in slots {
            s.restart = Restart::None;
        }
        self.pilot = Some(pilot);
    }
}

/// A pass's estimate per pixel (of `pixels`): the flux each slot's estimates gathered over
/// `π r² N_emitted`, plus `seen(pixel)`, the light the pass saw directly.
fn pass_values(
    slots: &[Slot],
    gathered: &Gathered,
    seen: impl Fn(usize) -> DVec3,
    emitted: u64,
    pixels: usize,
) -> Vec<DVec3> {
    let emitted = emitted as f64;
    let mut values = vec![DVec3::ZERO; pixels];
    for (k, s) in slots.iter().enumerate() {
        let primary = Estimate::new(s.primary.radius2(), 0.0, gathered.flux(k, 0));
        let indirect = Estimate::new(s.indirect.radius2(), 0.0, gathered.flux(k, 1));
        values[s.pixel as usize] += primary.radiance(emitted) + indirect.radiance(emitted);
    }
    for (i, v) in values.iter_mut().enumerate() {
        *v += seen(i);
    }
    values
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
