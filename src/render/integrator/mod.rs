//! The seam between a render and its renderer: every renderer is an [`Integrator`] that
//! renders a pass at a time and describes its own image and statistics ([`Frame`],
//! [`crate::render::frame::FrameStats`]). The session, the command line and the viewer talk to it through this
//! interface only; which renderers exist, and whether each renders pass after pass or one
//! frame per epoch, comes from the one list of renderers in `src/settings/renderer.rs`
//! ([`RendererKind`]).
//!
//! A new renderer is a file here with a type that implements [`Integrator`] and has
//! `fn new(scene: &Scene, setup: &Setup) -> Self`, plus its line in that list.

pub use crate::render::control::{Control, Interrupt};
use crate::render::frame::Frame;
use crate::scene::Scene;
use crate::settings::{RenderParams, RendererKind};

/// Work between two looks at the caller's [`Control`] when nobody asks for less: photons, for
/// photon mapping (a batch: [`crate::render::ppm::DEFAULT_BATCH_PHOTONS`]).
pub const DEFAULT_BATCH: u64 = crate::render::ppm::DEFAULT_BATCH_PHOTONS;

/// How an integrator is set up, beyond the scene's own settings.
#[derive(Clone)]
pub struct Setup {
    /// Work between two looks at the caller's [`Control`] (photons for photon mapping): small
    /// batches let a viewer react sooner; the image does not depend on it.
    pub batch: u64,
    /// Keep what a warm restart needs ([`Integrator::warm_restart`]).
    pub warm_restarts: bool,
    /// Asked often during a pass; returning true abandons it.
    pub interrupt: Option<Interrupt>,
}

impl Default for Setup {
    fn default() -> Self {
        Self {
            batch: DEFAULT_BATCH,
            warm_restarts: false,
            interrupt: None,
        }
    }
}

impl Setup {
    /// Whether the pass in progress is to be abandoned.
    pub fn interrupted(&self) -> bool {
        self.interrupt.as_ref().is_some_and(|i| i())
    }
}

/// What the coming pass is to do: the current parameters (α and the photon counts may change
/// between passes without a restart) and the photon ramp of a new epoch.
#[derive(Clone, Debug, PartialEq)]
pub struct PassPlan {
    /// The render parameters now.
    pub params: RenderParams,
    /// Photons in an epoch's first pass, doubling pass by pass up to the full count (`None`:
    /// full passes from the start).
    pub first_pass_photons: Option<u64>,
}

impl PassPlan {
    /// Photons of the pass after `completed` passes of a render whose full pass is `full`.
    /// An epoch that continues an earlier one's estimates (`warm`, a warm restart) ramps only
    /// its first pass: that pass stays small so that the edit's first image comes as soon as
    /// it did with the doubling ramp, but from then on its image is the kept estimates plus new
    /// photons, and what improves it is photons per second, which small passes waste on each
    /// pass's fixed cost (the stochastic eye pass is most of a 16,384-photon pass).
    pub fn pass_photons(&self, completed: u32, full: u64, warm: bool) -> u64 {
        if warm && completed > 0 {
            return full;
        }
        photon_ramp(self.first_pass_photons, completed, full)
    }
}

/// Photons of the pass after `completed` passes when a full pass is `full`: from `first`,
/// doubling pass by pass up to `full` (`None`: `full` from the start).
pub fn photon_ramp(first: Option<u64>, completed: u32, full: u64) -> u64 {
    match first {
        Some(first) => full.min(first.saturating_mul(1 << completed.min(40))),
        None => full,
    }
}

/// A renderer: one pass at a time, its image and statistics on request.
pub trait Integrator: Send {
    /// Renders the next pass of `scene` as `plan` says. `control` is asked between batches of
    /// work, with the render settings as the pass began, which it brings up to date: a live
    /// setting changed since (α, for photon mapping) applies from there on, for a renderer that
    /// reads it. [`Control::Abort`] abandons the pass. Returns whether the pass completed (an
    /// abandoned pass leaves no trace).
    fn render_pass(
        &mut self,
        scene: &Scene,
        plan: &PassPlan,
        control: &mut dyn FnMut(&mut RenderParams) -> Control,
    ) -> bool;

    /// Completed passes.
    fn passes(&self) -> u32;

    /// The image so far as a frame of `epoch`, `elapsed_secs` into it.
    fn frame(&self, epoch: u64, elapsed_secs: f64) -> Frame;

    /// The renderer of the next epoch, after an edit of the scene alone (`scene` as edited): a
    /// renderer that can carry what it learned over the edit (photon mapping's warm restart,
    /// [`crate::render::ppm::warm`]) makes its successor from itself; by default a new one
    /// starts from nothing.
    fn warm_restart(self: Box<Self>, scene: &Scene, setup: &Setup) -> Box<dyn Integrator> {
        make(scene.params.renderer, scene, setup)
    }
}

/// Declares each renderer's module and makes the integrator of a kind, from the list.
macro_rules! renderers {
    ($($variant:ident, $name:literal, $label:literal, $about:literal, $mode:ident, $module:ident :: $integrator:ident;)*) => {
        $(pub mod $module;)*

        /// The integrator of `kind` for `scene`.
        pub fn make(kind: RendererKind, scene: &Scene, setup: &Setup) -> Box<dyn Integrator> {
            match kind {
                $(RendererKind::$variant => Box::new($module::$integrator::new(scene, setup)),)*
            }
        }
    };
}

crate::settings::with_renderers!(renderers);

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_warm_epoch_ramps_only_its_first_pass() {
        let plan = PassPlan {
            params: crate::settings::RenderParams::default(),
            first_pass_photons: Some(1000),
        };
        let cold = [0, 1, 2, 3].map(|k| plan.pass_photons(k, 5000, false));
        let warm = [0, 1, 2, 3].map(|k| plan.pass_photons(k, 5000, true));
        assert_eq!(cold, [1000, 2000, 4000, 5000]);
        assert_eq!(warm, [1000, 5000, 5000, 5000]);
        let full = PassPlan {
            first_pass_photons: None,
            ..plan
        };
        assert_eq!(full.pass_photons(0, 5000, true), 5000);
    }
}
