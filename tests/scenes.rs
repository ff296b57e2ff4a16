//! Scene files: every shipped scene loads and renders; bad files give clear errors; analytic
//! checks of the ray tracer (point-lit plane, focus, Fresnel through a slab); patch textures;
//! determinism across thread counts.

use std::f64::consts::PI;
use std::path::{Path, PathBuf};

use caustic::render::render_whitted;
use caustic::scene::{RendererKind, Scene};
use glam::{DVec2, DVec3};

fn scenes_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes")
}

fn render_small(mut scene: Scene, w: u32, h: u32) -> caustic::render::Image {
    scene.camera.width = w;
    scene.camera.height = h;
    render_whitted(&scene, &|_| {}).0
}

#[test]
fn every_shipped_scene_loads_and_renders() {
    let mut names: Vec<PathBuf> = std::fs::read_dir(scenes_dir())
        .expect("scenes/")
        .map(|e| e.expect("entry").path())
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .collect();
    names.sort();
    let expected = [
        "builtin",
        "cornell",
        "design",
        "design_pool",
        "glass_teapot",
        "hairpin",
        "inline_patch",
        "leaf",
        "lens",
        "lens_dispersive",
        "pool",
        "prism",
        "ring",
        "ring_gold",
        "ring_usd",
        "ring_window",
        "scroll",
        "showcase",
        "smallppm",
        "teapot",
    ];
    let stems: Vec<String> = names
        .iter()
        .map(|p| p.file_stem().unwrap_or_default().to_string_lossy().into_owned())
        .collect();
    assert_eq!(stems, expected);
    let mut scenes: Vec<(String, Scene)> = names
        .iter()
        .map(|p| {
            (
                p.display().to_string(),
                Scene::load(p).unwrap_or_else(|e| panic!("{e}")),
            )
        })
        .collect();
    scenes.push(("<built-in>".into(), Scene::builtin()));
    for (name, mut scene) in scenes {
        scene.params.dof_samples = scene.params.dof_samples.min(4);
        let image = render_small(scene, 48, 36);
        assert!(
            image.pixels.iter().flatten().all(|c| c.is_finite() && *c >= 0.0),
            "{name}: NaN, infinite or negative radiance"
        );
        let mean = image.mean();
        let var = image
            .pixels
            .iter()
            .flatten()
            .map(|&c| (c as f64 - mean).powi(2))
            .sum::<f64>()
            / (3 * image.pixels.len()) as f64;
        assert!(
            mean > 1e-3 && var.sqrt() > 1e-3,
            "{name}: a blank picture (mean {mean}, sd {})",
            var.sqrt()
        );
    }
}

fn scene_text(extra: &str) -> String {
    format!(
        r#"
[camera]
position = [0, 0, 5]
look_at = [0, 0, 0]
fov = 40
width = 32
height = 24

[materials.m]
type = "diffuse"
color = [0.5, 0.5, 0.5]

[[lights]]
type = "point"
position = [0, 3, 3]
power = 100

[[objects]]
type = "sphere"
center = [0, 0, 0]
radius = 1
material = "m"
{extra}"#
    )
}

#[test]
fn bad_scene_files_are_reported_clearly() {
    let dir = tempfile::tempdir().expect("temp dir");
    let cases: Vec<(String, &str)> = vec![
        ("[camera".into(), "bad.toml:1: "),
        (scene_text("bogus = 1\n"), "unknown field `bogus`"),
        (
            scene_text("").replace("radius = 1", "radius = -2"),
            "bad.toml:18: objects[0] (sphere): 'radius' must be positive, got -2",
        ),
        (
            scene_text("").replace("radius = 1", "radius = nan"),
            "expected a finite number, found NaN",
        ),
        (
            scene_text("").replace("power = 100", "power = inf"),
            "expected a finite number, found inf",
        ),
        // A light bright enough to make an image of infinities is refused at load.
        (
            scene_text("").replace("power = 100", "power = 1e308"),
            "lights[0] (point): 'power' must be positive and at most 1e12 in every colour channel",
        ),
        (
            scene_text("").replace("power = 100", "power = 1e11\ncolor = [1e9, 1, 1]"),
            "'power' must be positive and at most 1e12 in every colour channel (with 'color' applied), got 100000000000000000000",
        ),
        (
            scene_text("").replace(
                "type = \"point\"\nposition = [0, 3, 3]",
                "type = \"sphere\"\ncenter = [0, 3, 3]\nradius = 1e-200",
            ),
            "lights[0] (sphere): 'power' over the light's area makes a radiance of",
        ),
        (
            scene_text("[render]\nambient = [1e30, 0, 0]\n"),
            "'ambient' makes a radiance of 1e30",
        ),
        (
            scene_text("").replace("fov = 40", "fov = \"wide\""),
            "invalid type: string \"wide\", expected a finite number",
        ),
        (
            scene_text("").replace("fov = 40", "fov = 200"),
            "[camera]: 'fov' must be between 0 and 180 degrees, got 200",
        ),
        (
            scene_text("").replace("material = \"m\"", "material = \"chrome\""),
            "objects[0] (sphere): unknown material 'chrome' (defined: m)",
        ),
        (
            scene_text("").replace("type = \"sphere\"", "type = \"torus\""),
            "unknown object type 'torus'",
        ),
        (
            scene_text("").replace("type = \"diffuse\"", "type = \"velvet\""),
            "[materials.m] (velvet): unknown material type 'velvet'",
        ),
        (
            scene_text("").replace("color = [0.5, 0.5, 0.5]", "color = [0.5, 1.5, 0.5]"),
            "'color' components must be between 0 and 1",
        ),
        (
            scene_text("").replace("color = [0.5, 0.5, 0.5]", "color = [0.5, 0.5, 0.5]\nior = 1.3"),
            "'ior' does not apply to type 'diffuse'",
        ),
        (
            scene_text("").replace("radius = 1\n", ""),
            "objects[0] (sphere): missing 'radius'",
        ),
        (
            scene_text("").replace("type = \"diffuse\"", "type = \"metal\"\nconductor = \"brass\""),
            "[materials.m] (metal): unknown conductor 'brass' (expected gold, silver, copper, aluminium, or 'eta' and 'k')",
        ),
        (
            scene_text("").replace("type = \"diffuse\"", "type = \"metal\"\neta = [0.2, 0.4, 1.4]"),
            "[materials.m] (metal): give either 'conductor' (gold, silver, copper, aluminium) or both 'eta' and 'k'",
        ),
        (
            scene_text("").replace("type = \"diffuse\"", "type = \"metal\"\neta = [0, 0.4, 1.4]\nk = [3, 2, 1]"),
            "'eta' components must be above 0 and at most 100",
        ),
        (
            scene_text("").replace("type = \"diffuse\"", "type = \"glass\"\nglass = \"crown\""),
            "[materials.m] (glass): unknown glass 'crown' (expected BK7, F2, SF11, fused silica)",
        ),
        (
            scene_text("").replace("type = \"diffuse\"", "type = \"glass\"\nglass = \"BK7\"\nior = 1.5"),
            "[materials.m] (glass): 'glass = \"BK7\"' gives the index itself: leave out 'ior' and 'abbe'",
        ),
        (
            scene_text("").replace("type = \"diffuse\"", "type = \"glass\"\nabbe = 0.5"),
            "[materials.m] (glass): 'abbe' must be between 1 and 1000, got 0.5",
        ),
        (
            scene_text("").replace("type = \"diffuse\"", "type = \"glass\"\nior = 0.2\nabbe = 1"),
            "[materials.m] (glass): 'abbe' 1 with 'ior' 0.2 gives an index of",
        ),
        (
            scene_text("").replace("type = \"diffuse\"", "type = \"diffuse\"\nabbe = 40"),
            "'abbe' does not apply to type 'diffuse'",
        ),
        (
            scene_text("").replace("type = \"diffuse\"", "type = \"mirror\"\nroughness = 1.5"),
            "[materials.m] (mirror): 'roughness' (GGX α) must be between 0 and 1, got 1.5",
        ),
        (
            scene_text("").replace("type = \"diffuse\"", "type = \"diffuse\"\nroughness = 0.2"),
            "'roughness' does not apply to type 'diffuse'",
        ),
        (
            scene_text("[[objects]]\ntype = \"mesh\"\nfile = \"nope.obj\"\nmaterial = \"m\"\n"),
            "nope.obj' does not exist",
        ),
        (
            scene_text("[[objects]]\ntype = \"patches\"\nfile = \"broken.bpt\"\nmaterial = \"m\"\n"),
            "broken.bpt:2: patch 1: expected degrees '3 3'",
        ),
        // A patches file that is a folder, or a link to a device, is named as what it is.
        (
            scene_text("[[objects]]\ntype = \"patches\"\nfile = \"folder.bpt\"\nmaterial = \"m\"\n"),
            "folder.bpt' is a folder, not a file",
        ),
        (
            scene_text("[[objects]]\ntype = \"patches\"\nfile = \"zero.bpt\"\nmaterial = \"m\"\n"),
            "zero.bpt' is not a regular file (a device, FIFO or socket)",
        ),
        (
            scene_text("[[objects]]\ntype = \"patches\"\nbuiltin = \"kettle\"\nmaterial = \"m\"\n"),
            "unknown 'builtin' patches 'kettle'",
        ),
        (
            scene_text("").replace("look_at = [0, 0, 0]", "look_at = [0, 0, 5]"),
            "'look_at' equals 'position'",
        ),
        (
            scene_text("").replace("width = 32", "width = 0"),
            "'width' must be between 1 and 16384 pixels, got 0",
        ),
        (
            scene_text("[render]\nalpha = 1.5\n"),
            "[render]: 'alpha' must be in (0, 1], got 1.5",
        ),
        (
            scene_text("[render]\nrenderer = \"pbrt\"\n"),
            "'renderer' must be \"whitted\" or \"ppm\"",
        ),
        (
            scene_text("").replace("type = \"point\"", "type = \"laser\""),
            "lights[0] (laser): unknown light type 'laser'",
        ),
        (
            scene_text("").replace("power = 100", "power = 100\nintensity = 3"),
            "lights[0] (point): needs exactly one of 'power' or 'intensity'",
        ),
        (
            scene_text("").replace(
                "[[lights]]\ntype = \"point\"\nposition = [0, 3, 3]\npower = 100\n",
                "",
            ),
            "the scene has no [[lights]]",
        ),
        (
            scene_text("").replace(
                "type = \"diffuse\"",
                "type = \"diffuse\"\ntexture = { file = \"missing.png\" }",
            ),
            "missing.png' does not exist",
        ),
        (
            scene_text("").replace(
                "type = \"diffuse\"",
                "type = \"diffuse\"\ntexture = { file = \"not-an-image.png\" }",
            ),
            "not-an-image.png: cannot read texture image",
        ),
    ];
    std::fs::write(dir.path().join("broken.bpt"), "1\n3 4\n").expect("write");
    std::fs::create_dir(dir.path().join("folder.bpt")).expect("folder");
    std::os::unix::fs::symlink("/dev/zero", dir.path().join("zero.bpt")).expect("link");
    std::fs::write(dir.path().join("not-an-image.png"), "hello").expect("write");
    let path = dir.path().join("bad.toml");
    for (text, expected) in cases {
        std::fs::write(&path, &text).expect("write");
        let err = match Scene::load(&path) {
            Ok(_) => panic!("accepted a bad scene (expected '{expected}'):\n{text}"),
            Err(e) => e.to_string(),
        };
        assert!(err.contains(expected), "expected '{expected}' in:\n{err}");
        assert!(
            err.starts_with(&path.display().to_string()),
            "error does not name the file: {err}"
        );
    }
    let missing = Scene::load(&dir.path().join("absent.toml")).expect_err("missing");
    assert!(missing
        .to_string()
        .contains("absent.toml:0: the scene file does not exist"));
}

#[test]
fn diffuse_plane_under_a_point_light_matches_the_closed_form() {
    let text = r#"
[camera]
position = [0.3, 4, 0.2]
look_at = [0, 0, 0]
up = [0, 0, 1]
fov = 60
width = 16
height = 12

[render]
antialias = false

[materials.floor]
type = "diffuse"
color = [0.6, 0.3, 0.9]

[[lights]]
type = "point"
position = [1.0, 2.5, -0.7]
power = 40

[[objects]]
type = "plane"
point = [0, 0, 0]
normal = [0, 1, 0]
material = "floor"
"#;
    let scene = Scene::from_str(text, Path::new("plane.toml"), None).expect("scene");
    let image = render_whitted(&scene, &|_| {}).0;
    let rho = DVec3::new(0.6, 0.3, 0.9);
    let light = DVec3::new(1.0, 2.5, -0.7);
    let intensity = 40.0 / (4.0 * PI);
    let mut checked = 0;
    for y in 0..12 {
        for x in 0..16 {
            let ray = scene.camera.ray(Scene::pixel_center(x, y), DVec2::ZERO);
            if ray.dir.y >= 0.0 {
                continue;
            }
            let p = ray.at(-ray.origin.y / ray.dir.y);
            let d = light - p;
            let cos = d.normalize().y;
            let expected = rho / PI * intensity * cos / d.length_squared();
            let got = image.get(x, y);
            for c in 0..3 {
                let rel = (got[c] as f64 - expected[c]).abs() / expected[c];
                assert!(
                    rel < 1e-6,
                    "pixel ({x},{y}) channel {c}: {} vs {}",
                    got[c],
                    expected[c]
                );
            }
            checked += 1;
        }
    }
    assert!(checked > 60);
}

/// Pixels brighter than half the peak: how spread out a small bright object's image is.
fn spread(image: &caustic::render::Image) -> usize {
    let peak = image.pixels.iter().map(|p| p[0]).fold(0.0f32, f32::max);
    image.pixels.iter().filter(|p| p[0] > 0.5 * peak).count()
}

#[test]
fn depth_of_field_keeps_the_focal_plane_sharp() {
    let scene_at = |z: f64, aperture: f64| {
        let text = format!(
            r#"
[camera]
position = [0, 0, 0]
look_at = [0, 0, 10]
fov = 20
aperture = {aperture}
focal_distance = 10
width = 64
height = 64

[render]
antialias = false
dof_samples = 64

[materials.black]
type = "diffuse"
color = [0, 0, 0]

[[lights]]
type = "sphere"
center = [0, 0, {z}]
radius = 0.15
power = 10

[[objects]]
type = "plane"
point = [0, 0, 30]
normal = [0, 0, -1]
material = "black"
"#
        );
        let scene = Scene::from_str(&text, Path::new("dof.toml"), None).expect("scene");
        render_whitted(&scene, &|_| {}).0
    };
    let sharp_pinhole = spread(&scene_at(10.0, 0.0));
    let sharp_lens = spread(&scene_at(10.0, 1.0));
    let near_pinhole = spread(&scene_at(5.0, 0.0));
    let near_lens = spread(&scene_at(5.0, 1.0));
    // In focus: the lens changes the image little; out of focus it spreads it out.
    assert!(
        (sharp_lens as f64) < 1.5 * sharp_pinhole as f64 + 4.0,
        "{sharp_lens} vs {sharp_pinhole}"
    );
    assert!(
        near_lens as f64 > 3.0 * near_pinhole as f64,
        "{near_lens} vs {near_pinhole}"
    );
}

#[test]
fn glass_slab_transmits_the_fresnel_fraction() {
    // Looking through a slab of glass (n = 1.5) at a quad light head-on: every bounce between
    // the faces adds T²R²ᵏ, so the total transmitted fraction is (1 − R)/(1 + R), R = 0.04.
    let text = r#"
[camera]
position = [0, 0, -5]
look_at = [0, 0, 0]
fov = 2
width = 4
height = 4

[render]
antialias = false
max_depth = 40
light_samples = 1

[materials.glass]
type = "glass"
color = [1, 1, 1]
ior = 1.5

[[lights]]
type = "quad"
corner = [-50, -50, 5]
edge_u = [0, 100, 0]
edge_v = [100, 0, 0]
power = 31415.926535897932

[[objects]]
type = "quad"
corner = [-20, -20, -0.5]
edge_u = [40, 0, 0]
edge_v = [0, 40, 0]
material = "glass"

[[objects]]
type = "quad"
corner = [-20, -20, 0.5]
edge_u = [40, 0, 0]
edge_v = [0, 40, 0]
material = "glass"
"#;
    let scene = Scene::from_str(text, Path::new("slab.toml"), None).expect("scene");
    let emitted = 31415.926535897932 / (PI * 100.0 * 100.0);
    let image = render_whitted(&scene, &|_| {}).0;
    let r = 0.04;
    let expected = emitted * (1.0 - r) / (1.0 + r);
    for p in &image.pixels {
        let rel = (p[0] as f64 - expected).abs() / expected;
        assert!(rel < 1e-6, "{} vs {expected}", p[0]);
    }
}

#[test]
fn patch_textures_use_the_original_parameters() {
    let scene = Scene::load(&scenes_dir().join("scroll.toml")).expect("scroll scene");
    let (sheet, obj) = scene.geometry.patches()[0];
    let material = &scene.materials[scene.objects[obj as usize].material];
    let texture = &scene.textures[material.texture.expect("the sheet is textured")];
    let mut checked = 0;
    for i in 1..20 {
        for j in 1..20 {
            let (u, v) = (i as f64 / 20.0, j as f64 / 20.0);
            let target = sheet.eval(u, v);
            let ray = caustic::geometry::Ray::new(scene.camera.position, target - scene.camera.position);
            let hit = scene
                .geometry
                .intersect(&ray, f64::INFINITY)
                .expect("sheet visible");
            if hit.object != obj || (hit.point - target).length() > 1e-9 {
                continue;
            }
            let expected = texture.sample(DVec2::new(u, v));
            assert!(
                (scene.albedo(material, &hit) - expected).length() < 1e-6,
                "texel at ({u},{v})"
            );
            checked += 1;
        }
    }
    assert!(checked > 300, "{checked} texture checks");
}

#[test]
fn renders_are_identical_for_one_and_two_threads() {
    let mut scene = Scene::load(&scenes_dir().join("cornell.toml")).expect("scene");
    scene.camera.width = 64;
    scene.camera.height = 48;
    let one = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .expect("pool");
    let two = rayon::ThreadPoolBuilder::new()
        .num_threads(2)
        .build()
        .expect("pool");
    let a = one.install(|| render_whitted(&scene, &|_| {}).0);
    let b = two.install(|| render_whitted(&scene, &|_| {}).0);
    assert_eq!(a.pixels, b.pixels);
    scene.camera.aperture = 0.2;
    scene.params.dof_samples = 4;
    let a = one.install(|| render_whitted(&scene, &|_| {}).0);
    let b = two.install(|| render_whitted(&scene, &|_| {}).0);
    assert_eq!(a.pixels, b.pixels);
    // A dispersive lens, which the ray tracer splits into a wavelength per channel.
    let mut scene = Scene::load(&scenes_dir().join("lens_dispersive.toml")).expect("scene");
    (scene.camera.width, scene.camera.height) = (64, 48);
    let a = one.install(|| render_whitted(&scene, &|_| {}).0);
    let b = two.install(|| render_whitted(&scene, &|_| {}).0);
    assert_eq!(a.pixels, b.pixels);
}

/// FORMAT.md's inline-patch example is `scenes/inline_patch.toml` word for word, and its patch
/// faces up as the text says (u along +z, v along +x: normal +z × +x = +y).
#[test]
fn the_inline_patch_example_is_the_shipped_scene_and_faces_up() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let scene_text = std::fs::read_to_string(root.join("scenes/inline_patch.toml")).expect("scene");
    let format = std::fs::read_to_string(root.join("scenes/FORMAT.md")).expect("FORMAT.md");
    assert!(
        format.contains(&format!("```toml\n{scene_text}```")),
        "FORMAT.md's example differs from scenes/inline_patch.toml"
    );
    let scene = Scene::load(&root.join("scenes/inline_patch.toml")).expect("loads");
    let (patch, _) = scene.geometry.patches()[0];
    let n = patch.normal(0.5, 0.5).expect("a normal");
    assert!(n.dot(glam::DVec3::Y) > 0.99, "normal {n}");
    assert!((patch.eval(0.0, 1.0) - glam::DVec3::new(1.0, 1.5, -1.0)).length() < 1e-12);
}

#[test]
fn the_brightest_light_allowed_renders_a_finite_image() {
    // A terawatt point light a hundredth of its radius from the sphere, seen by every renderer.
    let text = scene_text("")
        .replace("power = 100", "power = 1e12")
        .replace("position = [0, 3, 3]", "position = [0, 0, 1.01]");
    let scene = Scene::from_str(&text, Path::new("bright.toml"), None).expect("loads");
    for kind in [RendererKind::Whitted, RendererKind::Ppm, RendererKind::Path] {
        let mut scene = scene.clone();
        scene.params.renderer = kind;
        scene.params.photons_per_pass = 2000;
        // The ray tracer makes one frame and waits; the others stop after two passes.
        let passes = if kind == RendererKind::Whitted { 1 } else { 2 };
        let frame = render_frames(scene, passes);
        assert!(
            frame.radiance.iter().flatten().all(|c| c.is_finite()),
            "{kind:?} made a non-finite pixel"
        );
        let brightest = frame.radiance.iter().flatten().fold(0.0f32, |m, &c| m.max(c));
        assert!(brightest > 1e6, "{kind:?}: the light is seen ({brightest})");
    }
}

/// The last frame of `passes` passes of `scene` on a headless render session.
fn render_frames(scene: Scene, passes: u32) -> caustic::render::session::Frame {
    use caustic::render::session::{RenderSession, SessionOptions};
    let options = SessionOptions {
        max_passes: Some(passes),
        every_frame: true,
        ..Default::default()
    };
    let session = RenderSession::start_with(scene, options, None);
    let last = session.frames().iter().last();
    assert!(session.failure().is_none(), "{:?}", session.failure());
    last.expect("a frame")
}
