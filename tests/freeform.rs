//! Wavefront OBJ free-form surfaces: B-splines become Bézier patches by knot insertion and
//! match the B-spline evaluated directly (de Boor), Bézier surfaces round-trip bit for bit
//! through `export-obj --freeform`, textures follow the surface's own parameters, and every
//! malformed file is an error naming the file and the line.

mod common;

use std::path::Path;

use caustic::geometry::bspline::{BsplineSurface, Knots};
use caustic::geometry::freeform::DomainPatch;
use caustic::geometry::{parse_freeform_obj, write_freeform_obj, BezierPatch, Ray, Window};
use caustic::scene::Scene;
use glam::DVec3;

/// An OBJ file of one bicubic B-spline surface over an `nu` × `nv` grid of points (heights
/// from a fixed wave), with the given knots and range.
fn bspline_obj(nu: usize, nv: usize, u_knots: &[f64], v_knots: &[f64], range: [f64; 4]) -> String {
    surface_obj(("bspline", [3, 3]), (nu, nv), (u_knots, v_knots), range)
}

/// An OBJ file of one surface of type `kind` and `degrees` over an `nu` × `nv` grid of points
/// (heights from a fixed wave), with the given `parm` values and range.
fn surface_obj(
    (kind, degrees): (&str, [usize; 2]),
    (nu, nv): (usize, usize),
    (u_knots, v_knots): (&[f64], &[f64]),
    range: [f64; 4],
) -> String {
    let mut text = String::from("# test surface\n");
    for j in 0..nv {
        for i in 0..nu {
            let (x, y) = (i as f64 * 0.5, j as f64 * 0.4);
            let z = (1.3 * x).sin() * (0.7 * y + 0.2).cos() + 0.1 * (i * j) as f64;
            text += &format!("v {x} {y} {z}\n");
        }
    }
    let indices: Vec<String> = (1..=nu * nv).map(|k| k.to_string()).collect();
    let join = |k: &[f64]| k.iter().map(f64::to_string).collect::<Vec<_>>().join(" ");
    text += &format!(
        "cstype {kind}\ndeg {} {}\nsurf {} {} {} {} {}\nparm u {}\nparm v {}\nend\n",
        degrees[0],
        degrees[1],
        range[0],
        range[1],
        range[2],
        range[3],
        indices.join(" "),
        join(u_knots),
        join(v_knots)
    );
    text
}

/// The points of an OBJ text's `v` lines.
fn vertices(text: &str) -> Vec<DVec3> {
    text.lines()
        .filter_map(|l| l.strip_prefix("v "))
        .map(|l| {
            let n: Vec<f64> = l.split_whitespace().map(|w| w.parse().expect("number")).collect();
            DVec3::new(n[0], n[1], n[2])
        })
        .collect()
}

/// The non-rational patches of `text` with their windows.
fn parse(text: &str) -> Result<Vec<(BezierPatch, Window)>, String> {
    let patches = parse_freeform_obj(text, Path::new("surface.obj")).map_err(|e| e.to_string())?;
    assert!(patches.iter().all(|d| d.weights.is_none()), "a rational patch");
    Ok(patches.into_iter().map(|d| (d.patch, d.window)).collect())
}

#[test]
fn a_clamped_4x4_bspline_is_its_bezier_patch() {
    let clamped = [0.0, 0.0, 0.0, 0.0, 1.0, 1.0, 1.0, 1.0];
    let text = bspline_obj(4, 4, &clamped, &clamped, [0.0, 1.0, 0.0, 1.0]);
    let patches = parse(&text).expect("reads");
    assert_eq!(patches.len(), 1);
    let (patch, window) = patches[0];
    assert_eq!(window, Window::FULL);
    // OBJ lists u fastest: vertex i + 4j is the patch's P_ij.
    let points = vertices(&text);
    for i in 0..4 {
        for j in 0..4 {
            assert_eq!(patch.point(i, j), points[i + 4 * j], "P_{i}{j}");
        }
    }
}

#[test]
fn a_uniform_5x5_bspline_becomes_four_patches_on_the_surface() {
    let uniform: Vec<f64> = (0..9).map(f64::from).collect();
    let text = bspline_obj(5, 5, &uniform, &uniform, [3.0, 5.0, 3.0, 5.0]);
    let patches = parse(&text).expect("reads");
    assert_eq!(patches.len(), 4);
    let points = vertices(&text);
    let surface = BsplineSurface {
        points,
        u_knots: Knots::new(uniform.clone(), 5, 'u').expect("knots"),
        v_knots: Knots::new(uniform, 5, 'v').expect("knots"),
        range: Window {
            u0: 3.0,
            u1: 5.0,
            v0: 3.0,
            v1: 5.0,
        },
    };
    let mut windows: Vec<[f64; 4]> = patches.iter().map(|(_, w)| [w.u0, w.u1, w.v0, w.v1]).collect();
    windows.sort_by(|a, b| a.partial_cmp(b).expect("finite"));
    assert_eq!(
        windows,
        [
            [3.0, 4.0, 3.0, 4.0],
            [3.0, 4.0, 4.0, 5.0],
            [4.0, 5.0, 3.0, 4.0],
            [4.0, 5.0, 4.0, 5.0]
        ]
    );
    let mut worst: f64 = 0.0;
    for (patch, w) in &patches {
        for a in 0..=10 {
            for b in 0..=10 {
                let (s, t) = (a as f64 / 10.0, b as f64 / 10.0);
                let uv = w.map(s, t);
                worst = worst.max((patch.eval(s, t) - surface.eval(uv.x, uv.y)).length());
            }
        }
    }
    assert!(worst < 1e-12, "Bézier pieces stray {worst:e} from the B-spline");
}

#[test]
fn a_sub_range_and_repeated_knots_still_match_de_boor() {
    let u = [0.0, 0.0, 0.0, 0.0, 0.3, 0.3, 0.7, 1.0, 1.0, 1.0, 1.0];
    let v = [0.0, 0.0, 0.0, 0.0, 0.5, 1.0, 1.0, 1.0, 1.0];
    let text = bspline_obj(7, 5, &u, &v, [0.1, 0.9, 0.2, 1.0]);
    let patches = parse(&text).expect("reads");
    // u: spans [0.1,0.3], [0.3,0.7], [0.7,0.9]; v: [0.2,0.5], [0.5,1].
    assert_eq!(patches.len(), 6);
    let points = vertices(&text);
    let surface = BsplineSurface {
        points,
        u_knots: Knots::new(u.to_vec(), 7, 'u').expect("knots"),
        v_knots: Knots::new(v.to_vec(), 5, 'v').expect("knots"),
        range: Window::FULL,
    };
    for (patch, w) in &patches {
        for (s, t) in [(0.0, 0.0), (0.25, 0.75), (0.5, 0.5), (1.0, 1.0), (0.9, 0.1)] {
            let uv = w.map(s, t);
            let d = (patch.eval(s, t) - surface.eval(uv.x, uv.y)).length();
            assert!(d < 1e-12, "{d:e} at {uv} in {w:?}");
        }
    }
}

#[test]
fn bezier_surfaces_with_several_segments_and_negative_indices_read() {
    // A 7×4 Bézier surface: two segments along u (breakpoints 0, 2, 5), one along v.
    let mut text = String::new();
    for j in 0..4 {
        for i in 0..7 {
            text += &format!("v {} {} {}\n", i, j, (i * j) % 3);
        }
    }
    let indices: Vec<String> = (1..=28).rev().map(|k| format!("-{k}")).collect();
    text += &format!(
        "cstype bezier\ndeg 3 3\nsurf 0 5 0 1 \\\n {}\nparm u 0 2 5\nparm v 0 1\nend\n",
        indices.join(" ")
    );
    let patches = parse(&text).expect("reads");
    assert_eq!(patches.len(), 2);
    assert_eq!(
        patches[0].1,
        Window {
            u0: 0.0,
            u1: 2.0,
            v0: 0.0,
            v1: 1.0
        }
    );
    assert_eq!(
        patches[1].1,
        Window {
            u0: 2.0,
            u1: 5.0,
            v0: 0.0,
            v1: 1.0
        }
    );
    // Segment 2 starts at column 3: P_00 of the second patch is vertex (3, 0).
    assert_eq!(patches[1].0.point(0, 0), DVec3::new(3.0, 0.0, 0.0));
    assert_eq!(patches[1].0.point(3, 3), DVec3::new(6.0, 3.0, 0.0));
}

#[test]
fn patches_round_trip_bit_for_bit_through_the_freeform_writer() {
    let teapot = common::teapot_from_assets();
    let mut rng = common::rng(7);
    let patches: Vec<(BezierPatch, Window)> = teapot
        .iter()
        .map(|p| {
            let mut p = *p;
            // Digits that a short decimal cannot hold.
            p.points[5] += common::unit_vector(&mut rng) * 1e-3;
            (p, Window::FULL)
        })
        .chain([(
            teapot[0],
            Window {
                u0: -0.1,
                u1: 1.0 / 3.0,
                v0: 2.0,
                v1: 7.5,
            },
        )])
        .collect();
    let mut out = Vec::new();
    let groups = [(
        "teapot".to_owned(),
        patches
            .iter()
            .map(|&(patch, window)| DomainPatch {
                window,
                ..DomainPatch::whole(patch)
            })
            .collect(),
    )];
    write_freeform_obj(&groups, &mut out).expect("writes");
    let text = String::from_utf8(out).expect("utf-8");
    assert_eq!(parse(&text).expect("reads back"), patches);
}

/// The error message for `text`, which must fail.
fn error(text: &str) -> String {
    match parse(text) {
        Ok(p) => panic!("read {} patches from a bad file:\n{text}", p.len()),
        Err(e) => e,
    }
}

fn sixteen_points() -> String {
    (0..16).map(|k| format!("v {} {} 0\n", k % 4, k / 4)).collect()
}

const SURF: &str = "surf 0 1 0 1 1 2 3 4 5 6 7 8 9 10 11 12 13 14 15 16";

#[test]
fn malformed_surfaces_are_errors_naming_the_file_and_line() {
    let p = sixteen_points();
    let cases = [
        (
            format!("{}v 3 3 0 0\ncstype rat bspline\ndeg 3 3\n{SURF}\nparm u 0 0 0 0 1 1 1 1\nparm v 0 0 0 0 1 1 1 1\nend\n", &p[..p.rfind("v ").expect("v")]),
            "surface.obj:19: control point on line 16 has weight 0: a rational surface's weights must be above 0",
        ),
        (
            format!("{}v 3 3 0 2\ncstype bezier\ndeg 3 3\n{SURF}\nparm u 0 1\nparm v 0 1\nend\n", &p[..p.rfind("v ").expect("v")]),
            "surface.obj:19: control point on line 16 has weight 2, but the surface is not rational (use 'cstype rat bezier')",
        ),
        (
            format!("{p}cstype bspline\ndeg 4 3\n{SURF}\nparm u 0 0 0 0 0 1 1 1 1 1\nparm v 0 0 0 0 1 1 1 1\nend\n"),
            "surface.obj:19: degree 4 along u is not supported ('deg 4 3' on line 18); surfaces of degree 1 to 3 are",
        ),
        (
            format!("{p}cstype bspline\ndeg 3\n{SURF}\nparm u 0 0 0 0 1 1 1 1\nparm v 0 0 0 0 1 1 1 1\nend\n"),
            "surface.obj:19: 'deg' needs two degrees, along u and v, ('deg 3' on line 18)",
        ),
        (
            format!("{p}cstype bspline\ndeg 2 2\n{SURF}\nparm u 0 0 0 1 1 1\nparm v 0 0 0 1 1 1\nend\n"),
            "surface.obj:19: the surface lists 16 control points; its 'parm' lines (lines 20 and 21) need 3 × 3 = 9",
        ),
        (
            format!("{p}cstype bspline\ndeg 3 3\n{SURF}\nparm u 0 0 0 0 1 1 1 1\nend\n"),
            "surface.obj:21: the surface on line 19 has no 'parm v' line",
        ),
        (
            format!("{p}cstype bspline\ndeg 3 3\n{SURF}\nparm u 0 0 0 0 1 1 1 1 2\nparm v 0 0 0 0 1 1 1 1\nend\n"),
            "surface.obj:19: the surface lists 16 control points; its 'parm' lines (lines 20 and 21) need 5 × 4 = 20",
        ),
        (
            format!("{p}cstype bspline\ndeg 3 3\nsurf 0 1 0 1 1 2 3 4 5 6 7 8\nparm u 0 0 0 0 1 1 1 1\nparm v 0 0 0 1 1 1\nend\n"),
            "surface.obj:21: a curve of degree 3 needs at least 4 control points along v, found 2",
        ),
        (
            format!("{p}cstype bspline\ndeg 3 3\n{SURF}\nparm u 0 0 0 0 1 1 0.5 1\nparm v 0 0 0 0 1 1 1 1\nend\n"),
            "surface.obj:20: the knots along u must be finite and non-decreasing: knot 7 is 0.5 after 1",
        ),
        (
            format!("{p}cstype bezier\ndeg 3 3\n{SURF}\nparm u 1 0\nparm v 0 1\nend\n"),
            "surface.obj:20: a Bézier surface's 'parm u' needs two or more increasing breakpoints",
        ),
        (
            format!("{p}cstype bezier\ndeg 3 3\nsurf 0 2 0 1 1 2 3 4 5 6 7 8 9 10 11 12 13 14 15 16\nparm u 0 1\nparm v 0 1\nend\n"),
            "surface.obj:19: the parameter range [0, 2] along u",
        ),
        (
            format!("{p}cstype bezier\ndeg 3 3\nsurf 0 1 0 1 1 2 3 17\nparm u 0 1\nparm v 0 1\nend\n"),
            "surface.obj:19: 'surf': vertex index 17 is out of range (16 vertices 'v' so far)",
        ),
        (
            format!("{p}cstype bezier\ndeg 3 3\n{SURF}\nparm u 0 1\nparm v 0 1\n"),
            "surface.obj:19: the surface has no 'end' statement",
        ),
        (
            format!("{p}cstype bezier\ndeg 3 3\n{SURF}\nparm u 0 1\nparm v 0 1\ntrim 0 1 1\nend\n"),
            "surface.obj:22: 'trim': curve 1 is not in the file (0 'curv2' curves)",
        ),
        (
            format!("{p}cstype cardinal\ndeg 3 3\n{SURF}\nparm u 0 1\nparm v 0 1\nend\n"),
            "surface.obj:19: 'cstype cardinal' (line 17) is not supported",
        ),
        (format!("{p}f 1 2 3\n"), "surface.obj:17: no free-form surfaces"),
        ("v 1 nan 0\n".to_owned(), "surface.obj:1: 'v': 'nan' is not a finite number"),
    ];
    for (text, expected) in cases {
        let message = error(&text);
        assert!(
            message.starts_with(expected),
            "expected '{expected}…', got '{message}'\n{text}"
        );
    }
}

#[test]
fn a_scene_reads_obj_surfaces_and_textures_follow_their_parameters() {
    let dir = tempfile::tempdir().expect("temp dir");
    let uniform: Vec<f64> = (0..9).map(f64::from).collect();
    std::fs::write(
        dir.path().join("wave.obj"),
        bspline_obj(5, 5, &uniform, &uniform, [3.0, 5.0, 3.0, 5.0]),
    )
    .expect("writes");
    let scene_text = r#"
[camera]
position = [1, 0.8, 6]
look_at = [1, 0.8, 0]
fov = 40
width = 32
height = 24

[materials.m]
type = "diffuse"
texture = { checker = [[0.1, 0.1, 0.1], [0.9, 0.9, 0.9]], mapping = "uv" }

[[lights]]
type = "point"
position = [0, 0, 5]
power = 100

[[objects]]
type = "patches"
file = "wave.obj"
material = "m"
"#;
    let path = dir.path().join("wave.toml");
    std::fs::write(&path, scene_text).expect("writes");
    let scene = Scene::load(&path).expect("loads");
    assert_eq!(scene.geometry.patches().len(), 4);
    // A ray straight down at the surface: its (u,v) is the B-spline's, in [3,5]².
    let hit = scene
        .geometry
        .intersect(&Ray::new(DVec3::new(1.0, 0.8, 6.0), DVec3::NEG_Z), f64::INFINITY)
        .expect("hits the surface");
    assert!(
        (3.0..=5.0).contains(&hit.uv().x) && (3.0..=5.0).contains(&hit.uv().y),
        "uv {} is not in the surface's parameters",
        hit.uv()
    );
    // Edited and saved, the patches keep their windows.
    let loaded: Vec<BezierPatch> = scene.geometry.patches().iter().map(|(p, _)| *p).collect();
    let mut edited = scene.clone();
    assert!(edited.geometry.set_control_point(0, 5, DVec3::new(0.7, 0.5, 1.5)));
    let text = caustic::scene::save::scene_toml(&edited, &loaded, None).expect("saves");
    assert!(text.contains("domains"), "{text}");
    let back = Scene::from_str(&text, &path, Some(dir.path())).expect("loads back");
    assert_eq!(back.geometry.patches(), edited.geometry.patches());
    assert_eq!(back.geometry.patch_domains(), scene.geometry.patch_domains());
}

#[test]
fn export_obj_freeform_reads_back_to_the_same_patches() {
    let dir = tempfile::tempdir().expect("temp dir");
    let out = dir.path().join("teapot.obj");
    let run = common::caustic(&["export-obj", "--freeform", "--out", out.to_str().expect("utf-8")]);
    assert!(run.status.success(), "{}", common::text(&run));
    let builtin = Scene::builtin();
    let count = builtin.geometry.patches().len();
    assert!(common::text(&run).contains(&format!("{count} patches as free-form Bézier surfaces")));
    let read = caustic::geometry::load_freeform_obj(&out).expect("reads back");
    assert_eq!(read.len(), count);
    // Plain patches bit for bit; the ring's rational ones (read through their homogeneous form)
    // to rounding, with their weights exactly.
    for (k, (d, (q, _))) in read.iter().zip(builtin.geometry.patches()).enumerate() {
        let (p, weights) = (&d.patch, &d.weights);
        assert_eq!(d.window, Window::FULL);
        assert_eq!(weights.as_ref(), builtin.geometry.patch_weights(k), "patch {k}");
        if weights.is_none() {
            assert_eq!(p, q, "patch {k}");
        } else {
            for (a, b) in p.points.iter().zip(&q.points) {
                assert!(
                    (*a - *b).length() <= 1e-15 * b.length().max(1.0),
                    "patch {k}: {a} {b}"
                );
            }
        }
    }
    assert!(
        read.iter().any(|d| d.weights.is_some()),
        "the ring's patches are rational"
    );
    // Without --force an existing file is kept.
    let again = common::caustic(&["export-obj", "--freeform", "--out", out.to_str().expect("utf-8")]);
    assert!(!again.status.success());
    assert!(
        common::text(&again).contains("--force"),
        "{}",
        common::text(&again)
    );
}

/// `tests/data/geomdl_wave.obj`: a 6×5 bicubic B-spline surface with uneven knots, written as
/// OBJ from a Python geomdl 5.4 surface; `geomdl_wave_points.txt` holds geomdl's own evaluation
/// of it at 121 parameters. The patches this reader makes agree with that independent code.
#[test]
fn a_surface_from_geomdl_matches_geomdls_own_evaluation() {
    let data = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data");
    let patches = caustic::geometry::load_freeform_obj(&data.join("geomdl_wave.obj")).expect("reads");
    // u knots 0, 0.25, 0.6, 1 and v knots 0, 0.5, 1: 3 × 2 spans.
    assert_eq!(patches.len(), 6);
    let text = std::fs::read_to_string(data.join("geomdl_wave_points.txt")).expect("reads");
    let mut checked = 0;
    for line in text.lines().filter(|l| !l.starts_with('#')) {
        let n: Vec<f64> = line
            .split_whitespace()
            .map(|w| w.parse().expect("number"))
            .collect();
        let (u, v, expected) = (n[0], n[1], DVec3::new(n[2], n[3], n[4]));
        let found = patches
            .iter()
            .find(|d| (d.window.u0..=d.window.u1).contains(&u) && (d.window.v0..=d.window.v1).contains(&v))
            .expect("a patch covers every parameter");
        let (patch, w) = (&found.patch, &found.window);
        let s = (u - w.u0) / (w.u1 - w.u0);
        let t = (v - w.v0) / (w.v1 - w.v0);
        let d = (patch.eval(s, t) - expected).length();
        assert!(d < 1e-12, "{d:e} from geomdl at ({u}, {v})");
        checked += 1;
    }
    assert_eq!(checked, 121);
}

#[test]
fn inputs_past_the_stated_limits_are_refused_early() {
    use caustic::settings::limits::{MAX_KNOTS, MAX_PATCHES};
    let dir = tempfile::tempdir().expect("temp dir");
    // One surface whose 1,056 x 1,056 control points all name the first point: 2 MB of text
    // that would make 1.1 million patches.
    let n = 1_056;
    let knots: Vec<String> = (0..n + 4).map(|k| k.to_string()).collect();
    let text = format!(
        "v 0 0 0\ncstype bspline\ndeg 3 3\nsurf 3 {n} 3 {n} {}\nparm u {k}\nparm v {k}\nend\n",
        vec!["1"; n * n].join(" "),
        k = knots.join(" ")
    );
    let start = std::time::Instant::now();
    let err = parse_freeform_obj(&text, Path::new("bomb.obj")).expect_err("refused");
    assert!(
        err.to_string().contains(&format!("bomb.obj:4: the surface makes 1108809 Bézier patches, and the file 0 before it; a scene holds at most {MAX_PATCHES}")),
        "{err}"
    );
    assert!(start.elapsed().as_secs() < 20, "{:?}", start.elapsed());
    // A parm line of more knots than are read.
    let long = vec!["0"; MAX_KNOTS + 1].join(" ");
    let text = format!("v 0 0 0\ncstype bspline\ndeg 3 3\nsurf 0 1 0 1 1\nparm u {long}\nend\n");
    let err = parse_freeform_obj(&text, Path::new("knots.obj")).expect_err("refused");
    assert!(
        err.to_string().contains(&format!(
            "knots.obj:5: 'parm' gives 1000001 values; at most {MAX_KNOTS}"
        )),
        "{err}"
    );
    // A .bpt file that declares more patches than a scene holds.
    let bpt = dir.path().join("many.bpt");
    std::fs::write(&bpt, "600000\n3 3\n").expect("write");
    let err = caustic::geometry::load_bpt(&bpt).expect_err("refused");
    assert!(
        err.to_string()
            .contains("many.bpt:1: the file declares 600000 patches; a scene holds at most 500000"),
        "{err}"
    );
}

/// The B-spline basis function `N_{i,p}(t)` by the Cox–de Boor recursion (half-open spans; the
/// domain's last point belongs to the last non-empty span): an evaluation independent of the
/// reader's knot insertion.
fn basis(knots: &[f64], i: usize, p: usize, t: f64, last: bool) -> f64 {
    if p == 0 {
        let inside = knots[i] <= t && t < knots[i + 1];
        let at_end = last && t == knots[i + 1] && knots[i] < knots[i + 1];
        return f64::from(u8::from(inside || at_end));
    }
    let mut n = 0.0;
    if knots[i + p] > knots[i] {
        n += (t - knots[i]) / (knots[i + p] - knots[i]) * basis(knots, i, p - 1, t, last);
    }
    if knots[i + p + 1] > knots[i + 1] {
        n += (knots[i + p + 1] - t) / (knots[i + p + 1] - knots[i + 1]) * basis(knots, i + 1, p - 1, t, last);
    }
    n
}

/// A surface for the elevation test: type, degrees, points along u and v, `parm` lines, range.
type Case<'a> = (
    &'a str,
    [usize; 2],
    (usize, usize),
    (&'a [f64], &'a [f64]),
    [f64; 4],
);

/// Surfaces of degree 1 and 2 (B-splines with unclamped and repeated knots, and Bézier
/// surfaces) equal the bicubic patches they are read as, at 1,000 parameters each, within
/// 1e-12 (the patch holding each parameter found by its window).
#[test]
fn degree_one_and_two_surfaces_equal_their_elevated_bicubic_patches() {
    let cases: [Case; 4] = [
        (
            "bspline",
            [2, 2],
            (5, 4),
            (&[0., 1., 2., 3., 4., 5., 6., 7.], &[0., 0., 0., 1., 2., 2., 2.]),
            [2.0, 5.0, 0.0, 2.0],
        ),
        (
            "bspline",
            [1, 2],
            (4, 5),
            (&[0., 0., 1., 2.5, 3., 3.], &[0., 0., 0., 1., 1., 2., 2., 2.]),
            [0.0, 3.0, 0.0, 2.0],
        ),
        (
            "bspline",
            [2, 1],
            (6, 3),
            (&[0., 1., 2., 2., 3., 4., 5., 6., 7.], &[0., 0., 1., 2., 2.]),
            [2.5, 4.5, 0.0, 2.0],
        ),
        (
            "bezier",
            [2, 1],
            (5, 3),
            (&[0., 1., 3.], &[0., 0.5, 1.]),
            [0.0, 3.0, 0.0, 1.0],
        ),
    ];
    for (kind, [pu, pv], (nu, nv), (u_parm, v_parm), range) in cases {
        let text = surface_obj((kind, [pu, pv]), (nu, nv), (u_parm, v_parm), range);
        let patches = parse(&text).unwrap_or_else(|e| panic!("{kind} {pu}×{pv}: {e}"));
        let points = vertices(&text);
        // A Bézier surface's breakpoints as knots: ends p + 1 times, the rest p times.
        let knots = |parm: &[f64], p: usize| -> Vec<f64> {
            if kind == "bspline" {
                return parm.to_vec();
            }
            let last = parm.len() - 1;
            parm.iter()
                .enumerate()
                .flat_map(|(k, &b)| std::iter::repeat_n(b, if k == 0 || k == last { p + 1 } else { p }))
                .collect()
        };
        let (uk, vk) = (knots(u_parm, pu), knots(v_parm, pv));
        let mut state = 0x2545_f491_4f6c_dd1d_u64;
        let mut next = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        for _ in 0..1000 {
            let u = range[0] + next() * (range[1] - range[0]);
            let v = range[2] + next() * (range[3] - range[2]);
            let mut expected = DVec3::ZERO;
            for j in 0..nv {
                for i in 0..nu {
                    let w = basis(&uk, i, pu, u, u == range[1]) * basis(&vk, j, pv, v, v == range[3]);
                    expected += points[i + nu * j] * w;
                }
            }
            let (patch, w) = patches
                .iter()
                .find(|(_, w)| (w.u0..=w.u1).contains(&u) && (w.v0..=w.v1).contains(&v))
                .expect("a patch holds every parameter of the range");
            let got = patch.eval((u - w.u0) / (w.u1 - w.u0), (v - w.v0) / (w.v1 - w.v0));
            assert!(
                (got - expected).length() < 1e-12,
                "{kind} of degree {pu}×{pv} at ({u}, {v}): patch {got}, surface {expected}"
            );
        }
    }
}
