//! Opening a reference image (dialog, load on a thread), closing it and showing it instead of
//! the render: what the viewer does with [`super::reference::ReferenceState`].

use std::path::PathBuf;

use super::file_dialog::{take_finished, FileDialog, FileRequest, Finished};
use super::job::{Job, Poll};
use super::state::Status;
use super::viewer::Viewer;
use crate::render::compare::Reference;

impl Viewer {
    /// Reads `path` as the reference (on a thread); the result shows in the status bar.
    pub fn open_reference(&mut self, path: PathBuf) {
        let p = path.clone();
        let job = Job::spawn("caustic-reference", &self.ctx, move || {
            Reference::open(&p).map_err(|e| e.to_string())
        });
        self.reference.loading = Some((job, path));
    }

    /// Shows the open dialog for a reference (on a thread).
    pub fn pick_reference(&mut self) {
        if self.reference.picking.is_some() {
            return;
        }
        let request = FileRequest {
            title: "Open reference image".into(),
            filters: vec![("OpenEXR or PFM".into(), vec!["exr".into(), "pfm".into()])],
            directory: self.settings.last_directory.clone(),
            file_name: None,
            save: false,
            folder: false,
        };
        let native = self.native_dialog();
        self.reference.picking = Some(FileDialog::open(
            "caustic-reference-dialog",
            &self.ctx,
            native,
            request,
        ));
    }

    /// Closes the reference (the difference views fall back to the radiance).
    pub fn close_reference(&mut self) {
        if let Some(r) = self.reference.open.take() {
            self.status = Some(Status::Info(format!("Closed the reference {}", r.path.display())));
        }
        self.reference.show_reference = false;
        self.convergence.clear_reference();
        self.image_view.invalidate();
    }

    /// Shows the reference instead of the render, or the render again.
    pub fn show_reference(&mut self, on: bool) {
        self.reference.show_reference = on && self.reference.open.is_some();
        self.image_view.invalidate();
    }

    /// Takes a finished dialog or load; call once per UI frame.
    pub(super) fn poll_reference(&mut self) {
        match take_finished(&mut self.reference.picking) {
            Some(Finished::Chosen(path)) => self.open_reference(path),
            Some(Finished::Lost) => self.status = Some(Status::Error("the file dialog failed".into())),
            Some(Finished::Cancelled) | None => {}
        }
        let Some((job, path)) = &self.reference.loading else {
            return;
        };
        let result = match job.poll() {
            Poll::Pending => return,
            Poll::Ready(r) => r,
            Poll::Lost => Err(format!("{}: reading failed unexpectedly", path.display())),
        };
        self.reference.loading = None;
        match result {
            Ok(reference) => self.set_reference(reference),
            Err(e) => self.status = Some(Status::Error(format!("Reference not opened: {e}"))),
        }
    }

    /// Compares with `reference` from now on, if it has the scene's image size (else the
    /// status bar says why not and any open reference stays).
    pub fn set_reference(&mut self, reference: Reference) {
        let (w, h) = (self.scene().camera.width, self.scene().camera.height);
        if let Err(e) = reference.check_size(w, h) {
            self.status = Some(Status::Error(format!("Reference not opened: {e}")));
            return;
        }
        self.remember_folder_of(&reference.path);
        self.status = Some(Status::Info(format!(
            "Comparing with the reference {} (B: A/B, D: difference views)",
            reference.path.display()
        )));
        self.reference.open = Some(reference);
        self.convergence.clear_reference();
        if let Some(errors) = self.reference_errors() {
            let secs = self.frame.as_ref().map_or(0.0, |f| f.elapsed_secs);
            self.convergence.add_reference(secs, errors);
        }
        self.image_view.invalidate();
    }
}
