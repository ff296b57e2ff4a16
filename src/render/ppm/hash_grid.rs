//! A hashed uniform grid over visible points, rebuilt every pass (Hachisuka & Jensen 2009 §4;
//! pbrt-v4 `SPPMIntegrator`): each point is entered in every cell its search sphere's box
//! overlaps, so a photon looks in the one cell it falls into. Cells are hashed into a table of
//! about twice as many buckets as entries and stored compactly (counting sort, no per-cell vectors).

use glam::{DVec3, IVec3};
use rayon::prelude::*;

use super::points::SearchSphere;
#[cfg(test)]
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

/// Points whose buckets are computed together while the grid is built.
const BLOCK: usize = 1 << 16;

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
    pub fn build<P: SearchSphere + Sync>(points: &[P]) -> Self {
        if points.is_empty() {
            return Self::default();
        }
        let max_r = points.iter().map(|p| p.reach2()).fold(0.0f64, f64::max).sqrt();
        let cell = (2.0 * max_r).max(1e-12);
        let origin = points
            .iter()
            .fold(DVec3::splat(f64::INFINITY), |m, p| m.min(p.centre()))
            - DVec3::splat(max_r);
        let inv_cell = 1.0 / cell;
        let cell_of = |p: DVec3| ((p - origin) * inv_cell).floor().as_ivec3();
        // Two buckets per point (about four entries a bucket): a cell holds the entries of many
        // points, so cells are far fewer than buckets and rarely share one. Eight per point
        // (67 MiB of bucket starts at 1920×1080) measured no faster in `bench ppm`, and 4 %
        // faster at most in 1920×1080 passes of 2M photons.
        let buckets = (2 * points.len()).next_power_of_two().max(2);
        let mask = buckets as u64 - 1;
        // The distinct buckets of a point's cells: two of its cells may hash to the same
        // bucket, and a point listed twice there would be handed a photon twice. A sphere spans
        // 2 cells per axis, 3 when rounding puts its edge a hair past a cell boundary (seen in
        // the Cornell box), so at most 27.
        let buckets_of = |p: &P| -> ([u32; 27], usize) {
            let (c, r) = (p.centre(), p.reach2().sqrt());
            let (lo, hi) = (cell_of(c - r), cell_of(c + r));
            let mut b = [0u32; 27];
            let mut n = 0;
            for z in lo.z..=hi.z {
                for y in lo.y..=hi.y {
                    for x in lo.x..=hi.x {
                        let h = (hash(IVec3::new(x, y, z)) & mask) as u32;
                        if n < b.len() && !b[..n].contains(&h) {
                            b[n] = h;
                            n += 1;
                        }
                    }
                }
            }
            (b, n)
        };
        // Counting sort by bucket, a block of points at a time (the blocks' buckets are
        // computed in parallel, twice, rather than held for all points: at 1920×1080 that list
        // would be 66 MiB): bucket sizes, running ends, then entries filled from the back so
        // that each `starts[b]` comes down to its bucket's beginning and points stay in index
        // order.
        let block_ids =
            |block: &[P]| -> Vec<([u32; 27], usize)> { block.par_iter().map(buckets_of).collect() };
        let mut starts = vec![0u32; buckets + 1];
        let mut total = 0usize;
        for block in points.chunks(BLOCK) {
            for (b, n) in block_ids(block) {
                for &b in &b[..n] {
                    starts[b as usize] += 1;
                }
                total += n;
            }
        }
        let mut end = 0;
        for s in starts.iter_mut() {
            end += *s;
            *s = end;
        }
        let mut entries = vec![0u32; total];
        for (k0, block) in points.chunks(BLOCK).enumerate().rev() {
            for (k, (b, n)) in block_ids(block).into_iter().enumerate().rev() {
                for &b in b[..n].iter().rev() {
                    starts[b as usize] -= 1;
                    entries[starts[b as usize] as usize] = (k0 * BLOCK + k) as u32;
                }
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

    /// Rounding can make a sphere whose radius is the largest touch 3 cells along an axis (seen
    /// in the Cornell box, where many eye-pass points share one wall coordinate and radius):
    /// all its cells must be entered, or photons in some of them miss it.
    #[test]
    fn a_sphere_touching_three_cells_on_an_axis_is_found_everywhere() {
        let r = 0.8695652173913044;
        let point = |slot, position| VisiblePoint {
            slot,
            position,
            normal: DVec3::Z,
            weight: DVec3::ONE,
            radius2: r * r,
        };
        // Find a height where the rounding happens (the build computes the same expression).
        let inv_cell = 1.0 / (2.0 * r);
        let span = |y: f64| (((y + r) + r) * inv_cell).floor() - (((y - r) + r) * inv_cell).floor();
        let y = (1..20)
            .flat_map(|k| (-8i64..=8).map(move |ulps| (k, ulps)))
            .map(|(k, ulps)| f64::from_bits((k as f64 * 2.0 * r).to_bits().wrapping_add_signed(ulps)))
            .find(|&y| span(y) >= 2.0)
            .expect("a height near a cell boundary touches three cells");
        let centre = DVec3::new(10.0, y, 4.916823166961748);
        let mut points = vec![point(0, DVec3::ZERO), point(1, centre)];
        // Small points elsewhere make the table large enough that cells rarely share buckets.
        for k in 0..5000u32 {
            let mut p = point(
                2 + k,
                DVec3::new(
                    20.0 + (k % 10) as f64,
                    (k / 10 % 10) as f64,
                    (k / 100) as f64 * 0.2,
                ),
            );
            p.radius2 = 1e-4;
            points.push(p);
        }
        let grid = HashGrid::build(&points);
        for i in 0..=40 {
            for j in 0..=40 {
                let (theta, phi) = (i as f64 / 40.0 * std::f64::consts::PI, j as f64 / 40.0 * 6.3);
                let d = DVec3::new(theta.sin() * phi.cos(), theta.cos(), theta.sin() * phi.sin());
                let p = centre + d * r * 0.999;
                assert!(grid.candidates(p).contains(&1), "missed at {p}");
            }
        }
    }

    /// The grid is built a block of points at a time: points of every block, the last one
    /// partial, are each found once, and every bucket lists its points in index order.
    #[test]
    fn points_of_every_block_are_found_once_in_index_order() {
        let n = 2 * BLOCK + 7;
        let points: Vec<VisiblePoint> = (0..n as u32)
            .map(|k| VisiblePoint {
                slot: k,
                position: DVec3::new((k % 509) as f64 * 0.01, (k / 509) as f64 * 0.01, 0.0),
                normal: DVec3::Z,
                weight: DVec3::ONE,
                radius2: 0.004 * 0.004,
            })
            .collect();
        let grid = HashGrid::build(&points);
        for (k, p) in points.iter().enumerate() {
            let candidates = grid.candidates(p.position);
            assert!(candidates.windows(2).all(|w| w[0] < w[1]), "bucket out of order");
            let inside: Vec<u32> = candidates
                .iter()
                .copied()
                .filter(|&j| (points[j as usize].position - p.position).length_squared() <= p.radius2)
                .collect();
            assert_eq!(inside, [k as u32]);
        }
    }

    #[test]
    fn grid_and_kd_tree_return_each_point_in_reach_exactly_once() {
        let mut x = 0x1234_5678_9abc_def1u64;
        let mut next = || {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            (x >> 11) as f64 / (1u64 << 53) as f64
        };
        // Random radii in a volume, then points on the walls of a box with the largest radius
        // (a classic PPM eye pass: every point starts with the same radius). Many points then
        // share the same rounding, and a sphere can touch 3 cells along an axis.
        const WALL_RADIUS: f64 = 0.35;
        let mut points: Vec<VisiblePoint> = (0..3000)
            .map(|k| VisiblePoint {
                slot: k,
                position: DVec3::new(next(), next(), next()) * 10.0,
                normal: DVec3::Z,
                weight: DVec3::ONE,
                radius2: (0.05 + 0.3 * next()).powi(2),
            })
            .collect();
        for k in 0..3000u32 {
            let mut position = DVec3::new(next(), next(), next()) * 10.0;
            position[(k % 3) as usize] = if k % 2 == 0 { 0.0 } else { 10.0 };
            points.push(VisiblePoint {
                slot: 3000 + k,
                position,
                normal: DVec3::Z,
                weight: DVec3::ONE,
                radius2: WALL_RADIUS.powi(2),
            });
        }
        let grid = HashGrid::build(&points);
        let kd = KdTree::build(&points);
        for q in 0..6000 {
            let mut p = DVec3::new(next(), next(), next()) * 10.0;
            if q % 2 == 0 {
                p[q % 3] = if q % 4 == 0 { 0.0 } else { 10.0 };
            }
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
