//! Photon tracing (Jensen 2001; Hachisuka et al. 2008 §3.2; seed report §3.2.2): photons leave
//! the lights in proportion to their power, follow a delta lobe of mirrors and glass picked
//! with its share (Fresnel chooses reflection or refraction), and at every surface with a
//! smooth BSDF ([`crate::render::bsdf`]) hand their flux to the visible points whose search
//! sphere holds them — on the same side of the surface — before continuing in a direction
//! sampled from the BSDF (its Phong lobe included) under Russian roulette with the BSDF's
//! albedo as the survival probability. A stratified photon's direction comes from a low-discrepancy sequence over
//! the render's photons ([`crate::render::sequence`]; Keller, Grünschloß & Droske 2012).

use glam::{DVec2, DVec3};
use rand::Rng;
use rand_pcg::Pcg64Mcg;

use super::guide::EmissionGuide;
use crate::geometry::Ray;
use crate::render::bsdf::Bsdf;
use crate::render::sequence;
use crate::render::wavelength::Wavelength;
use crate::scene::Scene;

/// Counters of one batch of photons.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct PhotonCounts {
    /// Photon paths traced.
    pub paths: u64,
    /// Surface interactions (bounces).
    pub bounces: u64,
    /// Deposits made (counted by the caller's gather).
    pub deposits: u64,
    /// Paths that handed flux to at least one visible point (counted by the caller).
    pub useful: u64,
}

/// Where a traced photon came from: its light and the bin of the light's [`EmissionGuide`]
/// its random numbers fell in (0 without a guide).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Emitted {
    /// Index of the light in the scene.
    pub light: usize,
    /// Bin of the light's guided pair of random numbers.
    pub bin: u32,
}

/// Where the light's photons go: which light, with what flux.
pub struct PhotonSource<'a> {
    /// The scene.
    pub scene: &'a Scene,
    /// Cumulative distribution over lights, by power.
    pub cdf: Vec<f64>,
    /// Photon flux of each light, `power / p_light`, before the emission weight: radiance
    /// estimates divide by the total number of photons emitted (smallppm's convention), so the
    /// number of photons per pass may change between passes.
    pub flux: Vec<DVec3>,
    /// The scene's bounding sphere, for aiming lights outside it.
    pub target: Option<(DVec3, f64)>,
    /// Skip the deposit where a photon first meets anything, when that is a diffuse surface:
    /// that is direct light, computed by light sampling at the visible points. Photons that
    /// reached the surface through mirrors or glass (caustics) are still gathered — a shadow
    /// ray cannot see them.
    pub skip_direct: bool,
    /// The learned emission density, when photons are guided to where the camera looks.
    pub guide: Option<&'a EmissionGuide>,
    /// When photons are stratified: the digital shift of the Sobol points that choose their
    /// lights and directions ([`sequence::sobol_any`]); `None`, every number is random.
    pub stratified: Option<u64>,
    /// The wavelength every photon starts with: white light ([`Wavelength::WHITE`]), which
    /// takes one wavelength at the first dispersive glass it meets, or one fixed wavelength.
    pub wavelength: Wavelength,
}

/// The chance that a photon comes from each of the scene's lights: in proportion to power.
pub fn light_probabilities(scene: &Scene) -> Vec<f64> {
    let powers: Vec<f64> = scene
        .lights
        .iter()
        .map(|l| l.power().element_sum() / 3.0)
        .collect();
    let total: f64 = powers.iter().sum();
    powers.iter().map(|p| p / total).collect()
}

impl<'a> PhotonSource<'a> {
    /// Photons distributed over the scene's lights in proportion to their power.
    pub fn new(scene: &'a Scene, direct_light: bool) -> Self {
        let pick = light_probabilities(scene);
        let mut acc = 0.0;
        let cdf = pick
            .iter()
            .map(|p| {
                acc += p;
                acc
            })
            .collect();
        let flux = scene
            .lights
            .iter()
            .zip(&pick)
            .map(|(l, p)| l.power() / *p)
            .collect();
        Self {
            scene,
            cdf,
            flux,
            target: scene.geometry.bounding_sphere(),
            skip_direct: direct_light,
            guide: None,
            stratified: None,
            wavelength: Wavelength::WHITE,
        }
    }

    /// The same source emitting by `guide`'s learned density (weights keep it unbiased).
    pub fn with_guide(self, guide: Option<&'a EmissionGuide>) -> Self {
        Self { guide, ..self }
    }

    /// The same source choosing photon `n`'s light and direction by point `n` of Sobol's
    /// sequence, digitally shifted by `shift`, when that is given (see
    /// [`PhotonSource::stratified`]).
    pub fn with_stratified(self, shift: Option<u64>) -> Self {
        Self {
            stratified: shift,
            ..self
        }
    }

    /// The same source emitting light of one `wavelength` only (its colour weight is not
    /// applied: each photon keeps the light's flux).
    pub fn with_wavelength(self, wavelength: Wavelength) -> Self {
        Self { wavelength, ..self }
    }

    /// The light that `x` in [0, 1) picks (the power share it falls in) and `x` rescaled to
    /// [0, 1) within that share, which is uniform again and free to be used once more (the
    /// remapped sample of pbrt-v4's `SampleDiscrete`). With one light, `x` itself.
    fn pick(&self, x: f64) -> (usize, f64) {
        let last = self.cdf.len() - 1;
        let light = self.cdf.iter().position(|&c| x < c).unwrap_or(last);
        let below = if light == 0 { 0.0 } else { self.cdf[light - 1] };
        let share = self.cdf[light] - below;
        let rescaled = if share > 0.0 { (x - below) / share } else { 0.5 };
        (light, rescaled.clamp(0.0, 1.0 - f64::EPSILON / 2.0))
    }

    /// Emits photon number `n`: picks its light and its random numbers (from the sequence
    /// when photons are stratified), warps them by the guide, and returns where the photon
    /// came from, its flux (weighted by the guide's density) and its first ray.
    fn emit(&self, n: u64, rng: &mut Pcg64Mcg) -> (Emitted, DVec3, Ray) {
        let pick: f64 = rng.random();
        // A stratified photon's Sobol point picks the light by its first coordinate, which,
        // rescaled within that light's share, then places the photon with the second: each
        // light's photons are a stratified share of the sequence, not a random subset of it.
        // (The random pick is still drawn, so the photon's other numbers stay the same.)
        let (light_index, point) = match self.stratified {
            Some(shift) => {
                let q = sequence::sobol_any(n, shift);
                let (light, x) = self.pick(q.x);
                (light, Some(DVec2::new(x, q.y)))
            }
            None => (self.pick(pick).0, None),
        };
        let light = &self.scene.lights[light_index];
        let mut u = [rng.random(), rng.random(), rng.random(), rng.random()];
        if let Some(q) = point {
            let k = 2 * light.direction_pair();
            (u[k], u[k + 1]) = (q.x, q.y);
        }
        let (pdf, bin) = self.guide.map_or((1.0, 0), |g| g.warp(light_index, &mut u));
        let emitted = Emitted {
            light: light_index,
            bin,
        };
        let e = light.emit(u, self.target);
        (emitted, self.flux[light_index] * (e.weight / pdf), e.ray())
    }

    /// Traces photon number `n` (counted over the render; it places a stratified photon in
    /// its sequence) with `rng`. At every diffuse hit whose flux should be gathered
    /// (all but direct hits when direct light is computed by light sampling),
    /// calls `gather(point, (normal facing the photon, direction it came from), flux,
    /// indirect)`, `indirect` telling
    /// whether the photon has bounced off a diffuse surface before (indirect light) or came
    /// straight from the light or through mirrors and glass only (direct light, caustics).
    /// Returns where the photon came from.
    pub fn trace(
        &self,
        n: u64,
        rng: &mut Pcg64Mcg,
        counts: &mut PhotonCounts,
        gather: &mut impl FnMut(DVec3, (DVec3, DVec3), DVec3, bool),
    ) -> Emitted {
        let scene = self.scene;
        let (emitted, mut flux, mut ray) = self.emit(n, rng);
        let skip_first = self.skip_direct;
        counts.paths += 1;
        let mut first_interaction = true;
        let mut indirect = false;
        let mut wavelength = self.wavelength;
        for _depth in 0..scene.params.max_depth.max(1) * 4 {
            let Some(hit) = scene.geometry.intersect(&ray, f64::INFINITY) else {
                return emitted;
            };
            counts.bounces += 1;
            if scene.objects[hit.object as usize].emission.is_some() {
                return emitted;
            }
            let surface = scene.surface(&hit, ray.dir);
            flux *= wavelength.meet(surface.material, || rng.random());
            let bsdf = Bsdf::at(&surface, wavelength);
            let wo = -ray.dir;
            if bsdf.has_smooth() {
                if !(skip_first && first_interaction) {
                    gather(hit.point, (bsdf.normal(), wo), flux, indirect);
                }
                // Light that has met a diffuse lobe is indirect; a rough mirror, metal or glass
                // bends it as a smooth one does, into a caustic.
                indirect |= bsdf.diffuse_reflectance() != DVec3::ZERO;
                // Russian roulette on the albedo, then a bounce sampled from the BSDF.
                let survive = bsdf.albedo().max_element();
                if survive <= 0.0 || rng.random::<f64>() >= survive {
                    return emitted;
                }
                let Some(s) = bsdf.sample(wo, rng) else {
                    return emitted;
                };
                flux *= s.weight / survive;
                ray = hit.spawn(s.wi);
            } else {
                let lobes = bsdf.specular_lobes(wo);
                let Some(lobe) = lobes.choose(|| rng.random()) else {
                    return emitted;
                };
                flux *= lobe.tint;
                ray = hit.spawn(lobe.wi);
            }
            first_interaction = false;
            if flux.max_element() <= 0.0 {
                return emitted;
            }
        }
        emitted
    }
}
