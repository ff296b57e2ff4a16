//! The session's rules, free of threads and channels ([`SessionState`]): which commands apply
//! at once, which gather into a restart, when to wait, and what to render next ([`Next`]).

use std::time::Duration;

use super::command::{apply_to_scene, valid, Command};
use crate::scene::Scene;
use crate::settings::RenderParams;

/// How a session renders, beyond the scene's own settings.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SessionOptions {
    /// Work between two looks at the command channel (photons, for photon mapping): small
    /// batches let a viewer's change apply sooner; the image does not depend on it.
    pub batch: u64,
    /// Renderers keep what a warm restart after an edit of the scene needs
    /// ([`crate::render::integrator::Integrator::warm_restart`]).
    pub warm_restarts: bool,
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
    /// Render in a pool of this many threads (`None`: rayon's global pool, or with
    /// `background` a pool of one thread per core).
    pub threads: Option<usize>,
    /// Render in threads of lower priority (niceness 5 on Linux), so that a window's UI
    /// thread, which also rasterises in software where there is no GPU, is not kept waiting
    /// behind them: the viewer's sessions.
    pub background: bool,
}

/// Photons between two looks at the command channel in an interactive session: 4 chunks,
/// about 30–60 ms on 2 cores, so a slider reacts well within the 250 ms target.
pub const INTERACTIVE_BATCH_PHOTONS: u64 = 16_384;
/// Photons in the first pass of an interactive epoch (doubling up to photons per pass): the
/// first image of a new setting appears after one small pass.
pub const INTERACTIVE_FIRST_PASS_PHOTONS: u64 = 16_384;
/// A new cold interactive epoch first shows a preview at this fraction of the resolution.
pub const INTERACTIVE_PREVIEW_DIVISOR: u32 = 4;

impl Default for SessionOptions {
    /// Batches of the integrators' default size, no warm restarts, full passes from the start,
    /// no preview, no limits.
    fn default() -> Self {
        Self {
            batch: crate::render::integrator::DEFAULT_BATCH,
            warm_restarts: false,
            first_pass_photons: None,
            start_paused: false,
            preview_divisor: None,
            max_passes: None,
            time_limit: None,
            every_frame: false,
            threads: None,
            background: false,
        }
    }
}

impl SessionOptions {
    /// The viewer's options (and `bench edit`'s, which measures what the viewer shows): small
    /// batches, a photon ramp, a low-resolution preview of a cold epoch, and warm restarts
    /// after edits.
    pub fn interactive() -> Self {
        SessionOptions {
            batch: INTERACTIVE_BATCH_PHOTONS,
            warm_restarts: true,
            first_pass_photons: Some(INTERACTIVE_FIRST_PASS_PHOTONS),
            preview_divisor: Some(INTERACTIVE_PREVIEW_DIVISOR),
            ..Default::default()
        }
    }
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
    /// The scene's lights (their kinds, for checking [`Command::SetLight`]).
    lights: Vec<crate::scene::Light>,
    /// The scene's materials (their models, for checking [`Command::SetMaterial`]).
    materials: Vec<crate::scene::Material>,
    /// Passes completed in this epoch (the ray-traced frame counts as one).
    pub passes: u32,
    pub(super) preview_due: bool,
    /// Camera, control-point, light and material commands for the next epoch.
    pending: Vec<Command>,
    /// A restart is waiting.
    restart_due: bool,
    /// The waiting restart changes more than the scene's geometry and lights (settings,
    /// camera, or a plain restart): it starts cold.
    cold_due: bool,
    pub(super) shutdown: bool,
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
            lights: scene.lights.clone(),
            materials: scene.materials.clone(),
            passes: 0,
            preview_due: options.preview_divisor.is_some(),
            pending: Vec::new(),
            restart_due: false,
            cold_due: false,
            shutdown: false,
        }
    }

    /// Takes a command.
    pub fn apply(&mut self, command: Command) -> Effect {
        if !valid(&command, self.patches, &self.lights, &self.materials) {
            return Effect::Ignored;
        }
        let restarts = command.restarts(&self.params);
        // An edit of the scene (a control point or a light moved) keeps what is still valid.
        let edit = matches!(
            command,
            Command::MoveControlPoint { .. } | Command::SetLight { .. }
        );
        match command {
            // The restart takes the newest set: parameters need no replaying.
            Command::SetParams(p) => self.params = p,
            Command::Pause => self.paused = true,
            Command::Resume => self.paused = false,
            Command::Shutdown => {
                self.shutdown = true;
                return Effect::Shutdown;
            }
            Command::SetCamera(_)
            | Command::MoveControlPoint { .. }
            | Command::SetLight { .. }
            | Command::SetMaterial { .. }
            | Command::Restart => self.pending.push(command),
        }
        if restarts {
            self.restart_due = true;
            self.cold_due |= !edit;
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
            || (self.params.renderer.progressive()
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
        } else if !self.params.renderer.progressive() {
            Next::Trace
        } else if self.preview_due {
            Next::Preview
        } else {
            Next::Pass
        }
    }

    /// Whether to wait for a command before going on (also between photon batches).
    pub(super) fn idle(&self) -> bool {
        let limit_reached = self.options.max_passes.is_some_and(|n| self.passes >= n);
        !self.must_abort() && !limit_reached && self.waiting()
    }

    /// Paused, or the ray-traced frame of this epoch is done.
    fn waiting(&self) -> bool {
        self.paused || (!self.params.renderer.progressive() && self.passes > 0)
    }

    /// Opens a new epoch: the gathered commands are applied to `scene`. Returns whether the
    /// epoch starts warm ([`SessionOptions::warm_restarts`] and only the scene was edited); a
    /// warm epoch has no preview.
    pub fn restart(&mut self, scene: &mut Scene) -> bool {
        apply_to_scene(scene, std::mem::take(&mut self.pending));
        let warm = self.options.warm_restarts && !self.cold_due;
        self.restart_due = false;
        self.cold_due = false;
        scene.params = self.params.clone();
        self.epoch += 1;
        self.passes = 0;
        self.preview_due = self.options.preview_divisor.is_some() && !warm;
        warm
    }

    /// Photons of the pass after `completed` passes of a render whose full pass is `full`
    /// photons ([`RenderParams::pass_photons`]): the ramp from
    /// [`SessionOptions::first_pass_photons`] doubling up to `full`.
    pub fn pass_photons(&self, completed: u32, full: u64) -> u64 {
        crate::render::integrator::photon_ramp(self.options.first_pass_photons, completed, full)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::settings::RendererKind;
    use glam::DVec3;

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
