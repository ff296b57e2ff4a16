//! One progressive density estimate and its update rule (Hachisuka et al. 2008 §4:
//! `N' = N + αM`, `R'² = R²·(N + αM)/(N + M)`, `τ' = (τ + Φ)·(N + αM)/(N + M)`), the statistics
//! slot that holds a point's two estimates, and the update of every slot after a pass.

use std::f64::consts::PI;

use super::gathered::Gathered;
use super::radius::IndirectScale;
use super::{Ppm, SWEEP_BLOCK};
use glam::{DVec3, Vec3};
use rayon::prelude::*;

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

impl Ppm {
    /// Folds a completed pass into the slots and the statistics.
    pub(super) fn update(&mut self, gathered: Gathered) {
        if let (Some(guide), Some(tally)) = (&mut self.guide, &gathered.tally) {
            guide.learn(tally);
        }
        // Compute new photon counts, radii and flux (Hachisuka et al. 2008, eqs. 6–11), slot by
        // slot, [`SWEEP_BLOCK`] a task (memory-bound: 52-byte slots).
        let alpha = self.alpha;
        self.slots
            .par_chunks_mut(SWEEP_BLOCK)
            .enumerate()
            .for_each(|(chunk, slots)| {
                for (k, s) in (chunk * SWEEP_BLOCK..).zip(slots) {
                    if s.restart == Restart::Pending {
                        // The first pass's flux only stood in until this pass: it was
                        // gathered over the wide radius.
                        s.primary = Estimate::empty(s.primary.radius2());
                        s.restart = Restart::Restarted;
                    }
                    s.primary.update(gathered.flux(k, 0), gathered.count(k, 0), alpha);
                    s.indirect
                        .update(gathered.flux(k, 1), gathered.count(k, 1), alpha);
                }
            });
        if self.indirect_scale == IndirectScale::Automatic && self.stats.passes == 0 {
            self.widen_indirect(&gathered);
        }
        if self.adaptive_radius && self.stats.passes == 0 {
            self.first_pass_photons = self.pass_photons;
            self.adapt_radii(&gathered);
        }
        if self.stochastic && self.options.warm_restarts {
            self.last_points = self.point_records();
        }
        if self.stochastic {
            self.forget_before_supersampling();
            self.seen.tally(&self.pass_direct);
            for (d, p) in self.direct.iter_mut().zip(self.pass_direct.drain(..)) {
                *d += p.as_dvec3();
            }
            self.stats.eye_passes += 1;
            self.seen.choose(self.stats.eye_passes);
            self.seen.choose_by_variance(&self.direct, self.stats.eye_passes);
            self.stats.supersampled_share = self.seen.count() as f64 / self.direct.len().max(1) as f64;
        }
        self.stats.passes += 1;
        self.inherited = None;
        self.stats.indirect_radius_scale = match self.indirect_scale {
            IndirectScale::Fixed(k) => k,
            _ => 1.0,
        };
        self.stats.photons += self.pass_photons;
        self.stats.bounces += gathered.counts.bounces;
        self.stats.deposits += gathered.counts.deposits;
        self.stats.useful_paths += gathered.counts.useful;
        self.stats.visible_points = self.points.len();
        // Over the slots that have gathered photons; while none has (this estimate holds
        // caustics only when direct light is sampled, and a scene may have none), over every
        // slot with a radius: the radius in use, not 0.
        self.stats.mean_radius = mean_primary_radius(&self.slots, |s| s.primary.n > 0.0)
            .or_else(|| mean_primary_radius(&self.slots, Slot::has_radius))
            .unwrap_or(0.0);
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
