//! Reading MCAP logs as a stream: records are pulled through a buffered file (memory
//! scales with the largest chunk, not the file), rows assembled from the rate channel,
//! reference samples attached by time.
//!
//! # Which channel gives the rate
//! `--topic` if given (a JSON channel like `/gyro`, or a ROS 2 `sensor_msgs/msg/Imu`);
//! otherwise `/gyro`, or else the one `sensor_msgs/msg/Imu` channel in CDR. If two such
//! channels carry messages, reading fails and asks for `--topic`. Other channels are
//! skipped without being decoded.
//!
//! # Time
//! `time_s` is the log time (JSON channels) or the chosen ROS 2 stamp, in seconds. ROS 2
//! stamps count from the Unix epoch, where an `f64` second resolves only about 0.24 µs; so
//! for an Imu channel `time_s` counts from the whole second at or before the earliest
//! sample, and the metadata key [`TIME_ORIGIN_KEY`] holds that second.
//!
//! # Reference attachment
//! Reference samples (`/reference`, `{"angle_deg": f64|null}`) are attached to rate rows by
//! log time, after the whole file is read (so neither channel needs to be sorted):
//! - a reference message at exactly a row's time gives that row its value (`null`: the row
//!   has no reference); the k-th of several rows with one time stamp takes the k-th
//!   reference message with that time, in file order;
//! - otherwise the value is interpolated linearly between the latest earlier and the
//!   earliest later reference message, if both are non-null and at most
//!   [`REFERENCE_MAX_SPAN_S`] apart;
//! - otherwise (before the first or after the last reference, across a longer gap or a
//!   `null`) the row has none. Nothing is extrapolated.
//!
//! # Damaged files
//! A file that ends with the MCAP magic was finished by its writer: any unreadable record
//! in it is an error. A file without it is an interrupted recording or a cut copy: every
//! record up to the first incomplete or unreadable one is used (chunks are CRC-checked
//! before any of their messages is), and a warning says what was lost. Bad magic, an empty
//! file, a wrong schema on a known channel or an undecodable message are one-line errors
//! naming the file (and the channel and 1-based message index on that channel).

use super::ros2::{decode_imu, Axis, TimeSource, IMU_SCHEMA_NAME};
use super::{ns_to_seconds, GYRO_TOPIC, MAGIC, METADATA_NAME, REFERENCE_TOPIC};
use crate::{Log, LogError, Row};
use mcap::records::{op, Record};
use mcap::sans_io::{LinearReadEvent, LinearReader, LinearReaderOptions};
use mcap::McapError;
use serde::{Deserialize, Deserializer};
use std::collections::{BTreeMap, BTreeSet, HashMap};
use std::fs::File;
use std::io::{BufReader, ErrorKind, Read, Seek, SeekFrom};
use std::path::Path;

/// Longest time (s) between two reference samples across which a rate row's reference is
/// interpolated.
pub const REFERENCE_MAX_SPAN_S: f64 = 0.5;

/// Metadata key set for ROS 2 logs: the source-clock time (whole seconds; ROS time counts
/// from the Unix epoch) at which the log's `time_s` is 0.
pub const TIME_ORIGIN_KEY: &str = "time_origin_s";

/// Records (and chunks) larger than this are treated as corrupt rather than allocated.
const RECORD_LENGTH_LIMIT: usize = 1 << 30;

/// How to read an MCAP log (ignored for CSV).
#[derive(Clone, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "clap", derive(clap::Args))]
pub struct McapOptions {
    /// MCAP: channel with the rate, a JSON channel like `/gyro` or a ROS 2
    /// `sensor_msgs/msg/Imu` (default: `/gyro`, else the only Imu channel).
    #[cfg_attr(feature = "clap", arg(long))]
    pub topic: Option<String>,
    /// MCAP: JSON channel with the reference angle (`{"angle_deg": ...}`).
    #[cfg_attr(feature = "clap", arg(long, default_value = REFERENCE_TOPIC))]
    pub reference_topic: String,
    /// ROS 2 Imu: component of `angular_velocity` used as the rate (rad/s → deg/s).
    #[cfg_attr(feature = "clap", arg(long, value_enum, default_value_t = Axis::Z))]
    pub axis: Axis,
    /// ROS 2 Imu: negate the rate (sensor mounted upside down).
    #[cfg_attr(feature = "clap", arg(long))]
    pub flip: bool,
    /// ROS 2 Imu: time stamp from the message header (sampling time) or the MCAP log time
    /// (receive time).
    #[cfg_attr(feature = "clap", arg(long, value_enum, default_value_t = TimeSource::Header))]
    pub time_source: TimeSource,
}

impl Default for McapOptions {
    fn default() -> Self {
        Self {
            topic: None,
            reference_topic: REFERENCE_TOPIC.to_string(),
            axis: Axis::Z,
            flip: false,
            time_source: TimeSource::Header,
        }
    }
}

/// An MCAP log read into memory, with what the reader noticed.
#[derive(Clone, Debug, PartialEq)]
pub struct McapRead {
    /// The log. For MCAP, [`Row::line`] is the 1-based index of the row's message on the
    /// rate channel.
    pub log: Log,
    /// Channel the rate came from.
    pub rate_topic: String,
    /// True if the rate came from a ROS 2 Imu channel.
    pub ros2: bool,
    /// Messages read on all channels.
    pub messages: u64,
    /// Damage that did not stop reading (an interrupted recording).
    pub warnings: Vec<String>,
}

#[derive(Clone, Debug, PartialEq, Eq)]
enum Kind {
    /// A JSON channel of gyro samples (`rate_dps`, ...).
    GyroJson,
    /// A ROS 2 Imu channel in CDR.
    Imu,
    /// The JSON reference channel.
    Reference,
    /// Not used.
    Ignored,
}

struct ChannelInfo {
    topic: String,
    /// Schema name (empty if none).
    schema: String,
    kind: Kind,
    /// Messages seen on it.
    count: u64,
}

struct SchemaInfo {
    name: String,
    encoding: String,
    data: Vec<u8>,
}

/// Deserialize a field whose presence matters: absent → `None`, `null` → `Some(None)`.
fn present<'de, D: Deserializer<'de>>(d: D) -> Result<Option<Option<f64>>, D::Error> {
    Option::<f64>::deserialize(d).map(Some)
}

#[derive(Deserialize)]
struct GyroIn {
    #[serde(default, deserialize_with = "present")]
    rate_dps: Option<Option<f64>>,
    #[serde(default, deserialize_with = "present")]
    temperature_c: Option<Option<f64>>,
    #[serde(default)]
    #[allow(dead_code)] // checked for type; `Row` has no status yet
    status: Option<u32>,
}

#[derive(Deserialize)]
struct ReferenceIn {
    #[serde(default, deserialize_with = "present")]
    angle_deg: Option<Option<f64>>,
}

/// Everything gathered while streaming.
struct State<'a> {
    path: &'a Path,
    options: &'a McapOptions,
    saw_header: bool,
    schemas: HashMap<u16, SchemaInfo>,
    channels: HashMap<u16, ChannelInfo>,
    metadata: BTreeMap<String, String>,
    rate_topic: Option<(String, Kind)>,
    rows: Vec<Row>,
    row_ns: Vec<u64>,
    reference: Vec<(u64, Option<f64>)>,
    has_reference: bool,
    has_temperature: bool,
    messages: u64,
}

/// Read an MCAP log (or a ROS 2 bag in MCAP) as a stream; see the module docs for which
/// channel gives the rate, how the reference is attached and how damage is handled.
pub fn read_mcap(path: &Path, options: &McapOptions) -> Result<McapRead, LogError> {
    let io_err = |cause| LogError::Io {
        path: path.to_path_buf(),
        cause,
    };
    let mcap_err = |message: String| LogError::Mcap {
        path: path.to_path_buf(),
        message,
    };
    let mut file = File::open(path).map_err(io_err)?;
    let len = file.metadata().map_err(io_err)?.len();
    if len == 0 {
        return Err(mcap_err("empty file (0 bytes), not an MCAP log".into()));
    }
    let finished = ends_with_magic(&mut file, len).map_err(io_err)?;
    let mut source = BufReader::with_capacity(1 << 20, file);

    let mut reader = LinearReader::new_with_options(
        LinearReaderOptions::default()
            .with_prevalidate_chunk_crcs(true)
            .with_validate_data_section_crc(true)
            .with_record_length_limit(RECORD_LENGTH_LIMIT),
    );
    let mut state = State {
        path,
        options,
        saw_header: false,
        schemas: HashMap::new(),
        channels: HashMap::new(),
        metadata: BTreeMap::new(),
        rate_topic: None,
        rows: Vec::new(),
        row_ns: Vec::new(),
        reference: Vec::new(),
        has_reference: false,
        has_temperature: false,
        messages: 0,
    };
    // What stopped the reading early, and whether it was the end of the file.
    let mut damage: Option<(String, bool)> = None;
    while let Some(event) = reader.next_event() {
        match event {
            Ok(LinearReadEvent::ReadRequest(need)) => {
                let read = loop {
                    match source.read(reader.insert(need)) {
                        Ok(n) => break n,
                        Err(e) if e.kind() == ErrorKind::Interrupted => continue,
                        Err(e) => return Err(io_err(e)),
                    }
                };
                reader.notify_read(read);
            }
            Ok(LinearReadEvent::Record { opcode, data }) => {
                if let Err(e) = state.record(opcode, data)? {
                    damage = Some((e, false));
                    break;
                }
            }
            Err(e) => {
                damage = Some((describe(&e), matches!(e, McapError::UnexpectedEof)));
                break;
            }
        }
    }

    let mut warnings = Vec::new();
    if let Some((what, eof)) = damage {
        if !state.saw_header {
            return Err(mcap_err(if eof {
                format!("cut short ({len} bytes) before the end of the MCAP header")
            } else {
                format!("not an MCAP file ({what})")
            }));
        }
        if finished {
            return Err(mcap_err(format!("corrupt MCAP file: {what}")));
        }
        warnings.push(format!(
            "{}: the file has no MCAP footer (an interrupted recording or a cut copy); read up to the first unreadable record ({what}): {} rate samples kept",
            path.display(),
            state.rows.len()
        ));
    }
    state.finish(warnings)
}

/// True if the file ends with the MCAP magic (its writer finished it).
fn ends_with_magic(file: &mut File, len: u64) -> std::io::Result<bool> {
    if len < 2 * MAGIC.len() as u64 {
        return Ok(false);
    }
    let mut tail = [0_u8; 8];
    file.seek(SeekFrom::End(-(MAGIC.len() as i64)))?;
    file.read_exact(&mut tail)?;
    file.seek(SeekFrom::Start(0))?;
    Ok(&tail == MAGIC)
}

fn describe(e: &McapError) -> String {
    match e {
        McapError::BadMagic => "bad magic".into(),
        McapError::UnexpectedEof => "the file ends inside a record".into(),
        McapError::RecordTooLarge { .. } | McapError::ChunkTooLarge(_) => {
            format!("{e} (an unfinished chunk or a corrupt length)")
        }
        e => e.to_string(),
    }
}

impl State<'_> {
    /// Handle one record. Outer error: the file is bad in a way that is never tolerated
    /// (wrong schema, undecodable message); inner error: the record does not parse
    /// (damage, handled like a read error).
    fn record(&mut self, opcode: u8, data: &[u8]) -> Result<Result<(), String>, LogError> {
        if !matches!(
            opcode,
            op::HEADER | op::SCHEMA | op::CHANNEL | op::MESSAGE | op::METADATA
        ) {
            return Ok(Ok(()));
        }
        let record = match mcap::parse_record(opcode, data) {
            Ok(record) => record,
            Err(e) => {
                return Ok(Err(format!(
                    "unreadable record (opcode {opcode:#04x}): {e}"
                )))
            }
        };
        match record {
            Record::Header(_) => self.saw_header = true,
            Record::Schema { header, data } => {
                self.schemas.insert(
                    header.id,
                    SchemaInfo {
                        name: header.name,
                        encoding: header.encoding,
                        data: data.into_owned(),
                    },
                );
            }
            // Channels repeat in the summary section: the first record counts.
            Record::Channel(channel) if !self.channels.contains_key(&channel.id) => {
                let kind = self.classify(&channel)?;
                let schema = self
                    .schemas
                    .get(&channel.schema_id)
                    .map_or(String::new(), |s| s.name.clone());
                if kind == Kind::Reference {
                    self.has_reference = true;
                }
                self.channels.insert(
                    channel.id,
                    ChannelInfo {
                        topic: channel.topic,
                        schema,
                        kind,
                        count: 0,
                    },
                );
            }
            Record::Message { header, data } => self.message(&header, &data)?,
            Record::Metadata(metadata) if metadata.name == METADATA_NAME => {
                self.metadata.extend(metadata.metadata);
            }
            _ => {}
        }
        Ok(Ok(()))
    }

    /// What a channel is for; an error if it is a known channel with the wrong schema.
    fn classify(&self, channel: &mcap::records::Channel) -> Result<Kind, LogError> {
        let schema = self.schemas.get(&channel.schema_id);
        let topic = channel.topic.as_str();
        let fail = |message: String| LogError::McapChannel {
            path: self.path.to_path_buf(),
            channel: topic.to_string(),
            message,
        };
        let is_imu = schema.is_some_and(|s| s.name == IMU_SCHEMA_NAME);
        if topic == self.options.reference_topic {
            check_json(&channel.message_encoding, schema, "angle_deg").map_err(fail)?;
            return Ok(Kind::Reference);
        }
        let selected = match &self.options.topic {
            Some(wanted) => wanted == topic,
            None => topic == GYRO_TOPIC || is_imu,
        };
        if !selected {
            return Ok(Kind::Ignored);
        }
        if is_imu {
            if channel.message_encoding != "cdr" {
                if self.options.topic.is_none() {
                    return Ok(Kind::Ignored);
                }
                return Err(fail(format!(
                    "{IMU_SCHEMA_NAME} with message encoding `{}`; only `cdr` is read",
                    channel.message_encoding
                )));
            }
            return Ok(Kind::Imu);
        }
        check_json(&channel.message_encoding, schema, "rate_dps").map_err(|e| {
            if self.options.topic.is_some() {
                fail(format!(
                    "neither a gyro JSON channel nor {IMU_SCHEMA_NAME} in CDR: {e}"
                ))
            } else {
                fail(e)
            }
        })?;
        Ok(Kind::GyroJson)
    }

    fn message(
        &mut self,
        header: &mcap::records::MessageHeader,
        data: &[u8],
    ) -> Result<(), LogError> {
        self.messages += 1;
        let Some(channel) = self.channels.get_mut(&header.channel_id) else {
            return Err(LogError::Mcap {
                path: self.path.to_path_buf(),
                message: format!(
                    "message {} refers to channel id {} that no channel record defines",
                    self.messages, header.channel_id
                ),
            });
        };
        if channel.kind == Kind::Ignored {
            return Ok(());
        }
        channel.count += 1;
        let index = channel.count;
        let fail = |message: String| LogError::McapMessage {
            path: self.path.to_path_buf(),
            channel: channel.topic.clone(),
            index,
            message,
        };
        match channel.kind {
            Kind::Ignored => {}
            Kind::Reference => {
                let message: ReferenceIn = serde_json::from_slice(data)
                    .map_err(|e| fail(format!("not a reference JSON message: {e}")))?;
                let angle = message
                    .angle_deg
                    .ok_or_else(|| fail("no `angle_deg` field".into()))?;
                self.reference
                    .push((header.log_time, angle.filter(|a| a.is_finite())));
            }
            Kind::GyroJson | Kind::Imu => {
                match &self.rate_topic {
                    None => self.rate_topic = Some((channel.topic.clone(), channel.kind.clone())),
                    Some((topic, _)) if *topic == channel.topic => {}
                    Some((topic, _)) => {
                        return Err(LogError::McapSecondRate {
                            path: self.path.to_path_buf(),
                            channel: channel.topic.clone(),
                            first: topic.clone(),
                        })
                    }
                }
                let (time_ns, rate_dps, temperature_c) = if channel.kind == Kind::Imu {
                    let sample =
                        decode_imu(data, self.options.axis, self.options.flip).map_err(fail)?;
                    let time_ns = match self.options.time_source {
                        TimeSource::LogTime => header.log_time,
                        TimeSource::Header => {
                            sample.stamp_ns.ok_or_else(|| LogError::McapZeroStamp {
                                path: self.path.to_path_buf(),
                                channel: channel.topic.clone(),
                                index,
                            })?
                        }
                    };
                    (time_ns, sample.rate_dps, None)
                } else {
                    let message: GyroIn = serde_json::from_slice(data)
                        .map_err(|e| fail(format!("not a gyro JSON message: {e}")))?;
                    let rate = message
                        .rate_dps
                        .ok_or_else(|| fail("no `rate_dps` field".into()))?;
                    if message.temperature_c.is_some() {
                        self.has_temperature = true;
                    }
                    (header.log_time, rate, message.temperature_c.flatten())
                };
                self.rows.push(Row {
                    line: index,
                    time_s: ns_to_seconds(time_ns),
                    rate_dps: rate_dps.filter(|r| r.is_finite()),
                    reference_deg: None,
                    temperature_c: temperature_c.filter(|t| t.is_finite()),
                });
                self.row_ns.push(time_ns);
            }
        }
        Ok(())
    }

    /// Attach the reference and build the log.
    fn finish(mut self, warnings: Vec<String>) -> Result<McapRead, LogError> {
        let Some((rate_topic, kind)) = self.rate_topic.take() else {
            return Err(self.no_rate_channel(&warnings));
        };
        attach_reference(&mut self.rows, &self.row_ns, &mut self.reference);
        if kind == Kind::Imu {
            // ROS time is epoch-scale, where an f64 resolves only ~0.24 us: count from the
            // whole second before the first sample instead, and say so in the metadata.
            let origin_s = self.row_ns.iter().min().map_or(0, |t| t / 1_000_000_000);
            let origin_ns = origin_s * 1_000_000_000;
            for (row, &t) in self.rows.iter_mut().zip(&self.row_ns) {
                row.time_s = ns_to_seconds(t - origin_ns);
            }
            self.metadata
                .insert(TIME_ORIGIN_KEY.to_string(), origin_s.to_string());
        }
        Ok(McapRead {
            log: Log {
                path: self.path.to_path_buf(),
                metadata: self.metadata,
                has_reference: self.has_reference,
                has_temperature: self.has_temperature,
                rows: self.rows,
            },
            rate_topic,
            ros2: kind == Kind::Imu,
            messages: self.messages,
            warnings,
        })
    }

    fn no_rate_channel(&self, warnings: &[String]) -> LogError {
        let channels: BTreeSet<String> = self
            .channels
            .values()
            .map(|c| format!("{} [{}] ({} messages)", c.topic, c.schema, c.count))
            .collect();
        let listed = if channels.is_empty() {
            "none".to_string()
        } else {
            channels.into_iter().collect::<Vec<_>>().join(", ")
        };
        let what = match &self.options.topic {
            Some(topic) if self.channels.values().any(|c| &c.topic == topic) => {
                format!("no messages on `{topic}`")
            }
            Some(topic) => format!("no channel `{topic}`"),
            None if self
                .channels
                .values()
                .any(|c| matches!(c.kind, Kind::GyroJson | Kind::Imu)) =>
            {
                "no messages on the rate channel".to_string()
            }
            None => {
                format!("no `{GYRO_TOPIC}` JSON channel and no {IMU_SCHEMA_NAME} channel in CDR")
            }
        };
        let damage = if warnings.is_empty() {
            String::new()
        } else {
            " (the file is cut short)".to_string()
        };
        LogError::Mcap {
            path: self.path.to_path_buf(),
            message: format!("{what}{damage}; channels: {listed}"),
        }
    }
}

/// Check a JSON channel: message encoding `json`, and a schema (if any) in `jsonschema` of
/// `"type": "object"` with the `required` property.
fn check_json(
    message_encoding: &str,
    schema: Option<&SchemaInfo>,
    required: &str,
) -> Result<(), String> {
    if message_encoding != "json" {
        return Err(format!(
            "message encoding `{message_encoding}`, expected `json`"
        ));
    }
    let Some(schema) = schema else {
        return Ok(()); // schemaless JSON is valid MCAP
    };
    if schema.encoding != "jsonschema" {
        return Err(format!(
            "schema `{}` has encoding `{}`, expected `jsonschema`",
            schema.name, schema.encoding
        ));
    }
    let value: serde_json::Value = serde_json::from_slice(&schema.data)
        .map_err(|e| format!("schema `{}` is not valid JSON: {e}", schema.name))?;
    if value.get("type").and_then(|t| t.as_str()) != Some("object") {
        return Err(format!(
            "schema `{}` is not `\"type\": \"object\"`",
            schema.name
        ));
    }
    if value
        .get("properties")
        .and_then(|p| p.get(required))
        .is_none()
    {
        return Err(format!(
            "schema `{}` has no `{required}` property",
            schema.name
        ));
    }
    Ok(())
}

/// Attach reference samples to rows by time (rule in the module docs).
fn attach_reference(rows: &mut [Row], row_ns: &[u64], reference: &mut [(u64, Option<f64>)]) {
    if reference.is_empty() {
        return;
    }
    reference.sort_by_key(|&(t, _)| t); // stable: equal times keep file order
    let max_span_ns = (REFERENCE_MAX_SPAN_S * 1e9) as u64;
    let mut previous: Option<u64> = None;
    let mut same_time = 0_usize;
    let mut lo = 0_usize;
    for (row, &t) in rows.iter_mut().zip(row_ns) {
        same_time = if previous == Some(t) {
            same_time + 1
        } else {
            0
        };
        previous = Some(t);
        // First reference at or after t: walk forward from the last row's (rows are
        // usually in time order), search again when time goes back.
        lo = if lo > 0 && reference[lo - 1].0 >= t {
            reference.partition_point(|&(r, _)| r < t)
        } else {
            lo + reference[lo..].iter().take_while(|&&(r, _)| r < t).count()
        };
        let hi = lo + reference[lo..].iter().take_while(|&&(r, _)| r == t).count();
        row.reference_deg = if hi > lo {
            reference[lo + same_time.min(hi - lo - 1)].1
        } else if lo > 0 && lo < reference.len() {
            let (t0, v0) = reference[lo - 1];
            let (t1, v1) = reference[lo];
            match (v0, v1) {
                (Some(v0), Some(v1)) if t1 - t0 <= max_span_ns => {
                    let w = (t - t0) as f64 / (t1 - t0) as f64;
                    Some(v0 + w * (v1 - v0))
                }
                _ => None,
            }
        } else {
            None
        };
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn row(t: u64) -> Row {
        Row {
            line: 0,
            time_s: ns_to_seconds(t),
            rate_dps: Some(0.0),
            reference_deg: Some(-99.0),
            temperature_c: None,
        }
    }

    #[test]
    fn reference_exact_interpolated_or_none() {
        let ms = 1_000_000;
        let times = [
            0,
            5 * ms,
            10 * ms,
            10 * ms,
            15 * ms,
            20 * ms,
            900 * ms,
            2000 * ms,
            3000 * ms,
        ];
        let mut rows: Vec<Row> = times.iter().map(|&t| row(t)).collect();
        let mut reference = vec![
            (20 * ms, None),
            (10 * ms, Some(1.0)),
            (10 * ms, Some(2.0)),
            (0, Some(0.0)),
            (1000 * ms, Some(10.0)),
            (1400 * ms, Some(14.0)),
            (2100 * ms, Some(21.0)),
        ];
        attach_reference(&mut rows, &times, &mut reference);
        let got: Vec<Option<f64>> = rows.iter().map(|r| r.reference_deg).collect();
        assert_eq!(
            got,
            [
                Some(0.0), // exact
                Some(0.5), // halfway between 0 and 1.0 (the first at 10 ms)
                Some(1.0), // first row at 10 ms takes the first reference at 10 ms
                Some(2.0), // second row, second reference
                None,      // between 2.0 and null
                None,      // exact null
                None,      // between null (20 ms) and 10.0 (1 s)
                None,      // 1.4 s .. 2.1 s is longer than 0.5 s
                None,      // after the last reference: no extrapolation
            ]
        );
    }

    #[test]
    fn check_json_messages() {
        let schema = |encoding: &str, data: &str| SchemaInfo {
            name: "s".into(),
            encoding: encoding.into(),
            data: data.as_bytes().to_vec(),
        };
        let good = schema(
            "jsonschema",
            r#"{"type":"object","properties":{"rate_dps":{}}}"#,
        );
        assert!(check_json("json", Some(&good), "rate_dps").is_ok());
        assert!(check_json("json", None, "rate_dps").is_ok());
        assert!(check_json("cdr", Some(&good), "rate_dps")
            .unwrap_err()
            .contains("message encoding `cdr`"));
        assert!(check_json("json", Some(&good), "angle_deg")
            .unwrap_err()
            .contains("no `angle_deg` property"));
        let ros = schema("ros2msg", "float64 x");
        assert!(check_json("json", Some(&ros), "rate_dps")
            .unwrap_err()
            .contains("encoding `ros2msg`"));
        let array = schema("jsonschema", r#"{"type":"array"}"#);
        assert!(check_json("json", Some(&array), "rate_dps")
            .unwrap_err()
            .contains("object"));
        let broken = schema("jsonschema", "{");
        assert!(check_json("json", Some(&broken), "rate_dps")
            .unwrap_err()
            .contains("not valid JSON"));
    }
}
