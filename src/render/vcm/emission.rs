//! A light subpath's start, and the densities with which each light is met by the other
//! techniques: emission (a light subpath leaving it, [`Light::emit`]), light sampling at a
//! camera vertex ([`Light::sample`]) and a camera subpath hitting it. A light is picked
//! uniformly, the same way for emission and for light sampling, so the pick's chance cancels
//! wherever the two are compared.

use glam::DVec3;

use super::{mis, PassConstants};
use crate::geometry::Ray;
use crate::render::vcm::state::Subpath;
use crate::render::wavelength::Wavelength;
use crate::scene::light::{spot_falloff, Light};

/// The chance of each of `count` lights to be picked: every light equally likely, for
/// emission and light sampling alike.
pub fn pick_chance(count: usize) -> f64 {
    1.0 / count as f64
}

/// The light the uniform number `u` picks ([`pick_chance`]) and its chance; `None` without
/// lights.
pub fn pick_light(count: usize, u: f64) -> Option<(usize, f64)> {
    (count > 0).then(|| (((u * count as f64) as usize).min(count - 1), pick_chance(count)))
}

/// An area light's area and its unit normal at its surface point `on` (`None` for point and
/// spot lights, which have neither).
pub fn area_and_normal(light: &Light, on: DVec3) -> Option<(f64, DVec3)> {
    match *light {
        Light::Sphere { center, radius, .. } => Some((
            4.0 * std::f64::consts::PI * radius * radius,
            (on - center).normalize_or_zero(),
        )),
        Light::Quad { edge_u, edge_v, .. } => {
            let n = edge_u.cross(edge_v);
            Some((n.length(), n.normalize_or_zero()))
        }
        Light::Point { .. } | Light::Spot { .. } => None,
    }
}

/// The density with which `light` emits from its point `on` in direction `dir`: per area and
/// solid angle for an area light (uniform over its surface, cosine-weighted about its
/// normal), per solid angle for a point or spot light (uniform over the sphere, or over the
/// cone a point light outside the scene aims at `target`, or over a spot's outer cone).
pub fn emission_pdf(light: &Light, on: DVec3, dir: DVec3, target: Option<(DVec3, f64)>) -> f64 {
    use std::f64::consts::PI;
    let cone = |axis: DVec3, cos_max: f64| {
        if dir.dot(axis) >= cos_max {
            1.0 / (2.0 * PI * (1.0 - cos_max))
        } else {
            0.0
        }
    };
    match *light {
        Light::Point { position, .. } => match target.filter(|t| light.aims_at(*t)) {
            Some((center, radius)) => {
                let to = center - position;
                let d2 = to.length_squared();
                cone(to / d2.sqrt(), (1.0 - radius * radius / d2).sqrt())
            }
            None => 1.0 / (4.0 * PI),
        },
        Light::Spot {
            direction, cos_outer, ..
        } => cone(direction, cos_outer),
        Light::Sphere { .. } | Light::Quad { .. } => {
            let (area, n) = area_and_normal(light, on).expect("an area light");
            n.dot(dir).max(0.0) / (PI * area)
        }
    }
}

/// The density, per area of the light at `on`, with which light sampling from `from` picks
/// `on` ([`Light::sample`], whose density is per solid angle at `from`); 1 for a point or
/// spot light, which it picks for certain.
pub fn direct_pdf_area(light: &Light, on: DVec3, from: DVec3) -> f64 {
    match area_and_normal(light, on) {
        Some((_, n)) => {
            let d = from - on;
            let d2 = d.length_squared();
            light.pdf(from, on) * n.dot(d).abs() / (d2 * d2.sqrt())
        }
        None => 1.0,
    }
}

/// A light subpath as it leaves its light.
#[derive(Clone, Copy, Debug)]
pub struct Emitted {
    /// Its first ray (off the light's surface for an area light).
    pub ray: Ray,
    /// Its first vertex, on the light.
    pub origin: DVec3,
    /// Its state; `d_vcm` still lacks light sampling's density of the origin, which depends
    /// on the vertex the ray reaches ([`direct_pdf_area`]).
    pub subpath: Subpath,
}

/// Light `light` (picked with chance `pick`) emits a subpath from the four numbers `u`.
/// `None` when the direction carries nothing (a spot's dark edge).
pub fn emit(
    light: &Light,
    pick: f64,
    u: [f64; 4],
    target: Option<(DVec3, f64)>,
    k: &PassConstants,
) -> Option<Emitted> {
    let e = light.emit(u, target);
    let pdf = emission_pdf(light, e.origin, e.dir, target);
    if pdf <= 0.0 {
        return None;
    }
    let (throughput, d_vc) = match *light {
        Light::Point { intensity, .. } => (intensity / (pdf * pick), 0.0),
        Light::Spot {
            direction,
            intensity,
            cos_inner,
            cos_outer,
            ..
        } => {
            let falloff = spot_falloff(e.dir.dot(direction), cos_inner, cos_outer);
            (intensity * falloff / (pdf * pick), 0.0)
        }
        Light::Sphere { radiance, .. } | Light::Quad { radiance, .. } => {
            let (_, n) = area_and_normal(light, e.origin).expect("an area light");
            let cos = n.dot(e.dir).max(0.0);
            (radiance * cos / (pdf * pick), mis(cos / pdf))
        }
    };
    if throughput == DVec3::ZERO {
        return None;
    }
    Some(Emitted {
        ray: e.ray(),
        origin: e.origin,
        subpath: Subpath {
            throughput,
            length: 0,
            d_vcm: mis(1.0 / pdf),
            d_vc,
            d_vm: d_vc * k.mis_vc,
            wavelength: Wavelength::WHITE,
        },
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::rng::stream_rng;
    use rand::Rng;

    /// The mean of `throughput · pick` over many emissions is the light's power: the
    /// densities are those the directions were drawn with.
    #[test]
    fn emitted_flux_averages_to_the_lights_power() {
        let k = PassConstants::new(super::super::Techniques::ALL, 0.1, 0.75, 0, 1, 10);
        let lights = [
            Light::point(DVec3::ZERO, DVec3::new(3.0, 2.0, 1.0)),
            Light::spot(DVec3::ZERO, DVec3::Y, DVec3::splat(5.0), 60.0, 20.0),
            Light::sphere(DVec3::ONE, 0.5, DVec3::splat(7.0)),
            Light::quad(DVec3::ZERO, DVec3::X, DVec3::Z * 2.0, DVec3::splat(2.0)),
        ];
        let mut rng = stream_rng(1, 99, 0);
        for light in lights {
            let n = 200_000;
            let mut sum = DVec3::ZERO;
            for _ in 0..n {
                let u = [rng.random(), rng.random(), rng.random(), rng.random()];
                if let Some(e) = emit(&light, 0.5, u, None, &k) {
                    sum += e.subpath.throughput * 0.5;
                }
            }
            let mean = sum / n as f64;
            let power = light.power();
            assert!(
                ((mean - power).abs() / power).max_element() < 0.01,
                "{light:?}: {mean} against {power}"
            );
        }
    }

    #[test]
    fn light_sampling_density_per_area_is_one_over_the_area_for_a_quad() {
        let light = Light::quad(DVec3::ZERO, DVec3::X * 2.0, DVec3::Z, DVec3::ONE);
        let on = DVec3::new(0.5, 0.0, 0.5);
        let from = DVec3::new(0.3, -2.0, 0.1);
        assert!((direct_pdf_area(&light, on, from) - 0.5).abs() < 1e-12);
    }
}
