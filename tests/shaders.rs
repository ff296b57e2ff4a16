//! Every WGSL shader in `shaders/` parses and validates with naga (the compiler wgpu uses), and
//! the overlay's shader has the entry points its pipelines name.

use std::path::Path;

fn validate(path: &Path) -> naga::Module {
    let source = std::fs::read_to_string(path).expect("shader readable");
    let module = naga::front::wgsl::parse_str(&source)
        .unwrap_or_else(|e| panic!("{}: {}", path.display(), e.emit_to_string(&source)));
    naga::valid::Validator::new(
        naga::valid::ValidationFlags::all(),
        naga::valid::Capabilities::empty(),
    )
    .validate(&module)
    .unwrap_or_else(|e| panic!("{}: {e:?}", path.display()));
    module
}

#[test]
fn every_shader_validates() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("shaders");
    let mut count = 0;
    for entry in std::fs::read_dir(&dir).expect("shaders/ exists") {
        let path = entry.expect("dir entry").path();
        if path.extension().is_some_and(|e| e == "wgsl") {
            validate(&path);
            count += 1;
        }
    }
    assert!(count >= 1, "no shaders found in {}", dir.display());
}

#[test]
fn wireframe_shader_has_the_pipelines_entry_points() {
    let module = validate(&Path::new(env!("CARGO_MANIFEST_DIR")).join("shaders/wireframe.wgsl"));
    let names: Vec<&str> = module.entry_points.iter().map(|e| e.name.as_str()).collect();
    for name in ["vs_segment", "vs_marker", "fs_main"] {
        assert!(names.contains(&name), "{name} missing: {names:?}");
    }
}
