//! The trim curves of Wavefront OBJ free-form surfaces: `vp` parameter points, `curv2` curves
//! in a surface's `(u,v)` (Bézier or B-spline, rational or not, degree 1 to 3; Rhino writes
//! degree 1 for "trims as polylines"), and a surface's `trim` (outer) and `hole` (inner)
//! loops, each a list of `u0 u1 curv2` pieces: the curve's part from parameter `u0` to `u1`
//! (reversed when `u0 > u1`). Curves are referenced by number among the file's `curv2`s
//! (1-based; a negative number counts back from the last one before the statement) and may
//! come before or after the surface; they are resolved at the end of the file into a
//! [`TrimRegion`] shared by the surface's patches.

use std::ops::Range;
use std::sync::Arc;

use glam::DVec3;

use super::bspline::{bezier_segments, Knots, DEGREE};
use super::trim::{project, TrimLoop, TrimRegion, TrimSegment};
use crate::settings::limits::MAX_KNOTS;

/// How many trim segments a file may make in all (each curve's Bézier spans, over every
/// loop that uses it): beyond, the file is refused rather than read into memory.
pub const MAX_TRIM_SEGMENTS: usize = 1_000_000;

/// A gap between one trim curve's end and the next one's start larger than this share of the
/// surface's parameter range is an error; smaller gaps (rounding in the file) are closed with
/// a straight segment.
const GAP_TOLERANCE: f64 = 1e-3;

/// Whether a gap of `gap` between trim curves on a surface whose parameter range's diagonal
/// is `size` is small enough to close with a line (false for a gap that is not a number).
pub fn closes(gap: f64, size: f64) -> bool {
    gap <= GAP_TOLERANCE * size
}

/// Each trimmed surface's patches (a range of the reader's list) and its region.
pub type SurfaceTrims = Vec<(Range<usize>, Arc<TrimRegion>)>;

/// A `curv2` curve, read.
struct Curve2 {
    /// Homogeneous control points `(u w, v w, w)`.
    points: Vec<DVec3>,
    knots: Knots,
    line: usize,
}

/// A `curv2` being read, until its `end`.
struct OpenCurve {
    line: usize,
    points: Vec<DVec3>,
    bezier: bool,
    degree: usize,
    parm: Option<(Vec<f64>, usize)>,
}

/// One `u0 u1 curv2` piece of a loop, its curve not yet resolved.
struct Piece {
    range: (f64, f64),
    /// 0-based index among the file's curves.
    curve: usize,
}

/// A `trim` or `hole` statement.
struct PendingLoop {
    line: usize,
    hole: bool,
    pieces: Vec<Piece>,
}

/// A surface's loops, with the patches it became and its parameter range's diagonal.
struct PendingSurface {
    patches: Range<usize>,
    size: f64,
    loops: Vec<PendingLoop>,
}

/// An error: the line it stands on and what was wrong.
pub type LineError = (usize, String);

/// What the reader keeps of trim curves while it reads a file.
#[derive(Default)]
pub struct TrimReader {
    /// `vp` points `(u, v, w)`.
    params: Vec<DVec3>,
    curves: Vec<Curve2>,
    open: Option<OpenCurve>,
    /// The open surface's loops so far.
    loops: Vec<PendingLoop>,
    surfaces: Vec<PendingSurface>,
}

impl TrimReader {
    /// A `vp u v [w]` line.
    pub fn vp(&mut self, line: usize, n: &[f64]) -> Result<(), LineError> {
        if !(2..=3).contains(&n.len()) {
            return Err((
                line,
                format!("'vp' takes 2 or 3 numbers 'u v [w]', found {}", n.len()),
            ));
        }
        self.params
            .push(DVec3::new(n[0], n[1], n.get(2).copied().unwrap_or(1.0)));
        Ok(())
    }

    /// Whether a `curv2` is open (its `parm` and `end` are the reader's).
    pub fn curve_open(&self) -> bool {
        self.open.is_some()
    }

    /// A `curv2 vp1 vp2 …` line, its type (`bezier`, whether rational) and degree from the
    /// `cstype` and `deg` lines before it.
    pub fn open_curve(
        &mut self,
        line: usize,
        args: &[&str],
        (name, rational): (&str, bool),
        degree: &[String],
    ) -> Result<(), LineError> {
        let bezier = match name {
            "bezier" => true,
            "bspline" => false,
            other => {
                return Err((
                    line,
                    format!(
                        "'cstype {other}' is not supported for a trim curve; only 'bezier' and 'bspline'"
                    ),
                ))
            }
        };
        let degree = match degree {
            [d] => match d.parse::<usize>() {
                Ok(n @ 1..=DEGREE) => n,
                _ => return Err((line, format!("a trim curve's 'deg' is 1, 2 or 3, not '{d}'"))),
            },
            _ => {
                return Err((
                    line,
                    format!(
                        "a trim curve needs one degree ('deg 1' to 'deg 3'), found 'deg {}'",
                        degree.join(" ")
                    ),
                ))
            }
        };
        let mut points = Vec::with_capacity(args.len().min(MAX_KNOTS));
        for a in args {
            let index: i64 = a
                .parse()
                .map_err(|_| (line, format!("'curv2': '{a}' is not a 'vp' index")))?;
            let count = self.params.len() as i64;
            let resolved = if index < 0 { count + index } else { index - 1 };
            if index == 0 || !(0..count).contains(&resolved) {
                return Err((
                    line,
                    format!("'curv2': 'vp' index {index} is out of range ({count} points 'vp' so far)"),
                ));
            }
            let p = self.params[resolved as usize];
            if !(p.z.is_finite() && p.z > 0.0) || (!rational && p.z != 1.0) {
                return Err((
                    line,
                    if rational {
                        format!("'curv2': point {index} has weight {}: a rational trim curve's weights must be above 0", p.z)
                    } else {
                        format!("'curv2': point {index} has weight {}, but the curve is not rational (use 'cstype rat {name}')", p.z)
                    },
                ));
            }
            points.push(DVec3::new(p.x * p.z, p.y * p.z, p.z));
        }
        if points.len() > MAX_KNOTS {
            return Err((
                line,
                format!(
                    "'curv2' lists {} points; at most {MAX_KNOTS} are read",
                    points.len()
                ),
            ));
        }
        self.open = Some(OpenCurve {
            line,
            points,
            bezier,
            degree,
            parm: None,
        });
        Ok(())
    }

    /// The open curve's `parm u …` line.
    pub fn parm(&mut self, line: usize, axis: &str, values: Vec<f64>) -> Result<(), LineError> {
        let Some(open) = self.open.as_mut() else {
            return Ok(());
        };
        if axis != "u" {
            return Err((line, format!("a trim curve's 'parm' is along 'u', not '{axis}'")));
        }
        open.parm = Some((values, line));
        Ok(())
    }

    /// The open curve's `end`: its knots are checked against its points.
    pub fn close_curve(&mut self, line: usize) -> Result<(), LineError> {
        let Some(open) = self.open.take() else {
            return Ok(());
        };
        let (values, pline) = open.parm.ok_or_else(|| {
            (
                line,
                format!("the trim curve on line {} has no 'parm u' line", open.line),
            )
        })?;
        let values = if open.bezier {
            if values.len() < 2 || values.windows(2).any(|w| w[1] <= w[0]) {
                return Err((
                    pline,
                    "a Bézier trim curve's 'parm u' needs two or more increasing breakpoints".to_owned(),
                ));
            }
            Knots::from_breakpoints(&values, open.degree)
        } else {
            values
        };
        let knots = Knots::of_degree(values, open.points.len(), 'u', open.degree)
            .map_err(|e| (pline, format!("trim curve on line {}: {e}", open.line)))?;
        self.curves.push(Curve2 {
            points: open.points,
            knots,
            line: open.line,
        });
        Ok(())
    }

    /// A `trim` or `hole` line of the open surface: `u0 u1 curv2` triples.
    pub fn add_loop(&mut self, line: usize, hole: bool, n: &[f64]) -> Result<(), LineError> {
        let keyword = if hole { "hole" } else { "trim" };
        if n.is_empty() || !n.len().is_multiple_of(3) {
            return Err((
                line,
                format!(
                    "'{keyword}' takes 'u0 u1 curv2' triples, found {} numbers",
                    n.len()
                ),
            ));
        }
        let mut pieces = Vec::with_capacity(n.len() / 3);
        for c in n.chunks(3) {
            let index = c[2];
            let count = self.curves.len() as f64;
            let resolved = if index < 0.0 { count + index } else { index - 1.0 };
            if index.fract() != 0.0 || index == 0.0 || resolved < 0.0 || resolved >= MAX_KNOTS as f64 {
                return Err((line, format!("'{keyword}': '{index}' is not a curve number")));
            }
            if c[0] == c[1] {
                return Err((
                    line,
                    format!(
                        "'{keyword}': the curve {index}'s range {} to {} is empty",
                        c[0], c[1]
                    ),
                ));
            }
            pieces.push(Piece {
                range: (c[0], c[1]),
                curve: resolved as usize,
            });
        }
        self.loops.push(PendingLoop { line, hole, pieces });
        Ok(())
    }

    /// The open surface ended as `patches` of the reader's list, over a parameter range whose
    /// diagonal is `size`: its loops are kept for the end of the file.
    pub fn close_surface(&mut self, patches: Range<usize>, size: f64) {
        let loops = std::mem::take(&mut self.loops);
        if !loops.is_empty() {
            self.surfaces.push(PendingSurface { patches, size, loops });
        }
    }

    /// At the end of the file: each trimmed surface's region and the patches it belongs to.
    pub fn finish(self) -> Result<SurfaceTrims, LineError> {
        if let Some(open) = &self.open {
            return Err((open.line, "the trim curve has no 'end' statement".to_owned()));
        }
        let mut total = 0usize;
        let mut out = Vec::with_capacity(self.surfaces.len());
        for surface in &self.surfaces {
            let mut loops = Vec::with_capacity(surface.loops.len());
            for l in &surface.loops {
                let segments = self.loop_segments(l, surface.size, &mut total)?;
                loops.push(TrimLoop {
                    segments,
                    hole: l.hole,
                });
            }
            out.push((surface.patches.clone(), Arc::new(TrimRegion::new(loops))));
        }
        Ok(out)
    }

    /// The segments of one piece of a loop (the loop's `line` and `keyword` for errors), in
    /// the loop's direction.
    fn piece_segments(
        &self,
        piece: &Piece,
        (line, keyword): (usize, &str),
    ) -> Result<Vec<TrimSegment>, LineError> {
        let curve = self.curves.get(piece.curve).ok_or_else(|| {
            (
                line,
                format!(
                    "'{keyword}': curve {} is not in the file ({} 'curv2' curves)",
                    piece.curve + 1,
                    self.curves.len()
                ),
            )
        })?;
        let (a, b) = piece.range;
        let (start, end) = (a.min(b), a.max(b));
        curve.knots.check_range(start, end, 'u').map_err(|e| {
            (
                line,
                format!(
                    "'{keyword}': curve {} (line {}): {e}",
                    piece.curve + 1,
                    curve.line
                ),
            )
        })?;
        let mut part: Vec<TrimSegment> = bezier_segments(&curve.points, &curve.knots, start, end)
            .into_iter()
            .map(|(s, _)| s)
            .collect();
        if a > b {
            part.reverse();
            for s in &mut part {
                s.reverse();
            }
        }
        Ok(part)
    }

    /// The segments of one loop, its pieces end to end; `total` counts segments made so far.
    fn loop_segments(
        &self,
        l: &PendingLoop,
        size: f64,
        total: &mut usize,
    ) -> Result<Vec<TrimSegment>, LineError> {
        let keyword = if l.hole { "hole" } else { "trim" };
        let mut segments: Vec<TrimSegment> = Vec::new();
        for piece in &l.pieces {
            let part = self.piece_segments(piece, (l.line, keyword))?;
            *total += part.len();
            if *total > MAX_TRIM_SEGMENTS {
                return Err((
                    l.line,
                    format!("the file's trim curves make more than {MAX_TRIM_SEGMENTS} segments"),
                ));
            }
            if let (Some(last), Some(first)) = (segments.last(), part.first()) {
                let gap = project(last[3]).distance(project(first[0]));
                if !closes(gap, size) {
                    return Err((
                        l.line,
                        format!(
                            "'{keyword}': curve {} does not start where the loop's previous curve ends (a gap of {gap:e} in (u,v))",
                            piece.curve + 1
                        ),
                    ));
                }
            }
            segments.extend(part);
        }
        let all_finite = segments.iter().flatten().all(|p| p.is_finite() && p.z > 0.0);
        if !all_finite {
            return Err((
                l.line,
                format!(
                    "'{keyword}': its curves' points are too large to convert (the result is not finite)"
                ),
            ));
        }
        if let (Some(last), Some(first)) = (segments.last(), segments.first()) {
            let gap = project(last[3]).distance(project(first[0]));
            if !closes(gap, size) {
                return Err((
                    l.line,
                    format!("'{keyword}': the loop is not closed (it ends {gap:e} in (u,v) from its start)"),
                ));
            }
        }
        Ok(segments)
    }
}
