//! The Whitted ray tracer ([`crate::render::whitted`]) as an integrator: one frame per epoch.

use super::{Integrator, PassPlan, Setup};
use crate::render::frame::{Frame, FrameStats, StatRow};
use super::Control;
use crate::render::whitted::{render_whitted_until, WhittedStats};
use crate::scene::Scene;
use crate::settings::RendererKind;

/// The ray tracer's frame of an epoch.
pub struct RayTracer {
    setup: Setup,
    traced: Option<(crate::render::Image, WhittedStats)>,
}

impl RayTracer {
    /// Nothing traced yet.
    pub fn new(_scene: &Scene, setup: &Setup) -> Self {
        Self {
            setup: setup.clone(),
            traced: None,
        }
    }
}

/// The ray tracer's statistics as a frame's.
pub fn frame_stats(stats: &WhittedStats) -> FrameStats {
    let rate = stats.camera_rays as f64 / stats.elapsed_secs.max(1e-9);
    FrameStats {
        kind: RendererKind::Whitted,
        seconds: stats.elapsed_secs,
        rows: vec![
            StatRow::new("Camera rays", stats.camera_rays.to_string(), "Eye rays traced, anti-aliasing included"),
            StatRow::new(
                "Edge pixels",
                stats.edge_pixels.to_string(),
                "Pixels the edge-adaptive anti-aliasing sampled again",
            ),
        ],
        summary: vec![format!(
            " ray traced in {:.2} s ({} camera rays, {} edge pixels re-sampled, {rate:.0} rays/s)",
            stats.elapsed_secs, stats.camera_rays, stats.edge_pixels
        )],
        skipped: Vec::new(),
        json: serde_json::json!({ "whitted": stats }),
        metadata: vec![
            ("caustic:camera_rays".into(), stats.camera_rays.to_string()),
            ("caustic:elapsed_secs".into(), format!("{:.3}", stats.elapsed_secs)),
        ],
        progress: String::new(),
    }
}

impl Integrator for RayTracer {
    fn render_pass(&mut self, scene: &Scene, _plan: &PassPlan, _control: &mut dyn FnMut(&mut crate::settings::RenderParams) -> Control) -> bool {
        let setup = &self.setup;
        match render_whitted_until(scene, &|_| {}, &|| setup.interrupted()) {
            Some(traced) => {
                self.traced = Some(traced);
                true
            }
            None => false,
        }
    }

    fn passes(&self) -> u32 {
        u32::from(self.traced.is_some())
    }

    fn frame(&self, epoch: u64, elapsed_secs: f64) -> Frame {
        let Some((image, stats)) = &self.traced else {
            return Frame::of_radiance((0, 0), Vec::new(), 0, (epoch, elapsed_secs), frame_stats(&WhittedStats::default()));
        };
        Frame::of_radiance(
            (image.width, image.height),
            image.pixels.clone(),
            1,
            (epoch, elapsed_secs),
            frame_stats(stats),
        )
    }
}
