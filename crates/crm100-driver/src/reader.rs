//! Host side of the serial bridge (feature `std`): a reader over any [`std::io::Read`] (a
//! serial port, a pseudo-terminal, a file, a byte buffer) that runs a [`BridgeReceiver`]
//! and reports **every** event: each good frame with its sequence verdict, each CRC
//! failure, each run of skipped bytes, each read timeout. Nothing is dropped silently: the
//! counters in [`ReaderStats`] add up to what the events said.
//!
//! ```
//! use crm100_driver::{encode_to_array, BridgeFrame, BridgeReader, ReadEvent, SeqEvent};
//!
//! let frame = |seq| BridgeFrame { sequence: seq, timestamp_us: 1000 * seq as u64,
//!                                 command: 0x28, response: [0, 0, 24, 2, 0x13, 0xCC] };
//! let mut wire = encode_to_array(&frame(7)).to_vec();
//! wire.extend_from_slice(&[0xFF, 0x00]); // line noise
//! wire.extend_from_slice(&encode_to_array(&frame(9))); // frame 8 never arrived
//!
//! let mut reader = BridgeReader::new(std::io::Cursor::new(wire));
//! let mut events = Vec::new();
//! while let Some(event) = reader.next_event()? {
//!     events.push(event);
//! }
//! assert!(matches!(events[0], ReadEvent::Frame(r) if r.sequence == SeqEvent::First));
//! assert_eq!(events[1], ReadEvent::Skipped { bytes: 2 });
//! assert!(matches!(events[2], ReadEvent::Frame(r) if r.lost_before() == 1));
//! assert_eq!(reader.stats().receiver.sequence.frames_lost, 1);
//! # Ok::<(), std::io::Error>(())
//! ```
//!
//! A serial port configured with a read timeout returns [`std::io::ErrorKind::TimedOut`]
//! when the line is quiet; the reader turns that into [`ReadEvent::Timeout`] so the caller
//! can flush, refresh a display or check for Ctrl-C, then call again. Interrupted reads
//! (`EINTR`, a signal arrived) are reported as [`ReadEvent::Interrupted`] for the same
//! reason. End of stream (`read` returned 0) ends the events with `Ok(None)`, after a last
//! [`ReadEvent::Skipped`] for a partial frame left in the decoder.

use std::io::{self, ErrorKind, Read};

use crate::bridge::BridgeError;
use crate::sequence::{BridgeReceiver, Received, ReceiverStats};

/// Default size of the read buffer: about 170 frames.
pub const DEFAULT_READ_BUFFER: usize = 4096;

/// What the reader saw.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum ReadEvent {
    /// A frame whose CRC is good, with its place in the sequence. A
    /// [`SeqEvent::Gap`](crate::SeqEvent::Gap) means frames were lost just before it ([`Received::lost_before`]).
    Frame(Received),
    /// A candidate frame (sync and format matched) failed its CRC: a frame was damaged.
    /// Its bytes are reported in a following [`ReadEvent::Skipped`].
    Crc(BridgeError),
    /// Bytes the decoder dropped since the previous event: line noise, damaged or
    /// truncated frames, false syncs. Reported before the next frame or error, before
    /// each blocking read and at the end of the stream.
    Skipped {
        /// Number of bytes dropped.
        bytes: u64,
    },
    /// The source's read timed out with no data (a quiet serial line).
    Timeout,
    /// A read was interrupted by a signal (`EINTR`) before any data arrived.
    Interrupted,
}

/// Counters of a [`BridgeReader`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct ReaderStats {
    /// Decoder and sequence counters: bytes, frames, CRC errors, skipped bytes, lost
    /// frames, gaps, duplicates, steps back.
    pub receiver: ReceiverStats,
    /// `read` calls that returned data.
    pub reads: u64,
    /// Reads that timed out ([`ReadEvent::Timeout`]).
    pub timeouts: u64,
    /// Reads interrupted by a signal ([`ReadEvent::Interrupted`]).
    pub interrupted: u64,
}

/// Reads bridge frames from any byte source; see the [module docs](self).
#[derive(Debug)]
pub struct BridgeReader<R> {
    source: R,
    receiver: BridgeReceiver,
    buffer: Box<[u8]>,
    /// Next unread byte in `buffer[..filled]`.
    position: usize,
    filled: usize,
    /// Skipped bytes already reported.
    skipped_reported: u64,
    /// An event held back while the skipped bytes before it are reported.
    pending: Option<ReadEvent>,
    reads: u64,
    timeouts: u64,
    interrupted: u64,
    ended: bool,
}

impl<R: Read> BridgeReader<R> {
    /// A reader with a [`DEFAULT_READ_BUFFER`]-byte buffer.
    pub fn new(source: R) -> Self {
        Self::with_capacity(source, DEFAULT_READ_BUFFER)
    }

    /// A reader with a `capacity`-byte read buffer (at least 1).
    pub fn with_capacity(source: R, capacity: usize) -> Self {
        BridgeReader {
            source,
            receiver: BridgeReceiver::new(),
            buffer: vec![0; capacity.max(1)].into_boxed_slice(),
            position: 0,
            filled: 0,
            skipped_reported: 0,
            pending: None,
            reads: 0,
            timeouts: 0,
            interrupted: 0,
            ended: false,
        }
    }

    /// All counters so far.
    pub fn stats(&self) -> ReaderStats {
        ReaderStats {
            receiver: self.receiver.stats(),
            reads: self.reads,
            timeouts: self.timeouts,
            interrupted: self.interrupted,
        }
    }

    /// The receiver (decoder and sequence tracker).
    pub const fn receiver(&self) -> &BridgeReceiver {
        &self.receiver
    }

    /// The byte source.
    pub const fn get_ref(&self) -> &R {
        &self.source
    }

    /// The byte source, mutably (e.g. to change a port's timeout).
    pub fn get_mut(&mut self) -> &mut R {
        &mut self.source
    }

    /// Gives the source back; bytes read but not yet decoded are lost.
    pub fn into_inner(self) -> R {
        self.source
    }

    /// The next event; `Ok(None)` once the source reported end of stream (and every
    /// skipped byte has been reported). I/O errors other than timeouts and interruptions
    /// are returned as they are; the reader can be called again after one.
    pub fn next_event(&mut self) -> io::Result<Option<ReadEvent>> {
        if let Some(event) = self.pending.take() {
            return Ok(Some(event));
        }
        loop {
            // Decode what is buffered.
            while self.position < self.filled {
                let byte = self.buffer[self.position];
                self.position += 1;
                let skipped_before = self.skipped();
                if let Some(item) = self.receiver.push(byte) {
                    let event = match item {
                        Ok(received) => ReadEvent::Frame(received),
                        Err(error) => ReadEvent::Crc(error),
                    };
                    let unreported = skipped_before - self.skipped_reported;
                    if unreported > 0 {
                        self.skipped_reported = skipped_before;
                        self.pending = Some(event);
                        return Ok(Some(ReadEvent::Skipped { bytes: unreported }));
                    }
                    return Ok(Some(event));
                }
            }
            // Report skipped bytes before a read that may block.
            if let Some(event) = self.take_skipped() {
                return Ok(Some(event));
            }
            if self.ended {
                return Ok(None);
            }
            self.position = 0;
            self.filled = 0;
            match self.source.read(&mut self.buffer) {
                Ok(0) => {
                    // A partial frame can never complete now.
                    self.ended = true;
                    self.receiver.clear();
                }
                Ok(n) => {
                    self.reads += 1;
                    self.filled = n.min(self.buffer.len());
                }
                Err(e) if e.kind() == ErrorKind::TimedOut || e.kind() == ErrorKind::WouldBlock => {
                    self.timeouts += 1;
                    return Ok(Some(ReadEvent::Timeout));
                }
                Err(e) if e.kind() == ErrorKind::Interrupted => {
                    self.interrupted += 1;
                    return Ok(Some(ReadEvent::Interrupted));
                }
                Err(e) => return Err(e),
            }
        }
    }

    /// Drops a partial frame held in the decoder (counted and reported as skipped by the
    /// next [`next_event`](Self::next_event)), e.g. before giving up on a port.
    pub fn discard_partial(&mut self) {
        self.receiver.clear();
    }

    fn skipped(&self) -> u64 {
        self.receiver.decoder().stats().bytes_skipped
    }

    fn take_skipped(&mut self) -> Option<ReadEvent> {
        let skipped = self.skipped();
        let unreported = skipped - self.skipped_reported;
        self.skipped_reported = skipped;
        (unreported > 0).then_some(ReadEvent::Skipped { bytes: unreported })
    }
}

impl<R: Read> Iterator for BridgeReader<R> {
    type Item = io::Result<ReadEvent>;

    /// [`BridgeReader::next_event`] as an iterator; ends at end of stream. An I/O error is
    /// yielded once; iteration may continue after it.
    fn next(&mut self) -> Option<Self::Item> {
        self.next_event().transpose()
    }
}
