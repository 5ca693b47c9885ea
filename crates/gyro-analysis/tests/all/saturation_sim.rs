//! Simulated bench runs with a gyro that clips at 75 deg/s: every movement whose readings
//! clipped is flagged saturated, and none is in the same runs without the clip.
//!
//! Two ways to clip: a sensor whose range is ±75 deg/s, with the range known to the
//! pipeline (the model file's `sensor.range_dps`); and a ±300 deg/s sensor that clips at
//! 75 deg/s (effect `saturation`), where only the clip plateau tells. The same with the
//! gyro's own low-pass (effect `bandwidth`, 15 and 5 Hz), whose output repeats a reading
//! at smooth peaks and steady turns without any clip. `cargo test -p gyro-analysis --test all
//! saturation_sim:: -- --nocapture` prints the counts. The clip also at 100 Hz and at 8 kHz,
//! with and without the low-pass there.
#![allow(clippy::unwrap_used)] // test code: a failed unwrap is a failed test

use gyro_analysis::replay::{replay, MovementResult};
use gyro_core::Config;
use gyro_log::GridOptions;
use gyro_sim::{simulate, BenchProfile, Effect, Motion, SensorModel, SimOptions};

const CLIP_DPS: f64 = 75.0;
const SEEDS: std::ops::RangeInclusive<u64> = 1..=16;
/// The seeds also simulated at 8 kHz (eight times the samples: fewer, to keep the test
/// short unoptimised).
const SEEDS_8_KHZ: std::ops::RangeInclusive<u64> = 1..=6;

/// Per rotation: its true peak |rate| (deg/s), the angle the clip takes off it (deg,
/// from the true rate), and whether a logged reading sits at ±clip.
struct Truth {
    peak_dps: f64,
    lost_deg: f64,
    clipped: bool,
}

fn truths(motion: &Motion, log: &gyro_log::Log, clip_dps: f64) -> Vec<Truth> {
    motion
        .rotations()
        .iter()
        .map(|r| {
            let (start, end) = (r.start_s, r.start_s + r.duration_s);
            let n = (r.duration_s * 1000.0).ceil() as usize;
            let rates = (0..=n).map(|k| motion.rate_dps(start + k as f64 * 1e-3).abs());
            let (peak_dps, lost_deg) = rates.fold((0.0_f64, 0.0), |(p, l), v| {
                (p.max(v), l + (v - clip_dps).max(0.0) * 1e-3)
            });
            let clipped = log.rows.iter().any(|row| {
                row.time_s >= start
                    && row.time_s <= end
                    && row.rate_dps.is_some_and(|v| v.abs() >= clip_dps)
            });
            Truth {
                peak_dps,
                lost_deg,
                clipped,
            }
        })
        .collect()
}

fn movements(log: &gyro_log::Log, range_dps: Option<f32>) -> Vec<MovementResult> {
    let regular = gyro_log::regularize(log, &GridOptions::default()).unwrap();
    let config = Config {
        range_dps,
        ..Config::default()
    };
    replay(&regular, &config).unwrap().movements
}

/// A CRM100 read at 8 kHz.
fn at_8_khz() -> SensorModel {
    SensorModel {
        sample_rate_hz: 8000.0,
        ..SensorModel::default()
    }
}

#[test]
fn clipped_movements_are_flagged_and_unclipped_runs_are_not() {
    let options = |seed| SimOptions {
        seed,
        ..SimOptions::default()
    };
    let (mut movements_seen, mut clipped_seen) = (0, 0);
    let (mut by_range, mut by_plateau, mut plateau_missed) = (0, 0, 0);
    let mut low_passed_seen = 0;
    let mut missed_lost_deg = 0.0_f64;
    // The same for the noisy 8 kHz sensor.
    let mut missed_noisy_lost_deg = 0.0_f64;
    for seed in SEEDS {
        let motion = Motion::bench(&BenchProfile::default(), seed);
        let clean = simulate(&SensorModel::default(), &[], &motion, &options(seed));
        // No clip: nothing flagged, with the range known or not.
        for range_dps in [None, Some(300.0)] {
            let found = movements(&clean, range_dps);
            assert_eq!(found.len(), motion.rotations().len(), "seed {seed}");
            assert!(found.iter().all(|m| !m.saturated), "seed {seed}");
        }

        // A ±75 deg/s sensor, range known: every movement with a clipped reading.
        let narrow = SensorModel {
            range_dps: CLIP_DPS,
            ..SensorModel::default()
        };
        let log = simulate(&narrow, &[], &motion, &options(seed));
        let truth = truths(&motion, &log, CLIP_DPS);
        let found = movements(&log, Some(CLIP_DPS as f32));
        assert_eq!(found.len(), truth.len(), "seed {seed}");
        for (t, m) in truth.iter().zip(&found) {
            if t.clipped || t.peak_dps > CLIP_DPS {
                assert!(m.saturated, "seed {seed}: peak {} {m:?}", t.peak_dps);
            }
            // Well below the range (bias 0.3, 5 sigma of noise): never.
            if t.peak_dps < CLIP_DPS * 0.995 - 0.3 - 0.75 {
                assert!(!m.saturated, "seed {seed}: peak {} {m:?}", t.peak_dps);
            }
            movements_seen += 1;
            clipped_seen += usize::from(t.clipped);
            by_range += usize::from(m.saturated);
        }

        // A low-passed gyro repeats readings at smooth peaks and steady turns: no clip,
        // nothing flagged. Also at 8 kHz, where 16 readings last 2 ms.
        for (sensor, cutoff_hz) in [
            (SensorModel::default(), 15.0),
            (SensorModel::default(), 5.0),
            (at_8_khz(), 15.0),
        ] {
            if sensor.sample_rate_hz > 1000.0 && !SEEDS_8_KHZ.contains(&seed) {
                continue;
            }
            let effect = [Effect::Bandwidth { cutoff_hz }];
            let log = simulate(&sensor, &effect, &motion, &options(seed));
            for range_dps in [None, Some(300.0)] {
                let found = movements(&log, range_dps);
                assert_eq!(found.len(), motion.rotations().len(), "seed {seed}");
                low_passed_seen += found.len();
                assert!(
                    found.iter().all(|m| !m.saturated),
                    "seed {seed}, {cutoff_hz} Hz"
                );
            }
        }

        // A ±300 deg/s sensor clipping at 75 deg/s, range 300 (the model's) or unknown,
        // with and without a 15 Hz low-pass before the clip: the plateau flags every
        // movement whose true peak passes the clip by 1 deg/s; one that barely touches it
        // may go unflagged, losing little. At 8 kHz without the low-pass each reading's
        // noise (0.42 deg/s) breaks a clip barely passed into runs shorter than the 16 ms a
        // plateau needs there: the margin is 1 deg/s plus 3 σ of that noise.
        let clip = Effect::Saturation {
            limit_dps: CLIP_DPS,
        };
        let low_pass = Effect::Bandwidth { cutoff_hz: 15.0 };
        // And a 100 Hz sensor: 16 readings there last 160 ms, past the filter's lag.
        let at_100_hz = SensorModel {
            sample_rate_hz: 100.0,
            ..SensorModel::default()
        };
        let noisy_8k_margin_dps = 1.0 + 3.0 * at_8_khz().white_sigma_dps();
        for (sensor, effects, margin_dps) in [
            (SensorModel::default(), vec![clip], 1.0),
            (SensorModel::default(), vec![clip, low_pass], 1.0),
            (at_100_hz, vec![clip], 1.0),
            (at_8_khz(), vec![clip], noisy_8k_margin_dps),
            (at_8_khz(), vec![clip, low_pass], 1.0),
        ] {
            if sensor.sample_rate_hz > 1000.0 && !SEEDS_8_KHZ.contains(&seed) {
                continue;
            }
            let log = simulate(&sensor, &effects, &motion, &options(seed));
            let truth = truths(&motion, &log, CLIP_DPS);
            for range_dps in [None, Some(300.0)] {
                let found = movements(&log, range_dps);
                assert_eq!(found.len(), truth.len(), "seed {seed}");
                for (t, m) in truth.iter().zip(&found) {
                    if t.peak_dps > CLIP_DPS + margin_dps {
                        assert!(m.saturated, "seed {seed}: peak {} {m:?}", t.peak_dps);
                    }
                    if !t.clipped {
                        assert!(!m.saturated, "seed {seed}: not clipped {m:?}");
                    }
                    if range_dps.is_none() {
                        by_plateau += usize::from(m.saturated);
                        if t.clipped && !m.saturated {
                            plateau_missed += 1;
                            let lost = if margin_dps > 1.0 {
                                &mut missed_noisy_lost_deg
                            } else {
                                &mut missed_lost_deg
                            };
                            *lost = lost.max(t.lost_deg);
                        }
                    }
                }
            }
        }
    }
    println!(
        "{} runs, {movements_seen} movements, {clipped_seen} with a clipped reading; \
         range known: {by_range} flagged; plateau only (with and without low-pass): \
         {by_plateau} flagged, {plateau_missed} clipped but not flagged (at most \
         {missed_lost_deg:.4} deg lost; {missed_noisy_lost_deg:.4} by the noisy 8 kHz \
         sensor); low-passed without clip: {low_passed_seen} movements, none flagged",
        SEEDS.count()
    );
    assert!(clipped_seen >= 40, "{clipped_seen}");
    // A clip passed by less than 1 deg/s on a slow turn stands little beyond the filtered
    // rate and lasts less than the long plateau: it may go unflagged, losing under 0.1°.
    assert!(missed_lost_deg < 0.1, "{missed_lost_deg}");
    // At 8 kHz, with 0.42 deg/s of noise on each reading, such a clip may pass the clip by
    // 1.4 deg/s and lose up to 0.2°.
    assert!(missed_noisy_lost_deg < 0.25, "{missed_noisy_lost_deg}");
}
