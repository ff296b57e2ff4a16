//! Keyboard shortcuts (listed in the help window from the same table), as actions.

use egui::{Key, KeyboardShortcut, Modifiers, Vec2};

use super::action::Action;
use super::image_view::{MAX_SCALE, MIN_SCALE};
use super::settings::{DisplayMode, Zoom};
use super::state::ViewerState;

/// Shortcuts and mouse gestures as shown in the help window: (keys, what they do).
pub const HELP: &[(&str, &str)] = &[
    ("Ctrl+O", "Open a scene (or drop a .toml file on the window)"),
    ("Ctrl+S", "Save the current frame (PNG as displayed, EXR linear)"),
    ("Ctrl+Shift+S", "Save the scene as edited (TOML)"),
    (
        "Ctrl+Z / Ctrl+Shift+Z",
        "Undo / redo an edit (control points, lights, camera)",
    ),
    ("Space", "Pause / resume rendering"),
    ("R", "Restart the render (asks first when passes would be lost)"),
    (
        "E / Shift+E",
        "Exposure up / down half a stop (as in tev; also ] and [)",
    ),
    ("F", "Fit the image to the view (also: double-click)"),
    ("1", "Show the image 1:1"),
    ("+ / -", "Zoom in / out (also: mouse wheel over the image)"),
    (
        "Left drag",
        "Pan the image; on a control point or a light: move it (and the selection); on a spot light's aim point: turn it",
    ),
    (
        "Ctrl + left drag",
        "On a control point or a light: move it along the line of sight",
    ),
    (
        "Click / Shift+click",
        "Select a control point or a light / add it to the selection",
    ),
    ("A", "Select the whole patch of the selected point"),
    ("Esc", "Select nothing"),
    ("Arrows (Shift: ×10)", "Nudge the selection in the image plane"),
    (
        "Right drag",
        "Orbit the camera (Shift: pan, Ctrl: dolly; middle drag pans)",
    ),
    ("C", "Frame the selection (or all patches) with the camera"),
    ("W", "Show / hide the control nets"),
    ("[ / ]", "Exposure down / up by half a stop"),
    (
        "D",
        "Next display mode: radiance, radius, photon count (and the differences to a reference)",
    ),
    ("B", "A/B: show the reference instead of the render, and back"),
    ("P", "Show / hide the side panel"),
    ("F1", "This help"),
];

const OPEN: KeyboardShortcut = KeyboardShortcut::new(Modifiers::COMMAND, Key::O);
const SAVE: KeyboardShortcut = KeyboardShortcut::new(Modifiers::COMMAND, Key::S);
const SAVE_SCENE: KeyboardShortcut = KeyboardShortcut::new(Modifiers::COMMAND.plus(Modifiers::SHIFT), Key::S);
const UNDO: KeyboardShortcut = KeyboardShortcut::new(Modifiers::COMMAND, Key::Z);
const REDO: KeyboardShortcut = KeyboardShortcut::new(Modifiers::COMMAND.plus(Modifiers::SHIFT), Key::Z);
const REDO_Y: KeyboardShortcut = KeyboardShortcut::new(Modifiers::COMMAND, Key::Y);

/// The actions of the shortcuts pressed this frame (plain keys only when no widget has
/// focus).
pub fn handle(viewer: &ViewerState, ctx: &egui::Context, out: &mut Vec<Action>) {
    let shortcut = |s: &KeyboardShortcut| ctx.input_mut(|i| i.consume_shortcut(s));
    // With Shift before without: egui matches Ctrl+Z also when Shift is held.
    if shortcut(&SAVE_SCENE) {
        out.push(Action::SaveScene);
    } else if shortcut(&SAVE) {
        out.push(Action::SaveFrame);
    }
    if shortcut(&OPEN) {
        out.push(Action::PickScene);
    }
    if shortcut(&REDO) || shortcut(&REDO_Y) {
        out.push(Action::Redo);
    } else if shortcut(&UNDO) {
        out.push(Action::Undo);
    }
    // Plain keys belong to a focused widget (Space clicks a focused button, text fields type).
    if ctx.egui_wants_keyboard_input() || ctx.memory(|m| m.focused().is_some()) {
        return;
    }
    let pressed = |key: Key| ctx.input_mut(|i| i.consume_key(Modifiers::NONE, key));
    let settings = &viewer.settings;
    if pressed(Key::Space) {
        let mut p = viewer.params.clone();
        p.paused = !p.paused;
        out.push(Action::SetParams(p));
    }
    if pressed(Key::R) {
        out.push(Action::AskRestart);
    }
    // tev's exposure keys (Shift+E first: a plain-E match ignores Shift).
    if ctx.input_mut(|i| i.consume_key(Modifiers::SHIFT, Key::E)) {
        out.push(Action::SetExposure(settings.exposure_stops - 0.5));
    } else if pressed(Key::E) {
        out.push(Action::SetExposure(settings.exposure_stops + 0.5));
    }
    view_keys(viewer, ctx, out);
    if pressed(Key::OpenBracket) {
        out.push(Action::SetExposure(settings.exposure_stops - 0.5));
    }
    if pressed(Key::CloseBracket) {
        out.push(Action::SetExposure(settings.exposure_stops + 0.5));
    }
    if pressed(Key::D) {
        let modes: Vec<DisplayMode> = DisplayMode::all(&viewer.layer_labels())
            .into_iter()
            .filter(|m| viewer.reference().is_some() || !m.needs_reference())
            .collect();
        let at = modes.iter().position(|m| *m == settings.display).unwrap_or(0);
        out.push(Action::SetDisplay(modes[(at + 1) % modes.len()]));
    }
    if pressed(Key::B) && viewer.reference().is_some() {
        out.push(Action::ShowReference(!viewer.showing_reference()));
    }
    if pressed(Key::P) {
        out.push(Action::ShowSidePanel(!settings.show_side_panel));
    }
    if pressed(Key::F1) {
        out.push(Action::ShowHelp(!viewer.show_help));
    }
    editing_keys(viewer, ctx, out);
}

/// Zoom keys: fit, 1:1, in and out.
fn view_keys(viewer: &ViewerState, ctx: &egui::Context, out: &mut Vec<Action>) {
    let pressed = |key: Key| ctx.input_mut(|i| i.consume_key(Modifiers::NONE, key));
    let settings = &viewer.settings;
    if pressed(Key::F) {
        out.push(Action::SetZoom {
            zoom: Zoom::Fit,
            recentre: true,
        });
    }
    if pressed(Key::Num1) {
        out.push(Action::SetZoom {
            zoom: Zoom::Scale(1.0),
            recentre: true,
        });
    }
    let zoom_in = ctx.input_mut(|i| {
        i.consume_key(Modifiers::NONE, Key::Plus) || i.consume_key(Modifiers::NONE, Key::Equals)
    });
    let zoom_out = pressed(Key::Minus);
    if zoom_in || zoom_out {
        let factor = if zoom_in { 1.25 } else { 0.8 };
        let zoom = match settings.zoom {
            Zoom::Scale(s) => Zoom::Scale((s * factor).clamp(MIN_SCALE, MAX_SCALE)),
            Zoom::Fit => Zoom::Scale(factor),
        };
        out.push(Action::SetZoom {
            zoom,
            recentre: false,
        });
    }
}

/// Keys of the control-net editor.
fn editing_keys(viewer: &ViewerState, ctx: &egui::Context, out: &mut Vec<Action>) {
    let pressed = |key: Key| ctx.input_mut(|i| i.consume_key(Modifiers::NONE, key));
    if pressed(Key::W) {
        out.push(Action::ShowWireframe(!viewer.settings.show_wireframe));
    }
    if pressed(Key::C) {
        out.push(Action::FrameSelection);
    }
    let selected = viewer.editor.selection.first().copied();
    if pressed(Key::Escape) && selected.is_some() {
        out.push(Action::ClearSelection);
    }
    if pressed(Key::A) {
        out.extend(selected.and_then(|h| h.patch()).map(Action::SelectPatch));
    }
    if selected.is_none() {
        return;
    }
    for (key, step) in [
        (Key::ArrowLeft, Vec2::new(-1.0, 0.0)),
        (Key::ArrowRight, Vec2::new(1.0, 0.0)),
        (Key::ArrowUp, Vec2::new(0.0, -1.0)),
        (Key::ArrowDown, Vec2::new(0.0, 1.0)),
    ] {
        // Shift first: a plain match ignores Shift.
        if ctx.input_mut(|i| i.consume_key(Modifiers::SHIFT, key)) {
            out.push(Action::Nudge(step * 20.0));
        } else if pressed(key) {
            out.push(Action::Nudge(step * 2.0));
        }
    }
}
