//! A perfect mirror: all light leaves in the mirror direction, tinted by the colour.

use glam::DVec3;

use super::{SpecularLobe, SpecularLobes};
use crate::scene::material::reflect;

/// A perfect mirror of colour `color` about the unit normal `n`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Mirror {
    /// The tint of what it reflects.
    pub color: DVec3,
    /// Unit shading normal on `wo`'s side.
    pub n: DVec3,
}

impl Mirror {
    /// Its one lobe: light along `wo` came from the mirror direction.
    pub fn lobes(&self, wo: DVec3) -> SpecularLobes {
        SpecularLobes::one(SpecularLobe {
            wi: reflect(-wo, self.n),
            tint: self.color,
            share: 1.0,
        })
    }
}
