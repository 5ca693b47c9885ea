//! The outputs' bits, pinned: a checksum over every output (and every movement) of a fixed
//! input, per configuration, through `push_block` and `push`.
//!
//! `block.rs` shows that `push_block` gives what `push` gives; this shows that both give
//! what they gave when the checksums were recorded, so that a change meant only to make
//! the pipeline cheaper is held to the same bits (the firmware and the host compare
//! bits). A change that is meant to move outputs records the new checksums with them.
//!
//! The input: 5 minutes at 1 kHz of rests (a drifting bias, noise), raised-cosine turns
//! of either sign, slow swings near the thresholds, clip plateaus, a few rejected
//! readings and time stamps that are not finite, with a temperature that drifts (44
//! movements, 22 of them saturated, 18 rejected readings in the default configuration).
//! The varied configuration's range of ±300 °/s is contradicted by turns of up to
//! 500 °/s, so there only the clip plateaus flag a movement saturated.
// Helpers outside #[test] fns unwrap too: the configurations are valid.
#![allow(clippy::unwrap_used)]

use gyro_core::{
    Butterworth, Compensation, Config, Correction, Event, KalmanConfig, Movement, Output, Pipeline,
};

/// Xorshift64: a fixed stream of test values.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        self.0
    }

    /// Uniform in [0, 1), in f32.
    fn unit(&mut self) -> f32 {
        (self.next() >> 40) as f32 / (1_u64 << 24) as f32
    }
}

/// `(time_s, rate_dps, temperature_c)` of the test input.
fn input() -> Vec<(f64, f32, f32)> {
    const N: usize = 300_000;
    let mut rng = Rng(0x5eed_1234_abcd_0001);
    let mut samples = Vec::with_capacity(N);
    let (mut bias_dps, mut temperature_c) = (0.3_f32, 24.0_f32);
    let mut stretch = 0_u32;
    while samples.len() < N {
        let len = 200 + (rng.next() % 4000) as usize;
        let peak_dps = (rng.unit() - 0.5) * 500.0;
        let noise_dps = 0.02 + 0.2 * rng.unit();
        bias_dps += (rng.unit() - 0.5) * 0.2;
        for j in 0..len {
            let i = samples.len();
            let phase = j as f32 / len as f32;
            let noise = noise_dps * (rng.unit() - 0.5);
            let rate_dps = match stretch % 6 {
                0 | 2 => bias_dps + noise,
                1 | 4 => {
                    bias_dps
                        + peak_dps * (1.0 - (2.0 * core::f32::consts::PI * phase).cos())
                        + noise
                }
                3 => bias_dps + 2.5 * (core::f32::consts::PI * phase).sin() + noise,
                // A clip plateau inside a fast turn.
                _ if (len / 3..len / 3 + 40).contains(&j) => 300.0,
                _ => bias_dps + 280.0 * (core::f32::consts::PI * phase).sin() + noise,
            };
            let rate_dps = match rng.next() % 40_000 {
                0 => f32::NAN,
                1 => 3.0e4,
                _ => rate_dps,
            };
            let time_s = if rng.next() % 50_000 == 0 {
                f64::NAN
            } else {
                i as f64 * 1e-3
            };
            temperature_c += (rng.unit() - 0.49) * 0.01;
            samples.push((time_s, rate_dps, temperature_c));
            if samples.len() == N {
                break;
            }
        }
        stretch += 1;
    }
    samples
}

/// FNV-1a over 64-bit words.
struct Checksum(u64);

impl Checksum {
    fn word(&mut self, word: u64) {
        for byte in word.to_le_bytes() {
            self.0 ^= u64::from(byte);
            self.0 = self.0.wrapping_mul(0x0000_0100_0000_01b3);
        }
    }

    fn f32(&mut self, x: f32) {
        self.word(u64::from(x.to_bits()));
    }

    fn option_f32(&mut self, x: Option<f32>) {
        match x {
            Some(x) => {
                self.word(1);
                self.f32(x);
            }
            None => self.word(0),
        }
    }

    fn movement(&mut self, m: &Movement) {
        self.word(m.start_time_s.to_bits());
        self.word(m.end_time_s.to_bits());
        self.word(u64::from(m.start_index));
        self.word(u64::from(m.end_index));
        self.f32(m.angle_deg);
        self.f32(m.raw_angle_deg);
        self.word(u64::from(m.saturated));
        self.option_f32(m.angle_std_deg);
    }

    fn output(&mut self, out: &Output) {
        self.word(out.time_s.to_bits());
        self.f32(out.rate_dps);
        self.word(out.motion as u64);
        match &out.event {
            None => self.word(0),
            Some(Event::MovementStarted {
                start_time_s,
                start_index,
            }) => {
                self.word(1);
                self.word(start_time_s.to_bits());
                self.word(u64::from(*start_index));
            }
            Some(Event::MovementEnded(movement)) => {
                self.word(2);
                self.movement(movement);
            }
        }
        self.f32(out.angle_deg);
        self.f32(out.raw_angle_deg);
        self.option_f32(out.angle_std_deg);
        self.f32(out.bias_dps);
    }
}

/// The configurations pinned: the default in each compensation mode, and one with a
/// steeper filter, a correction, a known range and a fast-wandering bias model.
fn configs() -> Vec<(&'static str, Config)> {
    let mut configs: Vec<_> = [
        ("kalman", Compensation::Kalman),
        ("paper", Compensation::Paper),
        ("none", Compensation::None),
    ]
    .into_iter()
    .map(|(name, compensation)| {
        let mut config = Config {
            compensation,
            ..Config::default()
        };
        config.paper.beta_per_s = 0.3;
        config.paper.b0_dps = 0.05;
        config.paper.o0_deg = 0.01;
        (name, config)
    })
    .collect();
    configs.push((
        "varied",
        Config {
            filter: Butterworth {
                order: 4,
                cutoff_hz: 8.0,
            },
            kalman: KalmanConfig {
                beta_per_s: 0.5,
                ..KalmanConfig::default()
            },
            correction: Correction {
                scale_k: 0.02,
                asymmetry_k: -0.01,
                bias_dps_per_c: 0.05,
                scale_per_c: 1e-3,
                temperature_ref_c: None,
            },
            range_dps: Some(300.0),
            ..Config::default()
        },
    ));
    configs
}

/// The checksum of a run: outputs as they come, then the rejected count.
fn checksum(config: &Config, samples: &[(f64, f32, f32)], how: How) -> u64 {
    let mut pipeline = Pipeline::try_new(config).unwrap();
    let mut sum = Checksum(0xcbf2_9ce4_8422_2325);
    let temperature = config.correction.bias_dps_per_c != 0.0;
    match how {
        How::OneByOne => {
            for &(time_s, rate_dps, temperature_c) in samples {
                let out = if temperature {
                    pipeline.push_with_temperature(time_s, rate_dps, temperature_c)
                } else {
                    pipeline.push(time_s, rate_dps)
                };
                if let Some(out) = out {
                    sum.output(&out);
                }
            }
        }
        How::Blocks(len) => {
            for chunk in samples.chunks(len) {
                let times: Vec<f64> = chunk.iter().map(|s| s.0).collect();
                let rates: Vec<f32> = chunk.iter().map(|s| s.1).collect();
                let temperatures: Vec<f32> = chunk.iter().map(|s| s.2).collect();
                if temperature {
                    pipeline
                        .push_block_with_temperature(&times, &rates, &temperatures, |out| {
                            sum.output(&out)
                        })
                        .unwrap();
                } else {
                    pipeline
                        .push_block(&times, &rates, |out| sum.output(&out))
                        .unwrap();
                }
            }
        }
    }
    sum.word(u64::from(pipeline.rejected_samples()));
    sum.0
}

#[derive(Clone, Copy, Debug)]
enum How {
    OneByOne,
    Blocks(usize),
}

/// The recorded checksums, per configuration of [`configs`].
const EXPECTED: [(&str, u64); 4] = [
    ("kalman", 0xa87b_95bc_65ed_385e),
    ("paper", 0xc457_7005_29d1_2f4d),
    ("none", 0x3280_4917_e21d_d4fd),
    ("varied", 0x91dc_f9dc_1062_f911),
];

#[test]
fn outputs_keep_their_bits() {
    let samples = input();
    let mut got = Vec::new();
    for (name, config) in configs() {
        let whole = checksum(&config, &samples, How::Blocks(samples.len()));
        for how in [How::Blocks(1000), How::Blocks(77), How::OneByOne] {
            assert_eq!(checksum(&config, &samples, how), whole, "{name}: {how:?}");
        }
        println!("{name}: {whole:#018x}");
        got.push((name, whole));
    }
    for ((name, sum), (expected_name, expected)) in got.iter().zip(EXPECTED) {
        assert_eq!(*name, expected_name);
        assert_eq!(
            *sum, expected,
            "{name}: checksum {sum:#018x}, recorded {expected:#018x}"
        );
    }
}
