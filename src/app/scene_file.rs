//! Saving the edited scene (File → Save scene / Save scene as…) and the question asked before
//! unsaved edits would be lost (opening another scene, closing the window). A scene file is
//! never replaced without the user's confirmation.

use std::path::PathBuf;

use super::action::AfterDiscard;
use super::file_dialog::{take_finished, FileDialog, FileRequest, Finished};
use super::viewer::{Status, Viewer};
use crate::scene::save::save_scene;

impl Viewer {
    /// Does `after` now, or first asks what to do with unsaved edits.
    pub(super) fn unless_unsaved(&mut self, after: AfterDiscard) {
        if self.editor.history.unsaved() {
            self.unsaved_question = Some(after);
        } else {
            self.proceed(after);
        }
    }

    /// Closes the window without asking about unsaved edits (scripted runs).
    pub(super) fn close_discarding_edits(&mut self) {
        self.proceed(AfterDiscard::Close);
    }

    fn proceed(&mut self, after: AfterDiscard) {
        match after {
            AfterDiscard::Open(path) => self.open_scene(path),
            AfterDiscard::Pick => self.pick_scene(),
            AfterDiscard::Close => {
                self.allow_close = true;
                self.ctx.send_viewport_cmd(egui::ViewportCommand::Close);
            }
        }
    }

    /// Answers the unsaved-edits question: discard (`Some(true)`), save first
    /// (`Some(false)`), or cancel (`None`).
    pub(super) fn resolve_unsaved(&mut self, choice: Option<bool>) {
        let Some(after) = self.unsaved_question.take() else {
            return;
        };
        match choice {
            Some(true) => self.proceed(after),
            Some(false) => {
                self.after_save = Some(after);
                self.save_scene();
            }
            None => {}
        }
    }

    /// The scene's own file, when it was opened from one.
    fn scene_file(&self) -> Option<PathBuf> {
        self.scene().base_dir.as_ref()?;
        Some(self.scene().source.clone()).filter(|p| p.is_file())
    }

    /// Saves to the scene's own file (after confirming), or asks where.
    pub(super) fn save_scene(&mut self) {
        match self.scene_file() {
            Some(path) => self.confirm_scene_overwrite = Some(path),
            None => self.pick_scene_file(),
        }
    }

    /// The "save scene as" dialog (on a thread).
    pub(super) fn pick_scene_file(&mut self) {
        if self.scene_dialog.is_some() {
            return;
        }
        let name = match self.scene().source.file_stem() {
            Some(stem) if self.scene().base_dir.is_some() => {
                format!("{}-edited.toml", stem.to_string_lossy())
            }
            _ => "scene.toml".to_owned(),
        };
        let request = FileRequest {
            title: "Save scene".into(),
            filters: vec![("caustic scene".into(), vec!["toml".into()])],
            directory: self.settings.last_directory.clone(),
            file_name: Some(name),
            save: true,
            folder: false,
        };
        let native = self.native_dialog();
        self.scene_dialog = Some(FileDialog::open(
            "caustic-scene-dialog",
            &self.ctx,
            native,
            request,
        ));
    }

    /// Takes the answer of the "save scene as" dialog.
    pub(super) fn poll_scene_dialog(&mut self) {
        match take_finished(&mut self.scene_dialog) {
            Some(Finished::Chosen(path)) => self.save_scene_to(path),
            Some(Finished::Cancelled) => {
                self.after_save = None;
                self.status = Some(Status::Info("Scene not saved".into()));
            }
            Some(Finished::Lost) => {
                self.after_save = None;
                self.status = Some(Status::Error("the file dialog failed".into()));
            }
            None => {}
        }
    }

    /// Saves the scene to `path`, asking first if it exists.
    pub fn save_scene_to(&mut self, path: PathBuf) {
        let path = if path.extension().is_none() {
            path.with_extension("toml")
        } else {
            path
        };
        if path.exists() {
            self.confirm_scene_overwrite = Some(path);
        } else {
            self.write_scene(path, false);
        }
    }

    /// Answers the scene overwrite question.
    pub(super) fn confirm_scene_overwrite(&mut self, replace: bool) {
        let Some(path) = self.confirm_scene_overwrite.take() else {
            return;
        };
        if replace {
            self.write_scene(path, true);
        } else {
            self.after_save = None;
            self.status = Some(Status::Info(format!("{} kept as it was", path.display())));
        }
    }

    fn write_scene(&mut self, path: PathBuf, overwrite: bool) {
        let doc = &self.state.document;
        match save_scene(doc.scene(), doc.loaded_patches(), &path, overwrite) {
            Ok(text) => {
                // The file now holds the scene as edited: it is what "saved" means from here.
                self.state.document.saved_as(&path, text);
                self.editor.history.mark_saved();
                if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
                    self.settings.last_directory = Some(dir.to_path_buf());
                }
                self.status = Some(Status::Info(format!("Saved scene to {}", path.display())));
                if let Some(after) = self.after_save.take() {
                    self.proceed(after);
                }
            }
            Err(e) => {
                self.after_save = None;
                self.status = Some(Status::Error(format!("Scene not saved: {e}")));
            }
        }
    }
}
