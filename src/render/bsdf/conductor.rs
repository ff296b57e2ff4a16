//! A conductor: a metal with its complex index of refraction `η + ik` (gold, silver, copper,
//! aluminium, …), or a tinted mirror whose Fresnel reflectance is 1, smooth or rough. Rough
//! surfaces are GGX microfacets ([`super::microfacet`]) with the Torrance–Sparrow BRDF
//! `f = D(m) G2(wo, wi) F(wo·m) / (4 cos θo cos θi)`, `m` the half vector, sampled by the
//! normals visible from `wo` (Heitz 2018), as pbrt-v4's `ConductorBxDF` (Pharr, Jakob &
//! Humphreys, *Physically Based Rendering*, 4th ed., §9.6). A single-scattering model: light
//! that would bounce between microfacets is lost, so rough conductors reflect less than smooth
//! ones (tests/bsdf.rs reports how much).

use glam::{DVec2, DVec3};

use super::microfacet::{Frame, Ggx};
use super::{BsdfSample, Glossy, SpecularLobe, SpecularLobes};
use crate::scene::material::reflect;

/// A conductor's Fresnel reflectance.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Fresnel {
    /// 1 at every angle: a perfect mirror, tinted by the colour.
    One,
    /// A metal of complex index `eta + i k` per colour channel, relative to the outside.
    Metal {
        /// The real part η.
        eta: DVec3,
        /// The extinction coefficient k.
        k: DVec3,
    },
}

impl Fresnel {
    /// The reflectance for unpolarised light at the cosine `cos_i` of the incident angle.
    pub fn eval(&self, cos_i: f64) -> DVec3 {
        match *self {
            Fresnel::One => DVec3::ONE,
            Fresnel::Metal { eta, k } => DVec3::new(
                fresnel_conductor(cos_i, eta.x, k.x),
                fresnel_conductor(cos_i, eta.y, k.y),
                fresnel_conductor(cos_i, eta.z, k.z),
            ),
        }
    }
}

/// The Fresnel reflectance of a conductor of complex index `eta + i k` for unpolarised light,
/// exactly (the closed form of pbrt-v3's `FrConductor`, after Born & Wolf's *Principles of
/// Optics*, §14.4): `(Rs + Rp) / 2`.
pub fn fresnel_conductor(cos_i: f64, eta: f64, k: f64) -> f64 {
    let c = cos_i.clamp(0.0, 1.0);
    let (cos2, sin2) = (c * c, 1.0 - c * c);
    let (eta2, k2) = (eta * eta, k * k);
    let t0 = eta2 - k2 - sin2;
    let a2b2 = (t0 * t0 + 4.0 * eta2 * k2).sqrt();
    let t1 = a2b2 + cos2;
    let a = (0.5 * (a2b2 + t0)).max(0.0).sqrt();
    let t2 = 2.0 * c * a;
    let rs = (t1 - t2) / (t1 + t2);
    let t3 = cos2 * a2b2 + sin2 * sin2;
    let t4 = t2 * sin2;
    let rp = rs * (t3 - t4) / (t3 + t4);
    (0.5 * (rs + rp)).clamp(0.0, 1.0)
}

/// A conductor of colour `color` (a tint on the Fresnel reflectance) and GGX roughness `alpha`
/// (0: smooth, a delta lobe) about the unit normal `n`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Conductor {
    /// The tint of what it reflects.
    pub color: DVec3,
    /// The Fresnel reflectance.
    pub fresnel: Fresnel,
    /// The GGX roughness α; 0 is smooth.
    pub alpha: f64,
    /// Unit shading normal on `wo`'s side.
    pub n: DVec3,
}

impl Conductor {
    /// Whether it is smooth: one delta lobe, no smooth part.
    pub fn is_smooth(&self) -> bool {
        self.alpha <= 0.0
    }

    /// The smooth surface's lobe (none when rough).
    pub fn lobes(&self, wo: DVec3) -> SpecularLobes {
        if !self.is_smooth() {
            return SpecularLobes::NONE;
        }
        SpecularLobes::one(SpecularLobe {
            wi: reflect(-wo, self.n),
            tint: self.color * self.fresnel.eval(self.n.dot(wo)),
            share: 1.0,
        })
    }

    /// `f(wo, wi)` of the rough surface (zero when smooth or either direction is below it).
    pub fn eval(&self, wo: DVec3, wi: DVec3) -> DVec3 {
        microfacet_reflection(self.alpha, self.n, wo, wi).map_or(DVec3::ZERO, |(m, f)| {
            self.color * self.fresnel.eval(wo.dot(m)) * f
        })
    }

    /// The rough surface's lobe, compactly (its tint is the colour); `None` when smooth.
    pub fn glossy(&self) -> Option<Glossy> {
        (!self.is_smooth()).then_some(Glossy::Conductor {
            alpha: self.alpha as f32,
            metal: match self.fresnel {
                Fresnel::One => None,
                Fresnel::Metal { eta, k } => Some((eta.as_vec3(), k.as_vec3())),
            },
        })
    }

    /// The density with which [`Conductor::sample`] picks `wi`.
    pub fn pdf(&self, wo: DVec3, wi: DVec3) -> f64 {
        microfacet_pdf(self.alpha, self.n, wo, wi)
    }

    /// A direction by the normals visible from `wo` (two numbers from `u`).
    pub fn sample(&self, wo: DVec3, u: DVec2) -> Option<BsdfSample> {
        let (wi, m, weight) = microfacet_sample(self.alpha, self.n, wo, u)?;
        Some(BsdfSample {
            wi,
            weight: self.color * self.fresnel.eval(wo.dot(m)) * weight,
            pdf: self.pdf(wo, wi),
        })
    }
}

/// The Torrance–Sparrow reflection without its Fresnel factor, `D G2 / (4 cos θo cos θi)`, and
/// the half vector (world), where both directions are above the surface and it is rough.
pub fn microfacet_reflection(alpha: f64, n: DVec3, wo: DVec3, wi: DVec3) -> Option<(DVec3, f64)> {
    let (co, ci) = (n.dot(wo), n.dot(wi));
    if alpha <= 0.0 || co <= 0.0 || ci <= 0.0 {
        return None;
    }
    let m = (wo + wi).try_normalize()?;
    let frame = Frame::new(n);
    let ggx = Ggx { alpha };
    let (lo, li, lm) = (frame.local(wo), frame.local(wi), frame.local(m));
    Some((m, ggx.d(lm) * ggx.g2(lo, li) / (4.0 * co * ci)))
}

/// The density of a reflection sampled by the visible normals: `D_wo(m) / (4 |wo·m|)`.
pub fn microfacet_pdf(alpha: f64, n: DVec3, wo: DVec3, wi: DVec3) -> f64 {
    if alpha <= 0.0 || n.dot(wo) <= 0.0 || n.dot(wi) <= 0.0 {
        return 0.0;
    }
    let Some(m) = (wo + wi).try_normalize() else {
        return 0.0;
    };
    let frame = Frame::new(n);
    Ggx { alpha }.visible_pdf(frame.local(wo), frame.local(m)) / (4.0 * wo.dot(m).abs())
}

/// A reflection by a normal visible from `wo`: the direction, the normal, and the weight
/// `f cos θi / pdf` without the Fresnel factor, which is `G2 / G1(wo)`. `None` below the
/// surface.
pub fn microfacet_sample(alpha: f64, n: DVec3, wo: DVec3, u: DVec2) -> Option<(DVec3, DVec3, f64)> {
    if alpha <= 0.0 || n.dot(wo) <= 0.0 {
        return None;
    }
    let frame = Frame::new(n);
    let ggx = Ggx { alpha };
    let lo = frame.local(wo);
    let lm = ggx.sample_visible(lo, u);
    let li = reflect(-lo, lm);
    if li.z <= 0.0 {
        return None;
    }
    Some((frame.world(li), frame.world(lm), ggx.g2(lo, li) / ggx.g1(lo)))
}
