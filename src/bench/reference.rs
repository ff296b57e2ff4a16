//! The long reference render that `caustic bench convergence` measures error against, cached on
//! disk: an EXR with a TOML record beside it (program version, scene text, size, passes, every
//! render parameter and the seed). A cached reference is used only when its record matches the
//! one asked for exactly; otherwise it is rendered again and replaced.

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use crate::scene::Scene;
use crate::settings::RenderParams;

/// What a reference render was made from.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ReferenceRecord {
    /// `caustic <version>`.
    pub program: String,
    /// The scene's file, canonical (the same file named from another folder or by another
    /// path finds the same reference; the scene's relative asset names resolve against it).
    pub scene: String,
    /// The scene's TOML text.
    pub scene_text: String,
    /// Image width.
    pub width: u32,
    /// Image height.
    pub height: u32,
    /// Passes rendered.
    pub passes: u32,
    /// Every render parameter, seed included.
    pub params: RenderParams,
    /// An edit made to the scene after it was read (`bench edit`'s moved control point), in
    /// words; absent for the scene as written.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub edit: Option<String>,
}

impl ReferenceRecord {
    /// The record of a `passes`-pass reference of `scene` as it stands (size and parameters
    /// included).
    pub fn new(scene: &Scene, passes: u32) -> Self {
        Self {
            program: format!("caustic {}", env!("CARGO_PKG_VERSION")),
            scene: std::fs::canonicalize(&scene.source)
                .unwrap_or_else(|_| scene.source.clone())
                .display()
                .to_string(),
            scene_text: scene.text.to_string(),
            width: scene.camera.width,
            height: scene.camera.height,
            passes,
            params: scene.params.clone(),
            edit: None,
        }
    }

    /// Where this reference lives in `dir`: `<scene>-<w>x<h>-<passes>p-<hash>.exr`, the hash
    /// (FNV-1a) over the whole record.
    pub fn path_in(&self, dir: &Path) -> PathBuf {
        let text = toml::to_string(self).unwrap_or_default();
        let hash = text.bytes().fold(0xcbf2_9ce4_8422_2325u64, |h, b| {
            (h ^ b as u64).wrapping_mul(0x0100_0000_01b3)
        });
        let stem = Path::new(&self.scene)
            .file_stem()
            .map_or("scene".into(), |s| s.to_string_lossy().into_owned());
        let stem: String = stem
            .chars()
            .map(|c| if c.is_ascii_alphanumeric() { c } else { '_' })
            .collect();
        dir.join(format!(
            "{stem}-{}x{}-{}p-{hash:016x}.exr",
            self.width, self.height, self.passes
        ))
    }

    /// The cached reference's pixels in `dir`, if one with exactly this record is there.
    pub fn load(&self, dir: &Path) -> Option<Vec<[f32; 3]>> {
        let path = self.path_in(dir);
        let stored: ReferenceRecord =
            toml::from_str(&std::fs::read_to_string(path.with_extension("toml")).ok()?).ok()?;
        if stored != *self {
            return None;
        }
        let image = image::open(&path).ok()?.to_rgb32f();
        if (image.width(), image.height()) != (self.width, self.height) {
            return None;
        }
        Some(image.pixels().map(|p| p.0).collect())
    }

    /// Stores a reference's pixels (and this record beside them) in `dir`, replacing an older
    /// one of the same name. Returns the image's path.
    pub fn store(&self, dir: &Path, pixels: &[[f32; 3]]) -> Result<PathBuf, String> {
        std::fs::create_dir_all(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
        let path = self.path_in(dir);
        let image = crate::render::Image {
            width: self.width,
            height: self.height,
            pixels: pixels.to_vec(),
        };
        let metadata = vec![("caustic:reference_passes".into(), self.passes.to_string())];
        image
            .save(&path, 0.0, &metadata, true)
            .map_err(|e| e.to_string())?;
        let record = toml::to_string(self).map_err(|e| e.to_string())?;
        crate::files::write_atomically(&path.with_extension("toml"), true, |temporary| {
            std::fs::write(temporary, record).map_err(|e| e.to_string())
        })
        .map_err(|e| e.to_string())?;
        Ok(path)
    }
}

/// The folder references are cached in unless told otherwise: `$XDG_CACHE_HOME/caustic`,
/// `~/.cache/caustic`, or the system's temporary folder.
pub fn default_cache_dir() -> PathBuf {
    let base = std::env::var_os("XDG_CACHE_HOME")
        .map(PathBuf::from)
        .or_else(|| std::env::var_os("HOME").map(|h| PathBuf::from(h).join(".cache")))
        .unwrap_or_else(std::env::temp_dir);
    base.join("caustic").join("references")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_reference_is_reused_only_when_its_record_matches() {
        let dir = std::env::temp_dir().join(format!("caustic-ref-test-{}", std::process::id()));
        let mut scene = Scene::builtin();
        (scene.camera.width, scene.camera.height) = (4, 3);
        let record = ReferenceRecord::new(&scene, 7);
        let pixels: Vec<[f32; 3]> = (0..12).map(|k| [k as f32, 0.5, 0.25]).collect();
        let path = record.store(&dir, &pixels).expect("stored");
        assert!(path.exists() && path.with_extension("toml").exists());
        assert_eq!(record.load(&dir), Some(pixels));
        let mut other = record.clone();
        other.params.seed += 1;
        assert_ne!(other.path_in(&dir), path);
        assert_eq!(other.load(&dir), None, "another seed is another reference");
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn a_scene_named_by_another_path_finds_the_same_reference() {
        let dir = std::env::temp_dir();
        let relative = Scene::load(Path::new("scenes/leaf.toml")).expect("scene");
        let roundabout = Scene::load(Path::new("scenes/../scenes/./leaf.toml")).expect("scene");
        let absolute =
            Scene::load(&std::fs::canonicalize("scenes/leaf.toml").expect("exists")).expect("scene");
        let path = ReferenceRecord::new(&relative, 5).path_in(&dir);
        for scene in [&roundabout, &absolute] {
            assert_eq!(
                ReferenceRecord::new(scene, 5).path_in(&dir),
                path,
                "{}",
                scene.source.display()
            );
        }
        assert!(
            Path::new(&ReferenceRecord::new(&relative, 5).scene).is_absolute(),
            "the record names the file canonically"
        );
    }
}
