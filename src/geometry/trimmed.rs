//! How a trimmed patch meets rays: its prepared leaves that the trim loops cut away wholly are
//! dropped, leaves wholly kept intersect as any leaf, and only the leaves a trim curve crosses
//! test each hit's `(u,v)` against the loops ([`TrimRegion::contains`]), searching on past a
//! hit that lies in a cut-away part. So hits, shadow rays and photons all pass through what the
//! trims remove, and an untrimmed scene asks nothing more of its rays.

use glam::DVec2;

use super::mesh::TriangleMesh;
use super::patch::{PatchHit, PatchLeaf, Window};
use super::trim::{Coverage, TrimRegion};

/// Hits in cut-away parts a search passes before it gives up: a ray meets a small, nearly flat
/// leaf at most a few times.
const MAX_CROSSINGS: usize = 8;

/// The leaves of a patch whose window in its surface is `domain` that `trim` does not cut
/// away wholly.
pub fn kept_leaves(leaves: Vec<PatchLeaf>, trim: Option<&TrimRegion>, domain: &Window) -> Vec<PatchLeaf> {
    match trim {
        None => leaves,
        Some(region) => leaves
            .into_iter()
            .filter(|l| region.coverage(&surface_window(domain, &l.window)) != Coverage::Outside)
            .collect(),
    }
}

/// Whether each leaf must test its hits against its patch's trim loops (a trim curve may
/// cross it); empty when no patch is trimmed, so that an untrimmed scene's rays look no
/// further. `trim(k)` and `domain(k)` are patch `k`'s loops and window.
pub fn boundary_leaves<'a>(
    leaves: &[PatchLeaf],
    trim: impl Fn(usize) -> Option<&'a TrimRegion>,
    domain: impl Fn(usize) -> Window,
) -> Vec<bool> {
    let any = leaves.iter().any(|l| trim(l.patch as usize).is_some());
    if !any {
        return Vec::new();
    }
    leaves
        .iter()
        .map(|l| {
            let k = l.patch as usize;
            trim(k).is_some_and(|r| r.coverage(&surface_window(&domain(k), &l.window)) == Coverage::Boundary)
        })
        .collect()
}

/// The part `window` of a patch (in the patch's `[0,1]²`) in the parameters of the surface
/// the patch is the piece `domain` of.
fn surface_window(domain: &Window, window: &Window) -> Window {
    let (a, b) = (domain.map(window.u0, window.v0), domain.map(window.u1, window.v1));
    Window {
        u0: a.x,
        u1: b.x,
        v0: a.y,
        v1: b.y,
    }
}

/// The nearest hit that the trim keeps: `search(t_min)` finds the nearest hit on a patch
/// beyond `t_min`; `trim` is the patch's surface's loops and `domain` the patch's window in
/// that surface, which a hit's patch `(u,v)` is mapped through.
pub fn first_kept(
    mut search: impl FnMut(f64) -> Option<PatchHit>,
    (trim, domain): (&TrimRegion, &Window),
) -> Option<PatchHit> {
    let mut t_min = 0.0;
    for _ in 0..MAX_CROSSINGS {
        let hit = search(t_min)?;
        if trim.contains(domain.map(hit.uv.x, hit.uv.y)) {
            return Some(hit);
        }
        // Past this crossing: the next root lies beyond it by more than the solver's rounding.
        t_min = hit.t + 1e-9 * hit.t.abs().max(f64::MIN_POSITIVE);
    }
    None
}

/// Removes the triangles of a patch's tessellation (texture coordinates in the patch's
/// `[0,1]²`) whose centre the trim cuts away; `domain` is the patch's window in its surface.
/// The cut follows the tessellation's triangles, not the trim curve.
pub fn trim_mesh(mesh: &mut TriangleMesh, trim: &TrimRegion, domain: &Window) {
    let texcoords = &mesh.texcoords;
    mesh.indices.retain(|t| {
        let c = t.iter().map(|&i| texcoords[i as usize]).sum::<DVec2>() / 3.0;
        trim.contains(domain.map(c.x, c.y))
    });
}
