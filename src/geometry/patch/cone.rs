//! A cone that holds every normal of a Bézier patch (the normal cone of Sederberg & Meyers 1988,
//! "Loop detection in surface patch intersections"), found once when a leaf is prepared, so
//! that a ray can tell with one dot product, before projecting the leaf, that the normal keeps
//! one side towards it over the whole leaf.
//!
//! The normal `∂P/∂u × ∂P/∂v` is a sum, with non-negative Bernstein weights, of the cross
//! products `a × b` of a control point `a` of the `u`-derivative patch (differences of
//! neighbouring points along `u`, 12 of them) and one `b` of the `v`-derivative patch (12 along
//! `v`). A circular cone narrower than a half-space that holds all 144 of those products holds
//! every normal, since such a cone is convex.

use glam::DVec3;

use crate::geometry::bezier::BezierPatch;

/// Every normal of a patch lies within the cone's spread of its axis, or the cone proves
/// nothing (a product near zero, as at a collapsed edge, or products 90° or more apart).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NormalCone {
    /// Unit axis (zero when the cone proves nothing).
    axis: DVec3,
    /// The sine of the cone's half-angle, padded against rounding; infinite when it proves
    /// nothing.
    sin_spread: f64,
}

/// Added to the cone's sine: the products are rounded, and so is the dot product of the test.
const ROUNDING: f64 = 1e-9;

impl NormalCone {
    /// The cone that proves nothing.
    pub const NONE: NormalCone = NormalCone {
        axis: DVec3::ZERO,
        sin_spread: f64::INFINITY,
    };

    /// The normal cone of `patch`.
    pub fn of(patch: &BezierPatch) -> Self {
        let p = |i: usize, j: usize| patch.points[4 * i + j];
        let mut along_u = [DVec3::ZERO; 12];
        let mut along_v = [DVec3::ZERO; 12];
        for i in 0..3 {
            for j in 0..4 {
                along_u[4 * i + j] = p(i + 1, j) - p(i, j);
                along_v[3 * j + i] = p(j, i + 1) - p(j, i);
            }
        }
        // A product's length is of the order of the longest difference squared; one much
        // shorter may be rounding noise of a vanishing normal.
        let longest2 = along_u
            .iter()
            .chain(&along_v)
            .map(|d| d.length_squared())
            .fold(0.0, f64::max);
        let tiny = 1e-12 * longest2;
        // The products' directions.
        let mut directions = [DVec3::ZERO; 144];
        let mut sum = DVec3::ZERO;
        for (k, a) in along_u.iter().enumerate() {
            for (l, b) in along_v.iter().enumerate() {
                let c = a.cross(*b);
                let length = c.length();
                if length.is_nan() || length <= tiny {
                    // A product that vanishes (or is not finite): the normal may vanish too.
                    return Self::NONE;
                }
                directions[12 * k + l] = c / length;
                sum += directions[12 * k + l];
            }
        }
        let axis = sum.normalize_or_zero();
        let min_cos = directions.iter().map(|c| axis.dot(*c)).fold(1.0, f64::min);
        if min_cos.is_nan() || min_cos <= 0.0 {
            return Self::NONE;
        }
        Self {
            axis,
            sin_spread: (1.0 - min_cos * min_cos).max(0.0).sqrt() + ROUNDING,
        }
    }

    /// The sign (±1) that `n·dir` keeps for every normal `n` of the patch, when the cone proves
    /// it; `dir` is a unit vector.
    #[inline]
    pub fn sign_along(&self, dir: DVec3) -> Option<f64> {
        let c = self.axis.dot(dir);
        if c > self.sin_spread {
            Some(1.0)
        } else if c < -self.sin_spread {
            Some(-1.0)
        } else {
            None
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A dome over the unit square, curving by `bend`.
    fn dome(bend: f64) -> BezierPatch {
        let mut pts = [DVec3::ZERO; 16];
        for i in 0..4 {
            for j in 0..4 {
                let (x, y) = (i as f64 / 3.0 - 0.5, j as f64 / 3.0 - 0.5);
                pts[4 * i + j] = DVec3::new(x, y, -bend * (x * x + y * y));
            }
        }
        BezierPatch::new(pts)
    }

    #[test]
    fn every_normal_keeps_the_sign_the_cone_proves() {
        for bend in [0.0, 0.3, 1.0, 3.0] {
            let patch = dome(bend);
            let cone = NormalCone::of(&patch);
            let mut proved = 0;
            for k in 0..400 {
                let (theta, phi) = (k as f64 * 0.0157, k as f64 * 2.399);
                let dir = DVec3::new(theta.sin() * phi.cos(), theta.sin() * phi.sin(), theta.cos());
                let Some(sign) = cone.sign_along(dir) else {
                    continue;
                };
                proved += 1;
                for i in 0..=20 {
                    for j in 0..=20 {
                        let n = patch.normal(i as f64 / 20.0, j as f64 / 20.0).expect("normal");
                        assert!(n.dot(dir) * sign > 0.0, "bend {bend}, direction {dir}");
                    }
                }
            }
            // Directions near the axis are proved for all but the strongest bend.
            assert!(
                bend >= 3.0 || proved > 50,
                "bend {bend}: {proved} directions proved"
            );
        }
    }

    #[test]
    fn a_flat_patch_is_proved_for_all_but_grazing_directions() {
        let cone = NormalCone::of(&dome(0.0));
        assert_eq!(cone.sign_along(DVec3::Z), Some(1.0));
        assert_eq!(cone.sign_along(-DVec3::Z), Some(-1.0));
        let grazing = DVec3::new(1.0, 0.0, 1e-12).normalize();
        assert_eq!(cone.sign_along(grazing), None);
    }

    #[test]
    fn a_collapsed_edge_proves_nothing() {
        let mut patch = dome(0.5);
        for j in 0..4 {
            patch.points[j] = patch.points[0];
        }
        assert_eq!(NormalCone::of(&patch), NormalCone::NONE);
    }
}
