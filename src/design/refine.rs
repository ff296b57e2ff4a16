//! Giving a design more control points to move: a surface of Bézier patches is split by de
//! Casteljau subdivision (each patch into four, `levels` times) — the same surface exactly,
//! with four times the points a level — and written inline into the scene's text, so that the
//! designed scene saves as any edited scene does. The mitsuba tutorial's heightmap doubles its
//! resolution for the same reason: a coarse surface finds the broad shape, a fine one the
//! detail.

use toml_edit::{Array, DocumentMut, Item, Value};

use crate::geometry::bezier::BezierPatch;
use crate::scene::Scene;

/// `scene` with object `object`'s patches (named `name` in its text) split `levels` times,
/// read again from the edited text. Surfaces with their own net, trimmed or rational ones are
/// left as they are (`None`): a net is designed through its own points, and the others would
/// lose their weights or trims inline.
pub fn refined(scene: &Scene, (object, name): (u32, &str), levels: u32) -> Result<Option<Scene>, String> {
    let geometry = &scene.geometry;
    let own: Vec<usize> = (0..geometry.patches().len())
        .filter(|&k| geometry.patches()[k].1 == object)
        .collect();
    let plain = own.iter().all(|&k| {
        geometry.patch_net(k).is_none()
            && geometry.patch_trim(k).is_none()
            && geometry.patch_weights(k).is_none()
    });
    if levels == 0 || own.is_empty() || !plain {
        return Ok(None);
    }
    let mut patches: Vec<BezierPatch> = own.iter().map(|&k| geometry.patches()[k].0).collect();
    for _ in 0..levels {
        patches = patches.iter().flat_map(BezierPatch::split_quad).collect();
    }
    if patches.len() + geometry.patches().len() > crate::settings::limits::MAX_PATCHES {
        return Err(format!(
            "refining the surface {levels} times would make too many patches"
        ));
    }
    let mut doc: DocumentMut = scene.text.parse().map_err(|e| format!("the scene's text: {e}"))?;
    let objects = doc
        .get_mut("objects")
        .and_then(Item::as_array_of_tables_mut)
        .ok_or("the scene has no [[objects]]")?;
    let table = objects
        .iter_mut()
        .find(|t| t.get("name").and_then(Item::as_str) == Some(name))
        .ok_or_else(|| format!("no [[objects]] table is named '{name}'"))?;
    for key in ["file", "builtin", "transform", "domains", "weights", "trims"] {
        table.remove(key);
    }
    let list: Array = patches
        .iter()
        .map(|p| {
            Value::from(Array::from_iter(
                p.points
                    .iter()
                    .map(|q| Value::from(Array::from_iter(q.to_array()))),
            ))
        })
        .collect();
    table.insert("patches", toml_edit::value(list));
    let text = doc.to_string();
    Scene::from_str(&text, &scene.source, scene.base_dir.as_deref())
        .map(Some)
        .map_err(|e| format!("the refined scene does not load: {e}"))
}
