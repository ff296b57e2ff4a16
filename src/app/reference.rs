//! Comparing the live render with a reference image (an EXR or PFM: another program's
//! converged render, or a long run of this one), opened from the File menu, by dropping the
//! file on the window or with `caustic view --reference FILE`. While one is open, the
//! convergence plot adds the true error against it, the View menu offers the difference views
//! ([`super::difference`]) and `B` flips between the render and the reference (A/B). This
//! file holds the reference and its loading; opening, closing and showing it are the viewer's
//! (`reference_files.rs`).

use std::path::PathBuf;

use super::file_dialog::FileDialog;
use super::job::Job;
use crate::render::compare::Reference;

/// The reference and its loading.
#[derive(Default)]
pub struct ReferenceState {
    /// The open reference.
    pub(super) open: Option<Reference>,
    /// Shows the reference instead of the render (the A/B toggle).
    pub(super) show_reference: bool,
    pub(super) picking: Option<FileDialog>,
    pub(super) loading: Option<(Job<Result<Reference, String>>, PathBuf)>,
}

/// Whether a file is one the viewer opens as a reference (by its extension).
pub fn is_reference_file(path: &std::path::Path) -> bool {
    path.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("exr") || e.eq_ignore_ascii_case("pfm"))
}

impl ReferenceState {
    /// Whether a dialog or a load is under way.
    pub fn busy(&self) -> bool {
        self.picking.is_some() || self.loading.is_some()
    }
}
