//! Serial bridge framing: CRC, encoder, resynchronising decoder, sequence tracking.

use crate::common::{bridge_frame, wire};
use crm100_driver::{
    crc16_ccitt_false, crc16_ccitt_false_update, encode, BridgeDecoder, BridgeError, BridgeFrame,
    BridgeReceiver, Gap, SeqEvent, SequenceTracker, BRIDGE_FRAME_LEN, FORMAT_V1, MAX_FORWARD_STEP,
    SYNC,
};
use proptest::prelude::*;
use proptest::test_runner::RngSeed;

// ---------------------------------------------------------------------------------------
// CRC-16/CCITT-FALSE

#[test]
fn crc_matches_the_catalogue_check_value() {
    assert_eq!(crc16_ccitt_false(b"123456789"), 0x29B1);
    assert_eq!(crc16_ccitt_false(b""), 0xFFFF);
    // Reference values from Python's binascii.crc_hqx(data, 0xFFFF).
    assert_eq!(crc16_ccitt_false(b"A"), 0xB915);
    assert_eq!(crc16_ccitt_false(&[0x00]), 0xE1F0);
}

#[test]
fn crc_update_composes() {
    let data = b"the quick brown fox";
    for split in 0..=data.len() {
        let (a, b) = data.split_at(split);
        assert_eq!(
            crc16_ccitt_false_update(crc16_ccitt_false(a), b),
            crc16_ccitt_false(data)
        );
    }
}

// ---------------------------------------------------------------------------------------
// Encoder and single-frame parser

/// Golden frame; the CRC was computed independently with Python's `binascii.crc_hqx`.
const GOLDEN: [u8; BRIDGE_FRAME_LEN] = [
    0xA5, 0x5A, 0x01, 0x38, 0x04, 0x03, 0x02, 0x01, 0x88, 0x77, 0x66, 0x55, 0x44, 0x33, 0x22, 0x11,
    0x00, 0x03, 0xC0, 0x02, 0x58, 0xE2, 0x3E, 0x0F,
];

fn golden_frame() -> BridgeFrame {
    BridgeFrame {
        sequence: 0x0102_0304,
        timestamp_us: 0x1122_3344_5566_7788,
        command: 0x38,
        response: [0x00, 0x03, 0xC0, 0x02, 0x58, 0xE2],
    }
}

#[test]
fn encoder_matches_the_golden_layout() {
    let mut out = [0u8; BRIDGE_FRAME_LEN];
    assert_eq!(encode(&golden_frame(), &mut out), BRIDGE_FRAME_LEN);
    assert_eq!(out, GOLDEN);
    assert_eq!(golden_frame().to_bytes(), GOLDEN);
    assert_eq!(&GOLDEN[..2], &SYNC);
    assert_eq!(GOLDEN[2], FORMAT_V1);
    assert_eq!(BridgeFrame::from_bytes(&GOLDEN), Ok(golden_frame()));
    // The forwarded response is a valid CRM100 frame: 960 counts, 600 temperature word.
    let m = crm100_driver::decode(
        &golden_frame().response,
        crm100_driver::Range::Dps75,
        crm100_driver::Checks::DEFAULT,
    )
    .unwrap();
    assert_eq!(m.rate_dps, 10.0);
}

#[test]
fn parser_refuses_bad_sync_format_and_crc() {
    let mut bad = GOLDEN;
    bad[1] = 0x00;
    assert_eq!(BridgeFrame::from_bytes(&bad), Err(BridgeError::Sync));
    let mut bad = GOLDEN;
    bad[2] = 0x02;
    assert_eq!(BridgeFrame::from_bytes(&bad), Err(BridgeError::Format(2)));
    let mut bad = GOLDEN;
    bad[10] ^= 0x01;
    assert!(matches!(
        BridgeFrame::from_bytes(&bad),
        Err(BridgeError::Crc { .. })
    ));
    for e in [
        BridgeError::Sync,
        BridgeError::Format(9),
        BridgeError::Crc {
            expected: 1,
            found: 2,
        },
    ] {
        let as_error: &dyn core::error::Error = &e;
        assert!(!as_error.to_string().is_empty());
    }
}

/// The CRC covers bytes 2..24; every 1- and 2-bit error there is detected (exhaustive).
#[test]
fn crc_detects_every_single_and_double_bit_error() {
    const BITS: usize = (BRIDGE_FRAME_LEN - 2) * 8;
    let flip = |bytes: &mut [u8; BRIDGE_FRAME_LEN], bit: usize| {
        bytes[2 + bit / 8] ^= 1 << (bit % 8);
    };
    for a in 0..BITS {
        let mut one = GOLDEN;
        flip(&mut one, a);
        assert!(BridgeFrame::from_bytes(&one).is_err(), "bit {a}");
        for b in a + 1..BITS {
            let mut two = one;
            flip(&mut two, b);
            assert!(BridgeFrame::from_bytes(&two).is_err(), "bits {a}, {b}");
        }
    }
}

// ---------------------------------------------------------------------------------------
// Decoder: targeted cases

fn decode_all(decoder: &mut BridgeDecoder, bytes: &[u8]) -> Vec<Result<BridgeFrame, BridgeError>> {
    decoder.feed(bytes).collect()
}

fn frames_only(items: &[Result<BridgeFrame, BridgeError>]) -> Vec<BridgeFrame> {
    items.iter().filter_map(|i| i.ok()).collect()
}

#[test]
fn back_to_back_frames_decode_without_skipping() {
    let frames: Vec<_> = (0..50).map(bridge_frame).collect();
    let bytes: Vec<u8> = frames.iter().flat_map(wire).collect();
    let mut decoder = BridgeDecoder::new();
    let items = decode_all(&mut decoder, &bytes);
    assert_eq!(items.len(), 50);
    assert_eq!(frames_only(&items), frames);
    let s = decoder.stats();
    assert_eq!(
        (s.bytes_received, s.bytes_skipped, s.frames, s.crc_errors),
        (1200, 0, 50, 0)
    );
    assert_eq!(decoder.pending(), 0);
}

/// A false sync right before a good frame: the CRC failure is reported and the search
/// resumes inside the failed candidate, so the good frame is not swallowed.
#[test]
fn crc_failure_does_not_swallow_the_following_frame() {
    let good = bridge_frame(7);
    let mut bytes = vec![0xA5, 0x5A, 0x01, 0x38, 0x00];
    bytes.extend(wire(&good));
    let mut decoder = BridgeDecoder::new();
    let items = decode_all(&mut decoder, &bytes);
    assert!(matches!(items[0], Err(BridgeError::Crc { .. })));
    assert_eq!(items[1], Ok(good));
    assert_eq!(items.len(), 2);
    let s = decoder.stats();
    assert_eq!((s.crc_errors, s.frames, s.bytes_skipped), (1, 1, 5));
}

/// A frame cut short by lost bytes, then good frames.
#[test]
fn truncated_frame_is_skipped_and_the_next_ones_decode() {
    for cut in 1..BRIDGE_FRAME_LEN {
        let mut bytes = wire(&bridge_frame(1))[..cut].to_vec();
        bytes.extend(wire(&bridge_frame(2)));
        bytes.extend(wire(&bridge_frame(3)));
        let mut receiver = BridgeReceiver::new();
        let items: Vec<_> = receiver.feed(&bytes).collect();
        let frames: Vec<_> = items.iter().filter_map(|i| i.ok()).collect();
        assert_eq!(frames.len(), 2, "cut {cut}");
        assert_eq!(frames[0].frame, bridge_frame(2));
        assert_eq!(frames[1].frame, bridge_frame(3));
        assert_eq!(frames[0].sequence, SeqEvent::First);
        assert_eq!(frames[1].sequence, SeqEvent::InOrder);
        assert_eq!(receiver.stats().decoder.bytes_skipped, cut as u64);
    }
}

/// A corrupted frame whose payload contains a false sync: two CRC failures at most, and the
/// next good frame still decodes.
#[test]
fn false_sync_inside_a_corrupt_frame_is_survived() {
    let mut tricky = bridge_frame(10);
    // timestamp bytes carry sync + format
    tricky.timestamp_us = u64::from_le_bytes([0xA5, 0x5A, 0x01, 0, 0, 0, 0, 0]);
    let mut corrupt = wire(&tricky);
    corrupt[5] ^= 0x40;
    let next = bridge_frame(11);
    let mut bytes = corrupt;
    bytes.extend(wire(&next));
    bytes.extend(wire(&tricky)); // intact, with the false sync inside: decodes whole
    let mut decoder = BridgeDecoder::new();
    let items = decode_all(&mut decoder, &bytes);
    assert_eq!(frames_only(&items), vec![next, tricky]);
    assert_eq!(decoder.stats().crc_errors, 2);
}

#[test]
fn push_and_feed_agree_and_clear_counts_pending_bytes() {
    let mut bytes = vec![0x00, 0xA5];
    bytes.extend(wire(&bridge_frame(3)));
    bytes.extend(&wire(&bridge_frame(4))[..10]);
    let mut a = BridgeDecoder::new();
    let pushed: Vec<_> = bytes.iter().filter_map(|&b| a.push(b)).collect();
    let mut b = BridgeDecoder::new();
    assert_eq!(decode_all(&mut b, &bytes), pushed);
    assert_eq!(a.stats(), b.stats());
    assert_eq!(a.pending(), 10);
    a.clear();
    let s = a.stats();
    assert_eq!(a.pending(), 0);
    assert_eq!(s.bytes_received, s.bytes_skipped + 24 * s.frames);
}

// ---------------------------------------------------------------------------------------
// Sequence tracker

#[test]
fn sequence_tracker_reports_gaps_duplicates_and_wraps() {
    let mut t = SequenceTracker::new();
    assert_eq!(t.observe(u32::MAX - 2), SeqEvent::First);
    assert_eq!(t.observe(u32::MAX - 1), SeqEvent::InOrder);
    assert_eq!(
        t.observe(1),
        SeqEvent::Gap(Gap {
            from: u32::MAX - 1,
            to: 1,
            lost: 2 // u32::MAX and 0
        })
    );
    assert_eq!(t.observe(1), SeqEvent::Duplicate);
    assert_eq!(t.observe(2), SeqEvent::InOrder);
    assert_eq!(
        t.observe(0),
        SeqEvent::Backwards { from: 2, to: 0 } // bridge restart
    );
    assert_eq!(t.observe(1), SeqEvent::InOrder);
    let s = t.stats();
    assert_eq!(
        (s.frames, s.frames_lost, s.gaps, s.duplicates, s.backwards),
        (7, 2, 1, 1, 1)
    );
    t.reset();
    assert_eq!(t.last(), None);
    assert_eq!(t.observe(100), SeqEvent::First);
}

#[test]
fn plain_wrap_is_in_order_and_the_forward_limit_is_exact() {
    let mut t = SequenceTracker::new();
    t.observe(u32::MAX);
    assert_eq!(t.observe(0), SeqEvent::InOrder);

    let mut t = SequenceTracker::new();
    t.observe(5);
    assert_eq!(
        t.observe(5u32.wrapping_add(MAX_FORWARD_STEP)),
        SeqEvent::Gap(Gap {
            from: 5,
            to: 5 + MAX_FORWARD_STEP,
            lost: MAX_FORWARD_STEP - 1
        })
    );
    let mut t = SequenceTracker::new();
    t.observe(5);
    assert!(matches!(
        t.observe(5u32.wrapping_add(MAX_FORWARD_STEP + 1)),
        SeqEvent::Backwards { .. }
    ));
}

// ---------------------------------------------------------------------------------------
// Property tests on whole streams

/// What happens to each frame (or between frames) on the wire.
#[derive(Clone, Debug)]
enum Wire {
    Intact,
    /// Never sent (a lost frame): its sequence number is skipped.
    Dropped,
    /// Only the first `n` bytes arrive (1..24).
    Truncated(usize),
    /// One bit flipped (0..192).
    Flipped(usize),
    /// Garbage between frames (no sequence number used).
    Garbage(Vec<u8>),
}

fn wire_strategy() -> impl Strategy<Value = Wire> {
    // Garbage rich in sync and format bytes, to exercise resynchronisation.
    let garbage_byte = prop_oneof![
        Just(0xA5u8),
        Just(0x5Au8),
        Just(FORMAT_V1),
        any::<u8>(),
        any::<u8>()
    ];
    prop_oneof![
        6 => Just(Wire::Intact),
        1 => Just(Wire::Dropped),
        1 => (1..BRIDGE_FRAME_LEN).prop_map(Wire::Truncated),
        1 => (0..BRIDGE_FRAME_LEN * 8).prop_map(Wire::Flipped),
        1 => proptest::collection::vec(garbage_byte, 1..40).prop_map(Wire::Garbage),
    ]
}

fn start_strategy() -> impl Strategy<Value = u32> {
    prop_oneof![any::<u32>(), (u32::MAX - 30)..=u32::MAX]
}

/// Builds the byte stream; returns it with the intact frames in order.
fn build_stream(start: u32, plan: &[Wire]) -> (Vec<u8>, Vec<BridgeFrame>, Vec<Gap>, u64) {
    let mut bytes = Vec::new();
    let mut intact = Vec::new();
    let mut sequence = start;
    for step in plan {
        if let Wire::Garbage(g) = step {
            bytes.extend(g);
            continue;
        }
        let mut frame = bridge_frame(sequence);
        frame.timestamp_us = u64::from(sequence) * 1000 + 3; // distinct per frame
        let mut w = wire(&frame);
        match step {
            Wire::Intact => {
                bytes.extend(&w);
                intact.push(frame);
            }
            Wire::Dropped => {}
            Wire::Truncated(n) => bytes.extend(&w[..*n]),
            Wire::Flipped(bit) => {
                w[bit / 8] ^= 1 << (bit % 8);
                bytes.extend(&w);
            }
            Wire::Garbage(_) => unreachable!(),
        }
        sequence = sequence.wrapping_add(1);
    }
    let mut gaps = Vec::new();
    let mut lost = 0u64;
    for pair in intact.windows(2) {
        let (from, to) = (pair[0].sequence, pair[1].sequence);
        let step = to.wrapping_sub(from);
        if step > 1 {
            gaps.push(Gap {
                from,
                to,
                lost: step - 1,
            });
            lost += u64::from(step - 1);
        }
    }
    (bytes, intact, gaps, lost)
}

proptest! {
    // Fixed seed: a corrupt or truncated frame plus the bytes after it forms a candidate
    // whose CRC-16 matches by chance with probability 2^-16 and would then swallow the next
    // frame. That is the real, documented limit of the format; a random seed would turn it
    // into a rare flaky failure. A fixed seed keeps the test exact and reproducible.
    #![proptest_config(ProptestConfig {
        cases: 512,
        rng_seed: RngSeed::Fixed(0x00C5_2100),
        ..ProptestConfig::default()
    })]

    /// Garbage, truncated, flipped and dropped frames: every intact frame is decoded exactly
    /// once and in order, every gap is reported, and the lost count is exact.
    #[test]
    fn intact_frames_survive_any_damage(
        start in start_strategy(),
        plan in proptest::collection::vec(wire_strategy(), 0..60),
        chunk in 1usize..64,
    ) {
        let (bytes, intact, gaps, lost) = build_stream(start, &plan);
        let mut receiver = BridgeReceiver::new();
        let mut got = Vec::new();
        let mut got_gaps = Vec::new();
        for piece in bytes.chunks(chunk) {
            // CRC errors are expected here (damaged frames); only the good frames matter.
            for received in receiver.feed(piece).flatten() {
                got.push(received.frame);
                match received.sequence {
                    SeqEvent::Gap(gap) => got_gaps.push(gap),
                    SeqEvent::First | SeqEvent::InOrder => {}
                    other => prop_assert!(false, "unexpected {:?}", other),
                }
            }
        }
        prop_assert_eq!(&got, &intact);
        prop_assert_eq!(&got_gaps, &gaps);
        let stats = receiver.stats();
        prop_assert_eq!(stats.sequence.frames_lost, lost);
        prop_assert_eq!(stats.sequence.gaps, gaps.len() as u64);
        prop_assert_eq!(stats.decoder.frames, intact.len() as u64);
        let d = stats.decoder;
        prop_assert_eq!(d.bytes_received, bytes.len() as u64);
        prop_assert_eq!(
            d.bytes_received,
            d.bytes_skipped + 24 * d.frames + receiver.decoder().pending() as u64
        );
    }

    #[test]
    fn encode_parse_round_trip(
        sequence in any::<u32>(),
        timestamp_us in any::<u64>(),
        command in any::<u8>(),
        response in any::<[u8; 6]>(),
    ) {
        let frame = BridgeFrame { sequence, timestamp_us, command, response };
        let bytes = frame.to_bytes();
        prop_assert_eq!(BridgeFrame::from_bytes(&bytes), Ok(frame));
        let mut decoder = BridgeDecoder::new();
        let items: Vec<_> = decoder.feed(&bytes).collect();
        prop_assert_eq!(items, vec![Ok(frame)]);
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    /// Arbitrary bytes, fed in arbitrary chunks: no panic, counters consistent, chunking
    /// irrelevant.
    #[test]
    fn arbitrary_bytes_never_panic(
        bytes in proptest::collection::vec(
            prop_oneof![Just(0xA5u8), Just(0x5Au8), Just(0x01u8), any::<u8>()], 0..1500),
        chunk in 1usize..100,
    ) {
        let mut by_byte = BridgeReceiver::new();
        let one: Vec<_> = bytes.iter().filter_map(|&b| by_byte.push(b)).collect();
        let mut by_chunk = BridgeReceiver::new();
        let mut two = Vec::new();
        for piece in bytes.chunks(chunk) {
            two.extend(by_chunk.feed(piece));
        }
        prop_assert_eq!(one, two);
        prop_assert_eq!(by_byte.stats(), by_chunk.stats());
        let d = by_byte.stats().decoder;
        let pending = by_byte.decoder().pending();
        prop_assert!(pending < BRIDGE_FRAME_LEN);
        prop_assert_eq!(d.bytes_received, bytes.len() as u64);
        prop_assert_eq!(d.bytes_received, d.bytes_skipped + 24 * d.frames + pending as u64);
    }
}
