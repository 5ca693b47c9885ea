//! Put a log's rows on the regular grid the pipeline expects, counting every irregularity.
//!
//! The pipeline (like the firmware) runs at a fixed sample rate. Rows are placed by their
//! time step from the previous row: a step of `dt` advances `max(1, round(dt / period))`
//! slots, so jitter (9 or 11 ms at a nominal 10 ms) keeps every sample, and a step of two
//! or more periods leaves empty slots (a gap). The rules:
//!
//! - an exact copy of the previous row (time and every value) is a *duplicate*: dropped
//!   (loggers repeat the last row when a sample is lost; the gap after it is filled);
//! - the same time stamp with different values, or a small step back in time, is kept
//!   as the next slot and counted; a step back of more than `max_gap_s` is an error;
//! - a missing or non-finite rate, and the slots of a gap, are filled by linear
//!   interpolation between their neighbours, counted; a run longer than `max_gap_s` is an
//!   error naming the line after it; missing slots at the very start or end are trimmed;
//! - a missing reference or temperature is interpolated the same way within `max_gap_s`,
//!   else left missing.
//!
//! Nothing is invented silently: [`Quality`] reports each count with example lines.

use super::{Log, LogError, Row};
use serde::Serialize;

/// How to build the grid (also the command-line options of every command reading logs).
#[derive(Clone, Copy, Debug, PartialEq, clap::Args)]
pub struct GridOptions {
    /// Sample rate of the log (Hz); default: its `sample_rate_hz` metadata, else the median
    /// time step.
    #[arg(long)]
    pub sample_rate_hz: Option<f64>,
    /// Longest stretch of missing data (s) bridged by interpolation; longer is an error.
    #[arg(long, default_value_t = 0.5)]
    pub max_gap_s: f64,
}

impl Default for GridOptions {
    fn default() -> Self {
        Self {
            sample_rate_hz: None,
            max_gap_s: 0.5,
        }
    }
}

/// One slot of the regular grid.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Slot {
    /// Time stamp (s): the row's, or interpolated for a filled slot.
    pub time_s: f64,
    /// Rate (deg/s).
    pub rate_dps: f64,
    /// Reference angle (deg).
    pub reference_deg: Option<f64>,
    /// Temperature (°C).
    pub temperature_c: Option<f64>,
    /// Line of the row (0 for a slot filled in a gap).
    pub line: u64,
    /// True if the rate was interpolated.
    pub filled: bool,
}

/// What was irregular in a log, and what was done about it.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct Quality {
    /// Data rows read.
    pub rows: u64,
    /// Slots of the regular grid.
    pub slots: u64,
    /// Sample rate of the grid (Hz).
    pub sample_rate_hz: f64,
    /// Where the rate came from: `option`, `metadata` or `median_step`.
    pub sample_rate_source: &'static str,
    /// Slots over the time the log spans (Hz): differs from the grid rate if the
    /// logger's clock or the nominal rate is off.
    pub effective_rate_hz: f64,
    /// Exact copies of the previous row, dropped.
    pub duplicate_rows: u64,
    /// Rows with the previous row's time stamp but other values, kept.
    pub same_time_rows: u64,
    /// Rows stamped earlier than the previous row (by less than `max_gap_s`), kept.
    pub backward_steps: u64,
    /// Steps differing from the period by more than 5% (but less than 1.5 periods).
    pub jittered_steps: u64,
    /// Gaps (steps of 1.5 periods or more).
    pub gaps: u64,
    /// Longest step between rows (s).
    pub longest_step_s: f64,
    /// Rows whose rate was empty, NaN or infinite.
    pub missing_rate_rows: u64,
    /// Slots whose rate was interpolated (gaps and missing rates).
    pub filled_slots: u64,
    /// Slots trimmed at the start or end for lack of a rate.
    pub trimmed_slots: u64,
    /// Slots without a reference after interpolation (only if the log has one).
    pub missing_reference_slots: u64,
    /// The first few irregular lines: (what, line).
    pub examples: Vec<(String, u64)>,
}

const MAX_EXAMPLES: usize = 12;

impl Quality {
    fn note(&mut self, what: &str, line: u64) {
        if self.examples.len() < MAX_EXAMPLES {
            self.examples.push((what.to_string(), line));
        }
    }
}

/// A log on a regular grid.
#[derive(Clone, Debug, PartialEq)]
pub struct RegularLog {
    /// The slots.
    pub slots: Vec<Slot>,
    /// Grid rate (Hz).
    pub sample_rate_hz: f64,
    /// True if the log has a reference column.
    pub has_reference: bool,
    /// True if the log has a temperature column.
    pub has_temperature: bool,
    /// What was irregular.
    pub quality: Quality,
}

fn same_row(a: &Row, b: &Row) -> bool {
    a.time_s == b.time_s
        && a.rate_dps == b.rate_dps
        && a.reference_deg == b.reference_deg
        && a.temperature_c == b.temperature_c
}

/// The grid rate and where it came from.
fn sample_rate(log: &Log, options: &GridOptions) -> Result<(f64, &'static str), LogError> {
    let bad = |message: String| LogError::SampleRate {
        path: log.path.clone(),
        message,
    };
    if let Some(rate) = options.sample_rate_hz {
        if !(rate.is_finite() && rate > 0.0) {
            return Err(bad(format!(
                "--sample-rate-hz {rate} is not a positive number"
            )));
        }
        return Ok((rate, "option"));
    }
    if let Some(rate) = log.metadata_rate_hz() {
        return Ok((rate, "metadata"));
    }
    let mut steps: Vec<f64> = log
        .rows
        .windows(2)
        .take(100_000)
        .map(|w| w[1].time_s - w[0].time_s)
        .filter(|dt| *dt > 0.0)
        .collect();
    if steps.is_empty() {
        return Err(bad(
            "cannot estimate the sample rate (fewer than two distinct time stamps); pass --sample-rate-hz".into(),
        ));
    }
    steps.sort_by(f64::total_cmp);
    Ok((1.0 / steps[steps.len() / 2], "median_step"))
}

/// Place the rows of `log` on a regular grid.
pub fn regularize(log: &Log, options: &GridOptions) -> Result<RegularLog, LogError> {
    if log.rows.is_empty() {
        return Err(LogError::NoData {
            path: log.path.clone(),
            what: "no data rows after the header".into(),
        });
    }
    let (rate_hz, source) = sample_rate(log, options)?;
    let period_s = 1.0 / rate_hz;
    let mut quality = Quality {
        rows: log.rows.len() as u64,
        sample_rate_hz: rate_hz,
        sample_rate_source: source,
        ..Quality::default()
    };

    // Pass 1: assign slots; a missing rate is NaN (and `filled`) for now.
    let mut slots: Vec<Slot> = Vec::with_capacity(log.rows.len() + 16);
    let mut previous: Option<&Row> = None;
    for row in &log.rows {
        if let Some(prev) = previous {
            if same_row(prev, row) {
                quality.duplicate_rows += 1;
                quality.note("duplicate row dropped", row.line);
                continue;
            }
            let dt = row.time_s - prev.time_s;
            quality.longest_step_s = quality.longest_step_s.max(dt);
            if dt < 0.0 {
                if -dt > options.max_gap_s {
                    return Err(LogError::TimeBackwards {
                        path: log.path.clone(),
                        line: row.line,
                        previous_line: prev.line,
                        previous_s: prev.time_s,
                        time_s: row.time_s,
                        back_s: -dt,
                    });
                }
                quality.backward_steps += 1;
                quality.note("time stamp before the previous row", row.line);
            } else if dt == 0.0 {
                quality.same_time_rows += 1;
                quality.note("same time stamp as the previous row", row.line);
            }
            let steps = if dt <= 0.0 {
                1
            } else {
                ((dt / period_s).round() as u64).max(1)
            };
            if steps > 1 {
                if dt > options.max_gap_s {
                    return Err(LogError::Gap {
                        path: log.path.clone(),
                        line: row.line,
                        previous_line: prev.line,
                        gap_s: dt,
                        max_gap_s: options.max_gap_s,
                    });
                }
                quality.gaps += 1;
                quality.note("gap filled by interpolation", row.line);
                for j in 1..steps {
                    let time_s = prev.time_s + dt * j as f64 / steps as f64;
                    slots.push(Slot {
                        time_s,
                        rate_dps: f64::NAN,
                        reference_deg: None,
                        temperature_c: None,
                        line: 0,
                        filled: true,
                    });
                }
            } else if dt > 0.0 && (dt - period_s).abs() > 0.05 * period_s {
                quality.jittered_steps += 1;
            }
        }
        if row.rate_dps.is_none() {
            quality.missing_rate_rows += 1;
            quality.note("missing rate interpolated", row.line);
        }
        slots.push(Slot {
            time_s: row.time_s,
            rate_dps: row.rate_dps.unwrap_or(f64::NAN),
            reference_deg: row.reference_deg,
            temperature_c: row.temperature_c,
            line: row.line,
            filled: row.rate_dps.is_none(),
        });
        previous = Some(row);
    }

    // Trim slots without a rate at both ends.
    let first = slots.iter().position(|s| !s.rate_dps.is_nan());
    let last = slots.iter().rposition(|s| !s.rate_dps.is_nan());
    let (Some(first), Some(last)) = (first, last) else {
        return Err(LogError::NoData {
            path: log.path.clone(),
            what: "no row has a rate value".into(),
        });
    };
    quality.trimmed_slots = (slots.len() - 1 - last + first) as u64;
    slots.truncate(last + 1);
    slots.drain(..first);

    // Pass 2: interpolate the rate across missing slots (runs bounded by max_gap_s).
    let max_run = ((options.max_gap_s / period_s).floor() as usize).max(1);
    fill_runs(
        &mut slots,
        |s| (!s.rate_dps.is_nan()).then_some(s.rate_dps),
        |s, v| s.rate_dps = v,
        |before, after| {
            if after - before - 1 > max_run {
                Err((before, after))
            } else {
                Ok(true)
            }
        },
    )
    .map_err(|(before, after)| LogError::Gap {
        path: log.path.clone(),
        line: slots[after].line,
        previous_line: slots[before].line,
        gap_s: slots[after].time_s - slots[before].time_s,
        max_gap_s: options.max_gap_s,
    })?;
    quality.filled_slots = slots.iter().filter(|s| s.filled).count() as u64;

    // Pass 3: reference and temperature, interpolated within max_gap_s, else missing.
    let within = |before: usize, after: usize| -> Result<bool, LogError> {
        Ok(after - before - 1 <= max_run)
    };
    if log.has_reference {
        fill_runs(
            &mut slots,
            |s| s.reference_deg,
            |s, v| s.reference_deg = Some(v),
            within,
        )?;
        quality.missing_reference_slots =
            slots.iter().filter(|s| s.reference_deg.is_none()).count() as u64;
    }
    if log.has_temperature {
        fill_runs(
            &mut slots,
            |s| s.temperature_c,
            |s, v| s.temperature_c = Some(v),
            within,
        )?;
    }

    quality.slots = slots.len() as u64;
    let span_s = slots.last().map_or(0.0, |s| s.time_s) - slots[0].time_s;
    quality.effective_rate_hz = if span_s > 0.0 {
        (slots.len() - 1) as f64 / span_s
    } else {
        rate_hz
    };
    Ok(RegularLog {
        slots,
        sample_rate_hz: rate_hz,
        has_reference: log.has_reference,
        has_temperature: log.has_temperature,
        quality,
    })
}

/// Fill interior runs of missing values by linear interpolation over the slot index.
/// `decide(before, after)`, the indices of the known values around a run, says whether to
/// fill it (`Ok(true)`), leave it (`Ok(false)`) or fail.
fn fill_runs<E>(
    slots: &mut [Slot],
    get: impl Fn(&Slot) -> Option<f64>,
    set: impl Fn(&mut Slot, f64),
    decide: impl Fn(usize, usize) -> Result<bool, E>,
) -> Result<(), E> {
    let mut last_known: Option<(usize, f64)> = None;
    for i in 0..slots.len() {
        let Some(value) = get(&slots[i]) else {
            continue;
        };
        if let Some((j, previous)) = last_known {
            if i - j > 1 && decide(j, i)? {
                for (k, slot) in slots.iter_mut().enumerate().take(i).skip(j + 1) {
                    let w = (k - j) as f64 / (i - j) as f64;
                    set(slot, previous + w * (value - previous));
                }
            }
        }
        last_known = Some((i, value));
    }
    Ok(())
}
