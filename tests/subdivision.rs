//! Sub-patches: bounds contain the surface, and (u,v) through repeated splits map back exactly.

mod common;

use caustic::geometry::patch::subdivide;
use caustic::geometry::{SubdivisionParams, Window};
use common::*;
use rand::Rng;

#[test]
fn repeated_splits_keep_the_original_parameterisation() {
    let patches = teapot_from_assets();
    let diag = diagonal(&patches);
    let mut rng = rng(10);
    for patch in &patches {
        for _ in 0..20 {
            // Walk down a random path of quarter splits, as the seed's queue does.
            let (mut sub, mut window) = (*patch, Window::FULL);
            for _ in 0..rng.random_range(1..=12) {
                let k = rng.random_range(0..4);
                sub = sub.split_quad()[k];
                window = window.quarters()[k];
            }
            // The same window cut directly must agree with the split chain.
            let direct = patch.sub_patch(window.u0, window.u1, window.v0, window.v1);
            let bounds = sub.bounds().padded(1e-12 * diag);
            for _ in 0..10 {
                let (s, t) = (rng.random::<f64>(), rng.random::<f64>());
                let uv = window.map(s, t);
                let expected = patch.eval(uv.x, uv.y);
                assert!((sub.eval(s, t) - expected).length() < 1e-12 * diag);
                assert!((direct.eval(s, t) - expected).length() < 1e-12 * diag);
                assert!(bounds.contains(sub.eval(s, t)), "sub-patch leaves its bounds");
            }
        }
    }
}

#[test]
fn prepared_leaves_tile_each_patch_and_bound_it() {
    let patches = teapot_from_assets();
    let diag = diagonal(&patches);
    let mut rng = rng(11);
    for (k, patch) in patches.iter().enumerate() {
        let leaves = subdivide(patch, k as u32, &SubdivisionParams::default());
        let area: f64 = leaves
            .iter()
            .map(|l| (l.window.u1 - l.window.u0) * (l.window.v1 - l.window.v0))
            .sum();
        assert!(
            (area - 1.0).abs() < 1e-12,
            "patch {k}: leaves cover {area} of the domain"
        );
        for leaf in &leaves {
            for _ in 0..8 {
                let (s, t) = (rng.random::<f64>(), rng.random::<f64>());
                let uv = leaf.window.map(s, t);
                let p = patch.eval(uv.x, uv.y);
                assert!((leaf.sub_patch.eval(s, t) - p).length() < 1e-12 * diag);
                assert!(leaf.bounds.contains(p), "patch {k}: leaf bounds miss its surface");
            }
        }
    }
}

#[test]
fn the_leaf_budget_bounds_a_patch_and_leaves_the_shipped_scenes_as_they_were() {
    use caustic::geometry::patch::{leaf_budget, MIN_PATCH_LEAVES};
    // A crumpled patch asks for hundreds of leaves; held to a budget it gets at most that
    // many, which still tile it.
    let mut r = rng(57);
    let crumpled = caustic::geometry::BezierPatch::new(std::array::from_fn(|_| {
        glam::DVec3::new(r.random(), r.random(), r.random())
    }));
    let free = subdivide(&crumpled, 0, &SubdivisionParams::default());
    assert!(free.len() > 300, "{} leaves", free.len());
    for budget in [MIN_PATCH_LEAVES, 10, 100] {
        let params = SubdivisionParams {
            max_leaves: budget,
            ..Default::default()
        };
        let held = subdivide(&crumpled, 0, &params);
        assert!(
            held.len() <= budget && held.len() + 3 > budget,
            "{} of {budget}",
            held.len()
        );
        let area: f64 = held
            .iter()
            .map(|l| (l.window.u1 - l.window.u0) * (l.window.v1 - l.window.v0))
            .sum();
        assert!((area - 1.0).abs() < 1e-12, "the leaves tile the patch: {area}");
    }
    assert_eq!(leaf_budget(10_000), MIN_PATCH_LEAVES);
    // No shipped scene's patch asks for more than its share.
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes");
    for entry in std::fs::read_dir(&dir).expect("scenes").flatten() {
        let path = entry.path();
        if path.extension().is_none_or(|e| e != "toml") {
            continue;
        }
        let scene = caustic::scene::Scene::load(&path).expect("loads");
        let patches = scene.geometry.patches();
        let budget = leaf_budget(patches.len());
        for (k, (p, _)) in patches.iter().enumerate() {
            let n = subdivide(p, k as u32, &SubdivisionParams::default()).len();
            assert!(
                n <= budget,
                "{}: patch {k} asks for {n} leaves, its share is {budget}",
                path.display()
            );
        }
    }
}
