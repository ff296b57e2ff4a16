//! The render parameters the side panel edits, their ranges, and the command each change
//! sends to the render session.

use crate::render::session::Command;
use crate::scene::{RendererKind, Scene};

/// Values shown by the side panel (start from the scene file).
#[derive(Clone, Debug, PartialEq)]
pub struct RenderParams {
    /// PPM radius reduction α.
    pub alpha: f64,
    /// Photons per pass.
    pub photons_per_pass: u64,
    /// Initial radius from the pixel footprint.
    pub auto_radius: bool,
    /// Initial radius when not automatic (scene units).
    pub initial_radius: f64,
    /// Lens radius (0 = pinhole).
    pub aperture: f64,
    /// Distance to the plane in focus.
    pub focal_distance: f64,
    /// Maximum specular depth.
    pub max_depth: u32,
    /// Photon mapping or ray tracing.
    pub renderer: RendererKind,
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
    *crate::render::limits::MAX_DEPTH.start(),
    *crate::render::limits::MAX_DEPTH.end(),
);

impl RenderParams {
    /// The scene file's values.
    pub fn from_scene(scene: &Scene) -> Self {
        let s = &scene.settings;
        Self {
            alpha: s.alpha,
            photons_per_pass: s.photons_per_pass,
            auto_radius: s.initial_radius.is_none(),
            initial_radius: s
                .initial_radius
                .unwrap_or(Ranges::for_scene(scene).default_radius()),
            aperture: scene.camera.aperture,
            focal_distance: scene.camera.focal_distance,
            max_depth: s.max_depth,
            renderer: s.renderer,
            paused: false,
        }
    }

    /// The initial radius as the session takes it.
    pub fn initial_radius(&self) -> Option<f64> {
        (!self.auto_radius).then_some(self.initial_radius)
    }

    /// Writes these values into a scene (for restarting the renderer with them).
    pub fn apply_to(&self, scene: &mut Scene) {
        scene.settings.alpha = self.alpha;
        scene.settings.photons_per_pass = self.photons_per_pass;
        scene.settings.initial_radius = self.initial_radius();
        scene.settings.max_depth = self.max_depth;
        scene.settings.renderer = self.renderer;
        scene.camera.aperture = self.aperture;
        scene.camera.focal_distance = self.focal_distance;
    }

    /// The commands that take the session from `old` to `self`, in a fixed order.
    pub fn commands_from(&self, old: &RenderParams) -> Vec<Command> {
        let mut out = Vec::new();
        if self.alpha != old.alpha {
            out.push(Command::SetAlpha(self.alpha));
        }
        if self.photons_per_pass != old.photons_per_pass {
            out.push(Command::SetPhotonsPerPass(self.photons_per_pass));
        }
        if self.initial_radius() != old.initial_radius() {
            out.push(Command::SetInitialRadius(self.initial_radius()));
        }
        if self.aperture != old.aperture {
            out.push(Command::SetAperture(self.aperture));
        }
        if self.focal_distance != old.focal_distance {
            out.push(Command::SetFocalDistance(self.focal_distance));
        }
        if self.max_depth != old.max_depth {
            out.push(Command::SetMaxDepth(self.max_depth));
        }
        if self.renderer != old.renderer {
            out.push(Command::SetRenderer(self.renderer));
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
