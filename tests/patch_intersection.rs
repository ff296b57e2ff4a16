//! Exact ray/Bézier patch intersection on Newell's teapot: round trips, seams, poles, agreement
//! with a brute-force reference, grazing and axis-aligned rays, rays leaving a surface.

mod common;

use caustic::bench::{teapot_geometry, teapot_view};
use caustic::geometry::{GeometryBuilder, Hit, PatchMethod, Ray, ShapeRef};
use common::*;
use glam::{DVec2, DVec3};
use rand::Rng;
use rayon::prelude::*;

fn assert_finite(hit: &Hit) {
    assert!(
        hit.t.is_finite() && hit.point.is_finite() && hit.uv().is_finite(),
        "{hit:?}"
    );
    assert!(
        (hit.normal.length() - 1.0).abs() < 1e-9,
        "normal not unit: {hit:?}"
    );
}

#[test]
fn assets_teapot_is_newells_32_patches() {
    let patches = teapot_from_assets();
    assert_eq!(patches.len(), 32);
    assert_eq!(
        patches,
        caustic::assets::teapot(),
        "built-in copy differs from assets/"
    );
    let b = patches
        .iter()
        .fold(caustic::geometry::Aabb::EMPTY, |b, p| b.union(p.bounds()));
    assert_eq!(b.min.z, 0.0);
    assert_eq!(b.max.z, 3.15);
    assert_eq!(shared_edges(&patches).len(), 52);
}

#[test]
fn round_trip_hits_the_aimed_point() {
    let patches = teapot_from_assets();
    let diag = diagonal(&patches);
    let mut rng = rng(1);
    let (mut checked_uv, mut rays) = (0, 0);
    for (k, patch) in patches.iter().enumerate() {
        let mut builder = GeometryBuilder::default();
        builder.add_patch(*patch, k as u32);
        let geometry = builder.build();
        for _ in 0..250 {
            let (u, v) = (rng.random::<f64>(), rng.random::<f64>());
            let target = patch.eval(u, v);
            let n = patch.normal(u, v).expect("teapot normals exist");
            let dir = loop {
                let d = unit_vector(&mut rng);
                if d.dot(n).abs() >= 0.2 {
                    break d;
                }
            };
            let distance = 0.25;
            let ray = Ray::new(target - distance * dir, dir);
            let hit = geometry
                .intersect(&ray, f64::INFINITY)
                .unwrap_or_else(|| panic!("patch {k}: ray aimed at (u,v) = ({u}, {v}) missed"));
            rays += 1;
            assert_finite(&hit);
            assert_eq!(hit.shape, ShapeRef::Patch(0));
            // Every hit lies on the patch at its reported (u,v).
            let on_surface = (patch.eval(hit.uv().x, hit.uv().y) - hit.point).length();
            assert!(
                on_surface <= 1e-9 * diag,
                "patch {k} ({u},{v}) dir {dir} n {n}: hit {on_surface:e} off the surface at {}",
                hit.uv()
            );
            // The normal is the patch's at the hit, however the intersector came by it.
            let expected = patch
                .normal(hit.uv().x, hit.uv().y)
                .expect("teapot normals exist");
            assert!(
                (hit.normal - expected).length() < 1e-9,
                "patch {k} ({u},{v}): normal {} against the patch's {expected}",
                hit.normal
            );
            // The patch may fold in front of the target (never by more than rounding otherwise).
            if hit.t < distance - 1e-9 * diag {
                continue;
            }
            let error = (hit.point - target).length();
            assert!(
                error <= 1e-9 * diag,
                "patch {k} ({u},{v}) dir {dir:?}: position error {error:e}, t {}",
                hit.t
            );
            // (u,v) is recoverable where the parameterisation is regular.
            let sp = patch.eval_with_derivs(u, v);
            if sp.dp_du.cross(sp.dp_dv).length() > 1e-3 * diag * diag {
                let uv_error = (hit.uv() - DVec2::new(u, v)).length();
                assert!(uv_error < 1e-7, "patch {k}: (u,v) error {uv_error:e}");
                checked_uv += 1;
            }
        }
    }
    assert_eq!(rays, 32 * 250);
    assert!(checked_uv > 7000, "only {checked_uv} regular samples");
}

#[test]
fn no_ray_slips_through_a_seam() {
    let patches = teapot_from_assets();
    let diag = diagonal(&patches);
    let geometry = teapot_geometry(PatchMethod::default());
    let edges = shared_edges(&patches);
    assert_eq!(edges.len(), 52);
    let mut rng = rng(2);
    let mut rays = 0;
    let mut misses = Vec::new();
    for &(a, ea, b, eb, reversed) in &edges {
        for _ in 0..500 {
            let w = rng.random::<f64>();
            let uv_a = edge_uv(ea, w);
            let uv_b = edge_uv(eb, if reversed { 1.0 - w } else { w });
            let target = patches[a].eval(uv_a.x, uv_a.y);
            assert!((patches[b].eval(uv_b.x, uv_b.y) - target).length() < 1e-12 * diag);
            let na = patches[a].normal(uv_a.x, uv_a.y).expect("normal");
            let nb = patches[b].normal(uv_b.x, uv_b.y).expect("normal");
            let dir = loop {
                let d = unit_vector(&mut rng);
                if d.dot(na).abs() >= 0.01 && d.dot(nb).abs() >= 0.01 {
                    break d;
                }
            };
            let distance = 1.0;
            let ray = Ray::new(target - distance * dir, dir);
            rays += 1;
            match geometry.intersect(&ray, f64::INFINITY) {
                Some(hit) if hit.t <= distance + 1e-9 * diag => assert_finite(&hit),
                other => misses.push((a, b, w, other.map(|h| h.t))),
            }
        }
    }
    assert!(rays >= 25_600);
    assert!(
        misses.is_empty(),
        "{} of {rays} seam rays missed: {:?}",
        misses.len(),
        &misses[..misses.len().min(5)]
    );
}

#[test]
fn poles_are_hit_with_a_unit_normal() {
    let patches = teapot_from_assets();
    let diag = diagonal(&patches);
    let geometry = teapot_geometry(PatchMethod::default());
    let mut poles: Vec<DVec3> = Vec::new();
    for p in &patches {
        for (edge, collapsed) in p.collapsed_edges().into_iter().enumerate() {
            let point = edge_points(p, edge)[0];
            if collapsed && !poles.contains(&point) {
                poles.push(point);
            }
        }
    }
    assert_eq!(poles.len(), 2, "the lid top and the bottom centre: {poles:?}");
    let mut rng = rng(3);
    for pole in poles {
        // From above the lid's pole, from below the bottom's.
        let outward = if pole.z > 1.0 { DVec3::Z } else { -DVec3::Z };
        for k in 0..200 {
            let dir = if k == 0 {
                -outward
            } else {
                loop {
                    let d = unit_vector(&mut rng);
                    if d.dot(-outward) > 0.3 {
                        break d;
                    }
                }
            };
            let ray = Ray::new(pole - 2.0 * dir, dir);
            let hit = geometry.intersect(&ray, f64::INFINITY).expect("pole ray hits");
            assert_finite(&hit);
            assert!(
                (hit.point - pole).length() < 1e-9 * diag,
                "pole {pole}: hit {}",
                hit.point
            );
            assert!(
                hit.normal.dot(outward).abs() > 0.999,
                "pole normal {}",
                hit.normal
            );
        }
    }
}

#[test]
fn prepared_agrees_with_brute_force_reference() {
    let patches = teapot_from_assets();
    let diag = diagonal(&patches);
    let prepared = teapot_geometry(PatchMethod::default());
    let reference = teapot_geometry(PatchMethod::PerRay { depth: 22 });
    let rays = teapot_view(256, 256);
    let results: Vec<(Option<Hit>, Option<Hit>)> = rays
        .par_iter()
        .map(|r| {
            (
                prepared.intersect(r, f64::INFINITY),
                reference.intersect(r, f64::INFINITY),
            )
        })
        .collect();
    let mut hit_miss = 0;
    let mut nearest = 0;
    let mut hits = 0;
    for (p, r) in &results {
        match (p, r) {
            (Some(p), Some(r)) => {
                hits += 1;
                assert_finite(p);
                // Both normals are the patch's own at the hit, whichever intersector found it.
                for hit in [p, r] {
                    let ShapeRef::Patch(k) = hit.shape else {
                        panic!("only patches here: {hit:?}")
                    };
                    // The teapot's patches span their whole (u,v) domain.
                    let uv = hit.uv();
                    let expected = patches[k as usize].normal(uv.x, uv.y).expect("teapot normals");
                    assert!(
                        (hit.normal - expected).length() < 1e-9,
                        "{hit:?} against {expected}"
                    );
                }
                if (p.t - r.t).abs() > 1e-6 * diag {
                    nearest += 1;
                }
            }
            (None, None) => {}
            _ => hit_miss += 1,
        }
    }
    assert!(hits > 10_000, "the view shows the teapot ({hits} hits)");
    assert_eq!(hit_miss, 0, "hit/miss disagreements");
    let allowed = results.len() / 10_000;
    assert!(
        nearest <= allowed,
        "{nearest} nearest-hit disagreements (allowed {allowed})"
    );
}

#[test]
fn axis_aligned_and_grazing_rays_stay_finite() {
    let patches = teapot_from_assets();
    let diag = diagonal(&patches);
    let geometry = teapot_geometry(PatchMethod::default());
    let reference = teapot_geometry(PatchMethod::PerRay { depth: 22 });
    let bounds = geometry.bounds().padded(0.5);
    // Rays along ±x, ±y, ±z on a grid: two direction components exactly zero.
    let mut axis_rays = Vec::new();
    for axis in 0..3 {
        for sign in [-1.0, 1.0] {
            let mut dir = DVec3::ZERO;
            dir[axis] = sign;
            let (a1, a2) = ((axis + 1) % 3, (axis + 2) % 3);
            for i in 0..40 {
                for j in 0..40 {
                    let mut o = bounds.centroid() - dir * diag;
                    o[a1] = bounds.min[a1] + (i as f64 + 0.5) / 40.0 * (bounds.max[a1] - bounds.min[a1]);
                    o[a2] = bounds.min[a2] + (j as f64 + 0.5) / 40.0 * (bounds.max[a2] - bounds.min[a2]);
                    axis_rays.push(Ray::new(o, dir));
                }
            }
        }
    }
    let disagreements: usize = axis_rays
        .par_iter()
        .map(|ray| {
            let p = geometry.intersect(ray, f64::INFINITY);
            if let Some(h) = &p {
                assert_finite(h);
            }
            let r = reference.intersect(ray, f64::INFINITY);
            usize::from(p.is_some() != r.is_some())
        })
        .sum();
    assert_eq!(disagreements, 0, "axis-aligned rays disagree with the reference");

    // Rays tangent to the surface at random points.
    let mut rng = rng(4);
    for (k, patch) in patches.iter().enumerate() {
        for _ in 0..100 {
            let (u, v) = (rng.random::<f64>(), rng.random::<f64>());
            let sp = patch.eval_with_derivs(u, v);
            let Some(dir) = (if rng.random::<bool>() { sp.dp_du } else { sp.dp_dv }).try_normalize() else {
                continue;
            };
            let ray = Ray::new(sp.position - dir, dir);
            if let Some(hit) = geometry.intersect(&ray, f64::INFINITY) {
                assert_finite(&hit);
                let ShapeRef::Patch(hp) = hit.shape else {
                    panic!("only patches here")
                };
                let off = (patches[hp as usize].eval(hit.uv().x, hit.uv().y) - hit.point).length();
                assert!(
                    off < 1e-7 * diag,
                    "patch {k}: grazing hit {off:e} off its surface"
                );
            }
        }
    }
}

#[test]
fn rays_leaving_a_surface_do_not_hit_it_again_at_zero() {
    let patches = teapot_from_assets();
    let diag = diagonal(&patches);
    let geometry = teapot_geometry(PatchMethod::default());
    let mut rng = rng(5);
    let mut leaving = 0;
    for ray in teapot_view(64, 64) {
        let Some(hit) = geometry.intersect(&ray, f64::INFINITY) else {
            continue;
        };
        for _ in 0..8 {
            let dir = loop {
                let d = unit_vector(&mut rng);
                if d.dot(hit.normal).abs() >= 0.1 {
                    break d;
                }
            };
            let next = hit.spawn(dir);
            leaving += 1;
            if let Some(again) = geometry.intersect(&next, f64::INFINITY) {
                assert_finite(&again);
                assert!(
                    again.t > 1e-4 * diag,
                    "re-hit at t = {:e} from {}",
                    again.t,
                    hit.point
                );
            }
        }
    }
    assert!(leaving > 4000);
}

/// A ray that carries the patch point it leaves ([`Ray::leaving`]) lets the leaves around that
/// point skip the crossing there: it must find exactly what the same ray finds without it,
/// nearest hit and occlusion, whichever way it leaves (into the teapot too, where it meets the
/// same patch again on the far side) and at angles down to the least one that records it.
#[test]
fn a_departure_point_changes_no_hit() {
    let diag = diagonal(&teapot_from_assets());
    let geometry = teapot_geometry(PatchMethod::default());
    let mut rng = rng(9);
    let (mut rays, mut departing, mut same_patch_again, mut blocked) = (0, 0, 0, 0);
    for ray in teapot_view(48, 48) {
        let Some(hit) = geometry.intersect(&ray, f64::INFINITY) else {
            continue;
        };
        for k in 0..12 {
            let dir = loop {
                let d = unit_vector(&mut rng);
                // A third of the rays leave at slants between 0.1° and 6°.
                let least = if k % 3 == 0 { 2e-3 } else { 0.1 };
                let cos = d.dot(hit.normal).abs();
                if cos >= least && (k % 3 != 0 || cos < 0.1) {
                    break d;
                }
            };
            let next = hit.spawn(dir);
            let plain = next.leaving(None);
            rays += 1;
            departing += next.leaving.is_some() as usize;
            let (a, b) = (
                geometry.intersect(&next, f64::INFINITY),
                geometry.intersect(&plain, f64::INFINITY),
            );
            match (a, b) {
                (Some(a), Some(b)) => {
                    assert_eq!(a.shape, b.shape, "from {} along {dir}", hit.point);
                    assert!((a.t - b.t).abs() <= 1e-9 * diag, "t {} against {}", a.t, b.t);
                    same_patch_again += (a.shape == hit.shape) as usize;
                }
                (a, b) => assert_eq!(a.is_some(), b.is_some(), "from {} along {dir}", hit.point),
            }
            for reach in [0.05 * diag, diag] {
                let occluded = geometry.occluded(&next, reach);
                assert_eq!(
                    occluded,
                    geometry.occluded(&plain, reach),
                    "from {} along {dir}",
                    hit.point
                );
                blocked += occluded as usize;
            }
        }
    }
    assert!(rays > 6000, "{rays} rays");
    assert!(
        departing > rays * 9 / 10,
        "{departing} of {rays} rays carried their departure"
    );
    assert!(
        same_patch_again > 500,
        "{same_patch_again} rays met their own patch again"
    );
    assert!(blocked > 2000, "{blocked} occluded");
}

/// Nearest hits of many random rays through the teapot's bounds: `(t, uv, shape)`.
fn hits_of(geometry: &caustic::geometry::SceneGeometry, rays: &[Ray]) -> Vec<Option<(f64, DVec2, ShapeRef)>> {
    rays.par_iter()
        .map(|r| {
            geometry
                .intersect(r, f64::INFINITY)
                .map(|h| (h.t, h.uv(), h.shape))
        })
        .collect()
}

#[test]
fn re_preparing_edited_patches_intersects_like_a_fresh_build() {
    let patches = teapot_from_assets();
    let build = |patches: &[caustic::geometry::BezierPatch]| {
        let mut b = GeometryBuilder::default();
        for (k, p) in patches.iter().enumerate() {
            b.add_patch(*p, k as u32);
        }
        b.build()
    };
    let mut rng = rng(77);
    let rays: Vec<Ray> = (0..100_000)
        .map(|_| {
            let target = DVec3::new(
                rng.random::<f64>() * 7.0 - 3.5,
                rng.random::<f64>() * 5.0 - 2.5,
                rng.random::<f64>() * 3.5,
            );
            let origin = target - unit_vector(&mut rng) * 12.0;
            Ray::new(origin, target - origin)
        })
        .collect();
    let leaves = |p: &caustic::geometry::BezierPatch| build(std::slice::from_ref(p)).stats().patch_leaves;
    // A small move (every patch keeps its leaf count: the BVH is refit), a large one that
    // bends a patch into more leaves (the BVH is rebuilt), then two patches at once.
    let cases: [&[(usize, usize, DVec3)]; 3] = [
        &[(5, 5, DVec3::new(0.0, 0.0, 0.01))],
        &[(5, 5, DVec3::new(0.0, -2.5, 1.5))],
        &[
            (0, 6, DVec3::new(0.3, 0.2, 0.1)),
            (20, 9, DVec3::new(-0.2, 0.0, 0.4)),
        ],
    ];
    let mut paths = Vec::new();
    for moves in cases {
        let mut edited = build(&patches);
        let mut fresh = patches.clone();
        let mut edits = Vec::new();
        for &(patch, index, delta) in moves {
            fresh[patch].points[index] += delta;
            edits.push((patch, fresh[patch]));
        }
        let update = edited.update_patches(&edits).expect("valid edit");
        let same_counts = edits.iter().all(|(k, p)| leaves(p) == leaves(&patches[*k]));
        assert_eq!(update.refit, same_counts, "{moves:?}");
        paths.push(update.refit);
        let scratch = build(&fresh);
        assert_eq!(edited.stats().patch_leaves, scratch.stats().patch_leaves);
        let (a, b) = (hits_of(&edited, &rays), hits_of(&scratch, &rays));
        let hits = a.iter().filter(|h| h.is_some()).count();
        assert!(hits > 20_000, "only {hits} rays hit");
        for (k, (x, y)) in a.iter().zip(&b).enumerate() {
            match (x, y) {
                (Some((ta, uva, sa)), Some((tb, uvb, sb))) => {
                    assert!(
                        (ta - tb).abs() <= 1e-9 * tb.abs().max(1.0),
                        "ray {k}: t {ta} vs {tb}"
                    );
                    // Where two patches meet, either may report the seam point.
                    if sa == sb {
                        assert!((*uva - *uvb).length() < 1e-6, "ray {k}: uv {uva} vs {uvb}");
                    }
                }
                (None, None) => {}
                _ => panic!("ray {k}: {x:?} vs {y:?}"),
            }
        }
    }
    assert_eq!(
        paths[..2],
        [true, false],
        "both the refit and the rebuild were tried"
    );
    // Bad edits change nothing.
    let mut g = build(&patches);
    let mut bad = patches[3];
    bad.points[2].x = f64::NAN;
    assert!(g.update_patches(&[(3, bad)]).is_none());
    assert!(g.update_patches(&[(32, patches[0])]).is_none());
    assert!(!g.set_control_point(0, 16, DVec3::ZERO));
}
