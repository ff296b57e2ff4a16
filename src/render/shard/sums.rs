//! The exact sums of independent passes: per pixel, the sum of the passes' RGB radiance and of
//! their luminance squared, in fixed point.
//!
//! Floating-point addition is not associative: summing a shard's passes and then the shards
//! would round differently from one process summing the passes in order. Each pass's value is
//! therefore rounded once to a multiple of 2⁻⁴⁰ (about 9·10⁻¹³, far below what an f32 image
//! holds for any radiance above 10⁻⁵) and summed as a 128-bit integer, which is exact and
//! independent of order: merged shards equal one process bit for bit. A pass value is clamped
//! to ±10¹⁵, so 2³² passes cannot overflow.

use glam::DVec3;

use crate::color::luminance;

/// Bits after the binary point of the fixed-point sums.
pub const FRACTION_BITS: u32 = 40;

/// The largest magnitude a pass value keeps (larger ones are clamped; NaN counts as 0).
pub const MAX_PASS_VALUE: f64 = 1e15;

/// `v` in fixed point.
fn fixed(v: f64) -> i128 {
    if v.is_nan() {
        return 0;
    }
    let v = v.clamp(-MAX_PASS_VALUE, MAX_PASS_VALUE);
    (v * (1u64 << FRACTION_BITS) as f64).round() as i128
}

/// A fixed-point sum as a number.
fn real(x: i128) -> f64 {
    x as f64 / (1u64 << FRACTION_BITS) as f64
}

/// The sums of a set of passes of one render.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct PassSums {
    width: u32,
    height: u32,
    /// Per pixel, Σ RGB over the passes.
    rgb: Vec<[i128; 3]>,
    /// Per pixel, Σ luminance² over the passes.
    lum2: Vec<i128>,
    /// The passes summed, ascending.
    passes: Vec<u32>,
    /// Photons emitted by those passes.
    photons: u64,
}

impl PassSums {
    /// No passes yet, for a `width`×`height` image.
    pub fn new(width: u32, height: u32) -> Self {
        let n = width as usize * height as usize;
        Self {
            width,
            height,
            rgb: vec![[0; 3]; n],
            lum2: vec![0; n],
            passes: Vec::new(),
            photons: 0,
        }
    }

    /// Sums from their parts (as a part file holds them); `None` when the lengths disagree
    /// with the size or the passes are not ascending and distinct.
    pub fn from_parts(
        (width, height): (u32, u32),
        rgb: Vec<[i128; 3]>,
        lum2: Vec<i128>,
        passes: Vec<u32>,
        photons: u64,
    ) -> Option<Self> {
        let n = width as usize * height as usize;
        let ascending = passes.windows(2).all(|w| w[0] < w[1]);
        (rgb.len() == n && lum2.len() == n && ascending).then_some(Self {
            width,
            height,
            rgb,
            lum2,
            passes,
            photons,
        })
    }

    /// Adds pass `pass`, whose radiance per pixel is `values` and which emitted `photons`.
    ///
    /// # Panics
    /// If `values` is not one per pixel or the pass is already summed (callers choose passes
    /// from a [`super::Shard`]).
    pub fn add_pass(&mut self, pass: u32, values: &[DVec3], photons: u64) {
        assert_eq!(values.len(), self.rgb.len(), "one value per pixel");
        let at = self
            .passes
            .binary_search(&pass)
            .expect_err("a pass is summed once");
        self.passes.insert(at, pass);
        for ((sum, sq), v) in self.rgb.iter_mut().zip(&mut self.lum2).zip(values) {
            sum[0] += fixed(v.x);
            sum[1] += fixed(v.y);
            sum[2] += fixed(v.z);
            let l = luminance(*v).clamp(-MAX_PASS_VALUE, MAX_PASS_VALUE);
            *sq += fixed((l * l).min(MAX_PASS_VALUE));
        }
        self.photons += photons;
    }

    /// Adds `other`'s passes; refuses (changing nothing) when the sizes differ or a pass is in
    /// both, naming the first such pass.
    pub fn add(&mut self, other: &PassSums) -> Result<(), SumsClash> {
        if (self.width, self.height) != (other.width, other.height) {
            return Err(SumsClash::Size {
                ours: (self.width, self.height),
                theirs: (other.width, other.height),
            });
        }
        if let Some(p) = self.first_shared_pass(other) {
            return Err(SumsClash::Overlap(p));
        }
        for (a, b) in self.rgb.iter_mut().zip(&other.rgb) {
            for k in 0..3 {
                a[k] += b[k];
            }
        }
        for (a, b) in self.lum2.iter_mut().zip(&other.lum2) {
            *a += b;
        }
        self.passes.extend_from_slice(&other.passes);
        self.passes.sort_unstable();
        self.photons += other.photons;
        Ok(())
    }

    /// The first pass summed in both.
    pub fn first_shared_pass(&self, other: &PassSums) -> Option<u32> {
        first_common(&self.passes, &other.passes)
    }

    /// Image size.
    pub fn size(&self) -> (u32, u32) {
        (self.width, self.height)
    }

    /// The passes summed, ascending.
    pub fn passes(&self) -> &[u32] {
        &self.passes
    }

    /// Photons emitted by the passes summed.
    pub fn photons(&self) -> u64 {
        self.photons
    }

    /// Per pixel, Σ RGB in fixed point (2⁻⁴⁰ units).
    pub fn rgb_sums(&self) -> &[[i128; 3]] {
        &self.rgb
    }

    /// Per pixel, Σ luminance² in fixed point.
    pub fn luminance_square_sums(&self) -> &[i128] {
        &self.lum2
    }

    /// The image: each pixel's mean over the passes (zero before the first pass). The same
    /// bits for the same sums, however they were added.
    pub fn mean(&self) -> Vec<[f32; 3]> {
        let n = self.passes.len().max(1) as f64;
        self.rgb
            .iter()
            .map(|s| {
                [
                    (real(s[0]) / n) as f32,
                    (real(s[1]) / n) as f32,
                    (real(s[2]) / n) as f32,
                ]
            })
            .collect()
    }

    /// The estimated relative error of the image: the root mean square over pixels of the
    /// standard error of each pixel's mean luminance (from the passes' spread, which is
    /// known because they are independent), over the root mean square of the luminance — the
    /// measure of [`crate::render::error::relative_error_estimate`]. `None` with fewer than two
    /// passes or a black image.
    pub fn relative_error(&self) -> Option<f64> {
        let n = self.passes.len() as f64;
        if n < 2.0 {
            return None;
        }
        let (mut variance, mut square) = (0.0, 0.0);
        for (s, sq) in self.rgb.iter().zip(&self.lum2) {
            let m = luminance(DVec3::new(real(s[0]), real(s[1]), real(s[2]))) / n;
            let sample_variance = ((real(*sq) / n - m * m) * n / (n - 1.0)).max(0.0);
            variance += sample_variance / n;
            square += m * m;
        }
        (square > 0.0).then(|| (variance / square).sqrt())
    }
}

/// Why two sets of sums cannot be added.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum SumsClash {
    /// Different image sizes.
    #[error("image sizes differ: {}x{} and {}x{}", ours.0, ours.1, theirs.0, theirs.1)]
    Size {
        /// The sums added to.
        ours: (u32, u32),
        /// The sums added.
        theirs: (u32, u32),
    },
    /// A pass in both.
    #[error("both hold pass {0}")]
    Overlap(u32),
}

/// The first value in both ascending lists.
fn first_common(a: &[u32], b: &[u32]) -> Option<u32> {
    let (mut i, mut j) = (0, 0);
    while i < a.len() && j < b.len() {
        match a[i].cmp(&b[j]) {
            std::cmp::Ordering::Less => i += 1,
            std::cmp::Ordering::Greater => j += 1,
            std::cmp::Ordering::Equal => return Some(a[i]),
        }
    }
    None
}

/// A pass list as runs, such as `0-15,20,24-31` (how a part file writes it).
pub fn passes_text(passes: &[u32]) -> String {
    let mut out: Vec<String> = Vec::new();
    let mut i = 0;
    while i < passes.len() {
        let mut j = i;
        while j + 1 < passes.len() && passes[j + 1] == passes[j] + 1 {
            j += 1;
        }
        out.push(if i == j {
            passes[i].to_string()
        } else {
            format!("{}-{}", passes[i], passes[j])
        });
        i = j + 1;
    }
    out.join(",")
}

/// The pass list [`passes_text`] wrote, of a render of `total` passes: ascending runs of whole
/// numbers below `total`. Each run is checked before it is expanded, so the list costs at most
/// 4 bytes for each of the render's passes, whatever the text claims; the error says what is
/// wrong.
pub fn parse_passes(text: &str, total: u32) -> Result<Vec<u32>, String> {
    let mut passes: Vec<u32> = Vec::new();
    for run in text.split(',').filter(|r| !r.is_empty()) {
        let number = |s: &str| {
            s.parse::<u32>()
                .map_err(|_| format!("{s:?} is not a pass number"))
        };
        let (a, b) = match run.split_once('-') {
            Some((a, b)) => (number(a)?, number(b)?),
            None => {
                let a = number(run)?;
                (a, a)
            }
        };
        if a > b {
            return Err(format!("the run {run} runs backwards"));
        }
        if passes.last().is_some_and(|&l| l >= a) {
            return Err(format!("the run {run} is not after the pass before it"));
        }
        if b >= total {
            return Err(format!("it holds pass {b} of a render of {total} passes"));
        }
        passes.extend(a..=b);
    }
    Ok(passes)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sums_are_the_same_in_any_order() {
        let values: Vec<Vec<DVec3>> = (0..7)
            .map(|p| {
                (0..4)
                    .map(|i| DVec3::splat(0.1 * (p * 4 + i) as f64 + 1e-7))
                    .collect()
            })
            .collect();
        let mut all = PassSums::new(2, 2);
        for (p, v) in values.iter().enumerate() {
            all.add_pass(p as u32, v, 10);
        }
        let mut odd = PassSums::new(2, 2);
        let mut even = PassSums::new(2, 2);
        for (p, v) in values.iter().enumerate().rev() {
            let sums = if p % 2 == 1 { &mut odd } else { &mut even };
            sums.add_pass(p as u32, v, 10);
        }
        odd.add(&even).expect("disjoint");
        assert_eq!(odd, all);
        assert_eq!(odd.add(&even), Err(SumsClash::Overlap(0)));
    }

    #[test]
    fn pass_lists_round_trip_as_runs() {
        for passes in [vec![], vec![3], vec![0, 1, 2, 3, 7, 9, 10]] {
            let text = passes_text(&passes);
            assert_eq!(parse_passes(&text, 11), Ok(passes), "{text}");
        }
        assert_eq!(passes_text(&[0, 1, 2, 5]), "0-2,5");
        assert!(parse_passes("3,1", 10).is_err());
        assert!(parse_passes("x", 10).is_err());
        assert!(parse_passes("3-1", 10).is_err());
        assert!(parse_passes("0-9", 9)
            .expect_err("past the total")
            .contains("pass 9"));
    }

    #[test]
    fn a_pass_list_bomb_is_refused_before_it_is_expanded() {
        // Three runs of 10^8 passes claimed by a render of 1000 passes: refused at once.
        let text = "0-99999999,100000000-199999999,200000000-299999999";
        assert!(parse_passes(text, 1000).is_err());
    }

    #[test]
    fn the_error_estimate_follows_the_spread_of_the_passes() {
        let mut sums = PassSums::new(1, 1);
        for (p, v) in [1.0, 3.0, 1.0, 3.0].into_iter().enumerate() {
            sums.add_pass(p as u32, &[DVec3::splat(v)], 1);
        }
        // Sample standard deviation √(4/3), over √4 passes, over the mean 2.
        let expected = (4.0f64 / 3.0).sqrt() / 2.0 / 2.0;
        let got = sums.relative_error().expect("4 passes");
        assert!((got - expected).abs() < 1e-9, "{got} vs {expected}");
    }
}
