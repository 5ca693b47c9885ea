//! Where the records of an MCAP file are: one walk over the top-level record headers
//! (opcode and length; a chunk's first 16 bytes for its time range), without reading any
//! chunk's contents. This gives the order chunks are read in (by their first log time),
//! the records outside chunks (definitions, metadata), and where the file is damaged; it
//! works the same with or without a summary section.

use super::MAGIC;
use mcap::records::op;
use std::fs::File;
use std::io::{self, Read, Seek, SeekFrom};

/// Records longer than this are treated as corrupt rather than read.
pub(super) const RECORD_LENGTH_LIMIT: u64 = 1 << 30;

/// Opcode and length before every record's body.
pub(super) const RECORD_HEADER_LEN: u64 = 9;

/// Bytes of a message record's body before its log time ends (channel id, sequence, log
/// time).
const MESSAGE_TIME_END: usize = 2 + 4 + 8;

/// A piece of the data section read as one: a chunk, or a message outside any chunk.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) struct Unit {
    /// Byte offset of the record (its opcode).
    pub offset: u64,
    /// Length of the whole record, header included.
    pub len: u64,
    /// No message in it has an earlier log time (ns): a chunk's `message_start_time`, a
    /// loose message's log time.
    pub start_ns: u64,
    /// A chunk (else a loose message record).
    pub chunk: bool,
}

/// A record outside chunks that the reader needs before any message: a schema, a channel
/// (the data section's or the summary's copy) or a metadata record.
#[derive(Clone, Debug, PartialEq, Eq)]
pub(super) struct Definition {
    pub opcode: u8,
    pub body: Vec<u8>,
}

/// Where the walk stopped before the end of the file.
#[derive(Clone, Debug, PartialEq, Eq)]
pub(super) struct Damage {
    /// Byte offset of the first record that could not be read.
    pub offset: u64,
    /// What is wrong with it.
    pub what: String,
    /// True if the file simply ends inside it (a cut file); false if it is unreadable.
    pub cut: bool,
}

/// The outcome of the walk.
#[derive(Debug, Default)]
pub(super) struct Layout {
    /// File length (bytes).
    pub len: u64,
    /// The file ends with the MCAP magic: its writer finished it.
    pub finished: bool,
    /// A header record was found.
    pub saw_header: bool,
    /// The data section's units, in the order they are read: by `start_ns`, then offset.
    pub units: Vec<Unit>,
    /// Schemas, channels and metadata outside chunks, in file order.
    pub definitions: Vec<Definition>,
    /// The first damage met (the walk stops there).
    pub damage: Option<Damage>,
}

/// Walk the file's top-level records.
pub(super) fn scan(file: &mut File) -> io::Result<Layout> {
    let len = file.metadata()?.len();
    let mut layout = Layout {
        len,
        ..Layout::default()
    };
    layout.finished = len >= 2 * MAGIC.len() as u64 && {
        let mut tail = [0_u8; 8];
        read_at(file, len - MAGIC.len() as u64, &mut tail)?;
        &tail == MAGIC
    };
    let mut magic = [0_u8; 8];
    let got = read_some_at(file, 0, &mut magic)?;
    if got < MAGIC.len() || &magic != MAGIC {
        layout.damage = Some(Damage {
            offset: 0,
            what: if MAGIC.starts_with(&magic[..got]) {
                "the file ends inside the MCAP magic".into()
            } else {
                "bad magic".into()
            },
            cut: MAGIC.starts_with(&magic[..got]),
        });
        return Ok(layout);
    }
    let (offset, footer) = walk_records(file, &mut layout)?;
    if layout.damage.is_none() && !layout.finished {
        // Cut at a record boundary, or inside the closing magic.
        layout.damage = Some(Damage {
            offset,
            what: if footer {
                "the file ends inside the closing magic".into()
            } else {
                "the file ends after a complete record, without a footer".into()
            },
            cut: true,
        });
    }
    // Stable: units with one start time keep their file order.
    layout.units.sort_by_key(|u| u.start_ns);
    Ok(layout)
}

/// Walk the records after the opening magic into `layout` (units, definitions, the header,
/// the damage met) up to the footer, damage or the end of the file: where it stopped, and
/// whether at the footer.
fn walk_records(file: &mut File, layout: &mut Layout) -> io::Result<(u64, bool)> {
    let len = layout.len;
    let mut offset = MAGIC.len() as u64;
    let mut footer = false;
    let mut head = [0_u8; RECORD_HEADER_LEN as usize + 16];
    while offset < len {
        let got = read_some_at(file, offset, &mut head)?;
        let (opcode, body_len, record_len) = match record_header(&head[..got], offset, len) {
            Ok(header) => header,
            Err(damage) => {
                layout.damage = Some(damage);
                break;
            }
        };
        let body = &head[RECORD_HEADER_LEN as usize..got];
        match opcode {
            op::HEADER => layout.saw_header = true,
            op::FOOTER => {
                footer = true;
                break;
            }
            op::CHUNK | op::MESSAGE => match unit(opcode, body, body_len, offset, record_len) {
                Ok(unit) => layout.units.push(unit),
                Err(damage) => {
                    layout.damage = Some(damage);
                    break;
                }
            },
            op::SCHEMA | op::CHANNEL | op::METADATA => {
                let mut body = vec![0_u8; body_len as usize];
                read_at(file, offset + RECORD_HEADER_LEN, &mut body)?;
                layout.definitions.push(Definition { opcode, body });
            }
            _ => {}
        }
        offset += record_len;
    }
    Ok((offset, footer))
}

/// The record at `offset` from the bytes read of it (`head`), in a file of `len` bytes:
/// its opcode, body length and whole length, or the damage if it cannot be read.
fn record_header(head: &[u8], offset: u64, len: u64) -> Result<(u8, u64, u64), Damage> {
    let fail = |what: String, cut: bool| Damage { offset, what, cut };
    if head.len() < RECORD_HEADER_LEN as usize {
        return Err(fail("the file ends inside a record header".into(), true));
    }
    let opcode = head[0];
    let body_len = u64::from_le_bytes(le8(&head[1..9]));
    if body_len > RECORD_LENGTH_LIMIT {
        return Err(fail(
            if body_len == u64::MAX {
                format!("a record (opcode {opcode:#04x}) whose length was never written: an unfinished chunk")
            } else {
                format!("a record (opcode {opcode:#04x}) claims {body_len} bytes: corrupt")
            },
            false,
        ));
    }
    let record_len = RECORD_HEADER_LEN + body_len;
    if offset + record_len > len {
        return Err(fail(
            format!("the file ends inside a record (opcode {opcode:#04x}, {record_len} bytes)"),
            true,
        ));
    }
    Ok((opcode, body_len, record_len))
}

/// The unit of a chunk or message record at `offset` (`body`: its body's first bytes),
/// or the damage if it is too short to hold its start time.
fn unit(
    opcode: u8,
    body: &[u8],
    body_len: u64,
    offset: u64,
    record_len: u64,
) -> Result<Unit, Damage> {
    let chunk = opcode == op::CHUNK;
    let start = if chunk { 0..8 } else { 6..MESSAGE_TIME_END };
    if (body_len as usize) < start.end {
        return Err(Damage {
            offset,
            what: format!("a record (opcode {opcode:#04x}) too short to be read"),
            cut: false,
        });
    }
    Ok(Unit {
        offset,
        len: record_len,
        start_ns: u64::from_le_bytes(le8(&body[start])),
        chunk,
    })
}

fn le8(bytes: &[u8]) -> [u8; 8] {
    let mut out = [0_u8; 8];
    out.copy_from_slice(&bytes[..8]);
    out
}

/// Fill `buf` from `offset`; an error if the file ends first.
pub(super) fn read_at(file: &mut File, offset: u64, buf: &mut [u8]) -> io::Result<()> {
    file.seek(SeekFrom::Start(offset))?;
    file.read_exact(buf)
}

/// Read up to `buf.len()` bytes from `offset`; how many (fewer only at the end of the file).
fn read_some_at(file: &mut File, offset: u64, buf: &mut [u8]) -> io::Result<usize> {
    file.seek(SeekFrom::Start(offset))?;
    let mut filled = 0;
    while filled < buf.len() {
        match file.read(&mut buf[filled..]) {
            Ok(0) => break,
            Ok(n) => filled += n,
            Err(e) if e.kind() == io::ErrorKind::Interrupted => {}
            Err(e) => return Err(e),
        }
    }
    Ok(filled)
}
