//! Data built into the binary so it runs from any directory, with no files beside it.

use std::path::Path;

use crate::geometry::{parse_bpt, BezierPatch};

/// Newell's Utah teapot (1975): 32 bicubic patches, z up, in the `.bpt` text format.
/// The same figures as `assets/teapot.bpt`.
pub const TEAPOT_BPT: &str = include_str!("../assets/teapot.bpt");

/// smallppm's scene (Hachisuka's 100-line PPM), number for number: the default scene of
/// `caustic bench ppm` and `bench convergence`, so they run from any directory. The same text
/// as `scenes/smallppm.toml`.
pub const SMALLPPM_SCENE: &str = include_str!("../scenes/smallppm.toml");

/// One inline Bézier patch of glass over a floor (the README's first picture): the default
/// scene of `caustic bench edit`, so it runs from any directory. The same text as
/// `scenes/inline_patch.toml`, which names no other file.
pub const INLINE_PATCH_SCENE: &str = include_str!("../scenes/inline_patch.toml");

/// The Utah teapot's 32 patches.
pub fn teapot() -> Vec<BezierPatch> {
    parse_bpt(TEAPOT_BPT, Path::new("assets/teapot.bpt")).expect("the built-in teapot parses")
}
