//! Gyro logs: the shared CSV and MCAP contract (docs/log-formats.md), read into rows,
//! then put on a regular time grid with every irregularity counted.
//!
//! [`load`] is the one way in for a command: read either format (by content, else by
//! extension), pass on the warnings, place the rows on the grid; [`stream`] does the same
//! slot by slot. [`read_log`] reads without placing; [`write_log`] writes either format by
//! extension (MCAP compressed as [`McapCompression`] says), whole ([`whole`]: a partial
//! file beside the target, renamed when complete).
//!
//! ```
//! let regular = gyro_log::load(
//!     "../../fixtures/logs/bench_run.csv".as_ref(),
//!     &gyro_log::LogOptions::default(),
//!     &gyro_log::GridOptions::default(),
//!     &mut |warning| eprintln!("warning: {warning}"),
//! )?;
//! assert_eq!(regular.sample_rate_hz, 1000.0);
//! assert!(regular.has_reference && regular.quality.duplicate_rows == 0);
//! # Ok::<(), gyro_log::LogError>(())
//! ```

mod ahead;
pub mod backlog;
pub mod bursts;
mod csv_log;
pub mod jumps;
mod load;
pub mod mcap;
pub mod real_data;
mod regular;
pub mod repeated;
pub mod sense;
pub mod value;
pub mod whole;
pub mod wraps;

pub(crate) use ahead::read_ahead;
pub use bursts::Bursts;
pub(crate) use csv_log::CsvRows;
pub use csv_log::{
    excerpt, read_csv, write_csv, ColumnOptions, RateUnit, TimeUnit, DEFAULT_REFERENCE_COLUMN,
    DEFAULT_TEMPERATURE_COLUMN,
};
pub use load::{load, stream};
pub use mcap::{
    decode_reference, decode_sample, encode_reference, encode_sample, read_mcap, write_mcap,
    write_mcap_with, Axis, GyroSample, JsonChannel, McapCompression, McapLogWriter, McapOptions,
    McapRead, McapRows, McapWriteOptions, TimeSource, HAS_TEMPERATURE_KEY, REFERENCE_SCHEMA_NAME,
    SAMPLE_SCHEMA_NAME,
};
pub use regular::{
    place, regularize, GridOptions, LogInfo, Quality, RegularLog, Slot, SlotSink,
    MAX_BRIDGED_SLOTS, MAX_HELD_SLOTS, RATE_DISAGREEMENT, RATE_WARNING_SHARE, RATE_WINDOW_STEPS,
};

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// A log file format.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
pub enum LogFormat {
    /// CSV with `# key: value` metadata lines and a header.
    Csv,
    /// MCAP (`/gyro`, `/reference` in CDR or JSON; or a ROS 2 bag with an Imu channel).
    Mcap,
}

impl LogFormat {
    /// The format a file name asks for: `.csv` or `.mcap` (any case), else `None`.
    pub fn from_extension(path: &Path) -> Option<Self> {
        let ext = path.extension()?.to_str()?.to_ascii_lowercase();
        match ext.as_str() {
            "csv" => Some(Self::Csv),
            "mcap" => Some(Self::Mcap),
            _ => None,
        }
    }

    /// The format of an existing file: MCAP if it starts with the MCAP magic, else by
    /// extension, else CSV. A file that cannot be opened is judged by its extension (the
    /// reader then reports the error).
    pub fn detect(path: &Path) -> Self {
        use std::io::Read;
        let mut head = [0_u8; 5];
        let starts_mcap = std::fs::File::open(path)
            .and_then(|mut f| f.read_exact(&mut head))
            .is_ok()
            && head == mcap::MAGIC[..5];
        if starts_mcap {
            Self::Mcap
        } else {
            Self::from_extension(path).unwrap_or(Self::Csv)
        }
    }
}

/// How to read a log of either format.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "clap", derive(clap::Args))]
pub struct LogOptions {
    /// CSV columns and units.
    #[cfg_attr(feature = "clap", command(flatten, next_help_heading = "CSV input"))]
    pub columns: ColumnOptions,
    /// MCAP channels and ROS 2 options.
    #[cfg_attr(
        feature = "clap",
        command(flatten, next_help_heading = "MCAP / ROS 2 input")
    )]
    pub mcap: McapOptions,
}

impl LogOptions {
    /// The format of `path` ([`LogFormat::detect`]), refusing a setting given for the
    /// other format ([`LogError::NotApplicable`]): it would be ignored.
    pub fn format_of(&self, path: &Path) -> Result<LogFormat, LogError> {
        let format = LogFormat::detect(path);
        let (csv, mcap) = (ColumnOptions::default(), McapOptions::default());
        let given: &[(&'static str, bool)] = match format {
            LogFormat::Mcap => {
                let c = &self.columns;
                &[
                    ("time_column", c.time_column != csv.time_column),
                    ("time_unit", c.time_unit != csv.time_unit),
                    ("rate_column", c.rate_column != csv.rate_column),
                    ("rate_unit", c.rate_unit != csv.rate_unit),
                    ("reference_column", c.reference_column.is_some()),
                    ("temperature_column", c.temperature_column.is_some()),
                ]
            }
            LogFormat::Csv => {
                let m = &self.mcap;
                &[
                    ("topic", m.topic.is_some()),
                    ("reference_topic", m.reference_topic != mcap.reference_topic),
                    ("axis", m.axis != mcap.axis),
                    ("flip", m.flip != mcap.flip),
                    ("time_source", m.time_source != mcap.time_source),
                ]
            }
        };
        match given.iter().find(|(_, given)| *given) {
            None => Ok(format),
            Some((setting, _)) => Err(LogError::NotApplicable {
                path: path.to_path_buf(),
                format: match format {
                    LogFormat::Csv => "a CSV log",
                    LogFormat::Mcap => "an MCAP log",
                },
                setting,
                other: match format {
                    LogFormat::Csv => "MCAP",
                    LogFormat::Mcap => "CSV",
                },
            }),
        }
    }
}

/// Read a CSV or MCAP log (format from [`LogFormat::detect`]). MCAP damage that did not
/// stop reading (an interrupted recording) is returned as warnings, one line each. A
/// setting of the other format is refused ([`LogOptions::format_of`]).
pub fn read_log_with_warnings(
    path: &Path,
    options: &LogOptions,
) -> Result<(Log, Vec<String>), LogError> {
    match options.format_of(path)? {
        LogFormat::Csv => Ok((read_csv(path, &options.columns)?, Vec::new())),
        LogFormat::Mcap => {
            let read = read_mcap(path, &options.mcap)?;
            Ok((read.log, read.warnings))
        }
    }
}

/// Read a CSV or MCAP log (format from [`LogFormat::detect`]); warnings are dropped (see
/// [`read_log_with_warnings`]).
pub fn read_log(path: &Path, options: &LogOptions) -> Result<Log, LogError> {
    read_log_with_warnings(path, options).map(|(log, _)| log)
}

/// Write `log` to `path` as `format`, or by the path's extension (`.csv`, `.mcap`); MCAP
/// with the default [`McapCompression`] (zstd).
pub fn write_log(path: &Path, log: &Log, format: Option<LogFormat>) -> Result<(), LogError> {
    write_log_with(path, log, format, McapCompression::default())
}

/// [`write_log`], an MCAP file's chunks compressed with `compression` (a CSV ignores it).
pub fn write_log_with(
    path: &Path,
    log: &Log,
    format: Option<LogFormat>,
    compression: McapCompression,
) -> Result<(), LogError> {
    let format = format
        .or_else(|| LogFormat::from_extension(path))
        .ok_or_else(|| LogError::Format {
            path: path.to_path_buf(),
            message: "unknown output format: name it .csv or .mcap".into(),
        })?;
    // Written whole ([`whole`]): a failure leaves no half-written file that looks
    // finished, and a file that was there is kept.
    let io_err = |cause| LogError::Io {
        path: path.to_path_buf(),
        cause,
    };
    let partial = whole::Partial::beside(path).map_err(io_err)?;
    match write_log_as(partial.path(), log, format, compression) {
        Ok(()) => partial.finish().map_err(io_err),
        Err(e) => {
            partial.discard();
            Err(e)
        }
    }
}

/// [`write_log`]'s writing, straight to `path`.
fn write_log_as(
    path: &Path,
    log: &Log,
    format: LogFormat,
    compression: McapCompression,
) -> Result<(), LogError> {
    match format {
        LogFormat::Mcap => write_mcap_with(path, log, compression),
        LogFormat::Csv => {
            let window = log.rows.len().min(RATE_WINDOW_STEPS + 1);
            regular::check_time_order(&log.path, &log.rows[..window])?;
            let io_err = |cause| LogError::Io {
                path: path.to_path_buf(),
                cause,
            };
            let mut out = std::io::BufWriter::new(std::fs::File::create(path).map_err(io_err)?);
            write_csv(&mut out, log).map_err(io_err)?;
            std::io::Write::flush(&mut out).map_err(io_err)
        }
    }
}

/// One row of a log as recorded (units converted to s, deg/s, deg, °C).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Row {
    /// 1-based line number in the file.
    pub line: u64,
    /// Time stamp (s).
    pub time_s: f64,
    /// Angular rate (deg/s); `None` if the field is empty or NaN.
    pub rate_dps: Option<f64>,
    /// Reference (encoder) angle (deg), if the log has one and the field is present.
    pub reference_deg: Option<f64>,
    /// Sensor temperature (°C), if present.
    pub temperature_c: Option<f64>,
}

/// A row at `time_s` turning 1 deg/s, nothing else (unit tests of the row stages).
#[cfg(test)]
pub(crate) fn test_row(line: u64, time_s: f64) -> Row {
    Row {
        line,
        time_s,
        rate_dps: Some(1.0),
        reference_deg: None,
        temperature_c: None,
    }
}

/// A log read into memory.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Log {
    /// Where it came from.
    pub path: PathBuf,
    /// `# key: value` metadata lines before the header.
    pub metadata: BTreeMap<String, String>,
    /// True if the log has a reference column.
    pub has_reference: bool,
    /// True if the log has a temperature column.
    pub has_temperature: bool,
    /// The rows in file order.
    pub rows: Vec<Row>,
}

impl Log {
    /// The `sample_rate_hz` metadata value, if present and a positive number.
    pub fn metadata_rate_hz(&self) -> Option<f64> {
        metadata_rate_hz(&self.metadata)
    }
}

/// The `sample_rate_hz` value of a log's metadata, if present and a positive number.
pub fn metadata_rate_hz(metadata: &BTreeMap<String, String>) -> Option<f64> {
    metadata
        .get(SAMPLE_RATE_KEY)
        .and_then(|v| v.trim().parse::<f64>().ok())
        .filter(|v| v.is_finite() && *v > 0.0)
}

/// The metadata key of the nominal sample rate (Hz), the one key the code acts on.
pub const SAMPLE_RATE_KEY: &str = "sample_rate_hz";

/// Check a `sample_rate_hz` metadata value as it is read: a positive, finite number of Hz,
/// the same as any value given before it (`previous`). The error says what is wrong.
pub(crate) fn check_rate_metadata(value: &str, previous: Option<&str>) -> Result<f64, String> {
    let shown = csv_log::excerpt(value.as_bytes());
    let rate = value
        .trim()
        .parse::<f64>()
        .ok()
        .filter(|v| v.is_finite() && *v > 0.0)
        .ok_or_else(|| {
            format!(
                "`{SAMPLE_RATE_KEY}: {shown}`: expected a positive number of Hz (e.g. `{SAMPLE_RATE_KEY}: 1000`)"
            )
        })?;
    match previous {
        Some(before) if before.trim().parse::<f64>().ok() != Some(rate) => Err(format!(
            "`{SAMPLE_RATE_KEY}` given twice with different values ({} and {shown}); keep one",
            csv_log::excerpt(before.as_bytes())
        )),
        _ => Ok(rate),
    }
}

/// A rate as errors show it: at most three decimals, no trailing zeros (`1000`, `108.509`);
/// beyond [`SHOWN_LIMIT`] as [`num`] shows it.
pub(crate) fn hz(rate_hz: f64) -> String {
    if rate_hz.abs() >= SHOWN_LIMIT || rate_hz.is_nan() {
        return num(rate_hz);
    }
    let text = format!("{rate_hz:.3}");
    text.trim_end_matches('0').trim_end_matches('.').to_string()
}

/// Magnitude from which messages show a number in exponent form.
const SHOWN_LIMIT: f64 = 1e15;

/// A number as messages show it: the shortest form that reads back the same (`0.5`,
/// `1000`), in exponent form from 1e15 on (`1e300`), so that a corrupt value cannot make a
/// message hundreds of digits long.
pub(crate) fn num(value: f64) -> String {
    if value.abs() < SHOWN_LIMIT || !value.is_finite() {
        format!("{value}")
    } else {
        format!("{value:e}")
    }
}

/// `value` with `decimals` decimals (`0.290000`), in exponent form from 1e15 on
/// (`-1.000000e300`) and below what the decimals show (`1.0000e-6`).
pub(crate) fn fixed(value: f64, decimals: usize) -> String {
    let shown = (0.1_f64.powi(decimals as i32)..SHOWN_LIMIT).contains(&value.abs());
    if shown || value == 0.0 || !value.is_finite() {
        format!("{value:.decimals$}")
    } else {
        format!("{value:.decimals$e}")
    }
}

/// The memory `slots` grid slots take (GiB).
fn gib(slots: f64) -> f64 {
    slots * std::mem::size_of::<Slot>() as f64 / f64::from(1_u32 << 30)
}

/// `": {line}"` for an error naming a line, else nothing.
fn at_line(line: &Option<u64>) -> String {
    line.map_or_else(String::new, |l| format!(":{l}"))
}

/// Why a log could not be read. Every variant names the file; row-level ones the line.
#[derive(Debug, thiserror::Error)]
pub enum LogError {
    /// The file could not be opened or read.
    #[error("{path}: {cause}")]
    Io {
        /// File.
        path: PathBuf,
        /// Cause (in the message, not chained: it would print twice).
        cause: std::io::Error,
    },
    /// The CSV structure is broken (e.g. a row with the wrong number of fields).
    #[error("{path}:{line}: {message}")]
    Csv {
        /// File.
        path: PathBuf,
        /// Line (1-based).
        line: u64,
        /// What is wrong.
        message: String,
    },
    /// No header line.
    #[error("{path}: no header line (expected e.g. `time_s,rate_dps,reference_deg`)")]
    NoHeader {
        /// File.
        path: PathBuf,
    },
    /// A required column is missing.
    #[error("{path}:{line}: no column `{column}` in the header (columns: {available}){hint}")]
    MissingColumn {
        /// File.
        path: PathBuf,
        /// Header line.
        line: u64,
        /// The column looked for.
        column: String,
        /// The header's columns.
        available: String,
        /// `; …`: the option that would read a column that looks meant (a time or rate
        /// column under another name, its unit from the name's suffix), or empty.
        hint: String,
    },
    /// A field is not a number.
    #[error("{path}:{line}: column `{column}`: `{value}` is not a number")]
    NotANumber {
        /// File.
        path: PathBuf,
        /// Line.
        line: u64,
        /// Column name.
        column: String,
        /// The field as written.
        value: String,
    },
    /// A field is a number no logger writes: too large for a double (`1e400`, a thousand
    /// digits) or too long to be one (a corrupt line).
    #[error(
        "{path}:{line}: column `{column}`: `{value}` {what}; a corrupt line? fix or delete it"
    )]
    NumberOutOfRange {
        /// File.
        path: PathBuf,
        /// Line.
        line: u64,
        /// Column name.
        column: String,
        /// The field as written (an excerpt).
        value: String,
        /// What is wrong with it.
        what: String,
    },
    /// A time stamp is missing or not finite.
    #[error("{path}:{line}: missing or non-finite time stamp in column `{column}`")]
    BadTime {
        /// File.
        path: PathBuf,
        /// Line.
        line: u64,
        /// Column name.
        column: String,
    },
    /// No data rows (or none with a usable rate).
    #[error("{path}: {what}")]
    NoData {
        /// File.
        path: PathBuf,
        /// What is missing.
        what: String,
    },
    /// A metadata value the code acts on is invalid (`sample_rate_hz` not a positive
    /// number, or given twice with different values).
    #[error("{path}{}: {message}", at_line(line))]
    Metadata {
        /// File.
        path: PathBuf,
        /// The metadata line (CSV); `None` for MCAP's metadata record.
        line: Option<u64>,
        /// What is wrong.
        message: String,
    },
    /// The sample rate given ([`GridOptions::sample_rate_hz`]) is not a positive number.
    #[error("{path}: the sample rate {} Hz is not a positive number", num(*rate_hz))]
    SampleRateInvalid {
        /// File.
        path: PathBuf,
        /// The rate given (Hz).
        rate_hz: f64,
    },
    /// The file is not text in UTF-8 (UTF-16, binary).
    #[error("{path}: {what}")]
    NotUtf8 {
        /// File.
        path: PathBuf,
        /// What it looks like.
        what: String,
    },
    /// The longest gap to bridge ([`GridOptions::max_gap_s`]) is not a finite number ≥ 0.
    #[error(
        "{path}: the longest gap to bridge, {} s, is not a finite number of seconds >= 0",
        num(*max_gap_s)
    )]
    MaxGapInvalid {
        /// File.
        path: PathBuf,
        /// The value given (s).
        max_gap_s: f64,
    },
    /// The sample rate given (option or metadata) disagrees with the time stamps.
    #[error(
        "{path}: the {source_name} gives {} Hz but the time stamps say {} Hz ({} times that); on the given rate every angle would be off by that factor",
        num(*rate_hz),
        fixed(*measured_hz, 6),
        fixed(*ratio, 4)
    )]
    SampleRateDisagrees {
        /// File.
        path: PathBuf,
        /// The rate given (Hz).
        rate_hz: f64,
        /// Where it came from: "option" or "metadata" (printed as a phrase).
        source_name: &'static str,
        /// The rate of the stamps (Hz): the mean of the single-period steps, or the mean row
        /// rate for rows arriving in bursts.
        measured_hz: f64,
        /// `measured_hz / rate_hz`.
        ratio: f64,
    },
    /// The grid would need more memory than allowed ([`MAX_BRIDGED_SLOTS`],
    /// [`MAX_HELD_SLOTS`]); refused before it is made.
    #[error(
        "{path}: {what} {} samples ({} GiB), more than the limit of {limit} ({:.1} GiB)",
        num(*samples),
        fixed(gib(*samples), 1),
        gib(*limit as f64)
    )]
    TooLarge {
        /// File.
        path: PathBuf,
        /// What would need them ("the grid at 1000 Hz holds").
        what: String,
        /// The samples it would need.
        samples: f64,
        /// The limit (samples).
        limit: u64,
    },
    /// No sample rate given, none in the metadata, and the stamps cannot give one.
    #[error(
        "{path}: cannot estimate the sample rate (fewer than two distinct time stamps); give the sample rate"
    )]
    SampleRateUnknown {
        /// File.
        path: PathBuf,
    },
    /// Every row is stamped alike: the stamps give no time.
    #[error(
        "{path}: all {rows} rows ({first_line} to {last_line}, by CSV line or MCAP message) are stamped {} s: the stamps give no time order; fix the time stamps",
        fixed(*time_s, 6)
    )]
    TimeConstant {
        /// File.
        path: PathBuf,
        /// Rows looked at.
        rows: u64,
        /// First row's line (CSV) or message index (MCAP).
        first_line: u64,
        /// Last row's line.
        last_line: u64,
        /// The one stamp (s).
        time_s: f64,
    },
    /// More steps back in time than forward: rows in reverse order.
    #[error(
        "{path}:{line}: time runs backwards: {back} of {steps} steps between rows go back; rows in reverse order? sort them by time"
    )]
    TimeReversed {
        /// File.
        path: PathBuf,
        /// Line (CSV) or message index (MCAP) of the first row stamped before the one
        /// ahead of it.
        line: u64,
        /// Steps back.
        back: u64,
        /// Steps looked at.
        steps: u64,
    },
    /// Time runs backwards by more than the tolerated amount.
    #[error(
        "{path}:{line}: time goes back by {} s (from {} s at line {previous_line} to {} s); concatenated or corrupt log?",
        fixed(*back_s, 6),
        fixed(*previous_s, 6),
        fixed(*time_s, 6)
    )]
    TimeBackwards {
        /// File.
        path: PathBuf,
        /// Line.
        line: u64,
        /// Line of the previous kept row.
        previous_line: u64,
        /// Previous time (s).
        previous_s: f64,
        /// This row's time (s).
        time_s: f64,
        /// How far back (s).
        back_s: f64,
    },
    /// A gap in time longer than the longest one bridged by interpolation.
    #[error(
        "{path}:{line}: gap of {} s in the data (after line {previous_line}) exceeds the longest gap bridged, {} s; the rotation during it cannot be recovered",
        fixed(*gap_s, 3),
        num(*max_gap_s)
    )]
    Gap {
        /// File.
        path: PathBuf,
        /// Line after the gap.
        line: u64,
        /// Line before the gap.
        previous_line: u64,
        /// Gap length (s).
        gap_s: f64,
        /// The limit (s).
        max_gap_s: f64,
    },
    /// An MCAP file that cannot be read (not MCAP, empty, corrupt) or written.
    #[error("{path}: {message}")]
    Mcap {
        /// File.
        path: PathBuf,
        /// What is wrong.
        message: String,
    },
    /// An MCAP channel the log needs has the wrong schema or encoding.
    #[error("{path}: channel `{channel}`: {message}")]
    McapChannel {
        /// File.
        path: PathBuf,
        /// Topic.
        channel: String,
        /// What is wrong.
        message: String,
    },
    /// Two channels carry rates; which one is the gyro must be chosen
    /// ([`McapOptions::topic`]).
    #[error("{path}: channel `{channel}`: a second rate channel besides `{first}`; choose one")]
    McapSecondRate {
        /// File.
        path: PathBuf,
        /// The second rate channel.
        channel: String,
        /// The first rate channel.
        first: String,
    },
    /// A ROS 2 message's header stamp is zero: the publisher did not set it; its log time
    /// can be used instead ([`McapOptions::time_source`]).
    #[error("{path}: channel `{channel}` message {index}: header stamp is zero (unset); use the log time")]
    McapZeroStamp {
        /// File.
        path: PathBuf,
        /// Topic.
        channel: String,
        /// 1-based index of the message on its channel.
        index: u64,
    },
    /// An MCAP message cannot be decoded.
    #[error("{path}: channel `{channel}` message {index}: {message}")]
    McapMessage {
        /// File.
        path: PathBuf,
        /// Topic.
        channel: String,
        /// 1-based index of the message on its channel.
        index: u64,
        /// What is wrong.
        message: String,
    },
    /// A setting of the other format was given: CSV columns and units for an MCAP log, MCAP
    /// channels and ROS 2 options for a CSV log. It would be ignored, so it is refused.
    #[error("{path}: is {format}; the setting `{setting}` applies only to {other} logs")]
    NotApplicable {
        /// File.
        path: PathBuf,
        /// The file's format ("an MCAP log", "a CSV log").
        format: &'static str,
        /// The setting given ([`ColumnOptions`] or [`McapOptions`] field name).
        setting: &'static str,
        /// The format it applies to.
        other: &'static str,
    },
    /// The file format is unknown or unsupported.
    #[error("{path}: {message}")]
    Format {
        /// File.
        path: PathBuf,
        /// What is wrong.
        message: String,
    },
}
