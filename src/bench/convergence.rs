//! `caustic bench convergence`: error against wall time for a set of photon-mapping
//! configurations, measured against a long reference render (cached), printed as a table and
//! optionally written as CSV and a log-log PNG plot.

use std::path::{Path, PathBuf};
use std::time::Duration;

use anyhow::{bail, Context, Result};

use super::error_curves::{errors, write_csv, Checkpoint, Curve};
use super::output::BenchOutput;
use super::plot::write_plot;
use super::reference::{default_cache_dir, ReferenceRecord};
use crate::args::{CurveFiles, Threads};
use crate::render::ppm::Ppm;
use crate::render::session::SessionOptions;
use crate::run::render_session;
use crate::scene::{RendererKind, Scene};
use crate::settings::setting::Kind;
use crate::settings::RenderParams;

/// A configuration measured: the scene's settings changed as its text says, through the table
/// of settings — `default`, `photons-only` (photon mapping as the paper has it: every switch
/// off, one estimate, exactly the photons per pass), or `KEY=VALUE` changes joined by `+`
/// (`alpha=0.5`, `guided_emission=off+adaptive_radius=off`, `renderer=path`); an
/// `initial_radius` of `4x` is four times the automatic radius. Every configuration starts
/// from the scene's settings with photon mapping's switches and automatic settings at the
/// program's defaults, so that `default` measures them on whatever the scene sets.
#[derive(Clone, Debug, PartialEq)]
pub struct Config {
    /// As given (the table's, the CSV's and the plot's label).
    text: String,
    /// The changes, key and value.
    changes: Vec<(&'static str, String)>,
}

/// The changes `photons-only` stands for.
const PHOTONS_ONLY: &str = "direct_light=off+guided_emission=off+min_photons_per_pixel=0+stratified_eye_rays=off+stratified_photons=off+supersample_light_seen=off+indirect_radius_scale=1+adaptive_radius=off";

impl Config {
    /// Parses a configuration (as `--configs` gives it), checking each key against the table.
    pub fn parse(text: &str) -> Result<Config, String> {
        let spelled = match text {
            "default" => "",
            "photons-only" => PHOTONS_ONLY,
            other => other,
        };
        let mut changes = Vec::new();
        for change in spelled.split('+').filter(|c| !c.is_empty()) {
            let (key, value) = change
                .split_once('=')
                .ok_or_else(|| format!("{change:?}: expected KEY=VALUE, default or photons-only"))?;
            let setting = crate::settings::find_setting(key.trim())
                .ok_or_else(|| format!("{key:?} is not a render setting (see scenes/FORMAT.md)"))?;
            changes.push((setting.key, value.trim().to_owned()));
        }
        Ok(Config {
            text: text.to_owned(),
            changes,
        })
    }

    /// Name in tables, the CSV and the plot's legend.
    fn label(&self) -> &str {
        &self.text
    }

    /// The scene's parameters with this configuration's changes; `auto_radius` is the radius
    /// photon mapping picks by itself.
    fn params(&self, base: &RenderParams, auto_radius: f64) -> Result<RenderParams> {
        let defaults = RenderParams::default();
        let mut p = base.clone();
        for s in crate::settings::SETTINGS {
            let switch = matches!(s.kind, Kind::Bool | Kind::Auto);
            if s.renderers.contains(&RendererKind::Ppm) && switch {
                if let Some(v) = defaults.get(s.key) {
                    p.set(s.key, &v).map_err(anyhow::Error::msg)?;
                }
            }
        }
        for (key, value) in &self.changes {
            let value = match value.strip_suffix('x').map(str::parse::<f64>) {
                Some(Ok(k)) if *key == "initial_radius" => (k * auto_radius).to_string(),
                _ => value.clone(),
            };
            p.set_text(key, &value)
                .map_err(|e| anyhow::anyhow!("configuration {}: '{key}' {e}", self.text))?;
        }
        p.validate()
            .map_err(|e| anyhow::anyhow!("configuration {}: {e}", self.text))?;
        Ok(p)
    }
}

/// `bench convergence`'s flags.
#[derive(clap::Args)]
pub struct ConvergenceArgs {
    /// Scene file; smallppm's scene (built in) when omitted.
    scene: Option<PathBuf>,
    /// Image width (height follows the scene's aspect).
    #[arg(long, default_value_t = 256)]
    width: u32,
    /// Photons per pass (default: the scene's).
    #[arg(long)]
    photons: Option<u64>,
    /// Seconds each configuration renders.
    #[arg(long, default_value_t = 10.0)]
    seconds: f64,
    /// Seconds the first configuration (the baseline) renders, when not --seconds: its final
    /// error is the target the others are timed to.
    #[arg(long)]
    baseline_seconds: Option<f64>,
    /// Passes of the reference render (the scene's own settings and photons per pass, another
    /// seed).
    #[arg(long, default_value_t = 1000)]
    reference_passes: u32,
    /// Where reference renders are cached (default: ~/.cache/caustic/references).
    #[arg(long)]
    reference_dir: Option<PathBuf>,
    /// Configurations to measure, the first being the baseline: `default`, `photons-only`, or
    /// changes of the render settings `KEY=VALUE` joined by `+` (any key of scenes/FORMAT.md's
    /// [render] table; `initial_radius=4x`: four times the automatic radius).
    #[arg(
        long,
        value_delimiter = ',',
        value_parser = Config::parse,
        default_value = "photons-only,default,guided_emission=off,stratified_eye_rays=off,stratified_photons=off,supersample_light_seen=off,indirect_radius_scale=1,adaptive_radius=off,alpha=0.5,alpha=0.667,alpha=0.9,initial_radius=4x"
    )]
    configs: Vec<Config>,
    /// Rows (configuration, pass, seconds, RMSE, relMSE) and the plot of RMSE against seconds.
    #[command(flatten)]
    files: CurveFiles,
    /// `--threads`: the worker pool's size.
    #[command(flatten)]
    pub threads: Threads,
}

/// Runs the measurement and prints the table.
pub fn bench_convergence(args: ConvergenceArgs, out: &mut BenchOutput) -> Result<()> {
    let mut scene = crate::run::photon_scene(args.scene.as_deref())?;
    check(
        &args.width,
        args.seconds,
        args.baseline_seconds,
        args.reference_passes,
    )?;
    args.files.check()?;
    scene.camera.resize(Some(args.width), None);
    scene.params.renderer = RendererKind::Ppm;
    // The reference keeps the scene's own photons per pass, so runs with other --photons
    // share it.
    let reference = reference(
        &scene,
        args.reference_passes,
        args.reference_dir.as_deref(),
        None,
        out,
    )?;
    if let Some(n) = args.photons {
        scene.params.photons_per_pass = n;
    }
    scene
        .params
        .validate()
        .map_err(|e| anyhow::anyhow!("--photons: {e}"))?;
    let auto_radius = Ppm::automatic_initial_radius(&scene);
    out.say(format!(
        "Error against time on {}, {}x{}, {} photons per pass, {} s per configuration",
        scene.source.display(),
        scene.camera.width,
        scene.camera.height,
        scene.params.photons_per_pass,
        args.seconds
    ));
    out.set("scene", scene.source.display().to_string());
    out.set("size", [scene.camera.width, scene.camera.height]);
    out.set("photons_per_pass", scene.params.photons_per_pass);
    let mut curves = Vec::new();
    for (k, config) in args.configs.iter().enumerate() {
        let seconds = match (k, args.baseline_seconds) {
            (0, Some(s)) => s,
            _ => args.seconds,
        };
        let mut configured = scene.clone();
        configured.params = config.params(&scene.params, auto_radius)?;
        eprintln!("  {} ({seconds} s)...", config.label());
        curves.push(measure(configured, config.label(), seconds, &reference)?);
    }
    print_table(&curves, out);
    if let Some(path) = &args.files.csv {
        write_csv(&curves, path, args.files.overwrite.force)?;
        out.say(format!("rows written to {}", path.display()));
    }
    if let Some(path) = &args.files.plot {
        let title = format!(
            "{}: RMSE against time ({}x{})",
            scene
                .source
                .file_name()
                .map_or("scene".into(), |n| n.to_string_lossy()),
            scene.camera.width,
            scene.camera.height
        );
        write_plot(&curves, &title, path, args.files.overwrite.force)?;
        out.say(format!("plot written to {}", path.display()));
    }
    Ok(())
}

fn check(width: &u32, seconds: f64, baseline: Option<f64>, passes: u32) -> Result<()> {
    crate::settings::limits::image_side(*width).map_err(|e| anyhow::anyhow!("--width {e}"))?;
    for (flag, s) in [("--seconds", Some(seconds)), ("--baseline-seconds", baseline)] {
        if let Some(s) = s {
            if !(s.is_finite() && s > 0.0 && s <= 86_400.0) {
                bail!("{flag} must be a positive number of seconds up to a day, got {s}");
            }
        }
    }
    if passes == 0 {
        bail!("--reference-passes must be at least 1");
    }
    Ok(())
}

/// The reference: from the cache when its record matches, else rendered (another seed, the
/// scene's own parameters but one estimate for all photons, with the adaptive radius) and
/// cached: the least-biased settings, since PPM's bias grows with the radius. One estimate has
/// the narrowest radius everywhere, so the reference does not share the blur of the wider
/// indirect estimate that the default configurations use; the adaptive radius narrows it
/// further where photons are dense (a fixed-radius reference keeps the caustics blurred by the
/// initial radius for hundreds of passes, and would count a sharper caustic as error).
/// `edit` describes a change made to the scene after it was read (part of the cache's key).
pub fn reference(
    scene: &Scene,
    passes: u32,
    dir: Option<&Path>,
    edit: Option<String>,
    out: &mut BenchOutput,
) -> Result<Vec<[f32; 3]>> {
    let dir = dir.map_or_else(default_cache_dir, Path::to_path_buf);
    let mut reference_scene = scene.clone();
    reference_scene.params.seed ^= 0x5eed;
    reference_scene.params.indirect_radius_scale = Some(1.0);
    reference_scene.params.adaptive_radius = true;
    let record = ReferenceRecord {
        edit,
        ..ReferenceRecord::new(&reference_scene, passes)
    };
    if let Some(pixels) = record.load(&dir) {
        out.say(format!("reference: {} (cached)", record.path_in(&dir).display()));
        out.set("reference", record.path_in(&dir).display().to_string());
        return Ok(pixels);
    }
    let bar = crate::run::progress_bar(
        passes as u64,
        "{msg} [{bar:40}] pass {pos}/{len}, {elapsed} (eta {eta})",
        "reference".into(),
    )?;
    let options = SessionOptions {
        max_passes: Some(passes),
        ..Default::default()
    };
    let frame = render_session(reference_scene, options, |_| bar.inc(1))?;
    bar.finish_and_clear();
    let path = record
        .store(&dir, &frame.radiance)
        .map_err(|e| anyhow::anyhow!(e))
        .context("cannot cache the reference render")?;
    out.say(format!("reference: {} ({passes} passes, cached)", path.display()));
    out.set("reference", path.display().to_string());
    Ok(frame.radiance.to_vec())
}

/// Renders `scene` for `seconds`, the error against `reference` after every pass.
fn measure(scene: Scene, name: &str, seconds: f64, reference: &[[f32; 3]]) -> Result<Curve> {
    let options = SessionOptions {
        time_limit: Some(Duration::from_secs_f64(seconds)),
        ..Default::default()
    };
    let mut points = Vec::new();
    render_session(scene, options, |f| {
        let (rmse, rel_mse) = errors(&f.radiance, reference);
        points.push(Checkpoint {
            pass: f.pass,
            secs: f.elapsed_secs,
            rmse,
            rel_mse,
        });
    })?;
    Ok(Curve {
        name: name.to_owned(),
        points,
    })
}

/// The table: each configuration's final error, slope, and how soon it reached the error the
/// baseline (the first configuration) ended with.
fn print_table(curves: &[Curve], out: &mut BenchOutput) {
    let Some(target) = curves.first().and_then(Curve::last).map(|p| p.rmse) else {
        return;
    };
    let base_secs = curves[0].last().map_or(0.0, |p| p.secs);
    // Timed to its first point at the target, like the others (noise may reach it early).
    let base_reach = curves[0].time_to(target).unwrap_or(base_secs);
    out.say(format!(
        "{:<28} {:>7} {:>8} {:>11} {:>11} {:>7} {:>16} {:>9}",
        "configuration", "passes", "seconds", "RMSE", "relMSE", "slope", "s to target", "speed-up"
    ));
    out.set("target_rmse", target);
    for c in curves {
        let Some(last) = c.last() else { continue };
        let reach = c.time_to(target);
        out.say(format!(
            "{:<28} {:>7} {:>8.2} {:>11.4e} {:>11.4e} {:>7} {:>16} {:>9}",
            c.name,
            last.pass,
            last.secs,
            last.rmse,
            last.rel_mse,
            c.slope().map_or("-".into(), |s| format!("{s:.2}")),
            reach.map_or("not reached".into(), |t| format!("{t:.2}")),
            reach.map_or("-".into(), |t| format!("{:.1}x", base_reach / t.max(1e-9))),
        ));
        out.push(
            "configurations",
            serde_json::json!({
                "name": c.name,
                "passes": last.pass,
                "seconds": last.secs,
                "rmse": last.rmse,
                "rel_mse": last.rel_mse,
                "slope": c.slope(),
                "seconds_to_target": reach,
                "speedup": reach.map(|t| base_reach / t.max(1e-9)),
                "points": c.points.iter().map(|p| [p.secs, p.rmse, p.rel_mse]).collect::<Vec<_>>(),
            }),
        );
    }
    out.say(format!(
        "target: RMSE {target:.4e}, what '{}' reached after {base_secs:.1} s",
        curves[0].name
    ));
}
