//! The `[camera]` table.

use glam::DVec3;
use toml::Spanned;

use super::diagnostics::{v3, Ctx, Result, Table};
use crate::scene::camera::Camera;
use crate::scene::format::CameraDesc;
use crate::settings::limits;

pub(super) fn camera(ctx: &Ctx, desc: &Spanned<CameraDesc>) -> Result<Camera> {
    let t = Table {
        ctx,
        span: desc.span(),
        name: "[camera]".into(),
    };
    let d = desc.get_ref();
    let position = v3(&d.position);
    let look_at = v3(&d.look_at);
    let up = d.up.as_ref().map(v3).unwrap_or(DVec3::Y);
    let view = look_at - position;
    if view.length_squared() == 0.0 {
        return Err(t.err("'look_at' equals 'position': no view direction"));
    }
    if view.normalize().cross(up.normalize_or_zero()).length() < 1e-9 {
        return Err(t.err("'up' is parallel to the view direction (or zero)"));
    }
    let fov = d.fov.0;
    if !(fov > 0.0 && fov < 180.0) {
        return Err(t.err(format!("'fov' must be between 0 and 180 degrees, got {fov}")));
    }
    for (field, v) in [("width", d.width), ("height", d.height)] {
        limits::image_side(v).map_err(|e| t.err(format!("'{field}' {e}")))?;
    }
    let aperture = t.non_negative("aperture", d.aperture.map_or(0.0, |r| r.0))?;
    let focal_distance = d
        .focal_distance
        .map(|r| t.positive("focal_distance", r.0))
        .transpose()?;
    let mut camera = Camera::look_at(
        position,
        look_at,
        up,
        fov,
        d.width,
        d.height,
        aperture,
        focal_distance,
    );
    camera.near = t.non_negative("near", d.near.map_or(0.0, |r| r.0))?;
    Ok(camera)
}
