//! What a USD file adds beside a `patches` object's surfaces: each `Mesh` and `Sphere` prim
//! becomes an object of its own, named after the object and the prim, placed by the object's
//! `transform`, with a diffuse material of its `displayColor` (else the object's material).
//! They are added after the scene's own `[[objects]]`, so that those keep their numbers.

use glam::DVec3;

use super::diagnostics::{Result, Table};
use super::objects::{place_mesh, transform};
use crate::geometry::usd::{UsdContents, UsdShape};
use crate::geometry::{GeometryBuilder, Sphere, TriangleMesh};
use crate::scene::format::TransformDesc;
use crate::scene::material::{Material, MaterialKind};
use crate::scene::SceneObject;

/// One USD file's meshes and spheres, placed, waiting for the scene's own objects.
pub(super) struct UsdExtras {
    /// The object that read the file, and its material.
    owner: (String, usize),
    /// The table the file was named in (for the warning).
    label: String,
    meshes: Vec<UsdShape<TriangleMesh>>,
    spheres: Vec<UsdShape<Sphere>>,
    unread: Vec<String>,
}

impl UsdExtras {
    /// `usd`'s meshes and spheres placed by the object's transform `d`.
    pub(super) fn new(
        t: &Table,
        usd: UsdContents,
        (name, material): (&str, usize),
        d: Option<&TransformDesc>,
    ) -> Result<Self> {
        let (m, uniform) = transform(t, d)?;
        let mut meshes = usd.meshes;
        for mesh in &mut meshes {
            place_mesh(&mut mesh.shape, &m);
        }
        let mut spheres = usd.spheres;
        if !spheres.is_empty() {
            let Some(s) = uniform else {
                return Err(
                    t.err("the USD file holds Sphere prims: the object's 'transform.scale' must be uniform")
                );
            };
            for sphere in &mut spheres {
                sphere.shape = Sphere {
                    center: m.transform_point3(sphere.shape.center),
                    radius: sphere.shape.radius * s,
                };
            }
        }
        Ok(Self {
            owner: (name.to_owned(), material),
            label: t.name.clone(),
            meshes,
            spheres,
            unread: usd.unread,
        })
    }
}

/// Adds every file's meshes and spheres as objects (with a material for each display colour)
/// and returns one warning per file that held something not read.
pub(super) fn add_extras(
    extras: Vec<UsdExtras>,
    builder: &mut GeometryBuilder,
    materials: &mut Vec<Material>,
    objects: &mut Vec<SceneObject>,
) -> Vec<String> {
    let mut warnings = Vec::new();
    for extra in extras {
        let (owner, fallback) = extra.owner;
        let mut object = |prim: &str, color: Option<DVec3>| -> u32 {
            let name = format!("{owner} {prim}");
            let material = match color {
                Some(color) => {
                    materials.push(Material {
                        name: format!("{name} (displayColor)"),
                        kind: MaterialKind::Diffuse {
                            specular: 0.0,
                            shininess: 0.0,
                        },
                        color: color.min(DVec3::ONE),
                        texture: None,
                    });
                    materials.len() - 1
                }
                None => fallback,
            };
            objects.push(SceneObject {
                name,
                material,
                emission: None,
            });
            (objects.len() - 1) as u32
        };
        for mesh in extra.meshes {
            let id = object(&mesh.prim, mesh.color);
            builder.add_mesh(mesh.shape, id);
        }
        for sphere in extra.spheres {
            let id = object(&sphere.prim, sphere.color);
            builder.add_sphere(sphere.shape, id);
        }
        if !extra.unread.is_empty() {
            warnings.push(format!(
                "{}: not read from the USD file: {}",
                extra.label,
                extra.unread.join("; ")
            ));
        }
    }
    warnings
}
