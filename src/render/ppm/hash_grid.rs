//! A hashed uniform grid over visible points, rebuilt every pass (Hachisuka & Jensen 2009 §4;
//! pbrt-v4 `SPPMIntegrator`): each point is entered in every cell its search sphere's box
//! overlaps, so a photon looks in the one cell it falls into. Cells are hashed into a table of
//! about twice as many buckets as entries and stored compactly (counting sort, no per-cell vectors).

use glam::{DVec3, IVec3};
use rayon::prelude::*;

use super::visible::VisiblePoint;

/// The grid: bucket `b` holds `entries[starts[b]..starts[b + 1]]`.
#[derive(Clone, Debug, Default)]
pub struct HashGrid {
    origin: DVec3,
    inv_cell: f64,
    mask: u64,
    starts: Vec<u32>,
    entries: Vec<u32>,
}

#[inline]
fn hash(c: IVec3) -> u64 {
    // Teschner et al. 2003 spatial hash.
    ((c.x as i64 as u64).wrapping_mul(73_856_093)
        ^ (c.y as i64 as u64).wrapping_mul(19_349_663)
        ^ (c.z as i64 as u64).wrapping_mul(83_492_791))
    .wrapping_mul(0x9e37_79b9_7f4a_7c15)
        >> 16
}

impl HashGrid {
    /// Builds the grid over `points`, with cells as wide as the largest search diameter.
    pub fn build(points: &[VisiblePoint]) -> Self {
        if points.is_empty() {
            return Self::default();
        }
        let max_r = points.iter().map(|p| p.radius2).fold(0.0f64, f64::max).sqrt();
        let cell = (2.0 * max_r).max(1e-12);
        let origin = points
            .iter()
            .fold(DVec3::splat(f64::INFINITY), |m, p| m.min(p.position))
            - DVec3::splat(max_r);
        let inv_cell = 1.0 / cell;
        let cell_of = |p: DVec3| ((p - origin) * inv_cell).floor().as_ivec3();
        // Each point's cell range (a sphere of radius ≤ cell/2 spans at most 2 cells per axis).
        let ranges: Vec<(IVec3, IVec3)> = points
            .iter()
            .map(|p| {
                let r = p.radius2.sqrt();
                (cell_of(p.position - r), cell_of(p.position + r))
            })
            .collect();
        // The distinct buckets of each point's cells: two of its cells may hash to the same
        // bucket, and a point listed twice there would be handed a photon twice.
        let buckets_guess = (2 * points.len() * 4).next_power_of_two().max(2);
        let mask = buckets_guess as u64 - 1;
        let point_buckets: Vec<Vec<u64>> = ranges
            .par_iter()
            .map(|(lo, hi)| {
                let mut b = Vec::with_capacity(8);
                for z in lo.z..=hi.z {
                    for y in lo.y..=hi.y {
                        for x in lo.x..=hi.x {
                            b.push(hash(IVec3::new(x, y, z)) & mask);
                        }
                    }
                }
                b.sort_unstable();
                b.dedup();
                b
            })
            .collect();
        let count: usize = point_buckets.iter().map(Vec::len).sum();
        let buckets = buckets_guess;
        let mut starts = vec![0u32; buckets + 1];
        for bs in &point_buckets {
            for &b in bs {
                starts[b as usize + 1] += 1;
            }
        }
        for b in 0..buckets {
            starts[b + 1] += starts[b];
        }
        let mut fill = starts.clone();
        let mut entries = vec![0u32; count];
        for (k, bs) in point_buckets.iter().enumerate() {
            for &b in bs {
                entries[fill[b as usize] as usize] = k as u32;
                fill[b as usize] += 1;
            }
        }
        Self {
            origin,
            inv_cell,
            mask,
            starts,
            entries,
        }
    }

    /// Indices of the points whose search sphere may contain `p` (a superset: the caller
    /// checks distances).
    #[inline]
    pub fn candidates(&self, p: DVec3) -> &[u32] {
        if self.entries.is_empty() {
            return &[];
        }
        let c = ((p - self.origin) * self.inv_cell).floor().as_ivec3();
        let b = (hash(c) & self.mask) as usize;
        &self.entries[self.starts[b] as usize..self.starts[b + 1] as usize]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::ppm::kd_tree::KdTree;

    #[test]
    fn grid_and_kd_tree_return_each_point_in_reach_exactly_once() {
        let mut x = 0x1234_5678_9abc_def1u64;
        let mut next = || {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            (x >> 11) as f64 / (1u64 << 53) as f64
        };
        let points: Vec<VisiblePoint> = (0..3000)
            .map(|k| VisiblePoint {
                slot: k,
                position: DVec3::new(next(), next(), next()) * 10.0,
                normal: DVec3::Z,
                weight: DVec3::ONE,
                radius2: (0.05 + 0.3 * next()).powi(2),
            })
            .collect();
        let grid = HashGrid::build(&points);
        let kd = KdTree::build(&points);
        for _ in 0..2000 {
            let p = DVec3::new(next(), next(), next()) * 10.0;
            let inside =
                |k: &u32| (points[*k as usize].position - p).length_squared() <= points[*k as usize].radius2;
            let mut brute: Vec<u32> = (0..points.len() as u32).filter(inside).collect();
            let mut from_grid: Vec<u32> = grid.candidates(p).iter().copied().filter(inside).collect();
            let mut from_kd = Vec::new();
            kd.for_candidates(&points, p, &mut |k| {
                if inside(&k) {
                    from_kd.push(k)
                }
            });
            brute.sort_unstable();
            from_grid.sort_unstable();
            from_kd.sort_unstable();
            assert_eq!(from_grid, brute);
            assert_eq!(from_kd, brute);
        }
    }
}
