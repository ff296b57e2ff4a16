//! What the view can grab and move: a patch's control point, a point of a B-spline surface's
//! own net (whose patches follow it), or a light's handle. Hover,
//! selection, dragging, nudging, the exact x/y/z fields and undo treat both alike; only where
//! a handle's position lives differs ([`super::editor::Editor::point`]).

use glam::DVec3;

use crate::scene::Light;

/// A control point: patch index in the scene geometry and point `4i + j`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct PointRef {
    /// Patch index.
    pub patch: usize,
    /// Control point `4i + j`.
    pub index: usize,
}

/// A point of a B-spline or NURBS surface's own control net: the net's index among the
/// geometry's ([`crate::geometry::SceneGeometry::nets`]) and the point's (`u` fastest).
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct NetRef {
    /// Net index.
    pub net: usize,
    /// Point index, `i + nu · j`.
    pub index: usize,
}

/// Which handle of a light.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum LightPart {
    /// Where the light is: a point or spot light's position, a sphere's centre, a quad's
    /// centre. Moving it moves the whole light.
    Place,
    /// A spot light's aim point, on its axis: moving it turns the spot.
    Aim,
}

/// A light's handle: the light's index in the scene and which part.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct LightRef {
    /// Light index.
    pub light: usize,
    /// Which handle.
    pub part: LightPart,
}

/// Something the view can grab and move.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Handle {
    /// A patch's control point.
    Control(PointRef),
    /// A point of a surface's own net.
    Net(NetRef),
    /// A light's handle.
    Light(LightRef),
}

impl From<PointRef> for Handle {
    fn from(r: PointRef) -> Self {
        Handle::Control(r)
    }
}

impl From<LightRef> for Handle {
    fn from(r: LightRef) -> Self {
        Handle::Light(r)
    }
}

impl Handle {
    /// The control point, when it is one.
    pub fn control(self) -> Option<PointRef> {
        match self {
            Handle::Control(r) => Some(r),
            Handle::Net(_) | Handle::Light(_) => None,
        }
    }

    /// The patch it belongs to, when it is a patch's control point (a net's point belongs to
    /// all of its net's patches: [`super::document::Document::handle_patch`]).
    pub fn patch(self) -> Option<usize> {
        self.control().map(|r| r.patch)
    }

    /// Whether it is a point of a patch or of a net (not a light's).
    pub fn is_point(self) -> bool {
        !matches!(self, Handle::Light(_))
    }
}

/// Where a light's [`LightPart::Place`] handle is: its position or centre.
pub fn light_place(light: &Light) -> DVec3 {
    match *light {
        Light::Point { position, .. } | Light::Spot { position, .. } => position,
        Light::Sphere { center, .. } => center,
        Light::Quad {
            corner,
            edge_u,
            edge_v,
            ..
        } => corner + 0.5 * (edge_u + edge_v),
    }
}

/// The handles of `light` (index `k`): its place, and a spot's aim.
pub fn light_handles(k: usize, light: &Light) -> impl Iterator<Item = LightRef> {
    let aim = matches!(light, Light::Spot { .. });
    [LightPart::Place, LightPart::Aim]
        .into_iter()
        .take(if aim { 2 } else { 1 })
        .map(move |part| LightRef { light: k, part })
}
