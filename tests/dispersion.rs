//! Dispersion against closed forms: where a prism sends each wavelength (Snell's law with the
//! glass's Sellmeier index, traced by hand in the prism's plane), and white light through a
//! slab with parallel faces, which must come out white with the transmittance Fresnel's
//! equations give.

use std::path::Path;

use caustic::render::ppm::photon::{PhotonCounts, PhotonSource};
use caustic::render::rng::stream_rng;
use caustic::render::spectrum::sample_wavelength;
use caustic::render::wavelength::Wavelength;
use caustic::scene::glasses::Dispersion;
use caustic::scene::Scene;
use glam::{DVec2, DVec3};

/// A scene from `text`, resolving files as if it sat in `scenes/`.
fn scene(text: &str) -> Scene {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes");
    Scene::from_str(text, &dir.join("test.toml"), Some(&dir)).expect("scene")
}

/// The prism of `scenes/prism.toml`: its cross-section's corners (the OBJ's vertices at the
/// front end, `z > 0`), read from `assets/prism.obj`.
fn prism_corners() -> Vec<DVec2> {
    let obj = std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/prism.obj"))
        .expect("prism.obj");
    let corners: Vec<DVec2> = obj
        .lines()
        .filter_map(|l| l.strip_prefix("v "))
        .map(|l| {
            l.split_whitespace()
                .map(|x| x.parse::<f64>().expect("a number"))
                .collect::<Vec<_>>()
        })
        .filter(|v| v[2] > 0.0)
        .map(|v| DVec2::new(v[0], v[1]))
        .collect();
    assert_eq!(corners.len(), 3);
    corners
}

/// Snell's law in the plane: `d` refracted through the unit normal `n` (facing against `d`)
/// with `eta` = n_incident / n_transmitted.
fn refract(d: DVec2, n: DVec2, eta: f64) -> DVec2 {
    let cos_i = -d.dot(n);
    let cos_t = (1.0 - eta * eta * (1.0 - cos_i * cos_i)).sqrt();
    (eta * d + (eta * cos_i - cos_t) * n).normalize()
}

/// Where a ray from `p` along `d` crosses the line through `a` and `b` (`t`, and the point).
fn cross(p: DVec2, d: DVec2, a: DVec2, b: DVec2) -> DVec2 {
    let e = b - a;
    let t = (a - p).perp_dot(e) / d.perp_dot(e);
    p + d * t
}

/// The height at which light of index `n` from `p` along `d` meets the wall `x = wall`, after
/// entering the prism's left face and leaving its right face (corners: left, right, apex).
fn landing_height(c: &[DVec2], p: DVec2, d: DVec2, n: f64, wall: f64) -> f64 {
    let outward = |a: DVec2, b: DVec2| {
        let e = (b - a).normalize();
        DVec2::new(e.y, -e.x)
    };
    let (left, right, apex) = (c[0], c[1], c[2]);
    let p1 = cross(p, d, left, apex);
    let d1 = refract(d, outward(apex, left), 1.0 / n);
    let p2 = cross(p1, d1, right, apex);
    let d2 = refract(d1, -outward(right, apex), n);
    p2.y + (wall - p2.x) / d2.x * d2.y
}

/// The prism of `assets/prism.obj` lit by a narrow spot beam at its angle of least deviation
/// for SF11's index at 587.56 nm (as in `scenes/prism.toml`), a wall at `x = 3.5` behind it:
/// the scene, and the beam's origin and direction in the prism's plane.
fn prism_scene(corners: &[DVec2]) -> (Scene, DVec2, DVec2) {
    let n_d = Dispersion::named("SF11").expect("SF11").ior(0.0, 587.56);
    let half_apex = 30f64.to_radians();
    let rise = (n_d * half_apex.sin()).asin() - half_apex;
    let axis = DVec2::new(rise.cos(), rise.sin());
    let from = (corners[0] + corners[2]) / 2.0 - 3.0 * axis;
    let text = format!(
        r#"
[camera]
position = [-2.0, 2.4, 5.5]
look_at = [1.5, 1.8, 0.0]
fov = 40
width = 8
height = 6

[materials.prism]
type = "glass"
glass = "SF11"
color = [1, 1, 1]

[materials.wall]
type = "diffuse"

[[lights]]
type = "spot"
position = [{}, {}, 0]
direction = [{}, {}, 0]
cone_angle = 0.8
cone_falloff = 0.2
power = 100

[[objects]]
type = "plane"
point = [3.5, 0, 0]
normal = [-1, 0, 0]
material = "wall"

[[objects]]
type = "mesh"
file = "../assets/prism.obj"
material = "prism"
"#,
        from.x, from.y, axis.x, axis.y
    );
    (scene(&text), from, axis)
}

/// Each wavelength's photons land on the wall where Snell's law with SF11's Sellmeier index
/// sends the beam's axis, within 2 mm (the median of where photons land first on the wall); the spectrum from 420 to 680 nm is longer than 0.5 m.
#[test]
fn prism_sends_each_wavelength_where_snell_says() {
    let corners = prism_corners();
    let (scene, from, axis) = prism_scene(&corners);
    let sf11 = Dispersion::named("SF11").expect("SF11");
    let mut heights = Vec::new();
    for nm in [420.0, 480.0, 550.0, 620.0, 680.0] {
        let source = PhotonSource::new(&scene, false).with_wavelength(Wavelength::fixed(nm));
        let mut counts = PhotonCounts::default();
        let mut landed = Vec::new();
        for i in 0..20_000u64 {
            let mut rng = stream_rng(3, 41, i);
            let mut first = None;
            source.trace(i, &mut rng, &mut counts, &mut |p, (_, wo), _, _| {
                first = first.or(Some((p, wo)));
            });
            // Photons that reached the wall straight from the prism's right face: light the
            // faces reflected lands elsewhere.
            let from_right_face = |&(p, wo): &(DVec3, DVec3)| {
                let back = cross(
                    DVec2::new(p.x, p.y),
                    DVec2::new(wo.x, wo.y),
                    corners[1],
                    corners[2],
                );
                (p.x - 3.5).abs() < 1e-6 && back.y > corners[1].y && back.y < corners[2].y
            };
            landed.extend(first.filter(from_right_face).map(|(p, _)| p.y));
        }
        assert!(
            landed.len() > 10_000,
            "{nm} nm: {} photons reached the wall",
            landed.len()
        );
        // The median: the few photons reflected inside the prism before leaving it land
        // elsewhere.
        landed.sort_by(f64::total_cmp);
        let measured = landed[landed.len() / 2];
        let expected = landing_height(&corners, from, axis, sf11.ior(0.0, nm), 3.5);
        assert!(
            (measured - expected).abs() < 0.002,
            "{nm} nm: photons land at height {measured:.4}, Snell's law says {expected:.4}"
        );
        eprintln!("{nm} nm: median landing height {measured:.4}, Snell {expected:.4}");
        heights.push(measured);
    }
    // Violet is bent most: lowest on the wall.
    assert!(heights.windows(2).all(|w| w[0] < w[1]), "{heights:?}");
    assert!(heights[4] - heights[0] > 0.5, "{heights:?}");
}

/// White light through a dispersive slab at normal incidence: each channel's share of the
/// flux reaching the floor is the slab's transmittance `(1 − R) / (1 + R)` (all its internal
/// reflections summed) averaged over the wavelengths that make up the channel, within 0.3 %,
/// and the light stays white within 1 %.
#[test]
fn white_light_through_a_parallel_slab_stays_white() {
    let (ior, abbe) = (1.7, 20.0);
    let text = format!(
        r#"
[camera]
position = [0, 3, 4]
look_at = [0, 0, 0]
fov = 40
width = 8
height = 6

[materials.slab]
type = "glass"
color = [1, 1, 1]
ior = {ior}
abbe = {abbe}

[materials.floor]
type = "diffuse"

[[lights]]
type = "spot"
position = [0, 3, 0]
direction = [0, -1, 0]
cone_angle = 0.5
cone_falloff = 0.1
power = 1

[[objects]]
type = "plane"
point = [0, 0, 0]
normal = [0, 1, 0]
material = "floor"

[[objects]]
type = "quad"
corner = [-5, 1.2, -5]
edge_u = [0, 0, 10]
edge_v = [10, 0, 0]
material = "slab"

[[objects]]
type = "quad"
corner = [-5, 1.0, -5]
edge_u = [10, 0, 0]
edge_v = [0, 0, 10]
material = "slab"
"#
    );
    // The flux reaching the floor first, with the slab and without it.
    let floor = |scene: &Scene| {
        let source = PhotonSource::new(scene, false);
        let mut counts = PhotonCounts::default();
        let mut floor = DVec3::ZERO;
        for i in 0..400_000u64 {
            let mut rng = stream_rng(5, 43, i);
            let mut first = true;
            source.trace(i, &mut rng, &mut counts, &mut |p, _, flux, indirect| {
                if first && !indirect && p.y.abs() < 1e-6 {
                    floor += flux;
                }
                first = false;
            });
        }
        floor
    };
    let open = text
        .split("[[objects]]\ntype = \"quad\"")
        .next()
        .expect("the scene");
    let measured = floor(&scene(&text)) / floor(&scene(open));
    // The closed form, averaged over the spectrum as the renderer draws it.
    let dispersion = Dispersion::abbe(ior, abbe);
    let m = 200_000;
    let expected = (0..m)
        .map(|i| {
            let s = sample_wavelength((i as f64 + 0.5) / m as f64);
            let r = ((dispersion.ior(ior, s.nm) - 1.0) / (dispersion.ior(ior, s.nm) + 1.0)).powi(2);
            s.weight * (1.0 - r) / (1.0 + r)
        })
        .sum::<DVec3>()
        / m as f64;
    eprintln!("slab: per channel {measured}, closed form {expected}");
    let error = (measured / expected - DVec3::ONE).abs().max_element();
    assert!(error < 0.003, "per channel {measured}, expected {expected}");
    let tint = measured / measured.y;
    assert!(
        (tint - DVec3::ONE).abs().max_element() < 0.01,
        "white light came out tinted {tint}"
    );
}
