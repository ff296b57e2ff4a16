//! The convergence plot's data: the running error estimate from successive frames alone
//! ([`crate::render::error::relative_error_estimate`], which explains it) — it falls as the
//! render converges and is comparable between settings of a scene.

use std::sync::Arc;

use crate::render::error::relative_error_estimate;

/// One frame as the estimator needs it.
#[derive(Clone)]
struct Sample {
    count: u64,
    radiance: Arc<[[f32; 3]]>,
}

/// Error estimates of one epoch against time.
#[derive(Clone, Default)]
pub struct Convergence {
    previous: Option<Sample>,
    /// `(elapsed seconds, estimated relative RMS error)` per frame after the first.
    pub points: Vec<[f64; 2]>,
}

impl Convergence {
    /// Forgets everything (a new epoch).
    pub fn reset(&mut self) {
        *self = Self::default();
    }

    /// Takes a frame of the current epoch made from `photons` photons.
    pub fn add(&mut self, photons: u64, elapsed_secs: f64, radiance: &Arc<[[f32; 3]]>) {
        if let Some(prev) = &self.previous {
            if photons <= prev.count {
                return;
            }
            if let Some(e) = relative_error_estimate(prev.count, &prev.radiance, photons, radiance) {
                self.points.push([elapsed_secs, e]);
            }
        }
        self.previous = Some(Sample {
            count: photons,
            radiance: radiance.clone(),
        });
    }

    /// The newest estimate.
    pub fn latest(&self) -> Option<f64> {
        self.points.last().map(|p| p[1])
    }
}
