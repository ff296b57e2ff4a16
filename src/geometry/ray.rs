//! Rays, and the offset that keeps a ray leaving a surface from hitting that surface again.

use glam::DVec3;

use super::patch::PatchPoint;

/// A ray `origin + t * dir` with a unit direction, so `t` is a distance in scene units.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ray {
    /// Where the ray starts.
    pub origin: DVec3,
    /// Unit direction.
    pub dir: DVec3,
    /// The point of a Bézier patch the ray leaves from, when it was spawned there: the patch's
    /// intersector then knows the ray's own crossing of that patch instead of finding it again
    /// ([`PatchPoint`]).
    pub leaving: Option<PatchPoint>,
}

impl Ray {
    /// A ray from `origin` along `dir` (normalised here; `dir` must be non-zero and finite).
    pub fn new(origin: DVec3, dir: DVec3) -> Self {
        Self {
            origin,
            dir: dir.normalize(),
            leaving: None,
        }
    }

    /// This ray, known to leave the patch point `point`.
    pub fn leaving(self, point: Option<PatchPoint>) -> Self {
        Self {
            leaving: point,
            ..self
        }
    }

    /// The point at distance `t`.
    #[inline]
    pub fn at(&self, t: f64) -> DVec3 {
        self.origin + t * self.dir
    }
}

/// Relative size of the offset applied to a ray's origin when it leaves a surface, in units of
/// the largest coordinate of the hit point (never less than [`OFFSET_RELATIVE`] itself).
///
/// Intersection points are on the surface to about `1e-12` relative (patch Newton tolerance,
/// sphere and triangle rounding); an offset a thousand times larger puts the new origin safely
/// on the side the ray leaves towards, so it cannot re-hit the same spot at `t ≈ 0`.
pub const OFFSET_RELATIVE: f64 = 1e-9;

/// A ray leaving the surface point `point` with geometric normal `normal` in direction `dir`:
/// the origin is pushed off the surface along the normal, on the side `dir` goes to.
pub fn spawn_ray(point: DVec3, normal: DVec3, dir: DVec3) -> Ray {
    let scale = point.abs().max_element().max(1.0);
    let offset = normal * (OFFSET_RELATIVE * scale);
    let origin = if dir.dot(normal) >= 0.0 {
        point + offset
    } else {
        point - offset
    };
    Ray::new(origin, dir)
}
