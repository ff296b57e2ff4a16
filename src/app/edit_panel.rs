//! The side panel's editing section: the Edit menu's commands as buttons, the selection, exact
//! coordinates of a selected control point, its patch's material, saving the scene.

use egui::RichText;

use super::action::Action;
use super::commands::{Menu, COMMANDS};
use super::document::Document;
use super::editor::Editor;
use super::handle::{Handle, LightPart};
use super::material_panel::material_ui;
use super::state::ViewerState;

/// Three fields for a point's x, y, z; `Some` with the new position when one was changed.
fn coordinates_ui(ui: &mut egui::Ui, position: glam::DVec3, speed: f64) -> Option<glam::DVec3> {
    let mut p = position;
    ui.horizontal(|ui| {
        for (axis, value) in ["x", "y", "z"].into_iter().zip([&mut p.x, &mut p.y, &mut p.z]) {
            ui.label(axis);
            ui.add(egui::DragValue::new(value).speed(speed).max_decimals(6))
                .on_hover_text(format!(
                    "The point's {axis} in scene units: drag, or click and type an exact value"
                ));
        }
    });
    (p != position && p.is_finite()).then_some(p)
}

/// The side panel's editing section (under its heading, drawn by the panel).
pub fn edit_panel_ui(viewer: &ViewerState, ui: &mut egui::Ui, out: &mut Vec<Action>) {
    let editor = &viewer.editor;
    let mut nets = viewer.settings.show_wireframe;
    if ui
        .checkbox(&mut nets, "Show control nets and lights")
        .on_hover_text(
            "Draw the control nets and the lights over the image; click a point or a light to select it, drag to move it (W)",
        )
        .changed()
    {
        out.push(Action::ShowWireframe(nets));
    }
    selection_ui(editor, &viewer.document, ui, out);
    material_ui(viewer, ui, out);
    // The Edit menu's commands, as buttons.
    ui.horizontal_wrapped(|ui| {
        for c in COMMANDS.iter().filter(|c| c.menu == Menu::Edit) {
            let action = (c.action)(viewer);
            let tip = format!("{} ({})", c.tooltip, c.keys);
            if ui
                .add_enabled(action.is_some(), egui::Button::new(c.label))
                .on_hover_text(tip)
                .clicked()
            {
                out.extend(action);
            }
        }
    });
    let label = if viewer.unsaved_edits() {
        "Save scene...  (unsaved edits)"
    } else {
        "Save scene..."
    };
    if ui
        .button(label)
        .on_hover_text(
            "Write the scene as edited to a .toml file that loads back to the same patches (Ctrl+Shift+S)",
        )
        .clicked()
    {
        out.push(Action::SaveScene);
    }
}

/// What is selected: a hint when nothing is, one handle's name and exact x/y/z fields, or a
/// count of the points, patches and light handles.
fn selection_ui(editor: &Editor, doc: &Document, ui: &mut egui::Ui, out: &mut Vec<Action>) {
    let n = editor.selection.len();
    match editor.selection.first() {
        None => {
            ui.label(RichText::new("Click a control point or a light to select it (Shift adds).").weak());
        }
        Some(&first) if n == 1 => {
            let (label, size) = handle_label(editor, doc, first);
            ui.label(label);
            // A drag of the field moves about a thousandth of the patch (or scene) per point.
            let speed = (size * 1e-3).max(1e-6);
            if let Some(p) = coordinates_ui(ui, editor.point(doc, first), speed) {
                out.push(Action::SetPoint(first, p));
            }
        }
        Some(_) => {
            let patches: std::collections::BTreeSet<usize> = editor
                .selection
                .iter()
                .filter_map(|h| doc.handle_patch(*h))
                .collect();
            let lights = editor.selection.iter().filter(|h| !h.is_point()).count();
            ui.label(match lights {
                0 => format!("{n} points selected in {} patch(es)", patches.len()),
                _ => format!(
                    "{} points selected in {} patch(es), {lights} light handle(s)",
                    n - lights,
                    patches.len()
                ),
            });
        }
    }
}

/// A handle's name in the panel and the size its fields step by a thousandth of: its patch's
/// diagonal, or for a light four times its aim distance (the scene's diagonal until a drag of
/// the aim changed it).
fn handle_label(editor: &Editor, doc: &Document, h: Handle) -> (String, f64) {
    match h {
        Handle::Control(r) => {
            let weight = doc.scene().geometry.patch_weights(r.patch).map(|w| w[r.index]);
            (
                format!(
                    "Patch {}, point {} (row {}, column {}){}",
                    r.patch,
                    r.index,
                    r.index / 4,
                    r.index % 4,
                    weight.map_or(String::new(), |w| format!(", weight {w:.6}"))
                ),
                doc.patch(r.patch).map_or(1.0, |p| p.bounds().diagonal().length()),
            )
        }
        Handle::Net(r) => {
            let geometry = &doc.scene().geometry;
            let net = &geometry.nets()[r.net];
            let (nu, nv) = net.net.size();
            let weight = doc.net_point(r).map_or(1.0, |(_, w)| w);
            let patch = geometry.patches().get(net.patches.start);
            (
                format!(
                    "Surface {} ({nu} × {nv} points), point {} (u {}, v {}), weight {weight:.6}",
                    r.net,
                    r.index,
                    r.index % nu,
                    r.index / nu
                ),
                patch.map_or(1.0, |(p, _)| p.bounds().diagonal().length()),
            )
        }
        Handle::Light(l) => (
            format!(
                "Light {}: {}",
                l.light,
                match l.part {
                    LightPart::Place => "where it is",
                    LightPart::Aim => "the point it aims at",
                }
            ),
            editor.aims.get(l.light).copied().unwrap_or(1.0) * 4.0,
        ),
    }
}
