//! gyro from Python: the plain Rust layer of the `gyro` module (PyO3 in [`python`], behind
//! the `python` feature, which maturin turns on).
//!
//! [`run_file`] and [`run_arrays`] do what `gyro-cli run` does, with the same settings
//! ([`RunOptions`], assembled as the command line assembles them) and the same JSON
//! (`gyro_report::run::json`); [`Stream`] replays samples on a regular grid block by block.
//! Errors are [`Error`]: the command line's messages.

use gyro_analysis::findings::{self, Finding};
use gyro_analysis::model;
use gyro_analysis::replay::{
    self, Mode, MovementResult, ReplayOptions, Replayer, RunSettings, SeriesPoint,
};
use gyro_core::{Config, Tightening};
use gyro_log::{GridOptions, LogError, LogInfo, LogOptions, Quality, Row, Slot};
use std::path::{Path, PathBuf};

// Not in the unit tests: with the feature on and `PYO3_BUILD_EXTENSION_MODULE` set (CI's
// one build of the workspace, which makes the extension module too) the test binary has
// no interpreter to link; the tests are of the plain layer.
#[cfg(all(feature = "python", not(test)))]
mod python;

/// A failure, with the message the command line gives for it.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Error(pub String);

impl std::fmt::Display for Error {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for Error {}

/// The error's message with its causes, on one line, as `gyro-cli` prints it (`a: b`,
/// lines joined with "; ").
fn error(e: &dyn std::error::Error) -> Error {
    let mut message = e.to_string();
    let mut source = e.source();
    while let Some(cause) = source {
        message.push_str(": ");
        message.push_str(&cause.to_string());
        source = cause.source();
    }
    Error(
        message
            .lines()
            .map(str::trim)
            .filter(|l| !l.is_empty())
            .collect::<Vec<_>>()
            .join("; "),
    )
}

/// The options of `gyro-cli run`: the settings of the replay ([`RunSettings`], resolved by
/// the same function as the command line's) and the log's, checked as the command line
/// checks its flags ([`RunOptions::check`]).
#[derive(Clone, Debug, Default)]
pub struct RunOptions {
    /// `--model`, `--compensation`, `--range-dps`, the tightening window, `--scale-sigma`,
    /// `--reference-delay-s`, `--offline`.
    pub run: RunSettings,
    /// `--sample-rate-hz`, `--max-gap-s`.
    pub grid: GridOptions,
    /// The CSV and MCAP input options.
    pub input: LogOptions,
}

fn check_value(name: &str, value: Option<f64>, ok: bool, expected: &str) -> Result<(), Error> {
    match value {
        Some(v) if !ok => Err(Error(format!(
            "invalid value {v} for {name}: expected {expected}"
        ))),
        _ => Ok(()),
    }
}

impl RunOptions {
    /// Refuse what the command line refuses as it parses its flags.
    pub fn check(&self) -> Result<(), Error> {
        let positive = |v: Option<f64>| v.is_none_or(|v| v.is_finite() && v > 0.0);
        let non_negative = |v: Option<f64>| v.is_none_or(|v| v.is_finite() && v >= 0.0);
        let finite = |v: Option<f64>| v.is_none_or(f64::is_finite);
        let f = |v: Option<f32>| v.map(f64::from);
        let p = "a positive finite number";
        let n = "a finite number >= 0";
        let r = &self.run;
        let k_sigma = Some(f64::from(r.k_sigma));
        check_value("range_dps", f(r.range_dps), positive(f(r.range_dps)), p)?;
        check_value(
            "target_deg",
            f(r.target_deg),
            finite(f(r.target_deg)),
            "a finite number",
        )?;
        check_value(
            "tolerance_deg",
            f(r.tolerance_deg),
            positive(f(r.tolerance_deg)),
            p,
        )?;
        check_value("k_sigma", k_sigma, non_negative(k_sigma), n)?;
        check_value(
            "scale_sigma",
            f(r.scale_sigma),
            non_negative(f(r.scale_sigma)),
            n,
        )?;
        check_value(
            "reference_delay_s",
            r.reference_delay_s,
            finite(r.reference_delay_s),
            "a finite number",
        )?;
        check_value(
            "sample_rate_hz",
            self.grid.sample_rate_hz,
            positive(self.grid.sample_rate_hz),
            p,
        )?;
        check_value(
            "max_gap_s",
            Some(self.grid.max_gap_s),
            non_negative(Some(self.grid.max_gap_s)),
            n,
        )
    }

    /// The pipeline configuration, the scoring options and the mode, as `gyro-cli run`
    /// has them ([`RunSettings::resolve`], the command line's own function).
    pub fn settings(&self) -> Result<(Config, ReplayOptions, Mode), Error> {
        self.check()?;
        let r = self.run.resolve().map_err(|e| error(&e))?;
        Ok((r.config, r.options, r.mode))
    }
}

/// What a run gives: `gyro-cli run --format json`'s text and the output series.
#[derive(Clone, Debug)]
pub struct RunOutput {
    /// The JSON of `gyro-cli run --format json`, byte for byte.
    pub json: String,
    /// The output-rate series (what `--out` writes).
    pub series: Vec<SeriesPoint>,
}

/// The JSON of a report, its findings from the run and the log's `notices`.
fn output(
    file: &str,
    mut report: replay::RunReport,
    notices: &[String],
) -> Result<RunOutput, Error> {
    let found: Vec<Finding> = findings::of_run(&report, notices);
    let series = std::mem::take(&mut report.series);
    let json = gyro_report::run::json(file, &report, &found).map_err(|e| error(&e))?;
    Ok(RunOutput { json, series })
}

fn replay_error(e: replay::ReplayFileError) -> Error {
    match e {
        replay::ReplayFileError::Log(e) => error(&e),
        e @ replay::ReplayFileError::Config { .. } => error(&e),
    }
}

/// `gyro-cli run LOG --format json` (`file`: the log as given), with the series.
pub fn run_file(path: &Path, file: &str, options: &RunOptions) -> Result<RunOutput, Error> {
    let (config, replay_options, mode) = options.settings()?;
    let mut notices = Vec::new();
    let mut series = Vec::new();
    let mut report = replay::replay_file_into_mode(
        path,
        &options.input,
        &options.grid,
        &config,
        &replay_options,
        mode,
        &mut |notice: &str| notices.push(notice.to_string()),
        &mut series,
    )
    .map_err(replay_error)?;
    report.series = series;
    output(file, report, &notices)
}

/// A log as arrays: what a CSV's columns hold, in s, deg/s, deg and °C.
#[derive(Clone, Copy, Debug)]
pub struct Arrays<'a> {
    /// Time stamps (s).
    pub time_s: &'a [f64],
    /// Rates (deg/s); NaN: missing, as an empty CSV field.
    pub rate_dps: &'a [f64],
    /// Reference angles (deg); NaN: missing.
    pub reference_deg: Option<&'a [f64]>,
    /// Temperatures (°C); NaN: missing.
    pub temperature_c: Option<&'a [f64]>,
    /// The log's nominal rate (Hz), as a CSV's `# sample_rate_hz:` line gives it.
    pub nominal_rate_hz: Option<f64>,
    /// The line number of the first sample in errors and notices (1; a CSV's first data
    /// line to match the messages of `gyro-cli` on that CSV).
    pub first_line: u64,
}

impl Arrays<'_> {
    /// Refuse arrays of different lengths and stamps that are not finite.
    fn check(&self) -> Result<(), Error> {
        let n = self.time_s.len();
        for (name, len) in [
            ("rate_dps", Some(self.rate_dps.len())),
            ("reference_deg", self.reference_deg.map(<[f64]>::len)),
            ("temperature_c", self.temperature_c.map(<[f64]>::len)),
        ] {
            if let Some(len) = len.filter(|&len| len != n) {
                return Err(Error(format!(
                    "{name} has {len} values, time_s {n}: give one per time stamp"
                )));
            }
        }
        if let Some(i) = self.time_s.iter().position(|t| !t.is_finite()) {
            return Err(Error(format!(
                "time_s[{i}] is {}: expected a finite time stamp (s)",
                self.time_s[i]
            )));
        }
        if let Some(r) = self
            .nominal_rate_hz
            .filter(|r| !(r.is_finite() && *r > 0.0))
        {
            return Err(Error(format!(
                "invalid value {r} for nominal_rate_hz: expected a positive finite number"
            )));
        }
        Ok(())
    }

    /// The log's description for the grid (`path`: its name in errors).
    fn info<'p>(&self, path: &'p Path) -> LogInfo<'p> {
        LogInfo {
            path,
            metadata_rate_hz: self.nominal_rate_hz,
            has_reference: self.reference_deg.is_some(),
            has_temperature: self.temperature_c.is_some(),
        }
    }

    /// The rows, as a CSV reader gives them.
    fn rows(&self) -> impl Iterator<Item = Result<Row, LogError>> + '_ {
        (0..self.time_s.len()).map(|i| Ok(self.row(i)))
    }

    /// The arrays placed on the grid whole, as [`gyro_log::load`] places a CSV holding
    /// them (`name`: its file name in errors).
    pub fn regular(&self, name: &str, grid: &GridOptions) -> Result<gyro_log::RegularLog, Error> {
        self.check()?;
        let mut slots = Slots::default();
        let quality = gyro_log::place(&self.info(Path::new(name)), self.rows(), grid, &mut slots)
            .map_err(|e| error(&e))?;
        Ok(gyro_log::RegularLog {
            slots: slots.0,
            sample_rate_hz: quality.sample_rate_hz,
            has_reference: slots.1,
            has_temperature: slots.2,
            quality,
        })
    }

    /// Row `i` (line `i + 1`), a NaN field missing.
    fn row(&self, i: usize) -> Row {
        let present = |v: f64| (!v.is_nan()).then_some(v);
        Row {
            line: self.first_line.saturating_add(i as u64),
            time_s: self.time_s[i],
            rate_dps: present(self.rate_dps[i]),
            reference_deg: self.reference_deg.and_then(|r| present(r[i])),
            temperature_c: self.temperature_c.and_then(|t| present(t[i])),
        }
    }
}

/// Collects the slots, for a replay scored against a shifted reference.
#[derive(Default)]
struct Slots(Vec<Slot>, bool, bool);

impl gyro_log::SlotSink for Slots {
    fn columns(&mut self, has_reference: bool, has_temperature: bool) {
        self.1 = has_reference;
        self.2 = has_temperature;
    }
    fn start(&mut self, _sample_rate_hz: f64) {}
    fn slot(&mut self, slot: &Slot) {
        self.0.push(*slot);
    }
}

/// Replays slots as they come (the sink of [`run_arrays`]).
struct ReplaySlots<'a> {
    config: &'a Config,
    options: &'a ReplayOptions,
    mode: Mode,
    has_temperature: bool,
    replayer: Option<Result<Replayer, gyro_core::Error>>,
    series: Vec<SeriesPoint>,
}

impl gyro_log::SlotSink for ReplaySlots<'_> {
    fn columns(&mut self, _has_reference: bool, has_temperature: bool) {
        self.has_temperature = has_temperature;
    }
    fn start(&mut self, sample_rate_hz: f64) {
        self.replayer = Some(
            Replayer::new(
                sample_rate_hz,
                self.config,
                self.options,
                self.has_temperature,
            )
            .map(|r| r.with_mode(self.mode)),
        );
    }
    fn slot(&mut self, slot: &Slot) {
        if let Some(Ok(replayer)) = &mut self.replayer {
            if let Some(point) = replayer.push(slot) {
                replayer.emit(point, &mut self.series);
            }
        }
    }
}

/// `gyro-cli run` on a CSV holding `arrays` (`name`: its file name in the JSON and the
/// errors; the sample `i` is line `first_line + i`): the same grid, replay,
/// findings and JSON. The input options (columns, MCAP) do not apply and are ignored.
pub fn run_arrays(
    arrays: &Arrays<'_>,
    name: &str,
    options: &RunOptions,
) -> Result<RunOutput, Error> {
    arrays.check()?;
    let (config, replay_options, mode) = options.settings()?;
    let path = Path::new(name);
    let config_error = |cause, sample_rate_hz| {
        replay_error(replay::ReplayFileError::Config {
            path: path.to_path_buf(),
            cause,
            sample_rate_hz,
            output_rate_hz: config.output_rate_hz,
        })
    };
    let delay = replay_options.reference_delay_s;
    let report = if (delay.is_finite() && delay != 0.0) || mode == replay::Mode::Offline {
        // The shifted reference needs the log whole, as `replay_file_into` does; offline
        // replays it twice (the arrays are in memory already).
        let regular = arrays.regular(name, &options.grid)?;
        replay::replay_with_mode(&regular, &config, &replay_options, mode)
            .map_err(|cause| config_error(cause, regular.sample_rate_hz))?
    } else {
        let mut sink = ReplaySlots {
            config: &config,
            options: &replay_options,
            mode,
            has_temperature: false,
            replayer: None,
            series: Vec::new(),
        };
        let quality = gyro_log::place(&arrays.info(path), arrays.rows(), &options.grid, &mut sink)
            .map_err(|e| error(&e))?;
        let sample_rate_hz = quality.sample_rate_hz;
        match sink.replayer {
            Some(Ok(replayer)) => {
                let mut report = replayer.finish_into(quality, &mut sink.series);
                report.series = sink.series;
                report
            }
            Some(Err(cause)) => return Err(config_error(cause, sample_rate_hz)),
            None => Replayer::new(
                sample_rate_hz,
                &config,
                &replay_options,
                sink.has_temperature,
            )
            .map(|r| r.finish(quality))
            .map_err(|cause| config_error(cause, sample_rate_hz))?,
        }
    };
    // The grid's own warnings are the log's notices, as `gyro_log::stream` passes them on.
    let notices = report.input.warnings.clone();
    output(name, report, &notices)
}

/// What a block pushed into a [`Stream`] gave.
#[derive(Clone, Debug, Default)]
pub struct Pushed {
    /// The outputs the block completed.
    pub series: Vec<SeriesPoint>,
    /// The movements that started in the block: their start times (s).
    pub started_s: Vec<f64>,
    /// The movements that ended in the block, complete.
    pub ended: Vec<MovementResult>,
}

/// The pipeline fed block by block with samples already on a regular grid at a known rate,
/// as the wrench's firmware feeds it: each sample is one slot (no grid placement, no gap
/// filling). The outputs, the movements and the report equal those of [`run_arrays`] with
/// `sample_rate_hz` given on the same samples when their stamps are regular.
pub struct Stream {
    sample_rate_hz: f64,
    config: Config,
    options: ReplayOptions,
    replayer: Option<Replayer>,
    samples: u64,
    first_time_s: Option<f64>,
    last_time_s: Option<f64>,
    movements_seen: usize,
    moving_since_s: Option<f64>,
}

impl Stream {
    /// A stream at `sample_rate_hz` with `options` as `gyro-cli run` takes them; causal
    /// only, and the reference as logged (no `reference_delay_s`, no `offline`: both need
    /// samples ahead).
    pub fn new(sample_rate_hz: f64, options: &RunOptions) -> Result<Self, Error> {
        if !(sample_rate_hz.is_finite() && sample_rate_hz > 0.0) {
            return Err(Error(format!(
                "invalid value {sample_rate_hz} for sample_rate_hz: expected a positive finite number"
            )));
        }
        let (config, replay_options, mode) = options.settings()?;
        if mode != Mode::Causal {
            return Err(Error(
                "a Pipeline is causal: offline needs the rest after each movement; use run or run_arrays with offline=True".into(),
            ));
        }
        if replay_options.reference_delay_s != 0.0 {
            return Err(Error(
                "a Pipeline scores against the reference as logged: reference_delay_s needs the reference ahead; use run or run_arrays".into(),
            ));
        }
        // Fails now, not at the first block, if the rate does not fit the configuration.
        Replayer::new(sample_rate_hz, &config, &replay_options, false).map_err(|e| {
            Error(format!(
                "cannot configure the pipeline for {sample_rate_hz} Hz: {e}"
            ))
        })?;
        Ok(Self {
            sample_rate_hz,
            config,
            options: replay_options,
            replayer: None,
            samples: 0,
            first_time_s: None,
            last_time_s: None,
            movements_seen: 0,
            moving_since_s: None,
        })
    }

    /// Push a block of samples (arrays as [`run_arrays`] takes them; the temperature, if
    /// any, given with the first block and every later one).
    pub fn push(&mut self, block: &Arrays<'_>) -> Result<Pushed, Error> {
        block.check()?;
        if let (Some(last), Some(&first)) = (self.last_time_s, block.time_s.first()) {
            if first <= last {
                return Err(Error(format!(
                    "time_s[0] = {first} s is not after the previous block's last stamp {last} s: blocks come in time order"
                )));
            }
        }
        if let Some(i) = block.time_s.windows(2).position(|w| w[1] <= w[0]) {
            return Err(Error(format!(
                "time_s[{}] = {} s is not after time_s[{i}] = {} s: stamps must rise",
                i + 1,
                block.time_s[i + 1],
                block.time_s[i]
            )));
        }
        let has_temperature = block.temperature_c.is_some();
        let replayer = match &mut self.replayer {
            Some(r) => r,
            None => self.replayer.insert(
                Replayer::new(
                    self.sample_rate_hz,
                    &self.config,
                    &self.options,
                    has_temperature,
                )
                .map_err(|e| Error(e.to_string()))?,
            ),
        };
        let mut pushed = Pushed::default();
        for i in 0..block.time_s.len() {
            let row = block.row(i);
            let slot = Slot {
                time_s: row.time_s,
                rate_dps: row.rate_dps.unwrap_or(f64::NAN),
                reference_deg: row.reference_deg,
                temperature_c: row.temperature_c,
                line: self.samples + 1,
                filled: false,
            };
            self.samples += 1;
            if let Some(point) = replayer.push(&slot) {
                replayer.emit(point, &mut pushed.series);
            }
            let moving = replayer.moving_since_s();
            if let Some(start) = moving.filter(|s| Some(*s) != self.moving_since_s) {
                pushed.started_s.push(start);
            }
            self.moving_since_s = moving;
            let movements = replayer.movements();
            pushed
                .ended
                .extend_from_slice(&movements[self.movements_seen..]);
            self.movements_seen = movements.len();
        }
        if let (Some(&first), Some(&last)) = (block.time_s.first(), block.time_s.last()) {
            self.first_time_s.get_or_insert(first);
            self.last_time_s = Some(last);
        }
        Ok(pushed)
    }

    /// The report of everything pushed (`name`: the file name in the JSON); its series is
    /// empty (the blocks gave it).
    pub fn finish(self, name: &str) -> Result<RunOutput, Error> {
        let replayer = match self.replayer {
            Some(r) => r,
            None => Replayer::new(self.sample_rate_hz, &self.config, &self.options, false)
                .map_err(|e| Error(e.to_string()))?,
        };
        let span_s = match (self.first_time_s, self.last_time_s) {
            (Some(a), Some(b)) => b - a,
            _ => 0.0,
        };
        let quality = Quality {
            rows: self.samples,
            slots: self.samples,
            sample_rate_hz: self.sample_rate_hz,
            sample_rate_source: "option",
            effective_rate_hz: if span_s > 0.0 {
                (self.samples - 1) as f64 / span_s
            } else {
                self.sample_rate_hz
            },
            ..Quality::default()
        };
        output(name, replayer.finish(quality), &[])
    }
}

/// The options of `gyro-cli noise` that do not write files (each named after its flag).
#[derive(Clone, Debug)]
pub struct NoiseOptions {
    /// `--static-only`.
    pub static_only: bool,
    /// `--margin-s`.
    pub margin_s: f64,
    /// `--min-rest-s`.
    pub min_rest_s: f64,
    /// `--model`.
    pub model: Option<PathBuf>,
    /// `--tau-grid` (`log`, `octave`, `decade`).
    pub tau_grid: String,
    /// `--per-decade`.
    pub per_decade: u32,
    /// `--confidence`.
    pub confidence: f64,
    /// `--psd-segment`.
    pub psd_segment: Option<usize>,
    /// `--sample-rate-hz`, `--max-gap-s`.
    pub grid: GridOptions,
    /// The CSV and MCAP input options (time and rate only).
    pub input: LogOptions,
}

impl Default for NoiseOptions {
    fn default() -> Self {
        Self {
            static_only: false,
            margin_s: 0.5,
            min_rest_s: 1.0,
            model: None,
            tau_grid: "log".into(),
            per_decade: 10,
            confidence: gyro_analysis::noise::ONE_SIGMA,
            psd_segment: None,
            grid: GridOptions::default(),
            input: LogOptions::default(),
        }
    }
}

/// The noise options checked as the command line checks them, the configuration that
/// finds the rests (the model's, else the built-in one), the analysis options.
fn noise_settings(o: &NoiseOptions) -> Result<(Config, gyro_analysis::noise::NoiseOptions), Error> {
    use gyro_analysis::noise::{self, PsdOptions, TauGrid};
    if !(o.confidence > 0.0 && o.confidence < 1.0) {
        return Err(Error("--confidence must be in (0, 1)".into()));
    }
    if !(o.margin_s >= 0.0 && o.min_rest_s >= 0.0) {
        return Err(Error("--margin-s and --min-rest-s must be >= 0".into()));
    }
    if o.per_decade < 1 {
        return Err(Error(
            "invalid value 0 for per_decade: expected at least 1".into(),
        ));
    }
    if let Some(len) = o.psd_segment {
        if len < 2 || !len.is_power_of_two() {
            return Err(Error("--psd-segment must be a power of two >= 2".into()));
        }
    }
    let taus = match o.tau_grid.as_str() {
        "log" => TauGrid::PerDecade(o.per_decade),
        "octave" => TauGrid::Octave,
        "decade" => TauGrid::Decade,
        other => {
            return Err(Error(format!(
                "invalid value '{other}' for tau_grid: expected one of log, octave, decade"
            )))
        }
    };
    let config = match &o.model {
        Some(path) => model::load(path).map_err(|e| error(&e))?.config,
        None => Config::default(),
    };
    let options = noise::NoiseOptions {
        taus,
        confidence: o.confidence,
        psd: PsdOptions {
            segment_len: o.psd_segment,
            ..PsdOptions::default()
        },
        ..noise::NoiseOptions::default()
    };
    Ok((config, options))
}

/// One log of a noise run (`file`: its name in the JSON and the errors): whole, or its
/// rests with `static_only`.
fn noise_log(
    file: &str,
    regular: gyro_log::RegularLog,
    config: &Config,
    o: &NoiseOptions,
) -> Result<gyro_analysis::noise::NoiseLog, Error> {
    use gyro_analysis::noise;
    let rate: Vec<f64> = regular.slots.iter().map(|s| s.rate_dps).collect();
    let rests = |margin_s: f64, min_rest_s: f64| {
        noise::rest_segments(&regular, config, margin_s, min_rest_s).map_err(|e| {
            Error(format!(
                "{file}: cannot configure the pipeline for this log: {}",
                error(&e)
            ))
        })
    };
    let mut moving_share = None;
    let segments = if o.static_only {
        let segments = rests(o.margin_s, o.min_rest_s)?;
        if segments.is_empty() {
            return Err(Error(format!(
                "{file}: no rest stretch of at least {} s found (--static-only)",
                o.min_rest_s
            )));
        }
        segments
    } else {
        let at_rest: usize = rests(0.0, 0.0)?.iter().map(ExactSizeIterator::len).sum();
        moving_share = Some(1.0 - at_rest as f64 / rate.len().max(1) as f64);
        std::iter::once(0..rate.len()).collect()
    };
    Ok(noise::NoiseLog {
        file: file.to_string(),
        rate_dps: rate,
        sample_rate_hz: regular.sample_rate_hz,
        segments,
        input: regular.quality,
        moving_share,
    })
}

/// The JSON of a noise run on `loaded`.
fn noise_json(
    loaded: &[gyro_analysis::noise::NoiseLog],
    options: &gyro_analysis::noise::NoiseOptions,
    o: &NoiseOptions,
) -> Result<String, Error> {
    let run = gyro_analysis::noise::characterize_logs(loaded, options).map_err(|e| error(&e))?;
    gyro_report::noise::json(loaded, &run, o.static_only, None).map_err(|e| error(&e))
}

/// `gyro-cli noise LOG... --format json` (`files`: the logs as given): its JSON text.
pub fn noise_files(paths: &[PathBuf], files: &[String], o: &NoiseOptions) -> Result<String, Error> {
    if paths.is_empty() {
        return Err(Error("noise needs at least one log".into()));
    }
    refuse_repeated_runs(&[("static", paths)])?;
    let (config, options) = noise_settings(o)?;
    let mut loaded = Vec::new();
    for (path, file) in paths.iter().zip(files) {
        let regular =
            gyro_log::load(path, &o.input, &o.grid, &mut |_| {}).map_err(|e| error(&e))?;
        loaded.push(noise_log(&path.display().to_string(), regular, &config, o)?);
        if let Some(last) = loaded.last_mut() {
            last.file.clone_from(file);
        }
    }
    noise_json(&loaded, &options, o)
}

/// [`noise_files`] on logs given as arrays, each with its name (as if a CSV of that name
/// held them): the same JSON. The input options (columns, MCAP) do not apply.
pub fn noise_arrays(logs: &[(&str, Arrays<'_>)], o: &NoiseOptions) -> Result<String, Error> {
    if logs.is_empty() {
        return Err(Error("noise needs at least one log".into()));
    }
    let (config, options) = noise_settings(o)?;
    let mut loaded = Vec::new();
    for (name, arrays) in logs {
        let regular = arrays.regular(name, &o.grid)?;
        loaded.push(noise_log(name, regular, &config, o)?);
    }
    noise_json(&loaded, &options, o)
}

/// The options of `gyro-cli calibrate` (each named after its flag; `out` may be left out).
#[derive(Clone, Debug, Default)]
pub struct CalibrateArgs {
    /// The training runs.
    pub logs: Vec<PathBuf>,
    /// `--holdout`.
    pub holdout: Vec<PathBuf>,
    /// `--objective`.
    pub objective: gyro_analysis::calibrate::Objective,
    /// `--model`.
    pub model: Option<PathBuf>,
    /// `--tau-s`.
    pub tau_s: Option<f64>,
    /// `--fit-motion`.
    pub fit_motion: bool,
    /// `--reference-delay-s`.
    pub reference_delay_s: Option<f64>,
    /// Not `--no-leave-one-out`.
    pub leave_one_out: bool,
    /// `-o`: where to write the model file, if anywhere.
    pub out: Option<PathBuf>,
    /// `--sample-rate-hz`, `--max-gap-s`.
    pub grid: GridOptions,
    /// The CSV and MCAP input options.
    pub input: LogOptions,
}

/// `gyro-cli calibrate LOG... --format json`: its JSON text and the model file's (the file
/// written to `out` when given, as `-o` writes it).
pub fn calibrate_files(a: &CalibrateArgs) -> Result<(String, String), Error> {
    use gyro_analysis::calibrate::BenchRun;
    let base = calibrate_base(a, true)?;
    let load = |paths: &[PathBuf]| -> Result<Vec<BenchRun>, Error> {
        paths
            .iter()
            .map(|path| {
                let log =
                    gyro_log::load(path, &a.input, &a.grid, &mut |_| {}).map_err(|e| error(&e))?;
                Ok(BenchRun {
                    name: path.display().to_string(),
                    log,
                })
            })
            .collect()
    };
    let train = load(&a.logs)?;
    let holdout = load(&a.holdout)?;
    calibrate_runs(&base, &train, &holdout, a)
}

/// [`calibrate_files`] on runs given as arrays, each with its name (as if a CSV of that
/// name held them): the same JSON and model. `a`'s logs and input options do not apply.
pub fn calibrate_arrays(
    train: &[(&str, Arrays<'_>)],
    holdout: &[(&str, Arrays<'_>)],
    a: &CalibrateArgs,
) -> Result<(String, String), Error> {
    use gyro_analysis::calibrate::BenchRun;
    let base = calibrate_base(a, false)?;
    let runs = |logs: &[(&str, Arrays<'_>)]| -> Result<Vec<BenchRun>, Error> {
        logs.iter()
            .map(|(name, arrays)| {
                Ok(BenchRun {
                    name: (*name).to_string(),
                    log: arrays.regular(name, &a.grid)?,
                })
            })
            .collect()
    };
    let train = runs(train)?;
    let holdout = runs(holdout)?;
    calibrate_runs(&base, &train, &holdout, a)
}

/// The calibrate options checked as the command line checks them (`files`: a run given
/// twice refused), and the model file to start from.
fn calibrate_base(a: &CalibrateArgs, files: bool) -> Result<model::ModelFile, Error> {
    if let Some(t) = a.tau_s.filter(|t| !(t.is_finite() && *t > 0.0)) {
        return Err(Error(format!(
            "invalid value {t} for tau_s: expected a positive finite number"
        )));
    }
    if let Some(d) = a.reference_delay_s.filter(|d| !d.is_finite()) {
        return Err(Error(format!(
            "invalid value {d} for reference_delay_s: expected a finite number"
        )));
    }
    if files {
        refuse_repeated_runs(&[("training", &a.logs), ("hold-out", &a.holdout)])?;
    }
    replay::settings::check_reference_delay(a.reference_delay_s).map_err(|e| error(&e))?;
    match &a.model {
        Some(path) => model::load(path).map_err(|e| error(&e)),
        None => Ok(model::ModelFile::new(Config::default())),
    }
}

/// Calibrate on `train`, scored on `holdout`, from `base`: the JSON and the model file's
/// text (written to `a.out` when given).
fn calibrate_runs(
    base: &model::ModelFile,
    train: &[gyro_analysis::calibrate::BenchRun],
    holdout: &[gyro_analysis::calibrate::BenchRun],
    a: &CalibrateArgs,
) -> Result<(String, String), Error> {
    use gyro_analysis::calibrate::{calibrate, CalibrateOptions};
    let options = CalibrateOptions {
        objective: a.objective,
        leave_one_out: a.leave_one_out,
        initial_tau_s: a.tau_s,
        fit_motion: a.fit_motion,
        reference_delay_s: a
            .reference_delay_s
            .or((base.reference_delay_s != 0.0).then_some(base.reference_delay_s)),
    };
    let result = calibrate(train, holdout, &base.config, &options, &mut |_, _, _| {})
        .map_err(|e| error(&e))?;
    let (out, _) = result.model_file(base, train.iter().chain(holdout));
    if let Some(path) = &a.out {
        model::save(path, &out)
            .map_err(|e| Error(format!("writing the model file: {}", error(&e))))?;
    }
    let model_json = serde_json::to_string_pretty(&out).map_err(|e| error(&e))?;
    let inputs: Vec<_> = train
        .iter()
        .chain(holdout)
        .map(|run| gyro_report::input::InputJson {
            file: &run.name,
            input: &run.log.quality,
        })
        .collect();
    let json = gyro_report::calibrate::json(&inputs, &result).map_err(|e| error(&e))?;
    Ok((json, model_json))
}

/// Refuse a run given twice, as `gyro-cli` does
/// ([`gyro_log::repeated::refuse_repeated_runs`]).
fn refuse_repeated_runs(lists: &[(&str, &[PathBuf])]) -> Result<(), Error> {
    gyro_log::repeated::refuse_repeated_runs(lists).map_err(|e| error(&e))
}

/// The options of `gyro-cli diagnose` that diagnose logs and write no file (each named
/// after its flag).
#[derive(Clone, Debug)]
pub struct DiagnoseArgs {
    /// `--train`.
    pub train: Vec<PathBuf>,
    /// `--holdout`.
    pub holdout: Vec<PathBuf>,
    /// `--split-s`.
    pub split_s: Option<f64>,
    /// `--model`.
    pub model: Option<PathBuf>,
    /// `--seed`.
    pub seed: u64,
    /// `--members`.
    pub members: usize,
    /// `--candidate-members`.
    pub candidate_members: usize,
    /// `--score-every-candidate`.
    pub score_every_candidate: bool,
    /// `--sample-rate-hz`, `--max-gap-s`.
    pub grid: GridOptions,
    /// The CSV and MCAP input options.
    pub input: LogOptions,
}

impl Default for DiagnoseArgs {
    fn default() -> Self {
        let o = gyro_diagnose::Options::default();
        Self {
            train: Vec::new(),
            holdout: Vec::new(),
            split_s: None,
            model: None,
            seed: o.seed,
            members: o.members,
            candidate_members: o.candidate_members,
            score_every_candidate: o.score_every_candidate,
            grid: GridOptions::default(),
            input: LogOptions::default(),
        }
    }
}

/// `gyro-cli diagnose --train … --holdout … --format json`: its JSON text (the contract of
/// docs/diagnose-json.md), the runs read as the command line reads them
/// ([`gyro_diagnose::files::load_files`]).
pub fn diagnose_files(a: &DiagnoseArgs) -> Result<String, Error> {
    use gyro_diagnose::files::{self, FileOptions, FileRuns};
    let options = diagnose_options(a)?;
    let FileRuns {
        train,
        holdout,
        inputs,
    } = files::load_files(
        &a.train,
        &a.holdout,
        &FileOptions {
            input: &a.input,
            grid: &a.grid,
            split_s: a.split_s,
        },
        &mut |_| {},
    )
    .map_err(|e| error(&e))?;
    diagnose_runs(&train, &holdout, inputs, &options)
}

/// [`diagnose_files`] on runs given as arrays, each with its name (as if a CSV of that
/// name held them, cut by `a.split_s`): the same JSON. `a`'s files and input options do
/// not apply, its grid does.
pub fn diagnose_arrays(
    train: &[(&str, Arrays<'_>)],
    holdout: &[(&str, Arrays<'_>)],
    a: &DiagnoseArgs,
) -> Result<String, Error> {
    let options = diagnose_options(a)?;
    let mut inputs = Vec::new();
    let mut runs =
        |logs: &[(&str, Arrays<'_>)], role: &str| -> Result<Vec<gyro_diagnose::RealRun>, Error> {
            let mut out = Vec::new();
            for (name, arrays) in logs {
                let regular = arrays.regular(name, &a.grid)?;
                out.extend(
                    gyro_diagnose::files::runs_of_log(name, regular, role, a.split_s, &mut inputs)
                        .map_err(|e| error(&e))?,
                );
            }
            Ok(out)
        };
    let train = runs(train, "training")?;
    let holdout = runs(holdout, "held-out")?;
    diagnose_runs(&train, &holdout, inputs, &options)
}

/// The diagnosis options of `a`, checked as the command line checks them.
fn diagnose_options(a: &DiagnoseArgs) -> Result<gyro_diagnose::Options, Error> {
    if a.members < 2 || a.candidate_members < 2 {
        return Err(Error(
            "--members and --candidate-members must be at least 2".into(),
        ));
    }
    let options = gyro_diagnose::Options {
        seed: a.seed,
        members: a.members,
        candidate_members: a.candidate_members,
        score_every_candidate: a.score_every_candidate,
        ..gyro_diagnose::Options::default()
    };
    Ok(match &a.model {
        Some(path) => options.with_fixed_model(model::load(path).map_err(|e| error(&e))?),
        None => options,
    })
}

/// The diagnosis of `train` against `holdout` as JSON text, with the logs' input reports.
fn diagnose_runs(
    train: &[gyro_diagnose::RealRun],
    holdout: &[gyro_diagnose::RealRun],
    inputs: Vec<gyro_diagnose::InputEntry>,
    options: &gyro_diagnose::Options,
) -> Result<String, Error> {
    let advice = |e: gyro_diagnose::DiagnoseError| Error(e.with_advice());
    gyro_diagnose::check_runs(train, holdout).map_err(advice)?;
    let mut result =
        gyro_diagnose::diagnose(train, holdout, options, &gyro_diagnose::Silent).map_err(advice)?;
    result.inputs = inputs;
    serde_json::to_string_pretty(&result).map_err(|e| error(&e))
}

/// The tightening decision on one angle ([`gyro_core::decide`]): `None` for a turn the
/// other way. The window is checked as a model file's is.
pub fn decide(
    window: &Tightening,
    angle_deg: f32,
    angle_std_deg: f32,
    untrusted: bool,
) -> Result<Option<gyro_core::Verdict>, Error> {
    window
        .validate()
        .map_err(|e| Error(format!("the tightening window: {e}")))?;
    Ok(gyro_core::decide(
        window,
        angle_deg,
        angle_std_deg,
        untrusted,
    ))
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;

    fn bench() -> PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/logs/bench_run.csv")
    }

    /// The bench log's columns, read as the CSV reader reads them.
    fn columns() -> (Vec<f64>, Vec<f64>, Vec<f64>, Vec<f64>) {
        let log = gyro_log::read_log(&bench(), &LogOptions::default()).unwrap();
        let mut c = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
        for r in &log.rows {
            c.0.push(r.time_s);
            c.1.push(r.rate_dps.unwrap_or(f64::NAN));
            c.2.push(r.reference_deg.unwrap_or(f64::NAN));
            c.3.push(r.temperature_c.unwrap_or(f64::NAN));
        }
        c
    }

    #[test]
    fn arrays_give_the_files_json() {
        let options = RunOptions {
            run: RunSettings {
                target_deg: Some(90.0),
                tolerance_deg: Some(1.0),
                ..RunSettings::default()
            },
            ..RunOptions::default()
        };
        let file = run_file(&bench(), "bench", &options).unwrap();
        let c = columns();
        let arrays = Arrays {
            time_s: &c.0,
            rate_dps: &c.1,
            reference_deg: Some(&c.2),
            temperature_c: Some(&c.3),
            nominal_rate_hz: Some(1000.0),
            first_line: 5,
        };
        let from_arrays = run_arrays(&arrays, "bench", &options).unwrap();
        assert_eq!(file.json, from_arrays.json);
        assert_eq!(file.series, from_arrays.series);
        assert!(file.json.contains("\"verdict\": \"ok\""));
    }

    #[test]
    fn noise_on_arrays_gives_the_files_json() {
        let c = columns();
        let arrays = Arrays {
            time_s: &c.0,
            rate_dps: &c.1,
            reference_deg: Some(&c.2),
            temperature_c: Some(&c.3),
            nominal_rate_hz: Some(1000.0),
            first_line: 5,
        };
        let o = NoiseOptions {
            static_only: true,
            ..NoiseOptions::default()
        };
        let file = noise_files(&[bench()], &["bench".into()], &o).unwrap();
        assert_eq!(noise_arrays(&[("bench", arrays)], &o).unwrap(), file);
        let twice = noise_files(&[bench(), bench()], &["a".into(), "b".into()], &o);
        assert!(twice.unwrap_err().0.contains("give each run once"));
    }

    #[test]
    fn blocks_give_the_one_call() {
        let c = columns();
        let options = RunOptions {
            grid: GridOptions {
                sample_rate_hz: Some(1000.0),
                ..GridOptions::default()
            },
            ..RunOptions::default()
        };
        let arrays = Arrays {
            time_s: &c.0,
            rate_dps: &c.1,
            reference_deg: Some(&c.2),
            temperature_c: Some(&c.3),
            nominal_rate_hz: None,
            first_line: 1,
        };
        let one = run_arrays(&arrays, "x", &options).unwrap();
        let mut stream = Stream::new(1000.0, &RunOptions::default()).unwrap();
        let (mut series, mut ended, mut started) = (Vec::new(), Vec::new(), 0);
        for start in (0..c.0.len()).step_by(777) {
            let end = (start + 777).min(c.0.len());
            let pushed = stream
                .push(&Arrays {
                    time_s: &c.0[start..end],
                    rate_dps: &c.1[start..end],
                    reference_deg: Some(&c.2[start..end]),
                    temperature_c: Some(&c.3[start..end]),
                    nominal_rate_hz: None,
                    first_line: 1,
                })
                .unwrap();
            series.extend(pushed.series);
            ended.extend(pushed.ended);
            started += pushed.started_s.len();
        }
        let report = stream.finish("x").unwrap();
        assert_eq!(series, one.series);
        let json = |s: &str| serde_json::from_str::<serde_json::Value>(s).unwrap();
        let (a, b) = (json(&report.json), json(&one.json));
        assert_eq!(a["movements"], b["movements"]);
        assert_eq!(a["summary"], b["summary"]);
        assert_eq!(ended.len(), 6);
        assert_eq!(started, 6);
    }

    #[test]
    fn bad_input_is_an_error() {
        let t = [0.0, 0.001, f64::NAN];
        let r = [0.0; 3];
        let arrays = Arrays {
            time_s: &t,
            rate_dps: &r,
            reference_deg: None,
            temperature_c: None,
            nominal_rate_hz: None,
            first_line: 1,
        };
        let e = run_arrays(&arrays, "x", &RunOptions::default()).unwrap_err();
        assert!(e.0.contains("time_s[2]"), "{e}");
        let e = run_arrays(
            &Arrays {
                rate_dps: &r[..2],
                ..arrays
            },
            "x",
            &RunOptions::default(),
        )
        .unwrap_err();
        assert!(e.0.contains("rate_dps has 2 values"), "{e}");
        let e = run_file(Path::new("/nonexistent.csv"), "x", &RunOptions::default()).unwrap_err();
        assert!(e.0.contains("/nonexistent.csv"), "{e}");
        let options = RunOptions {
            run: RunSettings {
                target_deg: Some(90.0),
                ..RunSettings::default()
            },
            ..RunOptions::default()
        };
        assert!(options.settings().is_err());
    }
}
