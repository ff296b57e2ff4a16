//! What each fuzz target does with an input, shared by the fuzz targets (`fuzz_targets/`) and
//! the regression test that replays the kept inputs (`tests/fuzz_inputs.rs`). Every reader
//! must answer any bytes with a value or an error, never a panic; what it accepts must hold up
//! (a scene saves and loads again, prepared patches intersect to finite hits).

use std::path::Path;

use caustic::geometry::freeform::DomainPatch;
use caustic::geometry::{
    parse_bpt, parse_freeform_obj, write_freeform_obj, GeometryBuilder, Ray, TriangleMesh,
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
    let whole: Vec<DomainPatch> = patches.iter().copied().map(DomainPatch::whole).collect();
    shoot_at(&whole);
}

/// A free-form OBJ file: parse it; what it accepts has increasing windows and positive weights,
/// writes out and reads back to the same patches (a rational patch's points to rounding: they
/// are read through their homogeneous form), and up to 8 of them intersect to finite hits.
pub fn freeform(data: &[u8]) {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let Ok(patches) = parse_freeform_obj(text, Path::new("fuzz.obj")) else {
        return;
    };
    assert!(
        patches.iter().all(|d| d.window.u0 < d.window.u1
            && d.window.v0 < d.window.v1
            && d.weights
                .is_none_or(|w| w.iter().all(|&x| x > 0.0 && x.is_finite()))),
        "{patches:?}"
    );
    let mut out = Vec::new();
    write_freeform_obj(&[("fuzz".to_owned(), patches.clone())], &mut out).expect("writes to memory");
    let back = parse_freeform_obj(&String::from_utf8_lossy(&out), Path::new("fuzz-out.obj"))
        .expect("the written surfaces read back");
    assert_eq!(back.len(), patches.len());
    let close = |a: DVec3, b: DVec3| (a - b).abs().max_element() <= 1e-14 * a.abs().max_element().max(1e-300);
    for (d, e) in patches.iter().zip(&back) {
        assert_eq!(
            (d.window, d.weights),
            (e.window, e.weights),
            "windows and weights read back the same"
        );
        let (p, q) = (&d.patch, &e.patch);
        let same = match d.weights {
            None => p == q,
            Some(_) => p.points.iter().zip(&q.points).all(|(a, b)| close(*a, *b)),
        };
        assert!(same, "the written surfaces read back differently: {p:?} {q:?}");
        // Trim loops read back with the same segments, to rounding (written as projected points).
        let loops = |d: &DomainPatch| d.trim.as_ref().map(|t| t.loops().to_vec()).unwrap_or_default();
        let (a, b) = (loops(d), loops(e));
        assert_eq!(a.len(), b.len(), "trim loops read back");
        for (x, y) in a.iter().zip(&b) {
            assert_eq!((x.hole, x.segments.len()), (y.hole, y.segments.len()));
            let near = |a: DVec3, b: DVec3| {
                let (pa, pb) = (a.truncate() / a.z, b.truncate() / b.z);
                (pa - pb).abs().max_element() <= 1e-12 * pa.abs().max_element().max(1.0)
            };
            assert!(x
                .segments
                .iter()
                .flatten()
                .zip(y.segments.iter().flatten())
                .all(|(a, b)| near(*a, *b)));
        }
    }
    shoot_at(&patches);
}

/// A USD file (text, binary or package): parse it; what it accepts has increasing windows,
/// positive weights, finite meshes with indices in range and finite spheres, and up to 8 of
/// its patches intersect to finite hits.
pub fn usd(data: &[u8]) {
    let Ok(contents) = caustic::geometry::usd::parse_usd(data.to_vec(), Path::new("fuzz.usda")) else {
        return;
    };
    assert!(
        contents.patches.iter().all(|d| d.window.u0 < d.window.u1
            && d.window.v0 < d.window.v1
            && d.patch.points.iter().all(|p| p.is_finite())
            && d.weights
                .is_none_or(|w| w.iter().all(|&x| x > 0.0 && x.is_finite()))),
        "{:?}",
        contents.patches
    );
    for mesh in &contents.meshes {
        let m = &mesh.shape;
        assert!(m.positions.iter().all(|p| p.is_finite()));
        assert!(m
            .indices
            .iter()
            .flatten()
            .all(|&i| (i as usize) < m.positions.len()));
    }
    for sphere in &contents.spheres {
        assert!(
            sphere.shape.center.is_finite() && sphere.shape.radius > 0.0 && sphere.shape.radius.is_finite()
        );
    }
    shoot_at(&contents.patches);
}

/// Prepares up to 8 patches and shoots rays through their bounds: every hit must be finite,
/// its (u,v) too.
fn shoot_at(patches: &[DomainPatch]) {
    let mut builder = GeometryBuilder::default();
    for d in patches.iter().take(8) {
        builder.add_surface_patch(d.clone(), 0);
    }
    let geometry = builder.build();
    for d in patches.iter().take(8) {
        let bounds = d.patch.bounds();
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

/// A part file's header (the start of an EXR file): read it; one it accepts holds ascending
/// passes below its total, within the stated limits.
pub fn part_header(data: &[u8]) {
    let Ok(header) = caustic::render::shard::PartHeader::parse(data) else {
        return;
    };
    let limits = &caustic::settings::limits::PASSES;
    assert!(limits.contains(&header.total_passes), "{}", header.total_passes);
    assert!(header.passes.windows(2).all(|w| w[0] < w[1]));
    assert!(header.passes.last().is_none_or(|&p| p < header.total_passes));
    let side = caustic::settings::limits::IMAGE_SIDE;
    assert!(side.contains(&header.size.0) && side.contains(&header.size.1));
}

/// A part's pass list: the first four bytes are the render's total (within the limit), the
/// rest the list's text. One it accepts is ascending, below the total, and written again as
/// runs reads back the same.
pub fn pass_list(data: &[u8]) {
    use caustic::render::shard::sums::{parse_passes, passes_text};
    let (Some(total), Some(text)) = (data.get(..4), data.get(4..)) else {
        return;
    };
    let total = u32::from_le_bytes([total[0], total[1], total[2], total[3]]) % 10_000_001;
    let Ok(text) = std::str::from_utf8(text) else {
        return;
    };
    let Ok(passes) = parse_passes(text, total) else {
        return;
    };
    assert!(passes.windows(2).all(|w| w[0] < w[1]));
    assert!(passes.last().is_none_or(|&p| p < total));
    assert_eq!(parse_passes(&passes_text(&passes), total).as_ref(), Ok(&passes));
}

/// The value a POSIX shell makes of `word` (single quotes, backslash outside quotes, plain
/// characters), or `None` if anything in it is special to the shell outside quotes.
fn shell_value(word: &str) -> Option<String> {
    let mut out = String::new();
    let mut chars = word.chars();
    while let Some(c) = chars.next() {
        match c {
            '\'' => loop {
                match chars.next()? {
                    '\'' => break,
                    q => out.push(q),
                }
            },
            '\\' => out.push(chars.next()?),
            c if c.is_ascii_alphanumeric() || "/._-=:,+@%".contains(c) => out.push(c),
            _ => return None,
        }
    }
    Some(out)
}

/// A name for a farm: quoted as one shell word it reads back as itself; in a comment it holds
/// no line break; as the image and folder of a Kubernetes manifest it stays a value of the
/// two Jobs, and a Slurm script is written or refused without a panic.
pub fn farm_quote(data: &[u8]) {
    use caustic::farm::quote::{comment, shell_word};
    use std::os::unix::ffi::OsStrExt;
    let value = std::ffi::OsStr::from_bytes(data);
    match shell_word(value) {
        Ok(word) => {
            let text = value.to_str().expect("only UTF-8 is quoted");
            assert_eq!(shell_value(&word).as_deref(), Some(text), "{word}");
        }
        Err(_) => assert!(value.to_str().is_none() || data.contains(&0)),
    }
    let line = comment(value);
    assert!(
        !line.contains(['\n', '\r', '\u{85}', '\u{2028}', '\u{2029}', '\u{b}', '\u{c}']),
        "{line}"
    );
    let Some(text) = value.to_str() else {
        return;
    };
    let mut job = caustic::farm::Job {
        scene: "/data/scene.toml".into(),
        shards: 2,
        passes: 4,
        out: format!("/data/{text}").into(),
        threads: 1,
        program: "caustic".into(),
        image: Some(text.to_owned()),
        partition: Some(text.to_owned()),
        volume_claim: "caustic-data".into(),
        name: "caustic".into(),
        wait: false,
        render_args: Vec::new(),
    };
    let _ = caustic::farm::slurm::slurm_script(&job);
    if text.is_empty() {
        job.image = Some("i".into());
    }
    if let Ok(manifest) = caustic::farm::kubernetes::kubernetes_manifest(&job) {
        let docs: Vec<serde_yaml_ng::Value> = serde_yaml_ng::Deserializer::from_str(&manifest)
            .map(|d| <serde_yaml_ng::Value as serde::Deserialize>::deserialize(d).expect("parses"))
            .collect();
        assert_eq!(docs.len(), 2, "{manifest}");
        for doc in &docs {
            assert_eq!(doc["kind"].as_str(), Some("Job"));
            let container = &doc["spec"]["template"]["spec"]["containers"][0];
            assert_eq!(container["image"].as_str(), job.image.as_deref(), "{manifest}");
            assert_eq!(container.as_mapping().map(|m| m.len()), Some(5), "{manifest}");
        }
    }
}
