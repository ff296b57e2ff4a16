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
//! the blur falling as the radii² do, as `(n − n₁)^(−(1−α))` from the epoch's first frame's
//! `n₁` photons (photon mapping restarts its caustic estimates at their chosen radii after
//! the first pass), that product gives the blur at `n_b`. Only once the oldest of the three
//! is [`BLUR_SETTLED_PASSES`] passes past the first: in their first steps the radii fall
//! faster than the power law. The noise does enter the product's spread: where a few bright
//! pixels make it (pool's rare paths), a product within two standard errors of zero (over
//! runs of [`BLUR_BLOCK`] pixels) counts as no blur found. Solving for noise and blur from
//! the two differences' squares instead was tried: it subtracts one large noise from
//! another, and said 0–3.6 times the truth.
//!
//! **Few pixels.** A mean square over pixels is only as steady as the number of pixels that
//! carry it. Where the error is in a few bright pixels — a light seen in a pixel's corner
//! (the built-in scene: a pixel that sees a light of radiance ~3,000 in one pass of sixty
//! reads 0 after 32 passes, 51 after 64 and 50 in the reference), a rare caustic path's
//! speck (`scenes/pool.toml`), a focus a few pixels wide (`scenes/lens.toml`) — one frame's
//! true error is itself a matter of luck (lens: 3.5 % after 48 passes, 0.85 % after 64),
//! which no estimate from the frames can follow. [`ErrorEstimate::pixels`] counts
//! the pixels the half comparison effectively rests on, `(Σd²)²/Σd⁴`; below [`FEW_PIXELS`]
//! the estimate is marked uncertain and the plot says why. Measured on those three scenes:
//! the true error rests on 1–12 pixels of 19,200, the estimate on 1–10; on ring and
//! glass_teapot, on about a thousand.
//!
//! **Restarts.** Some pixels' estimates start again partway through an epoch, no longer
//! counting the passes before ([`Restarts`], from the frame): a lamp outline's light seen at
//! its first supersampled pass (the `seen` module: Kirk & Arvo's remedy for an adaptive
//! choice), and every pixel at photon mapping's adaptive-radius restart after the first pass.
//! There the later frame does not hold the earlier one's samples, and their difference is
//! both frames' noise: `scenes/leaf.toml` after 16 passes, compared with the frame after 7
//! while its outlines restarted at pass 9, read 1.9 times the true error. So each pixel is
//! compared by its own samples: one that restarted after `R` photons counts the share
//! `ρ = (n_a − R)/(n_b − R)` of them the earlier frame holds, and one that restarted after
//! the earlier frame is left out (and out of the blur's product). Where the pixels left out
//! hold [`SETTLING_SHARE`] of the image's squared radiance, or [`SETTLING_SHARE_OF_DIFFERENCE`]
//! of the two frames' difference, the estimate cannot see their error and says it is
//! settling. Frames from before the adaptive radius's restart are compared with none, so a
//! render's first estimate comes a few passes in.
//!
//! Measured (`caustic bench estimate SCENES --passes 16,64,256`: 160 pixels wide, as the
//! viewer renders, against 4000-pass references; the 20 shipped scenes, 60 checks, the
//! estimate over the true error): 39 within 1.5 times, 11 outside or near it and marked
//! uncertain, 10 outside and not marked (before restarts were told: 41, 7 and 12).
//!
//! - Within after 16, 64 and 256 passes: design, design_pool, glass_teapot, inline_patch,
//!   ring, ring_gold, ring_usd, ring_window (0.65–1.46).
//! - Marked uncertain, in a few pixels: the built-in scene after 16 (2.2), lens after 16
//!   (5.7), hairpin after 16 and 64 (0.45, 0.40), pool after 256 (0.49), prism after 16 and
//!   256 (0.38, 1.63), showcase after 64 (0.61); settling: lens_dispersive, scroll and
//!   teapot after 16 (0.61, 0.52, 0.65). Leaf and scroll after 16 read 1.91 and 1.54 times
//!   the truth before restarts were told; leaf now reads 1.15.
//! - Not marked: late underestimates where the true error holds a bias that barely falls
//!   between the frames, which no comparison of them can see (after 256 passes cornell 0.54,
//!   hairpin 0.30, leaf 0.42, teapot 0.34; lens_dispersive 0.64 and 0.54 after 64 and 256,
//!   teapot 0.54 after 64; smallppm 0.29–0.36 throughout, its true error in 15 pixels and
//!   its noise spread over hundreds). Where that error lies was looked at on teapot,
//!   smallppm and cornell after 256 passes: along the room's corners, the lid's rim and the
//!   teapot's foot, and in smallppm's focused caustic under the glass sphere — photon
//!   mapping's blur where the light changes within a search radius. At an edge it shrinks
//!   as the radius, `n^(−(1−α)/2)`, and its mean square as the radius too, so from one frame
//!   to the one of twice the photons it changes by about 5 %, below the noise; the
//!   4000-pass reference still holds two thirds of it. For cornell and lens_dispersive part
//!   of it is the viewer's: its first pass has 16,384 photons, and photon mapping's radius
//!   choices made from it (the indirect radius, the adaptive radii) differ from a full
//!   pass's; made as a full pass would, the estimate is 0.90 and 0.92 times the truth after
//!   256 passes (not adopted: at 640×480 cornell's own error after 16 and 64 passes grew from
//!   0.61 and 0.31 % to 0.78 and 0.41 % against a 500-pass reference; on teapot the truth
//!   after 256 passes fell from 4.12 to 3.80 % and the estimate rose to 0.48 of it).
//!
//! Frames are kept at photon counts at least [`KEEP_RATIO`] apart and dropped once a later
//! one serves as well, so about seven are held at a time.

use std::sync::Arc;

/// Where and when a progressive render's estimates started again in an epoch, no longer
/// counting the passes before ([`crate::render::frame::Frame::restarts`]): there, a frame from
/// before the restart is no part of later frames.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Restarts {
    /// Photons before the pass at which every pixel's estimates started again, counting that
    /// pass and those after it only (photon mapping's adaptive radius, at the second pass; 0:
    /// none did). A frame of no more photons is no part of later ones.
    pub all: u64,
    /// Pixels whose estimates started again, each once, with the photons before that pass (a
    /// lamp outline's light seen at its first supersampled pass).
    pub pixels: Arc<[(u32, u64)]>,
}

impl Restarts {
    /// Each of `pixels` pixels' latest restart, in photons (0: none); `None` when no pixel
    /// restarted on its own (at most every pixel together, [`Restarts::all`]).
    fn per_pixel(&self, pixels: usize) -> Option<Vec<u64>> {
        if self.pixels.is_empty() {
            return None;
        }
        let mut at = vec![self.all; pixels];
        for &(p, photons) in self.pixels.iter() {
            if let Some(r) = at.get_mut(p as usize) {
                *r = (*r).max(photons);
            }
        }
        Some(at)
    }
}

/// A frame compared from before some pixels' restart is settling
/// ([`ErrorEstimate::settling`]) once those pixels hold this share of the frame's squared
/// radiance: left out, they would leave the estimate blind to their error.
pub const SETTLING_SHARE: f64 = 0.01;

/// ... or this share of the two frames' squared difference. Their difference, both frames'
/// noise, bounds the later frame's there: left out, they may hold as large a share of its
/// error, and the estimate be low by `1/√(1 − share)` (1.12 times at a fifth). On
/// `scenes/lens_dispersive.toml` after 16 passes they held a third, and the estimate without
/// them was 0.61 times the truth (0.75 with them, compared as if they had not restarted).
pub const SETTLING_SHARE_OF_DIFFERENCE: f64 = 0.2;

/// Kept frames' photon counts grow at least this much from one to the next.
pub const KEEP_RATIO: f64 = 1.25;

/// One kept frame.
#[derive(Clone)]
struct Kept {
    photons: u64,
    radiance: Arc<[[f32; 3]]>,
}

/// Below this many effective pixels ([`ErrorEstimate::pixels`]) an estimate is uncertain:
/// if the frame's true error and the estimate each rested on `k` independent pixels (their
/// mean squares χ²-distributed with `k` degrees of freedom), their ratio would lie outside
/// 1/1.5–1.5 in 39 % of frames for `k = 5`, 22 % for 10 and 8 % for 20 (simulated).
pub const FEW_PIXELS: f64 = 20.0;

/// The estimated error of one frame ([`ErrorTracker::add`]), relative to its RMS radiance.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ErrorEstimate {
    /// The relative RMS noise.
    pub noise: f64,
    /// The relative RMS blur (photon mapping's bias), from three frames after
    /// `n_c < n_a < n_b` photons: `None` until there are three, for plain means (α = 1), or
    /// when undefined.
    pub blur: Option<f64>,
    /// How many pixels the noise estimate effectively rests on: `(Σ d²)² / Σ d⁴` over the
    /// pixels' squared differences `d²` between the two frames compared (the pixel count
    /// where every pixel differs alike, 1 where one pixel makes all the difference).
    pub pixels: f64,
    /// Whether the earlier frame compared came before some pixels' estimates started again
    /// ([`Restarts`]), and those pixels hold at least [`SETTLING_SHARE`] of the frame's squared
    /// radiance or [`SETTLING_SHARE_OF_DIFFERENCE`] of the two frames' squared difference. The
    /// later frame holds none of the earlier one's samples there, so their
    /// difference is both frames' noise, not the later one's alone: they are left out of the
    /// estimate, which then cannot see their error.
    pub settling: bool,
}

impl ErrorEstimate {
    /// Noise and blur together ([`total_error`]).
    pub fn total(&self) -> f64 {
        total_error(self.noise, self.blur)
    }

    /// Whether the estimate is uncertain ([`ErrorEstimate::why_uncertain`]).
    pub fn uncertain(&self) -> bool {
        self.why_uncertain().is_some()
    }

    /// Why the estimate may be far from the frame's true error, either way, in words for the
    /// plot: the estimate rests on fewer than [`FEW_PIXELS`] effective pixels (the error is in
    /// a few bright pixels that come and go, and one frame's true error is a matter of luck),
    /// or the frames compared straddle a restart of some pixels' estimates (`settling`).
    /// `None` when neither.
    pub fn why_uncertain(&self) -> Option<String> {
        if self.pixels < FEW_PIXELS {
            Some(format!("in ~{:.0} pixels", self.pixels.max(1.0)))
        } else if self.settling {
            Some("settling".into())
        } else {
            None
        }
    }
}

/// The effective number of pixels `(Σ d²)² / Σ d⁴` that frames `a` and `b` differ in, `d²`
/// each pixel's squared difference summed over its channels ([`ErrorEstimate::pixels`]).
pub fn effective_pixels(a: &[[f32; 3]], b: &[[f32; 3]]) -> f64 {
    let (mut s2, mut s4) = (0.0f64, 0.0f64);
    for (pa, pb) in a.iter().zip(b) {
        let d2: f64 = (0..3).map(|c| (pb[c] as f64 - pa[c] as f64).powi(2)).sum();
        s2 += d2;
        s4 += d2 * d2;
    }
    if s4 > 0.0 {
        s2 * s2 / s4
    } else {
        0.0
    }
}

/// The running error estimate of one epoch ([`ErrorTracker::add`]).
#[derive(Clone, Default)]
pub struct ErrorTracker {
    kept: Vec<Kept>,
    /// Photons of the epoch's first frame, whose radius choices the later passes' radii
    /// start from ([`blur_estimate`]'s origin).
    first: Option<u64>,
    /// Photons of the last frame added (a pass's photons are the difference).
    previous: u64,
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

/// The blur is estimated once the oldest of its three frames is this many passes (of the
/// newest frame's photons) past the epoch's first frame: before that, the radii are in their
/// first steps (a slot's first photons shrink its radius² by α at once, where the power law
/// assumes many), and the blur fell faster than the model, which then overestimated it
/// (`scenes/glass_teapot.toml` after 16 passes: noise and blur 2.7 times the true error, the
/// noise alone 1.4).
pub const BLUR_SETTLED_PASSES: u64 = 4;

/// Pixels a block of the blur's significance test holds (runs of the image in memory order).
pub const BLUR_BLOCK: usize = 64;

/// The relative RMS blur of frame `b` from frames `c`, `a`, `b` after `n_c < n_a < n_b`
/// photons of one render with photon mapping's `alpha`: the mean over pixels and channels of
/// `(L_b − L_a)(L_a − L_c)`, whose noise has zero mean (the two differences are of disjoint
/// photons' means, up to the growth of their variance), is the product of the blur's two
/// changes; with the blur falling as `(n − origin)^(−(1−α))`, that product gives the blur at
/// `n_b`. `origin`: the photons of the epoch's first pass, after which photon mapping
/// restarts its caustic estimates at their chosen radii (0 to count every photon). Pixels
/// whose estimates started again after `n_c` (`restart_of`: each pixel's latest restart, in
/// photons) are left out: there the differences are not of disjoint photons.
pub fn blur_estimate(
    frames: [(u64, &Arc<[[f32; 3]]>); 3],
    origin: u64,
    alpha: f64,
    restart_of: Option<&[u64]>,
) -> Option<f64> {
    let [(n_c, c), (n_a, a), (n_b, b)] = frames;
    if alpha >= 1.0 || !(n_c > origin && n_c < n_a && n_a < n_b) || a.len() != b.len() || c.len() != b.len() {
        return None;
    }
    let gamma = (1.0 - alpha).clamp(0.05, 0.95);
    let s = |n: u64| ((n - origin) as f64).powf(-gamma);
    let (s_c, s_a, s_b) = (s(n_c), s(n_a), s(n_b));
    // The products summed in runs of BLUR_BLOCK pixels: neighbouring pixels share photons
    // (their noise is correlated), runs of them far less.
    let (mut blocks, mut norm2) = (Vec::with_capacity(b.len() / BLUR_BLOCK + 1), 0.0f64);
    for (block, ((rc, ra), rb)) in c
        .chunks(BLUR_BLOCK)
        .zip(a.chunks(BLUR_BLOCK))
        .zip(b.chunks(BLUR_BLOCK))
        .enumerate()
    {
        let mut sum = 0.0f64;
        for (j, ((pc, pa), pb)) in rc.iter().zip(ra).zip(rb).enumerate() {
            if restart_of.is_some_and(|r| r[block * BLUR_BLOCK + j] >= n_c) {
                continue;
            }
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

/// The sums of the half comparison of frames `a` and `b` after `n_a < n_b` photons
/// ([`half_comparison`]), each over pixels and channels.
struct HalfComparison {
    /// `Σ (L_b − L_a)² / g`, `g` each pixel's [`noise_factor`].
    diff2: f64,
    /// `Σ L_b²` over the pixels compared.
    norm2: f64,
    /// `Σ L_b²` over the pixels left out.
    left_out: f64,
    /// `Σ (L_b − L_a)²` over the pixels left out, and over those compared.
    left_out_diff2: f64,
    compared_diff2: f64,
    /// [`effective_pixels`] of the pixels compared.
    pixels: f64,
}

/// Frames `a` and `b` after `n_a < n_b` photons compared pixel by pixel, each pixel's squared
/// difference over its noise factor `g(ρ)`: `ρ = n_a/n_b`, or for a pixel whose estimates
/// started again after `R` photons (`all` of them, or each by `restart_of`, which includes
/// `all`), `ρ = (n_a − R)/(n_b − R)`, the share of
/// its samples since that `a` holds. A pixel that started again after `a` (`R ≥ n_a`) is left
/// out: `b` holds none of `a`'s samples there.
fn half_comparison(
    (n_a, a): (u64, &[[f32; 3]]),
    (n_b, b): (u64, &[[f32; 3]]),
    alpha: f64,
    (all, restart_of): (u64, Option<&[u64]>),
) -> HalfComparison {
    let alpha = alpha.clamp(0.05, 1.0);
    // Every pixel's factor when it restarted with all of them (or never): computed once, as
    // a pixel of its own restart is rare (a lamp's outline).
    let g_all = noise_factor((n_a - all.min(n_a)) as f64 / (n_b - all.min(n_a)) as f64, alpha);
    let (mut diff2, mut norm2, mut left_out, mut left_out_diff2) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
    let (mut raw, mut raw4) = (0.0f64, 0.0f64);
    for (i, (pa, pb)) in a.iter().zip(b).enumerate() {
        let r = restart_of.map_or(all, |r| r[i]);
        let own: f64 = (0..3).map(|c| (pb[c] as f64).powi(2)).sum();
        let d2: f64 = (0..3).map(|c| (pb[c] as f64 - pa[c] as f64).powi(2)).sum();
        if r >= n_a && r > 0 {
            left_out += own;
            left_out_diff2 += d2;
            continue;
        }
        let g = if r == all {
            g_all
        } else {
            noise_factor((n_a - r) as f64 / (n_b - r) as f64, alpha)
        };
        diff2 += d2 / g;
        norm2 += own;
        raw += d2;
        raw4 += d2 * d2;
    }
    HalfComparison {
        diff2,
        norm2,
        left_out,
        left_out_diff2,
        compared_diff2: raw,
        pixels: if raw4 > 0.0 { raw * raw / raw4 } else { 0.0 },
    }
}

impl ErrorTracker {
    /// Takes the epoch's frame after `photons` photons, rendered with photon mapping's
    /// `alpha` (1 for plain means, as a path tracer's), with the epoch's `restarts` so far;
    /// returns its estimated relative RMS noise and blur and the pixels the noise rests on
    /// (`None` for the first frame, a frame with no more photons than the last, or an
    /// undefined estimate: a black image).
    pub fn add(
        &mut self,
        (photons, restarts): (u64, &Restarts),
        radiance: &Arc<[[f32; 3]]>,
        alpha: f64,
    ) -> Option<ErrorEstimate> {
        let origin = *self.first.get_or_insert(photons);
        let last = self.kept.last().map_or(0, |k| k.photons);
        let previous = std::mem::replace(&mut self.previous, photons);
        if photons <= last && !self.kept.is_empty() {
            return None;
        }
        // The newest kept frame with at most half the photons, else the oldest one.
        let at = self
            .kept
            .iter()
            .rposition(|k| k.photons <= photons / 2)
            .unwrap_or(0);
        let restart_of = restarts.per_pixel(radiance.len());
        let restart_of = restart_of.as_deref();
        let mut settling = false;
        let estimate = self.kept.get(at).and_then(|k| {
            if k.photons == 0 || k.radiance.len() != radiance.len() {
                return None;
            }
            let c = half_comparison(
                (k.photons, &k.radiance),
                (photons, radiance),
                alpha,
                (restarts.all, restart_of),
            );
            settling = c.left_out > SETTLING_SHARE * c.norm2
                || c.left_out_diff2 > SETTLING_SHARE_OF_DIFFERENCE * (c.left_out_diff2 + c.compared_diff2);
            let relative = (c.diff2 / c.norm2).sqrt();
            (c.norm2 > 0.0 && relative.is_finite()).then_some((relative, c.pixels))
        });
        // The newest kept frame with at most half of that one's photons: the blur's third.
        let quarter = self
            .kept
            .get(at)
            .and_then(|a| self.kept[..at].iter().rposition(|k| k.photons <= a.photons / 2));
        let blur = quarter.and_then(|c| {
            let (c, a) = (&self.kept[c], &self.kept[at]);
            // Early frames follow the radii's first steps, not their power law; before the
            // restart of every pixel, the oldest is no part of the others.
            if c.photons.saturating_sub(origin) < BLUR_SETTLED_PASSES * photons.saturating_sub(previous)
                || c.photons <= restarts.all
            {
                return None;
            }
            blur_estimate(
                [
                    (c.photons, &c.radiance),
                    (a.photons, &a.radiance),
                    (photons, radiance),
                ],
                origin,
                alpha,
                restart_of,
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
        estimate.map(|(noise, pixels)| ErrorEstimate {
            noise,
            blur,
            pixels,
            settling,
        })
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

    /// Frames whose blur falls as `(n − n₁)^(−(1−α))` under the noise of a mean of
    /// independent passes: from the frame [`BLUR_SETTLED_PASSES`] past the first on, with the
    /// noise below the blur, the blur is found within 5 %; whatever the
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
                // As photon mapping's radii, restarted after the first pass.
                let bias = (pass.max(2) as f64 - 1.0).powf(-0.3);
                let frame: Arc<[[f32; 3]]> = sum
                    .iter()
                    .zip(&beta)
                    .map(|(s, b)| [(s / pass as f64 + b * bias) as f32; 3])
                    .collect();
                let estimate = tracker.add((pass * 1000, &Restarts::default()), &frame, 0.7);
                if pass == 16 {
                    // The oldest of the three frames is 3 passes past the first.
                    assert_eq!(estimate.and_then(|e| e.blur), None, "no blur before it settles");
                }
                if ![32, 64, 256].contains(&pass) {
                    continue;
                }
                let rms = |f: &dyn Fn(usize) -> f64| {
                    ((0..pixels).map(|p| f(p).powi(2)).sum::<f64>() / pixels as f64).sqrt()
                };
                let norm = rms(&|p| frame[p][0] as f64);
                let true_blur = rms(&|p| beta[p] * bias) / norm;
                let true_error = rms(&|p| frame[p][0] as f64 - 1.0) / norm;
                let estimate = estimate.expect("two frames");
                let (noise, blur) = (estimate.noise, estimate.blur.expect("three frames"));
                assert!(!estimate.uncertain(), "{} pixels", estimate.pixels);
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

    /// A tenth of the pixels, noisy ones, start their means again at pass 9 (as a lamp's
    /// outline does at its first supersampled pass): while the frame compared is from before,
    /// they are left out and the estimate says it is settling; from then on each counts the
    /// share of its own samples the earlier frame holds, and the estimate is within 10 % of
    /// the true error. Without the restarts told, it is far off.
    #[test]
    fn pixels_that_start_again_are_compared_by_their_own_samples() {
        let pixels = 20_000;
        let restart_pass = 9u64;
        let noisy = |p: usize| p.is_multiple_of(10);
        let told = Restarts {
            all: 0,
            pixels: (0..pixels as u32)
                .filter(|&p| noisy(p as usize))
                .map(|p| (p, (restart_pass - 1) * 1000))
                .collect(),
        };
        for tell in [true, false] {
            let mut rng = rand_pcg::Pcg64::seed_from_u64(3);
            let (mut sum, mut count) = (vec![0.0f64; pixels], vec![0u64; pixels]);
            let mut tracker = ErrorTracker::default();
            let mut ratios = Vec::new();
            for pass in 1..=64u64 {
                if pass == restart_pass {
                    for p in (0..pixels).filter(|&p| noisy(p)) {
                        (sum[p], count[p]) = (0.0, 0);
                    }
                }
                for (p, (s, c)) in sum.iter_mut().zip(&mut count).enumerate() {
                    let spread = if noisy(p) { 20.0 } else { 1.0 };
                    *s += 1.0 + (rng.random::<f64>() - 0.5) * spread;
                    *c += 1;
                }
                let frame: Arc<[[f32; 3]]> = sum
                    .iter()
                    .zip(&count)
                    .map(|(s, &c)| [(s / c as f64) as f32; 3])
                    .collect();
                let restarts = if tell && pass >= restart_pass {
                    told.clone()
                } else {
                    Restarts::default()
                };
                let Some(e) = tracker.add((pass * 1000, &restarts), &frame, 1.0) else {
                    continue;
                };
                let truth =
                    (frame.iter().map(|p| (p[0] as f64 - 1.0).powi(2)).sum::<f64>() / pixels as f64).sqrt();
                let rms = (frame.iter().map(|p| (p[0] as f64).powi(2)).sum::<f64>() / pixels as f64).sqrt();
                if pass == 16 && tell {
                    assert!(
                        e.settling && e.uncertain(),
                        "pass 16 compares with a frame before the restart"
                    );
                }
                if pass >= 2 * restart_pass {
                    assert!(!e.settling, "pass {pass}");
                    ratios.push(e.noise * rms / truth);
                }
            }
            let worst = ratios.iter().map(|r| (r - 1.0).abs()).fold(0.0, f64::max);
            if tell {
                assert!(worst < 0.1, "{ratios:?}");
            } else {
                assert!(worst > 0.5, "untold, the restart reads as noise: {ratios:?}");
            }
        }
    }

    /// One pixel's difference is one effective pixel; differences alike everywhere are the
    /// pixel count; none is none.
    #[test]
    fn effective_pixels_count_where_the_difference_is() {
        let a: Vec<[f32; 3]> = vec![[1.0; 3]; 400];
        let mut b = a.clone();
        assert_eq!(effective_pixels(&a, &b), 0.0);
        b[17] = [3.0, 1.0, 1.0];
        assert!((effective_pixels(&a, &b) - 1.0).abs() < 1e-12);
        let c: Vec<[f32; 3]> = a
            .iter()
            .enumerate()
            .map(|(k, p)| [p[0] + if k % 2 == 0 { 0.5 } else { -0.5 }; 3])
            .collect();
        assert!((effective_pixels(&a, &c) - 400.0).abs() < 1e-9);
        b[18] = [3.0, 1.0, 1.0];
        assert!((effective_pixels(&a, &b) - 2.0).abs() < 1e-12);
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
            let estimate = tracker.add((pass * 1000, &Restarts::default()), &frame, 0.7);
            if [16, 64, 256].contains(&pass) {
                let truth =
                    (frame.iter().map(|p| (p[0] as f64 - 1.0).powi(2)).sum::<f64>() / pixels as f64).sqrt();
                let rms_b = (frame.iter().map(|p| (p[0] as f64).powi(2)).sum::<f64>() / pixels as f64).sqrt();
                let estimate = estimate.expect("defined").noise * rms_b;
                assert!(
                    (estimate / truth - 1.0).abs() < 0.1,
                    "pass {pass}: estimate {estimate} against {truth}"
                );
                assert!(tracker.held().len() <= 8, "held {:?}", tracker.held());
            }
        }
    }
}
