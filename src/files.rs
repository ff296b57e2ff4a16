//! Writing a file so that a failure never leaves half of it, and never replaces a file the
//! user made unless asked: the content goes to a hidden temporary name beside the target,
//! which is renamed over it only once complete.

use std::path::{Path, PathBuf};

/// Why [`write_atomically`] wrote nothing.
#[derive(Debug, thiserror::Error)]
pub enum WriteError {
    /// The target exists and replacing it was not allowed.
    #[error("{}: the file exists; choose another name or allow replacing it", .0.display())]
    Exists(PathBuf),
    /// Writing or renaming failed.
    #[error("{}: {message}", path.display())]
    Failed {
        /// The target.
        path: PathBuf,
        /// What went wrong.
        message: String,
    },
}

/// Writes `path` through `write(temporary_path)`, then renames the temporary file over
/// `path`. Refuses to replace an existing file unless `overwrite` (checked before and after
/// writing); removes the temporary file on any failure.
pub fn write_atomically(
    path: &Path,
    overwrite: bool,
    write: impl FnOnce(&Path) -> Result<(), String>,
) -> Result<(), WriteError> {
    let failed = |message: String| WriteError::Failed {
        path: path.to_owned(),
        message,
    };
    if !overwrite && path.exists() {
        return Err(WriteError::Exists(path.to_owned()));
    }
    let file_name = path.file_name().ok_or_else(|| failed("no file name".into()))?;
    let tmp = path.with_file_name(format!(".{}.partial", file_name.to_string_lossy()));
    if let Err(message) = write(&tmp) {
        let _ = std::fs::remove_file(&tmp);
        return Err(failed(message));
    }
    if !overwrite && path.exists() {
        let _ = std::fs::remove_file(&tmp);
        return Err(WriteError::Exists(path.to_owned()));
    }
    std::fs::rename(&tmp, path).map_err(|e| {
        let _ = std::fs::remove_file(&tmp);
        failed(e.to_string())
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn writes_refuses_to_replace_and_cleans_up_after_a_failure() {
        let dir = tempfile::tempdir().expect("temp dir");
        let path = dir.path().join("a.txt");
        write_atomically(&path, false, |tmp| {
            std::fs::write(tmp, "one").map_err(|e| e.to_string())
        })
        .expect("first write");
        let again = write_atomically(&path, false, |tmp| {
            std::fs::write(tmp, "two").map_err(|e| e.to_string())
        });
        assert!(matches!(again, Err(WriteError::Exists(_))));
        let failed = write_atomically(&path, true, |tmp| {
            std::fs::write(tmp, "half").map_err(|e| e.to_string())?;
            Err("disk full".into())
        });
        assert!(matches!(failed, Err(WriteError::Failed { .. })));
        assert_eq!(std::fs::read_to_string(&path).expect("kept"), "one");
        assert_eq!(
            std::fs::read_dir(dir.path()).expect("dir").count(),
            1,
            "temporary file left behind"
        );
    }
}
