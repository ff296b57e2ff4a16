//! Where a photon lands on the receiver, and how that point moves when the designed surface's
//! control points move: the derivative the caustic designer descends.
//!
//! A photon is traced through the scene's specular surfaces (smooth glass refracts it by
//! Snell's law, or reflects it totally; mirrors reflect it) to the receiver quad. Along the
//! way its origin and direction carry their derivatives with respect to the design's
//! parameters ([`super::dual`]), each parameter a control point (welded with the points that
//! coincide with it) moving along a fixed direction. At a hit on a bicubic Bézier patch the
//! hit point's parameters `(t, u, v)` solve `o + t d = S(u, v; θ)`; by the implicit function
//! theorem
//!
//! ```text
//! [d | −S_u | −S_v] · ∂(t, u, v)/∂θ = ∂S/∂θ − ∂o/∂θ − t ∂d/∂θ,
//! ```
//!
//! where `∂S/∂θ_p` is the Bernstein weight `B_i(u) B_j(v)` of the moved point times its
//! direction. The normal `S_u × S_v` moves with `(u, v)` (second derivatives of the patch)
//! and with the points (derivatives of the weights); the refracted or reflected direction
//! follows by the chain rule, and the landing point `(s, t)` on the receiver
//! `corner + s edge_u + t edge_v` solves the same kind of system. This is forward-mode
//! differentiation of a photon's path as the caustic-design literature does it (Papas et al.
//! 2011, "Goal-based caustics"; Mitsuba 3's caustics-optimisation tutorial differentiates a
//! light tracer the same way, through a heightmap mesh instead of exact patches).

use std::collections::HashMap;

use glam::{DMat3, DVec2, DVec3};

use super::dual::{Param, D1, D3};
use crate::geometry::bezier::BezierPatch;
use crate::geometry::{Aabb, Quad, Ray, ShapeRef};
use crate::scene::material::MaterialKind;
use crate::scene::Scene;

/// The bounds of object `object`'s patches (`None` when it has none).
pub fn surface_bounds(scene: &Scene, object: u32) -> Option<Aabb> {
    scene
        .geometry
        .patches()
        .iter()
        .filter(|(_, id)| *id == object)
        .map(|(p, _)| p.bounds())
        .reduce(|a, b| a.union(b))
}

/// What one parameter moves.
#[derive(Clone, Debug)]
pub enum Handle {
    /// Bézier control points that coincide, `(patch, point index)`, moved together.
    Points(Vec<(usize, usize)>),
    /// Point `index` of the geometry's net `net` (a B-spline surface's own control point):
    /// its patches are derived again when it moves.
    Net {
        /// The net's number among the geometry's.
        net: usize,
        /// The point's index (`u` fastest).
        index: usize,
    },
}

/// The movable control points of a design: each parameter `θ` moves one control point along
/// a fixed unit direction from where it started. A surface read with its own net (B-spline or
/// NURBS from OBJ or USD) moves the net's points, and each Bézier point of its patches moves
/// with the net's points by the fixed coefficients of knot insertion; other patches move
/// their Bézier points, coincident ones welded, so that seams stay closed.
#[derive(Clone, Debug, Default)]
pub struct DesignParams {
    /// For each patch with parameters, its points' dependence on them: `(point index,
    /// parameter, coefficient)`.
    by_patch: HashMap<usize, Vec<(usize, Param, f64)>>,
    /// Each parameter's direction (unit).
    pub dirs: Vec<DVec3>,
    /// What each parameter moves.
    pub handles: Vec<Handle>,
    /// Each parameter's point where the design started.
    pub origins: Vec<DVec3>,
    /// Pairs of parameters next to each other in a control net (for smoothness).
    pub neighbours: Vec<(Param, Param)>,
}

impl DesignParams {
    /// The control points of `object`'s patches in `scene`, each moving along `dir`, points
    /// that coincide (to a billionth of the object's size) welded.
    /// Rational surfaces are refused: their weights change the derivatives, which are not
    /// written here.
    pub fn of_object(scene: &Scene, object: u32, dir: DVec3) -> Result<Self, String> {
        let dir = dir
            .try_normalize()
            .ok_or("the direction the points move along is zero")?;
        let geometry = &scene.geometry;
        let mut out = Self::default();
        // Points closer than a billionth of the object's size are one point: subdivided
        // neighbours' shared edges agree to rounding, not always bit for bit.
        let size = surface_bounds(scene, object).map_or(1.0, |b| (b.max - b.min).length().max(1e-300));
        let quantum = 1e-9 * size;
        let mut welded: HashMap<[i64; 3], Param> = HashMap::new();
        let mut seen_nets = Vec::new();
        for (k, (patch, id)) in geometry.patches().iter().enumerate() {
            if *id != object {
                continue;
            }
            if geometry.patch_weights(k).is_some() {
                return Err(
                    "rational surfaces cannot be designed yet: their weights change the derivatives".into(),
                );
            }
            if let Some(n) = geometry.patch_net(k) {
                if !seen_nets.contains(&n) {
                    seen_nets.push(n);
                    out.add_net(scene, n, dir)?;
                }
                continue;
            }
            let mut own = Vec::with_capacity(16);
            let mut ids = [0 as Param; 16];
            for (i, p) in patch.points.iter().enumerate() {
                let key = p.to_array().map(|c| (c / quantum).round() as i64);
                let param = *welded.entry(key).or_insert_with(|| {
                    out.dirs.push(dir);
                    out.handles.push(Handle::Points(Vec::new()));
                    out.origins.push(*p);
                    (out.dirs.len() - 1) as Param
                });
                if let Handle::Points(points) = &mut out.handles[param as usize] {
                    points.push((k, i));
                }
                own.push((i, param, 1.0));
                ids[i] = param;
            }
            out.by_patch.insert(k, own);
            for i in 0..4 {
                for j in 0..4 {
                    if i < 3 {
                        out.neighbours.push((ids[4 * i + j], ids[4 * (i + 1) + j]));
                    }
                    if j < 3 {
                        out.neighbours.push((ids[4 * i + j], ids[4 * i + j + 1]));
                    }
                }
            }
        }
        if out.dirs.is_empty() {
            return Err("the object has no patches".into());
        }
        out.neighbours.retain(|(a, b)| a != b);
        out.neighbours.sort_unstable();
        out.neighbours.dedup();
        Ok(out)
    }

    /// Adds net `n`'s points as parameters, each with the coefficients by which the net's
    /// patches' points follow it (found by moving it by `dir`: knot insertion is linear).
    fn add_net(&mut self, scene: &Scene, n: usize, dir: DVec3) -> Result<(), String> {
        let placed = &scene.geometry.nets()[n];
        if placed.net.weights.is_some() {
            return Err(
                "rational surfaces cannot be designed yet: their weights change the derivatives".into(),
            );
        }
        let (nu, nv) = placed.net.size();
        let first = self.dirs.len() as Param;
        for (index, p) in placed.net.surface.points.iter().enumerate() {
            let param = self.dirs.len() as Param;
            self.dirs.push(dir);
            self.handles.push(Handle::Net { net: n, index });
            self.origins.push(*p);
            let (_, moved) = placed
                .moved(&[(index, *p + dir)])
                .ok_or("the surface's net cannot be moved")?;
            for (k, patch) in moved {
                let before = &scene.geometry.patches()[k].0;
                for (i, (a, b)) in patch.points.iter().zip(&before.points).enumerate() {
                    let coefficient = (*a - *b).dot(dir);
                    if coefficient.abs() > 1e-12 {
                        self.by_patch.entry(k).or_default().push((i, param, coefficient));
                    }
                }
            }
        }
        for j in 0..nv {
            for i in 0..nu {
                let at = |i: usize, j: usize| first + (i + nu * j) as Param;
                if i + 1 < nu {
                    self.neighbours.push((at(i, j), at(i + 1, j)));
                }
                if j + 1 < nv {
                    self.neighbours.push((at(i, j), at(i, j + 1)));
                }
            }
        }
        Ok(())
    }

    /// How many parameters there are.
    pub fn len(&self) -> usize {
        self.dirs.len()
    }

    /// Whether there are none.
    pub fn is_empty(&self) -> bool {
        self.dirs.is_empty()
    }

    /// Moves every parameter's points to `origin + θ · dir` in `scene`'s geometry; false when
    /// the geometry refuses a move (a point that is not finite).
    pub fn apply(&self, scene: &mut Scene, theta: &[f64]) -> bool {
        let mut net_moves: HashMap<usize, Vec<(usize, DVec3)>> = HashMap::new();
        let mut edited: HashMap<usize, BezierPatch> = HashMap::new();
        for (q, handle) in self.handles.iter().enumerate() {
            let position = self.origins[q] + theta[q] * self.dirs[q];
            match handle {
                Handle::Points(points) => {
                    for &(k, i) in points {
                        edited
                            .entry(k)
                            .or_insert_with(|| scene.geometry.patches()[k].0)
                            .points[i] = position;
                    }
                }
                Handle::Net { net, index } => net_moves.entry(*net).or_default().push((*index, position)),
            }
        }
        let mut edits: Vec<(usize, BezierPatch)> = edited
            .into_iter()
            .filter(|(k, p)| scene.geometry.patches()[*k].0 != *p)
            .collect();
        edits.sort_by_key(|(k, _)| *k);
        if !edits.is_empty() && scene.geometry.update_patches(&edits).is_none() {
            return false;
        }
        let mut nets: Vec<_> = net_moves.into_iter().collect();
        nets.sort_by_key(|(n, _)| *n);
        nets.into_iter()
            .all(|(n, moves)| scene.geometry.move_net_points(n, &moves).is_some())
    }
}

/// The receiver: a quad object, `corner + s edge_u + t edge_v` for `s, t` in `[0, 1]`.
#[derive(Clone, Copy, Debug)]
pub struct Receiver {
    /// Its object number.
    pub object: u32,
    /// Its shape.
    pub quad: Quad,
}

/// The cubic Bernstein polynomials at `t` with their first and second derivatives.
fn bases(t: f64) -> [[f64; 4]; 3] {
    let s = 1.0 - t;
    [
        [s * s * s, 3.0 * t * s * s, 3.0 * t * t * s, t * t * t],
        [
            -3.0 * s * s,
            3.0 * s * (1.0 - 3.0 * t),
            6.0 * t - 9.0 * t * t,
            3.0 * t * t,
        ],
        [6.0 * s, -12.0 + 18.0 * t, 6.0 - 18.0 * t, 6.0 * t],
    ]
}

/// The parameters a hit's derivatives involve: those of `o`, `d` and the patch's points.
fn involved(o: &D3, d: &D3, own: Option<&Vec<(usize, Param, f64)>>) -> Vec<Param> {
    let mut ids: Vec<Param> = o.g.iter().chain(&d.g).map(|e| e.0).collect();
    ids.extend(own.into_iter().flatten().map(|e| e.1));
    ids.sort_unstable();
    ids.dedup();
    ids
}

/// The point where the ray `o + t d` meets `patch` at its own `(u, v)`, and the patch's unit
/// normal `S_u × S_v` there, with their derivatives.
fn patch_hit(
    patch: &BezierPatch,
    uv: DVec2,
    (o, d): (&D3, &D3),
    own: Option<&Vec<(usize, Param, f64)>>,
    dirs: &[DVec3],
) -> Option<(D3, D3)> {
    let [bu, bu1, bu2] = bases(uv.x);
    let [bv, bv1, bv2] = bases(uv.y);
    let mut s = [DVec3::ZERO; 6]; // S, S_u, S_v, S_uu, S_uv, S_vv
    for i in 0..4 {
        for j in 0..4 {
            let p = patch.points[4 * i + j];
            for (k, w) in [
                bu[i] * bv[j],
                bu1[i] * bv[j],
                bu[i] * bv1[j],
                bu2[i] * bv[j],
                bu1[i] * bv1[j],
                bu[i] * bv2[j],
            ]
            .into_iter()
            .enumerate()
            {
                s[k] += w * p;
            }
        }
    }
    let [sp, su, sv, suu, suv, svv] = s;
    let t = (sp - o.v).dot(d.v) / d.v.length_squared();
    let inverse = {
        let j = DMat3::from_cols(d.v, -su, -sv);
        (j.determinant().abs() > 1e-300).then(|| j.inverse())?
    };
    let normal = su.cross(sv);
    let length = normal.length();
    if length.is_nan() || length <= 0.0 {
        return None;
    }
    let n = normal / length;
    let (mut point_g, mut normal_g) = (Vec::new(), Vec::new());
    for q in involved(o, d, own) {
        let (mut s_q, mut su_q, mut sv_q) = (DVec3::ZERO, DVec3::ZERO, DVec3::ZERO);
        for &(idx, _, c) in own.into_iter().flatten().filter(|e| e.1 == q) {
            let (i, j) = (idx / 4, idx % 4);
            let dir = c * dirs[q as usize];
            s_q += bu[i] * bv[j] * dir;
            su_q += bu1[i] * bv[j] * dir;
            sv_q += bu[i] * bv1[j] * dir;
        }
        let x = inverse * (s_q - o.d(q) - t * d.d(q));
        let (du, dv) = (x.y, x.z);
        point_g.push((q, su * du + sv * dv + s_q));
        let dsu = suu * du + suv * dv + su_q;
        let dsv = suv * du + svv * dv + sv_q;
        let dnormal = dsu.cross(sv) + su.cross(dsv);
        normal_g.push((q, (dnormal - n * n.dot(dnormal)) / length));
    }
    Some((D3 { v: sp, g: point_g }, D3 { v: n, g: normal_g }))
}

/// `d` reflected about the unit normal `n`.
fn reflect(d: &D3, n: &D3) -> D3 {
    d.add(&n.scale_by(&d.dot(n).scale(-2.0)))
}

/// The unit direction `d` refracted into (or out of) glass of index `ior` at the unit normal
/// `n` (either side), or reflected when it cannot leave (total internal reflection).
fn refract(d: &D3, n: &D3, ior: f64) -> D3 {
    let mut cos_in = d.dot(n).scale(-1.0);
    let mut n = n.clone();
    let eta = if cos_in.v < 0.0 {
        n = n.scale(-1.0);
        cos_in = cos_in.scale(-1.0);
        ior
    } else {
        1.0 / ior
    };
    let sin2 = D1::constant(1.0).add(&cos_in.mul(&cos_in).scale(-1.0));
    let k = D1::constant(1.0).add(&sin2.scale(-eta * eta));
    if k.v <= 0.0 {
        return reflect(d, &n);
    }
    let coefficient = cos_in.scale(eta).add(&k.sqrt().scale(-1.0));
    d.scale(eta).add(&n.scale_by(&coefficient))
}

/// Where the ray `o + τ d` meets the receiver's plane, as `(s, t)` with derivatives, if
/// inside it and ahead.
fn landing(o: &D3, d: &D3, quad: &Quad) -> Option<[D1; 2]> {
    let j = DMat3::from_cols(d.v, -quad.edge_u, -quad.edge_v);
    if j.determinant().abs() <= 1e-300 {
        return None;
    }
    let inverse = j.inverse();
    let x = inverse * (quad.corner - o.v);
    let (tau, s, t) = (x.x, x.y, x.z);
    if !(tau > 0.0 && (0.0..=1.0).contains(&s) && (0.0..=1.0).contains(&t)) {
        return None;
    }
    let (mut gs, mut gt) = (Vec::new(), Vec::new());
    for q in involved(o, d, None) {
        let dx = inverse * (-o.d(q) - tau * d.d(q));
        gs.push((q, dx.y));
        gt.push((q, dx.z));
    }
    Some([D1 { v: s, g: gs }, D1 { v: t, g: gt }])
}

/// Traces a photon leaving along `ray` through smooth glass and mirror surfaces (at most
/// `bounces` of them) to the receiver: its landing point `(s, t)` with its derivatives with
/// respect to `params`, or `None` when it is lost (meets anything else, a rough or non-patch
/// specular surface included, or leaves the scene).
pub fn land(
    scene: &Scene,
    params: &DesignParams,
    receiver: &Receiver,
    ray: Ray,
    bounces: usize,
) -> Option<[D1; 2]> {
    let (mut o, mut d) = (D3::constant(ray.origin), D3::constant(ray.dir.normalize()));
    let mut ray = ray;
    for _ in 0..=bounces {
        let hit = scene.geometry.intersect(&ray, f64::INFINITY)?;
        if hit.object == receiver.object {
            return landing(&o, &d, &receiver.quad);
        }
        let ShapeRef::Patch(k) = hit.shape else {
            return None;
        };
        let k = k as usize;
        let object = scene.objects.get(hit.object as usize)?;
        let kind = &scene.materials.get(object.material)?.kind;
        let w = scene.geometry.patch_domains()[k];
        let uv = hit.uv();
        let local = DVec2::new((uv.x - w.u0) / (w.u1 - w.u0), (uv.y - w.v0) / (w.v1 - w.v0));
        let patch = &scene.geometry.patches()[k].0;
        let (p, n) = patch_hit(patch, local, (&o, &d), params.by_patch.get(&k), &params.dirs)?;
        d = match kind {
            MaterialKind::Glass { ior, roughness, .. } if *roughness == 0.0 => refract(&d, &n, *ior),
            MaterialKind::Mirror { roughness } if *roughness == 0.0 => reflect(&d, &n),
            _ => return None,
        };
        o = p;
        ray = hit.spawn(d.v);
    }
    None
}
