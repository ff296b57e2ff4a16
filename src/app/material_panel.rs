//! The side panel's material section: the numbers of the selected patch's material — a rough
//! surface's roughness, glass's index, a Phong lobe's strength and exponent — edited live. An
//! edit restarts the render cold (every pixel may change), a slider drag is one undo step, and
//! Save scene writes the new numbers into the material's table.

use egui::RichText;

use super::action::Action;
use super::state::ViewerState;
use crate::scene::glasses::Dispersion;
use crate::scene::{Material, MaterialKind};

/// The material of the first selected control point's patch, with its controls.
pub fn material_ui(viewer: &ViewerState, ui: &mut egui::Ui, out: &mut Vec<Action>) {
    let doc = &viewer.document;
    let selected = viewer.editor.selection.iter().find_map(|h| doc.handle_patch(*h));
    let Some(index) = selected.and_then(|p| doc.patch_material(p)) else {
        return;
    };
    let material = &doc.materials()[index];
    ui.label(RichText::new(format!("Material '{}': {}", material.name, model(material))).strong());
    let mut edited = material.clone();
    let responses = controls(ui, &mut edited.kind);
    if responses.is_empty() {
        ui.label(
            RichText::new("Nothing to tune: a diffuse surface's colour is set in the scene file.").weak(),
        );
    }
    if edited != *material && responses.iter().any(egui::Response::changed) {
        out.push(Action::SetMaterial {
            material: index,
            value: edited,
            drag: responses
                .iter()
                .any(egui::Response::dragged)
                .then(|| ui.input(|i| i.pointer.press_start_time()).map(f64::to_bits))
                .flatten(),
        });
    }
}

/// The model's name as the panel shows it.
fn model(m: &Material) -> String {
    match m.kind {
        MaterialKind::Diffuse { specular, .. } if specular > 0.0 => "Phong".into(),
        MaterialKind::Diffuse { .. } => "diffuse".into(),
        MaterialKind::Mirror { .. } => "mirror".into(),
        MaterialKind::Metal { .. } => "metal".into(),
        MaterialKind::Glass { dispersion, .. } => match dispersion {
            Dispersion::None => "glass".into(),
            Dispersion::Cauchy { .. } => "dispersive glass (Abbe number)".into(),
            Dispersion::Sellmeier { .. } => "named dispersive glass".into(),
        },
    }
}

/// The sliders for `kind`'s numbers, changing it in place; their responses.
fn controls(ui: &mut egui::Ui, kind: &mut MaterialKind) -> Vec<egui::Response> {
    let mut responses = Vec::new();
    let roughness_tip = "GGX roughness α: 0 polished, 0.1 brushed, 0.5 matte";
    match kind {
        MaterialKind::Diffuse { specular, shininess } if *specular > 0.0 => {
            responses.push(
                ui.add(egui::Slider::new(specular, 0.001..=1.0).text("specular"))
                    .on_hover_text("The Phong lobe's reflectance"),
            );
            responses.push(
                ui.add(
                    egui::Slider::new(shininess, 1.0..=10_000.0)
                        .logarithmic(true)
                        .text("shininess"),
                )
                .on_hover_text("The Phong exponent: higher is a tighter highlight"),
            );
        }
        MaterialKind::Diffuse { .. } => {}
        MaterialKind::Mirror { roughness } | MaterialKind::Metal { roughness, .. } => {
            responses.push(roughness_slider(ui, roughness).on_hover_text(roughness_tip));
        }
        MaterialKind::Glass {
            ior,
            roughness,
            dispersion,
        } => {
            responses.push(roughness_slider(ui, roughness).on_hover_text(roughness_tip));
            if !matches!(dispersion, Dispersion::Sellmeier { .. }) {
                let abbe = dispersion.abbe_number(*ior);
                let r = ui
                    .add(egui::Slider::new(ior, 1.0..=3.0).text("index of refraction"))
                    .on_hover_text("At 587.56 nm where it varies (the Abbe number is kept)");
                if r.changed() && dispersion.is_dispersive() {
                    *dispersion = Dispersion::abbe(*ior, abbe);
                }
                responses.push(r);
            }
        }
    }
    responses
}

/// A roughness slider, logarithmic so that the narrow lobes that matter for caustics get room.
fn roughness_slider(ui: &mut egui::Ui, roughness: &mut f64) -> egui::Response {
    ui.add(
        egui::Slider::new(roughness, 0.0..=1.0)
            .logarithmic(true)
            .smallest_positive(0.001)
            .text("roughness"),
    )
}
