//! Writing a scene back as TOML: the text it was loaded from, edited in place (comments and
//! layout kept, through `toml_edit`), with the camera, the render settings and every edited
//! patch object brought up to date. Edited patches are written inline, in world space, row by
//! row (`[[x, y, z], …16]` per patch) and their `file`/`builtin`/`transform` keys removed, so
//! the saved file loads back to the same control points bit for bit. Relative file names are
//! made absolute when the scene is saved to another folder, so they still resolve.

use std::path::{Path, PathBuf};

use glam::DVec3;
use toml_edit::{Array, DocumentMut, Item, Table, Value};

use super::{RenderParams, Scene};
use crate::files::{write_atomically, WriteError};
use crate::geometry::{BezierPatch, Window};

/// Why a scene could not be saved.
#[derive(Debug, thiserror::Error)]
pub enum SaveError {
    /// The scene's own text no longer parses as TOML (it did when it was loaded).
    #[error("{}: the scene text cannot be edited: {message}", path.display())]
    Text {
        /// The scene's source.
        path: PathBuf,
        /// The parser's message.
        message: String,
    },
    /// The file could not be written (or exists and replacing it was not allowed).
    #[error(transparent)]
    Write(#[from] WriteError),
}

fn vec3(v: DVec3) -> Value {
    Array::from_iter([v.x, v.y, v.z]).into()
}

/// One patch as a TOML array of its 16 points, on one line.
fn patch_value(p: &BezierPatch) -> Value {
    let mut points: Array = p.points.iter().map(|q| vec3(*q)).collect();
    points.decor_mut().set_prefix("\n    ");
    points.into()
}

/// `file` made absolute against `base` when relative (so it resolves from another folder).
fn rebase(file: &str, base: &Path) -> String {
    let path = Path::new(file);
    if path.is_absolute() {
        return file.to_owned();
    }
    let joined = base.join(path);
    joined
        .canonicalize()
        .unwrap_or(joined)
        .to_string_lossy()
        .into_owned()
}

/// Rewrites the relative `file` key of a table, if it has one.
fn rebase_file_key(table: &mut dyn toml_edit::TableLike, base: &Path) {
    let Some(file) = table.get("file").and_then(Item::as_str).map(str::to_owned) else {
        return;
    };
    let rebased = rebase(&file, base);
    if rebased != file {
        table.insert("file", toml_edit::value(rebased));
    }
}

/// The scene as TOML text. `loaded` are the patches as the scene's file gave them (in
/// geometry order): objects whose patches differ are written inline. `out_dir` is the folder
/// the text will be saved in (relative names are rebased when it is not the scene's own).
pub fn scene_toml(
    scene: &Scene,
    loaded: &[BezierPatch],
    out_dir: Option<&Path>,
) -> Result<String, SaveError> {
    let mut doc = parse_text(scene)?;
    write_camera(&mut doc, scene);
    write_render(&mut doc, scene);
    write_patches(&mut doc, scene, loaded);
    if let (Some(base), Some(out)) = (&scene.base_dir, out_dir) {
        let same = base
            .canonicalize()
            .ok()
            .zip(out.canonicalize().ok())
            .is_some_and(|(a, b)| a == b);
        if !same {
            if let Some(materials) = doc.get_mut("materials").and_then(Item::as_table_like_mut) {
                for (_, m) in materials.iter_mut() {
                    let texture = m.as_table_like_mut().and_then(|t| t.get_mut("texture"));
                    if let Some(t) = texture.and_then(Item::as_table_like_mut) {
                        rebase_file_key(t, base);
                    }
                }
            }
            if let Some(objects) = doc.get_mut("objects").and_then(Item::as_array_of_tables_mut) {
                for o in objects.iter_mut() {
                    rebase_file_key(o, base);
                }
            }
        }
    }
    Ok(doc.to_string())
}

/// The scene's own text with only its render settings (`[render]`) and image size brought up to
/// date: what a render made from the text with command-line overrides would need, every
/// other line (camera, objects) kept verbatim, so the text loads back to the same camera bit
/// for bit (re-deriving `look_at` from the camera could move it by a rounding step).
pub fn settings_toml(scene: &Scene) -> Result<String, SaveError> {
    let mut doc = parse_text(scene)?;
    write_size(table(&mut doc, "camera"), scene);
    write_render(&mut doc, scene);
    Ok(doc.to_string())
}

fn write_size(t: &mut Table, scene: &Scene) {
    t.insert("width", toml_edit::value(i64::from(scene.camera.width)));
    t.insert("height", toml_edit::value(i64::from(scene.camera.height)));
}

/// The scene's own text as an editable TOML document.
fn parse_text(scene: &Scene) -> Result<DocumentMut, SaveError> {
    scene
        .text
        .parse()
        .map_err(|e: toml_edit::TomlError| SaveError::Text {
            path: scene.source.clone(),
            message: e.to_string(),
        })
}

fn table<'d>(doc: &'d mut DocumentMut, name: &str) -> &'d mut Table {
    let item = doc.entry(name).or_insert_with(|| Item::Table(Table::new()));
    if !item.is_table() {
        *item = Item::Table(Table::new());
    }
    item.as_table_mut().expect("made a table above")
}

fn write_camera(doc: &mut DocumentMut, scene: &Scene) {
    let c = &scene.camera;
    let t = table(doc, "camera");
    t.insert("position", toml_edit::value(vec3(c.position)));
    t.insert(
        "look_at",
        toml_edit::value(vec3(c.position + c.forward * c.focal_distance)),
    );
    t.insert("up", toml_edit::value(vec3(c.up)));
    t.insert("fov", toml_edit::value(c.fov_y.to_degrees()));
    write_size(t, scene);
    t.insert("aperture", toml_edit::value(c.aperture));
    t.insert("focal_distance", toml_edit::value(c.focal_distance));
}

/// Writes the render parameters into `[render]`: every key the table already has, and every
/// value that differs from the default (so a file that never named a setting stays lean).
fn write_render(doc: &mut DocumentMut, scene: &Scene) {
    let values = params_table(&scene.params);
    let defaults = params_table(&RenderParams::default());
    let t = table(doc, "render");
    for (key, item) in values.iter() {
        let default = defaults.get(key).map(|d| d.to_string());
        if t.contains_key(key) || default != Some(item.to_string()) {
            t.insert(key, item.clone());
        }
    }
    // Absent values (an automatic initial radius) are absent from the file too.
    let absent: Vec<String> = t
        .iter()
        .map(|(k, _)| k.to_owned())
        .filter(|k| !values.contains_key(k))
        .collect();
    for key in absent {
        t.remove(&key);
    }
}

/// Render parameters as a TOML table, through their serde form.
fn params_table(params: &RenderParams) -> toml_edit::Table {
    let text = toml::to_string(params).expect("render parameters serialize to TOML");
    let doc: DocumentMut = text.parse().expect("toml writes TOML that toml_edit reads");
    doc.as_table().clone()
}

fn write_patches(doc: &mut DocumentMut, scene: &Scene, loaded: &[BezierPatch]) {
    let patches = scene.geometry.patches();
    let domains = scene.geometry.patch_domains();
    let Some(objects) = doc.get_mut("objects").and_then(Item::as_array_of_tables_mut) else {
        return;
    };
    for (k, object) in objects.iter_mut().enumerate() {
        let own: Vec<(usize, &BezierPatch)> = patches
            .iter()
            .enumerate()
            .filter(|(_, (_, id))| *id as usize == k)
            .map(|(i, (p, _))| (i, p))
            .collect();
        let edited = own.iter().any(|(i, p)| loaded.get(*i) != Some(*p));
        if own.is_empty() || !edited {
            continue;
        }
        for key in ["file", "builtin", "transform", "domains"] {
            object.remove(key);
        }
        let mut list: Array = own.iter().map(|(_, p)| patch_value(p)).collect();
        list.set_trailing("\n");
        list.set_trailing_comma(true);
        object.insert("patches", toml_edit::value(list));
        // Patches cut from a larger surface keep their (u,v) windows, so textures still follow it.
        let windows: Vec<Window> = own.iter().map(|(i, _)| domains[*i]).collect();
        if windows.iter().any(|w| *w != Window::FULL) {
            let list: Array = windows
                .iter()
                .map(|w| Value::from(Array::from_iter([w.u0, w.u1, w.v0, w.v1])))
                .collect();
            object.insert("domains", toml_edit::value(list));
        }
    }
}

/// Saves the scene to `path` (temporary name, then rename); an existing file is replaced only
/// when `overwrite`. Returns the text written.
pub fn save_scene(
    scene: &Scene,
    loaded: &[BezierPatch],
    path: &Path,
    overwrite: bool,
) -> Result<String, SaveError> {
    let text = scene_toml(scene, loaded, path.parent())?;
    write_atomically(path, overwrite, |tmp| {
        std::fs::write(tmp, &text).map_err(|e| e.to_string())
    })?;
    Ok(text)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_edited_teapot_saves_and_loads_back_bit_for_bit() {
        let mut scene = Scene::builtin();
        let loaded: Vec<BezierPatch> = scene.geometry.patches().iter().map(|(p, _)| *p).collect();
        assert!(scene
            .geometry
            .set_control_point(3, 5, DVec3::new(0.1, -2.0 / 3.0, 1e-17)));
        scene.camera.position += DVec3::new(0.5, 0.25, -0.125);
        scene.camera.aperture = 0.05;
        scene.params.alpha = 0.6;
        let text = scene_toml(&scene, &loaded, None).expect("saves");
        assert!(text.contains("# The Utah teapot"), "comments lost");
        let back = Scene::from_str(&text, Path::new("saved.toml"), None).expect("loads back");
        let patches = |s: &Scene| s.geometry.patches().to_vec();
        assert_eq!(patches(&back), patches(&scene));
        assert_eq!(back.materials, scene.materials);
        assert_eq!(back.lights, scene.lights);
        assert_eq!(back.params, scene.params);
        let (a, b) = (&back.camera, &scene.camera);
        assert!((a.position - b.position).length() < 1e-12);
        assert!((a.forward - b.forward).length() < 1e-12 && (a.up - b.up).length() < 1e-12);
        assert!((a.fov_y - b.fov_y).abs() < 1e-12 && a.aperture == b.aperture);
        assert!((a.focal_distance - b.focal_distance).abs() < 1e-9);
        // Unedited, the teapot stays a reference to the built-in copy.
        let plain = scene_toml(&Scene::builtin(), &loaded, None).expect("saves");
        assert!(plain.contains("builtin = \"teapot\"") && !plain.contains("patches ="));
    }

    #[test]
    fn saved_elsewhere_relative_files_still_resolve() {
        let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes");
        let scene = Scene::load(&dir.join("scroll.toml")).expect("scroll loads");
        let loaded: Vec<BezierPatch> = scene.geometry.patches().iter().map(|(p, _)| *p).collect();
        let elsewhere = tempfile::tempdir().expect("temp dir");
        let text = scene_toml(&scene, &loaded, Some(elsewhere.path())).expect("saves");
        let back = Scene::from_str(&text, &elsewhere.path().join("s.toml"), Some(elsewhere.path()))
            .expect("its texture and patch files still resolve");
        assert_eq!(back.geometry.patches(), scene.geometry.patches());
        assert_eq!(back.textures.len(), 1);
        let painting = dir.join("../assets/painting.png").canonicalize().expect("exists");
        assert!(text.contains(&*painting.to_string_lossy()), "{text}");
    }
}
