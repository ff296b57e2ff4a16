//! The photon pass: photons traced in fixed chunks in parallel, batch by batch with the
//! caller asked between batches; where they meet diffuse surfaces is handed to the visible
//! points a window of many batches at a time, in the order of the grid's cells
//! ([`deposit`](super::deposit)), and reduced in that order (so the image is the same for
//! any thread count).

use rayon::prelude::*;

use super::config::Config;
use super::deposit::{Gather, Hit, Window, WINDOW_PHOTONS};
use super::gathered::Gathered;
use super::guide::{EmissionGuide, GAIN_DIVIDED_PASSES};
use super::index::SpatialIndex;
use super::photon::{Emitted, PhotonCounts, PhotonSource};
use super::points::VisiblePoints;
use super::streams;
use crate::render::control::Control;
use crate::render::rng::stream_rng;
use crate::scene::Scene;

/// Photons per chunk: the unit of parallel tracing (their hits are reduced in groups of the
/// sorted window, [`deposit`](super::deposit)). A batch ends when its last chunk does, and
/// photons through glass cost several times those that miss it: small chunks keep the threads
/// from waiting on one long chunk at the end of each batch. The image does not depend on the
/// chunk size: a photon's random numbers depend on its number alone.
pub const CHUNK: u64 = 1024;

/// The fewest photons a guided pass traces (or all of them, when a pass has fewer).
const FEWEST_GUIDED_PHOTONS: u64 = 4096;

/// What one chunk of photons left: where they met surfaces whose flux is gathered, where
/// each came from (in photon order), and counts.
struct Traced {
    hits: Vec<Hit>,
    from: Vec<Emitted>,
    counts: PhotonCounts,
}

/// A pass's photons: how many it emits, and the window of hits kept from pass to pass.
#[derive(Default)]
pub struct PhotonPass {
    /// Photons emitted by the pass in progress ([`guided_pass_photons`]).
    pub photons: u64,
    /// The hits awaiting their points, empty between passes; kept so that its tens of MiB
    /// are not mapped afresh (page by page) every pass.
    window: Window,
}

/// What a photon pass gathers into: the render's choices, where photons go, the points and
/// the index over them, and where the pass's photons start.
pub struct PhotonJob<'a> {
    /// The render's choices.
    pub config: &'a Config,
    /// Where photons are sent (`None`: as the lights emit).
    pub guide: Option<&'a EmissionGuide>,
    /// The index over `points`.
    pub index: &'a SpatialIndex,
    /// The pass's visible points.
    pub points: &'a VisiblePoints,
    /// The statistics slots the points hand flux to.
    pub slots: usize,
    /// Estimates per slot: 2, or 1 when the indirect estimate is off.
    pub estimates: usize,
    /// Each estimate's largest radius: how far from a photon its points are looked for.
    pub radius: [f64; 2],
    /// The random stream index of the pass's first photon.
    pub first_photon: u64,
}

impl PhotonPass {
    /// Traces `photons` photons of `scene` in batches and gathers their flux at the job's
    /// visible points, calling `control(alpha)` between batches (α as the caller sets it is
    /// kept whether or not the pass completes); `None` when `control` aborts the pass.
    pub fn run(
        &mut self,
        job: &PhotonJob,
        scene: &Scene,
        photons: u64,
        alpha: &mut f64,
        control: &mut dyn FnMut(&mut f64) -> Control,
    ) -> Option<Gathered> {
        let config = job.config;
        let source = PhotonSource::new(scene, config.direct_light)
            .with_guide(job.guide)
            .with_stratified(config.photon_shift);
        let mut out = Gathered::new(job.slots, job.estimates, job.guide.map(EmissionGuide::tally));
        self.photons = photons;
        let gather = Gather {
            index: job.index,
            points: job.points,
            radius: job.radius,
            estimates: job.estimates,
        };
        let mut window = std::mem::take(&mut self.window);
        let traced = self.trace_photons(job, &source, &gather, &mut window, &mut out, &mut || {
            control(alpha)
        });
        window.clear();
        self.window = window;
        traced.map(|()| out)
    }

    /// Traces the pass's photons batch by batch (asking `control` before each) and hands
    /// their hits to the points a window at a time, into `out`; `None` when `control` aborts.
    fn trace_photons(
        &self,
        job: &PhotonJob,
        source: &PhotonSource,
        gather: &Gather,
        window: &mut Window,
        out: &mut Gathered,
        control: &mut dyn FnMut() -> Control,
    ) -> Option<()> {
        let chunks = self.photons.div_ceil(CHUNK);
        let most = WINDOW_PHOTONS as u64 / CHUNK;
        let chunks_per_batch = job.config.options.batch_photons.div_ceil(CHUNK).clamp(1, most);
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
                    self.trace_chunk(job, c, first, source)
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

    /// Traces photon chunk `c` of this pass, whose first photon is the `first`th of its window:
    /// where its photons met surfaces whose flux is gathered, where they came from, its counts.
    fn trace_chunk(&self, job: &PhotonJob, c: u64, first: u32, source: &PhotonSource) -> Traced {
        let mut counts = PhotonCounts::default();
        let (photons, first_photon) = (self.photons, job.first_photon);
        let split = job.estimates == 2;
        let (start, end) = (c * CHUNK, ((c + 1) * CHUNK).min(photons));
        let mut hits = Vec::with_capacity(2 * (end - start) as usize);
        let mut from = Vec::with_capacity((end - start) as usize);
        for i in start..end {
            let n = first_photon + i;
            let mut rng = stream_rng(job.config.seed, streams::PHOTON, n);
            let photon = first + (i - start) as u32;
            let mut nth = 0;
            from.push(
                source.trace(n, &mut rng, &mut counts, &mut |p, sides, flux, indirect| {
                    let key = job.index.sort_key(p);
                    hits.push(Hit::new(key, p, sides, flux, (photon, nth), indirect && split));
                    nth += 1;
                }),
            );
        }
        Traced { hits, from, counts }
    }
}

/// A pass's photons: `photons_per_pass` divided by the `guide`'s gain for an epoch's first
/// [`GAIN_DIVIDED_PASSES`] passes, by its square root after them (see
/// [`guide`](super::guide)), but not below [`FEWEST_GUIDED_PHOTONS`] (or all of them).
/// `epoch_pass` is the pass in progress, counted from 0: in this epoch, or in the global
/// schedule (where it depends on the pass alone, whichever process renders it).
pub fn guided_pass_photons(guide: Option<&EmissionGuide>, photons_per_pass: u64, epoch_pass: u64) -> u64 {
    match guide {
        Some(g) => {
            let divisor = if epoch_pass < GAIN_DIVIDED_PASSES {
                g.gain()
            } else {
                g.gain().sqrt()
            };
            let reduced = (photons_per_pass as f64 / divisor).ceil() as u64;
            reduced.max(photons_per_pass.min(FEWEST_GUIDED_PHOTONS))
        }
        None => photons_per_pass,
    }
}
