//! Rest stretches of a log, found by the gyro-core motion detector.
//!
//! The log is replayed through [`gyro_core::Pipeline`] (the firmware's pipeline, its rate
//! set to the log's). Every movement it reports — from `MovementStarted` (its start time)
//! to `MovementEnded` (its end time), or to the end of the log if it is still moving — is
//! widened by `margin_s` on both sides (the low-pass filter's delay and ringing), and the
//! input samples outside all widened movements form the rest stretches; stretches shorter
//! than `min_len_s` are dropped. Kept simple on purpose: the detector's thresholds are
//! those of `config.motion`.

use gyro_core::{Config, Event, Pipeline};
use gyro_log::RegularLog;
use std::ops::Range;

/// Ranges of `log.slots` at rest (see the module docs).
pub fn rest_segments(
    log: &RegularLog,
    config: &Config,
    margin_s: f64,
    min_len_s: f64,
) -> Result<Vec<Range<usize>>, gyro_core::Error> {
    let config = Config {
        sample_rate_hz: log.sample_rate_hz as f32,
        ..*config
    };
    let mut pipeline = Pipeline::try_new(&config)?;
    let mut moves: Vec<(f64, f64)> = Vec::new();
    let mut open: Option<f64> = None;
    let end_s = log.slots.last().map_or(0.0, |s| s.time_s);
    for slot in &log.slots {
        let Some(out) = pipeline.push(slot.time_s, slot.rate_dps as f32) else {
            continue;
        };
        match out.event {
            Some(Event::MovementStarted { start_time_s, .. }) => open = Some(start_time_s),
            Some(Event::MovementEnded(m)) => {
                open = None;
                moves.push((m.start_time_s, m.end_time_s));
            }
            None => {}
        }
    }
    if let Some(start) = open {
        moves.push((start, end_s));
    }
    let moving = |t: f64| {
        moves
            .iter()
            .any(|(a, b)| t >= a - margin_s && t <= b + margin_s)
    };
    let min_len = (min_len_s * log.sample_rate_hz).ceil().max(1.0) as usize;
    let mut segments = Vec::new();
    let mut start: Option<usize> = None;
    for (i, slot) in log.slots.iter().enumerate() {
        match (moving(slot.time_s), start) {
            (false, None) => start = Some(i),
            (true, Some(s)) => {
                if i - s >= min_len {
                    segments.push(s..i);
                }
                start = None;
            }
            _ => {}
        }
    }
    if let Some(s) = start {
        if log.slots.len() - s >= min_len {
            segments.push(s..log.slots.len());
        }
    }
    Ok(segments)
}
