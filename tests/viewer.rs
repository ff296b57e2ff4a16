//! The viewer driven as a person would, through egui_kittest: sliders send the right session
//! commands, α keeps the epoch and the aperture starts a new one, frames save as readable PNG
//! and EXR without silent overwrites, a bad scene and a render-thread panic are shown in the
//! window, and a snapshot of the whole window with a fixed frame (rendered with wgpu).
#![cfg(feature = "viewer")]

mod common;

use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::{Duration, Instant};

use caustic::app::settings::ViewerSettings;
use caustic::app::viewer::Status;
use caustic::app::Viewer;
use caustic::render::ppm::{Control, Ppm, PpmOptions, PpmStats};
use caustic::render::session::{Command, Frame, FrameStats, RenderSession, SessionOptions};
use caustic::scene::{RendererKind, Scene};
use caustic::settings::RenderParams;
use egui::accesskit::Role;
use egui_kittest::kittest::Queryable;
use egui_kittest::Harness;

/// A glass ball on a floor under a point light: caustic, quick at 96×72.
const BALL: &str = r#"
[camera]
position = [0.0, 2.2, 4.5]
look_at = [0, 0.6, 0]
up = [0, 1, 0]
fov = 40
width = 96
height = 72

[render]
renderer = "ppm"
photons_per_pass = 20000
alpha = 0.7
antialias = false

[materials.floor]
type = "diffuse"
color = [0.75, 0.7, 0.6]

[materials.glass]
type = "glass"
color = [1, 1, 1]
ior = 1.5

[[lights]]
type = "point"
position = [1.0, 4.0, 1.0]
power = 900

[[objects]]
type = "plane"
point = [0, 0, 0]
normal = [0, 1, 0]
material = "floor"

[[objects]]
type = "sphere"
center = [0, 0.7, 0]
radius = 0.7
material = "glass"
"#;

/// A file dropped on the window, as the windowing layer reports it.
#[derive(Debug)]
struct DroppedPath(PathBuf);

impl egui::DroppedFile for DroppedPath {
    fn path(&self) -> &Path {
        &self.0
    }

    fn bytes(&self) -> Result<Vec<u8>, String> {
        std::fs::read(&self.0).map_err(|e| e.to_string())
    }
}

fn ball() -> Scene {
    Scene::from_str(BALL, Path::new("ball.toml"), None).expect("test scene loads")
}

type App<'a> = Harness<'a, Option<Viewer>>;

/// A window of `size` points that draws the viewer it holds (none yet).
fn window<'a>(size: egui::Vec2) -> App<'a> {
    Harness::builder().with_size(size).build_ui_state(
        |ui, viewer: &mut Option<Viewer>| {
            if let Some(v) = viewer {
                v.ui(ui);
            }
        },
        None,
    )
}

fn harness<'a>(scene: Scene, paused: bool) -> App<'a> {
    let mut h = window(egui::Vec2::new(1100.0, 720.0));
    let viewer = Viewer::with_pause(&h.ctx, scene, ViewerSettings::default(), paused);
    *h.state_mut() = Some(viewer);
    h.step();
    h
}

fn viewer<'h>(h: &'h App<'_>) -> &'h Viewer {
    h.state().as_ref().expect("viewer")
}

fn viewer_mut<'h>(h: &'h mut App<'_>) -> &'h mut Viewer {
    h.state_mut().as_mut().expect("viewer")
}

/// Steps the UI until `done` holds (the render thread works meanwhile); panics after 60 s.
fn step_until(h: &mut App<'_>, what: &str, done: impl Fn(&Viewer) -> bool) {
    let start = Instant::now();
    while !done(viewer(h)) {
        assert!(
            start.elapsed() < Duration::from_secs(60),
            "timed out waiting for {what}"
        );
        std::thread::sleep(Duration::from_millis(5));
        h.step();
    }
}

fn sent(h: &App<'_>) -> Vec<Command> {
    viewer(h).recent_commands().cloned().collect()
}

fn set_slider(h: &mut App<'_>, label: &str, value: f64) {
    h.get_by_role_and_label(Role::Slider, label)
        .set_value_accesskit(value);
    h.step();
    h.step();
}

/// [`set_slider`] while the render runs, stepping until the viewer sent the change. About one
/// request in ten, made as frames arrive, reached no widget (the slider kept its value and
/// nothing was sent), so it is asked again, at most three times.
fn set_slider_while_rendering(h: &mut App<'_>, label: &str, value: f64) {
    for _ in 0..3 {
        let before = sent(h);
        set_slider(h, label, value);
        if sent(h) != before {
            return;
        }
    }
    panic!("setting the {label} slider to {value} sent nothing, three times");
}

#[test]
fn each_slider_sends_its_command() {
    let mut h = harness(ball(), true);
    // Render settings go as one parameter set; the lens goes on the camera.
    type Change = fn(&mut RenderParams);
    let cases: Vec<(&str, f64, Change)> = vec![
        ("Alpha", 0.5, |p| p.alpha = 0.5),
        ("Photons per pass", 50_000.0, |p| p.photons_per_pass = 50_000),
        ("Min photons per pixel", 8.0, |p| p.min_photons_per_pixel = 8.0),
        ("Max depth", 3.0, |p| p.max_depth = 3),
    ];
    for (label, value, change) in cases {
        let mut expected = viewer(&h).params().render.clone();
        change(&mut expected);
        set_slider(&mut h, label, value);
        assert_eq!(
            sent(&h).last(),
            Some(&Command::SetParams(expected)),
            "slider {label}"
        );
    }
    set_slider(&mut h, "Aperture", 0.05);
    assert!(
        matches!(sent(&h).last(), Some(Command::SetCamera(c)) if c.aperture == 0.05),
        "slider Aperture"
    );
    set_slider(&mut h, "Focal distance", 3.0);
    assert!(
        matches!(sent(&h).last(), Some(Command::SetCamera(c)) if c.focal_distance == 3.0 && c.aperture == 0.05),
        "slider Focal distance"
    );
    let initial_radius = |h: &App<'_>| match sent(h).last() {
        Some(Command::SetParams(p)) => p.initial_radius,
        other => panic!("expected parameters, got {other:?}"),
    };
    // The initial radius slider is enabled by unticking "automatic".
    h.get_by_role_and_label(Role::CheckBox, "Automatic initial radius")
        .click();
    h.step();
    h.step();
    let radius = viewer(&h).params().manual.get("initial_radius").copied();
    assert!(radius.is_some_and(|r| r > 0.0), "the slider's value: {radius:?}");
    assert_eq!(initial_radius(&h), radius);
    set_slider(&mut h, "Initial radius", 0.01);
    assert_eq!(initial_radius(&h), Some(0.01));
    // Exposure is the viewer's own: no command.
    let before = sent(&h).len();
    set_slider(&mut h, "Exposure", 1.5);
    assert_eq!(viewer(&h).settings.exposure_stops, 1.5);
    assert_eq!(sent(&h).len(), before, "exposure sent a command");
    // The renderer buttons, pause and restart.
    h.get_by_label("Ray tracer").click();
    h.step();
    assert!(
        matches!(sent(&h).last(), Some(Command::SetParams(p)) if p.renderer == RendererKind::Whitted),
        "renderer button"
    );
    h.get_by_label("Resume").click();
    h.step();
    assert_eq!(sent(&h).last(), Some(&Command::Resume));
    h.key_press(egui::Key::Space);
    h.step();
    assert_eq!(sent(&h).last(), Some(&Command::Pause));
    h.get_by_label("Restart").click();
    h.step();
    assert_eq!(sent(&h).last(), Some(&Command::Restart));
}

#[test]
fn alpha_keeps_the_epoch_and_aperture_starts_a_new_one() {
    let mut h = harness(ball(), false);
    step_until(&mut h, "the first frame", |v| v.frame().is_some());
    assert_eq!(viewer(&h).frame().map(|f| f.epoch), Some(0));
    set_slider_while_rendering(&mut h, "Alpha", 0.6);
    let pass = viewer(&h).frame().map_or(0, |f| f.pass);
    step_until(&mut h, "two more passes", |v| {
        v.frame().is_some_and(|f| f.pass >= pass + 2)
    });
    assert_eq!(
        viewer(&h).frame().map(|f| f.epoch),
        Some(0),
        "alpha restarted the render"
    );
    set_slider_while_rendering(&mut h, "Aperture", 0.05);
    step_until(&mut h, "a new epoch", |v| v.frame().is_some_and(|f| f.epoch >= 1));
    // (That the new epoch starts from scratch is the session's rule, tested in tests/ppm.rs.)
    assert_eq!(viewer(&h).frame().map(|f| f.epoch), Some(1));
    assert!(viewer(&h).restart_latency_secs().is_some());
}

fn wait_saved(h: &mut App<'_>) -> Status {
    step_until(h, "the save", |v| !v.busy());
    viewer(h).status().cloned().expect("a status line")
}

#[test]
fn save_writes_readable_png_and_exr_and_asks_before_replacing() {
    let dir = tempfile::tempdir().expect("temp dir");
    // A paused renderer and a fixed frame: what is saved cannot change under the test.
    let mut h = harness(ball(), true);
    for f in fixed_frames() {
        viewer_mut(&mut h).show_frame(f);
    }
    h.step();
    let png = dir.path().join("frame.png");
    viewer_mut(&mut h).save_to(png.clone());
    match wait_saved(&mut h) {
        Status::Info(s) => assert!(s.contains("frame.png"), "{s}"),
        Status::Error(e) => panic!("{e}"),
    }
    let img = image::open(&png).expect("PNG reads back");
    assert_eq!((img.width(), img.height()), (96, 72));

    let exr = dir.path().join("frame.exr");
    viewer_mut(&mut h).save_to(exr.clone());
    wait_saved(&mut h);
    let linear = image::open(&exr).expect("EXR reads back").into_rgb32f();
    let frame = viewer(&h).frame().expect("frame").clone();
    let mean_exr: f64 = linear.pixels().map(|p| p.0[1] as f64).sum::<f64>() / (96.0 * 72.0);
    let mean_frame: f64 = frame.radiance.iter().map(|p| p[1] as f64).sum::<f64>() / (96.0 * 72.0);
    assert!(
        (mean_exr / mean_frame - 1.0).abs() < 1e-5,
        "EXR {mean_exr} vs frame {mean_frame}"
    );

    // Saving over an existing file asks first; "Cancel" leaves it alone.
    let before = std::fs::read(&png).expect("read");
    std::fs::write(&png, b"precious").expect("write");
    viewer_mut(&mut h).save_to(png.clone());
    h.run_steps(3);
    assert_eq!(viewer(&h).confirming_overwrite(), Some(png.as_path()));
    assert!(
        h.query_by_label("Replace file?").is_some(),
        "no overwrite question shown"
    );
    h.get_by_label("Cancel").click();
    h.step();
    h.step();
    assert_eq!(std::fs::read(&png).expect("read"), b"precious");
    // "Replace" writes it.
    viewer_mut(&mut h).save_to(png.clone());
    h.run_steps(3);
    h.get_by_label("Replace").click();
    h.step();
    wait_saved(&mut h);
    assert_eq!(
        std::fs::read(&png).expect("read"),
        before,
        "the same frame gives the same PNG"
    );

    // A name the viewer cannot write is refused with a clear message.
    viewer_mut(&mut h).save_to(dir.path().join("frame.bmp"));
    match viewer(&h).status() {
        Some(Status::Error(e)) => assert!(e.contains(".png") && e.contains("frame.bmp"), "{e}"),
        other => panic!("expected an error, got {other:?}"),
    }
}

/// What rfd answers on a desktop with neither xdg-desktop-portal nor zenity: nothing, at once.
fn no_native_dialog(_: &caustic::app::file_dialog::FileRequest) -> Option<PathBuf> {
    None
}

/// A paused viewer with fixed frames and no native file dialog, whose "Save frame..." has
/// opened the window's own dialog in `dir`.
fn saving_without_a_native_dialog<'a>(dir: &Path) -> App<'a> {
    let mut h = harness(ball(), true);
    for f in fixed_frames() {
        viewer_mut(&mut h).show_frame(f);
    }
    viewer_mut(&mut h).set_native_dialog(no_native_dialog);
    viewer_mut(&mut h).settings.last_directory = Some(dir.to_path_buf());
    h.step();
    h.get_by_role_and_label(Role::Button, "Save frame...").click();
    step_until(&mut h, "the in-window dialog", Viewer::file_dialog_in_window);
    h.run_steps(2);
    h
}

/// The window's own dialog takes the keyboard from the start: typing replaces the proposed
/// name's stem (the extension stays), Enter saves, Tab completes from the listing, and Escape
/// cancels; the mouse is never used after "Save frame...".
#[test]
fn the_window_s_own_dialog_is_driven_by_the_keyboard_alone() {
    let dir = tempfile::tempdir().expect("temp dir");
    let mut h = saving_without_a_native_dialog(dir.path());
    h.event(egui::Event::Text("keyboard".into()));
    h.step();
    h.key_press(egui::Key::Enter);
    let status = wait_saved(&mut h);
    assert!(
        matches!(&status, Status::Info(t) if t.contains("keyboard.png")),
        "{status:?}"
    );
    assert!(dir.path().join("keyboard.png").is_file());

    // Select all, type the start of the name, Tab completes it, Enter takes it, and the
    // replace question answers Enter too.
    h.get_by_role_and_label(Role::Button, "Save frame...").click();
    step_until(&mut h, "the dialog again", Viewer::file_dialog_in_window);
    h.run_steps(2);
    h.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::A);
    h.event(egui::Event::Text("keyb".into()));
    h.step();
    h.key_press(egui::Key::Tab);
    h.step();
    h.key_press(egui::Key::Enter);
    step_until(&mut h, "the replace question", |v| {
        v.confirming_overwrite().is_some()
    });
    assert_eq!(
        viewer(&h).confirming_overwrite(),
        Some(dir.path().join("keyboard.png").as_path())
    );
    h.key_press(egui::Key::Enter);
    let status = wait_saved(&mut h);
    assert!(
        matches!(&status, Status::Info(t) if t.contains("keyboard.png")),
        "{status:?}"
    );

    // Escape cancels.
    h.get_by_role_and_label(Role::Button, "Save frame...").click();
    step_until(&mut h, "the dialog a third time", Viewer::file_dialog_in_window);
    h.run_steps(2);
    h.key_press(egui::Key::Escape);
    step_until(&mut h, "the dialog to close", |v| !v.busy());
    assert!(matches!(viewer(&h).status(), Some(Status::Info(s)) if s == "Save cancelled"));
}

#[test]
fn without_a_native_dialog_the_frame_saves_through_the_window_s_own() {
    let dir = tempfile::tempdir().expect("temp dir");
    let mut h = saving_without_a_native_dialog(dir.path());
    // It never reports a cancel for the dialog that did not open.
    assert!(
        !matches!(viewer(&h).status(), Some(Status::Info(s)) if s.contains("cancelled")),
        "{:?}",
        viewer(&h).status()
    );
    assert!(h
        .query_by_label("Types: PNG image (as displayed) (.png); OpenEXR image (linear radiance) (.exr)")
        .is_some());
    // The proposed name is there; replace it by typing, then Save.
    let field = h.get_by_role_and_label(Role::TextInput, "File name:");
    field.focus();
    h.step();
    h.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::A);
    h.get_by_role_and_label(Role::TextInput, "File name:")
        .type_text("fallback.png");
    h.step();
    h.get_by_role_and_label(Role::Button, "Save").click();
    let status = wait_saved(&mut h);
    let saved = dir.path().join("fallback.png");
    let Status::Info(text) = status else {
        panic!("{status:?}");
    };
    assert!(text.contains("fallback.png"), "{text}");
    let img = image::open(&saved).expect("the PNG reads back");
    assert_eq!((img.width(), img.height()), (96, 72));
    assert!(!viewer(&h).file_dialog_in_window());

    // Escape closes the window's dialog as a cancel.
    h.get_by_role_and_label(Role::Button, "Save frame...").click();
    step_until(
        &mut h,
        "the in-window dialog again",
        Viewer::file_dialog_in_window,
    );
    h.key_press(egui::Key::Escape);
    step_until(&mut h, "the dialog to close", |v| !v.busy());
    assert!(matches!(viewer(&h).status(), Some(Status::Info(s)) if s == "Save cancelled"));
}

/// A scene that fails at launch: the window says the built-in scene is shown instead (there
/// was no scene before it to keep rendering).
#[test]
fn a_scene_that_fails_at_launch_says_the_built_in_scene_is_shown() {
    let mut h = harness(Scene::builtin(), true);
    viewer_mut(&mut h).report_launch_failure("missing.toml: no such file".into());
    h.run_steps(2);
    assert!(h.query_by_label("Could not open scene").is_some());
    assert!(h.query_by_label("missing.toml: no such file").is_some());
    assert!(h.query_by_label("The built-in scene is shown instead.").is_some());
    assert!(h.query_by_label("ball.toml is still rendering.").is_none());
    assert_eq!(
        viewer(&h).scene_error_instead(),
        Some("The built-in scene is shown instead.")
    );
}

#[test]
fn bad_scene_shows_its_error_and_the_old_scene_keeps_rendering() {
    let dir = tempfile::tempdir().expect("temp dir");
    let bad = dir.path().join("bad.toml");
    std::fs::write(&bad, BALL.replace("radius = 0.7", "radius = -2")).expect("write");
    let mut h = harness(ball(), false);
    step_until(&mut h, "the first frame", |v| v.frame().is_some());
    viewer_mut(&mut h).open_scene(bad.clone());
    step_until(&mut h, "the load", |v| !v.busy());
    let error = viewer(&h).scene_error().expect("an error").to_owned();
    assert!(error.contains("bad.toml") && error.contains("radius"), "{error}");
    h.step();
    assert!(
        h.query_by_label("Could not open scene").is_some(),
        "no error window"
    );
    assert!(h.query_by_label("ball.toml is still rendering.").is_some());
    assert_eq!(viewer(&h).scene().source, PathBuf::from("ball.toml"));
    let pass = viewer(&h).frame().map_or(0, |f| f.pass);
    step_until(&mut h, "more passes of the old scene", |v| {
        v.frame().is_some_and(|f| f.pass > pass)
    });
    h.get_by_label("OK").click();
    h.step();
    assert!(viewer(&h).scene_error().is_none());

    // A good file dropped on the window replaces the scene.
    let good = dir.path().join("good.toml");
    std::fs::write(&good, BALL).expect("write");
    h.input_mut()
        .dropped_files
        .push(Arc::new(DroppedPath(good.clone())));
    h.step();
    step_until(&mut h, "the dropped scene", |v| {
        !v.busy() && v.scene().source == good
    });
}

#[test]
fn a_render_thread_panic_is_shown_and_the_renderer_can_restart() {
    let mut h = harness(ball(), false);
    step_until(&mut h, "the first frame", |v| v.frame().is_some());
    // A session whose waker panics on the render thread after its second frame: a failure
    // the way a real one arrives.
    let calls = std::sync::atomic::AtomicU32::new(0);
    let failing = RenderSession::start_with(
        viewer(&h).scene().clone(),
        SessionOptions::default(),
        Some(Box::new(move || {
            if calls.fetch_add(1, std::sync::atomic::Ordering::Relaxed) == 1 {
                panic!("injected failure");
            }
        })),
    );
    viewer_mut(&mut h).attach_session(failing);
    step_until(&mut h, "the failure", |v| v.render_failure().is_some());
    h.step();
    assert!(
        h.query_by_label_contains("injected failure").is_some(),
        "failure not shown"
    );
    h.get_by_label("Restart renderer").click();
    h.step();
    assert!(viewer(&h).render_failure().is_none());
    step_until(&mut h, "frames after the restart", |v| v.frame().is_some());
}

/// A harness that renders the window with wgpu (paint callbacks included), 1100×880, no
/// viewer yet, on whatever adapter this machine has; and that adapter's backend.
fn wgpu_harness<'a>() -> (App<'a>, &'static str) {
    let (renderer, backend) = common::gpu::renderer();
    let h = Harness::builder()
        .with_size(egui::Vec2::new(1100.0, 880.0))
        .renderer(renderer)
        .build_ui_state(
            |ui, viewer: &mut Option<Viewer>| {
                if let Some(v) = viewer {
                    v.ui(ui);
                }
            },
            None,
        );
    (h, backend)
}

/// Four deterministic passes of the test scene as frames with fixed timings.
fn fixed_frames() -> Vec<Frame> {
    let scene = ball();
    let mut ppm = Ppm::new(&scene, PpmOptions::default());
    let mut frames = Vec::new();
    for pass in 1..=4u32 {
        ppm.run_pass(&scene, &mut |_| Control::Continue);
        let mut frame = Frame::from_ppm(&ppm, 0, pass as f64 * 0.25);
        frame.stats = FrameStats::from(PpmStats {
            elapsed_secs: pass as f64 * 0.25,
            photon_secs: pass as f64 * 0.2,
            ..ppm.stats().clone()
        });
        frames.push(frame);
    }
    frames
}

#[test]
fn window_snapshot_with_a_fixed_frame() {
    let (mut h, backend) = wgpu_harness();
    let mut v = Viewer::with_pause(&h.ctx, ball(), ViewerSettings::default(), true);
    for f in fixed_frames() {
        v.show_frame(f);
    }
    v.settings.exposure_stops = -1.0;
    *h.state_mut() = Some(v);
    h.run_steps(4);
    h.snapshot(common::gpu::snapshot_name("viewer_window", backend));
}

/// Frames that differ only in one bright pixel: the plot's estimate says it is uncertain and
/// why (the error is in about one pixel), and draws those estimates as points; frames that
/// differ alike everywhere get no such note.
#[test]
fn an_estimate_resting_on_a_few_pixels_says_so() {
    for speck in [true, false] {
        let mut h = window(egui::Vec2::new(1180.0, 760.0));
        let mut v = Viewer::with_pause(&h.ctx, ball(), ViewerSettings::default(), true);
        for (k, mut f) in fixed_frames().into_iter().enumerate() {
            // Synthetic frames: no pixel's estimate started again between them.
            f.restarts = Default::default();
            let pixels = f.radiance.len();
            f.radiance = (0..pixels)
                .map(|p| {
                    let noise = if speck {
                        if p == pixels / 2 {
                            50.0 / (k + 1) as f32
                        } else {
                            0.0
                        }
                    } else {
                        0.1 * ((p * 7 + k * 13) % 5) as f32 / (k + 1) as f32
                    };
                    [0.5 + noise; 3]
                })
                .collect();
            v.show_frame(f);
        }
        *h.state_mut() = Some(v);
        h.run_steps(3);
        let noted = h.query_by_label_contains("uncertain: in ~1 pixels").is_some();
        let latest = viewer(&h).convergence().latest();
        assert_eq!(
            noted, speck,
            "speck {speck}: the note is shown: {noted} ({latest:?})"
        );
        let points = viewer(&h).convergence().uncertain_points.len();
        assert_eq!(points > 0, speck, "speck {speck}: {points} uncertain points");
    }
}

/// Storage as eframe hands it to the app: string values by key.
#[derive(Default)]
struct MemoryStorage(std::collections::HashMap<String, String>);

impl eframe::Storage for MemoryStorage {
    fn get_string(&self, key: &str) -> Option<String> {
        self.0.get(key).cloned()
    }
    fn set_string(&mut self, key: &str, value: String) {
        self.0.insert(key.to_owned(), value);
    }
    fn remove_string(&mut self, key: &str) {
        self.0.remove(key);
    }
    fn flush(&mut self) {}
}

#[test]
fn settings_survive_storage_and_bad_stored_values_are_repaired() {
    use caustic::app::settings::{DisplayMode, Zoom, STORAGE_KEY};
    let settings = ViewerSettings {
        exposure_stops: 1.5,
        zoom: Zoom::Scale(2.0),
        display: DisplayMode::Layer(0),
        show_side_panel: false,
        last_directory: Some(PathBuf::from("/some/where")),
        show_wireframe: false,
    };
    let mut storage = MemoryStorage::default();
    eframe::set_value(&mut storage, STORAGE_KEY, &settings);
    let back: ViewerSettings = eframe::get_value(&storage, STORAGE_KEY).expect("stored");
    assert_eq!(back, settings);
    // Damaged values fall back to sane ones.
    let bad = ViewerSettings {
        exposure_stops: f32::NAN,
        zoom: Zoom::Scale(-1.0),
        ..Default::default()
    }
    .sanitized();
    assert_eq!((bad.exposure_stops, bad.zoom), (0.0, Zoom::Fit));
}

/// `R` asks before throwing passes away; `E` / Shift+`E` step the exposure as in tev.
#[test]
fn r_asks_before_discarding_passes_and_e_steps_the_exposure() {
    let mut h = harness(ball(), false);
    step_until(&mut h, "two passes", |v| v.frame().is_some_and(|f| f.pass >= 2));
    let before = sent(&h).len();
    h.key_press(egui::Key::R);
    h.step();
    h.step();
    assert_eq!(sent(&h).len(), before, "R restarted without asking");
    assert!(h.query_by_label("Discard and restart").is_some(), "no question");
    h.get_by_label("Keep rendering").click();
    h.step();
    h.step();
    assert_eq!(sent(&h).len(), before, "Keep rendering restarted");
    h.key_press(egui::Key::R);
    h.step();
    h.step();
    h.get_by_label("Discard and restart").click();
    h.step();
    assert_eq!(sent(&h).last(), Some(&Command::Restart));
    let stops = viewer(&h).settings.exposure_stops;
    h.key_press(egui::Key::E);
    h.step();
    assert_eq!(viewer(&h).settings.exposure_stops, stops + 0.5);
    h.key_press_modifiers(egui::Modifiers::SHIFT, egui::Key::E);
    h.step();
    assert_eq!(viewer(&h).settings.exposure_stops, stops);
}

/// Opening a reference (dropped on the window, as a person would) adds the true error to the
/// convergence plot; the difference views show their legend; A/B shows the reference; a
/// reference of another size is refused with a message.
#[test]
fn opening_a_reference_shows_the_true_error_curve_and_the_difference_view() {
    use caustic::app::settings::DisplayMode;
    let dir = tempfile::tempdir().expect("temp dir");
    let frames = fixed_frames();
    // The reference: the last fixed frame, 0.05 brighter everywhere.
    let last = frames.last().expect("frames").clone();
    let reference = caustic::render::Image {
        width: last.width,
        height: last.height,
        pixels: last.radiance.iter().map(|p| p.map(|c| c + 0.05)).collect(),
    };
    let path = dir.path().join("reference.exr");
    reference
        .save(&path, 0.0, &Vec::new(), false)
        .expect("write reference");

    let (mut h, _) = wgpu_harness();
    let v = Viewer::with_pause(&h.ctx, ball(), ViewerSettings::default(), true);
    *h.state_mut() = Some(v);
    h.step();
    h.input_mut()
        .dropped_files
        .push(Arc::new(DroppedPath(path.clone())));
    h.step();
    step_until(&mut h, "the reference", |v| v.reference().is_some());
    for f in frames {
        viewer_mut(&mut h).show_frame(f);
    }
    h.run_steps(3);
    let points = viewer(&h).convergence().reference_points.clone();
    assert_eq!(points.len(), 4, "one true error per frame: {points:?}");
    let last_rmse = points[3][1];
    assert!(
        (last_rmse - 0.05).abs() < 1e-4,
        "the last frame is 0.05 off: {last_rmse}"
    );
    assert!(points[0][1] > points[3][1], "the error falls: {points:?}");
    h.get_by_label_contains("against the reference: RMSE 5.000e-2");

    // The radius view has a legend: the layer's name and the ends of its log scale.
    h.key_press(egui::Key::D);
    h.run_steps(2);
    assert_eq!(viewer(&h).settings.display, DisplayMode::Layer(0));
    h.get_by_label("radius (log scale; black: none)");
    // The signed difference view shows its legend; A/B shows the reference.
    h.key_press(egui::Key::D);
    h.key_press(egui::Key::D);
    h.run_steps(2);
    assert_eq!(viewer(&h).settings.display, DisplayMode::SignedDifference);
    h.get_by_label("render − reference");
    h.get_by_label_contains("+5.000e-2");
    h.key_press(egui::Key::D);
    h.run_steps(2);
    h.get_by_label("|render − reference| / (reference + 0.01)");
    h.key_press(egui::Key::B);
    h.run_steps(2);
    assert!(viewer(&h).showing_reference());
    assert!(
        h.query_by_label_contains("render − reference").is_none(),
        "no legend in A/B"
    );

    // Another size: refused, the open reference stays.
    let small = dir.path().join("small.pfm");
    let tiny = caustic::render::Image::new(4, 3);
    std::fs::write(&small, caustic::render::compare::write_pfm(&tiny)).expect("write");
    viewer_mut(&mut h).open_reference(small);
    step_until(
        &mut h,
        "the refusal",
        |v| matches!(v.status(), Some(Status::Error(e)) if e.contains("4x3")),
    );
    assert_eq!(viewer(&h).reference().map(|r| r.path.clone()), Some(path));
}

/// "Send frame to tev" reaches a listener with the frame's size; nothing listening is a
/// message in the status bar.
#[test]
fn the_viewer_sends_its_frame_to_tev() {
    use caustic::tev::{read_packets, Packet};
    let listener = std::net::TcpListener::bind("127.0.0.1:0").expect("bind");
    let address = listener.local_addr().expect("address").to_string();
    let reader = std::thread::spawn(move || read_packets(listener.accept().expect("accept").0));
    let mut h = harness(ball(), true);
    for f in fixed_frames() {
        viewer_mut(&mut h).show_frame(f);
    }
    viewer_mut(&mut h).send_to_tev(&address);
    step_until(&mut h, "the send", |v| !v.busy());
    assert!(
        matches!(viewer(&h).status(), Some(Status::Info(s)) if s.contains(&address)),
        "{:?}",
        viewer(&h).status()
    );
    let packets = reader.join().expect("listener");
    assert!(
        matches!(&packets[0], Some(Packet::Create { width: 96, height: 72, channels, .. }) if channels.len() == 5),
        "{packets:?}"
    );
    assert!(matches!(
        &packets[1],
        Some(Packet::Update {
            width: 96,
            height: 72,
            ..
        })
    ));
    viewer_mut(&mut h).send_to_tev("127.0.0.1:1");
    step_until(&mut h, "the failed send", |v| !v.busy());
    assert!(
        matches!(viewer(&h).status(), Some(Status::Error(s)) if s.contains("127.0.0.1:1")),
        "{:?}",
        viewer(&h).status()
    );
}

/// "Replace file?" and "discard the passes?" answer the keyboard: Escape cancels, Enter takes
/// the default action (replace, restart).
#[test]
fn the_replace_and_restart_questions_answer_enter_and_escape() {
    let dir = tempfile::tempdir().expect("temp dir");
    let png = dir.path().join("frame.png");
    std::fs::write(&png, b"precious").expect("write");
    let mut h = harness(ball(), false);
    step_until(&mut h, "two passes", |v| v.frame().is_some_and(|f| f.pass >= 2));
    let paused = caustic::app::params::PanelParams {
        paused: true,
        ..viewer(&h).params()
    };
    viewer_mut(&mut h).set_params(paused);
    for (key, replaced) in [(egui::Key::Escape, false), (egui::Key::Enter, true)] {
        viewer_mut(&mut h).save_to(png.clone());
        h.run_steps(3);
        assert!(
            h.query_by_label("Replace file?").is_some(),
            "no question before {key:?}"
        );
        h.key_press(key);
        h.step();
        wait_saved(&mut h);
        let bytes = std::fs::read(&png).expect("read");
        assert_eq!(bytes != b"precious", replaced, "{key:?}");
    }
    for (key, restarts) in [(egui::Key::Escape, false), (egui::Key::Enter, true)] {
        let before = sent(&h).len();
        h.key_press(egui::Key::R);
        h.run_steps(2);
        assert!(
            h.query_by_label("Discard and restart").is_some(),
            "no question before {key:?}"
        );
        h.key_press(key);
        h.run_steps(2);
        assert!(
            h.query_by_label("Discard and restart").is_none(),
            "{key:?} left it open"
        );
        let restarted = sent(&h)[before..].contains(&Command::Restart);
        assert_eq!(restarted, restarts, "{key:?}");
    }
}

/// Part `k` of `n` of a `total`-pass global-schedule render of `scene`, written to `path`.
fn write_part(scene: &Scene, k: u32, n: u32, total: u32, path: &Path) {
    use caustic::render::shard::{Part, Shard};
    let mut scene = scene.clone();
    scene.params.radius_schedule = caustic::settings::RadiusSchedule::Global;
    let shard = Shard { index: k, count: n };
    let mut ppm = Ppm::new(&scene, PpmOptions::default());
    ppm.render_only(caustic::render::shard::PassSet::Shard(shard));
    ppm.photons_per_pass = scene.params.photons_per_pass;
    for _ in 0..shard.passes_of(total) {
        ppm.run_pass(&scene, &mut |_| Control::Continue);
    }
    let sums = ppm.pass_sums().expect("global").clone();
    let settings = toml::to_string(&scene.params).expect("settings");
    let metadata = caustic::render::image_metadata(&scene, "ppm", None);
    Part::new(sums, total, metadata, settings)
        .write(path, true)
        .expect("writes");
}

#[test]
fn watching_a_folder_merges_each_new_part_and_skips_what_does_not_belong() {
    let dir = tempfile::tempdir().expect("temp dir");
    let scene = ball();
    write_part(&scene, 0, 3, 6, &dir.path().join("part_0.exr"));
    let mut h = harness(ball(), false);
    viewer_mut(&mut h).watch_folder(dir.path().to_path_buf());
    step_until(&mut h, "the first part", |v| {
        v.watching().is_some_and(|w| w.passes == 2) && v.frame().is_some_and(|f| f.pass == 2)
    });
    let w = viewer(&h).watching().expect("watching").clone();
    assert_eq!((w.total, w.parts), (6, 1));
    assert!(w.relative_error.is_some_and(|e| e > 0.0 && e.is_finite()));
    assert!(viewer(&h).paused(), "the renderer pauses while watching");
    // A new part lands: the image now holds 4 passes.
    write_part(&scene, 1, 3, 6, &dir.path().join("part_1.exr"));
    step_until(&mut h, "the second part", |v| {
        v.frame().is_some_and(|f| f.pass == 4)
    });
    // The plot shows the merge's own estimate, one point a merge, as the panel says it.
    let error = viewer(&h).watching().and_then(|w| w.relative_error);
    let plotted = viewer(&h).convergence();
    assert_eq!(plotted.points.len(), 2, "{:?}", plotted.points);
    assert_eq!(plotted.latest().map(|e| e.total()), error);
    let frame = viewer(&h).frame().expect("frame");
    assert!(
        frame.radiance.iter().any(|p| p[0] > 0.0),
        "the merged image is not black"
    );
    h.get_by_label("Render folder");
    // What does nothing while watching is not shown: the renderer, pause, restart, the
    // render settings and a render's epoch, time and restarts; saving and exposure are.
    for gone in [
        "Renderer",
        "Pause",
        "Resume",
        "Restart",
        "Photon mapping",
        "Camera",
        "Alpha",
        "Epoch",
        "Elapsed",
        "Last restart",
    ] {
        assert!(h.query_by_label(gone).is_none(), "{gone} is shown while watching");
    }
    h.get_by_label("Save frame...");
    assert!(h.query_all_by_label("Exposure").next().is_some());
    // A part of another render (another α) is skipped with a message in the status bar.
    let mut other = ball();
    other.params.alpha = 0.5;
    write_part(&other, 2, 3, 6, &dir.path().join("part_x.exr"));
    step_until(
        &mut h,
        "the foreign part's message",
        |v| matches!(v.status(), Some(Status::Error(s)) if s.contains("part_x.exr: not merged: a part of another render (ball.toml, 96x72, 6 passes") && s.contains("): render settings differ: alpha 0.7 and 0.5")),
    );
    // The folder now holds two renders: the one of most parts is shown, the other can be chosen.
    step_until(&mut h, "two renders listed", |v| {
        v.watching().is_some_and(|w| w.renders.len() == 2)
    });
    h.run_steps(2);
    h.get_by_label("Render shown").click();
    h.run_steps(2);
    h.get_by_label_contains("— 1 parts").click();
    step_until(&mut h, "the chosen render", |v| {
        v.frame().is_some_and(|f| f.pass == 2)
    });
    assert_eq!(viewer(&h).watching().map(|w| w.passes), Some(2));
    h.get_by_label("Render shown").click();
    h.run_steps(2);
    h.get_by_label("The render most parts belong to").click();
    step_until(&mut h, "the render of most parts again", |v| {
        v.frame().is_some_and(|f| f.pass == 4)
    });
    // Half a file (a copy in progress) too.
    let whole = std::fs::read(dir.path().join("part_1.exr")).expect("read");
    std::fs::write(dir.path().join("part_y.exr"), &whole[..whole.len() / 2]).expect("write");
    step_until(
        &mut h,
        "the half file's message",
        |v| matches!(v.status(), Some(Status::Error(s)) if s.contains("part_y.exr: not a readable EXR")),
    );
    assert_eq!(
        viewer(&h).watching().map(|w| w.passes),
        Some(4),
        "neither was merged"
    );
    h.get_by_label("Stop watching").click();
    h.step();
    h.step();
    assert!(viewer(&h).watching().is_none());
    assert!(!viewer(&h).paused(), "rendering again");
    h.get_by_label("Restart");
    assert!(h.query_all_by_label("Photon mapping").next().is_some());
}

#[test]
fn the_probe_never_reads_past_a_frame_that_shrank() {
    // A watched folder's 320×240 part is replaced by 32×24 parts while the pointer rests
    // over the image's lower right.
    let dir = tempfile::tempdir().expect("temp dir");
    let mut big = ball();
    (big.camera.width, big.camera.height) = (320, 240);
    big.params.photons_per_pass = 2000;
    write_part(&big, 0, 1, 1, &dir.path().join("p_big.exr"));
    let mut h = harness(ball(), true);
    viewer_mut(&mut h).watch_folder(dir.path().to_path_buf());
    step_until(&mut h, "the big part", |v| {
        v.frame().is_some_and(|f| f.width == 320)
    });
    let probed = (0..40).find_map(|k| {
        let pos = egui::pos2(300.0 + 15.0 * k as f32, 360.0 + 5.0 * k as f32);
        h.event(egui::Event::PointerMoved(pos));
        h.run_steps(2);
        viewer(&h).probe().filter(|&(x, y)| x >= 32 && y >= 24)
    });
    assert!(probed.is_some(), "the pointer never probed a pixel past 32×24");
    std::fs::remove_file(dir.path().join("p_big.exr")).expect("remove");
    let mut small = ball();
    (small.camera.width, small.camera.height) = (32, 24);
    write_part(&small, 0, 2, 2, &dir.path().join("p0.exr"));
    write_part(&small, 1, 2, 2, &dir.path().join("p1.exr"));
    step_until(&mut h, "the small parts", |v| {
        v.frame().is_some_and(|f| f.width == 32)
    });
    h.run_steps(3);
    assert!(
        h.query_by_label_contains("Hover over the image").is_some()
            || viewer(&h).probe().is_some_and(|(x, y)| x < 32 && y < 24)
    );
}

/// At the window's default size (1180×760) the side panel shows, without scrolling, what a
/// person watches: the renderer, pause and restart, exposure, the key statistics, the error
/// plot, and the first of the current renderer's settings.
#[test]
fn the_side_panel_fits_what_matters_at_the_default_size() {
    let mut h = window(egui::Vec2::new(1180.0, 760.0));
    let mut v = Viewer::with_pause(&h.ctx, Scene::builtin(), ViewerSettings::default(), true);
    for f in fixed_frames() {
        v.show_frame(f);
    }
    *h.state_mut() = Some(v);
    h.run_steps(3);
    let status_top = h.get_by_label_contains("Hover over the image").rect().top();
    for label in [
        "Photon mapping",
        "Resume",
        "Restart",
        "Pass",
        "Photons/s",
        "Elapsed",
        "Estimated error",
        "Photons per pass",
        "Alpha",
    ] {
        let rect = h
            .query_all_by_label(label)
            .map(|n| n.rect())
            .fold(egui::Rect::NOTHING, |a, b| a.union(b));
        assert!(rect.is_positive(), "{label} is not drawn");
        assert!(
            rect.bottom() <= status_top,
            "{label} is below the fold: {rect:?} (the status bar starts at {status_top})"
        );
    }
}
