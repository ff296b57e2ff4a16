//! What a photon-mapping render measured ([`PpmStats`]).

use super::photon::PhotonCounts;
use crate::scene::Scene;

/// Run statistics.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize)]
pub struct PpmStats {
    /// Completed passes.
    pub passes: u32,
    /// Photons emitted in completed passes.
    pub photons: u64,
    /// Photon bounces traced.
    pub bounces: u64,
    /// Flux deposits made.
    pub deposits: u64,
    /// Photon paths that handed flux to at least one visible point (the share of `photons`
    /// that did any good).
    pub useful_paths: u64,
    /// Visible points in the last pass.
    pub visible_points: usize,
    /// Mean search radius over slots that have gathered photons (scene units); before any
    /// has, over every slot with a radius.
    pub mean_radius: f64,
    /// The indirect estimate's initial radius over the primary's (1: one estimate for all
    /// photons; chosen after the first pass when automatic).
    pub indirect_radius_scale: f64,
    /// Share of the statistics slots whose estimate restarted with a narrower radius after
    /// the first pass (adaptive radius; 0 before it or when off).
    pub narrowed_share: f64,
    /// Share of the statistics slots whose estimate restarted with a wider radius after the
    /// first pass, where photons were sparse (adaptive radius; 0 before it or when off).
    pub widened_share: f64,
    /// Share of the pixels whose light seen directly takes extra eye rays every pass, where it
    /// changes within the pixel (a lamp's outline and its images; the `seen` module).
    pub supersampled_share: f64,
    /// Share of the pixels whose statistics a warm restart kept from the previous epoch (0
    /// for a cold start).
    pub kept_share: f64,
    /// Share of the pixels whose points moved and that a warm restart gave the previous
    /// estimate of a point near their own.
    pub nearby_share: f64,
    /// Share of the pixels whose eye path a warm restart's first pass copied from the
    /// previous epoch's last instead of tracing it again (the `reuse` module).
    pub copied_share: f64,
    /// Photons emitted before the pass at which every pixel's estimates started again, no
    /// longer counting the passes before it (the adaptive radius's restart at the second pass;
    /// 0: none did). A frame of no more photons is no part of later frames.
    pub restarted_photons: u64,
    /// Seconds spent in completed passes.
    pub elapsed_secs: f64,
    /// Seconds spent tracing photons.
    pub photon_secs: f64,
    /// Seconds spent in eye passes (tracing and setting up visible points).
    pub eye_secs: f64,
    /// Seconds spent building the spatial index over visible points.
    pub index_secs: f64,
    /// Seconds spent sampling area lights at the visible points.
    pub direct_secs: f64,
    /// Eye passes run.
    pub eye_passes: u32,
    /// Work the scene did not need, in words.
    pub skipped: Vec<String>,
}

impl PpmStats {
    /// Adds a completed pass's `emitted` photons and what they did.
    pub fn count_photons(&mut self, emitted: u64, counts: &PhotonCounts) {
        self.photons += emitted;
        self.bounces += counts.bounces;
        self.deposits += counts.deposits;
        self.useful_paths += counts.useful;
    }

    /// After the global schedule's pilot pass: the counts start again at pass 0 (the pilot's
    /// time stays in the elapsed time; classic PPM keeps its one eye pass).
    pub fn restart_after_pilot(&mut self, stochastic: bool) {
        self.passes = 0;
        self.photons = 0;
        self.bounces = 0;
        self.deposits = 0;
        self.useful_paths = 0;
        self.restarted_photons = 0;
        if stochastic {
            self.eye_passes = 0;
        }
        self.skipped.push(
            "per-point statistics: every pass is an independent estimate (global radius schedule)".into(),
        );
    }
}

/// What a render of `scene` skips because the scene does not need it, in words (the render's
/// statistics list it); `stochastic`: whether the eye pass is traced anew every pass.
pub fn skipped_work(scene: &Scene, stochastic: bool) -> Vec<String> {
    let features = scene.features();
    let mut skipped = Vec::new();
    if !stochastic {
        skipped.push("eye pass traced once and reused (pinhole camera, no anti-aliasing)".to_owned());
    }
    if !features.patches {
        skipped.push("no Bézier patches: no patch intersection set up".to_owned());
    }
    if !features.glass {
        skipped.push("no glass: no refraction paths".to_owned());
    }
    if !features.textures {
        skipped.push("no textures: constant colours, no lookups".to_owned());
    }
    if scene.params.direct_light {
        skipped.push("photons' first diffuse bounce: direct light by light sampling".to_owned());
    }
    if let Some(target) = scene.geometry.bounding_sphere() {
        if scene.lights.iter().any(|l| l.aims_at(target)) {
            skipped.push("photons from point lights outside the scene aimed at its bounds".to_owned());
        }
    }
    skipped
}
