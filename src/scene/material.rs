//! Materials: Lambertian diffuse with an optional Phong lobe, mirrors and metals (smooth or
//! rough), and dielectric glass with exact Fresnel reflectance and total internal reflection,
//! smooth or rough, its index constant or varying with the wavelength ([`super::glasses`]).

use glam::DVec3;

use super::glasses::Dispersion;
use crate::settings::limits;

/// A surface's reflectance model.
#[derive(Clone, Debug, PartialEq)]
pub enum MaterialKind {
    /// Lambertian, `f = ρ/π`, plus an energy-normalised Phong lobe when `specular > 0`:
    /// `f_s = specular · (n+2)/(2π) · cos^n α` (Lafortune & Willems 1994).
    Diffuse {
        /// Phong specular reflectance.
        specular: f64,
        /// Phong exponent.
        shininess: f64,
    },
    /// Specular reflection tinted by the colour: perfect when `roughness` is 0, else GGX
    /// microfacets of that α.
    Mirror {
        /// GGX roughness α (0: smooth).
        roughness: f64,
    },
    /// A metal of complex index of refraction `eta + i k` per colour channel (named metals
    /// give theirs), its Fresnel reflectance tinted by the colour; smooth when `roughness` is
    /// 0, else GGX microfacets of that α.
    Metal {
        /// The real part of the index, per channel.
        eta: DVec3,
        /// The extinction coefficient, per channel.
        k: DVec3,
        /// GGX roughness α (0: smooth).
        roughness: f64,
    },
    /// Dielectric with index of refraction `ior` (relative to the outside, 1): smooth when
    /// `roughness` is 0, else GGX microfacets of that α (frosted glass).
    Glass {
        /// Index of refraction (at the d line, 587.56 nm, where it varies).
        ior: f64,
        /// GGX roughness α (0: smooth).
        roughness: f64,
        /// How the index varies with the wavelength.
        dispersion: Dispersion,
    },
}

/// A material: its model, its colour (reflectance or tint), and optionally a texture replacing
/// the colour.
#[derive(Clone, Debug, PartialEq)]
pub struct Material {
    /// The name in the scene file.
    pub name: String,
    /// The reflectance model.
    pub kind: MaterialKind,
    /// Reflectance or tint, components in [0, 1].
    pub color: DVec3,
    /// Index into the scene's textures.
    pub texture: Option<usize>,
}

impl Material {
    /// Whether photons stop here and radiance is estimated (diffuse surfaces).
    pub fn is_diffuse(&self) -> bool {
        matches!(self.kind, MaterialKind::Diffuse { .. })
    }

    /// Whether this material may be replaced by `new` in a live edit: the same name, model
    /// and texture (colour and the model's numbers may change), every number in the range a
    /// scene file may give it.
    pub fn can_become(&self, new: &Material) -> bool {
        let rough = |r: f64| limits::roughness(r).is_ok();
        let numbers = match new.kind {
            MaterialKind::Diffuse { specular, shininess } => {
                (0.0..=1.0).contains(&specular) && shininess.is_finite() && shininess >= 0.0
            }
            MaterialKind::Mirror { roughness } => rough(roughness),
            MaterialKind::Metal { eta, k, roughness } => {
                rough(roughness) && eta.is_finite() && k.is_finite() && eta.min_element() > 0.0
            }
            MaterialKind::Glass { ior, roughness, .. } => {
                rough(roughness) && ior.is_finite() && ior > 0.0 && ior <= 100.0
            }
        };
        let same_model = std::mem::discriminant(&self.kind) == std::mem::discriminant(&new.kind)
            && match (&self.kind, &new.kind) {
                (MaterialKind::Glass { dispersion: a, .. }, MaterialKind::Glass { dispersion: b, .. }) => {
                    std::mem::discriminant(a) == std::mem::discriminant(b)
                }
                _ => true,
            };
        numbers
            && same_model
            && self.name == new.name
            && self.texture == new.texture
            && new.color.is_finite()
            && new.color.cmpge(DVec3::ZERO).all()
            && new.color.cmple(DVec3::ONE).all()
    }

    /// Whether light is split into its wavelengths here (a glass whose index varies).
    pub fn is_dispersive(&self) -> bool {
        matches!(self.kind, MaterialKind::Glass { dispersion, .. } if dispersion.is_dispersive())
    }
}

/// Fresnel reflectance of a smooth dielectric interface for unpolarised light (exact, not
/// Schlick): `cos_i` is the cosine of the incident angle on the incident side, `eta` the ratio
/// `n_incident / n_transmitted`. Returns 1 under total internal reflection.
pub fn fresnel_dielectric(cos_i: f64, eta: f64) -> f64 {
    let cos_i = cos_i.clamp(0.0, 1.0);
    let sin2_t = eta * eta * (1.0 - cos_i * cos_i);
    if sin2_t >= 1.0 {
        return 1.0;
    }
    let cos_t = (1.0 - sin2_t).sqrt();
    let r_parallel = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    let r_perpendicular = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    0.5 * (r_parallel * r_parallel + r_perpendicular * r_perpendicular)
}

/// What a smooth dielectric does to a ray: Fresnel reflectance, and the reflected and (unless
/// totally internally reflected) refracted directions.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DielectricEvent {
    /// Fraction reflected.
    pub fresnel: f64,
    /// Reflected direction.
    pub reflected: DVec3,
    /// Refracted direction; `None` under total internal reflection.
    pub refracted: Option<DVec3>,
}

/// The one glass interaction every tracer uses: a unit direction `d` meets a surface of index
/// `ior` with unit normal `n` facing against `d`, entering it (`front`: from outside) or
/// leaving it.
pub fn dielectric(d: DVec3, n: DVec3, ior: f64, front: bool) -> DielectricEvent {
    let eta = if front { 1.0 / ior } else { ior };
    DielectricEvent {
        fresnel: fresnel_dielectric(-d.dot(n), eta),
        reflected: reflect(d, n),
        refracted: refract(d, n, eta),
    }
}

/// Mirror reflection of `d` about the unit normal `n`.
pub fn reflect(d: DVec3, n: DVec3) -> DVec3 {
    d - 2.0 * d.dot(n) * n
}

/// Refraction of the unit direction `d` through a surface with unit normal `n` facing against
/// `d`, with `eta = n_incident / n_transmitted`; `None` under total internal reflection.
pub fn refract(d: DVec3, n: DVec3, eta: f64) -> Option<DVec3> {
    let cos_i = -d.dot(n);
    let sin2_t = eta * eta * (1.0 - cos_i * cos_i);
    if sin2_t >= 1.0 {
        return None;
    }
    let cos_t = (1.0 - sin2_t).sqrt();
    Some((eta * d + (eta * cos_i - cos_t) * n).normalize())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fresnel_at_normal_incidence_and_tir() {
        let r = fresnel_dielectric(1.0, 1.0 / 1.5);
        assert!((r - 0.04).abs() < 1e-12);
        assert_eq!(fresnel_dielectric(0.1, 1.5), 1.0);
        // Same reflectance from either side at corresponding angles (Stokes).
        let d = DVec3::new(0.6, 0.0, -0.8);
        let t = refract(d, DVec3::Z, 1.0 / 1.5).expect("refracts");
        let outside = fresnel_dielectric(0.8, 1.0 / 1.5);
        let inside = fresnel_dielectric(-t.z, 1.5);
        assert!((outside - inside).abs() < 1e-12);
    }

    #[test]
    fn snell_holds() {
        let d = DVec3::new(0.6, 0.0, -0.8);
        let t = refract(d, DVec3::Z, 1.0 / 1.33).expect("refracts");
        assert!((0.6 - 1.33 * t.x).abs() < 1e-12);
        assert!(refract(DVec3::new(0.9, 0.0, -0.43588989435406733), DVec3::Z, 1.5).is_none());
    }
}
