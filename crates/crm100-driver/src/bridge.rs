//! Serial bridge framing: how a bridge MCU forwards CRM100 responses over UART/USB.
//!
//! The CRM100 speaks only SPI. A bridge MCU polls it at 1 kHz and sends each 6-byte
//! response, untouched, inside one [`BridgeFrame`] of [`BRIDGE_FRAME_LEN`] = 24 bytes. The
//! bridge does not judge the response (the host does, with the same codec), so the host
//! sees exactly what the sensor said. Modelled on quartiq/stabilizer's stream header: magic,
//! format, sequence number, so that the receiver detects loss and never guesses.
//!
//! # Frame layout, format 1
//!
//! All multi-byte fields little-endian.
//!
//! | offset | size | field          | content                                                 |
//! |-------:|-----:|----------------|---------------------------------------------------------|
//! | 0      | 2    | sync           | `0xA5 0x5A` ([`SYNC`])                                  |
//! | 2      | 1    | format         | `0x01` ([`FORMAT_V1`]); anything else is not a frame    |
//! | 3      | 1    | command        | command byte sent in the SPI transfer that read `response` |
//! | 4      | 4    | sequence       | `u32`, +1 per SPI transfer, wraps `0xFFFF_FFFF` → 0     |
//! | 8      | 8    | timestamp_us   | `u64`, bridge's monotonic µs clock when CS went low     |
//! | 16     | 6    | response       | the 6 bytes from MISO, raw                              |
//! | 22     | 2    | crc            | CRC-16/CCITT-FALSE over bytes 2..22 (format … response) |
//!
//! 24 bytes at 1 kHz = 24 kB/s: 240 kbit/s with 8N1, so a UART at ≥ 460 800 Bd (921 600
//! recommended) or USB CDC. A `u32` sequence at 1 kHz wraps after 49.7 days; a `u64` µs
//! timestamp never does (a `u32` would after 71 minutes, shorter than a bench session).
//! The sync word is not covered by the CRC (it is compared verbatim); the format byte is, and
//! is also checked before the CRC so a false sync is dropped early.
//!
//! # Receiving
//! [`BridgeDecoder`] takes bytes one at a time ([`BridgeDecoder::push`]) or a slice at a time
//! ([`BridgeDecoder::feed`]) and resynchronises by itself: it drops bytes until it sees
//! `sync, format`; once 24 bytes are buffered it checks the CRC; on a CRC failure it reports
//! [`BridgeError::Crc`] and re-scans from the byte *after* the false sync, so a frame that
//! starts inside a corrupt or truncated one is still found. Counters: bytes received, bytes
//! skipped, frames decoded, CRC errors ([`DecoderStats`]).
//!
//! Limit of the format: a damaged or truncated frame, read together with the bytes that
//! follow it, passes the 16-bit CRC by chance with probability 2⁻¹⁶. The decoder then returns
//! a frame made of two frames' bytes, and the good frame it overlapped is lost. Depending on
//! where the damage lies, the loss count is then one too low (the mixed frame carries the
//! damaged frame's own sequence number) or a spurious gap or step backwards is reported.
//! Validating the forwarded response with the CRM100 checksum ([`crate::decode`]) catches
//! most mixed frames.
//!
//! [`crate::SequenceTracker`] turns sequence numbers into reported gaps, and
//! [`crate::BridgeReceiver`] runs both. A host reader wraps either around any byte source:
//!
//! ```
//! use std::io::Read;
//! use crm100_driver::{encode_to_array, BridgeFrame, BridgeReceiver};
//!
//! // Two frames, with garbage in between and a lost frame (sequence 1).
//! let frame = |seq| BridgeFrame { sequence: seq, timestamp_us: 1000 * seq as u64,
//!                                 command: 0x38, response: [0, 0, 0, 2, 0x58, 0xA5] };
//! let mut wire = encode_to_array(&frame(0)).to_vec();
//! wire.extend_from_slice(&[0x13, 0x37, 0xA5]);
//! wire.extend_from_slice(&encode_to_array(&frame(2)));
//! let mut port = std::io::Cursor::new(wire); // a serial port in real life
//!
//! let mut receiver = BridgeReceiver::new();
//! let mut buffer = [0u8; 64];
//! let mut frames = Vec::new();
//! loop {
//!     let n = port.read(&mut buffer)?;
//!     if n == 0 { break; }
//!     for item in receiver.feed(&buffer[..n]) {
//!         match item {
//!             Ok(received) => frames.push(received),
//!             Err(error) => eprintln!("bridge: {error}"),
//!         }
//!     }
//! }
//! assert_eq!(frames.len(), 2);
//! assert_eq!(receiver.stats().sequence.frames_lost, 1);
//! assert_eq!(receiver.stats().decoder.bytes_skipped, 3);
//! # Ok::<(), std::io::Error>(())
//! ```

use core::fmt;

use crate::crc16::crc16_ccitt_false;
use crate::frame::FRAME_LEN;

/// Sync word at the start of every bridge frame.
pub const SYNC: [u8; 2] = [0xA5, 0x5A];

/// Format byte of the layout documented in this module.
pub const FORMAT_V1: u8 = 0x01;

/// Length of a format-1 bridge frame in bytes.
pub const BRIDGE_FRAME_LEN: usize = 24;

const CRC_START: usize = 2;
const CRC_END: usize = 22;

/// One forwarded SPI exchange.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct BridgeFrame {
    /// Per-transfer counter of the bridge (wrapping).
    pub sequence: u32,
    /// Bridge's monotonic microsecond clock when CS went low.
    pub timestamp_us: u64,
    /// Command byte sent in the transfer that read `response`.
    pub command: u8,
    /// The 6 bytes received from the CRM100, raw.
    pub response: [u8; FRAME_LEN],
}

impl BridgeFrame {
    /// The frame's 24 bytes.
    pub fn to_bytes(&self) -> [u8; BRIDGE_FRAME_LEN] {
        encode_to_array(self)
    }

    /// Parses exactly one frame (sync, format and CRC checked).
    pub fn from_bytes(bytes: &[u8; BRIDGE_FRAME_LEN]) -> Result<BridgeFrame, BridgeError> {
        if bytes[0..2] != SYNC {
            return Err(BridgeError::Sync);
        }
        if bytes[2] != FORMAT_V1 {
            return Err(BridgeError::Format(bytes[2]));
        }
        check_crc(bytes)?;
        Ok(parse_unchecked(bytes))
    }
}

/// Why bytes were not accepted as a bridge frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum BridgeError {
    /// A candidate frame (sync and format matched) failed its CRC. The decoder has already
    /// resumed the search at the byte after the false sync.
    Crc {
        /// CRC computed over bytes 2..22.
        expected: u16,
        /// CRC carried in bytes 22..24.
        found: u16,
    },
    /// [`BridgeFrame::from_bytes`]: the first two bytes are not [`SYNC`].
    Sync,
    /// [`BridgeFrame::from_bytes`]: unknown format byte.
    Format(u8),
}

impl fmt::Display for BridgeError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            BridgeError::Crc { expected, found } => write!(
                f,
                "bridge frame CRC mismatch: expected {expected:#06x}, found {found:#06x}"
            ),
            BridgeError::Sync => write!(f, "bridge frame does not start with the sync word"),
            BridgeError::Format(format) => {
                write!(f, "unsupported bridge frame format {format:#04x}")
            }
        }
    }
}

impl core::error::Error for BridgeError {}

/// Writes `frame` into `out` and returns the number of bytes written ([`BRIDGE_FRAME_LEN`]).
///
/// ```
/// use crm100_driver::{encode, BridgeFrame, BRIDGE_FRAME_LEN};
///
/// let mut out = [0u8; BRIDGE_FRAME_LEN];
/// let frame = BridgeFrame { sequence: 1, timestamp_us: 1000, command: 0x38,
///                           response: [0, 0, 0, 2, 0x13, 0xEA] };
/// let n = encode(&frame, &mut out);
/// assert_eq!(&out[..4], &[0xA5, 0x5A, 0x01, 0x38]);
/// assert_eq!(BridgeFrame::from_bytes(&out), Ok(frame));
/// # assert_eq!(n, BRIDGE_FRAME_LEN);
/// ```
pub fn encode(frame: &BridgeFrame, out: &mut [u8; BRIDGE_FRAME_LEN]) -> usize {
    out[0..2].copy_from_slice(&SYNC);
    out[2] = FORMAT_V1;
    out[3] = frame.command;
    out[4..8].copy_from_slice(&frame.sequence.to_le_bytes());
    out[8..16].copy_from_slice(&frame.timestamp_us.to_le_bytes());
    out[16..22].copy_from_slice(&frame.response);
    let crc = crc16_ccitt_false(&out[CRC_START..CRC_END]);
    out[22..24].copy_from_slice(&crc.to_le_bytes());
    BRIDGE_FRAME_LEN
}

/// [`encode`] into a new array.
pub fn encode_to_array(frame: &BridgeFrame) -> [u8; BRIDGE_FRAME_LEN] {
    let mut out = [0u8; BRIDGE_FRAME_LEN];
    encode(frame, &mut out);
    out
}

fn check_crc(bytes: &[u8; BRIDGE_FRAME_LEN]) -> Result<(), BridgeError> {
    let expected = crc16_ccitt_false(&bytes[CRC_START..CRC_END]);
    let found = u16::from_le_bytes([bytes[22], bytes[23]]);
    if expected == found {
        Ok(())
    } else {
        Err(BridgeError::Crc { expected, found })
    }
}

fn parse_unchecked(bytes: &[u8; BRIDGE_FRAME_LEN]) -> BridgeFrame {
    let [s0, s1, s2, s3] = [bytes[4], bytes[5], bytes[6], bytes[7]];
    let mut timestamp = [0u8; 8];
    timestamp.copy_from_slice(&bytes[8..16]);
    let mut response = [0u8; FRAME_LEN];
    response.copy_from_slice(&bytes[16..22]);
    BridgeFrame {
        sequence: u32::from_le_bytes([s0, s1, s2, s3]),
        timestamp_us: u64::from_le_bytes(timestamp),
        command: bytes[3],
        response,
    }
}

/// Decoder counters. Invariant: `bytes_received = bytes_skipped + 24 × frames +
/// pending bytes` ([`BridgeDecoder::pending`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct DecoderStats {
    /// Bytes pushed in.
    pub bytes_received: u64,
    /// Bytes dropped as not belonging to any good frame (garbage, truncated and corrupt
    /// frames, false syncs).
    pub bytes_skipped: u64,
    /// Good frames returned.
    pub frames: u64,
    /// Candidate frames (sync and format matched) that failed the CRC.
    pub crc_errors: u64,
}

/// Streaming bridge-frame decoder: push bytes in, get frames out. No allocation; 24 bytes
/// of buffer.
#[derive(Clone, Debug, Default)]
pub struct BridgeDecoder {
    buffer: [u8; BRIDGE_FRAME_LEN],
    len: usize,
    stats: DecoderStats,
}

impl BridgeDecoder {
    /// An empty decoder.
    pub const fn new() -> Self {
        BridgeDecoder {
            buffer: [0; BRIDGE_FRAME_LEN],
            len: 0,
            stats: DecoderStats {
                bytes_received: 0,
                bytes_skipped: 0,
                frames: 0,
                crc_errors: 0,
            },
        }
    }

    /// Counters so far.
    pub const fn stats(&self) -> DecoderStats {
        self.stats
    }

    /// Bytes buffered as the possible start of a frame (0..24).
    pub const fn pending(&self) -> usize {
        self.len
    }

    /// Drops the buffered bytes (counted as skipped), e.g. after reopening the port.
    pub fn clear(&mut self) {
        self.stats.bytes_skipped += self.len as u64;
        self.len = 0;
    }

    /// Takes one byte. Returns `Some(Ok(frame))` when it completes a good frame,
    /// `Some(Err(_))` when it completes a candidate that fails the CRC, `None` otherwise.
    /// At most one result per byte; never panics.
    pub fn push(&mut self, byte: u8) -> Option<Result<BridgeFrame, BridgeError>> {
        self.stats.bytes_received += 1;
        // `len < BRIDGE_FRAME_LEN` holds between calls: a full buffer is always consumed.
        if let Some(slot) = self.buffer.get_mut(self.len) {
            *slot = byte;
            self.len += 1;
        } else {
            // Unreachable by the invariant; refuse the byte rather than panic.
            self.stats.bytes_skipped += 1;
            return None;
        }
        self.align();
        if self.len < BRIDGE_FRAME_LEN {
            return None;
        }
        match check_crc(&self.buffer) {
            Ok(()) => {
                let frame = parse_unchecked(&self.buffer);
                self.len = 0;
                self.stats.frames += 1;
                Some(Ok(frame))
            }
            Err(error) => {
                self.stats.crc_errors += 1;
                // Re-scan from the byte after the false sync.
                self.drop_front(1);
                self.align();
                Some(Err(error))
            }
        }
    }

    /// Takes a slice; the iterator yields what [`BridgeDecoder::push`] would, in order. Bytes
    /// the iterator is not driven over are not consumed.
    pub fn feed<'d, 'b>(&'d mut self, bytes: &'b [u8]) -> Feed<'d, 'b> {
        Feed {
            decoder: self,
            bytes: bytes.iter(),
        }
    }

    /// Drops leading bytes until the buffer is empty or starts like a frame header.
    fn align(&mut self) {
        let start = (0..self.len)
            .find(|&i| header_prefix_ok(&self.buffer[i..self.len]))
            .unwrap_or(self.len);
        self.drop_front(start);
    }

    fn drop_front(&mut self, count: usize) {
        let count = count.min(self.len);
        if count > 0 {
            self.buffer.copy_within(count..self.len, 0);
            self.len -= count;
            self.stats.bytes_skipped += count as u64;
        }
    }
}

/// `true` if `bytes` (possibly shorter than the header) agree with sync and format.
fn header_prefix_ok(bytes: &[u8]) -> bool {
    let header = [SYNC[0], SYNC[1], FORMAT_V1];
    bytes.iter().zip(header.iter()).all(|(a, b)| a == b)
}

/// Iterator returned by [`BridgeDecoder::feed`].
#[derive(Debug)]
pub struct Feed<'d, 'b> {
    decoder: &'d mut BridgeDecoder,
    bytes: core::slice::Iter<'b, u8>,
}

impl Iterator for Feed<'_, '_> {
    type Item = Result<BridgeFrame, BridgeError>;

    fn next(&mut self) -> Option<Self::Item> {
        for &byte in self.bytes.by_ref() {
            if let Some(item) = self.decoder.push(byte) {
                return Some(item);
            }
        }
        None
    }
}
