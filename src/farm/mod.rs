//! What `caustic farm slurm|kubernetes` prints: a Slurm submission script ([`slurm`]: a job
//! array over the shards, then a merge job with `--dependency=afterok`) or a Kubernetes
//! manifest ([`kubernetes`]: an Indexed Job, then a merge Job) that render a scene's shards
//! (`caustic render --shard K/N`) on an existing batch system and merge them (`caustic
//! merge`). No scheduler or network code of ours.
//!
//! A render's file names come from users, and a script runs them on a cluster: every value
//! written into a script is quoted by [`quote::shell_word`], every comment by
//! [`quote::comment`], and the manifest is YAML from a serializer. A [`Job`] is checked
//! ([`Job::check`]) before anything is written, against the limits below.

pub mod kubernetes;
pub mod quote;
pub mod slurm;

use std::ffi::{OsStr, OsString};
use std::path::PathBuf;

pub use quote::QuoteError;

/// The most shards a job may have: Kubernetes' limit on an Indexed Job's completions
/// (10⁵); a Slurm array this long also needs `MaxArraySize` above it in slurm.conf.
pub const MAX_SHARDS: u32 = 100_000;

/// The largest job array Slurm takes by default (`MaxArraySize=1001`: indices 0 to 1000).
pub const SLURM_DEFAULT_MAX_ARRAY: u32 = 1001;

/// The most threads a task may ask for.
pub const MAX_THREADS: u32 = 4096;

/// A sharded render on a batch system.
#[derive(Clone, Debug)]
pub struct Job {
    /// The scene file as the tasks see it (absolute).
    pub scene: PathBuf,
    /// Shards (tasks).
    pub shards: u32,
    /// Passes of the whole render.
    pub passes: u32,
    /// The folder of the parts and the merged `image.exr`, seen by every task (absolute).
    pub out: PathBuf,
    /// Threads per task.
    pub threads: u32,
    /// The program the tasks run.
    pub program: String,
    /// Kubernetes: the pods' container image. Slurm: when set, tasks run the program through
    /// `apptainer exec IMAGE`.
    pub image: Option<String>,
    /// Slurm: the partition.
    pub partition: Option<String>,
    /// Kubernetes: the PersistentVolumeClaim mounted at `/data`.
    pub volume_claim: String,
    /// Kubernetes: the Jobs' name prefix.
    pub name: String,
    /// Slurm: the script waits for the merge job (`sbatch --wait`).
    pub wait: bool,
    /// Further `caustic render` flags for every shard.
    pub render_args: Vec<String>,
}

/// Why a job cannot be written: the message names the flag.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("{flag} {message}")]
pub struct FarmError {
    /// The flag (or argument) at fault.
    pub flag: &'static str,
    /// What is wrong, following the flag.
    pub message: String,
}

impl FarmError {
    fn new(flag: &'static str, message: impl Into<String>) -> Self {
        Self {
            flag,
            message: message.into(),
        }
    }
}

/// One word of a shard's command line: a value, or a value around the shard's index, which
/// the task's shell fills in from its scheduler's variable.
#[derive(Clone, Debug, PartialEq)]
pub enum Word {
    /// The word itself.
    Value(OsString),
    /// `before`, the shard index, then `after`.
    Indexed {
        /// What comes before the index.
        before: OsString,
        /// What follows it.
        after: String,
    },
}

impl Word {
    fn value(text: impl Into<OsString>) -> Word {
        Word::Value(text.into())
    }

    /// The word as shell text, the index read from the variable `index_var`.
    pub fn shell(&self, index_var: &str) -> Result<String, QuoteError> {
        Ok(match self {
            Word::Value(v) => quote::shell_word(v)?,
            Word::Indexed { before, after } => {
                let mut text = String::new();
                if !before.is_empty() {
                    text.push_str(&quote::shell_word(before)?);
                }
                text.push_str(&format!("\"${index_var}\""));
                if !after.is_empty() {
                    text.push_str(&quote::shell_word(OsStr::new(after))?);
                }
                text
            }
        })
    }

    /// The word as the task's shell makes it for shard `index`.
    pub fn with_index(&self, index: u32) -> OsString {
        match self {
            Word::Value(v) => v.clone(),
            Word::Indexed { before, after } => {
                let mut w = before.clone();
                w.push(format!("{index}{after}"));
                w
            }
        }
    }
}

impl Job {
    /// Checks the counts against their limits and every value that goes into a script or
    /// manifest; the error names the flag.
    pub fn check(&self) -> Result<(), FarmError> {
        if self.shards == 0 {
            return Err(FarmError::new("--shards", "must be at least 1"));
        }
        if self.shards > MAX_SHARDS {
            return Err(FarmError::new(
                "--shards",
                format!(
                    "at most {MAX_SHARDS} (Kubernetes' limit on an Indexed Job), got {}",
                    self.shards
                ),
            ));
        }
        crate::settings::limits::passes(self.passes).map_err(|e| FarmError::new("--passes", e))?;
        if self.shards > self.passes {
            return Err(FarmError::new(
                "--shards",
                format!(
                    "{} is more than --passes {}: some shards would render nothing",
                    self.shards, self.passes
                ),
            ));
        }
        if self.threads == 0 || self.threads > MAX_THREADS {
            return Err(FarmError::new(
                "--threads",
                format!("must be between 1 and {MAX_THREADS}, got {}", self.threads),
            ));
        }
        for (flag, path) in [("SCENE", &self.scene), ("--out", &self.out)] {
            if !path.is_absolute() {
                return Err(FarmError::new(
                    flag,
                    format!(
                        "{} must be an absolute path, as every task sees it",
                        quote::comment(path.as_os_str())
                    ),
                ));
            }
        }
        // Every value quotes.
        let values = [("SCENE", self.scene.as_os_str()), ("--out", self.out.as_os_str())]
            .into_iter()
            .chain(self.render_args.iter().map(|a| ("after `--`:", OsStr::new(a))));
        for (flag, value) in values {
            quote::shell_word(value).map_err(|e| FarmError::new(flag, e.to_string()))?;
        }
        for (flag, value) in [
            ("--program", Some(&self.program)),
            ("--image", self.image.as_ref()),
            ("--partition", self.partition.as_ref()),
        ] {
            if let Some(v) = value {
                quote::shell_word(OsStr::new(v)).map_err(|e| FarmError::new(flag, e.to_string()))?;
                if v.is_empty() {
                    return Err(FarmError::new(flag, "must not be empty"));
                }
            }
        }
        Ok(())
    }

    /// The arguments of a shard's `caustic render` (after the program and `render`): the
    /// shard, passes, threads and part file, the further flags, then `--` and the scene, so
    /// that no file name is ever read as a flag.
    pub fn shard_words(&self) -> Vec<Word> {
        let mut words = vec![
            Word::value("--shard"),
            Word::Indexed {
                before: OsString::new(),
                after: format!("/{}", self.shards),
            },
            Word::value(format!("--passes={}", self.passes)),
            Word::value(format!("--threads={}", self.threads)),
            Word::Indexed {
                before: self.out_prefix("--out=", "part_"),
                after: ".exr".into(),
            },
            Word::value("--force"),
        ];
        words.extend(self.render_args.iter().map(Word::value));
        words.push(Word::value("--"));
        words.push(Word::value(self.scene.clone()));
        words
    }

    /// The merge's arguments after `merge`, but for the parts' glob, which [`Job::merge_line`]
    /// writes.
    fn merge_out(&self) -> OsString {
        self.out_prefix("--out=", "image.exr")
    }

    /// `flag`, the output folder, `/` and `name`.
    fn out_prefix(&self, flag: &str, name: &str) -> OsString {
        let mut w = OsString::from(flag);
        w.push(self.out.join(name).as_os_str());
        w
    }

    /// The merge's command line after the program: the parts as a glob the shell expands, the
    /// merged file, `--force`.
    pub fn merge_line(&self) -> Result<String, QuoteError> {
        Ok(format!(
            "merge {}part_*.exr {} --force",
            quote::shell_word(self.out.join("").as_os_str())?,
            quote::shell_word(&self.merge_out())?,
        ))
    }

    /// The shard's command line after the program, the index read from `index_var`.
    pub fn shard_line(&self, index_var: &str) -> Result<String, QuoteError> {
        let words: Vec<String> = self
            .shard_words()
            .iter()
            .map(|w| w.shell(index_var))
            .collect::<Result<_, _>>()?;
        Ok(format!("render {}", words.join(" ")))
    }

    /// The program (and, with an image on Slurm, apptainer before it) as shell text.
    fn runner(&self, apptainer: bool) -> Result<String, QuoteError> {
        let program = quote::shell_word(OsStr::new(&self.program))?;
        Ok(match (&self.image, apptainer) {
            (Some(image), true) => format!(
                "apptainer exec {} {program}",
                quote::shell_word(OsStr::new(image))?
            ),
            _ => program,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    pub(crate) fn job() -> Job {
        Job {
            scene: "/data/scene.toml".into(),
            shards: 4,
            passes: 64,
            out: "/data/out".into(),
            threads: 2,
            program: "caustic".into(),
            image: None,
            partition: None,
            volume_claim: "caustic-data".into(),
            name: "caustic".into(),
            wait: false,
            render_args: vec!["--width".into(), "64".into()],
        }
    }

    #[test]
    fn a_shards_words_are_what_its_shell_makes_of_them() {
        let j = job();
        let words: Vec<OsString> = j.shard_words().iter().map(|w| w.with_index(3)).collect();
        let expected = [
            "--shard",
            "3/4",
            "--passes=64",
            "--threads=2",
            "--out=/data/out/part_3.exr",
            "--force",
            "--width",
            "64",
            "--",
            "/data/scene.toml",
        ];
        assert_eq!(words, expected.map(OsString::from));
        assert_eq!(
            j.shard_line("K").expect("quotes"),
            "render --shard \"$K\"/4 --passes=64 --threads=2 --out=/data/out/part_\"$K\".exr --force --width 64 -- /data/scene.toml"
        );
    }

    #[test]
    fn counts_are_limited() {
        let mut j = job();
        j.shards = 3_000_000_000;
        j.passes = 4_000_000_000;
        let e = j.check().expect_err("too many");
        assert!(e.to_string().contains("--shards at most 100000"), "{e}");
        j.shards = 4;
        let e = j.check().expect_err("too many");
        assert!(
            e.to_string().contains("--passes must be between 1 and 10000000"),
            "{e}"
        );
        j.passes = 64;
        j.out = "relative".into();
        assert!(j.check().expect_err("relative").to_string().contains("absolute"));
    }
}
