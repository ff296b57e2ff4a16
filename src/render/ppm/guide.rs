//! Photons sent where the camera looks: emission guided by which photons reached a visible
//! point.
//!
//! A photon is *useful* when it hands flux to at least one visible point — the path
//! visibility of Hachisuka & Jensen 2011 ("Robust adaptive photon tracing using photon path
//! visibility"). Instead of their Markov chain, every light keeps a learned importance map in
//! the spirit of Peter & Pietrek 1998 ("Importance driven construction of photon maps"): a
//! 32×32 histogram over the two random numbers that choose where the light's photons go (the
//! direction of point, spot and sphere lights — a sphere light picks its direction first — and
//! of a quad light). Each bin's share of useful
//! photons, counted over all completed passes, becomes a piecewise-constant density over that
//! pair (sampled by inverting its marginal and conditional distributions, as pbrt-v4's
//! `PiecewiseConstant2D`), mixed with a uniform share so that every direction keeps a non-zero
//! density. A photon's flux is divided by the density of its random numbers, so the estimate
//! stays unbiased, whatever the scene — infinite planes included — and whatever was learned.
//!
//! Fewer photons, as much light or more: photon mapping's radius, and so its bias, shrinks per
//! *pass* (Hachisuka et al. 2008, eq. 9), so early passes should be cheap. An epoch's first
//! [`GAIN_DIVIDED_PASSES`] guided passes therefore emit the photons per pass divided by the
//! guide's *gain* — how many times more of its photons reach a visible point than uniform
//! emission's would — so they land about as many useful photons as unguided passes, without
//! tracing the ones that would have been lost. Later passes, whose error is mostly the photon
//! estimate's noise, divide by the gain's square root: √gain times as many useful photons as
//! an unguided pass, fewer passes, less of the time in eye passes. Dividing by the whole gain
//! throughout would leave long renders' passes mostly eye pass; by its square root throughout,
//! the first passes after an edit would be slow to come.
//!
//! Determinism: the map changes only between passes, from integer counts summed over the
//! pass's chunks, so it is the same for any number of threads.

use crate::scene::Scene;

/// Bins along each of the two guided random numbers.
pub const RESOLUTION: usize = 32;
/// Bins per light.
const BINS: usize = RESOLUTION * RESOLUTION;
/// Share of the density that stays uniform: bounds a photon's weight by its inverse (4).
const UNIFORM_SHARE: f64 = 0.25;
/// A bin whose useful share is at least this fraction of a typical useful photon's bin gets
/// the full density: photons spread evenly over what the camera sees, not piled where it sees
/// most of a bin (see [`Density2D::learned`]).
const FULL_SHARE: f64 = 0.1;
/// Photons of prior belief per bin, at the light's overall useful share: a bin's own count
/// overrides it once it has seen several times as many.
const PRIOR_PHOTONS: f64 = 16.0;
/// Photons a light must have emitted before its map is used (a few per bin).
const MIN_PHOTONS: u64 = 4 * BINS as u64;
/// The largest gain the photons per pass are divided by.
pub const MAX_GAIN: f64 = 64.0;
/// Guided passes of an epoch (or of the global schedule) that divide the photons per pass by
/// the whole gain; later ones divide by its square root.
pub const GAIN_DIVIDED_PASSES: u64 = 32;
/// A light's learned density is used only when it gains at least this much: below, as in a
/// closed room where nearly every photon lands in view, reshaping the emission buys little and
/// costs time (guided photons reach more points, each a deposit).
pub const MIN_GAIN: f64 = 1.5;

/// Emitted and useful photons per light and bin, for one chunk or one pass.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct GuideTally {
    emitted: Vec<u32>,
    useful: Vec<u32>,
}

impl GuideTally {
    /// Zero counts for `lights` lights.
    pub fn new(lights: usize) -> Self {
        Self {
            emitted: vec![0; lights * BINS],
            useful: vec![0; lights * BINS],
        }
    }

    /// Counts one photon of `light` emitted into `bin`, useful or not.
    pub fn record(&mut self, light: usize, bin: u32, useful: bool) {
        let k = light * BINS + bin as usize;
        self.emitted[k] += 1;
        self.useful[k] += useful as u32;
    }

    /// Adds another tally's counts.
    pub fn add(&mut self, other: &GuideTally) {
        for (a, b) in self.emitted.iter_mut().zip(&other.emitted) {
            *a += b;
        }
        for (a, b) in self.useful.iter_mut().zip(&other.useful) {
            *a += b;
        }
    }
}

/// The learned emission density of every light of a scene.
#[derive(Clone, Debug)]
pub struct EmissionGuide {
    lights: Vec<LightGuide>,
    /// Probability that a photon comes from each light (by power, as the photon source picks).
    pick: Vec<f64>,
}

/// One light's counts and the density built from them.
#[derive(Clone, Debug)]
struct LightGuide {
    /// Which pair of the emission's four random numbers is guided (0: the first two).
    pair: usize,
    emitted: Vec<u64>,
    useful: Vec<u64>,
    /// `None` (uniform emission) until enough photons were seen, while none was useful, and
    /// while the density would gain less than [`MIN_GAIN`].
    density: Option<Density2D>,
}

impl EmissionGuide {
    /// A uniform guide for the scene's lights (nothing learned yet); `pick` is the chance
    /// that a photon comes from each light.
    pub fn new(scene: &Scene, pick: Vec<f64>) -> Self {
        Self {
            pick,
            lights: scene
                .lights
                .iter()
                .map(|l| LightGuide {
                    pair: l.direction_pair(),
                    emitted: vec![0; BINS],
                    useful: vec![0; BINS],
                    density: None,
                })
                .collect(),
        }
    }

    /// Empty counts shaped for this guide.
    pub fn tally(&self) -> GuideTally {
        GuideTally::new(self.lights.len())
    }

    /// Warps the guided pair of `u` (four uniform numbers for `light`'s emission) by the
    /// learned density; returns the density of the result (1 where nothing is learned) and
    /// the bin it fell in.
    pub fn warp(&self, light: usize, u: &mut [f64; 4]) -> (f64, u32) {
        let g = &self.lights[light];
        let (a, b) = (2 * g.pair, 2 * g.pair + 1);
        let pdf = match &g.density {
            Some(d) => {
                let (x, y, pdf) = d.sample(u[a], u[b]);
                (u[a], u[b]) = (x, y);
                pdf
            }
            None => 1.0,
        };
        (pdf, bin_of(u[a], u[b]))
    }

    /// Adds a completed pass's counts and rebuilds every light's density.
    pub fn learn(&mut self, tally: &GuideTally) {
        for (l, g) in self.lights.iter_mut().enumerate() {
            let range = l * BINS..(l + 1) * BINS;
            for (a, b) in g.emitted.iter_mut().zip(&tally.emitted[range.clone()]) {
                *a += *b as u64;
            }
            for (a, b) in g.useful.iter_mut().zip(&tally.useful[range]) {
                *a += *b as u64;
            }
            g.density = Density2D::learned(&g.emitted, &g.useful);
        }
    }

    /// This guide as the prior of a new epoch after an edit of the scene (a warm restart):
    /// each light's counts scaled down to at most `photons` emitted, so that what the new
    /// epoch learns soon outweighs them, and the densities rebuilt from the scaled counts;
    /// lights in `moved` (their photons now go partly elsewhere) to at most `moved_photons`.
    /// The guide always mixes in uniform emission, so whatever a light kept, it stays
    /// unbiased. `None` when the scene's lights are not the guide's (another count).
    pub fn as_prior(
        &self,
        scene: &Scene,
        (photons, moved_photons): (u64, u64),
        moved: &[usize],
    ) -> Option<Self> {
        if scene.lights.len() != self.lights.len() {
            return None;
        }
        let mut prior = self.clone();
        for (l, g) in prior.lights.iter_mut().enumerate() {
            let total: u64 = g.emitted.iter().sum();
            let cap = if moved.contains(&l) {
                moved_photons
            } else {
                photons
            };
            let keep = if total > cap {
                cap as f64 / total as f64
            } else {
                1.0
            };
            // Scaling both counts by one factor and rounding down keeps useful ≤ emitted.
            for c in g.emitted.iter_mut().chain(g.useful.iter_mut()) {
                *c = (*c as f64 * keep) as u64;
            }
            g.density = Density2D::learned(&g.emitted, &g.useful);
        }
        Some(prior)
    }

    /// How many times more photons reach a visible point with the learned densities than with
    /// uniform emission (by the counts so far; 1 before anything is learned), at most
    /// [`MAX_GAIN`].
    pub fn gain(&self) -> f64 {
        let (mut guided, mut uniform) = (0.0, 0.0);
        for (g, p) in self.lights.iter().zip(&self.pick) {
            let (u, s) = match &g.density {
                Some(d) => (d.uniform_share, d.guided_share),
                None => {
                    let rate =
                        g.useful.iter().sum::<u64>() as f64 / g.emitted.iter().sum::<u64>().max(1) as f64;
                    (rate, rate)
                }
            };
            guided += p * s;
            uniform += p * u;
        }
        if uniform > 0.0 {
            (guided / uniform).clamp(1.0, MAX_GAIN)
        } else {
            1.0
        }
    }
}

/// The bin of a point of the unit square.
fn bin_of(x: f64, y: f64) -> u32 {
    let cell = |t: f64| ((t * RESOLUTION as f64) as usize).min(RESOLUTION - 1);
    (cell(x) * RESOLUTION + cell(y)) as u32
}

/// A piecewise-constant density over the unit square, `RESOLUTION²` equal bins, sampled by
/// inverting its marginal over `x` and then the conditional over `y` in the chosen column.
#[derive(Clone, Debug)]
struct Density2D {
    /// Density of each bin (its probability × `BINS`), indexed `i·RESOLUTION + j`.
    pdf: Vec<f64>,
    /// Cumulative marginal over the `x` cells: `RESOLUTION + 1` entries from 0 to 1.
    marginal: Vec<f64>,
    /// Cumulative conditional over `y` for each `x` cell: `RESOLUTION + 1` entries each.
    conditional: Vec<f64>,
    /// Expected share of useful photons under uniform emission (the bins' mean share).
    uniform_share: f64,
    /// Expected share of useful photons under this density.
    guided_share: f64,
}

impl Density2D {
    /// The density from the counts. Each bin's useful share `s` is shrunk towards the light's
    /// overall share by [`PRIOR_PHOTONS`]; a bin's weight is `min(1, s / (FULL_SHARE·s̄))`,
    /// `s̄` the share of a typical useful photon's bin (`Σs²/Σs`) — close to an indicator of
    /// "the camera sees where these photons go", as in Hachisuka & Jensen's visibility-driven
    /// sampling: weighting by the share itself would pile photons onto the regions that fill
    /// a bin and starve the rest of what the camera sees, since every visible point's photon
    /// density follows the density of the bin its light comes through. The weights are
    /// normalised and mixed with [`UNIFORM_SHARE`] of the uniform density. `None` while too
    /// few photons were emitted or none was useful, and when the density would gain less
    /// than [`MIN_GAIN`].
    fn learned(emitted: &[u64], useful: &[u64]) -> Option<Self> {
        let total: u64 = emitted.iter().sum();
        let total_useful: u64 = useful.iter().sum();
        if total < MIN_PHOTONS || total_useful == 0 {
            return None;
        }
        let overall = total_useful as f64 / total as f64;
        let share: Vec<f64> = emitted
            .iter()
            .zip(useful)
            .map(|(&e, &u)| (u as f64 + PRIOR_PHOTONS * overall) / (e as f64 + PRIOR_PHOTONS))
            .collect();
        let sum: f64 = share.iter().sum();
        let typical = share.iter().map(|s| s * s).sum::<f64>() / sum;
        let weight: Vec<f64> = share
            .iter()
            .map(|s| (s / (FULL_SHARE * typical)).min(1.0))
            .collect();
        let weights: f64 = weight.iter().sum();
        let p: Vec<f64> = weight
            .iter()
            .map(|w| (1.0 - UNIFORM_SHARE) * w / weights + UNIFORM_SHARE / BINS as f64)
            .collect();
        let uniform_share = sum / BINS as f64;
        let guided_share: f64 = p.iter().zip(&share).map(|(p, s)| p * s).sum();
        (guided_share >= MIN_GAIN * uniform_share)
            .then(|| Self::from_probabilities(&p, uniform_share, guided_share))
    }

    /// The density with bin probabilities `p` (summing to 1, all positive) and the useful
    /// shares it was built for.
    fn from_probabilities(p: &[f64], uniform_share: f64, guided_share: f64) -> Self {
        let n = RESOLUTION;
        let columns: Vec<f64> = p.chunks(n).map(|c| c.iter().sum()).collect();
        let total: f64 = columns.iter().sum();
        let mut marginal = Vec::with_capacity(n + 1);
        let mut conditional = Vec::with_capacity(n * (n + 1));
        let mut acc = 0.0;
        marginal.push(0.0);
        for (i, column) in p.chunks(n).enumerate() {
            acc += columns[i];
            marginal.push(acc / total);
            let mut row = 0.0;
            conditional.push(0.0);
            for q in column {
                row += q;
                conditional.push(row / columns[i]);
            }
            // Exact ends: rounding must not leave a sliver above the last entry.
            conditional[i * (n + 1) + n] = 1.0;
        }
        marginal[n] = 1.0;
        Self {
            pdf: p.iter().map(|q| q / total * BINS as f64).collect(),
            marginal,
            conditional,
            uniform_share,
            guided_share,
        }
    }

    /// Maps uniform `(u, v)` to a point distributed by the density, and its density.
    fn sample(&self, u: f64, v: f64) -> (f64, f64, f64) {
        let (i, x) = invert(&self.marginal, u);
        let n = RESOLUTION + 1;
        let (j, y) = invert(&self.conditional[i * n..(i + 1) * n], v);
        (x, y, self.pdf[i * RESOLUTION + j])
    }
}

/// Inverts a cumulative table of `RESOLUTION` equal cells at `u`: the cell and the point in
/// `[0, 1)`, continuous and monotonic in `u` (stratified inputs stay stratified).
fn invert(cdf: &[f64], u: f64) -> (usize, f64) {
    let cells = cdf.len() - 1;
    // The table is non-decreasing, so the entries at or below `u` are a prefix: counting them
    // finds the binary search's answer without its unpredictable branches (and vectorises).
    let at_or_below = cdf.iter().filter(|&&c| c <= u).count();
    let i = (at_or_below.max(1) - 1).min(cells - 1);
    let width = cdf[i + 1] - cdf[i];
    let t = if width > 0.0 { (u - cdf[i]) / width } else { 0.0 };
    let x = (i as f64 + t.clamp(0.0, 1.0)) / cells as f64;
    // Stay inside the cell (and below 1) whatever the rounding.
    let below_next = ((i + 1) as f64 / cells as f64).next_down();
    (i, x.clamp(i as f64 / cells as f64, below_next))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A density that favours one corner strongly.
    fn skewed() -> Density2D {
        let mut emitted = vec![100u64; BINS];
        let mut useful = vec![0u64; BINS];
        for i in 0..4 {
            for j in 0..4 {
                useful[i * RESOLUTION + j] = 90;
            }
        }
        emitted[5] = 0; // an unseen bin gets the prior
        useful[5] = 0;
        Density2D::learned(&emitted, &useful).expect("learned")
    }

    #[test]
    fn sampling_follows_the_density_and_its_weights_average_to_one() {
        let d = skewed();
        let mut rng = crate::render::rng::stream_rng(1, 0, 0);
        let mut hits = vec![0u32; BINS];
        let (mut weight_sum, n) = (0.0, 400_000);
        for _ in 0..n {
            use rand::Rng;
            let (x, y, pdf) = d.sample(rng.random(), rng.random());
            assert!((0.0..1.0).contains(&x) && (0.0..1.0).contains(&y));
            let bin = bin_of(x, y) as usize;
            assert_eq!(pdf, d.pdf[bin], "the pdf is the bin's");
            hits[bin] += 1;
            weight_sum += 1.0 / pdf;
        }
        // E[1/pdf] = 1 under the density: the estimate stays unbiased.
        assert!(
            (weight_sum / n as f64 - 1.0).abs() < 0.01,
            "{}",
            weight_sum / n as f64
        );
        for (bin, &h) in hits.iter().enumerate() {
            let expected = d.pdf[bin] / BINS as f64 * n as f64;
            assert!(
                (h as f64 - expected).abs() < 5.0 * expected.sqrt() + 2.0,
                "bin {bin}: {h} hits, expected {expected}"
            );
        }
        // The favoured corner gets most photons, every bin keeps the uniform share.
        assert!(d.pdf[0] > 10.0 && d.pdf.iter().all(|&p| p >= UNIFORM_SHARE));
        assert!(
            d.pdf[5] > d.pdf[RESOLUTION * RESOLUTION - 1],
            "prior: the overall share"
        );
    }

    #[test]
    fn the_warp_is_monotonic_and_covers_the_square() {
        let d = skewed();
        let mut last = (-1.0, 0usize);
        for k in 0..=10_000 {
            let u = (k as f64 / 10_000.0).min(1.0f64.next_down());
            let (i, x) = invert(&d.marginal, u);
            assert!(x >= last.0 && i >= last.1, "u {u}: {x} after {}", last.0);
            last = (x, i);
        }
        assert!(invert(&d.marginal, 0.0).1 == 0.0 && last.0 > 0.999);
    }

    #[test]
    fn inverting_by_counting_finds_the_cell_a_binary_search_finds() {
        // Non-decreasing tables with empty cells (flat runs), at the cells' edges and between.
        let d = skewed();
        let flat = [0.0, 0.0, 0.25, 0.25, 0.25, 0.5, 1.0, 1.0, 1.0];
        for cdf in [&d.marginal[..], &d.conditional[..RESOLUTION + 1], &flat[..]] {
            let cells = cdf.len() - 1;
            let mut us: Vec<f64> = cdf
                .iter()
                .flat_map(|&c| [c.next_down(), c, c.next_up()])
                .collect();
            us.extend((0..1000).map(|k| k as f64 / 1000.0));
            for u in us.into_iter().filter(|u| (0.0..1.0).contains(u)) {
                let searched = (cdf.partition_point(|&c| c <= u).max(1) - 1).min(cells - 1);
                assert_eq!(invert(cdf, u).0, searched, "u {u} in {cdf:?}");
            }
        }
    }

    #[test]
    fn nothing_is_learned_from_too_few_useful_photons_or_for_too_little_gain() {
        assert!(Density2D::learned(&[1; BINS], &[1; BINS]).is_none());
        assert!(Density2D::learned(&[100; BINS], &[0; BINS]).is_none());
        // Every direction as useful: nothing to gain, uniform emission.
        assert!(Density2D::learned(&[100; BINS], &[7; BINS]).is_none());
        // Half the directions useful: a gain of about 1.6 (82 % of the photons to them).
        let mut useful = vec![0u64; BINS];
        useful[..BINS / 2].fill(500);
        let half = Density2D::learned(&[1000; BINS], &useful).expect("learned");
        let gain = half.guided_share / half.uniform_share;
        assert!(gain > MIN_GAIN && gain < 1.8, "gain {gain}");
    }

    #[test]
    fn the_gain_is_how_many_times_more_photons_are_useful() {
        let d = skewed();
        // 16 of 1024 bins 90 % useful, the rest never: uniform emission lands 1.4 %; the
        // density sends most of its photons to those bins (the rest still have the prior).
        assert!(
            (d.uniform_share - 16.0 * 0.9 / BINS as f64).abs() < 2e-3,
            "{}",
            d.uniform_share
        );
        let gain = d.guided_share / d.uniform_share;
        assert!(gain > 10.0 && gain < MAX_GAIN, "gain {gain}");
        // Useful bins share the density evenly, whatever their share.
        let mut emitted = vec![100u64; BINS];
        let mut useful = vec![0u64; BINS];
        (useful[0], useful[1], emitted[1]) = (90, 300, 1000);
        let d = Density2D::learned(&emitted, &useful).expect("learned");
        assert!(
            (d.pdf[0] / d.pdf[1] - 1.0).abs() < 1e-9,
            "{} {}",
            d.pdf[0],
            d.pdf[1]
        );
    }
}
