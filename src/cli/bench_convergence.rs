//! `caustic bench convergence`: error against wall time for a set of photon-mapping
//! configurations, measured against a long reference render (cached), printed as a table and
//! optionally written as CSV and a log-log PNG plot.

use std::path::{Path, PathBuf};
use std::time::Duration;

use anyhow::{bail, Context, Result};
use clap::ValueEnum;

use super::bench_output::BenchOutput;
use super::render_session;
use super::shared_args::{CurveFiles, Threads};
use caustic::bench::error_curves::{errors, write_csv, Checkpoint, Curve};
use caustic::bench::plot::write_plot;
use caustic::bench::reference::{default_cache_dir, ReferenceRecord};
use caustic::render::ppm::Ppm;
use caustic::render::session::SessionOptions;
use caustic::scene::{RendererKind, Scene};
use caustic::settings::RenderParams;
use caustic::settings::{IndexKind, RadiusSchedule};

/// A configuration measured: the scene's parameters with one thing changed.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum Config {
    /// The defaults before light sampling, balanced passes, guided emission, stratified eye
    /// rays and photons, supersampled outlines and the wider indirect estimate: photons carry
    /// all light in one estimate, lights emit as they shine at random, a pass traces exactly
    /// the scene's photons per pass and eye rays are jittered independently (the baseline).
    PhotonsOnly,
    /// The defaults: direct light by light sampling, guided emission, stratified eye rays and
    /// photons, an automatic wider radius for indirect light, α 0.7, automatic radius, hash grid.
    Default,
    /// The defaults with lights emitting as they shine (no guided emission).
    Unguided,
    /// The defaults with eye rays jittered independently (no stratification over passes).
    Unstratified,
    /// The defaults with photons' directions drawn independently at random (no Sobol
    /// sequence over the render's photons).
    UnstratifiedPhotons,
    /// The defaults with one eye ray per pixel a pass for the light seen directly (no
    /// supersampled lamp outlines).
    Unsupersampled,
    /// The defaults with one estimate for all photons (no wider indirect radius).
    OneEstimate,
    /// The defaults with every point starting at the initial radius (no adaptive radius).
    FixedRadius,
    /// α = 0.5.
    #[value(name = "alpha-0.5")]
    Alpha05,
    /// α = 2/3 (Knaus & Zwicker's asymptotically best choice).
    #[value(name = "alpha-0.667")]
    Alpha067,
    /// α = 0.9.
    #[value(name = "alpha-0.9")]
    Alpha09,
    /// An initial radius four times the automatic one.
    #[value(name = "radius-x4")]
    RadiusX4,
    /// The seed report's kd-tree instead of the hash grid.
    KdTree,
    /// The path tracer (one sample per pixel a pass), against the same photon-mapped
    /// reference.
    #[value(name = "path")]
    PathTracer,
    /// The defaults with the global radius schedule (Knaus & Zwicker 2011): every pass an
    /// independent estimate, as sharded renders need.
    GlobalSchedule,
}

impl Config {
    /// Name in tables, the CSV and the plot's legend.
    fn label(self) -> &'static str {
        match self {
            Config::PhotonsOnly => "old defaults (photons only)",
            Config::Default => "new defaults",
            Config::Unguided => "default without guided emission",
            Config::Unstratified => "default without stratified eye rays",
            Config::UnstratifiedPhotons => "default without stratified photons",
            Config::Unsupersampled => "default without supersampled outlines",
            Config::OneEstimate => "default with one estimate for all photons",
            Config::FixedRadius => "default without adaptive radius",
            Config::Alpha05 => "alpha 0.5",
            Config::Alpha067 => "alpha 2/3",
            Config::Alpha09 => "alpha 0.9",
            Config::RadiusX4 => "initial radius x4",
            Config::KdTree => "kd-tree",
            Config::PathTracer => "path tracer",
            Config::GlobalSchedule => "default, global radius schedule",
        }
    }

    /// The scene's parameters with this configuration's change; `auto_radius` is the radius
    /// photon mapping picks by itself.
    fn params(self, base: &RenderParams, auto_radius: f64) -> RenderParams {
        let mut p = RenderParams {
            direct_light: true,
            guided_emission: true,
            stratified_eye_rays: true,
            stratified_photons: true,
            supersample_light_seen: true,
            indirect_radius_scale: None,
            adaptive_radius: true,
            ..base.clone()
        };
        match self {
            Config::PhotonsOnly => {
                p.direct_light = false;
                p.guided_emission = false;
                p.min_photons_per_pixel = 0.0;
                p.stratified_eye_rays = false;
                p.stratified_photons = false;
                p.supersample_light_seen = false;
                p.indirect_radius_scale = Some(1.0);
                p.adaptive_radius = false;
            }
            Config::Default => {}
            Config::Unguided => p.guided_emission = false,
            Config::Unstratified => p.stratified_eye_rays = false,
            Config::UnstratifiedPhotons => p.stratified_photons = false,
            Config::Unsupersampled => p.supersample_light_seen = false,
            Config::OneEstimate => p.indirect_radius_scale = Some(1.0),
            Config::FixedRadius => p.adaptive_radius = false,
            Config::Alpha05 => p.alpha = 0.5,
            Config::Alpha067 => p.alpha = 2.0 / 3.0,
            Config::Alpha09 => p.alpha = 0.9,
            Config::RadiusX4 => p.initial_radius = Some(4.0 * auto_radius),
            Config::KdTree => p.index = IndexKind::KdTree,
            Config::PathTracer => p.renderer = RendererKind::Path,
            Config::GlobalSchedule => p.radius_schedule = RadiusSchedule::Global,
        }
        p
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
    /// Configurations to measure, the first being the baseline.
    #[arg(
        long,
        value_enum,
        value_delimiter = ',',
        default_value = "photons-only,default,unguided,unstratified,unstratified-photons,unsupersampled,one-estimate,fixed-radius,alpha-0.5,alpha-0.667,alpha-0.9,radius-x4"
    )]
    configs: Vec<Config>,
    /// Rows (configuration, pass, seconds, RMSE, relMSE) and the plot of RMSE against seconds.
    #[command(flatten)]
    files: CurveFiles,
    #[command(flatten)]
    pub threads: Threads,
}

/// Runs the measurement and prints the table.
pub fn bench_convergence(args: ConvergenceArgs, out: &mut BenchOutput) -> Result<()> {
    let mut scene = super::photon_scene(args.scene.as_deref())?;
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
        configured.params = config.params(&scene.params, auto_radius);
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
    caustic::settings::limits::image_side(*width).map_err(|e| anyhow::anyhow!("--width {e}"))?;
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
pub(super) fn reference(
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
    let bar = super::progress_bar(
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
