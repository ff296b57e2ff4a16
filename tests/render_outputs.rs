//! What `caustic render` gives besides the picture, as a user runs it: EXR layers, metadata
//! that `--from` renders again bit for bit, the error against a reference per pass, a JSON
//! summary, and a stream of passes to tev (checked against a local listener).

use std::net::TcpListener;
use std::path::Path;

use caustic::render::compare::write_pfm;
use caustic::render::film::exr_channel_names;
use caustic::render::Image;
use caustic::tev::{read_packets, Packet};

mod common;

use common::{caustic, text};

fn pixels(path: &Path) -> Vec<[f32; 3]> {
    let img = image::open(path).expect("readable image").to_rgb32f();
    img.pixels().map(|p| p.0).collect()
}

fn json(out: &std::process::Output) -> serde_json::Value {
    assert!(out.status.success(), "{}", text(out));
    serde_json::from_slice(&out.stdout).expect("stdout is one JSON document")
}

/// A photon-mapped render of the Cornell box to `out` with the flags `extra`.
fn cornell_render(out: &Path, extra: &[&str]) -> std::process::Output {
    let mut args = vec![
        "render",
        "scenes/cornell.toml",
        "--renderer",
        "ppm",
        "--seed",
        "5",
        "--out",
        out.to_str().expect("utf-8 path"),
    ];
    args.extend_from_slice(extra);
    caustic(&args)
}

/// A small photon-mapped render of the Cornell box with the flags `extra`.
fn small_render(out: &Path, extra: &[&str]) -> std::process::Output {
    let size = [
        "--width",
        "48",
        "--height",
        "36",
        "--passes",
        "3",
        "--photons",
        "8000",
    ];
    cornell_render(out, &[&size[..], extra].concat())
}

#[test]
fn from_renders_the_same_pixels_and_the_exr_has_its_layers() {
    let dir = tempfile::tempdir().expect("temp dir");
    let a = dir.path().join("a.exr");
    let out = small_render(&a, &["--threads", "2", "--alpha", "0.6"]);
    assert!(out.status.success(), "{}", text(&out));
    assert_eq!(
        exr_channel_names(&a).expect("channels"),
        ["B", "G", "R", "error.Y", "photons.Y", "radius.Y"]
    );
    let from = |out: &Path, extra: &[&str]| {
        let mut args = vec![
            "render",
            "--from",
            a.to_str().expect("utf-8"),
            "--out",
            out.to_str().expect("utf-8"),
        ];
        args.extend_from_slice(extra);
        caustic(&args)
    };
    let b = dir.path().join("b.exr");
    let again = from(&b, &["--threads", "1", "--json"]);
    let summary = json(&again);
    assert_eq!(summary["photon_mapping"]["passes"], 3, "{summary}");
    assert_eq!(summary["seed"], 5);
    let (pa, pb) = (pixels(&a), pixels(&b));
    assert!(pa.iter().flatten().any(|&c| c > 0.0), "the render is not black");
    assert!(
        pa.iter()
            .flatten()
            .zip(pb.iter().flatten())
            .all(|(x, y)| x.to_bits() == y.to_bits()),
        "--from must reproduce the pixels bit for bit"
    );
    // A flag given with --from overrides what the image records.
    let c = dir.path().join("c.exr");
    let other = from(&c, &["--seed", "6"]);
    assert!(other.status.success(), "{}", text(&other));
    assert_ne!(pixels(&c), pa, "another seed gives another image");
    // An image without the record says so.
    let plain = dir.path().join("plain.png");
    image::RgbImage::new(2, 2).save(&plain).expect("png");
    let refused = caustic(&[
        "render",
        "--from",
        plain.to_str().expect("utf-8"),
        "--out",
        "x.png",
    ]);
    assert!(!refused.status.success());
    assert!(text(&refused).contains("plain.png") && text(&refused).contains("caustic:scene_text"));
}

/// The largest seed a scene file can hold renders, and the image records it so that `--from`
/// reads it back (one past it is refused: `tests/cli.rs`).
#[test]
fn the_largest_seed_renders_and_is_recorded() {
    let dir = tempfile::tempdir().expect("temp dir");
    let (a, b) = (dir.path().join("a.exr"), dir.path().join("b.exr"));
    let largest = i64::MAX.to_string();
    let size = [
        "--width",
        "16",
        "--height",
        "12",
        "--passes",
        "1",
        "--photons",
        "2000",
    ];
    let out = caustic(
        &[
            &[
                "render",
                "scenes/cornell.toml",
                "--renderer",
                "ppm",
                "--seed",
                &largest,
            ][..],
            &size,
            &["--out", a.to_str().expect("utf-8 path")],
        ]
        .concat(),
    );
    assert!(out.status.success(), "{}", text(&out));
    let again = caustic(&[
        "render",
        "--from",
        a.to_str().expect("utf-8 path"),
        "--out",
        b.to_str().expect("utf-8 path"),
        "--json",
    ]);
    assert_eq!(json(&again)["seed"], i64::MAX);
    assert_eq!(
        pixels(&a),
        pixels(&b),
        "--from renders the recorded seed's pixels"
    );
}

#[test]
fn reference_errors_itself_an_offset_and_a_size_mismatch() {
    let dir = tempfile::tempdir().expect("temp dir");
    let a = dir.path().join("a.exr");
    assert!(small_render(&a, &[]).status.success());
    let a_s = a.to_str().expect("utf-8");
    let b = dir.path().join("b.exr");
    let itself = json(&small_render(&b, &["--reference", a_s, "--json"]));
    let reference = &itself["reference"];
    assert_eq!(reference["rmse"], 0.0, "{itself}");
    assert_eq!(reference["rel_mse"], 0.0);
    assert_eq!(reference["passes"].as_array().expect("passes").len(), 3);
    assert!(reference["passes"][0]["rmse"].as_f64().expect("rmse") > 0.0);

    // The same image raised by 0.25 everywhere, as a PFM: RMSE 0.25.
    let offset = Image {
        width: 48,
        height: 36,
        pixels: pixels(&a).iter().map(|p| p.map(|c| c + 0.25)).collect(),
    };
    let pfm = dir.path().join("offset.pfm");
    std::fs::write(&pfm, write_pfm(&offset)).expect("write pfm");
    let c = dir.path().join("c.exr");
    let shifted = json(&small_render(
        &c,
        &["--reference", pfm.to_str().expect("utf-8"), "--json"],
    ));
    let rmse = shifted["reference"]["rmse"].as_f64().expect("rmse");
    assert!((rmse - 0.25).abs() < 1e-5, "{rmse}");

    // Text output prints a line per pass.
    let d = dir.path().join("d.exr");
    let lines = small_render(&d, &["--reference", a_s]);
    assert!(lines.status.success(), "{}", text(&lines));
    assert_eq!(text(&lines).matches("relMSE").count(), 3, "{}", text(&lines));

    // Another size, or a file that is not an image, is a clear message before rendering.
    let e = dir.path().join("e.exr");
    let narrow = dir.path().join("narrow.pfm");
    std::fs::write(&narrow, write_pfm(&Image::new(40, 36))).expect("write pfm");
    let wrong = small_render(&e, &["--reference", narrow.to_str().expect("utf-8")]);
    assert!(!wrong.status.success());
    assert!(
        text(&wrong).contains("48x36") && text(&wrong).contains("40x36"),
        "{}",
        text(&wrong)
    );
    let junk = dir.path().join("junk.pfm");
    std::fs::write(&junk, "PF\n2 2\n").expect("write");
    let bad = small_render(&e, &["--reference", junk.to_str().expect("utf-8")]);
    assert!(
        !bad.status.success() && text(&bad).contains("junk.pfm"),
        "{}",
        text(&bad)
    );
    assert!(!e.exists(), "nothing is written after a bad reference");
}

#[test]
fn tev_receives_every_pass_and_a_refused_connection_is_a_warning() {
    let listener = TcpListener::bind("127.0.0.1:0").expect("bind");
    let address = listener.local_addr().expect("address").to_string();
    let reader = std::thread::spawn(move || read_packets(listener.accept().expect("accept").0));
    let dir = tempfile::tempdir().expect("temp dir");
    let a = dir.path().join("streamed.exr");
    let out = small_render(&a, &["--tev", &address]);
    assert!(out.status.success(), "{}", text(&out));
    let packets = reader.join().expect("listener");
    let Some(Some(Packet::Create {
        name,
        width,
        height,
        channels,
    })) = packets.first()
    else {
        panic!("first packet: {:?}", packets.first());
    };
    assert_eq!((name.as_str(), *width, *height), ("streamed.exr", 48, 36));
    assert_eq!(channels, &["R", "G", "B", "radius.Y", "photons.Y"]);
    let updates: Vec<_> = packets[1..]
        .iter()
        .map(|p| match p {
            Some(Packet::Update {
                width, height, data, ..
            }) => (*width, *height, data.len()),
            other => panic!("an update packet: {other:?}"),
        })
        .collect();
    assert_eq!(updates, vec![(48, 36, 48 * 36 * 5); 3], "one update per pass");

    // Nothing listening: a warning, and the render completes.
    let closed = TcpListener::bind("127.0.0.1:0").expect("bind");
    let address = closed.local_addr().expect("address").to_string();
    drop(closed);
    let b = dir.path().join("b.exr");
    let out = small_render(&b, &["--tev", &address, "--json"]);
    let summary = json(&out);
    assert!(b.exists());
    let warnings = summary["warnings"].as_array().expect("warnings");
    assert!(
        warnings.len() == 1 && warnings[0].as_str().expect("text").contains(&address),
        "{summary}"
    );
}

/// `--time-limit` without `--passes` renders passes until the limit, not the default 16;
/// with `--passes` as well, whichever ends first ends the render.
#[test]
fn a_time_limit_alone_renders_passes_until_it() {
    let dir = tempfile::tempdir().expect("temp dir");
    let out = dir.path().join("timed.png");
    let render = |extra: &[&str]| {
        let size = [
            "--width",
            "16",
            "--height",
            "12",
            "--photons",
            "1000",
            "--json",
            "--force",
        ];
        let doc = json(&cornell_render(&out, &[&size[..], extra].concat()));
        doc["photon_mapping"]["passes"]
            .as_u64()
            .unwrap_or_else(|| panic!("no pass count in {doc}"))
    };
    let timed = render(&["--time-limit", "2"]);
    assert!(timed > 16, "{timed} passes in 2 s of a 16x12 image");
    assert_eq!(render(&["--time-limit", "30", "--passes", "3"]), 3);
}
