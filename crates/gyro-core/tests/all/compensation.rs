//! Error compensation at the pipeline level: the paper's model and the Kalman form.

use crate::common::{run, BenchSpec, Profile, Rng};
use gyro_core::{Compensation, Config, Event, GaussMarkov, KalmanConfig};

fn bench_samples(seed: u64, bias_dps: f64, noise_dps: f64) -> (Profile, Vec<f32>) {
    let mut rng = Rng::new(seed);
    let profile = Profile::bench(&mut rng, &BenchSpec::default());
    let samples = profile.samples(1000.0, bias_dps, noise_dps, &mut rng);
    (profile, samples)
}

/// Paper mode: movement angle = raw movement angle − o(t_m), t_m the movement's duration;
/// between movements the angle is the sum of the compensated movements.
#[test]
fn paper_mode_subtracts_the_modelled_misalignment() {
    let paper = GaussMarkov {
        beta_per_s: 0.05,
        b0_dps: 0.3,
        o0_deg: 0.1,
    };
    let config = Config {
        compensation: Compensation::Paper,
        paper,
        ..Config::default()
    };
    for seed in 0..3 {
        let (profile, samples) = bench_samples(seed, 0.3, 0.05);
        let run = run(&config, &samples, 1000.0);
        assert_eq!(run.movements.len(), profile.swings.len());
        let mut total_deg = 0.0_f64;
        for &(k, movement) in &run.movements {
            let t_m = (movement.end_time_s - movement.start_time_s) as f32;
            let expected = movement.raw_angle_deg - paper.misalignment_deg(t_m);
            assert!(
                (movement.angle_deg - expected).abs() < 1e-3,
                "{movement:?}: expected {expected}"
            );
            // The model is not trivial here: it moves the angle by a visible amount.
            assert!(paper.misalignment_deg(t_m) > 0.3);
            total_deg += f64::from(movement.angle_deg);
            assert!((f64::from(run.outputs[k].angle_deg) - total_deg).abs() < 1e-3);
        }
    }
}

/// With the bias as its model (b0 = the bias, β = 0), paper mode recovers the true angle.
#[test]
fn paper_mode_with_the_true_bias_recovers_the_angle() {
    let bias_dps = 0.4;
    let config = Config {
        compensation: Compensation::Paper,
        paper: GaussMarkov {
            beta_per_s: 0.0,
            b0_dps: bias_dps as f32,
            o0_deg: 0.0,
        },
        ..Config::default()
    };
    let (profile, samples) = bench_samples(7, bias_dps, 0.05);
    let run = run(&config, &samples, 1000.0);
    assert_eq!(run.movements.len(), profile.swings.len());
    for ((_, movement), swing) in run.movements.iter().zip(&profile.swings) {
        let raw_error = f64::from(movement.raw_angle_deg) - swing.angle_deg;
        let error = f64::from(movement.angle_deg) - swing.angle_deg;
        assert!(raw_error.abs() > 0.3, "{raw_error}");
        assert!(error.abs() < 0.05, "{error}");
    }
}

/// Without compensation the movement angle is the raw one (the onset, integrated
/// tentatively before the movement is confirmed, belongs to both).
#[test]
fn no_compensation_reports_the_raw_angle() {
    let config = Config {
        compensation: Compensation::None,
        ..Config::default()
    };
    let (profile, samples) = bench_samples(3, 0.2, 0.05);
    let run = run(&config, &samples, 1000.0);
    assert_eq!(run.movements.len(), profile.swings.len());
    for (_, movement) in &run.movements {
        assert_eq!(movement.angle_deg, movement.raw_angle_deg);
    }
    assert!(run.outputs.iter().all(|o| o.angle_std_deg.is_none()));
}

/// Kalman mode with a constant bias and rests around every movement: the movement angle
/// is much closer to the truth than the raw one, and the angle's standard deviation is
/// reported and grows during motion.
#[test]
fn kalman_mode_removes_a_constant_bias() {
    let bias_dps = 0.5;
    let config = Config {
        compensation: Compensation::Kalman,
        ..Config::default()
    };
    let mut worst_raw: f64 = f64::INFINITY;
    let mut worst_kalman: f64 = 0.0;
    let mut worst_ratio: f64 = 0.0;
    for seed in 10..14 {
        let (profile, samples) = bench_samples(seed, bias_dps, 0.08);
        let run = run(&config, &samples, 1000.0);
        assert_eq!(run.movements.len(), profile.swings.len());
        assert!(run.outputs.iter().all(|o| o.angle_std_deg.is_some()));
        for (((started_at, _), (ended_at, movement)), swing) in
            run.starts.iter().zip(&run.movements).zip(&profile.swings)
        {
            let raw_error = (f64::from(movement.raw_angle_deg) - swing.angle_deg).abs();
            let kalman_error = (f64::from(movement.angle_deg) - swing.angle_deg).abs();
            assert!(
                kalman_error < 0.1 && kalman_error < 0.1 * raw_error,
                "seed {seed}: raw error {raw_error}, Kalman error {kalman_error}"
            );
            worst_raw = worst_raw.min(raw_error);
            worst_kalman = worst_kalman.max(kalman_error);
            worst_ratio = worst_ratio.max(kalman_error / raw_error);

            let std_at = |k: usize| run.outputs[k].angle_std_deg.expect("Kalman mode");
            // Grows during the movement...
            assert!(std_at(*ended_at) > std_at(*started_at - 1));
            assert!(std_at(*ended_at - 1) > std_at(*started_at + 1));
            // ... but not at rest.
            let before = std_at(*started_at - 1);
            assert!(std_at(*started_at - 20) <= before + 1e-6);
        }
        // The estimate has found the bias.
        let last = run.outputs.last().expect("outputs");
        assert!(
            (f64::from(last.bias_dps) - bias_dps).abs() < 0.02,
            "{last:?}"
        );
    }
    eprintln!(
        "bias 0.5 deg/s: smallest raw error {worst_raw:.3}°, largest Kalman error \
         {worst_kalman:.4}°, largest Kalman/raw ratio {worst_ratio:.3}"
    );
}

/// Without bias or noise the Kalman form must not cost accuracy: the quiet samples just
/// before a movement (the start of its rate, below `exit_dps`) are not bias observations.
#[test]
fn kalman_mode_is_exact_without_bias() {
    let config = Config {
        compensation: Compensation::Kalman,
        kalman: KalmanConfig::default(),
        ..Config::default()
    };
    let (profile, samples) = bench_samples(21, 0.0, 0.0);
    let run = run(&config, &samples, 1000.0);
    assert_eq!(run.movements.len(), profile.swings.len());
    for ((_, movement), swing) in run.movements.iter().zip(&profile.swings) {
        let error = f64::from(movement.angle_deg) - swing.angle_deg;
        assert!(error.abs() < 0.01, "{movement:?} vs {swing:?}");
    }
    for out in &run.outputs {
        if let Some(Event::MovementEnded(m)) = out.event {
            assert!((m.angle_deg - m.raw_angle_deg).abs() < 0.01);
        }
    }
}

/// A log that starts in motion: the first output has no interval before it, so the angle
/// turned equals the integral of the rate from the first output on, not one step more.
#[test]
fn a_log_starting_in_motion_gains_no_extra_step() {
    let mut pipeline =
        gyro_core::Pipeline::try_new(&gyro_core::Config::default()).expect("default config");
    let mut first = None;
    let mut last = None;
    for i in 0..3000 {
        let time_s = i as f64 * 1e-3;
        // 50 deg/s from the very first sample for 2 s, then rest.
        let rate_dps = if time_s < 2.0 { 50.0 } else { 0.0 };
        if let Some(out) = pipeline.push(time_s, rate_dps) {
            first.get_or_insert(out);
            last = Some(out);
        }
    }
    let (first, last) = (first.expect("outputs"), last.expect("outputs"));
    assert_eq!(
        first.raw_angle_deg, 0.0,
        "the first output integrates nothing"
    );
    // From the first output's block centre (9.5 ms) to the end of the motion, plus the
    // filter's delay: settled on the first sample, the filter acts as if the rate had been
    // 50 deg/s forever, so its output falls that much later (one step more would be +1 deg).
    let expected = 50.0 * (2.0 - first.time_s + pipeline.filter_delay_s());
    assert!(
        (f64::from(last.raw_angle_deg) - expected).abs() < 0.05,
        "{} vs {expected}",
        last.raw_angle_deg
    );
}
