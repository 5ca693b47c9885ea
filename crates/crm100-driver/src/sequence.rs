//! Loss accounting from sequence numbers, and the receiver that combines it with the
//! bridge decoder.
//!
//! The bridge increments a `u32` per SPI transfer. For two consecutive good frames with
//! sequence numbers `from` then `to`, let `d = to − from` (wrapping):
//!
//! | `d`                     | meaning                   | reported as                          |
//! |-------------------------|---------------------------|--------------------------------------|
//! | 1                       | next frame                | [`SeqEvent::InOrder`]                |
//! | 2 ..= 2³¹ − 1           | `d − 1` frames lost       | [`SeqEvent::Gap`] (`from`, `to`, `lost`) |
//! | 0                       | same frame again          | [`SeqEvent::Duplicate`]              |
//! | 2³¹ ..= 2³² − 1         | went backwards            | [`SeqEvent::Backwards`] (bridge restart or reordering; loss unknown, not guessed) |
//!
//! Wrap-around `0xFFFF_FFFF → 0` is `d = 1`, in order. Every gap is reported and counted;
//! nothing is dropped silently. Frames lost before the first good one cannot be seen.

use crate::bridge::{BridgeDecoder, BridgeError, BridgeFrame, DecoderStats, Feed};

/// Largest forward step still read as a gap rather than a step backwards.
pub const MAX_FORWARD_STEP: u32 = 0x7FFF_FFFF;

/// Frames missing between two good frames.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Gap {
    /// Sequence number of the last good frame before the gap.
    pub from: u32,
    /// Sequence number of the first good frame after the gap.
    pub to: u32,
    /// Frames missing in between: `to − from − 1` (wrapping).
    pub lost: u32,
}

/// What one sequence number says about the stream.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum SeqEvent {
    /// The first frame seen (or the first after [`SequenceTracker::reset`]).
    First,
    /// One more than the previous frame.
    InOrder,
    /// Frames were lost.
    Gap(Gap),
    /// Same number as the previous frame.
    Duplicate,
    /// The number went back (the bridge restarted, or frames were reordered); how many were
    /// lost is unknown. Tracking continues from `to`.
    Backwards {
        /// Previous sequence number.
        from: u32,
        /// This sequence number.
        to: u32,
    },
}

/// Counters of a [`SequenceTracker`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct SequenceStats {
    /// Sequence numbers observed.
    pub frames: u64,
    /// Frames lost, summed over all gaps.
    pub frames_lost: u64,
    /// Number of gaps.
    pub gaps: u64,
    /// Duplicates seen.
    pub duplicates: u64,
    /// Steps backwards seen.
    pub backwards: u64,
}

/// Counts lost frames from sequence gaps (wrap-around handled) and reports each gap.
#[derive(Clone, Debug, Default)]
pub struct SequenceTracker {
    last: Option<u32>,
    stats: SequenceStats,
}

impl SequenceTracker {
    /// A tracker that has seen nothing.
    pub const fn new() -> Self {
        SequenceTracker {
            last: None,
            stats: SequenceStats {
                frames: 0,
                frames_lost: 0,
                gaps: 0,
                duplicates: 0,
                backwards: 0,
            },
        }
    }

    /// Counters so far.
    pub const fn stats(&self) -> SequenceStats {
        self.stats
    }

    /// Last sequence number seen.
    pub const fn last(&self) -> Option<u32> {
        self.last
    }

    /// Forgets the last sequence number (counters kept): the next one is [`SeqEvent::First`].
    pub fn reset(&mut self) {
        self.last = None;
    }

    /// Takes the next sequence number.
    pub fn observe(&mut self, sequence: u32) -> SeqEvent {
        self.stats.frames += 1;
        let Some(from) = self.last else {
            self.last = Some(sequence);
            return SeqEvent::First;
        };
        let step = sequence.wrapping_sub(from);
        match step {
            0 => {
                self.stats.duplicates += 1;
                SeqEvent::Duplicate
            }
            1 => {
                self.last = Some(sequence);
                SeqEvent::InOrder
            }
            2..=MAX_FORWARD_STEP => {
                self.last = Some(sequence);
                let lost = step - 1;
                self.stats.gaps += 1;
                self.stats.frames_lost += u64::from(lost);
                SeqEvent::Gap(Gap {
                    from,
                    to: sequence,
                    lost,
                })
            }
            _ => {
                self.last = Some(sequence);
                self.stats.backwards += 1;
                SeqEvent::Backwards { from, to: sequence }
            }
        }
    }
}

/// A good frame and what its sequence number says.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Received {
    /// The frame.
    pub frame: BridgeFrame,
    /// Its place in the sequence.
    pub sequence: SeqEvent,
}

impl Received {
    /// Frames lost right before this one, as its sequence number says (0 unless the
    /// verdict is a [`SeqEvent::Gap`]).
    pub const fn lost_before(&self) -> u32 {
        match self.sequence {
            SeqEvent::Gap(gap) => gap.lost,
            _ => 0,
        }
    }
}

/// Counters of a [`BridgeReceiver`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct ReceiverStats {
    /// Byte-level counters: bytes skipped, CRC errors.
    pub decoder: DecoderStats,
    /// Frame-level counters: frames lost, gaps.
    pub sequence: SequenceStats,
}

/// [`BridgeDecoder`] + [`SequenceTracker`]: bytes in, frames with their sequence verdict out.
#[derive(Clone, Debug, Default)]
pub struct BridgeReceiver {
    decoder: BridgeDecoder,
    tracker: SequenceTracker,
}

impl BridgeReceiver {
    /// A fresh receiver.
    pub const fn new() -> Self {
        BridgeReceiver {
            decoder: BridgeDecoder::new(),
            tracker: SequenceTracker::new(),
        }
    }

    /// All counters.
    pub const fn stats(&self) -> ReceiverStats {
        ReceiverStats {
            decoder: self.decoder.stats(),
            sequence: self.tracker.stats(),
        }
    }

    /// The byte decoder.
    pub const fn decoder(&self) -> &BridgeDecoder {
        &self.decoder
    }

    /// The sequence tracker.
    pub const fn tracker(&self) -> &SequenceTracker {
        &self.tracker
    }

    /// Drops a partial frame held in the decoder (counted as skipped bytes), e.g. at the
    /// end of a stream or after reopening the port. The sequence tracker is kept.
    pub fn clear(&mut self) {
        self.decoder.clear();
    }

    /// Takes one byte; see [`BridgeDecoder::push`].
    pub fn push(&mut self, byte: u8) -> Option<Result<Received, BridgeError>> {
        let item = self.decoder.push(byte)?;
        Some(item.map(|frame| self.track(frame)))
    }

    /// Takes a slice; see [`BridgeDecoder::feed`].
    pub fn feed<'r, 'b>(&'r mut self, bytes: &'b [u8]) -> ReceiverFeed<'r, 'b> {
        ReceiverFeed {
            feed: self.decoder.feed(bytes),
            tracker: &mut self.tracker,
        }
    }

    fn track(&mut self, frame: BridgeFrame) -> Received {
        Received {
            frame,
            sequence: self.tracker.observe(frame.sequence),
        }
    }
}

/// Iterator returned by [`BridgeReceiver::feed`].
#[derive(Debug)]
pub struct ReceiverFeed<'r, 'b> {
    feed: Feed<'r, 'b>,
    tracker: &'r mut SequenceTracker,
}

impl Iterator for ReceiverFeed<'_, '_> {
    type Item = Result<Received, BridgeError>;

    fn next(&mut self) -> Option<Self::Item> {
        let item = self.feed.next()?;
        Some(item.map(|frame| Received {
            frame,
            sequence: self.tracker.observe(frame.sequence),
        }))
    }
}
