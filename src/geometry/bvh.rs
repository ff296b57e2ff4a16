//! A bounding volume hierarchy over primitive bounds: binned SAH construction (Wald 2007,
//! "On fast construction of SAH-based bounding volume hierarchies"; pbrt-v4 `BVHAggregate`)
//! flattened into a depth-first array, traversed with an explicit stack, at each node the child
//! nearer along its split axis first (pbrt-v4's `BVHAggregate::Intersect`).
//!
//! The walk reads the interior nodes in a second layout (`NodePair`): each holds its two
//! children's boxes side by side, as wider BVHs do (Wald et al. 2008, "Getting rid of packets";
//! Embree's BVH4 has four), so one step loads one record and tests both boxes with two-wide
//! arithmetic. The records stay two-wide and in `f64`: a ray leaves a surface only 1e-9 of its
//! coordinates off it ([`super::ray::OFFSET_RELATIVE`]), far below `f32`'s resolution, so boxes
//! rounded to `f32` would hand it back the surface it leaves, and every surface sharing that
//! plane; and four boxes a step span more cache lines and order their lanes with more branches
//! than the step saves.

use glam::DVec3;

use super::aabb::{safe_inverse, Aabb, FAR_SCALE};
use super::ray::Ray;

/// A flattened node: an interior node's first child follows it, the second is at `offset`; a
/// leaf holds `count > 0` primitives starting at `offset` in [`Bvh::order`].
#[derive(Clone, Copy, Debug)]
pub struct BvhNode {
    /// Bounds of everything below.
    pub bounds: Aabb,
    /// Second child (interior) or first primitive (leaf).
    pub offset: u32,
    /// Number of primitives; 0 for an interior node.
    pub count: u16,
    /// Split axis of an interior node: its first child holds the lower side.
    pub axis: u8,
}

/// The hierarchy: nodes plus the primitive order its leaves index into.
#[derive(Clone, Debug, Default)]
pub struct Bvh {
    /// Depth-first nodes; `nodes[0]` is the root.
    pub nodes: Vec<BvhNode>,
    /// Primitive indices, grouped by leaf.
    pub order: Vec<u32>,
    /// Depth of the deepest leaf: a traversal's stack holds fewer entries than this.
    levels: usize,
    /// The interior nodes as the walk reads them, both children's boxes side by side
    /// ([`NodePair`]), in depth-first order; derived from `nodes` after a build or a refit.
    pairs: Vec<NodePair>,
}

/// A child as the walk sees it: a leaf's primitives (`count > 0`, starting at `index` in
/// [`Bvh::order`]) or an interior node (`count == 0`, [`Bvh::pairs`]' entry `index`).
#[derive(Clone, Copy, Debug, Default)]
struct Child {
    index: u32,
    count: u16,
}

impl Child {
    /// The child `node` stands for, given its entry in [`Bvh::pairs`] should it be interior.
    fn of(node: &BvhNode, pair: u32) -> Self {
        if node.count > 0 {
            Self {
                index: node.offset,
                count: node.count,
            }
        } else {
            Self {
                index: pair,
                count: 0,
            }
        }
    }
}

/// An interior node laid out for the walk: its two children's boxes coordinate by coordinate,
/// the two side by side (`lo[axis][child]`), so that one pass of paired arithmetic tests both
/// (two-wide SIMD, which SSE2 has for `f64`), from one place in memory. Each lane computes
/// exactly [`Aabb::hit_interval`]'s arithmetic in its order, so spans, and everything that
/// follows from them, are the same as testing the children's own nodes one by one.
#[derive(Clone, Copy, Debug)]
struct NodePair {
    lo: [[f64; 2]; 3],
    hi: [[f64; 2]; 3],
    child: [Child; 2],
    /// The node's split axis: its first child holds the lower side.
    axis: u8,
}

/// Where the walk goes from an interior node the ray reaches ([`NodePair::enter`]).
struct Step {
    /// The child to go to, and the piece of the ray inside its box.
    near: (Child, (f64, f64)),
    /// The other child and its piece, to be visited later when `both`.
    far: (Child, (f64, f64)),
    /// Whether the ray enters both children (otherwise `far` is not entered).
    both: bool,
}

impl NodePair {
    /// The pieces `(near, far)` of the ray inside each child's box, clipped to `[0, t_max]`
    /// (a lane whose `near > far` misses): [`Aabb::hit_interval`] for both children at once.
    #[inline(always)]
    fn hit_intervals(&self, origin: DVec3, inv_dir: DVec3, t_max: f64) -> ([f64; 2], [f64; 2]) {
        let min = |a: f64, b: f64| if a < b { a } else { b };
        let max = |a: f64, b: f64| if a > b { a } else { b };
        let (o, inv) = (origin.to_array(), inv_dir.to_array());
        let mut near = [[0.0; 2]; 3];
        let mut far = [[0.0; 2]; 3];
        for k in 0..3 {
            for c in 0..2 {
                let a = (self.lo[k][c] - o[k]) * inv[k];
                let b = (self.hi[k][c] - o[k]) * inv[k];
                near[k][c] = min(a, b);
                far[k][c] = max(a, b) * FAR_SCALE;
            }
        }
        let mut t0 = [0.0; 2];
        let mut t1 = [0.0; 2];
        for c in 0..2 {
            t0[c] = max(max(max(near[0][c], near[1][c]), near[2][c]), 0.0);
            t1[c] = min(min(min(far[0][c], far[1][c]), far[2][c]), t_max);
        }
        (t0, t1)
    }

    /// Tests both children's boxes against the ray up to `t_max`: `None` when it enters
    /// neither. The child to go to first is the one on the near side of the node's split axis
    /// for the ray's direction (`negative`: along which axes the ray runs towards lower
    /// coordinates; the first child holds the lower side; pbrt-v4's `dirIsNeg`): the same
    /// answer at every node split on that axis, so the branch is predicted, where comparing
    /// the two entries was the walk's most mispredicted one. Equal entries keep the first
    /// child first, as comparing them did, so that primitives met at exactly one distance
    /// (two walls along their shared edge) resolve as they always have.
    ///
    /// Which children an incoherent ray (a photon, a secondary ray) enters is hard to
    /// predict: one branch asks whether it enters either, and the rest is chosen by selects,
    /// rather than branching four ways on the pair of outcomes.
    #[inline(always)]
    fn enter(&self, origin: DVec3, inv_dir: DVec3, t_max: f64, negative: &[bool; 3]) -> Option<Step> {
        let (t0, t1) = self.hit_intervals(origin, inv_dir, t_max);
        let (a, b) = ((self.child[0], (t0[0], t1[0])), (self.child[1], (t0[1], t1[1])));
        let (hit_a, hit_b) = (t0[0] <= t1[0], t0[1] <= t1[1]);
        if !(hit_a | hit_b) {
            return None;
        }
        let both = hit_a & hit_b;
        let a_first = if both {
            t0[0] == t0[1] || !negative[self.axis as usize]
        } else {
            hit_a
        };
        let (near, far) = if a_first { (a, b) } else { (b, a) };
        Some(Step { near, far, both })
    }
}

const BINS: usize = 16;
const MAX_LEAF: usize = 4;
/// Cost of a node traversal relative to one primitive test, for the SAH.
const TRAVERSAL_COST: f64 = 0.5;
/// Primitives a tree may hold for [`Bvh::traverse`] to test them all rather than walk it: in
/// smallppm's room (nine spheres, six of them walls whose boxes hold the whole room) nearly
/// every ray reaches nearly every leaf, and the box tests only add to the sphere tests.
pub const FLAT_PRIMITIVES: usize = 16;
/// Stack entries a traversal of a tree this deep or less keeps in arrays on the thread's stack.
const SHORT_STACK: usize = 32;
/// The same for deeper trees (deeper still, the stack is on the heap).
const LONG_STACK: usize = 64;

/// A traversal's stack: the nodes still to visit, where the ray enters their boxes and where
/// it leaves them. A node is kept as its [`Child`]'s two fields in two arrays, 6 bytes an
/// entry, where one array of `Child` would take 8 with its padding.
struct Stack<'a> {
    node: &'a mut [u32],
    count: &'a mut [u16],
    enter: &'a mut [f64],
    exit: &'a mut [f64],
    /// Entries held.
    top: usize,
}

impl Stack<'_> {
    /// Writes `child` and its piece of the ray above the entries held, and holds it when
    /// `keep`: written either way, so that whether it is kept is no branch.
    #[inline(always)]
    fn push_if(&mut self, (child, (enter, exit)): (Child, (f64, f64)), keep: bool) {
        let top = self.top;
        self.node[top] = child.index;
        self.count[top] = child.count;
        self.enter[top] = enter;
        self.exit[top] = exit;
        self.top += keep as usize;
    }

    /// The latest entry the ray still enters before `t_max`, dropping those it does not;
    /// `None` when none is left.
    #[inline(always)]
    fn pop_before(&mut self, t_max: f64) -> Option<(Child, (f64, f64))> {
        while self.top > 0 {
            self.top -= 1;
            let top = self.top;
            if self.enter[top] <= t_max {
                let child = Child {
                    index: self.node[top],
                    count: self.count[top],
                };
                return Some((child, (self.enter[top], self.exit[top])));
            }
        }
        None
    }
}

struct BuildItem {
    bounds: Aabb,
    centroid: DVec3,
    index: u32,
}

impl Bvh {
    /// Bytes its vectors hold (their capacities).
    pub fn memory(&self) -> usize {
        self.nodes.capacity() * std::mem::size_of::<BvhNode>()
            + self.order.capacity() * std::mem::size_of::<u32>()
            + self.pairs.capacity() * std::mem::size_of::<NodePair>()
    }

    /// Builds a hierarchy over primitives with the given bounds (index `i` is primitive `i`).
    pub fn build(bounds: &[Aabb]) -> Self {
        let mut items: Vec<BuildItem> = bounds
            .iter()
            .enumerate()
            .map(|(i, b)| BuildItem {
                bounds: *b,
                centroid: b.centroid(),
                index: i as u32,
            })
            .collect();
        let mut bvh = Bvh {
            nodes: Vec::with_capacity(2 * bounds.len()),
            order: Vec::with_capacity(bounds.len()),
            levels: 0,
            pairs: Vec::new(),
        };
        if !items.is_empty() {
            bvh.build_node(&mut items);
        }
        bvh.levels = bvh.measure_depth();
        bvh.pair_up();
        bvh
    }

    /// Derives [`Bvh::pairs`] from [`Bvh::nodes`]: interior nodes keep their depth-first order,
    /// so a node's first child, when interior, is the next pair.
    fn pair_up(&mut self) {
        let mut pair_of = Vec::with_capacity(self.nodes.len());
        let mut interior = 0u32;
        for n in &self.nodes {
            pair_of.push(interior);
            interior += (n.count == 0) as u32;
        }
        let child = |node: usize| Child::of(&self.nodes[node], pair_of[node]);
        let mut pairs = Vec::with_capacity(interior as usize);
        pairs.extend(
            (0..self.nodes.len())
                .filter(|&i| self.nodes[i].count == 0)
                .map(|i| {
                    let n = &self.nodes[i];
                    let (a, b) = (&self.nodes[i + 1].bounds, &self.nodes[n.offset as usize].bounds);
                    NodePair {
                        lo: [0, 1, 2].map(|k| [a.min[k], b.min[k]]),
                        hi: [0, 1, 2].map(|k| [a.max[k], b.max[k]]),
                        child: [child(i + 1), child(n.offset as usize)],
                        axis: n.axis,
                    }
                }),
        );
        self.pairs = pairs;
    }

    /// Bounds of everything, or the empty box.
    pub fn bounds(&self) -> Aabb {
        self.nodes.first().map_or(Aabb::EMPTY, |n| n.bounds)
    }

    fn push_leaf(&mut self, bounds: Aabb, items: &[BuildItem]) -> usize {
        let node = self.nodes.len();
        self.nodes.push(BvhNode {
            bounds,
            offset: self.order.len() as u32,
            count: items.len() as u16,
            axis: 0,
        });
        self.order.extend(items.iter().map(|it| it.index));
        node
    }

    fn build_node(&mut self, items: &mut [BuildItem]) -> usize {
        let bounds = items.iter().fold(Aabb::EMPTY, |b, it| b.union(it.bounds));
        if items.len() <= 1 {
            return self.push_leaf(bounds, items);
        }
        let centroids = items.iter().fold(Aabb::EMPTY, |b, it| b.grow(it.centroid));
        let axis = centroids.longest_axis();
        let (lo, hi) = (centroids.min[axis], centroids.max[axis]);
        if hi <= lo {
            // All centroids coincide: no split can separate them.
            if items.len() <= u16::MAX as usize {
                return self.push_leaf(bounds, items);
            }
            let mid = items.len() / 2;
            return self.push_interior(bounds, axis, items, mid);
        }

        // Bin centroids and sweep for the cheapest SAH split.
        let bin_of = |c: DVec3| (((c[axis] - lo) / (hi - lo) * BINS as f64) as usize).min(BINS - 1);
        let mut bin_bounds = [Aabb::EMPTY; BINS];
        let mut bin_count = [0usize; BINS];
        for it in items.iter() {
            let b = bin_of(it.centroid);
            bin_bounds[b] = bin_bounds[b].union(it.bounds);
            bin_count[b] += 1;
        }
        let mut below_area = [0.0; BINS - 1];
        let mut below_count = [0usize; BINS - 1];
        let (mut acc, mut n) = (Aabb::EMPTY, 0);
        for k in 0..BINS - 1 {
            acc = acc.union(bin_bounds[k]);
            n += bin_count[k];
            below_area[k] = acc.surface_area();
            below_count[k] = n;
        }
        let (mut best_cost, mut best_split) = (f64::INFINITY, 0);
        let (mut acc, mut n) = (Aabb::EMPTY, 0);
        for k in (0..BINS - 1).rev() {
            acc = acc.union(bin_bounds[k + 1]);
            n += bin_count[k + 1];
            let cost = below_count[k] as f64 * below_area[k] + n as f64 * acc.surface_area();
            if cost < best_cost {
                best_cost = cost;
                best_split = k;
            }
        }
        let leaf_cost = items.len() as f64;
        let split_cost = TRAVERSAL_COST + best_cost / bounds.surface_area().max(f64::MIN_POSITIVE);
        if items.len() <= MAX_LEAF && leaf_cost <= split_cost {
            return self.push_leaf(bounds, items);
        }
        let mut mid = partition(items, |it| bin_of(it.centroid) <= best_split);
        if mid == 0 || mid == items.len() {
            mid = items.len() / 2;
            items.select_nth_unstable_by(mid, |a, b| a.centroid[axis].total_cmp(&b.centroid[axis]));
        }
        self.push_interior(bounds, axis, items, mid)
    }

    fn push_interior(&mut self, bounds: Aabb, axis: usize, items: &mut [BuildItem], mid: usize) -> usize {
        let node = self.nodes.len();
        self.nodes.push(BvhNode {
            bounds,
            offset: 0,
            count: 0,
            axis: axis as u8,
        });
        let (left, right) = items.split_at_mut(mid);
        self.build_node(left);
        let second = self.build_node(right);
        self.nodes[node].offset = second as u32;
        node
    }

    /// Visits, nearer children first, every primitive whose leaf the ray reaches before `t_max`
    /// (in a tree of at most [`FLAT_PRIMITIVES`], every primitive, in the tree's order).
    /// `visit(primitive, t_max, span)` returns the distance of a nearer hit, which then bounds
    /// the rest of the traversal; `span` is the piece `(near, far)` of the ray inside the
    /// leaf's box ([`Aabb::hit_interval`]'s, `far` clipped to `t_max` when the box was tested;
    /// `(0, t_max)` in a tree that is not walked). Returns the final `t_max`.
    #[inline]
    pub fn traverse(
        &self,
        ray: &Ray,
        mut t_max: f64,
        mut visit: impl FnMut(u32, f64, (f64, f64)) -> Option<f64>,
    ) -> f64 {
        if self.order.len() <= FLAT_PRIMITIVES {
            for &prim in &self.order {
                if let Some(t) = visit(prim, t_max, (0.0, t_max)) {
                    t_max = t_max.min(t);
                }
            }
            return t_max;
        }
        let inv_dir = safe_inverse(ray.dir);
        let root = match self.nodes.first() {
            Some(root) => match root.bounds.hit_interval(ray.origin, inv_dir, t_max) {
                Some(span) => span,
                None => return t_max,
            },
            None => return t_max,
        };
        // Stack entries are nodes whose box the ray enters and leaves at the stored distances:
        // a node's ancestors' other children, fewer than the tree's depth. Plain arrays (not
        // an array of triples, whose padding makes the start-up zeroing a scalar loop).
        // Zeroing is a measurable part of a short traversal, so the arrays are sized to the
        // tree.
        if self.levels <= SHORT_STACK {
            self.walk_inline::<SHORT_STACK>(ray, inv_dir, root, t_max, visit)
        } else if self.levels <= LONG_STACK {
            self.walk_inline::<LONG_STACK>(ray, inv_dir, root, t_max, visit)
        } else {
            self.traverse_deep(ray, inv_dir, root, t_max, visit)
        }
    }

    /// [`Bvh::walk`] with a stack of `N` entries in arrays on the thread's stack (`N` at least
    /// [`Bvh::depth`]).
    #[inline(always)]
    fn walk_inline<const N: usize>(
        &self,
        ray: &Ray,
        inv_dir: DVec3,
        root: (f64, f64),
        t_max: f64,
        visit: impl FnMut(u32, f64, (f64, f64)) -> Option<f64>,
    ) -> f64 {
        let stack = Stack {
            node: &mut [0; N],
            count: &mut [0; N],
            enter: &mut [0.0; N],
            exit: &mut [0.0; N],
            top: 0,
        };
        self.walk(ray, inv_dir, root, t_max, visit, stack)
    }

    /// [`Bvh::traverse`] for a degenerate tree, deeper than the inline stacks: primitives
    /// spread so unevenly (say, exponentially along a line) that the SAH splits off a few at a
    /// time.
    #[cold]
    #[inline(never)]
    fn traverse_deep(
        &self,
        ray: &Ray,
        inv_dir: DVec3,
        root: (f64, f64),
        t_max: f64,
        visit: impl FnMut(u32, f64, (f64, f64)) -> Option<f64>,
    ) -> f64 {
        let (mut node, mut count, mut enter, mut exit) = (
            vec![0; self.levels],
            vec![0; self.levels],
            vec![0.0; self.levels],
            vec![0.0; self.levels],
        );
        let stack = Stack {
            node: &mut node,
            count: &mut count,
            enter: &mut enter,
            exit: &mut exit,
            top: 0,
        };
        self.walk(ray, inv_dir, root, t_max, visit, stack)
    }

    /// [`Bvh::traverse`] past the root's box (which the ray enters over `root`), with a stack
    /// of at least [`Bvh::depth`] entries.
    #[inline]
    fn walk(
        &self,
        ray: &Ray,
        inv_dir: DVec3,
        root: (f64, f64),
        mut t_max: f64,
        mut visit: impl FnMut(u32, f64, (f64, f64)) -> Option<f64>,
        mut stack: Stack<'_>,
    ) -> f64 {
        // Along which axes the ray runs towards lower coordinates.
        let negative = [ray.dir.x < 0.0, ray.dir.y < 0.0, ray.dir.z < 0.0];
        // The root, when interior, is the first pair; `span` is the piece of the ray inside
        // the current node's box.
        let (mut node, mut span) = (Child::of(&self.nodes[0], 0), root);
        loop {
            if node.count > 0 {
                let first = node.index as usize;
                for &prim in &self.order[first..first + node.count as usize] {
                    if let Some(t) = visit(prim, t_max, span) {
                        t_max = t_max.min(t);
                    }
                }
            } else if let Some(step) =
                self.pairs[node.index as usize].enter(ray.origin, inv_dir, t_max, &negative)
            {
                // Go to the nearer child, keep the farther for later.
                stack.push_if(step.far, step.both);
                (node, span) = step.near;
                continue;
            }
            // The next node the ray still reaches before the nearest hit so far.
            match stack.pop_before(t_max) {
                Some(next) => (node, span) = next,
                None => return t_max,
            }
        }
    }

    /// Whether any primitive reports a hit before `t_max`: `test(primitive, span)` for each
    /// candidate until one returns `true` (shadow rays); `span` as [`Bvh::traverse`]'s.
    pub fn any(&self, ray: &Ray, t_max: f64, mut test: impl FnMut(u32, (f64, f64)) -> bool) -> bool {
        let mut found = false;
        self.traverse(ray, t_max, |prim, _, span| {
            if !found && test(prim, span) {
                found = true;
                // A negative distance ends the traversal: no box starts before it.
                return Some(-1.0);
            }
            None
        });
        found
    }

    /// Recomputes every node's bounds from new primitive bounds, keeping the tree's shape
    /// (a "refit": the usual way to follow deforming geometry without a rebuild). Children
    /// follow their parent in the depth-first array, so one backward sweep suffices.
    pub fn refit(&mut self, bounds: &[Aabb]) {
        for i in (0..self.nodes.len()).rev() {
            let n = self.nodes[i];
            self.nodes[i].bounds = if n.count > 0 {
                let first = n.offset as usize;
                self.order[first..first + n.count as usize]
                    .iter()
                    .fold(Aabb::EMPTY, |b, &p| b.union(bounds[p as usize]))
            } else {
                self.nodes[i + 1]
                    .bounds
                    .union(self.nodes[n.offset as usize].bounds)
            };
        }
        self.pair_up();
    }

    /// Depth of the deepest leaf (for statistics and the stack-size guarantee).
    pub fn depth(&self) -> usize {
        self.levels
    }

    /// Walks the tree for [`Bvh::depth`].
    fn measure_depth(&self) -> usize {
        fn walk(bvh: &Bvh, node: usize) -> usize {
            let n = &bvh.nodes[node];
            if n.count > 0 {
                1
            } else {
                1 + walk(bvh, node + 1).max(walk(bvh, n.offset as usize))
            }
        }
        if self.nodes.is_empty() {
            0
        } else {
            walk(self, 0)
        }
    }
}

/// Moves the items satisfying `pred` to the front; returns how many there are.
fn partition<T>(items: &mut [T], pred: impl Fn(&T) -> bool) -> usize {
    let mut first = 0;
    for k in 0..items.len() {
        if pred(&items[k]) {
            items.swap(first, k);
            first += 1;
        }
    }
    first
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finds_the_same_nearest_box_as_brute_force() {
        // A deterministic cloud of small boxes.
        let mut boxes = Vec::new();
        let mut x = 0x2545F4914F6CDD1Du64;
        let mut next = || {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            (x >> 11) as f64 / (1u64 << 53) as f64
        };
        for _ in 0..2000 {
            let c = DVec3::new(next(), next(), next()) * 10.0;
            boxes.push(Aabb::new(c, c + 0.2));
        }
        // A tree walked, small trees tested in full (the first FLAT_PRIMITIVES boxes, larger
        // so that rays meet several) and the smallest tree that is walked.
        for n in [2000, FLAT_PRIMITIVES, FLAT_PRIMITIVES + 1] {
            let boxes: Vec<Aabb> = if n == 2000 {
                boxes.clone()
            } else {
                boxes[..n]
                    .iter()
                    .map(|b| Aabb::new(b.min - 2.0, b.max + 2.0))
                    .collect()
            };
            let bvh = Bvh::build(&boxes);
            assert!(bvh.depth() < 64);
            let mut hits = 0;
            for _ in 0..500 {
                let o = DVec3::new(next(), next(), next()) * 14.0 - 2.0;
                let d = DVec3::new(next() - 0.5, next() - 0.5, next() - 0.5);
                let ray = Ray::new(o, d);
                let inv = safe_inverse(ray.dir);
                let entry = |b: &Aabb| b.hit_interval(ray.origin, inv, f64::INFINITY).map(|(t0, _)| t0);
                let brute = boxes.iter().filter_map(entry).fold(f64::INFINITY, f64::min);
                let found = bvh.traverse(&ray, f64::INFINITY, |p, t_max, span| {
                    // The span is the piece of the ray in a box holding the primitive's.
                    if let Some(own) = boxes[p as usize].hit_interval(ray.origin, inv, t_max) {
                        assert!(span.0 <= own.0 && own.1 <= span.1, "{own:?} outside {span:?}");
                    }
                    entry(&boxes[p as usize])
                });
                assert_eq!(brute, found, "{n} boxes");
                let any = bvh.any(&ray, f64::INFINITY, |p, _| entry(&boxes[p as usize]).is_some());
                assert_eq!(any, brute.is_finite(), "{n} boxes");
                hits += brute.is_finite() as usize;
                if n <= FLAT_PRIMITIVES {
                    let mut visits = 0;
                    bvh.traverse(&ray, f64::INFINITY, |_, _, _| {
                        visits += 1;
                        None
                    });
                    assert_eq!(visits, n, "a small tree's primitives are all tested");
                }
            }
            assert!(hits > 100, "{n} boxes: {hits} of 500 rays hit");
        }
    }

    /// The binary walk the paired layout replaced, over [`Bvh::nodes`] and their own boxes: a
    /// reference for the order of the visits and their spans.
    fn reference_walk(
        bvh: &Bvh,
        ray: &Ray,
        mut t_max: f64,
        visit: &mut dyn FnMut(u32, f64, (f64, f64)) -> Option<f64>,
    ) {
        let inv = safe_inverse(ray.dir);
        let negative = [ray.dir.x < 0.0, ray.dir.y < 0.0, ray.dir.z < 0.0];
        let Some(root) = bvh.nodes[0].bounds.hit_interval(ray.origin, inv, t_max) else {
            return;
        };
        let mut stack = vec![(0usize, root)];
        while let Some((node, span)) = stack.pop() {
            if span.0 > t_max {
                continue;
            }
            let n = bvh.nodes[node];
            if n.count > 0 {
                let first = n.offset as usize;
                for &prim in &bvh.order[first..first + n.count as usize] {
                    if let Some(t) = visit(prim, t_max, span) {
                        t_max = t_max.min(t);
                    }
                }
                continue;
            }
            let (a, b) = (node + 1, n.offset as usize);
            let ha = bvh.nodes[a].bounds.hit_interval(ray.origin, inv, t_max);
            let hb = bvh.nodes[b].bounds.hit_interval(ray.origin, inv, t_max);
            match (ha, hb) {
                (Some(sa), Some(sb)) => {
                    let first = sa.0 == sb.0 || !negative[n.axis as usize];
                    let (near, far) = if first {
                        ((a, sa), (b, sb))
                    } else {
                        ((b, sb), (a, sa))
                    };
                    stack.push(far);
                    stack.push(near);
                }
                (Some(sa), None) => stack.push((a, sa)),
                (None, Some(sb)) => stack.push((b, sb)),
                (None, None) => {}
            }
        }
    }

    #[test]
    fn the_paired_walk_visits_as_the_binary_walk_did() {
        // Boxes on a grid (many entries tie where rays run along a row) and a random cloud.
        let mut x = 0x9E3779B97F4A7C15u64;
        let mut next = || {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            (x >> 11) as f64 / (1u64 << 53) as f64
        };
        let grid: Vec<Aabb> = (0..400)
            .map(|i| {
                let c = DVec3::new((i % 20) as f64, (i / 20) as f64, 0.0);
                Aabb::new(c, c + DVec3::new(1.0, 1.0, 0.5))
            })
            .collect();
        let cloud: Vec<Aabb> = (0..1500)
            .map(|_| {
                let c = DVec3::new(next(), next(), next()) * 20.0;
                Aabb::new(c, c + DVec3::new(next(), next(), next()))
            })
            .collect();
        for boxes in [grid, cloud] {
            let bvh = Bvh::build(&boxes);
            for k in 0..400 {
                let o = DVec3::new(next() * 24.0 - 2.0, next() * 24.0 - 2.0, next() * 8.0 - 4.0);
                // Every fourth ray runs along an axis, along the grid's rows and columns.
                let d = if k % 4 == 0 {
                    [DVec3::X, DVec3::NEG_Y, DVec3::Z][k / 4 % 3]
                } else {
                    DVec3::new(next() - 0.5, next() - 0.5, next() - 0.5)
                };
                let ray = Ray::new(o, d);
                let inv = safe_inverse(ray.dir);
                // A visit that records what it is shown and reports every other box's entry as a
                // hit, so that t_max shrinks and prunes as a search's would.
                let record = |log: &mut Vec<(u32, f64, (f64, f64))>, p: u32, t_max: f64, span: (f64, f64)| {
                    log.push((p, t_max, span));
                    p.is_multiple_of(2)
                        .then(|| {
                            boxes[p as usize]
                                .hit_interval(ray.origin, inv, t_max)
                                .map(|h| h.0)
                        })
                        .flatten()
                };
                let (mut walked, mut reference) = (Vec::new(), Vec::new());
                bvh.traverse(&ray, f64::INFINITY, |p, t, span| record(&mut walked, p, t, span));
                reference_walk(&bvh, &ray, f64::INFINITY, &mut |p, t, span| {
                    record(&mut reference, p, t, span)
                });
                assert_eq!(walked, reference, "ray {k}");
            }
        }
    }

    #[test]
    fn trees_deeper_than_the_inline_stacks_are_traversed_in_full() {
        // Boxes at exponentially growing distances along x: the binned SAH splits off a few
        // at a time, so the tree is far deeper than a balanced one. A ray along the line from
        // beyond the farthest box passes through every one of them. (Before the stack was
        // sized to the tree, the deeper one overflowed a fixed stack of 64 and panicked.)
        for (growth, depths) in [
            (1.05f64, SHORT_STACK + 1..=LONG_STACK),
            (1.1, LONG_STACK + 1..=usize::MAX),
        ] {
            let boxes: Vec<Aabb> = (0..3000)
                .map(|k| {
                    let x = growth.powi(k);
                    Aabb::new(DVec3::new(x, 0.0, 0.0), DVec3::new(x * 1.0001 + 1.0, 1.0, 1.0))
                })
                .collect();
            let bvh = Bvh::build(&boxes);
            assert!(
                depths.contains(&bvh.depth()),
                "growth {growth}: depth {}",
                bvh.depth()
            );
            let ray = Ray::new(DVec3::new(1e130, 0.5, 0.5), DVec3::new(-1.0, 0.0, 0.0));
            let inv = safe_inverse(ray.dir);
            let entry = |b: &Aabb| b.hit_interval(ray.origin, inv, f64::INFINITY).map(|(t0, _)| t0);
            let mut visited = 0;
            let found = bvh.traverse(&ray, f64::INFINITY, |p, _, _| {
                visited += 1;
                entry(&boxes[p as usize]).map(|_| f64::INFINITY)
            });
            assert_eq!(found, f64::INFINITY);
            assert_eq!(visited, boxes.len(), "growth {growth}");
            let nearest = bvh.traverse(&ray, f64::INFINITY, |p, _, _| entry(&boxes[p as usize]));
            let brute = boxes.iter().filter_map(entry).fold(f64::INFINITY, f64::min);
            assert_eq!(nearest, brute, "growth {growth}");
        }
    }

    #[test]
    fn refit_matches_a_rebuild_for_moved_boxes() {
        let boxes: Vec<Aabb> = (0..300)
            .map(|i| {
                let c = DVec3::new((i % 7) as f64, (i % 11) as f64, (i / 11) as f64);
                Aabb::new(c, c + 0.5)
            })
            .collect();
        let mut bvh = Bvh::build(&boxes);
        let moved: Vec<Aabb> = boxes
            .iter()
            .enumerate()
            .map(|(i, b)| {
                if i % 5 == 0 {
                    Aabb::new(b.min - 3.0, b.max + 1.0)
                } else {
                    *b
                }
            })
            .collect();
        bvh.refit(&moved);
        assert_eq!(bvh.bounds(), Bvh::build(&moved).bounds());
        for k in 0..200 {
            let o = DVec3::new(-5.0, k as f64 * 0.1 - 2.0, (k % 13) as f64);
            let ray = Ray::new(o, DVec3::new(1.0, 0.05, 0.02));
            let inv = safe_inverse(ray.dir);
            let entry = |b: &Aabb| b.hit_interval(ray.origin, inv, f64::INFINITY).map(|(t0, _)| t0);
            let brute = moved.iter().filter_map(entry).fold(f64::INFINITY, f64::min);
            assert_eq!(
                brute,
                bvh.traverse(&ray, f64::INFINITY, |p, _, _| entry(&moved[p as usize]))
            );
        }
    }
}
