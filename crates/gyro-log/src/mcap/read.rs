//! Reading MCAP logs as a stream: records are pulled through a buffered file (memory
//! scales with the largest chunk, not the file), rows assembled from the rate channel,
//! reference samples attached by time.
//!
//! # Which channel gives the rate
//! `--topic` if given (a `gyro_msgs/msg/Sample` channel like `/gyro`, a JSON channel of
//! earlier files, or a ROS 2 `sensor_msgs/msg/Imu`);
//! otherwise `/gyro`, or else the one `sensor_msgs/msg/Imu` channel in CDR. If two such
//! channels carry messages, reading fails and asks for `--topic`. Other channels are
//! skipped without being decoded.
//!
//! # Time
//! `time_s` is the log time (`/gyro` and JSON channels) or the chosen ROS 2 stamp, in seconds. ROS 2
//! stamps count from the Unix epoch, where an `f64` second resolves only about 0.24 µs; so
//! for an Imu channel `time_s` counts from the whole second at or before the earliest
//! sample, and the metadata key [`TIME_ORIGIN_KEY`] holds that second.
//!
//! # Order and memory
//! The file is read chunk by chunk ([`McapRows`]): one walk over the top-level record
//! headers finds the chunks (with or without a summary section), then the chunks are read
//! in order of their first log time (`message_start_time`; equal ones in file order), so
//! chunks written out of time order are read in time order; the messages of a chunk in
//! their order in the file. The chunks are read, CRC-checked and decompressed by the
//! thread that decodes them, a batch of whole chunks at a time (`UnitEvents`).
//! Memory holds a batch of chunks and the rows waiting for their reference (in a file whose
//! channels share chunks in time order, at most a chunk's worth), never the log.
//!
//! # Reference attachment
//! Reference samples (`/reference`, `gyro_msgs/msg/Reference` or JSON
//! `{"angle_deg": f64|null}`) are attached to rate rows by
//! log time (neither channel needs to be sorted; a row waits until no unread chunk can
//! hold a reference that decides it):
//! - a reference message at exactly a row's time gives that row its value (`null`: the row
//!   has no reference; so does NaN in CDR); the k-th of several rows with one time stamp takes the k-th
//!   reference message with that time, in the order read;
//! - otherwise the value is interpolated linearly between the latest earlier and the
//!   earliest later reference message, if both are non-null and at most
//!   [`REFERENCE_MAX_SPAN_S`] apart;
//! - otherwise (before the first or after the last reference, across a longer gap or a
//!   `null`) the row has none. Nothing is extrapolated.
//!
//! # Damaged files
//! A file that ends with the MCAP magic was finished by its writer: any unreadable record
//! in it is an error. A file without it is an interrupted recording or a cut copy: every
//! chunk up to the first incomplete or unreadable record is used (chunks are CRC-checked
//! before any of their messages is), and a warning names the byte offset where reading
//! stopped and how many rate samples were kept. Bad magic, an empty file, a wrong schema on
//! a known channel or an undecodable message are one-line errors naming the file (and the
//! channel and 1-based message index on that channel).

use super::attach::Attacher;
use super::binary::{self, HAS_TEMPERATURE_KEY, REFERENCE_SCHEMA_NAME, SAMPLE_SCHEMA_NAME};
use super::layout::{self, Layout};
use super::ros2::{decode_imu, Axis, TimeSource, IMU_SCHEMA_NAME};
use super::unit::{Event, UnitError, UnitEvents, Units};
use super::{json, ns_to_seconds, GYRO_TOPIC, METADATA_NAME, REFERENCE_TOPIC};
use crate::{metadata_rate_hz, Log, LogError, Row, RATE_WINDOW_STEPS};
use mcap::records::{op, Record};
use std::collections::{BTreeMap, BTreeSet, HashMap, VecDeque};
use std::fs::File;
use std::path::{Path, PathBuf};

/// Longest time (s) between two reference samples across which a rate row's reference is
/// interpolated.
pub const REFERENCE_MAX_SPAN_S: f64 = 0.5;

/// Metadata key set for ROS 2 logs: the source-clock time (whole seconds; ROS time counts
/// from the Unix epoch) at which the log's `time_s` is 0.
pub const TIME_ORIGIN_KEY: &str = "time_origin_s";

/// How to read an MCAP log (ignored for CSV).
#[derive(Clone, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "clap", derive(clap::Args))]
pub struct McapOptions {
    /// MCAP: channel with the rate, a gyro channel like `/gyro` (CDR or JSON) or a ROS 2
    /// `sensor_msgs/msg/Imu` (default: `/gyro`, else the only Imu channel).
    #[cfg_attr(feature = "clap", arg(long))]
    pub topic: Option<String>,
    /// MCAP: channel with the reference angle (`gyro_msgs/msg/Reference`, or JSON
    /// `{"angle_deg": ...}`).
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
    /// A `gyro_msgs/msg/Sample` channel in CDR (what the writer writes); `temperature`: the
    /// log has a temperature column.
    GyroCdr { temperature: bool },
    /// A JSON channel of gyro samples (`rate_dps`, ...).
    GyroJson,
    /// A ROS 2 Imu channel in CDR.
    Imu,
    /// The reference channel in CDR (`gyro_msgs/msg/Reference`).
    ReferenceCdr,
    /// The reference channel in JSON.
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

/// The channels by id: a lookup per message is one index into a table as long as the
/// largest id seen.
#[derive(Default)]
struct Channels {
    list: Vec<ChannelInfo>,
    /// By id: 1 + the channel's index in `list`, 0 for none.
    by_id: Vec<u32>,
}

impl Channels {
    fn contains_key(&self, id: &u16) -> bool {
        self.by_id.get(usize::from(*id)).is_some_and(|&i| i != 0)
    }

    /// Add channel `id` (not yet present).
    fn insert(&mut self, id: u16, channel: ChannelInfo) {
        let id = usize::from(id);
        if self.by_id.len() <= id {
            self.by_id.resize(id + 1, 0);
        }
        self.list.push(channel);
        self.by_id[id] = self.list.len() as u32;
    }

    fn get_mut(&mut self, id: &u16) -> Option<&mut ChannelInfo> {
        let i = *self.by_id.get(usize::from(*id))?;
        self.list.get_mut((i as usize).checked_sub(1)?)
    }

    fn values(&self) -> std::slice::Iter<'_, ChannelInfo> {
        self.list.iter()
    }
}

/// Everything gathered while streaming, besides the rows.
struct State {
    path: PathBuf,
    options: McapOptions,
    saw_header: bool,
    schemas: HashMap<u16, SchemaInfo>,
    channels: Channels,
    metadata: BTreeMap<String, String>,
    /// The rate channel: its id, topic and kind.
    rate_channel: Option<(u16, String, Kind)>,
    attacher: Attacher,
    has_reference: bool,
    has_temperature: bool,
    messages: u64,
}

/// Where reading stopped early in a file without footer.
struct Stop {
    offset: u64,
    what: String,
}

/// The rate rows of an MCAP log (or a ROS 2 bag in MCAP), read chunk by chunk, with their
/// reference attached; see the module docs for which channel gives the rate, the order,
/// how the reference is attached and how damage is handled.
///
/// An iterator of rows; an error ends it. [`McapRows::warnings`] then says what damage was
/// read around.
pub struct McapRows {
    state: State,
    units: UnitEvents,
    finished: bool,
    /// Damage the walk over the file met (reading stops there).
    scan_damage: Option<layout::Damage>,
    /// Where reading stopped.
    stop: Option<Stop>,
    /// All units read (or reading stopped).
    ended: bool,
    /// An error was given: nothing more.
    failed: bool,
    /// Rows read ahead by [`McapRows::prime`].
    primed: VecDeque<Result<Row, LogError>>,
    /// For ROS 2 Imu rows: the whole second (ns) their times count from.
    origin_ns: Option<u64>,
    /// Rows given.
    rows: u64,
}

impl McapRows {
    /// Open the file and read what precedes the first message: the layout, the schemas,
    /// channels and metadata outside chunks.
    pub fn open(path: &Path, options: &McapOptions) -> Result<Self, LogError> {
        let io_err = |cause| LogError::Io {
            path: path.to_path_buf(),
            cause,
        };
        let mcap_err = |message: String| LogError::Mcap {
            path: path.to_path_buf(),
            message,
        };
        let mut file = File::open(path).map_err(io_err)?;
        let Layout {
            len,
            finished,
            saw_header,
            units,
            definitions,
            damage,
        } = layout::scan(&mut file).map_err(io_err)?;
        if len == 0 {
            return Err(mcap_err("empty file (0 bytes), not an MCAP log".into()));
        }
        if let Some(damage) = &damage {
            if !saw_header {
                return Err(mcap_err(if damage.cut {
                    format!("cut short ({len} bytes) before the end of the MCAP header")
                } else {
                    format!("not an MCAP file ({})", damage.what)
                }));
            }
            if finished {
                return Err(mcap_err(format!(
                    "corrupt MCAP file: {} (byte {})",
                    damage.what, damage.offset
                )));
            }
        }
        let mut state = State {
            path: path.to_path_buf(),
            options: options.clone(),
            saw_header,
            schemas: HashMap::new(),
            channels: Channels::default(),
            metadata: BTreeMap::new(),
            rate_channel: None,
            attacher: Attacher::new(REFERENCE_MAX_SPAN_S),
            has_reference: false,
            has_temperature: false,
            messages: 0,
        };
        for definition in &definitions {
            if let Err(what) = state.record(definition.opcode, &definition.body)? {
                return Err(mcap_err(format!("corrupt MCAP file: {what}")));
            }
        }
        Ok(Self {
            state,
            units: UnitEvents::new(Units::new(file, units)),
            finished,
            scan_damage: damage,
            stop: None,
            ended: false,
            failed: false,
            primed: VecDeque::new(),
            origin_ns: None,
            rows: 0,
        })
    }

    /// Read ahead until [`RATE_WINDOW_STEPS`] + 1 rows are held (the rows placing holds
    /// back anyway) or the file ends, so that whether the log has a temperature and a
    /// reference is decided by them before the first row is placed. An error met is given
    /// by the iterator, after the rows before it.
    ///
    /// A finished file whose rate channels are all `gyro_msgs/msg/Sample` in CDR needs no
    /// read-ahead: its summary defines every channel, and each says in its metadata
    /// whether it has a temperature.
    pub fn prime(&mut self) {
        if self.finished {
            let rates: Vec<&Kind> = self
                .state
                .channels
                .values()
                .map(|c| &c.kind)
                .filter(|k| !matches!(k, Kind::Ignored | Kind::Reference | Kind::ReferenceCdr))
                .collect();
            if !rates.is_empty() && rates.iter().all(|k| matches!(k, Kind::GyroCdr { .. })) {
                self.state.has_temperature = rates
                    .iter()
                    .any(|k| matches!(k, Kind::GyroCdr { temperature: true }));
                return;
            }
        }
        while self.primed.len() <= RATE_WINDOW_STEPS {
            match self.next_row() {
                Some(row) => self.primed.push_back(row),
                None => break,
            }
        }
    }

    /// True if the log has a reference channel (so far).
    pub fn has_reference(&self) -> bool {
        self.state.has_reference
    }

    /// True if a rate message had a `temperature_c` field (so far).
    pub fn has_temperature(&self) -> bool {
        self.state.has_temperature
    }

    /// The `gyro` metadata (records outside chunks, all known from the start).
    pub fn metadata(&self) -> &BTreeMap<String, String> {
        &self.state.metadata
    }

    /// The `sample_rate_hz` metadata value, if valid.
    pub fn metadata_rate_hz(&self) -> Option<f64> {
        metadata_rate_hz(&self.state.metadata)
    }

    /// Rows held waiting for their reference now, and at most so far (read-ahead by
    /// [`McapRows::prime`] not counted).
    pub fn rows_held(&self) -> (usize, usize) {
        self.state.attacher.held()
    }

    /// Damage read around (a file without footer), one line each; final once the rows are
    /// all read.
    pub fn warnings(&self) -> Vec<String> {
        let stop = self
            .stop
            .as_ref()
            .map(|s| (s.offset, s.what.as_str()))
            .or(self
                .scan_damage
                .as_ref()
                .map(|d| (d.offset, d.what.as_str())));
        stop.map(|(offset, what)| {
            format!(
                "{}: the file has no MCAP footer (an interrupted recording or a cut copy); read up to byte {offset} of {} ({what}): {} rate samples kept",
                self.state.path.display(),
                self.units.file_len(),
                self.rows
            )
        })
        .into_iter()
        .collect()
    }

    /// The next row, with its reference; `None` at the end or after an error.
    fn next_row(&mut self) -> Option<Result<Row, LogError>> {
        if self.failed {
            return None;
        }
        let row = self.read_row();
        if let Some(Err(_)) = row {
            self.failed = true;
        }
        row
    }

    fn read_row(&mut self) -> Option<Result<Row, LogError>> {
        loop {
            if let Some((time_ns, mut row)) = self.state.attacher.pop() {
                let origin_ns = match self.origin() {
                    Ok(origin_ns) => origin_ns,
                    Err(e) => return Some(Err(e)),
                };
                row.time_s = ns_to_seconds(time_ns - origin_ns);
                self.rows += 1;
                return Some(Ok(row));
            }
            if self.ended {
                if self.state.rate_channel.is_none() {
                    let damaged = self.stop.is_some() || self.scan_damage.is_some();
                    return Some(Err(self.state.no_rate_channel(damaged)));
                }
                return None;
            }
            match self.units.next_event() {
                None => self.end(),
                Some(Ok(Event::UnitDone { next_start_ns })) => {
                    self.state.attacher.advance(next_start_ns);
                }
                Some(Ok(Event::Record { opcode, data })) => match self.state.record(opcode, data) {
                    Ok(Ok(())) => {}
                    Ok(Err(what)) => {
                        let offset = self.units.current_offset();
                        if let Err(e) = self.damaged(offset, what) {
                            return Some(Err(e));
                        }
                    }
                    Err(e) => return Some(Err(e)),
                },
                Some(Err(UnitError::Io(cause))) => {
                    return Some(Err(LogError::Io {
                        path: self.state.path.clone(),
                        cause,
                    }))
                }
                Some(Err(UnitError::Damaged { offset, what })) => {
                    if let Err(e) = self.damaged(offset, what) {
                        return Some(Err(e));
                    }
                }
            }
        }
    }

    /// Every unit read: every row is decided.
    fn end(&mut self) {
        self.ended = true;
        self.state.attacher.advance(u64::MAX);
    }

    /// Reading stops at damage: an error in a finished file, else the end.
    fn damaged(&mut self, offset: u64, what: String) -> Result<(), LogError> {
        if self.finished {
            return Err(LogError::Mcap {
                path: self.state.path.clone(),
                message: format!("corrupt MCAP file: {what} (byte {offset})"),
            });
        }
        self.stop = Some(Stop { offset, what });
        self.end();
        Ok(())
    }

    /// What row times count from: 0, or for ROS 2 Imu rows the whole second at or before
    /// the earliest (found by a pass over the rate channel's messages up to where reading
    /// stops).
    fn origin(&mut self) -> Result<u64, LogError> {
        if let Some(origin_ns) = self.origin_ns {
            return Ok(origin_ns);
        }
        let origin_ns = match &self.state.rate_channel {
            Some((id, _, Kind::Imu)) => {
                let earliest = self.earliest_imu_time(*id)?;
                earliest / 1_000_000_000 * 1_000_000_000
            }
            _ => 0,
        };
        self.origin_ns = Some(origin_ns);
        Ok(origin_ns)
    }

    /// The earliest time of the Imu channel `id`'s messages, read in a separate pass.
    fn earliest_imu_time(&self, id: u16) -> Result<u64, LogError> {
        let path = &self.state.path;
        let file = File::open(path).map_err(|cause| LogError::Io {
            path: path.clone(),
            cause,
        })?;
        let options = &self.state.options;
        let mut units = UnitEvents::new(Units::new(file, self.units.units()));
        let mut earliest = u64::MAX;
        while let Some(event) = units.next_event() {
            let Ok(Event::Record { opcode, data }) = event else {
                if let Err(UnitError::Io(cause)) = event {
                    return Err(LogError::Io {
                        path: path.clone(),
                        cause,
                    });
                }
                if event.is_err() {
                    break; // damage: reading stops there too
                }
                continue;
            };
            if opcode != op::MESSAGE {
                continue;
            }
            let Ok(Record::Message { header, data }) = mcap::parse_record(opcode, data) else {
                break;
            };
            if header.channel_id != id {
                continue;
            }
            // Undecodable messages are reported by the main pass.
            if let Ok(sample) = decode_imu(&data, options.axis, options.flip) {
                let time_ns = match options.time_source {
                    TimeSource::LogTime => Some(header.log_time),
                    TimeSource::Header => sample.stamp_ns,
                };
                earliest = earliest.min(time_ns.unwrap_or(u64::MAX));
            }
        }
        Ok(if earliest == u64::MAX { 0 } else { earliest })
    }

    /// Read every row into memory.
    fn read_all(mut self) -> Result<McapRead, LogError> {
        let mut rows = Vec::new();
        for row in self.by_ref() {
            rows.push(row?);
        }
        let warnings = self.warnings();
        let Some((_, rate_topic, kind)) = self.state.rate_channel.take() else {
            return Err(self.state.no_rate_channel(!warnings.is_empty()));
        };
        if kind == Kind::Imu {
            let origin_s = self.origin_ns.unwrap_or(0) / 1_000_000_000;
            self.state
                .metadata
                .insert(TIME_ORIGIN_KEY.to_string(), origin_s.to_string());
        }
        Ok(McapRead {
            log: Log {
                path: self.state.path,
                metadata: self.state.metadata,
                has_reference: self.state.has_reference,
                has_temperature: self.state.has_temperature,
                rows,
            },
            rate_topic,
            ros2: kind == Kind::Imu,
            messages: self.state.messages,
            warnings,
        })
    }
}

impl Iterator for McapRows {
    type Item = Result<Row, LogError>;

    fn next(&mut self) -> Option<Self::Item> {
        match self.primed.pop_front() {
            Some(row) => Some(row),
            None => self.next_row(),
        }
    }
}

/// Read an MCAP log (or a ROS 2 bag in MCAP) into memory ([`McapRows`], collected).
pub fn read_mcap(path: &Path, options: &McapOptions) -> Result<McapRead, LogError> {
    McapRows::open(path, options)?.read_all()
}

/// Bytes of a message record's header: channel id, sequence, log time, publish time.
const MESSAGE_HEADER_LEN: usize = 2 + 4 + 8 + 8;

/// The header of a message record's body, if it is long enough.
fn message_header(data: &[u8]) -> Option<mcap::records::MessageHeader> {
    let header = data.get(..MESSAGE_HEADER_LEN)?;
    let u64_at = |i: usize| {
        let mut bytes = [0_u8; 8];
        bytes.copy_from_slice(&header[i..i + 8]);
        u64::from_le_bytes(bytes)
    };
    Some(mcap::records::MessageHeader {
        channel_id: u16::from_le_bytes([header[0], header[1]]),
        sequence: u32::from_le_bytes([header[2], header[3], header[4], header[5]]),
        log_time: u64_at(6),
        publish_time: u64_at(14),
    })
}

impl State {
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
        if opcode == op::MESSAGE {
            // Parsed here: the most frequent record, by far.
            let Some(header) = message_header(data) else {
                return Ok(Err("unreadable record (opcode 0x05): too short".into()));
            };
            return self.message(&header, &data[MESSAGE_HEADER_LEN..]).map(Ok);
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
                if matches!(kind, Kind::Reference | Kind::ReferenceCdr) {
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
                if let Some(value) = metadata.metadata.get(crate::SAMPLE_RATE_KEY) {
                    let before = self.metadata.get(crate::SAMPLE_RATE_KEY);
                    crate::check_rate_metadata(value, before.map(String::as_str)).map_err(
                        |message| LogError::Metadata {
                            path: self.path.to_path_buf(),
                            line: None,
                            message: format!("metadata record `{METADATA_NAME}`: {message}"),
                        },
                    )?;
                }
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
            if channel.message_encoding == binary::MESSAGE_ENCODING {
                check_cdr(schema, REFERENCE_SCHEMA_NAME).map_err(fail)?;
                return Ok(Kind::ReferenceCdr);
            }
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
        if channel.message_encoding == binary::MESSAGE_ENCODING {
            check_cdr(schema, SAMPLE_SCHEMA_NAME).map_err(|e| {
                fail(format!(
                    "neither {SAMPLE_SCHEMA_NAME} nor {IMU_SCHEMA_NAME} in CDR: {e}"
                ))
            })?;
            let temperature = channel
                .metadata
                .get(HAS_TEMPERATURE_KEY)
                .is_none_or(|v| v != "false");
            return Ok(Kind::GyroCdr { temperature });
        }
        check_json(&channel.message_encoding, schema, "rate_dps").map_err(|e| {
            if self.options.topic.is_some() {
                fail(format!(
                    "neither a gyro channel ({SAMPLE_SCHEMA_NAME} in CDR, or JSON) nor {IMU_SCHEMA_NAME} in CDR: {e}"
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
        let channel: &ChannelInfo = channel;
        let fail = message_error(&self.path, channel, index);
        match channel.kind {
            Kind::Ignored => {}
            Kind::ReferenceCdr => {
                let angle = binary::decode_reference(data).map_err(fail)?;
                self.attacher.reference(header.log_time, angle);
            }
            Kind::Reference => {
                let angle = json::reference(data)
                    .map_err(|e| fail(format!("not a reference JSON message: {e}")))?
                    .ok_or_else(|| fail("no `angle_deg` field".into()))?;
                self.attacher
                    .reference(header.log_time, angle.filter(|a| a.is_finite()));
            }
            Kind::GyroCdr { .. } | Kind::GyroJson | Kind::Imu => {
                let first = claim_rate_channel(
                    &mut self.rate_channel,
                    header.channel_id,
                    channel,
                    &self.path,
                )?;
                if first
                    && channel.kind == Kind::Imu
                    && self.options.time_source == TimeSource::Header
                {
                    self.attacher.rows_not_at_log_time();
                }
                let sample = decode_rate(channel, header, data, &self.options, &self.path, index)?;
                self.has_temperature |= sample.has_temperature;
                let row = Row {
                    line: index,
                    time_s: 0.0, // from `time_ns` when the row is given
                    rate_dps: sample.rate_dps.filter(|r| r.is_finite()),
                    reference_deg: None,
                    temperature_c: sample.temperature_c.filter(|t| t.is_finite()),
                };
                self.attacher.row(sample.time_ns, row);
            }
        }
        Ok(())
    }

    fn no_rate_channel(&self, damaged: bool) -> LogError {
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
                .any(|c| matches!(c.kind, Kind::GyroCdr { .. } | Kind::GyroJson | Kind::Imu)) =>
            {
                "no messages on the rate channel".to_string()
            }
            None => {
                format!("no `{GYRO_TOPIC}` channel and no {IMU_SCHEMA_NAME} channel in CDR")
            }
        };
        let damage = if !damaged {
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

/// The error of message `index` of `channel` in the file at `path`, saying `message`.
fn message_error<'a>(
    path: &'a Path,
    channel: &'a ChannelInfo,
    index: u64,
) -> impl Fn(String) -> LogError + 'a {
    move |message: String| LogError::McapMessage {
        path: path.to_path_buf(),
        channel: channel.topic.clone(),
        index,
        message,
    }
}

/// Take `channel` (id `channel_id`) as the rate channel if there is none yet (true), or
/// check that it is the one taken (false); a second rate channel is an error.
fn claim_rate_channel(
    rate_channel: &mut Option<(u16, String, Kind)>,
    channel_id: u16,
    channel: &ChannelInfo,
    path: &Path,
) -> Result<bool, LogError> {
    match rate_channel {
        None => {
            *rate_channel = Some((channel_id, channel.topic.clone(), channel.kind.clone()));
            Ok(true)
        }
        Some((_, topic, _)) if *topic == channel.topic => Ok(false),
        Some((_, topic, _)) => Err(LogError::McapSecondRate {
            path: path.to_path_buf(),
            channel: channel.topic.clone(),
            first: topic.clone(),
        }),
    }
}

/// One message of the rate channel, decoded.
struct RateSample {
    time_ns: u64,
    rate_dps: Option<f64>,
    temperature_c: Option<f64>,
    /// The message shows the log has a temperature column.
    has_temperature: bool,
}

/// Decode message `index` (`data`, stamped `header`) of the rate channel `channel`, as
/// its kind says, its time from the log time or (for an Imu message, as `options` say)
/// its header stamp.
fn decode_rate(
    channel: &ChannelInfo,
    header: &mcap::records::MessageHeader,
    data: &[u8],
    options: &McapOptions,
    path: &Path,
    index: u64,
) -> Result<RateSample, LogError> {
    let fail = message_error(path, channel, index);
    let mut has_temperature = false;
    let (time_ns, rate_dps, temperature_c) = if channel.kind == Kind::Imu {
        let sample = decode_imu(data, options.axis, options.flip).map_err(fail)?;
        let time_ns = match options.time_source {
            TimeSource::LogTime => header.log_time,
            TimeSource::Header => sample.stamp_ns.ok_or_else(|| LogError::McapZeroStamp {
                path: path.to_path_buf(),
                channel: channel.topic.clone(),
                index,
            })?,
        };
        (time_ns, sample.rate_dps, None)
    } else if let Kind::GyroCdr { temperature } = channel.kind {
        let sample = binary::decode_sample(data).map_err(fail)?;
        has_temperature = temperature;
        (header.log_time, sample.rate_dps, sample.temperature_c)
    } else {
        let message =
            json::gyro(data).map_err(|e| fail(format!("not a gyro JSON message: {e}")))?;
        let rate = message
            .rate_dps
            .ok_or_else(|| fail("no `rate_dps` field".into()))?;
        if message.temperature_c.is_some() {
            has_temperature = true;
        }
        (header.log_time, rate, message.temperature_c.flatten())
    };
    Ok(RateSample {
        time_ns,
        rate_dps,
        temperature_c,
        has_temperature,
    })
}

/// Check a CDR channel's schema: `name` in `ros2msg`, declaring the fields the reader
/// decodes (a message of that name laid out otherwise would be read wrong, silently).
fn check_cdr(schema: Option<&SchemaInfo>, name: &str) -> Result<(), String> {
    match schema {
        None => Err(format!("a CDR channel without a schema; expected {name}")),
        Some(s) if s.name != name => Err(format!("schema `{}`, expected {name}", s.name)),
        Some(s) if s.encoding != binary::SCHEMA_ENCODING => Err(format!(
            "schema `{name}` has encoding `{}`, expected `{}`",
            s.encoding,
            binary::SCHEMA_ENCODING
        )),
        Some(s) => {
            let expected = binary::declared_fields(binary::definition(name));
            let found = binary::declared_fields(&String::from_utf8_lossy(&s.data));
            if found == expected {
                Ok(())
            } else {
                Err(format!(
                    "schema `{name}` declares `{}`; the reader decodes `{}`",
                    found.join("; "),
                    expected.join("; ")
                ))
            }
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

#[cfg(test)]
mod tests {
    use super::*;

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
