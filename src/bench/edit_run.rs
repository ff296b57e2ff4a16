//! What an edit looks like while it renders: one control point moved in the viewer's kind of
//! render session ([`SessionOptions::interactive`]), every frame of the new epoch compared with
//! a reference of the edited scene. Behind `caustic bench edit` (time to an error, warm and
//! cold restarts) and `caustic view --bench` (what is on screen 100 ms after an edit).

use std::time::{Duration, Instant};

use super::timings::median;
use crate::render::error::errors;
use crate::render::session::{Command, RenderSession, SessionOptions};
use crate::scene::Scene;

/// How long a pass before the edit may take at most.
const BEFORE_EDIT_WAIT: Duration = Duration::from_secs(120);

/// How long after an edit the picture on screen is judged (the drag preview's target).
pub const ON_SCREEN_AFTER: Duration = Duration::from_millis(100);

/// How one edit is measured.
#[derive(Clone, Debug)]
pub struct EditPlan {
    /// The edit (a [`Command::MoveControlPoint`]).
    pub edit: Command,
    /// Passes rendered before the edit (the image a person was looking at).
    pub before_passes: u32,
    /// Start the new epoch warm (else cold, with the low-resolution preview, as before warm
    /// restarts existed).
    pub warm: bool,
    /// Stop once the relative MSE is at most this.
    pub target: f64,
    /// Give up after this long.
    pub limit: Duration,
}

/// What one edit measured; errors against the reference of the edited scene.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EditRun {
    /// Seconds from the edit to the target relative MSE (`None`: not within the limit).
    pub to_target: Option<f64>,
    /// Seconds to the new epoch's first image, and its RMSE.
    pub first: (f64, f64),
    /// RMSE of the newest image there was [`ON_SCREEN_AFTER`] the edit (the previous epoch's
    /// last when none of the new one had come).
    pub on_screen: f64,
}

/// Renders `scene` in an interactive session, makes the edit after `before_passes` passes and
/// follows the new epoch until the target (or the limit). `Err` when the renderer failed.
pub fn measure_edit(scene: Scene, plan: &EditPlan, reference: &[[f32; 3]]) -> Result<EditRun, String> {
    let mut options = SessionOptions {
        every_frame: true,
        ..SessionOptions::interactive()
    };
    options.warm_restarts = plan.warm;
    let session = RenderSession::start_with(scene, options, None);
    let frames = session.frames();
    let mut edited_at: Option<Instant> = None;
    let mut first = None;
    let mut on_screen = None;
    let mut last = f64::NAN;
    let mut run = None;
    // Before the edit, passes may take long; after it, the limit counts.
    let wait = |edited_at: Option<Instant>| match edited_at {
        None => BEFORE_EDIT_WAIT,
        Some(at) => plan.limit.saturating_sub(at.elapsed()),
    };
    while let Ok(frame) = frames.recv_timeout(wait(edited_at)) {
        let rmse = errors(&frame.radiance, reference).0;
        let Some(at) = edited_at else {
            last = rmse;
            if frame.pass >= plan.before_passes && !frame.preview {
                session.send(plan.edit.clone());
                edited_at = Some(Instant::now());
            }
            continue;
        };
        if frame.epoch == 0 {
            last = rmse;
            continue;
        }
        let secs = at.elapsed();
        if secs > ON_SCREEN_AFTER {
            on_screen.get_or_insert(last);
        }
        last = rmse;
        first.get_or_insert((secs.as_secs_f64(), rmse));
        let rel_mse = errors(&frame.radiance, reference).1;
        if rel_mse <= plan.target {
            run = Some(secs.as_secs_f64());
            break;
        }
        if secs > plan.limit {
            break;
        }
    }
    let failure = session.failure();
    session.shutdown();
    if let Some(f) = failure {
        return Err(format!("the renderer failed: {f}"));
    }
    Ok(EditRun {
        to_target: run,
        first: first.unwrap_or((f64::NAN, f64::NAN)),
        on_screen: on_screen.unwrap_or(last),
    })
}

/// Runs of one edit with the new epoch started warm and cold.
#[derive(Clone, Debug, Default)]
pub struct WarmCold {
    /// The warm restarts' runs, in order.
    pub warm: Vec<EditRun>,
    /// The cold restarts' runs, in order.
    pub cold: Vec<EditRun>,
}

/// The medians of [`WarmCold`]'s runs, each as `[warm, cold]`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EditMedians {
    /// Seconds to the target (infinite for runs that did not reach it).
    pub to_target: [f64; 2],
    /// Seconds to the new epoch's first image, and its RMSE.
    pub first: [(f64, f64); 2],
    /// RMSE of what was on screen [`ON_SCREEN_AFTER`] the edit.
    pub on_screen: [f64; 2],
}

impl WarmCold {
    /// Measures the edit of `plan` (its `warm` is set per run) `runs` times each way, warm and
    /// cold interleaved; run `k` renders with the scene's seed plus `k`. `progress` hears of
    /// each run as it ends (its number from 0, whether warm, what it measured).
    pub fn measure(
        scene: &Scene,
        plan: &EditPlan,
        runs: u32,
        reference: &[[f32; 3]],
        mut progress: impl FnMut(u32, bool, &EditRun),
    ) -> Result<Self, String> {
        let mut out = Self::default();
        for run in 0..runs {
            for warm in [true, false] {
                let mut s = scene.clone();
                s.params.seed = s.params.seed.wrapping_add(u64::from(run));
                let plan = EditPlan { warm, ..plan.clone() };
                let r = measure_edit(s, &plan, reference)?;
                progress(run, warm, &r);
                if warm { &mut out.warm } else { &mut out.cold }.push(r);
            }
        }
        Ok(out)
    }

    /// The medians of the runs.
    pub fn medians(&self) -> EditMedians {
        let both = |f: &dyn Fn(&EditRun) -> f64| {
            [&self.warm, &self.cold].map(|runs| median(runs.iter().map(f).collect()))
        };
        let to_target = both(&|r| r.to_target.unwrap_or(f64::INFINITY));
        let first_secs = both(&|r| r.first.0);
        let first_rmse = both(&|r| r.first.1);
        EditMedians {
            to_target,
            first: [(first_secs[0], first_rmse[0]), (first_secs[1], first_rmse[1])],
            on_screen: both(&|r| r.on_screen),
        }
    }
}
