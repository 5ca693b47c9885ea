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
//!   as the next slot and counted (when more than 1% of the steps are such, the rows are
//!   resampled as rows in bursts instead: [`crate::bursts`]); a step back of more than `max_gap_s` is an error;
//! - a missing or non-finite rate, and the slots of a gap, are filled by linear
//!   interpolation between their neighbours, counted; a run longer than `max_gap_s` is an
//!   error naming the line after it; missing slots at the very start or end are trimmed;
//! - a missing reference or temperature is interpolated the same way within `max_gap_s`,
//!   else left missing.
//!
//! Nothing is invented silently: [`Quality`] reports each count with example lines.

use super::{Log, LogError, Row};
use crate::backlog::Retimer;
use crate::bursts::{self, Bursts, Resampler};
use crate::jumps::ReferenceJumps;
use crate::wraps::{describe_span, Unwrapper};
use serde::Serialize;
use std::path::Path;

/// How to build the grid (also the command-line options of every command reading logs).
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "clap", derive(clap::Args))]
pub struct GridOptions {
    /// Sample rate of the log (Hz); default: its `sample_rate_hz` metadata, else the median
    /// time step.
    #[cfg_attr(feature = "clap", arg(long, value_parser = crate::value::positive::<f64>))]
    pub sample_rate_hz: Option<f64>,
    /// Longest stretch of missing data (s) bridged by interpolation; longer is an error.
    #[cfg_attr(
        feature = "clap",
        arg(long, default_value_t = 0.5, value_parser = crate::value::non_negative::<f64>)
    )]
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
    /// Where the rate came from: `option`, `metadata`, `mean_step` (rows in bursts) or
    /// `single_steps` (the mean of the steps that are one period).
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
    /// Gaps (steps of 1.5 periods or more; for rows in bursts, steps over
    /// [`Bursts::gap_step_s`]), backlogs not included.
    pub gaps: u64,
    /// Gaps after which the rows arrived faster than the sensor samples until the count
    /// caught up: a stalled link's backlog, its rows spread evenly over the gap instead of
    /// bridging the gap ([`crate::backlog`]).
    pub backlogs: u64,
    /// Rows whose stamps were spread over a backlog's gap.
    pub retimed_rows: u64,
    /// Wraps of a tick counter in the time stamps, unwrapped ([`crate::wraps`]).
    pub counter_wraps: u64,
    /// The span of that counter (s), when it wrapped.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub counter_span_s: Option<f64>,
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
    /// Jumps of the reference while the gyro barely turns (a pose that wraps or flips):
    /// the reference after each is re-based ([`crate::jumps`]).
    pub reference_jumps: u64,
    /// Correlation of the gyro's and the reference's turns over blocks of
    /// [`crate::sense::BLOCK_S`] (−1 to 1), when the log has a reference and the gyro
    /// turns: near 1 when the reference follows the gyro; at or below
    /// [`crate::sense::OPPOSED_CORRELATION`] a reference of the opposite sense, warned of
    /// ([`crate::sense`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub reference_correlation: Option<f64>,
    /// The reference's turn per degree of the gyro's over the same blocks (least squares):
    /// about 1; beyond a factor of [`crate::sense::GAIN_LIMIT`] either way, units or
    /// scales that differ, warned of.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub reference_gain: Option<f64>,
    /// The first few irregular lines: (what, line).
    pub examples: Vec<(String, u64)>,
    /// Set if the rows arrive in bursts: their arrival statistics. The rate's integral was
    /// then resampled onto the grid ([`crate::bursts`]) instead of placing a row per slot;
    /// gaps are steps over `gap_step_s`, and slot times are grid times, not stamps.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub bursts: Option<Bursts>,
    /// What did not stop the log but may make its results wrong (a given rate more than
    /// [`RATE_WARNING_SHARE`] off the stamps'), one line each; left out when empty.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub warnings: Vec<String>,
}

pub(crate) const MAX_EXAMPLES: usize = 12;

impl Quality {
    pub(crate) fn note(&mut self, what: &str, line: u64) {
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

impl RegularLog {
    /// A log at `sample_rate_hz` of `(time_s, rate_dps, reference_deg)` samples as a reader
    /// makes of a clean log: every slot read (none filled), no temperature, a clean input
    /// report. For tests and for callers that hold samples already on a grid.
    pub fn with_reference(
        sample_rate_hz: f64,
        samples: impl IntoIterator<Item = (f64, f64, f64)>,
    ) -> Self {
        let slots = samples
            .into_iter()
            .enumerate()
            .map(|(i, (time_s, rate_dps, reference_deg))| Slot {
                time_s,
                rate_dps,
                reference_deg: Some(reference_deg),
                temperature_c: None,
                line: i as u64 + 2,
                filled: false,
            })
            .collect();
        Self {
            slots,
            sample_rate_hz,
            has_reference: true,
            has_temperature: false,
            quality: Quality::default(),
        }
    }
}

/// The grid rate is estimated from the median positive step among the first this many
/// steps, so a log without a rate holds this many rows back before placing any.
pub const RATE_WINDOW_STEPS: usize = 100_000;

/// What placing rows on the grid needs to know about a log besides its rows.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LogInfo<'a> {
    /// The file (for errors).
    pub path: &'a Path,
    /// The `sample_rate_hz` metadata value, if valid ([`super::metadata_rate_hz`]).
    pub metadata_rate_hz: Option<f64>,
    /// True if the log has a reference column.
    pub has_reference: bool,
    /// True if the log has a temperature column.
    pub has_temperature: bool,
}

impl<'a> LogInfo<'a> {
    /// The description of a log read into memory.
    pub fn of(log: &'a Log) -> Self {
        Self {
            path: &log.path,
            metadata_rate_hz: log.metadata_rate_hz(),
            has_reference: log.has_reference,
            has_temperature: log.has_temperature,
        }
    }
}

/// Where [`place`] delivers the slots, in order, as soon as each is final.
pub trait SlotSink {
    /// Called first, with the columns the log has.
    fn columns(&mut self, _has_reference: bool, _has_temperature: bool) {}
    /// Called once with the grid rate (Hz), before the first slot.
    fn start(&mut self, sample_rate_hz: f64);
    /// One slot of the grid.
    fn slot(&mut self, slot: &Slot);
}

pub(crate) fn same_row(a: &Row, b: &Row) -> bool {
    a.time_s == b.time_s
        && a.rate_dps == b.rate_dps
        && a.reference_deg == b.reference_deg
        && a.temperature_c == b.temperature_c
}

/// The rate given by the option, or the metadata; `None` if it must be estimated.
fn given_rate(
    info: &LogInfo<'_>,
    options: &GridOptions,
) -> Option<Result<(f64, &'static str), LogError>> {
    if let Some(rate) = options.sample_rate_hz {
        if !(rate.is_finite() && rate > 0.0) {
            return Some(Err(LogError::SampleRateInvalid {
                path: info.path.to_path_buf(),
                rate_hz: rate,
            }));
        }
        return Some(Ok((rate, "option")));
    }
    info.metadata_rate_hz.map(|rate| Ok((rate, "metadata")))
}

/// `max_gap_s` must be a finite number of seconds ≥ 0 (NaN would disable the gap check,
/// infinity would let a gap fill memory).
pub(crate) fn check_max_gap(path: &Path, options: &GridOptions) -> Result<(), LogError> {
    if options.max_gap_s.is_finite() && options.max_gap_s >= 0.0 {
        Ok(())
    } else {
        Err(LogError::MaxGapInvalid {
            path: path.to_path_buf(),
            max_gap_s: options.max_gap_s,
        })
    }
}

/// A given rate further than this factor from the rate the stamps measure is refused.
pub const RATE_DISAGREEMENT: f64 = 2.0;

/// A given rate further than this share from the rate the stamps measure (but within
/// [`RATE_DISAGREEMENT`]) is accepted with a warning.
pub const RATE_WARNING_SHARE: f64 = 0.01;

/// Positive steps needed before a given rate is checked against the stamps' rate.
pub const RATE_CHECK_MIN_STEPS: usize = 20;

/// Check a given rate (option or metadata) against the first rows' stamps: the stamps'
/// rate is the mean row rate for rows arriving in bursts, else the single steps' mean
/// ([`single_step_rate`]). More than [`RATE_DISAGREEMENT`] off either way is an error;
/// more than [`RATE_WARNING_SHARE`] off, a warning (returned). With fewer than [`RATE_CHECK_MIN_STEPS`] positive steps (a
/// median of a few steps says little) only a rate more than [`RATE_DISAGREEMENT`] above the
/// fastest step's is refused: every step would be a gap.
pub(crate) fn check_given_rate(
    path: &Path,
    rows: &[Row],
    arrival: Option<Bursts>,
    rate_hz: f64,
    source: &'static str,
) -> Result<Option<String>, LogError> {
    if source != "option" && source != "metadata" {
        return Ok(None);
    }
    let source_name = if source == "option" {
        "--sample-rate-hz option"
    } else {
        "sample_rate_hz metadata"
    };
    let disagrees = |measured_hz: f64| LogError::SampleRateDisagrees {
        path: path.to_path_buf(),
        rate_hz,
        source_name,
        measured_hz,
        ratio: measured_hz / rate_hz,
    };
    let steps = || {
        rows.windows(2)
            .take(RATE_WINDOW_STEPS)
            .map(|w| w[1].time_s - w[0].time_s)
            .filter(|dt| *dt > 0.0)
    };
    let positive = steps().count();
    if positive < RATE_CHECK_MIN_STEPS {
        let shortest = steps().fold(f64::INFINITY, f64::min);
        if positive > 0 && rate_hz * shortest > RATE_DISAGREEMENT {
            return Err(disagrees(1.0 / shortest));
        }
        return Ok(None);
    }
    let measured_hz = match arrival {
        Some(b) => 1.0 / b.mean_step_s,
        None => match single_step_rate(path, rows) {
            Ok((hz, _)) => hz,
            Err(_) => return Ok(None),
        },
    };
    let ratio = measured_hz / rate_hz;
    if !(1.0 / RATE_DISAGREEMENT..=RATE_DISAGREEMENT).contains(&ratio) {
        return Err(disagrees(measured_hz));
    }
    Ok(((ratio - 1.0).abs() > RATE_WARNING_SHARE).then(|| {
        format!(
            "{}: the {source_name} gives {} Hz but the time stamps say {} Hz ({} times \
             that); the grid follows the given rate, so angles are off by up to that factor if \
             the stamps are right",
            path.display(),
            crate::num(rate_hz),
            crate::fixed(measured_hz, 3),
            crate::fixed(ratio, 4)
        )
    }))
}

/// Most slots a run bridged by interpolation may need (`max_gap_s` × the grid rate): the
/// placer holds such a run in memory. 2^24 slots, 1 GiB; at 1 kHz, gaps of 4.6 hours.
pub const MAX_BRIDGED_SLOTS: u64 = 1 << 24;

/// Most slots of a log held whole in memory ([`crate::load`]): 2^26 slots, 4 GiB; at
/// 1 kHz, 18.6 hours.
pub const MAX_HELD_SLOTS: u64 = 1 << 26;

/// Refuse a grid on which bridging a gap of `max_gap_s` would hold more than
/// [`MAX_BRIDGED_SLOTS`] slots, before any is made.
pub(crate) fn check_bridged_slots(
    path: &Path,
    options: &GridOptions,
    rate_hz: f64,
) -> Result<(), LogError> {
    let slots = (options.max_gap_s * rate_hz).floor();
    if slots > MAX_BRIDGED_SLOTS as f64 {
        return Err(LogError::TooLarge {
            path: path.to_path_buf(),
            what: format!(
                "bridging gaps of up to {} s at {} Hz would hold",
                options.max_gap_s,
                crate::hz(rate_hz)
            ),
            samples: slots,
            limit: MAX_BRIDGED_SLOTS,
        });
    }
    Ok(())
}

/// The rate from the positive steps of the first [`RATE_WINDOW_STEPS`] steps that are one
/// period: the mean of those within half the median step of it, ends included (gaps, and
/// the zero steps of repeated stamps, left out). The median alone is not the period when
/// the steps are not symmetric about it: a 104 Hz sensor stamped to the millisecond steps
/// 9 and 10 ms, median 10 ms, and a row per slot on a 100 Hz grid would stretch time by 4%.
fn single_step_rate(path: &Path, rows: &[Row]) -> Result<(f64, &'static str), LogError> {
    let mut steps: Vec<f64> = rows
        .windows(2)
        .take(RATE_WINDOW_STEPS)
        .map(|w| w[1].time_s - w[0].time_s)
        .filter(|dt| *dt > 0.0)
        .collect();
    if steps.is_empty() {
        return Err(LogError::SampleRateUnknown {
            path: path.to_path_buf(),
        });
    }
    steps.sort_by(f64::total_cmp);
    Ok((1.0 / single_step_mean(&steps), "single_steps"))
}

/// Steps within this share of the median step of it are one period (half, and a little
/// more so that a 416 Hz sensor stamped to the millisecond, steps 2 and 3 ms, keeps its
/// 3 ms steps to rounding); a lost sample's step is twice the period.
const SINGLE_STEP_SPREAD: f64 = 0.500_001;

/// The mean of the sorted positive `steps` within [`SINGLE_STEP_SPREAD`] of the median (a
/// period each).
fn single_step_mean(sorted_steps: &[f64]) -> f64 {
    let median = sorted_steps[sorted_steps.len() / 2];
    let (sum, count) = sorted_steps
        .iter()
        .filter(|&&dt| (dt - median).abs() <= SINGLE_STEP_SPREAD * median)
        .fold((0.0, 0_usize), |(sum, count), &dt| (sum + dt, count + 1));
    sum / count as f64
}

/// Place the rows of `log` on a regular grid (all of it in memory; see [`place`] for the
/// streaming form, which this wraps).
pub fn regularize(log: &Log, options: &GridOptions) -> Result<RegularLog, LogError> {
    struct Collect(Vec<Slot>);
    impl SlotSink for Collect {
        fn start(&mut self, _sample_rate_hz: f64) {}
        fn slot(&mut self, slot: &Slot) {
            self.0.push(*slot);
        }
    }
    let mut collect = Collect(Vec::with_capacity(log.rows.len() + 16));
    let quality = place(
        &LogInfo::of(log),
        log.rows.iter().copied().map(Ok),
        options,
        &mut collect,
    )?;
    Ok(RegularLog {
        slots: collect.0,
        sample_rate_hz: quality.sample_rate_hz,
        has_reference: log.has_reference,
        has_temperature: log.has_temperature,
        quality,
    })
}

/// Place rows on a regular grid as they come, handing each slot to `sink` as soon as it is
/// final, and return the quality report once the rows are done.
///
/// Memory stays bounded: at most [`RATE_WINDOW_STEPS`] + 1 rows are held back while the
/// arrival pattern ([`bursts::classify`]) and, unless the option or the metadata gives it,
/// the rate are estimated; then only the slots of a run still waiting for interpolation
/// (at most `max_gap_s` of them).
///
/// The outcome is that of reading the whole log, then placing it: a read error anywhere
/// wins over any placement error, and placement errors come in the order of the passes
/// over a whole log (an empty log; the rate; steps back and gaps between rows; no rate at
/// all; a run of missing rates too long to interpolate), the first of each kind. So after
/// an error the rest of the rows are still read (and placed as far as they can decide
/// the outcome), and `sink` gets no more slots; on an error, what it got is to be
/// discarded.
pub fn place<S: SlotSink + ?Sized>(
    info: &LogInfo<'_>,
    rows: impl IntoIterator<Item = Result<Row, LogError>>,
    options: &GridOptions,
    sink: &mut S,
) -> Result<Quality, LogError> {
    sink.columns(info.has_reference, info.has_temperature);
    let mut rows = rows.into_iter();
    // Stamps from a counter that wraps are unwrapped before anything looks at them.
    let mut unwrapper = Unwrapper::default();
    // Rows held back while the arrival pattern (and, unless given, the rate) is estimated.
    let mut ahead: Vec<Row> = Vec::new();
    while ahead.len() <= RATE_WINDOW_STEPS {
        match rows.next() {
            Some(row) => {
                let mut row = row?;
                unwrapper.unwrap(&mut row);
                ahead.push(row);
            }
            None => break,
        }
    }
    if ahead.is_empty() {
        return Err(LogError::NoData {
            path: info.path.to_path_buf(),
            what: "no data rows after the header".into(),
        });
    }
    let arrival = bursts::classify(&ahead, RATE_WINDOW_STEPS);
    let rate = match (given_rate(info, options), arrival) {
        (Some(rate), _) => rate,
        (None, Some(b)) => Ok((1.0 / b.mean_step_s, "mean_step")),
        (None, None) => single_step_rate(info.path, &ahead),
    };
    let rate = check_max_gap(info.path, options)
        .and(check_time_order(info.path, &ahead))
        .and(rate);
    let rate = rate.and_then(|(rate_hz, source)| {
        let warning = check_given_rate(info.path, &ahead, arrival, rate_hz, source)?;
        check_bridged_slots(info.path, options, rate_hz)?;
        Ok((rate_hz, source, warning))
    });
    let (rate_hz, source, warning) = match rate {
        Ok(rate) => rate,
        Err(e) => {
            // A read error further on comes first.
            for row in rows {
                row?;
            }
            return Err(e);
        }
    };
    sink.start(rate_hz);
    let mut placer = Placer::new(info, options, rate_hz, source, arrival, sink);
    placer.quality.warnings.extend(warning);
    for row in std::mem::take(&mut ahead) {
        placer.row(&row);
    }
    for row in rows {
        let mut row = row?;
        unwrapper.unwrap(&mut row);
        placer.row(&row);
    }
    let mut quality = placer.finish()?;
    note_wraps(&mut quality, &unwrapper);
    Ok(quality)
}

/// Refuse rows whose time stamps give no order: every one of them stamped alike (a time
/// column of zeros, MCAP messages all at one log time), or more steps back in time than
/// forward (rows in reverse order). Either placed on the grid would be a log of another
/// length and order than the one recorded. `rows` are the first rows of a log (the
/// window the rate is estimated on, or the whole log).
pub(crate) fn check_time_order(path: &Path, rows: &[Row]) -> Result<(), LogError> {
    let (Some(first), Some(last)) = (rows.first(), rows.last()) else {
        return Ok(());
    };
    if rows.len() < 2 {
        return Ok(());
    }
    if rows.iter().all(|r| r.time_s == first.time_s) {
        return Err(LogError::TimeConstant {
            path: path.to_path_buf(),
            rows: rows.len() as u64,
            first_line: first.line,
            last_line: last.line,
            time_s: first.time_s,
        });
    }
    let (mut back, mut forward, mut first_back) = (0_u64, 0_u64, None);
    for pair in rows.windows(2) {
        let dt = pair[1].time_s - pair[0].time_s;
        if dt < 0.0 {
            back += 1;
            first_back.get_or_insert(pair[1].line);
        } else if dt > 0.0 {
            forward += 1;
        }
    }
    match first_back {
        Some(line) if back > forward => Err(LogError::TimeReversed {
            path: path.to_path_buf(),
            line,
            back,
            steps: rows.len() as u64 - 1,
        }),
        _ => Ok(()),
    }
}

/// The error for `row` stamped more than `max_back_s` before `previous` (a concatenated or
/// corrupt log), if it is.
pub(crate) fn time_backwards(
    path: &Path,
    previous: &Row,
    row: &Row,
    max_back_s: f64,
) -> Option<LogError> {
    let back_s = previous.time_s - row.time_s;
    (back_s > max_back_s).then(|| LogError::TimeBackwards {
        path: path.to_path_buf(),
        line: row.line,
        previous_line: previous.line,
        previous_s: previous.time_s,
        time_s: row.time_s,
        back_s,
    })
}

/// What `unwrapper` did, in the quality report: the count, the span, the first line.
fn note_wraps(quality: &mut Quality, unwrapper: &Unwrapper) {
    quality.counter_wraps = unwrapper.wraps;
    quality.counter_span_s = unwrapper.span_s();
    if let (Some(span_s), Some(line)) = (unwrapper.span_s(), unwrapper.first_line) {
        // First, so that the report's first lines always show it.
        let what = format!("time stamps wrap: {}, unwrapped", describe_span(span_s));
        quality.examples.insert(0, (what, line));
        quality.examples.truncate(MAX_EXAMPLES);
    }
}

/// The streaming form of the rules in the module documentation: rows in, final slots out.
///
/// Three stages, each the streaming form of one pass over a whole log: rows to slots
/// (duplicates, steps back, gaps: `row`); trimming and interpolating the rate (`rate`);
/// interpolating the reference and the temperature (`channels`), which hands the slots to
/// the sink.
struct Placer<'p, S: SlotSink + ?Sized> {
    path: &'p Path,
    period_s: f64,
    max_gap_s: f64,
    /// Longest run of missing slots interpolated.
    max_run: usize,
    quality: Quality,
    /// Stage 1: the last row kept.
    previous: Option<Row>,
    /// Stage 1 for rows arriving in bursts: the integral-preserving resampler (`None`: a
    /// row per slot), the steps counted as gaps, and the slots it completed.
    resampler: Option<Resampler>,
    gap_step_s: f64,
    resampled: Vec<Slot>,
    /// Stage 0: backlogs after a stall re-timed, and the rows it released.
    retimer: Retimer,
    released: Vec<Row>,
    /// A step back or gap between rows too long: stage 1 stops (the rows are still read).
    row_error: Option<LogError>,
    /// A run of missing rates too long: stages 2 and 3 stop.
    fill_error: Option<LogError>,
    /// Stage 2: slots without a rate before the first with one (trimmed).
    leading_missing: u64,
    /// Stage 2: the last slot with a rate.
    last_rate: Option<Slot>,
    /// Stage 2: the slots without a rate since `last_rate`, up to `max_run` of them (a
    /// longer run is an error, unless it ends the log: trimmed).
    missing: Vec<Slot>,
    /// Stage 2: how many slots without a rate since `last_rate`.
    missing_count: u64,
    /// Stage 3: slots waiting for a reference or temperature interpolation.
    pending: std::collections::VecDeque<Slot>,
    /// Stage 3: index of the first slot in `pending`.
    pending_start: u64,
    /// Stage 3: index of the next slot.
    next_index: u64,
    reference: Channel,
    temperature: Channel,
    /// Stage 3: time of the first and last slot delivered.
    first_time_s: Option<f64>,
    last_time_s: f64,
    /// The reference re-based after its jumps, as the slots are delivered.
    jumps: ReferenceJumps,
    sink: &'p mut S,
}

/// An optional value (reference, temperature) interpolated across short runs.
struct Channel {
    /// False if the log has no such column: nothing is interpolated.
    enabled: bool,
    /// The index and value of the last slot with a value.
    last_known: Option<(u64, f64)>,
}

impl Channel {
    /// True if the slot at `index`, with `value`, cannot change any more when `latest` is
    /// the index of the latest slot.
    fn is_final(&self, index: u64, value: Option<f64>, latest: u64, max_run: usize) -> bool {
        if !self.enabled || value.is_some() {
            return true;
        }
        match self.last_known {
            // Before any value: never interpolated.
            None => true,
            // Inside a run already decided.
            Some((known, _)) if index < known => true,
            // Inside an open run: final once it is too long to interpolate.
            Some((known, _)) => latest - known > max_run as u64,
        }
    }
}

impl<'p, S: SlotSink + ?Sized> Placer<'p, S> {
    fn new(
        info: &LogInfo<'p>,
        options: &GridOptions,
        rate_hz: f64,
        source: &'static str,
        arrival: Option<Bursts>,
        sink: &'p mut S,
    ) -> Self {
        let period_s = 1.0 / rate_hz;
        let max_run = ((options.max_gap_s / period_s).floor() as usize).max(1);
        let gap_step_s = arrival.map_or(1.5 * period_s, |b| b.gap_step_s.max(1.5 * period_s));
        Self {
            path: info.path,
            period_s,
            max_gap_s: options.max_gap_s,
            max_run,
            quality: Quality {
                sample_rate_hz: rate_hz,
                sample_rate_source: source,
                bursts: arrival,
                ..Quality::default()
            },
            previous: None,
            resampler: arrival
                .map(|_| Resampler::new(period_s, gap_step_s, options.max_gap_s, max_run)),
            gap_step_s,
            resampled: Vec::new(),
            retimer: Retimer::new(gap_step_s),
            released: Vec::new(),
            row_error: None,
            fill_error: None,
            leading_missing: 0,
            last_rate: None,
            missing: Vec::new(),
            missing_count: 0,
            pending: std::collections::VecDeque::new(),
            pending_start: 0,
            next_index: 0,
            reference: Channel {
                enabled: info.has_reference,
                last_known: None,
            },
            temperature: Channel {
                enabled: info.has_temperature,
                last_known: None,
            },
            first_time_s: None,
            last_time_s: 0.0,
            jumps: ReferenceJumps::default(),
            sink,
        }
    }

    /// Stage 0: a row through the retimer (a stalled link's backlog is re-timed over the
    /// stall, [`crate::backlog`]); the rows it releases go on to stage 1.
    fn row(&mut self, row: &Row) {
        let mut released = std::mem::take(&mut self.released);
        self.retimer.push(*row, &mut released);
        for row in released.drain(..) {
            self.place_row(&row);
        }
        self.released = released;
    }

    /// Stage 1: a row to its slot, after the slots of a gap before it. A missing rate is
    /// NaN (and `filled`) for now.
    fn place_row(&mut self, row: &Row) {
        self.quality.rows += 1;
        if self.row_error.is_some() {
            return;
        }
        if let Some(prev) = self.previous {
            if !self.step_to(&prev, row) {
                return;
            }
        }
        if row.rate_dps.is_none() {
            self.quality.missing_rate_rows += 1;
            self.quality.note("missing rate interpolated", row.line);
        }
        if let Some(resampler) = self.resampler.as_mut() {
            let mut slots = std::mem::take(&mut self.resampled);
            if let Err(e) = resampler.row(self.path, row, &mut slots) {
                if self.fill_error.is_none() {
                    self.fill_error = Some(e);
                }
            }
            for slot in slots.drain(..) {
                self.rate(slot);
            }
            self.resampled = slots;
        } else {
            self.rate(Slot {
                time_s: row.time_s,
                rate_dps: row.rate_dps.unwrap_or(f64::NAN),
                reference_deg: row.reference_deg,
                temperature_c: row.temperature_c,
                line: row.line,
                filled: row.rate_dps.is_none(),
            });
        }
        self.previous = Some(*row);
    }

    /// The step from the row kept before, `prev`, to `row`: counted (duplicate, backwards,
    /// same time, gap, jitter), a gap's slots placed. False if `row` is not to be placed
    /// (a duplicate dropped, or a step that is an error, now in `row_error`).
    fn step_to(&mut self, prev: &Row, row: &Row) -> bool {
        if same_row(prev, row) {
            self.quality.duplicate_rows += 1;
            self.quality.note("duplicate row dropped", row.line);
            return false;
        }
        let dt = row.time_s - prev.time_s;
        self.quality.longest_step_s = self.quality.longest_step_s.max(dt);
        if dt < 0.0 {
            if let Some(e) = time_backwards(self.path, prev, row, self.max_gap_s) {
                self.row_error = Some(e);
                return false;
            }
            self.quality.backward_steps += 1;
            self.quality
                .note("time stamp before the previous row", row.line);
        } else if dt == 0.0 {
            self.quality.same_time_rows += 1;
            self.quality
                .note("same time stamp as the previous row", row.line);
        }
        if self.resampler.is_some() {
            if dt > self.gap_step_s {
                if dt > self.max_gap_s {
                    self.row_error = Some(self.gap_error(prev, row, dt));
                    return false;
                }
                self.quality.gaps += 1;
                self.quality
                    .note("gap bridged by the resampled angle", row.line);
            } else if dt > 0.0 && (dt - self.period_s).abs() > 0.05 * self.period_s {
                self.quality.jittered_steps += 1;
            }
            true
        } else {
            self.fill_gap(prev, row, dt)
        }
    }

    /// A step of `dt` from `prev` to `row` on the grid (no resampler): the slots of a gap
    /// between them, rate missing, or a jittered step counted. False if the gap is too
    /// long (the error in `row_error`).
    fn fill_gap(&mut self, prev: &Row, row: &Row, dt: f64) -> bool {
        let steps = if dt <= 0.0 {
            1
        } else {
            ((dt / self.period_s).round() as u64).max(1)
        };
        if steps > 1 {
            if dt > self.max_gap_s {
                self.row_error = Some(self.gap_error(prev, row, dt));
                return false;
            }
            self.quality.gaps += 1;
            self.quality.note("gap filled by interpolation", row.line);
            for j in 1..steps {
                let time_s = prev.time_s + dt * j as f64 / steps as f64;
                self.rate(Slot {
                    time_s,
                    rate_dps: f64::NAN,
                    reference_deg: None,
                    temperature_c: None,
                    line: 0,
                    filled: true,
                });
            }
        } else if dt > 0.0 && (dt - self.period_s).abs() > 0.05 * self.period_s {
            self.quality.jittered_steps += 1;
        }
        true
    }

    /// A step between rows too long to bridge.
    fn gap_error(&self, prev: &Row, row: &Row, dt: f64) -> LogError {
        LogError::Gap {
            path: self.path.to_path_buf(),
            line: row.line,
            previous_line: prev.line,
            gap_s: dt,
            max_gap_s: self.max_gap_s,
        }
    }

    /// Stage 2: trim slots without a rate at the start (and, in `finish`, at the end);
    /// interpolate the rate across the runs between (bounded by `max_gap_s`).
    fn rate(&mut self, slot: Slot) {
        if self.fill_error.is_some() {
            return;
        }
        if slot.rate_dps.is_nan() {
            if self.last_rate.is_none() {
                self.leading_missing += 1;
            } else {
                self.missing_count += 1;
                if self.missing.len() < self.max_run {
                    self.missing.push(slot);
                }
            }
            return;
        }
        if let Some(before) = self.last_rate {
            if self.missing_count > self.max_run as u64 {
                self.fill_error = Some(LogError::Gap {
                    path: self.path.to_path_buf(),
                    line: slot.line,
                    previous_line: before.line,
                    gap_s: slot.time_s - before.time_s,
                    max_gap_s: self.max_gap_s,
                });
                self.missing.clear();
                return;
            }
            let (previous, value) = (before.rate_dps, slot.rate_dps);
            let span = (self.missing.len() + 1) as f64;
            for (k, mut filled) in std::mem::take(&mut self.missing).into_iter().enumerate() {
                let w = (k + 1) as f64 / span;
                filled.rate_dps = previous + w * (value - previous);
                self.channels(filled);
            }
            self.missing_count = 0;
        }
        self.last_rate = Some(slot);
        self.channels(slot);
    }

    /// Stage 3: interpolate the reference and the temperature across runs up to
    /// `max_gap_s` (else leave them missing); deliver the slots that cannot change.
    fn channels(&mut self, slot: Slot) {
        let index = self.next_index;
        self.next_index += 1;
        self.pending.push_back(slot);
        let max_run = self.max_run;
        let start = self.pending_start;
        let pending = &mut self.pending;
        interpolate(
            &mut self.reference,
            index,
            slot.reference_deg,
            max_run,
            |k, v| {
                if let Some(s) = slot_at(pending, start, k) {
                    s.reference_deg = Some(v);
                }
            },
        );
        interpolate(
            &mut self.temperature,
            index,
            slot.temperature_c,
            max_run,
            |k, v| {
                if let Some(s) = slot_at(pending, start, k) {
                    s.temperature_c = Some(v);
                }
            },
        );
        self.deliver(false);
    }

    /// Hand the final slots at the front of `pending` to the sink (all at the end).
    fn deliver(&mut self, all: bool) {
        let latest = self.next_index.saturating_sub(1);
        while let Some(front) = self.pending.front() {
            let index = self.pending_start;
            let done = all
                || (self
                    .reference
                    .is_final(index, front.reference_deg, latest, self.max_run)
                    && self
                        .temperature
                        .is_final(index, front.temperature_c, latest, self.max_run));
            if !done {
                break;
            }
            let Some(slot) = self.pending.pop_front() else {
                break;
            };
            self.pending_start += 1;
            self.quality.slots += 1;
            if slot.filled {
                self.quality.filled_slots += 1;
            }
            if self.reference.enabled && slot.reference_deg.is_none() {
                self.quality.missing_reference_slots += 1;
            }
            if self.first_time_s.is_none() {
                self.first_time_s = Some(slot.time_s);
            }
            self.last_time_s = slot.time_s;
            if self.reference.enabled {
                let sink = &mut self.sink;
                self.jumps
                    .push(slot, &mut self.quality, &mut |s| sink.slot(&s));
            } else {
                self.sink.slot(&slot);
            }
        }
    }

    /// The end of the rows: trim the trailing slots without a rate, deliver the rest, and
    /// return the report or the first error (in the order of the passes over a whole log).
    fn finish(mut self) -> Result<Quality, LogError> {
        let mut released = std::mem::take(&mut self.released);
        self.retimer.finish(&mut released);
        for row in released.drain(..) {
            self.place_row(&row);
        }
        self.quality.backlogs = self.retimer.backlogs;
        self.quality.retimed_rows = self.retimer.retimed_rows;
        if let Some(e) = self.row_error.take() {
            return Err(e);
        }
        if self.last_rate.is_none() {
            return Err(LogError::NoData {
                path: self.path.to_path_buf(),
                what: "no row has a rate value".into(),
            });
        }
        if let Some(e) = self.fill_error.take() {
            return Err(e);
        }
        self.quality.trimmed_slots = self.leading_missing
            + self.missing_count
            + self.resampler.as_ref().map_or(0, Resampler::trimmed_rows);
        self.deliver(true);
        let sink = &mut self.sink;
        self.jumps
            .finish(self.path, &mut self.quality, &mut |s| sink.slot(&s));
        let mut quality = self.quality;
        let first_time_s = self.first_time_s.unwrap_or(self.last_time_s);
        let span_s = self.last_time_s - first_time_s;
        quality.effective_rate_hz = if span_s > 0.0 {
            (quality.slots - 1) as f64 / span_s
        } else {
            quality.sample_rate_hz
        };
        Ok(quality)
    }
}

/// The pending slot of index `index` (`start`: the index of the first pending slot).
fn slot_at(
    pending: &mut std::collections::VecDeque<Slot>,
    start: u64,
    index: u64,
) -> Option<&mut Slot> {
    let offset = usize::try_from(index.checked_sub(start)?).ok()?;
    pending.get_mut(offset)
}

/// Stage 3 for one channel: a slot at `index` with `value`; if it ends a run of missing
/// values no longer than `max_run`, `set(k, v)` for each slot `k` of the run.
fn interpolate(
    channel: &mut Channel,
    index: u64,
    value: Option<f64>,
    max_run: usize,
    mut set: impl FnMut(u64, f64),
) {
    if !channel.enabled {
        return;
    }
    let Some(value) = value else {
        return;
    };
    if let Some((j, previous)) = channel.last_known {
        if index - j > 1 && index - j - 1 <= max_run as u64 {
            for k in j + 1..index {
                let w = (k - j) as f64 / (index - j) as f64;
                set(k, previous + w * (value - previous));
            }
        }
    }
    channel.last_known = Some((index, value));
}

#[cfg(test)]
#[allow(clippy::unwrap_used)] // test code: a failed unwrap is a failed test
mod tests {
    use super::*;
    use proptest::prelude::*;
    use std::collections::BTreeMap;

    mod whole {
        //! The whole-log passes that [`super::super::place`] streams.
        use super::super::{Bursts, GridOptions, Quality, RegularLog, Slot};
        use crate::{Log, LogError, Row};

        fn same_row_whole(a: &Row, b: &Row) -> bool {
            a.time_s == b.time_s
                && a.rate_dps == b.rate_dps
                && a.reference_deg == b.reference_deg
                && a.temperature_c == b.temperature_c
        }

        /// The grid rate and where it came from.
        fn sample_rate(
            log: &Log,
            options: &GridOptions,
            arrival: Option<Bursts>,
        ) -> Result<(f64, &'static str), LogError> {
            if let Some(rate) = options.sample_rate_hz {
                if !(rate.is_finite() && rate > 0.0) {
                    return Err(LogError::SampleRateInvalid {
                        path: log.path.clone(),
                        rate_hz: rate,
                    });
                }
                return Ok((rate, "option"));
            }
            if let Some(rate) = log.metadata_rate_hz() {
                return Ok((rate, "metadata"));
            }
            if let Some(b) = arrival {
                return Ok((1.0 / b.mean_step_s, "mean_step"));
            }
            let mut steps: Vec<f64> = log
                .rows
                .windows(2)
                .take(100_000)
                .map(|w| w[1].time_s - w[0].time_s)
                .filter(|dt| *dt > 0.0)
                .collect();
            if steps.is_empty() {
                return Err(LogError::SampleRateUnknown {
                    path: log.path.clone(),
                });
            }
            steps.sort_by(f64::total_cmp);
            let median = steps[steps.len() / 2];
            let single: Vec<f64> = steps
                .iter()
                .copied()
                .filter(|dt| (dt - median).abs() <= super::super::SINGLE_STEP_SPREAD * median)
                .collect();
            let mean_s = single.iter().sum::<f64>() / single.len() as f64;
            Ok((1.0 / mean_s, "single_steps"))
        }

        /// The rows with each stalled link's backlog re-timed over its gap (the whole-log
        /// form of [`crate::backlog`]), and the counts of backlogs and rows re-timed.
        fn retime_whole(rows: &[Row], gap_step_s: f64) -> (Vec<Row>, u64, u64) {
            use crate::backlog::{BACKLOG_HORIZON_S, LOCAL_PERIOD_WINDOW_S, MIN_LOCAL_STEPS};
            let mut rows = rows.to_vec();
            let (mut backlogs, mut retimed) = (0, 0);
            // The stamps made non-decreasing, as re-timed so far.
            let mut clock: Vec<f64> = rows.first().map(|r| r.time_s).into_iter().collect();
            let mut i = 1;
            while i < rows.len() {
                let last_s = clock[i - 1];
                // The steps of the local period, looked at only after a gap.
                let steps: Vec<f64> = if rows[i].time_s - last_s > gap_step_s {
                    (1..i)
                        .filter(|&k| clock[k] >= last_s - LOCAL_PERIOD_WINDOW_S)
                        .map(|k| clock[k] - clock[k - 1])
                        .filter(|&step_s| step_s <= gap_step_s)
                        .collect()
                } else {
                    Vec::new()
                };
                let mut end = i;
                if steps.len() >= MIN_LOCAL_STEPS {
                    let period_s = steps.iter().sum::<f64>() / steps.len() as f64;
                    let gap_s = rows[i].time_s - last_s;
                    let mut j = i;
                    while j < rows.len() {
                        if j > i && rows[j - 1].time_s - rows[j].time_s > gap_step_s {
                            break;
                        }
                        let span_s = rows[j].time_s.max(last_s) - last_s;
                        let count = j - i + 1;
                        if span_s <= count as f64 * period_s {
                            for (n, row) in rows[i..=j].iter_mut().enumerate() {
                                row.time_s = last_s + span_s * (n + 1) as f64 / count as f64;
                            }
                            backlogs += 1;
                            retimed += count as u64;
                            break;
                        }
                        if span_s - gap_s >= BACKLOG_HORIZON_S {
                            break;
                        }
                        j += 1;
                    }
                    end = j.min(rows.len() - 1);
                }
                for k in i..=end {
                    let previous = clock[k - 1];
                    clock.push(rows[k].time_s.max(previous));
                }
                i = end + 1;
            }
            (rows, backlogs, retimed)
        }

        /// The whole-log implementation `place` replaced, kept verbatim as the oracle.
        pub fn regularize_whole(log: &Log, options: &GridOptions) -> Result<RegularLog, LogError> {
            // The stamps unwrapped first, as in the streaming placement.
            let (unwrapped, unwrapper) = crate::wraps::unwrapped(log);
            let mut whole = placed_whole(&unwrapped, options)?;
            super::super::note_wraps(&mut whole.quality, &unwrapper);
            Ok(whole)
        }

        fn placed_whole(log: &Log, options: &GridOptions) -> Result<RegularLog, LogError> {
            if log.rows.is_empty() {
                return Err(LogError::NoData {
                    path: log.path.clone(),
                    what: "no data rows after the header".into(),
                });
            }
            let arrival = crate::bursts::classify(&log.rows, 100_000);
            super::super::check_max_gap(&log.path, options)?;
            let window = log.rows.len().min(super::super::RATE_WINDOW_STEPS + 1);
            super::super::check_time_order(&log.path, &log.rows[..window])?;
            let (rate_hz, source) = sample_rate(log, options, arrival)?;
            let warning =
                super::super::check_given_rate(&log.path, &log.rows, arrival, rate_hz, source)?;
            super::super::check_bridged_slots(&log.path, options, rate_hz)?;
            let grid_period_s = 1.0 / rate_hz;
            let gap_step_s = arrival.map_or(1.5 * grid_period_s, |b| {
                b.gap_step_s.max(1.5 * grid_period_s)
            });
            let (rows, backlogs, retimed_rows) = retime_whole(&log.rows, gap_step_s);
            let log = &Log {
                rows,
                ..log.clone()
            };
            if let Some(b) = arrival {
                let mut whole = resample_whole(log, options, rate_hz, source, b)?;
                whole.quality.backlogs = backlogs;
                whole.quality.retimed_rows = retimed_rows;
                // The rate's warning comes first, as in the streaming placement.
                let later = std::mem::take(&mut whole.quality.warnings);
                whole.quality.warnings.extend(warning);
                whole.quality.warnings.extend(later);
                return Ok(whole);
            }
            let period_s = 1.0 / rate_hz;
            let mut quality = Quality {
                rows: log.rows.len() as u64,
                sample_rate_hz: rate_hz,
                sample_rate_source: source,
                warnings: warning.into_iter().collect(),
                backlogs,
                retimed_rows,
                ..Quality::default()
            };

            // Pass 1: assign slots; a missing rate is NaN (and `filled`) for now.
            let mut slots: Vec<Slot> = Vec::with_capacity(log.rows.len() + 16);
            let mut previous: Option<&Row> = None;
            for row in &log.rows {
                if let Some(prev) = previous {
                    if same_row_whole(prev, row) {
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
            finish_whole(slots, quality, log, max_run, rate_hz)
        }

        /// Pass 3 and the report, for both placements.
        fn finish_whole(
            mut slots: Vec<Slot>,
            mut quality: Quality,
            log: &Log,
            max_run: usize,
            rate_hz: f64,
        ) -> Result<RegularLog, LogError> {
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
                let mut jumps = crate::jumps::ReferenceJumps::default();
                let mut rebased = Vec::with_capacity(slots.len());
                for slot in slots {
                    jumps.push(slot, &mut quality, &mut |s| rebased.push(s));
                }
                jumps.finish(&log.path, &mut quality, &mut |s| rebased.push(s));
                slots = rebased;
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

        /// The integral-preserving placement of rows arriving in bursts, written over the
        /// whole log: the cumulative angle at the rows with a rate, interpolated at the grid
        /// times and differenced.
        fn resample_whole(
            log: &Log,
            options: &GridOptions,
            rate_hz: f64,
            source: &'static str,
            bursts: Bursts,
        ) -> Result<RegularLog, LogError> {
            let period_s = 1.0 / rate_hz;
            let gap_step_s = bursts.gap_step_s.max(1.5 * period_s);
            let max_run = ((options.max_gap_s / period_s).floor() as usize).max(1);
            let mut quality = Quality {
                rows: log.rows.len() as u64,
                sample_rate_hz: rate_hz,
                sample_rate_source: source,
                bursts: Some(bursts),
                ..Quality::default()
            };
            // Pass 1: the rows kept, stamps made non-decreasing.
            let mut kept: Vec<Row> = Vec::new();
            let mut previous: Option<&Row> = None;
            for row in &log.rows {
                if let Some(prev) = previous {
                    if same_row_whole(prev, row) {
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
                    if dt > gap_step_s {
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
                        quality.note("gap bridged by the resampled angle", row.line);
                    } else if dt > 0.0 && (dt - period_s).abs() > 0.05 * period_s {
                        quality.jittered_steps += 1;
                    }
                }
                if row.rate_dps.is_none() {
                    quality.missing_rate_rows += 1;
                    quality.note("missing rate interpolated", row.line);
                }
                let mut kept_row = *row;
                if let Some(last) = kept.last() {
                    kept_row.time_s = kept_row.time_s.max(last.time_s);
                }
                kept.push(kept_row);
                previous = Some(row);
            }
            let valid: Vec<usize> = (0..kept.len())
                .filter(|&i| kept[i].rate_dps.is_some())
                .collect();
            let (Some(&first), Some(&last)) = (valid.first(), valid.last()) else {
                return Err(LogError::NoData {
                    path: log.path.clone(),
                    what: "no row has a rate value".into(),
                });
            };
            for pair in valid.windows(2) {
                let (p, q) = (pair[0], pair[1]);
                let span_s = kept[q].time_s - kept[p].time_s;
                if q > p + 1 && (q - p - 1 > max_run || span_s > options.max_gap_s) {
                    return Err(LogError::Gap {
                        path: log.path.clone(),
                        line: kept[q].line,
                        previous_line: kept[p].line,
                        gap_s: span_s,
                        max_gap_s: options.max_gap_s,
                    });
                }
            }
            quality.trimmed_slots = (first + kept.len() - 1 - last) as u64;
            let rate = |i: usize| kept[i].rate_dps.unwrap_or(f64::NAN);
            let mut angle_deg = vec![0.0; valid.len()];
            for k in 1..valid.len() {
                let (p, q) = (valid[k - 1], valid[k]);
                angle_deg[k] = angle_deg[k - 1]
                    + 0.5 * (rate(p) + rate(q)) * (kept[q].time_s - kept[p].time_s);
            }
            let start = kept[first];
            let mut slots = vec![Slot {
                time_s: start.time_s,
                rate_dps: rate(first),
                reference_deg: start.reference_deg,
                temperature_c: start.temperature_c,
                line: start.line,
                filled: false,
            }];
            let (mut k, mut previous_deg) = (1, 0.0);
            for j in 1.. {
                let time_s = start.time_s + j as f64 * period_s;
                if time_s > kept[last].time_s {
                    break;
                }
                while kept[valid[k]].time_s < time_s {
                    k += 1;
                }
                let (p, q) = (valid[k - 1], valid[k]);
                let (tp, tq) = (kept[p].time_s, kept[q].time_s);
                let at_deg = angle_deg[k - 1]
                    + (angle_deg[k] - angle_deg[k - 1]) * (time_s - tp) / (tq - tp);
                let segment = &kept[p..=q];
                slots.push(Slot {
                    time_s,
                    rate_dps: (at_deg - previous_deg) / period_s,
                    reference_deg: crate::bursts::value_at(segment, time_s, |r| r.reference_deg),
                    temperature_c: crate::bursts::value_at(segment, time_s, |r| r.temperature_c),
                    line: kept[q].line,
                    filled: q > p + 1 || tq - tp > gap_step_s,
                });
                previous_deg = at_deg;
            }
            finish_whole(slots, quality, log, max_run, rate_hz)
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
    }

    /// One step of a generated log.
    #[derive(Clone, Copy, Debug)]
    enum Step {
        Regular,
        Jitter(f64),
        Same,
        Back(f64),
        Gap(u32),
        LongGap,
        LongBack,
        Duplicate,
        /// A link that stalls for this many periods, then delivers its backlog a quarter
        /// period apart (in a bursty log; elsewhere a gap).
        Stall(u32),
    }

    fn step() -> impl Strategy<Value = Step> {
        prop_oneof![
            40 => Just(Step::Regular),
            8 => (-0.4..0.4_f64).prop_map(Step::Jitter),
            2 => Just(Step::Same),
            2 => (0.01..1.5_f64).prop_map(Step::Back),
            4 => (2_u32..12).prop_map(Step::Gap),
            3 => Just(Step::Duplicate),
            2 => (4_u32..30).prop_map(Step::Stall),
        ]
    }

    /// A row's fields: rate, reference, temperature, each possibly missing.
    type Fields = (Option<f64>, Option<f64>, Option<f64>);

    fn fields() -> impl Strategy<Value = Fields> {
        let value = |missing: u32| {
            prop_oneof![
                missing => Just(None),
                20 => (-100.0..100.0_f64).prop_map(Some),
            ]
        };
        (value(3), value(4), value(3))
    }

    /// Rows at a nominal 100 Hz with the generated irregularities; runs of missing values
    /// come from `missing_runs` (start, length, which field).
    fn make_log(
        steps: &[(Step, Fields)],
        missing_runs: &[(usize, usize, u8)],
        metadata_rate: bool,
        has_reference: bool,
        has_temperature: bool,
        bursty: bool,
    ) -> Log {
        let period = 0.01;
        let mut rows: Vec<Row> = Vec::new();
        let mut time_s = 12.5;
        // Rows of a stall's backlog still to deliver.
        let mut backlog = 0_u32;
        for (i, (step, (rate, reference, temperature))) in steps.iter().enumerate() {
            let line = i as u64 + 3;
            let mut row = Row {
                line,
                time_s,
                rate_dps: *rate,
                reference_deg: if has_reference { *reference } else { None },
                temperature_c: if has_temperature { *temperature } else { None },
            };
            if let Some(previous) = rows.last() {
                time_s = previous.time_s
                    + match step {
                        Step::Regular if bursty && backlog > 0 => {
                            backlog -= 1;
                            0.25 * period
                        }
                        // Arrival in bursts: regular steps from 0.25 to 1.75 periods.
                        Step::Regular if bursty => {
                            period * (0.25 + 1.5 * (i as f64 * 0.618_034).fract())
                        }
                        Step::Stall(n) => {
                            backlog = if bursty { n + n / 3 } else { 0 };
                            period * f64::from(*n)
                        }
                        Step::Regular | Step::Duplicate => period,
                        Step::Jitter(j) => period * (1.0 + j),
                        Step::Same => 0.0,
                        Step::Back(b) => -period * b,
                        Step::Gap(n) => period * f64::from(*n),
                        Step::LongGap => 0.3,
                        Step::LongBack => -0.3,
                    };
                row.time_s = time_s;
                if matches!(step, Step::Duplicate) {
                    row = Row { line, ..*previous };
                }
            }
            rows.push(row);
        }
        for &(start, len, which) in missing_runs {
            for row in rows.iter_mut().skip(start).take(len) {
                match which % 3 {
                    0 => row.rate_dps = None,
                    1 => row.reference_deg = None,
                    _ => row.temperature_c = None,
                }
            }
        }
        let mut metadata = BTreeMap::new();
        if metadata_rate {
            metadata.insert("sample_rate_hz".to_string(), "100".to_string());
        }
        Log {
            path: "generated.csv".into(),
            metadata,
            has_reference,
            has_temperature,
            rows,
        }
    }

    /// The two outcomes agree: the same error, or the same log; for rows in bursts the
    /// rates may differ by rounding (the oracle differences a cumulative angle), and so
    /// may a reference re-based after a jump (the gyro's turn over it is in the jump).
    fn same_outcome(
        streamed: Result<RegularLog, LogError>,
        whole: Result<RegularLog, LogError>,
    ) -> Result<(), String> {
        let (Ok(a), Ok(b)) = (&streamed, &whole) else {
            let (a, b) = (outcome(streamed), outcome(whole));
            return if a == b {
                Ok(())
            } else {
                Err(format!("{a}\n!=\n{b}"))
            };
        };
        if a.quality.bursts.is_none() || a.slots.len() != b.slots.len() {
            let (a, b) = (outcome(streamed), outcome(whole));
            return if a == b {
                Ok(())
            } else {
                Err(format!("{a}\n!=\n{b}"))
            };
        }
        let rounded = |log: &RegularLog| {
            let mut log = log.clone();
            // Sums over the rates: compared below, to rounding.
            log.quality.reference_correlation = None;
            log.quality.reference_gain = None;
            for slot in &mut log.slots {
                slot.rate_dps = 0.0;
                slot.reference_deg = slot.reference_deg.map(|_| 0.0);
            }
            format!("{log:?}")
        };
        if rounded(a) != rounded(b) {
            return Err(format!("{}\n!=\n{}", rounded(a), rounded(b)));
        }
        let close = |x: f64, y: f64| (x - y).abs() <= 1e-8 * (1.0 + y.abs());
        for (what, x, y) in [
            (
                "reference_correlation",
                a.quality.reference_correlation,
                b.quality.reference_correlation,
            ),
            (
                "reference_gain",
                a.quality.reference_gain,
                b.quality.reference_gain,
            ),
        ] {
            let agree = match (x, y) {
                (Some(x), Some(y)) => close(x, y),
                (x, y) => x == y,
            };
            if !agree {
                return Err(format!("{what}: {x:?} != {y:?}"));
            }
        }
        for (k, (x, y)) in a.slots.iter().zip(&b.slots).enumerate() {
            if !close(x.rate_dps, y.rate_dps) {
                return Err(format!("slot {k}: rate {} != {}", x.rate_dps, y.rate_dps));
            }
            if let (Some(p), Some(q)) = (x.reference_deg, y.reference_deg) {
                if !close(p, q) {
                    return Err(format!("slot {k}: reference {p} != {q}"));
                }
            }
        }
        Ok(())
    }

    fn outcome(result: Result<RegularLog, LogError>) -> String {
        match result {
            Ok(log) => format!("{log:?}"),
            Err(e) => format!("error: {e}"),
        }
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(600))]
        /// The streaming placer gives what the whole-log passes gave: slots, quality
        /// report, or the same error.
        #[test]
        fn streaming_placement_equals_whole_log_passes(
            mut steps in proptest::collection::vec((step(), fields()), 0..300),
            // At most one step too long to bridge, forward or back.
            long_step in proptest::option::weighted(0.2, (0_usize..300, any::<bool>())),
            missing_runs in proptest::collection::vec((0_usize..300, 1_usize..30, 0_u8..3), 0..4),
            metadata_rate: bool,
            option_rate in prop_oneof![4 => Just(None), 1 => Just(Some(100.0)), 1 => Just(Some(-1.0))],
            max_gap_s in prop_oneof![Just(0.05), Just(0.12), Just(0.5)],
            has_reference: bool,
            has_temperature: bool,
            bursty in proptest::bool::weighted(0.3),
        ) {
            if let Some((at, forward)) = long_step {
                if let Some(step) = steps.get_mut(at) {
                    step.0 = if forward { Step::LongGap } else { Step::LongBack };
                }
            }
            let log = make_log(&steps, &missing_runs, metadata_rate, has_reference, has_temperature, bursty);
            let options = GridOptions { sample_rate_hz: option_rate, max_gap_s };
            let same = same_outcome(regularize(&log, &options), whole::regularize_whole(&log, &options));
            prop_assert!(same.is_ok(), "{}", same.unwrap_err());
        }
    }

    /// A read error anywhere wins over any placement error, as when the log was read whole
    /// before being placed.
    #[test]
    fn read_errors_come_before_placement_errors() {
        let path = Path::new("x.csv");
        let info = LogInfo {
            path,
            metadata_rate_hz: Some(100.0),
            has_reference: false,
            has_temperature: false,
        };
        let row = |line: u64, time_s: f64| Row {
            line,
            time_s,
            rate_dps: Some(1.0),
            reference_deg: None,
            temperature_c: None,
        };
        let bad = || LogError::BadTime {
            path: path.to_path_buf(),
            line: 9,
            column: "time_s".into(),
        };
        struct Count(usize);
        impl SlotSink for Count {
            fn start(&mut self, _: f64) {}
            fn slot(&mut self, _: &Slot) {
                self.0 += 1;
            }
        }
        // A gap (line 2), then a read error (line 9).
        let rows = vec![
            Ok(row(1, 0.0)),
            Ok(row(2, 5.0)),
            Ok(row(3, 5.01)),
            Err(bad()),
        ];
        let err = place(&info, rows, &GridOptions::default(), &mut Count(0)).unwrap_err();
        assert!(
            err.to_string().contains("x.csv:9: missing or non-finite"),
            "{err}"
        );
        // A bad --sample-rate-hz, then a read error.
        let options = GridOptions {
            sample_rate_hz: Some(0.0),
            ..GridOptions::default()
        };
        let rows = vec![Ok(row(1, 0.0)), Err(bad())];
        let err = place(&info, rows, &options, &mut Count(0)).unwrap_err();
        assert!(err.to_string().contains("x.csv:9:"), "{err}");
        // Without a rate: the read error is inside the look-ahead.
        let info = LogInfo {
            metadata_rate_hz: None,
            ..info
        };
        let rows = vec![Ok(row(1, 0.0)), Err(bad())];
        let err = place(&info, rows, &GridOptions::default(), &mut Count(0)).unwrap_err();
        assert!(err.to_string().contains("x.csv:9:"), "{err}");
    }

    /// The look-ahead for the rate holds RATE_WINDOW_STEPS + 1 rows and no more; the
    /// estimate ignores what comes after (as it always did).
    #[test]
    fn rate_estimate_uses_the_first_window_only() {
        let n = RATE_WINDOW_STEPS + 50_000;
        let rows: Vec<Row> = (0..n)
            .map(|i| {
                // 100 Hz for the window, then 50 Hz.
                let time_s = if i <= RATE_WINDOW_STEPS {
                    i as f64 * 0.01
                } else {
                    RATE_WINDOW_STEPS as f64 * 0.01 + (i - RATE_WINDOW_STEPS) as f64 * 0.02
                };
                Row {
                    line: i as u64 + 2,
                    time_s,
                    rate_dps: Some(0.5),
                    reference_deg: None,
                    temperature_c: None,
                }
            })
            .collect();
        let log = Log {
            path: "window.csv".into(),
            rows,
            ..Log::default()
        };
        let options = GridOptions::default();
        let streamed = regularize(&log, &options).unwrap();
        assert_eq!(streamed.quality.sample_rate_source, "single_steps");
        assert!((streamed.sample_rate_hz - 100.0).abs() < 1e-6);
        assert_eq!(streamed.quality.gaps, 50_000 - 1);
        assert_eq!(
            outcome(Ok(streamed)),
            outcome(whole::regularize_whole(&log, &options))
        );
    }

    /// A log of `n` rows `step_s` apart, with the rate in the metadata if given.
    fn steady_log(n: usize, step_s: f64, metadata_rate: Option<&str>) -> Log {
        let mut metadata = BTreeMap::new();
        if let Some(rate) = metadata_rate {
            metadata.insert("sample_rate_hz".to_string(), rate.to_string());
        }
        Log {
            path: "steady.csv".into(),
            metadata,
            rows: (0..n)
                .map(|i| Row {
                    line: i as u64 + 2,
                    time_s: i as f64 * step_s,
                    rate_dps: Some(0.5),
                    reference_deg: None,
                    temperature_c: None,
                })
                .collect(),
            ..Log::default()
        }
    }

    /// A given rate more than twice or under half the stamps' is refused; more than 1% off,
    /// accepted with a warning; within 1%, silently.
    #[test]
    fn given_rates_are_refused_beyond_a_factor_two_and_warned_beyond_one_percent() {
        let log = steady_log(100, 0.001, None);
        let at = |rate: f64| {
            let options = GridOptions {
                sample_rate_hz: Some(rate),
                ..GridOptions::default()
            };
            regularize(&log, &options)
        };
        for rate in [100.0, 499.0, 2001.0, 1e9] {
            let err = at(rate).unwrap_err().to_string();
            assert!(err.contains("time stamps say 1000"), "{rate}: {err}");
        }
        for rate in [600.0, 980.0, 1900.0] {
            let warnings = at(rate).unwrap().quality.warnings;
            assert_eq!(warnings.len(), 1, "{rate}");
            assert!(
                warnings[0].contains("time stamps say 1000.000 Hz"),
                "{warnings:?}"
            );
        }
        assert!(at(1005.0).unwrap().quality.warnings.is_empty());
        // From the metadata, the same rule.
        let err = regularize(
            &steady_log(100, 0.001, Some("1e9")),
            &GridOptions::default(),
        )
        .unwrap_err()
        .to_string();
        assert!(
            err.contains("sample_rate_hz metadata gives 1000000000 Hz"),
            "{err}"
        );
    }

    /// With fewer steps than the median needs, a rate more than twice the fastest step's is
    /// still refused (every step would be a gap of up to a million slots).
    #[test]
    fn a_rate_far_above_a_few_steps_is_refused() {
        let log = steady_log(10, 0.001, Some("1e9"));
        let err = regularize(&log, &GridOptions::default())
            .unwrap_err()
            .to_string();
        assert!(err.contains("time stamps say 1000"), "{err}");
        assert!(regularize(
            &steady_log(10, 0.001, Some("1500")),
            &GridOptions::default()
        )
        .is_ok());
    }

    /// A grid on which bridging one gap would hold more than MAX_BRIDGED_SLOTS slots is
    /// refused before any slot is made, with the number and the memory.
    #[test]
    fn a_grid_bridging_too_many_slots_is_refused_up_front() {
        let log = steady_log(100, 0.001, Some("1000"));
        let options = GridOptions {
            max_gap_s: 1e6,
            ..GridOptions::default()
        };
        let err = regularize(&log, &options).unwrap_err().to_string();
        assert!(
            err.contains("bridging gaps of up to 1000000 s at 1000 Hz would hold 1000000000 samples (59.6 GiB), more than the limit of 16777216 (1.0 GiB)"),
            "{err}"
        );
        let options = GridOptions {
            max_gap_s: 3600.0,
            ..GridOptions::default()
        };
        assert!(regularize(&log, &options).is_ok());
    }

    /// A 100 Hz sensor turning 90° in one second (a raised cosine) over a link that
    /// delivers rows up to `wait_s` late, at least `spacing_s` apart; `stall` is a span of
    /// sample times whose rows wait for its end (a stalled link, then its backlog) or are
    /// lost.
    fn linked_turn(stall: Option<(f64, f64)>, lost: bool, wait_s: f64, spacing_s: f64) -> Log {
        let mut state: u64 = 7;
        let mut previous = f64::NEG_INFINITY;
        let mut rows = Vec::new();
        for k in 0..400_u32 {
            let t = f64::from(k) * 0.01;
            let rate = if (1.5..2.5).contains(&t) {
                90.0 * (1.0 - (2.0 * std::f64::consts::PI * (t - 1.5)).cos())
            } else {
                0.0
            };
            state = state
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            let mut arrival_s = t + (state >> 40) as f64 / f64::from(1_u32 << 24) * wait_s;
            if let Some((from, to)) = stall {
                if (from..to).contains(&t) {
                    if lost {
                        continue;
                    }
                    arrival_s = to;
                }
            }
            previous = arrival_s.max(previous + spacing_s);
            rows.push(Row {
                line: u64::from(k) + 2,
                time_s: previous,
                rate_dps: Some(rate),
                reference_deg: None,
                temperature_c: None,
            });
        }
        Log {
            path: "link.csv".into(),
            rows,
            ..Log::default()
        }
    }

    fn turn_deg(log: &RegularLog) -> f64 {
        log.slots[1..].iter().map(|s| s.rate_dps).sum::<f64>() / log.sample_rate_hz
    }

    /// A stalled link's backlog is spread over the stall, not counted twice; lost samples
    /// are bridged (filled), not re-timed; both as the whole-log passes do.
    #[test]
    fn a_backlog_after_a_stall_is_re_timed() {
        let options = GridOptions::default();
        let link = |stall, lost| linked_turn(stall, lost, 0.015, 0.0025);
        let clean = regularize(&link(None, false), &options).unwrap();
        assert!(clean.quality.bursts.is_some());
        assert_eq!(clean.quality.backlogs, 0);
        assert!(
            (turn_deg(&clean) - 90.0).abs() < 1.0,
            "{}",
            turn_deg(&clean)
        );
        // 0.2 s around the peak rate (about 35° of the turn) arrive at its end.
        let stalled = link(Some((1.8, 2.0)), false);
        let placed = regularize(&stalled, &options).unwrap();
        let q = &placed.quality;
        assert_eq!(q.backlogs, 1, "{q:?}");
        assert!(q.retimed_rows >= 20, "{q:?}");
        assert_eq!(q.filled_slots, 0, "{q:?}");
        assert!(
            (turn_deg(&placed) - 90.0).abs() < 1.0,
            "{}",
            turn_deg(&placed)
        );
        let oracle = whole::regularize_whole(&stalled, &options);
        same_outcome(Ok(placed), oracle).unwrap();
        // The same samples lost: no backlog; the gap is bridged and said.
        let holed = link(Some((1.8, 2.0)), true);
        let placed = regularize(&holed, &options).unwrap();
        assert_eq!(placed.quality.backlogs, 0);
        assert!(placed.quality.filled_slots >= 15, "{:?}", placed.quality);
        same_outcome(Ok(placed), whole::regularize_whole(&holed, &options)).unwrap();
    }

    /// A regular logger (rows 0-0.5 ms late: one per period) whose PC stalls for 0.2 s
    /// and then reads the buffered rows 0.2 ms apart: without re-timing, the stall is
    /// bridged as a gap and its rows placed after it (a 90° turn read as 122°).
    #[test]
    fn a_regular_logger_s_stall_is_re_timed_too() {
        let options = GridOptions::default();
        let stalled = linked_turn(Some((1.8, 2.0)), false, 0.0005, 0.0002);
        let placed = regularize(&stalled, &options).unwrap();
        let q = &placed.quality;
        assert!(q.bursts.is_none(), "{q:?}");
        assert_eq!((q.backlogs, q.gaps, q.filled_slots), (1, 0, 0), "{q:?}");
        assert_eq!(placed.slots.len(), 400, "one slot per sample");
        assert!(
            (turn_deg(&placed) - 90.0).abs() < 0.5,
            "{}",
            turn_deg(&placed)
        );
        same_outcome(Ok(placed), whole::regularize_whole(&stalled, &options)).unwrap();
        // Lost instead: a gap, filled, and no backlog.
        let holed = linked_turn(Some((1.8, 2.0)), true, 0.0005, 0.0002);
        let placed = regularize(&holed, &options).unwrap();
        assert_eq!((placed.quality.backlogs, placed.quality.gaps), (0, 1));
        same_outcome(Ok(placed), whole::regularize_whole(&holed, &options)).unwrap();
    }

    /// A 104 Hz sensor (9.6 ms) stamped to the millisecond steps 9 and 10 ms, the median
    /// 10 ms: the grid takes the mean of the single-period steps, so a row per slot keeps
    /// time (a 100 Hz grid would stretch every angle by 4%).
    #[test]
    fn the_grid_rate_is_the_mean_of_single_steps_not_the_median() {
        let period_s = 1.0 / 104.0;
        let rows: Vec<Row> = (0..2000_u32)
            .map(|k| Row {
                line: u64::from(k) + 2,
                time_s: (f64::from(k) * period_s * 1000.0).floor() / 1000.0,
                rate_dps: Some(10.0),
                reference_deg: None,
                temperature_c: None,
            })
            .collect();
        let log = Log {
            path: "ms.csv".into(),
            rows,
            ..Log::default()
        };
        let placed = regularize(&log, &GridOptions::default()).unwrap();
        assert_eq!(placed.quality.sample_rate_source, "single_steps");
        assert!(
            (placed.sample_rate_hz - 104.0).abs() < 0.1,
            "{}",
            placed.sample_rate_hz
        );
        assert_eq!(placed.slots.len(), 2000);
        // 10 °/s for the rows' span: the angle the stamps say.
        let span_s = log.rows[1999].time_s - log.rows[0].time_s;
        let angle_deg = turn_deg(&placed);
        assert!(
            (angle_deg - 10.0 * span_s).abs() < 0.01 * angle_deg,
            "{angle_deg}"
        );
        same_outcome(
            Ok(placed),
            whole::regularize_whole(&log, &GridOptions::default()),
        )
        .unwrap();
        // With a lost sample now and then (a step of two periods), the same.
        let mut holed = log.clone();
        holed.rows.retain(|r| r.line % 50 != 0);
        let placed = regularize(&holed, &GridOptions::default()).unwrap();
        assert!(
            (placed.sample_rate_hz - 104.0).abs() < 0.1,
            "{}",
            placed.sample_rate_hz
        );
        // 416 Hz to the millisecond: steps of 2 and 3 ms, median 2 ms; no slot filled.
        let mut fast = log.clone();
        for (k, row) in fast.rows.iter_mut().enumerate() {
            row.time_s = (k as f64 / 416.0 * 1000.0).floor() / 1000.0;
        }
        let placed = regularize(&fast, &GridOptions::default()).unwrap();
        assert!(
            (placed.sample_rate_hz - 416.0).abs() < 0.5,
            "{}",
            placed.sample_rate_hz
        );
        assert_eq!(placed.quality.filled_slots, 0, "{:?}", placed.quality);
        same_outcome(
            Ok(placed),
            whole::regularize_whole(&fast, &GridOptions::default()),
        )
        .unwrap();
    }
}
