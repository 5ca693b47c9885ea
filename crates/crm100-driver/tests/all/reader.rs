//! Host bridge reader (feature `std`): every frame, gap, CRC error, skipped byte and
//! timeout is an event, and the events add up to the counters.
#![allow(clippy::unwrap_used)]

use crate::common::{bridge_frame, wire};
use crm100_driver::{BridgeReader, ReadEvent, SeqEvent};
use proptest::prelude::*;
use proptest::test_runner::RngSeed;
use std::collections::VecDeque;
use std::io::{self, ErrorKind, Read};

/// A byte source that hands out scripted pieces: data, timeouts, interruptions.
struct Scripted(VecDeque<Result<Vec<u8>, ErrorKind>>);

impl Read for Scripted {
    fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
        match self.0.pop_front() {
            None => Ok(0),
            Some(Err(kind)) => Err(io::Error::new(kind, "scripted")),
            Some(Ok(mut bytes)) => {
                let n = bytes.len().min(buf.len());
                buf[..n].copy_from_slice(&bytes[..n]);
                if n < bytes.len() {
                    self.0.push_front(Ok(bytes.split_off(n)));
                }
                Ok(n)
            }
        }
    }
}

fn all_events<R: Read>(reader: &mut BridgeReader<R>) -> Vec<ReadEvent> {
    let mut events = Vec::new();
    while let Some(event) = reader.next_event().unwrap() {
        events.push(event);
    }
    events
}

#[test]
fn garbage_crc_errors_gaps_and_partial_tail_are_all_reported() {
    let mut bytes = wire(&bridge_frame(10));
    bytes.extend([0x00, 0x11, 0x22]); // noise
    let mut damaged = wire(&bridge_frame(11));
    damaged[12] ^= 0x40; // CRC error
    bytes.extend(&damaged);
    bytes.extend(wire(&bridge_frame(12)));
    bytes.extend(wire(&bridge_frame(15))); // 13, 14 lost
    bytes.extend(&wire(&bridge_frame(16))[..10]); // cut off at the end
    let mut reader = BridgeReader::new(io::Cursor::new(bytes));
    let events = all_events(&mut reader);

    let frames: Vec<_> = events
        .iter()
        .filter_map(|e| match e {
            ReadEvent::Frame(r) => Some((r.frame.sequence, r.sequence)),
            _ => None,
        })
        .collect();
    assert_eq!(frames.len(), 3);
    assert_eq!(frames[0], (10, SeqEvent::First));
    assert!(matches!(frames[1], (12, SeqEvent::Gap(g)) if g.lost == 1)); // 11 was damaged
    assert!(matches!(frames[2], (15, SeqEvent::Gap(g)) if g.lost == 2));
    let crc = events
        .iter()
        .filter(|e| matches!(e, ReadEvent::Crc(_)))
        .count();
    assert_eq!(crc, 1);
    let skipped: u64 = events
        .iter()
        .map(|e| match e {
            ReadEvent::Skipped { bytes } => *bytes,
            _ => 0,
        })
        .sum();
    assert_eq!(skipped, 3 + 24 + 10);
    // The noise is reported before the CRC error it precedes.
    assert_eq!(events[1], ReadEvent::Skipped { bytes: 3 });
    assert!(matches!(events[2], ReadEvent::Crc(_)));
    // The partial tail is the last event.
    assert_eq!(events.last(), Some(&ReadEvent::Skipped { bytes: 10 }));

    let stats = reader.stats();
    assert_eq!(stats.receiver.decoder.bytes_skipped, skipped);
    assert_eq!(stats.receiver.decoder.crc_errors, 1);
    assert_eq!(stats.receiver.sequence.frames_lost, 3);
    assert_eq!(stats.receiver.decoder.frames, 3);
}

#[test]
fn timeouts_and_interruptions_are_events_and_reading_goes_on() {
    let a = wire(&bridge_frame(1));
    let b = wire(&bridge_frame(2));
    let script = VecDeque::from([
        Ok(a[..5].to_vec()),
        Err(ErrorKind::TimedOut),
        Ok(a[5..].to_vec()),
        Err(ErrorKind::Interrupted),
        Ok(b.clone()),
        Err(ErrorKind::WouldBlock),
    ]);
    let mut reader = BridgeReader::new(Scripted(script));
    let events = all_events(&mut reader);
    assert_eq!(events.len(), 5, "{events:?}");
    assert_eq!(events[0], ReadEvent::Timeout);
    assert!(matches!(events[1], ReadEvent::Frame(r) if r.frame.sequence == 1));
    assert_eq!(events[2], ReadEvent::Interrupted);
    assert!(matches!(events[3], ReadEvent::Frame(r) if r.frame.sequence == 2));
    assert_eq!(events[4], ReadEvent::Timeout);
    let stats = reader.stats();
    assert_eq!((stats.timeouts, stats.interrupted, stats.reads), (2, 1, 3));
}

#[test]
fn other_io_errors_are_returned_and_reading_can_resume() {
    let script = VecDeque::from([Err(ErrorKind::BrokenPipe), Ok(wire(&bridge_frame(5)))]);
    let mut reader = BridgeReader::new(Scripted(script));
    assert_eq!(
        reader.next_event().unwrap_err().kind(),
        ErrorKind::BrokenPipe
    );
    assert!(matches!(
        reader.next_event().unwrap(),
        Some(ReadEvent::Frame(_))
    ));
    assert_eq!(reader.next_event().unwrap(), None);
    assert_eq!(reader.next_event().unwrap(), None);
}

#[test]
fn a_one_byte_buffer_gives_the_same_events() {
    let mut bytes = Vec::new();
    for seq in [0_u32, 1, 3, 4] {
        bytes.extend(wire(&bridge_frame(seq)));
        bytes.push(0xA5);
    }
    let big = all_events(&mut BridgeReader::new(io::Cursor::new(bytes.clone())));
    let small = all_events(&mut BridgeReader::with_capacity(io::Cursor::new(bytes), 1));
    assert_eq!(big, small);
    let iterated: Vec<_> = BridgeReader::new(io::Cursor::new(Vec::new()))
        .collect::<io::Result<Vec<_>>>()
        .unwrap();
    assert!(iterated.is_empty());
}

proptest! {
    #![proptest_config(ProptestConfig {
        cases: 128,
        rng_seed: RngSeed::Fixed(0x0052_EADE),
        ..ProptestConfig::default()
    })]

    /// Any bytes in any read sizes: the events account for every byte, frame and CRC
    /// error the counters hold, and reading ends.
    #[test]
    fn events_add_up_to_the_counters(
        frames in proptest::collection::vec((any::<bool>(), 0usize..24, any::<u8>()), 0..40),
        pieces in proptest::collection::vec(1usize..50, 1..20),
    ) {
        let mut bytes = Vec::new();
        for (i, (keep, cut, noise)) in frames.iter().enumerate() {
            let w = wire(&bridge_frame(i as u32 * 2));
            if *keep { bytes.extend(&w); } else { bytes.extend(&w[..*cut]); }
            bytes.push(*noise);
        }
        let mut script = VecDeque::new();
        let mut rest = bytes.as_slice();
        for &n in pieces.iter().cycle() {
            if rest.is_empty() { break; }
            let (piece, tail) = rest.split_at(n.min(rest.len()));
            script.push_back(Ok(piece.to_vec()));
            script.push_back(Err(ErrorKind::TimedOut));
            rest = tail;
        }
        let mut reader = BridgeReader::new(Scripted(script));
        let events = all_events(&mut reader);
        let (mut frames_seen, mut crc, mut skipped, mut lost) = (0u64, 0u64, 0u64, 0u64);
        for e in &events {
            match e {
                ReadEvent::Frame(r) => { frames_seen += 1; lost += u64::from(r.lost_before()); }
                ReadEvent::Crc(_) => crc += 1,
                ReadEvent::Skipped { bytes } => { prop_assert!(*bytes > 0); skipped += bytes }
                ReadEvent::Timeout | ReadEvent::Interrupted => {}
            }
        }
        let s = reader.stats().receiver;
        prop_assert_eq!(frames_seen, s.decoder.frames);
        prop_assert_eq!(crc, s.decoder.crc_errors);
        prop_assert_eq!(skipped, s.decoder.bytes_skipped);
        prop_assert_eq!(lost, s.sequence.frames_lost);
        prop_assert_eq!(s.decoder.bytes_received, bytes.len() as u64);
        prop_assert_eq!(s.decoder.bytes_received, skipped + 24 * frames_seen);
    }
}
