//! Flat shapes: finite parallelograms (quads) and infinite planes.

use glam::{DVec2, DVec3};

use super::aabb::Aabb;
use super::ray::Ray;

/// A parallelogram `corner + a·edge_u + b·edge_v`, `a, b ∈ [0,1]`; normal `edge_u × edge_v`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Quad {
    /// One corner.
    pub corner: DVec3,
    /// First edge from `corner`.
    pub edge_u: DVec3,
    /// Second edge from `corner`.
    pub edge_v: DVec3,
}

impl Quad {
    /// Unit normal `edge_u × edge_v`.
    pub fn normal(&self) -> DVec3 {
        self.edge_u.cross(self.edge_v).normalize()
    }

    /// Bounds of the four corners.
    pub fn bounds(&self) -> Aabb {
        let c = self.corner;
        Aabb::from_points([c, c + self.edge_u, c + self.edge_v, c + self.edge_u + self.edge_v])
    }

    /// Distance in `(t_min, t_max)` and `(a, b)` where `ray` meets the quad.
    pub fn intersect(&self, ray: &Ray, t_min: f64, t_max: f64) -> Option<(f64, DVec2)> {
        // Möller–Trumbore with the parallelogram's own barycentric limits.
        let p = ray.dir.cross(self.edge_v);
        let det = self.edge_u.dot(p);
        if det == 0.0 || !det.is_finite() {
            return None;
        }
        let inv = 1.0 / det;
        let s = ray.origin - self.corner;
        let a = s.dot(p) * inv;
        if !(0.0..=1.0).contains(&a) {
            return None;
        }
        let q = s.cross(self.edge_u);
        let b = ray.dir.dot(q) * inv;
        if !(0.0..=1.0).contains(&b) {
            return None;
        }
        let t = self.edge_v.dot(q) * inv;
        (t > t_min && t < t_max).then_some((t, DVec2::new(a, b)))
    }
}

/// An infinite plane through `point` with unit `normal`. Planes are unbounded, so they live
/// outside the BVH and every ray tests them.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Plane {
    /// A point on the plane.
    pub point: DVec3,
    /// Unit normal.
    pub normal: DVec3,
}

impl Plane {
    /// Distance in `(t_min, t_max)` where `ray` meets the plane.
    pub fn intersect(&self, ray: &Ray, t_min: f64, t_max: f64) -> Option<f64> {
        let denom = self.normal.dot(ray.dir);
        if denom == 0.0 {
            return None;
        }
        let t = self.normal.dot(self.point - ray.origin) / denom;
        (t > t_min && t < t_max).then_some(t)
    }

    /// Planar `(u,v)` in scene units along two tangent axes of the plane.
    pub fn uv(&self, p: DVec3) -> DVec2 {
        let (tu, tv) = self.normal.any_orthonormal_pair();
        let d = p - self.point;
        DVec2::new(d.dot(tu), d.dot(tv))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quad_hit_and_miss() {
        let q = Quad {
            corner: DVec3::ZERO,
            edge_u: DVec3::X * 2.0,
            edge_v: DVec3::Y,
        };
        let r = Ray::new(DVec3::new(1.0, 0.5, 1.0), -DVec3::Z);
        let (t, ab) = q.intersect(&r, 0.0, f64::INFINITY).expect("hit");
        assert!((t - 1.0).abs() < 1e-15 && (ab - DVec2::new(0.5, 0.5)).length() < 1e-15);
        let miss = Ray::new(DVec3::new(2.5, 0.5, 1.0), -DVec3::Z);
        assert!(q.intersect(&miss, 0.0, f64::INFINITY).is_none());
        assert_eq!(q.normal(), DVec3::Z);
    }

    #[test]
    fn plane_parallel_ray_misses() {
        let p = Plane {
            point: DVec3::ZERO,
            normal: DVec3::Y,
        };
        assert!(p
            .intersect(&Ray::new(DVec3::Y, DVec3::X), 0.0, f64::INFINITY)
            .is_none());
        assert_eq!(
            p.intersect(&Ray::new(DVec3::Y, -DVec3::Y), 0.0, f64::INFINITY),
            Some(1.0)
        );
    }
}
