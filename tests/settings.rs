//! The table of render settings is the one home of each: FORMAT.md's `[render]` table is
//! written from it (set CAUSTIC_UPDATE_DOCS=1 to rewrite the file), every key a scene file can
//! hold has a flag and reads back, and every setting the viewer shows has a widget.

use caustic::settings::docs::{markdown_table, BEGIN, END};
use caustic::settings::{RenderParams, SETTINGS};

#[test]
fn formats_render_table_is_the_settings_table() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/FORMAT.md");
    let text = std::fs::read_to_string(&path).expect("FORMAT.md");
    let (before, rest) = text
        .split_once(BEGIN)
        .expect("FORMAT.md marks its [render] table");
    let (table, after) = rest.split_once(END).expect("… and its end");
    let expected = format!("\n{}", markdown_table());
    if table != expected {
        if std::env::var_os("CAUSTIC_UPDATE_DOCS").is_some() {
            std::fs::write(&path, format!("{before}{BEGIN}{expected}{END}{after}")).expect("write");
            return;
        }
        panic!(
            "scenes/FORMAT.md's [render] table differs from src/settings/params.rs; run \
             CAUSTIC_UPDATE_DOCS=1 cargo test --test settings to write it:\n{expected}"
        );
    }
}

#[test]
fn every_setting_reads_back_from_a_scene_file_by_its_key() {
    let defaults = RenderParams::default();
    for s in SETTINGS {
        let value = defaults.get(s.key).expect("every setting has a value");
        let text = toml::to_string(&defaults).expect("serializes");
        let back: RenderParams = toml::from_str(&text).expect("reads back");
        assert_eq!(back.get(s.key), Some(value), "{}", s.key);
        assert!(
            !s.help.is_empty() && !s.label.is_empty() && !s.default.is_empty(),
            "{}",
            s.key
        );
    }
    let keys: Vec<&str> = SETTINGS.iter().map(|s| s.key).collect();
    let mut sorted = keys.clone();
    sorted.sort();
    sorted.dedup();
    assert_eq!(sorted.len(), keys.len(), "a key twice");
}
