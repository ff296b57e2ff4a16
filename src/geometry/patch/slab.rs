//! A slab that holds a flat leaf: the two parallel planes, across the normal of the leaf's corner
//! diagonals, between which all its control points lie, and so (by the convex hull property)
//! the whole sub-patch. Together with the leaf's box it bounds the leaf far more tightly than
//! the box alone wherever the leaf lies oblique to the axes: a ray that passes through the box
//! above or below the leaf is ruled out before the leaf is projected into ray space. Benthin,
//! Wald and Slusallek (2004, "Interactive ray tracing of free-form surfaces") bound their flat
//! sub-patches the same way.
//!
//! The test takes no division: the ray's height above the slab's planes is linear in the ray
//! distance, so the ray's piece inside the box misses the slab exactly when its two ends lie on
//! the same side of it. Every rounding is bounded and added to the slab, so no leaf a ray meets
//! is ever ruled out.

use glam::DVec3;

use crate::geometry::bezier::BezierPatch;

/// The region between two parallel planes, `lo ≤ normal·x ≤ hi`, that holds a patch.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Slab {
    /// Unit normal of the planes (zero when the slab rules nothing out).
    normal: DVec3,
    /// The lower plane's offset, padded against rounding.
    lo: f64,
    /// The upper plane's offset, padded against rounding.
    hi: f64,
}

/// Rounding of a computed dot product `n·x` with `|n_i| ≤ 1`, relative to `|x|₁` (`γ₃` of
/// Higham's bound, rounded up generously).
const DOT_ROUNDING: f64 = 4.0 * f64::EPSILON;

impl Slab {
    /// The slab that rules nothing out.
    pub const ALL: Slab = Slab {
        normal: DVec3::ZERO,
        lo: f64::NEG_INFINITY,
        hi: f64::INFINITY,
    };

    /// The thinnest slab across the normal of `patch`'s corner diagonals that holds all its
    /// control points; [`Slab::ALL`] where the diagonals are parallel or not finite.
    pub fn of(patch: &BezierPatch) -> Self {
        let p = &patch.points;
        let normal = (p[15] - p[0]).cross(p[12] - p[3]).normalize_or_zero();
        if normal == DVec3::ZERO {
            return Self::ALL;
        }
        let (mut lo, mut hi, mut size) = (f64::INFINITY, f64::NEG_INFINITY, 0.0f64);
        for q in p {
            let h = normal.dot(*q);
            lo = lo.min(h);
            hi = hi.max(h);
            size = size.max(q.abs().element_sum());
        }
        // Each offset was rounded by up to DOT_ROUNDING · |q|₁.
        let pad = DOT_ROUNDING * size;
        if !(lo - pad).is_finite() || !(hi + pad).is_finite() {
            return Self::ALL;
        }
        Self {
            normal,
            lo: lo - pad,
            hi: hi + pad,
        }
    }

    /// Whether the ray `origin + t·dir` (`dir` a unit vector) stays on one side of the slab
    /// for all `t` in `[t0, t1]` (`0 ≤ t0 ≤ t1`): the piece of the ray inside the leaf's box,
    /// whose computed ends may each lie a rounding inside the exact ones.
    #[inline]
    pub fn misses(&self, origin: DVec3, dir: DVec3, t0: f64, t1: f64) -> bool {
        let (height, climb) = (self.normal.dot(origin), self.normal.dot(dir));
        let (h0, h1) = (height + t0 * climb, height + t1 * climb);
        // The heights' rounding: the two dot products', the products and sums', and the ends'
        // own (a relative rounding of t each, times |climb| ≤ 1).
        let slack = 2.0 * DOT_ROUNDING * (origin.abs().element_sum() + 2.0 * t1);
        (h0 > self.hi + slack && h1 > self.hi + slack) || (h0 < self.lo - slack && h1 < self.lo - slack)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_pcg::Pcg64;

    /// A bent, oblique patch: a dome tilted off every axis and moved away from the origin.
    fn tilted_dome(bend: f64) -> BezierPatch {
        let mut pts = [DVec3::ZERO; 16];
        let (a, b) = (DVec3::new(0.8, 0.5, -0.3), DVec3::new(-0.2, 0.6, 0.7));
        let n = a.cross(b).normalize();
        for i in 0..4 {
            for j in 0..4 {
                let (x, y) = (i as f64 / 3.0 - 0.5, j as f64 / 3.0 - 0.5);
                pts[4 * i + j] = DVec3::new(40.0, -7.0, 3.0) + x * a + y * b + bend * (x * x + y * y) * n;
            }
        }
        BezierPatch::new(pts)
    }

    #[test]
    fn no_point_of_the_patch_lies_outside_its_slab() {
        for bend in [0.0, 0.05, 0.4] {
            let patch = tilted_dome(bend);
            let slab = Slab::of(&patch);
            assert_ne!(slab, Slab::ALL);
            for k in 0..=40 {
                for l in 0..=40 {
                    let x = patch.eval(k as f64 / 40.0, l as f64 / 40.0);
                    let h = slab.normal.dot(x);
                    assert!(
                        h >= slab.lo && h <= slab.hi,
                        "bend {bend}: {h} outside [{}, {}]",
                        slab.lo,
                        slab.hi
                    );
                }
            }
        }
    }

    #[test]
    fn rays_through_the_patch_are_never_ruled_out_and_rays_beside_it_are() {
        let mut rng = Pcg64::seed_from_u64(7);
        for bend in [0.0, 0.05, 0.4] {
            let patch = tilted_dome(bend);
            let slab = Slab::of(&patch);
            let (mut ruled_out, mut beside) = (0, 0);
            for _ in 0..20_000 {
                // A ray through a point of the patch, from anywhere within 30 units of it; its
                // piece around the point, as a box's interval would give it.
                let x = patch.eval(rng.random(), rng.random());
                let dir = DVec3::new(rng.random(), rng.random(), rng.random()) * 2.0 - 1.0;
                let Some(dir) = dir.try_normalize() else { continue };
                let t = rng.random_range(0.0..30.0);
                let origin = x - t * dir;
                let (t0, t1) = (
                    (t - rng.random_range(0.0..1.0f64)).max(0.0),
                    t + rng.random_range(0.0..1.0),
                );
                assert!(!slab.misses(origin, dir, t0, t1), "a ray through {x} ruled out");
                // The same ray's piece well before the point, where it is off the slab unless it
                // runs nearly along it.
                let away = 1.0 + 2.0 * (slab.hi - slab.lo);
                if slab.normal.dot(dir).abs() > 0.5 && t > away + 0.1 {
                    beside += 1;
                    ruled_out += usize::from(slab.misses(origin, dir, 0.0, t - away));
                }
            }
            assert!(beside > 1000, "bend {bend}: {beside} pieces beside");
            assert_eq!(
                ruled_out, beside,
                "bend {bend}: pieces beside the slab are ruled out"
            );
        }
    }

    #[test]
    fn a_degenerate_or_infinite_patch_rules_nothing_out() {
        let point = BezierPatch::new([DVec3::ONE; 16]);
        assert_eq!(Slab::of(&point), Slab::ALL);
        let mut huge = tilted_dome(0.1);
        huge.points[5] = DVec3::splat(f64::MAX);
        assert_eq!(Slab::of(&huge), Slab::ALL);
        assert!(!Slab::ALL.misses(DVec3::ZERO, DVec3::X, 0.0, 1.0));
    }
}
