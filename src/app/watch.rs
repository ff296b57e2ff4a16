//! Watching a render folder (`caustic view --watch DIR`, File → Watch a render folder…): a
//! thread scans the folder a few times a second ([`FolderMerge`]), merges the parts a farm
//! writes there as they land or are rewritten, and hands the viewer the merged image with
//! the passes done out of the render's total and the error estimate the passes' spread gives
//! ([`crate::render::shard::PassSums::relative_error`]). Parts it skips come with a message
//! for the status bar.

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

use crossbeam_channel::{unbounded, Receiver, Sender};

use crate::render::frame::{ErrorSource, FrameStats, StatRow};
use crate::render::session::Frame;
use crate::render::shard::{FolderMerge, RenderInFolder, RenderKey};
use crate::settings::RendererKind;

/// How often the folder is scanned.
pub const SCAN_INTERVAL: Duration = Duration::from_millis(250);

/// Where a watched render stands.
#[derive(Clone, Debug, PartialEq)]
pub struct WatchSummary {
    /// The folder.
    pub dir: PathBuf,
    /// Passes merged.
    pub passes: usize,
    /// Passes of the whole render (0 before the first part).
    pub total: u32,
    /// Part files merged.
    pub parts: usize,
    /// Photons the merged passes emitted (VCM: light subpaths).
    pub photons: u64,
    /// The renderer of the merged passes (photon mapping before the first part).
    pub renderer: RendererKind,
    /// The estimated relative error of the image (at least two passes).
    pub relative_error: Option<f64>,
    /// The first file merged of the render shown.
    pub first_part: Option<PathBuf>,
    /// Every render with parts in the folder, the one of most parts first.
    pub renders: Vec<RenderInFolder>,
    /// The render shown, and whether the user chose it (else it is the one of most parts).
    pub shown: Option<(RenderKey, bool)>,
}

/// What the watching thread sends after a scan that changed something.
pub struct WatchUpdate {
    /// Where the render stands.
    pub summary: WatchSummary,
    /// The merged image (with the merge's rebuilds as its epoch), when it changed.
    pub frame: Option<Frame>,
    /// Files skipped in the scan, each with its reason.
    pub skipped: Vec<String>,
    /// The folder could not be read.
    pub error: Option<String>,
}

/// A folder being watched: stop it by dropping it.
pub struct FolderWatch {
    dir: PathBuf,
    updates: Receiver<WatchUpdate>,
    choices: Sender<Option<RenderKey>>,
    stop: Arc<AtomicBool>,
}

impl FolderWatch {
    /// Starts watching `dir`; `wake` is called after each update is sent (the viewer asks
    /// for a repaint).
    pub fn start(dir: &Path, wake: impl Fn() + Send + 'static) -> Self {
        let (tx, updates) = unbounded();
        let (choices, chosen) = unbounded::<Option<RenderKey>>();
        let stop = Arc::new(AtomicBool::new(false));
        let (thread_stop, thread_dir) = (stop.clone(), dir.to_owned());
        let _ = std::thread::Builder::new()
            .name("caustic-watch".into())
            .spawn(move || {
                let started = Instant::now();
                let mut merge = FolderMerge::new();
                let mut last_error = None;
                let mut last_renders = Vec::new();
                while !thread_stop.load(Ordering::Relaxed) {
                    for key in chosen.try_iter() {
                        merge.choose(key);
                    }
                    let update = scan(&mut merge, &thread_dir, started);
                    let error_changed = update.error != last_error;
                    last_error = update.error.clone();
                    let renders_changed = update.summary.renders != last_renders;
                    last_renders = update.summary.renders.clone();
                    if update.frame.is_some()
                        || !update.skipped.is_empty()
                        || error_changed
                        || renders_changed
                    {
                        if tx.send(update).is_err() {
                            break;
                        }
                        wake();
                    }
                    std::thread::sleep(SCAN_INTERVAL);
                }
            });
        Self {
            dir: dir.to_owned(),
            updates,
            choices,
            stop,
        }
    }

    /// Shows render `key` of the folder from the next scan on (`None`: the one most parts
    /// belong to).
    pub fn choose(&self, key: Option<RenderKey>) {
        let _ = self.choices.send(key);
    }

    /// The folder.
    pub fn dir(&self) -> &Path {
        &self.dir
    }

    /// The updates sent since the last call.
    pub fn updates(&self) -> Vec<WatchUpdate> {
        self.updates.try_iter().collect()
    }
}

impl Drop for FolderWatch {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::Relaxed);
    }
}

/// One scan of `dir` into `merge`, as an update.
pub fn scan(merge: &mut FolderMerge, dir: &Path, started: Instant) -> WatchUpdate {
    let (report, error) = match merge.scan(dir) {
        Ok(r) => (r, None),
        Err(e) => (Default::default(), Some(e)),
    };
    let summary = WatchSummary {
        dir: dir.to_owned(),
        passes: merge.merged().map_or(0, |p| p.sums.passes().len()),
        total: merge.merged().map_or(0, |p| p.total_passes),
        parts: merge.parts_merged(),
        photons: merge.merged().map_or(0, |p| p.sums.photons()),
        renderer: merge.merged().map_or(RendererKind::Ppm, |p| p.renderer()),
        relative_error: merge.merged().and_then(|p| p.sums.relative_error()),
        first_part: merge.first_part().map(Path::to_owned),
        renders: merge.renders(),
        shown: merge.shown().map(|(k, chosen)| (k.clone(), chosen)),
    };
    let frame = match merge.merged() {
        // One epoch a rebuild: frames within it grow pass by pass, so the error plot keeps
        // their estimates.
        Some(part) if report.changed => Some(merged_frame(part, &summary, merge.rebuilds(), started)),
        _ => None,
    };
    WatchUpdate {
        summary,
        frame,
        skipped: report.skipped,
        error,
    }
}

/// The merged image as a frame of epoch `rebuilds`.
fn merged_frame(
    part: &crate::render::shard::Part,
    summary: &WatchSummary,
    rebuilds: u64,
    started: Instant,
) -> Frame {
    let stats = FrameStats {
        kind: summary.renderer,
        seconds: 0.0,
        summary: Vec::new(),
        skipped: Vec::new(),
        json: serde_json::json!({ "watched_folder": { "passes": summary.passes, "total": summary.total, "photons": summary.photons } }),
        metadata: vec![
            (
                crate::render::provenance::PASSES.into(),
                summary.passes.to_string(),
            ),
            ("caustic:photons".into(), summary.photons.to_string()),
        ],
        progress: String::new(),
        rows: vec![
            StatRow::new(
                "Passes merged",
                format!("{} of {}", summary.passes, summary.total),
                "Passes of the watched render merged from the folder's parts",
            ),
            StatRow::new("Parts", summary.parts.to_string(), "Part files merged"),
            StatRow::new(
                "Error estimate",
                summary
                    .relative_error
                    .map_or("-".into(), |e| format!("{:.2} %", 100.0 * e)),
                "Relative RMS error of the image, estimated from the spread of its independent passes",
            ),
        ],
    };
    let mut frame = Frame::of_radiance(
        part.sums.size(),
        part.sums.mean(),
        summary.passes as u32,
        (rebuilds, started.elapsed().as_secs_f64()),
        stats,
    );
    frame.photons = summary.photons;
    frame.error = ErrorSource::PassSpread(summary.relative_error);
    frame
}
