//! Writing MCAP logs incrementally, in chunks small enough that a killed writer loses at
//! most the last [`McapWriteOptions::max_chunk_duration_ns`] of data.

use super::binary::{self, GyroSample};
use super::{seconds_to_ns, GYRO_TOPIC, METADATA_NAME, RAW_TOPIC, REFERENCE_TOPIC};
use crate::{Log, LogError, Row};
use mcap::records::{MessageHeader, Metadata};
use mcap::{Compression, McapError, WriteOptions, Writer};
use serde::Serialize;
use std::collections::BTreeMap;
use std::fs::File;
use std::io::BufWriter;
use std::path::{Path, PathBuf};

/// JSON schema of raw frames written with [`McapLogWriter::write_raw`].
const RAW_SCHEMA: &str = r#"{
  "title": "gyro.RawFrame",
  "description": "Raw bytes of one sensor frame; log_time is the host receive time (ns)",
  "type": "object",
  "properties": {
    "hex": {"type": "string", "description": "the frame's bytes, lowercase hex"}
  },
  "required": ["hex"]
}"#;

/// Bytes a message record adds to a chunk besides its data (opcode, length, header).
const MESSAGE_OVERHEAD: usize = 1 + 8 + 2 + 4 + 8 + 8;

/// How an MCAP writer compresses its chunks: the `--compression` of every command that
/// writes MCAP. The readers read all three, chunk by chunk.
///
/// On the bench fixture (`fixtures/logs/bench_run.csv`, 40 000 rows, 1.26 MB of CSV;
/// docs/log-formats.md, "Compression") the file is 1.98 MB with zstd, 2.52 MB with lz4
/// and 5.38 MB uncompressed; 1.28 MB of each are message indexes, which are never
/// compressed and which Foxglove needs. `run` reads zstd in about 1.2 times lz4's time.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
pub enum McapCompression {
    /// zstd, level 3: the smallest file, a fifth smaller than lz4's; what the official
    /// `mcap` CLI writes.
    #[default]
    Zstd,
    /// lz4: a quarter larger than zstd, read about a fifth faster (what gyro-cli wrote
    /// before zstd became the default).
    Lz4,
    /// Uncompressed: 2.7 times zstd's size, for tools that decompress nothing.
    None,
}

impl McapCompression {
    /// Its name, as `--compression` takes it (a chunk record names no compression `""`).
    pub fn name(self) -> &'static str {
        match self {
            Self::Zstd => "zstd",
            Self::Lz4 => "lz4",
            Self::None => "none",
        }
    }

    /// The `mcap` crate's setting.
    fn to_mcap(self) -> Option<Compression> {
        match self {
            Self::Zstd => Some(Compression::Zstd),
            Self::Lz4 => Some(Compression::Lz4),
            Self::None => None,
        }
    }
}

impl std::fmt::Display for McapCompression {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// How an [`McapLogWriter`] writes.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct McapWriteOptions {
    /// A chunk is closed (compressed, written and flushed to the OS) before a message
    /// whose log time is this far (ns) from the chunk's first message: a killed writer
    /// loses less than this much log time. Default 0.5 s.
    pub max_chunk_duration_ns: u64,
    /// A chunk is also closed once it holds this many uncompressed bytes. Default 1 MiB.
    pub max_chunk_bytes: usize,
    /// The log has a temperature column: the `/gyro` channel's `has_temperature` metadata
    /// (messages carry `temperature_c` either way, NaN when a row has none). Default true.
    pub has_temperature: bool,
    /// Create the `/reference` channel up front, and write NaN for rows without a
    /// reference; otherwise it is created at the first row with one. Default false.
    pub has_reference: bool,
    /// How chunks are compressed. Default zstd.
    pub compression: McapCompression,
    /// Level of the compression (0: the codec's default, zstd 3 or lz4's fast mode).
    /// Default 0.
    pub compression_level: u32,
}

impl Default for McapWriteOptions {
    fn default() -> Self {
        Self {
            max_chunk_duration_ns: 500_000_000,
            max_chunk_bytes: 1 << 20,
            has_temperature: true,
            has_reference: false,
            compression: McapCompression::default(),
            compression_level: 0,
        }
    }
}

/// A channel added with [`McapLogWriter::add_json_channel`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct JsonChannel(u16);

#[derive(Serialize)]
struct RawMessage<'a> {
    hex: &'a str,
}

/// Writes a log as MCAP while it is being recorded: `/gyro`, `/reference` (CDR, see the
/// module docs) and any extra JSON channels, in chunks compressed as
/// [`McapWriteOptions::compression`] says (zstd by default) and closed every
/// [`McapWriteOptions::max_chunk_duration_ns`] of log time, metadata as a `gyro` metadata
/// record.
///
/// Call [`finish`](Self::finish) at the end: it writes the summary and footer. A writer
/// dropped without it still finishes the file (errors then go unreported); a killed
/// process leaves every closed chunk readable.
///
/// ```no_run
/// use gyro_log::{McapLogWriter, Row};
/// let mut w = McapLogWriter::create("run.mcap".as_ref())?;
/// w.write_metadata(&[("sample_rate_hz".to_string(), "1000".to_string())].into())?;
/// w.write_row(&Row { line: 1, time_s: 0.0, rate_dps: Some(0.1), reference_deg: None, temperature_c: Some(25.0) })?;
/// w.write_raw(0, &[0x00, 0x01, 0x02])?;
/// w.finish()?;
/// # Ok::<(), gyro_log::LogError>(())
/// ```
pub struct McapLogWriter {
    path: PathBuf,
    writer: Writer<BufWriter<File>>,
    options: McapWriteOptions,
    gyro: u16,
    reference: Option<u16>,
    raw: Option<JsonChannel>,
    /// Next sequence number per channel id.
    sequences: BTreeMap<u16, u32>,
    /// Log time of the first message of the open chunk, if one is open.
    chunk_start_ns: Option<u64>,
    /// Uncompressed bytes in the open chunk (messages only; an estimate).
    chunk_bytes: usize,
    buf: Vec<u8>,
    hex: String,
}

impl McapLogWriter {
    /// Create (truncate) `path` with the default [`McapWriteOptions`].
    pub fn create(path: &Path) -> Result<Self, LogError> {
        Self::create_with(path, McapWriteOptions::default())
    }

    /// Create (truncate) `path`: header, the `/gyro` channel and, if
    /// `options.has_reference`, the `/reference` channel.
    pub fn create_with(path: &Path, options: McapWriteOptions) -> Result<Self, LogError> {
        let file = File::create(path).map_err(|cause| LogError::Io {
            path: path.to_path_buf(),
            cause,
        })?;
        let err = |e| write_error(path, e);
        let mut writer = WriteOptions::new()
            .compression(options.compression.to_mcap())
            .compression_level(options.compression_level)
            // One thread: chunks are small, and the machine is shared with the pipeline.
            .compression_threads(0)
            // Chunks are closed by `roll_chunk`, by time and by size.
            .chunk_size(None)
            // Message indexes cost 16 uncompressed bytes per message (more than the
            // compressed message), but Foxglove's indexed reader rejects chunks without them.
            .library(concat!("gyro-cli ", env!("CARGO_PKG_VERSION")))
            .create(BufWriter::with_capacity(1 << 16, file))
            .map_err(err)?;
        let temperature = [(
            binary::HAS_TEMPERATURE_KEY.to_string(),
            options.has_temperature.to_string(),
        )];
        let gyro = add_cdr_channel(
            &mut writer,
            GYRO_TOPIC,
            binary::SAMPLE_SCHEMA_NAME,
            binary::SAMPLE_DEFINITION,
            &temperature.into(),
        )
        .map_err(err)?;
        let mut this = Self {
            path: path.to_path_buf(),
            writer,
            options,
            gyro,
            reference: None,
            raw: None,
            sequences: BTreeMap::new(),
            chunk_start_ns: None,
            chunk_bytes: 0,
            buf: Vec::with_capacity(256),
            hex: String::new(),
        };
        if this.options.has_reference {
            this.reference_channel()?;
        }
        Ok(this)
    }

    /// The file being written.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Write `metadata` as one `gyro` metadata record (closes the open chunk). Call it
    /// once, e.g. right after [`create`](Self::create); readers merge all `gyro` records.
    pub fn write_metadata(&mut self, metadata: &BTreeMap<String, String>) -> Result<(), LogError> {
        self.writer
            .write_metadata(&Metadata {
                name: METADATA_NAME.to_string(),
                metadata: metadata.clone(),
            })
            .map_err(|e| write_error(&self.path, e))?;
        self.chunk_start_ns = None;
        self.chunk_bytes = 0;
        Ok(())
    }

    /// Write one row: a `/gyro` message (status −1, unknown) and, if the row has a reference
    /// or the writer was created with `has_reference`, a `/reference` message, both at the
    /// row's time. Fails on a time below 0 or beyond u64 nanoseconds.
    pub fn write_row(&mut self, row: &Row) -> Result<(), LogError> {
        let time_ns = seconds_to_ns(row.time_s).ok_or_else(|| LogError::Mcap {
            path: self.path.clone(),
            message: format!(
                "row {}: time {} s cannot be an MCAP log time (must be >= 0 and < 1.8e10 s)",
                row.line, row.time_s
            ),
        })?;
        self.write_gyro(time_ns, row.rate_dps, row.temperature_c, None)?;
        if row.reference_deg.is_some() || self.options.has_reference {
            self.write_reference(time_ns, row.reference_deg)?;
        }
        Ok(())
    }

    /// Write a `/gyro` message. Missing and non-finite values are written as NaN, no
    /// status as −1.
    pub fn write_gyro(
        &mut self,
        time_ns: u64,
        rate_dps: Option<f64>,
        temperature_c: Option<f64>,
        status: Option<u32>,
    ) -> Result<(), LogError> {
        let message = binary::encode_sample(&GyroSample {
            rate_dps,
            temperature_c: temperature_c.filter(|_| self.options.has_temperature),
            status,
        });
        self.write_bytes(self.gyro, time_ns, &message)
    }

    /// Write a `/reference` message (creating the channel at the first one).
    pub fn write_reference(
        &mut self,
        time_ns: u64,
        angle_deg: Option<f64>,
    ) -> Result<(), LogError> {
        let channel = self.reference_channel()?;
        self.write_bytes(channel, time_ns, &binary::encode_reference(angle_deg))
    }

    /// Add a JSON channel: `schema` must be a JSON schema with `"type": "object"` (what
    /// Foxglove needs to plot the messages' fields).
    pub fn add_json_channel(
        &mut self,
        topic: &str,
        schema_name: &str,
        schema: &serde_json::Value,
    ) -> Result<JsonChannel, LogError> {
        if schema.get("type").and_then(|t| t.as_str()) != Some("object") {
            return Err(LogError::McapChannel {
                path: self.path.clone(),
                channel: topic.to_string(),
                message: "a JSON channel's schema needs \"type\": \"object\"".into(),
            });
        }
        let text = schema.to_string();
        let id = add_channel(&mut self.writer, topic, schema_name, &text)
            .map_err(|e| write_error(&self.path, e))?;
        Ok(JsonChannel(id))
    }

    /// Write a JSON message (an object, to match the `"type": "object"` schema) on a
    /// channel from [`add_json_channel`](Self::add_json_channel).
    pub fn write_json(
        &mut self,
        channel: JsonChannel,
        time_ns: u64,
        value: &serde_json::Value,
    ) -> Result<(), LogError> {
        self.write_serialized(channel.0, time_ns, value)
    }

    /// Write raw frame bytes on `/crm100/raw` as `{"hex": "0a1b..."}` (creating the
    /// channel at the first call).
    pub fn write_raw(&mut self, time_ns: u64, bytes: &[u8]) -> Result<(), LogError> {
        let channel = match self.raw {
            Some(channel) => channel,
            None => {
                let id = add_channel(&mut self.writer, RAW_TOPIC, "gyro.RawFrame", RAW_SCHEMA)
                    .map_err(|e| write_error(&self.path, e))?;
                *self.raw.insert(JsonChannel(id))
            }
        };
        let mut hex = std::mem::take(&mut self.hex);
        hex.clear();
        for b in bytes {
            use std::fmt::Write;
            let _ = write!(hex, "{b:02x}");
        }
        let result = self.write_serialized(channel.0, time_ns, &RawMessage { hex: &hex });
        self.hex = hex;
        result
    }

    /// Close the open chunk and flush everything written so far to the OS (e.g. when the
    /// data source goes quiet, so nothing waits in memory).
    pub fn flush(&mut self) -> Result<(), LogError> {
        self.writer
            .flush()
            .map_err(|e| write_error(&self.path, e))?;
        self.chunk_start_ns = None;
        self.chunk_bytes = 0;
        Ok(())
    }

    /// Close the last chunk, write the summary and footer, flush and sync the file.
    pub fn finish(mut self) -> Result<(), LogError> {
        self.writer
            .finish()
            .map_err(|e| write_error(&self.path, e))?;
        let path = self.path;
        let file = self
            .writer
            .into_inner()
            .into_inner()
            .map_err(|e| LogError::Io {
                path: path.clone(),
                cause: e.into_error(),
            })?;
        file.sync_all()
            .map_err(|cause| LogError::Io { path, cause })
    }

    fn reference_channel(&mut self) -> Result<u16, LogError> {
        if let Some(id) = self.reference {
            return Ok(id);
        }
        let id = add_cdr_channel(
            &mut self.writer,
            REFERENCE_TOPIC,
            binary::REFERENCE_SCHEMA_NAME,
            binary::REFERENCE_DEFINITION,
            &BTreeMap::new(),
        )
        .map_err(|e| write_error(&self.path, e))?;
        self.reference = Some(id);
        Ok(id)
    }

    fn write_serialized(
        &mut self,
        channel_id: u16,
        time_ns: u64,
        message: &impl Serialize,
    ) -> Result<(), LogError> {
        let mut buf = std::mem::take(&mut self.buf);
        buf.clear();
        let encoded = serde_json::to_writer(&mut buf, message).map_err(|e| LogError::Mcap {
            path: self.path.clone(),
            message: format!("cannot encode a message as JSON: {e}"),
        });
        let result = encoded.and_then(|()| self.write_bytes(channel_id, time_ns, &buf));
        self.buf = buf;
        result
    }

    fn write_bytes(&mut self, channel_id: u16, time_ns: u64, data: &[u8]) -> Result<(), LogError> {
        self.roll_chunk(time_ns)?;
        let sequence = self.sequences.entry(channel_id).or_insert(0);
        let header = MessageHeader {
            channel_id,
            sequence: *sequence,
            log_time: time_ns,
            publish_time: time_ns,
        };
        *sequence = sequence.wrapping_add(1);
        self.writer
            .write_to_known_channel(&header, data)
            .map_err(|e| write_error(&self.path, e))?;
        self.chunk_start_ns.get_or_insert(time_ns);
        self.chunk_bytes += data.len() + MESSAGE_OVERHEAD;
        Ok(())
    }

    /// Close the open chunk if a message at `time_ns` would make it span too long, or if
    /// it is full.
    fn roll_chunk(&mut self, time_ns: u64) -> Result<(), LogError> {
        if let Some(start) = self.chunk_start_ns {
            if time_ns.abs_diff(start) >= self.options.max_chunk_duration_ns
                || self.chunk_bytes >= self.options.max_chunk_bytes
            {
                self.flush()?;
            }
        }
        Ok(())
    }
}

fn add_channel(
    writer: &mut Writer<BufWriter<File>>,
    topic: &str,
    schema_name: &str,
    schema: &str,
) -> Result<u16, McapError> {
    let schema_id = writer.add_schema(schema_name, "jsonschema", schema.as_bytes())?;
    writer.add_channel(schema_id, topic, "json", &BTreeMap::new())
}

fn add_cdr_channel(
    writer: &mut Writer<BufWriter<File>>,
    topic: &str,
    schema_name: &str,
    definition: &str,
    metadata: &BTreeMap<String, String>,
) -> Result<u16, McapError> {
    let schema_id =
        writer.add_schema(schema_name, binary::SCHEMA_ENCODING, definition.as_bytes())?;
    writer.add_channel(schema_id, topic, binary::MESSAGE_ENCODING, metadata)
}

fn write_error(path: &Path, e: McapError) -> LogError {
    match e {
        McapError::Io(cause) => LogError::Io {
            path: path.to_path_buf(),
            cause,
        },
        e => LogError::Mcap {
            path: path.to_path_buf(),
            message: format!("cannot write: {e}"),
        },
    }
}

/// Write `log` as an MCAP file (see the module docs for the layout): its metadata, then
/// each row as a `/gyro` and (if the log has a reference) a `/reference` message.
///
/// A log whose time goes back by more than placement tolerates (the default
/// [`crate::GridOptions::max_gap_s`]: a concatenated or corrupt log, which `run` refuses as
/// it is) is refused, [`LogError::TimeBackwards`] naming its line, with nothing written:
/// MCAP orders messages by time, so its rows would come back in another order, a log that
/// reads. Stamps from a wrapping counter are to be unwrapped first ([`crate::wraps`]).
///
/// Chunks are compressed with the default [`McapCompression`] (zstd); see
/// [`write_mcap_with`] to choose.
pub fn write_mcap(path: &Path, log: &Log) -> Result<(), LogError> {
    write_mcap_with(path, log, McapCompression::default())
}

/// [`write_mcap`], its chunks compressed with `compression`.
///
/// Chunks stay as the recorder writes them (0.5 s of log time): chunks of ~4 MiB, as the
/// `mcap` CLI writes, make the zstd file of the bench fixture only 2% smaller, since the
/// message indexes (16 bytes a message, uncompressed, which Foxglove needs) are most of
/// it; small chunks keep a damaged file readable up to the damage and the reader's memory
/// at a chunk.
pub fn write_mcap_with(
    path: &Path,
    log: &Log,
    compression: McapCompression,
) -> Result<(), LogError> {
    let window = log.rows.len().min(crate::RATE_WINDOW_STEPS + 1);
    crate::regular::check_time_order(&log.path, &log.rows[..window])?;
    let max_back_s = crate::GridOptions::default().max_gap_s;
    if let Some(e) = log
        .rows
        .windows(2)
        .find_map(|pair| crate::regular::time_backwards(&log.path, &pair[0], &pair[1], max_back_s))
    {
        return Err(e);
    }
    let mut writer = McapLogWriter::create_with(
        path,
        McapWriteOptions {
            has_temperature: log.has_temperature,
            has_reference: log.has_reference,
            compression,
            ..McapWriteOptions::default()
        },
    )?;
    if !log.metadata.is_empty() {
        writer.write_metadata(&log.metadata)?;
    }
    for row in &log.rows {
        writer.write_row(row)?;
    }
    writer.finish()
}
