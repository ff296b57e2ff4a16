//! The menu bar, side panel, status bar and dialog windows. Every control edits a copy of the
//! parameters; [`Viewer::set_params`] turns the differences into session commands.

use egui::{Color32, RichText};
use egui_plot::{Line, Plot, PlotPoints};

use super::keys::HELP;
use super::params::{ALPHA_RANGE, DEPTH_RANGE, PHOTONS_RANGE};
use super::settings::{DisplayMode, IndexChoice, Zoom};
use super::viewer::{Status, Viewer};
use crate::render::session::Command;
use crate::scene::RendererKind;

/// Seconds as `1.23 s` or `4 min 05 s`.
fn duration(secs: f64) -> String {
    if secs < 60.0 {
        format!("{secs:.2} s")
    } else {
        format!("{} min {:02} s", (secs / 60.0) as u64, (secs % 60.0) as u64)
    }
}

/// A fraction as a percentage with about two significant digits (`32 %`, `4.1 %`, `0.52 %`).
fn percent(fraction: f64) -> String {
    let p = fraction * 100.0;
    let decimals = if p >= 10.0 {
        0
    } else if p >= 1.0 {
        1
    } else {
        2
    };
    format!("{p:.decimals$} %")
}

/// A count with thousands separators.
fn count(n: u64) -> String {
    let s = n.to_string();
    let mut out = String::new();
    for (i, c) in s.chars().enumerate() {
        if i > 0 && (s.len() - i).is_multiple_of(3) {
            out.push(',');
        }
        out.push(c);
    }
    out
}

/// File, View and Help menus.
pub fn menu_ui(viewer: &mut Viewer, ui: &mut egui::Ui) {
    egui::MenuBar::new().ui(ui, |ui| {
        ui.menu_button("File", |ui| {
            if ui
                .button("Open scene...  (Ctrl+O)")
                .on_hover_text("Open a scene file (.toml); you can also drop one on the window")
                .clicked()
            {
                viewer.pick_scene();
            }
            if ui
                .button("Save frame...  (Ctrl+S)")
                .on_hover_text("Save the current frame: PNG as displayed, or EXR with linear radiance")
                .clicked()
            {
                viewer.save_with_dialog();
            }
            ui.separator();
            if ui
                .button("Quit")
                .on_hover_text("Close the viewer (settings are kept)")
                .clicked()
            {
                ui.ctx().send_viewport_cmd(egui::ViewportCommand::Close);
            }
        });
        ui.menu_button("View", |ui| {
            if ui
                .button("Fit  (F)")
                .on_hover_text("Scale the image to fit the view")
                .clicked()
            {
                viewer.settings.zoom = Zoom::Fit;
                viewer.image_view.recentre();
            }
            if ui
                .button("1:1  (1)")
                .on_hover_text("One image pixel per screen pixel")
                .clicked()
            {
                viewer.settings.zoom = Zoom::Scale(1.0);
                viewer.image_view.recentre();
            }
            ui.separator();
            for mode in DisplayMode::ALL {
                if ui
                    .radio_value(&mut viewer.settings.display, mode, mode.label())
                    .on_hover_text("What the image shows; the probe always reports all three (D cycles)")
                    .changed()
                {
                    viewer.image_view.invalidate();
                }
            }
            ui.separator();
            ui.checkbox(&mut viewer.settings.show_side_panel, "Side panel  (P)")
                .on_hover_text("Show or hide the parameters and statistics");
        });
        ui.menu_button("Help", |ui| {
            if ui
                .button("Keys and mouse  (F1)")
                .on_hover_text("List the shortcuts")
                .clicked()
            {
                viewer.show_help = true;
            }
        });
        ui.separator();
        ui.label(RichText::new(viewer.scene.source.display().to_string()).weak())
            .on_hover_text("The scene file being rendered");
    });
}

/// Pixel probe and the last message.
pub fn status_ui(viewer: &mut Viewer, ui: &mut egui::Ui) {
    ui.horizontal(|ui| {
        match (&viewer.probe, &viewer.frame) {
            (Some(p), Some(f)) => {
                let i = (p.y * f.width + p.x) as usize;
                let [r, g, b] = f.radiance[i];
                ui.monospace(format!(
                    "({:4}, {:4})  RGB {:.4} {:.4} {:.4}  radius {:.4}  photons {:.0}",
                    p.x, p.y, r, g, b, f.radius[i], f.gathered[i]
                ))
                .on_hover_text(
                    "Linear radiance, PPM search radius and accumulated photon count under the cursor",
                );
            }
            _ => {
                ui.monospace("Hover over the image to probe a pixel");
            }
        }
        ui.separator();
        match &viewer.status {
            Some(Status::Info(s)) => {
                ui.label(s);
            }
            Some(Status::Error(s)) => {
                ui.colored_label(Color32::from_rgb(255, 110, 90), s);
            }
            None => {}
        }
    });
}

/// Parameters, actions, statistics and the convergence plot.
pub fn side_panel_ui(viewer: &mut Viewer, ui: &mut egui::Ui) {
    let mut p = viewer.params.clone();
    let ranges = viewer.ranges;
    let photon_mapping = p.renderer == RendererKind::Ppm;

    ui.heading("Render");
    ui.horizontal(|ui| {
        ui.label("Renderer");
        ui.selectable_value(&mut p.renderer, RendererKind::Ppm, "Photon mapping")
            .on_hover_text("Progressive photon mapping: converges to caustics and indirect light");
        ui.selectable_value(&mut p.renderer, RendererKind::Whitted, "Ray tracer")
            .on_hover_text("Whitted ray tracer: one fast frame, direct light, mirrors and glass only");
    });
    ui.horizontal(|ui| {
        let label = if p.paused { "Resume" } else { "Pause" };
        if ui
            .button(label)
            .on_hover_text("Pause or resume rendering; nothing is lost (Space)")
            .clicked()
        {
            p.paused = !p.paused;
        }
        if ui
            .button("Restart")
            .on_hover_text("Discard the accumulated image and start again (R)")
            .clicked()
        {
            viewer.send(Command::Restart);
        }
        if ui
            .button("Save frame...")
            .on_hover_text("Save the current frame: PNG as displayed, or EXR with linear radiance (Ctrl+S)")
            .clicked()
        {
            viewer.save_with_dialog();
        }
    });

    let exposure = ui
        .add(
            egui::Slider::new(&mut viewer.settings.exposure_stops, -10.0..=10.0)
                .step_by(0.1)
                .text("Exposure"),
        )
        .on_hover_text("Display brightness in stops: radiance × 2^stops, then sRGB ([ and ])");
    if exposure.changed() {
        viewer.image_view.invalidate();
    }

    ui.separator();
    ui.heading("Photon mapping");
    ui.add_enabled_ui(photon_mapping, |ui| {
        ui.add(egui::Slider::new(&mut p.alpha, ALPHA_RANGE.0..=ALPHA_RANGE.1).text("Alpha"))
            .on_hover_text("Fraction of new photons kept per pass (Hachisuka 2008); radius shrinks faster when smaller. 0.7 is the paper's choice. Applies from the next pass, without restarting.");
        ui.add(
            egui::Slider::new(&mut p.photons_per_pass, PHOTONS_RANGE.0..=PHOTONS_RANGE.1)
                .logarithmic(true)
                .text("Photons per pass"),
        )
        .on_hover_text("Photons traced per pass. Applies from the next pass, without restarting.");
        ui.checkbox(&mut p.auto_radius, "Automatic initial radius")
            .on_hover_text("Start from twice a pixel's footprint at the median visible distance. Changing it restarts.");
        ui.add_enabled(
            !p.auto_radius,
            egui::Slider::new(&mut p.initial_radius, ranges.radius.0..=ranges.radius.1)
                .logarithmic(true)
                .text("Initial radius"),
        )
        .on_hover_text("Starting search radius in scene units. Changing it restarts.");
        let mut direct = viewer.settings.direct_light;
        if ui
            .checkbox(&mut direct, "Direct light by shadow rays")
            .on_hover_text("Point and spot lights lit exactly with shadow rays; their photons count only after the first bounce (caustics kept). Restarts.")
            .changed()
        {
            viewer.settings.direct_light = direct;
            viewer.restart_renderer();
        }
        let mut index = viewer.settings.index;
        ui.horizontal(|ui| {
            ui.label("Index").on_hover_text("Spatial index over visible points; the image is the same, the speed differs");
            ui.selectable_value(&mut index, IndexChoice::HashGrid, "Hash grid")
                .on_hover_text("Hashed uniform grid (fastest here)");
            ui.selectable_value(&mut index, IndexChoice::KdTree, "kd-tree")
                .on_hover_text("The seed report's kd-tree");
        });
        if index != viewer.settings.index {
            viewer.settings.index = index;
            viewer.restart_renderer();
        }
    });

    ui.separator();
    ui.heading("Camera");
    ui.add(
        egui::Slider::new(&mut p.aperture, 0.0..=ranges.aperture_max)
            .text("Aperture")
            .max_decimals(4),
    )
    .on_hover_text(
        "Lens radius in scene units; 0 is a pinhole. Open apertures use stochastic PPM. Restarts.",
    );
    ui.add(
        egui::Slider::new(&mut p.focal_distance, ranges.focal.0..=ranges.focal.1)
            .logarithmic(true)
            .text("Focal distance"),
    )
    .on_hover_text("Distance from the lens to the plane in focus. Restarts.");
    ui.add(egui::Slider::new(&mut p.max_depth, DEPTH_RANGE.0..=DEPTH_RANGE.1).text("Max depth"))
        .on_hover_text("Most mirror/glass bounces followed by eye rays and photons. Restarts.");

    if p != viewer.params {
        viewer.set_params(p);
    }

    ui.separator();
    statistics_ui(viewer, ui);
}

fn statistics_ui(viewer: &mut Viewer, ui: &mut egui::Ui) {
    ui.heading("Statistics");
    if viewer.restart_pending() {
        let what = match viewer.params.renderer {
            RendererKind::Ppm => "Restarting: first pass of the new settings...",
            RendererKind::Whitted => "Ray tracing the frame...",
        };
        ui.label(RichText::new(what).italics());
    }
    let Some(frame) = &viewer.frame else {
        ui.label("Waiting for the first pass...");
        return;
    };
    egui::Grid::new("caustic-stats")
        .num_columns(2)
        .striped(true)
        .show(ui, |ui| {
            let mut row = |name: &str, value: String, tip: &str| {
                ui.label(name).on_hover_text(tip);
                ui.monospace(value).on_hover_text(tip);
                ui.end_row();
            };
            row(
                "Epoch",
                frame.epoch.to_string(),
                "Restarts so far: each change that discards the accumulation starts a new epoch",
            );
            let pass = if frame.preview {
                "preview (1/4 resolution)".to_owned()
            } else {
                frame.pass.to_string()
            };
            row(
                "Pass",
                pass,
                "Completed passes in this epoch; a new epoch first shows a quick low-resolution preview",
            );
            if frame.renderer == RendererKind::Ppm {
                row("Photons", count(frame.photons), "Photons emitted in this epoch");
                let rate = frame.photons as f64 / frame.stats.elapsed_secs.max(1e-9);
                row(
                    "Photons/s",
                    count(rate as u64),
                    "Photons per second of render time in this epoch",
                );
                row(
                    "Mean radius",
                    format!("{:.4e}", frame.stats.mean_radius),
                    "Mean search radius of points that have gathered photons (scene units)",
                );
                row(
                    "Visible points",
                    count(frame.stats.visible_points as u64),
                    "Gathering points of the last eye pass",
                );
            }
            row(
                "Elapsed",
                duration(frame.elapsed_secs),
                "Wall-clock time since this epoch started",
            );
            if let Some(l) = viewer.restart_latency_secs {
                row(
                    "Last restart",
                    format!("{:.0} ms", l * 1e3),
                    "From the last restarting change to its first image",
                );
            }
        });
    if !frame.stats.skipped.is_empty() {
        ui.label("Skipped work:")
            .on_hover_text("Work this scene does not need, left out");
        for s in &frame.stats.skipped {
            ui.label(RichText::new(format!("- {s}")).small());
        }
    }
    if frame.renderer == RendererKind::Ppm {
        ui.label("Estimated error")
            .on_hover_text("Relative RMS noise estimated from successive frames (log scale) against seconds; falls as the image converges");
        let points: Vec<[f64; 2]> = viewer
            .convergence
            .points
            .iter()
            .map(|[t, e]| [*t, e.max(1e-12).log10()])
            .collect();
        Plot::new("caustic-convergence")
            .height(120.0)
            .allow_zoom(false)
            .allow_drag(false)
            .allow_scroll(false)
            .y_axis_formatter(|mark, _| percent(10f64.powf(mark.value)))
            .show(ui, |plot| plot.line(Line::new("error", PlotPoints::from(points))));
        if let Some(e) = viewer.convergence.latest() {
            ui.label(format!("now {}", percent(e)));
        }
    }
}

/// Help, scene error, renderer failure and overwrite windows.
pub fn dialogs_ui(viewer: &mut Viewer, ctx: &egui::Context) {
    if viewer.show_help {
        let mut open = true;
        egui::Window::new("Keys and mouse")
            .open(&mut open)
            .resizable(false)
            .show(ctx, |ui| {
                egui::Grid::new("caustic-help").num_columns(2).show(ui, |ui| {
                    for (keys, what) in HELP {
                        ui.monospace(*keys);
                        ui.label(*what);
                        ui.end_row();
                    }
                });
                ui.separator();
                ui.label("Hover over any control for what it does.");
            });
        viewer.show_help = open;
    }
    if let Some(error) = viewer.scene_error.clone() {
        let mut open = true;
        egui::Window::new("Could not open scene")
            .open(&mut open)
            .show(ctx, |ui| {
                ui.colored_label(Color32::from_rgb(255, 110, 90), error);
                ui.label("The previous scene is still rendering.");
                if ui.button("OK").clicked() {
                    viewer.scene_error = None;
                }
            });
        if !open {
            viewer.scene_error = None;
        }
    }
    if let Some(failure) = viewer.render_failure.clone() {
        egui::Window::new("The renderer stopped").show(ctx, |ui| {
            ui.colored_label(
                Color32::from_rgb(255, 110, 90),
                format!("The render thread failed: {failure}"),
            );
            ui.label("The last image is kept; you can save it or start the renderer again.");
            if ui.button("Restart renderer").clicked() {
                viewer.restart_renderer();
            }
        });
    }
    if let Some(path) = viewer.confirming_overwrite().map(|p| p.display().to_string()) {
        let modal = egui::Modal::new(egui::Id::unique("caustic-overwrite")).show(ctx, |ui| {
            ui.heading("Replace file?");
            ui.label(format!(
                "{path} already exists. Replace it with the current frame?"
            ));
            ui.horizontal(|ui| {
                if ui.button("Replace").clicked() {
                    Some(true)
                } else if ui.button("Cancel").clicked() {
                    Some(false)
                } else {
                    None
                }
            })
            .inner
        });
        if let Some(answer) = modal.inner.or(modal.should_close().then_some(false)) {
            viewer.confirm_overwrite(answer);
        }
    }
}
