//! Rational bicubic Bézier patches: control points with positive weights,
//! `P(u,v) = Σ B_i(u) B_j(v) w_ij P_ij / Σ B_i(u) B_j(v) w_ij` (Piegl & Tiller, *The NURBS Book*,
//! §4.4). They represent conics exactly: a quarter circle is a rational quadratic, so Rhino's
//! cylinders, cones and surfaces of revolution are patches of this kind.
//!
//! A patch is kept in homogeneous form: the numerator `N_ij = w_ij P_ij` and the weights,
//! each a polynomial Bézier patch, so that De Casteljau splits, degree elevation and knot
//! insertion are the polynomial ones applied to both (§5.2). With positive weights the surface
//! lies in the convex hull of the projected points `P_ij` (every point is a convex combination
//! of them, with the weights `B_i B_j w_ij / W`), so bounds come from those; zero or negative
//! weights are refused where patches are read. Derivatives follow the quotient rule:
//! `∂P/∂u = (∂N/∂u − P ∂W/∂u) / W`.

use glam::DVec3;

use super::bezier::{
    bernstein, bernstein_deriv, limit_normal, split_grid_quad, sub_grid, BezierPatch, SurfacePoint,
};
use super::patch::Window;

/// The weights of a rational patch's 16 control points, `weights[4 * i + j]` as the points.
pub type Weights = [f64; 16];

/// Why a patch's weights cannot be used.
pub fn weights_error(weights: &Weights) -> Option<String> {
    let bad = weights.iter().position(|w| !(w.is_finite() && *w > 0.0))?;
    Some(format!(
        "weight {} of control point {bad} is not a positive number: rational patches need \
         weights above 0",
        weights[bad]
    ))
}

/// A rational bicubic patch in homogeneous form ([the module](self)).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RationalPatch {
    /// `w_ij P_ij`, as a polynomial patch.
    pub numerator: BezierPatch,
    /// `w_ij`.
    pub weights: Weights,
}

impl RationalPatch {
    /// The patch with control points `points` (as the user places them) and `weights`.
    pub fn new(points: &BezierPatch, weights: &Weights) -> Self {
        Self {
            numerator: BezierPatch::new(std::array::from_fn(|k| points.points[k] * weights[k])),
            weights: *weights,
        }
    }

    /// The control points `P_ij = N_ij / w_ij`: what bounds the surface and what the editor
    /// shows and moves.
    pub fn points(&self) -> BezierPatch {
        BezierPatch::new(std::array::from_fn(|k| {
            self.numerator.points[k] / self.weights[k]
        }))
    }

    /// `W(u,v)`, `∂W/∂u` and `∂W/∂v`.
    pub fn weight_with_derivs(&self, u: f64, v: f64) -> [f64; 3] {
        weight_with_derivs(&self.weights, u, v)
    }

    /// `P(u,v)`.
    pub fn eval(&self, u: f64, v: f64) -> DVec3 {
        self.eval_with_derivs(u, v).position
    }

    /// `P(u,v)` with `∂P/∂u` and `∂P/∂v` (the quotient rule).
    pub fn eval_with_derivs(&self, u: f64, v: f64) -> SurfacePoint {
        let n = self.numerator.eval_with_derivs(u, v);
        let [w, wu, wv] = self.weight_with_derivs(u, v);
        let position = n.position / w;
        SurfacePoint {
            position,
            dp_du: (n.dp_du - position * wu) / w,
            dp_dv: (n.dp_dv - position * wv) / w,
        }
    }

    /// The unit normal `∂P/∂u × ∂P/∂v`, or the limit normal nearby where it vanishes (as
    /// [`BezierPatch::normal_at_scale`], `scale` the patch's size).
    pub fn normal_at_scale(&self, u: f64, v: f64, scale: f64) -> Option<DVec3> {
        limit_normal(u, v, scale, |u, v| self.eval_with_derivs(u, v))
    }

    /// Splits into four at `(0.5, 0.5)`, in [`BezierPatch::split_quad`]'s order.
    pub fn split_quad(&self) -> [Self; 4] {
        let n = self.numerator.split_quad();
        let w = split_grid_quad(&self.weights);
        std::array::from_fn(|k| Self {
            numerator: n[k],
            weights: w[k],
        })
    }
}

/// `W(u,v)`, `∂W/∂u` and `∂W/∂v` of the weights `w` taken as a scalar Bézier patch.
pub fn weight_with_derivs(w: &Weights, u: f64, v: f64) -> [f64; 3] {
    let (bu, du) = (bernstein(u), bernstein_deriv(u));
    let (bv, dv) = (bernstein(v), bernstein_deriv(v));
    let mut out = [0.0; 3];
    for i in 0..4 {
        for j in 0..4 {
            let x = w[4 * i + j];
            out[0] += bu[i] * bv[j] * x;
            out[1] += du[i] * bv[j] * x;
            out[2] += bu[i] * dv[j] * x;
        }
    }
    out
}

/// The weights `w` restricted to `window` and reparameterised over `[0,1]²`, as
/// [`BezierPatch::sub_patch`] restricts points.
pub fn window_weights(w: &Weights, window: &Window) -> Weights {
    sub_grid(w, (window.u0, window.u1), (window.v0, window.v1))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A quarter of a unit cylinder around `z`, `u` around it (a rational quadratic raised to a
    /// cubic), `v` along it from 0 to 1.
    pub(crate) fn quarter_cylinder() -> (BezierPatch, Weights) {
        let h = std::f64::consts::FRAC_1_SQRT_2;
        // Quadratic: (1,0) w 1, (1,1) w √½, (0,1) w 1. Raised to degree 3 in homogeneous form.
        let quad = [
            (DVec3::new(1.0, 0.0, 0.0), 1.0),
            (DVec3::new(1.0, 1.0, 0.0), h),
            (DVec3::new(0.0, 1.0, 0.0), 1.0),
        ];
        let hom = |(p, w): (DVec3, f64)| (p * w, w);
        let lerp =
            |a: (DVec3, f64), b: (DVec3, f64), t: f64| (a.0 * (1.0 - t) + b.0 * t, a.1 * (1.0 - t) + b.1 * t);
        let q: Vec<(DVec3, f64)> = quad.into_iter().map(hom).collect();
        let cubic = [
            q[0],
            lerp(q[0], q[1], 2.0 / 3.0),
            lerp(q[1], q[2], 1.0 / 3.0),
            q[2],
        ];
        let mut points = [DVec3::ZERO; 16];
        let mut weights = [0.0; 16];
        for (i, (n, w)) in cubic.iter().enumerate() {
            for j in 0..4 {
                points[4 * i + j] = *n / *w + DVec3::Z * (j as f64 / 3.0);
                weights[4 * i + j] = *w;
            }
        }
        (BezierPatch::new(points), weights)
    }

    #[test]
    fn a_rational_quarter_cylinder_is_exactly_round() {
        let (points, weights) = quarter_cylinder();
        let p = RationalPatch::new(&points, &weights);
        for k in 0..=20 {
            for l in 0..=4 {
                let (u, v) = (k as f64 / 20.0, l as f64 / 4.0);
                let s = p.eval_with_derivs(u, v);
                assert!((s.position.truncate().length() - 1.0).abs() < 1e-14, "{u} {v}");
                assert!((s.position.z - v).abs() < 1e-14);
                // The tangent around is perpendicular to the radius; the normal is radial.
                assert!(s.dp_du.dot(s.position.truncate().extend(0.0)).abs() < 1e-13);
                let n = p.normal_at_scale(u, v, 2.0).unwrap_or_default();
                assert!((n.truncate().length() - 1.0).abs() < 1e-12 && n.z.abs() < 1e-12);
            }
        }
    }

    #[test]
    fn derivatives_match_differences_and_quarters_match_the_whole() {
        let (points, mut weights) = quarter_cylinder();
        weights[5] = 2.5;
        weights[10] = 0.4;
        let p = RationalPatch::new(&points, &weights);
        let h = 1e-6;
        let s = p.eval_with_derivs(0.3, 0.6);
        let du = (p.eval(0.3 + h, 0.6) - p.eval(0.3 - h, 0.6)) / (2.0 * h);
        let dv = (p.eval(0.3, 0.6 + h) - p.eval(0.3, 0.6 - h)) / (2.0 * h);
        assert!((s.dp_du - du).length() < 1e-7 && (s.dp_dv - dv).length() < 1e-7);
        let q = p.split_quad();
        // Quarter 3 is u, v in [0.5, 1].
        let a = q[3].eval(0.2, 0.8);
        let b = p.eval(0.6, 0.9);
        assert!((a - b).length() < 1e-14, "{a} {b}");
        assert!(weights_error(&weights).is_none());
        weights[3] = 0.0;
        assert!(weights_error(&weights).is_some_and(|e| e.contains("control point 3")));
    }
}
