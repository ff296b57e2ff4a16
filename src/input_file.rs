//! Opening a file the user named, for reading: when the path is not a regular file, the
//! reason says what it is instead (missing, a folder, a device or FIFO, a link that leads
//! nowhere or in a loop), and a file read whole is bounded in size, so that a link to
//! `/dev/zero` or a FIFO never hangs a reader or fills the memory.

use std::io::Read;
use std::path::Path;

/// The largest text file read whole (a scene file): 256 MiB.
pub const MAX_TEXT_BYTES: u64 = 256 << 20;

/// Why `path` cannot be read as a regular file, or its metadata when it can.
pub fn regular_file(path: &Path) -> Result<std::fs::Metadata, String> {
    match std::fs::metadata(path) {
        Ok(meta) if meta.is_file() => Ok(meta),
        Ok(meta) if meta.is_dir() => Err("is a folder, not a file".into()),
        Ok(_) => Err("is not a regular file (a device, FIFO or socket)".into()),
        Err(e) => Err(match std::fs::symlink_metadata(path) {
            Ok(link) if link.file_type().is_symlink() && e.kind() == std::io::ErrorKind::NotFound => {
                "is a symbolic link to a file that does not exist".into()
            }
            Ok(link) if link.file_type().is_symlink() => {
                format!("is a symbolic link that cannot be followed ({e})")
            }
            _ if e.kind() == std::io::ErrorKind::NotFound => "does not exist".into(),
            _ => format!("cannot be read ({e})"),
        }),
    }
}

/// Opens `path` after [`regular_file`].
pub fn open(path: &Path) -> Result<std::fs::File, String> {
    regular_file(path)?;
    std::fs::File::open(path).map_err(|e| format!("cannot be opened ({e})"))
}

/// Reads the regular file `path` as UTF-8 text of at most `max_bytes`.
pub fn read_text(path: &Path, max_bytes: u64) -> Result<String, String> {
    String::from_utf8(read_bytes(path, max_bytes)?).map_err(|_| "is not UTF-8 text".into())
}

/// Reads the regular file `path` whole, at most `max_bytes`.
pub fn read_bytes(path: &Path, max_bytes: u64) -> Result<Vec<u8>, String> {
    let meta = regular_file(path)?;
    if meta.len() > max_bytes {
        return Err(format!("is {} bytes; at most {max_bytes} are read", meta.len()));
    }
    let file = std::fs::File::open(path).map_err(|e| format!("cannot be opened ({e})"))?;
    let mut bytes = Vec::with_capacity(meta.len() as usize);
    // The size checked above may grow while the file is read: take no more than the bound.
    match file.take(max_bytes + 1).read_to_end(&mut bytes) {
        Ok(n) if n as u64 > max_bytes => Err(format!("grew past {max_bytes} bytes while being read")),
        Ok(_) => Ok(bytes),
        Err(e) => Err(format!("cannot be read ({e})")),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_kind_of_path_is_named() {
        let dir = tempfile::tempdir().expect("temp dir");
        let file = dir.path().join("a.txt");
        std::fs::write(&file, "hello").expect("write");
        assert_eq!(read_text(&file, 100).as_deref(), Ok("hello"));
        assert!(read_text(&file, 3).expect_err("too big").contains("at most 3"));
        assert_eq!(
            regular_file(&dir.path().join("nope")).expect_err("missing"),
            "does not exist"
        );
        assert_eq!(
            regular_file(dir.path()).expect_err("folder"),
            "is a folder, not a file"
        );
        #[cfg(unix)]
        {
            use std::os::unix::fs::symlink;
            assert!(regular_file(Path::new("/dev/zero"))
                .expect_err("device")
                .contains("device"));
            let zero = dir.path().join("zero");
            symlink("/dev/zero", &zero).expect("link");
            assert!(read_text(&zero, 100)
                .expect_err("device")
                .contains("not a regular file"));
            let dangling = dir.path().join("dangling");
            symlink(dir.path().join("gone"), &dangling).expect("link");
            assert!(regular_file(&dangling)
                .expect_err("dangling")
                .contains("does not exist"));
            let (a, b) = (dir.path().join("loop_a"), dir.path().join("loop_b"));
            symlink(&b, &a).expect("link");
            symlink(&a, &b).expect("link");
            assert!(regular_file(&a).expect_err("loop").contains("cannot be followed"));
        }
    }
}
