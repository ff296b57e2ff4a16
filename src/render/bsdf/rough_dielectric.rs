//! A rough dielectric interface (frosted glass): GGX microfacets ([`super::microfacet`]) that
//! reflect and refract, after Walter, Marschner, Li & Torrance 2007, "Microfacet models for
//! refraction through rough surfaces" (eqs. 20–21 for the BSDF, the generalised half vector
//! of §3.1, Jacobians eqs. 14 and 17), sampled by the normals visible from `wo` (Heitz 2018)
//! and choosing reflection or refraction by the microfacet's Fresnel reflectance, as
//! pbrt-v4's `DielectricBxDF` (Pharr, Jakob & Humphreys, *Physically Based Rendering*, 4th
//! ed., §9.7). As for smooth glass ([`super::Dielectric`]), `f` transports flux (radiance is
//! scaled by [`super::Bsdf::radiance_scale`] beside it), and the colour tints what is
//! refracted.

use glam::{DVec2, DVec3};

use super::microfacet::{Frame, Ggx};
use super::{BsdfSample, Glossy};
use crate::scene::material::{fresnel_dielectric, reflect, refract};

/// A rough interface of relative index `eta` (the far side's over `wo`'s side) and GGX
/// roughness `alpha` (> 0), about the unit normal `n` on `wo`'s side.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RoughDielectric {
    /// The tint of what it refracts.
    pub color: DVec3,
    /// The far side's index over `wo`'s side's.
    pub eta: f64,
    /// The GGX roughness α.
    pub alpha: f64,
    /// Unit shading normal on `wo`'s side.
    pub n: DVec3,
}

/// What a pair of directions means at a rough interface: the microfacet normal (local, facing
/// `wo`'s side) and whether light is reflected.
struct Pair {
    wo: DVec3,
    wi: DVec3,
    m: DVec3,
    reflected: bool,
}

impl RoughDielectric {
    /// The GGX distribution.
    fn ggx(&self) -> Ggx {
        Ggx { alpha: self.alpha }
    }

    /// The local directions and their microfacet normal; `None` when no microfacet joins them
    /// (`wo` below the surface, or the normal would face away from either direction).
    fn pair(&self, wo: DVec3, wi: DVec3) -> Option<(Frame, Pair)> {
        let frame = Frame::new(self.n);
        let (wo, wi) = (frame.local(wo), frame.local(wi));
        if wo.z <= 0.0 || wi.z == 0.0 {
            return None;
        }
        let reflected = wi.z > 0.0;
        let m = if reflected { wo + wi } else { wo + wi * self.eta };
        let m = m.try_normalize()?;
        let m = if m.z < 0.0 { -m } else { m };
        // Back-facing microfacets reflect and refract nothing.
        if m.dot(wo) <= 0.0 || m.dot(wi) * wi.z <= 0.0 {
            return None;
        }
        Some((frame, Pair { wo, wi, m, reflected }))
    }

    /// The Fresnel reflectance at a microfacet of normal `m` seen from `wo`.
    fn fresnel(&self, wo: DVec3, m: DVec3) -> f64 {
        fresnel_dielectric(wo.dot(m), 1.0 / self.eta)
    }

    /// `f(wo, wi)`: reflection when `wi` is on `wo`'s side, refraction when below.
    pub fn eval(&self, wo: DVec3, wi: DVec3) -> DVec3 {
        let Some((_, p)) = self.pair(wo, wi) else {
            return DVec3::ZERO;
        };
        self.f(&p)
    }

    /// `f` of a joined pair.
    fn f(&self, p: &Pair) -> DVec3 {
        let ggx = self.ggx();
        let (d, g, fr) = (ggx.d(p.m), ggx.g2(p.wo, p.wi), self.fresnel(p.wo, p.m));
        let (co, ci) = (p.wo.z, p.wi.z.abs());
        if p.reflected {
            return DVec3::splat(d * g * fr / (4.0 * co * ci));
        }
        let (im, om) = (p.wi.dot(p.m), p.wo.dot(p.m));
        let denom = (im + om / self.eta).powi(2) * co * ci;
        self.color * (d * (1.0 - fr) * g * (im * om / denom).abs())
    }

    /// Its lobes, compactly (the tint is inside: it applies to refraction alone).
    pub fn glossy(&self) -> Glossy {
        Glossy::Dielectric {
            alpha: self.alpha as f32,
            eta: self.eta as f32,
            tint: self.color.as_vec3(),
        }
    }

    /// The density with which [`RoughDielectric::sample`] picks `wi`.
    pub fn pdf(&self, wo: DVec3, wi: DVec3) -> f64 {
        match self.pair(wo, wi) {
            Some((_, p)) => self.pdf_of(&p),
            None => 0.0,
        }
    }

    /// The density of a joined pair.
    fn pdf_of(&self, p: &Pair) -> f64 {
        let visible = self.ggx().visible_pdf(p.wo, p.m);
        let fr = self.fresnel(p.wo, p.m);
        if p.reflected {
            visible / (4.0 * p.wo.dot(p.m)) * fr
        } else {
            let (im, om) = (p.wi.dot(p.m), p.wo.dot(p.m));
            visible * im.abs() / (im + om / self.eta).powi(2) * (1.0 - fr)
        }
    }

    /// A direction: a microfacet normal visible from `wo` (two numbers of `u`), then
    /// reflection with its Fresnel reflectance or refraction (`choice`). `None` below the
    /// surface, or when the refraction is totally reflected.
    pub fn sample(&self, wo: DVec3, u: DVec2, choice: f64) -> Option<BsdfSample> {
        let frame = Frame::new(self.n);
        let lo = frame.local(wo);
        if lo.z <= 0.0 {
            return None;
        }
        let m = self.ggx().sample_visible(lo, u);
        let fr = self.fresnel(lo, m);
        let li = if choice < fr {
            let li = reflect(-lo, m);
            (li.z > 0.0).then_some(li)?
        } else {
            let li = refract(-lo, m, 1.0 / self.eta)?;
            (li.z < 0.0).then_some(li)?
        };
        let wi = frame.world(li);
        let (_, p) = self.pair(wo, wi)?;
        let pdf = self.pdf_of(&p);
        if pdf <= 0.0 {
            return None;
        }
        Some(BsdfSample {
            wi,
            weight: self.f(&p) * (li.z.abs() / pdf),
            pdf,
        })
    }
}
