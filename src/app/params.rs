//! What the side panel edits — the render parameters and the lens (the document's), pause —
//! and the scene's scale for their sliders. Which controls the render parameters have comes
//! from the table of settings ([`super::setting_ui`]).

use crate::scene::Scene;
use crate::settings::RenderParams;

/// Values shown by the side panel: a form the widgets fill in, made each frame from the
/// document and the panel's own choices ([`PanelParams::of`]); a changed one is handed to
/// [`super::Viewer::set_params`].
#[derive(Clone, Debug, PartialEq)]
pub struct PanelParams {
    /// The render parameters the session receives whole ([`crate::render::session::Command::SetParams`]).
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

/// What the side panel holds that is not the scene's: each automatic setting's manual value
/// and whether rendering is paused.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PanelChoices {
    /// What the slider of each automatic setting shows (its value when automatic is off).
    pub manual: std::collections::BTreeMap<&'static str, f64>,
    /// Rendering paused.
    pub paused: bool,
}

impl PanelParams {
    /// What the panel shows for `scene` (the document's) with `choices`.
    pub fn of(scene: &Scene, choices: &PanelChoices) -> Self {
        Self {
            render: scene.params.clone(),
            manual: choices.manual.clone(),
            aperture: scene.camera.aperture,
            focal_distance: scene.camera.focal_distance,
            paused: choices.paused,
        }
    }

    /// The panel's own part of these values.
    pub fn choices(&self) -> PanelChoices {
        PanelChoices {
            manual: self.manual.clone(),
            paused: self.paused,
        }
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
