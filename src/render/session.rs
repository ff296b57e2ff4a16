//! The render session: photon-mapping passes (or one ray-traced frame) on a
//! thread of their own, steered by [`Command`]s over an unbounded channel and reporting a
//! [`Frame`] after each pass over a `bounded(1)` channel with `try_send` — the renderer never
//! waits for whoever watches; a frame nobody took is simply replaced by a newer one.
//!
//! The render parameters arrive whole ([`Command::SetParams`]). Commands are looked at between
//! photon batches, so a slider takes effect within one batch. α and photons per pass change
//! the coming update/pass without discarding anything; every other parameter, the camera and
//! the geometry restart accumulation under a new `epoch`; pause and resume lose nothing (a
//! paused pass continues where it stopped, so the image is the one an uninterrupted run gives).
//!
//! The rules live in [`SessionState`], free of threads (`apply(Command) -> Effect`, `next`);
//! the thread's loop only carries out what it says. The command line's `render` and `bench`
//! run on this session too (headless, [`SessionOptions::every_frame`]).
//!
//! A panic on the render thread is caught and kept as [`RenderSession::failure`], so a viewer
//! can show it and stay up.

use std::panic::AssertUnwindSafe;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use crossbeam_channel::{bounded, unbounded, Receiver, Sender, TryRecvError};
use glam::DVec3;

use super::ppm::{Control, Interrupt, PassOutcome, Ppm, PpmOptions, PpmStats};
use super::whitted::{render_whitted_until, WhittedStats};
use crate::geometry::BezierPatch;
use crate::scene::{Camera, RendererKind, Scene};
use crate::settings::limits;
use crate::settings::RenderParams;

/// What the UI (or a test) asks of the renderer.
#[derive(Clone, Debug, PartialEq)]
pub enum Command {
    /// Every render setting at once. α and photons per pass apply from the next batch and
    /// pass; any other change restarts ([`RenderParams::restarts_from`]). Ignored when
    /// [`RenderParams::validate`] rejects it.
    SetParams(RenderParams),
    /// A new camera (pose, lens, image size); restarts.
    SetCamera(Camera),
    /// Moves control point `index` of patch `patch`; restarts.
    MoveControlPoint {
        /// Patch index in the scene geometry.
        patch: usize,
        /// Control point `4i + j`.
        index: usize,
        /// New position.
        position: DVec3,
    },
    /// Stop between batches, keeping everything.
    Pause,
    /// Continue after [`Command::Pause`].
    Resume,
    /// Discard the accumulation and start again (new epoch).
    Restart,
    /// End the session's thread.
    Shutdown,
}

impl Command {
    /// Whether the command discards the accumulation (starts a new epoch) when valid, for a
    /// session whose parameters are `current`.
    pub fn restarts(&self, current: &RenderParams) -> bool {
        match self {
            Command::SetParams(p) => p.restarts_from(current),
            Command::SetCamera(_) | Command::MoveControlPoint { .. } | Command::Restart => true,
            Command::Pause | Command::Resume | Command::Shutdown => false,
        }
    }

    /// Whether the render thread should drop the pass in progress at once for it: restarts
    /// and shutdown do; α, photons and pause wait for the next batch.
    fn interrupts(&self, current: &RenderParams) -> bool {
        self.restarts(current) || matches!(self, Command::Shutdown)
    }
}

/// What a frame's renderer measured.
#[derive(Clone, Debug, PartialEq)]
pub enum FrameStats {
    /// Progressive photon mapping's statistics of the epoch so far.
    PhotonMapping(PpmStats),
    /// The ray tracer's statistics of its frame.
    RayTracing(WhittedStats),
}

impl FrameStats {
    /// Seconds the renderer spent on the frame (all passes of the epoch for photon mapping).
    pub fn elapsed_secs(&self) -> f64 {
        match self {
            FrameStats::PhotonMapping(s) => s.elapsed_secs,
            FrameStats::RayTracing(s) => s.elapsed_secs,
        }
    }

    /// Photon mapping's statistics, if the frame was photon mapped.
    pub fn photon_mapping(&self) -> Option<&PpmStats> {
        match self {
            FrameStats::PhotonMapping(s) => Some(s),
            FrameStats::RayTracing(_) => None,
        }
    }

    /// Which renderer made the frame.
    pub fn renderer(&self) -> RendererKind {
        match self {
            FrameStats::PhotonMapping(_) => RendererKind::Ppm,
            FrameStats::RayTracing(_) => RendererKind::Whitted,
        }
    }
}

/// One finished pass, as the viewer needs it.
#[derive(Clone, Debug)]
pub struct Frame {
    /// Increases whenever accumulated statistics are discarded.
    pub epoch: u64,
    /// Passes completed in this epoch (1 for a ray-traced frame).
    pub pass: u32,
    /// Photons emitted in this epoch.
    pub photons: u64,
    /// Seconds since this epoch started.
    pub elapsed_secs: f64,
    /// What the renderer measured (and so which renderer made it).
    pub stats: FrameStats,
    /// Image width.
    pub width: u32,
    /// Image height.
    pub height: u32,
    /// Linear RGB radiance, `width × height` pixels, rows from the top.
    pub radiance: Arc<[[f32; 3]]>,
    /// Search radius per pixel (largest of the pixel's slots), for the viewer's probe.
    pub radius: Arc<[f32]>,
    /// Accumulated photon count `N` per pixel (summed over the pixel's slots).
    pub gathered: Arc<[f32]>,
    /// A quick low-resolution preview of a new epoch (pass 0), enlarged to full size.
    pub preview: bool,
}

/// How a session renders, beyond the scene's own settings.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct SessionOptions {
    /// Photon-mapping options (index, direct light, batch size).
    pub ppm: PpmOptions,
    /// Photons in the first pass of every epoch, doubling pass by pass up to the photons per
    /// pass (`None`: full passes from the start). A viewer uses it to show a new epoch's first
    /// image sooner; PPM weighs every photon alike, so only the pass boundaries move.
    pub first_pass_photons: Option<u64>,
    /// Start paused: nothing is rendered until [`Command::Resume`].
    pub start_paused: bool,
    /// When set, every epoch of photon mapping begins with a preview frame rendered at
    /// 1/`n` of the resolution (one pass of [`SessionOptions::first_pass_photons`] or 16,384
    /// photons), so a changed setting shows within a fraction of a full pass.
    pub preview_divisor: Option<u32>,
    /// End the session after this many completed passes of an epoch (a ray-traced frame
    /// counts as one); `None`: render until shut down.
    pub max_passes: Option<u32>,
    /// End the session once an epoch has run this long (checked before each pass).
    pub time_limit: Option<Duration>,
    /// Deliver every frame, waiting for the receiver to take it (a headless consumer that
    /// needs each pass); by default a frame not yet taken is replaced and the renderer never
    /// waits.
    pub every_frame: bool,
    /// Render in a pool of this many threads (`None`: rayon's global pool).
    pub threads: Option<usize>,
}

/// A render running on its own thread.
pub struct RenderSession {
    commands: Sender<Command>,
    /// The newest valid parameters sent, to tell which commands interrupt the pass.
    params: Mutex<RenderParams>,
    /// Set by [`RenderSession::send`] for commands that interrupt the pass in progress.
    interrupt: Arc<AtomicBool>,
    frames: Receiver<Frame>,
    failure: Arc<Mutex<Option<String>>>,
    thread: Option<JoinHandle<()>>,
}

/// Called after each frame is offered (the viewer passes `ctx.request_repaint`).
pub type Waker = Box<dyn Fn() + Send + Sync>;

impl RenderSession {
    /// Starts rendering `scene` on a new thread (named `caustic-render`), in the global rayon
    /// pool, with full photon passes from the start.
    pub fn start(scene: Scene, options: PpmOptions, waker: Option<Waker>) -> Self {
        Self::start_with(
            scene,
            SessionOptions {
                ppm: options,
                ..Default::default()
            },
            waker,
        )
    }

    /// Starts rendering `scene` with session options (see [`SessionOptions`]).
    pub fn start_with(scene: Scene, options: SessionOptions, waker: Option<Waker>) -> Self {
        let (commands, command_rx) = unbounded();
        let (frame_tx, frames) = bounded(1);
        // The render thread holds a receiver too, to replace a frame nobody has taken.
        let stale = frames.clone();
        let failure = Arc::new(Mutex::new(None));
        let failed = failure.clone();
        let interrupt = Arc::new(AtomicBool::new(false));
        let interrupt_flag = interrupt.clone();
        let params = Mutex::new(scene.params.clone());
        let thread = std::thread::Builder::new()
            .name("caustic-render".into())
            .spawn(move || {
                let outcome = std::panic::catch_unwind(AssertUnwindSafe(|| {
                    let render = || {
                        let channel = (frame_tx, stale);
                        run(scene, options, command_rx, (&channel, &waker), interrupt_flag)
                    };
                    match options
                        .threads
                        .map(|n| rayon::ThreadPoolBuilder::new().num_threads(n).build())
                    {
                        Some(Ok(pool)) => pool.install(render),
                        Some(Err(e)) => panic!("cannot start {:?} render threads: {e}", options.threads),
                        None => render(),
                    }
                }));
                if let Err(payload) = outcome {
                    let message = payload
                        .downcast_ref::<&str>()
                        .map(|s| s.to_string())
                        .or_else(|| payload.downcast_ref::<String>().cloned())
                        .unwrap_or_else(|| "unknown panic".to_owned());
                    if let Ok(mut f) = failed.lock() {
                        *f = Some(message);
                    }
                    if let Some(w) = &waker {
                        w();
                    }
                }
            })
            .expect("spawn the render thread");
        Self {
            commands,
            params,
            interrupt,
            frames,
            failure,
            thread: Some(thread),
        }
    }

    /// Sends a command (ignored once the thread has ended). Restarts and shutdown also
    /// abandon the pass in progress, even mid-way through an eye pass.
    pub fn send(&self, command: Command) {
        let interrupts = match self.params.lock() {
            Ok(mut params) => {
                let interrupts = command.interrupts(&params);
                if let Command::SetParams(p) = &command {
                    if p.validate().is_ok() {
                        *params = p.clone();
                    }
                }
                interrupts
            }
            Err(_) => true,
        };
        let _ = self.commands.send(command);
        if interrupts {
            self.interrupt.store(true, Ordering::Release);
        }
    }

    /// The frames channel: at most one waiting frame, the newest.
    pub fn frames(&self) -> &Receiver<Frame> {
        &self.frames
    }

    /// The message of the panic that ended the render thread, if it did.
    pub fn failure(&self) -> Option<String> {
        self.failure.lock().ok().and_then(|f| f.clone())
    }

    /// Asks the thread to stop and waits for it.
    pub fn shutdown(mut self) {
        self.stop();
    }

    fn stop(&mut self) {
        let _ = self.commands.send(Command::Shutdown);
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
    }
}

impl Drop for RenderSession {
    fn drop(&mut self) {
        self.stop();
    }
}

/// Whether a command's values are valid for a scene with `patches` patches.
fn valid(command: &Command, patches: usize) -> bool {
    match command {
        Command::SetParams(p) => p.validate().is_ok(),
        Command::SetCamera(c) => {
            limits::aperture(c.aperture).is_ok()
                && limits::focal_distance(c.focal_distance).is_ok()
                && c.position.is_finite()
                && c.forward.is_finite()
        }
        Command::MoveControlPoint {
            patch,
            index,
            position,
        } => *patch < patches && *index < 16 && position.is_finite(),
        Command::Pause | Command::Resume | Command::Restart | Command::Shutdown => true,
    }
}

/// Applies the camera and control points of the commands that restart the accumulation to
/// the scene, in order. Control-point moves are gathered so that each edited patch is
/// re-prepared once, however many steps of a drag arrived together (the latest position of
/// each point wins).
fn apply_to_scene(scene: &mut Scene, commands: Vec<Command>) {
    let mut edited: std::collections::BTreeMap<usize, BezierPatch> = Default::default();
    for command in commands {
        match command {
            Command::SetCamera(c) => scene.camera = c,
            Command::MoveControlPoint {
                patch,
                index,
                position,
            } => {
                let current = scene.geometry.patches()[patch].0;
                edited.entry(patch).or_insert(current).points[index] = position;
            }
            _ => {}
        }
    }
    if !edited.is_empty() {
        let edits: Vec<(usize, BezierPatch)> = edited.into_iter().collect();
        scene.geometry.update_patches(&edits);
    }
}

impl Frame {
    /// The state of a photon-mapping render as a frame of `epoch`, `elapsed_secs` into it.
    pub fn from_ppm(ppm: &Ppm, epoch: u64, elapsed_secs: f64) -> Frame {
        let (width, height) = ppm.size();
        let stats = ppm.stats().clone();
        let (radius, gathered) = pixel_statistics(ppm);
        Frame {
            epoch,
            pass: stats.passes,
            photons: stats.photons,
            elapsed_secs,
            stats: FrameStats::PhotonMapping(stats),
            width,
            height,
            radiance: ppm.radiance().into(),
            radius,
            gathered,
            preview: false,
        }
    }
}

/// Per-pixel search radius (largest of the pixel's slots) and photon count (sum of them).
fn pixel_statistics(ppm: &Ppm) -> (Arc<[f32]>, Arc<[f32]>) {
    let (w, h) = ppm.size();
    let mut radius = vec![0.0f32; w as usize * h as usize];
    let mut gathered = vec![0.0f32; w as usize * h as usize];
    for s in ppm.slots() {
        let px = &mut radius[s.pixel as usize];
        *px = px.max(s.primary.radius2.sqrt() as f32);
        gathered[s.pixel as usize] += (s.primary.n + s.indirect.n) as f32;
    }
    (radius.into(), gathered.into())
}

/// Where frames go: the channel (with a receiver to take back a frame nobody took) and the
/// waker.
type Output<'a> = (&'a (Sender<Frame>, Receiver<Frame>), &'a Option<Waker>);

/// Offers a frame: without waiting, replacing a frame the viewer has not taken yet, or (with
/// [`SessionOptions::every_frame`]) waiting until the receiver has room.
fn offer(frame: Frame, ((frames, stale), waker): Output, every_frame: bool) {
    if every_frame {
        let _ = frames.send(frame);
    } else if let Err(crossbeam_channel::TrySendError::Full(frame)) = frames.try_send(frame) {
        let _ = stale.try_recv();
        let _ = frames.try_send(frame);
    }
    if let Some(w) = waker {
        w();
    }
}

/// Nearest-neighbour enlargement of a `(sw, sh)` image to `(w, h)`.
fn enlarge<T: Copy>(src: &[T], (sw, sh): (u32, u32), (w, h): (u32, u32)) -> Arc<[T]> {
    (0..h)
        .flat_map(|y| {
            let sy = (y as u64 * sh as u64 / h as u64) as usize;
            (0..w).map(move |x| src[sy * sw as usize + (x as u64 * sw as u64 / w as u64) as usize])
        })
        .collect()
}

/// One photon-mapping pass at 1/`divisor` of the resolution, enlarged: the first picture of a
/// new epoch. `None` when interrupted.
fn preview(scene: &mut Scene, options: &SessionOptions, divisor: u32, step: Step) -> Option<Frame> {
    let Step {
        epoch,
        epoch_start,
        interrupted,
    } = step;
    let (w, h) = (scene.camera.width, scene.camera.height);
    let small = ((w / divisor.max(1)).max(1), (h / divisor.max(1)).max(1));
    (scene.camera.width, scene.camera.height) = small;
    let mut ppm = Ppm::new(scene, options.ppm);
    ppm.photons_per_pass = options
        .first_pass_photons
        .unwrap_or(16_384)
        .min(scene.params.photons_per_pass);
    ppm.set_interrupt(Some(interrupted.clone()));
    let outcome = ppm.run_pass(scene, &mut |_| Control::Continue);
    (scene.camera.width, scene.camera.height) = (w, h);
    if outcome != PassOutcome::Completed {
        return None;
    }
    let frame = Frame::from_ppm(&ppm, epoch, epoch_start.elapsed().as_secs_f64());
    Some(Frame {
        pass: 0,
        photons: 0,
        width: w,
        height: h,
        radiance: enlarge(&frame.radiance, small, (w, h)),
        radius: enlarge(&frame.radius, small, (w, h)),
        gathered: enlarge(&frame.gathered, small, (w, h)),
        preview: true,
        ..frame
    })
}

/// What the session does next ([`SessionState::next`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Next {
    /// Nothing until a command arrives (paused, or the ray-traced frame is done).
    Wait,
    /// Apply the restarting commands gathered and open a new epoch.
    Restart,
    /// A low-resolution preview of the new epoch.
    Preview,
    /// A photon-mapping pass.
    Pass,
    /// The ray-traced frame of this epoch.
    Trace,
    /// End the session.
    Stop,
}

/// The session's rules, free of threads and channels: which commands apply at once, which
/// gather into a restart, when to wait, and what to render next.
#[derive(Clone, Debug)]
pub struct SessionState {
    options: SessionOptions,
    /// Epochs begun (each restart opens one).
    pub epoch: u64,
    /// Paused by [`Command::Pause`].
    pub paused: bool,
    /// The newest valid parameters: α and photons per pass for the coming batches and passes,
    /// the rest for the next epoch.
    pub params: RenderParams,
    patches: usize,
    /// Passes completed in this epoch (the ray-traced frame counts as one).
    pub passes: u32,
    preview_due: bool,
    /// Camera and control-point commands for the next epoch.
    pending: Vec<Command>,
    /// A restart is waiting.
    restart_due: bool,
    shutdown: bool,
}

/// What [`SessionState::apply`] made of a command.
#[derive(Clone, Debug, PartialEq)]
pub enum Effect {
    /// Out of range: ignored (the UI validates before sending).
    Ignored,
    /// Applied at once (α, photons per pass, pause, resume), nothing discarded.
    Applied,
    /// Gathered: the accumulation restarts under a new epoch.
    Restarts,
    /// The session ends.
    Shutdown,
}

impl SessionState {
    /// The state at the start of a session on `scene`.
    pub fn new(scene: &Scene, options: SessionOptions) -> Self {
        Self {
            options,
            epoch: 0,
            paused: options.start_paused,
            params: scene.params.clone(),
            patches: scene.geometry.patches().len(),
            passes: 0,
            preview_due: options.preview_divisor.is_some(),
            pending: Vec::new(),
            restart_due: false,
            shutdown: false,
        }
    }

    /// Takes a command.
    pub fn apply(&mut self, command: Command) -> Effect {
        if !valid(&command, self.patches) {
            return Effect::Ignored;
        }
        let restarts = command.restarts(&self.params);
        match command {
            // The restart takes the newest set: parameters need no replaying.
            Command::SetParams(p) => self.params = p,
            Command::Pause => self.paused = true,
            Command::Resume => self.paused = false,
            Command::Shutdown => {
                self.shutdown = true;
                return Effect::Shutdown;
            }
            Command::SetCamera(_) | Command::MoveControlPoint { .. } | Command::Restart => {
                self.pending.push(command)
            }
        }
        if restarts {
            self.restart_due = true;
            Effect::Restarts
        } else {
            Effect::Applied
        }
    }

    /// Whether the pass in progress must be dropped (a restart or the end waits).
    pub fn must_abort(&self) -> bool {
        self.shutdown || self.restart_due
    }

    /// Whether the session's limits are reached.
    fn finished(&self, epoch_secs: Duration) -> bool {
        self.options.max_passes.is_some_and(|n| self.passes >= n)
            || (self.params.renderer == RendererKind::Ppm
                && self.options.time_limit.is_some_and(|t| epoch_secs >= t))
    }

    /// What to do next, `epoch_secs` into the epoch.
    pub fn next(&self, epoch_secs: Duration) -> Next {
        if self.shutdown || self.finished(epoch_secs) {
            Next::Stop
        } else if self.restart_due {
            Next::Restart
        } else if self.waiting() {
            Next::Wait
        } else if self.params.renderer == RendererKind::Whitted {
            Next::Trace
        } else if self.preview_due {
            Next::Preview
        } else {
            Next::Pass
        }
    }

    /// Whether to wait for a command before going on (also between photon batches).
    fn idle(&self) -> bool {
        let limit_reached = self.options.max_passes.is_some_and(|n| self.passes >= n);
        !self.must_abort() && !limit_reached && self.waiting()
    }

    /// Paused, or the ray-traced frame of this epoch is done.
    fn waiting(&self) -> bool {
        self.paused || (self.params.renderer == RendererKind::Whitted && self.passes > 0)
    }

    /// Opens a new epoch: the gathered commands are applied to `scene`.
    pub fn restart(&mut self, scene: &mut Scene) {
        apply_to_scene(scene, std::mem::take(&mut self.pending));
        self.restart_due = false;
        scene.params = self.params.clone();
        self.epoch += 1;
        self.passes = 0;
        self.preview_due = self.options.preview_divisor.is_some();
    }

    /// Photons of the pass after `completed` passes of a render whose full pass is `full`
    /// photons ([`RenderParams::pass_photons`]): the ramp from
    /// [`SessionOptions::first_pass_photons`] doubling up to `full`.
    pub fn pass_photons(&self, completed: u32, full: u64) -> u64 {
        match self.options.first_pass_photons {
            Some(first) => full.min(first.saturating_mul(1 << completed.min(40))),
            None => full,
        }
    }
}

/// Applies the commands waiting on the channel; while the state is idle, waits for more.
/// Returns `false` when every sender is gone.
fn drain(state: &mut SessionState, commands: &Receiver<Command>) -> bool {
    loop {
        let next = if state.idle() {
            commands.recv().map_err(|_| TryRecvError::Disconnected)
        } else {
            commands.try_recv()
        };
        match next {
            Ok(command) => {
                state.apply(command);
            }
            Err(TryRecvError::Empty) => return true,
            Err(TryRecvError::Disconnected) => {
                state.shutdown = true;
                return false;
            }
        }
    }
}

/// The ray-traced frame of an epoch (`None` when a command interrupted it).
fn trace(scene: &Scene, epoch: u64, epoch_start: Instant, interrupted: &Interrupt) -> Option<Frame> {
    let (image, stats) = render_whitted_until(scene, &|_| {}, &|| interrupted())?;
    let pixels = image.pixels.len();
    Some(Frame {
        epoch,
        pass: 1,
        photons: 0,
        elapsed_secs: epoch_start.elapsed().as_secs_f64(),
        stats: FrameStats::RayTracing(stats),
        width: image.width,
        height: image.height,
        radiance: image.pixels.into(),
        radius: vec![0.0; pixels].into(),
        gathered: vec![0.0; pixels].into(),
        preview: false,
    })
}

/// The renderer of an epoch, made from the scene's parameters when the epoch opens.
enum Integrator {
    /// Progressive photon mapping: a pass at a time.
    PhotonMapping(Box<Ppm>),
    /// The Whitted ray tracer: one frame per epoch.
    RayTracer,
}

/// What a pass or frame needs from the session's loop.
struct Step<'a> {
    epoch: u64,
    epoch_start: Instant,
    interrupted: &'a Interrupt,
}

impl Integrator {
    /// The integrator `scene.params.renderer` names.
    fn new(scene: &Scene, options: PpmOptions, interrupted: &Interrupt) -> Self {
        match scene.params.renderer {
            RendererKind::Ppm => {
                let mut ppm = Ppm::new(scene, options);
                ppm.set_interrupt(Some(interrupted.clone()));
                Integrator::PhotonMapping(Box::new(ppm))
            }
            RendererKind::Whitted => Integrator::RayTracer,
        }
    }

    /// Renders the next pass (or the frame) with the state's α and photon ramp; `control` is
    /// asked between photon batches. `None` when the pass was abandoned; the state's pass count
    /// is updated otherwise.
    fn render(
        &mut self,
        scene: &Scene,
        state: &mut SessionState,
        step: Step,
        control: &mut dyn FnMut(&mut SessionState) -> Control,
    ) -> Option<Frame> {
        match self {
            Integrator::RayTracer => {
                let frame = trace(scene, step.epoch, step.epoch_start, step.interrupted)?;
                state.passes = 1;
                Some(frame)
            }
            Integrator::PhotonMapping(ppm) => {
                ppm.alpha = state.params.alpha;
                let (w, h) = ppm.size();
                let full = state
                    .params
                    .pass_photons(ppm.is_stochastic(), w as u64 * h as u64);
                ppm.photons_per_pass = state.pass_photons(ppm.stats().passes, full);
                let mut between_batches = |alpha: &mut f64| {
                    let c = control(state);
                    *alpha = state.params.alpha;
                    c
                };
                if ppm.run_pass(scene, &mut between_batches) != PassOutcome::Completed {
                    return None;
                }
                state.passes = ppm.stats().passes;
                Some(Frame::from_ppm(
                    ppm,
                    step.epoch,
                    step.epoch_start.elapsed().as_secs_f64(),
                ))
            }
        }
    }
}

/// The render thread: a loop over [`SessionState::next`], carried out by the epoch's
/// [`Integrator`].
fn run(
    mut scene: Scene,
    options: SessionOptions,
    commands: Receiver<Command>,
    output: Output,
    interrupt: Arc<AtomicBool>,
) {
    let interrupted: Interrupt = {
        let flag = interrupt.clone();
        Arc::new(move || flag.load(Ordering::Acquire))
    };
    let mut state = SessionState::new(&scene, options);
    let mut integrator = Integrator::new(&scene, options.ppm, &interrupted);
    let mut epoch_start = Instant::now();
    loop {
        // Whatever interrupted a pass is among the commands drained here.
        interrupt.store(false, Ordering::Release);
        if !drain(&mut state, &commands) {
            return;
        }
        let step = Step {
            epoch: state.epoch,
            epoch_start,
            interrupted: &interrupted,
        };
        let frame = match state.next(epoch_start.elapsed()) {
            Next::Stop => return,
            Next::Wait => None,
            Next::Restart => {
                state.restart(&mut scene);
                integrator = Integrator::new(&scene, options.ppm, &interrupted);
                epoch_start = Instant::now();
                None
            }
            Next::Preview => {
                state.preview_due = false;
                let divisor = options.preview_divisor.unwrap_or(4);
                preview(&mut scene, &options, divisor, step)
            }
            Next::Pass | Next::Trace => {
                // Between batches: commands apply; a restart or the end drops the pass.
                let mut control = |state: &mut SessionState| {
                    interrupt.store(false, Ordering::Release);
                    drain(state, &commands);
                    if state.must_abort() {
                        Control::Abort
                    } else {
                        Control::Continue
                    }
                };
                integrator.render(&scene, &mut state, step, &mut control)
            }
        };
        if let Some(frame) = frame {
            offer(frame, output, options.every_frame);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn state() -> SessionState {
        let mut scene = Scene::builtin();
        scene.params.renderer = RendererKind::Ppm;
        SessionState::new(
            &scene,
            SessionOptions {
                preview_divisor: Some(4),
                first_pass_photons: Some(1000),
                ..Default::default()
            },
        )
    }

    #[test]
    fn commands_apply_gather_or_are_ignored_by_the_rules() {
        let mut s = state();
        let now = Duration::ZERO;
        assert_eq!(s.next(now), Next::Preview);
        let with_alpha = |s: &SessionState, alpha| {
            Command::SetParams(RenderParams {
                alpha,
                ..s.params.clone()
            })
        };
        assert_eq!(s.apply(with_alpha(&s, 0.5)), Effect::Applied);
        assert_eq!(s.apply(with_alpha(&s, 1.5)), Effect::Ignored);
        assert_eq!(s.params.alpha, 0.5);
        assert_eq!(s.apply(Command::Pause), Effect::Applied);
        assert_eq!(s.next(now), Next::Wait);
        assert!(s.idle());
        let mut lens = Scene::builtin().camera;
        lens.aperture = 0.1;
        let mut bad_lens = lens.clone();
        bad_lens.focal_distance = f64::NAN;
        assert_eq!(s.apply(Command::SetCamera(bad_lens)), Effect::Ignored);
        assert_eq!(s.apply(Command::SetCamera(lens)), Effect::Restarts);
        assert!(s.must_abort() && !s.idle());
        assert_eq!(s.next(now), Next::Restart);
        let mut scene = Scene::builtin();
        scene.params.renderer = RendererKind::Ppm;
        s.restart(&mut scene);
        assert_eq!(
            (s.epoch, scene.camera.aperture, scene.params.alpha),
            (1, 0.1, 0.5)
        );
        assert_eq!(s.next(now), Next::Wait, "still paused");
        s.apply(Command::Resume);
        assert_eq!(s.next(now), Next::Preview);
        assert_eq!(
            s.apply(Command::MoveControlPoint {
                patch: 99,
                index: 0,
                position: DVec3::ZERO
            }),
            Effect::Ignored
        );
        assert_eq!(s.apply(Command::Shutdown), Effect::Shutdown);
        assert_eq!(s.next(now), Next::Stop);
    }

    #[test]
    fn passes_ramp_up_and_limits_end_the_session() {
        let mut s = state();
        assert_eq!(
            [0, 1, 2, 3].map(|k| s.pass_photons(k, 5000)),
            [1000, 2000, 4000, 5000]
        );
        s.options.max_passes = Some(3);
        s.preview_due = false;
        s.passes = 2;
        assert_eq!(s.next(Duration::ZERO), Next::Pass);
        s.passes = 3;
        assert_eq!(s.next(Duration::ZERO), Next::Stop);
        s.options.max_passes = None;
        s.options.time_limit = Some(Duration::from_secs(2));
        assert_eq!(s.next(Duration::from_secs(1)), Next::Pass);
        assert_eq!(s.next(Duration::from_secs(2)), Next::Stop);
        // The ray tracer makes one frame, then waits.
        s.options.time_limit = None;
        let whitted = RenderParams {
            renderer: RendererKind::Whitted,
            ..s.params.clone()
        };
        assert_eq!(s.apply(Command::SetParams(whitted)), Effect::Restarts);
        s.restart(&mut Scene::builtin());
        assert_eq!(s.next(Duration::ZERO), Next::Trace);
        s.passes = 1;
        assert_eq!(s.next(Duration::ZERO), Next::Wait);
        assert!(s.idle());
        // ...unless that frame was all it was asked for: then it ends instead of waiting.
        s.options.max_passes = Some(1);
        assert!(!s.idle());
        assert_eq!(s.next(Duration::ZERO), Next::Stop);
    }
}
