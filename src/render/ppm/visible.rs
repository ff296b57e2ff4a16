//! The eye pass of photon mapping (Hachisuka, Ogaki & Jensen 2008 §3.1; seed report §3.2.1):
//! trace eye rays through the delta lobes of mirrors and glass (all of them, or one picked
//! with its share) to the first surface with a smooth BSDF ([`crate::render::bsdf`]) and
//! record a visible point there — position, normal, and the weight (path throughput × the
//! BSDF's diffuse part ρ/π) that turns photon flux arriving there into pixel radiance. Where
//! the BSDF has glossy lobes (a Phong lobe), the point keeps them with its throughput and the
//! direction to the eye ([`GlossyPoint`]), and weighs each photon by them for the photon's own
//! direction: the full BSDF, as pbrt-v4's SPPM. Emission seen directly along the way, and
//! optionally direct light from point and spot lights (shadow rays, through the full BSDF), is
//! returned separately.

use std::f64::consts::PI;

use glam::{DVec2, DVec3, Vec3};
use rand::Rng;
use rand_pcg::Pcg64Mcg;

use crate::geometry::Hit;
use crate::geometry::Ray;
use crate::render::bsdf::{Bsdf, Glossy};
use crate::scene::{Light, Scene};

/// Where photons are gathered for one pixel (or one branch of one pixel's eye path).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct VisiblePoint {
    /// The statistics slot this point gathers into.
    pub slot: u32,
    /// Position on the diffuse surface.
    pub position: DVec3,
    /// Unit normal facing the eye path.
    pub normal: DVec3,
    /// Path throughput × BRDF (ρ/π), RGB.
    pub weight: DVec3,
    /// Search radius² (copied from the slot when the index is built).
    pub radius2: f64,
    /// The BSDF's glossy lobes, where it has any.
    pub glossy: Option<GlossyPoint>,
}

/// What a visible point on a glossy surface weighs photons by, beyond its diffuse weight (f32,
/// 36 bytes with its tag).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GlossyPoint {
    /// The eye path's throughput to the point.
    pub throughput: Vec3,
    /// The direction to the eye (unit).
    pub wo: Vec3,
    /// The lobes.
    pub lobes: Glossy,
}

impl GlossyPoint {
    /// Throughput × the lobes' `f(wo, wi)` about the normal `n`: what flux arriving from `wi`
    /// adds to the point's diffuse weight.
    #[inline]
    pub fn weight(&self, n: DVec3, wi: DVec3) -> DVec3 {
        self.throughput.as_dvec3() * self.lobes.eval(n, self.wo.as_dvec3(), wi)
    }
}

/// How the eye pass treats glass.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Branching {
    /// Follow both the reflected and the refracted ray, weighted by Fresnel (classic PPM:
    /// the eye pass runs once, so every branch must be kept).
    Split,
    /// Follow one, chosen with the Fresnel probability (stochastic PPM: a new eye pass each
    /// pass averages the choices). `first`, when given, is the uniform number in [0, 1) that
    /// decides the path's first choice (stratified over passes, so a light seen in glass
    /// settles sooner); later choices are random.
    Choose {
        /// The first choice's number (`None`: random).
        first: Option<f64>,
    },
}

/// Where one eye path's outputs go: its visible points (0, 1, or several with
/// [`Branching::Split`]) to a sink — so a pass allocates nothing per pixel — and the light it
/// sees directly (emission, plus direct light from point and spot lights when enabled) summed.
struct EyeOut<'a> {
    points: &'a mut dyn FnMut(VisiblePoint),
    direct: DVec3,
    /// The number for the next glass choice, used once (see [`Branching::Choose`]).
    first_choice: Option<f64>,
}

/// Traces the eye ray `ray` (of a pixel), handing each visible point, tagged with `slot`, to
/// `points`; returns the light seen directly.
pub fn trace_eye(
    scene: &Scene,
    ray: &Ray,
    slot: u32,
    branching: Branching,
    direct_light: bool,
    rng: &mut Pcg64Mcg,
    points: &mut dyn FnMut(VisiblePoint),
) -> DVec3 {
    let mut out = EyeOut {
        points,
        direct: DVec3::ZERO,
        first_choice: match branching {
            Branching::Choose { first } => first,
            Branching::Split => None,
        },
    };
    let walk = EyeWalk {
        scene,
        slot,
        branching,
        direct_light,
    };
    walk.walk(ray, DVec3::ONE, 0, rng, &mut out);
    out.direct
}

/// What stays fixed along one pixel's eye path.
struct EyeWalk<'s> {
    scene: &'s Scene,
    slot: u32,
    branching: Branching,
    direct_light: bool,
}

impl EyeWalk<'_> {
    /// Follows `ray` carrying `throughput` to the diffuse surfaces it reaches.
    fn walk(&self, ray: &Ray, throughput: DVec3, depth: u32, rng: &mut Pcg64Mcg, out: &mut EyeOut) {
        let scene = self.scene;
        if throughput.max_element() <= 0.0 {
            return;
        }
        let Some(hit) = scene.geometry.intersect(ray, f64::INFINITY) else {
            out.direct += throughput * scene.background;
            return;
        };
        out.direct += throughput * scene.emission(&hit, ray.dir);
        if scene.objects[hit.object as usize].emission.is_some() || depth >= scene.params.max_depth {
            return;
        }
        let bsdf = Bsdf::at(&scene.surface(&hit, ray.dir));
        if bsdf.has_smooth() {
            self.visible_point(&hit, &bsdf, -ray.dir, throughput, out);
        }
        let lobes = bsdf.specular_lobes(-ray.dir);
        match (self.branching, lobes.len()) {
            (Branching::Split, _) | (_, 1) => {
                for lobe in lobes.iter() {
                    let next = hit.spawn(lobe.wi);
                    self.walk(&next, throughput * lobe.share * lobe.tint, depth + 1, rng, out);
                }
            }
            (Branching::Choose { .. }, _) => {
                let first = &mut out.first_choice;
                if let Some(lobe) = lobes.choose(|| first.take().unwrap_or_else(|| rng.random())) {
                    self.walk(&hit.spawn(lobe.wi), throughput * lobe.tint, depth + 1, rng, out);
                }
            }
        }
    }

    /// A visible point where the walk, arriving from `wo`, meets a smooth surface, with the
    /// direct light of the point and spot lights when asked. Photon mapping gathers with the
    /// BSDF's diffuse part (`ρ/π`, in the weight) and its glossy lobes here.
    fn visible_point(&self, hit: &Hit, bsdf: &Bsdf, wo: DVec3, throughput: DVec3, out: &mut EyeOut) {
        let scene = self.scene;
        let n = bsdf.normal();
        let weight = throughput * bsdf.diffuse_reflectance() / PI;
        let glossy = bsdf.glossy().map(|lobes| GlossyPoint {
            throughput: throughput.as_vec3(),
            wo: wo.as_vec3(),
            lobes,
        });
        if self.direct_light {
            for (k, light) in scene
                .lights
                .iter()
                .enumerate()
                .filter(|(_, l)| direct_by_shadow_rays(l))
            {
                let Some(ls) = light.sample(hit.point, DVec2::ZERO) else {
                    continue;
                };
                let cos = n.dot(ls.wi);
                if cos > 0.0 && !scene.occluded_from_hit(hit, k, &ls) {
                    out.direct += throughput * bsdf.eval(wo, ls.wi) * ls.incident * cos;
                }
            }
        }
        (out.points)(VisiblePoint {
            slot: self.slot,
            position: hit.point,
            normal: n,
            weight,
            radius2: 0.0,
            glossy,
        });
    }
}

/// Whether the eye pass computes this light's direct light by one exact shadow ray when direct
/// light is on (point and spot lights); area lights are sampled each pass by [`super::direct`].
pub fn direct_by_shadow_rays(light: &Light) -> bool {
    !light.is_area()
}
