//! [`Viewer::apply`]: the one place that carries out the [`Action`]s the widgets emit —
//! changing the viewer's state, telling the render session, recording undo steps; undo and
//! redo replay inverse edits through the same code.

use glam::DVec3;

use super::action::{Action, AfterDiscard};
use super::editor::{Edit, Gesture};
use super::handle::{Handle, PointRef};
use super::settings::EXPOSURE_LIMIT;
use super::state::Status;
use super::viewer::Viewer;
use crate::render::session::Command;
use crate::scene::Camera;

impl Viewer {
    /// Carries out an action.
    pub fn apply(&mut self, action: Action) {
        if self.refused_while_designing(&action) {
            return;
        }
        match action {
            Action::PickScene => self.unless_unsaved(AfterDiscard::Pick),
            Action::OpenScene(path) => self.unless_unsaved(AfterDiscard::Open(path)),
            Action::PickReference => self.pick_reference(),
            Action::PickWatchFolder => self.pick_watch_folder(),
            Action::WatchFolder(dir) => self.watch_folder(dir),
            Action::StopWatching => self.stop_watching(),
            Action::WatchRender(key) => self.watch_render(key),
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
            a if a.is_design() => self.apply_design(a),
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
            | Action::ClearSelection
            | Action::BoxSelect { .. }) => self.apply_selection(a),
            a @ (Action::BeginPointDrag { .. }
            | Action::DragPoints { .. }
            | Action::BeginCameraDrag(_)
            | Action::DragCamera(_)
            | Action::EndGesture) => self.apply_gesture(a),
            edit => self.apply_edit(edit),
        }
    }

    /// Whether `action` must wait for the running design (it edits the scene the design is
    /// shaping); says so in the status bar.
    fn refused_while_designing(&mut self, action: &Action) -> bool {
        let refused = self.design_run.is_some() && action.edits_the_scene();
        if refused {
            self.status = Some(Status::Error(
                "a design is shaping the surface: stop it (Design panel) before editing".into(),
            ));
        }
        refused
    }

    /// The Design panel's choices, Start and Stop.
    fn apply_design(&mut self, action: Action) {
        let design = &mut self.state.design;
        match action {
            Action::SetDesignTarget(path) => design.target = Some(path),
            Action::SetDesignSurface(name) => design.surface = Some(name),
            Action::SetDesignReceiver(name) => design.receiver = Some(name),
            Action::SetDesignSteps(steps) => design.steps = Some(steps.clamp(1, 1_000_000)),
            Action::PickDesignTarget => self.pick_design_target(),
            Action::StartDesign => self.start_design(),
            Action::StopDesign => self.stop_design(),
            other => unreachable!("not a design action: {other:?}"),
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
                if !self.editor.exists(&self.document, point) {
                    return;
                }
                // A point shared by patches (a seam) is selected with its twins, so the
                // patches stay joined when it moves.
                let welded = self.editor.welded(&self.document, point);
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
            Action::BoxSelect { from, to, done } => {
                if !done {
                    self.editor.rubber_band = Some((from, to));
                    return;
                }
                self.editor.rubber_band = None;
                let rect = egui::Rect::from_two_pos(from, to);
                let Some(projection) = &self.projection else {
                    return;
                };
                let inside: Vec<Handle> = self
                    .editor
                    .handles(&self.document)
                    .filter(|(_, q)| projection.to_screen(*q).is_some_and(|s| rect.contains(s)))
                    .map(|(r, _)| r)
                    .collect();
                for r in inside {
                    let welded = self.editor.welded(&self.document, r);
                    self.editor.selection.extend(welded);
                }
                self.editor.touch();
            }
            Action::SelectPatch(patch) => {
                if patch < self.document.patches().len() {
                    // A patch derived from a net: the whole net, whose points are its handles.
                    let net = self.document.scene().geometry.patch_net(patch);
                    let points: Vec<Handle> = match net {
                        Some(n) => self
                            .document
                            .net_handles()
                            .filter(|(r, _)| r.net == n)
                            .map(|(r, _)| Handle::Net(r))
                            .collect(),
                        None => (0..16)
                            .map(|index| Handle::Control(PointRef { patch, index }))
                            .collect(),
                    };
                    let points = points.into_iter();
                    let state = &mut self.state;
                    state.editor.selection = points
                        .flat_map(|r| state.editor.welded(&state.document, r))
                        .collect();
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
                let doc = &self.state.document;
                let on_screen = self
                    .editor
                    .exists(doc, grab)
                    .then(|| self.editor.point(doc, grab));
                let on_screen = on_screen.and_then(|q| self.projection.as_ref()?.to_screen(q));
                if let Some(grab_screen) = on_screen {
                    // Dragging an unselected point selects it (with its twins at seams).
                    if !self.editor.selection.contains(&grab) {
                        let state = &mut self.state;
                        state.editor.selection =
                            state.editor.welded(&state.document, grab).into_iter().collect();
                        self.editor.touch();
                    }
                    let start = self.editor.selected_points(&self.document);
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
                    start: (self.scene().camera.clone(), self.editor.pivot),
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
                    let moves = self.editor.nudge(&self.document, proj, step);
                    let changed = self.move_points(&moves);
                    self.record(Edit::Points(changed));
                }
            }
            Action::FrameSelection => {
                let before = (self.scene().camera.clone(), self.editor.pivot);
                let (centre, radius) = self.editor.selection_sphere(&self.document);
                let camera =
                    super::navigate::frame(&self.scene().camera, centre, radius, self.editor.world_up);
                self.set_camera(camera, centre);
                let after = (self.scene().camera.clone(), self.editor.pivot);
                self.record(Edit::Camera { before, after });
            }
            Action::SetMaterial {
                material,
                value,
                drag,
            } => {
                let Some(before) = self.document.scene().materials.get(material).cloned() else {
                    return;
                };
                let Some(change) = self.state.document.set_material(material, value.clone()) else {
                    return;
                };
                self.send_change(change);
                let edit = Edit::Material {
                    index: material,
                    before: Box::new(before),
                    after: Box::new(value),
                };
                self.editor.history.record_in_drag(edit, drag);
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
    pub(super) fn record(&mut self, edit: Edit) {
        let empty = match &edit {
            Edit::Points(moves) => moves.is_empty(),
            Edit::Camera { before, after } => before == after,
            Edit::Material { before, after, .. } => before == after,
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
                    .map(|(r, before)| (r, before, self.editor.point(&self.document, r)))
                    .filter(|(_, a, b)| a != b)
                    .collect();
                self.record(Edit::Points(moves));
            }
            Some(Gesture::Camera { start, .. }) => {
                let after = (self.scene().camera.clone(), self.editor.pivot);
                self.record(Edit::Camera { before: start, after });
            }
            None => {}
        }
    }

    /// Applies an edit (undo or redo) without recording it.
    fn replay(&mut self, edit: Edit) {
        match edit {
            Edit::Points(moves) => {
                let targets: Vec<(Handle, DVec3)> = moves.iter().map(|(r, _, after)| (*r, *after)).collect();
                self.move_points(&targets);
            }
            Edit::Camera { after, .. } => self.set_camera(after.0, after.1),
            Edit::Material { index, after, .. } => {
                if let Some(change) = self.state.document.set_material(index, *after) {
                    self.send_change(change);
                }
            }
        }
    }

    /// Moves handles (control points, lights) in the document and sends the render session
    /// the changes; returns what moved.
    pub(super) fn move_points(&mut self, moves: &[(Handle, DVec3)]) -> Vec<(Handle, DVec3, DVec3)> {
        let state = &mut self.state;
        let (changed, changes) = state.editor.set_points(&mut state.document, moves);
        for change in changes {
            self.send_change(change);
        }
        changed
    }

    /// Places the camera (pose from `camera`, lens the document's) and the orbit pivot, and
    /// tells the render session.
    fn set_camera(&mut self, camera: Camera, pivot: DVec3) {
        if !(camera.position.is_finite() && camera.forward.is_finite() && pivot.is_finite()) {
            self.status = Some(Status::Error(
                "camera move ignored: it left the scene's numbers".into(),
            ));
            return;
        }
        self.editor.pivot = pivot;
        if let Some(change) = self.state.document.set_pose(&camera) {
            self.send_change(change);
        }
    }
}
