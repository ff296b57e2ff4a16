//! A B-spline or NURBS surface's own control net, kept beside the Bézier patches it became:
//! editing moves the net's points and derives the patches again (knot insertion, Boehm 1980,
//! as when the file was read), so an edited surface keeps the continuity its knots give it
//! (C² across the spans of a uniform bicubic), and saving writes back the surface it was.

use std::ops::Range;
use std::sync::Arc;

use glam::{DAffine3, DVec3};

use super::bezier::BezierPatch;
use super::bspline::BsplineSurface;
use super::patch::Window;
use super::rational::Weights;

/// A surface as its file gave it: control points (`u` fastest), knots, range, and weights
/// when rational.
#[derive(Clone, Debug, PartialEq)]
pub struct SurfaceNet {
    /// The B-spline: points, knots along `u` and `v`, the range converted.
    pub surface: BsplineSurface,
    /// One weight per point, when rational.
    pub weights: Option<Vec<f64>>,
}

impl SurfaceNet {
    /// Points along `u` and along `v`.
    pub fn size(&self) -> (usize, usize) {
        let nu = self.surface.nu();
        (nu, self.surface.points.len() / nu.max(1))
    }

    /// The Bézier patches, each with its window in the surface's parameters and its weights
    /// when rational, in the order the file's reading made them.
    pub fn patches(&self) -> Vec<(BezierPatch, Window, Option<Weights>)> {
        match &self.weights {
            Some(w) => self
                .surface
                .to_rational_bezier(w)
                .into_iter()
                .map(|(p, window, w)| (p, window, Some(w)))
                .collect(),
            None => self
                .surface
                .to_bezier()
                .into_iter()
                .map(|(p, window)| (p, window, None))
                .collect(),
        }
    }

    /// The net placed by `m` (an affine map commutes with knot insertion, weights and all).
    pub fn transformed(&self, m: &DAffine3) -> Self {
        let mut out = self.clone();
        for p in &mut out.surface.points {
            *p = m.transform_point3(*p);
        }
        out
    }
}

/// A net in a scene: the surface, the object it belongs to, and which of the geometry's
/// patches it became.
#[derive(Clone, Debug)]
pub struct PlacedNet {
    /// The surface as edited.
    pub net: Arc<SurfaceNet>,
    /// The object it belongs to.
    pub object: u32,
    /// Its patches among the geometry's.
    pub patches: Range<usize>,
}

impl PlacedNet {
    /// The net with its points moved (`(index, position)`, `u` fastest), and its patches
    /// derived again, each with its index in the geometry; `None` for an index out of range,
    /// a position that is not finite, or a net whose patches would not be.
    pub fn moved(&self, moves: &[(usize, DVec3)]) -> Option<(SurfaceNet, Vec<(usize, BezierPatch)>)> {
        let mut net = (*self.net).clone();
        for &(index, position) in moves {
            if !position.is_finite() {
                return None;
            }
            *net.surface.points.get_mut(index)? = position;
        }
        let patches = net.patches();
        if patches.len() != self.patches.len()
            || !patches
                .iter()
                .all(|(p, _, _)| p.points.iter().all(|q| q.is_finite()))
        {
            return None;
        }
        let edits = self
            .patches
            .clone()
            .zip(patches)
            .map(|(k, (p, _, _))| (k, p))
            .collect();
        Some((net, edits))
    }
}
