//! The spatial index over visible points a photon searches: the hashed grid or the seed's
//! kd-tree ([`IndexKind`]); the image does not depend on which.

use glam::DVec3;

use super::hash_grid::HashGrid;
use super::kd_tree::KdTree;
use super::points::SearchSphere;

/// A built spatial index.
pub enum SpatialIndex {
    /// Hash grid.
    Grid(HashGrid),
    /// kd-tree.
    Kd(KdTree),
}

impl SpatialIndex {
    /// The order photons are best handled in ([`HashGrid::cell_key`]; none for the kd-tree).
    #[inline]
    pub fn sort_key(&self, p: DVec3) -> u64 {
        match self {
            SpatialIndex::Grid(g) => g.cell_key(p),
            SpatialIndex::Kd(_) => 0,
        }
    }

    /// Calls `f` with candidate points near `p` (the caller checks the radius), among them
    /// every point whose sphere, of a radius at most `radius`, holds `p`.
    #[inline]
    pub fn for_candidates<P: SearchSphere>(
        &self,
        points: &[P],
        p: DVec3,
        radius: f64,
        f: &mut impl FnMut(u32),
    ) {
        match self {
            SpatialIndex::Grid(g) => g.for_candidates(p, radius, f),
            SpatialIndex::Kd(t) => t.for_candidates(points, p, f),
        }
    }
}
