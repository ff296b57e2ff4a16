//! The viewer's commands in one table, as rerun's `re_ui` keeps its command list: each
//! command's label, tooltip, keys, shortcuts and menu, and the action it asks for in the
//! viewer's state. The menus ([`menu_ui`]), the keyboard ([`shortcuts`]) and F1's help
//! ([`help_rows`]) are drawn from it; a new command is one entry here.

use egui::{Key, Modifiers};

use super::action::Action;
use super::image_view::{MAX_SCALE, MIN_SCALE};
use super::settings::{DisplayMode, Zoom};
use super::state::ViewerState;

/// Which menu lists a command.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Menu {
    /// File.
    File,
    /// Edit.
    Edit,
    /// View.
    View,
    /// Help.
    Help,
    /// None: a key only.
    None,
}

/// One command of the viewer.
pub struct Command {
    /// Its name in menus and buttons.
    pub label: &'static str,
    /// What it does: the menu item's tooltip and F1's help.
    pub tooltip: &'static str,
    /// Its keys as the menus and F1's help show them (empty: none).
    pub keys: &'static str,
    /// Its shortcuts, first match first. Keys without Ctrl act only when no widget has the
    /// keyboard (Space clicks a focused button, text fields type).
    pub shortcuts: &'static [(Modifiers, Key)],
    /// The menu that lists it.
    pub menu: Menu,
    /// The action it asks for in this state (`None`: it does nothing now; its menu item is
    /// disabled).
    pub action: fn(&ViewerState) -> Option<Action>,
    /// For a command that switches something on and off, whether it is on (its menu item is
    /// then a checkbox).
    pub checked: Option<fn(&ViewerState) -> bool>,
}

const NONE: Modifiers = Modifiers::NONE;
const CTRL: Modifiers = Modifiers::COMMAND;
const SHIFT: Modifiers = Modifiers::SHIFT;
const CTRL_SHIFT: Modifiers = Modifiers::COMMAND.plus(Modifiers::SHIFT);

/// Exposure steps of the exposure keys (half a stop, as tev's).
const EXPOSURE_STEP: f32 = 0.5;

/// The zoom `factor` times the current one.
fn zoomed(viewer: &ViewerState, factor: f32) -> Option<Action> {
    let zoom = match viewer.settings.zoom {
        Zoom::Scale(s) => Zoom::Scale((s * factor).clamp(MIN_SCALE, MAX_SCALE)),
        Zoom::Fit => Zoom::Scale(factor),
    };
    Some(Action::SetZoom {
        zoom,
        recentre: false,
    })
}

/// The display mode after the current one, among those the frame and the reference allow.
fn next_display(viewer: &ViewerState) -> Option<Action> {
    let modes: Vec<DisplayMode> = DisplayMode::all(&viewer.layer_labels())
        .into_iter()
        .filter(|m| viewer.reference().is_some() || !m.needs_reference())
        .collect();
    let at = modes
        .iter()
        .position(|m| *m == viewer.settings.display)
        .unwrap_or(0);
    Some(Action::SetDisplay(modes[(at + 1) % modes.len()]))
}

/// Every command, in menu order.
pub const COMMANDS: &[Command] = &[
    Command {
        label: "Open scene...",
        tooltip: "Open a scene (or drop a .toml file on the window)",
        keys: "Ctrl+O",
        shortcuts: &[(CTRL, Key::O)],
        menu: Menu::File,
        action: |_| Some(Action::PickScene),
        checked: None,
    },
    Command {
        label: "Save frame...",
        tooltip: "Save the current frame (PNG as displayed, EXR linear)",
        keys: "Ctrl+S",
        shortcuts: &[(CTRL, Key::S)],
        menu: Menu::File,
        action: |_| Some(Action::SaveFrame),
        checked: None,
    },
    Command {
        label: "Save scene",
        tooltip: "Save the scene as edited (TOML)",
        keys: "Ctrl+Shift+S",
        shortcuts: &[(CTRL_SHIFT, Key::S)],
        menu: Menu::File,
        action: |_| Some(Action::SaveScene),
        checked: None,
    },
    Command {
        label: "Save scene as...",
        tooltip: "Write the scene as edited to a new .toml file that loads back to the same patches",
        keys: "",
        shortcuts: &[],
        menu: Menu::File,
        action: |_| Some(Action::SaveSceneAs),
        checked: None,
    },
    Command {
        label: "Send frame to tev",
        tooltip: "Show the current frame (radiance and the renderer's layers) in a running tev at 127.0.0.1:14158",
        keys: "",
        shortcuts: &[],
        menu: Menu::File,
        action: |_| Some(Action::SendToTev(crate::tev::DEFAULT_ADDRESS.into())),
        checked: None,
    },
    Command {
        label: "Watch a render folder...",
        tooltip: "Show the parts a farm writes into a folder (caustic render --shard), merged as they land, with the passes done and the error estimate",
        keys: "",
        shortcuts: &[],
        menu: Menu::File,
        action: |v| v.watching().is_none().then_some(Action::PickWatchFolder),
        checked: None,
    },
    Command {
        label: "Stop watching",
        tooltip: "Stop merging the render folder's parts and render the scene again",
        keys: "",
        shortcuts: &[],
        menu: Menu::File,
        action: |v| v.watching().map(|_| Action::StopWatching),
        checked: None,
    },
    Command {
        label: "Open reference...",
        tooltip: "Compare with a reference image (.exr or .pfm of the render's size): the true error in the plot, difference views and A/B; you can also drop one on the window",
        keys: "",
        shortcuts: &[],
        menu: Menu::File,
        action: |_| Some(Action::PickReference),
        checked: None,
    },
    Command {
        label: "Close reference",
        tooltip: "Stop comparing with the reference",
        keys: "",
        shortcuts: &[],
        menu: Menu::File,
        action: |v| v.reference().map(|_| Action::CloseReference),
        checked: None,
    },
    Command {
        label: "Quit",
        tooltip: "Close the viewer (settings are kept; unsaved edits are asked about)",
        keys: "",
        shortcuts: &[],
        menu: Menu::File,
        action: |_| Some(Action::Close),
        checked: None,
    },
    Command {
        label: "Undo",
        tooltip: "Undo an edit (control points, lights, camera)",
        keys: "Ctrl+Z",
        shortcuts: &[(CTRL, Key::Z)],
        menu: Menu::Edit,
        action: |v| v.editor.history.can_undo_redo().0.then_some(Action::Undo),
        checked: None,
    },
    Command {
        label: "Redo",
        tooltip: "Redo the last undone edit",
        keys: "Ctrl+Shift+Z",
        shortcuts: &[(CTRL_SHIFT, Key::Z), (CTRL, Key::Y)],
        menu: Menu::Edit,
        action: |v| v.editor.history.can_undo_redo().1.then_some(Action::Redo),
        checked: None,
    },
    Command {
        label: "Whole patch",
        tooltip: "Select the whole patch of the selected point",
        keys: "A",
        shortcuts: &[(NONE, Key::A)],
        menu: Menu::Edit,
        action: |v| {
            let first = v.editor.selection.first()?;
            v.document.handle_patch(*first).map(Action::SelectPatch)
        },
        checked: None,
    },
    Command {
        label: "Select none",
        tooltip: "Select nothing",
        keys: "Esc",
        shortcuts: &[(NONE, Key::Escape)],
        menu: Menu::Edit,
        action: |v| v.editor.selection.first().map(|_| Action::ClearSelection),
        checked: None,
    },
    Command {
        label: "Frame",
        tooltip: "Frame the selection (or all patches and lights) with the camera",
        keys: "C",
        shortcuts: &[(NONE, Key::C)],
        menu: Menu::Edit,
        action: |_| Some(Action::FrameSelection),
        checked: None,
    },
    Command {
        label: "Pause / resume",
        tooltip: "Pause / resume rendering",
        keys: "Space",
        shortcuts: &[(NONE, Key::Space)],
        menu: Menu::None,
        action: |v| {
            let mut p = v.params();
            p.paused = !p.paused;
            Some(Action::SetParams(p))
        },
        checked: None,
    },
    Command {
        label: "Restart",
        tooltip: "Restart the render (asks first when passes would be lost)",
        keys: "R",
        shortcuts: &[(NONE, Key::R)],
        menu: Menu::None,
        action: |_| Some(Action::AskRestart),
        checked: None,
    },
    Command {
        label: "Exposure up",
        tooltip: "Exposure up half a stop (as in tev)",
        keys: "E / ]",
        shortcuts: &[(NONE, Key::E), (NONE, Key::CloseBracket)],
        menu: Menu::None,
        action: |v| Some(Action::SetExposure(v.settings.exposure_stops + EXPOSURE_STEP)),
        checked: None,
    },
    Command {
        label: "Exposure down",
        tooltip: "Exposure down half a stop (as in tev)",
        keys: "Shift+E / [",
        shortcuts: &[(SHIFT, Key::E), (NONE, Key::OpenBracket)],
        menu: Menu::None,
        action: |v| Some(Action::SetExposure(v.settings.exposure_stops - EXPOSURE_STEP)),
        checked: None,
    },
    Command {
        label: "Fit",
        tooltip: "Fit the image to the view (also: double-click)",
        keys: "F",
        shortcuts: &[(NONE, Key::F)],
        menu: Menu::View,
        action: |_| {
            Some(Action::SetZoom {
                zoom: Zoom::Fit,
                recentre: true,
            })
        },
        checked: None,
    },
    Command {
        label: "1:1",
        tooltip: "Show the image 1:1",
        keys: "1",
        shortcuts: &[(NONE, Key::Num1)],
        menu: Menu::View,
        action: |_| {
            Some(Action::SetZoom {
                zoom: Zoom::Scale(1.0),
                recentre: true,
            })
        },
        checked: None,
    },
    Command {
        label: "Zoom in",
        tooltip: "Zoom in (also: mouse wheel over the image)",
        keys: "+",
        shortcuts: &[(NONE, Key::Plus), (NONE, Key::Equals)],
        menu: Menu::None,
        action: |v| zoomed(v, 1.25),
        checked: None,
    },
    Command {
        label: "Zoom out",
        tooltip: "Zoom out (also: mouse wheel over the image)",
        keys: "-",
        shortcuts: &[(NONE, Key::Minus)],
        menu: Menu::None,
        action: |v| zoomed(v, 0.8),
        checked: None,
    },
    Command {
        label: "Next display mode",
        tooltip: "Next display mode: radiance, the renderer's layers (photon mapping: radius, photons), the differences to a reference",
        keys: "D",
        shortcuts: &[(NONE, Key::D)],
        menu: Menu::None,
        action: next_display,
        checked: None,
    },
    Command {
        label: "Show the reference (A/B)",
        tooltip: "A/B: show the reference instead of the render, and back",
        keys: "B",
        shortcuts: &[(NONE, Key::B)],
        menu: Menu::View,
        action: |v| v.reference().map(|_| Action::ShowReference(!v.showing_reference())),
        checked: Some(|v| v.showing_reference()),
    },
    Command {
        label: "Control nets and lights",
        tooltip: "Show / hide the control nets and the lights",
        keys: "W",
        shortcuts: &[(NONE, Key::W)],
        menu: Menu::View,
        action: |v| Some(Action::ShowWireframe(!v.settings.show_wireframe)),
        checked: Some(|v| v.settings.show_wireframe),
    },
    Command {
        label: "Side panel",
        tooltip: "Show / hide the side panel",
        keys: "P",
        shortcuts: &[(NONE, Key::P)],
        menu: Menu::View,
        action: |v| Some(Action::ShowSidePanel(!v.settings.show_side_panel)),
        checked: Some(|v| v.settings.show_side_panel),
    },
    Command {
        label: "Keys and mouse",
        tooltip: "This help",
        keys: "F1",
        shortcuts: &[(NONE, Key::F1)],
        menu: Menu::Help,
        action: |v| Some(Action::ShowHelp(!v.show_help)),
        checked: None,
    },
];

/// What the mouse does, for F1's help (gestures are not commands).
pub const GESTURES: &[(&str, &str)] = &[
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
    ("Arrows (Shift: ×10)", "Nudge the selection in the image plane"),
    (
        "Right drag",
        "Orbit the camera (Shift: pan, Ctrl: dolly; middle drag pans)",
    ),
];

/// F1's help: every command with keys, then the mouse.
pub fn help_rows() -> Vec<(&'static str, &'static str)> {
    COMMANDS
        .iter()
        .filter(|c| !c.keys.is_empty())
        .map(|c| (c.keys, c.tooltip))
        .chain(GESTURES.iter().copied())
        .collect()
}

/// The actions of the shortcuts pressed this frame: the commands' first (shortcuts with more
/// modifiers first, since egui matches Ctrl+Z when Shift is held too; keys without Ctrl only
/// when no widget has the keyboard).
pub fn shortcuts(viewer: &ViewerState, ctx: &egui::Context, out: &mut Vec<Action>) {
    let typing = ctx.egui_wants_keyboard_input() || ctx.memory(|m| m.focused().is_some());
    let mut all: Vec<(&Command, Modifiers, Key)> = COMMANDS
        .iter()
        .flat_map(|c| c.shortcuts.iter().map(move |&(m, k)| (c, m, k)))
        .collect();
    all.sort_by_key(|(_, m, _)| std::cmp::Reverse(modifier_count(*m)));
    for (command, modifiers, key) in all {
        if typing && !modifiers.command {
            continue;
        }
        if ctx.input_mut(|i| i.consume_key(modifiers, key)) {
            out.extend((command.action)(viewer));
        }
    }
}

/// How many modifiers a shortcut holds.
fn modifier_count(m: Modifiers) -> u32 {
    u32::from(m.alt) + u32::from(m.ctrl) + u32::from(m.shift) + u32::from(m.mac_cmd) + u32::from(m.command)
}

/// The commands of `menu` as menu items: label, keys, tooltip, enabled by their state.
pub fn menu_ui(viewer: &ViewerState, menu: Menu, ui: &mut egui::Ui, out: &mut Vec<Action>) {
    for c in COMMANDS.iter().filter(|c| c.menu == menu) {
        let action = (c.action)(viewer);
        let text = if c.keys.is_empty() {
            c.label.to_owned()
        } else {
            format!("{}  ({})", c.label, c.keys)
        };
        let clicked = match c.checked {
            Some(on) => {
                let mut on = on(viewer);
                ui.add_enabled(action.is_some(), egui::Checkbox::new(&mut on, text))
                    .on_hover_text(c.tooltip)
                    .changed()
            }
            None => ui
                .add_enabled(action.is_some(), egui::Button::new(text))
                .on_hover_text(c.tooltip)
                .clicked(),
        };
        if clicked {
            out.extend(action);
        }
    }
}

/// The command labelled `label`.
pub fn command(label: &str) -> Option<&'static Command> {
    COMMANDS.iter().find(|c| c.label == label)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn no_two_commands_share_a_shortcut() {
        let mut seen = Vec::new();
        for c in COMMANDS {
            for s in c.shortcuts {
                assert!(!seen.contains(s), "{} shares {s:?}", c.label);
                seen.push(*s);
            }
        }
    }
}
