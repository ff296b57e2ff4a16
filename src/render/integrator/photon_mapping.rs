//! Progressive photon mapping ([`crate::render::ppm`]) as an integrator: a pass at a time, α
//! and the photon counts taken from each pass's plan.

use super::{Control, Integrator, PassPlan, Setup};
use crate::render::frame::{Frame, FrameStats, PixelLayer, StatRow};
use crate::render::ppm::{Changed, PassOutcome, Ppm, PpmOptions, PpmStats};
use crate::render::provenance;
use crate::scene::Scene;
use crate::settings::RendererKind;

/// A photon-mapping render of one epoch.
pub struct PhotonMapping {
    ppm: Ppm,
    guided_emission: bool,
    /// The lights as this render began (a warm restart tells the next which moved).
    lights: Vec<crate::scene::Light>,
    /// The patches as this render began (a warm restart tells the next where they moved).
    patches: Vec<crate::geometry::BezierPatch>,
}

impl PhotonMapping {
    /// A new render of `scene`.
    pub fn new(scene: &Scene, setup: &Setup) -> Self {
        let options = PpmOptions {
            batch_photons: setup.batch,
            warm_restarts: setup.warm_restarts,
            ..Default::default()
        };
        let mut ppm = Ppm::new(scene, options);
        ppm.set_interrupt(setup.interrupt.clone());
        Self {
            ppm,
            guided_emission: scene.params.guided_emission,
            lights: scene.lights.clone(),
            patches: scene.geometry.patches().iter().map(|(p, _)| *p).collect(),
        }
    }
}

impl Integrator for PhotonMapping {
    fn render_pass(
        &mut self,
        scene: &Scene,
        plan: &PassPlan,
        control: &mut dyn FnMut(&mut crate::settings::RenderParams) -> Control,
    ) -> bool {
        let ppm = &mut self.ppm;
        ppm.alpha = plan.params.alpha;
        let (w, h) = ppm.size();
        let full = plan.params.pass_photons(ppm.is_stochastic(), w as u64 * h as u64);
        ppm.full_pass_photons = full;
        // The global schedule's passes are estimates of one kind, whatever process renders
        // them: every one is full (no ramp).
        ppm.photons_per_pass = if ppm.pass_sums().is_some() {
            full
        } else {
            plan.pass_photons(ppm.stats().passes, full, ppm.is_warm())
        };
        // Between batches the settings come up to date; α is the one photon mapping reads.
        let mut live = plan.params.clone();
        let mut between_batches = |alpha: &mut f64| {
            let go_on = control(&mut live);
            *alpha = live.alpha;
            go_on
        };
        ppm.run_pass(scene, &mut between_batches) == PassOutcome::Completed
    }

    fn passes(&self) -> u32 {
        self.ppm.stats().passes
    }

    fn warm_restart(self: Box<Self>, scene: &Scene, setup: &Setup) -> Box<dyn Integrator> {
        let mut next = PhotonMapping::new(scene, setup);
        if let Some(mut kept) = self.ppm.into_warm_start() {
            let moved = (0..scene.lights.len()).filter(|&k| self.lights.get(k) != scene.lights.get(k));
            moved.for_each(|k| kept.light_moved(k));
            kept.edited(Changed::between(&self.patches, &self.lights, scene));
            next.ppm.inherit(scene, kept);
        }
        Box::new(next)
    }

    fn frame(&self, epoch: u64, elapsed_secs: f64) -> Frame {
        let mut frame = Frame::from_ppm(&self.ppm, epoch, elapsed_secs);
        frame.stats = frame_stats(self.ppm.stats().clone(), self.guided_emission);
        frame
            .stats
            .metadata
            .push(("caustic:alpha".into(), self.ppm.alpha.to_string()));
        frame
    }
}

impl Frame {
    /// The state of a photon-mapping render as a frame of `epoch`, `elapsed_secs` into it.
    pub fn from_ppm(ppm: &Ppm, epoch: u64, elapsed_secs: f64) -> Frame {
        let (width, height) = ppm.size();
        let stats = ppm.stats().clone();
        let layers = ppm.pixel_layers();
        Frame {
            epoch,
            pass: stats.passes,
            photons: stats.photons,
            restarts: ppm.restarts(),
            elapsed_secs,
            stats: FrameStats::from(stats),
            width,
            height,
            radiance: layers.radiance,
            layers: vec![
                PixelLayer {
                    name: "radius",
                    label: "radius",
                    help: "The search radius of the pixel's visible points (the largest of its estimates), in scene units",
                    decimals: 4,
                    values: layers.radius,
                },
                PixelLayer {
                    name: "photons",
                    label: "photons",
                    help: "The photons the pixel's estimates hold (N, after the shrinking; with the global radius schedule, those its last pass gathered)",
                    decimals: 0,
                    values: layers.gathered,
                },
            ],
            preview: false,
            error: crate::render::frame::ErrorSource::Frames,
        }
    }
}

/// A number with thousands separators.
fn count(n: u64) -> String {
    let digits = n.to_string();
    let mut out = String::new();
    for (i, c) in digits.chars().enumerate() {
        if i > 0 && (digits.len() - i).is_multiple_of(3) {
            out.push(',');
        }
        out.push(c);
    }
    out
}

/// The viewer's rows of photon mapping's statistics.
fn rows(s: &PpmStats) -> Vec<StatRow> {
    vec![
        StatRow::new("Photons", count(s.photons), "Photons emitted in this epoch"),
        StatRow::new(
            "Photons/s",
            count((s.photons as f64 / s.elapsed_secs.max(1e-9)) as u64),
            "Photons per second of render time in this epoch",
        ),
        StatRow::new(
            "Mean radius",
            format!("{:.4e}", s.mean_radius),
            "Mean search radius of points that have gathered photons (scene units)",
        ),
        StatRow::new(
            "Visible points",
            count(s.visible_points as u64),
            "Gathering points of the last eye pass",
        ),
        StatRow::new(
            "Useful photons",
            format!("{:.1} %", 100.0 * s.useful_paths as f64 / s.photons.max(1) as f64),
            "Share of the photons that handed light to at least one visible point (guided emission raises it)",
        ),
        StatRow::new(
            "Indirect radius",
            format!("{:.2}x", s.indirect_radius_scale),
            "The indirect light's initial radius over the initial radius (1: one estimate for all photons)",
        ),
        StatRow::new(
            "Narrowed radius",
            format!("{:.1} %", 100.0 * s.narrowed_share),
            "Share of the points whose radius was narrowed after the first pass, where photons were dense (adaptive radius)",
        ),
        StatRow::new(
            "Widened radius",
            format!("{:.1} %", 100.0 * s.widened_share),
            "Share of the points whose radius was widened after the first pass, where photons were sparse and no denser light was near (adaptive radius)",
        ),
        StatRow::new(
            "Supersampled",
            format!("{:.2} %", 100.0 * s.supersampled_share),
            "Share of the pixels whose light seen directly takes more eye rays a pass: 16 where it changes within the pixel (a lamp's outline, its images in mirrors and glass), 4 where it varies most between passes (a texture's or a shadow's edge, a floor seen through glass)",
        ),
    ]
}

/// The command line's summary of photon mapping's statistics.
fn summary(s: &PpmStats, guided: bool) -> Vec<String> {
    let mut lines = vec![
        format!(
            ", {} passes, {} photons in {:.2} s ({:.0} photons/s while tracing photons), mean radius {:.4}, {} visible points",
            s.passes,
            s.photons,
            s.elapsed_secs,
            s.photons as f64 / s.photon_secs.max(1e-9),
            s.mean_radius,
            s.visible_points
        ),
        format!(
            "  photons that reached a visible point: {:.1} %{}",
            100.0 * s.useful_paths as f64 / s.photons.max(1) as f64,
            if guided { " (guided emission on)" } else { "" }
        ),
    ];
    if s.indirect_radius_scale > 1.0 {
        lines.push(format!(
            "  indirect light gathered over {:.2}x the radius of direct light and caustics",
            s.indirect_radius_scale
        ));
    }
    if s.narrowed_share > 0.0 || s.widened_share > 0.0 {
        lines.push(format!(
            "  adaptive radius: {:.1} % of the points narrowed after the first pass, where photons were dense, {:.1} % widened, where they were sparse",
            100.0 * s.narrowed_share,
            100.0 * s.widened_share
        ));
    }
    if s.supersampled_share > 0.0 {
        lines.push(format!(
            "  light seen directly supersampled in {:.2} % of the pixels ({} more eye rays a pass where it changes within them, {} where it varies most between passes)",
            100.0 * s.supersampled_share,
            crate::render::ppm::SUBSAMPLES,
            crate::render::ppm::VARIED_SUBSAMPLES,
        ));
    }
    lines.push(format!(
        "  time: eye passes {:.3} s ({} of them), area-light sampling {:.3} s, index builds {:.3} s, photons {:.3} s",
        s.eye_secs, s.eye_passes, s.direct_secs, s.index_secs, s.photon_secs
    ));
    lines.extend(s.skipped.iter().map(|k| format!("  skipped: {k}")));
    lines
}

/// Photon mapping's statistics as a frame's; `guided` says whether guided emission was on.
pub fn frame_stats(s: PpmStats, guided: bool) -> FrameStats {
    FrameStats {
        kind: RendererKind::Ppm,
        seconds: s.elapsed_secs,
        rows: rows(&s),
        summary: summary(&s, guided),
        skipped: s.skipped.clone(),
        json: serde_json::json!({ "photon_mapping": &s }),
        metadata: vec![
            (provenance::PASSES.into(), s.passes.to_string()),
            ("caustic:photons".into(), s.photons.to_string()),
            ("caustic:mean_radius".into(), format!("{:.6}", s.mean_radius)),
            ("caustic:elapsed_secs".into(), format!("{:.3}", s.elapsed_secs)),
        ],
        progress: format!("{:.2} M photons/s", s.photons as f64 / s.photon_secs.max(1e-9) / 1e6),
    }
}

impl From<PpmStats> for FrameStats {
    fn from(s: PpmStats) -> Self {
        frame_stats(s, false)
    }
}
