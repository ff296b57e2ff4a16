//! The viewer's state and its frame: render session, newest frame, parameters, open/save
//! flows, messages. The eframe app ([`super::CausticApp`]) and the kittest tests both drive
//! [`Viewer::ui`].

use std::collections::VecDeque;
use std::path::{Path, PathBuf};
use std::time::Instant;

use super::action::Action;
use super::controls;
use super::editor::Editor;
use super::file_dialog::{self, FileDialog, FileRequest, Finished, NativeDialog};
use super::image_view::{frame_image, Comparison, ImageView};
use super::job::{Job, Poll};
use super::keys;
use super::overlay::OverlayProjection;
use super::params::{PanelParams, Ranges};
use super::reference::is_reference_file;
use super::save::{default_file_name, SaveEvent, Snapshot};
use super::settings::{ViewerSettings, Zoom};
pub use super::state::Status;
use super::state::ViewerState;
use super::tev_send::TevSend;
use super::view_input;
use crate::render::image_metadata;
use crate::render::session::{Command, Frame, RenderSession, SessionOptions};
use crate::scene::{RendererKind, Scene};

/// Commands kept in [`Viewer::recent_commands`].
const COMMAND_LOG: usize = 256;

/// The viewer: its state ([`ViewerState`], what the widgets read) and what runs it (the render
/// session, dialogs and loads under way, the image's texture and the overlay). It derefs to its
/// state, so the code that carries out actions reads and writes the state's fields directly;
/// widgets get only `&ViewerState` and answer with actions.
pub struct Viewer {
    /// What the widgets read.
    pub state: ViewerState,
    pub(super) ctx: egui::Context,
    session: RenderSession,
    pub(super) image_view: ImageView,
    picking: Option<FileDialog>,
    /// How native file dialogs are shown.
    native_dialog: NativeDialog,
    loading: Option<(Job<Result<Scene, String>>, PathBuf)>,
    recent_commands: VecDeque<Command>,
    created: Instant,
    /// Where the image and its overlay were placed in the last UI frame.
    pub(super) projection: Option<OverlayProjection>,
    /// Whether the wgpu overlay was installed in the renderer (else it is not drawn).
    pub(super) overlay_installed: bool,
    /// The "save scene as" dialog.
    pub(super) scene_dialog: Option<FileDialog>,
    /// A frame being sent to tev.
    pub(super) tev: TevSend,
    /// The render folder being watched ([`super::watch`]).
    pub(super) watch: Option<super::watch::FolderWatch>,
    /// The folder dialog for a render folder to watch.
    pub(super) watch_picking: Option<FileDialog>,
    /// The part whose scene the viewer shows while watching.
    pub(super) watch_scene_from: Option<PathBuf>,
    /// Added to watched images' epochs, so they follow the session's frames.
    pub(super) watch_epoch_base: u64,
}

impl std::ops::Deref for Viewer {
    type Target = ViewerState;
    fn deref(&self) -> &ViewerState {
        &self.state
    }
}

impl std::ops::DerefMut for Viewer {
    fn deref_mut(&mut self) -> &mut ViewerState {
        &mut self.state
    }
}

fn session_options(start_paused: bool) -> SessionOptions {
    SessionOptions {
        start_paused,
        ..SessionOptions::interactive()
    }
}

/// The viewer always opens a scene with photon mapping (the image converges from the first
/// second); the ray tracer a scene file may ask for is one click away.
fn photon_mapped(mut scene: Scene) -> Scene {
    scene.params.renderer = RendererKind::Ppm;
    scene
}

fn start_session(ctx: &egui::Context, scene: Scene, paused: bool) -> RenderSession {
    let waker_ctx = ctx.clone();
    RenderSession::start_with(
        scene,
        session_options(paused),
        Some(Box::new(move || waker_ctx.request_repaint())),
    )
}

impl Viewer {
    /// A viewer rendering `scene`, with `settings` from storage.
    pub fn new(ctx: &egui::Context, scene: Scene, settings: ViewerSettings) -> Self {
        Self::with_pause(ctx, scene, settings, false)
    }

    /// A viewer whose renderer starts paused when `paused` (Resume, or Space, starts it).
    pub fn with_pause(ctx: &egui::Context, scene: Scene, settings: ViewerSettings, paused: bool) -> Self {
        let scene = photon_mapped(scene);
        let session = start_session(ctx, scene.clone(), paused);
        Self {
            state: ViewerState::new(scene, settings.sanitized(), paused),
            ctx: ctx.clone(),
            session,
            image_view: ImageView::default(),
            picking: None,
            native_dialog: file_dialog::rfd_dialog,
            loading: None,
            recent_commands: VecDeque::new(),
            created: Instant::now(),
            projection: None,
            overlay_installed: false,
            scene_dialog: None,
            tev: TevSend::default(),
            watch: None,
            watch_picking: None,
            watch_scene_from: None,
            watch_epoch_base: 0,
        }
    }

    /// Draws the control-net overlay with wgpu from now on: sets its pipelines up in
    /// `render_state` (eframe's, or a test's). `depth_format` must match the render pass's.
    pub fn install_overlay(
        &mut self,
        render_state: &eframe::egui_wgpu::RenderState,
        depth_format: Option<eframe::wgpu::TextureFormat>,
    ) {
        crate::gpu::wireframe::install(render_state, depth_format, 1);
        self.overlay_installed = true;
    }

    /// Commands sent to the render session, oldest first (the last 256).
    pub fn recent_commands(&self) -> impl Iterator<Item = &Command> {
        self.recent_commands.iter()
    }

    /// Whether a scene is being opened or a frame or scene saved.
    pub fn busy(&self) -> bool {
        self.loading.is_some()
            || self.picking.is_some()
            || self.save.busy()
            || self.scene_dialog.is_some()
            || self.reference.busy()
            || self.tev.busy()
    }

    /// Sends a command to the render session, remembering it (and when a restart was asked).
    pub fn send(&mut self, command: Command) {
        if command.restarts(&self.params.render) {
            let epoch = self.frame.as_ref().map_or(0, |f| f.epoch);
            self.pending_restart = Some((Instant::now(), epoch));
        }
        if self.recent_commands.len() == COMMAND_LOG {
            self.recent_commands.pop_front();
        }
        self.recent_commands.push_back(command.clone());
        self.session.send(command);
    }

    /// Sets parameters, sending the commands their changes need.
    pub fn set_params(&mut self, params: PanelParams) {
        for command in params.commands_from(&self.params, &self.scene.camera) {
            self.send(command);
        }
        self.scene.camera = params.lens_on(&self.scene.camera);
        self.params = params;
    }

    /// Starts a new render session for the current scene and parameters (after a renderer
    /// failure, or on another scene).
    pub fn restart_renderer(&mut self) {
        let scene = self.edited_scene();
        self.session = start_session(&self.ctx, scene, self.params.paused);
        self.render_failure = None;
        self.frame = None;
        self.convergence.reset();
        self.image_view.invalidate();
        self.pending_restart = Some((Instant::now(), 0));
    }

    /// Renders with `session` from now on: one started elsewhere, with options or a waker of
    /// its own (a test's, for example). The old session's frames are dropped.
    pub fn attach_session(&mut self, session: RenderSession) {
        self.session = session;
        self.frame = None;
        self.convergence.reset();
        self.image_view.invalidate();
    }

    /// Where the image and overlay were placed in the last UI frame.
    pub fn projection(&self) -> Option<&OverlayProjection> {
        self.projection.as_ref()
    }

    /// The handle (control point or light) a press at `pointer` would grab, with the overlay
    /// as placed in the last frame.
    pub fn handle_at(&self, pointer: egui::Pos2) -> Option<super::handle::Handle> {
        self.editor.pick(self.projection.as_ref()?, pointer)
    }

    /// Replaces the scene (a successful open).
    fn replace_scene(&mut self, scene: Scene) {
        self.replace_scene_with(scene, false);
    }

    /// Replaces the scene with its renderer paused (a watched render's scene).
    pub(super) fn replace_scene_paused(&mut self, scene: Scene) {
        self.replace_scene_with(scene, true);
    }

    fn replace_scene_with(&mut self, scene: Scene, paused: bool) {
        let scene = photon_mapped(scene);
        self.params = PanelParams::from_scene(&scene);
        self.params.paused = paused;
        self.ranges = Ranges::for_scene(&scene);
        self.editor = Editor::new(&scene);
        self.projection = None;
        self.scene = scene;
        self.restart_renderer();
        self.settings.zoom = Zoom::Fit;
        self.image_view.recentre();
    }

    /// Opens a scene file on a background thread; on failure the error is shown and the
    /// current scene keeps rendering.
    pub fn open_scene(&mut self, path: PathBuf) {
        let p = path.clone();
        let job = Job::spawn("caustic-load", &self.ctx, move || {
            Scene::load(&p).map_err(|e| e.to_string())
        });
        self.loading = Some((job, path));
    }

    /// Shows the open dialog (on a thread).
    pub fn pick_scene(&mut self) {
        if self.picking.is_some() {
            return;
        }
        let request = FileRequest {
            title: "Open scene".into(),
            filters: vec![("caustic scene".into(), vec!["toml".into()])],
            directory: self.settings.last_directory.clone(),
            file_name: None,
            save: false,
            folder: false,
        };
        self.picking = Some(FileDialog::open(
            "caustic-open-dialog",
            &self.ctx,
            self.native_dialog,
            request,
        ));
    }

    /// The current frame as something to save, with its metadata.
    fn snapshot(&self) -> Option<Snapshot> {
        let frame = self.frame.as_ref()?;
        let renderer = frame.stats.renderer().name();
        // The parameters the panel changes are added below; the base pairs (scene file, seed,
        // size) do not depend on them.
        let scene = self.edited_scene();
        let text = crate::scene::save::scene_toml(&scene, &self.editor.loaded, None).ok();
        let mut metadata = image_metadata(&scene, renderer, text);
        metadata.push(("caustic:passes".into(), frame.pass.to_string()));
        metadata.push(("caustic:photons".into(), frame.photons.to_string()));
        metadata.push(("caustic:alpha".into(), self.params.render.alpha.to_string()));
        metadata.push(("caustic:aperture".into(), self.params.aperture.to_string()));
        metadata.push((
            "caustic:focal_distance".into(),
            self.params.focal_distance.to_string(),
        ));
        metadata.push((
            crate::render::provenance::EXPOSURE.into(),
            self.settings.exposure_stops.to_string(),
        ));
        Some(Snapshot {
            image: frame_image(frame),
            exposure_stops: self.settings.exposure_stops,
            metadata,
            pass: frame.pass,
        })
    }

    /// Ctrl+S: the save dialog for the current frame.
    pub fn save_with_dialog(&mut self) {
        let Some(snapshot) = self.snapshot() else {
            self.status = Some(Status::Error("nothing to save yet: no frame has arrived".into()));
            return;
        };
        let name = default_file_name(&self.scene.source, snapshot.pass);
        let dir = self.settings.last_directory.clone();
        self.state
            .save
            .open_dialog(&self.ctx, self.native_dialog, snapshot, dir, name);
    }

    /// Saves the current frame to `path` (.png as displayed, .exr linear), asking before
    /// replacing a file; the write runs on a background thread.
    pub fn save_to(&mut self, path: PathBuf) {
        let Some(snapshot) = self.snapshot() else {
            self.status = Some(Status::Error("nothing to save yet: no frame has arrived".into()));
            return;
        };
        if let Some(event) = self.state.save.save_to(&self.ctx, path, snapshot) {
            self.on_save_event(event);
        }
    }

    /// Answers the overwrite question.
    pub fn confirm_overwrite(&mut self, replace: bool) {
        if let Some(event) = self.state.save.confirm_overwrite(&self.ctx, replace) {
            self.on_save_event(event);
        }
    }

    /// File dialogs start in the folder of the last file opened or saved.
    pub(super) fn remember_folder_of(&mut self, path: &Path) {
        if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
            self.settings.last_directory = Some(dir.to_path_buf());
        }
    }

    fn on_save_event(&mut self, event: SaveEvent) {
        self.status = Some(match event {
            SaveEvent::Saved { path, pass } => {
                self.remember_folder_of(&path);
                Status::Info(format!("Saved pass {pass} to {}", path.display()))
            }
            SaveEvent::Failed(e) => Status::Error(format!("Not saved: {e}")),
            SaveEvent::Cancelled => Status::Info("Save cancelled".into()),
        });
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
                        self.replace_scene(scene);
                        self.scene_error = None;
                        self.status = Some(Status::Info(format!("Opened {}", path.display())));
                    }
                    Err(e) => {
                        self.status = Some(Status::Error(format!("Could not open {}", path.display())));
                        self.scene_error = Some(e);
                    }
                }
            }
        }
        if let Some(event) = self.state.save.poll(&self.ctx) {
            self.on_save_event(event);
        }
        self.poll_scene_dialog();
        self.poll_reference();
        self.poll_watch();
        if let Some(status) = self.tev.poll() {
            self.status = Some(status);
        }
    }

    /// Shows `frame` as the newest image if it is newer (a later epoch, or a later pass of
    /// this one) than the one shown; older frames are dropped. Frames from the session arrive
    /// here; tests hand in fixed frames.
    pub fn show_frame(&mut self, frame: Frame) {
        let current = self.frame.as_ref().map(|f| (f.epoch, f.pass));
        if current.is_some_and(|(e, p)| frame.epoch < e || (frame.epoch == e && frame.pass <= p)) {
            return;
        }
        if current.is_none_or(|(e, _)| frame.epoch > e) {
            self.convergence.reset();
        }
        if let Some((sent, epoch)) = self.pending_restart {
            if frame.epoch > epoch || self.frame.is_none() {
                self.restart_latency_secs = Some(sent.elapsed().as_secs_f64());
                self.pending_restart = None;
            }
        }
        if frame.stats.renderer().progressive() && !frame.preview {
            self.convergence
                .add(frame.photons, frame.elapsed_secs, &frame.radiance);
        }
        if let Some(errors) = self
            .reference
            .open
            .as_ref()
            .and_then(|r| r.errors(&frame.radiance))
        {
            if !frame.preview {
                self.convergence.add_reference(frame.elapsed_secs, errors);
            }
        }
        let since_start = self.created.elapsed().as_secs_f64();
        self.first_image_secs.get_or_insert(since_start);
        self.frame = Some(frame);
        self.image_view.invalidate();
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

        egui::Panel::top("caustic-menu").show(ui, |ui| controls::menu_ui(self, ui, &mut actions));
        egui::Panel::bottom("caustic-status").show(ui, |ui| controls::status_ui(self, ui));
        if self.settings.show_side_panel {
            egui::Panel::right("caustic-controls")
                .resizable(true)
                .default_size(290.0)
                .show(ui, |ui| {
                    egui::ScrollArea::vertical()
                        .show(ui, |ui| controls::side_panel_ui(self, ui, &mut actions));
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

    /// Sends the current frame to tev at `address` (`HOST:PORT`) as the image
    /// `caustic: <scene file>`; the status bar says how it went.
    pub fn send_to_tev(&mut self, address: &str) {
        let Some(frame) = self.frame.clone() else {
            self.status = Some(Status::Error("nothing to send yet: no frame has arrived".into()));
            return;
        };
        let name = format!(
            "caustic: {}",
            self.scene
                .source
                .file_name()
                .map_or("scene".into(), |n| n.to_string_lossy())
        );
        self.tev.send(&self.ctx, frame, name, address);
    }

    /// The file dialogs under way (at most one of each kind).
    fn file_dialogs(&self) -> impl Iterator<Item = &FileDialog> {
        [
            self.picking.as_ref(),
            self.scene_dialog.as_ref(),
            self.reference.picking.as_ref(),
            self.watch_picking.as_ref(),
            self.save.file_dialog(),
        ]
        .into_iter()
        .flatten()
    }

    /// Whether a file dialog is showing inside the window (no native one could be shown).
    pub fn file_dialog_in_window(&self) -> bool {
        self.file_dialogs().any(FileDialog::in_window)
    }

    /// How native file dialogs are shown.
    pub(super) fn native_dialog(&self) -> NativeDialog {
        self.native_dialog
    }

    /// Shows file dialogs with `native` instead of the desktop's (rfd). A dialog that returns
    /// nothing at once counts as one that could not be shown, and the window's own opens.
    pub fn set_native_dialog(&mut self, native: NativeDialog) {
        self.native_dialog = native;
    }

    /// The image, the control-net overlay over it, and the mouse.
    fn central_ui(&mut self, ui: &mut egui::Ui, actions: &mut Vec<Action>) {
        let Some(frame) = &self.frame else {
            self.probe = None;
            let waiting;
            let text = if let Some(w) = &self.watching {
                waiting = format!("Watching {}: waiting for the first part...", w.dir.display());
                waiting.as_str()
            } else if self.params.paused {
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
                && view_input::grab_at(&self.editor, self.projection.as_ref(), press).is_some());
        let shown = self.image_view.ui(ui, self.settings.zoom, size, !grabbing);
        self.probe = shown.probe;
        if shown.zoom != self.settings.zoom {
            actions.push(Action::SetZoom {
                zoom: shown.zoom,
                recentre: false,
            });
        }
        let mut camera = self.scene.camera.clone();
        (camera.width, camera.height) = (size[0], size[1]);
        let projection = OverlayProjection::new(&camera, shown.image, shown.view);
        view_input::view_actions(
            &self.editor,
            &projection,
            &shown.response,
            self.editing(),
            actions,
        );
        if self.editing() && self.overlay_installed {
            let callback = crate::gpu::wireframe::WireframeCallback {
                uniforms: projection.uniforms(ui.ctx().pixels_per_point()),
                geometry: self.editor.overlay(),
                generation: self.editor.generation,
            };
            ui.painter_at(shown.view)
                .add(eframe::egui_wgpu::Callback::new_paint_callback(
                    shown.view, callback,
                ));
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
            super::difference::legend_ui(ui, shown.view, legend);
        }
    }
}
