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
//! and the radiance is `L = τ / (π R² N_emitted)` plus light seen directly (in stochastic
//! passes supersampled where it changes within a pixel, `seen`). No brightness
//! factor: exposure belongs to the viewer. After the first pass, two per-point choices are
//! made from its photon counts: the indirect estimate's radius (`Ppm::widen_indirect`) and
//! a restart of the primary one, narrower where photons are dense and wider where they are
//! sparse (`Ppm::adapt_radii`, the adaptive radius: in the spirit of classic photon
//! mapping's k-nearest-neighbour radius, Jensen 2001, chosen once and then shrunk by the
//! paper's rule).
//!
//! Determinism: photon `i` of the render uses the random stream `(seed, photon, i)` (and, when
//! photons are stratified, point `i` of Sobol's sequence under a shift drawn from the seed), pixels
//! `(seed, pass, pixel)`; photons are traced in fixed chunks, their hits sorted by cell
//! with ties in photon order and handed in fixed groups whose deposits are applied in group
//! order (`deposit.rs`), so the image is bit-identical for any number of threads.

mod deposit;
mod estimate;
mod eye_pass;
mod gathered;
mod global;
mod index;
mod photon_pass;
mod points;
mod radius;
mod seen;
mod stats;

pub mod direct;
pub mod guide;
pub mod hash_grid;
pub mod kd_tree;
pub mod photon;
pub mod visible;
pub mod warm;

use std::ops::Range;
use std::sync::Arc;
use std::time::Instant;

use glam::{DVec3, Vec3};
use rand::Rng;

use guide::EmissionGuide;
pub use hash_grid::HashGrid;
pub use kd_tree::KdTree;
use points::VisiblePoints;

pub use crate::render::control::{Control, Interrupt};
use crate::render::rng::stream_rng;
use crate::render::shard::PassSums;
use crate::scene::Scene;
use crate::settings::{IndexKind, RadiusSchedule};

pub use estimate::{Estimate, Restart, Slot};
pub use global::schedule_factor;
pub use index::SpatialIndex;
pub use photon_pass::DEFAULT_BATCH_PHOTONS;
use radius::IndirectScale;
pub use seen::{SUBSAMPLES, VARIED_SUBSAMPLES};
pub use stats::PpmStats;
pub use warm::{StreamOffset, WarmStart};

/// Random stream ids of photon mapping.
mod streams {
    pub const EYE: u64 = 10;
    pub const PHOTON: u64 = 11;
    /// Each pixel's fixed offsets of its eye-ray sequences (12 is `direct`'s).
    pub const EYE_OFFSETS: u64 = 13;
    /// The extra eye rays of pixels whose light seen is supersampled ([`super::seen`]).
    pub const SEEN: u64 = 14;
    /// Each such pixel's fixed offsets of its extra rays' sequences.
    pub const SEEN_OFFSETS: u64 = 15;
    /// The digital shift of stratified photons' sequence.
    pub const PHOTON_SHIFT: u64 = 16;
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
    /// Keep, after each stochastic pass, a copy of every pixel's visible point (36 bytes a
    /// pixel), so that an epoch can hand a warm restart its statistics ([`warm`]); classic
    /// PPM keeps its points anyway.
    pub warm_restarts: bool,
}

impl Default for PpmOptions {
    fn default() -> Self {
        Self {
            force_stochastic: false,
            batch_photons: DEFAULT_BATCH_PHOTONS,
            warm_restarts: false,
        }
    }
}

/// Whether a pass ran to the end.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PassOutcome {
    /// Finished and folded into the statistics.
    Completed,
    /// Abandoned between two batches at the caller's request; nothing of it was kept.
    Aborted,
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
    /// With stratified photons (from the render parameters): the digital shift of the Sobol
    /// points that choose their directions, drawn from the seed.
    photon_shift: Option<u64>,
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
    /// Photons of a full pass, what `photons_per_pass` ramps up to (the viewer's first passes
    /// are smaller): the adaptive radius tells sparse points by the photons such a pass
    /// would hand them (`Ppm::adapt_radii`). The scene's photons per pass unless set.
    pub full_pass_photons: u64,
    initial_radius: Option<f64>,
    slots: Vec<Slot>,
    /// This pass's visible points (classic PPM: the one eye pass's).
    points: VisiblePoints,
    direct: Vec<DVec3>,
    /// This stochastic pass's directly seen light, added to `direct` when the pass completes
    /// (f32: one pass's value, summed in f64).
    pass_direct: Vec<Vec3>,
    /// Area light sampled at the visible points, summed over completed passes, per pixel
    /// (empty unless direct light is on, the scene has area lights and the eye pass is
    /// classic: a stochastic pass adds its samples to `pass_direct`, which counts the same
    /// passes; at 1920×1080 that is 48 MiB less).
    area_direct: Vec<DVec3>,
    /// Where photons are sent, learned from completed passes (`None`: uniformly, as the
    /// lights emit).
    guide: Option<EmissionGuide>,
    /// Photons emitted by the pass in progress: `photons_per_pass`, divided by the guide's gain
    /// (or, after an epoch's first passes, its square root) when emission is guided.
    pass_photons: u64,
    stats: PpmStats,
    width: u32,
    height: u32,
    seed: u64,
    interrupt: Option<Interrupt>,
    /// Where this epoch's random streams start (after the previous epoch's, when warm).
    offset: StreamOffset,
    /// What a warm restart inherited, until the first pass completes ([`warm`]).
    inherited: Option<WarmStart>,
    /// Per pixel, its visible point in the last completed stochastic pass, with
    /// [`PpmOptions::warm_restarts`] ([`warm::records`]).
    last_points: Vec<warm::PointRecord>,
    /// The photon pass's hits awaiting their points, empty between passes; kept so that its
    /// tens of MiB are not mapped afresh (page by page) every pass.
    window: deposit::Window,
    /// The hash grid over the points as they lie now, kept while no eye pass replaces them
    /// (classic PPM traces one) for as long as it serves the shrinking radii
    /// ([`HashGrid::serves`]); never used again on the global schedule, whose passes must not
    /// depend on the passes before them.
    kept_grid: Option<HashGrid>,
    /// Per pixel, the light seen directly that a warm restart kept (empty when cold).
    prior_light: Vec<warm::PriorLight>,
    /// The global radius schedule's state (`None`: per-point statistics).
    global: Option<global::Global>,
    /// Which pixels' light seen directly is supersampled, learned from completed stochastic
    /// passes ([`seen`]).
    seen: seen::SeenLight,
}

/// What a render of `scene` skips because the scene does not need it, in words (the render's
/// statistics list it); `stochastic`: whether the eye pass is traced anew every pass.
fn skipped_work(scene: &Scene, stochastic: bool) -> Vec<String> {
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
    skipped
}

/// Items (pixels, slots, visible points) a task of a pass's parallel sweeps over them takes:
/// large enough that handing out the tasks, or a frame's block finding its first slot
/// ([`Ppm::pixel_layers`]), costs nothing beside them (with one thread a sweep is as fast as
/// a plain loop), small enough that two threads share a 320×240 image evenly.
pub(super) const SWEEP_BLOCK: usize = 4096;

/// The slots of each pixel of `pixels` in turn (empty for a pixel without any), from `slots`
/// in pixel order starting at the first of those pixels.
fn slots_by_pixel(slots: &[Slot], pixels: Range<usize>) -> impl Iterator<Item = &[Slot]> + '_ {
    let mut runs = slots.chunk_by(|a, b| a.pixel == b.pixel).peekable();
    pixels.map(move |i| runs.next_if(|run| run[0].pixel as usize == i).unwrap_or(&[]))
}

/// A frame's per-pixel layers ([`Ppm::pixel_layers`]).
pub struct PixelLayers {
    /// Linear RGB radiance ([`Ppm::radiance`]).
    pub radiance: Arc<[[f32; 3]]>,
    /// The largest primary search radius of the pixel's slots (0 without any).
    pub radius: Arc<[f32]>,
    /// Photons the pixel's slots gathered, both estimates (`N`, after the shrinking).
    pub gathered: Arc<[f32]>,
}

impl Ppm {
    /// A new render of `scene`; its render parameters give α, photons per pass, radius, seed,
    /// index and direct light.
    pub fn new(scene: &Scene, options: PpmOptions) -> Self {
        let cam = &scene.camera;
        let stochastic = options.force_stochastic || cam.aperture > 0.0 || scene.params.antialias;
        let skipped = skipped_work(scene, stochastic);
        let pixels = cam.width as usize * cam.height as usize;
        let full_pass = scene.params.pass_photons(stochastic, pixels as u64);
        Self {
            options,
            direct_light: scene.params.direct_light,
            index: scene.params.index,
            stochastic,
            stratified_eye_rays: scene.params.stratified_eye_rays,
            photon_shift: scene
                .params
                .stratified_photons
                .then(|| stream_rng(scene.params.seed, streams::PHOTON_SHIFT, 0).random()),
            indirect_scale: match scene.params.indirect_radius_scale {
                None => IndirectScale::Automatic,
                Some(k) if k > 1.0 => IndirectScale::Fixed(k),
                Some(_) => IndirectScale::Off,
            },
            adaptive_radius: scene.params.adaptive_radius,
            initial_radius2: 0.0,
            first_pass_photons: 0,
            alpha: scene.params.alpha,
            photons_per_pass: full_pass,
            full_pass_photons: full_pass,
            initial_radius: scene.params.initial_radius,
            slots: Vec::new(),
            points: VisiblePoints::default(),
            direct: vec![DVec3::ZERO; pixels],
            pass_direct: Vec::new(),
            area_direct: if scene.params.direct_light && direct::has_area_lights(scene) && !stochastic {
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
            offset: StreamOffset::default(),
            inherited: None,
            last_points: Vec::new(),
            window: deposit::Window::default(),
            kept_grid: None,
            prior_light: Vec::new(),
            global: (scene.params.radius_schedule == RadiusSchedule::Global)
                .then(|| global::Global::new(scene.params.alpha, cam.width, cam.height)),
            // On the global schedule every pass depends on (seed, pass) alone: its choices are
            // the pilot's one pass, too few for a variance.
            seen: if stochastic && scene.params.supersample_light_seen {
                seen::SeenLight::new(pixels, scene.params.radius_schedule != RadiusSchedule::Global)
            } else {
                seen::SeenLight::default()
            },
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

    /// Runs one pass: eye pass if needed, photons in batches (calling `control(&mut α)`
    /// between batches; `Abort` drops the pass), then the radius/flux update.
    /// With the global radius schedule, the pass is the next of this process's shard, an
    /// independent estimate at the global schedule's radius ([`schedule_factor`]).
    pub fn run_pass(&mut self, scene: &Scene, control: &mut dyn FnMut(&mut f64) -> Control) -> PassOutcome {
        if self.global.is_some() {
            return self.run_global_pass(scene, control);
        }
        self.run_statistics_pass(scene, control)
    }

    /// A pass of per-point statistics (also the global schedule's pilot pass).
    fn run_statistics_pass(
        &mut self,
        scene: &Scene,
        control: &mut dyn FnMut(&mut f64) -> Control,
    ) -> PassOutcome {
        let start = Instant::now();
        if self.interrupted() {
            return PassOutcome::Aborted;
        }
        if (self.stochastic || self.stats.eye_passes == 0) && !self.eye_pass(scene) {
            return PassOutcome::Aborted;
        }
        self.stats.eye_secs += start.elapsed().as_secs_f64();
        let Some(gathered) = self.gather(scene, control) else {
            return PassOutcome::Aborted;
        };
        self.sample_area_lights(scene);
        self.update(gathered);
        self.stats.elapsed_secs += start.elapsed().as_secs_f64();
        PassOutcome::Completed
    }

    /// Builds the index over this pass's visible points and traces its photons: what they
    /// handed each slot (`None` when the pass was interrupted or aborted).
    fn gather(
        &mut self,
        scene: &Scene,
        control: &mut dyn FnMut(&mut f64) -> Control,
    ) -> Option<gathered::Gathered> {
        let (index, largest) = self.build_index();
        if self.interrupted() {
            self.keep(index);
            return None;
        }
        let start = Instant::now();
        // Each estimate's largest radius: how far from a photon its points are looked for.
        let radius = largest.map(|r2| (r2 as f64).sqrt());
        let gathered = self.photon_pass(scene, &index, radius, control);
        self.keep(index);
        let gathered = gathered?;
        self.stats.photon_secs += start.elapsed().as_secs_f64();
        Some(gathered)
    }

    /// Keeps the hash grid for the next pass, should its points not change.
    fn keep(&mut self, index: SpatialIndex) {
        if let SpatialIndex::Grid(grid) = index {
            self.kept_grid = Some(grid);
        }
    }

    /// The spatial index over this pass's visible points, their radii first copied from
    /// their slots (the hash grid puts the points in its order; the last pass's grid is used
    /// again when the points are the same and it serves their radii), and each estimate's
    /// largest radius².
    fn build_index(&mut self) -> (SpatialIndex, [f32; 2]) {
        let start = Instant::now();
        let largest = self.points.set_radii(&self.slots);
        let reach = (largest[0].max(largest[1]) as f64).sqrt();
        let index = match self.index {
            IndexKind::HashGrid => match self.kept_grid.take() {
                // Not on the global schedule: each of its passes must come out the same
                // whichever passes this process rendered before (shards render some of them).
                Some(grid) if self.global.is_none() && grid.serves(reach) => SpatialIndex::Grid(grid),
                _ => {
                    let (grid, mut order) = HashGrid::build(&self.points.reach);
                    self.points.permute(&mut order);
                    SpatialIndex::Grid(grid)
                }
            },
            IndexKind::KdTree => SpatialIndex::Kd(KdTree::build(&self.points.reach)),
        };
        self.stats.index_secs += start.elapsed().as_secs_f64();
        (index, largest)
    }

    /// The pass whose random streams the eye pass and light samples use.
    fn stream_pass(&self) -> u64 {
        match &self.global {
            Some(g) => g.stream_pass(),
            None => self.offset.passes + self.stats.passes as u64,
        }
    }

    /// The random stream index of this pass's first photon.
    fn first_photon(&self) -> u64 {
        match &self.global {
            Some(g) => g.first_photon(),
            None => self.offset.photons + self.stats.photons,
        }
    }

    /// With the global radius schedule, the exact sums of the passes rendered so far.
    pub fn pass_sums(&self) -> Option<&PassSums> {
        self.global.as_ref().map(|g| &g.sums)
    }

    /// Linear RGB radiance per pixel: `τ/(π R² N_emitted)` of every slot of the pixel plus the
    /// mean of the light seen directly (with the global schedule, the mean of the passes).
    pub fn radiance(&self) -> Vec<[f32; 3]> {
        match &self.global {
            Some(g) => g.sums.mean(),
            None => self
                .slots_by_pixel()
                .enumerate()
                .map(|(i, slots)| self.pixel_radiance(i, slots))
                .collect(),
        }
    }

    /// What a frame shows per pixel — [`Ppm::radiance`], the largest search radius of the
    /// pixel's slots and the photons they gathered — each in one allocation, made in one
    /// parallel sweep over the slots, `SWEEP_BLOCK` pixels a task (each block finds its
    /// first slot by a binary search: they lie in pixel order), rather than three serial ones;
    /// each pixel's values depend on it alone, so they are the same for any number of threads.
    pub fn pixel_layers(&self) -> PixelLayers {
        use rayon::prelude::*;
        debug_assert!(
            self.slots.is_sorted_by_key(|s| s.pixel),
            "slots lie in pixel order"
        );
        let n = self.direct.len();
        // The global schedule's radiance is the mean of its passes' sums, not the slots'.
        let per_point = self.global.is_none();
        let mut radiance: Arc<[[f32; 3]]> = match &self.global {
            Some(g) => g.sums.mean().into(),
            None => std::iter::repeat_n([0.0; 3], n).collect(),
        };
        let mut radius: Arc<[f32]> = std::iter::repeat_n(0.0, n).collect();
        let mut gathered: Arc<[f32]> = std::iter::repeat_n(0.0, n).collect();
        let unique = "a new Arc has no other owner";
        debug_assert_eq!(radiance.len(), n);
        Arc::get_mut(&mut radiance)
            .expect(unique)
            .par_chunks_mut(SWEEP_BLOCK)
            .zip(
                Arc::get_mut(&mut radius)
                    .expect(unique)
                    .par_chunks_mut(SWEEP_BLOCK),
            )
            .zip(
                Arc::get_mut(&mut gathered)
                    .expect(unique)
                    .par_chunks_mut(SWEEP_BLOCK),
            )
            .enumerate()
            .for_each(|(b, ((radiance, radius), gathered))| {
                let first = b * SWEEP_BLOCK;
                let start = self.slots.partition_point(|s| (s.pixel as usize) < first);
                let pixels = first..first + radiance.len();
                for (k, slots) in slots_by_pixel(&self.slots[start..], pixels).enumerate() {
                    if per_point {
                        radiance[k] = self.pixel_radiance(first + k, slots);
                    }
                    radius[k] = slots
                        .iter()
                        .map(|s| s.primary.radius2().sqrt() as f32)
                        .fold(0.0, f32::max);
                    gathered[k] = slots
                        .iter()
                        .fold(0.0, |sum, s| sum + (s.primary.n() + s.indirect.n()) as f32);
                }
            });
        PixelLayers {
            radiance,
            radius,
            gathered,
        }
    }

    /// Pixel `i`'s radiance with per-point statistics, summed in f64 over its `slots`.
    fn pixel_radiance(&self, i: usize, slots: &[Slot]) -> [f32; 3] {
        let emitted = self.stats.photons as f64;
        let restarted = (self.stats.photons - self.first_pass_photons) as f64;
        let mut c = DVec3::ZERO;
        if emitted > 0.0 {
            for s in slots {
                let primary = match s.restart {
                    Restart::Restarted => s.primary.radiance(restarted + s.prior as f64),
                    _ => s.primary.radiance(emitted + s.prior as f64),
                };
                c += primary + s.indirect.radiance(emitted + s.prior as f64);
            }
        }
        let c = c + self.light_seen(i);
        [c.x as f32, c.y as f32, c.z as f32]
    }

    /// Pixel `i`'s mean light seen directly (emission, and lights sampled at its visible
    /// points), with what a warm restart kept of it counted as earlier passes.
    fn light_seen(&self, i: usize) -> DVec3 {
        let prior = self.prior_light.get(i).copied().unwrap_or_default();
        let eye = self.seen.passes(i, self.stats.eye_passes) as f64 + prior.direct_passes;
        let passes = self.stats.passes as f64 + prior.area_passes;
        let mut light = (self.direct[i] + prior.direct) / eye.max(1.0);
        if let Some(a) = self.area_direct.get(i) {
            light += (*a + prior.area) / passes.max(1.0);
        }
        light
    }

    /// Empties the light seen so far of the pixels chosen to be supersampled before this pass,
    /// their first supersampled one, and of what a warm restart kept for them ([`seen`]).
    fn forget_before_supersampling(&mut self) {
        for i in self.seen.take_pending() {
            self.direct[i as usize] = DVec3::ZERO;
            if let Some(prior) = self.prior_light.get_mut(i as usize) {
                prior.direct = DVec3::ZERO;
                prior.direct_passes = 0.0;
            }
        }
    }

    /// Each pixel's statistics slots, in pixel order (none for a pixel without a visible
    /// point): a pixel's slots lie together, and pixels in order, however the eye pass made
    /// them.
    pub fn slots_by_pixel(&self) -> impl Iterator<Item = &[Slot]> + '_ {
        debug_assert!(
            self.slots.is_sorted_by_key(|s| s.pixel),
            "slots lie in pixel order"
        );
        slots_by_pixel(&self.slots, 0..self.direct.len())
    }

    /// The statistics slots (for the viewer's probe).
    pub fn slots(&self) -> &[Slot] {
        &self.slots
    }
}
