//! Scenes: the file format, validation with errors that name file, line and field, and the
//! runtime scene the renderers read (camera, materials, textures, lights, geometry).
//! The format reference is `scenes/FORMAT.md`.

pub mod camera;
pub mod format;
pub mod glasses;
pub mod light;
mod load;
pub mod material;
pub mod metals;
pub mod save;
pub mod texture;

use std::path::PathBuf;

use glam::{DVec2, DVec3};

pub use crate::settings::{RenderParams, RendererKind};

pub use camera::Camera;
pub use light::Light;
pub use load::SceneError;
pub use material::{Material, MaterialKind};
pub use texture::Texture;

use crate::geometry::{Hit, SceneGeometry};

/// One `[[objects]]` entry (or an area light's visible surface) at run time.
#[derive(Clone, Debug, PartialEq)]
pub struct SceneObject {
    /// Name for statistics and errors.
    pub name: String,
    /// Index into [`Scene::materials`].
    pub material: usize,
    /// Emitted radiance for the visible surface of an area light.
    pub emission: Option<DVec3>,
}

/// A loaded, validated scene, ready to render.
#[derive(Clone, Debug)]
pub struct Scene {
    /// The file it came from (`<built-in>` for the default scene).
    pub source: PathBuf,
    /// The camera.
    pub camera: Camera,
    /// Render parameters (the `[render]` table, defaults filled in).
    pub params: RenderParams,
    /// Radiance of rays leaving the scene.
    pub background: DVec3,
    /// Materials; objects refer to them by index.
    pub materials: Vec<Material>,
    /// Textures; materials refer to them by index.
    pub textures: Vec<Texture>,
    /// Objects; hits carry their index as `object`.
    pub objects: Vec<SceneObject>,
    /// Lights.
    pub lights: Vec<Light>,
    /// For each light, the object that is its visible surface (area lights), which its own
    /// shadow rays ignore ([`Scene::occluded_from`]).
    pub light_objects: Vec<Option<u32>>,
    /// Everything intersectable, behind one BVH.
    pub geometry: SceneGeometry,
    /// The TOML text the scene was read from (what [`save::scene_toml`] edits).
    pub text: std::sync::Arc<str>,
    /// The folder relative file names in `text` resolve against (`None`: built-in data only).
    pub base_dir: Option<PathBuf>,
    /// What loading noticed but did not refuse (a USD file's prims that were not read), one
    /// message each, for the user to see.
    pub warnings: Vec<String>,
}

/// The scene the program shows when started without a file: a glass Utah teapot and a mirror
/// ring casting the coffee-cup caustic, on a table under a small lamp (the same text as
/// `scenes/builtin.toml`).
pub const BUILTIN_SCENE: &str = include_str!("../../scenes/builtin.toml");

impl Scene {
    /// The built-in default scene.
    pub fn builtin() -> Scene {
        load::load_str(BUILTIN_SCENE, std::path::Path::new("<built-in>"), None)
            .expect("the built-in scene is valid")
    }

    /// Reads and validates a scene file; relative paths inside resolve against its folder.
    pub fn load(path: &std::path::Path) -> Result<Scene, SceneError> {
        load::load_file(path)
    }

    /// Parses scene text; `path` names it in errors and `base_dir` resolves relative files
    /// (`None`: only built-in data may be referenced).
    pub fn from_str(
        text: &str,
        path: &std::path::Path,
        base_dir: Option<&std::path::Path>,
    ) -> Result<Scene, SceneError> {
        load::load_str(text, path, base_dir)
    }

    /// The material of a hit.
    pub fn material(&self, hit: &Hit) -> &Material {
        &self.materials[self.objects[hit.object as usize].material]
    }

    /// The colour (reflectance or tint) of a material at a hit, with its texture applied.
    pub fn albedo(&self, material: &Material, hit: &Hit) -> DVec3 {
        match material.texture {
            Some(t) => self.textures[t].lookup(hit.point, hit.uv()),
            None => material.color,
        }
    }

    /// The surface a ray of direction `dir` met at `hit`, as shading sees it: material, colour
    /// (texture applied), which side was hit, and the shading normal turned towards that side.
    pub fn surface(&self, hit: &Hit, dir: DVec3) -> Surface<'_> {
        let material = self.material(hit);
        let front = dir.dot(hit.normal) < 0.0;
        Surface {
            material,
            color: self.albedo(material, hit),
            front,
            normal: if front {
                hit.shading_normal
            } else {
                -hit.shading_normal
            },
        }
    }

    /// Emitted radiance seen by a ray of direction `dir` at `hit` (area lights only).
    pub fn emission(&self, hit: &Hit, dir: DVec3) -> DVec3 {
        match self.objects[hit.object as usize].emission {
            // Quads emit on their normal side only; spheres outward.
            Some(l) if dir.dot(hit.normal) < 0.0 => l,
            _ => DVec3::ZERO,
        }
    }

    /// Puts light `k` where `light` says (moved or turned; the same kind): an area light's
    /// visible surface moves with it, by a refit of the BVH (nothing is subdivided or rebuilt).
    /// Returns `false`, changing nothing, for an index out of range, another kind of light or
    /// a non-finite number.
    pub fn set_light(&mut self, k: usize, light: Light) -> bool {
        let Some(old) = self.lights.get(k) else {
            return false;
        };
        if !old.can_become(&light) {
            return false;
        }
        if let Some(object) = self.light_surface(k) {
            let moved = match light {
                Light::Sphere { center, radius, .. } => self
                    .geometry
                    .move_sphere(object, crate::geometry::Sphere { center, radius }),
                Light::Quad {
                    corner,
                    edge_u,
                    edge_v,
                    ..
                } => self.geometry.move_quad(
                    object,
                    crate::geometry::Quad {
                        corner,
                        edge_u,
                        edge_v,
                    },
                ),
                Light::Point { .. } | Light::Spot { .. } => true,
            };
            if !moved {
                return false;
            }
        }
        self.lights[k] = light;
        true
    }

    /// For each object, the light whose visible surface it is (what a path that meets an
    /// emitter weighs against sampling that light).
    pub fn light_of_objects(&self) -> Vec<Option<usize>> {
        let mut light_of = vec![None; self.objects.len()];
        for (k, object) in self.light_objects.iter().enumerate() {
            if let Some(o) = object {
                light_of[*o as usize] = Some(k);
            }
        }
        light_of
    }

    /// Whether something blocks the way from the surface point `point` (geometric normal
    /// `normal`) to the sample `ls` of light `light`: the shadow ray of
    /// [`light::LightSample::shadow_ray`], passing the light's own surface.
    pub fn occluded_from(&self, point: DVec3, normal: DVec3, light: usize, ls: &light::LightSample) -> bool {
        let (ray, reach) = ls.shadow_ray(point, normal);
        self.geometry
            .occluded_except(&ray, reach, self.light_surface(light))
    }

    /// [`Scene::occluded_from`] the point of `hit`: the shadow ray also carries where it leaves
    /// a Bézier patch ([`Hit::departure`]), so the patch's leaves around that point need not
    /// find the ray's own crossing again.
    pub fn occluded_from_hit(&self, hit: &Hit, light: usize, ls: &light::LightSample) -> bool {
        self.blocked_from_hit(hit, ls, self.light_surface(light))
    }

    /// Whether something lies between the point of `hit` and the point `distance` away along
    /// the unit direction `wi` (another surface's point, a lens point): the shadow ray of
    /// [`Scene::occluded_from_hit`], with no light's surface passed.
    pub fn occluded_between(&self, hit: &Hit, wi: DVec3, distance: f64) -> bool {
        let towards = light::LightSample {
            wi,
            distance,
            incident: DVec3::ZERO,
        };
        self.blocked_from_hit(hit, &towards, None)
    }

    /// Whether something but the object `skip` lies on the shadow ray from `hit` to `ls`.
    fn blocked_from_hit(&self, hit: &Hit, ls: &light::LightSample, skip: Option<u32>) -> bool {
        let (ray, reach) = ls.shadow_ray(hit.point, hit.normal);
        self.geometry
            .occluded_except(&ray.leaving(hit.departure(ls.wi)), reach, skip)
    }

    /// The object that is light `light`'s visible surface, which its own shadow rays pass
    /// (`None` for point and spot lights, or no such light).
    fn light_surface(&self, light: usize) -> Option<u32> {
        self.light_objects.get(light).copied().flatten()
    }

    /// What the scene contains, for skipping work it does not need.
    pub fn features(&self) -> SceneFeatures {
        SceneFeatures {
            patches: self.geometry.has_patches(),
            glass: self
                .materials
                .iter()
                .any(|m| matches!(m.kind, MaterialKind::Glass { .. })),
            textures: !self.textures.is_empty(),
            area_lights: self.lights.iter().any(Light::is_area),
            depth_of_field: self.camera.aperture > 0.0,
        }
    }

    /// A jitter-free pixel centre.
    pub fn pixel_center(x: u32, y: u32) -> DVec2 {
        DVec2::new(x as f64 + 0.5, y as f64 + 0.5)
    }
}

/// A hit surface as shading sees it ([`Scene::surface`]).
#[derive(Clone, Copy, Debug)]
pub struct Surface<'s> {
    /// Its material.
    pub material: &'s Material,
    /// Reflectance or tint at the hit, texture applied.
    pub color: DVec3,
    /// Whether the ray hit the side the geometric normal points to.
    pub front: bool,
    /// Unit shading normal on the side the ray came from.
    pub normal: DVec3,
}

/// What a scene contains.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SceneFeatures {
    /// Bézier patches.
    pub patches: bool,
    /// Refractive materials.
    pub glass: bool,
    /// Textures.
    pub textures: bool,
    /// Area lights.
    pub area_lights: bool,
    /// An open aperture.
    pub depth_of_field: bool,
}
