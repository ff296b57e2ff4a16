//! Non-rational B-spline surfaces of degree 1 to 3 turned into bicubic Bézier patches by knot
//! insertion (and, below degree 3, exact degree elevation of each segment:
//! [`super::elevate`]).
//!
//! Boehm's algorithm (W. Boehm, "Inserting new knots into B-spline curves", CAD 12(4), 1980)
//! inserts a knot without changing the curve. Inserting every distinct knot of the domain until
//! its multiplicity is the degree makes the control polygon of each knot span the Bézier
//! control polygon of that span. Done one insertion at a time, each shifting the whole vector,
//! that costs time quadratic in the knots; instead the range's two ends are inserted (a
//! constant number of insertions), the curve outside the range dropped, and the clamped curve
//! left is decomposed span by span as Piegl & Tiller's algorithm A5.6 (*The NURBS Book*, §5.6,
//! "DecomposeCurve") does, which touches each control point a bounded number of times: linear
//! in the knots. A surface is a tensor product: its rows are converted along `u`, then the
//! resulting columns along `v`.
//!
//! [`de_boor`] evaluates a curve directly (de Boor 1972): the tests check the conversion
//! against it.

use glam::{DVec3, DVec4};

use super::bezier::BezierPatch;
use super::elevate::to_cubic;
pub use super::elevate::Lerp;
use super::patch::Window;
use super::rational::Weights;

/// The degree of the patches made here: bicubic (lower degrees are raised to it).
pub const DEGREE: usize = 3;

/// Why a B-spline could not be converted. The messages name the knots and counts concerned;
/// the caller adds the file and line.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum BsplineError {
    /// The knot vector's length does not match the control points (`points + degree + 1`
    /// knots).
    #[error("{points} control points along {axis} need {} knots, the 'parm {axis}' line gives {knots}", points + degree + 1)]
    KnotCount {
        /// `u` or `v`.
        axis: char,
        /// Control points along the axis.
        points: usize,
        /// The degree along the axis.
        degree: usize,
        /// Knots given.
        knots: usize,
    },
    /// Too few control points for the degree.
    #[error("a curve of degree {degree} needs at least {} control points along {axis}, found {points}", degree + 1)]
    TooFewPoints {
        /// `u` or `v`.
        axis: char,
        /// The degree along the axis.
        degree: usize,
        /// Control points along the axis.
        points: usize,
    },
    /// A knot smaller than the one before it, or not finite.
    #[error(
        "the knots along {axis} must be finite and non-decreasing: knot {index} is {value} after {previous}"
    )]
    Decreasing {
        /// `u` or `v`.
        axis: char,
        /// 1-based position of the offending knot.
        index: usize,
        /// Its value.
        value: f64,
        /// The knot before it.
        previous: f64,
    },
    /// The parameter range is empty or reaches outside the knots' valid domain.
    #[error("the parameter range [{start}, {end}] along {axis} must be non-empty and within the knots' domain [{low}, {high}]")]
    Range {
        /// `u` or `v`.
        axis: char,
        /// Range start.
        start: f64,
        /// Range end.
        end: f64,
        /// The domain's start (knot `degree + 1`).
        low: f64,
        /// The domain's end (knot `points + 1`).
        high: f64,
    },
}

/// A B-spline curve's knots along one axis and its degree, checked against its control point
/// count.
#[derive(Clone, Debug, PartialEq)]
pub struct Knots {
    values: Vec<f64>,
    degree: usize,
}

impl Knots {
    /// Checks `values` for a cubic of `points` control points along `axis` (for messages).
    pub fn new(values: Vec<f64>, points: usize, axis: char) -> Result<Knots, BsplineError> {
        Self::of_degree(values, points, axis, DEGREE)
    }

    /// Checks `values` for a curve of `degree` (1 to 3) with `points` control points along
    /// `axis`.
    pub fn of_degree(
        values: Vec<f64>,
        points: usize,
        axis: char,
        degree: usize,
    ) -> Result<Knots, BsplineError> {
        assert!(
            (1..=DEGREE).contains(&degree),
            "degree {degree}: the caller checks 1 to 3"
        );
        if points < degree + 1 {
            return Err(BsplineError::TooFewPoints { axis, degree, points });
        }
        if values.len() != points + degree + 1 {
            return Err(BsplineError::KnotCount {
                axis,
                points,
                degree,
                knots: values.len(),
            });
        }
        for (i, pair) in values.windows(2).enumerate() {
            let ordered = pair[0].is_finite() && pair[1].is_finite() && pair[1] >= pair[0];
            if !ordered {
                return Err(BsplineError::Decreasing {
                    axis,
                    index: i + 2,
                    value: pair[1],
                    previous: pair[0],
                });
            }
        }
        Ok(Knots { values, degree })
    }

    /// The knots of a piecewise Bézier curve of `degree` with `breakpoints` (each segment's
    /// ends): every inner breakpoint `degree` times, the ends once more.
    pub fn from_breakpoints(breakpoints: &[f64], degree: usize) -> Vec<f64> {
        let mut values = Vec::with_capacity(degree * breakpoints.len() + 2);
        for (k, b) in breakpoints.iter().enumerate() {
            let copies = if k == 0 || k + 1 == breakpoints.len() {
                degree + 1
            } else {
                degree
            };
            values.extend(std::iter::repeat_n(*b, copies));
        }
        values
    }

    /// The knot values.
    pub fn values(&self) -> &[f64] {
        &self.values
    }

    /// The degree of the curve.
    pub fn degree(&self) -> usize {
        self.degree
    }

    /// The valid parameter domain `[t_p, t_n]` (0-based knots, degree `p`, `n` control points).
    pub fn domain(&self) -> (f64, f64) {
        let n = self.values.len() - self.degree - 1;
        (self.values[self.degree], self.values[n])
    }

    /// How many Bézier spans the range `[start, end]` holds: one more than its distinct knots
    /// strictly inside it.
    pub fn spans_in(&self, start: f64, end: f64) -> usize {
        let mut inside: Vec<f64> = self
            .values
            .iter()
            .copied()
            .filter(|&t| t > start && t < end)
            .collect();
        inside.dedup();
        inside.len() + 1
    }

    /// Checks that `[start, end]` is a non-empty part of the domain.
    pub fn check_range(&self, start: f64, end: f64, axis: char) -> Result<(), BsplineError> {
        let (low, high) = self.domain();
        if start < end && start >= low && end <= high {
            Ok(())
        } else {
            Err(BsplineError::Range {
                axis,
                start,
                end,
                low,
                high,
            })
        }
    }
}

/// Inserts knot `t` (within the domain) once into the curve of degree `p` (`knots`, `points`)
/// (Boehm 1980); the curve is unchanged.
fn insert_knot<T: Lerp>(knots: &mut Vec<f64>, points: &mut Vec<T>, t: f64, p: usize) {
    // The span k in [p, n] with knots[k] <= t <= knots[k + 1] (the last such span for a
    // repeated knot; at the domain's end, the last span).
    let n = points.len() - 1;
    let k = knots.iter().rposition(|&u| u <= t).unwrap_or(p).clamp(p, n);
    let mut out = Vec::with_capacity(points.len() + 1);
    for i in 0..=points.len() {
        let q = if i + p <= k {
            points[i]
        } else if i > k {
            points[i - 1]
        } else {
            let span = knots[i + p] - knots[i];
            let a = if span > 0.0 { (t - knots[i]) / span } else { 0.0 };
            points[i - 1].lerp_to(points[i], a)
        };
        out.push(q);
    }
    knots.insert(k + 1, t);
    *points = out;
}

/// How often `t` occurs in `knots`.
fn multiplicity(knots: &[f64], t: f64) -> usize {
    knots.iter().filter(|&&u| u == t).count()
}

/// The curve of degree `p` (`knots`, `points`) over `[start, end]` (within its domain) as a
/// clamped curve: each end inserted to multiplicity `p` (at most `2p` insertions), then the
/// knots and points outside the range dropped, the ends given multiplicity `p + 1`.
fn clamped_to<T: Lerp>(
    knots: &[f64],
    points: &[T],
    (start, end): (f64, f64),
    p: usize,
) -> (Vec<f64>, Vec<T>) {
    let (mut u, mut q) = (knots.to_vec(), points.to_vec());
    for t in [start, end] {
        while multiplicity(&u, t) < p {
            insert_knot(&mut u, &mut q, t, p);
        }
    }
    // With `start` at knots first..=last (multiplicity ≥ p), the curve from `start` on has the
    // points from last - p; symmetrically up to `end`.
    let last_start = u.iter().rposition(|&x| x == start).unwrap_or(p);
    let first_end = u.iter().position(|&x| x == end).unwrap_or(u.len() - p - 1);
    let first_point = last_start.saturating_sub(p);
    let last_point = first_end.saturating_sub(1).min(q.len() - 1);
    let mut knots = vec![start; p + 1];
    knots.extend_from_slice(&u[last_start + 1..first_end]);
    knots.extend(std::iter::repeat_n(end, p + 1));
    (knots, q[first_point..=last_point].to_vec())
}

/// The Bézier segments of a clamped curve of degree `p` (its first and last `p + 1` knots
/// equal), each `p + 1` points and its interval: Piegl & Tiller's algorithm A5.6, which raises
/// each interior knot to multiplicity `p` within a window of `p + 1` points as it walks the
/// knots once. Interior knots of multiplicity above `p` (a break in the curve) start a new
/// segment from the points after them.
fn decompose<T: Lerp>(u: &[f64], points: &[T], p: usize) -> Vec<(Vec<T>, (f64, f64))> {
    let m = u.len() - 1;
    let mut out = Vec::new();
    let mut q: Vec<T> = points[..=p].to_vec();
    let mut next = q.clone();
    let (mut a, mut b) = (p, p + 1);
    while b < m {
        let i = b;
        while b < m && u[b + 1] == u[b] {
            b += 1;
        }
        let mult = (b - i + 1).min(p);
        if mult < p {
            // Insert u[b] (p - mult) times into the window q.
            let numer = u[b] - u[a];
            let r = p - mult;
            let alphas: Vec<f64> = (0..r).map(|j| numer / (u[a + mult + 1 + j] - u[a])).collect();
            for j in 1..=r {
                let s = mult + j;
                for k in (s..=p).rev() {
                    q[k] = q[k - 1].lerp_to(q[k], alphas[k - s]);
                }
                if b < m {
                    // The new segment's first points come out of this one's last.
                    next[r - j] = q[p];
                }
            }
        }
        out.push((q.clone(), (u[a], u[b])));
        if b < m {
            for k in (p - mult)..=p {
                next[k] = points[b - p + k];
            }
            q.clone_from(&next);
            a = b;
            b += 1;
        }
    }
    out
}

/// One Bézier segment of a curve: its four control points and its parameter interval.
pub type Segment<T> = ([T; 4], (f64, f64));

/// The cubic Bézier segments of the B-spline curve (`points`, `knots`) over `[start, end]`:
/// each segment's four control points (raised exactly to degree 3 where the curve's degree is
/// lower) and its parameter interval, in order.
pub fn bezier_segments<T: Lerp>(
    points: &[T],
    knots: &Knots,
    start: f64,
    end: f64,
) -> Vec<([T; 4], (f64, f64))> {
    let p = knots.degree;
    let (u, q) = clamped_to(&knots.values, points, (start, end), p);
    decompose(&u, &q, p)
        .into_iter()
        .map(|(segment, interval)| (to_cubic(&segment), interval))
        .collect()
}

/// A point of the B-spline curve (`points`, `knots`) at `t` in its domain, by de Boor's
/// algorithm.
pub fn de_boor(points: &[DVec3], knots: &Knots, t: f64) -> DVec3 {
    let (u, p) = (&knots.values, knots.degree);
    let n = points.len();
    // The non-empty span k in [p, n-1] with u[k] <= t (the last span at the domain's end).
    let k = (p..n).rev().find(|&k| u[k] <= t && u[k] < u[k + 1]).unwrap_or(p);
    let mut d: Vec<DVec3> = (0..=p).map(|j| points[j + k - p]).collect();
    for r in 1..=p {
        for j in (r..=p).rev() {
            let i = j + k - p;
            let a = (t - u[i]) / (u[i + p + 1 - r] - u[i]);
            d[j] = d[j - 1].lerp_to(d[j], a);
        }
    }
    d[p]
}

/// A B-spline surface of degree 1 to 3 along each axis: control points `points[i + nu * j]` (`i` along `u` varying
/// fastest, as Wavefront OBJ lists them), knots along `u` and `v`, and the parameter range
/// to convert.
#[derive(Clone, Debug, PartialEq)]
pub struct BsplineSurface {
    /// Control points, `u` fastest.
    pub points: Vec<DVec3>,
    /// Knots along `u` (`nu + degree + 1` values).
    pub u_knots: Knots,
    /// Knots along `v`.
    pub v_knots: Knots,
    /// The range `[u0, u1] × [v0, v1]` of the surface to convert.
    pub range: Window,
}

impl BsplineSurface {
    /// Control points along `u`.
    pub fn nu(&self) -> usize {
        self.u_knots.values.len() - self.u_knots.degree - 1
    }

    /// A point of the surface, by de Boor along `u` on every row, then along `v`.
    pub fn eval(&self, u: f64, v: f64) -> DVec3 {
        let column: Vec<DVec3> = self
            .points
            .chunks_exact(self.nu())
            .map(|row| de_boor(row, &self.u_knots, u))
            .collect();
        de_boor(&column, &self.v_knots, v)
    }

    /// The bicubic Bézier patches of the surface over its range, each with its `(u,v)` window in the
    /// surface's own parameters, ordered by `u` span, then `v` span.
    pub fn to_bezier(&self) -> Vec<(BezierPatch, Window)> {
        spans(&self.points, self)
            .into_iter()
            .map(|(points, window)| (BezierPatch::new(points), window))
            .collect()
    }

    /// [`BsplineSurface::to_bezier`] for a rational surface whose points have `weights`
    /// (positive, one per point): converted in homogeneous form (Piegl & Tiller §4.4), each
    /// patch with its projected control points and their weights.
    pub fn to_rational_bezier(&self, weights: &[f64]) -> Vec<(BezierPatch, Window, Weights)> {
        let homogeneous: Vec<DVec4> = self
            .points
            .iter()
            .zip(weights)
            .map(|(p, &w)| (*p * w).extend(w))
            .collect();
        spans(&homogeneous, self)
            .into_iter()
            .map(|(h, window)| {
                let points = h.map(|q| q.truncate() / q.w);
                (BezierPatch::new(points), window, h.map(|q| q.w))
            })
            .collect()
    }
}

/// `surface`'s Bézier patches as 16 points each (row `i` along `u`), with their windows, for
/// its control points given as `points` (any [`Lerp`] type, `u` fastest).
fn spans<T: Lerp>(points: &[T], surface: &BsplineSurface) -> Vec<([T; 16], Window)> {
    let nu = surface.nu();
    let r = surface.range;
    // Along u for every row of constant v: rows[j] = segments of row j.
    let rows: Vec<Vec<Segment<T>>> = points
        .chunks_exact(nu)
        .map(|row| bezier_segments(row, &surface.u_knots, r.u0, r.u1))
        .collect();
    let u_spans = rows.first().map_or(0, Vec::len);
    let mut out = Vec::with_capacity(u_spans * surface.v_knots.spans_in(r.v0, r.v1));
    for su in 0..u_spans {
        // The column of 4-point groups along v for this u span, converted along v.
        let column: Vec<[T; 4]> = rows.iter().map(|row| row[su].0).collect();
        let v_segments = bezier_segments(&column, &surface.v_knots, r.v0, r.v1);
        let (u0, u1) = rows[0][su].1;
        for (quad, (v0, v1)) in v_segments {
            // quad[jv][iu]: a patch wants points[4 * iu + jv].
            out.push((
                std::array::from_fn(|k| quad[k % 4][k / 4]),
                Window { u0, u1, v0, v1 },
            ));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A point of a cubic Bézier segment.
    fn bezier(q: &[DVec3; 4], t: f64) -> DVec3 {
        let s = 1.0 - t;
        q[0] * s * s * s + q[1] * 3.0 * s * s * t + q[2] * 3.0 * s * t * t + q[3] * t * t * t
    }

    #[test]
    fn segments_follow_the_curve_whatever_the_knots() {
        // Unclamped ends, interior knots of multiplicity 1 to 4 (a break), zero-length spans,
        // and ranges that start and end between knots or on them.
        let cases: [(&[f64], (f64, f64)); 5] = [
            (&[0., 1., 2., 3., 4., 5., 6., 7., 8., 9.], (3.0, 6.0)),
            (
                &[0., 0., 0., 0., 1., 1., 2., 3., 3., 3., 4., 4., 4., 4.],
                (0.0, 4.0),
            ),
            (
                &[0., 0., 0., 0., 1., 2., 2., 2., 2., 3., 4., 4., 4., 4.],
                (0.0, 4.0),
            ),
            (&[0., 1., 2., 3., 4., 4., 5., 6., 7., 8., 9.], (3.25, 5.75)),
            (&[0., 0., 0., 0., 0.5, 1., 1.5, 2., 2., 2., 2.], (0.5, 1.5)),
        ];
        for (values, (start, end)) in cases {
            let n = values.len() - 4;
            let points: Vec<DVec3> = (0..n)
                .map(|k| DVec3::new(k as f64, ((k * 7) % 5) as f64, ((k * 3) % 4) as f64))
                .collect();
            let knots = Knots::new(values.to_vec(), n, 'u').expect("valid");
            let segments = bezier_segments(&points, &knots, start, end);
            assert_eq!(segments.len(), knots.spans_in(start, end), "{values:?}");
            assert_eq!(segments.first().map(|s| s.1 .0), Some(start));
            assert_eq!(segments.last().map(|s| s.1 .1), Some(end));
            for (q, (a, b)) in &segments {
                for t in [0.1, 0.5, 0.9] {
                    let x = a + t * (b - a);
                    let expected = de_boor(&points, &knots, x);
                    let got = bezier(q, t);
                    assert!(
                        (got - expected).length() < 1e-9,
                        "{values:?} at {x}: {got} vs {expected}"
                    );
                }
            }
            for pair in segments.windows(2) {
                assert_eq!(pair[0].1 .1, pair[1].1 .0, "segments meet");
            }
        }
    }
}
