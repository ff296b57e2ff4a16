//! The running error estimate of a progressive render, from its own frames alone
//! ([`ErrorTracker`]): what the viewer's error plot shows when there is no reference. It has
//! two parts, the noise and photon mapping's blur (its bias), shown as `√(noise² + blur²)`.
//!
//! **Noise.** Each new frame after `n_b` photons is compared with a kept earlier frame of the
//! same epoch after `n_a ≈ n_b/2` photons: the estimate is
//! `RMS(L_b − L_a) / √g(n_a/n_b) / RMS(L_b)`, the relative RMS of the frame's noise.
//! Why half: if a frame is the equal-weight mean of independent passes, whatever each pass's
//! own variance, then for `n_b = 2 n_a` every pass enters `L_b − L_a` with weight `±1/n_b`,
//! so `Var(L_b − L_a) = Var(L_b)` exactly (`g = 1`). Photon mapping's passes grow noisier as
//! their radii shrink (as `i^(1−α)`: Knaus & Zwicker 2011, "Progressive photon mapping: a
//! probabilistic approach"); for a kept frame not at exactly half, `g(ρ)` is that model's
//! `Var(L_b − L_a)/Var(L_b)` ([`noise_factor`]), 1 at `ρ = ½`. Comparing consecutive frames
//! (one pass apart) measures the noise of the newest pass alone, which on scenes whose error
//! comes from rare bright paths is mostly small (`scenes/pool.toml`: 0.2–0.8 times the true
//! error, against 0.7–1.04 for this estimate).
//!
//! **Blur.** The blur is the same in two frames but for the part that changed between them,
//! so one difference cannot see it. Three frames after `n_c < n_a < n_b` photons (about a
//! quarter, a half and all) can ([`blur_estimate`]): the two differences `L_b − L_a` and
//! `L_a − L_c` are of disjoint photons' means, so their noise is uncorrelated and the mean of
//! their product is the product of the blur's two changes, with no noise to subtract. With
//! the blur falling as the radii² do, as `n^(−(1−α))`, that product gives the blur at `n_b`.
//! The noise does enter the product's spread: where a few bright pixels make it (pool's rare
//! paths), a product within two standard errors of zero (over runs of [`BLUR_BLOCK`] pixels)
//! counts as no blur found. Solving for noise and blur from the two differences' squares
//! instead was tried: it subtracts one large noise from another, and said 0–3.6 times the
//! truth.
//!
//! Measured (`caustic bench estimate`, 160 pixels wide against 4000-pass references; the
//! estimate over the true error after 16, 64 and 256 passes): ring 0.90 / 1.21 / 1.42
//! (the noise alone: 0.90 / 0.74 / 0.67), pool 0.81 / 1.04 / 0.73 (0.72 / 1.04 / 0.73),
//! cornell 0.99 / 0.88 / 0.54 (no blur found), lens 5.82 / 1.45 / 0.87 (no blur found).
//! What it still cannot see: a blur that does not fall between the frames (cornell's wide
//! indirect estimate late on), and frames whose difference outgrows their error early on
//! (the built-in scene: 2.3 and 3.7 times the truth after 16 and 64 passes, 1.1 after 256;
//! lens: 5.8 after 16, where the true error itself jumps between passes, 20.6 % after 10 and
//! 2.4 % after 16). For equal-weight means of passes the half comparison is exact whatever
//! each pass's variance, so early frames there are not such means: an error that the frame
//! at half the photons had is mostly gone from the frame after all of them (the first
//! passes' radius choices, supersampling and the emission guide change how later passes
//! count; which of them does it is not yet measured).
//!
//! Frames are kept at photon counts at least [`KEEP_RATIO`] apart and dropped once a later
//! one serves as well, so about seven are held at a time.

use std::sync::Arc;

use super::error::mean_squares;

/// Kept frames' photon counts grow at least this much from one to the next.
pub const KEEP_RATIO: f64 = 1.25;

/// One kept frame.
#[derive(Clone)]
struct Kept {
    photons: u64,
    radiance: Arc<[[f32; 3]]>,
}

/// The running error estimate of one epoch ([`ErrorTracker::add`]).
#[derive(Clone, Default)]
pub struct ErrorTracker {
    kept: Vec<Kept>,
    /// The estimated relative blur of the last frame added ([`ErrorTracker::blur`]).
    blur: Option<f64>,
}

/// `g(ρ) = Var(L_b − L_a) / Var(L_b)` for frames after `ρ = n_a/n_b` of the photons, if each frame
/// is the mean of independent photons whose variance grows as `i^(1−α)` (photon mapping's
/// shrinking radii).
pub fn noise_factor(rho: f64, alpha: f64) -> f64 {
    1.0 - rho.powf(2.0 - alpha) + (1.0 - rho).powi(2) * rho.powf(-alpha)
}

/// The error an estimate's noise and blur make together, `√(noise² + blur²)`: the noise
/// alone where no blur was estimated.
pub fn total_error(noise: f64, blur: Option<f64>) -> f64 {
    noise.hypot(blur.unwrap_or(0.0))
}

/// Pixels a block of the blur's significance test holds (runs of the image in memory order).
pub const BLUR_BLOCK: usize = 64;

/// The relative RMS blur of frame `b` from frames `c`, `a`, `b` after `n_c < n_a < n_b`
/// photons of one render with photon mapping's `alpha`: the mean over pixels and channels of
/// `(L_b − L_a)(L_a − L_c)`, whose noise has zero mean (the two differences are of disjoint
/// photons' means, up to the growth of their variance), is the product of the blur's two
/// changes; with the blur falling as `n^(−(1−α))`, that product gives the blur at `n_b`.
pub fn blur_estimate(frames: [(u64, &Arc<[[f32; 3]]>); 3], alpha: f64) -> Option<f64> {
    let [(n_c, c), (n_a, a), (n_b, b)] = frames;
    if alpha >= 1.0 || !(n_c > 0 && n_c < n_a && n_a < n_b) || a.len() != b.len() || c.len() != b.len() {
        return None;
    }
    let gamma = (1.0 - alpha).clamp(0.05, 0.95);
    let s = |n: u64| (n as f64).powf(-gamma);
    let (s_c, s_a, s_b) = (s(n_c), s(n_a), s(n_b));
    // The products summed in runs of BLUR_BLOCK pixels: neighbouring pixels share photons
    // (their noise is correlated), runs of them far less.
    let (mut blocks, mut norm2) = (Vec::with_capacity(b.len() / BLUR_BLOCK + 1), 0.0f64);
    for ((rc, ra), rb) in c
        .chunks(BLUR_BLOCK)
        .zip(a.chunks(BLUR_BLOCK))
        .zip(b.chunks(BLUR_BLOCK))
    {
        let mut sum = 0.0f64;
        for ((pc, pa), pb) in rc.iter().zip(ra).zip(rb) {
            for k in 0..3 {
                let (vc, va, vb) = (pc[k] as f64, pa[k] as f64, pb[k] as f64);
                sum += (vb - va) * (va - vc);
                norm2 += vb * vb;
            }
        }
        blocks.push(sum);
    }
    // A product the noise alone could give (within two standard errors of zero) is no blur
    // found: a few bright pixels' noise would otherwise pass for one.
    let count = blocks.len() as f64;
    let mean = blocks.iter().sum::<f64>() / count;
    let spread2 = blocks.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (count - 1.0).max(1.0);
    let significant = mean > 2.0 * (spread2 / count).sqrt();
    let cross = if significant { mean * count } else { 0.0 };
    let bias2 = (cross * s_b * s_b / ((s_b - s_a) * (s_a - s_c))).max(0.0);
    let relative = (bias2 / norm2).sqrt();
    (norm2 > 0.0 && relative.is_finite()).then_some(relative)
}

impl ErrorTracker {
    /// Takes the epoch's frame after `photons` photons, rendered with photon mapping's
    /// `alpha` (1 for plain means, as a path tracer's); returns its estimated relative RMS
    /// noise (`None` for the first frame, a frame with no more photons than the last, or an
    /// undefined estimate: a black image).
    pub fn add(&mut self, photons: u64, radiance: &Arc<[[f32; 3]]>, alpha: f64) -> Option<f64> {
        let last = self.kept.last().map_or(0, |k| k.photons);
        if photons <= last && !self.kept.is_empty() {
            return None;
        }
        // The newest kept frame with at most half the photons, else the oldest one.
        let at = self
            .kept
            .iter()
            .rposition(|k| k.photons <= photons / 2)
            .unwrap_or(0);
        let estimate = self.kept.get(at).and_then(|k| {
            if k.photons == 0 || k.radiance.len() != radiance.len() {
                return None;
            }
            let (diff2, norm2) = mean_squares(&k.radiance, radiance);
            let rho = k.photons as f64 / photons as f64;
            let relative = (diff2 / noise_factor(rho, alpha.clamp(0.05, 1.0)) / norm2).sqrt();
            (norm2 > 0.0 && relative.is_finite()).then_some(relative)
        });
        // The newest kept frame with at most half of that one's photons: the blur's third.
        let quarter = self
            .kept
            .get(at)
            .and_then(|a| self.kept[..at].iter().rposition(|k| k.photons <= a.photons / 2));
        self.blur = quarter.and_then(|c| {
            let (c, a) = (&self.kept[c], &self.kept[at]);
            blur_estimate(
                [
                    (c.photons, &c.radiance),
                    (a.photons, &a.radiance),
                    (photons, radiance),
                ],
                alpha,
            )
        });
        // Frames before those used are never the better choice again.
        self.kept.drain(..quarter.unwrap_or(0));
        if self.kept.is_empty() || photons as f64 >= KEEP_RATIO * last as f64 {
            self.kept.push(Kept {
                photons,
                radiance: radiance.clone(),
            });
        }
        estimate
    }

    /// The estimated relative RMS blur (photon mapping's bias) of the last frame added, from
    /// three frames after `n_c < n_a < n_b` photons: `None` until there are three, for plain
    /// means (α = 1), or when undefined.
    pub fn blur(&self) -> Option<f64> {
        self.blur
    }

    /// Photon counts of the frames held (for tests).
    pub fn held(&self) -> Vec<u64> {
        self.kept.iter().map(|k| k.photons).collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};

    /// Frames whose blur falls as `n^(−(1−α))` under the noise of a mean of independent
    /// passes: with the noise below the blur, the blur is found within 5 %; whatever the
    /// noise, noise and blur together are the true error within 15 %; where there is no blur,
    /// next to none is found.
    #[test]
    fn finds_a_blur_that_falls_as_the_radii_shrink_and_none_where_there_is_none() {
        for (blur_scale, noise_scale) in [(0.3, 0.5), (0.3, 3.0), (0.0, 1.0)] {
            let mut rng = rand_pcg::Pcg64::seed_from_u64(9);
            let pixels = 20_000;
            // Each pixel's blur at n = 1: a smooth pattern of both signs.
            let beta: Vec<f64> = (0..pixels)
                .map(|p| blur_scale * (p as f64 * 0.01).sin())
                .collect();
            let mut sum = vec![0.0f64; pixels];
            let mut tracker = ErrorTracker::default();
            for pass in 1..=256u64 {
                for s in sum.iter_mut() {
                    *s += 1.0 + (rng.random::<f64>() - 0.5) * noise_scale;
                }
                let bias = (pass as f64).powf(-0.3);
                let frame: Arc<[[f32; 3]]> = sum
                    .iter()
                    .zip(&beta)
                    .map(|(s, b)| [(s / pass as f64 + b * bias) as f32; 3])
                    .collect();
                let noise = tracker.add(pass * 1000, &frame, 0.7);
                if ![16, 64, 256].contains(&pass) {
                    continue;
                }
                let rms = |f: &dyn Fn(usize) -> f64| {
                    ((0..pixels).map(|p| f(p).powi(2)).sum::<f64>() / pixels as f64).sqrt()
                };
                let norm = rms(&|p| frame[p][0] as f64);
                let true_blur = rms(&|p| beta[p] * bias) / norm;
                let true_error = rms(&|p| frame[p][0] as f64 - 1.0) / norm;
                let (noise, blur) = (noise.expect("two frames"), tracker.blur().expect("three frames"));
                let total = noise.hypot(blur);
                assert!(
                    (total / true_error - 1.0).abs() < 0.15,
                    "{blur_scale}/{noise_scale}, pass {pass}: noise {noise} and blur {blur} against {true_error}"
                );
                if blur_scale == 0.0 {
                    assert!(blur < 0.3 * noise, "pass {pass}: blur {blur} where there is none");
                } else if noise < 0.5 * true_blur {
                    assert!(
                        (blur / true_blur - 1.0).abs() < 0.05,
                        "pass {pass}: blur {blur} against {true_blur}"
                    );
                }
            }
        }
    }

    /// Passes whose variance grows as photon mapping's do (∝ i^0.3 for α = 0.7): the half
    /// comparison matches the true error within 10 %, as it is exact in expectation.
    #[test]
    fn matches_the_error_of_passes_of_growing_variance() {
        let mut rng = rand_pcg::Pcg64::seed_from_u64(5);
        let pixels = 20_000;
        let mut sum = vec![0.0f64; pixels];
        let mut tracker = ErrorTracker::default();
        for pass in 1..=256u64 {
            let spread = (pass as f64).powf(0.15);
            for s in sum.iter_mut() {
                *s += 1.0 + (rng.random::<f64>() - 0.5) * 2.0 * spread;
            }
            let frame: Arc<[[f32; 3]]> = sum.iter().map(|s| [(s / pass as f64) as f32; 3]).collect();
            let estimate = tracker.add(pass * 1000, &frame, 0.7);
            if [16, 64, 256].contains(&pass) {
                let truth =
                    (frame.iter().map(|p| (p[0] as f64 - 1.0).powi(2)).sum::<f64>() / pixels as f64).sqrt();
                let rms_b = (frame.iter().map(|p| (p[0] as f64).powi(2)).sum::<f64>() / pixels as f64).sqrt();
                let estimate = estimate.expect("defined") * rms_b;
                assert!(
                    (estimate / truth - 1.0).abs() < 0.1,
                    "pass {pass}: estimate {estimate} against {truth}"
                );
                assert!(tracker.held().len() <= 8, "held {:?}", tracker.held());
            }
        }
    }
}
