//! The convergence plot's data: the running error estimate from the epoch's own frames
//! ([`ErrorTracker`], whose module explains it and what it cannot see) — it falls as the
//! render converges and is comparable between settings of a scene — and, once a reference is
//! open, the true error.

use std::sync::Arc;

use crate::render::compare::ReferenceErrors;
use crate::render::error_tracker::{ErrorEstimate, ErrorTracker, Restarts};

/// Error estimates of one epoch against time.
#[derive(Clone, Default)]
pub struct Convergence {
    tracker: ErrorTracker,
    /// `(elapsed seconds, estimated relative RMS error)` per frame after the first: the
    /// noise, and from the third frame on the blur with it (`√(noise² + blur²)`).
    pub points: Vec<[f64; 2]>,
    /// Those of [`Convergence::points`] whose estimate is uncertain
    /// ([`ErrorEstimate::why_uncertain`]: the error is in a few pixels, or the frames compared
    /// straddle a restart).
    pub uncertain_points: Vec<[f64; 2]>,
    /// The newest estimate.
    latest: Option<ErrorEstimate>,
    /// `(elapsed seconds, RMSE, relative MSE)` against the reference, per frame since it was
    /// opened.
    pub reference_points: Vec<[f64; 3]>,
}

impl Convergence {
    /// Forgets everything (a new epoch).
    pub fn reset(&mut self) {
        *self = Self::default();
    }

    /// Takes a frame of the current epoch made from `photons` photons, with the epoch's
    /// `restarts` so far and photon mapping's `alpha` (1 for a path tracer's plain means).
    pub fn add(
        &mut self,
        (photons, restarts): (u64, &Restarts),
        elapsed_secs: f64,
        radiance: &Arc<[[f32; 3]]>,
        alpha: f64,
    ) {
        if let Some(estimate) = self.tracker.add((photons, restarts), radiance, alpha) {
            self.add_estimate(elapsed_secs, estimate);
        }
    }

    /// Takes an estimate made elsewhere after `elapsed_secs` (a watched render's, from the
    /// spread of its independent passes).
    pub fn add_estimate(&mut self, elapsed_secs: f64, estimate: ErrorEstimate) {
        self.points.push([elapsed_secs, estimate.total()]);
        if estimate.uncertain() {
            self.uncertain_points.push([elapsed_secs, estimate.total()]);
        }
        self.latest = Some(estimate);
    }

    /// Takes a frame's true error against the reference.
    pub fn add_reference(&mut self, elapsed_secs: f64, errors: ReferenceErrors) {
        self.reference_points
            .push([elapsed_secs, errors.rmse, errors.rel_mse]);
    }

    /// Forgets the true errors (the reference closed or changed).
    pub fn clear_reference(&mut self) {
        self.reference_points.clear();
    }

    /// The newest estimate.
    pub fn latest(&self) -> Option<ErrorEstimate> {
        self.latest
    }
}
