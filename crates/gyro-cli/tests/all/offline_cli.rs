//! `run --offline`: the mode is said in the table and the JSON (and the JSON without it has
//! no `mode` key), the movements are the causal run's with their angles from the rests on
//! both sides, the `--out` series is the smoothed one, and a compensation without the
//! Kalman form is refused.
#![allow(clippy::unwrap_used)] // test code: a failed unwrap is a failed test

use crate::common::{bench_log, gyro, temp_dir};

fn json(args: &[&str]) -> serde_json::Value {
    let out = gyro(args);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).unwrap()
}

#[test]
fn offline_says_its_mode_and_keeps_the_movements() {
    let log = bench_log();
    let log = log.to_str().unwrap();
    let causal = json(&["run", log, "--format", "json"]);
    let offline = json(&["run", log, "--format", "json", "--offline"]);
    assert!(causal.get("mode").is_none());
    assert_eq!(offline["mode"], "offline");
    let (c, o) = (
        causal["movements"].as_array().unwrap(),
        offline["movements"].as_array().unwrap(),
    );
    assert_eq!(c.len(), 6);
    assert_eq!(c.len(), o.len());
    for (c, o) in c.iter().zip(o) {
        assert_eq!(c["start_time_s"], o["start_time_s"]);
        assert_eq!(c["end_time_s"], o["end_time_s"]);
        assert_eq!(c["raw_angle_deg"], o["raw_angle_deg"]);
        // Smoothing moves the bench log's angles by hundredths of a degree.
        let d = c["angle_deg"].as_f64().unwrap() - o["angle_deg"].as_f64().unwrap();
        assert!(d.abs() < 0.05, "{d}");
        assert!(o["angle_std_deg"].as_f64().unwrap() > 0.0);
    }
    let table = gyro(&["run", log, "--offline"]);
    assert!(String::from_utf8_lossy(&table.stdout).contains("mode: offline"));
    let table = gyro(&["run", log]);
    assert!(!String::from_utf8_lossy(&table.stdout).contains("mode:"));
}

#[test]
fn offline_series_holds_every_output_smoothed() {
    let dir = temp_dir("offline-series");
    let log = bench_log();
    let log = log.to_str().unwrap();
    let (a, b) = (
        dir.path().join("causal.csv"),
        dir.path().join("offline.csv"),
    );
    let (a, b) = (a.to_str().unwrap(), b.to_str().unwrap());
    assert!(gyro(&["run", log, "--out", a]).status.success());
    assert!(gyro(&["run", log, "--out", b, "--offline"])
        .status
        .success());
    let rows = |path: &str| -> Vec<String> {
        std::fs::read_to_string(path)
            .unwrap()
            .lines()
            .filter(|l| !l.starts_with('#'))
            .map(String::from)
            .collect()
    };
    let (ra, rb) = (rows(a), rows(b));
    assert_eq!(ra.len(), rb.len());
    assert_eq!(ra[0], rb[0], "the same header");
    assert_ne!(ra, rb, "the angles are smoothed");
}

#[test]
fn offline_needs_the_kalman_form() {
    let log = bench_log();
    let out = gyro(&[
        "run",
        log.to_str().unwrap(),
        "--offline",
        "--compensation",
        "paper",
    ]);
    assert_eq!(out.status.code(), Some(1));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("--offline") && stderr.contains("kalman"),
        "{stderr}"
    );
}
