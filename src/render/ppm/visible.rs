//! The eye pass of photon mapping (Hachisuka, Ogaki & Jensen 2008 §3.1; seed report §3.2.1):
//! trace eye rays through the delta lobes of mirrors and glass (all of them, or one picked
//! with its share), carrying radiance (scaled at each refraction,
//! [`Bsdf::radiance_scale`]: a visible point may lie under water), to the first surface with a
//! smooth BSDF ([`crate::render::bsdf`]) and
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
use crate::render::mis::power_heuristic;
use crate::render::wavelength::Wavelength;
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

/// What a visible point of normal `n`, diffuse weight `diffuse` and glossy lobes `glossy` turns
/// flux arriving from `wi` (away from the surface, unit) into: the diffuse weight when `wi` is
/// above the surface, plus the lobes' weight (which may take light from below). The one rule
/// for photons, area-light samples and shadow rays alike.
#[inline]
pub fn point_weight(diffuse: DVec3, n: DVec3, glossy: Option<&GlossyPoint>, wi: DVec3) -> DVec3 {
    let diffuse = if n.dot(wi) > 0.0 { diffuse } else { DVec3::ZERO };
    match glossy {
        Some(g) => diffuse + g.weight(n, wi),
        None => diffuse,
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
    /// Rays cast so far: the path's segments and its shadow rays.
    rays: u32,
    /// The number for the next glass choice, used once (see [`Branching::Choose`]).
    first_choice: Option<f64>,
}

/// Which light a trace finds by shadow rays to point and spot lights (a path can never meet
/// them), added to the light it sees.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ShadowRays {
    /// None: another trace of the same pixel finds that light (a supersampled pixel's own ray).
    None,
    /// Through near-specular glossy lobes only, which the path follows instead of gathering
    /// them (direct light by photons).
    NearSpecular,
    /// At the visible points too (direct light by light sampling).
    All,
}

impl ShadowRays {
    /// The shadow rays of a trace, with direct light by light sampling or not, that is or is not
    /// the one that finds its pixel's light seen.
    pub fn new(direct_light: bool, finds_light_seen: bool) -> Self {
        match (finds_light_seen, direct_light) {
            (false, _) => ShadowRays::None,
            (true, false) => ShadowRays::NearSpecular,
            (true, true) => ShadowRays::All,
        }
    }
}

/// What one pixel's eye path found besides its visible points.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EyeTrace {
    /// The light seen directly.
    pub direct: DVec3,
    /// The rays the path cast: its segments and its shadow rays. A path of one ray that saw no
    /// light depends only on the scene along that ray (`ppm::reuse`).
    pub rays: u32,
}

/// Traces the eye ray `ray` (of a pixel), handing each visible point, tagged with `slot`, to
/// `points`; returns the light seen directly and the rays cast.
pub fn trace_eye(
    scene: &Scene,
    ray: &Ray,
    slot: u32,
    branching: Branching,
    shadow_rays: ShadowRays,
    rng: &mut Pcg64Mcg,
    points: &mut dyn FnMut(VisiblePoint),
) -> EyeTrace {
    let mut out = EyeOut {
        points,
        direct: DVec3::ZERO,
        rays: 0,
        first_choice: match branching {
            Branching::Choose { first } => first,
            Branching::Split => None,
        },
    };
    let walk = EyeWalk {
        scene,
        slot,
        branching,
        shadow_rays,
    };
    walk.walk(ray, (DVec3::ONE, Wavelength::WHITE), 0, rng, &mut out, None);
    EyeTrace {
        direct: out.direct,
        rays: out.rays,
    }
}

/// What stays fixed along one pixel's eye path.
struct EyeWalk<'s> {
    scene: &'s Scene,
    slot: u32,
    branching: Branching,
    shadow_rays: ShadowRays,
}

impl EyeWalk<'_> {
    /// Follows `ray` carrying `throughput` and its wavelength (white light until a dispersive
    /// glass fixes one, [`Wavelength::meet`]) to the diffuse surfaces it reaches; `from` is where
    /// and with what density a followed glossy lobe sampled it (an area light it meets is
    /// weighed against the light sampled there), `None` after a delta lobe or the camera.
    fn walk(
        &self,
        ray: &Ray,
        (throughput, mut wavelength): (DVec3, Wavelength),
        depth: u32,
        rng: &mut Pcg64Mcg,
        out: &mut EyeOut,
        from: Option<(DVec3, f64)>,
    ) {
        let scene = self.scene;
        if throughput.max_element() <= 0.0 {
            return;
        }
        out.rays += 1;
        let Some(hit) = scene.geometry.intersect(ray, f64::INFINITY) else {
            out.direct += throughput * scene.background;
            return;
        };
        let emitted = scene.emission(&hit, ray.dir);
        if emitted != DVec3::ZERO {
            // After a followed lobe, an area light is weighed against its own sample there.
            let light = || scene.light_objects.iter().position(|&o| o == Some(hit.object));
            let weight = match from.and_then(|f| Some((f, light()?))) {
                Some(((p, pdf), k)) => power_heuristic(pdf, scene.lights[k].pdf(p, hit.point)),
                None => 1.0,
            };
            out.direct += throughput * emitted * weight;
        }
        if scene.objects[hit.object as usize].emission.is_some() || depth >= scene.params.max_depth {
            return;
        }
        let surface = scene.surface(&hit, ray.dir);
        let throughput = throughput * wavelength.meet(surface.material, || rng.random());
        let bsdf = Bsdf::at(&surface, wavelength);
        let wo = -ray.dir;
        if bsdf.has_smooth() {
            match bsdf.glossy().filter(|(g, _)| self.follows(g, &bsdf)) {
                Some(lobes) => {
                    let arrival = (wo, throughput, wavelength);
                    self.near_specular(&hit, &bsdf, lobes, arrival, depth, rng, out)
                }
                None => self.visible_point(&hit, &bsdf, (wo, throughput), true, out),
            }
        }
        let lobes = bsdf.specular_lobes(wo);
        match (self.branching, lobes.len()) {
            (Branching::Split, _) | (_, 1) => {
                for lobe in lobes.iter() {
                    let next = hit.spawn(lobe.wi);
                    let carried = throughput * lobe.share * lobe.tint * bsdf.radiance_scale(wo, lobe.wi);
                    self.walk(&next, (carried, wavelength), depth + 1, rng, out, None);
                }
            }
            (Branching::Choose { .. }, _) => {
                let first = &mut out.first_choice;
                if let Some(lobe) = lobes.choose(|| first.take().unwrap_or_else(|| rng.random())) {
                    let carried = throughput * lobe.tint * bsdf.radiance_scale(wo, lobe.wi);
                    self.walk(
                        &hit.spawn(lobe.wi),
                        (carried, wavelength),
                        depth + 1,
                        rng,
                        out,
                        None,
                    );
                }
            }
        }
    }

    /// Whether the path follows `lobes` (of `bsdf`) rather than gathering them: their
    /// roughness is below the scene's `near_specular` times their share of the surface's
    /// reflectance ([`lobe_share`]), and the pass traces paths anew (classic PPM's one eye pass
    /// would fix one direction for good, so it gathers every lobe). A followed lobe costs the
    /// surface's diffuse estimate the passes the path takes the lobe, hence the share: measured
    /// on the Cornell box at 160×120 (10 s, `bench convergence`), the RMSE of following and
    /// gathering cross at α ≈ 0.15 for a rough gold sphere (share 1: following 2.2× faster at
    /// 0.1, gathering 1.2× lower error at 0.25) and at α ≈ 0.045 for a glossy floor of ρ 0.5
    /// and ρs 0.4 (share 0.44: gathering 1.6× lower error at α 0.1, following 1.9× faster at
    /// 0.02).
    fn follows(&self, lobes: &Glossy, bsdf: &Bsdf) -> bool {
        matches!(self.branching, Branching::Choose { .. })
            && lobes.roughness() < self.scene.params.near_specular * lobe_share(lobes, bsdf)
    }

    /// At a smooth surface, arriving from `wo` with `throughput` and `wavelength`, whose glossy lobes the path
    /// follows: either the lobes (picked with their share of the reflectance: the path goes on
    /// along a direction sampled from them) or a visible point that gathers the diffuse lobe
    /// alone, each weighted by one over its chance. The lobes' direct light is found here,
    /// whatever `direct_light` says, since the point gathers none through them: point and spot
    /// lights by shadow rays, area lights by one sample each weighed against the lobes' own
    /// sampling by the power heuristic (as the path tracer does). Photons still land here and
    /// leave through the lobes, so the caustics the lobes cast and receive are kept.
    #[allow(clippy::too_many_arguments)]
    fn near_specular(
        &self,
        hit: &Hit,
        bsdf: &Bsdf,
        (lobes, tint): (Glossy, DVec3),
        (wo, throughput, wavelength): (DVec3, DVec3, Wavelength),
        depth: u32,
        rng: &mut Pcg64Mcg,
        out: &mut EyeOut,
    ) {
        let n = bsdf.normal();
        let share = lobe_share(&lobes, bsdf);
        if self.shadow_rays != ShadowRays::None {
            for (k, light) in self.scene.lights.iter().enumerate() {
                // Counted whether or not it is cast: what decides that depends on the light.
                out.rays += 1;
                let u = DVec2::new(rng.random(), rng.random());
                let Some(ls) = light.sample(hit.point, u) else {
                    continue;
                };
                // Either side: a rough dielectric's lobes refract.
                let f = lobes.eval(n, wo, ls.wi);
                if f == DVec3::ZERO || self.scene.occluded_from_hit(hit, k, &ls) {
                    continue;
                }
                let weight = if light.is_area() {
                    let on = hit.point + ls.wi * ls.distance;
                    power_heuristic(light.pdf(hit.point, on), share * lobes.pdf(n, wo, ls.wi))
                } else {
                    1.0
                };
                out.direct += throughput * tint * f * ls.incident * n.dot(ls.wi).abs() * weight;
            }
        }
        if rng.random::<f64>() < share {
            let u = DVec3::new(rng.random(), rng.random(), rng.random());
            if let Some(s) = lobes.sample(n, wo, u) {
                let next = hit.spawn(s.wi);
                let from = Some((hit.point, share * s.pdf));
                self.walk(
                    &next,
                    (throughput * tint * s.weight / share, wavelength),
                    depth + 1,
                    rng,
                    out,
                    from,
                );
            }
        } else {
            self.visible_point(hit, bsdf, (wo, throughput / (1.0 - share)), false, out);
        }
    }

    /// A visible point where the walk, arriving from `wo` with `throughput`, meets a smooth
    /// surface, with the direct light of the point and spot lights when asked. Photon mapping
    /// gathers with the BSDF's diffuse part (`ρ/π`, in the weight) here, and with its glossy
    /// lobes if `glossy` (else the path follows them).
    fn visible_point(
        &self,
        hit: &Hit,
        bsdf: &Bsdf,
        (wo, throughput): (DVec3, DVec3),
        glossy: bool,
        out: &mut EyeOut,
    ) {
        let scene = self.scene;
        let n = bsdf.normal();
        let weight = throughput * bsdf.diffuse_reflectance() / PI;
        let glossy = bsdf.glossy().filter(|_| glossy).map(|(lobes, tint)| GlossyPoint {
            throughput: (throughput * tint).as_vec3(),
            wo: wo.as_vec3(),
            lobes,
        });
        if self.shadow_rays == ShadowRays::All {
            for (k, light) in scene
                .lights
                .iter()
                .enumerate()
                .filter(|(_, l)| direct_by_shadow_rays(l))
            {
                // Counted whether or not it is cast: what decides that depends on the light.
                out.rays += 1;
                let Some(ls) = light.sample(hit.point, DVec2::ZERO) else {
                    continue;
                };
                let f = point_weight(weight, n, glossy.as_ref(), ls.wi);
                if f != DVec3::ZERO && !scene.occluded_from_hit(hit, k, &ls) {
                    out.direct += f * ls.incident * n.dot(ls.wi).abs();
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

/// The share of a surface's reflectance that its glossy `lobes` hold beside `bsdf`'s diffuse
/// lobe (1 without one): the chance a path takes the lobes when it follows them.
fn lobe_share(lobes: &Glossy, bsdf: &Bsdf) -> f64 {
    let diffuse = bsdf.diffuse_reflectance().max_element();
    lobes.albedo() / (lobes.albedo() + diffuse)
}

/// Whether the eye pass computes this light's direct light by one exact shadow ray when direct
/// light is on (point and spot lights); area lights are sampled each pass by [`super::direct`].
pub fn direct_by_shadow_rays(light: &Light) -> bool {
    !light.is_area()
}
