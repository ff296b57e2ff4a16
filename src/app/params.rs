//! What the side panel edits — the render parameters, the lens, pause — the scene's scale for
//! their sliders, and the commands a change sends to the render session. Which controls the
//! render parameters have comes from the table of settings ([`super::setting_ui`]).

use crate::render::session::Command;
use crate::scene::{Camera, Scene};
use crate::settings::RenderParams;

/// Values shown by the side panel (start from the scene file).
#[derive(Clone, Debug, PartialEq)]
pub struct PanelParams {
    /// The render parameters the session receives whole ([`Command::SetParams`]).
    pub render: RenderParams,
    /// What the slider of each automatic setting shows (its value when automatic is off).
    pub manual: std::collections::BTreeMap<&'static str, f64>,
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
    /// Half the diagonal of the scene's bounded geometry (at most four focal distances): what
    /// sliders of lengths are fractions of.
    pub extent: f64,
    /// Aperture range (from 0).
    pub aperture_max: f64,
    /// Focal distance range.
    pub focal: (f64, f64),
}

impl PanelParams {
    /// The scene file's values.
    pub fn from_scene(scene: &Scene) -> Self {
        Self {
            render: scene.params.clone(),
            manual: Default::default(),
            aperture: scene.camera.aperture,
            focal_distance: scene.camera.focal_distance,
            paused: false,
        }
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
            extent,
            aperture_max: (extent * 0.1).max(cam.aperture * 2.0),
            focal: (
                (extent * 1e-3).min(cam.focal_distance * 0.5),
                (extent * 20.0).max(cam.focal_distance * 2.0),
            ),
        }
    }
}
