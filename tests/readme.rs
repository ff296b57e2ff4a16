//! The README tells the truth about what it lists: every folder and source file of `src/` is
//! named in its Layout, every shortcut of the viewer is in its table of keys, and it stays a
//! page a newcomer reads (at most 300 lines).

use std::path::{Path, PathBuf};

fn readme() -> String {
    std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("README.md")).expect("README.md")
}

/// The README's Layout block: each entry's path (`src/render/`) and text (its lines joined).
fn layout() -> Vec<(String, String)> {
    let text = readme();
    let block = text
        .split_once("<!-- layout:")
        .and_then(|(_, rest)| rest.split_once("```\n"))
        .and_then(|(_, rest)| rest.split_once("\n```"))
        .map(|(block, _)| block.to_owned())
        .expect("README.md has a layout block");
    let mut entries: Vec<(String, String)> = Vec::new();
    for line in block.lines() {
        if line.starts_with(' ') {
            if let Some(last) = entries.last_mut() {
                last.1.push(' ');
                last.1.push_str(line.trim());
            }
        } else if let Some((path, rest)) = line.split_once(' ') {
            entries.push((path.to_owned(), rest.trim().to_owned()));
        }
    }
    entries
}

/// Every `.rs` file under `dir`, as paths relative to the project.
fn sources(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).expect("readable folder").flatten() {
        let path = entry.path();
        if path.is_dir() {
            sources(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

/// Whether `text` holds `word` as a word (not inside a longer name).
fn names(text: &str, word: &str) -> bool {
    text.split(|c: char| !(c.is_alphanumeric() || c == '_'))
        .any(|w| w == word)
}

#[test]
fn the_layout_names_every_folder_and_file_of_src() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let entries = layout();
    let mut files = Vec::new();
    sources(&root.join("src"), &mut files);
    let mut missing = Vec::new();
    for file in &files {
        let relative = file.strip_prefix(root).expect("under the project");
        let parts: Vec<String> = relative
            .iter()
            .map(|p| p.to_string_lossy().into_owned())
            .collect();
        // The entry of its top folder: src/ for src/lib.rs, src/render/ for anything under render.
        let top = if parts.len() == 2 {
            "src/".to_owned()
        } else {
            format!("src/{}/", parts[1])
        };
        let Some((_, text)) = entries.iter().find(|(path, _)| *path == top) else {
            missing.push(format!("{top} (no entry)"));
            continue;
        };
        let stem = file.file_stem().expect("a name").to_string_lossy();
        let folders = parts.get(2..parts.len() - 1).unwrap_or(&[]);
        let named = (stem == "mod" || names(text, &stem)) && folders.iter().all(|f| names(text, f));
        if !named {
            missing.push(relative.display().to_string());
        }
    }
    assert!(
        missing.is_empty(),
        "README.md's Layout does not name: {missing:?}"
    );
}

#[test]
fn the_keys_table_is_the_viewers_table_of_commands_and_the_readme_stays_short() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("README.md");
    let text = readme();
    let (begin, end) = (
        "<!-- keys: written from src/app/commands.rs (tests/readme.rs checks it) -->",
        "<!-- end of keys -->",
    );
    let (before, rest) = text.split_once(begin).expect("README.md marks its keys table");
    let (table, after) = rest.split_once(end).expect("… and its end");
    let mut expected = String::from("\n| keys and mouse | what they do |\n|---|---|\n");
    for (keys, what) in caustic::app::commands::help_rows() {
        expected.push_str(&format!("| {} | {what} |\n", keys.replace('|', "\\|")));
    }
    if table != expected {
        if std::env::var_os("CAUSTIC_UPDATE_DOCS").is_some() {
            std::fs::write(&path, format!("{before}{begin}{expected}{end}{after}")).expect("write");
        } else {
            panic!("README.md's keys table differs from the viewer's commands; run CAUSTIC_UPDATE_DOCS=1 cargo test --test readme to write it:\n{expected}");
        }
    }
    let lines = readme().lines().count();
    assert!(
        lines <= 300,
        "README.md has {lines} lines; it is for users (at most 300)"
    );
}
