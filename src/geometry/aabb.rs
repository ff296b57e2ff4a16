//! Axis-aligned bounding boxes and the slab test.
//!
//! The slab test follows pbrt-v4 (`Bounds3::IntersectP`): the far distance is enlarged by
//! `1 + 2γ₃` so rounding never loses a box that the ray grazes. Zero direction components get
//! a huge finite reciprocal ([`safe_inverse`]) so the test is branch-free and NaN-free.

use glam::DVec3;

/// An axis-aligned box; `min > max` on any axis means empty.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Aabb {
    /// Lower corner.
    pub min: DVec3,
    /// Upper corner.
    pub max: DVec3,
}

/// `γ₃ = 3ε / (1 - 3ε)`, the rounding bound pbrt uses to pad the slab test's far distance.
const GAMMA3: f64 = 3.0 * f64::EPSILON * 0.5 / (1.0 - 3.0 * f64::EPSILON * 0.5);

/// The factor the slab test pads its far distance by, `1 + 2γ₃` (pbrt-v4's `Bounds3::IntersectP`).
pub(crate) const FAR_SCALE: f64 = 1.0 + 2.0 * GAMMA3;

impl Default for Aabb {
    fn default() -> Self {
        Self::EMPTY
    }
}

impl Aabb {
    /// The empty box (the identity of [`Aabb::union`]).
    pub const EMPTY: Aabb = Aabb {
        min: DVec3::splat(f64::INFINITY),
        max: DVec3::splat(f64::NEG_INFINITY),
    };

    /// The box with corners `min` and `max`.
    pub fn new(min: DVec3, max: DVec3) -> Self {
        Self { min, max }
    }

    /// The smallest box holding all `points`.
    pub fn from_points(points: impl IntoIterator<Item = DVec3>) -> Self {
        points.into_iter().fold(Self::EMPTY, |b, p| b.grow(p))
    }

    /// This box grown to hold `p`.
    #[inline]
    pub fn grow(self, p: DVec3) -> Self {
        Self {
            min: self.min.min(p),
            max: self.max.max(p),
        }
    }

    /// The smallest box holding both.
    #[inline]
    pub fn union(self, other: Aabb) -> Self {
        Self {
            min: self.min.min(other.min),
            max: self.max.max(other.max),
        }
    }

    /// Whether the box holds nothing.
    pub fn is_empty(&self) -> bool {
        self.min.cmpgt(self.max).any()
    }

    /// This box enlarged by `margin` on every side.
    pub fn padded(self, margin: f64) -> Self {
        Self {
            min: self.min - DVec3::splat(margin),
            max: self.max + DVec3::splat(margin),
        }
    }

    /// `max - min` (negative for the empty box).
    pub fn diagonal(&self) -> DVec3 {
        self.max - self.min
    }

    /// The centre.
    pub fn centroid(&self) -> DVec3 {
        0.5 * (self.min + self.max)
    }

    /// Surface area (0 for an empty box).
    pub fn surface_area(&self) -> f64 {
        if self.is_empty() {
            return 0.0;
        }
        let d = self.diagonal();
        2.0 * (d.x * d.y + d.y * d.z + d.z * d.x)
    }

    /// Index of the longest axis.
    pub fn longest_axis(&self) -> usize {
        let d = self.diagonal();
        if d.x >= d.y && d.x >= d.z {
            0
        } else if d.y >= d.z {
            1
        } else {
            2
        }
    }

    /// Whether `p` is inside or on the boundary.
    pub fn contains(&self, p: DVec3) -> bool {
        p.cmpge(self.min).all() && p.cmple(self.max).all()
    }

    /// The parametric interval `[t0, t1]` in which the ray `origin + t·dir` is inside the box,
    /// clipped to `[0, t_max]`, or `None`. `inv_dir` is [`safe_inverse`]`(dir)`.
    #[inline]
    pub fn hit_interval(&self, origin: DVec3, inv_dir: DVec3, t_max: f64) -> Option<(f64, f64)> {
        // Plain comparisons rather than `f64::min`/`max`: no NaN reaches here (see
        // `safe_inverse`), and these compile to single min/max instructions.
        let min = |a: f64, b: f64| if a < b { a } else { b };
        let max = |a: f64, b: f64| if a > b { a } else { b };
        let a = (self.min - origin) * inv_dir;
        let b = (self.max - origin) * inv_dir;
        let near = DVec3::new(min(a.x, b.x), min(a.y, b.y), min(a.z, b.z));
        let far = DVec3::new(max(a.x, b.x), max(a.y, b.y), max(a.z, b.z)) * FAR_SCALE;
        let t0 = max(max(max(near.x, near.y), near.z), 0.0);
        let t1 = min(min(min(far.x, far.y), far.z), t_max);
        (t0 <= t1).then_some((t0, t1))
    }
}

/// `1 / dir` component-wise, with zero and subnormal components (whose reciprocal would be
/// infinite) replaced by `±f64::MAX` (sign kept): `(bound - origin) · inv` is then never
/// `0 · ∞ = NaN` for a ray lying in a slab's plane, and overflow to `±∞` still orders
/// correctly, so [`Aabb::hit_interval`] needs no special cases.
#[inline]
pub fn safe_inverse(dir: DVec3) -> DVec3 {
    let inv = |d: f64| {
        if d.abs() < f64::MIN_POSITIVE {
            f64::MAX.copysign(d)
        } else {
            1.0 / d
        }
    };
    DVec3::new(inv(dir.x), inv(dir.y), inv(dir.z))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn slab_handles_axis_parallel_rays() {
        let b = Aabb::new(DVec3::ZERO, DVec3::ONE);
        let inv = safe_inverse;
        // Along +x through the box, y and z components zero.
        let hit = b.hit_interval(DVec3::new(-1.0, 0.5, 0.5), inv(DVec3::X), f64::INFINITY);
        assert_eq!(hit, Some((1.0, 2.0 * (1.0 + 2.0 * GAMMA3))));
        // In the plane of a face: still counts (boundary), no NaN poisoning.
        let on_face = b.hit_interval(DVec3::new(-1.0, 0.0, 0.0), inv(DVec3::X), f64::INFINITY);
        assert!(on_face.is_some());
        // Parallel and outside.
        assert!(b
            .hit_interval(DVec3::new(-1.0, 2.0, 0.5), inv(DVec3::X), f64::INFINITY)
            .is_none());
        // Behind the origin.
        assert!(b
            .hit_interval(DVec3::new(2.0, 0.5, 0.5), inv(DVec3::X), f64::INFINITY)
            .is_none());
        // A subnormal component in the plane of a face: finite reciprocal, no NaN, a hit.
        let tiny = DVec3::new(1.0, 1e-310, 0.0);
        assert!(safe_inverse(tiny).is_finite());
        let grazing = b.hit_interval(DVec3::new(-1.0, 0.0, 0.5), inv(tiny), f64::INFINITY);
        assert!(grazing.is_some_and(|(t0, t1)| t0 == 1.0 && t1 >= 2.0));
    }

    #[test]
    fn empty_box_and_union() {
        assert!(Aabb::EMPTY.is_empty());
        let b = Aabb::EMPTY.grow(DVec3::ONE).grow(-DVec3::ONE);
        assert_eq!(b.diagonal(), DVec3::splat(2.0));
        assert_eq!(b.surface_area(), 24.0);
        assert_eq!(Aabb::EMPTY.union(b), b);
    }
}
