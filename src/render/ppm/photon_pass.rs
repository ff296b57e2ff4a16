//! The photon pass: photons traced in fixed chunks in parallel, their deposits reduced in
//! chunk order (so the image is the same for any thread count), batch by batch with the
//! caller asked between batches.

use glam::Vec3;
use rayon::prelude::*;

use super::gathered::Gathered;
use super::guide::{EmissionGuide, GuideTally};
use super::photon::{PhotonCounts, PhotonSource};

use super::radius::IndirectScale;
use super::{streams, Control, Ppm, SpatialIndex};
use crate::render::rng::stream_rng;
use crate::scene::Scene;

/// Photons per chunk: the unit of parallel work and of deterministic reduction.
pub(super) const CHUNK: u64 = 4096;

/// Photons per batch unless [`PpmOptions::batch_photons`] says otherwise: the caller's
/// control callback is asked between batches.
pub const DEFAULT_BATCH_PHOTONS: u64 = 16 * CHUNK;

/// Deposits one chunk may hold before they are merged per slot: bounds memory when radii are
/// large (every photon then reaches thousands of points).
pub(super) const MAX_CHUNK_DEPOSITS: usize = 1 << 20;

/// Flux handed to a statistics slot: `(slot, flux × point weight, photon count)`, the flux
/// in f32 as the pass sums it (20 bytes a deposit, not 32).
pub(super) type Deposit = (u32, Vec3, u32);

/// What one chunk of photons left: its deposits, counts and guide tally.
pub(super) type ChunkResult = (Vec<Deposit>, PhotonCounts, Option<GuideTally>);

/// Merges deposits to the same slot, keeping each slot's additions in photon order (a stable
/// sort), so the sums depend only on the chunk's photons, not on threads.
pub(super) fn compact(deposits: &mut Vec<Deposit>) {
    deposits.sort_by_key(|d| d.0);
    let mut merged: Vec<Deposit> = Vec::with_capacity(deposits.len() / 4);
    for &(slot, flux, count) in deposits.iter() {
        match merged.last_mut() {
            Some(last) if last.0 == slot => {
                last.1 += flux;
                last.2 += count;
            }
            _ => merged.push((slot, flux, count)),
        }
    }
    *deposits = merged;
}

impl Ppm {
    /// Traces this pass's photons in batches and gathers their flux at the visible points;
    /// `None` when `control` aborts the pass.
    pub(super) fn photon_pass(
        &mut self,
        scene: &Scene,
        index: &SpatialIndex,
        control: &mut dyn FnMut(&mut f64) -> Control,
    ) -> Option<Gathered> {
        let source = PhotonSource::new(scene, self.direct_light).with_guide(self.guide.as_ref());
        let estimates = self.estimates();
        let mut out = Gathered::new(
            self.slots.len(),
            estimates,
            self.guide.as_ref().map(EmissionGuide::tally),
        );
        // Each estimate's largest radius: how far from a photon its points are looked for.
        let radius = [0, 1].map(|e| {
            let max2 = self
                .points
                .reach
                .iter()
                .map(|r| r.radius2[e])
                .fold(0.0f32, f32::max);
            (max2 as f64).sqrt()
        });
        self.pass_photons = self.guided_pass_photons();
        let chunks = self.pass_photons.div_ceil(CHUNK);
        let chunks_per_batch = self.options.batch_photons.div_ceil(CHUNK).max(1);
        let mut chunk = 0;
        while chunk < chunks {
            if control(&mut self.alpha) == Control::Abort {
                return None;
            }
            let end = (chunk + chunks_per_batch).min(chunks);
            let results: Vec<ChunkResult> = (chunk..end)
                .into_par_iter()
                .map(|c| self.trace_chunk(c, &source, index, radius))
                .collect();
            // Fold in chunk order: the same sums whatever the thread count.
            for (deposits, c, tally) in results {
                if let (Some(all), Some(t)) = (&mut out.tally, &tally) {
                    all.add(t);
                }
                for (at, flux, count) in deposits {
                    out.add(at, flux, count);
                }
                out.counts.paths += c.paths;
                out.counts.bounces += c.bounces;
                out.counts.useful += c.useful;
            }
            chunk = end;
        }
        Some(out)
    }

    /// Estimates each slot gathers into this pass: 2, or 1 when the indirect one is off.
    fn estimates(&self) -> usize {
        if self.indirect_scale == IndirectScale::Off {
            1
        } else {
            2
        }
    }

    /// This pass's photons: `photons_per_pass` divided by the guide's gain (as many useful
    /// photons, fewer lost ones; see [`guide`]), but not below one chunk (or all of them).
    pub(super) fn guided_pass_photons(&self) -> u64 {
        match &self.guide {
            Some(g) => {
                let reduced = (self.photons_per_pass as f64 / g.gain()).ceil() as u64;
                reduced.max(self.photons_per_pass.min(CHUNK))
            }
            None => self.photons_per_pass,
        }
    }

    /// Traces photon chunk `c` of this pass: the deposits it makes and its counts.
    pub(super) fn trace_chunk(
        &self,
        c: u64,
        source: &PhotonSource,
        index: &SpatialIndex,
        radius: [f64; 2],
    ) -> ChunkResult {
        let mut deposits: Vec<Deposit> = Vec::new();
        let mut counts = PhotonCounts::default();
        let mut tally = self.guide.as_ref().map(EmissionGuide::tally);
        let (photons, first_photon) = (self.pass_photons, self.first_photon());
        let (reach, shade) = (&self.points.reach, &self.points.shade);
        let estimates = self.estimates();
        let split = estimates == 2;
        for i in c * CHUNK..((c + 1) * CHUNK).min(photons) {
            let mut rng = stream_rng(self.seed, streams::PHOTON, first_photon + i);
            let mut useful = false;
            let from = source.trace(&mut rng, &mut counts, &mut |p, n, flux, indirect| {
                // Hand the flux to every visible point on this side of the surface whose
                // search sphere (of the photon's estimate) holds the photon.
                let estimate = usize::from(indirect && split);
                index.for_candidates(reach, p, radius[estimate], &mut |k| {
                    let r = &reach[k as usize];
                    if (r.position - p).length_squared() <= r.radius2[estimate] as f64 {
                        let s = &shade[k as usize];
                        if s.normal.as_dvec3().dot(n) > 1e-3 {
                            deposits.push((
                                Gathered::at(estimates, s.slot, estimate),
                                (s.weight.as_dvec3() * flux).as_vec3(),
                                1,
                            ));
                            useful = true;
                        }
                    }
                });
            });
            counts.useful += useful as u64;
            if let Some(t) = &mut tally {
                t.record(from.light, from.bin, useful);
            }
            if deposits.len() > MAX_CHUNK_DEPOSITS {
                compact(&mut deposits);
            }
        }
        (deposits, counts, tally)
    }
}
