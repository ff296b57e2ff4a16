//! Light subpaths: traced from a light, their vertices on smooth surfaces kept for the camera
//! subpaths to connect to and merge with ([`LightVertex`]), each vertex linked to the camera
//! as it is made (light tracing: what reaches the film directly, a caustic on a floor seen by
//! the camera among it).

use glam::{DVec2, DVec3};
use rand::Rng;
use rand_pcg::Pcg64Mcg;

use super::camera_link::link;
use super::emission::{direct_pdf_area, emit, pick_light};
use super::state::Subpath;
use super::{mis, PassConstants};
use crate::geometry::Hit;
use crate::render::bsdf::Bsdf;
use crate::render::ppm::{HashGrid, SearchSphere};
use crate::scene::{Scene, Surface};

/// A light subpath's vertex on a surface with a smooth part. A pass keeps one per pixel or
/// more, so the surface is kept as what its BSDF is made from (smaller than the BSDF),
/// made again for the few connections to it ([`LightVertex::bsdf`]).
#[derive(Clone, Copy, Debug)]
pub struct LightVertex {
    /// Where.
    pub point: DVec3,
    /// Unit direction towards the previous vertex: where the light came from.
    pub wl: DVec3,
    /// The subpath as it reached this vertex.
    pub subpath: Subpath,
    /// The shading normal on the side the light came from.
    normal: DVec3,
    /// The surface's colour there.
    color: DVec3,
    /// Its material's index.
    material: u32,
    /// Whether the light met the side the geometric normal points to.
    front: bool,
}

impl LightVertex {
    /// The vertex where the subpath `s`, arriving along `-wl`, met `surface` at `point`.
    fn new(point: DVec3, wl: DVec3, s: Subpath, surface: &Surface, material: usize) -> Self {
        Self {
            point,
            wl,
            subpath: s,
            normal: surface.normal,
            color: surface.color,
            material: material as u32,
            front: surface.front,
        }
    }

    /// The surface's BSDF as the light met it (its normal on the side the light came from).
    pub fn bsdf(&self, scene: &Scene) -> Bsdf {
        let surface = Surface {
            material: &scene.materials[self.material as usize],
            color: self.color,
            front: self.front,
            normal: self.normal,
        };
        Bsdf::at(&surface, self.subpath.wavelength)
    }
}

/// What one light subpath left: its vertices, and what it put on the film through the camera
/// (pixel, value), in the order made.
#[derive(Clone, Debug, Default)]
pub struct LightPath {
    /// Its vertices on smooth surfaces.
    pub vertices: Vec<LightVertex>,
    /// Its light-traced contributions.
    pub splats: Vec<(u32, DVec3)>,
    /// Segments traced.
    pub segments: u64,
}

/// Traces one light subpath: a light picked uniformly, its emission, then scattering until
/// the subpath leaves the scene, is absorbed, or could reach no further technique.
pub fn trace(scene: &Scene, k: &PassConstants, target: Option<(DVec3, f64)>, mut rng: Pcg64Mcg) -> LightPath {
    let mut out = LightPath::default();
    let Some((index, pick)) = pick_light(scene.lights.len(), rng.random()) else {
        return out;
    };
    let light = &scene.lights[index];
    let u = [rng.random(), rng.random(), rng.random(), rng.random()];
    let Some(emitted) = emit(light, pick, u, target, k) else {
        return out;
    };
    let (mut s, mut ray, mut previous) = (emitted.subpath, emitted.ray, emitted.origin);
    loop {
        out.segments += 1;
        let Some(hit) = scene.geometry.intersect(&ray, f64::INFINITY) else {
            break;
        };
        // Emitters reflect nothing.
        if scene.objects[hit.object as usize].emission.is_some() {
            break;
        }
        let surface = scene.surface(&hit, ray.dir);
        s.throughput *= s.wavelength.meet(surface.material, || rng.random());
        let bsdf = Bsdf::at(&surface, s.wavelength);
        let wl = -ray.dir;
        let n = bsdf.normal();
        if s.length == 0 {
            s.d_vcm *= mis(direct_pdf_area(light, previous, hit.point));
        }
        s.arrive((hit.point - previous).length(), n.dot(wl).abs());
        let lens = DVec2::new(rng.random(), rng.random());
        if bsdf.has_smooth() {
            let material = scene.objects[hit.object as usize].material;
            out.vertices
                .push(LightVertex::new(hit.point, wl, s, &surface, material));
            if k.techniques.connect && s.length < k.max_length {
                out.splats
                    .extend(to_camera(scene, k, (&hit, &bsdf, wl), &s, lens));
            }
        }
        if s.length + 2 > k.max_length {
            break;
        }
        let Some((wi, factor)) = scatter(&bsdf, wl, &mut s, k, &mut rng) else {
            break;
        };
        if !s.survives(factor, rng.random()) {
            break;
        }
        previous = hit.point;
        ray = hit.spawn(wi);
    }
    out
}

/// Leaves a light vertex: a direction from the smooth part, or a delta lobe picked by its
/// share. Returns the direction and the vertex's share of what goes on (for the roulette).
fn scatter(
    bsdf: &Bsdf,
    wl: DVec3,
    s: &mut Subpath,
    k: &PassConstants,
    rng: &mut Pcg64Mcg,
) -> Option<(DVec3, f64)> {
    let n = bsdf.normal();
    if bsdf.has_smooth() {
        let b = bsdf.sample(wl, rng)?;
        s.scatter_smooth(n.dot(b.wi).abs(), b.pdf, bsdf.pdf_reverse(wl, b.wi), k);
        s.throughput *= b.weight;
        Some((b.wi, b.weight.max_element()))
    } else {
        let lobe = bsdf.specular_lobes(wl).choose(|| rng.random())?;
        s.scatter_specular(n.dot(lobe.wi).abs());
        s.throughput *= lobe.tint;
        Some((lobe.wi, lobe.tint.max_element()))
    }
}

/// Light tracing: the vertex at `hit` linked to the lens point `lens` picks, weighed against
/// the camera subpaths that would have reached it. `None` when nothing reaches the film.
fn to_camera(
    scene: &Scene,
    k: &PassConstants,
    (hit, bsdf, wl): (&Hit, &Bsdf, DVec3),
    s: &Subpath,
    lens: DVec2,
) -> Option<(u32, DVec3)> {
    let link = link(&scene.camera, hit.point, lens)?;
    let wc = link.to_camera;
    let f = bsdf.eval(wl, wc);
    if f == DVec3::ZERO {
        return None;
    }
    let cos = bsdf.normal().dot(wc).abs();
    let d2 = link.distance * link.distance;
    let camera_pdf_a = link.pdf_w * cos / d2;
    let w_light =
        mis(camera_pdf_a / k.light_paths) * (k.mis_vm + s.d_vcm + s.d_vc * mis(bsdf.pdf_reverse(wl, wc)));
    let value = s.throughput * f * (cos * link.pdf_w / (d2 * k.light_paths) / (1.0 + w_light));
    if !value.is_finite() || value == DVec3::ZERO {
        return None;
    }
    if scene.occluded_between(hit, wc, link.distance) {
        return None;
    }
    Some((link.pixel as u32, value))
}

/// A pass's light vertices behind a hashed grid for merging.
pub struct Photons {
    /// The grid over every vertex, built for the pass's radius.
    pub grid: HashGrid,
    /// Place `i` of the grid holds vertex `order[i]`.
    pub order: Vec<u32>,
}

/// A light vertex's place in the grid: its point and the pass's radius².
struct Centre(DVec3, f64);

impl SearchSphere for Centre {
    fn centre(&self) -> DVec3 {
        self.0
    }

    fn reach2(&self) -> f64 {
        self.1
    }
}

impl Photons {
    /// The grid over `vertices` for merging radius `radius`.
    pub fn build(vertices: &[LightVertex], radius: f64) -> Self {
        let centres: Vec<Centre> = vertices
            .iter()
            .map(|v| Centre(v.point, radius * radius))
            .collect();
        let (grid, order) = HashGrid::build(&centres);
        Self { grid, order }
    }
}
