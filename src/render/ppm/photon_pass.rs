//! The photon pass: photons traced in fixed chunks in parallel, batch by batch with the
//! caller asked between batches; where they meet diffuse surfaces is handed to the visible
//! points a window of many batches at a time, in the order of the grid's cells
//! ([`deposit`](super::deposit)), and reduced in that order (so the image is the same for
//! any thread count).

use rayon::prelude::*;

use super::deposit::{Gather, Hit, Window, WINDOW_PHOTONS};
use super::gathered::Gathered;
use super::guide::{EmissionGuide, GAIN_DIVIDED_PASSES};
use super::photon::{Emitted, PhotonCounts, PhotonSource};

use super::radius::IndirectScale;
use super::{streams, Control, Ppm, SpatialIndex};
use crate::render::rng::stream_rng;
use crate::scene::Scene;

/// Photons per chunk: the unit of parallel tracing (their hits are reduced in groups of the
/// sorted window, [`deposit`](super::deposit)). A batch ends when its last chunk does, and
/// photons through glass cost several times those that miss it: small chunks keep the threads
/// from waiting on one long chunk at the end of each batch. The image does not depend on the
/// chunk size: a photon's random numbers depend on its number alone.
pub(super) const CHUNK: u64 = 1024;

/// Photons per batch unless [`PpmOptions::batch_photons`](super::PpmOptions::batch_photons)
/// says otherwise: the caller's control callback is asked between batches.
pub const DEFAULT_BATCH_PHOTONS: u64 = 65_536;

/// The fewest photons a guided pass traces (or all of them, when a pass has fewer).
const FEWEST_GUIDED_PHOTONS: u64 = 4096;

/// What one chunk of photons left: where they met surfaces whose flux is gathered, where
/// each came from (in photon order), and counts.
struct Traced {
    hits: Vec<Hit>,
    from: Vec<Emitted>,
    counts: PhotonCounts,
}

impl Ppm {
    /// Traces this pass's photons in batches and gathers their flux at the visible points,
    /// looking as far as `radius`, each estimate's largest radius; `None` when `control`
    /// aborts the pass.
    pub(super) fn photon_pass(
        &mut self,
        scene: &Scene,
        index: &SpatialIndex,
        radius: [f64; 2],
        control: &mut dyn FnMut(&mut f64) -> Control,
    ) -> Option<Gathered> {
        let source = PhotonSource::new(scene, self.direct_light)
            .with_guide(self.guide.as_ref())
            .with_stratified(self.photon_shift);
        let estimates = self.estimates();
        let mut out = Gathered::new(
            self.slots.len(),
            estimates,
            self.guide.as_ref().map(EmissionGuide::tally),
        );
        self.pass_photons = self.guided_pass_photons();
        let gather = Gather {
            index,
            points: &self.points,
            radius,
            estimates,
        };
        // α as the caller sets it between batches, kept whether or not the pass completes.
        let mut alpha = self.alpha;
        let mut window = std::mem::take(&mut self.window);
        let traced = self.trace_photons(&source, &gather, &mut window, &mut out, &mut || {
            control(&mut alpha)
        });
        self.alpha = alpha;
        window.clear();
        self.window = window;
        traced.map(|()| out)
    }

    /// Traces the pass's photons batch by batch (asking `control` before each) and hands
    /// their hits to the points a window at a time, into `out`; `None` when `control` aborts.
    fn trace_photons(
        &self,
        source: &PhotonSource,
        gather: &Gather,
        window: &mut Window,
        out: &mut Gathered,
        control: &mut dyn FnMut() -> Control,
    ) -> Option<()> {
        let chunks = self.pass_photons.div_ceil(CHUNK);
        let most = WINDOW_PHOTONS as u64 / CHUNK;
        let chunks_per_batch = self.options.batch_photons.div_ceil(CHUNK).clamp(1, most);
        let mut chunk = 0;
        while chunk < chunks {
            if control() == Control::Abort {
                return None;
            }
            let end = (chunk + chunks_per_batch).min(chunks);
            let traced: Vec<Traced> = (chunk..end)
                .into_par_iter()
                .map(|c| {
                    let first = window.photons() + ((c - chunk) * CHUNK) as u32;
                    self.trace_chunk(c, first, source, gather.index)
                })
                .collect();
            for t in traced {
                window.push(t.hits, t.from);
                out.counts.paths += t.counts.paths;
                out.counts.bounces += t.counts.bounces;
            }
            chunk = end;
            if window.is_full() || chunk == chunks {
                window.hand(gather, out, control)?;
            }
        }
        Some(())
    }

    /// Estimates each slot gathers into this pass: 2, or 1 when the indirect one is off.
    fn estimates(&self) -> usize {
        if self.indirect_scale == IndirectScale::Off {
            1
        } else {
            2
        }
    }

    /// This pass's photons: `photons_per_pass` divided by the guide's gain for an epoch's
    /// first [`GAIN_DIVIDED_PASSES`] passes, by its square root after them (see
    /// [`guide`](super::guide)), but not below [`FEWEST_GUIDED_PHOTONS`] (or all of them).
    pub(super) fn guided_pass_photons(&self) -> u64 {
        match &self.guide {
            Some(g) => {
                let divisor = if self.epoch_pass() < GAIN_DIVIDED_PASSES {
                    g.gain()
                } else {
                    g.gain().sqrt()
                };
                let reduced = (self.photons_per_pass as f64 / divisor).ceil() as u64;
                reduced.max(self.photons_per_pass.min(FEWEST_GUIDED_PHOTONS))
            }
            None => self.photons_per_pass,
        }
    }

    /// The pass in progress, counted from 0: in this epoch, or in the global schedule (where
    /// it depends on the pass alone, whichever process renders it).
    fn epoch_pass(&self) -> u64 {
        match &self.global {
            Some(g) => g.stream_pass().saturating_sub(1),
            None => u64::from(self.stats.passes),
        }
    }

    /// Traces photon chunk `c` of this pass, whose first photon is the `first`th of its window:
    /// where its photons met surfaces whose flux is gathered, where they came from, its counts.
    fn trace_chunk(&self, c: u64, first: u32, source: &PhotonSource, index: &SpatialIndex) -> Traced {
        let mut counts = PhotonCounts::default();
        let (photons, first_photon) = (self.pass_photons, self.first_photon());
        let split = self.estimates() == 2;
        let (start, end) = (c * CHUNK, ((c + 1) * CHUNK).min(photons));
        let mut hits = Vec::with_capacity(2 * (end - start) as usize);
        let mut from = Vec::with_capacity((end - start) as usize);
        for i in start..end {
            let n = first_photon + i;
            let mut rng = stream_rng(self.seed, streams::PHOTON, n);
            let photon = first + (i - start) as u32;
            let mut nth = 0;
            from.push(
                source.trace(n, &mut rng, &mut counts, &mut |p, normal, flux, indirect| {
                    let key = index.sort_key(p);
                    hits.push(Hit::new(key, p, normal, flux, (photon, nth), indirect && split));
                    nth += 1;
                }),
            );
        }
        Traced { hits, from, counts }
    }
}
