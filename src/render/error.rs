//! How far an image is from the truth: against a reference ([`errors`]: RMSE and pbrt's
//! relative MSE), and, with no reference, estimated from two frames of the same render
//! ([`relative_error_estimate`] for the whole image, [`pixel_error_estimate`] per pixel).
//!
//! The estimate: if the image after `n` photons were the photon-weighted mean of independent
//! estimates with per-pixel variance σ² per photon, then between frames at `n_a < n_b` photons
//! `Var(L_b − L_a) = σ²(1/n_a − 1/n_b)` and the error of `L_b` is `σ/√n_b`, so
//!
//! `error(L_b) ≈ |L_b − L_a| / √(n_b/n_a − 1)`.
//!
//! Counting photons rather than passes keeps the estimate right while a viewer's first passes
//! grow. PPM's shrinking radii make later photons count a little more than a plain mean, so
//! this estimates the noise, not the bias.

/// RMSE and relative MSE of `image` against `reference` (same size, linear RGB).
pub fn errors(image: &[[f32; 3]], reference: &[[f32; 3]]) -> (f64, f64) {
    let (mut sq, mut rel) = (0.0, 0.0);
    for (x, r) in image.iter().zip(reference) {
        for c in 0..3 {
            let (x, r) = (x[c] as f64, r[c] as f64);
            sq += (x - r) * (x - r);
            rel += (x - r) * (x - r) / (r * r + 0.01);
        }
    }
    let n = (3 * image.len().max(1)) as f64;
    ((sq / n).sqrt(), rel / n)
}

/// `RMS(b − a) / √(n_b/n_a − 1) / RMS(b)` for images after `n_a < n_b` samples (photons, or
/// passes of equal size), or `None` when it is undefined (no growth, black image, mismatched
/// sizes).
pub fn relative_error_estimate(n_a: u64, a: &[[f32; 3]], n_b: u64, b: &[[f32; 3]]) -> Option<f64> {
    if n_a == 0 || n_b <= n_a || a.len() != b.len() || a.is_empty() {
        return None;
    }
    let (diff2, norm2) = mean_squares(a, b);
    if norm2 <= 0.0 || !diff2.is_finite() || !norm2.is_finite() {
        return None;
    }
    let ratio = n_b as f64 / n_a as f64 - 1.0;
    Some((diff2 / ratio).sqrt() / norm2.sqrt())
}

/// The mean squares of `b − a` and of `b`, over every channel of equally long images: a
/// relative RMS difference is `√(first / second)`.
pub fn mean_squares(a: &[[f32; 3]], b: &[[f32; 3]]) -> (f64, f64) {
    let (mut diff2, mut norm2) = (0.0f64, 0.0f64);
    for (pa, pb) in a.iter().zip(b) {
        for c in 0..3 {
            let d = pb[c] as f64 - pa[c] as f64;
            diff2 += d * d;
            norm2 += pb[c] as f64 * pb[c] as f64;
        }
    }
    let n = (3 * b.len().max(1)) as f64;
    (diff2 / n, norm2 / n)
}

/// Per pixel, the estimated standard error of `b` (mean over the colour channels, radiance
/// units): `|b − a| / √(n_b/n_a − 1)` for images after `n_a < n_b` photons; `None` when it
/// is undefined (no growth, mismatched sizes). One difference per pixel is a noisy estimate of
/// the pixel's error (its square is unbiased); averaged over a region it is a good one.
pub fn pixel_error_estimate(n_a: u64, a: &[[f32; 3]], n_b: u64, b: &[[f32; 3]]) -> Option<Vec<f32>> {
    if n_a == 0 || n_b <= n_a || a.len() != b.len() {
        return None;
    }
    let scale = (n_b as f64 / n_a as f64 - 1.0).sqrt().recip() as f32;
    Some(
        a.iter()
            .zip(b)
            .map(|(pa, pb)| (0..3).map(|c| (pb[c] - pa[c]).abs()).sum::<f32>() / 3.0 * scale)
            .collect(),
    )
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
    fn pixel_estimate_and_reference_errors() {
        let a = vec![[1.0f32; 3], [2.0, 2.0, 2.0]];
        let b = vec![[1.5f32; 3], [2.0, 2.0, 2.0]];
        // n_b/n_a − 1 = 3: the difference is divided by √3.
        let e = pixel_error_estimate(1, &a, 4, &b).expect("defined");
        assert!((e[0] - 0.5 / 3f32.sqrt()).abs() < 1e-6 && e[1] == 0.0);
        assert_eq!(pixel_error_estimate(4, &a, 4, &b), None);
        let (rmse, rel) = errors(&[[1.1, 1.1, 1.1]], &[[1.0, 1.0, 1.0]]);
        assert!((rmse - 0.1).abs() < 1e-6 && (rel - 0.01 / 1.01).abs() < 1e-6);
        assert_eq!(errors(&b, &b), (0.0, 0.0));
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
