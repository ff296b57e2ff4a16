//! The mouse over the image, as actions: hover and pick control points, click to select
//! (Shift adds), drag a point (Ctrl: along the line of sight), and move the camera — right
//! drag orbits, Shift + right or middle drag pans, Ctrl + right drag dollies. Dragging
//! elsewhere with the left button pans the image (see [`super::image_view`]).

use egui::{PointerButton, Pos2, Response};

use super::action::Action;
use super::editor::{CameraMove, Editor, Gesture};
use super::overlay::{OverlayProjection, PointRef};

/// The control point a left drag starting at the press position would grab (with the
/// overlay as placed in the last frame), if the overlay is shown.
pub fn grab_at(
    editor: &Editor,
    projection: Option<&OverlayProjection>,
    press: Option<Pos2>,
) -> Option<PointRef> {
    projection?.pick(&editor.patches, press?)
}

/// Actions for this frame's pointer activity over the image view.
pub fn view_actions(
    editor: &Editor,
    projection: &OverlayProjection,
    response: &Response,
    editing: bool,
    out: &mut Vec<Action>,
) {
    let (modifiers, press) = response.ctx.input(|i| (i.modifiers, i.pointer.press_origin()));
    let pointer = response.interact_pointer_pos().or(response.hover_pos());

    // Hover (not while a gesture holds the pointer).
    if editor.gesture.is_none() {
        let hovered = if editing {
            response
                .hover_pos()
                .and_then(|p| projection.pick(&editor.patches, p))
        } else {
            None
        };
        if hovered != editor.hovered {
            out.push(Action::Hover(hovered));
        }
    }

    // Drags: points with the left button, the camera with the right or middle one.
    if response.drag_started_by(PointerButton::Primary) && editing {
        if let (Some(grab), Some(press)) = (grab_at(editor, Some(projection), press), press) {
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
    if let Some(how) = camera_move {
        out.push(Action::BeginCameraDrag(how));
    }
    let gesture = match (out.last(), &editor.gesture) {
        (Some(Action::BeginPointDrag { .. }), _) => Some(true),
        (Some(Action::BeginCameraDrag(_)), _) => Some(false),
        (_, Some(Gesture::Points { .. })) => Some(true),
        (_, Some(Gesture::Camera { .. })) => Some(false),
        _ => None,
    };
    if let (Some(points), Some(p)) = (gesture, pointer) {
        if response.dragged() {
            out.push(if points {
                Action::DragPoints {
                    pointer: p,
                    along_view: modifiers.command || modifiers.ctrl,
                }
            } else {
                Action::DragCamera(p - press.unwrap_or(p))
            });
        }
    }
    if response.drag_stopped() && gesture.is_some() {
        out.push(Action::EndGesture);
    }

    // Clicks select.
    if response.clicked() && editing {
        match response
            .hover_pos()
            .and_then(|p| projection.pick(&editor.patches, p))
        {
            Some(point) => out.push(Action::Select {
                point,
                add: modifiers.shift,
            }),
            None if !modifiers.shift && !editor.selection.is_empty() => out.push(Action::ClearSelection),
            None => {}
        }
    }
}
