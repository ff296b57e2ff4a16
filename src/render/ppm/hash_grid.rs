//! A hashed uniform grid over visible points, rebuilt every pass (Hachisuka & Jensen 2009 §4
//! hash the points into the cells their search sphere overlaps; so does pbrt-v4's
//! `SPPMIntegrator`). Here each point is entered once, in the cell of its centre, with cells
//! [`CELL_PER_RADIUS`] times the largest search radius wide: a photon looks in the cells
//! within its estimate's largest radius of it (1 or 2 per axis), and the points themselves
//! are stored sorted by bucket (counting sort), so each bucket's points lie together — what a
//! photon reads is contiguous (and a block of neighbouring cells' buckets are neighbours,
//! `HashGrid::bucket`), and the grid is only its bucket starts (at 1920×1080: 17 MiB,
//! where eight entries per point in the cells their sphere overlaps took 83 MiB and sent every
//! candidate to a random place).

use glam::{DVec3, IVec3, UVec3};
use rayon::prelude::*;

use super::points::SearchSphere;
#[cfg(test)]
use super::visible::VisiblePoint;

/// The grid: bucket `b` holds the points at places `starts[b]..starts[b + 1]` of the order
/// [`HashGrid::build`] returned.
#[derive(Clone, Debug, Default)]
pub struct HashGrid {
    origin: DVec3,
    inv_cell: f64,
    /// The largest search radius: how far from a photon the points' centres are looked for.
    reach: f64,
    mask: u64,
    starts: Vec<u32>,
}

/// Cell width over the largest search radius. A photon's bucket lookups are cache misses and
/// its candidates (read in a row) are cheap: cells of 3 radii mean about 1.7 cells per axis
/// to look in instead of 2 for cells of one diameter (4.6 lookups instead of 8) for about 1.5
/// times the candidates: with photons handed in cell order (`ppm/deposit.rs`), cells of 3
/// radii trace more photon paths per second than cells of 2 or 4 (`bench ppm`).
pub const CELL_PER_RADIUS: f64 = 3.0;

/// How far the largest radius may shrink below the one a grid was built for while the grid
/// is used again (its cells then up to this many times [`CELL_PER_RADIUS`] radii wide).
pub const KEEP_WHILE_SHRUNK: f64 = 1.5;

#[inline]
fn hash(c: IVec3) -> u64 {
    // Teschner et al. 2003 spatial hash.
    ((c.x as i64 as u64).wrapping_mul(73_856_093)
        ^ (c.y as i64 as u64).wrapping_mul(19_349_663)
        ^ (c.z as i64 as u64).wrapping_mul(83_492_791))
    .wrapping_mul(0x9e37_79b9_7f4a_7c15)
        >> 16
}

/// `x.floor() as i32` (saturating, 0 for NaN) without a call: the baseline x86-64 target has
/// no rounding instruction, and `f64::floor` is a library call there.
#[inline]
fn floor(x: f64) -> i32 {
    let t = x as i32;
    if t as f64 > x {
        t.saturating_sub(1)
    } else {
        t
    }
}

/// The 21 low bits of `v` spread to every third bit of the result.
#[inline]
fn spread(v: u32) -> u64 {
    let mut x = v as u64 & 0x1f_ffff;
    x = (x | x << 32) & 0x1f_0000_0000_ffff;
    x = (x | x << 16) & 0x1f_0000_ff00_00ff;
    x = (x | x << 8) & 0x100f_00f0_0f00_f00f;
    x = (x | x << 4) & 0x10c3_0c30_c30c_30c3;
    x = (x | x << 2) & 0x1249_2492_4924_9249;
    x
}

impl HashGrid {
    /// Builds the grid over `points` and returns with it the order the points must be stored
    /// in for it: place `i` holds point `order[i]` (within a bucket the points keep their
    /// order, so the order depends on the points only).
    pub fn build<P: SearchSphere + Sync>(points: &[P]) -> (Self, Vec<u32>) {
        if points.is_empty() {
            return (Self::default(), Vec::new());
        }
        let reach = points.iter().map(|p| p.reach2()).fold(0.0f64, f64::max).sqrt();
        let inv_cell = 1.0 / (CELL_PER_RADIUS * reach).max(1e-12);
        let origin = points
            .iter()
            .fold(DVec3::splat(f64::INFINITY), |m, p| m.min(p.centre()))
            - DVec3::splat(reach);
        // Two buckets per point: a cell holds several points, so occupied cells are far fewer
        // than buckets and rarely share one.
        let buckets = (2 * points.len()).next_power_of_two().max(2);
        let mask = buckets as u64 - 1;
        let mut grid = Self {
            origin,
            inv_cell,
            reach,
            mask,
            starts: vec![0u32; buckets + 1],
        };
        let bucket: Vec<u32> = points
            .par_iter()
            .map(|p| grid.bucket(grid.cell_of(p.centre())))
            .collect();
        // Counting sort: bucket sizes, running ends, then places filled from the back so that
        // each `starts[b]` comes down to its bucket's beginning.
        for &b in &bucket {
            grid.starts[b as usize] += 1;
        }
        let mut end = 0;
        for s in grid.starts.iter_mut() {
            end += *s;
            *s = end;
        }
        let mut order = vec![0u32; points.len()];
        for (k, &b) in bucket.iter().enumerate().rev() {
            grid.starts[b as usize] -= 1;
            order[grid.starts[b as usize] as usize] = k as u32;
        }
        (grid, order)
    }

    /// Whether this grid, built over the same points with larger or equal radii, still
    /// serves them now that their largest radius is `reach`: it reaches no farther than the
    /// radius the grid was built for, and is at least 1/[`KEEP_WHILE_SHRUNK`] of it (beyond
    /// that the grid's cells hold too many candidates for a search).
    pub fn serves(&self, reach: f64) -> bool {
        !self.starts.is_empty() && reach <= self.reach && reach * KEEP_WHILE_SHRUNK >= self.reach
    }

    #[inline]
    fn cell_of(&self, p: DVec3) -> IVec3 {
        let c = (p - self.origin) * self.inv_cell;
        IVec3::new(floor(c.x), floor(c.y), floor(c.z))
    }

    /// A key that orders places by their cell, neighbouring cells mostly near each other
    /// (Morton order of the cell's coordinates, clamped to 21 bits an axis): photons handled
    /// in this order read the same points' cells one after another.
    #[inline]
    pub fn cell_key(&self, p: DVec3) -> u64 {
        // A saturating cast truncates towards zero, the floor of a non-negative number.
        let c = ((p - self.origin) * self.inv_cell)
            .as_uvec3()
            .min(UVec3::splat((1 << 21) - 1));
        spread(c.x) | spread(c.y) << 1 | spread(c.z) << 2
    }

    /// Cell `c`'s bucket: blocks of 4×4×4 cells are hashed (Teschner et al. 2003) to runs of
    /// 64 consecutive buckets, the cells of a block in Morton order within the run. The points
    /// of neighbouring cells then lie near each other, and photons handed in Morton order of
    /// their cells ([`HashGrid::cell_key`]) read them nearly in a row, where hashing every
    /// cell on its own would scatter them.
    #[inline]
    fn bucket(&self, c: IVec3) -> u32 {
        let block = hash(c >> 2) << 6;
        let within = spread((c.x & 3) as u32) | spread((c.y & 3) as u32) << 1 | spread((c.z & 3) as u32) << 2;
        ((block | within) & self.mask) as u32
    }

    /// Calls `f` with the place of every point whose centre lies in a cell within `radius` of
    /// `p`: every point whose search sphere holds `p`, among others (the caller checks
    /// distances), each once, when `radius` is at least the radius of every sphere the caller
    /// tests (the photon's estimate's largest: a primary photon need not look as far as the
    /// wider indirect estimates reach). A sphere that holds `p` has its centre within its
    /// radius of `p`, so in a cell between those of `p` minus and plus that radius.
    #[inline]
    pub fn for_candidates(&self, p: DVec3, radius: f64, f: &mut impl FnMut(u32)) {
        if self.starts.is_empty() {
            return;
        }
        // A hair wider than asked, against rounding in the caller's distance test.
        let r = (radius * (1.0 + 1e-9)).min(self.reach);
        let (lo, hi) = (self.cell_of(p - r), self.cell_of(p + r));
        // Two of these cells may hash to one bucket: it is read once. Rounding can make the
        // range 3 cells long on an axis, so at most 27.
        let mut seen = [0u32; 27];
        let mut n = 0;
        for z in lo.z..=hi.z {
            for y in lo.y..=hi.y {
                for x in lo.x..=hi.x {
                    let b = self.bucket(IVec3::new(x, y, z));
                    if n == seen.len() || seen[..n].contains(&b) {
                        continue;
                    }
                    seen[n] = b;
                    n += 1;
                    let b = b as usize;
                    (self.starts[b]..self.starts[b + 1]).for_each(&mut *f);
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::ppm::kd_tree::KdTree;

    /// The grid over `points` and the slots (`VisiblePoint::slot`) of the candidates it gives
    /// for `p`.
    fn grid_slots(points: &[VisiblePoint]) -> impl Fn(DVec3) -> Vec<u32> + '_ {
        let (grid, order) = HashGrid::build(points);
        move |p| {
            let mut out = Vec::new();
            grid.for_candidates(p, f64::INFINITY, &mut |k| {
                out.push(points[order[k as usize] as usize].slot)
            });
            out
        }
    }

    /// A sphere whose centre lies on a cell boundary, up to rounding (seen in the Cornell box,
    /// where many eye-pass points share one wall coordinate and radius), is found by photons
    /// from all around it, whichever side of the boundary rounding puts it or them.
    #[test]
    fn a_sphere_centred_on_a_cell_boundary_is_found_everywhere() {
        let r = 0.8695652173913044;
        let point = |slot, position| VisiblePoint {
            slot,
            position,
            normal: DVec3::Z,
            weight: DVec3::ONE,
            radius2: r * r,
            glossy: None,
        };
        // A height a few ulps off a cell boundary (the origin is the lowest centre, 0, less r).
        let inv_cell = 1.0 / (CELL_PER_RADIUS * r);
        let y = (1..20)
            .flat_map(|k| (-8i64..=8).map(move |ulps| (k, ulps)))
            .map(|(k, ulps)| {
                f64::from_bits(
                    (k as f64 * CELL_PER_RADIUS * r - r)
                        .to_bits()
                        .wrapping_add_signed(ulps),
                )
            })
            .find(|&y| ((y + r) * inv_cell).fract() > 0.999_999)
            .expect("a height just below a cell boundary");
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
        let candidates = grid_slots(&points);
        for i in 0..=40 {
            for j in 0..=40 {
                let (theta, phi) = (i as f64 / 40.0 * std::f64::consts::PI, j as f64 / 40.0 * 6.3);
                let d = DVec3::new(theta.sin() * phi.cos(), theta.cos(), theta.sin() * phi.sin());
                let p = centre + d * r * 0.999;
                assert!(candidates(p).contains(&1), "missed at {p}");
            }
        }
    }

    /// The grid's order is a permutation (the points are stored in it: each bucket's points
    /// together, in their own order); every point is found once, from its own position.
    #[test]
    fn points_sorted_by_bucket_are_each_found_once() {
        let n = 100_003;
        let points: Vec<VisiblePoint> = (0..n as u32)
            .map(|k| VisiblePoint {
                slot: k,
                position: DVec3::new((k % 509) as f64 * 0.01, (k / 509) as f64 * 0.01, 0.0),
                normal: DVec3::Z,
                weight: DVec3::ONE,
                radius2: 0.004 * 0.004,
                glossy: None,
            })
            .collect();
        let (grid, order) = HashGrid::build(&points);
        let mut sorted = order.clone();
        sorted.sort_unstable();
        assert!(
            sorted.iter().copied().eq(0..n as u32),
            "the order is a permutation"
        );
        for (k, p) in points.iter().enumerate() {
            let mut inside = Vec::new();
            grid.for_candidates(p.position, p.radius2.sqrt(), &mut |place| {
                let q = &points[order[place as usize] as usize];
                if (q.position - p.position).length_squared() <= p.radius2 {
                    inside.push(q.slot);
                }
            });
            assert_eq!(inside, [k as u32]);
        }
    }

    /// A grid serves its points again while their largest radius has shrunk by less than
    /// [`KEEP_WHILE_SHRUNK`], never once any radius outgrew the one it was built for; an
    /// empty grid serves nothing.
    #[test]
    fn a_grid_serves_while_the_radii_shrink_a_little() {
        let with_radius = |r: f64| -> Vec<VisiblePoint> {
            (0..100u32)
                .map(|k| VisiblePoint {
                    slot: k,
                    position: DVec3::new(k as f64 * 0.1, 0.0, 0.0),
                    normal: DVec3::Z,
                    weight: DVec3::ONE,
                    radius2: r * r * (1.0 - k as f64 * 1e-3),
                    glossy: None,
                })
                .collect()
        };
        let reach = |points: &[VisiblePoint]| points.iter().map(|p| p.radius2).fold(0.0, f64::max).sqrt();
        let (grid, _) = HashGrid::build(&with_radius(0.3));
        let serves = |r: f64| grid.serves(reach(&with_radius(r)));
        assert!(serves(0.3));
        assert!(serves(0.3 / (KEEP_WHILE_SHRUNK * 0.99)));
        assert!(!serves(0.3 / (KEEP_WHILE_SHRUNK * 1.01)));
        assert!(!serves(0.3 * 1.000_001));
        let (empty, _) = HashGrid::build::<VisiblePoint>(&[]);
        assert!(!empty.serves(0.0));
    }

    #[test]
    fn floor_is_the_library_floor() {
        let cases = [
            0.0,
            -0.0,
            0.5,
            -0.5,
            1.0,
            -1.0,
            2.999_999,
            -2.000_001,
            1e-300,
            -1e-300,
            1e12,
            -1e12,
            f64::MAX,
            f64::MIN,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::NAN,
            i32::MAX as f64,
            i32::MIN as f64,
            i32::MIN as f64 - 0.5,
        ];
        for x in cases.into_iter().chain((-2000..2000).map(|k| k as f64 * 0.37)) {
            assert_eq!(floor(x), x.floor() as i32, "{x}");
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
                glossy: None,
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
                glossy: None,
            });
        }
        let candidates = grid_slots(&points);
        let kd = KdTree::build(&points);
        for q in 0..6000 {
            let mut p = DVec3::new(next(), next(), next()) * 10.0;
            if q % 2 == 0 {
                p[q % 3] = if q % 4 == 0 { 0.0 } else { 10.0 };
            }
            let inside =
                |k: &u32| (points[*k as usize].position - p).length_squared() <= points[*k as usize].radius2;
            let mut brute: Vec<u32> = (0..points.len() as u32).filter(inside).collect();
            let mut from_grid: Vec<u32> = candidates(p).into_iter().filter(inside).collect();
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
