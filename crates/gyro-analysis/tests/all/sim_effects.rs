//! Each effect of the simulator changes the statistic its signature names (docs/effects.md).
//!
//! Every run is compared with the same seed without the effect: the random streams are
//! per source, so the difference between the two is the effect's own term (plus rounding
//! to the output word).
#![allow(clippy::unwrap_used)] // test code: a failed unwrap is a failed test

use gyro_analysis::noise::AllanDeviation;
use gyro_log::Log;
use gyro_sim::{simulate, BenchProfile, Effect, Motion, Rotation, SensorModel, SimOptions};

const FS: f64 = 200.0;

fn sensor() -> SensorModel {
    SensorModel {
        sample_rate_hz: FS,
        lsb_dps: 0.0,
        ..SensorModel::default()
    }
}

fn bench() -> Motion {
    Motion::bench(&BenchProfile::default(), 5)
}

/// Fast and slow 90° rotations: peaks of 211 and 56 deg/s.
fn fast() -> Motion {
    let rotation = |start_s, duration_s, angle_deg| Rotation {
        start_s,
        duration_s,
        angle_deg,
    };
    Motion::from_rotations(
        vec![
            rotation(2.0, 0.8, 90.0),
            rotation(5.0, 3.0, -90.0),
            rotation(10.0, 0.8, -90.0),
        ],
        13.0,
    )
}

fn run(effects: &[Effect], motion: &Motion) -> Log {
    simulate(&sensor(), effects, motion, &SimOptions::default())
}

fn rates(log: &Log) -> Vec<f64> {
    log.rows.iter().map(|r| r.rate_dps.unwrap()).collect()
}

/// (true rate, with − without) per sample of two runs with the same rows.
fn diff(effect: Effect) -> (Motion, Vec<(f64, f64, f64)>) {
    diff_on(effect, bench())
}

fn diff_on(effect: Effect, motion: Motion) -> (Motion, Vec<(f64, f64, f64)>) {
    let with = run(&[effect], &motion);
    let without = run(&[], &motion);
    assert_eq!(with.rows.len(), without.rows.len());
    let d = with
        .rows
        .iter()
        .zip(&without.rows)
        .map(|(a, b)| {
            (
                motion.rate_dps(a.time_s),
                a.rate_dps.unwrap() - b.rate_dps.unwrap(),
                a.temperature_c.unwrap(),
            )
        })
        .collect();
    (motion, d)
}

/// Least-squares slope through the origin of y on x.
fn slope(points: impl Iterator<Item = (f64, f64)>) -> f64 {
    let (mut xy, mut xx) = (0.0, 0.0);
    for (x, y) in points {
        xy += x * y;
        xx += x * x;
    }
    xy / xx
}

#[test]
fn scale_factor_only_in_motion_proportional_to_rate() {
    let (_, d) = diff(Effect::ScaleFactor { k: 0.01 });
    let k = slope(d.iter().map(|&(r, e, _)| (r, e)));
    assert!((k - 0.01).abs() < 1e-6, "{k}");
    let at_rest = d
        .iter()
        .filter(|p| p.0 == 0.0)
        .map(|p| p.1.abs())
        .fold(0.0, f64::max);
    assert!(at_rest < 1e-12, "{at_rest}");
}

#[test]
fn scale_asymmetry_differs_by_sign() {
    let (_, d) = diff(Effect::ScaleAsymmetry { k: 0.005 });
    let positive = slope(d.iter().filter(|p| p.0 > 0.0).map(|&(r, e, _)| (r, e)));
    let negative = slope(d.iter().filter(|p| p.0 < 0.0).map(|&(r, e, _)| (r, e)));
    assert!(
        (positive - 0.005).abs() < 1e-6 && (negative + 0.005).abs() < 1e-6,
        "{positive} {negative}"
    );
}

#[test]
fn nonlinearity_is_cubic_in_rate() {
    let (_, d) = diff_on(Effect::Nonlinearity { k3_per_dps2: 2e-7 }, fast());
    // Residual / rate grows with rate squared: a curved residual, not a scale error.
    let k3 = slope(
        d.iter()
            .filter(|p| p.0.abs() > 1.0)
            .map(|&(r, e, _)| (r * r, e / r)),
    );
    assert!((k3 - 2e-7).abs() < 1e-9, "{k3}");
    let fast = d.iter().map(|p| p.0.abs()).fold(0.0, f64::max);
    assert!(fast > 100.0, "the profile must reach fast rates: {fast}");
}

#[test]
fn saturation_clips_raw_values() {
    let motion = fast();
    let with = rates(&run(&[Effect::Saturation { limit_dps: 120.0 }], &motion));
    let without = rates(&run(&[], &motion));
    let max = |v: &[f64]| v.iter().map(|x| x.abs()).fold(0.0, f64::max);
    assert!(max(&without) > 150.0);
    assert!(max(&with) <= 120.0);
    let clipped = with.iter().filter(|x| x.abs() == 120.0).count();
    assert!(clipped > 20, "{clipped} samples at the clip level");
}

#[test]
fn quantization_puts_values_on_a_grid() {
    let motion = bench();
    let on_grid = |v: &[f64]| {
        v.iter()
            .filter(|x| ((*x / 0.2) - (*x / 0.2).round()).abs() < 1e-9)
            .count()
    };
    let with = rates(&run(&[Effect::Quantization { lsb_dps: 0.2 }], &motion));
    let without = rates(&run(&[], &motion));
    assert_eq!(on_grid(&with), with.len());
    assert!(on_grid(&without) < without.len() / 100);
}

/// Lag (samples) at which the measured rate best matches the true rate.
fn best_lag(motion: &Motion, log: &Log) -> i64 {
    let measured = rates(log);
    let truth: Vec<f64> = log.rows.iter().map(|r| motion.rate_dps(r.time_s)).collect();
    (-10_i64..=20)
        .max_by(|&a, &b| {
            let score = |lag: i64| -> f64 {
                (20..truth.len() - 20)
                    .map(|i| measured[i] * truth[(i as i64 - lag) as usize])
                    .sum()
            };
            score(a).total_cmp(&score(b))
        })
        .unwrap()
}

#[test]
fn latency_moves_the_cross_correlation_peak_and_follows_acceleration() {
    let motion = bench();
    let with = run(&[Effect::Latency { delay_s: 0.025 }], &motion);
    assert_eq!(best_lag(&motion, &run(&[], &motion)), 0);
    assert_eq!(best_lag(&motion, &with), 5); // 25 ms at 200 Hz
                                             // The residual is −delay × angular acceleration.
    let (_, d) = diff(Effect::Latency { delay_s: 0.025 });
    let accel: Vec<f64> = (0..d.len())
        .map(|i| {
            let t = i as f64 / FS;
            (motion.rate_dps(t + 1e-4) - motion.rate_dps(t - 1e-4)) / 2e-4
        })
        .collect();
    let k = slope(accel.iter().zip(&d).map(|(a, p)| (*a, p.1)));
    assert!((k + 0.025).abs() < 0.003, "{k}");
}

#[test]
fn clock_error_scales_the_angle_with_a_clean_rate_shape() {
    let motion = bench();
    let eps = 5000e-6;
    let with = run(&[Effect::ClockError { ppm: 5000.0 }], &motion);
    let without = run(&[], &motion);
    // Integrated with the nominal period, each 90° rotation gains ε·90° (over as many
    // samples as the nominal run's: the fast clock takes ε more within the motion, at
    // rest after its last rotation).
    let n = without.rows.len();
    let integral = |log: &Log| -> f64 { rates(log)[..n].iter().sum::<f64>() / FS };
    let total_angle: f64 = motion.rotations().iter().map(|r| r.angle_deg).sum();
    let gained = integral(&with) - integral(&without);
    assert!(
        (gained - eps * total_angle).abs() < 0.05,
        "{gained} vs {}",
        eps * total_angle
    );
    // The stamps are the true sample times, 1/(fs(1+ε)) apart.
    let last = with.rows.last().unwrap();
    let period = last.time_s / (with.rows.len() - 1) as f64;
    assert!((period * FS * (1.0 + eps) - 1.0).abs() < 1e-9, "{period}");
    // The measured rate is the true rate at its stamp (no scale error in the rate itself).
    let true_at_sample: Vec<f64> = with
        .rows
        .iter()
        .map(|r| motion.rate_dps(r.time_s))
        .collect();
    let residual: Vec<f64> = rates(&with)
        .iter()
        .zip(&rates(&without))
        .zip(&without.rows)
        .zip(&true_at_sample)
        .map(|(((a, b), row), t)| (a - b) - (t - motion.rate_dps(row.time_s)))
        .collect();
    let worst = residual.iter().map(|x| x.abs()).fold(0.0, f64::max);
    // Up to two roundings of the output to 1e-6 deg/s.
    assert!(worst < 1.1e-6, "{worst}");
}

#[test]
fn dropouts_remove_samples_in_bursts() {
    let motion = bench();
    let with = run(
        &[Effect::Dropouts {
            rate_per_s: 0.5,
            mean_samples: 5.0,
        }],
        &motion,
    );
    let without = run(&[], &motion);
    let lost = without.rows.len() - with.rows.len();
    let gaps = with
        .rows
        .windows(2)
        .filter(|w| w[1].time_s - w[0].time_s > 1.5 / FS)
        .count();
    // 0.5 events/s over 90 s: ~45 gaps of ~5 samples.
    assert!((25..=70).contains(&gaps), "{gaps} gaps");
    let per_gap = lost as f64 / gaps as f64;
    assert!((3.0..=8.0).contains(&per_gap), "{per_gap} samples per gap");
}

#[test]
fn temperature_bias_tracks_temperature_at_rest() {
    let (_, d) = diff(Effect::TemperatureBias { dps_per_c: 0.05 });
    let start_c = d[0].2;
    let rest: Vec<(f64, f64)> = d
        .iter()
        .filter(|p| p.0 == 0.0)
        .map(|p| (p.2 - 25.0, p.1))
        .collect();
    let k = slope(rest.iter().copied());
    assert!((k - 0.05).abs() < 0.002, "{k} (start {start_c} C)");
    let spread =
        rest.iter().map(|p| p.1).fold(0.0, f64::max) - rest.iter().map(|p| p.1).fold(0.0, f64::min);
    assert!(
        spread > 0.1,
        "the temperature must change for the test to mean something: {spread}"
    );
}

#[test]
fn temperature_scale_tracks_temperature_only_in_motion() {
    let (_, d) = diff(Effect::TemperatureScale { per_c: 1e-3 });
    let k = slope(d.iter().map(|&(r, e, c)| (r * (c - 25.0), e)));
    assert!((k - 1e-3).abs() < 5e-5, "{k}");
    let at_rest = d
        .iter()
        .filter(|p| p.0 == 0.0)
        .map(|p| p.1.abs())
        .fold(0.0, f64::max);
    assert!(at_rest < 1e-12);
}

/// Log-log slope of the Allan deviation between τ = 10 s and 100 s, static 2000 s at 20 Hz.
fn long_tau_slope(effects: &[Effect]) -> f64 {
    let model = SensorModel {
        sample_rate_hz: 20.0,
        gm_sigma_dps: 0.0,
        lsb_dps: 0.0,
        ..SensorModel::default()
    };
    let still = Motion::from_rotations(vec![], 2000.0);
    let slopes: Vec<f64> = (1..=3)
        .map(|seed| {
            let log = simulate(
                &model,
                effects,
                &still,
                &SimOptions {
                    seed,
                    temperature_rise_c: 0.0,
                    ..SimOptions::default()
                },
            );
            let r = rates(&log);
            let adev = AllanDeviation::compute(&[&r], 20.0, &[200, 2000], 0.6827);
            let (a, b) = (&adev.points[0], &adev.points[1]);
            (b.adev_dps / a.adev_dps).log10() / (b.tau_s / a.tau_s).log10()
        })
        .collect();
    slopes.iter().sum::<f64>() / slopes.len() as f64
}

#[test]
fn bias_instability_flattens_and_rate_random_walk_raises_the_long_tau_allan_slope() {
    let white = long_tau_slope(&[]);
    let flicker = long_tau_slope(&[Effect::BiasInstability { sigma_dps: 0.05 }]);
    let walk = long_tau_slope(&[Effect::RateRandomWalk {
        k_dps_per_rt_s: 0.005,
    }]);
    println!("slopes: white {white:.2}, bias instability {flicker:.2}, rate random walk {walk:.2}");
    assert!((white + 0.5).abs() < 0.15, "{white}");
    assert!(flicker.abs() < 0.25, "{flicker}");
    assert!((walk - 0.5).abs() < 0.2, "{walk}");
}

#[test]
fn turn_on_bias_spreads_static_means_between_runs() {
    let still = Motion::from_rotations(vec![], 30.0);
    let spread = |effects: &[Effect]| -> (f64, f64) {
        let (mut means, mut within) = (Vec::new(), Vec::new());
        for seed in 1..=12 {
            let r = rates(&simulate(
                &sensor(),
                effects,
                &still,
                &SimOptions {
                    seed,
                    ..SimOptions::default()
                },
            ));
            let (first, second) = r.split_at(r.len() / 2);
            let mean = |x: &[f64]| x.iter().sum::<f64>() / x.len() as f64;
            means.push(mean(&r));
            within.push((mean(first) - mean(second)).abs());
        }
        let m = means.iter().sum::<f64>() / means.len() as f64;
        let between =
            (means.iter().map(|x| (x - m).powi(2)).sum::<f64>() / (means.len() - 1) as f64).sqrt();
        (between, within.iter().sum::<f64>() / within.len() as f64)
    };
    let (between_off, _) = spread(&[]);
    let (between_on, within_on) = spread(&[Effect::TurnOnBias { sigma_dps: 0.5 }]);
    assert!(
        between_on > 0.25 && between_on > 10.0 * within_on,
        "{between_on} vs within {within_on}"
    );
    assert!(
        between_on > 5.0 * between_off,
        "{between_on} vs {between_off} without"
    );
}

#[test]
fn bandwidth_lags_and_attenuates_fast_motion() {
    let motion = bench();
    let with = run(&[Effect::Bandwidth { cutoff_hz: 15.0 }], &motion);
    // Two first-order stages with poles at 23.3 Hz: about 14 ms of delay at low frequency.
    let lag = best_lag(&motion, &with);
    assert!((2..=4).contains(&lag), "{lag} samples");
    // The high band is attenuated: a 20 Hz vibration (like a stepper's ripple) of
    // ±63 deg/s comes out at |H(20 Hz)| = 1/(1 + (20/23.3)²) = 0.58 of its amplitude.
    let angle: Vec<f64> = (0..4000)
        .map(|k| 0.5 * (2.0 * std::f64::consts::PI * 20.0 * k as f64 / 2000.0).sin())
        .collect();
    let vibration = Motion::from_reference(0.0, 1.0 / 2000.0, &angle, 1);
    let (_, d) = diff_on(Effect::Bandwidth { cutoff_hz: 15.0 }, vibration);
    let rms = |x: &mut dyn Iterator<Item = f64>| {
        let v: Vec<f64> = x.collect();
        (v.iter().map(|y| y * y).sum::<f64>() / v.len() as f64).sqrt()
    };
    let settled = &d[40..];
    let ratio = rms(&mut settled.iter().map(|p| p.0 + p.1)) / rms(&mut settled.iter().map(|p| p.0));
    assert!((ratio - 0.58).abs() < 0.05, "{ratio}");
}
