//! The menu bar, side panel, status bar and dialog windows. They read the viewer and emit
//! [`Action`]s; a control edits a copy of a value and asks for the new one.

use egui::{Color32, RichText};
use egui_plot::{Line, Plot, PlotPoints, Points};

use super::action::Action;
use super::commands::{self, Menu};
use super::params::{PanelParams, Ranges};
use super::setting_ui;
use super::settings::DisplayMode;
use super::state::{Status, ViewerState};
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

/// The File, Edit, View and Help menus, drawn from the table of commands
/// ([`super::commands`]); View adds the display modes, which follow the frame's layers.
pub fn menu_ui(viewer: &ViewerState, ui: &mut egui::Ui, out: &mut Vec<Action>) {
    egui::MenuBar::new().ui(ui, |ui| {
        ui.menu_button("File", |ui| commands::menu_ui(viewer, Menu::File, ui, out));
        ui.menu_button("Edit", |ui| commands::menu_ui(viewer, Menu::Edit, ui, out));
        ui.menu_button("View", |ui| {
            commands::menu_ui(viewer, Menu::View, ui, out);
            ui.separator();
            display_modes_ui(viewer, ui, out);
        });
        ui.menu_button("Help", |ui| commands::menu_ui(viewer, Menu::Help, ui, out));
        ui.separator();
        ui.label(RichText::new(viewer.scene().source.display().to_string()).weak())
            .on_hover_text("The scene file being rendered");
    });
}

/// What the image shows: radiance, each of the frame's layers, the differences to a reference.
fn display_modes_ui(viewer: &ViewerState, ui: &mut egui::Ui, out: &mut Vec<Action>) {
    let mut display = viewer.settings.display;
    let layers = viewer.layer_labels();
    for mode in DisplayMode::all(&layers) {
        let enabled = viewer.reference().is_some() || !mode.needs_reference();
        let hover = if enabled {
            "What the image shows; the probe always reports radiance and every layer (D cycles)"
        } else {
            "Open a reference image first (File > Open reference...)"
        };
        ui.add_enabled_ui(enabled, |ui| {
            ui.radio_value(&mut display, mode, mode.label(&layers))
                .on_hover_text(hover)
                .on_disabled_hover_text(hover);
        });
    }
    if display != viewer.settings.display {
        out.push(Action::SetDisplay(display));
    }
}

/// Pixel probe and the last message.
pub fn status_ui(viewer: &ViewerState, ui: &mut egui::Ui) {
    ui.horizontal(|ui| {
        // The probe was taken on the frame shown last; the frame may since have changed size.
        let probed = viewer
            .probe
            .as_ref()
            .and_then(|p| Some((p, viewer.frame.as_ref()?.pixel(p.x, p.y)?)));
        match probed {
            Some((p, ([r, g, b], layers))) => {
                let layers: String = layers
                    .iter()
                    .map(|(layer, v)| format!("  {} {v:.*}", layer.label, layer.decimals))
                    .collect();
                ui.monospace(format!(
                    "({:4}, {:4})  RGB {:.4} {:.4} {:.4}{layers}",
                    p.x, p.y, r, g, b
                ))
                .on_hover_text(
                    "Linear radiance and the renderer's per-pixel layers (photon mapping: search radius, photons) under the cursor",
                );
            }
            None => {
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
pub fn side_panel_ui(viewer: &ViewerState, ui: &mut egui::Ui, out: &mut Vec<Action>) {
    if let Some(w) = viewer.watching() {
        watching_ui(w, ui, out);
        ui.separator();
    }
    // What a person watches first — the renderer, pause and restart, exposure, the key
    // statistics and the error plot — comes first; the settings follow in sections that fold
    // (egui remembers which are open, with the window's other state).
    let shown = viewer.params();
    let mut p = shown.clone();
    render_section_ui(viewer, &mut p, ui, out);
    ui.separator();
    statistics_ui(viewer, ui);
    // A watched folder's image comes from the farm: the renderer and its settings do
    // nothing there, so they are not shown.
    if viewer.watching().is_none() {
        renderer_section_ui(&mut p, viewer.ranges, ui);
        ui.separator();
        section(ui, "Camera", true, |ui| {
            camera_section_ui(&mut p, viewer.ranges, ui)
        });
    }
    if p != shown {
        out.push(Action::SetParams(p));
    }
    if !(viewer.patches().len() == 0 && viewer.lights().is_empty()) {
        ui.separator();
        section(ui, "Edit", true, |ui| {
            super::edit_panel::edit_panel_ui(viewer, ui, out)
        });
    }
    // Designing needs a surface to shape: a scene without patches has no Design section.
    if viewer.watching().is_none() && viewer.patches().len() > 0 {
        ui.separator();
        section(ui, "Design", false, |ui| {
            super::design_panel::design_panel_ui(viewer, ui, out)
        });
    }
}

/// A section of the side panel under a heading that folds it (open at first if `open`).
fn section(ui: &mut egui::Ui, title: &str, open: bool, body: impl FnOnce(&mut egui::Ui)) {
    egui::CollapsingHeader::new(RichText::new(title).heading())
        .id_salt(("caustic-section", title))
        .default_open(open)
        .show(ui, body);
}

/// The renderer, pause, restart, save and exposure.
fn render_section_ui(viewer: &ViewerState, p: &mut PanelParams, ui: &mut egui::Ui, out: &mut Vec<Action>) {
    let watching = viewer.watching().is_some();
    ui.heading("Render");
    if !watching {
        renderer_choice_ui(p, ui, out);
    } else {
        if ui
            .button("Save frame...")
            .on_hover_text("Save the merged image: PNG as displayed, or EXR with linear radiance (Ctrl+S)")
            .clicked()
        {
            out.push(Action::SaveFrame);
        }
    }
    exposure_ui(viewer, ui, out);
}

/// The renderer, pause, restart and save.
fn renderer_choice_ui(p: &mut PanelParams, ui: &mut egui::Ui, out: &mut Vec<Action>) {
    ui.horizontal(|ui| {
        ui.label("Renderer");
        // Progressive renderers first (the viewer's own), then single-frame ones.
        let mut kinds = RendererKind::ALL.to_vec();
        kinds.sort_by_key(|k| !k.progressive());
        for kind in kinds {
            ui.selectable_value(&mut p.render.renderer, kind, kind.label())
                .on_hover_text(kind.description());
        }
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
            out.push(Action::Restart);
        }
        if ui
            .button("Save frame...")
            .on_hover_text("Save the current frame: PNG as displayed, or EXR with linear radiance (Ctrl+S)")
            .clicked()
        {
            out.push(Action::SaveFrame);
        }
    });
}

/// The display's exposure.
fn exposure_ui(viewer: &ViewerState, ui: &mut egui::Ui, out: &mut Vec<Action>) {
    let mut exposure = viewer.settings.exposure_stops;
    if ui
        .add(
            egui::Slider::new(&mut exposure, -10.0..=10.0)
                .step_by(0.1)
                .text("Exposure"),
        )
        .on_hover_text("Display brightness in stops: radiance × 2^stops, then sRGB ([ and ])")
        .changed()
    {
        out.push(Action::SetExposure(exposure));
    }
}

/// The settings the current renderer reads, but not every renderer, under its heading (none
/// for the path tracer).
fn renderer_section_ui(p: &mut PanelParams, ranges: Ranges, ui: &mut egui::Ui) {
    let kind = p.render.renderer;
    let heading = match kind {
        RendererKind::Ppm => "Photon mapping",
        RendererKind::Whitted => "Ray tracing",
        RendererKind::Vcm => "Vertex connection and merging",
        RendererKind::Path => return,
    };
    ui.separator();
    section(ui, heading, true, |ui| {
        setting_ui::settings_ui(p, ranges, ui, setting_ui::read_by(kind));
    });
}

/// The lens and the depth of paths.
fn camera_section_ui(p: &mut PanelParams, ranges: Ranges, ui: &mut egui::Ui) {
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
    setting_ui::settings_ui(p, ranges, ui, setting_ui::every_renderer);
}

fn statistics_ui(viewer: &ViewerState, ui: &mut egui::Ui) {
    ui.heading("Statistics");
    if viewer.restart_pending() {
        let what = if viewer.scene().params.renderer.progressive() {
            "Restarting: first pass of the new settings..."
        } else {
            "Rendering the frame..."
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
            // A watched folder's frame is its parts' merge: its own rows say how far it is,
            // and it has no epochs, restarts or render time of its own.
            let rendering = viewer.watching.is_none();
            if rendering {
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
            }
            for r in &frame.stats.rows {
                row(&r.label, r.value.clone(), &r.tip);
            }
            if !rendering {
                return;
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
    let skipped = &frame.stats.skipped;
    if !skipped.is_empty() {
        egui::CollapsingHeader::new(format!("Skipped work ({})", skipped.len()))
            .id_salt("caustic-skipped-work")
            .default_open(false)
            .show(ui, |ui| {
                for s in skipped {
                    ui.label(RichText::new(format!("- {s}")).small());
                }
            })
            .header_response
            .on_hover_text("Work this scene does not need, left out");
    }
    if frame.stats.renderer().progressive() {
        convergence_plot_ui(viewer, ui);
    }
}

/// The colour of an uncertain estimate on the plot and its note (amber).
const UNCERTAIN: Color32 = Color32::from_rgb(235, 170, 60);

/// The error against time (log scale): the estimate from the render's own frames
/// ([`crate::render::error_tracker`]) and, with a reference open, the true RMSE and relative
/// MSE against it.
fn convergence_plot_ui(viewer: &ViewerState, ui: &mut egui::Ui) {
    let with_reference = viewer.reference().is_some();
    let title = if with_reference {
        "Error against time"
    } else {
        "Estimated error"
    };
    ui.label(title).on_hover_text(
        "Log scale against seconds. Estimate: the relative RMS error from this render's own frames: the noise (the frame against its frame at half the photons) and photon mapping's blur (how the frames at a quarter, half and all the photons drift apart as the radii shrink). With a reference: its RMSE and pbrt's relative MSE",
    );
    let log = |v: f64| v.max(1e-12).log10();
    let series = |k: usize| -> Vec<[f64; 2]> {
        let points = &viewer.convergence.reference_points;
        points.iter().map(|p| [p[0], log(p[k])]).collect()
    };
    let logged =
        |points: &[[f64; 2]]| -> Vec<[f64; 2]> { points.iter().map(|[t, e]| [*t, log(*e)]).collect() };
    let estimate = logged(&viewer.convergence.points);
    let mut plot = Plot::new("caustic-convergence")
        .height(if with_reference { 150.0 } else { 120.0 })
        .allow_zoom(false)
        .allow_drag(false)
        .allow_scroll(false);
    plot = if with_reference {
        plot.legend(egui_plot::Legend::default().position(egui_plot::Corner::LeftBottom))
            .y_axis_formatter(|mark, _| format!("{:.0e}", 10f64.powf(mark.value)))
    } else {
        plot.y_axis_formatter(|mark, _| percent(10f64.powf(mark.value)))
    };
    let uncertain = logged(&viewer.convergence.uncertain_points);
    plot.show(ui, |plot| {
        plot.line(Line::new(
            "estimated error (relative)",
            PlotPoints::from(estimate),
        ));
        if !uncertain.is_empty() {
            plot.points(
                Points::new(
                    "uncertain: a few pixels, or settling",
                    PlotPoints::from(uncertain),
                )
                .color(UNCERTAIN)
                .radius(2.0),
            );
        }
        if with_reference {
            plot.line(Line::new("RMSE", PlotPoints::from(series(1))));
            plot.line(Line::new("relative MSE", PlotPoints::from(series(2))));
        }
    });
    latest_estimate_ui(viewer, ui);
    if let Some(e) = viewer.reference_errors() {
        ui.label(format!(
            "against the reference: RMSE {:.3e}, relative MSE {:.3e}",
            e.rmse, e.rel_mse
        ));
    } else if let Some(r) = viewer.reference() {
        ui.label(
            RichText::new(format!(
                "reference {} (no frame to compare yet)",
                r.path.display()
            ))
            .small(),
        );
    }
}

/// The newest estimate in words: its noise and blur, and a note where it is uncertain.
fn latest_estimate_ui(viewer: &ViewerState, ui: &mut egui::Ui) {
    let Some(e) = viewer.convergence.latest() else {
        if viewer.watching.is_some() {
            ui.label(RichText::new("no estimate yet: it needs two passes").small())
                .on_hover_text("A watched render's estimate comes from the spread of its independent passes");
        } else {
            ui.label(RichText::new("no estimate yet: it compares two frames").small())
                .on_hover_text("The first estimate comes once a frame holds about twice the photons of an earlier one of the same render; with photon mapping, of one made after its estimates restarted with the adaptive radius (after the first pass)");
        }
        return;
    };
    let now = percent(e.total());
    ui.horizontal_wrapped(|ui| {
        ui.label(match e.blur {
            Some(blur) => format!("now {now} (noise {}, blur {})", percent(e.noise), percent(blur)),
            None => format!("now {now} (noise)"),
        });
        if let Some(why) = e.why_uncertain() {
            let help = if e.settling {
                "Some pixels started their estimates anew a few passes ago (a lamp's outline that now takes extra rays, the adaptive radius after the first pass), so the frames compared differ there by both frames' noise: those pixels are left out, and the estimate cannot see their error (it may be low) until they have a few passes of their own"
            } else {
                "The error is in a few pixels (bright specks that come and go: a light seen in a pixel's corner, rare caustic paths, a focus a few pixels wide), so this frame's true error may be far from the estimate either way"
            };
            ui.colored_label(UNCERTAIN, format!("uncertain: {why}"))
                .on_hover_text(help);
        }
    });
}

/// Help, scene error, renderer failure, overwrite and unsaved-edits windows.
pub fn dialogs_ui(viewer: &ViewerState, ctx: &egui::Context, out: &mut Vec<Action>) {
    if viewer.show_help {
        help_window_ui(ctx, out);
    }
    if let Some(error) = &viewer.scene_error {
        let mut open = true;
        let mut ok = false;
        egui::Window::new("Could not open scene")
            .open(&mut open)
            .show(ctx, |ui| {
                ui.colored_label(Color32::from_rgb(255, 110, 90), &error.message);
                ui.label(&error.instead);
                ok = ui.button("OK").clicked();
            });
        if !open || ok {
            out.push(Action::DismissSceneError);
        }
    }
    if let Some(failure) = &viewer.render_failure {
        egui::Window::new("The renderer stopped").show(ctx, |ui| {
            ui.colored_label(
                Color32::from_rgb(255, 110, 90),
                format!("The render thread failed: {failure}"),
            );
            ui.label("The last image is kept; you can save it or start the renderer again.");
            if ui.button("Restart renderer").clicked() {
                out.push(Action::RestartRenderer);
            }
        });
    }
    if let Some(path) = viewer.confirming_overwrite() {
        let text = format!(
            "{} already exists. Replace it with the current frame?",
            path.display()
        );
        if let Some(replace) = replace_question(ctx, "caustic-overwrite", &text) {
            out.push(Action::ConfirmFrameOverwrite(replace));
        }
    }
    if let Some(path) = &viewer.confirm_scene_overwrite {
        let text = format!("Replace {} with the scene as edited?", path.display());
        if let Some(replace) = replace_question(ctx, "caustic-scene-overwrite", &text) {
            out.push(Action::ConfirmSceneOverwrite(replace));
        }
    }
    if viewer.confirm_restart {
        let passes = viewer.frame.as_ref().map_or(0, |f| f.pass);
        let question = Question {
            id: "caustic-restart",
            heading: "Restart the render?",
            text: &format!("The {passes} passes rendered so far would be discarded."),
            yes: "Discard and restart",
            no: "Keep rendering",
        };
        if let Some(restart) = question.ask(ctx) {
            out.push(Action::ConfirmRestart(restart));
        }
    }
    if viewer.unsaved_question.is_some() {
        unsaved_question_ui(ctx, out);
    }
}

/// The list of keys and mouse gestures (F1).
fn help_window_ui(ctx: &egui::Context, out: &mut Vec<Action>) {
    let mut open = true;
    egui::Window::new("Keys and mouse")
        .open(&mut open)
        .resizable(false)
        .show(ctx, |ui| {
            egui::Grid::new("caustic-help").num_columns(2).show(ui, |ui| {
                for (keys, what) in commands::help_rows() {
                    ui.monospace(keys);
                    ui.label(what);
                    ui.end_row();
                }
            });
            ui.separator();
            ui.label("Hover over any control for what it does.");
        });
    if !open {
        out.push(Action::ShowHelp(false));
    }
}

/// Save, discard or cancel, before edits would be lost.
fn unsaved_question_ui(ctx: &egui::Context, out: &mut Vec<Action>) {
    // Enter saves (the first button), Escape cancels.
    let keys = answer_keys(ctx).map(|k| match k {
        AnswerKey::Enter => Some(false),
        AnswerKey::Escape => None,
    });
    let modal = egui::Modal::new(egui::Id::unique("caustic-unsaved")).show(ctx, |ui| {
        ui.heading("Unsaved edits");
        ui.label("The scene has edits that are not saved. Save them first?");
        ui.horizontal(|ui| {
            if ui
                .button("Save")
                .on_hover_text("Save the scene, then go on")
                .clicked()
            {
                Some(Some(false))
            } else if ui
                .button("Discard")
                .on_hover_text("Go on without saving")
                .clicked()
            {
                Some(Some(true))
            } else if ui.button("Cancel").clicked() {
                Some(None)
            } else {
                None
            }
        })
        .inner
    });
    if let Some(choice) = modal.inner.or(keys).or(modal.should_close().then_some(None)) {
        out.push(Action::ResolveUnsaved(choice));
    }
}

/// A modal yes/no question.
struct Question<'a> {
    id: &'static str,
    heading: &'a str,
    text: &'a str,
    yes: &'a str,
    no: &'a str,
}

impl Question<'_> {
    /// Shows it: `Some(true)` yes (its button, or Enter), `Some(false)` no (its button,
    /// Escape, or a click outside), `None` not answered yet.
    fn ask(&self, ctx: &egui::Context) -> Option<bool> {
        let keys = answer_keys(ctx);
        let modal = egui::Modal::new(egui::Id::unique(self.id)).show(ctx, |ui| {
            ui.heading(self.heading);
            ui.label(self.text);
            ui.horizontal(|ui| {
                if ui.button(self.yes).on_hover_text("Enter").clicked() {
                    Some(true)
                } else if ui.button(self.no).on_hover_text("Escape").clicked() {
                    Some(false)
                } else {
                    None
                }
            })
            .inner
        });
        let answer = keys.map(|k| k == AnswerKey::Enter);
        modal.inner.or(answer).or(modal.should_close().then_some(false))
    }
}

/// A key that answers an open question.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum AnswerKey {
    /// Take the default action (the first button).
    Enter,
    /// Cancel.
    Escape,
}

/// Enter or Escape pressed this frame (taken, so nothing else acts on it).
fn answer_keys(ctx: &egui::Context) -> Option<AnswerKey> {
    ctx.input_mut(|i| {
        if i.consume_key(egui::Modifiers::NONE, egui::Key::Enter) {
            Some(AnswerKey::Enter)
        } else if i.consume_key(egui::Modifiers::NONE, egui::Key::Escape) {
            Some(AnswerKey::Escape)
        } else {
            None
        }
    })
}

/// A "Replace file?" modal: `Some(true)` replace, `Some(false)` cancel, `None` not answered.
fn replace_question(ctx: &egui::Context, id: &'static str, text: &str) -> Option<bool> {
    Question {
        id,
        heading: "Replace file?",
        text,
        yes: "Replace",
        no: "Cancel",
    }
    .ask(ctx)
}

/// The watched render folder: passes done out of the total, parts, error estimate.
/// Which of the folder's renders to show, when it holds parts of more than one.
fn render_choice_ui(w: &super::watch::WatchSummary, ui: &mut egui::Ui, out: &mut Vec<Action>) {
    let shown = w.shown.as_ref();
    let label = |r: &crate::render::shard::RenderInFolder| format!("{} — {} parts", r.label, r.parts);
    let current = shown
        .and_then(|(k, _)| w.renders.iter().find(|r| &r.key == k))
        .map_or("(none yet)".to_owned(), label);
    // The label above and the choice truncated to the panel: a render's description is
    // longer than the panel is wide.
    let name = ui.label("Render shown");
    egui::ComboBox::from_id_salt("caustic-render-shown")
        .selected_text(current)
        .width(ui.available_width())
        .truncate()
        .show_ui(ui, |ui| {
            if ui
                .selectable_label(shown.is_some_and(|(_, chosen)| !chosen), "The render most parts belong to")
                .clicked()
            {
                out.push(Action::WatchRender(None));
            }
            for r in &w.renders {
                let selected = shown.is_some_and(|(k, chosen)| *chosen && k == &r.key);
                if ui.selectable_label(selected, label(r)).clicked() {
                    out.push(Action::WatchRender(Some(r.key.clone())));
                }
            }
        })
        .response
        .labelled_by(name.id)
        .on_hover_text("The folder holds parts of more than one render: the one most parts belong to is shown unless you choose another");
}

fn watching_ui(w: &super::watch::WatchSummary, ui: &mut egui::Ui, out: &mut Vec<Action>) {
    ui.heading("Render folder");
    ui.label(RichText::new(w.dir.display().to_string()).weak())
        .on_hover_text("The folder whose parts are merged as they land");
    if w.renders.len() > 1 {
        render_choice_ui(w, ui, out);
    }
    if w.total == 0 {
        ui.label("Waiting for the first part...");
    } else {
        let done = w.passes as f32 / w.total as f32;
        ui.add(egui::ProgressBar::new(done).text(format!("{} of {} passes", w.passes, w.total)))
            .on_hover_text("Passes merged out of the render's total");
        ui.label(format!(
            "{} parts, {} {}",
            w.parts,
            w.photons,
            w.renderer.emitted()
        ));
        let error = w
            .relative_error
            .map_or("error estimate after two passes".to_owned(), |e| {
                format!("error estimate {:.2} %", 100.0 * e)
            });
        ui.label(error).on_hover_text(
            "Relative RMS error of the image, estimated from the spread of its independent passes",
        );
    }
    if ui.button("Stop watching").clicked() {
        out.push(Action::StopWatching);
    }
}
