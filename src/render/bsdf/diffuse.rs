//! Lambertian reflection with an optional energy-normalised Phong lobe, the "modified Phong"
//! BRDF of Lafortune & Willems, "Using the modified Phong reflectance model for physically
//! based rendering" (1994):
//!
//! `f(wo, wi) = ρ/π + ρs · (n + 2)/(2π) · cosⁿ α`, with `α` the angle between `wi` and the
//! mirror direction of `wo`.
//!
//! Sampling picks the Phong lobe with probability `ρs / (ρs + max ρ)`, and then a direction
//! with density `(n + 1)/(2π) · cosⁿ α` around the mirror direction (Lafortune & Willems'
//! section 4); else a cosine-distributed direction (Malley's method). The density of a
//! direction is the mixture of the two. Without a Phong lobe a sample draws two numbers and
//! its weight is exactly ρ.

use std::f64::consts::PI;

use glam::{DVec2, DVec3};
use rand::Rng;

use super::glossy::{phong, phong_direction, phong_pdf};
use super::{BsdfSample, Glossy};
use crate::scene::light::cosine_hemisphere;
use crate::scene::material::reflect;

/// Lambertian reflectance `color` plus a Phong lobe of reflectance `specular` and exponent
/// `shininess`, about the unit normal `n`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Diffuse {
    /// Lambertian reflectance ρ.
    pub color: DVec3,
    /// Phong reflectance ρs (0: no lobe).
    pub specular: f64,
    /// Phong exponent n.
    pub shininess: f64,
    /// Unit shading normal on `wo`'s side.
    pub n: DVec3,
}

impl Diffuse {
    /// `f(wo, wi)`.
    pub fn eval(&self, wo: DVec3, wi: DVec3) -> DVec3 {
        if self.n.dot(wi) <= 0.0 {
            return DVec3::ZERO;
        }
        let mut f = self.color / PI;
        if self.specular > 0.0 {
            f += DVec3::splat(phong(self.specular, self.shininess, self.n, wo, wi));
        }
        f
    }

    /// The chance that a sample comes from the Phong lobe.
    fn lobe_share(&self) -> f64 {
        if self.specular > 0.0 {
            self.specular / (self.specular + self.color.max_element())
        } else {
            0.0
        }
    }

    /// The density with which [`Diffuse::sample`] picks `wi`.
    pub fn pdf(&self, wo: DVec3, wi: DVec3) -> f64 {
        let cos = self.n.dot(wi);
        if cos <= 0.0 {
            return 0.0;
        }
        let share = self.lobe_share();
        if share > 0.0 {
            (1.0 - share) * cos / PI + share * phong_pdf(self.shininess, self.n, wo, wi)
        } else {
            cos / PI
        }
    }

    /// A direction: from the Phong lobe (one number to choose, two to place) or
    /// cosine-distributed (two numbers).
    pub fn sample<R: Rng + ?Sized>(&self, wo: DVec3, rng: &mut R) -> Option<BsdfSample> {
        let share = self.lobe_share();
        if share <= 0.0 {
            let wi = cosine_hemisphere(self.n, DVec2::new(rng.random(), rng.random()));
            let cos = self.n.dot(wi);
            if cos <= 0.0 {
                return None;
            }
            // f · cos / pdf = (ρ/π) · cos / (cos/π).
            return Some(BsdfSample {
                wi,
                weight: self.color,
                pdf: cos / PI,
            });
        }
        let from_lobe = rng.random::<f64>() < share;
        let u = DVec2::new(rng.random(), rng.random());
        let wi = if from_lobe {
            phong_direction(reflect(-wo, self.n), self.shininess, u)
        } else {
            cosine_hemisphere(self.n, u)
        };
        let cos = self.n.dot(wi);
        let pdf = self.pdf(wo, wi);
        if cos <= 0.0 || pdf <= 0.0 {
            return None;
        }
        Some(BsdfSample {
            wi,
            weight: self.eval(wo, wi) * (cos / pdf),
            pdf,
        })
    }

    /// The Phong lobe, compactly; `None` without one.
    pub fn glossy(&self) -> Option<Glossy> {
        (self.specular > 0.0).then_some(Glossy::Phong {
            specular: self.specular as f32,
            shininess: self.shininess as f32,
        })
    }

    /// A bound of the reflectance, each channel at most 1: ρ, plus ρs with a Phong lobe.
    pub fn albedo(&self) -> DVec3 {
        if self.specular > 0.0 {
            (self.color + DVec3::splat(self.specular)).min(DVec3::ONE)
        } else {
            self.color
        }
    }
}
