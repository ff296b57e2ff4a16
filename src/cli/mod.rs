//! The `caustic` command line: argument parsing and dispatch; each command lives in a file of
//! its own ([`view`], [`render`], [`shard`], [`farm`], [`export`]). `caustic bench`'s
//! subcommands are the library's ([`caustic::bench::command`]), parsed here and run there.

mod design;
mod export;
mod farm;
mod render;
mod render_report;
mod shard;
mod view;

use anyhow::{bail, Context, Result};
use clap::{Parser, Subcommand};

#[derive(Parser)]
#[command(
    name = "caustic",
    version,
    about = "Progressive photon mapping of exact Bézier patches"
)]
struct Cli {
    /// What to do; without one, the viewer opens on the built-in scene.
    #[command(subcommand)]
    command: Option<Command>,
}

#[derive(Subcommand)]
enum Command {
    /// Open the viewer window on a scene (the built-in teapot scene when omitted).
    View(view::ViewArgs),
    /// Render a scene to an image (PNG: tonemapped sRGB; EXR: linear float).
    Render(render::RenderArgs),
    /// Merge part files of one render (from `render --shard K/N`) into one image.
    Merge(shard::MergeArgs),
    /// Print a batch script or manifest that renders a scene's shards on Slurm or Kubernetes
    /// and merges them.
    Farm(farm::FarmArgs),
    /// Write a scene's Bézier patches, tessellated, as a Wavefront OBJ file.
    ExportObj(export::ExportArgs),
    /// Shape a glass or mirror surface until the light it sends draws a target image.
    Design(design::DesignArgs),
    /// Measure performance; prints figures (nothing is asserted).
    Bench {
        /// Print the figures as one JSON document on stdout (the text goes to stderr).
        #[arg(long, global = true)]
        json: bool,
        #[command(subcommand)]
        what: caustic::bench::command::BenchCommand,
    },
}

/// Parses the command line and runs the command.
pub fn run() -> Result<()> {
    let launched = std::time::Instant::now();
    // No subcommand: the viewer with `view`'s own defaults.
    let command = Cli::parse()
        .command
        .unwrap_or_else(|| Command::View(view::ViewArgs::parse_from(["caustic view"])));
    use_threads(match &command {
        Command::View(a) => a.threads.threads,
        Command::Render(a) => a.threads.threads,
        Command::ExportObj(_) | Command::Merge(_) | Command::Farm(_) | Command::Design(_) => None,
        Command::Bench { what, .. } => what.threads(),
    })?;
    match command {
        Command::View(args) => view::view(args, launched),
        Command::Render(args) => render::render(args),
        Command::ExportObj(args) => export::export_obj(args),
        Command::Design(args) => design::design_command(args),
        Command::Merge(args) => shard::merge(args),
        Command::Farm(args) => farm::farm(args),
        Command::Bench { what, json } => caustic::bench::command::run(what, json),
    }
}

/// What the user sees of an error: its message and the chain of its causes, one a line —
/// never a backtrace, which `RUST_BACKTRACE=1` (common in a Rust user's shell) would add to
/// anyhow's own report: a mistake in a file or a flag is not a crash.
pub fn error_report(error: &anyhow::Error) -> String {
    let mut text = format!("Error: {error}");
    let causes: Vec<String> = error.chain().skip(1).map(|c| c.to_string()).collect();
    if !causes.is_empty() {
        text.push_str("\n\nCaused by:");
        for (k, cause) in causes.iter().enumerate() {
            text.push_str(&format!("\n    {k}: {cause}"));
        }
    }
    text
}

/// Sizes rayon's global pool for this run (`--threads N`, like pbrt's `--nthreads` and
/// Mitsuba's `-t`): every render of the command then uses `N` threads. `None`: one per core.
fn use_threads(threads: Option<usize>) -> Result<()> {
    if let Some(n) = threads {
        if n == 0 || n > 4096 {
            bail!("--threads must be between 1 and 4096, got {n}");
        }
        rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build_global()
            .context("cannot start the render threads")?;
    }
    Ok(())
}
