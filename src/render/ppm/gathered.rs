//! What one pass's photons handed the statistics slots ([`Gathered`]), before the update
//! folds it in.

use glam::{DVec3, Vec3};
use rayon::prelude::*;

use super::guide::GuideTally;
use super::photon::PhotonCounts;

/// What one pass's photons left: flux `Φ` and photon count `M` per slot and estimate (0
/// primary, 1 indirect; only the primary when the indirect estimate is off, which halves
/// them), and counts. A pass's flux is summed in f32 (12 bytes instead of 24 per estimate);
/// τ accumulates the passes.
pub struct Gathered {
    phi: Vec<Vec3>,
    m: Vec<u32>,
    /// Estimates per slot held: 2, or 1 when the indirect estimate is off.
    estimates: usize,
    pub(super) counts: PhotonCounts,
    /// Emitted and useful photons per light and bin, when emission is guided.
    pub(super) tally: Option<GuideTally>,
}

impl Gathered {
    /// Nothing gathered yet by `slots` slots of `estimates` estimates each.
    pub(super) fn new(slots: usize, estimates: usize, tally: Option<GuideTally>) -> Self {
        Self {
            // Filled in parallel: `vec!` writes a non-primitive zero one element at a time.
            phi: (0..estimates * slots)
                .into_par_iter()
                .map(|_| Vec3::ZERO)
                .collect(),
            m: vec![0; estimates * slots],
            estimates,
            counts: PhotonCounts::default(),
            tally,
        }
    }

    /// Where slot `slot`'s estimate `estimate` is held when each slot has `estimates`.
    #[inline]
    pub(super) fn at(estimates: usize, slot: u32, estimate: usize) -> u32 {
        slot * estimates as u32 + estimate as u32
    }

    /// Adds `count` photons of flux `flux` to the estimate held at `at` ([`Gathered::at`]).
    pub(super) fn add(&mut self, at: u32, flux: Vec3, count: u32) {
        self.phi[at as usize] += flux;
        self.m[at as usize] += count;
        self.counts.deposits += count as u64;
    }

    /// The flux slot `k`'s estimate `estimate` gathered.
    pub(super) fn flux(&self, k: usize, estimate: usize) -> DVec3 {
        if estimate < self.estimates {
            self.phi[k * self.estimates + estimate].as_dvec3()
        } else {
            DVec3::ZERO
        }
    }

    /// The photons slot `k`'s estimate `estimate` gathered.
    pub(super) fn count(&self, k: usize, estimate: usize) -> u32 {
        if estimate < self.estimates {
            self.m[k * self.estimates + estimate]
        } else {
            0
        }
    }

    /// The indirect estimates' photon counts, slot by slot (none when it is off).
    pub(super) fn indirect_counts(&self) -> impl Iterator<Item = u32> + '_ {
        let both: &[u32] = if self.estimates == 2 { &self.m } else { &[] };
        both.iter().skip(1).step_by(2).copied()
    }
}
