//! Writing a scene back as TOML: the text it was loaded from, edited in place (comments and
//! layout kept, through `toml_edit`), with the camera, the render settings and every edited
//! patch object brought up to date. Edited patches are written inline, in world space, row by
//! row (`[[x, y, z], …16]` per patch) and their `file`/`builtin`/`transform` keys removed, so
//! the saved file loads back to the same control points bit for bit. Relative file names are
//! made absolute when the scene is saved to another folder, so they still resolve.

use std::path::{Path, PathBuf};

use glam::DVec3;
use toml_edit::{Array, DocumentMut, Item, Table, Value};

use super::{Camera, Light, Material, MaterialKind, RenderParams, Scene};
use crate::files::{write_atomically, WriteError};
use crate::geometry::freeform::write_surfaces_obj;
use crate::geometry::rational::Weights;
use crate::geometry::trim::TrimRegion;
use crate::geometry::usd::is_usd_file;
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

/// Patches as FORMAT.md writes them: each patch on lines of its own, one row of four points a
/// line, numbers in their shortest round-trip form.
fn patch_list(own: &[(usize, &BezierPatch)]) -> Value {
    let point = |q: DVec3| format!("[{:?}, {:?}, {:?}]", q.x, q.y, q.z);
    let mut text = String::from("[\n");
    for (_, p) in own {
        text.push_str("[\n");
        for row in p.points.chunks_exact(4) {
            let row: Vec<String> = row.iter().map(|q| point(*q)).collect();
            text.push_str(&format!("    {},\n", row.join(", ")));
        }
        text.push_str("],\n");
    }
    text.push(']');
    text.parse().expect("the patches' text is a TOML array")
}

/// Moves only the edited points of an object whose patches are written inline (and not
/// transformed), each in its place: every other character of the file stays. `false` when the
/// object is not of that kind.
fn edit_inline_points(object: &mut Table, own: &[(usize, &BezierPatch)], loaded: &[BezierPatch]) -> bool {
    if object.contains_key("transform") {
        return false;
    }
    let Some(list) = object.get_mut("patches").and_then(Item::as_array_mut) else {
        return false;
    };
    if list.len() != own.len() || list.iter().any(|p| p.as_array().is_none_or(|a| a.len() != 16)) {
        return false;
    }
    for (slot, (i, patch)) in list.iter_mut().zip(own) {
        let Some(points) = slot.as_array_mut() else {
            return false;
        };
        for (j, q) in patch.points.iter().enumerate() {
            if loaded.get(*i).is_some_and(|l| l.points[j] == *q) {
                continue;
            }
            let decor = points.get(j).map(|v| v.decor().clone()).unwrap_or_default();
            let mut value = vec3(*q);
            *value.decor_mut() = decor;
            points.replace(j, value);
        }
    }
    true
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
    scene_text(scene, loaded, out_dir, None).map(|(text, _)| text)
}

/// An edited object whose patches all come from B-spline surfaces' own nets, written as those
/// surfaces to an OBJ file beside the scene: its index, the file's name and its text.
type NetFile = (usize, String, String);

/// [`scene_toml`]; with `beside` (the saved scene's file stem), edited objects made of
/// surfaces' own nets are written as those B-splines to OBJ files beside it
/// (`STEM.OBJECT.obj`), returned with the text, instead of inline.
fn scene_text(
    scene: &Scene,
    loaded: &[BezierPatch],
    out_dir: Option<&Path>,
    beside: Option<&str>,
) -> Result<(String, Vec<NetFile>), SaveError> {
    let mut doc = parse_text(scene)?;
    // What the file itself says: what did not change stays as the user wrote it.
    let original = Scene::from_str(&scene.text, &scene.source, scene.base_dir.as_deref()).ok();
    match &original {
        Some(o) => write_changed_camera(&mut doc, scene, &o.camera),
        None => write_camera(&mut doc, scene),
    }
    if original.as_ref().is_none_or(|o| o.params != scene.params) {
        write_render(&mut doc, scene);
    }
    let net_files = write_patches(&mut doc, scene, loaded, beside);
    if let Some(o) = &original {
        write_changed_lights(&mut doc, scene, &o.lights);
        write_changed_materials(&mut doc, scene, &o.materials);
    }
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
    // Written beside the scene: the name needs no rebasing.
    if let Some(objects) = doc.get_mut("objects").and_then(Item::as_array_of_tables_mut) {
        for (k, name, _) in &net_files {
            if let Some(o) = objects.get_mut(*k) {
                o.insert("file", toml_edit::value(name.as_str()));
            }
        }
    }
    Ok((doc.to_string(), net_files))
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

/// A `[camera]` array of three numbers.
fn table_vec3(t: &Table, key: &str) -> Option<DVec3> {
    let a = t.get(key)?.as_array()?;
    let v: Vec<f64> = a
        .iter()
        .map(|x| x.as_float().or_else(|| x.as_integer().map(|i| i as f64)))
        .collect::<Option<_>>()?;
    (v.len() == 3).then(|| DVec3::new(v[0], v[1], v[2]))
}

/// Whether two unit vectors agree to rounding.
fn same_direction(a: DVec3, b: DVec3) -> bool {
    (a - b).length() < 1e-12
}

/// Writes into `[camera]` only what differs from `original` (the camera the file gives), as a
/// person would: `look_at` kept while the view still passes through it, no derived `up`,
/// aperture or focal distance that the file's own values already give.
fn write_changed_camera(doc: &mut DocumentMut, scene: &Scene, original: &Camera) {
    let c = &scene.camera;
    if c == original {
        return;
    }
    let t = table(doc, "camera");
    if c.position != original.position {
        t.insert("position", toml_edit::value(vec3(c.position)));
    }
    let look_at = match table_vec3(t, "look_at") {
        Some(l) if same_direction((l - c.position).normalize(), c.forward) => l,
        _ => {
            let l = c.position + c.forward * c.focal_distance;
            t.insert("look_at", toml_edit::value(vec3(l)));
            l
        }
    };
    let up = table_vec3(t, "up").unwrap_or(DVec3::Y);
    let fov = c.fov_y.to_degrees();
    let implied = Camera::look_at(c.position, look_at, up, fov, c.width, c.height, 0.0, None);
    if !same_direction(implied.up, c.up) {
        t.insert("up", toml_edit::value(vec3(c.up)));
    }
    if c.fov_y != original.fov_y {
        t.insert("fov", toml_edit::value(fov));
    }
    if (c.width, c.height) != (original.width, original.height) {
        write_size(t, scene);
    }
    if c.aperture != original.aperture {
        t.insert("aperture", toml_edit::value(c.aperture));
    }
    let focal = t
        .get("focal_distance")
        .and_then(|v| v.as_float())
        .unwrap_or(implied.focal_distance);
    if (focal - c.focal_distance).abs() > 1e-12 * c.focal_distance {
        t.insert("focal_distance", toml_edit::value(c.focal_distance));
    }
}

/// Writes into each `[[lights]]` table only what moved since `original` (the lights the file
/// gives): a point or spot light's `position`, a spot's `direction`, a sphere's `center`, a
/// quad's `corner` (its edges move with it). Every other key stays as written.
fn write_changed_lights(doc: &mut DocumentMut, scene: &Scene, original: &[Light]) {
    let Some(tables) = doc.get_mut("lights").and_then(Item::as_array_of_tables_mut) else {
        return;
    };
    for ((t, light), before) in tables.iter_mut().zip(&scene.lights).zip(original) {
        if light == before {
            continue;
        }
        let mut set = |key: &str, now: DVec3, was: DVec3| {
            if now != was {
                t.insert(key, toml_edit::value(vec3(now)));
            }
        };
        match (*light, *before) {
            (Light::Point { position: p, .. }, Light::Point { position: q, .. }) => set("position", p, q),
            (
                Light::Spot {
                    position: p,
                    direction: d,
                    ..
                },
                Light::Spot {
                    position: q,
                    direction: e,
                    ..
                },
            ) => {
                set("position", p, q);
                if !same_direction(d, e) {
                    set("direction", d, e);
                }
            }
            (Light::Sphere { center: p, .. }, Light::Sphere { center: q, .. }) => set("center", p, q),
            (Light::Quad { corner: p, .. }, Light::Quad { corner: q, .. }) => set("corner", p, q),
            _ => {}
        }
    }
}

/// Writes the colour and numbers of each material that differs from `original` (the file's)
/// into its `[materials.NAME]` table; every other key stays as written.
fn write_changed_materials(doc: &mut DocumentMut, scene: &Scene, original: &[Material]) {
    let Some(tables) = doc.get_mut("materials").and_then(Item::as_table_like_mut) else {
        return;
    };
    for (m, before) in scene.materials.iter().zip(original) {
        let Some(t) = tables.get_mut(&m.name).and_then(Item::as_table_like_mut) else {
            continue;
        };
        if m == before {
            continue;
        }
        if m.color != before.color {
            t.insert("color", toml_edit::value(vec3(m.color)));
        }
        let named_glass = t.contains_key("glass");
        let mut set = |key: &str, now: f64, was: f64| {
            if now != was {
                t.insert(key, toml_edit::value(now));
            }
        };
        match (&m.kind, &before.kind) {
            (
                MaterialKind::Diffuse { specular, shininess },
                MaterialKind::Diffuse {
                    specular: s0,
                    shininess: n0,
                },
            ) => {
                set("specular", *specular, *s0);
                set("shininess", *shininess, *n0);
            }
            (MaterialKind::Mirror { roughness }, MaterialKind::Mirror { roughness: r0 })
            | (MaterialKind::Metal { roughness, .. }, MaterialKind::Metal { roughness: r0, .. }) => {
                set("roughness", *roughness, *r0);
            }
            (
                MaterialKind::Glass { ior, roughness, .. },
                MaterialKind::Glass {
                    ior: i0,
                    roughness: r0,
                    ..
                },
            ) => {
                set("roughness", *roughness, *r0);
                // A named glass's index is its own (the file may not give one).
                if !named_glass {
                    set("ior", *ior, *i0);
                }
            }
            _ => {}
        }
    }
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

fn write_patches(
    doc: &mut DocumentMut,
    scene: &Scene,
    loaded: &[BezierPatch],
    beside: Option<&str>,
) -> Vec<NetFile> {
    let patches = scene.geometry.patches();
    let domains = scene.geometry.patch_domains();
    let mut net_files = Vec::new();
    let Some(objects) = doc.get_mut("objects").and_then(Item::as_array_of_tables_mut) else {
        return net_files;
    };
    let mut usd_rest = Vec::new();
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
        if edit_inline_points(object, &own, loaded) {
            continue;
        }
        if let Some(rest) = usd_meshes_and_spheres(scene, k, object) {
            usd_rest.push(rest);
        }
        if let Some(file) = beside.and_then(|stem| net_file(scene, k, &own, stem)) {
            for key in [
                "file",
                "builtin",
                "transform",
                "domains",
                "weights",
                "trims",
                "patches",
            ] {
                object.remove(key);
            }
            net_files.push(file);
            continue;
        }
        for key in ["file", "builtin", "transform", "domains", "weights", "trims"] {
            object.remove(key);
        }
        object.insert("patches", toml_edit::value(patch_list(&own)));
        // Patches cut from a larger surface keep their (u,v) windows, so textures still follow it.
        let windows: Vec<Window> = own.iter().map(|(i, _)| domains[*i]).collect();
        if windows.iter().any(|w| *w != Window::FULL) {
            let list: Array = windows
                .iter()
                .map(|w| Value::from(Array::from_iter([w.u0, w.u1, w.v0, w.v1])))
                .collect();
            object.insert("domains", toml_edit::value(list));
        }
        // Rational patches keep their weights (a plain patch in the same object weighs 1).
        let weights: Vec<Option<&Weights>> = own
            .iter()
            .map(|(i, _)| scene.geometry.patch_weights(*i))
            .collect();
        if weights.iter().any(Option::is_some) {
            let list: Array = weights
                .iter()
                .map(|w| Value::from(Array::from_iter(w.copied().unwrap_or([1.0; 16]))))
                .collect();
            object.insert("weights", toml_edit::value(list));
        }
        // Trimmed surfaces keep their loops, each with the patches (numbered in this object) it cuts.
        if let Some(list) = trims_array(scene, &own) {
            object.insert("trims", toml_edit::value(list));
        }
    }
    for rest in usd_rest {
        objects.push(rest);
    }
    net_files
}

/// When object `k` (its table `object`) read its surfaces from a USD file that also gave the
/// scene meshes or spheres, a copy of its table that reads only those (`nurbs = false`): the
/// edited surfaces are saved elsewhere, and the rest of the file must stay in the scene.
fn usd_meshes_and_spheres(scene: &Scene, k: usize, object: &toml_edit::Table) -> Option<toml_edit::Table> {
    let file = object.get("file")?.as_str()?;
    let owner = &scene.objects.get(k)?.name;
    let prefix = format!("{owner} /");
    let gave_more = scene.objects.iter().any(|o| o.name.starts_with(&prefix));
    if !is_usd_file(file) || !gave_more {
        return None;
    }
    let mut rest = object.clone();
    rest.insert("nurbs", toml_edit::value(false));
    Some(rest)
}

/// Object `k`'s surfaces as an OBJ file named after the scene's `stem` and the object, when
/// every one of its patches (`own`) comes from a surface's own net.
fn net_file(scene: &Scene, k: usize, own: &[(usize, &BezierPatch)], stem: &str) -> Option<NetFile> {
    let geometry = &scene.geometry;
    let mut nets: Vec<usize> = Vec::new();
    for (i, _) in own {
        let n = geometry.patch_net(*i)?;
        if nets.last() != Some(&n) {
            nets.push(n);
        }
    }
    // The nets must still give the patches (an edit of a patch's own points, which the viewer
    // does not offer for them, leaves the patches written inline instead).
    let derives = |n: usize| {
        let placed = &geometry.nets()[n];
        let derived = placed.net.patches();
        derived.len() == placed.patches.len()
            && placed
                .patches
                .clone()
                .zip(&derived)
                .all(|(k, (p, _, _))| geometry.patches()[k].0 == *p)
    };
    if !nets.iter().all(|&n| derives(n)) {
        return None;
    }
    let surfaces: Vec<_> = nets
        .iter()
        .map(|&n| {
            let placed = &geometry.nets()[n];
            let trim = geometry.domain_patch(placed.patches.start).trim;
            (placed.net.clone(), trim)
        })
        .collect();
    let refs: Vec<_> = surfaces.iter().map(|(n, t)| (n.as_ref(), t.as_ref())).collect();
    let object = scene.objects.get(k).map_or("object", |o| o.name.as_str());
    let safe = safe_name(object);
    let mut text = Vec::new();
    write_surfaces_obj(&safe, &refs, &mut text).ok()?;
    Some((k, surface_file_name(stem, object), String::from_utf8(text).ok()?))
}

/// `name` with every character but ASCII letters, digits, `-` and `_` made `_`: a file name
/// part and an OBJ group name.
fn safe_name(name: &str) -> String {
    name.chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '-' || c == '_' {
                c
            } else {
                '_'
            }
        })
        .collect()
}

/// The file an object's surfaces are written to beside a scene saved as `STEM.toml`:
/// `STEM.OBJECT.obj`, the object's name made safe for a file name.
pub fn surface_file_name(stem: &str, object: &str) -> String {
    format!("{stem}.{}.obj", safe_name(object))
}

/// The `trims` of an object's patches (`own`: scene patch index and patch), one entry per
/// trim region they share, or `None` when none is trimmed.
fn trims_array(scene: &Scene, own: &[(usize, &BezierPatch)]) -> Option<Array> {
    let mut surfaces: Vec<(std::sync::Arc<TrimRegion>, Vec<usize>)> = Vec::new();
    for (local, (i, _)) in own.iter().enumerate() {
        let Some(region) = scene.geometry.domain_patch(*i).trim else {
            continue;
        };
        match surfaces
            .iter_mut()
            .find(|(r, _)| std::sync::Arc::ptr_eq(r, &region))
        {
            Some((_, patches)) => patches.push(local),
            None => surfaces.push((region, vec![local])),
        }
    }
    if surfaces.is_empty() {
        return None;
    }
    let list = surfaces
        .iter()
        .map(|(region, patches)| {
            let loops: Array = region
                .loops()
                .iter()
                .map(|l| {
                    let segments: Array = l
                        .segments
                        .iter()
                        .map(|s| {
                            Value::from(Array::from_iter(
                                s.iter().flat_map(|p| [p.x / p.z, p.y / p.z, p.z]),
                            ))
                        })
                        .collect();
                    let mut t = toml_edit::InlineTable::new();
                    t.insert("hole", Value::from(l.hole));
                    t.insert("segments", Value::from(segments));
                    Value::from(t)
                })
                .collect();
            let mut t = toml_edit::InlineTable::new();
            t.insert(
                "patches",
                Value::from(Array::from_iter(patches.iter().map(|&k| k as i64))),
            );
            t.insert("loops", Value::from(loops));
            Value::from(t)
        })
        .collect();
    Some(list)
}

/// Saves the scene to `path` (temporary name, then rename); an existing file is replaced only
/// when `overwrite`. An edited object made of B-spline surfaces' own nets is written as those
/// surfaces to `STEM.OBJECT.obj` beside it (knots, weights and trims kept), under the same
/// rule. Returns the scene's text.
pub fn save_scene(
    scene: &Scene,
    loaded: &[BezierPatch],
    path: &Path,
    overwrite: bool,
) -> Result<String, SaveError> {
    let stem = path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "scene".into());
    let (text, net_files) = scene_text(scene, loaded, path.parent(), Some(&stem))?;
    // The surfaces first: a scene is never left naming a file that was not written.
    let dir = path.parent().unwrap_or(Path::new("."));
    for (_, name, obj) in &net_files {
        write_atomically(&dir.join(name), overwrite, |tmp| {
            std::fs::write(tmp, obj).map_err(|e| e.to_string())
        })?;
    }
    write_atomically(path, overwrite, |tmp| {
        std::fs::write(tmp, &text).map_err(|e| e.to_string())
    })?;
    Ok(text)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::BUILTIN_SCENE;

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
        assert!(
            text.contains("# The scene built into the program"),
            "comments lost"
        );
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
        assert!(plain.contains("builtin = \"teapot\""));
        assert_eq!(
            plain.matches("patches =").count(),
            BUILTIN_SCENE.matches("patches =").count(),
            "the teapot was written inline"
        );
    }

    /// The inline-patch scene with one control point moved: the saved text differs from the
    /// file in that point's line only (camera, render table, other points and comments kept).
    #[test]
    fn moving_one_point_changes_only_its_line() {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/inline_patch.toml");
        let original = std::fs::read_to_string(&path).expect("scene");
        let mut scene = Scene::from_str(&original, &path, None).expect("loads");
        let loaded: Vec<BezierPatch> = scene.geometry.patches().iter().map(|(p, _)| *p).collect();
        assert!(scene
            .geometry
            .set_control_point(0, 6, DVec3::new(0.4, 2.75, -0.3)));
        let text = scene_toml(&scene, &loaded, None).expect("saves");
        let before: Vec<&str> = original.lines().collect();
        let after: Vec<&str> = text.lines().collect();
        assert_eq!(before.len(), after.len(), "{text}");
        let changed: Vec<(&&str, &&str)> = before.iter().zip(&after).filter(|(a, b)| a != b).collect();
        assert_eq!(changed.len(), 1, "{changed:#?}");
        assert_eq!(
            *changed[0].1,
            "    [-1, 1.5, -0.333], [-0.333, 2.6, -0.333], [0.4, 2.75, -0.3], [1, 1.5, -0.333],"
        );
        let back = Scene::from_str(&text, &path, None).expect("loads back");
        assert_eq!(back.geometry.patches(), scene.geometry.patches());
    }

    /// A scene with comments, several patches written inline as FORMAT.md does, and a camera
    /// that moved: the camera is written as a person would (look_at kept where the view still
    /// passes through it, no derived up), and everything loads back.
    #[test]
    fn a_moved_camera_and_several_patches_round_trip() {
        let mut scene = Scene::builtin();
        let loaded: Vec<BezierPatch> = scene.geometry.patches().iter().map(|(p, _)| *p).collect();
        assert!(scene.geometry.set_control_point(0, 0, DVec3::new(1.5, 0.25, 2.4)));
        assert!(scene.geometry.set_control_point(7, 3, DVec3::new(-0.5, 1.0, 2.0)));
        // Slide the camera along its view: the point looked at stays on the view axis.
        let c = &mut scene.camera;
        c.position -= c.forward * 0.5;
        c.focal_distance += 0.5;
        let text = scene_toml(&scene, &loaded, None).expect("saves");
        assert!(
            text.contains("# The scene built into the program"),
            "comments lost"
        );
        let camera = text.split("[camera]").nth(1).expect("camera table");
        let camera = camera.split("\n[").next().expect("table");
        let original_up = BUILTIN_SCENE.lines().find(|l| l.starts_with("up")).expect("up");
        assert!(camera.contains(original_up), "up rewritten:{camera}");
        assert!(
            !camera.contains("focal_distance"),
            "a derived focal distance was added:{camera}"
        );
        let original = Scene::builtin();
        let original_look_at = BUILTIN_SCENE
            .lines()
            .find(|l| l.starts_with("look_at"))
            .expect("look_at");
        assert!(camera.contains(original_look_at), "look_at rewritten:{camera}");
        // Each patch's rows on lines of their own.
        assert!(text.contains("patches = [\n[\n    ["), "{text}");
        let back = Scene::from_str(&text, Path::new("saved.toml"), None).expect("loads back");
        assert_eq!(back.geometry.patches(), scene.geometry.patches());
        let (a, b) = (&back.camera, &scene.camera);
        assert!((a.position - b.position).length() < 1e-12);
        assert!((a.forward - b.forward).length() < 1e-12 && (a.up - b.up).length() < 1e-12);
        assert!((a.focal_distance - b.focal_distance).abs() < 1e-9);
        assert_eq!(back.params, original.params);
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
