//! A smooth dielectric interface (glass): reflection with the exact Fresnel reflectance for
//! unpolarised light and refraction by Snell's law ([`crate::scene::material::dielectric`]),
//! total internal reflection included. The refracted light is tinted by the colour. The lobes
//! transport flux (photons): radiance carried from the eye is scaled by η² at a crossing as
//! well, which [`super::Bsdf::radiance_scale`] gives.

use glam::DVec3;

use super::{SpecularLobe, SpecularLobes};
use crate::scene::material::dielectric;

/// A smooth interface of index `ior` (inside relative to outside) about the unit normal `n`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Dielectric {
    /// The tint of what it transmits.
    pub color: DVec3,
    /// Index of refraction, inside relative to outside.
    pub ior: f64,
    /// Whether `wo` is outside (the light leaving along `wo` enters the glass when traced
    /// backwards).
    pub entering: bool,
    /// Unit shading normal on `wo`'s side.
    pub n: DVec3,
}

impl Dielectric {
    /// Reflection with its Fresnel share, and refraction with the rest (none under total
    /// internal reflection).
    pub fn lobes(&self, wo: DVec3) -> SpecularLobes {
        let event = dielectric(-wo, self.n, self.ior, self.entering);
        let reflected = SpecularLobe {
            wi: event.reflected,
            tint: DVec3::ONE,
            share: event.fresnel,
        };
        match event.refracted {
            Some(t) => SpecularLobes::two(
                reflected,
                SpecularLobe {
                    wi: t,
                    tint: self.color,
                    share: 1.0 - event.fresnel,
                },
            ),
            None => SpecularLobes::one(reflected),
        }
    }
}
