//! Where the control-net overlay goes on screen and what it shows: the render camera's
//! projection composed with the image's place in the view (so the net lies on the rendered
//! surfaces at any zoom and pan), picking, and the overlay's geometry with hover and
//! selection highlighted. The wgpu side is [`crate::gpu::wireframe`].

use std::collections::BTreeSet;

use egui::{Pos2, Rect};
use glam::{DMat4, DVec2, DVec3, DVec4};

use crate::geometry::rational::{RationalPatch, Weights};
use crate::geometry::trim::TrimRegion;
use crate::geometry::{BezierPatch, Window};
use crate::gpu::wireframe::{Marker, Segment, Uniforms, WireframeGeometry};
use crate::scene::{Camera, Light};

pub use super::handle::{Handle, LightPart, LightRef, NetRef, PointRef};

/// A handle is picked when the cursor is this close (points).
pub const PICK_RADIUS: f32 = 8.0;
/// Samples per patch boundary curve.
const CURVE_SEGMENTS: usize = 16;
/// Samples per trim curve segment.
const TRIM_SEGMENTS: usize = 24;

/// The camera's projection into the view: `clip_from_world` maps a world point to the clip
/// space of `view` (the paint callback's viewport), with the image occupying `image`.
#[derive(Clone, Debug, PartialEq)]
pub struct OverlayProjection {
    /// The render camera.
    pub camera: Camera,
    /// Where the image is drawn (points; may extend past the view when zoomed in).
    pub image: Rect,
    /// The view the overlay is painted in (points).
    pub view: Rect,
    /// Clip space of `view` from world space.
    pub clip_from_world: DMat4,
}

impl OverlayProjection {
    /// The projection of `camera`'s image drawn at `image` inside `view`.
    pub fn new(camera: &Camera, image: Rect, view: Rect) -> Self {
        let c = camera;
        let h = (0.5 * c.fov_y).tan();
        let aspect = c.width as f64 / c.height as f64;
        // Camera space: x right, y up, w the depth along the view axis (as Camera::project).
        let rows = [
            (c.right / (h * aspect)).extend(-c.position.dot(c.right) / (h * aspect)),
            (c.up / h).extend(-c.position.dot(c.up) / h),
            DVec4::ZERO,
            c.forward.extend(-c.position.dot(c.forward)),
        ];
        let image_ndc_from_world = DMat4::from_cols(rows[0], rows[1], rows[2], rows[3]).transpose();
        // The image's NDC square mapped into the view's NDC square.
        let (ic, vc) = (image.center(), view.center());
        let sx = (image.width() / view.width()) as f64;
        let sy = (image.height() / view.height()) as f64;
        let tx = ((ic.x - vc.x) / (0.5 * view.width())) as f64;
        let ty = -((ic.y - vc.y) / (0.5 * view.height())) as f64;
        let view_from_image = DMat4::from_cols(
            DVec4::new(sx, 0.0, 0.0, 0.0),
            DVec4::new(0.0, sy, 0.0, 0.0),
            DVec4::new(0.0, 0.0, 1.0, 0.0),
            DVec4::new(tx, ty, 0.0, 1.0),
        );
        Self {
            camera: camera.clone(),
            image,
            view,
            clip_from_world: view_from_image * image_ndc_from_world,
        }
    }

    /// Where `p` appears in the view (points), computed as the GPU does (in `f32`, with the
    /// uniform's matrix); `None` behind the eye.
    pub fn to_screen(&self, p: DVec3) -> Option<Pos2> {
        let c = self.clip_from_world.as_mat4() * p.as_vec3().extend(1.0);
        if c.w <= 0.0 {
            return None;
        }
        let v = self.view;
        Some(Pos2::new(
            v.center().x + c.x / c.w * 0.5 * v.width(),
            v.center().y - c.y / c.w * 0.5 * v.height(),
        ))
    }

    /// Image pixels per point.
    fn image_pixels_per_point(&self) -> f64 {
        self.camera.width as f64 / self.image.width() as f64
    }

    /// The image position (pixels) under screen point `s`.
    pub fn image_pixel(&self, s: Pos2) -> DVec2 {
        let local = s - self.image.min;
        DVec2::new(local.x as f64, local.y as f64) * self.image_pixels_per_point()
    }

    /// The world point under screen point `s` at `depth` along the view axis (the inverse of
    /// [`OverlayProjection::to_screen`] on that plane).
    pub fn unproject(&self, s: Pos2, depth: f64) -> DVec3 {
        let c = &self.camera;
        c.position + c.pinhole_direction(self.image_pixel(s)) * depth
    }

    /// Depth of `p` along the view axis.
    pub fn depth(&self, p: DVec3) -> f64 {
        (p - self.camera.position).dot(self.camera.forward)
    }

    /// World length of one screen point at `depth`.
    pub fn world_per_point(&self, depth: f64) -> f64 {
        let c = &self.camera;
        2.0 * (0.5 * c.fov_y).tan() * depth / c.height as f64 * self.image_pixels_per_point()
    }

    /// The uniforms for the GPU; `ppp` is physical pixels per point.
    pub fn uniforms(&self, ppp: f32) -> Uniforms {
        let scale = self.camera.position.length().max(1.0);
        // Geometry nearer the eye than this (along the view axis) is cut off.
        Uniforms {
            clip_from_world: self.clip_from_world.as_mat4().to_cols_array_2d(),
            viewport_px: [self.view.width() * ppp, self.view.height() * ppp],
            near_w: (1e-5 * scale) as f32,
            pixels_per_point: ppp,
        }
    }
}

/// Every control point of `patches` with its position, patch by patch.
pub fn control_points<'a>(
    patches: impl IntoIterator<Item = &'a BezierPatch> + 'a,
) -> impl Iterator<Item = (PointRef, DVec3)> + 'a {
    patches.into_iter().enumerate().flat_map(|(patch, p)| {
        p.points
            .iter()
            .enumerate()
            .map(move |(index, q)| (PointRef { patch, index }, *q))
    })
}

fn f32x3(p: DVec3) -> [f32; 3] {
    p.as_vec3().to_array()
}

const NET: [f32; 4] = [0.55, 0.85, 1.0, 0.55];
const NET_SELECTED: [f32; 4] = [0.7, 0.95, 1.0, 0.95];
const BOUNDARY: [f32; 4] = [1.0, 0.62, 0.2, 0.85];
const TRIM: [f32; 4] = [1.0, 0.35, 0.85, 0.95];
const POINT: [f32; 4] = [0.92, 0.95, 1.0, 0.9];
const POINT_HOVERED: [f32; 4] = [1.0, 0.92, 0.2, 1.0];
const POINT_SELECTED: [f32; 4] = [1.0, 0.25, 0.45, 1.0];
const LIGHT: [f32; 4] = [1.0, 0.85, 0.35, 0.95];
/// Segments of a sphere light's outline circles.
const CIRCLE_SEGMENTS: usize = 32;

/// One patch as the overlay draws it: its control points, its weights when rational, its
/// surface's trim loops with the patch's window in that surface when trimmed, and whether it
/// was derived from a surface's own net (whose points, not the patch's, are then drawn and
/// grabbed).
#[derive(Clone, Copy, Debug)]
pub struct OverlayPatch<'a> {
    /// Control points.
    pub points: &'a BezierPatch,
    /// Weights, when rational.
    pub weights: Option<&'a Weights>,
    /// Trim loops and the patch's window in their surface.
    pub trim: Option<(&'a TrimRegion, Window)>,
    /// Derived from a net.
    pub in_net: bool,
}

impl<'a> OverlayPatch<'a> {
    /// A plain patch: polynomial, untrimmed, its own points the handles.
    pub fn plain(points: &'a BezierPatch) -> Self {
        Self {
            points,
            weights: None,
            trim: None,
            in_net: false,
        }
    }
}

/// The overlay for `patches`, the surfaces' own `nets` (points, `u` fastest, and how many
/// along `u`) and `lights` (each with its aim point): each control net (rows and columns),
/// each patch's four boundary curves and the part of its surface's trim curves that lies on
/// it, a marker per handle, and the lights' gizmos (`light_gizmos`); hovered and selected
/// handles, and the nets with a selected point, stand out.
pub fn overlay_geometry<'a>(
    patches: impl IntoIterator<Item = OverlayPatch<'a>>,
    nets: &[(&[DVec3], usize)],
    lights: &[(Light, DVec3)],
    hovered: Option<Handle>,
    selection: &BTreeSet<Handle>,
) -> WireframeGeometry {
    let mut g = WireframeGeometry::default();
    for (k, o) in patches.into_iter().enumerate() {
        patch_overlay(&mut g, k, o, hovered, selection);
    }
    for (n, &(points, nu)) in nets.iter().enumerate() {
        net_overlay(&mut g, n, (points, nu), hovered, selection);
    }
    for (k, (light, aim)) in lights.iter().enumerate() {
        light_gizmos(&mut g, k, light, *aim, hovered, selection);
    }
    g
}

fn segment(a: DVec3, b: DVec3, color: [f32; 4], width: f32) -> Segment {
    Segment {
        a: f32x3(a),
        b: f32x3(b),
        color,
        width,
    }
}

/// Patch `k`'s part of the overlay: its boundary curves and trim curves, and unless it came
/// from a net, its control net and points.
fn patch_overlay(
    g: &mut WireframeGeometry,
    k: usize,
    o: OverlayPatch,
    hovered: Option<Handle>,
    selection: &BTreeSet<Handle>,
) {
    let p = o.points;
    let rational = o.weights.map(|w| RationalPatch::new(p, w));
    let eval = |u: f64, v: f64| rational.as_ref().map_or_else(|| p.eval(u, v), |r| r.eval(u, v));
    if !o.in_net {
        let active =
            selection.iter().any(|s| s.patch() == Some(k)) || hovered.is_some_and(|h| h.patch() == Some(k));
        let (net, width) = if active { (NET_SELECTED, 1.6) } else { (NET, 1.0) };
        for i in 0..4 {
            for j in 0..3 {
                g.segments
                    .push(segment(p.point(i, j), p.point(i, j + 1), net, width));
                g.segments
                    .push(segment(p.point(j, i), p.point(j + 1, i), net, width));
            }
        }
        for (index, q) in p.points.iter().enumerate() {
            let r = Handle::Control(PointRef { patch: k, index });
            push_handle_marker(&mut g.markers, *q, r, (POINT, 5.0), hovered, selection);
        }
    }
    for edge in 0..4 {
        let at = |t: f64| match edge {
            0 => eval(t, 0.0),
            1 => eval(t, 1.0),
            2 => eval(0.0, t),
            _ => eval(1.0, t),
        };
        for s in 0..CURVE_SEGMENTS {
            let (t0, t1) = (
                s as f64 / CURVE_SEGMENTS as f64,
                (s + 1) as f64 / CURVE_SEGMENTS as f64,
            );
            g.segments.push(segment(at(t0), at(t1), BOUNDARY, 1.5));
        }
    }
    if let Some((region, window)) = o.trim {
        for (a, b) in trim_pieces(region, &window) {
            g.segments
                .push(segment(eval(a.x, a.y), eval(b.x, b.y), TRIM, 2.0));
        }
    }
}

/// Net `n`'s part of the overlay: its rows and columns of points, and a marker per point.
fn net_overlay(
    g: &mut WireframeGeometry,
    n: usize,
    (points, nu): (&[DVec3], usize),
    hovered: Option<Handle>,
    selection: &BTreeSet<Handle>,
) {
    let mine = |h: &Handle| matches!(h, Handle::Net(r) if r.net == n);
    let active = selection.iter().any(mine) || hovered.as_ref().is_some_and(mine);
    let (color, width) = if active { (NET_SELECTED, 1.6) } else { (NET, 1.0) };
    let nu = nu.max(1);
    for (index, q) in points.iter().enumerate() {
        if index % nu + 1 < nu {
            g.segments.push(segment(*q, points[index + 1], color, width));
        }
        if let Some(next) = points.get(index + nu) {
            g.segments.push(segment(*q, *next, color, width));
        }
        let r = Handle::Net(NetRef { net: n, index });
        push_handle_marker(&mut g.markers, *q, r, (POINT, 5.0), hovered, selection);
    }
}

/// The pieces of `region`'s trim curves (sampled) that lie on the patch whose window in the
/// surface is `window`, in the patch's `[0,1]²`: each piece whose middle lies on the patch,
/// its ends kept on it (the neighbouring patch draws the rest of a piece that crosses over).
fn trim_pieces(region: &TrimRegion, window: &Window) -> Vec<(DVec2, DVec2)> {
    let local = |q: DVec2| {
        DVec2::new(
            (q.x - window.u0) / (window.u1 - window.u0),
            (q.y - window.v0) / (window.v1 - window.v0),
        )
    };
    let on = |q: DVec2| (0.0..=1.0).contains(&q.x) && (0.0..=1.0).contains(&q.y);
    let mut pieces = Vec::new();
    for (points, _) in region.polylines(TRIM_SEGMENTS) {
        for pair in points.windows(2) {
            let (a, b) = (local(pair[0]), local(pair[1]));
            if on(0.5 * (a + b)) {
                pieces.push((a.clamp(DVec2::ZERO, DVec2::ONE), b.clamp(DVec2::ZERO, DVec2::ONE)));
            }
        }
    }
    pieces
}

/// The dark rim around a hovered or selected handle's marker (points each side), so that it
/// stands out on any background: a bright floor as well as a dark wall.
const HALO: f32 = 2.0;
const HALO_COLOR: [f32; 4] = [0.0, 0.0, 0.0, 0.85];

/// Pushes a handle's marker: hovered and selected ones larger, in their colours, over a dark
/// halo.
fn push_handle_marker(
    markers: &mut Vec<Marker>,
    q: DVec3,
    h: Handle,
    (color, size): ([f32; 4], f32),
    hovered: Option<Handle>,
    selection: &BTreeSet<Handle>,
) {
    let (color, size, halo) = if selection.contains(&h) {
        (POINT_SELECTED, size + 4.0, true)
    } else if hovered == Some(h) {
        (POINT_HOVERED, size + 5.0, true)
    } else {
        (color, size, false)
    };
    if halo {
        markers.push(Marker {
            position: f32x3(q),
            color: HALO_COLOR,
            size: size + 2.0 * HALO,
        });
    }
    markers.push(Marker {
        position: f32x3(q),
        color,
        size,
    });
}

/// Light `k`'s gizmo: a marker at its place (position or centre), and its shape: a spot's
/// axis to its aim point (a second handle), a quad's outline, a sphere's three great circles.
fn light_gizmos(
    g: &mut WireframeGeometry,
    k: usize,
    light: &Light,
    aim: DVec3,
    hovered: Option<Handle>,
    selection: &BTreeSet<Handle>,
) {
    let handle = |part| Handle::Light(LightRef { light: k, part });
    let active = [LightPart::Place, LightPart::Aim]
        .iter()
        .any(|p| selection.contains(&handle(*p)) || hovered == Some(handle(*p)));
    let width = if active { 2.0 } else { 1.3 };
    let mut line = |a: DVec3, b: DVec3| {
        g.segments.push(Segment {
            a: f32x3(a),
            b: f32x3(b),
            color: LIGHT,
            width,
        })
    };
    let place = super::handle::light_place(light);
    match *light {
        Light::Point { .. } => {}
        Light::Spot { .. } => line(place, aim),
        Light::Quad {
            corner,
            edge_u,
            edge_v,
            ..
        } => {
            let c = [corner, corner + edge_u, corner + edge_u + edge_v, corner + edge_v];
            for i in 0..4 {
                line(c[i], c[(i + 1) % 4]);
            }
        }
        Light::Sphere { center, radius, .. } => {
            for (a, b) in [(DVec3::X, DVec3::Y), (DVec3::Y, DVec3::Z), (DVec3::Z, DVec3::X)] {
                let at = |s: usize| {
                    let t = std::f64::consts::TAU * s as f64 / CIRCLE_SEGMENTS as f64;
                    center + radius * (t.cos() * a + t.sin() * b)
                };
                for s in 0..CIRCLE_SEGMENTS {
                    line(at(s), at(s + 1));
                }
            }
        }
    }
    push_handle_marker(
        &mut g.markers,
        place,
        handle(LightPart::Place),
        (LIGHT, 9.0),
        hovered,
        selection,
    );
    if matches!(light, Light::Spot { .. }) {
        push_handle_marker(
            &mut g.markers,
            aim,
            handle(LightPart::Aim),
            (LIGHT, 6.0),
            hovered,
            selection,
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn overlay_projection_agrees_with_the_camera_at_any_zoom_and_pan() {
        let scene = crate::scene::Scene::builtin();
        let cam = &scene.camera;
        let view = Rect::from_min_size(Pos2::new(10.0, 30.0), egui::vec2(800.0, 600.0));
        let (w, h) = (cam.width as f32, cam.height as f32);
        // Fit, 2× zoom panned off-centre (partly outside the view), and a small image.
        let images = [
            Rect::from_center_size(view.center(), egui::vec2(w, h) * 1.25),
            Rect::from_center_size(view.center() + egui::vec2(-300.0, 170.0), egui::vec2(w, h) * 2.0),
            Rect::from_min_size(Pos2::new(40.0, 50.0), egui::vec2(w, h) * 0.3),
        ];
        for image in images {
            let proj = OverlayProjection::new(cam, image, view);
            let scale = image.width() / w;
            for (p, _) in scene.geometry.patches() {
                for q in p.points {
                    let px = cam.project(q).expect("in front");
                    let expected = image.min + egui::vec2(px.x as f32, px.y as f32) * scale;
                    let got = proj.to_screen(q).expect("in front");
                    assert!(got.distance(expected) < 0.5, "{got:?} vs {expected:?}");
                    // And the plane-parallel inverse returns the point.
                    let back = proj.unproject(got, proj.depth(q));
                    assert!((back - q).length() < 1e-3, "{back} vs {q}");
                }
            }
        }
    }

    #[test]
    fn selected_and_hovered_handles_sit_on_a_dark_halo() {
        let scene = crate::scene::Scene::builtin();
        let patches: Vec<BezierPatch> = scene.geometry.patches().iter().map(|(p, _)| *p).collect();
        let lights: Vec<(Light, DVec3)> = scene.lights.iter().map(|l| (*l, DVec3::ZERO)).collect();
        let light = Handle::Light(LightRef {
            light: 0,
            part: LightPart::Place,
        });
        let point = Handle::Control(PointRef { patch: 0, index: 5 });
        let plain = overlay_geometry(
            patches.iter().map(OverlayPatch::plain),
            &[],
            &lights,
            None,
            &BTreeSet::new(),
        );
        let chosen = overlay_geometry(
            patches.iter().map(OverlayPatch::plain),
            &[],
            &lights,
            Some(point),
            &BTreeSet::from([light]),
        );
        assert_eq!(chosen.markers.len(), plain.markers.len() + 2);
        for (marker, colour) in [
            (patches[0].points[5], POINT_HOVERED),
            (
                super::super::handle::light_place(&scene.lights[0]),
                POINT_SELECTED,
            ),
        ] {
            let at = chosen
                .markers
                .iter()
                .position(|m| m.position == f32x3(marker) && m.color == colour)
                .expect("the marker");
            let halo = &chosen.markers[at - 1];
            assert_eq!(
                (halo.position, halo.color),
                (chosen.markers[at].position, HALO_COLOR)
            );
            assert_eq!(halo.size, chosen.markers[at].size + 2.0 * HALO);
        }
    }

    /// A trimmed patch's overlay draws its trim curve on the surface (here a diamond on a flat
    /// patch whose `(u,v)` is its `(x,y)`), and a patch of the same surface the curve does not
    /// reach draws none of it.
    #[test]
    fn trim_curves_are_drawn_on_the_patches_they_cross() {
        use crate::geometry::trim::{line, TrimLoop};
        let flat = BezierPatch::new(std::array::from_fn(|k| {
            DVec3::new((k / 4) as f64 / 3.0, (k % 4) as f64 / 3.0, 0.0)
        }));
        let p = |x: f64, y: f64| DVec2::new(x, y);
        let corners = [p(0.5, 0.1), p(0.9, 0.5), p(0.5, 0.9), p(0.1, 0.5)];
        let diamond = TrimLoop {
            segments: (0..4).map(|k| line(corners[k], corners[(k + 1) % 4])).collect(),
            hole: false,
        };
        let region = TrimRegion::new(vec![diamond]);
        let beside = Window {
            u0: 1.0,
            u1: 2.0,
            ..Window::FULL
        };
        for (window, expected) in [(Window::FULL, 4 * TRIM_SEGMENTS), (beside, 0)] {
            let o = OverlayPatch {
                trim: Some((&region, window)),
                ..OverlayPatch::plain(&flat)
            };
            let g = overlay_geometry([o], &[], &[], None, &BTreeSet::new());
            let trims: Vec<&Segment> = g.segments.iter().filter(|s| s.color == TRIM).collect();
            assert_eq!(trims.len(), expected);
            for s in trims {
                for q in [s.a, s.b] {
                    let on_diamond = (q[0] - 0.5).abs() + (q[1] - 0.5).abs();
                    assert!((on_diamond - 0.4).abs() < 1e-5 && q[2] == 0.0, "{q:?}");
                }
            }
        }
    }

    /// A patch derived from a net draws no points of its own: the net's points and its rows and
    /// columns are drawn instead, and grabbed.
    #[test]
    fn a_net_is_drawn_in_place_of_its_patches_points() {
        let flat = BezierPatch::new(std::array::from_fn(|k| {
            DVec3::new((k / 4) as f64, (k % 4) as f64, 0.0)
        }));
        let points: Vec<DVec3> = (0..20)
            .map(|k| DVec3::new((k % 5) as f64, (k / 5) as f64, 1.0))
            .collect();
        let o = OverlayPatch {
            in_net: true,
            ..OverlayPatch::plain(&flat)
        };
        let g = overlay_geometry([o], &[(&points, 5)], &[], None, &BTreeSet::new());
        assert_eq!(g.markers.len(), 20);
        assert!(g.markers.iter().all(|m| m.position[2] == 1.0));
        let net_lines = g.segments.iter().filter(|s| s.color == NET).count();
        assert_eq!(net_lines, 4 * 4 + 5 * 3);
    }
}
