//! Reading the data section unit by unit ([`Unit`]: a chunk or a loose message), in the
//! order the layout gives. A chunk compressed with lz4 or zstd (or not compressed) is read whole,
//! decompressed in one call straight into the batch the records are given from, its
//! CRC checked (over the decompressed records, before any of them is given), and its
//! records given in place, without a copy. Any other unit (a loose message, a chunk in
//! another compression) goes through one `mcap` linear reader, fed the units' bytes one
//! after the other.

use super::layout::{Unit, RECORD_HEADER_LEN, RECORD_LENGTH_LIMIT};
use super::lz4;
use mcap::sans_io::{LinearReadEvent, LinearReader, LinearReaderOptions};
use mcap::McapError;
use std::fs::File;
use std::io::{self, Read, Seek, SeekFrom};
use std::ops::Range;
use std::sync::Arc;

/// What the stream of units gives.
pub(super) enum Event<'a> {
    /// A record of the current unit (inside a chunk: after its CRC was checked).
    Record { opcode: u8, data: &'a [u8] },
    /// Every record of a unit has been given; no message of a later unit has a log time
    /// before `next_start_ns` (`u64::MAX` after the last unit).
    UnitDone { next_start_ns: u64 },
}

/// Why the stream stopped early.
#[derive(Debug)]
pub(super) enum UnitError {
    /// The file could not be read.
    Io(io::Error),
    /// The unit at `offset` is damaged (CRC, compression, a record that does not parse).
    Damaged { offset: u64, what: String },
}

/// Bytes of a chunk record's body before its compression name: start and end time,
/// uncompressed size, uncompressed CRC, the name's length.
const CHUNK_FIXED_LEN: usize = 8 + 8 + 8 + 4 + 4;

/// The data section's units as one stream of records.
pub(super) struct Units {
    file: File,
    units: Arc<[Unit]>,
    /// Index of the next unit to read.
    next: usize,
    /// The current unit's bytes, as in the file: the first `raw_len`.
    raw: Vec<u8>,
    raw_len: usize,
    /// zstd's decompression context, reused from chunk to chunk (made at the first).
    zstd: Option<zstd::bulk::Decompressor<'static>>,
    /// For units read otherwise (made at the first).
    reader: Option<LinearReader>,
}

impl Units {
    pub fn new(file: File, units: impl Into<Arc<[Unit]>>) -> Self {
        Self {
            file,
            units: units.into(),
            next: 0,
            raw: Vec::new(),
            raw_len: 0,
            zstd: None,
            reader: None,
        }
    }

    /// Length of the file (bytes).
    pub fn file_len(&self) -> u64 {
        self.file.metadata().map_or(0, |m| m.len())
    }

    /// Offset of the unit being read.
    pub fn current_offset(&self) -> u64 {
        self.next
            .checked_sub(1)
            .and_then(|i| self.units.get(i))
            .map_or(0, |u| u.offset)
    }

    /// The units, in reading order.
    pub fn units(&self) -> Arc<[Unit]> {
        Arc::clone(&self.units)
    }

    /// Read the next unit into `batch`: its records, then its `UnitDone`. `Ok(false)` once
    /// every unit has been read. On an error, the unit's records before the damage are
    /// in `batch` (none for a chunk whose CRC or compression fails).
    fn read_unit(&mut self, batch: &mut Batch) -> Result<bool, UnitError> {
        let Some(&unit) = self.units.get(self.next) else {
            return Ok(false);
        };
        self.next += 1;
        let offset = unit.offset;
        let len = unit.len as usize;
        if self.raw.len() < len {
            self.raw.resize(len, 0); // zeroed once, when it grows: kept for later units
        }
        self.raw_len = len;
        let read = self
            .file
            .seek(SeekFrom::Start(offset))
            .and_then(|_| self.file.read_exact(&mut self.raw[..len]));
        if let Err(e) = read {
            // `UnexpectedEof`: the file shrank since it was scanned.
            return Err(UnitError::Io(e));
        }
        let fast = unit.chunk && self.chunk(offset, batch)?;
        if !fast {
            self.linear(offset, batch)?;
        }
        let next_start_ns = self.units.get(self.next).map_or(u64::MAX, |u| u.start_ns);
        batch.items.push((Item::UnitDone { next_start_ns }, offset));
        Ok(true)
    }

    /// The chunk in `raw`, if compressed with lz4, zstd or not at all: decompressed into
    /// `batch.data`, CRC-checked, its records listed. `Ok(false)` for another compression.
    fn chunk(&mut self, offset: u64, batch: &mut Batch) -> Result<bool, UnitError> {
        let body = self
            .raw
            .get(RECORD_HEADER_LEN as usize..self.raw_len)
            .unwrap_or_default();
        let Some(chunk) = ChunkBody::parse(body, offset)? else {
            return Ok(false);
        };
        let start = batch.data.len();
        chunk.decompress(&mut self.zstd, &mut batch.data, offset)?;
        check_crc(chunk.crc, &mut batch.data, start, offset)?;
        list_records(batch, start, offset)?;
        Ok(true)
    }

    /// The unit in `raw` through the linear reader: its records copied into `batch`.
    fn linear(&mut self, offset: u64, batch: &mut Batch) -> Result<(), UnitError> {
        let reader = self.reader.get_or_insert_with(|| {
            LinearReader::new_with_options(
                LinearReaderOptions::default()
                    .with_skip_start_magic(true)
                    .with_skip_end_magic(true)
                    .with_prevalidate_chunk_crcs(true)
                    .with_record_length_limit(RECORD_LENGTH_LIMIT as usize),
            )
        });
        let mut fed = false;
        loop {
            match reader.next_event() {
                // Not reached: the reader is never told the file ended.
                None => return Ok(()),
                Some(Ok(LinearReadEvent::ReadRequest(_))) => {
                    if fed {
                        // The reader asks for more after the unit's last byte: it has
                        // given all of that unit's records.
                        return Ok(());
                    }
                    let len = self.raw_len;
                    reader.insert(len)[..len].copy_from_slice(&self.raw[..len]);
                    reader.notify_read(len);
                    fed = true;
                }
                Some(Ok(LinearReadEvent::Record { opcode, data })) => {
                    let start = batch.data.len();
                    batch.data.extend_from_slice(data);
                    let range = start..batch.data.len();
                    batch.items.push((Item::Record { opcode, range }, offset));
                }
                Some(Err(e)) => {
                    let what = match e {
                        McapError::UnexpectedEof => "the chunk ends early".into(),
                        McapError::RecordTooLarge { .. } | McapError::ChunkTooLarge(_) => {
                            format!("{e} (a corrupt length)")
                        }
                        e => e.to_string(),
                    };
                    return Err(UnitError::Damaged { offset, what });
                }
            }
        }
    }
}

/// A chunk record's body, read as far as its compressed records.
struct ChunkBody<'a> {
    codec: Codec,
    /// CRC of the uncompressed records (0: none stored).
    crc: u32,
    uncompressed_size: u64,
    compressed_size: u64,
    compressed: &'a [u8],
}

impl<'a> ChunkBody<'a> {
    /// The chunk record `body` of the unit at `offset`; `None` for a compression other
    /// than lz4, zstd or none, an error for a header that does not fit the record.
    fn parse(body: &'a [u8], offset: u64) -> Result<Option<Self>, UnitError> {
        let damaged = |what: String| UnitError::Damaged { offset, what };
        let u64_at = |i: usize| -> Option<u64> {
            Some(u64::from_le_bytes(body.get(i..i + 8)?.try_into().ok()?))
        };
        let u32_at = |i: usize| -> Option<u32> {
            Some(u32::from_le_bytes(body.get(i..i + 4)?.try_into().ok()?))
        };
        let too_short = || damaged("a chunk too short for its header".into());
        let uncompressed_size = u64_at(16).ok_or_else(too_short)?;
        let crc = u32_at(24).ok_or_else(too_short)?;
        let name_len = u32_at(28).ok_or_else(too_short)? as usize;
        let name_end = CHUNK_FIXED_LEN
            .checked_add(name_len)
            .filter(|&end| end <= body.len())
            .ok_or_else(too_short)?;
        let compression = &body[CHUNK_FIXED_LEN..name_end];
        let codec = match compression {
            b"zstd" => Codec::Zstd,
            b"lz4" => Codec::Lz4,
            b"" => Codec::None,
            _ => return Ok(None),
        };
        let compressed_size = u64_at(name_end).ok_or_else(too_short)?;
        let data_start = name_end + 8;
        let compressed = usize::try_from(compressed_size)
            .ok()
            .and_then(|size| body.get(data_start..data_start.checked_add(size)?))
            .ok_or_else(|| {
                damaged(format!(
                    "a chunk whose compressed size ({compressed_size} bytes) exceeds the record"
                ))
            })?;
        if uncompressed_size > RECORD_LENGTH_LIMIT {
            return Err(damaged(format!(
                "a chunk claims {uncompressed_size} uncompressed bytes: corrupt"
            )));
        }
        Ok(Some(Self {
            codec,
            crc,
            uncompressed_size,
            compressed_size,
            compressed,
        }))
    }

    /// Decompress the records onto the end of `data` (`zstd`: the context, made at the
    /// first use); on an error `data` is as it was (`offset`: the unit's, for the error).
    fn decompress(
        &self,
        zstd: &mut Option<zstd::bulk::Decompressor<'static>>,
        data: &mut Vec<u8>,
        offset: u64,
    ) -> Result<(), UnitError> {
        let damaged = |what: String| UnitError::Damaged { offset, what };
        let (compressed, compressed_size, uncompressed_size) = (
            self.compressed,
            self.compressed_size,
            self.uncompressed_size,
        );
        let start = data.len();
        let size = uncompressed_size as usize;
        match self.codec {
            Codec::Lz4 => {
                data.resize(start + size, 0);
                let decoded = lz4::decompress_frame(compressed, &mut data[start..]);
                if let Err(what) = decoded {
                    data.truncate(start);
                    return Err(damaged(format!(
                        "the chunk does not decompress (lz4: {what})"
                    )));
                }
            }
            Codec::Zstd => {
                data.reserve(size);
                let decompressor = match zstd {
                    Some(d) => d,
                    empty => empty.insert(zstd::bulk::Decompressor::new().map_err(UnitError::Io)?),
                };
                let mut out = io::Cursor::new(&mut *data);
                out.set_position(start as u64);
                let wrote = decompressor
                    .decompress_to_buffer(compressed, &mut out)
                    .map_err(|e| damaged(format!("the chunk does not decompress (zstd: {e})")))?;
                if wrote != size {
                    data.truncate(start);
                    return Err(damaged(format!(
                        "the chunk decompresses to {wrote} bytes, its header says {size}"
                    )));
                }
            }
            Codec::None => {
                if compressed_size != uncompressed_size {
                    return Err(damaged(format!(
                    "an uncompressed chunk of {compressed_size} bytes whose header says {uncompressed_size}"
                )));
                }
                data.extend_from_slice(compressed);
            }
        }
        Ok(())
    }
}

/// Check the records decompressed into `data[start..]` against the chunk's `crc` (0: none
/// stored); on a mismatch they are dropped.
fn check_crc(crc: u32, data: &mut Vec<u8>, start: usize, offset: u64) -> Result<(), UnitError> {
    let records = &data[start..];
    if crc != 0 {
        let calculated = crc32fast::hash(records);
        if calculated != crc {
            data.truncate(start);
            return Err(UnitError::Damaged {
                offset,
                what: format!("chunk CRC mismatch (stored {crc:08x}, computed {calculated:08x})"),
            });
        }
    }
    Ok(())
}

/// List the records in `batch.data[start..]` (a chunk's, of the unit at `offset`) as
/// the batch's items, each a range of that data.
fn list_records(batch: &mut Batch, start: usize, offset: u64) -> Result<(), UnitError> {
    let damaged = |what: String| UnitError::Damaged { offset, what };
    let header_len = RECORD_HEADER_LEN as usize;
    let end = batch.data.len();
    let mut at = start;
    while at < end {
        let rest = &batch.data[at..end];
        let Some(len) = rest
            .get(1..header_len)
            .and_then(|b| Some(u64::from_le_bytes(b.try_into().ok()?)))
        else {
            return Err(damaged("the chunk ends inside a record header".into()));
        };
        let opcode = rest[0];
        let Some(record_end) = usize::try_from(len)
            .ok()
            .and_then(|len| len.checked_add(at + header_len))
            .filter(|&e| e <= end)
        else {
            return Err(damaged(format!(
                "a record (opcode {opcode:#04x}) of {len} bytes overruns its chunk"
            )));
        };
        let range = at + header_len..record_end;
        batch.items.push((Item::Record { opcode, range }, offset));
        at = record_end;
    }
    Ok(())
}

/// How a chunk's records are compressed (the chunk record's `compression`).
#[derive(Clone, Copy)]
enum Codec {
    None,
    Zstd,
    Lz4,
}

/// A batch is refilled with whole units until its records hold this many bytes (fewer
/// refills than one per chunk; the memory held is about one batch).
const BATCH_BYTES: usize = 1 << 18;

/// One event of a batch.
enum Item {
    /// A record: its opcode and its bytes in the batch's `data`.
    Record {
        opcode: u8,
        range: Range<usize>,
    },
    UnitDone {
        next_start_ns: u64,
    },
}

/// Events of one or more units, as [`Units`] gave them.
#[derive(Default)]
struct Batch {
    data: Vec<u8>,
    /// The events, each with [`Units::current_offset`] when it was given.
    items: Vec<(Item, u64)>,
    /// After the items: nothing (more batches follow), the end (`Some(None)`) or an error.
    last: Option<Option<UnitError>>,
    /// [`Units::current_offset`] when `last` was given.
    last_offset: u64,
}

/// [`Units`] as events, a batch of whole units at a time, on the caller's thread: the
/// thread that decodes the messages also reads and decompresses the chunks, and the grid
/// and the pipeline keep the other core (a third thread that decompressed ahead made
/// `run` no faster on two cores, and held more chunks).
pub(super) struct UnitEvents {
    units: Units,
    current: Batch,
    /// Next item of `current` to give.
    position: usize,
    /// The stream has ended (an error or the end was given).
    done: bool,
    offset: u64,
}

impl UnitEvents {
    pub fn new(units: Units) -> Self {
        Self {
            units,
            current: Batch::default(),
            position: 0,
            done: false,
            offset: 0,
        }
    }

    /// Length of the file (bytes).
    pub fn file_len(&self) -> u64 {
        self.units.file_len()
    }

    /// [`Units::current_offset`] when the last event was given.
    pub fn current_offset(&self) -> u64 {
        self.offset
    }

    /// The units, in reading order.
    pub fn units(&self) -> Arc<[Unit]> {
        self.units.units()
    }

    /// The next record of the current unit, the end of a unit, or why reading stopped;
    /// `None` after the last.
    pub fn next_event(&mut self) -> Option<Result<Event<'_>, UnitError>> {
        loop {
            if let Some((item, offset)) = self.current.items.get(self.position) {
                self.position += 1;
                self.offset = *offset;
                return Some(Ok(match item {
                    Item::Record { opcode, range } => Event::Record {
                        opcode: *opcode,
                        data: self.current.data.get(range.clone()).unwrap_or_default(),
                    },
                    Item::UnitDone { next_start_ns } => Event::UnitDone {
                        next_start_ns: *next_start_ns,
                    },
                }));
            }
            if self.done {
                return None;
            }
            if let Some(last) = self.current.last.take() {
                self.done = true;
                self.offset = self.current.last_offset;
                return last.map(Err);
            }
            fill(&mut self.units, &mut self.current);
            self.position = 0;
        }
    }
}

/// Empty `batch` and fill it with the next units' events: whole units until it holds
/// [`BATCH_BYTES`], the end or an error.
fn fill(units: &mut Units, batch: &mut Batch) {
    batch.data.clear();
    batch.items.clear();
    batch.last = None;
    while batch.last.is_none() && batch.data.len() < BATCH_BYTES {
        match units.read_unit(batch) {
            Ok(true) => {}
            Ok(false) => batch.last = Some(None),
            Err(e) => batch.last = Some(Some(e)),
        }
    }
    batch.last_offset = units.current_offset();
}
