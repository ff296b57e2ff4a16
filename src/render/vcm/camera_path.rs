//! Camera subpaths: traced from the eye, and at each smooth vertex every technique that
//! completes a path there, each weighted against all the others (Georgiev 2012,
//! "Implementing vertex connection and merging", §5): light met by the path itself, light
//! sampling, connections to the light subpath of the same index, and merges with the pass's
//! light vertices within its radius.

use glam::{DVec2, DVec3};
use rand::Rng;
use rand_pcg::Pcg64Mcg;

use super::camera_link::eye_ray_pdf;
use super::emission::{area_and_normal, direct_pdf_area, emission_pdf, pick_chance, pick_light};
use super::light_path::{LightVertex, Photons};
use super::state::Subpath;
use super::{mis, PassConstants};
use crate::geometry::{Hit, Ray};
use crate::render::bsdf::Bsdf;
use crate::render::wavelength::Wavelength;
use crate::scene::Scene;

/// What a pass gives every camera subpath to read.
pub struct PassData<'a> {
    /// The scene.
    pub scene: &'a Scene,
    /// The pass's radius and factors.
    pub k: &'a PassConstants,
    /// For each object, the light whose visible surface it is.
    pub light_of: &'a [Option<usize>],
    /// The scene's bounding sphere, which point lights outside it aim their emission at.
    pub target: Option<(DVec3, f64)>,
    /// Every light vertex of the pass, subpath by subpath.
    pub vertices: &'a [LightVertex],
    /// The grid over them, when merging.
    pub photons: Option<&'a Photons>,
}

/// One camera subpath being traced: the light subpath of its index and its own numbers.
pub struct CameraPath<'a> {
    /// The pass.
    pub pass: &'a PassData<'a>,
    /// The vertices of the light subpath of the same index.
    pub own: &'a [LightVertex],
    /// Its random numbers.
    pub rng: Pcg64Mcg,
    /// Segments traced.
    pub segments: u64,
    /// Light vertices merged with.
    pub merged: u64,
}

/// A camera vertex as the techniques there see it.
struct At<'h> {
    hit: &'h Hit,
    bsdf: Bsdf,
    /// Unit direction towards the previous vertex (towards the eye).
    wc: DVec3,
}

impl At<'_> {
    /// `f` for light arriving from `wl` and leaving towards the eye, as radiance.
    fn f(&self, wl: DVec3) -> DVec3 {
        self.bsdf.eval(self.wc, wl) * self.bsdf.radiance_scale(self.wc, wl)
    }

    /// |cos| of `w` to the shading normal.
    fn cos(&self, w: DVec3) -> f64 {
        self.bsdf.normal().dot(w).abs()
    }
}

impl CameraPath<'_> {
    /// The radiance this subpath and the techniques along it bring back along `ray`, an eye
    /// ray.
    pub fn radiance(&mut self, mut ray: Ray) -> DVec3 {
        let (scene, k) = (self.pass.scene, *self.pass.k);
        let mut s = Subpath {
            throughput: DVec3::ONE,
            length: 0,
            d_vcm: mis(k.light_paths / eye_ray_pdf(&scene.camera, ray.dir.dot(scene.camera.forward))),
            d_vc: 0.0,
            d_vm: 0.0,
            wavelength: Wavelength::WHITE,
        };
        let (mut l, mut previous) = (DVec3::ZERO, ray.origin);
        loop {
            self.segments += 1;
            let Some(hit) = scene.geometry.intersect(&ray, f64::INFINITY) else {
                return l + s.throughput * scene.background;
            };
            let distance = (hit.point - previous).length();
            if scene.objects[hit.object as usize].emission.is_some() {
                s.arrive(distance, hit.normal.dot(ray.dir).abs());
                return l + s.throughput * self.light_met(&hit, ray.dir, previous, &s);
            }
            let surface = scene.surface(&hit, ray.dir);
            s.throughput *= s.wavelength.meet(surface.material, || self.rng.random());
            let at = At {
                hit: &hit,
                bsdf: Bsdf::at(&surface, s.wavelength),
                wc: -ray.dir,
            };
            s.arrive(distance, at.cos(at.wc));
            if at.bsdf.has_smooth() {
                if k.techniques.connect {
                    if s.length < k.max_length {
                        l += s.throughput * self.light_sample(&at, &s);
                    }
                    l += s.throughput * self.connect(&at, &s);
                }
                if k.techniques.merge {
                    l += s.throughput * self.merge(&at, &s);
                    if !k.techniques.connect {
                        return l;
                    }
                }
            }
            if s.length >= k.max_length {
                return l;
            }
            let Some((wi, factor)) = self.scatter(&at, &mut s) else {
                return l;
            };
            if !s.survives(factor, self.rng.random()) {
                return l;
            }
            previous = hit.point;
            ray = hit.spawn(wi);
        }
    }

    /// Leaves a camera vertex as radiance flows: a direction from the smooth part, or a delta
    /// lobe picked by its share. Returns the direction and the throughput's factor.
    fn scatter(&mut self, at: &At, s: &mut Subpath) -> Option<(DVec3, f64)> {
        let k = self.pass.k;
        let (wi, weight) = if at.bsdf.has_smooth() {
            let b = at.bsdf.sample(at.wc, &mut self.rng)?;
            s.scatter_smooth(at.cos(b.wi), b.pdf, at.bsdf.pdf_reverse(at.wc, b.wi), k);
            (b.wi, b.weight)
        } else {
            let lobe = at.bsdf.specular_lobes(at.wc).choose(|| self.rng.random())?;
            s.scatter_specular(at.cos(lobe.wi));
            (lobe.wi, lobe.tint)
        };
        let weight = weight * at.bsdf.radiance_scale(at.wc, wi);
        s.throughput *= weight;
        Some((wi, weight.max_element()))
    }

    /// Light met by the subpath at an emitter `hit` (direction `dir`, from `previous`),
    /// weighed against light sampling and the light subpaths that would have started there.
    fn light_met(&self, hit: &Hit, dir: DVec3, previous: DVec3, s: &Subpath) -> DVec3 {
        let scene = self.pass.scene;
        let emitted = scene.emission(hit, dir);
        if emitted == DVec3::ZERO || s.length == 1 {
            // Seen directly, light is met by this technique alone.
            return emitted;
        }
        let Some(k) = self.pass.light_of[hit.object as usize] else {
            return emitted;
        };
        let light = &scene.lights[k];
        let pick = pick_chance(scene.lights.len());
        let direct = pick * direct_pdf_area(light, hit.point, previous);
        let emission = pick * emission_pdf(light, hit.point, -dir, self.pass.target);
        emitted / (1.0 + mis(direct) * s.d_vcm + mis(emission) * s.d_vc)
    }

    /// Next event estimation: one light picked uniformly and sampled, weighed against the
    /// BSDF's sample hitting it and the light subpaths that would have reached this vertex.
    fn light_sample(&mut self, at: &At, s: &Subpath) -> DVec3 {
        let (scene, k) = (self.pass.scene, self.pass.k);
        let (choice, u) = (
            self.rng.random::<f64>(),
            DVec2::new(self.rng.random(), self.rng.random()),
        );
        let Some((index, pick)) = pick_light(scene.lights.len(), choice) else {
            return DVec3::ZERO;
        };
        let light = &scene.lights[index];
        let Some(ls) = light.sample(at.hit.point, u) else {
            return DVec3::ZERO;
        };
        let f = at.f(ls.wi);
        if f == DVec3::ZERO {
            return DVec3::ZERO;
        }
        let on = at.hit.point + ls.wi * ls.distance;
        let (direct_w, cos_light, w_light) = match area_and_normal(light, on) {
            Some((_, n)) => {
                let direct_w = light.pdf(at.hit.point, on);
                let w_light = mis(at.bsdf.pdf(at.wc, ls.wi) / (pick * direct_w));
                (direct_w, n.dot(ls.wi).abs(), w_light)
            }
            None => (ls.distance * ls.distance, 1.0, 0.0),
        };
        let emission = emission_pdf(light, on, -ls.wi, self.pass.target);
        let cos = at.cos(ls.wi);
        let w_camera = mis(emission * cos / (direct_w * cos_light))
            * (k.mis_vm + s.d_vcm + s.d_vc * mis(at.bsdf.pdf_reverse(at.wc, ls.wi)));
        let value = f * ls.incident * (cos / pick / (w_light + 1.0 + w_camera));
        if !value.is_finite() || scene.occluded_from_hit(at.hit, index, &ls) {
            return DVec3::ZERO;
        }
        value
    }

    /// Vertex connection: this vertex joined to every vertex of the light subpath of the same
    /// index that it sees.
    fn connect(&mut self, at: &At, s: &Subpath) -> DVec3 {
        let (scene, k) = (self.pass.scene, self.pass.k);
        let mut sum = DVec3::ZERO;
        for y in self.own {
            if s.length + y.subpath.length + 1 > k.max_length {
                continue;
            }
            let y_bsdf = y.bsdf(scene);
            let v = y.point - at.hit.point;
            let d2 = v.length_squared();
            let d = d2.sqrt();
            let dir = v / d;
            let (f_x, f_y) = (at.f(dir), y_bsdf.eval(y.wl, -dir));
            if f_x == DVec3::ZERO || f_y == DVec3::ZERO {
                continue;
            }
            let (cos_x, cos_y) = (at.cos(dir), y_bsdf.normal().dot(dir).abs());
            let camera_pdf_a = at.bsdf.pdf(at.wc, dir) * cos_y / d2;
            let light_pdf_a = y_bsdf.pdf(y.wl, -dir) * cos_x / d2;
            let w_light = mis(camera_pdf_a)
                * (k.mis_vm + y.subpath.d_vcm + y.subpath.d_vc * mis(y_bsdf.pdf_reverse(y.wl, -dir)));
            let w_camera =
                mis(light_pdf_a) * (k.mis_vm + s.d_vcm + s.d_vc * mis(at.bsdf.pdf_reverse(at.wc, dir)));
            let value = f_x * f_y * y.subpath.throughput * (cos_x * cos_y / d2 / (w_light + 1.0 + w_camera));
            if !value.is_finite() || value == DVec3::ZERO {
                continue;
            }
            if !scene.occluded_between(at.hit, dir, d) {
                sum += value;
            }
        }
        sum
    }

    /// Vertex merging: the light vertices within the pass's radius, as photons: each
    /// arriving as if at this vertex, weighed against the connections that would have made
    /// the same path.
    fn merge(&mut self, at: &At, s: &Subpath) -> DVec3 {
        let Some(photons) = self.pass.photons else {
            return DVec3::ZERO;
        };
        let k = self.pass.k;
        let r2 = k.radius * k.radius;
        let (mut sum, mut merged) = (DVec3::ZERO, 0);
        photons.grid.for_candidates(at.hit.point, k.radius, &mut |place| {
            let y = &self.pass.vertices[photons.order[place as usize] as usize];
            if (y.point - at.hit.point).length_squared() > r2 || s.length + y.subpath.length > k.max_length {
                return;
            }
            let f = at.f(y.wl);
            if f == DVec3::ZERO {
                return;
            }
            let weight = if k.weighs_merges() {
                let w_light = y.subpath.d_vcm * k.mis_vc + y.subpath.d_vm * mis(at.bsdf.pdf(at.wc, y.wl));
                let w_camera = s.d_vcm * k.mis_vc + s.d_vm * mis(at.bsdf.pdf_reverse(at.wc, y.wl));
                1.0 / (w_light + 1.0 + w_camera)
            } else {
                1.0
            };
            sum += f * y.subpath.throughput * weight;
            merged += 1;
        });
        self.merged += merged;
        let value = sum * k.vm_normalization;
        if value.is_finite() {
            value
        } else {
            DVec3::ZERO
        }
    }
}
