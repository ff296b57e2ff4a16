//! The Edit menu and the side panel's editing section: undo/redo, selection, exact
//! coordinates of a selected control point, framing, saving the scene.

use egui::RichText;

use super::action::Action;
use super::overlay::PointRef;
use super::viewer::Viewer;

/// The Edit menu.
pub fn edit_menu_ui(viewer: &Viewer, ui: &mut egui::Ui, out: &mut Vec<Action>) {
    let (can_undo, can_redo) = viewer.editor.history.can_undo_redo();
    let selected = viewer.editor.selection.first().copied();
    ui.menu_button("Edit", |ui| {
        if ui
            .add_enabled(can_undo, egui::Button::new("Undo  (Ctrl+Z)"))
            .on_hover_text("Undo the last control-point or camera edit")
            .clicked()
        {
            out.push(Action::Undo);
        }
        if ui
            .add_enabled(can_redo, egui::Button::new("Redo  (Ctrl+Shift+Z)"))
            .on_hover_text("Redo the last undone edit")
            .clicked()
        {
            out.push(Action::Redo);
        }
        ui.separator();
        if ui
            .add_enabled(selected.is_some(), egui::Button::new("Select whole patch  (A)"))
            .on_hover_text("Select all 16 control points of the selected point's patch, to move it as one")
            .clicked()
        {
            out.extend(selected.map(|r| Action::SelectPatch(r.patch)));
        }
        if ui
            .add_enabled(selected.is_some(), egui::Button::new("Select none  (Esc)"))
            .on_hover_text("Clear the selection")
            .clicked()
        {
            out.push(Action::ClearSelection);
        }
        if ui
            .button("Frame selection  (C)")
            .on_hover_text("Turn and move the camera onto the selection (or all patches)")
            .clicked()
        {
            out.push(Action::FrameSelection);
        }
    });
}

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

/// The side panel's editing section.
pub fn edit_panel_ui(viewer: &Viewer, ui: &mut egui::Ui, out: &mut Vec<Action>) {
    let editor = &viewer.editor;
    ui.heading("Edit");
    let mut nets = viewer.settings.show_wireframe;
    if ui
        .checkbox(&mut nets, "Show control nets")
        .on_hover_text(
            "Draw the control nets over the image; click a point to select it, drag to move it (W)",
        )
        .changed()
    {
        out.push(Action::ShowWireframe(nets));
    }
    let n = editor.selection.len();
    match editor.selection.first() {
        None => {
            ui.label(RichText::new("Click a control point to select it (Shift adds).").weak());
        }
        Some(&first) if n == 1 => {
            ui.label(format!(
                "Patch {}, point {} (row {}, column {})",
                first.patch,
                first.index,
                first.index / 4,
                first.index % 4
            ));
            // A drag of the field moves about a thousandth of the patch per point.
            let speed = (editor.patches[first.patch].bounds().diagonal().length() * 1e-3).max(1e-6);
            if let Some(p) = coordinates_ui(ui, editor.point(first), speed) {
                out.push(Action::SetPoint(first, p));
            }
        }
        Some(_) => {
            let patches: std::collections::BTreeSet<usize> =
                editor.selection.iter().map(|r: &PointRef| r.patch).collect();
            ui.label(format!("{n} points selected in {} patch(es)", patches.len()));
        }
    }
    ui.horizontal(|ui| {
        let (can_undo, can_redo) = editor.history.can_undo_redo();
        if ui
            .add_enabled(can_undo, egui::Button::new("Undo"))
            .on_hover_text("Ctrl+Z")
            .clicked()
        {
            out.push(Action::Undo);
        }
        if ui
            .add_enabled(can_redo, egui::Button::new("Redo"))
            .on_hover_text("Ctrl+Shift+Z")
            .clicked()
        {
            out.push(Action::Redo);
        }
        if ui
            .add_enabled(n > 0, egui::Button::new("Whole patch"))
            .on_hover_text("Select every control point of the selected point's patch (A)")
            .clicked()
        {
            out.extend(editor.selection.first().map(|r| Action::SelectPatch(r.patch)));
        }
        if ui
            .button("Frame")
            .on_hover_text("Point the camera at the selection, or at all patches (C)")
            .clicked()
        {
            out.push(Action::FrameSelection);
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
