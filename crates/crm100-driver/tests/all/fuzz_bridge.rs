//! Fuzz: the CRM100 frame decoder, the bridge-frame decoder and `BridgeReader` over
//! arbitrary bytes (random, and a bridge stream built from the firmware fixture's rate
//! words, then mutated: bit flips, truncation, insertion, duplication, deletion). None
//! may panic; every error is one line naming what is wrong; the counters add up.
#![allow(clippy::unwrap_used)] // a failed unwrap fails the test

use crm100_driver::{
    decode_slice, encode_to_array, BridgeDecoder, BridgeFrame, BridgeReader, Checks, Range,
    ReadEvent, Response, Status, BRIDGE_FRAME_LEN,
};
use proptest::prelude::*;
use proptest::test_runner::RngSeed;
use std::io;
use std::path::Path;

/// Cases per property.
const CASES: u32 = 2048;

/// A bridge stream of the first `frames` rate words of `fixtures/firmware/bench_run_20s.i16be`
/// (big-endian i16 words, as the firmware reads them), one frame per millisecond.
fn fixture_stream(frames: usize) -> Vec<u8> {
    let path =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/firmware/bench_run_20s.i16be");
    let words = std::fs::read(path).unwrap();
    let mut bytes = Vec::new();
    for (i, word) in words.chunks_exact(2).take(frames).enumerate() {
        let response = Response {
            status: Status(0),
            rate_counts: i16::from_be_bytes([word[0], word[1]]),
            temperature_word: 600,
        };
        let frame = BridgeFrame {
            sequence: i as u32,
            timestamp_us: i as u64 * 1000,
            command: Range::Dps300.command(),
            response: response.to_bytes(),
        };
        bytes.extend_from_slice(&encode_to_array(&frame));
    }
    bytes
}

/// One change to a byte string; positions are taken modulo its length.
#[derive(Clone, Debug)]
enum Mutation {
    Flip { at: usize, bit: u8 },
    Truncate { at: usize },
    Insert { at: usize, bytes: Vec<u8> },
    Duplicate { from: usize, len: usize, at: usize },
    Delete { from: usize, len: usize },
}

fn mutation() -> impl Strategy<Value = Mutation> {
    prop_oneof![
        4 => (any::<usize>(), 0u8..8).prop_map(|(at, bit)| Mutation::Flip { at, bit }),
        1 => any::<usize>().prop_map(|at| Mutation::Truncate { at }),
        2 => (any::<usize>(), proptest::collection::vec(any::<u8>(), 1..30))
            .prop_map(|(at, bytes)| Mutation::Insert { at, bytes }),
        2 => (any::<usize>(), 1usize..60, any::<usize>())
            .prop_map(|(from, len, at)| Mutation::Duplicate { from, len, at }),
        2 => (any::<usize>(), 1usize..60).prop_map(|(from, len)| Mutation::Delete { from, len }),
    ]
}

fn apply(bytes: &mut Vec<u8>, mutation: &Mutation) {
    let n = bytes.len();
    if n == 0 {
        if let Mutation::Insert { bytes: new, .. } = mutation {
            bytes.extend_from_slice(new);
        }
        return;
    }
    match mutation {
        Mutation::Flip { at, bit } => bytes[at % n] ^= 1 << bit,
        Mutation::Truncate { at } => bytes.truncate(at % n),
        Mutation::Insert { at, bytes: new } => {
            let at = at % (n + 1);
            bytes.splice(at..at, new.iter().copied());
        }
        Mutation::Duplicate { from, len, at } => {
            let from = from % n;
            let piece = bytes[from..(from + len).min(n)].to_vec();
            let at = at % (n + 1);
            bytes.splice(at..at, piece);
        }
        Mutation::Delete { from, len } => {
            let from = from % n;
            bytes.drain(from..(from + len).min(n));
        }
    }
}

/// Mutated fixture streams, or random bytes.
fn stream() -> impl Strategy<Value = Vec<u8>> {
    let seed = fixture_stream(200);
    prop_oneof![
        3 => proptest::collection::vec(mutation(), 1..12).prop_map(move |mutations| {
            let mut bytes = seed.clone();
            mutations.iter().for_each(|m| apply(&mut bytes, m));
            bytes
        }),
        1 => proptest::collection::vec(any::<u8>(), 0..2000),
    ]
}

fn assert_one_line(message: &str) {
    assert!(!message.is_empty(), "empty error message");
    assert!(
        !message.contains('\n'),
        "error on more than one line: {message:?}"
    );
}

#[test]
fn the_unmutated_fixture_stream_decodes_whole() {
    let bytes = fixture_stream(200);
    let frames = BridgeReader::new(io::Cursor::new(bytes))
        .filter(|event| matches!(event, Ok(ReadEvent::Frame(_))))
        .count();
    assert_eq!(frames, 200);
}

proptest! {
    #![proptest_config(ProptestConfig {
        cases: CASES,
        rng_seed: RngSeed::Fixed(0x00F0_22B1),
        failure_persistence: None,
        ..ProptestConfig::default()
    })]

    /// `BridgeReader` over any bytes, in any buffer size: no panic, reading ends, and
    /// every byte is a frame's or counted as skipped.
    #[test]
    fn reader_accounts_for_every_byte(bytes in stream(), capacity in 1usize..100) {
        let total = bytes.len() as u64;
        let mut reader = BridgeReader::with_capacity(io::Cursor::new(bytes), capacity);
        let (mut frames, mut skipped, mut crc) = (0_u64, 0_u64, 0_u64);
        for _ in 0..=2 * total + 2 {
            match reader.next_event().unwrap() {
                None => break,
                Some(ReadEvent::Frame(_)) => frames += 1,
                Some(ReadEvent::Skipped { bytes }) => skipped += bytes,
                Some(ReadEvent::Crc(error)) => {
                    assert_one_line(&error.to_string());
                    crc += 1;
                }
                Some(other) => panic!("a cursor neither times out nor is interrupted: {other:?}"),
            }
        }
        prop_assert!(reader.next_event().unwrap().is_none(), "reading did not end");
        prop_assert_eq!(frames * BRIDGE_FRAME_LEN as u64 + skipped, total);
        let stats = reader.stats().receiver.decoder;
        prop_assert_eq!(stats.bytes_received, total);
        prop_assert_eq!((stats.frames, stats.bytes_skipped, stats.crc_errors), (frames, skipped, crc));
    }

    /// The decoder pushed byte by byte agrees with `BridgeFrame::from_bytes` on every
    /// frame it returns.
    #[test]
    fn decoder_frames_reencode_to_their_bytes(bytes in stream()) {
        let mut decoder = BridgeDecoder::default();
        for frame in decoder.feed(&bytes) {
            match frame {
                Ok(frame) => {
                    let wire = frame.to_bytes();
                    prop_assert_eq!(BridgeFrame::from_bytes(&wire), Ok(frame));
                }
                Err(error) => assert_one_line(&error.to_string()),
            }
        }
        let stats = decoder.stats();
        prop_assert_eq!(
            stats.bytes_received,
            stats.bytes_skipped + BRIDGE_FRAME_LEN as u64 * stats.frames + decoder.pending() as u64
        );
    }

    /// Any 24 bytes as a bridge frame: a frame, or a one-line error.
    #[test]
    fn any_24_bytes_are_a_frame_or_an_error(bytes in proptest::array::uniform24(any::<u8>())) {
        if let Err(error) = BridgeFrame::from_bytes(&bytes) {
            assert_one_line(&error.to_string());
        }
    }

    /// Any slice as a CRM100 response under any checks and range: a measurement with a
    /// finite rate and temperature, or a one-line error.
    #[test]
    fn any_slice_is_a_measurement_or_an_error(
        bytes in proptest::collection::vec(any::<u8>(), 0..10),
        verify_checksum in any::<bool>(),
        reject_status_fault in any::<bool>(),
        reject_saturated in any::<bool>(),
        range in 0usize..4,
    ) {
        let checks = Checks { verify_checksum, reject_status_fault, reject_saturated };
        match decode_slice(&bytes, Range::ALL[range], checks) {
            Ok(m) => prop_assert!(m.rate_dps.is_finite() && m.temperature_c.is_finite()),
            Err(error) => assert_one_line(&error.to_string()),
        }
    }
}
