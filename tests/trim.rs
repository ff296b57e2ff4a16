//! Trimmed surfaces from OBJ (`trim`/`hole` loops of `curv2` curves): hits, shadow rays and
//! photons pass through what the loops cut away, exactly on a rational circle; a disk and the
//! plane it was cut from leave no seam between them; polyline trims, reversed curve ranges,
//! exports and saves keep the loops; bad trims are errors naming the file and line.

mod common;

use std::path::Path;

use caustic::geometry::rational::RationalPatch;
use caustic::geometry::{
    load_freeform_obj, parse_freeform_obj, write_freeform_obj, GeometryBuilder, PatchMethod, Ray,
};
use caustic::render::ppm::photon::{PhotonCounts, PhotonSource};
use caustic::render::rng::stream_rng;
use caustic::scene::Scene;
use glam::{DVec2, DVec3};

/// The trim circle's centre and radius, in (u,v), which is (x,y) on the planes below.
const CENTRE: DVec2 = DVec2::new(1.0, 1.0);
const RADIUS: f64 = 0.5;

/// A flat bicubic Bézier plane over `[0,2]²` at height `z` whose `(u,v)` is its `(x,y)`, with
/// `trims` (lines such as `trim 0 4 1`) and, before it, the trim curves: curve 1 the circle
/// about [`CENTRE`] (a rational quadratic B-spline, 9 points, weights 1 and √½), curve 2 the
/// square `[0,2]²` as a polyline (degree 1).
fn plane_obj(z: f64, trims: &str) -> String {
    let circle = common::rational_circle();
    let mut text = String::new();
    for (x, y, w) in circle {
        let p = CENTRE + RADIUS * DVec2::new(x, y);
        text += &format!("vp {} {} {w}\n", p.x, p.y);
    }
    text += "cstype rat bspline\ndeg 2\ncurv2 1 2 3 4 5 6 7 8 9\nparm u 0 0 0 1 1 2 2 3 3 4 4 4\nend\n";
    for (u, v) in [(0.0, 0.0), (2.0, 0.0), (2.0, 2.0), (0.0, 2.0), (0.0, 0.0)] {
        text += &format!("vp {u} {v}\n");
    }
    text += "cstype bspline\ndeg 1\ncurv2 -5 -4 -3 -2 -1\nparm u 0 0 1 2 3 4 4\nend\n";
    for j in 0..4 {
        for i in 0..4 {
            text += &format!("v {} {} {z}\n", 2.0 * i as f64 / 3.0, 2.0 * j as f64 / 3.0);
        }
    }
    let indices: Vec<String> = (1..=16).map(|i| i.to_string()).collect();
    text += &format!(
        "cstype bezier\ndeg 3 3\nsurf 0 2 0 2 {}\nparm u 0 2\nparm v 0 2\n{trims}\nend\n",
        indices.join(" ")
    );
    text
}

/// `a` and `b` keep the same points of `[0,2]²` (5,000 drawn with `seed`; those within 1e-9 of
/// the circle, where rounding may decide, left out).
fn assert_same_region(
    a: &caustic::geometry::trim::TrimRegion,
    b: &caustic::geometry::trim::TrimRegion,
    seed: u64,
) {
    let mut rng = common::rng(seed);
    for _ in 0..5000 {
        let p = DVec2::new(
            rand::Rng::random::<f64>(&mut rng),
            rand::Rng::random::<f64>(&mut rng),
        ) * 2.0;
        if ((p - CENTRE).length() - RADIUS).abs() > 1e-9 {
            assert_eq!(a.contains(p), b.contains(p), "at {p}");
        }
    }
}

/// Geometry of the OBJ texts, each its own object (0, 1, …), with the patch intersector
/// `method`.
fn geometry(objs: &[String], method: PatchMethod) -> caustic::geometry::SceneGeometry {
    let mut builder = GeometryBuilder::with_patch_method(method);
    for (object, text) in objs.iter().enumerate() {
        for piece in parse_freeform_obj(text, Path::new("plane.obj")).expect("reads") {
            builder.add_surface_patch(piece, object as u32);
        }
    }
    builder.build()
}

fn methods() -> [PatchMethod; 2] {
    [PatchMethod::default(), PatchMethod::PerRay { depth: 8 }]
}

/// A ray straight down onto `(x, y)`.
fn down(p: DVec2) -> Ray {
    Ray::new(p.extend(1.0), -DVec3::Z)
}

/// The circle as an outer loop (a disk) and as a hole (a square with a round hole): a ray 1e-9
/// inside the circle hits the disk and passes the hole, a ray 1e-9 outside passes the disk
/// and hits the square, at a thousand angles; shadow rays agree; both intersectors.
#[test]
fn a_rational_circle_trims_exactly_as_outer_loop_and_as_hole() {
    for method in methods() {
        for (trims, kept_inside) in [("trim 0 4 1", true), ("hole 0 4 1", false)] {
            let plane = geometry(&[plane_obj(0.0, trims)], method);
            let hits = |ray: &Ray| {
                let hit = plane.intersect(ray, f64::INFINITY);
                assert_eq!(
                    hit.is_some(),
                    plane.occluded(ray, 2.0),
                    "{method:?} {trims}: shadow rays agree"
                );
                hit.is_some_and(|h| (h.t - 1.0).abs() < 1e-9)
            };
            for k in 0..1000 {
                let a = k as f64 * 0.00628;
                let at = |r: f64| CENTRE + r * DVec2::new(a.cos(), a.sin());
                let (inside, outside) = (down(at(RADIUS - 1e-9)), down(at(RADIUS + 1e-9)));
                assert_eq!(
                    hits(&inside),
                    kept_inside,
                    "{method:?} {trims}, angle {a}: inside"
                );
                assert_eq!(
                    hits(&outside),
                    !kept_inside,
                    "{method:?} {trims}, angle {a}: outside"
                );
            }
            // The circle's middle and the plane's corner.
            assert_eq!(hits(&down(CENTRE)), kept_inside);
            assert_eq!(hits(&down(DVec2::splat(0.1))), !kept_inside);
        }
    }
}

/// The disk at height 0 and, 0.01 below it, the plane with the same circle as a hole: every
/// ray down near the circle meets one of the two (the disk inside, the holed plane outside),
/// none slips through the seam between them.
#[test]
fn a_disk_and_its_hole_leave_no_seam() {
    let mut rng = common::rng(7);
    for method in methods() {
        let pair = geometry(
            &[plane_obj(0.0, "trim 0 4 1"), plane_obj(-0.01, "hole 0 4 1")],
            method,
        );
        for _ in 0..20_000 {
            let a = rand::Rng::random::<f64>(&mut rng) * std::f64::consts::TAU;
            let r = RADIUS + (rand::Rng::random::<f64>(&mut rng) - 0.5) * 2e-6;
            let p = CENTRE + r * DVec2::new(a.cos(), a.sin());
            let hit = pair.intersect(&down(p), f64::INFINITY);
            let Some(hit) = hit else {
                panic!("{method:?}: a ray at radius {r} (angle {a}) slipped through the seam");
            };
            let expected = if (p - CENTRE).length() < RADIUS { 0 } else { 1 };
            if ((p - CENTRE).length() - RADIUS).abs() > 1e-9 {
                assert_eq!(hit.object, expected, "{method:?}: radius {r}");
            }
            assert!(pair.occluded(&down(p), 2.0));
        }
    }
}

/// An outer loop written as a polyline (degree 1, as Rhino's "trims as polylines" writes),
/// traversed backwards (`trim 4 0 2`), with the circle as a hole: the square's inside is kept
/// but for the hole.
#[test]
fn a_polyline_outer_loop_read_backwards_with_a_hole() {
    let plane = geometry(
        &[plane_obj(0.0, "trim 4 0 2\nhole 0 4 1")],
        PatchMethod::default(),
    );
    for (p, kept) in [
        (DVec2::new(0.1, 0.1), true),
        (DVec2::new(1.9, 1.0), true),
        (CENTRE, false),
        (CENTRE + DVec2::new(RADIUS - 1e-6, 0.0), false),
        (CENTRE + DVec2::new(RADIUS + 1e-6, 0.0), true),
    ] {
        assert_eq!(plane.intersect(&down(p), f64::INFINITY).is_some(), kept, "at {p}");
    }
}

/// Photons from a point light above the holed plane: those that first land on the floor
/// below passed through the hole, and those that land on the plane landed outside it.
#[test]
fn photons_pass_through_the_hole_only() {
    let dir = tempfile::tempdir().expect("temp dir");
    std::fs::write(dir.path().join("holed.obj"), plane_obj(0.0, "hole 0 4 1")).expect("writes");
    let scene_path = dir.path().join("holed.toml");
    let text = "[camera]\nposition = [1, 1, 5]\nlook_at = [1, 1, 0]\nfov = 40\nwidth = 16\nheight = 16\n\n\
         [materials.white]\ntype = \"diffuse\"\ncolor = [0.5, 0.5, 0.5]\n\n\
         [[lights]]\ntype = \"point\"\nposition = [1, 1, 1]\npower = 10\n\n\
         [[objects]]\nname = \"holed\"\ntype = \"patches\"\nfile = \"holed.obj\"\nmaterial = \"white\"\n\n\
         [[objects]]\nname = \"floor\"\ntype = \"quad\"\ncorner = [-5, -5, -1]\nedge_u = [10, 0, 0]\nedge_v = [0, 10, 0]\nmaterial = \"white\"\n";
    std::fs::write(&scene_path, text).expect("writes");
    let scene = Scene::load(&scene_path).expect("loads");
    let source = PhotonSource::new(&scene, false);
    let mut counts = PhotonCounts::default();
    let (mut through, mut on_plane) = (0, 0);
    for i in 0..20_000u64 {
        let mut rng = stream_rng(1, 2, i);
        let mut first = None;
        source.trace(i, &mut rng, &mut counts, &mut |p, _, _, _| {
            first = first.or(Some(p));
        });
        let Some(p) = first else { continue };
        if p.z.abs() < 1e-6 {
            on_plane += 1;
            assert!(
                (p.truncate() - CENTRE).length() > RADIUS - 1e-6,
                "a photon landed in the hole at {p}"
            );
        } else if (p.z + 1.0).abs() < 1e-6 {
            // Straight down from the light at (1, 1, 1): it crossed z = 0 halfway.
            let crossing = CENTRE + 0.5 * (p.truncate() - CENTRE);
            if (crossing - CENTRE).length() < 1.0 {
                through += 1;
                assert!(
                    (crossing - CENTRE).length() < RADIUS + 1e-6,
                    "a photon reached the floor at {p} through the plane at {crossing}"
                );
            }
        }
    }
    assert!(
        through > 500 && on_plane > 500,
        "{through} through the hole, {on_plane} on the plane"
    );
}

/// `write_freeform_obj` writes the trims with the patches; they read back to the same kept
/// region, also through `export-obj --freeform` of a scene.
#[test]
fn trims_are_written_and_read_back() {
    let patches =
        parse_freeform_obj(&plane_obj(0.0, "trim 4 0 2\nhole 0 4 1"), Path::new("a.obj")).expect("reads");
    let mut out = Vec::new();
    write_freeform_obj(&[("plane".to_owned(), patches.clone())], &mut out).expect("writes");
    let back =
        parse_freeform_obj(&String::from_utf8(out).expect("text"), Path::new("b.obj")).expect("reads back");
    let (a, b) = (
        patches[0].trim.as_ref().expect("trimmed"),
        back[0].trim.as_ref().expect("trimmed"),
    );
    assert_same_region(a, b, 3);
}

/// Bad trims are errors naming the file and the line.
#[test]
fn bad_trims_are_errors_naming_the_line() {
    let cases = [
        ("trim 0 4 3", "curve 3 is not in the file"),
        ("trim 0 5 1", "curve 1"),
        ("trim 0 4", "'trim' takes 'u0 u1 curv2' triples"),
        ("hole 0 2 1", "the loop is not closed"),
        (
            "trim 0 2 1 0 2 2",
            "does not start where the loop's previous curve ends",
        ),
    ];
    for (trims, expected) in cases {
        let err = parse_freeform_obj(&plane_obj(0.0, trims), Path::new("bad.obj"))
            .expect_err(trims)
            .to_string();
        assert!(
            err.starts_with("bad.obj:") && err.contains(expected),
            "{trims}: {err}"
        );
    }
    let outside = "trim 0 1 1\n".to_owned() + &plane_obj(0.0, "");
    let err = parse_freeform_obj(&outside, Path::new("bad.obj"))
        .expect_err("refused")
        .to_string();
    assert!(err.contains("bad.obj:1: 'trim' outside a surface"), "{err}");
    let no_parm = "vp 0 0\nvp 1 1\ncstype bspline\ndeg 1\ncurv2 1 2\nend\n".to_owned() + &plane_obj(0.0, "");
    let err = parse_freeform_obj(&no_parm, Path::new("bad.obj"))
        .expect_err("refused")
        .to_string();
    assert!(
        err.contains("bad.obj:6: the trim curve on line 5 has no 'parm u' line"),
        "{err}"
    );
}

/// A scene holding the trimmed plane of `obj` (saved beside it) as its object `plane`.
fn plane_scene(dir: &Path, obj: &str) -> std::path::PathBuf {
    std::fs::write(dir.join("plane.obj"), obj).expect("writes");
    let path = dir.join("plane.toml");
    let text = "[camera]\nposition = [1, 1, 5]\nlook_at = [1, 1, 0]\nfov = 40\nwidth = 16\nheight = 16\n\n\
         [materials.white]\ntype = \"diffuse\"\ncolor = [0.5, 0.5, 0.5]\n\n\
         [[lights]]\ntype = \"point\"\nposition = [1, 1, 1]\npower = 10\n\n\
         [[objects]]\nname = \"plane\"\ntype = \"patches\"\nfile = \"plane.obj\"\nmaterial = \"white\"\n";
    std::fs::write(&path, text).expect("writes");
    path
}

/// An edited trimmed surface is saved inline with its loops (`trims`), and loads back with the
/// same points, and hits where the trims keep it.
#[test]
fn an_edited_trimmed_surface_saves_its_loops() {
    let dir = tempfile::tempdir().expect("temp dir");
    let path = plane_scene(dir.path(), &plane_obj(0.0, "trim 4 0 2\nhole 0 4 1"));
    let mut scene = Scene::load(&path).expect("loads");
    let loaded: Vec<_> = scene.geometry.patches().iter().map(|(p, _)| *p).collect();
    assert!(scene.geometry.set_control_point(0, 0, DVec3::new(0.0, 0.0, 0.1)));
    caustic::scene::save::save_scene(&scene, &loaded, &path, true).expect("saves");
    let text = std::fs::read_to_string(&path).expect("reads");
    assert!(text.contains("trims = [{ patches = [0], loops = ["), "{text}");
    let back = Scene::load(&path).expect("loads back");
    assert_eq!(back.geometry.patches(), scene.geometry.patches());
    let (a, b) = (
        scene.geometry.patch_trim(0).expect("trimmed"),
        back.geometry.patch_trim(0).expect("trimmed"),
    );
    assert_same_region(a, b, 5);
    assert!(back.geometry.intersect(&down(CENTRE), f64::INFINITY).is_none());
    assert!(back
        .geometry
        .intersect(&down(DVec2::new(1.0, 0.2)), f64::INFINITY)
        .is_some());
}

/// Bad inline trims are errors naming the file and the field.
#[test]
fn bad_inline_trims_are_errors_naming_the_field() {
    let dir = tempfile::tempdir().expect("temp dir");
    let path = dir.path().join("bad.toml");
    let points: Vec<String> = (0..16)
        .map(|k| format!("[{}, {}, 0]", (k / 4) as f64 / 3.0, (k % 4) as f64 / 3.0))
        .collect();
    let line = |a: (f64, f64), b: (f64, f64)| {
        let at = |t: f64| format!("{}, {}, 1", a.0 + t * (b.0 - a.0), a.1 + t * (b.1 - a.1));
        format!("[{}, {}, {}, {}]", at(0.0), at(1.0 / 3.0), at(2.0 / 3.0), at(1.0))
    };
    let triangle = format!(
        "[{}, {}, {}]",
        line((0.1, 0.1), (0.9, 0.1)),
        line((0.9, 0.1), (0.5, 0.9)),
        line((0.5, 0.9), (0.1, 0.1))
    );
    let open = format!(
        "[{}, {}]",
        line((0.1, 0.1), (0.9, 0.1)),
        line((0.9, 0.1), (0.5, 0.9))
    );
    let cases = [
        (
            format!("trims = [{{ patches = [1], loops = [{{ segments = {triangle} }}] }}]"),
            "'trims[0].patches' names patch 1; the object has 1",
        ),
        (
            format!("trims = [{{ patches = [0], loops = [{{ segments = {open} }}] }}]"),
            "'trims[0].loops[0]': segment 0 does not start where segment 1 ends",
        ),
        (
            "trims = [{ patches = [0], loops = [{ segments = [[0, 0, 1, 1, 0, 1, 1, 1, -1, 0, 0, 1]] }] }]"
                .to_owned(),
            "'trims[0].loops[0].segments[0]': point 2 has weight -1",
        ),
        (
            "trims = [{ patches = [0], loops = [] }]".to_owned(),
            "'trims[0]' needs 'patches' and 'loops'",
        ),
    ];
    for (trims, expected) in cases {
        let text = format!(
            "[camera]\nposition = [0.5, 0.5, 3]\nlook_at = [0.5, 0.5, 0]\nfov = 40\nwidth = 16\nheight = 16\n\n[materials.white]\ntype = \"diffuse\"\ncolor = [0.5, 0.5, 0.5]\n\n\
             [[lights]]\ntype = \"point\"\nposition = [0, 0, 2]\npower = 1\n\n\
             [[objects]]\ntype = \"patches\"\nmaterial = \"white\"\npatches = [[{}]]\n{trims}\n",
            points.join(", ")
        );
        let err = Scene::from_str(&text, &path, Some(dir.path()))
            .err()
            .unwrap_or_else(|| panic!("accepted: {trims}"))
            .to_string();
        assert!(
            err.contains("bad.toml") && err.contains(expected),
            "{err}\nexpected: {expected}"
        );
    }
    // The same triangle, well formed, trims the patch.
    let text = format!(
        "[camera]\nposition = [0.5, 0.5, 3]\nlook_at = [0.5, 0.5, 0]\nfov = 40\nwidth = 16\nheight = 16\n\n[materials.white]\ntype = \"diffuse\"\ncolor = [0.5, 0.5, 0.5]\n\n\
         [[lights]]\ntype = \"point\"\nposition = [0, 0, 2]\npower = 1\n\n\
         [[objects]]\ntype = \"patches\"\nmaterial = \"white\"\npatches = [[{}]]\ntrims = [{{ patches = [0], loops = [{{ segments = {triangle} }}] }}]\n",
        points.join(", ")
    );
    let scene = Scene::from_str(&text, &path, Some(dir.path())).expect("loads");
    assert!(scene
        .geometry
        .intersect(&down(DVec2::new(0.5, 0.4)), f64::INFINITY)
        .is_some());
    assert!(scene
        .geometry
        .intersect(&down(DVec2::new(0.1, 0.8)), f64::INFINITY)
        .is_none());
}

/// `tests/data/geomdl_trim.obj` (from `make_geomdl_trim.py`): a rational B-spline surface with
/// a rational cubic outer loop, read backwards, and a rational circle as a hole, written from
/// geomdl 5.4's own control points, weights and knots. The patches agree with geomdl's
/// evaluation of the surface at 121 parameters within 1e-12, and the trim boundary passes
/// through geomdl's evaluation of each curve at 200 parameters: a point 1e-9 to one side is
/// kept, 1e-9 to the other cut away.
#[test]
fn a_trimmed_surface_from_geomdl_matches_geomdls_evaluation() {
    let data = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data");
    let patches = load_freeform_obj(&data.join("geomdl_trim.obj")).expect("reads");
    let trim = patches[0].trim.clone().expect("trimmed");
    assert!(patches
        .iter()
        .all(|d| d.trim.as_ref().is_some_and(|t| std::sync::Arc::ptr_eq(t, &trim))));
    let text = std::fs::read_to_string(data.join("geomdl_trim_points.txt")).expect("reads");
    let mut loops: [Vec<DVec2>; 2] = [Vec::new(), Vec::new()];
    let mut surface_points = 0;
    for line in text.lines().filter(|l| !l.starts_with('#')) {
        let words: Vec<&str> = line.split_whitespace().collect();
        let n: Vec<f64> = words[1..].iter().map(|w| w.parse().expect("number")).collect();
        if words[0] == "t" {
            loops[n[0] as usize].push(DVec2::new(n[1], n[2]));
            continue;
        }
        let (u, v, expected) = (n[0], n[1], DVec3::new(n[2], n[3], n[4]));
        let d = patches
            .iter()
            .find(|d| (d.window.u0..=d.window.u1).contains(&u) && (d.window.v0..=d.window.v1).contains(&v))
            .expect("a patch covers every parameter");
        let w = &d.window;
        let (s, t) = ((u - w.u0) / (w.u1 - w.u0), (v - w.v0) / (w.v1 - w.v0));
        let got = RationalPatch::new(&d.patch, d.weights.as_ref().expect("rational")).eval(s, t);
        assert!(
            (got - expected).length() < 1e-12,
            "{:e} from geomdl at ({u}, {v})",
            (got - expected).length()
        );
        surface_points += 1;
    }
    assert_eq!(surface_points, 121);
    for (k, points) in loops.iter().enumerate() {
        assert_eq!(points.len(), 200);
        let centre = points.iter().sum::<DVec2>() / points.len() as f64;
        for i in 0..points.len() {
            let (prev, p, next) = (points[(i + 199) % 200], points[i], points[(i + 1) % 200]);
            let tangent = (next - prev).normalize();
            let mut towards_centre = DVec2::new(-tangent.y, tangent.x);
            if towards_centre.dot(centre - p) < 0.0 {
                towards_centre = -towards_centre;
            }
            // Inside the outer loop is kept; inside the hole is cut away.
            let kept_towards_centre = k == 0;
            assert_eq!(
                trim.contains(p + 1e-9 * towards_centre),
                kept_towards_centre,
                "loop {k} at {p}"
            );
            assert_eq!(
                trim.contains(p - 1e-9 * towards_centre),
                !kept_towards_centre,
                "loop {k} at {p}"
            );
        }
    }
}

/// A trimmed surface edited through its own net is saved as that surface, to an OBJ file
/// beside the scene, with its loops: it loads back with the same patches and region.
#[test]
fn an_edited_trimmed_net_saves_as_a_trimmed_surface_beside_the_scene() {
    let dir = tempfile::tempdir().expect("temp dir");
    let path = plane_scene(dir.path(), &plane_obj(0.0, "trim 4 0 2\nhole 0 4 1"));
    let mut scene = Scene::load(&path).expect("loads");
    let loaded: Vec<_> = scene.geometry.patches().iter().map(|(p, _)| *p).collect();
    assert_eq!(scene.geometry.nets().len(), 1);
    assert!(scene
        .geometry
        .move_net_points(0, &[(5, DVec3::new(0.7, 0.7, 0.3))])
        .is_some());
    let saved = dir.path().join("saved.toml");
    caustic::scene::save::save_scene(&scene, &loaded, &saved, false).expect("saves");
    let obj = std::fs::read_to_string(dir.path().join("saved.plane.obj")).expect("the surface beside it");
    assert!(
        obj.contains("cstype bspline\ndeg 3 3\n") && obj.contains("\ntrim ") && obj.contains("\nhole "),
        "{obj}"
    );
    let back = Scene::load(&saved).expect("loads back");
    assert_eq!(back.geometry.patches(), scene.geometry.patches());
    let (a, b) = (
        scene.geometry.patch_trim(0).expect("trimmed"),
        back.geometry.patch_trim(0).expect("trimmed"),
    );
    assert_same_region(a, b, 9);
    // Saving again to the same name without leave to replace is refused, naming the file.
    let err = caustic::scene::save::save_scene(&scene, &loaded, &saved, false).expect_err("exists");
    assert!(err.to_string().contains("saved.plane.obj"), "{err}");
}

/// A surface placed by an object's `transform` is placed with its net: its patches are the
/// untransformed ones transformed (to rounding), its net's points are transformed, and a move
/// of a net point derives the same patches from the placed net as from scratch.
#[test]
fn a_placed_surface_moves_with_its_net() {
    let dir = tempfile::tempdir().expect("temp dir");
    let path = plane_scene(dir.path(), &plane_obj(0.0, "hole 0 4 1"));
    let plain = Scene::load(&path).expect("loads");
    let text = std::fs::read_to_string(&path).expect("reads")
        + "transform = { scale = 2, rotate = [90, 0, 30], translate = [1, -2, 3] }\n";
    std::fs::write(&path, text).expect("writes");
    let mut placed = Scene::load(&path).expect("loads placed");
    let m = glam::DAffine3::from_translation(DVec3::new(1.0, -2.0, 3.0))
        * glam::DAffine3::from_rotation_z(30f64.to_radians())
        * glam::DAffine3::from_rotation_y(0.0)
        * glam::DAffine3::from_rotation_x(90f64.to_radians())
        * glam::DAffine3::from_scale(DVec3::splat(2.0));
    let (a, b) = (&plain.geometry.patches()[0].0, &placed.geometry.patches()[0].0);
    for (p, q) in a.points.iter().zip(&b.points) {
        assert!(
            (m.transform_point3(*p) - *q).length() < 1e-12,
            "{p} placed at {q}"
        );
    }
    let net = &placed.geometry.nets()[0].net;
    for (p, q) in plain.geometry.nets()[0]
        .net
        .surface
        .points
        .iter()
        .zip(&net.surface.points)
    {
        assert!((m.transform_point3(*p) - *q).length() < 1e-12);
    }
    let target = net.surface.points[5] + DVec3::new(0.0, 0.0, 0.5);
    assert!(placed.geometry.move_net_points(0, &[(5, target)]).is_some());
    let expected = placed.geometry.nets()[0].net.patches();
    assert_eq!(placed.geometry.patches()[0].0, expected[0].0);
    assert!(
        placed.geometry.patch_trim(0).is_some(),
        "the trim stays with the placed surface"
    );
}
