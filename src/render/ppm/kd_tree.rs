//! The seed report's kd-tree over visible points (§3.2.1): a balanced tree (median splits on
//! the widest axis) whose nodes are the points themselves, each storing the largest search
//! radius in its subtree, so a photon descends only where some point's sphere can reach it.

use glam::DVec3;

use super::points::SearchSphere;

#[derive(Clone, Copy, Debug)]
struct Node {
    point: u32,
    axis: u8,
    /// Largest `radius²` of any point in this subtree.
    max_radius2: f64,
}

/// A kd-tree stored as an implicit balanced binary tree over `nodes[lo..hi]` ranges.
#[derive(Clone, Debug, Default)]
pub struct KdTree {
    nodes: Vec<Node>,
}

impl KdTree {
    /// Builds the tree over `points`.
    pub fn build<P: SearchSphere>(points: &[P]) -> Self {
        let mut order: Vec<u32> = (0..points.len() as u32).collect();
        let mut nodes = vec![
            Node {
                point: 0,
                axis: 0,
                max_radius2: 0.0
            };
            points.len()
        ];
        build(points, &mut order, &mut nodes, 0);
        Self { nodes }
    }

    /// Calls `f` with every point whose search sphere's subtree bound reaches `p` (a superset:
    /// the caller checks distances).
    pub fn for_candidates<P: SearchSphere>(&self, points: &[P], p: DVec3, f: &mut impl FnMut(u32)) {
        self.visit(points, 0, self.nodes.len(), p, f);
    }

    fn visit<P: SearchSphere>(&self, points: &[P], lo: usize, hi: usize, p: DVec3, f: &mut impl FnMut(u32)) {
        if lo >= hi {
            return;
        }
        let mid = (lo + hi) / 2;
        let node = self.nodes[mid];
        if node.max_radius2 <= 0.0 {
            return;
        }
        let split = points[node.point as usize].centre()[node.axis as usize];
        let d = p[node.axis as usize] - split;
        let (near, far) = if d < 0.0 {
            ((lo, mid), (mid + 1, hi))
        } else {
            ((mid + 1, hi), (lo, mid))
        };
        self.visit(points, near.0, near.1, p, f);
        f(node.point);
        // The far side holds points on the other side of the split plane: reachable only if
        // some sphere there is larger than the distance to the plane.
        if far.0 < far.1 {
            let far_mid = (far.0 + far.1) / 2;
            if d * d <= self.nodes[far_mid].max_radius2 {
                self.visit(points, far.0, far.1, p, f);
            }
        }
    }
}

fn build<P: SearchSphere>(points: &[P], order: &mut [u32], nodes: &mut [Node], offset: usize) -> f64 {
    if order.is_empty() {
        return 0.0;
    }
    let bounds = order
        .iter()
        .fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), &i| {
            let p = points[i as usize].centre();
            (lo.min(p), hi.max(p))
        });
    let extent = bounds.1 - bounds.0;
    let axis = if extent.x >= extent.y && extent.x >= extent.z {
        0
    } else if extent.y >= extent.z {
        1
    } else {
        2
    };
    let mid = order.len() / 2;
    order.select_nth_unstable_by(mid, |&a, &b| {
        points[a as usize].centre()[axis].total_cmp(&points[b as usize].centre()[axis])
    });
    let point = order[mid];
    let (left, rest) = order.split_at_mut(mid);
    let right = &mut rest[1..];
    let left_max = build(points, left, nodes, offset);
    let right_max = build(points, right, nodes, offset + mid + 1);
    let max_radius2 = points[point as usize].reach2().max(left_max).max(right_max);
    nodes[offset + mid] = Node {
        point,
        axis: axis as u8,
        max_radius2,
    };
    max_radius2
}
