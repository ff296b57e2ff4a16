//! A render folder's parts merged as they land ([`FolderMerge`]): what `caustic view --watch
//! DIR` shows while a farm renders into `DIR`.
//!
//! Each scan lists the folder's `.exr` files (hidden ones, such as a part being written under
//! its temporary name, are left out) and reads those that are new or changed (by size and
//! modification time). The first part accepted fixes the render; a part of another render, or
//! one that cannot be read (half written by a copy, not a part), is skipped with a message,
//! and read again only once it changes. A part whose passes are already merged (the farm's
//! own merged image beside its parts) adds nothing. A part rewritten in place (a shard run
//! again) makes the next scan merge everything again, since its old passes cannot be told
//! from its new ones.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::time::SystemTime;

use super::Part;

/// What a file looked like when it was last read.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Seen {
    len: u64,
    modified: Option<SystemTime>,
}

impl Seen {
    /// How the file at `path` looks now (`None`: not a file).
    fn of(path: &Path) -> Option<Seen> {
        let meta = std::fs::metadata(path).ok().filter(|m| m.is_file())?;
        Some(Seen {
            len: meta.len(),
            modified: meta.modified().ok(),
        })
    }
}

/// What became of a file at its last reading.
#[derive(Clone, Debug, PartialEq, Eq)]
enum Fate {
    /// Its sums are in the merge.
    Merged,
    /// All of its passes were already in the merge.
    Redundant,
    /// Skipped, for this reason.
    Skipped(String),
}

/// The parts of one render folder, merged.
#[derive(Default)]
pub struct FolderMerge {
    files: BTreeMap<PathBuf, (Seen, Fate)>,
    /// The merge so far, and the file whose render it is.
    merged: Option<(PathBuf, Part)>,
    /// Bumped whenever the merge changes.
    generation: u64,
}

/// A scan's result: what changed, and the messages of files skipped in this scan.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ScanReport {
    /// Whether the merge changed (a new image to show).
    pub changed: bool,
    /// Files skipped in this scan, each with its reason (file name first).
    pub skipped: Vec<String>,
}

impl FolderMerge {
    /// Nothing read yet.
    pub fn new() -> Self {
        Self::default()
    }

    /// The merge so far (`None` before the first part).
    pub fn merged(&self) -> Option<&Part> {
        self.merged.as_ref().map(|(_, p)| p)
    }

    /// The file that fixed which render is merged.
    pub fn first_part(&self) -> Option<&Path> {
        self.merged.as_ref().map(|(p, _)| p.as_path())
    }

    /// Increases whenever the merge changes.
    pub fn generation(&self) -> u64 {
        self.generation
    }

    /// Files merged so far.
    pub fn parts_merged(&self) -> usize {
        self.files.values().filter(|(_, f)| *f == Fate::Merged).count()
    }

    /// Reads what is new or changed in `dir` and merges it.
    pub fn scan(&mut self, dir: &Path) -> Result<ScanReport, String> {
        let read = std::fs::read_dir(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
        // Each file looked at once a scan.
        let mut files: Vec<(PathBuf, Seen)> = read
            .flatten()
            .map(|e| e.path())
            .filter(|p| {
                let name = p
                    .file_name()
                    .map(|n| n.to_string_lossy().into_owned())
                    .unwrap_or_default();
                !name.starts_with('.') && p.extension().is_some_and(|e| e.eq_ignore_ascii_case("exr"))
            })
            .filter_map(|p| Some((p.clone(), Seen::of(&p)?)))
            .collect();
        files.sort_by(|a, b| a.0.cmp(&b.0));
        let mut report = ScanReport::default();
        let rewritten = files
            .iter()
            .any(|(p, now)| matches!(self.files.get(p), Some((seen, Fate::Merged)) if now != seen))
            || self
                .files
                .iter()
                .any(|(p, (_, f))| *f == Fate::Merged && files.binary_search_by(|(q, _)| q.cmp(p)).is_err());
        if rewritten {
            // A merged part changed or went away: merge everything again.
            self.files.clear();
            self.merged = None;
            report.changed = true;
        }
        for (path, seen) in files {
            if self.files.get(&path).is_some_and(|(s, _)| *s == seen) {
                continue;
            }
            let fate = self.take(&path);
            if let Fate::Skipped(why) = &fate {
                report.skipped.push(why.clone());
            }
            report.changed |= fate == Fate::Merged;
            self.files.insert(path, (seen, fate));
        }
        if report.changed {
            self.generation += 1;
        }
        Ok(report)
    }

    /// Reads `path` and merges it if it belongs.
    fn take(&mut self, path: &Path) -> Fate {
        let name = path.file_name().map_or_else(
            || path.display().to_string(),
            |n| n.to_string_lossy().into_owned(),
        );
        let part = match Part::read(path) {
            Ok(p) => p,
            Err(e) => return Fate::Skipped(format!("{name}: {}", e.message)),
        };
        let Some((first, merged)) = &mut self.merged else {
            self.merged = Some((path.to_owned(), part));
            return Fate::Merged;
        };
        if part
            .sums
            .passes()
            .iter()
            .all(|p| merged.sums.passes().binary_search(p).is_ok())
        {
            return Fate::Redundant;
        }
        match merged.merge(first, &part, path) {
            Ok(()) => Fate::Merged,
            Err(e) => Fate::Skipped(format!("{name}: not merged: {}", e.what)),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_empty_or_missing_folder() {
        let dir = tempfile::tempdir().expect("temp dir");
        let mut f = FolderMerge::new();
        assert_eq!(f.scan(dir.path()), Ok(ScanReport::default()));
        assert!(f.merged().is_none());
        assert!(f.scan(&dir.path().join("nope")).is_err());
    }
}
