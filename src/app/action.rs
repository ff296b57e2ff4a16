//! Everything a person can ask of the viewer, as data: menus, panels, keys, the mouse over
//! the image and scripted runs emit [`Action`]s; [`Viewer::apply`] is the one place that
//! carries them out (changing the viewer's state, telling the render session, recording undo
//! steps). Undo and redo replay inverse edits through the same code.

use std::path::PathBuf;

use egui::{Pos2, Vec2};
use glam::DVec3;

use super::editor::{CameraMove, Edit, Gesture};
use super::overlay::PointRef;
use super::params::PanelParams;
use super::settings::{DisplayMode, Zoom, EXPOSURE_LIMIT};
use super::viewer::{Status, Viewer};
use crate::render::session::Command;
use crate::scene::Camera;

/// What an unsaved-edits question was asked for.
#[derive(Clone, Debug, PartialEq)]
pub enum AfterDiscard {
    /// Open this scene.
    Open(PathBuf),
    /// Show the open dialog.
    Pick,
    /// Close the window.
    Close,
}

/// A request to the viewer.
#[derive(Clone, Debug, PartialEq)]
pub enum Action {
    /// Show the open dialog (asks first when there are unsaved edits).
    PickScene,
    /// Open a scene file (asks first when there are unsaved edits).
    OpenScene(PathBuf),
    /// Show the open dialog for a reference image (.exr, .pfm).
    PickReference,
    /// Compare with this reference image.
    OpenReference(PathBuf),
    /// Stop comparing with the reference.
    CloseReference,
    /// Show the reference instead of the render (`true`), or the render (A/B).
    ShowReference(bool),
    /// Send the current frame to tev at this address.
    SendToTev(String),
    /// Show the save dialog for the current frame.
    SaveFrame,
    /// Answer the frame overwrite question (`true`: replace).
    ConfirmFrameOverwrite(bool),
    /// Save the scene to its own file (asks before replacing it), or ask where.
    SaveScene,
    /// Ask where to save the scene.
    SaveSceneAs,
    /// Save the scene to this file (asks before replacing one).
    SaveSceneTo(PathBuf),
    /// Answer the scene overwrite question (`true`: replace).
    ConfirmSceneOverwrite(bool),
    /// Answer the unsaved-edits question: `Some(true)` discard and go on, `Some(false)` save
    /// first, `None` cancel.
    ResolveUnsaved(Option<bool>),
    /// Close the window (asks first when there are unsaved edits).
    Close,
    /// New parameter values (the differences become session commands).
    SetParams(PanelParams),
    /// Discard the accumulation and render again.
    Restart,
    /// Restart, asking first when passes would be thrown away (the `R` key).
    AskRestart,
    /// The answer to [`Action::AskRestart`]'s question: restart or not.
    ConfirmRestart(bool),
    /// Start a fresh render session (after a failure).
    RestartRenderer,
    /// Close the "could not open scene" window.
    DismissSceneError,
    /// Exposure in stops.
    SetExposure(f32),
    /// Image placement; `recentre` also clears the pan.
    SetZoom {
        /// New zoom.
        zoom: Zoom,
        /// Clear the pan.
        recentre: bool,
    },
    /// What the image shows.
    SetDisplay(DisplayMode),
    /// Side panel shown or hidden.
    ShowSidePanel(bool),
    /// Help window shown or hidden.
    ShowHelp(bool),
    /// Control-net overlay shown or hidden.
    ShowWireframe(bool),
    /// The control point under the cursor changed.
    Hover(Option<PointRef>),
    /// Select a point; `add` toggles it in the selection instead of replacing it.
    Select {
        /// The point.
        point: PointRef,
        /// Shift held.
        add: bool,
    },
    /// Select every control point of a patch.
    SelectPatch(usize),
    /// Select nothing.
    ClearSelection,
    /// A drag begins on a control point.
    BeginPointDrag {
        /// The grabbed point.
        grab: PointRef,
        /// Where the button went down (points).
        press: Pos2,
    },
    /// The cursor of a point drag moved; `along_view` moves along the line of sight.
    DragPoints {
        /// Cursor.
        pointer: Pos2,
        /// Ctrl held.
        along_view: bool,
    },
    /// A camera drag begins.
    BeginCameraDrag(CameraMove),
    /// The cursor of a camera drag moved this far since it began (points).
    DragCamera(Vec2),
    /// The mouse was released: the gesture becomes one undo step.
    EndGesture,
    /// Put a control point at an exact position (the panel's fields).
    SetPoint(PointRef, DVec3),
    /// Move the selection by a step in screen points (arrow keys).
    Nudge(Vec2),
    /// Turn and move the camera to frame the selection (or every patch).
    FrameSelection,
    /// Undo the last edit.
    Undo,
    /// Redo the last undone edit.
    Redo,
}

impl Viewer {
    /// Carries out an action.
    pub fn apply(&mut self, action: Action) {
        match action {
            Action::PickScene => self.unless_unsaved(AfterDiscard::Pick),
            Action::OpenScene(path) => self.unless_unsaved(AfterDiscard::Open(path)),
            Action::PickReference => self.pick_reference(),
            Action::OpenReference(path) => self.open_reference(path),
            Action::CloseReference => self.close_reference(),
            Action::ShowReference(on) => self.show_reference(on),
            Action::SendToTev(address) => self.send_to_tev(&address),
            Action::SaveFrame => self.save_with_dialog(),
            Action::ConfirmFrameOverwrite(replace) => self.confirm_overwrite(replace),
            Action::SaveScene => self.save_scene(),
            Action::SaveSceneAs => self.pick_scene_file(),
            Action::SaveSceneTo(path) => self.save_scene_to(path),
            Action::ConfirmSceneOverwrite(replace) => self.confirm_scene_overwrite(replace),
            Action::ResolveUnsaved(choice) => self.resolve_unsaved(choice),
            Action::Close => self.unless_unsaved(AfterDiscard::Close),
            Action::SetParams(p) => self.set_params(p),
            Action::Restart => self.send(Command::Restart),
            Action::AskRestart => {
                // One pass (or a preview) is no work to lose; more is worth a question.
                if self.frame.as_ref().is_some_and(|f| f.pass >= 2) {
                    self.confirm_restart = true;
                } else {
                    self.send(Command::Restart);
                }
            }
            Action::ConfirmRestart(restart) => {
                self.confirm_restart = false;
                if restart {
                    self.send(Command::Restart);
                }
            }
            Action::RestartRenderer => self.restart_renderer(),
            Action::DismissSceneError => self.scene_error = None,
            Action::SetExposure(stops) => {
                self.settings.exposure_stops = stops.clamp(-EXPOSURE_LIMIT, EXPOSURE_LIMIT);
                self.image_view.invalidate();
            }
            Action::SetZoom { zoom, recentre } => {
                self.settings.zoom = zoom;
                if recentre {
                    self.image_view.recentre();
                }
            }
            Action::SetDisplay(mode) => {
                self.settings.display = mode;
                self.image_view.invalidate();
            }
            Action::ShowSidePanel(on) => self.settings.show_side_panel = on,
            Action::ShowHelp(on) => self.show_help = on,
            Action::ShowWireframe(on) => self.settings.show_wireframe = on,
            a @ (Action::Hover(_)
            | Action::Select { .. }
            | Action::SelectPatch(_)
            | Action::ClearSelection) => self.apply_selection(a),
            a @ (Action::BeginPointDrag { .. }
            | Action::DragPoints { .. }
            | Action::BeginCameraDrag(_)
            | Action::DragCamera(_)
            | Action::EndGesture) => self.apply_gesture(a),
            edit => self.apply_edit(edit),
        }
    }

    /// Hover and selection.
    fn apply_selection(&mut self, action: Action) {
        match action {
            Action::Hover(point) => {
                if self.editor.hovered != point {
                    self.editor.hovered = point;
                    self.editor.touch();
                }
            }
            Action::Select { point, add } => {
                if !self.editor.exists(point) {
                    return;
                }
                // A point shared by patches (a seam) is selected with its twins, so the
                // patches stay joined when it moves.
                let welded = self.editor.welded(point);
                if !add {
                    self.editor.selection = welded.into_iter().collect();
                } else if self.editor.selection.contains(&point) {
                    for r in welded {
                        self.editor.selection.remove(&r);
                    }
                } else {
                    self.editor.selection.extend(welded);
                }
                self.editor.touch();
            }
            Action::SelectPatch(patch) => {
                if patch < self.editor.patches.len() {
                    let points = (0..16).map(|index| PointRef { patch, index });
                    self.editor.selection = points.flat_map(|r| self.editor.welded(r)).collect();
                    self.editor.touch();
                }
            }
            Action::ClearSelection => {
                self.editor.selection.clear();
                self.editor.touch();
            }
            other => unreachable!("not a selection action: {other:?}"),
        }
    }

    /// Mouse drags of points and of the camera.
    fn apply_gesture(&mut self, action: Action) {
        match action {
            Action::BeginPointDrag { grab, press } => {
                let on_screen = self.editor.exists(grab).then(|| self.editor.point(grab));
                let on_screen = on_screen.and_then(|q| self.projection.as_ref()?.to_screen(q));
                if let Some(grab_screen) = on_screen {
                    // Dragging an unselected point selects it (with its twins at seams).
                    if !self.editor.selection.contains(&grab) {
                        self.editor.selection = self.editor.welded(grab).into_iter().collect();
                        self.editor.touch();
                    }
                    let start = self.editor.selected_points();
                    self.editor.gesture = Some(Gesture::Points {
                        grab,
                        grab_screen,
                        press,
                        start,
                    });
                }
            }
            Action::DragPoints { pointer, along_view } => {
                if let Some(proj) = &self.projection {
                    let moves = self.editor.dragged_points(proj, pointer, along_view);
                    self.move_points(&moves);
                }
            }
            Action::BeginCameraDrag(how) => {
                self.editor.gesture = Some(Gesture::Camera {
                    how,
                    start: (self.scene.camera.clone(), self.editor.pivot),
                });
            }
            Action::DragCamera(delta) => {
                if let Some(proj) = &self.projection {
                    if let Some((camera, pivot)) = self.editor.dragged_camera(proj, delta) {
                        self.set_camera(camera, pivot);
                    }
                }
            }
            Action::EndGesture => self.end_gesture(),
            other => unreachable!("not a gesture action: {other:?}"),
        }
    }

    /// One-step edits and undo/redo.
    fn apply_edit(&mut self, action: Action) {
        match action {
            Action::SetPoint(point, position) => {
                let changed = self.move_points(&[(point, position)]);
                self.record(Edit::Points(changed));
            }
            Action::Nudge(step) => {
                if let Some(proj) = &self.projection {
                    let moves = self.editor.nudge(proj, step);
                    let changed = self.move_points(&moves);
                    self.record(Edit::Points(changed));
                }
            }
            Action::FrameSelection => {
                let before = (self.scene.camera.clone(), self.editor.pivot);
                let (centre, radius) = self.editor.selection_sphere();
                let camera = super::navigate::frame(&self.scene.camera, centre, radius, self.editor.world_up);
                self.set_camera(camera, centre);
                let after = (self.scene.camera.clone(), self.editor.pivot);
                self.record(Edit::Camera { before, after });
            }
            Action::Undo => {
                if let Some(edit) = self.editor.history.undo() {
                    self.replay(edit);
                }
            }
            Action::Redo => {
                if let Some(edit) = self.editor.history.redo() {
                    self.replay(edit);
                }
            }
            other => unreachable!("not an editing action: {other:?}"),
        }
    }

    /// Records an edit unless it changed nothing.
    fn record(&mut self, edit: Edit) {
        let empty = match &edit {
            Edit::Points(moves) => moves.is_empty(),
            Edit::Camera { before, after } => before == after,
        };
        if !empty {
            self.editor.history.record(edit);
        }
    }

    /// The gesture in progress becomes one undo step.
    fn end_gesture(&mut self) {
        match self.editor.gesture.take() {
            Some(Gesture::Points { start, .. }) => {
                let moves = start
                    .into_iter()
                    .map(|(r, before)| (r, before, self.editor.point(r)))
                    .filter(|(_, a, b)| a != b)
                    .collect();
                self.record(Edit::Points(moves));
            }
            Some(Gesture::Camera { start, .. }) => {
                let after = (self.scene.camera.clone(), self.editor.pivot);
                self.record(Edit::Camera { before: start, after });
            }
            None => {}
        }
    }

    /// Applies an edit (undo or redo) without recording it.
    fn replay(&mut self, edit: Edit) {
        match edit {
            Edit::Points(moves) => {
                let targets: Vec<(PointRef, DVec3)> =
                    moves.iter().map(|(r, _, after)| (*r, *after)).collect();
                self.move_points(&targets);
            }
            Edit::Camera { after, .. } => self.set_camera(after.0, after.1),
        }
    }

    /// Moves control points and tells the render session; returns what changed.
    fn move_points(&mut self, moves: &[(PointRef, DVec3)]) -> Vec<(PointRef, DVec3, DVec3)> {
        let changed = self.editor.set_points(moves);
        for (r, _, position) in &changed {
            self.send(Command::MoveControlPoint {
                patch: r.patch,
                index: r.index,
                position: *position,
            });
        }
        changed
    }

    /// Places the camera (pose from `camera`, lens from the panel's parameters) and the
    /// orbit pivot, and tells the render session.
    fn set_camera(&mut self, camera: Camera, pivot: DVec3) {
        let camera = self.params.lens_on(&camera);
        if !(camera.position.is_finite() && camera.forward.is_finite() && pivot.is_finite()) {
            self.status = Some(Status::Error(
                "camera move ignored: it left the scene's numbers".into(),
            ));
            return;
        }
        self.editor.pivot = pivot;
        if camera != self.scene.camera {
            self.scene.camera = camera.clone();
            self.send(Command::SetCamera(camera));
        }
    }
}
