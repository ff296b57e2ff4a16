//! Linking a light vertex to the camera (light tracing): a point of the lens, the pixel whose
//! eye rays from that point pass through the vertex, and the density with which an eye ray of
//! that pixel samples the vertex's direction.
//!
//! An eye ray's position in its pixel is uniform over the pixel, its lens point uniform over
//! the lens ([`crate::scene::camera::EyeRays::ray`]). Through the thin lens a pixel of side
//! `s` (at unit distance from the lens, `s = 2 tan(fov/2) / height`) maps to a patch of the
//! plane in focus, and the solid angle of that patch from any lens point is
//! `s² cos³θ` per pixel area, θ the ray's angle to the view axis: so the eye ray's direction
//! has density `1 / (s² cos³θ)` per pixel, the same for a pinhole (pbrt-v4's
//! `PerspectiveCamera::PDF_We` with the lens's density left out: light tracing picks the lens
//! point with the eye rays' own density, and the two cancel).

use glam::{DVec2, DVec3};

use crate::scene::camera::{concentric_disk, Camera};

/// A light vertex seen from a lens point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CameraLink {
    /// The pixel (row-major index) whose eye rays pass through the vertex.
    pub pixel: usize,
    /// The lens point.
    pub lens: DVec3,
    /// Unit direction from the vertex to the lens point.
    pub to_camera: DVec3,
    /// Distance from the vertex to the lens point.
    pub distance: f64,
    /// The density per solid angle with which one of the pixel's eye rays takes this
    /// direction.
    pub pdf_w: f64,
}

/// The eye rays' direction density per pixel at angle θ to the view axis (`cos = cos θ`).
pub fn eye_ray_pdf(camera: &Camera, cos: f64) -> f64 {
    let s = 2.0 * (0.5 * camera.fov_y).tan() / camera.height as f64;
    1.0 / (s * s * cos * cos * cos)
}

/// Links `point` to the lens point that `u` (two uniform numbers) picks. `None` when the
/// point is behind the lens or the near plane, or outside the image.
pub fn link(camera: &Camera, point: DVec3, u: DVec2) -> Option<CameraLink> {
    let lens = if camera.aperture > 0.0 {
        let d = concentric_disk(u) * camera.aperture;
        camera.position + d.x * camera.right + d.y * camera.up
    } else {
        camera.position
    };
    let v = point - lens;
    let z = v.dot(camera.forward);
    if z <= camera.near.max(0.0) || !z.is_finite() {
        return None;
    }
    // Where the ray from the lens point through the vertex meets the plane in focus, seen from
    // the lens's centre: the pixel whose rays converge there.
    let through = if camera.aperture > 0.0 {
        lens + v * (camera.focal_distance / z)
    } else {
        point
    };
    let raster = camera.project(through)?;
    let (w, h) = (camera.width as f64, camera.height as f64);
    if !(raster.x >= 0.0 && raster.x < w && raster.y >= 0.0 && raster.y < h) {
        return None;
    }
    let distance = v.length();
    let cos = z / distance;
    Some(CameraLink {
        pixel: raster.y as usize * camera.width as usize + raster.x as usize,
        lens,
        to_camera: -v / distance,
        distance,
        pdf_w: eye_ray_pdf(camera, cos),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn camera(aperture: f64) -> Camera {
        Camera::look_at(
            DVec3::new(0.0, 0.0, 5.0),
            DVec3::ZERO,
            DVec3::Y,
            40.0,
            64,
            48,
            aperture,
            Some(5.0),
        )
    }

    /// The pixel found is the one whose eye ray from the same lens point passes through the
    /// point, for a pinhole and a thin lens.
    #[test]
    fn the_link_finds_the_pixel_of_the_eye_ray_through_the_point() {
        for aperture in [0.0, 0.3] {
            let camera = camera(aperture);
            let rays = camera.eye_rays();
            let pixel = DVec2::new(17.3, 30.8);
            let lens_u = DVec2::new(0.3, 0.8);
            let ray = rays.ray_with_lens_sample(pixel, lens_u);
            let point = ray.origin + ray.dir * 3.7;
            let l = link(&camera, point, lens_u).expect("in view");
            assert_eq!(l.pixel, 30 * 64 + 17, "aperture {aperture}");
            assert!((l.lens - ray.origin).length() < 1e-12);
            assert!((l.to_camera + ray.dir).length() < 1e-12);
        }
    }

    /// The density integrates to 1 over a pixel: the solid angle of the pixel's directions
    /// times the density, measured by the directions of its corners.
    #[test]
    fn the_eye_ray_density_is_one_over_the_pixels_solid_angle() {
        let camera = camera(0.0);
        let rays = camera.eye_rays();
        let corner = |x: f64, y: f64| rays.direction(DVec2::new(x, y)).normalize();
        let (x, y) = (5.0, 7.0);
        let (a, b, c) = (corner(x, y), corner(x + 1.0, y), corner(x, y + 1.0));
        let d = corner(x + 1.0, y + 1.0);
        // Two spherical triangles (Van Oosterom & Strackee).
        let tri = |p: DVec3, q: DVec3, r: DVec3| {
            2.0 * (p.dot(q.cross(r)))
                .abs()
                .atan2(1.0 + p.dot(q) + q.dot(r) + r.dot(p))
        };
        let solid = tri(a, b, d) + tri(a, d, c);
        let centre = rays.direction(DVec2::new(x + 0.5, y + 0.5)).normalize();
        let pdf = eye_ray_pdf(&camera, centre.dot(camera.forward));
        assert!((pdf * solid - 1.0).abs() < 1e-3, "{}", pdf * solid);
    }
}
