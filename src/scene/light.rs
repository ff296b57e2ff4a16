//! Lights: point, spot, and area lights (spheres and one-sided quads) specified by their total
//! emitted power, with the sampling the ray tracer needs for shadows. Conventions follow
//! pbrt-v4: a point light of power Φ has intensity `I = Φ/4π`; a diffuse area light of area
//! `A` has radiance `L = Φ/(πA)` (one-sided).

use glam::{DVec2, DVec3};

/// A light source.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Light {
    /// Isotropic point light.
    Point {
        /// Where.
        position: DVec3,
        /// Radiant intensity (per steradian), RGB.
        intensity: DVec3,
    },
    /// A point light emitting into a cone, with a smooth edge.
    Spot {
        /// Where.
        position: DVec3,
        /// Unit axis of the cone.
        direction: DVec3,
        /// Intensity on the axis, RGB.
        intensity: DVec3,
        /// Cosine of the half-angle where the falloff starts.
        cos_inner: f64,
        /// Cosine of the half-angle where the light ends.
        cos_outer: f64,
    },
    /// A diffusely emitting sphere.
    Sphere {
        /// Centre.
        center: DVec3,
        /// Radius.
        radius: f64,
        /// Emitted radiance, RGB.
        radiance: DVec3,
    },
    /// A diffusely emitting parallelogram, emitting on the side of `edge_u × edge_v`.
    Quad {
        /// A corner.
        corner: DVec3,
        /// First edge.
        edge_u: DVec3,
        /// Second edge.
        edge_v: DVec3,
        /// Emitted radiance, RGB.
        radiance: DVec3,
    },
}

/// Light arriving at a shading point from one light sample.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LightSample {
    /// Unit direction from the shading point towards the light.
    pub wi: DVec3,
    /// Distance to the sampled point on the light.
    pub distance: f64,
    /// Irradiance factor: the contribution is `f · incident · cos θ_i`. For point lights
    /// `I/r²`; for area lights radiance × geometry term ÷ pdf.
    pub incident: DVec3,
}

impl Light {
    /// A point light of total power `power` (W, per channel): intensity `Φ/4π`.
    pub fn point(position: DVec3, power: DVec3) -> Light {
        Light::Point {
            position,
            intensity: power / (4.0 * std::f64::consts::PI),
        }
    }

    /// A spot light of total power `power` into a cone of full angle `cone_degrees`, fading
    /// over its outer `falloff_degrees` (clamped to the cone): the intensity is the power over
    /// the cone's solid angle, counting the fade at its mean.
    pub fn spot(
        position: DVec3,
        direction: DVec3,
        power: DVec3,
        cone_degrees: f64,
        falloff_degrees: f64,
    ) -> Light {
        let falloff = falloff_degrees.clamp(0.0, cone_degrees);
        let cos_outer = (0.5 * cone_degrees).to_radians().cos();
        let cos_inner = (0.5 * (cone_degrees - falloff)).to_radians().cos();
        let solid = 2.0 * std::f64::consts::PI * (1.0 - 0.5 * (cos_inner + cos_outer));
        Light::Spot {
            position,
            direction: direction.normalize(),
            intensity: power / solid,
            cos_inner,
            cos_outer,
        }
    }

    /// A diffusely emitting sphere of total power `power`: radiance `Φ/(π · 4πr²)`.
    pub fn sphere(center: DVec3, radius: f64, power: DVec3) -> Light {
        use std::f64::consts::PI;
        Light::Sphere {
            center,
            radius,
            radiance: power / (4.0 * PI * PI * radius * radius),
        }
    }

    /// A one-sided diffuse quad of total power `power`, emitting on the side of
    /// `edge_u × edge_v`: radiance `Φ/(πA)`.
    pub fn quad(corner: DVec3, edge_u: DVec3, edge_v: DVec3, power: DVec3) -> Light {
        let area = edge_u.cross(edge_v).length();
        Light::Quad {
            corner,
            edge_u,
            edge_v,
            radiance: power / (std::f64::consts::PI * area),
        }
    }

    /// The same light moved by `delta` (turned and sized as it was).
    pub fn translated(&self, delta: DVec3) -> Light {
        let mut light = *self;
        match &mut light {
            Light::Point { position, .. } | Light::Spot { position, .. } => *position += delta,
            Light::Sphere { center, .. } => *center += delta,
            Light::Quad { corner, .. } => *corner += delta,
        }
        light
    }

    /// A spot light turned to shine along `direction` (normalised; a zero or non-finite
    /// direction, or another kind of light, leaves it as it is).
    pub fn aimed(&self, direction: DVec3) -> Light {
        let mut light = *self;
        if let (Light::Spot { direction: d, .. }, Some(n)) = (&mut light, direction.try_normalize()) {
            *d = n;
        }
        light
    }

    /// Whether `new` may take this light's place in a scene: the same kind of light (an area
    /// light's surface keeps its shape), every number finite.
    pub fn can_become(&self, new: &Light) -> bool {
        std::mem::discriminant(self) == std::mem::discriminant(new) && new.is_finite()
    }

    /// Whether every number of the light is finite.
    pub fn is_finite(&self) -> bool {
        match *self {
            Light::Point { position, intensity } => position.is_finite() && intensity.is_finite(),
            Light::Spot {
                position,
                direction,
                intensity,
                ..
            } => position.is_finite() && direction.is_finite() && intensity.is_finite(),
            Light::Sphere {
                center,
                radius,
                radiance,
            } => center.is_finite() && radius.is_finite() && radiance.is_finite(),
            Light::Quad {
                corner,
                edge_u,
                edge_v,
                radiance,
            } => corner.is_finite() && edge_u.is_finite() && edge_v.is_finite() && radiance.is_finite(),
        }
    }

    /// Total emitted power, RGB.
    pub fn power(&self) -> DVec3 {
        use std::f64::consts::PI;
        match self {
            Light::Point { intensity, .. } => 4.0 * PI * *intensity,
            Light::Spot {
                intensity,
                cos_inner,
                cos_outer,
                ..
            } => *intensity * 2.0 * PI * (1.0 - 0.5 * (cos_inner + cos_outer)),
            Light::Sphere { radius, radiance, .. } => *radiance * PI * 4.0 * PI * radius * radius,
            Light::Quad {
                edge_u,
                edge_v,
                radiance,
                ..
            } => *radiance * PI * edge_u.cross(*edge_v).length(),
        }
    }

    /// The bounds of the light's visible surface (area lights; `None` for point and spot
    /// lights, which no ray can meet).
    pub fn surface_bounds(&self) -> Option<crate::geometry::Aabb> {
        match *self {
            Light::Point { .. } | Light::Spot { .. } => None,
            Light::Sphere { center, radius, .. } => Some(crate::geometry::Sphere { center, radius }.bounds()),
            Light::Quad {
                corner,
                edge_u,
                edge_v,
                ..
            } => Some(
                crate::geometry::Quad {
                    corner,
                    edge_u,
                    edge_v,
                }
                .bounds(),
            ),
        }
    }

    /// Whether many shadow samples are needed (area lights) or one is exact (point lights).
    pub fn is_area(&self) -> bool {
        matches!(self, Light::Sphere { .. } | Light::Quad { .. })
    }

    /// Samples light arriving at `point` with the uniform numbers `u` (ignored for point
    /// lights). `None` when this sample carries no light (outside a spot's cone, behind a quad).
    pub fn sample(&self, point: DVec3, u: DVec2) -> Option<LightSample> {
        match self {
            Light::Point { position, intensity } => {
                let d = *position - point;
                let r2 = d.length_squared();
                let distance = r2.sqrt();
                Some(LightSample {
                    wi: d / distance,
                    distance,
                    incident: *intensity / r2,
                })
            }
            Light::Spot {
                position,
                direction,
                intensity,
                cos_inner,
                cos_outer,
            } => {
                let d = *position - point;
                let r2 = d.length_squared();
                let distance = r2.sqrt();
                let wi = d / distance;
                let falloff = spot_falloff(-wi.dot(*direction), *cos_inner, *cos_outer);
                (falloff > 0.0).then(|| LightSample {
                    wi,
                    distance,
                    incident: *intensity * falloff / r2,
                })
            }
            Light::Quad {
                corner,
                edge_u,
                edge_v,
                radiance,
            } => sample_quad((*corner, *edge_u, *edge_v), *radiance, point, u),
            Light::Sphere {
                center,
                radius,
                radiance,
            } => sample_sphere((*center, *radius), *radiance, point, u),
        }
    }

    /// The solid-angle density with which [`Light::sample`] picks the direction from `from`
    /// to the point `on` of this light's surface (0 for point and spot lights, which it
    /// samples exactly): what multiple importance sampling weighs a BSDF sample that hit the
    /// light against.
    pub fn pdf(&self, from: DVec3, on: DVec3) -> f64 {
        match self {
            Light::Quad { edge_u, edge_v, .. } => {
                let n = edge_u.cross(*edge_v);
                let area = n.length();
                let d = on - from;
                let cos = (d.normalize().dot(n / area)).abs();
                if cos <= 0.0 {
                    0.0
                } else {
                    d.length_squared() / (area * cos)
                }
            }
            Light::Sphere { center, radius, .. } => {
                let dc2 = (*center - from).length_squared();
                if dc2 <= radius * radius {
                    return 0.0;
                }
                let cos_max = (1.0 - radius * radius / dc2).max(0.0).sqrt();
                1.0 / (std::f64::consts::TAU * (1.0 - cos_max))
            }
            Light::Point { .. } | Light::Spot { .. } => 0.0,
        }
    }
}

/// A uniform sample of the quad `(corner, edge_u, edge_v)` of radiance `radiance` seen from
/// `point` (by area: `incident` is `L cos θ_l A / r²`); `None` from behind it.
fn sample_quad(
    (corner, edge_u, edge_v): (DVec3, DVec3, DVec3),
    radiance: DVec3,
    point: DVec3,
    u: DVec2,
) -> Option<LightSample> {
    let p = corner + u.x * edge_u + u.y * edge_v;
    let n = edge_u.cross(edge_v);
    let area = n.length();
    let d = p - point;
    let r2 = d.length_squared();
    let distance = r2.sqrt();
    let wi = d / distance;
    let cos_light = -wi.dot(n / area);
    (cos_light > 0.0).then(|| LightSample {
        wi,
        distance,
        incident: radiance * (cos_light * area / r2),
    })
}

/// A uniform sample of the cone of directions the sphere `(center, radius)` subtends from
/// `point` (pbrt-v4); `None` from inside it.
fn sample_sphere(
    (center, radius): (DVec3, f64),
    radiance: DVec3,
    point: DVec3,
    u: DVec2,
) -> Option<LightSample> {
    let to_center = center - point;
    let dc2 = to_center.length_squared();
    if dc2 <= radius * radius {
        return None;
    }
    let dc = dc2.sqrt();
    let axis = to_center / dc;
    let sin_max2 = radius * radius / dc2;
    let cos_max = (1.0 - sin_max2).max(0.0).sqrt();
    let cos_theta = 1.0 - u.x * (1.0 - cos_max);
    let sin_theta = (1.0 - cos_theta * cos_theta).max(0.0).sqrt();
    let phi = std::f64::consts::TAU * u.y;
    let (t1, t2) = axis.any_orthonormal_pair();
    let wi = cos_theta * axis + sin_theta * (phi.cos() * t1 + phi.sin() * t2);
    // Distance to the sphere along wi (nearest root).
    let b = wi.dot(to_center);
    let disc = (radius * radius - (to_center - b * wi).length_squared()).max(0.0);
    let distance = b - disc.sqrt();
    let solid_angle = std::f64::consts::TAU * (1.0 - cos_max);
    Some(LightSample {
        wi,
        distance,
        incident: radiance * solid_angle,
    })
}

impl LightSample {
    /// The shadow ray from the surface point `point` (geometric normal `normal`) towards this
    /// sample, pushed off the surface ([`crate::geometry::ray::spawn_ray`]), and how far it may
    /// go before it reaches the light: measured from its own origin, less a relative margin of
    /// 1e-7. (Measured from `point` instead, the push — at least 1e-9 — eats the margin in a
    /// scene a thousandth of a unit across, and the light shadows itself.)
    pub fn shadow_ray(&self, point: DVec3, normal: DVec3) -> (crate::geometry::Ray, f64) {
        let ray = crate::geometry::ray::spawn_ray(point, normal, self.wi);
        let target = point + self.wi * self.distance;
        let reach = (target - ray.origin).dot(self.wi);
        (ray, reach * (1.0 - 1e-7))
    }
}

/// A photon leaving a light: where, which way, and its flux relative to the light's power.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Emission {
    /// Origin on the light.
    pub origin: DVec3,
    /// Unit direction.
    pub dir: DVec3,
    /// Flux carried, as a multiple of the light's power divided by the photons emitted from it
    /// (1 for uniform emission; a spot's falloff, or aiming at the scene, changes it).
    pub weight: f64,
    /// The light's surface normal at `origin` (area lights): the photon's ray must leave that
    /// surface, or it meets the light itself at once and is lost.
    pub surface_normal: Option<DVec3>,
}

impl Emission {
    /// The photon's first ray, pushed off the light's own surface for area lights.
    pub fn ray(&self) -> crate::geometry::Ray {
        match self.surface_normal {
            Some(n) => crate::geometry::ray::spawn_ray(self.origin, n, self.dir),
            None => crate::geometry::Ray::new(self.origin, self.dir),
        }
    }
}

/// A uniformly distributed unit vector.
pub fn uniform_sphere(u: DVec2) -> DVec3 {
    let z = 1.0 - 2.0 * u.x;
    let r = (1.0 - z * z).max(0.0).sqrt();
    let phi = std::f64::consts::TAU * u.y;
    DVec3::new(r * phi.cos(), r * phi.sin(), z)
}

/// A cosine-distributed unit vector around `n` (Malley's method).
pub fn cosine_hemisphere(n: DVec3, u: DVec2) -> DVec3 {
    let r = u.x.sqrt();
    let phi = std::f64::consts::TAU * u.y;
    let (t, b) = n.any_orthonormal_pair();
    (r * phi.cos() * t + r * phi.sin() * b + (1.0 - u.x).max(0.0).sqrt() * n).normalize()
}

/// A unit vector uniform in the cone of half-angle `acos(cos_max)` around `axis`.
pub fn uniform_cone(axis: DVec3, cos_max: f64, u: DVec2) -> DVec3 {
    let cos_theta = 1.0 - u.x * (1.0 - cos_max);
    let sin_theta = (1.0 - cos_theta * cos_theta).max(0.0).sqrt();
    let phi = std::f64::consts::TAU * u.y;
    let (t, b) = axis.any_orthonormal_pair();
    cos_theta * axis + sin_theta * (phi.cos() * t + phi.sin() * b)
}

impl Light {
    /// Whether [`Light::emit`] aims this light's photons at the bounding sphere `target`
    /// (a point light clearly outside it) instead of emitting them in every direction.
    pub fn aims_at(&self, (center, radius): (DVec3, f64)) -> bool {
        matches!(self, Light::Point { position, .. }
            if (center - *position).length_squared() > radius * radius * 1.0001)
    }

    /// Which pair of [`Light::emit`]'s four numbers chooses the photon's direction (0: the
    /// first two; a sphere light picks its direction first, a quad light its point first):
    /// the pair photon mapping guides and stratifies.
    pub fn direction_pair(&self) -> usize {
        match self {
            Light::Point { .. } | Light::Spot { .. } | Light::Sphere { .. } => 0,
            Light::Quad { .. } => 1,
        }
    }

    /// Samples a photon leaving the light from four uniform numbers. `target`, the bounding
    /// sphere `(centre, radius)` of the scene, lets a point light outside it aim its photons at
    /// the scene instead of wasting them (the weight then carries the cone's share of 4π).
    pub fn emit(&self, u: [f64; 4], target: Option<(DVec3, f64)>) -> Emission {
        use std::f64::consts::PI;
        let (u1, u2) = (DVec2::new(u[0], u[1]), DVec2::new(u[2], u[3]));
        match self {
            Light::Point { position, .. } => {
                if let Some((center, radius)) = target.filter(|t| self.aims_at(*t)) {
                    let to = center - *position;
                    let d2 = to.length_squared();
                    let cos_max = (1.0 - radius * radius / d2).sqrt();
                    let dir = uniform_cone(to / d2.sqrt(), cos_max, u1);
                    let weight = 2.0 * PI * (1.0 - cos_max) / (4.0 * PI);
                    return Emission {
                        origin: *position,
                        dir,
                        weight,
                        surface_normal: None,
                    };
                }
                Emission {
                    origin: *position,
                    dir: uniform_sphere(u1),
                    weight: 1.0,
                    surface_normal: None,
                }
            }
            Light::Spot {
                position,
                direction,
                cos_inner,
                cos_outer,
                ..
            } => {
                // Uniform in the outer cone; the falloff becomes the weight, normalised so
                // the mean weight is 1 (the light's power is what the cone carries).
                let dir = uniform_cone(*direction, *cos_outer, u1);
                let falloff = spot_falloff(dir.dot(*direction), *cos_inner, *cos_outer);
                let cone = 2.0 * PI * (1.0 - cos_outer);
                let effective = 2.0 * PI * (1.0 - 0.5 * (cos_inner + cos_outer));
                Emission {
                    origin: *position,
                    dir,
                    weight: falloff * cone / effective,
                    surface_normal: None,
                }
            }
            Light::Sphere { center, radius, .. } => {
                // A uniformly emitting sphere shines equally in every direction, and in each
                // direction uniformly over its silhouette disk: pick the direction, then the
                // point of the disk, and move it back onto the sphere — the same photons as a
                // uniform point with a cosine lobe, but the first pair alone chooses where
                // they go (what emission guiding learns).
                let dir = uniform_sphere(u1);
                let disk = crate::scene::camera::concentric_disk(u2);
                let (t, b) = dir.any_orthonormal_pair();
                let depth = (1.0 - disk.length_squared()).max(0.0).sqrt();
                // The point of the sphere facing `dir` whose projection is `disk`.
                let n = (disk.x * t + disk.y * b + depth * dir).normalize();
                Emission {
                    origin: *center + n * *radius,
                    dir,
                    weight: 1.0,
                    surface_normal: Some(n),
                }
            }
            Light::Quad {
                corner,
                edge_u,
                edge_v,
                ..
            } => {
                let n = edge_u.cross(*edge_v).normalize();
                Emission {
                    origin: *corner + u1.x * *edge_u + u1.y * *edge_v,
                    dir: cosine_hemisphere(n, u2),
                    weight: 1.0,
                    surface_normal: Some(n),
                }
            }
        }
    }
}

/// Smooth spot-light falloff: 1 inside the inner cone, 0 outside the outer, smoothstep between.
pub fn spot_falloff(cos_angle: f64, cos_inner: f64, cos_outer: f64) -> f64 {
    if cos_angle >= cos_inner {
        1.0
    } else if cos_angle <= cos_outer {
        0.0
    } else {
        let t = (cos_angle - cos_outer) / (cos_inner - cos_outer);
        t * t * (3.0 - 2.0 * t)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quad_light_irradiance_matches_the_analytic_disk_limit() {
        // A small quad light far away behaves like a point of intensity L·A·cos.
        let l = Light::Quad {
            corner: DVec3::new(-0.01, -0.01, 10.0),
            edge_u: DVec3::new(0.0, 0.02, 0.0),
            edge_v: DVec3::new(0.02, 0.0, 0.0),
            radiance: DVec3::ONE,
        };
        let s = l.sample(DVec3::ZERO, DVec2::splat(0.5)).expect("faces the point");
        assert!((s.incident.x - 0.0004 / 100.0).abs() < 1e-12);
        assert!((l.power().x - std::f64::consts::PI * 0.0004).abs() < 1e-15);
    }

    #[test]
    fn sphere_light_samples_land_on_the_sphere() {
        let l = Light::Sphere {
            center: DVec3::new(0.0, 0.0, 5.0),
            radius: 1.0,
            radiance: DVec3::ONE,
        };
        for k in 0..50 {
            let u = DVec2::new((k as f64 + 0.5) / 50.0, (k * 7 % 50) as f64 / 50.0);
            let s = l.sample(DVec3::ZERO, u).expect("outside");
            let p = s.wi * s.distance;
            assert!(((p - DVec3::new(0.0, 0.0, 5.0)).length() - 1.0).abs() < 1e-9);
        }
    }
}
