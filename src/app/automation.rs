//! Scripted runs of the real window: `caustic view --screenshot FILE` saves a picture of the
//! window (egui's own screenshot) once the render has reached some passes, and
//! `caustic view --bench` measures launch-to-first-image, UI frame rate while rendering,
//! slider-to-new-epoch-image latency, and drags of a control point (on scenes with patches)
//! and of a light made through the same actions the mouse emits (each step to its new epoch's
//! first image, the frame rate meanwhile, what is on screen 100 ms after a move, and the time
//! to re-prepare the edited patch), prints them and exits.

use std::path::PathBuf;
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use super::action::Action;
use super::handle::{Handle, LightPart, LightRef, NetRef};
use super::overlay::PointRef;
use super::viewer::Viewer;
use crate::bench::convergence::reference;
use crate::bench::edit_run::{EditPlan, WarmCold, ON_SCREEN_AFTER};
use crate::bench::output::BenchOutput;
use crate::render::session::Command;
use crate::scene::Scene;

/// What to do besides showing the window.
#[derive(Clone, Debug)]
pub struct LaunchOptions {
    /// Save a screenshot of the window here, then close it.
    pub screenshot: Option<PathBuf>,
    /// Passes to wait for before the screenshot.
    pub screenshot_after_passes: u32,
    /// Replace an existing screenshot file.
    pub force: bool,
    /// Measure and print the viewer's responsiveness, then close.
    pub bench: bool,
    /// When the process started (for launch-to-first-image).
    pub launched: Instant,
    /// A reference image to compare with from the start.
    pub reference: Option<crate::render::compare::Reference>,
    /// A render folder to watch from the start (`view --watch`).
    pub watch: Option<PathBuf>,
}

impl Default for LaunchOptions {
    fn default() -> Self {
        Self {
            screenshot: None,
            screenshot_after_passes: 4,
            force: false,
            bench: false,
            launched: Instant::now(),
            reference: None,
            watch: None,
        }
    }
}

/// Longest a scripted run waits for the renderer before giving up.
const TIMEOUT: Duration = Duration::from_secs(300);
/// How long the frame rate is measured.
const FPS_WINDOW: Duration = Duration::from_secs(5);
/// Restarts measured.
const LATENCY_ROUNDS: usize = 6;
/// Steps of each drag measured.
const DRAG_ROUNDS: usize = 12;
/// The control point the first drag stage moves: patch 0, an inner point of its net.
const DRAG_POINT: PointRef = PointRef { patch: 0, index: 5 };
/// The light the second drag stage moves, by its place.
const DRAG_LIGHT: LightRef = LightRef {
    light: 0,
    part: LightPart::Place,
};

enum Stage {
    WaitFirstImage,
    FrameRate {
        start: Instant,
        frames: u32,
        worst: Duration,
        last: Instant,
        ui_secs: f64,
        paused: bool,
    },
    Latency {
        round: usize,
        sent: Option<Instant>,
    },
    Drag(Box<DragStage>),
    Screenshot {
        requested: bool,
    },
    Done,
}

impl Stage {
    /// A fresh frame-rate measurement starting `now`, with the renderer running or paused.
    fn frame_rate(now: Instant, paused: bool) -> Stage {
        Stage::FrameRate {
            start: now,
            frames: 0,
            worst: Duration::ZERO,
            last: now,
            ui_secs: 0.0,
            paused,
        }
    }
}

/// A drag stage of `--bench`: a handle (a control point, then a light) dragged step by step
/// through the same actions the mouse emits, each step timed to its new epoch's first image.
struct DragStage {
    grab: Handle,
    round: usize,
    /// When the current step was made.
    sent: Option<Instant>,
    /// Where the drag pressed (the handle's place on screen).
    press: Option<egui::Pos2>,
    /// The scene before the first step (what the drag preview's error is measured from).
    before: Option<Scene>,
    start: Instant,
    frames: u32,
    /// Each step's move to its new-epoch image (seconds).
    latencies: Vec<f64>,
}

/// What a finished drag stage measured.
struct DragFigures {
    grab: Handle,
    /// Each step's move to its new-epoch image (seconds).
    latencies: Vec<f64>,
    /// UI frames per second while dragging.
    fps: f64,
    /// The scene before the drag and the edit the whole drag made.
    edit: Option<(Scene, Command)>,
}

impl DragStage {
    fn new(grab: Handle, now: Instant) -> Self {
        DragStage {
            grab,
            round: 0,
            sent: None,
            press: None,
            before: None,
            start: now,
            frames: 0,
            latencies: Vec::new(),
        }
    }

    /// The first drag stage after `after` for `viewer`'s scene: the control point, then the
    /// light, each where the scene has it.
    fn next(viewer: &Viewer, after: Option<Handle>, now: Instant) -> Option<Self> {
        let point = (viewer.patches().len() > 0).then(|| drag_point(viewer));
        let light = (!viewer.document.lights().is_empty()).then_some(Handle::Light(DRAG_LIGHT));
        let order = [point, light];
        let from = match after {
            None => 0,
            Some(h) => order
                .iter()
                .position(|o| *o == Some(h))
                .map_or(order.len(), |k| k + 1),
        };
        order[from..]
            .iter()
            .flatten()
            .next()
            .map(|&h| DragStage::new(h, now))
    }

    /// One UI frame of the stage: `Some(Ok(figures))` when done (with no steps when the
    /// handle is behind the camera), `Some(Err)` when the renderer showed nothing for a
    /// minute.
    fn step(&mut self, viewer: &mut Viewer, now: Instant) -> Option<Result<DragFigures, String>> {
        self.frames += 1;
        let Some(at) = self.sent else {
            if self.press.is_none() {
                let point = viewer.editor.point(&viewer.document, self.grab);
                self.press = viewer.projection().and_then(|p| p.to_screen(point));
                if self.press.is_none() {
                    // Behind the camera: there is nothing on screen to grab.
                    return Some(Ok(DragFigures {
                        grab: self.grab,
                        latencies: Vec::new(),
                        fps: 0.0,
                        edit: None,
                    }));
                }
                self.before = Some(viewer.scene().clone());
            }
            let screen = self.press?;
            if self.round == 0 {
                viewer.apply(Action::BeginPointDrag {
                    grab: self.grab,
                    press: screen,
                });
            }
            let step = (self.round + 1) as f32;
            viewer.apply(Action::DragPoints {
                pointer: screen + egui::vec2(3.0, -2.0) * step,
                along_view: false,
            });
            self.sent = Some(now);
            return None;
        };
        if viewer.restart_latency_secs().is_some() && !viewer.restart_pending() {
            self.latencies.push(viewer.restart_latency_secs().unwrap_or(0.0));
            self.round += 1;
            self.sent = None;
            if self.round == DRAG_ROUNDS {
                viewer.apply(Action::EndGesture);
                let edit = self
                    .before
                    .take()
                    .and_then(|b| whole_edit(b, viewer.scene(), self.grab));
                return Some(Ok(DragFigures {
                    grab: self.grab,
                    latencies: std::mem::take(&mut self.latencies),
                    fps: self.frames as f64 / (now - self.start).as_secs_f64(),
                    edit,
                }));
            }
        } else if now - at > Duration::from_secs(60) {
            return Some(Err(format!("no image 60 s after a move of {}", name(self.grab))));
        }
        None
    }
}

/// The point handle the bench drags: [`DRAG_POINT`], or where the first patch comes from a
/// surface's own net, that net's middle point.
fn drag_point(viewer: &Viewer) -> Handle {
    match viewer.document.scene().geometry.nets().first() {
        Some(placed) if viewer.document.patch_in_net(DRAG_POINT.patch) => {
            let (nu, nv) = placed.net.size();
            Handle::Net(NetRef {
                net: 0,
                index: nu * (nv / 2) + nu / 2,
            })
        }
        _ => Handle::Control(DRAG_POINT),
    }
}

/// A dragged handle in words.
fn name(grab: Handle) -> &'static str {
    match grab {
        Handle::Control(_) => "control point",
        Handle::Net(_) => "net point",
        Handle::Light(_) => "light",
    }
}

/// The edit a whole drag of `grab` made, from `before` to `after`, as one command.
fn whole_edit(before: Scene, after: &Scene, grab: Handle) -> Option<(Scene, Command)> {
    let command = match grab {
        Handle::Control(r) => Command::MoveControlPoint {
            patch: r.patch,
            index: r.index,
            position: after.geometry.patches().get(r.patch)?.0.points[r.index],
        },
        Handle::Light(r) => Command::SetLight {
            light: r.light,
            value: *after.lights.get(r.light)?,
        },
        // A net point's drag moves many patches' points: not one command for `bench edit`.
        Handle::Net(_) => return None,
    };
    Some((before, command))
}

/// The state of a scripted run.
pub struct Automation {
    options: LaunchOptions,
    stage: Stage,
    screenshot_result: Arc<Mutex<Option<Result<PathBuf, String>>>>,
    first_image_secs: Option<f64>,
    /// Frames per second, slowest frame and mean time in the viewer's own UI code (seconds).
    fps: Option<(f64, f64, f64)>,
    /// The same with the renderer paused.
    fps_paused: Option<(f64, f64, f64)>,
    latencies: Vec<f64>,
    /// What each drag stage measured.
    drags: Vec<DragFigures>,
    /// Exit status for the process (non-zero when the run failed).
    pub failed: Option<String>,
    /// Whether the window's frames are paced while an edit waits ([`super::pacing`]).
    pub paced: bool,
}

impl Automation {
    /// A scripted run, or `None` when the options ask for none.
    pub fn new(options: LaunchOptions) -> Option<Self> {
        (options.screenshot.is_some() || options.bench).then(|| Self {
            options,
            stage: Stage::WaitFirstImage,
            screenshot_result: Arc::new(Mutex::new(None)),
            first_image_secs: None,
            fps: None,
            fps_paused: None,
            latencies: Vec::new(),
            drags: Vec::new(),
            failed: None,
            paced: false,
        })
    }

    /// Ends the run: closes the window without asking about the edits the run made.
    fn finish(&mut self, viewer: &mut Viewer, failure: Option<String>) {
        if let Some(f) = &failure {
            eprintln!("caustic view: {f}");
        }
        self.failed = failure;
        self.stage = Stage::Done;
        viewer.close_discarding_edits();
    }

    /// Advances the script; called once per UI frame after the viewer's own UI.
    pub fn step(&mut self, viewer: &mut Viewer, ctx: &egui::Context, ui_secs: f64) {
        ctx.request_repaint();
        if let Some(f) = viewer.render_failure() {
            let f = f.to_owned();
            self.finish(viewer, Some(format!("the renderer failed: {f}")));
            return;
        }
        if self.options.launched.elapsed() > TIMEOUT && !matches!(self.stage, Stage::Done) {
            self.finish(viewer, Some(format!("gave up after {} s", TIMEOUT.as_secs())));
            return;
        }
        let now = Instant::now();
        match &mut self.stage {
            Stage::WaitFirstImage => {
                if viewer.frame().is_some() {
                    self.first_image_secs = Some(self.options.launched.elapsed().as_secs_f64());
                    self.stage = if self.options.bench {
                        Stage::frame_rate(now, false)
                    } else {
                        Stage::Screenshot { requested: false }
                    };
                }
            }
            Stage::FrameRate { .. } => self.frame_rate_step(viewer, now, ui_secs),
            Stage::Latency { .. } => self.latency_step(viewer, now),
            Stage::Drag(drag) => match drag.step(viewer, now) {
                Some(Ok(figures)) => {
                    let grab = figures.grab;
                    self.drags.push(figures);
                    self.stage = DragStage::next(viewer, Some(grab), now)
                        .map_or(Stage::Screenshot { requested: false }, |d| {
                            Stage::Drag(Box::new(d))
                        });
                }
                Some(Err(e)) => self.finish(viewer, Some(e)),
                None => {}
            },
            Stage::Screenshot { .. } => self.screenshot_step(viewer, ctx),
            Stage::Done => {}
        }
    }

    /// Counts a UI frame of the frame-rate measurement; after the window, records the rate and
    /// moves on (rendering, then paused, then the latency rounds).
    fn frame_rate_step(&mut self, viewer: &mut Viewer, now: Instant, ui_secs: f64) {
        let Stage::FrameRate {
            start,
            frames,
            worst,
            last,
            ui_secs: total_ui,
            paused,
        } = &mut self.stage
        else {
            return;
        };
        *frames += 1;
        *total_ui += ui_secs;
        *worst = (*worst).max(now - *last);
        *last = now;
        if now - *start >= FPS_WINDOW {
            let secs = (now - *start).as_secs_f64();
            let figures = (
                *frames as f64 / secs,
                worst.as_secs_f64(),
                *total_ui / *frames as f64,
            );
            // Then the same with the renderer paused: what the UI costs by itself here.
            let mut p = viewer.params();
            if *paused {
                self.fps_paused = Some(figures);
                p.paused = false;
                self.stage = Stage::Latency { round: 0, sent: None };
            } else {
                self.fps = Some(figures);
                p.paused = true;
                self.stage = Stage::frame_rate(now, true);
            }
            viewer.set_params(p);
        }
    }

    /// One round of the aperture-change latency: change it, then wait for the new image.
    fn latency_step(&mut self, viewer: &mut Viewer, now: Instant) {
        let Stage::Latency { round, sent } = &mut self.stage else {
            return;
        };
        match sent {
            None => {
                // Move the aperture slider's value, exactly as a drag would.
                let mut p = viewer.params();
                let open = viewer.ranges.aperture_max * 0.02;
                p.aperture = if *round % 2 == 0 { open } else { 0.0 };
                viewer.set_params(p);
                *sent = Some(now);
            }
            Some(at) => {
                let shown = viewer.restart_latency_secs().is_some() && !viewer.restart_pending();
                if shown {
                    self.latencies.push(viewer.restart_latency_secs().unwrap_or(0.0));
                    *round += 1;
                    *sent = None;
                    if *round == LATENCY_ROUNDS {
                        self.stage = DragStage::next(viewer, None, now)
                            .map_or(Stage::Screenshot { requested: false }, |d| {
                                Stage::Drag(Box::new(d))
                            });
                    }
                } else if now - *at > Duration::from_secs(60) {
                    self.finish(viewer, Some("no image 60 s after a restart".into()));
                }
            }
        }
    }

    /// Takes the screenshot once enough passes are done, then ends the run.
    fn screenshot_step(&mut self, viewer: &mut Viewer, ctx: &egui::Context) {
        let Stage::Screenshot { requested } = &mut self.stage else {
            return;
        };
        let Some(path) = self.options.screenshot.clone() else {
            self.report(viewer);
            self.finish(viewer, None);
            return;
        };
        let passes = viewer.frame().map_or(0, |f| f.pass);
        let single_frame = viewer.frame().is_some_and(|f| !f.stats.renderer().progressive());
        if !*requested && (passes >= self.options.screenshot_after_passes || single_frame) {
            *requested = true;
            let result = self.screenshot_result.clone();
            let force = self.options.force;
            let waker = ctx.clone();
            ctx.request_screenshot(move |image| {
                let outcome = save_screenshot(&image, &path, force);
                if let Ok(mut r) = result.lock() {
                    *r = Some(outcome);
                }
                waker.request_repaint();
            });
        }
        let done = self.screenshot_result.lock().ok().and_then(|mut r| r.take());
        if let Some(outcome) = done {
            if self.options.bench {
                self.report(viewer);
            }
            match outcome {
                Ok(p) => {
                    println!("caustic view: screenshot saved to {}", p.display());
                    self.finish(viewer, None);
                }
                Err(e) => self.finish(viewer, Some(e)),
            }
        }
    }

    fn report(&self, viewer: &Viewer) {
        if !self.options.bench {
            return;
        }
        println!("caustic view --bench ({})", viewer.scene().source.display());
        if let Some(t) = self.first_image_secs {
            println!("  launch to first image:        {:.0} ms", t * 1e3);
        }
        println!(
            "  UI frames while an edit waits for its image: {}",
            match self.paced {
                true => format!(
                    "at most one per {} ms (the window is painted on the CPU)",
                    super::pacing::EDIT_FRAME_INTERVAL.as_millis()
                ),
                false => "not paced (the window is painted on a GPU)".to_owned(),
            }
        );
        if let Some((fps, worst, ui)) = self.fps {
            println!(
                "  UI frame rate while rendering: {fps:.1} fps (slowest frame {:.0} ms; the viewer's own UI code {:.1} ms per frame)",
                worst * 1e3,
                ui * 1e3
            );
        }
        if let Some((fps, worst, ui)) = self.fps_paused {
            println!(
                "  UI frame rate, renderer paused:  {fps:.1} fps (slowest frame {:.0} ms; own UI code {:.1} ms per frame)",
                worst * 1e3,
                ui * 1e3
            );
        }
        if !self.latencies.is_empty() {
            let mut l = self.latencies.clone();
            l.sort_by(f64::total_cmp);
            let ms: Vec<String> = self.latencies.iter().map(|s| format!("{:.0}", s * 1e3)).collect();
            println!(
                "  aperture change to new-epoch image: median {:.0} ms, max {:.0} ms  (each: {} ms)",
                l[l.len() / 2] * 1e3,
                l[l.len() - 1] * 1e3,
                ms.join(", ")
            );
        }
        for drag in &self.drags {
            report_drag(drag, viewer);
        }
        if let Some(f) = viewer.frame() {
            println!(
                "  last frame: epoch {}, pass {}, {} photons in {:.2} s",
                f.epoch, f.pass, f.photons, f.elapsed_secs
            );
        }
    }
}

/// Prints what a drag stage measured: its steps, the frame rate, the drag preview's error
/// and, for a control point, the time to re-prepare its patch.
fn report_drag(drag: &DragFigures, viewer: &Viewer) {
    let what = name(drag.grab);
    let mut l = drag.latencies.clone();
    l.sort_by(f64::total_cmp);
    if l.is_empty() {
        println!("  {what} drag: not measured (it is behind the camera)");
        return;
    }
    let ms: Vec<String> = drag.latencies.iter().map(|s| format!("{:.0}", s * 1e3)).collect();
    println!(
        "  {what} drag step to new-epoch image: median {:.0} ms, max {:.0} ms over {} steps  (each: {} ms)",
        l[l.len() / 2] * 1e3,
        l[l.len() - 1] * 1e3,
        l.len(),
        ms.join(", ")
    );
    println!(
        "  UI frame rate while dragging the {what}:  {:.1} fps  (each step moves once and rests: where frames are paced, a frame without input waits for the image)",
        drag.fps
    );
    match &drag.edit {
        Some((before, edit)) => match drag_preview_error(viewer.scene(), before, edit) {
            Ok(line) => println!("  {what} {line}"),
            Err(e) => println!("  {what} drag preview error: not measured ({e})"),
        },
        None if matches!(drag.grab, Handle::Net(_)) => println!(
            "  {what} drag preview error: not measured (a net point moves many patches; bench edit replays one control point)"
        ),
        None => println!("  {what} drag preview error: not measured (the drag made no edit)"),
    }
    if let Handle::Control(r) = drag.grab {
        let secs = crate::bench::time_reprepare(&viewer.scene().geometry, r.patch, r.index, 21);
        if !secs.is_empty() {
            println!(
                "  re-prepare one edited patch (subdivision + BVH update): median {:.2} ms, max {:.2} ms over {} edits",
                secs[secs.len() / 2] * 1e3,
                secs[secs.len() - 1] * 1e3,
                secs.len()
            );
        }
    }
}

/// Passes of the reference the drag preview is measured against.
const PREVIEW_REFERENCE_PASSES: u32 = 100;

/// The drag preview's figure: the RMSE of what is on screen [`ON_SCREEN_AFTER`] the whole
/// drag's `edit` of `before` (which made `edited`), against the reference of the edited scene
/// that `bench edit` uses (cached), with warm restarts (the viewer's) and with the cold
/// restart and preview the viewer had before them; medians of 3 runs each (`bench edit`'s
/// harness, [`WarmCold`]), in the viewer's kind of render session without the window.
fn drag_preview_error(edited: &Scene, before: &Scene, edit: &Command) -> Result<String, String> {
    let mut out = BenchOutput::new(false, "view");
    let what = match edit {
        Command::MoveControlPoint {
            patch,
            index,
            position,
        } => format!("control point {index} of patch {patch} moved to {position:?}"),
        Command::SetLight { light, value } => format!("light {light} set to {value:?}"),
        _ => return Err("not an edit".into()),
    };
    let reference = reference(edited, PREVIEW_REFERENCE_PASSES, None, Some(what), &mut out)
        .map_err(|e| format!("{e:#}"))?;
    let plan = EditPlan {
        edit: edit.clone(),
        before_passes: 8,
        warm: true,
        target: 0.0,
        limit: std::time::Duration::from_secs(3),
    };
    let m = WarmCold::measure(before, &plan, 3, &reference, |_, _, _| {})?.medians();
    let ([warm, cold], [(wt, we), (ct, ce)]) = (m.on_screen, m.first);
    Ok(format!(
        "drag preview, against a {PREVIEW_REFERENCE_PASSES}-pass reference of the edited scene (medians of 3 moves): the new epoch's first image has RMSE {we:.3e} at {:.0} ms with warm restarts, {ce:.3e} at {:.0} ms with the cold restart's ¼-resolution preview ({:.2}x); on screen {} ms after the move: {warm:.3e} and {cold:.3e} ({:.2}x)",
        wt * 1e3,
        ct * 1e3,
        we / ce,
        ON_SCREEN_AFTER.as_millis(),
        warm / cold
    ))
}

/// Writes a window screenshot as PNG (temp name + rename; refuses to replace unless `force`).
fn save_screenshot(image: &egui::ColorImage, path: &std::path::Path, force: bool) -> Result<PathBuf, String> {
    let [w, h] = image.size;
    let bytes: Vec<u8> = image
        .pixels
        .iter()
        .flat_map(|c| c.to_srgba_unmultiplied())
        .collect();
    let rgba = image::RgbaImage::from_raw(w as u32, h as u32, bytes)
        .ok_or_else(|| "screenshot has an inconsistent size".to_owned())?;
    crate::files::write_atomically(path, force, |tmp| {
        rgba.save_with_format(tmp, image::ImageFormat::Png)
            .map_err(|e| e.to_string())
    })
    .map_err(|e| match e {
        crate::files::WriteError::Exists(p) => format!("{} exists (pass --force to replace it)", p.display()),
        other => other.to_string(),
    })?;
    Ok(path.to_path_buf())
}
