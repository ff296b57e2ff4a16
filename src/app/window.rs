//! The viewer's frame: [`Viewer::poll`] takes what arrived (frames, finished dialogs and
//! loads), and [`Viewer::ui`] draws the window — menu, side panel, status bar, the image with
//! its overlay, dialogs — and carries out the actions its widgets answer with. This is the
//! top of the viewer: it calls into the rest (the core in [`super::viewer`], the flows in
//! `scene_file`, `reference_files`, `watch_folder`, and [`Viewer::apply`]), none of which calls
//! back here.

use std::path::PathBuf;

use super::action::Action;
use super::controls;
use super::file_dialog::{self, FileDialog, Finished};
use super::image_view::Comparison;
use super::job::Poll;
use super::keys;
use super::overlay::OverlayProjection;
use super::reference::is_reference_file;
use super::state::Status;
use super::view_input;
use super::viewer::Viewer;

impl Viewer {
    /// Whether the render session has a frame the window has not taken yet.
    pub fn frame_waiting(&self) -> bool {
        !self.session.frames().is_empty()
    }

    /// Takes new frames, failures and finished jobs; call once per UI frame.
    pub fn poll(&mut self) {
        // Newest frame of the newest epoch.
        while let Ok(frame) = self.session.frames().try_recv() {
            self.show_frame(frame);
        }
        if self.render_failure.is_none() {
            self.render_failure = self.session.failure();
        }
        match file_dialog::take_finished(&mut self.picking) {
            Some(Finished::Chosen(path)) => self.open_scene(path),
            Some(Finished::Lost) => self.status = Some(Status::Error("the file dialog failed".into())),
            Some(Finished::Cancelled) | None => {}
        }
        if let Some((job, path)) = &self.loading {
            let path = path.clone();
            let loaded = match job.poll() {
                Poll::Pending => None,
                Poll::Ready(r) => Some(r),
                Poll::Lost => Some(Err(format!("{}: loading failed unexpectedly", path.display()))),
            };
            if let Some(result) = loaded {
                self.loading = None;
                match result {
                    Ok(scene) => {
                        self.remember_folder_of(&path);
                        let mut message = format!("Opened {}", path.display());
                        for warning in &scene.warnings {
                            eprintln!("caustic view: warning: {warning}");
                            message.push_str(&format!(" (warning: {warning})"));
                        }
                        self.replace_scene(scene);
                        self.scene_error = None;
                        self.status = Some(Status::Info(message));
                    }
                    Err(e) => {
                        self.status = Some(Status::Error(format!("Could not open {}", path.display())));
                        self.scene_failed(e);
                    }
                }
            }
        }
        if let Some(event) = self.state.save.poll(&self.ctx) {
            self.on_save_event(event);
        }
        self.poll_scene_dialog();
        self.poll_reference();
        self.poll_design();
        self.poll_watch();
        if let Some(status) = self.tev.poll() {
            self.status = Some(status);
        }
    }

    /// The whole window: menu, side panel, status bar, image with its overlay, dialogs. The
    /// parts emit [`Action`]s, carried out at the end of the frame by [`Viewer::apply`].
    pub fn ui(&mut self, ui: &mut egui::Ui) {
        self.poll();
        let mut actions = Vec::new();
        // An open question or the window's own file dialog takes the keyboard (Enter, Escape).
        if !self.file_dialog_in_window() && !self.question_open() {
            keys::handle(self, ui.ctx(), &mut actions);
        }
        // Files dropped on the window open as scenes (the first one); images (.exr, .pfm)
        // open as the reference.
        let dropped: Option<PathBuf> = ui.input(|i| {
            i.raw
                .dropped_files
                .iter()
                .map(|f| f.path().to_path_buf())
                .find(|p| !p.as_os_str().is_empty())
        });
        actions.extend(dropped.map(|p| match is_reference_file(&p) {
            true => Action::OpenReference(p),
            false => Action::OpenScene(p),
        }));
        // Closing with unsaved edits asks first.
        if ui.input(|i| i.viewport().close_requested()) && !self.allow_close && self.editor.history.unsaved()
        {
            ui.ctx().send_viewport_cmd(egui::ViewportCommand::CancelClose);
            actions.push(Action::Close);
        }
        let state = &self.state;
        if let Some(frame) = &state.frame {
            let comparison = Comparison {
                reference: state.reference.open.as_ref().map(|r| &r.image.pixels[..]),
                show_reference: state.reference.show_reference,
            };
            self.image_view.update_texture(
                ui.ctx(),
                frame,
                state.settings.display,
                state.settings.exposure_stops,
                comparison,
            );
        }

        let frame = self.panel_frame(ui.style());
        egui::Panel::top("caustic-menu")
            .frame(frame)
            .show(ui, |ui| controls::menu_ui(self, ui, &mut actions));
        egui::Panel::bottom("caustic-status")
            .frame(frame)
            .show(ui, |ui| controls::status_ui(self, ui));
        if self.settings.show_side_panel {
            // The panel opens scrolled to its top: egui keeps a scroll position from the last
            // run, which would open the next with "Render" half hidden.
            let first = !std::mem::replace(&mut self.side_panel_shown, true);
            egui::Panel::right("caustic-controls")
                .frame(frame)
                .resizable(true)
                .default_size(290.0)
                .show(ui, |ui| {
                    let mut area = egui::ScrollArea::vertical().id_salt("caustic-side-panel");
                    if first {
                        area = area.vertical_scroll_offset(0.0);
                    }
                    area.show(ui, |ui| controls::side_panel_ui(self, ui, &mut actions));
                });
        }
        egui::CentralPanel::no_frame().show(ui, |ui| self.central_ui(ui, &mut actions));
        controls::dialogs_ui(self, ui.ctx(), &mut actions);
        for dialog in self.file_dialogs() {
            dialog.ui(ui.ctx());
        }
        for action in actions {
            self.apply(action);
        }
    }

    /// The file dialogs under way (at most one of each kind).
    fn file_dialogs(&self) -> impl Iterator<Item = &FileDialog> {
        [
            self.picking.as_ref(),
            self.scene_dialog.as_ref(),
            self.reference.picking.as_ref(),
            self.watch_picking.as_ref(),
            self.design.picking.as_ref(),
            self.save.file_dialog(),
        ]
        .into_iter()
        .flatten()
    }

    /// Whether a file dialog is showing inside the window (no native one could be shown).
    pub fn file_dialog_in_window(&self) -> bool {
        self.file_dialogs().any(FileDialog::in_window)
    }

    /// The frame of the bars and the side panel: egui's, without its fill where the window is
    /// cleared to it ([`Viewer::panels_on_clear_colour`]).
    fn panel_frame(&self, style: &egui::Style) -> egui::Frame {
        let frame = egui::Frame::side_top_panel(style);
        match self.panels_on_clear {
            true => frame.fill(egui::Color32::TRANSPARENT),
            false => frame,
        }
    }

    /// The image, the control-net overlay over it, and the mouse.
    fn central_ui(&mut self, ui: &mut egui::Ui, actions: &mut Vec<Action>) {
        let Some(frame) = &self.frame else {
            self.probe = None;
            let waiting;
            let text = if let Some(w) = &self.watching {
                waiting = format!("Watching {}: waiting for the first part...", w.dir.display());
                waiting.as_str()
            } else if self.panel.paused {
                "Paused before the first pass: press Space or Resume"
            } else {
                "Rendering the first pass..."
            };
            ui.centered_and_justified(|ui| ui.label(text));
            return;
        };
        let size = [frame.width, frame.height];
        // A left drag that starts on a control point moves it; elsewhere it pans the image.
        let press = ui.input(|i| i.pointer.press_origin());
        let box_selecting =
            self.editor.rubber_band.is_some() || (self.editing() && ui.input(|i| i.modifiers.shift));
        let grabbing = box_selecting
            || matches!(self.editor.gesture, Some(super::editor::Gesture::Points { .. }))
            || (self.editing()
                && view_input::grab_at(&self.editor, &self.document, self.projection.as_ref(), press)
                    .is_some());
        let shown = self.image_view.ui(ui, self.settings.zoom, size, !grabbing);
        self.probe = shown.probe;
        if shown.zoom != self.settings.zoom {
            actions.push(Action::SetZoom {
                zoom: shown.zoom,
                recentre: false,
            });
        }
        let mut camera = self.scene().camera.clone();
        (camera.width, camera.height) = (size[0], size[1]);
        let projection = OverlayProjection::new(&camera, shown.image, shown.view);
        view_input::view_actions(
            &self.editor,
            &self.document,
            &projection,
            &shown.response,
            self.editing(),
            actions,
        );
        if self.editing() && self.overlay_installed {
            let callback = crate::gpu::wireframe::WireframeCallback {
                uniforms: projection.uniforms(ui.ctx().pixels_per_point()),
                geometry: self.state.editor.overlay(&self.state.document),
                generation: self.editor.generation,
            };
            ui.painter_at(shown.view)
                .add(eframe::egui_wgpu::Callback::new_paint_callback(
                    shown.view, callback,
                ));
        }
        if self.editing() {
            let markers = super::light_markers::edge_markers(&projection, self.lights());
            super::light_markers::paint(&ui.painter_at(shown.view), &markers);
        }
        if let Some((from, to)) = self.editor.rubber_band {
            let band = egui::Rect::from_two_pos(from, to);
            let stroke = egui::Stroke::new(1.0, ui.visuals().selection.stroke.color);
            let painter = ui.painter_at(shown.view);
            painter.rect_filled(band, 0.0, ui.visuals().selection.bg_fill.gamma_multiply(0.25));
            painter.rect_stroke(band, 0.0, stroke, egui::StrokeKind::Inside);
        }
        self.projection = Some(projection);
        if let Some(legend) = self.image_view.legend {
            legend.ui(ui, shown.view);
        }
    }
}
