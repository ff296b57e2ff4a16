//! A running error estimate for the convergence plot, from successive frames alone (no
//! reference image).
//!
//! If the image after `n` photons were the photon-weighted mean of independent estimates with
//! per-pixel variance σ² per photon, then between frames at `n_a < n_b` photons
//! `Var(L_b − L_a) = σ²(1/n_a − 1/n_b)` and the error of `L_b` is `σ/√n_b`, so
//!
//! `error(L_b) ≈ RMS(L_b − L_a) / √(n_b/n_a − 1)`,
//!
//! reported relative to `RMS(L_b)`. Counting photons rather than passes keeps the estimate
//! right while the viewer's first passes grow (16,384 photons, doubling). PPM's shrinking radii
//! make later photons count a little more than a plain mean, so this estimates the noise, not
//! the bias; it falls as the render converges and is comparable between settings of a scene.

use std::sync::Arc;

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

/// `RMS(b − a) / √(n_b/n_a − 1) / RMS(b)` for images after `n_a < n_b` samples (photons, or
/// passes of equal size), or `None` when it is undefined (no growth, black image, mismatched
/// sizes).
pub fn relative_error_estimate(n_a: u64, a: &[[f32; 3]], n_b: u64, b: &[[f32; 3]]) -> Option<f64> {
    if n_a == 0 || n_b <= n_a || a.len() != b.len() || a.is_empty() {
        return None;
    }
    let (mut diff2, mut norm2) = (0.0f64, 0.0f64);
    for (pa, pb) in a.iter().zip(b) {
        for c in 0..3 {
            let d = pb[c] as f64 - pa[c] as f64;
            diff2 += d * d;
            norm2 += pb[c] as f64 * pb[c] as f64;
        }
    }
    if norm2 <= 0.0 || !diff2.is_finite() || !norm2.is_finite() {
        return None;
    }
    let ratio = n_b as f64 / n_a as f64 - 1.0;
    Some((diff2 / ratio).sqrt() / norm2.sqrt())
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

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};

    /// For running means of noisy passes the estimate matches the true error.
    #[test]
    fn estimate_matches_the_error_of_a_running_mean() {
        let mut rng = rand_pcg::Pcg64::seed_from_u64(7);
        let truth = 2.0f32;
        let pixels = 20_000;
        let mut sum = vec![0.0f64; pixels];
        let mut frames: Vec<(u64, Vec<[f32; 3]>)> = Vec::new();
        for pass in 1..=32u64 {
            for s in sum.iter_mut() {
                *s += truth as f64 + (rng.random::<f64>() - 0.5) * 2.0;
            }
            if pass == 8 || pass == 12 || pass == 32 {
                let mean = sum.iter().map(|s| [(s / pass as f64) as f32; 3]).collect();
                frames.push((pass, mean));
            }
        }
        for w in frames.windows(2) {
            let (a, b) = (&w[0], &w[1]);
            let estimate = relative_error_estimate(a.0, &a.1, b.0, &b.1).expect("defined");
            let rms: f64 =
                (b.1.iter()
                    .map(|p| (p[0] - truth) as f64)
                    .map(|d| d * d)
                    .sum::<f64>()
                    / pixels as f64)
                    .sqrt();
            let actual = rms / truth as f64;
            assert!(
                (estimate / actual - 1.0).abs() < 0.1,
                "estimate {estimate} vs actual {actual} (passes {} → {})",
                a.0,
                b.0
            );
        }
    }

    /// Passes that grow (the viewer's 16,384-photon start, doubling) are weighed by their
    /// sample counts: the estimate still matches the true error.
    #[test]
    fn estimate_follows_growing_passes() {
        let mut rng = rand_pcg::Pcg64::seed_from_u64(11);
        let truth = 1.0f64;
        let pixels = 20_000;
        let mut sum = vec![0.0f64; pixels];
        let mut count = 0u64;
        let mut frames: Vec<(u64, Vec<[f32; 3]>)> = Vec::new();
        for pass in 0..6 {
            let samples = 1u64 << pass; // 1, 2, 4, 8, 16, 32 samples per pixel
            for s in sum.iter_mut() {
                for _ in 0..samples {
                    *s += truth + (rng.random::<f64>() - 0.5) * 2.0;
                }
            }
            count += samples;
            if pass >= 4 {
                frames.push((
                    count,
                    sum.iter().map(|s| [(s / count as f64) as f32; 3]).collect(),
                ));
            }
        }
        let ((a, la), (b, lb)) = (&frames[0], &frames[1]);
        let estimate = relative_error_estimate(*a, la, *b, lb).expect("defined");
        let actual = (lb.iter().map(|p| (p[0] as f64 - truth).powi(2)).sum::<f64>() / pixels as f64).sqrt();
        assert!(
            (estimate / actual - 1.0).abs() < 0.1,
            "estimate {estimate} vs actual {actual}"
        );
    }

    #[test]
    fn undefined_cases_give_none() {
        let a = vec![[1.0f32; 3]; 4];
        assert_eq!(relative_error_estimate(0, &a, 2, &a), None);
        assert_eq!(relative_error_estimate(2, &a, 2, &a), None);
        assert_eq!(relative_error_estimate(1, &a, 2, &[[0.0; 3]; 4]), None);
        assert_eq!(relative_error_estimate(1, &a, 2, &a[..2]), None);
    }
}
