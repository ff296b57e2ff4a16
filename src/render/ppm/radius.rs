//! The choice of radii: the automatic initial radius (from the pixel footprint), the indirect
//! estimate's radius chosen after the first pass ([`RadiusPolicy::widen_indirect`]) and the adaptive
//! radius, narrowed where photons are dense and widened where they are sparse
//! ([`RadiusPolicy::adapt_radii`]; in the spirit of classic photon mapping's k-nearest-neighbour
//! radius, Jensen 2001, chosen once and then shrunk by the paper's rule).

use super::estimate::{Estimate, Restart, Slot};
use super::gathered::Gathered;
use super::points::VisiblePoints;
use crate::scene::{Camera, Scene};
use crate::settings::RenderParams;

/// How the indirect estimate's radius is chosen ([`RenderParams::indirect_radius_scale`]).
///
/// [`RenderParams::indirect_radius_scale`]: crate::settings::RenderParams::indirect_radius_scale
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum IndirectScale {
    /// One estimate for all photons.
    Off,
    /// From the first pass's photon density ([`RadiusPolicy::widen_indirect`]).
    Automatic,
    /// This multiple of the initial radius.
    Fixed(f64),
}

impl IndirectScale {
    /// The radius a cold slot's indirect estimate starts at, for the initial radius `r0`: none
    /// when it is off; `r0` while automatic (the first pass measures the photon density, and
    /// [`RadiusPolicy::widen_indirect`] widens it after).
    pub fn initial_radius(self, r0: f64) -> f64 {
        match self {
            IndirectScale::Off => 0.0,
            IndirectScale::Automatic => r0,
            IndirectScale::Fixed(k) => k * r0,
        }
    }
}

/// Indirect photons an automatic indirect radius aims to hand each point per pass.
pub const INDIRECT_PHOTONS: f64 = 32.0;

/// The widest automatic indirect radius, over the initial radius.
pub const MAX_INDIRECT_SCALE: f64 = 4.0;

/// Photons a pass should hand a point after the radius is narrowed where photons are dense
/// ([`RadiusPolicy::adapt_radii`]).
pub const DENSE_PHOTONS: f64 = 64.0;

/// The most an adaptive radius narrows a point's initial radius (in radius, not area).
pub const MAX_NARROWING: f64 = 4.0;

/// Photons a pass should hand a point after the radius is widened where photons are sparse
/// ([`RadiusPolicy::adapt_radii`]).
pub const SPARSE_PHOTONS: f64 = 2.0;

/// The most an adaptive radius widens a point's initial radius (in radius, not area); also
/// how much wider the first pass gathers.
pub const MAX_WIDENING: f64 = 2.0;

/// How far, in pixels along each axis, a sparse point looks for denser light before its
/// radius is widened ([`RadiusPolicy::adapt_radii`]): the initial radius is two pixels' footprint.
const SPARSE_NEIGHBOURHOOD: usize = 2;

/// How a render chooses its radii: the initial radius, the indirect estimate's scale and the
/// adaptive radius, and what it chose.
#[derive(Clone, Copy, Debug)]
pub struct RadiusPolicy {
    /// The initial radius the render parameters (or a warm restart) give; `None`: automatic
    /// ([`automatic_radius`]).
    pub initial_radius: Option<f64>,
    /// The initial radius², once the first eye pass has chosen it.
    pub initial_radius2: f64,
    /// How the indirect estimate's radius is chosen (from the render parameters; then what
    /// the first pass chose when automatic).
    pub indirect_scale: IndirectScale,
    /// Narrow the primary radius where the first pass found photons dense, widen it where
    /// they are sparse (from the render parameters).
    pub adaptive_radius: bool,
}

impl RadiusPolicy {
    /// The policy `params` choose.
    pub fn new(params: &RenderParams) -> Self {
        Self {
            initial_radius: params.initial_radius,
            initial_radius2: 0.0,
            indirect_scale: match params.indirect_radius_scale {
                None => IndirectScale::Automatic,
                Some(k) if k > 1.0 => IndirectScale::Fixed(k),
                Some(_) => IndirectScale::Off,
            },
            adaptive_radius: params.adaptive_radius,
        }
    }

    /// Estimates each slot gathers into: 2, or 1 when the indirect one is off.
    pub fn estimates(&self) -> usize {
        if self.indirect_scale == IndirectScale::Off {
            1
        } else {
            2
        }
    }

    /// The indirect estimate's radius over the primary's, for the statistics (1: one estimate
    /// for all photons, or not chosen yet).
    pub fn indirect_scale_shown(&self) -> f64 {
        match self.indirect_scale {
            IndirectScale::Fixed(k) => k,
            _ => 1.0,
        }
    }

    /// After the first eye pass, before any slot has a radius: the initial radius (given, or
    /// [`automatic_radius`] from `points`), and every slot's radii from it
    /// ([`RadiusPolicy::first_pass_radius2`], [`IndirectScale::initial_radius`]).
    pub fn start(&mut self, slots: &mut [Slot], points: &VisiblePoints, scene: &Scene) {
        let r0 = self
            .initial_radius
            .unwrap_or_else(|| automatic_radius(points, scene));
        let indirect = self.indirect_scale.initial_radius(r0);
        let primary = self.first_pass_radius2(r0 * r0);
        for s in slots {
            s.primary = Estimate::empty(primary);
            s.indirect = Estimate::empty(indirect * indirect);
        }
        self.initial_radius2 = r0 * r0;
    }

    /// After the first pass of an automatic indirect radius: widens every slot's indirect
    /// estimate by `k = √(INDIRECT_PHOTONS / m̄)`, clamped to [1, MAX_INDIRECT_SCALE], where m̄
    /// is the mean number of indirect photons a slot gathered in that pass — so that a pass
    /// hands each point about `INDIRECT_PHOTONS` of them. Where photons are sparse it grows;
    /// where they are dense (small closed rooms) `k` is 1 and the two estimates merge into
    /// one. The estimate is scaled as PPM's update assumes, for a density uniform within the
    /// radius: N and τ by the area. Counts are deterministic, so is `k`.
    pub fn widen_indirect(&mut self, slots: &mut [Slot], gathered: &Gathered) {
        let count = slots.len().max(1) as f64;
        let mean = gathered.indirect_counts().map(|c| c as f64).sum::<f64>() / count;
        let k = (INDIRECT_PHOTONS / mean).sqrt().clamp(1.0, MAX_INDIRECT_SCALE);
        if k == 1.0 {
            // Dense photons: the two estimates would share one radius, so they become one
            // (the second only costs memory and time). Each is brought to the smaller of the
            // two radii — N and τ scaled by the area, as PPM's update does — and summed.
            for s in slots {
                let r2 = s.primary.radius2().min(s.indirect.radius2());
                let (p, i) = (s.primary.resized(r2), s.indirect.resized(r2));
                s.primary = Estimate::new(r2, p.n() + i.n(), p.tau() + i.tau());
                s.indirect = Estimate::default();
            }
            self.indirect_scale = IndirectScale::Off;
            return;
        }
        let area = k * k;
        for s in slots {
            s.indirect = s.indirect.resized(s.indirect.radius2() * area);
        }
        self.indirect_scale = IndirectScale::Fixed(k);
    }

    /// The radius² a cold slot's primary estimate gathers at in the first pass, for the initial
    /// radius² `r0_2`: with an adaptive radius [`MAX_WIDENING`] times wider, so that the pass
    /// counts photons over an area wide enough to tell a sparse point from an empty one
    /// ([`RadiusPolicy::adapt_radii`]); `r0_2` otherwise.
    pub fn first_pass_radius2(&self, r0_2: f64) -> f64 {
        if self.adaptive_radius {
            r0_2 * MAX_WIDENING * MAX_WIDENING
        } else {
            r0_2
        }
    }

    /// After the first pass, with an adaptive radius: each cold slot's primary estimate
    /// (caustics, and all light when one estimate is kept) restarts at the second pass with a
    /// radius chosen from `m`, the photons that pass would have handed it within the initial
    /// radius `R₀` (it gathered over [`MAX_WIDENING`]·`R₀`, [`RadiusPolicy::first_pass_radius2`];
    /// `m` is that count over the area ratio):
    ///
    /// - **dense** (`m > DENSE_PHOTONS`): narrowed so that a pass hands it about that many,
    ///   `R² = R₀² · DENSE_PHOTONS / m`, at most [`MAX_NARROWING`] times narrower. PPM's bias
    ///   (the blur of sharp light such as a caustic's edge) grows with the radius and shrinks
    ///   only pass by pass, while its noise depends on photons per point: where they are dense
    ///   a narrower radius removes blur at once for little noise;
    /// - **sparse** (`m⁺ < SPARSE_PHOTONS`, `m⁺` the photons a full pass of `full_pass`
    ///   photons would hand it within `R₀` counting one more than the first pass, of
    ///   `pass_photons`, found; and no point of a pixel within [`SPARSE_NEIGHBOURHOOD`] pixels
    ///   has `2·SPARSE_PHOTONS` or more): widened so that a pass hands it about that many,
    ///   `R² = R₀² · SPARSE_PHOTONS / m⁺`, at most
    ///   [`MAX_WIDENING`] times wider and no wider than the indirect estimate (none when one
    ///   estimate holds all photons). Where a pass hands a point a photon or none (light
    ///   spread thin, such as a curved glass's reflection over a floor) its noise dominates and
    ///   the light varies slowly; the neighbours' counts keep the wide radius away from
    ///   brighter light next to it (the rim of a caustic, a lens's focus seen through the
    ///   lens), whose blur would cost more than the noise saved;
    /// - otherwise `R₀`.
    ///
    /// The first pass's flux, gathered over the wide radius, is dropped at the second pass
    /// (kept until then, scaled by the area, so the image does not go dark), so that no blur of
    /// it stays in the estimate; the radius is chosen from photons the estimate then never
    /// uses. Counts are deterministic, so are the radii. The neighbours' counts matter where
    /// dim light lies beside bright (the focus of `scenes/lens.toml`, seen through the lens):
    /// widened there, a point would blur the bright light into its estimate.
    ///
    /// Returns the shares of the slots narrowed and widened.
    pub fn adapt_radii(
        &self,
        slots: &mut [Slot],
        gathered: &Gathered,
        (full_pass, pass_photons): (u64, u64),
        (width, height): (u32, u32),
    ) -> (f64, f64) {
        let merged = self.indirect_scale == IndirectScale::Off;
        let r0_2 = self.initial_radius2;
        let area = MAX_WIDENING * MAX_WIDENING;
        // The widest a sparse point may grow: no wider than the indirect estimate's radius,
        // which sets the spatial index's reach already — beyond it, every photon would look
        // at more points. With one estimate for all photons, not at all.
        let widest2 = match self.indirect_scale {
            IndirectScale::Fixed(k) => k.min(MAX_WIDENING).powi(2),
            _ => 1.0,
        };
        // Photons within R₀: the primary's over the wide radius's area; when one estimate was
        // kept, the indirect one's too, which gathered at R₀ itself. In f32, exact for counts
        // (quarters of integers below 2²⁴): at 1920×1080 these arrays are the first pass's
        // only extra memory, 8 MiB each.
        let within: Vec<f32> = (0..slots.len())
            .map(|k| {
                let wide = gathered.count(k, 0) as f64 / area;
                (wide + if merged { gathered.count(k, 1) as f64 } else { 0.0 }) as f32
            })
            .collect();
        // The sparse test counts photons as a full pass would hand them, and one more than
        // the first pass found: the viewer's first pass is smaller (16,384 photons), and its
        // few photons cannot tell a sparse point from one they missed (counting only what it
        // found would widen nearly every point after a cold restart).
        let full = (full_pass as f64 / pass_photons.max(1) as f64).max(1.0);
        let pixels = slots.iter().map(|s| s.pixel);
        let nearby = densest_nearby(pixels, &within, width, height);
        let (mut narrowed, mut widened) = (0usize, 0usize);
        for (k, s) in slots.iter_mut().enumerate() {
            // A slot a warm restart kept has its radius already.
            if s.primary.radius2() <= 0.0 || s.prior > 0.0 {
                continue;
            }
            let m = within[k] as f64;
            let m_full = (m + 1.0 / area) * full;
            let factor = if m > DENSE_PHOTONS {
                narrowed += 1;
                (DENSE_PHOTONS / m).max(MAX_NARROWING.powi(-2))
            } else if m_full < SPARSE_PHOTONS
                && nearby[k] as f64 * full < 2.0 * SPARSE_PHOTONS
                && widest2 > 1.0
            {
                widened += 1;
                (SPARSE_PHOTONS / m_full).min(widest2)
            } else {
                1.0
            };
            s.primary = s.primary.resized(r0_2 * factor);
            s.restart = Restart::Pending;
        }
        let count = slots.len().max(1) as f64;
        (narrowed as f64 / count, widened as f64 / count)
    }
}

/// The automatic initial radius: twice the footprint of one pixel at the median distance
/// of the visible `points` from the eye. (smallppm's rule — the visible points' bounding
/// box over the image size — explodes for an infinite floor reaching the horizon.)
pub fn automatic_radius(points: &VisiblePoints, scene: &Scene) -> f64 {
    let cam = &scene.camera;
    let mut distances: Vec<f64> = points
        .reach
        .iter()
        .map(|p| (p.position - cam.position).dot(cam.forward).abs())
        .collect();
    footprint_radius(&mut distances, cam)
}

/// Twice the footprint of one pixel of `camera` at the median of `distances` (along the view
/// axis; reordered): the automatic radius's rule, which VCM's radius follows too. 1e-3 when
/// there is no distance.
pub fn footprint_radius(distances: &mut [f64], camera: &Camera) -> f64 {
    if distances.is_empty() {
        return 1e-3;
    }
    let mid = distances.len() / 2;
    let median = *distances.select_nth_unstable_by(mid, f64::total_cmp).1;
    let pixel = 2.0 * (0.5 * camera.fov_y).tan() / camera.height as f64;
    (2.0 * median * pixel).max(1e-9)
}

/// For every slot (its pixel in `pixels`), the most photons `within` gives any slot of a
/// pixel within [`SPARSE_NEIGHBOURHOOD`] pixels of its own (its own included): a square
/// window over the image, each pixel holding the largest count of its slots.
fn densest_nearby(
    pixels: impl Iterator<Item = u32> + Clone,
    within: &[f32],
    width: u32,
    height: u32,
) -> Vec<f32> {
    let (w, h) = (width as usize, height as usize);
    let mut per_pixel = vec![0.0f32; w * h];
    for (pixel, &m) in pixels.clone().zip(within) {
        let p = &mut per_pixel[pixel as usize];
        *p = p.max(m);
    }
    // The window's maximum, rows then columns (a separable filter).
    let reach = SPARSE_NEIGHBOURHOOD;
    let mut rows = vec![0.0f32; w * h];
    for y in 0..h {
        let row = &per_pixel[y * w..(y + 1) * w];
        for x in 0..w {
            let span = &row[x.saturating_sub(reach)..(x + reach + 1).min(w)];
            rows[y * w + x] = span.iter().copied().fold(0.0, f32::max);
        }
    }
    pixels
        .map(|pixel| {
            let (x, y) = (pixel as usize % w, pixel as usize / w);
            (y.saturating_sub(reach)..(y + reach + 1).min(h))
                .map(|yy| rows[yy * w + x])
                .fold(0.0, f32::max)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// One dense pixel in a 9×7 image: it is the densest light of every pixel within
    /// `SPARSE_NEIGHBOURHOOD` pixels along each axis (its square window), and of no other;
    /// a pixel's own count counts, and of a pixel's several slots the largest.
    #[test]
    fn the_densest_light_nearby_is_a_square_window_of_pixels() {
        let (w, h) = (9u32, 7u32);
        let mut slots: Vec<Slot> = (0..w * h).map(Slot::new).collect();
        // A second slot of pixel (1, 1), as classic PPM keeps one per point.
        slots.push(Slot::new(w + 1));
        let mut within = vec![0.5; slots.len()];
        let dense = (4, 3);
        within[(dense.1 * w + dense.0) as usize] = 10.0;
        *within.last_mut().expect("a slot") = 3.0;
        let nearby = densest_nearby(slots.iter().map(|s| s.pixel), &within, w, h);
        for (k, s) in slots.iter().enumerate() {
            let (x, y) = ((s.pixel % w) as i64, (s.pixel / w) as i64);
            let reach = SPARSE_NEIGHBOURHOOD as i64;
            let near_dense = (x - dense.0 as i64).abs() <= reach && (y - dense.1 as i64).abs() <= reach;
            let near_second = (x - 1).abs() <= reach && (y - 1).abs() <= reach;
            let expected = if near_dense {
                10.0
            } else if near_second {
                3.0
            } else {
                0.5
            };
            assert_eq!(nearby[k], expected, "pixel ({x}, {y})");
        }
    }
}
