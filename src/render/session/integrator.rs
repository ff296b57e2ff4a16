//! The integrator of an epoch as the session uses it: the plan of each pass, and the
//! low-resolution preview a new epoch of a progressive renderer may open with.

use std::time::Instant;

use super::state::{SessionOptions, SessionState};
use crate::render::frame::Frame;
use crate::render::integrator::{make, Integrator, PassPlan, Setup};
use crate::scene::Scene;

/// What a pass or frame needs from the session's loop.
pub(super) struct Step {
    pub(super) epoch: u64,
    pub(super) epoch_start: Instant,
}

/// The plan of the coming pass: the state's parameters and the options' photon ramp.
pub(super) fn plan(state: &SessionState, options: &SessionOptions) -> PassPlan {
    PassPlan {
        params: state.params.clone(),
        first_pass_photons: options.first_pass_photons,
    }
}

/// One pass of the epoch's renderer at 1/`divisor` of the resolution, enlarged: the first
/// picture of a new epoch (one pass of [`SessionOptions::first_pass_photons`] or 16,384
/// photons). `None` when interrupted.
pub(super) fn preview(
    scene: &mut Scene,
    setup: &Setup,
    plan: &PassPlan,
    divisor: u32,
    step: Step,
) -> Option<Frame> {
    let (w, h) = (scene.camera.width, scene.camera.height);
    let small = ((w / divisor.max(1)).max(1), (h / divisor.max(1)).max(1));
    (scene.camera.width, scene.camera.height) = small;
    let mut integrator = make(scene.params.renderer, scene, setup);
    // One small pass: the ramp's first photons, or 16,384, never more than a full pass.
    let photons = plan
        .first_pass_photons
        .unwrap_or(16_384)
        .min(plan.params.photons_per_pass);
    let small_plan = PassPlan {
        params: crate::settings::RenderParams {
            photons_per_pass: photons,
            min_photons_per_pixel: 0.0,
            ..plan.params.clone()
        },
        first_pass_photons: None,
    };
    let completed = integrator.render_pass(scene, &small_plan, &mut |_| {
        crate::render::control::Control::Continue
    });
    (scene.camera.width, scene.camera.height) = (w, h);
    if !completed {
        return None;
    }
    let frame = integrator.frame(step.epoch, step.epoch_start.elapsed().as_secs_f64());
    Some(frame.enlarged_preview((w, h)))
}

/// Renders the next pass with `integrator`; `None` when abandoned, the state's pass count
/// updated otherwise.
pub(super) fn pass(
    integrator: &mut dyn Integrator,
    scene: &Scene,
    plan: &PassPlan,
    step: Step,
    control: &mut dyn FnMut(&mut crate::settings::RenderParams) -> crate::render::control::Control,
) -> Option<Frame> {
    integrator
        .render_pass(scene, plan, control)
        .then(|| integrator.frame(step.epoch, step.epoch_start.elapsed().as_secs_f64()))
}
