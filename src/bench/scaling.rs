//! `caustic bench ppm` and `caustic bench whitted`: a renderer's throughput at several thread
//! counts, and how it scales. With `--repeat N` the thread counts' runs interleave N times and
//! each count reports its best and median run (see [`super::timings`]): on a shared
//! machine one run's scaling can be off by 15 % either way.

use std::path::PathBuf;

use anyhow::{bail, Result};
use clap::Args;

use super::output::BenchOutput;
use super::timings::{interleaved, Timings};
use crate::render::render_whitted;
use crate::render::session::SessionOptions;
use crate::run::{load_scene, photon_scene, render_session};
use crate::scene::RendererKind;

/// Thread counts to measure and how often.
#[derive(Args)]
pub struct ScalingArgs {
    /// Thread counts to measure.
    #[arg(long, value_delimiter = ',', default_value = "1,2")]
    threads: Vec<usize>,
    /// Times each thread count is measured, interleaved (1, 2, 1, 2, …); each count then
    /// reports its best run (the steadiest figure on a shared machine) and its median.
    #[arg(long, default_value_t = 1)]
    repeat: usize,
}

impl ScalingArgs {
    /// Checks the thread counts and repeats.
    fn validate(&self) -> Result<()> {
        if self.threads.is_empty() || self.threads.contains(&0) {
            bail!("--threads values must be at least 1");
        }
        if self.repeat == 0 {
            bail!("--repeat must be at least 1");
        }
        Ok(())
    }
}

/// `bench ppm`'s arguments.
#[derive(Args)]
pub struct PpmArgs {
    /// Scene file; smallppm's scene (built in) when omitted.
    scene: Option<PathBuf>,
    /// Photons per pass.
    #[arg(long, default_value_t = 500_000)]
    photons: u64,
    /// Passes per measurement.
    #[arg(long, default_value_t = 3)]
    passes: u32,
    /// The indirect estimate's radius scale (default: the scene's, automatic unless it
    /// says otherwise); 1 gathers every photon in one estimate, as smallppm does, so the
    /// paths per second compare with smallppm's.
    #[arg(long, value_name = "K")]
    indirect_radius_scale: Option<f64>,
    #[command(flatten)]
    scaling: ScalingArgs,
}

/// `bench whitted`'s arguments.
#[derive(Args)]
pub struct WhittedArgs {
    /// Scene file; the built-in scene when omitted.
    scene: Option<PathBuf>,
    /// Image width (height follows the scene's aspect).
    #[arg(long, default_value_t = 640)]
    width: u32,
    #[command(flatten)]
    scaling: ScalingArgs,
}

/// What a bench measured: each thread count's runs, the work one run did (photon paths or
/// camera rays, the same for every run), and the names of the rate (work a second) and of
/// the rate per thread in the JSON.
struct Measured<'a> {
    threads: &'a [usize],
    timings: &'a [Timings],
    work: f64,
    rate_name: &'a str,
    per_thread_name: &'a str,
}

/// Prints one row of the table per thread count and its JSON entry under `runs`: the best
/// and median seconds, the best run's rate (also per thread), and the speed-up over the first
/// count by best runs and by medians.
fn report(m: Measured, out: &mut BenchOutput) {
    let Some(first) = m.timings.first() else { return };
    for (&threads, timings) in m.threads.iter().zip(m.timings) {
        let (best, median) = (timings.best(), timings.median());
        let speedup = first.best() / best;
        let speedup_median = first.median() / median;
        let rate = m.work / best;
        let per_thread = rate / threads as f64;
        out.say(format!(
            "{threads:>8} {best:>10.3} {median:>10.3} {rate:>14.0} {per_thread:>18.0} {speedup:>9.2}x {speedup_median:>9.2}x",
        ));
        out.push(
            "runs",
            serde_json::json!({
                "threads": threads,
                "seconds": best,
                "median_seconds": median,
                "all_seconds": timings.seconds(),
                m.rate_name: rate,
                m.per_thread_name: per_thread,
                "speedup": speedup,
                "speedup_median": speedup_median,
            }),
        );
    }
}

/// The table's header: `rate` and `per_thread` name the two rate columns.
fn header(rate: &str, per_thread: &str, out: &BenchOutput) {
    out.say(format!(
        "{:>8} {:>10} {:>10} {rate:>14} {per_thread:>18} {:>10} {:>10}",
        "threads", "best s", "median s", "speed-up", "(medians)"
    ));
}

/// `bench ppm`: photon paths per second (the photon passes' time alone) at each thread count.
pub fn bench_ppm(args: PpmArgs, out: &mut BenchOutput) -> Result<()> {
    let PpmArgs { photons, passes, .. } = args;
    args.scaling.validate()?;
    if photons == 0 || passes == 0 {
        bail!("--photons and --passes must be at least 1");
    }
    let mut scene = photon_scene(args.scene.as_deref())?;
    scene.params.photons_per_pass = photons;
    if let Some(k) = args.indirect_radius_scale {
        scene.params.indirect_radius_scale = Some(k);
        scene
            .params
            .validate()
            .map_err(|e| anyhow::anyhow!("--indirect-radius-scale: {e}"))?;
    }
    scene.params.renderer = RendererKind::Ppm;
    let (w, h) = (scene.camera.width, scene.camera.height);
    let repeat = args.scaling.repeat;
    out.say(format!(
        "Photon mapping on {}, {w}x{h}, {passes} passes of {photons} photons, {}",
        scene.source.display(),
        runs_text(repeat)
    ));
    out.set("scene", scene.source.display().to_string());
    out.set("size", [w, h]);
    out.set("passes", passes);
    out.set("photons_per_pass", photons);
    out.set("repeat", repeat);
    out.set("indirect_radius_scale", scene.params.indirect_radius_scale);
    out.say(match scene.params.indirect_radius_scale {
        Some(k) if k <= 1.0 => "one estimate for all photons (as smallppm gathers)".to_owned(),
        Some(k) => format!("indirect photons gathered over {k}x the radius"),
        None => "indirect radius automatic (--indirect-radius-scale 1 gathers as smallppm does)".to_owned(),
    });
    header("photon paths/s", "paths per core-s", out);
    let threads = &args.scaling.threads;
    let mut paths = 0;
    let timings = interleaved(repeat, threads, |n| -> Result<f64> {
        let session = SessionOptions {
            max_passes: Some(passes),
            threads: Some(n),
            ..Default::default()
        };
        let frame = render_session(scene.clone(), session, |_| {})?;
        let (photons, photon_secs) = photon_work(&frame)?;
        // The same seed traces the same photons whatever the thread count.
        paths = photons;
        Ok(photon_secs)
    })?;
    let measured = Measured {
        threads,
        timings: &timings,
        work: paths as f64,
        rate_name: "photon_paths_per_second",
        per_thread_name: "paths_per_core_second",
    };
    report(measured, out);
    Ok(())
}

/// `bench whitted`: camera rays per second of the ray tracer at each thread count.
pub fn bench_whitted(args: WhittedArgs, out: &mut BenchOutput) -> Result<()> {
    args.scaling.validate()?;
    let mut scene = load_scene(args.scene.as_deref())?;
    scene.camera.resize(Some(args.width.clamp(1, 16384)), None);
    let repeat = args.scaling.repeat;
    out.say(format!(
        "Whitted ray tracer on {}, {}x{}, {}",
        scene.source.display(),
        scene.camera.width,
        scene.camera.height,
        runs_text(repeat)
    ));
    out.set("scene", scene.source.display().to_string());
    out.set("size", [scene.camera.width, scene.camera.height]);
    out.set("repeat", repeat);
    header("camera rays/s", "rays per core-s", out);
    let threads = &args.scaling.threads;
    let mut rays = 0;
    let timings = interleaved(repeat, threads, |n| -> Result<f64> {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(n).build()?;
        let (_, stats) = pool.install(|| render_whitted(&scene, &|_| {}));
        rays = stats.camera_rays;
        Ok(stats.elapsed_secs)
    })?;
    let measured = Measured {
        threads,
        timings: &timings,
        work: rays as f64,
        rate_name: "camera_rays_per_second",
        per_thread_name: "camera_rays_per_core_second",
    };
    report(measured, out);
    Ok(())
}

/// "1 run per thread count" or "N interleaved runs per thread count".
fn runs_text(repeat: usize) -> String {
    if repeat == 1 {
        "1 run per thread count".to_owned()
    } else {
        format!("{repeat} interleaved runs per thread count (best and median)")
    }
}

/// The photons a photon-mapped frame's epoch traced and the seconds spent tracing them, from
/// the statistics photon mapping describes (`photon_mapping` in its JSON).
fn photon_work(frame: &crate::render::session::Frame) -> Result<(u64, f64)> {
    let stats = &frame.stats.json["photon_mapping"];
    match (stats["photons"].as_u64(), stats["photon_secs"].as_f64()) {
        (Some(photons), Some(secs)) => Ok((photons, secs)),
        _ => anyhow::bail!("the renderer returned a frame that was not photon mapped"),
    }
}
