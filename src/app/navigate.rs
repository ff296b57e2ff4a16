//! Camera moves made from the view: a turntable orbit about a pivot, panning parallel to the
//! image plane, dollying towards the pivot, and framing a sphere. Each returns a new camera;
//! the viewer sends it to the render session like any other camera change.

use glam::{DQuat, DVec3};

use crate::scene::Camera;

/// The coordinate axis (±x, ±y, ±z) nearest `up`: the turntable's vertical for a scene whose
/// camera is tilted a little off its world's up.
pub fn world_up(up: DVec3) -> DVec3 {
    let a = up.abs();
    let axis = if a.x >= a.y && a.x >= a.z {
        DVec3::X
    } else if a.y >= a.z {
        DVec3::Y
    } else {
        DVec3::Z
    };
    axis * up.dot(axis).signum()
}

/// `cam` moved to `position`, looking along `forward`, upright with respect to `up`.
fn placed(cam: &Camera, position: DVec3, forward: DVec3, up: DVec3) -> Camera {
    let forward = forward.normalize();
    let right = forward.cross(up);
    let right = if right.length_squared() > 1e-12 {
        right.normalize()
    } else {
        cam.right
    };
    Camera {
        position,
        forward,
        right,
        up: right.cross(forward),
        ..cam.clone()
    }
}

/// Orbits `cam` about `pivot`: `yaw` radians about `up`, then `pitch` radians about the
/// camera's right axis, stopping 2° short of looking straight along `up`.
pub fn orbit(cam: &Camera, pivot: DVec3, up: DVec3, yaw: f64, pitch: f64) -> Camera {
    let offset = cam.position - pivot;
    let yawed = DQuat::from_axis_angle(up, yaw) * offset;
    let elevation = (yawed.normalize().dot(up)).clamp(-1.0, 1.0).acos();
    let limit = 2f64.to_radians();
    let target = (elevation - pitch).clamp(limit, std::f64::consts::PI - limit);
    let right = up.cross(yawed);
    let offset = if right.length_squared() > 1e-12 {
        DQuat::from_axis_angle(right.normalize(), target - elevation) * yawed
    } else {
        yawed
    };
    placed(cam, pivot + offset, -offset, up)
}

/// Moves `cam` by `delta` without turning it.
pub fn pan(cam: &Camera, delta: DVec3) -> Camera {
    Camera {
        position: cam.position + delta,
        ..cam.clone()
    }
}

/// Moves `cam` towards (`factor` < 1) or away from `pivot`, keeping its direction; never
/// closer than a millionth of the distance it started at.
pub fn dolly(cam: &Camera, pivot: DVec3, factor: f64) -> Camera {
    let offset = cam.position - pivot;
    let factor = if factor.is_finite() { factor.max(1e-6) } else { 1.0 };
    Camera {
        position: pivot + offset * factor,
        ..cam.clone()
    }
}

/// `cam` turned towards `center` and moved so a sphere of `radius` there fills about 80 % of
/// the image's height.
pub fn frame(cam: &Camera, center: DVec3, radius: f64, up: DVec3) -> Camera {
    let radius = if radius.is_finite() && radius > 0.0 {
        radius
    } else {
        1.0
    };
    let distance = radius / (0.4 * cam.fov_y).sin();
    let dir = (center - cam.position).try_normalize().unwrap_or(cam.forward);
    placed(cam, center - dir * distance, dir, up)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn camera() -> Camera {
        Camera::look_at(
            DVec3::new(5.0, -7.5, 4.5),
            DVec3::new(0.2, 0.0, 1.3),
            DVec3::Z,
            40.0,
            64,
            48,
            0.0,
            None,
        )
    }

    #[test]
    fn orbit_keeps_the_pivot_in_view_and_the_distance() {
        let cam = camera();
        let pivot = cam.position + cam.forward * 9.0;
        let o = orbit(&cam, pivot, DVec3::Z, 0.7, -0.3);
        assert!(((o.position - pivot).length() - (cam.position - pivot).length()).abs() < 1e-9);
        assert!((o.forward - (pivot - o.position).normalize()).length() < 1e-12);
        assert!(o.right.dot(DVec3::Z).abs() < 1e-12, "camera rolled");
        // Pitching far past the pole stops short of it.
        let top = orbit(&cam, pivot, DVec3::Z, 0.0, 10.0);
        let down = top.forward.dot(-DVec3::Z);
        assert!(
            down > 0.99 && down < 1.0 - 1e-5 && top.forward.is_finite(),
            "{down}"
        );
        assert_eq!(world_up(DVec3::new(0.1, -0.2, 0.97)), DVec3::Z);
    }

    #[test]
    fn dolly_and_frame_move_along_the_view() {
        let cam = camera();
        let pivot = cam.position + cam.forward * 9.0;
        let d = dolly(&cam, pivot, 0.5);
        assert!(((d.position - pivot).length() - 4.5).abs() < 1e-9);
        let f = frame(&cam, DVec3::ZERO, 1.0, DVec3::Z);
        let px = f.project(DVec3::ZERO).expect("in front");
        assert!((px.x - 32.0).abs() < 1e-6 && (px.y - 24.0).abs() < 1e-6);
    }
}
