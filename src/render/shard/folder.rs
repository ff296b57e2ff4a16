//! A render folder's parts merged as they land ([`FolderMerge`]): what `caustic view --watch
//! DIR` shows while a farm renders into `DIR`.
//!
//! Each scan lists the folder's `.exr` files (hidden ones, such as a part being written under
//! its temporary name, are left out) and reads the header of those that are new or changed
//! (by size and modification time): which render each belongs to ([`RenderKey`]) and which
//! passes it holds. The folder's parts are grouped by render, and the render shown is the one
//! the user chose ([`FolderMerge::choose`]) or else the one most parts belong to (then the
//! one with most passes) — never whichever file sorts first, so a stray part of another scene
//! cannot take the folder over. Its parts' sums are merged; every other file is skipped with
//! a message, once, when it is first read or when the render shown changes: a part of
//! another render, one that cannot be read (half written by a copy, not a part). A part whose
//! passes are all merged already (the farm's own merged image beside its parts) adds nothing.
//! A merged part rewritten in place (a shard run again) or removed makes the next scan merge
//! everything again, since its old passes cannot be told from its new ones.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::time::SystemTime;

use super::part::{PartHeader, RenderKey};
use super::Part;
use crate::render::provenance;

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

/// What became of a file.
#[derive(Clone, Debug, PartialEq, Eq)]
enum Fate {
    /// Not yet decided (its render is not the one shown, or it is new).
    Pending,
    /// Its sums are in the merge.
    Merged,
    /// All of its passes were already in the merge.
    Redundant,
    /// Skipped, for this reason (told once).
    Skipped(String),
}

/// A file of the folder: how it looked, its header (or why it has none), what became of it.
struct Entry {
    seen: Seen,
    header: Result<PartHeader, String>,
    fate: Fate,
}

/// One render whose parts are in the folder, for the viewer's choice.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct RenderInFolder {
    /// What identifies it.
    pub key: RenderKey,
    /// In words: the scene file, size, passes and the scene text's hash.
    pub label: String,
    /// Part files of it.
    pub parts: usize,
    /// Distinct passes those parts hold.
    pub passes: usize,
}

/// The parts of one render folder, merged.
#[derive(Default)]
pub struct FolderMerge {
    files: BTreeMap<PathBuf, Entry>,
    /// The render the user chose to see, if any.
    chosen: Option<RenderKey>,
    /// The merge so far: its render, the file it started from, the sums.
    merged: Option<(RenderKey, PathBuf, Part)>,
    /// Bumped whenever the merge changes.
    generation: u64,
    /// Bumped whenever the merge starts again from nothing.
    rebuilds: u64,
}

/// A scan's result: what changed, and the messages of files skipped in this scan.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ScanReport {
    /// Whether the merge changed (a new image to show).
    pub changed: bool,
    /// Files skipped in this scan, each with its reason (file name first).
    pub skipped: Vec<String>,
}

/// `path`'s file name, for messages.
fn name_of(path: &Path) -> String {
    path.file_name().map_or_else(
        || path.display().to_string(),
        |n| n.to_string_lossy().into_owned(),
    )
}

impl FolderMerge {
    /// Nothing read yet.
    pub fn new() -> Self {
        Self::default()
    }

    /// The merge so far (`None` before the first part).
    pub fn merged(&self) -> Option<&Part> {
        self.merged.as_ref().map(|(_, _, p)| p)
    }

    /// The first file merged of the render shown (its scene is the render's).
    pub fn first_part(&self) -> Option<&Path> {
        self.merged.as_ref().map(|(_, p, _)| p.as_path())
    }

    /// The render shown, and whether the user chose it.
    pub fn shown(&self) -> Option<(&RenderKey, bool)> {
        self.merged
            .as_ref()
            .map(|(k, _, _)| (k, self.chosen.as_ref() == Some(k)))
    }

    /// Increases whenever the merge changes.
    pub fn generation(&self) -> u64 {
        self.generation
    }

    /// Increases whenever the merge starts again from nothing (another render shown, a merged
    /// part rewritten or gone); between two, each change adds passes.
    pub fn rebuilds(&self) -> u64 {
        self.rebuilds
    }

    /// Files merged so far.
    pub fn parts_merged(&self) -> usize {
        self.files.values().filter(|e| e.fate == Fate::Merged).count()
    }

    /// Shows the render `key` from the next scan on, whatever most parts belong to; `None`
    /// goes back to the render of most parts.
    pub fn choose(&mut self, key: Option<RenderKey>) {
        self.chosen = key;
    }

    /// Every render with parts in the folder, the one of most parts first.
    pub fn renders(&self) -> Vec<RenderInFolder> {
        let mut groups: BTreeMap<&RenderKey, (usize, Vec<u32>, &PartHeader)> = BTreeMap::new();
        for header in self.files.values().filter_map(|e| e.header.as_ref().ok()) {
            let group = groups.entry(&header.key).or_insert((0, Vec::new(), header));
            group.0 += 1;
            group.1.extend(&header.passes);
        }
        let mut renders: Vec<RenderInFolder> = groups
            .into_iter()
            .map(|(key, (parts, mut passes, header))| {
                passes.sort_unstable();
                passes.dedup();
                RenderInFolder {
                    key: key.clone(),
                    label: label(header),
                    parts,
                    passes: passes.len(),
                }
            })
            .collect();
        renders.sort_by(|a, b| (b.parts, b.passes, &a.key).cmp(&(a.parts, a.passes, &b.key)));
        renders
    }

    /// The render to show: the chosen one, or the one of most parts (then most passes).
    fn render_to_show(&self) -> Option<RenderKey> {
        self.chosen
            .clone()
            .or_else(|| self.renders().into_iter().next().map(|r| r.key))
    }

    /// Reads what is new or changed in `dir` and merges it.
    pub fn scan(&mut self, dir: &Path) -> Result<ScanReport, String> {
        let mut report = ScanReport::default();
        let listed = list_parts(dir)?;
        // Forget files that went away; a merged one makes the merge start again.
        let before = self.files.len();
        let mut lost_merged = false;
        self.files.retain(|path, entry| {
            let kept = listed.contains_key(path);
            lost_merged |= !kept && entry.fate == Fate::Merged;
            kept
        });
        let mut new = self.files.len() != before;
        for (path, seen) in listed {
            if self.files.get(&path).is_some_and(|e| e.seen == seen) {
                continue;
            }
            let header = PartHeader::read(&path).map_err(|e| e.message);
            let old = self.files.insert(
                path,
                Entry {
                    seen,
                    header,
                    fate: Fate::Pending,
                },
            );
            lost_merged |= old.is_some_and(|e| e.fate == Fate::Merged);
            new = true;
        }
        let show = self.render_to_show();
        let current = self.merged.as_ref().map(|(key, _, _)| key.clone());
        if lost_merged || show != current {
            // Another render to show, or a merged part rewritten or gone: merge again.
            if self.merged.take().is_some() {
                report.changed = true;
                self.rebuilds += 1;
            }
            for entry in self.files.values_mut() {
                if entry.fate == Fate::Merged || entry.fate == Fate::Redundant {
                    entry.fate = Fate::Pending;
                }
            }
            new = true;
        }
        if new {
            self.decide(show.as_ref(), &mut report);
        }
        if report.changed {
            self.generation += 1;
        }
        Ok(report)
    }

    /// Merges the pending files of render `show` and skips, with a message, the pending files
    /// of other renders and those that cannot be read.
    fn decide(&mut self, show: Option<&RenderKey>, report: &mut ScanReport) {
        let paths: Vec<PathBuf> = self.files.keys().cloned().collect();
        for path in paths {
            let Some(entry) = self.files.get(&path) else {
                continue;
            };
            let fate = match (&entry.fate, &entry.header) {
                (Fate::Pending, Err(why)) => Fate::Skipped(format!("{}: {why}", name_of(&path))),
                (Fate::Pending, Ok(h)) if Some(&h.key) != show => {
                    Fate::Skipped(format!("{}: {}", name_of(&path), other_render(h, show)))
                }
                (Fate::Pending, Ok(_)) => self.take(&path),
                // Skipped before: told once, until the render shown changes.
                (Fate::Skipped(why), Ok(h)) if Some(&h.key) != show => Fate::Skipped(why.clone()),
                (Fate::Skipped(_), Ok(_)) => self.take(&path),
                (fate, _) => fate.clone(),
            };
            let changed = entry_fate(&self.files, &path) != Some(&fate);
            match (&fate, changed) {
                (Fate::Skipped(why), true) => report.skipped.push(why.clone()),
                (Fate::Redundant, true) => report.skipped.extend(self.redundant(&path)),
                _ => {}
            }
            report.changed |= changed && fate == Fate::Merged;
            if let Some(e) = self.files.get_mut(&path) {
                e.fate = fate;
            }
        }
    }

    /// Why the part at `path` added nothing: every one of its passes was merged already
    /// (from other parts), and whether the render was complete before it came. `None` for a
    /// file that holds the whole render (the farm's own merge beside its parts), which is
    /// expected there.
    fn redundant(&self, path: &Path) -> Option<String> {
        let header = self.files.get(path)?.header.as_ref().ok()?;
        if header.passes.len() as u64 == u64::from(header.total_passes) {
            return None;
        }
        let complete = self.merged.as_ref().is_some_and(|(_, _, m)| m.is_complete());
        let when = if complete {
            "the render is complete"
        } else {
            "other parts hold them"
        };
        Some(format!(
            "{}: adds nothing: its passes are merged already ({when})",
            name_of(path)
        ))
    }

    /// Reads `path` (of the render shown) and merges it.
    fn take(&mut self, path: &Path) -> Fate {
        let part = match Part::read(path) {
            Ok(p) => p,
            Err(e) => return Fate::Skipped(format!("{}: {}", name_of(path), e.message)),
        };
        let key = self
            .files
            .get(path)
            .and_then(|e| e.header.as_ref().ok())
            .map(|h| h.key.clone());
        let Some((_, first, merged)) = &mut self.merged else {
            self.merged = key.map(|k| (k, path.to_owned(), part));
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
            Err(e) => Fate::Skipped(format!("{}: not merged: {}", name_of(path), e.what)),
        }
    }
}

/// The fate `path` had before this decision.
fn entry_fate<'a>(files: &'a BTreeMap<PathBuf, Entry>, path: &Path) -> Option<&'a Fate> {
    files.get(path).map(|e| &e.fate)
}

/// The folder's visible `.exr` files, with how each looks now.
fn list_parts(dir: &Path) -> Result<BTreeMap<PathBuf, Seen>, String> {
    let read = std::fs::read_dir(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    Ok(read
        .flatten()
        .map(|e| e.path())
        .filter(|p| {
            !name_of(p).starts_with('.') && p.extension().is_some_and(|e| e.eq_ignore_ascii_case("exr"))
        })
        .filter_map(|p| Some((p.clone(), Seen::of(&p)?)))
        .collect())
}

/// A render in words, from one of its parts' headers.
fn label(h: &PartHeader) -> String {
    let scene = h.get(provenance::SCENE).map_or("a scene".into(), |s| {
        Path::new(s)
            .file_name()
            .map_or(s.to_owned(), |n| n.to_string_lossy().into_owned())
    });
    format!(
        "{scene}, {}x{}, {} passes (scene {})",
        h.size.0,
        h.size.1,
        h.total_passes,
        h.key.scene_hash.get(..8).unwrap_or(&h.key.scene_hash)
    )
}

/// Why a part of another render is not merged: what differs from the render shown.
fn other_render(h: &PartHeader, show: Option<&RenderKey>) -> String {
    let Some(show) = show else {
        return format!("not merged: a part of another render ({})", label(h));
    };
    let k = &h.key;
    let what = if k.software != show.software {
        format!("written by {}, the render shown by {}", k.software, show.software)
    } else if k.size != show.size {
        format!(
            "image size {}x{}, the render shown is {}x{}",
            k.size.0, k.size.1, show.size.0, show.size.1
        )
    } else if k.settings != show.settings {
        format!(
            "render settings differ: {}",
            super::part::settings_difference(&show.settings, &k.settings)
        )
    } else if k.scene_hash != show.scene_hash {
        format!(
            "scenes differ (scene text hash {} and {})",
            show.scene_hash, k.scene_hash
        )
    } else {
        format!(
            "a render of {} passes, the render shown has {}",
            k.total_passes, show.total_passes
        )
    };
    format!("not merged: a part of another render ({}): {what}", label(h))
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
