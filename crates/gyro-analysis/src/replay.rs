//! Replay a regular log through the core [`Pipeline`] and score it against the reference.
//!
//! The reference angle goes through the same decimator and low-pass as the rate (both
//! linear, so filtering the angle equals integrating the filtered rate): the comparison
//! measures sensor and integration error, not the filter's intended lag. Both start at 0.
//!
//! Samples go through the core exactly as on the wrench: with their temperature
//! ([`Pipeline::push_with_temperature`]) when the log has one, so that the configured
//! [`gyro_core::Correction`] applies in full. A known latency of the gyro behind the
//! reference ([`ReplayOptions::reference_delay_s`], the model file's `reference_delay_s`)
//! is a matter of scoring only: the reference is shifted by it before the comparison.

use crate::lag::{LagMeter, LagTrendMeter};
use crate::model::ModelFile;
use gyro_core::{
    decide, Compensation, Config, Decimator, Event, MotionState, Pipeline, Sos, SosState,
    Tightening, Verdict,
};
use gyro_log::{GridOptions, LogError, LogOptions, Quality, RegularLog, Slot, SlotSink};
use serde::Serialize;
use std::collections::VecDeque;
use std::path::{Path, PathBuf};

mod offline;
use crate::bias_path::BiasPath;
pub mod settings;

pub use settings::{Resolved, RunSettings, SettingsError};

/// How a replay estimates each movement's angle.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Mode {
    /// As the wrench does: each movement at its end, from the rests before it.
    #[default]
    Causal,
    /// For a log analysed after the fact: each movement's bias from the rests of the whole
    /// log on both sides, read in a first pass ([`crate::bias_path`]).
    Offline,
}

impl Mode {
    /// The causal mode (left out of the JSON, which then reads as before the mode existed).
    pub fn is_causal(&self) -> bool {
        *self == Mode::Causal
    }
}

/// One output sample of the run, with the reference where present.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct SeriesPoint {
    /// Time (s).
    pub time_s: f64,
    /// Filtered rate (deg/s).
    pub rate_dps: f32,
    /// Motion state.
    pub motion: MotionState,
    /// Compensated angle (deg).
    pub angle_deg: f32,
    /// Uncompensated angle (deg).
    pub raw_angle_deg: f32,
    /// Standard deviation of the angle (deg), Kalman mode.
    pub angle_std_deg: Option<f32>,
    /// Bias estimate (deg/s).
    pub bias_dps: f32,
    /// Reference angle change since the start, filtered like the rate (deg).
    pub reference_deg: Option<f64>,
}

impl SeriesPoint {
    /// Compensated angle minus reference (deg).
    pub fn error_deg(&self) -> Option<f64> {
        self.reference_deg.map(|r| f64::from(self.angle_deg) - r)
    }
}

/// One movement found in the run.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct MovementResult {
    /// 1-based number.
    pub index: usize,
    /// Start (s).
    pub start_time_s: f64,
    /// End (s), or the last sample's time if the log ends while moving.
    pub end_time_s: f64,
    /// Duration (s).
    pub duration_s: f64,
    /// False if the log ended during the movement.
    pub complete: bool,
    /// Angle turned, compensated (deg).
    pub angle_deg: f32,
    /// Angle turned, uncompensated (deg).
    pub raw_angle_deg: f32,
    /// Reference angle change over the movement (deg).
    pub reference_deg: Option<f64>,
    /// `angle_deg − reference_deg`.
    pub error_deg: Option<f64>,
    /// `raw_angle_deg − reference_deg`.
    pub raw_error_deg: Option<f64>,
    /// A reading reached the sensor's range or a clip plateau during the movement (the
    /// core's [`gyro_core::Movement::saturated`]): the angle is a lower bound.
    pub saturated: bool,
    /// Input samples interpolated during the movement (a gap in the log, or missing
    /// rates): the rotation across them is a guess.
    pub filled_samples: u32,
    /// Standard deviation of `angle_deg` (deg), in Kalman mode
    /// ([`gyro_core::Movement::angle_std_deg`]); for a movement the log ends in, as if it
    /// ended there ([`gyro_core::Pipeline::movement_std_deg`]).
    pub angle_std_deg: Option<f32>,
    /// The tightening decision ([`gyro_core::decide`]) when the configuration has a window;
    /// absent without one, or for a turn the other way (not a tightening). `invalid` when
    /// the movement saturated, was cut off by the end of the log, or has filled samples.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub verdict: Option<Verdict>,
    /// The output samples (0-based output indices, into [`RunReport::series`] when it is
    /// kept) that bound the movement, as the core published them: its last quiet sample
    /// before and first quiet sample after (the last sample if the log ends while moving).
    /// Not in the JSON.
    #[serde(skip)]
    pub samples: (usize, usize),
}

/// Error statistics over the run.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct Summary {
    /// Compensation used.
    pub compensation: Compensation,
    /// Output samples.
    pub outputs: usize,
    /// Duration covered (s).
    pub duration_s: f64,
    /// Movements (complete or not).
    pub movements: usize,
    /// Input samples the pipeline rejected (non-finite or implausible).
    pub rejected_samples: u32,
    /// Final compensated angle (deg).
    pub final_angle_deg: f32,
    /// Final uncompensated angle (deg).
    pub final_raw_angle_deg: f32,
    /// Max |angle − reference| over the run (deg).
    pub max_abs_error_deg: Option<f64>,
    /// RMS of angle − reference (deg).
    pub rms_error_deg: Option<f64>,
    /// angle − reference at the last sample (deg).
    pub final_error_deg: Option<f64>,
    /// Max |raw angle − reference| (deg).
    pub raw_max_abs_error_deg: Option<f64>,
    /// RMS of raw angle − reference (deg).
    pub raw_rms_error_deg: Option<f64>,
    /// Raw angle − reference at the last sample (deg).
    pub raw_final_error_deg: Option<f64>,
    /// The gyro's lag behind the reference it was scored against (s; negative: it leads),
    /// from the output series' rates ([`crate::lag::LagMeter`]); `None` without a
    /// reference, without motion both show, or beyond ±[`crate::lag::SEARCH_S`].
    pub reference_lag_s: Option<f64>,
    /// The lag's change through the run, when block by block it follows a line
    /// ([`crate::lag::LagTrendMeter`]): a clock that runs off its nominal rate while the
    /// rows are stamped by the sample count. `None` without a reference, on runs shorter
    /// than a few blocks, or when the block lags do not trend.
    pub reference_lag_trend: Option<crate::lag::LagTrend>,
    /// The largest |rate| among the input samples the pipeline accepted (deg/s).
    pub largest_abs_rate_dps: f64,
    /// A reading went beyond the configured range ([`Pipeline::range_contradicted`]): it
    /// is not the sensor's, and from then on only clip plateaus flag a movement saturated.
    pub range_contradicted: bool,
}

/// How a replay is scored, beyond the pipeline's configuration.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct ReplayOptions {
    /// The gyro lags the reference by this much (s; negative: it leads). The angle at `t`
    /// is compared with the reference at `t − reference_delay_s`, interpolated linearly
    /// between grid slots; where that time falls outside the log (or next to a slot without
    /// reference) the sample has no reference. 0: the reference as logged.
    pub reference_delay_s: f64,
    /// The sensor's clock runs fast by this (ppm) in a log stamped by its sample count
    /// ([`ModelFile::count_clock_ppm`]): the reference is read at `t / (1 + ε)` (then less
    /// `reference_delay_s`), `t` from the log's first slot. 0: none.
    pub count_clock_ppm: f64,
}

impl ReplayOptions {
    /// The options a model file asks for.
    pub fn from_model(model: &ModelFile) -> Self {
        Self {
            reference_delay_s: model.reference_delay_s,
            count_clock_ppm: model.count_clock_ppm,
        }
    }

    /// Whether the reference is read at other times than logged.
    pub fn shifts_reference(&self) -> bool {
        let finite_nonzero = |x: f64| x.is_finite() && x != 0.0;
        finite_nonzero(self.reference_delay_s) || finite_nonzero(self.count_clock_ppm)
    }

    /// The reference's shift at slot `i` in grid slots at `sample_rate_hz` (positive: the
    /// reference is read that many slots earlier); a non-finite setting counts as none.
    fn shift_slots(&self, i: usize, sample_rate_hz: f64) -> f64 {
        let finite = |x: f64| if x.is_finite() { x } else { 0.0 };
        let eps = finite(self.count_clock_ppm) * 1e-6;
        finite(self.reference_delay_s) * sample_rate_hz + i as f64 * eps / (1.0 + eps)
    }
}

/// The result of replaying one log.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct RunReport {
    /// How the movements' angles were estimated; in the JSON only when offline.
    #[serde(skip_serializing_if = "Mode::is_causal")]
    pub mode: Mode,
    /// Input grid rate (Hz).
    pub sample_rate_hz: f64,
    /// Decimation factor.
    pub decimation_factor: u16,
    /// Output rate (Hz).
    pub output_rate_hz: f32,
    /// The configured output rate (Hz) when the log was slower and ran at its own rate
    /// ([`config_for_rate`]); `None` otherwise.
    pub output_rate_lowered_from_hz: Option<f32>,
    /// What was irregular in the input.
    pub input: Quality,
    /// The configuration used.
    pub config: Config,
    /// The gyro's delay behind the reference the scoring allowed for (s).
    pub reference_delay_s: f64,
    /// The temperature (°C) from which the correction measured ΔT: the configured
    /// reference, else the log's first valid temperature; `None` if there was neither (the
    /// correction's temperature terms were then not applied).
    pub temperature_reference_c: Option<f32>,
    /// Error statistics.
    pub summary: Summary,
    /// The movements.
    pub movements: Vec<MovementResult>,
    /// The output series (written by `--out`, not in JSON); empty when it went to a
    /// [`SeriesSink`] instead ([`replay_file_into`]).
    #[serde(skip)]
    pub series: Vec<SeriesPoint>,
}

/// Where the output series goes as it is made, so that a replay need not hold it.
pub trait SeriesSink {
    /// Outputs come at `output_rate_hz`: called once, before the first point.
    fn start(&mut self, _output_rate_hz: f32) {}
    /// The next output sample.
    fn point(&mut self, point: &SeriesPoint);
}

/// Keeps the whole series.
impl SeriesSink for Vec<SeriesPoint> {
    fn point(&mut self, point: &SeriesPoint) {
        self.push(*point);
    }
}

/// Drops the series: the report's movements and summary only.
impl SeriesSink for () {
    fn point(&mut self, _point: &SeriesPoint) {}
}

/// Max |e|, RMS and last value of a series of errors, one error at a time.
#[derive(Clone, Copy, Debug, Default)]
struct ErrorStats {
    max_abs: f64,
    sum_sq: f64,
    n: usize,
    last: Option<f64>,
}

impl ErrorStats {
    fn add(&mut self, e: f64) {
        self.max_abs = self.max_abs.max(e.abs());
        self.sum_sq += e * e;
        self.n += 1;
        self.last = Some(e);
    }

    /// Max |e|, RMS, last; all `None` without errors.
    fn get(&self) -> (Option<f64>, Option<f64>, Option<f64>) {
        if self.n == 0 {
            (None, None, None)
        } else {
            (
                Some(self.max_abs),
                Some((self.sum_sq / self.n as f64).sqrt()),
                self.last,
            )
        }
    }
}

/// Replay `log` through a pipeline configured by `config` (its sample rate replaced by the
/// log's), scoring against the reference as logged.
pub fn replay(log: &RegularLog, config: &Config) -> Result<RunReport, gyro_core::Error> {
    replay_with(log, config, &ReplayOptions::default())
}

/// Replay `log` through a pipeline configured by `config` (its sample rate replaced by the
/// log's), scoring as `options` say.
pub fn replay_with(
    log: &RegularLog,
    config: &Config,
    options: &ReplayOptions,
) -> Result<RunReport, gyro_core::Error> {
    replay_with_mode(log, config, options, Mode::Causal)
}

/// [`replay_with`] in `mode`.
pub fn replay_with_mode(
    log: &RegularLog,
    config: &Config,
    options: &ReplayOptions,
    mode: Mode,
) -> Result<RunReport, gyro_core::Error> {
    let replayer = || -> Result<Replayer, gyro_core::Error> {
        Ok(
            Replayer::new(log.sample_rate_hz, config, options, log.has_temperature)?
                .with_mode(mode),
        )
    };
    let mut replayer = match mode {
        Mode::Causal => replayer()?,
        // A first pass reads the bias through the whole log from its rests.
        Mode::Offline => {
            let mut first = replayer()?;
            replay_slots(&mut first, log, options, &mut ());
            match first.finish_bias_path() {
                Some(path) => replayer()?.with_bias_path(path),
                None => replayer()?,
            }
        }
    };
    let mut series = Vec::new();
    replay_slots(&mut replayer, log, options, &mut series);
    let mut report = replayer.finish_into(log.quality.clone(), &mut series);
    report.series = series;
    Ok(report)
}

/// Every slot of `log` through `replayer`, its outputs to `series`, the reference shifted
/// as `options` say.
fn replay_slots(
    replayer: &mut Replayer,
    log: &RegularLog,
    options: &ReplayOptions,
    series: &mut dyn SeriesSink,
) {
    if !options.shifts_reference() {
        for slot in &log.slots {
            if let Some(point) = replayer.push(slot) {
                replayer.emit(point, series);
            }
        }
    } else {
        // The reference at other slots, ahead or behind: the whole log is at hand.
        replayer.reference_origin = log.slots.iter().find_map(|s| s.reference_deg);
        for (i, slot) in log.slots.iter().enumerate() {
            let shift = options.shift_slots(i, log.sample_rate_hz);
            if let Some(point) = replayer.push_scored(slot, shifted_reference(&log.slots, i, shift))
            {
                replayer.emit(point, series);
            }
        }
    }
}

/// Why [`replay_file`] failed.
#[derive(Debug, thiserror::Error)]
pub enum ReplayFileError {
    /// The log cannot be read or placed on the grid.
    #[error(transparent)]
    Log(#[from] LogError),
    /// The pipeline cannot be configured for the log's sample rate.
    #[error(
        "{path}: cannot configure the pipeline for this log{}",
        rate_hint(*sample_rate_hz, *output_rate_hz)
    )]
    Config {
        /// The log.
        path: PathBuf,
        /// Why.
        #[source]
        cause: gyro_core::Error,
        /// The log's sample rate as placed (Hz).
        sample_rate_hz: f64,
        /// The configuration's output rate (Hz).
        output_rate_hz: f32,
    },
}

/// Slowest log (Hz) that runs at its own rate when it is slower than the configured
/// output rate. Below it, time stamps in ms read as seconds are likelier than so slow a
/// gyro (a 1 kHz log then reads 1 Hz, an 8 kHz one 8 Hz): refused, with that hint.
pub const MIN_OWN_RATE_HZ: f64 = 10.0;

/// `config` for a log at `sample_rate_hz` (its sample rate replaced). A log slower than
/// the output rate, and at least [`MIN_OWN_RATE_HZ`], runs at its own rate without
/// decimation, the low-pass cutoff scaled by the same factor (its share of the output
/// rate kept: 12.5 Hz of 50 becomes 6.25 Hz of 25); the configured output rate is
/// returned beside it, to be said in every output. Anything else is left to
/// [`Pipeline::try_new`] to accept or refuse.
pub fn config_for_rate(config: &Config, sample_rate_hz: f64) -> (Config, Option<f32>) {
    let mut placed = Config {
        sample_rate_hz: sample_rate_hz as f32,
        ..*config
    };
    let configured_hz = config.output_rate_hz;
    if sample_rate_hz.is_finite()
        && sample_rate_hz >= MIN_OWN_RATE_HZ
        && sample_rate_hz < f64::from(configured_hz)
    {
        let factor = placed.sample_rate_hz / configured_hz;
        placed.output_rate_hz = placed.sample_rate_hz;
        placed.filter.cutoff_hz = config.filter.cutoff_hz * factor;
        return (placed, Some(configured_hz));
    }
    (placed, None)
}

/// What [`config_for_rate`] did to a log at `sample_rate_hz` slower than the configured
/// `configured_hz`, its low-pass now at `cutoff_hz`: the words every output says it in.
pub fn lowered_rate_note(sample_rate_hz: f64, configured_hz: f32, cutoff_hz: f32) -> String {
    format!(
        "the log's {} Hz is below the configured output rate of {configured_hz} Hz: the pipeline runs at the log's rate without decimation, its low-pass at {cutoff_hz} Hz (the configured cutoff's share of the output rate)",
        (sample_rate_hz * 1e3).round() / 1e3
    )
}

/// Why a sample rate cannot be decimated to the output rate, when that is the reason: a
/// rate below it is most often stamps in ms read as seconds.
fn rate_hint(sample_rate_hz: f64, output_rate_hz: f32) -> String {
    if sample_rate_hz < f64::from(output_rate_hz) {
        format!(
            " (its stamps give {} Hz, below the output rate of {output_rate_hz} Hz and the {MIN_OWN_RATE_HZ} Hz a log runs at its own rate from: time stamps in ms read as seconds? --time-unit ms; else a model file's config.output_rate_hz at most the sample rate)",
            (sample_rate_hz * 1e3).round() / 1e3
        )
    } else {
        String::new()
    }
}

/// Read, place on the grid and replay a log: what [`gyro_log::load`] and [`replay_with`]
/// do, with the same result and the same errors, in one pass without holding the log
/// ([`replay_file_into`] keeping the series in the report).
pub fn replay_file(
    path: &Path,
    options: &LogOptions,
    grid: &GridOptions,
    config: &Config,
    replay_options: &ReplayOptions,
    warn: &mut dyn FnMut(&str),
) -> Result<RunReport, ReplayFileError> {
    let mut series = Vec::new();
    let mut report = replay_file_into(
        path,
        options,
        grid,
        config,
        replay_options,
        warn,
        &mut series,
    )?;
    report.series = series;
    Ok(report)
}

/// [`replay_file`] with the output series given to `series` as it is made instead of
/// kept: the report's series is empty. Memory does not grow with the log
/// ([`gyro_log::stream`]; the rate look-ahead, and at most [`Replayer::max_held_outputs`]
/// recent outputs), except when scoring against a reference shifted by a delay: that
/// needs the reference ahead, so the log is then loaded whole and replayed by
/// [`replay_with`] (its series still goes to `series`). MCAP warnings go to `warn` before
/// anything else is reported.
pub fn replay_file_into(
    path: &Path,
    options: &LogOptions,
    grid: &GridOptions,
    config: &Config,
    replay_options: &ReplayOptions,
    warn: &mut dyn FnMut(&str),
    series: &mut dyn SeriesSink,
) -> Result<RunReport, ReplayFileError> {
    replay_file_into_mode(
        path,
        options,
        grid,
        config,
        replay_options,
        Mode::Causal,
        warn,
        series,
    )
}

/// [`replay_file_into`] in `mode`. Offline, the file is read twice (the first pass reads
/// the bias through the log from its rests, [`crate::bias_path`]), and memory holds the
/// outputs from a movement's start to the next one's and three numbers per 0.2 s block of
/// rest, besides what the causal replay holds.
#[allow(clippy::too_many_arguments)]
pub fn replay_file_into_mode(
    path: &Path,
    options: &LogOptions,
    grid: &GridOptions,
    config: &Config,
    replay_options: &ReplayOptions,
    mode: Mode,
    warn: &mut dyn FnMut(&str),
    series: &mut dyn SeriesSink,
) -> Result<RunReport, ReplayFileError> {
    let config_error = |cause, sample_rate_hz| ReplayFileError::Config {
        path: path.to_path_buf(),
        cause,
        sample_rate_hz,
        output_rate_hz: config.output_rate_hz,
    };
    if replay_options.shifts_reference() {
        let regular = gyro_log::load(path, options, grid, warn)?;
        let mut report = replay_with_mode(&regular, config, replay_options, mode)
            .map_err(|cause| config_error(cause, regular.sample_rate_hz))?;
        series.start(report.output_rate_hz);
        for point in std::mem::take(&mut report.series) {
            series.point(&point);
        }
        return Ok(report);
    }
    // Offline, a first pass reads the bias through the whole log from its rests; the
    // second replays the log with it (the file is read twice, memory does not grow).
    let (bias_path, warn): (_, &mut dyn FnMut(&str)) = match mode {
        Mode::Causal => (None, warn),
        Mode::Offline => {
            let mut first = ReplaySink {
                config,
                options: replay_options,
                mode,
                has_temperature: false,
                replayer: None,
                bias_path: None,
                series: &mut (),
            };
            gyro_log::stream(path, options, grid, &mut first, warn)?;
            let bias_path = match first.replayer {
                Some(Ok(replayer)) => replayer.finish_bias_path(),
                _ => None,
            };
            (bias_path, &mut |_: &str| {})
        }
    };
    let mut sink = ReplaySink {
        config,
        options: replay_options,
        mode,
        has_temperature: false,
        replayer: None,
        bias_path,
        series,
    };
    let quality = gyro_log::stream(path, options, grid, &mut sink, warn)?;
    let sample_rate_hz = quality.sample_rate_hz;
    match sink.replayer {
        Some(Ok(replayer)) => Ok(replayer.finish_into(quality, sink.series)),
        Some(Err(cause)) => Err(config_error(cause, sample_rate_hz)),
        // `place` succeeded, so it gave the rate: not reached.
        None => Replayer::new(
            quality.sample_rate_hz,
            config,
            replay_options,
            sink.has_temperature,
        )
        .map(|replayer| {
            sink.series.start(replayer.output_rate_hz);
            replayer.finish(quality)
        })
        .map_err(|cause| config_error(cause, sample_rate_hz)),
    }
}

/// The sink of [`replay_file_into`]: a replayer built once the rate is known. If the
/// pipeline cannot be configured, the error waits until the log has been read (its errors
/// first).
struct ReplaySink<'c> {
    config: &'c Config,
    options: &'c ReplayOptions,
    mode: Mode,
    has_temperature: bool,
    replayer: Option<Result<Replayer, gyro_core::Error>>,
    /// Offline: the bias through the log from a first pass.
    bias_path: Option<BiasPath>,
    series: &'c mut dyn SeriesSink,
}

impl SlotSink for ReplaySink<'_> {
    fn columns(&mut self, _has_reference: bool, has_temperature: bool) {
        self.has_temperature = has_temperature;
    }

    fn start(&mut self, sample_rate_hz: f64) {
        let mode = self.mode;
        let replayer = Replayer::new(
            sample_rate_hz,
            self.config,
            self.options,
            self.has_temperature,
        )
        .map(|r| {
            let r = r.with_mode(mode);
            match self.bias_path.take() {
                Some(path) => r.with_bias_path(path),
                None => r,
            }
        });
        if let Ok(replayer) = &replayer {
            self.series.start(replayer.output_rate_hz);
        }
        self.replayer = Some(replayer);
    }

    fn slot(&mut self, slot: &Slot) {
        if let Some(Ok(replayer)) = &mut self.replayer {
            if let Some(point) = replayer.push(slot) {
                replayer.emit(point, self.series);
            }
        }
    }
}

/// Replays slots one at a time: the state of [`replay_with`] between two slots. Holds
/// neither the input nor the output series: each output goes back to the caller
/// ([`Replayer::push`]), and only the last [`Replayer::max_held_outputs`] outputs are kept,
/// for the movements' ends.
pub struct Replayer {
    sample_rate_hz: f64,
    config: Config,
    /// The configured output rate, when the log runs at its own ([`config_for_rate`]).
    output_rate_lowered_from_hz: Option<f32>,
    reference_delay_s: f64,
    /// The log has a temperature column: every sample goes in with its temperature.
    has_temperature: bool,
    pipeline: Pipeline,
    factor: u16,
    output_rate_hz: f32,
    // The reference path: same decimation and low-pass, on the angle relative to its start.
    reference_origin: Option<f64>,
    ref_decimator: Decimator,
    ref_sos: Sos,
    ref_state: SosState,
    ref_last: f32,
    ref_block_complete: bool,
    /// What the reference's low-pass gives at the first output
    /// ([`Replayer::start_reference`]): subtracted from every filtered reference.
    ref_start: f32,
    /// The reference's low-pass has been started ([`Replayer::start_reference`]).
    ref_started: bool,
    /// The largest plausible |rate| so far (deg/s).
    largest_abs_rate_dps: f64,
    /// The latest outputs, oldest first: `held[0]` is output number `outputs - held.len()`.
    held: VecDeque<Held>,
    /// How many outputs `held` keeps at most.
    max_held: usize,
    /// Outputs so far.
    outputs: usize,
    first_time_s: Option<f64>,
    errors: ErrorStats,
    raw_errors: ErrorStats,
    lag: LagMeter,
    lag_trend: LagTrendMeter,
    movements: Vec<MovementResult>,
    open: Option<OpenMovement>,
    /// Filled input slots (gaps, missing rates) so far.
    filled_total: u32,
    /// Causal, or offline with its smoother.
    mode: Mode,
    smoother: offline::Smoother,
    /// The last smoothed output (offline).
    last_smoothed: Option<SeriesPoint>,
}

/// What the replay keeps of a recent output: what a movement's ends read.
#[derive(Clone, Copy, Debug)]
struct Held {
    time_s: f64,
    angle_deg: f32,
    raw_angle_deg: f32,
    reference_deg: Option<f64>,
    /// Filled input slots before this output, counted up to the slot that completed it.
    filled_before: u32,
}

/// A movement the core confirmed and has not ended yet.
#[derive(Clone, Copy, Debug)]
struct OpenMovement {
    start_time_s: f64,
    start_index: usize,
    /// The output at `start_index`.
    start: Option<Held>,
    /// The reference at the output nearest `start_time_s` ([`Replayer::nearest`]), once an
    /// output at or after that time has come (until then the latest output is the nearest).
    reference_at_start: Option<Option<f64>>,
}

impl Replayer {
    /// A replayer for slots at `sample_rate_hz`, with a pipeline configured by `config`
    /// (its sample rate replaced); `options.reference_delay_s` is reported (the shift
    /// itself is [`replay_with`]'s); `has_temperature`: the log has a temperature column.
    pub fn new(
        sample_rate_hz: f64,
        config: &Config,
        options: &ReplayOptions,
        has_temperature: bool,
    ) -> Result<Self, gyro_core::Error> {
        let (config, output_rate_lowered_from_hz) = config_for_rate(config, sample_rate_hz);
        let pipeline = Pipeline::try_new(&config)?;
        let factor = config.decimation_factor()?;
        let output_rate_hz = config.effective_output_rate_hz()?;
        let ref_decimator = Decimator::try_new(factor)?;
        let ref_sos: Sos = config.filter.sos(output_rate_hz.into())?;
        // A movement's end names an output at most a confirming run (a `u16` of outputs in
        // the core) plus the filter delay before the output that reports it; two more for
        // the neighbour `nearest` compares with and rounding.
        let delay_outputs = pipeline.filter_delay_s() * f64::from(output_rate_hz);
        let delay_outputs = if delay_outputs.is_finite() && delay_outputs > 0.0 {
            delay_outputs.ceil().min(1e6) as usize
        } else {
            0
        };
        let max_held = usize::from(u16::MAX) + delay_outputs + 4;
        Ok(Self {
            sample_rate_hz,
            config,
            output_rate_lowered_from_hz,
            reference_delay_s: options.reference_delay_s,
            has_temperature,
            pipeline,
            factor,
            output_rate_hz,
            reference_origin: None,
            ref_decimator,
            ref_sos,
            ref_state: SosState::new(),
            ref_last: 0.0,
            ref_block_complete: true,
            ref_start: 0.0,
            ref_started: false,
            largest_abs_rate_dps: 0.0,
            held: VecDeque::new(),
            max_held,
            outputs: 0,
            first_time_s: None,
            errors: ErrorStats::default(),
            raw_errors: ErrorStats::default(),
            lag: LagMeter::new(1.0 / f64::from(output_rate_hz)),
            lag_trend: LagTrendMeter::new(1.0 / f64::from(output_rate_hz)),
            movements: Vec::new(),
            open: None,
            filled_total: 0,
            mode: Mode::Causal,
            smoother: offline::Smoother::default(),
            last_smoothed: None,
        })
    }

    /// The replayer in `mode`.
    pub fn with_mode(self, mode: Mode) -> Self {
        let smoother = offline::Smoother::new(
            1.0 / f64::from(self.output_rate_hz),
            f64::from(self.config.kalman.rate_noise_dps),
        );
        Self {
            mode,
            smoother,
            ..self
        }
    }

    /// Give `point`, an output of [`Replayer::push`], to `series`: as it is when causal;
    /// offline, the smoothed outputs it has made ready instead, scored as they go.
    pub fn emit(&mut self, point: SeriesPoint, series: &mut dyn SeriesSink) {
        match self.mode {
            Mode::Causal => series.point(&point),
            Mode::Offline => self.emit_smoothed(series),
        }
    }

    /// Offline, each movement's bias from `path`, the bias through the whole log that a first
    /// pass gave ([`Replayer::finish_bias_path`]), in place of the causal filter's.
    pub fn with_bias_path(mut self, path: BiasPath) -> Self {
        if self.mode == Mode::Offline && self.config.compensation == gyro_core::Compensation::Kalman
        {
            self.smoother = std::mem::take(&mut self.smoother).with_path(path);
        }
        self
    }

    /// The end of a first offline pass: the bias through the log smoothed from its rests
    /// ([`offline::Smoother::bias_path`]); `None` when causal or without a rest.
    pub fn finish_bias_path(mut self) -> Option<BiasPath> {
        if self.mode != Mode::Offline {
            return None;
        }
        // Its rests are what counts: the movements' angles of this pass are not reported.
        self.smoother.finish();
        self.smoother.bias_path()
    }

    /// Score the smoothed outputs made ready and give them to `series`.
    fn emit_smoothed(&mut self, series: &mut dyn SeriesSink) {
        let ready: Vec<SeriesPoint> = self.smoother.take_ready().collect();
        for point in ready {
            if let Some(e) = point.error_deg() {
                self.errors.add(e);
            }
            series.point(&point);
            self.last_smoothed = Some(point);
        }
    }

    /// The movements ended so far, in order (causal angles).
    pub fn movements(&self) -> &[MovementResult] {
        &self.movements
    }

    /// The start (s) of the movement under way, if one is.
    pub fn moving_since_s(&self) -> Option<f64> {
        self.open.map(|o| o.start_time_s)
    }

    /// The most outputs the offline smoother has held at once (0 when causal).
    pub fn most_smoothed_held(&self) -> usize {
        self.smoother.most_held()
    }

    /// Put a movement's offline angle and σ in its result.
    fn apply(&mut self, smoothed: Option<offline::Smoothed>) {
        let Some(smoothed) = smoothed else { return };
        let tightening = self.config.tightening;
        let Some(m) = self.movements.get_mut(smoothed.movement) else {
            return;
        };
        m.angle_deg = smoothed.angle_deg;
        m.angle_std_deg = smoothed.angle_std_deg;
        m.error_deg = m.reference_deg.map(|r| f64::from(m.angle_deg) - r);
        let untrusted = m.saturated || !m.complete || m.filled_samples > 0;
        m.verdict = tightening.as_ref().and_then(|window| {
            decide(
                window,
                m.angle_deg,
                m.angle_std_deg.unwrap_or(0.0),
                untrusted,
            )
        });
    }

    /// The output rate (Hz).
    pub fn output_rate_hz(&self) -> f32 {
        self.output_rate_hz
    }

    /// How many recent outputs the replayer holds at most, whatever the log's length.
    pub fn max_held_outputs(&self) -> usize {
        self.max_held
    }

    /// How many recent outputs it holds now.
    pub fn held_outputs(&self) -> usize {
        self.held.len()
    }

    /// One slot of the grid, scored against its own reference; the output sample it
    /// completed, if any.
    ///
    /// The reference origin is the first reference value. Until it comes, every block is
    /// incomplete (no reference) and the reference filter sees zeros: running it then is
    /// the same as not running it when the log has no reference at all.
    pub fn push(&mut self, slot: &Slot) -> Option<SeriesPoint> {
        if self.reference_origin.is_none() {
            self.reference_origin = slot.reference_deg;
        }
        self.push_scored(slot, slot.reference_deg)
    }

    /// Start the reference's low-pass at the first output whose block holds a reference
    /// throughout (its mean `mean`), as the pipeline starts its own: settled, as if the
    /// motion had gone on before as it is then. The pipeline's filter is settled on its
    /// first rate, so its angle counts the motion from a filter delay before the first
    /// output; the reference's filter is settled on the ramp of the pipeline's rate
    /// `rate_dps` there, and takes the pipeline's angle `angle_deg` there (0 at the first
    /// output): the error is counted from that output on. A log that starts in motion is
    /// then scored from the same instant on both paths; settled on a constant, the
    /// reference would carry the start's rate times the filter delay as an error over the
    /// whole log (2.85° at 300 °/s on a 1 kHz log).
    fn start_reference(&mut self, mean: f32, rate_dps: f32, angle_deg: f32) {
        /// Output steps the ramp is run for: the low-pass has forgotten its settled start
        /// long before (its poles decay within a few output steps).
        const RAMP_STEPS: u16 = 64;
        let step = if rate_dps.is_finite() {
            rate_dps / self.output_rate_hz
        } else {
            0.0
        };
        self.ref_sos
            .settle(&mut self.ref_state, mean - step * f32::from(RAMP_STEPS));
        for k in (1..RAMP_STEPS).rev() {
            self.ref_sos
                .process(&mut self.ref_state, mean - step * f32::from(k));
        }
        let mut probe = self.ref_state;
        self.ref_start = self.ref_sos.process(&mut probe, mean) - angle_deg;
        self.ref_started = true;
    }

    /// One slot, scored against `reference` (deg; the origin is set).
    fn push_scored(&mut self, slot: &Slot, reference: Option<f64>) -> Option<SeriesPoint> {
        let ref_mean = self.decimate_reference(reference);
        self.count_input(slot);
        let out = self.run_pipeline(slot)?;
        let reference_deg = self.filter_reference(ref_mean, out.rate_dps, out.angle_deg);
        let point = SeriesPoint {
            time_s: out.time_s,
            rate_dps: out.rate_dps,
            motion: out.motion,
            angle_deg: out.angle_deg,
            raw_angle_deg: out.raw_angle_deg,
            angle_std_deg: out.angle_std_deg,
            bias_dps: out.bias_dps,
            reference_deg,
        };
        self.hold(&point);
        if self.mode == Mode::Offline {
            self.smoother.push(point);
        }
        match out.event {
            Some(Event::MovementStarted {
                start_time_s,
                start_index,
            }) => self.movement_started(&point, start_time_s, start_index as usize),
            Some(Event::MovementEnded(m)) => self.movement_ended(&m),
            None => {}
        }
        Some(point)
    }

    /// The slot's `reference` (deg) relative to the origin into the reference's block
    /// decimator (the last one again when absent, the block then incomplete); the block's
    /// mean when the slot completes a block.
    fn decimate_reference(&mut self, reference: Option<f64>) -> Option<f32> {
        let reference = match (reference, self.reference_origin) {
            (Some(r), Some(origin)) => {
                self.ref_last = (r - origin) as f32;
                Some(self.ref_last)
            }
            _ => {
                self.ref_block_complete = false;
                None
            }
        };
        self.ref_decimator.push(reference.unwrap_or(self.ref_last))
    }

    /// Counts the slot into the largest plausible |rate| and the filled samples.
    fn count_input(&mut self, slot: &Slot) {
        let magnitude = slot.rate_dps.abs();
        // NaN fails the test: an implausible reading is the pipeline's to reject.
        if magnitude <= f64::from(self.config.max_abs_rate_dps) {
            self.largest_abs_rate_dps = self.largest_abs_rate_dps.max(magnitude);
        }
        self.filled_total = self.filled_total.saturating_add(u32::from(slot.filled));
    }

    /// The slot into the pipeline, with its temperature when the log has them; the output
    /// sample it completed, if any.
    fn run_pipeline(&mut self, slot: &Slot) -> Option<gyro_core::Output> {
        // A slot without temperature in a log that has them (a filled gap) keeps the last
        // valid temperature: NaN tells the pipeline so.
        if self.has_temperature || slot.temperature_c.is_some() {
            let temperature_c = slot.temperature_c.map_or(f32::NAN, |t| t as f32);
            self.pipeline
                .push_with_temperature(slot.time_s, slot.rate_dps as f32, temperature_c)
        } else {
            self.pipeline.push(slot.time_s, slot.rate_dps as f32)
        }
    }

    /// The low-passed reference angle (deg) at an output whose block's reference mean is
    /// `ref_mean`, started on the output's `rate_dps` and `angle_deg` at the first
    /// complete block ([`Self::start_reference`]); None while the block is incomplete.
    fn filter_reference(
        &mut self,
        ref_mean: Option<f32>,
        rate_dps: f32,
        angle_deg: f32,
    ) -> Option<f64> {
        match ref_mean {
            Some(mean) => {
                let complete = self.ref_block_complete;
                if !self.ref_started {
                    if complete {
                        self.start_reference(mean, rate_dps, angle_deg);
                    } else if self.outputs == 0 {
                        self.ref_sos.settle(&mut self.ref_state, mean);
                    }
                }
                let filtered = self.ref_sos.process(&mut self.ref_state, mean) - self.ref_start;
                self.ref_block_complete = true;
                complete.then_some(f64::from(filtered))
            }
            None => None,
        }
    }

    /// A movement started at `start_time_s` (output `start_index`): open it, with its
    /// reference when `point` has reached its time; offline, the smoother restarts there.
    fn movement_started(&mut self, point: &SeriesPoint, start_time_s: f64, start_index: usize) {
        let mut open = OpenMovement {
            start_time_s,
            start_index,
            start: self.held(start_index).copied(),
            reference_at_start: None,
        };
        if point.time_s >= start_time_s {
            open.reference_at_start = Some(self.reference_near(start_time_s));
        }
        self.open = Some(open);
        if self.mode == Mode::Offline {
            let smoothed = self.smoother.movement_started(start_index);
            self.apply(smoothed);
        }
    }

    /// The movement `m` ended: score it against the reference's change over it, with the
    /// samples filled within it.
    fn movement_ended(&mut self, m: &gyro_core::Movement) {
        let open = self.open.take();
        let samples = (m.start_index as usize, m.end_index as usize);
        // The core ends the movement it started: its start was read then.
        let (start_filled, start_reference) = match open {
            Some(open)
                if open.start_index == samples.0
                    && open.start_time_s.to_bits() == m.start_time_s.to_bits() =>
            {
                (
                    open.start.map_or(0, |h| h.filled_before),
                    open.reference_at_start
                        .unwrap_or_else(|| self.reference_near(open.start_time_s)),
                )
            }
            _ => (
                self.held(samples.0).map_or(0, |h| h.filled_before),
                self.reference_near(m.start_time_s),
            ),
        };
        let filled_samples = self.held(samples.1).map_or(0, |h| h.filled_before) - start_filled;
        let end_reference = self.reference_near(m.end_time_s);
        self.movements.push(movement_result(
            self.movements.len() + 1,
            (m.start_time_s, m.end_time_s),
            (m.angle_deg, m.raw_angle_deg),
            Flags {
                complete: true,
                saturated: m.saturated,
                filled_samples,
                angle_std_deg: m.angle_std_deg,
            },
            samples,
            reference_change(start_reference, end_reference),
            self.config.tightening.as_ref(),
        ));
        if self.mode == Mode::Offline {
            self.smoother
                .movement_ended(self.movements.len() - 1, samples.1);
        }
    }

    /// Count `point` into the summary and hold it (dropping the oldest held output past
    /// `max_held`); resolve the open movement's start once an output reaches its time.
    fn hold(&mut self, point: &SeriesPoint) {
        // Offline, the smoothed outputs are scored as they are made.
        if let (Some(e), Mode::Causal) = (point.error_deg(), self.mode) {
            self.errors.add(e);
        }
        if let Some(r) = point.reference_deg {
            self.raw_errors.add(f64::from(point.raw_angle_deg) - r);
        }
        self.lag
            .push(f64::from(point.rate_dps), point.reference_deg);
        self.lag_trend
            .push(point.time_s, f64::from(point.rate_dps), point.reference_deg);
        self.first_time_s.get_or_insert(point.time_s);
        if self.held.len() >= self.max_held {
            self.held.pop_front();
        }
        self.held.push_back(Held {
            time_s: point.time_s,
            angle_deg: point.angle_deg,
            raw_angle_deg: point.raw_angle_deg,
            reference_deg: point.reference_deg,
            filled_before: self.filled_total,
        });
        self.outputs += 1;
        if let Some(open) = self.open {
            if open.reference_at_start.is_none() && point.time_s >= open.start_time_s {
                let reference = self.reference_near(open.start_time_s);
                if let Some(open) = &mut self.open {
                    open.reference_at_start = Some(reference);
                }
            }
        }
    }

    /// Output number `index`, if held.
    fn held(&self, index: usize) -> Option<&Held> {
        let first = self.outputs - self.held.len();
        self.held.get(index.checked_sub(first)?)
    }

    /// The reference at the output nearest `time_s` ([`nearest`]).
    fn reference_near(&self, time_s: f64) -> Option<f64> {
        nearest(&self.held, self.outputs, time_s)?.reference_deg
    }

    /// The report, with `input` the quality of the grid the slots came from; its series is
    /// empty (the caller has had every point from [`Replayer::push`]).
    pub fn finish(self, input: Quality) -> RunReport {
        self.finish_into(input, &mut ())
    }

    /// [`Replayer::finish`], the outputs still held for smoothing (offline) given to
    /// `series` first.
    pub fn finish_into(mut self, input: Quality, series: &mut dyn SeriesSink) -> RunReport {
        if self.mode == Mode::Offline {
            let smoothed = self.smoother.finish();
            self.apply(smoothed);
            self.emit_smoothed(series);
        }
        let last = self.held.back().copied();
        let last_angle_deg = match (self.mode, self.last_smoothed) {
            (Mode::Offline, Some(p)) => Some(p.angle_deg),
            _ => last.map(|p| p.angle_deg),
        };
        let mut movements = self.movements;
        if let (Some(open), Some(last)) = (self.open, last) {
            let samples = (open.start_index, self.outputs - 1);
            // Unresolved: no output reached the start's time, the last is the nearest.
            let start_reference = open.reference_at_start.unwrap_or(last.reference_deg);
            let first = open.start.unwrap_or(last);
            let filled_samples = last.filled_before - open.start.map_or(0, |h| h.filled_before);
            movements.push(movement_result(
                movements.len() + 1,
                (open.start_time_s, last.time_s),
                (
                    last.angle_deg - first.angle_deg,
                    last.raw_angle_deg - first.raw_angle_deg,
                ),
                Flags {
                    complete: false,
                    saturated: self.pipeline.movement_saturated(),
                    filled_samples,
                    angle_std_deg: self.pipeline.movement_std_deg(),
                },
                samples,
                reference_change(start_reference, last.reference_deg),
                self.config.tightening.as_ref(),
            ));
        }

        let (max_abs, rms, final_e) = self.errors.get();
        let (raw_max_abs, raw_rms, raw_final) = self.raw_errors.get();
        let summary = Summary {
            compensation: self.config.compensation,
            outputs: self.outputs,
            duration_s: match (self.first_time_s, last) {
                (Some(a), Some(b)) => b.time_s - a,
                _ => 0.0,
            },
            movements: movements.len(),
            rejected_samples: self.pipeline.rejected_samples(),
            final_angle_deg: last_angle_deg.unwrap_or(0.0),
            final_raw_angle_deg: last.map_or(0.0, |p| p.raw_angle_deg),
            max_abs_error_deg: max_abs,
            rms_error_deg: rms,
            final_error_deg: final_e,
            raw_max_abs_error_deg: raw_max_abs,
            raw_rms_error_deg: raw_rms,
            raw_final_error_deg: raw_final,
            reference_lag_s: self.lag.lag_s(),
            reference_lag_trend: self.lag_trend.trend(),
            largest_abs_rate_dps: self.largest_abs_rate_dps,
            range_contradicted: self.pipeline.range_contradicted(),
        };
        RunReport {
            mode: self.mode,
            sample_rate_hz: self.sample_rate_hz,
            decimation_factor: self.factor,
            output_rate_hz: self.output_rate_hz,
            output_rate_lowered_from_hz: self.output_rate_lowered_from_hz,
            input,
            config: self.config,
            reference_delay_s: self.reference_delay_s,
            temperature_reference_c: self.pipeline.corrector().reference_c(),
            summary,
            movements,
            series: Vec::new(),
        }
    }
}

/// The reference angle at grid position `i − shift_slots`, linear between slots: `None`
/// outside the log or next to a slot without reference. A zero shift gives the slot's own
/// value, untouched.
fn shifted_reference(slots: &[Slot], i: usize, shift_slots: f64) -> Option<f64> {
    if shift_slots == 0.0 {
        return slots.get(i)?.reference_deg;
    }
    let position = i as f64 - shift_slots;
    if position.is_nan() || position < 0.0 {
        return None;
    }
    let below = position.floor();
    let fraction = position - below;
    // Saturating: a position past `usize::MAX` is simply outside the log.
    let below = below as usize;
    let a = slots.get(below)?.reference_deg?;
    if fraction == 0.0 {
        return Some(a);
    }
    let b = slots.get(below.checked_add(1)?)?.reference_deg?;
    Some(a + fraction * (b - a))
}

/// The output nearest to `time_s` among the held outputs (the last `held.len()` of
/// `outputs`, times rising): where the reference is read at a movement's time on the
/// input's time line (the filtered reference at the movement's own samples,
/// [`MovementResult::samples`], is a filter delay later: see [`gyro_core::Event`]). Before
/// the first output, the first; past the last, the last; between two, the nearer (the
/// earlier on a tie). `None` without outputs, or if the nearest may be one no longer held
/// (the replayer holds enough that the core's events never name one).
fn nearest(held: &VecDeque<Held>, outputs: usize, time_s: f64) -> Option<&Held> {
    let i = held.partition_point(|p| p.time_s < time_s);
    if i == 0 {
        return if held.len() == outputs {
            held.front()
        } else {
            None
        };
    }
    if i >= held.len() {
        return held.back();
    }
    if (held[i].time_s - time_s).abs() < (time_s - held[i - 1].time_s).abs() {
        held.get(i)
    } else {
        held.get(i - 1)
    }
}

/// The reference's change between two outputs.
fn reference_change(start: Option<f64>, end: Option<f64>) -> Option<f64> {
    Some(end? - start?)
}

/// What the core and the replay know about a movement besides its times and angles.
struct Flags {
    complete: bool,
    saturated: bool,
    filled_samples: u32,
    angle_std_deg: Option<f32>,
}

fn movement_result(
    index: usize,
    (start_time_s, end_time_s): (f64, f64),
    (angle_deg, raw_angle_deg): (f32, f32),
    flags: Flags,
    samples: (usize, usize),
    reference_deg: Option<f64>,
    tightening: Option<&Tightening>,
) -> MovementResult {
    let untrusted = flags.saturated || !flags.complete || flags.filled_samples > 0;
    MovementResult {
        index,
        start_time_s,
        end_time_s,
        duration_s: end_time_s - start_time_s,
        complete: flags.complete,
        angle_deg,
        raw_angle_deg,
        reference_deg,
        error_deg: reference_deg.map(|r| f64::from(angle_deg) - r),
        raw_error_deg: reference_deg.map(|r| f64::from(raw_angle_deg) - r),
        saturated: flags.saturated,
        filled_samples: flags.filled_samples,
        angle_std_deg: flags.angle_std_deg,
        verdict: tightening.and_then(|window| {
            decide(
                window,
                angle_deg,
                flags.angle_std_deg.unwrap_or(0.0),
                untrusted,
            )
        }),
        samples,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_log_slower_than_the_output_rate_runs_at_its_own() {
        let config = Config::default();
        let (placed, lowered) = config_for_rate(&config, 25.0);
        assert_eq!(lowered, Some(50.0));
        assert_eq!((placed.sample_rate_hz, placed.output_rate_hz), (25.0, 25.0));
        assert_eq!(placed.filter.cutoff_hz, 6.25);
        assert!(Pipeline::try_new(&placed).is_ok());
        // At or above the output rate, and below the floor, only the rate is placed.
        for rate in [50.0, 1000.0, 9.9, f64::NAN] {
            let (placed, lowered) = config_for_rate(&config, rate);
            assert_eq!(lowered, None, "{rate}");
            assert_eq!(placed.output_rate_hz, 50.0);
            assert_eq!(placed.filter.cutoff_hz, config.filter.cutoff_hz);
        }
        assert!(Pipeline::try_new(&config_for_rate(&config, 9.9).0).is_err());
    }

    fn slots(references: &[Option<f64>]) -> Vec<Slot> {
        references
            .iter()
            .enumerate()
            .map(|(i, &reference_deg)| Slot {
                time_s: i as f64 * 1e-3,
                rate_dps: 0.0,
                reference_deg,
                temperature_c: None,
                line: i as u64 + 2,
                filled: false,
            })
            .collect()
    }

    #[test]
    fn reference_shift_interpolates_on_the_grid() {
        let s = slots(&[Some(0.0), Some(1.0), Some(3.0), None, Some(10.0)]);
        // No shift: the slot's own value, missing ones included.
        assert_eq!(shifted_reference(&s, 2, 0.0), Some(3.0));
        assert_eq!(shifted_reference(&s, 3, 0.0), None);
        // The gyro lags by 1.5 slots: slot 2 is compared with position 0.5.
        assert_eq!(shifted_reference(&s, 2, 1.5), Some(0.5));
        assert_eq!(shifted_reference(&s, 2, 1.0), Some(1.0));
        // Before the log, past its end, or next to a missing reference: none.
        assert_eq!(shifted_reference(&s, 0, 0.25), None);
        assert_eq!(shifted_reference(&s, 4, -0.5), None);
        assert_eq!(shifted_reference(&s, 2, -0.5), None);
        assert_eq!(shifted_reference(&s, 4, 2.5), Some(2.0));
        // Leading: slot 0 is compared with position 1.25.
        assert_eq!(shifted_reference(&s, 0, -1.25), Some(1.5));
        assert_eq!(shifted_reference(&s, 0, f64::MAX), None);
        assert_eq!(shifted_reference(&s, 0, -f64::MAX), None);
        assert_eq!(shifted_reference(&s, 0, f64::NAN), None);
    }

    /// A log that starts in motion: 1 kHz at a steady 300 °/s from its first row, the
    /// reference exact, or 12 ms ahead of the gyro and scored with that delay.
    fn turning_log(lead_s: f64) -> RegularLog {
        gyro_log::RegularLog::with_reference(
            1000.0,
            (0..3000).map(|i| {
                let time_s = i as f64 * 1e-3;
                (time_s, 300.0, 25.0 + 300.0 * (time_s + lead_s))
            }),
        )
    }

    /// A count-stamped clock 1% fast on a steady turn: the scale it writes alone leaves
    /// an error growing through the run (the angle is the one at the gyro's own time);
    /// with `count_clock_ppm` the reference is read there and the error goes.
    #[test]
    fn a_count_stamped_clock_is_scored_at_the_gyros_own_time() {
        let ppm = 10_000.0;
        let mut config = Config::default();
        config.correction.scale_k = (ppm * 1e-6) as f32;
        let max_error = |options: &ReplayOptions| {
            replay_with(&turning_log(0.0), &config, options)
                .expect("replay")
                .summary
                .max_abs_error_deg
                .expect("scored")
        };
        let scale_only = max_error(&ReplayOptions::default());
        let both = max_error(&ReplayOptions {
            count_clock_ppm: ppm,
            ..ReplayOptions::default()
        });
        assert!(scale_only > 7.0, "{scale_only}");
        assert!(both < 0.05 * scale_only, "{both} against {scale_only}");
        // The shift in slots: the delay's, and the clock's growing with the slot.
        let options = ReplayOptions {
            reference_delay_s: 0.01,
            count_clock_ppm: ppm,
        };
        let shift = options.shift_slots(1000, 1000.0);
        assert!(
            (shift - (10.0 + 1000.0 * 0.01 / 1.01)).abs() < 1e-9,
            "{shift}"
        );
        assert!(options.shifts_reference() && !ReplayOptions::default().shifts_reference());
    }

    /// Settled on a constant, the reference's low-pass made this log's error the rate
    /// times the filter delay (2.85°) from its start to its end.
    #[test]
    fn a_log_that_starts_in_motion_is_scored_from_the_same_instant() {
        for (lead_s, delay_s) in [(0.0, 0.0), (0.012, 0.012)] {
            let options = ReplayOptions {
                reference_delay_s: delay_s,
                ..ReplayOptions::default()
            };
            let report =
                replay_with(&turning_log(lead_s), &Config::default(), &options).expect("replay");
            let scored: Vec<f64> = report
                .series
                .iter()
                .filter_map(|p| Some(f64::from(p.angle_deg) - p.reference_deg?))
                .collect();
            assert!(scored.len() > 140, "{}", scored.len());
            let worst = scored.iter().fold(0.0_f64, |m, e| m.max(e.abs()));
            assert!(worst < 0.05, "lead {lead_s}: error up to {worst}°");
            let final_error = report.summary.final_error_deg.expect("a reference");
            assert!(final_error.abs() < 0.05, "{final_error}");
        }
    }

    /// The samples each movement carries are the core's: the raw angle between them is the
    /// movement's raw angle (held at rest), and their times less the filter delay are the
    /// movement's times.
    #[test]
    fn movements_carry_the_core_samples_that_bound_them() {
        use gyro_sim::{simulate, BenchProfile, Motion, SensorModel, SimOptions};
        let mut checked = 0;
        for seed in 1..=3 {
            let motion = Motion::bench(&BenchProfile::default(), seed);
            let log = simulate(
                &SensorModel::default(),
                &[],
                &motion,
                &SimOptions::default(),
            );
            let regular = gyro_log::regularize(&log, &GridOptions::default()).expect("grid");
            let report = replay(&regular, &Config::default()).expect("replay");
            let delay_s = Pipeline::try_new(&report.config)
                .expect("config")
                .filter_delay_s();
            for m in report.movements.iter().filter(|m| m.complete) {
                let (a, b) = (&report.series[m.samples.0], &report.series[m.samples.1]);
                assert!((b.raw_angle_deg - a.raw_angle_deg - m.raw_angle_deg).abs() < 1e-3);
                assert!((a.time_s - delay_s - m.start_time_s).abs() < 1e-6, "{m:?}");
                assert!((b.time_s - delay_s - m.end_time_s).abs() < 1e-6, "{m:?}");
                checked += 1;
            }
        }
        assert!(checked >= 10, "{checked}");
    }
}
