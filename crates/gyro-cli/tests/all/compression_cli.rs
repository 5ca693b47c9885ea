//! `--compression zstd|lz4|none` of the commands that write MCAP (`convert`, `simulate`,
//! `record`), the format by the output's extension, and `simulate --static` for `noise`.
#![allow(clippy::unwrap_used)] // test code: a failed unwrap is a failed test

use crate::common;
use crate::common::{bench_log, gyro, ok, temp_dir};

use gyro_log::{self as log, McapOptions};
use std::path::Path;
use std::process::Output;

const COMPRESSIONS: [&str; 3] = ["none", "lz4", "zstd"];

/// The compression name of every chunk of the finished MCAP file at `path` (`""`: none).
fn chunk_compressions(path: &Path) -> Vec<String> {
    let bytes = std::fs::read(path).unwrap();
    let summary = mcap::Summary::read(&bytes).unwrap().unwrap();
    summary
        .chunk_indexes
        .iter()
        .map(|c| c.compression.clone())
        .collect()
}

fn run_summary(path: &str) -> serde_json::Value {
    let mut value: serde_json::Value =
        serde_json::from_str(&ok(&gyro(&["run", path, "--format", "json"]))).unwrap();
    value.as_object_mut().unwrap().remove("file");
    value
}

/// Refused: a non-zero exit with exactly one `error:` line, containing `needle`.
fn assert_refused(out: &Output, needle: &str) {
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "accepted: {stderr}");
    let errors: Vec<&str> = stderr.lines().filter(|l| l.starts_with("error:")).collect();
    assert_eq!(errors.len(), 1, "{stderr}");
    assert!(errors[0].contains(needle), "{stderr}");
}

#[test]
fn convert_with_each_compression_reads_back_identically() {
    let scratch = temp_dir("compression-convert");
    let csv = bench_log();
    let csv = csv.to_str().unwrap();
    let from_csv = run_summary(csv);
    for compression in COMPRESSIONS {
        let path = scratch.path().join(format!("bench_{compression}.mcap"));
        let out = gyro(&[
            "convert",
            csv,
            path.to_str().unwrap(),
            "--compression",
            compression,
        ]);
        ok(&out);
        let said = String::from_utf8_lossy(&out.stderr);
        let expected = if compression == "none" {
            "uncompressed chunks"
        } else {
            compression
        };
        assert!(said.contains(expected), "{said}");
        let chunk_name = if compression == "none" {
            ""
        } else {
            compression
        };
        let names = chunk_compressions(&path);
        assert!(!names.is_empty() && names.iter().all(|n| n == chunk_name));
        assert_eq!(
            run_summary(path.to_str().unwrap()),
            from_csv,
            "run on the {compression} file"
        );
        // And the rows themselves, bit for bit.
        let a = log::read_csv(Path::new(csv), &log::ColumnOptions::default()).unwrap();
        let b = log::read_mcap(&path, &McapOptions::default()).unwrap().log;
        assert_eq!(a.rows.len(), b.rows.len());
        for (x, y) in a.rows.iter().zip(&b.rows) {
            // `line` is the CSV's line, the MCAP message's index: all else is equal.
            assert_eq!(*x, log::Row { line: x.line, ..*y }, "{compression}");
        }
    }
}

/// The default is zstd, the smallest of the three. Any MCAP of this layout stays above
/// the CSV on the bench fixture (1.57x with zstd): its message indexes, 16 bytes a message
/// and never compressed, which Foxglove needs, take 32 bytes a row, the CSV's row size;
/// what is left is 0.56x the CSV.
#[test]
fn the_default_is_zstd_and_the_smallest() {
    let scratch = temp_dir("compression-default");
    let csv = bench_log();
    let size = |args: &[&str], name: &str| {
        let path = scratch.path().join(name);
        let mut all = vec!["convert", csv.to_str().unwrap(), path.to_str().unwrap()];
        all.extend_from_slice(args);
        ok(&gyro(&all));
        (std::fs::metadata(&path).unwrap().len(), path)
    };
    let (default, path) = size(&[], "default.mcap");
    assert!(chunk_compressions(&path).iter().all(|n| n == "zstd"));
    let (zstd, _) = size(&["--compression", "zstd"], "zstd.mcap");
    let (lz4, _) = size(&["--compression", "lz4"], "lz4.mcap");
    let (none, _) = size(&["--compression", "none"], "none.mcap");
    assert_eq!(default, zstd);
    assert!(
        zstd < lz4 && lz4 < none,
        "zstd {zstd}, lz4 {lz4}, none {none}"
    );
    let csv_size = std::fs::metadata(&csv).unwrap().len();
    let rows = 40_000;
    let message_indexes = 2 * 16 * rows;
    assert!(
        zstd - message_indexes < csv_size * 6 / 10,
        "zstd {zstd} B (message indexes {message_indexes} B), CSV {csv_size} B"
    );
    assert!(zstd < csv_size * 16 / 10, "zstd {zstd} B, CSV {csv_size} B");
}

#[test]
fn compression_is_refused_where_it_would_be_ignored_and_a_bad_value_named() {
    let scratch = temp_dir("compression-refused");
    let dir = scratch.path();
    let csv = bench_log();
    let csv = csv.to_str().unwrap();
    let out_csv = dir.join("out.csv");
    let out = gyro(&[
        "convert",
        csv,
        out_csv.to_str().unwrap(),
        "--compression",
        "lz4",
    ]);
    assert_refused(&out, "--compression lz4");
    assert!(!out_csv.exists());
    let out = gyro(&[
        "simulate",
        "--duration-s",
        "2",
        "-o",
        out_csv.to_str().unwrap(),
        "--compression",
        "zstd",
    ]);
    assert_refused(&out, "--compression zstd");
    assert!(!out_csv.exists());
    let out_mcap = dir.join("out.mcap");
    let out = gyro(&[
        "convert",
        csv,
        out_mcap.to_str().unwrap(),
        "--compression",
        "brotli",
    ]);
    assert_refused(&out, "--compression");
    assert!(!out_mcap.exists());
    // `--to mcap` makes the format, whatever the name.
    let named_txt = dir.join("out.txt");
    ok(&gyro(&[
        "convert",
        csv,
        named_txt.to_str().unwrap(),
        "--to",
        "mcap",
        "--compression",
        "lz4",
    ]));
    assert!(chunk_compressions(&named_txt).iter().all(|n| n == "lz4"));
}

#[test]
fn help_says_what_the_commands_write() {
    let convert = ok(&gyro(&["convert", "--help"]));
    for needle in ["--compression", "zstd", "lz4", "none", "extension"] {
        assert!(convert.contains(needle), "convert --help lacks {needle}");
    }
    let simulate = ok(&gyro(&["simulate", "--help"]));
    for needle in [".mcap", "CSV", "--static", "--compression"] {
        assert!(simulate.contains(needle), "simulate --help lacks {needle}");
    }
    assert!(!simulate.contains("Output log (CSV)"));
    let record = ok(&gyro(&["record", "--help"]));
    for needle in [".csv", "--compression"] {
        assert!(record.contains(needle), "record --help lacks {needle}");
    }
}

/// `simulate --static`: the sensor at rest, the reference 0 throughout; `noise` on it
/// finds the model's angle random walk. An effect applies as in motion.
#[test]
fn simulate_static_then_noise_finds_the_models_arw() {
    let scratch = temp_dir("compression-static");
    let dir = scratch.path();
    let rest = dir.join("rest.mcap");
    let out = gyro(&[
        "simulate",
        "--static",
        "--duration-s",
        "600",
        "-o",
        rest.to_str().unwrap(),
    ]);
    ok(&out);
    assert!(String::from_utf8_lossy(&out.stderr).contains("at rest"));
    assert!(chunk_compressions(&rest).iter().all(|n| n == "zstd"));
    let log = log::read_mcap(&rest, &McapOptions::default()).unwrap().log;
    assert_eq!(log.rows.len(), 600_001);
    assert!(log.rows.iter().all(|r| r.reference_deg == Some(0.0)));
    let noise: serde_json::Value = serde_json::from_str(&ok(&gyro(&[
        "noise",
        rest.to_str().unwrap(),
        "--format",
        "json",
    ])))
    .unwrap();
    let arw = noise["logs"][0]["fit"]["arw_deg_per_rt_h"]
        .as_f64()
        .unwrap();
    let model = gyro_sim::SensorModel::default().arw_deg_per_rt_h;
    assert!(
        (arw / model - 1.0).abs() < 0.05,
        "ARW {arw} deg/√h against the model's {model}"
    );

    // An effect at rest: against the same run without it (same seed), the bias follows
    // the warming sensor.
    let simulate = |name: &str, effect: &[&str]| {
        let path = dir.join(name);
        let mut args = vec!["simulate", "--static", "--duration-s", "60", "-o"];
        args.push(path.to_str().unwrap());
        args.extend_from_slice(effect);
        ok(&gyro(&args));
        log::read_csv(&path, &log::ColumnOptions::default()).unwrap()
    };
    let plain = simulate("plain.csv", &[]);
    let warm = simulate("warm.csv", &["--effect", "temperature_bias:dps_per_c=0.05"]);
    assert!(warm.rows.iter().all(|r| r.reference_deg == Some(0.0)));
    let added = |i: usize| warm.rows[i].rate_dps.unwrap() - plain.rows[i].rate_dps.unwrap();
    let (early, late) = (added(1_000), added(59_000));
    assert!(
        late > early + 0.01,
        "the effect adds {early} then {late} deg/s"
    );

    let out = gyro(&[
        "simulate",
        "--static",
        "--motion-from",
        dir.join("warm.csv").to_str().unwrap(),
        "-o",
        dir.join("x.csv").to_str().unwrap(),
    ]);
    assert_refused(&out, "--static");
}

/// `record` writes by the extension too (CSV for a `.csv` name), MCAP compressed as asked.
#[cfg(unix)]
#[test]
fn record_writes_by_the_extension_and_compresses_as_asked() {
    use std::ffi::OsStr;
    let scratch = temp_dir("compression-record");
    let dir = scratch.path();
    let emulate: Vec<&OsStr> = ["--seed", "3", "--duration-s", "2", "--as-fast-as-possible"]
        .iter()
        .map(OsStr::new)
        .collect();
    let mcap = dir.join("rec.mcap");
    let (_, record) = common::emulate_into_record_with(&emulate, &["--compression", "lz4"], &mcap);
    assert!(
        record.status.success(),
        "{}",
        String::from_utf8_lossy(&record.stderr)
    );
    assert!(chunk_compressions(&mcap).iter().all(|n| n == "lz4"));
    let rows = log::read_mcap(&mcap, &McapOptions::default())
        .unwrap()
        .log
        .rows
        .len();
    assert!(rows > 1000, "{rows} rows");

    let csv = dir.join("rec.csv");
    let (_, record) = common::emulate_into_record(&emulate, &csv);
    assert!(
        record.status.success(),
        "{}",
        String::from_utf8_lossy(&record.stderr)
    );
    assert_eq!(log::LogFormat::detect(&csv), log::LogFormat::Csv);
    assert!(std::fs::read_to_string(&csv).unwrap().contains("time_s,"));

    let refused = gyro(&[
        "record",
        "--port",
        "/dev/null",
        "--csv",
        "-o",
        dir.join("r.mcap").to_str().unwrap(),
    ]);
    assert_refused(&refused, "--csv");
    let refused = gyro(&[
        "record",
        "--port",
        "/dev/null",
        "--compression",
        "zstd",
        "-o",
        dir.join("r.csv").to_str().unwrap(),
    ]);
    assert_refused(&refused, "--compression zstd");
}
