//! Recording the bridge: frames from a [`BridgeReader`] into an MCAP (or CSV) log as they
//! arrive, with every loss counted and written down.
//!
//! # What is written (MCAP)
//! | channel | content | log time |
//! |---|---|---|
//! | `/gyro` (`gyro.Sample`) | `rate_dps`, `temperature_c`, `status` of each frame | bridge timestamp |
//! | `/crm100/raw` (`crm100.BridgeFrame`) | every good bridge frame: `sequence`, `timestamp_us`, `command`, `hex` (the 6 response bytes), `checksum_ok` | bridge timestamp |
//! | `/crm100/events` (`crm100.Event`) | one message per loss or fault: `gap` (`from`, `to`, `lost`), `crc_error`, `skipped_bytes`, `checksum_error`, `status_fault`, `saturated`, `duplicate`, `backwards`, `command_mismatch` | bridge time of the last good frame |
//! | `/crm100/stats` (`crm100.Stats`) | the cumulative counters ([`RecordStats`]), every flush (0.25 s) and at the end | bridge time of the last good frame |
//!
//! plus a `gyro` metadata record: `sensor`, `sample_rate_hz`, `range_dps`, `lsb_per_dps`,
//! `bridge_format`, `time_base`, `source`, `checks`. `/gyro` is a ROS 2 message in CDR
//! (`gyro_msgs/msg/Sample`), every other channel a JSON channel with a `"type": "object"`
//! JSON schema (Foxglove plots the fields of both directly).
//!
//! # Frames that fail a check
//! The raw frame is always written to `/crm100/raw` and the failure is counted and written
//! to `/crm100/events`. The `/gyro` sample is written too, so the log keeps one row per
//! frame and `run` reports the bad ones as missing values (never interpolated silently):
//! - CRM100 checksum wrong: no word of the response can be trusted: `rate_dps`,
//!   `temperature_c` and `status` are `null`;
//! - status byte non-zero (its bits are undocumented): rate and temperature as decoded,
//!   `status` holds the byte, so a reader can drop or keep the sample;
//! - rate word beyond ±7200 counts: `rate_dps` is `null` (not a rate), temperature and
//!   status as decoded.
//!
//! A duplicate sequence number (the same frame again) is counted and kept in
//! `/crm100/raw` but not written to `/gyro` a second time.
//!
//! # Durability
//! The MCAP writer (chunks compressed as [`RecordOptions::compression`] says) closes a
//! chunk every 0.5 s of bridge time, and [`record`] also closes it and flushes every
//! [`RecordOptions::flush_interval`] (0.25 s) of wall time, so a killed recorder loses at
//! most about that much (under 0.5 s); Ctrl-C (the `stop` flag) finishes the file with its
//! summary. A killed file has no summary: every reader in `gyro_log` reads it up to its
//! unfinished last chunk, with a warning.

use crm100_driver::{
    BridgeFrame, BridgeReader, Checks, Range, ReadEvent, ReaderStats, Received, Response, SeqEvent,
    BRIDGE_FRAME_LEN, FORMAT_V1,
};
use gyro_log::mcap::RAW_TOPIC;
use gyro_log::{JsonChannel, LogError, McapCompression, McapLogWriter, McapWriteOptions};
use serde::Serialize;
use serde_json::json;
use std::collections::BTreeMap;
use std::fs::File;
use std::io::{self, BufWriter, ErrorKind, Read, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

/// Channel of the cumulative loss and fault counters.
pub const STATS_TOPIC: &str = "/crm100/stats";
/// Channel of the individual loss and fault events.
pub const EVENTS_TOPIC: &str = "/crm100/events";

/// How [`record`] decodes, and when it stops.
#[derive(Clone, Debug, PartialEq)]
pub struct RecordOptions {
    /// Range whose LSB scales the rate word.
    pub range: Range,
    /// Verify the CRM100 response checksum (default on).
    pub verify_checksum: bool,
    /// Nominal frame rate (Hz), written to the metadata (`sample_rate_hz`).
    pub sample_rate_hz: f64,
    /// Stop after this much wall time.
    pub duration: Option<Duration>,
    /// Stop when no byte arrived for this long.
    pub idle_stop: Option<Duration>,
    /// Flush the output (close the MCAP chunk) at least this often (wall time), and write
    /// a `/crm100/stats` message each time. Default 0.25 s (a killed recorder loses less than 0.5 s).
    pub flush_interval: Duration,
    /// Call the status callback this often. Default 0.25 s.
    pub status_interval: Duration,
    /// Description of the source for the metadata (`source`), e.g. the port and baud rate.
    pub source: String,
    /// How [`McapSink`] compresses its chunks (a CSV has none). Default zstd, as every
    /// MCAP writer of gyro-cli.
    pub compression: McapCompression,
}

impl Default for RecordOptions {
    fn default() -> Self {
        RecordOptions {
            range: Range::Dps300,
            verify_checksum: true,
            sample_rate_hz: 1000.0,
            duration: None,
            idle_stop: None,
            flush_interval: Duration::from_millis(250),
            status_interval: Duration::from_millis(250),
            source: String::new(),
            compression: McapCompression::default(),
        }
    }
}

impl RecordOptions {
    /// The checks applied to each response: checksum as configured, status and saturation
    /// flagged, never refused (the sample is written with what it says; see the module
    /// docs).
    pub fn checks(&self) -> Checks {
        Checks {
            verify_checksum: self.verify_checksum,
            reject_status_fault: false,
            reject_saturated: false,
        }
    }

    /// The metadata written at the start of a recording.
    pub fn metadata(&self) -> BTreeMap<String, String> {
        let mut m = BTreeMap::new();
        m.insert("sensor".into(), "CRM100".into());
        m.insert("sample_rate_hz".into(), format!("{}", self.sample_rate_hz));
        m.insert("range_dps".into(), self.range.full_scale_dps().to_string());
        m.insert("lsb_per_dps".into(), self.range.lsb_per_dps().to_string());
        m.insert(
            "bridge_format".into(),
            format!(
                "crm100-bridge format {FORMAT_V1}: {BRIDGE_FRAME_LEN}-byte frames, sync a5 5a, u32 sequence, u64 timestamp_us, 6 response bytes, CRC-16/CCITT-FALSE (little-endian)"
            ),
        );
        m.insert(
            "time_base".into(),
            "bridge clock: log time = bridge timestamp_us x 1000 ns".into(),
        );
        m.insert(
            "checks".into(),
            format!(
                "crm100 checksum {}; status and saturation flagged, not refused",
                if self.verify_checksum {
                    "verified"
                } else {
                    "not verified"
                }
            ),
        );
        if !self.source.is_empty() {
            m.insert("source".into(), self.source.clone());
        }
        m.insert(
            "recorded_by".into(),
            concat!("gyro-cli ", env!("CARGO_PKG_VERSION")).into(),
        );
        m
    }
}

/// Cumulative counters of a recording (the `/crm100/stats` message and the summary).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
pub struct RecordStats {
    /// Good bridge frames (CRC passed), all written to `/crm100/raw`.
    pub frames: u64,
    /// `/gyro` messages (or CSV rows) written.
    pub samples: u64,
    /// Samples among them with a rate (no check failed on the rate).
    pub samples_with_rate: u64,
    /// Frames lost, from sequence gaps.
    pub frames_lost: u64,
    /// Sequence gaps.
    pub gaps: u64,
    /// Bridge frames that failed their CRC.
    pub crc_errors: u64,
    /// Bytes dropped by the decoder (noise, damaged and truncated frames).
    pub bytes_skipped: u64,
    /// Bytes received.
    pub bytes_received: u64,
    /// Responses failing the CRM100 checksum.
    pub checksum_errors: u64,
    /// Responses with a non-zero status byte.
    pub status_faults: u64,
    /// Responses with a rate word beyond full scale.
    pub saturated: u64,
    /// Frames whose sequence number repeated the previous one.
    pub duplicates: u64,
    /// Steps back of the sequence number (bridge restarts).
    pub backwards: u64,
    /// Frames whose command byte selects another range than the one decoding them.
    pub command_mismatches: u64,
    /// Read timeouts (quiet line).
    pub timeouts: u64,
    /// Good frames stamped earlier than the good frame before them (the bridge clock
    /// stepped back: a restart, a wrap).
    pub clock_steps_back: u64,
    /// The largest of those steps back (µs).
    pub largest_clock_step_back_us: u64,
    /// Bridge time covered (µs): the sum of the forward steps between consecutive good
    /// frames' timestamps (a step back adds nothing).
    pub bridge_time_us: u64,
    /// Bridge timestamp of the first good frame (µs).
    pub first_timestamp_us: Option<u64>,
    /// Bridge timestamp of the last good frame (µs).
    pub last_timestamp_us: Option<u64>,
}

impl RecordStats {
    fn absorb(&mut self, reader: &ReaderStats) {
        let r = reader.receiver;
        self.frames_lost = r.sequence.frames_lost;
        self.gaps = r.sequence.gaps;
        self.crc_errors = r.decoder.crc_errors;
        self.bytes_skipped = r.decoder.bytes_skipped;
        self.bytes_received = r.decoder.bytes_received;
        self.duplicates = r.sequence.duplicates;
        self.backwards = r.sequence.backwards;
        self.timeouts = reader.timeouts;
    }

    /// Bridge time covered (s): the forward steps of the bridge clock from the first to
    /// the last good frame (steps back, counted in `clock_steps_back`, add nothing).
    pub fn bridge_span_s(&self) -> f64 {
        self.bridge_time_us as f64 * 1e-6
    }
}

/// One decoded frame, as handed to a [`RecordSink`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DecodedFrame {
    /// The bridge frame.
    pub frame: BridgeFrame,
    /// `false` if the CRM100 checksum failed (the words are then not trusted).
    pub checksum_ok: bool,
    /// Rate (°/s); `None` if the checksum failed or the word is beyond full scale.
    pub rate_dps: Option<f64>,
    /// Temperature (°C); `None` if the checksum failed.
    pub temperature_c: Option<f64>,
    /// Raw status byte; `None` if the checksum failed.
    pub status: Option<u8>,
    /// Write a `/gyro` sample for it (`false` for a duplicate).
    pub sample: bool,
}

/// Decodes a response: rate and temperature in f64 (exact quotients of the words).
fn decode(
    frame: &BridgeFrame,
    range: Range,
    checks: Checks,
    stats: &mut RecordStats,
) -> DecodedFrame {
    let (checksum_ok, rate_dps, temperature_c, status) =
        match Response::from_bytes(&frame.response, checks.verify_checksum) {
            Err(_) => {
                stats.checksum_errors += 1;
                (false, None, None, None)
            }
            Ok(response) => {
                let status = response.status.raw();
                if response.status.is_fault() {
                    stats.status_faults += 1;
                }
                let rate = if response.is_saturated() {
                    stats.saturated += 1;
                    None
                } else {
                    Some(f64::from(response.rate_counts) / f64::from(range.lsb_per_dps()))
                };
                let temperature = (f64::from(response.temperature_word)
                    - f64::from(crm100_driver::TEMPERATURE_OFFSET_WORD))
                    / f64::from(crm100_driver::TEMPERATURE_LSB_PER_C);
                (true, rate, Some(temperature), Some(status))
            }
        };
    DecodedFrame {
        frame: *frame,
        checksum_ok,
        rate_dps,
        temperature_c,
        status,
        sample: true,
    }
}

/// A loss or fault, as written to `/crm100/events`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(tag = "event", rename_all = "snake_case")]
pub enum RecordEvent {
    /// Frames lost between two good frames.
    Gap {
        /// Sequence number before the gap.
        from: u32,
        /// Sequence number after it.
        to: u32,
        /// Frames missing.
        lost: u32,
    },
    /// A bridge frame failed its CRC.
    CrcError {
        /// CRC computed.
        expected: u16,
        /// CRC received.
        found: u16,
    },
    /// Bytes dropped by the decoder.
    SkippedBytes {
        /// How many.
        bytes: u64,
    },
    /// The CRM100 checksum failed.
    ChecksumError {
        /// The frame's sequence number.
        sequence: u32,
    },
    /// Non-zero status byte.
    StatusFault {
        /// The frame's sequence number.
        sequence: u32,
        /// The status byte.
        status: u8,
    },
    /// Rate word beyond full scale.
    Saturated {
        /// The frame's sequence number.
        sequence: u32,
    },
    /// Same sequence number as the previous frame.
    Duplicate {
        /// The sequence number.
        sequence: u32,
    },
    /// The sequence number went back (bridge restart).
    Backwards {
        /// Previous sequence number.
        from: u32,
        /// This one.
        to: u32,
    },
    /// The bridge clock stepped back: the frame is stamped before the good frame ahead of
    /// it (a restart, a wrap, a corrupt stamp).
    ClockBack {
        /// The frame's sequence number.
        sequence: u32,
        /// The previous good frame's timestamp (µs).
        from_us: u64,
        /// This frame's (µs).
        to_us: u64,
    },
    /// The frame's command byte selects another range than the one decoding it.
    CommandMismatch {
        /// The frame's sequence number.
        sequence: u32,
        /// Its command byte.
        command: u8,
    },
}

/// Where [`record`] writes: MCAP ([`McapSink`]) or CSV ([`CsvSink`]).
pub trait RecordSink {
    /// One good bridge frame, decoded.
    fn frame(&mut self, decoded: &DecodedFrame) -> Result<(), LogError>;
    /// One loss or fault, at bridge time `time_ns`.
    fn event(&mut self, time_ns: u64, event: &RecordEvent) -> Result<(), LogError>;
    /// The counters so far, at bridge time `time_ns`.
    fn stats(&mut self, time_ns: u64, stats: &RecordStats) -> Result<(), LogError>;
    /// Make everything written so far durable against a kill.
    fn flush(&mut self) -> Result<(), LogError>;
    /// Finish the file.
    fn finish(self: Box<Self>) -> Result<(), LogError>;
}

/// Writes a recording as MCAP (see the module docs for the channels).
pub struct McapSink {
    writer: McapLogWriter,
    raw: JsonChannel,
    events: JsonChannel,
    stats: JsonChannel,
}

const RAW_FRAME_SCHEMA: &str = r#"{
  "title": "crm100.BridgeFrame",
  "description": "One good serial-bridge frame; log_time is its bridge timestamp (ns)",
  "type": "object",
  "properties": {
    "sequence": {"type": "integer", "minimum": 0, "description": "bridge sequence number (u32, wraps)"},
    "timestamp_us": {"type": "integer", "minimum": 0, "description": "bridge clock when CS went low (us)"},
    "command": {"type": "integer", "minimum": 0, "maximum": 255, "description": "command byte of the SPI transfer"},
    "hex": {"type": "string", "description": "the 6 CRM100 response bytes, lowercase hex"},
    "checksum_ok": {"type": "boolean", "description": "the CRM100 response checksum matched (true if not verified)"}
  },
  "required": ["sequence", "timestamp_us", "command", "hex", "checksum_ok"]
}"#;

const EVENT_SCHEMA: &str = r#"{
  "title": "crm100.Event",
  "description": "A loss or fault seen while recording; log_time is the bridge time of the last good frame (ns)",
  "type": "object",
  "properties": {
    "event": {"type": "string", "enum": ["gap", "crc_error", "skipped_bytes", "checksum_error", "status_fault", "saturated", "duplicate", "backwards", "clock_back", "command_mismatch"]},
    "from": {"type": "integer"}, "to": {"type": "integer"}, "lost": {"type": "integer"},
    "expected": {"type": "integer"}, "found": {"type": "integer"},
    "bytes": {"type": "integer"}, "sequence": {"type": "integer"},
    "status": {"type": "integer"}, "command": {"type": "integer"},
    "from_us": {"type": "integer"}, "to_us": {"type": "integer"}
  },
  "required": ["event"]
}"#;

fn stats_schema() -> serde_json::Value {
    let counter = |d: &str| json!({"type": "integer", "minimum": 0, "description": d});
    json!({
        "title": "crm100.Stats",
        "description": "Cumulative counters of the recording; log_time is the bridge time of the last good frame (ns)",
        "type": "object",
        "properties": {
            "frames": counter("good bridge frames"),
            "samples": counter("/gyro messages written"),
            "samples_with_rate": counter("/gyro messages with a rate"),
            "frames_lost": counter("frames lost (sequence gaps)"),
            "gaps": counter("sequence gaps"),
            "crc_errors": counter("bridge frames failing the CRC"),
            "bytes_skipped": counter("bytes dropped by the decoder"),
            "bytes_received": counter("bytes received"),
            "checksum_errors": counter("CRM100 checksum failures"),
            "status_faults": counter("non-zero status bytes"),
            "saturated": counter("rate words beyond full scale"),
            "duplicates": counter("repeated sequence numbers"),
            "backwards": counter("sequence steps back"),
            "command_mismatches": counter("command byte of another range"),
            "timeouts": counter("read timeouts"),
            "clock_steps_back": counter("good frames stamped before the previous good frame"),
            "largest_clock_step_back_us": counter("the largest of those steps back (us)"),
            "bridge_time_us": counter("forward steps of the bridge clock, summed (us)"),
            "first_timestamp_us": {"type": ["integer", "null"]},
            "last_timestamp_us": {"type": ["integer", "null"]}
        },
        "required": ["frames", "frames_lost", "crc_errors", "bytes_skipped"]
    })
}

impl McapSink {
    /// Creates `path` with the channels and the metadata of `options`.
    pub fn create(path: &Path, options: &RecordOptions) -> Result<Self, LogError> {
        let mut writer = McapLogWriter::create_with(
            path,
            McapWriteOptions {
                compression: options.compression,
                ..McapWriteOptions::default()
            },
        )?;
        writer.write_metadata(&options.metadata())?;
        let schema = |text: &str| -> Result<serde_json::Value, LogError> {
            serde_json::from_str(text).map_err(|e| LogError::Mcap {
                path: path.to_path_buf(),
                message: format!("internal schema: {e}"),
            })
        };
        let raw =
            writer.add_json_channel(RAW_TOPIC, "crm100.BridgeFrame", &schema(RAW_FRAME_SCHEMA)?)?;
        let events =
            writer.add_json_channel(EVENTS_TOPIC, "crm100.Event", &schema(EVENT_SCHEMA)?)?;
        let stats = writer.add_json_channel(STATS_TOPIC, "crm100.Stats", &stats_schema())?;
        Ok(McapSink {
            writer,
            raw,
            events,
            stats,
        })
    }
}

fn to_value(path: &Path, value: &impl Serialize) -> Result<serde_json::Value, LogError> {
    serde_json::to_value(value).map_err(|e| LogError::Mcap {
        path: path.to_path_buf(),
        message: format!("cannot encode a message: {e}"),
    })
}

fn hex(bytes: &[u8]) -> String {
    use std::fmt::Write as _;
    let mut s = String::with_capacity(bytes.len() * 2);
    for b in bytes {
        let _ = write!(s, "{b:02x}");
    }
    s
}

/// Bridge timestamp (µs) as a log time (ns).
pub fn timestamp_ns(timestamp_us: u64) -> u64 {
    timestamp_us.saturating_mul(1000)
}

impl RecordSink for McapSink {
    fn frame(&mut self, d: &DecodedFrame) -> Result<(), LogError> {
        let time_ns = timestamp_ns(d.frame.timestamp_us);
        let raw = json!({
            "sequence": d.frame.sequence,
            "timestamp_us": d.frame.timestamp_us,
            "command": d.frame.command,
            "hex": hex(&d.frame.response),
            "checksum_ok": d.checksum_ok,
        });
        self.writer.write_json(self.raw, time_ns, &raw)?;
        if d.sample {
            self.writer.write_gyro(
                time_ns,
                d.rate_dps,
                d.temperature_c,
                d.status.map(u32::from),
            )?;
        }
        Ok(())
    }

    fn event(&mut self, time_ns: u64, event: &RecordEvent) -> Result<(), LogError> {
        let value = to_value(self.writer.path(), event)?;
        self.writer.write_json(self.events, time_ns, &value)
    }

    fn stats(&mut self, time_ns: u64, stats: &RecordStats) -> Result<(), LogError> {
        let value = to_value(self.writer.path(), stats)?;
        self.writer.write_json(self.stats, time_ns, &value)
    }

    fn flush(&mut self) -> Result<(), LogError> {
        self.writer.flush()
    }

    fn finish(self: Box<Self>) -> Result<(), LogError> {
        self.writer.finish()
    }
}

/// Writes a recording as CSV: the metadata as `# key: value` lines, then
/// `time_s,rate_dps,temperature_c,status,sequence,raw` (empty fields where the MCAP has
/// `null`; `raw` is the response in hex). Events and counters are not in the CSV: they go
/// to the summary.
pub struct CsvSink {
    path: PathBuf,
    out: BufWriter<File>,
}

impl CsvSink {
    /// Creates `path` and writes the metadata and header.
    pub fn create(path: &Path, options: &RecordOptions) -> Result<Self, LogError> {
        let io_err = |cause| LogError::Io {
            path: path.to_path_buf(),
            cause,
        };
        let mut out = BufWriter::with_capacity(1 << 16, File::create(path).map_err(io_err)?);
        let mut head = || -> io::Result<()> {
            for (key, value) in options.metadata() {
                writeln!(out, "# {key}: {value}")?;
            }
            writeln!(out, "time_s,rate_dps,temperature_c,status,sequence,raw")?;
            out.flush()
        };
        head().map_err(io_err)?;
        Ok(CsvSink {
            path: path.to_path_buf(),
            out,
        })
    }

    fn io_err(&self, cause: io::Error) -> LogError {
        LogError::Io {
            path: self.path.clone(),
            cause,
        }
    }
}

impl RecordSink for CsvSink {
    fn frame(&mut self, d: &DecodedFrame) -> Result<(), LogError> {
        if !d.sample {
            return Ok(());
        }
        let field = |v: Option<f64>| v.map_or_else(String::new, |v| format!("{v}"));
        let us = d.frame.timestamp_us;
        let written = writeln!(
            self.out,
            "{}.{:06},{},{},{},{},{}",
            us / 1_000_000,
            us % 1_000_000,
            field(d.rate_dps),
            field(d.temperature_c),
            d.status.map_or_else(String::new, |s| s.to_string()),
            d.frame.sequence,
            hex(&d.frame.response),
        );
        written.map_err(|e| self.io_err(e))
    }

    fn event(&mut self, _time_ns: u64, _event: &RecordEvent) -> Result<(), LogError> {
        Ok(())
    }

    fn stats(&mut self, _time_ns: u64, _stats: &RecordStats) -> Result<(), LogError> {
        Ok(())
    }

    fn flush(&mut self) -> Result<(), LogError> {
        self.out.flush().map_err(|e| self.io_err(e))
    }

    fn finish(mut self: Box<Self>) -> Result<(), LogError> {
        self.out.flush().map_err(|e| self.io_err(e))?;
        self.out.get_ref().sync_all().map_err(|e| self.io_err(e))
    }
}

/// Why a recording ended.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum StopReason {
    /// The stop flag was set (Ctrl-C).
    Interrupted,
    /// [`RecordOptions::duration`] elapsed.
    Duration,
    /// No byte for [`RecordOptions::idle_stop`].
    Idle,
    /// The source ended (end of file).
    EndOfStream,
    /// The port hung up (device unplugged, the other end of a pseudo-terminal closed).
    PortClosed,
    /// Reading the port failed.
    PortError(String),
}

impl std::fmt::Display for StopReason {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            StopReason::Interrupted => write!(f, "interrupted"),
            StopReason::Duration => write!(f, "duration reached"),
            StopReason::Idle => write!(f, "no data (idle timeout)"),
            StopReason::EndOfStream => write!(f, "end of stream"),
            StopReason::PortClosed => write!(f, "port closed"),
            StopReason::PortError(e) => write!(f, "port error: {e}"),
        }
    }
}

/// The result of [`record`].
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct RecordSummary {
    /// Counters.
    pub stats: RecordStats,
    /// Wall time recorded (s).
    pub elapsed_s: f64,
    /// Why it ended.
    pub stop: StopReason,
}

impl std::fmt::Display for RecordSummary {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let s = &self.stats;
        writeln!(
            f,
            "recorded {:.1} s ({:.3} s of bridge time), stopped: {}",
            self.elapsed_s,
            s.bridge_span_s(),
            self.stop
        )?;
        writeln!(
            f,
            "frames {}  samples {} ({} with a rate)  lost {} in {} gaps  CRC errors {}  skipped bytes {}",
            s.frames, s.samples, s.samples_with_rate, s.frames_lost, s.gaps, s.crc_errors, s.bytes_skipped
        )?;
        write!(
            f,
            "checksum errors {}  status faults {}  saturated {}  duplicates {}  backwards {}  command mismatches {}  timeouts {}",
            s.checksum_errors, s.status_faults, s.saturated, s.duplicates, s.backwards, s.command_mismatches, s.timeouts
        )?;
        if s.clock_steps_back > 0 {
            write!(
                f,
                "\nwarning: the bridge clock stepped back {} times, by up to {:.6} s (a restart?): every frame is kept at its own stamp (each step back in /crm100/events, `clock_back`); bridge time counts the forward steps only, and the log's times go back there: readers refuse a step back of more than 0.5 s",
                s.clock_steps_back,
                s.largest_clock_step_back_us as f64 * 1e-6
            )?;
        }
        Ok(())
    }
}

/// What the status callback sees, a few times per second.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LiveStatus {
    /// Counters so far.
    pub stats: RecordStats,
    /// Last rate (°/s).
    pub rate_dps: Option<f64>,
    /// Last temperature (°C).
    pub temperature_c: Option<f64>,
    /// Good frames per second of wall time since the previous call.
    pub frames_per_s: f64,
    /// Wall time since the start (s).
    pub elapsed_s: f64,
}

/// Records from `reader` into `sink` until `stop` is set, the duration or idle time of
/// `options` runs out, or the source ends; then writes the final counters and finishes the
/// sink. Port errors end the recording (the file is still finished) and are the
/// [`StopReason`]; only output errors are returned as errors.
pub fn record<R: Read>(
    reader: &mut BridgeReader<R>,
    mut sink: Box<dyn RecordSink>,
    options: &RecordOptions,
    stop: &AtomicBool,
    status: &mut dyn FnMut(&LiveStatus),
) -> Result<RecordSummary, LogError> {
    let mut rec = Recording::new(Instant::now(), options.checks());
    let stop_reason = loop {
        if stop.load(Ordering::Relaxed) {
            break StopReason::Interrupted;
        }
        let now = Instant::now();
        if options.duration.is_some_and(|d| now - rec.start >= d) {
            break StopReason::Duration;
        }
        if options.idle_stop.is_some_and(|d| now - rec.last_data >= d) {
            break StopReason::Idle;
        }
        if now - rec.last_flush >= options.flush_interval {
            rec.flush(now, reader, &mut *sink)?;
        }
        if now - rec.last_status >= options.status_interval {
            rec.report_status(now, reader, status);
        }
        let event = match reader.next_event() {
            Ok(Some(event)) => event,
            Ok(None) => break StopReason::EndOfStream,
            Err(e) if e.kind() == ErrorKind::BrokenPipe => break StopReason::PortClosed,
            Err(e) => break StopReason::PortError(e.to_string()),
        };
        rec.event(event, now, options, &mut *sink)?;
    };
    rec.finish(reader, sink, stop_reason)
}

/// The state of a recording from one event to the next: counters, when things were last
/// done, and the last values for the status.
struct Recording {
    start: Instant,
    checks: Checks,
    stats: RecordStats,
    /// Log time of the last frame (ns), which events and counters are stamped with.
    last_ns: u64,
    last_data: Instant,
    last_flush: Instant,
    last_status: Instant,
    frames_at_status: u64,
    last_rate: Option<f64>,
    last_temperature: Option<f64>,
    /// Something happened since the counters were last written.
    dirty: bool,
    /// Skipped bytes already written as events.
    skipped_reported: u64,
}

impl Recording {
    fn new(start: Instant, checks: Checks) -> Self {
        Self {
            start,
            checks,
            stats: RecordStats::default(),
            last_ns: 0,
            last_data: start,
            last_flush: start,
            last_status: start,
            frames_at_status: 0,
            last_rate: None,
            last_temperature: None,
            dirty: false,
            skipped_reported: 0,
        }
    }

    /// Write the counters (if they changed) and flush the sink.
    fn flush<R: Read>(
        &mut self,
        now: Instant,
        reader: &BridgeReader<R>,
        sink: &mut dyn RecordSink,
    ) -> Result<(), LogError> {
        self.stats.absorb(&reader.stats());
        if self.dirty {
            sink.stats(self.last_ns, &self.stats)?;
            self.dirty = false;
        }
        sink.flush()?;
        self.last_flush = now;
        Ok(())
    }

    /// Give `status` the counters, the last values and the frame rate since the last call.
    fn report_status<R: Read>(
        &mut self,
        now: Instant,
        reader: &BridgeReader<R>,
        status: &mut dyn FnMut(&LiveStatus),
    ) {
        self.stats.absorb(&reader.stats());
        let dt = (now - self.last_status).as_secs_f64();
        status(&LiveStatus {
            stats: self.stats,
            rate_dps: self.last_rate,
            temperature_c: self.last_temperature,
            frames_per_s: (self.stats.frames - self.frames_at_status) as f64 / dt,
            elapsed_s: (now - self.start).as_secs_f64(),
        });
        self.frames_at_status = self.stats.frames;
        self.last_status = now;
    }

    /// One event read at `now`: a frame recorded, a CRC error or skipped bytes written.
    fn event(
        &mut self,
        event: ReadEvent,
        now: Instant,
        options: &RecordOptions,
        sink: &mut dyn RecordSink,
    ) -> Result<(), LogError> {
        match event {
            ReadEvent::Timeout | ReadEvent::Interrupted => {}
            ReadEvent::Frame(received) => {
                self.last_data = now;
                self.dirty = true;
                let d = handle_frame(&received, options, self.checks, &mut self.stats, sink)?;
                self.last_ns = timestamp_ns(received.frame.timestamp_us);
                if d.checksum_ok {
                    self.last_rate = d.rate_dps;
                    self.last_temperature = d.temperature_c;
                }
            }
            ReadEvent::Crc(error) => {
                self.last_data = now;
                self.dirty = true;
                if let crm100_driver::BridgeError::Crc { expected, found } = error {
                    sink.event(self.last_ns, &RecordEvent::CrcError { expected, found })?;
                }
            }
            ReadEvent::Skipped { bytes } => {
                self.last_data = now;
                self.dirty = true;
                self.skipped_reported += bytes;
                sink.event(self.last_ns, &RecordEvent::SkippedBytes { bytes })?;
            }
        }
        Ok(())
    }

    /// End the recording stopped for `stop`: the skipped bytes not yet reported, the final
    /// counters, the sink finished.
    fn finish<R: Read>(
        mut self,
        reader: &mut BridgeReader<R>,
        mut sink: Box<dyn RecordSink>,
        stop: StopReason,
    ) -> Result<RecordSummary, LogError> {
        let last_ns = self.last_ns;
        // A partial frame left in the decoder can no longer complete: report it with any
        // skipped bytes not reported yet.
        reader.discard_partial();
        self.stats.absorb(&reader.stats());
        if self.stats.bytes_skipped > self.skipped_reported {
            let bytes = self.stats.bytes_skipped - self.skipped_reported;
            sink.event(last_ns, &RecordEvent::SkippedBytes { bytes })?;
        }
        sink.stats(last_ns, &self.stats)?;
        sink.finish()?;
        Ok(RecordSummary {
            stats: self.stats,
            elapsed_s: self.start.elapsed().as_secs_f64(),
            stop,
        })
    }
}

/// One frame: the bridge clock and the sequence tracked, the frame decoded and written,
/// each fault written as an event and counted.
fn handle_frame(
    received: &Received,
    options: &RecordOptions,
    checks: Checks,
    stats: &mut RecordStats,
    sink: &mut dyn RecordSink,
) -> Result<DecodedFrame, LogError> {
    let frame = received.frame;
    let time_ns = timestamp_ns(frame.timestamp_us);
    stats.frames += 1;
    track_bridge_clock(&frame, time_ns, stats, sink)?;
    write_sequence_event(received, time_ns, sink)?;
    if Range::from_command(frame.command).is_some_and(|r| r != options.range) {
        stats.command_mismatches += 1;
        sink.event(
            time_ns,
            &RecordEvent::CommandMismatch {
                sequence: frame.sequence,
                command: frame.command,
            },
        )?;
    }
    let before = *stats;
    let mut d = decode(&frame, options.range, checks, stats);
    d.sample = received.sequence != SeqEvent::Duplicate;
    let sequence = frame.sequence;
    if stats.checksum_errors > before.checksum_errors {
        sink.event(time_ns, &RecordEvent::ChecksumError { sequence })?;
    }
    if let (true, Some(status)) = (stats.status_faults > before.status_faults, d.status) {
        sink.event(time_ns, &RecordEvent::StatusFault { sequence, status })?;
    }
    if stats.saturated > before.saturated {
        sink.event(time_ns, &RecordEvent::Saturated { sequence })?;
    }
    sink.frame(&d)?;
    if d.sample {
        stats.samples += 1;
        stats.samples_with_rate += u64::from(d.rate_dps.is_some());
    }
    Ok(d)
}

/// The bridge clock at `frame` (logged at `time_ns`): its forward steps added to the
/// bridge time, a step back counted and written as an event.
fn track_bridge_clock(
    frame: &BridgeFrame,
    time_ns: u64,
    stats: &mut RecordStats,
    sink: &mut dyn RecordSink,
) -> Result<(), LogError> {
    stats.first_timestamp_us.get_or_insert(frame.timestamp_us);
    if let Some(last) = stats.last_timestamp_us {
        match frame.timestamp_us.checked_sub(last) {
            Some(step) => stats.bridge_time_us = stats.bridge_time_us.saturating_add(step),
            None => {
                // Said in `/crm100/events` and the summary; the frame is kept, at its own
                // stamp (a reader refuses or re-times what goes back, and says so).
                let back_us = last - frame.timestamp_us;
                stats.clock_steps_back += 1;
                stats.largest_clock_step_back_us = stats.largest_clock_step_back_us.max(back_us);
                sink.event(
                    time_ns,
                    &RecordEvent::ClockBack {
                        sequence: frame.sequence,
                        from_us: last,
                        to_us: frame.timestamp_us,
                    },
                )?;
            }
        }
    }
    stats.last_timestamp_us = Some(frame.timestamp_us);
    Ok(())
}

/// A gap, duplicate or step back in the sequence of `received`, written as an event.
fn write_sequence_event(
    received: &Received,
    time_ns: u64,
    sink: &mut dyn RecordSink,
) -> Result<(), LogError> {
    let frame = received.frame;
    match received.sequence {
        SeqEvent::Gap(gap) => sink.event(
            time_ns,
            &RecordEvent::Gap {
                from: gap.from,
                to: gap.to,
                lost: gap.lost,
            },
        )?,
        SeqEvent::Duplicate => sink.event(
            time_ns,
            &RecordEvent::Duplicate {
                sequence: frame.sequence,
            },
        )?,
        SeqEvent::Backwards { from, to } => {
            sink.event(time_ns, &RecordEvent::Backwards { from, to })?
        }
        SeqEvent::First | SeqEvent::InOrder => {}
    }
    Ok(())
}
