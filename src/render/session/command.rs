//! The command protocol: what the UI (or a test) may ask of a render session, which commands
//! discard the accumulation, which values are valid, and how the restarting ones change the
//! scene.

use glam::DVec3;

use crate::geometry::BezierPatch;
use crate::scene::{Camera, Scene};
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
    /// Puts light `light` where `value` says (moved or turned, the same kind); restarts.
    /// An area light's surface moves with it; no patch is re-prepared.
    SetLight {
        /// Light index in the scene.
        light: usize,
        /// The light as it now is.
        value: crate::scene::Light,
    },
    /// Replaces material `material` (its colour and model's numbers; the same model, a
    /// texture kept); restarts, cold: every pixel may change.
    SetMaterial {
        /// Material index in the scene.
        material: usize,
        /// The material as it now is.
        value: crate::scene::Material,
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
            Command::SetCamera(_)
            | Command::MoveControlPoint { .. }
            | Command::SetLight { .. }
            | Command::SetMaterial { .. }
            | Command::Restart => true,
            Command::Pause | Command::Resume | Command::Shutdown => false,
        }
    }

    /// Whether the render thread should drop the pass in progress at once for it: restarts
    /// and shutdown do; α, photons and pause wait for the next batch.
    pub(super) fn interrupts(&self, current: &RenderParams) -> bool {
        self.restarts(current) || matches!(self, Command::Shutdown)
    }
}

/// Whether a command's values are valid for a scene with `patches` patches, `lights` and
/// `materials`.
pub(super) fn valid(
    command: &Command,
    patches: usize,
    lights: &[crate::scene::Light],
    materials: &[crate::scene::Material],
) -> bool {
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
        Command::SetLight { light, value } => lights.get(*light).is_some_and(|l| l.can_become(value)),
        Command::SetMaterial { material, value } => {
            materials.get(*material).is_some_and(|m| m.can_become(value))
        }
        Command::Pause | Command::Resume | Command::Restart | Command::Shutdown => true,
    }
}

/// Applies the camera, control points, lights and materials of the commands that restart the
/// accumulation to the scene, in order. Control-point moves are gathered so that each edited
/// patch is re-prepared once, however many steps of a drag arrived together (the latest
/// position of each point wins).
pub fn apply_to_scene(scene: &mut Scene, commands: Vec<Command>) {
    let mut edited: std::collections::BTreeMap<usize, BezierPatch> = Default::default();
    for command in commands {
        match command {
            Command::SetCamera(c) => scene.camera = c,
            Command::SetLight { light, value } => {
                scene.set_light(light, value);
            }
            Command::SetMaterial { material, value } => {
                if let Some(m) = scene.materials.get_mut(material) {
                    *m = value;
                }
            }
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
