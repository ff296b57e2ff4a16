//! A subpath's running state: its throughput and the three recursive quantities of its MIS
//! weights (Georgiev 2012, "Implementing vertex connection and merging", §4–5: `dVCM`, `dVC`,
//! `dVM`). Each sums, over the techniques that would have sampled the subpath so far
//! differently, the squared ratios of their densities to this one's; a connection or a merge
//! then weighs itself against all of them from its two ends' quantities alone.

use glam::DVec3;

use super::{mis, PassConstants};
use crate::render::wavelength::Wavelength;

/// A light or camera subpath as it reaches its current vertex.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Subpath {
    /// What it carries: flux (a light subpath) or importance's weight on radiance (a camera
    /// subpath), divided by the densities it was sampled with.
    pub throughput: DVec3,
    /// Segments from its start to its current vertex.
    pub length: u32,
    /// `dVCM`: the techniques that would have ended the path at this subpath's previous
    /// vertex (light sampling, or hitting the light) or merged there.
    pub d_vcm: f64,
    /// `dVC`: the connections at earlier vertices.
    pub d_vc: f64,
    /// `dVM`: the merges at earlier vertices.
    pub d_vm: f64,
    /// The wavelength, once a dispersive surface fixed it.
    pub wavelength: Wavelength,
}

impl Subpath {
    /// Reaches a vertex `distance` from the previous one, meeting its surface at `cos`
    /// (absolute): the densities so far turn from solid angle at the previous vertex to area
    /// at this one.
    pub fn arrive(&mut self, distance: f64, cos: f64) {
        let cos = mis(cos.max(1e-12));
        self.d_vcm *= mis(distance * distance) / cos;
        self.d_vc /= cos;
        self.d_vm /= cos;
        self.length += 1;
    }

    /// Leaves a vertex in a direction its smooth part sampled with density `pdf`, at `cos`
    /// (absolute) to the surface, where the other subpath would have sampled the way it came
    /// with density `pdf_reverse`.
    pub fn scatter_smooth(&mut self, cos: f64, pdf: f64, pdf_reverse: f64, k: &PassConstants) {
        let f = mis(cos / pdf);
        self.d_vc = f * (self.d_vc * mis(pdf_reverse) + self.d_vcm + k.mis_vm);
        self.d_vm = f * (self.d_vm * mis(pdf_reverse) + self.d_vcm * k.mis_vc + 1.0);
        self.d_vcm = mis(1.0 / pdf);
    }

    /// Leaves a vertex by a delta lobe at `cos` (absolute): no technique ends or merges here,
    /// and the lobe's density in either direction is the same.
    pub fn scatter_specular(&mut self, cos: f64) {
        self.d_vcm = 0.0;
        self.d_vc *= mis(cos);
        self.d_vm *= mis(cos);
    }

    /// Russian roulette after the third segment on `factor`, this vertex's share of what goes
    /// on (at most 1): whether the subpath goes on, its throughput divided by the chance if so.
    /// The densities in the MIS quantities leave the roulette out, so every technique's weight
    /// is the same function of the path and they still sum to 1.
    pub fn survives(&mut self, factor: f64, u: f64) -> bool {
        if self.length < 3 {
            return true;
        }
        let survive = factor.min(1.0);
        if survive <= 0.0 || !survive.is_finite() || u >= survive {
            return false;
        }
        self.throughput /= survive;
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::vcm::Techniques;

    fn start() -> Subpath {
        Subpath {
            throughput: DVec3::ONE,
            length: 0,
            d_vcm: 2.0,
            d_vc: 3.0,
            d_vm: 5.0,
            wavelength: Wavelength::WHITE,
        }
    }

    #[test]
    fn arriving_converts_to_area_and_scattering_follows_the_recursion() {
        let mut s = start();
        s.arrive(2.0, 0.5);
        assert_eq!(s.length, 1);
        assert!((s.d_vcm - 2.0 * 16.0 / 0.25).abs() < 1e-12);
        assert!((s.d_vc - 12.0).abs() < 1e-12);
        assert!((s.d_vm - 20.0).abs() < 1e-12);
        let k = PassConstants::new(Techniques::ALL, 0.1, 0.75, 0, 100, 10);
        let before = s;
        s.scatter_smooth(0.5, 0.25, 0.125, &k);
        let f = 4.0;
        assert!((s.d_vc - f * (before.d_vc / 64.0 + before.d_vcm + k.mis_vm)).abs() < 1e-9 * s.d_vc);
        assert!((s.d_vm - f * (before.d_vm / 64.0 + before.d_vcm * k.mis_vc + 1.0)).abs() < 1e-12 * s.d_vm);
        assert_eq!(s.d_vcm, 16.0);
        s.scatter_specular(0.5);
        assert_eq!(s.d_vcm, 0.0);
    }

    #[test]
    fn roulette_spares_short_subpaths_and_reweighs_survivors() {
        let mut s = start();
        assert!(s.survives(0.0, 0.99));
        s.length = 3;
        assert!(!s.survives(0.5, 0.6));
        assert!(s.survives(0.5, 0.4));
        assert_eq!(s.throughput, DVec3::splat(2.0));
    }
}
