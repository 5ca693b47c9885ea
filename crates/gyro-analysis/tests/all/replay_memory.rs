//! The replayer holds a bounded number of recent outputs, whatever the log's length, and
//! still reads every movement's ends as the whole series would: a movement longer than
//! what is held, filled slots, a stretch without reference and a log that ends while
//! moving, checked against the rules applied to the whole series here.
#![allow(clippy::unwrap_used)] // test code: a failed unwrap is a failed test

use gyro_analysis::replay::{ReplayOptions, Replayer, SeriesPoint};
use gyro_core::Config;
use gyro_log::{Quality, Slot};

const RATE_HZ: f64 = 100.0;

/// Rate (deg/s) at `t`: a rest, a 1500 s slow turn that never rests, a rest, short turns
/// 2 s long with 5 s rests between, the last one cut off by the end of the log.
fn rate_dps(t: f64) -> f64 {
    let bias = 0.1;
    let wobble = 0.01 * (t * 7.3).sin();
    let moving = if (10.0..1510.0).contains(&t) {
        5.0 + 2.0 * (t * 0.05).sin()
    } else if t >= 1530.0 {
        let phase = (t - 1530.0) % 7.0;
        if phase < 2.0 {
            45.0 * (1.0 - (std::f64::consts::PI * phase).cos())
        } else {
            0.0
        }
    } else {
        0.0
    };
    bias + wobble + moving
}

/// The whole-series rule: the output nearest `time_s` (the earlier on a tie).
fn nearest(series: &[SeriesPoint], time_s: f64) -> usize {
    let i = series.partition_point(|p| p.time_s < time_s);
    if i == 0 {
        return 0;
    }
    if i >= series.len() {
        return series.len() - 1;
    }
    if (series[i].time_s - time_s).abs() < (time_s - series[i - 1].time_s).abs() {
        i
    } else {
        i - 1
    }
}

#[test]
fn held_outputs_are_bounded_and_movements_read_as_from_the_whole_series() {
    let end_s = 1530.0 + 10.0 * 7.0 + 1.0; // ends 1 s into a turn
    let slots = (end_s * RATE_HZ) as usize;
    let mut replayer = Replayer::new(
        RATE_HZ,
        &Config::default(),
        &ReplayOptions::default(),
        false,
    )
    .unwrap();
    let (mut series, mut filled_before) = (Vec::new(), Vec::new());
    let (mut angle_deg, mut filled, mut most_held) = (0.0, 0_u32, 0);
    for i in 0..slots {
        let time_s = i as f64 / RATE_HZ;
        let rate = rate_dps(time_s);
        angle_deg += (rate - 0.1) / RATE_HZ;
        // Filled slots early in the long turn and in its middle; no reference for 3 s of
        // the last rest.
        let is_filled = (2000..2003).contains(&i) || (90_000..90_010).contains(&i);
        filled += u32::from(is_filled);
        let slot = Slot {
            time_s,
            rate_dps: rate,
            reference_deg: (!(1512.0..1515.0).contains(&time_s)).then_some(angle_deg),
            temperature_c: None,
            line: i as u64 + 2,
            filled: is_filled,
        };
        if let Some(point) = replayer.push(&slot) {
            series.push(point);
            filled_before.push(filled);
        }
        most_held = most_held.max(replayer.held_outputs());
    }
    let bound = replayer.max_held_outputs();
    assert!(most_held <= bound, "{most_held} > {bound}");
    assert!(
        series.len() > bound,
        "the test must outlast what is held: {bound} held, {} outputs",
        series.len()
    );
    let report = replayer.finish(Quality::default());
    assert!(report.series.is_empty());

    let long = &report.movements[0];
    assert!(
        long.samples.1 - long.samples.0 > bound,
        "the first movement must be longer than what is held: {long:?}"
    );
    assert!(long.complete && long.filled_samples == 13, "{long:?}");
    assert!(report.movements.len() >= 10, "{}", report.movements.len());
    let last = report.movements.last().unwrap();
    assert!(!last.complete, "{last:?}");
    for m in &report.movements {
        let (start, end) = m.samples;
        let at = (
            nearest(&series, m.start_time_s),
            nearest(&series, m.end_time_s),
        );
        let reference = match (series[at.0].reference_deg, series[at.1].reference_deg) {
            (Some(a), Some(b)) => Some(b - a),
            _ => None,
        };
        assert_eq!(m.reference_deg, reference, "{m:?}");
        assert_eq!(m.filled_samples, filled_before[end] - filled_before[start]);
        if !m.complete {
            assert_eq!(end, series.len() - 1);
            assert_eq!(m.angle_deg, series[end].angle_deg - series[start].angle_deg);
        }
    }
    let errors: Vec<f64> = series.iter().filter_map(SeriesPoint::error_deg).collect();
    let rms = (errors.iter().map(|e| e * e).sum::<f64>() / errors.len() as f64).sqrt();
    assert_eq!(report.summary.outputs, series.len());
    assert_eq!(report.summary.rms_error_deg, Some(rms));
    assert_eq!(report.summary.final_error_deg, errors.last().copied());
    assert_eq!(
        report.summary.duration_s,
        series.last().unwrap().time_s - series[0].time_s
    );
}
