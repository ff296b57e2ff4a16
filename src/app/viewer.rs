//! The viewer's core: its state ([`ViewerState`]) and what runs it — the render session and
//! what it is sent, opening and saving, the newest frame. The window's frame
//! ([`Viewer::poll`], [`Viewer::ui`], which the eframe app ([`super::CausticApp`]) and the
//! kittest tests drive) is in `window.rs`, the one file that calls into all the others.

use std::collections::VecDeque;
use std::path::{Path, PathBuf};
use std::time::Instant;

use super::document::{Change, Document};
use super::editor::Editor;
use super::file_dialog::{self, FileDialog, FileRequest, NativeDialog};
use super::image_view::{frame_image, ImageView};
use super::job::Job;
use super::overlay::OverlayProjection;
use super::params::{PanelChoices, PanelParams, Ranges};
use super::save::{default_file_name, SaveEvent, Snapshot};
use super::settings::{ViewerSettings, Zoom};
pub use super::state::Status;
use super::state::ViewerState;
use super::tev_send::TevSend;
use crate::render::error_tracker::ErrorEstimate;
use crate::render::frame::ErrorSource;
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
    pub(super) session: RenderSession,
    pub(super) image_view: ImageView,
    pub(super) picking: Option<FileDialog>,
    /// How native file dialogs are shown.
    native_dialog: NativeDialog,
    pub(super) loading: Option<(Job<Result<Scene, String>>, PathBuf)>,
    recent_commands: VecDeque<Command>,
    created: Instant,
    /// Where the image and its overlay were placed in the last UI frame.
    pub(super) projection: Option<OverlayProjection>,
    /// Whether the wgpu overlay was installed in the renderer (else it is not drawn).
    pub(super) overlay_installed: bool,
    /// Whether the window is cleared to the panels' colour, so the panels draw no fill
    /// ([`Viewer::panels_on_clear_colour`]).
    pub(super) panels_on_clear: bool,
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
    /// Whether the side panel has been drawn (its first frame starts at the top).
    pub(super) side_panel_shown: bool,
    /// The design running (the Design panel's).
    pub(super) design_run: Option<super::design::DesignRun>,
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
        background: true,
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
            panels_on_clear: false,
            scene_dialog: None,
            tev: TevSend::default(),
            watch: None,
            watch_picking: None,
            watch_scene_from: None,
            watch_epoch_base: 0,
            side_panel_shown: false,
            design_run: None,
        }
    }

    /// Draws the image and the control-net overlay with wgpu from now on: sets their pipelines
    /// up in `render_state` (eframe's, or a test's). `depth_format` must match the render
    /// pass's.
    pub fn install_wgpu(
        &mut self,
        render_state: &eframe::egui_wgpu::RenderState,
        depth_format: Option<eframe::wgpu::TextureFormat>,
    ) {
        crate::gpu::wireframe::install(render_state, depth_format, 1);
        crate::gpu::image_quad::install(render_state, depth_format, 1);
        self.image_view.draw_with_wgpu();
        self.overlay_installed = true;
    }

    /// Draws the menu bar, status bar and side panel without a fill of their own, on a window
    /// whose frames are cleared to the panels' colour ([`super::CausticApp`]'s
    /// `clear_color`). A software rasteriser pays for every pixel of a fill: the panels' fills
    /// were a third of a frame (`caustic view --bench`, teapot, lavapipe, paused: 33 fps with
    /// them, 46–48 without).
    pub fn panels_on_clear_colour(&mut self) {
        self.panels_on_clear = true;
    }

    /// Shows why the scene asked for at launch could not be opened: the viewer has opened
    /// the built-in scene instead, and says so.
    pub fn report_launch_failure(&mut self, message: String) {
        self.scene_error = Some(super::state::SceneError {
            message,
            instead: "The built-in scene is shown instead.".to_owned(),
        });
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
            || self.design_run.is_some()
            || self.design.picking.is_some()
    }

    /// Sends a command to the render session, remembering it (and when a restart was asked).
    pub fn send(&mut self, command: Command) {
        let restarts = command.restarts(&self.document.scene().params);
        self.send_command(command, restarts);
    }

    /// Sends the render session what an edit of the document changed.
    pub(super) fn send_change(&mut self, change: Change) {
        self.send_command(change.command, change.restarts);
    }

    fn send_command(&mut self, command: Command, restarts: bool) {
        if restarts {
            let epoch = self.frame.as_ref().map_or(0, |f| f.epoch);
            self.pending_restart = Some((Instant::now(), epoch));
        }
        if self.recent_commands.len() == COMMAND_LOG {
            self.recent_commands.pop_front();
        }
        self.recent_commands.push_back(command.clone());
        self.session.send(command);
    }

    /// Sets what the side panel edits: the document's render parameters and lens, and the
    /// panel's choices (manual values, pause), sending the render session what changed.
    pub fn set_params(&mut self, params: PanelParams) {
        let changes = [
            self.state.document.set_params(&params.render),
            self.state
                .document
                .set_lens(params.aperture, params.focal_distance),
        ];
        for change in changes.into_iter().flatten() {
            self.send_change(change);
        }
        let choices = params.choices();
        if choices.paused != self.panel.paused {
            self.send(if choices.paused {
                Command::Pause
            } else {
                Command::Resume
            });
        }
        self.panel = choices;
    }

    /// Starts a new render session for the current scene and parameters (after a renderer
    /// failure, or on another scene).
    pub fn restart_renderer(&mut self) {
        let scene = self.document.scene().clone();
        self.session = start_session(&self.ctx, scene, self.panel.paused);
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
        self.editor
            .pick(&self.document, self.projection.as_ref()?, pointer)
    }

    /// Replaces the scene (a successful open).
    pub(super) fn replace_scene(&mut self, scene: Scene) {
        self.replace_scene_with(scene, false);
    }

    /// Replaces the scene with its renderer paused (a watched render's scene).
    pub(super) fn replace_scene_paused(&mut self, scene: Scene) {
        self.replace_scene_with(scene, true);
    }

    fn replace_scene_with(&mut self, scene: Scene, paused: bool) {
        self.abandon_design();
        let scene = photon_mapped(scene);
        self.panel = PanelChoices {
            paused,
            ..PanelChoices::default()
        };
        self.ranges = Ranges::for_scene(&scene);
        self.editor = Editor::new(&scene);
        self.projection = None;
        self.document = Document::new(scene);
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
        let scene = self.document.scene();
        let text = crate::scene::save::scene_toml(scene, self.document.loaded_patches(), None).ok();
        let mut metadata = image_metadata(scene, renderer, text);
        metadata.push(("caustic:passes".into(), frame.pass.to_string()));
        metadata.push(("caustic:photons".into(), frame.photons.to_string()));
        metadata.push(("caustic:alpha".into(), scene.params.alpha.to_string()));
        metadata.push(("caustic:aperture".into(), scene.camera.aperture.to_string()));
        metadata.push((
            "caustic:focal_distance".into(),
            scene.camera.focal_distance.to_string(),
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
        let name = default_file_name(&self.scene().source, snapshot.pass);
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

    pub(super) fn on_save_event(&mut self, event: SaveEvent) {
        self.status = Some(match event {
            SaveEvent::Saved { path, pass } => {
                self.remember_folder_of(&path);
                Status::Info(format!("Saved pass {pass} to {}", path.display()))
            }
            SaveEvent::Failed(e) => Status::Error(format!("Not saved: {e}")),
            SaveEvent::Cancelled => Status::Info("Save cancelled".into()),
        });
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
        if let ErrorSource::PassSpread(spread) = frame.error {
            if let Some(noise) = spread {
                // Over every pixel: each one's passes spread.
                let pixels = frame.width as f64 * frame.height as f64;
                let estimate = ErrorEstimate {
                    noise,
                    blur: None,
                    pixels,
                    settling: false,
                };
                self.convergence.add_estimate(frame.elapsed_secs, estimate);
            }
        } else if frame.stats.renderer().progressive() && !frame.preview {
            // Photon mapping's α shapes how its noise and bias fall; a path tracer's passes
            // are plain means (α = 1: no bias to fall).
            let alpha = match frame.stats.renderer() {
                crate::settings::RendererKind::Ppm => self.document.scene().params.alpha,
                _ => 1.0,
            };
            self.convergence.add(
                (frame.photons, &frame.restarts),
                frame.elapsed_secs,
                &frame.radiance,
                alpha,
            );
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

    /// Sends the current frame to tev at `address` (`HOST:PORT`) as the image
    /// `caustic: <scene file>`; the status bar says how it went.
    pub fn send_to_tev(&mut self, address: &str) {
        let Some(frame) = self.frame.clone() else {
            self.status = Some(Status::Error("nothing to send yet: no frame has arrived".into()));
            return;
        };
        let name = format!(
            "caustic: {}",
            self.scene()
                .source
                .file_name()
                .map_or("scene".into(), |n| n.to_string_lossy())
        );
        self.tev.send(&self.ctx, frame, name, address);
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
}
