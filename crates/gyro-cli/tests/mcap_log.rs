//! MCAP logs through the library: round trips, schemas, damaged files, ROS 2 bags.
#![allow(clippy::unwrap_used)] // test code: a failed unwrap is a failed test

use gyro_host::log::{self, Log, LogOptions, McapOptions};
use std::path::{Path, PathBuf};

fn workspace_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("gyro-mcap-test-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn bench() -> Log {
    log::read_csv(
        &workspace_root().join("fixtures/logs/bench_run.csv"),
        &log::ColumnOptions::default(),
    )
    .unwrap()
}

fn assert_same_rows(a: &Log, b: &Log) {
    assert_eq!(a.rows.len(), b.rows.len());
    for (x, y) in a.rows.iter().zip(&b.rows) {
        assert_eq!(
            (
                x.time_s.to_bits(),
                x.rate_dps,
                x.reference_deg,
                x.temperature_c
            ),
            (
                y.time_s.to_bits(),
                y.rate_dps,
                y.reference_deg,
                y.temperature_c
            ),
            "{x:?} vs {y:?}"
        );
    }
    assert_eq!(a.has_reference, b.has_reference);
    assert_eq!(a.has_temperature, b.has_temperature);
    assert_eq!(a.metadata, b.metadata);
}

#[test]
fn csv_to_mcap_to_csv_is_lossless() {
    let dir = temp_dir("roundtrip");
    let csv = bench();
    let mcap = dir.join("bench.mcap");
    log::write_mcap(&mcap, &csv).unwrap();
    let back = log::read_mcap(&mcap, &McapOptions::default()).unwrap();
    assert!(back.warnings.is_empty());
    assert_eq!(back.rate_topic, "/gyro");
    assert_same_rows(&csv, &back.log);
    for (i, row) in back.log.rows.iter().enumerate() {
        assert_eq!(row.line, i as u64 + 1);
    }
    let csv2 = dir.join("bench2.csv");
    log::write_log(&csv2, &back.log, None).unwrap();
    let again = log::read_log(&csv2, &LogOptions::default()).unwrap();
    assert_same_rows(&csv, &again);
}
