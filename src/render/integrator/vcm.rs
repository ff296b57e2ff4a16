//! Vertex connection and merging as a renderer ([`crate::render::vcm`] has the estimator):
//! each pass traces one light subpath per pixel, then one camera subpath per pixel, and adds
//! the camera subpaths' radiance and what the light subpaths put on the film through the lens
//! to the image, which is the mean of its passes. Every random number comes from
//! `(seed, stream, pass · pixels + index)`, and light tracing's contributions are added in
//! subpath order: the image is the same for any number of threads.
//!
//! Pass `i`'s radius and random streams depend on `(scene, i)` alone, so any set of passes
//! can be rendered apart and their sums merged ([`Vcm::render_only`], `render --shard`).

use std::time::Instant;

use glam::DVec3;
use rayon::prelude::*;

use super::{Control, Integrator, PassPlan, Setup};
use crate::render::frame::{Frame, FrameStats, StatRow};
use crate::render::provenance;
use crate::render::rng::stream_rng;
use crate::render::sequence;
use crate::render::shard::{PassSet, PassSums};
use crate::render::vcm::camera_path::{CameraPath, PassData};
use crate::render::vcm::light_path::{self, LightPath, LightVertex, Photons};
use crate::render::vcm::radius::automatic_radius;
use crate::render::vcm::{PassConstants, Techniques};
use crate::scene::Scene;
use crate::settings::{RenderParams, RendererKind};

/// Random streams of vertex connection and merging (the path tracer's are 20–21).
mod streams {
    /// One light subpath.
    pub const LIGHT: u64 = 30;
    /// One camera subpath.
    pub const CAMERA: u64 = 31;
    /// Each pixel's fixed offsets of its sample sequences.
    pub const OFFSETS: u64 = 32;
}

/// Rows of pixels (camera subpaths, and as many light subpaths) between two questions to
/// the caller.
const BATCH_ROWS: usize = 8;

/// What a render by vertex connection and merging did.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize)]
pub struct VcmStats {
    /// Completed passes.
    pub passes: u32,
    /// The initial merging radius.
    pub initial_radius: f64,
    /// The last pass's merging radius.
    pub radius: f64,
    /// Light vertices kept (on smooth surfaces), all passes.
    pub light_vertices: u64,
    /// Segments traced by light and camera subpaths (shadow rays not counted).
    pub segments: u64,
    /// Light vertices merged with.
    pub merged: u64,
    /// Seconds spent in completed passes.
    pub elapsed_secs: f64,
}

/// A render by vertex connection and merging: each pixel's sum of pass estimates.
pub struct Vcm {
    setup: Setup,
    size: (u32, u32),
    techniques: Techniques,
    sums: Vec<DVec3>,
    stats: VcmStats,
    /// The passes of the render this one renders, in order (all of them unless a shard's).
    passes: PassSet,
    /// The rendered passes' exact sums, kept when a set of passes was chosen
    /// ([`Vcm::render_only`]).
    part: Option<PassSums>,
}

impl Vcm {
    /// Nothing traced yet; both halves of the estimator on.
    pub fn new(scene: &Scene, setup: &Setup) -> Self {
        Self::with_techniques(scene, setup, Techniques::ALL)
    }

    /// Nothing traced yet, with the techniques given: connections alone make a bidirectional
    /// path tracer, merges alone progressive photon mapping (at least one must be on).
    pub fn with_techniques(scene: &Scene, setup: &Setup, techniques: Techniques) -> Self {
        assert!(techniques.connect || techniques.merge, "VCM needs connections or merges");
        let size = (scene.camera.width, scene.camera.height);
        Self {
            setup: setup.clone(),
            size,
            techniques,
            sums: vec![DVec3::ZERO; size.0 as usize * size.1 as usize],
            stats: VcmStats::default(),
            passes: PassSet::default(),
            part: None,
        }
    }

    /// Renders only `passes` of the render (a shard's, or a part's own list), in order, and
    /// keeps their exact sums ([`Vcm::pass_sums`]) for a part file.
    pub fn render_only(&mut self, passes: PassSet) {
        self.passes = passes;
        self.part = Some(PassSums::new(self.size.0, self.size.1));
    }

    /// The exact sums of the passes rendered, after [`Vcm::render_only`].
    pub fn pass_sums(&self) -> Option<&PassSums> {
        self.part.as_ref()
    }

    /// Adds pass `index`'s image (one estimate per pixel) to the sums, and to the part's.
    fn add_to_sums(&mut self, index: u32, image: &[DVec3]) {
        for (sum, v) in self.sums.iter_mut().zip(image) {
            *sum += *v;
        }
        if let Some(part) = &mut self.part {
            part.add_pass(index, image, image.len() as u64);
        }
    }

    /// The index in the render of the next pass this one renders.
    fn next_pass(&self) -> u64 {
        self.passes.pass(self.stats.passes)
    }

    /// What it did so far.
    pub fn stats(&self) -> &VcmStats {
        &self.stats
    }

    /// The light subpaths of the coming pass, `None` when abandoned.
    fn light_paths(
        &self,
        (scene, target): (&Scene, Option<(DVec3, f64)>),
        k: &PassConstants,
        live: &mut RenderParams,
        control: &mut dyn FnMut(&mut RenderParams) -> Control,
    ) -> Option<LightPaths> {
        let n = self.sums.len();
        let (seed, pass) = (scene.params.seed, self.next_pass());
        let batch = (BATCH_ROWS * self.size.0 as usize).max(1);
        let mut paths = LightPaths {
            vertices: Vec::new(),
            starts: Vec::with_capacity(n + 1),
            image: vec![DVec3::ZERO; n],
            segments: 0,
        };
        let mut traced = Vec::with_capacity(batch);
        for first in (0..n).step_by(batch) {
            if control(live) == Control::Abort || self.setup.interrupted() {
                return None;
            }
            let range = first..(first + batch).min(n);
            traced.clear();
            traced.par_extend(range.into_par_iter().map(|i| {
                light_path::trace(scene, k, target, stream_rng(seed, streams::LIGHT, pass * n as u64 + i as u64))
            }));
            // Flattened batch by batch, so that the subpaths' own lists never hold a whole
            // pass's vertices beside the flat list.
            for path in traced.drain(..) {
                paths.add(path);
            }
        }
        paths.starts.push(paths.vertices.len());
        Some(paths)
    }

    /// One camera subpath of pixel `i`: its radiance, segments and merges.
    fn camera_sample(&self, pass: &PassData, own: &[LightVertex], i: u64) -> (DVec3, u64, u64) {
        let scene = pass.scene;
        let (n, seed, index) = (self.sums.len() as u64, scene.params.seed, self.next_pass());
        let ray = sequence::pixel_ray(&scene.camera, index, i, &mut stream_rng(seed, streams::OFFSETS, i));
        let mut path = CameraPath {
            pass,
            own,
            rng: stream_rng(seed, streams::CAMERA, index * n + i),
            segments: 0,
            merged: 0,
        };
        let l = path.radiance(ray);
        // A path that met a numerical accident carries no light rather than a NaN.
        let l = if l.is_finite() { l } else { DVec3::ZERO };
        (l, path.segments, path.merged)
    }
}

impl Integrator for Vcm {
    fn render_pass(
        &mut self,
        scene: &Scene,
        plan: &PassPlan,
        control: &mut dyn FnMut(&mut RenderParams) -> Control,
    ) -> bool {
        let start = Instant::now();
        if self.stats.passes == 0 {
            self.stats.initial_radius = scene.params.initial_radius.unwrap_or_else(|| automatic_radius(scene));
        }
        let n = self.sums.len();
        let max_length = scene.params.max_depth.max(1) * 4 + 1;
        // A pass of the render's passes (`--passes`, at most a u32).
        let index = u32::try_from(self.next_pass()).unwrap_or(u32::MAX);
        let k = PassConstants::new(
            self.techniques,
            self.stats.initial_radius,
            plan.params.alpha,
            index,
            n,
            max_length,
        );
        // Nothing here is a live setting: the settings it gets back are left alone.
        let mut live = plan.params.clone();
        // What point lights outside the scene aim their emission at.
        let target = scene.geometry.bounding_sphere();
        let Some(LightPaths {
            vertices,
            starts,
            mut image,
            mut segments,
        }) = self.light_paths((scene, target), &k, &mut live, control)
        else {
            return false;
        };
        let photons = k.techniques.merge.then(|| Photons::build(&vertices, k.radius));
        let light_of = scene.light_of_objects();
        let pass = PassData {
            scene,
            k: &k,
            light_of: &light_of,
            target,
            vertices: &vertices,
            photons: photons.as_ref(),
        };
        let width = self.size.0 as usize;
        let mut merged = 0;
        for (batch, rows) in image.chunks_mut(BATCH_ROWS * width).enumerate() {
            if control(&mut live) == Control::Abort || self.setup.interrupted() {
                return false;
            }
            let first = batch * BATCH_ROWS * width;
            let counts: (u64, u64) = rows
                .par_iter_mut()
                .enumerate()
                .map(|(j, out)| {
                    let i = first + j;
                    let (l, s, m) = self.camera_sample(&pass, &vertices[starts[i]..starts[i + 1]], i as u64);
                    *out += l;
                    (s, m)
                })
                .reduce(|| (0, 0), |a, b| (a.0 + b.0, a.1 + b.1));
            segments += counts.0;
            merged += counts.1;
        }
        if self.setup.interrupted() {
            return false;
        }
        self.add_to_sums(index, &image);
        let s = &mut self.stats;
        s.passes += 1;
        s.radius = k.radius;
        s.light_vertices += vertices.len() as u64;
        s.segments += segments;
        s.merged += merged;
        s.elapsed_secs += start.elapsed().as_secs_f64();
        true
    }

    fn passes(&self) -> u32 {
        self.stats.passes
    }

    fn frame(&self, epoch: u64, elapsed_secs: f64) -> Frame {
        let n = self.stats.passes.max(1) as f64;
        let radiance = self.sums.iter().map(|s| (*s / n).as_vec3().to_array()).collect();
        let mut frame = Frame::of_radiance(
            self.size,
            radiance,
            self.stats.passes,
            (epoch, elapsed_secs),
            frame_stats(&self.stats),
        );
        // Light subpaths traced: what error estimates scale by, as photons are for photon
        // mapping.
        frame.photons = self.stats.passes as u64 * self.sums.len() as u64;
        frame
    }
}

/// A pass's light subpaths, flattened: every vertex, where each subpath's begin, and what
/// they put on the film through the lens.
struct LightPaths {
    /// Every subpath's vertices, subpath after subpath.
    vertices: Vec<LightVertex>,
    /// Subpath `i`'s vertices are `vertices[starts[i]..starts[i + 1]]`.
    starts: Vec<usize>,
    /// Light tracing's image: each pixel's sum over the subpaths, added in subpath order.
    image: Vec<DVec3>,
    /// Segments traced.
    segments: u64,
}

impl LightPaths {
    /// Appends the next subpath.
    fn add(&mut self, path: LightPath) {
        self.starts.push(self.vertices.len());
        self.vertices.extend(path.vertices);
        for (pixel, value) in path.splats {
            self.image[pixel as usize] += value;
        }
        self.segments += path.segments;
    }
}

/// The statistics as a frame's.
fn frame_stats(s: &VcmStats) -> FrameStats {
    let segment_rate = s.segments as f64 / s.elapsed_secs.max(1e-9);
    let per_pass = |x: u64| x as f64 / s.passes.max(1) as f64;
    FrameStats {
        kind: RendererKind::Vcm,
        seconds: s.elapsed_secs,
        rows: vec![
            StatRow::new(
                "Radius",
                format!("{:.3e}", s.radius),
                "The merging radius of the last pass (it shrinks pass by pass with alpha)",
            ),
            StatRow::new(
                "Light vertices",
                format!("{:.0}", per_pass(s.light_vertices)),
                "Light subpath vertices on smooth surfaces a pass: what camera subpaths connect to and merge with",
            ),
            StatRow::new("Segments/s", format!("{segment_rate:.0}"), "Subpath segments traced per second"),
        ],
        summary: vec![format!(
            ", {} passes in {:.2} s (radius {:.3e} → {:.3e}, {:.0} light vertices and {:.0} merges a pass, {segment_rate:.0} segments/s)",
            s.passes,
            s.elapsed_secs,
            s.initial_radius,
            s.radius,
            per_pass(s.light_vertices),
            per_pass(s.merged),
        )],
        skipped: Vec::new(),
        json: serde_json::json!({ "vcm": s }),
        metadata: vec![
            (provenance::PASSES.into(), s.passes.to_string()),
            ("caustic:elapsed_secs".into(), format!("{:.3}", s.elapsed_secs)),
            ("caustic:vcm_initial_radius".into(), format!("{:e}", s.initial_radius)),
        ],
        progress: String::new(),
    }
}
