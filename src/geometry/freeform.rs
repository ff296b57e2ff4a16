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

use glam::DVec3;

use super::bezier::BezierPatch;
use super::bspline::{BsplineSurface, Knots, DEGREE};
use super::patch::Window;
use super::rational::{weights_error, Weights};
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

/// A Bézier patch, its `(u,v)` window in the parameters of the surface it came from and, for
/// a rational surface, its weights ([`super::rational`]).
pub type DomainPatch = (BezierPatch, Window, Option<Weights>);

/// Reads every free-form surface (degree 1 to 3) of an OBJ file as bicubic Bézier patches, a
/// line at a time: what the reader keeps beyond the patches is the `v` points (40 bytes each)
/// and the open surface's indices, whatever else the file holds.
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
    /// A free-form curve is open: its `parm` and `end` are skipped.
    in_curve: bool,
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
    Ok(reader.patches)
}

impl Reader<'_> {
    fn err(&self, line: usize, message: String) -> FreeformError {
        FreeformError {
            path: self.path.to_owned(),
            line,
            message,
        }
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
                    return Err(self.err(line, format!("'v' takes 3 or 4 numbers 'x y z [w]', found {}", n.len())));
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
            "deg" => self.degree = Some((args.iter().map(|a| a.to_string()).collect(), line)),
            "surf" => self.open_surface(line, args)?,
            "curv" | "curv2" => self.in_curve = true,
            "parm" => self.parm(line, args)?,
            "trim" | "hole" | "scrv" | "sp" if self.surface.is_some() => {
                return Err(self.err(
                    line,
                    format!("'{keyword}': trimmed surfaces and curves on surfaces are not supported (only whole surfaces)"),
                ))
            }
            "end" => {
                if self.surface.is_some() {
                    self.close_surface(line)?;
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

    fn parm(&mut self, line: usize, args: &[&str]) -> Result<(), FreeformError> {
        if self.surface.is_none() {
            if self.in_curve {
                return Ok(());
            }
            return Err(self.err(line, "'parm' without a 'surf' before it".to_owned()));
        }
        let (axis, values) = match args {
            [axis, "closed", rest @ ..] | [axis, rest @ ..] => (*axis, rest),
            [] => return Err(self.err(line, "'parm' takes 'u' or 'v' and its values".to_owned())),
        };
        if values.len() > MAX_KNOTS {
            return Err(self.err(
                line,
                format!(
                    "'parm' gives {} values; at most {MAX_KNOTS} are read",
                    values.len()
                ),
            ));
        }
        let values = self.numbers(line, "parm", values)?;
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
        let patches: Vec<DomainPatch> = if rational {
            let weights: Vec<f64> = open.indices.iter().map(|&i| self.vertices[i].weight).collect();
            surface
                .to_rational_bezier(&weights)
                .into_iter()
                .map(|(p, window, w)| (p, window, Some(w)))
                .collect()
        } else {
            surface
                .to_bezier()
                .into_iter()
                .map(|(p, w)| (p, w, None))
                .collect()
        };
        let finite = |(p, w, weights): &DomainPatch| {
            p.points.iter().all(|q| q.is_finite())
                && (w.u1 - w.u0).is_finite()
                && (w.v1 - w.v0).is_finite()
                && weights.as_ref().is_none_or(|w| weights_error(w).is_none())
        };
        if !patches.iter().all(finite) {
            return Err(self.err(
                line,
                "the surface's knots or points are too large to convert (the result is not finite)"
                    .to_owned(),
            ));
        }
        if self.patches.is_empty() {
            self.patches = patches;
        } else {
            self.patches.extend(patches);
        }
        Ok(())
    }
}

/// Writes named groups of patches as OBJ `cstype bezier` surfaces: 16 `v` lines and one
/// `surf` per patch, its window as the surface's range and breakpoints, numbers in their
/// shortest round-trip form, so [`parse_freeform_obj`] reads the same points bit for bit.
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
    for (name, patches) in groups {
        writeln!(out, "g {name}")?;
        for (patch, w, weights) in patches {
            // OBJ lists control points with u varying fastest: point iu + 4 jv.
            for jv in 0..4 {
                for iu in 0..4 {
                    let p = patch.point(iu, jv);
                    match weights {
                        Some(weights) => writeln!(out, "v {} {} {} {}", p.x, p.y, p.z, weights[4 * iu + jv])?,
                        None => writeln!(out, "v {} {} {}", p.x, p.y, p.z)?,
                    }
                }
            }
            let rat = if weights.is_some() { "rat " } else { "" };
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
            writeln!(out, "parm u {} {}\nparm v {} {}\nend", w.u0, w.u1, w.v0, w.v1)?;
            next += 16;
        }
    }
    Ok(())
}
