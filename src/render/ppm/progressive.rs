//! A progressive photon mapping render ([`Ppm`]): its parts, each owning its state — the
//! statistics slots ([`Estimates`]), the eye pass ([`EyePass`]), the photon pass
//! ([`PhotonPass`]), the radius policy ([`RadiusPolicy`]), the emission guide
//! ([`EmissionGuide`]), the light seen directly ([`LightSeen`]), the warm-restart epoch
//! ([`Epoch`]) and the global schedule ([`Global`]) — run in a pass's order: eye pass,
//! spatial index, photons, then every slot's update.

use std::time::Instant;

use super::config::{Config, PpmOptions};
use super::estimate::{mean_primary_radius, Slot};
use super::estimates::Estimates;
use super::eye_pass::{trace_classic, EyeJob, EyePass};
use super::gathered::Gathered;
use super::global::Global;
use super::guide::EmissionGuide;
use super::index::SpatialIndex;
use super::layers::PixelLayers;
use super::light::LightSeen;
use super::photon;
use super::photon_pass::{guided_pass_photons, PhotonJob, PhotonPass};
use super::radius::{IndirectScale, RadiusPolicy};
use super::reuse::PathKind;
use super::stats::{skipped_work, PpmStats};
use super::warm::{
    records, records_in_place, Epoch, PointRecord, Reopen, StreamOffset, WarmStart, PRIOR_PASSES,
};
use crate::render::control::{Control, Interrupt};
use crate::render::error_tracker::Restarts;
use crate::render::shard::{PassSet, PassSums};
use crate::scene::Scene;
use crate::settings::RadiusSchedule;

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
    /// What the render chose once.
    config: Config,
    /// α for the next update.
    pub alpha: f64,
    /// Photons per pass from the next pass on.
    pub photons_per_pass: u64,
    /// Photons of a full pass, what `photons_per_pass` ramps up to (the viewer's first passes
    /// are smaller): the adaptive radius tells sparse points by the photons such a pass
    /// would hand them (`RadiusPolicy::adapt_radii`). The scene's photons per pass unless
    /// set.
    pub full_pass_photons: u64,
    /// The statistics slots.
    estimates: Estimates,
    /// How radii are chosen, and what was chosen.
    radius: RadiusPolicy,
    /// The visible points and the index over them.
    eye: EyePass,
    /// The photons of the pass in progress.
    photons: PhotonPass,
    /// Where photons are sent, learned from completed passes (`None`: uniformly, as the
    /// lights emit).
    guide: Option<EmissionGuide>,
    /// The light seen directly, per pixel.
    light: LightSeen,
    /// Where this epoch's streams start and what it inherited.
    epoch: Epoch,
    /// The global radius schedule's state (`None`: per-point statistics).
    global: Option<Global>,
    stats: PpmStats,
    interrupt: Option<Interrupt>,
}

impl Ppm {
    /// A new render of `scene`; its render parameters give α, photons per pass, radius, seed,
    /// index and direct light.
    pub fn new(scene: &Scene, options: PpmOptions) -> Self {
        let config = Config::new(scene, options);
        let params = &scene.params;
        let full_pass = params.pass_photons(config.stochastic, config.pixels() as u64);
        Self {
            alpha: params.alpha,
            photons_per_pass: full_pass,
            full_pass_photons: full_pass,
            estimates: Estimates::default(),
            radius: RadiusPolicy::new(params),
            eye: EyePass::default(),
            photons: PhotonPass::default(),
            guide: (params.guided_emission && !scene.lights.is_empty())
                .then(|| EmissionGuide::new(scene, photon::light_probabilities(scene))),
            light: LightSeen::new(scene, &config),
            epoch: Epoch::default(),
            global: (params.radius_schedule == RadiusSchedule::Global)
                .then(|| Global::new(params.alpha, config.width, config.height)),
            stats: PpmStats {
                skipped: skipped_work(scene, config.stochastic),
                ..Default::default()
            },
            interrupt: None,
            config,
        }
    }

    /// The initial radius photon mapping would choose for `scene` by itself (its own
    /// `initial_radius` ignored): see `radius::automatic_radius`. Traces one eye
    /// pass.
    pub fn automatic_initial_radius(scene: &Scene) -> f64 {
        let mut scene = scene.clone();
        scene.params.initial_radius = None;
        let mut ppm = Ppm::new(&scene, PpmOptions::default());
        if !ppm.eye_pass(&scene) || ppm.radius.initial_radius2 <= 0.0 {
            return 1e-3;
        }
        // The initial radius itself, not the first pass's (wider with an adaptive radius).
        ppm.radius.initial_radius2.sqrt()
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
        self.config.stochastic
    }

    /// Image size.
    pub fn size(&self) -> (u32, u32) {
        (self.config.width, self.config.height)
    }

    /// Runs one pass: eye pass if needed, photons in batches (calling `control(&mut α)`
    /// between batches; `Abort` drops the pass), then the radius/flux update.
    /// With the global radius schedule, the pass is the next of this process's shard, an
    /// independent estimate at the global schedule's radius ([`super::schedule_factor`]).
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
        if (self.config.stochastic || self.stats.eye_passes == 0) && !self.eye_pass(scene) {
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

    /// The next pass of this process's shard on the global schedule: the pilot first (once),
    /// then the pass's own eye pass, photons at the scheduled radii and its estimate added to
    /// the sums.
    fn run_global_pass(
        &mut self,
        scene: &Scene,
        control: &mut dyn FnMut(&mut f64) -> Control,
    ) -> PassOutcome {
        if self.global.as_ref().is_some_and(Global::learning) {
            // Stream position 0 until the pilot completes.
            if self.run_statistics_pass(scene, control) == PassOutcome::Aborted {
                return PassOutcome::Aborted;
            }
            if let Some(g) = &mut self.global {
                g.finish_pilot(&mut self.estimates.slots, &self.radius);
            }
            self.stats.restart_after_pilot(self.config.stochastic);
        }
        let start = Instant::now();
        let Some(g) = &mut self.global else {
            return PassOutcome::Aborted;
        };
        let pass = g.next_pass();
        if self.interrupted() || (self.config.stochastic && !self.trace_stochastic_eye_pass(scene)) {
            return PassOutcome::Aborted;
        }
        if let Some(g) = &self.global {
            g.schedule_radii(pass, &mut self.estimates.slots);
        }
        self.stats.eye_secs += start.elapsed().as_secs_f64();
        let Some(gathered) = self.gather(scene, control) else {
            return PassOutcome::Aborted;
        };
        self.light.clear_area();
        self.sample_area_lights(scene);
        let (light, stochastic, eye_passes) = (&self.light, self.config.stochastic, self.stats.eye_passes);
        if let Some(g) = &mut self.global {
            let seen = |i| light.pass_value(i, stochastic, eye_passes);
            g.add_pass(
                pass,
                &mut self.estimates.slots,
                &gathered,
                seen,
                self.photons.photons,
            );
        }
        let s = &mut self.stats;
        s.passes += 1;
        if stochastic {
            s.eye_passes += 1;
        }
        s.count_photons(self.photons.photons, &gathered.counts);
        s.visible_points = self.eye.points.len();
        s.mean_radius = mean_primary_radius(&self.estimates.slots, Slot::has_radius).unwrap_or(0.0);
        s.elapsed_secs += start.elapsed().as_secs_f64();
        PassOutcome::Completed
    }

    /// What the eye pass needs of the render now.
    fn eye_job(&self) -> EyeJob<'_> {
        EyeJob {
            config: &self.config,
            pass: self.stream_pass(),
            interrupt: self.interrupt.as_deref(),
            reuse: None,
            keep_copy: false,
        }
    }

    /// Whether this is a warm epoch's first stochastic pass, which may reuse the previous
    /// epoch's last ([`super::reuse`]).
    fn reuses(&self) -> bool {
        self.stats.passes == 0 && self.config.stochastic && self.global.is_none()
    }

    /// Traces a stochastic eye pass ([`EyePass::trace_stochastic`]); its light seen chooses
    /// pixels to supersample except on the global schedule after the pilot.
    fn trace_stochastic_eye_pass(&mut self, scene: &Scene) -> bool {
        let reuse = self.epoch.reuse(self.reuses(), &scene.camera);
        let job = EyeJob {
            config: &self.config,
            pass: self.stream_pass(),
            interrupt: self.interrupt.as_deref(),
            reuse: reuse.as_ref(),
            keep_copy: self.config.options.warm_restarts,
        };
        let observe = self.global.as_ref().is_none_or(Global::learning);
        self.eye.trace_stochastic(&job, scene, &mut self.light, observe)
    }

    /// Traces the eye pass; `false` when interrupted (nothing the next pass needs changed then).
    /// The first sets the slots' radii ([`RadiusPolicy::start`]) and, in an epoch that
    /// inherited a warm start, keeps the unmoved pixels' statistics.
    fn eye_pass(&mut self, scene: &Scene) -> bool {
        if self.config.stochastic {
            // A stochastic pass's directly seen light counts only when the pass completes.
            if !self.trace_stochastic_eye_pass(scene) {
                return false;
            }
            if self.estimates.slots.is_empty() {
                self.estimates.slots = (0..self.config.width * self.config.height)
                    .map(Slot::new)
                    .collect();
            }
        } else {
            // Classic PPM keeps its one eye pass at once: a slot per visible point.
            let Some((direct, points)) = trace_classic(&self.eye_job(), scene) else {
                return false;
            };
            self.stats.eye_passes += 1;
            self.light.add_eye_pass(direct);
            self.eye.set_classic(points, &mut self.estimates.slots);
        }
        let slots = &mut self.estimates.slots;
        if self.stats.passes == 0 && slots.iter().all(|s| s.primary.radius2() == 0.0) {
            self.radius.start(slots, &self.eye.points, scene);
        }
        if self.stats.passes == 0 {
            self.keep_unmoved();
        }
        true
    }

    /// After the first eye pass of an epoch that inherited a warm start: the statistics and
    /// light seen of unmoved pixels, and estimates near moved points ([`WarmStart::keep_unmoved`]).
    fn keep_unmoved(&mut self) {
        let Some(warm) = &self.epoch.inherited else {
            return;
        };
        let reopen = Reopen::new(&self.radius, self.alpha, self.photons_per_pass);
        // This pass's copy in place, when it keeps one (with warm restarts, as here).
        let now = if self.eye.copy.len() == self.estimates.slots.len() {
            records_in_place(&self.eye.copy)
        } else {
            self.point_records()
        };
        let size = self.size();
        let kept = warm.keep_unmoved(&mut self.estimates.slots, &now, &reopen, size);
        self.light.set_prior(kept.light);
        self.stats.nearby_share = kept.nearby_share;
        let copied = self.eye.kinds.iter().filter(|&&k| k == PathKind::Copied).count();
        self.stats.copied_share = copied as f64 / self.eye.kinds.len().max(1) as f64;
        self.stats.kept_share = kept.kept_share;
    }

    /// Builds the index over this pass's visible points and traces its photons: what they
    /// handed each slot (`None` when the pass was interrupted or aborted).
    fn gather(&mut self, scene: &Scene, control: &mut dyn FnMut(&mut f64) -> Control) -> Option<Gathered> {
        let start = Instant::now();
        // Not on the global schedule: each of its passes must come out the same whichever
        // passes this process rendered before (shards render some of them).
        let reuse = self.global.is_none();
        let (index, largest) = self.eye.index(&self.estimates.slots, self.config.index, reuse);
        self.stats.index_secs += start.elapsed().as_secs_f64();
        if self.interrupted() {
            self.eye.keep(index);
            return None;
        }
        let start = Instant::now();
        // Each estimate's largest radius: how far from a photon its points are looked for.
        let radius = largest.map(|r2| (r2 as f64).sqrt());
        let gathered = self.photon_pass(scene, &index, radius, control);
        self.eye.keep(index);
        let gathered = gathered?;
        self.stats.photon_secs += start.elapsed().as_secs_f64();
        Some(gathered)
    }

    /// Traces this pass's photons ([`PhotonPass::run`]), as many as the guide chooses
    /// ([`guided_pass_photons`]), looking as far as `radius` from each.
    fn photon_pass(
        &mut self,
        scene: &Scene,
        index: &SpatialIndex,
        radius: [f64; 2],
        control: &mut dyn FnMut(&mut f64) -> Control,
    ) -> Option<Gathered> {
        let epoch_pass = match &self.global {
            Some(g) => g.stream_pass().saturating_sub(1),
            None => u64::from(self.stats.passes),
        };
        let photons = guided_pass_photons(self.guide.as_ref(), self.photons_per_pass, epoch_pass);
        let job = PhotonJob {
            config: &self.config,
            guide: self.guide.as_ref(),
            index,
            points: &self.eye.points,
            slots: self.estimates.slots.len(),
            estimates: self.radius.estimates(),
            radius,
            first_photon: self.first_photon(),
        };
        self.photons.run(&job, scene, photons, &mut self.alpha, control)
    }

    /// Adds one light sample of every area light at each visible point of this pass to the
    /// per-pixel sums (when direct light is on; see [`super::direct`]).
    fn sample_area_lights(&mut self, scene: &Scene) {
        if !self.config.direct_light || !super::direct::has_area_lights(scene) {
            return;
        }
        let start = Instant::now();
        let (pass, seed) = (self.stream_pass(), self.config.seed);
        let reuse = self.epoch.reuse(self.reuses(), &scene.camera);
        // Copied points whose light is the previous pass's (stochastic: slot k is pixel k).
        let known = reuse
            .map(|r| r.copy_area_light(scene, &self.eye.kinds, self.light.pass_light_mut()))
            .unwrap_or_default();
        let shade = &self.eye.points.shade;
        let skip = |k: usize| known.get(shade[k].slot as usize).is_some_and(|&b| b);
        let skip: Option<&(dyn Fn(usize) -> bool + Sync)> = (!known.is_empty()).then_some(&skip);
        self.light.sample_area_lights(
            scene,
            (&self.eye.points, &self.estimates.slots),
            (pass, seed),
            (self.config.stochastic, skip),
        );
        self.stats.direct_secs += start.elapsed().as_secs_f64();
    }

    /// Folds a completed pass into the slots, the radius choices after the first, the guide,
    /// the light seen and the statistics.
    fn update(&mut self, gathered: Gathered) {
        if let (Some(guide), Some(tally)) = (&mut self.guide, &gathered.tally) {
            guide.learn(tally);
        }
        self.estimates.fold(&gathered, self.alpha);
        if self.radius.indirect_scale == IndirectScale::Automatic && self.stats.passes == 0 {
            self.radius.widen_indirect(&mut self.estimates.slots, &gathered);
        }
        if self.radius.adaptive_radius && self.stats.passes == 0 {
            self.estimates.first_pass_photons = self.photons.photons;
            let size = self.size();
            let (narrowed, widened) = self.radius.adapt_radii(
                &mut self.estimates.slots,
                &gathered,
                (self.full_pass_photons, self.photons.photons),
                size,
            );
            self.stats.narrowed_share = narrowed;
            self.stats.widened_share = widened;
        }
        if self.config.stochastic && self.config.options.warm_restarts {
            let kept = self.epoch.last_eye.get_or_insert_with(Default::default);
            kept.keep(&mut self.eye.copy, &self.eye.kinds, self.light.pass_light());
        }
        if self.config.stochastic {
            self.stats.eye_passes += 1;
            self.stats.supersampled_share = self
                .light
                .complete_stochastic_pass(self.stats.eye_passes, self.stats.photons);
        }
        // The adaptive radius restarts its estimates at the second pass.
        if self.radius.adaptive_radius && self.stats.passes == 1 {
            self.stats.restarted_photons = self.stats.photons;
        }
        self.stats.passes += 1;
        self.epoch.inherited = None;
        self.stats.indirect_radius_scale = self.radius.indirect_scale_shown();
        self.stats.count_photons(self.photons.photons, &gathered.counts);
        self.stats.visible_points = self.eye.points.len();
        self.stats.mean_radius = self.estimates.mean_radius();
    }

    /// The pass whose random streams the eye pass and light samples use.
    fn stream_pass(&self) -> u64 {
        match &self.global {
            Some(g) => g.stream_pass(),
            None => self.epoch.offset.passes + self.stats.passes as u64,
        }
    }

    /// The random stream index of this pass's first photon.
    fn first_photon(&self) -> u64 {
        match &self.global {
            Some(g) => g.first_photon(),
            None => self.epoch.offset.photons + self.stats.photons,
        }
    }

    /// With the global radius schedule, renders only `passes` of the render (a shard's, or a
    /// part's own list), in order, instead of every pass; nothing otherwise.
    pub fn render_only(&mut self, passes: PassSet) {
        if let Some(g) = &mut self.global {
            g.render_only(passes);
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
    /// pixel's slots and the photons they gathered ([`PixelLayers::sweep`]).
    pub fn pixel_layers(&self) -> PixelLayers {
        // The global schedule's radiance is the mean of its passes' sums, not the slots'.
        let mean = self.global.as_ref().map(|g| g.sums.mean());
        PixelLayers::sweep(&self.estimates.slots, self.light.pixels(), mean, |i, slots| {
            self.pixel_radiance(i, slots)
        })
    }

    /// Pixel `i`'s radiance with per-point statistics, summed in f64 over its `slots`, plus its
    /// light seen directly.
    fn pixel_radiance(&self, i: usize, slots: &[Slot]) -> [f32; 3] {
        let c = self.estimates.photon_radiance(slots, self.stats.photons)
            + self.light.pixel(i, self.stats.eye_passes, self.stats.passes);
        [c.x as f32, c.y as f32, c.z as f32]
    }

    /// Each pixel's statistics slots, in pixel order (none for a pixel without a visible
    /// point): a pixel's slots lie together, and pixels in order, however the eye pass made
    /// them.
    pub fn slots_by_pixel(&self) -> impl Iterator<Item = &[Slot]> + '_ {
        self.estimates.by_pixel(self.light.pixels())
    }

    /// The statistics slots (for the viewer's probe).
    pub fn slots(&self) -> &[Slot] {
        &self.estimates.slots
    }

    /// What restarted in this epoch: every pixel's estimates at the adaptive radius's restart,
    /// and each lamp outline's light seen at its first supersampled pass (the `seen` module).
    pub fn restarts(&self) -> Restarts {
        Restarts {
            all: self.stats.restarted_photons,
            pixels: self.light.restarts().into(),
        }
    }

    /// Whether this epoch continues an earlier one's estimates (it inherited a warm start).
    pub fn is_warm(&self) -> bool {
        self.epoch.is_warm()
    }

    /// Each slot's visible point of the last eye pass (see [`records`]).
    fn point_records(&self) -> Vec<PointRecord> {
        records(self.estimates.slots.len(), &self.eye.points)
    }

    /// What this epoch hands to the next after an edit: `None` when it learned nothing (no
    /// pass completed and nothing inherited).
    pub fn into_warm_start(mut self) -> Option<WarmStart> {
        if self.global.is_some() {
            // Every pass of the global schedule is its own estimate at a scheduled radius:
            // there are no per-point statistics to keep.
            return None;
        }
        if self.stats.passes == 0 {
            return self.epoch.inherited;
        }
        // A stochastic eye pass interrupted since the last completed pass left its points
        // half written: the records kept at that pass count (see `update`).
        let (points, eye) = if self.config.stochastic {
            let eye = self.epoch.last_eye.take();
            let points = eye.as_ref().map(|e| records_in_place(&e.points));
            (points.unwrap_or_default(), eye)
        } else {
            (self.point_records(), None)
        };
        let s = &self.stats;
        Some(WarmStart {
            size: self.size(),
            stochastic: self.config.stochastic,
            slots: self.estimates.kept(s.photons),
            points,
            light: self.light.kept(s.eye_passes, s.passes),
            initial_radius2: self.radius.initial_radius2,
            indirect_scale: self.radius.indirect_scale,
            guide: self.guide,
            moved_lights: Vec::new(),
            next: StreamOffset {
                passes: self.epoch.offset.passes + s.passes as u64,
                photons: self.epoch.offset.photons + s.photons,
            },
            eye,
            changed: None,
        })
    }

    /// Starts this (new, edited) epoch from `warm`: the radius choices, the guide and the
    /// random streams now; the statistics of unmoved pixels at the first eye pass
    /// (`WarmStart::keep_unmoved`). Ignored when the image size or the kind of eye pass
    /// differ, or the points are missing (a stochastic render without
    /// [`PpmOptions::warm_restarts`]).
    pub fn inherit(&mut self, scene: &Scene, warm: WarmStart) {
        if self.global.is_some()
            || warm.size != self.size()
            || warm.stochastic != self.config.stochastic
            || warm.points.len() != warm.slots.len()
            || self.stats.passes > 0
        {
            return;
        }
        self.radius.initial_radius = Some(warm.initial_radius2.sqrt());
        self.radius.indirect_scale = warm.indirect_scale;
        if let (Some(guide), true) = (&warm.guide, self.guide.is_some()) {
            // A moved light keeps one first pass's worth (see `warm`'s module doc).
            let cap = (PRIOR_PASSES * self.photons_per_pass as f64) as u64;
            let caps = (cap, self.photons_per_pass);
            if let Some(prior) = guide.as_prior(scene, caps, &warm.moved_lights) {
                self.guide = Some(prior);
            }
        }
        self.epoch.inherit(warm);
    }
}
