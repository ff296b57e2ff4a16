//! `caustic farm slurm|kubernetes`: the flags, made into a [`caustic::farm::Job`] whose script
//! or manifest [`caustic::farm`] writes (every value quoted there by one function). The flags
//! after `--` are parsed here as a shard's `caustic render` will parse them, so a mistake is
//! reported before anything reaches the queue (see README, "Rendering on a cluster").

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};

use caustic::farm::{kubernetes::kubernetes_manifest, slurm, Job};

/// `caustic farm`'s flags.
#[derive(clap::Args)]
pub struct FarmArgs {
    /// The batch system.
    #[command(subcommand)]
    system: System,
}

/// Which batch system to write for.
#[derive(clap::Subcommand)]
enum System {
    /// A bash script that submits a Slurm job array (one task per shard, `SLURM_ARRAY_TASK_ID`
    /// picks K) and a merge job after all of them (`--dependency=afterok`). Run it with bash
    /// on a login node.
    Slurm(JobArgs),
    /// A Kubernetes manifest: an Indexed Job (`completionMode: Indexed`, `JOB_COMPLETION_INDEX`
    /// picks K) writing parts to a shared volume, and a merge Job that merges them once all
    /// are there. Apply it with `kubectl apply -f`.
    Kubernetes(JobArgs),
}

/// What to render and where, for either system.
#[derive(clap::Args)]
struct JobArgs {
    /// The scene file, as the tasks see it (on Slurm made absolute; on Kubernetes an absolute
    /// path in the container, such as /data/scenes/cornell.toml on the shared volume).
    scene: PathBuf,
    /// Shards (tasks) to split the passes into (at most 100000).
    #[arg(long)]
    shards: u32,
    /// Passes of the whole render (at most 10000000).
    #[arg(long)]
    passes: u32,
    /// The folder the parts and the merged image.exr go to, seen by every task (shared
    /// storage; on Kubernetes an absolute path on the shared volume).
    #[arg(long)]
    out: PathBuf,
    /// Threads per task (Slurm's --cpus-per-task, Kubernetes' CPU request).
    #[arg(long, default_value_t = 1)]
    threads: u32,
    /// The container image. Kubernetes: the image the pods run (it must have `caustic` on its
    /// PATH, or give --program). Slurm: optional; when given, tasks run the program through
    /// `apptainer exec IMAGE`.
    #[arg(long)]
    image: Option<String>,
    /// The caustic program the tasks run (Slurm default: this program's absolute path;
    /// Kubernetes default: `caustic`).
    #[arg(long)]
    program: Option<String>,
    /// Slurm: the partition (default: the cluster's default). Kubernetes: ignored.
    #[arg(long)]
    partition: Option<String>,
    /// Kubernetes: the PersistentVolumeClaim mounted at /data in every pod.
    #[arg(long, default_value = "caustic-data")]
    volume_claim: String,
    /// Kubernetes: the Jobs' name prefix (the shard Job is PREFIX-shards, the merge
    /// PREFIX-merge).
    #[arg(long, default_value = "caustic")]
    name: String,
    /// Slurm: the script waits for the merge job to finish (sbatch --wait), for scripts
    /// and CI.
    #[arg(long)]
    wait: bool,
    /// Further `caustic render` flags for every shard (after `--`), such as `--width 1920`.
    #[arg(last = true)]
    render_args: Vec<String>,
}

/// A shard's `caustic render` command line, parsed as that command parses it.
#[derive(clap::Parser)]
struct ShardLine {
    #[command(flatten)]
    render: super::render::RenderArgs,
}

/// Prints the script or manifest.
pub fn farm(args: FarmArgs) -> Result<()> {
    let text = match args.system {
        System::Slurm(a) => {
            let job = a.job(true)?;
            check_render_args(&job)?;
            let script = slurm::slurm_script(&job)?;
            if let Some(warning) = slurm::array_size_warning(&job) {
                eprintln!("{warning}");
            }
            script
        }
        System::Kubernetes(a) => {
            let job = a.job(false)?;
            check_render_args(&job)?;
            kubernetes_manifest(&job)?
        }
    };
    print!("{text}");
    Ok(())
}

impl JobArgs {
    /// The job, with (on Slurm, `local`) the scene and output made absolute and the program
    /// defaulted to this one.
    fn job(self, local: bool) -> Result<Job> {
        let (scene, out, program) = if local {
            let scene = self
                .scene
                .canonicalize()
                .with_context(|| format!("{}: cannot find the scene", self.scene.display()))?;
            let program = match self.program {
                Some(p) => p,
                None => std::env::current_exe()
                    .context("cannot tell where this program is: give --program")?
                    .to_str()
                    .context("this program's path is not valid UTF-8: give --program")?
                    .to_owned(),
            };
            (scene, absolute(&self.out)?, program)
        } else {
            (
                self.scene,
                self.out,
                self.program.unwrap_or_else(|| "caustic".into()),
            )
        };
        Ok(Job {
            scene,
            shards: self.shards,
            passes: self.passes,
            out,
            threads: self.threads,
            program,
            image: self.image,
            partition: self.partition,
            volume_claim: self.volume_claim,
            name: self.name,
            wait: self.wait,
            render_args: self.render_args,
        })
    }
}

/// Parses the first shard's command line as `caustic render` will, and checks it as a shard's
/// render does, so that a misspelt, repeated or refused flag after `--` is reported here
/// rather than by every task of the job.
fn check_render_args(job: &Job) -> Result<()> {
    job.check()?;
    let words = job.shard_words().into_iter().map(|w| w.with_index(0));
    let line = std::iter::once("caustic render".into()).chain(words);
    let parsed = <ShardLine as clap::Parser>::try_parse_from(line).map_err(|e| {
        // clap's message without its "error: " and its pointer to `farm --help`.
        let message = e.to_string();
        let message = message
            .split("\n\nFor more information")
            .next()
            .unwrap_or("")
            .to_owned();
        anyhow::anyhow!(
            "the flags after `--` do not make a shard's `caustic render` command line: {} \
             (see `caustic render --help`)",
            message.trim_start_matches("error: ").trim_end()
        )
    })?;
    super::render::check_shard_flags(&parsed.render)
        .context("the flags after `--` cannot be given to a shard")
}

/// `path` made absolute against the working folder (it need not exist yet).
fn absolute(path: &Path) -> Result<PathBuf> {
    Ok(if path.is_absolute() {
        path.to_owned()
    } else {
        std::env::current_dir()
            .context("cannot read the working folder")?
            .join(path)
    })
}
