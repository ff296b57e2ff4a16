//! What each fuzz target does with an input, shared by the fuzz targets (`fuzz_targets/`) and
//! the regression test that replays the kept inputs (`tests/fuzz_inputs.rs`). Every reader
//! must answer any bytes with a value or an error, never a panic; what it accepts must hold up
//! (a scene saves and loads again, prepared patches intersect to finite hits).

use std::path::Path;

use caustic::geometry::{
    parse_bpt, parse_freeform_obj, write_freeform_obj, BezierPatch, GeometryBuilder, Ray, TriangleMesh,
    Window,
};
use caustic::scene::texture::TextureSource;
use caustic::scene::Scene;
use glam::DVec3;

/// A scene file: parse it; one that loads must save (settings and size laid in) and load again.
pub fn scene(data: &[u8]) {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let Ok(scene) = Scene::from_str(text, Path::new("fuzz.toml"), None) else {
        return;
    };
    let saved = caustic::scene::save::settings_toml(&scene).expect("a loaded scene saves");
    let again = Scene::from_str(&saved, Path::new("fuzz-saved.toml"), None);
    assert!(
        again.is_ok(),
        "the saved scene does not load: {:?}\n{saved}",
        again.err()
    );
}

/// A `.bpt` file: parse it; up to 8 patches it accepts are prepared and shot at with rays
/// through their bounds, and every hit must be finite.
pub fn bpt(data: &[u8]) {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let Ok(patches) = parse_bpt(text, Path::new("fuzz.bpt")) else {
        return;
    };
    let whole: Vec<(BezierPatch, Window)> = patches.iter().map(|p| (*p, Window::FULL)).collect();
    shoot_at(&whole);
}

/// A free-form OBJ file: parse it; what it accepts has increasing windows, writes out and
/// reads back to the same patches, and up to 8 of them intersect to finite hits.
pub fn freeform(data: &[u8]) {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let Ok(patches) = parse_freeform_obj(text, Path::new("fuzz.obj")) else {
        return;
    };
    assert!(
        patches.iter().all(|(_, w)| w.u0 < w.u1 && w.v0 < w.v1),
        "{patches:?}"
    );
    let mut out = Vec::new();
    write_freeform_obj(&[("fuzz".to_owned(), patches.clone())], &mut out).expect("writes to memory");
    let back = parse_freeform_obj(&String::from_utf8_lossy(&out), Path::new("fuzz-out.obj"));
    assert_eq!(
        back.ok().as_ref(),
        Some(&patches),
        "the written surfaces read back differently"
    );
    shoot_at(&patches);
}

/// Prepares up to 8 patches and shoots rays through their bounds: every hit must be finite,
/// its (u,v) too.
fn shoot_at(patches: &[(BezierPatch, Window)]) {
    let mut builder = GeometryBuilder::default();
    for (p, w) in patches.iter().take(8) {
        builder.add_patch_in(*p, *w, 0);
    }
    let geometry = builder.build();
    for (p, _) in patches.iter().take(8) {
        let bounds = p.bounds();
        let centre = (bounds.min + bounds.max) * 0.5;
        let size = (bounds.max - bounds.min).length().max(1e-9);
        for dir in [
            DVec3::X,
            DVec3::Y,
            DVec3::Z,
            DVec3::new(1.0, 1.0, 1.0).normalize(),
        ] {
            let ray = Ray::new(centre - dir * 2.0 * size, dir);
            if let Some(hit) = geometry.intersect(&ray, f64::INFINITY) {
                assert!(
                    hit.t.is_finite() && hit.point.is_finite() && hit.uv().is_finite(),
                    "non-finite hit {hit:?}"
                );
            }
        }
    }
}

/// An OBJ file: parse it; a mesh it accepts has indices inside its vertices.
pub fn obj(data: &[u8]) {
    let mut reader = std::io::BufReader::new(data);
    let Ok(mesh) = TriangleMesh::parse_obj(&mut reader, Path::new("fuzz.obj")) else {
        return;
    };
    let n = mesh.positions.len() as u32;
    assert!(mesh.indices.iter().flatten().all(|&i| i < n));
}

/// An image file: decode it; a texture it gives has as many texels as pixels.
pub fn texture(data: &[u8]) {
    if let Ok(TextureSource::Image {
        width,
        height,
        texels,
        ..
    }) = TextureSource::decode(data, Path::new("fuzz.png"))
    {
        assert_eq!(texels.len(), width * height);
        assert!(texels.iter().all(|t| t.is_finite()));
    }
}
