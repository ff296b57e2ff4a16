//! A BSDF's glossy lobes at one surface point, without its diffuse one: what photon mapping's
//! visible points keep so that every photon they gather is weighted by the BSDF for its own
//! direction, as pbrt-v4's SPPM evaluates the BSDF for each photon (Pharr, Jakob & Humphreys,
//! *Physically Based Rendering*, 4th ed., §13.4 of the online edition). The diffuse lobe does
//! not depend on the photon's direction and stays folded into the point's weight. Kept in f32
//! (a deposit's flux is summed in f32 anyway): a glossy point holds it with its throughput and
//! `wo`. Only eye paths use these lobes, so they carry radiance: a dielectric's refraction is
//! scaled by `(η_wo / η_wi)²` ([`super::Bsdf::radiance_scale`]).

use std::f64::consts::{PI, TAU};

use glam::{DVec2, DVec3, Vec3};

use super::conductor::{microfacet_pdf, microfacet_reflection, microfacet_sample};
use super::{Bsdf, BsdfSample, Fresnel, RoughDielectric};
use crate::scene::material::reflect;

/// The glossy lobes of a BSDF, compactly, without their tint.
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
    /// A rough [`super::Conductor`]'s GGX lobe.
    Conductor {
        /// The GGX roughness α (> 0).
        alpha: f32,
        /// The metal's `(η, k)`; `None`: a Fresnel reflectance of 1 (a mirror).
        metal: Option<(Vec3, Vec3)>,
    },
    /// A [`RoughDielectric`]'s GGX reflection and refraction: light arrives from both sides.
    Dielectric {
        /// The GGX roughness α (> 0).
        alpha: f32,
        /// The far side's index over `wo`'s side's.
        eta: f32,
        /// The tint of what it refracts.
        tint: Vec3,
    },
}

impl Glossy {
    /// `f(wo, wi)` of the glossy lobes about the unit shading normal `n` (on `wo`'s side),
    /// for radiance; zero when `wi` is below the surface, unless the lobes refract.
    pub fn eval(&self, n: DVec3, wo: DVec3, wi: DVec3) -> DVec3 {
        let above = n.dot(wi) > 0.0;
        match *self {
            Glossy::Phong { specular, shininess } if above => {
                DVec3::splat(phong(specular as f64, shininess as f64, n, wo, wi))
            }
            Glossy::Conductor { alpha, metal } if above => microfacet_reflection(alpha as f64, n, wo, wi)
                .map_or(DVec3::ZERO, |(m, f)| fresnel(metal).eval(wo.dot(m)) * f),
            Glossy::Dielectric { alpha, eta, tint } => {
                let b = rough_dielectric(alpha, eta, tint, n);
                b.eval(wo, wi) * Bsdf::RoughDielectric(b).radiance_scale(wo, wi)
            }
            Glossy::Phong { .. } | Glossy::Conductor { .. } => DVec3::ZERO,
        }
    }

    /// Whether light arriving from below the surface counts (a dielectric's refraction): a
    /// visible point then gathers photons from both sides.
    pub fn two_sided(&self) -> bool {
        matches!(self, Glossy::Dielectric { .. })
    }

    /// The lobes' width as a microfacet roughness α: for a Phong lobe of exponent `n`, the
    /// Beckmann α of the same width, `√(2/(n + 2))` (Walter et al. 2007, "Microfacet models
    /// for refraction through rough surfaces", §5.2).
    pub fn roughness(&self) -> f64 {
        match *self {
            Glossy::Phong { shininess, .. } => (2.0 / (shininess as f64 + 2.0)).sqrt(),
            Glossy::Conductor { alpha, .. } | Glossy::Dielectric { alpha, .. } => alpha as f64,
        }
    }

    /// A bound of what the lobes reflect (at most 1): the share of a path they take when a
    /// tracer picks between them and the diffuse lobe.
    pub fn albedo(&self) -> f64 {
        match *self {
            Glossy::Phong { specular, .. } => (specular as f64).min(1.0),
            Glossy::Conductor { .. } | Glossy::Dielectric { .. } => 1.0,
        }
    }

    /// The density with which [`Glossy::sample`] picks `wi`.
    pub fn pdf(&self, n: DVec3, wo: DVec3, wi: DVec3) -> f64 {
        let above = n.dot(wi) > 0.0;
        match *self {
            Glossy::Phong { shininess, .. } if above => phong_pdf(shininess as f64, n, wo, wi),
            Glossy::Conductor { alpha, .. } if above => microfacet_pdf(alpha as f64, n, wo, wi),
            Glossy::Dielectric { alpha, eta, tint } => rough_dielectric(alpha, eta, tint, n).pdf(wo, wi),
            Glossy::Phong { .. } | Glossy::Conductor { .. } => 0.0,
        }
    }

    /// A direction from the lobes alone, with `u` uniform in [0, 1)³ (a dielectric's third
    /// number chooses reflection or refraction): its weight is `f(wo, wi) |cos θi| / pdf` of
    /// the lobes, for radiance. `None` below the surface (for lobes that only reflect).
    pub fn sample(&self, n: DVec3, wo: DVec3, u: DVec3) -> Option<BsdfSample> {
        let (u, choice) = (DVec2::new(u.x, u.y), u.z);
        match *self {
            Glossy::Phong { shininess, .. } => {
                let wi = phong_direction(reflect(-wo, n), shininess as f64, u);
                let (cos, pdf) = (n.dot(wi), self.pdf(n, wo, wi));
                (cos > 0.0 && pdf > 0.0).then(|| BsdfSample {
                    wi,
                    weight: self.eval(n, wo, wi) * (cos / pdf),
                    pdf,
                })
            }
            Glossy::Conductor { alpha, metal } => {
                let (wi, m, weight) = microfacet_sample(alpha as f64, n, wo, u)?;
                Some(BsdfSample {
                    wi,
                    weight: fresnel(metal).eval(wo.dot(m)) * weight,
                    pdf: self.pdf(n, wo, wi),
                })
            }
            Glossy::Dielectric { alpha, eta, tint } => {
                let b = rough_dielectric(alpha, eta, tint, n);
                let mut s = b.sample(wo, u, choice)?;
                s.weight *= Bsdf::RoughDielectric(b).radiance_scale(wo, s.wi);
                Some(s)
            }
        }
    }
}

/// The rough dielectric of a compact [`Glossy::Dielectric`], about `n`.
fn rough_dielectric(alpha: f32, eta: f32, tint: Vec3, n: DVec3) -> RoughDielectric {
    RoughDielectric {
        color: tint.as_dvec3(),
        eta: eta as f64,
        alpha: alpha as f64,
        n,
    }
}

/// A compact metal's Fresnel reflectance.
fn fresnel(metal: Option<(Vec3, Vec3)>) -> Fresnel {
    match metal {
        Some((eta, k)) => Fresnel::Metal {
            eta: eta.as_dvec3(),
            k: k.as_dvec3(),
        },
        None => Fresnel::One,
    }
}

/// The density of [`phong_direction`]'s directions about the mirror direction of `wo`:
/// `(n + 1)/(2π) cosⁿ α` (Lafortune & Willems' §4).
pub fn phong_pdf(shininess: f64, normal: DVec3, wo: DVec3, wi: DVec3) -> f64 {
    let c = reflect(-wo, normal).dot(wi).max(0.0);
    (shininess + 1.0) / TAU * c.powf(shininess)
}

/// A direction about the unit `axis` with density `(n + 1)/(2π) cosⁿ α`, `α` its angle to the
/// axis, from `u` uniform in [0, 1)².
pub fn phong_direction(axis: DVec3, shininess: f64, u: DVec2) -> DVec3 {
    let cos_a = u.x.powf(1.0 / (shininess + 1.0));
    let sin_a = (1.0 - cos_a * cos_a).max(0.0).sqrt();
    let phi = TAU * u.y;
    let (t, b) = axis.any_orthonormal_pair();
    (sin_a * phi.cos() * t + sin_a * phi.sin() * b + cos_a * axis).normalize()
}

/// The modified Phong lobe (Lafortune & Willems 1994): `ρs (n + 2)/(2π) cosⁿ α`, `α` the angle
/// between `wi` and the mirror direction of `wo` about `normal`; energy-normalised, so that it
/// reflects at most ρs. Not masked by the hemisphere: the caller checks `wi`'s side.
pub fn phong(specular: f64, shininess: f64, normal: DVec3, wo: DVec3, wi: DVec3) -> f64 {
    let c = reflect(-wi, normal).dot(wo).max(0.0);
    specular * (shininess + 2.0) / (2.0 * PI) * c.powf(shininess)
}
