//! Several logs characterised together: each on its own, and pooled when they share a
//! sample rate (what `gyro-cli noise LOG...` reports).

use super::{characterize, Characterization, NoiseError, NoiseOptions};
use gyro_log::Quality;
use std::ops::Range;

/// One log's rates, ready to characterise.
#[derive(Clone, Debug, PartialEq)]
pub struct NoiseLog {
    /// The file, as it is named in outputs.
    pub file: String,
    /// The rate on the grid (deg/s).
    pub rate_dps: Vec<f64>,
    /// Grid rate (Hz).
    pub sample_rate_hz: f64,
    /// The stretches used: the whole log, or its rests.
    pub segments: Vec<Range<usize>>,
    /// What was irregular in the log.
    pub input: Quality,
    /// The share of the stretches used that the motion detector finds moving (0..1), when
    /// the log is taken whole; `None` when only its rests are used.
    pub moving_share: Option<f64>,
}

/// A log taken whole whose stretches are more than this share in motion is not a static
/// log: its Allan deviation and PSD are the motion's, not the sensor's noise.
pub const MOVING_SHARE_LIMIT: f64 = 0.01;

/// The warning for `log` when it is taken whole and moves ([`MOVING_SHARE_LIMIT`]).
pub fn moving_warning(log: &NoiseLog) -> Option<String> {
    let share = log.moving_share.filter(|s| *s > MOVING_SHARE_LIMIT)?;
    Some(format!(
        "{}: {:.0}% of the log is in motion by the motion detector: its Allan deviation, PSD and fit are of the motion, not of the sensor's noise; use --static-only (its rests) or a static log",
        log.file,
        100.0 * share
    ))
}

impl NoiseLog {
    /// The rate of each segment.
    pub fn parts(&self) -> Vec<&[f64]> {
        self.segments
            .iter()
            .map(|r| &self.rate_dps[r.clone()])
            .collect()
    }

    /// The segments as (start, end) times from the log's start (s).
    pub fn stretches_s(&self) -> Vec<(f64, f64)> {
        let dt = 1.0 / self.sample_rate_hz;
        self.segments
            .iter()
            .map(|s| (s.start as f64 * dt, s.end as f64 * dt))
            .collect()
    }
}

/// The characterisation of each log, and of all pooled.
#[derive(Clone, Debug, PartialEq)]
pub struct NoiseRun {
    /// One per log, in order.
    pub results: Vec<Characterization>,
    /// All logs pooled, when there are several at one sample rate.
    pub combined: Option<Characterization>,
    /// True when there are several logs but their sample rates differ (nothing pooled).
    pub rates_differ: bool,
}

impl NoiseRun {
    /// The result a model file or a plot is made from: the pooled one, else the only one.
    pub fn single(&self) -> Option<&Characterization> {
        match (&self.combined, self.results.as_slice()) {
            (Some(c), _) => Some(c),
            (None, [only]) => Some(only),
            _ => None,
        }
    }
}

/// Why [`characterize_logs`] failed.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum NoiseLogsError {
    /// One log cannot be characterised.
    #[error("{file}: {cause}")]
    Log {
        /// The log.
        file: String,
        /// Why (in the message, not chained: it would print twice).
        cause: NoiseError,
    },
    /// The pooled logs cannot be characterised.
    #[error("all logs pooled: {cause}")]
    Pooled {
        /// Why (in the message, not chained).
        cause: NoiseError,
    },
}

/// Characterise each log, and all of them pooled when there are several at one rate.
pub fn characterize_logs(
    logs: &[NoiseLog],
    options: &NoiseOptions,
) -> Result<NoiseRun, NoiseLogsError> {
    let results = logs
        .iter()
        .map(|l| {
            characterize(&l.parts(), l.sample_rate_hz, options).map_err(|cause| {
                NoiseLogsError::Log {
                    file: l.file.clone(),
                    cause,
                }
            })
        })
        .collect::<Result<Vec<_>, _>>()?;
    let (mut combined, mut rates_differ) = (None, false);
    if let [first, _, ..] = logs {
        let rate = first.sample_rate_hz;
        if logs
            .iter()
            .all(|l| (l.sample_rate_hz / rate - 1.0).abs() < 1e-9)
        {
            let parts: Vec<&[f64]> = logs.iter().flat_map(NoiseLog::parts).collect();
            combined = Some(
                characterize(&parts, rate, options)
                    .map_err(|cause| NoiseLogsError::Pooled { cause })?,
            );
        } else {
            rates_differ = true;
        }
    }
    Ok(NoiseRun {
        results,
        combined,
        rates_differ,
    })
}
