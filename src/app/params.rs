//! What the side panel edits — the render parameters, the lens, pause — their slider
//! ranges, and the commands a change sends to the render session.

use crate::render::session::Command;
use crate::scene::{Camera, Scene};
use crate::settings::RenderParams;

/// Values shown by the side panel (start from the scene file).
#[derive(Clone, Debug, PartialEq)]
pub struct PanelParams {
    /// The render parameters the session receives whole ([`Command::SetParams`]).
    pub render: RenderParams,
    /// The initial radius the slider shows (used when the automatic radius is off).
    pub manual_radius: f64,
    /// The indirect radius scale the slider shows (used when the automatic scale is off).
    pub manual_indirect_scale: f64,
    /// Lens radius (0 = pinhole).
    pub aperture: f64,
    /// Distance to the plane in focus.
    pub focal_distance: f64,
    /// Rendering paused.
    pub paused: bool,
}

/// Slider ranges scaled to the scene's size.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ranges {
    /// Initial radius range.
    pub radius: (f64, f64),
    /// Aperture range (from 0).
    pub aperture_max: f64,
    /// Focal distance range.
    pub focal: (f64, f64),
}

/// Photons-per-pass slider range.
pub const PHOTONS_RANGE: (u64, u64) = (1_000, 10_000_000);
/// α slider range (α = 1 keeps the radius; the paper uses 0.7).
pub const ALPHA_RANGE: (f64, f64) = (0.05, 1.0);
/// Depth slider range: all the session accepts.
pub const DEPTH_RANGE: (u32, u32) = (
    *crate::settings::limits::MAX_DEPTH.start(),
    *crate::settings::limits::MAX_DEPTH.end(),
);

impl PanelParams {
    /// The scene file's values.
    pub fn from_scene(scene: &Scene) -> Self {
        Self {
            render: scene.params.clone(),
            manual_radius: scene
                .params
                .initial_radius
                .unwrap_or(Ranges::for_scene(scene).default_radius()),
            manual_indirect_scale: scene.params.indirect_radius_scale.unwrap_or(2.0),
            aperture: scene.camera.aperture,
            focal_distance: scene.camera.focal_distance,
            paused: false,
        }
    }

    /// Whether the initial radius comes from the pixel footprint.
    pub fn auto_radius(&self) -> bool {
        self.render.initial_radius.is_none()
    }

    /// Switches the automatic initial radius on or off (off: the slider's value).
    pub fn set_auto_radius(&mut self, auto: bool) {
        self.render.initial_radius = (!auto).then_some(self.manual_radius);
    }

    /// Switches the automatic indirect radius scale on or off (off: the slider's value).
    pub fn set_auto_indirect_scale(&mut self, auto: bool) {
        self.render.indirect_radius_scale = (!auto).then_some(self.manual_indirect_scale);
    }

    /// `camera` with this lens.
    pub fn lens_on(&self, camera: &Camera) -> Camera {
        Camera {
            aperture: self.aperture,
            focal_distance: self.focal_distance,
            ..camera.clone()
        }
    }

    /// Writes these values into a scene (for restarting the renderer with them).
    pub fn apply_to(&self, scene: &mut Scene) {
        scene.params = self.render.clone();
        scene.camera = self.lens_on(&scene.camera);
    }

    /// The commands that take the session from `old` to `self` (`camera` is the pose the
    /// lens goes on), in a fixed order.
    pub fn commands_from(&self, old: &PanelParams, camera: &Camera) -> Vec<Command> {
        let mut out = Vec::new();
        if self.render != old.render {
            out.push(Command::SetParams(self.render.clone()));
        }
        if (self.aperture, self.focal_distance) != (old.aperture, old.focal_distance) {
            out.push(Command::SetCamera(self.lens_on(camera)));
        }
        if self.paused != old.paused {
            out.push(if self.paused {
                Command::Pause
            } else {
                Command::Resume
            });
        }
        out
    }
}

impl Ranges {
    /// Ranges for a scene: lengths scale with its bounded geometry, but no more than four
    /// focal distances (smallppm's walls are spheres of radius 10⁵).
    pub fn for_scene(scene: &Scene) -> Self {
        let cam = &scene.camera;
        let bounds = scene.geometry.bounds();
        let extent = if bounds.is_empty() {
            cam.focal_distance
        } else {
            0.5 * bounds.diagonal().length()
        };
        let extent = if extent.is_finite() && extent > 0.0 {
            extent
        } else {
            10.0
        };
        let extent = extent.min(4.0 * cam.focal_distance);
        Self {
            radius: (extent * 1e-5, extent * 0.2),
            aperture_max: (extent * 0.1).max(cam.aperture * 2.0),
            focal: (
                (extent * 1e-3).min(cam.focal_distance * 0.5),
                (extent * 20.0).max(cam.focal_distance * 2.0),
            ),
        }
    }

    /// A starting value for a manual radius.
    pub fn default_radius(&self) -> f64 {
        (self.radius.0 * self.radius.1).sqrt()
    }
}
