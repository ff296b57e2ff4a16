//! The caustic designer: where a photon lands on the receiver moves with the designed
//! surface's control points as finite differences of the traced landing say; a design lowers
//! its loss and is the same on any thread count; `caustic design` writes the scene with only
//! the surface changed and the surface beside it, and refuses bad input clearly.

mod common;

use caustic::design::landing::{land, surface_bounds, DesignParams, Receiver};
use caustic::design::optimize::{design, DesignSettings};
use caustic::design::photons::design_photons;
use caustic::design::setup::{prepare_design, DesignOptions};
use caustic::design::target::{correlation, load_target, Target};
use caustic::geometry::{Quad, Ray};
use caustic::render::ppm::{Control, Ppm, PpmOptions};
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
    let wall = object(&scene, "wall");
    (scene, Receiver { object: wall, quad })
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
    let lens = object(&scene, "lens");
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
    let water = object(&scene, "water");
    let floor = object(&scene, "floor");
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

/// `scenes/design_pool.toml`, its water's parameters and its receiver.
fn pool_design() -> (Scene, DesignParams, Receiver) {
    let scene = Scene::load(std::path::Path::new("scenes/design_pool.toml")).expect("loads");
    let water = object(&scene, "water");
    let screen = object(&scene, "screen");
    let quad = scene.geometry.quad_of(screen).expect("a quad");
    let params = DesignParams::of_object(&scene, water, DVec3::NEG_Y).expect("params");
    // 4 × 4 patches of 16 points, welded along their shared edges: a 13 × 13 net.
    assert_eq!(params.len(), 169);
    (scene, params, Receiver { object: screen, quad })
}

/// Object `name`'s number.
fn object(scene: &Scene, name: &str) -> u32 {
    scene
        .objects
        .iter()
        .position(|o| o.name == name)
        .unwrap_or_else(|| panic!("an object '{name}'")) as u32
}

/// A short design (120 steps, a 13 × 13 net) lowers the loss by over 40 % (to 17 % of the
/// start), and runs the same on 1 and 2 threads.
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
        let water = object(&scene, "water");
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
                |_, _| std::ops::ControlFlow::Continue(()),
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
    assert_eq!(water.len(), 256, "16 patches refined twice");
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

/// `scenes/design.toml` with each `(from, to)` of `edits` made to its text.
fn design_scene(edits: &[(&str, &str)]) -> Scene {
    let mut text = std::fs::read_to_string("scenes/design.toml").expect("reads");
    for (from, to) in edits {
        assert!(text.contains(from), "scenes/design.toml has {from:?}");
        text = text.replace(from, to);
    }
    Scene::from_str(
        &text,
        std::path::Path::new("scenes/design.toml"),
        Some(std::path::Path::new("scenes")),
    )
    .expect("loads")
}

/// Moves each of object `name`'s control points by a random amount up to `reach` along y
/// (seeded), so that derivatives are checked on a curved surface, not only a flat one.
fn perturbed(mut scene: Scene, name: &str, reach: f64, seed: u64) -> Scene {
    use rand::Rng;
    let surface = object(&scene, name);
    let params = DesignParams::of_object(&scene, surface, DVec3::Y).expect("params");
    let mut rng = common::rng(seed);
    let theta: Vec<f64> = (0..params.len())
        .map(|_| rng.random_range(-reach..reach))
        .collect();
    assert!(params.apply(&mut scene, &theta));
    scene
}

/// On random control points of the slab's top — as glass, refracting, and as a mirror,
/// reflecting onto a receiver beside the light — each landing point's analytic derivative
/// agrees with central finite differences (relative 1e-7, checked by the helper).
#[test]
fn refracted_and_reflected_landings_match_finite_differences_on_random_surfaces() {
    let mirror_receiver = "[[objects]]\ntype = \"quad\"\nname = \"above\"\ncorner = [0.5, 2, -2]\nedge_u = [4, 0, 0]\nedge_v = [0, 0, 4]\nmaterial = \"screen\"\n";
    let cases = [
        (design_scene(&[]), "screen", DVec3::new(0.0, 6.0, 0.0)),
        (
            design_scene(&[
                ("type = \"glass\"\nior = 1.5", "type = \"mirror\""),
                ("position = [0.0, 6.0, 0.0]", "position = [-3.0, 3.0, 0.0]"),
                (
                    "[[objects]]\ntype = \"quad\"",
                    &format!("{mirror_receiver}\n[[objects]]\ntype = \"quad\""),
                ),
            ]),
            "above",
            DVec3::new(-3.0, 3.0, 0.0),
        ),
    ];
    for (seed, (scene, receiver_name, light)) in cases.into_iter().enumerate() {
        let mut scene = perturbed(scene, "lens", 0.04, seed as u64);
        let lens = object(&scene, "lens");
        let receiver = object(&scene, receiver_name);
        let receiver = Receiver {
            object: receiver,
            quad: scene.geometry.quad_of(receiver).expect("a quad"),
        };
        let params = DesignParams::of_object(&scene, lens, DVec3::NEG_Y).expect("params");
        let rays: Vec<Ray> = [
            (-0.9, 0.3),
            (0.15, -0.55),
            (0.7, 0.85),
            (-0.35, -0.9),
            (0.85, 0.05),
        ]
        .iter()
        .map(|&(x, z)| Ray::new(light, (DVec3::new(x, 0.0, z) - light).normalize()))
        .collect();
        let (checked, moved) = agree_with_finite_differences(&mut scene, (&params, &receiver), &rays, 1e-3);
        assert!(
            checked > 1000 && moved > 40,
            "case {seed}: {checked} checked, {moved} moving"
        );
    }
}

/// Designs the slab's top in `scene` (as it is: 13 × 13 welded points) for `target` with a
/// small grid and few steps; returns the scene as designed.
fn design_slab(scene: Scene, target: &Target, steps: usize) -> Scene {
    let options = DesignOptions {
        steps,
        photons: 10_000,
        refine: 0,
        grid: 24,
        // Bounded by steps alone: the default 110 s stopped it at 601 of 800 steps on a busy
        // 2-core machine.
        seconds: 86_400.0,
        ..DesignOptions::default()
    };
    let mut p = prepare_design(scene, ("lens", "screen"), target, &options).expect("prepares");
    let outcome = p.run(|_, _| std::ops::ControlFlow::Continue(()));
    assert_eq!(outcome.steps.len(), steps);
    p.scene
}

/// The paraboloid `y = a + d (x² + z²)` fitted (least squares) to object `name`'s surface,
/// sampled at 9 × 9 points a patch: `(d, largest |y − a|)`.
fn fitted_paraboloid(scene: &Scene, name: &str) -> (f64, f64) {
    let surface = object(scene, name);
    let points: Vec<DVec3> = scene
        .geometry
        .patches()
        .iter()
        .filter(|(_, id)| *id == surface)
        .flat_map(|(p, _)| (0..81).map(|k| p.eval((k % 9) as f64 / 8.0, (k / 9) as f64 / 8.0)))
        .collect();
    let n = points.len() as f64;
    let r2: Vec<f64> = points.iter().map(|p| p.x * p.x + p.z * p.z).collect();
    let (sr, sy) = (r2.iter().sum::<f64>(), points.iter().map(|p| p.y).sum::<f64>());
    let srr: f64 = r2.iter().map(|r| r * r).sum();
    let sry: f64 = r2.iter().zip(&points).map(|(r, p)| r * p.y).sum();
    let d = (n * sry - sr * sy) / (n * srr - sr * sr);
    let a = (sy - d * sr) / n;
    (d, points.iter().map(|p| (p.y - a).abs()).fold(0.0, f64::max))
}

/// The slab under a far light (nearly parallel rays) with its screen 12 below the top.
fn far_slab() -> Scene {
    design_scene(&[
        ("position = [0.0, 6.0, 0.0]", "position = [0.0, 200.0, 0.0]"),
        ("corner = [-1.2, -1.5, 1.2]", "corner = [-1.2, -12, 1.2]"),
    ])
}

/// Known answer: for a target that is one bright spot, the flat slab becomes a converging
/// lens, and the paraboloid fitted to its top has the focal length that puts the focus on the
/// screen: `R / (n − 1)` within 5 % of the screen's distance from the lens's rear principal
/// plane (11.95: 12 below the top, less `t (1 − 1/n)` = 0.05 for the slab's thickness `t` =
/// 0.15; it comes within 1.5 %). A uniform target leaves the flat slab flat: no point moves by
/// 1 % of its width, and the fitted focal length is over ten times the screen's distance.
#[test]
fn a_spot_target_makes_a_focusing_lens_and_a_uniform_one_leaves_the_slab_flat() {
    let spot = Target {
        width: 32,
        height: 32,
        values: (0..32 * 32)
            .map(|k| {
                let (x, y) = ((k % 32) as f64 - 15.5, (k / 32) as f64 - 15.5);
                (-(x * x + y * y) / 2.0).exp()
            })
            .collect(),
    };
    let lens = design_slab(far_slab(), &spot, 800);
    let expected = 12.0 - 0.15 * (1.0 - 1.0 / 1.5);
    let (d, _) = fitted_paraboloid(&lens, "lens");
    let focal_length = -1.0 / (2.0 * d * (1.5 - 1.0));
    eprintln!("focal length {focal_length} (expected {expected})");
    assert!(
        (focal_length / expected - 1.0).abs() < 0.05,
        "focal length {focal_length}, the screen at {expected}"
    );
    let uniform = Target {
        width: 8,
        height: 8,
        values: vec![1.0; 64],
    };
    let flat = design_slab(far_slab(), &uniform, 400);
    let (d, deviation) = fitted_paraboloid(&flat, "lens");
    eprintln!("uniform: curvature {d}, largest deviation {deviation}");
    assert!(
        deviation < 0.01 * 2.4,
        "the surface moved by {deviation} (1 % of the slab's width is 0.024)"
    );
    assert!(
        (1.0 / (2.0 * d * 0.5)).abs() > 10.0 * expected,
        "curvature {d}: a focal length of {}, not over ten times the screen's distance",
        -1.0 / (2.0 * d * 0.5)
    );
}

/// End to end: `scenes/design.toml`'s slab designed for its smooth target
/// (`assets/design_smooth.png`, 400 steps on a 24 × 24 grid), then rendered by photon mapping
/// with the scene's own camera (which sees exactly the screen): the render's luminance
/// correlates with the target at 0.9 or more (Pearson; it reaches 0.98).
#[test]
fn a_designed_slab_renders_its_smooth_target() {
    let target = load_target(std::path::Path::new("assets/design_smooth.png")).expect("target");
    let mut scene = design_slab(design_scene(&[]), &target, 400);
    (scene.camera.width, scene.camera.height) = (32, 32);
    let mut ppm = Ppm::new(&scene, PpmOptions::default());
    for _ in 0..30 {
        ppm.run_pass(&scene, &mut |_| Control::Continue);
    }
    let luminance: Vec<f64> = ppm
        .radiance()
        .iter()
        .map(|&c| caustic::color::luminance(glam::Vec3::from(c).as_dvec3()))
        .collect();
    let r = correlation(&luminance, &target.resampled(32, 32));
    eprintln!("correlation {r}");
    assert!(r >= 0.9, "the render correlates with the target at {r}");
}
