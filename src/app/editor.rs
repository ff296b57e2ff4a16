//! Shaping patches and placing lights by hand: the selection and hover of their handles
//! ([`Handle`]), the gesture in progress (dragging handles, or orbiting/panning/dollying the
//! camera), and the undo history (handles, the camera, materials). The control points and
//! lights themselves are the document's ([`Document`]): the editor keeps the state of editing
//! and does the geometry of a gesture; the viewer ([`super::Viewer::apply`]) carries actions
//! out and sends the document's changes to the render session.

use std::collections::BTreeSet;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Arc;

use egui::{Pos2, Vec2};
use glam::DVec3;

use super::document::{Change, Document};
use super::handle::{light_handles, light_place, Handle, LightPart, LightRef, NetRef};
use super::navigate;
use super::overlay::{overlay_geometry, OverlayPatch, OverlayProjection, PICK_RADIUS};
use crate::gpu::wireframe::WireframeGeometry;
use crate::scene::{Camera, Light, Material, Scene};

/// Radians of orbit per point dragged.
const ORBIT_PER_POINT: f64 = 0.008;
/// Dolly factor per point dragged: `exp(dy × DOLLY_PER_POINT)`.
const DOLLY_PER_POINT: f64 = 0.006;

/// What a camera drag does.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CameraMove {
    /// Turntable about the pivot (right mouse button).
    Orbit,
    /// Parallel to the image plane (middle button, or Shift + right).
    Pan,
    /// Towards or away from the pivot (Ctrl + right).
    Dolly,
}

/// A drag in progress.
#[derive(Clone, Debug, PartialEq)]
pub enum Gesture {
    /// Moving the selection by a grabbed handle.
    Points {
        /// The handle under the cursor when the drag began.
        grab: Handle,
        /// Where that point was on screen.
        grab_screen: Pos2,
        /// Where the button went down.
        press: Pos2,
        /// Every moved handle and where it started.
        start: Vec<(Handle, DVec3)>,
    },
    /// Moving the camera.
    Camera {
        /// How.
        how: CameraMove,
        /// The camera and pivot when the drag began.
        start: (Camera, DVec3),
    },
}

/// One undoable change.
// Edits are few (one per gesture): boxing the camera variant would buy nothing.
#[allow(clippy::large_enum_variant)]
#[derive(Clone, Debug, PartialEq)]
pub enum Edit {
    /// Control points and light handles: `(handle, before, after)`.
    Points(Vec<(Handle, DVec3, DVec3)>),
    /// The camera pose and orbit pivot.
    Camera {
        /// Before.
        before: (Camera, DVec3),
        /// After.
        after: (Camera, DVec3),
    },
    /// A material's colour or numbers.
    Material {
        /// Material index in the scene.
        index: usize,
        /// Before.
        before: Box<Material>,
        /// After.
        after: Box<Material>,
    },
}

impl Edit {
    /// The change that undoes this one.
    pub fn inverse(&self) -> Edit {
        match self {
            Edit::Points(moves) => Edit::Points(moves.iter().map(|(r, a, b)| (*r, *b, *a)).collect()),
            Edit::Camera { before, after } => Edit::Camera {
                before: after.clone(),
                after: before.clone(),
            },
            Edit::Material { index, before, after } => Edit::Material {
                index: *index,
                before: after.clone(),
                after: before.clone(),
            },
        }
    }
}

/// Undo and redo stacks; each entry carries an id so that "unsaved" is a comparison.
#[derive(Clone, Debug, Default)]
pub struct History {
    done: Vec<(u64, Edit)>,
    undone: Vec<(u64, Edit)>,
    /// The material and drag token of the last change made by a drag, if it was.
    drag: Option<(usize, u64)>,
    next_id: u64,
    saved: u64,
}

impl History {
    /// Records a new change (clearing what could be redone).
    pub fn record(&mut self, edit: Edit) {
        self.drag = None;
        self.next_id += 1;
        self.done.push((self.next_id, edit));
        self.undone.clear();
    }

    /// Records `edit`, a step of the drag `drag` (a token for one press of the mouse) if
    /// any: the steps of one drag that edit the same material are one change.
    pub fn record_in_drag(&mut self, edit: Edit, drag: Option<u64>) {
        let Edit::Material { index, after, .. } = &edit else {
            return self.record(edit);
        };
        let token = drag.map(|d| (*index, d));
        let same_drag = token.is_some() && token == self.drag && self.undone.is_empty();
        match self.done.last_mut() {
            Some((
                id,
                Edit::Material {
                    index: last,
                    after: a,
                    ..
                },
            )) if same_drag && last == index => {
                // A new id: the merged step is not the one a save may have marked.
                self.next_id += 1;
                *id = self.next_id;
                a.clone_from(after);
            }
            _ => self.record(edit),
        }
        // After the record, which forgets the drag of any other change.
        self.drag = token;
    }

    /// The change to apply to undo the last one.
    pub fn undo(&mut self) -> Option<Edit> {
        let (id, edit) = self.done.pop()?;
        let inverse = edit.inverse();
        self.undone.push((id, edit));
        Some(inverse)
    }

    /// The change to apply to redo the last undone one.
    pub fn redo(&mut self) -> Option<Edit> {
        let (id, edit) = self.undone.pop()?;
        self.done.push((id, edit.clone()));
        Some(edit)
    }

    fn state(&self) -> u64 {
        self.done.last().map_or(0, |(id, _)| *id)
    }

    /// Marks the current state as saved.
    pub fn mark_saved(&mut self) {
        self.saved = self.state();
    }

    /// Whether the state differs from the last save (or the scene as opened).
    pub fn unsaved(&self) -> bool {
        self.state() != self.saved
    }

    /// Whether there is something to undo / redo.
    pub fn can_undo_redo(&self) -> (bool, bool) {
        (!self.done.is_empty(), !self.undone.is_empty())
    }
}

/// The editing state of the open scene.
pub struct Editor {
    /// Each light's aim distance: a spot's [`LightPart::Aim`] handle lies this far along its
    /// axis (where the last drag of it left it).
    pub aims: Vec<f64>,
    /// Selected handles.
    pub selection: BTreeSet<Handle>,
    /// The rectangle of a box selection under way (screen points, corner to corner).
    pub rubber_band: Option<(Pos2, Pos2)>,
    /// The handle under the cursor.
    pub hovered: Option<Handle>,
    /// The drag in progress.
    pub gesture: Option<Gesture>,
    /// The point the camera orbits and dollies about.
    pub pivot: DVec3,
    /// The turntable's vertical.
    pub world_up: DVec3,
    /// Undo / redo.
    pub history: History,
    overlay: Arc<WireframeGeometry>,
    /// Changes whenever the overlay's geometry does, to a value no editor of this process
    /// had before (a process-wide counter): the GPU keeps the geometry of the generation it last
    /// uploaded, and a scene opened in place of another must not pass for it.
    pub generation: u64,
    overlay_stale: bool,
}

/// A generation of overlay geometry no editor of this process had before.
fn next_generation() -> u64 {
    static NEXT: AtomicU64 = AtomicU64::new(0);
    NEXT.fetch_add(1, Ordering::Relaxed)
}

impl Editor {
    /// The editor for a freshly opened scene.
    pub fn new(scene: &Scene) -> Self {
        let cam = &scene.camera;
        let bounds = scene.geometry.bounds();
        let aim = if bounds.is_empty() {
            1.0
        } else {
            (0.25 * bounds.diagonal().length()).max(1e-3)
        };
        Self {
            aims: vec![aim; scene.lights.len()],
            selection: BTreeSet::new(),
            rubber_band: None,
            hovered: None,
            gesture: None,
            pivot: cam.position + cam.forward * cam.focal_distance,
            world_up: navigate::world_up(cam.up),
            history: History::default(),
            overlay: Arc::default(),
            generation: next_generation(),
            overlay_stale: true,
        }
    }

    /// Position of a handle: a control point, a light's place, a spot's aim point.
    pub fn point(&self, doc: &Document, h: Handle) -> DVec3 {
        match h {
            Handle::Control(r) => doc.patch(r.patch).map_or(DVec3::ZERO, |p| p.points[r.index]),
            Handle::Net(r) => doc.net_point(r).map_or(DVec3::ZERO, |(p, _)| p),
            Handle::Light(LightRef { light, part }) => {
                let l = &doc.lights()[light];
                match (part, l) {
                    (LightPart::Aim, Light::Spot { direction, .. }) => {
                        light_place(l) + *direction * self.aims[light]
                    }
                    _ => light_place(l),
                }
            }
        }
    }

    /// `h` and every other control point at the same place (within a billionth of its patch's
    /// size): the points a seam or a collapsed edge shares, which move together. A light's
    /// handle has no twins.
    pub fn welded(&self, doc: &Document, h: Handle) -> Vec<Handle> {
        if !self.exists(doc, h) {
            return Vec::new();
        }
        let p = self.point(doc, h);
        let twins: Vec<Handle> = match h {
            Handle::Control(r) => {
                let tolerance = doc
                    .patch(r.patch)
                    .map_or(0.0, |q| 1e-9 * q.bounds().diagonal().length());
                doc.patch_handles()
                    .filter(|(o, q)| *o != r && (*q - p).length() <= tolerance)
                    .map(|(o, _)| Handle::Control(o))
                    .collect()
            }
            // A closed surface's first and last rows of points (a cylinder's seam) coincide.
            Handle::Net(r) => {
                let points = &doc.scene().geometry.nets()[r.net].net.surface.points;
                let (lo, hi) = points.iter().fold((p, p), |(lo, hi), q| (lo.min(*q), hi.max(*q)));
                let tolerance = 1e-9 * (hi - lo).length();
                (0..points.len())
                    .filter(|&i| i != r.index && (points[i] - p).length() <= tolerance)
                    .map(|index| Handle::Net(NetRef { net: r.net, index }))
                    .collect()
            }
            Handle::Light(_) => Vec::new(),
        };
        std::iter::once(h).chain(twins).collect()
    }

    /// Whether `h` names a handle of this scene.
    pub fn exists(&self, doc: &Document, h: Handle) -> bool {
        match h {
            Handle::Control(r) => r.patch < doc.patches().len() && r.index < 16 && !doc.patch_in_net(r.patch),
            Handle::Net(r) => doc.net_point(r).is_some(),
            Handle::Light(l) => doc
                .lights()
                .get(l.light)
                .is_some_and(|light| light_handles(l.light, light).any(|x| x == l)),
        }
    }

    /// Every handle with its position: control points patch by patch (the points of the nets
    /// that patches came from in their place), then the lights'.
    pub fn handles<'a>(&'a self, doc: &'a Document) -> impl Iterator<Item = (Handle, DVec3)> + 'a {
        let controls = doc.patch_handles().map(|(r, q)| (Handle::Control(r), q));
        let nets = doc.net_handles().map(|(r, q)| (Handle::Net(r), q));
        let lights = doc
            .lights()
            .iter()
            .enumerate()
            .flat_map(|(k, l)| light_handles(k, l))
            .map(move |r| (Handle::Light(r), self.point(doc, Handle::Light(r))));
        controls.chain(nets).chain(lights)
    }

    /// The handle nearest `pointer` within [`PICK_RADIUS`], if any.
    pub fn pick(&self, doc: &Document, proj: &OverlayProjection, pointer: Pos2) -> Option<Handle> {
        let mut best: Option<(f32, Handle)> = None;
        for (h, q) in self.handles(doc) {
            let Some(s) = proj.to_screen(q) else {
                continue;
            };
            let d = s.distance(pointer);
            if d <= PICK_RADIUS && best.is_none_or(|(b, _)| d < b) {
                best = Some((d, h));
            }
        }
        best.map(|(_, h)| h)
    }

    /// Marks the overlay for rebuilding (hover, selection or points changed).
    pub fn touch(&mut self) {
        self.overlay_stale = true;
    }

    /// The overlay's geometry, rebuilt if something changed.
    pub fn overlay(&mut self, doc: &Document) -> Arc<WireframeGeometry> {
        if self.overlay_stale {
            let lights: Vec<(Light, DVec3)> = (0..doc.lights().len())
                .map(|k| {
                    let aim = LightRef {
                        light: k,
                        part: LightPart::Aim,
                    };
                    (doc.lights()[k], self.point(doc, Handle::Light(aim)))
                })
                .collect();
            let geometry = &doc.scene().geometry;
            let patches = doc.patches().enumerate().map(|(k, points)| OverlayPatch {
                points,
                weights: geometry.patch_weights(k),
                trim: geometry.patch_trim(k).map(|t| (t, geometry.patch_domains()[k])),
                in_net: geometry.patch_net(k).is_some(),
            });
            let nets: Vec<(&[DVec3], usize)> = geometry
                .nets()
                .iter()
                .map(|n| (n.net.surface.points.as_slice(), n.net.size().0))
                .collect();
            self.overlay = Arc::new(overlay_geometry(
                patches,
                &nets,
                &lights,
                self.hovered,
                &self.selection,
            ));
            self.generation = next_generation();
            self.overlay_stale = false;
        }
        self.overlay.clone()
    }

    /// Puts handles at positions in `doc`, in order (a light's place before its aim: the aim
    /// turns the spot from where it then is); returns `(handle, before, after)` for those that
    /// changed, and the changes for the render session: the control points' (moved together,
    /// in one update of the geometry), then each changed light's last.
    pub fn set_points(
        &mut self,
        doc: &mut Document,
        moves: &[(Handle, DVec3)],
    ) -> (Vec<(Handle, DVec3, DVec3)>, Vec<Change>) {
        let mut changed = Vec::new();
        let mut controls = Vec::new();
        let mut nets = Vec::new();
        let mut lights: Vec<(usize, Change)> = Vec::new();
        for &(h, p) in moves {
            if !self.exists(doc, h) || !p.is_finite() {
                continue;
            }
            let before = self.point(doc, h);
            if before == p {
                continue;
            }
            match h {
                Handle::Control(r) => {
                    controls.push((r, p));
                    changed.push((h, before, p));
                }
                Handle::Net(r) => {
                    nets.push((r, p));
                    changed.push((h, before, p));
                }
                Handle::Light(LightRef { light, part }) => {
                    let l = doc.lights()[light];
                    let place = light_place(&l);
                    let (moved, reach) = match part {
                        LightPart::Place => (l.translated(p - place), None),
                        LightPart::Aim => {
                            let reach = (p - place).length();
                            if reach <= 1e-9 * (1.0 + place.length()) {
                                continue;
                            }
                            (l.aimed(p - place), Some(reach))
                        }
                    };
                    let Some(change) = doc.set_light(light, moved) else {
                        continue;
                    };
                    if let Some(reach) = reach {
                        self.aims[light] = reach;
                    }
                    match lights.iter_mut().find(|(k, _)| *k == light) {
                        Some((_, last)) => *last = change,
                        None => lights.push((light, change)),
                    }
                    changed.push((h, before, self.point(doc, h)));
                }
            }
        }
        let mut changes = doc.move_control_points(&controls);
        changes.extend(doc.move_net_points(&nets));
        changes.extend(lights.into_iter().map(|(_, c)| c));
        if !changed.is_empty() {
            self.touch();
        }
        (changed, changes)
    }

    /// The selected points and where they are: what a drag moves.
    pub fn selected_points(&self, doc: &Document) -> Vec<(Handle, DVec3)> {
        self.selection.iter().map(|r| (*r, self.point(doc, *r))).collect()
    }

    /// Where the dragged points go with the cursor at `pointer`: parallel to the image plane
    /// through the grabbed point (the grabbed point stays under the cursor), or along the
    /// line of sight when `along_view` (dragging up moves away from the eye).
    pub fn dragged_points(
        &self,
        proj: &OverlayProjection,
        pointer: Pos2,
        along_view: bool,
    ) -> Vec<(Handle, DVec3)> {
        let Some(Gesture::Points {
            grab,
            grab_screen,
            press,
            start,
        }) = &self.gesture
        else {
            return Vec::new();
        };
        let Some(&(_, origin)) = start.iter().find(|(r, _)| r == grab) else {
            return Vec::new();
        };
        let depth = proj.depth(origin);
        // The grabbed point follows the cursor's motion since the press.
        let offset = pointer - *press;
        let delta = if along_view {
            let dy = -offset.y as f64;
            let dir = (origin - proj.camera.position).normalize_or_zero();
            dir * dy * proj.world_per_point(depth)
        } else {
            // Exact on the plane: the point under the moved screen position at its depth.
            let here = proj.unproject(*grab_screen, depth);
            proj.unproject(*grab_screen + offset, depth) - here
        };
        start.iter().map(|(r, p)| (*r, *p + delta)).collect()
    }

    /// The camera and pivot a camera drag gives for a cursor moved `delta` points since the
    /// drag began.
    pub fn dragged_camera(&self, proj: &OverlayProjection, delta: Vec2) -> Option<(Camera, DVec3)> {
        let Some(Gesture::Camera { how, start }) = &self.gesture else {
            return None;
        };
        let (cam, pivot) = start;
        let (dx, dy) = (delta.x as f64, delta.y as f64);
        Some(match how {
            CameraMove::Orbit => (
                navigate::orbit(
                    cam,
                    *pivot,
                    self.world_up,
                    -dx * ORBIT_PER_POINT,
                    dy * ORBIT_PER_POINT,
                ),
                *pivot,
            ),
            CameraMove::Pan => {
                let scale = proj.world_per_point((*pivot - cam.position).dot(cam.forward));
                let shift = (-dx * cam.right + dy * cam.up) * scale;
                (navigate::pan(cam, shift), *pivot + shift)
            }
            CameraMove::Dolly => (navigate::dolly(cam, *pivot, (dy * DOLLY_PER_POINT).exp()), *pivot),
        })
    }

    /// A step of `points` screen points in the image plane, at the selection's depth: what
    /// the arrow keys move the selection by.
    pub fn nudge(&self, doc: &Document, proj: &OverlayProjection, step: Vec2) -> Vec<(Handle, DVec3)> {
        let Some(first) = self.selection.first() else {
            return Vec::new();
        };
        let c = &proj.camera;
        let scale = proj.world_per_point(proj.depth(self.point(doc, *first)));
        let delta = (step.x as f64 * c.right - step.y as f64 * c.up) * scale;
        self.selection
            .iter()
            .map(|r| (*r, self.point(doc, *r) + delta))
            .collect()
    }

    /// Centre and radius of the selection (all patches and lights when nothing is selected).
    pub fn selection_sphere(&self, doc: &Document) -> (DVec3, f64) {
        let points: Vec<DVec3> = if self.selection.is_empty() {
            let lights = doc.lights().iter().map(light_place);
            doc.patches().flat_map(|p| p.points).chain(lights).collect()
        } else {
            self.selection.iter().map(|r| self.point(doc, *r)).collect()
        };
        if points.is_empty() {
            return (self.pivot, 1.0);
        }
        let centre = points.iter().sum::<DVec3>() / points.len() as f64;
        let radius = points.iter().map(|p| (*p - centre).length()).fold(0.0, f64::max);
        (centre, radius.max(1e-3))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn another_scene_s_overlay_is_never_taken_for_the_last_one() {
        let scene = Scene::builtin();
        let (mut first, doc) = (Editor::new(&scene), Document::new(scene.clone()));
        first.overlay(&doc);
        let mut second = Editor::new(&scene);
        assert_ne!(second.generation, first.generation);
        second.overlay(&doc);
        assert_ne!(
            second.generation, first.generation,
            "the GPU would keep the first scene's nets"
        );
    }

    #[test]
    fn history_undoes_redoes_and_knows_what_is_unsaved() {
        let mut h = History::default();
        let r = Handle::Control(crate::app::handle::PointRef { patch: 0, index: 1 });
        let edit = Edit::Points(vec![(r, DVec3::ZERO, DVec3::X)]);
        assert!(!h.unsaved());
        h.record(edit.clone());
        assert!(h.unsaved());
        h.mark_saved();
        assert!(!h.unsaved());
        assert_eq!(h.undo(), Some(Edit::Points(vec![(r, DVec3::X, DVec3::ZERO)])));
        assert!(h.unsaved());
        assert_eq!(h.redo(), Some(edit));
        assert!(!h.unsaved());
        assert_eq!(h.redo(), None);
    }
}
