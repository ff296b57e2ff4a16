//! The merging radius a render starts from when the scene does not set one: photon mapping's
//! rule ([`footprint_radius`]: twice the footprint of one pixel at the median distance of
//! what the camera sees), measured here on the first surfaces met by rays through a grid of
//! pixel centres.

use crate::render::ppm::footprint_radius;
use crate::scene::Scene;

/// Rays traced along each side of the grid, at most.
const GRID: u32 = 64;

/// The automatic initial radius of `scene` (1e-3 when the camera sees nothing).
pub fn automatic_radius(scene: &Scene) -> f64 {
    let camera = &scene.camera;
    let rays = camera.eye_rays();
    let (nx, ny) = (camera.width.min(GRID), camera.height.min(GRID));
    let mut distances = Vec::with_capacity((nx * ny) as usize);
    for j in 0..ny {
        for i in 0..nx {
            let pixel = glam::DVec2::new(
                (i as f64 + 0.5) * camera.width as f64 / nx as f64,
                (j as f64 + 0.5) * camera.height as f64 / ny as f64,
            );
            let ray = rays.ray(pixel, glam::DVec2::ZERO);
            if let Some(hit) = scene.geometry.intersect(&ray, f64::INFINITY) {
                distances.push((hit.point - camera.position).dot(camera.forward).abs());
            }
        }
    }
    footprint_radius(&mut distances, camera)
}
