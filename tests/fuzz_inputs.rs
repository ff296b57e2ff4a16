//! Replays every input kept beside the fuzz targets — the seed corpora
//! (`tests/fuzz/corpus/<target>/`) and the inputs that once crashed or hung a reader
//! (`tests/fuzz/regressions/<target>/`) — through the same checks the fuzzer runs
//! (`tests/fuzz/inputs.rs`). CI runs these; fuzzing itself needs nightly and time.

#[path = "fuzz/inputs.rs"]
mod inputs;

use std::path::Path;

/// Runs `check` on every file of the target's corpus and regression folders; returns how many.
fn replay(target: &str, check: fn(&[u8])) -> usize {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fuzz");
    let mut count = 0;
    for kind in ["corpus", "regressions"] {
        let dir = root.join(kind).join(target);
        let Ok(entries) = std::fs::read_dir(&dir) else {
            continue;
        };
        let mut files: Vec<_> = entries.flatten().map(|e| e.path()).collect();
        files.sort();
        for file in files.iter().filter(|f| f.is_file()) {
            let data = std::fs::read(file).expect("readable input");
            let outcome = std::panic::catch_unwind(|| check(&data));
            assert!(outcome.is_ok(), "{} fails its check", file.display());
            count += 1;
        }
    }
    count
}

#[test]
fn kept_scene_inputs_load_or_fail_cleanly() {
    assert!(replay("scene", inputs::scene) >= 8);
}

#[test]
fn kept_bpt_inputs_load_or_fail_cleanly() {
    assert!(replay("bpt", inputs::bpt) >= 3);
}

#[test]
fn kept_obj_inputs_load_or_fail_cleanly() {
    assert!(replay("obj", inputs::obj) >= 2);
}

#[test]
fn kept_freeform_inputs_load_or_fail_cleanly() {
    assert!(replay("freeform", inputs::freeform) >= 4);
}

#[test]
fn kept_texture_inputs_decode_or_fail_cleanly() {
    assert!(replay("texture", inputs::texture) >= 3);
}

#[test]
fn kept_part_header_inputs_read_or_fail_cleanly() {
    assert!(replay("part_header", inputs::part_header) >= 2);
}

#[test]
fn kept_pass_list_inputs_parse_or_fail_cleanly() {
    assert!(replay("pass_list", inputs::pass_list) >= 3);
}

#[test]
fn kept_farm_names_quote_and_stay_values() {
    assert!(replay("farm_quote", inputs::farm_quote) >= 5);
}

#[test]
fn kept_usd_inputs_load_or_fail_cleanly() {
    assert!(replay("usd", inputs::usd) >= 4);
}
