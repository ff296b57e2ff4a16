//! The viewer's state: everything its widgets read (the scene being edited — the
//! [`Document`] —, the panel's own choices, the newest frame, the edits, the open questions and flows, the messages), apart from what runs it
//! (the render session, the dialogs and loads under way, the texture), which stays in
//! [`super::viewer::Viewer`]. Widgets read a `&ViewerState` and answer with
//! [`super::action::Action`]s; `Viewer::apply` carries them out.

use std::path::{Path, PathBuf};
use std::time::Instant;

use super::action::AfterDiscard;
use super::document::Document;
use super::editor::Editor;
use super::error_plot::Convergence;
use super::image_view::Probe;
use super::params::{PanelChoices, PanelParams, Ranges};
use super::reference::ReferenceState;
use super::save::SaveFlow;
use super::settings::ViewerSettings;
use crate::geometry::BezierPatch;
use crate::render::compare::{Reference, ReferenceErrors};
use crate::render::session::Frame;
use crate::scene::Light;
use crate::scene::Scene;

/// A line in the status bar.
#[derive(Clone, Debug, PartialEq)]
pub enum Status {
    /// Something worked.
    Info(String),
    /// Something did not.
    Error(String),
}

/// A scene that could not be opened, as its window tells it.
#[derive(Clone, Debug, PartialEq)]
pub struct SceneError {
    /// Why, naming the file and field.
    pub message: String,
    /// What the viewer shows instead ("ball.toml is still rendering.").
    pub instead: String,
}

/// What the viewer's widgets read.
pub struct ViewerState {
    /// Persisted preferences.
    pub settings: ViewerSettings,
    /// The scene being edited: the one copy of it in the viewer.
    pub(super) document: Document,
    /// Slider ranges for the scene.
    pub(super) ranges: Ranges,
    /// What the side panel holds that is not the scene's (manual values, pause).
    pub(super) panel: PanelChoices,
    /// Newest frame of the newest epoch seen.
    pub(super) frame: Option<Frame>,
    pub(super) probe: Option<Probe>,
    pub(super) convergence: Convergence,
    /// A restart sent at this time, from this epoch, not shown yet.
    pub(super) pending_restart: Option<(Instant, u64)>,
    /// Seconds from the last restart-type change to its first image.
    pub(super) restart_latency_secs: Option<f64>,
    pub(super) save: SaveFlow,
    /// A scene that failed to open: its error, and what is shown instead (in a window).
    pub(super) scene_error: Option<SceneError>,
    /// The render thread's panic message.
    pub(super) render_failure: Option<String>,
    pub(super) status: Option<Status>,
    pub(super) show_help: bool,
    /// Seconds from the viewer's start to the first image shown.
    pub(super) first_image_secs: Option<f64>,
    /// Control points as edited, selection, gesture and undo history.
    pub(super) editor: Editor,
    /// A scene file waiting for the user to confirm replacing it.
    pub(super) confirm_scene_overwrite: Option<PathBuf>,
    /// What waits on the unsaved-edits question.
    pub(super) unsaved_question: Option<AfterDiscard>,
    /// What to do once the scene is saved (from "Save" in the unsaved-edits question).
    pub(super) after_save: Option<AfterDiscard>,
    /// The window may close even with unsaved edits (the user said so).
    pub(super) allow_close: bool,
    /// The `R` key asked to restart: "discard the passes?" is shown.
    pub(super) confirm_restart: bool,
    /// The reference image compared with, and its loading.
    pub(super) reference: ReferenceState,
    /// The render folder being watched, where it stands (`None`: not watching).
    pub(super) watching: Option<super::watch::WatchSummary>,
    /// The Design panel's choices and the design's progress.
    pub(super) design: super::design::DesignState,
}

impl ViewerState {
    /// The render folder being watched and where it stands.
    pub fn watching(&self) -> Option<&super::watch::WatchSummary> {
        self.watching.as_ref()
    }

    /// The labels of the shown frame's per-pixel layers (none before the first frame).
    pub fn layer_labels(&self) -> Vec<&'static str> {
        self.frame
            .as_ref()
            .map_or_else(Vec::new, |f| f.layers.iter().map(|l| l.label).collect())
    }

    /// The pixel under the pointer when the image was last drawn (it may lie outside a frame
    /// that has since shrunk).
    pub fn probe(&self) -> Option<(u32, u32)> {
        self.probe.as_ref().map(|p| (p.x, p.y))
    }

    /// The state of a viewer that has just opened `scene` (parameters as in its file, with
    /// `paused`), with `settings` from storage.
    pub(super) fn new(scene: Scene, settings: ViewerSettings, paused: bool) -> Self {
        Self {
            settings,
            ranges: Ranges::for_scene(&scene),
            panel: PanelChoices {
                paused,
                ..PanelChoices::default()
            },
            frame: None,
            probe: None,
            convergence: Convergence::default(),
            pending_restart: None,
            restart_latency_secs: None,
            save: SaveFlow::default(),
            scene_error: None,
            render_failure: None,
            status: None,
            show_help: false,
            first_image_secs: None,
            editor: Editor::new(&scene),
            confirm_scene_overwrite: None,
            unsaved_question: None,
            after_save: None,
            allow_close: false,
            confirm_restart: false,
            reference: ReferenceState::default(),
            watching: None,
            design: Default::default(),
            document: Document::new(scene),
        }
    }

    /// The Design panel's choices and the design's progress.
    pub fn design(&self) -> &super::design::DesignState {
        &self.design
    }

    /// The scene as edited: parameters, lens and camera, control points and lights.
    pub fn scene(&self) -> &Scene {
        self.document.scene()
    }

    /// What the side panel shows: the document's parameters and lens with the panel's own
    /// choices.
    pub fn params(&self) -> PanelParams {
        PanelParams::of(self.document.scene(), &self.panel)
    }

    /// Whether rendering is paused.
    pub fn paused(&self) -> bool {
        self.panel.paused
    }

    /// The newest frame shown.
    pub fn frame(&self) -> Option<&Frame> {
        self.frame.as_ref()
    }

    /// The error curves of the epoch shown (estimate, and the true error against a reference).
    pub fn convergence(&self) -> &Convergence {
        &self.convergence
    }

    /// The error of the last scene that failed to open, if it is still shown.
    pub fn scene_error(&self) -> Option<&str> {
        self.scene_error.as_ref().map(|e| e.message.as_str())
    }

    /// What the scene-error window says is shown instead of the scene that failed.
    pub fn scene_error_instead(&self) -> Option<&str> {
        self.scene_error.as_ref().map(|e| e.instead.as_str())
    }

    /// The error of a scene that failed to open while this one renders on.
    pub(super) fn scene_failed(&mut self, message: String) {
        let scene = self.document.scene();
        // Built-in scenes are named "<built-in ...>".
        let instead = match scene.source.file_name() {
            Some(name) if !scene.source.to_string_lossy().starts_with('<') => {
                format!("{} is still rendering.", name.to_string_lossy())
            }
            _ => "The built-in scene is still rendering.".to_owned(),
        };
        self.scene_error = Some(SceneError { message, instead });
    }

    /// The render thread's failure, if it failed.
    pub fn render_failure(&self) -> Option<&str> {
        self.render_failure.as_deref()
    }

    /// The status line.
    pub fn status(&self) -> Option<&Status> {
        self.status.as_ref()
    }

    /// Seconds from creation to the first image shown, once there is one.
    pub fn first_image_secs(&self) -> Option<f64> {
        self.first_image_secs
    }

    /// Seconds from the last restarting change to the first image of its epoch.
    pub fn restart_latency_secs(&self) -> Option<f64> {
        self.restart_latency_secs
    }

    /// Whether a restarting change waits for its first image.
    pub fn restart_pending(&self) -> bool {
        self.pending_restart.is_some()
    }

    /// The control points as edited (geometry order).
    pub fn patches(&self) -> impl ExactSizeIterator<Item = &BezierPatch> + Clone + '_ {
        self.document.patches()
    }

    /// The lights as edited (scene order).
    pub fn lights(&self) -> &[Light] {
        self.document.lights()
    }

    /// Where a handle (control point or light) is now, if the scene has it.
    pub fn handle_position(&self, h: super::handle::Handle) -> Option<glam::DVec3> {
        self.editor
            .exists(&self.document, h)
            .then(|| self.editor.point(&self.document, h))
    }

    /// The selected handles (control points and lights).
    pub fn selection(&self) -> impl Iterator<Item = super::handle::Handle> + '_ {
        self.editor.selection.iter().copied()
    }

    /// Whether the scene has edits not saved yet.
    pub fn unsaved_edits(&self) -> bool {
        self.editor.history.unsaved()
    }

    /// Whether an overwrite question is open.
    pub fn confirming_overwrite(&self) -> Option<&Path> {
        self.save.confirm.as_ref().map(|(p, _)| p.as_path())
    }

    /// Whether the overlay is shown and can be edited.
    pub fn editing(&self) -> bool {
        self.settings.show_wireframe
            && !(self.document.patches().len() == 0 && self.document.lights().is_empty())
    }

    /// The open reference.
    pub fn reference(&self) -> Option<&Reference> {
        self.reference.open.as_ref()
    }

    /// Whether the reference is shown instead of the render (A/B).
    pub fn showing_reference(&self) -> bool {
        self.reference.show_reference && self.reference.open.is_some()
    }

    /// The current frame's error against the reference, when both are there and match.
    pub fn reference_errors(&self) -> Option<ReferenceErrors> {
        let frame = self.frame.as_ref()?;
        self.reference.open.as_ref()?.errors(&frame.radiance)
    }

    /// Whether a question waits for an answer (replace a file, discard passes, unsaved edits).
    pub fn question_open(&self) -> bool {
        self.confirming_overwrite().is_some()
            || self.confirm_scene_overwrite.is_some()
            || self.confirm_restart
            || self.unsaved_question.is_some()
    }
}
