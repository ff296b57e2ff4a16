//! `caustic farm slurm|kubernetes`: prints what renders a scene's shards on an existing batch
//! system and merges them — a Slurm submission script (a job array over the shards, then a
//! merge job with `--dependency=afterok`) or a Kubernetes manifest (an Indexed Job, then a
//! merge Job). No scheduler or network code of ours: the shards are `caustic render --shard
//! K/N` and the merge is `caustic merge` (see README, "Rendering on a cluster").

use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};

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
    Slurm(Job),
    /// A Kubernetes manifest: an Indexed Job (`completionMode: Indexed`, `JOB_COMPLETION_INDEX`
    /// picks K) writing parts to a shared volume, and a merge Job that merges them once all
    /// are there. Apply it with `kubectl apply -f`.
    Kubernetes(Job),
}

/// What to render and where, for either system.
#[derive(clap::Args)]
struct Job {
    /// The scene file, as the tasks see it (on Slurm made absolute; on Kubernetes a path in
    /// the container, such as /data/scenes/cornell.toml on the shared volume).
    scene: PathBuf,
    /// Shards (tasks) to split the passes into.
    #[arg(long)]
    shards: u32,
    /// Passes of the whole render.
    #[arg(long)]
    passes: u32,
    /// The folder the parts and the merged image.exr go to, seen by every task (shared
    /// storage; on Kubernetes a path on the shared volume).
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

/// A shard's `caustic render` command line, parsed as that command parses it
/// ([`Job::check_render_args`]).
#[derive(clap::Parser)]
struct ShardLine {
    #[command(flatten)]
    render: super::render::RenderArgs,
}

/// Prints the script or manifest.
pub fn farm(args: FarmArgs) -> Result<()> {
    let text = match args.system {
        System::Slurm(job) => {
            job.check()?;
            slurm_script(&job.absolute()?)
        }
        System::Kubernetes(job) => {
            job.check()?;
            kubernetes_manifest(&job)?
        }
    };
    print!("{text}");
    Ok(())
}

impl Job {
    fn check(&self) -> Result<()> {
        if self.shards == 0 {
            bail!("--shards must be at least 1");
        }
        if self.passes == 0 {
            bail!("--passes must be at least 1");
        }
        if self.shards > self.passes {
            bail!(
                "--shards {} is more than --passes {}: some shards would render nothing",
                self.shards,
                self.passes
            );
        }
        if self.threads == 0 || self.threads > 4096 {
            bail!("--threads must be between 1 and 4096, got {}", self.threads);
        }
        self.check_render_args()
    }

    /// What follows `render` on a shard's command line, as shell text: `index` is the shell
    /// text of the shard's index (`$K` in the Slurm script, `$JOB_COMPLETION_INDEX` in the
    /// Kubernetes Job). The scripts and [`Job::check_render_args`] all take it from here.
    fn shard_flags(&self, index: &str) -> String {
        let extra: String = self.render_args.iter().map(|a| format!(" {}", sh(a))).collect();
        format!(
            "{scene} --shard \"{index}/{shards}\" --passes {passes} --threads {threads} --out {out}/part_{index}.exr --force{extra}",
            scene = sh(&self.scene.display().to_string()),
            shards = self.shards,
            passes = self.passes,
            threads = self.threads,
            out = sh(&self.out.display().to_string()),
        )
    }

    /// Parses the first shard's command line as `caustic render` will, so that a misspelt or
    /// repeated flag after `--` is reported here rather than by every task of the job.
    fn check_render_args(&self) -> Result<()> {
        // The words the shell makes of the scripts' line, with the index 0.
        let words = shlex::split(&self.shard_flags("0"))
            .context("a shard's command line does not split into words")?;
        let line = std::iter::once("caustic render".to_owned()).chain(words);
        match <ShardLine as clap::Parser>::try_parse_from(line) {
            Ok(_) => Ok(()),
            Err(e) => {
                // clap's message without its "error: " and its pointer to `farm --help`.
                let message = e.to_string();
                let message = message.split("\n\nFor more information").next().unwrap_or("");
                bail!(
                    "the flags after `--` do not make a shard's `caustic render` command line: {} \
                     (see `caustic render --help`)",
                    message.trim_start_matches("error: ").trim_end()
                )
            }
        }
    }

    /// Paths made absolute and the program defaulted, as Slurm tasks need them.
    fn absolute(&self) -> Result<Job> {
        let scene = self
            .scene
            .canonicalize()
            .with_context(|| format!("{}: cannot find the scene", self.scene.display()))?;
        let out = absolute(&self.out)?;
        let program = match &self.program {
            Some(p) => p.clone(),
            None => std::env::current_exe()
                .context("cannot tell where this program is: give --program")?
                .display()
                .to_string(),
        };
        Ok(Job {
            scene,
            out,
            program: Some(program),
            image: self.image.clone(),
            partition: self.partition.clone(),
            volume_claim: self.volume_claim.clone(),
            name: self.name.clone(),
            render_args: self.render_args.clone(),
            ..*self
        })
    }
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

/// `s` quoted for a POSIX shell.
fn sh(s: &str) -> String {
    if !s.is_empty()
        && s.chars()
            .all(|c| c.is_ascii_alphanumeric() || "/._-=:,+@%".contains(c))
    {
        s.to_owned()
    } else {
        format!("'{}'", s.replace('\'', "'\\''"))
    }
}

/// The Slurm submission script.
fn slurm_script(job: &Job) -> String {
    let program = job.program.as_deref().unwrap_or("caustic");
    let run = match &job.image {
        Some(image) => format!("apptainer exec {} {}", sh(image), sh(program)),
        None => sh(program),
    };
    let out = job.out.display().to_string();
    let partition = job
        .partition
        .as_ref()
        .map_or(String::new(), |p| format!("#SBATCH --partition={}\n", sh(p)));
    let wait = if job.wait { " --wait" } else { "" };
    format!(
        r#"#!/bin/bash
# Renders {scene} in {shards} shards of {passes} passes on Slurm, then merges them.
# Written by `caustic farm slurm`; run it with bash (it calls sbatch twice).
set -euo pipefail
OUT={out_q}
mkdir -p "$OUT/logs"

# The shards: a job array, one task per shard; SLURM_ARRAY_TASK_ID picks K.
shards=$(sbatch --parsable <<'SHARDS'
#!/bin/bash
#SBATCH --job-name=caustic-shards
#SBATCH --array=0-{last}
#SBATCH --cpus-per-task={threads}
{partition}#SBATCH --output={out_q}/logs/shard_%a.out
set -euo pipefail
K=$SLURM_ARRAY_TASK_ID
{run} render {flags}
SHARDS
)
shards=${{shards%%;*}}
echo "shards: job $shards"

# The merge, once every shard succeeded.
merge=$(sbatch --parsable{wait} --dependency=afterok:$shards <<'MERGE'
#!/bin/bash
#SBATCH --job-name=caustic-merge
#SBATCH --cpus-per-task=1
{partition}#SBATCH --output={out_q}/logs/merge.out
set -euo pipefail
{run} merge {out_q}/part_*.exr --out {out_q}/image.exr --force
MERGE
)
echo "merge: job ${{merge%%;*}} (writes {out_q}/image.exr)"
"#,
        scene = job.scene.display(),
        flags = job.shard_flags("$K"),
        shards = job.shards,
        passes = job.passes,
        last = job.shards - 1,
        threads = job.threads,
        out_q = sh(&out),
    )
}

/// The Kubernetes manifest: the Indexed Job of the shards and the merge Job.
fn kubernetes_manifest(job: &Job) -> Result<String> {
    let Some(image) = &job.image else {
        bail!("--image is required for Kubernetes: the container image the pods run");
    };
    let program = job.program.as_deref().unwrap_or("caustic");
    let scene = job.scene.display().to_string();
    let out = job.out.display().to_string();
    let shard_command = format!(
        "exec {} render {}",
        sh(program),
        job.shard_flags("$JOB_COMPLETION_INDEX")
    );
    let merge_command = format!(
        "until [ \"$(ls {out_q}/part_*.exr 2>/dev/null | wc -l)\" -ge {n} ]; do sleep 10; done; exec {} merge {out_q}/part_*.exr --out {out_q}/image.exr --force",
        sh(program),
        out_q = sh(&out),
        n = job.shards,
    );
    let header = format!(
        r#"# Renders {scene} in {shards} shards of {passes} passes on Kubernetes, then merges them.
# Written by `caustic farm kubernetes`; apply with `kubectl apply -f`. The scene and {out}
# are paths on the PersistentVolumeClaim {claim}, mounted at /data in every pod. Parts are
# written under a hidden name and renamed when complete, so the merge Job counts only whole
# parts; it merges once all {shards} are there.
"#,
        shards = job.shards,
        passes = job.passes,
        claim = job.volume_claim,
    );
    let shards = PodJob {
        name: format!("{}-shards", job.name),
        spec: format!(
            "  completions: {n}\n  parallelism: {n}\n  completionMode: Indexed\n  backoffLimit: {}\n",
            3 * job.shards,
            n = job.shards
        ),
        restart: "Never",
        container: "shard",
        command: shard_command,
        cpu: job.threads.to_string(),
    };
    let merge = PodJob {
        name: format!("{}-merge", job.name),
        spec: "  backoffLimit: 3\n".into(),
        restart: "OnFailure",
        container: "merge",
        command: merge_command,
        cpu: "1".into(),
    };
    Ok(format!(
        "{header}{}---\n{}",
        shards.yaml(image, &job.volume_claim),
        merge.yaml(image, &job.volume_claim)
    ))
}

/// One Job of the Kubernetes manifest: a pod of one container with the shared volume.
struct PodJob {
    name: String,
    /// The Job's own `spec` lines (indented two spaces) before its template.
    spec: String,
    restart: &'static str,
    container: &'static str,
    /// The container's shell command.
    command: String,
    /// Its CPU request.
    cpu: String,
}

impl PodJob {
    /// The Job as YAML, running `image` with the PersistentVolumeClaim `claim` at /data.
    fn yaml(&self, image: &str, claim: &str) -> String {
        let q = |s: &str| serde_json::to_string(s).unwrap_or_default();
        format!(
            r#"apiVersion: batch/v1
kind: Job
metadata:
  name: {name}
spec:
{spec}  template:
    spec:
      restartPolicy: {restart}
      containers:
        - name: {container}
          image: {image}
          command: ["sh", "-c", {command}]
          resources:
            requests:
              cpu: "{cpu}"
          volumeMounts:
            - name: data
              mountPath: /data
      volumes:
        - name: data
          persistentVolumeClaim:
            claimName: {claim}
"#,
            name = q(&self.name),
            spec = self.spec,
            restart = self.restart,
            container = self.container,
            image = q(image),
            command = q(&self.command),
            cpu = self.cpu,
            claim = q(claim),
        )
    }
}
