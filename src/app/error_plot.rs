//! The convergence plot's data: the running error estimate from successive frames alone
//! ([`crate::render::error::relative_error_estimate`], which explains it) — it falls as the
//! render converges and is comparable between settings of a scene.

use std::sync::Arc;

use crate::render::compare::ReferenceErrors;
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
    /// `(elapsed seconds, RMSE, relative MSE)` against the reference, per frame since it was
    /// opened.
    pub reference_points: Vec<[f64; 3]>,
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
    pub fn latest(&self) -> Option<f64> {
        self.points.last().map(|p| p[1])
    }
}
