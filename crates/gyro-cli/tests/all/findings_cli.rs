//! `run`'s findings: one list per run, the same in the table, the JSON (`warnings` and
//! `findings`, always present), the series CSV's header comments and stderr; and the
//! findings a user met silently before: a lag that grows (a clock off its rate), a run that
//! never rests (the bias unobservable), movements the reference does not follow.
#![allow(clippy::unwrap_used)] // test code: a failed unwrap is a failed test

use crate::common;
use crate::common::{gyro, json_of, ok, temp_dir};

/// The codes of a JSON report's findings, in order.
fn codes(report: &serde_json::Value) -> Vec<String> {
    report["findings"]
        .as_array()
        .unwrap()
        .iter()
        .map(|f| f["code"].as_str().unwrap().to_string())
        .collect()
}

/// Every finding of the JSON is a `warning:` line of the table, in the same order, and the
/// table has no other; the JSON's `warnings` are the findings' sentences.
fn same_in_table_and_json(log: &str) -> serde_json::Value {
    let report = json_of(&gyro(&["run", log, "--format", "json"]));
    let table = ok(&gyro(&["run", log]));
    let said: Vec<&str> = table
        .lines()
        .filter_map(|l| l.strip_prefix("warning: "))
        .collect();
    let messages: Vec<&str> = report["findings"]
        .as_array()
        .unwrap()
        .iter()
        .map(|f| f["message"].as_str().unwrap())
        .collect();
    assert_eq!(said, messages, "{table}");
    let warnings: Vec<&str> = report["warnings"]
        .as_array()
        .unwrap()
        .iter()
        .map(|w| w.as_str().unwrap())
        .collect();
    assert_eq!(warnings, messages);
    report
}

/// A gyro whose clock runs 2% fast, its rows stamped by its sample count: the lag grows
/// through the run, said with its rate in every output.
#[test]
fn a_lag_that_grows_is_said_everywhere() {
    let scratch = temp_dir("findings-clock");
    let dir = scratch.path();
    let log = dir.join("clock.csv");
    let log_s = log.to_str().unwrap();
    ok(&gyro(&[
        "simulate",
        "-o",
        log_s,
        "--seed",
        "3",
        "--duration-s",
        "60",
        "--effect",
        "clock_error_count_stamped:ppm=20000",
    ]));
    let report = same_in_table_and_json(log_s);
    assert!(
        codes(&report).contains(&"lag_drift".to_string()),
        "{report}"
    );
    let trend = &report["summary"]["reference_lag_trend"];
    let per_s = trend["per_s"].as_f64().unwrap();
    assert!((per_s - 0.0196).abs() < 0.002, "{trend}");
    let drift = report["findings"]
        .as_array()
        .unwrap()
        .iter()
        .find(|f| f["code"] == "lag_drift")
        .unwrap();
    assert!(drift["time_s"].is_number(), "{drift}");
    let message = drift["message"].as_str().unwrap();
    assert!(
        message.contains("ms per minute") && message.contains("% above its nominal rate"),
        "{message}"
    );

    // The series CSV opens with the findings; the CSV format says them on stderr.
    let series = dir.join("series.csv");
    let out = gyro(&[
        "run",
        log_s,
        "--format",
        "csv",
        "--out",
        series.to_str().unwrap(),
    ]);
    assert!(out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains(message));
    let text = std::fs::read_to_string(&series).unwrap();
    let head: Vec<&str> = text.lines().take_while(|l| l.starts_with('#')).collect();
    assert!(
        head.iter()
            .any(|l| l.starts_with("# warning (lag_drift): ") && l.ends_with(message)),
        "{head:?}"
    );
    assert!(
        head.last().unwrap().starts_with("# output_rate_hz"),
        "{head:?}"
    );

    // A steady clock: no drift, and `warnings` is still there, empty.
    let steady = dir.join("steady.csv");
    ok(&gyro(&[
        "simulate",
        "-o",
        steady.to_str().unwrap(),
        "--seed",
        "3",
        "--duration-s",
        "60",
    ]));
    let report = json_of(&gyro(&[
        "run",
        steady.to_str().unwrap(),
        "--format",
        "json",
    ]));
    assert_eq!(report["warnings"], serde_json::json!([]), "{report}");
    assert_eq!(report["findings"], serde_json::json!([]));
}

/// On the shared real recordings (when beside the workspace): the shaft that never rests
/// says its bias is unobservable and how fast the error may grow, with σ on its movement;
/// the robot's turns about the other axes are flagged.
#[test]
fn real_recordings_say_what_their_figures_do_not() {
    let real = gyro_log::real_data::dir();
    let ssong = real.join("ssong_x_slow.csv");
    let rasteiro = real.join("rasteiro/rasteiro_MPU6050RM3100_V_300_x.csv");
    if !ssong.exists() || !rasteiro.exists() {
        gyro_log::real_data::skipped(&format!("{} or {}", ssong.display(), rasteiro.display()));
        return;
    }
    let report = same_in_table_and_json(ssong.to_str().unwrap());
    assert!(
        codes(&report).contains(&"bias_unobservable".to_string()),
        "{}",
        report["findings"]
    );
    let movement = &report["movements"][0];
    assert!(
        movement["angle_std_deg"].as_f64().unwrap() > 100.0,
        "{movement}"
    );
    let unobservable = report["findings"]
        .as_array()
        .unwrap()
        .iter()
        .find(|f| f["code"] == "bias_unobservable")
        .unwrap()["message"]
        .as_str()
        .unwrap()
        .to_string();
    assert!(
        unobservable.starts_with("no rest for 1500 s") && unobservable.contains("deg/s"),
        "{unobservable}"
    );

    let report = same_in_table_and_json(rasteiro.to_str().unwrap());
    let flagged: Vec<u64> = report["findings"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|f| f["code"] == "reference_does_not_follow")
        .map(|f| f["movement"].as_u64().unwrap())
        .collect();
    assert_eq!(flagged, [1, 2, 3, 4], "{}", report["findings"]);
}

/// A log of three rows runs, and says its figures say nothing.
#[test]
fn a_log_too_short_says_so() {
    let scratch = temp_dir("findings-short");
    let log = common::write(
        scratch.path(),
        "three.csv",
        "time_s,rate_dps,reference_deg\n0,0.1,0\n0.001,0.1,0\n0.002,0.1,0\n",
    );
    let report = same_in_table_and_json(&log);
    assert_eq!(codes(&report), ["short_log"], "{}", report["findings"]);
}

/// A log that ends while the gyro turns and the reference stays still: said as well.
#[test]
fn a_turn_the_reference_misses_to_the_log_end_is_said() {
    let scratch = temp_dir("findings-midturn");
    let mut text = String::from("time_s,rate_dps,reference_deg\n");
    for i in 0..6000 {
        let t = f64::from(i) / 1000.0;
        let rate = if t < 3.0 { 0.0 } else { 36.0 };
        text.push_str(&format!("{t:.3},{rate},0\n"));
    }
    let log = common::write(scratch.path(), "midturn.csv", &text);
    let report = same_in_table_and_json(&log);
    assert!(
        codes(&report).contains(&"reference_does_not_follow".to_string()),
        "{}",
        report["findings"]
    );
    assert_eq!(report["movements"][0]["complete"], false);
    assert!(report["movements"][0]["angle_std_deg"].is_number());
}
