//! The `caustic` binary as a user runs it: render to PNG/EXR with metadata, never overwrite
//! silently, export patches as OBJ, and clear errors for bad input.

use std::path::Path;
use std::process::Command;

mod common;

use common::{caustic, text};

#[test]
fn render_writes_png_and_exr_with_metadata_and_refuses_to_overwrite() {
    let dir = tempfile::tempdir().expect("temp dir");
    let png = dir.path().join("leaf.png");
    let png_s = png.to_str().expect("utf-8 path");
    let out = caustic(&[
        "render",
        "scenes/leaf.toml",
        "--out",
        png_s,
        "--width",
        "40",
        "--height",
        "30",
    ]);
    assert!(out.status.success(), "{}", text(&out));
    let img = image::open(&png).expect("readable PNG").to_rgb8();
    assert_eq!((img.width(), img.height()), (40, 30));
    let decoder = png::Decoder::new(std::io::BufReader::new(std::fs::File::open(&png).expect("open")));
    let reader = decoder.read_info().expect("png info");
    let keys: Vec<&str> = reader
        .info()
        .utf8_text
        .iter()
        .map(|t| t.keyword.as_str())
        .collect();
    assert!(
        keys.contains(&"caustic:scene") && keys.contains(&"caustic:seed"),
        "{keys:?}"
    );

    // A second render to the same name is refused and leaves the file alone.
    let before = std::fs::read(&png).expect("read");
    let again = caustic(&[
        "render",
        "scenes/leaf.toml",
        "--out",
        png_s,
        "--width",
        "8",
        "--height",
        "6",
    ]);
    assert!(!again.status.success());
    assert!(
        text(&again).contains("the file exists; choose another name or pass --force"),
        "{}",
        text(&again)
    );
    assert_eq!(std::fs::read(&png).expect("read"), before);
    let forced = caustic(&[
        "render",
        "scenes/leaf.toml",
        "--out",
        png_s,
        "--width",
        "8",
        "--height",
        "6",
        "--force",
    ]);
    assert!(forced.status.success(), "{}", text(&forced));
    assert_eq!(image::open(&png).expect("PNG").width(), 8);
    // One side given: the other follows the scene's aspect (640×480).
    for (flag, side, expected) in [("--width", "32", (32, 24)), ("--height", "15", (20, 15))] {
        let one_side = caustic(&[
            "render",
            "scenes/leaf.toml",
            "--out",
            png_s,
            flag,
            side,
            "--force",
        ]);
        assert!(one_side.status.success(), "{}", text(&one_side));
        let img = image::open(&png).expect("PNG");
        assert_eq!((img.width(), img.height()), expected, "{flag} {side}");
    }

    let exr = dir.path().join("leaf.exr");
    let out = caustic(&[
        "render",
        "scenes/leaf.toml",
        "--out",
        exr.to_str().expect("utf-8"),
        "--width",
        "20",
        "--height",
        "15",
    ]);
    assert!(out.status.success(), "{}", text(&out));
    let linear = image::open(&exr).expect("readable EXR").to_rgb32f();
    assert_eq!((linear.width(), linear.height()), (20, 15));
    assert!(linear.pixels().any(|p| p[1] > 0.0));
    let meta = exr::meta::MetaData::read_from_file(&exr, false).expect("EXR header");
    let attrs = &meta.headers[0].own_attributes.other;
    assert!(attrs.keys().any(|k| k == "caustic:scene"), "{attrs:?}");
    assert!(std::fs::read_dir(dir.path()).expect("dir").all(|e| !e
        .expect("entry")
        .file_name()
        .to_string_lossy()
        .contains("partial")));
}

#[test]
fn render_with_photon_mapping_reports_its_statistics() {
    let dir = tempfile::tempdir().expect("temp dir");
    let exr = dir.path().join("smallppm.exr");
    let out = caustic(&[
        "render",
        "scenes/smallppm.toml",
        "--out",
        exr.to_str().expect("utf-8"),
        "--width",
        "64",
        "--height",
        "48",
        "--passes",
        "3",
        "--photons",
        "20000",
    ]);
    let t = text(&out);
    assert!(out.status.success(), "{t}");
    assert!(t.contains("3 passes, 60000 photons"), "{t}");
    assert!(t.contains("skipped: eye pass traced once and reused"), "{t}");
    assert!(t.contains("skipped: no Bézier patches"), "{t}");
    let linear = image::open(&exr).expect("readable EXR").to_rgb32f();
    assert!(linear.pixels().all(|p| p.0.iter().all(|c| c.is_finite())));
    assert!(linear.pixels().filter(|p| p[0] > 0.0).count() > 64 * 48 / 2);
    let meta = exr::meta::MetaData::read_from_file(&exr, false).expect("EXR header");
    let attrs = &meta.headers[0].own_attributes.other;
    assert!(attrs.keys().any(|k| k == "caustic:photons"), "{attrs:?}");
}

#[test]
fn export_obj_writes_the_tessellated_patches() {
    let dir = tempfile::tempdir().expect("temp dir");
    let obj = dir.path().join("teapot.obj");
    let out = caustic(&[
        "export-obj",
        "scenes/teapot.toml",
        "--out",
        obj.to_str().expect("utf-8"),
        "--resolution",
        "8",
    ]);
    assert!(out.status.success(), "{}", text(&out));
    let mesh = caustic::geometry::TriangleMesh::load_obj(&obj).expect("tobj reads our OBJ");
    assert_eq!(mesh.indices.len(), 32 * 8 * 8 * 2);
    assert_eq!(mesh.texcoords.len(), mesh.positions.len());
    let again = caustic(&["export-obj", "--out", obj.to_str().expect("utf-8")]);
    assert!(!again.status.success() && text(&again).contains("--force"));
}

#[test]
fn bad_input_gives_clear_errors() {
    let dir = tempfile::tempdir().expect("temp dir");
    let out_png = dir.path().join("x.png");
    let out_s = out_png.to_str().expect("utf-8");
    let cases: Vec<(Vec<&str>, &str)> = vec![
        (
            vec!["render", "scenes/nope.toml", "--out", out_s],
            "scenes/nope.toml:0: the scene file does not exist",
        ),
        (
            vec!["render", "scenes/leaf.toml", "--out", "x.bmp"],
            "x.bmp: unknown image format (use .png or .exr)",
        ),
        (
            vec!["render", "scenes/leaf.toml", "--out", out_s, "--width", "0"],
            "--width must be between 1 and 16384",
        ),
        (
            vec!["render", "scenes/leaf.toml", "--out", out_s, "--exposure", "NaN"],
            "--exposure must be a finite number",
        ),
        (
            vec!["render", "scenes/leaf.toml", "--out", out_s, "--width", "many"],
            "invalid value 'many' for '--width",
        ),
        (
            vec!["render", "scenes/smallppm.toml", "--out", out_s, "--alpha", "1.5"],
            "--alpha must be in (0, 1]",
        ),
        (
            vec!["render", "scenes/smallppm.toml", "--out", out_s, "--radius", "-1"],
            "--radius must be a positive number",
        ),
        (
            vec!["render", "scenes/smallppm.toml", "--out", out_s, "--passes", "0"],
            "--passes must be between 1 and 10000000, got 0",
        ),
        (
            vec![
                "render",
                "scenes/smallppm.toml",
                "--out",
                out_s,
                "--time-limit",
                "-3",
            ],
            "--time-limit must be a positive number of seconds",
        ),
        (
            vec!["export-obj", "scenes/smallppm.toml", "--out", out_s],
            "has no Bézier patches to export",
        ),
        // A seed past TOML's integers could not be recorded in the image's scene (this
        // panicked while writing it).
        (
            vec![
                "render",
                "scenes/leaf.toml",
                "--out",
                out_s,
                "--seed",
                "18446744073709551615",
            ],
            "--seed must be between 0 and 9223372036854775807",
        ),
        // Depth 12 asked for 4^12 leaves a patch (hundreds of GB) and never came back.
        (
            vec!["bench", "intersect", "--size", "4", "--max-depth", "9"],
            "--max-depth must be at most 8",
        ),
    ];
    for (args, expected) in cases {
        let out = caustic(&args);
        assert!(!out.status.success(), "{args:?} succeeded");
        let t = text(&out);
        assert!(t.contains(expected), "{args:?}: expected '{expected}' in:\n{t}");
        assert!(!t.contains("panicked"), "{args:?} panicked:\n{t}");
    }
    assert!(!Path::new(out_s).exists(), "a failed render left a file");
}

#[test]
fn view_flags_are_checked_before_a_window_opens() {
    let out = caustic(&["view", "--screenshot", "shot.jpg"]);
    assert!(!out.status.success());
    let msg = text(&out);
    assert!(msg.contains("shot.jpg") && msg.contains(".png"), "{msg}");
    let help = text(&caustic(&["view", "--help"]));
    for flag in ["--screenshot", "--after-passes", "--bench", "--force"] {
        assert!(help.contains(flag), "view --help lacks {flag}: {help}");
    }
}

#[test]
fn photon_benches_run_from_any_directory_on_the_built_in_scene() {
    let dir = tempfile::tempdir().expect("temp dir");
    let out = Command::new(env!("CARGO_BIN_EXE_caustic"))
        .args([
            "bench",
            "ppm",
            "--photons",
            "2000",
            "--passes",
            "1",
            "--threads",
            "1",
        ])
        .current_dir(dir.path())
        .output()
        .expect("run caustic");
    let t = text(&out);
    assert!(out.status.success(), "{t}");
    assert!(t.contains("<built-in smallppm>, 1024x768"), "{t}");
}

/// `bench edit` without a scene measures its built-in one, from any directory (it read
/// `scenes/inline_patch.toml` relative to the working folder, so only ran in the repository).
#[test]
fn edit_bench_runs_from_any_directory_on_its_built_in_scene() {
    let dir = tempfile::tempdir().expect("temp dir");
    let refs = dir.path().join("references");
    let out = Command::new(env!("CARGO_BIN_EXE_caustic"))
        .args([
            "bench",
            "edit",
            "--runs",
            "1",
            "--before-passes",
            "1",
            "--reference-passes",
            "2",
            "--target",
            "0.5",
            "--limit",
            "20",
            "--threads",
            "2",
            "--reference-dir",
            refs.to_str().expect("utf-8"),
        ])
        .current_dir(dir.path())
        .output()
        .expect("run caustic");
    let t = text(&out);
    assert!(out.status.success(), "{t}");
    assert!(t.contains("Edit of <built-in inline_patch>"), "{t}");
    assert!(t.contains("edit to relative MSE 5e-1: warm"), "{t}");
}

/// `bench convergence` on a tiny configuration: a table, a CSV with the expected columns, a
/// readable PNG plot, and a cached reference reused on the second run.
#[test]
fn convergence_bench_writes_its_csv_and_plot_and_reuses_the_reference() {
    let dir = tempfile::tempdir().expect("temp dir");
    let csv = dir.path().join("curves.csv");
    let plot = dir.path().join("curves.png");
    let refs = dir.path().join("references");
    let run = |extra: &[&str]| {
        let mut args = vec![
            "bench",
            "convergence",
            "scenes/cornell.toml",
            "--width",
            "16",
            "--photons",
            "2000",
            "--seconds",
            "0.3",
            "--reference-passes",
            "4",
            "--configs",
            "photons-only,default",
            "--reference-dir",
            refs.to_str().expect("utf-8"),
        ];
        args.extend_from_slice(extra);
        caustic(&args)
    };
    let out = run(&[
        "--csv",
        csv.to_str().expect("utf-8"),
        "--plot",
        plot.to_str().expect("utf-8"),
    ]);
    assert!(out.status.success(), "{}", text(&out));
    assert!(text(&out).contains("speed-up"), "{}", text(&out));
    let rows = std::fs::read_to_string(&csv).expect("CSV");
    let mut lines = rows.lines();
    assert_eq!(lines.next(), Some("configuration,pass,seconds,rmse,rel_mse"));
    let body: Vec<&str> = lines.collect();
    assert!(body.iter().all(|l| l.split(',').count() == 5), "{rows}");
    for name in ["photons-only,", "default,"] {
        assert!(
            body.iter().any(|l| l.starts_with(name)),
            "no rows of {name}: {rows}"
        );
    }
    let png = image::open(&plot).expect("readable PNG");
    assert_eq!((png.width(), png.height()), caustic::bench::plot::SIZE);
    // The second run finds the reference it cached; existing outputs are not replaced.
    let again = run(&["--csv", csv.to_str().expect("utf-8")]);
    assert!(!again.status.success(), "overwrote the CSV");
    let again = run(&[]);
    assert!(again.status.success(), "{}", text(&again));
    assert!(text(&again).contains("(cached)"), "{}", text(&again));
}

/// `--threads N` sizes the render's pool; the image does not depend on it.
#[test]
fn render_threads_flag_gives_the_same_image() {
    let dir = tempfile::tempdir().expect("temp dir");
    let render = |threads: &str| {
        let out = dir.path().join(format!("t{threads}.exr"));
        let o = caustic(&[
            "render",
            "scenes/cornell.toml",
            "--renderer",
            "ppm",
            "--passes",
            "2",
            "--photons",
            "5000",
            "--width",
            "48",
            "--height",
            "36",
            "--threads",
            threads,
            "--out",
            out.to_str().expect("utf-8"),
        ]);
        assert!(o.status.success(), "{}", text(&o));
        image::open(&out).expect("EXR").to_rgb32f().into_raw()
    };
    assert_eq!(render("1"), render("2"));
    let bad = caustic(&["render", "--threads", "0", "--out", "x.png"]);
    assert!(!bad.status.success());
    assert!(
        text(&bad).contains("--threads must be between 1 and 4096"),
        "{}",
        text(&bad)
    );
}

/// `bench memory` samples resident memory while a stochastic render runs.
#[test]
fn memory_bench_prints_its_samples() {
    let out = caustic(&[
        "bench",
        "memory",
        "--width",
        "32",
        "--height",
        "24",
        "--passes",
        "4",
        "--every",
        "2",
        "--photons",
        "1000",
    ]);
    let t = text(&out);
    assert!(out.status.success(), "{t}");
    assert!(t.contains("peak MiB"), "{t}");
    let rows = t
        .lines()
        .filter(|l| l.split_whitespace().count() == 4 && l.trim_start().starts_with(char::is_numeric))
        .count();
    assert_eq!(rows, 3, "passes 1, 2 and 4 sampled: {t}");
}

/// `bench ppm|whitted --repeat N`: every thread count is run N times, interleaved; each
/// reports its runs, its best (the least) and median seconds, and speed-ups from both.
#[test]
fn scaling_benches_repeat_each_thread_count_and_report_best_and_median() {
    let cases: [(&str, Vec<&str>); 2] = [
        ("ppm", vec!["--photons", "2000", "--passes", "1"]),
        ("whitted", vec!["scenes/leaf.toml", "--width", "16"]),
    ];
    for (bench, args) in cases {
        let mut all = vec!["bench", bench, "--json", "--threads", "1,2", "--repeat", "3"];
        all.extend(&args);
        let out = caustic(&all);
        assert!(out.status.success(), "{bench}: {}", text(&out));
        let doc: serde_json::Value =
            serde_json::from_slice(&out.stdout).unwrap_or_else(|e| panic!("{bench}: {e}: {}", text(&out)));
        assert_eq!(doc["repeat"], 3, "{doc}");
        let runs = doc["runs"].as_array().expect("runs");
        assert_eq!(runs.len(), 2, "{doc}");
        for (run, threads) in runs.iter().zip([1, 2]) {
            assert_eq!(run["threads"], threads, "{doc}");
            let all: Vec<f64> = run["all_seconds"]
                .as_array()
                .expect("all_seconds")
                .iter()
                .map(|s| s.as_f64().expect("seconds"))
                .collect();
            assert_eq!(all.len(), 3, "{doc}");
            let mut sorted = all.clone();
            sorted.sort_by(f64::total_cmp);
            assert_eq!(run["seconds"].as_f64(), Some(sorted[0]), "{doc}");
            assert_eq!(run["median_seconds"].as_f64(), Some(sorted[1]), "{doc}");
        }
        let first = &runs[0];
        assert_eq!(first["speedup"].as_f64(), Some(1.0), "{doc}");
        let best = |r: &serde_json::Value| r["seconds"].as_f64().expect("seconds");
        let speedup = runs[1]["speedup"].as_f64().expect("speedup");
        assert!((speedup - best(first) / best(&runs[1])).abs() < 1e-9, "{doc}");
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(stderr.contains("3 interleaved runs per thread count"), "{stderr}");
        assert!(stderr.contains("median s"), "{stderr}");

        let mut zero = vec!["bench", bench, "--repeat", "0"];
        zero.extend(&args);
        let out = caustic(&zero);
        assert!(!out.status.success(), "{bench} --repeat 0 succeeded");
        assert!(
            text(&out).contains("--repeat must be at least 1"),
            "{}",
            text(&out)
        );
    }
}

/// Every bench prints one JSON document on stdout with `--json` (its text goes to stderr).
#[test]
fn every_bench_has_a_json_summary() {
    let dir = tempfile::tempdir().expect("temp dir");
    let refs = dir.path().join("references");
    let cases: [(&str, Vec<&str>, &str); 6] = [
        (
            "tessellation",
            vec!["--width", "24", "--segments", "2,4", "--per-ray-depth", "3"],
            "renders",
        ),
        ("intersect", vec!["--size", "16", "--repeat", "1"], "intersectors"),
        (
            "ppm",
            vec!["--photons", "2000", "--passes", "1", "--threads", "1"],
            "runs",
        ),
        (
            "whitted",
            vec!["scenes/leaf.toml", "--width", "16", "--threads", "1"],
            "runs",
        ),
        (
            "memory",
            vec![
                "--width",
                "16",
                "--height",
                "12",
                "--passes",
                "2",
                "--every",
                "1",
                "--photons",
                "500",
            ],
            "samples",
        ),
        (
            "convergence",
            vec![
                "scenes/cornell.toml",
                "--width",
                "12",
                "--photons",
                "1000",
                "--seconds",
                "0.2",
                "--reference-passes",
                "2",
                "--configs",
                "photons-only,default",
                "--reference-dir",
                refs.to_str().expect("utf-8"),
            ],
            "configurations",
        ),
    ];
    for (bench, args, list) in cases {
        let mut all = vec!["bench", bench, "--json"];
        all.extend(args);
        let out = caustic(&all);
        assert!(out.status.success(), "{bench}: {}", text(&out));
        let doc: serde_json::Value =
            serde_json::from_slice(&out.stdout).unwrap_or_else(|e| panic!("{bench}: {e}: {}", text(&out)));
        assert_eq!(doc["bench"], bench);
        let entries = doc[list]
            .as_array()
            .unwrap_or_else(|| panic!("{bench}: no {list}: {doc}"));
        assert!(!entries.is_empty(), "{bench}: {doc}");
    }
}

/// `bench intersect --order shuffled` traces the same rays as the image order, only in
/// another order: the same rays hit and miss, and the report says which order it used.
#[test]
fn intersect_bench_shuffles_the_same_rays() {
    let run = |order: &str| -> serde_json::Value {
        let out = caustic(&[
            "bench",
            "intersect",
            "--json",
            "--size",
            "24",
            "--repeat",
            "1",
            "--method",
            "prepared",
            "--order",
            order,
        ]);
        assert!(out.status.success(), "{order}: {}", text(&out));
        serde_json::from_slice(&out.stdout).unwrap_or_else(|e| panic!("{order}: {e}: {}", text(&out)))
    };
    let (image, shuffled) = (run("image"), run("shuffled"));
    assert_eq!(image["order"], "image");
    assert_eq!(shuffled["order"], "shuffled");
    let counts = |doc: &serde_json::Value| {
        let t = &doc["intersectors"][0];
        (
            t["hit_rays"].as_u64().expect("hits"),
            t["miss_rays"].as_u64().expect("misses"),
        )
    };
    let (hits, misses) = counts(&image);
    assert!(hits > 0 && misses > 0 && hits + misses == 24 * 24, "{image}");
    assert_eq!(counts(&shuffled), (hits, misses));
}

/// `bench tessellation`: the exact render, the per-ray one (same picture) and tessellations
/// whose error falls as they get finer, as a CSV and a readable plot.
#[test]
fn tessellation_bench_compares_exact_and_tessellated_renders() {
    let dir = tempfile::tempdir().expect("temp dir");
    let csv = dir.path().join("tess.csv");
    let plot = dir.path().join("tess.png");
    let out = caustic(&[
        "bench",
        "tessellation",
        "scenes/teapot.toml",
        "--width",
        "64",
        "--segments",
        "2,8",
        "--csv",
        csv.to_str().expect("utf-8"),
        "--plot",
        plot.to_str().expect("utf-8"),
    ]);
    assert!(out.status.success(), "{}", text(&out));
    let rows = std::fs::read_to_string(&csv).expect("CSV");
    let lines: Vec<&str> = rows.lines().collect();
    assert_eq!(
        lines[0],
        "geometry,segments,triangles,prepare_seconds,render_seconds,rmse"
    );
    assert_eq!(lines.len(), 5, "{rows}");
    let rmse = |line: &str| -> f64 { line.rsplit(',').next().expect("rmse").parse().expect("number") };
    assert_eq!(rmse(lines[1]), 0.0, "the exact render is the reference");
    assert!(rmse(lines[2]) < 1e-3, "per-ray and prepared agree: {rows}");
    // A name with a comma is quoted: every row has six fields.
    assert!(lines[2].starts_with("\"exact (per-ray, depth 5)\",,0,"), "{rows}");
    assert!(
        rmse(lines[3]) > rmse(lines[4]),
        "finer tessellation, less error: {rows}"
    );
    assert!(lines[4].contains(",8,") && lines[4].contains(&(2 * 8 * 8 * 32).to_string()));
    let png = image::open(&plot).expect("readable PNG");
    assert_eq!((png.width(), png.height()), caustic::bench::plot::SIZE);
    let flat = caustic(&["bench", "tessellation", "scenes/smallppm.toml", "--width", "8"]);
    assert!(
        !flat.status.success() && text(&flat).contains("no Bézier patches"),
        "{}",
        text(&flat)
    );
}

#[test]
fn errors_carry_no_backtrace_even_with_rust_backtrace_set() {
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_caustic"))
        .args([
            "render",
            "scenes/nope.toml",
            "--out",
            "/tmp/caustic-never-written.png",
        ])
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .env("RUST_BACKTRACE", "1")
        .env("RUST_LIB_BACKTRACE", "1")
        .output()
        .expect("run caustic");
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.starts_with("Error: scenes/nope.toml:0: the scene file does not exist"),
        "{err}"
    );
    assert!(!err.to_lowercase().contains("backtrace"), "{err}");
    assert!(err.lines().count() <= 4, "{err}");
}
