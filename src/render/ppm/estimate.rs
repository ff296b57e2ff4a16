//! One progressive density estimate and its update rule (Hachisuka et al. 2008 §4:
//! `N' = N + αM`, `R'² = R²·(N + αM)/(N + M)`, `τ' = (τ + Φ)·(N + αM)/(N + M)`), the statistics
//! slot that holds a point's two estimates.

use std::f64::consts::PI;

use glam::{DVec3, Vec3};

/// One progressive density estimate (Hachisuka et al. 2008 §4): search radius², photon
/// count `N` and flux `τ`, updated after every pass. Stored in f32 (20 bytes instead of 40:
/// at 1920×1080 a stochastic render holds two per pixel) and computed in f64: each update
/// rounds once, a relative 6·10⁻⁸, so after 10,000 passes an estimate is off by about
/// 10⁻⁵ of itself at most for rounding that happens to go one way, far below its noise.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Estimate {
    radius2: f32,
    n: f32,
    tau: Vec3,
}

impl Estimate {
    /// An estimate of radius² `radius2`, photon count `n` and flux `tau`.
    pub fn new(radius2: f64, n: f64, tau: DVec3) -> Self {
        Self {
            radius2: radius2 as f32,
            n: n as f32,
            tau: tau.as_vec3(),
        }
    }

    /// An empty estimate of radius² `radius2`.
    pub fn empty(radius2: f64) -> Self {
        Self::new(radius2, 0.0, DVec3::ZERO)
    }

    /// Search radius².
    #[inline]
    pub fn radius2(&self) -> f64 {
        self.radius2 as f64
    }

    /// Accumulated photon count `N`.
    pub fn n(&self) -> f64 {
        self.n as f64
    }

    /// Accumulated flux `τ`.
    pub fn tau(&self) -> DVec3 {
        self.tau.as_dvec3()
    }

    /// Sets the photon count `N` (the global schedule shows each pass's own).
    pub(super) fn set_n(&mut self, n: f64) {
        self.n = n as f32;
    }

    /// Multiplies the flux by `factor`, per channel.
    pub(super) fn scale_tau(&mut self, factor: DVec3) {
        self.tau = (self.tau() * factor).as_vec3();
    }

    /// Folds in a pass that brought `m` photons of flux `phi` within the radius (eqs. 6–11):
    /// the radius shrinks so that a share α of the new photons is kept.
    pub(super) fn update(&mut self, phi: DVec3, m: u32, alpha: f64) {
        let m = m as f64;
        if m > 0.0 {
            let n = self.n();
            let g = (n + alpha * m) / (n + m);
            *self = Self::new(self.radius2() * g, n + alpha * m, (self.tau() + phi) * g);
        }
    }

    /// The estimate brought to radius² `radius2` as PPM's update assumes, for a density
    /// uniform within the radius: N and τ scaled by the area (an estimate without a radius
    /// holds nothing to scale).
    pub(super) fn resized(self, radius2: f64) -> Self {
        let share = if self.radius2 > 0.0 {
            radius2 / self.radius2()
        } else {
            0.0
        };
        Self::new(radius2, self.n() * share, self.tau() * share)
    }

    /// Reflected radiance `τ/(π R² N_emitted)`.
    pub(super) fn radiance(&self, emitted: f64) -> DVec3 {
        if self.radius2 > 0.0 {
            self.tau() / (PI * self.radius2() * emitted)
        } else {
            DVec3::ZERO
        }
    }
}

/// Accumulated statistics of one gathering point (classic PPM) or pixel (stochastic PPM): two
/// estimates, since photons that have bounced off a diffuse surface carry light that varies
/// slowly and are gathered over a wider radius ([`RenderParams::indirect_radius_scale`]).
///
/// [`RenderParams::indirect_radius_scale`]: crate::settings::RenderParams::indirect_radius_scale
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Slot {
    /// The pixel it contributes to.
    pub pixel: u32,
    /// Photons straight from a light or through mirrors and glass only: direct light (when
    /// light sampling is off) and caustics — every photon when one estimate is kept
    /// (`indirect_radius_scale = 1`).
    pub primary: Estimate,
    /// Photons after a diffuse bounce (indirect light), when the scale is above 1.
    pub indirect: Estimate,
    /// Whether the primary estimate was restarted with its adapted radius after the first
    /// pass (adaptive radius).
    pub restart: Restart,
    /// Photons emitted before this epoch that both estimates' flux already counts: a slot a
    /// warm restart kept ([`super::warm`]) carries its previous estimate as a prior worth
    /// this many photons, which fades as the epoch's own photons come (0: a cold slot).
    pub prior: f32,
}

/// A primary estimate's restart with its adapted radius (`Ppm::adapt_radii`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Restart {
    /// Not restarted: it counts every pass.
    #[default]
    None,
    /// Adapted after the first pass: its radius is the new one, its flux the first pass's
    /// (scaled by the area, so the image does not change) until the second pass replaces it.
    Pending,
    /// Restarted at the second pass: the first pass's photons do not count for it.
    Restarted,
}

impl Slot {
    /// Whether its primary estimate has a search radius (its radii are set).
    pub(super) fn has_radius(&self) -> bool {
        self.primary.radius2() > 0.0
    }

    /// An empty slot of `pixel` (its radii are set before the first pass).
    pub(super) fn new(pixel: u32) -> Self {
        Self {
            pixel,
            primary: Estimate::default(),
            indirect: Estimate::default(),
            restart: Restart::None,
            prior: 0.0,
        }
    }
}

/// The mean primary search radius of the slots `keep` picks, for the statistics; `None` when
/// it picks none.
pub(super) fn mean_primary_radius(slots: &[Slot], keep: impl Fn(&Slot) -> bool) -> Option<f64> {
    let (sum, count) = slots
        .iter()
        .filter(|s| keep(s))
        .fold((0.0, 0usize), |(sum, count), s| {
            (sum + s.primary.radius2().sqrt(), count + 1)
        });
    (count > 0).then(|| sum / count as f64)
}
