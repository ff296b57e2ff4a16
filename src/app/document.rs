//! The scene being edited ([`Document`]): the one copy of it in the viewer. The widgets read
//! it; every edit — render parameters, lens, camera pose, control points, lights, materials —
//! changes it and answers with the [`Change`]s that bring the render session's own copy along.

use std::path::Path;

use glam::DVec3;

use super::handle::{Handle, NetRef, PointRef};
use crate::geometry::BezierPatch;
use crate::render::session::Command;
use crate::scene::{Camera, Light, Material, Scene};
use crate::settings::RenderParams;

/// An edit as the render session hears of it.
#[derive(Clone, Debug, PartialEq)]
pub struct Change {
    /// What the session is sent.
    pub command: Command,
    /// Whether it starts a new epoch (judged against the parameters before the edit).
    pub restarts: bool,
}

impl Change {
    fn new(command: Command, before: &RenderParams) -> Self {
        Self {
            restarts: command.restarts(before),
            command,
        }
    }
}

/// The scene as edited, and the control points its file gave (what a save compares with).
pub struct Document {
    scene: Scene,
    loaded: Vec<BezierPatch>,
}

impl Document {
    /// A document for `scene` as opened.
    pub fn new(scene: Scene) -> Self {
        Self {
            loaded: scene.geometry.patches().iter().map(|(p, _)| *p).collect(),
            scene,
        }
    }

    /// The scene as edited.
    pub fn scene(&self) -> &Scene {
        &self.scene
    }

    /// The control points as the scene's file gave them (geometry order).
    pub fn loaded_patches(&self) -> &[BezierPatch] {
        &self.loaded
    }

    /// The patches as edited (geometry order).
    pub fn patches(&self) -> impl ExactSizeIterator<Item = &BezierPatch> + Clone + '_ {
        self.scene.geometry.patches().iter().map(|(p, _)| p)
    }

    /// Patch `k` as edited.
    pub fn patch(&self, k: usize) -> Option<&BezierPatch> {
        self.scene.geometry.patches().get(k).map(|(p, _)| p)
    }

    /// Point `r` of a surface's own net, as edited, and its weight (1 for a polynomial
    /// surface); `None` for a point out of range.
    pub fn net_point(&self, r: NetRef) -> Option<(DVec3, f64)> {
        let net = &self.scene.geometry.nets().get(r.net)?.net;
        let p = *net.surface.points.get(r.index)?;
        Some((p, net.weights.as_ref().map_or(1.0, |w| w[r.index])))
    }

    /// The control points that are handles, with their positions: every point of the patches
    /// not derived from a net, patch by patch.
    pub fn patch_handles(&self) -> impl Iterator<Item = (PointRef, DVec3)> + '_ {
        self.patches()
            .enumerate()
            .filter(|(k, _)| !self.patch_in_net(*k))
            .flat_map(|(patch, p)| (0..16).map(move |index| (PointRef { patch, index }, p.points[index])))
    }

    /// Every point of the surfaces' own nets, with its position, net by net.
    pub fn net_handles(&self) -> impl Iterator<Item = (NetRef, DVec3)> + '_ {
        self.scene
            .geometry
            .nets()
            .iter()
            .enumerate()
            .flat_map(|(net, placed)| {
                placed
                    .net
                    .surface
                    .points
                    .iter()
                    .enumerate()
                    .map(move |(index, q)| (NetRef { net, index }, *q))
            })
    }

    /// Whether patch `k` is derived from a surface's own net (its Bézier points are then not
    /// handles: the net's are).
    pub fn patch_in_net(&self, k: usize) -> bool {
        self.scene.geometry.patch_net(k).is_some()
    }

    /// The patch a point handle belongs to: a control point's own, a net point's net's first.
    pub fn handle_patch(&self, h: Handle) -> Option<usize> {
        match h {
            Handle::Control(r) => Some(r.patch),
            Handle::Net(r) => self.scene.geometry.nets().get(r.net).map(|n| n.patches.start),
            Handle::Light(_) => None,
        }
    }

    /// The lights as edited (scene order).
    pub fn lights(&self) -> &[Light] {
        &self.scene.lights
    }

    /// The materials as edited (scene order).
    pub fn materials(&self) -> &[Material] {
        &self.scene.materials
    }

    /// The material of the object patch `k` belongs to (its index in the scene).
    pub fn patch_material(&self, k: usize) -> Option<usize> {
        let (_, object) = self.scene.geometry.patches().get(k)?;
        self.scene.objects.get(*object as usize).map(|o| o.material)
    }

    /// Replaces material `k` (`None` when it has no such material, nothing changes, or
    /// `value` is not one it can become: [`Material::can_become`]).
    pub fn set_material(&mut self, k: usize, value: Material) -> Option<Change> {
        let current = self.scene.materials.get(k)?;
        if *current == value || !current.can_become(&value) {
            return None;
        }
        self.scene.materials[k] = value.clone();
        let command = Command::SetMaterial { material: k, value };
        Some(Change::new(command, &self.scene.params))
    }

    /// The document was written to `path` as `text`: from now on that file is the scene's,
    /// and what a later save compares the control points with.
    pub fn saved_as(&mut self, path: &Path, text: String) {
        self.scene.text = text.into();
        self.scene.source = path.to_path_buf();
        self.scene.base_dir = path.parent().map(Path::to_path_buf);
        self.loaded = self.patches().copied().collect();
    }

    /// Sets the render parameters.
    pub fn set_params(&mut self, params: &RenderParams) -> Option<Change> {
        if *params == self.scene.params {
            return None;
        }
        let change = Change::new(Command::SetParams(params.clone()), &self.scene.params);
        self.scene.params = params.clone();
        Some(change)
    }

    /// Sets the lens: its radius and the distance in focus.
    pub fn set_lens(&mut self, aperture: f64, focal_distance: f64) -> Option<Change> {
        let camera = Camera {
            aperture,
            focal_distance,
            ..self.scene.camera.clone()
        };
        self.set_camera(camera)
    }

    /// Places the camera with `pose`'s position and orientation and the current lens.
    pub fn set_pose(&mut self, pose: &Camera) -> Option<Change> {
        let camera = Camera {
            aperture: self.scene.camera.aperture,
            focal_distance: self.scene.camera.focal_distance,
            ..pose.clone()
        };
        self.set_camera(camera)
    }

    fn set_camera(&mut self, camera: Camera) -> Option<Change> {
        if camera == self.scene.camera {
            return None;
        }
        let change = Change::new(Command::SetCamera(camera.clone()), &self.scene.params);
        self.scene.camera = camera;
        Some(change)
    }

    /// Moves control points (finite positions of existing points; the rest are ignored), all
    /// at once: one update of the geometry, a change per point.
    pub fn move_control_points(&mut self, moves: &[(PointRef, DVec3)]) -> Vec<Change> {
        let mut edits: Vec<(usize, BezierPatch)> = Vec::new();
        let mut changes = Vec::new();
        for &(r, position) in moves {
            let Some(patch) = self.patch(r.patch).copied() else {
                continue;
            };
            if r.index >= 16 || !position.is_finite() {
                continue;
            }
            let patch = match edits.iter_mut().find(|(k, _)| *k == r.patch) {
                Some((_, edited)) => edited,
                None => {
                    edits.push((r.patch, patch));
                    &mut edits.last_mut().expect("just pushed").1
                }
            };
            patch.points[r.index] = position;
            let command = Command::MoveControlPoint {
                patch: r.patch,
                index: r.index,
                position,
            };
            changes.push(Change::new(command, &self.scene.params));
        }
        if !edits.is_empty() {
            self.scene.geometry.update_patches(&edits);
        }
        changes
    }

    /// Moves points of surfaces' own nets (finite positions of existing points; the rest are
    /// ignored): each edited net's patches are derived again in one update of the geometry,
    /// and the session hears of every Bézier point that changed.
    pub fn move_net_points(&mut self, moves: &[(NetRef, DVec3)]) -> Vec<Change> {
        let mut by_net: std::collections::BTreeMap<usize, Vec<(usize, DVec3)>> = Default::default();
        for &(r, position) in moves {
            if self.net_point(r).is_some() && position.is_finite() {
                by_net.entry(r.net).or_default().push((r.index, position));
            }
        }
        let mut changes = Vec::new();
        for (n, net_moves) in by_net {
            let range = self.scene.geometry.nets()[n].patches.clone();
            let before: Vec<BezierPatch> = range.clone().filter_map(|k| self.patch(k).copied()).collect();
            let Some(edits) = self.scene.geometry.move_net_points(n, &net_moves) else {
                continue;
            };
            for (patch, after) in edits {
                let old = before[patch - range.start];
                for index in (0..16).filter(|&i| after.points[i] != old.points[i]) {
                    let position = after.points[index];
                    let command = Command::MoveControlPoint {
                        patch,
                        index,
                        position,
                    };
                    changes.push(Change::new(command, &self.scene.params));
                }
            }
        }
        changes
    }

    /// Replaces light `k` (`None` when it has no such light or `light` is not one it can
    /// become: a sphere stays a sphere).
    pub fn set_light(&mut self, k: usize, light: Light) -> Option<Change> {
        if !self.scene.set_light(k, light) {
            return None;
        }
        let command = Command::SetLight {
            light: k,
            value: light,
        };
        Some(Change::new(command, &self.scene.params))
    }
}
