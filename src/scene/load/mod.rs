//! Reading and validating scene files. Every error names the file, the line of the table it
//! concerns, the table (`objects[2] (sphere)`) and the field, and says what was expected.
//!
//! Files: `diagnostics` (errors and the checks tables share), `camera`, `materials` (and
//! textures), `objects` (and their transforms), `trims` (inline trim loops), `usd_objects`
//! (what a USD file adds beside its surfaces) and `lights` (and the surfaces of area lights).

mod camera;
mod diagnostics;
mod lights;
mod materials;
mod objects;
mod trims;
mod usd_objects;

use std::collections::BTreeMap;
use std::path::Path;

use glam::DVec3;
use toml::Spanned;

use super::format::SceneFile;
use super::{RenderParams, Scene};
use crate::geometry::GeometryBuilder;
use diagnostics::{v3, Ctx, Result, Table};

pub use diagnostics::SceneError;

pub(super) fn load_file(path: &Path) -> Result<Scene> {
    let text =
        crate::input_file::read_text(path, crate::input_file::MAX_TEXT_BYTES).map_err(|e| SceneError {
            path: path.to_owned(),
            line: 0,
            message: format!("the scene file {e}"),
        })?;
    let base = path.parent().map(Path::to_owned).unwrap_or_default();
    load_str(&text, path, Some(&base))
}

pub(super) fn load_str(text: &str, path: &Path, base_dir: Option<&Path>) -> Result<Scene> {
    let ctx = Ctx { path, text, base_dir };
    let file: SceneFile = toml::from_str(text).map_err(|e| {
        let span = e.span().unwrap_or(0..0);
        ctx.err(&span, e.message().trim().to_owned())
    })?;

    let camera = camera::camera(&ctx, &file.camera)?;
    let params = match &file.render {
        Some(r) => render_params(&ctx, r)?,
        None => RenderParams::default(),
    };
    let background = file.background.as_ref().map(v3).unwrap_or(DVec3::ZERO);
    if background.cmplt(DVec3::ZERO).any() {
        return Err(ctx.err(
            &(0..0),
            format!("'background' must not be negative, got {background}"),
        ));
    }

    let mut materials = Vec::new();
    let mut textures = Vec::new();
    let mut material_index = BTreeMap::new();
    for (name, desc) in &file.materials {
        let m = materials::material(&ctx, name, desc, &mut textures)?;
        material_index.insert(name.clone(), materials.len());
        materials.push(m);
    }

    let mut builder = GeometryBuilder::default();
    let mut objects = Vec::new();
    let mut extras = Vec::new();
    for object in file.objects.iter().enumerate() {
        objects::object(
            &ctx,
            object,
            &material_index,
            &mut builder,
            &mut objects,
            &mut extras,
        )?;
    }
    let warnings = usd_objects::add_extras(extras, &mut builder, &mut materials, &mut objects);

    let (lights, light_objects) =
        lights::add_lights(&ctx, &file.lights, &mut builder, &mut materials, &mut objects)?;
    if lights.is_empty() {
        return Err(ctx.err(&(0..0), "the scene has no [[lights]]: nothing would be visible"));
    }
    if objects.is_empty() {
        return Err(ctx.err(&(0..0), "the scene has no [[objects]]"));
    }

    Ok(Scene {
        source: path.to_owned(),
        camera,
        params,
        background,
        materials,
        textures,
        objects,
        lights,
        light_objects,
        geometry: builder.build(),
        text: text.into(),
        base_dir: base_dir.map(Path::to_path_buf),
        warnings,
    })
}

/// The `[render]` table (read straight into [`RenderParams`]), checked by its one `validate`.
fn render_params(ctx: &Ctx, desc: &Spanned<RenderParams>) -> Result<RenderParams> {
    let t = Table {
        ctx,
        span: desc.span(),
        name: "[render]".into(),
    };
    let params = desc.get_ref().clone();
    params.validate().map_err(|e| t.err(e))?;
    Ok(params)
}
