//! Keyboard shortcuts (listed in the help window from the same table).

use egui::{Key, KeyboardShortcut, Modifiers};

use super::image_view::{MAX_SCALE, MIN_SCALE};
use super::settings::{DisplayMode, Zoom, EXPOSURE_LIMIT};
use super::viewer::Viewer;

/// Shortcuts as shown in the help window: (keys, what they do).
pub const HELP: &[(&str, &str)] = &[
    ("Ctrl+O", "Open a scene (or drop a .toml file on the window)"),
    ("Ctrl+S", "Save the current frame (PNG as displayed, EXR linear)"),
    ("Space", "Pause / resume rendering"),
    ("R", "Restart the render"),
    ("F", "Fit the image to the view (also: double-click)"),
    ("1", "Show the image 1:1"),
    ("+ / -", "Zoom in / out (also: mouse wheel over the image)"),
    ("Drag", "Pan the image"),
    ("[ / ]", "Exposure down / up by half a stop"),
    ("D", "Next display mode: radiance, radius, photon count"),
    ("P", "Show / hide the side panel"),
    ("F1", "This help"),
];

const OPEN: KeyboardShortcut = KeyboardShortcut::new(Modifiers::COMMAND, Key::O);
const SAVE: KeyboardShortcut = KeyboardShortcut::new(Modifiers::COMMAND, Key::S);

/// Applies the shortcuts pressed this frame (plain keys only when no widget has focus).
pub fn handle(viewer: &mut Viewer, ctx: &egui::Context) {
    if ctx.input_mut(|i| i.consume_shortcut(&OPEN)) {
        viewer.pick_scene();
    }
    if ctx.input_mut(|i| i.consume_shortcut(&SAVE)) {
        viewer.save_with_dialog();
    }
    // Plain keys belong to a focused widget (Space clicks a focused button, text fields type).
    if ctx.egui_wants_keyboard_input() || ctx.memory(|m| m.focused().is_some()) {
        return;
    }
    let pressed = |key: Key| ctx.input_mut(|i| i.consume_key(Modifiers::NONE, key));
    if pressed(Key::Space) {
        let mut p = viewer.params.clone();
        p.paused = !p.paused;
        viewer.set_params(p);
    }
    if pressed(Key::R) {
        viewer.send(crate::render::session::Command::Restart);
    }
    if pressed(Key::F) {
        viewer.settings.zoom = Zoom::Fit;
        viewer.image_view.recentre();
    }
    if pressed(Key::Num1) {
        viewer.settings.zoom = Zoom::Scale(1.0);
        viewer.image_view.recentre();
    }
    let zoom_in = ctx.input_mut(|i| {
        i.consume_key(Modifiers::NONE, Key::Plus) || i.consume_key(Modifiers::NONE, Key::Equals)
    });
    let zoom_out = pressed(Key::Minus);
    if zoom_in || zoom_out {
        let factor = if zoom_in { 1.25 } else { 0.8 };
        viewer.settings.zoom = match viewer.settings.zoom {
            Zoom::Scale(s) => Zoom::Scale((s * factor).clamp(MIN_SCALE, MAX_SCALE)),
            Zoom::Fit => Zoom::Scale(factor),
        };
    }
    if pressed(Key::OpenBracket) {
        viewer.settings.exposure_stops = (viewer.settings.exposure_stops - 0.5).max(-EXPOSURE_LIMIT);
        viewer.image_view.invalidate();
    }
    if pressed(Key::CloseBracket) {
        viewer.settings.exposure_stops = (viewer.settings.exposure_stops + 0.5).min(EXPOSURE_LIMIT);
        viewer.image_view.invalidate();
    }
    if pressed(Key::D) {
        let modes = DisplayMode::ALL;
        let at = modes
            .iter()
            .position(|m| *m == viewer.settings.display)
            .unwrap_or(0);
        viewer.settings.display = modes[(at + 1) % modes.len()];
        viewer.image_view.invalidate();
    }
    if pressed(Key::P) {
        viewer.settings.show_side_panel = !viewer.settings.show_side_panel;
    }
    if pressed(Key::F1) {
        viewer.show_help = !viewer.show_help;
    }
}
