//! Files in, shapes out: malformed .bpt and .obj give errors naming file and line, never panics;
//! every shape kind shares one BVH and agrees with testing each shape on its own.

mod common;

use std::path::Path;

use caustic::geometry::{load_bpt, parse_bpt, GeometryBuilder, Plane, Quad, Ray, Sphere, TriangleMesh};
use common::*;
use glam::DVec3;

fn patch_text(points: usize) -> String {
    let mut text = String::from("1\n3 3\n");
    for k in 0..points {
        text.push_str(&format!("{} {} 0\n", k / 4, k % 4));
    }
    text
}

#[test]
fn malformed_bpt_files_are_reported_with_line_numbers() {
    let cases: Vec<(String, &str)> = vec![
        (
            String::new(),
            "scene.bpt:0: the file ends where the patch count was expected",
        ),
        (
            "two\n".into(),
            "scene.bpt:1: expected the number of patches, found 'two'",
        ),
        ("0\n".into(), "scene.bpt:1: the file declares 0 patches"),
        (
            "1\n3 2\n".into(),
            "scene.bpt:2: patch 1: expected degrees '3 3' (only bicubic patches), found '3 2'",
        ),
        (
            patch_text(15),
            "scene.bpt:17: the file ends where control point 16 of patch 1 was expected",
        ),
        (
            patch_text(16).replace("1 2 0", "1 2"),
            "scene.bpt:9: patch 1, control point 7: expected 3 numbers 'x y z', found 2",
        ),
        (
            patch_text(16).replace("2 3 0", "2 3 NaN"),
            "scene.bpt:14: patch 1, control point 12: 'NaN' is not a finite number",
        ),
        (
            patch_text(16).replace("0 1 0", "0 1 1e999"),
            "scene.bpt:4: patch 1, control point 2: '1e999' is not a finite number",
        ),
        (
            patch_text(16) + "3 3\n",
            "scene.bpt:19: unexpected content after the 1 declared patches: '3 3'",
        ),
        (
            "2\n".to_string() + &patch_text(16)[2..],
            "the file ends where the degrees '3 3' of patch 2 was expected",
        ),
    ];
    for (text, expected) in cases {
        let err = parse_bpt(&text, Path::new("scene.bpt")).expect_err(expected);
        assert!(
            err.to_string().contains(expected),
            "got '{err}', expected '{expected}'"
        );
    }
    assert_eq!(
        parse_bpt(&patch_text(16), Path::new("ok.bpt"))
            .map(|p| p.len())
            .ok(),
        Some(1)
    );
    let missing = load_bpt(Path::new("/nonexistent/teapot.bpt")).expect_err("missing file");
    assert!(missing
        .to_string()
        .starts_with("/nonexistent/teapot.bpt:0: the file does not exist"));
}

#[test]
fn obj_meshes_load_and_bad_ones_are_errors() {
    let dir = tempfile::tempdir().expect("temp dir");
    let write = |name: &str, text: &str| {
        let path = dir.path().join(name);
        std::fs::write(&path, text).expect("write");
        path
    };
    let good = write(
        "quad.obj",
        "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nf 1/1 2/2 3/3 4/4\n",
    );
    let mesh = TriangleMesh::load_obj(&good).expect("good OBJ");
    assert_eq!(mesh.indices.len(), 2, "the quad face is triangulated");
    assert_eq!(mesh.texcoords.len(), 4);

    let cases = [
        (
            "garbage.obj",
            "v a b c\nf 1 2 3\n",
            "garbage.obj: cannot read OBJ mesh",
        ),
        (
            "index.obj",
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n",
            "index.obj: cannot read OBJ mesh",
        ),
        (
            "empty.obj",
            "# nothing here\nv 0 0 0\n",
            "empty.obj: the file holds no faces",
        ),
    ];
    for (name, text, expected) in cases {
        let err = TriangleMesh::load_obj(&write(name, text)).expect_err(name);
        assert!(err.to_string().contains(expected), "{name}: got '{err}'");
    }
    let err = TriangleMesh::load_obj(&dir.path().join("missing.obj")).expect_err("missing");
    assert!(
        err.to_string().contains("missing.obj: the file does not exist"),
        "got '{err}'"
    );
}

#[test]
fn one_bvh_holds_every_shape_kind() {
    let patches = teapot_from_assets();
    let mut builder = GeometryBuilder::default();
    let sphere = Sphere {
        center: DVec3::new(-4.0, 0.0, 1.0),
        radius: 1.0,
    };
    builder.add_sphere(sphere, 1);
    let quad = Quad {
        corner: DVec3::new(3.5, -1.0, 0.0),
        edge_u: DVec3::Y * 2.0,
        edge_v: DVec3::Z * 2.0,
    };
    builder.add_quad(quad, 2);
    builder.add_plane(
        Plane {
            point: DVec3::new(0.0, 0.0, -0.01),
            normal: DVec3::Z,
        },
        3,
    );
    let mesh = TriangleMesh {
        positions: vec![
            DVec3::new(1.5, -3.0, 2.5),
            DVec3::new(3.0, -3.0, 2.5),
            DVec3::new(2.2, -3.0, 4.0),
        ],
        indices: vec![[0, 1, 2]],
        ..Default::default()
    };
    builder.add_mesh(mesh.clone(), 4);
    for p in &patches {
        builder.add_patch(*p, 5);
    }
    let geometry = builder.build();
    // Each shape alone, for the brute-force nearest.
    let alone: Vec<caustic::geometry::SceneGeometry> = {
        let mut v = Vec::new();
        let mut b = GeometryBuilder::default();
        b.add_sphere(sphere, 1);
        v.push(b.build());
        let mut b = GeometryBuilder::default();
        b.add_quad(quad, 2);
        v.push(b.build());
        let mut b = GeometryBuilder::default();
        b.add_plane(
            Plane {
                point: DVec3::new(0.0, 0.0, -0.01),
                normal: DVec3::Z,
            },
            3,
        );
        v.push(b.build());
        let mut b = GeometryBuilder::default();
        b.add_mesh(mesh, 4);
        v.push(b.build());
        for p in &patches {
            let mut b = GeometryBuilder::default();
            b.add_patch(*p, 5);
            v.push(b.build());
        }
        v
    };
    let mut rng = rng(12);
    let mut kinds = std::collections::HashSet::new();
    for _ in 0..3000 {
        let origin = DVec3::new(0.0, -9.0, 4.0) + unit_vector(&mut rng) * 2.0;
        let target = DVec3::new(0.0, 0.0, 1.0) + unit_vector(&mut rng) * 4.5;
        let ray = Ray::new(origin, target - origin);
        let hit = geometry.intersect(&ray, f64::INFINITY);
        let nearest = alone
            .iter()
            .filter_map(|g| g.intersect(&ray, f64::INFINITY))
            .min_by(|a, b| a.t.total_cmp(&b.t));
        match (hit, nearest) {
            (Some(h), Some(n)) => {
                assert!((h.t - n.t).abs() < 1e-9, "{} vs {}", h.t, n.t);
                assert_eq!(h.object, n.object);
                kinds.insert(std::mem::discriminant(&h.shape));
                assert_eq!(geometry.occluded(&ray, h.t * 0.999), h.t * 0.999 > n.t);
                assert!(geometry.occluded(&ray, h.t * 1.001));
            }
            (None, None) => assert!(!geometry.occluded(&ray, f64::INFINITY)),
            (a, b) => panic!("BVH {a:?} vs brute force {b:?}"),
        }
    }
    assert_eq!(kinds.len(), 5, "every shape kind was hit: {kinds:?}");
}
