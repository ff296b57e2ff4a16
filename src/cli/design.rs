//! `caustic design`: moves a surface's control points until the light it sends draws a target
//! image on a receiver, then writes the scene with only that surface changed, and the surface
//! as an OBJ free-form file beside it.

use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};

use caustic::args::Overwrite;
use caustic::design::landing::Handle;
use caustic::design::optimize::drawn;
use caustic::design::setup::{prepare_design, DesignOptions, PreparedDesign};
use caustic::design::target::{correlation, load_target};
use caustic::files::write_atomically;
use caustic::geometry::freeform::write_freeform_obj;
use caustic::scene::save::surface_file_name;
use caustic::scene::Scene;

/// `caustic design`'s flags.
#[derive(clap::Args)]
pub struct DesignArgs {
    /// Scene file (TOML).
    scene: PathBuf,
    /// The `patches` object to shape (glass or mirror).
    #[arg(long)]
    surface: String,
    /// The `quad` object the light should draw the target on.
    #[arg(long)]
    receiver: String,
    /// The picture to draw (PNG, JPEG, EXR or PFM; taken as luminance). Its top-left pixel lies
    /// at the receiver's `corner + edge_v`, x along `edge_u`, rows towards `corner`.
    #[arg(long)]
    target: PathBuf,
    /// Where to write the designed scene (TOML); the surface is also written beside it as
    /// `STEM.SURFACE.obj`.
    #[arg(long)]
    out: PathBuf,
    /// Stop after this many seconds, even before the last step (the steps' length decays over
    /// `--steps`, so a design cut short is coarser).
    #[arg(long, default_value_t = DesignOptions::default().seconds)]
    seconds: f64,
    /// Steps of the descent: the same steps give the same surface on any machine and thread
    /// count.
    #[arg(long, default_value_t = DesignOptions::default().steps)]
    steps: usize,
    /// Photons traced at every step (eight times as many are prepared, used in turn).
    #[arg(long, default_value_t = DesignOptions::default().photons)]
    photons: usize,
    /// How far a control point may move, in scene units (default: a tenth of the surface's
    /// size).
    #[arg(long)]
    max_height: Option<f64>,
    /// Weight of the smoothness term (0: none).
    #[arg(long, default_value_t = DesignOptions::default().smoothness)]
    smoothness: f64,
    /// Split a surface of Bézier patches this many times first (each time into four patches a
    /// patch, the same surface with four times the control points); a surface with its own
    /// B-spline net is designed through that net's points instead.
    #[arg(long, default_value_t = DesignOptions::default().refine)]
    refine: u32,
    /// Cells of the receiver grid along its longer edge.
    #[arg(long, default_value_t = DesignOptions::default().grid)]
    grid: usize,
    /// Also write the target beside the picture the design's photons draw (a grey PNG, each
    /// half scaled to its brightest cell).
    #[arg(long, value_name = "FILE.png")]
    preview: Option<PathBuf>,
    /// Print the loss curve as JSON on stdout (progress stays on stderr).
    #[arg(long)]
    json: bool,
    #[command(flatten)]
    overwrite: Overwrite,
}

impl DesignArgs {
    /// The options as the library takes them.
    fn options(&self) -> DesignOptions {
        DesignOptions {
            seconds: self.seconds,
            steps: self.steps,
            photons: self.photons,
            max_height: self.max_height,
            smoothness: self.smoothness,
            refine: self.refine,
            grid: self.grid,
        }
    }
}

/// A design ready to run, and where its surface is written.
struct Prepared {
    design: PreparedDesign,
    surface_obj: PathBuf,
}

/// Reads and checks everything a design needs, and that its outputs may be written, before
/// any work.
fn prepare(args: &DesignArgs) -> Result<Prepared> {
    let options = args.options();
    options.check().map_err(anyhow::Error::msg)?;
    let scene = Scene::load(&args.scene)?;
    let stem = args
        .out
        .file_stem()
        .map_or("scene".into(), |s| s.to_string_lossy().into_owned());
    let surface_obj = args.out.with_file_name(surface_file_name(&stem, &args.surface));
    let folder = match args.out.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    if !folder.is_dir() {
        bail!(
            "--out: the folder {} does not exist (nothing was designed or written)",
            folder.display()
        );
    }
    args.overwrite.check(
        [args.out.as_path(), surface_obj.as_path()]
            .into_iter()
            .chain(args.preview.as_deref()),
    )?;
    let target = load_target(&args.target).map_err(|e| anyhow::anyhow!("{}: {e}", args.target.display()))?;
    let design = prepare_design(scene, (&args.surface, &args.receiver), &target, &options)
        .map_err(anyhow::Error::msg)?;
    Ok(Prepared { design, surface_obj })
}

/// Runs `caustic design`.
pub fn design_command(args: DesignArgs) -> Result<()> {
    let Prepared {
        design: mut p,
        surface_obj,
    } = prepare(&args)?;
    let loaded: Vec<_> = p.scene.geometry.patches().iter().map(|(q, _)| *q).collect();
    let (grid, max_height) = (p.settings.grid, p.settings.max_height);
    eprintln!(
        "designing '{}' ({} control points, moving up to {max_height:.4} along the light's direction) for '{}' on a {}×{} grid with {} photons a step",
        args.surface,
        p.params.len(),
        args.receiver,
        grid.0,
        grid.1,
        p.photons.len() / p.settings.subsets
    );
    let mut last_print = -1.0;
    let outcome = p.run(|s, _| {
        if s.elapsed - last_print >= 1.0 || s.step == 0 {
            last_print = s.elapsed;
            eprintln!(
                "step {:>5}  loss {:.5}  landed {:>5.1} %  {:.1} s",
                s.step,
                s.loss,
                100.0 * s.landed,
                s.elapsed
            );
        }
        std::ops::ControlFlow::Continue(())
    });
    let picture = drawn(&p.scene, (&p.params, &p.receiver), &p.photons, &p.settings);
    write_outputs(&args, (&p, &surface_obj), (&loaded, &picture))?;
    let first = outcome.initial_loss;
    let correlation = correlation(&picture, &p.target_grid);
    eprintln!(
        "loss {first:.5} → {:.5} ({:.1} % of the start) in {} steps, correlation with the target {correlation:.3}; wrote {} and {}",
        outcome.final_loss,
        100.0 * outcome.final_loss / first,
        outcome.steps.len(),
        args.out.display(),
        surface_obj.display()
    );
    if args.json {
        let json = serde_json::json!({
            "scene": args.scene,
            "out": args.out,
            "surface_obj": surface_obj,
            "parameters": p.params.len(),
            "photons_per_step": p.photons.len() / p.settings.subsets,
            "grid": [grid.0, grid.1],
            "max_height": max_height,
            "initial_loss": first,
            "final_loss": outcome.final_loss,
            "correlation": correlation,
            "steps": outcome.steps,
        });
        println!("{}", serde_json::to_string_pretty(&json)?);
    }
    Ok(())
}

/// Writes the designed scene (only the surface changed), the surface beside it (a net surface
/// is written by the scene's save itself) and the preview (the target beside `picture`, what
/// the design's photons draw).
fn write_outputs(
    args: &DesignArgs,
    (p, surface_obj): (&PreparedDesign, &Path),
    (loaded, picture): (&[caustic::geometry::BezierPatch], &[f64]),
) -> Result<()> {
    let force = args.overwrite.force;
    caustic::scene::save::save_scene(&p.scene, loaded, &args.out, force)
        .with_context(|| format!("cannot write {}", args.out.display()))?;
    if !p.params.handles.iter().any(|h| matches!(h, Handle::Net { .. })) {
        write_surface(&p.scene, p.surface, (&args.surface, surface_obj), force)?;
    }
    if let Some(preview) = &args.preview {
        write_preview(preview, p.settings.grid, &p.target_grid, picture, force)?;
    }
    Ok(())
}

/// Writes object `surface`'s patches as OBJ free-form surfaces to `path`.
fn write_surface(scene: &Scene, surface: u32, (name, path): (&str, &Path), force: bool) -> Result<()> {
    let patches: Vec<_> = (0..scene.geometry.patches().len())
        .filter(|&k| scene.geometry.patches()[k].1 == surface)
        .map(|k| scene.geometry.domain_patch(k))
        .collect();
    let group = name.replace(char::is_whitespace, "_");
    super::export::write_obj_file(path, force, |file| write_freeform_obj(&[(group, patches)], file))
        .with_context(|| format!("cannot write {}", path.display()))
}

/// Writes the target and the picture the design's photons draw side by side, as a grey PNG
/// (each scaled to its brightest cell).
fn write_preview(
    path: &Path,
    (nx, ny): (usize, usize),
    target: &[f64],
    drawn: &[f64],
    force: bool,
) -> Result<()> {
    let peak = |v: &[f64]| v.iter().copied().fold(0.0f64, f64::max).max(1e-300);
    let (pt, pd) = (peak(target), peak(drawn));
    let mut pixels = vec![0u8; 2 * nx * ny];
    for y in 0..ny {
        for x in 0..nx {
            pixels[y * 2 * nx + x] = (255.0 * (target[y * nx + x] / pt).sqrt()) as u8;
            pixels[y * 2 * nx + nx + x] = (255.0 * (drawn[y * nx + x] / pd).sqrt()) as u8;
        }
    }
    let write = |tmp: &Path| -> Result<(), String> {
        image::save_buffer_with_format(
            tmp,
            &pixels,
            (2 * nx) as u32,
            ny as u32,
            image::ColorType::L8,
            image::ImageFormat::Png,
        )
        .map_err(|e| e.to_string())
    };
    write_atomically(path, force, write).with_context(|| format!("cannot write {}", path.display()))
}
