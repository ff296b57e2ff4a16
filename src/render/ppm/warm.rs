//! Warm restarts: what a new epoch keeps from the previous one after an edit of the scene (a
//! control point or a light moved; camera and settings unchanged).
//!
//! Kept, because it is still valid or converges to the right image anyway:
//! - **The statistics of every pixel whose visible points did not move.** The new epoch's first
//!   eye pass traces the same eye rays as the previous epoch's last one (the random streams
//!   continue, [`StreamOffset`]); a pixel whose points come out where they were (or moved by
//!   at most [`NEAR`] of their radius, facing the same way) keeps its slots: radius, photon
//!   count `N`, and its flux as a *prior* worth at most [`PRIOR_PASSES`] times the epoch's
//!   first pass of photons ([`Slot::prior`]; with the viewer's photon ramp that first pass is
//!   16,384 photons, so the prior is a fraction of a full pass), and the light it saw
//!   directly, worth [`PRIOR_PASSES`] passes. The prior
//!   is counted like photons emitted before the epoch, so the estimate
//!   `τ/(πR²(N_emitted + prior))` starts at the previous image and the epoch's own photons take
//!   over as they come: where the edit changed the light (a moved caustic or shadow), the old
//!   light's share after the epoch has emitted `k` first passes' worth of photons is at most
//!   `PRIOR_PASSES/(PRIOR_PASSES + k)`, and the converged image is the edited scene's.
//!   The count `N` is capped with the flux, so the estimate goes on as one that had gathered
//!   the prior's photons; and a radius so narrow that the first passes would hand it fewer
//!   photons than a cold slot's adaptive radius aims at is widened towards it (never beyond a
//!   cold slot's), its value unchanged (`Reopen`): kept at their converged radii, those few
//!   new photons would be noisier than a cold start's.
//! - **Estimates near a moved point.** A point that moved further (the edited surface, what is
//!   seen through or in it) takes the previous estimate of the nearest point of any pixel
//!   whose radius holds it and that faces the same way, the flux scaled by the ratio of the
//!   two points' weights: a density estimate is one of light arriving around a place, whoever
//!   looks at it. Only points with no estimate near start cold, at the previous epoch's initial
//!   radius.
//! - **The radius choices**: the initial radius and the indirect estimate's scale, so cold and
//!   kept pixels agree.
//! - **The emission guide's learned densities** as a prior the new epoch keeps learning
//!   ([`EmissionGuide::as_prior`]). A moved or turned light keeps one first pass's worth of
//!   its own, an eighth of the others': a move made by hand changes where its photons go a
//!   little, and from the epoch's second pass what it learns anew outweighs what it kept. A
//!   light that forgot its guide emitted uniformly, and the first image after a move was as
//!   noisy as a cold restart's preview (`caustic bench edit scenes/ring.toml --light 0`:
//!   RMSE 1.16e-1 forgotten, 4.6e-2 kept).
//!
//! A moved (or turned) light changes the light seen directly at every pixel it reaches, a
//! term each pass estimates afresh (point lights by shadow ray, area lights by one sample a
//! pass): its prior is dropped, and only the photons' estimates are kept, which the new
//! photons take over from as after a moved control point.
//!
//! An epoch interrupted before its first pass completed hands on what it inherited, so a drag
//! that moves faster than a pass still warms each step from the last image that was made.

use super::estimate::{Estimate, Slot};
use super::guide::EmissionGuide;
use super::hash_grid::HashGrid;
use super::light::PriorLight;
use super::points::{SearchSphere, Shade, VisiblePoints};
use super::radius::{IndirectScale, RadiusPolicy, DENSE_PHOTONS, INDIRECT_PHOTONS};
use super::reuse::{Changed, KeptEye, Reuse};
use glam::{DVec3, Vec3};
use rayon::prelude::*;

use crate::geometry::Aabb;
use crate::scene::Camera;

/// The most a kept pixel's previous estimate counts for, in passes of the epoch's first pass's
/// photons (the photon ramp's first pass in the viewer, 16,384 photons: on
/// `scenes/inline_patch.toml` at 480×360 the prior is then 131,072 photons, 0.19 of a full
/// pass). Chosen with `caustic bench edit` (time from an edit to relative MSE 1e-2): a smaller
/// prior lets the new photons' noise at the kept, narrow radii through; a larger one keeps the
/// old light where the edit changed it (the caustic's moved edge) too long.
pub const PRIOR_PASSES: f64 = 8.0;

/// Where an epoch's random streams start: a warm epoch continues the previous one's, so its
/// photons are new ones and its first eye pass repeats the previous epoch's last.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct StreamOffset {
    /// Passes before this epoch (the eye pass and light-sample index).
    pub passes: u64,
    /// Photons before this epoch (the photon index).
    pub photons: u64,
}

/// What an epoch hands to the next after an edit ([`super::Ppm::into_warm_start`]): a
/// control point or a light moved ([`WarmStart::light_moved`]).
#[derive(Clone, Debug)]
pub struct WarmStart {
    /// The image size.
    pub(super) size: (u32, u32),
    /// Whether the eye pass was stochastic.
    pub(super) stochastic: bool,
    /// The statistics, each with its flux counted as [`Slot::prior`] photons (not yet capped),
    /// in pixel order.
    pub(super) slots: Vec<Slot>,
    /// Each slot's visible point in the last completed eye pass.
    pub(super) points: Vec<PointRecord>,
    /// Per pixel, the light seen directly, as sums over the passes they count.
    pub(super) light: Vec<PriorLight>,
    /// The initial radius².
    pub(super) initial_radius2: f64,
    /// The indirect estimate's radius choice.
    pub(super) indirect_scale: IndirectScale,
    /// The emission guide as it learned.
    pub(super) guide: Option<EmissionGuide>,
    /// Lights moved since the guide learned (they forget).
    pub(super) moved_lights: Vec<usize>,
    /// The streams after the last completed pass.
    pub(super) next: StreamOffset,
    /// The last completed stochastic pass's points, for the next epoch's first pass to copy
    /// where the edits cannot have changed them ([`super::reuse`]).
    pub(super) eye: Option<KeptEye>,
    /// What the edits since that pass changed (`None`: not known, nothing is reused).
    pub(super) changed: Option<Changed>,
}

impl WarmStart {
    /// Notes what an edit changed (added to what earlier edits since the kept pass did): the
    /// next epoch's first pass traces again whatever may meet it, and copies the rest of the
    /// kept pass's points (`ppm::reuse`). Without it nothing is copied.
    pub fn edited(&mut self, changed: Changed) {
        match &mut self.changed {
            Some(c) => c.add(changed),
            None => self.changed = Some(changed),
        }
    }

    /// The reuse of the kept pass's points by the next epoch's first pass, when there is one.
    pub(super) fn reuse(&self, camera: &Camera) -> Option<Reuse<'_>> {
        let eye = self.eye.as_ref()?;
        let changed = self.changed.as_ref()?;
        Some(Reuse::new(eye, changed, camera, !self.moved_lights.is_empty()))
    }

    /// Notes that light `light` moved or turned: its part of the emission guide is kept at
    /// one first pass's worth, and the light seen directly starts afresh.
    pub fn light_moved(&mut self, light: usize) {
        if !self.moved_lights.contains(&light) {
            self.moved_lights.push(light);
        }
    }
}

/// A slot's visible point, kept compactly (40 bytes) for the next epoch to compare with; all
/// zero for a slot without one.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PointRecord {
    position: Vec3,
    normal: Vec3,
    weight: Vec3,
    /// Whether the point has glossy lobes: its estimate then weighs photons by the direction
    /// to the eye as well, and carries only to the same point.
    glossy: bool,
}

impl PointRecord {
    /// Whether an estimate may carry to or from another pixel's point near it: a point
    /// without glossy lobes (whose estimate is one of light arriving, scaled by the weight).
    fn carries_nearby(&self) -> bool {
        self.weight != Vec3::ZERO && !self.glossy
    }
}

/// Each of `slots` slots' visible point among `points` (each point names its slot).
pub fn records(slots: usize, points: &VisiblePoints) -> Vec<PointRecord> {
    let mut out = vec![PointRecord::default(); slots];
    for (k, (r, s)) in points.reach.iter().zip(&points.shade).enumerate() {
        out[s.slot as usize] = PointRecord {
            position: r.position.as_vec3(),
            normal: s.normal,
            weight: s.weight,
            glossy: matches!(points.glossy.get(k), Some(Some(_))),
        };
    }
    out
}

/// [`records`] of points that lie one place a slot (place `k` holds slot `k`'s point or a
/// placeholder: a stochastic pass's, before the placeholders are dropped), in parallel.
pub fn records_in_place(points: &VisiblePoints) -> Vec<PointRecord> {
    (0..points.len())
        .into_par_iter()
        .with_min_len(4096)
        .map(|k| {
            let (r, s) = (&points.reach[k], &points.shade[k]);
            if s.slot == Shade::NONE {
                return PointRecord::default();
            }
            debug_assert_eq!(s.slot as usize, k, "one place a slot");
            PointRecord {
                position: r.position.as_vec3(),
                normal: s.normal,
                weight: s.weight,
                glossy: matches!(points.glossy.get(k), Some(Some(_))),
            }
        })
        .collect()
}

/// How a previous slot's estimate carries to a new visible point of the same pixel: `None`
/// when the point moved by more than [`NEAR`] of the estimate's radius, turned, its weight
/// changed more than twofold, or it changed at all on a glossy surface (whose estimate
/// depends on the direction to the eye, which no factor corrects); else the factor the flux
/// takes for the new weight (1 where nothing changed).
fn carry(old: &PointRecord, new: &PointRecord, radius2: f64) -> Option<DVec3> {
    // Equal, or both without a point (a stochastic pixel whose path found no diffuse surface
    // in either pass).
    if old == new {
        return Some(DVec3::ONE);
    }
    if old.weight == Vec3::ZERO || new.weight == Vec3::ZERO || old.glossy || new.glossy {
        return None;
    }
    let moved2 = (old.position - new.position).as_dvec3().length_squared();
    if moved2 > NEAR * NEAR * radius2 || old.normal.dot(new.normal) < 0.9 {
        return None;
    }
    let ratio = (new.weight / old.weight.max(Vec3::splat(1e-30))).as_dvec3();
    let plausible = |r: f64| (0.5..=2.0).contains(&r);
    (plausible(ratio.x) && plausible(ratio.y) && plausible(ratio.z)).then_some(ratio)
}

/// How a kept estimate is reopened for the new epoch ([`Reopen::prior`]).
#[derive(Clone, Copy, Debug)]
pub(super) struct Reopen {
    /// Photons of the epoch's first pass (a prior is worth at most [`PRIOR_PASSES`] of them,
    /// [`Reopen::cap`]).
    first_pass: f64,
    /// PPM's α (a pass adds `α M` to `N`).
    alpha: f64,
    /// The radius² a cold slot starts at: primary, indirect estimate.
    ceiling2: [f64; 2],
}

impl Reopen {
    /// The most photons a prior is worth.
    fn cap(&self) -> f64 {
        PRIOR_PASSES * self.first_pass
    }

    /// A previous slot as a prior for a new point, its flux scaled by `factor` for the new
    /// point's weight. It is worth at most `Reopen::cap` photons: flux and count `N` scaled
    /// down with the photons it counts, so that it behaves as an estimate that gathered that
    /// many. And
    /// each estimate is widened (`Reopen::widened`) where its converged, narrow radius would
    /// hand the new epoch's first passes too few photons: at the old radius those few new
    /// photons are noisier than a cold start's (on the built-in teapot a warm restart reached
    /// the error 1e-2 later than a cold one).
    pub fn prior(&self, mut slot: Slot, factor: DVec3) -> Slot {
        let prior = slot.prior as f64;
        let cap = self.cap();
        let scale = if prior > cap { cap / prior } else { 1.0 };
        let photons = prior * scale;
        for (k, e) in [&mut slot.primary, &mut slot.indirect].into_iter().enumerate() {
            e.scale_tau(scale * factor);
            e.set_n(e.n() * scale);
            *e = self.widened(
                *e,
                photons,
                self.ceiling2[k],
                if k == 0 { DENSE_PHOTONS } else { INDIRECT_PHOTONS },
            );
        }
        slot.prior = photons as f32;
        slot
    }

    /// `e` (an estimate that counts `photons` emitted photons) brought to the radius at which
    /// a first pass would hand it about `aim` photons — as [`RadiusPolicy::adapt_radii`] and
    /// [`RadiusPolicy::widen_indirect`] choose a cold slot's — never narrower than it is nor wider than
    /// a cold slot's `ceiling2`; `N` and `τ` scaled by the area as PPM's update assumes, so its
    /// value is unchanged. Its density is taken from `N`, which grows by `α M` a pass; the
    /// photons counted then fell within radii at least as wide, so it errs towards less
    /// widening.
    fn widened(&self, e: Estimate, photons: f64, ceiling2: f64, aim: f64) -> Estimate {
        let r2 = e.radius2();
        if r2 <= 0.0 || r2 >= ceiling2 {
            return e;
        }
        let per_pass = e.n() / (self.alpha * photons.max(1.0)) * self.first_pass;
        if per_pass >= aim {
            return e;
        }
        let wider = if per_pass > 0.0 {
            r2 * aim / per_pass
        } else {
            ceiling2
        };
        e.resized(wider.min(ceiling2))
    }
}

/// A visible point that moved by at most this share of its previous estimate's radius keeps
/// the estimate (as a prior, with the flux scaled by the new weight): the photons it gathered
/// lie about as near the new point, as PPM's own radius assumes.
pub const NEAR: f64 = 0.5;

/// Pixel-ordered runs of slots: `(pixel, range in slots)`.
fn runs(slots: &[Slot]) -> Vec<(u32, std::ops::Range<usize>)> {
    let mut out: Vec<(u32, std::ops::Range<usize>)> = Vec::new();
    for (k, s) in slots.iter().enumerate() {
        match out.last_mut() {
            Some((px, range)) if *px == s.pixel => range.end = k + 1,
            _ => out.push((s.pixel, k..k + 1)),
        }
    }
    out
}

/// An epoch's part in warm restarts: where its random streams start, what it inherited, and
/// the points of its last completed stochastic pass.
#[derive(Default)]
pub(super) struct Epoch {
    /// Where this epoch's random streams start (after the previous epoch's, when warm).
    pub offset: StreamOffset,
    /// What a warm restart inherited, until the first pass completes.
    pub inherited: Option<WarmStart>,
    /// The last completed stochastic pass's points, with [`PpmOptions::warm_restarts`].
    ///
    /// [`PpmOptions::warm_restarts`]: super::PpmOptions::warm_restarts
    pub last_eye: Option<KeptEye>,
}

impl Epoch {
    /// The reuse of the previous epoch's last pass by this epoch's first (`first`), seen by
    /// `camera`, when it inherited one ([`WarmStart::reuse`]).
    pub fn reuse(&self, first: bool, camera: &Camera) -> Option<Reuse<'_>> {
        self.inherited.as_ref().filter(|_| first)?.reuse(camera)
    }

    /// Whether this epoch continues an earlier one's estimates (it inherited a warm start).
    pub fn is_warm(&self) -> bool {
        self.offset != StreamOffset::default()
    }

    /// Inherits `warm`: the first eye pass repeats the previous epoch's last one, so that
    /// unmoved points come out equal; photons continue after the previous epoch's.
    pub fn inherit(&mut self, warm: WarmStart) {
        self.offset = StreamOffset {
            passes: warm.next.passes.saturating_sub(1),
            photons: warm.next.photons,
        };
        self.inherited = Some(warm);
    }
}

/// What a warm restart kept at the epoch's first eye pass ([`WarmStart::keep_unmoved`]).
pub(super) struct Kept {
    /// Share of the pixels whose slots were kept.
    pub kept_share: f64,
    /// Share of the pixels warmed by an estimate near their moved points.
    pub nearby_share: f64,
    /// Per pixel, the light seen directly that was kept.
    pub light: Vec<PriorLight>,
}

impl Reopen {
    /// How an epoch whose radius choices are `radius` (after its first eye pass, when the
    /// initial radius is set), with `alpha` and `first_pass` photons in its first pass,
    /// reopens the estimates it keeps.
    pub fn new(radius: &RadiusPolicy, alpha: f64, first_pass: u64) -> Self {
        let r0_2 = radius.initial_radius2;
        let indirect = radius.indirect_scale.initial_radius(r0_2.sqrt());
        Reopen {
            first_pass: first_pass as f64,
            alpha,
            ceiling2: [r0_2, indirect * indirect],
        }
    }
}

impl WarmStart {
    /// After the first eye pass of an epoch that inherited this (of a `size` image, whose
    /// `slots` have their visible points `now`): every pixel whose visible points are where
    /// they were (or moved by at most [`NEAR`] of their radius) keeps its slots' statistics,
    /// the flux capped to a prior of [`PRIOR_PASSES`] first passes; the slots of moved points
    /// near a previous point take its estimate (`WarmStart::carry_nearby`).
    pub(super) fn keep_unmoved(
        &self,
        slots: &mut [Slot],
        now: &[PointRecord],
        reopen: &Reopen,
        size: (u32, u32),
    ) -> Kept {
        let pixels = size.0 as usize * size.1 as usize;
        let mut light = vec![PriorLight::default(); pixels];
        let mut carried = vec![false; slots.len()];
        let one_each = self.stochastic && self.slots.len() == slots.len() && slots.len() == pixels;
        let kept = if one_each {
            self.keep_one_each(slots, now, reopen, (&mut light, &mut carried))
        } else {
            self.keep_runs(slots, now, reopen, (&mut light, &mut carried))
        };
        let nearby = self.carry_nearby(slots, now, &carried, reopen);
        let pixels = (size.0 as f64 * size.1 as f64).max(1.0);
        Kept {
            kept_share: kept as f64 / pixels,
            nearby_share: nearby as f64 / pixels,
            light,
        }
    }

    /// [`WarmStart::keep_unmoved`] where every pixel has one slot, its own (stochastic: slot
    /// `k` is pixel `k`), in parallel: the slots kept, their light seen, and which were kept.
    /// Returns the pixels kept.
    fn keep_one_each(
        &self,
        slots: &mut [Slot],
        now: &[PointRecord],
        reopen: &Reopen,
        (light, carried): (&mut [PriorLight], &mut [bool]),
    ) -> usize {
        let keep_light = self.moved_lights.is_empty();
        slots
            .par_iter_mut()
            .zip(light.par_iter_mut())
            .zip(carried.par_iter_mut())
            .enumerate()
            .with_min_len(4096)
            .map(|(k, ((slot, light), carried))| {
                let old = &self.slots[k];
                let Some(factor) = carry(&self.points[k], &now[k], old.primary.radius2()) else {
                    return 0;
                };
                if keep_light {
                    *light = self.light[k].capped(PRIOR_PASSES, factor);
                }
                *slot = reopen.prior(*old, factor);
                *carried = true;
                1
            })
            .sum()
    }

    /// [`WarmStart::keep_unmoved`] for pixels with any number of slots (classic PPM's split
    /// glass paths): a pixel keeps its slots when it has as many as before and every one of
    /// its points carries. Returns the pixels kept.
    fn keep_runs(
        &self,
        slots: &mut [Slot],
        now: &[PointRecord],
        reopen: &Reopen,
        (light, carried): (&mut [PriorLight], &mut [bool]),
    ) -> usize {
        let (old, new) = (runs(&self.slots), runs(slots));
        // Whether each run's points all carry, decided in parallel.
        let carries: Vec<Option<(usize, DVec3)>> = new
            .par_iter()
            .enumerate()
            .map(|(n, (pixel, range))| {
                let o = if old.get(n).is_some_and(|(q, _)| q == pixel) {
                    Some(n)
                } else {
                    old.binary_search_by_key(pixel, |(q, _)| *q).ok()
                };
                let old_range = &old[o?].1;
                (old_range.len() == range.len()).then_some(())?;
                let mut first = None;
                for (from, to) in old_range.clone().zip(range.clone()) {
                    let f = carry(&self.points[from], &now[to], self.slots[from].primary.radius2())?;
                    first.get_or_insert((o?, f));
                }
                first
            })
            .collect();
        let mut kept = 0usize;
        for ((pixel, range), first) in new.iter().zip(carries) {
            let Some((o, first)) = first else {
                continue;
            };
            let old_range = &old[o].1;
            if self.moved_lights.is_empty() {
                light[*pixel as usize] = self.light[*pixel as usize].capped(PRIOR_PASSES, first);
            }
            for (from, to) in old_range.clone().zip(range.clone()) {
                let factor = carry(&self.points[from], &now[to], self.slots[from].primary.radius2())
                    .unwrap_or(DVec3::ONE);
                slots[to] = reopen.prior(self.slots[from], factor);
            }
            kept += 1;
            carried[range.clone()].iter_mut().for_each(|c| *c = true);
        }
        kept
    }

    /// For each slot of a moved pixel whose new visible point lies within the radius of a
    /// previous one (any pixel's, facing the same way): that estimate as its prior, the flux
    /// scaled by the ratio of the two points' weights (the estimate's density of arriving
    /// light is the same there, up to PPM's own blur). Of several, the nearest; of equally
    /// near ones, the first slot's. Returns the pixels so warmed.
    ///
    /// The points left after a small edit are few and the previous ones many, so the grid is
    /// built over the points left and each previous point near them looks for those within
    /// its own radius: a grid over the previous points cost more than the rest of the warm
    /// start together.
    fn carry_nearby(
        &self,
        slots: &mut [Slot],
        now: &[PointRecord],
        carried: &[bool],
        reopen: &Reopen,
    ) -> usize {
        let left: Vec<Left> = now
            .iter()
            .zip(carried)
            .enumerate()
            .filter(|(_, (r, &c))| !c && r.carries_nearby())
            .map(|(to, (r, _))| Left {
                to: to as u32,
                position: r.position.as_dvec3(),
                normal: r.normal.as_dvec3(),
                reach2: 0.0,
            })
            .collect();
        if left.is_empty() {
            return 0;
        }
        // Only previous points near the points left can hold one.
        let near = left
            .iter()
            .fold(Aabb::EMPTY, |b, l| b.grow(l.position))
            .padded(self.initial_radius2.sqrt());
        let old: Vec<u32> = (0..self.points.len() as u32)
            .into_par_iter()
            .filter(|&k| {
                let r = &self.points[k as usize];
                r.carries_nearby() && near.contains(r.position.as_dvec3())
            })
            .collect();
        let reach2 = old
            .iter()
            .map(|&k| self.slots[k as usize].primary.radius2())
            .fold(0.0, f64::max);
        let left: Vec<Left> = left.into_iter().map(|l| Left { reach2, ..l }).collect();
        let (grid, order) = HashGrid::build(&left);
        let left: Vec<Left> = order.iter().map(|&k| left[k as usize]).collect();
        // Every (point left, previous point) pair within the previous point's radius, then
        // the nearest for each point left.
        let mut pairs: Vec<(u32, f64, u32)> = old
            .par_iter()
            .flat_map_iter(|&from| {
                let o = &self.points[from as usize];
                let (p, normal) = (o.position.as_dvec3(), o.normal.as_dvec3());
                let radius2 = self.slots[from as usize].primary.radius2();
                let mut found = Vec::new();
                grid.for_candidates(p, radius2.sqrt(), &mut |k| {
                    let l = &left[k as usize];
                    let d2 = (p - l.position).length_squared();
                    if normal.dot(l.normal) >= 0.9 && d2 <= radius2 {
                        found.push((l.to, d2, from));
                    }
                });
                found
            })
            .collect();
        pairs.par_sort_unstable_by(|a, b| (a.0, a.1, a.2).partial_cmp(&(b.0, b.1, b.2)).expect("finite"));
        pairs.dedup_by_key(|p| p.0);
        let mut warmed = std::collections::BTreeSet::new();
        for (to, _, from) in pairs {
            let (to, from) = (to as usize, from as usize);
            let factor =
                now[to].weight.as_dvec3() / self.points[from].weight.as_dvec3().max(DVec3::splat(1e-30));
            let mut slot = reopen.prior(self.slots[from], factor);
            slot.pixel = slots[to].pixel;
            slots[to] = slot;
            warmed.insert(slot.pixel);
        }
        warmed.len()
    }
}

/// A point left to warm by [`WarmStart::carry_nearby`], as the grid holds it: a sphere as
/// wide as the widest previous estimate near, so that every previous point finds the points
/// within its own radius.
#[derive(Clone, Copy)]
struct Left {
    to: u32,
    position: DVec3,
    normal: DVec3,
    reach2: f64,
}

impl SearchSphere for Left {
    fn centre(&self) -> DVec3 {
        self.position
    }

    fn reach2(&self) -> f64 {
        self.reach2
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A reopening for a first pass of 10,000 photons (a cap of 80,000), α = 0.5, cold radii²
    /// 1 and 4.
    const REOPEN: Reopen = Reopen {
        first_pass: 10_000.0,
        alpha: 0.5,
        ceiling2: [1.0, 4.0],
    };

    fn slot(primary: Estimate, indirect: Estimate, prior: f64) -> Slot {
        Slot {
            primary,
            indirect,
            prior: prior as f32,
            ..Slot::new(0)
        }
    }

    fn close(a: DVec3, b: DVec3) -> bool {
        (a - b).abs().max_element() <= 1e-5 * b.abs().max_element()
    }

    /// The nearest previous point by brute force, as `carry_nearby` defines it.
    fn nearest_by_brute_force(warm: &WarmStart, new: &PointRecord) -> Option<usize> {
        let p = new.position.as_dvec3();
        (0..warm.points.len())
            .filter(|&k| {
                let o = &warm.points[k];
                let d2 = (o.position.as_dvec3() - p).length_squared();
                o.carries_nearby()
                    && o.normal.as_dvec3().dot(new.normal.as_dvec3()) >= 0.9
                    && d2 <= warm.slots[k].primary.radius2()
            })
            .map(|k| ((warm.points[k].position.as_dvec3() - p).length_squared(), k))
            .min_by(|a, b| a.partial_cmp(b).expect("finite"))
            .map(|(_, k)| k)
    }

    #[test]
    fn a_moved_point_takes_the_nearest_previous_estimate_whose_radius_holds_it() {
        use rand::{Rng, SeedableRng};
        let mut rng = rand_pcg::Pcg64Mcg::seed_from_u64(5);
        let record = |rng: &mut rand_pcg::Pcg64Mcg| {
            let flip = rng.random::<f32>() < 0.1;
            PointRecord {
                // Some on a grid, so that equally near points occur.
                position: if rng.random::<f32>() < 0.3 {
                    Vec3::new(
                        rng.random_range(0..20) as f32 * 0.05,
                        rng.random_range(0..20) as f32 * 0.05,
                        0.0,
                    )
                } else {
                    Vec3::new(rng.random(), rng.random(), rng.random::<f32>() * 0.05)
                },
                normal: if flip { -Vec3::Z } else { Vec3::Z },
                weight: Vec3::new(0.5, rng.random::<f32>() + 0.1, 0.25),
                glossy: rng.random::<f32>() < 0.05,
            }
        };
        let old: Vec<PointRecord> = (0..3000).map(|_| record(&mut rng)).collect();
        let slots: Vec<Slot> = (0..3000)
            .map(|k| Slot {
                primary: Estimate::new(rng.random::<f64>() * 0.004, 50.0, DVec3::splat(k as f64)),
                prior: 1e5,
                ..Slot::new(k as u32)
            })
            .collect();
        let warm = WarmStart {
            size: (3000, 1),
            stochastic: true,
            slots,
            points: old,
            light: Vec::new(),
            initial_radius2: 0.004,
            indirect_scale: IndirectScale::Fixed(1.0),
            guide: None,
            moved_lights: Vec::new(),
            next: StreamOffset::default(),
            eye: None,
            changed: None,
        };
        let now: Vec<PointRecord> = (0..3000).map(|_| record(&mut rng)).collect();
        let carried: Vec<bool> = (0..3000).map(|k| k % 3 == 0).collect();
        let mut new_slots: Vec<Slot> = (0..3000).map(|k| Slot::new(k as u32)).collect();
        let warmed = warm.carry_nearby(&mut new_slots, &now, &carried, &REOPEN);
        let mut expected_warmed = 0;
        for (to, new) in now.iter().enumerate() {
            let from = (!carried[to] && new.carries_nearby())
                .then(|| nearest_by_brute_force(&warm, new))
                .flatten();
            let expected = match from {
                Some(from) => {
                    expected_warmed += 1;
                    let factor = new.weight.as_dvec3() / warm.points[from].weight.as_dvec3();
                    Slot {
                        pixel: to as u32,
                        ..REOPEN.prior(warm.slots[from], factor)
                    }
                }
                None => Slot::new(to as u32),
            };
            assert_eq!(new_slots[to], expected, "point {to}");
        }
        assert_eq!(warmed, expected_warmed);
        assert!(expected_warmed > 300, "{expected_warmed}: too few to test");
    }

    #[test]
    fn a_kept_slot_is_worth_at_most_the_cap_and_shows_the_same_light() {
        // 800,000 photons emitted; at radius² 0.01 the primary gathered N = 0.5 · 6,400
        // (a first pass hands it 80, more than DENSE_PHOTONS): it keeps its radius.
        let primary = Estimate::new(0.01, 3_200.0, DVec3::new(2.0, 3.0, 4.0));
        let indirect = Estimate::new(3.0, 400_000.0, DVec3::splat(10.0));
        let old = slot(primary, indirect, 800_000.0);
        let new = REOPEN.prior(old, DVec3::ONE);
        assert_eq!(new.prior, 80_000.0);
        assert_eq!(new.primary.radius2(), 0.01_f32 as f64);
        assert!((new.primary.n() - 320.0).abs() < 1e-3);
        for (a, b) in [(old.primary, new.primary), (old.indirect, new.indirect)] {
            assert!(close(b.radiance(80_000.0), a.radiance(800_000.0)));
        }
        // A weight twice as bright doubles the flux.
        let brighter = REOPEN.prior(old, DVec3::splat(2.0));
        assert!(close(brighter.primary.tau(), 2.0 * new.primary.tau()));
    }

    #[test]
    fn a_sparse_narrow_estimate_widens_towards_a_cold_radius_with_the_same_value() {
        // Radius² 0.01 with N = 0.5 · 160 over 800,000 photons: a first pass hands it 2
        // photons; 64 would need radius² 0.32.
        let primary = Estimate::new(0.01, 80.0, DVec3::new(2.0, 3.0, 4.0));
        // Radius² 0.5, a first pass hands it 0.5: widened to the cold indirect radius² 4.
        let indirect = Estimate::new(0.5, 20.0, DVec3::splat(1.0));
        let old = slot(primary, indirect, 800_000.0);
        let new = REOPEN.prior(old, DVec3::ONE);
        assert!((new.primary.radius2() - 0.32).abs() < 1e-6, "{:?}", new.primary);
        assert_eq!(new.indirect.radius2(), 4.0);
        for (a, b) in [(old.primary, new.primary), (old.indirect, new.indirect)] {
            assert!(close(b.radiance(80_000.0), a.radiance(800_000.0)));
        }
        // N as the capped photons would have gathered at the new radius: 2 · 32 · 0.5 · 8.
        assert!((new.primary.n() - 256.0).abs() < 1e-3, "{:?}", new.primary);
        // No photon ever: straight to the cold radius. No radius (the indirect estimate is
        // off): none.
        let dark = slot(
            Estimate::new(0.01, 0.0, DVec3::ZERO),
            Estimate::default(),
            800_000.0,
        );
        let new = REOPEN.prior(dark, DVec3::ONE);
        assert_eq!(new.primary.radius2(), 1.0);
        assert_eq!(new.indirect.radius2(), 0.0);
        // A radius already as wide as a cold one stays.
        let wide = slot(
            Estimate::new(2.0, 1.0, DVec3::ONE),
            Estimate::default(),
            800_000.0,
        );
        assert_eq!(REOPEN.prior(wide, DVec3::ONE).primary.radius2(), 2.0);
    }
}
