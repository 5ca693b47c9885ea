//! Reading the data section unit by unit ([`Unit`]: a chunk or a loose message), in the
//! order the layout gives. One `mcap` linear reader is fed the units' bytes one after the
//! other: it checks each chunk's CRC before handing on any of its records and decompresses
//! it (zstd, lz4 or none), reusing its buffers and decompressor from chunk to chunk.

use super::layout::{Unit, RECORD_LENGTH_LIMIT};
use mcap::sans_io::{LinearReadEvent, LinearReader, LinearReaderOptions};
use mcap::McapError;
use std::fs::File;
use std::io::{self, Read, Seek, SeekFrom};
use std::ops::Range;
use std::sync::mpsc::{sync_channel, Receiver, SyncSender};
use std::sync::{Arc, Mutex};
use std::thread::JoinHandle;

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
    units: Arc<[Unit]>,
    /// Index of the next unit to feed to the reader.
    next: usize,
    /// Bytes of the current unit not yet fed.
    remaining: u64,
    /// The current unit's `UnitDone` has been given.
    announced: bool,
    reader: LinearReader,
    /// The last record given, copied out of the reader.
    record: Vec<u8>,
}

/// An [`Event`] whose record was copied out.
enum Next {
    Record { opcode: u8 },
    UnitDone { next_start_ns: u64 },
}

impl Units {
    pub fn new(file: File, units: impl Into<Arc<[Unit]>>) -> Self {
        Self {
            file,
            units: units.into(),
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
    pub fn units(&self) -> Arc<[Unit]> {
        Arc::clone(&self.units)
    }

    /// The next event; `None` once every unit has been read.
    pub fn next_event(&mut self) -> Option<Result<Event<'_>, UnitError>> {
        let mut record = std::mem::take(&mut self.record);
        record.clear();
        let next = self.next_into(&mut record);
        self.record = record;
        Some(next?.map(|next| match next {
            Next::Record { opcode } => Event::Record {
                opcode,
                data: &self.record,
            },
            Next::UnitDone { next_start_ns } => Event::UnitDone { next_start_ns },
        }))
    }

    /// The next event, a record's bytes appended to `data`; `None` once every unit has
    /// been read.
    fn next_into(&mut self, data: &mut Vec<u8>) -> Option<Result<Next, UnitError>> {
        loop {
            let need = match self.reader.next_event()? {
                Ok(LinearReadEvent::ReadRequest(need)) => need,
                Ok(LinearReadEvent::Record {
                    opcode,
                    data: record,
                }) => {
                    data.extend_from_slice(record);
                    return Some(Ok(Next::Record { opcode }));
                }
                Err(e) => return Some(Err(self.damaged(&e))),
            };
            if self.remaining == 0 {
                // The reader asks for exactly the bytes it lacks: wanting more after a
                // unit's last byte, it has given all of that unit's records.
                if !self.announced {
                    self.announced = true;
                    let next_start_ns = self.units.get(self.next).map_or(u64::MAX, |u| u.start_ns);
                    return Some(Ok(Next::UnitDone { next_start_ns }));
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

/// Batches in flight between the threads of [`UnitsAhead`].
const BATCHES_AHEAD: usize = 2;
/// A batch is sent once its records hold this many bytes, at the end of a unit (fewer
/// hand-overs between the threads than one per chunk; the memory held is about
/// `BATCHES_AHEAD + 2` batches).
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

/// [`Units`] read on a thread of its own: the file is read, CRC-checked and decompressed a
/// few units ahead while the caller decodes the records. The same events in the same
/// order, with the same offsets; if the thread cannot be started, the units are read on
/// the caller's thread.
pub(super) struct UnitsAhead {
    units: Arc<[Unit]>,
    file_len: u64,
    source: Source,
    current: Batch,
    /// Next item of `current` to give.
    position: usize,
    /// The stream has ended (an error or the end was given).
    done: bool,
    offset: u64,
}

enum Source {
    Thread {
        batches: Option<Receiver<Batch>>,
        spare: SyncSender<Batch>,
        thread: Option<JoinHandle<()>>,
    },
    Here(Box<Units>),
}

impl UnitsAhead {
    pub fn new(units: Units) -> Self {
        let list = units.units();
        let file_len = units.file_len();
        let shared = Arc::new(Mutex::new(Some(units)));
        let (sender, batches) = sync_channel::<Batch>(BATCHES_AHEAD);
        let (spare, spares) = sync_channel::<Batch>(BATCHES_AHEAD + 2);
        let theirs = Arc::clone(&shared);
        let thread = std::thread::Builder::new()
            .name("gyro-mcap-units".into())
            .spawn(move || {
                let Some(units) = theirs.lock().ok().and_then(|mut u| u.take()) else {
                    return;
                };
                produce(units, &sender, &spares);
            });
        let source = match thread {
            Ok(thread) => Source::Thread {
                batches: Some(batches),
                spare,
                thread: Some(thread),
            },
            Err(_) => match shared.lock().ok().and_then(|mut u| u.take()) {
                Some(units) => Source::Here(Box::new(units)),
                // Not reached: the closure that would have taken them was not run.
                None => Source::Thread {
                    batches: None,
                    spare,
                    thread: None,
                },
            },
        };
        Self {
            units: list,
            file_len,
            source,
            current: Batch::default(),
            position: 0,
            done: false,
            offset: 0,
        }
    }

    /// Length of the file (bytes).
    pub fn file_len(&self) -> u64 {
        self.file_len
    }

    /// [`Units::current_offset`] when the last event was given.
    pub fn current_offset(&self) -> u64 {
        match &self.source {
            Source::Here(units) => units.current_offset(),
            Source::Thread { .. } => self.offset,
        }
    }

    /// The units, in reading order.
    pub fn units(&self) -> Arc<[Unit]> {
        Arc::clone(&self.units)
    }

    /// [`Units::next_event`].
    pub fn next_event(&mut self) -> Option<Result<Event<'_>, UnitError>> {
        let (batches, spare) = match &mut self.source {
            Source::Here(units) => return units.next_event(),
            Source::Thread { batches, spare, .. } => (batches, spare),
        };
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
            let Some(next) = batches.as_ref().and_then(|b| b.recv().ok()) else {
                self.done = true;
                return Some(Err(UnitError::Io(io::Error::other(
                    "the thread reading the file stopped",
                ))));
            };
            let used = std::mem::replace(&mut self.current, next);
            let _ = spare.try_send(used);
            self.position = 0;
        }
    }
}

impl Drop for UnitsAhead {
    /// The thread stops at its next batch once nobody receives them.
    fn drop(&mut self) {
        if let Source::Thread {
            batches, thread, ..
        } = &mut self.source
        {
            *batches = None;
            if let Some(thread) = thread.take() {
                let _ = thread.join();
            }
        }
    }
}

/// The thread of [`UnitsAhead`]: every event of `units`, in batches of whole units, until
/// the end, an error, or nobody receives.
fn produce(mut units: Units, sender: &SyncSender<Batch>, spares: &Receiver<Batch>) {
    loop {
        let mut batch = spares.try_recv().unwrap_or_default();
        batch.data.clear();
        batch.items.clear();
        batch.last = None;
        loop {
            let start = batch.data.len();
            let item = match units.next_into(&mut batch.data) {
                Some(Ok(Next::Record { opcode })) => Item::Record {
                    opcode,
                    range: start..batch.data.len(),
                },
                Some(Ok(Next::UnitDone { next_start_ns })) => Item::UnitDone { next_start_ns },
                Some(Err(e)) => {
                    batch.last = Some(Some(e));
                    break;
                }
                None => {
                    batch.last = Some(None);
                    break;
                }
            };
            let unit_done = matches!(item, Item::UnitDone { .. });
            batch.items.push((item, units.current_offset()));
            if unit_done && batch.data.len() >= BATCH_BYTES {
                break;
            }
        }
        batch.last_offset = units.current_offset();
        let last = batch.last.is_some();
        if sender.send(batch).is_err() || last {
            return;
        }
    }
}
