//! Vertex connection and merging against closed forms, the path tracer and photon mapping: an
//! integrating sphere, every light kind over a plane, the Cornell box's converged mean (also
//! with merging off, a bidirectional path tracer, and with connections off, photon mapping),
//! caustics seen directly and through a mirror, and the same image for one and two threads.

mod common;

use std::path::Path;

use caustic::render::integrator::vcm::Vcm;
use caustic::render::integrator::{make, Setup};
use caustic::render::vcm::Techniques;
use caustic::scene::{RendererKind, Scene};
use common::lighting::{assert_furnace, assert_light_kinds};
use common::rendered;

/// `passes` passes of VCM with `techniques`.
fn vcm(scene: &Scene, techniques: Techniques, passes: u32) -> Vec<[f32; 3]> {
    rendered(
        Box::new(Vcm::with_techniques(scene, &Setup::default(), techniques)),
        scene,
        passes,
    )
}

const BPT: Techniques = Techniques {
    connect: true,
    merge: false,
};
const MERGES: Techniques = Techniques {
    connect: false,
    merge: true,
};

/// Channel `c`'s mean.
fn mean(image: &[[f32; 3]], c: usize) -> f64 {
    image.iter().map(|p| p[c] as f64).sum::<f64>() / image.len() as f64
}

fn cornell(width: u32, height: u32) -> Scene {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/cornell.toml");
    let mut scene = Scene::load(&path).expect("cornell");
    (scene.camera.width, scene.camera.height) = (width, height);
    scene
}

/// The furnace ([`assert_furnace`]): every bounce counts, and every technique reaches some
/// of them.
#[test]
fn an_integrating_sphere_gives_its_closed_form() {
    assert_furnace("VCM", |scene| vcm(scene, Techniques::ALL, 256));
}

/// Every light kind over the diffuse plane: the closed form within 1 %.
#[test]
fn every_light_kind_over_a_plane_gives_the_closed_form() {
    assert_light_kinds("VCM", |scene| vcm(scene, Techniques::ALL, 256));
}

/// Whether `got`'s mean is within 0.5 % of `traced`'s, channel by channel.
fn assert_means_agree(name: &str, traced: &[[f32; 3]], got: &[[f32; 3]]) {
    for c in 0..3 {
        let (pt, v) = (mean(traced, c), mean(got, c));
        let gap = v / pt - 1.0;
        eprintln!(
            "{name} channel {c}: path traced {pt:.5}, VCM {v:.5} ({:+.3} %)",
            100.0 * gap
        );
        assert!(gap.abs() < 0.005, "{name} channel {c}: {gap}");
    }
}

/// The Cornell box (glass and mirror spheres, an area light, a Phong teapot): VCM's converged
/// mean, channel by channel, within 0.5 % of the path tracer's, and so are those of its two
/// halves: the bidirectional path tracer (merging off) and photon mapping (connections off).
#[test]
fn the_cornell_box_converges_to_the_path_tracers_mean() {
    let scene = cornell(40, 30);
    let traced = rendered(make(RendererKind::Path, &scene, &Setup::default()), &scene, 4096);
    for (name, techniques, passes) in [
        ("vcm", Techniques::ALL, 512),
        ("bpt", BPT, 512),
        ("merges", MERGES, 1024),
    ] {
        assert_means_agree(name, &traced, &vcm(&scene, techniques, passes));
    }
}

/// Every material in the Cornell box: the mirror sphere made of rough gold (α 0.2), the glass
/// sphere frosted (α 0.1, refraction's densities in both directions) or made of dispersive
/// flint glass (SF11, a wavelength fixed on either subpath): VCM's mean within 0.5 % of the
/// path tracer's. The merging radius is a 320-pixel-wide render's: at 40 × 30 the automatic
/// one is a third of the frosted sphere's radius, and merges on it blur over its curvature
/// (merges alone +0.7 % there, while the connections alone are within 0.001 %).
#[test]
fn every_material_converges_to_the_path_tracers_mean() {
    use caustic::scene::MaterialKind;
    let mut base = cornell(40, 30);
    base.params.initial_radius = Some(0.02);
    let with = |change: &dyn Fn(&mut MaterialKind)| {
        let mut scene = base.clone();
        scene.materials.iter_mut().for_each(|m| change(&mut m.kind));
        scene
    };
    let (eta, k) = caustic::scene::metals::named("gold").expect("gold");
    let gold = with(&|m| {
        if matches!(m, MaterialKind::Mirror { .. }) {
            *m = MaterialKind::Metal {
                eta,
                k,
                roughness: 0.2,
            };
        }
    });
    let frosted = with(&|m| {
        if let MaterialKind::Glass { roughness, .. } = m {
            *roughness = 0.1;
        }
    });
    let sf11 = caustic::scene::glasses::Dispersion::named("SF11").expect("SF11");
    let flint = with(&|m| {
        if matches!(m, MaterialKind::Glass { .. }) {
            *m = MaterialKind::Glass {
                ior: sf11.ior(0.0, caustic::scene::glasses::D_LINE_NM),
                roughness: 0.0,
                dispersion: sf11,
            };
        }
    });
    for (name, scene) in [
        ("rough gold α 0.2", gold),
        ("frosted glass α 0.1", frosted),
        ("SF11", flint),
    ] {
        let traced = rendered(make(RendererKind::Path, &scene, &Setup::default()), &scene, 4096);
        assert_means_agree(name, &traced, &vcm(&scene, Techniques::ALL, 512));
    }
}

/// A caustic seen directly and one seen through a mirror both survive: under a point light, a
/// glass sphere focuses light on a floor, and an upright mirror beside it shows the floor. The
/// caustic's pixels are many times brighter than the floor around it in VCM's image as in
/// photon mapping's, directly and in the mirror.
#[test]
fn caustics_seen_directly_and_through_a_mirror_survive() {
    let text = r#"
[camera]
position = [0, 4, 6]
look_at = [0, 0.3, 0]
fov = 60
width = 64
height = 48

[render]
antialias = true
photons_per_pass = 100000

[materials.floor]
type = "diffuse"
color = [0.7, 0.7, 0.7]

[materials.glass]
type = "glass"
ior = 1.5

[materials.mirror]
type = "mirror"

[[lights]]
type = "point"
position = [0, 5, 0]
power = 300

[[objects]]
type = "plane"
point = [0, 0, 0]
normal = [0, 1, 0]
material = "floor"

[[objects]]
type = "sphere"
center = [0, 1.2, 0]
radius = 0.6
material = "glass"

[[objects]]
type = "quad"
corner = [-1.5, 0, -3]
edge_u = [0, 0, 8]
edge_v = [0, 3, 0]
material = "mirror"
"#;
    let scene = Scene::from_str(text, Path::new("caustic.toml"), None).expect("scene");
    let image = vcm(&scene, Techniques::ALL, 64);
    let mut ppm = scene.clone();
    ppm.params.renderer = RendererKind::Ppm;
    let mapped = rendered(make(RendererKind::Ppm, &ppm, &Setup::default()), &ppm, 64);
    let w = scene.camera.width as usize;
    // Where the caustic lands (the floor under the sphere, at its focus) and a lit floor
    // pixel beside it, found by projecting the points; their images in the mirror likewise,
    // by reflecting the points in the mirror's plane (x = -1.5).
    let pixel_of = |p: glam::DVec3| {
        let r = scene.camera.project(p).expect("in view");
        (r.x as usize, r.y as usize)
    };
    let focus = glam::DVec3::new(0.0, 0.0, 0.0);
    let beside = glam::DVec3::new(0.0, 0.0, 1.3);
    let mirrored = |p: glam::DVec3| glam::DVec3::new(-3.0 - p.x, p.y, p.z);
    // The brightest of the 3 × 3 pixels around a point (the focus is smaller than a pixel).
    let lum = |image: &[[f32; 3]], (x, y): (usize, usize)| {
        let near = (y - 1..=y + 1).flat_map(|j| (x - 1..=x + 1).map(move |i| j * w + i));
        near.map(|i| image[i][1] as f64).fold(0.0, f64::max)
    };
    for (name, a, b) in [
        ("seen directly", pixel_of(focus), pixel_of(beside)),
        (
            "through the mirror",
            pixel_of(mirrored(focus)),
            pixel_of(mirrored(beside)),
        ),
    ] {
        let (vcm_ratio, ppm_ratio) = (lum(&image, a) / lum(&image, b), lum(&mapped, a) / lum(&mapped, b));
        eprintln!("{name}: caustic / floor: VCM {vcm_ratio:.2}, photon mapping {ppm_ratio:.2}");
        assert!(
            ppm_ratio > 3.0,
            "{name}: the test's caustic is not where it is looked for ({ppm_ratio})"
        );
        assert!(
            vcm_ratio > 0.5 * ppm_ratio,
            "{name}: VCM {vcm_ratio}, photon mapping {ppm_ratio}"
        );
    }
}

/// The same seed gives the same image, bit for bit, on one thread and two (open aperture, so
/// the lens samples count too); another seed gives another.
#[test]
fn vcm_is_identical_for_one_and_two_threads() {
    let mut scene = cornell(40, 30);
    scene.camera.aperture = 0.2;
    let pool = |n| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build()
            .expect("pool")
    };
    let [one, two] = [1, 2].map(|n| pool(n).install(|| vcm(&scene, Techniques::ALL, 4)));
    assert_eq!(one, two);
    let mut other_seed = scene.clone();
    other_seed.params.seed = 2;
    assert_ne!(
        vcm(&other_seed, Techniques::ALL, 4),
        one,
        "the seed changes the samples"
    );
}

/// `caustic render --renderer vcm` renders passes, reports them, records them, and `--from`
/// renders the same pixels again.
#[test]
fn render_with_vcm_reports_and_reproduces() {
    let dir = tempfile::tempdir().expect("temp dir");
    let (first, second) = (dir.path().join("a.exr"), dir.path().join("b.exr"));
    let first_arg = first.to_str().expect("utf-8");
    let out = common::caustic(&[&VCM_CORNELL[..], &["--out", first_arg]].concat());
    let t = common::text(&out);
    assert!(out.status.success(), "{t}");
    assert!(t.contains("40x30, 5 passes"), "{t}");
    assert!(t.contains("light vertices"), "{t}");
    let again = common::caustic(&[
        "render",
        "--from",
        first_arg,
        "--out",
        second.to_str().expect("utf-8"),
        "--json",
    ]);
    let json: serde_json::Value = serde_json::from_slice(&again.stdout).expect("JSON summary");
    assert_eq!(json["vcm"]["passes"], 5, "{json}");
    assert!(
        json["vcm"]["initial_radius"].as_f64().is_some_and(|r| r > 0.0),
        "{json}"
    );
    let [a, b] = [&first, &second].map(|p| image::open(p).expect("EXR").into_rgb32f().into_raw());
    assert_eq!(a, b, "--from renders the same pixels");
}

/// `render --renderer vcm`: five passes of the Cornell box at 40 pixels wide.
const VCM_CORNELL: [&str; 8] = [
    "render",
    "scenes/cornell.toml",
    "--renderer",
    "vcm",
    "--width",
    "40",
    "--passes",
    "5",
];

/// VCM's passes are independent: `--shard` renders a part of VCM passes; two shards merged
/// equal the one-shard render bit for bit (on one thread and on two) and the plain render
/// within float rounding; `render --from` a part renders its passes again; a part's settings
/// tell it from a photon-mapped part of the same scene; `--renderer path` is refused, saying
/// why.
#[test]
fn vcm_shards_merge_into_the_plain_render() {
    let dir = tempfile::tempdir().expect("temp dir");
    let path = |name: &str| dir.path().join(name).to_str().expect("utf-8").to_owned();
    let shard = |k: &str, out: &str, threads: &str| {
        let out = common::caustic(
            &[
                &VCM_CORNELL[..],
                &["--shard", k, "--out", &path(out), "--threads", threads],
            ]
            .concat(),
        );
        let t = common::text(&out);
        assert!(out.status.success(), "{t}");
        assert!(t.contains("light subpaths"), "{t}");
    };
    shard("0/2", "p0.exr", "1");
    shard("1/2", "p1.exr", "2");
    shard("0/1", "all.exr", "2");
    let merge = |parts: &[&str], out: &str| {
        let mut args = vec!["merge".to_owned()];
        args.extend(parts.iter().map(|p| path(p)));
        args.extend(["--out".to_owned(), path(out)]);
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        common::caustic(&args)
    };
    for (parts, out) in [
        (&["p0.exr", "p1.exr"][..], "merged.exr"),
        (&["all.exr"][..], "one.exr"),
    ] {
        let done = merge(parts, out);
        assert!(done.status.success(), "{}", common::text(&done));
    }
    let plain = common::caustic(&[&VCM_CORNELL[..], &["--out", &path("plain.exr")]].concat());
    assert!(plain.status.success(), "{}", common::text(&plain));
    let [merged, one, plain] = ["merged.exr", "one.exr", "plain.exr"]
        .map(|p| image::open(path(p)).expect("EXR").into_rgb32f().into_raw());
    assert_eq!(
        merged, one,
        "two shards merged are the one-shard render, bit for bit"
    );
    assert!(merged.iter().any(|&v| v > 0.0), "the image is not black");
    for (m, p) in merged.iter().zip(&plain) {
        assert!(
            (m - p).abs() <= 1e-5 * p.abs().max(1e-3),
            "{m} against the plain render's {p}"
        );
    }
    let again = common::caustic(&[
        "render",
        "--from",
        &path("p0.exr"),
        "--shard",
        "1/2",
        "--out",
        &path("p1b.exr"),
    ]);
    assert!(again.status.success(), "{}", common::text(&again));
    let [p1, p1b] =
        ["p1.exr", "p1b.exr"].map(|p| image::open(path(p)).expect("EXR").into_rgb32f().into_raw());
    assert_eq!(p1, p1b, "a sibling shard from a part's record");
    let ppm = common::caustic(&[
        "render",
        "scenes/cornell.toml",
        "--width",
        "40",
        "--passes",
        "5",
        "--photons",
        "2000",
        "--shard",
        "1/2",
        "--out",
        &path("q1.exr"),
    ]);
    assert!(ppm.status.success(), "{}", common::text(&ppm));
    let mixed = merge(&["p0.exr", "q1.exr"], "mixed.exr");
    let t = common::text(&mixed);
    assert!(
        !mixed.status.success() && t.contains("renderer \"vcm\" and \"ppm\""),
        "{t}"
    );
    // A folder of VCM parts, as `view --watch` sees it: VCM's frame, light subpaths counted.
    let read = |p: &str| caustic::render::shard::Part::read(Path::new(&path(p))).expect("reads");
    assert_eq!(read("merged.exr").renderer(), RendererKind::Vcm);
    assert_eq!(read("q1.exr").renderer(), RendererKind::Ppm);
    let folder = tempfile::tempdir().expect("temp dir");
    for p in ["p0.exr", "p1.exr"] {
        std::fs::copy(path(p), folder.path().join(p)).expect("copies");
    }
    let mut merge = caustic::render::shard::FolderMerge::new();
    let update = caustic::app::watch::scan(&mut merge, folder.path(), std::time::Instant::now());
    assert_eq!(update.summary.renderer, RendererKind::Vcm);
    assert_eq!(update.summary.renderer.emitted(), "light subpaths");
    let frame = update.frame.expect("a merged frame");
    assert_eq!(frame.stats.renderer(), RendererKind::Vcm);
    let mut path_tracer = VCM_CORNELL;
    path_tracer[3] = "path";
    let refused = common::caustic(&[&path_tracer[..], &["--shard", "0/2", "--out", &path("r.exr")]].concat());
    let t = common::text(&refused);
    assert!(!refused.status.success(), "{t}");
    assert!(
        t.contains("--renderer path") && t.contains("only photon mapping"),
        "{t}"
    );
}
