//! Markers at the edge of the image view for lights outside it: a light whose gizmo cannot be
//! seen still says where it is, so that a person knows which way to turn or dolly to reach
//! it. Drawn with egui's painter over the image while the overlay is shown.

use egui::{Color32, Pos2, Shape, Stroke, Vec2};

use super::handle::light_place;
use super::overlay::OverlayProjection;
use crate::scene::Light;

/// How far inside the view's edge a marker's tip sits (points).
const MARGIN: f32 = 12.0;

/// The marker of one light outside the view.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EdgeMarker {
    /// The light (scene order).
    pub light: usize,
    /// Where the marker's tip is: on the view's edge, 12 points inside it.
    pub at: Pos2,
    /// The unit direction on screen from the view's centre towards the light.
    pub toward: Vec2,
}

/// A marker for each light whose place is outside `proj`'s view or behind the eye. A light
/// behind the eye is pointed at by its offset across the view (right and up of the camera).
pub fn edge_markers(proj: &OverlayProjection, lights: &[Light]) -> Vec<EdgeMarker> {
    let view = proj.view;
    let centre = view.center();
    let inner = view.shrink(MARGIN);
    lights
        .iter()
        .enumerate()
        .filter_map(|(light, l)| {
            let place = light_place(l);
            let d = match proj.to_screen(place) {
                Some(s) if view.contains(s) => return None,
                Some(s) => s - centre,
                None => {
                    let c = &proj.camera;
                    let v = place - c.position;
                    Vec2::new(v.dot(c.right) as f32, -v.dot(c.up) as f32)
                }
            };
            let length = d.length();
            if !(length.is_finite() && length > 1e-6) || inner.width() <= 0.0 || inner.height() <= 0.0 {
                return None;
            }
            let toward = d / length;
            // Along `toward` from the centre to the inner rectangle's edge.
            let half = inner.size() * 0.5;
            let reach = |h: f32, c: f32| {
                if c.abs() > 1e-6 {
                    h / c.abs()
                } else {
                    f32::INFINITY
                }
            };
            let t = reach(half.x, toward.x).min(reach(half.y, toward.y));
            Some(EdgeMarker {
                light,
                at: centre + toward * t,
                toward,
            })
        })
        .collect()
}

/// Paints `markers` (arrowheads in the lights' gizmo colour, outlined so that they show on
/// any background).
pub fn paint(painter: &egui::Painter, markers: &[EdgeMarker]) {
    let fill = Color32::from_rgb(255, 217, 89);
    let outline = Stroke::new(1.5, Color32::from_black_alpha(220));
    for m in markers {
        let side = Vec2::new(-m.toward.y, m.toward.x);
        let tip = m.at;
        let back = tip - m.toward * 14.0;
        let points = vec![tip, back + side * 7.0, back - side * 7.0];
        painter.add(Shape::convex_polygon(points, fill, outline));
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use egui::Rect;
    use glam::DVec3;

    fn projection() -> OverlayProjection {
        let camera = crate::scene::Camera::look_at(
            DVec3::new(0.0, 0.0, 10.0),
            DVec3::ZERO,
            DVec3::Y,
            40.0,
            800,
            600,
            0.0,
            None,
        );
        let view = Rect::from_min_size(Pos2::new(0.0, 20.0), egui::vec2(800.0, 600.0));
        let image = Rect::from_center_size(view.center(), egui::vec2(800.0, 600.0));
        OverlayProjection::new(&camera, image, view)
    }

    fn point(x: f64, y: f64, z: f64) -> Light {
        Light::Point {
            position: DVec3::new(x, y, z),
            intensity: DVec3::ONE,
        }
    }

    #[test]
    fn lights_outside_the_view_get_a_marker_on_its_edge_pointing_at_them() {
        let proj = projection();
        let view = proj.view;
        let lights = [
            point(0.0, 0.0, 0.0),
            point(100.0, 0.0, 0.0),
            point(0.0, 50.0, 0.0),
            point(-3.0, 0.0, 20.0),
        ];
        let markers = edge_markers(&proj, &lights);
        // The light at the centre is in view; the others are not.
        assert_eq!(markers.iter().map(|m| m.light).collect::<Vec<_>>(), [1, 2, 3]);
        // Far right: on the right edge, pointing right.
        assert!(
            (markers[0].at.x - (view.right() - MARGIN)).abs() < 0.5,
            "{markers:?}"
        );
        assert!((markers[0].at.y - view.center().y).abs() < 0.5 && markers[0].toward.x > 0.99);
        // Far up: on the top edge, pointing up (screen y down).
        assert!((markers[1].at.y - (view.top() + MARGIN)).abs() < 0.5 && markers[1].toward.y < -0.99);
        // Behind the eye, to the left: on the left edge.
        assert!((markers[2].at.x - (view.left() + MARGIN)).abs() < 0.5 && markers[2].toward.x < -0.99);
        for m in &markers {
            assert!(view.contains(m.at));
        }
    }
}
