//! The eye pass: visible points traced through the pixels — once for classic PPM (pinhole,
//! no anti-aliasing; glass paths split), every pass for stochastic PPM (Hachisuka & Jensen
//! 2009: one jittered point per pixel) — and the spatial index over them.

use glam::{DVec2, DVec3, Vec3};
use rand::Rng;
use rand_pcg::Pcg64Mcg;
use rayon::prelude::*;

use super::config::Config;
use super::estimate::Slot;
use super::hash_grid::HashGrid;
use super::index::SpatialIndex;
use super::kd_tree::KdTree;
use super::light::LightSeen;
use super::points::{Place, VisiblePoints};
use super::reuse::{PathKind, Reuse};
use super::seen;
use super::streams;
use super::visible::{trace_eye, Branching, ShadowRays, VisiblePoint};
use crate::render::bsdf::Bsdf;
use crate::render::rng::stream_rng;
use crate::render::sequence;
use crate::scene::Scene;
use crate::settings::IndexKind;

/// A pass's visible points and the spatial index over them, kept while the points stay.
#[derive(Default)]
pub struct EyePass {
    /// This pass's visible points (classic PPM: the one eye pass's).
    pub points: VisiblePoints,
    /// Per pixel, what its eye path was in this stochastic pass ([`super::reuse`]).
    pub kinds: Vec<PathKind>,
    /// With [`EyeJob::keep_copy`], a copy of this stochastic pass's points, one place a pixel
    /// (placeholders kept).
    pub copy: VisiblePoints,
    /// The hash grid over the points as they lie now, kept while no eye pass replaces them
    /// (classic PPM traces one) for as long as it serves the shrinking radii
    /// ([`HashGrid::serves`]).
    kept_grid: Option<HashGrid>,
}

/// What an eye pass needs besides the scene: the render's choices, the pass whose random
/// streams it uses, and what may interrupt it.
pub struct EyeJob<'a> {
    /// The render's choices.
    pub config: &'a Config,
    /// The pass of the random streams.
    pub pass: u64,
    /// Polled during the pass; true abandons it.
    pub interrupt: Option<&'a (dyn Fn() -> bool + Send + Sync)>,
    /// The previous pass's points, to copy where the pass would find them again (a warm
    /// epoch's first pass, [`super::reuse`]).
    pub reuse: Option<&'a Reuse<'a>>,
    /// Whether to keep a copy of the points in pixel order ([`EyePass::copy`]), for a warm
    /// restart's reuse.
    pub keep_copy: bool,
}

impl EyePass {
    /// Stochastic PPM's eye pass: one eye ray per pixel (jittered, through the lens), in
    /// parallel, written in place: each pixel's visible point (at most one: glass is chosen,
    /// not split) into `points` at the pixel's index, its directly seen light into the pass's
    /// light seen; pixels without a point are then squeezed out. Nothing is allocated per
    /// pixel, and the buffers keep their capacity from pass to pass. With `observe`, the
    /// pass's light seen chooses pixels to supersample ([`LightSeen::observe`]). `false` when
    /// interrupted (the pass is then traced again, so the half-written buffers do not matter).
    pub fn trace_stochastic(
        &mut self,
        job: &EyeJob,
        scene: &Scene,
        light: &mut LightSeen,
        observe: bool,
    ) -> bool {
        let config = job.config;
        let (w, h) = (config.width as u64, config.height as u64);
        let pass = job.pass;
        let (direct_light, seed) = (config.direct_light, config.seed);
        let sequences = config
            .stratified_eye_rays
            .then(|| (sequence::r4(pass)[0], sequence::golden(pass)));
        let interrupt = job.interrupt;
        let skipped = std::sync::atomic::AtomicBool::new(false);
        let pixels = (w * h) as usize;
        // New points: the grid over the old ones no longer holds them.
        self.kept_grid = None;
        // A warm epoch's first pass starts from the previous pass's points, each pixel's at
        // its place, and traces only the pixels an edit may have changed.
        match job.reuse {
            Some(r) if r.points().len() == pixels => self.points.copy_from(r.points()),
            _ => self.points.reset(pixels, Bsdf::scene_has_glossy(scene)),
        }
        let reuse = job.reuse.filter(|r| r.points().len() == pixels);
        let (seen, pass_direct) = light.start_stochastic_pass();
        self.kinds.clear();
        self.kinds.resize(pixels, PathKind::Other);
        let rays = scene.camera.eye_rays();
        let tracer = PixelTracer {
            subsampler: seen::Subsampler {
                scene,
                rays: &rays,
                seed,
                pass,
                pixels: w * h,
                stratified: config.stratified_eye_rays,
                direct_light,
            },
            seen,
            reuse,
            sequences,
            width: w,
        };
        self.points
            .places_mut()
            .zip(pass_direct.par_iter_mut())
            .zip(self.kinds.par_iter_mut())
            .enumerate()
            .for_each(|(i, ((place, direct), kind))| {
                if interrupt.is_some_and(|f| f()) {
                    skipped.store(true, std::sync::atomic::Ordering::Relaxed);
                    return;
                }
                (*direct, *kind) = tracer.trace(i as u64, place);
            });
        if skipped.into_inner() {
            return false;
        }
        if observe {
            light.observe(w as usize);
        }
        if job.keep_copy {
            self.copy.copy_from(&self.points);
        }
        self.points.drop_empty();
        true
    }

    /// Classic PPM's points: those of its one eye pass ([`trace_classic`]), each given a new
    /// slot of its pixel (its `slot` holds the pixel until then) at the end of `slots`.
    pub fn set_classic(&mut self, points: Vec<VisiblePoint>, slots: &mut Vec<Slot>) {
        self.kept_grid = None;
        self.points = points.into_iter().collect();
        for shade in &mut self.points.shade {
            let pixel = shade.slot;
            shade.slot = slots.len() as u32;
            slots.push(Slot::new(pixel));
        }
    }

    /// The spatial index of kind `kind` over the points, their radii first copied from their
    /// `slots` (the hash grid puts the points in its order; the last pass's grid is used
    /// again, when `reuse` allows, if the points are the same and it serves their radii), and
    /// each estimate's largest radius².
    pub fn index(&mut self, slots: &[Slot], kind: IndexKind, reuse: bool) -> (SpatialIndex, [f32; 2]) {
        let largest = self.points.set_radii(slots);
        let reach = (largest[0].max(largest[1]) as f64).sqrt();
        let index = match kind {
            IndexKind::HashGrid => match self.kept_grid.take() {
                Some(grid) if reuse && grid.serves(reach) => SpatialIndex::Grid(grid),
                _ => {
                    let (grid, mut order) = HashGrid::build(&self.points.reach);
                    self.points.permute(&mut order);
                    SpatialIndex::Grid(grid)
                }
            },
            IndexKind::KdTree => SpatialIndex::Kd(KdTree::build(&self.points.reach)),
        };
        (index, largest)
    }

    /// Keeps the hash grid for the next pass, should its points not change.
    pub fn keep(&mut self, index: SpatialIndex) {
        if let SpatialIndex::Grid(grid) = index {
            self.kept_grid = Some(grid);
        }
    }
}

/// What one pixel's eye path in a stochastic pass needs besides its place: the scene, the
/// pass and its streams (held by the supersampler, which needs them too), the pixels chosen
/// to supersample, and the previous pass's points a warm epoch's first pass may copy.
struct PixelTracer<'a> {
    subsampler: seen::Subsampler<'a>,
    seen: &'a seen::SeenLight,
    reuse: Option<&'a Reuse<'a>>,
    /// This pass's points of the lens and first-choice sequences, with stratified eye rays.
    sequences: Option<(DVec2, f64)>,
    width: u64,
}

impl PixelTracer<'_> {
    /// Traces pixel `i`'s eye path into `place` (or keeps the previous pass's point there,
    /// [`Reuse`]): the light it saw directly and what the path was.
    fn trace(&self, i: u64, mut place: Place) -> (Vec3, PathKind) {
        let sub = &self.subsampler;
        let (x, y) = (i % self.width, i / self.width);
        // A supersampled pixel's light seen comes from its extra rays alone, so its own ray
        // needs no shadow rays (they draw no random numbers: the point is the same).
        let chosen = self.seen.chosen(i as usize);
        // The previous pass's point, already in place, where it is still right.
        let reuse = self.reuse.filter(|_| !chosen);
        if reuse.is_some_and(|r| r.copies_unseen(i as usize, x, y)) {
            return (Vec3::ZERO, PathKind::Copied);
        }
        let mut rng = stream_rng(sub.seed, streams::EYE, sub.pass * sub.pixels + i);
        let (jitter, lens, first) = eye_sample(sub.seed, sub.pass, i, self.sequences, &mut rng);
        let px = DVec2::new(x as f64, y as f64) + jitter;
        let ray = sub.rays.ray_with_lens_sample(px, lens);
        if let Some(r) = reuse {
            if r.copies(i as usize, &ray) {
                return (Vec3::ZERO, PathKind::Copied);
            }
            place.clear();
        }
        let mut sink = |vp: VisiblePoint| place.set(&vp);
        let traced = trace_eye(
            sub.scene,
            &ray,
            i as u32,
            Branching::Choose { first },
            ShadowRays::new(sub.direct_light, !chosen),
            &mut rng,
            &mut sink,
        );
        let direct = if chosen {
            sub.light_seen(i, x, y, self.seen.subsamples(i as usize))
        } else {
            traced.direct
        };
        (
            direct.as_vec3(),
            PathKind::traced(traced.rays, traced.direct, chosen),
        )
    }
}

/// Classic PPM's one eye pass: an eye ray through each pixel centre, split at glass, rows
/// in parallel. Per pixel: the directly seen light; per visible point: the point, its
/// `slot` holding its pixel. `None` when interrupted.
pub fn trace_classic(job: &EyeJob, scene: &Scene) -> Option<(Vec<DVec3>, Vec<VisiblePoint>)> {
    let config = job.config;
    let (w, h) = (config.width as u64, config.height as u64);
    let pass = job.pass;
    let (direct_light, seed) = (config.direct_light, config.seed);
    let interrupt = job.interrupt;
    let skipped = std::sync::atomic::AtomicBool::new(false);
    let rays = scene.camera.eye_rays();
    let rows: Vec<(Vec<DVec3>, Vec<VisiblePoint>)> = (0..h)
        .into_par_iter()
        .map(|y| {
            let (mut direct, mut points) = (Vec::with_capacity(w as usize), Vec::new());
            if interrupt.is_some_and(|f| f()) {
                skipped.store(true, std::sync::atomic::Ordering::Relaxed);
                return (direct, points);
            }
            for x in 0..w {
                let i = y * w + x;
                let mut rng = stream_rng(seed, streams::EYE, pass * w * h + i);
                let px = Scene::pixel_center(x as u32, y as u32);
                direct.push(
                    trace_eye(
                        scene,
                        &rays.ray(px, DVec2::ZERO),
                        i as u32,
                        Branching::Split,
                        ShadowRays::new(direct_light, true),
                        &mut rng,
                        &mut |vp| points.push(vp),
                    )
                    .direct,
                );
            }
            (direct, points)
        })
        .collect();
    if skipped.into_inner() {
        return None;
    }
    let mut direct = Vec::with_capacity((w * h) as usize);
    let mut points = Vec::new();
    for (d, p) in rows {
        direct.extend(d);
        points.extend(p);
    }
    Some((direct, points))
}

/// Pixel `i`'s eye-ray numbers in pass `pass`: its place in the pixel, its place on the lens
/// and the number of its first choice at glass. With `sequences` (this pass's points of R4 over
/// the lens and of the golden-ratio sequence) they are the pass's points of the pixel's
/// sequences, shifted by the pixel's own offsets, the same every pass (their own stream, so
/// the path's other random numbers stay as they were); without, independent numbers from `rng`.
fn eye_sample(
    seed: u64,
    pass: u64,
    i: u64,
    sequences: Option<(DVec2, f64)>,
    rng: &mut Pcg64Mcg,
) -> (DVec2, DVec2, Option<f64>) {
    match sequences {
        Some((lens, choice)) => {
            let mut offsets = stream_rng(seed, streams::EYE_OFFSETS, i);
            let jitter = sequence::sobol(pass, offsets.random());
            let offset = DVec2::new(offsets.random(), offsets.random());
            let first = sequence::rotated_1d(choice, offsets.random());
            (jitter, sequence::rotated(lens, offset), Some(first))
        }
        None => (
            DVec2::new(rng.random(), rng.random()),
            DVec2::new(rng.random(), rng.random()),
            None,
        ),
    }
}
