//! MCAP chunk compression (`--compression zstd|lz4|none`): every compression the writers
//! offer comes back bit for bit, whole and streamed, from a finished file and from one cut
//! short; the default is zstd, the smallest.
#![allow(clippy::unwrap_used)] // test code: a failed unwrap is a failed test

use crate::common::{temp_dir, workspace_root};

use gyro_log::{
    self, Log, LogFormat, McapCompression, McapLogWriter, McapOptions, McapRows, McapWriteOptions,
    Row,
};
use std::path::Path;

const ALL: [McapCompression; 3] = [
    McapCompression::Zstd,
    McapCompression::Lz4,
    McapCompression::None,
];

fn bench_path() -> std::path::PathBuf {
    workspace_root().join("fixtures/logs/bench_run.csv")
}

fn bench() -> Log {
    gyro_log::read_csv(&bench_path(), &gyro_log::ColumnOptions::default()).unwrap()
}

/// A row's time (as bits) and values, for bit-for-bit comparison.
fn values(row: &Row) -> (u64, Option<u64>, Option<u64>, Option<u64>) {
    let bits = |v: Option<f64>| v.map(f64::to_bits);
    (
        row.time_s.to_bits(),
        bits(row.rate_dps),
        bits(row.reference_deg),
        bits(row.temperature_c),
    )
}

fn assert_same_rows(got: &[Row], expected: &[Row], what: &str) {
    assert_eq!(got.len(), expected.len(), "{what}: rows");
    for (a, b) in got.iter().zip(expected) {
        assert_eq!(values(a), values(b), "{what}: row {}", b.line);
    }
}

/// The compression name every chunk of the finished file at `path` carries.
fn chunk_compressions(path: &Path) -> Vec<String> {
    let bytes = std::fs::read(path).unwrap();
    let summary = mcap::Summary::read(&bytes).unwrap().unwrap();
    summary
        .chunk_indexes
        .iter()
        .map(|c| c.compression.clone())
        .collect()
}

/// What MCAP calls the compression in a chunk record.
fn chunk_name(compression: McapCompression) -> &'static str {
    match compression {
        McapCompression::None => "",
        other => other.name(),
    }
}

#[test]
fn every_compression_round_trips_the_bench_fixture_bit_for_bit() {
    let scratch = temp_dir("compression-round-trip");
    let csv = bench();
    for compression in ALL {
        let path = scratch.path().join(format!("bench_{compression}.mcap"));
        gyro_log::write_mcap_with(&path, &csv, compression).unwrap();
        let names = chunk_compressions(&path);
        assert!(names.len() > 10, "{compression}: {} chunks", names.len());
        assert!(
            names.iter().all(|n| n == chunk_name(compression)),
            "{compression}: {names:?}"
        );
        let read = gyro_log::read_mcap(&path, &McapOptions::default()).unwrap();
        assert!(read.warnings.is_empty(), "{:?}", read.warnings);
        assert_eq!(read.log.metadata, csv.metadata, "{compression}");
        assert_eq!(read.log.has_reference, csv.has_reference);
        assert_eq!(read.log.has_temperature, csv.has_temperature);
        assert_same_rows(&read.log.rows, &csv.rows, compression.name());
        // Streamed, chunk by chunk, as `run` reads it.
        let streamed: Vec<Row> = McapRows::open(&path, &McapOptions::default())
            .unwrap()
            .map(Result::unwrap)
            .collect();
        assert_same_rows(&streamed, &csv.rows, compression.name());
    }
}

/// `write_log_with` writes MCAP by the extension with the compression asked for, and a
/// CSV (which has none) the same whatever it is given.
#[test]
fn write_log_with_compresses_mcap_and_leaves_csv_alone() {
    let scratch = temp_dir("compression-write-log");
    let csv = bench();
    let plain = scratch.path().join("plain.csv");
    gyro_log::write_log(&plain, &csv, None).unwrap();
    for compression in ALL {
        let path = scratch.path().join(format!("b_{compression}.mcap"));
        gyro_log::write_log_with(&path, &csv, None, compression).unwrap();
        assert_eq!(LogFormat::detect(&path), LogFormat::Mcap);
        let names = chunk_compressions(&path);
        assert!(names.iter().all(|n| n == chunk_name(compression)));
        let again = scratch.path().join(format!("b_{compression}.csv"));
        gyro_log::write_log_with(&again, &csv, None, compression).unwrap();
        assert_eq!(
            std::fs::read(&again).unwrap(),
            std::fs::read(&plain).unwrap()
        );
    }
}

/// zstd by default, as the official `mcap` CLI; of the three the smallest file. The
/// message indexes (16 bytes a message, never compressed, which Foxglove needs) keep any
/// MCAP of this layout above 32 bytes a sample, the size of the CSV's rows (1.57x the
/// CSV with them); without them the zstd file would be 0.56x the CSV.
#[test]
fn the_default_is_zstd_and_the_smallest() {
    let scratch = temp_dir("compression-default");
    let csv = bench();
    let default = scratch.path().join("default.mcap");
    gyro_log::write_mcap(&default, &csv).unwrap();
    assert_eq!(McapCompression::default(), McapCompression::Zstd);
    assert!(chunk_compressions(&default).iter().all(|n| n == "zstd"));
    let size = |c: McapCompression| {
        let path = scratch.path().join(format!("{c}.mcap"));
        gyro_log::write_mcap_with(&path, &csv, c).unwrap();
        std::fs::metadata(&path).unwrap().len()
    };
    let (zstd, lz4, none) = (
        size(McapCompression::Zstd),
        size(McapCompression::Lz4),
        size(McapCompression::None),
    );
    assert_eq!(std::fs::metadata(&default).unwrap().len(), zstd);
    assert!(
        zstd < lz4 && lz4 < none,
        "zstd {zstd}, lz4 {lz4}, none {none}"
    );
    let csv_size = std::fs::metadata(bench_path()).unwrap().len();
    let message_indexes = 16 * 2 * csv.rows.len() as u64; // a /gyro and a /reference a row
    assert!(
        zstd - message_indexes < csv_size * 6 / 10,
        "zstd {zstd} B, of which message indexes {message_indexes} B; CSV {csv_size} B"
    );
}

/// The recording writer compresses as asked too, and a file cut short (a killed
/// recorder: no summary, no closing magic) reads up to the cut for every compression.
#[test]
fn the_recording_writer_compresses_as_asked_and_a_cut_file_reads_to_the_cut() {
    let scratch = temp_dir("compression-recording");
    let csv = bench();
    for compression in ALL {
        let path = scratch.path().join(format!("rec_{compression}.mcap"));
        let mut w = McapLogWriter::create_with(
            &path,
            McapWriteOptions {
                has_reference: true,
                compression,
                ..McapWriteOptions::default()
            },
        )
        .unwrap();
        w.write_metadata(&csv.metadata).unwrap();
        for row in &csv.rows {
            w.write_row(row).unwrap();
            if row.line % 1000 == 0 {
                w.write_raw((row.time_s * 1e9) as u64, &[0x80, 0x01, 0x02])
                    .unwrap();
            }
        }
        w.finish().unwrap();
        let names = chunk_compressions(&path);
        assert!(names.iter().all(|n| n == chunk_name(compression)));
        let read = gyro_log::read_mcap(&path, &McapOptions::default()).unwrap();
        assert_same_rows(&read.log.rows, &csv.rows, compression.name());

        let bytes = std::fs::read(&path).unwrap();
        let cut = scratch.path().join(format!("cut_{compression}.mcap"));
        std::fs::write(&cut, &bytes[..bytes.len() * 2 / 3]).unwrap();
        let read = gyro_log::read_mcap(&cut, &McapOptions::default()).unwrap();
        assert_eq!(read.warnings.len(), 1, "{compression}: {:?}", read.warnings);
        let kept = read.log.rows.len();
        assert!(
            kept > csv.rows.len() / 3 && kept < csv.rows.len(),
            "{compression}: {kept} rows kept"
        );
        assert_same_rows(&read.log.rows, &csv.rows[..kept], compression.name());
    }
}
