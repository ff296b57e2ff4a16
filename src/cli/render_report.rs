//! What `caustic render` tells the person running it: a progress bar, warnings, the error
//! against a reference after each pass, and the closing summary — as lines of text, or with
//! `--json` as one JSON document on stdout (progress and warnings stay on stderr).

use std::path::Path;

use serde::Serialize;

use caustic::render::compare::{Reference, ReferenceErrors};
use caustic::render::session::FrameStats;
use caustic::render::Image;
use caustic::scene::Scene;

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
    /// The renderer's statistics under its key (`photon_mapping`, `whitted`, …).
    #[serde(flatten)]
    renderer: &'a serde_json::Value,
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
        caustic::run::progress_bar(len, template, message)
            .unwrap_or_else(|_| indicatif::ProgressBar::hidden())
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
        stats: &FrameStats,
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
                renderer: &stats.json,
                reference: reference_summary,
                warnings: &self.warnings,
            };
            match serde_json::to_string_pretty(&summary) {
                Ok(text) => println!("{text}"),
                Err(e) => eprintln!("error: cannot write the JSON summary: {e}"),
            }
            return;
        }
        print_text(out, image, stats);
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

fn print_text(out: &Path, image: &Image, stats: &FrameStats) {
    let (w, h) = (image.width, image.height);
    let mut lines = stats.summary.iter();
    println!(
        "{}: {w}x{h}{}",
        out.display(),
        lines.next().map_or("", String::as_str)
    );
    for line in lines {
        println!("{line}");
    }
}
