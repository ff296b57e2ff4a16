//! The solve in one ray-space sub-patch ([`super`]'s root finder): where Newton starts (the
//! ray's crossing of the corners' bilinear patch), the quadrilateral test that rules a
//! sub-patch out before any Newton step, Newton itself (Levenberg–Marquardt where the
//! Jacobian is near singular), and the test that proves a root unique (the Jacobian's sign
//! fixed over the sub-patch).

use glam::{DVec2, DVec3};

use crate::geometry::bezier::BezierPatch;

/// Newton iterations before giving up on a sub-patch and splitting it.
const MAX_NEWTON_ITERATIONS: usize = 10;

/// Where the ray meets the bilinear patch through the four corners of the ray-space patch `p`
/// (inverse bilinear interpolation, solved as a quadratic), clamped near `[0,1]²`; the middle
/// `(0.5, 0.5)` when the quadratic has no usable root. A start this close to the root lets
/// Newton converge in two or three steps to the root in this window rather than another.
pub(super) fn bilinear_start(p: &BezierPatch) -> (f64, f64) {
    let cross = |a: DVec2, b: DVec2| a.x * b.y - a.y * b.x;
    let p00 = p.points[0].truncate();
    let e = p.points[12].truncate() - p00; // along s
    let f = p.points[3].truncate() - p00; // along t
    let g = p00 - p.points[12].truncate() - p.points[3].truncate() + p.points[15].truncate();
    let h = -p00;
    let k2 = cross(g, f);
    let k1 = cross(e, f) + cross(h, g);
    let k0 = cross(h, e);
    let t_candidates = if k2.abs() <= 1e-12 * k1.abs() {
        [-k0 / k1, f64::NAN]
    } else {
        let disc = k1 * k1 - 4.0 * k0 * k2;
        if disc < 0.0 {
            return (0.5, 0.5);
        }
        let q = -0.5 * (k1 + k1.signum() * disc.sqrt());
        [q / k2, k0 / q]
    };
    let mut best = (0.5, 0.5);
    let mut best_outside = f64::INFINITY;
    for t in t_candidates {
        if !t.is_finite() {
            continue;
        }
        let den = e + g * t;
        let s = if den.x.abs() >= den.y.abs() {
            (h.x - f.x * t) / den.x
        } else {
            (h.y - f.y * t) / den.y
        };
        if !s.is_finite() {
            continue;
        }
        // Prefer the candidate nearest the unit square.
        let outside = (s - s.clamp(0.0, 1.0)).abs().max((t - t.clamp(0.0, 1.0)).abs());
        if outside < best_outside {
            best_outside = outside;
            best = (s.clamp(-0.25, 1.25), t.clamp(-0.25, 1.25));
        }
    }
    best
}

/// Whether the ray passes farther than `tolerance` from the ray-space sub-patch `p`, judged by
/// the bilinear patch `L` through its four corners.
///
/// `p − L` is itself a Bézier patch whose control points are `D_ij = P_ij − L(i/3, j/3)` (a
/// bilinear patch degree-elevated to bicubic has the control points `L(i/3, j/3)`). Where the
/// corners form a strictly convex quadrilateral, `L` maps the unit square onto it, so by the
/// convex hull property no point of `p` lies farther outside an edge line than
/// `δ_e = max n_e·D_ij` (`n_e` the edge's outward unit normal), and a ray farther than `δ_e +
/// tolerance` outside it meets no point of `p`. (`δ_e` is at most the largest `|D_ij|`, which
/// `deviation` bounds, and is often far smaller: a flat leaf's deviations mostly lie along
/// its edges, so the per-edge bound rules out more sub-patches than the largest `|D_ij|`
/// would.) For a nearly flat sub-patch the quadrilateral is much tighter than the box
/// of the control points: this one test replaces the Newton solves and splits that find no
/// root where the ray passes beside a sub-patch (its root lies in a neighbour, or it misses).
pub(super) fn beside(p: &BezierPatch, tolerance: f64, deviation: f64) -> bool {
    let corner = |k: usize| p.points[k].truncate();
    // Counter-clockwise or clockwise; the orientation comes from the first corner's turn.
    let quad = [corner(0), corner(12), corner(15), corner(3)];
    let cross = |a: DVec2, b: DVec2| a.x * b.y - a.y * b.x;
    let edges = [
        quad[1] - quad[0],
        quad[2] - quad[1],
        quad[3] - quad[2],
        quad[0] - quad[3],
    ];
    let turns = [
        cross(edges[3], edges[0]),
        cross(edges[0], edges[1]),
        cross(edges[1], edges[2]),
        cross(edges[2], edges[3]),
    ];
    let orientation = turns[0].signum();
    if !turns.iter().all(|&turn| turn * orientation > 0.0) {
        return false;
    }
    // Distance of the ray (the origin) outside each edge line (times the edge's length); the
    // largest one. An edge the origin lies inside of cannot decide the test (that needs a
    // distance above the tolerance), so its length (a square root) is not taken: a ray
    // through the quadrilateral, as every hitting ray's is, takes none.
    let mut outside: f64 = 0.0;
    let mut beyond = [(0.0, 0.0); 4];
    for (k, (edge, start)) in edges.iter().zip(quad).enumerate() {
        // The origin relative to the edge's start, against the interior's side.
        let signed = -orientation * cross(*edge, -start);
        if signed > 0.0 {
            let length = edge.length();
            beyond[k] = (signed, length);
            outside = outside.max(signed / length);
        }
    }
    // (No NaN reaches here: a NaN corner fails the convexity test above.)
    if outside <= tolerance {
        return false;
    }
    // A bound on the deviation the caller knows (the leaf's, in space: its projection is no
    // larger) may settle it before the sixteen points are measured.
    if outside - tolerance > deviation {
        return true;
    }
    // The surface is `L + D`, `D` the Bézier patch of the deviations `D_ij`. Beyond an edge
    // line, `L` lies inside (a convex quadrilateral holds `L`'s image) and `D` reaches at most
    // `max n·D_ij`, `n` the edge's outward unit normal (the convex hull property): the ray
    // misses when it lies farther than that, plus the tolerance, outside some edge. That is
    // never looser than the largest `|D_ij|` and, for the edge a ray passes beside, often far
    // tighter: a flat leaf's deviations mostly lie along the edges.
    let (p00, e, f, g) = (
        quad[0],
        edges[0],
        quad[3] - quad[0],
        quad[0] - quad[1] + quad[2] - quad[3],
    );
    let mut reach = [f64::NEG_INFINITY; 4];
    for i in 0..4 {
        let s = i as f64 / 3.0;
        for j in 0..4 {
            let t = j as f64 / 3.0;
            let d = corner(4 * i + j) - (p00 + e * s + f * t + g * (s * t));
            for (k, edge) in edges.iter().enumerate() {
                // `n·D` times the edge's length.
                reach[k] = reach[k].max(-orientation * cross(*edge, d));
            }
        }
    }
    beyond
        .iter()
        .zip(reach)
        .any(|(&(signed, length), reach)| signed > 0.0 && signed - tolerance * length > reach)
}

/// A root of a ray-space sub-patch: where the ray meets it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Root {
    /// The sub-patch's parameters.
    pub s: f64,
    /// The sub-patch's second parameter.
    pub t: f64,
    /// Distance along the ray (the third ray-space coordinate there).
    pub dist: f64,
    /// `∂P/∂s` there, in ray space (zero where it is not known).
    pub ds: DVec3,
    /// `∂P/∂t` there, in ray space (zero where it is not known).
    pub dt: DVec3,
}

impl Root {
    /// A root whose derivatives are not known (a departure point, which is never a hit).
    pub fn without_derivatives(s: f64, t: f64, dist: f64) -> Self {
        Self {
            s,
            t,
            dist,
            ds: DVec3::ZERO,
            dt: DVec3::ZERO,
        }
    }
}

/// Newton (or Levenberg–Marquardt where the Jacobian is near singular) on the first two
/// ray-space coordinates, from [`bilinear_start`] and, should that fail (its corners can
/// coincide at a pole), from the middle. Returns the root, its ray distance and the
/// derivatives there.
pub(super) fn newton(p: &BezierPatch, tolerance: f64, start: (f64, f64)) -> Option<Root> {
    let clamped = !(0.0..=1.0).contains(&start.0) || !(0.0..=1.0).contains(&start.1);
    newton_from(p, tolerance, start)
        .or_else(|| clamped.then(|| newton_from(p, tolerance, (0.5, 0.5))).flatten())
}

/// Newton from `(s, t)`, with steps limited to half the sub-patch.
fn newton_from(p: &BezierPatch, tolerance: f64, (mut s, mut t): (f64, f64)) -> Option<Root> {
    let mut previous = f64::INFINITY;
    for iteration in 0..MAX_NEWTON_ITERATIONS {
        let [f, fs, ft] = p.eval_xy_with_derivs(s, t);
        let residual = f.x.abs().max(f.y.abs());
        if residual <= tolerance {
            // The third coordinate completes the derivatives this step evaluated: the
            // distance and the tangents (so the normal) at the root, for one coordinate's cost.
            let [dist, zs, zt] = p.eval_z_with_derivs(s, t);
            return Some(Root {
                s,
                t,
                dist,
                ds: fs.extend(zs),
                dt: ft.extend(zt),
            });
        }
        // Converging Newton shrinks the residual far faster than this; give the split
        // fallback the sub-patch instead of iterating on.
        if iteration >= 3 && residual > 0.5 * previous {
            return None;
        }
        previous = residual;
        // Solve [fs ft] (ds, dt) = f for the first two coordinates.
        let det = fs.x * ft.y - fs.y * ft.x;
        let norm2 = fs.x * fs.x + fs.y * fs.y + ft.x * ft.x + ft.y * ft.y;
        let (mut ds, mut dt) = if det.abs() > 1e-9 * norm2 {
            ((f.x * ft.y - f.y * ft.x) / det, (fs.x * f.y - fs.y * f.x) / det)
        } else {
            // Minimum-norm damped least squares: Δ = Jᵀ (J Jᵀ + λI)⁻¹ f.
            let lambda = 1e-12 * norm2 + f64::MIN_POSITIVE;
            let a = fs.x * fs.x + ft.x * ft.x + lambda;
            let b = fs.x * fs.y + ft.x * ft.y;
            let d = fs.y * fs.y + ft.y * ft.y + lambda;
            let det2 = a * d - b * b;
            if det2 == 0.0 || !det2.is_finite() {
                return None;
            }
            let y0 = (d * f.x - b * f.y) / det2;
            let y1 = (a * f.y - b * f.x) / det2;
            (fs.x * y0 + fs.y * y1, ft.x * y0 + ft.y * y1)
        };
        // Trust region: never jump more than half the sub-patch in one step.
        let step = ds.abs().max(dt.abs());
        if step > MAX_STEP {
            (ds, dt) = shortened(ds, dt, step);
        }
        s -= ds;
        t -= dt;
        // Well outside the sub-patch: the root (if any) is not this one's.
        if !(-0.5..=1.5).contains(&s) || !(-0.5..=1.5).contains(&t) {
            return None;
        }
    }
    None
}

/// Largest Newton step in sub-patch parameters.
const MAX_STEP: f64 = 0.5;

/// The Newton step `(ds, dt)`, whose larger component is `step`, shortened to [`MAX_STEP`].
/// Out of line: taken inline, the compiler computes the division on every step (a select
/// rather than a branch), an eighth of the solve's own time, for a step rarely this long.
#[cold]
#[inline(never)]
fn shortened(ds: f64, dt: f64, step: f64) -> (f64, f64) {
    (ds * (MAX_STEP / step), dt * (MAX_STEP / step))
}

/// Whether `det [∂(x,y)/∂s ∂(x,y)/∂t]` — which in ray space is `(Ps × Pt)·d`, the normal
/// against the ray direction — provably keeps one sign over the sub-patch. The derivative
/// patches' control points are differences of `p`'s; interval products of their bounds bound
/// the determinant. Between two crossings of a smooth surface piece the ray would have to be
/// tangent to it somewhere, where the determinant is zero, so a fixed sign means at most one
/// root. Returns that sign (±1), or `None` when it is not proven fixed.
pub(super) fn jacobian_sign(p: &BezierPatch) -> Option<f64> {
    let (mut su_lo, mut su_hi) = (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY));
    let (mut sv_lo, mut sv_hi) = (su_lo, su_hi);
    for i in 0..4 {
        for j in 0..4 {
            if i < 3 {
                let d = (p.points[4 * (i + 1) + j] - p.points[4 * i + j]).truncate();
                su_lo = su_lo.min(d);
                su_hi = su_hi.max(d);
            }
            if j < 3 {
                let d = (p.points[4 * i + j + 1] - p.points[4 * i + j]).truncate();
                sv_lo = sv_lo.min(d);
                sv_hi = sv_hi.max(d);
            }
        }
    }
    let product = |a_lo: f64, a_hi: f64, b_lo: f64, b_hi: f64| {
        let c = [a_lo * b_lo, a_lo * b_hi, a_hi * b_lo, a_hi * b_hi];
        (
            c.iter().copied().fold(f64::INFINITY, f64::min),
            c.iter().copied().fold(f64::NEG_INFINITY, f64::max),
        )
    };
    let (a_lo, a_hi) = product(su_lo.x, su_hi.x, sv_lo.y, sv_hi.y);
    let (b_lo, b_hi) = product(su_lo.y, su_hi.y, sv_lo.x, sv_hi.x);
    // det = a - b ∈ [a_lo - b_hi, a_hi - b_lo]
    if a_lo - b_hi > 0.0 {
        Some(1.0)
    } else if a_hi - b_lo < 0.0 {
        Some(-1.0)
    } else {
        None
    }
}

/// The Jacobian `det [∂(x,y)/∂s ∂(x,y)/∂t]` of the ray-space patch `p` at `(s, t)` (the
/// polynomial's value, also outside `[0,1]²`).
pub(super) fn jacobian_at(p: &BezierPatch, s: f64, t: f64) -> f64 {
    let [_, fs, ft] = p.eval_xy_with_derivs(s, t);
    fs.x * ft.y - fs.y * ft.x
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;

    /// A curved sub-patch over the unit square: the bilinear patch through four corners, its
    /// control points moved by up to `bend` in every coordinate.
    fn bent_patch(next: &mut impl FnMut() -> f64, bend: f64) -> BezierPatch {
        let corners = [
            DVec2::new(0.0, 0.0) + DVec2::new(next(), next()) * 0.2,
            DVec2::new(1.0, 0.0) + DVec2::new(next(), next()) * 0.2,
            DVec2::new(0.0, 1.0) + DVec2::new(next(), next()) * 0.2,
            DVec2::new(1.0, 1.0) + DVec2::new(next(), next()) * 0.2,
        ];
        let mut points = [DVec3::ZERO; 16];
        for i in 0..4 {
            for j in 0..4 {
                let (s, t) = (i as f64 / 3.0, j as f64 / 3.0);
                let xy = corners[0] * (1.0 - s) * (1.0 - t)
                    + corners[1] * s * (1.0 - t)
                    + corners[2] * (1.0 - s) * t
                    + corners[3] * s * t;
                let corner = (i == 0 || i == 3) && (j == 0 || j == 3);
                let moved = if corner { 0.0 } else { bend };
                let offset = DVec3::new(next() - 0.5, next() - 0.5, next() - 0.5) * 2.0 * moved;
                points[4 * i + j] = xy.extend(2.0) + offset;
            }
        }
        BezierPatch::new(points)
    }

    #[test]
    fn beside_never_rules_out_a_ray_that_comes_within_the_tolerance() {
        let mut x = 0x2545F4914F6CDD1Du64;
        let mut next = move || {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            (x >> 11) as f64 / (1u64 << 53) as f64
        };
        let tolerance = 0.02;
        let (mut ruled_out, mut near) = (0, 0);
        for _ in 0..300 {
            let p = bent_patch(&mut next, 0.15);
            // Points on the patch, densely: a ray passing within the tolerance of one of them
            // may not be ruled out.
            let samples: Vec<DVec2> = (0..=40)
                .flat_map(|i| (0..=40).map(move |j| (i as f64 / 40.0, j as f64 / 40.0)))
                .map(|(s, t)| p.eval(s, t).truncate())
                .collect();
            for _ in 0..40 {
                // Rays from well inside to well outside the quadrilateral.
                let ray = DVec2::new(next(), next()) * 1.8 - DVec2::splat(0.4);
                let shifted = BezierPatch::new(p.points.map(|c| c - ray.extend(0.0)));
                let verdict = beside(&shifted, tolerance, f64::INFINITY);
                if samples.iter().any(|q| (*q - ray).length() <= tolerance) {
                    near += 1;
                    assert!(
                        !verdict,
                        "a ray through {ray} passes within the tolerance of the patch"
                    );
                }
                ruled_out += verdict as usize;
            }
        }
        assert!(
            near > 2000 && ruled_out > 2000,
            "near {near}, ruled out {ruled_out}"
        );
    }

    #[test]
    fn beside_bounds_each_edge_by_the_deviation_across_it() {
        // The unit square, its inner control points pushed along the edge at x = 1 (in y)
        // by 0.3: far from the bilinear patch, but not across that edge.
        let mut points = [DVec3::ZERO; 16];
        for i in 0..4 {
            for j in 0..4 {
                let along = if (1..3).contains(&i) && (1..3).contains(&j) {
                    0.3
                } else {
                    0.0
                };
                points[4 * i + j] = DVec3::new(i as f64 / 3.0, j as f64 / 3.0 + along, 1.0);
            }
        }
        let p = BezierPatch::new(points);
        // A ray 0.1 beyond the edge x = 1: nearer than the largest deviation (0.3), farther
        // than any deviation across the edge (none) and the tolerance.
        let shifted = BezierPatch::new(p.points.map(|c| c - DVec3::new(1.1, 0.5, 0.0)));
        assert!(beside(&shifted, 0.01, f64::INFINITY));
        // Pushed across the edge instead, the same ray may meet the patch.
        let mut across = points;
        for (k, q) in across.iter_mut().enumerate() {
            let (i, j) = (k / 4, k % 4);
            if (1..3).contains(&i) && (1..3).contains(&j) {
                *q = DVec3::new(i as f64 / 3.0 + 0.3, j as f64 / 3.0, 1.0);
            }
        }
        let shifted = BezierPatch::new(across.map(|c| c - DVec3::new(1.1, 0.5, 0.0)));
        assert!(!beside(&shifted, 0.01, f64::INFINITY));
    }
}
