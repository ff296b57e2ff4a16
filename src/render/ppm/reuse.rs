//! A warm epoch's first pass traced only where the edit can change it.
//!
//! The first eye pass of a warm epoch repeats the previous epoch's last one (the same random
//! streams, [`super::warm::StreamOffset`]), and so do its area-light samples. Most of it
//! would find what that pass found:
//! - **Eye paths.** A pixel whose eye path was one ray that saw no light ([`PathKind::Single`]:
//!   no mirror or glass, no shadow ray, neither emission nor background) depends only on the
//!   scene along that ray. When the ray, up to its old visible point, meets none of the boxes
//!   the edits changed ([`Changed`]: a moved patch's control hull before and after, a moved
//!   area light's surface before and after), tracing it again would find the same point, and
//!   the point is copied instead ([`Reuse::copies`]); a pixel in front of which no changed
//!   box lies on screen is copied without its ray ([`Reuse::copies_unseen`]).
//! - **Area-light samples.** At a copied point, when no light moved and no box comes near the
//!   segments from the point to the area lights, the previous pass's samples (the same
//!   numbers as before) find the light they found ([`Reuse::copy_area_light`]).
//!
//! A copy is what a trace would give, bit for bit (up to hits exactly tied between two
//! surfaces), so the warm epoch's image is the same as with every pixel traced. On
//! `scenes/teapot.toml` a moved control point of patch 0 (`caustic bench edit
//! scenes/teapot.toml`) copies 98.5 % of the eye paths and 76 % of the area-light samples.
//!
//! Relighting engines keep the eye rays' surfaces in the same way and shade them again for
//! each change of the lights (Pellacini et al. 2005, "Lpics: a hybrid hardware-accelerated
//! relighting engine for computer cinematography"); here the surfaces themselves may move, so
//! what is kept is bounded by the boxes of what moved.

use glam::{DVec2, DVec3, Vec3};
use rayon::prelude::*;

use super::points::{Shade, VisiblePoints};
use crate::geometry::aabb::safe_inverse;
use crate::geometry::{Aabb, BezierPatch, Ray};
use crate::scene::{Camera, Light, Scene};

/// What one pixel's eye path was, for the next epoch's reuse.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum PathKind {
    /// Anything else: traced again.
    #[default]
    Other,
    /// One ray that saw no light, traced this pass.
    Single,
    /// One ray that saw no light, copied from the previous pass.
    Copied,
}

impl PathKind {
    /// The kind of a traced path that cast `rays` rays and saw `direct`, unless its pixel was
    /// supersampled (its light seen then came from other rays).
    pub fn traced(rays: u32, direct: DVec3, supersampled: bool) -> Self {
        if rays == 1 && direct == DVec3::ZERO && !supersampled {
            PathKind::Single
        } else {
            PathKind::Other
        }
    }

    /// Whether the path was one ray that saw no light.
    pub fn single(self) -> bool {
        self != PathKind::Other
    }
}

/// Where edits changed the scene: boxes holding every surface that moved, where it was and
/// where it is. A ray that meets none of them meets the same surfaces as before.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Changed {
    boxes: Vec<Aabb>,
}

impl Changed {
    /// What changed from a scene of `patches` and `lights` to `scene` (the same surfaces but
    /// for moved control points and moved lights): each changed patch's control hull before
    /// and after (a Bézier patch lies in its control points' hull), and each changed area
    /// light's surface before and after. Point and spot lights have no surface; the paths
    /// their light reaches cast shadow rays and are never reused.
    pub fn between(patches: &[BezierPatch], lights: &[Light], scene: &Scene) -> Self {
        let now = scene.geometry.patches();
        let mut boxes = Vec::new();
        for (old, (new, _)) in patches.iter().zip(now) {
            if old != new {
                boxes.push(old.bounds());
                boxes.push(new.bounds());
            }
        }
        for (old, new) in lights.iter().zip(&scene.lights) {
            if old != new {
                boxes.extend(old.surface_bounds());
                boxes.extend(new.surface_bounds());
            }
        }
        // A margin a thousand times the offset of a ray leaving a surface
        // ([`crate::geometry::ray::OFFSET_RELATIVE`]), so that a shadow ray's origin, off its
        // point, and rounding in the hulls and hits are covered.
        let scale = scene.geometry.bounds().diagonal().length();
        let margin = 1e-6 * if scale.is_finite() { scale.max(1.0) } else { 1.0 };
        Self {
            boxes: boxes.into_iter().map(|b| b.padded(margin)).collect(),
        }
    }

    /// What changed from `before` to `after`, a scene made from it by moving control points
    /// and lights ([`Changed::between`]).
    pub fn edit(before: &Scene, after: &Scene) -> Self {
        let patches: Vec<BezierPatch> = before.geometry.patches().iter().map(|(p, _)| *p).collect();
        Self::between(&patches, &before.lights, after)
    }

    /// Adds what later edits changed.
    pub fn add(&mut self, later: Changed) {
        self.boxes.extend(later.boxes);
    }

    /// Whether the segment `origin + t·dir`, `0 ≤ t ≤ t_max`, meets none of the boxes.
    pub fn misses(&self, origin: DVec3, dir: DVec3, t_max: f64) -> bool {
        self.misses_widened(origin, dir, t_max, 0.0)
    }

    /// Whether the segment `origin + t·dir`, `0 ≤ t ≤ t_max`, meets none of the boxes
    /// widened by `by` on every side.
    pub fn misses_widened(&self, origin: DVec3, dir: DVec3, t_max: f64, by: f64) -> bool {
        let inv = safe_inverse(dir);
        self.boxes
            .iter()
            .all(|b| b.padded(by).hit_interval(origin, inv, t_max).is_none())
    }
}

/// A sphere holding an area light's surface (`None` for point and spot lights).
fn bounding_sphere(light: &Light) -> Option<(DVec3, f64)> {
    match *light {
        Light::Sphere { center, radius, .. } => Some((center, radius)),
        _ => light
            .surface_bounds()
            .map(|b| (b.centroid(), 0.5 * b.diagonal().length())),
    }
}

/// What the last completed stochastic pass leaves for a warm epoch's first pass to reuse.
#[derive(Clone, Debug, Default)]
pub struct KeptEye {
    /// Its visible points, one place a pixel in pixel order (a placeholder,
    /// [`Shade::NONE`], where the pixel had none).
    pub points: VisiblePoints,
    /// Per pixel, what its eye path was.
    pub kinds: Vec<PathKind>,
    /// Per pixel, the light it saw in that pass: emission, shadow rays and area-light
    /// samples (for a [`PathKind::single`] path, the area-light samples alone).
    pub light: Vec<Vec3>,
}

impl KeptEye {
    /// Keeps a completed pass's `points` (taken: a copy made before the placeholders were
    /// dropped and the spatial index put them in its order), and copies of its path `kinds`
    /// and `light` seen, in the memory of the last.
    pub fn keep(&mut self, points: &mut VisiblePoints, kinds: &[PathKind], light: &[Vec3]) {
        std::mem::swap(&mut self.points, points);
        self.kinds.clear();
        self.kinds.extend_from_slice(kinds);
        self.light.clear();
        self.light.extend_from_slice(light);
    }
}

/// A rectangle of pixels, inclusive.
#[derive(Clone, Copy, Debug, PartialEq)]
struct PixelRect {
    x0: i64,
    y0: i64,
    x1: i64,
    y1: i64,
}

impl PixelRect {
    fn contains(&self, x: i64, y: i64) -> bool {
        (self.x0..=self.x1).contains(&x) && (self.y0..=self.y1).contains(&y)
    }
}

/// The pixels whose eye rays (jittered within the pixel, through any point of the lens) may
/// meet `b`: the rectangle around its corners' projections, widened by the lens's blur at
/// their nearest and farthest depths and by a pixel; `None` when any pixel's may (a corner
/// on or behind the lens plane). A box in front of the camera projects inside the hull of its
/// corners' projections.
fn pixels_meeting(camera: &Camera, b: &Aabb) -> Option<PixelRect> {
    let corners = (0..8).map(|k| {
        DVec3::new(
            if k & 1 == 0 { b.min.x } else { b.max.x },
            if k & 2 == 0 { b.min.y } else { b.max.y },
            if k & 4 == 0 { b.min.z } else { b.max.z },
        )
    });
    let (mut lo, mut hi) = (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY));
    let (mut near, mut far) = (f64::INFINITY, 0.0f64);
    for c in corners {
        let z = (c - camera.position).dot(camera.forward);
        if z <= 1e-9 * camera.position.abs().max_element().max(1.0) {
            return None;
        }
        let p = camera.project(c)?;
        (lo, hi) = (lo.min(p), hi.max(p));
        (near, far) = (near.min(z), far.max(z));
    }
    // A lens point `a` off the axis moves a point at depth z by a·|1/z − 1/f| on the image
    // plane at unit distance, whose height is 2·tan(fov/2) over `height` pixels.
    let per_unit = camera.height as f64 / (2.0 * (0.5 * camera.fov_y).tan());
    let blur = |z: f64| camera.aperture * (1.0 / z - 1.0 / camera.focal_distance).abs() * per_unit;
    let margin = blur(near).max(blur(far)) + 1.0;
    let (lo, hi) = (lo - margin, hi + margin);
    if !(lo.is_finite() && hi.is_finite()) {
        return None;
    }
    let clamp = |v: f64| v.floor().clamp(-1.0, 1e9) as i64;
    Some(PixelRect {
        x0: clamp(lo.x),
        y0: clamp(lo.y),
        x1: clamp(hi.x),
        y1: clamp(hi.y),
    })
}

/// A warm epoch's first pass's reuse of the previous pass ([`KeptEye`]) outside the
/// [`Changed`] boxes.
pub struct Reuse<'a> {
    kept: &'a KeptEye,
    changed: &'a Changed,
    /// Rectangles holding every pixel whose eye rays may meet a changed box (`None`: any
    /// pixel's may).
    rects: Option<Vec<PixelRect>>,
    /// Whether a light moved: every area-light sample is taken again.
    lights_moved: bool,
}

impl<'a> Reuse<'a> {
    /// Reuse of `kept` outside `changed`, seen by `camera`.
    pub fn new(kept: &'a KeptEye, changed: &'a Changed, camera: &Camera, lights_moved: bool) -> Self {
        let rects = changed.boxes.iter().map(|b| pixels_meeting(camera, b)).collect();
        Self {
            kept,
            changed,
            rects,
            lights_moved,
        }
    }

    /// The previous pass's points, one place a pixel ([`KeptEye::points`]).
    pub fn points(&self) -> &VisiblePoints {
        &self.kept.points
    }

    /// Whether pixel `pixel`, at `(x, y)`, keeps its previous point without a look at its
    /// ray: its path was one ray, and no changed box is in front of the pixel.
    pub fn copies_unseen(&self, pixel: usize, x: u64, y: u64) -> bool {
        let single = self.kept.kinds.get(pixel).is_some_and(|k| k.single());
        let clear = |rects: &Vec<PixelRect>| !rects.iter().any(|r| r.contains(x as i64, y as i64));
        single && self.rects.as_ref().is_some_and(clear)
    }

    /// Whether pixel `pixel`, whose eye ray `ray` is the same as in the previous pass, keeps
    /// its previous point: its path was one ray, and the ray, up to the old point (or all of
    /// it, without one), misses every changed box.
    pub fn copies(&self, pixel: usize, ray: &Ray) -> bool {
        if !self.kept.kinds.get(pixel).is_some_and(|k| k.single()) {
            return false;
        }
        let points = &self.kept.points;
        // The box test pads its far end.
        let t_max = match points.shade.get(pixel) {
            Some(s) if s.slot != Shade::NONE => {
                (points.reach[pixel].position - ray.origin).length() / ray.dir.length()
            }
            _ => f64::INFINITY,
        };
        self.changed.misses(ray.origin, ray.dir, t_max)
    }

    /// Adds the previous pass's area-light samples to `light` (this pass's light seen per
    /// pixel) at each copied pixel (`kinds`) where they are still right: no light moved, and
    /// no changed box comes near the segment from the point to any area light (a segment to
    /// the light's bounding sphere's centre, missing the boxes widened by its radius, holds
    /// every shadow ray to the light). Returns, per pixel, whether its light was so found; the
    /// others sample the lights. In pixel order, in parallel.
    pub fn copy_area_light(&self, scene: &Scene, kinds: &[PathKind], light: &mut [Vec3]) -> Vec<bool> {
        let pixels = light.len();
        if self.lights_moved || kinds.len() != pixels || self.kept.light.len() != pixels {
            return Vec::new();
        }
        let spheres: Vec<(DVec3, f64)> = scene.lights.iter().filter_map(bounding_sphere).collect();
        let points = &self.kept.points;
        let mut known = vec![false; pixels];
        known
            .par_iter_mut()
            .zip(light.par_iter_mut())
            .enumerate()
            .with_min_len(4096)
            .for_each(|(p, (known, light))| {
                if kinds[p] != PathKind::Copied {
                    return;
                }
                let position = points.reach[p].position;
                let clear =
                    |&(c, r): &(DVec3, f64)| self.changed.misses_widened(position, c - position, 1.0, r);
                if points.shade[p].slot == Shade::NONE || spheres.iter().all(clear) {
                    *light += self.kept.light[p];
                    *known = true;
                }
            });
        known
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_segment_misses_only_boxes_it_does_not_reach() {
        let changed = Changed {
            boxes: vec![Aabb::new(DVec3::new(1.0, -1.0, -1.0), DVec3::new(2.0, 1.0, 1.0))],
        };
        // Along +x from the origin: the box starts at t = 1.
        assert!(changed.misses(DVec3::ZERO, DVec3::X, 0.99));
        assert!(!changed.misses(DVec3::ZERO, DVec3::X, 1.01));
        assert!(!changed.misses(DVec3::ZERO, DVec3::X, f64::INFINITY));
        // Away from it, or past it.
        assert!(changed.misses(DVec3::ZERO, -DVec3::X, f64::INFINITY));
        assert!(changed.misses(DVec3::new(0.0, 2.0, 0.0), DVec3::X, f64::INFINITY));
        assert!(Changed::default().misses(DVec3::ZERO, DVec3::X, f64::INFINITY));
    }
}
