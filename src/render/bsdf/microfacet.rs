//! The GGX (Trowbridge–Reitz) microfacet distribution, isotropic, with the height-correlated
//! Smith masking–shadowing term and sampling of the normals visible from a direction:
//!
//! - `D(m) = α² / (π ((n·m)² (α² − 1) + 1)²)` and Smith's `Λ` (Walter, Marschner, Li &
//!   Torrance 2007, "Microfacet models for refraction through rough surfaces", eqs. 33–34);
//! - `G2(wo, wi) = 1 / (1 + Λ(wo) + Λ(wi))` (Heitz 2014, "Understanding the masking-shadowing
//!   function in microfacet-based BRDFs", §6);
//! - visible normals sampled as in Heitz 2018, "Sampling the GGX distribution of visible
//!   normals" (JCGT 7(4)), with density `D_wo(m) = G1(wo) max(0, wo·m) D(m) / (n·wo)`.
//!
//! Directions are in a local frame whose z axis is the shading normal ([`Frame`]).

use std::f64::consts::{PI, TAU};

use glam::{DVec2, DVec3};

/// An orthonormal frame about a unit normal: world directions to local ones (z along the
/// normal) and back.
#[derive(Clone, Copy, Debug)]
pub struct Frame {
    t: DVec3,
    b: DVec3,
    n: DVec3,
}

impl Frame {
    /// The frame about `n`.
    pub fn new(n: DVec3) -> Self {
        let (t, b) = n.any_orthonormal_pair();
        Self { t, b, n }
    }

    /// `v` in local coordinates.
    pub fn local(&self, v: DVec3) -> DVec3 {
        DVec3::new(v.dot(self.t), v.dot(self.b), v.dot(self.n))
    }

    /// The local `v` in world coordinates.
    pub fn world(&self, v: DVec3) -> DVec3 {
        v.x * self.t + v.y * self.b + v.z * self.n
    }
}

/// GGX with roughness `alpha` (> 0).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ggx {
    /// The roughness α (not remapped).
    pub alpha: f64,
}

impl Ggx {
    /// The density of microfacet normals `m` (local), per projected solid angle.
    pub fn d(&self, m: DVec3) -> f64 {
        if m.z <= 0.0 {
            return 0.0;
        }
        let a2 = self.alpha * self.alpha;
        let t = m.z * m.z * (a2 - 1.0) + 1.0;
        a2 / (PI * t * t)
    }

    /// Smith's `Λ(w)` (local `w`).
    pub fn lambda(&self, w: DVec3) -> f64 {
        let cos2 = w.z * w.z;
        if cos2 <= 0.0 {
            return f64::INFINITY;
        }
        let tan2 = (1.0 - cos2).max(0.0) / cos2;
        ((1.0 + self.alpha * self.alpha * tan2).sqrt() - 1.0) / 2.0
    }

    /// The share of the microfacets seen from `w` that are not masked.
    pub fn g1(&self, w: DVec3) -> f64 {
        1.0 / (1.0 + self.lambda(w))
    }

    /// The height-correlated masking–shadowing of `wo` and `wi`.
    pub fn g2(&self, wo: DVec3, wi: DVec3) -> f64 {
        1.0 / (1.0 + self.lambda(wo) + self.lambda(wi))
    }

    /// The density of the normals visible from `wo` (local, above the surface) at `m`.
    pub fn visible_pdf(&self, wo: DVec3, m: DVec3) -> f64 {
        if wo.z <= 0.0 {
            return 0.0;
        }
        self.g1(wo) * wo.dot(m).max(0.0) * self.d(m) / wo.z
    }

    /// A normal visible from `wo` (local, above the surface), from `u` uniform in [0, 1)²
    /// (Heitz 2018, listing 1): the view is stretched to the hemisphere configuration, a
    /// point sampled on the projected half disk, and the normal unstretched.
    pub fn sample_visible(&self, wo: DVec3, u: DVec2) -> DVec3 {
        let a = self.alpha;
        let v = DVec3::new(a * wo.x, a * wo.y, wo.z).normalize();
        let len2 = v.x * v.x + v.y * v.y;
        let t1 = if len2 > 0.0 {
            DVec3::new(-v.y, v.x, 0.0) / len2.sqrt()
        } else {
            DVec3::X
        };
        let t2 = v.cross(t1);
        let r = u.x.sqrt();
        let phi = TAU * u.y;
        let p1 = r * phi.cos();
        let s = 0.5 * (1.0 + v.z);
        let p2 = (1.0 - s) * (1.0 - p1 * p1).max(0.0).sqrt() + s * r * phi.sin();
        let h = p1 * t1 + p2 * t2 + (1.0 - p1 * p1 - p2 * p2).max(0.0).sqrt() * v;
        DVec3::new(a * h.x, a * h.y, h.z.max(1e-12)).normalize()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The distribution's projected area is the surface's: `∫ D(m) (n·m) dm = 1`, and from any
    /// direction the visible normals' density integrates to 1 (midpoint rule on the
    /// hemisphere), for rough and nearly smooth surfaces.
    #[test]
    fn the_distribution_and_the_visible_normals_are_normalised() {
        for alpha in [0.05, 0.3, 1.0] {
            let ggx = Ggx { alpha };
            let wo = DVec3::new(0.6, 0.0, 0.8);
            let (nt, np) = (4000, 64);
            let (mut projected, mut visible) = (0.0, 0.0);
            for i in 0..nt {
                // cos θ from 0 to 1, finer near the pole where a narrow lobe lives.
                let x = (i as f64 + 0.5) / nt as f64;
                let z = 1.0 - x * x;
                let dz = 2.0 * x / nt as f64;
                let s = (1.0 - z * z).max(0.0).sqrt();
                for j in 0..np {
                    let phi = (j as f64 + 0.5) / np as f64 * TAU;
                    let m = DVec3::new(s * phi.cos(), s * phi.sin(), z);
                    let dw = dz * TAU / np as f64;
                    projected += ggx.d(m) * m.z * dw;
                    visible += ggx.visible_pdf(wo, m) * dw;
                }
            }
            assert!((projected - 1.0).abs() < 2e-3, "α {alpha}: ∫D cos = {projected}");
            assert!((visible - 1.0).abs() < 2e-3, "α {alpha}: ∫D_wo = {visible}");
        }
    }
}
