//! The scattering seam: what a surface does to light, asked the same way by every renderer.
//!
//! A [`Bsdf`] is made at a hit from its material ([`Bsdf::at`], the one list of materials).
//! Directions are in world space and point away from the surface: `wo` towards where the
//! light goes (the eye, or back along a photon's arrival), `wi` towards where it comes from;
//! the normal is the shading normal on `wo`'s side. A BSDF has two parts, either of which may
//! be empty:
//!
//! - a **smooth** part (diffuse and glossy lobes): [`Bsdf::eval`] gives `f(wo, wi)`,
//!   [`Bsdf::pdf`] the solid-angle density with which [`Bsdf::sample`] picks `wi`; light is
//!   sampled at it, photons are stored at it, and radiance is estimated at it;
//! - a **specular** part (delta lobes: mirror reflection, smooth refraction):
//!   [`Bsdf::specular_lobes`] lists each lobe's direction, tint and share, which a tracer
//!   follows all at once (Whitted, classic photon mapping's eye pass) or one at a time, picked
//!   with its share.
//!
//! The interface follows pbrt-v4's `BxDF` (Pharr, Jakob & Humphreys, *Physically Based
//! Rendering*, 4th ed., ch. 9: `f`, `Sample_f`, `PDF`), with delta lobes returned as a list so
//! that the splitting tracers need no case of their own. A new material is its file here plus
//! one line in [`Bsdf::at`].

mod dielectric;
mod diffuse;
mod glossy;
mod mirror;

use glam::DVec3;
use rand::Rng;

pub use dielectric::Dielectric;
pub use diffuse::Diffuse;
pub use glossy::{phong, Glossy};
pub use mirror::Mirror;

use crate::scene::material::{Material, MaterialKind};
use crate::scene::{Scene, Surface};

/// A direction sampled from a BSDF's smooth part.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BsdfSample {
    /// The sampled direction, away from the surface.
    pub wi: DVec3,
    /// `f(wo, wi) · cos θi / pdf`: what the path's throughput is multiplied by.
    pub weight: DVec3,
    /// The solid-angle density of `wi` ([`Bsdf::pdf`]).
    pub pdf: f64,
}

/// One delta lobe of a BSDF at a given `wo`: light leaves along `wo` only if it arrives
/// along `wi`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpecularLobe {
    /// The one direction the lobe takes light from, away from the surface.
    pub wi: DVec3,
    /// The lobe's colour (a mirror's or a glass's tint; white for a dielectric's reflection).
    pub tint: DVec3,
    /// The lobe's share of what the specular part scatters (the Fresnel reflectance for a
    /// dielectric's reflection); the shares sum to 1. The lobe scatters `share · tint`.
    pub share: f64,
}

/// The delta lobes of a BSDF at one `wo` (at most two: reflection and refraction).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SpecularLobes {
    lobes: [Option<SpecularLobe>; 2],
}

impl SpecularLobes {
    /// No delta lobe.
    pub const NONE: Self = Self { lobes: [None, None] };

    /// One lobe.
    pub fn one(lobe: SpecularLobe) -> Self {
        Self {
            lobes: [Some(lobe), None],
        }
    }

    /// Two lobes.
    pub fn two(first: SpecularLobe, second: SpecularLobe) -> Self {
        Self {
            lobes: [Some(first), Some(second)],
        }
    }

    /// The lobes in order.
    pub fn iter(&self) -> impl Iterator<Item = &SpecularLobe> {
        self.lobes.iter().flatten()
    }

    /// How many there are.
    pub fn len(&self) -> usize {
        self.iter().count()
    }

    /// Whether there is none.
    pub fn is_empty(&self) -> bool {
        self.lobes[0].is_none()
    }

    /// One lobe picked with its share: a single lobe without a random number, else the first
    /// when `u() < its share` (one number drawn). `None` when there is no lobe.
    pub fn choose(&self, u: impl FnOnce() -> f64) -> Option<SpecularLobe> {
        match self.lobes {
            [None, _] => None,
            [Some(only), None] => Some(only),
            [Some(first), Some(second)] => Some(if u() < first.share { first } else { second }),
        }
    }
}

/// The BSDF at a surface point: one of the materials, with the hit's colour and normal.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Bsdf {
    /// Lambertian with an optional Phong lobe.
    Diffuse(Diffuse),
    /// A perfect mirror.
    Mirror(Mirror),
    /// A smooth dielectric (glass).
    Dielectric(Dielectric),
}

impl Bsdf {
    /// The BSDF of `surface` (its material, colour, side and normal): the one list of
    /// materials.
    pub fn at(surface: &Surface) -> Self {
        let (color, n) = (surface.color, surface.normal);
        match surface.material.kind {
            MaterialKind::Diffuse { specular, shininess } => Bsdf::Diffuse(Diffuse {
                color,
                specular,
                shininess,
                n,
            }),
            MaterialKind::Mirror => Bsdf::Mirror(Mirror { color, n }),
            MaterialKind::Glass { ior } => Bsdf::Dielectric(Dielectric {
                color,
                ior,
                entering: surface.front,
                n,
            }),
        }
    }

    /// Whether a surface of `material` has glossy lobes ([`Bsdf::glossy`]): whether a
    /// renderer needs room for them. Beside [`Bsdf::at`], and kept in step with it.
    pub fn has_glossy(material: &Material) -> bool {
        match material.kind {
            MaterialKind::Diffuse { specular, .. } => specular > 0.0,
            MaterialKind::Mirror | MaterialKind::Glass { .. } => false,
        }
    }

    /// Whether any of `scene`'s materials has glossy lobes.
    pub fn scene_has_glossy(scene: &Scene) -> bool {
        scene.materials.iter().any(Self::has_glossy)
    }

    /// The shading normal on `wo`'s side.
    pub fn normal(&self) -> DVec3 {
        match self {
            Bsdf::Diffuse(b) => b.n,
            Bsdf::Mirror(b) => b.n,
            Bsdf::Dielectric(b) => b.n,
        }
    }

    /// Whether the BSDF has a smooth (non-delta) part: where light is sampled, photons are
    /// stored and radiance is estimated.
    pub fn has_smooth(&self) -> bool {
        match self {
            Bsdf::Diffuse(_) => true,
            Bsdf::Mirror(_) | Bsdf::Dielectric(_) => false,
        }
    }

    /// The smooth part's Lambertian reflectance ρ (`f = ρ/π` for its diffuse lobe): what the
    /// ray tracer's ambient term lights and the part of `f` that does not depend on the
    /// directions.
    pub fn diffuse_reflectance(&self) -> DVec3 {
        match self {
            Bsdf::Diffuse(b) => b.color,
            Bsdf::Mirror(_) | Bsdf::Dielectric(_) => DVec3::ZERO,
        }
    }

    /// The smooth part's glossy lobes (all but its diffuse lobe), compactly, for a visible
    /// point to weigh each photon by: `eval(wo, wi) = diffuse_reflectance()/π + glossy.eval(n,
    /// wo, wi)`. `None` when the smooth part is diffuse only.
    pub fn glossy(&self) -> Option<Glossy> {
        match self {
            Bsdf::Diffuse(b) => b.glossy(),
            Bsdf::Mirror(_) | Bsdf::Dielectric(_) => None,
        }
    }

    /// A bound of the smooth part's reflectance (each channel at most 1): a photon's chance
    /// of going on under Russian roulette.
    pub fn albedo(&self) -> DVec3 {
        match self {
            Bsdf::Diffuse(b) => b.albedo(),
            Bsdf::Mirror(_) | Bsdf::Dielectric(_) => DVec3::ZERO,
        }
    }

    /// `f(wo, wi)` of the smooth part (zero when `wi` is below the surface).
    pub fn eval(&self, wo: DVec3, wi: DVec3) -> DVec3 {
        match self {
            Bsdf::Diffuse(b) => b.eval(wo, wi),
            Bsdf::Mirror(_) | Bsdf::Dielectric(_) => DVec3::ZERO,
        }
    }

    /// The solid-angle density with which [`Bsdf::sample`] picks `wi` at `wo`.
    pub fn pdf(&self, wo: DVec3, wi: DVec3) -> f64 {
        match self {
            Bsdf::Diffuse(b) => b.pdf(wo, wi),
            Bsdf::Mirror(_) | Bsdf::Dielectric(_) => 0.0,
        }
    }

    /// A direction from the smooth part, drawing what numbers it needs from `rng` (a
    /// Lambertian surface draws two). `None` when the part is empty or the sample falls below
    /// the surface.
    pub fn sample<R: Rng + ?Sized>(&self, wo: DVec3, rng: &mut R) -> Option<BsdfSample> {
        match self {
            Bsdf::Diffuse(b) => b.sample(wo, rng),
            Bsdf::Mirror(_) | Bsdf::Dielectric(_) => None,
        }
    }

    /// The specular part's lobes at `wo`.
    pub fn specular_lobes(&self, wo: DVec3) -> SpecularLobes {
        match self {
            Bsdf::Diffuse(_) => SpecularLobes::NONE,
            Bsdf::Mirror(b) => b.lobes(wo),
            Bsdf::Dielectric(b) => b.lobes(wo),
        }
    }
}
