//! The caustic designer: where a photon lands on the receiver moves with the designed
//! surface's control points as finite differences of the traced landing say; a design lowers
//! its loss and is the same on any thread count; `caustic design` writes the scene with only
//! the surface changed and the surface beside it, and refuses bad input clearly.

mod common;

use caustic::design::landing::{land, surface_bounds, DesignParams, Receiver};
use caustic::design::optimize::{design, DesignSettings};
use caustic::design::photons::design_photons;
use caustic::design::refine::refined;
use caustic::design::target::load_target;
use caustic::geometry::{Quad, Ray};
use caustic::scene::Scene;
use glam::DVec3;

/// `scenes/lens.toml` (a biconvex glass lens of two patches lit by a spot light) with its
/// wall replaced by a receiver quad, and the receiver.
fn lens_scene() -> (Scene, Receiver) {
    let text = std::fs::read_to_string("scenes/lens.toml").expect("reads");
    let wall = "type = \"plane\"\nname = \"wall\"\npoint = [2.5, 0, 0]\nnormal = [-1, 0, 0]";
    assert!(text.contains(wall));
    let quad = Quad {
        corner: DVec3::new(2.5, -1.0, 2.0),
        edge_u: DVec3::new(0.0, 0.0, -4.0),
        edge_v: DVec3::new(0.0, 4.0, 0.0),
    };
    let receiver =
        "type = \"quad\"\nname = \"wall\"\ncorner = [2.5, -1, 2]\nedge_u = [0, 0, -4]\nedge_v = [0, 4, 0]";
    let scene = Scene::from_str(
        &text.replace(wall, receiver),
        std::path::Path::new("scenes/lens.toml"),
        Some(std::path::Path::new("scenes")),
    )
    .expect("loads");
    let object = scene
        .objects
        .iter()
        .position(|o| o.name == "wall")
        .expect("a wall") as u32;
    (scene, Receiver { object, quad })
}

/// Rays from the spot light through points spread over the lens.
fn rays(scene: &Scene, lens: u32) -> Vec<Ray> {
    let bounds = surface_bounds(scene, lens).expect("lens patches");
    let centre = (bounds.min + bounds.max) * 0.5;
    let size = bounds.max - bounds.min;
    let light = DVec3::new(-4.0, 1.6, 0.0);
    let mut out = Vec::new();
    for (a, b) in [
        (0.0, 0.0),
        (0.2, 0.1),
        (-0.25, 0.3),
        (0.3, -0.2),
        (-0.1, -0.35),
        (0.05, 0.2),
    ] {
        let target = centre + DVec3::new(0.0, a * size.y, b * size.z);
        out.push(Ray::new(light, (target - light).normalize()));
    }
    out
}

/// Checks every landing point's derivative with respect to every parameter against central
/// finite differences (step 1e-5) to 1e-7; returns how many were checked and how many moved
/// by more than `moving`.
fn agree_with_finite_differences(
    scene: &mut Scene,
    (params, receiver): (&DesignParams, &Receiver),
    rays: &[Ray],
    moving: f64,
) -> (usize, usize) {
    let analytic: Vec<_> = rays
        .iter()
        .map(|r| land(scene, params, receiver, *r, 8).expect("lands"))
        .collect();
    let (h, mut checked, mut moved) = (1e-5, 0, 0);
    for q in 0..params.len() {
        let mut at = |offset: f64| -> Vec<Option<[f64; 2]>> {
            let mut theta = vec![0.0; params.len()];
            theta[q] = offset;
            assert!(params.apply(scene, &theta));
            rays.iter()
                .map(|r| land(scene, params, receiver, *r, 8).map(|[s, t]| [s.v, t.v]))
                .collect()
        };
        let (plus, minus) = (at(h), at(-h));
        at(0.0);
        for (r, (a, (p, m))) in analytic.iter().zip(plus.iter().zip(&minus)).enumerate() {
            let (Some(p), Some(m)) = (p, m) else { continue };
            for axis in 0..2 {
                let fd = (p[axis] - m[axis]) / (2.0 * h);
                let exact = a[axis].g.iter().find(|e| e.0 == q as u32).map_or(0.0, |e| e.1);
                assert!(
                    (fd - exact).abs() <= 1e-7 * (1.0 + exact.abs()),
                    "ray {r}, parameter {q}, axis {axis}: analytic {exact}, finite differences {fd}"
                );
                checked += 1;
                moved += usize::from(exact.abs() > moving);
            }
        }
    }
    (checked, moved)
}

/// The analytic derivative of each landing point with respect to every control point agrees
/// with central finite differences (step 1e-5) to 1e-7 (they agree to about 1e-10): 240
/// derivatives over six photons and the lens's 20 welded control points, 158 of them moving.
#[test]
fn landing_derivatives_match_finite_differences() {
    let (mut scene, receiver) = lens_scene();
    let lens = scene
        .objects
        .iter()
        .position(|o| o.name == "lens")
        .expect("a lens") as u32;
    let params = DesignParams::of_object(&scene, lens, DVec3::X).expect("params");
    assert!(
        params.len() > 16 && params.len() < 32,
        "{} parameters (two patches welded at the rim)",
        params.len()
    );
    let rays = rays(&scene, lens);
    let (checked, moved) = agree_with_finite_differences(&mut scene, (&params, &receiver), &rays, 1e-3);
    assert!(
        checked > 100 && moved > 20,
        "{checked} derivatives checked, {moved} of them moving"
    );
}

/// A surface with its own net (the pool's water, an 11 × 11 B-spline) is designed through the
/// net's points: each Bézier point follows them by knot insertion's coefficients, and the
/// landing points' derivatives agree with finite differences of moved nets.
#[test]
fn net_derivatives_match_finite_differences() {
    let mut scene = Scene::load(std::path::Path::new("scenes/pool.toml")).expect("loads");
    let water = scene
        .objects
        .iter()
        .position(|o| o.name == "water")
        .expect("water") as u32;
    let floor = scene
        .objects
        .iter()
        .position(|o| o.name == "floor")
        .expect("floor") as u32;
    let receiver = Receiver {
        object: floor,
        quad: Quad {
            corner: DVec3::new(-2.4, -1.5, -2.4),
            edge_u: DVec3::new(0.0, 0.0, 4.8),
            edge_v: DVec3::new(4.8, 0.0, 0.0),
        },
    };
    let params = DesignParams::of_object(&scene, water, DVec3::NEG_Y).expect("params");
    assert_eq!(params.len(), 121);
    let light = DVec3::new(0.3, 3.0, 0.2);
    let rays: Vec<Ray> = [(-1.1, 0.4), (0.2, -0.7), (0.9, 1.3), (-0.3, -1.6), (1.7, 0.1)]
        .iter()
        .map(|&(x, z)| Ray::new(light, (DVec3::new(x, 0.0, z) - light).normalize()))
        .collect();
    let (checked, moved) = agree_with_finite_differences(&mut scene, (&params, &receiver), &rays, 1e-4);
    assert!(checked > 1000 && moved > 30, "{checked} checked, {moved} moving");
}

/// `scenes/design_pool.toml` refined once, its water's parameters and its receiver.
fn pool_design() -> (Scene, DesignParams, Receiver) {
    let scene = Scene::load(std::path::Path::new("scenes/design_pool.toml")).expect("loads");
    let water = scene
        .objects
        .iter()
        .position(|o| o.name == "water")
        .expect("water") as u32;
    let scene = refined(&scene, (water, "water"), 1)
        .expect("refines")
        .expect("refined");
    assert_eq!(
        scene
            .geometry
            .patches()
            .iter()
            .filter(|(_, id)| *id == water)
            .count(),
        4
    );
    let screen = scene
        .objects
        .iter()
        .position(|o| o.name == "screen")
        .expect("screen") as u32;
    let quad = scene.geometry.quad_of(screen).expect("a quad");
    let params = DesignParams::of_object(&scene, water, DVec3::NEG_Y).expect("params");
    // 4 patches of 16 points, welded along their shared edges: a 7 × 7 net.
    assert_eq!(params.len(), 49);
    (scene, params, Receiver { object: screen, quad })
}

/// A short design (120 steps, a 7 × 7 net) lowers the loss by over 40 % (it reaches 52 %),
/// and runs the same on 1 and 2 threads.
#[test]
fn a_design_lowers_its_loss_and_is_the_same_on_any_thread_count() {
    let target = load_target(std::path::Path::new("assets/design_target.png")).expect("target");
    let settings = DesignSettings {
        grid: (24, 24),
        sigma: 0.75,
        smoothness: 0.01,
        max_height: 0.3,
        step: 0.3 / 40.0,
        subsets: 4,
        seconds: 1e9,
        max_steps: 120,
        bounces: 8,
    };
    let run = |threads: usize| {
        let (mut scene, params, receiver) = pool_design();
        let water = scene
            .objects
            .iter()
            .position(|o| o.name == "water")
            .expect("water") as u32;
        let photons = design_photons(&scene, water, 16_000).expect("photons");
        let grid = target.resampled(24, 24);
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("pool");
        pool.install(|| {
            design(
                &mut scene,
                (&params, &receiver),
                &photons,
                &grid,
                &settings,
                |_| {},
            )
        })
    };
    let one = run(1);
    assert!(
        one.final_loss < 0.6 * one.initial_loss,
        "loss {} → {}",
        one.initial_loss,
        one.final_loss
    );
    assert_eq!(one.steps.len(), 120);
    let two = run(2);
    assert_eq!(one.theta, two.theta, "1 and 2 threads design the same surface");
}

/// `caustic design` writes the designed scene (it loads, with only the water changed) and the
/// water beside it as OBJ surfaces (read back, the same patches), prints the loss curve with
/// `--json`, and will not replace what exists without `--force`.
#[test]
fn the_design_command_writes_the_scene_and_the_surface() {
    let dir = tempfile::tempdir().expect("temp dir");
    let out = dir.path().join("designed.toml");
    let out_text = out.to_str().expect("utf-8");
    let args = [
        "design",
        "scenes/design_pool.toml",
        "--surface",
        "water",
        "--receiver",
        "screen",
        "--target",
        "assets/design_target.png",
        "--out",
        out_text,
        "--steps",
        "25",
        "--photons",
        "3000",
        "--json",
    ];
    let run = common::caustic(&args);
    assert!(run.status.success(), "{}", common::text(&run));
    let json: serde_json::Value = serde_json::from_slice(&run.stdout).expect("JSON on stdout");
    assert_eq!(json["steps"].as_array().map(Vec::len), Some(25));
    assert!(
        json["final_loss"].as_f64() < json["initial_loss"].as_f64(),
        "{json}"
    );
    let original = Scene::load(std::path::Path::new("scenes/design_pool.toml")).expect("loads");
    let designed = Scene::load(&out).expect("the designed scene loads");
    assert_eq!(designed.camera, original.camera);
    assert_eq!(designed.lights, original.lights);
    assert_eq!(designed.materials, original.materials);
    let screen = |s: &Scene| s.geometry.quad_of(1);
    assert_eq!(screen(&designed), screen(&original));
    let water: Vec<_> = designed
        .geometry
        .patches()
        .iter()
        .filter(|(_, id)| *id == 0)
        .map(|(p, _)| *p)
        .collect();
    assert_eq!(water.len(), 16, "refined twice");
    assert!(
        water.iter().any(|p| p.points.iter().any(|q| q.y != 0.0)),
        "the water moved"
    );
    let obj = caustic::geometry::load_freeform_obj(&dir.path().join("designed.water.obj"))
        .expect("the surface beside it");
    let from_obj: Vec<_> = obj.iter().map(|d| d.patch).collect();
    assert_eq!(from_obj, water);
    let again = common::caustic(&args);
    assert!(!again.status.success());
    assert!(
        common::text(&again).contains("designed.toml"),
        "{}",
        common::text(&again)
    );
}

/// Bad names, a receiver that is not a quad, a surface that is not smooth glass or mirror, a
/// black target and a scene without a point or spot light are errors that say so.
#[test]
fn bad_design_input_is_a_clear_error() {
    let dir = tempfile::tempdir().expect("temp dir");
    std::fs::write(
        dir.path().join("black.pfm"),
        b"Pf\n2 2\n-1.0\n\0\0\0\0\0\0\0\0\0\0\0\0\0\0\0\0",
    )
    .expect("writes");
    let black = dir.path().join("black.pfm");
    let out = dir.path().join("out.toml");
    let cases: [(&str, &str, &str, &str, &str); 6] = [
        (
            "scenes/design_pool.toml",
            "sea",
            "screen",
            "assets/design_target.png",
            "no object named 'sea' (it has: water, screen)",
        ),
        (
            "scenes/design_pool.toml",
            "water",
            "water",
            "assets/design_target.png",
            "'water' is not a quad",
        ),
        (
            "scenes/design_pool.toml",
            "screen",
            "screen",
            "assets/design_target.png",
            "'screen' has no patches",
        ),
        (
            "scenes/design_pool.toml",
            "water",
            "screen",
            black.to_str().expect("utf-8"),
            "black everywhere",
        ),
        (
            "scenes/cornell.toml",
            "teapot",
            "floor",
            "assets/design_target.png",
            "'teapot' is not smooth glass or a smooth mirror",
        ),
        (
            "scenes/pool.toml",
            "water",
            "floor",
            "assets/design_target.png",
            "no point or spot light",
        ),
    ];
    for (scene, surface, receiver, target, expected) in cases {
        let run = common::caustic(&[
            "design",
            scene,
            "--surface",
            surface,
            "--receiver",
            receiver,
            "--target",
            target,
            "--out",
            out.to_str().expect("utf-8"),
            "--steps",
            "2",
        ]);
        let text = common::text(&run);
        assert!(!run.status.success(), "{text}");
        assert!(text.contains(expected), "{expected:?} in {text}");
        assert!(!text.contains("panicked"), "{text}");
    }
    assert!(!out.exists());
}
