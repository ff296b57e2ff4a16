//! `caustic bench shards`: what a sharded render costs here — each shard's passes per second
//! and peak memory (rendered one after another in this process, each with every thread), the
//! merge's time and peak memory over all the parts, and from them the wall time of a render of
//! any length on any number of machines.

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{bail, Context, Result};

use super::output::BenchOutput;
use crate::args::Threads;
use crate::render::shard::{merge_parts, shard_part};
use crate::render::shard::{PassSet, Shard};
use crate::run::load_scene;
use crate::scene::Scene;

/// `bench shards`'s flags.
#[derive(clap::Args)]
pub struct ShardsArgs {
    /// Scene file; the built-in scene when omitted.
    scene: Option<PathBuf>,
    /// Image width.
    #[arg(long, default_value_t = 1920)]
    width: u32,
    /// Image height.
    #[arg(long, default_value_t = 1080)]
    height: u32,
    /// Parts (shards) to render and merge.
    #[arg(long, default_value_t = 4)]
    parts: u32,
    /// Passes of the whole render (each shard renders passes/parts of them, at least one).
    #[arg(long)]
    passes: Option<u32>,
    /// Photons per pass (default: the scene's).
    #[arg(long)]
    photons: Option<u64>,
    /// Least photons per pixel of a pass (default: the scene's).
    #[arg(long)]
    min_photons_per_pixel: Option<f64>,
    /// Where the parts are written and kept (default: a temporary folder, removed afterwards).
    #[arg(long)]
    dir: Option<PathBuf>,
    /// For the projection: passes of the render to project.
    #[arg(long, default_value_t = 10_000)]
    project_passes: u32,
    /// For the projection: machines.
    #[arg(long, default_value_t = 64)]
    project_machines: u32,
    /// `--threads`: the worker pool's size.
    #[command(flatten)]
    pub threads: Threads,
}

/// Peak resident memory since the last reset, in MiB (`/proc/self/status` VmHWM).
fn peak_mib() -> Option<f64> {
    super::memory::resident_mib().map(|(_, peak)| peak)
}

/// Starts a new peak-memory measurement (Linux: writing 5 to clear_refs resets VmHWM).
fn reset_peak() {
    let _ = std::fs::write("/proc/self/clear_refs", "5");
}

/// What rendering the parts took.
struct Rendered {
    /// The part files, in shard order.
    paths: Vec<PathBuf>,
    /// Seconds, all shards together.
    secs: f64,
    /// The largest peak resident memory of a shard, MiB.
    peak: f64,
    /// Passes rendered (without the pilots).
    passes: u32,
}

/// Renders the `parts` shards of a `passes`-pass render of `scene` one after another into
/// `dir`, printing each one's figures.
fn render_parts(
    scene: &Scene,
    parts: u32,
    passes: u32,
    dir: &Path,
    out: &mut BenchOutput,
) -> Result<Rendered> {
    let mut done = Rendered {
        paths: Vec::new(),
        secs: 0.0,
        peak: 0.0,
        passes: 0,
    };
    for k in 0..parts {
        let shard = Shard {
            index: k,
            count: parts,
        };
        reset_peak();
        let start = Instant::now();
        let mut scene = scene.clone();
        let (part, photons) = shard_part(&mut scene, &PassSet::Shard(shard), passes, || {})?;
        let secs = start.elapsed().as_secs_f64();
        let peak = peak_mib().unwrap_or(0.0);
        let path = dir.join(format!("part_{k}.exr"));
        part.write(&path, true)?;
        let count = shard.passes_of(passes);
        out.say(format!(
            "  shard {shard}: {count} passes (and the pilot) in {secs:.2} s, {photons} photons, peak {peak:.0} MiB"
        ));
        out.push(
            "shards",
            serde_json::json!({ "shard": shard.to_string(), "passes": count, "seconds": secs, "photons": photons, "peak_mib": peak }),
        );
        done.secs += secs;
        done.peak = done.peak.max(peak);
        done.passes += count;
        done.paths.push(path);
    }
    Ok(done)
}

/// Renders the parts, merges them, prints the figures.
pub fn bench_shards(args: ShardsArgs, out: &mut BenchOutput) -> Result<()> {
    if args.parts == 0 || args.project_machines == 0 || args.project_passes == 0 {
        bail!("--parts, --project-passes and --project-machines must be at least 1");
    }
    let passes = args.passes.unwrap_or(args.parts);
    if passes < args.parts {
        bail!(
            "--passes {passes} is fewer than --parts {}: some parts would be empty",
            args.parts
        );
    }
    let mut scene = load_scene(args.scene.as_deref())?;
    for (flag, v) in [("--width", args.width), ("--height", args.height)] {
        crate::settings::limits::image_side(v).map_err(|e| anyhow::anyhow!("{flag} {e}"))?;
    }
    scene.camera.resize(Some(args.width), Some(args.height));
    if let Some(n) = args.photons {
        scene.params.photons_per_pass = n;
    }
    if let Some(n) = args.min_photons_per_pixel {
        scene.params.min_photons_per_pixel = n;
    }
    scene.params.validate().map_err(|e| anyhow::anyhow!("{e}"))?;
    let temporary = args.dir.is_none();
    let dir = args
        .dir
        .clone()
        .unwrap_or_else(|| std::env::temp_dir().join(format!("caustic-bench-shards-{}", std::process::id())));
    std::fs::create_dir_all(&dir).with_context(|| format!("{}: cannot make the folder", dir.display()))?;
    out.say(format!(
        "{} parts of a {passes}-pass render of {}, {}x{}, {} threads",
        args.parts,
        scene.source.display(),
        args.width,
        args.height,
        rayon::current_num_threads()
    ));
    out.set("scene", scene.source.display().to_string());
    out.set("size", [args.width, args.height]);
    out.set("parts", args.parts);
    out.set("passes", passes);
    let rendered = render_parts(&scene, args.parts, passes, &dir, out)?;
    merge_and_project(&args, rendered, &dir, out)?;
    if temporary {
        let _ = std::fs::remove_dir_all(&dir);
    }
    Ok(())
}

/// Merges the parts, prints the merge's time and peak memory and the projection of
/// `--project-passes` passes on `--project-machines` machines.
fn merge_and_project(args: &ShardsArgs, rendered: Rendered, dir: &Path, out: &mut BenchOutput) -> Result<()> {
    let Rendered {
        paths,
        secs: render_secs,
        peak: shard_peak,
        passes: rendered,
    } = rendered;
    reset_peak();
    let start = Instant::now();
    let merged = merge_parts(&paths)?;
    let merged_path = dir.join("image.exr");
    merged.write(&merged_path, true)?;
    let merge_secs = start.elapsed().as_secs_f64();
    let merge_peak = peak_mib().unwrap_or(0.0);
    let part_mib = std::fs::metadata(&paths[0]).map_or(0.0, |m| m.len() as f64 / (1 << 20) as f64);
    let per_pass = render_secs / rendered as f64;
    out.say(format!(
        "  all shards: {rendered} passes in {render_secs:.2} s ({:.3} passes/s with the pilots), peak {shard_peak:.0} MiB a shard; a part is {part_mib:.1} MiB",
        1.0 / per_pass
    ));
    out.say(format!(
        "  merge of {} parts (read, add, write): {merge_secs:.2} s, peak {merge_peak:.0} MiB",
        args.parts
    ));
    let (p, m) = (args.project_passes as f64, args.project_machines as f64);
    let pilot_and_pass = render_secs / args.parts as f64 / (rendered as f64 / args.parts as f64 + 1.0);
    let projected = (p / m).ceil() * pilot_and_pass + pilot_and_pass + merge_secs * m / args.parts as f64;
    out.say(format!(
        "  projected: {} passes on {} machines like this one: about {:.0} s ({:.1} h) a shard of {} passes plus a pilot, and the merge (scaled to {} parts)",
        args.project_passes,
        args.project_machines,
        projected,
        projected / 3600.0,
        (p / m).ceil(),
        args.project_machines
    ));
    out.set("render_seconds", render_secs);
    out.set("shard_peak_mib", shard_peak);
    out.set("merge_seconds", merge_secs);
    out.set("merge_peak_mib", merge_peak);
    out.set("part_mib", part_mib);
    out.set("projected_seconds", projected);
    Ok(())
}
