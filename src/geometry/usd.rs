//! OpenUSD files (`.usda` text, `.usdz` packages of text layers) read one layer at a time with
//! the `openusd` crate's text reader ([`super::usd_layer`]; binary layers are refused there): `NurbsPatch` prims become surfaces
//! ([`super::usd_nurbs`]), `Mesh` prims triangle meshes and `Sphere` prims spheres, each placed
//! by its prims' transforms (`xformOpOrder`, evaluated here), with a constant
//! `primvars:displayColor` kept as its colour.
//!
//! The crate's composed stage is not used: on malformed input it recursed without bound (a
//! stack overflow no error can report), while its text reader, guarded as
//! [`super::usd_layer`] says, returns errors. So a file is read as the one layer it is; references, payloads, sublayers, variants, classes and `over`
//! prims are not composed, and what is not read is listed in [`UsdContents::unread`].

use std::borrow::Cow;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use glam::{DAffine3, DMat3, DMat4, DQuat, DVec2, DVec3};
use openusd::sdf::{self, Value};

use super::freeform::{place_pieces, DomainPatch};
use super::mesh::TriangleMesh;
use super::sphere::Sphere;
use super::usd_layer::{layer_from_bytes, line_of, open_layer, Layer};
use super::usd_nurbs::{islands, nurbs_patches, Budget, NurbsFields, TrimFields};

/// Triangles a file's meshes may make in all; beyond, the file is refused.
pub const MAX_USD_TRIANGLES: usize = 20_000_000;

/// Prims below the root a file may nest; deeper ones are refused (each level is a frame of
/// the reader's own recursion).
const MAX_NESTING: usize = 256;

/// A USD file that cannot be read: which file, which line and prim, what was wrong.
#[derive(Debug, thiserror::Error)]
#[error("{}{}: {}{message}", path.display(), line.map(|l| format!(":{l}")).unwrap_or_default(), prim.as_ref().map(|p| format!("prim {p}: ")).unwrap_or_default())]
pub struct UsdError {
    /// The file (as given).
    pub path: PathBuf,
    /// The line of the prim or attribute concerned, when known.
    pub line: Option<usize>,
    /// The prim concerned, when one is.
    pub prim: Option<String>,
    /// What was wrong.
    pub message: String,
}

/// A shape read from a prim, placed, with the prim's path and its display colour.
#[derive(Clone, Debug)]
pub struct UsdShape<T> {
    /// The prim's path (`/World/Floor`).
    pub prim: String,
    /// The shape, placed by the prim's transforms.
    pub shape: T,
    /// Its constant `primvars:displayColor`, if it has one.
    pub color: Option<DVec3>,
}

/// What a USD file holds that caustic reads, and a list of what it does not.
#[derive(Clone, Debug, Default)]
pub struct UsdContents {
    /// The `NurbsPatch` prims' Bézier patches, placed, each surface's net and trim shared by
    /// its patches.
    pub patches: Vec<DomainPatch>,
    /// The `Mesh` prims.
    pub meshes: Vec<UsdShape<TriangleMesh>>,
    /// The `Sphere` prims.
    pub spheres: Vec<UsdShape<Sphere>>,
    /// What was not read, one short phrase each (`2 Camera prims`), in a stable order.
    pub unread: Vec<String>,
}

/// Whether a file name is a USD file's by its extension (`.usda`, `.usdc`, `.usdz`, `.usd`).
pub fn is_usd_file(name: &str) -> bool {
    let ext = Path::new(name)
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    matches!(ext.as_deref(), Some("usda" | "usdc" | "usdz" | "usd"))
}

/// Reads the USD file at `path` (`.usda` text, `.usdz` package, or `.usd`; [`super::usd_layer`]).
pub fn load_usd(path: &Path) -> Result<UsdContents, UsdError> {
    read_layer(open_layer(path), path)
}

/// [`load_usd`] for a file's bytes already read (`path` names it in errors).
pub fn parse_usd(bytes: Vec<u8>, path: &Path) -> Result<UsdContents, UsdError> {
    read_layer(layer_from_bytes(bytes), path)
}

/// The prims of `layer`, or why it could not be read.
fn read_layer(layer: Result<Layer, String>, path: &Path) -> Result<UsdContents, UsdError> {
    let layer = layer.map_err(|message| UsdError {
        path: path.to_owned(),
        line: None,
        prim: None,
        message,
    })?;
    let mut reader = Reader {
        layer: &layer,
        path,
        contents: UsdContents::default(),
        budget: Budget {
            patches: 0,
            trim_segments: 0,
        },
        triangles: 0,
        unread: BTreeMap::new(),
    };
    reader.layer_notes();
    reader.children(&sdf::Path::abs_root(), DMat4::IDENTITY, 0)?;
    let mut contents = reader.contents;
    contents
        .unread
        .extend(reader.unread.into_iter().map(|(what, n)| match n {
            0 => what,
            n => format!("{n} × {what}"),
        }));
    Ok(contents)
}

/// The prim kinds read here.
enum Kind {
    Nurbs,
    Mesh,
    Sphere,
    /// Transforms and groups: only their children are read.
    Group,
}

struct Reader<'a> {
    layer: &'a Layer,
    path: &'a Path,
    contents: UsdContents,
    budget: Budget,
    /// Triangles made by the file's meshes so far.
    triangles: usize,
    /// What was not read and how often (0: a note without a count).
    unread: BTreeMap<String, usize>,
}

impl Reader<'_> {
    /// An error about `prim`, at the line of the attribute its message names first (`'uOrder'
    /// is 5 …`), else of the prim.
    fn err(&self, prim: &sdf::Path, message: String) -> UsdError {
        let attr = message
            .strip_prefix('\'')
            .and_then(|m| m.split('\'').next())
            .map(|a| a.split('[').next().unwrap_or(a));
        UsdError {
            path: self.path.to_owned(),
            line: line_of(&self.layer.text, prim.as_str(), attr),
            prim: Some(prim.to_string()),
            message,
        }
    }

    fn note(&mut self, what: impl Into<String>) {
        *self.unread.entry(what.into()).or_insert(0) += 1;
    }

    /// Notes about the layer as a whole: sublayers and a Z-up stage.
    fn layer_notes(&mut self) {
        let root = sdf::Path::abs_root();
        if self.has(&root, "subLayers") {
            self.unread.insert("sublayers (not composed)".into(), 0);
        }
        if let Some(axis) = self
            .field(&root, "upAxis")
            .and_then(|v| v.as_str().map(str::to_owned))
        {
            if axis != "Y" {
                self.unread.insert(
                    format!(
                        "upAxis \"{axis}\" (read as it is; caustic's up is +y: rotate the object with 'transform.rotate = [-90, 0, 0]')"
                    ),
                    0,
                );
            }
        }
    }

    fn field(&self, path: &sdf::Path, name: &str) -> Option<Cow<'_, Value>> {
        self.layer.field(path, name)
    }

    /// Whether the spec at `path` has the field `name`.
    fn has(&self, path: &sdf::Path, name: &str) -> bool {
        self.layer.has(path, name)
    }

    /// An attribute's default value.
    fn attr(&self, prim: &sdf::Path, name: &str) -> Option<Cow<'_, Value>> {
        let property = prim.append_property(name).ok()?;
        self.field(&property, "default")
    }

    /// Reads the children of `parent`, placed by `parent_m`.
    fn children(&mut self, parent: &sdf::Path, parent_m: DMat4, depth: usize) -> Result<(), UsdError> {
        let names: Vec<String> = match self.field(parent, "primChildren").as_deref() {
            Some(Value::TokenVec(t)) => t.iter().map(|t| t.as_str().to_owned()).collect(),
            _ => return Ok(()),
        };
        if depth >= MAX_NESTING {
            let top: Vec<&str> = parent.as_str().split('/').take(4).collect();
            return Err(UsdError {
                path: self.path.to_owned(),
                line: None,
                prim: None,
                message: format!(
                    "prims nest deeper than {MAX_NESTING} levels (below {}/…)",
                    top.join("/")
                ),
            });
        }
        for name in names {
            let text = if parent.is_abs_root() {
                format!("/{name}")
            } else {
                format!("{parent}/{name}")
            };
            let Ok(path) = sdf::Path::new(&text) else {
                self.note(format!("prim '{text}' (not a valid path)"));
                continue;
            };
            self.prim(&path, parent_m, depth)?;
        }
        Ok(())
    }

    /// Reads one prim and its children.
    fn prim(&mut self, path: &sdf::Path, parent_m: DMat4, depth: usize) -> Result<(), UsdError> {
        let specifier = match self.field(path, "specifier").as_deref() {
            Some(Value::Specifier(s)) if *s != sdf::Specifier::Def => Some(format!("{s:?}").to_lowercase()),
            _ => None,
        };
        if let Some(s) = specifier {
            self.note(format!("'{s}' prims (not composed)"));
            return Ok(());
        }
        if matches!(self.field(path, "active").as_deref(), Some(Value::Bool(false))) {
            return Ok(());
        }
        for (field, what) in [
            ("references", "references (not composed)"),
            ("payload", "payloads (not composed)"),
            ("inheritPaths", "inherits (not composed)"),
            ("specializes", "specializes (not composed)"),
            ("variantSetNames", "variant sets (not composed)"),
        ] {
            if self.has(path, field) {
                self.note(what);
            }
        }
        let type_name = match self.field(path, "typeName").as_deref() {
            Some(v) => v.as_str().unwrap_or_default().to_owned(),
            None => String::new(),
        };
        let kind = match type_name.as_str() {
            "NurbsPatch" => Kind::Nurbs,
            "Mesh" => Kind::Mesh,
            "Sphere" => Kind::Sphere,
            "" | "Xform" | "Scope" => Kind::Group,
            other => {
                self.note(format!("{other} prims"));
                return Ok(());
            }
        };
        let (local, reset) = self.local_transform(path)?;
        let m = if reset { local } else { parent_m * local };
        // Visibility and purpose are inherited: an invisible prim hides its children, and
        // guide and proxy prims (with theirs) are not rendered.
        if matches!(
            self.attr(path, "visibility").as_deref().and_then(Value::as_str),
            Some("invisible")
        ) {
            return Ok(());
        }
        if let Some(purpose @ ("guide" | "proxy")) =
            self.attr(path, "purpose").as_deref().and_then(Value::as_str)
        {
            let what = format!("prims of purpose \"{purpose}\" (not rendered)");
            self.note(what);
            return Ok(());
        }
        match kind {
            Kind::Nurbs => self.nurbs(path, &m)?,
            Kind::Mesh => self.mesh(path, &m)?,
            Kind::Sphere => self.sphere(path, &m)?,
            Kind::Group => {}
        }
        self.children(path, m, depth + 1)
    }

    /// The prim's own transform (its `xformOpOrder`, first op outermost) and whether it resets
    /// the parent's (`!resetXformStack!`).
    fn local_transform(&mut self, prim: &sdf::Path) -> Result<(DMat4, bool), UsdError> {
        let order: Vec<String> = match self.attr(prim, "xformOpOrder").as_deref() {
            Some(Value::TokenVec(t)) => t.iter().map(|t| t.as_str().to_owned()).collect(),
            _ => return Ok((DMat4::IDENTITY, false)),
        };
        let mut m = DMat4::IDENTITY;
        let mut reset = false;
        for op in order {
            if op == "!resetXformStack!" {
                (m, reset) = (DMat4::IDENTITY, true);
                continue;
            }
            let (name, invert) = match op.strip_prefix("!invert!") {
                Some(rest) => (rest.to_owned(), true),
                None => (op.clone(), false),
            };
            let value = self.attr(prim, &name).map(Cow::into_owned);
            let mut op_m = xform_op(&name, value.as_ref())
                .map_err(|why| self.err(prim, format!("transform op '{name}': {why}")))?;
            if invert {
                if op_m.determinant().abs() < 1e-300 {
                    return Err(self.err(prim, format!("transform op '{op}' cannot be inverted")));
                }
                op_m = op_m.inverse();
            }
            m *= op_m;
        }
        if !m.is_finite() {
            return Err(self.err(prim, "its transform is not finite".into()));
        }
        Ok((m, reset))
    }

    fn color(&mut self, prim: &sdf::Path) -> Option<DVec3> {
        let colors = self.attr(prim, "primvars:displayColor").and_then(|v| vec3s(&v))?;
        match colors.as_slice() {
            [c] if c.is_finite() && c.min_element() >= 0.0 => Some(*c),
            [] => None,
            _ => {
                self.note("displayColor varying over a prim (its object keeps the scene's material)");
                None
            }
        }
    }

    fn nurbs(&mut self, prim: &sdf::Path, m: &DMat4) -> Result<(), UsdError> {
        let ints = |r: &Self, name: &str| r.attr(prim, name).and_then(|v| ints(&v));
        let int = |r: &Self, name: &str| r.attr(prim, name).and_then(|v| int(&v));
        let f64s = |r: &Self, name: &str| r.attr(prim, name).and_then(|v| f64s(&v));
        let vec2 = |r: &Self, name: &str| r.attr(prim, name).and_then(|v| vec2(&v));
        let fields = NurbsFields {
            vertex_counts: [int(self, "uVertexCount"), int(self, "vVertexCount")],
            orders: [int(self, "uOrder"), int(self, "vOrder")],
            knots: [f64s(self, "uKnots"), f64s(self, "vKnots")],
            ranges: [vec2(self, "uRange"), vec2(self, "vRange")],
            points: self.attr(prim, "points").and_then(|v| vec3s(&v)),
            weights: f64s(self, "pointWeights"),
            trim: TrimFields {
                counts: ints(self, "trimCurve:counts"),
                orders: ints(self, "trimCurve:orders"),
                vertex_counts: ints(self, "trimCurve:vertexCounts"),
                knots: f64s(self, "trimCurve:knots"),
                ranges: self.attr(prim, "trimCurve:ranges").and_then(|v| vec2s(&v)),
                points: self.attr(prim, "trimCurve:points").and_then(|v| vec3s(&v)),
            },
        };
        let patches = nurbs_patches(&fields, &mut self.budget).map_err(|why| self.err(prim, why))?;
        if let Some(trim) = patches.first().and_then(|p| p.trim.as_ref()) {
            if islands(trim) > 0 {
                self.note("trim loops inside a hole (cut away with the hole)");
            }
        }
        if self.color(prim).is_some() {
            self.note("displayColor of NurbsPatch prims (the object's material is used)");
        }
        let placed = place_pieces(patches, &affine(m));
        self.contents.patches.extend(placed);
        Ok(())
    }

    fn mesh(&mut self, prim: &sdf::Path, m: &DMat4) -> Result<(), UsdError> {
        let points = self
            .attr(prim, "points")
            .and_then(|v| vec3s(&v))
            .ok_or_else(|| self.err(prim, "'points' is not authored".into()))?;
        let counts = self
            .attr(prim, "faceVertexCounts")
            .and_then(|v| ints(&v))
            .ok_or_else(|| self.err(prim, "'faceVertexCounts' is not authored".into()))?;
        let indices = self
            .attr(prim, "faceVertexIndices")
            .and_then(|v| ints(&v))
            .ok_or_else(|| self.err(prim, "'faceVertexIndices' is not authored".into()))?;
        let left_handed = matches!(
            self.attr(prim, "orientation").as_deref().and_then(Value::as_str),
            Some("leftHanded")
        );
        if !matches!(
            self.attr(prim, "subdivisionScheme")
                .as_deref()
                .and_then(Value::as_str),
            Some("none")
        ) {
            self.note("subdivision of Mesh prims (each is rendered as its polygons)");
        }
        let triangles =
            fan_triangles(&counts, &indices, points.len(), left_handed).map_err(|why| self.err(prim, why))?;
        self.triangles += triangles.len();
        if self.triangles > MAX_USD_TRIANGLES {
            return Err(self.err(
                prim,
                format!("the file's meshes make more than {MAX_USD_TRIANGLES} triangles"),
            ));
        }
        let a = affine(m);
        let positions: Vec<DVec3> = points.iter().map(|p| a.transform_point3(*p)).collect();
        if positions.iter().any(|p| !p.is_finite()) {
            return Err(self.err(prim, "'points' placed by its transform are not finite".into()));
        }
        let color = self.color(prim);
        self.contents.meshes.push(UsdShape {
            prim: prim.to_string(),
            shape: TriangleMesh {
                positions,
                normals: Vec::new(),
                texcoords: Vec::new(),
                indices: triangles,
            },
            color,
        });
        Ok(())
    }

    fn sphere(&mut self, prim: &sdf::Path, m: &DMat4) -> Result<(), UsdError> {
        let radius = match self.attr(prim, "radius") {
            None => 1.0,
            Some(v) => f64s(&v)
                .and_then(|r| r.first().copied())
                .ok_or_else(|| self.err(prim, "'radius' is not a number".into()))?,
        };
        let a = affine(m);
        let scale = [a.matrix3.x_axis, a.matrix3.y_axis, a.matrix3.z_axis].map(DVec3::length);
        let uniform = (scale[0] - scale[1]).abs() <= 1e-9 * scale[0]
            && (scale[0] - scale[2]).abs() <= 1e-9 * scale[0]
            && (a.matrix3.transpose() * a.matrix3 - DMat3::from_diagonal(DVec3::splat(scale[0] * scale[0])))
                .to_cols_array()
                .iter()
                .all(|x| x.abs() <= 1e-9 * scale[0] * scale[0]);
        if !uniform {
            self.note("Sphere prims under a non-uniform scale or shear (not read)");
            return Ok(());
        }
        let radius = radius.abs() * scale[0];
        if !(radius.is_finite() && radius > 0.0) {
            return Err(self.err(prim, format!("its radius {radius} must be above 0 and finite")));
        }
        let color = self.color(prim);
        self.contents.spheres.push(UsdShape {
            prim: prim.to_string(),
            shape: Sphere {
                center: a.translation,
                radius,
            },
            color,
        });
        Ok(())
    }
}

/// `m` as an affine map (USD transforms are affine; the last row is dropped).
fn affine(m: &DMat4) -> DAffine3 {
    DAffine3::from_mat4(*m)
}

/// The polygons `counts` over `indices` as triangle fans (reversed for a left-handed mesh).
fn fan_triangles(
    counts: &[i64],
    indices: &[i64],
    points: usize,
    left_handed: bool,
) -> Result<Vec<[u32; 3]>, String> {
    let total: i64 = counts.iter().map(|&c| c.max(0)).sum();
    if counts.iter().any(|&c| c < 3) || total != indices.len() as i64 {
        return Err(format!(
            "'faceVertexCounts' must list faces of 3 or more vertices adding up to the {} 'faceVertexIndices' (they add up to {total})",
            indices.len()
        ));
    }
    if let Some(i) = indices
        .iter()
        .find(|&&i| i < 0 || i as usize >= points || i > u32::MAX as i64)
    {
        return Err(format!(
            "'faceVertexIndices' holds {i}, outside the {points} points"
        ));
    }
    let mut out = Vec::with_capacity(indices.len());
    let mut start = 0usize;
    for &c in counts {
        let face = &indices[start..start + c as usize];
        for k in 1..face.len() - 1 {
            let t = [face[0], face[k], face[k + 1]].map(|i| i as u32);
            out.push(if left_handed { [t[0], t[2], t[1]] } else { t });
        }
        start += c as usize;
    }
    Ok(out)
}

/// One transform op's matrix: `translate`, `scale`, `rotateX|Y|Z`, the six `rotateXYZ`
/// orders (the first letter's rotation applied first), `orient` and `transform`.
fn xform_op(name: &str, value: Option<&Value>) -> Result<DMat4, String> {
    let kind = name
        .strip_prefix("xformOp:")
        .ok_or("not an 'xformOp:' attribute")?
        .split(':')
        .next()
        .unwrap_or_default();
    let value = value.ok_or("the op's attribute has no default value")?;
    let v3 = || vec3(value).ok_or(format!("expected three numbers, found {}", describe(value)));
    let angle = || {
        f64s(value)
            .filter(|v| v.len() == 1)
            .map(|v| v[0].to_radians())
            .ok_or(format!("expected an angle, found {}", describe(value)))
    };
    let axis_rotation = |axis: char, degrees: f64| match axis {
        'X' => DMat4::from_rotation_x(degrees.to_radians()),
        'Y' => DMat4::from_rotation_y(degrees.to_radians()),
        _ => DMat4::from_rotation_z(degrees.to_radians()),
    };
    Ok(match kind {
        "translate" => DMat4::from_translation(v3()?),
        "scale" => DMat4::from_scale(v3()?),
        "rotateX" => DMat4::from_rotation_x(angle()?),
        "rotateY" => DMat4::from_rotation_y(angle()?),
        "rotateZ" => DMat4::from_rotation_z(angle()?),
        "rotateXYZ" | "rotateXZY" | "rotateYXZ" | "rotateYZX" | "rotateZXY" | "rotateZYX" => {
            let angles = v3()?;
            let axes: Vec<char> = kind["rotate".len()..].chars().collect();
            let by_axis = |c: char| match c {
                'X' => angles.x,
                'Y' => angles.y,
                _ => angles.z,
            };
            // The first axis's rotation acts first, so it stands rightmost.
            axes.iter()
                .rev()
                .fold(DMat4::IDENTITY, |m, &c| m * axis_rotation(c, by_axis(c)))
        }
        "orient" => {
            let q = match value {
                Value::Quatd(q) => DQuat::from_xyzw(q.x, q.y, q.z, q.w),
                Value::Quatf(q) => DQuat::from_xyzw(q.x.into(), q.y.into(), q.z.into(), q.w.into()),
                Value::Quath(q) => DQuat::from_xyzw(q.x.to_f64(), q.y.to_f64(), q.z.to_f64(), q.w.to_f64()),
                other => return Err(format!("expected a quaternion, found {}", describe(other))),
            };
            if !(q.is_finite() && q.length() > 0.0) {
                return Err("the quaternion must be finite and not zero".into());
            }
            DMat4::from_quat(q.normalize())
        }
        "transform" => match value {
            // USD's matrices act on row vectors: its rows are glam's columns.
            Value::Matrix4d(m) => DMat4::from_cols_array(&m.0),
            other => return Err(format!("expected a matrix4d, found {}", describe(other))),
        },
        other => return Err(format!("'{other}' ops are not read")),
    })
}

/// A short name of a value's type, for errors.
fn describe(v: &Value) -> String {
    let debug = format!("{v:?}");
    debug
        .split(['(', ' ', '{'])
        .next()
        .unwrap_or("a value")
        .to_owned()
}

/// Integers (an `int[]` or one `int`).
fn ints(v: &Value) -> Option<Vec<i64>> {
    Some(match v {
        Value::IntVec(x) => x.iter().map(|&i| i64::from(i)).collect(),
        Value::Int64Vec(x) => x.clone(),
        Value::UintVec(x) => x.iter().map(|&i| i64::from(i)).collect(),
        _ => vec![int(v)?],
    })
}

/// One integer.
fn int(v: &Value) -> Option<i64> {
    Some(match v {
        Value::Int(i) => i64::from(*i),
        Value::Int64(i) => *i,
        Value::Uint(i) => i64::from(*i),
        Value::Uchar(i) => i64::from(*i),
        _ => return None,
    })
}

/// Numbers (an array of any precision, or one number).
fn f64s(v: &Value) -> Option<Vec<f64>> {
    Some(match v {
        Value::DoubleVec(x) => x.clone(),
        Value::FloatVec(x) => x.iter().map(|&f| f64::from(f)).collect(),
        Value::HalfVec(x) => x.iter().map(|h| h.to_f64()).collect(),
        Value::Double(x) => vec![*x],
        Value::Float(x) => vec![f64::from(*x)],
        Value::Half(x) => vec![x.to_f64()],
        _ => ints(v)?.into_iter().map(|i| i as f64).collect(),
    })
}

/// One 2-vector.
fn vec2(v: &Value) -> Option<DVec2> {
    vec2s(v).filter(|x| x.len() == 1).map(|x| x[0])
}

/// 2-vectors (an array, or one).
fn vec2s(v: &Value) -> Option<Vec<DVec2>> {
    Some(match v {
        Value::Vec2dVec(x) => x.iter().map(|p| DVec2::new(p.x, p.y)).collect(),
        Value::Vec2fVec(x) => x.iter().map(|p| DVec2::new(p.x.into(), p.y.into())).collect(),
        Value::Vec2d(p) => vec![DVec2::new(p.x, p.y)],
        Value::Vec2f(p) => vec![DVec2::new(p.x.into(), p.y.into())],
        _ => return None,
    })
}

/// One 3-vector.
fn vec3(v: &Value) -> Option<DVec3> {
    vec3s(v).filter(|x| x.len() == 1).map(|x| x[0])
}

/// 3-vectors (an array of any precision, or one).
fn vec3s(v: &Value) -> Option<Vec<DVec3>> {
    let f = |p: &openusd::gf::Vec3f| DVec3::new(p.x.into(), p.y.into(), p.z.into());
    let h = |p: &openusd::gf::Vec3h| DVec3::new(p.x.to_f64(), p.y.to_f64(), p.z.to_f64());
    Some(match v {
        Value::Vec3dVec(x) => x.iter().map(|p| DVec3::new(p.x, p.y, p.z)).collect(),
        Value::Vec3fVec(x) => x.iter().map(f).collect(),
        Value::Vec3hVec(x) => x.iter().map(h).collect(),
        Value::Vec3d(p) => vec![DVec3::new(p.x, p.y, p.z)],
        Value::Vec3f(p) => vec![f(p)],
        Value::Vec3h(p) => vec![h(p)],
        _ => return None,
    })
}
