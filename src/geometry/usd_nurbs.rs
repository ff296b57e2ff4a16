//! OpenUSD's `NurbsPatch` (`UsdGeomNurbsPatch`) as caustic surfaces: a rational or polynomial
//! B-spline surface of order 2 to 4 along each axis (degree 1 to 3, raised exactly to bicubic)
//! with its trim curves, kept as its own net ([`super::net`]) so that an editor moves its
//! control points.
//!
//! The schema follows RenderMan's `RiNuPatch` and `RiTrimCurve` (OpenUSD's
//! `usdGeom/nurbsPatch.h`): `points` lists the control points with `u` varying fastest,
//! `uKnots` holds `uVertexCount + uOrder` values, `uRange` is the part of the knots' domain to
//! draw (the whole domain when unauthored), `pointWeights` makes the surface rational (points
//! are not pre-weighted). Trim curves are rational B-splines in the surface's `(u,v)`:
//! `trimCurve:counts` gives the curves of each loop, `orders`, `vertexCounts`, `knots` and
//! `ranges` each curve, and `points` their homogeneous control points `(u w, v w, w)`. Which
//! loops are holes follows RenderMan's odd winding rule: a loop inside an odd number of other
//! loops is a hole, so a loop's orientation does not matter.

use std::sync::Arc;

use glam::{DVec2, DVec3};

use super::bspline::{bezier_segments, BsplineSurface, Knots, DEGREE};
use super::freeform::{net_pieces, DomainPatch};
use super::freeform_trim::{closes, MAX_TRIM_SEGMENTS};
use super::net::SurfaceNet;
use super::patch::Window;
use super::trim::{project, TrimLoop, TrimRegion, TrimSegment};
use crate::settings::limits::{MAX_KNOTS, MAX_PATCHES};

/// A `NurbsPatch` prim's attributes, as read from its layer (unauthored ones `None`).
#[derive(Clone, Debug, Default)]
pub struct NurbsFields {
    /// `uVertexCount`, `vVertexCount`.
    pub vertex_counts: [Option<i64>; 2],
    /// `uOrder`, `vOrder`.
    pub orders: [Option<i64>; 2],
    /// `uKnots`, `vKnots`.
    pub knots: [Option<Vec<f64>>; 2],
    /// `uRange`, `vRange`.
    pub ranges: [Option<DVec2>; 2],
    /// `points`.
    pub points: Option<Vec<DVec3>>,
    /// `pointWeights`.
    pub weights: Option<Vec<f64>>,
    /// The `trimCurve:*` arrays.
    pub trim: TrimFields,
}

/// A `NurbsPatch` prim's `trimCurve:*` attributes.
#[derive(Clone, Debug, Default)]
pub struct TrimFields {
    /// `trimCurve:counts`: curves per loop.
    pub counts: Option<Vec<i64>>,
    /// `trimCurve:orders`: each curve's order.
    pub orders: Option<Vec<i64>>,
    /// `trimCurve:vertexCounts`: each curve's control points.
    pub vertex_counts: Option<Vec<i64>>,
    /// `trimCurve:knots`, all curves' knots end to end.
    pub knots: Option<Vec<f64>>,
    /// `trimCurve:ranges`: each curve's `(min, max)` parameter.
    pub ranges: Option<Vec<DVec2>>,
    /// `trimCurve:points`: homogeneous `(u w, v w, w)`.
    pub points: Option<Vec<DVec3>>,
}

/// What [`nurbs_patches`] adds to a file's tally: patches made so far, so that one file
/// cannot make more than a scene holds.
pub struct Budget {
    /// Bézier patches made by the file's earlier prims.
    pub patches: usize,
    /// Trim segments made by the file's earlier prims.
    pub trim_segments: usize,
}

/// The attribute `name`, or an error saying it is missing.
fn required<T: Clone>(value: &Option<T>, name: &str) -> Result<T, String> {
    value.clone().ok_or_else(|| format!("'{name}' is not authored"))
}

/// A count or order that must lie in `range`, as `usize`.
fn count(value: i64, name: &str, range: std::ops::RangeInclusive<usize>) -> Result<usize, String> {
    usize::try_from(value)
        .ok()
        .filter(|v| range.contains(v))
        .ok_or_else(|| {
            format!(
                "'{name}' is {value}; expected {} to {}",
                range.start(),
                range.end()
            )
        })
}

/// The degree of an order, 1 to 3, or an error naming the attribute.
fn degree(order: i64, name: &str) -> Result<usize, String> {
    match order {
        2..=4 => Ok(order as usize - 1),
        _ => Err(format!(
            "'{name}' is {order} (degree {}); surfaces and trim curves of order 2 to 4 (degree 1 to {DEGREE}) are read",
            order - 1
        )),
    }
}

/// The checked knots along one axis: `vertices + order` values.
fn axis_knots(f: &NurbsFields, k: usize) -> Result<(Knots, usize), String> {
    let (axis, prefix) = if k == 0 { ('u', "u") } else { ('v', "v") };
    let n = count(
        required(&f.vertex_counts[k], &format!("{prefix}VertexCount"))?,
        &format!("{prefix}VertexCount"),
        1..=MAX_KNOTS,
    )?;
    let order = required(&f.orders[k], &format!("{prefix}Order"))?;
    let p = degree(order, &format!("{prefix}Order"))?;
    let values = required(&f.knots[k], &format!("{prefix}Knots"))?;
    if values.len() != n + p + 1 {
        return Err(format!(
            "'{prefix}Knots' has {} values; {prefix}VertexCount {n} and {prefix}Order {order} need {}",
            values.len(),
            n + p + 1
        ));
    }
    let knots = Knots::of_degree(values, n, axis, p).map_err(|e| format!("'{prefix}Knots': {e}"))?;
    Ok((knots, n))
}

/// The checked `pointWeights` of a surface of `n` points (`None` when unauthored).
fn point_weights(f: &NurbsFields, n: usize) -> Result<Option<Vec<f64>>, String> {
    let Some(w) = &f.weights else {
        return Ok(None);
    };
    if w.len() != n {
        return Err(format!("'pointWeights' has {} weights for {n} points", w.len()));
    }
    if let Some((i, x)) = w.iter().enumerate().find(|(_, x)| !(x.is_finite() && **x > 0.0)) {
        return Err(format!(
            "'pointWeights[{i}]' is {x}: a rational surface's weights must be above 0"
        ));
    }
    Ok(Some(w.clone()))
}

/// The Bézier patches of one `NurbsPatch` prim (in its own space; the caller places them),
/// sharing its net and trim region. `budget` counts what the file made before.
pub fn nurbs_patches(f: &NurbsFields, budget: &mut Budget) -> Result<Vec<DomainPatch>, String> {
    let (u_knots, nu) = axis_knots(f, 0)?;
    let (v_knots, nv) = axis_knots(f, 1)?;
    let points = required(&f.points, "points")?;
    if points.len() != nu * nv {
        return Err(format!(
            "'points' has {} points; uVertexCount × vVertexCount is {nu} × {nv} = {}",
            points.len(),
            nu * nv
        ));
    }
    if let Some(p) = points.iter().find(|p| !p.is_finite()) {
        return Err(format!("'points' holds {p}, which is not finite"));
    }
    let weights = point_weights(f, points.len())?;
    let range = |k: usize, knots: &Knots| -> Result<(f64, f64), String> {
        let (lo, hi) = f.ranges[k].map_or(knots.domain(), |r| (r.x, r.y));
        let axis = if k == 0 { 'u' } else { 'v' };
        knots
            .check_range(lo, hi, axis)
            .map_err(|e| format!("'{axis}Range': {e}"))?;
        Ok((lo, hi))
    };
    let (u0, u1) = range(0, &u_knots)?;
    let (v0, v1) = range(1, &v_knots)?;
    let spans = u_knots.spans_in(u0, u1) * v_knots.spans_in(v0, v1);
    if budget.patches + spans > MAX_PATCHES {
        return Err(format!(
            "the surface makes {spans} Bézier patches, and the file {} before it; a scene holds at most {MAX_PATCHES}",
            budget.patches
        ));
    }
    budget.patches += spans;
    let surface = BsplineSurface {
        points,
        u_knots,
        v_knots,
        range: Window { u0, u1, v0, v1 },
    };
    let size = DVec2::new(u1 - u0, v1 - v0).length();
    let trim = trim_region(&f.trim, size, budget)?.map(Arc::new);
    net_pieces(SurfaceNet { surface, weights }, trim).map_err(str::to_owned)
}

/// The trim loops of `t` (none when `trimCurve:counts` is unauthored or empty), over a
/// surface whose parameter range's diagonal is `size`.
fn trim_region(t: &TrimFields, size: f64, budget: &mut Budget) -> Result<Option<TrimRegion>, String> {
    let counts = match &t.counts {
        Some(c) if !c.is_empty() => c,
        _ => return Ok(None),
    };
    let mut curves = 0usize;
    for (i, &c) in counts.iter().enumerate() {
        curves += count(c, &format!("trimCurve:counts[{i}]"), 1..=MAX_KNOTS)?;
    }
    let segments_of_curve = trim_curves(t, curves, budget)?;
    let mut loops = Vec::with_capacity(counts.len());
    let mut first = 0usize;
    for (l, &c) in counts.iter().enumerate() {
        let parts = &segments_of_curve[first..first + c as usize];
        first += c as usize;
        loops.push(TrimLoop {
            segments: joined(parts, size).map_err(|why| format!("trim loop {l} {why}"))?,
            hole: false,
        });
    }
    mark_holes(&mut loops);
    Ok(Some(TrimRegion::new(loops)))
}

/// The segments of each of the `curves` trim curves of `t`, checked against the arrays.
fn trim_curves(t: &TrimFields, curves: usize, budget: &mut Budget) -> Result<Vec<Vec<TrimSegment>>, String> {
    let orders = required(&t.orders, "trimCurve:orders")?;
    let vertex_counts = required(&t.vertex_counts, "trimCurve:vertexCounts")?;
    let knots = required(&t.knots, "trimCurve:knots")?;
    let ranges = required(&t.ranges, "trimCurve:ranges")?;
    let points = required(&t.points, "trimCurve:points")?;
    for (name, len) in [
        ("trimCurve:orders", orders.len()),
        ("trimCurve:vertexCounts", vertex_counts.len()),
        ("trimCurve:ranges", ranges.len()),
    ] {
        if len != curves {
            return Err(format!(
                "'{name}' has {len} entries; 'trimCurve:counts' makes {curves} curves"
            ));
        }
    }
    let mut out = Vec::with_capacity(curves);
    let (mut next_point, mut next_knot) = (0usize, 0usize);
    for c in 0..curves {
        let p = degree(orders[c], &format!("trimCurve:orders[{c}]"))?;
        let n = count(
            vertex_counts[c],
            &format!("trimCurve:vertexCounts[{c}]"),
            p + 1..=MAX_KNOTS,
        )?;
        let (Some(pts), Some(ks)) = (
            points.get(next_point..next_point + n),
            knots.get(next_knot..next_knot + n + p + 1),
        ) else {
            return Err(format!(
                "trim curve {c} needs {n} points and {} knots beyond the {next_point} and {next_knot} before it; 'trimCurve:points' has {} and 'trimCurve:knots' {}",
                n + p + 1,
                points.len(),
                knots.len()
            ));
        };
        (next_point, next_knot) = (next_point + n, next_knot + n + p + 1);
        let segments =
            curve_segments(pts, (ks, p), ranges[c]).map_err(|why| format!("trim curve {c}: {why}"))?;
        budget.trim_segments += segments.len();
        if budget.trim_segments > MAX_TRIM_SEGMENTS {
            return Err(format!(
                "the file's trim curves make more than {MAX_TRIM_SEGMENTS} segments"
            ));
        }
        out.push(segments);
    }
    if next_point != points.len() || next_knot != knots.len() {
        return Err(format!(
            "the trim curves use {next_point} of the {} 'trimCurve:points' and {next_knot} of the {} 'trimCurve:knots'",
            points.len(),
            knots.len()
        ));
    }
    Ok(out)
}

/// One trim curve's cubic segments over `range`: its homogeneous points and its knots of
/// degree `p`.
fn curve_segments(
    points: &[DVec3],
    (knots, p): (&[f64], usize),
    range: DVec2,
) -> Result<Vec<TrimSegment>, String> {
    if let Some(q) = points.iter().find(|q| !(q.is_finite() && q.z > 0.0)) {
        return Err(format!("the point {q} must be finite with a weight above 0"));
    }
    let knots = Knots::of_degree(knots.to_vec(), points.len(), 'u', p).map_err(|e| e.to_string())?;
    knots
        .check_range(range.x, range.y, 'u')
        .map_err(|e| format!("its range: {e}"))?;
    let segments: Vec<TrimSegment> = bezier_segments(points, &knots, range.x, range.y)
        .into_iter()
        .map(|(s, _)| s)
        .collect();
    if !segments.iter().flatten().all(|q| q.is_finite() && q.z > 0.0) {
        return Err("its points are too large to convert (the result is not finite)".into());
    }
    Ok(segments)
}

/// A loop's curves end to end, each starting where the one before ends and the last ending
/// at the first's start (up to the gap [`closes`] allows on a surface of diagonal `size`).
fn joined(parts: &[Vec<TrimSegment>], size: f64) -> Result<Vec<TrimSegment>, String> {
    let mut segments: Vec<TrimSegment> = Vec::new();
    for part in parts {
        if let (Some(last), Some(first)) = (segments.last(), part.first()) {
            let gap = project(last[3]).distance(project(first[0]));
            if !closes(gap, size) {
                return Err(format!(
                    "has a curve that does not start where the one before it ends (a gap of {gap:e} in (u,v))"
                ));
            }
        }
        segments.extend_from_slice(part);
    }
    if let (Some(last), Some(first)) = (segments.last(), segments.first()) {
        let gap = project(last[3]).distance(project(first[0]));
        if !closes(gap, size) {
            return Err(format!("is not closed (it ends {gap:e} in (u,v) from its start)"));
        }
    }
    Ok(segments)
}

/// Marks as holes the loops that lie inside an odd number of the others (each judged by its
/// first point; trim loops do not cross).
fn mark_holes(loops: &mut [TrimLoop]) {
    let alone: Vec<TrimRegion> = loops.iter().map(|l| TrimRegion::new(vec![l.clone()])).collect();
    let depth: Vec<usize> = loops
        .iter()
        .enumerate()
        .map(|(i, l)| {
            let p = project(l.segments[0][0]);
            alone
                .iter()
                .enumerate()
                .filter(|(j, r)| *j != i && r.contains(p))
                .count()
        })
        .collect();
    for (l, d) in loops.iter_mut().zip(depth) {
        l.hole = d % 2 == 1;
    }
}

/// How many loops lie inside a hole (islands), which the kept region (inside an outer loop
/// and inside no hole) cuts away with the hole.
pub fn islands(region: &TrimRegion) -> usize {
    let loops = region.loops();
    loops
        .iter()
        .filter(|l| !l.hole)
        .filter(|l| {
            let p = project(l.segments[0][0]);
            loops.iter().filter(|h| h.hole).any(|h| {
                TrimRegion::new(vec![TrimLoop {
                    hole: false,
                    ..h.clone()
                }])
                .contains(p)
            })
        })
        .count()
}
