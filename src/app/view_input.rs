//! The mouse over the image, as actions: hover and pick handles (control points and lights), click to select
//! (Shift adds), drag a point (Ctrl: along the line of sight), and move the camera — right
//! drag orbits, Shift + right or middle drag pans, Ctrl + right drag dollies. Dragging
//! elsewhere with the left button pans the image (see [`super::image_view`]).

use egui::{PointerButton, Pos2, Response};

use super::action::Action;
use super::document::Document;
use super::editor::{CameraMove, Editor, Gesture};
use super::handle::Handle;
use super::overlay::OverlayProjection;

/// The handle a left drag starting at the press position would grab (with the overlay as
/// placed in the last frame), if the overlay is shown.
pub fn grab_at(
    editor: &Editor,
    doc: &Document,
    projection: Option<&OverlayProjection>,
    press: Option<Pos2>,
) -> Option<Handle> {
    editor.pick(doc, projection?, press?)
}

/// Actions for this frame's pointer activity over the image view.
pub fn view_actions(
    editor: &Editor,
    doc: &Document,
    projection: &OverlayProjection,
    response: &Response,
    editing: bool,
    out: &mut Vec<Action>,
) {
    // Hover (not while a gesture holds the pointer).
    if editor.gesture.is_none() {
        let hovered = response
            .hover_pos()
            .filter(|_| editing)
            .and_then(|p| editor.pick(doc, projection, p));
        if hovered != editor.hovered {
            out.push(Action::Hover(hovered));
        }
    }
    if box_select_actions(editor, doc, projection, response, editing, out) {
        return;
    }
    drag_actions(editor, doc, projection, response, editing, out);
    // Clicks select.
    if response.clicked() && editing {
        let shift = response.ctx.input(|i| i.modifiers.shift);
        match response.hover_pos().and_then(|p| editor.pick(doc, projection, p)) {
            Some(point) => out.push(Action::Select { point, add: shift }),
            None if !shift && !editor.selection.is_empty() => out.push(Action::ClearSelection),
            None => {}
        }
    }
}

/// Shift + left drag on empty space: a box selection. Returns whether one is under way (it
/// takes the pointer: no click or drag else this frame).
fn box_select_actions(
    editor: &Editor,
    doc: &Document,
    projection: &OverlayProjection,
    response: &Response,
    editing: bool,
    out: &mut Vec<Action>,
) -> bool {
    let (shift, press) = response
        .ctx
        .input(|i| (i.modifiers.shift, i.pointer.press_origin()));
    let starts = response.drag_started_by(PointerButton::Primary)
        && editing
        && shift
        && grab_at(editor, doc, Some(projection), press).is_none();
    let Some(from) = editor
        .rubber_band
        .map(|(from, _)| from)
        .or(press.filter(|_| starts))
    else {
        return false;
    };
    let to = response
        .interact_pointer_pos()
        .or(response.hover_pos())
        .or(editor.rubber_band.map(|(_, to)| to))
        .unwrap_or(from);
    let done = response.drag_stopped() || !response.ctx.input(|i| i.pointer.primary_down());
    out.push(Action::BoxSelect { from, to, done });
    true
}

/// Drags: points with the left button, the camera with the right or middle one.
fn drag_actions(
    editor: &Editor,
    doc: &Document,
    projection: &OverlayProjection,
    response: &Response,
    editing: bool,
    out: &mut Vec<Action>,
) {
    let (modifiers, press) = response.ctx.input(|i| (i.modifiers, i.pointer.press_origin()));
    if response.drag_started_by(PointerButton::Primary) && editing {
        if let (Some(grab), Some(press)) = (grab_at(editor, doc, Some(projection), press), press) {
            out.push(Action::BeginPointDrag { grab, press });
        }
    }
    let camera_move = if response.drag_started_by(PointerButton::Middle) {
        Some(CameraMove::Pan)
    } else if response.drag_started_by(PointerButton::Secondary) {
        Some(if modifiers.shift {
            CameraMove::Pan
        } else if modifiers.command || modifiers.ctrl {
            CameraMove::Dolly
        } else {
            CameraMove::Orbit
        })
    } else {
        None
    };
    out.extend(camera_move.map(Action::BeginCameraDrag));
    // Whether a points (true) or camera (false) gesture is under way, begun now or before.
    let gesture = match out.last() {
        Some(Action::BeginPointDrag { .. }) => Some(true),
        Some(Action::BeginCameraDrag(_)) => Some(false),
        _ => editor
            .gesture
            .as_ref()
            .map(|g| matches!(g, Gesture::Points { .. })),
    };
    let pointer = response.interact_pointer_pos().or(response.hover_pos());
    if let (Some(points), Some(p), true) = (gesture, pointer, response.dragged()) {
        out.push(if points {
            Action::DragPoints {
                pointer: p,
                along_view: modifiers.command || modifiers.ctrl,
            }
        } else {
            Action::DragCamera(p - press.unwrap_or(p))
        });
    }
    if response.drag_stopped() && gesture.is_some() {
        out.push(Action::EndGesture);
    }
}
