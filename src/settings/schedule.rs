//! How photon mapping shrinks its search radii: a setting, beside the other settings.

/// How the photon-mapping radius shrinks from pass to pass (`--radius-schedule` on the command
/// line, `radius_schedule` in a scene's `[render]` table).
#[derive(
    Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize, clap::ValueEnum,
)]
pub enum RadiusSchedule {
    /// Per-point statistics (Hachisuka et al. 2008): each visible point's photon count and
    /// flux carry from pass to pass, and its radius shrinks with the photons it gathered
    /// (default).
    #[default]
    #[value(name = "per-point")]
    #[serde(rename = "per_point")]
    PerPoint,
    /// One global schedule (Knaus & Zwicker 2011): pass `i` gathers at the radius
    /// `r_i² = r_1² · Π_{k<i} (k + α)/(k + 1)`, every pass is an independent estimate and the
    /// image is their average, so passes can be rendered on any machine in any order and
    /// merged (`render --shard`, `caustic merge`).
    #[value(name = "global")]
    #[serde(rename = "global")]
    Global,
}

impl RadiusSchedule {
    /// The name a scene file uses.
    pub fn name(self) -> &'static str {
        match self {
            RadiusSchedule::PerPoint => "per_point",
            RadiusSchedule::Global => "global",
        }
    }
}
