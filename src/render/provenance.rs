//! What an output image records of the render that made it, and reading it back: the program
//! version, the whole effective scene text (the file with its command-line overrides laid in),
//! the folder its relative file names resolve against, the command line, the seed and the
//! passes — enough for `caustic render --from IMAGE` to render the same pixels again.
//!
//! The keys are EXR string attributes or PNG text chunks (the convention pbrt-v4 and Mitsuba
//! follow for their own render metadata).

use std::path::{Path, PathBuf};

use super::film::{read_metadata, Metadata};
use crate::scene::Scene;

/// The program that wrote the image (`caustic <version>`).
pub const SOFTWARE: &str = "Software";
/// The scene's file (`<built-in>` for the built-in scene).
pub const SCENE: &str = "caustic:scene";
/// The effective scene text: the file with every override laid in.
pub const SCENE_TEXT: &str = "caustic:scene_text";
/// The folder the scene text's relative file names resolve against.
pub const BASE_DIR: &str = "caustic:base_dir";
/// The command line that made the image (for people: the scene text already holds its effect).
pub const COMMAND_LINE: &str = "caustic:command_line";
/// Photon-mapping passes rendered.
pub const PASSES: &str = "caustic:passes";
/// PNG exposure in stops.
pub const EXPOSURE: &str = "caustic:exposure_stops";

/// This program's [`SOFTWARE`] value.
pub fn software() -> String {
    format!("caustic {}", env!("CARGO_PKG_VERSION"))
}

/// Metadata every output image carries: software, scene file, the effective scene text (see
/// [`crate::scene::save::settings_toml`]; `scene_text` replaces it when the caller has a
/// better one, such as the viewer's edited scene), base folder, command line, renderer, seed
/// and size. Callers append renderer-specific pairs.
pub fn image_metadata(scene: &Scene, renderer: &str, scene_text: Option<String>) -> Metadata {
    let text = scene_text
        .or_else(|| crate::scene::save::settings_toml(scene).ok())
        .unwrap_or_else(|| scene.text.to_string());
    let mut pairs: Metadata = vec![
        (SOFTWARE.into(), software()),
        (SCENE.into(), scene.source.display().to_string()),
        (SCENE_TEXT.into(), text),
    ];
    if let Some(dir) = &scene.base_dir {
        let dir = dir.canonicalize().unwrap_or_else(|_| dir.clone());
        pairs.push((BASE_DIR.into(), dir.display().to_string()));
    }
    let command_line: Vec<String> = std::env::args().collect();
    pairs.extend([
        (COMMAND_LINE.into(), command_line.join(" ")),
        ("caustic:renderer".into(), renderer.into()),
        ("caustic:seed".into(), scene.params.seed.to_string()),
        (
            "caustic:size".into(),
            format!("{}x{}", scene.camera.width, scene.camera.height),
        ),
    ]);
    pairs
}

/// A render read back from an image's metadata.
#[derive(Clone, Debug)]
pub struct Recorded {
    /// The scene as it was rendered (overrides included).
    pub scene: Scene,
    /// Photon-mapping passes it ran (`None` for a ray-traced image).
    pub passes: Option<u32>,
    /// The PNG exposure it was written with.
    pub exposure: Option<f32>,
    /// The program that wrote it.
    pub software: String,
}

/// Why an image's render could not be read back.
#[derive(Debug, thiserror::Error)]
#[error("{}: {message}", path.display())]
pub struct RecordedError {
    /// The image.
    pub path: PathBuf,
    /// What is wrong.
    pub message: String,
}

impl Recorded {
    /// Reads the render recorded in an image written by `caustic render` or the viewer.
    pub fn read(path: &Path) -> Result<Recorded, RecordedError> {
        let error = |message: String| RecordedError {
            path: path.to_owned(),
            message,
        };
        let metadata = read_metadata(path).map_err(|e| error(format!("cannot read its metadata: {e}")))?;
        let get = |key: &str| metadata.iter().find(|(k, _)| k == key).map(|(_, v)| v.as_str());
        let text = get(SCENE_TEXT).ok_or_else(|| {
            error(format!(
                "it holds no {SCENE_TEXT} (it was not written by caustic 0.1 or later)"
            ))
        })?;
        let source = PathBuf::from(get(SCENE).unwrap_or("<recorded>"));
        let base_dir = get(BASE_DIR).map(PathBuf::from);
        let scene = Scene::from_str(text, &source, base_dir.as_deref())
            .map_err(|e| error(format!("its recorded scene does not load: {e}")))?;
        let number = |key: &str| -> Result<Option<f64>, RecordedError> {
            get(key)
                .map(|v| {
                    v.parse::<f64>()
                        .ok()
                        .filter(|x| x.is_finite())
                        .ok_or_else(|| error(format!("its {key} {v:?} is not a number")))
                })
                .transpose()
        };
        let passes = match number(PASSES)? {
            Some(p) if p >= 1.0 && p <= u32::MAX as f64 && p.fract() == 0.0 => Some(p as u32),
            Some(p) => return Err(error(format!("its {PASSES} {p} is not a pass count"))),
            None => None,
        };
        Ok(Recorded {
            scene,
            passes,
            exposure: number(EXPOSURE)?.map(|e| e as f32),
            software: get(SOFTWARE).unwrap_or("an unknown program").to_owned(),
        })
    }
}
