//! Inline `trims` of a `patches` object: which inline patches each trimmed surface is made of,
//! and its loops of cubic rational Bézier segments in the patches' `(u,v)` (their `domains`),
//! as the faithful save writes them for an edited trimmed surface ([`crate::geometry::trim`]).

use std::sync::Arc;

use glam::{DVec2, DVec3};

use super::diagnostics::{Result, Table};
use crate::geometry::freeform::DomainPatch;
use crate::geometry::freeform_trim::closes;
use crate::geometry::trim::{eval, TrimLoop, TrimRegion, TrimSegment};
use crate::scene::format::TrimDesc;

/// Applies inline `trims`: each entry's loops become the trim region of its patches.
pub(super) fn patch_trims(t: &Table, patches: &mut [DomainPatch], trims: &[TrimDesc]) -> Result<()> {
    let mut owner: Vec<Option<usize>> = vec![None; patches.len()];
    for (i, surface) in trims.iter().enumerate() {
        if surface.patches.is_empty() || surface.loops.is_empty() {
            return Err(t.err(format!(
                "'trims[{i}]' needs 'patches' and 'loops', each not empty"
            )));
        }
        for &k in &surface.patches {
            match owner.get_mut(k) {
                None => {
                    return Err(t.err(format!(
                        "'trims[{i}].patches' names patch {k}; the object has {} (numbered from 0)",
                        patches.len()
                    )))
                }
                Some(Some(j)) => return Err(t.err(format!("patch {k} is in 'trims[{j}]' and 'trims[{i}]'"))),
                Some(slot) => *slot = Some(i),
            }
        }
        // The gap a loop may have is measured against the surface's parameter range.
        let (lo, hi) = surface
            .patches
            .iter()
            .fold((DVec2::MAX, DVec2::MIN), |(lo, hi), &k| {
                let w = &patches[k].window;
                (lo.min(DVec2::new(w.u0, w.v0)), hi.max(DVec2::new(w.u1, w.v1)))
            });
        let size = (hi - lo).length();
        let mut loops = Vec::with_capacity(surface.loops.len());
        for (j, l) in surface.loops.iter().enumerate() {
            let segments = loop_segments(t, &format!("trims[{i}].loops[{j}]"), &l.segments, size)?;
            loops.push(TrimLoop {
                segments,
                hole: l.hole,
            });
        }
        let region = Arc::new(TrimRegion::new(loops));
        for &k in &surface.patches {
            patches[k].trim = Some(region.clone());
        }
    }
    Ok(())
}

/// One loop's segments, each 12 numbers `u, v, w` per point (`w` above 0), checked closed.
fn loop_segments(
    t: &Table,
    name: &str,
    given: &[[crate::scene::format::Real; 12]],
    size: f64,
) -> Result<Vec<TrimSegment>> {
    if given.is_empty() {
        return Err(t.err(format!("'{name}.segments' is empty")));
    }
    let mut segments = Vec::with_capacity(given.len());
    for (s, numbers) in given.iter().enumerate() {
        let n = numbers.map(|r| r.0);
        let segment: TrimSegment = std::array::from_fn(|k| {
            let (u, v, w) = (n[3 * k], n[3 * k + 1], n[3 * k + 2]);
            DVec3::new(u * w, v * w, w)
        });
        if let Some(k) = (0..4).find(|&k| !(n[3 * k + 2] > 0.0 && n[3 * k + 2].is_finite())) {
            return Err(t.err(format!(
                "'{name}.segments[{s}]': point {k} has weight {}; a trim curve's weights must be above 0",
                n[3 * k + 2]
            )));
        }
        if !segment.iter().all(|p| p.is_finite()) {
            return Err(t.err(format!(
                "'{name}.segments[{s}]' is too large (u·w or v·w is not finite)"
            )));
        }
        segments.push(segment);
    }
    for s in 0..segments.len() {
        let next = (s + 1) % segments.len();
        let gap = eval(&segments[s], 1.0).distance(eval(&segments[next], 0.0));
        if !closes(gap, size) {
            return Err(t.err(format!(
                "'{name}': segment {next} does not start where segment {s} ends (a gap of {gap:e} in (u,v)); a loop is closed"
            )));
        }
    }
    Ok(segments)
}
