//! Progressive photon mapping: convergence to a closed form, energy conservation through
//! glass, determinism across thread counts, index agreement, and the render session's rules.

use std::f64::consts::PI;
use std::path::Path;
use std::time::{Duration, Instant};

mod common;

use caustic::render::ppm::photon::{PhotonCounts, PhotonSource};
use caustic::render::ppm::{Control, PassOutcome, Ppm, PpmOptions};
use caustic::render::rng::stream_rng;
use caustic::render::session::{Command, Frame, RenderSession, SessionOptions};
use caustic::scene::Scene;
use caustic::settings::IndexKind;
use common::lighting::{closed_form, mean_red, plane_lit_by, LIGHT_KINDS, PLANE};
use common::pool;
use glam::{DVec2, DVec3};

/// The closed form ρ/π · I cos θ / r² at the plane point seen through each pixel centre.
fn expected_plane(scene: &Scene) -> Vec<DVec3> {
    let rho = DVec3::new(0.8, 0.6, 0.4);
    let light = DVec3::new(0.5, 3.0, 0.2);
    let intensity = 400.0 / (4.0 * PI);
    let (w, h) = (scene.camera.width, scene.camera.height);
    (0..h)
        .flat_map(|y| (0..w).map(move |x| (x, y)))
        .map(|(x, y)| {
            let ray = scene.camera.ray(Scene::pixel_center(x, y), DVec2::ZERO);
            let p = ray.at(-ray.origin.y / ray.dir.y);
            let d = light - p;
            rho / PI * intensity * d.normalize().y / d.length_squared()
        })
        .collect()
}

fn relative_errors(image: &[[f32; 3]], expected: &[DVec3]) -> (f64, f64) {
    let (mut sum_ratio, mut sum_sq) = (0.0, 0.0);
    for (p, e) in image.iter().zip(expected) {
        let ratio = p[0] as f64 / e.x;
        sum_ratio += ratio;
        sum_sq += (ratio - 1.0).powi(2);
    }
    let n = image.len() as f64;
    (sum_ratio / n, (sum_sq / n).sqrt())
}

#[test]
fn ppm_converges_to_the_point_lit_plane() {
    let scene = Scene::from_str(PLANE, Path::new("plane.toml"), None).expect("scene");
    let expected = expected_plane(&scene);
    let mut ppm = Ppm::new(&scene, PpmOptions::default());
    let mut errors = Vec::new();
    for pass in 1..=40 {
        ppm.run_pass(&scene, &mut |_| Control::Continue);
        if pass == 4 || pass == 40 {
            errors.push(relative_errors(&ppm.radiance(), &expected));
        }
    }
    let (mean_ratio, rms) = errors[1];
    assert!(
        (mean_ratio - 1.0).abs() < 0.01,
        "mean PPM / closed form = {mean_ratio}"
    );
    assert!(rms < errors[0].1 * 0.75, "RMS error did not shrink: {errors:?}");
    assert!(rms < 0.06, "per-pixel RMS relative error {rms}");
}

/// A bounded object far from the lit plane must not make the point light aim its photons at
/// that object alone: no sphere holds an infinite plane. (This once left the plane black
/// outside the object's cone.)
#[test]
fn photons_are_not_aimed_away_from_an_infinite_plane() {
    let with_ball = format!(
        "{PLANE}\n[[objects]]\ntype = \"sphere\"\ncenter = [0, 8, 40]\nradius = 0.5\nmaterial = \"floor\"\n"
    );
    let scene = Scene::from_str(&with_ball, Path::new("plane_ball.toml"), None).expect("scene");
    assert_eq!(scene.geometry.bounding_sphere(), None);
    let expected = expected_plane(&scene);
    let mut ppm = Ppm::new(&scene, PpmOptions::default());
    for _ in 0..8 {
        ppm.run_pass(&scene, &mut |_| Control::Continue);
    }
    let (mean_ratio, _) = relative_errors(&ppm.radiance(), &expected);
    assert!(
        (mean_ratio - 1.0).abs() < 0.03,
        "mean PPM / closed form = {mean_ratio}"
    );
}

#[test]
fn direct_light_option_is_exact_for_direct_illumination() {
    let mut scene = Scene::from_str(PLANE, Path::new("plane.toml"), None).expect("scene");
    let expected = expected_plane(&scene);
    scene.params.direct_light = true;
    let mut ppm = Ppm::new(&scene, PpmOptions::default());
    ppm.run_pass(&scene, &mut |_| Control::Continue);
    // Only the plane: photons bounce off it once and leave, so all light is direct.
    let (mean_ratio, rms) = relative_errors(&ppm.radiance(), &expected);
    assert!(
        (mean_ratio - 1.0).abs() < 1e-6 && rms < 1e-6,
        "{mean_ratio} {rms}"
    );
}

#[test]
fn glass_conserves_photon_flux() {
    // A closed black box with a glass sphere under the light: every photon ends on a wall, so
    // the flux gathered at first diffuse hits is the light's power.
    let text = r#"
[camera]
position = [0, 0, -0.9]
look_at = [0, 0, 0]
fov = 40
width = 4
height = 4

[render]
max_depth = 16

[materials.black]
type = "diffuse"
color = [0, 0, 0]

[materials.glass]
type = "glass"
color = [1, 1, 1]
ior = 1.5

[[lights]]
type = "point"
position = [0, 0.8, 0]
power = 100

[[objects]]
type = "sphere"
center = [0, 0, 0]
radius = 0.5
material = "glass"

[[objects]]
type = "sphere"
center = [0, 0, 0]
radius = 1.0
material = "black"
"#;
    let scene = Scene::from_str(text, Path::new("box.toml"), None).expect("scene");
    // Directions at random, and stratified (Sobol's sequence, digitally shifted).
    for shift in [None, Some(0x5eed_cafe_f00d_u64)] {
        let source = PhotonSource::new(&scene, false).with_stratified(shift);
        let mut counts = PhotonCounts::default();
        let mut total = DVec3::ZERO;
        let mut through_glass = 0u64;
        let n = 200_000u64;
        for i in 0..n {
            let mut rng = stream_rng(7, 99, i);
            let before = counts.bounces;
            source.trace(i, &mut rng, &mut counts, &mut |_, _, flux, _| total += flux);
            through_glass += u64::from(counts.bounces - before > 1);
        }
        let ratio = total.x / (100.0 * n as f64);
        assert!(
            through_glass > n / 10,
            "{shift:?}: few photons met the glass: {through_glass}"
        );
        assert!(
            ratio > 0.998 && ratio < 1.0 + 1e-9,
            "{shift:?}: gathered flux / power = {ratio}"
        );
    }
}

fn cornell_small(aperture: f64) -> Scene {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/cornell.toml");
    let mut scene = Scene::load(&path).expect("cornell");
    scene.camera.width = 40;
    scene.camera.height = 30;
    scene.camera.aperture = aperture;
    scene.params.photons_per_pass = 20_000;
    scene.params.antialias = false;
    // The file asks for the ray tracer; the session follows the scene's renderer.
    scene.params.renderer = caustic::scene::RendererKind::Ppm;
    scene
}

fn render_passes(scene: &Scene, options: PpmOptions, passes: u32) -> Vec<[f32; 3]> {
    let mut ppm = Ppm::new(scene, options);
    for _ in 0..passes {
        ppm.run_pass(scene, &mut |_| Control::Continue);
    }
    ppm.radiance()
}

#[test]
fn ppm_is_identical_for_one_and_two_threads() {
    let [one, two] = [1, 2].map(pool);
    for aperture in [0.0, 0.2] {
        let scene = cornell_small(aperture);
        // Its quad light is sampled at the visible points (the default) as well as photon mapped.
        assert!(scene.params.direct_light);
        // Its photons are guided (the default), learned from earlier passes, and stratified.
        assert!(scene.params.guided_emission && scene.params.stratified_photons);
        let a = one.install(|| render_passes(&scene, PpmOptions::default(), 3));
        let b = two.install(|| render_passes(&scene, PpmOptions::default(), 3));
        assert_eq!(a, b, "aperture {aperture}");
        assert!(a.iter().flatten().all(|c| c.is_finite()) && a.iter().any(|p| p[0] > 0.0));
    }
    // Photons and eye paths that take a wavelength at a dispersive prism.
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/prism.toml");
    let mut scene = Scene::load(&path).expect("prism");
    (scene.camera.width, scene.camera.height) = (48, 36);
    scene.params.photons_per_pass = 20_000;
    let a = one.install(|| render_passes(&scene, PpmOptions::default(), 3));
    let b = two.install(|| render_passes(&scene, PpmOptions::default(), 3));
    assert_eq!(a, b, "prism");
}

/// A frame's per-pixel layers, swept in parallel blocks that each find their first slot by a
/// binary search, are each pixel's values from its own slots, for 1 and 2 threads: at
/// 96×72 two blocks, the second partial, and with a pinhole camera (classic PPM) glass
/// splits eye paths, so some pixels have several slots and some none.
#[test]
fn a_frames_pixel_layers_are_each_pixels_slots() {
    let mut scene = cornell_small(0.0);
    (scene.camera.width, scene.camera.height) = (96, 72);
    let layers = |threads: usize| {
        pool(threads).install(|| {
            let mut ppm = Ppm::new(&scene, PpmOptions::default());
            for _ in 0..2 {
                ppm.run_pass(&scene, &mut |_| Control::Continue);
            }
            let mut slot_counts = [0usize; 3];
            for slots in ppm.slots_by_pixel() {
                slot_counts[slots.len().min(2)] += 1;
            }
            assert!(
                slot_counts.iter().all(|&n| n > 0),
                "pixels with 0, 1, 2+ slots: {slot_counts:?}"
            );
            let layers = ppm.pixel_layers();
            assert_eq!(&layers.radiance[..], &ppm.radiance()[..]);
            for (k, slots) in ppm.slots_by_pixel().enumerate() {
                let largest = slots
                    .iter()
                    .map(|s| s.primary.radius2().sqrt() as f32)
                    .fold(0.0, f32::max);
                let gathered = slots
                    .iter()
                    .fold(0.0, |sum, s| sum + (s.primary.n() + s.indirect.n()) as f32);
                assert_eq!(
                    (layers.radius[k], layers.gathered[k]),
                    (largest, gathered),
                    "pixel {k}"
                );
            }
            assert!(layers.gathered.iter().any(|&n| n > 0.0));
            layers
        })
    };
    let (one, two) = (layers(1), layers(2));
    assert_eq!(one.radiance, two.radiance);
    assert_eq!((&one.radius, &one.gathered), (&two.radius, &two.gathered));
}

#[test]
fn kd_tree_and_hash_grid_find_the_same_points() {
    let scene = cornell_small(0.0);
    let grid = render_passes(&scene, PpmOptions::default(), 2);
    let mut kd_scene = scene.clone();
    kd_scene.params.index = IndexKind::KdTree;
    let kd = render_passes(&kd_scene, PpmOptions::default(), 2);
    for (a, b) in grid.iter().zip(&kd) {
        for c in 0..3 {
            assert!(
                (a[c] - b[c]).abs() <= 1e-5 * a[c].abs().max(1e-3),
                "{a:?} vs {b:?}"
            );
        }
    }
}

fn next_frame(session: &RenderSession, timeout: Duration) -> Frame {
    session.frames().recv_timeout(timeout).expect("a frame")
}

#[test]
fn session_epochs_follow_the_rules_and_never_block() {
    let scene = cornell_small(0.0);
    let lens = cornell_small(0.1);
    let session = RenderSession::start(scene, None);
    let first = next_frame(&session, Duration::from_secs(60));
    assert_eq!(first.epoch, 0);
    // Nobody reads for a while: the renderer keeps going and the channel holds the newest.
    std::thread::sleep(Duration::from_millis(1500));
    let later = next_frame(&session, Duration::from_secs(60));
    assert!(
        later.pass > first.pass + 1,
        "renderer stalled: {} then {}",
        first.pass,
        later.pass
    );
    // α applies without a restart.
    let mut params = lens.params.clone();
    params.alpha = 0.5;
    session.send(Command::SetParams(params.clone()));
    let f = next_frame(&session, Duration::from_secs(60));
    assert_eq!(f.epoch, 0);
    params.photons_per_pass = 5_000;
    session.send(Command::SetParams(params));
    assert_eq!(next_frame(&session, Duration::from_secs(60)).epoch, 0);
    // The aperture restarts under a new epoch.
    session.send(Command::SetCamera(lens.camera.clone()));
    let deadline = Instant::now() + Duration::from_secs(60);
    let f = loop {
        let f = next_frame(&session, Duration::from_secs(60));
        if f.epoch > 0 || Instant::now() > deadline {
            break f;
        }
    };
    assert_eq!(f.epoch, 1);
    assert!(f.pass <= 3, "a new epoch starts from scratch (pass {})", f.pass);
    // Editing a control point restarts too.
    session.send(Command::MoveControlPoint {
        patch: 0,
        index: 5,
        position: DVec3::new(5.0, 3.0, 5.0),
    });
    let f = loop {
        let f = next_frame(&session, Duration::from_secs(60));
        if f.epoch > 1 || Instant::now() > deadline {
            break f;
        }
    };
    assert_eq!(f.epoch, 2);
    session.shutdown();
}

#[test]
fn session_switches_to_the_ray_tracer_and_reports_a_panic() {
    let scene = cornell_small(0.0);
    let mut whitted_scene = scene.clone();
    whitted_scene.params.renderer = caustic::scene::RendererKind::Whitted;
    // A waker that panics once told to: a failure on the render thread.
    let fail = std::sync::Arc::new(std::sync::atomic::AtomicBool::new(false));
    let fail_flag = fail.clone();
    let waker = Box::new(move || {
        if fail_flag.load(std::sync::atomic::Ordering::Relaxed) {
            panic!("boom");
        }
    });
    let session = RenderSession::start(scene, Some(waker));
    assert_eq!(
        next_frame(&session, Duration::from_secs(60)).stats.renderer(),
        caustic::scene::RendererKind::Ppm
    );
    session.send(Command::SetParams(whitted_scene.params.clone()));
    let f = loop {
        let f = next_frame(&session, Duration::from_secs(60));
        if f.stats.renderer() == caustic::scene::RendererKind::Whitted {
            break f;
        }
    };
    assert_eq!((f.epoch, f.pass, f.photons), (1, 1, 0));
    let (expected, _) = caustic::render::render_whitted(&whitted_scene, &|_| {});
    assert_eq!(&f.radiance[..], &expected.pixels[..]);
    // One ray-traced frame per epoch; then the thread waits for commands.
    assert!(session.frames().recv_timeout(Duration::from_millis(300)).is_err());
    assert_eq!(session.failure(), None);
    fail.store(true, std::sync::atomic::Ordering::Relaxed);
    session.send(Command::Restart);
    let start = Instant::now();
    while session.failure().is_none() && start.elapsed() < Duration::from_secs(30) {
        std::thread::sleep(Duration::from_millis(5));
    }
    assert_eq!(session.failure().as_deref(), Some("boom"));
    session.shutdown();
}

/// A pass abandoned part-way (twice in the middle of a stochastic eye pass, once between photon
/// batches after its eye pass) leaves no trace: the render equals one never interrupted.
#[test]
fn an_interrupted_pass_leaves_no_trace() {
    use std::sync::atomic::{AtomicUsize, Ordering};
    use std::sync::Arc;
    let scene = cornell_small(0.1);
    let reference = render_passes(&scene, PpmOptions::default(), 3);
    let mut ppm = Ppm::new(&scene, PpmOptions::default());
    assert!(ppm.is_stochastic());
    // The 500th question (mid eye pass of pass 2) and the 1700th answer "interrupt".
    let calls = Arc::new(AtomicUsize::new(0));
    let counter = calls.clone();
    ppm.set_interrupt(Some(Arc::new(move || {
        let n = counter.fetch_add(1, Ordering::Relaxed);
        n == 500 + 1200 || n == 500 + 1200 * 2
    })));
    let mut outcomes = Vec::new();
    // And the caller drops pass 3 once at its first photon batch, after its eye pass.
    let mut dropped = false;
    while ppm.stats().passes < 3 {
        let at_pass_3 = ppm.stats().passes == 2;
        outcomes.push(ppm.run_pass(&scene, &mut |_| {
            if at_pass_3 && !dropped {
                dropped = true;
                Control::Abort
            } else {
                Control::Continue
            }
        }));
    }
    assert_eq!(
        outcomes.iter().filter(|o| **o == PassOutcome::Aborted).count(),
        3,
        "{outcomes:?}"
    );
    assert_eq!(ppm.radiance(), reference);
}

#[test]
fn a_new_epoch_starts_with_a_full_size_preview() {
    let mut scene = cornell_small(0.0);
    scene.camera.width = 160;
    scene.camera.height = 120;
    // Full passes much longer than the preview's 16,384 photons, so the preview is seen.
    scene.params.photons_per_pass = 4_000_000;
    let options = SessionOptions {
        preview_divisor: Some(4),
        ..Default::default()
    };
    let mut lens = scene.camera.clone();
    lens.aperture = 0.1;
    let session = RenderSession::start_with(scene, options, None);
    let f = next_frame(&session, Duration::from_secs(60));
    assert!(f.preview, "first frame is not a preview (pass {})", f.pass);
    assert_eq!((f.epoch, f.pass, f.width, f.height), (0, 0, 160, 120));
    assert_eq!(f.radiance.len(), 160 * 120);
    assert!(f.radiance.iter().any(|p| p[0] > 0.0), "black preview");
    // 4×4 blocks repeat one low-resolution pixel.
    assert_eq!(f.radiance[0], f.radiance[3 + 3 * 160]);
    // A restart interrupts the long pass at once and previews the new epoch.
    session.send(Command::SetCamera(lens));
    let f = next_frame(&session, Duration::from_secs(60));
    assert!(
        f.preview && f.epoch == 1,
        "epoch {} preview {}",
        f.epoch,
        f.preview
    );
    session.shutdown();
}

#[test]
fn pause_and_resume_lose_nothing() {
    let scene = cornell_small(0.0);
    let reference_scene = scene.clone();
    let session = RenderSession::start(scene, None);
    session.send(Command::Pause);
    std::thread::sleep(Duration::from_millis(300));
    session.send(Command::Resume);
    std::thread::sleep(Duration::from_millis(100));
    session.send(Command::Pause);
    std::thread::sleep(Duration::from_millis(200));
    session.send(Command::Resume);
    let f = next_frame(&session, Duration::from_secs(60));
    session.shutdown();
    let reference = render_passes(&reference_scene, PpmOptions::default(), f.pass);
    assert_eq!(&f.radiance[..], &reference[..], "pass {}", f.pass);
}

/// A light (`light`: the body of its `[[lights]]` table) above a glass ball of radius 1
/// centred `height` above a grey floor, seen by `camera` (the body of the `[camera]` table),
/// `photons` photons a pass, no anti-aliasing.
fn glass_ball(camera: &str, height: f64, photons: u32, light: &str) -> Scene {
    let text = format!(
        r#"
[camera]
{camera}

[render]
antialias = false
photons_per_pass = {photons}
max_depth = 12

[materials.floor]
type = "diffuse"
color = [0.7, 0.7, 0.7]

[materials.glass]
type = "glass"
color = [1, 1, 1]
ior = 1.5

[[lights]]
{light}

[[objects]]
type = "sphere"
center = [0, {height}, 0]
radius = 1.0
material = "glass"

[[objects]]
type = "plane"
point = [0, 0, 0]
normal = [0, 1, 0]
material = "floor"
"#
    );
    Scene::from_str(&text, Path::new("glass_ball.toml"), None).expect("scene")
}

#[test]
fn direct_light_option_keeps_caustics() {
    // A light above a glass ball above a floor: under the ball all light is caustic (the
    // shadow ray is blocked), so computing direct light by light sampling must not lose it —
    // for a point light and for area lights alike.
    let lights = [
        "type = \"point\"\nposition = [0, 6, 0]\npower = 500",
        "type = \"sphere\"\ncenter = [0, 6, 0]\nradius = 0.3\npower = 500",
        "type = \"quad\"\ncorner = [-0.3, 6, -0.3]\nedge_u = [0.6, 0, 0]\nedge_v = [0, 0, 0.6]\npower = 500",
    ];
    for light in lights {
        let scene = glass_ball(
            "position = [2.5, 0.4, 0.0]\nlook_at = [0, 0, 0]\nfov = 12\nwidth = 32\nheight = 24",
            2.2,
            40_000,
            light,
        );
        let mean = |direct_light: bool| {
            let mut scene = scene.clone();
            scene.params.direct_light = direct_light;
            let image = render_passes(&scene, PpmOptions::default(), 12);
            image.iter().map(|p| p[0] as f64).sum::<f64>() / image.len() as f64
        };
        let (photons_only, with_direct) = (mean(false), mean(true));
        assert!(photons_only > 0.0);
        let ratio = with_direct / photons_only;
        assert!(
            (ratio - 1.0).abs() < 0.1,
            "direct light by light sampling changes the caustic of {light}: ratio {ratio}"
        );
    }
}

/// Stratified photons (the default): a point light above a glass ball throws a broad caustic
/// on the floor (the floor lies well before the focus), all the light there coming through the
/// ball, carried by photons. With each photon's direction taken from Sobol's sequence over the
/// render's photons, the passes' photons cover the ball evenly, so after 32 passes the image
/// is closer to a long render than with directions drawn at random: over eight seeds, each
/// pair of renders sharing everything else, the squared error is 0.82 of random photons'
/// (asserted below 0.9). The image converges to the same result (a long render with random
/// photons has the same mean), and it is the same for one and two threads.
#[test]
fn stratified_photons_settle_a_caustic_sooner_and_keep_the_image() {
    let base = glass_ball(
        "position = [0.0, 2.6, 0.01]\nlook_at = [0, 0, 0]\nfov = 40\nwidth = 32\nheight = 32",
        1.15,
        1000,
        "type = \"point\"\nposition = [0, 6, 0]\npower = 500",
    );
    assert!(base.params.stratified_photons);
    let scene = |stratified: bool, seed: u64| {
        let mut scene = base.clone();
        scene.params.stratified_photons = stratified;
        scene.params.seed = seed;
        scene
    };
    let reference = render_passes(&scene(true, 99), PpmOptions::default(), 1000);
    let random_long = render_passes(&scene(false, 98), PpmOptions::default(), 1000);
    assert_means_within_1_percent(&reference, [("random photons, 1000 passes", &random_long)]);
    let (mut stratified_sq, mut random_sq) = (0.0, 0.0);
    for seed in 1..=8 {
        let [stratified, random] =
            [true, false].map(|on| render_passes(&scene(on, seed), PpmOptions::default(), 32));
        stratified_sq += rms_red(&stratified, &reference).powi(2);
        random_sq += rms_red(&random, &reference).powi(2);
    }
    let ratio = stratified_sq / random_sq;
    eprintln!("squared error after 32 passes, stratified / random photons: {ratio}");
    assert!(
        ratio < 0.9,
        "squared error after 32 passes, stratified / random photons: {ratio}"
    );
    let [one, two] = [1, 2]
        .map(|threads| pool(threads).install(|| render_passes(&scene(true, 5), PpmOptions::default(), 4)));
    assert_eq!(one, two, "stratified photons with one and two threads");
}

/// The statistics' mean radius is the radius in use even while no point has gathered a photon
/// into the estimate it measures: under light sampling that estimate holds caustics only, a
/// plane under a point light has none, and the photons bouncing off it leave the scene (the
/// mean was 0 then).
#[test]
fn the_mean_radius_is_the_radius_in_use_before_any_photon_arrives() {
    let text = PLANE.replace("direct_light = false", "direct_light = true");
    let mut scene = Scene::from_str(&text, Path::new("plane.toml"), None).expect("scene");
    scene.params.initial_radius = Some(0.05);
    let mut ppm = Ppm::new(&scene, PpmOptions::default());
    ppm.run_pass(&scene, &mut |_| Control::Continue);
    let stats = ppm.stats();
    assert_eq!(stats.useful_paths, 0, "no photon reaches a point");
    // No point gathered a photon, so with the adaptive radius (the default) every one is
    // widened to twice the initial radius for the next pass; without it, the initial radius.
    assert!(
        (stats.mean_radius - 0.1).abs() < 1e-6,
        "mean radius {}",
        stats.mean_radius
    );
    scene.params.adaptive_radius = false;
    let mut ppm = Ppm::new(&scene, PpmOptions::default());
    ppm.run_pass(&scene, &mut |_| Control::Continue);
    let r = ppm.stats().mean_radius;
    assert!((r - 0.05).abs() < 1e-6, "mean radius without adaptive radius {r}");
}

#[test]
fn automatic_radius_ignores_a_floor_reaching_the_horizon() {
    // The showcase's table is an infinite plane: a bounding-box rule would give a radius of
    // thousands of units (and every photon would reach every point).
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/showcase.toml");
    let mut scene = Scene::load(&path).expect("showcase");
    scene.camera.width = 64;
    scene.camera.height = 48;
    scene.params.photons_per_pass = 20_000;
    let r = Ppm::automatic_initial_radius(&scene);
    assert!(r > 0.0 && r < 0.5, "initial radius {r}");
    let mut ppm = Ppm::new(&scene, PpmOptions::default());
    ppm.run_pass(&scene, &mut |_| Control::Continue);
    // The radii in use after the first pass: narrowed or widened by at most 2.
    let mean = ppm.stats().mean_radius;
    assert!(
        mean > 0.0 && mean <= 2.0 * r + 1e-9,
        "mean radius {mean} for initial radius {r}"
    );
    assert!(ppm.radiance().iter().flatten().all(|c| c.is_finite()));
}

#[test]
fn huge_radii_stay_deterministic_and_bounded() {
    // Every photon reaches every visible point: the per-chunk deposit lists are merged per
    // slot on the way, and the result must still not depend on the thread count.
    let mut scene = cornell_small(0.0);
    scene.camera.width = 32;
    scene.camera.height = 24;
    scene.params.initial_radius = Some(50.0);
    scene.params.photons_per_pass = 8192;
    let one = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .expect("pool");
    let two = rayon::ThreadPoolBuilder::new()
        .num_threads(2)
        .build()
        .expect("pool");
    let a = one.install(|| render_passes(&scene, PpmOptions::default(), 2));
    let b = two.install(|| render_passes(&scene, PpmOptions::default(), 2));
    assert_eq!(a, b);
    assert!(a.iter().flatten().all(|c| c.is_finite()));
}

#[test]
fn control_point_moves_render_like_the_edited_scene_built_from_scratch() {
    let mut scene = Scene::builtin();
    (scene.camera.width, scene.camera.height) = (64, 48);
    scene.params.photons_per_pass = 20_000;
    scene.params.renderer = caustic::scene::RendererKind::Ppm;
    let session = RenderSession::start_with(
        scene.clone(),
        SessionOptions {
            start_paused: true,
            ..Default::default()
        },
        None,
    );
    // A drag's steps (the latest position wins) and a second point of another patch.
    let moves = [
        (4, 5, DVec3::new(1.0, -1.0, 2.0)),
        (4, 5, DVec3::new(1.2, -1.5, 2.2)),
        (9, 6, DVec3::new(-1.0, 0.5, 1.0)),
        (4, 5, DVec3::new(1.3, -1.6, 2.4)),
    ];
    for (patch, index, position) in moves {
        session.send(Command::MoveControlPoint {
            patch,
            index,
            position,
        });
    }
    session.send(Command::Resume);
    let frame = next_frame(&session, Duration::from_secs(60));
    session.shutdown();
    assert!(frame.epoch >= 1);

    // The edited scene written out and loaded again: prepared from scratch.
    let loaded: Vec<_> = scene.geometry.patches().iter().map(|(p, _)| *p).collect();
    let mut edited = scene.clone();
    assert!(edited
        .geometry
        .set_control_point(4, 5, DVec3::new(1.3, -1.6, 2.4)));
    assert!(edited
        .geometry
        .set_control_point(9, 6, DVec3::new(-1.0, 0.5, 1.0)));
    let text = caustic::scene::save::scene_toml(&edited, &loaded, None).expect("saves");
    let mut fresh = Scene::from_str(&text, Path::new("edited.toml"), None).expect("loads");
    (fresh.camera.width, fresh.camera.height) = (64, 48);
    assert_eq!(fresh.geometry.patches(), edited.geometry.patches());
    let mut ppm = Ppm::new(&fresh, PpmOptions::default());
    ppm.run_pass(&fresh, &mut |_| Control::Continue);
    assert_eq!(frame.pass, 1);
    assert_eq!(
        &frame.radiance[..],
        ppm.radiance().as_slice(),
        "the session's edited render differs"
    );
}

/// Moving a light (here the porcelain teapot scene's sphere light) moves its visible surface by a refit, with
/// no patch prepared again, refuses another kind of light or a non-finite number, and renders
/// like the scene saved with the light there and loaded from scratch.
#[test]
fn a_moved_light_renders_like_the_scene_written_with_it_there() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/teapot.toml");
    let mut scene = Scene::load(&path).expect("the porcelain teapot loads");
    (scene.camera.width, scene.camera.height) = (64, 48);
    scene.params.photons_per_pass = 20_000;
    scene.params.renderer = caustic::scene::RendererKind::Ppm;
    let caustic::scene::Light::Sphere { center, .. } = scene.lights[0] else {
        panic!("the teapot is lit by a sphere");
    };
    let moved = scene.lights[0].translated(DVec3::new(0.4, 0.3, -0.5));
    let mut edited = scene.clone();
    assert!(!edited.set_light(0, caustic::scene::Light::point(DVec3::ZERO, DVec3::ONE)));
    assert!(!edited.set_light(0, scene.lights[0].translated(DVec3::new(f64::NAN, 0.0, 0.0))));
    assert!(!edited.set_light(7, moved));
    assert!(edited.set_light(0, moved));
    let leaves = |s: &Scene| -> Vec<_> {
        s.geometry
            .patch_leaves()
            .iter()
            .map(|l| (l.patch, l.bounds))
            .collect()
    };
    assert_eq!(leaves(&edited), leaves(&scene), "no patch re-prepared");
    let object = scene.light_objects[0].expect("a sphere light has a surface");
    let new_center = center + DVec3::new(0.4, 0.3, -0.5);
    let from = new_center + DVec3::new(0.0, 0.0, -3.0);
    let ray = caustic::geometry::Ray::new(from, (new_center - from).normalize());
    let hit = edited
        .geometry
        .intersect(&ray, f64::INFINITY)
        .expect("the moved sphere is hit");
    assert_eq!(hit.object, object);
    assert!((hit.point - new_center).length() < 0.61);

    let session = RenderSession::start_with(
        scene.clone(),
        SessionOptions {
            start_paused: true,
            ..Default::default()
        },
        None,
    );
    session.send(Command::SetLight {
        light: 0,
        value: moved,
    });
    session.send(Command::Resume);
    let frame = next_frame(&session, Duration::from_secs(60));
    session.shutdown();
    assert!(frame.epoch >= 1);
    let loaded: Vec<_> = scene.geometry.patches().iter().map(|(p, _)| *p).collect();
    let text = caustic::scene::save::scene_toml(&edited, &loaded, None).expect("saves");
    assert!(text.contains("center = ["), "{text}");
    let mut fresh = Scene::from_str(&text, Path::new("moved.toml"), None).expect("loads");
    (fresh.camera.width, fresh.camera.height) = (64, 48);
    assert_eq!(fresh.lights[0], moved);
    let mut ppm = Ppm::new(&fresh, PpmOptions::default());
    ppm.run_pass(&fresh, &mut |_| Control::Continue);
    assert_eq!(
        &frame.radiance[..],
        ppm.radiance().as_slice(),
        "the moved light renders differently"
    );
}

/// A uniformly emitting sphere lights every receiver that sees all of it exactly as a point
/// light of the same power at its centre does. (Photons once started on the sphere's own
/// surface and half of them hit it again at once: the sphere gave about half the light.)
#[test]
fn a_sphere_light_lights_like_a_point_light_of_equal_power() {
    // Out of the camera's view, so only the light it casts is seen.
    let point = plane_lit_by("type = \"point\"\nposition = [2.0, 2.0, 0.0]\npower = 400", false);
    let sphere = plane_lit_by(
        "type = \"sphere\"\ncenter = [2.0, 2.0, 0.0]\nradius = 0.3\npower = 400",
        false,
    );
    let [a, b] = [point, sphere].map(|scene| mean_red(&render_passes(&scene, PpmOptions::default(), 8)));
    assert!((b / a - 1.0).abs() < 0.01, "sphere / point = {}", b / a);
}

/// The root-mean-square difference of the red channels of `image` and `reference`.
fn rms_red(image: &[[f32; 3]], reference: &[[f32; 3]]) -> f64 {
    let sum: f64 = image
        .iter()
        .zip(reference)
        .map(|(a, b)| (a[0] as f64 - b[0] as f64).powi(2))
        .sum();
    (sum / image.len() as f64).sqrt()
}

/// Asserts that each named image's mean red is within 1 % of `reference`'s.
fn assert_means_within_1_percent<const N: usize>(
    reference: &[[f32; 3]],
    images: [(&str, &Vec<[f32; 3]>); N],
) {
    let mean = mean_red(reference);
    for (name, image) in images {
        let ratio = mean_red(image) / mean;
        assert!((ratio - 1.0).abs() < 0.01, "{name}: mean / reference {ratio}");
    }
}

/// Stratified eye rays (the default): a sphere light seen directly, its outline crossing
/// pixels. After 64 passes the image is much closer to a long render than with independent
/// jitter (an outline pixel's coverage error falls nearly as 1/n, not 1/√n), and the same on
/// average.
#[test]
fn stratified_eye_rays_settle_a_lights_outline_sooner() {
    let scene = |stratified: bool, seed: u64| {
        let mut scene = plane_lit_by(
            "type = \"sphere\"\ncenter = [0.1, 0.6, 0.05]\nradius = 0.35\npower = 400",
            true,
        );
        scene.params.stratified_eye_rays = stratified;
        jittered(scene, seed)
    };
    assert_settles_sooner(scene, 2048, 64, 0.5, ["stratified", "independent"]);
}

/// `scene` with jittered eye rays (anti-aliased, so the eye pass runs every pass), 1000
/// photons a pass and no least photons per pixel, seeded with `seed`: what the eye-ray tests
/// below compare.
fn jittered(mut scene: Scene, seed: u64) -> Scene {
    scene.params.antialias = true;
    scene.params.photons_per_pass = 1000;
    scene.params.min_photons_per_pixel = 0.0;
    scene.params.seed = seed;
    scene
}

/// Renders `scene(on, 1)` for `passes` passes with an option on and off, and `scene(true, 7)`
/// for `reference_passes` (another seed: other per-pixel offsets, so its error is independent
/// of the renders'). Asserts that the option on leaves less than `factor` times the RMS error
/// (red) it leaves off, and that both keep the long render's mean; `names` name the two.
fn assert_settles_sooner(
    scene: impl Fn(bool, u64) -> Scene,
    reference_passes: u32,
    passes: u32,
    factor: f64,
    names: [&str; 2],
) {
    let reference = render_passes(&scene(true, 7), PpmOptions::default(), reference_passes);
    let [on, off] = [true, false].map(|on| render_passes(&scene(on, 1), PpmOptions::default(), passes));
    let (e_on, e_off) = (rms_red(&on, &reference), rms_red(&off, &reference));
    assert!(
        e_on < factor * e_off,
        "RMS error after {passes} passes: {} {e_on}, {} {e_off}",
        names[0],
        names[1]
    );
    assert_means_within_1_percent(&reference, [(names[0], &on), (names[1], &off)]);
}

/// Supersampled light seen (the default): a small sphere light seen directly, high above the
/// plane (the plane behind it is 60 times darker than the light), its outline crossing pixels.
/// The outline's pixels trace 16 more eye rays a pass for the light they see, so after 32
/// passes the image is much closer to a long render than with one eye ray per pixel, the same
/// on average, and the same for one and two threads.
#[test]
fn supersampled_outlines_settle_sooner_and_keep_the_image() {
    let scene = |on: bool, seed: u64| {
        let mut scene = plane_lit_by(
            "type = \"sphere\"\ncenter = [0.1, 2.5, 0.05]\nradius = 0.12\npower = 40",
            true,
        );
        // Large enough that the budget (1/64 of the pixels) covers the outline.
        scene.camera.width = 96;
        scene.camera.height = 72;
        scene.params.supersample_light_seen = on;
        jittered(scene, seed)
    };
    // Measured: 0.016 against 0.164.
    assert_settles_sooner(scene, 512, 32, 0.25, ["supersampled", "one ray"]);
    let mut ppm = Ppm::new(&scene(true, 1), PpmOptions::default());
    ppm.run_pass(&scene(true, 1), &mut |_| Control::Continue);
    let share = ppm.stats().supersampled_share;
    assert!(share > 0.005 && share <= 1.0 / 64.0, "supersampled share {share}");
    let [one, two] = [1, 2].map(pool);
    let a = one.install(|| render_passes(&scene(true, 3), PpmOptions::default(), 4));
    let b = two.install(|| render_passes(&scene(true, 3), PpmOptions::default(), 4));
    assert_eq!(a, b);
}

/// Light seen supersampled where it varies between passes (the default): a checker floor under
/// a point light, anti-aliased, so one eye ray a pass lands on either colour in the pixels the
/// squares' edges cross. After 8 passes the pixels whose light seen varied most take 4 more eye
/// rays a pass: after 64 passes the image is closer to a long render than with one ray a pass,
/// the same on average, and the same for one and two threads.
#[test]
fn pixels_whose_light_varies_between_passes_are_supersampled_and_keep_the_image() {
    let scene = |on: bool, seed: u64| {
        let text = PLANE
            .replace(
                "color = [0.8, 0.6, 0.4]",
                "texture = { checker = [[0.9, 0.9, 0.9], [0.1, 0.1, 0.1]], mapping = \"planar\", scale = 1.5 }",
            )
            .replace("direct_light = false", "direct_light = true")
            .replace("width = 24", "width = 96")
            .replace("height = 18", "height = 72");
        let mut scene = Scene::from_str(&text, Path::new("checker.toml"), None).expect("scene");
        scene.params.supersample_light_seen = on;
        jittered(scene, seed)
    };
    // Measured: 6.7e-4 against 1.23e-3.
    assert_settles_sooner(scene, 512, 64, 0.7, ["supersampled", "one ray"]);
    let share = |passes: u32| {
        let mut ppm = Ppm::new(&scene(true, 1), PpmOptions::default());
        for _ in 0..passes {
            ppm.run_pass(&scene(true, 1), &mut |_| Control::Continue);
        }
        ppm.stats().supersampled_share
    };
    let (before, after) = (share(7), share(8));
    assert_eq!(
        before, 0.0,
        "no lamp outline; the variances are taken after 8 passes"
    );
    // Measured: 3.6 %. The budget: a quarter more eye rays, 4 a pixel.
    assert!(after > 0.01 && after <= 0.25 / 4.0, "supersampled share {after}");
    let [one, two] = [1, 2].map(pool);
    let a = one.install(|| render_passes(&scene(true, 3), PpmOptions::default(), 12));
    let b = two.install(|| render_passes(&scene(true, 3), PpmOptions::default(), 12));
    assert_eq!(a, b);
}

/// Indirect light gathered over a wider radius (the default, chosen from the first pass's
/// photon density): sparse photons widen it, dense ones keep it, and the image is the one a
/// single estimate for all photons converges to.
#[test]
fn a_wider_indirect_estimate_is_chosen_by_photon_density_and_keeps_the_image() {
    let scale_for = |photons: u64| {
        let mut scene = cornell_small(0.0);
        scene.params.photons_per_pass = photons;
        assert_eq!(scene.params.indirect_radius_scale, None, "automatic by default");
        let mut ppm = Ppm::new(&scene, PpmOptions::default());
        ppm.run_pass(&scene, &mut |_| Control::Continue);
        ppm.stats().indirect_radius_scale
    };
    let (sparse, dense) = (scale_for(1_000), scale_for(200_000));
    assert!(
        sparse > 2.0 && sparse <= 4.0,
        "1000 photons a pass: scale {sparse}"
    );
    assert_eq!(dense, 1.0, "200,000 photons a pass");

    let render = |scale: Option<f64>| {
        let mut scene = cornell_small(0.0);
        // Twice cornell_small's resolution: radii half as wide, so the blur at the box's
        // edges and corners (a disc reaching past a wall gathers less) stays small.
        (scene.camera.width, scene.camera.height) = (80, 60);
        scene.params.photons_per_pass = 2_000;
        scene.params.indirect_radius_scale = scale;
        let mut ppm = Ppm::new(&scene, PpmOptions::default());
        for _ in 0..800 {
            ppm.run_pass(&scene, &mut |_| Control::Continue);
        }
        (ppm.radiance(), ppm.stats().indirect_radius_scale)
    };
    let (one, k1) = render(Some(1.0));
    let (wide, k) = render(None);
    assert_eq!(k1, 1.0);
    assert!(k > 1.5, "2000 photons a pass: scale {k}");
    let ratio = mean_red(&wide) / mean_red(&one);
    assert!((ratio - 1.0).abs() < 0.01, "wide / one estimate: {ratio}");
}

/// For every light kind, direct light by light sampling agrees with photon mapping and with the
/// closed form (image means within 1 %).
#[test]
fn light_sampling_agrees_with_photons_and_the_closed_form_for_every_light() {
    for (kind, light) in LIGHT_KINDS {
        let photons = plane_lit_by(light, false);
        let sampled = plane_lit_by(light, true);
        let expected = closed_form(&sampled);
        let expected_mean = expected.iter().map(|e| e.x).sum::<f64>() / expected.len() as f64;
        let by_photons = mean_red(&render_passes(&photons, PpmOptions::default(), 8));
        let by_sampling = mean_red(&render_passes(&sampled, PpmOptions::default(), 8));
        eprintln!(
            "{kind}: photons {by_photons:.5}, sampling {by_sampling:.5}, closed form {expected_mean:.5}"
        );
        assert!(
            (by_sampling / expected_mean - 1.0).abs() < 0.01,
            "{kind}: light sampling / closed form = {}",
            by_sampling / expected_mean
        );
        assert!(
            (by_photons / by_sampling - 1.0).abs() < 0.01,
            "{kind}: photons / light sampling = {}",
            by_photons / by_sampling
        );
    }
}

/// Emission guided by what the camera sees: the camera looks at a small part of an infinite
/// plane, so most of a point light's photons land where it does not look. Guided, many times
/// more of them reach a visible point, the image still converges to the closed form (the
/// weights keep it unbiased) with no more error than unguided emission after as many passes
/// (photons' directions at random, so that only the guide differs; measured 0.030 against
/// 0.034), and it is the same for one and two threads. Its first 32 passes trace the photons
/// per pass divided by the gain, later ones divided by the gain's square root. With
/// stratified photons (the default) the guided image keeps the closed form and its error
/// falls several times (measured 3.8×: RMS relative error 0.0078 against 0.030).
#[test]
fn guided_emission_sends_photons_where_the_camera_looks_and_keeps_the_image() {
    let mut scene = Scene::from_str(PLANE, Path::new("plane.toml"), None).expect("scene");
    let expected = expected_plane(&scene);
    let photons = scene.params.photons_per_pass as f64;
    let mut render = |guided: bool, stratified: bool, threads: usize| {
        scene.params.guided_emission = guided;
        scene.params.stratified_photons = stratified;
        pool(threads).install(|| {
            let mut ppm = Ppm::new(&scene, PpmOptions::default());
            let mut per_pass = Vec::new();
            for _ in 0..40 {
                let before = ppm.stats().photons;
                ppm.run_pass(&scene, &mut |_| Control::Continue);
                per_pass.push(ppm.stats().photons - before);
            }
            (ppm.radiance(), (ppm.stats().clone(), per_pass))
        })
    };
    let (unguided, (u, _)) = render(false, false, 2);
    let (guided, (g, per_pass)) = render(true, false, 2);
    // The first 32 passes divide the photons by the gain, later ones by its square root.
    let gain = photons / per_pass[31] as f64;
    let later = photons / per_pass[32] as f64;
    assert!(gain > 3.0, "gain {gain}");
    assert!(
        (later / gain.sqrt() - 1.0).abs() < 0.1,
        "gain {gain}, later passes divided by {later}"
    );
    let share = |s: &caustic::render::ppm::PpmStats| s.useful_paths as f64 / s.photons as f64;
    assert!(
        share(&g) > 3.0 * share(&u),
        "useful photons: guided {:.4}, unguided {:.4}",
        share(&g),
        share(&u)
    );
    assert!(g.photons < u.photons, "guided passes trace fewer photons");
    let (mean_u, rms_u) = relative_errors(&unguided, &expected);
    let (mean_g, rms_g) = relative_errors(&guided, &expected);
    assert!(
        (mean_u - 1.0).abs() < 0.01,
        "unguided mean / closed form {mean_u}"
    );
    assert!((mean_g - 1.0).abs() < 0.01, "guided mean / closed form {mean_g}");
    assert!(
        rms_g < 1.25 * rms_u,
        "RMS relative error guided {rms_g}, unguided {rms_u}"
    );
    let (one_thread, _) = render(true, false, 1);
    assert_eq!(guided, one_thread, "guided emission with one and two threads");
    let (stratified, _) = render(true, true, 2);
    let (mean_s, rms_s) = relative_errors(&stratified, &expected);
    assert!(
        (mean_s - 1.0).abs() < 0.01,
        "guided, stratified mean / closed form {mean_s}"
    );
    assert!(
        rms_s < 0.5 * rms_g,
        "RMS relative error guided with stratified photons {rms_s}, with random ones {rms_g}"
    );
}

/// Stratified photons from two lights: the Sobol point's first coordinate picks the light and,
/// rescaled within that light's share, places the photon, so each light's photons are a
/// stratified share of the sequence rather than a random subset of it. A plane lit by two
/// point lights of unequal power (photons only, unguided so that only the numbers differ)
/// keeps the closed form, its error falls to well under half that of random photons
/// (measured 0.0081 against 0.034; picking the light at random, as before, 0.024), and
/// one and two threads agree.
#[test]
fn stratified_photons_stay_stratified_over_several_lights() {
    let two_lights = "type = \"point\"\nposition = [0.5, 3.0, 0.2]\npower = 300\n\n[[lights]]\n\
                      type = \"point\"\nposition = [-0.8, 2.0, -0.4]\npower = 100";
    let mut scene = plane_lit_by(two_lights, false);
    assert_eq!(scene.lights.len(), 2);
    scene.params.guided_emission = false;
    let expected = closed_form(&scene);
    let mut render = |stratified: bool, threads: usize| {
        scene.params.stratified_photons = stratified;
        pool(threads).install(|| render_passes(&scene, PpmOptions::default(), 40))
    };
    let (stratified, random) = (render(true, 2), render(false, 2));
    let (mean_s, rms_s) = relative_errors(&stratified, &expected);
    let (mean_r, rms_r) = relative_errors(&random, &expected);
    eprintln!("two lights, RMS relative error: stratified {rms_s}, random {rms_r}");
    assert!(
        (mean_s - 1.0).abs() < 0.01,
        "stratified mean / closed form {mean_s}"
    );
    assert!((mean_r - 1.0).abs() < 0.01, "random mean / closed form {mean_r}");
    assert!(
        rms_s < 0.4 * rms_r,
        "RMS relative error with stratified photons {rms_s}, with random ones {rms_r}"
    );
    assert_eq!(
        stratified,
        render(true, 1),
        "stratified photons with one and two threads"
    );
}

/// Adaptive radius (the default): the first pass gathers over twice the initial radius;
/// where it found photons dense, a point restarts its estimate with a narrower radius at the
/// second pass and the first pass's photons no longer count for it — the first pass's image
/// is the one a fixed radius of that width makes, the image stays normalised (a plane lit by
/// a point light, every point dense: the closed form after 3 passes, as with the fixed
/// radius), and the radius is narrower.
#[test]
fn an_adaptive_radius_restarts_dense_points_narrower_and_keeps_the_image() {
    let plane = Scene::from_str(PLANE, Path::new("plane.toml"), None).expect("scene");
    let r0 = Ppm::automatic_initial_radius(&plane);
    let run = |adaptive: bool, radius: f64| {
        let mut scene = plane.clone();
        scene.params.adaptive_radius = adaptive;
        scene.params.initial_radius = Some(radius);
        let mut ppm = Ppm::new(&scene, PpmOptions::default());
        let mut after_one = Vec::new();
        for pass in 0..3 {
            ppm.run_pass(&scene, &mut |_| Control::Continue);
            if pass == 0 {
                after_one = ppm.radiance();
            }
        }
        let stats = ppm.stats().clone();
        (after_one, ppm.radiance(), stats)
    };
    let (_, fixed, fixed_stats) = run(false, r0);
    let (wide_one, _, _) = run(false, 2.0 * r0);
    let (adaptive_one, adaptive, adaptive_stats) = run(true, r0);
    let expected = closed_form_plane();
    let (fixed_mean, _) = relative_errors(&fixed, &expected);
    let (adaptive_mean, _) = relative_errors(&adaptive, &expected);
    eprintln!(
        "mean / closed form: fixed {fixed_mean:.4}, adaptive {adaptive_mean:.4}; narrowed {:.3}, mean radius {:.4} vs {:.4}",
        adaptive_stats.narrowed_share, adaptive_stats.mean_radius, fixed_stats.mean_radius
    );
    assert_eq!(fixed_stats.narrowed_share, 0.0);
    assert_eq!(adaptive_stats.widened_share, 0.0, "no point is sparse");
    assert!(
        adaptive_stats.narrowed_share > 0.9,
        "dense everywhere: {}",
        adaptive_stats.narrowed_share
    );
    assert!(adaptive_stats.mean_radius < 0.8 * fixed_stats.mean_radius);
    // Unchanged up to the rounding of the narrowed estimate's radius² and flux, which are
    // stored in f32.
    for (a, f) in adaptive_one.iter().zip(&wide_one) {
        for c in 0..3 {
            assert!(
                (a[c] - f[c]).abs() <= 1e-6 * f[c].abs().max(1e-3),
                "the first pass's image is the wide radius's: {a:?} vs {f:?}"
            );
        }
    }
    assert!((adaptive_mean - 1.0).abs() < 0.02, "adaptive: {adaptive_mean}");
    assert!((adaptive_mean / fixed_mean - 1.0).abs() < 0.02);
}

/// Adaptive radius where photons are sparse: the same plane with 0.3 % of the photons, so that
/// a pass hands a point less than one. Points are widened (up to twice the initial radius),
/// the image keeps the closed form's mean, and its noise is lower than at the initial radius
/// after as many passes (RMS relative error 0.08-0.09 against 0.14-0.15 after 40 passes). And light next to a sparse point keeps it from widening: the same
/// plane with a hard-edged spot light, dense inside its disc, widens fewer points.
#[test]
fn an_adaptive_radius_widens_sparse_points_and_keeps_the_mean() {
    let mut plane = Scene::from_str(PLANE, Path::new("plane.toml"), None).expect("scene");
    plane.params.photons_per_pass = 300;
    let run = |scene: &Scene, adaptive: bool, passes: usize| {
        let mut scene = scene.clone();
        scene.params.adaptive_radius = adaptive;
        let mut ppm = Ppm::new(&scene, PpmOptions::default());
        for _ in 0..passes {
            ppm.run_pass(&scene, &mut |_| Control::Continue);
        }
        (ppm.radiance(), ppm.stats().clone())
    };
    let expected = closed_form_plane();
    let (mut fixed_sq, mut adaptive_sq) = (0.0, 0.0);
    for seed in 1..=4 {
        plane.params.seed = seed;
        let (fixed, _) = run(&plane, false, 40);
        let (adaptive, stats) = run(&plane, true, 40);
        let (fixed_mean, fixed_rms) = relative_errors(&fixed, &expected);
        let (adaptive_mean, adaptive_rms) = relative_errors(&adaptive, &expected);
        eprintln!(
            "seed {seed}: widened {:.3}, narrowed {:.3}; mean / closed form fixed {fixed_mean:.4}, adaptive {adaptive_mean:.4}; RMS relative error fixed {fixed_rms:.4}, adaptive {adaptive_rms:.4}",
            stats.widened_share, stats.narrowed_share
        );
        assert!(stats.widened_share > 0.5, "sparse: {}", stats.widened_share);
        assert_eq!(stats.narrowed_share, 0.0);
        assert!(
            (adaptive_mean - 1.0).abs() < 0.03,
            "adaptive mean {adaptive_mean}"
        );
        fixed_sq += fixed_rms * fixed_rms;
        adaptive_sq += adaptive_rms * adaptive_rms;
    }
    assert!(
        adaptive_sq < 0.7 * fixed_sq,
        "squared relative error widened {adaptive_sq}, at the initial radius {fixed_sq}"
    );
    // The spot light's disc holds most of the photons: points beside it see them near.
    let spot = "type = \"spot\"\nposition = [0.3, 3.0, 0.0]\ndirection = [0, -1, 0]\ncone_angle = 20\ncone_falloff = 1\npower = 400";
    let mut spotlit = plane_lit_by(spot, false);
    spotlit.params.photons_per_pass = plane.params.photons_per_pass;
    let (_, lone) = run(&plane, true, 1);
    let (_, beside) = run(&spotlit, true, 1);
    eprintln!(
        "widened: point light {:.3}, spot light {:.3}",
        lone.widened_share, beside.widened_share
    );
    assert!(beside.widened_share < lone.widened_share);
}

/// The closed form of [`PLANE`] at its own resolution.
fn closed_form_plane() -> Vec<DVec3> {
    expected_plane(&Scene::from_str(PLANE, Path::new("plane.toml"), None).expect("scene"))
}

/// Adaptive radius blurs sharp light less: the plane under a spot light with a hard-edged
/// cone (1° falloff), photons carrying the direct light (its disc is dense in photons, like
/// the inside of a caustic). After 8 passes the image is much closer to the closed form than
/// with every point at the initial radius (whose disc blurs the cone's edge), with the same
/// mean.
#[test]
fn an_adaptive_radius_sharpens_a_hard_edge_towards_the_closed_form() {
    let light = "type = \"spot\"\nposition = [0.3, 3.0, 0.0]\ndirection = [0, -1, 0]\ncone_angle = 40\ncone_falloff = 1\npower = 400";
    let mut scene = plane_lit_by(light, false);
    (scene.camera.width, scene.camera.height) = (64, 48);
    scene.params.photons_per_pass = 400_000;
    let expected = closed_form(&scene);
    let error = |image: &[[f32; 3]]| {
        let sum: f64 = image
            .iter()
            .zip(&expected)
            .map(|(p, e)| (p[0] as f64 - e.x).powi(2))
            .sum();
        (sum / image.len() as f64).sqrt()
    };
    let render = |adaptive: bool| {
        let mut scene = scene.clone();
        scene.params.adaptive_radius = adaptive;
        render_passes(&scene, PpmOptions::default(), 8)
    };
    let (fixed, adaptive) = (render(false), render(true));
    let expected_mean = expected.iter().map(|e| e.x).sum::<f64>() / expected.len() as f64;
    let (e_fixed, e_adaptive) = (error(&fixed), error(&adaptive));
    let (m_fixed, m_adaptive) = (mean_red(&fixed), mean_red(&adaptive));
    eprintln!(
        "RMS error: fixed {e_fixed:.4e}, adaptive {e_adaptive:.4e}; means {m_fixed:.5} {m_adaptive:.5}, closed form {expected_mean:.5}"
    );
    assert!(
        e_adaptive < 0.6 * e_fixed,
        "adaptive {e_adaptive} vs fixed {e_fixed}"
    );
    assert!((m_adaptive / expected_mean - 1.0).abs() < 0.02);
    assert!((m_fixed / expected_mean - 1.0).abs() < 0.02);
    // The radii come from photon counts: the same image for one and two threads.
    let [one, two] = [1, 2].map(pool);
    let mut short = scene.clone();
    short.params.photons_per_pass = 100_000;
    assert_eq!(
        one.install(|| render_passes(&short, PpmOptions::default(), 3)),
        two.install(|| render_passes(&short, PpmOptions::default(), 3))
    );
}
