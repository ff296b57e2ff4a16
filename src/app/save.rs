//! Saving the current frame: a save dialog (rfd, on a thread so the UI keeps drawing), an
//! overwrite confirmation, and the atomic write ([`Image::save`]) on a background thread.

use std::path::{Path, PathBuf};

use super::file_dialog::{FileDialog, FileRequest, NativeDialog};
use super::job::{Job, Poll};
use crate::render::film::Format;
use crate::render::{Image, Metadata};

/// A frame ready to be written.
#[derive(Clone)]
pub struct Snapshot {
    /// Linear radiance.
    pub image: Image,
    /// Exposure applied to PNG output.
    pub exposure_stops: f32,
    /// Render metadata stored in the file.
    pub metadata: Metadata,
    /// Pass the frame shows (for the status line).
    pub pass: u32,
}

/// A write under way: the job, its path and the pass it writes.
type Write = (Job<Result<(), String>>, PathBuf, u32);

/// Where a save stands.
#[derive(Default)]
pub struct SaveFlow {
    dialog: Option<(FileDialog, Snapshot)>,
    /// A path that exists, waiting for the user to confirm replacing it.
    pub confirm: Option<(PathBuf, Snapshot)>,
    writing: Option<Write>,
}

/// What the flow reports to the status line.
pub enum SaveEvent {
    /// Written.
    Saved {
        /// Where.
        path: PathBuf,
        /// Pass shown by the saved frame.
        pass: u32,
    },
    /// Nothing written, with the reason.
    Failed(String),
    /// The dialog was closed without a choice.
    Cancelled,
}

/// A default file name for a frame: `<scene>-pass<N>.png`.
pub fn default_file_name(scene: &Path, pass: u32) -> String {
    let stem = scene
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .filter(|s| !s.is_empty())
        .unwrap_or_else(|| "caustic".to_owned());
    format!("{stem}-pass{pass}.png")
}

impl SaveFlow {
    /// Whether a dialog, confirmation or write is under way.
    pub fn busy(&self) -> bool {
        self.dialog.is_some() || self.confirm.is_some() || self.writing.is_some()
    }

    /// Opens the save dialog (shown by `native`, or inside the window) for `snapshot`.
    pub fn open_dialog(
        &mut self,
        ctx: &egui::Context,
        native: NativeDialog,
        snapshot: Snapshot,
        directory: Option<PathBuf>,
        file_name: String,
    ) {
        if self.busy() {
            return;
        }
        let request = FileRequest {
            title: "Save frame".into(),
            filters: vec![
                ("PNG image (as displayed)".into(), vec!["png".into()]),
                ("OpenEXR image (linear radiance)".into(), vec!["exr".into()]),
            ],
            directory,
            file_name: Some(file_name),
            save: true,
            folder: false,
        };
        let dialog = FileDialog::open("caustic-save-dialog", ctx, native, request);
        self.dialog = Some((dialog, snapshot));
    }

    /// The open file dialog, if any (the viewer draws it when it is the window's own).
    pub fn file_dialog(&self) -> Option<&FileDialog> {
        self.dialog.as_ref().map(|(d, _)| d)
    }

    /// Saves `snapshot` to `path` (what happens once the dialog returned a path): asks before
    /// replacing an existing file, refuses unknown extensions.
    pub fn save_to(&mut self, ctx: &egui::Context, path: PathBuf, snapshot: Snapshot) -> Option<SaveEvent> {
        if Format::from_path(&path).is_none() {
            return Some(SaveEvent::Failed(format!(
                "{}: choose a file name ending in .png (as displayed) or .exr (linear radiance)",
                path.display()
            )));
        }
        if path.exists() {
            self.confirm = Some((path, snapshot));
            return None;
        }
        self.write(ctx, path, snapshot, false);
        None
    }

    /// The user's answer to the overwrite question.
    pub fn confirm_overwrite(&mut self, ctx: &egui::Context, replace: bool) -> Option<SaveEvent> {
        let (path, snapshot) = self.confirm.take()?;
        if replace {
            self.write(ctx, path, snapshot, true);
            None
        } else {
            Some(SaveEvent::Cancelled)
        }
    }

    fn write(&mut self, ctx: &egui::Context, path: PathBuf, snapshot: Snapshot, overwrite: bool) {
        let (p, pass) = (path.clone(), snapshot.pass);
        let job = Job::spawn("caustic-save", ctx, move || {
            snapshot
                .image
                .save(&p, snapshot.exposure_stops, &snapshot.metadata, overwrite)
                .map_err(|e| e.to_string())
        });
        self.writing = Some((job, path, pass));
    }

    /// Advances the flow; returns what finished this frame.
    pub fn poll(&mut self, ctx: &egui::Context) -> Option<SaveEvent> {
        if let Some((job, _)) = &self.dialog {
            match job.poll() {
                Poll::Pending => {}
                Poll::Ready(choice) => {
                    let (_, snapshot) = self.dialog.take()?;
                    return match choice {
                        Some(path) => self.save_to(ctx, path, snapshot),
                        None => Some(SaveEvent::Cancelled),
                    };
                }
                Poll::Lost => {
                    self.dialog = None;
                    return Some(SaveEvent::Failed("the file dialog failed".to_owned()));
                }
            }
        }
        if let Some((job, path, pass)) = &self.writing {
            let event = match job.poll() {
                Poll::Pending => return None,
                Poll::Ready(Ok(())) => SaveEvent::Saved {
                    path: path.clone(),
                    pass: *pass,
                },
                Poll::Ready(Err(e)) => SaveEvent::Failed(e),
                Poll::Lost => SaveEvent::Failed(format!("writing {} failed", path.display())),
            };
            self.writing = None;
            return Some(event);
        }
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn default_names_use_the_scene_stem() {
        assert_eq!(
            default_file_name(Path::new("scenes/cornell.toml"), 12),
            "cornell-pass12.png"
        );
        assert_eq!(default_file_name(Path::new(""), 3), "caustic-pass3.png");
    }
}
