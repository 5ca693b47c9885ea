//! Saturation: a movement during which a reading reached the sensor's range, or sat on a
//! clip plateau, is flagged; the same movement unclipped, and rests on a quantised output,
//! are not.

use crate::common::{run, BenchSpec, Profile, Rng, Shape, Swing};
use gyro_core::{Config, Pipeline, CLIP_PLATEAU_MIN_DPS, CLIP_PLATEAU_SAMPLES};

const FS_HZ: f64 = 1000.0;
/// The nominal CRM100 of the simulator: white noise per sample, output step (deg/s).
const NOISE_DPS: f64 = 0.148;
const LSB_DPS: f64 = 1.0 / 24.0;

/// `profile` as a sensor reads it: bias and white noise, rounded to `lsb_dps`, clipped at
/// ±`clip_dps`.
fn readings(profile: &Profile, bias_dps: f64, lsb_dps: f64, clip_dps: f64, seed: u64) -> Vec<f32> {
    let mut rng = Rng::new(seed);
    let n = (profile.total_s * FS_HZ).round() as usize;
    (0..n)
        .map(|i| {
            let t = i as f64 / FS_HZ;
            let measured = profile.rate_dps(t) + bias_dps + NOISE_DPS * rng.normal();
            let rounded = if lsb_dps > 0.0 {
                (measured / lsb_dps).round() * lsb_dps
            } else {
                measured
            };
            rounded.clamp(-clip_dps, clip_dps) as f32
        })
        .collect()
}

/// One 91.2° turn in 1.2 s (peak 152 deg/s) between rests.
fn one_turn() -> Profile {
    Profile {
        swings: vec![Swing {
            start_s: 3.0,
            duration_s: 1.2,
            angle_deg: 91.2,
            shape: Shape::RaisedCosine,
        }],
        total_s: 8.0,
    }
}

fn with_range(range_dps: Option<f32>) -> Config {
    Config {
        range_dps,
        ..Config::default()
    }
}

/// The saturated flags of the movements found.
fn flags(config: &Config, samples: &[f32]) -> Vec<bool> {
    run(config, samples, FS_HZ)
        .movements
        .iter()
        .map(|(_, m)| m.saturated)
        .collect()
}

#[test]
fn a_clipped_turn_is_flagged_by_the_range_and_by_its_plateau() {
    let clipped = readings(&one_turn(), 0.3, LSB_DPS, 75.0, 1);
    let r = run(&with_range(Some(75.0)), &clipped, FS_HZ);
    assert_eq!(r.movements.len(), 1);
    let m = r.movements[0].1;
    assert!(m.saturated);
    // The angle is a lower bound: the clip lost a third of the turn.
    assert!(m.angle_deg < 80.0, "{}", m.angle_deg);
    // Range unknown: the plateau at 75 deg/s alone flags it.
    assert_eq!(flags(&with_range(None), &clipped), [true]);
    // A nominal range above the clip (an analog clip below full scale): the plateau again.
    assert_eq!(flags(&with_range(Some(300.0)), &clipped), [true]);
}

#[test]
fn the_same_turn_unclipped_is_not_flagged() {
    let unclipped = readings(&one_turn(), 0.3, LSB_DPS, 300.0, 1);
    for range_dps in [None, Some(300.0), Some(900.0)] {
        let r = run(&with_range(range_dps), &unclipped, FS_HZ);
        assert_eq!(r.movements.len(), 1, "{range_dps:?}");
        let m = r.movements[0].1;
        assert!(!m.saturated, "{range_dps:?}");
        assert!((m.angle_deg - 91.2).abs() < 0.5, "{}", m.angle_deg);
    }
}

/// A configured range the readings go beyond is not the sensor's: reaching it no longer
/// flags a movement (the MPU6500 at 450 deg/s against the CRM100's ±300), a clip plateau
/// still does, and the pipeline says the range is contradicted. Within the margin
/// (0.5%) a reading is still at the range.
#[test]
fn a_range_the_readings_go_beyond_flags_plateaus_only() {
    // 91.2° in 1.2 s peaks at 152 deg/s: told the range is ±100, it goes beyond.
    let fast = readings(&one_turn(), 0.3, LSB_DPS, 1000.0, 3);
    let config = with_range(Some(100.0));
    assert_eq!(flags(&config, &fast), [false]);
    let mut pipeline = Pipeline::try_new(&config).unwrap();
    for (i, &x) in fast.iter().enumerate() {
        pipeline.push(i as f64 / FS_HZ, x);
    }
    assert!(pipeline.range_contradicted());
    // The same turn clipped at 100.4 deg/s (within the margin of ±100): flagged, and the
    // range stands.
    let clipped = readings(&one_turn(), 0.3, LSB_DPS, 100.4, 3);
    assert_eq!(flags(&config, &clipped), [true]);
    let mut pipeline = Pipeline::try_new(&config).unwrap();
    for (i, &x) in clipped.iter().enumerate() {
        pipeline.push(i as f64 / FS_HZ, x);
    }
    assert!(!pipeline.range_contradicted());
    // Clipped at 120 deg/s with a range of ±100: beyond it, but the plateau flags it.
    let plateau = readings(&one_turn(), 0.3, LSB_DPS, 120.0, 3);
    assert_eq!(flags(&config, &plateau), [true]);
}

/// A rest on a quantised output repeats one reading for seconds: below
/// [`CLIP_PLATEAU_MIN_DPS`] that is no clip, and it does not reach a known range either.
#[test]
fn rests_on_a_quantised_output_are_not_flagged() {
    let profile = one_turn();
    for (bias_dps, lsb_dps) in [(0.0, 1.0), (5.0, 1.0), (-20.0, 2.0), (0.25, LSB_DPS)] {
        // At rest the output repeats the bias on the output grid; the turn is read finely.
        let rest_value = ((bias_dps / lsb_dps).round() * lsb_dps) as f32;
        let mut samples = readings(&profile, bias_dps, LSB_DPS, 300.0, 2);
        for (i, sample) in samples.iter_mut().enumerate() {
            if profile.rate_dps(i as f64 / FS_HZ) == 0.0 {
                *sample = rest_value;
            }
        }
        for range_dps in [None, Some(300.0), Some(900.0)] {
            let config = Config {
                motion: gyro_core::MotionConfig {
                    initial_bias_dps: bias_dps as f32,
                    ..Default::default()
                },
                ..with_range(range_dps)
            };
            let r = run(&config, &samples, FS_HZ);
            assert_eq!(r.movements.len(), 1, "bias {bias_dps} lsb {lsb_dps}");
            assert!(!r.movements[0].1.saturated, "bias {bias_dps} lsb {lsb_dps}");
        }
        // Without a movement the rest stays unflagged to the end.
        samples.truncate(2500);
        let r = run(&with_range(Some(300.0)), &samples, FS_HZ);
        assert!(r.movements.is_empty() && !r.pipeline.movement_saturated());
    }
}

/// A run of identical readings in motion is a clip plateau from
/// [`CLIP_PLATEAU_SAMPLES`] on, and only at |rate| ≥ [`CLIP_PLATEAU_MIN_DPS`].
#[test]
fn plateau_rule_needs_enough_identical_readings_high_enough() {
    let plateau = usize::from(CLIP_PLATEAU_SAMPLES);
    // Readings of the unclipped turn with `length` identical ones at `level` spliced in at
    // the point where the turn passes that level.
    let spliced = |level: f32, length: usize| -> Vec<f32> {
        let mut samples = readings(&one_turn(), 0.0, 0.0, 300.0, 3);
        let at = samples
            .iter()
            .position(|&r| r >= level)
            .expect("the turn passes the level");
        samples[at..at + length].fill(level);
        samples
    };
    let config = with_range(None);
    assert_eq!(flags(&config, &spliced(75.0, plateau - 1)), [false]);
    assert_eq!(flags(&config, &spliced(75.0, plateau)), [true]);
    assert_eq!(flags(&config, &spliced(75.0, 400)), [true]);
    let below = CLIP_PLATEAU_MIN_DPS * 0.95;
    assert_eq!(flags(&config, &spliced(below, 400)), [false]);
    // A known range far above: the plateau still counts (a clip below full scale).
    assert_eq!(
        flags(&with_range(Some(900.0)), &spliced(75.0, plateau)),
        [true]
    );
}

/// A reading within 0.5% of the range counts as reaching it; one below does not.
#[test]
fn range_rule_has_a_half_percent_margin() {
    let base = readings(&one_turn(), 0.0, 0.0, 300.0, 4);
    let peak = base.iter().fold(0.0_f32, |a, &r| a.max(r));
    assert!(peak > 140.0 && peak < 160.0, "{peak}");
    let range_just_above = peak / (1.0 - 0.004);
    let range_above_margin = peak / (1.0 - 0.006);
    assert_eq!(flags(&with_range(Some(range_just_above)), &base), [true]);
    assert_eq!(flags(&with_range(Some(range_above_margin)), &base), [false]);
    // Negative turns too.
    let negative: Vec<f32> = base.iter().map(|r| -r).collect();
    assert_eq!(
        flags(&with_range(Some(range_just_above)), &negative),
        [true]
    );
}

/// A reading at the range outside any movement (a spike too short to make one) is
/// forgotten: the next movement, which does not reach the range, is not flagged.
#[test]
fn a_clip_outside_any_movement_is_not_carried_to_the_next() {
    let slow = Profile {
        swings: vec![Swing {
            start_s: 3.0,
            duration_s: 2.0,
            angle_deg: 20.0,
            shape: Shape::RaisedCosine,
        }],
        total_s: 8.0,
    };
    let mut samples = readings(&slow, 0.0, LSB_DPS, 300.0, 5);
    // One reading at a 30 deg/s range, a second before the turn (peak 20 deg/s).
    samples[2000] = 30.0;
    let r = run(&with_range(Some(30.0)), &samples, FS_HZ);
    assert_eq!(r.movements.len(), 1);
    assert!(!r.movements[0].1.saturated);
    // The same spike inside the turn flags it.
    samples[2000] = samples[4000];
    samples[4000] = 30.0;
    assert_eq!(flags(&with_range(Some(30.0)), &samples), [true]);
}

/// A turn that clips in its first samples, before the movement is confirmed, is flagged;
/// a host can ask while the movement is in progress.
#[test]
fn a_clip_during_the_confirming_run_is_kept() {
    let fast = Profile {
        swings: vec![Swing {
            start_s: 2.0,
            duration_s: 0.4,
            angle_deg: -90.0,
            shape: Shape::MinimumJerk,
        }],
        total_s: 5.0,
    };
    // Clipped at 20 deg/s, reached within the movement's first 60 ms.
    let samples = readings(&fast, 0.0, LSB_DPS, 20.0, 6);
    let first_clip = samples.iter().position(|&r| r <= -20.0).expect("clips");
    assert!(first_clip < 2060, "{first_clip}");
    let r = run(&with_range(Some(20.0)), &samples, FS_HZ);
    assert_eq!(flags(&with_range(Some(20.0)), &samples), [true]);
    assert_eq!(r.movements.len(), 1);

    let mut pipeline = Pipeline::try_new(&with_range(Some(20.0))).expect("config");
    let mut seen = false;
    for (i, &rate) in samples.iter().enumerate().take(2200) {
        pipeline.push(i as f64 / FS_HZ, rate);
        seen |= pipeline.movement_saturated();
    }
    assert!(seen && pipeline.movement_saturated());
}

/// Bench-like runs on the nominal sensor and on a 0.2 deg/s output step, range 300: no
/// movement reaches the range and none is flagged; clipped at 75 deg/s, every movement
/// whose true peak exceeds the clip by 1 deg/s is flagged, with the range known or not.
#[test]
fn bench_runs_flag_clipped_movements_only() {
    let (mut flagged, mut clipped_movements) = (0, 0);
    for seed in 1..=12 {
        let mut rng = Rng::new(seed);
        let profile = Profile::bench(&mut rng, &BenchSpec::default());
        for lsb_dps in [LSB_DPS, 0.2] {
            let clean = readings(&profile, 0.3, lsb_dps, 300.0, seed);
            for range_dps in [None, Some(300.0)] {
                let f = flags(&with_range(range_dps), &clean);
                assert_eq!(f.len(), profile.swings.len(), "seed {seed}");
                assert!(f.iter().all(|s| !s), "seed {seed} lsb {lsb_dps}: {f:?}");
            }
            let clipped = readings(&profile, 0.3, lsb_dps, 75.0, seed);
            for range_dps in [None, Some(75.0)] {
                let f = flags(&with_range(range_dps), &clipped);
                assert_eq!(f.len(), profile.swings.len(), "seed {seed}");
                for (swing, saturated) in profile.swings.iter().zip(&f) {
                    let peak = match swing.shape {
                        Shape::RaisedCosine => 2.0,
                        Shape::MinimumJerk => 1.875,
                    } * swing.angle_deg.abs()
                        / swing.duration_s;
                    if peak > 76.0 {
                        assert!(saturated, "seed {seed}: peak {peak} not flagged");
                        clipped_movements += 1;
                    }
                    if peak < 74.0 - 0.3 - 5.0 * NOISE_DPS {
                        assert!(!saturated, "seed {seed}: peak {peak} flagged");
                    }
                    flagged += usize::from(*saturated);
                }
            }
        }
    }
    assert!(clipped_movements >= 40, "{clipped_movements}");
    assert!(flagged >= clipped_movements);
}

/// Readings at 1 kHz that rest 2 s, rise from 0 at `slope_dps_per_s` to `peak_dps`, fall
/// back at the same slope and rest 2 s, quantised to the CRM100 step without noise (a gyro
/// whose own low-pass leaves its noise under the step), clipped at ±`clip_dps`.
fn triangle(slope_dps_per_s: f64, peak_dps: f64, clip_dps: f64) -> Vec<f32> {
    let rise_s = peak_dps / slope_dps_per_s;
    let n = ((4.0 + 2.0 * rise_s) * FS_HZ).round() as usize;
    (0..n)
        .map(|i| {
            let t = i as f64 / FS_HZ - 2.0;
            let rate = (peak_dps - slope_dps_per_s * (t - rise_s).abs()).max(0.0);
            ((rate / LSB_DPS).round() * LSB_DPS).min(clip_dps) as f32
        })
        .collect()
}

/// A run of identical readings counts as a clip plateau when it stands beyond the filtered
/// rate (a steep rise cut off) or lasts (a slow rise cut off), not when the output is
/// merely steady: readings that hold one value at a smooth peak or a steady turn sit at
/// the rate the filter already has.
#[test]
fn a_steady_reading_is_a_clip_plateau_only_beyond_the_filtered_rate_or_long() {
    let unknown = with_range(None);
    // A turn that eases into a steady 60 deg/s over 1 s (raised cosine), holds it for
    // 100 samples (under the long run) and eases out: one reading at the top for longer
    // than the plateau, at the rate the filter already has.
    let ease = |t: f64| 30.0 * (1.0 - (std::f64::consts::PI * t.clamp(0.0, 1.0)).cos());
    let hold_s = 0.1;
    assert!(hold_s < f64::from(gyro_core::CLIP_PLATEAU_LONG_S));
    let steady: Vec<f32> = (0..6100)
        .map(|i| {
            let t = i as f64 / FS_HZ - 2.0;
            let rate = ease(t).min(ease(2.0 + hold_s - t));
            ((rate / LSB_DPS).round() * LSB_DPS) as f32
        })
        .collect();
    let top = steady.iter().filter(|&&r| r == 60.0).count();
    assert!((100..128).contains(&top), "{top}");
    assert_eq!(flags(&unknown, &steady), [false]);

    // A steep turn (1000 deg/s per s, peak 70) cut off at 60 deg/s: 20 identical readings,
    // reached from far below the filtered rate.
    let steep = triangle(1000.0, 70.0, 60.0);
    let run = steep.iter().filter(|&&r| r == 60.0).count();
    assert!((16..40).contains(&run), "{run}");
    assert_eq!(flags(&unknown, &steep), [true]);

    // A slow turn (20 deg/s per s, peak 70) cut off at 60 deg/s: the filtered rate keeps
    // up with the rise (under 1 deg/s behind), but the clip lasts a second.
    let slow = triangle(20.0, 70.0, 60.0);
    assert_eq!(flags(&unknown, &slow), [true]);
    // The same slow turn cut off for fewer readings than the long run, at 69.9 deg/s:
    // not told from a steady peak (it loses 0.0004°).
    let barely = triangle(20.0, 70.0, 69.9);
    let run = barely
        .iter()
        .filter(|&&r| r == barely[0].max(69.875))
        .count();
    assert!(
        (run as f64) < f64::from(gyro_core::CLIP_PLATEAU_LONG_S) * FS_HZ,
        "{run}"
    );
    assert_eq!(flags(&unknown, &barely), [false]);
}

/// The long plateau is a time: 128 readings at 1 kHz, every plateau (16 readings) below
/// 125 Hz, 1024 at 8 kHz, and the run counter's 65 535 only above 512 kHz.
#[test]
fn the_long_plateau_is_a_time() {
    let long = |sample_rate_hz: f32| {
        let config = Config {
            sample_rate_hz,
            ..Config::default()
        };
        Pipeline::try_new(&config)
            .expect("config")
            .clip_plateau_long_samples()
    };
    assert_eq!(long(1000.0), 128);
    assert_eq!(long(500.0), 64);
    assert_eq!(long(100.0), u16::from(CLIP_PLATEAU_SAMPLES));
    assert_eq!(long(8000.0), 1024);
    assert_eq!(long(1.0e6), u16::MAX);
}

/// At 8 kHz the plateaus last what they last at 1 kHz: 16 ms (128 readings) and, whatever
/// the filtered rate, 128 ms (1024). A reading held 100 ms at the top of a smooth turn is
/// not a clip (16 readings, 2 ms, on its slope stand beyond the filtered rate); a turn
/// clipped steeply for 20 ms, or slowly for a second, is.
#[test]
fn the_long_plateau_holds_at_8_khz() {
    const FS_8K_HZ: f64 = 8000.0;
    let config = Config {
        sample_rate_hz: FS_8K_HZ as f32,
        range_dps: None,
        ..Config::default()
    };
    let flags_8k = |samples: &[f32]| -> Vec<bool> {
        run(&config, samples, FS_8K_HZ)
            .movements
            .iter()
            .map(|(_, m)| m.saturated)
            .collect()
    };
    let quantised = |rate: f64| ((rate / LSB_DPS).round() * LSB_DPS) as f32;
    // Eases into 60 deg/s over 1 s, holds it 100 ms, eases out.
    let ease = |t: f64| 30.0 * (1.0 - (std::f64::consts::PI * t.clamp(0.0, 1.0)).cos());
    let hold_s = 0.1;
    let n = (6.1 * FS_8K_HZ) as usize;
    let steady: Vec<f32> = (0..n)
        .map(|i| {
            let t = i as f64 / FS_8K_HZ - 2.0;
            quantised(ease(t).min(ease(2.0 + hold_s - t)))
        })
        .collect();
    let top = steady.iter().filter(|&&r| r == 60.0).count();
    assert!((800..1024).contains(&top), "{top}");
    assert_eq!(flags_8k(&steady), [false]);

    // Rises at `slope` deg/s per s to 70, cut off at 60: steeply (1000 deg/s per s, 20 ms
    // on the clip, reached far ahead of the filtered rate) and slowly (a second).
    let cut = |slope_dps_per_s: f64| -> Vec<f32> {
        let rise_s = 70.0 / slope_dps_per_s;
        let n = ((4.0 + 2.0 * rise_s) * FS_8K_HZ) as usize;
        (0..n)
            .map(|i| {
                let t = i as f64 / FS_8K_HZ - 2.0;
                quantised((70.0 - slope_dps_per_s * (t - rise_s).abs()).max(0.0)).min(60.0)
            })
            .collect()
    };
    assert_eq!(flags_8k(&cut(1000.0)), [true]);
    assert_eq!(flags_8k(&cut(20.0)), [true]);
}

/// The short plateau is a time above 1 kHz: 16 readings up to 1 kHz, 128 at 8 kHz.
#[test]
fn the_short_plateau_is_a_time_above_1_khz() {
    let short = |sample_rate_hz: f32| {
        let config = Config {
            sample_rate_hz,
            ..Config::default()
        };
        Pipeline::try_new(&config)
            .expect("config")
            .clip_plateau_samples()
    };
    assert_eq!(short(100.0), u16::from(CLIP_PLATEAU_SAMPLES));
    assert_eq!(short(1000.0), u16::from(CLIP_PLATEAU_SAMPLES));
    assert_eq!(short(2000.0), 32);
    assert_eq!(short(8000.0), 128);
}
