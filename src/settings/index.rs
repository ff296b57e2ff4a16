//! The spatial index photon mapping finds visible points with: a setting, so it lives with
//! the other settings rather than in the photon mapper.

/// Which spatial index finds the visible points near a photon (`--index grid|kd` on the
/// command line; stored by name in the viewer's preferences).
#[derive(
    Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize, clap::ValueEnum,
)]
pub enum IndexKind {
    /// Hashed uniform grid, rebuilt per pass (default).
    #[default]
    #[value(name = "grid")]
    #[serde(rename = "grid")]
    HashGrid,
    /// The seed report's kd-tree with per-subtree maximum radius.
    #[value(name = "kd")]
    #[serde(rename = "kd")]
    KdTree,
}
