//! What the root finder ([`super`]) solves: a sub-patch in ray space, polynomial or rational.
//!
//! A polynomial patch's ray-space control points are the patch itself, moved and turned
//! ([`super::RayFrame`]). A rational patch `P = N / W` meets the ray where the first two
//! coordinates of `P` vanish, which (with `W > 0`) is where those of the numerator `N` vanish:
//! `N` is a polynomial Bézier patch, so Newton, the hull test, the `beside` test and the
//! Jacobian's sign test work on it unchanged, as in Martin et al. 2000 ("Practical ray tracing
//! of trimmed NURBS surfaces"), who solve rational surfaces the same way. What differs is read at
//! the root — the distance `N_z / W` and the tangents by the quotient rule — and the depth
//! range, which comes from the projected points `N_ij / w_ij` (the surface lies in their hull).

use glam::DVec3;

use super::root::Root;
use crate::geometry::bezier::BezierPatch;
use crate::geometry::rational::{weight_with_derivs, RationalPatch};

/// Bounds of the ray-space control points: `(lo, hi)`.
#[inline]
fn hull(p: &BezierPatch) -> (DVec3, DVec3) {
    let b = p.bounds();
    (b.min, b.max)
}

/// A bound on the rounding of the ray-space sub-patch `p`'s coordinates (the projection's and
/// the splits'), from its two opposite corners' distance from the ray's origin.
#[inline]
fn rounding(p: &BezierPatch) -> f64 {
    let far = p.points[0]
        .abs()
        .max_element()
        .max(p.points[15].abs().max_element());
    16.0 * f64::EPSILON * far
}

/// A ray-space sub-patch the root finder can solve.
pub(super) trait RaySpace: Sized {
    /// The polynomial patch whose first two coordinates vanish where the ray meets the
    /// surface (the patch itself, or a rational patch's numerator).
    fn roots(&self) -> &BezierPatch;
    /// Bounds `(lo, hi)` of the surface's ray-space coordinates: the first two may be those
    /// of [`RaySpace::roots`] (only their sign matters), the third is the distance range.
    fn hull(&self) -> (DVec3, DVec3);
    /// The four quarters, in [`BezierPatch::split_quad`]'s order.
    fn split_quad(&self) -> [Self; 4];
    /// A Newton root of [`RaySpace::roots`] completed: the surface's distance and tangents.
    fn complete(&self, root: Root) -> Root;
    /// The distance along the ray of corner `k` (0, 3, 12 or 15).
    fn corner_distance(&self, k: usize) -> f64;
    /// A bound on the rounding of [`RaySpace::roots`]' coordinates.
    fn rounding(&self) -> f64;
    /// What a distance from the ray becomes in [`RaySpace::roots`]' coordinates, at least: 1
    /// for a polynomial patch, the smallest weight for a rational one.
    fn least_scale(&self) -> f64;
}

impl RaySpace for BezierPatch {
    #[inline]
    fn roots(&self) -> &BezierPatch {
        self
    }

    #[inline]
    fn hull(&self) -> (DVec3, DVec3) {
        hull(self)
    }

    #[inline]
    fn split_quad(&self) -> [Self; 4] {
        BezierPatch::split_quad(self)
    }

    #[inline]
    fn complete(&self, root: Root) -> Root {
        root
    }

    #[inline]
    fn corner_distance(&self, k: usize) -> f64 {
        self.points[k].z
    }

    #[inline]
    fn rounding(&self) -> f64 {
        rounding(self)
    }

    #[inline]
    fn least_scale(&self) -> f64 {
        1.0
    }
}

/// A rational sub-patch in ray space ([`RationalPatch::new`] of the ray-space projected points).
impl RaySpace for RationalPatch {
    fn roots(&self) -> &BezierPatch {
        &self.numerator
    }

    fn hull(&self) -> (DVec3, DVec3) {
        let (mut lo, mut hi) = (DVec3::INFINITY, DVec3::NEG_INFINITY);
        for (n, w) in self.numerator.points.iter().zip(self.weights) {
            let q = DVec3::new(n.x, n.y, n.z / w);
            lo = lo.min(q);
            hi = hi.max(q);
        }
        (lo, hi)
    }

    fn split_quad(&self) -> [Self; 4] {
        RationalPatch::split_quad(self)
    }

    fn complete(&self, root: Root) -> Root {
        let [w, ws, wt] = weight_with_derivs(&self.weights, root.s, root.t);
        // At the root N = (≈0, ≈0, N_z); P = N / W and P' = (N' − P W') / W.
        let [nx, ny] = self.numerator.eval_xy_with_derivs(root.s, root.t)[0].to_array();
        let p = DVec3::new(nx, ny, root.dist) / w;
        Root {
            dist: p.z,
            ds: (root.ds - p * ws) / w,
            dt: (root.dt - p * wt) / w,
            ..root
        }
    }

    fn corner_distance(&self, k: usize) -> f64 {
        self.numerator.points[k].z / self.weights[k]
    }

    fn rounding(&self) -> f64 {
        rounding(&self.numerator)
    }

    fn least_scale(&self) -> f64 {
        self.weights.iter().copied().fold(f64::INFINITY, f64::min)
    }
}
