//! MCAP logs through the library: round trips, schemas and encodings, chunking, damaged
//! files, wrong schemas, ROS 2 bags.
#![allow(clippy::unwrap_used)] // test code: a failed unwrap is a failed test

use crate::common::{temp_dir, workspace_root};

use gyro_log::{
    self, Axis, Log, LogError, LogOptions, McapLogWriter, McapOptions, Row, TimeSource,
};
use std::collections::BTreeMap;
use std::io::BufWriter;
use std::path::{Path, PathBuf};

fn bench() -> Log {
    gyro_log::read_csv(
        &workspace_root().join("fixtures/logs/bench_run.csv"),
        &gyro_log::ColumnOptions::default(),
    )
    .unwrap()
}

fn bench_mcap(dir: &Path) -> PathBuf {
    let path = dir.join("bench.mcap");
    gyro_log::write_mcap(&path, &bench()).unwrap();
    path
}

fn values(row: &Row) -> (u64, Option<f64>, Option<f64>, Option<f64>) {
    (
        row.time_s.to_bits(),
        row.rate_dps,
        row.reference_deg,
        row.temperature_c,
    )
}

fn assert_same_rows(a: &Log, b: &Log) {
    assert_eq!(a.rows.len(), b.rows.len());
    for (x, y) in a.rows.iter().zip(&b.rows) {
        assert_eq!(values(x), values(y), "{x:?} vs {y:?}");
    }
    assert_eq!(a.has_reference, b.has_reference);
    assert_eq!(a.has_temperature, b.has_temperature);
    assert_eq!(a.metadata, b.metadata);
}

fn read(path: &Path) -> Result<gyro_log::McapRead, LogError> {
    gyro_log::read_mcap(path, &McapOptions::default())
}

fn err(path: &Path, options: &McapOptions) -> String {
    gyro_log::read_mcap(path, options).unwrap_err().to_string()
}

#[test]
fn csv_to_mcap_to_csv_is_lossless() {
    let scratch = temp_dir("roundtrip");
    let dir = scratch.path();
    let csv = bench();
    let mcap = bench_mcap(dir);
    let back = read(&mcap).unwrap();
    assert!(back.warnings.is_empty());
    assert_eq!(back.rate_topic, "/gyro");
    assert!(!back.ros2);
    assert_eq!(back.messages, 2 * csv.rows.len() as u64);
    assert_same_rows(&csv, &back.log);
    for (i, row) in back.log.rows.iter().enumerate() {
        assert_eq!(row.line, i as u64 + 1, "line = message index on /gyro");
    }
    let csv2 = dir.join("bench2.csv");
    gyro_log::write_log(&csv2, &back.log, None).unwrap();
    let again = gyro_log::read_log(&csv2, &LogOptions::default()).unwrap();
    assert_same_rows(&csv, &again);
}

#[test]
fn missing_values_columns_and_full_precision_survive() {
    let scratch = temp_dir("missing");
    let dir = scratch.path();
    let mut metadata = BTreeMap::new();
    metadata.insert("sample_rate_hz".to_string(), "100".to_string());
    let row = |line, time_s, rate_dps, reference_deg| Row {
        line,
        time_s,
        rate_dps,
        reference_deg,
        temperature_c: None,
    };
    let third = 1.0 / 3.0;
    let log = Log {
        path: PathBuf::new(),
        metadata,
        has_reference: true,
        has_temperature: false,
        rows: vec![
            row(1, 0.0, Some(third), Some(-0.1)),
            row(2, 0.01, None, Some(1e-300)),
            row(3, 0.02, Some(-7.25e-9), None),
            row(4, 0.02, Some(f64::MAX), Some(2.0)), // same time stamp, its own reference
            row(5, 0.03, Some(0.1 + 0.2), None),
        ],
    };
    let path = dir.join("missing.mcap");
    gyro_log::write_mcap(&path, &log).unwrap();
    let back = read(&path).unwrap();
    assert_same_rows(&log, &back.log);

    // Without a reference channel or temperatures, the log says so.
    let bare = Log {
        has_reference: false,
        rows: log
            .rows
            .iter()
            .map(|r| Row {
                reference_deg: None,
                ..*r
            })
            .collect(),
        ..log.clone()
    };
    gyro_log::write_mcap(&path, &bare).unwrap();
    let back = read(&path).unwrap().log;
    assert!(!back.has_reference && !back.has_temperature);
    assert_same_rows(&bare, &back);

    // A negative time cannot be an MCAP log time.
    let negative = Log {
        rows: vec![row(7, -0.5, Some(1.0), None)],
        ..log
    };
    let e = gyro_log::write_mcap(&path, &negative)
        .unwrap_err()
        .to_string();
    assert!(e.contains("missing.mcap") && e.contains("row 7"), "{e}");
}

/// The written file, as the `mcap` crate sees it: what Foxglove needs to plot it (ROS 2
/// message definitions in CDR, lz4 chunks).
#[test]
fn written_file_has_ros_2_schemas_foxglove_plots() {
    let scratch = temp_dir("schemas");
    let dir = scratch.path();
    let path = bench_mcap(dir);
    let bytes = std::fs::read(&path).unwrap();
    let summary = mcap::Summary::read(&bytes).unwrap().unwrap();
    let mut topics: Vec<&str> = summary.channels.values().map(|c| &*c.topic).collect();
    topics.sort_unstable();
    assert_eq!(topics, ["/gyro", "/reference"]);
    for channel in summary.channels.values() {
        assert_eq!(channel.message_encoding, "cdr");
        let schema = channel.schema.as_ref().unwrap();
        assert_eq!(schema.encoding, "ros2msg");
        let definition = std::str::from_utf8(&schema.data).unwrap();
        let (name, fields): (&str, &[&str]) = if channel.topic == "/gyro" {
            assert_eq!(channel.metadata["has_temperature"], "true");
            (
                "gyro_msgs/msg/Sample",
                &["float64 rate_dps", "float64 temperature_c", "int64 status"],
            )
        } else {
            ("gyro_msgs/msg/Reference", &["float64 angle_deg"])
        };
        assert_eq!(schema.name, name);
        // The fields, in order, one per line before any comment.
        let declared: Vec<String> = definition
            .lines()
            .map(|l| {
                l.split('#')
                    .next()
                    .unwrap()
                    .split_whitespace()
                    .collect::<Vec<_>>()
                    .join(" ")
            })
            .filter(|l| !l.is_empty())
            .collect();
        assert_eq!(declared, fields, "{}", channel.topic);
    }
    for chunk in &summary.chunk_indexes {
        assert_eq!(chunk.compression, "zstd");
    }
    let stats = summary.stats.as_ref().unwrap();
    assert_eq!(stats.message_count, 80_000);
    assert_eq!(stats.metadata_count, 1);
    let index = &summary.metadata_indexes[0];
    assert_eq!(index.name, "gyro");
    let metadata = mcap::read::metadata(&bytes, index).unwrap();
    assert_eq!(metadata.metadata["sample_rate_hz"], "1000");

    let mut seen = 0;
    for message in mcap::MessageStream::new(&bytes).unwrap() {
        let message = message.unwrap();
        assert_eq!(message.log_time, message.publish_time);
        if seen < 2 {
            if message.channel.topic == "/gyro" {
                // CDR little-endian: the header, then the fields at 8-byte alignment.
                assert_eq!(message.data.len(), 28);
                assert_eq!(message.data[..4], [0, 1, 0, 0]);
                assert_eq!(message.data[4..12], 0.2083_f64.to_le_bytes());
                assert_eq!(message.data[12..20], 25.03_f64.to_le_bytes());
                assert_eq!(message.data[20..28], (-1_i64).to_le_bytes());
                assert_eq!(message.log_time, 0);
            } else {
                assert_eq!(*message.data, [0, 1, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0]);
            }
        }
        seen += 1;
    }
    assert_eq!(seen, 80_000);
}

/// Chunks stay short in time, so a killed writer loses little; extra JSON channels and raw
/// frames come out as written.
#[test]
fn incremental_writer_chunks_by_time_and_writes_extra_channels() {
    let scratch = temp_dir("incremental");
    let dir = scratch.path();
    let path = dir.join("rec.mcap");
    let mut w = McapLogWriter::create(&path).unwrap();
    w.write_metadata(&[("sample_rate_hz".to_string(), "1000".to_string())].into())
        .unwrap();
    let schema = serde_json::json!({
        "type": "object",
        "properties": {"seq": {"type": "integer"}}
    });
    let counters = w
        .add_json_channel("/crm100/stats", "gyro.Stats", &schema)
        .unwrap();
    let bad = w.add_json_channel("/x", "x", &serde_json::json!({"type": "array"}));
    assert!(bad.unwrap_err().to_string().contains("object"));
    for i in 0..5000_u64 {
        let t = i * 1_000_000;
        w.write_gyro(t, Some(i as f64 * 0.5), Some(25.0), Some(0x80))
            .unwrap();
        w.write_raw(t, &[0x80, (i >> 8) as u8, i as u8, 0x12, 0x34, 0xff])
            .unwrap();
        if i % 1000 == 0 {
            w.write_json(counters, t, &serde_json::json!({"seq": i}))
                .unwrap();
        }
    }
    w.finish().unwrap();

    let bytes = std::fs::read(&path).unwrap();
    let summary = mcap::Summary::read(&bytes).unwrap().unwrap();
    assert!(
        summary.chunk_indexes.len() >= 10,
        "{}",
        summary.chunk_indexes.len()
    );
    for chunk in &summary.chunk_indexes {
        assert_eq!(chunk.compression, "zstd");
        let span = chunk.message_end_time - chunk.message_start_time;
        assert!(span < 500_000_000, "chunk spans {span} ns");
    }
    let mut raw = 0;
    let mut stats = Vec::new();
    for message in mcap::MessageStream::new(&bytes).unwrap() {
        let message = message.unwrap();
        if message.channel.topic == "/gyro" {
            let sample = gyro_log::decode_sample(&message.data).unwrap();
            assert_eq!(sample.status, Some(0x80));
            continue;
        }
        let value: serde_json::Value = serde_json::from_slice(&message.data).unwrap();
        match &*message.channel.topic {
            "/crm100/raw" => {
                if raw == 258 {
                    assert_eq!(value["hex"], "80010212 34ff".replace(' ', ""));
                }
                raw += 1;
            }
            "/crm100/stats" => stats.push(value["seq"].as_u64().unwrap()),
            other => panic!("unexpected channel {other}"),
        }
    }
    assert_eq!(raw, 5000);
    assert_eq!(stats, [0, 1000, 2000, 3000, 4000]);

    let back = read(&path).unwrap().log;
    assert_eq!(back.rows.len(), 5000);
    assert!(!back.has_reference && back.has_temperature);
    assert_eq!(back.rows[4999].rate_dps, Some(2499.5));
    assert_eq!(back.rows[4999].time_s, 4.999);
    assert_eq!(back.metadata_rate_hz(), Some(1000.0));
}

/// Cut a finished file at many points: every row of every complete chunk is read back (an
/// exact prefix), with a warning; or a clear error if too little is left. Never a panic.
#[test]
fn truncated_files_keep_every_complete_chunk() {
    let scratch = temp_dir("truncated");
    let dir = scratch.path();
    let mut short = bench();
    short.rows.truncate(6000); // 12 chunks of 0.5 s
    let full_path = dir.join("short.mcap");
    gyro_log::write_mcap(&full_path, &short).unwrap();
    let full = read(&full_path).unwrap().log;
    let bytes = std::fs::read(&full_path).unwrap();
    let summary = mcap::Summary::read(&bytes).unwrap().unwrap();
    let cut_path = dir.join("cut.mcap");
    let n = bytes.len();
    let mut cuts: Vec<usize> = vec![1, 7, 8, 30, 200, n - 1, n - 8, n - 9, n - 100];
    cuts.extend((1..40).map(|k| n * k / 40));
    for chunk in summary.chunk_indexes.iter().step_by(3) {
        let end = (chunk.chunk_start_offset + chunk.chunk_length) as usize;
        cuts.extend([end - 1, end, end + 1]);
    }
    let mut tolerated = 0;
    for cut in cuts {
        std::fs::write(&cut_path, &bytes[..cut]).unwrap();
        // Rows that must survive: those of chunks that end before the cut.
        let complete_until = summary
            .chunk_indexes
            .iter()
            .filter(|c| (c.chunk_start_offset + c.chunk_length) as usize <= cut)
            .filter(|c| !c.message_index_offsets.is_empty()) // the first holds only channels
            .map(|c| c.message_end_time)
            .max();
        let must = complete_until.map_or(0, |t| {
            full.rows
                .iter()
                .filter(|r| r.time_s <= t as f64 / 1e9)
                .count()
        });
        match read(&cut_path) {
            Ok(got) => {
                tolerated += 1;
                assert!(
                    got.log.rows.len() >= must,
                    "cut {cut}: {} < {must}",
                    got.log.rows.len()
                );
                for (a, b) in got.log.rows.iter().zip(&full.rows) {
                    assert_eq!(values(a), values(b), "cut {cut}");
                }
                assert_eq!(got.warnings.len(), 1, "cut {cut}");
                assert!(
                    got.warnings[0].contains("no MCAP footer"),
                    "{}",
                    got.warnings[0]
                );
                assert_eq!(got.log.metadata, full.metadata);
            }
            Err(e) => {
                assert_eq!(must, 0, "cut {cut}: {e}");
                let e = e.to_string();
                assert!(e.starts_with(&cut_path.display().to_string()), "{e}");
                assert!(!e.contains('\n'), "{e}");
                assert!(
                    e.contains("cut short") || e.contains("no messages"),
                    "cut {cut}: {e}"
                );
            }
        }
    }
    assert!(tolerated > 40, "{tolerated}");
}

#[test]
fn empty_garbage_and_corrupt_files_are_clear_errors() {
    let scratch = temp_dir("corrupt");
    let dir = scratch.path();
    let path = dir.join("x.mcap");
    std::fs::write(&path, b"").unwrap();
    let e = err(&path, &McapOptions::default());
    assert!(e.contains("x.mcap: empty file (0 bytes)"), "{e}");

    std::fs::write(&path, b"time_s,rate_dps\n0,1\n").unwrap();
    let e = err(&path, &McapOptions::default());
    assert!(e.contains("x.mcap: not an MCAP file (bad magic)"), "{e}");

    // A flipped byte inside a chunk of a finished file: the chunk CRC (or zstd) catches it.
    let full = bench_mcap(dir);
    let bytes = std::fs::read(&full).unwrap();
    let summary = mcap::Summary::read(&bytes).unwrap().unwrap();
    let chunk = &summary.chunk_indexes[20];
    let mut damaged = bytes.clone();
    let at = (chunk.chunk_start_offset + chunk.chunk_length / 2) as usize;
    damaged[at] ^= 0x55;
    std::fs::write(&path, &damaged).unwrap();
    let e = err(&path, &McapOptions::default());
    assert!(e.contains("x.mcap: corrupt MCAP file"), "{e}");

    // The same damage in a file without footer (a cut recording): the rows before it.
    let cut = (summary.chunk_indexes[40].chunk_start_offset) as usize;
    std::fs::write(&path, &damaged[..cut]).unwrap();
    let got = read(&path).unwrap();
    assert!(
        got.warnings[0].contains("CRC") || got.warnings[0].contains("ompress"),
        "{:?}",
        got.warnings
    );
    let before = chunk.message_start_time as f64 / 1e9;
    assert_eq!(
        got.log.rows.len(),
        bench().rows.iter().filter(|r| r.time_s < before).count()
    );

    // A file that is not there.
    let e = err(&dir.join("nope.mcap"), &McapOptions::default());
    assert!(e.contains("nope.mcap"), "{e}");
}

/// Write a small MCAP by hand: `channels` are (topic, schema name, schema encoding,
/// schema text, message encoding), `messages` are (channel index, log time ns, payload).
fn handmade(
    path: &Path,
    channels: &[(&str, &str, &str, &str, &str)],
    messages: &[(usize, u64, &[u8])],
) {
    let file = std::fs::File::create(path).unwrap();
    let mut w = mcap::WriteOptions::new()
        .create(BufWriter::new(file))
        .unwrap();
    let ids: Vec<u16> = channels
        .iter()
        .map(|(topic, name, encoding, text, message_encoding)| {
            let schema = if name.is_empty() {
                0 // no schema
            } else {
                w.add_schema(name, encoding, text.as_bytes()).unwrap()
            };
            w.add_channel(schema, topic, message_encoding, &BTreeMap::new())
                .unwrap()
        })
        .collect();
    for (i, &(c, t, data)) in messages.iter().enumerate() {
        w.write_to_known_channel(
            &mcap::records::MessageHeader {
                channel_id: ids[c],
                sequence: i as u32,
                log_time: t,
                publish_time: t,
            },
            data,
        )
        .unwrap();
    }
    w.finish().unwrap();
}

const GYRO_SCHEMA: &str = r#"{"type":"object","properties":{"rate_dps":{"type":"number"}}}"#;
const REF_SCHEMA: &str = r#"{"type":"object","properties":{"angle_deg":{"type":"number"}}}"#;

#[test]
fn wrong_schemas_and_bad_messages_name_channel_and_message() {
    let scratch = temp_dir("schema");
    let dir = scratch.path();
    let path = dir.join("s.mcap");
    let opts = McapOptions::default();
    let gyro = ("/gyro", "gyro.Sample", "jsonschema", GYRO_SCHEMA, "json");

    handmade(
        &path,
        &[("/gyro", "Foo", "ros2msg", "float64 x", "cdr")],
        &[],
    );
    let e = err(&path, &opts);
    assert!(
        e.contains(
            "s.mcap: channel `/gyro`: neither gyro_msgs/msg/Sample nor sensor_msgs/msg/Imu in \
             CDR: schema `Foo`, expected gyro_msgs/msg/Sample"
        ),
        "{e}"
    );

    // The written CDR channels: a wrong schema encoding, a reference of another type, a
    // message too short or in another CDR form, named by channel and message.
    let sample = (
        "/gyro",
        "gyro_msgs/msg/Sample",
        "ros2msg",
        "float64 rate_dps\nfloat64 temperature_c\nint64 status",
        "cdr",
    );
    handmade(
        &path,
        &[("/gyro", "gyro_msgs/msg/Sample", "ros2idl", "", "cdr")],
        &[],
    );
    let e = err(&path, &opts);
    assert!(
        e.contains("schema `gyro_msgs/msg/Sample` has encoding `ros2idl`, expected `ros2msg`"),
        "{e}"
    );
    handmade(
        &path,
        &[sample, ("/reference", "R", "ros2msg", "float64 deg", "cdr")],
        &[],
    );
    let e = err(&path, &opts);
    assert!(
        e.contains("channel `/reference`: schema `R`, expected gyro_msgs/msg/Reference"),
        "{e}"
    );
    // A message of that name laid out otherwise would be misread: refused.
    handmade(
        &path,
        &[(
            "/gyro",
            "gyro_msgs/msg/Sample",
            "ros2msg",
            "float32 rate_dps\nfloat64 temperature_c",
            "cdr",
        )],
        &[],
    );
    let e = err(&path, &opts);
    assert!(
        e.contains(
            "schema `gyro_msgs/msg/Sample` declares `float32 rate_dps; float64 temperature_c`; \
             the reader decodes `float64 rate_dps; float64 temperature_c; int64 status`"
        ),
        "{e}"
    );
    let good = gyro_log::encode_sample(&gyro_log::GyroSample {
        rate_dps: Some(1.5),
        temperature_c: None,
        status: None,
    });
    handmade(
        &path,
        &[sample],
        &[(0, 0, &good), (0, 1000, b"\x00\x01\x00\x00")],
    );
    let e = err(&path, &opts);
    assert!(
        e.contains(
            "channel `/gyro` message 2: 4 bytes, a gyro_msgs/msg/Sample message in CDR has 28"
        ),
        "{e}"
    );
    let mut xcdr = good;
    xcdr[1] = 0x07;
    handmade(&path, &[sample], &[(0, 0, &xcdr)]);
    let e = err(&path, &opts);
    assert!(e.contains("message 1: CDR encapsulation 0x0007"), "{e}");

    handmade(
        &path,
        &[("/gyro", "Foo", "ros2msg", "float64 x", "json")],
        &[],
    );
    let e = err(&path, &opts);
    assert!(
        e.contains("channel `/gyro`: schema `Foo` has encoding `ros2msg`"),
        "{e}"
    );

    handmade(
        &path,
        &[
            gyro,
            (
                "/reference",
                "R",
                "jsonschema",
                r#"{"type":"object","properties":{"deg":{}}}"#,
                "json",
            ),
        ],
        &[],
    );
    let e = err(&path, &opts);
    assert!(
        e.contains("channel `/reference`: schema `R` has no `angle_deg` property"),
        "{e}"
    );

    handmade(
        &path,
        &[("/gyro", "G", "jsonschema", r#"{"type":"array"}"#, "json")],
        &[],
    );
    assert!(err(&path, &opts).contains("\"type\": \"object\""));

    handmade(
        &path,
        &[gyro],
        &[
            (0, 0, br#"{"rate_dps": 1.5}"#),
            (0, 1000, br#"{"rate": 2}"#),
        ],
    );
    let e = err(&path, &opts);
    assert!(
        e.contains("s.mcap: channel `/gyro` message 2: no `rate_dps` field"),
        "{e}"
    );

    handmade(&path, &[gyro], &[(0, 0, br#"{"rate_dps": "fast"}"#)]);
    let e = err(&path, &opts);
    assert!(
        e.contains("channel `/gyro` message 1: not a gyro JSON message"),
        "{e}"
    );

    handmade(&path, &[gyro], &[(0, 0, b"\x00\x01")]);
    let e = err(&path, &opts);
    assert!(
        e.contains("channel `/gyro` message 1: not a gyro JSON message"),
        "{e}"
    );

    // No rate channel at all, or one without messages: the channels are listed.
    handmade(
        &path,
        &[("/other", "O", "jsonschema", GYRO_SCHEMA, "json")],
        &[(0, 0, b"{}")],
    );
    let e = err(&path, &opts);
    assert!(
        e.contains("no `/gyro` channel") && e.contains("/other [O] (0 messages)"),
        "{e}"
    );
    handmade(&path, &[gyro], &[]);
    assert!(err(&path, &opts).contains("no messages on the rate channel"));
    let e = err(
        &path,
        &McapOptions {
            topic: Some("/imu".into()),
            ..McapOptions::default()
        },
    );
    assert!(e.contains("no channel `/imu`"), "{e}");

    // Any JSON channel can be the rate channel with --topic; schemaless JSON is accepted.
    handmade(
        &path,
        &[("/wrench/gyro", "", "", "", "json")],
        &[(0, 5, br#"{"rate_dps": 3.0, "extra": [1]}"#)],
    );
    let got = gyro_log::read_mcap(
        &path,
        &McapOptions {
            topic: Some("/wrench/gyro".into()),
            ..McapOptions::default()
        },
    )
    .unwrap();
    assert_eq!(got.log.rows[0].rate_dps, Some(3.0));
    assert_eq!(got.log.rows[0].time_s, 5e-9);
}

#[test]
fn reference_on_its_own_clock_is_interpolated() {
    let scratch = temp_dir("refclock");
    let dir = scratch.path();
    let path = dir.join("r.mcap");
    let gyro = ("/gyro", "gyro.Sample", "jsonschema", GYRO_SCHEMA, "json");
    let reference = (
        "/reference",
        "gyro.Reference",
        "jsonschema",
        REF_SCHEMA,
        "json",
    );
    let ms = 1_000_000;
    handmade(
        &path,
        &[gyro, reference],
        &[
            (1, 0, br#"{"angle_deg": 0.0}"#),
            (0, 0, br#"{"rate_dps": 0}"#),
            (0, 2 * ms, br#"{"rate_dps": 0}"#),
            (0, 4 * ms, br#"{"rate_dps": 0}"#), // reference arrives after the row
            (1, 4 * ms, br#"{"angle_deg": 4.0}"#),
            (0, 6 * ms, br#"{"rate_dps": 0}"#),
            (1, 8 * ms, br#"{"angle_deg": null}"#),
            (0, 10 * ms, br#"{"rate_dps": null, "temperature_c": null}"#),
        ],
    );
    let log = read(&path).unwrap().log;
    let refs: Vec<Option<f64>> = log.rows.iter().map(|r| r.reference_deg).collect();
    assert_eq!(refs, [Some(0.0), Some(2.0), Some(4.0), None, None]);
    assert!(log.has_reference && log.has_temperature);
    assert_eq!(log.rows[4].rate_dps, None);
}

fn ros(topic: Option<&str>, axis: Axis, flip: bool, time_source: TimeSource) -> McapOptions {
    McapOptions {
        topic: topic.map(str::to_string),
        axis,
        flip,
        time_source,
        ..McapOptions::default()
    }
}

/// `fixtures/mcap/make_ros2_bags.py`: angular_velocity x = i/1000, y = -0.5,
/// z = (i % 50)/10 - 2.5 rad/s; stamp 1700000000.5 s + 10 ms i; log time 1.5 ms (+ 0.1 ms
/// (i % 3)) later.
#[test]
fn ros2_imu_bag_each_axis_sign_and_time_source() {
    let path = workspace_root().join("fixtures/mcap/ros2_imu.mcap");
    let expected = |i: usize, axis: Axis| -> f64 {
        let rad = match axis {
            Axis::X => i as f64 / 1000.0,
            Axis::Y => -0.5,
            Axis::Z => (i % 50) as f64 / 10.0 - 2.5,
        };
        rad.to_degrees()
    };
    for axis in [Axis::X, Axis::Y, Axis::Z] {
        for flip in [false, true] {
            let got =
                gyro_log::read_mcap(&path, &ros(None, axis, flip, TimeSource::Header)).unwrap();
            assert!(got.ros2 && got.warnings.is_empty());
            assert_eq!(got.rate_topic, "/imu/data");
            let log = got.log;
            assert_eq!(log.rows.len(), 200);
            assert!(!log.has_reference && !log.has_temperature);
            let keys: Vec<&str> = log.metadata.keys().map(String::as_str).collect();
            assert_eq!(keys, ["time_origin_s"], "rosbag2 metadata is not ours");
            let sign = if flip { -1.0 } else { 1.0 };
            for (i, row) in log.rows.iter().enumerate() {
                assert_eq!(row.rate_dps, Some(sign * expected(i, axis)), "{axis:?} {i}");
                assert_eq!(row.line, i as u64 + 1);
                // Seconds since the whole second before the first stamp.
                let stamp_ns = 500_000_000 + i as u64 * 10_000_000;
                assert_eq!(row.time_s, gyro_log::mcap::ns_to_seconds(stamp_ns));
            }
            assert_eq!(log.metadata["time_origin_s"], "1700000000");
        }
    }
    let got = gyro_log::read_mcap(
        &path,
        &ros(Some("/imu/data"), Axis::Z, false, TimeSource::LogTime),
    )
    .unwrap();
    for (i, row) in got.log.rows.iter().enumerate() {
        let log_ns = 500_000_000 + i as u64 * 10_000_000 + 1_500_000 + (i as u64 % 3) * 100_000;
        assert_eq!(row.time_s, gyro_log::mcap::ns_to_seconds(log_ns), "{i}");
    }
    // The 100 Hz rate comes out of the header stamps.
    let header = gyro_log::read_mcap(&path, &McapOptions::default())
        .unwrap()
        .log;
    let regular = gyro_log::regularize(&header, &gyro_log::GridOptions::default()).unwrap();
    assert!((regular.sample_rate_hz - 100.0).abs() < 1e-6);

    // --topic naming a channel that is neither JSON nor Imu.
    let e = err(
        &path,
        &ros(Some("/chatter"), Axis::Z, false, TimeSource::Header),
    );
    assert!(
        e.contains(
            "channel `/chatter`: neither gyro_msgs/msg/Sample nor sensor_msgs/msg/Imu in CDR"
        ),
        "{e}"
    );
}

#[test]
fn ros2_bag_with_two_imus_needs_a_topic() {
    let path = workspace_root().join("fixtures/mcap/ros2_two_imus.mcap");
    let e = err(&path, &McapOptions::default());
    assert!(
        e.contains("channel `/imu/raw`: a second rate channel besides `/imu/data`; choose one"),
        "{e}"
    );

    let data = gyro_log::read_mcap(
        &path,
        &ros(Some("/imu/data"), Axis::Y, false, TimeSource::Header),
    )
    .unwrap();
    assert_eq!(data.log.rows.len(), 20);
    assert_eq!(data.log.rows[3].rate_dps, Some((-0.5_f64).to_degrees()));

    let e = err(
        &path,
        &ros(Some("/imu/raw"), Axis::Z, false, TimeSource::Header),
    );
    assert!(
        e.contains("channel `/imu/raw` message 1: header stamp is zero (unset); use the log time"),
        "{e}"
    );
    let raw = gyro_log::read_mcap(
        &path,
        &ros(Some("/imu/raw"), Axis::Z, true, TimeSource::LogTime),
    )
    .unwrap();
    assert_eq!(raw.log.rows.len(), 20);
    assert_eq!(raw.log.rows[0].rate_dps, Some(-(3.0_f64.to_degrees())));
    assert_eq!(raw.log.rows[19].time_s, 0.19);
    assert_eq!(raw.log.metadata["time_origin_s"], "1700000000");
}

#[test]
fn read_log_picks_the_format_by_content() {
    let scratch = temp_dir("dispatch");
    let dir = scratch.path();
    let mcap = bench_mcap(dir);
    // An MCAP file named .csv is still read as MCAP.
    let disguised = dir.join("really_mcap.csv");
    std::fs::copy(&mcap, &disguised).unwrap();
    assert_eq!(
        gyro_log::LogFormat::detect(&disguised),
        gyro_log::LogFormat::Mcap
    );
    let log = gyro_log::read_log(&disguised, &LogOptions::default()).unwrap();
    assert_eq!(log.rows.len(), 40_000);
    let csv = workspace_root().join("fixtures/logs/bench_run.csv");
    assert_eq!(gyro_log::LogFormat::detect(&csv), gyro_log::LogFormat::Csv);
    assert_eq!(
        gyro_log::LogFormat::detect(&dir.join("missing.mcap")),
        gyro_log::LogFormat::Mcap
    );
    let e = gyro_log::write_log(&dir.join("out.txt"), &log, None)
        .unwrap_err()
        .to_string();
    assert!(e.contains("out.txt: unknown output format"), "{e}");
    gyro_log::write_log(&dir.join("out.txt"), &log, Some(gyro_log::LogFormat::Mcap)).unwrap();
    assert_eq!(
        gyro_log::LogFormat::detect(&dir.join("out.txt")),
        gyro_log::LogFormat::Mcap
    );
}
