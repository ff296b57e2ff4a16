//! Where a scene file's errors point: the file, the line of the table, the table's name and
//! the field ([`SceneError`]), and the checks every table shares ([`Table`]).

use std::ops::Range;
use std::path::{Path, PathBuf};

use glam::DVec3;

use crate::scene::format::Vec3;

/// A scene file that cannot be used: where, and why.
#[derive(Debug, thiserror::Error)]
#[error("{}:{line}: {message}", path.display())]
pub struct SceneError {
    /// The scene file.
    pub path: PathBuf,
    /// 1-based line (0 when the file could not be read).
    pub line: usize,
    /// What is wrong, naming the table and field.
    pub message: String,
}

/// Where the errors point.
pub(super) struct Ctx<'a> {
    pub(super) path: &'a Path,
    pub(super) text: &'a str,
    pub(super) base_dir: Option<&'a Path>,
}

pub(super) type Result<T> = std::result::Result<T, SceneError>;

impl Ctx<'_> {
    pub(super) fn line(&self, span: &Range<usize>) -> usize {
        self.text[..span.start.min(self.text.len())].matches('\n').count() + 1
    }

    pub(super) fn err(&self, span: &Range<usize>, message: impl Into<String>) -> SceneError {
        SceneError {
            path: self.path.to_owned(),
            line: self.line(span),
            message: message.into(),
        }
    }

    /// A file named in the scene, resolved against the scene's folder and checked to exist.
    pub(super) fn resolve(&self, span: &Range<usize>, what: &str, file: &str) -> Result<PathBuf> {
        let Some(base) = self.base_dir else {
            return Err(self.err(
                span,
                format!("{what}: '{file}': a built-in scene cannot refer to files"),
            ));
        };
        let path = base.join(file);
        if let Err(why) = crate::input_file::regular_file(&path) {
            return Err(self.err(span, format!("{what}: '{}' {why}", path.display())));
        }
        Ok(path)
    }
}

pub(super) fn v3(v: &Vec3) -> DVec3 {
    DVec3::new(v[0].0, v[1].0, v[2].0)
}

/// Checks of one table: its name for messages and its span for the line.
pub(super) struct Table<'a, 'c> {
    pub(super) ctx: &'a Ctx<'c>,
    pub(super) span: Range<usize>,
    pub(super) name: String,
}

impl Table<'_, '_> {
    pub(super) fn err(&self, message: impl std::fmt::Display) -> SceneError {
        self.ctx.err(&self.span, format!("{}: {message}", self.name))
    }

    pub(super) fn required<T: Copy>(&self, field: &str, value: Option<T>) -> Result<T> {
        value.ok_or_else(|| self.err(format!("missing '{field}'")))
    }

    pub(super) fn positive(&self, field: &str, v: f64) -> Result<f64> {
        if v > 0.0 {
            Ok(v)
        } else {
            Err(self.err(format!("'{field}' must be positive, got {v}")))
        }
    }

    pub(super) fn non_negative(&self, field: &str, v: f64) -> Result<f64> {
        if v >= 0.0 {
            Ok(v)
        } else {
            Err(self.err(format!("'{field}' must not be negative, got {v}")))
        }
    }

    pub(super) fn nonzero(&self, field: &str, v: DVec3) -> Result<DVec3> {
        if v.length_squared() > 0.0 {
            Ok(v)
        } else {
            Err(self.err(format!("'{field}' must not be the zero vector")))
        }
    }

    pub(super) fn reflectance(&self, field: &str, v: DVec3) -> Result<DVec3> {
        if v.cmpge(DVec3::ZERO).all() && v.cmple(DVec3::ONE).all() {
            Ok(v)
        } else {
            Err(self.err(format!("'{field}' components must be between 0 and 1, got {v}")))
        }
    }

    /// Rejects keys given that this table's `type` does not use.
    pub(super) fn only(&self, kind: &str, given: &[(&str, bool)], allowed: &[&str]) -> Result<()> {
        for (key, present) in given {
            if *present && !allowed.contains(key) {
                return Err(self.err(format!(
                    "'{key}' does not apply to type '{kind}' (it takes: {})",
                    allowed.join(", ")
                )));
            }
        }
        Ok(())
    }
}
