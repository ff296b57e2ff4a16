//! The diffuse plane lit by each light kind, and the closed forms of the light it reflects:
//! shared by the photon-mapping and path-tracing tests.

use std::f64::consts::PI;
use std::path::Path;

use caustic::scene::Scene;
use glam::{DVec2, DVec3};

/// A diffuse plane (ρ = 0.8, 0.6, 0.4) under a point light, seen from above.
pub const PLANE: &str = r#"
[camera]
position = [0.0, 5.0, 0.5]
look_at = [0, 0, 0]
up = [0, 0, 1]
fov = 30
width = 24
height = 18

[render]
antialias = false
photons_per_pass = 100000
alpha = 0.7
direct_light = false

[materials.floor]
type = "diffuse"
color = [0.8, 0.6, 0.4]

[[lights]]
type = "point"
position = [0.5, 3.0, 0.2]
power = 400

[[objects]]
type = "plane"
point = [0, 0, 0]
normal = [0, 1, 0]
material = "floor"
"#;

/// The plane scene lit by `light` (a `[[lights]]` table's body) instead of its point light,
/// with direct light by light sampling on or off.
pub fn plane_lit_by(light: &str, direct_light: bool) -> Scene {
    let text = PLANE
        .replace(
            "[[lights]]\ntype = \"point\"\nposition = [0.5, 3.0, 0.2]\npower = 400\n",
            &format!("[[lights]]\n{light}\n"),
        )
        .replace("direct_light = false", &format!("direct_light = {direct_light}"));
    assert!(text.contains(light), "the light was not replaced");
    Scene::from_str(&text, Path::new("plane_lit.toml"), None).expect("scene")
}

pub fn mean_red(image: &[[f32; 3]]) -> f64 {
    image.iter().map(|p| p[0] as f64).sum::<f64>() / image.len() as f64
}

/// Irradiance at `x` (normal `n`) from a uniformly emitting parallelogram of radiance `l`, by
/// Lambert's formula for polygons: `E = L/2 · Σ Θᵢ (n · Γᵢ)`.
pub fn quad_irradiance(x: DVec3, n: DVec3, corner: DVec3, eu: DVec3, ev: DVec3, l: DVec3) -> DVec3 {
    let vertices = [corner, corner + eu, corner + eu + ev, corner + ev];
    let mut sum = 0.0;
    for i in 0..4 {
        let a = (vertices[i] - x).normalize();
        let b = (vertices[(i + 1) % 4] - x).normalize();
        sum += a.dot(b).clamp(-1.0, 1.0).acos() * n.dot(a.cross(b).normalize());
    }
    l * 0.5 * sum.abs()
}

/// The closed form of the direct light the plane reflects to each pixel, from all its lights.
pub fn closed_form(scene: &Scene) -> Vec<DVec3> {
    use caustic::scene::light::spot_falloff;
    use caustic::scene::Light;
    let rho = DVec3::new(0.8, 0.6, 0.4);
    let n = DVec3::Y;
    let irradiance_from = |light: &Light, p: DVec3| -> DVec3 {
        let point_like = |position: DVec3, intensity: DVec3, falloff: f64| {
            let d = position - p;
            intensity * falloff * n.dot(d.normalize()) / d.length_squared()
        };
        match *light {
            Light::Point { position, intensity } => point_like(position, intensity, 1.0),
            // Seen whole from every receiver: a point light of equal power (I = L·πR²).
            Light::Sphere {
                center,
                radius,
                radiance,
            } => point_like(center, radiance * PI * radius * radius, 1.0),
            Light::Spot {
                position,
                direction,
                intensity,
                cos_inner,
                cos_outer,
            } => {
                let wi = (position - p).normalize();
                point_like(
                    position,
                    intensity,
                    spot_falloff(-wi.dot(direction), cos_inner, cos_outer),
                )
            }
            Light::Quad {
                corner,
                edge_u,
                edge_v,
                radiance,
            } => quad_irradiance(p, n, corner, edge_u, edge_v, radiance),
        }
    };
    let irradiance = |p: DVec3| -> DVec3 { scene.lights.iter().map(|l| irradiance_from(l, p)).sum() };
    let (w, h) = (scene.camera.width, scene.camera.height);
    (0..h)
        .flat_map(|y| (0..w).map(move |x| (x, y)))
        .map(|(x, y)| {
            let ray = scene.camera.ray(Scene::pixel_center(x, y), DVec2::ZERO);
            rho / PI * irradiance(ray.at(-ray.origin.y / ray.dir.y))
        })
        .collect()
}

/// Every light kind, out of the camera's view above the diffuse plane.
pub const LIGHT_KINDS: [(&str, &str); 4] = [
    ("point", "type = \"point\"\nposition = [2.0, 2.0, 0.0]\npower = 400"),
    (
        "spot",
        "type = \"spot\"\nposition = [2.0, 2.0, 0.0]\ndirection = [-1, -1, 0]\ncone_angle = 70\ncone_falloff = 20\npower = 400",
    ),
    (
        "sphere",
        "type = \"sphere\"\ncenter = [2.0, 2.0, 0.0]\nradius = 0.3\npower = 400",
    ),
    (
        "quad",
        "type = \"quad\"\ncorner = [1.7, 2.0, -0.3]\nedge_u = [0.6, 0, 0]\nedge_v = [0, 0, 0.6]\npower = 400",
    ),
];

/// The camera inside a diffuse sphere of radius 2 and reflectance `rho`, with `light` at its
/// centre.
pub fn integrating_sphere(light: &str, rho: f64) -> Scene {
    let text = format!(
        r#"
[camera]
position = [0, 0, 0.5]
look_at = [0, 0, 3]
fov = 60
width = 16
height = 12

[render]
max_depth = 64

[materials.wall]
type = "diffuse"
color = [{rho}, {rho}, {rho}]

[[lights]]
{light}

[[objects]]
type = "sphere"
center = [0, 0, 0]
radius = 2
material = "wall"
"#
    );
    Scene::from_str(&text, Path::new("furnace.toml"), None).expect("scene")
}

/// The furnace's closed form and what `render` makes of it, for a point light and a small
/// sphere light at the centre of the integrating sphere (ρ 0.5, Φ 100, R 2): in a diffuse
/// sphere of reflectance ρ with a source of power Φ at its centre, every bounce lights the
/// wall uniformly, so its radiance is ρΦ / (π · 4πR² · (1 − ρ)), half of it after the first
/// bounce. Asserts `render`'s image mean within 1 %.
pub fn assert_furnace(name: &str, render: impl Fn(&Scene) -> Vec<[f32; 3]>) {
    let (rho, power, radius) = (0.5, 100.0, 2.0);
    let expected = rho * power / (PI * 4.0 * PI * radius * radius * (1.0 - rho));
    for light in [
        "type = \"point\"\nposition = [0, 0, 0]\npower = 100",
        "type = \"sphere\"\ncenter = [0, 0, 0]\nradius = 0.05\npower = 100",
    ] {
        let got = mean_red(&render(&integrating_sphere(light, rho)));
        eprintln!("{light}: {name} {got:.5} against {expected:.5}");
        assert!(
            (got / expected - 1.0).abs() < 0.01,
            "{light}: {name} / closed form = {}",
            got / expected
        );
    }
}

/// Every light kind over the diffuse plane, with direct light by light sampling: `render`'s
/// image mean within 1 % of the closed form's.
pub fn assert_light_kinds(name: &str, render: impl Fn(&Scene) -> Vec<[f32; 3]>) {
    for (kind, light) in LIGHT_KINDS {
        let scene = plane_lit_by(light, true);
        let expected = closed_form(&scene);
        let expected_mean = expected.iter().map(|e| e.x).sum::<f64>() / expected.len() as f64;
        let got = mean_red(&render(&scene));
        eprintln!("{kind}: {name} {got:.5}, closed form {expected_mean:.5}");
        assert!(
            (got / expected_mean - 1.0).abs() < 0.01,
            "{kind}: {name} / closed form = {}",
            got / expected_mean
        );
    }
}
