//! `push_block` gives what `push` gives, bit for bit: the same outputs and the same state,
//! however the samples are split into blocks (the firmware and the host compare bits).

use gyro_core::{Compensation, Config, Correction, Error, MotionConfig, Output, Pipeline};
use proptest::prelude::*;

/// A stretch of input: what a sensor, a clipping sensor or a broken link delivers.
#[derive(Clone, Copy, Debug)]
enum Stretch {
    /// Rest: a bias and a small ripple.
    Rest { bias_dps: f32 },
    /// A raised-cosine turn of `peak_dps`.
    Turn { peak_dps: f32 },
    /// The same reading again and again (a clip plateau when high, a quantised rest when
    /// low).
    Flat { reading_dps: f32 },
    /// One odd reading.
    Odd { reading_dps: f32 },
}

fn any_stretch() -> impl Strategy<Value = (Stretch, usize)> {
    prop_oneof![
        3 => (-2.0..2.0_f32, 1..400_usize).prop_map(|(bias_dps, n)| (Stretch::Rest { bias_dps }, n)),
        3 => (-400.0..400.0_f32, 20..600_usize)
            .prop_map(|(peak_dps, n)| (Stretch::Turn { peak_dps }, n)),
        2 => (
            prop_oneof![Just(300.0_f32), Just(-300.0), Just(35.0), Just(0.0), Just(29.9), -500.0..500.0_f32],
            1..60_usize,
        )
            .prop_map(|(reading_dps, n)| (Stretch::Flat { reading_dps }, n)),
        2 => prop_oneof![
            Just(f32::NAN),
            Just(f32::INFINITY),
            Just(f32::NEG_INFINITY),
            Just(2e4_f32),
            Just(-1.000_001e4_f32),
            Just(1e4_f32),
            Just(-0.0_f32),
            prop::num::f32::ANY,
        ]
        .prop_map(|reading_dps| (Stretch::Odd { reading_dps }, 1)),
    ]
}

/// Times: a 1 kHz clock, with a few stamps that are not finite or jump.
fn any_time(i: usize, glitch: u32) -> f64 {
    match glitch % 97 {
        0 => f64::NAN,
        1 => f64::INFINITY,
        2 => -1.0,
        3 => f64::MAX,
        _ => i as f64 * 1e-3,
    }
}

/// The samples `(time, rate, temperature)` of `stretches`, glitches from `seed`.
fn samples(stretches: &[(Stretch, usize)], seed: u32) -> Vec<(f64, f32, f32)> {
    let mut out = Vec::new();
    let mut state = seed | 1;
    let mut next = || {
        // xorshift32: a repeatable stream for glitches and ripple.
        state ^= state << 13;
        state ^= state >> 17;
        state ^= state << 5;
        state
    };
    for &(stretch, n) in stretches {
        for j in 0..n {
            let i = out.len();
            let ripple = (next() % 1000) as f32 * 1e-4 - 0.05;
            let rate = match stretch {
                Stretch::Rest { bias_dps } => bias_dps + ripple,
                Stretch::Turn { peak_dps } => {
                    let phase = j as f32 / n as f32;
                    peak_dps * 0.5 * (1.0 - (2.0 * core::f32::consts::PI * phase).cos()) + ripple
                }
                Stretch::Flat { reading_dps } | Stretch::Odd { reading_dps } => reading_dps,
            };
            let temperature = match next() % 50 {
                0 => f32::NAN,
                1 => 8000.0,
                _ => 20.0 + (i as f32) * 1e-3,
            };
            out.push((any_time(i, next()), rate, temperature));
        }
    }
    out
}

fn any_config() -> impl Strategy<Value = Config> {
    (
        prop_oneof![
            Just(1.0_f32),
            Just(2.0),
            Just(3.0),
            Just(7.0),
            Just(20.0),
            Just(50.0)
        ],
        prop_oneof![
            Just(Compensation::None),
            Just(Compensation::Paper),
            Just(Compensation::Kalman)
        ],
        prop_oneof![
            Just(Correction::IDENTITY),
            Just(Correction {
                scale_k: 0.01,
                asymmetry_k: -0.005,
                bias_dps_per_c: 0.02,
                scale_per_c: 1e-4,
                temperature_ref_c: None,
            }),
        ],
        proptest::option::of(prop_oneof![Just(300.0_f32), Just(250.0)]),
        prop_oneof![Just(1.0e4_f32), Just(450.0)],
    )
        .prop_map(
            |(factor, compensation, correction, range_dps, max_abs_rate_dps)| Config {
                output_rate_hz: 1000.0 / factor,
                // Below the output's Nyquist frequency for every factor.
                filter: gyro_core::Butterworth {
                    order: 2,
                    cutoff_hz: 5.0,
                },
                compensation,
                correction,
                range_dps,
                max_abs_rate_dps,
                motion: MotionConfig {
                    min_motion_s: 0.02,
                    min_rest_s: 0.06,
                    ..MotionConfig::default()
                },
                ..Config::default()
            },
        )
}

/// Outputs and state in full, every bit (Debug prints each float's shortest exact form).
fn bits(outputs: &[Output], pipeline: &Pipeline) -> (String, String) {
    (format!("{outputs:?}"), format!("{pipeline:?}"))
}

/// Push `input` one by one; and in blocks of the lengths `cuts` (cycled; empty ones
/// included), with a single push for every length 1. Both must agree on every bit.
fn compare(config: &Config, input: &[(f64, f32, f32)], cuts: &[usize], temperature: bool) {
    let mut one = Pipeline::try_new(config).expect("valid config");
    let mut expected = Vec::new();
    for &(t, r, c) in input {
        let out = if temperature {
            one.push_with_temperature(t, r, c)
        } else {
            one.push(t, r)
        };
        expected.extend(out);
    }

    let times: Vec<f64> = input.iter().map(|s| s.0).collect();
    let rates: Vec<f32> = input.iter().map(|s| s.1).collect();
    let temps: Vec<f32> = input.iter().map(|s| s.2).collect();
    let mut block = Pipeline::try_new(config).expect("valid config");
    let mut got = Vec::new();
    let mut start = 0;
    // Empty blocks are pushed too, but some cut must move on.
    let cuts = if cuts.iter().all(|&cut| cut == 0) {
        vec![0, 5]
    } else {
        cuts.to_vec()
    };
    for &cut in cuts.iter().cycle() {
        if start >= input.len() {
            break;
        }
        let end = (start + cut).min(input.len());
        if cut == 1 {
            let (t, r, c) = input[start];
            got.extend(if temperature {
                block.push_with_temperature(t, r, c)
            } else {
                block.push(t, r)
            });
        } else if temperature {
            block
                .push_block_with_temperature(
                    &times[start..end],
                    &rates[start..end],
                    &temps[start..end],
                    |out| got.push(out),
                )
                .expect("same lengths");
        } else {
            block
                .push_block(&times[start..end], &rates[start..end], |out| got.push(out))
                .expect("same lengths");
        }
        start = end;
    }
    assert!(!expected.is_empty() || input.len() < 60);
    assert_eq!(bits(&got, &block), bits(&expected, &one));
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    #[test]
    fn blocks_give_the_bits_of_one_by_one(
        config in any_config(),
        stretches in prop::collection::vec(any_stretch(), 1..24),
        seed in any::<u32>(),
        cuts in prop::collection::vec(
            prop_oneof![1 => Just(1_usize), 1 => 0..10_usize, 2 => 10..300_usize, 1 => 300..3000_usize],
            1..8,
        ),
        temperature in any::<bool>(),
    ) {
        let input = samples(&stretches, seed);
        compare(&config, &input, &cuts, temperature);
    }
}

/// Long clean stretches, where whole blocks go side by side, with the bench's settings.
#[test]
fn long_blocks_give_the_bits_of_one_by_one() {
    let stretches = [
        (Stretch::Rest { bias_dps: 0.3 }, 3000),
        (Stretch::Turn { peak_dps: 180.0 }, 1000),
        (Stretch::Rest { bias_dps: 0.3 }, 3000),
        (Stretch::Flat { reading_dps: 300.0 }, 100),
        (Stretch::Turn { peak_dps: -250.0 }, 700),
        (Stretch::Rest { bias_dps: -0.2 }, 2500),
    ];
    let input = samples(&stretches, 7);
    for compensation in [
        Compensation::None,
        Compensation::Paper,
        Compensation::Kalman,
    ] {
        let config = Config {
            compensation,
            range_dps: Some(300.0),
            ..Config::default()
        };
        for temperature in [false, true] {
            compare(&config, &input, &[input.len()], temperature);
            compare(&config, &input, &[997, 13, 1, 1, 400], temperature);
        }
    }
}

#[test]
fn slices_of_different_lengths_are_refused() {
    let mut pipeline = Pipeline::try_new(&Config::default()).expect("default config");
    let before = format!("{pipeline:?}");
    assert_eq!(
        pipeline.push_block(&[0.0, 1e-3], &[1.0], |_| {}),
        Err(Error::LengthMismatch("rates_dps"))
    );
    assert_eq!(
        pipeline.push_block_with_temperature(&[0.0], &[1.0], &[], |_| {}),
        Err(Error::LengthMismatch("temperatures_c"))
    );
    assert_eq!(format!("{pipeline:?}"), before);
}
