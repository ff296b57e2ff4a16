//! Wavefront OBJ free-form surfaces in and out: the `cstype [rat] bezier` and `cstype [rat]
//! bspline` surfaces of degree 1 to 3 along each axis that CAD programs (Rhino, for one)
//! export, read as bicubic Bézier patches (lower degrees raised exactly,
//! [`super::elevate`]; rational ones converted in homogeneous coordinates and kept with their
//! weights, [`super::rational`]) with their parameter windows, and patches written back as
//! `cstype [rat] bezier` surfaces.
//!
//! The statements read (Wavefront's *Object Files* appendix B1, "Free-form curve/surface
//! attributes" and "body statements"): `v x y z [w]`, `cstype [rat] bezier|bspline`,
//! `deg du dv`, `surf s0 s1 t0 t1 v1 v2 …` (control points with `u` varying fastest; negative
//! indices count back from the last `v`), `parm u …`, `parm v …` (a B-spline's knots, a Bézier
//! surface's breakpoints) and `end`; a line ending in `\` continues on the next. Polygons,
//! texture vertices, groups and materials are ignored, and so are free-form curves. A
//! B-spline surface is split into one Bézier patch per knot span by knot insertion
//! ([`super::bspline`]), each with its `(u,v)` window in the surface's own parameters, so
//! textures follow the original parameters.
//!
//! ```text
//! v 0 0 0
//! …                      (16 points)
//! cstype bezier
//! deg 3 3
//! surf 0 1 0 1 1 2 3 4 5 6 7 8 9 10 11 12 13 14 15 16
//! parm u 0 1
//! parm v 0 1
//! end
//! ```

use std::path::{Path, PathBuf};
use std::sync::Arc;

use glam::{DVec2, DVec3};

use super::bezier::BezierPatch;
use super::bspline::{BsplineSurface, Knots, DEGREE};
use super::freeform_trim::TrimReader;
use super::net::SurfaceNet;
use super::patch::Window;
use super::rational::{weights_error, Weights};
use super::trim::TrimRegion;
use crate::settings::limits::{MAX_KNOTS, MAX_PATCHES};

/// A free-form OBJ file that cannot be read: which file, which line, what was wrong.
#[derive(Debug, thiserror::Error)]
#[error("{}:{line}: {message}", path.display())]
pub struct FreeformError {
    /// The file (as given).
    pub path: PathBuf,
    /// 1-based line number (0 when the file is unreadable).
    pub line: usize,
    /// What was wrong.
    pub message: String,
}

/// A Bézier patch as a piece of the surface it came from.
#[derive(Clone, Debug, PartialEq)]
pub struct DomainPatch {
    /// Its control points (a rational patch's projected ones).
    pub patch: BezierPatch,
    /// Its `(u,v)` window in the parameters of the surface it came from.
    pub window: Window,
    /// Its weights, for a rational surface ([`super::rational`]).
    pub weights: Option<Weights>,
    /// The surface's trim loops, in the surface's `(u,v)`, shared by its patches
    /// ([`super::trim`]).
    pub trim: Option<Arc<TrimRegion>>,
    /// The B-spline or NURBS surface it was derived from, shared by its patches: what an
    /// editor moves ([`super::net`]).
    pub net: Option<Arc<SurfaceNet>>,
}

impl DomainPatch {
    /// A whole polynomial patch over `[0,1]²`, untrimmed.
    pub fn whole(patch: BezierPatch) -> Self {
        Self {
            patch,
            window: Window::FULL,
            weights: None,
            trim: None,
            net: None,
        }
    }
}

/// The Bézier patches of a B-spline or NURBS surface, each sharing the surface's net and
/// `trim`; an error when the knots or points are too large for them to be finite.
pub fn net_pieces(net: SurfaceNet, trim: Option<Arc<TrimRegion>>) -> Result<Vec<DomainPatch>, &'static str> {
    let net = Arc::new(net);
    let patches: Vec<DomainPatch> = net
        .patches()
        .into_iter()
        .map(|(patch, window, weights)| DomainPatch {
            patch,
            window,
            weights,
            trim: trim.clone(),
            net: Some(net.clone()),
        })
        .collect();
    let finite = |d: &DomainPatch| {
        let w = &d.window;
        d.patch.points.iter().all(|q| q.is_finite())
            && (w.u1 - w.u0).is_finite()
            && (w.v1 - w.v0).is_finite()
            && d.weights.as_ref().is_none_or(|w| weights_error(w).is_none())
    };
    if !patches.iter().all(finite) {
        return Err("the surface's knots or points are too large to convert (the result is not finite)");
    }
    Ok(patches)
}

/// `pieces` placed by `m`: a plain patch's points transformed; the patches of a surface with
/// its net derived again from the transformed net (an affine map commutes with knot insertion),
/// so that an edit of the placed net, which derives them the same way, changes only what it
/// moves.
pub fn place_pieces(pieces: Vec<DomainPatch>, m: &glam::DAffine3) -> Vec<DomainPatch> {
    type Derived = std::vec::IntoIter<(BezierPatch, Window, Option<Weights>)>;
    let mut current: Option<(Arc<SurfaceNet>, Arc<SurfaceNet>, Derived)> = None;
    let mut out = Vec::with_capacity(pieces.len());
    for piece in pieces {
        let derived = piece.net.as_ref().and_then(|source| {
            if !current.as_ref().is_some_and(|(s, _, _)| Arc::ptr_eq(s, source)) {
                let net = Arc::new(source.transformed(m));
                let patches = net.patches().into_iter();
                current = Some((source.clone(), net, patches));
            }
            let (_, net, patches) = current.as_mut()?;
            patches
                .next()
                .map(|(patch, window, weights)| (patch, window, weights, net.clone()))
        });
        out.push(match derived {
            Some((patch, window, weights, net)) => DomainPatch {
                patch,
                window,
                weights,
                net: Some(net),
                ..piece
            },
            None => DomainPatch {
                patch: piece.patch.transformed(m),
                net: None,
                ..piece
            },
        });
    }
    out
}

/// Reads every free-form surface (degree 1 to 3) of an OBJ file as bicubic Bézier patches, a
/// line at a time: what the reader keeps beyond the patches is the `v` points (40 bytes each),
/// the open surface's indices, each surface's own net (its points and weights, shared by its
/// patches) and the trim curves, whatever else the file holds.
pub fn load_freeform_obj(path: &Path) -> Result<Vec<DomainPatch>, FreeformError> {
    let file = crate::input_file::open(path).map_err(|why| FreeformError {
        path: path.to_owned(),
        line: 0,
        message: format!("the file {why}"),
    })?;
    read_freeform_obj(std::io::BufReader::new(file), path)
}

/// A `v` line: the point, its weight and the line it stands on.
struct Vertex {
    point: DVec3,
    weight: f64,
    line: usize,
}

/// The type set by the last `cstype`.
#[derive(Clone, Debug)]
struct CurveType {
    rational: bool,
    name: String,
    line: usize,
}

/// A `surf` being read, until its `end`.
struct OpenSurface {
    line: usize,
    range: Window,
    indices: Vec<usize>,
    parm_u: Option<(Vec<f64>, usize)>,
    parm_v: Option<(Vec<f64>, usize)>,
    cstype: Option<CurveType>,
    degree: Option<(Vec<String>, usize)>,
}

/// The logical lines of an OBJ file, one at a time: comments removed, `\` continuations
/// joined, each with the number of its first physical line. One line's buffers are reused for
/// the next, so reading costs the longest logical line, not the file.
struct LogicalLines<R> {
    reader: R,
    /// Physical lines read so far.
    physical: usize,
    raw: Vec<u8>,
    joined: String,
}

impl<R: std::io::BufRead> LogicalLines<R> {
    fn new(reader: R) -> Self {
        Self {
            reader,
            physical: 0,
            raw: Vec::new(),
            joined: String::new(),
        }
    }

    /// The next logical line and its first physical line's number; `Err` names the line that
    /// could not be read.
    fn next_line(&mut self) -> Result<Option<(usize, &str)>, (usize, String)> {
        self.joined.clear();
        let start = self.physical + 1;
        loop {
            self.raw.clear();
            let n = self
                .reader
                .read_until(b'\n', &mut self.raw)
                .map_err(|e| (self.physical + 1, format!("cannot read the file: {e}")))?;
            if n == 0 {
                // The end: a pending continuation is a line of its own.
                return Ok((!self.joined.is_empty()).then_some((start, self.joined.as_str())));
            }
            self.physical += 1;
            let text = std::str::from_utf8(&self.raw)
                .map_err(|_| (self.physical, "the line is not UTF-8 text".to_owned()))?;
            let line = text.split('#').next().unwrap_or("").trim_end();
            match line.strip_suffix('\\') {
                Some(head) => {
                    self.joined.push_str(head);
                    self.joined.push(' ');
                }
                None => {
                    self.joined.push_str(line);
                    return Ok(Some((start, self.joined.as_str())));
                }
            }
        }
    }
}

struct Reader<'a> {
    path: &'a Path,
    vertices: Vec<Vertex>,
    cstype: Option<CurveType>,
    degree: Option<(Vec<String>, usize)>,
    surface: Option<OpenSurface>,
    /// A free-form curve in space is open: its `parm` and `end` are skipped.
    in_curve: bool,
    /// Trim curves and the surfaces' loops.
    trims: TrimReader,
    patches: Vec<DomainPatch>,
}

/// Parses OBJ text; `path` only names the source in errors.
pub fn parse_freeform_obj(text: &str, path: &Path) -> Result<Vec<DomainPatch>, FreeformError> {
    read_freeform_obj(text.as_bytes(), path)
}

/// Reads OBJ text from `input` a line at a time; `path` only names the source in errors.
pub fn read_freeform_obj(
    input: impl std::io::BufRead,
    path: &Path,
) -> Result<Vec<DomainPatch>, FreeformError> {
    let mut reader = Reader {
        path,
        vertices: Vec::new(),
        cstype: None,
        degree: None,
        surface: None,
        in_curve: false,
        trims: TrimReader::default(),
        patches: Vec::new(),
    };
    let mut lines = LogicalLines::new(input);
    let mut last_line = 1;
    while let Some((line, content)) = lines
        .next_line()
        .map_err(|(line, message)| reader.err(line, message))?
    {
        last_line = line;
        let mut words = content.split_whitespace();
        let Some(keyword) = words.next() else {
            continue;
        };
        let args: Vec<&str> = words.collect();
        reader.statement(line, keyword, &args)?;
    }
    if let Some(open) = &reader.surface {
        return Err(reader.err(open.line, "the surface has no 'end' statement".to_owned()));
    }
    if reader.patches.is_empty() {
        return Err(reader.err(
            last_line,
            "no free-form surfaces ('surf' … 'end') in the file; a polygon mesh is an object of type \"mesh\"".to_owned(),
        ));
    }
    let Reader {
        path,
        trims,
        mut patches,
        ..
    } = reader;
    let err = |(line, message)| FreeformError {
        path: path.to_owned(),
        line,
        message,
    };
    for (range, region) in trims.finish().map_err(err)? {
        for p in &mut patches[range] {
            p.trim = Some(region.clone());
        }
    }
    Ok(patches)
}

impl Reader<'_> {
    fn err(&self, line: usize, message: String) -> FreeformError {
        FreeformError {
            path: self.path.to_owned(),
            line,
            message,
        }
    }

    fn line_err(&self, (line, message): (usize, String)) -> FreeformError {
        self.err(line, message)
    }

    /// A `curv2` line: a trim curve of the type and degree set before it.
    fn open_curve(&mut self, line: usize, args: &[&str]) -> Result<(), FreeformError> {
        if self.surface.is_some() {
            return Err(self.err(
                line,
                "'curv2' inside a surface; trim curves come before or after it".to_owned(),
            ));
        }
        let Some(cstype) = self.cstype.clone() else {
            return Err(self.err(line, "the trim curve has no 'cstype' before it".to_owned()));
        };
        let degree = self.degree.as_ref().map_or(&[][..], |(d, _)| d.as_slice());
        self.in_curve = false;
        self.trims
            .open_curve(line, args, (&cstype.name, cstype.rational), degree)
            .map_err(|e| self.line_err(e))
    }

    fn numbers(&self, line: usize, keyword: &str, args: &[&str]) -> Result<Vec<f64>, FreeformError> {
        args.iter()
            .map(|a| {
                a.parse::<f64>()
                    .ok()
                    .filter(|v| v.is_finite())
                    .ok_or_else(|| self.err(line, format!("'{keyword}': '{a}' is not a finite number")))
            })
            .collect()
    }

    fn statement(&mut self, line: usize, keyword: &str, args: &[&str]) -> Result<(), FreeformError> {
        match keyword {
            "v" => {
                let n = self.numbers(line, "v", args)?;
                if !(3..=4).contains(&n.len()) {
                    return Err(self.err(
                        line,
                        format!("'v' takes 3 or 4 numbers 'x y z [w]', found {}", n.len()),
                    ));
                }
                self.vertices.push(Vertex {
                    point: DVec3::new(n[0], n[1], n[2]),
                    weight: n.get(3).copied().unwrap_or(1.0),
                    line,
                });
            }
            "cstype" => {
                let (rational, name) = match args {
                    ["rat", name] => (true, *name),
                    [name] => (false, *name),
                    _ => return Err(self.err(line, "'cstype' takes '[rat] TYPE'".to_owned())),
                };
                self.cstype = Some(CurveType {
                    rational,
                    name: name.to_owned(),
                    line,
                });
            }
            "vp" => {
                let n = self.numbers(line, "vp", args)?;
                self.trims.vp(line, &n).map_err(|e| self.line_err(e))?;
            }
            "deg" => self.degree = Some((args.iter().map(|a| a.to_string()).collect(), line)),
            "surf" => self.open_surface(line, args)?,
            "curv" => self.in_curve = true,
            "curv2" => self.open_curve(line, args)?,
            "parm" => self.parm(line, args)?,
            "trim" | "hole" => {
                if self.surface.is_none() {
                    return Err(self.err(line, format!("'{keyword}' outside a surface ('surf' … 'end')")));
                }
                let n = self.numbers(line, keyword, args)?;
                self.trims
                    .add_loop(line, keyword == "hole", &n)
                    .map_err(|e| self.line_err(e))?;
            }
            "end" => {
                if self.surface.is_some() {
                    self.close_surface(line)?;
                } else if self.trims.curve_open() {
                    self.trims.close_curve(line).map_err(|e| self.line_err(e))?;
                } else if !std::mem::take(&mut self.in_curve) {
                    return Err(self.err(line, "'end' without a 'surf' before it".to_owned()));
                }
            }
            _ => {}
        }
        Ok(())
    }

    fn open_surface(&mut self, line: usize, args: &[&str]) -> Result<(), FreeformError> {
        if self.surface.is_some() {
            return Err(self.err(line, "'surf' before the previous surface's 'end'".to_owned()));
        }
        if self.trims.curve_open() {
            return Err(self.err(line, "'surf' before the trim curve's 'end'".to_owned()));
        }
        if args.len() < 5 {
            return Err(self.err(
                line,
                "'surf' takes 's0 s1 t0 t1' and the control points' indices".to_owned(),
            ));
        }
        let r = self.numbers(line, "surf", &args[..4])?;
        let mut indices = Vec::with_capacity(args.len() - 4);
        for a in &args[4..] {
            let first = a.split('/').next().unwrap_or("");
            let index: i64 = first
                .parse()
                .map_err(|_| self.err(line, format!("'surf': '{a}' is not a vertex index")))?;
            let count = self.vertices.len() as i64;
            let resolved = if index < 0 { count + index } else { index - 1 };
            if index == 0 || !(0..count).contains(&resolved) {
                return Err(self.err(
                    line,
                    format!("'surf': vertex index {index} is out of range ({count} vertices 'v' so far)"),
                ));
            }
            indices.push(resolved as usize);
        }
        self.in_curve = false;
        self.surface = Some(OpenSurface {
            line,
            range: Window {
                u0: r[0],
                u1: r[1],
                v0: r[2],
                v1: r[3],
            },
            indices,
            parm_u: None,
            parm_v: None,
            cstype: self.cstype.clone(),
            degree: self.degree.clone(),
        });
        Ok(())
    }

    /// A `parm` line's values: at most [`MAX_KNOTS`] finite numbers.
    fn parm_values(&self, line: usize, values: &[&str]) -> Result<Vec<f64>, FreeformError> {
        if values.len() > MAX_KNOTS {
            return Err(self.err(
                line,
                format!(
                    "'parm' gives {} values; at most {MAX_KNOTS} are read",
                    values.len()
                ),
            ));
        }
        self.numbers(line, "parm", values)
    }

    fn parm(&mut self, line: usize, args: &[&str]) -> Result<(), FreeformError> {
        if self.surface.is_none() {
            if self.in_curve {
                return Ok(());
            }
            if self.trims.curve_open() {
                let [axis, values @ ..] = args else {
                    return Err(self.err(line, "'parm' takes 'u' and its values".to_owned()));
                };
                let values = self.parm_values(line, values)?;
                return self.trims.parm(line, axis, values).map_err(|e| self.line_err(e));
            }
            return Err(self.err(line, "'parm' without a 'surf' before it".to_owned()));
        }
        let (axis, values) = match args {
            [axis, "closed", rest @ ..] | [axis, rest @ ..] => (*axis, rest),
            [] => return Err(self.err(line, "'parm' takes 'u' or 'v' and its values".to_owned())),
        };
        let values = self.parm_values(line, values)?;
        let Some(open) = self.surface.as_mut() else {
            return Ok(());
        };
        match axis {
            "u" => open.parm_u = Some((values, line)),
            "v" => open.parm_v = Some((values, line)),
            other => return Err(self.err(line, format!("'parm': expected 'u' or 'v', found '{other}'"))),
        }
        Ok(())
    }

    /// Whether the open surface is a Bézier surface (else a B-spline), its degrees along `u`
    /// and `v`, and whether it is rational: checks its type, degree and weights.
    fn check_kind(&self, open: &OpenSurface) -> Result<(bool, [usize; 2], bool), FreeformError> {
        let line = open.line;
        let bezier = match &open.cstype {
            None => return Err(self.err(line, "the surface has no 'cstype' before it".to_owned())),
            Some(c) => match c.name.as_str() {
                "bezier" => true,
                "bspline" => false,
                other => {
                    return Err(self.err(
                        line,
                        format!(
                            "'cstype {other}' (line {}) is not supported; only 'bezier' and 'bspline'",
                            c.line
                        ),
                    ))
                }
            },
        };
        let degrees = match &open.degree {
            Some((d, dline)) => self.degrees(d, *dline, line)?,
            None => {
                return Err(self.err(
                    line,
                    "the surface has no 'deg' line before it (such as 'deg 3 3')".to_owned(),
                ))
            }
        };
        let rational = open.cstype.as_ref().is_some_and(|c| c.rational);
        let weights = open.indices.iter().map(|&i| &self.vertices[i]);
        let bad = |v: &&Vertex| !(v.weight.is_finite() && v.weight > 0.0);
        if let Some(v) = weights
            .clone()
            .find(|v| if rational { bad(v) } else { v.weight != 1.0 })
        {
            let message = if rational {
                format!(
                    "control point on line {} has weight {}: a rational surface's weights must be above 0",
                    v.line, v.weight
                )
            } else {
                format!(
                    "control point on line {} has weight {}, but the surface is not rational \
                     (use 'cstype rat {}')",
                    v.line,
                    v.weight,
                    open.cstype.as_ref().map_or("bspline", |c| c.name.as_str())
                )
            };
            return Err(self.err(line, message));
        }
        Ok((bezier, degrees, rational))
    }

    /// The degrees along `u` and `v` of a `deg` line (`dline`) set for the surface on `line`:
    /// each 1, 2 or 3.
    fn degrees(&self, d: &[String], dline: usize, line: usize) -> Result<[usize; 2], FreeformError> {
        let refuse = |what: String| {
            self.err(
                line,
                format!(
                    "{what} ('deg {}' on line {dline}); surfaces of degree 1 to 3 are",
                    d.join(" ")
                ),
            )
        };
        let [du, dv] = d else {
            return Err(refuse("'deg' needs two degrees, along u and v,".to_owned()));
        };
        let mut out = [0; 2];
        for (k, (axis, value)) in [('u', du), ('v', dv)].into_iter().enumerate() {
            out[k] = match value.parse::<usize>() {
                Ok(n @ 1..=DEGREE) => n,
                Ok(n) => return Err(refuse(format!("degree {n} along {axis} is not supported"))),
                Err(_) => return Err(refuse(format!("'{value}' is not a degree along {axis}"))),
            };
        }
        Ok(out)
    }

    /// The knot values of one `parm` line (a Bézier surface's breakpoints made knots), with
    /// the line they stand on.
    fn knot_values(
        &self,
        open: &OpenSurface,
        (axis, degree): (char, usize),
        bezier: bool,
        end_line: usize,
    ) -> Result<(Vec<f64>, usize), FreeformError> {
        let parm = if axis == 'u' { &open.parm_u } else { &open.parm_v };
        let (values, pline) = parm.clone().ok_or_else(|| {
            self.err(
                end_line,
                format!("the surface on line {} has no 'parm {axis}' line", open.line),
            )
        })?;
        if !bezier {
            return Ok((values, pline));
        }
        if values.len() < 2 || values.windows(2).any(|w| w[1] <= w[0]) {
            return Err(self.err(
                pline,
                format!("a Bézier surface's 'parm {axis}' needs two or more increasing breakpoints"),
            ));
        }
        Ok((Knots::from_breakpoints(&values, degree), pline))
    }

    /// The Bézier patches of the open surface's B-spline `surface` (rational with the points'
    /// weights when `rational`), checked finite.
    fn bezier_pieces(
        &self,
        surface: BsplineSurface,
        open: &OpenSurface,
        rational: bool,
    ) -> Result<Vec<DomainPatch>, FreeformError> {
        let weights = rational.then(|| open.indices.iter().map(|&i| self.vertices[i].weight).collect());
        net_pieces(SurfaceNet { surface, weights }, None).map_err(|why| self.err(open.line, why.to_owned()))
    }

    fn close_surface(&mut self, end_line: usize) -> Result<(), FreeformError> {
        let Some(open) = self.surface.take() else {
            return Ok(());
        };
        let line = open.line;
        let (bezier, [pu, pv], rational) = self.check_kind(&open)?;
        let (u_values, u_line) = self.knot_values(&open, ('u', pu), bezier, end_line)?;
        let (v_values, v_line) = self.knot_values(&open, ('v', pv), bezier, end_line)?;
        let nu = u_values.len().saturating_sub(pu + 1);
        let nv = v_values.len().saturating_sub(pv + 1);
        if nu * nv != open.indices.len() {
            return Err(self.err(
                line,
                format!(
                    "the surface lists {} control points; its 'parm' lines (lines {u_line} and {v_line}) need {nu} × {nv} = {}",
                    open.indices.len(),
                    nu * nv
                ),
            ));
        }
        let u_knots = Knots::of_degree(u_values, nu, 'u', pu).map_err(|e| self.err(u_line, e.to_string()))?;
        let v_knots = Knots::of_degree(v_values, nv, 'v', pv).map_err(|e| self.err(v_line, e.to_string()))?;
        let r = open.range;
        u_knots
            .check_range(r.u0, r.u1, 'u')
            .map_err(|e| self.err(line, e.to_string()))?;
        v_knots
            .check_range(r.v0, r.v1, 'v')
            .map_err(|e| self.err(line, e.to_string()))?;
        let surface = BsplineSurface {
            points: open.indices.iter().map(|&i| self.vertices[i].point).collect(),
            u_knots,
            v_knots,
            range: r,
        };
        let spans = surface.u_knots.spans_in(r.u0, r.u1) * surface.v_knots.spans_in(r.v0, r.v1);
        if self.patches.len() + spans > MAX_PATCHES {
            return Err(self.err(
                line,
                format!(
                    "the surface makes {spans} Bézier patches, and the file {} before it; a scene holds at most {MAX_PATCHES}",
                    self.patches.len()
                ),
            ));
        }
        let patches = self.bezier_pieces(surface, &open, rational)?;
        let first = self.patches.len();
        if self.patches.is_empty() {
            self.patches = patches;
        } else {
            self.patches.extend(patches);
        }
        let size = DVec2::new(r.u1 - r.u0, r.v1 - r.v0).length();
        self.trims.close_surface(first..self.patches.len(), size);
        Ok(())
    }
}

/// Writes named groups of patches as OBJ `cstype bezier` surfaces: 16 `v` lines and one
/// `surf` per patch, its window as the surface's range and breakpoints, numbers in their
/// shortest round-trip form, so [`parse_freeform_obj`] reads the same points bit for bit. A
/// trimmed patch keeps its surface's loops: each trim segment is written once, as a `cstype
/// rat bezier` `curv2` of degree 3 over `vp` points, and every patch of the surface lists
/// the loops (`trim` and `hole`) in the surface's `(u,v)`, which its window is part of.
pub fn write_freeform_obj(
    groups: &[(String, Vec<DomainPatch>)],
    out: &mut impl std::io::Write,
) -> std::io::Result<()> {
    writeln!(
        out,
        "# Bicubic Bézier patches written by caustic {}",
        env!("CARGO_PKG_VERSION")
    )?;
    let mut next = 1usize;
    let mut curves = CurveWriter::default();
    for (name, patches) in groups {
        writeln!(out, "g {name}")?;
        for d in patches {
            let loops = match &d.trim {
                Some(region) => curves.write(region, out)?,
                None => Vec::new(),
            };
            let (patch, w) = (&d.patch, &d.window);
            // OBJ lists control points with u varying fastest: point iu + 4 jv.
            for jv in 0..4 {
                for iu in 0..4 {
                    write_vertex(out, patch.point(iu, jv), d.weights.map(|w| w[4 * iu + jv]))?;
                }
            }
            let rat = if d.weights.is_some() { "rat " } else { "" };
            writeln!(out, "cstype {rat}bezier\ndeg 3 3")?;
            let indices: Vec<String> = (next..next + 16).map(|i| i.to_string()).collect();
            writeln!(
                out,
                "surf {} {} {} {} {}",
                w.u0,
                w.u1,
                w.v0,
                w.v1,
                indices.join(" ")
            )?;
            writeln!(out, "parm u {} {}\nparm v {} {}", w.u0, w.u1, w.v0, w.v1)?;
            end_surface(out, loops)?;
            next += 16;
        }
    }
    Ok(())
}

/// Writes surfaces as the B-splines they are (their own nets, [`SurfaceNet`]): per surface
/// its `v` points (with weights when rational, `u` fastest), `cstype [rat] bspline`, its
/// degrees, range and knots, and its trim loops when it has some, which
/// [`parse_freeform_obj`] reads back to the same net and patches.
pub fn write_surfaces_obj(
    name: &str,
    surfaces: &[(&SurfaceNet, Option<&Arc<TrimRegion>>)],
    out: &mut impl std::io::Write,
) -> std::io::Result<()> {
    writeln!(
        out,
        "# B-spline surfaces written by caustic {}",
        env!("CARGO_PKG_VERSION")
    )?;
    writeln!(out, "g {name}")?;
    let mut next = 1usize;
    let mut curves = CurveWriter::default();
    for (net, trim) in surfaces {
        let loops = match trim {
            Some(region) => curves.write(region, out)?,
            None => Vec::new(),
        };
        let s = &net.surface;
        for (k, p) in s.points.iter().enumerate() {
            write_vertex(out, *p, net.weights.as_ref().map(|w| w[k]))?;
        }
        let rat = if net.weights.is_some() { "rat " } else { "" };
        let (du, dv) = (s.u_knots.degree(), s.v_knots.degree());
        let indices: Vec<String> = (next..next + s.points.len()).map(|i| i.to_string()).collect();
        let r = &s.range;
        writeln!(out, "cstype {rat}bspline\ndeg {du} {dv}")?;
        writeln!(
            out,
            "surf {} {} {} {} {}",
            r.u0,
            r.u1,
            r.v0,
            r.v1,
            indices.join(" ")
        )?;
        let knots = |k: &[f64]| k.iter().map(|x| x.to_string()).collect::<Vec<_>>().join(" ");
        writeln!(
            out,
            "parm u {}\nparm v {}",
            knots(s.u_knots.values()),
            knots(s.v_knots.values())
        )?;
        end_surface(out, loops)?;
        next += s.points.len();
    }
    Ok(())
}

/// A `v` line: the point, and its weight for a rational surface.
fn write_vertex(out: &mut impl std::io::Write, p: DVec3, weight: Option<f64>) -> std::io::Result<()> {
    match weight {
        Some(w) => writeln!(out, "v {} {} {} {w}", p.x, p.y, p.z),
        None => writeln!(out, "v {} {} {}", p.x, p.y, p.z),
    }
}

/// A surface's `trim` and `hole` lines, then its `end`.
fn end_surface(out: &mut impl std::io::Write, loops: LoopLines) -> std::io::Result<()> {
    for (line, hole) in loops {
        writeln!(out, "{} {line}", if hole { "hole" } else { "trim" })?;
    }
    writeln!(out, "end")
}

/// Each loop's `u0 u1 curv2` list, and whether it is a hole.
type LoopLines = Vec<(String, bool)>;

/// Writes each trim region once as `curv2` curves and remembers their numbers.
#[derive(Default)]
struct CurveWriter {
    /// Regions written, with their loops' lines.
    written: Vec<(Arc<TrimRegion>, LoopLines)>,
    /// `vp` points and `curv2` curves written so far.
    points: usize,
    curves: usize,
}

impl CurveWriter {
    /// The `trim`/`hole` lists of `region`'s loops, its curves written first if they are not yet.
    fn write(
        &mut self,
        region: &Arc<TrimRegion>,
        out: &mut impl std::io::Write,
    ) -> std::io::Result<LoopLines> {
        if let Some((_, loops)) = self.written.iter().find(|(r, _)| Arc::ptr_eq(r, region)) {
            return Ok(loops.clone());
        }
        let mut loops = Vec::new();
        for l in region.loops() {
            let mut pieces = Vec::with_capacity(l.segments.len());
            for s in &l.segments {
                for p in s {
                    writeln!(out, "vp {} {} {}", p.x / p.z, p.y / p.z, p.z)?;
                }
                let first = self.points + 1;
                self.points += 4;
                self.curves += 1;
                writeln!(
                    out,
                    "cstype rat bezier\ndeg 3\ncurv2 {} {} {} {}\nparm u 0 1\nend",
                    first,
                    first + 1,
                    first + 2,
                    first + 3
                )?;
                pieces.push(format!("0 1 {}", self.curves));
            }
            loops.push((pieces.join(" "), l.hole));
        }
        self.written.push((region.clone(), loops.clone()));
        Ok(loops)
    }
}
