//! The light a pixel sees directly, supersampled where it changes within the pixel.
//!
//! A stochastic pass traces one eye ray per pixel. Its visible point gathers photons; what the
//! ray met on its way is that pass's sample of the pixel's *light seen*: emission, seen
//! directly or through mirrors and glass, and point and spot lights by shadow ray at the
//! visible point. Where that light has an edge inside the pixel (a lamp's outline, or the
//! lamp's image in a mirror or a glass sphere), the pass's one sample is either the lamp or
//! not. Even stratified over passes ([`crate::render::sequence`]), the pixel's error after
//! `n` passes is then about the lamp's radiance over `n`. Those few pixels hold most of a
//! Cornell box's squared error: after 110 passes at 320×240, 100 pixels of 76,800 held 75 %
//! of it, every one on the lamp's outline or its images.
//!
//! The light seen is an integral over the pixel of its own, apart from the photons' part, so
//! it may take more samples than the visible point does. After every eye pass, each pixel's
//! light seen in that pass is compared with its eight neighbours'. A pixel whose largest difference exceeds
//! [`CONTRAST`] times the pass's mean light seen is a candidate; the outline of a lamp that
//! covers less than 1/[`CONTRAST`] of the image qualifies. The candidates with the largest
//! differences are chosen while the budget lasts: chosen pixels add at most [`BUDGET`] to
//! the pass's eye rays. From the next pass on, each chosen pixel traces [`SUBSAMPLES`] more
//! eye rays a pass that only look for light seen, on low-discrepancy sequences of their own.
//! Consecutive blocks of Sobol's points stratify the pixel, so the outline's error falls
//! about as 1/(16 n).
//!
//! A second choice looks at each pixel over passes rather than beside its neighbours. After
//! [`VARIANCE_PASSES`] passes, the pixels whose light seen varied most between them, more than
//! [`VARIANCE_FACTOR`] times the image's mean variance, take [`VARIED_SUBSAMPLES`] extra rays a
//! pass, largest variance first, in what the budget leaves. Those are the pixels a texture's
//! edge or a shadow's crosses, and those that see the floor through glass, whose one chosen path
//! lands somewhere else every pass. On `scenes/glass_teapot.toml` (320×240) 5 % of the pixels
//! held 93 % of the light seen's variance after 43 passes (two seeds' difference), and the
//! choice (3.9 % of the pixels) cut that variance from 5.8e-6 to 2.6e-6 for a seventh more eye
//! time; the image's RMSE after 46 passes fell from 4.70e-3–4.78e-3 to 4.40e-3–4.49e-3 (seeds
//! 1–3) for 7 % more time.
//!
//! Only the light seen is supersampled: the visible point, and with it the share of the pixel
//! that reflects photons and area light, still comes from the pixel's one eye ray a pass.
//! Where the surface behind a lamp is nearly as bright as the lamp, its outline gains less.
//!
//! A pixel's choice depends on the light it saw before, so a chosen pixel's light seen counts
//! only the passes after it was chosen. This is Kirk & Arvo's remedy (1991, "Unbiased
//! sampling techniques for image synthesis"): an adaptive decision made on samples that the
//! estimate then discards leaves the estimate unbiased. The extra rays' sequences are
//! randomised by offsets of their own, which no decision has looked at. A choice is never
//! taken back.
//!
//! On the global radius schedule the pilot pass makes the choice and it is then kept, so
//! every pass depends on `(seed, pass)` alone ([`super::global`]).

use glam::{DVec2, DVec3, Vec3};
use rand::Rng;
use rayon::prelude::*;

use super::streams;
use super::visible::{trace_eye, Branching, ShadowRays};
use crate::render::rng::stream_rng;
use crate::render::sequence;
use crate::scene::camera::EyeRays;
use crate::scene::Scene;

/// Extra eye rays a pass in a supersampled pixel. A power of two: each pass's block of Sobol's
/// points is then a (0, 4, 2)-net, one point in each of 16 dyadic boxes of any shape.
pub const SUBSAMPLES: u32 = 16;

/// The most the extra rays may add to a pass's eye rays, as a share of them. A quarter means
/// at most 1/64 of the pixels are supersampled.
pub const BUDGET: f64 = 0.25;

/// How many times the pass's mean light seen a pixel's difference from a neighbour must exceed
/// for the pixel to be supersampled. Lamps' outlines and their images exceed it by far; below
/// it, the edges of an ordinary lit surface (a checker floor seen through glass) would be
/// chosen too, whose extra rays cost much and buy little.
pub const CONTRAST: f32 = 8.0;

/// Extra eye rays a pass in a pixel chosen for its variance between passes. A power of two,
/// as [`SUBSAMPLES`]. Fewer than an outline's: these pixels are many more (a checker floor's
/// edges, a glass object), and their light changes by less: beyond 4, the extra rays' cost
/// grows faster than the error falls.
pub const VARIED_SUBSAMPLES: u32 = 4;

/// Completed passes whose light seen per pixel gives the variances the second choice is made
/// from ([`SeenLight::choose_by_variance`]).
pub const VARIANCE_PASSES: u32 = 8;

/// How many times the image's mean variance a pixel's variance must exceed to be chosen for
/// it: a few per cent of the pixels hold most of the light seen's variance, and those are
/// what it chooses.
pub const VARIANCE_FACTOR: f64 = 8.0;

/// The value a pixel's light seen is compared by: the mean of its channels.
fn value(c: &Vec3) -> f32 {
    (c.x + c.y + c.z) / 3.0
}

/// Pixel `i`'s bit in a one-bit-per-pixel set.
fn bit(set: &[u64], i: usize) -> bool {
    set.get(i / 64).is_some_and(|w| w >> (i % 64) & 1 == 1)
}

/// Sets pixel `i`'s bit in a one-bit-per-pixel set.
fn set_bit(set: &mut [u64], i: usize) {
    set[i / 64] |= 1 << (i % 64);
}

/// Which pixels take extra samples of the light they see, chosen from completed passes.
#[derive(Clone, Debug, Default)]
pub struct SeenLight {
    /// Pixels in the image.
    pixels: usize,
    /// One bit per pixel: whether it takes extra rays a pass ([`SeenLight::subsamples`]).
    chosen: Vec<u64>,
    /// The chosen pixels, in pixel order, each with the eye passes completed when it was chosen.
    since: Vec<(u32, u32)>,
    /// The last complete eye pass's candidates, largest difference first.
    candidates: Vec<u32>,
    /// Pixels chosen whose light seen so far still counts ([`SeenLight::take_pending`]).
    pending: Vec<u32>,
    /// One bit per pixel: chosen for the variance of its light seen between passes
    /// ([`SeenLight::choose_by_variance`]), taking [`VARIED_SUBSAMPLES`] extra rays a pass
    /// rather than [`SUBSAMPLES`].
    varied: Vec<u64>,
    /// Extra eye rays a pass of the chosen pixels together: what the budget counts.
    rays: usize,
    /// Per pixel, the sum of its light seen's value squared over the completed passes, until
    /// the pixels of largest variance are chosen (then emptied).
    squares: Vec<f32>,
}

impl SeenLight {
    /// Nothing chosen yet in a `pixels`-pixel image (0: supersampling is off); with
    /// `by_variance`, pixels are also chosen for their variance between passes
    /// ([`SeenLight::choose_by_variance`]; without it, [`SeenLight::tally`] keeps nothing).
    pub fn new(pixels: usize, by_variance: bool) -> Self {
        Self {
            pixels,
            chosen: vec![0; pixels.div_ceil(64)],
            varied: vec![0; pixels.div_ceil(64)],
            squares: if by_variance {
                vec![0.0; pixels]
            } else {
                Vec::new()
            },
            ..Self::default()
        }
    }

    /// Whether pixel `i` takes extra samples.
    pub fn chosen(&self, i: usize) -> bool {
        bit(&self.chosen, i)
    }

    /// Extra rays pixel `i` takes (0 when not chosen).
    pub fn subsamples(&self, i: usize) -> u32 {
        if !self.chosen(i) {
            0
        } else if bit(&self.varied, i) {
            VARIED_SUBSAMPLES
        } else {
            SUBSAMPLES
        }
    }

    /// Adds a completed pass's light seen per pixel (before it joins the sums) to the
    /// squares, until the pixels of largest variance are chosen (never without `by_variance`).
    pub fn tally(&mut self, seen: &[Vec3]) {
        if seen.len() != self.squares.len() {
            return;
        }
        for (square, c) in self.squares.iter_mut().zip(seen) {
            let v = value(c);
            *square += v * v;
        }
    }

    /// After the [`VARIANCE_PASSES`]-th completed pass (`eye_passes`), whose light seen per
    /// pixel sums to `sums`: chooses the pixels not chosen yet whose light seen varied most
    /// between those passes, more than [`VARIANCE_FACTOR`] times the image's mean variance,
    /// largest first (ties by pixel), while the budget lasts. They take [`VARIED_SUBSAMPLES`]
    /// extra rays a pass from the next pass on. The squares are then dropped: the choice is
    /// made once.
    pub fn choose_by_variance(&mut self, sums: &[DVec3], eye_passes: u32) {
        if eye_passes != VARIANCE_PASSES || sums.len() != self.squares.len() || self.pixels == 0 {
            return;
        }
        let n = eye_passes as f64;
        // The sample variance of each pixel's value over the passes (0 for a chosen pixel,
        // whose passes were supersampled). In pixel order, not in parallel: the mean, and so
        // the choice, must not depend on how the work was split between threads.
        let variance: Vec<f64> = (0..sums.len())
            .map(|i| {
                if self.chosen(i) {
                    return 0.0;
                }
                let mean = (sums[i].x + sums[i].y + sums[i].z) / 3.0 / n;
                ((self.squares[i] as f64 - n * mean * mean) / (n - 1.0)).max(0.0)
            })
            .collect();
        self.squares = Vec::new();
        let threshold = VARIANCE_FACTOR * variance.iter().sum::<f64>() / variance.len() as f64;
        let mut found: Vec<(u32, f64)> = variance
            .into_iter()
            .enumerate()
            .filter(|&(_, v)| v > threshold)
            .map(|(i, v)| (i as u32, v))
            .collect();
        found.sort_unstable_by(|a, b| b.1.total_cmp(&a.1).then(a.0.cmp(&b.0)));
        found.truncate(self.room() / VARIED_SUBSAMPLES as usize);
        self.add(found.into_iter().map(|(i, _)| i), eye_passes, true);
    }

    /// Extra rays a pass the budget still allows.
    fn room(&self) -> usize {
        ((BUDGET * self.pixels as f64) as usize).saturating_sub(self.rays)
    }

    /// Chooses `pixels` (not chosen yet) after `eye_passes` completed passes: for their
    /// variance (`varied`, [`VARIED_SUBSAMPLES`] rays each) or their outline ([`SUBSAMPLES`]).
    fn add(&mut self, pixels: impl Iterator<Item = u32>, eye_passes: u32, varied: bool) {
        let rays = if varied { VARIED_SUBSAMPLES } else { SUBSAMPLES } as usize;
        for i in pixels {
            set_bit(&mut self.chosen, i as usize);
            if varied {
                set_bit(&mut self.varied, i as usize);
            }
            self.since.push((i, eye_passes));
            self.pending.push(i);
            self.rays += rays;
        }
        self.since.sort_unstable();
    }

    /// Pixels that take extra samples.
    pub fn count(&self) -> usize {
        self.since.len()
    }

    /// Of `eye_passes` completed eye passes, how many pixel `i`'s light seen counts: those
    /// since it was chosen, or all of them until its first supersampled pass completes (its
    /// sum is emptied then, see [`SeenLight::take_pending`]).
    pub fn passes(&self, i: usize, eye_passes: u32) -> u32 {
        if !self.chosen(i) {
            return eye_passes;
        }
        match self.since.binary_search_by_key(&(i as u32), |&(p, _)| p) {
            Ok(k) if eye_passes > self.since[k].1 => eye_passes - self.since[k].1,
            _ => eye_passes,
        }
    }

    /// Finds the candidates in a complete eye pass's light seen per pixel (`seen`, a
    /// `width`-wide image): the pixels not yet chosen whose light seen differs from a
    /// neighbour's by more than [`CONTRAST`] times the mean, largest difference first (ties by
    /// pixel, the same on any machine). Observing the same pass twice (an abandoned pass traced
    /// again) finds the same ones.
    pub fn observe(&mut self, seen: &[Vec3], width: usize) {
        if seen.len() != self.pixels || self.pixels == 0 || width == 0 {
            return;
        }
        // Summed in order, not in parallel: the threshold, and so the choice, must not depend
        // on how the work was split between threads.
        let mean = seen.iter().map(|c| value(c) as f64).sum::<f64>() / seen.len() as f64;
        let threshold = CONTRAST * mean as f32;
        let height = seen.len() / width;
        let mut found: Vec<(u32, f32)> = (0..seen.len())
            .into_par_iter()
            .filter(|&i| !self.chosen(i))
            .filter_map(|i| {
                let (x, y) = (i % width, i / width);
                let v = value(&seen[i]);
                let mut most = 0.0f32;
                for ny in y.saturating_sub(1)..(y + 2).min(height) {
                    for nx in x.saturating_sub(1)..(x + 2).min(width) {
                        most = most.max((v - value(&seen[ny * width + nx])).abs());
                    }
                }
                (most > threshold).then_some((i as u32, most))
            })
            .collect();
        found.sort_unstable_by(|a, b| b.1.total_cmp(&a.1).then(a.0.cmp(&b.0)));
        self.candidates = found.into_iter().map(|(i, _)| i).collect();
    }

    /// After the `eye_passes`-th completed pass: chooses the last observed candidates while
    /// the budget allows, from the next pass on.
    pub fn choose(&mut self, eye_passes: u32) {
        let mut candidates = std::mem::take(&mut self.candidates);
        candidates.truncate(self.room() / SUBSAMPLES as usize);
        self.add(candidates.into_iter(), eye_passes, false);
    }

    /// The pixels chosen since this was last asked: their light seen so far no longer counts
    /// once the pass in progress, their first supersampled one, completes.
    pub fn take_pending(&mut self) -> Vec<u32> {
        std::mem::take(&mut self.pending)
    }
}

/// What a pixel's extra eye rays need: the scene, its rays, and the pass's numbers.
pub struct Subsampler<'a> {
    /// The scene.
    pub scene: &'a Scene,
    /// The camera's rays.
    pub rays: &'a EyeRays<'a>,
    /// The render's seed.
    pub seed: u64,
    /// The pass (its sequences' block and its random streams).
    pub pass: u64,
    /// Pixels in the image (the random streams' stride).
    pub pixels: u64,
    /// Whether eye rays follow low-discrepancy sequences.
    pub stratified: bool,
    /// Direct light by shadow rays at visible points.
    pub direct_light: bool,
}

impl Subsampler<'_> {
    /// The mean light seen by `subsamples` eye rays (a power of two, the same every pass)
    /// through pixel `i` at `(x, y)`. With
    /// stratified eye rays they take this pass's block of each of the eye ray's sequences
    /// (Sobol's over the pixel, R4 over the lens, the golden-ratio one for the first choice at
    /// glass), randomised by the pixel's own offsets for its extra rays; otherwise independent
    /// random numbers.
    pub fn light_seen(&self, i: u64, x: u64, y: u64, subsamples: u32) -> DVec3 {
        let mut rng = stream_rng(self.seed, streams::SEEN, self.pass * self.pixels + i);
        let mut offsets = stream_rng(self.seed, streams::SEEN_OFFSETS, i);
        let shift: u64 = offsets.random();
        let lens_offset = DVec2::new(offsets.random(), offsets.random());
        let choice_offset: f64 = offsets.random();
        let mut sum = DVec3::ZERO;
        for j in 0..subsamples as u64 {
            let n = self.pass * subsamples as u64 + j;
            let (jitter, lens, first) = if self.stratified {
                (
                    sequence::sobol(n, shift),
                    sequence::rotated(sequence::r4(n)[0], lens_offset),
                    Some(sequence::rotated_1d(sequence::golden(n), choice_offset)),
                )
            } else {
                let jitter = DVec2::new(rng.random(), rng.random());
                (jitter, DVec2::new(rng.random(), rng.random()), None)
            };
            let pixel = DVec2::new(x as f64, y as f64) + jitter;
            sum += trace_eye(
                self.scene,
                &self.rays.ray_with_lens_sample(pixel, lens),
                i as u32,
                Branching::Choose { first },
                ShadowRays::new(self.direct_light, true),
                &mut rng,
                &mut |_| {},
            )
            .direct;
        }
        sum / subsamples as f64
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 128×128 image, dark but for a bright 4×4 lamp at (6..10, 6..10).
    fn lamp() -> Vec<Vec3> {
        let mut seen = vec![Vec3::splat(0.01); 128 * 128];
        for y in 6..10 {
            for x in 6..10 {
                seen[y * 128 + x] = Vec3::splat(30.0);
            }
        }
        seen
    }

    #[test]
    fn the_outline_of_a_lamp_is_chosen_and_its_inside_is_not() {
        let mut seen = SeenLight::new(128 * 128, true);
        seen.observe(&lamp(), 128);
        seen.choose(1);
        for y in 0..16usize {
            for x in 0..16usize {
                let ring = (5..=10).contains(&x) && (5..=10).contains(&y);
                let inside = (7..=8).contains(&x) && (7..=8).contains(&y);
                assert_eq!(seen.chosen(y * 128 + x), ring && !inside, "pixel ({x}, {y})");
            }
        }
        assert_eq!(seen.count(), 32);
        assert_eq!(seen.take_pending().len(), 32);
        assert!(seen.take_pending().is_empty());
        // Observed again, the chosen pixels are no candidates.
        seen.observe(&lamp(), 128);
        seen.choose(2);
        assert_eq!(seen.count(), 32);
    }

    #[test]
    fn a_chosen_pixel_counts_only_the_passes_after_its_first_supersampled_one_began() {
        let mut seen = SeenLight::new(128 * 128, true);
        let mut image = vec![Vec3::ZERO; 128 * 128];
        image[5] = Vec3::splat(10.0);
        seen.observe(&image, 128);
        seen.choose(4);
        assert!(seen.chosen(5) && seen.chosen(4) && !seen.chosen(7));
        assert_eq!(
            seen.passes(5, 4),
            4,
            "before its first supersampled pass completes"
        );
        assert_eq!(seen.passes(5, 5), 1);
        assert_eq!(seen.passes(5, 9), 5);
        assert_eq!(seen.passes(7, 9), 9, "a pixel not chosen counts every pass");
    }

    #[test]
    fn the_budget_bounds_the_chosen_pixels_largest_differences_first_and_choices_stay() {
        // 64×64: the budget is 4096 / 64 = 64 pixels.
        let mut seen = SeenLight::new(4096, true);
        // A bright row, brighter to the right: it and the rows beside it, 192 pixels, qualify.
        let image: Vec<Vec3> = (0..4096)
            .map(|i| {
                Vec3::splat(if i / 64 == 32 {
                    1000.0 + (i % 64) as f32
                } else {
                    0.0
                })
            })
            .collect();
        seen.observe(&image, 64);
        assert_eq!(seen.candidates.len(), 192);
        seen.choose(1);
        assert_eq!(seen.count(), 64);
        let at = |x: usize, y: usize| y * 64 + x;
        assert!(seen.chosen(at(63, 32)) && seen.chosen(at(63, 31)) && seen.chosen(at(62, 33)));
        assert!(!seen.chosen(at(0, 32)) && !seen.chosen(at(63, 30)));
        seen.observe(&vec![Vec3::ZERO; 4096], 64);
        seen.choose(2);
        assert_eq!(seen.count(), 64, "nothing more fits, nothing chosen is dropped");
        assert!(seen.chosen(at(63, 32)));
    }

    /// A 64×64 image's light seen in pass `k`: 0.5 everywhere, but alternating between 0 and
    /// `swing(i)` from pass to pass in the pixels `i` where `swing` is positive.
    fn flickering(k: u32, swing: impl Fn(usize) -> f32) -> Vec<Vec3> {
        (0..4096)
            .map(|i| {
                Vec3::splat(if swing(i) > 0.0 {
                    swing(i) * (k % 2) as f32
                } else {
                    0.5
                })
            })
            .collect()
    }

    /// A swing for [`flickering`]: pixel `i` flickers when `i % period == at`, the more the
    /// higher its index.
    fn flickering_every(period: usize, at: usize) -> impl Fn(usize) -> f32 + Copy {
        move |i| {
            if i % period == at {
                1.0 + i as f32 / 4096.0
            } else {
                0.0
            }
        }
    }

    /// Feeds `passes` completed passes to `seen` as the renderer does: the squares, the sums,
    /// then the choices.
    fn run(seen: &mut SeenLight, passes: u32, swing: impl Fn(usize) -> f32) {
        let mut sums = vec![DVec3::ZERO; 4096];
        for k in 1..=passes {
            let image = flickering(k, &swing);
            seen.tally(&image);
            for (s, c) in sums.iter_mut().zip(&image) {
                *s += c.as_dvec3();
            }
            seen.choose_by_variance(&sums, k);
        }
    }

    #[test]
    fn the_pixels_whose_light_varies_most_between_passes_are_chosen_once() {
        // Eleven pixels flicker, the brighter the higher their index; the rest are steady.
        let swing = flickering_every(400, 7);
        let mut early = SeenLight::new(4096, true);
        run(&mut early, VARIANCE_PASSES - 1, swing);
        assert_eq!(
            early.count(),
            0,
            "nothing is chosen before the variances are taken"
        );
        let mut seen = SeenLight::new(4096, true);
        run(&mut seen, VARIANCE_PASSES, swing);
        assert_eq!(seen.count(), 11);
        assert!(seen.chosen(7) && seen.chosen(3607) && !seen.chosen(8));
        assert_eq!(seen.subsamples(7), VARIED_SUBSAMPLES);
        assert_eq!(seen.subsamples(8), 0);
        assert_eq!(seen.take_pending().len(), 11);
        assert_eq!(seen.passes(7, VARIANCE_PASSES + 3), 3);
        // Without the choice by variance (the global radius schedule) nothing is chosen.
        let mut outlines_only = SeenLight::new(4096, false);
        run(&mut outlines_only, VARIANCE_PASSES, swing);
        assert_eq!(outlines_only.count(), 0);
        // Later passes choose nothing more.
        let mut sums = vec![DVec3::ZERO; 4096];
        sums[8] = DVec3::splat(1e3);
        seen.choose_by_variance(&sums, VARIANCE_PASSES + 1);
        assert_eq!(seen.count(), 11);
    }

    #[test]
    fn an_image_that_varies_evenly_chooses_nothing_and_the_budget_bounds_the_rest() {
        let mut even = SeenLight::new(4096, true);
        run(&mut even, VARIANCE_PASSES, |_| 1.0);
        assert_eq!(even.count(), 0, "no pixel varies 8 times more than the mean");
        // 400 pixels flicker: the budget, a quarter of 4096 eye rays at 4 a pixel, takes the
        // 256 that flicker most.
        let every_tenth = flickering_every(10, 3);
        let mut seen = SeenLight::new(4096, true);
        run(&mut seen, VARIANCE_PASSES, every_tenth);
        assert_eq!(seen.count(), 256);
        assert!(seen.chosen(4093) && !seen.chosen(3));
        // An outline chosen first leaves less: 16 rays for each of its pixels.
        let mut seen = SeenLight::new(4096, true);
        let mut image = vec![Vec3::ZERO; 4096];
        image[5] = Vec3::splat(10.0);
        seen.observe(&image, 64);
        seen.choose(1);
        let outline = seen.count();
        assert_eq!(outline, 6, "the pixel and its neighbours");
        assert_eq!(seen.subsamples(5), SUBSAMPLES);
        run(&mut seen, VARIANCE_PASSES, every_tenth);
        assert_eq!(seen.count(), outline + (1024 - 16 * outline) / 4);
    }

    #[test]
    fn an_even_image_chooses_nothing() {
        let mut seen = SeenLight::new(4096, true);
        seen.observe(&vec![Vec3::splat(2.0); 4096], 64);
        seen.choose(1);
        assert_eq!(seen.count(), 0);
    }
}
