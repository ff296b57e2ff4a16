//! The side panel's Design section: the surface to shape, the receiver to draw on and the
//! target image, Start and Stop, the design's progress and its loss plot (`caustic design` in
//! the window; [`super::design`]).

use egui::RichText;
use egui_plot::{Line, Plot, PlotPoints};

use super::action::Action;
use super::state::ViewerState;
use crate::design::setup::design_candidates;

/// The object a selected control point belongs to.
pub fn selected_object(viewer: &ViewerState) -> Option<u32> {
    let doc = &viewer.document;
    let k = viewer
        .editor
        .selection
        .iter()
        .find_map(|h| doc.handle_patch(*h))?;
    doc.scene().geometry.patches().get(k).map(|(_, id)| *id)
}

/// A drop-down of `names` with `current` chosen; `Some` with the name picked.
fn choice_ui(ui: &mut egui::Ui, label: &str, names: &[String], current: &str, tip: &str) -> Option<String> {
    let mut picked = None;
    ui.horizontal(|ui| {
        ui.label(label).on_hover_text(tip);
        egui::ComboBox::from_id_salt(("caustic-design", label))
            .selected_text(current)
            .show_ui(ui, |ui| {
                for name in names {
                    if ui.selectable_label(name == current, name).clicked() && name != current {
                        picked = Some(name.clone());
                    }
                }
            });
    });
    picked
}

/// The Design section (under its heading, drawn by the panel).
pub fn design_panel_ui(viewer: &ViewerState, ui: &mut egui::Ui, out: &mut Vec<Action>) {
    let design = viewer.design();
    let scene = viewer.scene();
    let (surfaces, receivers) = design_candidates(scene);
    let selected = selected_object(viewer).and_then(|k| scene.objects.get(k as usize));
    let surface = design.surface(&surfaces, selected.map(|o| o.name.as_str()));
    let receiver = design.receiver(&receivers);
    let running = design.running();
    ui.add_enabled_ui(!running, |ui| {
        match &surface {
            Some(current) => out.extend(
                choice_ui(ui, "Surface", &surfaces, current, "The patches of smooth glass or mirror whose control points move (the selected point's object, or 'lens', unless you choose)")
                    .map(Action::SetDesignSurface),
            ),
            None => {
                ui.label("No surface to design: it needs patches of smooth glass or mirror.");
            }
        }
        match &receiver {
            Some(current) => out.extend(
                choice_ui(ui, "Receiver", &receivers, current, "The quad the light draws the target on (the one named 'screen', unless you choose); the target's top-left pixel is at its corner + edge_v")
                    .map(Action::SetDesignReceiver),
            ),
            None => {
                ui.label("No receiver: the light draws on a quad object.");
            }
        }
        ui.horizontal(|ui| {
            let name = design.target().map_or("(none)".into(), |t| {
                t.file_name().map_or(t.display().to_string(), |n| n.to_string_lossy().into_owned())
            });
            ui.label("Target").on_hover_text("The picture the light should draw, taken as luminance (PNG, JPEG, EXR, PFM)");
            ui.label(RichText::new(name).monospace());
            if ui.button("Choose...").on_hover_text("Open a target image").clicked() {
                out.push(Action::PickDesignTarget);
            }
        });
        let mut steps = design.steps();
        ui.horizontal(|ui| {
            ui.label("Steps").on_hover_text("Steps of the descent; the same steps give the same surface on any machine. The design also ends after 110 s");
            if ui.add(egui::DragValue::new(&mut steps).range(1..=1_000_000).speed(10)).changed() {
                out.push(Action::SetDesignSteps(steps));
            }
        });
    });
    ui.horizontal(|ui| {
        let can_start = !running && surface.is_some() && receiver.is_some() && design.target().is_some();
        if ui
            .add_enabled(can_start, egui::Button::new("Start"))
            .on_hover_text("Move the surface's control points until the light draws the target; the render follows. Undo puts the surface back in one step")
            .clicked()
        {
            out.push(Action::StartDesign);
        }
        if ui
            .add_enabled(running, egui::Button::new("Stop"))
            .on_hover_text("End the design after its current step, keeping the surface as it is")
            .clicked()
        {
            out.push(Action::StopDesign);
        }
    });
    progress_ui(viewer, ui);
}

/// The design's figures, its message and its loss plot.
fn progress_ui(viewer: &ViewerState, ui: &mut egui::Ui) {
    let design = viewer.design();
    if let Some(r) = design.latest() {
        ui.label(format!(
            "step {} of {}: loss {:.4}, {:.0} % landed, {:.1} s ({} control points)",
            r.step + 1,
            design.steps(),
            r.loss,
            100.0 * r.landed,
            r.elapsed,
            design.parameters
        ));
    }
    match design.message() {
        Some(Ok(m)) => {
            ui.label(RichText::new(m).small());
        }
        Some(Err(e)) => {
            ui.label(RichText::new(e).small().color(ui.visuals().error_fg_color));
        }
        None => {}
    }
    if design.losses().is_empty() {
        return;
    }
    let points: Vec<[f64; 2]> = design
        .losses()
        .iter()
        .map(|[s, l]| [*s, l.max(1e-12).log10()])
        .collect();
    ui.label("Loss against step").on_hover_text(
        "Log scale. The loss compares the light drawn on the receiver with the target, whatever its brightness: 0 is the target exactly. Each step sees one of 8 sets of photons, so the curve is noisy",
    );
    Plot::new("caustic-design-loss")
        .height(90.0)
        .allow_zoom(false)
        .allow_drag(false)
        .allow_scroll(false)
        .y_axis_formatter(|mark, _| format!("{:.2}", 10f64.powf(mark.value)))
        .show(ui, |plot| plot.line(Line::new("loss", PlotPoints::from(points))));
}
