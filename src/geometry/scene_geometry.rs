//! All of a scene's shapes behind one SAH BVH: spheres, quads, triangle meshes and Bézier
//! patches (as prepared leaves, or whole for the per-ray reference intersector), plus
//! unbounded planes tested beside the BVH.
//!
//! ```
//! use caustic::geometry::{GeometryBuilder, Ray, Sphere};
//! use glam::DVec3;
//!
//! let mut builder = GeometryBuilder::default();
//! builder.add_sphere(Sphere { center: DVec3::ZERO, radius: 1.0 }, 7);
//! let geometry = builder.build();
//! let hit = geometry.intersect(&Ray::new(DVec3::new(0.0, 0.0, -3.0), DVec3::Z), f64::INFINITY);
//! assert_eq!(hit.map(|h| (h.t, h.object)), Some((2.0, 7)));
//! ```

use std::sync::Arc;

use glam::{DVec2, DVec3};

use super::aabb::Aabb;
use super::bezier::BezierPatch;
use super::bvh::{Bvh, FLAT_PRIMITIVES};
use super::freeform::DomainPatch;
use super::mesh::TriangleMesh;
use super::net::PlacedNet;
use super::patch::{
    intersect_leaf, intersect_per_ray_weighted, intersect_rational_leaf, leaf_occludes,
    rational_leaf_occludes, subdivide_weighted, PatchHit, PatchLeaf, PatchPoint, RayFrame, SubdivisionParams,
    Window,
};
use super::quad::{Plane, Quad};
use super::rational::{window_weights, RationalPatch, Weights};
use super::ray::{spawn_ray, Ray};
use super::sphere::Sphere;
use super::sphere_batch::SphereBatch;
use super::trim::TrimRegion;
use super::trimmed::{boundary_leaves, first_kept, kept_leaves, trim_mesh};

/// Which ray/patch intersector the geometry uses.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum PatchMethod {
    /// Leaves prepared once per scene, in the BVH; Newton per leaf (the default).
    Prepared(SubdivisionParams),
    /// The seed's per-ray queue subdivision to `depth` levels, then Newton (reference).
    PerRay {
        /// Subdivision levels before Newton.
        depth: u32,
    },
}

impl Default for PatchMethod {
    fn default() -> Self {
        PatchMethod::Prepared(SubdivisionParams::default())
    }
}

/// One thing the BVH holds; the closed set of shapes (pbrt-style `match`, no trait objects).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Primitive {
    /// `spheres[i]`.
    Sphere(u32),
    /// `quads[i]`.
    Quad(u32),
    /// Triangle `triangle` of `meshes[mesh]`.
    Triangle {
        /// Mesh index.
        mesh: u32,
        /// Triangle index within the mesh.
        triangle: u32,
    },
    /// `leaves[i]` (prepared patch method).
    PatchLeaf(u32),
    /// `patches[i]` whole (per-ray patch method).
    Patch(u32),
    /// `planes[i]`: unbounded, so tested beside the BVH rather than in it.
    Plane(u32),
}

/// Which shape a hit landed on: kind and index within its kind (stable across BVH builds).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum ShapeRef {
    /// A sphere.
    Sphere(u32),
    /// A quad.
    Quad(u32),
    /// A plane.
    Plane(u32),
    /// A mesh.
    Mesh(u32),
    /// A Bézier patch.
    Patch(u32),
}

/// A ray's nearest intersection.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    /// Distance along the ray.
    pub t: f64,
    /// The hit point.
    pub point: DVec3,
    /// Geometric unit normal as the shape defines it (not flipped towards the ray).
    pub normal: DVec3,
    /// Unit shading normal (interpolated for meshes with normals), same side as `normal`.
    pub shading_normal: DVec3,
    /// [`Hit::uv`], but for spheres, whose `(u,v)` (two inverse trigonometric functions) is
    /// computed from the normal only when asked for: most hits never need it.
    param: DVec2,
    /// The caller's object id given when the shape was added.
    pub object: u32,
    /// The shape hit.
    pub shape: ShapeRef,
    /// The patch point hit (the patch's own `(u,v)`, before any domain mapping), for rays
    /// that leave it ([`Hit::departure`]).
    patch_point: Option<PatchPoint>,
}

/// A ray that leaves a surface closer to it than this (the sine of the angle to the tangent
/// plane) records no departure point ([`Hit::departure`]): its own crossing of the surface,
/// behind its offset origin, may then lie far from the point it left.
const GRAZING_DEPARTURE: f64 = 1e-3;

impl Hit {
    /// Surface parameters: the original patch's `(u,v)`, sphere `(φ/2π, θ/π)`, quad `(a,b)`,
    /// plane coordinates in scene units, mesh texture coordinates (or barycentrics).
    pub fn uv(&self) -> DVec2 {
        match self.shape {
            ShapeRef::Sphere(_) => Sphere::uv_of_normal(self.normal),
            _ => self.param,
        }
    }

    /// A ray leaving this hit in direction `dir`, offset so it cannot re-hit this point, and
    /// carrying its departure point ([`Hit::departure`]).
    pub fn spawn(&self, dir: DVec3) -> Ray {
        spawn_ray(self.point, self.normal, dir).leaving(self.departure(dir))
    }

    /// Where a ray leaving this hit in direction `dir` leaves a Bézier patch, so that the
    /// patch's intersector need not find that crossing again ([`Ray::leaving`]): the patch
    /// point hit, unless the ray leaves at a grazing angle or the hit is on another shape.
    pub fn departure(&self, dir: DVec3) -> Option<PatchPoint> {
        self.patch_point
            .filter(|_| self.normal.dot(dir).abs() > GRAZING_DEPARTURE * dir.length())
    }
}

/// Collects shapes, then [`GeometryBuilder::build`]s the [`SceneGeometry`].
#[derive(Clone, Debug, Default)]
pub struct GeometryBuilder {
    spheres: Vec<(Sphere, u32)>,
    quads: Vec<(Quad, u32)>,
    planes: Vec<(Plane, u32)>,
    meshes: Vec<(TriangleMesh, u32)>,
    patches: Vec<(BezierPatch, u32)>,
    /// Each patch's `(u,v)` window in the parameters of the surface it came from.
    patch_domains: Vec<Window>,
    /// Each patch's weights, when it is rational.
    patch_weights: Vec<Option<Box<Weights>>>,
    /// Each patch's surface's trim loops, when it is trimmed.
    patch_trims: Vec<Option<Arc<TrimRegion>>>,
    /// The B-spline and NURBS surfaces the patches came from, with their patches.
    nets: Vec<PlacedNet>,
    /// The patch intersector.
    pub patch_method: PatchMethod,
}

impl GeometryBuilder {
    /// An empty builder whose patches will use `patch_method`.
    pub fn with_patch_method(patch_method: PatchMethod) -> Self {
        Self {
            patch_method,
            ..Default::default()
        }
    }

    /// Adds a sphere tagged with `object`.
    pub fn add_sphere(&mut self, sphere: Sphere, object: u32) -> ShapeRef {
        self.spheres.push((sphere, object));
        ShapeRef::Sphere(self.spheres.len() as u32 - 1)
    }
    /// Adds a quad tagged with `object`.
    pub fn add_quad(&mut self, quad: Quad, object: u32) -> ShapeRef {
        self.quads.push((quad, object));
        ShapeRef::Quad(self.quads.len() as u32 - 1)
    }
    /// Adds an infinite plane tagged with `object`.
    pub fn add_plane(&mut self, plane: Plane, object: u32) -> ShapeRef {
        self.planes.push((plane, object));
        ShapeRef::Plane(self.planes.len() as u32 - 1)
    }
    /// Adds a triangle mesh tagged with `object`.
    pub fn add_mesh(&mut self, mesh: TriangleMesh, object: u32) -> ShapeRef {
        self.meshes.push((mesh, object));
        ShapeRef::Mesh(self.meshes.len() as u32 - 1)
    }
    /// Bézier patches added so far.
    pub fn patch_count(&self) -> usize {
        self.patches.len()
    }

    /// Adds a Bézier patch tagged with `object`; its hits report `(u,v)` in `[0,1]²`.
    pub fn add_patch(&mut self, patch: BezierPatch, object: u32) -> ShapeRef {
        self.add_patch_in(patch, Window::FULL, object)
    }

    /// Adds a Bézier patch that is the piece `domain` of a larger surface (a B-spline span):
    /// its hits report `(u,v)` in the surface's parameters, so textures follow the surface.
    pub fn add_patch_in(&mut self, patch: BezierPatch, domain: Window, object: u32) -> ShapeRef {
        self.add_weighted_patch_in(patch, None, domain, object)
    }

    /// [`GeometryBuilder::add_patch_in`] for a patch that may be rational: `patch` holds its
    /// control points, `weights` their weights, which the caller has checked are positive
    /// ([`crate::geometry::rational::weights_error`]).
    pub fn add_weighted_patch_in(
        &mut self,
        patch: BezierPatch,
        weights: Option<Weights>,
        domain: Window,
        object: u32,
    ) -> ShapeRef {
        let piece = DomainPatch {
            window: domain,
            weights,
            ..DomainPatch::whole(patch)
        };
        self.add_surface_patch(piece, object)
    }

    /// Adds a piece of a surface that may be rational and trimmed
    /// ([`GeometryBuilder::add_weighted_patch_in`]; hits the trim loops cut away pass it).
    pub fn add_surface_patch(&mut self, piece: DomainPatch, object: u32) -> ShapeRef {
        self.patches.push((piece.patch, object));
        self.patch_domains.push(piece.window);
        self.patch_weights.push(piece.weights.map(Box::new));
        self.patch_trims.push(piece.trim);
        let k = self.patches.len() - 1;
        if let Some(net) = piece.net {
            match self.nets.last_mut() {
                Some(last)
                    if Arc::ptr_eq(&last.net, &net) && last.patches.end == k && last.object == object =>
                {
                    last.patches.end = k + 1
                }
                _ => self.nets.push(PlacedNet {
                    net,
                    object,
                    patches: k..k + 1,
                }),
            }
        }
        ShapeRef::Patch(k as u32)
    }

    /// The spheres, quads and mesh triangles as primitives, with their bounds, in that order.
    fn shape_primitives(&self) -> (Vec<Primitive>, Vec<Aabb>) {
        let mut primitives = Vec::new();
        let mut bounds = Vec::new();
        for (k, (s, _)) in self.spheres.iter().enumerate() {
            primitives.push(Primitive::Sphere(k as u32));
            bounds.push(s.bounds());
        }
        for (k, (q, _)) in self.quads.iter().enumerate() {
            primitives.push(Primitive::Quad(k as u32));
            bounds.push(q.bounds());
        }
        for (m, (mesh, _)) in self.meshes.iter().enumerate() {
            for t in 0..mesh.indices.len() {
                primitives.push(Primitive::Triangle {
                    mesh: m as u32,
                    triangle: t as u32,
                });
                bounds.push(mesh.triangle_bounds(t));
            }
        }
        (primitives, bounds)
    }

    /// Prepares patches (per the patch method) and builds the BVH.
    pub fn build(self) -> SceneGeometry {
        let patch_scales: Vec<f64> = self
            .patches
            .iter()
            .map(|(p, _)| p.bounds().diagonal().length())
            .collect();
        let mut leaves = Vec::new();
        let mut patch_method = self.patch_method;
        if let PatchMethod::Prepared(params) = &mut patch_method {
            // Each patch's share of the scene's leaves: an edit re-prepares it within the same.
            params.max_leaves = params
                .max_leaves
                .min(super::patch::leaf_budget(self.patches.len()));
            for (k, ((patch, _), w)) in self.patches.iter().zip(&self.patch_weights).enumerate() {
                let trim = (self.patch_trims[k].as_deref(), &self.patch_domains[k]);
                leaves.extend(prepared_leaves(patch, w.as_deref(), trim, k, params));
            }
        }
        let (mut primitives, mut bounds) = self.shape_primitives();
        match self.patch_method {
            PatchMethod::Prepared(_) => {
                for (k, leaf) in leaves.iter().enumerate() {
                    primitives.push(Primitive::PatchLeaf(k as u32));
                    bounds.push(leaf.bounds);
                }
            }
            PatchMethod::PerRay { .. } => {
                for (k, (p, _)) in self.patches.iter().enumerate() {
                    primitives.push(Primitive::Patch(k as u32));
                    bounds.push(p.bounds().padded(1e-9 * patch_scales[k]));
                }
            }
        }
        let bvh = Bvh::build(&bounds);
        let flat_spheres = flat_spheres(&bvh, &primitives, &self.spheres);
        // Grown by pushing: give back the spare capacity (up to half of a large scene's).
        let (mut patches, mut patch_domains, mut patch_weights, mut patch_trims) = (
            self.patches,
            self.patch_domains,
            self.patch_weights,
            self.patch_trims,
        );
        leaves.shrink_to_fit();
        primitives.shrink_to_fit();
        bounds.shrink_to_fit();
        patches.shrink_to_fit();
        patch_domains.shrink_to_fit();
        patch_weights.shrink_to_fit();
        patch_trims.shrink_to_fit();
        SceneGeometry {
            primitive_bounds: bounds,
            spheres: self.spheres,
            quads: self.quads,
            planes: self.planes,
            meshes: self.meshes,
            leaf_weights: leaf_weights(&leaves, &patch_weights),
            leaf_trimmed: leaf_trimmed(&leaves, &patch_trims, &patch_domains),
            patches,
            patch_domains,
            patch_weights,
            patch_trims,
            nets: self.nets,
            patch_scales,
            leaves,
            primitives,
            bvh,
            flat_spheres,
            patch_method,
        }
    }
}

/// When some patch is rational, each leaf's weights (a rational patch's over the leaf's
/// window, none for a polynomial patch's leaf); nothing otherwise.
fn leaf_weights(leaves: &[PatchLeaf], patch_weights: &[Option<Box<Weights>>]) -> Vec<Option<Weights>> {
    if patch_weights.iter().all(Option::is_none) {
        return Vec::new();
    }
    leaves
        .iter()
        .map(|l| {
            patch_weights[l.patch as usize]
                .as_deref()
                .map(|w| window_weights(w, &l.window))
        })
        .collect()
}

/// Patch `k`'s leaves, subdivided per `params`, less those its trim loops (with its window in
/// their surface) cut away wholly.
fn prepared_leaves(
    patch: &BezierPatch,
    weights: Option<&Weights>,
    (trim, domain): (Option<&TrimRegion>, &Window),
    k: usize,
    params: &SubdivisionParams,
) -> Vec<PatchLeaf> {
    kept_leaves(subdivide_weighted(patch, weights, k as u32, params), trim, domain)
}

/// When some patch is trimmed, whether each leaf tests its hits against the trim loops
/// ([`boundary_leaves`]); nothing otherwise.
fn leaf_trimmed(leaves: &[PatchLeaf], trims: &[Option<Arc<TrimRegion>>], domains: &[Window]) -> Vec<bool> {
    boundary_leaves(leaves, |k| trims[k].as_deref(), |k| domains[k])
}

/// The spheres of a tree [`Bvh::traverse`] does not walk, when it holds nothing else, in the
/// order it visits them, each tagged with its index among the spheres ([`SphereBatch`]).
fn flat_spheres(bvh: &Bvh, primitives: &[Primitive], spheres: &[(Sphere, u32)]) -> Option<SphereBatch> {
    if bvh.order.is_empty() || bvh.order.len() > FLAT_PRIMITIVES {
        return None;
    }
    let lanes: Option<Vec<(Sphere, u32, u32)>> = bvh
        .order
        .iter()
        .map(|&k| match primitives[k as usize] {
            Primitive::Sphere(i) => Some((spheres[i as usize].0, i, spheres[i as usize].1)),
            _ => None,
        })
        .collect();
    lanes.map(SphereBatch::new)
}

/// Shapes and the BVH over them, ready for rays.
#[derive(Clone, Debug)]
pub struct SceneGeometry {
    spheres: Vec<(Sphere, u32)>,
    quads: Vec<(Quad, u32)>,
    planes: Vec<(Plane, u32)>,
    meshes: Vec<(TriangleMesh, u32)>,
    patches: Vec<(BezierPatch, u32)>,
    patch_domains: Vec<Window>,
    patch_weights: Vec<Option<Box<Weights>>>,
    patch_trims: Vec<Option<Arc<TrimRegion>>>,
    nets: Vec<PlacedNet>,
    /// With a rational patch, each leaf's weights ([`leaf_weights`]); otherwise empty.
    leaf_weights: Vec<Option<Weights>>,
    /// With a trimmed patch, whether each leaf tests its hits against the trims
    /// ([`leaf_trimmed`]); otherwise empty.
    leaf_trimmed: Vec<bool>,
    patch_scales: Vec<f64>,
    leaves: Vec<PatchLeaf>,
    /// Everything in the BVH; its leaves index this list. Patch leaves (or whole patches,
    /// per-ray method) come last, in patch order.
    primitives: Vec<Primitive>,
    /// Bounds of `primitives[k]`, kept for refitting the BVH after an edit.
    primitive_bounds: Vec<Aabb>,
    bvh: Bvh,
    /// The spheres, tested at once, when they are all the BVH holds and it is not walked.
    flat_spheres: Option<SphereBatch>,
    patch_method: PatchMethod,
}

/// The raw result of a primitive test, before the hit record is filled in.
#[derive(Clone, Copy)]
struct Candidate {
    t: f64,
    primitive: Primitive,
    /// Shape-specific parameters: patch `(u,v)`, quad `(a,b)`, triangle barycentrics.
    param: DVec2,
    /// A patch's unit normal where its root finder knew it ([`PatchHit::normal`]).
    normal: Option<DVec3>,
}

impl SceneGeometry {
    /// The same shapes built again with another patch intersector, or with every patch
    /// replaced by its tessellation (`tessellate_segments` quads per patch edge, one triangle
    /// mesh per patch, same object, the patch's (u,v) as texture coordinates): what exactness
    /// buys is measured against these.
    pub fn rebuilt(&self, method: PatchMethod, tessellate_segments: Option<usize>) -> SceneGeometry {
        let mut builder = GeometryBuilder {
            spheres: self.spheres.clone(),
            quads: self.quads.clone(),
            planes: self.planes.clone(),
            meshes: self.meshes.clone(),
            patches: Vec::new(),
            patch_domains: Vec::new(),
            patch_weights: Vec::new(),
            patch_trims: Vec::new(),
            nets: Vec::new(),
            patch_method: method,
        };
        for (k, ((p, object), domain)) in self.patches.iter().zip(&self.patch_domains).enumerate() {
            match tessellate_segments {
                Some(n) => {
                    let mut mesh = super::tessellate::tessellate_weighted(p, self.patch_weights(k), n);
                    if let Some(trim) = self.patch_trim(k) {
                        trim_mesh(&mut mesh, trim, domain);
                    }
                    for uv in &mut mesh.texcoords {
                        *uv = domain.map(uv.x, uv.y);
                    }
                    builder.add_mesh(mesh, *object)
                }
                None => builder.add_surface_patch(self.domain_patch(k), *object),
            };
        }
        builder.build()
    }

    /// Bounds of the bounded shapes (planes excluded).
    pub fn bounds(&self) -> Aabb {
        self.bvh.bounds()
    }

    /// The sphere around all geometry (centre, radius), or `None` when there is none or when
    /// the scene has an infinite plane, which no sphere holds (photons aimed at a sphere would
    /// then miss the plane outside it).
    pub fn bounding_sphere(&self) -> Option<(DVec3, f64)> {
        let b = self.bounds();
        (!b.is_empty() && self.planes.is_empty()).then(|| (b.centroid(), 0.5 * b.diagonal().length()))
    }

    /// The patches, with their object ids.
    pub fn patches(&self) -> &[(BezierPatch, u32)] {
        &self.patches
    }

    /// Each patch's `(u,v)` window in the surface it came from (`[0,1]²` for a whole patch),
    /// in the order of [`SceneGeometry::patches`].
    pub fn patch_domains(&self) -> &[Window] {
        &self.patch_domains
    }

    /// Patch `k`'s weights, when it is rational (its control points are
    /// [`SceneGeometry::patches`]' own).
    pub fn patch_weights(&self, k: usize) -> Option<&Weights> {
        self.patch_weights.get(k).and_then(|w| w.as_deref())
    }

    /// Patch `k`'s surface's trim loops, when it is trimmed (shared by the surface's patches).
    pub fn patch_trim(&self, k: usize) -> Option<&TrimRegion> {
        self.patch_trims.get(k).and_then(|t| t.as_deref())
    }

    /// Patch `k` as a piece of its surface: points, window, weights and trim loops.
    pub fn domain_patch(&self, k: usize) -> DomainPatch {
        DomainPatch {
            patch: self.patches[k].0,
            window: self.patch_domains[k],
            weights: self.patch_weights(k).copied(),
            trim: self.patch_trims[k].clone(),
            net: self.patch_net(k).map(|n| self.nets[n].net.clone()),
        }
    }

    /// The B-spline and NURBS surfaces the patches came from (read from OBJ), each with its
    /// object and its patches: what an editor shows and moves instead of their Bézier points.
    pub fn nets(&self) -> &[PlacedNet] {
        &self.nets
    }

    /// The net patch `k` was derived from, as an index into [`SceneGeometry::nets`].
    pub fn patch_net(&self, k: usize) -> Option<usize> {
        let n = self.nets.partition_point(|n| n.patches.end <= k);
        self.nets.get(n).filter(|n| n.patches.contains(&k)).map(|_| n)
    }

    /// Moves points of net `n` (`(index, position)`, `u` fastest) and derives its patches
    /// again, re-preparing those that changed ([`SceneGeometry::update_patches`]). Returns the
    /// changed patches as they now are, with their indices; `None` (changing nothing) for a net
    /// or point out of range or a position that is not finite.
    pub fn move_net_points(
        &mut self,
        n: usize,
        moves: &[(usize, DVec3)],
    ) -> Option<Vec<(usize, BezierPatch)>> {
        let (net, mut edits) = self.nets.get(n)?.moved(moves)?;
        // Only the patches the moved points' basis functions reach changed: the rest keep
        // their leaves.
        edits.retain(|(k, p)| self.patches[*k].0 != *p);
        self.update_patches(&edits)?;
        self.nets[n].net = Arc::new(net);
        Some(edits)
    }

    /// Whether leaf `leaf` tests its hits against trim loops, on a ray's path: a scene without
    /// trimmed patches keeps no flags, so this asks nothing more of it.
    #[inline(always)]
    fn trimmed_leaf(&self, leaf: u32) -> bool {
        self.leaf_trimmed.get(leaf as usize).copied().unwrap_or(false)
    }

    /// The nearest hit on leaf `i` in `t_range`, polynomial or rational.
    #[inline(always)]
    fn leaf_hit(
        &self,
        i: u32,
        frame: &RayFrame,
        span: (f64, f64),
        (t_min, t_max): (f64, f64),
    ) -> Option<PatchHit> {
        let leaf = &self.leaves[i as usize];
        match self.rational_weights(i) {
            None => intersect_leaf(leaf, frame, span, t_min, t_max),
            Some(w) => intersect_rational_leaf(leaf, w, frame, span, (t_min, t_max)),
        }
    }

    /// The nearest hit on leaf `i`, a trim curve crossing it, that the trim keeps.
    #[inline(never)]
    fn trimmed_leaf_hit(&self, i: u32, frame: &RayFrame, span: (f64, f64), t_max: f64) -> Option<PatchHit> {
        let k = self.leaves[i as usize].patch as usize;
        let trim = (self.patch_trim(k)?, &self.patch_domains[k]);
        first_kept(|t_min| self.leaf_hit(i, frame, span, (t_min, t_max)), trim)
    }

    /// Leaf `leaf`'s weights when its patch is rational, on a ray's path: a scene without
    /// rational patches keeps no leaf weights, so this asks nothing more of it.
    #[inline(always)]
    fn rational_weights(&self, leaf: u32) -> Option<&Weights> {
        self.leaf_weights.get(leaf as usize).and_then(Option::as_ref)
    }

    /// Moves control point `index` (0–15, `4i + j`) of patch `patch` to `position` and
    /// re-prepares that patch ([`SceneGeometry::update_patches`]). Returns `false` (changing
    /// nothing) for an index out of range or a non-finite position.
    pub fn set_control_point(&mut self, patch: usize, index: usize, position: DVec3) -> bool {
        let Some((p, _)) = self.patches.get(patch) else {
            return false;
        };
        if index >= 16 {
            return false;
        }
        let mut edited = *p;
        edited.points[index] = position;
        self.update_patches(&[(patch, edited)]).is_some()
    }

    /// Puts the sphere of object `object` (an area light's surface) at `sphere` and refits the
    /// BVH; `false` when no sphere belongs to that object.
    pub fn move_sphere(&mut self, object: u32, sphere: Sphere) -> bool {
        let Some(k) = self.spheres.iter().position(|(_, o)| *o == object) else {
            return false;
        };
        self.spheres[k].0 = sphere;
        self.primitive_bounds[k] = sphere.bounds();
        self.bvh.refit(&self.primitive_bounds);
        self.flat_spheres = flat_spheres(&self.bvh, &self.primitives, &self.spheres);
        true
    }

    /// The quad of object `object`, placed (its first, when it has several).
    pub fn quad_of(&self, object: u32) -> Option<Quad> {
        self.quads.iter().find(|(_, o)| *o == object).map(|(q, _)| *q)
    }

    /// Puts the quad of object `object` (an area light's surface) at `quad` and refits the
    /// BVH; `false` when no quad belongs to that object.
    pub fn move_quad(&mut self, object: u32, quad: Quad) -> bool {
        let Some(k) = self.quads.iter().position(|(_, o)| *o == object) else {
            return false;
        };
        self.quads[k].0 = quad;
        // Quads follow the spheres among the primitives (see `GeometryBuilder::build`).
        self.primitive_bounds[self.spheres.len() + k] = quad.bounds();
        self.bvh.refit(&self.primitive_bounds);
        true
    }

    /// Replaces patches (`(index, new patch)`; a later entry for the same index wins) and
    /// re-prepares only them: their leaves are subdivided again, and the BVH is refit when
    /// every edited patch keeps its number of leaves, or rebuilt over the unchanged bounds of
    /// everything else when one does not (nothing else is subdivided again). The result
    /// intersects like a scene built from scratch with the edited patches.
    ///
    /// Returns `None` (changing nothing) for an index out of range or a non-finite point.
    pub fn update_patches(&mut self, edits: &[(usize, BezierPatch)]) -> Option<PatchUpdate> {
        let valid =
            |(k, p): &(usize, BezierPatch)| *k < self.patches.len() && p.points.iter().all(|q| q.is_finite());
        if !edits.iter().all(valid) {
            return None;
        }
        // The last edit of each patch, in patch order.
        let edits: std::collections::BTreeMap<usize, BezierPatch> = edits.iter().copied().collect();
        for (&k, p) in &edits {
            self.patches[k].0 = *p;
            self.patch_scales[k] = p.bounds().diagonal().length();
        }
        let first = self.primitives.len()
            - match self.patch_method {
                PatchMethod::Prepared(_) => self.leaves.len(),
                PatchMethod::PerRay { .. } => self.patches.len(),
            };
        let refit = match self.patch_method {
            PatchMethod::Prepared(params) => {
                let fresh: Vec<(usize, Vec<PatchLeaf>)> = edits
                    .iter()
                    .map(|(&k, p)| {
                        let trim = (self.patch_trim(k), &self.patch_domains[k]);
                        (k, prepared_leaves(p, self.patch_weights(k), trim, k, &params))
                    })
                    .collect();
                self.replace_leaves(first, fresh)
            }
            PatchMethod::PerRay { .. } => {
                for &k in edits.keys() {
                    let padded = self.patches[k].0.bounds().padded(1e-9 * self.patch_scales[k]);
                    self.primitive_bounds[first + k] = padded;
                }
                true
            }
        };
        self.leaf_weights = leaf_weights(&self.leaves, &self.patch_weights);
        self.leaf_trimmed = leaf_trimmed(&self.leaves, &self.patch_trims, &self.patch_domains);
        if refit {
            self.bvh.refit(&self.primitive_bounds);
        } else {
            self.bvh = Bvh::build(&self.primitive_bounds);
        }
        self.flat_spheres = flat_spheres(&self.bvh, &self.primitives, &self.spheres);
        Some(PatchUpdate {
            patches: edits.len(),
            refit,
        })
    }

    /// Puts new leaves for some patches in place (leaves start at primitive `first`); returns
    /// whether every patch kept its leaf count (the BVH can then be refit).
    fn replace_leaves(&mut self, first: usize, fresh: Vec<(usize, Vec<PatchLeaf>)>) -> bool {
        let range = |leaves: &[PatchLeaf], k: u32| {
            leaves.partition_point(|l| l.patch < k)..leaves.partition_point(|l| l.patch <= k)
        };
        let same_counts = fresh
            .iter()
            .all(|(k, new)| range(&self.leaves, *k as u32).len() == new.len());
        if same_counts {
            for (k, new) in fresh {
                let r = range(&self.leaves, k as u32);
                for (i, leaf) in r.zip(new) {
                    self.primitive_bounds[first + i] = leaf.bounds;
                    self.leaves[i] = leaf;
                }
            }
            return true;
        }
        // Splice, keeping leaves in patch order, as a fresh build lays them out.
        let mut fresh = fresh.into_iter().peekable();
        let old = std::mem::take(&mut self.leaves);
        for k in 0..self.patches.len() as u32 {
            match fresh.next_if(|(e, _)| *e as u32 == k) {
                Some((_, new)) => self.leaves.extend(new),
                None => self.leaves.extend_from_slice(&old[range(&old, k)]),
            }
        }
        self.primitives.truncate(first);
        self.primitive_bounds.truncate(first);
        for (k, leaf) in self.leaves.iter().enumerate() {
            self.primitives.push(Primitive::PatchLeaf(k as u32));
            self.primitive_bounds.push(leaf.bounds);
        }
        false
    }

    /// The prepared leaves (empty for the per-ray method).
    pub fn patch_leaves(&self) -> &[PatchLeaf] {
        &self.leaves
    }

    /// Counts of what the BVH holds, for statistics.
    pub fn stats(&self) -> GeometryStats {
        GeometryStats {
            primitives: self.primitives.len(),
            bvh_nodes: self.bvh.nodes.len(),
            bvh_depth: self.bvh.depth(),
            patches: self.patches.len(),
            patch_leaves: self.leaves.len(),
        }
    }

    /// Where the geometry's memory goes: bytes held by each of its parts (its vectors'
    /// capacities times their elements' sizes), in the order the patches' data then the BVH's.
    pub fn memory(&self) -> Vec<(&'static str, usize)> {
        /// What a vector holds, its spare capacity included.
        #[allow(clippy::ptr_arg)]
        fn bytes<T>(v: &Vec<T>) -> usize {
            v.capacity() * std::mem::size_of::<T>()
        }
        let meshes: usize = self
            .meshes
            .iter()
            .map(|(m, _)| bytes(&m.positions) + bytes(&m.normals) + bytes(&m.texcoords) + bytes(&m.indices))
            .sum();
        vec![
            (
                "patches (control points, domains, scales, weights, trims)",
                bytes(&self.patches)
                    + bytes(&self.patch_domains)
                    + bytes(&self.patch_scales)
                    + bytes(&self.patch_weights)
                    + bytes(&self.patch_trims)
                    + self.patch_weights.iter().flatten().count() * std::mem::size_of::<Weights>(),
            ),
            (
                "patch leaves (sub-patches and their tests, weights, trim flags)",
                bytes(&self.leaves) + bytes(&self.leaf_weights) + bytes(&self.leaf_trimmed),
            ),
            (
                "primitive list and bounds",
                bytes(&self.primitives) + bytes(&self.primitive_bounds),
            ),
            ("BVH nodes, node pairs and order", self.bvh.memory()),
            (
                "spheres, quads, planes, meshes",
                bytes(&self.spheres) + bytes(&self.quads) + bytes(&self.planes) + meshes,
            ),
        ]
    }

    /// Whether the scene holds any Bézier patch.
    pub fn has_patches(&self) -> bool {
        !self.patches.is_empty()
    }

    /// `primitive`'s nearest hit by `ray` before `t_max`; `span`, the piece of the ray inside
    /// a box holding the primitive ([`Bvh::traverse`]'s), rules out patch leaves early.
    fn test(
        &self,
        primitive: Primitive,
        ray: &Ray,
        frame: &Option<RayFrame>,
        span: (f64, f64),
        t_max: f64,
    ) -> Option<Candidate> {
        let hit = |t: f64, param: DVec2| Candidate {
            t,
            primitive,
            param,
            normal: None,
        };
        let patch_hit = |h: PatchHit| Candidate {
            normal: h.normal,
            ..hit(h.t, h.uv)
        };
        match primitive {
            Primitive::Sphere(i) => self.spheres[i as usize]
                .0
                .intersect(ray, 0.0, t_max)
                .map(|t| hit(t, DVec2::ZERO)),
            Primitive::Quad(i) => self.quads[i as usize]
                .0
                .intersect(ray, 0.0, t_max)
                .map(|(t, ab)| hit(t, ab)),
            Primitive::Triangle { mesh, triangle } => self.meshes[mesh as usize]
                .0
                .intersect_triangle(triangle as usize, ray, 0.0, t_max)
                .map(|h| hit(h.t, h.barycentric)),
            Primitive::PatchLeaf(i) => {
                let frame = frame.as_ref()?;
                if self.trimmed_leaf(i) {
                    return self.trimmed_leaf_hit(i, frame, span, t_max).map(patch_hit);
                }
                self.leaf_hit(i, frame, span, (0.0, t_max)).map(patch_hit)
            }
            Primitive::Patch(i) => {
                let depth = match self.patch_method {
                    PatchMethod::PerRay { depth } => depth,
                    PatchMethod::Prepared(_) => 0,
                };
                let k = i as usize;
                let search = |t_min| {
                    intersect_per_ray_weighted(
                        &self.patches[k].0,
                        self.patch_weights(k),
                        self.patch_scales[k],
                        ray,
                        (t_min, t_max),
                        depth,
                    )
                };
                match self.patch_trim(k) {
                    None => search(0.0),
                    Some(trim) => first_kept(search, (trim, &self.patch_domains[k])),
                }
                .map(patch_hit)
            }
            Primitive::Plane(i) => self.planes[i as usize]
                .0
                .intersect(ray, 0.0, t_max)
                .map(|t| hit(t, DVec2::ZERO)),
        }
    }

    fn nearest(&self, ray: &Ray, t_max: f64) -> Option<Candidate> {
        let frame = self.has_patches().then(|| RayFrame::new(ray));
        let mut best: Option<Candidate> = None;
        let t_max = match &self.flat_spheres {
            Some(batch) => match batch.nearest(ray, t_max) {
                Some((t, i)) => {
                    best = Some(Candidate {
                        t,
                        primitive: Primitive::Sphere(i),
                        param: DVec2::ZERO,
                        normal: None,
                    });
                    t
                }
                None => t_max,
            },
            None => self.bvh.traverse(ray, t_max, |k, t_max, span| {
                let c = self.test(self.primitives[k as usize], ray, &frame, span, t_max)?;
                best = Some(c);
                Some(c.t)
            }),
        };
        for k in 0..self.planes.len() {
            let t_max = best.map_or(t_max, |b| b.t);
            if let Some(c) = self.test(Primitive::Plane(k as u32), ray, &frame, (0.0, t_max), t_max) {
                best = Some(c);
            }
        }
        best
    }

    /// The nearest hit of `ray` in `(0, t_max)`.
    pub fn intersect(&self, ray: &Ray, t_max: f64) -> Option<Hit> {
        let c = self.nearest(ray, t_max)?;
        let point = ray.at(c.t);
        let patch_point = match c.primitive {
            Primitive::PatchLeaf(i) => Some(PatchPoint {
                patch: self.leaves[i as usize].patch,
                uv: c.param,
            }),
            _ => None,
        };
        let (normal, shading_normal, uv, object, shape) = match c.primitive {
            Primitive::Sphere(i) => {
                let (s, obj) = &self.spheres[i as usize];
                let n = s.normal(point);
                (n, n, DVec2::ZERO, *obj, ShapeRef::Sphere(i))
            }
            Primitive::Plane(i) => {
                let (p, obj) = &self.planes[i as usize];
                (p.normal, p.normal, p.uv(point), *obj, ShapeRef::Plane(i))
            }
            Primitive::Quad(i) => {
                let (q, obj) = &self.quads[i as usize];
                let n = q.normal();
                (n, n, c.param, *obj, ShapeRef::Quad(i))
            }
            Primitive::Triangle { mesh, triangle } => {
                let (m, obj) = &self.meshes[mesh as usize];
                let n = m.geometric_normal(triangle as usize);
                let mut ns = m.shading_normal(triangle as usize, c.param);
                if ns.dot(n) < 0.0 {
                    ns = -ns;
                }
                (
                    n,
                    ns,
                    m.uv(triangle as usize, c.param),
                    *obj,
                    ShapeRef::Mesh(mesh),
                )
            }
            Primitive::PatchLeaf(i) => {
                let leaf = &self.leaves[i as usize];
                self.patch_surface(leaf.patch, c.param, c.normal, Some(leaf.scale))
            }
            Primitive::Patch(patch) => self.patch_surface(patch, c.param, c.normal, None),
        };
        Some(Hit {
            t: c.t,
            point,
            normal,
            shading_normal,
            param: uv,
            object,
            shape,
            patch_point,
        })
    }

    /// A patch hit's normals, surface `(u,v)`, object and shape: the normal the root finder
    /// found (`known`), or the patch's limit normal where it had none; `scale`, the patch's
    /// bounds' diagonal, when a prepared leaf knows it.
    fn patch_surface(
        &self,
        patch: u32,
        uv: DVec2,
        known: Option<DVec3>,
        scale: Option<f64>,
    ) -> (DVec3, DVec3, DVec2, u32, ShapeRef) {
        let (p, obj) = &self.patches[patch as usize];
        let n = match (known, self.patch_weights(patch as usize)) {
            (Some(n), _) => Some(n),
            (None, Some(w)) => {
                let scale = scale.unwrap_or(self.patch_scales[patch as usize]);
                RationalPatch::new(p, w).normal_at_scale(uv.x, uv.y, scale)
            }
            (None, None) => match scale {
                Some(scale) => p.normal_at_scale(uv.x, uv.y, scale),
                None => p.normal(uv.x, uv.y),
            },
        };
        // A patch degenerate everywhere has no normal; any unit vector keeps shading finite.
        let n = n.unwrap_or(DVec3::Z);
        let surface_uv = self.patch_domains[patch as usize].map(uv.x, uv.y);
        (n, n, surface_uv, *obj, ShapeRef::Patch(patch))
    }

    /// Whether anything lies on `ray` in `(0, t_max)` (shadow rays).
    pub fn occluded(&self, ray: &Ray, t_max: f64) -> bool {
        self.occluded_except(ray, t_max, None)
    }

    /// Whether anything but the object `skip` lies on `ray` in `(0, t_max)`: a shadow ray
    /// towards an area light passes its own surface, which a ray aimed near the edge of a
    /// sphere light would otherwise graze on the way, the light shadowing itself.
    pub fn occluded_except(&self, ray: &Ray, t_max: f64, skip: Option<u32>) -> bool {
        let counts = |object: u32| skip != Some(object);
        if self
            .planes
            .iter()
            .any(|(p, obj)| counts(*obj) && p.intersect(ray, 0.0, t_max).is_some())
        {
            return true;
        }
        if let Some(batch) = &self.flat_spheres {
            return batch.any(ray, t_max, skip);
        }
        let frame = self.has_patches().then(|| RayFrame::new(ray));
        self.bvh.any(ray, t_max, |k, span| {
            let primitive = self.primitives[k as usize];
            counts(self.object_of(primitive))
                && match (primitive, &frame) {
                    (Primitive::PatchLeaf(i), Some(frame)) if self.trimmed_leaf(i) => {
                        self.trimmed_leaf_hit(i, frame, span, t_max).is_some()
                    }
                    (Primitive::PatchLeaf(i), Some(frame)) => match self.rational_weights(i) {
                        None => leaf_occludes(&self.leaves[i as usize], frame, span, 0.0, t_max),
                        Some(w) => rational_leaf_occludes(&self.leaves[i as usize], w, frame, span, t_max),
                    },
                    _ => self.test(primitive, ray, &frame, span, t_max).is_some(),
                }
        })
    }

    /// The object a primitive belongs to.
    fn object_of(&self, primitive: Primitive) -> u32 {
        match primitive {
            Primitive::Sphere(i) => self.spheres[i as usize].1,
            Primitive::Plane(i) => self.planes[i as usize].1,
            Primitive::Quad(i) => self.quads[i as usize].1,
            Primitive::Triangle { mesh, .. } => self.meshes[mesh as usize].1,
            Primitive::PatchLeaf(i) => self.patches[self.leaves[i as usize].patch as usize].1,
            Primitive::Patch(i) => self.patches[i as usize].1,
        }
    }
}

/// What [`SceneGeometry::update_patches`] did.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PatchUpdate {
    /// Patches re-prepared.
    pub patches: usize,
    /// Whether the BVH was refit (every patch kept its leaf count) rather than rebuilt.
    pub refit: bool,
}

/// Sizes of a built geometry.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct GeometryStats {
    /// Primitives in the BVH.
    pub primitives: usize,
    /// BVH nodes.
    pub bvh_nodes: usize,
    /// Deepest BVH leaf.
    pub bvh_depth: usize,
    /// Bézier patches.
    pub patches: usize,
    /// Prepared patch leaves.
    pub patch_leaves: usize,
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A sphere hit's `(u,v)`, made from its normal when asked for, is the sphere's own at the
    /// hit point; other shapes keep the parameters their test found.
    #[test]
    fn a_sphere_hits_uv_is_the_spheres_at_the_point() {
        let sphere = Sphere {
            center: DVec3::new(1.0, 2.0, -3.0),
            radius: 1.5,
        };
        let mut builder = GeometryBuilder::default();
        builder.add_sphere(sphere, 0);
        let quad = builder.add_quad(
            Quad {
                corner: DVec3::new(-10.0, -10.0, 5.0),
                edge_u: DVec3::X * 20.0,
                edge_v: DVec3::Y * 20.0,
            },
            1,
        );
        let geometry = builder.build();
        let origin = DVec3::new(0.5, 1.0, 4.0);
        for offset in [
            DVec3::ZERO,
            DVec3::new(0.9, -0.4, 0.0),
            DVec3::new(-1.0, 0.7, 0.2),
        ] {
            let ray = Ray::new(origin, sphere.center + offset - origin);
            let hit = geometry
                .intersect(&ray, f64::INFINITY)
                .expect("the ray meets the sphere");
            assert!(matches!(hit.shape, ShapeRef::Sphere(_)));
            assert_eq!(hit.uv(), sphere.uv(hit.point));
        }
        let up = Ray::new(DVec3::new(-9.0, -9.0, 0.0), DVec3::Z);
        let hit = geometry
            .intersect(&up, f64::INFINITY)
            .expect("the ray meets the quad");
        assert_eq!(hit.shape, quad);
        assert!((hit.uv() - DVec2::new(0.05, 0.05)).length() < 1e-12);
    }

    /// A scene of spheres only, whose BVH is not walked, tests them at once
    /// ([`SphereBatch`]); the same spheres with a quad far out of the rays' way are tested one
    /// by one. Both find the same hits bit for bit, the same shadows (an object skipped
    /// included), also after a sphere is moved.
    #[test]
    fn spheres_tested_at_once_find_what_spheres_tested_one_by_one_find() {
        let spheres = [
            (DVec3::new(1e5 + 1.0, 40.8, 81.6), 1e5),
            (DVec3::new(-1e5 + 99.0, 40.8, 81.6), 1e5),
            (DVec3::new(50.0, 40.8, 1e5), 1e5),
            (DVec3::new(50.0, 40.8, -1e5 + 170.0), 1e5),
            (DVec3::new(50.0, 1e5, 81.6), 1e5),
            (DVec3::new(50.0, -1e5 + 81.6, 81.6), 1e5),
            (DVec3::new(27.0, 16.5, 47.0), 16.5),
            (DVec3::new(73.0, 16.5, 78.0), 16.5),
            (DVec3::new(50.0, 681.33, 81.6), 600.0),
        ];
        let build = |with_quad: bool| {
            let mut builder = GeometryBuilder::default();
            for (k, &(center, radius)) in spheres.iter().enumerate() {
                builder.add_sphere(Sphere { center, radius }, k as u32);
            }
            if with_quad {
                let corner = DVec3::splat(1e7);
                builder.add_quad(
                    Quad {
                        corner,
                        edge_u: DVec3::X,
                        edge_v: DVec3::Y,
                    },
                    99,
                );
            }
            builder.build()
        };
        let (mut at_once, mut one_by_one) = (build(false), build(true));
        assert!(at_once.flat_spheres.is_some() && one_by_one.flat_spheres.is_none());
        let mut rng = <rand_pcg::Pcg64Mcg as rand::SeedableRng>::seed_from_u64(5);
        let mut next = || rand::Rng::random::<f64>(&mut rng);
        for round in 0..2 {
            if round == 1 {
                let moved = Sphere {
                    center: DVec3::new(40.0, 30.0, 60.0),
                    radius: 10.0,
                };
                assert!(at_once.move_sphere(7, moved) && one_by_one.move_sphere(7, moved));
            }
            for k in 0..3000 {
                let origin = DVec3::new(next() * 98.0 + 1.0, next() * 80.0 + 0.5, next() * 160.0 + 5.0);
                let ray = Ray::new(origin, DVec3::new(next() - 0.5, next() - 0.5, next() - 0.5));
                let t_max = if k % 2 == 0 { f64::INFINITY } else { 40.0 };
                let (a, b) = (at_once.intersect(&ray, t_max), one_by_one.intersect(&ray, t_max));
                let key = |h: Option<Hit>| {
                    h.map(|h| (h.t.to_bits(), h.object, h.normal.to_array().map(f64::to_bits)))
                };
                assert_eq!(key(a), key(b), "round {round}, ray {k}");
                let skip = Some(k as u32 % 9);
                assert_eq!(at_once.occluded(&ray, t_max), one_by_one.occluded(&ray, t_max));
                assert_eq!(
                    at_once.occluded_except(&ray, t_max, skip),
                    one_by_one.occluded_except(&ray, t_max, skip),
                    "round {round}, ray {k}"
                );
            }
        }
    }
}
