//! Independent passes with the global radius schedule (Knaus & Zwicker 2011): shards merged
//! equal the one-process render bit for bit (fixed-point sums), for any thread count; every
//! merge refusal has its message; merges merge again; the global schedule converges to the
//! per-point image; and the command line's shard → merge → `render --from` round trip.

use std::path::Path;

use caustic::render::image_metadata;
use caustic::render::ppm::{Control, Ppm, PpmOptions};
use caustic::render::shard::{Part, PassSums, Shard};
use caustic::scene::Scene;
use caustic::settings::{RadiusSchedule, RendererKind};

mod common;
use common::{caustic, pool, text};

/// `scenes/inline_patch.toml` (a glass sheet over a floor under a point light: a caustic) at
/// `width` pixels, photon mapped with the global schedule; `antialias` off makes it classic PPM.
fn sheet(width: u32, antialias: bool) -> Scene {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/inline_patch.toml");
    let mut scene = Scene::load(&path).expect("scenes/inline_patch.toml loads");
    scene.camera.resize(Some(width), None);
    scene.params.renderer = RendererKind::Ppm;
    scene.params.photons_per_pass = 20_000;
    scene.params.min_photons_per_pixel = 0.0;
    scene.params.antialias = antialias;
    scene.params.radius_schedule = RadiusSchedule::Global;
    scene
}

/// The sums of shard `shard` of a `total`-pass render.
fn shard_sums(scene: &Scene, shard: Shard, total: u32) -> PassSums {
    let mut ppm = Ppm::new(scene, PpmOptions::default());
    ppm.render_only(caustic::render::shard::PassSet::Shard(shard));
    ppm.photons_per_pass = scene.params.photons_per_pass;
    for _ in 0..shard.passes_of(total) {
        ppm.run_pass(scene, &mut |_| Control::Continue);
    }
    ppm.pass_sums().expect("global schedule").clone()
}

/// A part of `sums` as `render --shard` writes it.
fn part(scene: &Scene, sums: PassSums, total: u32) -> Part {
    let settings = toml::to_string(&scene.params).expect("settings");
    Part::new(sums, total, image_metadata(scene, "ppm", None), settings)
}

#[test]
fn merged_shards_equal_the_one_process_render_bit_for_bit() {
    for antialias in [false, true] {
        let scene = sheet(40, antialias);
        for (n, total) in [(2u32, 6u32), (3, 7), (4, 9)] {
            let one = pool(2).install(|| shard_sums(&scene, Shard::default(), total));
            assert_eq!(one.passes().len(), total as usize);
            let mut merged = PassSums::new(one.size().0, one.size().1);
            for k in 0..n {
                // Shards on one thread, the one-process render on two.
                let s = pool(1).install(|| shard_sums(&scene, Shard { index: k, count: n }, total));
                merged.add(&s).expect("disjoint shards");
            }
            assert_eq!(
                merged, one,
                "{n} shards of {total} passes (antialias {antialias})"
            );
            let (a, b) = (merged.mean(), one.mean());
            assert!(a
                .iter()
                .zip(&b)
                .all(|(x, y)| x.map(f32::to_bits) == y.map(f32::to_bits)));
            assert!(one.mean().iter().any(|p| p[0] > 0.0), "the image is not black");
        }
    }
}

#[test]
fn part_files_round_trip_and_merges_merge_again() {
    let dir = tempfile::tempdir().expect("temp dir");
    let scene = sheet(32, true);
    let total = 8;
    let paths: Vec<_> = (0..4)
        .map(|k| {
            let path = dir.path().join(format!("part_{k}.exr"));
            let sums = shard_sums(&scene, Shard { index: k, count: 4 }, total);
            part(&scene, sums, total).write(&path, false).expect("writes");
            path
        })
        .collect();
    let read: Vec<Part> = paths.iter().map(|p| Part::read(p).expect("reads")).collect();
    let expected = shard_sums(&scene, Shard { index: 1, count: 4 }, total);
    assert_eq!(read[1].sums, expected, "a part reads back exactly");
    // (0 + 1) and (2 + 3), written, read and merged again.
    let mut left = read[0].clone();
    left.merge(&paths[0], &read[1], &paths[1]).expect("0 and 1 merge");
    let mut right = read[2].clone();
    right
        .merge(&paths[2], &read[3], &paths[3])
        .expect("2 and 3 merge");
    let (lp, rp) = (dir.path().join("left.exr"), dir.path().join("right.exr"));
    left.write(&lp, false).expect("writes");
    right.write(&rp, false).expect("writes");
    let mut all = Part::read(&lp).expect("reads");
    all.merge(&lp, &Part::read(&rp).expect("reads"), &rp)
        .expect("merges merge");
    assert!(all.is_complete());
    assert_eq!(all.sums, shard_sums(&scene, Shard::default(), total));
    assert_eq!(all.get("caustic:passes"), Some("8"));
    assert_eq!(all.get("caustic:pass_list"), Some("0-7"));
}

#[test]
fn every_merge_refusal_names_what_differs() {
    let dir = tempfile::tempdir().expect("temp dir");
    let scene = sheet(24, true);
    let write = |name: &str, scene: &Scene, shard: Shard, total: u32, edit: &dyn Fn(&mut Part)| {
        let path = dir.path().join(name);
        let mut p = part(scene, shard_sums(scene, shard, total), total);
        edit(&mut p);
        p.write(&path, false).expect("writes");
        path
    };
    let none = |_: &mut Part| {};
    let base = write("base.exr", &scene, Shard { index: 0, count: 2 }, 4, &none);
    let refusal = |other: &Path| -> String {
        let ours = Part::read(&base).expect("reads");
        let theirs = Part::read(other).expect("reads");
        ours.check_joins(&base, &theirs, other)
            .expect_err("refused")
            .to_string()
    };
    let other_shard = Shard { index: 1, count: 2 };
    let version = write("version.exr", &scene, other_shard, 4, &|p: &mut Part| {
        for (k, v) in &mut p.metadata {
            if k == "Software" {
                *v = "caustic 0.0.1".into();
            }
        }
    });
    assert!(
        refusal(&version).contains("written by different programs"),
        "{}",
        refusal(&version)
    );
    let mut small = scene.clone();
    small.camera.resize(Some(20), None);
    let size = write("size.exr", &small, other_shard, 4, &none);
    assert!(
        refusal(&size).contains("image sizes differ: 24x"),
        "{}",
        refusal(&size)
    );
    let mut alpha = scene.clone();
    alpha.params.alpha = 0.5;
    let settings = write("alpha.exr", &alpha, other_shard, 4, &none);
    assert!(
        refusal(&settings).contains("render settings differ: alpha 0.7 and 0.5"),
        "{}",
        refusal(&settings)
    );
    // Another scene text (the same settings and size).
    let text = scene.text.replace("[camera]", "# another scene\n[camera]");
    assert_ne!(text, *scene.text);
    let mut moved = Scene::from_str(&text, &scene.source, scene.base_dir.as_deref()).expect("loads");
    moved.camera.resize(Some(24), None);
    moved.params = scene.params.clone();
    let scene_file = write("scene.exr", &moved, other_shard, 4, &none);
    assert!(
        refusal(&scene_file).contains("scenes differ"),
        "{}",
        refusal(&scene_file)
    );
    let longer = write("longer.exr", &scene, other_shard, 6, &none);
    assert!(
        refusal(&longer).contains("different lengths: 4 and 6 passes"),
        "{}",
        refusal(&longer)
    );
    let overlap = write("overlap.exr", &scene, Shard { index: 0, count: 4 }, 4, &none);
    assert!(
        refusal(&overlap).contains("both hold pass 0"),
        "{}",
        refusal(&overlap)
    );
    let fine = write("fine.exr", &scene, other_shard, 4, &none);
    let ours = Part::read(&base).expect("reads");
    ours.check_joins(&base, &Part::read(&fine).expect("reads"), &fine)
        .expect("the other shard joins");
    // What is not a part says so.
    let half = dir.path().join("half.exr");
    std::fs::write(&half, &std::fs::read(&fine).expect("read")[..1000]).expect("write");
    let e = Part::read(&half).expect_err("half a file").to_string();
    assert!(e.contains("half.exr") && e.contains("not a readable EXR"), "{e}");
}

#[test]
fn the_global_schedule_converges_to_the_per_point_image() {
    let mut global = sheet(48, true);
    global.params.photons_per_pass = 40_000;
    let mut per_point = global.clone();
    per_point.params.radius_schedule = RadiusSchedule::PerPoint;
    let render = |scene: &Scene| {
        let mut ppm = Ppm::new(scene, PpmOptions::default());
        ppm.photons_per_pass = scene.params.photons_per_pass;
        for _ in 0..48 {
            ppm.run_pass(scene, &mut |_| Control::Continue);
        }
        let image = ppm.radiance();
        image.iter().map(|p| (p[0] + p[1] + p[2]) as f64).sum::<f64>() / image.len() as f64
    };
    let (g, p) = (render(&global), render(&per_point));
    assert!((g / p - 1.0).abs() < 0.01, "global {g} vs per-point {p}");
}

#[test]
fn the_command_line_shards_merges_refuses_and_renders_a_merge_again() {
    let dir = tempfile::tempdir().expect("temp dir");
    let d = |name: &str| dir.path().join(name).display().to_string();
    let render = |shard: &str, out: &str| {
        let args = [
            "render",
            "scenes/inline_patch.toml",
            "--shard",
            shard,
            "--passes",
            "5",
            "--width",
            "32",
            "--photons",
            "20000",
            "--min-photons-per-pixel",
            "0",
            "--out",
            out,
        ];
        let run = caustic(&args);
        assert!(run.status.success(), "{}", text(&run));
    };
    for k in 0..3 {
        render(&format!("{k}/3"), &d(&format!("part_{k}.exr")));
    }
    let merge = caustic(&[
        "merge",
        &d("part_0.exr"),
        &d("part_1.exr"),
        &d("part_2.exr"),
        "--out",
        &d("image.exr"),
    ]);
    assert!(merge.status.success(), "{}", text(&merge));
    assert!(text(&merge).contains("5 of 5 passes"), "{}", text(&merge));
    // Missing a part: refused unless --partial.
    let partial = caustic(&["merge", &d("part_0.exr"), &d("part_2.exr"), "--out", &d("p.exr")]);
    assert!(!partial.status.success());
    assert!(
        text(&partial).contains("hold 3 of the render's 5 passes (missing: 1, 4)"),
        "{}",
        text(&partial)
    );
    // Overlapping parts: refused, naming both files.
    let twice = caustic(&["merge", &d("image.exr"), &d("part_1.exr"), "--out", &d("t.exr")]);
    assert!(!twice.status.success());
    assert!(
        text(&twice).contains("part_1.exr: the pass lists overlap: both hold pass 1"),
        "{}",
        text(&twice)
    );
    // A missing part, and flags that report on a whole render, are refused.
    let missing = caustic(&["merge", &d("part_0.exr"), &d("nope.exr"), "--out", &d("m.exr")]);
    assert!(
        text(&missing).contains("nope.exr: the file does not exist"),
        "{}",
        text(&missing)
    );
    let json = caustic(&[
        "render",
        "scenes/inline_patch.toml",
        "--shard",
        "0/2",
        "--json",
        "--out",
        &d("j.exr"),
    ]);
    assert!(
        !json.status.success() && text(&json).contains("merge the parts"),
        "{}",
        text(&json)
    );
    // The merge rendered again from what it records: the same pixels.
    let again = caustic(&["render", "--from", &d("image.exr"), "--out", &d("again.exr")]);
    assert!(again.status.success(), "{}", text(&again));
    let pixels = |p: &str| image::open(p).expect("EXR opens").to_rgb32f().into_raw();
    assert_eq!(pixels(&d("again.exr")), pixels(&d("image.exr")));
    // And the one-process shard 0/1 has the same sums.
    render("0/1", &d("one.exr"));
    let one = Part::read(Path::new(&d("one.exr"))).expect("reads");
    let merged = Part::read(Path::new(&d("image.exr"))).expect("reads");
    assert_eq!(one.sums, merged.sums);
}

#[test]
fn a_watched_folder_merges_new_parts_ignores_hidden_and_redundant_ones_and_rebuilds_after_a_rewrite() {
    use caustic::render::shard::FolderMerge;
    let dir = tempfile::tempdir().expect("temp dir");
    let scene = sheet(24, true);
    let total = 6;
    let write = |k: u32, name: &str| {
        let sums = shard_sums(&scene, Shard { index: k, count: 3 }, total);
        part(&scene, sums, total)
            .write(&dir.path().join(name), true)
            .expect("writes");
    };
    let mut folder = FolderMerge::new();
    write(0, "part_0.exr");
    // A part being written under its temporary name is not read.
    std::fs::write(dir.path().join(".part_1.exr.partial"), b"half").expect("write");
    let report = folder.scan(dir.path()).expect("scans");
    assert!(report.changed && report.skipped.is_empty(), "{report:?}");
    assert_eq!(
        folder.merged().map(|p| p.sums.passes().to_vec()),
        Some(vec![0, 3])
    );
    // Nothing new: nothing changes.
    assert!(!folder.scan(dir.path()).expect("scans").changed);
    write(1, "part_1.exr");
    write(2, "part_2.exr");
    assert!(folder.scan(dir.path()).expect("scans").changed);
    let all = folder.merged().expect("merged").clone();
    assert!(all.is_complete());
    assert_eq!(folder.rebuilds(), 0, "new parts add to the merge");
    assert_eq!(all.sums, shard_sums(&scene, Shard::default(), total));
    // The farm's own merge beside its parts adds nothing and is not an error.
    all.write(&dir.path().join("image.exr"), false).expect("writes");
    let report = folder.scan(dir.path()).expect("scans");
    assert!(!report.changed && report.skipped.is_empty(), "{report:?}");
    assert_eq!(folder.parts_merged(), 3);
    // A part rewritten in place (a shard run again): everything is merged again, same sums.
    std::thread::sleep(std::time::Duration::from_millis(20));
    write(1, "part_1.exr");
    let generation = folder.generation();
    assert!(folder.scan(dir.path()).expect("scans").changed);
    assert!(folder.generation() > generation);
    assert_eq!(folder.rebuilds(), 1, "a rewritten part starts the merge again");
    assert_eq!(folder.merged().map(|p| &p.sums), Some(&all.sums));
}

/// Renders `scenes/inline_patch.toml` at 32 pixels with `flags` into `out` (asserting success).
fn render_part(flags: &[&str], out: &str) {
    let mut args = vec![
        "render",
        "--width",
        "32",
        "--photons",
        "20000",
        "--min-photons-per-pixel",
        "0",
        "--out",
        out,
    ];
    args.extend(flags);
    let run = caustic(&args);
    assert!(run.status.success(), "{flags:?}: {}", text(&run));
}

#[test]
fn render_from_a_part_renders_exactly_its_passes() {
    let dir = tempfile::tempdir().expect("temp dir");
    let d = |name: &str| dir.path().join(name).display().to_string();
    // Shard 0 of 2 of a 4-pass render: passes 0 and 2.
    render_part(
        &["scenes/inline_patch.toml", "--shard", "0/2", "--passes", "4"],
        &d("p02.exr"),
    );
    let original = Part::read(Path::new(&d("p02.exr"))).expect("reads");
    assert_eq!(original.sums.passes(), [0, 2]);
    // Rendered again: the same passes, the same sums.
    let run = caustic(&["render", "--from", &d("p02.exr"), "--out", &d("again.exr")]);
    assert!(run.status.success(), "{}", text(&run));
    let again = Part::read(Path::new(&d("again.exr"))).expect("reads");
    assert_eq!(again.sums, original.sums);
    assert_eq!(again.total_passes, 4);
    // A shard of the part's render takes the part's total, so it merges with its sibling.
    let run = caustic(&[
        "render",
        "--from",
        &d("p02.exr"),
        "--shard",
        "1/2",
        "--out",
        &d("p13.exr"),
    ]);
    assert!(run.status.success(), "{}", text(&run));
    let merge = caustic(&["merge", &d("p02.exr"), &d("p13.exr"), "--out", &d("all.exr")]);
    assert!(merge.status.success(), "{}", text(&merge));
    assert!(text(&merge).contains("4 of 4 passes"), "{}", text(&merge));
    // Other passes than the part's are refused, saying why.
    let run = caustic(&[
        "render",
        "--from",
        &d("p02.exr"),
        "--passes",
        "3",
        "--out",
        &d("x.exr"),
    ]);
    assert!(!run.status.success());
    assert!(
        text(&run).contains("the part's own passes (0,2 of 4)"),
        "{}",
        text(&run)
    );
    let run = caustic(&["render", "--from", &d("p02.exr"), "--out", &d("x.png")]);
    assert!(
        !run.status.success() && text(&run).contains("use .exr"),
        "{}",
        text(&run)
    );
    assert!(!Path::new(&d("x.exr")).exists() && !Path::new(&d("x.png")).exists());
}

#[test]
fn merge_names_what_each_bad_path_is() {
    let dir = tempfile::tempdir().expect("temp dir");
    let d = |name: &str| dir.path().join(name);
    let scene = sheet(16, true);
    let good = part(&scene, shard_sums(&scene, Shard { index: 0, count: 2 }, 2), 2);
    good.write(&d("good.exr"), false).expect("writes");
    std::fs::create_dir(d("folder.exr")).expect("folder");
    let fifo = std::process::Command::new("mkfifo").arg(d("fifo.exr")).status();
    assert!(fifo.is_ok_and(|s| s.success()), "mkfifo");
    std::os::unix::fs::symlink(d("loop_b.exr"), d("loop_a.exr")).expect("link");
    std::os::unix::fs::symlink(d("loop_a.exr"), d("loop_b.exr")).expect("link");
    // A part of a later format, and a pass list that claims 3·10⁸ passes of a 2-pass render.
    let with = |key: &str, value: &str, name: &str| {
        let mut p = good.clone();
        for (k, v) in p.metadata.iter_mut() {
            if k == key {
                *v = value.to_owned();
            }
        }
        p.write(&d(name), false).expect("writes");
    };
    with("caustic:part", "2", "v2.exr");
    with(
        "caustic:pass_list",
        "0-99999999,100000000-199999999,200000000-299999999",
        "bomb.exr",
    );
    with("caustic:total_passes", "4000000000", "long.exr");
    for (name, message) in [
        ("missing.exr", "missing.exr: the file does not exist"),
        ("folder.exr", "folder.exr: the file is a folder, not a file"),
        (
            "fifo.exr",
            "fifo.exr: the file is not a regular file (a device, FIFO or socket)",
        ),
        (
            "loop_a.exr",
            "loop_a.exr: the file is a symbolic link that cannot be followed",
        ),
        (
            "v2.exr",
            "its caustic:part is \"2\": a part file of another format",
        ),
        (
            "bomb.exr",
            "its caustic:pass_list is damaged: it holds pass 99999999 of a render of 2 passes",
        ),
        (
            "long.exr",
            "its caustic:total_passes must be between 1 and 10000000",
        ),
    ] {
        let start = std::time::Instant::now();
        let out = d("out.exr").display().to_string();
        let run = caustic(&[
            "merge",
            &d("good.exr").display().to_string(),
            &d(name).display().to_string(),
            "--out",
            &out,
        ]);
        assert!(!run.status.success(), "{name}");
        assert!(text(&run).contains(message), "{name}: {}", text(&run));
        assert!(
            start.elapsed().as_secs() < 10,
            "{name} took {:?}",
            start.elapsed()
        );
        assert!(!d("out.exr").exists());
    }
}

#[test]
fn a_watched_folder_follows_the_render_most_parts_belong_to_or_the_one_chosen() {
    use caustic::render::shard::FolderMerge;
    let dir = tempfile::tempdir().expect("temp dir");
    let scene = sheet(24, true);
    let mut other = sheet(24, true);
    other.params.seed = 99;
    let total = 4;
    let write = |scene: &Scene, k: u32, name: &str| {
        let sums = shard_sums(scene, Shard { index: k, count: 2 }, total);
        part(scene, sums, total)
            .write(&dir.path().join(name), true)
            .expect("writes");
    };
    // A part of another render sorts before the real parts, and holds passes they hold.
    write(&other, 0, "a_other_scene.exr");
    write(&scene, 0, "p0.exr");
    write(&scene, 1, "p1.exr");
    let mut folder = FolderMerge::new();
    let report = folder.scan(dir.path()).expect("scans");
    assert!(report.changed);
    let merged = folder.merged().expect("merged");
    assert!(merged.is_complete(), "the two real parts are merged");
    assert_eq!(merged.sums, shard_sums(&scene, Shard::default(), total));
    assert_eq!(folder.first_part(), Some(dir.path().join("p0.exr").as_path()));
    assert_eq!(report.skipped.len(), 1, "{report:?}");
    assert!(
        report.skipped[0].starts_with("a_other_scene.exr: not merged: a part of another render")
            && report.skipped[0].contains("seed 1 and 99"),
        "{report:?}"
    );
    // Told once.
    assert_eq!(folder.scan(dir.path()).expect("scans"), Default::default());
    // A part that arrives after the render is complete adds nothing, and says so, once.
    std::fs::copy(dir.path().join("p0.exr"), dir.path().join("p9_late.exr")).expect("copy");
    let report = folder.scan(dir.path()).expect("scans");
    assert!(!report.changed, "{report:?}");
    assert_eq!(
        report.skipped,
        ["p9_late.exr: adds nothing: its passes are merged already (the render is complete)"]
    );
    assert_eq!(folder.scan(dir.path()).expect("scans"), Default::default());
    std::fs::remove_file(dir.path().join("p9_late.exr")).expect("remove");
    folder.scan(dir.path()).expect("scans");
    // The renders in the folder, most parts first; choosing the other shows it.
    let renders = folder.renders();
    assert_eq!(
        renders.iter().map(|r| (r.parts, r.passes)).collect::<Vec<_>>(),
        [(2, 4), (1, 2)]
    );
    folder.choose(Some(renders[1].key.clone()));
    let report = folder.scan(dir.path()).expect("scans");
    assert!(report.changed && report.skipped.len() == 2, "{report:?}");
    assert_eq!(
        folder.merged().map(|p| p.sums.passes().to_vec()),
        Some(vec![0, 2])
    );
    folder.choose(None);
    assert!(folder.scan(dir.path()).expect("scans").changed);
    assert!(folder.merged().is_some_and(Part::is_complete));
    // A later part of the other render that overtakes: the folder follows the majority.
    write(&other, 1, "b_other.exr");
    std::fs::copy(
        dir.path().join("b_other.exr"),
        dir.path().join("c_other_copy.exr"),
    )
    .expect("copy");
    let report = folder.scan(dir.path()).expect("scans");
    assert!(report.changed, "{report:?}");
    assert_eq!(folder.renders()[0].parts, 3);
    assert!(folder.merged().is_some_and(Part::is_complete));
    assert_eq!(
        folder.merged().map(|p| p.sums.clone()),
        Some(shard_sums(&other, Shard::default(), total))
    );
}
