//! `diagnose` on a real sensor (the ssong yaw recordings, ../shared/data/real beside the
//! workspace, when present): trained on the slow trial, held out on the medium one (another
//! speed). The gyro lags its encoder by about 12 ms (the plain estimate of
//! `scripts/ssong_plain.py`: 12.0 ms slow, 12.1 ms medium); a two-pole bandwidth fitted to
//! the same signature puts the cross-correlation peak at more than twice that, so it must
//! fail its posterior check and the latency be named; the scale must be the plain
//! regression's (+0.60%), no bias wander must pass, and the written model must not make
//! the held-out angles worse. A few 50 s windows and small ensembles keep it quick; the
//! README's figures come from the full recordings.
#![allow(clippy::unwrap_used)] // test code: a failed unwrap is a failed test

#[path = "../../../gyro-analysis/tests/all/common/mod.rs"]
mod common;

use common::real_log;
use gyro_diagnose::{diagnose, split, Options, RealRun, Silent};
use gyro_log::GridOptions;

/// Small ensembles and `bootstrap` resamples: quick enough for a test.
fn quick(bootstrap: usize) -> Options {
    Options {
        members: 8,
        candidate_members: 4,
        bootstrap,
        ..Options::default()
    }
}

/// A real recording placed on a 100 Hz grid (the rasteiro sensors' nominal rate), or
/// `None` when the recordings are not beside the workspace.
fn load_at_100(name: String) -> Option<RealRun> {
    let grid = GridOptions {
        sample_rate_hz: Some(100.0),
        ..GridOptions::default()
    };
    let log = real_log(&name, &grid)?;
    Some(RealRun::prepare(name, log).unwrap())
}

/// The rasteiro x recordings of both boards: at the speeds `train`, and at `holdout`;
/// `None` when they are not beside the workspace.
fn rasteiro_x(train: [&str; 2], holdout: &str) -> Option<(Vec<RealRun>, Vec<RealRun>)> {
    let file =
        |sensor: &str, speed: &str| format!("rasteiro/rasteiro_{sensor}RM3100_{speed}_x.csv");
    let boards = ["MPU6050", "MPU6500"];
    let train = boards
        .iter()
        .flat_map(|b| train.map(|v| file(b, v)))
        .map(load_at_100)
        .collect::<Option<Vec<_>>>()?;
    let holdout = boards
        .iter()
        .map(|b| load_at_100(file(b, holdout)))
        .collect::<Option<Vec<_>>>()?;
    Some((train, holdout))
}

fn windows(file: &str, take: usize) -> Option<Vec<RealRun>> {
    let log = real_log(file, &GridOptions::default())?;
    Some(
        split(&log, 50.0)
            .into_iter()
            .take(take)
            .enumerate()
            .map(|(i, w)| RealRun::prepare(format!("{file}#{}", i + 1), w).unwrap())
            .collect(),
    )
}

#[test]
fn latency_is_named_on_real_yaw_and_its_correction_does_not_hurt() {
    let (Some(train), Some(holdout)) = (
        windows("ssong_z_slow.csv", 4),
        windows("ssong_z_medium.csv", 4),
    ) else {
        return;
    };
    let d = diagnose(&train, &holdout, &quick(300), &Silent).unwrap();
    let named: Vec<&str> = d.verdict.unmodelled.clone();
    assert!(named.contains(&"latency"), "named {named:?}");
    assert!(!named.contains(&"bandwidth"), "named {named:?}");
    let latency = d.effects.iter().find(|e| e.id == "latency").unwrap();
    let delay_ms = latency.params["delay_s"] * 1e3;
    assert!((9.0..15.0).contains(&delay_ms), "{delay_ms} ms");
    let check = latency.posterior_check.as_ref().unwrap();
    assert!(check.passes && !check.statistics.is_empty(), "{check:?}");
    if let Some(bw) = d.effects.iter().find(|e| e.id == "bandwidth") {
        if let Some(c) = &bw.posterior_check {
            assert!(c.statistics.is_empty() || !c.passes || !bw.significant);
        }
    }
    // What is written lowers the held-out error; what would not is named, not corrected.
    let c = d.compensation.as_ref().unwrap();
    let total =
        |f: &dyn Fn(&gyro_diagnose::CompensationRun) -> f64| -> f64 { c.runs.iter().map(f).sum() };
    let before = total(&|r| r.max_abs_error_before_deg);
    let after = total(&|r| r.max_abs_error_after_deg);
    assert!(after <= before, "{before} -> {after}");
    assert!(c.corrected.contains(&"latency"), "{:?}", c.corrected);
    for n in &c.not_corrected {
        assert!(!c.corrected.contains(&n.id));
    }
    // The scale against the encoder, read as the straight line in the low band, is the
    // plain regression's +0.60% (a whole-band joint fit gave +3.7%); its interval covers it.
    let scale = d.effects.iter().find(|e| e.id == "scale_factor").unwrap();
    let k = scale.params["k"];
    assert!((0.003..0.009).contains(&k), "scale {k}");
    let [lo, hi] = scale.ci95["k"];
    assert!(
        lo.unwrap() <= 0.006 && hi.unwrap() >= 0.006,
        "{:?}",
        scale.ci95
    );
    // The residual's excess fades from 1 s to 16 s: no bias wander fits its shape, or
    // there is none beyond the baseline's (its test does not pass).
    for id in ["rate_random_walk", "bias_instability"] {
        let e = d.effects.iter().find(|e| e.id == id).unwrap();
        let why = e.test.contains("not a bias wander") || e.test.ends_with("does not pass");
        assert!(!e.significant && why, "{id}: {}", e.test);
    }
    // The stepper's vibration is in the motion (both sensors see it), near 12.8 Hz in the
    // slow trial and 40.5 Hz in the medium one: said, and not named as a sensor's.
    assert!(!named.contains(&"vibration"), "named {named:?}");
    for (runs, band) in [("training", 12.0..14.0), ("held-out", 39.0..42.0)] {
        let line = d.motion_lines.iter().find(|m| m.runs == runs);
        let f = line.map(|m| m.frequency_hz);
        assert!(f.is_some_and(|f| band.contains(&f)), "{runs}: {f:?}");
    }
    // The gyro's response to the 12.8 Hz line, against the motion (numpy's cross-spectrum
    // on a 1 ms grid: 0.956, 12.1 ms): a roll-off a pure delay does not have.
    let line = d
        .motion_lines
        .iter()
        .find(|m| m.runs == "training")
        .unwrap();
    assert!((0.9..0.99).contains(&line.gyro_gain), "{line:?}");
    assert!((0.010..0.014).contains(&line.gyro_lag_s), "{line:?}");
    // The effective noise on moving data (the largest white noise that what the
    // deterministic terms leave allows from 1 s to 10 s; `scripts/ssong_plain.py` on the
    // whole recordings: 6.6 deg/sqrt(h) slow, 17.1 medium) is tens of times the model's
    // white noise, and grows with the speed: a property of this motion, not of the sensor
    // alone.
    // The 12 ms lag is well inside the cross-correlation's search.
    assert!(d.warnings.is_empty(), "{:?}", d.warnings);
    let e = &d.effective_noise;
    let (t, h) = (e.training.as_ref().unwrap(), e.holdout.as_ref().unwrap());
    assert!((4.0..9.0).contains(&t.arw_deg_per_rt_h), "{}", t.describe());
    assert!(t.ratio_to_model > 10.0, "{}", t.describe());
    assert_eq!(t.compared_with, "prior model");
    // These runs never rest: the baseline's white noise is the one measured on their
    // moving residual, not the CRM100 prior's, and its note says so; the starting model
    // holds no bias wander, and its note says a wander the runs show is for the
    // vocabulary to name.
    let sensor = &d.model.sensor;
    assert_eq!(sensor.arw_deg_per_rt_h, t.arw_deg_per_rt_h);
    let notes = d.model.notes.join("\n");
    assert!(notes.contains("fitted to the moving residual"), "{notes}");
    assert!(notes.contains("no bias wander"), "{notes}");
    assert!(
        h.arw_deg_per_rt_h > 1.5 * t.arw_deg_per_rt_h,
        "{} / {}",
        t.describe(),
        h.describe()
    );
}

/// The rasteiro recordings (a robot's pose logged over a buffering link): the gyro lags the
/// pose by 80-105 ms, beyond the cross-correlation's ±50 ms search, and the diagnosis says
/// that its lag statistic is cut there rather than reporting the edge as a measurement.
#[test]
fn a_lag_beyond_the_search_is_said() {
    let file =
        |speed: &str, axis: &str| format!("rasteiro/rasteiro_MPU6050RM3100_{speed}_{axis}.csv");
    let (Some(train), Some(holdout)) = (
        ["x", "y"]
            .iter()
            .map(|a| load_at_100(file("V_300", a)))
            .collect::<Option<Vec<_>>>(),
        ["x", "y"]
            .iter()
            .map(|a| load_at_100(file("V_800", a)))
            .collect::<Option<Vec<_>>>(),
    ) else {
        return;
    };
    let d = diagnose(&train, &holdout, &quick(200), &Silent).unwrap();
    let warning = d
        .warnings
        .iter()
        .find(|w| w.contains("on 4 of 4 runs the gyro-reference lag lies at or beyond the edge of the cross-correlation's search, ±50 ms"))
        .unwrap_or_else(|| panic!("{:?}", d.warnings));
    // Searched wider, the lag is measured: the gyro 80-120 ms behind the pose.
    let range = warning
        .split("those runs give ")
        .nth(1)
        .and_then(|r| r.split(" ms").next())
        .unwrap_or_else(|| panic!("{warning}"));
    let (lo, hi) = range.split_once(" to ").unwrap();
    let (lo, hi): (f64, f64) = (lo.parse().unwrap(), hi.parse().unwrap());
    assert!(lo >= 80.0 && hi <= 125.0, "{warning}");
}

/// The rasteiro x recordings rest to rest, held out by speed (trained on both sensors at
/// V_300 and V_800, held out at V1500): the turns show the gyro 80-125 ms behind the pose,
/// a scale of about -1.1% (pooled over the two boards, whose plain lines give -1.2% and
/// -0.9%), which is named, written and takes most of the held-out turns' error away; and the y and z turns the x gyro sees through the board's tilt are listed
/// as movements the reference does not follow.
#[test]
fn the_turns_show_the_lag_the_scale_and_the_tilt() {
    let Some((train, holdout)) = rasteiro_x(["V_300", "V_800"], "V1500") else {
        return;
    };
    let d = diagnose(&train, &holdout, &quick(500), &Silent).unwrap();
    let t = d.turns.as_ref().unwrap();
    assert_eq!((t.train_turns, t.holdout_turns), (12, 6), "{t:?}");
    let lag = t.lag.as_ref().unwrap();
    assert!((0.08..=0.125).contains(&lag.median_s), "{lag:?}");
    assert!(lag.beyond_statistic && lag.written, "{lag:?}");
    let s = t.scale.as_ref().unwrap();
    assert!((-0.014..=-0.009).contains(&s.k), "{s:?}");
    assert!(s.named && s.written, "{s:?}");
    assert!(
        s.holdout_turn_rms_deg.1 < 0.4 * s.holdout_turn_rms_deg.0,
        "{s:?}"
    );
    let model = d.corrected_model.as_ref().unwrap();
    assert!((f64::from(model.config.correction.scale_k) - s.k).abs() < 1e-4);
    // Every run shows the tilt: the y and z turns, 4-10 degrees on the x gyro.
    assert!(t.untracked.len() >= 18, "{:?}", t.untracked);
    assert!(
        t.untracked
            .iter()
            .all(|u| (3.0..=12.0).contains(&u.gyro_deg.abs()) && u.reference_deg.abs() < 0.5),
        "{:?}",
        t.untracked
    );
}

/// The pose lags the gyro by about 100 ms, beyond the per-sample statistic: the residual
/// during turns is the rate times the lag, which the vocabulary's fit on the rate reads as
/// a scale of about −1.5% on x (trained on the two faster speeds). That scale is never
/// written: simulated at its fitted value it does not reproduce the low-band slope it was
/// fitted to (the lag, not a scale, made it), so it is not named; were it named, it would
/// be set aside for the turns' scale. The turns' own, rest to rest (the plain line's
/// −0.9% to −1.3% on x), is written.
#[test]
fn a_lag_beyond_the_statistic_leaves_the_scale_to_the_turns() {
    let Some((train, holdout)) = rasteiro_x(["V_800", "V1500"], "V_300") else {
        return;
    };
    let d = diagnose(&train, &holdout, &quick(500), &Silent).unwrap();
    let c = d.compensation.as_ref().unwrap();
    assert!(!c.corrected.contains(&"scale_factor"), "{c:?}");
    let per_sample = d.effects.iter().find(|e| e.id == "scale_factor").unwrap();
    assert!(
        (-0.02..=-0.01).contains(&per_sample.params["k"]),
        "{per_sample:?}"
    );
    if d.verdict.unmodelled.contains(&"scale_factor") {
        let from_turns = gyro_diagnose::SCALE_FROM_TURNS;
        assert!(
            c.not_corrected
                .iter()
                .any(|n| n.id == "scale_factor" && n.reason == Some(from_turns)),
            "{c:?}"
        );
    } else {
        let check = per_sample.posterior_check.as_ref().unwrap();
        assert!(!check.passes, "{per_sample:?}");
    }
    let s = d.turns.as_ref().unwrap().scale.as_ref().unwrap();
    assert!(s.named && s.written, "{s:?}");
    let k = f64::from(
        d.corrected_model
            .as_ref()
            .unwrap()
            .config
            .correction
            .scale_k,
    );
    assert!((-0.014..=-0.009).contains(&k), "{k}");
    assert!((k - s.k).abs() < 1e-4, "{k} {s:?}");
}
