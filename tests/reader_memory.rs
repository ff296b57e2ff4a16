//! What the readers keep while they read: every allocation of this test binary is counted,
//! and each reader, given a generated input, may hold at most 64 bytes for each byte of it
//! beyond what it returns (issue 57's bound), and much less where the input is mostly lines
//! it has no use for; and converting a B-spline allocates in proportion to its knots. One
//! test, so that no other test allocates meanwhile.
#![allow(unsafe_code)]

use std::alloc::{GlobalAlloc, Layout, System};
use std::path::Path;
use std::sync::atomic::{AtomicUsize, Ordering};

use caustic::geometry::freeform::DomainPatch;
use caustic::geometry::{load_bpt, load_freeform_obj, BezierPatch, TriangleMesh};

/// The system allocator, counting the bytes held now and their peak.
struct Counting;

static HELD: AtomicUsize = AtomicUsize::new(0);
static PEAK: AtomicUsize = AtomicUsize::new(0);
/// Bytes ever allocated.
static TOTAL: AtomicUsize = AtomicUsize::new(0);

fn count_up(bytes: usize) {
    TOTAL.fetch_add(bytes, Ordering::Relaxed);
    let now = HELD.fetch_add(bytes, Ordering::Relaxed) + bytes;
    PEAK.fetch_max(now, Ordering::Relaxed);
}

// SAFETY: every call is forwarded to the system allocator unchanged; the counters only watch.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        count_up(layout.size());
        // SAFETY: the caller's layout, as given.
        unsafe { System.alloc(layout) }
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        HELD.fetch_sub(layout.size(), Ordering::Relaxed);
        // SAFETY: `ptr` came from `alloc` with this layout.
        unsafe { System.dealloc(ptr, layout) }
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        count_up(new_size);
        // SAFETY: as for `dealloc` and `alloc`.
        let moved = unsafe { System.realloc(ptr, layout, new_size) };
        HELD.fetch_sub(layout.size(), Ordering::Relaxed);
        moved
    }
}

#[global_allocator]
static ALLOCATOR: Counting = Counting;

/// The most bytes `read` held at once beyond what it held before, and what it returned.
fn peak_of<T>(read: impl FnOnce() -> T) -> (usize, T) {
    let before = HELD.load(Ordering::Relaxed);
    PEAK.store(before, Ordering::Relaxed);
    let out = read();
    (PEAK.load(Ordering::Relaxed) - before, out)
}

/// Checks one reader: `read` of a `len`-byte input peaked at most `bound` bytes per input byte
/// beyond `kept`, the bytes of what it returned.
fn check(what: &str, len: usize, peak: usize, kept: usize, bound: f64) {
    let per_byte = peak.saturating_sub(kept) as f64 / len as f64;
    eprintln!("{what}: {len} bytes in, peak {peak} bytes, {kept} kept: {per_byte:.2} bytes a byte");
    assert!(per_byte <= 64.0, "{what}: {per_byte:.1} bytes a byte of input");
    assert!(
        per_byte <= bound,
        "{what}: {per_byte:.2} bytes a byte of input, expected at most {bound}"
    );
}

/// A bicubic Bézier surface over the last 16 `v` lines, as OBJ text.
const SURFACE: &str = "cstype bezier\ndeg 3 3\nsurf 0 1 0 1 -16 -15 -14 -13 -12 -11 -10 -9 -8 -7 -6 -5 -4 -3 -2 -1\nparm u 0 1\nparm v 0 1\nend\n";

fn grid_points() -> String {
    (0..16)
        .map(|k| format!("v {} {} {}\n", k % 4, (k * 7 % 5) as f64 * 0.1, k / 4))
        .collect()
}

fn write(dir: &Path, name: &str, text: &str) -> std::path::PathBuf {
    let path = dir.join(name);
    std::fs::write(&path, text).expect("write");
    path
}

fn domain_patches_bytes(patches: &Vec<DomainPatch>) -> usize {
    patches.capacity() * std::mem::size_of::<DomainPatch>()
}

#[test]
fn readers_hold_little_beyond_what_they_return() {
    let dir = tempfile::tempdir().expect("temp dir");
    // 8 MB of blank lines and one surface: nothing of the blank lines is kept.
    let text = format!("{}{}{SURFACE}", "\n".repeat(8 << 20), grid_points());
    let path = write(dir.path(), "blank.obj", &text);
    let (peak, patches) = peak_of(|| load_freeform_obj(&path).expect("reads"));
    check(
        "free-form, blank lines",
        text.len(),
        peak,
        domain_patches_bytes(&patches),
        0.01,
    );
    // 4 MB of points and one surface: 40 bytes a point of 8 bytes of text.
    let text = format!("{}{}{SURFACE}", "v 0 0 0\n".repeat(500_000), grid_points());
    let path = write(dir.path(), "points.obj", &text);
    let (peak, patches) = peak_of(|| load_freeform_obj(&path).expect("reads"));
    check(
        "free-form, points",
        text.len(),
        peak,
        domain_patches_bytes(&patches),
        8.0,
    );
    // 4000 small surfaces.
    let text: String = (0..4000).map(|_| format!("{}{SURFACE}", grid_points())).collect();
    let path = write(dir.path(), "many.obj", &text);
    let (peak, patches) = peak_of(|| load_freeform_obj(&path).expect("reads"));
    assert_eq!(patches.len(), 4000);
    check(
        "free-form, 4000 surfaces",
        text.len(),
        peak,
        domain_patches_bytes(&patches),
        8.0,
    );
    // A B-spline of 20,000 knots along u, 4 rows along v: 19,997 patches.
    let nu = 20_000 - 4;
    let points: String = (0..4 * nu)
        .map(|k| format!("v {} {} {}\n", k % nu, (k % 3) as f64 * 0.1, k / nu))
        .collect();
    let knots: Vec<String> = (0..nu + 4).map(|k| k.to_string()).collect();
    let indices: Vec<String> = (1..=4 * nu).map(|k| k.to_string()).collect();
    let text = format!(
        "{points}cstype bspline\ndeg 3 3\nsurf 3 {} 3 4 {}\nparm u {}\nparm v 0 1 2 3 4 5 6 7\nend\n",
        nu,
        indices.join(" "),
        knots.join(" ")
    );
    let path = write(dir.path(), "long.obj", &text);
    let (peak, patches) = peak_of(|| load_freeform_obj(&path).expect("reads"));
    assert_eq!(patches.len(), nu - 3);
    check(
        "free-form, 20,000 knots",
        text.len(),
        peak,
        domain_patches_bytes(&patches),
        16.0,
    );
    // A .bpt file padded with comments: read whole, then in place.
    let one: String = (0..16)
        .map(|k| format!("{} {} {}\n", k % 4, 0.1 * (k % 3) as f64, k / 4))
        .collect();
    let text = format!(
        "2000\n{}",
        (0..2000)
            .map(|_| format!("# a patch\n\n3 3\n{one}"))
            .collect::<String>()
    );
    let path = write(dir.path(), "many.bpt", &text);
    let (peak, patches) = peak_of(|| load_bpt(&path).expect("reads"));
    let kept = patches.capacity() * std::mem::size_of::<BezierPatch>();
    check(".bpt, 2000 patches", text.len(), peak, kept, 2.0);
    // An OBJ mesh of 100,000 triangles.
    let mut text = String::new();
    for k in 0..100_000 {
        text.push_str(&format!("v {k} 0 0\nv {k} 1 0\nv {k} 0 1\n"));
    }
    for k in 0..100_000 {
        text.push_str(&format!("f {} {} {}\n", 3 * k + 1, 3 * k + 2, 3 * k + 3));
    }
    let path = write(dir.path(), "mesh.obj", &text);
    let (peak, mesh) = peak_of(|| TriangleMesh::load_obj(&path).expect("reads"));
    let kept = mesh.positions.capacity() * 24
        + mesh.normals.capacity() * 24
        + mesh.texcoords.capacity() * 16
        + mesh.indices.capacity() * 12;
    check("OBJ mesh, 100,000 triangles", text.len(), peak, kept, 64.0);
    // Converting a B-spline of 4n knots allocates about four times what n knots do (knot
    // insertion one knot at a time copied every point for every knot: sixteen times).
    let allocated = |n: usize| {
        let knots: Vec<f64> = (0..n + 4).map(|k| k as f64).collect();
        let knots = caustic::geometry::bspline::Knots::new(knots, n, 'u').expect("valid");
        let points: Vec<glam::DVec3> = (0..n)
            .map(|k| glam::DVec3::new(k as f64, (k % 3) as f64, 0.0))
            .collect();
        let before = TOTAL.load(Ordering::Relaxed);
        let segments = caustic::geometry::bspline::bezier_segments(&points, &knots, 3.5, n as f64 - 0.5);
        assert_eq!(segments.len(), n - 3);
        TOTAL.load(Ordering::Relaxed) - before
    };
    let (small, large) = (allocated(5_000), allocated(20_000));
    let ratio = large as f64 / small as f64;
    eprintln!("B-spline conversion: {small} bytes allocated for 5,000 knots, {large} for 20,000");
    assert!(
        ratio < 4.5,
        "{small} bytes for 5,000 knots, {large} for 20,000: {ratio:.2}x"
    );
}
