//! Progressive photon mapping (Hachisuka, Ogaki & Jensen 2008) and its stochastic variant
//! (Hachisuka & Jensen 2009), as the seed report §3.2 describes it, physically scaled.
//!
//! Each pass: (1) the eye pass records visible points ([`visible`]) — once for a pinhole
//! camera without anti-aliasing (classic PPM, glass paths split), or every pass with jittered
//! pixel and lens samples (stochastic PPM, one point per pixel, per-pixel statistics); (2) a
//! spatial index over the points is built ([`HashGrid`] or the seed's [`KdTree`]); (3) photons
//! are traced ([`photon`]) and hand flux to points within their radius; (4) every statistics
//! slot is updated with the paper's rule
//!
//! `N' = N + αM`, `R'² = R²·(N + αM)/(N + M)`, `τ' = (τ + φ)·(N + αM)/(N + M)`;
//!
//! and the radiance is `L = τ / (π R² N_emitted)` plus light seen directly. No brightness
//! factor: exposure belongs to the viewer. After the first pass, two per-point choices are
//! made from its photon counts: the indirect estimate's radius ([`Ppm::widen_indirect`]) and,
//! where photons are dense, a narrower restart of the primary one ([`Ppm::narrow_dense`], the
//! adaptive radius: in the spirit of classic photon mapping's k-nearest-neighbour radius,
//! Jensen 2001, chosen once and then shrunk by the paper's rule).
//!
//! Determinism: photon `i` of the render uses the random stream `(seed, photon, i)`, pixels
//! `(seed, pass, pixel)`; photons are traced in fixed chunks whose deposits are applied in
//! chunk order, so the image is bit-identical for any number of threads.

pub mod direct;
pub mod guide;
pub mod hash_grid;
pub mod kd_tree;
pub mod photon;
pub mod visible;

use std::f64::consts::PI;
use std::sync::Arc;
use std::time::Instant;

use glam::{DVec2, DVec3, Vec3};
use rand::Rng;
use rayon::prelude::*;

use guide::{EmissionGuide, GuideTally};
pub use hash_grid::HashGrid;
pub use kd_tree::KdTree;
use photon::{PhotonCounts, PhotonSource};
use visible::{trace_eye, Branching, VisiblePoint};

use super::rng::stream_rng;
use super::sequence;
use crate::scene::camera::concentric_disk;
use crate::scene::Scene;
use crate::settings::IndexKind;

/// Random stream ids of photon mapping.
mod streams {
    pub const EYE: u64 = 10;
    pub const PHOTON: u64 = 11;
    /// Each pixel's fixed offsets of its eye-ray sequences (12 is `direct`'s).
    pub const EYE_OFFSETS: u64 = 13;
}

/// How the indirect estimate's radius is chosen ([`RenderParams::indirect_radius_scale`]).
///
/// [`RenderParams::indirect_radius_scale`]: crate::settings::RenderParams::indirect_radius_scale
#[derive(Clone, Copy, Debug, PartialEq)]
enum IndirectScale {
    /// One estimate for all photons.
    Off,
    /// From the first pass's photon density ([`Ppm::widen_indirect`]).
    Automatic,
    /// This multiple of the initial radius.
    Fixed(f64),
}

/// Indirect photons an automatic indirect radius aims to hand each point per pass.
const INDIRECT_PHOTONS: f64 = 32.0;
/// The widest automatic indirect radius, over the initial radius.
const MAX_INDIRECT_SCALE: f64 = 4.0;

/// Photons a pass should hand a point after the radius is narrowed where photons are dense
/// ([`Ppm::narrow_dense`]).
const DENSE_PHOTONS: f64 = 64.0;
/// The most an adaptive radius narrows a point's initial radius (in radius, not area).
const MAX_NARROWING: f64 = 4.0;

/// Photons per chunk: the unit of parallel work and of deterministic reduction.
const CHUNK: u64 = 4096;
/// Photons per batch unless [`PpmOptions::batch_photons`] says otherwise: the caller's
/// control callback is asked between batches.
pub const DEFAULT_BATCH_PHOTONS: u64 = 16 * CHUNK;

/// Deposits one chunk may hold before they are merged per slot: bounds memory when radii are
/// large (every photon then reaches thousands of points).
const MAX_CHUNK_DEPOSITS: usize = 1 << 20;

/// Flux handed to a statistics slot: `(slot, flux × point weight, photon count)`.
type Deposit = (u32, DVec3, u32);

/// A visible point's position and its estimates' radii², packed for the candidate test.
type Reach = [f64; 5];

/// What one chunk of photons left: its deposits, counts and guide tally.
type ChunkResult = (Vec<Deposit>, PhotonCounts, Option<GuideTally>);

/// Merges deposits to the same slot, keeping each slot's additions in photon order (a stable
/// sort), so the sums depend only on the chunk's photons, not on threads.
fn compact(deposits: &mut Vec<Deposit>) {
    deposits.sort_by_key(|d| d.0);
    let mut merged: Vec<Deposit> = Vec::with_capacity(deposits.len() / 4);
    for &(slot, flux, count) in deposits.iter() {
        match merged.last_mut() {
            Some(last) if last.0 == slot => {
                last.1 += flux;
                last.2 += count;
            }
            _ => merged.push((slot, flux, count)),
        }
    }
    *deposits = merged;
}

/// How photon mapping runs, beyond the scene's render parameters (which hold every setting
/// that changes the image or its speed a user chooses: α, photons, index, direct light, …).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PpmOptions {
    /// Force stochastic PPM (a new eye pass every pass) even for a pinhole camera.
    pub force_stochastic: bool,
    /// Photons traced between two calls of the control callback (rounded up to whole
    /// 4096-photon chunks). Smaller batches let a viewer react sooner; the image does not
    /// depend on it.
    pub batch_photons: u64,
}

impl Default for PpmOptions {
    fn default() -> Self {
        Self {
            force_stochastic: false,
            batch_photons: DEFAULT_BATCH_PHOTONS,
        }
    }
}

/// A built spatial index.
pub enum SpatialIndex {
    /// Hash grid.
    Grid(HashGrid),
    /// kd-tree.
    Kd(KdTree),
}

impl SpatialIndex {
    /// Calls `f` with candidate points near `p` (the caller checks the radius).
    #[inline]
    pub fn for_candidates(&self, points: &[VisiblePoint], p: DVec3, f: &mut impl FnMut(u32)) {
        match self {
            SpatialIndex::Grid(g) => g.candidates(p).iter().for_each(|&k| f(k)),
            SpatialIndex::Kd(t) => t.for_candidates(points, p, f),
        }
    }
}

/// The empty visible point (no slot): a stochastic eye pass's placeholder for a pixel whose
/// path found no diffuse surface.
const NO_POINT: VisiblePoint = VisiblePoint {
    slot: u32::MAX,
    position: DVec3::ZERO,
    normal: DVec3::ZERO,
    weight: DVec3::ZERO,
    radius2: 0.0,
};

/// One progressive density estimate (Hachisuka et al. 2008 §4): search radius², photon
/// count `N` and flux `τ`, updated after every pass.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Estimate {
    /// Search radius².
    pub radius2: f64,
    /// Accumulated photon count `N`.
    pub n: f64,
    /// Accumulated flux `τ`.
    pub tau: DVec3,
}

impl Estimate {
    /// Folds in a pass that brought `m` photons of flux `phi` within the radius (eqs. 6–11):
    /// the radius shrinks so that a share α of the new photons is kept.
    fn update(&mut self, phi: DVec3, m: u32, alpha: f64) {
        let m = m as f64;
        if m > 0.0 {
            let g = (self.n + alpha * m) / (self.n + m);
            self.radius2 *= g;
            self.tau = (self.tau + phi) * g;
            self.n += alpha * m;
        }
    }

    /// The estimate brought to radius² `radius2` as PPM's update assumes, for a density
    /// uniform within the radius: N and τ scaled by the area (an estimate without a radius
    /// holds nothing to scale).
    fn resized(self, radius2: f64) -> Self {
        let share = if self.radius2 > 0.0 {
            radius2 / self.radius2
        } else {
            0.0
        };
        Self {
            radius2,
            n: self.n * share,
            tau: self.tau * share,
        }
    }

    /// Reflected radiance `τ/(π R² N_emitted)`.
    fn radiance(&self, emitted: f64) -> DVec3 {
        if self.radius2 > 0.0 {
            self.tau / (PI * self.radius2 * emitted)
        } else {
            DVec3::ZERO
        }
    }
}

/// Accumulated statistics of one gathering point (classic PPM) or pixel (stochastic PPM): two
/// estimates, since photons that have bounced off a diffuse surface carry light that varies
/// slowly and are gathered over a wider radius ([`RenderParams::indirect_radius_scale`]).
///
/// [`RenderParams::indirect_radius_scale`]: crate::settings::RenderParams::indirect_radius_scale
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Slot {
    /// The pixel it contributes to.
    pub pixel: u32,
    /// Photons straight from a light or through mirrors and glass only: direct light (when
    /// light sampling is off) and caustics — every photon when one estimate is kept
    /// (`indirect_radius_scale = 1`).
    pub primary: Estimate,
    /// Photons after a diffuse bounce (indirect light), when the scale is above 1.
    pub indirect: Estimate,
    /// Whether the primary estimate was restarted with a narrower radius after the first
    /// pass (adaptive radius).
    pub restart: Restart,
}

/// A primary estimate's restart with a narrower radius ([`Ppm::narrow_dense`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Restart {
    /// Not restarted: it counts every pass.
    #[default]
    None,
    /// Narrowed after the first pass: its radius is the new one, its flux the first pass's
    /// (scaled by the area, so the image does not change) until the second pass replaces it.
    Pending,
    /// Restarted at the second pass: the first pass's photons do not count for it.
    Restarted,
}

impl Slot {
    /// An empty slot of `pixel` (its radii are set before the first pass).
    fn new(pixel: u32) -> Self {
        Self {
            pixel,
            primary: Estimate::default(),
            indirect: Estimate::default(),
            restart: Restart::None,
        }
    }

    /// The larger search radius², which the spatial index must reach.
    fn reach2(&self) -> f64 {
        self.primary.radius2.max(self.indirect.radius2)
    }
}

/// What one pass's photons left: flux `Φ` and photon count `M` per slot and estimate (index
/// `2 × slot + estimate`, 0 primary, 1 indirect), and counts. A pass's flux is summed in f32
/// (12 bytes instead of 24 per estimate: at 1920×1080 this keeps the peak under 1 GiB with
/// two estimates per slot); τ accumulates the passes in f64.
struct Gathered {
    phi: Vec<Vec3>,
    m: Vec<u32>,
    counts: PhotonCounts,
    /// Emitted and useful photons per light and bin, when emission is guided.
    tally: Option<GuideTally>,
}

/// Run statistics.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize)]
pub struct PpmStats {
    /// Completed passes.
    pub passes: u32,
    /// Photons emitted in completed passes.
    pub photons: u64,
    /// Photon bounces traced.
    pub bounces: u64,
    /// Flux deposits made.
    pub deposits: u64,
    /// Photon paths that handed flux to at least one visible point (the share of `photons`
    /// that did any good).
    pub useful_paths: u64,
    /// Visible points in the last pass.
    pub visible_points: usize,
    /// Mean search radius over slots that have gathered photons (scene units).
    pub mean_radius: f64,
    /// The indirect estimate's initial radius over the primary's (1: one estimate for all
    /// photons; chosen after the first pass when automatic).
    pub indirect_radius_scale: f64,
    /// Share of the statistics slots whose estimate restarted with a narrower radius after
    /// the first pass (adaptive radius; 0 before it or when off).
    pub narrowed_share: f64,
    /// Seconds spent in completed passes.
    pub elapsed_secs: f64,
    /// Seconds spent tracing photons.
    pub photon_secs: f64,
    /// Seconds spent in eye passes (tracing and setting up visible points).
    pub eye_secs: f64,
    /// Seconds spent building the spatial index over visible points.
    pub index_secs: f64,
    /// Seconds spent sampling area lights at the visible points.
    pub direct_secs: f64,
    /// Eye passes run.
    pub eye_passes: u32,
    /// Work the scene did not need, in words.
    pub skipped: Vec<String>,
}

/// Whether a pass ran to the end.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PassOutcome {
    /// Finished and folded into the statistics.
    Completed,
    /// Abandoned between two batches at the caller's request; nothing of it was kept.
    Aborted,
}

/// What the caller wants between two photon batches (it may also change α, which the
/// callback receives by reference and which applies to this pass's update).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Control {
    /// Go on.
    Continue,
    /// Drop this pass.
    Abort,
}

/// A progressive photon mapping render in progress.
pub struct Ppm {
    options: PpmOptions,
    /// Direct light by light sampling (from the render parameters).
    direct_light: bool,
    /// The spatial index (from the render parameters).
    index: IndexKind,
    stochastic: bool,
    /// Eye rays placed by low-discrepancy sequences over passes (from the render parameters).
    stratified_eye_rays: bool,
    /// How the indirect estimate's radius is chosen (from the render parameters).
    indirect_scale: IndirectScale,
    /// Narrow the primary radius where the first pass found photons dense (from the render
    /// parameters).
    adaptive_radius: bool,
    /// The initial radius², once the first eye pass has chosen it.
    initial_radius2: f64,
    /// Photons emitted by the first pass (a restarted estimate does not count them).
    first_pass_photons: u64,
    /// α for the next update.
    pub alpha: f64,
    /// Photons per pass from the next pass on.
    pub photons_per_pass: u64,
    initial_radius: Option<f64>,
    slots: Vec<Slot>,
    points: Vec<VisiblePoint>,
    direct: Vec<DVec3>,
    /// This stochastic pass's directly seen light, added to `direct` when the pass completes.
    pass_direct: Vec<DVec3>,
    /// Area light sampled at the visible points, summed over completed passes, per pixel
    /// (empty unless direct light is on and the scene has area lights).
    area_direct: Vec<DVec3>,
    /// Where photons are sent, learned from completed passes (`None`: uniformly, as the
    /// lights emit).
    guide: Option<EmissionGuide>,
    /// Photons emitted by the pass in progress: `photons_per_pass`, divided by the guide's
    /// gain when emission is guided.
    pass_photons: u64,
    stats: PpmStats,
    width: u32,
    height: u32,
    seed: u64,
    interrupt: Option<Interrupt>,
}

/// Asked often during a pass (from any thread); returning true abandons the pass. The render
/// session sets one that turns true when a restart is waiting.
pub type Interrupt = Arc<dyn Fn() -> bool + Send + Sync>;

impl Ppm {
    /// A new render of `scene`; its render parameters give α, photons per pass, radius, seed,
    /// index and direct light.
    pub fn new(scene: &Scene, options: PpmOptions) -> Self {
        let cam = &scene.camera;
        let stochastic = options.force_stochastic || cam.aperture > 0.0 || scene.params.antialias;
        let features = scene.features();
        let mut skipped = Vec::new();
        if !stochastic {
            skipped.push("eye pass traced once and reused (pinhole camera, no anti-aliasing)".to_owned());
        }
        if !features.patches {
            skipped.push("no Bézier patches: no patch intersection set up".to_owned());
        }
        if !features.glass {
            skipped.push("no glass: no refraction paths".to_owned());
        }
        if !features.textures {
            skipped.push("no textures: constant colours, no lookups".to_owned());
        }
        if scene.params.direct_light {
            skipped.push("photons' first diffuse bounce: direct light by light sampling".to_owned());
        }
        if let Some(target) = scene.geometry.bounding_sphere() {
            if scene.lights.iter().any(|l| l.aims_at(target)) {
                skipped.push("photons from point lights outside the scene aimed at its bounds".to_owned());
            }
        }
        let pixels = cam.width as usize * cam.height as usize;
        Self {
            options,
            direct_light: scene.params.direct_light,
            index: scene.params.index,
            stochastic,
            stratified_eye_rays: scene.params.stratified_eye_rays,
            indirect_scale: match scene.params.indirect_radius_scale {
                None => IndirectScale::Automatic,
                Some(k) if k > 1.0 => IndirectScale::Fixed(k),
                Some(_) => IndirectScale::Off,
            },
            adaptive_radius: scene.params.adaptive_radius,
            initial_radius2: 0.0,
            first_pass_photons: 0,
            alpha: scene.params.alpha,
            photons_per_pass: scene
                .params
                .pass_photons(stochastic, cam.width as u64 * cam.height as u64),
            initial_radius: scene.params.initial_radius,
            slots: Vec::new(),
            points: Vec::new(),
            direct: vec![DVec3::ZERO; pixels],
            pass_direct: Vec::new(),
            area_direct: if scene.params.direct_light && direct::has_area_lights(scene) {
                vec![DVec3::ZERO; pixels]
            } else {
                Vec::new()
            },
            guide: (scene.params.guided_emission && !scene.lights.is_empty())
                .then(|| EmissionGuide::new(scene, photon::light_probabilities(scene))),
            pass_photons: 0,
            stats: PpmStats {
                skipped,
                ..Default::default()
            },
            width: cam.width,
            height: cam.height,
            seed: scene.params.seed,
            interrupt: None,
        }
    }

    /// Lets `interrupt` abandon a pass mid-way (also during the eye pass, which the control
    /// callback does not reach). An abandoned pass leaves no trace: running it again gives the
    /// same result.
    pub fn set_interrupt(&mut self, interrupt: Option<Interrupt>) {
        self.interrupt = interrupt;
    }

    fn interrupted(&self) -> bool {
        self.interrupt.as_ref().is_some_and(|f| f())
    }

    /// Statistics so far.
    pub fn stats(&self) -> &PpmStats {
        &self.stats
    }

    /// Whether a new eye pass runs every pass.
    pub fn is_stochastic(&self) -> bool {
        self.stochastic
    }

    /// Image size.
    pub fn size(&self) -> (u32, u32) {
        (self.width, self.height)
    }

    /// Stochastic PPM's eye pass: one eye ray per pixel (jittered, through the lens), in
    /// parallel, written in place: each pixel's visible point (at most one: glass is chosen,
    /// not split) into `points` at the pixel's index, its directly seen light into
    /// `pass_direct`; pixels without a point are then squeezed out. Nothing is allocated per
    /// pixel, and the buffers keep their capacity from pass to pass. `false` when interrupted
    /// (the pass is then traced again, so the half-written buffers do not matter).
    fn trace_stochastic_eye_pass(&mut self, scene: &Scene) -> bool {
        let (w, h) = (self.width as u64, self.height as u64);
        let pass = self.stats.passes as u64;
        let (direct_light, seed) = (self.direct_light, self.seed);
        let sequences = self
            .stratified_eye_rays
            .then(|| (sequence::r4(pass)[0], sequence::golden(pass)));
        let interrupt = self.interrupt.as_deref();
        let skipped = std::sync::atomic::AtomicBool::new(false);
        let pixels = (w * h) as usize;
        self.points.clear();
        self.points.resize(pixels, NO_POINT);
        self.pass_direct.clear();
        self.pass_direct.resize(pixels, DVec3::ZERO);
        let rays = scene.camera.eye_rays();
        self.points
            .par_iter_mut()
            .zip(self.pass_direct.par_iter_mut())
            .enumerate()
            .for_each(|(i, (point, direct))| {
                if interrupt.is_some_and(|f| f()) {
                    skipped.store(true, std::sync::atomic::Ordering::Relaxed);
                    return;
                }
                let i = i as u64;
                let (x, y) = (i % w, i / w);
                let mut rng = stream_rng(seed, streams::EYE, pass * w * h + i);
                let (jitter, lens, first) = match sequences {
                    // This pixel's shift and offsets, the same every pass (its own stream, so
                    // the path's other random numbers stay as they were).
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
                };
                let px = DVec2::new(x as f64, y as f64) + jitter;
                let lens = concentric_disk(lens);
                let mut sink = |vp: VisiblePoint| {
                    debug_assert!(point.slot == NO_POINT.slot, "a chosen path ends once");
                    *point = vp;
                };
                *direct = trace_eye(
                    scene,
                    &rays.ray(px, lens),
                    i as u32,
                    Branching::Choose { first },
                    direct_light,
                    &mut rng,
                    &mut sink,
                );
            });
        if skipped.into_inner() {
            return false;
        }
        self.points.retain(|p| p.slot != NO_POINT.slot);
        true
    }

    /// Classic PPM's one eye pass: an eye ray through each pixel centre, split at glass, rows
    /// in parallel. Per pixel: the directly seen light; per visible point: the point, its
    /// `slot` holding its pixel. `None` when interrupted.
    fn trace_classic_eye_pass(&self, scene: &Scene) -> Option<(Vec<DVec3>, Vec<VisiblePoint>)> {
        let (w, h) = (self.width as u64, self.height as u64);
        let pass = self.stats.passes as u64;
        let (direct_light, seed) = (self.direct_light, self.seed);
        let interrupt = self.interrupt.as_deref();
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
                    direct.push(trace_eye(
                        scene,
                        &rays.ray(px, DVec2::ZERO),
                        i as u32,
                        Branching::Split,
                        direct_light,
                        &mut rng,
                        &mut |vp| points.push(vp),
                    ));
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

    /// Traces the eye pass; `false` when interrupted (nothing the next pass needs changed then).
    fn eye_pass(&mut self, scene: &Scene) -> bool {
        if self.stochastic {
            // A stochastic pass's directly seen light counts only when the pass completes.
            if !self.trace_stochastic_eye_pass(scene) {
                return false;
            }
            if self.slots.is_empty() {
                self.slots = (0..self.width * self.height).map(Slot::new).collect();
            }
        } else {
            // Classic PPM keeps its one eye pass at once: a slot per visible point.
            let Some((direct, points)) = self.trace_classic_eye_pass(scene) else {
                return false;
            };
            self.stats.eye_passes += 1;
            for (d, p) in self.direct.iter_mut().zip(direct) {
                *d += p;
            }
            self.points = points;
            for vp in &mut self.points {
                let pixel = vp.slot;
                vp.slot = self.slots.len() as u32;
                self.slots.push(Slot::new(pixel));
            }
        }
        if self.stats.passes == 0 && self.slots.iter().all(|s| s.primary.radius2 == 0.0) {
            let r0 = self
                .initial_radius
                .unwrap_or_else(|| self.automatic_radius(scene));
            let indirect = match self.indirect_scale {
                IndirectScale::Off => 0.0,
                // The first pass measures the photon density; `update` widens it after.
                IndirectScale::Automatic => r0,
                IndirectScale::Fixed(k) => k * r0,
            };
            for s in &mut self.slots {
                s.primary.radius2 = r0 * r0;
                s.indirect.radius2 = indirect * indirect;
            }
            self.initial_radius2 = r0 * r0;
        }
        for vp in &mut self.points {
            vp.radius2 = self.slots[vp.slot as usize].reach2();
        }
        true
    }

    /// The initial radius photon mapping would choose for `scene` by itself (its own
    /// `initial_radius` ignored): see [`Ppm::automatic_radius`]. Traces one eye pass.
    pub fn automatic_initial_radius(scene: &Scene) -> f64 {
        let mut scene = scene.clone();
        scene.params.initial_radius = None;
        let mut ppm = Ppm::new(&scene, PpmOptions::default());
        if !ppm.eye_pass(&scene) {
            return 1e-3;
        }
        ppm.slots.first().map_or(1e-3, |s| s.primary.radius2.sqrt())
    }

    /// The automatic initial radius: twice the footprint of one pixel at the median distance
    /// of the visible points from the eye. (smallppm's rule — the visible points' bounding
    /// box over the image size — explodes for an infinite floor reaching the horizon.)
    fn automatic_radius(&self, scene: &Scene) -> f64 {
        let cam = &scene.camera;
        let mut distances: Vec<f64> = self
            .points
            .iter()
            .map(|p| (p.position - cam.position).dot(cam.forward).abs())
            .collect();
        if distances.is_empty() {
            return 1e-3;
        }
        let mid = distances.len() / 2;
        let median = *distances.select_nth_unstable_by(mid, f64::total_cmp).1;
        let pixel = 2.0 * (0.5 * cam.fov_y).tan() / self.height as f64;
        (2.0 * median * pixel).max(1e-9)
    }

    /// Runs one pass: eye pass if needed, photons in batches (calling `control(&mut α)`
    /// between batches; `Abort` drops the pass), then the radius/flux update.
    pub fn run_pass(&mut self, scene: &Scene, control: &mut dyn FnMut(&mut f64) -> Control) -> PassOutcome {
        let start = Instant::now();
        if self.interrupted() {
            return PassOutcome::Aborted;
        }
        if self.stochastic || self.stats.eye_passes == 0 {
            if !self.eye_pass(scene) {
                return PassOutcome::Aborted;
            }
        } else {
            for vp in &mut self.points {
                vp.radius2 = self.slots[vp.slot as usize].reach2();
            }
        }
        let index_start = Instant::now();
        self.stats.eye_secs += (index_start - start).as_secs_f64();
        let index = match self.index {
            IndexKind::HashGrid => SpatialIndex::Grid(HashGrid::build(&self.points)),
            IndexKind::KdTree => SpatialIndex::Kd(KdTree::build(&self.points)),
        };
        self.stats.index_secs += index_start.elapsed().as_secs_f64();
        if self.interrupted() {
            return PassOutcome::Aborted;
        }
        let photon_start = Instant::now();
        let Some(gathered) = self.photon_pass(scene, &index, control) else {
            return PassOutcome::Aborted;
        };
        self.stats.photon_secs += photon_start.elapsed().as_secs_f64();
        self.sample_area_lights(scene);
        self.update(gathered);
        self.stats.elapsed_secs += start.elapsed().as_secs_f64();
        PassOutcome::Completed
    }

    /// Traces this pass's photons in batches and gathers their flux at the visible points;
    /// `None` when `control` aborts the pass.
    fn photon_pass(
        &mut self,
        scene: &Scene,
        index: &SpatialIndex,
        control: &mut dyn FnMut(&mut f64) -> Control,
    ) -> Option<Gathered> {
        let source = PhotonSource::new(scene, self.direct_light).with_guide(self.guide.as_ref());
        // Positions and both radii packed tightly: the candidate test reads nothing else.
        let reach: Vec<Reach> = self
            .points
            .iter()
            .map(|v| {
                let s = &self.slots[v.slot as usize];
                let p = v.position;
                [p.x, p.y, p.z, s.primary.radius2, s.indirect.radius2]
            })
            .collect();
        let mut out = Gathered {
            phi: vec![Vec3::ZERO; 2 * self.slots.len()],
            m: vec![0u32; 2 * self.slots.len()],
            counts: PhotonCounts::default(),
            tally: self.guide.as_ref().map(EmissionGuide::tally),
        };
        self.pass_photons = self.guided_pass_photons();
        let chunks = self.pass_photons.div_ceil(CHUNK);
        let chunks_per_batch = self.options.batch_photons.div_ceil(CHUNK).max(1);
        let mut chunk = 0;
        while chunk < chunks {
            if control(&mut self.alpha) == Control::Abort {
                return None;
            }
            let end = (chunk + chunks_per_batch).min(chunks);
            let results: Vec<ChunkResult> = (chunk..end)
                .into_par_iter()
                .map(|c| self.trace_chunk(c, &source, index, &reach))
                .collect();
            // Fold in chunk order: the same sums whatever the thread count.
            for (deposits, c, tally) in results {
                if let (Some(all), Some(t)) = (&mut out.tally, &tally) {
                    all.add(t);
                }
                for (slot, flux, count) in deposits {
                    out.phi[slot as usize] += flux.as_vec3();
                    out.m[slot as usize] += count;
                    out.counts.deposits += count as u64;
                }
                out.counts.paths += c.paths;
                out.counts.bounces += c.bounces;
                out.counts.useful += c.useful;
            }
            chunk = end;
        }
        Some(out)
    }

    /// This pass's photons: `photons_per_pass` divided by the guide's gain (as many useful
    /// photons, fewer lost ones; see [`guide`]), but not below one chunk (or all of them).
    fn guided_pass_photons(&self) -> u64 {
        match &self.guide {
            Some(g) => {
                let reduced = (self.photons_per_pass as f64 / g.gain()).ceil() as u64;
                reduced.max(self.photons_per_pass.min(CHUNK))
            }
            None => self.photons_per_pass,
        }
    }

    /// Traces photon chunk `c` of this pass: the deposits it makes and its counts.
    fn trace_chunk(
        &self,
        c: u64,
        source: &PhotonSource,
        index: &SpatialIndex,
        reach: &[Reach],
    ) -> ChunkResult {
        let mut deposits: Vec<Deposit> = Vec::new();
        let mut counts = PhotonCounts::default();
        let mut tally = self.guide.as_ref().map(EmissionGuide::tally);
        let (photons, first_photon) = (self.pass_photons, self.stats.photons);
        let points = &self.points;
        let split = self.indirect_scale != IndirectScale::Off;
        for i in c * CHUNK..((c + 1) * CHUNK).min(photons) {
            let mut rng = stream_rng(self.seed, streams::PHOTON, first_photon + i);
            let mut useful = false;
            let from = source.trace(&mut rng, &mut counts, &mut |p, n, flux, indirect| {
                // Hand the flux to every visible point on this side of the surface whose
                // search sphere (of the photon's estimate) holds the photon.
                let estimate = usize::from(indirect && split);
                index.for_candidates(points, p, &mut |k| {
                    let r = &reach[k as usize];
                    if (DVec3::new(r[0], r[1], r[2]) - p).length_squared() <= r[3 + estimate] {
                        let vp = &points[k as usize];
                        if vp.normal.dot(n) > 1e-3 {
                            deposits.push((2 * vp.slot + estimate as u32, vp.weight * flux, 1));
                            useful = true;
                        }
                    }
                });
            });
            counts.useful += useful as u64;
            if let Some(t) = &mut tally {
                t.record(from.light, from.bin, useful);
            }
            if deposits.len() > MAX_CHUNK_DEPOSITS {
                compact(&mut deposits);
            }
        }
        (deposits, counts, tally)
    }

    /// Folds a completed pass into the slots and the statistics.
    fn update(&mut self, gathered: Gathered) {
        let Gathered {
            phi,
            m,
            counts,
            tally,
        } = gathered;
        if let (Some(guide), Some(tally)) = (&mut self.guide, &tally) {
            guide.learn(tally);
        }
        // Compute new photon counts, radii and flux (Hachisuka et al. 2008, eqs. 6–11).
        let alpha = self.alpha;
        for (k, s) in self.slots.iter_mut().enumerate() {
            if s.restart == Restart::Pending {
                // The first pass's flux only stood in until this pass: it was gathered over
                // the wide radius.
                s.primary.n = 0.0;
                s.primary.tau = DVec3::ZERO;
                s.restart = Restart::Restarted;
            }
            s.primary.update(phi[2 * k].as_dvec3(), m[2 * k], alpha);
            s.indirect.update(phi[2 * k + 1].as_dvec3(), m[2 * k + 1], alpha);
        }
        if self.indirect_scale == IndirectScale::Automatic && self.stats.passes == 0 {
            self.widen_indirect(&m);
        }
        if self.adaptive_radius && self.stats.passes == 0 {
            self.first_pass_photons = self.pass_photons;
            self.narrow_dense(&m);
        }
        if self.stochastic {
            for (d, p) in self.direct.iter_mut().zip(self.pass_direct.drain(..)) {
                *d += p;
            }
            self.stats.eye_passes += 1;
        }
        self.stats.passes += 1;
        self.stats.indirect_radius_scale = match self.indirect_scale {
            IndirectScale::Fixed(k) => k,
            _ => 1.0,
        };
        self.stats.photons += self.pass_photons;
        self.stats.bounces += counts.bounces;
        self.stats.deposits += counts.deposits;
        self.stats.useful_paths += counts.useful;
        self.stats.visible_points = self.points.len();
        let gathered: Vec<f64> = self
            .slots
            .iter()
            .filter(|s| s.primary.n > 0.0)
            .map(|s| s.primary.radius2.sqrt())
            .collect();
        self.stats.mean_radius = gathered.iter().sum::<f64>() / gathered.len().max(1) as f64;
    }

    /// After the first pass of an automatic indirect radius: widens every slot's indirect
    /// estimate by `k = √(INDIRECT_PHOTONS / m̄)`, clamped to [1, MAX_INDIRECT_SCALE], where m̄
    /// is the mean number of indirect photons a slot gathered in that pass — so that a pass
    /// hands each point about `INDIRECT_PHOTONS` of them. Where photons are sparse it grows;
    /// where they are dense (small closed rooms) `k` is 1 and the two estimates merge into
    /// one. The estimate is scaled as PPM's update assumes, for a density uniform within the
    /// radius: N and τ by the area. Counts are deterministic, so is `k`.
    fn widen_indirect(&mut self, m: &[u32]) {
        let slots = self.slots.len().max(1) as f64;
        let mean = m.iter().skip(1).step_by(2).map(|&c| c as f64).sum::<f64>() / slots;
        let k = (INDIRECT_PHOTONS / mean).sqrt().clamp(1.0, MAX_INDIRECT_SCALE);
        if k == 1.0 {
            // Dense photons: the two estimates would share one radius, so they become one
            // (the second only costs memory and time). Each is brought to the smaller of the
            // two radii — N and τ scaled by the area, as PPM's update does — and summed.
            for s in &mut self.slots {
                let r2 = s.primary.radius2.min(s.indirect.radius2);
                let (p, i) = (s.primary.resized(r2), s.indirect.resized(r2));
                s.primary = Estimate {
                    radius2: r2,
                    n: p.n + i.n,
                    tau: p.tau + i.tau,
                };
                s.indirect = Estimate::default();
            }
            self.indirect_scale = IndirectScale::Off;
            return;
        }
        let area = k * k;
        for s in &mut self.slots {
            s.indirect = s.indirect.resized(s.indirect.radius2 * area);
        }
        self.indirect_scale = IndirectScale::Fixed(k);
    }

    /// After the first pass, with an adaptive radius: where that pass handed a slot's primary
    /// estimate more than `DENSE_PHOTONS` photons (caustics, and all light when one estimate
    /// is kept), the estimate restarts at the second pass with the initial radius narrowed so
    /// that a pass hands it about that many: `R² = R₀² · DENSE_PHOTONS / m`, at most
    /// `MAX_NARROWING` times narrower. PPM's bias (the blur of sharp light such as a caustic's
    /// edge) grows with the radius and shrinks only pass by pass, while its noise depends on
    /// photons per point: where they are dense a narrower radius removes blur at once for
    /// little noise. The first pass's flux, gathered over the wide radius, is dropped at the
    /// second pass (kept until then, scaled by the area, so the image does not go dark), so
    /// that no blur of it stays in the estimate; the radius is chosen from photons the
    /// estimate then never uses. Counts are deterministic, so are the radii.
    fn narrow_dense(&mut self, m: &[u32]) {
        let merged = self.indirect_scale == IndirectScale::Off;
        let r0_2 = self.initial_radius2;
        let mut narrowed = 0usize;
        for (k, s) in self.slots.iter_mut().enumerate() {
            let count = m[2 * k] as f64 + if merged { m[2 * k + 1] as f64 } else { 0.0 };
            if count <= DENSE_PHOTONS || s.primary.radius2 <= 0.0 {
                continue;
            }
            let radius2 = r0_2 * (DENSE_PHOTONS / count).max(MAX_NARROWING.powi(-2));
            s.primary = s.primary.resized(radius2);
            s.restart = Restart::Pending;
            narrowed += 1;
        }
        self.stats.narrowed_share = narrowed as f64 / self.slots.len().max(1) as f64;
    }

    /// Adds one light sample of every area light at each visible point of this pass to the
    /// per-pixel sums (when direct light is on; see [`direct`]).
    fn sample_area_lights(&mut self, scene: &Scene) {
        if self.area_direct.is_empty() {
            return;
        }
        let start = Instant::now();
        let slots = &self.slots;
        let light = direct::area_light_pass(
            scene,
            &self.points,
            |k| self.points[k].slot as u64,
            self.stats.passes as u64,
            self.seed,
        );
        for (vp, l) in self.points.iter().zip(light) {
            self.area_direct[slots[vp.slot as usize].pixel as usize] += l;
        }
        self.stats.direct_secs += start.elapsed().as_secs_f64();
    }

    /// Linear RGB radiance per pixel: `τ/(π R² N_emitted)` of every slot of the pixel plus the
    /// mean of the light seen directly.
    pub fn radiance(&self) -> Vec<[f32; 3]> {
        let mut out = vec![DVec3::ZERO; self.direct.len()];
        if self.stats.photons > 0 {
            let emitted = self.stats.photons as f64;
            let restarted = (self.stats.photons - self.first_pass_photons) as f64;
            for s in &self.slots {
                let primary = match s.restart {
                    Restart::Restarted => s.primary.radiance(restarted),
                    _ => s.primary.radiance(emitted),
                };
                out[s.pixel as usize] += primary + s.indirect.radiance(emitted);
            }
        }
        let eye = self.stats.eye_passes.max(1) as f64;
        let passes = self.stats.passes.max(1) as f64;
        for (o, a) in out.iter_mut().zip(&self.area_direct) {
            *o += *a / passes;
        }
        out.iter()
            .zip(&self.direct)
            .map(|(l, d)| {
                let c = *l + *d / eye;
                [c.x as f32, c.y as f32, c.z as f32]
            })
            .collect()
    }

    /// The statistics slots (for the viewer's probe).
    pub fn slots(&self) -> &[Slot] {
        &self.slots
    }
}
