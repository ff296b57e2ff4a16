//! `caustic export-obj`: a scene's Bézier patches, tessellated, as a Wavefront OBJ file.

use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};

use super::load_scene;
use caustic::files::write_atomically;
use caustic::geometry::tessellate::{tessellate, write_obj};

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
    /// Replace the output file if it exists.
    #[arg(long)]
    force: bool,
}

/// Writes the scene's patches, tessellated, as an OBJ file.
pub fn export_obj(args: ExportArgs) -> Result<()> {
    let ExportArgs {
        scene: scene_path,
        out,
        resolution,
        force,
    } = args;
    let out = out.as_path();
    if !(1..=256).contains(&resolution) {
        bail!("--resolution must be between 1 and 256, got {resolution}");
    }
    if out.exists() && !force {
        bail!(
            "{}: the file exists; choose another name or pass --force to overwrite it",
            out.display()
        );
    }
    let scene = load_scene(scene_path.as_deref())?;
    let meshes: Vec<(String, caustic::geometry::TriangleMesh)> = scene
        .geometry
        .patches()
        .iter()
        .enumerate()
        .map(|(k, (p, obj))| {
            let name = format!("{}_patch{k}", scene.objects[*obj as usize].name.replace(' ', "_"));
            (name, tessellate(p, resolution))
        })
        .collect();
    if meshes.is_empty() {
        bail!(
            "{}: the scene has no Bézier patches to export",
            scene.source.display()
        );
    }
    let write = |tmp: &Path| -> Result<(), String> {
        let mut file = std::io::BufWriter::new(std::fs::File::create(tmp).map_err(|e| e.to_string())?);
        write_obj(&meshes, &mut file).map_err(|e| e.to_string())?;
        std::io::Write::flush(&mut file).map_err(|e| e.to_string())
    };
    write_atomically(out, force, write).context("cannot write the OBJ file")?;
    let triangles: usize = meshes.iter().map(|(_, m)| m.indices.len()).sum();
    println!(
        "{}: {} patches, {triangles} triangles",
        out.display(),
        meshes.len()
    );
    Ok(())
}
