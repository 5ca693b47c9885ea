//! Logs whose rows arrive in bursts, and how their rate is put on the grid.
//!
//! Loggers that stamp rows on arrival at a PC (USB, Bluetooth, a wireless link) deliver a
//! sensor's samples in bursts: steps of a quarter of the sample period follow steps of two
//! periods, and the median step is not the sample period. Placing such rows one slot each
//! (the rule for regular and jittered logs) stretches or squeezes time and invents
//! rotation. For these logs the *cumulative angle* is resampled instead: the rate is
//! integrated on the stamps (trapezoid), that angle is interpolated at the grid times, and
//! each slot's rate is the angle gained since the previous slot divided by the period. The
//! integral of the rate over the log is then the one the stamps say, whatever the bursts.
//!
//! A stall of the link (a gap, then the buffered rows a few milliseconds apart) is re-timed
//! before the rows get here ([`crate::backlog`]).
//!
//! A log is *bursty* when, among its first [`crate::RATE_WINDOW_STEPS`] steps, either
//! - more than a third are *off the grid*: further than a quarter of the median step from a
//!   whole number (one or more) of median steps. Those are the steps a row-per-slot
//!   placement gets wrong; jitter and lost samples (steps of two or three periods) are not
//!   off the grid. Regular loggers: well under 1%; the rasteiro recordings: 63–70%; or
//! - more than [`REPEATED_LIMIT`] of the steps do not advance the stamp (a repeated stamp
//!   with other values, or a step back). A row per slot gives each such row a period its
//!   stamp does not: samples delivered in packets stamped on arrival (four rows, one
//!   stamp, then a step of four periods: time stretched fourfold), a sensor faster than
//!   the stamps' resolution (2 kHz stamped to the millisecond: twofold), or stamps coarser
//!   than the rows (110 rows/s stamped to 10 ms: steps of 0, 10 and 20 ms, every positive
//!   one on the grid, and 18% more slots than time).

use crate::{LogError, Row, Slot};
use serde::Serialize;
use std::path::Path;

/// A step further than this share of the median step from a whole number of median steps
/// is *off the grid*.
const OFF_GRID: f64 = 0.25;
/// A log is bursty when more than this share of its steps are off the grid.
const BURSTY_SHARE: f64 = 1.0 / 3.0;
/// Fewer positive steps than this say nothing about arrival: treated as regular.
const MIN_STEPS: usize = 20;
/// A log in which more than this share of the steps do not advance the stamp is bursty
/// (each such row placed one per slot adds a period of time: 1% of them, a 90° turn 0.9°
/// off).
pub const REPEATED_LIMIT: f64 = 0.01;

/// The arrival statistics of a bursty log (from its first steps).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Bursts {
    /// Median positive step (s): not the sample period in such a log.
    pub median_step_s: f64,
    /// Mean step (s): the span over the rows kept; the grid period unless a rate is given.
    pub mean_step_s: f64,
    /// Share of the positive steps off the grid: further than a quarter of the median step
    /// from a whole number (one or more) of median steps.
    pub off_grid_share: f64,
    /// Steps longer than this (s) are counted as gaps: twice the 99th percentile step, at
    /// least 1.5 mean steps (the bursts themselves are not gaps).
    pub gap_step_s: f64,
    /// Share of the steps that do not advance the stamp (a repeated stamp with other
    /// values, or a step back; exact duplicates are dropped, not counted).
    pub repeated_stamp_share: f64,
}

/// The arrival statistics of `rows` if they arrive in bursts (see the module docs); `None`
/// for regular or jittered rows, or too few steps to tell.
pub fn classify(rows: &[Row], window_steps: usize) -> Option<Bursts> {
    let window = &rows[..rows.len().min(window_steps + 1)];
    let mut steps: Vec<f64> = Vec::with_capacity(window.len());
    let mut kept = 1_usize;
    for pair in window.windows(2) {
        if crate::regular::same_row(&pair[0], &pair[1]) {
            continue;
        }
        kept += 1;
        let dt = pair[1].time_s - pair[0].time_s;
        if dt > 0.0 {
            steps.push(dt);
        }
    }
    if steps.len() < MIN_STEPS {
        return None;
    }
    // Kept steps that do not advance the stamp.
    let repeated_stamp_share = (kept - 1 - steps.len()) as f64 / (kept - 1) as f64;
    steps.sort_by(f64::total_cmp);
    let median_step_s = steps[steps.len() / 2];
    let off = steps
        .iter()
        .filter(|dt| {
            let periods = **dt / median_step_s;
            (periods - periods.round().max(1.0)).abs() > OFF_GRID
        })
        .count();
    let off_grid_share = off as f64 / steps.len() as f64;
    let span_s = window.last()?.time_s - window.first()?.time_s;
    let mean_step_s = span_s / (kept - 1) as f64;
    let bursty = off_grid_share > BURSTY_SHARE || repeated_stamp_share > REPEATED_LIMIT;
    if !(bursty && mean_step_s.is_finite() && mean_step_s > 0.0) {
        return None;
    }
    let p99 = steps[(steps.len() * 99 / 100).min(steps.len() - 1)];
    Some(Bursts {
        median_step_s,
        mean_step_s,
        off_grid_share,
        gap_step_s: (2.0 * p99).max(1.5 * mean_step_s),
        repeated_stamp_share,
    })
}

/// The value of an optional channel at `time_s` within `segment` (rows in time order, the
/// first before `time_s`, the last at or after it): linear between the rows around it, or
/// the last row's at its own time; `None` if either row lacks the value.
pub(crate) fn value_at(
    segment: &[Row],
    time_s: f64,
    get: impl Fn(&Row) -> Option<f64>,
) -> Option<f64> {
    let i = segment
        .iter()
        .rposition(|r| r.time_s <= time_s)
        .unwrap_or(0);
    let a = segment.get(i)?;
    let Some(b) = segment.get(i + 1) else {
        return get(a);
    };
    let (va, vb) = (get(a)?, get(b)?);
    let w = (time_s - a.time_s) / (b.time_s - a.time_s);
    Some(va + w * (vb - va))
}

/// Rows in, grid slots out, preserving the integral of the rate (streaming).
///
/// Grid point 0 is the first row with a rate (its values as they are); grid point `j` is at
/// `start + j·period` and carries the mean rate over the period before it. Rows are taken
/// in order with their stamps made non-decreasing (a step back counts as no time). A row
/// without a rate adds no angle of its own: the trapezoid spans from the row with a rate
/// before it to the one after (the rate's linear interpolation). Reference and temperature
/// are interpolated at the grid times between the rows around them.
pub(crate) struct Resampler {
    period_s: f64,
    gap_step_s: f64,
    max_gap_s: f64,
    max_run: usize,
    /// Time of grid point 0 (the first row with a rate).
    start_s: f64,
    /// Index of the next grid point.
    next_index: u64,
    /// The last row with a rate (stamp made non-decreasing).
    valid: Option<Row>,
    /// Angle gained from the last grid point up to `valid` (deg).
    since_grid_deg: f64,
    /// Rows without a rate since `valid` (at most `max_run` + 1 kept).
    between: Vec<Row>,
    /// How many rows without a rate since `valid`.
    between_count: u64,
    /// Rows without a rate before the first with one.
    leading: u64,
    /// The latest stamp (non-decreasing).
    clock_s: f64,
}

impl Resampler {
    /// A resampler onto a grid of `period_s`; `gap_step_s` marks the steps that are gaps;
    /// a run of rows without a rate longer than `max_run` rows or `max_gap_s` is an error.
    pub(crate) fn new(period_s: f64, gap_step_s: f64, max_gap_s: f64, max_run: usize) -> Self {
        Self {
            period_s,
            gap_step_s,
            max_gap_s,
            max_run,
            start_s: 0.0,
            next_index: 0,
            valid: None,
            since_grid_deg: 0.0,
            between: Vec::new(),
            between_count: 0,
            leading: 0,
            clock_s: f64::NEG_INFINITY,
        }
    }

    /// Rows without a rate at the start and the end of the rows so far (trimmed).
    pub(crate) fn trimmed_rows(&self) -> u64 {
        self.leading + self.between_count
    }

    /// Take one row (in file order, duplicates already dropped); push the grid slots it
    /// completes onto `out`. An error is a run without a rate too long to bridge.
    pub(crate) fn row(
        &mut self,
        path: &Path,
        row: &Row,
        out: &mut Vec<Slot>,
    ) -> Result<(), LogError> {
        let mut row = *row;
        row.time_s = row.time_s.max(self.clock_s);
        self.clock_s = row.time_s;
        let Some(rate_dps) = row.rate_dps else {
            if self.valid.is_none() {
                self.leading += 1;
            } else {
                self.between_count += 1;
                if self.between.len() <= self.max_run {
                    self.between.push(row);
                }
            }
            return Ok(());
        };
        let Some(before) = self.valid else {
            self.start_s = row.time_s;
            self.next_index = 1;
            self.valid = Some(row);
            out.push(Slot {
                time_s: row.time_s,
                rate_dps,
                reference_deg: row.reference_deg,
                temperature_c: row.temperature_c,
                line: row.line,
                filled: false,
            });
            return Ok(());
        };
        let span_s = row.time_s - before.time_s;
        if self.between_count > 0
            && (self.between_count > self.max_run as u64 || span_s > self.max_gap_s)
        {
            return Err(LogError::Gap {
                path: path.to_path_buf(),
                line: row.line,
                previous_line: before.line,
                gap_s: span_s,
                max_gap_s: self.max_gap_s,
            });
        }
        let increment_deg = 0.5 * (before.rate_dps.unwrap_or(rate_dps) + rate_dps) * span_s;
        let filled = self.between_count > 0 || span_s > self.gap_step_s;
        let mut segment = Vec::with_capacity(self.between.len() + 2);
        segment.push(before);
        segment.extend_from_slice(&self.between);
        segment.push(row);
        let mut assigned_deg = 0.0;
        loop {
            let time_s = self.start_s + self.next_index as f64 * self.period_s;
            if time_s > row.time_s {
                break;
            }
            // Grid points up to `before` were emitted with it, so here span_s > 0.
            let share_deg = increment_deg * (time_s - before.time_s) / span_s;
            let rate_dps = (self.since_grid_deg + share_deg - assigned_deg) / self.period_s;
            self.since_grid_deg = 0.0;
            assigned_deg = share_deg;
            out.push(Slot {
                time_s,
                rate_dps,
                reference_deg: value_at(&segment, time_s, |r| r.reference_deg),
                temperature_c: value_at(&segment, time_s, |r| r.temperature_c),
                line: row.line,
                filled,
            });
            self.next_index += 1;
        }
        self.since_grid_deg += increment_deg - assigned_deg;
        self.valid = Some(row);
        self.between.clear();
        self.between_count = 0;
        Ok(())
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)] // test code: a failed unwrap is a failed test
mod tests {
    use super::*;
    use crate::{regularize, GridOptions, Log, RATE_WINDOW_STEPS};

    fn row(line: u64, time_s: f64, rate_dps: f64) -> Row {
        Row {
            line,
            time_s,
            rate_dps: Some(rate_dps),
            reference_deg: None,
            temperature_c: None,
        }
    }

    /// A 100 Hz sensor turning 90° in one second (a raised-cosine rate) between rests,
    /// with a bias of 0.5 °/s; `stamp(k, sample_time_s)` gives the logged time of sample k.
    fn turn_log(stamp: impl Fn(usize, f64) -> f64) -> Log {
        let rows = (0..400)
            .map(|k| {
                let t = k as f64 * 0.01;
                let rate = if (1.5..2.5).contains(&t) {
                    90.0 * (1.0 - (2.0 * std::f64::consts::PI * (t - 1.5)).cos())
                } else {
                    0.0
                };
                row(k as u64 + 2, stamp(k, t), rate + 0.5)
            })
            .collect();
        Log {
            path: "turn.csv".into(),
            rows,
            ..Log::default()
        }
    }

    /// Arrival in groups: samples wait and come four at a time, 2.5 ms apart, once every
    /// 40 ms (steps of 2.5 and 32.5 ms, all whole numbers of the 2.5 ms median).
    fn in_groups(k: usize, _t: f64) -> f64 {
        0.04 * (k / 4) as f64 + 0.0025 * (k % 4) as f64 + 0.03
    }

    /// Arrival over a link: each sample waits 0–15 ms (pseudo-random), and rows cannot
    /// arrive closer than 2.5 ms (steps from 2.5 to about 23 ms; about 60% off the grid, as
    /// on the rasteiro recordings).
    fn in_bursts(log: Log) -> Log {
        let mut state: u64 = 1;
        let mut previous = f64::NEG_INFINITY;
        let rows = log
            .rows
            .into_iter()
            .map(|mut row| {
                state = state
                    .wrapping_mul(6_364_136_223_846_793_005)
                    .wrapping_add(1_442_695_040_888_963_407);
                let wait_s = (state >> 40) as f64 / f64::from(1_u32 << 24) * 0.015;
                row.time_s = (row.time_s + wait_s).max(previous + 0.0025);
                previous = row.time_s;
                row
            })
            .collect();
        Log { rows, ..log }
    }

    fn integral_deg(log: &crate::RegularLog) -> f64 {
        let period_s = 1.0 / log.sample_rate_hz;
        log.slots[1..].iter().map(|s| s.rate_dps * period_s).sum()
    }

    /// Trapezoid on the stamps, from the first row to `end_s`.
    fn on_stamps_deg(log: &Log, end_s: f64) -> f64 {
        let mut sum = 0.0;
        for w in log.rows.windows(2) {
            let (a, b) = (&w[0], &w[1]);
            let (ra, rb) = (a.rate_dps.unwrap(), b.rate_dps.unwrap());
            if b.time_s <= end_s {
                sum += 0.5 * (ra + rb) * (b.time_s - a.time_s);
            } else if a.time_s < end_s {
                let rb_end = ra + (rb - ra) * (end_s - a.time_s) / (b.time_s - a.time_s);
                sum += 0.5 * (ra + rb_end) * (end_s - a.time_s);
            }
        }
        sum
    }

    #[test]
    fn regular_and_jittered_stamps_are_not_bursts() {
        let regular = turn_log(|_, t| t);
        assert_eq!(classify(&regular.rows, RATE_WINDOW_STEPS), None);
        // ±4% jitter (a deterministic pattern).
        let jittered = turn_log(|k, t| t + 0.0004 * ((k * 7 % 5) as f64 - 2.0) / 2.0);
        assert_eq!(classify(&jittered.rows, RATE_WINDOW_STEPS), None);
        // Too few steps to tell.
        let short = Log {
            rows: in_bursts(turn_log(|_, t| t)).rows[..15].to_vec(),
            ..Log::default()
        };
        assert_eq!(classify(&short.rows, RATE_WINDOW_STEPS), None);
    }

    #[test]
    fn bursts_are_recognised_with_the_mean_step_as_period() {
        let log = turn_log(in_groups);
        // Groups on a 2.5 ms grid: every step is a whole number of median steps, so a
        // row per slot keeps every stamp (the long steps are gaps, interpolated).
        assert_eq!(classify(&log.rows, RATE_WINDOW_STEPS), None);
        // Rows that wait for a varying time: off the grid.
        let irregular = in_bursts(turn_log(|_, t| t));
        let b = classify(&irregular.rows, RATE_WINDOW_STEPS).unwrap();
        assert!(b.off_grid_share > BURSTY_SHARE, "{b:?}");
        assert!((b.mean_step_s - 0.01).abs() < 1e-4, "{b:?}");
        // The median step is not the period (9.1 ms here).
        assert!(b.median_step_s < 0.0095, "{b:?}");
    }

    /// The integral of the rate over the grid is the integral on the stamps, and the turn
    /// comes out at its true angle; one slot per row would not preserve it.
    #[test]
    fn resampling_preserves_the_integral_of_the_rate() {
        let log = in_bursts(turn_log(|_, t| t));
        let placed = regularize(&log, &GridOptions::default()).unwrap();
        assert!(placed.quality.bursts.is_some());
        assert_eq!(placed.quality.sample_rate_source, "mean_step");
        let end_s = placed.slots.last().unwrap().time_s;
        let on_grid = integral_deg(&placed);
        let on_stamps = on_stamps_deg(&log, end_s);
        assert!(
            (on_grid - on_stamps).abs() < 1e-9,
            "{on_grid} vs {on_stamps}"
        );
        // The turn, bias removed: 90° (within what the bursts' timing errors make).
        let bias_deg = 0.5 * (end_s - placed.slots[0].time_s);
        assert!(
            (on_grid - bias_deg - 90.0).abs() < 1.5,
            "{}",
            on_grid - bias_deg
        );
        // A given rate (within what the stamps allow) keeps the resampling.
        let per_row = regularize(
            &log,
            &GridOptions {
                sample_rate_hz: Some(110.0),
                ..GridOptions::default()
            },
        )
        .unwrap();
        assert!(
            per_row.quality.bursts.is_some(),
            "a given rate keeps the resampling"
        );
        let end_s = per_row.slots.last().unwrap().time_s;
        assert!((integral_deg(&per_row) - on_stamps_deg(&log, end_s)).abs() < 1e-9);
    }

    /// Rows sharing a stamp: a row per slot would give each a period its stamp does not
    /// (packets of four stamped on arrival: time four times too long; a 100 Hz stream
    /// stamped to 20 ms: twice). Every positive step is on the grid, so only the repeated
    /// stamps tell; the rate is the mean row rate and the turn keeps its angle.
    #[test]
    fn rows_sharing_a_stamp_are_bursts_and_keep_their_angle() {
        // Sensor noise (a deterministic ±0.01 °/s pattern): rows of the same stamp differ,
        // as real samples do (exact copies are duplicates, dropped).
        let noisy = |mut log: Log| {
            for (k, row) in log.rows.iter_mut().enumerate() {
                row.rate_dps = row.rate_dps.map(|r| r + 0.005 * ((k * 7 % 5) as f64 - 2.0));
            }
            log
        };
        let packets = noisy(turn_log(|k, _| 0.04 * (k / 4) as f64 + 0.035));
        let coarse = noisy(turn_log(|_, t| (t / 0.02 + 1e-9).floor() * 0.02));
        for (log, share) in [(packets, 0.75), (coarse, 0.5)] {
            let b = classify(&log.rows, RATE_WINDOW_STEPS).unwrap();
            assert!(b.off_grid_share < BURSTY_SHARE, "{b:?}");
            assert!((b.repeated_stamp_share - share).abs() < 0.01, "{b:?}");
            let placed = regularize(&log, &GridOptions::default()).unwrap();
            assert_eq!(placed.quality.sample_rate_source, "mean_step");
            assert!(
                (placed.sample_rate_hz - 100.0).abs() < 1.5,
                "{}",
                placed.sample_rate_hz
            );
            let span_s = placed.slots.last().unwrap().time_s - placed.slots[0].time_s;
            let turn_deg = integral_deg(&placed) - 0.5 * span_s;
            assert!((turn_deg - 90.0).abs() < 1.5, "{turn_deg}");
        }
        // A repeated stamp now and then (under 1% of the steps) is not a burst.
        let rare = turn_log(|k, t| if k == 200 { t - 0.01 } else { t });
        assert_eq!(classify(&rare.rows, RATE_WINDOW_STEPS), None);
    }

    /// A rate the stamps contradict (here 4x) is refused, naming both.
    #[test]
    fn a_given_rate_the_stamps_contradict_is_refused() {
        let log = turn_log(|_, t| t);
        let err = regularize(
            &log,
            &GridOptions {
                sample_rate_hz: Some(400.0),
                ..GridOptions::default()
            },
        )
        .unwrap_err();
        let text = err.to_string();
        assert!(
            text.contains("400 Hz") && text.contains("say 100.0"),
            "{text}"
        );
        let mut with_metadata = log.clone();
        with_metadata
            .metadata
            .insert("sample_rate_hz".into(), "1000".into());
        let err = regularize(&with_metadata, &GridOptions::default()).unwrap_err();
        assert!(err.to_string().contains("sample_rate_hz metadata"), "{err}");
        // Within 20%: accepted (a logger clock a few percent off is not a wrong rate).
        assert!(regularize(
            &log,
            &GridOptions {
                sample_rate_hz: Some(95.0),
                ..GridOptions::default()
            }
        )
        .is_ok());
    }

    #[test]
    fn values_between_rows_are_interpolated_or_missing() {
        let mut a = row(2, 0.0, 1.0);
        let mut b = row(3, 0.01, 1.0);
        a.reference_deg = Some(10.0);
        b.reference_deg = Some(20.0);
        let segment = [a, b];
        assert_eq!(value_at(&segment, 0.0025, |r| r.reference_deg), Some(12.5));
        assert_eq!(value_at(&segment, 0.01, |r| r.reference_deg), Some(20.0));
        b.reference_deg = None;
        assert_eq!(value_at(&[a, b], 0.005, |r| r.reference_deg), None);
    }
}
