//! The 6-byte SPI frame codec: known vectors, exhaustive round trips, corruption.

use crm100_driver::{
    checksum, command_frame, decode, decode_slice, temperature_c_to_word, temperature_word_to_c,
    verify_checksum, Checks, FrameError, Range, Response, Status, FULL_SCALE_COUNTS,
};
use proptest::prelude::*;

const ALL_CHECKS: [Checks; 4] = [
    Checks::DEFAULT,
    Checks::STRICT,
    Checks::NONE,
    Checks {
        verify_checksum: false,
        reject_status_fault: true,
        reject_saturated: false,
    },
];

#[test]
fn range_command_frames_match_known_vectors() {
    assert_eq!(command_frame(0x38), [0x38, 0x00, 0x00, 0x00, 0x00, 0xC7]);
    assert_eq!(
        command_frame(Range::Dps75.command()),
        [0x38, 0, 0, 0, 0, 0xC7]
    );
    assert_eq!(
        command_frame(Range::Dps150.command()),
        [0x30, 0, 0, 0, 0, 0xCF]
    );
    assert_eq!(
        command_frame(Range::Dps300.command()),
        [0x28, 0, 0, 0, 0, 0xD7]
    );
    assert_eq!(
        command_frame(Range::Dps900.command()),
        [0x20, 0, 0, 0, 0, 0xDF]
    );
    assert_eq!(command_frame(0x00), [0, 0, 0, 0, 0, 0xFF]);
}

#[test]
fn checksum_is_ones_complement_of_wrapping_sum() {
    assert_eq!(checksum([0, 0, 0, 0, 0]), 0xFF);
    assert_eq!(checksum([0xFF; 5]), !0xFBu8); // 5 × 255 = 1275 ≡ 0xFB
    assert_eq!(checksum([0x80, 0x80, 0, 0, 0]), 0xFF); // 256 wraps to 0
    assert_eq!(checksum([1, 2, 3, 4, 5]), !15u8);
}

#[test]
fn ranges_agree_on_full_scale_and_commands() {
    for range in Range::ALL {
        assert_eq!(
            i32::from(range.full_scale_dps()) * i32::from(range.lsb_per_dps()),
            i32::from(FULL_SCALE_COUNTS)
        );
        assert_eq!(Range::from_command(range.command()), Some(range));
    }
    let range_commands: Vec<u8> = Range::ALL.iter().map(|r| r.command()).collect();
    for command in 0..=255u8 {
        if !range_commands.contains(&command) {
            assert_eq!(Range::from_command(command), None, "{command:#04x}");
        }
    }
    assert_eq!(Range::Dps75.to_string(), "±75 °/s");
}

/// Every range × every i16 rate word: bytes → words → °/s → counts is the identity, scaling
/// is exact, and saturation is judged exactly at ±7200.
#[test]
fn every_rate_word_round_trips_in_every_range() {
    for range in Range::ALL {
        let lsb = f32::from(range.lsb_per_dps());
        for counts in i16::MIN..=i16::MAX {
            let bytes = Response {
                status: Status(0),
                rate_counts: counts,
                temperature_word: 531,
            }
            .to_bytes();
            assert_eq!(verify_checksum(&bytes), Ok(()));
            let m = decode(&bytes, range, Checks::NONE).unwrap();
            assert_eq!(m.raw.rate_counts, counts);
            assert_eq!(m.rate_dps, f32::from(counts) / lsb);
            assert_eq!(m.range, range);
            assert_eq!(range.dps_to_counts(m.rate_dps), counts);
            let beyond = i32::from(counts).abs() > 7200;
            assert_eq!(m.is_saturated(), beyond);
            match decode(&bytes, range, Checks::DEFAULT) {
                Ok(_) => assert!(!beyond, "{counts} accepted"),
                Err(e) => {
                    assert!(beyond, "{counts} refused");
                    assert_eq!(e, FrameError::Saturated { counts });
                }
            }
        }
    }
}

#[test]
fn full_scale_maps_to_the_range_limits() {
    for range in Range::ALL {
        let fs = f32::from(range.full_scale_dps());
        assert_eq!(range.counts_to_dps(7200), fs);
        assert_eq!(range.counts_to_dps(-7200), -fs);
        assert_eq!(range.dps_to_counts(fs), 7200);
    }
    // Clamping and NaN in the inverse.
    assert_eq!(Range::Dps900.dps_to_counts(1e9), i16::MAX);
    assert_eq!(Range::Dps900.dps_to_counts(-1e9), i16::MIN);
    assert_eq!(Range::Dps900.dps_to_counts(f32::NAN), 0);
    assert_eq!(Range::Dps75.dps_to_counts(1.0 / 192.0), 1); // half a count rounds away
    assert_eq!(Range::Dps75.dps_to_counts(-1.0 / 192.0), -1);
}

/// Every temperature word: word → °C → word is the identity.
#[test]
fn every_temperature_word_round_trips() {
    for word in 0..=u16::MAX {
        let c = temperature_word_to_c(word);
        assert_eq!(c, (f32::from(word) - 531.0) / 2.75);
        assert_eq!(temperature_c_to_word(c), word);
        let bytes = Response {
            status: Status(0),
            rate_counts: 0,
            temperature_word: word,
        }
        .to_bytes();
        let m = decode(&bytes, Range::Dps300, Checks::DEFAULT).unwrap();
        assert_eq!(m.temperature_c, c);
        assert_eq!(m.raw.temperature_word, word);
    }
    assert_eq!(temperature_word_to_c(531), 0.0);
    assert_eq!(temperature_word_to_c(531 + 275), 100.0);
    assert_eq!(temperature_c_to_word(f32::NAN), 0);
    assert_eq!(temperature_c_to_word(-1e6), 0);
    assert_eq!(temperature_c_to_word(1e9), u16::MAX);
}

#[test]
fn status_is_kept_raw_and_flagged_or_refused() {
    let bytes = Response {
        status: Status(0x42),
        rate_counts: 96,
        temperature_word: 600,
    }
    .to_bytes();
    let m = decode(&bytes, Range::Dps75, Checks::DEFAULT).unwrap();
    assert_eq!(m.status, Status(0x42));
    assert_eq!(m.status.raw(), 0x42);
    assert!(m.status.is_fault());
    assert_eq!(m.rate_dps, 1.0);
    assert_eq!(
        decode(&bytes, Range::Dps75, Checks::STRICT),
        Err(FrameError::StatusFault(0x42))
    );
    assert!(!Status(0).is_fault());
}

#[test]
fn checksum_check_is_switchable() {
    let mut bytes = Response {
        status: Status(0),
        rate_counts: -48,
        temperature_word: 600,
    }
    .to_bytes();
    bytes[5] ^= 0x10;
    assert_eq!(
        decode(&bytes, Range::Dps150, Checks::DEFAULT),
        Err(FrameError::Checksum {
            expected: bytes[5] ^ 0x10,
            found: bytes[5]
        })
    );
    let unchecked = Checks {
        verify_checksum: false,
        ..Checks::DEFAULT
    };
    assert_eq!(
        decode(&bytes, Range::Dps150, unchecked).unwrap().rate_dps,
        -1.0
    );
}

#[test]
fn stuck_miso_lines_are_rejected() {
    for stuck in [[0x00u8; 6], [0xFF; 6]] {
        assert!(matches!(
            decode(&stuck, Range::Dps75, Checks::DEFAULT),
            Err(FrameError::Checksum { .. })
        ));
    }
}

#[test]
fn wrong_lengths_are_refused_not_panicked_on() {
    for len in [0, 1, 5, 7, 100] {
        let bytes = vec![0u8; len];
        assert_eq!(
            decode_slice(&bytes, Range::Dps75, Checks::NONE),
            Err(FrameError::Length { found: len })
        );
    }
    let good = Response::default().to_bytes();
    assert!(decode_slice(&good, Range::Dps75, Checks::STRICT).is_ok());
}

#[test]
fn errors_display_and_act_as_core_errors() {
    let errors = [
        FrameError::Length { found: 3 },
        FrameError::Checksum {
            expected: 1,
            found: 2,
        },
        FrameError::StatusFault(4),
        FrameError::Saturated { counts: 9000 },
    ];
    for e in errors {
        let as_error: &dyn core::error::Error = &e;
        assert!(!as_error.to_string().is_empty());
    }
    assert_eq!(
        FrameError::Checksum {
            expected: 0xC7,
            found: 0x00
        }
        .to_string(),
        "CRM100 frame checksum mismatch: expected 0xc7, found 0x00"
    );
}

/// Flipping two bits is *not* always caught by the 8-bit sum: the documented examples.
#[test]
fn some_double_bit_flips_escape_the_checksum() {
    let good = Response {
        status: Status(0),
        rate_counts: 0x0100,
        temperature_word: 0x0258,
    }
    .to_bytes();
    // Bit 7 in two data bytes: ±128 ± 128 ≡ 0 (mod 256).
    let mut msb_pair = good;
    msb_pair[1] ^= 0x80;
    msb_pair[3] ^= 0x80;
    assert_eq!(verify_checksum(&msb_pair), Ok(()));
    // Same bit going 1→0 in one byte and 0→1 in another (rate 0x0100 → 0x0001).
    let mut swap = good;
    swap[1] ^= 0x01;
    swap[2] ^= 0x01;
    assert_eq!(verify_checksum(&swap), Ok(()));
    assert_ne!(
        Response::from_bytes(&swap, true).unwrap().rate_counts,
        0x0100
    );
}

fn response_strategy() -> impl Strategy<Value = Response> {
    (any::<u8>(), any::<i16>(), any::<u16>()).prop_map(|(s, r, t)| Response {
        status: Status(s),
        rate_counts: r,
        temperature_word: t,
    })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(2000))]

    #[test]
    fn responses_round_trip_through_bytes(response in response_strategy()) {
        let bytes = response.to_bytes();
        prop_assert_eq!(Response::from_bytes(&bytes, true), Ok(response));
        for range in Range::ALL {
            let m = decode(&bytes, range, Checks::NONE).unwrap();
            prop_assert_eq!(m.raw, response);
            prop_assert_eq!(m.status, response.status);
            prop_assert_eq!(range.dps_to_counts(m.rate_dps), response.rate_counts);
            prop_assert_eq!(temperature_c_to_word(m.temperature_c), response.temperature_word);
        }
    }

    /// Every single-bit flip, anywhere in any valid frame, is caught by the checksum.
    #[test]
    fn every_single_bit_flip_is_detected(response in response_strategy()) {
        let good = response.to_bytes();
        for byte in 0..6 {
            for bit in 0..8 {
                let mut bad = good;
                bad[byte] ^= 1 << bit;
                let caught = matches!(
                    decode(&bad, Range::Dps75, Checks::NONE.with_checksum()),
                    Err(FrameError::Checksum { .. })
                );
                prop_assert!(caught, "byte {} bit {} escaped in {:02x?}", byte, bit, bad);
            }
        }
    }

    /// Any bytes of any length, any checks: a value or an error, never a panic.
    #[test]
    fn arbitrary_bytes_never_panic(bytes in proptest::collection::vec(any::<u8>(), 0..16)) {
        for checks in ALL_CHECKS {
            for range in Range::ALL {
                let result = decode_slice(&bytes, range, checks);
                if bytes.len() != 6 {
                    prop_assert_eq!(result, Err(FrameError::Length { found: bytes.len() }));
                }
            }
        }
    }
}

/// Exhaustive version of the single-flip property over every value of each byte position.
#[test]
fn single_bit_flips_detected_for_every_byte_value() {
    for position in 0..6 {
        for value in 0..=255u8 {
            let mut good = [0x38, 0x12, 0x34, 0x02, 0x58, 0];
            good[position] = value;
            good[5] = if position == 5 {
                value
            } else {
                checksum([good[0], good[1], good[2], good[3], good[4]])
            };
            if verify_checksum(&good).is_err() {
                continue; // position 5 with a wrong checksum value: not a valid frame
            }
            for byte in 0..6 {
                for bit in 0..8 {
                    let mut bad = good;
                    bad[byte] ^= 1 << bit;
                    assert!(verify_checksum(&bad).is_err());
                }
            }
        }
    }
}

trait WithChecksum {
    fn with_checksum(self) -> Self;
}

impl WithChecksum for Checks {
    fn with_checksum(mut self) -> Self {
        self.verify_checksum = true;
        self
    }
}
