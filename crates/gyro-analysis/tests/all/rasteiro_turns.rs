//! The angle of each turn on the rasteiro recordings (../shared/data/real/rasteiro beside
//! the workspace, when present: IMUs turned by a robot, rest–turn–rest, rows stamped on
//! arrival at a PC in bursts), rest to rest, against the robot's pose: the replay with the
//! default configuration (what `gyro-cli run` does) beside the plain per-rest estimator
//! (trapezoid on the logged stamps minus the mean rate of the rest before), per sensor and
//! speed. The oracle is `scripts/rasteiro_turns.py` step for step (its constants, its rests,
//! its truth), so that the README's table is held here too.
#![allow(clippy::unwrap_used)] // test code: a failed unwrap is a failed test

use gyro_analysis::replay::replay;
use gyro_core::Config;
use gyro_log::{load, read_log, GridOptions, LogOptions};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// A turn counts when the pose and the plain estimate both change by more than this (deg).
const MIN_TURN_DEG: f64 = 20.0;
/// A rest lasts at least this long (s).
const REST_MIN_S: f64 = 0.6;
/// Over every window this long (s) within a rest...
const REST_WINDOW_S: f64 = 0.2;
/// ...the gyro's rate spans less than this (deg/s)...
const REST_RATE_SPREAD_DPS: f64 = 2.0;
/// ...and 60% of the pose samples agree to this (deg, modulo 360).
const REST_TOLERANCE_DEG: f64 = 0.05;
/// Rest means use the rest less this much (s) at each end (the gyro lags the pose).
const TRIM_S: f64 = 0.25;

/// A turn: its truth, the plain estimator's error and the replay's (deg).
type Turn = (f64, f64, f64);

fn recordings() -> Vec<PathBuf> {
    gyro_log::real_data::csv_files("rasteiro")
}

/// Angles folded into [−180, 180).
fn wrapped(deg: f64) -> f64 {
    (deg + 180.0).rem_euclid(360.0) - 180.0
}

/// First index whose time is at least `t` (numpy's `searchsorted`, side left).
fn search(times_s: &[f64], t: f64) -> usize {
    times_s.partition_point(|&x| x < t)
}

/// How many of `values` agree with each of them to the tolerance, modulo 360.
fn agreeing(values: &[f64]) -> Vec<usize> {
    values
        .iter()
        .map(|&v| {
            values
                .iter()
                .filter(|&&x| wrapped(x - v).abs() < REST_TOLERANCE_DEG)
                .count()
        })
        .collect()
}

/// At least 60% of `values` agree to the tolerance.
fn held(values: &[f64]) -> bool {
    agreeing(values).into_iter().max().unwrap_or(0) as f64 >= 0.6 * values.len() as f64
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    }
}

/// numpy's `percentile` (linear between order statistics).
fn percentile(mut v: Vec<f64>, q: f64) -> f64 {
    v.sort_by(f64::total_cmp);
    let at = q / 100.0 * (v.len() - 1) as f64;
    let (lo, frac) = (at.floor() as usize, at - at.floor());
    if lo + 1 < v.len() {
        v[lo] + frac * (v[lo + 1] - v[lo])
    } else {
        v[lo]
    }
}

/// The pose over a rest: the value (modulo 360) most of its samples hold, when at least
/// half of them do.
fn rest_angle(reference: &[f64]) -> Option<f64> {
    let held = agreeing(reference);
    let best = (0..held.len()).fold(0, |b, i| if held[i] > held[b] { i } else { b });
    if (held[best] as f64) < 0.5 * reference.len() as f64 {
        return None;
    }
    let v = reference[best];
    let near: Vec<f64> = reference
        .iter()
        .map(|&x| wrapped(x - v))
        .filter(|d| d.abs() < REST_TOLERANCE_DEG)
        .collect();
    Some(v + median(near))
}

/// The rests: (first, last) index pairs.
fn rests(t: &[f64], w: &[f64], reference: &[f64]) -> Vec<(usize, usize)> {
    let n = t.len();
    let mut still = vec![false; n];
    let mut j = 0;
    for i in 0..n {
        while t[j] < t[i] - REST_WINDOW_S {
            j += 1;
        }
        let rates = &w[j..=i];
        let spread = rates.iter().copied().fold(f64::NEG_INFINITY, f64::max)
            - rates.iter().copied().fold(f64::INFINITY, f64::min);
        still[i] = spread < REST_RATE_SPREAD_DPS && held(&reference[j..=i]);
    }
    let (mut out, mut i) = (Vec::new(), 0);
    while i < n {
        if !still[i] {
            i += 1;
            continue;
        }
        // A still window ending at i means the rest began a window earlier.
        let start = search(t, t[i] - REST_WINDOW_S);
        let mut k = i;
        while k < n && still[k] {
            k += 1;
        }
        if t[k - 1] - t[start] >= REST_MIN_S {
            out.push((start, k - 1));
        }
        i = k;
    }
    out
}

/// The central part of rest `(a, b)`: indices `lo..hi`.
fn central(t: &[f64], (a, b): (usize, usize)) -> (usize, usize) {
    let lo = search(t, t[a] + TRIM_S);
    let hi = search(t, t[b] - TRIM_S);
    (lo, hi.max(lo + 1))
}

/// The plain estimator from `t0` to `t1`.
fn plain(t: &[f64], w: &[f64], before: (usize, usize), t0: f64, t1: f64) -> f64 {
    let (lo, hi) = central(t, before);
    let bias = w[lo..hi].iter().sum::<f64>() / (hi - lo) as f64;
    let (k0, k1) = (search(t, t0), (search(t, t1) + 1).min(t.len()));
    let (st, sw) = (&t[k0..k1], &w[k0..k1]);
    let integral: f64 = (1..st.len())
        .map(|i| 0.5 * (sw[i] + sw[i - 1]) * (st[i] - st[i - 1]))
        .sum();
    integral - bias * (st[st.len() - 1] - st[0])
}

/// numpy's `interp`: linear, held at the ends.
fn interp(x: f64, xs: &[f64], ys: &[f64]) -> f64 {
    let i = xs.partition_point(|&v| v <= x);
    if i == 0 {
        ys[0]
    } else if i == xs.len() {
        ys[xs.len() - 1]
    } else {
        let f = (x - xs[i - 1]) / (xs[i] - xs[i - 1]);
        ys[i - 1] + f * (ys[i] - ys[i - 1])
    }
}

/// The turns of `path`.
fn turns(path: &Path) -> Vec<Turn> {
    let log = read_log(path, &LogOptions::default()).unwrap();
    let rows: Vec<(f64, f64, f64)> = log
        .rows
        .iter()
        .filter_map(|r| Some((r.time_s, r.rate_dps?, r.reference_deg?)))
        .collect();
    assert_eq!(rows.len(), log.rows.len(), "{}", path.display());
    let t: Vec<f64> = rows.iter().map(|r| r.0).collect();
    let w: Vec<f64> = rows.iter().map(|r| r.1).collect();
    let reference: Vec<f64> = rows.iter().map(|r| r.2).collect();

    let regular = load(
        path,
        &LogOptions::default(),
        &GridOptions::default(),
        &mut |_| {},
    )
    .unwrap();
    let series = replay(&regular, &Config::default()).unwrap().series;
    let st: Vec<f64> = series.iter().map(|p| p.time_s).collect();
    let sa: Vec<f64> = series.iter().map(|p| f64::from(p.angle_deg)).collect();

    let found = rests(&t, &w, &reference);
    let mut out = Vec::new();
    for pair in found.windows(2) {
        let (before, after) = (pair[0], pair[1]);
        let (lo, hi) = central(&t, before);
        let (lo2, hi2) = central(&t, after);
        let (Some(r0), Some(r1)) = (
            rest_angle(&reference[lo..hi]),
            rest_angle(&reference[lo2..hi2]),
        ) else {
            continue;
        };
        let t0 = 0.5 * (t[before.0] + t[before.1]);
        let t1 = 0.5 * (t[after.0] + t[after.1]);
        let p = plain(&t, &w, before, t0, t1);
        // The pose wraps by whole turns in places: the multiple of 360 the gyro agrees with.
        let truth = r1 - r0 + 360.0 * ((p - (r1 - r0)) / 360.0).round_ties_even();
        if truth.abs() < MIN_TURN_DEG || p.abs() < MIN_TURN_DEG {
            continue;
        }
        let r = interp(t1, &st, &sa) - interp(t0, &st, &sa);
        out.push((truth, p - truth, r - truth));
    }
    out
}

#[test]
fn run_is_as_good_as_the_plain_estimator_turn_by_turn() {
    // (sensor, speed) → turns.
    let mut groups: BTreeMap<(String, String), Vec<Turn>> = BTreeMap::new();
    for path in recordings() {
        let name = path.file_stem().unwrap().to_string_lossy().into_owned();
        let name = name.trim_start_matches("rasteiro_");
        let (sensor, rest) = name.split_once("RM3100_").unwrap();
        let speed = rest.rsplit_once('_').unwrap().0;
        groups
            .entry((sensor.to_string(), speed.to_string()))
            .or_default()
            .extend(turns(&path));
    }
    if groups.is_empty() {
        return;
    }
    let summary = |found: &[Turn]| {
        let plain: Vec<f64> = found.iter().map(|f| f.1.abs()).collect();
        let run: Vec<f64> = found.iter().map(|f| f.2.abs()).collect();
        (
            median(plain.clone()),
            percentile(plain, 90.0),
            median(run.clone()),
            percentile(run, 90.0),
        )
    };
    let mut sensors: BTreeMap<String, Vec<Turn>> = BTreeMap::new();
    for ((sensor, speed), found) in &groups {
        let (pm, p90, rm, r90) = summary(found);
        println!(
            "{sensor} {speed}: {} turns, plain {pm:.2} ({p90:.2}), run {rm:.2} ({r90:.2}), \
             run / plain {:.2}",
            found.len(),
            rm / pm
        );
        assert_eq!(found.len(), 7, "{sensor} {speed}");
        // On 7 turns whose errors are the sensor's scale, common to both: within 5%.
        assert!(rm <= 1.05 * pm, "{sensor} {speed}: {rm} against {pm}");
        sensors
            .entry(sensor.clone())
            .or_default()
            .extend(found.iter().copied());
    }
    for (sensor, found) in &sensors {
        let (pm, p90, rm, r90) = summary(found);
        println!(
            "{sensor} all: {} turns, plain {pm:.2} ({p90:.2}), run {rm:.2} ({r90:.2}), run / \
             plain {:.2}",
            found.len(),
            rm / pm
        );
        // Per sensor, over its three speeds: at least as good in the median, and the
        // 90th percentile within 1%.
        assert!(rm <= pm, "{sensor}: {rm} against {pm}");
        assert!(r90 <= 1.01 * p90, "{sensor}: {r90} against {p90}");
    }
}
