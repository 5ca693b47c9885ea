//! `gyro-cli convert` and MCAP input to `gyro-cli run`; a writer killed mid-recording.
#![allow(clippy::unwrap_used)] // test code: a failed unwrap is a failed test

use crate::common::{gyro, ok, temp_dir, workspace_root};

use gyro_log::{self as log, McapLogWriter, McapOptions, Row};
use std::path::Path;
use std::process::Command;

fn summary_without_file(json: &str) -> serde_json::Value {
    let mut value: serde_json::Value = serde_json::from_str(json).unwrap();
    value.as_object_mut().unwrap().remove("file");
    value
}

#[test]
fn run_on_mcap_gives_the_same_summary_as_on_csv() {
    let scratch = temp_dir("run");
    let dir = scratch.path();
    let csv = workspace_root().join("fixtures/logs/bench_run.csv");
    let csv = csv.to_str().unwrap();
    let mcap = dir.join("bench_run.mcap");
    let mcap = mcap.to_str().unwrap();
    let out = gyro(&["convert", csv, mcap]);
    ok(&out);
    let note = String::from_utf8_lossy(&out.stderr);
    assert!(
        note.contains("40000 rows, reference: yes, temperature: yes"),
        "{note}"
    );
    for mode in ["kalman", "none"] {
        let from_csv = ok(&gyro(&[
            "run",
            csv,
            "--format",
            "json",
            "--compensation",
            mode,
        ]));
        let from_mcap = ok(&gyro(&[
            "run",
            mcap,
            "--format",
            "json",
            "--compensation",
            mode,
        ]));
        assert_eq!(
            summary_without_file(&from_csv),
            summary_without_file(&from_mcap),
            "{mode}"
        );
    }

    // And back to CSV: the same rows.
    let back = dir.join("back.csv");
    ok(&gyro(&["convert", mcap, back.to_str().unwrap()]));
    let a = log::read_csv(Path::new(csv), &log::ColumnOptions::default()).unwrap();
    let b = log::read_csv(&back, &log::ColumnOptions::default()).unwrap();
    assert_eq!(a.metadata, b.metadata);
    assert_eq!(a.rows.len(), b.rows.len());
    for (x, y) in a.rows.iter().zip(&b.rows) {
        assert_eq!(
            (x.time_s, x.rate_dps, x.reference_deg, x.temperature_c),
            (y.time_s, y.rate_dps, y.reference_deg, y.temperature_c)
        );
    }
}

#[test]
fn convert_ros2_bag_with_axis_options_and_errors() {
    let scratch = temp_dir("ros2");
    let dir = scratch.path();
    let bag = workspace_root().join("fixtures/mcap/ros2_imu.mcap");
    let bag = bag.to_str().unwrap();
    let out_csv = dir.join("imu.csv");
    let out_csv = out_csv.to_str().unwrap();
    ok(&gyro(&["convert", bag, out_csv, "--axis", "y", "--flip"]));
    let log = log::read_csv(Path::new(out_csv), &log::ColumnOptions::default()).unwrap();
    assert_eq!(log.rows.len(), 200);
    assert_eq!(log.metadata["time_origin_s"], "1700000000");
    assert_eq!(log.rows[0].time_s, 0.5);
    // write_csv writes the shortest exact form: 0.5 rad/s in deg/s, bit for bit.
    assert_eq!(log.rows[7].rate_dps, Some(0.5_f64.to_degrees()));

    // ROS 2 bag straight to our MCAP, then run on it.
    let out_mcap = dir.join("imu.mcap");
    let out_mcap = out_mcap.to_str().unwrap();
    ok(&gyro(&["convert", bag, out_mcap, "--topic", "/imu/data"]));
    let read = log::read_mcap(Path::new(out_mcap), &McapOptions::default()).unwrap();
    assert_eq!(read.rate_topic, "/gyro");
    assert_eq!(read.log.rows.len(), 200);
    assert_eq!(read.log.rows[10].rate_dps, Some((-1.5_f64).to_degrees()));
    ok(&gyro(&["run", bag, "--format", "json"]));

    // Errors are one line naming the file.
    let two = workspace_root().join("fixtures/mcap/ros2_two_imus.mcap");
    let two_csv = dir.join("two.csv");
    let out = gyro(&["convert", two.to_str().unwrap(), two_csv.to_str().unwrap()]);
    assert!(!out.status.success());
    let e = String::from_utf8_lossy(&out.stderr);
    assert!(
        e.contains("ros2_two_imus.mcap: channel `/imu/raw`") && e.contains("--topic"),
        "{e}"
    );
    assert_eq!(e.trim_end().lines().count(), 1, "{e}");
    assert!(!two_csv.exists());

    let out = gyro(&["convert", bag, dir.join("x.txt").to_str().unwrap()]);
    let e = String::from_utf8_lossy(&out.stderr);
    assert!(
        !out.status.success() && e.contains("x.txt: unknown output format"),
        "{e}"
    );
    let out = gyro(&[
        "convert",
        bag,
        dir.join("x.txt").to_str().unwrap(),
        "--to",
        "csv",
    ]);
    ok(&out);
    let out = gyro(&["convert", bag, bag]);
    assert!(!out.status.success());
}

const CHILD: &str = "GYRO_MCAP_KILL_CHILD";

/// The recording child: writes 3 s of 1 kHz samples, reference and raw frames, then dies
/// without any cleanup (abort, like SIGKILL: no flush, no destructors). Does nothing unless
/// started by `killed_writer_loses_at_most_the_open_chunk`.
#[test]
fn kill_child() {
    let Ok(path) = std::env::var(CHILD) else {
        return;
    };
    let mut w = McapLogWriter::create(Path::new(&path)).unwrap();
    w.write_metadata(&[("sample_rate_hz".to_string(), "1000".to_string())].into())
        .unwrap();
    for i in 0..3000_u64 {
        let row = Row {
            line: i + 1,
            time_s: i as f64 / 1000.0,
            rate_dps: Some(i as f64),
            reference_deg: Some(i as f64 / 10.0),
            temperature_c: Some(25.0),
        };
        w.write_row(&row).unwrap();
        w.write_raw(i * 1_000_000, &[0x80, 0, 0, 0, 0, 0x7f])
            .unwrap();
    }
    std::process::abort();
}

#[test]
fn killed_writer_loses_at_most_the_open_chunk() {
    let scratch = temp_dir("kill");
    let dir = scratch.path();
    let path = dir.join("killed.mcap");
    // The child test's name as the harness knows it: its module path without the crate's.
    let child = concat!(module_path!(), "::kill_child");
    let child = child.split_once("::").map_or(child, |(_, name)| name);
    let status = Command::new(std::env::current_exe().unwrap())
        .args(["--exact", child, "--nocapture", "--test-threads", "1"])
        .env(CHILD, &path)
        .output()
        .unwrap()
        .status;
    assert!(!status.success(), "the child aborts");
    let read = log::read_mcap(&path, &McapOptions::default()).unwrap();
    assert_eq!(read.warnings.len(), 1, "{:?}", read.warnings);
    let rows = &read.log.rows;
    // Chunks close every 0.5 s of log time: the open one is all that is lost.
    assert!(rows.len() >= 2500, "kept {}", rows.len());
    assert!(rows.len() < 3000, "kept {}", rows.len());
    for (i, row) in rows.iter().enumerate() {
        assert_eq!(row.rate_dps, Some(i as f64));
        assert_eq!(row.reference_deg, Some(i as f64 / 10.0));
    }
    assert_eq!(read.log.metadata_rate_hz(), Some(1000.0));

    // `run` uses what survived, and says what happened.
    let out = gyro(&["run", path.to_str().unwrap(), "--format", "json"]);
    ok(&out);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("warning:") && stderr.contains("no MCAP footer"),
        "{stderr}"
    );
}

/// A log whose time goes back (two recordings concatenated) is refused by `convert` to
/// MCAP as `run` refuses it, naming the line, and nothing is written: MCAP orders messages
/// by time, and would give the rows back interleaved, a log that reads.
#[test]
fn convert_refuses_time_that_goes_back() {
    let scratch = temp_dir("convert_back");
    let dir = scratch.path();
    let csv = dir.join("back.csv");
    let mut text = String::from("time_s,rate_dps,reference_deg\n");
    for k in 0..400 {
        let t = if k < 200 {
            k as f64 * 0.01
        } else {
            (k - 200) as f64 * 0.01
        };
        text.push_str(&format!("{t:.2},1.0,{:.2}\n", 0.01 * k as f64));
    }
    std::fs::write(&csv, text).unwrap();
    let csv = csv.to_str().unwrap();
    let mcap = dir.join("back.mcap");
    for out in [
        gyro(&["run", csv]),
        gyro(&["convert", csv, mcap.to_str().unwrap()]),
    ] {
        assert!(!out.status.success());
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(
            err.contains("back.csv:202: time goes back by 1.990000 s"),
            "{err}"
        );
    }
    assert!(!mcap.exists());
}
