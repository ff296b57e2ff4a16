//! Flags several commands share, each defined once and flattened into the commands that take
//! it: `--force` with its check ([`Overwrite`]), `--csv` and `--plot` of the benches that
//! measure curves ([`CurveFiles`]), and `--threads` ([`Threads`]).

use std::path::{Path, PathBuf};

use anyhow::{bail, Result};

/// `--force`: replace output files that exist; without it an existing file is never replaced.
#[derive(clap::Args, Clone, Copy, Debug, Default)]
pub struct Overwrite {
    /// Replace output files that exist (without it, an existing file is never replaced).
    #[arg(long)]
    pub force: bool,
}

impl Overwrite {
    /// Fails, naming the file, when one of `paths` exists and `--force` was not given.
    pub fn check<'p>(&self, paths: impl IntoIterator<Item = &'p Path>) -> Result<()> {
        for path in paths {
            if path.exists() && !self.force {
                bail!(
                    "{}: the file exists; choose another name or pass --force to overwrite it",
                    path.display()
                );
            }
        }
        Ok(())
    }
}

/// `--csv` and `--plot`: where a bench that measures curves writes its rows and their plot.
#[derive(clap::Args, Clone, Debug, Default)]
pub struct CurveFiles {
    /// Write every measured row to this CSV file.
    #[arg(long)]
    pub csv: Option<PathBuf>,
    /// Write the log-log plot of the measured error to this PNG file.
    #[arg(long)]
    pub plot: Option<PathBuf>,
    /// `--force` for both files.
    #[command(flatten)]
    pub overwrite: Overwrite,
}

impl CurveFiles {
    /// Fails before any work when an output file exists and `--force` was not given.
    pub fn check(&self) -> Result<()> {
        self.overwrite.check(
            [&self.csv, &self.plot]
                .into_iter()
                .flatten()
                .map(PathBuf::as_path),
        )
    }
}

/// `--threads N`: the size of the render thread pool.
#[derive(clap::Args, Clone, Copy, Debug, Default)]
pub struct Threads {
    /// Render with this many threads (default: one per core); the image does not depend on it.
    #[arg(long, value_name = "N")]
    pub threads: Option<usize>,
}
