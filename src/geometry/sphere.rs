//! Spheres, intersected with the numerically careful quadratic of Haines et al., "Precision
//! Improvements for Ray/Sphere Intersection" (Ray Tracing Gems, ch. 7), which keeps
//! smallppm's walls — spheres of radius 1e5 — accurate where the textbook formula is not.

use glam::{DVec2, DVec3};

use super::aabb::Aabb;
use super::ray::Ray;

/// A sphere.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sphere {
    /// Centre.
    pub center: DVec3,
    /// Radius (positive).
    pub radius: f64,
}

impl Sphere {
    /// Bounds.
    pub fn bounds(&self) -> Aabb {
        Aabb::new(self.center - self.radius, self.center + self.radius)
    }

    /// Nearest distance in `(t_min, t_max)` at which `ray` meets the sphere.
    pub fn intersect(&self, ray: &Ray, t_min: f64, t_max: f64) -> Option<f64> {
        let f = ray.origin - self.center;
        let b = -f.dot(ray.dir);
        let c = f.length_squared() - self.radius * self.radius;
        // From outside (c > 0), a sphere behind the ray (b ≤ 0) has both roots at t ≤ 0:
        // nothing to find in (t_min, t_max) for t_min ≥ 0, without the square root and the
        // division (a photon in smallppm's room has half its walls behind it).
        if c > 0.0 && b <= 0.0 && t_min >= 0.0 {
            return None;
        }
        // r² − |f − (f·d)d|², robust for rays far from large spheres.
        let l = f + b * ray.dir;
        let disc = self.radius * self.radius - l.length_squared();
        if disc < 0.0 {
            return None;
        }
        let q = b + b.signum() * disc.sqrt();
        let (mut t0, mut t1) = if q == 0.0 { (0.0, 0.0) } else { (c / q, q) };
        if t0 > t1 {
            std::mem::swap(&mut t0, &mut t1);
        }
        [t0, t1].into_iter().find(|&t| t > t_min && t < t_max)
    }

    /// Outward unit normal at `p` on the sphere.
    pub fn normal(&self, p: DVec3) -> DVec3 {
        (p - self.center) / self.radius
    }

    /// Spherical `(u,v)`: `u = φ/2π` around the y axis, `v = θ/π` from +y.
    pub fn uv(&self, p: DVec3) -> DVec2 {
        Self::uv_of_normal(self.normal(p))
    }

    /// Spherical `(u,v)` of the point whose outward unit normal is `n` ([`Sphere::uv`]).
    pub fn uv_of_normal(n: DVec3) -> DVec2 {
        let phi = n.z.atan2(n.x);
        let u = (phi / std::f64::consts::TAU).rem_euclid(1.0);
        let v = n.y.clamp(-1.0, 1.0).acos() / std::f64::consts::PI;
        DVec2::new(u, v)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hits_from_outside_and_inside() {
        let s = Sphere {
            center: DVec3::ZERO,
            radius: 2.0,
        };
        let out = Ray::new(DVec3::new(0.0, 0.0, -5.0), DVec3::Z);
        assert_eq!(s.intersect(&out, 0.0, f64::INFINITY), Some(3.0));
        let inside = Ray::new(DVec3::ZERO, DVec3::X);
        assert_eq!(s.intersect(&inside, 0.0, f64::INFINITY), Some(2.0));
        assert_eq!(s.intersect(&out, 0.0, 2.5), None);
    }

    #[test]
    fn spheres_behind_the_ray_are_missed_and_nothing_in_front_is() {
        let s = Sphere {
            center: DVec3::new(1.0, -2.0, 0.5),
            radius: 1.5,
        };
        // From outside, looking away (or tangentially away): no hit, for any range from 0.
        let away = Ray::new(DVec3::new(1.0, -2.0, 4.0), DVec3::Z);
        assert_eq!(s.intersect(&away, 0.0, f64::INFINITY), None);
        // Random rays from inside and outside against the textbook quadratic, far from
        // tangency: the early rejection must not lose a hit in front of the ray.
        let mut rng = <rand_pcg::Pcg64Mcg as rand::SeedableRng>::seed_from_u64(3);
        let mut next = || rand::Rng::random::<f64>(&mut rng) * 2.0 - 1.0;
        let (mut hits, mut misses) = (0, 0);
        for _ in 0..20_000 {
            let origin = s.center + DVec3::new(next(), next(), next()) * 4.0;
            let dir = DVec3::new(next(), next(), next());
            if dir.length() < 1e-3 {
                continue;
            }
            let ray = Ray::new(origin, dir.normalize());
            let f = ray.origin - s.center;
            let (b, c) = (-f.dot(ray.dir), f.length_squared() - s.radius * s.radius);
            let disc = b * b - c;
            if disc.abs() < 1e-6 || c.abs() < 1e-6 {
                continue;
            }
            let textbook = (disc > 0.0)
                .then(|| [b - disc.sqrt(), b + disc.sqrt()])
                .and_then(|roots| roots.into_iter().find(|&t| t > 0.0));
            match (s.intersect(&ray, 0.0, f64::INFINITY), textbook) {
                (Some(t), Some(expected)) => {
                    assert!((t - expected).abs() < 1e-9, "{ray:?}: {t} against {expected}");
                    hits += 1;
                }
                (None, None) => misses += 1,
                (got, expected) => panic!("{ray:?}: {got:?} against {expected:?}"),
            }
        }
        assert!(hits > 1000 && misses > 3000, "{hits} hits, {misses} misses");
    }

    #[test]
    fn huge_wall_sphere_is_accurate() {
        // smallppm's left wall: radius 1e5, the room (x in (1, 99)) inside it, inner surface at x = 1.
        let wall = Sphere {
            center: DVec3::new(1e5 + 1.0, 40.8, 81.6),
            radius: 1e5,
        };
        let ray = Ray::new(DVec3::new(50.0, 40.8, 81.6), -DVec3::X);
        let t = wall.intersect(&ray, 0.0, f64::INFINITY).expect("hit");
        assert!((t - 49.0).abs() < 1e-10, "t = {t}");
        let oblique = Ray::new(DVec3::new(50.0, 40.0, 80.0), DVec3::new(-1.0, 0.3, 0.2));
        let hit = oblique.at(wall.intersect(&oblique, 0.0, f64::INFINITY).expect("hit"));
        assert!(((hit - wall.center).length() - 1e5).abs() < 1e-9);
    }
}
