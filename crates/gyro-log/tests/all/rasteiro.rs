//! The rasteiro recordings (../shared/data/real/rasteiro beside the workspace, when
//! present): rows stamped on arrival at a PC, in bursts. They are recognised as such, and
//! the grid keeps the integral of the rate the stamps say.
#![allow(clippy::unwrap_used)] // test code: a failed unwrap is a failed test

use gyro_log::{load, read_log, GridOptions, LogOptions};
use std::path::PathBuf;

fn recordings() -> Vec<PathBuf> {
    gyro_log::real_data::csv_files("rasteiro")
}

/// `path` on the grid, with the default options.
fn placed(path: &std::path::Path) -> gyro_log::RegularLog {
    load(
        path,
        &LogOptions::default(),
        &GridOptions::default(),
        &mut |_| {},
    )
    .unwrap()
}

#[test]
fn bursts_are_recognised_and_the_integral_is_kept() {
    for path in recordings() {
        let raw = read_log(&path, &LogOptions::default()).unwrap();
        let placed = placed(&path);
        let bursts = placed
            .quality
            .bursts
            .unwrap_or_else(|| panic!("{}: not bursts", path.display()));
        assert!(
            bursts.off_grid_share > 0.5,
            "{}: {bursts:?}",
            path.display()
        );
        assert_eq!(placed.quality.sample_rate_source, "mean_step");
        // About 100 Hz sensors, 101-111 rows per second.
        assert!(
            (95.0..120.0).contains(&placed.sample_rate_hz),
            "{}",
            placed.sample_rate_hz
        );
        // The integral on the grid is the trapezoid on the stamps up to the last grid time,
        // where no backlog was re-timed (one file has them: below).
        if placed.quality.backlogs > 0 {
            continue;
        }
        let end_s = placed.slots.last().unwrap().time_s;
        let mut on_stamps = 0.0;
        for w in raw.rows.windows(2) {
            let (a, b) = (&w[0], &w[1]);
            let (ra, rb) = (a.rate_dps.unwrap(), b.rate_dps.unwrap());
            let until = b.time_s.min(end_s);
            if until > a.time_s {
                let r_until = ra + (rb - ra) * (until - a.time_s) / (b.time_s - a.time_s);
                on_stamps += 0.5 * (ra + r_until) * (until - a.time_s);
            }
        }
        let period_s = 1.0 / placed.sample_rate_hz;
        let on_grid: f64 = placed.slots[1..]
            .iter()
            .map(|s| s.rate_dps * period_s)
            .sum();
        assert!(
            (on_grid - on_stamps).abs() < 1e-6 * (1.0 + on_stamps.abs()),
            "{}: {on_grid} on the grid, {on_stamps} on the stamps",
            path.display()
        );
        // One slot per period of the stamps' span: no time invented.
        let span_s = raw.rows.last().unwrap().time_s - raw.rows[0].time_s;
        let expected = span_s * placed.sample_rate_hz;
        assert!(
            (placed.slots.len() as f64 - expected).abs() < 2.0,
            "{} slots, {expected}",
            placed.slots.len()
        );
    }
}

/// The MPU6500 recordings at V_300 stall for 0.17 s during a −180° z turn at 450 °/s, and
/// the 24 rows after the stall arrive 4 ms apart until the count catches up: the stall's
/// samples, buffered. Bridged as a gap, the stall's 76° would count twice (the gap's
/// trapezoid, then the backlog's rows); re-timed, the turn comes out right.
#[test]
fn a_stalled_link_s_backlog_is_re_timed_not_counted_twice() {
    for path in recordings() {
        let placed = placed(&path);
        let q = &placed.quality;
        let name = path.file_name().unwrap().to_string_lossy().into_owned();
        if !name.starts_with("rasteiro_MPU6500RM3100_V_300_") {
            // The other files' gaps are lost samples (or too early in a log to tell).
            assert_eq!(q.backlogs, 0, "{name}: {q:?}");
            continue;
        }
        // The 41 ms gap at 3.6 s (5 rows) and the 0.17 s stall at 11.1 s (24 rows).
        assert_eq!((q.backlogs, q.retimed_rows), (2, 29), "{name}: {q:?}");
        if name.ends_with("_z.csv") {
            // The −180° turn, from rest (10.5 s) to rest (12.5 s), bias removed.
            let period_s = 1.0 / placed.sample_rate_hz;
            let mean = |a: f64, b: f64| {
                let r: Vec<f64> = placed
                    .slots
                    .iter()
                    .filter(|s| (a..b).contains(&s.time_s))
                    .map(|s| s.rate_dps)
                    .collect();
                r.iter().sum::<f64>() / r.len() as f64
            };
            let bias_dps = mean(8.0, 8.8);
            let turn_deg: f64 = placed
                .slots
                .iter()
                .filter(|s| (10.0..12.8).contains(&s.time_s))
                .map(|s| (s.rate_dps - bias_dps) * period_s)
                .sum();
            assert!((turn_deg + 180.0).abs() < 4.0, "{name}: {turn_deg}");
        }
    }
}

/// The robot's pose wraps and flips while the board is still: every recording has such
/// jumps, and after they are re-based the reference ends where the gyro says (within the
/// sensors' own error, a few degrees over the whole path; as logged, the end is off by
/// 320-720 degrees on 10 of the 18 files, and jumps that cancel leave the others' middles
/// off).
#[test]
fn reference_jumps_are_re_based() {
    for path in recordings() {
        let placed = placed(&path);
        let q = &placed.quality;
        assert!(
            (1..=3).contains(&q.reference_jumps),
            "{}: {q:?}",
            path.display()
        );
        assert!(q.warnings.iter().any(|w| w.contains("reference jumps")));
        let period_s = 1.0 / placed.sample_rate_hz;
        let gyro_deg: f64 = placed.slots[1..]
            .iter()
            .map(|s| s.rate_dps * period_s)
            .sum();
        let first = placed.slots.iter().find_map(|s| s.reference_deg).unwrap();
        let last = placed
            .slots
            .iter()
            .rev()
            .find_map(|s| s.reference_deg)
            .unwrap();
        let off = (gyro_deg - (last - first)).abs();
        assert!(off < 10.0, "{}: {off} deg", path.display());
    }
}

/// On the z recordings the robot turns the board +180 deg and back; its pose wraps at the
/// far end while the gyro, 80-120 ms behind, still turns. Re-based by whole turns, the
/// reference reaches 180 deg and comes back to where it began.
#[test]
fn a_wrap_during_a_turn_keeps_the_pose_s_own_angle() {
    for path in recordings()
        .into_iter()
        .filter(|p| p.to_string_lossy().ends_with("_z.csv"))
    {
        let placed = placed(&path);
        let reference: Vec<f64> = placed
            .slots
            .iter()
            .filter_map(|s| s.reference_deg)
            .collect();
        let (first, last) = (reference[0], reference[reference.len() - 1]);
        let top = reference.iter().copied().fold(f64::MIN, f64::max);
        assert!(
            (last - first).abs() < 0.1,
            "{}: {first} -> {last}",
            path.display()
        );
        assert!(
            (top - first - 180.0).abs() < 1.0,
            "{}: top {top}",
            path.display()
        );
    }
}

/// The same recordings as other loggers would stamp them: packets of four rows stamped on
/// the last one's arrival, and stamps rounded to 10 ms (steps of 0, 10 and 20 ms, every
/// positive one on the grid). Rows sharing a stamp make the log bursty (a row per slot
/// would stretch time by 18% to 300%), and the angle follows the recording's own to within
/// 3° (0.1–2.1°), once the shift the coarser stamps make is allowed for (the backlog files
/// aside: their stall's rows, once stamped alike, no longer show it).
#[test]
fn rows_sharing_a_stamp_keep_the_recording_s_angle() {
    let cumulative = |log: &gyro_log::RegularLog| -> (Vec<f64>, Vec<f64>) {
        let period_s = 1.0 / log.sample_rate_hz;
        let mut angle_deg = 0.0;
        let angles = log
            .slots
            .iter()
            .enumerate()
            .map(|(k, s)| {
                if k > 0 {
                    angle_deg += s.rate_dps * period_s;
                }
                angle_deg
            })
            .collect();
        (log.slots.iter().map(|s| s.time_s).collect(), angles)
    };
    let at = |(times, angles): &(Vec<f64>, Vec<f64>), t: f64| -> f64 {
        let k = times.partition_point(|&x| x < t).clamp(1, times.len() - 1);
        let w = ((t - times[k - 1]) / (times[k] - times[k - 1])).clamp(0.0, 1.0);
        angles[k - 1] + w * (angles[k] - angles[k - 1])
    };
    let mut checked = 0;
    for path in recordings() {
        let raw = read_log(&path, &LogOptions::default()).unwrap();
        let original = gyro_log::regularize(&raw, &GridOptions::default()).unwrap();
        if original.quality.backlogs > 0 {
            continue;
        }
        let reference = cumulative(&original);
        let n = raw.rows.len();
        type Stamp<'a> = Box<dyn Fn(usize, f64) -> f64 + 'a>;
        let stampings: [(&str, Stamp); 2] = [
            (
                "packets of four",
                Box::new(|k, _| raw.rows[(k / 4 * 4 + 3).min(n - 1)].time_s),
            ),
            ("10 ms", Box::new(|_, t| (t / 0.01).round() * 0.01)),
        ];
        for (what, stamp) in &stampings {
            let mut log = raw.clone();
            for (k, row) in log.rows.iter_mut().enumerate() {
                row.time_s = stamp(k, row.time_s);
            }
            let placed = gyro_log::regularize(&log, &GridOptions::default()).unwrap();
            let name = format!("{} stamped in {what}", path.display());
            let b = placed
                .quality
                .bursts
                .unwrap_or_else(|| panic!("{name}: not bursts"));
            assert!(b.repeated_stamp_share > 0.1, "{name}: {b:?}");
            let (times, angles) = cumulative(&placed);
            // Against the recording's angle over the 50 ms around each time (packets hold
            // rows back by up to three periods, rounding moves them by 5 ms).
            let worst = times
                .iter()
                .zip(&angles)
                .map(|(&t, &a)| {
                    let around = [-0.05, -0.025, 0.0, 0.025, 0.05].map(|d| at(&reference, t + d));
                    let lo = around.iter().copied().fold(f64::INFINITY, f64::min);
                    let hi = around.iter().copied().fold(f64::NEG_INFINITY, f64::max);
                    (lo - a).max(a - hi).max(0.0)
                })
                .fold(0.0, f64::max);
            assert!(worst < 3.0, "{name}: {worst} deg off the recording's angle");
            // One slot per period of the stamps' span: no time invented.
            let span_s = log.rows[n - 1].time_s - log.rows[0].time_s;
            let expected = span_s * placed.sample_rate_hz;
            assert!(
                (placed.slots.len() as f64 - expected).abs() < 2.0,
                "{name}: {} slots, {expected}",
                placed.slots.len()
            );
            checked += 1;
        }
    }
    if checked > 0 {
        assert!(checked >= 30, "{checked}");
    }
}

/// The pose follows the gyro on every recording (the correlation of their turns over
/// 0.5 s blocks 0.89–0.99, the pose's turn per degree of the gyro's 0.77–1.19); negated,
/// as an encoder wired the other way would give it, it is found turning against the gyro,
/// and with the rate in rad/s read as deg/s, turning 57 times as far; both are warned of.
#[test]
fn a_reference_of_the_opposite_sense_or_other_units_is_warned_of() {
    for path in recordings() {
        let name = path.display().to_string();
        let raw = read_log(&path, &LogOptions::default()).unwrap();
        let placed = gyro_log::regularize(&raw, &GridOptions::default()).unwrap();
        let c = placed.quality.reference_correlation.unwrap();
        assert!(c > 0.85, "{name}: {c}");
        let gain = placed.quality.reference_gain.unwrap();
        assert!((0.7..1.3).contains(&gain), "{name}: {gain}");
        assert!(
            !placed
                .quality
                .warnings
                .iter()
                .any(|w| w.contains("against") || w.contains("times as far")),
            "{name}"
        );
        // The rate in rad/s, read as deg/s.
        let mut radians = raw.clone();
        for row in &mut radians.rows {
            row.rate_dps = row.rate_dps.map(f64::to_radians);
        }
        let placed = gyro_log::regularize(&radians, &GridOptions::default()).unwrap();
        let gain = placed.quality.reference_gain.unwrap();
        assert!((40.0..80.0).contains(&gain), "{name} in rad/s: {gain}");
        assert!(
            placed
                .quality
                .warnings
                .iter()
                .any(|w| w.contains("--rate-unit rads")),
            "{name} in rad/s: {:?}",
            placed.quality.warnings
        );
        let mut negated = raw.clone();
        for row in &mut negated.rows {
            row.reference_deg = row.reference_deg.map(|r| -r);
        }
        let placed = gyro_log::regularize(&negated, &GridOptions::default()).unwrap();
        let c = placed.quality.reference_correlation.unwrap();
        assert!(c < -0.85, "{name} negated: {c}");
        assert!(
            placed
                .quality
                .warnings
                .iter()
                .any(|w| w.contains("the reference turns against the gyro")),
            "{name} negated: {:?}",
            placed.quality.warnings
        );
    }
}

/// The recordings stamped by a tick counter that wraps mid-log, as small loggers stamp:
/// Arduino's 32-bit `micros()` (read in seconds, wrapping at 4294.967296 s) and a 16-bit
/// millisecond tick (wrapping at 65.536 s). Unwrapped, every slot is that of the same
/// stamps without the wrap; not unwrapped, the logs were refused (time goes back).
#[test]
fn a_counter_that_wraps_mid_log_is_unwrapped() {
    let mut checked = 0;
    for path in recordings() {
        let raw = read_log(&path, &LogOptions::default()).unwrap();
        // (span, tick): the counter wraps 8 s into the log.
        for (span_s, tick_s) in [(4_294.967_296, 1e-6), (65.536, 1e-3)] {
            let name = format!("{} as a counter of {span_s} s", path.display());
            let count = |t: f64| ((t + span_s - 8.0) / tick_s).round() * tick_s;
            let mut unwrapped = raw.clone();
            let mut wrapped = raw.clone();
            for (u, w) in unwrapped.rows.iter_mut().zip(wrapped.rows.iter_mut()) {
                u.time_s = count(u.time_s);
                w.time_s = u.time_s.rem_euclid(span_s);
            }
            let expected = gyro_log::regularize(&unwrapped, &GridOptions::default()).unwrap();
            let placed = gyro_log::regularize(&wrapped, &GridOptions::default())
                .unwrap_or_else(|e| panic!("{name}: {e}"));
            let q = &placed.quality;
            assert_eq!(
                (q.counter_wraps, q.counter_span_s),
                (1, Some(span_s)),
                "{name}"
            );
            assert!(
                q.examples
                    .iter()
                    .any(|(what, _)| what.contains("time stamps wrap")),
                "{name}: {:?}",
                q.examples
            );
            assert_eq!(placed.slots.len(), expected.slots.len(), "{name}");
            for (a, b) in placed.slots.iter().zip(&expected.slots) {
                assert!((a.time_s - b.time_s).abs() < 1e-9, "{name}: {a:?} {b:?}");
                assert!(
                    (a.rate_dps - b.rate_dps).abs() < 1e-6,
                    "{name}: {a:?} {b:?}"
                );
            }
            checked += 1;
        }
    }
    if checked > 0 {
        assert_eq!(checked, 36);
    }
}
