//! Helpers shared by the integration tests.
#![allow(dead_code)]

use caustic::geometry::{load_bpt, BezierPatch};
use glam::{DVec2, DVec3};
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64Mcg;

/// The unit circle as a rational quadratic B-spline, as CAD programs write it: 9 points
/// `(x, y, weight)` (the square's corners weigh √½), knots `0 0 0 1 1 2 2 3 3 4 4 4`.
pub fn rational_circle() -> [(f64, f64, f64); 9] {
    let h = std::f64::consts::FRAC_1_SQRT_2;
    [
        (1.0, 0.0, 1.0),
        (1.0, 1.0, h),
        (0.0, 1.0, 1.0),
        (-1.0, 1.0, h),
        (-1.0, 0.0, 1.0),
        (-1.0, -1.0, h),
        (0.0, -1.0, 1.0),
        (1.0, -1.0, h),
        (1.0, 0.0, 1.0),
    ]
}

/// Runs the `caustic` binary with `args` in the project folder.
pub fn caustic(args: &[&str]) -> std::process::Output {
    std::process::Command::new(env!("CARGO_BIN_EXE_caustic"))
        .args(args)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .expect("run caustic")
}

/// A run's stdout and stderr, for assertion messages.
pub fn text(out: &std::process::Output) -> String {
    format!(
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    )
}

/// The project's own teapot file (never ../shared).
pub fn teapot_from_assets() -> Vec<BezierPatch> {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/teapot.bpt");
    load_bpt(&path).expect("assets/teapot.bpt loads")
}

/// Diagonal of the bounds of all patches.
pub fn diagonal(patches: &[BezierPatch]) -> f64 {
    patches
        .iter()
        .fold(caustic::geometry::Aabb::EMPTY, |b, p| b.union(p.bounds()))
        .diagonal()
        .length()
}

/// A deterministic generator for test `seed`.
pub fn rng(seed: u64) -> Pcg64Mcg {
    Pcg64Mcg::seed_from_u64(seed)
}

/// A uniformly random unit vector.
pub fn unit_vector(rng: &mut Pcg64Mcg) -> DVec3 {
    loop {
        let v = DVec3::new(rng.random::<f64>(), rng.random::<f64>(), rng.random::<f64>()) * 2.0 - 1.0;
        let l = v.length_squared();
        if l > 1e-6 && l <= 1.0 {
            return v / l.sqrt();
        }
    }
}

/// One boundary curve of a patch: `[v=0, v=1, u=0, u=1]` (as `BezierPatch::collapsed_edges`).
pub fn edge_points(p: &BezierPatch, edge: usize) -> [DVec3; 4] {
    std::array::from_fn(|k| match edge {
        0 => p.point(k, 0),
        1 => p.point(k, 3),
        2 => p.point(0, k),
        _ => p.point(3, k),
    })
}

/// Parameters of the point at `w ∈ [0,1]` along boundary `edge`.
pub fn edge_uv(edge: usize, w: f64) -> DVec2 {
    match edge {
        0 => DVec2::new(w, 0.0),
        1 => DVec2::new(w, 1.0),
        2 => DVec2::new(0.0, w),
        _ => DVec2::new(1.0, w),
    }
}

/// An edge shared by two patches: `(patch a, edge of a, patch b, edge of b, reversed)`.
pub type SharedEdge = (usize, usize, usize, usize, bool);

/// Every boundary curve that two patches share exactly (collapsed edges excluded).
pub fn shared_edges(patches: &[BezierPatch]) -> Vec<SharedEdge> {
    let mut out = Vec::new();
    for a in 0..patches.len() {
        for b in a + 1..patches.len() {
            for ea in 0..4 {
                let pa = edge_points(&patches[a], ea);
                if pa.iter().all(|p| *p == pa[0]) {
                    continue;
                }
                for eb in 0..4 {
                    let pb = edge_points(&patches[b], eb);
                    let mut rev = pb;
                    rev.reverse();
                    if pa == pb {
                        out.push((a, ea, b, eb, false));
                    } else if pa == rev {
                        out.push((a, ea, b, eb, true));
                    }
                }
            }
        }
    }
    out
}

#[cfg(feature = "viewer")]
pub mod gpu;
pub mod lighting;

/// A rayon thread pool of `threads` threads (for determinism across thread counts).
pub fn pool(threads: usize) -> rayon::ThreadPool {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .expect("pool")
}

/// `passes` passes of `integrator` over `scene`, each completed: the image.
pub fn rendered(
    mut integrator: Box<dyn caustic::render::integrator::Integrator>,
    scene: &caustic::scene::Scene,
    passes: u32,
) -> Vec<[f32; 3]> {
    let plan = caustic::render::integrator::PassPlan {
        params: scene.params.clone(),
        first_pass_photons: None,
    };
    for _ in 0..passes {
        assert!(integrator.render_pass(scene, &plan, &mut |_| {
            caustic::render::integrator::Control::Continue
        }));
    }
    assert_eq!(integrator.passes(), passes);
    integrator.frame(0, 0.0).radiance.to_vec()
}
