//! `caustic bench edit`: how soon an edit shows converged. One control point is moved by a
//! few per cent of its patch's size (or, with `--light`, a light by a few per cent of the
//! scene's size across the view) while the viewer's kind of session renders; the time from
//! the edit to relative MSE 1e-2 against a (cached) reference of the edited scene is measured
//! with the new epoch started warm and cold, runs interleaved, medians printed.

use std::path::PathBuf;
use std::time::Duration;

use anyhow::{bail, Result};
use clap::Parser;
use glam::DVec3;

use super::edit_run::{EditPlan, WarmCold, ON_SCREEN_AFTER};
use super::output::BenchOutput;
use crate::args::Threads;
use crate::render::session::Command;
use crate::scene::{RendererKind, Scene};

/// `caustic bench edit`.
#[derive(Parser)]
pub struct EditArgs {
    /// Scene file with Bézier patches (default: scenes/inline_patch.toml, built in).
    pub scene: Option<PathBuf>,
    /// The patch whose control point moves.
    #[arg(long, default_value_t = 0)]
    patch: usize,
    /// The control point that moves (4i + j; default an inner one).
    #[arg(long, default_value_t = 5)]
    point: usize,
    /// Move this light instead of a control point (its index in the scene's `[[lights]]`,
    /// from 0): along the camera's right, by `--distance` of the scene's bounding-box
    /// diagonal.
    #[arg(long, value_name = "K")]
    light: Option<usize>,
    /// How far it moves, as a share of the patch's bounding-box diagonal, along the surface's
    /// normal there (with `--light`, of the scene's diagonal, across the view).
    #[arg(long, default_value_t = 0.03)]
    distance: f64,
    /// Passes rendered before the edit (the image a person was looking at).
    #[arg(long, default_value_t = 16)]
    before_passes: u32,
    /// Runs of each kind of restart (warm and cold, interleaved; the medians are printed).
    #[arg(long, default_value_t = 5)]
    runs: u32,
    /// The relative MSE to reach.
    #[arg(long, default_value_t = 1e-2)]
    target: f64,
    /// Give up on a run after this many seconds.
    #[arg(long, default_value_t = 60.0)]
    limit: f64,
    /// Passes of the edited scene's reference render (cached, as `bench convergence`'s).
    #[arg(long, default_value_t = 400)]
    reference_passes: u32,
    /// Where reference renders are cached (default: ~/.cache/caustic/references).
    #[arg(long, value_name = "DIR")]
    reference_dir: Option<PathBuf>,
    /// `--threads`: the worker pool's size.
    #[command(flatten)]
    pub threads: Threads,
}

/// Runs the measurement.
pub fn bench_edit(args: EditArgs, out: &mut BenchOutput) -> Result<()> {
    if args.runs == 0 || args.before_passes == 0 {
        bail!("--runs and --before-passes must be at least 1");
    }
    if !(args.target > 0.0 && args.limit > 0.0 && args.distance.is_finite()) {
        bail!("--target and --limit must be positive, --distance finite");
    }
    let mut scene = crate::run::scene_or_built_in(
        args.scene.as_deref(),
        crate::assets::INLINE_PATCH_SCENE,
        "inline_patch",
    )?;
    scene.params.renderer = RendererKind::Ppm;
    let (edit, what) = match args.light {
        Some(k) => light_edit(&scene, k, args.distance)?,
        None => point_edit(&scene, &args)?,
    };
    let mut edited = scene.clone();
    crate::render::session::command::apply_to_scene(&mut edited, vec![edit.clone()]);
    let reference = super::convergence::reference(
        &edited,
        args.reference_passes,
        args.reference_dir.as_deref(),
        Some(what.clone()),
        out,
    )?;
    out.say(format!(
        "Edit of {}: {what} ({} % of the {}'s size); {} passes before the edit, {}x{}",
        scene.source.display(),
        100.0 * args.distance,
        if args.light.is_some() { "scene" } else { "patch" },
        args.before_passes,
        scene.camera.width,
        scene.camera.height
    ));
    let plan = EditPlan {
        edit,
        before_passes: args.before_passes,
        warm: true,
        target: args.target,
        limit: Duration::from_secs_f64(args.limit),
    };
    let runs = WarmCold::measure(&scene, &plan, args.runs, &reference, |run, warm, r| {
        eprintln!(
            "  run {} {}: {}",
            run + 1,
            if warm { "warm" } else { "cold" },
            r.to_target.map_or("not reached".into(), |t| format!("{t:.3} s"))
        );
    })
    .map_err(|e| anyhow::anyhow!(e))?;
    report(&runs, args.target, out);
    Ok(())
}

/// The moved point: `--distance` of the patch's diagonal along the surface normal at it; the
/// command and what it did, in words.
fn point_edit(scene: &Scene, args: &EditArgs) -> Result<(Command, String)> {
    let patches = scene.geometry.patches();
    let Some((patch, _)) = patches.get(args.patch) else {
        bail!(
            "--patch {}: {} has {} patches",
            args.patch,
            scene.source.display(),
            patches.len()
        );
    };
    if args.point >= 16 {
        bail!(
            "--point {}: a bicubic patch has control points 0 to 15",
            args.point
        );
    }
    let (i, j) = (args.point / 4, args.point % 4);
    let normal = patch.normal(i as f64 / 3.0, j as f64 / 3.0).unwrap_or(DVec3::Y);
    let bounds = patch.bounds();
    let size = (bounds.max - bounds.min).length();
    let position = patch.points[args.point] + normal * (args.distance * size);
    let what = format!(
        "control point {} of patch {} moved to {position:?}",
        args.point, args.patch
    );
    let command = Command::MoveControlPoint {
        patch: args.patch,
        index: args.point,
        position,
    };
    Ok((command, what))
}

/// Light `k` moved along the camera's right by `distance` of the scene's diagonal; the
/// command and what it did, in words.
fn light_edit(scene: &Scene, k: usize, distance: f64) -> Result<(Command, String)> {
    let Some(light) = scene.lights.get(k) else {
        bail!(
            "--light {k}: {} has {} lights",
            scene.source.display(),
            scene.lights.len()
        );
    };
    let bounds = scene.geometry.bounds();
    let size = if bounds.is_empty() {
        1.0
    } else {
        (bounds.max - bounds.min).length()
    };
    let cam = &scene.camera;
    let right = cam.forward.cross(cam.up).normalize_or_zero();
    let value = light.translated(right * (distance * size));
    let what = format!("light {k} moved by {:?}", right * (distance * size));
    Ok((Command::SetLight { light: k, value }, what))
}

/// Prints the medians: the time to the target, then the first image after the edit and what
/// is on screen [`ON_SCREEN_AFTER`] it.
fn report(runs: &WarmCold, target: f64, out: &mut BenchOutput) {
    let m = runs.medians();
    let [w, c] = m.to_target;
    out.say(format!(
        "edit to relative MSE {target:.0e}: warm {w:.2} s, cold {c:.2} s  (medians of {} runs each)",
        runs.warm.len()
    ));
    let [(wt, we), (ct, ce)] = m.first;
    out.say(format!(
        "first image after the edit: warm at {:.0} ms, RMSE {we:.3e}; cold at {:.0} ms, RMSE {ce:.3e}",
        wt * 1e3,
        ct * 1e3
    ));
    let [ws, cs] = m.on_screen;
    out.say(format!(
        "on screen {} ms after the edit: RMSE warm {ws:.3e}, cold {cs:.3e} ({:.2}x)",
        ON_SCREEN_AFTER.as_millis(),
        ws / cs
    ));
    out.set("on_screen_rmse", [ws, cs]);
    out.set("warm_secs", w);
    out.set("cold_secs", c);
    out.set("warm_first_image", [wt, we]);
    out.set("cold_first_image", [ct, ce]);
    for (name, runs) in [("warm_runs", &runs.warm), ("cold_runs", &runs.cold)] {
        for r in runs {
            out.push(name, r.to_target);
        }
    }
}
