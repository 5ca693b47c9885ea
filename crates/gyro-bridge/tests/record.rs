//! The bridge end to end through a pseudo-terminal pair: the emulator streams a simulated
//! 1 kHz run with injected faults into the master, `record` reads the slave (opened by
//! name like a serial port) into MCAP or CSV, and the file is compared with the
//! emulator's own fault log.
#![cfg(unix)]
#![allow(clippy::unwrap_used)] // test code: a failed unwrap is a failed test

use crm100_driver::serial::{
    self,
    serialport::{SerialPort, TTYPort},
};
use gyro_bridge::{
    self as bridge, self, CsvSink, Emulator, EmulatorConfig, EmulatorReport, FaultSpec, McapSink,
    Pacing, PlannedFrame, RecordOptions, RecordSink, RecordSummary, Sample, SensorFault,
    StopReason,
};
use gyro_log::{self as log, McapOptions};
use gyro_sim::SensorModel;
use std::collections::BTreeMap;
use std::path::Path;
use std::sync::atomic::AtomicBool;
use std::time::{Duration, Instant};

const LSB_DPS: f64 = 1.0 / 24.0; // ±300 °/s range

/// A fresh folder for one test, named after it; removed with everything in it when the
/// returned guard is dropped, so that test runs leave nothing in the temporary folder.
fn temp_dir(name: &str) -> tempfile::TempDir {
    tempfile::Builder::new()
        .prefix(&format!("gyro-record-test-{name}-"))
        .tempdir()
        .unwrap()
}

/// A simulated bench run at 1 kHz in the ±300 °/s range.
fn simulated(duration_s: f64, seed: u64) -> Vec<Sample> {
    gyro_bridge::simulated_samples(&SensorModel::default(), duration_s, seed).unwrap()
}

/// Streams `planned` as fast as possible into a pty pair while `record` reads it into the
/// sink `make_sink` builds; returns the emulator's report and the recorder's summary.
fn run_through_pty(
    planned: &[PlannedFrame],
    make_sink: impl FnOnce(&RecordOptions) -> Box<dyn RecordSink>,
) -> (EmulatorReport, RecordSummary, f64) {
    let (mut master, slave) = TTYPort::pair().unwrap();
    let name = slave.name().unwrap();
    let mut reader = serial::open_reader(&name, 921_600, Duration::from_millis(50)).unwrap();
    let options = RecordOptions {
        idle_stop: Some(Duration::from_millis(1500)),
        source: name.clone(),
        ..RecordOptions::default()
    };
    let sink = make_sink(&options);
    let frames = planned.to_vec();
    let start = Instant::now();
    // The emulator hands the master back: it stays open until `record` has read
    // everything (closing it would hang up the line and discard unread bytes).
    let emulator = std::thread::spawn(move || {
        let report = bridge::stream(
            frames,
            &mut master,
            Pacing::AsFastAsPossible,
            None,
            None,
            None,
        )
        .unwrap();
        (report, master)
    });
    let stop = AtomicBool::new(false);
    let mut updates = 0;
    let summary =
        bridge::record(&mut reader, sink, &options, &stop, &mut |_| updates += 1).unwrap();
    let elapsed = start.elapsed().as_secs_f64();
    let (report, _master) = emulator.join().unwrap();
    drop(slave);
    assert_eq!(summary.stop, StopReason::Idle);
    assert!(updates > 0, "the status callback was never called");
    (report, summary, elapsed)
}

struct Message {
    topic: String,
    log_time: u64,
    value: serde_json::Value,
}

fn messages(path: &Path) -> Vec<Message> {
    let bytes = std::fs::read(path).unwrap();
    mcap::MessageStream::new(&bytes)
        .unwrap()
        .map(|m| {
            let m = m.unwrap();
            // `/gyro` is CDR (gyro_msgs/msg/Sample): seen here as the same JSON fields.
            let value = if m.channel.message_encoding == "cdr" {
                let sample = log::decode_sample(&m.data).unwrap();
                serde_json::json!({
                    "rate_dps": sample.rate_dps,
                    "temperature_c": sample.temperature_c,
                    "status": sample.status,
                })
            } else {
                serde_json::from_slice(&m.data).unwrap()
            };
            Message {
                topic: m.channel.topic.clone(),
                log_time: m.log_time,
                value,
            }
        })
        .collect()
}

/// 60 s at 1 kHz with every kind of fault, as fast as the pty takes it: every intact
/// frame is in the MCAP exactly once, every lost one is counted, the rates are the
/// emulator's to the LSB, and the file is what Foxglove and `read_mcap` expect.
#[test]
fn sixty_seconds_with_faults_every_intact_frame_once_every_loss_counted() {
    let scratch = temp_dir("mcap");
    let dir = scratch.path();
    let path = dir.join("run.mcap");
    let source = simulated(60.0, 11);
    let config = EmulatorConfig {
        faults: FaultSpec::parse(
            "drop=2e-3,byte_loss=1e-3,bit_flip=1e-3,checksum=1e-3,status=1e-3,stall=1e-4,stall_ms=120,seed=21",
        )
        .unwrap(),
        first_sequence: u32::MAX - 30_000, // the sequence wraps mid-run
        first_timestamp_us: 5_000_000,
        ..EmulatorConfig::default()
    };
    let planned: Vec<_> = Emulator::new(source.clone().into_iter(), config).collect();
    assert_eq!(planned.len(), 60_001);
    let mcap_path = path.clone();
    let (report, summary, elapsed) = run_through_pty(&planned, |options| {
        Box::new(McapSink::create(&mcap_path, options).unwrap())
    });
    let stats = summary.stats;
    eprintln!(
        "sent {} frames ({} intact, {} dropped, {} byte loss, {} bit flips, {} bad checksums, {} status faults, {} stalls) in {elapsed:.1} s; received {} frames, lost {}, CRC errors {}, skipped {} B",
        report.frames, report.intact, report.dropped, report.byte_loss, report.bit_flips,
        report.bad_checksums, report.status_faults, report.stalls,
        stats.frames, stats.frames_lost, stats.crc_errors, stats.bytes_skipped
    );
    // Every fault kind happened.
    for (what, n) in [
        ("dropped", report.dropped),
        ("byte loss", report.byte_loss),
        ("bit flips", report.bit_flips),
        ("bad checksums", report.bad_checksums),
        ("status faults", report.status_faults),
        ("stalls", report.stalls),
    ] {
        assert!(n > 0, "no {what} injected");
    }

    // Counters against the emulator's fault log.
    let intact: Vec<&PlannedFrame> = planned.iter().filter(|p| p.arrives_intact()).collect();
    assert_eq!(stats.frames, intact.len() as u64);
    assert_eq!(stats.frames, report.intact);
    assert_eq!(stats.frames_lost, report.lost_sequences.len() as u64);
    assert_eq!(
        stats.frames_lost,
        report.dropped + report.byte_loss + report.bit_flips
    );
    let intact_sensor =
        |kind: fn(&SensorFault) -> bool| intact.iter().filter(|p| kind(&p.sensor)).count() as u64;
    assert_eq!(
        stats.checksum_errors,
        intact_sensor(|s| matches!(s, SensorFault::Checksum { .. }))
    );
    assert_eq!(
        stats.status_faults,
        intact_sensor(|s| matches!(s, SensorFault::Status { .. }))
    );
    // Each damaged frame's bytes were skipped: 23 for a lost byte, 24 for a flipped bit.
    assert_eq!(
        stats.bytes_skipped,
        23 * report.byte_loss + 24 * report.bit_flips
    );
    assert!(stats.crc_errors >= report.bit_flips / 2, "{stats:?}");
    assert_eq!(stats.bytes_received, report.bytes);
    assert_eq!((stats.duplicates, stats.backwards), (0, 0));
    assert!(stats.timeouts > 0, "the stalls showed as read timeouts");

    // The file: one /crm100/raw and one /gyro message per intact frame, in order.
    let all = messages(&path);
    let on = |topic: &str| {
        all.iter()
            .filter(move |m| m.topic == topic)
            .collect::<Vec<_>>()
    };
    let raw = on("/crm100/raw");
    let gyro = on("/gyro");
    assert_eq!(raw.len(), intact.len());
    assert_eq!(gyro.len(), intact.len());
    for ((r, g), p) in raw.iter().zip(&gyro).zip(&intact) {
        let f = p.frame;
        assert_eq!(r.value["sequence"], f.sequence);
        assert_eq!(r.value["timestamp_us"], f.timestamp_us);
        assert_eq!(r.log_time, f.timestamp_us * 1000);
        assert_eq!(g.log_time, f.timestamp_us * 1000);
        let hex: String = f.response.iter().map(|b| format!("{b:02x}")).collect();
        assert_eq!(r.value["hex"], hex);
        let source_rate = source[p.source_index].rate_dps.unwrap();
        match p.sensor {
            SensorFault::Checksum { .. } => {
                assert_eq!(r.value["checksum_ok"], false);
                assert!(g.value["rate_dps"].is_null());
                assert!(g.value["status"].is_null());
            }
            SensorFault::Status { status } => {
                assert_eq!(g.value["status"], status);
                let rate = g.value["rate_dps"].as_f64().unwrap();
                assert!((rate - source_rate).abs() <= LSB_DPS);
            }
            SensorFault::None => {
                assert_eq!(r.value["checksum_ok"], true);
                assert_eq!(g.value["status"], 0);
                let rate = g.value["rate_dps"].as_f64().unwrap();
                assert_eq!(rate * 24.0, f64::from(p.intended.rate_counts));
                assert!(
                    (rate - source_rate).abs() <= LSB_DPS,
                    "{rate} vs {source_rate}"
                );
                let temperature = g.value["temperature_c"].as_f64().unwrap();
                let source_temperature = source[p.source_index].temperature_c.unwrap();
                assert!((temperature - source_temperature).abs() <= 0.5 / 2.75 + 1e-9);
            }
        }
    }
    // Every gap is an event, and the last stats message holds the final counters.
    let gaps: u64 = on("/crm100/events")
        .iter()
        .filter(|m| m.value["event"] == "gap")
        .map(|m| m.value["lost"].as_u64().unwrap())
        .sum();
    assert_eq!(gaps, stats.frames_lost);
    let last_stats = on("/crm100/stats").last().unwrap().value.clone();
    assert_eq!(last_stats["frames_lost"], stats.frames_lost);
    assert_eq!(last_stats["frames"], stats.frames);
    assert_eq!(last_stats["crc_errors"], stats.crc_errors);

    // Foxglove: `/gyro` in CDR, every other channel JSON with a "type": "object" JSON
    // schema; the metadata.
    let bytes = std::fs::read(&path).unwrap();
    let summary_section = mcap::Summary::read(&bytes).unwrap().unwrap();
    let mut topics: Vec<&str> = summary_section
        .channels
        .values()
        .map(|c| &*c.topic)
        .collect();
    topics.sort_unstable();
    assert_eq!(
        topics,
        ["/crm100/events", "/crm100/raw", "/crm100/stats", "/gyro"]
    );
    for channel in summary_section.channels.values() {
        if channel.topic == "/gyro" {
            // A ROS 2 message definition in CDR, which Foxglove plots as well.
            let schema = channel.schema.as_ref().unwrap();
            assert_eq!(channel.message_encoding, "cdr");
            assert_eq!(schema.encoding, "ros2msg");
            assert_eq!(schema.name, log::SAMPLE_SCHEMA_NAME);
            assert_eq!(channel.metadata[log::HAS_TEMPERATURE_KEY], "true");
            continue;
        }
        assert_eq!(channel.message_encoding, "json");
        let schema = channel.schema.as_ref().unwrap();
        assert_eq!(schema.encoding, "jsonschema");
        let value: serde_json::Value = serde_json::from_slice(&schema.data).unwrap();
        assert_eq!(value["type"], "object", "{}", channel.topic);
    }
    let index = &summary_section.metadata_indexes[0];
    let metadata = mcap::read::metadata(&bytes, index).unwrap().metadata;
    assert_eq!(metadata["sample_rate_hz"], "1000");
    assert_eq!(metadata["range_dps"], "300");
    assert!(metadata["bridge_format"].contains("24-byte"));

    // The log reader takes it as a finished gyro log: one row per intact frame, the
    // checksum failures as missing rates.
    let read = log::read_mcap(&path, &McapOptions::default()).unwrap();
    assert!(read.warnings.is_empty(), "{:?}", read.warnings);
    assert_eq!(read.log.rows.len(), intact.len());
    let missing = read
        .log
        .rows
        .iter()
        .filter(|r| r.rate_dps.is_none())
        .count();
    assert_eq!(missing as u64, stats.checksum_errors);
    assert_eq!(read.log.metadata_rate_hz(), Some(1000.0));
    std::fs::remove_dir_all(dir).unwrap();
}

/// `--csv`: the same rows as CSV, read back by the CSV reader.
#[test]
fn csv_output_has_a_row_per_intact_frame() {
    let scratch = temp_dir("csv");
    let dir = scratch.path();
    let path = dir.join("run.csv");
    let source = simulated(5.0, 4);
    let config = EmulatorConfig {
        faults: FaultSpec::parse("typical,stall=0,seed=8").unwrap(),
        ..EmulatorConfig::default()
    };
    let planned: Vec<_> = Emulator::new(source.clone().into_iter(), config).collect();
    let csv_path = path.clone();
    let (report, summary, _) = run_through_pty(&planned, |options| {
        Box::new(CsvSink::create(&csv_path, options).unwrap())
    });
    assert_eq!(summary.stats.frames, report.intact);
    assert_eq!(
        summary.stats.frames_lost,
        report.lost_sequences.len() as u64
    );
    let csv = log::read_csv(&path, &log::ColumnOptions::default()).unwrap();
    let intact: Vec<_> = planned.iter().filter(|p| p.arrives_intact()).collect();
    assert_eq!(csv.rows.len(), intact.len());
    assert_eq!(csv.metadata_rate_hz(), Some(1000.0));
    for (row, p) in csv.rows.iter().zip(&intact) {
        assert_eq!(row.time_s, p.frame.timestamp_us as f64 / 1e6);
        match (row.rate_dps, p.sensor) {
            (None, SensorFault::Checksum { .. }) => {}
            (Some(rate), _) => {
                assert!((rate - source[p.source_index].rate_dps.unwrap()).abs() <= LSB_DPS)
            }
            (None, other) => panic!("rate missing for {other:?}"),
        }
    }
    let text = std::fs::read_to_string(&path).unwrap();
    let header: BTreeMap<_, _> = text
        .lines()
        .filter_map(|l| l.strip_prefix("# ")?.split_once(": "))
        .collect();
    assert_eq!(header["range_dps"], "300");
    std::fs::remove_dir_all(dir).unwrap();
}

/// A bridge clock that steps back (a restart) is counted and warned about, and the bridge
/// time of the summary sums the clock's forward steps instead of wrapping to 2^64 µs.
#[test]
fn a_bridge_clock_stepping_back_is_counted_not_wrapped() {
    let scratch = temp_dir("clock-back");
    let dir = scratch.path();
    let path = dir.join("run.csv");
    let mut planned: Vec<PlannedFrame> =
        Emulator::new(simulated(2.0, 3).into_iter(), EmulatorConfig::default()).collect();
    // From frame 1000 on, the clock reads 0.5 s earlier.
    for p in planned.iter_mut().skip(1000) {
        p.frame.timestamp_us -= 500_000;
    }
    let mut wire = Vec::new();
    planned.iter().for_each(|p| p.extend_wire(&mut wire));
    let options = RecordOptions::default();
    let sink = Box::new(CsvSink::create(&path, &options).unwrap());
    let mut reader = crm100_driver::BridgeReader::new(std::io::Cursor::new(wire));
    let summary = bridge::record(
        &mut reader,
        sink,
        &options,
        &AtomicBool::new(false),
        &mut |_| {},
    )
    .unwrap();
    assert_eq!(summary.stats.clock_steps_back, 1);
    // 999 ms before the step, 1000 ms after it.
    assert!(
        (summary.stats.bridge_span_s() - 1.999).abs() < 1e-9,
        "{}",
        summary.stats.bridge_span_s()
    );
    let text = summary.to_string();
    assert!(
        text.contains("(1.999 s of bridge time)")
            && text.contains("warning: the bridge clock stepped back 1 times, by up to 0.499000 s")
            && text.contains("every frame is kept"),
        "{text}"
    );
    assert_eq!(summary.stats.largest_clock_step_back_us, 499_000);
    // Every frame kept, the ones after the step at their own stamps.
    let written = std::fs::read_to_string(&path).unwrap();
    assert_eq!(
        written.lines().filter(|l| !l.starts_with('#')).count() as u64,
        summary.stats.samples + 1,
        "{}",
        &written[..200]
    );
    assert_eq!(summary.stats.samples, planned.len() as u64);
}
