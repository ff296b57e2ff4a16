//! The desktop viewer: eframe with the wgpu renderer, the render session on its
//! own thread, the image with exposure, zoom and a pixel probe, a side panel of parameters
//! and statistics, open and save dialogs, persisted preferences.
//!
//! Built with the `viewer` feature (on by default); the render core never depends on it.
//!
//! - [`document`]: the scene being edited, the one copy of it; each edit answers with the
//!   commands that bring the render session along.
//! - [`viewer`], [`state`]: what runs the viewer and what its widgets read; `window`: the
//!   frame ([`Viewer::ui`] is what eframe and the tests run).
//! - [`action`]: every request as an [`action::Action`]; [`Viewer::apply`] carries them out.
//! - [`controls`], [`edit_panel`], [`material_panel`]: menu, side panel, status bar, dialog
//!   windows.
//! - [`overlay`], [`editor`], [`view_input`], [`navigate`]: the control-net overlay's
//!   projection and geometry, the editing state and undo history, the mouse over the image,
//!   and camera moves (drawn by [`crate::gpu::wireframe`]); [`light_markers`]: where the
//!   lights outside the view are.
//! - [`image_view`]: texture, fit / 1:1 / zoom / pan, probe.
//! - [`params`]: what the side panel edits (the document's parameters and lens, pause); [`setting_ui`]:
//!   each render setting's control, from the table of settings.
//! - [`error_plot`]: the error estimate (and the true error against a reference) plotted
//!   against time; [`mod@reference`], [`difference`]: the reference image, the difference views
//!   and the A/B toggle.
//! - [`save`], [`job`], [`file_dialog`]: dialogs (native, or inside the window where no native
//!   one can be shown) and file writes off the UI thread; [`tev_send`]: the frame
//!   to a running tev.
//! - [`commands`]: the one table of the viewer's commands (menus, shortcuts, F1's help);
//!   [`keys`], [`settings`], [`automation`]: the keyboard, stored preferences, scripted runs.
//! - [`watch`]: a render folder's parts merged as a farm writes them (`view --watch`).

pub mod action;
mod apply;
pub mod automation;
pub mod commands;
pub mod controls;
pub mod design;
mod design_actions;
pub mod design_panel;
pub mod difference;
pub mod document;
pub mod edit_panel;
pub mod editor;
pub mod error_plot;
pub mod false_colour;
pub mod file_dialog;
pub mod handle;
pub mod image_view;
pub mod job;
pub mod keys;
pub mod light_markers;
pub mod material_panel;
pub mod navigate;
pub mod overlay;
pub mod pacing;
pub mod params;
pub mod reference;
mod reference_files;
pub mod save;
mod scene_file;
pub mod setting_ui;
pub mod settings;
pub mod state;
pub mod tev_send;
pub mod view_input;
pub mod viewer;
pub mod watch;
mod watch_folder;
mod window;

use std::path::PathBuf;

pub use action::Action;
pub use automation::LaunchOptions;
pub use settings::ViewerSettings;
pub use viewer::Viewer;

use crate::scene::Scene;
use automation::Automation;

/// The eframe application: the viewer plus an optional scripted run.
pub struct CausticApp {
    /// The viewer.
    pub viewer: Viewer,
    automation: Option<Automation>,
    /// Paces frames while an edit waits for its image, where the window is painted on the CPU.
    pacer: pacing::FramePacer,
    /// Set when a scripted run failed (read after the window closed).
    failure: std::sync::Arc<std::sync::Mutex<Option<String>>>,
}

impl eframe::App for CausticApp {
    fn ui(&mut self, ui: &mut egui::Ui, _frame: &mut eframe::Frame) {
        let viewer = &self.viewer;
        let pending = viewer.restart_pending() && !viewer.paused();
        let input = ui
            .ctx()
            .input(|i| !i.events.is_empty() || i.pointer.delta() != egui::Vec2::ZERO);
        self.pacer.wait((pending, input), || viewer.frame_waiting());
        let start = std::time::Instant::now();
        self.viewer.ui(ui);
        let ui_secs = start.elapsed().as_secs_f64();
        if let Some(a) = &mut self.automation {
            a.step(&mut self.viewer, ui.ctx(), ui_secs);
            if let (Some(f), Ok(mut slot)) = (&a.failed, self.failure.lock()) {
                *slot = Some(f.clone());
            }
        }
    }

    /// The panels' colour: the bars and the side panel are drawn on it without a fill of their
    /// own ([`Viewer::panels_on_clear_colour`]).
    fn clear_color(&self, visuals: &egui::Visuals) -> [f32; 4] {
        visuals.panel_fill.to_normalized_gamma_f32()
    }

    fn save(&mut self, storage: &mut dyn eframe::Storage) {
        eframe::set_value(storage, settings::STORAGE_KEY, &self.viewer.settings);
    }
}

/// Opens the viewer window on `scene_path` (the built-in scene when `None`) and runs until it
/// closes. A scene that fails to load is reported in the window over the built-in scene.
pub fn run(scene_path: Option<PathBuf>, mut launch: LaunchOptions) -> anyhow::Result<()> {
    let reference = launch.reference.take();
    let watch = launch.watch.take();
    let (scene, error) = match &scene_path {
        None => (Scene::builtin(), None),
        Some(p) => match Scene::load(p) {
            Ok(s) => {
                for warning in &s.warnings {
                    eprintln!("caustic view: warning: {warning}");
                }
                (s, None)
            }
            Err(e) => {
                eprintln!("caustic view: {e}");
                (Scene::builtin(), Some(e.to_string()))
            }
        },
    };
    let scripted = launch.screenshot.is_some() || launch.bench;
    let native = eframe::NativeOptions {
        viewport: egui::ViewportBuilder::default()
            .with_title("caustic")
            .with_inner_size([1180.0, 760.0])
            .with_min_inner_size([480.0, 320.0])
            .with_drag_and_drop(true),
        renderer: eframe::Renderer::Wgpu,
        // A scripted run must not depend on (or change) what a person's last session stored.
        persistence_path: scripted.then(|| std::env::temp_dir().join("caustic-scripted-run")),
        ..Default::default()
    };
    let failure = std::sync::Arc::new(std::sync::Mutex::new(None));
    let app_failure = failure.clone();
    eframe::run_native(
        "caustic",
        native,
        Box::new(move |cc| {
            let settings = if scripted {
                ViewerSettings::default()
            } else {
                cc.storage
                    .and_then(|s| eframe::get_value::<ViewerSettings>(s, settings::STORAGE_KEY))
                    .unwrap_or_default()
            };
            let mut viewer = Viewer::new(&cc.egui_ctx, scene, settings);
            if let Some(render_state) = &cc.wgpu_render_state {
                // eframe's default `depth_buffer: 0` gives egui's pass no depth attachment.
                viewer.install_wgpu(render_state, None);
            }
            viewer.panels_on_clear_colour();
            if let Some(e) = error {
                viewer.report_launch_failure(e);
            }
            if let Some(r) = reference {
                viewer.set_reference(r);
            }
            if let Some(dir) = watch {
                viewer.watch_folder(dir);
            }
            let software = cc.wgpu_render_state.as_ref().is_some_and(pacing::paints_on_cpu);
            let mut automation = Automation::new(launch);
            if let Some(a) = &mut automation {
                a.paced = software;
            }
            Ok(Box::new(CausticApp {
                viewer,
                automation,
                pacer: pacing::FramePacer::new(software),
                failure: app_failure,
            }))
        }),
    )
    .map_err(|e| anyhow::anyhow!("could not open the viewer window: {e}"))?;
    let failed = failure.lock().ok().and_then(|f| f.clone());
    match failed {
        Some(f) => Err(anyhow::anyhow!(f)),
        None => Ok(()),
    }
}
