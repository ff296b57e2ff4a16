//! A few spheres tested against one ray at once: their centres and radii stored coordinate by
//! coordinate (structure of arrays), four to a block, so that each step of
//! [`Sphere::intersect`]'s arithmetic runs over four spheres in two-wide `f64` SIMD (SSE2)
//! rather than one sphere at a time with a branch at each early exit. The scene holds one when
//! its BVH is not walked and holds spheres only ([`Bvh::traverse`] tests every primitive of
//! such a tree in turn): smallppm's room, nine spheres, six of them walls.
//!
//! Each lane computes exactly [`Sphere::intersect`]'s operations in its order, so every
//! distance is bit for bit the same; the nearest of them, the first in the tree's order on a
//! tie, is what testing them one by one with the distance so far as the limit finds.
//!
//! [`Bvh::traverse`]: super::bvh::Bvh::traverse

use glam::DVec3;

use super::ray::Ray;
use super::sphere::Sphere;

/// Spheres a block holds.
const LANES: usize = 4;

/// Four spheres, coordinate by coordinate. A lane holding no sphere has radius² −1 and its
/// centre at the origin, which no ray meets.
#[derive(Clone, Copy, Debug)]
struct Block {
    x: [f64; LANES],
    y: [f64; LANES],
    z: [f64; LANES],
    radius2: [f64; LANES],
}

impl Block {
    const EMPTY: Block = Block {
        x: [0.0; LANES],
        y: [0.0; LANES],
        z: [0.0; LANES],
        radius2: [-1.0; LANES],
    };

    /// Each lane's nearest hit in `(0, t_max)`, +∞ for none: [`Sphere::intersect`] with
    /// `t_min = 0`, lane by lane. Written as one loop per step, each a plain map over the four lanes with selects for
    /// branches, which the compiler turns into packed (SIMD) arithmetic.
    #[inline(always)]
    fn nearest(&self, o: DVec3, d: DVec3, t_max: f64) -> [f64; LANES] {
        let lanes = |f: &dyn Fn(usize) -> f64| -> [f64; LANES] { std::array::from_fn(f) };
        let fx = lanes(&|k| o.x - self.x[k]);
        let fy = lanes(&|k| o.y - self.y[k]);
        let fz = lanes(&|k| o.z - self.z[k]);
        let b = lanes(&|k| -(fx[k] * d.x + fy[k] * d.y + fz[k] * d.z));
        let c = lanes(&|k| (fx[k] * fx[k] + fy[k] * fy[k] + fz[k] * fz[k]) - self.radius2[k]);
        let lx = lanes(&|k| fx[k] + b[k] * d.x);
        let ly = lanes(&|k| fy[k] + b[k] * d.y);
        let lz = lanes(&|k| fz[k] + b[k] * d.z);
        let disc = lanes(&|k| self.radius2[k] - (lx[k] * lx[k] + ly[k] * ly[k] + lz[k] * lz[k]));
        let q = lanes(&|k| b[k] + 1.0f64.copysign(b[k]) * disc[k].sqrt());
        let ratio = lanes(&|k| c[k] / q[k]);
        let t0 = lanes(&|k| if q[k] == 0.0 { 0.0 } else { ratio[k] });
        let t1 = lanes(&|k| if q[k] == 0.0 { 0.0 } else { q[k] });
        let near = lanes(&|k| if t0[k] > t1[k] { t1[k] } else { t0[k] });
        let far = lanes(&|k| if t0[k] > t1[k] { t0[k] } else { t1[k] });
        let far = lanes(&|k| {
            if far[k] > 0.0 && far[k] < t_max {
                far[k]
            } else {
                f64::INFINITY
            }
        });
        let found = lanes(&|k| {
            if near[k] > 0.0 && near[k] < t_max {
                near[k]
            } else {
                far[k]
            }
        });
        // Outside and moving away, or passing beside: no hit (the two early exits).
        lanes(&|k| {
            let missed = ((c[k] > 0.0) & (b[k] <= 0.0)) | (disc[k] < 0.0);
            if missed {
                f64::INFINITY
            } else {
                found[k]
            }
        })
    }
}

/// Spheres in a fixed order, each with a tag (its primitive's index) and its object.
#[derive(Clone, Debug, Default)]
pub struct SphereBatch {
    blocks: Vec<Block>,
    tags: Vec<u32>,
    objects: Vec<u32>,
}

impl SphereBatch {
    /// The spheres `(sphere, tag, object)` in the order ties are resolved in.
    pub fn new(spheres: impl IntoIterator<Item = (Sphere, u32, u32)>) -> Self {
        let mut batch = SphereBatch::default();
        for (k, (sphere, tag, object)) in spheres.into_iter().enumerate() {
            if k % LANES == 0 {
                batch.blocks.push(Block::EMPTY);
            }
            let block = batch.blocks.last_mut().expect("a block was pushed");
            let lane = k % LANES;
            (block.x[lane], block.y[lane], block.z[lane]) =
                (sphere.center.x, sphere.center.y, sphere.center.z);
            block.radius2[lane] = sphere.radius * sphere.radius;
            batch.tags.push(tag);
            batch.objects.push(object);
        }
        batch
    }

    /// The nearest hit in `(0, t_max)`: its distance and its sphere's tag.
    pub fn nearest(&self, ray: &Ray, t_max: f64) -> Option<(f64, u32)> {
        let mut best: Option<(f64, usize)> = None;
        for (b, block) in self.blocks.iter().enumerate() {
            let t = block.nearest(ray.origin, ray.dir, t_max);
            for (lane, &t) in t.iter().enumerate() {
                if t < best.map_or(f64::INFINITY, |(bt, _)| bt) {
                    best = Some((t, b * LANES + lane));
                }
            }
        }
        best.map(|(t, k)| (t, self.tags[k]))
    }

    /// Whether a sphere of any object but `skip` lies on `ray` in `(0, t_max)`.
    pub fn any(&self, ray: &Ray, t_max: f64, skip: Option<u32>) -> bool {
        self.blocks.iter().enumerate().any(|(b, block)| {
            let t = block.nearest(ray.origin, ray.dir, t_max);
            (0..LANES).any(|lane| {
                let k = b * LANES + lane;
                t[lane] < f64::INFINITY && skip != Some(self.objects[k])
            })
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_pcg::Pcg64Mcg;

    /// Spheres of every size (walls of radius 1e5 as in smallppm's room among them), rays from
    /// inside, outside and on them: the batch finds what testing the spheres one by one finds,
    /// bit for bit, the first sphere winning a tie.
    #[test]
    fn the_batch_finds_what_the_spheres_one_by_one_find() {
        let mut rng = Pcg64Mcg::seed_from_u64(11);
        let mut spheres: Vec<Sphere> = [
            (DVec3::new(1e5 + 1.0, 40.8, 81.6), 1e5),
            (DVec3::new(-1e5 + 99.0, 40.8, 81.6), 1e5),
            (DVec3::new(50.0, 40.8, 1e5), 1e5),
            (DVec3::new(50.0, 1e5, 81.6), 1e5),
            (DVec3::new(27.0, 16.5, 47.0), 16.5),
        ]
        .map(|(center, radius)| Sphere { center, radius })
        .to_vec();
        for _ in 0..6 {
            let center = DVec3::new(rng.random(), rng.random(), rng.random()) * 100.0;
            spheres.push(Sphere {
                center,
                radius: rng.random::<f64>() * 20.0 + 0.5,
            });
        }
        // The same sphere twice: every hit ties, and the first must win.
        spheres.push(spheres[4]);
        let batch = SphereBatch::new(
            spheres
                .iter()
                .enumerate()
                .map(|(k, s)| (*s, k as u32, 100 + k as u32)),
        );
        let mut hits = 0;
        for k in 0..4000 {
            let origin = if k % 4 == 0 {
                // On a sphere, as a bounce leaves it.
                let s = spheres[k / 4 % spheres.len()];
                s.center
                    + DVec3::new(rng.random::<f64>() - 0.5, rng.random::<f64>() - 0.5, 0.3).normalize()
                        * s.radius
            } else {
                DVec3::new(rng.random(), rng.random(), rng.random()) * 120.0 - 10.0
            };
            let dir = DVec3::new(
                rng.random::<f64>() - 0.5,
                rng.random::<f64>() - 0.5,
                rng.random::<f64>() - 0.5,
            );
            let ray = Ray::new(origin, dir);
            let t_max = if k % 3 == 0 { 30.0 } else { f64::INFINITY };
            let mut one_by_one: Option<(f64, u32)> = None;
            for (i, s) in spheres.iter().enumerate() {
                if let Some(t) = s.intersect(&ray, 0.0, one_by_one.map_or(t_max, |b| b.0)) {
                    one_by_one = Some((t, i as u32));
                }
            }
            let found = batch.nearest(&ray, t_max);
            assert_eq!(
                found.map(|f| (f.0.to_bits(), f.1)),
                one_by_one.map(|f| (f.0.to_bits(), f.1)),
                "ray {k}"
            );
            hits += found.is_some() as usize;
            let any = spheres.iter().any(|s| s.intersect(&ray, 0.0, t_max).is_some());
            assert_eq!(batch.any(&ray, t_max, None), any, "ray {k}");
            // Skipping the nearest sphere's object leaves what the others hit.
            if let Some((_, i)) = found {
                let others = spheres
                    .iter()
                    .enumerate()
                    .any(|(j, s)| j != i as usize && s.intersect(&ray, 0.0, t_max).is_some());
                assert_eq!(batch.any(&ray, t_max, Some(100 + i)), others, "ray {k}");
            }
        }
        assert!(hits > 2000, "{hits} of 4000 rays hit");
    }
}
