//! The keyboard: the commands' shortcuts ([`super::commands`], the one table of them), and the
//! arrow keys, which nudge the selection.

use egui::{Key, Modifiers, Vec2};

use super::action::Action;
use super::state::ViewerState;

/// The actions of the keys pressed this frame.
pub fn handle(viewer: &ViewerState, ctx: &egui::Context, out: &mut Vec<Action>) {
    super::commands::shortcuts(viewer, ctx, out);
    // Plain keys belong to a focused widget (text fields move their cursor with the arrows).
    if ctx.egui_wants_keyboard_input() || ctx.memory(|m| m.focused().is_some()) {
        return;
    }
    if viewer.editor.selection.is_empty() {
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
        } else if ctx.input_mut(|i| i.consume_key(Modifiers::NONE, key)) {
            out.push(Action::Nudge(step * 2.0));
        }
    }
}
