//! A BSDF's glossy lobes at one surface point, without its diffuse one: what photon mapping's
//! visible points keep so that every photon they gather is weighted by the BSDF for its own
//! direction, as pbrt-v4's SPPM evaluates the BSDF for each photon (Pharr, Jakob & Humphreys,
//! *Physically Based Rendering*, 4th ed., §13.4 of the online edition). The diffuse lobe does
//! not depend on the photon's direction and stays folded into the point's weight. Kept in f32
//! (a deposit's flux is summed in f32 anyway): a glossy point holds it with its throughput and
//! `wo`.

use std::f64::consts::PI;

use glam::DVec3;

use crate::scene::material::reflect;

/// The glossy lobes of a BSDF, compactly.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Glossy {
    /// The modified Phong lobe of [`super::Diffuse`]: reflectance `specular`, exponent
    /// `shininess`.
    Phong {
        /// Phong reflectance ρs.
        specular: f32,
        /// Phong exponent n.
        shininess: f32,
    },
}

impl Glossy {
    /// `f(wo, wi)` of the glossy lobes about the unit shading normal `n` (on `wo`'s side);
    /// zero when `wi` is below the surface.
    pub fn eval(&self, n: DVec3, wo: DVec3, wi: DVec3) -> DVec3 {
        if n.dot(wi) <= 0.0 {
            return DVec3::ZERO;
        }
        match *self {
            Glossy::Phong { specular, shininess } => {
                DVec3::splat(phong(specular as f64, shininess as f64, n, wo, wi))
            }
        }
    }
}

/// The modified Phong lobe (Lafortune & Willems 1994): `ρs (n + 2)/(2π) cosⁿ α`, `α` the angle
/// between `wi` and the mirror direction of `wo` about `normal`; energy-normalised, so that it
/// reflects at most ρs. Not masked by the hemisphere: the caller checks `wi`'s side.
pub fn phong(specular: f64, shininess: f64, normal: DVec3, wo: DVec3, wi: DVec3) -> f64 {
    let c = reflect(-wi, normal).dot(wo).max(0.0);
    specular * (shininess + 2.0) / (2.0 * PI) * c.powf(shininess)
}
