//! Repeated timings on a shared machine. Another tenant of the host can only add time to a
//! run, never take it away, so the least of several runs is the steadiest figure of what the
//! code costs, and the median says what a person typically waits. Runs of different
//! configurations (thread counts) are interleaved round by round, so a slow spell of the host
//! falls on all of them rather than on one (as Chen & Revels 2016, "Robust benchmarking in
//! noisy environments", argue for the minimum).

/// The seconds one measurement took each time it was run.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Timings {
    seconds: Vec<f64>,
}

impl Timings {
    /// Adds one run's seconds.
    pub fn push(&mut self, seconds: f64) {
        self.seconds.push(seconds);
    }

    /// Every run's seconds, in the order they ran.
    pub fn seconds(&self) -> &[f64] {
        &self.seconds
    }

    /// The least of the runs (NaN when there were none).
    pub fn best(&self) -> f64 {
        self.seconds.iter().copied().reduce(f64::min).unwrap_or(f64::NAN)
    }

    /// The median of the runs ([`median`]).
    pub fn median(&self) -> f64 {
        median(self.seconds.clone())
    }
}

/// The median of `values`: the middle one, for an even count the upper of the two middle ones
/// (always a value that was measured); NaN for none.
pub fn median(mut values: Vec<f64>) -> f64 {
    values.sort_by(f64::total_cmp);
    values.get(values.len() / 2).copied().unwrap_or(f64::NAN)
}

/// Runs `measure` for every one of `configurations` in turn, `rounds` times over (round by
/// round, so the configurations' runs interleave), and gathers each configuration's seconds;
/// stops at the first error.
pub fn interleaved<C: Copy, E>(
    rounds: usize,
    configurations: &[C],
    mut measure: impl FnMut(C) -> Result<f64, E>,
) -> Result<Vec<Timings>, E> {
    let mut timings = vec![Timings::default(); configurations.len()];
    for _ in 0..rounds {
        for (config, t) in configurations.iter().zip(&mut timings) {
            t.push(measure(*config)?);
        }
    }
    Ok(timings)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn of(seconds: &[f64]) -> Timings {
        let mut t = Timings::default();
        seconds.iter().for_each(|&s| t.push(s));
        t
    }

    #[test]
    fn best_is_the_least_and_median_the_middle() {
        let t = of(&[3.0, 1.5, 2.0]);
        assert_eq!(t.best(), 1.5);
        assert_eq!(t.median(), 2.0);
        let even = of(&[4.0, 1.0, 3.0, 2.0]);
        assert_eq!(even.best(), 1.0);
        assert_eq!(even.median(), 3.0);
        assert_eq!(even.seconds(), &[4.0, 1.0, 3.0, 2.0]);
        assert!(Timings::default().best().is_nan());
        assert!(Timings::default().median().is_nan());
    }

    #[test]
    fn configurations_interleave_round_by_round() {
        let mut order = Vec::new();
        let mut clock = 0.0;
        let timings = interleaved(3, &[1usize, 2], |threads| {
            order.push(threads);
            clock += 1.0;
            Ok::<_, ()>(clock * threads as f64)
        })
        .expect("no run fails");
        assert_eq!(order, [1, 2, 1, 2, 1, 2]);
        assert_eq!(timings[0].seconds(), &[1.0, 3.0, 5.0]);
        assert_eq!(timings[1].seconds(), &[4.0, 8.0, 12.0]);
    }

    #[test]
    fn the_first_error_stops_the_runs() {
        let mut runs = 0;
        let result = interleaved(4, &[1usize, 2], |threads| {
            runs += 1;
            if runs == 3 {
                Err(format!("run {runs} with {threads} threads failed"))
            } else {
                Ok(1.0)
            }
        });
        assert_eq!(result, Err("run 3 with 1 threads failed".to_owned()));
        assert_eq!(runs, 3);
    }
}
