//! The thin-lens camera (Kolb et al. 1995; pbrt-v4 `PerspectiveCamera`): rays leave a disk of
//! radius `aperture` and converge on the plane at `focal_distance`, so points on that plane are
//! sharp and others blur — the seed report's depth of field (§3.1.1).

use glam::{DVec2, DVec3};

use crate::geometry::Ray;

/// A thin-lens perspective camera.
#[derive(Clone, Debug, PartialEq)]
pub struct Camera {
    /// Eye (lens centre).
    pub position: DVec3,
    /// Unit view direction.
    pub forward: DVec3,
    /// Unit right vector of the image plane.
    pub right: DVec3,
    /// Unit up vector of the image plane.
    pub up: DVec3,
    /// Vertical field of view in radians.
    pub fov_y: f64,
    /// Lens radius (0 = pinhole).
    pub aperture: f64,
    /// Distance of the plane in focus along the view axis.
    pub focal_distance: f64,
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// Eye rays start on the plane this far along the view axis.
    pub near: f64,
}

impl Camera {
    /// A camera at `position` looking at `look_at`; `up` need not be orthogonal to the view.
    #[allow(clippy::too_many_arguments)]
    pub fn look_at(
        position: DVec3,
        look_at: DVec3,
        up: DVec3,
        fov_y_degrees: f64,
        width: u32,
        height: u32,
        aperture: f64,
        focal_distance: Option<f64>,
    ) -> Self {
        let forward = (look_at - position).normalize();
        let right = forward.cross(up).normalize();
        let up = right.cross(forward);
        Self {
            position,
            forward,
            right,
            up,
            fov_y: fov_y_degrees.to_radians(),
            aperture,
            focal_distance: focal_distance.unwrap_or_else(|| (look_at - position).dot(forward)),
            width,
            height,
            near: 0.0,
        }
    }

    /// Sets the image size: both sides as given, or one side and the other following the
    /// current aspect (the field of view is vertical, so changing the width alone would widen
    /// or narrow the view instead of scaling the image).
    pub fn resize(&mut self, width: Option<u32>, height: Option<u32>) {
        let (w, h) = (self.width as f64, self.height as f64);
        match (width, height) {
            (Some(width), Some(height)) => (self.width, self.height) = (width, height),
            (Some(width), None) => {
                self.height = ((width as f64 * (h / w)).round() as u32).max(1);
                self.width = width;
            }
            (None, Some(height)) => {
                self.width = ((height as f64 * (w / h)).round() as u32).max(1);
                self.height = height;
            }
            (None, None) => {}
        }
    }

    /// The constants of this camera's eye rays, to compute once for many rays.
    pub fn eye_rays(&self) -> EyeRays<'_> {
        EyeRays {
            camera: self,
            half_height: (0.5 * self.fov_y).tan(),
            aspect: self.width as f64 / self.height as f64,
        }
    }

    /// The un-normalised direction through image position `pixel` (in pixels, `(0,0)` the top
    /// left corner of the image) with unit component along `forward`.
    pub fn pinhole_direction(&self, pixel: DVec2) -> DVec3 {
        self.eye_rays().direction(pixel)
    }

    /// The eye ray through image position `pixel`, leaving the lens at `lens` (a point of the
    /// unit disk, scaled by the aperture). Many rays: [`Camera::eye_rays`].
    pub fn ray(&self, pixel: DVec2, lens: DVec2) -> Ray {
        self.eye_rays().ray(pixel, lens)
    }

    /// The pixel `(x, y)` (fractional) where the world point `p` projects, if in front.
    pub fn project(&self, p: DVec3) -> Option<DVec2> {
        let v = p - self.position;
        let z = v.dot(self.forward);
        if z <= 0.0 {
            return None;
        }
        let EyeRays {
            half_height: h,
            aspect,
            ..
        } = self.eye_rays();
        let sx = v.dot(self.right) / z / (h * aspect);
        let sy = v.dot(self.up) / z / h;
        Some(DVec2::new(
            (sx + 1.0) * 0.5 * self.width as f64,
            (1.0 - sy) * 0.5 * self.height as f64,
        ))
    }
}

/// A camera's eye rays with the constants they share computed once (per pass), as pbrt-v4's
/// cameras precompute their transforms: the same rays, bit for bit, as [`Camera::ray`].
#[derive(Clone, Copy, Debug)]
pub struct EyeRays<'a> {
    camera: &'a Camera,
    /// Half the image plane's height at unit distance.
    half_height: f64,
    /// Width over height.
    aspect: f64,
}

impl EyeRays<'_> {
    /// The un-normalised direction through image position `pixel` with unit component along
    /// the view axis.
    pub fn direction(&self, pixel: DVec2) -> DVec3 {
        let (c, h) = (self.camera, self.half_height);
        let sx = (2.0 * pixel.x / c.width as f64 - 1.0) * h * self.aspect;
        let sy = (1.0 - 2.0 * pixel.y / c.height as f64) * h;
        c.forward + sx * c.right + sy * c.up
    }

    /// The eye ray through image position `pixel`, leaving the lens at `lens` (a point of the
    /// unit disk, scaled by the aperture).
    pub fn ray(&self, pixel: DVec2, lens: DVec2) -> Ray {
        let c = self.camera;
        let d = self.direction(pixel);
        let (origin, dir) = if c.aperture > 0.0 {
            let focus = c.position + d * c.focal_distance;
            let origin = c.position + c.aperture * (lens.x * c.right + lens.y * c.up);
            (origin, focus - origin)
        } else {
            (c.position, d)
        };
        let dir = dir.normalize();
        // Start on the near plane (measured along the view axis, like smallppm's clip).
        let start = c.near / dir.dot(c.forward).max(1e-12);
        Ray::new(origin + start * dir, dir)
    }

    /// [`EyeRays::ray`] leaving the lens where [`concentric_disk`] maps `u`, a point of the
    /// unit square. A pinhole camera needs no lens point, and skips the mapping's sine and
    /// cosine (1.5 % of a glass-teapot render's samples, `perf`).
    pub fn ray_with_lens_sample(&self, pixel: DVec2, u: DVec2) -> Ray {
        let lens = if self.camera.aperture > 0.0 {
            concentric_disk(u)
        } else {
            DVec2::ZERO
        };
        self.ray(pixel, lens)
    }
}

/// A uniformly distributed point on the unit disk from two uniform numbers (Shirley & Chiu's
/// concentric mapping, which keeps stratification).
pub fn concentric_disk(u: DVec2) -> DVec2 {
    let o = 2.0 * u - DVec2::ONE;
    if o == DVec2::ZERO {
        return DVec2::ZERO;
    }
    let (r, theta) = if o.x.abs() > o.y.abs() {
        (o.x, std::f64::consts::FRAC_PI_4 * (o.y / o.x))
    } else {
        (
            o.y,
            std::f64::consts::FRAC_PI_2 - std::f64::consts::FRAC_PI_4 * (o.x / o.y),
        )
    };
    r * DVec2::new(theta.cos(), theta.sin())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn resize_keeps_the_aspect_when_one_side_is_given() {
        let base = Camera::look_at(DVec3::Z, DVec3::ZERO, DVec3::Y, 40.0, 1024, 768, 0.0, None);
        let sized = |w, h| {
            let mut c = base.clone();
            c.resize(w, h);
            (c.width, c.height)
        };
        assert_eq!(sized(Some(320), None), (320, 240));
        assert_eq!(sized(None, Some(60)), (80, 60));
        assert_eq!(sized(Some(10), Some(10)), (10, 10));
        assert_eq!(sized(None, None), (1024, 768));
        assert_eq!(sized(Some(1), None), (1, 1), "never a zero side");
    }

    #[test]
    fn projection_inverts_the_pinhole_ray() {
        let cam = Camera::look_at(
            DVec3::new(1.0, 2.0, 3.0),
            DVec3::ZERO,
            DVec3::Y,
            50.0,
            320,
            200,
            0.0,
            None,
        );
        let px = DVec2::new(37.25, 151.5);
        let ray = cam.ray(px, DVec2::ZERO);
        let back = cam.project(ray.at(5.0)).expect("in front");
        assert!((back - px).length() < 1e-9);
    }

    #[test]
    fn lens_rays_meet_on_the_focal_plane() {
        let cam = Camera::look_at(DVec3::ZERO, DVec3::Z, DVec3::Y, 40.0, 100, 100, 0.5, Some(7.0));
        let px = DVec2::new(20.0, 70.0);
        let a = cam.ray(px, DVec2::new(0.9, 0.1));
        let b = cam.ray(px, DVec2::new(-0.3, -0.8));
        let on_plane = |r: &Ray| r.at((7.0 - r.origin.z) / r.dir.z);
        assert!((on_plane(&a) - on_plane(&b)).length() < 1e-12);
    }
}
