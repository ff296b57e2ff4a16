//! Bicubic Bézier patch maths in `f64`: evaluation, partial derivatives, the unit normal (with a
//! limit at collapsed edges), De Casteljau splitting and control-hull bounds.
//!
//! A patch is 16 control points `P[4*i + j]`; `i` runs along `u`, `j` along `v`:
//!
//! `P(u,v) = Σ_i Σ_j B_i(u) B_j(v) P_ij`, with the cubic Bernstein basis `B_k`.
//!
//! The seed report (§2.1–2.3) evaluates a patch as a curve of curves and splits it with the
//! De Casteljau construction `L1 = (P0+P1)/2, L2 = (P0+2P1+P2)/4, L3 = (P0+3P1+3P2+P3)/8`;
//! this module generalises the split to any parameter `t`, which is what
//! [`BezierPatch::sub_patch`] needs to cut out an arbitrary `(u,v)` window exactly.
//! Intersection with rays lives apart, in [`crate::geometry::patch`].

use std::ops::{Add, AddAssign, Mul};

use glam::{DAffine3, DVec2, DVec3};

use super::aabb::Aabb;

/// A bicubic Bézier patch: 4×4 control points, row `i` along `u`, column `j` along `v`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BezierPatch {
    /// Control points, `points[4 * i + j]` weighted by `B_i(u) B_j(v)`.
    pub points: [DVec3; 16],
}

/// The four cubic Bernstein polynomials at `t`.
#[inline]
pub fn bernstein(t: f64) -> [f64; 4] {
    let s = 1.0 - t;
    [s * s * s, 3.0 * t * s * s, 3.0 * t * t * s, t * t * t]
}

/// Derivatives of the four cubic Bernstein polynomials at `t`.
#[inline]
pub fn bernstein_deriv(t: f64) -> [f64; 4] {
    let s = 1.0 - t;
    [
        -3.0 * s * s,
        3.0 * s * s - 6.0 * t * s,
        6.0 * t * s - 3.0 * t * t,
        3.0 * t * t,
    ]
}

/// Splits the cubic `[p0, p1, p2, p3]` at `t` with De Casteljau's construction, returning the
/// control points of the pieces over `[0, t]` and `[t, 1]`.
#[inline]
pub fn split_cubic<T>(p: [T; 4], t: f64) -> ([T; 4], [T; 4])
where
    T: Copy + std::ops::Add<Output = T> + std::ops::Sub<Output = T> + std::ops::Mul<f64, Output = T>,
{
    let lerp = |a: T, b: T| a + (b - a) * t;
    let p01 = lerp(p[0], p[1]);
    let p12 = lerp(p[1], p[2]);
    let p23 = lerp(p[2], p[3]);
    let p012 = lerp(p01, p12);
    let p123 = lerp(p12, p23);
    let mid = lerp(p012, p123);
    ([p[0], p01, p012, mid], [mid, p123, p23, p[3]])
}

/// What a grid of 4×4 Bézier coefficients may hold: points, or a rational patch's weights.
pub trait Coefficient:
    Copy + Add<Output = Self> + std::ops::Sub<Output = Self> + Mul<f64, Output = Self>
{
}

impl<T: Copy + Add<Output = T> + std::ops::Sub<Output = T> + Mul<f64, Output = T>> Coefficient for T {}

/// The 4×4 coefficients `c` (`c[4 * i + j]`, `i` along `u`) split along `u` at `t` with De
/// Casteljau's construction: those over `u ∈ [0,t]` and `u ∈ [t,1]`.
#[inline]
pub fn split_grid_u<T: Coefficient>(c: &[T; 16], t: f64) -> ([T; 16], [T; 16]) {
    let (mut lo, mut hi) = (*c, *c);
    for j in 0..4 {
        let (a, b) = split_cubic([c[j], c[4 + j], c[8 + j], c[12 + j]], t);
        for i in 0..4 {
            lo[4 * i + j] = a[i];
            hi[4 * i + j] = b[i];
        }
    }
    (lo, hi)
}

/// [`split_grid_u`] along `v`.
#[inline]
pub fn split_grid_v<T: Coefficient>(c: &[T; 16], t: f64) -> ([T; 16], [T; 16]) {
    let (mut lo, mut hi) = (*c, *c);
    for i in 0..4 {
        let (a, b) = split_cubic([c[4 * i], c[4 * i + 1], c[4 * i + 2], c[4 * i + 3]], t);
        lo[4 * i..4 * i + 4].copy_from_slice(&a);
        hi[4 * i..4 * i + 4].copy_from_slice(&b);
    }
    (lo, hi)
}

/// The coefficients split in four at `(0.5, 0.5)`: `[u-low v-low, u-high v-low, u-low v-high,
/// u-high v-high]`.
#[inline]
pub fn split_grid_quad<T: Coefficient>(c: &[T; 16]) -> [[T; 16]; 4] {
    let (ul, uh) = split_grid_u(c, 0.5);
    let (a, cc) = split_grid_v(&ul, 0.5);
    let (b, d) = split_grid_v(&uh, 0.5);
    [a, b, cc, d]
}

/// The coefficients restricted to `[u0,u1] × [v0,v1]` and reparameterised over `[0,1]²`.
pub fn sub_grid<T: Coefficient>(c: &[T; 16], (u0, u1): (f64, f64), (v0, v1): (f64, f64)) -> [T; 16] {
    type Split<T> = fn(&[T; 16], f64) -> ([T; 16], [T; 16]);
    let cut = |c: [T; 16], lo: f64, hi: f64, split: Split<T>| {
        // Cut off above `hi`, then below `lo` measured in the remaining piece.
        let below_hi = if hi < 1.0 { split(&c, hi).0 } else { c };
        if lo > 0.0 && hi > 0.0 {
            split(&below_hi, lo / hi).1
        } else {
            below_hi
        }
    };
    let c = cut(*c, u0, u1, split_grid_u);
    cut(c, v0, v1, split_grid_v)
}

/// The unit normal `∂P/∂u × ∂P/∂v` of a surface whose point and derivatives `eval` gives, at
/// `(u,v)`, or where it vanishes (a collapsed edge) the limit normal from points approaching
/// `(u,v)` from the inside; `scale` is the surface's size, below `1e-12 · scale²` a cross
/// product is rounding noise. `None` for a surface degenerate everywhere near `(u,v)`.
pub fn limit_normal(u: f64, v: f64, scale: f64, eval: impl Fn(f64, f64) -> SurfacePoint) -> Option<DVec3> {
    if scale == 0.0 || !scale.is_finite() {
        return None;
    }
    let tiny = 1e-12 * scale * scale;
    for step in [0.0, 1e-7, 1e-5, 1e-3, 1e-2] {
        let sp = eval(u + (0.5 - u) * step, v + (0.5 - v) * step);
        let n = sp.dp_du.cross(sp.dp_dv);
        if n.length() > tiny {
            return Some(n.normalize());
        }
    }
    None
}

/// Point and first partial derivatives of a patch.
#[derive(Clone, Copy, Debug)]
pub struct SurfacePoint {
    /// `P(u,v)`.
    pub position: DVec3,
    /// `∂P/∂u`.
    pub dp_du: DVec3,
    /// `∂P/∂v`.
    pub dp_dv: DVec3,
}

impl BezierPatch {
    /// A patch from its 16 control points (`points[4*i + j]`, `i` along `u`).
    pub fn new(points: [DVec3; 16]) -> Self {
        Self { points }
    }

    /// The control point `P_ij`.
    #[inline]
    pub fn point(&self, i: usize, j: usize) -> DVec3 {
        self.points[4 * i + j]
    }

    /// `P(u,v)`.
    pub fn eval(&self, u: f64, v: f64) -> DVec3 {
        let bu = bernstein(u);
        let bv = bernstein(v);
        let mut p = DVec3::ZERO;
        for (row, weight) in self.points.chunks_exact(4).zip(bu) {
            p += weight * (bv[0] * row[0] + bv[1] * row[1] + bv[2] * row[2] + bv[3] * row[3]);
        }
        p
    }

    /// `P(u,v)` with `∂P/∂u` and `∂P/∂v`.
    #[inline]
    pub fn eval_with_derivs(&self, u: f64, v: f64) -> SurfacePoint {
        let [position, dp_du, dp_dv] = self.eval_part_with_derivs(u, v, |p| p);
        SurfacePoint {
            position,
            dp_du,
            dp_dv,
        }
    }

    /// The first two coordinates of `P(u,v)`, `∂P/∂u` and `∂P/∂v`: what a root finder in ray
    /// space needs (the third coordinate is the distance along the ray, wanted only at the
    /// root). The same arithmetic as [`BezierPatch::eval_with_derivs`] on those coordinates,
    /// so the same bits.
    #[inline]
    pub fn eval_xy_with_derivs(&self, u: f64, v: f64) -> [DVec2; 3] {
        self.eval_part_with_derivs(u, v, DVec3::truncate)
    }

    /// The third coordinate of `P(u,v)`, `∂P/∂u` and `∂P/∂v`: what a root finder in ray space
    /// adds at the root to [`BezierPatch::eval_xy_with_derivs`]'s two (the distance along the
    /// ray and the normal's missing components). The same arithmetic as
    /// [`BezierPatch::eval_with_derivs`] on that coordinate, so the same bits.
    #[inline]
    pub fn eval_z_with_derivs(&self, u: f64, v: f64) -> [f64; 3] {
        self.eval_part_with_derivs(u, v, |p| p.z)
    }

    /// `part` of `P(u,v)`, `∂P/∂u` and `∂P/∂v`, where `part` picks coordinates of a point (a
    /// linear map, so it commutes with the sums): the one body of the three evaluations
    /// above, whose arithmetic per coordinate is therefore the same.
    #[inline(always)]
    fn eval_part_with_derivs<T>(&self, u: f64, v: f64, part: impl Fn(DVec3) -> T) -> [T; 3]
    where
        T: Copy + Default + Add<Output = T> + AddAssign,
        f64: Mul<T, Output = T>,
    {
        let bu = bernstein(u);
        let bv = bernstein(v);
        let du = bernstein_deriv(u);
        let dv = bernstein_deriv(v);
        let (mut position, mut dp_du, mut dp_dv) = (T::default(), T::default(), T::default());
        for i in 0..4 {
            let r = |j: usize| part(self.points[4 * i + j]);
            let row = bv[0] * r(0) + bv[1] * r(1) + bv[2] * r(2) + bv[3] * r(3);
            let row_dv = dv[0] * r(0) + dv[1] * r(1) + dv[2] * r(2) + dv[3] * r(3);
            position += bu[i] * row;
            dp_du += du[i] * row;
            dp_dv += bu[i] * row_dv;
        }
        [position, dp_du, dp_dv]
    }

    /// The unit normal `∂P/∂u × ∂P/∂v` at `(u,v)`.
    ///
    /// Where that cross product vanishes (a collapsed edge such as the poles of the Utah
    /// teapot's lid and bottom, where a whole row of control points coincides) the limit normal
    /// is taken from points approaching `(u,v)` from the inside of the patch. Returns `None`
    /// only for a patch that is degenerate everywhere near `(u,v)` (all points coincide).
    pub fn normal(&self, u: f64, v: f64) -> Option<DVec3> {
        self.normal_at_scale(u, v, self.bounds().diagonal().length())
    }

    /// [`BezierPatch::normal`] for a patch whose bounds' diagonal, `scale`, the caller knows
    /// (a prepared patch: finding the bounds again is a fifth of the work).
    pub fn normal_at_scale(&self, u: f64, v: f64, scale: f64) -> Option<DVec3> {
        limit_normal(u, v, scale, |u, v| self.eval_with_derivs(u, v))
    }

    /// Splits along `u` at `t`: the patches over `u ∈ [0,t]` and `u ∈ [t,1]`.
    #[inline]
    pub fn split_u(&self, t: f64) -> (Self, Self) {
        let (lo, hi) = split_grid_u(&self.points, t);
        (Self::new(lo), Self::new(hi))
    }

    /// Splits along `v` at `t`: the patches over `v ∈ [0,t]` and `v ∈ [t,1]`.
    #[inline]
    pub fn split_v(&self, t: f64) -> (Self, Self) {
        let (lo, hi) = split_grid_v(&self.points, t);
        (Self::new(lo), Self::new(hi))
    }

    /// Splits into four at `(0.5, 0.5)`: `[u-low v-low, u-high v-low, u-low v-high, u-high v-high]`.
    #[inline]
    pub fn split_quad(&self) -> [Self; 4] {
        split_grid_quad(&self.points).map(Self::new)
    }

    /// The patch restricted to `[u0,u1] × [v0,v1]`, reparameterised over `[0,1]²`: its point at
    /// `(s,t)` is this patch's point at `(u0 + s(u1-u0), v0 + t(v1-v0))`.
    pub fn sub_patch(&self, u0: f64, u1: f64, v0: f64, v1: f64) -> Self {
        Self::new(sub_grid(&self.points, (u0, u1), (v0, v1)))
    }

    /// Bounds of the control hull, which contain the patch (convex hull property).
    #[inline]
    pub fn bounds(&self) -> Aabb {
        // From the first point on (not from the empty box): the ray-space hull test of every
        // leaf a ray reaches runs through here.
        let (mut min, mut max) = (self.points[0], self.points[0]);
        for q in &self.points[1..] {
            min = min.min(*q);
            max = max.max(*q);
        }
        Aabb { min, max }
    }

    /// The patch with every control point transformed (Bézier patches are affine invariant).
    pub fn transformed(&self, transform: &DAffine3) -> Self {
        Self::new(self.points.map(|p| transform.transform_point3(p)))
    }

    /// Largest distance of a control point from the bilinear patch through the four corners,
    /// sampled at the control points' own parameters `(i/3, j/3)`: zero for a bilinear patch,
    /// used as the flatness measure for adaptive subdivision.
    pub fn bilinear_deviation(&self) -> f64 {
        let c00 = self.point(0, 0);
        let c30 = self.point(3, 0);
        let c03 = self.point(0, 3);
        let c33 = self.point(3, 3);
        let mut worst: f64 = 0.0;
        for i in 0..4 {
            let s = i as f64 / 3.0;
            for j in 0..4 {
                let t = j as f64 / 3.0;
                let bilinear = (1.0 - s) * ((1.0 - t) * c00 + t * c03) + s * ((1.0 - t) * c30 + t * c33);
                worst = worst.max((self.point(i, j) - bilinear).length());
            }
        }
        worst
    }

    /// Whether the 4 control points of the edge `v = 0` coincide (a pole), and likewise for the
    /// other edges in the order `[v=0, v=1, u=0, u=1]`.
    pub fn collapsed_edges(&self) -> [bool; 4] {
        let same = |a: [DVec3; 4]| a.iter().all(|p| *p == a[0]);
        let edge = |k: usize| -> [DVec3; 4] {
            match k {
                0 => [
                    self.point(0, 0),
                    self.point(1, 0),
                    self.point(2, 0),
                    self.point(3, 0),
                ],
                1 => [
                    self.point(0, 3),
                    self.point(1, 3),
                    self.point(2, 3),
                    self.point(3, 3),
                ],
                2 => [
                    self.point(0, 0),
                    self.point(0, 1),
                    self.point(0, 2),
                    self.point(0, 3),
                ],
                _ => [
                    self.point(3, 0),
                    self.point(3, 1),
                    self.point(3, 2),
                    self.point(3, 3),
                ],
            }
        };
        [same(edge(0)), same(edge(1)), same(edge(2)), same(edge(3))]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn wavy() -> BezierPatch {
        let mut pts = [DVec3::ZERO; 16];
        for i in 0..4 {
            for j in 0..4 {
                let z = ((i * 7 + j * 3) % 5) as f64 * 0.3 - 0.6;
                pts[4 * i + j] = DVec3::new(i as f64, j as f64 + 0.1 * i as f64, z);
            }
        }
        BezierPatch::new(pts)
    }

    #[test]
    fn corners_interpolate_control_points() {
        let p = wavy();
        assert_eq!(p.eval(0.0, 0.0), p.point(0, 0));
        assert_eq!(p.eval(1.0, 0.0), p.point(3, 0));
        assert_eq!(p.eval(0.0, 1.0), p.point(0, 3));
        assert_eq!(p.eval(1.0, 1.0), p.point(3, 3));
    }

    #[test]
    fn derivatives_match_finite_differences() {
        let p = wavy();
        let h = 1e-6;
        for &(u, v) in &[(0.3, 0.7), (0.0, 0.5), (0.91, 0.12)] {
            let sp = p.eval_with_derivs(u, v);
            let fu = (p.eval(u + h, v) - p.eval(u - h, v)) / (2.0 * h);
            let fv = (p.eval(u, v + h) - p.eval(u, v - h)) / (2.0 * h);
            assert!((sp.dp_du - fu).length() < 1e-7, "{:?} vs {:?}", sp.dp_du, fu);
            assert!((sp.dp_dv - fv).length() < 1e-7);
            assert!((sp.position - p.eval(u, v)).length() < 1e-14);
        }
    }

    #[test]
    fn partial_evaluations_give_the_full_evaluations_bits() {
        let p = wavy();
        for &(u, v) in &[
            (0.3, 0.7),
            (0.0, 0.5),
            (0.91, 0.12),
            (-0.2, 1.3),
            (1.0 / 3.0, 0.1),
        ] {
            let full = p.eval_with_derivs(u, v);
            let [xy, xy_du, xy_dv] = p.eval_xy_with_derivs(u, v);
            let [z, z_du, z_dv] = p.eval_z_with_derivs(u, v);
            assert_eq!(xy.extend(z), full.position);
            assert_eq!(xy_du.extend(z_du), full.dp_du);
            assert_eq!(xy_dv.extend(z_dv), full.dp_dv);
            assert_eq!(z, p.eval(u, v).z);
        }
    }

    #[test]
    fn split_pieces_reproduce_the_patch() {
        let p = wavy();
        let (a, b) = p.split_u(0.3);
        let (c, d) = p.split_v(0.8);
        for &(s, t) in &[(0.2, 0.4), (0.9, 0.1), (0.5, 0.5)] {
            assert!((a.eval(s, t) - p.eval(0.3 * s, t)).length() < 1e-13);
            assert!((b.eval(s, t) - p.eval(0.3 + 0.7 * s, t)).length() < 1e-13);
            assert!((c.eval(s, t) - p.eval(s, 0.8 * t)).length() < 1e-13);
            assert!((d.eval(s, t) - p.eval(s, 0.8 + 0.2 * t)).length() < 1e-13);
        }
    }

    #[test]
    fn bilinear_patch_has_zero_deviation() {
        let mut pts = [DVec3::ZERO; 16];
        for i in 0..4 {
            for j in 0..4 {
                let (s, t) = (i as f64 / 3.0, j as f64 / 3.0);
                pts[4 * i + j] = DVec3::new(s, t, s * t);
            }
        }
        assert!(BezierPatch::new(pts).bilinear_deviation() < 1e-15);
        assert!(wavy().bilinear_deviation() > 0.1);
    }
}
