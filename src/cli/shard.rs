//! `caustic render --shard K/N`: one shard of a render with the global radius schedule, its
//! passes' exact sums written as a part file ([`caustic::render::shard::part`]) for
//! `caustic merge`; and `caustic merge`.

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{bail, Result};

use caustic::args::Overwrite;
use caustic::render::shard::PassSet;
use caustic::render::shard::{merge_parts, shard_part};
use caustic::scene::Scene;
use caustic::settings::limits;

/// Renders the passes `passes` of a `total`-pass render of `scene` (its flags laid in;
/// [`caustic::render::shard::render_part::shard_renderer`] says which renderer) into the part
/// file `out`, which `render` has checked may be written.
pub fn render_shard(scene: &mut Scene, passes: PassSet, total: u32, out: &Path, force: bool) -> Result<()> {
    if !out.extension().is_some_and(|e| e.eq_ignore_ascii_case("exr")) {
        bail!(
            "{}: a part (a shard, or a part's passes rendered again) is written as an EXR part file (use .exr)",
            out.display()
        );
    }
    limits::passes(total).map_err(|e| anyhow::anyhow!("--passes {e}"))?;
    let start = Instant::now();
    let count = passes.passes_of(total);
    let bar = caustic::run::progress_bar(
        count as u64,
        "{msg} [{bar:40}] pass {pos}/{len}, {elapsed} (eta {eta})",
        format!(
            "{passes} of {total} passes, {}x{}",
            scene.camera.width, scene.camera.height
        ),
    )?;
    let (part, photons) = shard_part(scene, &passes, total, || bar.inc(1))?;
    bar.finish_and_clear();
    part.write(out, force)?;
    let emitted = scene.params.renderer.emitted();
    println!(
        "{passes}: {count} of {total} passes, {photons} {emitted} in {:.2} s ({:.2} passes/s) → {}",
        start.elapsed().as_secs_f64(),
        count as f64 / start.elapsed().as_secs_f64().max(1e-9),
        out.display()
    );
    Ok(())
}

/// `caustic merge`'s flags.
#[derive(clap::Args)]
pub struct MergeArgs {
    /// Part files (from `render --shard`, or earlier merges) of one render.
    #[arg(required = true, num_args = 1..)]
    parts: Vec<PathBuf>,
    /// The merged part file (.exr): the mean of every pass in RGB, the sums for further merges.
    #[arg(short, long)]
    out: PathBuf,
    /// Accept parts that together hold fewer than the render's passes (the image is the mean
    /// of those they hold).
    #[arg(long)]
    partial: bool,
    #[command(flatten)]
    overwrite: Overwrite,
}

/// Adds the parts' sums and writes the merged part; refuses parts of different renders or
/// overlapping passes, naming the files and what differs.
pub fn merge(args: MergeArgs) -> Result<()> {
    if !args
        .out
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("exr"))
    {
        bail!(
            "{}: the merge is written as an EXR part file (use .exr)",
            args.out.display()
        );
    }
    args.overwrite.check([args.out.as_path()])?;
    let start = Instant::now();
    let merged = merge_parts(&args.parts)?;
    let (done, total) = (merged.sums.passes().len(), merged.total_passes);
    if !merged.is_complete() && !args.partial {
        bail!(
            "the parts hold {done} of the render's {total} passes (missing: {}); pass --partial to merge them anyway",
            missing(merged.sums.passes(), total)
        );
    }
    merged.write(&args.out, args.overwrite.force)?;
    let error = merged
        .sums
        .relative_error()
        .map_or(String::new(), |e| format!(", estimated relative error {e:.2e}"));
    println!(
        "merged {} parts: {done} of {total} passes{error} in {:.2} s → {}",
        args.parts.len(),
        start.elapsed().as_secs_f64(),
        args.out.display()
    );
    Ok(())
}

/// The first few passes of `0..total` not in `passes` (ascending).
fn missing(passes: &[u32], total: u32) -> String {
    let gaps: Vec<String> = (0..total)
        .filter(|p| passes.binary_search(p).is_err())
        .take(8)
        .map(|p| p.to_string())
        .collect();
    let more = (total as usize - passes.len()).saturating_sub(gaps.len());
    if more > 0 {
        format!("{} and {more} more", gaps.join(", "))
    } else {
        gaps.join(", ")
    }
}
