//! Triangle meshes, loaded from Wavefront OBJ through `tobj`, intersected with Möller–Trumbore.

use std::path::{Path, PathBuf};

use glam::{DVec2, DVec3};

use super::aabb::Aabb;
use super::ray::Ray;

/// An indexed triangle mesh with optional per-vertex normals and texture coordinates.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TriangleMesh {
    /// Vertex positions.
    pub positions: Vec<DVec3>,
    /// Per-vertex normals, empty when the file has none.
    pub normals: Vec<DVec3>,
    /// Per-vertex texture coordinates, empty when the file has none.
    pub texcoords: Vec<DVec2>,
    /// Vertex indices, three per triangle.
    pub indices: Vec<[u32; 3]>,
}

/// What went wrong reading an OBJ file.
#[derive(Debug, thiserror::Error)]
pub enum MeshError {
    /// The OBJ parser rejected the file.
    #[error("{path}: cannot read OBJ mesh: {source}")]
    Parse {
        /// The file.
        path: PathBuf,
        /// The parser's error.
        source: tobj::LoadError,
    },
    /// The file parsed but its contents are unusable.
    #[error("{path}: {message}")]
    Invalid {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        message: String,
    },
}

/// Where a ray met a triangle: distance and barycentrics `(b1, b2)` of vertices 1 and 2.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TriangleHit {
    /// Distance along the ray.
    pub t: f64,
    /// Barycentric weights of the second and third vertex.
    pub barycentric: DVec2,
}

impl TriangleMesh {
    /// Loads every model of an OBJ file into one mesh (triangulated; materials ignored).
    pub fn load_obj(path: &Path) -> Result<Self, MeshError> {
        let file = crate::input_file::open(path).map_err(|why| MeshError::Invalid {
            path: path.to_owned(),
            message: format!("the file {why}"),
        })?;
        Self::parse_obj(&mut std::io::BufReader::new(file), path)
    }

    /// Reads OBJ text (every model into one mesh, triangulated; materials ignored); `path`
    /// names it in errors.
    pub fn parse_obj(reader: &mut impl std::io::BufRead, path: &Path) -> Result<Self, MeshError> {
        let options = tobj::LoadOptions {
            triangulate: true,
            single_index: true,
            ..Default::default()
        };
        // Material libraries are not read (materials come from the scene file).
        let no_materials = |_: &Path| Ok((Vec::new(), Default::default()));
        let (models, _materials) =
            tobj::load_obj_buf(reader, &options, no_materials).map_err(|source| MeshError::Parse {
                path: path.to_owned(),
                source,
            })?;
        let invalid = |message: String| MeshError::Invalid {
            path: path.to_owned(),
            message,
        };
        let mut mesh = TriangleMesh::default();
        for model in &models {
            let m = &model.mesh;
            let base = mesh.positions.len() as u32;
            let count = m.positions.len() / 3;
            for (k, p) in m.positions.chunks_exact(3).enumerate() {
                let v = DVec3::new(p[0] as f64, p[1] as f64, p[2] as f64);
                if !v.is_finite() {
                    return Err(invalid(format!(
                        "vertex {} of object '{}' is not finite: {v}",
                        k + 1,
                        model.name
                    )));
                }
                mesh.positions.push(v);
            }
            let has_normals = m.normals.len() == m.positions.len();
            let has_uv = m.texcoords.len() / 2 == count;
            for n in m.normals.chunks_exact(3).filter(|_| has_normals) {
                mesh.normals
                    .push(DVec3::new(n[0] as f64, n[1] as f64, n[2] as f64));
            }
            for t in m.texcoords.chunks_exact(2).filter(|_| has_uv) {
                mesh.texcoords.push(DVec2::new(t[0] as f64, t[1] as f64));
            }
            for tri in m.indices.chunks_exact(3) {
                if let Some(&bad) = tri.iter().find(|&&i| i as usize >= count) {
                    return Err(invalid(format!(
                        "object '{}' refers to vertex {} but has only {count}",
                        model.name,
                        bad + 1
                    )));
                }
                mesh.indices.push([base + tri[0], base + tri[1], base + tri[2]]);
            }
        }
        // Keep normals/uvs only if every object had them.
        if mesh.normals.len() != mesh.positions.len() {
            mesh.normals.clear();
        }
        if mesh.texcoords.len() != mesh.positions.len() {
            mesh.texcoords.clear();
        }
        if mesh.indices.is_empty() {
            return Err(invalid("the file holds no faces".to_owned()));
        }
        Ok(mesh)
    }

    /// The three corners of triangle `tri`.
    pub fn corners(&self, tri: usize) -> [DVec3; 3] {
        self.indices[tri].map(|i| self.positions[i as usize])
    }

    /// Bounds of triangle `tri`.
    pub fn triangle_bounds(&self, tri: usize) -> Aabb {
        Aabb::from_points(self.corners(tri))
    }

    /// Möller–Trumbore intersection of `ray` with triangle `tri` in `(t_min, t_max)`.
    pub fn intersect_triangle(&self, tri: usize, ray: &Ray, t_min: f64, t_max: f64) -> Option<TriangleHit> {
        let [p0, p1, p2] = self.corners(tri);
        let e1 = p1 - p0;
        let e2 = p2 - p0;
        let p = ray.dir.cross(e2);
        let det = e1.dot(p);
        if det == 0.0 || !det.is_finite() {
            return None;
        }
        let inv = 1.0 / det;
        let s = ray.origin - p0;
        let b1 = s.dot(p) * inv;
        if !(0.0..=1.0).contains(&b1) {
            return None;
        }
        let q = s.cross(e1);
        let b2 = ray.dir.dot(q) * inv;
        if b2 < 0.0 || b1 + b2 > 1.0 {
            return None;
        }
        let t = e2.dot(q) * inv;
        (t > t_min && t < t_max).then_some(TriangleHit {
            t,
            barycentric: DVec2::new(b1, b2),
        })
    }

    /// Geometric unit normal `(p1-p0) × (p2-p0)` of triangle `tri`.
    pub fn geometric_normal(&self, tri: usize) -> DVec3 {
        let [p0, p1, p2] = self.corners(tri);
        (p1 - p0).cross(p2 - p0).normalize_or_zero()
    }

    /// Interpolated shading normal, or the geometric one when the mesh has no normals.
    pub fn shading_normal(&self, tri: usize, b: DVec2) -> DVec3 {
        if self.normals.is_empty() {
            return self.geometric_normal(tri);
        }
        let [i0, i1, i2] = self.indices[tri].map(|i| i as usize);
        let n = (1.0 - b.x - b.y) * self.normals[i0] + b.x * self.normals[i1] + b.y * self.normals[i2];
        n.try_normalize().unwrap_or_else(|| self.geometric_normal(tri))
    }

    /// Interpolated texture coordinates, or the barycentrics when the mesh has none.
    pub fn uv(&self, tri: usize, b: DVec2) -> DVec2 {
        if self.texcoords.is_empty() {
            return b;
        }
        let [i0, i1, i2] = self.indices[tri].map(|i| i as usize);
        (1.0 - b.x - b.y) * self.texcoords[i0] + b.x * self.texcoords[i1] + b.y * self.texcoords[i2]
    }
}
