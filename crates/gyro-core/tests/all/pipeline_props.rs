//! Properties of the whole pipeline: no panic and finite state on any input, rejected
//! samples counted, and any valid configuration builds and runs.

use crate::common;

use crate::common::{BenchSpec, Profile, Rng};
use gyro_core::{
    Butterworth, Compensation, Config, Correction, Event, GaussMarkov, KalmanConfig, MotionConfig,
    Output, Pipeline,
};
use proptest::prelude::*;

/// Rates as a sensor, a broken link or a fuzzer might deliver them.
fn any_rate() -> impl Strategy<Value = f32> {
    prop_oneof![
        4 => -300.0..300.0_f32,
        2 => -1.0..1.0_f32,
        1 => prop::num::f32::ANY,
        1 => prop::num::f32::SUBNORMAL | prop::num::f32::ZERO,
        1 => prop_oneof![
            Just(f32::NAN),
            Just(f32::INFINITY),
            Just(f32::NEG_INFINITY),
            Just(3e38_f32),
            Just(-3e38_f32),
            Just(f32::MAX),
            Just(f32::MIN),
            Just(1e4_f32),
            Just(-1.000_001e4_f32),
        ],
    ]
}

/// Times: mostly a regular clock with jitter, sometimes anything at all.
fn any_time_step() -> impl Strategy<Value = Option<f64>> {
    prop_oneof![
        8 => Just(None),
        1 => prop::num::f64::ANY.prop_map(Some),
        1 => prop_oneof![
            Just(f64::NAN),
            Just(f64::INFINITY),
            Just(f64::MAX),
            Just(-f64::MAX),
            Just(0.0),
            Just(-1.0),
        ]
        .prop_map(Some),
    ]
}

/// Temperatures (°C): mostly plausible, sometimes garbage.
fn any_temperature() -> impl Strategy<Value = f32> {
    prop_oneof![
        6 => 0.0..60.0_f32,
        1 => prop::num::f32::ANY,
        1 => prop_oneof![
            Just(f32::NAN),
            Just(f32::INFINITY),
            Just(f32::NEG_INFINITY),
            Just(-273.15_f32),
            Just(8000.0_f32),
        ],
    ]
}

/// A valid correction: scale errors up to 15%, 1e-3/°C, 1 deg/s/°C.
fn any_valid_correction() -> impl Strategy<Value = Correction> {
    (
        -0.15..0.15_f32,
        -0.15..0.15_f32,
        -1.0..1.0_f32,
        -1e-3..1e-3_f32,
        prop::option::of(-20.0..60.0_f32),
    )
        .prop_map(
            |(scale_k, asymmetry_k, bias_dps_per_c, scale_per_c, temperature_ref_c)| Correction {
                scale_k,
                asymmetry_k,
                bias_dps_per_c,
                scale_per_c,
                temperature_ref_c,
            },
        )
}

fn any_compensation() -> impl Strategy<Value = Compensation> {
    prop_oneof![
        Just(Compensation::None),
        Just(Compensation::Paper),
        Just(Compensation::Kalman),
    ]
}

/// Everything a caller can see is finite.
fn assert_output_finite(out: &Output) {
    assert!(out.time_s.is_finite(), "{out:?}");
    assert!(out.rate_dps.is_finite(), "{out:?}");
    assert!(out.angle_deg.is_finite(), "{out:?}");
    assert!(out.raw_angle_deg.is_finite(), "{out:?}");
    assert!(out.bias_dps.is_finite(), "{out:?}");
    assert!(out.angle_std_deg.is_none_or(f32::is_finite), "{out:?}");
    match out.event {
        Some(Event::MovementStarted { start_time_s, .. }) => assert!(start_time_s.is_finite()),
        Some(Event::MovementEnded(m)) => {
            assert!(
                m.start_time_s.is_finite() && m.end_time_s.is_finite(),
                "{m:?}"
            );
            assert!(
                m.angle_deg.is_finite() && m.raw_angle_deg.is_finite(),
                "{m:?}"
            );
        }
        None => {}
    }
}

/// Push `(time, rate)` pairs; check state and outputs after every sample; return the
/// outputs.
fn push_all(pipeline: &mut Pipeline, input: impl IntoIterator<Item = (f64, f32)>) -> usize {
    let mut outputs = 0;
    for (time_s, rate_dps) in input {
        if let Some(out) = pipeline.push(time_s, rate_dps) {
            assert_output_finite(&out);
            outputs += 1;
        }
        assert!(pipeline.is_finite());
    }
    outputs
}

/// As [`push_all`], with a temperature per sample.
fn push_all_with_temperature(
    pipeline: &mut Pipeline,
    input: impl IntoIterator<Item = (f64, f32, f32)>,
) -> usize {
    let mut outputs = 0;
    for (time_s, rate_dps, temperature_c) in input {
        if let Some(out) = pipeline.push_with_temperature(time_s, rate_dps, temperature_c) {
            assert_output_finite(&out);
            outputs += 1;
        }
        assert!(pipeline.is_finite());
        assert!(pipeline.corrector().delta_c().is_finite());
    }
    outputs
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]

    /// Any rate, time and temperature through any valid correction: no panic, finite state
    /// and outputs, rejected samples counted as without temperatures.
    #[test]
    fn any_input_with_temperature_keeps_the_state_finite(
        input in prop::collection::vec((any_rate(), any_time_step(), any_temperature()), 0..1500),
        compensation in any_compensation(),
        correction in any_valid_correction(),
    ) {
        let config = Config { compensation, correction, ..Config::default() };
        let mut pipeline = Pipeline::try_new(&config).expect("valid config");
        let samples = input.iter().enumerate().map(|(i, &(rate, time, temperature))| {
            (time.unwrap_or(i as f64 * 1e-3), rate, temperature)
        });
        let outputs = push_all_with_temperature(&mut pipeline, samples);
        prop_assert_eq!(outputs, input.len() / 20);
        let bad = input
            .iter()
            .filter(|(r, _, _)| !r.is_finite() || r.abs() > config.max_abs_rate_dps)
            .count();
        prop_assert_eq!(pipeline.rejected_samples() as usize, bad);
    }

    /// Any f32 input with any times: no panic, finite state and outputs, and every
    /// non-finite or implausible rate counted as rejected.
    #[test]
    fn any_input_keeps_the_state_finite(
        input in prop::collection::vec((any_rate(), any_time_step()), 0..1500),
        compensation in any_compensation(),
    ) {
        let config = Config { compensation, ..Config::default() };
        let mut pipeline = Pipeline::try_new(&config).expect("default config");
        let samples = input.iter().enumerate().map(|(i, &(rate, time))| {
            (time.unwrap_or(i as f64 * 1e-3 + 1e-5 * (i % 3) as f64), rate)
        });
        let outputs = push_all(&mut pipeline, samples);
        prop_assert_eq!(outputs, input.len() / 20);
        let bad = input
            .iter()
            .filter(|(r, _)| !r.is_finite() || r.abs() > config.max_abs_rate_dps)
            .count();
        prop_assert_eq!(pipeline.rejected_samples() as usize, bad);
    }
}

/// A valid configuration drawn from wide ranges.
fn any_valid_config() -> impl Strategy<Value = Config> {
    let rates = (
        prop_oneof![Just(100.0_f32), Just(200.0), Just(1000.0)],
        1..=50_u16,
    );
    let filter = (1..=8_u8, 0.002..0.49_f32);
    let motion = (
        0.0..3.0_f32,
        0.0..10.0_f32,
        0.0..1.0_f32,
        0.0..2.0_f32,
        -2.0..2.0_f32,
    );
    let paper = (0.0..10.0_f32, -2.0..2.0_f32, -5.0..5.0_f32);
    let kalman = (
        0.0..1.0_f32,
        0.0..2.0_f32,
        -1.0..1.0_f32,
        1e-3..1.0_f32,
        0.0..5.0_f32,
    );
    (
        rates,
        filter,
        motion,
        any_compensation(),
        paper,
        kalman,
        10.0..1e6_f32,
        any_valid_correction(),
        proptest::option::of(1.0..1e4_f32),
    )
        .prop_map(
            |(
                (sample_rate_hz, factor),
                (order, cutoff_fraction),
                (exit_dps, enter_above_dps, min_motion_s, min_rest_s, initial_bias_dps),
                compensation,
                (paper_beta, b0_dps, o0_deg),
                (kalman_beta, bias_sigma_dps, bias_mean_dps, rate_noise_dps, initial_sigma),
                max_abs_rate_dps,
                correction,
                range_dps,
            )| {
                let factor = factor.min(sample_rate_hz as u16);
                let output_rate_hz = sample_rate_hz / f32::from(factor);
                Config {
                    sample_rate_hz,
                    output_rate_hz,
                    max_abs_rate_dps,
                    filter: Butterworth {
                        order,
                        cutoff_hz: cutoff_fraction * output_rate_hz,
                    },
                    motion: MotionConfig {
                        enter_dps: exit_dps + enter_above_dps,
                        exit_dps,
                        min_motion_s,
                        min_rest_s,
                        initial_bias_dps,
                    },
                    compensation,
                    paper: GaussMarkov {
                        beta_per_s: paper_beta,
                        b0_dps,
                        o0_deg,
                    },
                    kalman: KalmanConfig {
                        beta_per_s: kalman_beta,
                        bias_sigma_dps,
                        bias_mean_dps,
                        rate_noise_dps,
                        initial_bias_sigma_dps: initial_sigma,
                    },
                    correction,
                    range_dps,
                    tightening: None,
                }
            },
        )
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(32))]

    /// Any valid configuration builds and runs a bench-like input (with some garbage in
    /// it) without panic, with finite state and outputs.
    #[test]
    fn any_valid_config_builds_and_runs(
        config in any_valid_config(),
        seed in any::<u64>(),
        bias_dps in -1.0..1.0_f64,
        noise_dps in 0.0..0.2_f64,
    ) {
        let mut pipeline = Pipeline::try_new(&config)
            .unwrap_or_else(|e| panic!("{e}: {config:?}"));
        let mut rng = Rng::new(seed);
        let spec = BenchSpec {
            total_s: 20.0,
            first_rest_s: (0.5, 2.0),
            rest_s: (0.5, 4.0),
            swing_s: (0.3, 3.0),
            angle_deg: (5.0, 200.0),
        };
        let profile = Profile::bench(&mut rng, &spec);
        let sample_rate_hz = f64::from(config.sample_rate_hz);
        let mut samples = profile.samples(sample_rate_hz, bias_dps, noise_dps, &mut rng);
        for _ in 0..samples.len() / 500 {
            let i = rng.next_u64() as usize % samples.len();
            samples[i] = [f32::NAN, f32::INFINITY, -3e38][i % 3];
        }
        // A warm-up of 10 °C with a few bad readings.
        let input = samples.iter().enumerate().map(|(i, &r)| {
            let time_s = i as f64 / sample_rate_hz;
            let temperature_c = if i % 997 == 5 { f32::NAN } else { 25.0 + 0.5 * time_s as f32 };
            (time_s, r, temperature_c)
        });
        let outputs = push_all_with_temperature(&mut pipeline, input);
        let factor = usize::from(config.decimation_factor().expect("valid"));
        prop_assert_eq!(outputs, samples.len() / factor);
    }
}

/// Times near the ends of the f64 range still give finite output times (the centre of
/// a block used to be computed as a sum, which overflows).
#[test]
fn huge_times_give_finite_output_times() {
    let mut pipeline = Pipeline::try_new(&Config::default()).expect("default config");
    for time_s in [f64::MAX, -f64::MAX] {
        for _ in 0..20 {
            if let Some(out) = pipeline.push(time_s, 1.0) {
                assert_output_finite(&out);
                assert_eq!(out.time_s, time_s);
            }
        }
    }
}

/// The counted rejections are exactly the bad samples, and they do not move the angle.
#[test]
fn rejected_samples_are_counted_and_held() {
    let config = Config {
        compensation: Compensation::None,
        ..Config::default()
    };
    let mut clean = Pipeline::try_new(&config).expect("default config");
    let mut dirty = Pipeline::try_new(&config).expect("default config");
    let mut last = (None, None);
    for i in 0..4000 {
        let t = i as f64 * 1e-3;
        let rate = if (1.0..2.0).contains(&t) { 90.0 } else { 0.0 };
        let bad = [f32::NAN, f32::INFINITY, f32::NEG_INFINITY, 2e4, -3e38];
        // Replace a sample at rest by garbage: the pipeline holds the last valid rate (0).
        let dirty_rate = if i % 100 == 7 && rate == 0.0 {
            bad[i / 100 % 5]
        } else {
            rate
        };
        last.0 = clean.push(t, rate).or(last.0);
        last.1 = dirty.push(t, dirty_rate).or(last.1);
    }
    let rejected = (0..4000)
        .filter(|i| i % 100 == 7 && !(1000..2000).contains(i))
        .count();
    assert_eq!(dirty.rejected_samples() as usize, rejected);
    assert_eq!(clean.rejected_samples(), 0);
    let (clean, dirty) = (last.0.expect("outputs"), last.1.expect("outputs"));
    assert_eq!(clean.angle_deg, dirty.angle_deg);
    assert!((clean.angle_deg - 90.0).abs() < 0.05);
}

/// With `min_rest_s` of a single sample the end comes on the first quiet sample, which
/// must still be integrated: the same movement as with a longer rest, and the end time
/// on the same output sample.
#[test]
fn a_one_sample_rest_ends_the_movement_on_its_last_sample() {
    let samples: Vec<f32> = (0..6000)
        .map(|i| {
            let t = i as f64 * 1e-3;
            if (1.0..2.0).contains(&t) {
                (90.0 * (1.0 - (2.0 * std::f64::consts::PI * (t - 1.0)).cos())) as f32
            } else {
                0.0
            }
        })
        .collect();
    let movement = |min_rest_s: f32| {
        // A high exit level, so that the last integrated step is large enough to miss;
        // entry at the same level, so that with a one-sample rest the onset is not taken
        // for a new rest level.
        let config = Config {
            compensation: Compensation::None,
            motion: MotionConfig {
                exit_dps: 5.0,
                enter_dps: 5.0,
                min_rest_s,
                ..MotionConfig::default()
            },
            ..Config::default()
        };
        let run = common::run(&config, &samples, 1000.0);
        assert_eq!(run.movements.len(), 1);
        run.movements[0].1
    };
    let one = movement(0.0);
    let two = movement(0.04);
    assert_eq!(one.start_time_s, two.start_time_s);
    assert_eq!(one.end_time_s, two.end_time_s);
    assert_eq!(one.raw_angle_deg, two.raw_angle_deg);
    assert_eq!(one.angle_deg, two.angle_deg);
}
