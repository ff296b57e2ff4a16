//! Ray / bicubic Bézier patch intersection.
//!
//! Two intersectors share one root finder:
//!
//! * **Prepared** (the default): at scene preparation each patch is subdivided
//!   adaptively into [`PatchLeaf`]s — sub-patches that are nearly bilinear — each carrying its
//!   `(u,v)` window in the original patch and its control points. The leaves' bounds go into
//!   the scene BVH, so the per-ray work is BVH traversal plus a Newton solve on the one or two
//!   leaves the ray reaches.
//! * **Per-ray** (the seed report §2.3, kept as a reference and for benchmarks): for each ray,
//!   a queue splits the patch into quarters with De Casteljau, keeps the quarters whose
//!   bounding box the ray hits, stops at a fixed depth and runs Newton on the survivors.
//!
//! ## The root finder
//!
//! The ray is written as the intersection of two planes (Kajiya 1982; Martin et al. 2000,
//! "Practical ray tracing of trimmed NURBS surfaces"): with `n1`, `n2` orthonormal to the ray
//! direction `d`, every control point is taken to *ray space* `(n1·(P-o), n2·(P-o), d·(P-o))`.
//! The patch meets the ray where the first two coordinates of the (ray-space) patch vanish:
//! a 2×2 Newton iteration in `(s,t)`, started in the middle of the sub-patch. The third
//! coordinate at the root is the ray distance. Because Bézier patches are affine invariant the
//! ray-space patch is just the patch with transformed control points, so the convex hull
//! property gives a cheap exact rejection: if the projected control points do not surround the
//! origin the ray misses. A tighter test follows it (`beside`): the bilinear patch through the
//! corners, widened by the sub-patch's largest deviation from it, bounds the surface too, so a
//! ray outside that quadrilateral needs no Newton solve.
//!
//! Near-singular Jacobians (the collapsed rows at the teapot's poles, folds at grazing angles)
//! take a Levenberg–Marquardt step instead of a Newton step. When Newton does not converge to a
//! root inside the window, the sub-patch is split in four and each quarter that still surrounds
//! the ray is solved again, nearest first (the seed's subdivision, used as a fallback only).
//!
//! A ray spawned on a patch ([`Ray::leaving`]) crosses that patch where it leaves it, behind its
//! offset origin; every leaf around that point would find this crossing again with a Newton
//! solve (and, where the ray leaves at a slant, a split or two) only to reject it. Instead, a
//! leaf whose window holds the departure point, or lies beside it, is ruled out at once when
//! the Jacobian's sign is fixed over the leaf and agrees with its sign at the departure: the
//! ray then crosses the leaf at most once and that crossing is the departure (see
//! `departure`). Shadow rays from a patch's own points are most of a ray-traced patch
//! scene's rays.
//!
//! Sub-patch `(s,t)` map back to the original patch as `u = u0 + s(u1-u0)`, `v = v0 + t(v1-v0)`
//! (seed report §2.4: the linear map survives any number of De Casteljau splits), so texture
//! coordinates always refer to the original patch.
//!
//! Rational patches ([`crate::geometry::rational`]) take the same path: the root finder solves
//! their numerator, a polynomial patch with the same roots (the `ray_space` module explains it).

use glam::{DVec2, DVec3};

use super::aabb::{safe_inverse, Aabb};
use super::bezier::BezierPatch;
use super::rational::{RationalPatch, Weights};
use super::ray::Ray;

mod cone;
mod ray_space;
mod root;
mod slab;

pub use cone::NormalCone;
pub use slab::Slab;

use ray_space::RaySpace;
use root::{beside, bilinear_start, jacobian_at, jacobian_sign, newton, Root};

/// A rectangle `[u0,u1] × [v0,v1]` of a patch's parameter domain.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Window {
    /// Lower `u`.
    pub u0: f64,
    /// Upper `u`.
    pub u1: f64,
    /// Lower `v`.
    pub v0: f64,
    /// Upper `v`.
    pub v1: f64,
}

impl Window {
    /// The whole domain `[0,1]²`.
    pub const FULL: Window = Window {
        u0: 0.0,
        u1: 1.0,
        v0: 0.0,
        v1: 1.0,
    };

    /// The original patch's `(u,v)` for the sub-patch parameters `(s,t)`.
    #[inline]
    pub fn map(&self, s: f64, t: f64) -> DVec2 {
        DVec2::new(
            self.u0 + s * (self.u1 - self.u0),
            self.v0 + t * (self.v1 - self.v0),
        )
    }

    /// The four quarters, in the order of [`BezierPatch::split_quad`].
    pub fn quarters(&self) -> [Window; 4] {
        let um = 0.5 * (self.u0 + self.u1);
        let vm = 0.5 * (self.v0 + self.v1);
        [
            Window {
                u1: um,
                v1: vm,
                ..*self
            },
            Window {
                u0: um,
                v1: vm,
                ..*self
            },
            Window {
                u1: um,
                v0: vm,
                ..*self
            },
            Window {
                u0: um,
                v0: vm,
                ..*self
            },
        ]
    }
}

/// A piece of a patch prepared for intersection: its window in the original patch, its own
/// control points (the original restricted to the window) and their bounds.
///
/// A rational patch's leaves hold their projected control points, which bound them as a
/// polynomial patch's do; their weights (the patch's restricted to the window,
/// [`crate::geometry::rational::window_weights`]) are kept beside the leaves by the scene
/// geometry and given to [`intersect_rational_leaf`], not here: a larger leaf made the
/// polynomial leaves' search slower.
#[derive(Clone, Debug)]
pub struct PatchLeaf {
    /// Index of the original patch in the scene geometry.
    pub patch: u32,
    /// Where this leaf lies in the original patch's `(u,v)` domain.
    pub window: Window,
    /// The sub-patch, parameterised over `[0,1]²`.
    pub sub_patch: BezierPatch,
    /// Bounds of the sub-patch's control points, padded against rounding.
    pub bounds: Aabb,
    /// Diagonal of the original patch's bounds: the length scale for tolerances.
    pub scale: f64,
    /// The largest distance of the sub-patch's control points from the bilinear patch through
    /// its corners ([`BezierPatch::bilinear_deviation`]): in ray space the projected deviation
    /// is no larger, so the solver's `beside` test can often rule a ray out without measuring it.
    pub deviation: f64,
    /// A cone holding every normal of the sub-patch: tells a ray that leaves the leaf whether
    /// the normal keeps one side towards it, before the leaf is projected (`departure`).
    pub normals: NormalCone,
    /// A slab that holds the sub-patch: with `bounds`, rules out rays that pass through the
    /// box above or below a leaf lying oblique to the axes, before it is projected.
    pub slab: Slab,
}

impl PatchLeaf {
    /// The piece `(near, far)` of `frame`'s ray inside the leaf's own box, up to `t_max`
    /// ([`intersect_leaf`]'s `span` where no BVH has found one).
    pub fn span(&self, frame: &RayFrame, t_max: f64) -> Option<(f64, f64)> {
        self.bounds
            .hit_interval(frame.origin, safe_inverse(frame.dir), t_max)
    }
}

/// How finely [`subdivide`] cuts a patch.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SubdivisionParams {
    /// A leaf is flat enough when its control points are within `flatness × diagonal` of the
    /// bilinear patch through its corners.
    pub flatness: f64,
    /// A leaf is small enough when its diagonal is at most `max_size × diagonal` of the patch.
    pub max_size: f64,
    /// Depth limit (a patch becomes at most `4^max_depth` leaves).
    pub max_depth: u32,
    /// The most leaves one patch may become. When the criteria above ask for more, the leaves
    /// furthest from them are split first until the budget is spent: a leaf that is not flat
    /// enough still intersects exactly (Newton falls back to splitting it per ray), only more
    /// slowly. [`leaf_budget`] sets it from a scene's patch count.
    pub max_leaves: usize,
}

impl Default for SubdivisionParams {
    fn default() -> Self {
        Self {
            flatness: 0.05,
            max_size: 0.35,
            max_depth: 6,
            max_leaves: usize::MAX,
        }
    }
}

/// Leaves a scene's patches may become in all, whatever their number: about 28 MB of leaves
/// and their BVH nodes.
pub const SCENE_LEAVES: usize = 32_768;

/// The fewest leaves a patch may be held to: four keeps a prepared patch within 4 KB (a leaf
/// and its share of the BVH take about 850 bytes, the patch itself 430).
pub const MIN_PATCH_LEAVES: usize = 4;

/// The leaves each of `patches` patches may become: an equal share of [`SCENE_LEAVES`], at
/// least [`MIN_PATCH_LEAVES`]. A scene of a few hundred patches is not held back at all.
pub fn leaf_budget(patches: usize) -> usize {
    (SCENE_LEAVES / patches.max(1)).max(MIN_PATCH_LEAVES)
}

/// Relative padding of leaf bounds: rounding in the slab test can never lose a seam point.
const BOUNDS_PAD: f64 = 1e-9;

/// Subdivides `patch` into leaves that are flat and small enough for a Newton solve started in
/// their middle to converge to the only root (for all but grazing rays), within
/// [`SubdivisionParams::max_leaves`].
pub fn subdivide(patch: &BezierPatch, patch_index: u32, params: &SubdivisionParams) -> Vec<PatchLeaf> {
    subdivide_weighted(patch, None, patch_index, params)
}

/// [`subdivide`] for a patch that may be rational: `patch` holds its control points, `weights`
/// their weights (positive). The pieces are split in homogeneous form and judged flat by their
/// projected control points.
pub fn subdivide_weighted(
    patch: &BezierPatch,
    weights: Option<&Weights>,
    patch_index: u32,
    params: &SubdivisionParams,
) -> Vec<PatchLeaf> {
    let scale = patch.bounds().diagonal().length();
    let leaf = |piece: Piece| piece.leaf(patch_index, scale);
    let whole = Piece::new(*patch, weights.copied(), Window::FULL, 0, params, scale);
    match depth_first(&whole, params, scale) {
        Some(pieces) => pieces.into_iter().map(leaf).collect(),
        None => worst_first(whole, params, scale).into_iter().map(leaf).collect(),
    }
}

/// A piece of a patch on its way to becoming a leaf.
#[derive(Clone)]
struct Piece {
    /// Its control points (projected, when rational).
    sub: BezierPatch,
    /// Its weights, when rational.
    weights: Option<Weights>,
    window: Window,
    depth: u32,
    deviation: f64,
    /// How far it is from flat and small enough: at most 1 when it is both.
    excess: f64,
}

impl Piece {
    fn new(
        sub: BezierPatch,
        weights: Option<Weights>,
        window: Window,
        depth: u32,
        params: &SubdivisionParams,
        scale: f64,
    ) -> Self {
        let diag = sub.bounds().diagonal().length();
        let deviation = sub.bilinear_deviation();
        let flat = deviation <= params.flatness * diag;
        let small = diag <= params.max_size * scale;
        let excess = if flat && small {
            0.0
        } else {
            (deviation / (params.flatness * diag).max(f64::MIN_POSITIVE))
                .max(diag / (params.max_size * scale).max(f64::MIN_POSITIVE))
                .max(1.0 + f64::EPSILON)
        };
        Self {
            sub,
            weights,
            window,
            depth,
            deviation,
            excess,
        }
    }

    /// Whether it is a leaf as it is: flat and small enough, or as deep as allowed.
    fn done(&self, params: &SubdivisionParams) -> bool {
        self.excess == 0.0 || self.depth >= params.max_depth
    }

    fn split(&self, params: &SubdivisionParams, scale: f64) -> [Piece; 4] {
        let windows = self.window.quarters();
        let depth = self.depth + 1;
        match &self.weights {
            None => {
                let children = self.sub.split_quad();
                std::array::from_fn(|k| Piece::new(children[k], None, windows[k], depth, params, scale))
            }
            Some(w) => {
                let children = RationalPatch::new(&self.sub, w).split_quad();
                std::array::from_fn(|k| {
                    let (sub, w) = (children[k].points(), children[k].weights);
                    Piece::new(sub, Some(w), windows[k], depth, params, scale)
                })
            }
        }
    }

    fn leaf(self, patch: u32, scale: f64) -> PatchLeaf {
        // A rational leaf's numerator, which the ray is solved against, is not bounded by the
        // projected points' deviation, nor its normals by their cone: neither is claimed.
        let rational = self.weights.is_some();
        PatchLeaf {
            patch,
            window: self.window,
            bounds: self
                .sub
                .bounds()
                .padded(BOUNDS_PAD * scale.max(f64::MIN_POSITIVE)),
            sub_patch: self.sub,
            scale,
            deviation: if rational { f64::INFINITY } else { self.deviation },
            normals: if rational {
                NormalCone::NONE
            } else {
                NormalCone::of(&self.sub)
            },
            slab: Slab::of(&self.sub),
        }
    }
}

/// The pieces the criteria ask for, depth first; `None` as soon as they are more than
/// [`SubdivisionParams::max_leaves`].
fn depth_first(whole: &Piece, params: &SubdivisionParams, scale: f64) -> Option<Vec<Piece>> {
    let mut pieces = Vec::new();
    let mut stack = vec![whole.clone()];
    while let Some(piece) = stack.pop() {
        if pieces.len() + stack.len() + 1 > params.max_leaves {
            return None;
        }
        if piece.done(params) {
            pieces.push(piece);
        } else {
            stack.extend(piece.split(params, scale));
        }
    }
    Some(pieces)
}

/// At most [`SubdivisionParams::max_leaves`] pieces: the piece furthest from the criteria is
/// split first (ties: the one found first), while splitting it stays within the budget.
fn worst_first(whole: Piece, params: &SubdivisionParams, scale: f64) -> Vec<Piece> {
    use std::cmp::Reverse;
    use std::collections::BinaryHeap;
    /// A piece's place in the queue: its excess (larger first), then the order it was found.
    #[derive(PartialEq)]
    struct Key(f64, Reverse<usize>);
    impl Eq for Key {}
    impl PartialOrd for Key {
        fn partial_cmp(&self, other: &Self) -> Option<std::cmp::Ordering> {
            Some(self.cmp(other))
        }
    }
    impl Ord for Key {
        fn cmp(&self, other: &Self) -> std::cmp::Ordering {
            self.0.total_cmp(&other.0).then(self.1.cmp(&other.1))
        }
    }
    /// Pieces that are leaves as they are, and the others queued by their key.
    #[derive(Default)]
    struct Pieces {
        found: Vec<Option<Piece>>,
        done: Vec<Piece>,
        queue: BinaryHeap<Key>,
    }
    impl Pieces {
        fn add(&mut self, piece: Piece, params: &SubdivisionParams) {
            if piece.done(params) {
                self.done.push(piece);
            } else {
                self.queue.push(Key(piece.excess, Reverse(self.found.len())));
                self.found.push(Some(piece));
            }
        }
    }
    let mut pieces = Pieces::default();
    pieces.add(whole, params);
    // Splitting one piece into four adds three.
    while pieces.done.len() + pieces.queue.len() + 3 <= params.max_leaves {
        let Some(Key(_, Reverse(k))) = pieces.queue.pop() else {
            break;
        };
        let Some(piece) = pieces.found[k].take() else {
            break;
        };
        for child in piece.split(params, scale) {
            pieces.add(child, params);
        }
    }
    let Pieces {
        mut found,
        mut done,
        queue,
    } = pieces;
    done.extend(queue.into_iter().filter_map(|Key(_, Reverse(k))| found[k].take()));
    done
}

/// A point of a prepared patch: the patch's index in the scene geometry and its own `(u,v)`
/// (before any domain mapping), where a ray leaves that patch ([`Ray::leaving`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PatchPoint {
    /// Index of the patch in the scene geometry.
    pub patch: u32,
    /// The patch's own parameters, in `[0,1]²`.
    pub uv: DVec2,
}

/// How far outside a leaf's window (in units of the window's own size) a ray's departure point
/// may lie for the leaf to be ruled out by [`departure`]: the leaves beside the one holding
/// it, whose bounds the ray starts in as often as in its own.
const DEPARTURE_MARGIN: f64 = 0.5;

/// What a ray's departure point tells a leaf's search ([`departure`]).
#[derive(Clone, Copy, Debug, PartialEq)]
enum Departure {
    /// The ray provably meets the leaf nowhere in front of it.
    Only,
    /// The departure lies in the leaf's window, at these sub-patch parameters: a root the
    /// search knows without solving (behind the ray), though the leaf may hold another.
    Inside(f64, f64),
    /// The departure says nothing about the leaf.
    Away,
}

/// Where the departure point `from` of a ray lies in `leaf`'s sub-patch parameters, when it is
/// on the same patch and in the leaf's window or beside it.
fn departure_point(leaf: &PatchLeaf, from: Option<PatchPoint>) -> Option<(f64, f64)> {
    let from = from.filter(|f| f.patch == leaf.patch)?;
    let w = &leaf.window;
    let s = (from.uv.x - w.u0) / (w.u1 - w.u0);
    let t = (from.uv.y - w.v0) / (w.v1 - w.v0);
    let near = |x: f64| (-DEPARTURE_MARGIN..=1.0 + DEPARTURE_MARGIN).contains(&x);
    (near(s) && near(t)).then_some((s, t))
}

/// Whether `(s, t)` lies in the unit square.
fn in_window(s: f64, t: f64) -> bool {
    (0.0..=1.0).contains(&s) && (0.0..=1.0).contains(&t)
}

/// What a ray's departure point `(s, t)` (in the leaf's sub-patch parameters) says about the
/// leaf, given the sign the normal keeps against the ray over the leaf (`sign`, when it is
/// fixed) and the sign of `n·d` at the departure (`at_departure`, asked only when needed).
///
/// When the Jacobian's sign (in ray space, the normal against the ray direction) is fixed over
/// the leaf, the ray crosses it at most once (as [`Problem::solve`] argues). If the departure
/// point lies in the leaf's window, that one crossing is the departure itself, behind the ray's
/// offset origin. If it lies just outside (beside a seam) and the Jacobian has the same sign
/// there, a second crossing inside the window would have to be in the departure's own sense:
/// the ray would pass the surface twice the same way with no crossing back between them, which
/// a smooth patch that keeps one orientation towards the ray across the seam does not allow.
/// [`Hit`](super::scene_geometry::Hit) only records a departure for rays that leave the surface
/// at more than a grazing angle, so the departure crossing lies within rounding of the
/// departure point.
fn departure((s, t): (f64, f64), sign: Option<f64>, at_departure: impl FnOnce() -> f64) -> Departure {
    let inside = in_window(s, t);
    match sign {
        Some(_) if inside => Departure::Only,
        Some(sign) if at_departure() * sign > 0.0 => Departure::Only,
        _ if inside => Departure::Inside(s, t),
        _ => Departure::Away,
    }
}

/// A ray/patch intersection: distance along the ray, the original patch's `(u,v)` and the
/// normal there.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PatchHit {
    /// Distance along the ray.
    pub t: f64,
    /// Parameters in the original patch, within `[0,1]²`.
    pub uv: DVec2,
    /// The unit normal `∂P/∂u × ∂P/∂v` at `uv`, from the root finder's own derivatives (equal
    /// to [`BezierPatch::normal`]'s within rounding). `None` where the cross product vanishes
    /// (a collapsed edge, such as the Utah teapot's poles) or the search settled without a
    /// Newton root: the caller takes the limit normal ([`BezierPatch::normal_at_scale`]).
    pub normal: Option<DVec3>,
}

/// [`PatchHit`] while a search runs: the normal still in ray space.
#[derive(Clone, Copy, Debug)]
struct Found {
    t: f64,
    uv: DVec2,
    /// `∂P/∂s × ∂P/∂t` of the sub-patch in ray space, where it is not rounding noise.
    normal: Option<DVec3>,
}

/// The frame of a ray: `n1`, `n2`, `dir` orthonormal; and the patch point it leaves, if any.
#[derive(Clone, Copy, Debug)]
pub struct RayFrame {
    origin: DVec3,
    n1: DVec3,
    n2: DVec3,
    dir: DVec3,
    leaving: Option<PatchPoint>,
}

impl RayFrame {
    /// The frame of `ray` (whose direction is unit length).
    pub fn new(ray: &Ray) -> Self {
        let (n1, n2) = ray.dir.any_orthonormal_pair();
        Self {
            origin: ray.origin,
            n1,
            n2,
            dir: ray.dir,
            leaving: ray.leaving,
        }
    }

    /// A search's hit with its normal turned from ray space back to world space and
    /// normalised. `(n1, n2, dir)` is a right-handed orthonormal basis (Duff et al. 2017,
    /// "Building an orthonormal basis, revisited", which glam's `any_orthonormal_pair`
    /// implements), so cross products carry over unchanged.
    fn hit(&self, found: Found) -> PatchHit {
        PatchHit {
            t: found.t,
            uv: found.uv,
            normal: found
                .normal
                .map(|n| (n.x * self.n1 + n.y * self.n2 + n.z * self.dir).normalize()),
        }
    }

    /// The patch in ray space (control points as distances from the ray along `n1`, `n2`,
    /// and along it): a Bézier patch too, since Bézier patches are affine invariant, so its
    /// evaluation, hull and splits are [`BezierPatch`]'s own.
    #[inline]
    fn project(&self, patch: &BezierPatch) -> BezierPatch {
        BezierPatch::new(patch.points.map(|p| {
            let q = p - self.origin;
            DVec3::new(self.n1.dot(q), self.n2.dot(q), self.dir.dot(q))
        }))
    }
}

/// How far outside `[0,1]²` (in sub-patch parameters) a root still counts as inside: roots on a
/// shared edge are found by both neighbours rather than by neither.
const WINDOW_MARGIN: f64 = 1e-8;
/// Convergence tolerance relative to the patch size: `|distance from ray| ≤ 1e-12 · scale`.
const RELATIVE_TOLERANCE: f64 = 1e-12;

/// One ray's search for the nearest root over ray-space sub-patches.
struct Problem {
    /// Sub-patches this search may still split: bounds the work where hull tests cannot
    /// separate anything (every sub-patch touching a pole contains the pole).
    budget: u32,
    t_min: f64,
    tolerance: f64,
    /// Diagonal of the original patch's bounds (as [`PatchLeaf::scale`]): the scale below
    /// which a normal is rounding noise.
    scale: f64,
    /// A bound on the rounding of each ray-space coordinate ([`rounding`]).
    rounding: f64,
    best: Option<Found>,
    /// Whether any root in range will do (shadow rays): the search ends at the first one
    /// instead of ruling out nearer ones.
    any: bool,
    /// The largest distance of the prepared leaf's control points from the bilinear patch
    /// through its corners ([`PatchLeaf::deviation`]; infinite when not known).
    deviation: f64,
}

impl Problem {
    /// A search over the ray-space sub-patch `p` of a patch whose bounds' diagonal is `scale`:
    /// its tolerance and its normals' rounding bound come from `p`'s own coordinates
    /// ([`rounding`], [`tolerance`]); `deviation` is [`Problem::deviation`]'s.
    fn new<P: RaySpace>(p: &P, scale: f64, t_min: f64, any: bool, deviation: f64) -> Self {
        let rounding = p.rounding();
        Self {
            budget: SPLIT_BUDGET,
            t_min,
            // A rational patch's numerator is its distance from the ray times the weight.
            tolerance: tolerance(scale * p.least_scale(), rounding),
            scale,
            rounding,
            best: None,
            any,
            deviation,
        }
    }

    /// Whether a ray-space patch with hull `(lo, hi)` can meet the ray within `(t_min, t_max)`.
    #[inline]
    fn may_hit(&self, (lo, hi): (DVec3, DVec3), t_max: f64) -> bool {
        let pad = self.tolerance;
        lo.x <= pad && hi.x >= -pad && lo.y <= pad && hi.y >= -pad && hi.z > self.t_min && lo.z < t_max
    }

    /// A bound on the deviation of the sub-patch solved at `depth` from its corners' bilinear
    /// patch: the leaf's own at the leaf's depth, none below.
    fn deviation_at(&self, depth: u32) -> f64 {
        if depth == LEAF_FALLBACK_DEPTH {
            self.deviation
        } else {
            f64::INFINITY
        }
    }

    fn t_max(&self, t_max: f64) -> f64 {
        self.best.map_or(t_max, |h| h.t)
    }

    /// The normal `∂P/∂s × ∂P/∂t` of `root` (a root of the sub-patch over `window`), in ray
    /// space, where its direction is known to [`NORMAL_TURN`]: the ray-space coordinates'
    /// rounding (`ε`) turns it by up to about `ε (|∂P/∂s| + |∂P/∂t|) / |∂P/∂s × ∂P/∂t|`. That
    /// rules out the nearly vanishing normals of a collapsed edge (a pole) and of the tiny
    /// sub-patches that splitting reaches, whose limit normal the caller takes instead
    /// ([`BezierPatch::normal_at_scale`]). [`BezierPatch::normal_at_scale`]'s own threshold,
    /// `1e-12 · scale²` for the original patch's normal, which the sub-patch's scales by the
    /// window's area, holds too. Both are compared squared, without square roots, the turn's
    /// `(|∂P/∂s| + |∂P/∂t|)²` bounded by `2 (|∂P/∂s|² + |∂P/∂t|²)`.
    fn normal(&self, root: &Root, window: Window) -> Option<DVec3> {
        let n = root.ds.cross(root.dt);
        let length2 = n.length_squared();
        let area = (window.u1 - window.u0) * (window.v1 - window.v0);
        let tiny = 1e-12 * self.scale * self.scale * area;
        let turn2 =
            2.0 * self.rounding * self.rounding * (root.ds.length_squared() + root.dt.length_squared());
        (length2 > tiny * tiny && turn2 < NORMAL_TURN * NORMAL_TURN * length2).then_some(n)
    }

    /// Finds the nearest root of the ray-space patch `p` over `window` (whose hull the caller
    /// has checked with [`Problem::may_hit`]), splitting up to `depth` more times where Newton
    /// fails or a second, nearer root cannot be ruled out. `known` is a root of `p` already
    /// found in the sub-patch this one was split from: it stands for the Newton solve, which
    /// would only find it again.
    fn solve<P: RaySpace>(&mut self, p: &P, window: Window, depth: u32, t_max: f64, known: Option<Root>) {
        let t_max = self.t_max(t_max);
        let r = p.roots();
        let root = match known {
            Some(root) => Some(root),
            None if beside(r, self.tolerance, self.deviation_at(depth)) => return,
            None => newton(r, self.tolerance, bilinear_start(r)).map(|root| p.complete(root)),
        };
        self.budget = self.budget.saturating_sub(1);
        if let Some(root) = root {
            let (s, t, dist) = (root.s, root.t, root.dist);
            let inside = |x: f64| (-WINDOW_MARGIN..=1.0 + WINDOW_MARGIN).contains(&x);
            if inside(s) && inside(t) && dist > self.t_min && dist < t_max {
                let uv = window.map(s.clamp(0.0, 1.0), t.clamp(0.0, 1.0));
                // A root just outside the window (on a seam, within the margin) is moved onto
                // it, away from where its derivatives were taken; shadow rays need no normal.
                let normal = (in_window(s, t) && !self.any)
                    .then(|| self.normal(&root, window))
                    .flatten();
                self.best = Some(Found { t: dist, uv, normal });
                if self.any {
                    return;
                }
            }
            // With n·d of one sign over the sub-patch the ray crosses it at most once: the
            // root Newton found (inside or outside the window) is the only one there is.
            if jacobian_sign(r).is_some() {
                return;
            }
        }
        if self.budget == 0 {
            // Degenerate configuration (a pole, a tangent ray): keep what was found. A root at
            // a pole lies on the boundary of every leaf around it and is found by one of them.
            return;
        }
        if depth == 0 {
            self.settle_at_corner(p, window, t_max);
            return;
        }
        self.solve_quarters(p, window, depth, t_max, root);
    }

    /// At the depth limit, a tiny sub-patch that still surrounds the ray: accepts the corner
    /// nearest the ray when nothing was found. Corners lie exactly on the surface, and at a
    /// pole one of them is the pole.
    fn settle_at_corner<P: RaySpace>(&mut self, p: &P, window: Window, t_max: f64) {
        if self.best.is_some() {
            return;
        }
        let corners = [(0, 0.0, 0.0), (3, 0.0, 1.0), (12, 1.0, 0.0), (15, 1.0, 1.0)];
        let off = |k: usize| p.roots().points[k].truncate().length();
        let (k, s, t) = corners
            .into_iter()
            .min_by(|a, b| off(a.0).total_cmp(&off(b.0)))
            .unwrap_or((0, 0.0, 0.0));
        let dist = p.corner_distance(k);
        if dist > self.t_min && dist < t_max {
            self.best = Some(Found {
                t: dist,
                uv: window.map(s, t),
                normal: None,
            });
        }
    }

    /// Splits `p` (over `window`) into quarters and solves those that may hold a root,
    /// nearest first so that later ones are pruned by the nearer root found. `root`, the root
    /// Newton found in `p` (if any), goes to the quarter that holds it ([`Problem::solve`]'s
    /// `known`).
    fn solve_quarters<P: RaySpace>(
        &mut self,
        p: &P,
        window: Window,
        depth: u32,
        t_max: f64,
        root: Option<Root>,
    ) {
        let t_max = self.t_max(t_max);
        let children = p.split_quad();
        let windows = window.quarters();
        // Quarters that may hold a root, nearest first, so later ones are pruned by t_max.
        let mut live = [(0.0f64, 0usize); 4];
        let mut n = 0;
        for (k, child) in children.iter().enumerate() {
            let h = child.hull();
            if self.may_hit(h, t_max) {
                live[n] = (h.0.z, k);
                n += 1;
            }
        }
        let live = &mut live[..n];
        live.sort_unstable_by(|a, b| a.0.total_cmp(&b.0));
        for &(near, k) in live.iter() {
            // Only a root nearer by more than the tolerance is worth finding: without this
            // slack every sub-patch touching a pole (which all contain the root) would be
            // searched, doubling at each level.
            if self.any && self.best.is_some() {
                return;
            }
            if near < self.t_max(t_max) - self.tolerance {
                // The root found here, in the quarter's own parameters, if it lies there.
                let (ds, dt) = QUARTER_OFFSETS[k];
                // The quarter's derivatives are half its parent's (exactly: a power of 2).
                let inherited = root.and_then(|r| {
                    let (s, t) = (2.0 * r.s - ds, 2.0 * r.t - dt);
                    ((0.0..=1.0).contains(&s) && (0.0..=1.0).contains(&t)).then_some(Root {
                        s,
                        t,
                        dist: r.dist,
                        ds: 0.5 * r.ds,
                        dt: 0.5 * r.dt,
                    })
                });
                self.solve(&children[k], windows[k], depth - 1, t_max, inherited);
            }
        }
    }

    /// Culls, then solves the ray-space patch `p`.
    fn run<P: RaySpace>(&mut self, p: &P, window: Window, depth: u32, t_max: f64) {
        if self.may_hit(p.hull(), self.t_max(t_max)) {
            self.solve(p, window, depth, t_max, None);
        }
    }
}

/// Where each quarter of [`BezierPatch::split_quad`] starts in its parent's `(s, t)`, doubled.
const QUARTER_OFFSETS: [(f64, f64); 4] = [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (1.0, 1.0)];

/// Sub-patches one search may solve before it settles for the nearest root found so far.
/// Ordinary rays use one to a few; rays through a pole or tangent to the surface can use many.
const SPLIT_BUDGET: u32 = 256;

/// How many more times a prepared leaf may be split when Newton fails in it.
const LEAF_FALLBACK_DEPTH: u32 = 24;

/// How far rounding may turn a normal from the root finder's derivatives before the
/// intersector leaves the normal to [`BezierPatch::normal_at_scale`] ([`Problem::normal`]).
const NORMAL_TURN: f64 = 1e-10;

/// Tolerance for a patch of size `scale` whose ray-space coordinates round by `rounding`: the
/// relative target, or the rounding if that is larger.
#[inline]
fn tolerance(scale: f64, rounding: f64) -> f64 {
    (RELATIVE_TOLERANCE * scale).max(rounding)
}

/// Intersects `ray` with a prepared leaf: the nearest hit in `(t_min, t_max)`. `span` is the
/// piece `(near, far)` of the ray inside a box that holds the leaf, as the BVH's walk found it
/// ([`Bvh::traverse`](super::bvh::Bvh::traverse)) or [`PatchLeaf::span`] finds it.
pub fn intersect_leaf(
    leaf: &PatchLeaf,
    frame: &RayFrame,
    span: (f64, f64),
    t_min: f64,
    t_max: f64,
) -> Option<PatchHit> {
    search_leaf(leaf, None, frame, span, (t_min, t_max), false)
}

/// [`intersect_leaf`] for a leaf of a rational patch, `weights` its own.
#[inline(never)]
pub fn intersect_rational_leaf(
    leaf: &PatchLeaf,
    weights: &Weights,
    frame: &RayFrame,
    span: (f64, f64),
    t_range: (f64, f64),
) -> Option<PatchHit> {
    search_leaf(leaf, Some(weights), frame, span, t_range, false)
}

/// [`leaf_occludes`] (from 0) for a leaf of a rational patch, `weights` its own.
#[inline(never)]
pub fn rational_leaf_occludes(
    leaf: &PatchLeaf,
    weights: &Weights,
    frame: &RayFrame,
    span: (f64, f64),
    t_max: f64,
) -> bool {
    search_leaf(leaf, Some(weights), frame, span, (0.0, t_max), true).is_some()
}

/// Whether `ray` meets a prepared leaf anywhere in `(t_min, t_max)` (shadow rays): the same
/// search as [`intersect_leaf`], ended at the first root found. Where the ray's sub-patch may
/// hold two roots (the ray nearly tangent to it, as shadow rays often are) the nearest-hit
/// search splits it to rule out a nearer one; this has no need to.
pub fn leaf_occludes(leaf: &PatchLeaf, frame: &RayFrame, span: (f64, f64), t_min: f64, t_max: f64) -> bool {
    search_leaf(leaf, None, frame, span, (t_min, t_max), true).is_some()
}

/// The search of one leaf, whose weights are `weights` when it is rational.
#[inline(always)]
fn search_leaf(
    leaf: &PatchLeaf,
    weights: Option<&Weights>,
    frame: &RayFrame,
    span: (f64, f64),
    (t_min, t_max): (f64, f64),
    any: bool,
) -> Option<PatchHit> {
    // The ray's piece in a box holding the leaf passes above or below it: no projection needed.
    if leaf
        .slab
        .misses(frame.origin, frame.dir, span.0, span.1.min(t_max))
    {
        return None;
    }
    let from = departure_point(leaf, frame.leaving);
    // A leaf the ray leaves, first by its normal cone: no projection needed.
    if let Some((s, t)) = from {
        let sign = leaf.normals.sign_along(frame.dir);
        let at = || {
            let d = leaf.sub_patch.eval_with_derivs(s, t);
            d.dp_du.cross(d.dp_dv).dot(frame.dir)
        };
        if departure((s, t), sign, at) == Departure::Only {
            return None;
        }
    }
    let p = frame.project(&leaf.sub_patch);
    let found = match weights {
        None => solve_leaf(&p, leaf, from, (t_min, t_max), any),
        Some(w) => solve_leaf(&RationalPatch::new(&p, w), leaf, from, (t_min, t_max), any),
    };
    found.map(|found| frame.hit(found))
}

/// [`search_leaf`]'s solve of the leaf's ray-space sub-patch `p`, `from` the ray's departure
/// point in it (if any), for a root within `(t_min, t_max)`.
#[inline(always)]
fn solve_leaf<P: RaySpace>(
    p: &P,
    leaf: &PatchLeaf,
    from: Option<(f64, f64)>,
    (t_min, t_max): (f64, f64),
    any: bool,
) -> Option<Found> {
    let mut problem = Problem::new(p, leaf.scale, t_min, any, leaf.deviation);
    if problem.may_hit(p.hull(), t_max) {
        // In ray space the Jacobian is n·d too; its interval test sometimes proves the sign
        // where the cone does not.
        let r = p.roots();
        let known = match from.map(|st| departure(st, jacobian_sign(r), || jacobian_at(r, st.0, st.1))) {
            Some(Departure::Only) => return None,
            // The departure stands for the root Newton would find there (behind the ray).
            Some(Departure::Inside(s, t)) => Some(Root::without_derivatives(s, t, f64::NEG_INFINITY)),
            _ => None,
        };
        problem.solve(p, leaf.window, LEAF_FALLBACK_DEPTH, t_max, known);
    }
    problem.best
}

/// The seed's per-ray intersector: a queue of quarters culled by their bounding boxes down to
/// `depth` splits, then Newton on every survivor; the nearest root wins.
///
/// `depth = 5` is the seed's working setting (sub-patches 1/32 of the patch across); with
/// `depth ≈ 22` the survivors are a few `1e-7` across and this becomes the brute-force
/// reference the prepared intersector is tested against.
pub fn intersect_per_ray(
    patch: &BezierPatch,
    scale: f64,
    ray: &Ray,
    t_min: f64,
    t_max: f64,
    depth: u32,
) -> Option<PatchHit> {
    intersect_per_ray_weighted(patch, None, scale, ray, (t_min, t_max), depth)
}

/// [`intersect_per_ray`] for a patch that may be rational (`weights`, positive), within
/// `(t_min, t_max)`.
pub fn intersect_per_ray_weighted(
    patch: &BezierPatch,
    weights: Option<&Weights>,
    scale: f64,
    ray: &Ray,
    (t_min, t_max): (f64, f64),
    depth: u32,
) -> Option<PatchHit> {
    let frame = RayFrame::new(ray);
    let inv_dir = super::aabb::safe_inverse(ray.dir);
    let pad = BOUNDS_PAD * scale.max(f64::MIN_POSITIVE);
    let mut survivors = Vec::new();
    let mut queue = std::collections::VecDeque::new();
    queue.push_back((*patch, weights.copied(), Window::FULL, 0u32));
    while let Some((sub, w, window, level)) = queue.pop_front() {
        if level == depth {
            survivors.push((sub, w, window));
            continue;
        }
        let children: [(BezierPatch, Option<Weights>); 4] = match &w {
            None => sub.split_quad().map(|c| (c, None)),
            Some(w) => RationalPatch::new(&sub, w)
                .split_quad()
                .map(|c| (c.points(), Some(c.weights))),
        };
        for ((child, cw), quarter) in children.into_iter().zip(window.quarters()) {
            if child
                .bounds()
                .padded(pad)
                .hit_interval(ray.origin, inv_dir, t_max)
                .is_some()
            {
                queue.push_back((child, cw, quarter, level + 1));
            }
        }
    }
    let mut best: Option<PatchHit> = None;
    for (sub, w, window) in survivors {
        let p = frame.project(&sub);
        let t_max = best.map_or(t_max, |h| h.t);
        let found = match &w {
            None => solve_whole(&p, scale, window, (t_min, t_max)),
            Some(w) => solve_whole(&RationalPatch::new(&p, w), scale, window, (t_min, t_max)),
        };
        if let Some(found) = found {
            best = Some(frame.hit(found));
        }
    }
    best
}

/// The per-ray intersector's solve of one surviving ray-space sub-patch.
fn solve_whole<P: RaySpace>(p: &P, scale: f64, window: Window, (t_min, t_max): (f64, f64)) -> Option<Found> {
    let mut problem = Problem::new(p, scale, t_min, false, f64::INFINITY);
    problem.run(p, window, LEAF_FALLBACK_DEPTH, t_max);
    problem.best
}

#[cfg(test)]
mod tests {
    use super::*;

    fn dome() -> BezierPatch {
        let mut pts = [DVec3::ZERO; 16];
        for i in 0..4 {
            for j in 0..4 {
                let (x, y) = (i as f64 - 1.5, j as f64 - 1.5);
                pts[4 * i + j] = DVec3::new(x, y, 1.0 - 0.2 * (x * x + y * y));
            }
        }
        BezierPatch::new(pts)
    }

    #[test]
    fn prepared_and_per_ray_agree_on_a_dome() {
        let patch = dome();
        let scale = patch.bounds().diagonal().length();
        let leaves = subdivide(&patch, 0, &SubdivisionParams::default());
        assert!(leaves.len() > 1);
        for k in 0..200 {
            let (u, v) = ((k % 17) as f64 / 16.0, (k / 17 % 12) as f64 / 11.0);
            let target = patch.eval(u, v);
            let ray = Ray::new(target + DVec3::new(0.3, -0.2, 3.0), -DVec3::new(0.3, -0.2, 3.0));
            let frame = RayFrame::new(&ray);
            let prepared = leaves
                .iter()
                .filter_map(|l| intersect_leaf(l, &frame, l.span(&frame, f64::INFINITY)?, 0.0, f64::INFINITY))
                .min_by(|a, b| a.t.total_cmp(&b.t))
                .expect("prepared hit");
            let reference =
                intersect_per_ray(&patch, scale, &ray, 0.0, f64::INFINITY, 12).expect("reference hit");
            assert!((ray.at(prepared.t) - target).length() < 1e-10 * scale);
            assert!((prepared.t - reference.t).abs() < 1e-9 * scale);
            assert!((prepared.uv - DVec2::new(u, v)).length() < 1e-8);
        }
    }

    #[test]
    fn the_solves_normal_is_the_patchs_normal_from_either_side() {
        let patch = dome();
        let leaves = subdivide(&patch, 0, &SubdivisionParams::default());
        let mut checked = 0;
        for k in 0..200 {
            // Points off the leaves' seams, where a root may lie a rounding outside the leaf.
            let (u, v) = ((k as f64 * 0.618034) % 1.0, (k as f64 * 0.414214 + 0.01) % 1.0);
            let target = patch.eval(u, v);
            // From above and from below: ray frames with the direction's z of either sign, whose
            // bases glam builds with opposite signs.
            for offset in [DVec3::new(0.3, -0.2, 3.0), DVec3::new(-0.4, 0.1, -2.0)] {
                let ray = Ray::new(target + offset, -offset);
                let frame = RayFrame::new(&ray);
                let hit = leaves
                    .iter()
                    .filter_map(|l| {
                        intersect_leaf(l, &frame, l.span(&frame, f64::INFINITY)?, 0.0, f64::INFINITY)
                    })
                    .min_by(|a, b| a.t.total_cmp(&b.t))
                    .expect("prepared hit");
                let solved = hit.normal.expect("a regular point's normal comes from the solve");
                let expected = patch.normal(hit.uv.x, hit.uv.y).expect("the dome is regular");
                assert!((solved - expected).length() < 1e-12, "{solved} vs {expected}");
                let per_ray = intersect_per_ray(&patch, 1.0, &ray, 0.0, f64::INFINITY, 5).expect("hit");
                let per_ray = per_ray.normal.expect("per-ray normal");
                assert!((per_ray - expected).length() < 1e-12, "{per_ray} vs {expected}");
                checked += 1;
            }
        }
        assert_eq!(checked, 400);
    }
}
