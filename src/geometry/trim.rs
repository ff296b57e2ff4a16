//! Trimmed surfaces: the part of a surface's `(u,v)` domain that closed loops of curves keep.
//!
//! A CAD surface is often a larger surface cut by curves in its parameter plane (Wavefront
//! OBJ's `trim` and `hole` loops of `curv2` curves; OpenUSD's `trimCurve` arrays; the trimmed
//! NURBS of Rhino and of RenderMan). A point `(u,v)` is kept when it lies inside some outer
//! loop and inside no hole; with no outer loop, the whole domain is the outer boundary.
//!
//! Each loop is a chain of cubic rational Bézier segments in homogeneous form `(u w, v w, w)`
//! with positive weights (curves of lower degree raised exactly, B-splines split at their
//! knots). Inside means a non-zero winding number, so a loop's orientation does not matter.
//! The winding number is counted exactly along the ray from the point in `+u`: a segment
//! whose control polygon's box lies wholly to the right of the point crosses the ray as often
//! (with sign) as its ends say, since a rational curve with positive weights stays in the
//! convex hull of its projected control points; a segment whose box holds the point's `u` is
//! halved (de Casteljau, in homogeneous coordinates) until its box misses the ray or lies
//! right of the point, or is smaller than rounding, where its chord decides. So the test is
//! refined only near the curve, where a coarser one (a polyline of the trim curves) would let
//! rays through a seam or stop them short of it. The same hull boxes tell a rectangle of the
//! domain that no curve enters, which then lies wholly inside or wholly outside.

use glam::{DVec2, DVec3};

use super::patch::Window;

/// One segment of a trim curve: a cubic rational Bézier curve in the surface's `(u,v)`,
/// its control points homogeneous `(u w, v w, w)` with `w > 0`.
pub type TrimSegment = [DVec3; 4];

/// Halvings of a segment near a point before its chord decides: 2⁻⁶⁰ of a segment is below
/// the rounding of its coordinates.
const MAX_DEPTH: u32 = 60;

/// Halvings of a segment when asking whether it enters a rectangle; deeper pieces count as
/// entering (the rectangle is then tested point by point, which is exact, only slower).
const RECT_DEPTH: u32 = 12;

/// A closed loop of trim curves.
#[derive(Clone, Debug, PartialEq)]
pub struct TrimLoop {
    /// The segments, end to end; the last ends where the first begins.
    pub segments: Vec<TrimSegment>,
    /// A hole (OBJ `hole`): its inside is cut away. Otherwise an outer loop (OBJ `trim`).
    pub hole: bool,
}

/// Where a rectangle of the domain lies against the trim loops.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Coverage {
    /// Wholly kept.
    Inside,
    /// Wholly cut away.
    Outside,
    /// A trim curve may cross it: each point must be tested.
    Boundary,
}

/// The kept part of a surface's domain: its outer loops and holes.
#[derive(Clone, Debug, PartialEq)]
pub struct TrimRegion {
    loops: Vec<TrimLoop>,
    /// The box of the outer loops' control points (every kept point lies in it); `None` when
    /// there is no outer loop.
    outer_box: Option<(DVec2, DVec2)>,
}

impl TrimRegion {
    /// The region of `loops`. Each loop must be closed (its segments end to end); a gap
    /// between one segment's end and the next one's start is closed with a straight segment,
    /// so the winding number stays whole. Loops without segments are dropped.
    pub fn new(loops: Vec<TrimLoop>) -> Self {
        let loops: Vec<TrimLoop> = loops
            .into_iter()
            .filter(|l| !l.segments.is_empty())
            .map(close_gaps)
            .collect();
        let outer_box = loops
            .iter()
            .filter(|l| !l.hole)
            .flat_map(|l| l.segments.iter().flat_map(|s| s.map(project)))
            .fold(None, |b: Option<(DVec2, DVec2)>, p| {
                Some(b.map_or((p, p), |(lo, hi)| (lo.min(p), hi.max(p))))
            });
        Self { loops, outer_box }
    }

    /// The loops, outer ones and holes, as given (gaps closed).
    pub fn loops(&self) -> &[TrimLoop] {
        &self.loops
    }

    /// Whether the surface keeps the point `uv`: inside an outer loop (or there is none) and
    /// inside no hole.
    pub fn contains(&self, uv: DVec2) -> bool {
        if let Some((lo, hi)) = self.outer_box {
            if uv.x < lo.x || uv.y < lo.y || uv.x > hi.x || uv.y > hi.y {
                return false;
            }
        }
        let inside = |l: &TrimLoop| {
            l.segments
                .iter()
                .map(|s| crossings(s, uv, MAX_DEPTH))
                .sum::<i32>()
                != 0
        };
        let outer = self.outer_box.is_none() || self.loops.iter().filter(|l| !l.hole).any(inside);
        outer && !self.loops.iter().filter(|l| l.hole).any(inside)
    }

    /// Where the rectangle `window` (in the surface's `(u,v)`) lies: wholly kept, wholly cut
    /// away, or crossed by a trim curve (or too near one to tell).
    pub fn coverage(&self, window: &Window) -> Coverage {
        let rect = (
            DVec2::new(window.u0.min(window.u1), window.v0.min(window.v1)),
            DVec2::new(window.u0.max(window.u1), window.v0.max(window.v1)),
        );
        let enters = self
            .loops
            .iter()
            .flat_map(|l| &l.segments)
            .any(|s| enters(s, rect, RECT_DEPTH));
        if enters {
            Coverage::Boundary
        } else if self.contains(0.5 * (rect.0 + rect.1)) {
            Coverage::Inside
        } else {
            Coverage::Outside
        }
    }

    /// Each loop as points along its curves, `per_segment` to a segment (its start included,
    /// the loop's end point last), with whether it is a hole: for drawing the trim boundary.
    pub fn polylines(&self, per_segment: usize) -> Vec<(Vec<DVec2>, bool)> {
        let n = per_segment.max(1);
        self.loops
            .iter()
            .map(|l| {
                let mut points: Vec<DVec2> = l
                    .segments
                    .iter()
                    .flat_map(|s| (0..n).map(move |k| eval(s, k as f64 / n as f64)))
                    .collect();
                if let Some(last) = l.segments.last() {
                    points.push(project(last[3]));
                }
                (points, l.hole)
            })
            .collect()
    }
}

/// The point `(u,v)` of a homogeneous control point.
#[inline]
pub fn project(p: DVec3) -> DVec2 {
    DVec2::new(p.x / p.z, p.y / p.z)
}

/// The point of segment `s` at `t` (de Casteljau in homogeneous coordinates).
pub fn eval(s: &TrimSegment, t: f64) -> DVec2 {
    let [a, b, c, d] = *s;
    let (ab, bc, cd) = (a.lerp(b, t), b.lerp(c, t), c.lerp(d, t));
    let (abc, bcd) = (ab.lerp(bc, t), bc.lerp(cd, t));
    project(abc.lerp(bcd, t))
}

/// The two halves of segment `s` (de Casteljau at ½, in homogeneous coordinates).
fn halves(s: &TrimSegment) -> (TrimSegment, TrimSegment) {
    let [a, b, c, d] = *s;
    let (ab, bc, cd) = ((a + b) * 0.5, (b + c) * 0.5, (c + d) * 0.5);
    let (abc, bcd) = ((ab + bc) * 0.5, (bc + cd) * 0.5);
    let mid = (abc + bcd) * 0.5;
    ([a, ab, abc, mid], [mid, bcd, cd, d])
}

/// The box of a segment's projected control points, which holds the curve (positive weights).
fn hull_box(s: &TrimSegment) -> (DVec2, DVec2) {
    let q = s.map(project);
    (
        q[0].min(q[1]).min(q[2].min(q[3])),
        q[0].max(q[1]).max(q[2].max(q[3])),
    )
}

/// The signed number of times segment `s` crosses the ray from `p` in `+u`, upwards positive.
/// A point counts as above the ray when its `v` exceeds `p.y` (a half-open rule, so a curve
/// through the ray's line at a segment's joint is counted once).
fn crossings(s: &TrimSegment, p: DVec2, depth: u32) -> i32 {
    let (lo, hi) = hull_box(s);
    if hi.y <= p.y || lo.y > p.y || hi.x < p.x {
        return 0;
    }
    let above = |q: DVec2| (q.y > p.y) as i32;
    let (start, end) = (project(s[0]), project(s[3]));
    if lo.x > p.x {
        return above(end) - above(start);
    }
    let small =
        (hi - lo).max_element() <= 4.0 * f64::EPSILON * (hi.abs().max_element() + lo.abs().max_element());
    if depth == 0 || small {
        // The chord: where it crosses the ray's line, if it does, decides.
        let change = above(end) - above(start);
        if change == 0 {
            return 0;
        }
        let x = start.x + (p.y - start.y) * (end.x - start.x) / (end.y - start.y);
        return if x > p.x { change } else { 0 };
    }
    let (a, b) = halves(s);
    crossings(&a, p, depth - 1) + crossings(&b, p, depth - 1)
}

/// Whether segment `s` may enter the rectangle `rect` (corners `lo`, `hi`): false only when it
/// surely does not.
fn enters(s: &TrimSegment, (rlo, rhi): (DVec2, DVec2), depth: u32) -> bool {
    let (lo, hi) = hull_box(s);
    if hi.x < rlo.x || hi.y < rlo.y || lo.x > rhi.x || lo.y > rhi.y {
        return false;
    }
    let within = lo.x >= rlo.x && lo.y >= rlo.y && hi.x <= rhi.x && hi.y <= rhi.y;
    if within || depth == 0 {
        return true;
    }
    let (a, b) = halves(s);
    enters(&a, (rlo, rhi), depth - 1) || enters(&b, (rlo, rhi), depth - 1)
}

/// `l` with a straight segment wherever one segment does not end where the next begins
/// (the last's end and the first's start included).
fn close_gaps(l: TrimLoop) -> TrimLoop {
    let n = l.segments.len();
    let mut segments = Vec::with_capacity(n);
    for k in 0..n {
        let s = l.segments[k];
        segments.push(s);
        let (end, next) = (project(s[3]), project(l.segments[(k + 1) % n][0]));
        if end != next {
            segments.push(line(end, next));
        }
    }
    TrimLoop {
        segments,
        hole: l.hole,
    }
}

/// The straight segment from `a` to `b`, as a cubic.
pub fn line(a: DVec2, b: DVec2) -> TrimSegment {
    let at = |t: f64| a.lerp(b, t).extend(1.0);
    [at(0.0), at(1.0 / 3.0), at(2.0 / 3.0), at(1.0)]
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The unit circle about `c` of radius `r` as four rational quarter arcs (degree 2, the
    /// middle weight √½), raised to cubics.
    fn circle(c: DVec2, r: f64, hole: bool) -> TrimLoop {
        let w = std::f64::consts::FRAC_1_SQRT_2;
        let corners = [
            (1.0, 0.0),
            (1.0, 1.0),
            (0.0, 1.0),
            (-1.0, 1.0),
            (-1.0, 0.0),
            (-1.0, -1.0),
            (0.0, -1.0),
            (1.0, -1.0),
        ];
        let h = |k: usize, weight: f64| {
            let (x, y) = corners[k % 8];
            (c + r * DVec2::new(x, y)).extend(1.0) * weight
        };
        let segments = (0..4)
            .map(|q| super::super::elevate::to_cubic(&[h(2 * q, 1.0), h(2 * q + 1, w), h(2 * q + 2, 1.0)]))
            .collect();
        TrimLoop { segments, hole }
    }

    /// Points just inside and just outside a rational circle, 1e-12 from it, are told apart at
    /// every angle: the test is exact on the curve, not on a polygon through it.
    #[test]
    fn a_rational_circle_is_told_apart_exactly() {
        let region = TrimRegion::new(vec![circle(DVec2::new(0.5, 0.5), 0.25, false)]);
        for k in 0..997 {
            let a = k as f64 * 0.0063;
            let dir = DVec2::new(a.cos(), a.sin());
            let at = |r: f64| DVec2::new(0.5, 0.5) + r * dir;
            assert!(region.contains(at(0.25 - 1e-12)), "angle {a}: inside");
            assert!(!region.contains(at(0.25 + 1e-12)), "angle {a}: outside");
        }
    }

    /// A hole cuts its inside away from an outer loop's; with only a hole, the rest of the
    /// domain is kept. Orientation does not matter.
    #[test]
    fn holes_cut_outer_loops() {
        let square = |lo: f64, hi: f64, hole: bool| TrimLoop {
            segments: vec![
                line(DVec2::new(lo, lo), DVec2::new(hi, lo)),
                line(DVec2::new(hi, lo), DVec2::new(hi, hi)),
                line(DVec2::new(hi, hi), DVec2::new(lo, hi)),
                line(DVec2::new(lo, hi), DVec2::new(lo, lo)),
            ],
            hole,
        };
        let mut reversed = square(0.0, 1.0, false);
        reversed.segments.reverse();
        for s in &mut reversed.segments {
            s.reverse();
        }
        let region = TrimRegion::new(vec![reversed, circle(DVec2::splat(0.5), 0.2, true)]);
        assert!(region.contains(DVec2::new(0.1, 0.1)));
        assert!(!region.contains(DVec2::new(0.5, 0.5)));
        assert!(!region.contains(DVec2::new(1.5, 0.5)));
        let holes_only = TrimRegion::new(vec![circle(DVec2::splat(0.5), 0.2, true)]);
        assert!(holes_only.contains(DVec2::new(0.1, 0.9)));
        assert!(!holes_only.contains(DVec2::new(0.55, 0.45)));
    }

    /// A point on the ray's line through a joint of two segments (and through a control point
    /// of a curve's hull) is counted once, not twice: a diamond's left and right corners.
    #[test]
    fn joints_on_the_rays_line_count_once() {
        let p = |x: f64, y: f64| DVec2::new(x, y);
        let diamond = TrimLoop {
            segments: vec![
                line(p(0.5, 0.0), p(1.0, 0.5)),
                line(p(1.0, 0.5), p(0.5, 1.0)),
                line(p(0.5, 1.0), p(0.0, 0.5)),
                line(p(0.0, 0.5), p(0.5, 0.0)),
            ],
            hole: false,
        };
        let region = TrimRegion::new(vec![diamond]);
        assert!(region.contains(p(0.5, 0.5)));
        assert!(region.contains(p(0.1, 0.5)));
        assert!(!region.contains(p(-0.1, 0.5)));
        assert!(!region.contains(p(0.9, 0.9)));
    }

    /// Rectangles well inside, well outside and across a circle are classified so, and every
    /// classified rectangle agrees with its points.
    #[test]
    fn rectangles_are_classified_by_their_points() {
        let region = TrimRegion::new(vec![circle(DVec2::splat(0.5), 0.3, false)]);
        let window = |u0: f64, u1: f64, v0: f64, v1: f64| Window { u0, u1, v0, v1 };
        assert_eq!(region.coverage(&window(0.45, 0.55, 0.45, 0.55)), Coverage::Inside);
        assert_eq!(region.coverage(&window(0.0, 0.1, 0.0, 0.1)), Coverage::Outside);
        assert_eq!(region.coverage(&window(0.7, 0.9, 0.4, 0.6)), Coverage::Boundary);
        for i in 0..16 {
            for j in 0..16 {
                let w = window(
                    i as f64 / 16.0,
                    (i + 1) as f64 / 16.0,
                    j as f64 / 16.0,
                    (j + 1) as f64 / 16.0,
                );
                let c = region.coverage(&w);
                for (s, t) in [(0.01, 0.01), (0.99, 0.5), (0.5, 0.99), (0.3, 0.7)] {
                    let inside = region.contains(w.map(s, t));
                    match c {
                        Coverage::Inside => assert!(inside),
                        Coverage::Outside => assert!(!inside),
                        Coverage::Boundary => {}
                    }
                }
            }
        }
    }

    /// A loop with a gap is closed by a straight segment: the winding number stays whole.
    #[test]
    fn gaps_are_closed() {
        let p = |x: f64, y: f64| DVec2::new(x, y);
        let open = TrimLoop {
            segments: vec![
                line(p(0.0, 0.0), p(1.0, 0.0)),
                line(p(1.0, 0.0), p(1.0, 1.0)),
                line(p(1.0, 1.0), p(0.0, 1.0)),
            ],
            hole: false,
        };
        let region = TrimRegion::new(vec![open]);
        assert_eq!(region.loops()[0].segments.len(), 4);
        assert!(region.contains(p(0.5, 0.5)));
        assert!(!region.contains(p(-0.5, 0.5)));
    }
}
