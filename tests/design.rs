//! The caustic designer's derivative: where a photon lands on the receiver moves with the
//! designed surface's control points as finite differences of the traced landing say.

use caustic::design::landing::{land, DesignParams, Receiver};
use caustic::geometry::{Quad, Ray};
use caustic::scene::Scene;
use glam::DVec3;

/// `scenes/lens.toml` (a biconvex glass lens of two patches lit by a spot light) with its
/// wall replaced by a receiver quad, and the receiver.
fn lens_scene() -> (Scene, Receiver) {
    let text = std::fs::read_to_string("scenes/lens.toml").expect("reads");
    let wall = "type = \"plane\"\nname = \"wall\"\npoint = [2.5, 0, 0]\nnormal = [-1, 0, 0]";
    assert!(text.contains(wall));
    let quad = Quad {
        corner: DVec3::new(2.5, -1.0, 2.0),
        edge_u: DVec3::new(0.0, 0.0, -4.0),
        edge_v: DVec3::new(0.0, 4.0, 0.0),
    };
    let receiver =
        "type = \"quad\"\nname = \"wall\"\ncorner = [2.5, -1, 2]\nedge_u = [0, 0, -4]\nedge_v = [0, 4, 0]";
    let scene = Scene::from_str(
        &text.replace(wall, receiver),
        std::path::Path::new("scenes/lens.toml"),
        Some(std::path::Path::new("scenes")),
    )
    .expect("loads");
    let object = scene
        .objects
        .iter()
        .position(|o| o.name == "wall")
        .expect("a wall") as u32;
    (scene, Receiver { object, quad })
}

/// Rays from the spot light through points spread over the lens.
fn rays(scene: &Scene, lens: u32) -> Vec<Ray> {
    let bounds = scene
        .geometry
        .patches()
        .iter()
        .filter(|(_, id)| *id == lens)
        .map(|(p, _)| p.bounds())
        .reduce(|a, b| a.union(b))
        .expect("lens patches");
    let centre = (bounds.min + bounds.max) * 0.5;
    let size = bounds.max - bounds.min;
    let light = DVec3::new(-4.0, 1.6, 0.0);
    let mut out = Vec::new();
    for (a, b) in [
        (0.0, 0.0),
        (0.2, 0.1),
        (-0.25, 0.3),
        (0.3, -0.2),
        (-0.1, -0.35),
        (0.05, 0.2),
    ] {
        let target = centre + DVec3::new(0.0, a * size.y, b * size.z);
        out.push(Ray::new(light, (target - light).normalize()));
    }
    out
}

/// The analytic derivative of each landing point with respect to every control point agrees
/// with central finite differences (step 1e-5) to 1e-7 (they agree to about 1e-10): 240
/// derivatives over six photons and the lens's 20 welded control points, 158 of them moving.
#[test]
fn landing_derivatives_match_finite_differences() {
    let (mut scene, receiver) = lens_scene();
    let lens = scene
        .objects
        .iter()
        .position(|o| o.name == "lens")
        .expect("a lens") as u32;
    let params = DesignParams::of_object(&scene, lens, DVec3::X).expect("params");
    assert!(
        params.len() > 16 && params.len() < 32,
        "{} parameters (two patches welded at the rim)",
        params.len()
    );
    let rays = rays(&scene, lens);
    let analytic: Vec<_> = rays
        .iter()
        .map(|r| land(&scene, &params, &receiver, *r, 8).expect("lands"))
        .collect();
    let h = 1e-5;
    let mut checked = 0;
    let mut moved = 0;
    for q in 0..params.len() {
        let mut at = |offset: f64| -> Vec<Option<[f64; 2]>> {
            let mut theta = vec![0.0; params.len()];
            theta[q] = offset;
            assert!(params.apply(&mut scene, &theta));
            rays.iter()
                .map(|r| land(&scene, &params, &receiver, *r, 8).map(|[s, t]| [s.v, t.v]))
                .collect()
        };
        let (plus, minus) = (at(h), at(-h));
        at(0.0);
        for (r, (a, (p, m))) in analytic.iter().zip(plus.iter().zip(&minus)).enumerate() {
            let (Some(p), Some(m)) = (p, m) else { continue };
            for axis in 0..2 {
                let fd = (p[axis] - m[axis]) / (2.0 * h);
                let exact = a[axis].g.iter().find(|e| e.0 == q as u32).map_or(0.0, |e| e.1);
                assert!(
                    (fd - exact).abs() <= 1e-7 * (1.0 + exact.abs()),
                    "ray {r}, parameter {q}, axis {axis}: analytic {exact}, finite differences {fd}"
                );
                checked += 1;
                moved += usize::from(exact.abs() > 1e-3);
            }
        }
    }
    assert!(
        checked > 100 && moved > 20,
        "{checked} derivatives checked, {moved} of them moving"
    );
}

/// A surface with its own net (the pool's water, an 11 × 11 B-spline) is designed through the
/// net's points: each Bézier point follows them by knot insertion's coefficients, and the
/// landing points' derivatives agree with finite differences of moved nets.
#[test]
fn net_derivatives_match_finite_differences() {
    let mut scene = Scene::load(std::path::Path::new("scenes/pool.toml")).expect("loads");
    let water = scene
        .objects
        .iter()
        .position(|o| o.name == "water")
        .expect("water") as u32;
    let floor = scene
        .objects
        .iter()
        .position(|o| o.name == "floor")
        .expect("floor") as u32;
    let receiver = Receiver {
        object: floor,
        quad: Quad {
            corner: DVec3::new(-2.4, -1.5, -2.4),
            edge_u: DVec3::new(0.0, 0.0, 4.8),
            edge_v: DVec3::new(4.8, 0.0, 0.0),
        },
    };
    let params = DesignParams::of_object(&scene, water, DVec3::NEG_Y).expect("params");
    assert_eq!(params.len(), 121);
    let light = DVec3::new(0.3, 3.0, 0.2);
    let rays: Vec<Ray> = [(-1.1, 0.4), (0.2, -0.7), (0.9, 1.3), (-0.3, -1.6), (1.7, 0.1)]
        .iter()
        .map(|&(x, z)| Ray::new(light, (DVec3::new(x, 0.0, z) - light).normalize()))
        .collect();
    let analytic: Vec<_> = rays
        .iter()
        .map(|r| land(&scene, &params, &receiver, *r, 8).expect("lands"))
        .collect();
    let (h, mut checked, mut moved) = (1e-5, 0, 0);
    for q in 0..params.len() {
        let mut at = |offset: f64| -> Vec<Option<[f64; 2]>> {
            let mut theta = vec![0.0; params.len()];
            theta[q] = offset;
            assert!(params.apply(&mut scene, &theta));
            rays.iter()
                .map(|r| land(&scene, &params, &receiver, *r, 8).map(|[s, t]| [s.v, t.v]))
                .collect()
        };
        let (plus, minus) = (at(h), at(-h));
        at(0.0);
        for (a, (p, m)) in analytic.iter().zip(plus.iter().zip(&minus)) {
            let (Some(p), Some(m)) = (p, m) else { continue };
            for axis in 0..2 {
                let fd = (p[axis] - m[axis]) / (2.0 * h);
                let exact = a[axis].g.iter().find(|e| e.0 == q as u32).map_or(0.0, |e| e.1);
                assert!(
                    (fd - exact).abs() <= 1e-7 * (1.0 + exact.abs()),
                    "parameter {q}, axis {axis}: analytic {exact}, finite differences {fd}"
                );
                checked += 1;
                moved += usize::from(exact.abs() > 1e-4);
            }
        }
    }
    assert!(checked > 1000 && moved > 30, "{checked} checked, {moved} moving");
}
