//! The render's statistics slots — every visible point's two progressive estimates, in pixel
//! order — and what is done with all of them at once: a completed pass folded in with the
//! paper's update rule, each pixel's photon radiance read out, the slots a warm restart keeps.

use std::ops::Range;

use glam::DVec3;
use rayon::prelude::*;

use super::estimate::{mean_primary_radius, Estimate, Restart, Slot};
use super::gathered::Gathered;
use super::sweep::SWEEP_BLOCK;

/// The statistics slots of a render.
#[derive(Default)]
pub struct Estimates {
    /// One per visible point (classic PPM) or pixel (stochastic PPM), in pixel order.
    pub slots: Vec<Slot>,
    /// Photons emitted by the first pass (a restarted estimate does not count them).
    pub first_pass_photons: u64,
}

impl Estimates {
    /// Folds what a completed pass `gathered` into every slot: new photon counts, radii and
    /// flux (Hachisuka et al. 2008, eqs. 6–11) with `alpha`, slot by slot, [`SWEEP_BLOCK`] a
    /// task (memory-bound: 52-byte slots). A restart pending since the first pass happens
    /// now ([`Restart`]).
    pub fn fold(&mut self, gathered: &Gathered, alpha: f64) {
        self.slots
            .par_chunks_mut(SWEEP_BLOCK)
            .enumerate()
            .for_each(|(chunk, slots)| {
                for (k, s) in (chunk * SWEEP_BLOCK..).zip(slots) {
                    if s.restart == Restart::Pending {
                        // The first pass's flux only stood in until this pass: it was
                        // gathered over the wide radius.
                        s.primary = Estimate::empty(s.primary.radius2());
                        s.restart = Restart::Restarted;
                    }
                    s.primary.update(gathered.flux(k, 0), gathered.count(k, 0), alpha);
                    s.indirect
                        .update(gathered.flux(k, 1), gathered.count(k, 1), alpha);
                }
            });
    }

    /// The photons' radiance `τ/(π R² N_emitted)` of `slots` (one pixel's), summed in f64,
    /// after `emitted` photons (a restarted estimate counts those after the first pass only,
    /// a kept one its prior too).
    pub fn photon_radiance(&self, slots: &[Slot], emitted: u64) -> DVec3 {
        let restarted = (emitted - self.first_pass_photons) as f64;
        let emitted = emitted as f64;
        let mut c = DVec3::ZERO;
        if emitted > 0.0 {
            for s in slots {
                let primary = match s.restart {
                    Restart::Restarted => s.primary.radiance(restarted + s.prior as f64),
                    _ => s.primary.radiance(emitted + s.prior as f64),
                };
                c += primary + s.indirect.radiance(emitted + s.prior as f64);
            }
        }
        c
    }

    /// The mean primary radius for the statistics: over the slots that have gathered photons;
    /// while none has (this estimate holds caustics only when direct light is sampled, and a
    /// scene may have none), over every slot with a radius: the radius in use, not 0.
    pub fn mean_radius(&self) -> f64 {
        mean_primary_radius(&self.slots, |s| s.primary.n() > 0.0)
            .or_else(|| mean_primary_radius(&self.slots, Slot::has_radius))
            .unwrap_or(0.0)
    }

    /// Each of the first `pixels` pixels' slots in turn (empty for a pixel without any).
    pub fn by_pixel(&self, pixels: usize) -> impl Iterator<Item = &[Slot]> + '_ {
        debug_assert!(
            self.slots.is_sorted_by_key(|s| s.pixel),
            "slots lie in pixel order"
        );
        slots_by_pixel(&self.slots, 0..pixels)
    }

    /// The slots as a warm restart keeps them after `emitted` photons: both estimates brought
    /// to one count of photons (the indirect one's), which each holds as its prior.
    pub fn kept(&self, emitted: u64) -> Vec<Slot> {
        let restarted = (emitted - self.first_pass_photons) as f64;
        let emitted = emitted as f64;
        self.slots
            .par_iter()
            .with_min_len(4096)
            .map(|s| {
                let all = emitted + s.prior as f64;
                let primary = match s.restart {
                    Restart::Restarted => restarted + s.prior as f64,
                    _ => all,
                };
                let mut kept = *s;
                kept.primary.scale_tau(DVec3::splat(all / primary.max(1.0)));
                kept.prior = all as f32;
                kept.restart = Restart::None;
                kept
            })
            .collect()
    }
}

/// The slots of each pixel of `pixels` in turn (empty for a pixel without any), from `slots`
/// in pixel order starting at the first of those pixels.
pub fn slots_by_pixel(slots: &[Slot], pixels: Range<usize>) -> impl Iterator<Item = &[Slot]> + '_ {
    let mut runs = slots.chunk_by(|a, b| a.pixel == b.pixel).peekable();
    pixels.map(move |i| runs.next_if(|run| run[0].pixel as usize == i).unwrap_or(&[]))
}
