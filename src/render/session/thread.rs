//! The render thread and the handle to it ([`RenderSession`]): a loop over
//! [`SessionState::next`], carried out by the epoch's integrator, with commands in over an
//! unbounded channel and frames out over a `bounded(1)` one that never blocks the renderer.

use std::panic::AssertUnwindSafe;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::thread::JoinHandle;
use std::time::Instant;

use crossbeam_channel::{bounded, unbounded, Receiver, Sender, TryRecvError};

use super::command::Command;
use super::integrator::{pass, plan, preview, Step};
use super::state::{Next, SessionOptions, SessionState};
use crate::render::control::{Control, Interrupt};
use crate::render::frame::Frame;
use crate::render::integrator::{make, Setup};
use crate::scene::Scene;
use crate::settings::RenderParams;

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
    /// pool, with the default options: full passes from the start, no limits.
    pub fn start(scene: Scene, waker: Option<Waker>) -> Self {
        Self::start_with(scene, SessionOptions::default(), waker)
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
                    if options.background {
                        lower_priority();
                    }
                    let cores = || std::thread::available_parallelism().map_or(1, |n| n.get());
                    let pool_size = match (options.threads, options.background) {
                        (Some(n), _) => Some(n),
                        (None, true) => Some(cores()),
                        (None, false) => None,
                    };
                    let background = options.background;
                    match pool_size.map(|n| {
                        rayon::ThreadPoolBuilder::new()
                            .num_threads(n)
                            .start_handler(move |_| {
                                if background {
                                    lower_priority();
                                }
                            })
                            .build()
                    }) {
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

/// The render thread: a loop over [`SessionState::next`], carried out by the epoch's
/// integrator.
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
    let setup = Setup {
        batch: options.batch,
        warm_restarts: options.warm_restarts,
        interrupt: Some(interrupted),
    };
    let mut state = SessionState::new(&scene, options);
    let mut integrator = make(scene.params.renderer, &scene, &setup);
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
        };
        let plan = plan(&state, &options);
        let frame = match state.next(epoch_start.elapsed()) {
            Next::Stop => return,
            Next::Wait => None,
            Next::Restart => {
                let warm = state.restart(&mut scene);
                integrator = if warm {
                    integrator.warm_restart(&scene, &setup)
                } else {
                    drop(integrator);
                    make(scene.params.renderer, &scene, &setup)
                };
                epoch_start = Instant::now();
                None
            }
            Next::Preview => {
                state.preview_due = false;
                let divisor = options.preview_divisor.unwrap_or(4);
                preview(&mut scene, &setup, &plan, divisor, step)
            }
            Next::Pass | Next::Trace => {
                // Between batches: commands apply (α among them); a restart or the end
                // drops the pass.
                let mut control = |live: &mut crate::settings::RenderParams| {
                    interrupt.store(false, Ordering::Release);
                    drain(&mut state, &commands);
                    live.clone_from(&state.params);
                    if state.must_abort() {
                        Control::Abort
                    } else {
                        Control::Continue
                    }
                };
                let frame = pass(integrator.as_mut(), &scene, &plan, step, &mut control);
                if frame.is_some() {
                    state.passes = integrator.passes();
                }
                frame
            }
        };
        if let Some(frame) = frame {
            offer(frame, output, options.every_frame);
        }
    }
}

/// Lowers the calling thread's scheduling priority (a render thread of the viewer): niceness
/// 5 on Linux (the crate maps 35 of 0..=99 to it), a weight a third of the UI thread's, so
/// the UI keeps its frame rate while a change's first image still comes soon; the lowest
/// priority (19) starved the render of the cores the UI's software rasteriser takes. Where
/// the system refuses, the thread keeps its priority: the image is the same either way.
fn lower_priority() {
    if let Ok(value) = thread_priority::ThreadPriorityValue::try_from(35u8) {
        let _ = thread_priority::set_current_thread_priority(thread_priority::ThreadPriority::Crossplatform(
            value,
        ));
    }
}
