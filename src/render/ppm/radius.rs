//! The choice of radii: the automatic initial radius (from the pixel footprint), the indirect
//! estimate's radius chosen after the first pass ([`Ppm::widen_indirect`]) and the adaptive
//! narrowing where photons are dense ([`Ppm::narrow_dense`]; in the spirit of classic photon
//! mapping's k-nearest-neighbour radius, Jensen 2001, chosen once and then shrunk by the
//! paper's rule).

use super::gathered::Gathered;
use super::{Estimate, Ppm, PpmOptions, Restart};
use crate::scene::Scene;

/// How the indirect estimate's radius is chosen ([`RenderParams::indirect_radius_scale`]).
///
/// [`RenderParams::indirect_radius_scale`]: crate::settings::RenderParams::indirect_radius_scale
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum IndirectScale {
    /// One estimate for all photons.
    Off,
    /// From the first pass's photon density ([`Ppm::widen_indirect`]).
    Automatic,
    /// This multiple of the initial radius.
    Fixed(f64),
}

impl IndirectScale {
    /// The radius a cold slot's indirect estimate starts at, for the initial radius `r0`: none
    /// when it is off; `r0` while automatic (the first pass measures the photon density, and
    /// [`Ppm::widen_indirect`] widens it after).
    pub(super) fn initial_radius(self, r0: f64) -> f64 {
        match self {
            IndirectScale::Off => 0.0,
            IndirectScale::Automatic => r0,
            IndirectScale::Fixed(k) => k * r0,
        }
    }
}

/// Indirect photons an automatic indirect radius aims to hand each point per pass.
pub(super) const INDIRECT_PHOTONS: f64 = 32.0;

/// The widest automatic indirect radius, over the initial radius.
pub(super) const MAX_INDIRECT_SCALE: f64 = 4.0;

/// Photons a pass should hand a point after the radius is narrowed where photons are dense
/// ([`Ppm::narrow_dense`]).
pub(super) const DENSE_PHOTONS: f64 = 64.0;

/// The most an adaptive radius narrows a point's initial radius (in radius, not area).
pub(super) const MAX_NARROWING: f64 = 4.0;

impl Ppm {
    /// The initial radius photon mapping would choose for `scene` by itself (its own
    /// `initial_radius` ignored): see [`Ppm::automatic_radius`]. Traces one eye pass.
    pub fn automatic_initial_radius(scene: &Scene) -> f64 {
        let mut scene = scene.clone();
        scene.params.initial_radius = None;
        let mut ppm = Ppm::new(&scene, PpmOptions::default());
        if !ppm.eye_pass(&scene) {
            return 1e-3;
        }
        ppm.slots.first().map_or(1e-3, |s| s.primary.radius2().sqrt())
    }

    /// The automatic initial radius: twice the footprint of one pixel at the median distance
    /// of the visible points from the eye. (smallppm's rule — the visible points' bounding
    /// box over the image size — explodes for an infinite floor reaching the horizon.)
    pub(super) fn automatic_radius(&self, scene: &Scene) -> f64 {
        let cam = &scene.camera;
        let mut distances: Vec<f64> = self
            .points
            .reach
            .iter()
            .map(|p| (p.position - cam.position).dot(cam.forward).abs())
            .collect();
        if distances.is_empty() {
            return 1e-3;
        }
        let mid = distances.len() / 2;
        let median = *distances.select_nth_unstable_by(mid, f64::total_cmp).1;
        let pixel = 2.0 * (0.5 * cam.fov_y).tan() / self.height as f64;
        (2.0 * median * pixel).max(1e-9)
    }

    /// After the first pass of an automatic indirect radius: widens every slot's indirect
    /// estimate by `k = √(INDIRECT_PHOTONS / m̄)`, clamped to [1, MAX_INDIRECT_SCALE], where m̄
    /// is the mean number of indirect photons a slot gathered in that pass — so that a pass
    /// hands each point about `INDIRECT_PHOTONS` of them. Where photons are sparse it grows;
    /// where they are dense (small closed rooms) `k` is 1 and the two estimates merge into
    /// one. The estimate is scaled as PPM's update assumes, for a density uniform within the
    /// radius: N and τ by the area. Counts are deterministic, so is `k`.
    pub(super) fn widen_indirect(&mut self, gathered: &Gathered) {
        let slots = self.slots.len().max(1) as f64;
        let mean = gathered.indirect_counts().map(|c| c as f64).sum::<f64>() / slots;
        let k = (INDIRECT_PHOTONS / mean).sqrt().clamp(1.0, MAX_INDIRECT_SCALE);
        if k == 1.0 {
            // Dense photons: the two estimates would share one radius, so they become one
            // (the second only costs memory and time). Each is brought to the smaller of the
            // two radii — N and τ scaled by the area, as PPM's update does — and summed.
            for s in &mut self.slots {
                let r2 = s.primary.radius2().min(s.indirect.radius2());
                let (p, i) = (s.primary.resized(r2), s.indirect.resized(r2));
                s.primary = Estimate::new(r2, p.n() + i.n(), p.tau() + i.tau());
                s.indirect = Estimate::default();
            }
            self.indirect_scale = IndirectScale::Off;
            return;
        }
        let area = k * k;
        for s in &mut self.slots {
            s.indirect = s.indirect.resized(s.indirect.radius2() * area);
        }
        self.indirect_scale = IndirectScale::Fixed(k);
    }

    /// After the first pass, with an adaptive radius: where that pass handed a slot's primary
    /// estimate more than `DENSE_PHOTONS` photons (caustics, and all light when one estimate
    /// is kept), the estimate restarts at the second pass with the initial radius narrowed so
    /// that a pass hands it about that many: `R² = R₀² · DENSE_PHOTONS / m`, at most
    /// `MAX_NARROWING` times narrower. PPM's bias (the blur of sharp light such as a caustic's
    /// edge) grows with the radius and shrinks only pass by pass, while its noise depends on
    /// photons per point: where they are dense a narrower radius removes blur at once for
    /// little noise. The first pass's flux, gathered over the wide radius, is dropped at the
    /// second pass (kept until then, scaled by the area, so the image does not go dark), so
    /// that no blur of it stays in the estimate; the radius is chosen from photons the
    /// estimate then never uses. Counts are deterministic, so are the radii.
    pub(super) fn narrow_dense(&mut self, gathered: &Gathered) {
        let merged = self.indirect_scale == IndirectScale::Off;
        let r0_2 = self.initial_radius2;
        let mut narrowed = 0usize;
        for (k, s) in self.slots.iter_mut().enumerate() {
            let count = gathered.count(k, 0) as f64 + if merged { gathered.count(k, 1) as f64 } else { 0.0 };
            // A slot a warm restart kept has its radius already.
            if count <= DENSE_PHOTONS || s.primary.radius2() <= 0.0 || s.prior > 0.0 {
                continue;
            }
            let radius2 = r0_2 * (DENSE_PHOTONS / count).max(MAX_NARROWING.powi(-2));
            s.primary = s.primary.resized(radius2);
            s.restart = Restart::Pending;
            narrowed += 1;
        }
        self.stats.narrowed_share = narrowed as f64 / self.slots.len().max(1) as f64;
    }
}
