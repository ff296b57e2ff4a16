//! Rational patches, exactly: a NURBS cylinder read from OBJ (`cstype rat bspline`, degree 2
//! around) is hit on its true circle, the prepared intersector agrees with the per-ray one on
//! patches with uneven weights, inline `weights` load and save back with an edit, and bad
//! weights are errors naming the file and the field.

mod common;

use std::path::Path;

use caustic::geometry::rational::RationalPatch;
use caustic::geometry::{parse_freeform_obj, GeometryBuilder, PatchMethod, Ray};
use caustic::scene::Scene;
use glam::DVec3;

/// A unit circle around `z` as a rational quadratic B-spline (9 points, weights 1 and √½), swept
/// from `z = 0` to `z = 2` (degree 1): the exact cylinder, as CAD programs write it.
fn cylinder_obj() -> String {
    let circle = common::rational_circle();
    let mut text = String::new();
    for z in [0.0, 2.0] {
        for (x, y, w) in circle {
            text += &format!("v {x} {y} {z} {w}\n");
        }
    }
    let indices: Vec<String> = (1..=18).map(|i| i.to_string()).collect();
    text += "cstype rat bspline\ndeg 2 1\n";
    text += &format!("surf 0 4 0 1 {}\n", indices.join(" "));
    text += "parm u 0 0 0 1 1 2 2 3 3 4 4 4\nparm v 0 0 1 1\nend\n";
    text
}

/// Where `ray` first meets the cylinder `x² + y² = 1`, `0 < z < 2` (from outside or inside).
fn cylinder_hit(ray: &Ray) -> Option<f64> {
    let (o, d) = (ray.origin, ray.dir);
    let a = d.x * d.x + d.y * d.y;
    let b = 2.0 * (o.x * d.x + o.y * d.y);
    let c = o.x * o.x + o.y * o.y - 1.0;
    let disc = b * b - 4.0 * a * c;
    if a == 0.0 || disc < 0.0 {
        return None;
    }
    let root = disc.sqrt();
    [(-b - root) / (2.0 * a), (-b + root) / (2.0 * a)]
        .into_iter()
        .find(|&t| t > 1e-9 && (0.0..=2.0).contains(&(o.z + t * d.z)))
}

#[test]
fn a_nurbs_cylinder_from_obj_is_hit_on_its_true_circle() {
    let patches = parse_freeform_obj(&cylinder_obj(), Path::new("cylinder.obj")).expect("reads");
    // Four quadratic spans around, one linear span along: four rational bicubic patches.
    assert_eq!(patches.len(), 4);
    assert!(patches.iter().all(|d| d.weights.is_some()));
    let mut builder = GeometryBuilder::default();
    for d in &patches {
        builder.add_weighted_patch_in(d.patch, d.weights, d.window, 0);
    }
    let geometry = builder.build();
    let mut rng = common::rng(11);
    let (mut outside, mut inside) = (0, 0);
    for k in 0..4000 {
        // From outside towards a point near the axis, or from near the axis outwards.
        let from_inside = k % 2 == 1;
        let a = common::unit_vector(&mut rng);
        let b = common::unit_vector(&mut rng);
        let origin = if from_inside {
            DVec3::new(0.3 * a.x, 0.3 * a.y, 1.0 + 0.5 * a.z)
        } else {
            DVec3::new(3.0 * a.x, 3.0 * a.y, 1.0 + 0.8 * a.z).normalize() * 3.0 + DVec3::Z
        };
        let target = DVec3::new(0.4 * b.x, 0.4 * b.y, 1.0 + 0.9 * b.z);
        let ray = Ray::new(origin, (target - origin).normalize());
        let expected = cylinder_hit(&ray);
        let hit = geometry.intersect(&ray, f64::INFINITY);
        match (expected, hit) {
            (Some(t), Some(hit)) => {
                assert!((hit.t - t).abs() < 1e-9, "ray {k}: t {} against {t}", hit.t);
                let radius = hit.point.truncate().length();
                assert!((radius - 1.0).abs() < 1e-9, "ray {k}: radius {radius}");
                // The normal is radial, either way round.
                let radial = hit.point.truncate().normalize().extend(0.0);
                assert!(
                    hit.normal.dot(radial).abs() > 1.0 - 1e-9,
                    "ray {k}: normal {}",
                    hit.normal
                );
                // The hit's parameters lie in the surface's own range [0, 4] × [0, 1].
                let uv = hit.uv();
                assert!((0.0..=4.0).contains(&uv.x) && (0.0..=1.0).contains(&uv.y));
                if from_inside {
                    inside += 1;
                } else {
                    outside += 1;
                }
            }
            (None, None) => {}
            (e, h) => panic!("ray {k}: expected {e:?}, found {h:?}"),
        }
    }
    assert!(outside > 1000 && inside > 500, "{outside} {inside}");
}

/// A bumpy patch over the unit square with weights from 0.25 to 4.
fn uneven_patch(rng: &mut rand_pcg::Pcg64Mcg) -> (caustic::geometry::BezierPatch, [f64; 16]) {
    use rand::Rng;
    let points = std::array::from_fn(|k| {
        let (i, j) = (k / 4, k % 4);
        DVec3::new(i as f64 / 3.0, j as f64 / 3.0, rng.random_range(-0.3..0.3))
    });
    let weights = std::array::from_fn(|_| 4f64.powf(rng.random_range(-1.0..1.0)));
    (caustic::geometry::BezierPatch::new(points), weights)
}

#[test]
fn prepared_and_per_ray_intersectors_agree_on_uneven_weights() {
    let mut rng = common::rng(5);
    for case in 0..8 {
        let (patch, weights) = uneven_patch(&mut rng);
        let surface = RationalPatch::new(&patch, &weights);
        let build = |method| {
            let mut b = GeometryBuilder::with_patch_method(method);
            b.add_weighted_patch_in(patch, Some(weights), caustic::geometry::Window::FULL, 0);
            b.build()
        };
        let prepared = build(PatchMethod::default());
        let per_ray = build(PatchMethod::PerRay { depth: 12 });
        let mut hits = 0;
        for k in 0..400 {
            let a = common::unit_vector(&mut rng);
            let origin = DVec3::new(0.5, 0.5, 0.0) + a * 3.0;
            let target = DVec3::new(
                rand::Rng::random_range(&mut rng, -0.1..1.1),
                rand::Rng::random_range(&mut rng, -0.1..1.1),
                0.0,
            );
            let ray = Ray::new(origin, (target - origin).normalize());
            let (p, q) = (
                prepared.intersect(&ray, f64::INFINITY),
                per_ray.intersect(&ray, f64::INFINITY),
            );
            match (p, q) {
                (Some(p), Some(q)) => {
                    assert!(
                        (p.t - q.t).abs() < 1e-9,
                        "case {case} ray {k}: {} against {}",
                        p.t,
                        q.t
                    );
                    // The hit lies on the rational surface at its own parameters.
                    let on = surface.eval(p.uv().x, p.uv().y);
                    assert!(
                        (on - p.point).length() < 1e-9,
                        "case {case} ray {k}: {on} against {}",
                        p.point
                    );
                    let n = surface
                        .normal_at_scale(p.uv().x, p.uv().y, 1.0)
                        .expect("a normal");
                    assert!(n.dot(p.normal).abs() > 1.0 - 1e-9, "case {case} ray {k}");
                    hits += 1;
                }
                (None, None) => {}
                (p, q) => panic!("case {case} ray {k}: prepared {p:?}, per ray {q:?}"),
            }
        }
        assert!(hits > 100, "case {case}: {hits} hits");
    }
}

/// A scene with one `patches` object whose extra keys are `keys`.
fn scene_with(keys: &str) -> String {
    format!(
        "[camera]\nposition = [0.5, 0.5, 3]\nlook_at = [0.5, 0.5, 0]\nfov = 40\nwidth = 16\nheight = 16\n\n\
         [materials.white]\ntype = \"diffuse\"\ncolor = [0.8, 0.8, 0.8]\n\n\
         [[lights]]\ntype = \"point\"\nposition = [0, 0, 2]\npower = 10\n\n\
         [[objects]]\nname = \"lens\"\ntype = \"patches\"\nmaterial = \"white\"\n{keys}\n"
    )
}

fn inline_points() -> String {
    let points: Vec<String> = (0..16)
        .map(|k| {
            format!(
                "[{}, {}, {}]",
                (k / 4) as f64 / 3.0,
                (k % 4) as f64 / 3.0,
                0.1 * (k % 3) as f64
            )
        })
        .collect();
    format!("patches = [[{}]]", points.join(", "))
}

#[test]
fn inline_weights_load_edit_and_save_back() {
    let weights: Vec<String> = (0..16)
        .map(|k| format!("{}", 0.5 + 0.25 * (k % 5) as f64))
        .collect();
    let text = scene_with(&format!(
        "{}\nweights = [[{}]]",
        inline_points(),
        weights.join(", ")
    ));
    let dir = tempfile::tempdir().expect("temp dir");
    let path = dir.path().join("weighted.toml");
    let mut scene = Scene::from_str(&text, &path, Some(dir.path())).expect("loads");
    let w = *scene.geometry.patch_weights(0).expect("rational");
    assert_eq!(w[3], 0.5 + 0.25 * 3.0);
    let loaded: Vec<_> = scene.geometry.patches().iter().map(|(p, _)| *p).collect();
    assert!(scene.geometry.set_control_point(0, 5, DVec3::new(0.4, 0.3, 0.7)));
    caustic::scene::save::save_scene(&scene, &loaded, &path, false).expect("saves");
    let back = Scene::load(&path).expect("loads back");
    assert_eq!(back.geometry.patches(), scene.geometry.patches());
    assert_eq!(back.geometry.patch_weights(0), Some(&w));
}

#[test]
fn an_edited_rational_obj_surface_saves_inline_with_its_weights() {
    let dir = tempfile::tempdir().expect("temp dir");
    std::fs::write(dir.path().join("cylinder.obj"), cylinder_obj()).expect("writes");
    let path = dir.path().join("cylinder.toml");
    let text = scene_with("file = \"cylinder.obj\"");
    std::fs::write(&path, &text).expect("writes");
    let mut scene = Scene::load(&path).expect("loads");
    let loaded: Vec<_> = scene.geometry.patches().iter().map(|(p, _)| *p).collect();
    assert!(scene
        .geometry
        .set_control_point(2, 6, DVec3::new(-0.9, -0.9, 1.0)));
    caustic::scene::save::save_scene(&scene, &loaded, &path, true).expect("saves");
    let back = Scene::load(&path).expect("loads back");
    assert_eq!(back.geometry.patches(), scene.geometry.patches());
    assert_eq!(back.geometry.patch_domains(), scene.geometry.patch_domains());
    for k in 0..4 {
        assert_eq!(
            back.geometry.patch_weights(k),
            scene.geometry.patch_weights(k),
            "patch {k}"
        );
    }
}

#[test]
fn bad_weights_are_errors_naming_the_file_and_field() {
    let dir = tempfile::tempdir().expect("temp dir");
    let path = dir.path().join("bad.toml");
    let cases = [
        (
            format!("{}\nweights = [[{}]]", inline_points(), vec!["1"; 15].join(", ")),
            "'weights[0]' must have 16 weights, has 15",
        ),
        (
            format!(
                "{}\nweights = [[{}, -2]]",
                inline_points(),
                vec!["1"; 15].join(", ")
            ),
            "'weights[0]': weight -2 of control point 15 is not a positive number",
        ),
        (
            format!(
                "{}\nweights = [[{}], [{}]]",
                inline_points(),
                vec!["1"; 16].join(", "),
                vec!["1"; 16].join(", ")
            ),
            "'weights' has 2 entries for 1 patches",
        ),
        (
            format!("builtin = \"teapot\"\nweights = [[{}]]", vec!["1"; 16].join(", ")),
            "'weights' applies only to inline 'patches'",
        ),
    ];
    for (keys, expected) in cases {
        let err = Scene::from_str(&scene_with(&keys), &path, Some(dir.path()))
            .err()
            .unwrap_or_else(|| panic!("accepted: {keys}"))
            .to_string();
        assert!(
            err.contains("bad.toml") && err.contains(expected),
            "{err}\nexpected: {expected}"
        );
    }
}

#[test]
fn the_example_ring_is_exactly_round() {
    let scene = Scene::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/ring.toml")).expect("loads");
    let ring = scene.geometry.patches();
    assert_eq!(ring.len(), 4);
    for (k, (p, _)) in ring.iter().enumerate() {
        let surface = RationalPatch::new(p, scene.geometry.patch_weights(k).expect("rational"));
        for i in 0..=10 {
            for j in 0..=10 {
                let q = surface.eval(i as f64 / 10.0, j as f64 / 10.0);
                let radius = DVec3::new(q.x, 0.0, q.z).length();
                assert!((radius - 1.0).abs() < 1e-13, "patch {k}: radius {radius}");
            }
        }
    }
}

#[test]
fn export_obj_writes_the_rational_ring_round_and_as_rational_surfaces() {
    let dir = tempfile::tempdir().expect("temp dir");
    let mesh = dir.path().join("ring_mesh.obj");
    let run = common::caustic(&[
        "export-obj",
        "scenes/ring.toml",
        "--out",
        mesh.to_str().expect("utf-8"),
    ]);
    assert!(run.status.success(), "{}", common::text(&run));
    let text = std::fs::read_to_string(&mesh).expect("reads");
    let mut vertices = 0;
    for line in text.lines().filter(|l| l.starts_with("v ")) {
        let n: Vec<f64> = line[2..]
            .split_whitespace()
            .map(|w| w.parse().expect("number"))
            .collect();
        let radius = (n[0] * n[0] + n[2] * n[2]).sqrt();
        assert!((radius - 1.0).abs() < 1e-5, "{line}");
        vertices += 1;
    }
    assert!(vertices > 100, "{vertices} vertices");
    let freeform = dir.path().join("ring.obj");
    let run = common::caustic(&[
        "export-obj",
        "scenes/ring.toml",
        "--freeform",
        "--out",
        freeform.to_str().expect("utf-8"),
    ]);
    assert!(run.status.success(), "{}", common::text(&run));
    let text = std::fs::read_to_string(&freeform).expect("reads");
    assert_eq!(text.matches("cstype rat bezier").count(), 4);
    let back = parse_freeform_obj(&text, &freeform).expect("reads back");
    let scene = Scene::load(Path::new("scenes/ring.toml")).expect("loads");
    for (k, d) in back.iter().enumerate() {
        let p = &d.patch;
        assert_eq!(d.weights.as_ref(), scene.geometry.patch_weights(k), "patch {k}");
        let q = &scene.geometry.patches()[k].0;
        for (a, b) in p.points.iter().zip(&q.points) {
            assert!((*a - *b).length() < 1e-15, "patch {k}: {a} against {b}");
        }
    }
}

/// The unit sphere as CAD programs write it: a rational quadratic semicircle (5 points,
/// weights 1, √½, 1, √½, 1) revolved by a rational quadratic circle (9 points), each point's
/// weight the product of the two (Piegl & Tiller, *The NURBS Book*, §8.5).
fn sphere_obj() -> String {
    let h = std::f64::consts::FRAC_1_SQRT_2;
    let profile = [
        (0.0, -1.0, 1.0),
        (1.0, -1.0, h),
        (1.0, 0.0, 1.0),
        (1.0, 1.0, h),
        (0.0, 1.0, 1.0),
    ];
    let circle = common::rational_circle();
    let mut text = String::new();
    // u along the profile (fastest), v around.
    for (x, y, c) in circle {
        for (r, z, w) in profile {
            text += &format!("v {} {} {z} {}\n", r * x, r * y, w * c);
        }
    }
    let indices: Vec<String> = (1..=45).map(|i| i.to_string()).collect();
    text += "cstype rat bspline\ndeg 2 2\n";
    text += &format!("surf 0 2 0 4 {}\n", indices.join(" "));
    text += "parm u 0 0 0 1 1 2 2 2\nparm v 0 0 0 1 1 2 2 3 3 4 4 4\nend\n";
    text
}

/// The NURBS cylinder and sphere, exactly: every vertex of their patches' tessellation lies on
/// the analytic shape within 1e-12, and rays hit the sphere where the analytic sphere is hit,
/// within 1e-9, with its radial normal.
#[test]
fn a_nurbs_sphere_and_cylinder_are_exact_in_tessellation_and_intersection() {
    use caustic::geometry::tessellate::tessellate_weighted;
    let cylinder = parse_freeform_obj(&cylinder_obj(), Path::new("cylinder.obj")).expect("reads");
    let sphere = parse_freeform_obj(&sphere_obj(), Path::new("sphere.obj")).expect("reads");
    assert_eq!(sphere.len(), 8);
    for (pieces, on_shape) in [
        (
            &cylinder,
            (|p: DVec3| (p.x * p.x + p.y * p.y).sqrt() - 1.0) as fn(DVec3) -> f64,
        ),
        (&sphere, |p: DVec3| p.length() - 1.0),
    ] {
        for d in pieces.iter() {
            let mesh = tessellate_weighted(&d.patch, d.weights.as_ref(), 24);
            for p in &mesh.positions {
                assert!(
                    on_shape(*p).abs() < 1e-12,
                    "a vertex {:e} off the shape",
                    on_shape(*p)
                );
            }
        }
    }
    let mut builder = GeometryBuilder::default();
    for d in &sphere {
        builder.add_weighted_patch_in(d.patch, d.weights, d.window, 0);
    }
    let geometry = builder.build();
    let mut rng = common::rng(12);
    for k in 0..4000 {
        let origin = common::unit_vector(&mut rng) * 3.0;
        let target = common::unit_vector(&mut rng) * 0.9;
        let ray = Ray::new(origin, target - origin);
        // The analytic sphere: |o + t d| = 1, the nearer root.
        let (o, dir) = (ray.origin, ray.dir);
        let (a, b, c) = (dir.dot(dir), 2.0 * o.dot(dir), o.dot(o) - 1.0);
        let t = (-b - (b * b - 4.0 * a * c).sqrt()) / (2.0 * a);
        let hit = geometry
            .intersect(&ray, f64::INFINITY)
            .unwrap_or_else(|| panic!("ray {k} missed"));
        assert!((hit.t - t).abs() < 1e-9, "ray {k}: t {} against {t}", hit.t);
        assert!(
            hit.normal.dot(hit.point.normalize()).abs() > 1.0 - 1e-9,
            "ray {k}: normal {}",
            hit.normal
        );
    }
}
