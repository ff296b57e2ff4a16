//! Measurement: every benchmark of `caustic bench` and the harnesses they and the viewer's
//! `view --bench` share. Figures are printed, never asserted (tests assert correctness;
//! benches report speed); inputs are deterministic.
//!
//! - [`command`]: the subcommands and [`command::run`]; [`output`]: text or one JSON document.
//! - One file a bench, flags and all: [`intersect`], [`scaling`] (`ppm`, `whitted`),
//!   [`convergence`], [`edit`], [`memory`], [`shards`], [`tessellation`], and [`all`] (the
//!   README's table from the others' JSON).
//! - Harnesses: [`edit_run`] (an edit in the viewer's kind of session, warm or cold),
//!   [`error_curves`] (curves, CSV), [`plot`] (log-log PNG), [`mod@reference`] (the cached
//!   reference render), [`timings`] (medians, interleaved runs).

pub mod all;
pub mod command;
pub mod convergence;
pub mod edit;
pub mod edit_run;
pub mod error_curves;
pub mod estimate;
pub mod intersect;
pub mod memory;
pub mod output;
pub mod plot;
pub mod reference;
pub mod scaling;
pub mod shards;
pub mod tessellation;
pub mod timings;

use std::borrow::Cow;
use std::time::Instant;

use glam::DVec3;

use crate::assets::teapot;
use crate::geometry::{GeometryBuilder, PatchMethod, Ray, SceneGeometry};

/// `text` as one CSV field (RFC 4180): quoted, with quotes doubled, when it holds a comma,
/// a quote or a line break; as it is otherwise.
pub fn csv_field(text: &str) -> Cow<'_, str> {
    if text.contains([',', '"', '\n', '\r']) {
        Cow::Owned(format!("\"{}\"", text.replace('"', "\"\"")))
    } else {
        Cow::Borrowed(text)
    }
}

/// Primary rays of a `width × height` pinhole view that frames the whole Utah teapot (z up),
/// one ray through each pixel centre, row by row from the top.
pub fn teapot_view(width: usize, height: usize) -> Vec<Ray> {
    let target = DVec3::new(0.2, 0.0, 1.4);
    let eye = target + 10.0 * DVec3::new(0.35, -1.0, 0.55).normalize();
    let forward = (target - eye).normalize();
    let right = forward.cross(DVec3::Z).normalize();
    let up = right.cross(forward);
    let half = (40.0f64.to_radians() * 0.5).tan();
    let aspect = width as f64 / height as f64;
    let mut rays = Vec::with_capacity(width * height);
    for y in 0..height {
        for x in 0..width {
            let sx = ((x as f64 + 0.5) / width as f64 * 2.0 - 1.0) * half * aspect;
            let sy = (1.0 - (y as f64 + 0.5) / height as f64 * 2.0) * half;
            rays.push(Ray::new(eye, forward + sx * right + sy * up));
        }
    }
    rays
}

/// The teapot's patches in a geometry using `method`.
pub fn teapot_geometry(method: PatchMethod) -> SceneGeometry {
    let mut builder = GeometryBuilder::with_patch_method(method);
    for patch in teapot() {
        builder.add_patch(patch, 0);
    }
    builder.build()
}

/// Timing of one intersector over one view.
#[derive(Clone, Debug)]
pub struct IntersectTiming {
    /// Intersector name.
    pub method: String,
    /// Rays that hit the teapot.
    pub hit_rays: usize,
    /// Rays that miss it.
    pub miss_rays: usize,
    /// Mean nanoseconds per hitting ray.
    pub ns_per_hit: f64,
    /// Mean nanoseconds per missing ray.
    pub ns_per_miss: f64,
}

/// Times `geometry.intersect` over `rays`, split into the rays that hit and those that miss,
/// repeating each set `repeat` times on the calling thread.
pub fn time_intersect(name: &str, geometry: &SceneGeometry, rays: &[Ray], repeat: usize) -> IntersectTiming {
    let (hits, misses): (Vec<Ray>, Vec<Ray>) = rays
        .iter()
        .partition(|r| geometry.intersect(r, f64::INFINITY).is_some());
    let time = |set: &[Ray]| {
        if set.is_empty() {
            return 0.0;
        }
        let start = Instant::now();
        let mut checksum = 0.0;
        for _ in 0..repeat {
            for ray in set {
                if let Some(h) = geometry.intersect(ray, f64::INFINITY) {
                    checksum += h.t;
                }
            }
        }
        let elapsed = start.elapsed().as_secs_f64();
        std::hint::black_box(checksum);
        elapsed * 1e9 / (set.len() * repeat) as f64
    };
    IntersectTiming {
        method: name.to_owned(),
        hit_rays: hits.len(),
        miss_rays: misses.len(),
        ns_per_hit: time(&hits),
        ns_per_miss: time(&misses),
    }
}

/// Seconds to re-prepare one edited patch of `geometry` (its subdivision and the BVH update,
/// [`SceneGeometry::update_patches`]), once per round, with control point `index` of `patch`
/// moved a little further each round as a drag moves it. Sorted, fastest first.
pub fn time_reprepare(geometry: &SceneGeometry, patch: usize, index: usize, rounds: usize) -> Vec<f64> {
    let mut g = geometry.clone();
    let Some((original, _)) = geometry.patches().get(patch).copied() else {
        return Vec::new();
    };
    let size = original.bounds().diagonal().length();
    let mut secs: Vec<f64> = (0..rounds)
        .map(|k| {
            let mut p = original;
            p.points[index % 16] += DVec3::new(0.3, -0.2, 0.25) * size * 0.01 * (k + 1) as f64;
            let start = Instant::now();
            std::hint::black_box(g.update_patches(&[(patch, p)]));
            start.elapsed().as_secs_f64()
        })
        .collect();
    secs.sort_by(f64::total_cmp);
    secs
}

#[cfg(test)]
mod tests {
    #[test]
    fn csv_fields_are_quoted_only_when_they_must_be() {
        assert_eq!(super::csv_field("tessellated 4x4"), "tessellated 4x4");
        assert_eq!(
            super::csv_field("exact (per-ray, depth 5)"),
            "\"exact (per-ray, depth 5)\""
        );
        assert_eq!(super::csv_field("a \"b\""), "\"a \"\"b\"\"\"");
    }
}
