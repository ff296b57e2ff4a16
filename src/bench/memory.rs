//! `caustic bench memory`: resident memory of a long stochastic photon-mapping render (an open
//! aperture, so every pass traces a new eye pass), sampled every few passes: the peak must
//! stay bounded and the current size flat, whatever the number of passes.

use std::path::PathBuf;

use anyhow::{bail, Result};

use super::output::BenchOutput;
use crate::args::Threads;
use crate::render::session::SessionOptions;
use crate::run::{load_scene, render_session};
use crate::scene::RendererKind;

/// `bench memory`'s flags.
#[derive(clap::Args)]
pub struct MemoryArgs {
    /// Scene file; the built-in scene when omitted.
    scene: Option<PathBuf>,
    /// Image width.
    #[arg(long, default_value_t = 1920)]
    width: u32,
    /// Image height.
    #[arg(long, default_value_t = 1080)]
    height: u32,
    /// Passes to render.
    #[arg(long, default_value_t = 100)]
    passes: u32,
    /// Sample the memory every this many passes.
    #[arg(long, default_value_t = 10)]
    every: u32,
    /// Photons per pass (small: the eye pass and its visible points are what grows).
    #[arg(long, default_value_t = 20_000)]
    photons: u64,
    /// `--threads`: the worker pool's size.
    #[command(flatten)]
    pub threads: Threads,
}

/// Resident set size and its peak, in MiB, from `/proc/self/status` (Linux).
pub(super) fn resident_mib() -> Option<(f64, f64)> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let field = |name: &str| -> Option<f64> {
        let line = status.lines().find(|l| l.starts_with(name))?;
        let kib: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
        Some(kib / 1024.0)
    };
    Some((field("VmRSS:")?, field("VmHWM:")?))
}

/// Where the prepared geometry's bytes go, in all and per Bézier patch.
fn geometry_memory(scene: &crate::scene::Scene, out: &mut BenchOutput) {
    let stats = scene.geometry.stats();
    let parts = scene.geometry.memory();
    let total: usize = parts.iter().map(|(_, b)| b).sum();
    let per_patch = |b: usize| b as f64 / stats.patches.max(1) as f64;
    out.say(format!(
        "Geometry: {} patches as {} leaves, {} BVH nodes: {:.1} MiB{}",
        stats.patches,
        stats.patch_leaves,
        stats.bvh_nodes,
        total as f64 / (1 << 20) as f64,
        if stats.patches > 0 {
            format!(", {:.0} bytes a patch", per_patch(total))
        } else {
            String::new()
        }
    ));
    for (what, bytes) in &parts {
        out.say(format!(
            "  {what:<45} {:>9.2} MiB {:>8.0} bytes a patch",
            *bytes as f64 / (1 << 20) as f64,
            per_patch(*bytes)
        ));
        out.push(
            "geometry_bytes",
            serde_json::json!({ "part": what, "bytes": bytes, "bytes_per_patch": per_patch(*bytes) }),
        );
    }
    out.set("patches", stats.patches);
    out.set("patch_leaves", stats.patch_leaves);
    out.set("geometry_bytes_per_patch", per_patch(total));
}

/// Renders and prints the memory samples.
pub fn bench_memory(args: MemoryArgs, out: &mut BenchOutput) -> Result<()> {
    if args.passes == 0 || args.every == 0 {
        bail!("--passes and --every must be at least 1");
    }
    if resident_mib().is_none() {
        bail!("resident memory is read from /proc/self/status, which this system does not have");
    }
    let mut scene = load_scene(args.scene.as_deref())?;
    for (flag, v) in [("--width", args.width), ("--height", args.height)] {
        crate::settings::limits::image_side(v).map_err(|e| anyhow::anyhow!("{flag} {e}"))?;
    }
    (scene.camera.width, scene.camera.height) = (args.width, args.height);
    // An open aperture: stochastic PPM, a new eye pass (and new visible points) every pass.
    if scene.camera.aperture <= 0.0 {
        scene.camera.aperture = 0.01 * scene.camera.focal_distance;
    }
    scene.params.renderer = RendererKind::Ppm;
    scene.params.photons_per_pass = args.photons;
    scene.params.min_photons_per_pixel = 0.0;
    scene
        .params
        .validate()
        .map_err(|e| anyhow::anyhow!("--photons: {e}"))?;
    let before = resident_mib().map_or(0.0, |m| m.0);
    out.say(format!(
        "Memory of a stochastic render of {}, {}x{}, aperture {:.4}, {} photons per pass; {before:.0} MiB before rendering",
        scene.source.display(),
        args.width,
        args.height,
        scene.camera.aperture,
        args.photons
    ));
    out.set("scene", scene.source.display().to_string());
    out.set("size", [args.width, args.height]);
    out.set("aperture", scene.camera.aperture);
    out.set("photons_per_pass", args.photons);
    out.set("resident_mib_before", before);
    geometry_memory(&scene, out);
    out.say(format!(
        "{:>8} {:>10} {:>14} {:>10}",
        "pass", "seconds", "resident MiB", "peak MiB"
    ));
    let options = SessionOptions {
        max_passes: Some(args.passes),
        ..Default::default()
    };
    let mut samples = Vec::new();
    let mut peak_mib: f64 = 0.0;
    render_session(scene, options, |f| {
        if f.pass % args.every == 0 || f.pass == 1 {
            if let Some((rss, peak)) = resident_mib() {
                out.say(format!(
                    "{:>8} {:>10.1} {rss:>14.1} {peak:>10.1}",
                    f.pass, f.elapsed_secs
                ));
                out.push(
                    "samples",
                    serde_json::json!({
                        "pass": f.pass,
                        "seconds": f.elapsed_secs,
                        "resident_mib": rss,
                        "peak_mib": peak,
                    }),
                );
                samples.push(rss);
                peak_mib = peak_mib.max(peak);
            }
        }
    })?;
    if let (Some(first), Some(last)) = (samples.get(1).or(samples.first()), samples.last()) {
        out.say(format!(
            "resident size from the first sample after pass 1 to the last: {first:.1} → {last:.1} MiB ({:+.1} %)",
            (last / first - 1.0) * 100.0
        ));
        out.set("growth_percent", (last / first - 1.0) * 100.0);
    }
    out.set("peak_mib", peak_mib);
    Ok(())
}
