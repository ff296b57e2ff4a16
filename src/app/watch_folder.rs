//! What the viewer does with a watched render folder ([`super::watch`]): the folder dialog,
//! starting and stopping the watch, and each update — the merged image shown as the frame,
//! the render's scene loaded from its first part (so the overlay and the probe match), the
//! skipped parts' messages in the status bar.

use std::path::{Path, PathBuf};

use super::file_dialog::{take_finished, FileDialog, FileRequest, Finished};
use super::state::Status;
use super::viewer::Viewer;
use super::watch::FolderWatch;
use crate::render::provenance::Recorded;

impl Viewer {
    /// Shows the folder dialog for a render folder to watch (on a thread).
    pub fn pick_watch_folder(&mut self) {
        if self.watch_picking.is_some() {
            return;
        }
        let request = FileRequest {
            title: "Watch a render folder".into(),
            filters: Vec::new(),
            directory: self.settings.last_directory.clone(),
            file_name: None,
            save: false,
            folder: true,
        };
        let native = self.native_dialog();
        self.watch_picking = Some(FileDialog::open(
            "caustic-watch-dialog",
            &self.ctx,
            native,
            request,
        ));
    }

    /// Watches `dir`: the renderer pauses, and the parts a farm writes there are merged and
    /// shown as they land.
    pub fn watch_folder(&mut self, dir: PathBuf) {
        if !dir.is_dir() {
            self.status = Some(Status::Error(format!(
                "Not watching {}: no such folder",
                dir.display()
            )));
            return;
        }
        let mut p = self.params();
        p.paused = true;
        self.set_params(p);
        self.frame = None;
        self.convergence.reset();
        self.image_view.invalidate();
        let ctx = self.ctx.clone();
        self.watch = Some(FolderWatch::start(&dir, move || ctx.request_repaint()));
        self.watch_scene_from = None;
        self.settings.last_directory = Some(dir.clone());
        self.status = Some(Status::Info(format!(
            "Watching {} for parts of a render",
            dir.display()
        )));
        self.watching = Some(super::watch::WatchSummary {
            dir,
            passes: 0,
            total: 0,
            parts: 0,
            photons: 0,
            renderer: crate::settings::RendererKind::Ppm,
            relative_error: None,
            first_part: None,
            renders: Vec::new(),
            shown: None,
        });
    }

    /// Shows render `key` of the watched folder (`None`: the one most parts belong to).
    pub fn watch_render(&mut self, key: Option<crate::render::shard::RenderKey>) {
        if let Some(w) = &self.watch {
            w.choose(key);
        }
    }

    /// Stops watching and renders the scene again.
    pub fn stop_watching(&mut self) {
        if let Some(w) = self.watch.take() {
            self.status = Some(Status::Info(format!("Stopped watching {}", w.dir().display())));
        }
        self.watching = None;
        self.panel.paused = false;
        self.restart_renderer();
    }

    /// Takes the folder dialog's answer and the watch's updates; call once per UI frame.
    pub(super) fn poll_watch(&mut self) {
        match take_finished(&mut self.watch_picking) {
            Some(Finished::Chosen(dir)) => self.watch_folder(dir),
            Some(Finished::Lost) => self.status = Some(Status::Error("the folder dialog failed".into())),
            Some(Finished::Cancelled) | None => {}
        }
        let Some(watch) = &self.watch else { return };
        for update in watch.updates() {
            if let Some(first) = &update.summary.first_part {
                if self.watch_scene_from.as_deref() != Some(first.as_path()) {
                    self.watch_scene_from = Some(first.clone());
                    self.load_watched_scene(first);
                }
            }
            if let Some(e) = &update.error {
                self.status = Some(Status::Error(format!("Watching: {e}")));
            } else if let Some(skipped) = update.skipped.last() {
                let more = match update.skipped.len() {
                    1 => String::new(),
                    n => format!(" (and {} more)", n - 1),
                };
                self.status = Some(Status::Error(format!("Skipped {skipped}{more}")));
            }
            if let Some(mut frame) = update.frame {
                // Watched images follow whatever the paused session showed.
                frame.epoch += self.watch_epoch_base;
                self.show_frame(frame);
            }
            self.watching = Some(update.summary);
        }
    }

    /// Shows the scene the watched render records (its first part's scene text), paused, so
    /// the overlay, the probe and a saved frame's metadata are the render's.
    fn load_watched_scene(&mut self, part: &Path) {
        match Recorded::read(part) {
            Ok(recorded) => {
                self.replace_scene_paused(recorded.scene);
                self.watch_epoch_base = 1 << 32;
            }
            Err(e) => self.status = Some(Status::Error(format!("The render's scene: {e}"))),
        }
    }
}
