//! Tessellation of Bézier patches into triangle meshes, for `caustic export-obj` and
//! comparisons with tessellating renderers.

use glam::{DVec2, DVec3};

use super::bezier::BezierPatch;
use super::mesh::TriangleMesh;
use super::rational::{RationalPatch, Weights};

/// A `resolution × resolution` grid of quads (two triangles each) over the patch, with exact
/// normals and the patch's `(u,v)` as texture coordinates.
pub fn tessellate(patch: &BezierPatch, resolution: usize) -> TriangleMesh {
    tessellate_weighted(patch, None, resolution)
}

/// [`tessellate`] for a patch that may be rational (`weights`, positive).
pub fn tessellate_weighted(
    patch: &BezierPatch,
    weights: Option<&Weights>,
    resolution: usize,
) -> TriangleMesh {
    let n = resolution.max(1);
    let rational = weights.map(|w| RationalPatch::new(patch, w));
    let scale = patch.bounds().diagonal().length();
    let mut mesh = TriangleMesh::default();
    for i in 0..=n {
        for j in 0..=n {
            let (u, v) = (i as f64 / n as f64, j as f64 / n as f64);
            let (position, normal) = match &rational {
                None => (patch.eval(u, v), patch.normal(u, v)),
                Some(r) => (r.eval(u, v), r.normal_at_scale(u, v, scale)),
            };
            mesh.positions.push(position);
            mesh.normals.push(normal.unwrap_or(DVec3::Z));
            mesh.texcoords.push(DVec2::new(u, v));
        }
    }
    let idx = |i: usize, j: usize| (i * (n + 1) + j) as u32;
    for i in 0..n {
        for j in 0..n {
            // Winding follows ∂P/∂u × ∂P/∂v, the patch's normal.
            mesh.indices.push([idx(i, j), idx(i + 1, j), idx(i + 1, j + 1)]);
            mesh.indices.push([idx(i, j), idx(i + 1, j + 1), idx(i, j + 1)]);
        }
    }
    mesh
}

/// Writes meshes as one Wavefront OBJ text, each as a named object, with normals and texture
/// coordinates where the mesh has them.
pub fn write_obj(meshes: &[(String, TriangleMesh)], out: &mut impl std::io::Write) -> std::io::Result<()> {
    writeln!(out, "# written by caustic {}", env!("CARGO_PKG_VERSION"))?;
    let mut base = 1usize;
    for (name, mesh) in meshes {
        writeln!(out, "o {name}")?;
        for p in &mesh.positions {
            writeln!(out, "v {} {} {}", p.x, p.y, p.z)?;
        }
        for t in &mesh.texcoords {
            writeln!(out, "vt {} {}", t.x, t.y)?;
        }
        for n in &mesh.normals {
            writeln!(out, "vn {} {} {}", n.x, n.y, n.z)?;
        }
        let (has_t, has_n) = (!mesh.texcoords.is_empty(), !mesh.normals.is_empty());
        for tri in &mesh.indices {
            let corner = |i: u32| {
                let k = base + i as usize;
                match (has_t, has_n) {
                    (true, true) => format!("{k}/{k}/{k}"),
                    (true, false) => format!("{k}/{k}"),
                    (false, true) => format!("{k}//{k}"),
                    (false, false) => format!("{k}"),
                }
            };
            writeln!(out, "f {} {} {}", corner(tri[0]), corner(tri[1]), corner(tri[2]))?;
        }
        base += mesh.positions.len();
    }
    Ok(())
}
