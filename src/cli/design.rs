//! `caustic design`: moves a surface's control points until the light it sends draws a target
//! image on a receiver, then writes the scene with only that surface changed, and the surface
//! as an OBJ free-form file beside it.

use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};

use caustic::args::Overwrite;
use caustic::design::landing::{surface_bounds, DesignParams, Handle, Receiver};
use caustic::design::optimize::{design, drawn, DesignSettings};
use caustic::design::photons::design_photons;
use caustic::design::refine::refined;
use caustic::design::target::load_target;
use caustic::files::write_atomically;
use caustic::geometry::freeform::write_freeform_obj;
use caustic::scene::light::Light;
use caustic::scene::material::MaterialKind;
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
    #[arg(long, default_value_t = 110.0)]
    seconds: f64,
    /// Steps of the descent: the same steps give the same surface on any machine and thread
    /// count.
    #[arg(long, default_value_t = 1500)]
    steps: usize,
    /// Photons traced at every step (eight times as many are prepared, used in turn).
    #[arg(long, default_value_t = 20_000)]
    photons: usize,
    /// How far a control point may move, in scene units (default: a tenth of the surface's
    /// size).
    #[arg(long)]
    max_height: Option<f64>,
    /// Weight of the smoothness term (0: none).
    #[arg(long, default_value_t = 0.01)]
    smoothness: f64,
    /// Split a surface of Bézier patches this many times first (each time into four patches a
    /// patch, the same surface with four times the control points); a surface with its own
    /// B-spline net is designed through that net's points instead.
    #[arg(long, default_value_t = 2)]
    refine: u32,
    /// Cells of the receiver grid along its longer edge.
    #[arg(long, default_value_t = 48)]
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

/// The object named `name`, or an error listing the names.
fn object_named(scene: &Scene, name: &str, flag: &str) -> Result<u32> {
    match scene.objects.iter().position(|o| o.name == name) {
        Some(k) => Ok(k as u32),
        None => {
            let names: Vec<&str> = scene.objects.iter().map(|o| o.name.as_str()).collect();
            bail!(
                "{flag}: the scene has no object named '{name}' (it has: {})",
                names.join(", ")
            )
        }
    }
}

/// Checks the flags' numbers.
fn check_numbers(args: &DesignArgs) -> Result<()> {
    if !(args.seconds.is_finite() && args.seconds > 0.0 && args.seconds <= 86_400.0) {
        bail!(
            "--seconds must be above 0 and at most a day, got {}",
            args.seconds
        );
    }
    if !(1..=1_000_000).contains(&args.steps) {
        bail!("--steps must be between 1 and 1,000,000, got {}", args.steps);
    }
    if !(100..=10_000_000).contains(&args.photons) {
        bail!(
            "--photons must be between 100 and 10,000,000, got {}",
            args.photons
        );
    }
    if args.refine > 4 {
        bail!("--refine must be between 0 and 4, got {}", args.refine);
    }
    if !(4..=512).contains(&args.grid) {
        bail!("--grid must be between 4 and 512, got {}", args.grid);
    }
    if !(args.smoothness.is_finite() && args.smoothness >= 0.0) {
        bail!(
            "--smoothness must be a number of 0 or more, got {}",
            args.smoothness
        );
    }
    if let Some(h) = args.max_height {
        if !(h.is_finite() && h > 0.0) {
            bail!("--max-height must be a positive number, got {h}");
        }
    }
    Ok(())
}

/// Checks that object `surface` (named `name`) is patches of smooth glass or mirror.
fn check_surface(scene: &Scene, surface: u32, name: &str) -> Result<()> {
    if !scene.geometry.patches().iter().any(|(_, id)| *id == surface) {
        bail!("--surface: '{name}' has no patches (it must be a `patches` object)");
    }
    let smooth_specular = match &scene.materials[scene.objects[surface as usize].material].kind {
        MaterialKind::Glass { roughness, .. } | MaterialKind::Mirror { roughness } => *roughness == 0.0,
        _ => false,
    };
    if !smooth_specular {
        bail!("--surface: '{name}' is not smooth glass or a smooth mirror: the light it sends has no shape to design");
    }
    Ok(())
}

/// A design ready to run: the scene (refined), what moves, the photons and the settings.
struct Prepared {
    scene: Scene,
    surface: u32,
    receiver: Receiver,
    params: DesignParams,
    photons: Vec<caustic::design::photons::DesignPhoton>,
    settings: DesignSettings,
    target_grid: Vec<f64>,
    surface_obj: PathBuf,
}

/// Reads and checks everything a design needs, before any work.
fn prepare(args: &DesignArgs) -> Result<Prepared> {
    check_numbers(args)?;
    let mut scene = Scene::load(&args.scene)?;
    let surface = object_named(&scene, &args.surface, "--surface")?;
    let receiver = object_named(&scene, &args.receiver, "--receiver")?;
    let Some(quad) = scene.geometry.quad_of(receiver) else {
        bail!("--receiver: '{}' is not a quad", args.receiver);
    };
    check_surface(&scene, surface, &args.surface)?;
    if let Some(refined) = refined(&scene, (surface, &args.surface), args.refine)
        .map_err(|e| anyhow::anyhow!("--refine: {e}"))?
    {
        scene = refined;
    }
    let target = load_target(&args.target).map_err(|e| anyhow::anyhow!("{}: {e}", args.target.display()))?;
    let stem = args
        .out
        .file_stem()
        .map_or("scene".into(), |s| s.to_string_lossy().into_owned());
    let surface_obj = args.out.with_file_name(surface_file_name(&stem, &args.surface));
    args.overwrite.check(
        [args.out.as_path(), surface_obj.as_path()]
            .into_iter()
            .chain(args.preview.as_deref()),
    )?;
    let bounds = surface_bounds(&scene, surface).expect("checked: the surface has patches");
    let (centre, size) = (
        (bounds.min + bounds.max) * 0.5,
        (bounds.max - bounds.min).length(),
    );
    let light = scene.lights.iter().find_map(|l| match l {
        Light::Point { position, .. } | Light::Spot { position, .. } => Some(*position),
        _ => None,
    });
    let Some(light) = light else {
        bail!("the scene has no point or spot light: a design traces photons from those");
    };
    let params = DesignParams::of_object(&scene, surface, centre - light)
        .map_err(|e| anyhow::anyhow!("--surface '{}': {e}", args.surface))?;
    let photons = design_photons(&scene, surface, 8 * args.photons).map_err(|e| anyhow::anyhow!("{e}"))?;
    let (eu, ev) = (quad.edge_u.length(), quad.edge_v.length());
    let grid = if eu >= ev {
        (args.grid, ((args.grid as f64 * ev / eu).round() as usize).max(4))
    } else {
        (((args.grid as f64 * eu / ev).round() as usize).max(4), args.grid)
    };
    let max_height = args.max_height.unwrap_or(0.1 * size);
    Ok(Prepared {
        target_grid: target.resampled(grid.0, grid.1),
        settings: DesignSettings {
            grid,
            sigma: 0.75,
            smoothness: args.smoothness,
            max_height,
            step: max_height / 40.0,
            subsets: 8,
            seconds: args.seconds,
            max_steps: args.steps,
            bounces: 16,
        },
        scene,
        surface,
        receiver: Receiver {
            object: receiver,
            quad,
        },
        params,
        photons,
        surface_obj,
    })
}

/// Runs `caustic design`.
pub fn design_command(args: DesignArgs) -> Result<()> {
    let mut p = prepare(&args)?;
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
    let outcome = design(
        &mut p.scene,
        (&p.params, &p.receiver),
        &p.photons,
        &p.target_grid,
        &p.settings,
        |s| {
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
        },
    );
    write_outputs(&args, &p, &loaded)?;
    let first = outcome.initial_loss;
    eprintln!(
        "loss {first:.5} → {:.5} ({:.1} % of the start) in {} steps; wrote {} and {}",
        outcome.final_loss,
        100.0 * outcome.final_loss / first,
        outcome.steps.len(),
        args.out.display(),
        p.surface_obj.display()
    );
    if args.json {
        let json = serde_json::json!({
            "scene": args.scene,
            "out": args.out,
            "surface_obj": p.surface_obj,
            "parameters": p.params.len(),
            "photons_per_step": p.photons.len() / p.settings.subsets,
            "grid": [grid.0, grid.1],
            "max_height": max_height,
            "initial_loss": first,
            "final_loss": outcome.final_loss,
            "steps": outcome.steps,
        });
        println!("{}", serde_json::to_string_pretty(&json)?);
    }
    Ok(())
}

/// Writes the designed scene (only the surface changed), the surface beside it (a net surface
/// is written by the scene's save itself) and the preview.
fn write_outputs(args: &DesignArgs, p: &Prepared, loaded: &[caustic::geometry::BezierPatch]) -> Result<()> {
    let force = args.overwrite.force;
    caustic::scene::save::save_scene(&p.scene, loaded, &args.out, force)
        .with_context(|| format!("cannot write {}", args.out.display()))?;
    if !p.params.handles.iter().any(|h| matches!(h, Handle::Net { .. })) {
        write_surface(&p.scene, p.surface, (&args.surface, &p.surface_obj), force)?;
    }
    if let Some(preview) = &args.preview {
        let picture = drawn(&p.scene, (&p.params, &p.receiver), &p.photons, &p.settings);
        write_preview(preview, p.settings.grid, &p.target_grid, &picture, force)?;
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
