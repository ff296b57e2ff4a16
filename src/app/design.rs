//! Designing a caustic in the viewer: what the Design panel chose (the surface, the receiver,
//! the target), the design running on its own thread ([`DesignRun`]) and what it reports. The
//! thread runs the same design as `caustic design` ([`crate::design`]) on a copy of the scene
//! as edited and sends its moves as it goes; the viewer puts them into the document
//! (`design_actions.rs`), so that the control points move on screen and the render follows
//! with warm restarts, and records the whole design as one undo step when it ends.

use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

use crossbeam_channel::{unbounded, Receiver};
use glam::DVec3;

use super::file_dialog::FileDialog;
use super::handle::{Handle, NetRef, PointRef};
use crate::design::landing::Handle as DesignHandle;
use crate::design::optimize::StepReport;
use crate::design::setup::{design_candidates, prepare_design, DesignOptions};
use crate::design::target::load_target;
use crate::scene::Scene;

/// How often the design thread offers its moves: often enough to watch the surface change.
const MOVE_EVERY: Duration = Duration::from_millis(300);

/// The longest the viewer holds a design's newest moves back while the render has not shown
/// the previous ones (moves are put into the scene once the render has drawn the last, so that
/// there is a picture between two of them, however slow the render).
pub const MOVE_AT_LEAST_EVERY: Duration = Duration::from_secs(2);

/// What the Design panel chose and what the design it runs reports.
#[derive(Default)]
pub struct DesignState {
    /// The surface chosen (`None`: the panel's default, [`DesignState::surface`]).
    pub(super) surface: Option<String>,
    /// The receiver chosen (`None`: the default).
    pub(super) receiver: Option<String>,
    /// The target image.
    pub(super) target: Option<PathBuf>,
    /// Steps of the descent.
    pub(super) steps: Option<usize>,
    /// The target's file dialog.
    pub(super) picking: Option<FileDialog>,
    /// Whether a design is running.
    pub(super) running: bool,
    /// The loss after each step of the design shown: `[step, loss]`.
    pub(super) losses: Vec<[f64; 2]>,
    /// The newest step's figures.
    pub(super) latest: Option<StepReport>,
    /// Control points the running design moves.
    pub(super) parameters: usize,
    /// How the last design ended, or why it could not start.
    pub(super) message: Option<Result<String, String>>,
}

impl DesignState {
    /// The surface a design shapes, among `surfaces` (the scene's candidates,
    /// [`design_candidates`]): the one chosen, else the selected point's object (`selected`),
    /// else the one named `lens`, else the first (`None`: there is none).
    pub fn surface(&self, surfaces: &[String], selected: Option<&str>) -> Option<String> {
        let known = |s: &str| surfaces.iter().any(|c| c == s);
        self.surface
            .clone()
            .filter(|s| known(s))
            .or_else(|| selected.filter(|s| known(s)).map(str::to_owned))
            .or_else(|| known("lens").then(|| "lens".to_owned()))
            .or_else(|| surfaces.first().cloned())
    }

    /// The receiver a design draws on, among `receivers` (the scene's quads): the one chosen,
    /// else the one named `screen`, else the first.
    pub fn receiver(&self, receivers: &[String]) -> Option<String> {
        let known = |s: &str| receivers.iter().any(|c| c == s);
        self.receiver
            .clone()
            .filter(|s| known(s))
            .or_else(|| known("screen").then(|| "screen".to_owned()))
            .or_else(|| receivers.first().cloned())
    }

    /// The surface and receiver a design of `scene` uses now, the selected point being of
    /// object `selected`.
    pub fn choice(&self, scene: &Scene, selected: Option<u32>) -> (Option<String>, Option<String>) {
        let (surfaces, receivers) = design_candidates(scene);
        let selected = selected
            .and_then(|k| scene.objects.get(k as usize))
            .map(|o| o.name.as_str());
        (self.surface(&surfaces, selected), self.receiver(&receivers))
    }

    /// The target image chosen.
    pub fn target(&self) -> Option<&PathBuf> {
        self.target.as_ref()
    }

    /// Whether a design is running.
    pub fn running(&self) -> bool {
        self.running
    }

    /// The losses of the design shown, `[step, loss]`.
    pub fn losses(&self) -> &[[f64; 2]] {
        &self.losses
    }

    /// The newest step's figures.
    pub fn latest(&self) -> Option<&StepReport> {
        self.latest.as_ref()
    }

    /// How the last design ended (`Ok`), or why it failed (`Err`).
    pub fn message(&self) -> Option<&Result<String, String>> {
        self.message.as_ref()
    }

    /// The steps a design takes.
    pub fn steps(&self) -> usize {
        self.steps.unwrap_or(DesignOptions::default().steps)
    }
}

/// What one design parameter moves in the viewer's terms: the handles, where they started and
/// the direction they move along.
#[derive(Clone, Debug)]
pub struct MovedHandles {
    /// The handles (welded Bézier points, or one net point).
    pub handles: Vec<Handle>,
    /// Where they started.
    pub origin: DVec3,
    /// Their direction of motion (unit).
    pub dir: DVec3,
}

/// What the design thread tells the viewer.
#[derive(Debug)]
pub enum DesignUpdate {
    /// The design is ready and starts: what each parameter moves.
    Started(Vec<MovedHandles>),
    /// A step was taken: its figures, and the moves so far when it is time to show them.
    Step(StepReport, Option<Vec<f64>>),
    /// The design ended (stopped, out of time or steps) with these moves, and its loss before
    /// and after over all its photons.
    Finished {
        /// Each parameter's move.
        theta: Vec<f64>,
        /// The loss as the surface started.
        initial_loss: f64,
        /// The loss as it ends.
        final_loss: f64,
    },
    /// The design could not start.
    Failed(String),
}

/// A design running on its own thread.
pub struct DesignRun {
    stop: Arc<AtomicBool>,
    /// What it reports.
    pub(super) updates: Receiver<DesignUpdate>,
    /// What each parameter moves (once started).
    pub(super) moved: Vec<MovedHandles>,
    /// Every handle the design may move and where it was when the design began.
    pub(super) start: Vec<(Handle, DVec3)>,
    /// The newest moves not yet put into the scene.
    pub(super) waiting: Option<Vec<f64>>,
    /// When moves were last put into the scene.
    pub(super) applied: Instant,
}

impl DesignRun {
    /// Starts designing `surface` of `scene` (a copy of the scene as edited) to draw `target`
    /// on `receiver`. The surface is designed through its own control points as they are (the
    /// viewer does not split it: the render's patches stay the document's).
    pub fn spawn(
        ctx: &egui::Context,
        scene: Scene,
        (surface, receiver, target): (String, String, PathBuf),
        steps: usize,
    ) -> Self {
        let (tx, updates) = unbounded();
        let stop = Arc::new(AtomicBool::new(false));
        let flag = stop.clone();
        let ctx = ctx.clone();
        let work = move || {
            let options = DesignOptions {
                steps,
                refine: 0,
                ..DesignOptions::default()
            };
            let prepared = load_target(&target)
                .map_err(|e| format!("{}: {e}", target.display()))
                .and_then(|t| prepare_design(scene, (&surface, &receiver), &t, &options));
            let mut p = match prepared {
                Ok(p) => p,
                Err(e) => {
                    let _ = tx.send(DesignUpdate::Failed(e));
                    ctx.request_repaint();
                    return;
                }
            };
            let _ = tx.send(DesignUpdate::Started(moved_handles(&p.params)));
            let mut shown = Instant::now();
            let outcome = p.run(|report, theta| {
                let show = shown.elapsed() >= MOVE_EVERY;
                if show {
                    shown = Instant::now();
                }
                let _ = tx.send(DesignUpdate::Step(*report, show.then(|| theta.to_vec())));
                ctx.request_repaint();
                match flag.load(Ordering::Relaxed) {
                    true => std::ops::ControlFlow::Break(()),
                    false => std::ops::ControlFlow::Continue(()),
                }
            });
            let _ = tx.send(DesignUpdate::Finished {
                theta: outcome.theta,
                initial_loss: outcome.initial_loss,
                final_loss: outcome.final_loss,
            });
            ctx.request_repaint();
        };
        // If the thread cannot start, the sender is dropped with the closure and the run reads
        // as lost, which the viewer reports.
        let _ = std::thread::Builder::new()
            .name("caustic-design".into())
            .spawn(work);
        Self {
            stop,
            updates,
            moved: Vec::new(),
            start: Vec::new(),
            waiting: None,
            applied: Instant::now(),
        }
    }

    /// Asks the design to end after its current step.
    pub fn stop(&self) {
        self.stop.store(true, Ordering::Relaxed);
    }

    /// Where each handle is after the moves `theta`.
    pub fn positions(&self, theta: &[f64]) -> Vec<(Handle, DVec3)> {
        self.moved
            .iter()
            .zip(theta)
            .flat_map(|(m, t)| m.handles.iter().map(move |h| (*h, m.origin + *t * m.dir)))
            .collect()
    }
}

/// The viewer's handles for each of a design's parameters.
fn moved_handles(params: &crate::design::landing::DesignParams) -> Vec<MovedHandles> {
    params
        .handles
        .iter()
        .zip(params.origins.iter().zip(&params.dirs))
        .map(|(h, (origin, dir))| MovedHandles {
            handles: match h {
                DesignHandle::Points(points) => points
                    .iter()
                    .map(|&(patch, index)| Handle::Control(PointRef { patch, index }))
                    .collect(),
                DesignHandle::Net { net, index } => vec![Handle::Net(NetRef {
                    net: *net,
                    index: *index,
                })],
            },
            origin: *origin,
            dir: *dir,
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_surface_is_the_chosen_else_the_selected_else_lens_else_the_first() {
        let names = |v: &[&str]| v.iter().map(|s| s.to_string()).collect::<Vec<_>>();
        let surfaces = names(&["water", "lens", "mirror"]);
        let mut state = DesignState::default();
        assert_eq!(state.surface(&surfaces, None).as_deref(), Some("lens"));
        assert_eq!(
            state.surface(&surfaces, Some("mirror")).as_deref(),
            Some("mirror")
        );
        assert_eq!(state.surface(&surfaces, Some("floor")).as_deref(), Some("lens"));
        state.surface = Some("water".into());
        assert_eq!(state.surface(&surfaces, Some("mirror")).as_deref(), Some("water"));
        state.surface = Some("gone".into());
        assert_eq!(state.surface(&names(&["a", "b"]), None).as_deref(), Some("a"));
        assert_eq!(state.surface(&[], None), None);
        assert_eq!(
            state.receiver(&names(&["wall", "screen"])).as_deref(),
            Some("screen")
        );
        assert_eq!(state.receiver(&names(&["wall"])).as_deref(), Some("wall"));
        state.receiver = Some("wall".into());
        assert_eq!(
            state.receiver(&names(&["wall", "screen"])).as_deref(),
            Some("wall")
        );
    }
}
