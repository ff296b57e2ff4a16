//! Warm restarts after an edit (a control point or a light moved): the new epoch keeps what
//! is still valid, converges to the edited scene's image (mean within 1 % of a cold render),
//! is the same for 1 and 2 threads, and the session starts it without the low-resolution
//! preview.

use std::path::Path;
use std::time::Duration;

use caustic::render::ppm::{Changed, Control, Ppm, PpmOptions};
use caustic::render::session::{Command, Frame, RenderSession, SessionOptions};
use caustic::scene::Scene;
use glam::DVec3;

mod common;
use common::pool;

/// `scenes/inline_patch.toml` (a glass sheet over a floor, a point light) at `width`, with
/// `photons` per pass; `antialias` off makes it classic PPM (one eye pass, glass split).
fn sheet(width: u32, photons: u64, antialias: bool) -> Scene {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/inline_patch.toml");
    let mut scene = Scene::load(&path).expect("scenes/inline_patch.toml loads");
    scene.camera.resize(Some(width), None);
    scene.params.photons_per_pass = photons;
    scene.params.antialias = antialias;
    scene
}

/// The sheet's inner control point 5 raised by `by`.
fn edited(scene: &Scene, by: f64) -> (Scene, Command) {
    let mut patch = scene.geometry.patches()[0].0;
    patch.points[5] += DVec3::Y * by;
    let mut out = scene.clone();
    out.geometry.update_patches(&[(0, patch)]);
    let command = Command::MoveControlPoint {
        patch: 0,
        index: 5,
        position: patch.points[5],
    };
    (out, command)
}

/// The sheet's light moved by `by`.
fn light_moved(scene: &Scene, by: DVec3) -> (Scene, Command) {
    let mut out = scene.clone();
    let value = scene.lights[0].translated(by);
    assert!(out.set_light(0, value));
    (out, Command::SetLight { light: 0, value })
}

fn options() -> PpmOptions {
    PpmOptions {
        warm_restarts: true,
        ..Default::default()
    }
}

fn run(ppm: &mut Ppm, scene: &Scene, passes: u32) {
    for _ in 0..passes {
        ppm.run_pass(scene, &mut |_| Control::Continue);
    }
}

/// `before` passes of the scene, the edit, then `after` passes warm: the image and the share
/// of pixels kept.
fn warm_render(scene: &Scene, edit: &Scene, before: u32, after: u32) -> (Vec<[f32; 3]>, f64) {
    let mut old = Ppm::new(scene, options());
    run(&mut old, scene, before);
    let mut new = Ppm::new(edit, options());
    new.inherit(edit, old.into_warm_start().expect("a completed pass hands on"));
    run(&mut new, edit, after);
    (new.radiance(), new.stats().kept_share + new.stats().nearby_share)
}

fn mean(image: &[[f32; 3]]) -> f64 {
    image.iter().map(|p| (p[0] + p[1] + p[2]) as f64).sum::<f64>() / (3 * image.len()) as f64
}

#[test]
fn an_unchanged_scene_restarts_where_it_was() {
    for antialias in [true, false] {
        let scene = sheet(96, 20_000, antialias);
        let mut old = Ppm::new(&scene, options());
        run(&mut old, &scene, 6);
        let before = old.radiance();
        let mut new = Ppm::new(&scene, options());
        new.inherit(&scene, old.into_warm_start().expect("warm start"));
        run(&mut new, &scene, 1);
        assert_eq!(
            new.stats().kept_share,
            1.0,
            "antialias {antialias}: every pixel kept"
        );
        assert_eq!(new.stats().nearby_share, 0.0);
        let (a, b) = (mean(&before), mean(&new.radiance()));
        assert!(
            (a - b).abs() < 0.02 * a,
            "antialias {antialias}: one warm pass keeps the image: mean {a} then {b}"
        );
    }
}

#[test]
fn a_warm_restart_converges_to_the_edited_scene_for_any_thread_count() {
    for antialias in [true, false] {
        let scene = sheet(96, 20_000, antialias);
        let (edit, _) = edited(&scene, 0.1);
        let (one, warmed) = pool(1).install(|| warm_render(&scene, &edit, 6, 40));
        let (two, _) = pool(2).install(|| warm_render(&scene, &edit, 6, 40));
        assert!(
            one == two,
            "antialias {antialias}: the same image for 1 and 2 threads"
        );
        assert!(warmed > 0.9, "antialias {antialias}: pixels warmed: {warmed}");
        let mut cold = Ppm::new(&edit, options());
        run(&mut cold, &edit, 40);
        let (w, c) = (mean(&one), mean(&cold.radiance()));
        assert!(
            (w - c).abs() < 0.01 * c,
            "antialias {antialias}: warm mean {w} against cold {c}"
        );
    }
}

#[test]
fn a_moved_light_restarts_warm_and_converges_to_its_new_light() {
    for antialias in [true, false] {
        let scene = sheet(96, 20_000, antialias);
        // Far enough that the sheet's caustic and the floor's shading move visibly.
        let (edit, _) = light_moved(&scene, DVec3::new(0.6, 0.8, 0.3));
        let mut old = Ppm::new(&scene, options());
        run(&mut old, &scene, 6);
        let before = mean(&old.radiance());
        let mut kept = old.into_warm_start().expect("warm start");
        kept.light_moved(0);
        let mut new = Ppm::new(&edit, options());
        new.inherit(&edit, kept);
        // The viewer's ramp: a small first pass, so the old light's prior is worth one full
        // pass (it counts as 8 first passes) and its share falls as 1/(1 + passes).
        new.photons_per_pass = 2_500;
        run(&mut new, &edit, 1);
        new.photons_per_pass = 20_000;
        run(&mut new, &edit, 39);
        assert_eq!(
            new.stats().kept_share,
            1.0,
            "antialias {antialias}: a light's move moves no visible point"
        );
        let mut cold = Ppm::new(&edit, options());
        run(&mut cold, &edit, 40);
        let (w, c) = (mean(&new.radiance()), mean(&cold.radiance()));
        assert!(
            (before - c).abs() > 0.03 * c,
            "antialias {antialias}: the move changes the image ({before} and {c})"
        );
        assert!(
            (w - c).abs() < 0.01 * c,
            "antialias {antialias}: warm mean {w} against cold {c}"
        );
    }
}

#[test]
fn the_moved_sheet_takes_nearby_estimates_and_the_rest_is_kept() {
    for antialias in [true, false] {
        let scene = sheet(96, 20_000, antialias);
        // Raised far enough that what is seen through the sheet moves beyond half its radius,
        // which the adaptive radius widens (up to twice) where this scene's photons are sparse.
        let (edit, _) = edited(&scene, 0.3);
        let mut old = Ppm::new(&scene, options());
        run(&mut old, &scene, 4);
        let mut new = Ppm::new(&edit, options());
        new.inherit(&edit, old.into_warm_start().expect("warm start"));
        run(&mut new, &edit, 1);
        let (kept, nearby) = (new.stats().kept_share, new.stats().nearby_share);
        assert!(kept > 0.5 && kept < 0.99, "antialias {antialias}: kept {kept}");
        assert!(nearby > 0.0, "antialias {antialias}: nearby {nearby}");
    }
}

/// `scenes/teapot.toml` (a Phong teapot in a box under a sphere light) at `width`, stochastic.
fn teapot(width: u32) -> Scene {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/teapot.toml");
    let mut scene = Scene::load(&path).expect("scenes/teapot.toml loads");
    scene.camera.resize(Some(width), None);
    scene.params.photons_per_pass = 20_000;
    scene.params.antialias = true;
    scene
}

/// Three passes of `scene`, then `edit` warm for two passes, told what the edit changed when
/// `described`: the image and the share of pixels the first warm pass copied.
fn warm_after(scene: &Scene, edit: &Scene, light_moved: bool, described: bool) -> (Vec<[f32; 3]>, f64) {
    let mut old = Ppm::new(scene, options());
    run(&mut old, scene, 3);
    let mut kept = old.into_warm_start().expect("warm start");
    if light_moved {
        kept.light_moved(0);
    }
    if described {
        kept.edited(Changed::edit(scene, edit));
    }
    let mut new = Ppm::new(edit, options());
    new.inherit(edit, kept);
    run(&mut new, edit, 1);
    let copied = new.stats().copied_share;
    run(&mut new, edit, 1);
    (new.radiance(), copied)
}

/// A flat diffuse patch between a sphere lamp and a floor, seen from low down beside it:
/// the floor under the patch's shadow is seen by rays that pass below the patch.
const SHADOW: &str = r#"
[camera]
position = [6, 1, 0]
look_at = [0, 0, 0]
fov = 40
width = 96
height = 72

[render]
photons_per_pass = 20000

[materials.grey]
type = "diffuse"
color = [0.7, 0.7, 0.7]

[[lights]]
type = "sphere"
center = [0, 5, 0]
radius = 0.3
power = 800

[[objects]]
type = "plane"
point = [0, 0, 0]
normal = [0, 1, 0]
material = "grey"

[[objects]]
type = "patches"
material = "grey"
patches = [[
    [-0.6, 2, -0.6], [-0.2, 2, -0.6], [0.2, 2, -0.6], [0.6, 2, -0.6],
    [-0.6, 2, -0.2], [-0.2, 2, -0.2], [0.2, 2, -0.2], [0.6, 2, -0.2],
    [-0.6, 2, 0.2], [-0.2, 2, 0.2], [0.2, 2, 0.2], [0.6, 2, 0.2],
    [-0.6, 2, 0.6], [-0.2, 2, 0.6], [0.2, 2, 0.6], [0.6, 2, 0.6],
]]
"#;

#[test]
fn a_moved_shadow_is_sampled_again_where_the_floor_is_copied() {
    let mut scene = Scene::from_str(SHADOW, Path::new("shadow.toml"), None).expect("the scene loads");
    scene.params.antialias = true;
    let mut patch = scene.geometry.patches()[0].0;
    patch
        .points
        .iter_mut()
        .for_each(|p| *p += DVec3::new(0.0, 0.0, 0.7));
    let mut edit = scene.clone();
    edit.geometry.update_patches(&[(0, patch)]);
    let (traced, _) = warm_after(&scene, &edit, false, false);
    let (copied, share) = warm_after(&scene, &edit, false, true);
    assert!(share > 0.8, "the floor is copied: {share}");
    assert!(traced == copied, "the shadow moved on the copied floor");
}

#[test]
fn a_warm_first_pass_copies_what_the_edit_cannot_reach_and_the_image_is_the_traced_one() {
    let scene = teapot(96);
    let mut patch = scene.geometry.patches()[0].0;
    // Out sideways: the shadow on the floor changes where the floor is copied.
    patch.points[5] += DVec3::new(1.0, -1.0, 0.0);
    let mut moved_patch = scene.clone();
    moved_patch.geometry.update_patches(&[(0, patch)]);
    let (moved_light, _) = light_moved(&scene, DVec3::new(-1.5, 1.0, -0.5));
    for (edit, light, what) in [
        (&moved_patch, false, "control point"),
        (&moved_light, true, "light"),
    ] {
        let (traced, none) = pool(2).install(|| warm_after(&scene, edit, light, false));
        assert_eq!(
            none, 0.0,
            "{what}: nothing is copied unless the edit is described"
        );
        let (copied, share) = pool(2).install(|| warm_after(&scene, edit, light, true));
        assert!(share > 0.5, "{what}: most pixels copied: {share}");
        assert!(
            traced == copied,
            "{what}: the image with {share} of the pixels copied is the traced one"
        );
        let (one, _) = pool(1).install(|| warm_after(&scene, edit, light, true));
        assert!(one == copied, "{what}: the same image for 1 and 2 threads");
    }
    // The moved patch is in view: its pixels are traced again.
    let (_, share) = warm_after(&scene, &moved_patch, false, true);
    let (_, unmoved) = warm_after(&scene, &scene, false, true);
    assert!(
        share < unmoved,
        "the moved patch's pixels are traced: {share} against {unmoved}"
    );
}

fn next_frame(session: &RenderSession) -> Frame {
    session
        .frames()
        .recv_timeout(Duration::from_secs(60))
        .expect("a frame within a minute")
}

#[test]
fn the_session_restarts_warm_after_an_edit_and_cold_after_a_setting() {
    let scene = sheet(64, 8_000, true);
    let (_, command) = edited(&scene, 0.05);
    let session = RenderSession::start_with(
        scene.clone(),
        SessionOptions {
            every_frame: true,
            ..SessionOptions::interactive()
        },
        None,
    );
    while next_frame(&session).pass < 3 {}
    session.send(command);
    let first = loop {
        let f = next_frame(&session);
        if f.epoch == 1 {
            break f;
        }
    };
    let kept = first.stats.json["photon_mapping"]["kept_share"]
        .as_f64()
        .unwrap_or(0.0);
    assert!(
        !first.preview,
        "a warm epoch opens with a full pass, not a preview"
    );
    assert!(kept > 0.8, "most pixels kept: {kept}");
    // So does a moved light, and undoing the move.
    let (moved, command) = light_moved(&scene, DVec3::new(0.2, 0.0, 0.0));
    for (epoch, command) in [
        (2, command),
        (
            3,
            Command::SetLight {
                light: 0,
                value: scene.lights[0],
            },
        ),
    ] {
        session.send(command);
        let first = loop {
            let f = next_frame(&session);
            if f.epoch == epoch {
                break f;
            }
        };
        let kept = first.stats.json["photon_mapping"]["kept_share"]
            .as_f64()
            .unwrap_or(0.0);
        assert!(
            !first.preview && kept > 0.8,
            "a light's move is warm: kept {kept}"
        );
    }
    assert_ne!(moved.lights[0], scene.lights[0]);
    // A setting restarts cold: the preview first, nothing kept.
    let mut params = scene.params.clone();
    params.initial_radius = Some(0.05);
    session.send(Command::SetParams(params));
    let first = loop {
        let f = next_frame(&session);
        if f.epoch == 4 {
            break f;
        }
    };
    assert!(first.preview, "a cold epoch opens with the preview");
    let f = next_frame(&session);
    assert_eq!(f.stats.json["photon_mapping"]["kept_share"].as_f64(), Some(0.0));
    session.shutdown();
}
