//! The renderer of an epoch, made from the scene's parameters when the epoch opens: a
//! photon-mapping pass at a time, or the ray tracer's one frame; and the low-resolution
//! preview a new epoch may open with.

use std::time::Instant;

use super::frame::{enlarge, Frame, FrameStats};
use super::state::{SessionOptions, SessionState};
use crate::render::ppm::{Control, Interrupt, PassOutcome, Ppm, PpmOptions};
use crate::render::whitted::render_whitted_until;
use crate::scene::{RendererKind, Scene};

/// One photon-mapping pass at 1/`divisor` of the resolution, enlarged: the first picture of a
/// new epoch. `None` when interrupted.
pub(super) fn preview(
    scene: &mut Scene,
    options: &SessionOptions,
    divisor: u32,
    step: Step,
) -> Option<Frame> {
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
pub(super) enum Integrator {
    /// Progressive photon mapping: a pass at a time.
    PhotonMapping(Box<Ppm>),
    /// The Whitted ray tracer: one frame per epoch.
    RayTracer,
}

/// What a pass or frame needs from the session's loop.
pub(super) struct Step<'a> {
    pub(super) epoch: u64,
    pub(super) epoch_start: Instant,
    pub(super) interrupted: &'a Interrupt,
}

impl Integrator {
    /// The integrator `scene.params.renderer` names.
    pub(super) fn new(scene: &Scene, options: PpmOptions, interrupted: &Interrupt) -> Self {
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
    pub(super) fn render(
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
