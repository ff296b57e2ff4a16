//! `caustic bench tessellation`: what exact patches buy. The scene is ray traced (Whitted:
//! deterministic, so every difference is geometry, not noise) with its patches intersected
//! exactly (prepared sub-patches + Newton), with the seed report's per-ray subdivision, and
//! with every patch tessellated into a triangle mesh at several resolutions; each render's
//! time and its RMSE against the exact one are printed, and written as CSV and a log-log plot
//! of error against time on request.

use std::fmt::Write as _;
use std::path::PathBuf;
use std::time::Instant;

use anyhow::{bail, Context, Result};

use super::output::BenchOutput;
use super::plot::{draw_series, write_png, Frame, Series};
use crate::args::{CurveFiles, Threads};
use crate::files::write_atomically;
use crate::geometry::{PatchMethod, SubdivisionParams};
use crate::render::error::errors;
use crate::render::render_whitted;
use crate::run::load_scene;
use crate::scene::Scene;

/// `bench tessellation`'s flags.
#[derive(clap::Args)]
pub struct TessellationArgs {
    /// Scene file; the built-in teapot scene when omitted. It must have Bézier patches.
    scene: Option<PathBuf>,
    /// Image width (height follows the scene's aspect).
    #[arg(long, default_value_t = 640)]
    width: u32,
    /// Segments per patch edge to tessellate with (each patch becomes 2·n² triangles).
    #[arg(long, value_delimiter = ',', default_value = "4,8,16,32,64")]
    segments: Vec<usize>,
    /// Subdivision depth of the per-ray (seed report) intersector.
    #[arg(long, default_value_t = 5)]
    per_ray_depth: u32,
    /// Rows (method, segments, triangles, seconds, RMSE) and the plot of RMSE against seconds.
    #[command(flatten)]
    files: CurveFiles,
    /// `--threads`: the worker pool's size.
    #[command(flatten)]
    pub threads: Threads,
}

/// One render of the comparison.
struct Row {
    method: String,
    segments: Option<usize>,
    triangles: usize,
    prepare_secs: f64,
    render_secs: f64,
    rmse: f64,
}

/// Renders the scene with each intersector and prints the table.
pub fn bench_tessellation(args: TessellationArgs, out: &mut BenchOutput) -> Result<()> {
    let mut scene = load_scene(args.scene.as_deref())?;
    if !scene.geometry.has_patches() {
        bail!(
            "{}: the scene has no Bézier patches to tessellate",
            scene.source.display()
        );
    }
    if let Some(&bad) = args.segments.iter().find(|&&n| !(1..=256).contains(&n)) {
        bail!("--segments must be between 1 and 256, got {bad}");
    }
    if !(1..=30).contains(&args.per_ray_depth) {
        bail!(
            "--per-ray-depth must be between 1 and 30, got {}",
            args.per_ray_depth
        );
    }
    args.files.check()?;
    crate::settings::limits::image_side(args.width).map_err(|e| anyhow::anyhow!("--width {e}"))?;
    scene.camera.resize(Some(args.width), None);
    let (w, h) = (scene.camera.width, scene.camera.height);
    let patches = scene.geometry.patches().len();
    out.say(format!(
        "Exact patches against tessellation on {}, {w}x{h}, {patches} patches, ray traced",
        scene.source.display()
    ));
    out.set("scene", scene.source.display().to_string());
    out.set("size", [w, h]);
    out.set("patches", patches);

    let rows = measure(&scene, &args, out);
    if let Some(path) = &args.files.csv {
        write_rows(&rows, path, args.files.overwrite.force, out)?;
    }
    if let Some(path) = &args.files.plot {
        write_rows_plot(&scene, &rows, path, args.files.overwrite.force, out)?;
    }
    Ok(())
}

/// Renders the scene with each geometry (exact, per-ray, tessellated) and measures it
/// against the first.
fn measure(scene: &Scene, args: &TessellationArgs, out: &mut BenchOutput) -> Vec<Row> {
    let patches = scene.geometry.patches().len();
    let exact_method = PatchMethod::Prepared(SubdivisionParams::default());
    let mut methods = vec![
        ("exact (prepared)".to_owned(), exact_method, None),
        (
            format!("exact (per-ray, depth {})", args.per_ray_depth),
            PatchMethod::PerRay {
                depth: args.per_ray_depth,
            },
            None,
        ),
    ];
    for &n in &args.segments {
        methods.push((format!("tessellated {n}x{n}"), exact_method, Some(n)));
    }
    let mut reference: Option<Vec<[f32; 3]>> = None;
    let mut rows = Vec::new();
    out.say(format!(
        "{:<26} {:>10} {:>11} {:>10} {:>12}",
        "geometry", "triangles", "prepare ms", "render s", "RMSE vs exact"
    ));
    for (method, patch_method, segments) in methods {
        eprintln!("  {method}...");
        let start = Instant::now();
        let mut variant: Scene = scene.clone();
        variant.geometry = scene.geometry.rebuilt(patch_method, segments);
        let prepare_secs = start.elapsed().as_secs_f64();
        let (image, stats) = render_whitted(&variant, &|_| {});
        let rmse = match &reference {
            Some(r) => errors(&image.pixels, r).0,
            None => 0.0,
        };
        reference.get_or_insert(image.pixels);
        let row = Row {
            method,
            segments,
            triangles: segments.map_or(0, |n| 2 * n * n * patches),
            prepare_secs,
            render_secs: stats.elapsed_secs,
            rmse,
        };
        out.say(format!(
            "{:<26} {:>10} {:>11.1} {:>10.3} {:>12.4e}",
            row.method,
            row.triangles,
            row.prepare_secs * 1e3,
            row.render_secs,
            row.rmse
        ));
        out.push(
            "renders",
            serde_json::json!({
                "geometry": row.method,
                "segments": row.segments,
                "triangles": row.triangles,
                "prepare_seconds": row.prepare_secs,
                "render_seconds": row.render_secs,
                "rmse": row.rmse,
            }),
        );
        rows.push(row);
    }
    rows
}

/// Writes the rows as CSV.
fn write_rows(rows: &[Row], path: &std::path::Path, force: bool, out: &mut BenchOutput) -> Result<()> {
    let mut text = String::from("geometry,segments,triangles,prepare_seconds,render_seconds,rmse\n");
    for r in rows {
        let segments = r.segments.map_or(String::new(), |n| n.to_string());
        let _ = writeln!(
            text,
            "{},{segments},{},{:.6},{:.6},{:.6e}",
            super::csv_field(&r.method),
            r.triangles,
            r.prepare_secs,
            r.render_secs,
            r.rmse
        );
    }
    write_atomically(path, force, |t| {
        std::fs::write(t, &text).map_err(|e| e.to_string())
    })?;
    out.say(format!("rows written to {}", path.display()));
    Ok(())
}

/// Draws the tessellated renders' error against their time, the exact ones as markers.
fn write_rows_plot(
    scene: &Scene,
    rows: &[Row],
    path: &std::path::Path,
    force: bool,
    out: &mut BenchOutput,
) -> Result<()> {
    let (w, h) = (scene.camera.width, scene.camera.height);
    let name = scene
        .source
        .file_name()
        .map_or("scene".into(), |n| n.to_string_lossy())
        .replace("<built-in>", "built-in teapot scene");
    let title = format!("{name}: tessellation error against render time ({w}x{h}, ray traced)");
    let pixels = draw_series(
        &[tessellated_series(rows)],
        &Frame {
            title: &title,
            x: "render seconds",
            y: "RMSE against the exact render",
            markers: rows
                .iter()
                .filter(|r| r.segments.is_none())
                .map(|r| (marker_label(r), r.render_secs))
                .collect(),
            legend_lower_left: false,
        },
    )
    .map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?;
    write_png(&pixels, path, force).context("cannot write the plot")?;
    out.say(format!("plot written to {}", path.display()));
    Ok(())
}

/// An exact render's legend entry: its time and its RMSE against the prepared exact render
/// (0 for that one itself; the per-ray intersector's Newton tolerance leaves a small one).
fn marker_label(r: &Row) -> String {
    if r.rmse == 0.0 {
        format!("{}: {:.2} s, the reference", r.method, r.render_secs)
    } else {
        format!("{}: {:.2} s, RMSE {:.1e}", r.method, r.render_secs, r.rmse)
    }
}

/// The tessellated renders as one line: render time against error, each point labelled with
/// its segments per edge.
fn tessellated_series(rows: &[Row]) -> Series {
    let tessellated: Vec<&Row> = rows.iter().filter(|r| r.segments.is_some()).collect();
    Series {
        name: "tessellated (segments per patch edge)".into(),
        points: tessellated.iter().map(|r| (r.render_secs, r.rmse)).collect(),
        point_labels: tessellated
            .iter()
            .map(|r| r.segments.map_or(String::new(), |n| n.to_string()))
            .collect(),
    }
}
