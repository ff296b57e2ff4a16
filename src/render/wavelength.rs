//! The wavelength a path carries: none (all of white light, in RGB) until it meets a
//! dispersive glass, then one wavelength for the rest of the path.
//!
//! Transport stays RGB everywhere except on the paths that meet a dispersive surface. This is
//! hero-wavelength sampling (Wilkie, Nawaz, Droske, Weidlich & Hanika 2014, "Hero wavelength
//! spectral sampling", as pbrt-v4's `SampledWavelengths::TerminateSecondary`) at the moment it
//! matters: before a dispersive interface every wavelength follows the same path, which RGB
//! transport carries without colour noise; at the interface the secondary wavelengths end
//! and one continues, drawn by [`crate::render::spectrum::sample_wavelength`], its colour
//! weight multiplying the path's throughput. Photons carry a wavelength the same way.
//!
//! Photon mapping draws an eye path's wavelength and a photon's independently, so where both
//! pass through dispersive glass (a spectrum seen through a prism) their colours meet as RGB
//! products, as every colour does in this renderer; the path tracer's single path has one.

use glam::DVec3;

use super::spectrum::sample_wavelength;
use crate::scene::material::Material;

/// A path's wavelength in nm, once fixed.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Wavelength(Option<f64>);

impl Wavelength {
    /// White light: no wavelength fixed yet.
    pub const WHITE: Self = Self(None);

    /// One fixed wavelength in nm.
    pub fn fixed(nm: f64) -> Self {
        Self(Some(nm))
    }

    /// The wavelength in nm, if fixed.
    pub fn nm(self) -> Option<f64> {
        self.0
    }

    /// Called at each surface the path meets: at a dispersive `material` (a glass whose index
    /// varies) a path of white light draws its wavelength with `u` and gets back the colour
    /// weight to multiply its throughput by; otherwise nothing is drawn and the weight is 1.
    pub fn meet(&mut self, material: &Material, u: impl FnOnce() -> f64) -> DVec3 {
        if self.0.is_some() || !material.is_dispersive() {
            return DVec3::ONE;
        }
        let s = sample_wavelength(u());
        self.0 = Some(s.nm);
        s.weight
    }
}
