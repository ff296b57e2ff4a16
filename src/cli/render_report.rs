//! What `caustic render` tells the person running it: a progress bar, warnings, the error
//! against a reference after each pass, and the closing summary — as lines of text, or with
//! `--json` as one JSON document on stdout (progress and warnings stay on stderr).

use std::path::Path;

use serde::Serialize;

use caustic::render::compare::{Reference, ReferenceErrors};
use caustic::render::ppm::PpmStats;
use caustic::render::{Image, WhittedStats};
use caustic::scene::Scene;

/// What the renderer measured.
#[derive(Serialize)]
#[serde(rename_all = "snake_case")]
pub enum RendererSummary {
    /// Photon mapping's statistics.
    PhotonMapping(PpmStats),
    /// The ray tracer's statistics.
    Whitted(WhittedStats),
}

/// The error against the reference after one pass.
#[derive(Clone, Copy, Serialize)]
pub struct PassError {
    /// Passes completed.
    pub pass: u32,
    /// Seconds since the render started.
    pub seconds: f64,
    /// The errors.
    #[serde(flatten)]
    pub errors: ReferenceErrors,
}

/// The report being gathered while a render runs.
pub struct Report {
    json: bool,
    warnings: Vec<String>,
    pass_errors: Vec<PassError>,
    bar: Option<indicatif::ProgressBar>,
}

/// The JSON summary.
#[derive(Serialize)]
struct Summary<'a> {
    output: String,
    program: String,
    scene: String,
    width: u32,
    height: u32,
    seed: u64,
    mean: f64,
    #[serde(flatten)]
    renderer: &'a RendererSummary,
    reference: Option<ReferenceSummary<'a>>,
    warnings: &'a [String],
}

#[derive(Serialize)]
struct ReferenceSummary<'a> {
    path: String,
    #[serde(flatten)]
    last: Option<ReferenceErrors>,
    passes: &'a [PassError],
}

impl Report {
    /// An empty report; `json` chooses the summary's form.
    pub fn new(json: bool) -> Self {
        Self {
            json,
            warnings: Vec::new(),
            pass_errors: Vec::new(),
            bar: None,
        }
    }

    /// A progress bar over `len` steps (drawn only on a terminal, on stderr).
    pub fn bar(&self, len: u64, template: &str, message: String) -> indicatif::ProgressBar {
        super::progress_bar(len, template, message).unwrap_or_else(|_| indicatif::ProgressBar::hidden())
    }

    /// The bar lines are printed above while it runs.
    pub fn set_bar(&mut self, bar: Option<indicatif::ProgressBar>) {
        self.bar = bar;
    }

    fn print_line(&self, line: &str, stderr: bool) {
        let print = || {
            if stderr {
                eprintln!("{line}");
            } else {
                println!("{line}");
            }
        };
        match &self.bar {
            Some(bar) => bar.suspend(print),
            None => print(),
        }
    }

    /// A warning: printed on stderr now and listed in the JSON summary.
    pub fn warn(&mut self, message: String) {
        self.print_line(&format!("warning: {message}"), true);
        self.warnings.push(message);
    }

    /// The error after a pass: a line of text now (not with `--json`: the summary lists them).
    pub fn pass_error(&mut self, pass: u32, seconds: f64, errors: ReferenceErrors) {
        if !self.json {
            self.print_line(
                &format!(
                    "pass {pass:>5} {seconds:>9.2} s   RMSE {:.4e}   relMSE {:.4e}",
                    errors.rmse, errors.rel_mse
                ),
                false,
            );
        }
        self.pass_errors.push(PassError {
            pass,
            seconds,
            errors,
        });
    }

    /// Prints the closing summary of a render saved to `out`.
    pub fn finish(
        &self,
        out: &Path,
        scene: &Scene,
        renderer: RendererSummary,
        reference: Option<&Reference>,
        image: &Image,
    ) {
        let reference_summary = reference.map(|r| ReferenceSummary {
            path: r.path.display().to_string(),
            last: r.errors(&image.pixels),
            passes: &self.pass_errors,
        });
        if self.json {
            let summary = Summary {
                output: out.display().to_string(),
                program: caustic::render::provenance::software(),
                scene: scene.source.display().to_string(),
                width: image.width,
                height: image.height,
                seed: scene.params.seed,
                mean: image.mean(),
                renderer: &renderer,
                reference: reference_summary,
                warnings: &self.warnings,
            };
            match serde_json::to_string_pretty(&summary) {
                Ok(text) => println!("{text}"),
                Err(e) => eprintln!("error: cannot write the JSON summary: {e}"),
            }
            return;
        }
        print_text(out, image, &renderer, scene.params.guided_emission);
        if let Some(r) = reference_summary {
            if let Some(e) = r.last {
                println!(
                    "  against {}: RMSE {:.4e}, relative MSE {:.4e}",
                    r.path, e.rmse, e.rel_mse
                );
            }
        }
    }
}

fn print_text(out: &Path, image: &Image, renderer: &RendererSummary, guided: bool) {
    let (w, h) = (image.width, image.height);
    match renderer {
        RendererSummary::Whitted(stats) => println!(
            "{}: {w}x{h} ray traced in {:.2} s ({} camera rays, {} edge pixels re-sampled, {:.0} rays/s)",
            out.display(),
            stats.elapsed_secs,
            stats.camera_rays,
            stats.edge_pixels,
            stats.camera_rays as f64 / stats.elapsed_secs.max(1e-9)
        ),
        RendererSummary::PhotonMapping(s) => {
            println!(
                "{}: {w}x{h}, {} passes, {} photons in {:.2} s ({:.0} photons/s while tracing photons), mean radius {:.4}, {} visible points",
                out.display(),
                s.passes,
                s.photons,
                s.elapsed_secs,
                s.photons as f64 / s.photon_secs.max(1e-9),
                s.mean_radius,
                s.visible_points
            );
            println!(
                "  photons that reached a visible point: {:.1} %{}",
                100.0 * s.useful_paths as f64 / s.photons.max(1) as f64,
                if guided { " (guided emission on)" } else { "" }
            );
            if s.indirect_radius_scale > 1.0 {
                println!(
                    "  indirect light gathered over {:.2}x the radius of direct light and caustics",
                    s.indirect_radius_scale
                );
            }
            if s.narrowed_share > 0.0 {
                println!(
                    "  adaptive radius: {:.1} % of the points narrowed after the first pass, where photons were dense",
                    100.0 * s.narrowed_share
                );
            }
            println!(
                "  time: eye passes {:.3} s ({} of them), area-light sampling {:.3} s, index builds {:.3} s, photons {:.3} s",
                s.eye_secs, s.eye_passes, s.direct_secs, s.index_secs, s.photon_secs
            );
            for skipped in &s.skipped {
                println!("  skipped: {skipped}");
            }
        }
    }
}
