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

mod conductor;
mod dielectric;
mod diffuse;
mod glossy;
pub mod microfacet;
mod mirror;
mod rough_dielectric;

use glam::{DVec2, DVec3};
use rand::Rng;

pub use conductor::{fresnel_conductor, Conductor, Fresnel};
pub use dielectric::Dielectric;
pub use diffuse::Diffuse;
pub use glossy::{phong, Glossy};
pub use mirror::Mirror;
pub use rough_dielectric::RoughDielectric;

use super::wavelength::Wavelength;
use crate::scene::glasses::Dispersion;
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
    /// A metal or a rough mirror (smooth or GGX microfacets).
    Conductor(Conductor),
    /// A smooth dielectric (glass).
    Dielectric(Dielectric),
    /// A rough dielectric (frosted glass).
    RoughDielectric(RoughDielectric),
}

impl Bsdf {
    /// The BSDF of `surface` (its material, colour, side and normal) for light of
    /// `wavelength` (which only a dispersive glass asks; white light sees its nominal index):
    /// the one list of materials.
    pub fn at(surface: &Surface, wavelength: Wavelength) -> Self {
        let (color, n) = (surface.color, surface.normal);
        let index = |ior: f64, dispersion: Dispersion| match wavelength.nm() {
            Some(nm) => dispersion.ior(ior, nm),
            None => ior,
        };
        match surface.material.kind {
            MaterialKind::Diffuse { specular, shininess } => Bsdf::Diffuse(Diffuse {
                color,
                specular,
                shininess,
                n,
            }),
            MaterialKind::Mirror { roughness } if roughness <= 0.0 => Bsdf::Mirror(Mirror { color, n }),
            MaterialKind::Mirror { roughness } => Bsdf::Conductor(Conductor {
                color,
                fresnel: Fresnel::One,
                alpha: roughness,
                n,
            }),
            MaterialKind::Metal { eta, k, roughness } => Bsdf::Conductor(Conductor {
                color,
                fresnel: Fresnel::Metal { eta, k },
                alpha: roughness,
                n,
            }),
            MaterialKind::Glass {
                ior,
                roughness,
                dispersion,
            } if roughness <= 0.0 => Bsdf::Dielectric(Dielectric {
                color,
                ior: index(ior, dispersion),
                entering: surface.front,
                n,
            }),
            MaterialKind::Glass {
                ior,
                roughness,
                dispersion,
            } => {
                let ior = index(ior, dispersion);
                Bsdf::RoughDielectric(RoughDielectric {
                    color,
                    eta: if surface.front { ior } else { 1.0 / ior },
                    alpha: roughness,
                    n,
                })
            }
        }
    }

    /// Whether a surface of `material` has glossy lobes ([`Bsdf::glossy`]): whether a
    /// renderer needs room for them. Beside [`Bsdf::at`], and kept in step with it.
    pub fn has_glossy(material: &Material) -> bool {
        match material.kind {
            MaterialKind::Diffuse { specular, .. } => specular > 0.0,
            MaterialKind::Mirror { roughness }
            | MaterialKind::Metal { roughness, .. }
            | MaterialKind::Glass { roughness, .. } => roughness > 0.0,
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
            Bsdf::Conductor(b) => b.n,
            Bsdf::Dielectric(b) => b.n,
            Bsdf::RoughDielectric(b) => b.n,
        }
    }

    /// Whether the BSDF has a smooth (non-delta) part: where light is sampled, photons are
    /// stored and radiance is estimated.
    pub fn has_smooth(&self) -> bool {
        match self {
            Bsdf::Diffuse(_) | Bsdf::RoughDielectric(_) => true,
            Bsdf::Conductor(b) => !b.is_smooth(),
            Bsdf::Mirror(_) | Bsdf::Dielectric(_) => false,
        }
    }

    /// The smooth part's Lambertian reflectance ρ (`f = ρ/π` for its diffuse lobe): what the
    /// ray tracer's ambient term lights and the part of `f` that does not depend on the
    /// directions.
    pub fn diffuse_reflectance(&self) -> DVec3 {
        match self {
            Bsdf::Diffuse(b) => b.color,
            Bsdf::Mirror(_) | Bsdf::Conductor(_) | Bsdf::Dielectric(_) | Bsdf::RoughDielectric(_) => {
                DVec3::ZERO
            }
        }
    }

    /// The smooth part's glossy lobes (all but its diffuse lobe), compactly, with the tint
    /// they are multiplied by, for a visible point to weigh each photon by: `eval(wo, wi) =
    /// diffuse_reflectance()/π + tint × glossy.eval(n, wo, wi)`. `None` when the smooth part
    /// is diffuse only.
    pub fn glossy(&self) -> Option<(Glossy, DVec3)> {
        match self {
            Bsdf::Diffuse(b) => b.glossy().map(|g| (g, DVec3::ONE)),
            Bsdf::Conductor(b) => b.glossy().map(|g| (g, b.color)),
            Bsdf::RoughDielectric(b) => Some((b.glossy(), DVec3::ONE)),
            Bsdf::Mirror(_) | Bsdf::Dielectric(_) => None,
        }
    }

    /// A bound of the smooth part's reflectance (each channel at most 1): a photon's chance
    /// of going on under Russian roulette.
    pub fn albedo(&self) -> DVec3 {
        match self {
            Bsdf::Diffuse(b) => b.albedo(),
            Bsdf::Conductor(b) if !b.is_smooth() => b.color,
            Bsdf::RoughDielectric(b) => b.color.max(DVec3::ONE).min(DVec3::ONE),
            Bsdf::Mirror(_) | Bsdf::Conductor(_) | Bsdf::Dielectric(_) => DVec3::ZERO,
        }
    }

    /// `f(wo, wi)` of the smooth part (zero when `wi` is below the surface).
    pub fn eval(&self, wo: DVec3, wi: DVec3) -> DVec3 {
        match self {
            Bsdf::Diffuse(b) => b.eval(wo, wi),
            Bsdf::Conductor(b) => b.eval(wo, wi),
            Bsdf::RoughDielectric(b) => b.eval(wo, wi),
            Bsdf::Mirror(_) | Bsdf::Dielectric(_) => DVec3::ZERO,
        }
    }

    /// The solid-angle density with which [`Bsdf::sample`] picks `wi` at `wo`.
    pub fn pdf(&self, wo: DVec3, wi: DVec3) -> f64 {
        match self {
            Bsdf::Diffuse(b) => b.pdf(wo, wi),
            Bsdf::Conductor(b) => b.pdf(wo, wi),
            Bsdf::RoughDielectric(b) => b.pdf(wo, wi),
            Bsdf::Mirror(_) | Bsdf::Dielectric(_) => 0.0,
        }
    }

    /// The density with which a path arriving the other way, along `wi`, samples `wo`: what
    /// bidirectional methods weigh a vertex by when the light's subpath, not the eye's, made
    /// it (the reverse density of Veach 1997, §10.2). Where `wi` lies beyond the surface
    /// (refraction) the surface is seen from the other side, through the inverse index.
    pub fn pdf_reverse(&self, wo: DVec3, wi: DVec3) -> f64 {
        if self.normal().dot(wi) >= 0.0 {
            return self.pdf(wi, wo);
        }
        match *self {
            Bsdf::RoughDielectric(b) => RoughDielectric {
                eta: 1.0 / b.eta,
                n: -b.n,
                ..b
            }
            .pdf(wi, wo),
            // Surfaces that only reflect take nothing from beyond them.
            _ => 0.0,
        }
    }

    /// A direction from the smooth part, drawing what numbers it needs from `rng` (a
    /// Lambertian surface and a rough conductor draw two, a rough dielectric three). `None`
    /// when the part is empty, or the sample falls below the surface (or, refracted, on its
    /// own side).
    pub fn sample<R: Rng + ?Sized>(&self, wo: DVec3, rng: &mut R) -> Option<BsdfSample> {
        match self {
            Bsdf::Diffuse(b) => b.sample(wo, rng),
            Bsdf::Conductor(b) if !b.is_smooth() => b.sample(wo, DVec2::new(rng.random(), rng.random())),
            Bsdf::RoughDielectric(b) => {
                let u = DVec2::new(rng.random(), rng.random());
                b.sample(wo, u, rng.random())
            }
            Bsdf::Mirror(_) | Bsdf::Conductor(_) | Bsdf::Dielectric(_) => None,
        }
    }

    /// The specular part's lobes at `wo`.
    pub fn specular_lobes(&self, wo: DVec3) -> SpecularLobes {
        match self {
            Bsdf::Diffuse(_) => SpecularLobes::NONE,
            Bsdf::Mirror(b) => b.lobes(wo),
            Bsdf::Conductor(b) => b.lobes(wo),
            Bsdf::Dielectric(b) => b.lobes(wo),
            Bsdf::RoughDielectric(_) => SpecularLobes::NONE,
        }
    }

    /// What radiance carried from `wi` to `wo` is scaled by beside `f`: `(η_wo / η_wi)²` when
    /// `wi` is refracted from the far side of a dielectric, else 1. The BSDFs here transport
    /// flux (photons; pbrt-v4's `TransportMode::Importance`); a tracer carrying radiance from
    /// the eye multiplies this in at each refraction (pbrt-v4's `TransportMode::Radiance`,
    /// §9.5.2). On a path that enters and leaves the same glass the factors cancel, which is
    /// why the path tracer, whose paths start and end in air, may leave them out; photon
    /// mapping's eye paths may not, since they end at a visible point that can lie in water or
    /// glass (under `scenes/pool.toml`'s water, without them, photon mapping was 1.47× the path
    /// tracer).
    pub fn radiance_scale(&self, wo: DVec3, wi: DVec3) -> f64 {
        let (n, far) = match self {
            Bsdf::Dielectric(b) => (b.n, if b.entering { b.ior } else { 1.0 / b.ior }),
            Bsdf::RoughDielectric(b) => (b.n, b.eta),
            _ => return 1.0,
        };
        if n.dot(wi) < 0.0 && n.dot(wo) > 0.0 {
            1.0 / (far * far)
        } else {
            1.0
        }
    }

    /// The delta lobes of the same surface made smooth: a rough mirror, metal or glass as a
    /// polished one, anything else as it is. What a ray tracer that follows only delta lobes
    /// (Whitted) shows of a rough surface, beside its highlights.
    pub fn smooth_lobes(&self, wo: DVec3) -> SpecularLobes {
        match *self {
            Bsdf::Conductor(b) => Conductor { alpha: 0.0, ..b }.lobes(wo),
            Bsdf::RoughDielectric(b) => Dielectric {
                color: b.color,
                ior: b.eta,
                entering: true,
                n: b.n,
            }
            .lobes(wo),
            _ => self.specular_lobes(wo),
        }
    }
}
