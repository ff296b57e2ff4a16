//! Error against time: the curves `caustic bench convergence` measures, the figures read off
//! them (the error reached, the fitted log-log slope, the time to reach a target error) and the
//! CSV they are written to. The plot is [`super::plot`]; the cached reference is
//! [`super::reference`].

use std::fmt::Write as _;
use std::path::Path;

use crate::files::{write_atomically, WriteError};
pub use crate::render::error::errors;

/// One checkpoint of a curve: a completed pass.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Checkpoint {
    /// Passes completed.
    pub pass: u32,
    /// Wall-clock seconds since the render started.
    pub secs: f64,
    /// Root-mean-square error against the reference (over pixels and channels).
    pub rmse: f64,
    /// Relative mean squared error: mean of `(x − r)² / (r² + 0.01)` (pbrt's relMSE, with its
    /// guard against dark pixels).
    pub rel_mse: f64,
}

/// The error of one configuration over time.
#[derive(Clone, Debug, PartialEq)]
pub struct Curve {
    /// Name of the configuration.
    pub name: String,
    /// Checkpoints in time order.
    pub points: Vec<Checkpoint>,
}

impl Curve {
    /// The last checkpoint.
    pub fn last(&self) -> Option<&Checkpoint> {
        self.points.last()
    }

    /// Seconds until the RMSE first reached `target` (`None`: never).
    pub fn time_to(&self, target: f64) -> Option<f64> {
        self.points.iter().find(|p| p.rmse <= target).map(|p| p.secs)
    }

    /// The slope of log RMSE against log seconds, fitted by least squares over the second half
    /// of the curve (where the start-up has passed): about −1/3 for PPM with α = 2/3 in theory
    /// (Knaus & Zwicker 2011), flatter while the radius bias dominates. `None` with fewer than
    /// three usable points.
    pub fn slope(&self) -> Option<f64> {
        let usable: Vec<(f64, f64)> = self
            .points
            .iter()
            .filter(|p| p.secs > 0.0 && p.rmse > 0.0)
            .map(|p| (p.secs.ln(), p.rmse.ln()))
            .collect();
        let half = &usable[usable.len() / 2..];
        if half.len() < 3 {
            return None;
        }
        let n = half.len() as f64;
        let (mx, my) = half
            .iter()
            .fold((0.0, 0.0), |(a, b), (x, y)| (a + x / n, b + y / n));
        let (sxy, sxx) = half.iter().fold((0.0, 0.0), |(a, b), (x, y)| {
            (a + (x - mx) * (y - my), b + (x - mx) * (x - mx))
        });
        (sxx > 0.0).then(|| sxy / sxx)
    }
}

/// The CSV's header.
pub const CSV_HEADER: &str = "configuration,pass,seconds,rmse,rel_mse";

/// The curves as CSV text, a row per checkpoint.
pub fn csv(curves: &[Curve]) -> String {
    let mut text = format!("{CSV_HEADER}\n");
    for curve in curves {
        for p in &curve.points {
            let _ = writeln!(
                text,
                "{},{},{:.4},{:.6e},{:.6e}",
                super::csv_field(&curve.name),
                p.pass,
                p.secs,
                p.rmse,
                p.rel_mse
            );
        }
    }
    text
}

/// Writes [`csv`] to `path` (replacing it only when `force`).
pub fn write_csv(curves: &[Curve], path: &Path, force: bool) -> Result<(), WriteError> {
    write_atomically(path, force, |temporary| {
        std::fs::write(temporary, csv(curves)).map_err(|e| e.to_string())
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn curve(points: &[(f64, f64)]) -> Curve {
        Curve {
            name: "c".into(),
            points: points
                .iter()
                .enumerate()
                .map(|(k, &(secs, rmse))| Checkpoint {
                    pass: k as u32 + 1,
                    secs,
                    rmse,
                    rel_mse: rmse * rmse,
                })
                .collect(),
        }
    }

    #[test]
    fn slope_time_and_errors_read_the_curve() {
        // rmse = t^(-1/2) exactly.
        let c = curve(&[1.0, 2.0, 4.0, 8.0, 16.0, 32.0, 64.0].map(|t: f64| (t, t.powf(-0.5))));
        assert!((c.slope().expect("slope") + 0.5).abs() < 1e-12);
        assert_eq!(c.time_to(0.3), Some(16.0));
        assert_eq!(c.time_to(1e-3), None);
    }
}
