//! The gyro's delay behind the reference, for scoring: a logger that stamps rows on
//! arrival, or a reference pose sent on its own path, puts the two tens of milliseconds
//! apart. Scored against the reference as logged, every movement's reference change then
//! misses the part of the turn the reference made before the gyro's movement began, and
//! the per-sample error during turns is the rate times the delay; both look like sensor
//! errors. The delay is each run's cross-correlation peak ([`crate::lag::log_lag_s`]),
//! the median over the training runs.

use super::BenchRun;
use crate::lag::log_lag_s;
use serde::Serialize;

/// Half-width of the search (s): the same as `run`'s ([`crate::lag::SEARCH_S`]).
pub use crate::lag::SEARCH_S;

/// Delays shorter than this many grid slots are not applied: the parabola through the peak
/// resolves a fraction of a slot, but below half of one a delay cannot be told from where
/// the grid's slots fall (a bench encoder and gyro sampled together show a few µs).
pub const MIN_SLOTS: f64 = 0.5;

/// Where the delay used for scoring came from.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum DelaySource {
    /// Given (`--reference-delay-s`, or the starting model file's `reference_delay_s`).
    Given,
    /// The cross-correlation peak, median over the training runs.
    CrossCorrelation,
    /// Measured below [`MIN_SLOTS`] grid slots (or not measurable): none applied.
    NotApplied,
}

/// The delay every replay of the calibration is scored with.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ReferenceDelay {
    /// The delay applied (s; positive: the gyro lags the reference). Written to the model
    /// file's `reference_delay_s`.
    pub delay_s: f64,
    /// Where it came from.
    pub source: DelaySource,
    /// The peak per training run (s), in training order; `None` where a run has no
    /// defined peak. Empty when the delay was given.
    pub per_run_s: Vec<Option<f64>>,
}

impl ReferenceDelay {
    /// A delay given by the user or the starting model.
    pub fn given(delay_s: f64) -> Self {
        Self {
            delay_s,
            source: DelaySource::Given,
            per_run_s: Vec::new(),
        }
    }
}

/// The delay measured on `runs`: the median of their peaks, applied when it is at least
/// [`MIN_SLOTS`] grid slots of the first run.
pub fn measure(runs: &[&BenchRun]) -> ReferenceDelay {
    let per_run_s: Vec<Option<f64>> = runs.iter().map(|run| log_lag_s(&run.log)).collect();
    let lags: Vec<f64> = per_run_s.iter().flatten().copied().collect();
    let fs = runs.first().map_or(f64::NAN, |r| r.log.sample_rate_hz);
    match crate::median(&lags) {
        Some(delay_s) if delay_s.abs() * fs >= MIN_SLOTS => ReferenceDelay {
            delay_s,
            source: DelaySource::CrossCorrelation,
            per_run_s,
        },
        _ => ReferenceDelay {
            delay_s: 0.0,
            source: DelaySource::NotApplied,
            per_run_s,
        },
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use gyro_log::{Quality, RegularLog, Slot};

    /// A run whose gyro sees the reference's turns `lag_s` late.
    fn run(lag_s: f64, fs: f64) -> BenchRun {
        let angle = |t: f64| {
            // Rest, a 90 degree turn in 1 s, rest, back, rest.
            let ramp =
                |t: f64| 90.0 * (0.5 - 0.5 * (std::f64::consts::PI * t.clamp(0.0, 1.0)).cos());
            ramp(t - 2.0) - ramp(t - 5.0)
        };
        let n = (8.0 * fs) as usize;
        let slots = (0..n)
            .map(|i| {
                let t = i as f64 / fs;
                let rate = (angle(t - lag_s + 0.5 / fs) - angle(t - lag_s - 0.5 / fs)) * fs;
                Slot {
                    time_s: t,
                    rate_dps: rate,
                    reference_deg: Some(angle(t)),
                    temperature_c: None,
                    line: i as u64 + 1,
                    filled: false,
                }
            })
            .collect();
        BenchRun {
            name: format!("lag {lag_s}"),
            log: RegularLog {
                slots,
                sample_rate_hz: fs,
                has_reference: true,
                has_temperature: false,
                quality: Quality::default(),
            },
        }
    }

    #[test]
    fn finds_a_logger_delay_and_ignores_none() {
        let runs = [run(0.09, 100.0), run(0.1, 100.0), run(0.08, 100.0)];
        let refs: Vec<&BenchRun> = runs.iter().collect();
        let d = measure(&refs);
        assert_eq!(d.source, DelaySource::CrossCorrelation);
        assert!((d.delay_s - 0.09).abs() < 0.004, "{d:?}");
        let still = [run(0.0, 1000.0), run(0.0, 1000.0)];
        let refs: Vec<&BenchRun> = still.iter().collect();
        let d = measure(&refs);
        assert_eq!(d.source, DelaySource::NotApplied, "{d:?}");
        assert_eq!(d.delay_s, 0.0);
    }

    #[test]
    fn a_lead_is_negative() {
        let runs = [run(-0.03, 1000.0), run(-0.03, 1000.0)];
        let refs: Vec<&BenchRun> = runs.iter().collect();
        let d = measure(&refs);
        assert!((d.delay_s + 0.03).abs() < 0.001, "{d:?}");
    }
}
