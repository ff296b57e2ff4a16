//! `caustic view`: the viewer window, or a scripted run of it.

use std::path::PathBuf;

#[cfg(feature = "viewer")]
use anyhow::bail;
use anyhow::Result;
use clap::Parser;

use caustic::args::{Overwrite, Threads};

/// `caustic view` (also what `caustic` alone runs, with these defaults).
#[derive(Parser)]
pub struct ViewArgs {
    /// Scene file (TOML).
    pub scene: Option<PathBuf>,
    /// Save a screenshot of the window (PNG) once the render has reached
    /// --after-passes passes, then close.
    #[arg(long, value_name = "FILE.png")]
    pub screenshot: Option<PathBuf>,
    /// Passes to wait for before --screenshot.
    #[arg(long, default_value_t = 4, value_name = "N")]
    pub after_passes: u32,
    #[command(flatten)]
    pub overwrite: Overwrite,
    /// Measure launch-to-first-image, UI frame rate while rendering and the latency from
    /// an aperture change to the new image; print them and close.
    #[arg(long)]
    pub bench: bool,
    #[command(flatten)]
    pub threads: Threads,
    /// Compare with this reference image (.exr or .pfm of the scene's size): the true error
    /// in the convergence plot, the difference views and the A/B toggle (B).
    #[arg(long, value_name = "FILE")]
    pub reference: Option<PathBuf>,
    /// Watch a render folder instead of rendering: the parts `caustic render --shard` writes
    /// there (by a Slurm or Kubernetes farm) are merged and shown as they land, with the
    /// passes done and the error estimate.
    #[arg(long, value_name = "DIR", conflicts_with = "scene")]
    pub watch: Option<PathBuf>,
}

/// Opens the viewer (only with the `viewer` feature).
#[cfg(feature = "viewer")]
pub fn view(args: ViewArgs, launched: std::time::Instant) -> Result<()> {
    let ViewArgs {
        scene,
        screenshot,
        after_passes,
        overwrite,
        bench,
        threads: _,
        reference,
        watch,
    } = args;
    if let Some(dir) = &watch {
        if !dir.is_dir() {
            bail!("--watch {}: no such folder", dir.display());
        }
    }
    let reference = reference
        .map(|p| caustic::render::compare::Reference::open(&p))
        .transpose()?;
    if let Some(p) = &screenshot {
        if p.extension().is_none_or(|e| !e.eq_ignore_ascii_case("png")) {
            bail!(
                "--screenshot {}: the screenshot is written as PNG; name it .png",
                p.display()
            );
        }
    }
    let launch = caustic::app::LaunchOptions {
        screenshot,
        screenshot_after_passes: after_passes.max(1),
        force: overwrite.force,
        bench,
        launched,
        reference,
        watch,
    };
    caustic::app::run(scene, launch)
}

/// Without the `viewer` feature there is no window to open.
#[cfg(not(feature = "viewer"))]
pub fn view(_: ViewArgs, _: std::time::Instant) -> Result<()> {
    anyhow::bail!("this caustic was built without the viewer (the `viewer` feature); use `caustic render`")
}
