//! What the viewer remembers between runs (eframe storage): view preferences, not the scene's
//! own render parameters (index and direct light included), which start from the scene file
//! each time it is opened.

use std::path::PathBuf;

use serde::{Deserialize, Serialize};

/// Largest exposure, in stops either way, the viewer keeps.
pub const EXPOSURE_LIMIT: f32 = 20.0;

/// Key under which [`ViewerSettings`] is stored.
pub const STORAGE_KEY: &str = "caustic.viewer";

/// How the image is placed in the view.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub enum Zoom {
    /// Scaled to fit the view, centred.
    Fit,
    /// Image pixels per screen pixel (1.0 = 1:1), panned freely.
    Scale(f32),
}

/// What the image view shows.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum DisplayMode {
    /// Radiance, exposure-scaled and sRGB-encoded.
    Radiance,
    /// The frame's `k`-th per-pixel layer (photon mapping: search radius, photon count) in
    /// false colour (log scale).
    Layer(u8),
    /// `render − reference`, diverging false colour (needs a reference).
    SignedDifference,
    /// `|render − reference| / (reference + 0.01)`, false colour (needs a reference).
    RelativeDifference,
}

impl DisplayMode {
    /// The modes for a frame of `layers` (labels), in menu order: radiance, each layer, the
    /// differences to a reference.
    pub fn all(layers: &[&str]) -> Vec<DisplayMode> {
        let mut modes = vec![DisplayMode::Radiance];
        modes.extend((0..layers.len().min(u8::MAX as usize)).map(|k| DisplayMode::Layer(k as u8)));
        modes.extend([DisplayMode::SignedDifference, DisplayMode::RelativeDifference]);
        modes
    }

    /// Whether the mode compares with a reference (and so shows radiance without one).
    pub fn needs_reference(self) -> bool {
        matches!(
            self,
            DisplayMode::SignedDifference | DisplayMode::RelativeDifference
        )
    }

    /// Name shown in menus, for a frame of `layers` (labels).
    pub fn label(self, layers: &[&str]) -> String {
        match self {
            DisplayMode::Radiance => "Radiance (sRGB)".into(),
            DisplayMode::Layer(k) => format!(
                "{} (false colour)",
                layers.get(k as usize).copied().unwrap_or("layer")
            ),
            DisplayMode::SignedDifference => "Difference to reference (signed)".into(),
            DisplayMode::RelativeDifference => "Difference to reference (relative)".into(),
        }
    }
}

/// Viewer preferences persisted with eframe storage.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct ViewerSettings {
    /// Exposure in stops (the displayed and PNG-saved image is radiance × 2^stops).
    pub exposure_stops: f32,
    /// Image placement.
    pub zoom: Zoom,
    /// What the image view shows.
    pub display: DisplayMode,
    /// Side panel shown.
    pub show_side_panel: bool,
    /// Folder the last scene was opened from or frame saved to (file dialogs start there).
    pub last_directory: Option<PathBuf>,
    /// The control-net overlay is drawn (and can be edited).
    pub show_wireframe: bool,
}

impl Default for ViewerSettings {
    fn default() -> Self {
        Self {
            exposure_stops: 0.0,
            zoom: Zoom::Fit,
            display: DisplayMode::Radiance,
            show_side_panel: true,
            last_directory: None,
            show_wireframe: true,
        }
    }
}

impl ViewerSettings {
    /// Repairs values a hand-edited or old storage file may hold (NaN exposure, zero zoom).
    pub fn sanitized(mut self) -> Self {
        if !self.exposure_stops.is_finite() {
            self.exposure_stops = 0.0;
        }
        self.exposure_stops = self.exposure_stops.clamp(-EXPOSURE_LIMIT, EXPOSURE_LIMIT);
        if let Zoom::Scale(s) = self.zoom {
            if !(s.is_finite() && s > 0.0) {
                self.zoom = Zoom::Fit;
            }
        }
        self
    }
}
