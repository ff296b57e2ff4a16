//! OpenUSD input: a `patches` object's USD `file` gives its `NurbsPatch` surfaces (weights,
//! ranges, trims, transforms) and its `Mesh` and `Sphere` prims as objects with their
//! `displayColor`; packages read as their text layer does, binary layers are refused saying
//! how to convert them; what is not read is one warning; bad files are errors naming the file, the prim and the attribute; an edited USD
//! surface saves without losing the file's other prims.

use std::path::{Path, PathBuf};

use caustic::geometry::{load_freeform_obj, Ray};
use caustic::scene::Scene;
use glam::{DVec2, DVec3};

/// A scene beside `usd` (written as `name`) whose one object reads it, with `extra` lines in
/// that object's table.
fn usd_scene(dir: &Path, name: &str, usd: impl AsRef<[u8]>, extra: &str) -> PathBuf {
    std::fs::write(dir.join(name), usd).expect("writes");
    let path = dir.join("scene.toml");
    let text = format!(
        "[camera]\nposition = [0, 2, 6]\nlook_at = [0, 0, 0]\nfov = 40\nwidth = 16\nheight = 16\n\n\
         [materials.white]\ntype = \"diffuse\"\ncolor = [0.5, 0.5, 0.5]\n\n\
         [[lights]]\ntype = \"point\"\nposition = [0, 5, 0]\npower = 10\n\n\
         [[objects]]\nname = \"thing\"\ntype = \"patches\"\nfile = \"{name}\"\nmaterial = \"white\"\n{extra}"
    );
    std::fs::write(&path, text).expect("writes");
    path
}

/// A bilinear NURBS patch (order 2 × 2) over `[0,1]²` at height 0, with `more` attributes.
fn flat_patch(more: &str) -> String {
    format!(
        "#usda 1.0\n\ndef NurbsPatch \"Flat\"\n{{\n    int uVertexCount = 2\n    int vVertexCount = 2\n    \
         int uOrder = 2\n    int vOrder = 2\n    double[] uKnots = [0, 0, 1, 1]\n    double[] vKnots = [0, 0, 1, 1]\n    \
         point3f[] points = [(0, 0, 0), (1, 0, 0), (0, 0, 1), (1, 0, 1)]\n{more}}}\n"
    )
}

/// The ring of `scenes/ring_usd.toml` is the ring of `assets/ring_window.obj`: the same
/// patches (its points are `point3f`, so to float rounding), windows and weights, and a trim
/// region keeping the same points; the tile and the marble are objects with their colours.
#[test]
fn the_usd_ring_is_the_obj_ring_with_its_tile_and_marble() {
    let scene = Scene::load(Path::new("scenes/ring_usd.toml")).expect("loads");
    assert!(scene.warnings.is_empty(), "{:?}", scene.warnings);
    let obj = load_freeform_obj(Path::new("assets/ring_window.obj")).expect("reads");
    let patches = scene.geometry.patches();
    let ring: Vec<usize> = (0..patches.len()).filter(|&k| patches[k].1 == 1).collect();
    assert_eq!(ring.len(), obj.len());
    for (&k, want) in ring.iter().zip(&obj) {
        let got = scene.geometry.domain_patch(k);
        assert_eq!(got.window, want.window);
        assert_eq!(got.weights, want.weights);
        for (a, b) in got.patch.points.iter().zip(&want.patch.points) {
            assert!(a.distance(*b) < 1e-7, "{a} against {b}");
        }
        let (a, b) = (got.trim.expect("trimmed"), want.trim.as_ref().expect("trimmed"));
        let n = 97;
        for i in 0..=n {
            for j in 0..=n {
                // Off the domain's edges, which the USD file's outer loop runs along.
                let uv = DVec2::new(
                    (i as f64 + 0.5) / (n + 1) as f64,
                    4.0 * (j as f64 + 0.5) / (n + 1) as f64,
                );
                assert_eq!(a.contains(uv), b.contains(uv), "at {uv}");
            }
        }
    }
    let names: Vec<&str> = scene.objects.iter().map(|o| o.name.as_str()).collect();
    assert_eq!(names, ["table", "ring", "ring /World/Tile", "ring /World/Marble"]);
    let tile = &scene.materials[scene.objects[2].material];
    assert!(
        tile.color.distance(DVec3::new(0.15, 0.3, 0.7)) < 1e-7,
        "{}",
        tile.color
    );
    // The marble is where its translate puts it: a ray down through its centre hits its top.
    let hit = scene
        .geometry
        .intersect(&Ray::new(DVec3::new(1.3, 2.0, 1.0), DVec3::NEG_Y), f64::INFINITY)
        .expect("hits the marble");
    assert_eq!(hit.object, 3);
    assert!((hit.point.y - 0.3).abs() < 1e-9, "{}", hit.point);
}

/// A binary layer (written by the crate's own writer) is refused, saying how to convert it:
/// the crate's binary reader aborts the program on malformed files.
#[test]
fn usdc_is_refused_saying_how_to_convert_it() {
    let dir = tempfile::tempdir().expect("temp dir");
    let text = std::fs::read_to_string("assets/ring_window.usda").expect("reads");
    let data = openusd::usda::parse(&text).expect("parses");
    let mut usdc = std::io::Cursor::new(Vec::new());
    openusd::usdc::CrateWriter::write(&data, &mut usdc).expect("writes usdc");
    for name in ["ring.usdc", "ring.usd"] {
        let err = Scene::load(&usd_scene(dir.path(), name, usdc.get_ref(), "")).expect_err("refused");
        let message = err.to_string();
        assert!(
            message.contains(name)
                && message.contains("binary USD (crate) layers are not read")
                && message.contains("usdcat"),
            "{message}"
        );
    }
}

/// Transform ops compose as USD says (first op outermost, a parent's before its child's),
/// `!invert!` inverts, `!resetXformStack!` drops the parent's, and `rotateXYZ` turns about x
/// first.
#[test]
fn transforms_compose_as_usd_says() {
    let dir = tempfile::tempdir().expect("temp dir");
    let usd = r#"#usda 1.0
def Xform "Parent"
{
    double3 xformOp:translate = (10, 0, 0)
    float3 xformOp:scale = (2, 2, 2)
    uniform token[] xformOpOrder = ["xformOp:translate", "xformOp:scale"]

    def Sphere "A"
    {
        double radius = 0.5
        double3 xformOp:translate = (1, 2, 3)
        double3 xformOp:translate:back = (0, 1, 0)
        uniform token[] xformOpOrder = ["xformOp:translate", "!invert!xformOp:translate:back"]
    }

    def Sphere "B"
    {
        double radius = 1
        double3 xformOp:rotateXYZ = (90, 90, 0)
        double3 xformOp:translate = (0, 1, 0)
        uniform token[] xformOpOrder = ["!resetXformStack!", "xformOp:rotateXYZ", "xformOp:translate"]
    }

    def Sphere "C"
    {
        matrix4d xformOp:transform = ( (1, 0, 0, 0), (0, 1, 0, 0), (0, 0, 1, 0), (5, 6, 7, 1) )
        uniform token[] xformOpOrder = ["xformOp:transform"]
    }
}
"#;
    let path = usd_scene(dir.path(), "t.usda", usd, "nurbs = true\n");
    let scene = Scene::load(&path).expect("loads");
    let object = |name: &str| {
        scene
            .objects
            .iter()
            .position(|o| o.name == format!("thing /Parent/{name}"))
            .unwrap_or_else(|| panic!("no {name}"))
    };
    let top = |x: f64, z: f64| {
        scene
            .geometry
            .intersect(&Ray::new(DVec3::new(x, 100.0, z), DVec3::NEG_Y), f64::INFINITY)
            .map(|h| (h.object, h.point.y))
    };
    // A: parent · (translate (1,2,3) · translate (0,1,0)⁻¹) = 10 + 2·(1, 1, 3), radius 1.
    let a = object("A");
    assert_eq!(top(12.0, 6.0).map(|(o, _)| o as usize), Some(a));
    assert!((top(12.0, 6.0).expect("hits").1 - 3.0).abs() < 1e-9);
    // B ignores the parent: rotate x by 90 then y by 90 takes (0,1,0) to (0,0,1) then to (1,0,0).
    let b = object("B");
    assert_eq!(top(1.0, 0.0).map(|(o, _)| o as usize), Some(b));
    assert!((top(1.0, 0.0).expect("hits").1 - 1.0).abs() < 1e-9);
    // C: the matrix's last row is its translation, under the parent's: 10 + 2·5, 2·6, 2·7;
    // the default radius 1 scaled by 2.
    let c = object("C");
    assert_eq!(top(20.0, 14.0).map(|(o, _)| o as usize), Some(c));
    assert!((top(20.0, 14.0).expect("hits").1 - 14.0).abs() < 1e-9);
}

/// What is not read (other prim types, composition arcs, a Z-up stage, guides) is listed in
/// one warning naming the object, and the rest is read; an invisible prim hides its children.
#[test]
fn what_is_not_read_is_one_warning() {
    let dir = tempfile::tempdir().expect("temp dir");
    let usd = r#"#usda 1.0
(
    upAxis = "Z"
)
def Camera "Cam"
{
}
def DistantLight "Sun"
{
}
def DistantLight "Moon"
{
}
over "Elsewhere"
{
}
def Xform "Group" (
    references = @other.usda@
)
{
    def Sphere "Ball"
    {
        double radius = 2
    }
}
def Xform "Hidden"
{
    token visibility = "invisible"
    def Sphere "Inside"
    {
    }
}
def Xform "Helpers"
{
    uniform token purpose = "guide"
    def Sphere "Handle"
    {
    }
}
"#;
    let path = usd_scene(dir.path(), "w.usda", usd, "");
    let scene = Scene::load(&path).expect("loads");
    assert_eq!(scene.warnings.len(), 1, "{:?}", scene.warnings);
    let w = &scene.warnings[0];
    for part in [
        "objects[0] (patches \"thing\")",
        "1 × Camera prims",
        "2 × DistantLight prims",
        "1 × 'over' prims (not composed)",
        "references (not composed)",
        "upAxis \"Z\"",
        "1 × prims of purpose \"guide\" (not rendered)",
    ] {
        assert!(w.contains(part), "{part:?} missing from {w}");
    }
    assert_eq!(scene.objects.len(), 2);
    assert_eq!(scene.objects[1].name, "thing /Group/Ball");
}

/// A mesh's polygons become triangle fans, turned for a left-handed mesh.
#[test]
fn meshes_are_fans_and_left_handed_ones_turn() {
    let dir = tempfile::tempdir().expect("temp dir");
    let mesh = |orientation: &str| {
        format!(
            "#usda 1.0\ndef Mesh \"M\"\n{{\n    int[] faceVertexCounts = [5]\n    int[] faceVertexIndices = [0, 1, 2, 3, 4]\n    \
             point3f[] points = [(0, 0, 0), (0, 0, 1), (1, 0, 1), (1.5, 0, 0.5), (1, 0, 0)]\n    \
             uniform token orientation = \"{orientation}\"\n    uniform token subdivisionScheme = \"none\"\n}}\n"
        )
    };
    for (orientation, up) in [("rightHanded", true), ("leftHanded", false)] {
        let path = usd_scene(dir.path(), "m.usda", mesh(orientation), "");
        let scene = Scene::load(&path).expect("loads");
        assert!(scene.warnings.is_empty(), "{:?}", scene.warnings);
        let hit = scene
            .geometry
            .intersect(&Ray::new(DVec3::new(1.2, 1.0, 0.5), DVec3::NEG_Y), f64::INFINITY)
            .expect("hits the pentagon's third triangle");
        assert_eq!(hit.normal.y > 0.0, up, "{orientation}: {}", hit.normal);
    }
}

/// Trim loops over `[0,1]²`: a square hole given first, then the square outer loop (both
/// polylines).
const TRIMS: &str = "    int[] trimCurve:counts = [1, 1]\n    int[] trimCurve:orders = [2, 2]\n    \
     int[] trimCurve:vertexCounts = [5, 5]\n    \
     double[] trimCurve:knots = [0, 0, 1, 2, 3, 4, 4, 0, 0, 1, 2, 3, 4, 4]\n    \
     double2[] trimCurve:ranges = [(0, 4), (0, 4)]\n    \
     double3[] trimCurve:points = [(0.4, 0.4, 1), (0.4, 0.6, 1), (0.6, 0.6, 1), (0.6, 0.4, 1), (0.4, 0.4, 1), \
     (0, 0, 1), (1, 0, 1), (1, 1, 1), (0, 1, 1), (0, 0, 1)]\n";

/// A NURBS patch's own `pointWeights`, `uRange` and trim loops are read: a quarter of the
/// square is kept by a range, and a square hole in a square outer loop cuts it (the loops
/// given inner first, so the order does not decide which is the hole).
#[test]
fn ranges_weights_and_trims_are_read() {
    let dir = tempfile::tempdir().expect("temp dir");
    let hit = |scene: &Scene, x: f64, z: f64| {
        scene
            .geometry
            .intersect(&Ray::new(DVec3::new(x, 1.0, z), DVec3::NEG_Y), f64::INFINITY)
            .is_some()
    };
    let ranged = flat_patch("    double2 uRange = (0, 0.5)\n    double[] pointWeights = [1, 2, 2, 1]\n");
    let scene = Scene::load(&usd_scene(dir.path(), "r.usda", &ranged, "")).expect("loads");
    assert_eq!(scene.geometry.patch_domains()[0].u1, 0.5);
    assert!(scene.geometry.patch_weights(0).is_some());
    assert!(hit(&scene, 0.1, 0.5) && !hit(&scene, 0.9, 0.5));
    let trimmed = flat_patch(TRIMS);
    let scene = Scene::load(&usd_scene(dir.path(), "t.usda", &trimmed, "")).expect("loads");
    assert!(!hit(&scene, 0.5, 0.5), "the hole is cut");
    assert!(hit(&scene, 0.2, 0.5) && hit(&scene, 0.8, 0.9), "the rest is kept");
}

/// Bad files are errors naming the scene's object, the USD file and line, the prim and the
/// attribute.
#[test]
fn bad_usd_is_an_error_naming_file_prim_and_attribute() {
    let dir = tempfile::tempdir().expect("temp dir");
    let cases: Vec<(String, &str)> = vec![
        (flat_patch("").replace("int uOrder = 2", "int uOrder = 5"), "bad.usda:7: prim /Flat: 'uOrder' is 5 (degree 4)"),
        (flat_patch("").replace("[0, 0, 1, 1]\n    double[] vKnots", "[0, 1, 1]\n    double[] vKnots"), "'uKnots' has 3 values"),
        (flat_patch("    double[] pointWeights = [1, 0, 1, 1]\n"), "bad.usda:12: prim /Flat: 'pointWeights[1]' is 0"),
        (flat_patch("").replace("(1, 0, 1)]", "(1, 0, 1), (2, 0, 2)]"), "'points' has 5 points"),
        (flat_patch("    double2 uRange = (0, 3)\n"), "'uRange'"),
        (
            flat_patch("    int[] trimCurve:counts = [2]\n    int[] trimCurve:orders = [2]\n"),
            "'trimCurve:vertexCounts' is not authored",
        ),
        (
            flat_patch(&TRIMS.replace("counts = [1, 1]", "counts = [1, 2]")),
            "'trimCurve:orders' has 2 entries; 'trimCurve:counts' makes 3 curves",
        ),
        (
            flat_patch(&TRIMS.replace("(0, 0, 1)]", "(0, 0.5, 1)]")),
            "trim loop 1 is not closed",
        ),
        (
            "#usda 1.0\ndef Mesh \"M\"\n{\n    int[] faceVertexCounts = [3]\n    int[] faceVertexIndices = [0, 1, 7]\n    point3f[] points = [(0, 0, 0), (1, 0, 0), (0, 0, 1)]\n}\n".to_owned(),
            "'faceVertexIndices' holds 7",
        ),
        ("#usda 1.0\ndef Sphere \"S\" {\n    double radius = \n}\n".to_owned(), "not a readable USD text file: line 4, column"),
    ];
    for (usd, expected) in cases {
        let err = Scene::load(&usd_scene(dir.path(), "bad.usda", &usd, "")).expect_err(expected);
        let message = err.to_string();
        assert!(
            message.contains("bad.usda") && message.contains(expected),
            "{expected:?} in {message}"
        );
        assert!(message.contains("objects[0]"), "{message}");
        if !expected.starts_with("not a readable") {
            assert!(message.contains("prim /"), "{message}");
        }
    }
    let missing = usd_scene(dir.path(), "x.usda", "", "").with_file_name("scene.toml");
    std::fs::remove_file(dir.path().join("x.usda")).expect("removes");
    let err = Scene::load(&missing).expect_err("missing file");
    assert!(err.to_string().contains("x.usda"), "{err}");
    let err = Scene::load(&usd_scene(dir.path(), "y.obj", "", "nurbs = false\n")).expect_err("nurbs on OBJ");
    assert!(
        err.to_string().contains("'nurbs' applies only to a USD 'file'"),
        "{err}"
    );
}

/// An edited USD surface saves as an OBJ beside the scene, and the file's other prims stay:
/// the saved scene reads them from the USD file with `nurbs = false`.
#[test]
fn an_edited_usd_surface_saves_and_keeps_the_files_other_prims() {
    let dir = tempfile::tempdir().expect("temp dir");
    let text = std::fs::read_to_string("assets/ring_window.usda").expect("reads");
    let path = usd_scene(dir.path(), "ring.usda", &text, "");
    let mut scene = Scene::load(&path).expect("loads");
    let loaded: Vec<_> = scene.geometry.patches().iter().map(|(p, _)| *p).collect();
    assert_eq!(scene.geometry.nets().len(), 1);
    assert!(scene
        .geometry
        .move_net_points(0, &[(3, DVec3::new(1.2, 0.7, 1.0))])
        .is_some());
    let saved = dir.path().join("saved.toml");
    caustic::scene::save::save_scene(&scene, &loaded, &saved, false).expect("saves");
    let toml = std::fs::read_to_string(&saved).expect("reads");
    assert!(toml.contains("file = \"saved.thing.obj\""), "{toml}");
    assert!(
        toml.contains("file = \"ring.usda\"") && toml.contains("nurbs = false"),
        "{toml}"
    );
    let back = Scene::load(&saved).expect("loads back");
    assert_eq!(back.geometry.patches(), scene.geometry.patches());
    let names: Vec<&str> = back.objects.iter().map(|o| o.name.as_str()).collect();
    assert_eq!(
        names,
        ["thing", "thing", "thing /World/Tile", "thing /World/Marble"]
    );
}

/// A USDZ package's first USD layer is read (a text one; a binary one is refused as a
/// `.usdc` file is), whatever else the package holds.
#[test]
fn usdz_packages_are_read() {
    use std::io::Write;
    let dir = tempfile::tempdir().expect("temp dir");
    let text = std::fs::read_to_string("assets/ring_window.usda").expect("reads");
    let package = |name: &str, layer: &[u8]| {
        let mut zip = zip::ZipWriter::new(std::io::Cursor::new(Vec::new()));
        let stored =
            zip::write::SimpleFileOptions::default().compression_method(zip::CompressionMethod::Stored);
        zip.start_file("texture.png", stored).expect("starts");
        zip.write_all(b"not read").expect("writes");
        zip.start_file(name, stored).expect("starts");
        zip.write_all(layer).expect("writes");
        zip.finish().expect("finishes").into_inner()
    };
    let plain = Scene::load(&usd_scene(dir.path(), "ring.usda", &text, "")).expect("loads usda");
    let packaged = Scene::load(&usd_scene(
        dir.path(),
        "ring.usdz",
        package("ring.usda", text.as_bytes()),
        "",
    ))
    .expect("loads usdz");
    assert_eq!(plain.geometry.patches(), packaged.geometry.patches());
    assert_eq!(packaged.objects.len(), 3);
    let data = openusd::usda::parse(&text).expect("parses");
    let mut usdc = std::io::Cursor::new(Vec::new());
    openusd::usdc::CrateWriter::write(&data, &mut usdc).expect("writes usdc");
    let err = Scene::load(&usd_scene(
        dir.path(),
        "ring.usdz",
        package("ring.usdc", usdc.get_ref()),
        "",
    ))
    .expect_err("a binary layer in a package");
    assert!(
        err.to_string().contains("binary USD (crate) layers are not read"),
        "{err}"
    );
}
