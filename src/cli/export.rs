//! `caustic export-obj`: a scene's Bézier patches as a Wavefront OBJ file, tessellated into
//! triangles, or exactly as `cstype bezier` free-form surfaces (`--freeform`).

use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};

use caustic::args::Overwrite;
use caustic::files::write_atomically;
use caustic::geometry::freeform::{write_freeform_obj, DomainPatch};
use caustic::geometry::tessellate::{tessellate_weighted, write_obj};
use caustic::geometry::trimmed::trim_mesh;
use caustic::run::load_scene;

/// `caustic export-obj`'s flags.
#[derive(clap::Args)]
pub struct ExportArgs {
    /// Scene file (TOML); the built-in scene when omitted.
    scene: Option<PathBuf>,
    /// Output .obj file.
    #[arg(short, long)]
    out: PathBuf,
    /// Quads per patch side.
    #[arg(long, default_value_t = 16)]
    resolution: usize,
    /// Write the patches exactly, as OBJ free-form `cstype bezier` surfaces (each with its
    /// (u,v) window), instead of triangles: reading the file back gives the same control points.
    #[arg(long, conflicts_with = "resolution")]
    freeform: bool,
    #[command(flatten)]
    overwrite: Overwrite,
}

/// Writes the scene's patches, tessellated, as an OBJ file.
pub fn export_obj(args: ExportArgs) -> Result<()> {
    let ExportArgs {
        scene: scene_path,
        out,
        resolution,
        freeform,
        overwrite,
    } = args;
    let force = overwrite.force;
    let out = out.as_path();
    if !(1..=256).contains(&resolution) {
        bail!("--resolution must be between 1 and 256, got {resolution}");
    }
    overwrite.check([out])?;
    let scene = load_scene(scene_path.as_deref())?;
    if !scene.geometry.has_patches() {
        bail!(
            "{}: the scene has no Bézier patches to export",
            scene.source.display()
        );
    }
    if freeform {
        return export_freeform(&scene, out, force);
    }
    let meshes: Vec<(String, caustic::geometry::TriangleMesh)> = scene
        .geometry
        .patches()
        .iter()
        .enumerate()
        .map(|(k, (p, obj))| {
            let name = format!("{}_patch{k}", group_name(&scene, *obj));
            let mut mesh = tessellate_weighted(p, scene.geometry.patch_weights(k), resolution);
            if let Some(trim) = scene.geometry.patch_trim(k) {
                trim_mesh(&mut mesh, trim, &scene.geometry.patch_domains()[k]);
            }
            (name, mesh)
        })
        .collect();
    write_obj_file(out, force, |file| write_obj(&meshes, file))?;
    let triangles: usize = meshes.iter().map(|(_, m)| m.indices.len()).sum();
    println!(
        "{}: {} patches, {triangles} triangles",
        out.display(),
        meshes.len()
    );
    Ok(())
}

/// Writes `out` through a buffer filled by `fill` (temporary name, then rename; an existing
/// file only replaced when `force`).
pub(super) fn write_obj_file(
    out: &Path,
    force: bool,
    fill: impl FnOnce(&mut std::io::BufWriter<std::fs::File>) -> std::io::Result<()>,
) -> Result<()> {
    let write = |tmp: &Path| -> Result<(), String> {
        let mut file = std::io::BufWriter::new(std::fs::File::create(tmp).map_err(|e| e.to_string())?);
        fill(&mut file).map_err(|e| e.to_string())?;
        std::io::Write::flush(&mut file).map_err(|e| e.to_string())
    };
    write_atomically(out, force, write).context("cannot write the OBJ file")
}

/// The object name of each patch, as an OBJ group name (no spaces).
fn group_name(scene: &caustic::scene::Scene, object: u32) -> String {
    scene.objects[object as usize]
        .name
        .replace(char::is_whitespace, "_")
}

/// Writes the scene's patches, as the scene file holds them (edits saved into it included), as
/// free-form surfaces, one OBJ group per object.
fn export_freeform(scene: &caustic::scene::Scene, out: &Path, force: bool) -> Result<()> {
    let mut groups: Vec<(String, Vec<DomainPatch>)> = Vec::new();
    let patches = scene.geometry.patches();
    for (k, (_, object)) in patches.iter().enumerate() {
        let name = group_name(scene, *object);
        let patch = scene.geometry.domain_patch(k);
        match groups.last_mut() {
            Some((last, list)) if *last == name => list.push(patch),
            _ => groups.push((name, vec![patch])),
        }
    }
    write_obj_file(out, force, |file| write_freeform_obj(&groups, file))?;
    println!(
        "{}: {} patches as free-form Bézier surfaces",
        out.display(),
        patches.len()
    );
    Ok(())
}
