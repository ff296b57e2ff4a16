//! `caustic bench estimate`: how true the viewer's error estimate is. Each scene renders as
//! in the viewer (photon mapping, the photon ramp, every frame seen) and, after some passes,
//! the estimate from its own frames ([`ErrorTracker`], and the consecutive-frame estimate it
//! replaced) is set beside the true relative RMS error against a long reference render
//! (cached, as `bench convergence`'s).
//!
//! Scenes are rendered smaller than their own size so that a 4000-pass reference takes
//! minutes; the photons per pass are scaled with the pixels, so that each pixel sees as many
//! photons a pass as at the scene's own size.

use std::path::PathBuf;
use std::time::{Duration, Instant};

use anyhow::{bail, Result};
use clap::Parser;

use super::convergence::reference;
use super::output::BenchOutput;
use crate::args::Threads;
use crate::render::error::{mean_squares, relative_error_estimate};
use crate::render::error_tracker::{effective_pixels, ErrorEstimate, ErrorTracker};
use crate::render::session::state::INTERACTIVE_FIRST_PASS_PHOTONS;
use crate::render::session::SessionOptions;
use crate::run::render_session;
use crate::scene::{RendererKind, Scene};

/// `caustic bench estimate`.
#[derive(Parser)]
pub struct EstimateArgs {
    /// Scene files (default: scenes/pool.toml, scenes/cornell.toml, scenes/ring.toml).
    pub scenes: Vec<PathBuf>,
    /// Image width (the height keeps the scene's aspect).
    #[arg(long, default_value_t = 160)]
    width: u32,
    /// Passes after which the estimate is compared with the truth.
    #[arg(long, value_delimiter = ',', default_value = "16,64,256")]
    passes: Vec<u32>,
    /// Passes of the reference render (cached).
    #[arg(long, default_value_t = 4000)]
    reference_passes: u32,
    /// Where reference renders are cached (default: ~/.cache/caustic/references).
    #[arg(long, value_name = "DIR")]
    reference_dir: Option<PathBuf>,
    /// `--threads`: the worker pool's size.
    #[command(flatten)]
    pub threads: Threads,
}

/// One comparison: after `pass` passes, the true relative RMS error, the estimate and the
/// consecutive-frame estimate.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EstimateCheck {
    /// Passes rendered.
    pub pass: u32,
    /// `RMS(L − reference) / RMS(reference)`.
    pub truth: f64,
    /// The effective number of pixels the true error is in ([`effective_pixels`] of the
    /// frame and the reference).
    pub truth_pixels: f64,
    /// [`ErrorTracker`]'s estimate.
    pub estimate: Option<ErrorEstimate>,
    /// The previous frame's comparison (one pass apart).
    pub consecutive: Option<f64>,
}

impl EstimateCheck {
    /// The estimate (noise and blur) over the truth.
    pub fn ratio(&self) -> Option<f64> {
        self.estimate.map(|e| e.total() / self.truth)
    }

    /// What the check found: `within` (the estimate within 1.5 times the truth either way),
    /// `uncertain` (the estimate says it rests on few pixels), `off`, or `none` (no estimate).
    pub fn verdict(&self) -> &'static str {
        match (self.estimate, self.ratio()) {
            (Some(_), Some(r)) if (1.0 / 1.5..=1.5).contains(&r) => "within",
            (Some(e), _) if e.uncertain() => "uncertain",
            (Some(_), _) => "off",
            (None, _) => "none",
        }
    }
}

/// `scene` at `width`, photon mapping, photons per pass scaled with the pixels.
pub fn scaled(mut scene: Scene, width: u32) -> Scene {
    let before = scene.camera.width as f64 * scene.camera.height as f64;
    scene.camera.resize(Some(width), None);
    let after = scene.camera.width as f64 * scene.camera.height as f64;
    let photons = (scene.params.photons_per_pass as f64 * after / before).round() as u64;
    scene.params.photons_per_pass = photons.max(1000);
    scene.params.renderer = RendererKind::Ppm;
    scene
}

/// Renders `scene` as the viewer does for the largest of `passes`, comparing the estimates
/// with the truth against `reference` after each of them; also the mean seconds the estimate
/// took a frame.
pub fn check_estimates(
    scene: Scene,
    passes: &[u32],
    reference: &[[f32; 3]],
) -> Result<(Vec<EstimateCheck>, f64)> {
    let most = passes.iter().copied().max().unwrap_or(0);
    let options = SessionOptions {
        max_passes: Some(most),
        first_pass_photons: Some(INTERACTIVE_FIRST_PASS_PHOTONS),
        ..Default::default()
    };
    let alpha = scene.params.alpha;
    let mut tracker = ErrorTracker::default();
    let mut previous: Option<(u64, std::sync::Arc<[[f32; 3]]>)> = None;
    let mut out = Vec::new();
    let (mut tracking, mut frames) = (Duration::ZERO, 0u32);
    render_session(scene, options, |f| {
        let start = Instant::now();
        let estimate = tracker.add((f.photons, &f.restarts), &f.radiance, alpha);
        tracking += start.elapsed();
        frames += 1;
        let consecutive = previous
            .as_ref()
            .and_then(|(n, a)| relative_error_estimate(*n, a, f.photons, &f.radiance));
        previous = Some((f.photons, f.radiance.clone()));
        if passes.contains(&f.pass) {
            let (diff2, norm2) = mean_squares(&f.radiance, reference);
            out.push(EstimateCheck {
                pass: f.pass,
                truth: (diff2 / norm2).sqrt(),
                truth_pixels: effective_pixels(&f.radiance, reference),
                estimate,
                consecutive,
            });
        }
    })?;
    Ok((out, tracking.as_secs_f64() / frames.max(1) as f64))
}

/// Runs the measurement.
pub fn bench_estimate(args: EstimateArgs, out: &mut BenchOutput) -> Result<()> {
    if args.passes.is_empty() || args.passes.contains(&0) || args.width == 0 {
        bail!("--passes must list passes of at least 1, and --width be at least 1");
    }
    let scenes = if args.scenes.is_empty() {
        ["pool", "cornell", "ring"]
            .map(|s| PathBuf::from(format!("scenes/{s}.toml")))
            .to_vec()
    } else {
        args.scenes.clone()
    };
    out.say(
        "scene  pass  true (pixels)  noise (ratio)  blur (ratio)  noise and blur (ratio, pixels)  verdict  consecutive frames (ratio)"
            .to_string(),
    );
    for path in &scenes {
        let scene = scaled(Scene::load(path)?, args.width);
        let reference = reference(
            &scene,
            args.reference_passes,
            args.reference_dir.as_deref(),
            None,
            out,
        )?;
        let (w, h) = (scene.camera.width, scene.camera.height);
        let (checks, per_frame) = check_estimates(scene, &args.passes, &reference)?;
        out.say(format!(
            "{}: the estimate took {:.2} ms a frame at {w}x{h} (the viewer's thread, after each pass)",
            path.display(),
            1e3 * per_frame
        ));
        out.push(
            "estimate_time",
            serde_json::json!({ "scene": path.display().to_string(), "width": w, "height": h, "secs_a_frame": per_frame }),
        );
        for c in checks {
            report_check(path, &c, out);
        }
    }
    Ok(())
}

/// Prints and records one check of the estimate of `path`'s render.
fn report_check(path: &std::path::Path, c: &EstimateCheck, out: &mut BenchOutput) {
    let show = |e: Option<f64>| {
        e.map_or("-".into(), |e| {
            format!("{:.2} % ({:.2}x)", 100.0 * e, e / c.truth)
        })
    };
    let total = c.estimate.map_or("-".into(), |e| {
        format!(
            "{:.2} % ({:.2}x, {:.0})",
            100.0 * e.total(),
            e.total() / c.truth,
            e.pixels
        )
    });
    out.say(format!(
        "{}  {}  {:.2} % ({:.0})  {}  {}  {}  {}  {}",
        path.display(),
        c.pass,
        100.0 * c.truth,
        c.truth_pixels,
        show(c.estimate.map(|e| e.noise)),
        show(c.estimate.and_then(|e| e.blur)),
        total,
        c.verdict(),
        show(c.consecutive)
    ));
    let name = path
        .file_stem()
        .map_or("scene".into(), |s| s.to_string_lossy().into_owned());
    out.push(
        "checks",
        serde_json::json!({
            "scene": name,
            "pass": c.pass,
            "truth": c.truth,
            "truth_pixels": c.truth_pixels,
            "estimate": c.estimate.map(|e| e.noise),
            "blur": c.estimate.and_then(|e| e.blur),
            "total": c.estimate.map(|e| e.total()),
            "pixels": c.estimate.map(|e| e.pixels),
            "verdict": c.verdict(),
            "consecutive": c.consecutive,
        }),
    );
}
