//! Reading the data section unit by unit ([`Unit`]: a chunk or a loose message), in the
//! order the layout gives. One `mcap` linear reader is fed the units' bytes one after the
//! other: it checks each chunk's CRC before handing on any of its records and decompresses
//! it (zstd, lz4 or none), reusing its buffers and decompressor from chunk to chunk.

use super::layout::{Unit, RECORD_LENGTH_LIMIT};
use mcap::sans_io::{LinearReadEvent, LinearReader, LinearReaderOptions};
use mcap::McapError;
use std::fs::File;
use std::io::{self, Read, Seek, SeekFrom};

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

/// The data section's units as one stream of records.
pub(super) struct Units {
    file: File,
    units: Vec<Unit>,
    /// Index of the next unit to feed to the reader.
    next: usize,
    /// Bytes of the current unit not yet fed.
    remaining: u64,
    /// The current unit's `UnitDone` has been given.
    announced: bool,
    reader: LinearReader,
    /// The last record given, copied out of the reader.
    opcode: u8,
    record: Vec<u8>,
}

impl Units {
    pub fn new(file: File, units: Vec<Unit>) -> Self {
        Self {
            file,
            units,
            next: 0,
            remaining: 0,
            announced: true,
            reader: LinearReader::new_with_options(
                LinearReaderOptions::default()
                    .with_skip_start_magic(true)
                    .with_skip_end_magic(true)
                    .with_prevalidate_chunk_crcs(true)
                    .with_record_length_limit(RECORD_LENGTH_LIMIT as usize),
            ),
            opcode: 0,
            record: Vec::new(),
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
    pub fn units(&self) -> &[Unit] {
        &self.units
    }

    /// The next event; `None` once every unit has been read.
    pub fn next_event(&mut self) -> Option<Result<Event<'_>, UnitError>> {
        loop {
            let need = match self.reader.next_event()? {
                Ok(LinearReadEvent::ReadRequest(need)) => need,
                Ok(LinearReadEvent::Record { opcode, data }) => {
                    self.opcode = opcode;
                    self.record.clear();
                    self.record.extend_from_slice(data);
                    break;
                }
                Err(e) => return Some(Err(self.damaged(&e))),
            };
            if self.remaining == 0 {
                // The reader asks for exactly the bytes it lacks: wanting more after a
                // unit's last byte, it has given all of that unit's records.
                if !self.announced {
                    self.announced = true;
                    let next_start_ns = self.units.get(self.next).map_or(u64::MAX, |u| u.start_ns);
                    return Some(Ok(Event::UnitDone { next_start_ns }));
                }
                let Some(unit) = self.units.get(self.next) else {
                    self.reader.notify_read(0); // the end
                    continue;
                };
                if let Err(e) = self.file.seek(SeekFrom::Start(unit.offset)) {
                    return Some(Err(UnitError::Io(e)));
                }
                self.remaining = unit.len;
                self.next += 1;
                self.announced = false;
            }
            let want = need.min(self.remaining as usize);
            let read = loop {
                match self.file.read(&mut self.reader.insert(want)[..want]) {
                    Ok(n) => break n,
                    Err(e) if e.kind() == io::ErrorKind::Interrupted => continue,
                    Err(e) => return Some(Err(UnitError::Io(e))),
                }
            };
            if read == 0 {
                // The file shrank since it was scanned.
                return Some(Err(UnitError::Io(io::ErrorKind::UnexpectedEof.into())));
            }
            self.remaining -= read as u64;
            self.reader.notify_read(read);
        }
        Some(Ok(Event::Record {
            opcode: self.opcode,
            data: &self.record,
        }))
    }

    fn damaged(&self, e: &McapError) -> UnitError {
        let offset = self.current_offset();
        let what = match e {
            McapError::UnexpectedEof => "the chunk ends early".into(),
            McapError::RecordTooLarge { .. } | McapError::ChunkTooLarge(_) => {
                format!("{e} (a corrupt length)")
            }
            e => e.to_string(),
        };
        UnitError::Damaged { offset, what }
    }
}
