//! Sensor-error correction in the pipeline: the identity correction changes nothing (bit for
//! bit, pinned against the pipeline before corrections existed), and a known scale /
//! temperature error is removed from the angle.
#![allow(clippy::unwrap_used)]

use crate::common::{BenchSpec, Profile, Rng};
use gyro_core::{Compensation, Config, Correction, Event, Output, Pipeline};

/// FNV-1a over the bits of every output field.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Digest(u64);

impl Digest {
    const NEW: Self = Self(0xcbf2_9ce4_8422_2325);

    fn bytes(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.0 ^= u64::from(b);
            self.0 = self.0.wrapping_mul(0x0000_0100_0000_01b3);
        }
    }

    fn output(&mut self, out: &Output) {
        self.bytes(&out.time_s.to_bits().to_le_bytes());
        self.bytes(&out.rate_dps.to_bits().to_le_bytes());
        self.bytes(&out.angle_deg.to_bits().to_le_bytes());
        self.bytes(&out.raw_angle_deg.to_bits().to_le_bytes());
        self.bytes(
            &out.angle_std_deg
                .map_or(u32::MAX, f32::to_bits)
                .to_le_bytes(),
        );
        self.bytes(&out.bias_dps.to_bits().to_le_bytes());
        self.bytes(format!("{:?}", out.motion).as_bytes());
        match out.event {
            None => self.bytes(b"-"),
            Some(Event::MovementStarted { start_time_s, .. }) => {
                self.bytes(b"S");
                self.bytes(&start_time_s.to_bits().to_le_bytes());
            }
            Some(Event::MovementEnded(m)) => {
                self.bytes(b"E");
                self.bytes(&m.start_time_s.to_bits().to_le_bytes());
                self.bytes(&m.end_time_s.to_bits().to_le_bytes());
                self.bytes(&m.angle_deg.to_bits().to_le_bytes());
                self.bytes(&m.raw_angle_deg.to_bits().to_le_bytes());
            }
        }
    }
}

/// Bench-like input: 90 s at 1 kHz, bias 0.3 deg/s, noise, and a few glitches.
fn bench_input(seed: u64) -> Vec<f32> {
    let mut rng = Rng::new(seed);
    let profile = Profile::bench(&mut rng, &BenchSpec::default());
    let mut samples = profile.samples(1000.0, 0.3, 0.05, &mut rng);
    for i in [1234, 5678, 40_000] {
        samples[i] = f32::NAN;
    }
    samples[60_000] = 1e6;
    samples
}

const COMPENSATIONS: [Compensation; 3] = [
    Compensation::None,
    Compensation::Paper,
    Compensation::Kalman,
];

/// Digest of three bench runs in every compensation mode, each sample pushed by `push`
/// (pipeline, sample index, rate).
fn digest_of(
    config: &Config,
    push: impl Fn(&mut Pipeline, usize, f32) -> Option<Output>,
) -> Digest {
    let mut digest = Digest::NEW;
    for seed in 1..=3 {
        let samples = bench_input(seed);
        for compensation in COMPENSATIONS {
            let mut config = Config {
                compensation,
                ..*config
            };
            config.paper.b0_dps = 0.01;
            let mut pipeline = Pipeline::try_new(&config).unwrap();
            for (i, &rate) in samples.iter().enumerate() {
                if let Some(out) = push(&mut pipeline, i, rate) {
                    digest.output(&out);
                }
            }
            digest.bytes(&pipeline.rejected_samples().to_le_bytes());
        }
    }
    digest
}

/// A warm-up with a few bad readings, as a sensor may report it.
fn temperature_c(i: usize) -> f32 {
    match i % 5000 {
        17 => f32::NAN,
        18 => 9999.0,
        _ => 20.0 + 8.0 * (1.0 - (-(i as f32) * 1e-3 / 40.0).exp()),
    }
}

#[test]
fn identity_leaves_the_outputs_bit_identical() {
    let push = |p: &mut Pipeline, i: usize, rate: f32| p.push(i as f64 * 1e-3, rate);
    let with_temperature = |p: &mut Pipeline, i: usize, rate: f32| {
        p.push_with_temperature(i as f64 * 1e-3, rate, temperature_c(i))
    };
    let default = Config::default();
    assert_eq!(default.correction, Correction::IDENTITY);
    // `push` never applies temperature terms: with the identity it is the plain pipeline.
    let plain = digest_of(&default, push);
    assert_eq!(digest_of(&default, with_temperature), plain);
    let with_reference = Config {
        correction: Correction {
            temperature_ref_c: Some(21.0),
            ..Correction::IDENTITY
        },
        ..default
    };
    assert_eq!(digest_of(&with_reference, with_temperature), plain);
}

/// `push` applies scale and asymmetry but no temperature terms: it equals
/// `push_with_temperature` at the reference temperature, and differs from it when warm.
#[test]
fn push_ignores_temperature_terms() {
    let config = Config {
        correction: Correction {
            scale_k: 0.02,
            asymmetry_k: 0.005,
            bias_dps_per_c: 0.05,
            scale_per_c: 1e-3,
            temperature_ref_c: Some(25.0),
        },
        ..Config::default()
    };
    let samples = bench_input(7);
    let run = |temperature: Option<f32>| {
        let mut pipeline = Pipeline::try_new(&config).unwrap();
        let mut digest = Digest::NEW;
        for (i, &rate) in samples.iter().enumerate() {
            let time_s = i as f64 * 1e-3;
            let out = match temperature {
                None => pipeline.push(time_s, rate),
                Some(t) => pipeline.push_with_temperature(time_s, rate, t),
            };
            if let Some(out) = out {
                digest.output(&out);
            }
        }
        digest
    };
    assert_eq!(run(None), run(Some(25.0)));
    assert_ne!(run(None), run(Some(30.0)));
    assert_ne!(run(None), digest_of_one(&Config::default(), &samples));
}

fn digest_of_one(config: &Config, samples: &[f32]) -> Digest {
    let mut pipeline = Pipeline::try_new(config).unwrap();
    let mut digest = Digest::NEW;
    for (i, &rate) in samples.iter().enumerate() {
        if let Some(out) = pipeline.push(i as f64 * 1e-3, rate) {
            digest.output(&out);
        }
    }
    digest
}

/// The largest |movement angle − true angle| (deg) over bench runs of a sensor with scale,
/// asymmetry and temperature errors, replayed with `correction`.
fn max_movement_error_deg(correction: Correction) -> f64 {
    let truth = Correction {
        scale_k: 0.02,
        asymmetry_k: 0.005,
        bias_dps_per_c: 0.05,
        scale_per_c: 1e-3,
        temperature_ref_c: None,
    };
    let config = Config {
        correction,
        ..Config::default()
    };
    let mut worst = 0.0_f64;
    for seed in 11..=14 {
        let mut rng = Rng::new(seed);
        let profile = Profile::bench(&mut rng, &BenchSpec::default());
        let n = (profile.total_s * 1000.0).round() as usize;
        let mut pipeline = Pipeline::try_new(&config).unwrap();
        let mut movements = Vec::new();
        for i in 0..n {
            let t = i as f64 * 1e-3;
            // A warm-up of 8 °C with a 40 s time constant.
            let delta_c = 8.0 * (1.0 - (-t / 40.0).exp());
            let measured = truth.measured_dps(profile.rate_dps(t) as f32, delta_c as f32)
                + (0.3 + 0.05 * rng.normal()) as f32;
            let out = pipeline.push_with_temperature(t, measured, (25.0 + delta_c) as f32);
            if let Some(Event::MovementEnded(m)) = out.and_then(|o| o.event) {
                movements.push(m);
            }
        }
        assert_eq!(movements.len(), profile.swings.len(), "seed {seed}");
        for (m, swing) in movements.iter().zip(&profile.swings) {
            worst = worst.max((f64::from(m.angle_deg) - swing.angle_deg).abs());
        }
    }
    worst
}

/// The true correction removes the scale and temperature errors from every movement.
#[test]
fn correction_removes_scale_and_temperature_errors() {
    let without = max_movement_error_deg(Correction::IDENTITY);
    let with = max_movement_error_deg(Correction {
        scale_k: 0.02,
        asymmetry_k: 0.005,
        bias_dps_per_c: 0.05,
        scale_per_c: 1e-3,
        temperature_ref_c: None,
    });
    println!("max |movement error|: without correction {without:.4} deg, with {with:.4} deg");
    // 90° turns read 2–3.3% large without the correction (2 to 3 degrees).
    assert!(without > 1.5, "{without}");
    assert!(with < 0.1, "{with}");
    assert!(with * 20.0 < without, "{with} vs {without}");
}
