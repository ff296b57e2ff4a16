//! The Slurm submission script: a bash script that submits the shards as a job array
//! (`SLURM_ARRAY_TASK_ID` picks the shard) and the merge as a second job that starts once
//! every shard succeeded (`--dependency=afterok`).
//!
//! Both jobs are given to `sbatch` on its command line, their commands with `--wrap`, so that
//! no user value stands in a heredoc (whose end a line of the value could forge) or in a
//! `#SBATCH` line (which ends at a newline): every value is one word quoted by
//! [`super::quote::shell_word`], and a command given to `--wrap`, which `sbatch` runs with
//! `/bin/sh`, is quoted a second time as a whole. The log file names are Slurm filename
//! patterns, in which `%` is escaped as `%%` (sbatch(1), "filename pattern").

use std::ffi::OsStr;

use super::quote::{comment, shell_text, shell_word};
use super::{FarmError, Job};

/// The scheduler's variable holding a task's index in the array.
const INDEX_VAR: &str = "SLURM_ARRAY_TASK_ID";

/// The Slurm script for `job` (checked by [`Job::check`]).
pub fn slurm_script(job: &Job) -> Result<String, FarmError> {
    job.check()?;
    let out = job
        .out
        .to_str()
        .ok_or_else(|| FarmError::new("--out", "not valid UTF-8"))?;
    if out.contains('\\') {
        return Err(FarmError::new(
            "--out",
            format!(
                "{}: Slurm reads a backslash in a log file name as 'no patterns here', so the \
                 logs could not be named per task; choose a folder without one",
                comment(job.out.as_os_str())
            ),
        ));
    }
    let quote =
        |flag: &'static str, v: &OsStr| shell_word(v).map_err(|e| FarmError::new(flag, e.to_string()));
    let runner = job
        .runner(true)
        .map_err(|e| FarmError::new("--program or --image", e.to_string()))?;
    let shard = job
        .shard_line(INDEX_VAR)
        .map_err(|e| FarmError::new("SCENE", e.to_string()))?;
    let merge = job
        .merge_line()
        .map_err(|e| FarmError::new("--out", e.to_string()))?;
    let logs = |name: &str| shell_text(&format!("--output={}/logs/{name}", out.replace('%', "%%")));
    let partition = match &job.partition {
        Some(p) => format!(
            " {}",
            quote("--partition", OsStr::new(&format!("--partition={p}")))?
        ),
        None => String::new(),
    };
    let wrap = |command: String| shell_text(&format!("--wrap=exec {command}"));
    let wait = if job.wait { " --wait" } else { "" };
    Ok(format!(
        r#"#!/bin/bash
# Renders {scene} in {shards} shards of {passes} passes on Slurm, then merges them.
# Written by `caustic farm slurm`; run it with bash (it calls sbatch twice).
set -euo pipefail
out={out_q}
mkdir -p "$out/logs"

# The shards: a job array, one task per shard; {INDEX_VAR} picks the shard.
shards=$(sbatch --parsable --job-name=caustic-shards --array=0-{last} --cpus-per-task={threads}{partition} \
    {shard_log} \
    {shard_wrap})
shards=${{shards%%;*}}
echo "shards: job $shards"

# The merge, once every shard succeeded.
merge=$(sbatch --parsable{wait} --dependency=afterok:"$shards" --job-name=caustic-merge --cpus-per-task=1{partition} \
    {merge_log} \
    {merge_wrap})
echo "merge: job ${{merge%%;*}} (writes $out/image.exr)"
"#,
        scene = comment(job.scene.as_os_str()),
        shards = job.shards,
        passes = job.passes,
        out_q = quote("--out", job.out.as_os_str())?,
        last = job.shards - 1,
        threads = job.threads,
        shard_log = logs("shard_%a.out"),
        shard_wrap = wrap(format!("{runner} {shard}")),
        merge_log = logs("merge.out"),
        merge_wrap = wrap(format!("{runner} {merge}")),
    ))
}

/// A warning for arrays longer than Slurm takes by default, or `None`.
pub fn array_size_warning(job: &Job) -> Option<String> {
    (job.shards > super::SLURM_DEFAULT_MAX_ARRAY).then(|| {
        format!(
            "warning: a job array of {} tasks needs MaxArraySize of at least {} in slurm.conf \
             (Slurm's default is {}); sbatch refuses it otherwise",
            job.shards,
            job.shards,
            super::SLURM_DEFAULT_MAX_ARRAY
        )
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::farm::tests::job;

    #[test]
    fn percent_signs_in_the_folder_are_not_patterns() {
        let mut j = job();
        j.out = "/data/100%a".into();
        let script = slurm_script(&j).expect("writes");
        assert!(
            script.contains("--output=/data/100%%a/logs/shard_%a.out"),
            "{script}"
        );
        j.out = r"/data/a\b".into();
        assert!(slurm_script(&j)
            .expect_err("refused")
            .to_string()
            .contains("backslash"));
    }

    #[test]
    fn long_arrays_are_warned_of() {
        let mut j = job();
        assert_eq!(array_size_warning(&j), None);
        j.shards = 5000;
        j.passes = 5000;
        assert!(array_size_warning(&j).is_some_and(|w| w.contains("MaxArraySize")));
    }
}
