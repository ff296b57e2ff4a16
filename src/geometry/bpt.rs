//! The `.bpt` Bézier patch text format: the number of patches, then for each patch a line
//! with its degrees `3 3` and 16 lines of control points `x y z`, row by row (`P[4i + j]`).
//!
//! ```text
//! 1
//! 3 3
//! 0 0 0
//! 0 1 0
//! …            (16 points)
//! ```

use std::path::{Path, PathBuf};

use glam::DVec3;

use super::bezier::BezierPatch;
use crate::settings::limits::MAX_PATCHES;

/// A malformed `.bpt` file: which file, which line, what was expected.
#[derive(Debug, thiserror::Error)]
#[error("{}:{line}: {message}", path.display())]
pub struct BptError {
    /// The file (as given).
    pub path: PathBuf,
    /// 1-based line number (the last line for a file that ends early; 0 when unreadable).
    pub line: usize,
    /// What was wrong.
    pub message: String,
}

/// Reads a `.bpt` file (whole: at most [`crate::input_file::MAX_TEXT_BYTES`]; the text is
/// then read in place, a line at a time).
pub fn load_bpt(path: &Path) -> Result<Vec<BezierPatch>, BptError> {
    let text =
        crate::input_file::read_text(path, crate::input_file::MAX_TEXT_BYTES).map_err(|why| BptError {
            path: path.to_owned(),
            line: 0,
            message: format!("the file {why}"),
        })?;
    parse_bpt(&text, path)
}

/// Parses `.bpt` text; `path` only names the source in errors.
pub fn parse_bpt(text: &str, path: &Path) -> Result<Vec<BezierPatch>, BptError> {
    let mut lines = text
        .lines()
        .enumerate()
        .map(|(i, l)| (i + 1, l.trim()))
        .filter(|(_, l)| !l.is_empty() && !l.starts_with('#'));
    let last_line = text.lines().count();
    let err = |line: usize, message: String| BptError {
        path: path.to_owned(),
        line,
        message,
    };
    let mut next = |what: &str| {
        lines
            .next()
            .ok_or_else(|| err(last_line, format!("the file ends where {what} was expected")))
    };

    let (line, count_text) = next("the patch count")?;
    let count: usize = count_text.parse().map_err(|_| {
        err(
            line,
            format!("expected the number of patches, found '{count_text}'"),
        )
    })?;
    if count == 0 {
        return Err(err(line, "the file declares 0 patches".to_owned()));
    }
    if count > MAX_PATCHES {
        return Err(err(
            line,
            format!("the file declares {count} patches; a scene holds at most {MAX_PATCHES}"),
        ));
    }
    let mut patches = Vec::with_capacity(count.min(1 << 16));
    for k in 1..=count {
        let (line, degrees) = next(&format!("the degrees '3 3' of patch {k}"))?;
        let deg: Vec<&str> = degrees.split_whitespace().collect();
        if deg != ["3", "3"] {
            return Err(err(
                line,
                format!("patch {k}: expected degrees '3 3' (only bicubic patches), found '{degrees}'"),
            ));
        }
        let mut points = [DVec3::ZERO; 16];
        for (n, point) in points.iter_mut().enumerate() {
            let (line, text) = next(&format!("control point {} of patch {k}", n + 1))?;
            let values: Vec<&str> = text.split_whitespace().collect();
            if values.len() != 3 {
                return Err(err(
                    line,
                    format!(
                        "patch {k}, control point {}: expected 3 numbers 'x y z', found {}",
                        n + 1,
                        values.len()
                    ),
                ));
            }
            let mut xyz = [0.0; 3];
            for (c, s) in xyz.iter_mut().zip(&values) {
                *c = s.parse::<f64>().ok().filter(|v| v.is_finite()).ok_or_else(|| {
                    err(
                        line,
                        format!("patch {k}, control point {}: '{s}' is not a finite number", n + 1),
                    )
                })?;
            }
            *point = DVec3::from_array(xyz);
        }
        patches.push(BezierPatch::new(points));
    }
    if let Some((line, extra)) = lines.next() {
        return Err(err(
            line,
            format!("unexpected content after the {count} declared patches: '{extra}'"),
        ));
    }
    Ok(patches)
}
