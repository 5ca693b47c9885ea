//! MCAP read chunk by chunk: the same rows and slots as reading whole, truncated files read
//! up to the damage with its byte offset, chunks out of time order, and a bound on the rows
//! held.
#![allow(clippy::unwrap_used)] // test code: a failed unwrap is a failed test

use crate::common::{temp_dir, workspace_root};

use gyro_log::{
    self, GridOptions, Log, LogOptions, McapOptions, McapRows, RegularLog, Row, Slot, SlotSink,
};
use std::collections::BTreeMap;
use std::io::BufWriter;
use std::path::Path;

fn bench() -> Log {
    gyro_log::read_csv(
        &workspace_root().join("fixtures/logs/bench_run.csv"),
        &gyro_log::ColumnOptions::default(),
    )
    .unwrap()
}

fn values(row: &Row) -> (u64, u64, Option<f64>, Option<f64>, Option<f64>) {
    (
        row.line,
        row.time_s.to_bits(),
        row.rate_dps,
        row.reference_deg,
        row.temperature_c,
    )
}

struct Slots(Vec<Slot>);
impl SlotSink for Slots {
    fn start(&mut self, _: f64) {}
    fn slot(&mut self, slot: &Slot) {
        self.0.push(*slot);
    }
}

/// `stream` and `load` of an MCAP file give the slots and quality of placing the log
/// read whole.
fn assert_stream_equals_whole(path: &Path, whole: &Log, options: &LogOptions) {
    let grid = GridOptions::default();
    let expected: RegularLog = gyro_log::regularize(whole, &grid).unwrap();
    let mut slots = Slots(Vec::new());
    let mut warnings = Vec::new();
    let quality = gyro_log::stream(path, options, &grid, &mut slots, &mut |w| {
        warnings.push(w.to_string())
    })
    .unwrap();
    assert!(warnings.is_empty(), "{warnings:?}");
    assert_eq!(quality, expected.quality);
    assert_eq!(slots.0.len(), expected.slots.len());
    assert!(slots.0 == expected.slots, "slots differ");
    let loaded = gyro_log::load(path, options, &grid, &mut |_| {}).unwrap();
    assert!(loaded == expected, "loaded log differs");
}

#[test]
fn streaming_equals_whole_file_reading_on_the_fixtures() {
    let scratch = temp_dir("stream-fixtures");
    let dir = scratch.path();
    let path = dir.join("bench.mcap");
    let csv = bench();
    gyro_log::write_mcap(&path, &csv).unwrap();
    let read = gyro_log::read_mcap(&path, &McapOptions::default()).unwrap();
    assert_eq!(read.log.rows.len(), csv.rows.len());
    for (a, b) in read.log.rows.iter().zip(&csv.rows) {
        assert_eq!(values(a).1, values(b).1);
        assert_eq!(values(a).2..=values(a).4, values(b).2..=values(b).4);
    }
    assert_stream_equals_whole(&path, &read.log, &LogOptions::default());
    let ros = workspace_root().join("fixtures/mcap/ros2_imu.mcap");
    let whole = gyro_log::read_mcap(&ros, &McapOptions::default())
        .unwrap()
        .log;
    assert_stream_equals_whole(&ros, &whole, &LogOptions::default());
}

/// A finished file of CDR samples says in its summary whether it has a temperature (its
/// rows are not read ahead for it): streamed, the columns are those of the file read
/// whole, with a temperature and without one.
#[test]
fn the_summary_decides_the_columns_of_a_finished_file() {
    let scratch = temp_dir("stream-columns");
    let dir = scratch.path();
    for with_temperature in [true, false] {
        let mut log = bench();
        if !with_temperature {
            log.has_temperature = false;
            log.rows.iter_mut().for_each(|r| r.temperature_c = None);
        }
        let path = dir.join(format!("t{with_temperature}.mcap"));
        gyro_log::write_mcap(&path, &log).unwrap();
        let whole = gyro_log::read_mcap(&path, &McapOptions::default())
            .unwrap()
            .log;
        assert_eq!(whole.has_temperature, with_temperature);
        assert_stream_equals_whole(&path, &whole, &LogOptions::default());
        let loaded = gyro_log::load(
            &path,
            &LogOptions::default(),
            &GridOptions::default(),
            &mut |_| {},
        )
        .unwrap();
        assert_eq!(loaded.has_temperature, with_temperature);
    }
}

#[test]
fn a_truncated_file_warns_with_the_byte_offset_and_keeps_the_rows_before() {
    let scratch = temp_dir("stream-cut");
    let dir = scratch.path();
    let full = dir.join("full.mcap");
    gyro_log::write_mcap(&full, &bench()).unwrap();
    let bytes = std::fs::read(&full).unwrap();
    let summary = mcap::Summary::read(&bytes).unwrap().unwrap();
    let all = gyro_log::read_mcap(&full, &McapOptions::default())
        .unwrap()
        .log;
    let chunk = &summary.chunk_indexes[30];
    let cut = (chunk.chunk_start_offset + chunk.chunk_length / 2) as usize;
    let path = dir.join("cut.mcap");
    std::fs::write(&path, &bytes[..cut]).unwrap();

    let mut rows = McapRows::open(&path, &McapOptions::default()).unwrap();
    let got: Vec<Row> = rows.by_ref().map(Result::unwrap).collect();
    let before = chunk.message_start_time as f64 / 1e9;
    let kept = all.rows.iter().filter(|r| r.time_s < before).count();
    assert_eq!(got.len(), kept);
    for (a, b) in got.iter().zip(&all.rows) {
        assert_eq!(values(a), values(b));
    }
    let warnings = rows.warnings();
    assert_eq!(warnings.len(), 1);
    let offset = format!("read up to byte {} of {cut}", chunk.chunk_start_offset);
    assert!(warnings[0].contains(&offset), "{}", warnings[0]);
    assert!(warnings[0].contains(&format!("{kept} rate samples kept")));

    // `stream` passes the warning on and places the rows kept.
    let mut slots = Slots(Vec::new());
    let mut warned = Vec::new();
    let grid = GridOptions::default();
    let quality = gyro_log::stream(&path, &LogOptions::default(), &grid, &mut slots, &mut |w| {
        warned.push(w.to_string())
    })
    .unwrap();
    assert_eq!(warned, warnings);
    assert_eq!(quality.rows, kept as u64);
}

/// Messages of one channel pair (`/gyro`, `/reference`) at the given times, written in the
/// given groups, each group closed as a chunk of its own.
fn write_groups(path: &Path, groups: &[Vec<u64>], finish: bool) {
    write_groups_as(path, groups, finish, Some(mcap::Compression::Zstd), true);
}

/// [`write_groups`] with chunks compressed by `compression`, or without chunks.
fn write_groups_as(
    path: &Path,
    groups: &[Vec<u64>],
    finish: bool,
    compression: Option<mcap::Compression>,
    chunked: bool,
) {
    let file = std::fs::File::create(path).unwrap();
    let mut w = mcap::WriteOptions::new()
        .compression(compression)
        .use_chunks(chunked)
        .create(BufWriter::new(file))
        .unwrap();
    let gyro_schema = r#"{"type":"object","properties":{"rate_dps":{}}}"#;
    let ref_schema = r#"{"type":"object","properties":{"angle_deg":{}}}"#;
    let g = w
        .add_schema("gyro.Sample", "jsonschema", gyro_schema.as_bytes())
        .unwrap();
    let r = w
        .add_schema("gyro.Reference", "jsonschema", ref_schema.as_bytes())
        .unwrap();
    let gyro = w.add_channel(g, "/gyro", "json", &BTreeMap::new()).unwrap();
    let reference = w
        .add_channel(r, "/reference", "json", &BTreeMap::new())
        .unwrap();
    let mut sequence = 0;
    for group in groups {
        for &ms in group {
            for (channel, text) in [
                (gyro, format!(r#"{{"rate_dps":{}}}"#, ms % 7)),
                (
                    reference,
                    format!(r#"{{"angle_deg":{}}}"#, ms as f64 / 10.0),
                ),
            ] {
                sequence += 1;
                let header = mcap::records::MessageHeader {
                    channel_id: channel,
                    sequence,
                    log_time: ms * 1_000_000,
                    publish_time: ms * 1_000_000,
                };
                w.write_to_known_channel(&header, text.as_bytes()).unwrap();
            }
        }
        w.flush().unwrap(); // close the chunk
    }
    if finish {
        w.finish().unwrap();
    }
}

/// zstd chunks (decompressed whole), uncompressed chunks, lz4 chunks and messages outside
/// chunks (mcap's linear reader) give the same rows, finished or cut after a few chunks.
#[test]
fn every_compression_and_loose_messages_read_alike() {
    let scratch = temp_dir("stream-compression");
    let dir = scratch.path();
    let groups: Vec<Vec<u64>> = (0..6).map(|g| (g * 500..(g + 1) * 500).collect()).collect();
    let zstd = dir.join("zstd.mcap");
    write_groups(&zstd, &groups, true);
    let expected = gyro_log::read_mcap(&zstd, &McapOptions::default()).unwrap();
    assert_eq!(expected.log.rows.len(), 3000);
    assert!(expected.warnings.is_empty());
    for (name, compression, chunked) in [
        ("none", None, true),
        ("lz4", Some(mcap::Compression::Lz4), true),
        ("loose", None, false),
    ] {
        let path = dir.join(format!("{name}.mcap"));
        write_groups_as(&path, &groups, true, compression, chunked);
        let got = gyro_log::read_mcap(&path, &McapOptions::default()).unwrap();
        assert!(got.warnings.is_empty(), "{name}: {:?}", got.warnings);
        assert_eq!(got.log.rows.len(), expected.log.rows.len(), "{name}");
        for (a, b) in got.log.rows.iter().zip(&expected.log.rows) {
            assert_eq!(values(a), values(b), "{name}");
        }
        // Cut in the middle of the data: the rows before the cut, with a warning.
        let bytes = std::fs::read(&path).unwrap();
        let cut = dir.join(format!("{name}-cut.mcap"));
        std::fs::write(&cut, &bytes[..bytes.len() / 2]).unwrap();
        let got = gyro_log::read_mcap(&cut, &McapOptions::default()).unwrap();
        assert_eq!(got.warnings.len(), 1, "{name}");
        assert!(got.warnings[0].contains("read up to byte"), "{name}");
        let kept = got.log.rows.len();
        assert!(kept > 0 && kept < 3000, "{name}");
        // The last row's reference may be cut off (loose messages: it comes after it).
        for (i, (a, b)) in got.log.rows.iter().zip(&expected.log.rows).enumerate() {
            let (a, b) = (values(a), values(b));
            if i + 1 < kept {
                assert_eq!(a, b, "{name}");
            } else {
                assert_eq!((a.0, a.1, a.2), (b.0, b.1, b.2), "{name}");
            }
        }
    }
}

#[test]
fn chunks_out_of_time_order_are_read_in_time_order() {
    let scratch = temp_dir("stream-order");
    let dir = scratch.path();
    let times: Vec<u64> = (0..3000).collect();
    let in_order = dir.join("in_order.mcap");
    write_groups(&in_order, std::slice::from_ref(&times), true);
    let expected = gyro_log::read_mcap(&in_order, &McapOptions::default()).unwrap();
    assert_eq!(expected.log.rows.len(), 3000);
    // The last second first, then the first, then the middle.
    let shuffled = dir.join("shuffled.mcap");
    let groups = vec![
        times[2000..].to_vec(),
        times[..1000].to_vec(),
        times[1000..2000].to_vec(),
    ];
    write_groups(&shuffled, &groups, true);
    let got = gyro_log::read_mcap(&shuffled, &McapOptions::default()).unwrap();
    assert!(got.warnings.is_empty());
    let strip = |rows: &[Row]| -> Vec<_> { rows.iter().map(values).collect() };
    assert_eq!(strip(&got.log.rows), strip(&expected.log.rows));
    // Every row has its reference (exact times), whatever chunk it was in.
    assert!(got.log.rows.iter().all(|r| r.reference_deg.is_some()));
}

#[test]
fn rows_held_stay_within_a_chunk_whatever_the_length() {
    let scratch = temp_dir("stream-memory");
    let dir = scratch.path();
    let mut log = bench();
    // 120 s at 1 kHz with a reference: 240 chunks of 0.5 s.
    let rows = log.rows.clone();
    let period = rows.len() as f64 / 1000.0;
    log.rows = (0..120_000)
        .map(|i| {
            let mut row = rows[i % rows.len()];
            row.time_s += (i / rows.len()) as f64 * period;
            row.time_s = (row.time_s * 1000.0).round() / 1000.0;
            row.line = i as u64 + 1;
            row
        })
        .collect();
    let path = dir.join("long.mcap");
    gyro_log::write_mcap(&path, &log).unwrap();
    let mut reader = McapRows::open(&path, &McapOptions::default()).unwrap();
    let mut count = 0;
    for row in reader.by_ref() {
        row.unwrap();
        count += 1;
    }
    assert_eq!(count, 120_000);
    let (now, most) = reader.rows_held();
    assert_eq!(now, 0);
    // A chunk holds at most 0.5 s (500 rows); nothing else is held.
    assert!(most <= 500, "{most} rows held");
}
